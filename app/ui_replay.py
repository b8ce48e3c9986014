"""Replay of a comparison: the phase-plane marker, the time-plot cursor and the 3D rotors move together.

Viser hands Plotly only ``data``/``layout``/``config`` (``fig.frames`` are dropped), and the three
views live in different widgets, so the replay is **server-pushed**: a per-client thread sends
frames at :data:`FRAME_HZ`. To keep a frame cheap, each figure is serialised once per simulation
into a JSON template with placeholders; a frame only splices in the trajectory drawn so far
(≤ 2 k points per trace) and the marker, and sets the widget's JSON directly. The time plots are
large, so their cursor is refreshed at :data:`CURSOR_HZ`. Nothing runs while idle.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import viser

from app.figures import (
    LABELS,
    cursor_index,
    decimate_index,
    make_phase_plane_figure,
    make_time_plots_figure,
    runs,
)
from app.ui_scene import RotorScene

FRAME_HZ = 20.0
CURSOR_HZ = 2.0
AUTOPLAY_DELAY_S = 0.4
SPEEDS = {"0.1×": 0.1, "0.25×": 0.25, "0.5×": 0.5, "1×": 1.0}
_CURSOR = "__cursor__"


def set_figure_json(handle: viser.GuiPlotlyHandle, json_str: str) -> None:
    """Send a ready-made Plotly JSON string to a plot widget (skips re-encoding a go.Figure).

    ``_plotly_json_str`` is the widget property that ``GuiPlotlyHandle.figure`` itself sets.
    """
    handle._plotly_json_str = json_str


def _numbers(a: np.ndarray) -> list[str]:
    return [f"{v:.6g}" for v in a.tolist()]


class PhaseTemplate:
    """Phase-plane JSON with the "so far" and "now" traces left open for each frame."""

    def __init__(self, comparison: Any) -> None:
        fig = make_phase_plane_figure(comparison, t_now=0.0)
        data = json.loads(fig.to_json())
        self._series: list[tuple[np.ndarray, list[str], list[str]]] = []
        for key, run in runs(comparison):
            tr = run.trace
            i = decimate_index(len(tr.t))
            x = tr.theta_r[i] - comparison.derived.params.manoeuvre.theta_dem
            self._series.append((tr.t[i], _numbers(x), _numbers(tr.omega_r[i])))
            for suffix in ("so far", "now"):
                trace = next(t for t in data["data"] if t["name"] == f"{LABELS[key]} {suffix}")
                trace["x"], trace["y"] = f"@{key}_{suffix}_x@", f"@{key}_{suffix}_y@"
        self._keys = [key for key, _ in runs(comparison)]
        self._text = json.dumps(data)

    def frame(self, t_now: float) -> str:
        """The figure JSON at replay time ``t_now`` [s]."""
        text = self._text
        for key, (t, xs, ys) in zip(self._keys, self._series, strict=True):
            k = cursor_index(t, t_now)
            for suffix, sl in (("so far", slice(0, k + 1)), ("now", slice(k, k + 1))):
                text = text.replace(f'"@{key}_{suffix}_x@"', "[" + ",".join(xs[sl]) + "]")
                text = text.replace(f'"@{key}_{suffix}_y@"', "[" + ",".join(ys[sl]) + "]")
        return text


def time_template(comparison: Any) -> str:
    """Time-plot JSON with the cursor's x left open (placeholder ``"__cursor__"``)."""
    data = json.loads(make_time_plots_figure(comparison).to_json())
    shape = data["layout"]["shapes"][0]
    shape["x0"] = shape["x1"] = _CURSOR
    return json.dumps(data)


class Replay:
    """Play/pause/replay buttons, time slider and speed; drives the figures and the 3D scene."""

    def __init__(self, gui: viser.GuiApi, phase: viser.GuiPlotlyHandle,
                 time_plots: viser.GuiPlotlyHandle, scene: RotorScene | None,
                 flush: Callable[[], None] = lambda: None) -> None:
        self._phase, self._time_plots, self._scene, self._flush = phase, time_plots, scene, flush
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._comparison: Any = None
        self._phase_tpl: PhaseTemplate | None = None
        self._time_tpl = ""
        self._t_end = 1.0
        self._t_now = 0.0
        with gui.add_folder("Replay"):
            self.buttons = gui.add_button_group("Replay", ("Play", "Pause", "Replay"))
            self.slider = gui.add_slider("t [s]", min=0.0, max=1.0, step=0.001, initial_value=0.0)
            self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.25×")
        self.buttons.on_click(self._on_button)
        self.slider.on_update(self._on_slider)

    def load(self, comparison: Any, autoplay: bool = True) -> None:
        """Show a new comparison: whole figures first, then (optionally) replay from t = 0."""
        self.pause()
        set_figure_json(self._phase, make_phase_plane_figure(comparison).to_json())
        self._flush()  # the phase plane goes out before the larger figures are even built
        with self._lock:
            self._comparison = comparison
            self._phase_tpl = PhaseTemplate(comparison)
            self._time_tpl = time_template(comparison)
            self._t_end = max(float(run.trace.t[-1]) for _, run in runs(comparison))
        set_figure_json(self._time_plots, self._time_tpl.replace(f'"{_CURSOR}"', "0"))
        self.slider.max = self._t_end
        self.slider.step = self._t_end / 1000.0
        if autoplay:
            self.play(restart=True, delay=AUTOPLAY_DELAY_S)  # the browser draws the whole result first
        else:
            self.seek(self._t_end)

    def seek(self, t_now: float, cursor: bool = True) -> None:
        """Show the state at ``t_now`` [s] in all three views."""
        with self._lock:
            tpl, comparison = self._phase_tpl, self._comparison
            self._t_now = t_now = min(max(t_now, 0.0), self._t_end)
        if tpl is None:
            return
        set_figure_json(self._phase, tpl.frame(t_now))
        if cursor:
            set_figure_json(self._time_plots, self._time_tpl.replace(f'"{_CURSOR}"', f"{t_now:.6g}"))
        if self._scene is not None:
            self._scene.show({key: float(np.interp(t_now, run.trace.t, run.trace.theta_r))
                              for key, run in runs(comparison)})

    def play(self, restart: bool = False, delay: float = 0.0) -> None:
        """Start (or restart from t = 0) the replay thread, after ``delay`` [s]."""
        self.pause()
        if self._phase_tpl is None:
            return
        if restart or self._t_now >= self._t_end:
            self._t_now = 0.0
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, args=(delay,), name="ui-replay", daemon=True)
        self._thread.start()

    def pause(self) -> None:
        """Stop the replay thread (keeps the current time)."""
        self._stop.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        self._thread = None

    def _run(self, delay: float) -> None:
        if self._stop.wait(delay):
            return
        period, every = 1.0 / FRAME_HZ, max(1, round(FRAME_HZ / CURSOR_HZ))
        t0, wall0, n = self._t_now, time.monotonic(), 0
        while not self._stop.is_set():
            t_now = t0 + (time.monotonic() - wall0) * SPEEDS.get(self.speed.value, 0.25)
            done = t_now >= self._t_end
            self.seek(t_now, cursor=done or n % every == 0)
            self.slider.value = round(min(t_now, self._t_end), 6)
            if done:
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
