"""Sensors in the simulated drive: quantized encoder, noisy quantized currents, the closed-form noise gain.

The standstill ripple the simulation shows (with the sensors in the loop, the physics exact) is
predicted by the discrete Lyapunov equation of :func:`control.fdsmc.noise.noise_gain` within 20 %
where the loop is linear (no chatter), and scales with the encoder's count.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.noise import noise_gain
from pmsm_commissioning.control.fdsmc.params import Sensors
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc.design import design_drive, encoder_needed, predicted_noise
from pmsm_commissioning.sim.fdsmc.engine import simulate

IDEAL = ["sensors.encoder_cpr=0", "sensors.i_noise=0", "sensors.i_adc_bits=0"]
#: The Siemens drive's loops at the torque limit (T_so = 1 ms, K recommended): a fixed case for the noise gain,
#: with the paper's FDC (no q-axis voltage-mismatch estimate), which the closed form models.
SIEMENS_LOOPS = ["controller.T_so_ms=1", "controller.T_salpha_ms=3", "controller.K=0.043075511186974044",
                 "controller.T_c=T_a", "controller.alpha_max_rule=torque_limit", "controller.T_dv=0"]


def test_encoder_reads_whole_counts_down_and_the_adc_rounds_and_clips():
    step = 2 * math.pi / 8192
    assert sensors.encoder_angle(0.0, step) == 0.0
    assert sensors.encoder_angle(1.5 * step, step) == step
    assert sensors.encoder_angle(-0.5 * step, step) == -step  # floor, as a counter reads
    assert sensors.encoder_angle(0.123, 0.0) == 0.123
    assert sensors.adc_current(1.26, 0.0, 0.0, 0.5, 10.0) == 1.5
    assert sensors.adc_current(30.0, 0.0, 0.0, 0.5, 10.0) == 10.0
    assert sensors.adc_current(1.0, 2.0, 0.1, 0.0, 0.0) == pytest.approx(1.2)


def test_noise_is_seeded_and_reproducible():
    a = sensors.noise_table(Sensors(i_noise=0.1, seed=7))
    b = sensors.noise_table(Sensors(i_noise=0.1, seed=7))
    c = sensors.noise_table(Sensors(i_noise=0.1, seed=8))
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert abs(float(np.std(a)) - 1.0) < 0.01
    p = load_preset("odrive_d5065_belt")
    assert simulate(p).metrics == simulate(p).metrics


def test_an_adc_needs_its_full_scale_and_sensors_need_a_sample_rate():
    with pytest.raises(ParameterError, match=r"sensors.i_adc_range = 0.0 A .*allowed > 0 A"):
        Sensors(i_adc_bits=12)
    with pytest.raises(ParameterError, match="continuous"):
        load_preset("siemens_1ft7044_ak7", ["controller.f_s=continuous"])


@pytest.mark.parametrize(("overrides", "what"), [
    (["sensors.encoder_cpr=131072"], "17-bit encoder"),
    (["sensors.encoder_cpr=1048576"], "20-bit encoder"),
    (["sensors.i_noise=0.1"], "0.1 A current noise"),
    (["sensors.i_noise=0.5", "sensors.encoder_cpr=131072"], "both"),
])
def test_standstill_ripple_matches_the_closed_form_noise_gain(overrides, what):
    p = load_preset("siemens_1ft7044_ak7", IDEAL + SIEMENS_LOOPS + overrides)
    d = derive(p)
    pred = predicted_noise(p, d)
    m = simulate(p, "fdsmc", d).metrics
    assert not m.chatter
    assert m.hold_i_q_rms_A == pytest.approx(pred.i_q_rms, rel=0.2), what


def test_quantization_ripple_scales_with_the_count_and_sets_the_encoder_needed():
    p = load_preset("siemens_1ft7044_ak7", IDEAL + SIEMENS_LOOPS + ["sensors.i_noise=0.05"])
    d = derive(p)
    # white quantization error (Δ²/12): the ripple is linear in the count
    g17, g20 = (noise_gain(d.loop, "slope", p.controller.K, 2 * math.pi / 2**b, 0.0, coloured=False) for b in (17, 20))
    assert g17.i_q_rms == pytest.approx(8 * g20.i_q_rms, rel=1e-9)
    assert g17.i_q_current_rms == 0.0 and g17.i_q_quant_rms == g17.i_q_rms
    crit = 0.1
    need = encoder_needed(p, d, crit)
    assert need is not None and need & (need - 1) == 0  # a power of two
    assert predicted_noise(p, d, need).i_q_rms <= crit < predicted_noise(p, d, need // 2).i_q_rms
    # the current noise alone above the criterion: no encoder helps
    assert encoder_needed(p, d, 0.5 * predicted_noise(p, d, 0).i_q_rms) is None


def test_the_design_slows_the_observer_for_a_coarse_encoder_and_verifies_it_with_the_sensors():
    # 8192 counts on the D5065: at T_so = 1 ms the predicted ripple is above the 2 A criterion;
    # the design lengthens T_so/T_sα until it is not, and the simulation with the encoder agrees.
    # (the closed form models the paper's FDC: without the q-axis voltage-mismatch estimate, T_dv = 0)
    asked = load_preset("odrive_d5065_belt", ["controller.T_so_ms=1", "controller.T_salpha_ms=3", "controller.T_dv=0"])
    d = derive(asked)
    assert predicted_noise(asked, d).i_q_rms > 2.0
    dd = design_drive(asked)
    m = dd.comparison.fdsmc.metrics
    assert dd.clean and dd.params.controller.T_so > asked.controller.T_so
    assert m.hold_i_q_rms_A <= 2.0 and m.i_peak_A <= 40.0 + 3 * asked.sensors.reading_noise
    assert m.hold_i_q_rms_A == pytest.approx(dd.noise.i_q_rms, rel=0.2)
