"""Offline HTML report of one simulated case: verdicts, metrics table, inputs, derived values, plots.

A single file (Plotly's JavaScript inlined once) that opens without a network. Each time plot
gets :data:`ROW_HEIGHT_PX` of height so the six signals stay legible; figure ids are fixed so the
same case always gives the same bytes.
"""

from __future__ import annotations

import math

import plotly.graph_objects as go
import plotly.io as pio

from pmsm_commissioning.app.exports.tool_id import TOOL
from pmsm_commissioning.app.figures.fdsmc_comparison import TIME_ROWS, make_phase_plane_figure, make_time_plots_figure
from pmsm_commissioning.app.figures.fdsmc_energy import make_energy_bars_figure, make_energy_figure
from pmsm_commissioning.app.figures.style import BAD_COLOUR
from pmsm_commissioning.app.io.derived_view import derived_rows
from pmsm_commissioning.app.io.numbers import format_metric
from pmsm_commissioning.app.io.presets import to_raw
from pmsm_commissioning.app.io.user_text import html_text
from pmsm_commissioning.control.fdsmc.model import available_voltage
from pmsm_commissioning.sim.fdsmc.engine import LABELS, Comparison
from pmsm_commissioning.sim.fdsmc.recommend import recommend
from pmsm_commissioning.sim.fdsmc.verdicts import comparator_notes, run_warnings

#: Height of each time-plot row and of every other figure [px].
ROW_HEIGHT_PX, FIGURE_HEIGHT_PX = 280, 520

#: Metrics table rows: (metric key, label, unit, limit key or None).
METRICS = (
    ("omega_peak_rad_s", "Peak speed", "rad/s", "omega_b"),
    ("torque_peak_Nm", "Peak torque", "N·m", "Gamma_max"),
    ("i_q_peak_A", "Peak i_q", "A", "i_max"),
    ("u_peak_V", "Peak |u_dq|", "V", "u_max"),
    ("saturated_s", "Time on an inverter limit", "s", None),
    ("t_2pct_settle_s", "2 % settling time", "s", "T_m"),
    ("theta_error_at_Tm_rad", "Position error at T_m", "rad", None),
    ("overshoot_rad", "Overshoot", "rad", None),
    ("friction_J", "Friction loss over [0, T_m]", "J", None),
    ("copper_J", "Copper loss over [0, T_m]", "J", None),
    ("electrical_in_J", "Net electrical input over [0, T_m]", "J", None),
    ("electrical_in_total_J", "Net electrical input, whole run", "J", None),
    ("energy_balance_residual_J", "Energy-balance residual", "J", None),
    ("chatter", "Chatter (limit cycle)", "", None),
    ("stable", "Stable", "", None),
)


def _limits(cmp: Comparison) -> dict[str, tuple[float, str]]:
    """Limit values [SI] and where each comes from."""
    p = cmp.derived.params
    m, c = p.motor, p.controller
    u_max = (c.V_dc / math.sqrt(3.0), "V_dc/√3") if c.V_dc > 0 else (available_voltage(m), "√(2/3)·V_0")
    out = {"omega_b": (m.omega_b, "ω_b"), "Gamma_max": (m.Gamma_max, "Γ_max"), "u_max": u_max,
           "T_m": (p.manoeuvre.T_m, "T_m")}
    if c.i_max > 0:
        out["i_max"] = (c.i_max, "i_max")
    return out


def _over(value: object, limit: tuple[float, str] | None) -> bool:
    return isinstance(value, float) and limit is not None and abs(value) > limit[0]


def metrics_table(cmp: Comparison) -> str:
    """HTML table: each metric per controller, the limit it is checked against (red if exceeded)."""
    runs = [r for r in (cmp.fdsmc, cmp.conventional) if r is not None]
    if not runs:
        return "<p>No simulated run (infeasible manoeuvre).</p>"
    limits = _limits(cmp)
    head = "".join(f"<th>{html_text(r.controller)}</th>" for r in runs)
    body = []
    for key, label, unit, lim_key in METRICS:
        lim = limits.get(lim_key) if lim_key else None
        cells = "".join(f"<td class='{'warn' if _over(getattr(r.metrics, key), lim) else ''}'>"
                        f"{format_metric(getattr(r.metrics, key))}</td>" for r in runs)
        lim_text = f"{lim[0]:.5g} ({lim[1]})" if lim else ""
        body.append(f"<tr><td>{html_text(label)}</td><td>{html_text(unit)}</td>{cells}"
                    f"<td>{html_text(lim_text)}</td></tr>")
    saving = f"<p>Friction saving over [0, T_m]: {format_metric(cmp.saving_friction_pct)} %</p>"
    return (f"<table><thead><tr><th>metric</th><th>unit</th>{head}<th>limit</th></tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>{saving}")


def _table(rows: list[tuple[str, ...]], head: tuple[str, ...]) -> str:
    th = "".join(f"<th>{html_text(h)}</th>" for h in head)
    trs = "".join("<tr>" + "".join(f"<td>{html_text(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{trs}</tbody></table>"


def energy_headline(cmp: Comparison) -> str:
    """Return the report's headline: the supply's energy per controller under the DC-link choice, the recommendation.

    Beside it the energy drawn from and returned to the DC link, the net electrical input, copper and friction.
    """
    rec = recommend(cmp.derived.params, cmp)
    if not rec.energies:
        return "<p>No simulated run.</p>"
    rows = [(LABELS[e.controller], f"{e.dc_link_J:.5g}", f"{e.drawn_J:.5g}", f"{e.returned_J:.5g}",
             f"{e.net_electrical_J:.5g}", f"{e.copper_J:.4g}", f"{e.friction_J:.4g}", ", ".join(e.failed) or "none")
            for e in rec.energies]
    table = _table(rows, ("controller", "from the supply [J]", "drawn [J]", "returned [J]", "net electrical input [J]",
                          "copper [J]", "friction [J]", "failed checks"))
    return f"<p><b>{html_text(rec.dc_link)}</b></p>{table}<p><b>Recommended:</b> {html_text(rec.why)}</p>"


def report_figures(cmp: Comparison) -> list[go.Figure]:
    """Return the report's figures, each with its height set for print/offline reading."""
    figs = [make_phase_plane_figure(cmp).update_layout(height=FIGURE_HEIGHT_PX)]
    if cmp.fdsmc is not None:
        figs.append(make_time_plots_figure(cmp).update_layout(height=ROW_HEIGHT_PX * len(TIME_ROWS)))
        figs += [make_energy_figure(cmp).update_layout(height=FIGURE_HEIGHT_PX),
                 make_energy_bars_figure(cmp).update_layout(height=FIGURE_HEIGHT_PX)]
    return figs


def html_report(cmp: Comparison) -> str:
    """Self-contained HTML report (Plotly inlined, opens offline) of one case."""
    d = cmp.derived
    params = d.params
    raw = to_raw(params)
    inputs = [(sec, k, str(v)) for sec in ("motor", "load", "controller", "manoeuvre") for k, v in raw[sec].items()]
    derived = [(r.label, r.symbol, r.text(), r.unit, r.ref) for r in derived_rows(d)]
    warnings = list(d.warnings) + run_warnings(cmp) + comparator_notes(cmp)
    warn = "".join(f"<li>{html_text(w)}</li>" for w in warnings) or "<li>none</li>"
    plots = [pio.to_html(fig, full_html=False, include_plotlyjs=(i == 0), div_id=f"figure{i}",
                         default_height=f"{fig.layout.height}px") for i, fig in enumerate(report_figures(cmp))]
    style = ("body{font-family:sans-serif;margin:24px;max-width:1200px}table{border-collapse:collapse;"
             "margin-bottom:16px}td,th{border:1px solid #ccc;padding:3px 8px;font-size:13px}"
             f".warn{{color:{BAD_COLOUR};font-weight:600}}")
    name = html_text(params.name)
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>FDSMC commissioning report — {name}"
            f"</title><style>{style}</style></head><body><h1>FDSMC commissioning report — {name}</h1>"
            f"<p>Source: {html_text(params.source)}<br>Generated by {TOOL}.</p>"
            f"<h2>Net electrical input</h2>{energy_headline(cmp)}"
            f"<h2>Verdicts and warnings</h2><ul class='warn'>{warn}</ul>"
            f"<h2>Simulated metrics</h2>{metrics_table(cmp)}"
            f"<h2>Inputs (SI)</h2>{_table(inputs, ('section', 'field', 'value'))}"
            f"<h2>Derived values</h2>{_table(derived, ('quantity', 'symbol', 'value', 'unit', 'ref.'))}"
            f"<h2>Figures</h2>{''.join(plots)}</body></html>")
