"""The K sweep: a grid of runs animated by the figure's own slider, in the browser, with no server message."""

from __future__ import annotations

from tests.browser.conftest import click_tab, figure, open_page

#: Frames the page script handed to Plotly.animate, and what the figure shows now (verdict, trajectory).
STATE_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout && e.layout.meta
                                                                      && e.layout.meta.id === 'k_sweep');
  if (!el || !el._fullData) return null;
  const v = el._fullData.find(t => t.name === 'verdict');
  const tr = el._fullData.find(t => t.name === 'FDSMC trajectory');
  return {frames: window.__appKSweepFrames, verdict: v.text[0], n: tr.x.length,
          y0: Array.from(tr.y).reduce((a, b) => a + b, 0),
          active: el._fullLayout.sliders[0].active, steps: el._fullLayout.sliders[0].steps.length};
}"""
#: Counts websocket frames the server sends from now on.
WS_COUNT_JS = """() => { window.__wsIn = 0; }"""
WS_HOOK = """(() => { const Orig = window.WebSocket;
  window.WebSocket = function(...a) { const ws = new Orig(...a);
    ws.addEventListener('message', () => { window.__wsIn = (window.__wsIn || 0) + 1; }); return ws; };
  window.WebSocket.prototype = Orig.prototype; Object.assign(window.WebSocket, Orig); })();"""


def test_dragging_the_sweep_slider_redraws_every_step_from_frames_without_the_server(browser, ui_server):
    context, page = open_page(browser, ui_server, viewport={"width": 1280, "height": 720}, init_script=WS_HOOK)
    try:
        click_tab(page, "K sweep")
        page.wait_for_function(f"() => ({STATE_JS})() !== null")
        start = page.evaluate(STATE_JS)
        assert start["steps"] >= 25 and "CHATTER" in start["verdict"]  # the paper's K = 1000 chatters
        rail = page.locator(".js-plotly-plot .slider-rail-rect").first
        box = rail.bounding_box()
        page.evaluate(WS_COUNT_JS)
        seen = []
        page.mouse.move(box["x"] + box["width"] - 2, box["y"] + box["height"] / 2)
        page.mouse.down()
        for k in range(41):
            page.mouse.move(box["x"] + box["width"] * (1 - k / 40.0), box["y"] + box["height"] / 2)
            page.wait_for_timeout(30)
            seen.append(page.evaluate(STATE_JS))
        page.mouse.up()
        verdicts = {s["verdict"] for s in seen}
        assert any("CHATTER" in v for v in verdicts) and any("sliding, no chatter" in v for v in verdicts)
        assert len({s["active"] for s in seen}) >= 20 and seen[-1]["active"] == 0
        assert seen[-1]["frames"] >= 20
        assert len({round(s["y0"], 1) for s in seen}) >= 15  # the trajectory itself changes
        assert page.evaluate("() => window.__wsIn") == 0  # no server message while dragging
        assert figure(page, "k_sweep")["meta"]["K"][0] == 0.01
    finally:
        context.close()

