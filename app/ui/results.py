"""The results panel (docked right, the rest of the window): overview, time plots, energy, Table 1.

The *Overview* tab is what a projector shows: one line of key numbers above one figure holding
the phase plane and a compact time plot (ω_r and Γ vs t), replayed together in the browser.

Only builds widgets and pushes figures made by the pure ``make_*_figure`` functions; the
simulations themselves run on the session's worker. The figures of the *Time plots*, *Energy* and
*Stock drive* tabs go out only while their tab is shown (:mod:`app.ui.tab_figures`), from the page's
opening on: a new page gets them when such a tab is first chosen. The overview, its key numbers and
the K sweep (the K demo) go out with the page and with every run.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import viser

from pmsm_commissioning.app.figures.fdsmc_comparison import runs, time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_energy import energy_bars_spec, energy_spec, make_table1_figure
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.figures.stock_route import stock_route_spec
from pmsm_commissioning.app.io.numbers import parse_T_m_list
from pmsm_commissioning.app.ui.k_sweep import KSweepView
from pmsm_commissioning.app.ui.layout import PanelLayout
from pmsm_commissioning.app.ui.paper_text import errata_html, table1_html
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.replay import Replay, overview_json, time_plots_json
from pmsm_commissioning.app.ui.savings import annual_savings, savings_markdown
from pmsm_commissioning.app.ui.scene import RotorScene
from pmsm_commissioning.app.ui.tab_figures import Build, TabFigures
from pmsm_commissioning.app.ui.text import key_numbers_html, stock_html
from pmsm_commissioning.app.ui.viser_adapter import add_figure, figure_json_shown, set_figure_json
from pmsm_commissioning.sim.fdsmc.table1 import PAPER_TABLE1, TABLE1_T_M

#: Plot height / width per figure [-].
ASPECT_PHASE, ASPECT_TIME, ASPECT_SMALL, ASPECT_STOCK = 0.72, 1.45, 0.55, 0.95


@functools.cache
def empty_table1_json() -> str:
    """JSON of the Table-1 figure before a sweep (the paper's rows only): built once per process.

    Building it with plotly's figure objects takes ≈ 60 ms, a fifth of a page's build.
    """
    return make_table1_figure([], PAPER_TABLE1).to_json()


def prebuild_results(comparison: Any) -> None:
    """Build what every new page's results panel shows of ``comparison`` (the start-up one) now, at server start.

    The empty Table-1 figure, and the stock drives' lines: their routes tuned for this case
    (≈ 90 ms, kept by :func:`sim.stock.tuning.tuned`), else a third of the first page's build.
    """
    empty_table1_json()
    if runs(comparison):
        stock_html(comparison)


def _when_simulated(spec: Callable[[Any], dict[str, Any]]) -> Build:
    """Return the builder of ``spec``'s figure JSON: None (the figure shown stays) for a comparison without runs."""
    return lambda comparison: figure_json(spec(comparison)) if runs(comparison) else None


#: The JSON of the tab figures of the start-up comparison, by figure: (comparison, JSON). Every new
#: page shows that comparison, so each of these is built once per server (when a page first
#: chooses its tab), not once per page.
_STARTUP: dict[str, tuple[Any, str | None]] = {}


#: The builders of the figures that wait for their tab, by ``layout.meta.id``.
_BUILDS: dict[str, Build] = {
    "time_plots": lambda comparison: figure_json(time_plots_spec(comparison)),
    "energy_time": _when_simulated(energy_spec), "energy_bars": _when_simulated(energy_bars_spec),
    "stock_route": _when_simulated(stock_route_spec)}
#: Where the start-up comparison's figure comes from if not from :data:`_BUILDS`: its time plots are
#: built at server start (:func:`app.ui.replay.prebuild_figures`).
_STARTUP_BUILDS: dict[str, Build] = {"time_plots": time_plots_json}


def _shared_for(startup: Any, name: str) -> Build:
    """Return the builder of the figure ``name``, taking that of the comparison ``startup`` from :data:`_STARTUP`.

    No lock: two pages choosing the tab at once may both build it (the same JSON); neither waits.
    """
    def build(comparison: Any) -> str | None:
        if comparison is not startup:
            return _BUILDS[name](comparison)
        kept = _STARTUP.get(name)
        if kept is None or kept[0] is not comparison:
            kept = _STARTUP[name] = (comparison, _STARTUP_BUILDS.get(name, _BUILDS[name])(comparison))
        return kept[1]
    return build


class ResultsPanel:
    """Right-hand panel with the result tabs of one client."""

    def __init__(self, client: viser.ClientHandle, comparison: Any, scene: RotorScene | None,
                 on_sweep: Callable[[list[float]], None],
                 on_3d: Callable[[bool], None] = lambda _: None) -> None:
        gui = client.gui
        self._on_sweep = on_sweep
        self._comparison = comparison
        self._rest_pending = False
        self.tab_figures = TabFigures(comparison)
        self.panel = gui.add_panel()
        phase_tab = self.panel.add_tab("Overview", viser.Icon.CHART_DOTS)
        time_tab = self.panel.add_tab("Time plots", viser.Icon.CHART_LINE)
        # the widgets carry the start-up comparison from their first message (app/ui/viser_adapter.py)
        overview, targets = overview_json(comparison)
        with phase_tab:
            self.key_numbers = gui.add_html(key_numbers_html(comparison))
            self.phase = add_figure(gui, overview, ASPECT_PHASE)
        with self.panel.add_tab("K sweep", viser.Icon.CHART_DOTS):
            self.k_sweep = KSweepView(gui)
        with time_tab:
            self.time_plots = self._tab_figure(gui, "Time plots", "time_plots", ASPECT_TIME)
        with phase_tab:
            self.replay = Replay(gui, self.phase, scene, (comparison, targets),
                                 flush=client.flush, on_3d=on_3d)
            with gui.add_folder("Paper errata for this figure", expand_by_default=False):
                gui.add_html(errata_html("overview"))
        with time_tab:
            gui.add_html(errata_html("time_plots"))
        with self.panel.add_tab("Energy", viser.Icon.BOLT):
            self.energy = self._tab_figure(gui, "Energy", "energy_time", ASPECT_SMALL)
            self.bars = self._tab_figure(gui, "Energy", "energy_bars", ASPECT_SMALL)
            self._build_savings(gui)
        with self.panel.add_tab("Stock drive", viser.Icon.ROUTE):
            self.stock_text = gui.add_html(stock_html(comparison) if runs(comparison) else "")
            self.stock = self._tab_figure(gui, "Stock drive", "stock_route", ASPECT_STOCK)
        with self.panel.add_tab("Table 1 sweep", viser.Icon.TABLE):
            self.t_m_list = gui.add_text("T_m list [s]", ", ".join(map(str, TABLE1_T_M)))
            self.sweep_button = gui.add_button("Run Table-1 sweep", icon=viser.Icon.PLAYER_PLAY)
            self.progress = gui.add_progress_bar(0.0, animated=False)
            self.table1_numbers = gui.add_html(table1_html([], PAPER_TABLE1))
            self.table1 = add_figure(gui, empty_table1_json(), ASPECT_SMALL)
            gui.add_html(errata_html("table1"))
        self.sweep_button.on_click(lambda _: self._sweep_clicked(client))

    def _tab_figure(self, gui: viser.GuiApi, tab: str, name: str, aspect: float) -> viser.GuiPlotlyHandle:
        """Add the figure ``name`` of ``tab``, empty: sent (the comparison in force) only while ``tab`` is shown."""
        handle = add_figure(gui, None, aspect)
        self.tab_figures.add(tab, handle, _shared_for(self._comparison, name))
        return handle

    def _build_savings(self, gui: viser.GuiApi) -> None:
        with gui.add_folder("Savings estimate (electrical input, per axis)"):
            self.cycles = gui.add_number("Cycles per hour [1/h]", 600.0, step=1.0)
            self.hours = gui.add_number("Hours per year [h]", 4000.0, step=10.0)
            self.price = gui.add_number("Energy price [€/kWh]", 0.25, step=0.01)
            for h in (self.cycles, self.hours, self.price):
                h.precision = 4
                h.on_update(lambda _: self._update_savings())
            self.savings = gui.add_markdown("")
        self._update_savings()

    def _update_savings(self) -> None:
        values = (self.cycles.value, self.hours.value, self.price.value)
        if any(not isinstance(v, int | float) or v < 0 for v in values):
            self.savings.content = "**Savings inputs must be numbers ≥ 0.**"
            return
        self.savings.content = savings_markdown(annual_savings(self._comparison, *values))

    def fit(self, layout: PanelLayout) -> None:
        """Size the overview plot for the window; the page's CSS sizes the panel (:mod:`app.ui.layout`)."""
        self.phase.aspect = layout.plot_aspect

    def show(self, comparison: Any, autoplay: bool = True, overview_only: bool = False,
             plant_J_L: float | None = None) -> None:
        """Draw a new comparison: key numbers and overview first (what the user waits for), then the rest.

        With ``overview_only`` (a slider being dragged) the other tabs keep their figures and the
        overview comes without its replay controls until :meth:`show_rest`; each redraw then sends
        only what the Overview tab shows, and the browser redraws it faster.
        """
        self._comparison = comparison
        assign(self.key_numbers, content=key_numbers_html(comparison))
        self.replay.plant_J_L = plant_J_L
        self.replay.load(comparison, autoplay=autoplay, light=overview_only)
        self._rest_pending = overview_only
        if not overview_only:
            self.show_rest()

    def show_rest(self) -> None:
        """Draw the rest of the comparison last shown: the overview's replay if pending, texts, the tabs' figures.

        The time plots, energy and stock-route figures go out now only if their tab is shown
        (:meth:`tab_shown` sends them when it is chosen).
        """
        comparison = self._comparison
        if self._rest_pending:
            self.replay.complete(comparison)
        self._rest_pending = False
        assign(self.stock_text, content=stock_html(comparison))
        self._update_savings()
        self.tab_figures.show(comparison)

    def show_derived_only(self, comparison: Any) -> None:
        """Show an infeasible case (no runs): the key numbers say so, the overview shows the boundary."""
        self.key_numbers.content = key_numbers_html(comparison)
        self.replay.load(comparison, autoplay=False)
        self.tab_figures.show(comparison)  # the time plots empty; the energy and stock figures stay

    def tab_shown(self, tab: str | None) -> None:
        """Send the figures of the results tab ``tab`` the page shows (None: unknown) for the comparison in force."""
        self.tab_figures.tab_shown(tab)

    def figure_jsons(self) -> list[str]:
        """Return the JSON of each figure of the panel for the comparison in force (not shown yet: built, not sent)."""
        deferred = [self.tab_figures.figure_json(h) for h in (self.time_plots, self.energy, self.bars)]
        return [figure_json_shown(self.phase), *deferred, figure_json_shown(self.table1)]

    def _sweep_clicked(self, client: viser.ClientHandle) -> None:
        try:
            values = parse_T_m_list(self.t_m_list.value, "Table 1 › T_m list")
        except ValueError as exc:
            client.add_notification("Table-1 sweep not started", str(exc), color="red",
                                    auto_close_seconds=10.0)
            return
        self._on_sweep(values)

    def set_progress(self, done: int, total: int) -> None:
        """Progress of the sweep [-]."""
        self.progress.value = 100.0 * done / max(total, 1)

    def show_table1(self, rows: list[Any], paper: dict[float, float]) -> None:
        """Draw the sweep result."""
        self.table1_numbers.content = table1_html(rows, paper)
        set_figure_json(self.table1, make_table1_figure(rows, paper).to_json())
