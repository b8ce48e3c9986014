"""``pmsm-commission dutycycle PRESET FILE [--cycles-per-hour N] [--hours-per-year H] [--price P] [--json]``.

FILE is a YAML list of moves ``{theta_dem: RAD, T_m: S, dwell: S}`` (dwell optional, default 0),
simulated back to back (one continuous run per comparator, :mod:`sim.studies.duty`) with the FDSMC,
the conventional controller and the tracked minimum-energy optimum.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.cli.main import add_preset_arguments
from pmsm_commissioning.app.io.bounded import ReadError, read_bounded
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import number_option, parse_number
from pmsm_commissioning.app.io.presets import MAX_BYTES, load_preset, loads_raw
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.studies.duty import Move, duty_cycle

MAX_MOVES = 50


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``dutycycle``."""
    add_preset_arguments(p)
    p.add_argument("file", metavar="FILE", help="YAML list of moves {theta_dem, T_m, dwell}")
    p.add_argument("--cycles-per-hour", type=number_option("--cycles-per-hour"), default=3600.0,
                   help="cycles per hour (default 3600)")
    p.add_argument("--hours-per-year", type=number_option("--hours-per-year"), default=4000.0,
                   help="operating hours per year (default 4000)")
    p.add_argument("--price", type=number_option("--price"), default=0.25, help="energy price per kWh (default 0.25)")
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")


def _field(item: dict[str, Any], key: str, where: str, default: float | None = None) -> float:
    v = item.get(key, default)
    if isinstance(v, str):  # the strict loader keeps scalars as text: parse them exactly
        return parse_number(v, f"{where}: {key}")
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ParameterError(f"{where}: {key} = {v!r} is not allowed: a finite number")
    return float(v)


#: Longest move and dwell of a duty cycle [s] (a dwell of a day; the step budget bounds the rest).
MAX_T_M_S, MAX_DWELL_S = 1e4, 86400.0


def read_moves(path: str) -> str:
    """Return the moves file's UTF-8 text; one line naming the file when it cannot be read."""
    try:  # never more than MAX_BYTES read (a sparse, /proc or device file); a FIFO refused
        data = read_bounded(path, MAX_BYTES, f"FILE = {escaped(path)!r}")
    except ReadError as exc:
        raise ParameterError(str(exc)) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise ParameterError(f"FILE = {path!r} is not UTF-8 text: allowed a YAML file") from None


def parse_moves(raw: Any, origin: str) -> list[Move]:
    """Parse the YAML list into moves, with a clear message for a bad entry."""
    if not isinstance(raw, list) or not 1 <= len(raw) <= MAX_MOVES:
        raise ParameterError(f"{origin}: expected a YAML list of 1 … {MAX_MOVES} moves")
    moves = []
    for i, item in enumerate(raw):
        where = f"{origin}: move {i + 1}"
        if not isinstance(item, dict) or set(item) - {"theta_dem", "T_m", "dwell"}:
            raise ParameterError(f"{where}: expected a mapping with theta_dem, T_m and optional dwell only")
        mv = Move(_field(item, "theta_dem", where), _field(item, "T_m", where), _field(item, "dwell", where, 0.0))
        if not (0.0 < mv.T_m <= MAX_T_M_S and 0.0 <= mv.dwell <= MAX_DWELL_S):
            raise ParameterError(f"{where}: T_m = {mv.T_m:g} s, dwell = {mv.dwell:g} s not allowed: "
                                 f"0 < T_m ≤ {MAX_T_M_S:g} s, 0 ≤ dwell ≤ {MAX_DWELL_S:g} s")
        moves.append(mv)
    return moves


def run(args: argparse.Namespace) -> int:
    """Simulate the cycle and print energies per cycle and per year."""
    for name, v in (("--cycles-per-hour", args.cycles_per_hour), ("--hours-per-year", args.hours_per_year),
                    ("--price", args.price)):
        if not (math.isfinite(v) and v >= 0.0):
            raise ParameterError(f"{name} = {v:g} is not allowed: ≥ 0")
    if args.hours_per_year > 8784.0:
        raise ParameterError(f"--hours-per-year = {args.hours_per_year:g} is not allowed: ≤ 8784 h")
    params = load_preset(args.preset, args.overrides)
    if not isinstance(params, DriveParams):
        raise ParameterError(f"preset {args.preset!r} is not a position drive")
    path = Path(args.file)
    if not path.is_file():
        raise ParameterError(f"FILE = {args.file!r} is not a readable file")
    res = duty_cycle(params, parse_moves(loads_raw(read_moves(str(path)), str(path)), str(path)))
    year = res.per_year(args.cycles_per_hour, args.hours_per_year, args.price)
    out = {"cycle_s": res.cycle_s, "cycle_J": res.cycle_J, "moves_J": list(res.moves),
           "kWh_per_year": {c: (v[0] if v else None) for c, v in year.items()},
           "cost_per_year": {c: (v[1] if v else None) for c, v in year.items()},
           "runs": {c: {"stable": r.stable, "electrical_in_J": r.electrical_in_J, "copper_J": r.copper_J,
                        "friction_J": r.friction_J, "load_work_J": r.load_work_J,
                        "stored_end_J": r.stored_end_J, "balance_residual_J": r.balance_residual_J,
                        "theta_error_end_rad": r.theta_error_end_rad} for c, r in res.runs.items()},
           "notes": list(res.notes)}
    if args.json:
        print(json.dumps(to_json(out), indent=2, ensure_ascii=False))
        return 0
    print(f"Cycle of {len(res.moves)} moves, {res.cycle_s:.4g} s, simulated back to back")
    for c, w in res.cycle_J.items():
        y = year[c]
        print(f"  {c:13s} {w if w is not None else float('nan'):10.4g} J per cycle"
              + (f", {y[0]:.4g} kWh and {y[1]:.4g} per year" if y else ""))
    for note in res.notes:
        print(f"  {note}")
    return 0
