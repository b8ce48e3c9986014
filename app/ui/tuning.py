"""Live tuning: sliders for K, T_c, T_m and J_L that re-simulate while they are dragged.

K has its own logarithmic slider mirroring the K field (:mod:`app.ui.k_slider`); T_c, T_m and
J_L are linear, centred on their value after a preset, file or design.

A slider never simulates by itself: it writes its value into the inputs panel (the same field,
shown and kept exactly as if typed) and asks the session to simulate the panel's values. While
a run is in progress further moves only mark the panel as changed; when the run ends, one new
run of the latest values starts. Stale values are never queued, and what runs is what the
inputs panel shows.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import viser

from app.io import units
from app.ui.k_slider import KSlider, hide_box_css
from app.ui.layout import install_css_js
from app.ui.viser_adapter import run_script
from app.ui.worker import Worker
from control.fdsmc.params import DriveParams

#: Slider range around the value it is centred on: [value / SPAN, value · SPAN].
SPAN = 5.0
#: Positions per slider.
STEPS = 200
#: Quiet time after the last slider move before the rest of the results (replay, time plots,
#: energy figures) is drawn [s]: a drag's moves arrive tens of ms apart.
TUNE_SETTLE_S = 0.4


@dataclass(frozen=True)
class Knob:
    """One slider: page label, the inputs-panel key, and shown value ↔ SI [shown unit → SI unit]."""

    label: str
    key: str
    to_si: Callable[[float], float]
    from_si: Callable[[float], float]


KNOBS = (
    Knob("T_c [ms]", "controller.T_c", units.ms_to_s, units.s_to_ms),
    Knob("T_m [s]", "manoeuvre.T_m", float, float),
    Knob("J_L [kg·cm²]", "load.J_L", units.kgcm2_to_kgm2, lambda J: J * 1e4),
)


def _si_values(params: DriveParams, T_c: float) -> dict[str, float]:
    """Return the current SI values of the linear knobs (T_c [s] is the one in force)."""
    return {"controller.T_c": T_c,
            "manoeuvre.T_m": params.manoeuvre.T_m, "load.J_L": params.load.J_L}


def slider_range(value: float) -> tuple[float, float, float]:
    """(min, max, step) of a slider centred on ``value`` (> 0) in the shown unit."""
    lo, hi = value / SPAN, value * SPAN
    return lo, hi, (hi - lo) / STEPS


def slider_precision(step: float) -> int:
    """Decimals a slider with ``step`` keeps: two finer than the step.

    The page rounds every slider value to its ``precision``, which viser fixes when the slider is
    made; a slider re-centred on a small value (K = 0.043 s/rad, step ≈ 0.001) with the
    precision of its first range (2) rounded each key step back to 0.04.
    """
    return max(0, 2 - math.floor(math.log10(step)))


class LiveTuning:
    """The "Live tuning" folder; ``apply(key, si)`` writes a value into the inputs panel."""

    def __init__(self, gui: viser.GuiApi, apply: Callable[[str, float], None],
                 request_run: Callable[[], None]) -> None:
        self._apply, self._request_run = apply, request_run
        self._sliders: dict[str, Any] = {}
        with gui.add_folder("Live tuning (drag: re-simulates)", expand_by_default=True):
            self.k = KSlider(gui, self._k_moved)
            for knob in KNOBS:
                slider = gui.add_slider(knob.label, min=0.0, max=1.0, step=0.01, initial_value=0.5)
                slider.on_update(lambda event, k=knob: self._moved(event, k))
                self._sliders[knob.key] = slider
        run_script(gui, install_css_js(hide_box_css(self.k.uuid), "app-k-slider-style"))

    def show_K(self, K: float, K_limit: float, K_rec: float | None) -> None:
        """Move the K slider to ``K`` [s/rad] (the K field's value) with K_limit and K_rec marked."""
        self.k.show(K, K_limit, K_rec)

    def centre(self, params: DriveParams, T_c: float) -> None:
        """Centre each linear slider's range on the current value (after a preset, file or design)."""
        for knob in KNOBS:
            shown = knob.from_si(_si_values(params, T_c)[knob.key])
            if not shown > 0.0:
                continue
            lo, hi, step = slider_range(shown)
            slider = self._sliders[knob.key]
            slider.min, slider.max, slider.step = lo, hi, step
            slider.precision = slider_precision(step)
            slider.value = shown

    def _k_moved(self, K: float) -> None:
        self._apply("controller.K", K)
        self._request_run()

    def _moved(self, event: viser.GuiEvent, knob: Knob) -> None:
        if event.client is None:  # our own centring
            return
        self._apply(knob.key, knob.to_si(float(self._sliders[knob.key].value)))
        self._request_run()


class TuneRunner:
    """Runs the latest slider values on a client's worker while a slider moves.

    ``run_latest()`` simulates the inputs panel's values (False: an input error, stop); ``finish()``
    draws the rest of the results once no move came for :data:`TUNE_SETTLE_S`.
    """

    def __init__(self, worker: Worker, run_latest: Callable[[], bool], finish: Callable[[], None]) -> None:
        self._worker, self._run_latest, self._finish = worker, run_latest, finish
        self._pending = False
        self._moved = threading.Event()

    def request(self) -> None:
        """Run the latest slider value as soon as the worker is free (a slider moved)."""
        self._pending = True
        self._moved.set()
        if not self._worker.busy:
            self._worker.submit(self._loop)

    def resume(self) -> None:
        """Run the latest value if a slider moved during the job that just ended (the worker is free)."""
        if self._pending:
            self._worker.submit(self._loop)

    def _loop(self) -> None:
        """One run per batch of moves, overview only; the rest once the drag has stopped.

        The drag has stopped once no move came for :data:`TUNE_SETTLE_S`: a drag's moves arrive
        tens of ms apart, often slower than a run, and drawing the rest between two moves would
        double the browser's work.
        """
        while True:
            self._moved.clear()
            while self._pending:
                self._pending = False
                if not self._run_latest():
                    return
            if not self._moved.wait(TUNE_SETTLE_S):
                break
            self._worker.checkpoint()
        self._finish()
