"""Exports: the drive parameter file (YAML / JSON / C header), CSV time series, an offline HTML report.

The YAML file is a valid preset (written by :func:`app.presets.dumps_preset`, so it re-imports
to exactly the same inputs in the UI and the CLI) followed by ``exported_from`` and the derived
``drive_gains`` as data, one ``NAME: value  # [unit] reference`` line each. The JSON file holds the same inputs and
gains as data, plus the full ``derive --json`` object. The C header ``#define``s every gain in
upper case with its unit in a comment.
"""

from __future__ import annotations

import datetime as _dt
import html
import io
import json
from dataclasses import dataclass
from typing import Any

import numpy as np
import plotly.graph_objects as go
import plotly.io as pio

from app.derived_view import derived_json, derived_rows
from app.presets import SCHEMA, dumps_preset, to_raw
from control.derivations import Derived
from control.params import DriveParams

TOOL = "pmsm-commissioning (FDSMC)"


@dataclass(frozen=True)
class Gain:
    """One value the drive firmware needs: name (C identifier), value, unit, reference."""

    name: str
    value: float
    unit: str
    ref: str


def drive_gains(d: Derived) -> list[Gain]:
    """Every derived gain and setting the drive needs, in SI units.

    K1…K4 (continuous, eq. (18)), L1…L4 and the pole for f_s (discrete observer), α_max, ω_p,
    T_a, T_c, K, g1, g2, T_si, T_sα, θ_dem, T_m.
    """
    p, pr, o = d.params, d.profile, d.observer
    units = {r.symbol: r.unit for r in derived_rows(d)}
    gains = [
        Gain("ALPHA_MAX", d.alpha.alpha_max, "rad/s^2", f"alpha_max, {d.alpha.rule} rule"),
        Gain("OMEGA_P", pr.omega_p, "rad/s", "peak speed, eq. (60)"),
        Gain("T_A", pr.T_a, "s", "acceleration time, eq. (58)"),
        Gain("T_C", pr.T_c, "s", "sliding-mode time constant, eq. (59)"),
        Gain("K_BL", p.controller.K, "s/rad", "boundary-layer gain K, eq. (45)"),
        Gain("G1", d.conventional.g1, "1/s^2", "conventional gain, eq. (61)"),
        Gain("G2", d.conventional.g2, "1/s", "conventional gain, eq. (61)"),
        Gain("T_SI", p.controller.T_si, "s", "d-current settling time, eq. (8)"),
        Gain("T_SALPHA", p.controller.T_salpha, "s", "acceleration settling time, eq. (13)"),
        Gain("THETA_DEM", p.manoeuvre.theta_dem, "rad", "demanded angle"),
        Gain("T_M", p.manoeuvre.T_m, "s", "manoeuvre time"),
        Gain("OBS_Q", o.q, "1/s", "observer pole magnitude, eq. (17)"),
    ]
    gains += [Gain(f"OBS_K{i}", getattr(o, f"K{i}"), units.get(f"K{i}", "-"), "observer gain, eq. (18)")
              for i in range(1, 5)]
    od = d.observer_discrete
    if od is not None:
        gains += [Gain("F_S", 1.0 / od.T_s, "Hz", "controller sample rate"),
                  Gain("OBS_Z_POLE", od.z_pole, "-", "discrete observer pole exp(-q/f_s)")]
        gains += [Gain(f"OBS_L{i + 1}", float(v), units.get(f"L{i + 1}", "-"),
                       "discrete observer gain (Ackermann)") for i, v in enumerate(od.L)]
    return gains


def _num(x: float) -> str:
    return repr(float(x))


def parameter_yaml(params: DriveParams, d: Derived, origin: str) -> str:
    """Drive parameter file as YAML: an importable preset + ``exported_from`` + ``drive_gains`` data.

    ``drive_gains`` maps each upper-case gain name to its SI value, with the unit and equation in
    a comment on the same line. On import the gains are recomputed from the inputs (the preset
    loader ignores ``drive_gains`` and ``exported_from``), so export → import is exact.
    """
    head = [f"# Drive parameter file — {TOOL}, {_dt.date.today().isoformat()}",
            "# All values SI (see docs/nomenclature.md). Re-import: upload this file in the web UI, or",
            "# `python -m app derive <file>`; drive_gains are then recomputed from the inputs."]
    tail = [f"exported_from: {json.dumps(origin)}", "drive_gains:"]
    tail += [f"  {g.name}: {_num(g.value)}  # [{g.unit}] {g.ref}" for g in drive_gains(d)]
    tail += [f"# warning: {w}" for w in d.warnings]
    return "\n".join(head) + "\n" + dumps_preset(params) + "\n".join(tail) + "\n"


def parameter_data(params: DriveParams, d: Derived, origin: str) -> dict[str, Any]:
    """Drive parameter file as plain data: schema, origin, inputs (SI), gains, derived values."""
    return {
        "schema": SCHEMA,
        "tool": TOOL,
        "preset": origin,
        "inputs": to_raw(params),
        "gains": {g.name: {"value": g.value, "unit": g.unit, "ref": g.ref} for g in drive_gains(d)},
        "derived": derived_json(d),
    }


def parameter_json(params: DriveParams, d: Derived, origin: str) -> str:
    """Drive parameter file as JSON text."""
    return json.dumps(parameter_data(params, d, origin), indent=2, ensure_ascii=False) + "\n"


def parameter_c_header(params: DriveParams, d: Derived, origin: str) -> str:
    """Drive parameter file as a C header: ``#define FDSMC_<NAME> <value> /* [unit] ref */``."""
    guard = "FDSMC_DRIVE_PARAMETERS_H"
    lines = ["/* Drive parameter file generated by " + TOOL + f" on {_dt.date.today().isoformat()}.",
             f" * Inputs from: {origin.replace('*/', '* /')}. All values in SI units. */",
             f"#ifndef {guard}", f"#define {guard}", ""]
    for g in drive_gains(d):
        lines.append(f"#define FDSMC_{g.name:<12} ({_num(g.value)}) /* [{g.unit}] {g.ref} */")
    lines += ["", f"#endif /* {guard} */", ""]
    return "\n".join(lines)


#: CSV columns: (trace attribute, header with unit).
CSV_COLUMNS = (
    ("t", "t_s"), ("theta_r", "theta_r_rad"), ("omega_r", "omega_r_rad_s"), ("i_d", "i_d_A"),
    ("i_q", "i_q_A"), ("u_d", "u_d_V"), ("u_q", "u_q_V"), ("alpha", "alpha_rad_s2"),
    ("alpha_dem", "alpha_dem_rad_s2"), ("Gamma_L", "Gamma_L_Nm"), ("Gamma_L_hat", "Gamma_L_hat_Nm"),
    ("theta_hat", "theta_hat_rad"), ("omega_hat", "omega_hat_rad_s"), ("S", "S_rad_s"),
    ("E_friction", "E_friction_J"), ("E_copper", "E_copper_J"), ("E_electrical", "E_electrical_J"),
)


def trace_csv(comparison: Any) -> str:
    """Time series of both runs as CSV (one row per controller and sample, SI units in headers)."""
    out = io.StringIO()
    out.write("controller," + ",".join(h for _, h in CSV_COLUMNS) + "\n")
    for run in (comparison.fdsmc, comparison.conventional):
        if run is None:
            continue
        block = io.StringIO()
        table = np.column_stack([getattr(run.trace, a) for a, _ in CSV_COLUMNS])
        np.savetxt(block, table, fmt="%.9g", delimiter=",")
        prefix = f"{run.controller},"
        out.writelines(prefix + line + "\n" for line in block.getvalue().splitlines())
    return out.getvalue()


def _table(rows: list[tuple[str, ...]], head: tuple[str, ...]) -> str:
    th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    trs = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{trs}</tbody></table>"


def html_report(params: DriveParams, d: Derived, origin: str, warnings: list[str],
                figures: list[go.Figure]) -> str:
    """Self-contained HTML report (Plotly inlined, opens offline): inputs, derived values, warnings, figures."""
    raw = to_raw(params)
    inputs = [(sec, k, str(v)) for sec in ("motor", "load", "controller", "manoeuvre")
              for k, v in raw[sec].items()]
    derived = [(r.label, r.symbol, r.text(), r.unit, r.ref) for r in derived_rows(d)]
    warn = "".join(f"<li>{html.escape(w)}</li>" for w in warnings) or "<li>none</li>"
    plots = [pio.to_html(fig, full_html=False, include_plotlyjs=(i == 0), default_height="560px")
             for i, fig in enumerate(figures)]
    style = ("body{font-family:sans-serif;margin:24px;max-width:1200px}table{border-collapse:collapse;"
             "margin-bottom:16px}td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px}"
             ".warn{color:#c92a2a;font-weight:600}")
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>FDSMC commissioning report — "
            f"{html.escape(params.name)}</title><style>{style}</style></head><body>"
            f"<h1>FDSMC commissioning report</h1><p>Preset: {html.escape(origin)} — "
            f"{html.escape(params.source)}<br>Generated {_dt.datetime.now().isoformat(timespec='seconds')} "
            f"by {TOOL}.</p><h2>Warnings</h2><ul class='warn'>{warn}</ul>"
            f"<h2>Inputs (SI)</h2>{_table(inputs, ('section', 'field', 'value'))}"
            f"<h2>Derived values</h2>{_table(derived, ('quantity', 'symbol', 'value', 'unit', 'ref.'))}"
            f"<h2>Figures</h2>{''.join(plots)}</body></html>")
