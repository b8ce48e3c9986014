"""Pure Plotly figures of one comparison: the phase plane and the time plots.

Every ``make_*_figure`` function takes results and returns a new :class:`plotly.graph_objects.Figure`;
nothing here touches the GUI. Each figure carries ``layout.meta = {"id": …}`` so that the page
(and the browser tests) can tell the figures apart. Long traces are decimated for drawing with
min/max bins (:mod:`app.figures.decimate`), so that chatter stays visible as a band.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import plotly.graph_objects as go

from pmsm_commissioning.app.figures.decimate import BINS_PHASE, BINS_TIME_PLOTS, envelope, f32, minmax_index
from pmsm_commissioning.app.figures.plain import to_figure
from pmsm_commissioning.app.figures.style import BAD_COLOUR, FONT_PX, POSITION_COLOURS, POSITION_DASHES, WARNING_COLOUR
from pmsm_commissioning.control.fdsmc.sliding_mode import boundary_speed, in_boundary_layer
from pmsm_commissioning.sim.fdsmc.engine import LABELS, Comparison, RunResult

#: Most points drawn per trace by :func:`decimate_index` (the drive-log overlay).
MAX_POINTS = 2000
#: Most points per trace in the (24-trace) time plots: about one per pixel of the plot's width.
MAX_POINTS_TIME = 800
#: Line colours per controller (the tracked minimum-energy optimum when simulated).
COLOURS = {key: POSITION_COLOURS[key] for key in ("fdsmc", "conventional", "optimum")}
DASHES = {key: POSITION_DASHES[key] for key in COLOURS}
BOUNDARY_COLOUR = "#2b2b2b"
BAND_COLOUR = "rgba(120, 120, 120, 0.18)"
_MARGIN = {"l": 60, "r": 16, "t": 40, "b": 44}


def decimate_index(n: int, n_max: int = MAX_POINTS) -> np.ndarray:
    """Return the indices of at most ``n_max`` evenly spread samples of ``n``, always keeping the last one."""
    if n <= n_max:
        return np.arange(n)
    idx = np.linspace(0, n - 1, n_max).round().astype(int)
    return np.unique(idx)


def stride_index(n: int, n_max: int) -> np.ndarray:
    """Every k-th sample of ``n`` with k chosen so that at most ``n_max`` remain (a uniform grid stays uniform)."""
    return np.arange(0, n, max(1, -(-n // n_max)))


def runs(comparison: Comparison) -> list[tuple[str, RunResult]]:
    """Return ``(key, RunResult)`` of the controllers present, FDSMC first, the optimum last."""
    return [
        (key, getattr(comparison, key)) for key in COLOURS
        if getattr(comparison, key, None) is not None
    ]


def phase_plane_extent(comparison: Comparison) -> tuple[float, float]:
    """θ_re range [rad] covering the manoeuvre and the trajectories, with a margin."""
    d = comparison.derived
    dth = d.params.manoeuvre.theta_dem
    lo, hi = min(-dth, 0.0), max(-dth, 0.0)
    for _, run in runs(comparison):
        theta_re = run.trace.theta_r - dth
        lo, hi = min(lo, float(np.min(theta_re))), max(hi, float(np.max(theta_re)))
    pad = 0.06 * (hi - lo)
    return lo - pad, hi + pad


def boundary_xy(comparison: Comparison, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """Return the switching boundary of eq. (41) in [1] over the phase-plane extent: (θ_re [rad], ω_r [rad/s])."""
    lo, hi = phase_plane_extent(comparison)
    prof = comparison.derived.profile
    knee = prof.T_c * prof.omega_p
    x = np.unique(np.concatenate([np.linspace(lo, hi, n), [-knee, 0.0, knee]]))
    return x, boundary_speed(x, prof.omega_p, prof.T_c)


def _phase_static_traces(comparison: Comparison) -> list[dict[str, Any]]:
    x, y = boundary_xy(comparison)
    half = 1.0 / comparison.derived.params.controller.K
    return [
        {"type": "scatter", "x": f32(np.concatenate([x, x[::-1]])),
         "y": f32(np.concatenate([y + half, (y - half)[::-1]])),
         "fill": "toself", "fillcolor": BAND_COLOUR, "line": {"width": 0}, "hoverinfo": "skip",
         "name": f"Boundary layer ±1/K = ±{half:.3g} rad/s, eq. (45)"},
        {"type": "scatter", "x": f32(x), "y": f32(y), "mode": "lines", "name": "Switching boundary, eq. (41)",
         "line": {"color": BOUNDARY_COLOUR, "width": 2, "dash": "dash"}},
    ]


def layer_entry_index(comparison: Comparison, run: RunResult) -> int | None:
    """First sample inside the boundary layer |ω_r − ω_b(θ_re)| ≤ 1/K, eqs. (41), (45) in [1]; None if never.

    Before it the drive is *reaching* the switching boundary, from it on it is *sliding* along it.
    """
    d, tr = comparison.derived, run.trace
    prof = d.profile
    inside = np.flatnonzero(in_boundary_layer(tr.theta_r - d.params.manoeuvre.theta_dem, tr.omega_r, prof.omega_p,
                                              prof.T_c, d.params.controller.K))
    return int(inside[0]) if inside.size else None


def load_step_times(comparison: Comparison) -> list[float]:
    """Return the times [s] of the external load-torque steps of the manoeuvre."""
    return [float(s.t) for s in comparison.derived.params.load.steps]


def _phase_marks(comparison: Comparison, key: str, run: RunResult, x_mid: float) -> list[dict[str, Any]]:
    """Return the sliding phase (FDSMC, from the layer entry on), layer entry and load steps of a trajectory.

    ``x_mid`` is the middle of the θ_re axis [rad]: the entry's label leans from there into the plot.
    """
    tr, th = run.trace, comparison.derived.params.manoeuvre.theta_dem
    out = []
    # only the FDSMC has a boundary layer: the conventional law and the tracked optimum do not slide
    k = layer_entry_index(comparison, run) if key == "fdsmc" else None
    if k is not None:
        i = k + minmax_index(tr.omega_r[k:], BINS_PHASE)
        out.append({"type": "scatter", "x": f32(tr.theta_r[i] - th), "y": f32(tr.omega_r[i]), "mode": "lines",
                    "name": "FDSMC sliding phase (in the layer)", "hoverinfo": "skip", "opacity": 0.3,
                    "line": {"color": COLOURS[key], "width": 9}})
    if k is not None:
        out.append({"type": "scatter", "x": [float(tr.theta_r[k] - th)], "y": [float(tr.omega_r[k])],
                    "mode": "markers+text", "text": ["reaching → sliding"],
                    # the label leans into the plot (it was clipped at the plot's edge)
                    "textposition": "top right" if tr.theta_r[k] - th < x_mid else "top left",
                    "name": f"{LABELS[key]} enters boundary layer",
                    "marker": {"symbol": "diamond", "size": 11, "color": COLOURS[key],
                               "line": {"color": BOUNDARY_COLOUR, "width": 1.5}},
                    "hovertemplate": f"t = {tr.t[k]:.4f} s: reaching → sliding<extra>{LABELS[key]}</extra>"})
    steps = [t for t in load_step_times(comparison) if t <= tr.t[-1]]
    if steps:
        idx = [min(int(np.searchsorted(tr.t, t)), len(tr.t) - 1) for t in steps]
        out.append({"type": "scatter", "x": tr.theta_r[idx] - th, "y": tr.omega_r[idx], "mode": "markers",
                    "name": f"{LABELS[key]} load step", "showlegend": key == "fdsmc",
                    # an "-thin" symbol is drawn by its line alone: the line carries the red
                    "marker": {"symbol": "x-thin", "size": 14, "color": BAD_COLOUR,
                               "line": {"width": 3, "color": BAD_COLOUR}},
                    "hovertemplate": "load step at t = %{customdata:.4g} s<extra></extra>",
                    "customdata": np.asarray(steps)})
    return out


def phase_plane_spec(comparison: Comparison) -> dict[str, Any]:
    """Phase plane θ_re–ω_r as a plain-dict figure (see :func:`make_phase_plane_figure`)."""
    d = comparison.derived
    data = _phase_static_traces(comparison)
    lo, hi = phase_plane_extent(comparison)
    for key, run in runs(comparison):
        tr = run.trace
        i = minmax_index(tr.omega_r, BINS_PHASE)  # the chatter band of ω_r survives
        t, x, y = tr.t[i], f32(tr.theta_r[i] - d.params.manoeuvre.theta_dem), f32(tr.omega_r[i])
        colour, label = COLOURS[key], LABELS[key]
        data.append({"type": "scatter", "x": x, "y": y, "mode": "lines", "name": f"{label} trajectory",
                     "customdata": f32(t), "line": {"color": colour, "width": 2},
                     "hovertemplate": "t = %{customdata:.4f} s<br>θ_re = %{x:.4g} rad<br>"
                                      "ω_r = %{y:.4g} rad/s<extra>" + label + "</extra>"})
        data.extend(_phase_marks(comparison, key, run, (lo + hi) / 2.0))
        data.append({"type": "scatter", "x": x[-1:], "y": y[-1:], "mode": "markers+text", "text": [""],
                     # above the marker: below it, the time sat on the zoom inset's rectangle in a replay
                     "textposition": "top right", "name": f"{label} now", "showlegend": False,
                     "hoverinfo": "skip", "textfont": {"size": FONT_PX},
                     "marker": {"color": colour, "size": 14, "line": {"color": "white", "width": 2}}})
    prof = d.profile
    return {"data": data, "layout": {
        "meta": {"id": "phase_plane", "omega_p": prof.omega_p, "T_c": prof.T_c},
        "title": {"text": f"Phase plane — ω_p = {prof.omega_p:.4g} rad/s, T_c = {prof.T_c:.4g} s", "x": 0.01},
        "xaxis": {"title": {"text": "θ_re = θ_r − θ_rdem [rad]"}, "range": [lo, hi], "zeroline": True},
        "yaxis": {"title": {"text": "ω_r [rad/s]"}, "zeroline": True},
        "legend": {"orientation": "h", "y": -0.14, "x": 0.0, "font": {"size": FONT_PX}},
        "margin": _MARGIN, "template": "plotly_white", "hovermode": "closest",
    }}


def make_phase_plane_figure(comparison: Comparison) -> go.Figure:
    """Phase plane θ_re–ω_r: boundary (41), band ±1/K (45), both trajectories and their markers.

    Per controller, in this order: the whole trajectory (``"<name> trajectory"``), the
    boundary-layer entry where reaching turns into sliding (``"<name> enters boundary layer"``,
    if reached), the load steps (``"<name> load step"``, if any) and the marker the replay moves
    (``"<name> now"``, at the end).

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
        ``derived`` gives ω_p [rad/s], T_c [s] and K [s/rad]; ``fdsmc``/``conventional`` may be None
        (then only the boundary is drawn).

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return to_figure(phase_plane_spec(comparison))


#: Time-plot rows: (title, unit, [(trace attribute or None, label, dash)]).
TIME_ROWS: tuple[tuple[str, str, tuple[tuple[str, str, str], ...]], ...] = (
    ("Position", "rad", (("theta_r", "θ_r", "solid"),)),
    ("Speed", "rad/s", (("omega_r", "ω_r", "solid"),)),
    ("Currents", "A", (("i_d", "i_d", "dot"), ("i_q", "i_q", "solid"))),
    ("Voltages", "V", (("u_d", "u_d", "dot"), ("u_q", "u_q", "solid"))),
    ("Acceleration", "rad/s²", (("alpha", "α", "solid"), ("alpha_dem", "α_dem", "dot"))),
    ("Load torque", "N·m", (("Gamma_L", "Γ_L", "solid"), ("Gamma_L_hat", "Γ̂_L", "dot"))),
)


def _references(comparison: Comparison, t_end: float) -> list[dict[str, Any]]:
    d = comparison.derived
    th, wp = d.params.manoeuvre.theta_dem, d.profile.omega_p
    grey = {"color": "#555", "width": 1.5, "dash": "dash"}
    sign = 1.0 if th >= 0 else -1.0
    return [{"type": "scatter", "x": [0.0, t_end], "y": [th, th], "mode": "lines", "line": grey, "name": "θ_dem",
             "xaxis": "x", "yaxis": "y"},
            {"type": "scatter", "x": [0.0, t_end], "y": [sign * wp, sign * wp], "mode": "lines", "line": grey,
             "name": "ω_p, eq. (60)", "xaxis": "x", "yaxis": "y2"}]


def _time_axes(n_rows: int, spacing: float = 0.025) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Layout axes of ``n_rows`` stacked subplots sharing x, and the row titles as annotations."""
    h = (1.0 - spacing * (n_rows - 1)) / n_rows
    layout: dict[str, Any] = {}
    notes = []
    for r in range(n_rows):
        top = 1.0 - r * (h + spacing)
        sfx = "" if r == 0 else str(r + 1)
        layout[f"yaxis{sfx}"] = {"domain": [max(0.0, round(top - h, 9)), min(1.0, round(top, 9))], "anchor": f"x{sfx}"}
        layout[f"xaxis{sfx}"] = {"anchor": f"y{sfx}", "showticklabels": r == n_rows - 1,
                                 **({} if r == 0 else {"matches": "x"})}
        title, unit, _ = TIME_ROWS[r]
        notes.append({"text": f"{title} [{unit}]", "x": 0.5, "y": top, "xref": "paper", "yref": "paper",
                      "xanchor": "center", "yanchor": "bottom", "showarrow": False, "font": {"size": FONT_PX}})
    layout[f"xaxis{'' if n_rows == 1 else n_rows}"]["title"] = {"text": "t [s]"}
    return layout, notes


def time_plots_spec(comparison: Comparison, rows: tuple[int, ...] | None = None,
                    n_bins: int = BINS_TIME_PLOTS) -> dict[str, Any]:
    """Time plots as a plain-dict figure (see :func:`make_time_plots_figure`); ``rows`` picks rows of TIME_ROWS."""
    rows = tuple(range(len(TIME_ROWS))) if rows is None else rows
    data: list[dict[str, Any]] = []
    t_end = 0.0
    for key, run in runs(comparison):
        tr = run.trace
        t_end = max(t_end, float(tr.t[-1]))
        for pos, row in enumerate(rows, start=1):
            _, unit, signals = TIME_ROWS[row]
            for attr, label, dash in signals:
                t, y = envelope(tr.t, getattr(tr, attr), n_bins)  # chatter stays a band
                data.append({"type": "scatter", **t, "y": f32(y), "mode": "lines",
                             "name": f"{label} {LABELS[key]}", "legendgroup": key,
                             "line": {"color": COLOURS[key], "width": 1.6, "dash": dash},
                             "hovertemplate": f"%{{y:.4g}} {unit}", "xaxis": f"x{'' if pos == 1 else pos}",
                             "yaxis": f"y{'' if pos == 1 else pos}"})
    refs = _references(comparison, t_end)
    data += [refs[rows.index(r)] | {"yaxis": f"y{'' if rows.index(r) == 0 else rows.index(r) + 1}"}
             for r in (0, 1) if r in rows]
    axes, notes = _time_axes(len(rows))
    shapes = [{"type": "line", "xref": "x", "yref": "paper", "x0": t, "x1": t, "y0": 0.0, "y1": 1.0,
                "line": {"color": BAD_COLOUR, "width": 2, "dash": "dot"}} for t in load_step_times(comparison)]
    notes += [{"text": f"load step {t:.3g} s", "x": t, "y": 1.0, "xref": "x", "yref": "paper",
               "showarrow": False, "font": {"color": WARNING_COLOUR, "size": FONT_PX}, "xanchor": "left",
               "yanchor": "top"}
              for t in load_step_times(comparison)]
    return {"data": data, "layout": {
        **axes, "annotations": notes, "shapes": shapes, "meta": {"id": "time_plots"}, "template": "plotly_white",
        "hovermode": "x unified", "margin": {"l": 60, "r": 16, "t": 30, "b": 40},
        "legend": {"orientation": "h", "y": -0.04, "x": 0.0}, "font": {"size": FONT_PX}}}


def make_time_plots_figure(comparison: Comparison) -> go.Figure:
    """Time plots of both controllers: θ_r/θ_dem, ω_r/ω_p, i_d/i_q, u_d/u_q, α/α_dem, Γ_L/Γ̂_L.

    Dotted vertical lines (``layout.shapes``) mark the load steps.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return to_figure(time_plots_spec(comparison))


def cursor_index(t: np.ndarray, t_now: float) -> int:
    """Index of the last sample at or before ``t_now`` [s] (0 before the start)."""
    return max(int(np.searchsorted(t, t_now, side="right")) - 1, 0)


__all__ = [
    "COLOURS", "DASHES", "LABELS", "MAX_POINTS", "TIME_ROWS", "boundary_xy", "cursor_index", "decimate_index",
    "stride_index", "layer_entry_index", "load_step_times", "make_phase_plane_figure",
    "make_time_plots_figure",
    "phase_plane_extent", "phase_plane_spec", "runs", "time_plots_spec",
]
