"""The "Position drive (FDSMC)" tab: its controls, its actions, and the port its panels use.

The tab is the only writer of the browser tab's :class:`~app.ui.case.CaseState`. Its sub-panels —
inputs, files, drive log, verdicts, live tuning, optimum toggle — are built here; the drive-log
panel and the studies receive this tab as a :class:`~app.ui.case.CasePort` (read the case, ask for
actions) and nothing else. Simulations run on the browser tab's worker, never on the GUI loop.
"""

from __future__ import annotations

import contextlib
import sys
import traceback
from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

import viser

from pmsm_commissioning.app.io.presets import list_presets_of, load, require_mode
from pmsm_commissioning.app.ui.axis_inputs import axis_markdown
from pmsm_commissioning.app.ui.case import Case, CaseState
from pmsm_commissioning.app.ui.choices import checked_choice
from pmsm_commissioning.app.ui.files import ExportRefusedError, FilesPanel, uncommitted
from pmsm_commissioning.app.ui.inputs import InputError, InputsPanel
from pmsm_commissioning.app.ui.lecture import DemoStateFiles, LecturePins
from pmsm_commissioning.app.ui.log import LogPanel
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.results import ResultsPanel
from pmsm_commissioning.app.ui.runs import OBJECTIVE_LABELS, comparison_or_derived, table1_job
from pmsm_commissioning.app.ui.studies import OptimumToggle
from pmsm_commissioning.app.ui.text import derived_markdown, design_markdown, md_text, stale_results_html
from pmsm_commissioning.app.ui.tuning import PLANT_J_L, LiveTuning, TuneRunner
from pmsm_commissioning.app.ui.verdict_panel import VerdictPanel
from pmsm_commissioning.app.ui.worker import Cancelled, Worker
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import Comparison
from pmsm_commissioning.sim.fdsmc.objective import OBJECTIVES, design_for
from pmsm_commissioning.sim.fdsmc.verdicts import T_c_advice, recommended_K


class PositionTab:
    """Controls and actions of the position-drive tab of one browser tab (a :class:`~app.ui.case.CasePort`).

    Parameters
    ----------
    client : viser.ClientHandle
        The browser tab.
    state : CaseState
        The case it shows and changes.
    worker : Worker
        The browser tab's one worker (its busy and error callbacks call :meth:`set_busy`, :meth:`job_failed`).
    """

    def __init__(self, client: viser.ClientHandle, state: CaseState, worker: Worker) -> None:
        self._client, self._state, self._worker = client, state, worker
        self._recentre = True
        self._plant_J_L: float | None = None  # the J_L slider's plant [kg·m²]; None: the model's
        self.results: ResultsPanel | None = None  # the right-hand panel, given by the page once built
        self.demo_link: Any = None  # the page's address (app.ui.demo_link.DemoLink), given by the page
        self.tuner = TuneRunner(worker, self._run_latest, self._tuned)
        self._controls(client.gui)

    # ---- the port (app.ui.case.CasePort) ------------------------------------------------------
    @property
    def client(self) -> viser.ClientHandle:
        """The browser tab's client."""
        return self._client

    @property
    def case(self) -> Case:
        """The current case (frozen snapshot)."""
        return self._state.current

    def submit(self, fn: Callable[[], None]) -> bool:
        """Run ``fn`` on this client's worker (one job at a time); False (with a note) if busy."""
        if self._worker.submit(fn) is None:
            self._client.add_notification("Busy", "A run is still in progress — wait for it to finish.",
                                          color="yellow", auto_close_seconds=4.0)
            return False
        return True

    def checkpoint(self) -> None:
        """On the worker: raise Cancelled if the running job was cancelled."""
        self._worker.checkpoint()

    def cancel(self) -> bool:
        """Cancel the running job (its result is discarded); False if nothing runs."""
        return self._worker.cancel()

    def on_cancel(self, hook: Callable[[], None]) -> Callable[[], None]:
        """Run ``hook`` when the running job is cancelled or the page closed (e.g. end a process pool)."""
        return self._worker.on_cancel(hook)

    def say(self, text: str) -> None:
        """Show ``text`` on the status line."""
        self.status.content = text

    def collect_inputs(self) -> DriveParams:
        """Return the inputs shown, validated (InputError naming the field if not)."""
        return self.inputs.collect()

    def open_case(self, params: DriveParams, origin: str) -> None:
        """Show ``params`` in the inputs as coming from ``origin`` (not simulated yet); its preset in the dropdown."""
        if origin in self._preset_names and origin != self.preset.value:  # e.g. a loaded demo state
            self.preset.value = self._preset_shown = origin
        self.inputs.populate(params)
        self._state.opened(params, origin)

    def run(self, params: DriveParams, autoplay: bool = True, overview_only: bool = False,
            keep_plant: bool = False) -> None:
        """On the worker: simulate ``params`` and show the results (``overview_only``: a live-tuning run).

        A live-tuning run (or ``keep_plant``) keeps the J_L slider's plant; any other run simulates
        the nominal plant.
        """
        if not overview_only:
            self.status.content = "Simulating…"
            if not keep_plant:
                self._plant_J_L = None
        assign(self.design_note, content="")
        self._worker.checkpoint()
        plant_J_L = self._plant_J_L
        comparison = comparison_or_derived(params, self.optimum.wanted, plant_J_L)  # ParameterError → job_failed
        self._worker.checkpoint()
        self._state.ran(params, comparison, plant_J_L)
        if comparison.fdsmc is not None:
            self._results().show(comparison, autoplay=autoplay, overview_only=overview_only, plant_J_L=plant_J_L)
        else:
            self._results().show_derived_only(comparison)
        self.show_text(status=not overview_only)

    def simulate(self) -> bool:
        """Commit the inputs and simulate both controllers on the worker; False if not started."""
        return self._commit_and_submit(self.run)

    def results_tab(self, title: str, icon: Any) -> AbstractContextManager[Any]:
        """Return a new tab of the results panel."""
        return self._results().panel.add_tab(title, icon)

    # ---- controls -----------------------------------------------------------------------------
    def _controls(self, gui: viser.GuiApi) -> None:
        case = self.case
        names = self._preset_names = tuple(list_presets_of("position"))
        self.preset = gui.add_dropdown("Preset", names, initial_value=case.origin if case.origin in names
                                       else names[0])
        self.preset.on_update(self._preset_chosen)
        self._preset_shown = self.preset.value
        # the sliders sit above everything a run changes (warnings, status, Cancel): a drag never moves them
        self.tuning = LiveTuning(gui, self._apply_knob, self.tuner.request)
        self.lecture = LecturePins(gui, self)
        # the K demo's remedies and warnings next, in the first screen at 1280×720 (the inputs below)
        self.verdicts = VerdictPanel(gui, self._use_recommended_k, self._use_T_c_min)
        self.files = FilesPanel(self._client, self.export_state, self._imported, case.params)
        self.demo_files = DemoStateFiles(gui, self)
        self.log_panel = LogPanel(self)
        self.simulate_button = gui.add_button("Simulate", icon=viser.Icon.PLAYER_PLAY, color="green")
        self.simulate_button.on_click(lambda _: self.simulate())
        self.design_button = gui.add_button("Design for this drive", icon=viser.Icon.WAND, color="blue",
                                            hint="α_max, T_m, K and T_c for this nameplate, load and inverter, "
                                                 "verified by simulation")
        self.design_button.on_click(lambda _: self.design())
        self.objective = gui.add_dropdown("Design objective", OBJECTIVE_LABELS,
                                          hint="energy from the supply under the DC link: the α that takes least; "
                                               "friction: the paper's profile at the torque limit")
        self.design_note = gui.add_markdown("")
        self.optimum = OptimumToggle(gui, self.simulate)
        self.cancel_button = gui.add_button("Cancel", icon=viser.Icon.PLAYER_STOP, color="red", visible=False)
        self.cancel_button.on_click(lambda _: self.cancel_run())
        self.status = gui.add_markdown("Ready.")
        with gui.add_form(None) as form:
            self.inputs = InputsPanel(gui, case.params)
        form.on_submit(lambda _: self.simulate())
        self.inputs.dc_link.on_update(lambda e: self.simulate() if e.client is not None else None)  # re-ranks
        with gui.add_folder("Derived values", expand_by_default=True):
            self.derived = gui.add_markdown("")

    def _results(self) -> ResultsPanel:
        if self.results is None:
            raise RuntimeError("the results panel is not built yet")
        return self.results

    # ---- actions ------------------------------------------------------------------------------
    def cancel_run(self) -> bool:
        """Cancel the running job and say so on the status line; False if nothing runs."""
        if not self.cancel():
            return False
        self.status.content = "Cancelling…"
        return True

    def design(self) -> bool:
        """Commit the inputs, design for this drive on the worker and show the verified design."""
        return self._commit_and_submit(self._run_design)

    def _commit_and_submit(self, job: Callable[[DriveParams], None]) -> bool:
        """Validate the inputs (nothing runs on an error) and hand ``job(params)`` to the worker."""
        try:
            params = self.inputs.collect()
        except InputError as exc:
            self._reject(str(exc))
            return False
        if self._worker.busy:
            return self.submit(lambda: None)  # refused, with the "busy" note
        self._results().replay.pause()  # frees the browser for the new result
        return self.submit(lambda: job(params))

    def _run_design(self, params: DriveParams) -> None:
        self.status.content = "Designing and verifying…"
        objective = OBJECTIVES[OBJECTIVE_LABELS.index(checked_choice(self.objective.value, OBJECTIVE_LABELS,
                                                                     "Design objective"))]
        dd = design_for(params, objective).design
        self.design_note.content = design_markdown(dd)
        if dd.refused:  # nothing designed or simulated: the inputs and plant stay, the results are marked stale
            self.status.content = "Design refused before any run — see the design note."
            self.verdicts.design_failed(dd)
            if self.results is not None:
                assign(self.results.key_numbers, content=stale_results_html(dd))
            return
        shown = dd.params
        self.inputs.populate(shown)
        self._plant_J_L = None
        self._recentre = True
        comparison = (None if self.optimum.wanted else dd.comparison) or comparison_or_derived(
            shown, self.optimum.wanted)
        self._state.ran(shown, comparison)
        if comparison.fdsmc is not None:
            self._results().show(comparison)
        self.show_text()
        if dd.verdict != "clean":  # the design's diagnosis stays in the warnings box, never "No warnings"
            self.verdicts.design_failed(dd, comparison)

    def _run_latest(self) -> bool:
        """Simulate the inputs panel's values, overview only (a slider moves); False on an input error."""
        try:
            params = self.inputs.collect()
        except InputError as exc:
            self._reject(str(exc))
            return False
        self.run(params, autoplay=False, overview_only=True)
        return True

    def _tuned(self) -> None:
        """Draw the rest of the results of the last run once a drag has stopped."""
        if self.case.comparison.fdsmc is not None:
            self._results().show_rest()
        self.show_text()

    def _apply_knob(self, key: str, value_si: float) -> None:
        """Write a live-tuning slider's value into the inputs panel, as if typed."""
        if key == PLANT_J_L:
            self._plant_J_L = value_si
        elif key == "controller.T_c":
            self.inputs.set_T_c(value_si)
        else:
            self.inputs.set_value(key, value_si)

    def sweep(self, T_m_values: list[float]) -> None:
        """Run the Table-1 sweep over ``T_m_values`` [s] on the worker with a progress bar."""
        self.submit(table1_job(self, self._results(), T_m_values))

    def _preset_chosen(self, event: viser.GuiEvent) -> None:
        if event.client is None:
            return
        try:
            name = checked_choice(self.preset.value, self._preset_names, "Preset")
            params = load(name, mode="position")
        except ValueError as exc:
            self.preset.value = self._preset_shown  # back to the preset whose values are shown
            self._reject(str(exc))
            return
        self._preset_shown = name
        self._imported(params, name)

    def _imported(self, params: DriveParams, origin: str) -> None:
        try:
            require_mode(params, "position", origin)
        except ValueError as exc:
            self._reject(str(exc))
            return
        self.files.show_names(params)
        self._recentre = True
        self.open_case(params, origin)
        self.simulate()

    @property
    def busy(self) -> bool:
        """True while a job runs on this tab's worker."""
        return self._worker.busy

    def hold_ranges(self) -> None:
        """Keep the sliders' ranges as they are at the next run (a loaded demo state set them)."""
        self._recentre = False

    def run_with_plant(self, params: DriveParams, plant_J_L: float | None) -> None:
        """On the worker: simulate ``params`` on a plant with load inertia ``plant_J_L`` [kg·m²] (None: the model's)."""
        self._plant_J_L = plant_J_L
        self.run(params, keep_plant=True)

    def _use_recommended_k(self) -> None:
        k_rec = recommended_K(self.case.comparison.derived)
        if k_rec is not None:
            self.inputs.set_value("controller.K", k_rec)
            self.simulate()

    def _use_T_c_min(self) -> None:
        T_c = T_c_advice(self.case.comparison.derived)
        if T_c is not None:
            self.inputs.set_T_c(T_c)
            self.simulate()

    # ---- feedback -----------------------------------------------------------------------------
    def show_text(self, status: bool = True) -> None:
        """Show the derived values, verdicts and status of the current case."""
        case = self.case
        d = case.comparison.derived
        axis = axis_markdown(case.params, self.inputs.rated_derived, case.origin)
        assign(self.derived, content=derived_markdown(d) + (f"\n\n{axis}" if axis else ""))
        self.optimum.show(case.comparison)
        self.inputs.show_T_c_in_force(d.profile.T_c)
        if status:  # not during a drag: the sliders stand where the user's pointer holds them
            self.tuning.show(d, case.plant_J_L, recentre=self._recentre)
            self._recentre = False
            if self.demo_link is not None:  # a reload of the page, or its address sent on, opens this demo
                self.demo_link.remember()
            if self.results is not None:  # the K sweep of this run, after it (yields to the next job)
                self.results.k_sweep.schedule(self._worker.submit_tail, self._worker.tail_checkpoint,
                                              case.comparison, case.plant_J_L)
        nameplate = self.inputs.nameplate_warnings(case.params.motor)
        self.verdicts.show(case.comparison, case.error, nameplate)
        if status:
            self.status.content = f"Ready — {case.runs} run(s) in this session. Preset: {md_text(case.origin)}."

    def _reject(self, message: str) -> None:
        self._state.refused(message)
        self.verdicts.reject(message)
        self._client.add_notification("Input rejected — nothing simulated", message, color="red",
                                      auto_close_seconds=12.0)

    def job_failed(self, exc: Exception) -> None:
        """Report a failed job (the worker's error callback): cancelled, refused input or internal error."""
        if isinstance(exc, Cancelled):
            with contextlib.suppress(Exception):
                self.status.content = "Cancelled — the previous results are kept."
            return
        if isinstance(exc, ValueError):
            self._reject(str(exc))
        else:
            traceback.print_exception(exc, file=sys.stderr)
            self._client.add_notification("Internal error", f"{type(exc).__name__}: {exc}", color="red")
        with contextlib.suppress(Exception):  # the client may be gone
            self.status.content = f"Ready — {self.case.runs} run(s) in this session."

    def set_busy(self, busy: bool) -> None:
        """Enable or disable the run buttons (the worker's busy callback)."""
        if not busy:
            self.tuner.resume()  # a slider moved during the run: its latest value
        self.simulate_button.disabled = busy
        self.design_button.disabled = busy
        self.cancel_button.visible = busy
        if self.results is not None:
            self.results.sweep_button.disabled = busy
        if busy:
            self.status.content = "Working…"

    def export_state(self) -> Comparison:
        """Return the simulated case if the page shows it; else raise ExportRefusedError saying what differs."""
        try:
            shown = self.inputs.collect()
        except ValueError as exc:
            raise ExportRefusedError(f"The inputs shown are not valid, so nothing was exported: {exc}") from None
        comparison = self.case.comparison
        if self.case.plant_J_L is not None:
            raise ExportRefusedError(f"The run shown has the J_L slider's plant (J_L = {self.case.plant_J_L:.4g} "
                                     f"kg·m², model {comparison.derived.params.load.J_L:.4g} kg·m²), which no export "
                                     "describes — press Simulate to run the typed inputs, then export.")
        changed = uncommitted(shown, comparison.derived.params)
        if changed:
            raise ExportRefusedError("Inputs edited but not simulated — press Simulate (or wait for the run in "
                                     "progress), then export. Not committed: " + "; ".join(changed))
        return comparison


__all__ = ["OBJECTIVE_LABELS", "PositionTab", "comparison_or_derived"]
