"""Live tuning: logarithmic sliders for K, T_c, T_m and the plant's J_L that re-simulate while dragged.

Each slider is an :class:`app.ui.log_slider.LogSlider` (K's is :class:`app.ui.k_slider.KSlider`)
with the values a lecturer steers by marked on its track: K_limit, K_recommended and (where the
sensors' noise sets the recommendation) K_noise on K; T_a of
eq. (59) ("eq.59") and T_c,min ("ζ=1") on T_c; T_m,min ("min") on T_m; the nominal J_L ("nom")
on J_L. After every committed run (Simulate, a preset, a file, a design, "Use …") each slider
mirrors its field (:meth:`LiveTuning.show`); during a drag nothing moves under the pointer.

A slider never simulates by itself: K, T_c and T_m write their value into the inputs panel (the
same field, shown and kept exactly as if typed) and ask the session to simulate the panel's
values. The J_L slider changes the **plant's** load inertia only: the controller keeps the typed
J_L as its model and does not know (the robustness demo); a Simulate of the typed inputs runs
the nominal plant again. While a run is in progress further moves only mark the panel as
changed; when the run ends, one new run of the latest values starts. Stale values are never
queued, and what runs is what the inputs panel shows.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import viser

from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.ui.k_slider import KSlider
from pmsm_commissioning.app.ui.layout import install_css_js
from pmsm_commissioning.app.ui.log_slider import LogSlider, default_readout, hide_box_css
from pmsm_commissioning.app.ui.viser_adapter import run_script
from pmsm_commissioning.app.ui.worker import Worker
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.sim.fdsmc.verdicts import recommended_K

#: Quiet time after the last slider move before the rest of the results (replay, time plots,
#: energy figures) is drawn [s]: a drag's moves arrive tens of ms apart.
TUNE_SETTLE_S = 0.4
#: The key of the plant's load inertia (not an input field: the controller's model keeps J_L).
PLANT_J_L = "plant.J_L"
#: Least span of the T_c, T_m and J_L sliders around their reference value [-]: ×/÷ this, widened
#: to whole decades.
SPAN = 10.0


def _around(value: float) -> tuple[float, float]:
    """Least range of a slider around ``value``: whole decades holding [value / SPAN, value · SPAN]."""
    if not (value > 0.0 and math.isfinite(value)):
        return 1.0, 10.0
    return 10.0 ** math.floor(math.log10(value / SPAN)), 10.0 ** math.ceil(math.log10(value * SPAN))


def _ms(t: float) -> float:
    return units.s_to_ms(t) if math.isfinite(t) else math.nan


class LiveTuning:
    """The "Live tuning" folder; ``apply(key, si)`` writes a value into the inputs panel (or the plant)."""

    def __init__(self, gui: viser.GuiApi, apply: Callable[[str, float], None],
                 request_run: Callable[[], None]) -> None:
        self._apply, self._request_run = apply, request_run
        with gui.add_folder("Live tuning (drag: re-simulates)", expand_by_default=True):
            self.k = KSlider(gui, self._k_moved)
            self.T_c = LogSlider(gui, "T_c [ms] (log)", (1.0, 100.0), default_readout("T_c", "ms"),
                                 self._mover("controller.T_c", units.ms_to_s),
                                 hint="eq.59: T_c = T_a of eq. (59); ζ=1: T_c,min, critically damped with "
                                      "the recommended K")
            self.T_m = LogSlider(gui, "T_m [s] (log)", (0.1, 10.0), default_readout("T_m", "s"),
                                 self._mover("manoeuvre.T_m", float),
                                 hint="min: T_m,min, the shortest feasible manoeuvre time")
            self.J_L = LogSlider(gui, "J_L plant [kg·cm²] (log)", (1.0, 100.0),
                                 default_readout("J_L plant", "kg·cm²"),
                                 self._mover(PLANT_J_L, units.kgcm2_to_kgm2),
                                 hint="The plant's load inertia; the controller keeps the typed J_L (nom) as "
                                      "its model. Simulate runs the nominal plant again")
        css = "\n".join(hide_box_css(s.uuid) for s in (self.k, self.T_c, self.T_m, self.J_L))
        run_script(gui, install_css_js(css, "app-k-slider-style"))

    def show(self, d: Derived, plant_J_L: float | None = None, recentre: bool = False) -> None:
        """Mirror the fields of ``d.params`` (and the plant's J_L [kg·m²]) with their marks.

        ``recentre`` (a new drive: preset, file, design): the J_L track is laid out around its J_L.
        """
        p, g = d.params, d.gain
        self.k.show_gains(p.controller.K, g.K_limit, recommended_K(d), g.K_noise_binding)
        T_a = _ms(d.profile.T_a)
        self.T_c.show(_ms(d.profile.T_c), (("eq.59", T_a), ("ζ=1", _ms(g.T_c_min))), _around(T_a))
        self.T_m.show(p.manoeuvre.T_m, (("min", d.profile.T_m_min),), _around(p.manoeuvre.T_m) if recentre else None)
        nominal = units.kgm2_to_kgcm2(p.load.J_L)
        J = nominal if plant_J_L is None else units.kgm2_to_kgcm2(plant_J_L)
        self.J_L.show(J, (("nom", nominal),), _around(nominal) if recentre else None)

    @property
    def _logs(self) -> dict[str, LogSlider]:
        return {"K": self.k, "T_c": self.T_c, "T_m": self.T_m, "J_L": self.J_L}

    @property
    def ranges(self) -> dict[str, tuple[float, float]]:
        """The least range of each slider [its unit], by name (``K``, ``T_c``, ``T_m``, ``J_L``)."""
        return {name: s.least for name, s in self._logs.items()}

    @ranges.setter
    def ranges(self, ranges: dict[str, tuple[float, float]]) -> None:
        for name, least in ranges.items():
            if name in self._logs:
                self._logs[name].least = least

    def _mover(self, key: str, to_si: Callable[[float], float]) -> Callable[[float], None]:
        def moved(value: float) -> None:
            self._apply(key, to_si(value))
            self._request_run()
        return moved

    def _k_moved(self, K: float) -> None:
        self._apply("controller.K", K)
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
