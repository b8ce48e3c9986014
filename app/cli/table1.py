"""``pmsm-commission table1 PRESET [--set …] [--tm 1.0,1.4,1.8,2.2,2.6] [--json]``.

The Table-1 sweep of [1]: per manoeuvre time the simulated FDSMC and conventional friction
energies over [0, T_m], the saving, eq. (52)'s prediction, the bound 1 − 4/5.6, and the paper's
printed value beside them — both as printed and with the printed columns reversed (see
``docs/paper_reproduction.md``).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

from pmsm_commissioning.app.cli.main import add_preset_arguments
from pmsm_commissioning.app.cli.progress import Progress
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import format_metric, parse_T_m_list
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.sim.fdsmc.table1 import PAPER_TABLE1, TABLE1_T_M, Table1Row, table1_sweep

DEFAULT_TM = ",".join(map(str, TABLE1_T_M))


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``table1``."""
    add_preset_arguments(p)
    p.add_argument("--tm", default=DEFAULT_TM, metavar="T1,T2,…",
                   help=f"comma-separated manoeuvre times in s (default {DEFAULT_TM})")
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")


def reversed_paper() -> dict[float, float]:
    """Table 1's printed savings with the column order reversed (T_m ↦ value of the mirror column)."""
    keys = sorted(PAPER_TABLE1)
    return {k: PAPER_TABLE1[m] for k, m in zip(keys, reversed(keys), strict=True)}


def row_json(r: Table1Row) -> dict[str, float | None]:
    """One row of ``table1 --json``."""
    out = dataclasses.asdict(r)
    out["paper_reversed_pct"] = reversed_paper().get(round(r.T_m, 3))
    return out


def run(args: argparse.Namespace) -> int:
    """Run the sweep and print the table (or JSON)."""
    params = load(args.preset, args.overrides, mode="position")
    tms = parse_T_m_list(args.tm, "--tm")
    if args.json:
        rows = table1_sweep(params, tms)
        print(json.dumps(to_json({"rows": [row_json(r) for r in rows]}), indent=2))
        return 0
    with Progress("simulated", "run") as progress:
        rows = table1_sweep(params, tms, progress)
    print(f"Preset: {params.name}, f_s = {params.controller.f_s}, K = {params.controller.K:g} s/rad\n")
    print(f"{'T_m [s]':>8} {'W_FDSMC [J]':>12} {'W_conv [J]':>12} {'saving %':>9} {'eq.52 %':>8} "
          f"{'bound %':>8} {'paper %':>8} {'reversed %':>10}")
    rev = reversed_paper()
    for r in rows:
        paper, mirrored = format_metric(r.paper_pct, ".2f"), format_metric(rev.get(round(r.T_m, 3)), ".2f")
        print(f"{r.T_m:8.3g} {r.friction_fdsmc_J:12.2f} {r.friction_conventional_J:12.2f} "
              f"{r.saving_pct:9.2f} {r.saving_eq52_pct:8.2f} {r.bound_pct:8.2f} {paper:>8} {mirrored:>10}")
    print("\nSaving = 1 − W_FDSMC/W_conv, friction over [0, T_m]. 'reversed' = the paper's printed "
          "row read right-to-left (see docs/paper_reproduction.md).")
    return 0
