"""The "Robustness" tab: Monte-Carlo over plants the controller does not know (:mod:`sim.studies.robustness`).

The controller keeps the simulated inputs as its model; each sample draws the plant's J_L, R_s,
Ψ_PM, L_d/L_q and F_v from the spreads typed here (the command line's ``--spread`` syntax, parsed
by :func:`app.io.study_inputs.parse_spread`). The cost is checked before anything starts. Large
runs go to the Dask cluster named by ``PMSM_DASK_SCHEDULER`` when it is set (checked and warmed
first: :mod:`sim.studies.dask_runner`), else to a process pool (all cores) that is shut down when
the run ends or is cancelled; Cancel is polled between chunks of ≥ 0.1 s and cancels every chunk
not yet started. A lost cluster or pool is reported in one line. The study waits for a
server-wide slot; its pool has the slot's share of processes, at lowered priority
(:mod:`app.ui.studies_queue`).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

import viser

from pmsm_commissioning.app.figures.fdsmc_studies import robustness_spec, robustness_table_markdown
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.io.study_inputs import parse_spread
from pmsm_commissioning.app.ui.case import CasePort
from pmsm_commissioning.app.ui.studies_queue import STUDY_NICE
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.app.ui.viser_adapter import add_figure, set_figure_json
from pmsm_commissioning.app.ui.worker import Cancelled
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common.budget import MAX_STEPS, BudgetError
from pmsm_commissioning.sim.fdsmc.grid import check_budget
from pmsm_commissioning.sim.studies.robustness import (
    TRACE_POINTS,
    IncompleteRunError,
    RobustnessResult,
    Spread,
    robustness,
)
from pmsm_commissioning.sim.studies.runner import ExecutorError, RetryingPool

#: Most samples of one study from the page [-].
MAX_SAMPLES = 100_000
#: Most RK4 steps of one study (all samples, both controllers) [-]: 25 single-request budgets,
#: about a minute or two of CPU on this machine's cores for the paper's drive.
STUDY_MAX_STEPS = 25 * MAX_STEPS
#: From this many samples on the study runs in a process pool or on the cluster (below: in the worker thread).
POOL_MIN_SAMPLES = 64
#: Environment variable naming the Dask scheduler the page's large studies run on (as the CLI's).
SCHEDULER_ENV = "PMSM_DASK_SCHEDULER"
#: Spread inputs: (label, plant fields the spread applies to, default text).
SPREAD_FIELDS = (
    ("J_L spread", ("J_L",), "±50%"),
    ("R_s spread", ("R_s",), "±20%"),
    ("Ψ_PM spread", ("psi_pm",), "±20%"),
    ("L_d, L_q spread", ("L_d", "L_q"), ""),
    ("F_v spread", ("F_v",), ""),
)
SPREAD_HINT = ("Plant's true value vs the controller's model, SI units: LO:HI uniform (e.g. 0:0.3 kg·m² for "
               "J_L), ±X% uniform around the model's value, ~X% normal with σ = X %; empty = exact")


def parse_page_spreads(texts: dict[str, str]) -> list[Spread]:
    """Return the typed spreads (label → text) as :class:`Spread` s; ParameterError naming the field."""
    out: list[Spread] = []
    for label, fields, _ in SPREAD_FIELDS:
        text = str(texts.get(label, "")).strip()
        if not text:
            continue
        for f in fields:
            try:
                out.append(parse_spread(f"plant.{f}={text}"))
            except ParameterError as exc:
                raise ParameterError(f"Robustness › {label} = {text!r}: {exc}") from None
    return out


def check_study(params: DriveParams, samples: float, seed: float) -> tuple[int, int]:
    """Return (samples, seed) as integers once the study fits the budget.

    ParameterError/BudgetError otherwise.

    One sample (both controllers) must fit the single-request budget (the message names the drive's
    fields), and all samples together :data:`STUDY_MAX_STEPS`.
    """
    for label, v in (("samples", samples), ("seed", seed)):
        if isinstance(v, bool) or not isinstance(v, int | float) or v != v:
            raise ParameterError(f"Robustness › {label} = {v!r} is not a number: allowed a whole number")
    if not float(samples).is_integer() or not 1 <= samples <= MAX_SAMPLES:
        raise ParameterError(f"Robustness › samples = {samples:g} is out of range: allowed a whole number "
                             f"1 … {MAX_SAMPLES}")
    if not float(seed).is_integer() or not 0 <= seed < 2**32:
        raise ParameterError(f"Robustness › seed = {seed:g} is out of range: allowed a whole number 0 … {2**32 - 1}")
    one = check_budget(params, 2, max_points=TRACE_POINTS)
    n_max = max(1, STUDY_MAX_STEPS // max(one.steps, 1))
    if samples > n_max:
        raise BudgetError(f"Robustness › samples = {int(samples)} is too many for this drive: "
                          f"{int(samples)} × {one.steps:.3g} RK4 steps = {samples * one.steps:.3g} steps; allowed "
                          f"1 … {n_max} samples (≤ {STUDY_MAX_STEPS:.3g} steps per study)")
    return int(samples), int(seed)


class RobustnessView:
    """Inputs, Run / Cancel, progress, histograms and the summary table of one session.

    ``as_study`` marks its runs as studies (server-wide slots); ``processes`` bounds its pool.
    """

    #: The study's name in the queue's messages.
    LABEL = "Robustness study"

    def __init__(self, port: CasePort, as_study: Callable[[str], AbstractContextManager[Any]],
                 processes: int) -> None:
        self._s = port
        self._as_study, self._processes = as_study, processes
        gui = port.client.gui
        self.samples = gui.add_number("Samples", 200, min=1, max=MAX_SAMPLES, step=1)
        self.seed = gui.add_number("Seed", 0, min=0, step=1)
        self.spreads = {label: gui.add_text(label, default, hint=SPREAD_HINT) for label, _, default in SPREAD_FIELDS}
        self.run_button = gui.add_button("Run robustness study", icon=viser.Icon.PLAYER_PLAY, color="green")
        self.cancel_button = gui.add_button("Cancel robustness study", icon=viser.Icon.PLAYER_STOP, color="red",
                                            visible=False)
        self.progress = gui.add_progress_bar(0.0, animated=False)
        self.status = gui.add_markdown("Not run yet: the controller keeps the simulated inputs as its model; "
                                       "each sample draws the plant from the spreads above.")
        self.figure = add_figure(gui, aspect=0.8)
        self.table = gui.add_markdown("")
        self.run_button.on_click(lambda _: self.start())
        self.cancel_button.on_click(lambda _: self.cancel())
        self._done = 0
        self.result: RobustnessResult | None = None

    def start(self) -> bool:
        """Check the inputs and the budget, then run the study on the session's worker; False if refused."""
        params = self._s.case.params
        try:
            spreads = parse_page_spreads({k: h.value for k, h in self.spreads.items()})
            samples, seed = check_study(params, self.samples.value, self.seed.value)
        except ParameterError as exc:
            self._refuse(str(exc))
            return False
        with self._as_study(self.LABEL):
            return bool(self._s.submit(lambda: self._job(params, spreads, samples, seed)))

    def cancel(self) -> bool:
        """Ask the running study to stop; False if nothing runs."""
        if not self._s.cancel():
            return False
        self.status.content = f"Cancelling after {self._done} samples…"
        return True

    def _refuse(self, message: str) -> None:
        self.status.content = f"**Not started:** {md_text(message)}"
        self._s.client.add_notification("Robustness study not started", message, color="red",
                                        auto_close_seconds=12.0)

    def _cancel_requested(self) -> bool:
        try:
            self._s.checkpoint()
        except Cancelled:
            return True
        return False

    def _progress(self, done: int, total: int) -> None:
        pct = 100.0 * done / max(total, 1)
        if int(pct) != int(self.progress.value) or done == total:
            self.progress.value = pct
            self.status.content = f"Running: {done} of {total} samples…"
        self._done = done

    def _job(self, params: DriveParams, spreads: list[Spread], samples: int, seed: int) -> None:
        self._done = 0
        self.progress.value = 0.0
        self.status.content = f"Starting {samples} samples…"
        self.run_button.disabled, self.cancel_button.visible = True, True
        try:
            result = self._run(params, spreads, samples, seed)
        except (ParameterError, ExecutorError, IncompleteRunError) as exc:  # a pool ended by Cancel fails
            if self._cancel_requested():
                self.status.content = (f"**Cancelled** after {self._done} of {samples} samples; the remaining "
                                       "work was cancelled and the pool shut down.")
                raise Cancelled(str(exc)) from None
            self._fail(str(exc))
            return
        finally:
            self.run_button.disabled, self.cancel_button.visible = False, False
        self.show(result, torque_limit(params))
        self._s.say(f"Ready — robustness study of {samples} samples done.")

    def _fail(self, message: str) -> None:
        self.status.content = f"**Failed:** {md_text(message)}"
        self._s.client.add_notification("Robustness study failed", message, color="red", auto_close_seconds=12.0)
        self._s.say("Ready — the robustness study failed (see its tab).")

    def _run(self, params: DriveParams, spreads: list[Spread], samples: int, seed: int) -> RobustnessResult:
        if samples < POOL_MIN_SAMPLES:
            return robustness(params, spreads, samples, seed, progress=self._progress,
                              cancelled=self._cancel_requested)
        if os.environ.get(SCHEDULER_ENV):
            from pmsm_commissioning.sim.studies.dask_runner import connect

            with connect(os.environ[SCHEDULER_ENV]) as ex:
                return robustness(params, spreads, samples, seed, ex, ex.workers, self._progress,
                                  self._cancel_requested)
        workers = self._processes
        pool = RetryingPool(workers, nice=STUDY_NICE)
        unhook = self._s.on_cancel(pool.terminate)  # Cancel or a closed page: at once, no retry
        try:
            return robustness(params, spreads, samples, seed, pool, workers, self._progress,
                              self._cancel_requested)
        finally:
            unhook()
            pool.shutdown(wait=True, cancel_futures=True)  # the rest never starts

    def show(self, result: RobustnessResult, torque_limit_Nm: float) -> None:
        """Draw the histograms and the summary table of a finished study."""
        self.result = result
        set_figure_json(self.figure, figure_json(robustness_spec(result, torque_limit_Nm)))
        self.table.content = robustness_table_markdown(result.summary)
        with contextlib.suppress(Exception):
            self.progress.value = 100.0
        self.status.content = f"Done: {result.summary['samples']} samples in {result.summary['seconds']:.1f} s."


__all__ = ["MAX_SAMPLES", "POOL_MIN_SAMPLES", "SPREAD_FIELDS", "STUDY_MAX_STEPS", "RobustnessView", "check_study",
           "parse_page_spreads"]
