"""Browser tests: a figure saved as SVG (1280×720) and PNG (1920×1080: 1280×720 at scale 1.5) without the
replay buttons; no console errors over a demo.

Uses the shared in-process server of ``tests/browser/conftest.py``.
"""

from __future__ import annotations

import struct
from pathlib import Path

from tests.browser.conftest import click_tab, figure, open_page, set_number

#: Collects console errors, uncaught exceptions and rejected promises from the page's first script on.
ERRORS_JS = """window.__errors = [];
const original = console.error.bind(console);
console.error = (...args) => { window.__errors.push(args.map(String).join(' ')); original(...args); };
window.addEventListener('error', (e) => window.__errors.push('uncaught: ' + e.message));
window.addEventListener('unhandledrejection', (e) => window.__errors.push('rejected: ' + String(e.reason)));"""


def _save(page, figure_id: str, button: str) -> bytes:
    click_tab(page, "Share")
    dropdown = page.locator('xpath=//label[normalize-space(.)="Figure"]/ancestor::*[.//input][1]//input').first
    dropdown.click()
    page.get_by_role("option", name=figure_id, exact=True).click()
    page.wait_for_timeout(150)  # viser sends GUI updates every 50 ms
    with page.expect_download() as info:
        page.get_by_role("button", name=button).click()
    return Path(info.value.path()).read_bytes()


def test_overview_saved_as_svg_and_png_without_replay_buttons(browser, ui_server):
    context, page = open_page(browser, ui_server)
    try:
        assert figure(page, "phase_plane") is not None
        svg = _save(page, "phase_plane", "Save SVG (vector, 1280×720)").decode("utf-8")
        assert svg.startswith("<svg") and 'width="1280"' in svg[:400] and 'height="720"' in svg[:400]
        assert "updatemenu" not in svg and "1×" not in svg  # no replay buttons
        assert "ω" in svg  # the axes and traces are there
        png = _save(page, "phase_plane", "Save PNG 1920×1080")
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
        assert struct.unpack(">II", png[16:24]) == (1920, 1080)
    finally:
        context.close()


#: Colour [r, g, b] and font size [px] of every slider limit label of the page.
MARK_LABELS_JS = """() => [...document.querySelectorAll('.mantine-Slider-markLabel')].map(e => {
  const s = getComputedStyle(e);
  return [s.color.match(/[0-9.]+/g).slice(0, 3).map(Number), parseFloat(s.fontSize)]; })"""


def _contrast_on_white(rgb: list[float]) -> float:
    """WCAG 2 contrast ratio of an sRGB colour (0–255) on white."""
    lin = [c / 255 / 12.92 if c / 255 <= 0.04045 else ((c / 255 + 0.055) / 1.055) ** 2.4 for c in rgb]
    luminance = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    return 1.05 / (luminance + 0.05)


def test_no_console_errors_over_a_demo_on_both_tabs(browser, ui_server):
    """Simulate, a K change, the results tabs, the BLDC tab with its side-by-side run, back: no console error.

    On the way: the sliders' limit labels are legible (contrast ≥ 4.5:1 on white, ≥ 13 px).
    """
    context, page = open_page(browser, ui_server, init_script=ERRORS_JS)
    try:
        labels = page.evaluate(MARK_LABELS_JS)
        assert labels and all(_contrast_on_white(rgb) >= 4.5 and px >= 13 for rgb, px in labels), labels
        page.get_by_role("button", name="Simulate", exact=True).click()
        page.wait_for_timeout(1500)
        page.get_by_text("Controller", exact=True).first.click()
        set_number(page, "K boundary-layer gain [s/rad]", 0.3)
        page.get_by_role("button", name="Simulate", exact=True).click()
        page.wait_for_timeout(1500)
        for tab in ("Time plots", "Energy", "Overview"):
            click_tab(page, tab)
            page.wait_for_timeout(300)
        click_tab(page, "BLDC speed SMC")
        page.get_by_text("Paper drive with / without anti-windup, side by side", exact=True).click()
        page.wait_for_timeout(150)
        page.get_by_role("button", name="Simulate BLDC").click()
        page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => "
                               "e.layout && e.layout.meta && e.layout.meta.id === 'bldc_antiwindup' && e.data.length)",
                               timeout=60_000)
        click_tab(page, "Position drive (FDSMC)")
        page.wait_for_timeout(500)
        assert page.evaluate("window.__errors") == []
    finally:
        context.close()
