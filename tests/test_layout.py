"""Panel layout for the browser window: widths, overview-plot aspect, the page's CSS, the window report.

The widths the page's CSS gives the panels in a real browser are checked against
:func:`layout_for_window` in tests/browser/test_layout_steady.py.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pmsm_commissioning.app.ui.layout import (
    ASPECT_MAX,
    ASPECT_MIN,
    BORDERS,
    CANVAS_SPARE,
    CHROME_HEIGHT,
    CONTROL_WIDTH,
    CONTROL_WIDTH_WIDE,
    DEFAULT_WINDOW,
    PLOT_PADDING,
    RAIL,
    RESULTS_MIN,
    SCENE_MIN,
    WIDE_WINDOW,
    WindowFit,
    hide_field_js,
    install_css_js,
    layout_for_window,
    page_css,
    page_marks_js,
    parse_window,
    window_report_js,
)

ROOT = Path(__file__).resolve().parents[1]


def _plot_height(lay) -> float:
    return lay.plot_aspect * (lay.results_width - PLOT_PADDING)


def test_projector_layout_fits_1280x720_and_uses_wide_screens():
    small = layout_for_window(1280, 720)
    assert small.control_width + small.results_width + CANVAS_SPARE + BORDERS == 1280  # the whole width
    assert _plot_height(small) + CHROME_HEIGHT <= 720 + 1  # no scrolling
    wide = layout_for_window(1920, 1080)
    assert wide.control_width == CONTROL_WIDTH_WIDE and small.control_width == CONTROL_WIDTH
    assert wide.results_width > 960 and _plot_height(wide) + CHROME_HEIGHT <= 1080 + 1
    shown = layout_for_window(1920, 1080, show_3d=True)
    assert shown.show_3d and 1920 - shown.control_width - shown.results_width - BORDERS == pytest.approx(0.22 * 1920)
    small_3d = layout_for_window(1280, 720, show_3d=True)  # 22 % of 1280 px = 281.6 px ≥ SCENE_MIN
    assert 1280 - small_3d.control_width - small_3d.results_width - BORDERS >= SCENE_MIN


@pytest.mark.parametrize("width", [WIDE_WINDOW, WIDE_WINDOW + 1])
def test_the_wide_control_panel_starts_just_above_wide_window(width):
    lay = layout_for_window(width, 900)
    assert lay.control_width == (CONTROL_WIDTH_WIDE if width > WIDE_WINDOW else CONTROL_WIDTH)


def test_aspect_is_bounded_and_the_results_panel_has_a_least_width():
    assert layout_for_window(1280, 4000).plot_aspect == ASPECT_MAX  # very tall: no taller than ASPECT_MAX
    assert layout_for_window(3000, 400).plot_aspect == ASPECT_MIN  # very flat: no flatter than ASPECT_MIN
    assert layout_for_window(600, 720).results_width == RESULTS_MIN


@pytest.mark.parametrize(("text", "size"), [("1280x720", (1280.0, 720.0)), (" 1920x1080 ", (1920.0, 1080.0))])
def test_a_reported_window_size_is_read(text, size):
    assert parse_window(text) == size


@pytest.mark.parametrize("text", ["", "1280", "1280x", "x720", "1280 x 720", "-1280x720", "1e3x720",
                                  "99x720", "1280x20001", "1280x720;drop", "<b>1280x720</b>"])
def test_anything_else_is_not_a_window(text):
    assert parse_window(text) is None


def test_window_fit_refits_on_a_new_size_and_ignores_junk():
    applied = []
    fit = WindowFit(applied.append)
    assert applied == [layout_for_window(*DEFAULT_WINDOW)] and not fit.show_3d
    fit.window_reported("1280x720")  # the window assumed at start: nothing to send
    assert len(applied) == 1
    fit.window_reported("1920x1080")
    assert fit.window == (1920.0, 1080.0) and applied[-1] == layout_for_window(1920, 1080)
    fit.window_reported("garbage")  # not a size: the layout stays
    fit.window_reported("0x0")
    assert fit.window == (1920.0, 1080.0) and len(applied) == 2
    fit.set_3d(True)
    assert applied[-1] == layout_for_window(1920, 1080, show_3d=True) and fit.show_3d
    fit.window_reported("1400x900")  # the 3D view stays shown through a resize
    assert applied[-1] == layout_for_window(1400, 900, show_3d=True)
    fit.set_3d(False)
    assert applied[-1] == layout_for_window(1400, 900)


def test_page_css_carries_the_widths_of_layout_for_window():
    folded, shown = page_css(), page_css(show_3d=True)
    assert folded != shown
    # control panel + viser's two 2 px gutters, narrow and wide windows; a folded region: the rail
    assert f"--fit-left: {CONTROL_WIDTH + BORDERS / 2:g}px" in folded
    wide_px = CONTROL_WIDTH_WIDE + BORDERS / 2
    wide = f"(min-width: {WIDE_WINDOW + 1:g}px) {{ [data-dock-root] {{--fit-left: {wide_px:g}px}}"
    assert wide in folded
    assert f"--fit-left: {RAIL + BORDERS / 2:g}px" in folded and f"--fit-right: {RAIL + BORDERS / 2:g}px" in folded
    # results: the rest of the window beside the folded canvas; 22 % of it for the shown 3D view
    assert f"--fit-canvas: {CANVAS_SPARE:g}px" in folded and f"--fit-canvas: max({SCENE_MIN:g}px, 22%)" in shown
    rest = f"--fit-right: max({RESULTS_MIN + BORDERS / 2:g}px, calc(100% - var(--fit-left) - var(--fit-canvas)))"
    assert rest in folded
    assert "[data-app-hidden] {display: none !important}" in folded  # the window field's row (page_marks_js)
    assert "[data-app-bldc] canvas {visibility: hidden}" in folded


def test_no_css_of_the_page_selects_with_has():
    """No ``:has()`` in any CSS the page gets: with one, every forced layout re-styled the whole page."""
    sources = [*(ROOT / "app").rglob("*.py"), *(ROOT / "app" / "ui" / "assets").glob("*.js")]
    selector = re.compile(r":has\((?!\))")  # ":has()" in prose is fine
    offenders = [str(p.relative_to(ROOT)) for p in sources if selector.search(p.read_text(encoding="utf-8"))]
    assert offenders == []
    assert ":has(" not in page_css() + page_css(show_3d=True)


def test_page_marks_script_quotes_the_field_id():
    js = page_marks_js(['a"b', "c"])
    assert f"const hiddenFields = {json.dumps(['a' + chr(34) + 'b', 'c'])};" in js
    for mark in ("data-app-bldc", "data-app-rail-", "data-app-fit", "data-app-column", "data-app-overview-window",
                 "data-app-hidden"):
        assert mark in js and mark in page_css()


def test_css_script_quotes_the_css():
    css = 'x"); alert(1); ("'
    js = install_css_js(css)
    assert f"s.textContent = {json.dumps(css)};" in js  # a JSON string, not raw text


def test_window_report_script_quotes_the_field_id():
    js = window_report_js('a"b')
    assert f"const uuid = {json.dumps('a' + chr(34) + 'b')};" in js  # a JSON string, not raw text
    assert "window.innerWidth" in js and "addEventListener('resize'" in js


def test_a_field_made_after_the_marks_is_hidden_by_them_too():
    assert hide_field_js('a"b') == f"window.__appHideField({json.dumps('a' + chr(34) + 'b')});"
    assert "window.__appHideField = (uuid) =>" in page_marks_js(["c"])
