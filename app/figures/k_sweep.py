"""The K sweep: a grid of K values, each FDSMC run drawn as one Plotly frame under the figure's own slider.

The K demo's live path (the panel's K slider → a run on the server → a new figure) redraws about
ten times a second: viser sends a slider's value at most every 50 ms, and the server's run and the
page's redraw follow each other in series. Here the runs are done beforehand, for a grid of K
values (:func:`k_grid`: log-spaced over the K slider's range, with K_limit·(1 ± 1 %), K_recommended,
K_noise and the K in force as grid points), and the figure carries them as inline frames of a
Plotly slider (``layout.sliders``): dragging it calls ``Plotly.animate`` with the frame of that K
and ``redraw: false`` in the browser — no server round trip, so the figure follows the pointer at
the display's frame rate.

Per frame only what K changes: the layer ±1/K (eq. (45) in [1]), the FDSMC trajectory in the phase
plane, its ω_r and motor torque Γ against t, and the verdict of that very run
(:func:`app.figures.fdsmc_verdict.chatter_verdict`) as a text trace in the phase plane's own axes
(a layout annotation would need ``redraw: true``; a hidden overlaid axis of its own was one more
subplot for Plotly to lay out and draw at every frame). The axes hold every run of the grid, so
nothing rescales while dragging, and the verdict stays where it was put. Frames are written as
text with 4 significant digits (:func:`_frame_json`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import html
import json
import math
from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.decimate import envelope, minmax_index
from pmsm_commissioning.app.figures.fdsmc_comparison import BAND_COLOUR, BOUNDARY_COLOUR, COLOURS, phase_plane_extent
from pmsm_commissioning.app.figures.fdsmc_overview import REF_LINE, motor_torque
from pmsm_commissioning.app.figures.fdsmc_verdict import DETAIL_FONT_PX, VERDICT_FONT_PX, chatter_verdict
from pmsm_commissioning.app.figures.style import BAD_COLOUR, FONT_PX, GOOD_COLOUR, TITLE_PX
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.control.fdsmc.sliding_mode import boundary_speed

#: Log-spaced points of the grid over the slider's range (the marked gains are added to them).
N_LOG = 26
#: Bins of the decimated trajectory (phase plane) and of the time rows (two points each).
BINS_SWEEP_PHASE, BINS_SWEEP_ROWS = 200, 150
#: Indices of the traces a frame changes: layer, trajectory, ω_r, Γ, verdict.
DYNAMIC = (0, 2, 3, 4, 7)
#: ``Plotly.animate`` options of a slider step: the frame at once, no transition, no full redraw.
STEP_ANIMATE = {"mode": "immediate", "frame": {"duration": 0, "redraw": False}, "transition": {"duration": 0}}
PHASE_X, TIME_X, ROW_Y = (0.0, 0.55), (0.66, 1.0), ((0.56, 1.0), (0.0, 0.44))


def k_grid(lo: float, hi: float, K: float, K_limit: float, K_rec: float | None,
           K_noise: float = math.inf) -> tuple[float, ...]:
    """Return the sweep's K values [s/rad], increasing: :data:`N_LOG` log-spaced from 10^lo to 10^hi and the gains.

    The gains are K (the one in force), K_limit·0.99 and K_limit·1.01 (either side of the chatter
    limit), K_recommended and K_noise (where below K_limit); values closer than 0.5 % to one
    already in the grid are dropped.
    """
    values = list(np.logspace(lo, hi, N_LOG))
    marked = [K, 0.99 * K_limit, 1.01 * K_limit, K_rec, K_noise if K_noise < K_limit else None]
    for v in marked:
        if v is not None and math.isfinite(v) and v > 0.0:
            values.append(float(v))
    out: list[float] = []
    for v in sorted(values):
        if not out or v > out[-1] * 1.005:
            out.append(float(f"{v:.4g}"))
    if K > 0.0 and float(f"{K:.4g}") not in out:  # the K in force is always a step, exactly
        out = sorted({*out, float(f"{K:.4g}")})
    return tuple(out)


def _nums(a: Any) -> str:
    return "[" + ",".join(f"{v:.4g}" for v in np.asarray(a, dtype=float).tolist()) + "]"


def _band(x: np.ndarray, y: np.ndarray, K: float) -> tuple[np.ndarray, np.ndarray]:
    half = 1.0 / K
    return np.concatenate([x, x[::-1]]), np.concatenate([y + half, (y - half)[::-1]])


def _verdict_text(comparison: Any, plant_J_L: float | None) -> tuple[str, str]:
    v = chatter_verdict(comparison, plant_J_L)
    K = comparison.derived.params.controller.K
    if v is None:
        return f"K = {K:.3g} s/rad: not simulated", BAD_COLOUR
    icon = "✗" if v.chatter else "✓"
    return (f"<b>{icon} {html.escape(v.headline)}</b><br><span style=\"font-size:{DETAIL_FONT_PX}px\">"
            f"K = {K:.3g} s/rad · {html.escape(v.detail)}</span>", BAD_COLOUR if v.chatter else GOOD_COLOUR)


def _frame_json(comparison: Any, boundary: tuple[np.ndarray, np.ndarray], plant_J_L: float | None) -> str:
    """One frame: the layer, the trajectory, ω_r, Γ and the verdict of one K's run (JSON text)."""
    d, run = comparison.derived, comparison.fdsmc
    tr = run.trace
    i = minmax_index(tr.omega_r, BINS_SWEEP_PHASE)
    _, band_y = _band(*boundary, d.params.controller.K)
    _, w = envelope(tr.t, tr.omega_r, BINS_SWEEP_ROWS)
    _, g = envelope(tr.t, motor_torque(d.params.motor, tr.i_d, tr.i_q), BINS_SWEEP_ROWS)
    text, colour = _verdict_text(comparison, plant_J_L)
    x = tr.theta_r[i] - d.params.manoeuvre.theta_dem
    parts = [f'{{"y":{_nums(band_y)}}}', f'{{"x":{_nums(x)},"y":{_nums(tr.omega_r[i])}}}',
             f'{{"y":{_nums(w)}}}', f'{{"y":{_nums(g)}}}',
             f'{{"text":[{_json_str(text)}],"textfont":{{"color":"{colour}","size":{VERDICT_FONT_PX}}}}}']
    return f'{{"data":[{",".join(parts)}],"traces":[{",".join(map(str, DYNAMIC))}]}}'


def _json_str(s: str) -> str:
    return json.dumps(s, ensure_ascii=False)


def _extent(points: list[Any]) -> tuple[list[float], list[float], list[float], list[float]]:
    """Axis ranges holding every run of the grid: θ_re, ω_r (phase plane), ω_r and Γ (rows)."""
    lo = min(phase_plane_extent(c)[0] for c in points)
    hi = max(phase_plane_extent(c)[1] for c in points)
    w = [min(float(np.min(c.fdsmc.trace.omega_r)) for c in points),
         max(float(np.max(c.fdsmc.trace.omega_r)) for c in points)]
    w_p = points[0].derived.profile.omega_p
    w = [min(w[0], -w_p), max(w[1], w_p)]
    g_max = torque_limit(points[0].derived.params)
    g = [-1.05 * g_max, 1.05 * g_max]
    for c in points:
        tr = c.fdsmc.trace
        gam = motor_torque(c.derived.params.motor, tr.i_d, tr.i_q)
        g = [min(g[0], float(np.min(gam))), max(g[1], float(np.max(gam)))]
    pad = 0.06 * (w[1] - w[0])
    return [lo, hi], [w[0] - pad, w[1] + pad], [w[0] - pad, w[1] + pad], g


def _step_label(K: float) -> str:
    """Return a step's label on the slider: K [s/rad] in two significant digits ("0.3", "1000").

    Plotly labels every n-th step only, n set by the widest label; short labels keep n at 2.
    """
    return f"{K:.0f}" if K >= 100.0 else f"{K:.2g}"


def _static_traces(points: list[Any], active: Any, boundary: tuple[np.ndarray, np.ndarray],
                   ranges: tuple[list[float], list[float]]) -> list[dict[str, Any]]:
    """Return the figure's traces as they show the ``active`` run (the frames change :data:`DYNAMIC` of them).

    ``ranges`` are the phase plane's fixed θ_re [rad] and ω_r [rad/s] ranges: the verdict stands in
    their empty half.
    """
    d = active.derived
    bx, by = _band(*boundary, d.params.controller.K)
    tr = active.fdsmc.trace
    i = minmax_index(tr.omega_r, BINS_SWEEP_PHASE)
    t_w, w = envelope(tr.t, tr.omega_r, BINS_SWEEP_ROWS)
    t_g, g = envelope(tr.t, motor_torque(d.params.motor, tr.i_d, tr.i_q), BINS_SWEEP_ROWS)
    text, colour = _verdict_text(active, None)
    t_end, w_p, g_max = float(tr.t[-1]), d.profile.omega_p, torque_limit(d.params)
    sign = 1.0 if d.params.manoeuvre.theta_dem >= 0 else -1.0
    line = {"type": "scatter", "mode": "lines", "hoverinfo": "skip", "showlegend": False}
    fd = {"color": COLOURS["fdsmc"], "width": 1.8}
    return [
        {**line, "x": bx.tolist(), "y": by.tolist(), "fill": "toself", "fillcolor": BAND_COLOUR,
         "line": {"width": 0}, "name": "layer ±1/K, eq. (45)"},
        {**line, "x": boundary[0].tolist(), "y": boundary[1].tolist(), "name": "switching boundary, eq. (41)",
         "line": {"color": BOUNDARY_COLOUR, "width": 2, "dash": "dash"}},
        {**line, "x": (tr.theta_r[i] - d.params.manoeuvre.theta_dem).tolist(), "y": tr.omega_r[i].tolist(),
         "name": "FDSMC trajectory", "line": fd},
        {**line, **t_w, "y": w.tolist(), "name": "ω_r FDSMC", "xaxis": "x2", "yaxis": "y2", "line": fd},
        {**line, **t_g, "y": g.tolist(), "name": "Γ FDSMC", "xaxis": "x3", "yaxis": "y3", "line": fd},
        {**line, "x": [0.0, t_end], "y": [sign * w_p] * 2, "name": "ω_p", "xaxis": "x2", "yaxis": "y2",
         "line": REF_LINE},
        {**line, "x": [0.0, t_end, None, 0.0, t_end], "y": [g_max, g_max, None, -g_max, -g_max],
         "name": "±Γ_max", "xaxis": "x3", "yaxis": "y3", "line": REF_LINE},
        # in the phase plane's empty half (below the cruise for a positive move): not on the trajectory
        {"type": "scatter", "mode": "text", "x": [_at(ranges[0], 0.5)], "y": [_at(ranges[1], 0.3 if sign > 0 else 0.7)],
         "text": [text], "textposition": "middle center", "cliponaxis": False,
         "textfont": {"color": colour, "size": VERDICT_FONT_PX},
         "hoverinfo": "skip", "showlegend": False, "name": "verdict"},
    ]


def _at(span: list[float], share: float) -> float:
    """Return the point ``share`` of the way along the axis range ``span``."""
    return span[0] + share * (span[1] - span[0])


def _layout(points: list[Any], t_end: float) -> dict[str, Any]:
    """Axes of the phase plane (left) and of the ω_r and Γ rows (right)."""
    x_r, y_r, w_r, g_r = _extent(points)
    return {
        "xaxis": {"domain": list(PHASE_X), "range": x_r, "title": {"text": "θ_re = θ_r − θ_rdem [rad]"}},
        "yaxis": {"range": y_r, "title": {"text": "ω_r [rad/s]"}},
        "xaxis2": {"domain": list(TIME_X), "anchor": "y2", "range": [0.0, t_end], "showticklabels": False},
        "yaxis2": {"domain": list(ROW_Y[0]), "anchor": "x2", "range": w_r, "title": {"text": "ω_r [rad/s]"}},
        "xaxis3": {"domain": list(TIME_X), "anchor": "y3", "range": [0.0, t_end], "matches": "x2",
                   "title": {"text": "t [s]", "standoff": 4}},
        "yaxis3": {"domain": list(ROW_Y[1]), "anchor": "x3", "range": g_r, "title": {"text": "Γ [N·m]"}},
    }


def k_sweep_spec(points: list[Any], K_now: float, marks: dict[str, float],
                 plant_J_L: float | None = None) -> tuple[dict[str, Any], dict[str, str]]:
    """Build the K-sweep figure: one frame per run of ``points`` under the figure's own slider.

    Parameters
    ----------
    points : list of sim.fdsmc.engine.Comparison
        One comparison per K of the grid (increasing K), each with its FDSMC run.
    K_now : float
        The K in force [s/rad]: the slider starts at its step.
    marks : dict
        Label → gain [s/rad] of the marked gains (``{"lim": K_limit, "rec": K_rec}``), kept in ``meta.marks``.
    plant_J_L : float or None
        The plant's load inertia [kg·m²] when it differs from the controller's model.

    Returns
    -------
    (dict, dict)
        The plain-dict figure (``layout.meta.id`` ``"k_sweep"``, ``meta.K`` the grid) and the
        placeholder → frame JSON map for :func:`app.figures.plain.figure_json`.
    """
    Ks = [c.derived.params.controller.K for c in points]
    active = int(np.argmin([abs(math.log(K / K_now)) for K in Ks]))
    d = points[active].derived
    x_r, y_r = _extent(points)[:2]
    knee = d.profile.T_c * d.profile.omega_p
    bx = np.unique(np.array([x_r[0], -knee, 0.0, knee, x_r[1]]))
    boundary = (bx, boundary_speed(bx, d.profile.omega_p, d.profile.T_c))
    data = _static_traces(points, points[active], boundary, (x_r, y_r))
    if plant_J_L is not None:  # the active frame's verdict says so too
        data[7]["text"] = [_verdict_text(points[active], plant_J_L)[0]]
    raw = {f"__k_frame_{k}__": "[" + _frame_json(c, boundary, plant_J_L) + "]" for k, c in enumerate(points)}
    steps = [{"label": _step_label(K), "value": f"{K:.4g}", "method": "animate",
              "execute": False, "args": [f"__k_frame_{k}__", STEP_ANIMATE]} for k, K in enumerate(Ks)]
    layout = {**_layout(points, float(points[active].fdsmc.trace.t[-1])),
              "meta": {"id": "k_sweep", "K": Ks, "marks": marks}, "template": "plotly_white", "showlegend": False,
              "title": {"text": f"K sweep: {len(Ks)} runs, drag the slider (in the browser)",
                        "font": {"size": TITLE_PX}, "x": 0.01},
              "margin": {"l": 60, "r": 16, "t": 48, "b": 110},
              "sliders": [{"active": active, "steps": steps, "x": 0.0, "len": 0.96, "y": 0.0, "yanchor": "top",
                           "pad": {"t": 56, "b": 4}, "currentvalue": {"visible": False},
                           "font": {"size": FONT_PX}, "transition": {"duration": 0}}]}
    return {"data": data, "layout": layout}, raw


__all__ = ["DYNAMIC", "N_LOG", "STEP_ANIMATE", "k_grid", "k_sweep_spec"]
