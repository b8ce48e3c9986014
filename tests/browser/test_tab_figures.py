"""The time plots go out only while their tab is shown: a new page gets none of them (nor the energy and
stock-route figures) until their tab is chosen, then the start-up run's, once; a Simulate on the Overview
sends none; choosing *Time plots* then draws the run just simulated (sent once), a Simulate while they
are shown updates them at once, and a demo state restoring the *Time plots* tab shows its own run there.

The page's websocket frames are read as they arrive (decoded like viser's client does) and each
figure message counted by its ``layout.meta.id``.
"""

from __future__ import annotations

import dataclasses
import json
import time
from typing import Any

import pytest

from pmsm_commissioning.app.ui.demo_state import DemoState, PageView, dumps_state
from tests.browser.conftest import TIMEOUT_MS, click_tab, figure, session_of, set_number, wait_for_layout
from tests.page_client import decode_frame

T_M_FIELD = "T_m manoeuvre time [s]"
#: Manoeuvre times typed in turn [s]: each gives another ω_p (eq. (60)), the start-up one is 1 s.
T_M = (0.8, 1.3, 0.7)
#: The tabs whose figures wait for the tab, and those figures (the Overview and the K sweep go out with
#: the page and with every run).
TAB_IDS = {"Time plots": ("time_plots",), "Energy": ("energy_time", "energy_bars"), "Stock drive": ("stock_route",)}
WAITING = tuple(fid for ids in TAB_IDS.values() for fid in ids)
DRAWN = ("(id) => [...document.querySelectorAll('.js-plotly-plot')]"
         ".some(e => e.layout && e.layout.meta && e.layout.meta.id === id)")
PHASE_DRAWN = ("() => [...document.querySelectorAll('.js-plotly-plot')]"
               ".some(e => e.layout && e.layout.meta && e.layout.meta.id === 'phase_plane')")


class Figures:
    """The figure messages a page received, in order: their ``layout.meta.id``."""

    def __init__(self, page: Any) -> None:
        self.ids: list[str] = []
        page.on("websocket", lambda ws: ws.on("framereceived", self._frame))

    def _frame(self, payload: Any) -> None:
        if not isinstance(payload, bytes):
            return
        for m in decode_frame(payload):
            fig = (m.get("props") or {}).get("_plotly_json_str") or (m.get("updates") or {}).get("_plotly_json_str")
            meta = json.loads(fig).get("layout", {}).get("meta") if fig else None
            if meta and "id" in meta:
                self.ids.append(meta["id"])

    def since(self, n: int) -> list[str]:
        """The figure ids received after the first ``n``."""
        return self.ids[n:]


def _open(browser: Any, ui: Any) -> tuple[Any, Any, Figures, Any]:
    """A 1280×720 page whose frames are counted from its first one (the socket opens at page load)."""
    context = browser.new_context(viewport={"width": 1280, "height": 720}, accept_downloads=True)
    page = context.new_page()
    page.set_default_timeout(TIMEOUT_MS)
    figures = Figures(page)
    before = set(ui.config.sessions)
    page.goto(ui.url)
    page.get_by_role("button", name="Simulate").wait_for(timeout=3 * TIMEOUT_MS)
    page.wait_for_function(PHASE_DRAWN, timeout=3 * TIMEOUT_MS)
    session = session_of(page, ui, before)
    wait_for_layout(page, session)
    return context, page, figures, session


def _until(page: Any, condition: Any, what: str, timeout_s: float = 120.0) -> None:
    """Poll ``condition()`` (server state or frames received) while the page runs: a positive condition."""
    end = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < end, f"timed out waiting for {what}"
        page.wait_for_timeout(50)


def _simulate(page: Any, session: Any, figures: Figures, T_m: float) -> int:
    """Type ``T_m``, press Simulate and wait for the run's last message (its K sweep); the frames index before."""
    set_number(page, T_M_FIELD, T_m)
    runs, n = session.runs, len(figures.ids)
    page.get_by_role("button", name="Simulate").click()
    _until(page, lambda: session.runs > runs and not session.tab.busy, f"the run of T_m = {T_m} s")
    assert session.params.manoeuvre.T_m == T_m
    _until(page, lambda: "k_sweep" in figures.since(n), "the run's K sweep (sent after the rest of the run)")
    return n


def _omega_p_of(spec: dict[str, Any]) -> float:
    """ω_p of a time-plots figure's JSON (its reference line, eq. (60)) [rad/s]."""
    return abs(next(t for t in spec["data"] if t["name"].startswith("ω_p"))["y"][0])


def _omega_p_drawn(page: Any) -> float | None:
    """ω_p of the time plots drawn in the page (its reference line, eq. (60)) [rad/s]; None if not drawn."""
    fig = figure(page, "time_plots")
    refs = [t["y"] for t in fig["traces"] if t["name"].startswith("ω_p")] if fig else []
    return abs(refs[0][0]) if refs and refs[0] else None


def shows_the_time_plots_of(page: Any, session: Any) -> None:
    """Wait until the time plots drawn are those of the session's run in force (its ω_p, eq. (60))."""
    omega_p = session.comparison.derived.profile.omega_p
    page.wait_for_function("""(w) => { const el = [...document.querySelectorAll('.js-plotly-plot')]
        .find(e => e.layout && e.layout.meta && e.layout.meta.id === 'time_plots');
      const ref = el && el._fullData && el._fullData.find(t => t.name.startsWith('ω_p'));
      return !!ref && Math.abs(Math.abs(ref.y[0]) - w) <= 1e-6 * w; }""", arg=omega_p)
    assert abs(_omega_p_drawn(page) - omega_p) <= 1e-6 * omega_p


def _choose(page: Any, session: Any, tab: str) -> None:
    """Choose the results tab ``tab`` and wait until the server holds the page's report of it."""
    click_tab(page, tab)
    _until(page, lambda: session.tab.demo_files.probe.view.results_tab == tab, f"the page's report of {tab!r}")


def test_a_new_page_gets_a_tabs_figures_when_the_tab_is_chosen_once_those_of_the_start_up_run(browser, ui_server):
    context, page, figures, session = _open(browser, ui_server)
    try:
        _until(page, lambda: "k_sweep" in figures.ids, "the page's own K sweep")  # the page has all it gets
        assert session.comparison is ui_server.config.initial()
        assert "phase_plane" in figures.ids and not set(WAITING) & set(figures.ids), figures.ids
        for tab, ids in TAB_IDS.items():
            n = len(figures.ids)
            _choose(page, session, tab)
            _until(page, lambda ids=ids, n=n: set(ids) <= set(figures.since(n)), f"the figures of {tab!r}")
            for fid in ids:
                page.wait_for_function(DRAWN, arg=fid)
            if tab == "Time plots":
                shows_the_time_plots_of(page, session)  # the start-up run's (its ω_p)
        n = len(figures.ids)
        for tab in ("Overview", *TAB_IDS):  # chosen again: nothing sent again
            _choose(page, session, tab)
        page.wait_for_timeout(500)  # a figure sent after the report would arrive by now
        assert figures.since(n) == [], figures.since(n)
        assert sorted(f for f in figures.ids if f in WAITING) == sorted(WAITING)  # each once in all
    finally:
        context.close()


def test_the_time_plots_go_out_when_their_tab_is_chosen_and_with_each_run_while_shown(browser, ui_server):
    context, page, figures, session = _open(browser, ui_server)
    try:
        _until(page, lambda: "k_sweep" in figures.ids, "the page's own K sweep")
        n = _simulate(page, session, figures, T_M[0])  # on the Overview
        sent = figures.since(n)
        assert "phase_plane" in sent and "k_sweep" in sent  # what the Overview and the K demo show
        assert not set(WAITING) & set(sent), sent  # nothing of the tabs not shown
        exported = json.loads(session.export.figures()["time_plots"])  # the Share tab's: this run's, unsent
        assert _omega_p_of(exported) == pytest.approx(session.comparison.derived.profile.omega_p, rel=1e-6)
        assert "time_plots" not in figures.since(n)
        n = len(figures.ids)
        click_tab(page, "Time plots")
        shows_the_time_plots_of(page, session)  # the run just simulated, not the start-up one
        assert figures.since(n) == ["time_plots"]
        click_tab(page, "Overview")
        click_tab(page, "Time plots")  # chosen again: the same figure, not sent again
        n = _simulate(page, session, figures, T_M[1])  # while the time plots are shown
        shows_the_time_plots_of(page, session)
        sent = figures.since(n)
        assert sent.count("time_plots") == 1, sent  # this run's only: the tab chosen again sent nothing
        assert sent.index("time_plots") < sent.index("k_sweep")  # with the run, not after a tab choice
    finally:
        context.close()


def test_a_demo_state_restoring_the_time_plots_tab_shows_its_run_there(browser, ui_server):
    context, page, figures, session = _open(browser, ui_server)
    try:
        n = _simulate(page, session, figures, T_M[0])  # on the Overview: no time plots sent
        assert "time_plots" not in figures.since(n)
        params = session.params
        params = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=T_M[2]))
        state = DemoState(params, None, session.origin, {}, (), PageView("Position drive (FDSMC)", "Time plots", {}))
        runs = session.runs
        page.locator("input[type=file][accept^='.json']").set_input_files(
            files=[{"name": "lecture.json", "mimeType": "application/json", "buffer": dumps_state(state).encode()}])
        _until(page, lambda: session.runs > runs and not session.tab.busy, "the demo state's run")
        assert session.params.manoeuvre.T_m == T_M[2]
        page.wait_for_function("() => [...document.querySelectorAll('[role=\"tab\"][aria-selected=\"true\"]')]"
                               ".some(t => t.title === 'Time plots')")
        shows_the_time_plots_of(page, session)
    finally:
        context.close()
