"""A lecture on one 1280×720 page: the live-tuning sliders mirror the fields, the replay draws its trail
progressively (no console errors over play, pause and scrub), pins leave ghosts, the paper's
Table 1 is a numeric table, and the main story fits the projector without scrolling.

The tests share one page (module scope) and run in file order; each leaves the page in a state
the next one can start from.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from pmsm_commissioning.app.figures.fdsmc_replay import SPEEDS
from pmsm_commissioning.app.ui.demo_state import loads_state
from tests.browser.conftest import ARTIFACTS, click_tab, field, open_page, set_number

#: Trail pieces as drawn (the SVG, not the data: Plotly can keep a path its data lost):
#: [line segments drawn, pieces drawn, pieces, latest end time drawn].
TRAIL_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const groups = [...el.querySelectorAll('g.trace.scatter')].filter(g => { const m = g.__data__[0].trace.meta;
    return m && typeof m.trail === 'number'; });
  const drawn = groups.map(g => { const p = g.querySelector('path.js-line');
    return [((p && p.getAttribute('d')) || '').split('L').length - 1, g.__data__[0].trace.meta.trail]; })
    .filter(([n, _]) => n > 0);
  return [drawn.reduce((n, d) => n + d[0], 0), drawn.length, groups.length, Math.max(-1, ...drawn.map(d => d[1]))];
}"""
#: The overview plot element.
OVERVIEW_EL = "[...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane')"
NAMES_JS = f"() => {OVERVIEW_EL}._fullData.map(d => d.name)"


@pytest.fixture(scope="module")
def lecture(browser: Any, ui_server: Any) -> Iterator[Any]:
    """One 1280×720 page shared by this module's tests, with every console error and page error recorded."""
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    page.errors = []  # type: ignore[attr-defined]
    page.on("console", lambda m: m.type in ("error", "warning") and page.errors.append(m.text))
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    try:
        yield page
    finally:
        context.close()


def _thumb(page: Any, label: str) -> Any:
    return page.locator(f'xpath=//label[normalize-space(.)="{label}"]/ancestor::*[.//*[@role="slider"]][1]'
                        '//*[@role="slider"]').first


def _wait_thumb(page: Any, label: str, value: float) -> None:
    page.wait_for_function("([t, p]) => Math.abs(parseFloat(t.getAttribute('aria-valuenow')) - p) < 0.006",
                           arg=[_thumb(page, label).element_handle(), math.log10(value)])


def test_the_sliders_mirror_the_fields_after_typing_and_simulate(lecture, ui_server):
    page = lecture
    set_number(page, "T_m manoeuvre time [s]", 1.4)
    set_number(page, "K boundary-layer gain [s/rad]", 2)
    page.get_by_role("button", name="Simulate").click()
    _wait_thumb(page, "T_m [s] (log)", 1.4)
    _wait_thumb(page, "K [s/rad] (log)", 2.0)
    page.locator('[data-role="t-m-readout"]', has_text="T_m = 1.4 s").wait_for()
    marks = page.locator(".mantine-Slider-markLabel").all_inner_texts()
    assert {"lim", "rec", "eq.59", "min", "nom"} <= set(marks)
    # T_c (rule T_c = T_a of eq. (59)): the slider stands at the T_c in force, on its "eq.59" mark
    T_c_ms = float(field(page, "T_c sliding time const. [ms]").input_value())
    _wait_thumb(page, "T_c [ms] (log)", T_c_ms)
    # the plant's J_L stands at the model's (nominal) J_L after a Simulate
    J_L = ui_server.config.initial().derived.params.load.J_L
    _wait_thumb(page, "J_L plant [kg·cm²] (log)", J_L * 1e4)
    page.get_by_text("Ready — ").wait_for()


def test_the_replay_draws_the_trail_progressively_without_console_errors(lecture):
    page = lecture
    points, _, pieces, _ = page.evaluate(TRAIL_JS)
    assert pieces > 20 and points > 0  # the whole trail drawn before any replay
    names = page.evaluate(NAMES_JS)
    assert "FDSMC enters boundary layer" in names and "Conventional enters boundary layer" not in names
    assert {"FDSMC reaching", "FDSMC linear (−θ_re/T_c)"} <= set(names)
    page.locator(".updatemenu-button", has_text=f"▶ {list(SPEEDS)[2]}").click()  # 0.1×: ≈ 14 s
    page.wait_for_function(f"() => {{ const r = ({TRAIL_JS})(); return r[1] > 0 && r[1] < r[2] / 3; }}")
    early = page.evaluate(TRAIL_JS)
    page.wait_for_function(f"(n) => ({TRAIL_JS})()[0] > n", arg=early[0])
    later = page.evaluate(TRAIL_JS)
    assert later[0] > early[0] and later[3] > early[3]  # more points, reaching later in time
    page.screenshot(path=str(ARTIFACTS / "lecture_replay.png"))
    page.locator(".updatemenu-button", has_text="Pause").click()
    page.locator(".updatemenu-button", has_text=f"▶ {list(SPEEDS)[0]}").click()
    box = page.locator('xpath=//label[normalize-space(.)="Replay t [s]"]/ancestor::*[.//input][1]'
                       '//input[not(@type="hidden")]').first
    box.fill("0.3")
    box.press("Tab")  # a scrub during a replay: pauses it
    page.wait_for_function(f"() => {{ const r = ({TRAIL_JS})(); return r[1] > 0 && r[3] <= 0.3; }}")
    page.wait_for_timeout(300)  # an interrupted animation's rejection would be logged by now
    assert not [e for e in page.errors if "rejected" in e or "Uncaught" in e], page.errors


def test_a_pinned_run_stays_as_a_ghost_until_cleared(lecture):
    page = lecture
    page.get_by_role("button", name="Pin this run").click()
    page.wait_for_function(f"() => ({NAMES_JS})().includes('pin 1 trajectory')")
    page.locator('[data-role="pins"]', has_text="pin 1").wait_for()
    set_number(page, "K boundary-layer gain [s/rad]", 1000)
    page.get_by_role("button", name="Simulate").click()
    page.wait_for_function("() => { const el = [...document.querySelectorAll('.js-plotly-plot')]"
                           ".find(e => e.layout.meta.id === 'phase_plane');"
                           " return (el.layout.annotations || []).some(a => a.name === 'verdict'"
                           " && a.text.includes('CHATTER')); }")
    names = page.evaluate(NAMES_JS)
    assert {"pin 1 trajectory", "pin 1 ω_r"} <= set(names)  # the ghost outlives the new run
    page.get_by_role("button", name="Clear pins").click()
    page.wait_for_function(f"() => !({NAMES_JS})().some(n => n.startsWith('pin '))")


def test_table1_tab_shows_the_printed_row_reversed_row_and_simulation(lecture):
    page = lecture
    click_tab(page, "Table 1 sweep")
    table = page.locator('[data-role="table1"]')
    rows = table.locator("tr").all_inner_texts()
    assert rows[1].startswith("printed in [1]") and "27.9" in rows[1]
    assert rows[2].startswith("printed, columns reversed")
    assert rows[1].split()[-1] == rows[2].split()[3] == "25.1"  # last printed under T_m = 1 s
    page.locator('[data-role="errata-table1"]', has_text="reverse column order").wait_for()
    field(page, "T_m list [s]").fill("1, 1.4")
    page.wait_for_timeout(120)  # viser throttles GUI messages to one per 50 ms
    page.get_by_role("button", name="Run Table-1 sweep").click()
    page.get_by_text("Ready — Table 1: 2 manoeuvre time(s) simulated.").wait_for()  # not "Working…"
    simulated = table.locator("tr").nth(3).inner_text().split()
    assert simulated[:3] == ["simulated,", "this", "drive"] and float(simulated[3]) > 20.0
    click_tab(page, "Overview")


def test_a_saved_demo_state_loads_back_and_a_bad_file_is_refused(lecture, tmp_path):
    page = lecture
    page.get_by_role("button", name="Pin this run").click()
    page.locator('[data-role="pins"]', has_text="pin 1").wait_for()
    page.get_by_text("Demo state (lecture)").click()
    with page.expect_download() as info:
        page.get_by_role("button", name="Save demo state").click()
    saved = Path(info.value.path()).read_text(encoding="utf-8")
    state = loads_state(saved, "saved.json")
    assert len(state.pins) == 1 and state.ranges["T_m"][0] < state.params.manoeuvre.T_m
    T_m = field(page, "T_m manoeuvre time [s]").input_value()
    assert float(T_m) == state.params.manoeuvre.T_m
    page.get_by_role("button", name="Clear pins").click()
    set_number(page, "T_m manoeuvre time [s]", 2.2)
    page.get_by_role("button", name="Simulate").click()
    page.wait_for_function(f"() => !({NAMES_JS})().some(n => n.startsWith('pin '))")
    _wait_thumb(page, "T_m [s] (log)", 2.2)  # the run is shown: the worker is free for the upload
    page.get_by_text("Ready — ").wait_for()
    upload = page.locator("input[type=file][accept^='.json']")
    upload.set_input_files(files=[{"name": "lecture.json", "mimeType": "application/json",
                                   "buffer": saved.encode()}])
    page.wait_for_function(f"() => ({NAMES_JS})().includes('pin 1 trajectory')")
    assert field(page, "T_m manoeuvre time [s]").input_value() == T_m
    _wait_thumb(page, "T_m [s] (log)", float(T_m))
    page.get_by_text("Ready — ").wait_for()
    upload.set_input_files(files=[{"name": "not_a_state.json", "mimeType": "application/json",
                                   "buffer": b'{"demo_state": 1, "preset": "x"}'}])
    page.get_by_text("not_a_state.json is not a demo-state file").wait_for()
    assert field(page, "T_m manoeuvre time [s]").input_value() == T_m  # nothing changed


#: Scrolls the control panel back to its top (earlier tests scrolled it), as a page opens.
TOP_JS = """() => { let e = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === 'Preset');
  for (; e; e = e.parentElement) if (e.scrollTop) e.scrollTop = 0; }"""
#: Boxes (page px) of what a lecturer needs on the projector, and the page's scroll size.
STORY_JS = """() => {
  const row = (text) => { const l = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === text);
    let r = l; while (r && !r.querySelector('[role="slider"]')) r = r.parentElement; return r; };
  const box = (e) => { const r = e.getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; };
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const r = el.getBoundingClientRect(), L = el._fullLayout;
  const verdict = [...el.querySelectorAll('.annotation')].find(a => a.textContent.includes('CHATTER')
                                                                  || a.textContent.includes('chatter'));
  const pin = [...document.querySelectorAll('button')].find(b => b.textContent.trim() === 'Pin this run');
  return {sliders: LABELS.map(t => box(row(t))), pin: box(pin),
          preset: box([...document.querySelectorAll('label')].find(l => l.textContent.trim() === 'Preset')),
          phase: [r.x + L.xaxis._offset, r.y + L.yaxis._offset, L.xaxis._length, L.yaxis._length],
          numbers: box(document.querySelector('[data-role="key-numbers"]')), verdict: box(verdict),
          scroll: [document.scrollingElement.scrollWidth, document.scrollingElement.scrollHeight]};
}"""


def test_the_main_story_fits_1280x720_without_scrolling(lecture):
    page = lecture
    page.get_by_text("Demo state (lecture)").click()  # folded again, as a lecture starts
    page.evaluate(TOP_JS)
    page.wait_for_timeout(100)  # one frame to lay out
    labels = ["K [s/rad] (log)", "T_c [ms] (log)", "T_m [s] (log)", "J_L plant [kg·cm²] (log)"]
    boxes = page.evaluate(STORY_JS.replace("LABELS", json.dumps(labels)))
    page.add_style_tag(content=".mantine-Notifications-root { display: none !important; }")  # uploads' notes
    page.screenshot(path=str(ARTIFACTS / "lecture_1280x720.png"))
    assert boxes["scroll"] == [1280, 720]
    for name in ("pin", "preset", "phase", "numbers", "verdict", *(f"slider {i}" for i in range(4))):
        x, y, w, h = boxes["sliders"][int(name[-1])] if name.startswith("slider") else boxes[name]
        assert w > 0 and h > 0 and x >= 0 and y >= 0 and x + w <= 1280 and y + h <= 720, (name, x, y, w, h)
    # the phase plane keeps its size (≥ 270 px tall: the 14 px tab row wraps to two lines)
    assert boxes["phase"][2] >= 380 and boxes["phase"][3] >= 270


def test_clearing_pins_while_a_runs_figures_go_out_leaves_no_ghost(browser, ui_server, monkeypatch):
    # the overview with its replay is built after the light one is sent; a "Clear pins" in between
    # must not be undone by that figure (drawn with the pins read before the click)
    import pmsm_commissioning.app.ui.replay as replay_module

    built = replay_module.overview_json

    def slow(comparison, *args, **kwargs):
        if kwargs.get("replay", args[0] if args else True):
            time.sleep(0.6)  # the full figure is still being built when the pins are cleared
        return built(comparison, *args, **kwargs)

    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720})
    try:
        page.get_by_role("button", name="Pin this run").click()
        page.wait_for_function(f"() => ({NAMES_JS})().includes('pin 1 trajectory')")
        monkeypatch.setattr(replay_module, "overview_json", slow)
        set_number(page, "K boundary-layer gain [s/rad]", 2)
        page.get_by_role("button", name="Simulate").click()
        page.wait_for_function(f"() => ({NAMES_JS})().some(n => n.includes('±1/K = ±0.5 rad/s'))")  # the light one
        page.get_by_role("button", name="Clear pins").click()
        # the last figure: the run's overview with its replay, without the pin (never, had the run's
        # own full figure come last, as it did)
        page.wait_for_function(f"""() => {{ const n = ({NAMES_JS})(), el = {OVERVIEW_EL};
          return (el.layout.updatemenus || []).length > 0 && n.some(x => x.includes('±1/K = ±0.5 rad/s'))
            && !n.some(x => x.startsWith('pin ')); }}""")
        page.get_by_text("Ready — ").wait_for()
        names = page.evaluate(NAMES_JS)
        assert not [n for n in names if n.startswith("pin ")], names
        assert any("±1/K = ±0.5 rad/s" in n for n in names)  # the new run, not the one before
    finally:
        context.close()
