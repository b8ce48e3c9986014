"""Browser-test fixtures, reusable by every UI test: an in-process server, Chromium, a page.

* ``ui_server`` (session): the web UI on a free loopback port, 3D view and HDRI off.
* ``browser`` (session): Debian's Chromium driven by Playwright (never ``playwright install``).
* ``page`` (function): a fresh 1400×900 context + page, connected, showing the phase plane, fitted.
* :func:`click_tab` selects a tab once its box is steady (the tab row moves while a page opens).
* :func:`figure` reads a Plotly figure out of the page by its ``layout.meta.id``.

Missing Chromium or Playwright: a failure when ``CI=true``, a skip otherwise.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from tests.net import free_port

CHROMIUM = os.environ.get("CHROMIUM_PATH", "/usr/bin/chromium")
LAUNCH_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
               "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"]
VIEWPORT = {"width": 1400, "height": 900}
ARTIFACTS = Path(__file__).resolve().parents[2] / "test-artifacts"
TIMEOUT_MS = 30_000


def _missing(reason: str) -> None:
    if os.environ.get("CI") == "true":
        pytest.fail(f"CI=true: {reason}")
    pytest.skip(reason)


@dataclass
class UiServer:
    """A running web UI: its URL, the viser server and the app config (sessions by client id)."""

    url: str
    server: Any
    config: Any


@pytest.fixture(scope="session")
def ui_server() -> Iterator[UiServer]:
    """The web UI with the default preset, in-process on a free loopback port."""
    from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
    from pmsm_commissioning.app.ui.page import create_server

    server, config = create_server(load_preset(PAPER_PRESET), PAPER_PRESET, host="127.0.0.1",
                                   port=free_port(), scene_3d=False, environment_map=False)
    try:
        yield UiServer(f"http://127.0.0.1:{server.get_port()}", server, config)
    finally:
        server.stop()


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    """Playwright's Chromium (Debian's binary)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _missing("playwright is not installed")
    if not (Path(CHROMIUM).exists() or shutil.which(CHROMIUM)):
        _missing(f"chromium not found at {CHROMIUM} (apt-get install chromium)")
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
        try:
            yield b
        finally:
            b.close()


def open_page(browser: Any, ui: UiServer, viewport: dict[str, int] | None = None,
              init_script: str | None = None, scale: float = 1.0) -> tuple[Any, Any]:
    """A new context + page of ``ui``, waited until the phase plane is drawn and the panels are
    fitted to the window (:func:`wait_for_layout`). Returns (context, page).

    ``init_script`` runs in the page before any of its own scripts; ``scale`` is the device
    pixel ratio (device pixels per CSS pixel).
    """
    context = browser.new_context(viewport=viewport or VIEWPORT, accept_downloads=True,
                                  device_scale_factor=scale)
    if init_script is not None:
        context.add_init_script(init_script)
    page = context.new_page()
    page.set_default_timeout(TIMEOUT_MS)
    before = set(ui.config.sessions)
    page.goto(ui.url)
    # first draw of the page: allowed 3× the usual wait (a loaded 2-core machine needs > 30 s)
    page.get_by_role("button", name="Simulate").wait_for(timeout=3 * TIMEOUT_MS)
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')]"
                           ".some(e => e.layout && e.layout.meta && e.layout.meta.id === 'phase_plane')",
                           timeout=3 * TIMEOUT_MS)
    wait_for_layout(page, session_of(page, ui, before))
    return context, page


def session_of(page: Any, ui: UiServer, before: set[int]) -> Any:
    """The server-side session that ``page`` opened (the one not in ``before``).

    The server registers a session once it is built, which may be just after its first figures
    reached the page: polled until it is there.
    """
    for _ in range(TIMEOUT_MS // 20):
        new = [cid for cid in list(ui.config.sessions) if cid not in before]
        if new:
            assert len(new) == 1, f"expected exactly one new session for the page, found {new}"
            return ui.config.sessions[new[0]]
        page.wait_for_timeout(20)  # poll the server's state again (a positive condition)
    raise AssertionError(f"the page opened no session on the server within {TIMEOUT_MS} ms")


def wait_for_layout(page: Any, session: Any) -> None:
    """Wait until the server knows the page's window size.

    The page's CSS gives the panels their widths from the first frame (``app/ui/layout.py``);
    only the overview plot's height follows the window size the page reports to the server.
    """
    vp = page.viewport_size
    want = (float(vp["width"]), float(vp["height"]))
    for _ in range(TIMEOUT_MS // 20):
        if session.fit.window == want:
            return
        page.wait_for_timeout(20)  # poll the server's state again (a positive condition)
    raise AssertionError(f"the server never got the {vp} window: it has {session.fit.window}")


# A tab's bounding box, recorded once per animation frame; true once it stayed the same in three
# frames running and the tab itself (not a neighbour) is the element under its centre.
TAB_STEADY_JS = """(tab) => {
  const r = tab.getBoundingClientRect();
  const key = [r.x, r.y, r.width, r.height].join();
  const seen = tab.__boxes = (tab.__boxes || []).concat([key]).slice(-3);
  if (r.width === 0 || seen.length < 3 || seen.some(k => k !== key)) return false;
  const hit = document.elementFromPoint(r.x + r.width / 2, r.y + r.height / 2);
  return hit !== null && tab.contains(hit);
}"""


def click_tab(page: Any, name: str) -> None:
    """Select the tab ``name`` (results panel or control panel) and wait until it is selected.

    Clicks only once the tab's box has been steady over two animation frames and nothing covers
    it, so a tab row re-laid out under the pointer cannot take the click. Viser's "software WebGL"
    notice, shown in headless Chromium, may lie over the tab row: notifications let clicks through.
    """
    page.add_style_tag(content=".mantine-Notifications-root, .mantine-Notifications-root * "
                               "{ pointer-events: none !important; }")
    tab = page.get_by_role("tab", name=name, exact=True)
    tab.wait_for()
    tab.scroll_into_view_if_needed()  # a control-panel tab scrolls away with the panel's content
    page.wait_for_function(TAB_STEADY_JS, arg=tab.element_handle(), polling="raf")
    tab.click()
    page.wait_for_function("(t) => t.getAttribute('aria-selected') === 'true'", arg=tab.element_handle())


@pytest.fixture
def page(browser: Any, ui_server: UiServer) -> Iterator[Any]:
    """A connected page of the web UI (own browser context = own session), fitted to its window."""
    context, pg = open_page(browser, ui_server)
    try:
        yield pg
    finally:
        context.close()


FIGURE_JS = """(id) => {
  const el = [...document.querySelectorAll('.js-plotly-plot')]
    .find(e => e.layout && e.layout.meta && e.layout.meta.id === id);
  if (!el) return null;
  // _fullData holds the decoded arrays (data keeps Plotly's base64 "bdata" form).
  return {meta: el.layout.meta, title: el.layout.title && el.layout.title.text,
          traces: el._fullData.map(t => ({name: t.name, n: t.x ? t.x.length : 0,
                                          y: Array.from(t.y || []).slice(0, 4000)}))};
}"""


def figure(page: Any, figure_id: str) -> dict[str, Any] | None:
    """The figure with ``layout.meta.id == figure_id`` as drawn in the page (names, lengths, meta)."""
    return page.evaluate(FIGURE_JS, figure_id)


def field(page: Any, label: str) -> Any:
    """The input of the GUI row labelled ``label`` (viser's text inputs are not linked to their label)."""
    return page.locator(f'xpath=//label[normalize-space(.)="{label}"]/ancestor::*[.//input][1]//input').first


def set_number(page: Any, label: str, value: float | str) -> None:
    """Type a value into the number field labelled ``label`` and leave the field (blur)."""
    field_ = field(page, label)
    field_.fill(str(value))
    field_.press("Tab")
    page.wait_for_timeout(120)  # viser throttles GUI messages to one per 50 ms
