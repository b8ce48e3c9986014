"""The K demo at 1280×720: the results panel's tabs on one line and nothing in it scrolls; the K demo's
controls (K slider, its verdict readout, "Use recommended K", the T_c button, the phase plane with its
verdict) in view together; the overview's legend entries never overlap, simulated or not.
"""

from __future__ import annotations

import re
from typing import Any

from tests.browser.conftest import TIMEOUT_MS, open_page, set_number

VIEW = {"width": 1280, "height": 720}
#: The results panel's tab titles (a row of its own, right of the control panel).
RESULTS_TABS = ("Overview", "Time plots", "K sweep", "Energy", "Stock drive", "Table 1 sweep", "Studies",
                "BLDC figures", "Share")
#: [top, bottom] of each results tab.
TABS_JS = """(titles) => titles.map(t => { const e = [...document.querySelectorAll('[role="tab"]')]
  .find(x => x.getAttribute('title') === t); const r = e && e.getBoundingClientRect();
  return r ? [r.top, r.bottom, r.right] : null; })"""
#: Every scroll box of the results panel (the one holding the key numbers, and any inside it):
#: [scrollHeight, clientHeight].
RESULTS_SCROLL_JS = """() => { const k = document.querySelector('[data-role="key-numbers"]');
  const boxes = []; for (let e = k; e; e = e.parentElement) {
    if (['auto', 'scroll'].includes(getComputedStyle(e).overflowY)) boxes.push(e); }
  const panel = boxes[boxes.length - 1];
  const inner = panel ? [...panel.querySelectorAll('*')].filter(e => ['auto', 'scroll']
    .includes(getComputedStyle(e).overflowY)) : [];
  return [...new Set([...boxes, ...inner])].map(e => [e.scrollHeight, e.clientHeight]); }"""
#: Boxes [left, top, right, bottom] of the K demo's controls (null: not found or not shown).
CONTROLS_JS = """() => { const box = e => { if (!e) return null; const r = e.getBoundingClientRect();
    return r.width && r.height ? [r.left, r.top, r.right, r.bottom] : null; };
  const button = p => [...document.querySelectorAll('button')].find(b => b.textContent.trim().startsWith(p));
  const label = t => [...document.querySelectorAll('label')].find(l => l.textContent.trim() === t);
  const slider = l => l && l.closest('.mantine-Flex-root') && l.closest('.mantine-Flex-root')
    .querySelector('.mantine-Slider-root');
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout && e.layout.meta
    && e.layout.meta.id === 'phase_plane');
  const v = el ? el.layout.annotations.findIndex(a => a.name === 'verdict') : -1;
  return {'K slider': box(slider(label('K [s/rad] (log)'))),
          'K readout': box(document.querySelector('[data-role="k-readout"]')),
          'Use recommended K': box(button('Use recommended K')), 'Use T_c': box(button('Use T_c')),
          'phase plane': box(el && el.querySelector('.nsewdrag')),
          'verdict': box(el && el.querySelector(`g.annotation[data-index="${v}"] rect.bg`))}; }"""
#: The overview legend's entries as drawn: [name, left, top, right, bottom] of each entry's symbol and text.
LEGEND_JS = """() => { const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout
    && e.layout.meta && e.layout.meta.id === 'phase_plane');
  return [...el.querySelectorAll('g.legend g.traces')].map(g => { const t = g.querySelector('text.legendtext');
    const s = g.querySelector('.legendpoints'); const a = t.getBoundingClientRect(), b = s.getBoundingClientRect();
    return [t.textContent, Math.min(a.left, b.left), Math.min(a.top, b.top), Math.max(a.right, b.right),
            Math.max(a.bottom, b.bottom)]; }); }"""


def _fits(page: Any, wanted: tuple[str, ...]) -> None:
    """The results tabs on one line, nothing in the results panel scrolls, ``wanted`` controls in the window."""
    tabs = page.evaluate(TABS_JS, list(RESULTS_TABS))
    assert all(t is not None for t in tabs), tabs
    assert max(t[0] for t in tabs) - min(t[0] for t in tabs) < 1, tabs  # one line
    assert max(t[2] for t in tabs) <= VIEW["width"], tabs
    scroll = page.evaluate(RESULTS_SCROLL_JS)
    assert scroll and all(height <= client for height, client in scroll), scroll
    boxes = page.evaluate(CONTROLS_JS)
    for name in wanted:
        box = boxes[name]
        assert box is not None, (name, boxes)
        left, top, right, bottom = box
        assert left >= 0 and top >= 0 and right <= VIEW["width"] and bottom <= VIEW["height"], (name, box)


def _wait_ready(page: Any, runs: int) -> None:
    page.wait_for_function("(n) => document.body.innerText.includes(`Ready — ${n} run(s) in this session`)",
                           arg=runs, timeout=3 * TIMEOUT_MS)


def test_the_k_demo_fits_1280x720_without_scrolling(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport=VIEW)
    try:
        page.get_by_role("button", name=re.compile("^Use recommended K")).wait_for()  # K = 1000 chatters
        page.wait_for_timeout(500)  # the tab row's web font settles (a positive check follows)
        _fits(page, ("K slider", "K readout", "Use recommended K", "phase plane", "verdict"))
        # a slow manoeuvre: the recommended K still limit-cycles about θ_dem; the T_c remedy appears
        set_number(page, "T_m manoeuvre time [s]", 60)
        page.get_by_role("button", name="Simulate").click()
        _wait_ready(page, 1)
        page.get_by_role("button", name=re.compile("^Use recommended K")).click()
        _wait_ready(page, 2)
        page.get_by_role("button", name=re.compile("^Use T_c = ")).wait_for()
        _fits(page, ("K slider", "K readout", "Use T_c", "phase plane", "verdict"))
    finally:
        context.close()


def _legend_apart(page: Any) -> list[list[Any]]:
    entries = page.evaluate(LEGEND_JS)
    assert len(entries) >= 2, entries
    for i, a in enumerate(entries):
        for b in entries[i + 1:]:
            apart = a[3] <= b[1] or b[3] <= a[1] or a[4] <= b[2] or b[4] <= a[2]
            assert apart, (a, b)
    return entries


def test_the_overview_legend_entries_never_overlap(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport=VIEW)
    try:
        assert len(_legend_apart(page)) >= 5  # a run: layer, boundary, the phases, the other controllers
        set_number(page, "T_m manoeuvre time [s]", 0.3)  # below T_m,min: not simulated
        page.get_by_role("button", name="Simulate").click()
        page.get_by_text("Not simulated (infeasible manoeuvre).").wait_for(timeout=3 * TIMEOUT_MS)
        page.wait_for_function("() => { const el = [...document.querySelectorAll('.js-plotly-plot')].find("
                               "e => e.layout && e.layout.meta && e.layout.meta.id === 'phase_plane');"
                               " return el && el._fullData.every(t => !(t.name || '').endsWith(' now')); }")
        names = [e[0] for e in _legend_apart(page)]
        assert any(n.startswith("Layer ±1/K") for n in names), names
    finally:
        context.close()


#: Plays the overview's replay at ``label`` and, in each of ``n`` animation frames, records whether the
#: FDSMC marker's time label meets the verdict box, the zoom window's mark in the phase plane or the
#: zoom inset; resolves with {labelled frames, hits by what, first hits, [verdict, zoom mark, inset found],
#: the last frame's [label text, label box, phase-plane plot area box]}.
REPLAY_HITS_JS = """([label, n]) => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const now = () => [...el.querySelectorAll('g.trace.scatter')].find(g => g.__data__[0].trace.name === 'FDSMC now');
  const box = e => { if (!e) return null; const r = e.getBoundingClientRect();
    return r.width ? [r.left, r.top, r.right, r.bottom] : null; };
  const meet = (a, b) => a && b && a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
  const L = el.layout, v = L.annotations.findIndex(a => a.name === 'verdict');
  const z = (L.shapes || []).findIndex(s => s.xref === 'x' && s.yref === 'y');
  const b = L.updatemenus[0].buttons.find(x => x.label === label);
  window.Plotly.animate(el, ...b.args);
  const out = {frames: 0, hits: {verdict: 0, zoom: 0, inset: 0}, first: [], marks: [v >= 0, z >= 0, false]};
  const f = () => {
    const t = now() && now().querySelector('text'), tb = t && t.textContent ? box(t) : null;
    const others = {verdict: box(el.querySelector(`g.annotation[data-index="${v}"] rect.bg`)),
                    zoom: z >= 0 ? box(el.querySelector(`.shapelayer path[data-index="${z}"]`)) : null,
                    inset: box(el.querySelector('g.x4y5 > rect.nsewdrag'))};
    out.marks[2] = !!others.inset;
    if (tb) { out.frames += 1; out.last = [t.textContent, tb, box(el.querySelector('g.xy > rect.nsewdrag'))];
      for (const [k, o] of Object.entries(others)) if (meet(tb, o)) { out.hits[k] += 1;
        if (out.first.length < 4) out.first.push([k, t.textContent, tb, o]); } }
    if (--n > 0) requestAnimationFrame(f); else resolve(out);
  };
  requestAnimationFrame(f);
})"""


def test_the_replay_time_label_keeps_clear_of_the_verdict_and_the_zoom(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport=VIEW)
    try:
        for clean in (False, True):  # the paper's K = 1000 (chatter), then the recommended K (a wide layer)
            if clean:
                page.get_by_role("button", name=re.compile("^Use recommended K")).click()
                _wait_ready(page, 1)
                page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout"
                                       " && e.layout.meta && e.layout.meta.id === 'phase_plane'"
                                       " && (e.layout.updatemenus || []).length > 0"
                                       " && e.layout.annotations.some(a => a.name === 'verdict'"
                                       " && a.text.includes('no chatter')))", timeout=3 * TIMEOUT_MS)
            seen = page.evaluate(REPLAY_HITS_JS, ["▶ 0.25×", 240])
            assert seen["frames"] >= 30 and seen["marks"] == [True, True, True], seen
            assert seen["hits"] == {"verdict": 0, "zoom": 0, "inset": 0}, seen
            text, label, plane = seen["last"]  # the replay's end: the marker at the plot's right edge
            assert text.startswith("t = ") and plane[0] - 1 <= label[0] and label[2] <= plane[2] + 1, seen["last"]
    finally:
        context.close()
