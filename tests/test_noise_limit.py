"""The sensors' noise limit on K: where the encoder's counts and the current noise alone make α_dem chatter.

With a coarse encoder the paper's sampled loop is stable well above the recommended K, yet the
quantization error, through the observer (eq. (15) in [1], corrected) and the boundary-layer law
(eq. (46)), swings α_dem by more than the chatter criterion allows. The recommended K must be the
one the sensors allow (``control.fdsmc.noise.noise_gain_limit``).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.loop_analysis import CHATTER_PTP_FRACTION, slope_damping
from pmsm_commissioning.control.fdsmc.noise import PTP_PER_RMS, noise_gain, noise_gain_limit
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.criteria import window_below_count
from pmsm_commissioning.sim.fdsmc.design import design_drive
from pmsm_commissioning.sim.fdsmc.engine import compare, simulate
from pmsm_commissioning.sim.fdsmc.grid import with_field
from pmsm_commissioning.sim.fdsmc.verdicts import criteria_warnings, run_warnings

#: A Σ-7 servo with a catalogue 8192-count encoder instead of its 24-bit one; an in-position
#: window of a few counts.
COARSE = ["sensors.encoder_cpr=8192", "limits.in_position_rad=0.005"]


def _swing(p: DriveParams, K: float) -> float:
    """Predicted swing of α_dem [fraction of α_max] at K (white quantization error, as the limit's search)."""
    d, se = derive(with_field(p, "controller.K", K)), p.sensors
    rms = noise_gain(d.loop, "slope", K, se.encoder_step, se.reading_noise, p.controller.T_dv,
                     coloured=False).alpha_dem_rms
    return PTP_PER_RMS * rms / d.alpha.alpha_max


def test_ideal_sensors_leave_the_recommendation_at_half_the_stability_limit():
    for p in (load_preset("paper_12kw_pmsm"),
              load_preset("yaskawa_sgm7j_04a", ["sensors.encoder_cpr=0", "sensors.i_noise=0", "sensors.i_adc_bits=0"])):
        g = derive(p).gain
        assert g.K_noise == math.inf and not g.noise_limited
        assert g.K_recommended == g.K_limit / g.margin


def test_K_noise_is_where_the_predicted_swing_reaches_the_chatter_criterion():
    p = load_preset("yaskawa_sgm7j_04a", COARSE)
    g = derive(p).gain
    assert g.noise_limited and 0.0 < g.K_noise < g.K_limit / 5.0
    assert _swing(p, g.K_noise) >= CHATTER_PTP_FRACTION > _swing(p, g.K_noise / 1.006)  # bisection to 0.5 %
    # the recommendation keeps the gain margin on the swing: half the criterion
    assert _swing(p, g.K_recommended) == pytest.approx(CHATTER_PTP_FRACTION / g.margin, rel=0.01)
    assert g.K_noise_binding == g.K_noise
    # a 24-bit encoder: the noise never binds below K_limit/2, the recommendation is the loop's; its
    # swing grows steeply only next to K_limit (poor damping), which is not a noise limit to show;
    # with the shipped q-axis voltage-mismatch estimate (T_dv) it stays below the criterion up to K_limit
    fine = derive(load_preset("yaskawa_sgm7j_04a")).gain
    assert not fine.noise_limited and fine.K_recommended == fine.K_limit / fine.margin
    assert fine.K_noise > 0.9 * fine.K_limit and fine.K_noise_binding == math.inf
    paper_fdc = derive(load_preset("yaskawa_sgm7j_04a", ["controller.T_dv=0"])).gain
    assert 0.9 * paper_fdc.K_limit < paper_fdc.K_noise < paper_fdc.K_limit


def test_T_c_min_damps_the_recommended_K_critically_where_the_noise_sets_it():
    """ζ = √(α_max·K·T_c)/2 = 1 at T_c = T_c_min with the K the page recommends (the advice is one
    setting, not two); with ideal sensors it is the cruise segment's K_limit/margin.
    """
    coarse = derive(load_preset("yaskawa_sgm7j_04a", COARSE))
    ideal = derive(load_preset("paper_12kw_pmsm"))
    for d, K in ((coarse, coarse.gain.K_recommended), (ideal, ideal.gain.K_limit_cruise / ideal.gain.margin)):
        g = d.gain
        assert g.K_unit_damping == K
        assert slope_damping(d.alpha.alpha_max, K, g.T_c_min) == pytest.approx(1.0, rel=1e-12)
    assert coarse.gain.noise_limited and not ideal.gain.noise_limited


def test_the_recommended_K_with_a_coarse_encoder_does_not_chatter_where_half_K_limit_did():
    p = load_preset("yaskawa_sgm7j_04a", COARSE)
    d = derive(p)
    g = d.gain
    old = simulate(with_field(p, "controller.K", g.K_limit / g.margin), "fdsmc").metrics  # the loop-only recommendation
    assert old.chatter and old.chatter_frequency_Hz > 500.0
    rec = simulate(with_field(p, "controller.K", g.K_recommended), "fdsmc").metrics
    assert rec.stable and not rec.chatter
    above = with_field(p, "controller.K", 1.5 * g.K_noise)
    assert simulate(above, "fdsmc").metrics.chatter  # above the noise limit it does
    # the prediction alone warns of nothing (it is conservative); the run's chatter warning says why
    assert not [x for x in d.warnings if "K_noise" in x]
    half_limit = with_field(p, "controller.K", g.K_limit / g.margin)
    hint = [x for x in run_warnings(compare(half_limit, ("fdsmc",))) if "Chatter" in x]
    assert hint and f"noise limit K_noise = {g.K_noise:.4g}" in hint[0] and f"{g.K_recommended:.4g}" in hint[0]


@pytest.mark.parametrize(("name", "overrides"), [("yaskawa_sgm7j_04a", COARSE), ("odrive_d5065_belt", [])])
def test_the_predicted_rms_of_alpha_dem_bounds_the_simulated_swing(name, overrides):
    # below the limit the run does not chatter; its high-passed α_dem spans between a uniform
    # distribution's √12 rms (quantization passed nearly unfiltered) and PTP_PER_RMS·rms (Gaussian)
    p = load_preset(name, overrides)
    g = derive(p).gain
    K = 0.8 * g.K_noise
    q = with_field(p, "controller.K", K)
    d, se = derive(q), q.sensors
    rms = noise_gain(d.loop, "slope", K, se.encoder_step, se.reading_noise, q.controller.T_dv,
                     coloured=False).alpha_dem_rms
    m = simulate(q, "fdsmc", d).metrics
    assert not m.chatter
    assert 0.9 * math.sqrt(12.0) * rms <= m.chatter_alpha_ptp_rad_s2 <= 1.1 * PTP_PER_RMS * rms


def test_a_continuous_controller_or_ideal_sensors_have_no_noise_limit():
    p = load_preset("yaskawa_sgm7j_04a", COARSE)
    loop = derive(p).loop
    assert noise_gain_limit(dataclasses.replace(loop, f_s=None), 1e-3, 0.1, 0.2, 1.0) == math.inf
    assert noise_gain_limit(loop, 0.0, 0.0, 0.2, 1.0) == math.inf
    assert noise_gain_limit(loop, 1e-3, 0.1, 0.2, 0.0) == math.inf  # no stable K to search
    # a nanoampere of current noise swings α_dem only where the loop itself goes unstable: no noise limit
    faint = derive(load_preset("yaskawa_sgm7j_04a", ["sensors.encoder_cpr=0", "sensors.i_noise=1e-9",
                                                     "sensors.i_adc_bits=0"])).gain
    assert faint.K_noise == math.inf and faint.K_recommended == faint.K_limit / faint.margin


def test_an_in_position_window_narrower_than_one_count_is_refused_with_its_remedy():
    # the Σ-7 preset's ±1 µm window (6.28e-4 rad) with an 8192-count encoder (7.67e-4 rad a count)
    p = load_preset("yaskawa_sgm7j_04a", ["sensors.encoder_cpr=8192"])
    msg = window_below_count(p)
    assert msg is not None and "limits.in_position = 0.0006283 rad" in msg
    assert "0.001534 rad (two counts)" in msg and "≥ 32768 counts/rev" in msg  # 4π/6.283e-4 = 2·10⁴ → 2¹⁵
    dd = design_drive(p)
    assert dd.comparison is None and not dd.clean  # said at once, not after every slowdown
    assert dd.params == p  # nothing designed: the inputs stay as they are
    assert [c.text for c in dd.limiting if c.violated] == [msg]
    run = simulate(p, "fdsmc")
    assert msg in criteria_warnings(run, derive(p))
    # two counts inside the window (the default ±10 counts, or the 24-bit encoder): nothing to say
    assert window_below_count(load_preset("yaskawa_sgm7j_04a", COARSE)) is None
    assert window_below_count(load_preset("yaskawa_sgm7j_04a")) is None
    assert window_below_count(load_preset("yaskawa_sgm7j_04a", ["sensors.encoder_cpr=8192",
                                                                "limits.in_position_rad=0"])) is None
