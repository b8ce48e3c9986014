"""The K sweep tab: a grid of FDSMC runs over K, computed after a run, animated in the browser.

After every committed run (Simulate, a preset, a file, a design, "Use …", the end of a drag) the
session's worker runs the FDSMC alone for each K of :func:`app.figures.k_sweep.k_grid` (≈ 30 runs,
0.1–0.2 s of CPU on the paper preset) as a *tail* job (:meth:`app.ui.worker.Worker.submit_tail`):
the buttons stay enabled and the next Simulate or slider move stops it at its next run, so it
never delays a run of this page; other pages are not touched (each page has its own worker, and
the kernel releases the GIL). Each run passes the cost budget like every run (``compare``).

The figure (:func:`app.figures.k_sweep.k_sweep_spec`) carries one frame per K under its own
Plotly slider; a page script (``assets/k_sweep.js``) hands a step's frame to ``Plotly.animate``
(``redraw: false``) and swallows the rejection an interrupted animation gives. Dragging it costs
no server traffic at all. The panel's K slider stays the exact path: any K, between the grid's
points too, written into the K field and re-simulated.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import viser

from pmsm_commissioning.app.figures.k_sweep import k_grid, k_sweep_spec
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.io.plant_overrides import with_plant_J_L
from pmsm_commissioning.app.ui.k_slider import log_K_range
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.viser_adapter import add_figure, run_script, set_figure_json
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.verdicts import recommended_K

#: Plot height / width of the sweep figure [-].
ASPECT_SWEEP = 0.62
#: Installed once per page: a slider step of the sweep figure → ``Plotly.animate`` of its frame.
K_SWEEP_JS = (Path(__file__).resolve().parent / "assets" / "k_sweep.js").read_text(encoding="utf-8")
_LAST: dict[str, tuple[Any, Any, str]] = {}  # the last sweep built: (comparison, plant J_L, JSON)
_LAST_LOCK = threading.Lock()


def sweep_points(comparison: Any, plant_J_L: float | None,
                 checkpoint: Callable[[], None] = lambda: None) -> list[Any]:
    """Run the FDSMC alone for each K of the grid of ``comparison``'s case, on its plant.

    ``checkpoint()`` is called before each run (raises to stop the sweep).
    """
    d = comparison.derived
    p, g = d.params, d.gain
    K_rec = recommended_K(d)
    lo, hi = log_K_range(p.controller.K, g.K_limit, K_rec)
    points = []
    for K in k_grid(lo, hi, p.controller.K, g.K_limit, K_rec, g.K_noise_binding):
        checkpoint()
        q = dataclasses.replace(p, controller=dataclasses.replace(p.controller, K=K))
        plant = None if plant_J_L is None else with_plant_J_L(q, plant_J_L)
        points.append(compare(q, ("fdsmc",), plant=plant))
    return points


def k_sweep_json(comparison: Any, plant_J_L: float | None,
                 checkpoint: Callable[[], None] = lambda: None) -> str | None:
    """Return the Plotly JSON of the K sweep of ``comparison`` (None when it has no FDSMC run); the last one is kept."""
    if comparison.fdsmc is None:
        return None
    with _LAST_LOCK:
        last = _LAST.get("sweep")
    if last is not None and last[0] is comparison and last[1] == plant_J_L:
        return last[2]
    points = sweep_points(comparison, plant_J_L, checkpoint)
    d = comparison.derived
    spec, raw = k_sweep_spec(points, d.params.controller.K, {"lim": d.gain.K_limit, "rec": recommended_K(d) or 0.0},
                             plant_J_L)
    text = figure_json(spec, raw)
    with _LAST_LOCK:
        _LAST["sweep"] = (comparison, plant_J_L, text)
    return text


class KSweepView:
    """The "K sweep" tab's note and figure; :meth:`schedule` computes and sends a case's sweep."""

    def __init__(self, gui: viser.GuiApi) -> None:
        self.note = gui.add_html('<div data-role="k-sweep-note" style="font-size:16px">The K sweep is '
                                 "computed after each run.</div>")
        self.figure = add_figure(gui, None, ASPECT_SWEEP)
        run_script(gui, K_SWEEP_JS)

    def schedule(self, submit_tail: Callable[[Callable[[], None]], None], checkpoint: Callable[[], None],
                 comparison: Any, plant_J_L: float | None) -> None:
        """Compute the sweep of ``comparison`` (on ``plant_J_L``) as a tail job of the worker, then send it."""
        def job() -> None:
            text = k_sweep_json(comparison, plant_J_L, checkpoint)
            checkpoint()
            if text is None:
                assign(self.note, content=_note("No K sweep: the manoeuvre was not simulated."))
                return
            set_figure_json(self.figure, text)
            assign(self.note, content=_note("Drag the slider under the figure: each step is a run at that K "
                                            "(computed after the last run; the panel's K slider simulates "
                                            "any K in between)."))
        submit_tail(job)


def _note(text: str) -> str:
    return f'<div data-role="k-sweep-note" style="font-size:16px">{text}</div>'


__all__ = ["ASPECT_SWEEP", "K_SWEEP_JS", "KSweepView", "k_sweep_json", "sweep_points"]
