"""The live page: the replay is animated by the browser, with no server traffic per frame."""

from __future__ import annotations

import msgspec
import numpy as np
import pytest

from pmsm_commissioning.app.figures.fdsmc_replay import SPEEDS

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


def sent_bytes(ui_server) -> list[int]:
    """Sizes [B] of the messages the server queues for the newest page from now on (msgpack).

    Counted on the server: Playwright reports the frames of a page's sockets opened after
    ``page.on("websocket")`` only, and the page's socket is open before the test starts.
    """
    sessions = ui_server.config.sessions
    connection = sessions[max(sessions)].client.gui._websock_interface  # the newest page's
    sizes: list[int] = []
    queue = connection.queue_message

    def counted(message) -> None:
        sizes.append(len(msgspec.msgpack.encode(message.as_serializable_dict())))
        queue(message)

    connection.queue_message = counted
    return sizes


def test_in_plot_replay_moves_the_marker_without_server_traffic(page, ui_server):
    received = sent_bytes(ui_server)
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
    thumb = _slider(page, "K [s/rad] (log)")
    thumb.focus()
    for _ in range(4):
        thumb.press("ArrowLeft")  # smaller K: wider boundary layer
    k_shown = float(f"{10 ** float(thumb.get_attribute('aria-valuenow')):.3g}")  # log₁₀ K, written to 3 digits
    assert k_shown < k0
    # the field holds the slider's value, and the phase plane is redrawn for exactly that K
    page.wait_for_function(f"(k) => Math.abs(parseFloat(({BAND_JS})().split('±')[2]) * k - 1) < 6e-3",
                           arg=k_shown)
    assert abs(float(k_field.input_value()) - k_shown) <= 1e-9 * k_shown
    assert page.evaluate(BAND_JS) != before_band
    after_y = page.evaluate(FDSMC_Y_JS)
    assert len(after_y) != len(before_y) or max(abs(a - b) for a, b in zip(after_y, before_y, strict=True)) > 1e-3
    # once the drag has stopped the overview gets its replay back (play buttons)
    page.wait_for_function("() => { const el = [...document.querySelectorAll('.js-plotly-plot')]"
                           ".find(e => e.layout.meta.id === 'phase_plane');"
                           " return (el.layout.updatemenus || []).length > 0; }")
    assert abs(float(page.evaluate(BAND_JS).split("±")[2].split()[0]) * k_shown - 1) < 6e-3
    # and is interactive again: the drag's static plot (no hover, zoom, mode bar) ends with the drag
    assert page.evaluate("() => { const el = [...document.querySelectorAll('.js-plotly-plot')]"
                         ".find(e => e.layout.meta.id === 'phase_plane');"
                         " return [el._context.staticPlot, !!el.querySelector('.modebar'),"
                         " !!el.querySelector('.nsewdrag')]; }") == [False, True, True]


def test_the_replay_t_slider_puts_the_markers_on_the_trajectories_at_that_time(page, ui_server):
    """Scrubbing to t: each "now" marker drawn at (θ_r(t) − θ_dem, ω_r(t)) of its run, with a few
    hundred bytes from the server per move.
    """
    comparison = ui_server.config.initial()
    th = comparison.derived.params.manoeuvre.theta_dem
    received = sent_bytes(ui_server)
    # the slider's number box (the slider itself also holds a hidden input)
    box = page.locator('xpath=//label[normalize-space(.)="Replay t [s]"]/ancestor::*[.//input][1]'
                       '//input[not(@type="hidden")]').first
    for t in (0.25, 0.6):
        n0 = len(received)
        box.fill(f"{t:g}")
        box.press("Tab")
        page.wait_for_function(f"() => ({MARKER_JS})()[2] === 't = {t:.3f} s'")
        x, y, _ = page.evaluate(MARKER_JS)
        tr = comparison.fdsmc.trace
        assert x == pytest.approx(np.interp(t, tr.t, tr.theta_r) - th, rel=1e-4, abs=1e-9)
        assert y == pytest.approx(np.interp(t, tr.t, tr.omega_r), rel=1e-4, abs=1e-6)
        assert received[n0:] and max(received[n0:]) < 1000  # small scripts and values, never a figure
