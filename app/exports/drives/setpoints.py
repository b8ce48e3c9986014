"""A setpoint table for any PLC or motion controller: the stock trapezoid sampled at the drive's cycle time.

One row per cycle from t = 0 to T_m inclusive: ``t [s]``, ``theta [U]``, ``omega [U/s]``,
``alpha [U/s^2]`` with U the user's angle unit (rad, deg or rev), ``%.9g``; ``#`` header lines
first (``pandas.read_csv(f, comment="#")``). The trapezoid's jerk is unbounded (steps of α at
0, T_a, T_m − T_a, T_m), so no jerk column is written: a controller that needs one wants an
S-curve, which this tool does not plan.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.app.exports.drives.stock import StockSettings
from pmsm_commissioning.app.exports.drives.stock_lines import CASCADE_UNITS, cascade_lines, parse_cascade
from pmsm_commissioning.app.exports.drives.units import ANGLE_UNITS, rad_to_angle_unit
from pmsm_commissioning.app.io.user_text import csv_comment
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_samples
from pmsm_commissioning.sim.stock.route import StockLoop

#: Most rows of a setpoint table (a longer table needs a longer cycle time).
MAX_ROWS = 2_000_000


@dataclass(frozen=True)
class SetpointTable:
    """A parsed setpoint table: unit and columns (t [s]; θ, ω, α in ``unit``, ``unit``/s, ``unit``/s²)."""

    unit: str
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray


def columns(unit: str) -> tuple[str, str, str, str]:
    """Return the header's column names for angle unit ``unit``."""
    return ("t [s]", f"theta [{unit}]", f"omega [{unit}/s]", f"alpha [{unit}/s^2]")


def setpoint_times(T_m: float, cycle_s: float) -> np.ndarray:
    """Sample times k·cycle for k = 0 … ⌈T_m/cycle⌉ (the last row at or just after T_m, at rest) [s]."""
    if not (math.isfinite(cycle_s) and cycle_s > 0.0):
        raise ParameterError(f"cycle time = {cycle_s!r} s is not allowed: allowed > 0 s")
    n = math.ceil(T_m / cycle_s - 1e-9) + 1
    if n > MAX_ROWS:
        raise ParameterError(f"cycle time = {cycle_s:g} s gives {n} rows: allowed ≥ {T_m / (MAX_ROWS - 1):.3g} s "
                             f"(at most {MAX_ROWS} rows)")
    return np.arange(n) * cycle_s


#: The cascade lines of a setpoint table (every key of the comment block but the planner's limits).
CASCADE_KEYS = tuple(k for k in CASCADE_UNITS if k not in ("vel_limit", "accel_limit"))


def cascade_values(s: StockSettings) -> dict[str, float]:
    """Return the loops (SI) a setpoint table carries as comment lines: cascade, PLL, rate, current loop, motor."""
    g, L = s.gains, 0.5 * (s.L_d + s.L_q)
    return dict(zip(CASCADE_KEYS, (g.pos_gain, g.vel_gain, g.vel_integrator_gain, g.inertia, s.pll_bandwidth,
                                   s.f_loop, s.current_bandwidth, 1.5 * s.p * s.psi_pm, s.current_limit, s.R_s, L),
                    strict=True))


def setpoints_csv(s: StockSettings, header: list[str], unit: str = "rad", cycle_s: float | None = None) -> str:
    """Return the setpoint table of the stock trapezoid (see the module doc).

    The ``#`` lines go through :func:`app.io.user_text.csv_comment`: no added row, no cell a
    spreadsheet reads as a formula.
    """
    if unit not in ANGLE_UNITS:
        raise ParameterError(f"angle unit = {unit!r} is not allowed: one of {', '.join(ANGLE_UNITS)}")
    cycle = s.cycle_s if cycle_s is None else cycle_s
    t = setpoint_times(s.trapezoid.T_m, cycle)
    theta, omega, alpha = (rad_to_angle_unit(1.0, unit) * x for x in trapezoid_samples(s.trapezoid, t))
    out = io.StringIO()
    notes = [f"setpoints: symmetric trapezoid, cycle {cycle:.9g} s, angles in {unit} (no jerk column: the "
             "trapezoid's jerk is unbounded)", "the drive's position/speed cascade and current loop this table was "
             "verified with (SI units):"] + cascade_lines(cascade_values(s))
    for line in header + notes:
        out.write(f"# {csv_comment(line)}\n")
    out.write(",".join(columns(unit)) + "\n")
    np.savetxt(out, np.column_stack((t, theta, omega, alpha)), fmt="%.9g", delimiter=",")
    return out.getvalue()


def parse_setpoints(text: str) -> SetpointTable:
    """Strict parser of a setpoint table: ``#`` lines, the header of one unit, four numbers per row, t rising.

    Raises
    ------
    ParameterError
        Naming the line for a wrong header, a row that is not four finite numbers, or t not increasing.
    """
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    if not lines:
        raise ParameterError("setpoint table is empty: allowed a header and at least one row")
    unit = next((u for u in ANGLE_UNITS if lines[0] == ",".join(columns(u))), None)
    if unit is None:
        raise ParameterError(f"setpoint header = {lines[0][:80]!r} is not allowed: {','.join(columns('rad'))} "
                             "(unit rad, deg or rev)")
    rows = []
    for n, line in enumerate(lines[1:], start=2):
        try:
            row = [float(x) for x in line.split(",")]
        except ValueError:
            row = []
        if len(row) != 4 or not all(math.isfinite(x) for x in row):
            raise ParameterError(f"setpoint row {n} = {line[:60]!r} is not allowed: four finite numbers")
        rows.append(row)
    data = np.array(rows).reshape(-1, 4)
    if np.any(np.diff(data[:, 0]) <= 0.0):
        raise ParameterError("setpoint times are not increasing: allowed t strictly rising row by row")
    return SetpointTable(unit, *data.T)


def setpoints_loop(text: str) -> StockLoop:
    """Return the stock route of a setpoint table: its rows (rad) interpolated, run by its ``cascade.*`` loops.

    Raises
    ------
    ParameterError
        For a malformed table, missing cascade lines or rows that are not equally spaced from t = 0.
    """
    table = parse_setpoints(text)
    c = parse_cascade((ln.lstrip("#").strip() for ln in text.splitlines() if ln.startswith("#")), CASCADE_KEYS)
    dt = float(table.t[1] - table.t[0]) if table.t.size > 1 else 1.0 / c["loop_rate"]
    k = np.arange(table.t.size)
    if not (dt > 0.0 and np.allclose(table.t, k * dt, rtol=1e-8, atol=1e-6 * dt)):  # 9-digit times
        raise ParameterError("setpoint times are not allowed: equally spaced rows from t = 0 s (one per cycle)")
    to_rad = 1.0 / rad_to_angle_unit(1.0, table.unit)
    rows = np.ascontiguousarray(np.vstack((table.theta, table.omega, table.alpha)) * to_rad)
    bw = c["current_bandwidth"]
    return StockLoop("setpoints", c["loop_rate"], "cascade", c["pos_gain"], c["vel_gain"], c["vel_integrator_gain"],
                     math.inf, math.inf, c["inertia"], c["torque_constant"], c["current_limit"], c["pll_bandwidth"],
                     False, c["inductance"] * bw, c["resistance"] * bw, rows, dt)
