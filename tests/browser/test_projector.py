"""Projector layout: at 1280×720 the phase plane, the compact time plot and the key numbers are on
screen without scrolling; wide screens use their width; the 3D view folds away and hides in the
BLDC tabs; the warnings box folds to one line; the replay moves the time cursor with the marker.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest

from pmsm_commissioning.app.figures.fdsmc_overview import CURSORS
from pmsm_commissioning.app.figures.fdsmc_replay import SPEEDS
from tests.browser.conftest import (
    ARTIFACTS,
    TIMEOUT_MS,
    UiServer,
    click_tab,
    open_page,
    session_of,
    wait_for_layout,
)

#: Bounding boxes (page pixels) of the phase-plane subplot, the two time rows, the key numbers and
#: the "Replay t" slider row.
BOXES_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const r = el.getBoundingClientRect(), L = el._fullLayout;
  const box = (xa, ya) => ({x: r.x + L[xa]._offset, y: r.y + L[ya]._offset,
                            width: L[xa]._length, height: L[ya]._length});
  const k = document.querySelector('[data-role="key-numbers"]').getBoundingClientRect();
  const label = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === 'Replay t [s]');
  let row = label; while (row && !row.querySelector('[role="slider"]')) row = row.parentElement;
  const s = row.getBoundingClientRect();
  return {phase: box('xaxis', 'yaxis'), omega: box('xaxis2', 'yaxis2'), torque: box('xaxis3', 'yaxis3'),
          numbers: {x: k.x, y: k.y, width: k.width, height: k.height},
          scrub: {x: s.x, y: s.y, width: s.width, height: s.height},
          results: [...document.querySelectorAll('[role="tab"]')].filter(t => t.title === 'Overview')
                     .map(t => t.closest('[data-dock-tab]').parentElement.getBoundingClientRect().width)[0],
          scroll: [document.scrollingElement.scrollWidth, document.scrollingElement.scrollHeight]};
}"""
STATE_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const get = n => el._fullData.find(t => t.name === n);
  const m = get('FDSMC now');
  return {marker: [Number(m.x[0]), Number(m.y[0]), (m.text || [''])[0]],
          cursors: CURSORS.map(n => Array.from(get(n).x).map(Number))};
}""".replace("CURSORS", json.dumps(list(CURSORS)))
FRAMES_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  window.__frames = 0; window.__pairs = [];
  el.on('plotly_animatingframe', () => {
    window.__frames += 1;
    const get = n => el._fullData.find(t => t.name === n);
    const text = (get('FDSMC now').text || [''])[0];
    window.__pairs.push([text, Number(get(CURSOR).x[0])]);
  });
}""".replace("CURSOR", json.dumps(CURSORS[0]))


def _open(browser: Any, ui: UiServer, width: int, height: int) -> tuple[Any, Any]:
    """A page of ``ui`` in a ``width`` × ``height`` window, drawn and fitted (:func:`wait_for_layout`)."""
    context = browser.new_context(viewport={"width": width, "height": height})
    page = context.new_page()
    page.set_default_timeout(TIMEOUT_MS)
    before = set(ui.config.sessions)
    page.goto(ui.url)
    # first draw of the page: allowed 3× the usual wait (a loaded 2-core machine needs > 30 s)
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')]"
                           ".some(e => e.layout && e.layout.meta && e.layout.meta.overview"
                           " && e._fullLayout && e._fullLayout.xaxis2)", timeout=3 * TIMEOUT_MS)
    wait_for_layout(page, session_of(page, ui, before))
    return context, page


@pytest.fixture(scope="module")
def projector(browser: Any, ui_server: Any) -> Iterator[Any]:
    """A page in a 1280×720 window, shared by the tests that leave it as they found it: the
    replay ends where it starts (at t_end), the warnings box is unfolded again.
    """
    context, page = _open(browser, ui_server, 1280, 720)
    try:
        yield page
    finally:
        context.close()


def _inside(box: dict[str, float], width: int, height: int) -> bool:
    return (box["width"] > 0 and box["height"] > 0 and box["x"] >= 0 and box["y"] >= 0
            and box["x"] + box["width"] <= width and box["y"] + box["height"] <= height)


def test_1280x720_shows_phase_plane_time_plot_numbers_and_scrub_without_scrolling(projector):
    page = projector
    page.wait_for_function(f"() => {{ const b = ({BOXES_JS})(); const r = p => p.y + p.height <= 720;"
                           " return r(b.phase) && r(b.torque) && r(b.numbers) && r(b.scrub); }")
    boxes = page.evaluate(BOXES_JS)
    for name in ("phase", "omega", "torque", "numbers", "scrub"):
        assert _inside(boxes[name], 1280, 720), (name, boxes[name])
    assert boxes["scroll"] == [1280, 720]  # the page itself does not scroll
    assert boxes["phase"]["width"] >= 300 and boxes["phase"]["height"] >= 250  # legible on a projector
    assert boxes["omega"]["x"] > boxes["phase"]["x"] + boxes["phase"]["width"]  # side by side
    text = page.inner_text('[data-role="key-numbers"]')
    assert "From the supply" in text and "Optimum" in text and "Γ_max" in text
    page.wait_for_timeout(300)  # let the last layout message settle before the picture
    ARTIFACTS.mkdir(exist_ok=True)
    out = ARTIFACTS / "projector_1280x720.png"  # copied by hand to docs/ for the README
    page.screenshot(path=str(out))
    assert out.stat().st_size > 30_000


def test_wide_screen_gives_the_results_more_than_half_the_width(browser, ui_server):
    context, page = _open(browser, ui_server, 1920, 1080)
    try:
        page.wait_for_function(f"() => {{ const b = ({BOXES_JS})(); return b.results > 960 && b.phase.width > 600; }}")
        boxes = page.evaluate(BOXES_JS)
        assert boxes["results"] > 960
        assert _inside(boxes["phase"], 1920, 1080) and _inside(boxes["torque"], 1920, 1080)
        assert boxes["phase"]["width"] > 600  # the phase plane grows with the panel
    finally:
        context.close()


def test_replay_moves_the_time_cursor_with_the_marker(projector, ui_server):
    page = projector
    received: list[int] = []
    page.on("websocket", lambda ws: ws.on("framereceived", lambda p: received.append(len(p))))
    t_end = float(ui_server.config.initial().fdsmc.trace.t[-1])
    before = page.evaluate(STATE_JS)
    assert all(c == pytest.approx([t_end, t_end], rel=1e-4) for c in before["cursors"])  # at the end
    page.evaluate(FRAMES_JS)
    n0 = len(received)
    page.locator(".updatemenu-button", has_text=f"▶ {list(SPEEDS)[1]}").click()  # 0.25×: t_end / 0.25 s
    page.wait_for_function("() => window.__frames >= 20")
    pairs = page.evaluate("() => window.__pairs.slice()")
    page.wait_for_function(f"() => ({STATE_JS})().marker[2] === 't = {t_end:.3f} s'",
                           timeout=TIMEOUT_MS + 8000 * t_end)
    frames = page.evaluate("() => window.__frames")
    # in every frame the cursor stands at the time the marker shows
    moved = [(float(text.split()[2]), x) for text, x in pairs if text]
    assert len(moved) >= 15
    for t_marker, x_cursor in moved:
        assert x_cursor == pytest.approx(t_marker, abs=1.5e-3)
    assert min(x for _, x in moved) < 0.5 * t_end  # it really moved from the start
    assert page.evaluate(STATE_JS)["cursors"][1] == pytest.approx([t_end, t_end], rel=1e-4)
    assert sum(received[n0:]) < 1000 * frames  # no server traffic per frame (< 1 kB each)


def test_warnings_box_folds_to_one_line_and_expands(projector):
    page = projector
    summary = page.locator('[data-role="warnings-summary"]')
    summary.wait_for()
    box = page.locator('[data-role="warnings"]')
    details = page.locator('[data-role="warnings-list"]')
    assert details.evaluate("d => d.open")
    tall = box.bounding_box()["height"]
    summary.click()
    page.wait_for_function("() => !document.querySelector('[data-role=\"warnings-list\"]').open")
    line = summary.bounding_box()["height"]
    folded = box.bounding_box()["height"]
    assert line < 30 and folded < line + 24 < tall  # one line (plus the box's padding)
    assert "warning" in summary.inner_text()
    summary.click()
    page.wait_for_function("() => document.querySelector('[data-role=\"warnings-list\"]').open")
    assert box.bounding_box()["height"] == pytest.approx(tall, abs=2)


def test_folded_warnings_stay_folded_over_a_new_run_with_other_warnings(page):
    """The "Fold warnings to one line" choice holds for every later run: the paper preset's
    K = 1000 s/rad chatters (warned); with K = 0.3 s/rad, under the limit of the linearised loop,
    that warning goes and the new set of warnings arrives folded.
    """
    from tests.browser.conftest import set_number

    box = page.locator('[data-role="warnings"]')
    box.wait_for()
    before = box.inner_text()
    assert "K = 1000" in before
    page.get_by_label("Fold warnings to one line").check()
    page.wait_for_function("() => !document.querySelector('[data-role=\"warnings-list\"]').open")
    set_number(page, "K boundary-layer gain [s/rad]", "0.3")
    page.get_by_role("button", name="Simulate").click()
    page.wait_for_function("(t) => { const s = document.querySelector('[data-role=\"warnings\"]');"
                           " return s && s.innerText !== t; }", arg=before)
    assert "K = 1000" not in box.inner_text()  # the new warnings are there…
    assert not page.evaluate("() => document.querySelector('[data-role=\"warnings-list\"]').open")  # …folded


@pytest.fixture(scope="module")
def server_3d() -> Iterator[Any]:
    """The web UI with the 3D view available (folded by default)."""
    from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
    from pmsm_commissioning.app.ui.page import create_server
    from tests.browser.conftest import UiServer
    from tests.net import free_port

    server, config = create_server(load_preset(PAPER_PRESET), PAPER_PRESET, port=free_port(), scene_3d=True)
    try:
        yield UiServer(f"http://127.0.0.1:{server.get_port()}", server, config)
    finally:
        server.stop()


CANVAS_JS = "() => getComputedStyle(document.querySelector('canvas')).visibility"


def test_3d_view_folds_by_default_and_hides_in_the_bldc_tab(browser, server_3d):
    context, page = _open(browser, server_3d, 1280, 720)
    try:
        session = max(server_3d.config.sessions.values(), key=lambda s: s.client.client_id)
        scene = session.results.replay._scene
        assert scene is not None and not scene.visible  # folded: the results get the width
        folded_width = session.fit.layout.results_width
        page.get_by_text("3D view", exact=True).click()
        page.get_by_text("Show 3D rotors").click()
        page.wait_for_function("() => document.querySelector('canvas').getBoundingClientRect().width > 250")
        assert scene.visible and session.fit.layout.results_width < folded_width
        assert page.evaluate(CANVAS_JS) == "visible"
        click_tab(page, "BLDC speed SMC")
        page.wait_for_function(f"() => ({CANVAS_JS})() === 'hidden'")
        click_tab(page, "Position drive (FDSMC)")
        page.wait_for_function(f"() => ({CANVAS_JS})() === 'visible'")
    finally:
        context.close()


#: Keeps the page's console.log lines in ``window.__logs`` (viser logs its WebGL renderer there).
LOGS_INIT = ("window.__logs = []; const log = console.log;"
             " console.log = (...a) => { window.__logs.push(a.map(String).join(' ')); log(...a); };")
WEBGL_NOTICE_JS = ("() => [...document.querySelectorAll('.mantine-Notification-title')]"
                   ".some(t => t.textContent.includes('WebGL'))")


def test_viser_software_webgl_notice_is_closed_while_no_3d_view_is_shown(browser, server_3d):
    # viser's notice stays until closed, over the results' tab row and the key numbers; the plots
    # are SVG, only the (folded) 3D view uses WebGL
    context, page = open_page(browser, server_3d, {"width": 1280, "height": 720}, init_script=LOGS_INIT)
    try:
        renderer = page.wait_for_function(
            "() => window.__logs.find(m => m.startsWith('WebGL support'))").json_value()
        # the case is set up: headless Chromium renders WebGL in software, where viser shows its notice
        assert "swiftshader" in renderer.lower() or "software" in renderer.lower(), renderer
        page.wait_for_function(f"() => !({WEBGL_NOTICE_JS})()")
        page.wait_for_timeout(500)  # and it stays closed
        assert not page.evaluate(WEBGL_NOTICE_JS)
        assert "From the supply" in page.inner_text('[data-role="key-numbers"]')
    finally:
        context.close()
