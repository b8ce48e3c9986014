"""Plotly figures of the BLDC speed-control mode (pure functions, no GUI).

Each figure carries ``layout.meta = {"id": …}`` so the page (and the browser tests) can find
it. Speeds are shown in rpm, angles in electrical degrees (display edge only).

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from pmsm_commissioning.app.figures.decimate import BINS_TIME_PLOTS, envelope, f32
from pmsm_commissioning.app.figures.plain import slim_template
from pmsm_commissioning.app.figures.style import (
    BLDC_COLOURS,
    PHASE_COLOURS,
    PHASE_DASHES,
    REFERENCE_COLOUR,
    TITLE_PX,
    WARNING_COLOUR,
)
from pmsm_commissioning.app.figures.style import line as style_line
from pmsm_commissioning.app.io.units import rad_s_to_rpm
from pmsm_commissioning.control.bldc.design import BldcDesign
from pmsm_commissioning.control.bldc.dqx import dqx_coefficients, ideal_coefficients
from pmsm_commissioning.sim.bldc import emf as bldc_emf
from pmsm_commissioning.sim.bldc.engine import LABELS, BldcComparison

_MARGIN = {"l": 64, "r": 15, "t": 48, "b": 40}
_IDEAL = {"dash": "dash", "color": REFERENCE_COLOUR}
_REAL = {"color": WARNING_COLOUR}


def finish_layout(fig: go.Figure, fid: str, title: str, height: int = 320) -> go.Figure:
    """Give a BLDC figure its id, title, height, the slim template (page fonts) and a legend below."""
    fig.update_layout(meta={"id": fid}, title={"text": title, "font": {"size": TITLE_PX}}, height=height,
                      margin=_MARGIN, template=slim_template(),
                      legend={"orientation": "h", "y": -0.12, "yanchor": "top"},
                      hovermode="x unified")
    return fig


def xy(t: np.ndarray, y: np.ndarray, n_bins: int = BINS_TIME_PLOTS) -> dict[str, Any]:
    """Trace keys of ``y(t)``: its min/max envelope on about one point per pixel, float32 (chatter stays a band)."""
    axis, values = envelope(t, y, n_bins)
    return {**axis, "y": f32(values)}


def make_emf_figure(table: np.ndarray, Phi_m: float) -> go.Figure:
    """Φ'_ra(θ_e): the ideal trapezoid (controller) and the machine's waveform (Fig. 4)."""
    deg = np.degrees(bldc_emf.grid(table.size))
    fig = go.Figure()
    fig.add_scatter(x=deg, y=bldc_emf.ideal_table(Phi_m, table.size), name="ideal trapezoid",
                    line=_IDEAL)
    fig.add_scatter(x=deg, y=table, name="machine (real)", line=_REAL)
    fig.update_xaxes(title="θ_e [deg]", dtick=60)
    fig.update_yaxes(title="Φ'_ra = e_a/ω_e [Wb]")
    return finish_layout(fig, "bldc_emf", "Back-EMF shape, phase a")


def make_dqx_figure(table: np.ndarray, Phi_m: float) -> go.Figure:
    """a_x(θ_e) and θ_x(θ_e), eqs. (7)–(8), ideal vs machine waveform (Figs. 5–6 of [2])."""
    th = bldc_emf.grid(360)
    ideal = ideal_coefficients(th, Phi_m)
    real = dqx_coefficients(th, bldc_emf.table_phases(table, th), bldc_emf.table_slopes(table, th), Phi_m)
    deg = np.degrees(th)
    fig = make_subplots(rows=2, cols=1, shared_xaxes=True, vertical_spacing=0.08)
    for c, name, style in ((ideal, "ideal trapezoid", _IDEAL), (real, "machine (real)", _REAL)):
        fig.add_scatter(x=deg, y=c.a_x, name=f"a_x, {name}", line=style, row=1, col=1)
        fig.add_scatter(x=deg, y=np.degrees(c.theta_x), name=f"θ_x, {name}", line=style, row=2, col=1)
    fig.update_yaxes(title="a_x [-]", row=1, col=1)
    fig.update_yaxes(title="θ_x [deg]", row=2, col=1)
    fig.update_xaxes(title="θ_e [deg]", dtick=60, row=2, col=1)
    return finish_layout(fig, "bldc_dqx", "dq_x coefficients a_x, θ_x (Figs. 5–6)", height=420)


def make_speed_figure(comp: BldcComparison) -> go.Figure:
    """Speed of every drive and ω*, load torque below (Figs. 9–10, 12–13 of [2])."""
    fig = make_subplots(rows=2, cols=1, shared_xaxes=True, row_heights=[0.72, 0.28], vertical_spacing=0.06)
    tr0 = comp.runs[0].trace
    fig.add_scatter(**xy(tr0.t, rad_s_to_rpm(tr0.omega_ref)), name="ω*",
                    line={"dash": "dot", "color": REFERENCE_COLOUR},
                    row=1, col=1)
    for r in comp.runs:
        tr = r.trace
        fig.add_scatter(**xy(tr.t, rad_s_to_rpm(tr.omega)), name=LABELS[r.controller],
                        line=style_line(r.controller, 1.8), row=1, col=1)
    fig.add_scatter(**xy(tr0.t, tr0.T_L), name="T_L", line={"color": REFERENCE_COLOUR, "shape": "hv"},
                    row=2, col=1)
    fig.update_yaxes(title="n [rpm]", row=1, col=1)
    fig.update_yaxes(title="T_L [N·m]", row=2, col=1)
    fig.update_xaxes(title="t [s]", row=2, col=1)
    return finish_layout(fig, "bldc_speed", "Speed and load torque", height=420)


def make_sigma_figure(comp: BldcComparison) -> go.Figure:
    """Sliding variable σ_ω of eq. (16) (ε_ω for the plain law, ε + I/K_p for PI)."""
    fig = go.Figure()
    for r in comp.runs:
        tr = r.trace
        fig.add_scatter(**xy(tr.t, tr.sigma), name=r.controller, line=style_line(r.controller, 1.8))
    fig.update_xaxes(title="t [s]")
    fig.update_yaxes(title="σ_ω [rad/s]")
    return finish_layout(fig, "bldc_sigma", "Sliding variable σ_ω, eq. (16)")


def make_currents_figure(comp: BldcComparison,
                         controllers: tuple[str, ...] = ("smc_integral", "six_step")) -> go.Figure:
    """Phase currents i_a, i_b, i_c, one row per drive of ``controllers`` present in ``comp``.

    By default the paper's drive (currents shaped by dq_x) above six-step (120° square waves).
    """
    names = [c for c in controllers if any(r.controller == c for r in comp.runs)] or [comp.runs[0].controller]
    fig = make_subplots(rows=len(names), cols=1, shared_xaxes=True, vertical_spacing=0.1,
                        subplot_titles=[LABELS[c] for c in names])
    for row, c in enumerate(names, start=1):
        tr = comp.run(c).trace
        for j, phase in enumerate("abc"):
            fig.add_scatter(**xy(tr.t, tr.i_abc[j]), name=f"i_{phase}", legendgroup=phase,
                            showlegend=row == 1, row=row, col=1,
                            line={"color": PHASE_COLOURS[j], "dash": PHASE_DASHES[j], "width": 1.5})
        fig.update_yaxes(title="i [A]", row=row, col=1)
    fig.update_xaxes(title="t [s]", row=len(names), col=1)
    return finish_layout(fig, "bldc_currents", "Phase currents", height=200 + 150 * len(names))


def make_reachability_figure(design: BldcDesign) -> go.Figure:
    """λ(ε) inside the reachability hyperbola of eq. (24) (Fig. 8 of [2])."""
    rc = design.reachability
    fig = go.Figure()
    bound = np.where(np.isfinite(rc.bound), rc.bound, np.nan)
    top = max(5.0 * float(np.max(rc.lam)), 1.0)
    fig.add_scatter(x=rad_s_to_rpm(rc.eps), y=np.clip(bound, -top, top), name="hyperbola, eq. (24)",
                    line=_REAL, connectgaps=False)
    fig.add_scatter(x=rad_s_to_rpm(rc.eps), y=rc.lam, name="λ(ε) = λ₀/(1 + (ε/ε_λ)²)",
                    line={"color": BLDC_COLOURS["smc_integral"]})
    for a, b in rc.violated:
        fig.add_vrect(x0=rad_s_to_rpm(a), x1=rad_s_to_rpm(b), fillcolor=WARNING_COLOUR, opacity=0.15, line_width=0)
    fig.update_xaxes(title="ε_ω [rpm]")
    fig.update_yaxes(title="λ [1/s]", range=[0.0, top])
    verdict = "inside everywhere" if rc.ok else "VIOLATED (red bands)"
    return finish_layout(fig, "bldc_reach", f"Reachability: λ(ε) vs hyperbola — {verdict}")
