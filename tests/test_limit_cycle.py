"""The slow half of the chatter criterion (sim/fdsmc/limit_cycle.py): limit cycles the 5 ms average follows.

Closed-form signals first (a sustained 11 Hz oscillation, a ramp, a decaying ring, 270 Hz switching),
then the case that showed the gap: the Siemens 1FT7044 preset with its rotor inertia typed 10× too
small, whose FDSMC run oscillates at ≈ 17 Hz with ω_r swinging by tens of rad/s while the switching
test saw nothing.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmsm_commissioning.app.io.preset_modes import load_mode_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc.engine import simulate
from pmsm_commissioning.sim.fdsmc.limit_cycle import limit_cycle_stats
from pmsm_commissioning.sim.fdsmc.metrics import CHATTER_SMOOTHING_S, detect_chatter, moving_average
from pmsm_commissioning.sim.studies.batch import chatter_rows, chatter_stats

ALPHA_MAX = 400.0  # [rad/s²]
T = np.arange(5000) * 5e-5  # a 0.25 s window at 20 kHz [s]
WINDOW = (0.0, float(T[-1]))


def _signals() -> dict[str, np.ndarray]:
    w = 2 * np.pi * 11.0
    return {
        "11 Hz cycle": ALPHA_MAX * np.sin(w * T),
        "ramp": 3000.0 * T - 50.0,
        "decaying ring": ALPHA_MAX * np.exp(-T / 0.02) * np.sin(w * T),
        "270 Hz switching": ALPHA_MAX * np.sign(np.sin(2 * np.pi * 270.0 * T)),
    }


def test_a_sustained_11_hz_cycle_chatters_though_the_switching_test_misses_it():
    a = _signals()["11 Hz cycle"]
    n = int(round(CHATTER_SMOOTHING_S / 5e-5))
    hf_ptp = float(np.ptp(a - moving_average(a, n)))
    assert hf_ptp < 0.1 * ALPHA_MAX  # the 5 ms average follows it: half the 20 % threshold, at the edges
    v = detect_chatter(T, a, np.zeros_like(a), WINDOW, ALPHA_MAX)
    assert v.chatter and v.ptp > 1.9 * ALPHA_MAX  # the residual about its line swings the whole sine
    assert v.frequency_Hz == pytest.approx(11.0, abs=1.0 / (2 * WINDOW[1]) + 1e-9)  # changes / (2 · window)


@pytest.mark.parametrize("name", ["ramp", "decaying ring"])
def test_a_ramp_or_a_decaying_ring_does_not_chatter(name):
    a = _signals()[name]
    assert not detect_chatter(T, a, np.zeros_like(a), WINDOW, ALPHA_MAX).chatter


def test_switching_chatter_still_found_by_the_switching_test():
    a = _signals()["270 Hz switching"]
    v = detect_chatter(T, a, np.zeros_like(a), WINDOW, ALPHA_MAX)
    assert v.chatter and v.frequency_Hz == pytest.approx(270.0, rel=0.02)
    n = int(round(CHATTER_SMOOTHING_S / 5e-5))
    ptp, changes = chatter_stats(a[None, :], n, 0.025 * ALPHA_MAX)
    assert v.ptp == ptp[0] and v.sign_changes == changes[0]  # the switching test's own figures


def test_batches_give_the_verdicts_of_single_runs():
    rows = np.vstack(list(_signals().values()))
    batch = chatter_rows(T, rows, WINDOW, ALPHA_MAX)
    single = [detect_chatter(T, a, np.zeros_like(a), WINDOW, ALPHA_MAX).chatter for a in rows]
    assert batch.tolist() == single == [True, False, False, True]


def test_a_model_inertia_typed_ten_times_too_small_is_no_longer_called_clean():
    p = load_mode_preset("siemens_1ft7044_ak7", mode="position")
    assert not simulate(p, "fdsmc", derive(p)).metrics.chatter  # as shipped: clean
    q = dataclasses.replace(p, motor=dataclasses.replace(p.motor, J_r=p.motor.J_r / 10.0))
    m = simulate(q, "fdsmc", derive(q)).metrics
    assert m.chatter and 5.0 < m.chatter_frequency_Hz < 40.0
    assert m.cruise_omega_ptp_rad_s > 10.0  # ω_r itself swings by tens of rad/s


def test_compiled_and_plain_python_statistics_agree_exactly():
    rows = np.vstack(list(_signals().values()))
    compiled = limit_cycle_stats(rows, T, 0.025 * ALPHA_MAX)
    plain = limit_cycle_stats.py_func(rows, T, 0.025 * ALPHA_MAX)  # the same source, not compiled
    for c, p in zip(compiled, plain, strict=True):
        assert c.tolist() == p.tolist()
    assert compiled[2].tolist()[0] >= 4 and compiled[2].tolist()[1] == 0  # the cycle's sign changes, the ramp's
