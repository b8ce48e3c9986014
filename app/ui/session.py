"""The commissioning web UI: one :class:`Session` per browser tab, all state on ``client.gui``.

``server.gui`` is shared by every client, so nothing per-user lives there: each connection gets
its own inputs, results, worker thread and replay. Simulations run on the session's worker (never
on the GUI event loop); a second Simulate while one runs is refused.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field

import viser

from app.io.preset_modes import list_presets_of, load_mode_preset, require_mode
from app.threads import limit_blas_threads
from app.ui.bldc import add_bldc_tab
from app.ui.files import ExportRefusedError, FilesPanel, uncommitted
from app.ui.inputs import InputError, InputsPanel
from app.ui.layout import PanelLayout, WindowFit, install_css_js, page_css, window_report_js
from app.ui.log import LogPanel
from app.ui.plotly_js import run_script, use_basic_plotly
from app.ui.props import assign
from app.ui.results import ResultsPanel
from app.ui.scene import RotorScene, aim_camera
from app.ui.studies import OptimumToggle, StudiesSection
from app.ui.text import checked_choice, derived_markdown, design_markdown, md_text
from app.ui.tuning import LiveTuning, TuneRunner
from app.ui.verdict_panel import VerdictPanel
from app.ui.web_guard import Guard, guarded
from app.ui.worker import Cancelled, Worker
from control.fdsmc.derivations import derive
from control.fdsmc.params import DriveParams
from sim.fdsmc.engine import COMPARATORS, CONTROLLERS, PAPER_TABLE1, Comparison, compare, table1_sweep
from sim.fdsmc.objective import OBJECTIVES, design_for
from sim.fdsmc.verdicts import T_c_advice, recommended_K

#: The page's words for the design objectives (same order as :data:`sim.fdsmc.objective.OBJECTIVES`).
OBJECTIVE_LABELS = ("minimum net electrical energy", "minimum friction (paper)")


def comparison_or_derived(params: DriveParams, optimum: bool = False) -> Comparison:
    """Simulate both controllers (and the tracked optimum if ``optimum``).

    For an infeasible case, return the derivations alone (no runs).
    """
    d = derive(params)  # a ParameterError here is an input error for the caller
    if not d.profile.feasible:
        return Comparison(d, None, None, None, None)
    return compare(params, COMPARATORS if optimum else CONTROLLERS, derived=d)


@dataclass
class AppConfig:
    """Server-wide settings; ``initial`` is simulated once and shared read-only by new sessions."""

    params: DriveParams
    origin: str
    scene_3d: bool = True
    _initial: Comparison | None = None
    _lock: threading.Lock = field(default_factory=threading.Lock)
    sessions: dict[int, Session] = field(default_factory=dict)
    guard: Guard | None = None

    def initial(self) -> Comparison:
        """Return the comparison of the start-up preset (computed on first use)."""
        with self._lock:
            if self._initial is None:
                self._initial = comparison_or_derived(self.params, optimum=True)  # the toggle's default
            return self._initial


class Session:
    """Everything one browser tab sees and does."""

    def __init__(self, client: viser.ClientHandle, config: AppConfig) -> None:
        self.client, self.gui = client, client.gui
        self.params, self.origin = config.params, config.origin
        self.comparison = config.initial()
        self.error: str | None = None
        self.runs = 0
        self._recentre = True
        self.worker = Worker(self._set_busy, self._job_failed, name=f"ui-client-{client.client_id}")
        self.tuner = TuneRunner(self.worker, self._run_latest, self._tuned)
        scene = RotorScene(client.scene) if config.scene_3d else None
        self._layout(scene)  # the results panel shows the start-up comparison from its first message
        self._show_text()

    # ---- layout -------------------------------------------------------------------------------
    def _layout(self, scene: RotorScene | None) -> None:
        """Dock the control panel left, the results panel right, the 3D canvas between them.

        The page's CSS sizes the panels from the window's width; the overview plot's height
        follows the window size the page reports into a hidden field (:mod:`app.ui.layout`).
        """
        with self.client.atomic():  # one batch: the page CSS, the panels and their docking arrive together
            gui = self.gui
            gui.configure_theme(control_width="large", show_share_button=False, show_logo=False)
            self._window_probe = gui.add_text("window [px]", "")
            self._install_page_css(show_3d=False)
            use_basic_plotly(gui)  # before the first add_plotly: 0.45 MB instead of 1.7 MB on the wire
            gui.main_panel.dock_left()
            tabs = gui.add_tab_group()
            with tabs.add_tab("Position drive (FDSMC)"):
                self._controls()
            self.results = ResultsPanel(self.client, self.comparison, scene, self.sweep,
                                        on_3d=lambda shown: self.fit.set_3d(shown))
            self.results.panel.dock_right()
            self.studies = StudiesSection(self)
            add_bldc_tab(self.client, tabs, self.submit, self.results.panel, self.worker)
            self.fit = WindowFit(self._apply_layout)
            if scene is not None:
                aim_camera(self.client.camera)
        self._window_probe.on_update(lambda _: self.fit.window_reported(self._window_probe.value))
        run_script(gui, window_report_js(self._window_probe._impl.uuid))

    def _apply_layout(self, layout: PanelLayout) -> None:
        self.results.fit(layout)  # the panel widths come from the page's CSS, not set_width
        if layout.show_3d != self._style_3d:
            self._install_page_css(layout.show_3d)

    def _install_page_css(self, show_3d: bool) -> None:
        """Put the page's CSS (:func:`app.ui.layout.page_css`) for the 3D view shown or folded into the page."""
        self._style_3d = show_3d
        run_script(self.gui, install_css_js(page_css(self._window_probe._impl.uuid, show_3d)))

    def _controls(self) -> None:
        gui = self.gui
        names = self._preset_names = tuple(list_presets_of("position"))
        self.preset = gui.add_dropdown("Preset", names, initial_value=self.origin if self.origin in names
                                       else names[0])
        self.preset.on_update(self._preset_chosen)
        self._preset_shown = self.preset.value
        self.files = FilesPanel(self.client, self._export_state, self._imported, self.params)
        self.log_panel = LogPanel(self)
        self.simulate_button = gui.add_button("Simulate", icon=viser.Icon.PLAYER_PLAY, color="green")
        self.simulate_button.on_click(lambda _: self.simulate())
        self.design_button = gui.add_button("Design for this drive", icon=viser.Icon.WAND, color="blue",
                                            hint="α_max, T_m, K and T_c for this nameplate, load and inverter, "
                                                 "verified by simulation")
        self.design_button.on_click(lambda _: self.design())
        self.objective = gui.add_dropdown("Design objective", OBJECTIVE_LABELS,
                                          hint="net electrical input (copper + friction): the α that draws least; "
                                               "friction: the paper's profile at the torque limit")
        self.design_note = gui.add_markdown("")
        self.optimum = OptimumToggle(gui, self.simulate)
        self.cancel_button = gui.add_button("Cancel", icon=viser.Icon.PLAYER_STOP, color="red", visible=False)
        self.cancel_button.on_click(lambda _: self.cancel())
        self.status = gui.add_markdown("Ready.")
        self.verdicts = VerdictPanel(gui, self._use_recommended_k, self._use_T_c_min)
        self.tuning = LiveTuning(gui, self._apply_knob, self.tuner.request)
        with gui.add_form(None) as form:
            self.inputs = InputsPanel(gui, self.params)
        form.on_submit(lambda _: self.simulate())
        with gui.add_folder("Derived values", expand_by_default=True):
            self.derived = gui.add_markdown("")

    # ---- actions ------------------------------------------------------------------------------
    def simulate(self) -> bool:
        """Commit the inputs and simulate both controllers on the worker; False if not started."""
        return self._commit_and_submit(self._run)

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
        if self.worker.busy:
            return self.submit(lambda: None)  # refused, with the "busy" note
        self.results.replay.pause()  # frees the browser for the new result
        return self.submit(lambda: job(params))

    def _run_design(self, params: DriveParams) -> None:
        self.status.content = "Designing and verifying…"
        objective = OBJECTIVES[OBJECTIVE_LABELS.index(checked_choice(self.objective.value, OBJECTIVE_LABELS,
                                                                     "Design objective"))]
        dd = design_for(params, objective).design
        self.inputs.populate(dd.params)
        self.params, self.error, self._recentre = dd.params, None, True
        self.comparison = (None if self.optimum.wanted else dd.comparison) or comparison_or_derived(
            dd.params, self.optimum.wanted)
        self.runs += 1
        self.design_note.content = design_markdown(dd)
        if self.comparison.fdsmc is not None:
            self.results.show(self.comparison)
        self._show_text()

    def submit(self, fn: Callable[[], None]) -> bool:
        """Run ``fn`` on this client's worker (one job at a time); False (with a note) if busy."""
        if self.worker.submit(fn) is None:
            self.client.add_notification("Busy", "A run is still in progress — wait for it to finish.",
                                         color="yellow", auto_close_seconds=4.0)
            return False
        return True

    def cancel(self) -> bool:
        """Cancel the running job (its result is discarded); False if nothing runs."""
        if not self.worker.cancel():
            return False
        self.status.content = "Cancelling…"
        return True

    def _run_latest(self) -> bool:
        """Simulate the inputs panel's values, overview only (a slider moves); False on an input error."""
        try:
            params = self.inputs.collect()
        except InputError as exc:
            self._reject(str(exc))
            return False
        self._run(params, autoplay=False, overview_only=True)
        return True

    def _tuned(self) -> None:
        """Draw the rest of the results of the last run once a drag has stopped."""
        if self.comparison is not None and self.comparison.fdsmc is not None:
            self.results.show_rest()
        self._show_text()

    def _apply_knob(self, key: str, value_si: float) -> None:
        """Write a live-tuning slider's value into the inputs panel, as if typed."""
        if key == "controller.T_c":
            self.inputs.set_T_c(value_si)
        else:
            self.inputs.set_value(key, value_si)

    def _run(self, params: DriveParams, autoplay: bool = True, overview_only: bool = False) -> None:
        """Simulate ``params`` and show the results (``overview_only``: a live-tuning run, see :meth:`_run_latest`)."""
        if not overview_only:
            self.status.content = "Simulating…"
        assign(self.design_note, content="")
        self.worker.checkpoint()
        comparison = comparison_or_derived(params, self.optimum.wanted)  # ParameterError → _job_failed
        self.worker.checkpoint()
        self.params, self.comparison, self.error = params, comparison, None
        self.runs += 1
        if comparison.fdsmc is not None:
            self.results.show(comparison, autoplay=autoplay, overview_only=overview_only)
        else:
            self.results.show_derived_only(comparison)
        self._show_text(status=not overview_only)

    def sweep(self, T_m_values: list[float]) -> None:
        """Run the Table-1 sweep over ``T_m_values`` [s] on the worker with a progress bar."""
        params = self.params

        def progress(done: int, total: int) -> None:
            self.worker.checkpoint()
            self.results.set_progress(done, total)

        def job() -> None:
            progress(0, len(T_m_values))
            rows = table1_sweep(params, T_m_values, progress=progress)
            self.results.show_table1(rows, PAPER_TABLE1)

        self.submit(job)

    def _preset_chosen(self, event: viser.GuiEvent) -> None:
        if event.client is None:
            return
        try:
            name = checked_choice(self.preset.value, self._preset_names, "Preset")
            params = load_mode_preset(name, mode="position")
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
        self.origin, self._recentre = origin, True
        self.inputs.populate(params)
        self.params = params
        self.simulate()

    def _use_recommended_k(self) -> None:
        k_rec = recommended_K(self.comparison.derived)
        if k_rec is not None:
            self.inputs.set_value("controller.K", k_rec)
            self.simulate()

    def _use_T_c_min(self) -> None:
        T_c = T_c_advice(self.comparison.derived)
        if T_c is not None:
            self.inputs.set_T_c(T_c)
            self.simulate()

    # ---- feedback -----------------------------------------------------------------------------
    def _show_text(self, status: bool = True) -> None:
        d = self.comparison.derived
        assign(self.derived, content=derived_markdown(d))
        self.optimum.show(self.comparison)
        self.inputs.show_T_c_in_force(d.profile.T_c)
        if self._recentre:
            self._recentre = False
            self.tuning.centre(self.params, d.profile.T_c)
        nameplate = self.inputs.nameplate_warnings(self.params.motor)
        self.verdicts.show(self.comparison, self.params.controller.K, self.error, nameplate)
        if status:
            self.status.content = f"Ready — {self.runs} run(s) in this session. Preset: {md_text(self.origin)}."

    def _reject(self, message: str) -> None:
        self.error = message
        self.verdicts.reject(message)
        self.client.add_notification("Input rejected — nothing simulated", message, color="red",
                                     auto_close_seconds=12.0)

    def _job_failed(self, exc: Exception) -> None:
        if isinstance(exc, Cancelled):
            with contextlib.suppress(Exception):
                self.status.content = "Cancelled — the previous results are kept."
            return
        if isinstance(exc, ValueError):
            self._reject(str(exc))
        else:
            traceback.print_exception(exc, file=sys.stderr)
            self.client.add_notification("Internal error", f"{type(exc).__name__}: {exc}", color="red")
        self._show_text_safely()

    def _show_text_safely(self) -> None:
        with contextlib.suppress(Exception):  # the client may be gone
            self.status.content = f"Ready — {self.runs} run(s) in this session."

    def _set_busy(self, busy: bool) -> None:
        if not busy:
            self.tuner.resume()  # a slider moved during the run: its latest value
        self.simulate_button.disabled = busy
        self.design_button.disabled = busy
        self.cancel_button.visible = busy
        self.results.sweep_button.disabled = busy
        if busy:
            self.status.content = "Working…"

    def _export_state(self) -> Comparison:
        """Return the simulated case if the page shows it; else raise ExportRefusedError saying what differs."""
        try:
            shown = self.inputs.collect()
        except ValueError as exc:
            raise ExportRefusedError(f"The inputs shown are not valid, so nothing was exported: {exc}") from None
        changed = uncommitted(shown, self.comparison.derived.params)
        if changed:
            raise ExportRefusedError("Inputs edited but not simulated — press Simulate (or wait for the run in "
                                     "progress), then export. Not committed: " + "; ".join(changed))
        return self.comparison

    def close(self) -> None:
        """Stop the worker and the replay (client disconnected)."""
        self.worker.close()
        self.results.replay.close()


def create_server(params: DriveParams, origin: str, host: str = "127.0.0.1", port: int = 8080,
                  scene_3d: bool = True, environment_map: bool = False,
                  guard: Guard | None = None) -> tuple[viser.ViserServer, AppConfig]:
    """Start the viser server with one :class:`Session` per connecting client.

    Parameters
    ----------
    params : DriveParams  Start-up inputs of every new session.
    origin : str          Preset name or file they came from.
    host, port            Bind address; viser moves to the next free port if taken (see ``get_port``).
    scene_3d : bool       Show the 3D rotors (tests switch it off).
    environment_map : bool  viser's HDRI background (off by default: it stalls software WebGL).
    guard : Guard or None   Origin/Host/token rules (default: same-host origins on ``host``, no token).

    Returns
    -------
    (viser.ViserServer, AppConfig)
        The running server and its settings (``config.sessions`` maps client id → Session).
    """
    limit_blas_threads()
    guard = guard or Guard.for_host(host)
    with guarded(guard):
        server = viser.ViserServer(host=host, port=port, verbose=False)
    server.gui.set_panel_label("PMSM commissioning (FDSMC)")
    if not environment_map:  # the HDRI stalls software WebGL for seconds
        server.scene.configure_environment_map(hdri=None)
    config = AppConfig(params, origin, scene_3d, guard=guard)

    @server.on_client_connect
    def _(client: viser.ClientHandle) -> None:
        config.sessions[client.client_id] = Session(client, config)

    @server.on_client_disconnect
    def _(client: viser.ClientHandle) -> None:
        session = config.sessions.pop(client.client_id, None)
        if session is not None:
            session.close()

    return server, config


__all__ = ["AppConfig", "Session", "comparison_or_derived", "create_server"]
