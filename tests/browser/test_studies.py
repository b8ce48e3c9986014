"""The studies beyond the paper in a real Chromium: optimum side by side, robustness, multi-axis."""

from __future__ import annotations

import multiprocessing
import re
from typing import Any

from pmsm_commissioning.app.figures.fdsmc_comparison import LABELS
from pmsm_commissioning.sim.fdsmc.verdicts import TARGET_BAND
from tests.browser.conftest import click_tab, figure, set_number

PROGRESS_JS = """() => {
  const bars = [...document.querySelectorAll('[role=progressbar]')].filter(e => e.offsetParent !== null);
  return bars.length ? Number(bars[0].getAttribute('aria-valuenow')) : null;
}"""
# Records every value the visible progress bar shows (attribute changes), from now on.
WATCH_PROGRESS_JS = """() => {
  window.__progress = [];
  const seen = () => { const v = (PROGRESS)(); if (v !== null) window.__progress.push(v); };
  new MutationObserver(seen).observe(document.body, {attributes: true, subtree: true,
                                                      attributeFilter: ['aria-valuenow']});
}""".replace("PROGRESS", PROGRESS_JS)
FIGURE_META_JS = """(id) => {
  const el = [...document.querySelectorAll('.js-plotly-plot')]
    .find(e => e.layout && e.layout.meta && e.layout.meta.id === id);
  return el ? el.layout.meta : null;
}"""
# θ_r/θ_dem of each axis read off the drawn traces (x0/dx grid) at the common T_m.
ARRIVAL_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')]
    .find(e => e.layout && e.layout.meta && e.layout.meta.id === 'multiaxis');
  const T = el.layout.meta.T_m;
  return el._fullData.filter(t => t.yaxis === 'y').map(t => {
    const k = Math.round((T - t.x0) / t.dx);
    return {name: t.name, y: Number(t.y[k])};
  });
}"""


def _open_tab(page: Any, name: str) -> None:
    """Select a results tab (the studies' tabs sit inside "Studies")."""
    for label in (("Studies", name) if name in ("Robustness", "Multi-axis") else (name,)):
        click_tab(page, label)


def _session(ui_server: Any, page: Any) -> Any:
    """The server-side session of ``page`` (the most recently connected one)."""
    return ui_server.config.sessions[max(ui_server.config.sessions)]


def _meta(page: Any, fid: str) -> dict[str, Any] | None:
    return page.evaluate(FIGURE_META_JS, fid)


def test_optimum_is_drawn_and_its_energy_bar_is_below_both_others(page):
    # shown by default: the optimum is simulated with every Simulate
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && "
                           "e.layout.meta && e.layout.meta.id === 'phase_plane' && "
                           "e.data.some(t => t.name === 'Optimum trajectory'))")
    phase = {t["name"]: t for t in figure(page, "phase_plane")["traces"]}
    assert phase["Optimum trajectory"]["n"] > 100
    _open_tab(page, "Energy")
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && "
                           "e.layout.meta && e.layout.meta.id === 'energy_bars' && e.data.length === 3)")
    bars = {t["name"]: t["y"] for t in figure(page, "energy_bars")["traces"]}
    electrical = {k: v[2] for k, v in bars.items()}  # kinds: friction, copper, electrical input
    assert electrical["Optimum"] < electrical["FDSMC"] and electrical["Optimum"] < electrical["Conventional"]
    gaps = _meta(page, "energy_bars")["gap_to_optimum_pct"]
    assert abs(gaps["fdsmc"] - 100.0 * (1.0 - electrical["Optimum"] / electrical["FDSMC"])) < 1e-6 * 100
    page.get_by_text(re.compile(rf"undercuts {LABELS['fdsmc']}'s by {gaps['fdsmc']:.1f} %")).wait_for()


def test_robustness_run_progress_reaches_100_and_draws_histograms(page, ui_server):
    _open_tab(page, "Robustness")
    set_number(page, "Samples", 40)
    set_number(page, "Seed", 5)
    page.evaluate(WATCH_PROGRESS_JS)
    page.get_by_role("button", name="Run robustness study").click()
    page.get_by_text(re.compile(r"Done: 40 samples in")).wait_for()
    page.wait_for_function(f"() => ({PROGRESS_JS})() === 100")
    seen = page.evaluate("() => window.__progress")
    assert any(0 < v < 100 for v in seen), seen  # it advanced while running, not only at the end
    assert seen == sorted(seen)
    meta = _meta(page, "robustness")
    assert meta["samples"] == 40
    traces = figure(page, "robustness")["traces"]
    friction = [t for t in traces if t["name"] == "FDSMC vs conventional"][0]
    result = _session(ui_server, page).studies.robustness.result
    with_saving = sum(isinstance(r["fdsmc"]["saving_friction_pct"], float) for r in result.runs)
    assert round(sum(friction["y"])) == with_saving == meta["drawn"]["saving_friction_pct"]["fdsmc"]
    assert {"FDSMC", "Conventional"} <= {t["name"] for t in traces}
    page.get_by_text("chatter probability", exact=False).first.wait_for()


def test_cancel_stops_a_large_robustness_run(page, ui_server):
    _open_tab(page, "Robustness")
    set_number(page, "Samples", 5000)
    before = set(multiprocessing.active_children())
    page.get_by_role("button", name="Run robustness study").click()
    page.get_by_text(re.compile(r"Running: \d+ of 5000 samples")).wait_for(timeout=90_000)
    page.get_by_role("button", name="Cancel robustness study").click()
    status = page.get_by_text(re.compile(r"Cancelled after \d+ of 5000 samples"))
    status.wait_for(timeout=60_000)
    done = int(re.search(r"after (\d+) of", status.inner_text()).group(1))
    assert done < 5000
    session = _session(ui_server, page)
    assert not session.worker.busy  # the job has ended …
    assert set(multiprocessing.active_children()) <= before  # … and the pool's processes are gone
    assert page.evaluate(PROGRESS_JS) < 100
    assert session.studies.robustness.progress.value < 100
    page.get_by_text("Cancelled — the previous results are kept.").wait_for()


def test_multiaxis_axes_all_arrive_within_tolerance_at_common_T_m(page):
    _open_tab(page, "Multi-axis")
    page.get_by_role("button", name="Run multi-axis move").click()
    page.get_by_text(re.compile(r"Done: \d+ of \d+ axes arrived")).wait_for(timeout=90_000)
    page.wait_for_function(f"() => ({FIGURE_META_JS})('multiaxis') !== null")
    meta = _meta(page, "multiaxis")
    band = TARGET_BAND["fdsmc"]
    assert meta["band"] == band and len(meta["names"]) >= 2
    arrivals = page.evaluate(ARRIVAL_JS)
    assert [a["name"] for a in arrivals] == meta["names"]
    for a in arrivals:
        assert abs(a["y"] - 1.0) <= band + 1e-3, a
    assert page.get_by_text(re.compile(rf"Common T_m = {meta['T_m']:.4g} s")).count() >= 1
