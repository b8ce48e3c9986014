"""``python -m app bldc PRESET [--set …] [--json] [--bench]``: the BLDC speed-drive comparison.

Prints the metrics of the compared drives side by side (or JSON), the derived values and the
warnings. The metric rows and the JSON form are shared with the web UI's BLDC tab.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from typing import Any

from app.cli import add_preset_arguments
from app.preset_modes import load_mode_preset
from app.presets import load_preset
from control.bldc_design import BldcDesign
from control.bldc_params import BldcParams
from control.params import ParameterError
from sim.bldc_engine import CONTROLLERS, LABELS, BldcComparison, compare_bldc, simulate_bldc

#: (metric key, label, unit, format) of the side-by-side table, in reading order.
METRIC_ROWS: tuple[tuple[str, str, str, str], ...] = (
    ("speed_error_ss_rpm", "Steady-state speed error", "rpm", ".3f"),
    ("overshoot_rpm", "Overshoot", "rpm", ".2f"),
    ("recovery_time_s", "Recovery after load steps (longest)", "s", ".4f"),
    ("torque_ripple_pct", "Torque ripple (p-p / mean)", "%", ".2f"),
    ("reach_time_s", "Time to reach ω*", "s", ".4f"),
    ("i_peak_A", "Peak phase current", "A", ".2f"),
    ("v_peak_V", "Peak phase voltage", "V", ".1f"),
    ("torque_peak_Nm", "Peak torque", "N·m", ".2f"),
    ("copper_loss_J", "Copper loss", "J", ".3f"),
    ("copper_loss_mean_W", "Mean copper loss power", "W", ".2f"),
    ("energy_balance_residual_pct", "Energy-balance residual", "%", ".2e"),
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``bldc``."""
    add_preset_arguments(p)
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")
    p.add_argument("--controllers", default=",".join(CONTROLLERS),
                   help=f"comma-separated subset of {', '.join(CONTROLLERS)}")
    p.add_argument("--bench", action="store_true",
                   help="print simulated seconds per wall second of the paper's 2000 rpm scenario")


def format_value(value: Any, fmt: str) -> str:
    """A metric as text ('—' for None / not finite)."""
    if isinstance(value, bool) or value is None:
        return "—" if value is None else str(value)
    if isinstance(value, float) and not math.isfinite(value):
        return "—"
    return format(value, fmt)


def metric_table(comp: BldcComparison) -> list[list[str]]:
    """Header + one row per metric, one column per controller (text cells)."""
    head = ["metric", "unit"] + [r.controller for r in comp.runs]
    rows = [head]
    for key, label, unit, fmt in METRIC_ROWS:
        rows.append([label, unit] + [format_value(r.metrics.get(key), fmt) for r in comp.runs])
    return rows


def _plain(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def design_json(d: BldcDesign) -> dict[str, Any]:
    """Derived values of a case as plain JSON data (SI units)."""
    return {
        "K_Tx_Nm_per_A": d.K_Tx, "K_T_fig7_Nm_per_A": d.K_T_fig7, "i_qx_max_A": d.i_qx_max,
        "current_loop_gain_V_per_A": d.current.gain, "current_loop_bandwidth_rad_s": d.current.bandwidth,
        "current_loop_discrete_gain": d.current.discrete_gain, "T_L_max_Nm": d.T_L_max,
        "eps_plain_ss_predicted_rad_s": d.eps_plain_ss, "E_line_peak_V": d.E_line_peak,
        "pi_gains": {"K_p_i": d.pi.K_p_i, "K_i_i": d.pi.K_i_i, "K_p_w": d.pi.K_p_w, "K_i_w": d.pi.K_i_w,
                     "K_T": d.pi.K_T},
        "reachability_ok": d.reachability.ok,
        "reachability_violated_rad_s": [list(v) for v in d.reachability.violated],
    }


def comparison_json(comp: BldcComparison) -> dict[str, Any]:
    """The stable JSON form: scenario, design, per-controller metrics, warnings."""
    case = comp.params.case
    return {
        "preset": comp.params.name,
        "scenario": {"name": case.name, "omega_0_rad_s": case.omega_0, "omega_ref_rad_s": case.omega_ref,
                     "t_end_s": case.t_end, "emf": comp.params.machine.emf},
        "design": design_json(comp.design),
        "controllers": {r.controller: {"label": LABELS[r.controller],
                                       **{k: _plain(v) for k, v in r.metrics.items()}}
                        for r in comp.runs},
        "warnings": list(comp.design.warnings),
    }


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
    return (f"bldc: {p.case.name} scenario, {t_sim:g} s at f_s = {p.inverter.f_s / 1e3:g} kHz, "
            f"paper drive: best {best * 1e3:.1f} ms → {t_sim / best:,.0f}× real time   [goal ≥ 20×]")


def run(args: argparse.Namespace) -> int:
    """Print the comparison (table or JSON)."""
    params = load_mode_preset(args.preset, args.overrides, mode="bldc")
    if args.bench:
        names = [c.name for c in params.scenario.cases]
        fast = [*args.overrides, "scenario.active=2000rpm"]
        print(bench_figure(load_preset(args.preset, fast) if "2000rpm" in names else params))
        return 0
    comp = compare_bldc(params, _controllers(args.controllers))
    if args.json:
        print(json.dumps(comparison_json(comp), indent=2, ensure_ascii=False))
        return 0
    case = params.case
    print(f"Preset: {params.name}  ({params.source})")
    print(f"Scenario {case.name}: ω {case.omega_0 * 60 / (2 * math.pi):g} → "
          f"{case.omega_ref * 60 / (2 * math.pi):g} rpm over {case.t_end:g} s; machine back-EMF: "
          f"{params.machine.emf}\n")
    rows = metric_table(comp)
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) if i < 2 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths, strict=True))))
    print("\nControllers: " + "; ".join(f"{r.controller} = {LABELS[r.controller]}" for r in comp.runs))
    print("\nWarnings:" if comp.design.warnings else "\nNo warnings.")
    for w in comp.design.warnings:
        print(f"  ! {w}")
    return 0
