"""Take the documentation's screenshots from the real page at 1280×720 (a projector) with Playwright.

Writes ``docs/k_demo_chatter_1280x720.png`` (paper preset, K = 1000: chattering),
``docs/k_demo_clean_1280x720.png`` (after "Use recommended K") and ``docs/bldc_tab_1280x720.png``
(BLDC tab, paper drive with and without anti-windup side by side), and the BLDC torque small
multiples and anti-windup figures scrolled into view (``docs/bldc_torque_1280x720.png``,
``docs/bldc_antiwindup_1280x720.png``). The server runs in-process
with the 3D view off. Usage: ``.venv/bin/python scripts/docs_screenshots.py``
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from playwright.sync_api import sync_playwright  # noqa: E402

from app.io.presets import PAPER_PRESET, load_preset  # noqa: E402
from app.ui.page import create_server  # noqa: E402
from tests.browser.conftest import CHROMIUM, LAUNCH_ARGS, click_tab, free_port  # noqa: E402

DOCS = ROOT / "docs"
SIZE = {"width": 1280, "height": 720}
FIGURE_DRAWN = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
                " && e.layout.meta.id === id && e.data.length && e.getBoundingClientRect().width > 0)")

SCROLL_TO = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout && e.layout.meta"
             " && e.layout.meta.id === id).scrollIntoView({block: 'start'})")


def _settle(page) -> None:
    page.wait_for_timeout(2500)  # the run, its figures and an autoplayed replay's first frames


def main() -> int:
    server, config = create_server(load_preset(PAPER_PRESET), PAPER_PRESET, port=free_port(), scene_3d=False)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
            page = browser.new_page(viewport=SIZE)
            page.set_default_timeout(120_000)
            page.goto(f"http://127.0.0.1:{server.get_port()}")
            page.add_style_tag(content=".mantine-Notifications-root {display: none !important}")  # WebGL notice
            page.wait_for_function(FIGURE_DRAWN, arg="phase_plane")
            _settle(page)
            page.screenshot(path=str(DOCS / "k_demo_chatter_1280x720.png"))
            page.get_by_role("button", name=re.compile(r"^Use recommended K")).first.click()
            _settle(page)
            page.get_by_role("tab", name="Position drive (FDSMC)", exact=True).scroll_into_view_if_needed()
            page.mouse.move(200, 30)  # no tooltip under the pointer
            page.wait_for_timeout(500)
            page.screenshot(path=str(DOCS / "k_demo_clean_1280x720.png"))
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
            browser.close()
    finally:
        server.stop()
    print("wrote", ", ".join(p.name for p in sorted(DOCS.glob("*_1280x720.png"))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
