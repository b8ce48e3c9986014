"""``pmsm-commission bldc PRESET [--set …] [--json] [--bench]``: the BLDC speed-drive comparison.

Prints the metrics of the compared drives side by side (or JSON), the derived values and the
warnings. The metric rows and the JSON form are shared with the web UI's BLDC tab.
"""

from __future__ import annotations

import argparse
import json
import time

from pmsm_commissioning.app.cli.main import add_preset_arguments
from pmsm_commissioning.app.io.bldc_view import anti_windup_text, comparison_json, metric_table
from pmsm_commissioning.app.io.presets import load, load_preset
from pmsm_commissioning.app.io.units import Hz_to_kHz, rad_s_to_rpm, s_to_ms
from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.bldc.engine import CONTROLLERS, LABELS, compare_bldc, simulate_bldc


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``bldc``."""
    add_preset_arguments(p)
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")
    p.add_argument("--controllers", default=",".join(CONTROLLERS),
                   help=f"comma-separated subset of {', '.join(CONTROLLERS)}")
    p.add_argument("--no-anti-windup", action="store_true",
                   help="integral speed surfaces with λ = λ_0: eq. (16) without its anti-windup (ε_λ is kept)")
    p.add_argument("--bench", action="store_true",
                   help="print simulated seconds per wall second of the paper's 2000 rpm scenario")


def _controllers(text: str) -> tuple[str, ...]:
    names = tuple(c.strip() for c in text.split(",") if c.strip())
    bad = [c for c in names if c not in CONTROLLERS]
    if bad or not names:
        raise ParameterError(f"--controllers = {text!r} is not allowed: a comma-separated subset of "
                             f"{', '.join(CONTROLLERS)}")
    return names


def bench_figure(params: BldcParams | None = None, repeat: int = 5) -> str:
    """One line: simulated seconds per wall second of the 2000 rpm scenario (paper's drive)."""
    p = params or load_preset("bldc_smc_paper", ["scenario.active=2000rpm"])
    simulate_bldc(p)  # JIT load / compile
    walls = []
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        simulate_bldc(p)
        walls.append(time.perf_counter() - t0)
    best, t_sim = min(walls), p.case.t_end
    return (f"bldc: {p.case.name} scenario, {t_sim:g} s at f_s = {Hz_to_kHz(p.inverter.f_s):g} kHz, "
            f"paper drive: best {s_to_ms(best):.1f} ms → {t_sim / best:,.0f}× real time   [goal ≥ 20×]")


def run(args: argparse.Namespace) -> int:
    """Print the comparison (table or JSON)."""
    params = load(args.preset, args.overrides, mode="bldc")
    if args.bench:
        names = [c.name for c in params.scenario.cases]
        fast = [*args.overrides, "scenario.active=2000rpm"]
        print(bench_figure(load_preset(args.preset, fast) if "2000rpm" in names else params))
        return 0
    comp = compare_bldc(params, _controllers(args.controllers), anti_windup=not args.no_anti_windup)
    if args.json:
        print(json.dumps(comparison_json(comp), indent=2, ensure_ascii=False))
        return 0
    case = params.case
    print(f"Preset: {params.name}  ({params.source})")
    print(f"Scenario {case.name}: ω {rad_s_to_rpm(case.omega_0):g} → "
          f"{rad_s_to_rpm(case.omega_ref):g} rpm over {case.t_end:g} s; machine back-EMF: "
          f"{params.machine.emf}; {anti_windup_text(comp)}\n")
    rows = metric_table(comp)
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True))))
    print("\nControllers: " + "; ".join(f"{r.controller} = {LABELS[r.controller]}" for r in comp.runs))
    print("\nWarnings:" if comp.design.warnings else "\nNo warnings.")
    for w in comp.design.warnings:
        print(f"  ! {w}")
    return 0
