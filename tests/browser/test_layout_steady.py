"""Panels that fit the window from the first frame: while a page opens, the results panel, the
control panel and the 3D canvas each take one width (the one of ``layout_for_window``) and the
results panel's tab row stays where it is; a resized window refits them and the overview plot;
the results panel takes the width the control panel frees when folded to its rail.
"""

from __future__ import annotations

from typing import Any

import pytest

from pmsm_commissioning.app.ui.layout import BORDERS, CANVAS_SPARE, RAIL, layout_for_window
from tests.browser.conftest import open_page, session_of, wait_for_layout

#: Every animation frame from the page's start: the results panel's width (the dock group of the
#: "Overview" tab) and its tab's position, the control panel's and the canvas's widths [px]; a new
#: entry only when one of them changed. ``window.__frames`` counts the frames.
RECORD_JS = """(() => {
  const seen = window.__layouts = [];
  window.__frames = 0;
  const width = (e) => e ? Math.round(e.getBoundingClientRect().width * 10) / 10 : null;
  const tick = () => {
    window.__frames += 1;
    const tab = [...document.querySelectorAll('[role="tab"]')].find(t => t.title === 'Overview');
    if (tab) {
      const r = tab.getBoundingClientRect();
      const now = {results: width(tab.closest('[data-dock-tab]').parentElement),
                   tab: [Math.round(r.x), Math.round(r.y)],
                   control: width(document.querySelector('[data-dock-region="left"]')),
                   canvas: width(document.querySelector('canvas'))};
      const last = seen[seen.length - 1];
      if (!last || JSON.stringify(last) !== JSON.stringify(now)) seen.push(now);
    }
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
})();"""

#: True once the overview plot is drawn at ``aspect`` (height / width) of its width.
PLOT_AT_ASPECT_JS = """(aspect) => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const L = el && el._fullLayout;
  return !!L && Math.abs(L.height - aspect * L.width) <= 1.5;
}"""

#: True once the results panel is ``w`` px wide.
RESULTS_AT_JS = """(w) => { const l = window.__layouts[window.__layouts.length - 1];
  return !!l && Math.abs(l.results - w) <= 0.5; }"""


def _expected(width: int, height: int) -> dict[str, Any]:
    lay = layout_for_window(width, height)
    canvas = width - lay.control_width - lay.results_width - BORDERS
    return {"results": lay.results_width, "control": lay.control_width + BORDERS / 2, "canvas": canvas}


def _assert_one_layout(layouts: list[dict[str, Any]]) -> None:
    """Every recorded frame has the same panel widths, and the tab row moved by at most 1 px.

    The tab's position is rounded to whole pixels; a text row whose top sits on a half pixel
    rounds to either neighbour when the font's metrics settle (the web font replacing its
    fallback), which no one sees. A panel that reflows moves it by its tab height or more.
    """
    first = layouts[0]
    for now in layouts[1:]:
        assert {k: now[k] for k in ("results", "control", "canvas")} == \
            {k: first[k] for k in ("results", "control", "canvas")}, layouts
        assert max(abs(a - b) for a, b in zip(now["tab"], first["tab"], strict=True)) <= 1, layouts


@pytest.mark.parametrize(("width", "height", "scale"), [(1280, 720, 1.0), (1920, 1080, 1.0), (1280, 720, 1.5)])
def test_panels_take_one_width_from_the_first_frame(browser, ui_server, width, height, scale):
    """Also on a high-density screen (1.5 device pixels per CSS pixel, e.g. a laptop at 150 %
    driving a projector), where the 3D canvas's drawing buffer is 1.5× its CSS size.
    """
    context, page = open_page(browser, ui_server, {"width": width, "height": height}, init_script=RECORD_JS,
                              scale=scale)
    try:
        aspect = layout_for_window(width, height).plot_aspect
        page.wait_for_function(PLOT_AT_ASPECT_JS, arg=aspect, polling="raf")  # plot refitted: steady
        frames = page.evaluate("() => window.__frames")
        page.wait_for_function("(n) => window.__frames >= n + 10", arg=frames, polling="raf")
        layouts = page.evaluate("() => window.__layouts")
        _assert_one_layout(layouts)  # one width each, one place of the tab row, from the first frame
        want = _expected(width, height)
        for key in ("results", "control", "canvas"):
            assert layouts[0][key] == pytest.approx(want[key], abs=0.5), (key, layouts[0])
    finally:
        context.close()


def test_a_resized_window_refits_the_panels_and_the_plot(browser, ui_server):
    before = set(ui_server.config.sessions)
    context, page = open_page(browser, ui_server, {"width": 1280, "height": 720}, init_script=RECORD_JS)
    try:
        session = session_of(page, ui_server, before)
        for width, height in ((1920, 1080), (1400, 900)):
            page.set_viewport_size({"width": width, "height": height})
            want = _expected(width, height)
            page.wait_for_function(RESULTS_AT_JS, arg=want["results"], polling="raf")
            assert page.evaluate("() => window.__layouts")[-1]["control"] == pytest.approx(want["control"], abs=0.5)
            wait_for_layout(page, session)  # the server has the new window…
            lay = layout_for_window(width, height)
            assert session.fit.layout == lay
            page.wait_for_function(PLOT_AT_ASPECT_JS, arg=lay.plot_aspect, polling="raf")  # …and the plot fits it
            assert page.evaluate("() => window.__layouts")[-1]["canvas"] == pytest.approx(want["canvas"], abs=0.5)
        # the control panel folded to viser's rail: the results panel takes the width it frees
        page.locator('[data-dock-region-handle="left"]').click()
        rail = RAIL + BORDERS / 2
        page.wait_for_function(RESULTS_AT_JS, arg=1400 - rail - CANVAS_SPARE - BORDERS / 2, polling="raf")
        assert page.evaluate("() => window.__layouts")[-1]["control"] == pytest.approx(rail, abs=0.5)
        page.locator('[data-dock-region="left"] [data-dock-minimize-all]').click()  # unfolded again
        page.wait_for_function(RESULTS_AT_JS, arg=_expected(1400, 900)["results"], polling="raf")
    finally:
        context.close()
