"""The page in a real Chromium against hostile input: a foreign web page cannot open the tool's
websocket, and markup in user text (file names, preset names) is shown as text.
"""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator

import pytest
import viser

from app.io.presets import PRESET_DIR, loads_preset
from tests.browser.conftest import click_tab

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
