"""The live page: the replay is animated by the browser, with no server traffic per frame."""

from __future__ import annotations

import numpy as np

from app.figures_replay import SPEEDS

MARKER_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const t = el.data.find(t => t.name === 'FDSMC now');
  return [t.x[0], t.y[0], (t.text || [''])[0]];
}"""
COUNT_FRAMES_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  window.__frames = 0;
  el.on('plotly_animatingframe', () => { window.__frames += 1; });
}"""


def test_in_plot_replay_moves_the_marker_without_server_traffic(page, ui_server):
    for close in page.locator(".mantine-Notification-closeButton").all():
        close.click()  # e.g. viser's "software WebGL" notice
    received: list[int] = []
    page.on("websocket", lambda ws: ws.on("framereceived", lambda p: received.append(len(p))))
    start = page.evaluate(MARKER_JS)
    t_end = float(ui_server.config.initial().fdsmc.trace.t[-1])
    page.evaluate(COUNT_FRAMES_JS)
    n0 = len(received)
    page.locator(".updatemenu-button", has_text=f"▶ {list(SPEEDS)[0]}").click()
    # the marker starts at t = 0 (θ_re = −θ_dem, at rest) and runs to the end of the trajectory
    page.wait_for_function(f"() => window.__frames >= 30 && ({MARKER_JS})()[2] === 't = {t_end:.3f} s'")
    end = page.evaluate(MARKER_JS)
    frames = page.evaluate("() => window.__frames")
    assert frames >= 30
    assert np.isclose(end[0], start[0], rtol=1e-3, atol=1e-6)  # back at the end of the trajectory
    # the server sent (nearly) nothing meanwhile: < 1 kB per animated frame
    assert sum(received[n0:]) < 1000 * frames
