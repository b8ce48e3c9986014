"""``pmsm-commission simulate PRESET [--set …] [--controller …] [--json] [--csv FILE]``."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from pmsm_commissioning.app.cli.main import add_preset_arguments, check_writable
from pmsm_commissioning.app.io.assumed import assumptions
from pmsm_commissioning.app.io.atomic import write_atomic_text
from pmsm_commissioning.app.io.axis_view import run_at_output, run_line, transmission_json, transmission_lines
from pmsm_commissioning.app.io.dc_link_view import ENERGY_BASIS, choice_json, energy_lines, run_json
from pmsm_commissioning.app.io.derived_view import derived_json
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import format_metric
from pmsm_commissioning.app.io.plant_overrides import load_model_and_plant
from pmsm_commissioning.app.io.presets import load_raw
from pmsm_commissioning.app.io.stock_view import stock_json, stock_lines
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, LABELS, Comparison, compare
from pmsm_commissioning.sim.fdsmc.optimum_gap import DRAWN_BASIS, saving_vs_optimum, supply_saving_vs_optimum
from pmsm_commissioning.sim.fdsmc.recommend import recommend, run_supply_J, runs_of
from pmsm_commissioning.sim.fdsmc.verdicts import comparator_notes, run_warnings

#: Rows of the terminal summary: (metric key, label, unit).
SUMMARY = (
    ("friction_J", "Friction loss over [0, T_m]", "J"),
    ("copper_J", "Copper loss over [0, T_m]", "J"),
    ("electrical_in_J", "Net electrical input over [0, T_m]", "J"),
    ("regenerated_J", "Regenerated over [0, T_m]", "J"),
    ("friction_total_J", "Friction loss, whole run", "J"),
    ("copper_total_J", "Copper loss, whole run", "J"),
    ("electrical_in_total_J", "Net electrical input, whole run", "J"),
    ("motoring_total_J", "Drawn from the DC link, whole run", "J"),
    ("regenerated_total_J", "Returned to the DC link, whole run", "J"),
    ("energy_balance_residual_J", "Energy-balance residual", "J"),
    ("t_2pct_first_s", "First entry into the 2 % band", "s"),
    ("t_2pct_settle_s", "2 % settling time", "s"),
    ("theta_error_at_Tm_rad", "Position error at T_m", "rad"),
    ("overshoot_rad", "Overshoot", "rad"),
    ("omega_peak_rad_s", "Peak speed", "rad/s"),
    ("i_q_peak_A", "Peak i_q", "A"),
    ("torque_peak_Nm", "Peak torque", "N·m"),
    ("u_peak_V", "Peak |u_dq|", "V"),
    ("saturated_s", "Time saturated", "s"),
    ("chatter", "Chatter (limit cycle)", ""),
    ("stable", "Stable", ""),
)




def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``simulate``."""
    add_preset_arguments(p)
    p.add_argument("--controller", choices=("fdsmc", "conventional", "optimum", "stock", "both", "all"),
                   default="all", help="which run(s): both = FDSMC and conventional, all = both, the tracked "
                                       "minimum-energy optimum and the stock drive's trapezoid (default all)")
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")
    p.add_argument("--csv", metavar="FILE",
                   help="write the time series (CSV: controller column, units in the headers); '-': to stdout instead "
                        "of the table")




def comparison_json(cmp: Comparison) -> dict[str, Any]:
    """Return the stable JSON contract of ``simulate --json``.

    Each run's entry holds its metrics, ``dc_link_J`` (the supply's energy under ``controller.dc_link``)
    and its ``dc_link`` energies; with the optimum run, the other entries gain ``saving_vs_optimum_pct``
    (net, :func:`saving_vs_optimum`), ``…_drawn_pct`` and ``…_dc_link_pct`` (the supply's energy).
    """
    c = cmp.derived.params.controller
    out: dict[str, Any] = {"derived": derived_json(cmp.derived), "dc_link": choice_json(c)}
    for run in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock):
        if run is not None:
            out[run.controller] = to_json(run.metrics)
    if cmp.optimum is not None:
        for run in (cmp.fdsmc, cmp.conventional, cmp.stock):
            if run is not None:
                out[run.controller]["saving_vs_optimum_pct"] = saving_vs_optimum(run, cmp.optimum)
                out[run.controller]["saving_vs_optimum_drawn_pct"] = saving_vs_optimum(run, cmp.optimum, DRAWN_BASIS)
                out[run.controller]["saving_vs_optimum_dc_link_pct"] = supply_saving_vs_optimum(run, cmp.optimum, c)
    rec = recommend(cmp.derived.params, cmp)
    for e in rec.energies:
        out[e.controller]["net_electrical_J"] = e.net_electrical_J
        out[e.controller]["checks_failed"] = list(e.failed)
        out[e.controller]["dc_link_J"] = e.dc_link_J
        out[e.controller]["dc_link"] = run_json(e)
    out["recommended"] = {"controller": rec.controller, "why": rec.why, "dc_link": c.dc_link}
    out["energy_basis"] = ENERGY_BASIS
    out["saving_friction_pct"] = cmp.saving_friction_pct
    out["saving_electrical_pct"] = cmp.saving_electrical_pct
    out["saving_electrical_drawn_pct"] = _drawn_saving(cmp)
    out["saving_dc_link_pct"] = dc_link_saving(cmp)
    if (tr := transmission_json(cmp.derived.params)) is not None:
        out["transmission"] = tr
        for run in runs_of(cmp):
            out[run.controller]["at_output"] = run_at_output(run.metrics, cmp.derived.params)
    out["run_warnings"] = run_warnings(cmp)
    out["comparator_notes"] = comparator_notes(cmp)
    if cmp.stock is not None:
        out["stock"].update(stock_json(cmp))
    return to_json(out)


def dc_link_saving(cmp: Comparison) -> float | None:
    """Return the FDSMC's saving over the conventional on the supply's energy (``controller.dc_link``) [%]."""
    c = cmp.derived.params.controller
    a, b = run_supply_J(cmp.fdsmc, c), run_supply_J(cmp.conventional, c)
    return None if a is None or b is None or b <= 0.0 else 100.0 * (1.0 - a / b)


def _drawn_saving(cmp: Comparison) -> float | None:
    """FDSMC's saving over the conventional comparator on the energy drawn from the DC link [%]."""
    if cmp.saving_electrical_pct is None or cmp.fdsmc is None or cmp.conventional is None:
        return None
    a, b = cmp.fdsmc.metrics.motoring_total_J, cmp.conventional.metrics.motoring_total_J
    return None if a is None or not b else 100.0 * (1.0 - a / b)


def write_csv(path: str, cmp: Comparison) -> None:
    """Write the time series in the one CSV format of the exports (:func:`app.exports.model.trace_csv`).

    ``path`` ``-`` is stdout.
    """
    from pmsm_commissioning.app.exports.model import trace_csv  # the export model's imports cost ≈ 0.25 s of cold start

    if path == "-":
        sys.stdout.write(trace_csv(cmp))
        return
    try:
        write_atomic_text(path, trace_csv(cmp))  # a temporary file renamed when complete
    except OSError as exc:
        raise ParameterError(f"cannot write --csv {path!r}: {exc.strerror or exc}") from None


def print_summary(cmp: Comparison) -> None:
    """Side-by-side table of the runs, savings, warnings and explanations."""
    runs = runs_of(cmp)
    p = cmp.derived.params
    print(f"Preset: {p.name}  T_m = {p.manoeuvre.T_m:g} s, θ_dem = {p.manoeuvre.theta_dem:g} rad, "
          f"f_s = {p.controller.f_s}, K = {p.controller.K:g} s/rad\n")
    rec = recommend(p, cmp)
    for line in energy_lines(rec):
        print(line)
    print(f"Recommended: {LABELS.get(rec.controller or '', 'none')}. {rec.why}\n")
    print(f"{'':40s}" + "".join(f"{r.controller:>16s}" for r in runs))
    for key, label, unit in SUMMARY:
        head = label + (f" [{unit}]" if unit else "")
        print(f"{head:40s}" + "".join(f"{format_metric(getattr(r.metrics, key)):>16s}" for r in runs))
    if cmp.saving_friction_pct is not None:
        e = cmp.derived.energy
        print(f"\nFriction saving over [0, T_m]: {cmp.saving_friction_pct:.2f} %  "
              f"(eq. (52) predicts {format_metric(e.saving_pct)} %, bound {e.bound_pct:.2f} %)")
        print(f"Supply-energy saving, whole run ({p.controller.dc_link}): {format_metric(dc_link_saving(cmp))} %; "
              f"net electrical input {cmp.saving_electrical_pct:.2f} %")
    for run in (cmp.fdsmc, cmp.conventional):
        gap = supply_saving_vs_optimum(run, cmp.optimum, p.controller)
        net = saving_vs_optimum(run, cmp.optimum)
        if run is not None and gap is not None:
            print(f"The tracked minimum-energy optimum would save {gap:.2f} % of the {run.controller}'s energy "
                  f"from the supply ({p.controller.dc_link}, whole run), {format_metric(net)} % of its net input")
    for line in transmission_lines(p):
        print(line)
    if transmission_lines(p):
        for r in runs:
            print("  " + run_line(r.controller, r.metrics, p))
    if cmp.stock is not None:
        print("\n" + "\n".join(stock_lines(cmp)))
    for w in run_warnings(cmp) + list(cmp.derived.warnings) + comparator_notes(cmp):
        print(f"  ! {w}")


def run(args: argparse.Namespace) -> int:
    """Simulate and print (table or JSON); optionally write the CSV (``--csv -``: the CSV alone, on stdout)."""
    to_stdout = args.csv == "-"
    if to_stdout and args.json:
        raise ParameterError("--csv - writes the time series to stdout, where --json writes too: give --csv a file "
                             "name, or leave out --json")
    if args.csv and not to_stdout:
        check_writable(args.csv, "--csv")
    params, plant = load_model_and_plant(args.preset, args.overrides)
    ctrls = {"both": ("fdsmc", "conventional"), "all": COMPARATORS}.get(
        args.controller, (args.controller,))
    cmp = compare(params, ctrls, plant=plant)
    if args.csv:
        write_csv(args.csv, cmp)
    if to_stdout:  # the CSV alone on stdout
        return 0
    assumed = assumptions(load_raw(args.preset), params, tuple(args.overrides), params.name)
    if args.json:
        out = comparison_json(cmp) | {"assumptions": to_json(assumed.to_json())}
        print(json.dumps(out, indent=2, ensure_ascii=False, allow_nan=False))
    else:
        print_summary(cmp)
        for line in assumed.lines():
            print(f"  ! {line}")
    return 0
