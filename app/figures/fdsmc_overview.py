"""The overview figure: phase plane and a compact time plot (ω_r and Γ vs t) in ONE Plotly figure.

One figure, so that each in-browser replay frame (:mod:`app.figures.fdsmc_replay`) moves the phase-plane
markers *and* the time cursors together, with no server traffic per frame. The phase plane keeps
its trace names and order (:func:`app.figures.fdsmc_comparison.phase_plane_spec`); the compact time plot
adds, per controller, ω_r [rad/s] and the motor torque Γ [N·m] (eq. (5) in [1]), the true load
torque Γ_L dotted, the references ω_p and ±Γ_max dashed, the load steps as red dotted lines, and
one ``"time cursor …"`` trace per row that the replay moves.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.decimate import BINS_OVERVIEW_ROWS, envelope, f32
from pmsm_commissioning.app.figures.fdsmc_comparison import (
    COLOURS,
    DASHES,
    LABELS,
    load_step_times,
    phase_plane_spec,
    runs,
)
from pmsm_commissioning.app.figures.fdsmc_pins import Pin, ghost_traces
from pmsm_commissioning.app.figures.fdsmc_trail import piece_traces, pieces
from pmsm_commissioning.app.figures.fdsmc_verdict import chatter_verdict, verdict_annotation
from pmsm_commissioning.app.figures.fdsmc_zoom import zoom_parts
from pmsm_commissioning.app.figures.style import BAD_COLOUR, FONT_PX, TITLE_PX
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.control.fdsmc.model import electromagnetic_torque

#: Horizontal domains [-] of the phase plane and of the compact time plot.
#: The time rows end short of the right edge: the Γ_L axis's red tick labels stand outside its plot
#: area there (inside, they sat on the blue band of a chattering Γ).
PHASE_X, TIME_X = (0.0, 0.55), (0.66, 0.95)
#: Vertical domains [-] of the two time rows: ω_r on top, Γ below.
ROW_Y = ((0.56, 1.0), (0.0, 0.44))
#: Names of the two cursor traces the replay moves (one per time row).
CURSORS = ("time cursor ω_r", "time cursor Γ")
LOAD_STEP_COLOUR = BAD_COLOUR
REF_LINE = {"color": "#555", "width": 1.2, "dash": "dash"}


def motor_torque(motor: Any, i_d: np.ndarray, i_q: np.ndarray) -> np.ndarray:
    """Electromagnetic torque Γ of eq. (5) in [1] [N·m] (:func:`control.fdsmc.model.electromagnetic_torque`)."""
    return electromagnetic_torque(motor.p, motor.psi_pm, motor.L_d, motor.L_q, i_d, i_q)


def _padded(lo: float, hi: float, pad: float = 0.08) -> list[float]:
    span = hi - lo if hi > lo else max(abs(hi), 1.0)
    return [lo - pad * span, hi + pad * span]


def _row_traces(comparison: Any) -> tuple[list[dict[str, Any]], list[list[float]], float]:
    """ω_r, Γ and Γ_L traces of both controllers, the y ranges (ω_r, Γ, Γ_L's own axis) and t_end [s].

    Γ_L has its own axis (``y4``, right, over the Γ row): a load step of a few N·m stays visible
    next to a chattering Γ on a ±Γ_max scale.
    """
    d = comparison.derived
    motor, g_max, w_p = d.params.motor, torque_limit(d.params), d.profile.omega_p
    data: list[dict[str, Any]] = []
    ys: list[list[float]] = [[-w_p, w_p, 0.0], [-g_max, g_max], [0.0]]
    t_end = 0.0
    for key, run in runs(comparison):
        tr = run.trace
        t_end = max(t_end, float(tr.t[-1]))
        gamma = motor_torque(motor, tr.i_d, tr.i_q)
        style = {"type": "scatter", "mode": "lines", "showlegend": False}
        for row, axis, full, name, unit, line in (
                (0, 0, tr.omega_r, "ω_r", "rad/s", {"width": 1.6, "dash": DASHES[key]}),
                (1, 1, gamma, "Γ", "N·m", {"width": 1.6, "dash": DASHES[key]}),
                (1, 2, tr.Gamma_L, "Γ_L", "N·m", {"width": 2.0, "dash": "dot"})):
            t, y = envelope(tr.t, full, BINS_OVERVIEW_ROWS)  # a chattering Γ stays a band
            data.append({**style, **t, "y": f32(y), "name": f"{name} {LABELS[key]}", "xaxis": f"x{row + 2}",
                         "yaxis": f"y{axis + 2}", "line": {"color": COLOURS[key], **line},
                         "hovertemplate": f"t = %{{x:.4f}} s: %{{y:.4g}} {unit}<extra>{LABELS[key]}</extra>"})
            ys[axis] += [float(np.min(y)), float(np.max(y))]
    return data, [_padded(min(y), max(y)) for y in ys], t_end


def _reference_traces(comparison: Any, t_end: float, ranges: list[list[float]]) -> list[dict[str, Any]]:
    """ω_p (eq. (60)) and ±Γ_max references, and the two time cursors (at t_end, moved by the replay)."""
    d = comparison.derived
    w_p, g_max = d.profile.omega_p, torque_limit(d.params)
    sign = 1.0 if d.params.manoeuvre.theta_dem >= 0 else -1.0
    ref = {"type": "scatter", "mode": "lines", "line": REF_LINE, "hoverinfo": "skip", "showlegend": False}
    out = [{**ref, "x": [0.0, t_end], "y": [sign * w_p] * 2, "name": "ω_p reference", "xaxis": "x2", "yaxis": "y2"},
           {**ref, "x": [0.0, t_end, None, 0.0, t_end], "y": [g_max, g_max, None, -g_max, -g_max],
            "name": "±Γ_max limit", "xaxis": "x3", "yaxis": "y3"}]
    for row, name in enumerate(CURSORS):
        out.append({"type": "scatter", "mode": "lines", "x": [t_end, t_end], "y": ranges[row], "name": name,
                    "showlegend": False, "hoverinfo": "skip", "xaxis": f"x{row + 2}", "yaxis": f"y{row + 2}",
                    "line": {"color": "#212529", "width": 1.5}})
    return out


def _time_layout(comparison: Any, t_end: float, ranges: list[list[float]]) -> dict[str, Any]:
    """Axes, row titles and load-step lines of the compact time plot."""
    g_max = torque_limit(comparison.derived.params)
    axes: dict[str, Any] = {}
    for row, (y_dom, title) in enumerate(zip(ROW_Y, ("ω_r [rad/s]", "Γ [N·m]"), strict=True)):
        n = row + 2
        axes[f"xaxis{n}"] = {"domain": list(TIME_X), "anchor": f"y{n}", "range": [0.0, t_end],
                             "showticklabels": row == 1, **({"matches": "x2"} if row else {})}
        axes[f"yaxis{n}"] = {"domain": list(y_dom), "anchor": f"x{n}", "range": ranges[row],
                             "title": {"text": title, "standoff": 4}}
    axes["xaxis3"]["title"] = {"text": "t [s]", "standoff": 4}
    axes["yaxis4"] = {"overlaying": "y3", "side": "right", "anchor": "x3", "range": ranges[2], "showgrid": False,
                      "zeroline": False, "ticklabelposition": "outside", "tickfont": {"color": LOAD_STEP_COLOUR},
                      "nticks": 4}  # no title: the row's note names it (a title at the edge hid the ticks)
    # two short lines: one did not fit the column's width at 1280×720 (its end was cut off)
    notes = [{"text": f"motor Γ [N·m]; ±Γ_max = {g_max:.4g} dashed<br>load Γ_L dotted, scale right (red)",
              "x": TIME_X[0],
              "y": ROW_Y[1][1], "xref": "paper", "yref": "paper", "xanchor": "left", "yanchor": "bottom",
              "showarrow": False, "font": {"size": FONT_PX, "color": "#555"}}]
    shapes = []
    for k, t in enumerate(load_step_times(comparison)):
        for row in (2, 3):
            shapes.append({"type": "line", "xref": f"x{row}", "yref": f"y{row} domain", "x0": t, "x1": t,
                           "y0": 0.0, "y1": 1.0, "line": {"color": LOAD_STEP_COLOUR, "width": 2, "dash": "dot"}})
        # staggered: the labels of steps close in time do not overlap
        notes.append({"text": f"load step {t:.3g} s", "x": t, "y": 1.0 - 0.14 * (k % 3), "xref": "x2",
                      "yref": "y2 domain",
                      "xanchor": "left", "yanchor": "top", "showarrow": False,
                      "font": {"size": FONT_PX, "color": LOAD_STEP_COLOUR}})
    return {**axes, "annotations": notes, "shapes": shapes}


def _with_trail(comparison: Any, data: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Return the phase plane's traces with the replay's trail (:mod:`app.figures.fdsmc_trail`) drawing the runs.

    The trail pieces go under everything else but the boundary and its layer (the first two
    traces); the whole trajectories stay (hover, names) but transparent; the FDSMC's translucent
    sliding band gives way to the trail's phase colours.
    """
    def kept(tr: dict[str, Any]) -> dict[str, Any]:
        name = str(tr.get("name", ""))
        if name.endswith(" trajectory"):
            return {**tr, "opacity": 0.0, "showlegend": False}
        if name.endswith(" enters boundary layer"):  # labelled "reaching → sliding" on the plot
            return {**tr, "showlegend": False}
        return tr
    rest = [kept(tr) for tr in data[2:] if "sliding phase" not in str(tr.get("name", ""))]
    return [short_layer(data[0]), data[1]] + piece_traces(pieces(comparison)) + rest


def short_layer(layer: dict[str, Any]) -> dict[str, Any]:
    """Return the boundary layer's trace with its legend entry short enough for a third of the legend's width.

    The overview's legend has three entries a row (``entrywidth`` 0.3): "Boundary layer ±1/K = …,
    eq. (45)" ran into its neighbour; "Layer ±1/K = … (45)" fits.
    """
    name = str(layer.get("name", ""))
    return {**layer, "name": name.replace("Boundary layer", "Layer").replace(", eq. (45)", " (45)")}


def keeper(xaxis: str, yaxis: str) -> dict[str, Any]:
    """Return an invisible one-point trace on subplot (``xaxis``, ``yaxis``) that every replay frame carries.

    Plotly's replay transitions clear a subplot none of whose traces is in the frame: the Γ_L
    axis and the zoom inset would go blank while a replay runs (:mod:`app.figures.fdsmc_replay`).
    """
    return {"type": "scatter", "mode": "markers", "x": [0.0], "y": [0.0], "xaxis": xaxis, "yaxis": yaxis,
            "name": f"keeper {xaxis}{yaxis}", "showlegend": False, "hoverinfo": "skip",
            "marker": {"opacity": 0.0, "size": 1}, "meta": {"keep": True}}


def _add_zoom(comparison: Any, data: list[dict[str, Any]], layout: dict[str, Any]) -> None:
    """Add the sliding-region inset (:mod:`app.figures.fdsmc_zoom`) to ``data`` and ``layout``, if the run cruised."""
    zoom = zoom_parts(comparison)
    if zoom is not None:
        traces, axes, shapes, notes = zoom
        data += traces
        layout.update(axes)
        layout["shapes"] = shapes + layout["shapes"]
        layout["annotations"] += notes


def overview_spec(comparison: Any, pins: tuple[Pin, ...] = (), plant_J_L: float | None = None) -> dict[str, Any]:
    """Build the phase plane (left) and the compact time plot (right) as one plain-dict figure.

    ``layout.meta.id`` stays ``"phase_plane"`` (the page and its tests find the figure by it);
    ``layout.meta.overview`` is True. The FDSMC run's chatter verdict
    (:func:`app.figures.fdsmc_verdict.chatter_verdict`) is the annotation named ``"verdict"``,
    top right of the phase plane.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
    pins : tuple of Pin
        Pinned runs, drawn first as grey ghosts (:func:`app.figures.fdsmc_pins.ghost_traces`).
    plant_J_L : float or None
        The plant's load inertia [kg·m²] of the runs where it is not the model's (the verdict says so).

    Returns
    -------
    dict
        ``{"data": [...], "layout": {...}}`` for :func:`app.figures.plain.figure_json`.
    """
    spec = phase_plane_spec(comparison)
    layout = spec["layout"]
    layout["xaxis"] = {**layout["xaxis"], "domain": list(PHASE_X)}
    layout["meta"] = {**layout["meta"], "overview": True}
    layout["title"] = {**layout["title"], "font": {"size": TITLE_PX}, "y": 0.995, "yref": "container", "yanchor": "top"}
    layout["legend"] = {"orientation": "h", "x": 0.0, "y": 1.01, "yanchor": "bottom", "font": {"size": FONT_PX},
                        "entrywidth": 0.3, "entrywidthmode": "fraction"}
    layout["margin"] = {"l": 56, "r": 12, "t": 124, "b": 84, "autoexpand": False}  # title and a 3-row legend at 14 px
    if not runs(comparison):  # not simulated: the boundary and its layer (same legend as a run's)
        return {**spec, "data": ghost_traces(pins, time_row=False) + [short_layer(spec["data"][0])] + spec["data"][1:]}
    spec["data"] = _with_trail(comparison, spec["data"])
    traces, ranges, t_end = _row_traces(comparison)
    phase_notes = list(layout.get("annotations", []))
    verdict = chatter_verdict(comparison, plant_J_L)
    if verdict is not None:
        phase_notes.append(verdict_annotation(verdict, PHASE_X[1]))
    layout.update(_time_layout(comparison, t_end, ranges))
    layout["annotations"] = phase_notes + layout["annotations"]
    _add_zoom(comparison, spec["data"], layout)
    data = (ghost_traces(pins) + spec["data"] + traces + _reference_traces(comparison, t_end, ranges)
            + [keeper(xa, ya) for xa, ya in (("x3", "y4"), ("x4", "y5")) if f"yaxis{ya[1:]}" in layout])
    return {"data": data, "layout": layout}


__all__ = ["CURSORS", "motor_torque", "overview_spec"]
