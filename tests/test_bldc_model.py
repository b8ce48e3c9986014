"""abc model of [2] (eqs. (1)–(3), (17)) in the BLDC kernel: energy balance, torque, back-EMF shapes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.units import rad_s_to_rpm
from pmsm_commissioning.control.bldc.design import bldc_design
from pmsm_commissioning.control.bldc.dqx import trapezoid_unit
from pmsm_commissioning.control.bldc.speed_smc import reachability_bound, reachability_check
from pmsm_commissioning.sim.bldc import emf as bldc_emf
from pmsm_commissioning.sim.bldc import kernel as kn
from pmsm_commissioning.sim.bldc.engine import CONTROLLERS, pack_parameters, simulate_bldc


@pytest.fixture(scope="module")
def params():
    return load_preset("bldc_smc_paper")


@pytest.mark.parametrize("controller", CONTROLLERS)
def test_energy_balance_closes(params, controller):
    """∫Σv_x·i_x dt = copper + friction + load work + ΔE_kin + E_mag (eq. (1) with eq. (2)–(3),
    (17)): closes to 1e-8 of the input; the load and copper terms are a sizeable share.
    """
    m = simulate_bldc(params, controller).metrics
    assert m.stable
    assert abs(m.energy_balance_residual_J) < 1e-8 * m.electrical_in_total_J
    assert m.copper_total_J > 0.1 * m.electrical_in_total_J
    assert m.kinetic_change_J == pytest.approx(0.5 * 0.0042 * (1000 * math.pi / 30) ** 2, rel=0.01)


def test_emf_power_equals_mechanical_power_eq2_eq3(params):
    """Σe_x·i_x = T_EL·ω (eq. (2) and eq. (3)) at any state, distorted back-EMF included."""
    tab = bldc_emf.distorted_table(0.12)
    prm = pack_parameters(params, bldc_design(params), "smc_integral")
    rng = np.random.default_rng(3)
    dy = np.zeros(kn.N_X)
    for _ in range(20):
        y = np.zeros(kn.N_X)
        y[:4] = rng.normal(size=4) * (5, 5, 100, 3)
        T = kn.plant_derivative(y, 0.0, 0.0, 0.0, 0.0, prm, tab, dy)
        th = 3 * y[3]
        f = [kn.emf_lookup(tab, th - k * 2 * math.pi / 3) for k in range(3)]
        i = (y[0], y[1], -y[0] - y[1])
        p_emf = sum(3 * y[2] * fk * ik for fk, ik in zip(f, i, strict=True))
        assert math.isclose(p_emf, T * y[2], rel_tol=1e-12, abs_tol=1e-9)
        # star without neutral: every phase sees the same star-point voltage, v_k − v_n =
        # L·di_k/dt + R·i_k + e_k (eq. (1)), with di_c/dt = −(di_a/dt + di_b/dt)
        di = (dy[0], dy[1], -(dy[0] + dy[1]))
        v_n = [-(prm[kn.P_L] * dk + prm[kn.P_R] * ik + 3 * y[2] * fk) for dk, ik, fk in zip(di, i, f, strict=True)]
        assert max(v_n) - min(v_n) < 1e-9 * (1 + max(abs(v) for v in v_n))


def test_ideal_table_is_the_trapezoid_and_distorted_is_smooth():
    """Ideal table: Fig. 2 values (flat ±Φ_M, 0 at 0° and 180°). Distorted example: odd
    half-wave symmetry f(θ + π) = −f(θ), no jumps in the slope (smooth), fundamental within 5 %
    of the trapezoid's (4/π)·(sin 30°/30°)·Φ_M.
    """
    ideal = bldc_emf.ideal_table(0.12)
    th = bldc_emf.grid()
    assert np.allclose(ideal, [0.12 * trapezoid_unit(t) for t in th])
    assert ideal[180] == pytest.approx(-0.12) and ideal[0] == pytest.approx(0.0, abs=1e-15)
    d = bldc_emf.distorted_table(0.12)
    n = d.size
    assert np.allclose(np.roll(d, -n // 2), -d, atol=1e-12)
    slope = np.diff(np.append(d, d[0]))
    assert np.max(np.abs(np.diff(slope))) < 0.05 * np.max(np.abs(slope))
    fund = 2 * abs(np.fft.fft(d)[1]) / n
    assert fund == pytest.approx(4 / math.pi * 0.5 / (math.pi / 6) * 0.12, rel=0.05)
    assert np.max(np.abs(d - ideal)) > 0.02 * 0.12  # really not ideal


def test_reachability_hyperbola_eq24():
    """Eq. (24): bound = B/J + (T_max − T_L − B·ω*)/(J·ε) for ε > 0; → B/J as |ε| → ∞; the
    preset's λ(ε) stays inside; a too large λ_0 is reported with the violated interval.
    """
    J, B, w, Tm, TL = 0.0042, 0.003032, 104.72, 5.0, 2.2
    b = reachability_bound(np.array([1.0, 1e9]), w, J, B, Tm, TL)
    assert b[0] == pytest.approx(B / J + (Tm - TL - B * w) / J)
    assert b[1] == pytest.approx(B / J, rel=1e-6)
    assert reachability_check(80.0, 1.0, w, J, B, Tm, TL).ok
    bad = reachability_check(5e5, 50.0, w, J, B, Tm, TL)
    assert not bad.ok and bad.violated
    lo, hi = bad.violated[-1]
    assert 0.0 < lo < hi


def test_one_rk4_step_per_sample_is_converged():
    """The default N_SUB = 1 (h = 50 µs) against 4 substeps: metrics agree to 1e-3 relative."""
    p = load_preset("bldc_smc_paper", ["scenario.active=2000rpm"])
    a, b = simulate_bldc(p, n_sub=1).metrics, simulate_bldc(p, n_sub=4).metrics
    for key in ("torque_ripple_pct", "copper_loss_J", "overshoot_rad_s", "electrical_in_total_J"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-3)
    assert abs(rad_s_to_rpm(a.speed_error_ss_rad_s) - rad_s_to_rpm(b.speed_error_ss_rad_s)) < 1e-3
