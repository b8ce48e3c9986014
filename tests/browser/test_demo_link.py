"""The demo survives a reload and can be sent on: after a run the page's address names its demo state
(preset, typed fields, K, T_m, the results tab); a reload, or the address opened in another browser,
restores it — and the window-size report, which rides in the same message, still arrives. After
*Load demo state* the Preset dropdown names the loaded state's preset.
"""

from __future__ import annotations

import time
from typing import Any

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.ui.demo_link import state_of
from pmsm_commissioning.app.ui.demo_state import DemoState, PageView, dumps_state, loads_state
from tests.browser.conftest import TIMEOUT_MS, click_tab, field, open_page, session_of, set_number, wait_for_layout
from tests.browser.test_design import choose
from tests.browser.test_tab_figures import shows_the_time_plots_of

K_FIELD, T_M_FIELD = "K boundary-layer gain [s/rad]", "T_m manoeuvre time [s]"
#: A preset other than the server's start-up one, and the K, T_m typed over it [s/rad], [s].
PRESET, K, T_M = "yaskawa_sgm7j_04a", 0.04, 0.62
RESULTS_TAB = "Time plots"


def _wait(condition: Any, what: str, timeout_s: float = 120.0) -> None:
    """Poll the server-side ``condition()`` until true (a positive condition, no fixed sleep)."""
    end = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < end, f"timed out waiting for {what}"
        time.sleep(0.05)


def _wait_field(page: Any, label: str, value: float | str) -> None:
    """Wait until the field ``label`` shows ``value`` (the page draws the server's update a moment later)."""
    for _ in range(TIMEOUT_MS // 50):
        text = field(page, label).input_value()
        if (text == value) if isinstance(value, str) else (text and float(text) == value):
            return
        page.wait_for_timeout(50)  # poll the page's state again (a positive condition)
    raise AssertionError(f"{label} shows {field(page, label).input_value()!r}, not {value!r}")


def _address_state(page: Any) -> DemoState | None:
    text = state_of(page.evaluate("() => location.search"))
    return None if text is None else loads_state(text, "address")


def _shows_the_demo(page: Any, ui: Any, before: set[int]) -> None:
    """The page just opened (a reload or the link) restores the demo, and its window size reached the server."""
    page.get_by_role("button", name="Simulate").wait_for(timeout=3 * TIMEOUT_MS)
    session = session_of(page, ui, before)
    wait_for_layout(page, session)  # the window report arrived (the address rides in it)
    _wait(lambda: session.runs >= 1 and session.origin == PRESET and not session.tab.busy, "the demo's run")
    assert session.params.controller.K == K and session.params.manoeuvre.T_m == T_M
    _wait_field(page, K_FIELD, K)
    _wait_field(page, T_M_FIELD, T_M)
    _wait_field(page, "Preset", PRESET)  # the dropdown names the demo's preset
    page.wait_for_function("(t) => [...document.querySelectorAll('[role=\"tab\"]')].some("
                           "e => e.getAttribute('title') === t && e.getAttribute('aria-selected') === 'true')",
                           arg=RESULTS_TAB)
    page.get_by_text("Ready — ").wait_for(timeout=3 * TIMEOUT_MS)  # its run ends before the page closes
    shows_the_time_plots_of(page, session)  # the restored tab shows the demo's run (sent once it is chosen)


def test_a_reload_and_the_sent_link_restore_the_demo(browser, ui_server):
    context, page = open_page(browser, ui_server)  # 1400×900: a window report other than the default
    try:
        choose(page, "Preset", PRESET)
        page.get_by_text(f"Preset: {PRESET}").wait_for(timeout=3 * TIMEOUT_MS)
        click_tab(page, RESULTS_TAB)
        set_number(page, K_FIELD, K)
        set_number(page, T_M_FIELD, T_M)
        page.get_by_role("button", name="Simulate").click()
        _wait(lambda: (s := _address_state(page)) is not None and s.params.controller.K == K
              and s.params.manoeuvre.T_m == T_M and s.view.results_tab == RESULTS_TAB, "the demo in the address")
        address = page.url
        assert "?demo=" in address
        page.get_by_text("Ready — ").wait_for(timeout=3 * TIMEOUT_MS)
        before = set(ui_server.config.sessions)
        page.reload()
        _shows_the_demo(page, ui_server, before)
    finally:
        context.close()
    other = browser.new_context(viewport={"width": 1920, "height": 1080})  # another browser, the link sent on
    try:
        second = other.new_page()
        second.set_default_timeout(TIMEOUT_MS)
        before = set(ui_server.config.sessions)
        second.goto(address)
        _shows_the_demo(second, ui_server, before)
    finally:
        other.close()


def test_an_address_naming_no_kept_demo_opens_the_start_up_case(browser, ui_server):
    context = browser.new_context(viewport={"width": 1280, "height": 720})
    try:
        page = context.new_page()
        page.set_default_timeout(TIMEOUT_MS)
        before = set(ui_server.config.sessions)
        page.goto(ui_server.url + "/?demo=0123456789abcdef")
        page.get_by_role("button", name="Simulate").wait_for(timeout=3 * TIMEOUT_MS)
        session = session_of(page, ui_server, before)
        wait_for_layout(page, session)
        assert session.runs == 0 and not session.tab.busy and session.origin == ui_server.config.origin
        assert field(page, "Preset").input_value() == ui_server.config.origin
    finally:
        context.close()


def test_the_preset_dropdown_follows_a_loaded_demo_file(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    try:
        assert field(page, "Preset").input_value() == ui_server.config.origin != PRESET
        params = load_preset(PRESET)
        state = DemoState(params, None, PRESET, {}, (), PageView())
        page.locator("input[type=file][accept^='.json']").set_input_files(
            files=[{"name": "lecture.json", "mimeType": "application/json", "buffer": dumps_state(state).encode()}])
        page.get_by_text(f"Preset: {PRESET}").wait_for(timeout=3 * TIMEOUT_MS)
        _wait_field(page, "Preset", PRESET)
        _wait_field(page, K_FIELD, float(f"{params.controller.K:.5g}"))
    finally:
        context.close()
