"""Take the documentation's screenshots from the real page with Playwright (1280×720: a projector).

Writes, from one in-process server (paper preset, 3D view off):

* ``docs/k_demo_chatter_1280x720.png`` (K = 1000: chattering) and ``docs/k_demo_clean_1280x720.png``
  (after "Use recommended K");
* ``docs/k_sweep_chatter_1280x720.png`` and ``docs/k_sweep_clean_1280x720.png``: the *K sweep* tab
  mid-drag, its own slider held at a chattering K, then at a clean one;
* ``docs/sliding_zoom_1280x720.png``: the overview at the recommended K with its phase plane
  zoomed onto the window of the automatic sliding-region inset (boundary layer, sliding at ω_p);
* ``docs/projector_1280x720.png``: the same page half-way through a replay (the trail drawn so far);
* ``docs/table1_1280x720.png`` and ``docs/table1_errata_1280x720.png``: the *Table 1 sweep* tab
  after the sweep (numeric table with the printed row, the printed row reversed and the
  simulation, and the figure), then scrolled to the figure and the errata;
* ``docs/bldc_tab_1280x720.png`` (BLDC tab, paper drive with and without anti-windup side by
  side) and the BLDC torque small multiples and anti-windup figures scrolled into view
  (``docs/bldc_torque_1280x720.png``, ``docs/bldc_antiwindup_1280x720.png``);
* ``docs/screenshot.png``: the main view on a 1920×1080 screen (the README's picture).

Usage: ``.venv/bin/python scripts/docs_screenshots.py`` (about a minute).
"""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from playwright.sync_api import sync_playwright  # noqa: E402

from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset  # noqa: E402
from pmsm_commissioning.app.ui.page import create_server  # noqa: E402
from tests.browser.conftest import CHROMIUM, LAUNCH_ARGS, click_tab  # noqa: E402
from tests.net import free_port  # noqa: E402

DOCS = ROOT / "docs"
SIZE = {"width": 1280, "height": 720}
WIDE = {"width": 1920, "height": 1080}
FIGURE_DRAWN = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
                " && e.layout.meta.id === id && e.data.length && e.getBoundingClientRect().width > 0)")
SCROLL_TO = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout && e.layout.meta"
             " && e.layout.meta.id === id).scrollIntoView({block: 'start'})")
#: Zoom the overview's phase plane onto the sliding region: from its left edge (the layer entry) to the
#: right end of the automatic inset's window (axes x4/y5), at the inset's speeds widened by half.
ZOOM_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const L = el.layout; if (!L.xaxis4 || !L.yaxis5) return false;
  const [y0, y1] = L.yaxis5.range, x = [L.xaxis.range[0], L.xaxis4.range[1]];
  window.Plotly.relayout(el, {'xaxis.range': x, 'yaxis.range': [y0 - (y1 - y0) / 2, y1 + (y1 - y0) / 2]});
  return true;
}"""
#: Start the overview's in-browser replay at the speed ``label`` (its play button).
PLAY_JS = """(label) => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const b = [...el.querySelectorAll('.updatemenu-button')].find(b => b.textContent.includes(label));
  if (!b) return false;
  b.dispatchEvent(new MouseEvent('click', {bubbles: true})); return true;
}"""


def _settle(page: Any, ms: int = 2500) -> None:
    page.wait_for_timeout(ms)  # the run, its figures and an autoplayed replay's first frames


def _shot(page: Any, name: str) -> None:
    page.mouse.move(200, 30)  # no tooltip under the pointer
    page.wait_for_timeout(300)
    page.screenshot(path=str(DOCS / name))


def _open(browser: Any, port: int, size: dict[str, int]) -> Any:
    page = browser.new_page(viewport=size)
    page.set_default_timeout(120_000)
    page.goto(f"http://127.0.0.1:{port}")
    page.wait_for_function(FIGURE_DRAWN, arg="phase_plane")
    _settle(page)
    return page


def _k_demo(page: Any) -> None:
    """The K demo: chatter at K = 1000, clean at the recommended K, its sliding region, a replay."""
    _shot(page, "k_demo_chatter_1280x720.png")
    page.get_by_role("button", name=re.compile(r"^Use recommended K")).first.click()
    _settle(page)
    page.get_by_role("tab", name="Position drive (FDSMC)", exact=True).scroll_into_view_if_needed()
    _shot(page, "k_demo_clean_1280x720.png")
    page.evaluate(PLAY_JS, "0.25×")
    page.wait_for_timeout(2500)  # half of the replay (≈ 5 s): the trail drawn so far
    _shot(page, "projector_1280x720.png")
    page.wait_for_timeout(3500)  # the replay ends: the whole trajectory
    if page.evaluate(ZOOM_JS):
        _shot(page, "sliding_zoom_1280x720.png")


def _k_sweep(page: Any) -> None:
    """The K sweep tab mid-drag: its own slider held at a chattering K, then at a clean one (the pointer down)."""
    click_tab(page, "K sweep")
    page.wait_for_function(FIGURE_DRAWN, arg="k_sweep")
    page.wait_for_timeout(800)
    rail = page.locator(".js-plotly-plot .slider-rail-rect").first.bounding_box()
    steps = page.evaluate("() => [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta"
                          " && e.layout.meta.id === 'k_sweep')._fullLayout.sliders[0].steps.length")
    y, dx = rail["y"] + rail["height"] / 2, (rail["width"] - 4) / (steps - 1)
    page.mouse.move(rail["x"] + 2 + (steps - 1) * dx, y)
    page.mouse.down()
    for k, name in ((steps - 6, "k_sweep_chatter_1280x720.png"), (7, "k_sweep_clean_1280x720.png")):
        page.mouse.move(rail["x"] + 2 + k * dx, y, steps=12)
        page.wait_for_timeout(400)
        page.screenshot(path=str(DOCS / name))
    page.mouse.up()
    click_tab(page, "Overview")


def _table1(page: Any) -> None:
    """The Table 1 sweep tab after its sweep: the numeric table and figure, then the errata."""
    click_tab(page, "Table 1 sweep")
    page.get_by_role("button", name="Run Table-1 sweep").click()
    page.get_by_text(re.compile(r"^Ready — Table 1:")).wait_for()
    page.wait_for_function(FIGURE_DRAWN, arg="table1")
    page.wait_for_timeout(800)
    _shot(page, "table1_1280x720.png")
    page.locator('[data-role="errata-table1"]').scroll_into_view_if_needed()
    _shot(page, "table1_errata_1280x720.png")
    click_tab(page, "Overview")


def _bldc(page: Any) -> None:
    """The BLDC tab with the anti-windup runs side by side, and two of its figures scrolled into view."""
    page.get_by_role("tab", name="BLDC speed SMC", exact=True).scroll_into_view_if_needed()
    click_tab(page, "BLDC speed SMC")
    page.get_by_text("Paper drive with / without anti-windup, side by side", exact=True).click()
    page.wait_for_timeout(200)
    page.get_by_role("button", name="Simulate BLDC").click()
    page.wait_for_function(FIGURE_DRAWN, arg="bldc_antiwindup")
    page.wait_for_timeout(1500)
    page.screenshot(path=str(DOCS / "bldc_tab_1280x720.png"))
    for fid in ("bldc_torque", "bldc_antiwindup"):  # the small multiples and the side-by-side runs
        page.evaluate(SCROLL_TO, fid)
        page.wait_for_timeout(800)
        page.screenshot(path=str(DOCS / f"{fid}_1280x720.png"))


def _wide(browser: Any, port: int) -> None:
    """The main view on a 1920×1080 screen after "Use recommended K" (the README's picture)."""
    page = _open(browser, port, WIDE)
    page.get_by_role("button", name=re.compile(r"^Use recommended K")).first.click()
    _settle(page)
    page.get_by_role("tab", name="Position drive (FDSMC)", exact=True).scroll_into_view_if_needed()
    _shot(page, "screenshot.png")
    page.close()


def main() -> int:
    started = time.monotonic()
    server, _ = create_server(load_preset(PAPER_PRESET), PAPER_PRESET, port=free_port(), scene_3d=False)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
            page = _open(browser, server.get_port(), SIZE)
            _k_demo(page)
            _k_sweep(page)
            _table1(page)
            _bldc(page)
            page.close()
            _wide(browser, server.get_port())
            browser.close()
    finally:
        server.stop()
    names = sorted(p.name for p in DOCS.glob("*.png"))
    print(f"wrote {', '.join(names)} in {time.monotonic() - started:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
