"""The page's colours stay apart for colour-blind viewers; numbers are rounded to their meaning; exports drop the UI.

Colour-vision deficiency is simulated with the severity-1.0 protanomaly and deuteranomaly matrices of
Machado, Oliveira & Fernandes (2009), applied to linear sRGB; differences are CIEDE2000
(Sharma, Wu & Dalal 2005) in CIELAB (D65). A ΔE00 of 10 is a clearly visible difference for thin
lines (≈ 2.3 is a just-noticeable one on large patches).
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from pmsm_commissioning.app.figures.style import (
    BLDC_COLOURS,
    BLDC_DASHES,
    FIGURE_GROUPS,
    PHASE_COLOURS,
    PHASE_DASHES,
    POSITION_COLOURS,
    POSITION_DASHES,
    fmt,
    round_to_meaning,
)

PROTAN = np.array([[0.152286, 1.052583, -0.204868], [0.114503, 0.786281, 0.099216], [-0.003882, -0.048116, 1.051998]])
DEUTAN = np.array([[0.367322, 0.860646, -0.227968], [0.280085, 0.672501, 0.047413], [-0.011820, 0.042940, 0.968881]])
VISION = {"normal": np.eye(3), "deutan": DEUTAN, "protan": PROTAN}
SRGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
WHITE_D65 = np.array([0.95047, 1.0, 1.08883])


def linear_rgb(hex_colour: str) -> np.ndarray:
    c = np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)]) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def lab(rgb_linear: np.ndarray) -> np.ndarray:
    xyz = SRGB_TO_XYZ @ np.clip(rgb_linear, 0.0, 1.0) / WHITE_D65
    d = 6.0 / 29.0
    f = np.where(xyz > d**3, np.cbrt(xyz), xyz / (3 * d * d) + 4.0 / 29.0)
    return np.array([116.0 * f[1] - 16.0, 500.0 * (f[0] - f[1]), 200.0 * (f[1] - f[2])])


def _mean_hue(h1: float, h2: float, c_product: float) -> float:
    if c_product == 0:
        return h1 + h2
    if abs(h1 - h2) <= 180:
        return (h1 + h2) / 2
    return (h1 + h2 + 360) / 2 if h1 + h2 < 360 else (h1 + h2 - 360) / 2


def ciede2000(lab1: np.ndarray, lab2: np.ndarray) -> float:
    """CIEDE2000 colour difference (k_L = k_C = k_H = 1)."""
    (L1, a1, b1), (L2, a2, b2) = lab1, lab2
    c_bar = (np.hypot(a1, b1) + np.hypot(a2, b2)) / 2
    g = 0.5 * (1 - np.sqrt(c_bar**7 / (c_bar**7 + 25.0**7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    h1, h2 = np.degrees(np.arctan2(b1, a1p)) % 360, np.degrees(np.arctan2(b2, a2p)) % 360
    dh = 0.0 if c1p * c2p == 0 else (h2 - h1 + 180) % 360 - 180
    d_big_h = 2 * np.sqrt(c1p * c2p) * np.sin(np.radians(dh / 2))
    l_bar, cp_bar, h_bar = (L1 + L2) / 2, (c1p + c2p) / 2, _mean_hue(h1, h2, c1p * c2p)
    t = (1 - 0.17 * np.cos(np.radians(h_bar - 30)) + 0.24 * np.cos(np.radians(2 * h_bar))
         + 0.32 * np.cos(np.radians(3 * h_bar + 6)) - 0.20 * np.cos(np.radians(4 * h_bar - 63)))
    s_l = 1 + 0.015 * (l_bar - 50) ** 2 / np.sqrt(20 + (l_bar - 50) ** 2)
    s_c, s_h = 1 + 0.045 * cp_bar, 1 + 0.015 * cp_bar * t
    r_t = (-np.sin(np.radians(60 * np.exp(-(((h_bar - 275) / 25) ** 2))))
           * 2 * np.sqrt(cp_bar**7 / (cp_bar**7 + 25.0**7)))
    dl, dc, dh_ = (L2 - L1) / s_l, (c2p - c1p) / s_c, d_big_h / s_h
    return float(np.sqrt(dl**2 + dc**2 + dh_**2 + r_t * dc * dh_))


def delta_e(c1: str, c2: str, vision: str) -> float:
    m = VISION[vision]
    return ciede2000(lab(m @ linear_rgb(c1)), lab(m @ linear_rgb(c2)))


def test_ciede2000_matches_sharma_reference_pairs():
    """Pairs 1 and 7 of Sharma, Wu & Dalal's test data: ΔE00 = 2.0425 and 2.3669."""
    pair_1 = np.array([50.0, 2.6772, -79.7751]), np.array([50.0, 0.0, -82.7485])
    assert ciede2000(*pair_1) == pytest.approx(2.0425, abs=1e-4)
    assert ciede2000(np.array([50.0, 0.0, 0.0]), np.array([50.0, -1.0, 2.0])) == pytest.approx(2.3669, abs=1e-4)


def test_old_palette_failed_for_deutan_viewers():
    """The check has teeth: the former phase colours a/b (#d62728 vs #2ca02c) fall below ΔE 10 for deutans."""
    assert delta_e("#d62728", "#2ca02c", "deutan") < 10 < delta_e("#d62728", "#2ca02c", "normal")


@pytest.mark.parametrize("vision", sorted(VISION))
@pytest.mark.parametrize("group", sorted(FIGURE_GROUPS))
def test_colours_drawn_together_differ_for_deutan_and_protan(group, vision):
    """Every pair of colours of one figure: CIEDE2000 ΔE ≥ 10 under normal, deutan and protan vision."""
    worst = min((delta_e(a, b, vision), a, b) for a, b in itertools.combinations(FIGURE_GROUPS[group], 2))
    assert worst[0] >= 10.0, f"{group}, {vision}: {worst[1]} vs {worst[2]} ΔE00 = {worst[0]:.1f}"


@pytest.mark.parametrize(("a", "b"), [("smc_plain", "pi_sinusoidal"), ("smc_integral", "six_step")])
def test_named_bldc_pairs_differ(a, b):
    assert min(delta_e(BLDC_COLOURS[a], BLDC_COLOURS[b], v) for v in VISION) >= 10.0
    assert BLDC_DASHES[a] != BLDC_DASHES[b]  # and a second cue


def test_every_controller_and_phase_has_its_own_dash():
    for dashes in (POSITION_DASHES, BLDC_DASHES):
        assert len(set(dashes.values())) == len(dashes)
    assert len(set(PHASE_DASHES)) == len(PHASE_COLOURS) == 3
    assert set(POSITION_DASHES) == set(POSITION_COLOURS)


@pytest.mark.parametrize(("value", "unit", "text"), [
    (1432.39448783, "rpm", "1432 rpm"), (4.822855, "", "4.823"), (0.000123456, "s", "0.0001235 s"),
    (12345.6, "", "12346"), (-0.00049999, "", "-0.0005"), (2.5e-7, "s", "2.5e-07 s"), (0.0, "", "0"),
    (None, "A", "—"), (float("nan"), "", "—"), (3, "", "3"), (999.96, "", "1000"),
])
def test_fmt_rounds_to_meaning(value, unit, text):
    assert fmt(value, unit) == text


def test_round_to_meaning_keeps_significant_digits():
    assert round_to_meaning(1432.39448783) == 1432.0
    assert round_to_meaning(4.822855, 3) == 4.82
    assert round_to_meaning(-0.012345678) == -0.01235


def test_export_drops_the_replay_ui_and_sets_format_and_size():
    from pmsm_commissioning.app.figures.style import EXPORT_SCALE, EXPORT_SIZE
    from pmsm_commissioning.app.ui.figure_export import UI_KEYS, export_figure, export_js

    fig = {"data": [{"type": "scatter", "y": [1, 2]}], "layout": {
        "meta": {"id": "phase_plane"}, "height": 500, "updatemenus": [{"buttons": []}], "sliders": [{}],
        "title": {"text": "t"}}}
    for fmt_ in ("svg", "png"):
        out, options = export_figure(json.dumps(fig, separators=(",", ":")), fmt_)
        assert not set(UI_KEYS) & set(out["layout"]) and "height" not in out["layout"]
        assert out["data"] == fig["data"] and out["layout"]["title"] == {"text": "t"}
        assert options == {"format": fmt_, "width": EXPORT_SIZE[0], "height": EXPORT_SIZE[1],
                           "scale": EXPORT_SCALE if fmt_ == "png" else 1, "filename": "phase_plane"}
        assert EXPORT_SIZE[0] * options["scale"] >= (1920 if fmt_ == "png" else 1280)
        assert "updatemenus" not in export_js(out, options)
    with pytest.raises(ValueError, match="allowed svg, png"):
        export_figure(json.dumps(fig), "gif")
