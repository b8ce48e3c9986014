"""Pure Plotly figures of one comparison: the phase plane and the time plots.

Every ``make_*_figure`` function takes results and returns a new :class:`plotly.graph_objects.Figure`;
nothing here touches the GUI. Each figure carries ``layout.meta = {"id": …}`` so that the page
(and the browser tests) can tell the figures apart. Long traces are decimated to at most
:data:`MAX_POINTS` points per trace for drawing.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from control.sliding_mode import boundary_speed

#: Most points drawn per trace.
MAX_POINTS = 2000
#: Most points per trace in the (24-trace) time plots.
MAX_POINTS_TIME = 1500
#: Line colours per controller.
COLOURS = {"fdsmc": "#1f6fd1", "conventional": "#e8590c"}
LABELS = {"fdsmc": "FDSMC", "conventional": "Conventional"}
BOUNDARY_COLOUR = "#2b2b2b"
BAND_COLOUR = "rgba(120, 120, 120, 0.18)"
_MARGIN = {"l": 60, "r": 16, "t": 40, "b": 44}


def decimate_index(n: int, n_max: int = MAX_POINTS) -> np.ndarray:
    """Indices of at most ``n_max`` evenly spread samples of ``n``, always keeping the last one."""
    if n <= n_max:
        return np.arange(n)
    idx = np.linspace(0, n - 1, n_max).round().astype(int)
    return np.unique(idx)


def f32(a: np.ndarray) -> np.ndarray:
    """``a`` as float32: halves the figure JSON (base64 typed arrays) at ample drawing precision."""
    return np.asarray(a, dtype=np.float32)


def runs(comparison: Any) -> list[tuple[str, Any]]:
    """``(key, RunResult)`` of the controllers present in a comparison, FDSMC first."""
    return [
        (key, getattr(comparison, key)) for key in ("fdsmc", "conventional")
        if getattr(comparison, key, None) is not None
    ]


def phase_plane_extent(comparison: Any) -> tuple[float, float]:
    """θ_re range [rad] covering the manoeuvre and the trajectories, with a margin."""
    d = comparison.derived
    dth = d.params.manoeuvre.theta_dem
    lo, hi = min(-dth, 0.0), max(-dth, 0.0)
    for _, run in runs(comparison):
        theta_re = run.trace.theta_r - dth
        lo, hi = min(lo, float(np.min(theta_re))), max(hi, float(np.max(theta_re)))
    pad = 0.06 * (hi - lo)
    return lo - pad, hi + pad


def boundary_xy(comparison: Any, n: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """The switching boundary of eq. (41) in [1] over the phase-plane extent: (θ_re [rad], ω_r [rad/s])."""
    lo, hi = phase_plane_extent(comparison)
    prof = comparison.derived.profile
    knee = prof.T_c * prof.omega_p
    x = np.unique(np.concatenate([np.linspace(lo, hi, n), [-knee, 0.0, knee]]))
    return x, boundary_speed(x, prof.omega_p, prof.T_c)


def _phase_static_traces(comparison: Any) -> list[go.Scatter]:
    x, y = boundary_xy(comparison)
    half = 1.0 / comparison.derived.params.controller.K
    return [
        go.Scatter(x=np.concatenate([x, x[::-1]]), y=np.concatenate([y + half, (y - half)[::-1]]),
                   fill="toself", fillcolor=BAND_COLOUR, line={"width": 0}, hoverinfo="skip",
                   name=f"Boundary layer ±1/K = ±{half:.3g} rad/s, eq. (45)"),
        go.Scatter(x=x, y=y, mode="lines", line={"color": BOUNDARY_COLOUR, "width": 2, "dash": "dash"},
                   name="Switching boundary, eq. (41)"),
    ]


def make_phase_plane_figure(comparison: Any, t_now: float | None = None) -> go.Figure:
    """Phase plane θ_re–ω_r: boundary (41), band ±1/K (45), both trajectories and live markers.

    Per controller three traces, in this order (relied on by the replay): the whole trajectory
    (``"<name> trajectory"``, faint while replaying), the part drawn so far (``"<name> so far"``)
    and the marker at ``t_now`` (``"<name> now"``).

    Parameters
    ----------
    comparison : sim.engine.Comparison
        ``derived`` gives ω_p [rad/s], T_c [s] and K [s/rad]; ``fdsmc``/``conventional`` may be None
        (then only the boundary is drawn).
    t_now : float or None
        Replay time [s]; None draws the whole trajectories with the markers at the end.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    d = comparison.derived
    fig = go.Figure(_phase_static_traces(comparison))
    for key, run in runs(comparison):
        tr = run.trace
        i = decimate_index(len(tr.t))
        t, x, y = tr.t[i], f32(tr.theta_r[i] - d.params.manoeuvre.theta_dem), f32(tr.omega_r[i])
        k = len(t) - 1 if t_now is None else cursor_index(t, t_now)
        colour, label = COLOURS[key], LABELS[key]
        fig.add_scatter(x=x, y=y, mode="lines", name=f"{label} trajectory", customdata=f32(t),
                        line={"color": colour, "width": 1.5}, opacity=1.0 if t_now is None else 0.3,
                        hovertemplate="t = %{customdata:.4f} s<br>θ_re = %{x:.4g} rad<br>"
                                      "ω_r = %{y:.4g} rad/s<extra>" + label + "</extra>")
        fig.add_scatter(x=x[: k + 1], y=y[: k + 1], mode="lines", name=f"{label} so far",
                        line={"color": colour, "width": 3}, hoverinfo="skip", showlegend=False)
        fig.add_scatter(x=x[k: k + 1], y=y[k: k + 1], mode="markers", name=f"{label} now",
                        marker={"color": colour, "size": 14, "line": {"color": "white", "width": 2}},
                        hoverinfo="skip", showlegend=False)
    prof = d.profile
    lo, hi = phase_plane_extent(comparison)
    fig.update_layout(
        meta={"id": "phase_plane", "omega_p": prof.omega_p, "T_c": prof.T_c},
        title={"text": f"Phase plane — ω_p = {prof.omega_p:.4g} rad/s, T_c = {prof.T_c:.4g} s",
               "x": 0.01},
        xaxis={"title": "θ_re = θ_r − θ_rdem [rad]", "range": [lo, hi], "zeroline": True},
        yaxis={"title": "ω_r [rad/s]", "zeroline": True},
        legend={"orientation": "h", "y": -0.12, "x": 0.0},
        margin=_MARGIN, template="plotly_white", hovermode="closest",
    )
    return fig


#: Time-plot rows: (title, unit, [(trace attribute or None, label, dash)]).
TIME_ROWS: tuple[tuple[str, str, tuple[tuple[str, str, str], ...]], ...] = (
    ("Position", "rad", (("theta_r", "θ_r", "solid"),)),
    ("Speed", "rad/s", (("omega_r", "ω_r", "solid"),)),
    ("Currents", "A", (("i_d", "i_d", "dot"), ("i_q", "i_q", "solid"))),
    ("Voltages", "V", (("u_d", "u_d", "dot"), ("u_q", "u_q", "solid"))),
    ("Acceleration", "rad/s²", (("alpha", "α", "solid"), ("alpha_dem", "α_dem", "dot"))),
    ("Load torque", "N·m", (("Gamma_L", "Γ_L", "solid"), ("Gamma_L_hat", "Γ̂_L", "dot"))),
)


def _add_references(fig: go.Figure, comparison: Any, t_end: float) -> None:
    d = comparison.derived
    th, wp = d.params.manoeuvre.theta_dem, d.profile.omega_p
    grey = {"color": "#555", "width": 1.5, "dash": "dash"}
    fig.add_scatter(x=[0.0, t_end], y=[th, th], mode="lines", line=grey, name="θ_dem", row=1, col=1)
    sign = 1.0 if th >= 0 else -1.0
    fig.add_scatter(x=[0.0, t_end], y=[sign * wp, sign * wp], mode="lines", line=grey,
                    name="ω_p, eq. (60)", row=2, col=1)


def make_time_plots_figure(comparison: Any) -> go.Figure:
    """Time plots of both controllers: θ_r/θ_dem, ω_r/ω_p, i_d/i_q, u_d/u_q, α/α_dem, Γ_L/Γ̂_L.

    A vertical cursor (``layout.shapes[0]``) marks the replay time; it starts at t = 0.

    Parameters
    ----------
    comparison : sim.engine.Comparison

    Returns
    -------
    plotly.graph_objects.Figure
    """
    fig = make_subplots(rows=len(TIME_ROWS), cols=1, shared_xaxes=True, vertical_spacing=0.025,
                        subplot_titles=[f"{t} [{u}]" for t, u, _ in TIME_ROWS])
    t_end = 0.0
    for key, run in runs(comparison):
        tr = run.trace
        i = decimate_index(len(tr.t), MAX_POINTS_TIME)
        t_end = max(t_end, float(tr.t[-1]))
        for row, (_, unit, signals) in enumerate(TIME_ROWS, start=1):
            for attr, label, dash in signals:
                fig.add_scatter(x=f32(tr.t[i]), y=f32(getattr(tr, attr)[i]), mode="lines",
                                name=f"{label} {LABELS[key]}", legendgroup=key,
                                line={"color": COLOURS[key], "width": 1.6, "dash": dash},
                                hovertemplate=f"%{{y:.4g}} {unit}", row=row, col=1)
    _add_references(fig, comparison, t_end)
    fig.add_shape(type="line", xref="x", yref="paper", x0=0.0, x1=0.0, y0=0.0, y1=1.0,
                  line={"color": "#c92a2a", "width": 1.5})
    fig.update_xaxes(title_text="t [s]", row=len(TIME_ROWS), col=1)
    fig.update_layout(meta={"id": "time_plots"}, template="plotly_white", hovermode="x unified",
                      margin={"l": 60, "r": 16, "t": 30, "b": 40},
                      legend={"orientation": "h", "y": -0.04, "x": 0.0}, font={"size": 11})
    return fig


def cursor_index(t: np.ndarray, t_now: float) -> int:
    """Index of the last sample at or before ``t_now`` [s] (0 before the start)."""
    return max(int(np.searchsorted(t, t_now, side="right")) - 1, 0)


__all__ = [
    "COLOURS", "LABELS", "MAX_POINTS", "TIME_ROWS", "boundary_xy", "cursor_index", "decimate_index",
    "make_phase_plane_figure", "make_time_plots_figure", "phase_plane_extent", "runs",
]
