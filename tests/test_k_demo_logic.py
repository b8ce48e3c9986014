"""The K demo without a browser: the verdict text, the log K slider's range, marks and readout."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from pmsm_commissioning.app.figures.fdsmc_verdict import VERDICT_FONT_PX, chatter_verdict, verdict_annotation
from pmsm_commissioning.app.figures.style import BAD_COLOUR
from pmsm_commissioning.app.ui.k_slider import (
    K_RANGE,
    OK_COLOUR,
    K_marks,
    K_of_position,
    hide_box_css,
    log_K_range,
    readout_html,
)


def _comparison(K: float, K_limit: float, chatter: bool = False, freq: float | None = None,
                stable: bool = True, ran: bool = True, K_noise: float = math.inf) -> SimpleNamespace:
    metrics = SimpleNamespace(chatter=chatter, chatter_frequency_Hz=freq, stable=stable)
    derived = SimpleNamespace(params=SimpleNamespace(controller=SimpleNamespace(K=K)),
                              gain=SimpleNamespace(K_limit=K_limit, K_noise_binding=K_noise))
    return SimpleNamespace(fdsmc=SimpleNamespace(metrics=metrics) if ran else None, derived=derived)


def test_verdict_says_chatter_with_its_frequency_and_K_against_the_limit():
    v = chatter_verdict(_comparison(1000.0, 0.6048, chatter=True, freq=270.4))
    assert v is not None and v.chatter
    assert v.text == "CHATTER 270 Hz (K ≥ K_limit = 0.605)"


def test_verdict_below_the_limit_is_sliding_without_chatter():
    v = chatter_verdict(_comparison(0.3024, 0.6048))
    assert v is not None and not v.chatter
    assert v.text == "sliding, no chatter (K < K_limit = 0.605)"


def test_verdict_comes_from_the_run_not_from_the_prediction():
    # above the predicted limit but the run is clean: the run decides, the detail says where K is
    assert chatter_verdict(_comparison(0.7, 0.6048)).text == "sliding, no chatter (K ≥ K_limit = 0.605)"
    assert chatter_verdict(_comparison(0.3, 0.6048, chatter=True)).text == "CHATTER (K < K_limit = 0.605)"
    assert chatter_verdict(_comparison(5.0, 0.0)).detail == "K = 5"  # no limit known
    unstable = chatter_verdict(_comparison(5.0, 0.6, chatter=True, stable=False))
    assert unstable.headline == "UNSTABLE" and unstable.chatter
    assert chatter_verdict(_comparison(1.0, 0.6, ran=False)) is None  # infeasible: nothing run


def test_verdict_names_the_sensors_noise_limit_where_it_is_below_K_limit():
    # a coarse encoder: the noise, not the loop's stability, sets where α_dem starts to chatter
    v = chatter_verdict(_comparison(0.0571, 0.114, chatter=True, freq=1524.0, K_noise=0.0105))
    assert v.text == "CHATTER 1524 Hz (K > K_noise = 0.0105 (sensors))"
    assert chatter_verdict(_comparison(0.005, 0.114, K_noise=0.0105)).detail == "K ≤ K_noise = 0.0105 (sensors)"
    # a noise limit above the stability limit is not the binding one
    assert chatter_verdict(_comparison(0.3, 0.6048, K_noise=0.7)).detail == "K < K_limit = 0.605"


def test_the_K_slider_marks_and_reddens_at_the_noise_limit():
    marks = dict((label, pos) for pos, label in K_marks(-3.0, 4.0, 0.114, 0.00525, 0.0105))
    assert marks["noise"] == pytest.approx(math.log10(0.0105)) and marks["lim"] == pytest.approx(math.log10(0.114))
    assert "noise" not in {label for _, label in K_marks(-3.0, 4.0, 0.114, 0.057, 0.2)}  # above K_limit: no mark
    assert BAD_COLOUR in readout_html(0.02, 0.114, 0.00525, 0.0105)  # above K_noise, below K_limit: red
    ok = readout_html(0.005, 0.114, 0.00525, 0.0105)
    assert OK_COLOUR in ok and "✓ no chatter" in ok and "noise 0.0105" in ok
    assert "✗ chatters" in readout_html(0.02, 0.114, 0.00525, 0.0105)


def test_verdict_annotation_is_large_named_and_escaped():
    a = verdict_annotation(chatter_verdict(_comparison(0.3, 0.6)), 0.55)
    assert a["name"] == "verdict" and a["font"]["size"] == VERDICT_FONT_PX >= 16
    assert "&lt; K_limit" in a["text"] and "< K" not in a["text"]  # a raw "<" opens a tag in Plotly
    assert a["font"]["color"] != verdict_annotation(chatter_verdict(_comparison(1e3, 0.6, True)), 0.55)["font"]["color"]


def test_log_range_holds_the_default_span_and_every_gain_in_whole_decades():
    lo, hi = log_K_range(1000.0, 0.605, 0.302)
    assert (lo, hi) == (math.log10(K_RANGE[0]), math.log10(K_RANGE[1]))
    assert log_K_range(2e5, 1e-4, None) == (-4.0, 6.0)
    assert log_K_range(1.0, math.inf, None) == (-2.0, math.log10(K_RANGE[1]))  # no finite limit: ignored


def test_marks_label_both_ends_the_recommended_K_and_the_limit():
    marks = K_marks(-2.0, 3.7, 0.605, 0.302)
    assert marks[0] == (-2.0, "0.01") and marks[1][1] == "5011.87"
    assert (pytest.approx(math.log10(0.302)), "rec") == marks[2] and marks[3][1] == "lim"
    assert [m[1] for m in K_marks(-2.0, 4.0, 0.0, None)] == ["0.01", "10000"]


def test_slider_positions_become_K_with_three_significant_digits():
    assert K_of_position(3.0) == 1000.0
    assert K_of_position(math.log10(0.30242085)) == 0.302
    assert K_of_position(-0.52) == 0.302
    # the rounding stays within half a slider step: the mirrored slider does not jump back
    for p in (-1.995, -0.215, 0.005, 2.345):
        assert abs(math.log10(K_of_position(p)) - p) < 0.005


def test_readout_says_K_in_red_at_or_above_the_limit():
    above, below = readout_html(5000.0, 0.605, 0.302), readout_html(0.302, 0.605, 0.302)
    assert "K = 5000 s/rad" in above and BAD_COLOUR in above and BAD_COLOUR not in below
    assert "lim 0.605" in below and "rec 0.302" in below
    assert 'id="abc"' in hide_box_css("abc")


def test_verdict_says_K_limit_is_the_models_when_the_plant_differs():
    c = _comparison(0.5, 0.605, chatter=True, freq=162.0)
    c.derived.params.load = SimpleNamespace(J_L=2.0e-3)
    want = "CHATTER 162 Hz (K < K_limit = 0.605, the model's (plant J_L ×3))"
    assert chatter_verdict(c, plant_J_L=6.0e-3).text == want
    assert chatter_verdict(c, plant_J_L=2.0e-3).detail == "K < K_limit = 0.605"  # the plant is the model


def test_k_grid_holds_the_marked_gains_and_spans_the_slider():
    from pmsm_commissioning.app.figures.k_sweep import N_LOG, k_grid
    grid = k_grid(-2.0, 4.0, 1000.0, 0.6048, 0.3024)
    assert grid == tuple(sorted(grid)) and grid[0] == 0.01 and grid[-1] == 1e4
    for K in (1000.0, 0.3024, 0.9 * 0.6048 * 1.1, 0.99 * 0.6048, 1.01 * 0.6048):
        if K != 0.9 * 0.6048 * 1.1:
            assert any(abs(g / K - 1.0) < 0.005 for g in grid), K
    assert N_LOG <= len(grid) <= N_LOG + 5
    assert any(g < 0.6048 for g in grid if g > 0.59) and any(0.6048 < g < 0.62 for g in grid)  # either side of lim


def test_k_sweep_frames_carry_each_runs_own_verdict():
    import json

    from pmsm_commissioning.app.figures.k_sweep import DYNAMIC, k_sweep_spec
    from pmsm_commissioning.app.figures.plain import figure_json
    from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
    from pmsm_commissioning.app.ui.k_sweep import sweep_points
    from pmsm_commissioning.sim.fdsmc.engine import compare

    params = load_preset(PAPER_PRESET)
    points = sweep_points(compare(params, ("fdsmc",)), None)
    spec, raw = k_sweep_spec(points, 1000.0, {"lim": points[0].derived.gain.K_limit})
    fig = json.loads(figure_json(spec, raw))
    steps = fig["layout"]["sliders"][0]["steps"]
    assert len(steps) == len(points) and fig["layout"]["sliders"][0]["active"] == fig["layout"]["meta"]["K"].index(1000)
    for step, c in zip(steps, points, strict=True):
        frame = step["args"][0][0]
        assert frame["traces"] == list(DYNAMIC) and step["args"][1]["frame"]["redraw"] is False
        text = frame["data"][-1]["text"][0]
        assert ("CHATTER" in text) == c.fdsmc.metrics.chatter and f"K = {c.derived.params.controller.K:.3g}" in text
    assert sum(len(s["args"][0][0]["data"][1]["x"]) for s in steps) / len(steps) <= 410  # bounded per frame
