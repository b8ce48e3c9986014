"""The commissioning web UI's page and server: config, layout, CSS, tabs; one :class:`Session` per browser tab.

``server.gui`` is shared by every client, so nothing per-user lives there: each connection gets
its own case, inputs, results, worker thread and replay. A session composes the page — the control
panel docked left with the two mode tabs (:mod:`app.ui.position_tab`, :mod:`app.ui.bldc_tab`), the
results panel docked right (:mod:`app.ui.results`) with the studies (:mod:`app.ui.studies`), the 3D
canvas between them — and sizes it from the window (:mod:`app.ui.layout`). Simulations run on the
session's worker (never on the GUI event loop); a second Simulate while one runs is refused.
Studies (robustness, multi-axis, Table-1 sweeps) share the server's slots (:mod:`app.ui.studies_queue`).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import viser

from pmsm_commissioning.app.io.presets import list_presets_of
from pmsm_commissioning.app.threads import limit_blas_threads, release_memory
from pmsm_commissioning.app.ui.bldc_results import follow_tabs_js
from pmsm_commissioning.app.ui.bldc_tab import add_bldc_tab, warm_bldc
from pmsm_commissioning.app.ui.case import Case, CaseState
from pmsm_commissioning.app.ui.demo_link import DemoLink
from pmsm_commissioning.app.ui.demo_view import PageViewProbe
from pmsm_commissioning.app.ui.figure_export import FigureExport
from pmsm_commissioning.app.ui.files import FilesPanel
from pmsm_commissioning.app.ui.inputs import InputsPanel
from pmsm_commissioning.app.ui.layout import (
    LEGIBILITY_CSS,
    PanelLayout,
    WindowFit,
    hide_field_js,
    install_css_js,
    page_address,
    page_css,
    page_marks_js,
    window_report_js,
)
from pmsm_commissioning.app.ui.log import LogPanel
from pmsm_commissioning.app.ui.plotly_js import use_basic_plotly
from pmsm_commissioning.app.ui.position_tab import PositionTab
from pmsm_commissioning.app.ui.replay import prebuild_figures
from pmsm_commissioning.app.ui.results import ResultsPanel, prebuild_results
from pmsm_commissioning.app.ui.runs import comparison_or_derived
from pmsm_commissioning.app.ui.scene import RotorScene, aim_camera
from pmsm_commissioning.app.ui.studies import StudiesSection
from pmsm_commissioning.app.ui.studies_queue import StudySlots
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.app.ui.viser_adapter import figure_json_shown, run_script, warm_icons, widget_id
from pmsm_commissioning.app.ui.web_guard import Guard, guarded
from pmsm_commissioning.app.ui.worker import Worker
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import Comparison, start_run_threads


@dataclass
class AppConfig:
    """Server-wide settings; ``initial`` is simulated once and shared read-only by new sessions."""

    params: DriveParams
    origin: str
    scene_3d: bool = True
    _initial: Comparison | None = None
    _lock: threading.Lock = field(default_factory=threading.Lock)
    sessions: dict[int, Session] = field(default_factory=dict)
    #: Clients that left while their page was still being built (never registered, closed once built).
    gone: set[int] = field(default_factory=set)
    _sessions_lock: threading.Lock = field(default_factory=threading.Lock)
    guard: Guard | None = None
    slots: StudySlots = field(default_factory=StudySlots.for_machine)

    def register(self, client_id: int, session: Session) -> bool:
        """Register a built page; return False when its client left while it was built (it is then closed)."""
        with self._sessions_lock:
            gone = client_id in self.gone
            self.gone.discard(client_id)
            if not gone:
                self.sessions[client_id] = session
        return not gone

    def unregister(self, client_id: int) -> Session | None:
        """Remove a leaving client's page and return it; None if still being built (closed once it is)."""
        with self._sessions_lock:
            session = self.sessions.pop(client_id, None)
            if session is None:
                self.gone.add(client_id)
        return session

    def initial(self) -> Comparison:
        """Return the comparison of the start-up preset (computed on first use)."""
        with self._lock:
            if self._initial is None:
                self._initial = comparison_or_derived(self.params, optimum=True)  # the toggle's default
            return self._initial


#: The Table-1 sweep's label as a study.
SWEEP = "Table-1 sweep"
#: Delay from a page's disconnect to returning freed memory to the system [s] (its job stops by then).
RELEASE_AFTER_S = 2.0


class Session:
    """One browser tab's page: its case, its worker, the two mode tabs and the results panel."""

    def __init__(self, client: viser.ClientHandle, config: AppConfig) -> None:
        self.client, self.gui = client, client.gui
        self.state = CaseState(Case(config.params, config.origin, config.initial()))
        self.slots = config.slots
        self.worker = Worker(lambda busy: self.tab.set_busy(busy), lambda exc: self.tab.job_failed(exc),
                             name=f"ui-client-{client.client_id}", slots=config.slots, on_queued=self._queued)
        scene = RotorScene(client.scene) if config.scene_3d else None
        self._layout(scene)  # the results panel shows the start-up comparison from its first message
        self.tab.show_text()

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
            # the marks before the panels: a panel drawn before them would take its width for a frame
            run_script(gui, page_marks_js((widget_id(self._window_probe),)))
            use_basic_plotly(gui)  # before the first add_plotly: 0.45 MB instead of 1.7 MB on the wire
            gui.main_panel.dock_left()
            tabs = gui.add_tab_group()
            with tabs.add_tab("Position drive (FDSMC)"):
                self.tab = PositionTab(self.client, self.state, self.worker)
            self.results = ResultsPanel(self.client, self.state.current.comparison, scene, self._sweep,
                                        on_3d=lambda shown: self.fit.set_3d(shown))
            self.tab.results = self.results
            self.results.panel.dock_right()
            self.studies = StudiesSection(self.tab, self.worker.as_study, self.slots.processes_per_study)
            self.bldc = add_bldc_tab(self.client, tabs, self.tab.submit, self.results.panel, self.worker)
            with self.results.panel.add_tab("Share", viser.Icon.SHARE):
                self.export = FigureExport(gui, self._figure_jsons)
            self.fit = WindowFit(self._apply_layout)
            self.tab.demo_files.probe = probe = PageViewProbe(gui)  # outside the mode tabs: in every mode
            run_script(gui, hide_field_js(widget_id(probe.field)))
            self.tab.demo_link = link = DemoLink(self.client, self.tab.demo_files)  # a reload keeps the demo
            probe.on_view(lambda view: self.results.tab_shown(view.results_tab))  # its figures, if not sent
            probe.on_view(lambda _: link.remember())  # a tab chosen: the address names it too
            if scene is not None:
                aim_camera(self.client.camera)
        self._window_probe.on_update(lambda _: self._window_reported(self._window_probe.value))
        run_script(gui, window_report_js(widget_id(self._window_probe)))
        run_script(gui, follow_tabs_js())
        run_script(gui, install_css_js(LEGIBILITY_CSS, "app-legibility-style"))

    def _window_reported(self, text: str) -> None:
        """Fit the panels to the window the page reported; open the demo its address names (first report)."""
        self.fit.window_reported(text)
        self.tab.demo_link.opened(page_address(text))

    def _figure_jsons(self) -> list[str]:
        """Return the JSON of every figure the Share tab offers (the results panel's: of the run in force)."""
        b = self.bldc.results
        return [*self.results.figure_jsons(), *(figure_json_shown(h) for h in (
            b.speed, b.torque, b.antiwindup, b.sigma, b.currents, b.emf, b.dqx, b.reach))]

    def _sweep(self, T_m_values: list[float]) -> None:
        """Start the Table-1 sweep as a study (it waits for a server-wide slot)."""
        with self.worker.as_study(SWEEP):
            self.tab.sweep(T_m_values)

    def _queued(self, label: str, ahead: int) -> None:
        """Say on the status line, and in the study's tab, that the study ``label`` waits (worker thread)."""
        text = md_text(self.slots.queued_text(label, ahead))
        self.tab.say(text)
        self.studies.queued(label, text)

    def _apply_layout(self, layout: PanelLayout) -> None:
        self.results.fit(layout)  # the panel widths come from the page's CSS, not set_width
        if layout.show_3d != self._style_3d:
            self._install_page_css(layout.show_3d)

    def _install_page_css(self, show_3d: bool) -> None:
        """Put the page's CSS (:func:`app.ui.layout.page_css`) for the 3D view shown or folded into the page."""
        self._style_3d = show_3d
        run_script(self.gui, install_css_js(page_css(show_3d)))

    # ---- what tests and scripts read of a session ---------------------------------------------
    @property
    def case(self) -> Case:
        """The current case (frozen snapshot)."""
        return self.state.current

    @property
    def params(self) -> DriveParams:
        """The committed inputs."""
        return self.state.current.params

    @property
    def origin(self) -> str:
        """Where the committed inputs came from."""
        return self.state.current.origin

    @property
    def comparison(self) -> Comparison:
        """The comparison shown."""
        return self.state.current.comparison

    @property
    def error(self) -> str | None:
        """The last input refusal (None after a successful run)."""
        return self.state.current.error

    @property
    def runs(self) -> int:
        """Runs done in this session."""
        return self.state.current.runs

    @property
    def inputs(self) -> InputsPanel:
        """The position tab's inputs."""
        return self.tab.inputs

    @property
    def files(self) -> FilesPanel:
        """The position tab's files panel (export, import)."""
        return self.tab.files

    @property
    def log_panel(self) -> LogPanel:
        """The position tab's drive-log panel."""
        return self.tab.log_panel

    @property
    def preset(self) -> viser.GuiDropdownHandle:
        """The position tab's preset dropdown."""
        return self.tab.preset

    def simulate(self) -> bool:
        """Commit the position tab's inputs and simulate them (see :meth:`PositionTab.simulate`)."""
        return self.tab.simulate()

    def design(self) -> bool:
        """Design for the position tab's drive (see :meth:`PositionTab.design`)."""
        return self.tab.design()

    def cancel(self) -> bool:
        """Cancel the running job; False if nothing runs."""
        return self.tab.cancel_run()

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
    start_run_threads()  # at normal priority, before any study's lowered thread could start one
    guard = guard or Guard.for_host(host)
    with guarded(guard):
        server = viser.ViserServer(host=host, port=port, verbose=False)
    server.gui.set_panel_label("PMSM commissioning (FDSMC)")
    if not environment_map:  # the HDRI stalls software WebGL for seconds
        server.scene.configure_environment_map(hdri=None)
    config = AppConfig(params, origin, scene_3d, guard=guard)
    # the first page must not wait for the kernels' first load, the start-up run or its figures
    prebuild_figures(config.initial())
    prebuild_results(config.initial())
    list_presets_of("position")  # the preset files read and parsed once (each page lists them: ≈ 70 ms)
    warm_icons()
    warm_bldc()

    @server.on_client_connect
    def _(client: viser.ClientHandle) -> None:
        session = Session(client, config)
        if not config.register(client.client_id, session):  # it left while its page was built
            session.close()

    @server.on_client_disconnect
    def _(client: viser.ClientHandle) -> None:
        session = config.unregister(client.client_id)
        if session is not None:
            session.close()
            # once its job has stopped (next checkpoint), the page's memory goes back to the system
            threading.Timer(RELEASE_AFTER_S, release_memory).start()

    return server, config


__all__ = ["AppConfig", "Session", "comparison_or_derived", "create_server"]
