"""The K demo of a lecture: the logarithmic K slider mirrors the K field, the verdict on the plot
flips at K_limit, and the slider stays where it is while the warnings change under it.
"""

from __future__ import annotations

import math

from playwright.sync_api import expect

from pmsm_commissioning.app.ui.number_fields import shown_text
from tests.browser.conftest import field, set_number
from tests.browser.test_design import choose

K_FIELD = "K boundary-layer gain [s/rad]"
SLIDER_LABEL = "K [s/rad] (log)"
VERDICT_JS = """() => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const a = (el.layout.annotations || []).find(a => a.name === 'verdict');
  return a ? a.text : null;
}"""
#: Records the slider's box (x, y, width, height) in every animation frame from now on.
WATCH_BOX_JS = """(thumb) => {
  const root = thumb.closest('.mantine-Slider-root');
  window.__boxes = new Set();
  const f = () => { const r = root.getBoundingClientRect();
                    window.__boxes.add([r.x, r.y, r.width, r.height].join()); requestAnimationFrame(f); };
  requestAnimationFrame(f);
}"""


def _thumb(page):
    return page.locator(f'xpath=//label[normalize-space(.)="{SLIDER_LABEL}"]/ancestor::*[.//*[@role="slider"]][1]'
                        '//*[@role="slider"]').first


def _wait_position(page, K: float) -> None:
    """Wait until the slider's thumb stands at log₁₀ K (within half a step)."""
    page.wait_for_function("([t, p]) => Math.abs(parseFloat(t.getAttribute('aria-valuenow')) - p) < 0.006",
                           arg=[_thumb(page).element_handle(), math.log10(K)])


def _wait_verdict(page, words: str) -> str:
    page.wait_for_function(f"(w) => {{ const v = ({VERDICT_JS})(); return v !== null && v.includes(w); }}",
                           arg=words)
    return page.evaluate(VERDICT_JS)


def test_k_slider_mirrors_the_field_and_the_verdict_flips_at_K_limit(page, ui_server):
    gain = ui_server.config.initial().derived.gain
    # the paper preset: K = 1000 chatters, the slider stands at 1000 with K_limit marked
    assert "CHATTER" in _wait_verdict(page, "CHATTER")
    _wait_position(page, 1000.0)
    labels = page.locator(".mantine-Slider-markLabel").all_inner_texts()
    assert "lim" in labels and "rec" in labels
    # typed K + Simulate: the slider follows
    set_number(page, K_FIELD, "2")
    page.get_by_role("button", name="Simulate").click()
    _wait_position(page, 2.0)
    # "Use recommended K": the slider follows, and the run does not chatter
    page.get_by_role("button", name="Use recommended K").click()
    _wait_position(page, gain.K_recommended)
    assert field(page, K_FIELD).input_value() == shown_text(gain.K_recommended)  # rounded; the run uses it exactly
    verdict = _wait_verdict(page, "no chatter")
    assert "CHATTER" not in verdict and f"K_limit = {gain.K_limit:.3g}" in verdict


def test_dragging_K_across_K_limit_keeps_the_slider_in_place(page, ui_server):
    gain = ui_server.config.initial().derived.gain
    page.get_by_role("button", name="Use recommended K").click()
    _wait_verdict(page, "no chatter")
    _wait_position(page, gain.K_recommended)
    thumb = _thumb(page)
    thumb.focus()  # scrolls the control panel to the slider (the remedy button sits lower)
    page.evaluate(WATCH_BOX_JS, thumb.element_handle())
    thumb.press("End")  # K = 5000 s/rad: above K_limit, the chatter warning and its remedy appear
    assert "CHATTER" in _wait_verdict(page, "CHATTER")
    assert float(field(page, K_FIELD).input_value()) == 5000.0
    page.get_by_role("button", name="Use recommended K").wait_for()  # the warnings did change
    page.locator('[data-role="k-readout"]', has_text="K = 5000 s/rad").wait_for()
    assert page.evaluate("() => window.__boxes.size") == 1  # the slider never moved
    page.get_by_text("Ready — ").wait_for()  # the drag's settling redraw is done before the page closes


def test_k_slider_mirrors_a_preset_chosen_from_the_list(page):
    choose(page, "Preset", "odrive_d5065_belt")
    K = 0.024679024621241528  # presets/odrive_d5065_belt.yaml
    page.wait_for_function("(k) => Math.abs(parseFloat(document.querySelector"
                           "('[data-role=\"k-readout\"]').innerText.split('K = ')[1]) - k) < 1e-4", arg=K)
    _wait_position(page, K)
    # its designed K sits between the noise-capped recommendation and the noise limit, verified clean:
    # no remedy is offered
    _wait_verdict(page, "no chatter")
    expect(page.get_by_role("button", name="Use recommended K")).to_be_hidden()


def test_recommended_K_with_a_coarse_encoder_is_the_one_the_sensors_allow(page):
    # a Σ-7 servo with a catalogue 8192-count encoder: K_limit/2 chatters on the counts' noise; the
    # recommended K is capped at the sensors' noise limit, marked "noise" on the track, and is clean
    choose(page, "Preset", "yaskawa_sgm7j_04a")
    _wait_verdict(page, "no chatter")
    set_number(page, "Encoder counts per rev (0 = ideal) [counts/rev]", "8192")
    page.get_by_role("button", name="Simulate").click()
    verdict = _wait_verdict(page, "CHATTER")
    assert "K_noise" in verdict and "(sensors)" in verdict
    # the sliders follow the run's derived values after its figures: waited for, not read at once
    page.wait_for_function("() => [...document.querySelectorAll('.mantine-Slider-markLabel')]"
                           ".some(l => l.textContent.trim() === 'noise')")
    page.get_by_text("sensors' noise limit K_noise").first.wait_for()  # the warning says why
    page.get_by_role("button", name="Use recommended K").click()
    verdict = _wait_verdict(page, "no chatter")
    assert "K ≤ K_noise" in verdict


#: The K slider's mark labels as drawn: [text, left, right] [px], left to right.
K_LABELS_JS = """() => {
  const label = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === '""" + SLIDER_LABEL + """');
  let box = label; while (box && !box.querySelector('.mantine-Slider-root')) box = box.parentElement;
  return [...box.querySelectorAll('.mantine-Slider-markLabel')].map(l => { const r = l.getBoundingClientRect();
    return [l.textContent, r.left, r.right]; }).sort((a, b) => a[1] - b[1]);
}"""


#: True once the K slider's mark labels, left to right, do not overlap.
APART_JS = f"() => {{ const l = ({K_LABELS_JS})(); return l.every((a, i) => i === 0 || l[i - 1][2] <= a[1]); }}"


def test_the_K_tracks_labels_never_overlap(page):
    # K_recommended = K_limit/2 is 0.3 decade from it on a 5.7-decade track: "rec" and "lim" would
    # overlap by a few pixels on a 1280×720 page; with a coarse encoder "noise" joins them
    page.set_viewport_size({"width": 1280, "height": 720})
    page.wait_for_function(f"() => ({K_LABELS_JS})().map(l => l[0]).includes('rec')")
    page.wait_for_function(APART_JS)
    choose(page, "Preset", "yaskawa_sgm7j_04a")
    _wait_verdict(page, "no chatter")
    set_number(page, "Encoder counts per rev (0 = ideal) [counts/rev]", "8192")
    page.get_by_role("button", name="Simulate").click()
    _wait_verdict(page, "CHATTER")
    page.wait_for_function(f"() => ({K_LABELS_JS})().map(l => l[0]).includes('noise')")
    page.wait_for_function(APART_JS)
    assert {"rec", "noise", "lim"} <= {t for t, _, _ in page.evaluate(K_LABELS_JS)}
