"""A reload keeps the demo: the page's address names its demo state after a run, and opening it again
restores K and the preset (the dropdown names the loaded preset).
"""

from __future__ import annotations

from app.io.presets import PAPER_PRESET
from tests.browser.conftest import field, open_page, set_number

K_FIELD = "K boundary-layer gain [s/rad]"


def test_a_reload_restores_the_demo_and_the_preset_dropdown(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    try:
        set_number(page, K_FIELD, "2.5")
        page.get_by_role("button", name="Simulate").click()
        page.wait_for_function("() => location.search.startsWith('?demo=')")
        address = page.url
        second = context.new_page()
        second.goto(address)
        second.get_by_role("button", name="Simulate").wait_for(timeout=90_000)
        second.wait_for_function("(f) => { const i = [...document.querySelectorAll('input')].find(e => e.value === f);"
                                 " return !!i; }", arg="2.5", timeout=60_000)
        assert field(second, K_FIELD).input_value() == "2.5"
        preset = second.locator('xpath=//label[normalize-space(.)="Preset"]/ancestor::*[.//input][1]//input').first
        assert preset.input_value() == PAPER_PRESET  # the dropdown names the preset of the loaded demo
        second.get_by_text("Ready — ").wait_for(timeout=60_000)  # its run ends before the page closes
    finally:
        context.close()
