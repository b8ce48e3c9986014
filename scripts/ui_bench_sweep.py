"""The K sweep's figures for ``scripts/ui_bench.py``: redraws per second while its slider is dragged, CPU and bytes.

* **redraws/s**: the page is on the *K sweep* tab; the mouse drags the figure's own slider back and
  forth over its steps (Playwright's moves, which the browser hands to the page at most once per
  animation frame); an in-page counter counts the animation frames in which the figure shows a
  new K (the trajectory's data replaced by a frame), over the drag's time.
* **CPU and bytes** (in-process, paper preset, warm): the grid's FDSMC runs and the figure's JSON,
  its size as sent (msgpack's string) and after viser's zstd (level 1).
"""

from __future__ import annotations

import statistics
import time

#: Counts animation frames with a new K shown in the sweep figure until ``window.__sweepStop``;
#: resolves with [redraws, elapsed ms].
COUNT_JS = """() => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout && e.layout.meta
                                                                      && e.layout.meta.id === 'k_sweep');
  const shown = () => el.data[2].y;
  let last = shown(), n = 0; const t0 = performance.now(); window.__sweepStop = false;
  const f = () => { const s = shown(); if (s !== last) { n += 1; last = s; }
    if (!window.__sweepStop) requestAnimationFrame(f); else resolve([n, performance.now() - t0]); };
  requestAnimationFrame(f); })"""
READY_JS = """() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta
  && e.layout.meta.id === 'k_sweep' && e._fullLayout && e._fullLayout.sliders && e._fullLayout.sliders.length)"""


def sweep_redraws(page, seconds: float = 2.0) -> float:
    """Redraws per second of the K sweep figure while the mouse drags its slider (one step per move)."""
    from tests.browser.conftest import click_tab

    click_tab(page, "K sweep")
    page.wait_for_function(READY_JS, timeout=30_000)
    rail = page.locator(".js-plotly-plot .slider-rail-rect").first.bounding_box()
    steps = page.evaluate("() => [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta"
                          " && e.layout.meta.id === 'k_sweep')._fullLayout.sliders[0].steps.length")
    y, x0, dx = rail["y"] + rail["height"] / 2, rail["x"] + 2, (rail["width"] - 4) / max(steps - 1, 1)
    page.mouse.move(x0, y)
    page.mouse.down()
    page.evaluate(f"() => {{ window.__sweepCount = ({COUNT_JS})(); }}")  # not awaited: it ends at __sweepStop
    t0, k, way = time.perf_counter(), 0, 1
    while time.perf_counter() - t0 < seconds:
        k += way
        if k in (0, steps - 1):
            way = -way
        page.mouse.move(x0 + k * dx, y)
    page.evaluate("() => { window.__sweepStop = true; }")
    n, ms = page.evaluate("() => window.__sweepCount")
    page.mouse.up()
    click_tab(page, "Overview")
    return n / (ms / 1e3)


def sweep_cost(rounds: int = 5) -> str:
    """One line: server CPU of the grid's runs and of the figure, its JSON and zstd bytes (paper preset, warm)."""
    import zstandard

    from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
    from pmsm_commissioning.app.ui.k_sweep import k_sweep_json, sweep_points
    from pmsm_commissioning.sim.fdsmc.engine import compare

    base = compare(load_preset(PAPER_PRESET), ("fdsmc",))
    sweep_points(base, None)  # the kernels loaded
    runs_s, fig_s, size = [], [], (0, 0, 0)
    for _ in range(rounds):
        c = compare(load_preset(PAPER_PRESET), ("fdsmc",))  # a new comparison: nothing cached
        t0 = time.process_time()
        points = sweep_points(c, None)
        t1 = time.process_time()
        text = k_sweep_json(c, None)
        fig_s.append(time.process_time() - t1 - (t1 - t0))  # k_sweep_json runs the grid again
        runs_s.append(t1 - t0)
        raw = text.encode()
        size = (len(points), len(raw), len(zstandard.ZstdCompressor(level=1).compress(raw)))
    return (f"K sweep (paper preset, {size[0]} K values, {rounds} rounds, in-process, warm): FDSMC runs "
            f"{statistics.median(runs_s):.3f} s CPU (min {min(runs_s):.3f}, max {max(runs_s):.3f}), figure "
            f"{statistics.median(fig_s) * 1e3:.0f} ms; JSON {size[1] / 1e3:.0f} kB, {size[2] / 1e3:.0f} kB after "
            f"viser's zstd")


__all__ = ["sweep_cost", "sweep_redraws"]
