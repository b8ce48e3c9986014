"""The stock route's verdict at the edge: JSON of ``simulate --json`` and the page's lines.

The engine's ``stock`` run is a setpoint-table drive's own loops (:mod:`sim.stock.route`), tuned on the
simulated checks (:mod:`sim.stock.tuning`); each vendor drive's tuned route is reported beside it, with
the settings its file carries. The verdict a written drive file carries is the one simulated from that
file's own numbers (:mod:`app.exports.drives.stock_route`); it equals these to the files' 9 digits.
"""

from __future__ import annotations

import math
from typing import Any

from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.engine import Comparison, RunResult
from pmsm_commissioning.sim.stock.tuning import DRIVES, ROBUST_J_L, StockTuning, tuned

#: The drives' names in messages.
DRIVE_LABELS = {"odrive": "ODrive fw 0.5.x", "moteus": "moteus", "vesc": "VESC", "setpoints": "setpoint table"}


def verdict_word(failed: list[str]) -> str:
    """Return ``"clean"`` or ``"not clean"``."""
    return "not clean" if failed else "clean"


def _checks(cmp: Comparison, run: RunResult) -> list[str]:
    return [c.text for c in run_checks(cmp.derived.params, run) if c.violated]


def drive_json(tu: StockTuning) -> dict[str, Any]:
    """One vendor drive's tuned route: verdict, checks, in-position time and the settings it runs (SI)."""
    checks = [c.text for c in tu.checks] + ([] if tu.robust or tu.checks else
                                            [f"not robust to J_L × {ROBUST_J_L[0]:g} … × {ROBUST_J_L[1]:g}"])
    if tu.budget_stop:
        checks.append(f"the search stopped at the run budget after {tu.tried} settings")
    loop = tu.loop
    return {"verdict": verdict_word(checks), "checks": checks, "in_position_s": tu.run.metrics.in_position_s,
            "loop_rate_Hz": loop.f_loop, "law": loop.law, "accel_rad_s2": tu.trapezoid.alpha,
            "accel_fraction_of_alpha_max": tu.accel_fraction, "speed_bandwidth_rad_s": tu.omega_v,
            "kp": loop.kp, "kd_Nms_per_rad": loop.kd, "ki": loop.ki, "inertia_kgm2": loop.J_ff,
            "pll_bandwidth_rad_s": loop.omega_e, "current_kp_V_per_A": loop.current_kp,
            "current_ki_V_per_As": loop.current_ki, "robust_J_L_factors": list(ROBUST_J_L),
            "speed_clamp_rad_s": None if math.isinf(loop.omega_lim) else loop.omega_lim,
            "settings_tried": tu.tried, "search_stopped_at_budget": tu.budget_stop}


def stock_json(cmp: Comparison) -> dict[str, Any]:
    """``stock.verdict``, ``stock.checks``, ``stock.drive`` and ``stock.drives`` of ``simulate --json``."""
    d = cmp.derived
    failed = _checks(cmp, cmp.stock) if cmp.stock is not None else ["not simulated"]
    drives = {name: drive_json(tuned(spec, d.params, d)) for name, spec in DRIVES.items()}
    return {"drive": "setpoints", "verdict": verdict_word(failed), "checks": failed, "drives": drives}


def stock_lines(cmp: Comparison) -> list[str]:
    """One line per vendor drive: its tuned route's verdict and in-position time (the page, the CLI)."""
    out = []
    for name, entry in stock_json(cmp)["drives"].items():
        when = entry["in_position_s"]
        settled = "never in position" if when is None else f"in position at {when:.4g} s"
        why = "" if entry["verdict"] == "clean" else " — " + "; ".join(entry["checks"])
        out.append(f"Stock route, {DRIVE_LABELS[name]}: {entry['verdict'].upper()}, {settled}{why}")
    return out
