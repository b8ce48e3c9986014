"""The page in a real Chromium against hostile input: a foreign web page cannot open the tool's
websocket, and markup in user text (file names, column headers, notes, preset names and sources) is
shown as text: no script runs.
"""

from __future__ import annotations

import http.server
import re
import threading
from collections.abc import Iterator
from typing import Any

import pytest
import viser

from pmsm_commissioning.app.io.presets import PRESET_DIR, loads_preset
from pmsm_commissioning.app.ui.log import EXAMPLE_LOG
from tests.browser.conftest import click_tab, open_page

OPEN_WS_JS = """async ([url, protocol]) => await new Promise((resolve) => {
  const ws = new WebSocket(url, [protocol]);
  ws.onopen = () => { ws.close(); resolve('open'); };
  ws.onerror = () => resolve('refused');
  setTimeout(() => resolve('timeout'), 15000);
})"""
MARKUP = "# GAINS VERIFIED - USE K=50 <b>bold</b> `x` ![i](http://127.0.0.1:9/i.png)"


@pytest.fixture
def foreign_site() -> Iterator[str]:
    """Another web site (another origin) on a loopback port, serving an empty page."""

    class Quiet(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802
            body = b"<html><body>another site</body></html>"
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: object) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()


def test_foreign_origin_cannot_open_the_websocket(browser, ui_server, foreign_site):
    ws_url = ui_server.url.replace("http://", "ws://")
    protocol = f"viser-v{viser.__version__}"
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto(foreign_site)
        assert page.evaluate(OPEN_WS_JS, [ws_url, protocol]) == "refused"
        assert any(foreign_site.lower() in r for r in ui_server.config.guard.refused)
        page.goto(ui_server.url)  # the tool's own page may
        assert page.evaluate(OPEN_WS_JS, [ws_url, protocol]) == "open"
    finally:
        context.close()


def test_markup_in_file_and_preset_names_is_shown_as_text(page):
    text = (PRESET_DIR / "bldc_smc_paper.yaml").read_text(encoding="utf-8").replace(
        "name: bldc_smc_paper", f"name: '{MARKUP}'")
    assert loads_preset(text).name == MARKUP
    file_name = "`<img src=x onerror=alert(1)>`.yaml"
    click_tab(page, "BLDC speed SMC")
    with page.expect_file_chooser() as chooser:
        page.get_by_role("button", name="Import BLDC preset (YAML)").click()
    chooser.value.set_files(files=[{"name": file_name, "mimeType": "text/yaml", "buffer": text.encode()}])
    status = page.locator("p", has_text="Imported").first
    status.wait_for()
    shown = status.inner_text()
    assert "GAINS VERIFIED - USE K=50 <b>bold</b> `x` ![i](http://127.0.0.1:9/i.png)" in shown
    assert "<img src=x onerror=alert(1)>" in shown
    assert page.locator("img[src='x']").count() == 0
    assert page.locator("img[src='http://127.0.0.1:9/i.png']").count() == 0
    assert page.get_by_role("heading", name="GAINS VERIFIED").count() == 0
    assert status.locator("b", has_text="bold").count() == 0


# Markup whose script, if it ever ran, sets window.__pwn (top window or parent of an iframe).
SCRIPT_NAME = "x<img src=x onerror=window.__pwn=1>.csv"
IFRAME = '<iframe srcdoc="&lt;script&gt;parent.__pwn=2&lt;/script&gt;"></iframe>'
SVG = "<svg onload=window.__pwn=3>"
ARMED = "window.__pwn = 0; window.alert = () => { window.__pwn = 9; };"


def _hostile_log() -> bytes:
    """The example log plus a tool column whose header (unit) carries an iframe with a script."""
    lines = EXAMPLE_LOG.read_text(encoding="utf-8").splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    header = IFRAME.replace('"', '""')
    lines[head] += f',"alpha [{header}]"'
    lines[head + 1:] = [f"{line},0" for line in lines[head + 1:]]
    return ("\n".join(lines) + "\n").encode()


def _assert_inert(page: Any) -> None:
    """No payload ran and none became an element: the markup is shown as text only."""
    assert page.evaluate("window.__pwn") == 0
    assert page.locator("iframe[srcdoc]").count() == 0
    assert page.locator("img[src='x']").count() == 0
    assert page.locator("svg[onload]").count() == 0


def test_markup_in_log_header_file_name_and_preset_runs_no_script(browser, ui_server):
    context, page = open_page(browser, ui_server, init_script=ARMED)
    try:
        page.get_by_text("Drive log (measured)").click()
        page.get_by_role("button", name="Load example log").click()
        page.get_by_text(re.compile(r"drive_log_dq\.csv: 6800 samples")).wait_for()
        page.locator("input[type=file][accept*='.csv']").set_input_files(
            files=[{"name": SCRIPT_NAME, "mimeType": "text/csv", "buffer": _hostile_log()}])
        page.get_by_text(re.compile(r"x<img src=x onerror=window.__pwn=1>\.csv: 6800 samples")).wait_for()
        body = page.inner_text("body")
        assert "ignored column(s) alpha [<iframe srcdoc=" in body  # the header, shown as text
        click_tab(page, "Drive log")
        page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && "
                               "e.layout.meta && e.layout.meta.id === 'log-overlay' && "
                               "e.layout.title.text.includes('&lt;img'))")
        _assert_inert(page)

        text = (PRESET_DIR / "example_log_drive.yaml").read_text(encoding="utf-8")
        text = re.sub(r"(?m)^name: .*$", f"name: '{SVG} {MARKUP}'", text)
        text = re.sub(r"(?m)^source: .*$", f"source: '{IFRAME}'", text)
        with page.expect_file_chooser() as chooser:
            page.get_by_role("button", name="Import preset (YAML/JSON)").click()
        chooser.value.set_files(files=[{"name": f"p{SVG}.yaml", "mimeType": "text/yaml",
                                        "buffer": text.encode()}])
        page.get_by_text(re.compile(r"Preset: p<svg onload=window\.__pwn=3>\.yaml")).wait_for()
        _assert_inert(page)
    finally:
        context.close()
