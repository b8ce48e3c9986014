"""The demo state brings back the page's view: a saved file holds the tabs shown and the overview's
zoom (reported by the page), and loading it selects those tabs and draws the overview at that zoom.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.ui.demo_state import PageView, loads_state
from tests.browser.conftest import click_tab, open_page, session_of, set_number

OVERVIEW = "[...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane')"
#: The phase-plane subplot's box in the page [px]: x, y, width, height.
BOX_JS = f"""() => {{ const el = {OVERVIEW}, r = el.getBoundingClientRect(), L = el._fullLayout;
  return [r.x + L.xaxis._offset, r.y + L.yaxis._offset, L.xaxis._length, L.yaxis._length]; }}"""
RESET_JS = f"() => window.Plotly.relayout({OVERVIEW}, {{'xaxis.autorange': true, 'yaxis.autorange': true}})"
RANGES_JS = f"() => {{ const el = {OVERVIEW}; return el ? [el.layout.xaxis.range, el.layout.yaxis.range] : null; }}"
#: True once the overview's phase plane shows the ranges ``z`` ([[x0, x1], [y0, y1]]).
AT_JS = f"""(z) => {{ const r = ({RANGES_JS})();
  return r !== null && r.every((p, i) => p.every((v, j) => Math.abs(v - z[i][j]) < 1e-9)); }}"""
SELECTED_JS = """() => [...document.querySelectorAll('[role="tab"][aria-selected="true"]')].map(t => t.title)"""


def _reported(page: Any, probe: Any, view: PageView) -> None:
    """Wait until the server holds ``view`` as the page's report."""
    for _ in range(200):
        if probe.view == view:
            return
        page.wait_for_timeout(25)
    raise AssertionError(f"the page reported {probe.view}, not {view}")


def _zoom_box(page: Any) -> dict[str, tuple[float, float]]:
    """Draw a zoom box with the mouse on the upper left of the phase plane; return the axes' new ranges."""
    x, y, w, h = page.evaluate(BOX_JS)
    page.mouse.move(x + 0.08 * w, y + 0.25 * h)
    page.mouse.down()
    page.mouse.move(x + 0.2 * w, y + 0.35 * h, steps=4)
    page.mouse.move(x + 0.35 * w, y + 0.5 * h, steps=4)
    page.mouse.up()
    page.wait_for_function(f"() => {OVERVIEW}.layout.xaxis.autorange === false")
    xr, yr = page.evaluate(RANGES_JS)
    return {"xaxis": (xr[0], xr[1]), "yaxis": (yr[0], yr[1])}


def _load(page: Any, name: str, text: str) -> None:
    page.locator("input[type=file][accept^='.json']").set_input_files(
        files=[{"name": name, "mimeType": "application/json", "buffer": text.encode()}])


def test_a_demo_state_brings_back_its_tabs_and_the_overviews_zoom(browser, ui_server):
    before = set(ui_server.config.sessions)
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    try:
        probe = session_of(page, ui_server, before).tab.demo_files.probe
        page.wait_for_function("() => { const l = [...document.querySelectorAll('label')]"
                               ".find(l => l.textContent === 'page view'); return l && l.offsetParent === null; }")
        zoom = _zoom_box(page)
        saved_view = PageView("Position drive (FDSMC)", "Overview", zoom)
        _reported(page, probe, saved_view)
        page.get_by_text("Demo state (lecture)").click()
        with page.expect_download() as info:
            page.get_by_role("button", name="Save demo state").click()
        saved = Path(info.value.path()).read_text(encoding="utf-8")
        assert loads_state(saved, "saved.json").view == saved_view
        page.evaluate(RESET_JS)  # zoom undone, another tab
        click_tab(page, "Energy")
        _reported(page, probe, PageView("Position drive (FDSMC)", "Energy", {}))
        _load(page, "lecture.json", saved)
        page.wait_for_function(AT_JS, arg=[list(zoom["xaxis"]), list(zoom["yaxis"])])
        assert {"Position drive (FDSMC)", "Overview"} <= set(page.evaluate(SELECTED_JS))
        _reported(page, probe, saved_view)  # the restored zoom is the zoom shown: saved again as it is
        page.get_by_text("Ready — ").wait_for()
        raw = json.loads(saved)
        raw["tab"], raw["zoom"] = {"mode": "BLDC speed SMC", "results": "BLDC figures"}, {}
        _load(page, "bldc.json", json.dumps(raw))
        page.wait_for_function(f"() => ({SELECTED_JS})().includes('BLDC speed SMC')")
        _reported(page, probe, PageView("BLDC speed SMC", "BLDC figures", {}))
        assert errors == []
    finally:
        context.close()


def test_the_overviews_zoom_survives_another_results_tab(browser, ui_server):
    # viser unmounts a hidden tab: the overview drawn again on its return gets the zoom back, while a
    # new run (a new figure) starts unzoomed
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    try:
        page.wait_for_function(f"() => {OVERVIEW} !== undefined && {OVERVIEW}._fullLayout !== undefined")
        zoom = _zoom_box(page)
        click_tab(page, "Time plots")
        page.wait_for_function(f"() => {OVERVIEW} === undefined || {OVERVIEW}.offsetParent === null")
        click_tab(page, "Overview")
        page.wait_for_function(AT_JS, arg=[list(zoom["xaxis"]), list(zoom["yaxis"])])
        set_number(page, "K boundary-layer gain [s/rad]", "2")
        page.get_by_role("button", name="Simulate").click()
        page.wait_for_function(f"(z) => !({AT_JS})(z)", arg=[list(zoom["xaxis"]), list(zoom["yaxis"])])
        assert errors == []
    finally:
        context.close()
