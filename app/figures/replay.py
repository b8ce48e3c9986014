"""The replay, animated by the browser: Plotly buttons and a slider with inline key frames.

Viser hands Plotly only ``data``/``layout``/``config`` (``fig.frames`` are dropped), but
``Plotly.animate`` also takes a list of frame *objects*, and a layout ``updatemenus`` button
passes its ``args`` straight to it. So each speed's button carries its own short list of
*key frames*, each moving only the phase-plane "now" markers and the time cursors of the overview
figure (:mod:`app.figures.overview`; a few numbers per frame); the figure goes out once per
Simulate and the replay then costs no server traffic at all.

Between two key frames Plotly moves the markers and the cursor lines itself, at the browser's
frame rate: each frame's ``transition`` lasts exactly the frame's duration with ``"linear"``
easing, and ``redraw: false`` keeps it to the moved traces. (``Plotly.animate`` takes one
transition per frame as a list: the first is instantaneous, so a replay jumps to t = 0 instead of
gliding back from where the marker stands.) Key frames are evenly spaced in
simulated time, so the cursors (``x = [t, t]``) move exactly with time and the markers follow the
trajectory through a key frame every 1/:data:`KEY_RATE` wall seconds (at most
:data:`MAX_FRAMES` per speed). A slow replay (0.01×) is therefore as smooth as a fast one, with a
figure that stays small (≈150 B per key frame, before compression).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from app.figures.comparison import runs
from sim.fdsmc.engine import Comparison

#: Replay speeds: button label → simulated seconds per wall-clock second.
SPEEDS = {"1×": 1.0, "0.25×": 0.25, "0.1×": 0.1, "0.01×": 0.01}
#: Key frames per wall-clock second, and the most key frames per speed (bounds the figure size).
KEY_RATE, MAX_FRAMES = 10.0, 150
#: Positions on the scrub slider.
SLIDER_STEPS = 50


def _frames_json(comparison: Comparison, now: list[int], t_grid: np.ndarray, cursors: tuple[int, ...] = ()) -> str:
    """Write the JSON list of frames at the times ``t_grid`` [s].

    Per time t: the x/y of each "now" marker (and a time label) and ``x = [t, t]`` of each
    time-cursor trace (indices ``cursors``).

    Written as text directly: a few thousand small frames are ~10× faster this way than as dicts.
    """
    th = comparison.derived.params.manoeuvre.theta_dem
    cols = []
    for _, run in runs(comparison):
        tr = run.trace
        x = np.interp(t_grid, tr.t, tr.theta_r) - th
        y = np.interp(t_grid, tr.t, tr.omega_r)
        cols.append(([f"{v:.5g}" for v in x.tolist()], [f"{v:.5g}" for v in y.tolist()]))
    traces = ",".join(map(str, [*now, *cursors]))
    frames = []
    for k, t in enumerate(t_grid.tolist()):
        parts = [f'{{"x":[{x[k]}],"y":[{y[k]}]' + (f',"text":["t = {t:.3f} s"]}}' if j == 0 else "}")
                 for j, (x, y) in enumerate(cols)]
        parts += [f'{{"x":[{t:.6g},{t:.6g}]}}'] * len(cursors)
        frames.append(f'{{"data":[{",".join(parts)}],"traces":[{traces}]}}')
    return "[" + ",".join(frames) + "]"


def _n_frames(t_end: float, speed: float) -> int:
    """Key frames of one speed: :data:`KEY_RATE` per wall second, at most :data:`MAX_FRAMES`."""
    return int(min(MAX_FRAMES, max(2, math.ceil(t_end / speed * KEY_RATE) + 1)))


def replay_layout(comparison: Comparison, data: list[dict[str, Any]]) -> tuple[dict[str, Any], dict[str, str]]:
    """Layout entries (``updatemenus``, ``sliders``) that replay ``comparison`` in the browser.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
    data : list of dict
        The figure's traces in order; the ``"<name> now"`` markers and the ``"time cursor …"``
        lines (vertical, ``x = [t, t]``) are the ones moved.

    Returns
    -------
    (dict, dict)
        The layout entries, with each button's frame list left as a placeholder string, and
        placeholder → frame-list JSON (for :func:`app.figures.plain.figure_json`'s ``raw``).
    """
    rs = runs(comparison)
    if not rs:
        return {}, {}
    names = [t.get("name", "") for t in data]
    now = [i for i, n in enumerate(names) if n.endswith(" now")]
    cursors = tuple(i for i, n in enumerate(names) if n.startswith("time cursor"))
    t_end = max(float(run.trace.t[-1]) for _, run in rs)
    buttons, raw = [], {}
    for k, (label, speed) in enumerate(SPEEDS.items()):
        n = _n_frames(t_end, speed)
        raw[f"__frames_{k}__"] = _frames_json(comparison, now, np.linspace(0.0, t_end, n), cursors)
        ms = 1e3 * t_end / speed / (n - 1)
        # per key frame: a jump to the start, then glides of one frame's duration each
        glide = [{"duration": 0}] + [{"duration": ms, "easing": "linear"} for _ in range(n - 1)]
        buttons.append({"label": f"▶ {label}", "method": "animate", "args": [f"__frames_{k}__", {
            "mode": "immediate", "frame": {"duration": ms, "redraw": False}, "transition": glide}]})
    buttons.append({"label": "Pause", "method": "animate", "args": [[None], {
        "mode": "immediate", "frame": {"duration": 0, "redraw": False}, "transition": {"duration": 0}}]})
    t_grid = np.linspace(0.0, t_end, SLIDER_STEPS + 1)
    marks = json.loads(_frames_json(comparison, now, t_grid, cursors))
    cursor_y = [list(data[i]["y"]) for i in cursors]
    steps = [{"label": f"{t:.3g}", "method": "restyle",
              "args": [{"x": [d["x"] for d in m["data"]], "y": [d["y"] for d in m["data"][:len(now)]] + cursor_y,
                        "text": [m["data"][0]["text"]] + [[""]] * (len(now) + len(cursors) - 1)},
                       [*now, *cursors]]}
             for t, m in zip(t_grid, marks, strict=True)]
    return {
        "updatemenus": [{"type": "buttons", "direction": "left", "showactive": False, "x": 1.0, "y": -0.1,
                         "xanchor": "right", "yanchor": "top", "pad": {"t": 0, "b": 2},
                         "font": {"size": 11}, "buttons": buttons}],
        "sliders": [{"active": SLIDER_STEPS, "steps": steps, "x": 0.0, "len": 0.52, "y": -0.1, "yanchor": "top",
                     "currentvalue": {"prefix": "replay t = ", "suffix": " s", "font": {"size": 11}},
                     "pad": {"t": 0, "b": 0}, "tickwidth": 0, "ticklen": 0, "font": {"size": 1},
                     "minorticklen": 0}],
    }, raw


__all__ = ["KEY_RATE", "MAX_FRAMES", "SPEEDS", "replay_layout"]
