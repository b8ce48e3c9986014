"""The live page: the replay is animated by the browser, with no server traffic per frame."""

from __future__ import annotations

import numpy as np

from app.figures.replay import SPEEDS

MARKER_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const t = el._fullData.find(t => t.name === 'FDSMC now');
  return [Number(t.x[0]), Number(t.y[0]), (t.text || [''])[0]];
}"""
#: Counts the animation frames in which the drawn FDSMC marker (its SVG transform) moved: the key
#: frames and Plotly's glides between them.
COUNT_FRAMES_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const g = () => [...el.querySelectorAll('g.trace.scatter')]
    .find(g => g.__data__[0].trace.name === 'FDSMC now');
  const pos = () => { const t = g(); const p = t && t.querySelector('path.point');
                      return p && p.getAttribute('transform'); };
  window.__frames = 0; let last = pos();
  const f = () => { const p = pos(); if (p !== last) { window.__frames += 1; last = p; } requestAnimationFrame(f); };
  requestAnimationFrame(f);
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
    page.locator(".updatemenu-button", has_text=f"▶ {list(SPEEDS)[1]}").click()
    # the marker starts at t = 0 (θ_re = −θ_dem, at rest) and runs to the end of the trajectory
    page.wait_for_function(f"() => window.__frames >= 30 && ({MARKER_JS})()[2] === 't = {t_end:.3f} s'",
                           timeout=30_000 + 8000 * t_end)
    end = page.evaluate(MARKER_JS)
    frames = page.evaluate("() => window.__frames")
    assert frames >= 30
    assert np.isclose(end[0], start[0], rtol=1e-3, atol=1e-6)  # back at the end of the trajectory
    # the server sent (nearly) nothing meanwhile: < 1 kB per animated frame
    assert sum(received[n0:]) < 1000 * frames


BAND_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  return el.data[0].name;
}"""
FDSMC_Y_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  return Array.from(el._fullData.find(t => t.name === 'FDSMC trajectory').y);
}"""


def _slider(page, label: str):
    return page.locator(f'xpath=//label[normalize-space(.)="{label}"]/ancestor::*[.//*[@role="slider"]][1]'
                        '//*[@role="slider"]').first


def test_dragging_the_K_slider_resimulates_with_the_latest_value(page):
    """Key presses on the K slider (each a move, faster than a run): the last value is what runs,
    it is the value the K field shows, and the trajectory changes (the band ±1/K of eq. (45) too).
    """
    from tests.browser.conftest import field

    before_band, before_y = page.evaluate(BAND_JS), page.evaluate(FDSMC_Y_JS)
    k_field = field(page, "K boundary-layer gain [s/rad]")
    k0 = float(k_field.input_value())
    thumb = _slider(page, "K [s/rad]")
    thumb.focus()
    for _ in range(4):
        thumb.press("ArrowLeft")  # smaller K: wider boundary layer
    k_shown = float(thumb.get_attribute("aria-valuenow"))
    assert k_shown < k0
    # the field holds the slider's value, and the phase plane is redrawn for exactly that K
    page.wait_for_function(f"(k) => Math.abs(parseFloat(({BAND_JS})().split('±')[2]) * k - 1) < 6e-3",
                           arg=k_shown)
    assert abs(float(k_field.input_value()) - k_shown) <= 1e-9 * k_shown
    assert page.evaluate(BAND_JS) != before_band
    after_y = page.evaluate(FDSMC_Y_JS)
    assert len(after_y) != len(before_y) or max(abs(a - b) for a, b in zip(after_y, before_y, strict=True)) > 1e-3
    # once the drag has stopped the overview gets its replay back (play buttons and scrub slider)
    page.wait_for_function("() => { const el = [...document.querySelectorAll('.js-plotly-plot')]"
                           ".find(e => e.layout.meta.id === 'phase_plane');"
                           " return (el.layout.updatemenus || []).length > 0"
                           " && (el.layout.sliders || []).length > 0; }")
    assert abs(float(page.evaluate(BAND_JS).split("±")[2].split()[0]) * k_shown - 1) < 6e-3
