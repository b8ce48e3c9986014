"""The replay, animated by the browser: Plotly buttons with inline key frames; a scrub update.

Viser hands Plotly only ``data``/``layout``/``config`` (``fig.frames`` are dropped), but
``Plotly.animate`` also takes a list of frame *objects*, and a layout ``updatemenus`` button
passes its ``args`` straight to it. So each speed's button carries its own short list of
*key frames*, each moving only the phase-plane "now" markers and the time cursors of the overview
figure (:mod:`app.figures.fdsmc_overview`; a few numbers per frame); the figure goes out once per
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

The buttons do not call Plotly themselves (``execute: false``): the page's handler
(:data:`app.ui.replay.BUTTONS_JS`) passes their ``args`` to ``Plotly.animate`` and ignores the
rejection Plotly gives an animation that a pause, a scrub or another speed interrupts (through
Plotly's own button call, every such interruption logged "API call to Plotly.animate rejected").

Scrubbing to a time is a ``Plotly.restyle`` of the same traces (:func:`scrub_update`, a few hundred
bytes) that the page's "Replay t" slider sends per move. A Plotly slider inside the figure would
need no server, but it is drawn again with every redraw of the figure: with 50 positions it made
each redraw ≈ 40 % slower (≈ 114 ms instead of ≈ 64 ms in headless Chromium).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.fdsmc_comparison import phase_plane_extent, runs
from pmsm_commissioning.app.figures.style import FONT_PX
from pmsm_commissioning.sim.fdsmc.engine import Comparison

#: Replay speeds: button label → simulated seconds per wall-clock second.
SPEEDS = {"1×": 1.0, "0.25×": 0.25, "0.1×": 0.1, "0.01×": 0.01}
#: Key frames per wall-clock second, and the most key frames per speed (bounds the figure size).
KEY_RATE, MAX_FRAMES = 10.0, 150
#: Share of the phase plane's width, at its right edge, where the time label stands left of the
#: marker [-] (right of it, the label was cut at the plot's edge at the end of a replay).
LABEL_LEFT_SHARE = 0.2


@dataclass(frozen=True)
class ScrubTargets:
    """Traces a replay moves: the ``"<name> now"`` markers, the time cursors (``x = [t, t]``), the trail.

    ``cursor_y`` keeps each cursor's vertical extent [row units]; ``trail`` holds, per trail piece
    (:mod:`app.figures.fdsmc_trail`), its trace index, end time [s], its points as the JSON object
    ``{"x": […], "y": […]}`` a frame shows once the replay has passed it, and the same with its
    first point only: the piece not reached yet. (A line of one point is not drawn; an empty
    trace would be, because Plotly's transitions keep the path of a trace that lost all its points.)
    """

    now: tuple[int, ...]
    cursors: tuple[int, ...]
    cursor_y: tuple[tuple[float, ...], ...]
    trail: tuple[tuple[int, float, str, str], ...] = ()
    keep: tuple[tuple[int, str], ...] = ()

    @classmethod
    def of(cls, data: list[dict[str, Any]], points: bool = True) -> ScrubTargets:
        """Find the moved traces among a figure's traces ``data`` by their names (the trail by ``meta.trail``).

        Without ``points`` the trail's JSON is left empty (a figure without replay frames: a drag).
        """
        names = [t.get("name", "") for t in data]
        cursors = tuple(i for i, n in enumerate(names) if n.startswith("time cursor"))
        trail = tuple((i, float(t["meta"]["trail"]), _points_json(t["x"], t["y"]) if points else "",
                       _points_json(t["x"][:1], t["y"][:1]) if points else "")
                      for i, t in enumerate(data) if isinstance(t.get("meta"), dict) and "trail" in t["meta"])
        keep = tuple((i, _points_json(t["x"], t["y"])) for i, t in enumerate(data)
                     if isinstance(t.get("meta"), dict) and t["meta"].get("keep"))
        return cls(tuple(i for i, n in enumerate(names) if n.endswith(" now")), cursors,
                   tuple(tuple(float(v) for v in data[i]["y"]) for i in cursors), trail, keep)


def _points_json(x: Any, y: Any) -> str:
    """``{"x": […], "y": […]}`` of a trail piece, 4 significant digits."""
    def fmt(a: Any) -> str:
        return ",".join(f"{v:.4g}" for v in np.asarray(a, dtype=float).tolist())
    return f'{{"x":[{fmt(x)}],"y":[{fmt(y)}]}}'


def _trail_frames(trail: tuple[tuple[int, float, str, str], ...],
                  t_grid: np.ndarray) -> list[tuple[list[int], list[str]]]:
    """Per key frame, the trail pieces it changes: all hidden at the first, then each once passed."""
    out: list[tuple[list[int], list[str]]] = []
    before = -math.inf
    for k, t in enumerate(t_grid.tolist()):
        shown = [(i, points) for i, t_end, points, _ in trail if before < t_end <= t]
        if k == 0:
            shown = [(i, points if t_end <= t else hidden) for i, t_end, points, hidden in trail]
        out.append(([i for i, _ in shown], [points for _, points in shown]))
        before = t
    return out


def end_time(comparison: Comparison) -> float:
    """End of the longest run of ``comparison`` [s] (1 s when nothing was simulated)."""
    return max((float(run.trace.t[-1]) for _, run in runs(comparison)), default=1.0)


def _marker_positions(comparison: Comparison, t_grid: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(θ_r − θ_dem [rad], ω_r [rad/s]) of each run at the times ``t_grid`` [s], linear between samples."""
    th = comparison.derived.params.manoeuvre.theta_dem
    return [(np.interp(t_grid, run.trace.t, run.trace.theta_r) - th, np.interp(t_grid, run.trace.t, run.trace.omega_r))
            for _, run in runs(comparison)]


def label_sides(comparison: Comparison, x: Any) -> list[str]:
    """Return the ``textposition`` of the time label for the FDSMC marker at each θ_re of ``x`` [rad].

    Above the marker; left of it in the right :data:`LABEL_LEFT_SHARE` of the phase plane.
    """
    lo, hi = phase_plane_extent(comparison)
    edge = hi - LABEL_LEFT_SHARE * (hi - lo)
    return ["top left" if v > edge else "top right" for v in np.atleast_1d(np.asarray(x, dtype=float)).tolist()]


def _frames_json(comparison: Comparison, targets: ScrubTargets, t_grid: np.ndarray) -> str:
    """Write the JSON list of frames at the times ``t_grid`` [s].

    Per time t: the x/y of each "now" marker (and a time label on the side of :func:`label_sides`),
    ``x = [t, t]`` of each time-cursor trace, the trail pieces the frame shows (:func:`_trail_frames`)
    and each subplot's *keeper* as it is (``meta.keep``: Plotly's transitions clear a subplot none of whose traces
    is in the frame).

    Written as text directly: a few thousand small frames are ~10× faster this way than as dicts.
    """
    marks = _marker_positions(comparison, t_grid)
    cols = [([f"{v:.5g}" for v in x.tolist()], [f"{v:.5g}" for v in y.tolist()]) for x, y in marks]
    sides = label_sides(comparison, marks[0][0]) if marks else []
    frames, cursors = [], targets.cursors
    keep = [i for i, _ in targets.keep], [points for _, points in targets.keep]
    for k, (t, (pieces, points)) in enumerate(zip(t_grid.tolist(), _trail_frames(targets.trail, t_grid),
                                                  strict=True)):
        parts = [f'{{"x":[{x[k]}],"y":[{y[k]}]'
                 + (f',"text":["t = {t:.3f} s"],"textposition":["{sides[k]}"]}}' if j == 0 else "}")
                 for j, (x, y) in enumerate(cols)]
        parts += [f'{{"x":[{t:.6g},{t:.6g}]}}'] * len(cursors) + points + keep[1]
        traces = ",".join(map(str, [*targets.now, *cursors, *pieces, *keep[0]]))
        frames.append(f'{{"data":[{",".join(parts)}],"traces":[{traces}]}}')
    return "[" + ",".join(frames) + "]"


def _n_frames(t_end: float, speed: float) -> int:
    """Key frames of one speed: :data:`KEY_RATE` per wall second, at most :data:`MAX_FRAMES`."""
    return int(min(MAX_FRAMES, max(2, math.ceil(t_end / speed * KEY_RATE) + 1)))


def replay_layout(comparison: Comparison, data: list[dict[str, Any]],
                  targets: ScrubTargets | None = None) -> tuple[dict[str, Any], dict[str, str]]:
    """Layout entries (``updatemenus``) that replay ``comparison`` in the browser.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
    data : list of dict
        The figure's traces in order; the ``"<name> now"`` markers and the ``"time cursor …"``
        lines (vertical, ``x = [t, t]``) are the ones moved.
    targets : ScrubTargets or None
        ``ScrubTargets.of(data)`` if the caller has it already.

    Returns
    -------
    (dict, dict)
        The layout entries, with each button's frame list left as a placeholder string, and
        placeholder → frame-list JSON (for :func:`app.figures.plain.figure_json`'s ``raw``).
    """
    rs = runs(comparison)
    if not rs:
        return {}, {}
    targets = ScrubTargets.of(data) if targets is None else targets
    t_end = end_time(comparison)
    buttons, raw = [], {}
    for k, (label, speed) in enumerate(SPEEDS.items()):
        n = _n_frames(t_end, speed)
        raw[f"__frames_{k}__"] = _frames_json(comparison, targets, np.linspace(0.0, t_end, n))
        ms = 1e3 * t_end / speed / (n - 1)
        # per key frame: a jump to the start, then glides of one frame's duration each
        glide = [{"duration": 0}] + [{"duration": ms, "easing": "linear"} for _ in range(n - 1)]
        buttons.append({"label": f"▶ {label}", "method": "animate", "execute": False, "args": [f"__frames_{k}__", {
            "mode": "immediate", "frame": {"duration": ms, "redraw": False}, "transition": glide}]})
    buttons.append({"label": "Pause", "method": "animate", "execute": False, "args": [[None], PAUSE]})
    return {
        # below the time plot's axis title at any height: a fixed pad [px] under the plot area, not a
        # fraction of its height (at 1920×1080 y = -0.1 put the buttons past the bottom margin)
        "updatemenus": [{"type": "buttons", "direction": "left", "showactive": False, "x": 1.0, "y": 0.0,
                         "xanchor": "right", "yanchor": "top", "pad": {"t": BUTTONS_BELOW_PX, "b": 2},
                         "font": {"size": FONT_PX}, "buttons": buttons}],
    }, raw


#: Gap between the bottom of the plot area and the replay buttons [px].
BUTTONS_BELOW_PX = 34

#: ``Plotly.animate`` options that stop a running replay where it stands.
PAUSE = {"mode": "immediate", "frame": {"duration": 0, "redraw": False}, "transition": {"duration": 0}}


def scrub_update(comparison: Comparison, targets: ScrubTargets, t: float) -> tuple[dict[str, Any], list[int]]:
    """``Plotly.restyle`` arguments that put the replayed traces at time ``t`` [s].

    The markers go to (θ_r(t) − θ_dem, ω_r(t)) of each run (linear between samples, as the key
    frames), the cursors to ``x = [t, t]`` with their vertical extent kept; the first marker's
    text gives the time, on the side :func:`label_sides` picks. (The trail follows in the page:
    :data:`app.ui.replay.BUTTONS_JS`.)

    Returns
    -------
    (dict, list of int)
        The update and the indices of the traces it applies to.
    """
    t = float(t)
    marks = [(float(x[0]), float(y[0])) for x, y in _marker_positions(comparison, np.array([t]))]
    texts = [[f"t = {t:.3f} s"]] + [[""]] * (len(marks) - 1 + len(targets.cursors))
    sides = [label_sides(comparison, marks[0][0]) if marks else ["top right"]]
    sides += [["top right"]] * (len(marks) - 1 + len(targets.cursors))
    return ({"x": [[x] for x, _ in marks] + [[t, t]] * len(targets.cursors),
             "y": [[y] for _, y in marks] + [list(y) for y in targets.cursor_y], "text": texts,
             "textposition": sides},
            [*targets.now, *targets.cursors])


__all__ = ["KEY_RATE", "LABEL_LEFT_SHARE", "MAX_FRAMES", "PAUSE", "SPEEDS", "ScrubTargets", "end_time",
           "label_sides", "replay_layout", "scrub_update"]
