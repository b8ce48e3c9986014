"""Replay of a comparison: the browser animates the overview figure, the server turns the 3D rotors.

The overview figure (phase plane and compact time plot, :mod:`app.figures.fdsmc_overview`) carries its
own play buttons (one per speed) and pause (:mod:`app.figures.fdsmc_replay`): it is sent once per
Simulate and animated by Plotly in the browser — the phase-plane markers and the time cursors
move together — with no server traffic per frame. The "Replay t" slider below it scrubs: each move
sends one ``Plotly.restyle`` of the markers and cursors (a few hundred bytes) and turns the 3D
rotors to the same time. The 3D rotors are scene nodes, folded away by default ("Show 3D rotors");
their replay (Play/Pause) sends one small orientation update per rotor and one scrub per tick and
runs only while playing.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import viser

from pmsm_commissioning.app.figures.fdsmc_comparison import runs, time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_overview import overview_spec
from pmsm_commissioning.app.figures.fdsmc_pins import Pin
from pmsm_commissioning.app.figures.fdsmc_replay import (
    PAUSE,
    SPEEDS,
    ScrubTargets,
    end_time,
    replay_layout,
    scrub_update,
)
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.ui.layout import ASPECT_MAX, ASPECT_MIN, CHROME_HEIGHT
from pmsm_commissioning.app.ui.page_hooks import with_hooks
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.scene import RotorScene
from pmsm_commissioning.app.ui.viser_adapter import run_script, set_figure_json

FRAME_HZ = 25.0


#: The last figures built without pins, by kind: (comparison, result). Every new page shows the
#: start-up comparison: its figures are built once, not once per page.
_LAST: dict[str, tuple[Any, Any]] = {}


def _last_or_build(kind: str, comparison: Any, build: Callable[[], Any]) -> Any:
    """Return ``build()``, or what it returned for this very ``comparison`` (an immutable result) last time."""
    last = _LAST.get(kind)
    if last is not None and last[0] is comparison:
        return last[1]
    out = build()
    _LAST[kind] = (comparison, out)
    return out


def overview_json(comparison: Any, replay: bool = True, pins: tuple[Pin, ...] = (),
                  static: bool = True, plant_J_L: float | None = None) -> tuple[str, ScrubTargets]:
    """JSON of the overview figure (phase plane + compact time plot, ``pins`` as ghosts) and the traces a scrub moves.

    With ``replay`` the figure carries its in-browser replay (play buttons and key frames); without
    them (and without Plotly's mode bar) the browser redraws it faster: what a slider drag needs;
    both come back when the drag stops (``static`` False: the same light figure with Plotly's
    default config, drawn first after a Simulate; a change of config makes Plotly draw the next
    figure from scratch, at twice the cost). The page fits the figure's height to the window
    (``layout.meta.fit_height``, :data:`app.ui.plotly_js.REACT_JS`). ``plant_J_L`` [kg·m²]: the
    plant's load inertia where it is not the model's (the verdict then says K_limit is the model's).
    """
    if pins or plant_J_L is not None:
        return _overview_json(comparison, replay, pins, static, plant_J_L)
    return _last_or_build(f"overview {replay} {static}", comparison,
                          lambda: _overview_json(comparison, replay, (), static))


def _overview_json(comparison: Any, replay: bool, pins: tuple[Pin, ...],
                   static: bool, plant_J_L: float | None = None) -> tuple[str, ScrubTargets]:
    spec = overview_spec(comparison, pins, plant_J_L)
    spec["layout"]["meta"] = {**spec["layout"]["meta"], "fit_height": [CHROME_HEIGHT, ASPECT_MIN, ASPECT_MAX]}
    if not replay:
        drag = _drag_figure(spec, {"staticPlot": True} if static else {})
        return figure_json(drag), ScrubTargets.of(drag["data"], points=False)
    targets = ScrubTargets.of(spec["data"])
    layout, raw = replay_layout(comparison, spec["data"], targets)
    spec["layout"].update(layout)
    # Plotly.react keeps the previous figure's config when given none: the default config must be
    # explicit, or the drag figure's static mode would outlive the drag
    return figure_json({**spec, "config": {}}, raw), targets


def _drag_figure(spec: dict[str, Any], config: dict[str, Any]) -> dict[str, Any]:
    """Return the light overview, with Plotly's ``config``: only the traces that show.

    While a slider is dragged it is a static plot (no hover, zoom or mode bar; they return with
    the replay once the drag stops: ≈ 20 % off each redraw). It has the whole trajectories
    instead of the replay's trail: Plotly's cost per redraw grows with the number of traces
    (148 → 22 traces: 60 → 31 ms in headless Chromium), so the trail pieces (empty until a
    replay runs), the "now" markers and the time cursors (at the end of the run, where a replay
    leaves them) are left out.
    """
    data = [_drag_trace(tr) for tr in spec["data"] if not _replay_only(tr)]
    return {**spec, "data": data, "config": config}


def _replay_only(tr: dict[str, Any]) -> bool:
    """Return True for a trace only a replay moves: a trail piece, a "now" marker, a time cursor."""
    name = str(tr.get("name", ""))
    trail = isinstance(tr.get("meta"), dict) and "trail" in tr["meta"]
    return trail or name.endswith(" now") or name.startswith("time cursor")


def _drag_trace(tr: dict[str, Any]) -> dict[str, Any]:
    """One trace of the drag figure (see :func:`_drag_figure`): the trajectories drawn whole."""
    return {**tr, "opacity": 1.0} if str(tr.get("name", "")).endswith(" trajectory") else tr


def phase_plane_json(comparison: Any, replay: bool = True, pins: tuple[Pin, ...] = (),
                     plant_J_L: float | None = None) -> str:
    """JSON of the overview figure, with its in-browser replay if ``replay`` (see :func:`overview_json`)."""
    return overview_json(comparison, replay, pins, plant_J_L=plant_J_L)[0]


#: Script run in the page for a scrub: stop the overview's replay, then restyle its moved traces.
SCRUB_JS = """(() => {{ const P = window.Plotly; if (!P) return;
  for (const el of document.querySelectorAll('.js-plotly-plot')) {{
    if (!(el.layout && el.layout.meta && el.layout.meta.id === 'phase_plane' && el.data)) continue;
    P.animate(el, [null], {pause}).catch(() => {{}});
    const show = () => {{ P.restyle(el, {update}, {indices}); if (window.__appTrail) window.__appTrail(el, {t}); }};
    if (window.__appAfterTransition) window.__appAfterTransition(el, show); else show();
  }} }})();"""


#: Installed once per page. The overview's replay buttons (``execute: false``) call ``Plotly.animate``
#: from here, where the rejection of an interrupted animation (pause, scrub, another speed) is
#: caught. ``window.__appTrail(el, t)`` shows the trail pieces ending by ``t`` [s]: their points
#: are kept from the figure as it arrived (a replay empties them), so a scrub sends only ``t``.
BUTTONS_JS = with_hooks((Path(__file__).resolve().parent / "assets" / "replay_buttons.js").read_text(encoding="utf-8"))


def scrub_js(comparison: Any, targets: ScrubTargets, t: float) -> str:
    """Return the page script that puts the overview's markers and cursors at time ``t`` [s]."""
    update, indices = scrub_update(comparison, targets, t)
    return SCRUB_JS.format(pause=json.dumps(PAUSE), update=json.dumps(update, separators=(",", ":")),
                           indices=json.dumps(indices), t=json.dumps(float(t)))


def prebuild_figures(comparison: Any) -> None:
    """Build the figures every new page gets for ``comparison`` (the start-up one) now, at server start."""
    overview_json(comparison)
    time_plots_json(comparison)


def time_plots_json(comparison: Any) -> str:
    """JSON of the time plots."""
    return _last_or_build("time plots", comparison, lambda: figure_json(time_plots_spec(comparison)))


class Replay:
    """Sends the overview of a comparison; the "Replay t" scrub; Play/Pause for the 3D rotors."""

    def __init__(self, gui: viser.GuiApi, phase: viser.GuiPlotlyHandle, scene: RotorScene | None,
                 shown: tuple[Any, ScrubTargets] | None = None,
                 flush: Any = lambda: None, on_3d: Callable[[bool], None] = lambda _: None) -> None:
        """``shown``: the comparison the overview widget already shows, and the traces a scrub moves."""
        self._phase, self._scene, self._flush = phase, scene, flush
        self._on_3d = on_3d
        self._lock = threading.Lock()
        # One overview sent at a time, whole: a pin cleared while a run's figures go out waits for
        # them, then draws that run without the pin (not the run before, nor the pin again after).
        self._sending = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._gui = gui
        self.pins: tuple[Pin, ...] = ()  # pinned runs, drawn as ghosts in every overview sent
        self.plant_J_L: float | None = None  # the plant's J_L of the runs shown [kg·m²] (None: the model's)
        self._comparison, self._targets = shown if shown is not None else (None, ScrubTargets((), (), ()))
        self._t_end = self._t_now = end_time(self._comparison) if self._comparison is not None else 1.0
        self.slider = gui.add_slider("Replay t [s]", min=0.0, max=self._t_end, step=self._t_end / 1000.0,
                                     initial_value=self._t_end,
                                     hint="Scrub: the phase-plane markers, the time cursors and the 3D rotors "
                                          "go to this time")
        self.folder = gui.add_folder("3D view", expand_by_default=False, visible=scene is not None)
        with self.folder:
            self.show_3d = gui.add_checkbox("Show 3D rotors", False,
                                            hint="FDSMC (blue, left) and conventional (orange, right) rotors "
                                                 "turning with θ_r; hidden in the BLDC tabs")
            self.buttons = gui.add_button_group("3D rotors", ("Play", "Pause", "Replay"))
            self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.25×")
        self.buttons.on_click(self._on_button)
        self.slider.on_update(self._on_slider)
        run_script(gui, BUTTONS_JS)
        self.show_3d.on_update(lambda _: self._toggle_3d())

    def _toggle_3d(self) -> None:
        shown = bool(self.show_3d.value)
        if self._scene is not None:
            self._scene.visible = shown
        if not shown:
            self.pause()
        self._on_3d(shown)

    def load(self, comparison: Any, autoplay: bool = True, light: bool = False) -> None:
        """Show a new comparison in the overview; rotors to the end.

        ``light`` (a slider being dragged): the overview without its replay controls, until
        :meth:`complete`. Otherwise the light overview goes out first (the browser
        draws its 22 traces in a third of the time of the replay's 150) and the overview with its
        replay right after it.
        """
        self.pause()
        with self._sending:
            if not light:
                set_figure_json(self._phase, overview_json(comparison, replay=False, pins=self.pins, static=False,
                                                                   plant_J_L=self.plant_J_L)[0])
                self._flush()
            figure, targets = overview_json(comparison, replay=not light, pins=self.pins, plant_J_L=self.plant_J_L)
            set_figure_json(self._phase, figure)
            self._flush()  # the phase plane goes out before the larger figure is even built
            with self._lock:
                self._comparison, self._targets = comparison, targets
                rs = runs(comparison)
                self._t_end = end_time(comparison)
        # the figure shows the end of the runs
        assign(self.slider, max=self._t_end, step=self._t_end / 1000.0, value=self._t_end)
        if autoplay and self._scene is not None and self._scene.visible and rs:
            self.play(restart=True)
        else:
            self.seek(self._t_end, scrub=False)

    def complete(self, comparison: Any) -> None:
        """Send what a light :meth:`load` left out: the overview's replay."""
        with self._sending:
            set_figure_json(self._phase, phase_plane_json(comparison, pins=self.pins, plant_J_L=self.plant_J_L))

    def show_pins(self, pins: tuple[Pin, ...]) -> None:
        """Draw the overview of the comparison shown again with ``pins`` as its ghosts."""
        with self._sending:
            with self._lock:
                self.pins, comparison = pins, self._comparison
            if comparison is not None:
                figure, targets = overview_json(comparison, pins=pins, plant_J_L=self.plant_J_L)
                set_figure_json(self._phase, figure)
                with self._lock:
                    self._targets = targets

    def seek(self, t_now: float, scrub: bool = True) -> None:
        """Turn the 3D rotors to their angles at ``t_now`` [s]; with ``scrub`` move the overview's markers too."""
        with self._lock:
            comparison, targets = self._comparison, self._targets
            self._t_now = t_now = min(max(t_now, 0.0), self._t_end)
        if comparison is None or not runs(comparison):
            return
        if self._scene is not None:
            self._scene.show({key: float(np.interp(t_now, run.trace.t, run.trace.theta_r))
                              for key, run in runs(comparison)})
        if scrub:
            run_script(self._gui, scrub_js(comparison, targets, t_now))

    def play(self, restart: bool = False) -> None:
        """Start (or restart from t = 0) the 3D replay thread."""
        self.pause()
        if self._comparison is None or self._scene is None:
            return
        if restart or self._t_now >= self._t_end:
            self._t_now = 0.0
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="ui-replay-3d", daemon=True)
        self._thread.start()

    def pause(self) -> None:
        """Stop the 3D replay thread (keeps the current time)."""
        self._stop.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        self._thread = None

    def _run(self) -> None:
        period = 1.0 / FRAME_HZ
        t0, wall0, n = self._t_now, time.monotonic(), 0
        while not self._stop.is_set():
            t_now = t0 + (time.monotonic() - wall0) * SPEEDS.get(self.speed.value, 0.25)
            self.seek(t_now)
            self.slider.value = round(min(t_now, self._t_end), 6)
            if t_now >= self._t_end:
                return
            n += 1
            self._stop.wait(max(0.0, wall0 + n * period - time.monotonic()))

    def _on_button(self, event: viser.GuiEvent) -> None:
        label = self.buttons.value
        if label.endswith("Pause"):
            self.pause()
        else:
            self.play(restart=label.endswith("Replay"))

    def _on_slider(self, event: viser.GuiEvent) -> None:
        if event.client is None:  # our own update during play
            return
        self.pause()
        self.seek(float(self.slider.value))

    def close(self) -> None:
        """Stop the replay for good (client left)."""
        self.pause()
