"""Small-multiple figures of the BLDC mode: torque per drive with its loaded-window ripple, anti-windup side by side.

One panel per drive instead of every drive's torque on one axis: T_EL (eq. (3) of [2]) and T*
over the run on the left, the loaded steady window (where ``torque_ripple_pct`` is measured) zoomed
on the right with its ripple. The anti-windup figure puts the paper's drive with λ(ε) of eq. (16)
(integral weight falling off with the speed error, half value at ε_λ) beside the same drive with a
constant λ = λ_0 (no anti-windup), same axes.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from pmsm_commissioning.app.figures.bldc_speed_smc import finish_layout, xy
from pmsm_commissioning.app.figures.decimate import BINS_OVERVIEW_ROWS, f32, time_axis
from pmsm_commissioning.app.figures.style import REFERENCE_COLOUR, fmt
from pmsm_commissioning.app.figures.style import line as style_line
from pmsm_commissioning.app.io.units import rad_s_to_rpm
from pmsm_commissioning.sim.bldc.engine import LABELS, BldcComparison, BldcRunResult

_REF = {"color": REFERENCE_COLOUR, "dash": "dot", "width": 1.5}
#: Height of one small-multiple row [px].
ROW_PX = 130
#: Top margin [px]: the figure's title above the panels' own titles.
TOP_PX = 84


def loaded_window(comp: BldcComparison) -> tuple[float, float]:
    """Return (t0, t1) [s], the loaded steady window of the ripple metric (else the run's last 10 %)."""
    for r in comp.runs:
        if r.metrics.ripple_window_s:
            t0, t1 = r.metrics.ripple_window_s
            return float(t0), float(t1)
    t_end = float(comp.runs[0].trace.t[-1])
    return 0.9 * t_end, t_end


def _window(t: np.ndarray, t0: float, t1: float) -> slice:
    i0, i1 = np.searchsorted(t, [t0, t1])
    return slice(int(i0), int(max(i1, i0 + 2)))


def _torque_cell(fig: go.Figure, run: BldcRunResult, row: int, col: int, part: slice | None) -> None:
    tr, c = run.trace, run.controller
    line = style_line(c, 1.8)
    first = row == 1 and col == 1
    if part is None:  # the whole run: one point per pixel; the zoomed window: every sample
        t_el, t_ref = xy(tr.t, tr.T_EL, BINS_OVERVIEW_ROWS), xy(tr.t, tr.T_ref, BINS_OVERVIEW_ROWS)
    else:
        axis = time_axis(tr.t[part])
        t_el, t_ref = {**axis, "y": f32(tr.T_EL[part])}, {**axis, "y": f32(tr.T_ref[part])}
    fig.add_scatter(**t_el, name=LABELS[c], line=line, showlegend=col == 1, legendgroup=c, row=row, col=col)
    fig.add_scatter(**t_ref, name="T* (reference)", line=_REF, showlegend=first, legendgroup="ref", row=row, col=col)


def make_torque_grid_figure(comp: BldcComparison) -> go.Figure:
    """T_EL and T* per drive (one row each): the whole run and the loaded window zoomed, with its ripple."""
    t0, t1 = loaded_window(comp)
    titles = []
    for r in comp.runs:
        ripple = r.metrics.torque_ripple_pct
        titles += [LABELS[r.controller], f"ripple {fmt(ripple, '%', 3)}"]
    fig = make_subplots(rows=len(comp.runs), cols=2, shared_xaxes="columns", column_widths=[0.55, 0.45],
                        vertical_spacing=0.07, horizontal_spacing=0.08, subplot_titles=titles)
    for row, r in enumerate(comp.runs, start=1):
        _torque_cell(fig, r, row, 1, None)
        _torque_cell(fig, r, row, 2, _window(r.trace.t, t0, t1))
        fig.update_yaxes(title="N·m", row=row, col=1)
    n = len(comp.runs)
    fig.update_xaxes(title="t [s]", row=n, col=1)
    fig.update_xaxes(title=f"t [s], loaded window {fmt(t0)}–{fmt(t1)} s", row=n, col=2)
    fig = finish_layout(fig, "bldc_torque", "Torque T_EL per drive (eq. (3)); right: loaded-window ripple",
                        height=90 + ROW_PX * n)
    return fig.update_layout(margin={"t": TOP_PX})


def make_antiwindup_figure(with_aw: BldcRunResult, without_aw: BldcRunResult, eps_lambda: float) -> go.Figure:
    """Draw the paper's drive with and without anti-windup side by side: speed above, torque below, same axes.

    Parameters
    ----------
    with_aw : BldcRunResult     Run with λ(ε) = λ_0/(1 + (ε/ε_λ)²), eq. (16) of [2].
    without_aw : BldcRunResult  Same drive with λ = λ_0 (integral of eq. (16) never relieved).
    eps_lambda : float          ε_λ of the first run [rad/s].
    """
    titles = (f"with anti-windup (ε_λ = {fmt(rad_s_to_rpm(eps_lambda), 'rpm', 3)})", "without (λ = λ_0)")
    fig = make_subplots(rows=2, cols=2, shared_xaxes=True, shared_yaxes="rows", vertical_spacing=0.1,
                        horizontal_spacing=0.05, row_heights=[0.55, 0.45], subplot_titles=titles)
    for col, (run, key) in enumerate(((with_aw, "smc_integral"), (without_aw, "smc_plain")), start=1):
        tr = run.trace
        line = style_line(key, 1.8)
        name = titles[col - 1]
        fig.add_scatter(**xy(tr.t, rad_s_to_rpm(tr.omega_ref)), name="ω*", line=_REF, showlegend=col == 1,
                        legendgroup="ref", row=1, col=col)
        fig.add_scatter(**xy(tr.t, rad_s_to_rpm(tr.omega)), name=name, line=line, legendgroup=name,
                        row=1, col=col)
        fig.add_scatter(**xy(tr.t, tr.T_EL), name=f"T_EL, {name}", line=line, legendgroup=name,
                        showlegend=False, row=2, col=col)
        ov = run.metrics.overshoot_rad_s
        fig.add_annotation(text=f"overshoot {fmt(None if ov is None else rad_s_to_rpm(ov), 'rpm', 3)}",
                           xref=f"x{'' if col == 1 else col} domain", yref=f"y{'' if col == 1 else col} domain",
                           x=0.98, y=0.05, xanchor="right", showarrow=False, bgcolor="rgba(255,255,255,0.8)")
    fig.update_yaxes(title="n [rpm]", row=1, col=1)
    fig.update_yaxes(title="T_EL [N·m]", row=2, col=1)
    fig.update_xaxes(title="t [s]", row=2)
    fig = finish_layout(fig, "bldc_antiwindup", "Paper drive: anti-windup on λ(ε), eq. (16), side by side",
                        height=440)
    return fig.update_layout(margin={"t": TOP_PX})


__all__ = ["ROW_PX", "loaded_window", "make_antiwindup_figure", "make_torque_grid_figure"]
