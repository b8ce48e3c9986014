"""The in-plot replay is smooth at every speed: Plotly glides the marker and the cursor between key frames.

The positions are read from the drawn SVG (the marker's ``transform``, the cursor line's path) once
per browser animation frame: a smooth replay moves both in (nearly) every animation frame, and
keeps them in step. One test runs the real page; one draws the overview figure alone with the basic
plotly.js bundle the page can use instead of the full one (:mod:`app.ui.plotly_js`).
"""

from __future__ import annotations

import pytest

from pmsm_commissioning.app.figures.fdsmc_replay import SPEEDS
from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
from pmsm_commissioning.app.ui.plotly_js import BUNDLE
from pmsm_commissioning.app.ui.replay import phase_plane_json
from pmsm_commissioning.sim.fdsmc.engine import compare
from tests.browser.conftest import TIMEOUT_MS

#: Resolves with the drawn [θ_re, ω_r, t] of the FDSMC marker and the ω_r cursor, as fractions of their
#: axes' ranges, and the plot's size (one number), in ``n`` animation frames from ``settle`` ms after
#: pressing ``label`` on (the first key frame is a jump to t = 0). Read from the SVG (marker
#: ``transform``, cursor path) and mapped back through the axes, so that a resize of the plot
#: meanwhile does not count as motion.
SAMPLE_JS = """([label, n, settle]) => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const g = n => [...el.querySelectorAll('g.trace.scatter')].find(g => g.__data__[0].trace.name === n);
  const num = s => s.match(/-?[0-9.]+(e-?[0-9]+)?/g).map(Number);
  const frac = (ax, px) => { const r = ax.range; return (ax.p2d(px) - r[0]) / (r[1] - r[0]); };
  const pos = () => { const L = el._fullLayout;
    const [mx, my] = num(g('FDSMC now').querySelector('path.point').getAttribute('transform'));
    const cx = num(g('time cursor ω_r').querySelector('path.js-line').getAttribute('d'))[0];
    return [frac(L.xaxis, mx), frac(L.yaxis, my), frac(L.xaxis2, cx), L.width * 1e5 + L.height]; };
  const b = el.layout.updatemenus[0].buttons.find(x => x.label === label);
  window.Plotly.animate(el, ...b.args);
  const out = []; let t0 = null;
  const f = (now) => { if (t0 === null) t0 = now;
    if (now - t0 > settle) out.push(pos());
    if (out.length < n) requestAnimationFrame(f); else resolve(out); };
  requestAnimationFrame(f);
})"""
SLOWEST = f"▶ {list(SPEEDS)[-1]}"


def _assert_smooth(samples: list[list[float]], share: float = 0.8, jumps: bool = True) -> None:
    """Marker and cursor move in ≥ ``share`` of the animation frames, the cursor rightwards, no big jump.

    A replay without glides moves only at its key frames (every 1/10 s at best, ≈0.5 s at 0.01×), so
    most animation frames would show no motion and each key frame a jump.
    """
    pairs = [(a, b) for a, b in zip(samples, samples[1:], strict=False) if a[3] == b[3]]  # same plot size
    assert len(pairs) >= 15
    moved = [max(abs(b[0] - a[0]), abs(b[1] - a[1])) > 1e-9 for a, b in pairs]
    assert sum(moved) >= share * len(pairs), f"marker moved in {sum(moved)} of {len(pairs)} animation frames"
    assert sum(b[2] > a[2] for a, b in pairs) >= share * len(pairs)  # the cursor: t grows
    assert sum(b[2] - a[2] for a, b in pairs) > 0
    steps = [max(abs(b[0] - a[0]), abs(b[1] - a[1])) for a, b in pairs]
    assert not jumps or max(steps) <= 0.25 * sum(steps)  # the path is many small steps, not a few jumps


def test_slowest_replay_glides_the_marker_and_the_cursor_in_the_page(page):
    # 0.01×: one key frame per 1/10 s of wall time at most; skip the first key frame (a jump to t = 0)
    samples = page.evaluate(SAMPLE_JS, [SLOWEST, 40, 800])
    # the page's panels may be re-fitted to the window meanwhile: frames across a resize are left out,
    # a few frames right after one read positions not yet redrawn, and the page's animation frames
    # come irregularly on a loaded machine (so step sizes vary: checked on the plot alone below)
    _assert_smooth(samples, share=0.6, jumps=False)


#: Presses ``label`` of the overview's replay and resolves, once per animation frame for ``ms``, with the
#: "Replay t" slider as drawn: [thumb offset [%], number box, slider maximum [s]].
FOLLOW_JS = """([label, ms]) => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const name = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === 'Replay t [s]');
  const row = name.closest('.mantine-Flex-root'), thumb = row.querySelector('[role="slider"]');
  const box = row.querySelector('input.mantine-NumberInput-input');
  window.Plotly.animate(el, ...el.layout.updatemenus[0].buttons.find(x => x.label === label).args).catch(() => {});
  const out = []; const t0 = performance.now();
  const f = () => { out.push([parseFloat(thumb.style.getPropertyValue('--slider-thumb-offset')), parseFloat(box.value),
                              parseFloat(thumb.getAttribute('aria-valuemax'))]);
    if (performance.now() - t0 < ms) requestAnimationFrame(f); else resolve(out); };
  requestAnimationFrame(f); })"""


def test_the_replay_t_slider_follows_the_replay(page):
    """During the in-plot replay the "Replay t" slider is drawn at the replay's time, from 0 to the end."""
    samples = page.evaluate(FOLLOW_JS, [f"▶ {list(SPEEDS)[0]}", 3000])  # 1×: the paper's run lasts ≈ 1.3 s
    offsets = [o for o, _, _ in samples]
    assert min(offsets) <= 10.0 and offsets[-1] == pytest.approx(100.0)  # start (1×: a key frame per 7.7 %) to end
    inside = [(o, t, end) for o, t, end in samples if 5.0 < o < 95.0]
    assert len(inside) >= 5  # seen on its way, not only at the ends
    for o, t, end in inside:
        assert t == pytest.approx(o / 100.0 * end, abs=2e-3)  # the number box says the same time
    moving = offsets[offsets.index(min(offsets)):]
    assert all(b >= a for a, b in zip(moving, moving[1:], strict=False))  # forward only


@pytest.fixture(scope="module")
def overview_json() -> str:
    return phase_plane_json(compare(load_preset(PAPER_PRESET)))


def test_basic_bundle_draws_the_overview_and_glides_its_replay(browser, overview_json):
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    try:
        pg = context.new_page()
        pg.set_default_timeout(TIMEOUT_MS)
        pg.set_content("<div class='js-plotly-plot-host' id='p' style='width:1200px;height:700px'></div>")
        pg.add_script_tag(path=str(BUNDLE))
        drawn = pg.evaluate("(f) => Plotly.newPlot('p', JSON.parse(f)).then(el => el._fullData.map(t => t.name))",
                            overview_json)
        assert {"FDSMC trajectory", "FDSMC now", "time cursor ω_r", "Γ FDSMC"} <= set(drawn)
        assert pg.evaluate("() => document.querySelectorAll('#p .updatemenu-button').length") == len(SPEEDS) + 1
        _assert_smooth(pg.evaluate(SAMPLE_JS, [SLOWEST, 30, 800]))
    finally:
        context.close()
