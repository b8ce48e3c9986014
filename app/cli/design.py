"""``pmsm-commission design PRESET [--set …] [--json] [-o FILE] [--objective …]``: a clean design for this drive.

Exit status: 0 clean, 3 not as asked (clean only at a longer T_m, or in position later than asked),
4 not clean (:data:`sim.fdsmc.design.EXIT_STATUS`); 2 bad input, 130 interrupted.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from typing import Any

from pmsm_commissioning.app.cli.main import add_preset_arguments, check_writable
from pmsm_commissioning.app.io.assumed import INHERITED, Assumptions, assumptions
from pmsm_commissioning.app.io.atomic import write_atomic_text
from pmsm_commissioning.app.io.axis_view import run_at_output, run_line, transmission_json, transmission_lines
from pmsm_commissioning.app.io.dc_link_view import ENERGY_BASIS, choice_json, energy_lines, run_json
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.motor_defaults import DERIVED
from pmsm_commissioning.app.io.presets import dumps, load_preset, load_raw, to_raw
from pmsm_commissioning.app.io.user_text import check_label
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.objective import OBJECTIVES, ObjectiveDesign, design_for

_VERIFIED_KEYS = ("torque_peak_Nm", "i_q_peak_A", "i_peak_A", "over_i_max_s", "u_peak_V", "omega_peak_rad_s",
                  "theta_error_at_Tm_rad", "overshoot_rad", "in_position_s", "hold_i_q_rms_A", "hold_u_q_ptp_V",
                  "chatter", "saturated_s", "stable", "friction_J", "electrical_in_J")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``design``."""
    add_preset_arguments(p)
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")
    p.add_argument("-o", "--output", metavar="FILE", help="write the designed preset (YAML) to FILE")
    p.add_argument("--objective", choices=OBJECTIVES, default=OBJECTIVES[0],
                   help="what the design minimises: the supply's energy under controller.dc_link (default) or the "
                        "paper's friction loss; "
                        "in_position_by_T_m: the axis in position by T_m (the move ends earlier), least energy")
    p.add_argument("--name", help="name written in the designed preset (default: the preset's)")
    p.add_argument("--source", help="source written in the designed preset, e.g. the motor's data sheet")


def _axis_json(od: ObjectiveDesign, assumed: Assumptions) -> dict[str, Any]:
    """Return the ``assumptions`` and (with a transmission) ``transmission`` entries of ``design --json``."""
    out: dict[str, Any] = {"assumptions": assumed.to_json()}
    params, cmp = od.design.params, od.design.comparison
    if (tr := transmission_json(params)) is not None:
        runs = [r for r in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock) if r is not None] if cmp else []
        out["transmission"] = tr | {"at_output": {r.controller: run_at_output(r.metrics, params) for r in runs}}
    return out


def _designed_preset(preset: dict[str, Any], assumed: Assumptions) -> dict[str, Any]:
    """Write the derived rated values as ``derived`` and the inherited fields' list into the designed preset.

    Reloaded, the rated values are derived again and the inherited values are listed again.
    """
    for a in assumed.derived:
        preset["motor"][a.key.partition(".")[2]] = DERIVED
    if assumed.inherited:
        preset[INHERITED] = {"base": assumed.base, "fields": [a.key for a in assumed.inherited]}
    return preset


def design_json(od: ObjectiveDesign) -> dict[str, Any]:
    """Return the JSON contract of ``design --json``."""
    dd = od.design
    c, cmp = dd.params.controller, dd.comparison
    verified: dict[str, Any] = {}
    for name in ("fdsmc", "conventional"):
        run = getattr(cmp, name) if cmp is not None else None
        if run is not None:
            metrics = to_json(run.metrics)
            verified[name] = {k: metrics[k] for k in _VERIFIED_KEYS}
            verified[name]["checks_failed"] = [c.name for c in run_checks(dd.params, run)]
    crit = pass_criteria(dd.params)
    rec = od.recommendation
    return to_json({
        "objective": od.objective,
        "alpha_max_rule": c.alpha_max_rule,
        "energies": {e.controller: {"net_electrical_J": e.net_electrical_J, "copper_J": e.copper_J,
                                    "friction_J": e.friction_J, "checks_failed": list(e.failed)} | run_json(e)
                     for e in (rec.energies if rec else ())},
        "energy_basis": ENERGY_BASIS,
        "dc_link": choice_json(c),
        "recommended": {"controller": rec.controller, "why": rec.why, "dc_link": c.dc_link} if rec else None,
        "clean": dd.clean,
        "verdict": dd.verdict,
        "exit_status": dd.exit_status,
        "T_m_asked": dd.T_m_asked,
        "T_m": dd.params.manoeuvre.T_m,
        "in_position_s": dd.in_position_s,
        "as_asked": dd.as_asked,
        "criteria": {"omega_max_rad_s": crit.omega_max, "in_position_rad": crit.in_position,
                     "overshoot_rad": crit.overshoot, "hold_i_rms_A": crit.hold_i_rms},
        "noise": None if dd.noise is None else {"hold_i_q_rms_A": dd.noise.i_q_rms, "hold_u_q_rms_V": dd.noise.u_q_rms},
        "encoder_cpr_needed": dd.encoder_cpr_needed,
        "limiting": [{"name": x.name, "value": x.value, "limit": x.limit, "unit": x.unit,
                      "violated": x.violated, "text": x.text} for x in dd.limiting],
        "alternatives": [{"field": a.field, "value": a.value, "unit": a.unit, "verdict": a.verdict, "T_m": a.T_m,
                          "in_position_s": a.in_position_s, "text": a.text} for a in dd.alternatives],
        "notes": list(dd.notes),
        "comparator_notes": list(dd.comparator),
        "design": {"alpha_max": dd.derived.alpha.alpha_max, "T_m": dd.params.manoeuvre.T_m, "K": c.K,
                   "T_c": dd.derived.profile.T_c, "T_c_rule": "T_a" if c.T_c == "T_a" else "given",
                   "f_s": c.f_s, "overshoot_eta": dd.derived.alpha.overshoot, "T_so": c.T_so,
                   "alpha_max_rule": c.alpha_max_rule,
                   "T_salpha": c.T_salpha},
        "verified": verified,
        "saving_friction_pct": cmp.saving_friction_pct if cmp else None,
        "saving_electrical_pct": cmp.saving_electrical_pct if cmp else None,
        "preset": to_raw(dd.params),
    })


def run(args: argparse.Namespace) -> int:
    """Design, verify and print (table or JSON); optionally write the designed preset."""
    params = load_preset(args.preset, args.overrides)
    renamed = {k: check_label(v, f"--{k}") for k, v in (("name", args.name), ("source", args.source))
               if v is not None}
    params = dataclasses.replace(params, **renamed)
    if args.output:  # checked before the work: a device, read-only file, link loop … is refused as export does
        check_writable(args.output, "-o")
    od = design_for(params, args.objective)
    dd = od.design
    assumed = assumptions(load_raw(args.preset), params, tuple(args.overrides), params.name)
    out = design_json(od) | to_json(_axis_json(od, assumed))
    out["preset"] = _designed_preset(out["preset"], assumed)
    if args.output:
        try:
            write_atomic_text(args.output, dumps(out["preset"]))  # a temporary file renamed when complete
        except OSError as exc:
            raise ValueError(f"cannot write -o {args.output!r}: {exc.strerror or exc}") from None
    if args.json:
        print(json.dumps(out, indent=2, ensure_ascii=False))
        return dd.exit_status
    d = out["design"]
    t_in = "never" if dd.in_position_s is None else f"{dd.in_position_s:.4g} s"
    print(f"Design for {params.name} (objective: {od.objective}, α_max rule {d['alpha_max_rule']}): "
          f"{dd.verdict.upper()} — T_m = {d['T_m']:g} s, in position at {t_in}")
    print(f"  α_max = {d['alpha_max']:.5g} rad/s²  T_m = {d['T_m']:g} s  K = {d['K']:.4g} s/rad  "
          f"T_c = {d['T_c']:.4g} s  T_so = {d['T_so'] * 1e3:.4g} ms  T_sα = {d['T_salpha'] * 1e3:.4g} ms  "
          f"f_s = {d['f_s']}  (η = {d['overshoot_eta']:.3g})")
    for x in dd.limiting:
        print(f"  {'✗' if x.violated else '·'} {x.text}")
    for a in dd.alternatives:
        print(f"  alternative: {a.text}")
    for n in dd.notes + dd.comparator:
        print(f"  note: {n}")
    if od.recommendation is not None:
        for line in energy_lines(od.recommendation):
            print(f"  {line}")
        print(f"  recommended: {od.recommendation.why}")
    for line in transmission_lines(dd.params):
        print(f"  {line}")
    cmp = dd.comparison
    if cmp is not None and transmission_lines(dd.params):
        for r in (x for x in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock) if x is not None):
            print("    " + run_line(r.controller, r.metrics, dd.params))
    for line in assumed.lines():
        print(f"  ! {line}")
    for name, v in out["verified"].items():
        inpos = "never" if v["in_position_s"] is None else f"{v['in_position_s']:.4g} s"
        print(f"  {name}: peak {v['torque_peak_Nm']:.4g} N·m, |i_dq| {v['i_peak_A']:.4g} A, {v['u_peak_V']:.4g} V; "
              f"error at T_m {v['theta_error_at_Tm_rad']:.3g} rad; overshoot {v['overshoot_rad']:.3g} rad; "
              f"in position {inpos}; standstill ripple {v['hold_i_q_rms_A']:.3g} A rms; chatter {v['chatter']}")
    print(f"  exit status {dd.exit_status} ({dd.verdict})")
    return dd.exit_status
