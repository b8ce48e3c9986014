"""The sliding region zoomed: an inset of the phase plane around the FDSMC's constant-speed segment.

At the phase plane's own scale the boundary layer ±1/K (eq. (45) in [1]) and a chatter of a few
rad/s are about ten pixels tall. The inset (own axes ``x4``/``y5``, in the empty lower middle of
the phase plane) shows a short stretch of the cruise, where the FDSMC slides on — or chatters about
— ω_r = ω_p: the layer, the switching boundary of eq. (41) and the FDSMC's samples there at full
resolution. The window (:func:`zoom_window`) is chosen from the run, so it always holds the
layer and the run's excursions from it; a grey bracket under the path on the phase plane marks where it is.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.decimate import f32, minmax_index
from pmsm_commissioning.app.figures.fdsmc_comparison import BOUNDARY_COLOUR
from pmsm_commissioning.app.figures.style import FONT_PX, POSITION_COLOURS

#: Inset domain in the figure [paper]: x within the phase plane's, y from its bottom.
INSET_X, INSET_Y = (0.13, 0.40), (0.07, 0.40)
#: Share of the cruise samples the window spans [-], the least half-height in layer widths, and
#: the headroom over the largest excursion [-].
WINDOW_SHARE, LAYERS_SHOWN, HEADROOM = 0.08, 4.0, 1.3
#: Most samples of the trajectory drawn in the inset.
INSET_BINS = 300
ZOOM_COLOUR = "#495057"


def zoom_window(theta_re: np.ndarray, omega_r: np.ndarray, omega_p: float, knee: float,
                K: float) -> tuple[float, float, float, float] | None:
    """Return the inset's window (θ_lo, θ_hi [rad], ω_lo, ω_hi [rad/s]) or None without a cruise.

    The window spans :data:`WINDOW_SHARE` of the cruise samples (|θ_re| beyond the knee T_c·ω_p
    of eq. (41) and ω_r within 10 % of ±ω_p) around their middle, and in speed ±ω_p ± the larger
    of :data:`LAYERS_SHOWN` layer half-widths 1/K and :data:`HEADROOM` × the largest excursion there.
    """
    theta_re, omega_r = np.asarray(theta_re, dtype=float), np.asarray(omega_r, dtype=float)
    sign = 1.0 if np.mean(omega_r) >= 0.0 else -1.0
    cruise = np.flatnonzero((np.abs(theta_re) > knee) & (np.abs(omega_r - sign * omega_p) < 0.1 * omega_p))
    if cruise.size < 20:
        return None
    mid, half = cruise.size // 2, max(5, int(WINDOW_SHARE * cruise.size / 2))
    window = cruise[max(0, mid - half):mid + half]
    excursion = float(np.max(np.abs(omega_r[window] - sign * omega_p)))
    dy = max(LAYERS_SHOWN / K, HEADROOM * excursion)
    return (float(theta_re[window].min()), float(theta_re[window].max()),
            sign * omega_p - dy, sign * omega_p + dy)


def zoom_parts(comparison: Any) -> tuple[list[dict[str, Any]], dict[str, Any], list[dict[str, Any]],
                                         list[dict[str, Any]]] | None:
    """Inset traces, its axes, shapes (ground, marking bracket) and title for ``comparison``'s FDSMC run.

    None without a cruise. For a move to a negative θ_dem the inset sits in the upper half (the
    lower one holds the trajectory).
    """
    run, d = comparison.fdsmc, comparison.derived
    if run is None:
        return None
    prof, K, th = d.profile, d.params.controller.K, d.params.manoeuvre.theta_dem
    x_all, y_all = run.trace.theta_r - th, run.trace.omega_r
    win = zoom_window(x_all, y_all, prof.omega_p, prof.T_c * prof.omega_p, K)
    if win is None:
        return None
    x0, x1, y0, y1 = win
    inside = np.flatnonzero((x_all >= x0) & (x_all <= x1))
    i = inside[minmax_index(y_all[inside], INSET_BINS)]
    w_b = float(np.sign(y0 + y1) * prof.omega_p)  # the boundary is flat here: ω_b = ±ω_p
    axes = {"xaxis": "x4", "yaxis": "y5", "hoverinfo": "skip", "showlegend": False}
    traces = [
        {"type": "scatter", "x": [x0, x1, x1, x0], "y": [w_b + 1 / K, w_b + 1 / K, w_b - 1 / K, w_b - 1 / K],
         "fill": "toself", "fillcolor": "rgba(120, 120, 120, 0.25)", "line": {"width": 0}, "mode": "lines",
         "name": "zoom: boundary layer", **axes},
        {"type": "scatter", "x": [x0, x1], "y": [w_b, w_b], "mode": "lines", "name": "zoom: boundary",
         "line": {"color": BOUNDARY_COLOUR, "width": 1.5, "dash": "dash"}, **axes},
        {"type": "scatter", "x": f32(x_all[i]), "y": f32(y_all[i]), "mode": "lines", "name": "zoom: FDSMC",
         "line": {"color": POSITION_COLOURS["fdsmc"], "width": 1.5}, **axes},
    ]
    return traces, *_inset_frame((x0, x1, y0, y1), th >= 0, K)


def _inset_frame(win: tuple[float, float, float, float], upward: bool,
                 K: float) -> tuple[dict[str, Any], list[dict[str, Any]], list[dict[str, Any]]]:
    """Return the inset's axes over window ``win``, its white ground, the bracket marking it, and its title."""
    x0, x1, y0, y1 = win
    frame = {"showgrid": False, "zeroline": False, "mirror": True, "showline": True, "linecolor": ZOOM_COLOUR,
             "tickfont": {"size": FONT_PX}}
    y_dom = INSET_Y if upward else (1.0 - INSET_Y[1] - 0.1, 1.0 - INSET_Y[0] - 0.1)
    layout = {"xaxis4": {**frame, "domain": list(INSET_X), "anchor": "y5", "range": [x0, x1], "nticks": 3},
              "yaxis5": {**frame, "domain": list(y_dom), "anchor": "x4", "range": [y0, y1], "nticks": 4}}
    # the window marked in the phase plane by a bracket under the path (its sides up to the path's
    # middle), not a box around it: the replay's time label, above the moving marker, would sit on
    # a box's top edge while the marker crosses it
    w_mid = 0.5 * (y0 + y1)
    bracket = {"type": "path", "xref": "x", "yref": "y", "path": f"M{x0},{w_mid} L{x0},{y0} L{x1},{y0} L{x1},{w_mid}",
               "line": {"color": ZOOM_COLOUR, "width": 1.5}, "name": "zoom window"}
    # the inset's own white ground, under its traces, over the phase plane's grid
    ground = {"type": "rect", "xref": "x4", "yref": "y5", "x0": x0, "x1": x1, "y0": y0, "y1": y1, "layer": "below",
              "fillcolor": "white", "line": {"width": 0}}
    title = {"text": f"zoom: sliding region, layer ±1/K = ±{1 / K:.3g} rad/s", "x": INSET_X[0],
             "y": y_dom[1], "xref": "paper", "yref": "paper", "xanchor": "left", "yanchor": "bottom",
             "showarrow": False, "font": {"size": FONT_PX, "color": ZOOM_COLOUR}, "bgcolor": "rgba(255,255,255,0.8)"}
    return layout, [ground, bracket], [title]


__all__ = ["INSET_X", "INSET_Y", "zoom_parts", "zoom_window"]
