"""``pmsm-commission multiaxis FILE [--T-m SECONDS] [--json]``: axes that must finish together.

FILE is a YAML list of axes, each ``{preset: NAME_OR_PATH, set: [SECTION.FIELD=VALUE, …],
name: LABEL}`` (``set`` and ``name`` optional), e.g.::

    - {preset: siemens_1ft7044_ak7, name: X}
    - {preset: yaskawa_sgm7j_04a, name: Y, set: [manoeuvre.theta_dem=31.4]}
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.io.bounded import ReadError, read_utf8
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import number_option
from pmsm_commissioning.app.io.presets import MAX_BYTES, loads_raw
from pmsm_commissioning.app.io.study_inputs import parse_axes
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.studies.multiaxis import MultiAxisResult, coordinate


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``multiaxis``."""
    p.add_argument("file", metavar="FILE", help="YAML list of axes (preset, set, name)")
    p.add_argument("--T-m", dest="T_m", type=number_option("--T-m"), default=None,
                   help="requested common manoeuvre time [s] (default: the shortest all axes can do)")
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")


def multiaxis_json(res: MultiAxisResult) -> dict[str, Any]:
    """Per-axis and total energies [J], common T_m [s] and arrival."""
    axes = []
    for a in res.axes:
        axes.append({"name": a.name, "T_m_own_s": a.fastest.params.manoeuvre.T_m,
                     "energy_own_fastest_J": a.energy("fastest"), "energy_common_J": a.energy("common"),
                     "theta_error_at_Tm_rad": a.theta_error_at_Tm_rad, "arrived": a.arrived,
                     "clean": a.common.clean, "K": a.common.params.controller.K})
    own = [x["energy_own_fastest_J"] for x in axes]
    com = [x["energy_common_J"] for x in axes]
    return to_json({
        "T_m_s": res.T_m, "axes": axes,
        "total_energy_common_J": sum(com) if None not in com else None,
        "total_energy_own_fastest_J": sum(own) if None not in own else None,
        "all_arrived": all(x["arrived"] for x in axes)})


def run(args: argparse.Namespace) -> int:
    """Coordinate the axes and print the result."""
    path = Path(args.file)
    try:
        text = read_utf8(path, MAX_BYTES, f"FILE = {escaped(args.file)!r}")
    except ReadError as exc:
        raise ParameterError(str(exc)) from None
    if args.T_m is not None and not 0.0 < args.T_m <= 1e4:
        raise ParameterError(f"--T-m = {args.T_m:g} s is not allowed: 0 < T_m ≤ 1e4 s")
    axes = parse_axes(loads_raw(text, str(path)), str(path))
    out = multiaxis_json(coordinate(axes, args.T_m))
    if args.json:
        print(json.dumps(out, indent=2, ensure_ascii=False))
        return 0
    print(f"Common manoeuvre time T_m = {out['T_m_s']:.4g} s")
    for a in out["axes"]:
        print(f"  {a['name']:16s} own fastest {a['T_m_own_s']:.4g} s: {a['energy_own_fastest_J']:.4g} J; "
              f"at common T_m: {a['energy_common_J']:.4g} J, θ error {a['theta_error_at_Tm_rad']:.3g} rad, "
              f"{'arrived' if a['arrived'] else 'NOT arrived'}{'' if a['clean'] else ' (design not clean)'}")
    print(f"Total: {out['total_energy_common_J']:.4g} J together vs {out['total_energy_own_fastest_J']:.4g} J "
          "each at its own fastest")
    return 0
