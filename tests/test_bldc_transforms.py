"""dq_x transformation of [2] (eqs. (4)–(12)): round trips, torque eq. (3) = eq. (9), eq. (10),
and the paper's typos (eq. (12) θ_r, single-argument tan⁻¹ in eq. (8), K_T of Fig. 7).
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pmsm_commissioning.control.bldc import dqx

angles = st.floats(-20.0, 20.0, allow_nan=False)
values = st.floats(-100.0, 100.0, allow_nan=False)
PHI_M, NPP = 0.12, 3


def _ideal_gain_angle(theta_e: float) -> tuple[float, float, tuple[float, float, float]]:
    phases = tuple(PHI_M * dqx.trapezoid_unit(theta_e - k * 2 * math.pi / 3) for k in range(3))
    a_x, phi = dqx.dqx_gain_angle(*dqx.alpha_beta(*phases), PHI_M)
    return a_x, phi, phases


@settings(max_examples=200, deadline=None)
@given(values, values, values)
def test_abc_alpha_beta_zero_round_trip(x_a, x_b, x_c):
    """Eqs. (5)–(6) and their inverse: abc → αβ0 → abc to 1e-12 (relative to the size)."""
    back = dqx.abc_from_alpha_beta(*dqx.alpha_beta(x_a, x_b, x_c), dqx.zero_sequence(x_a, x_b, x_c))
    scale = max(1.0, abs(x_a), abs(x_b), abs(x_c))
    assert np.allclose(back, (x_a, x_b, x_c), rtol=0.0, atol=1e-12 * scale)


@settings(max_examples=200, deadline=None)
@given(angles, values, values)
def test_dqx_round_trip_with_ideal_coefficients(theta_e, x_alpha, x_beta):
    """Eq. (4) and its inverse with a_x, θ_x of the ideal trapezoid: round trip to 1e-12."""
    a_x, phi, _ = _ideal_gain_angle(theta_e)
    back = dqx.from_dqx(*dqx.to_dqx(x_alpha, x_beta, a_x, phi), a_x, phi)
    scale = max(1.0, abs(x_alpha), abs(x_beta))
    assert np.allclose(back, (x_alpha, x_beta), rtol=0.0, atol=1e-12 * scale)


def test_power_invariance():
    """Eq. (5) is power invariant: Σ v_x·i_x = v_α·i_α + v_β·i_β + v_0·i_0."""
    rng = np.random.default_rng(1)
    for v, i in zip(rng.normal(size=(20, 3)), rng.normal(size=(20, 3)), strict=True):
        p_abc = float(v @ i)
        va, vb = dqx.alpha_beta(*v)
        ia, ib = dqx.alpha_beta(*i)
        p_ab0 = va * ia + vb * ib + dqx.zero_sequence(*v) * dqx.zero_sequence(*i)
        assert math.isclose(p_abc, p_ab0, rel_tol=1e-12, abs_tol=1e-12)


@settings(max_examples=300, deadline=None)
@given(angles, values, values)
def test_torque_eq3_equals_eq9_for_ideal_waveform(theta_e, i_d, i_q):
    """Currents set in dq_x (zero-sequence free) on the ideal machine: eq. (3) in abc equals
    eq. (9), T = n_pp·√(3/2)·Φ_m·i_qx, at any θ_e; i_dx gives no torque.
    """
    a_x, phi, phases = _ideal_gain_angle(theta_e)
    i_abc = dqx.abc_from_alpha_beta(*dqx.from_dqx(i_d, i_q, a_x, phi), 0.0)
    T3 = NPP * sum(f * i for f, i in zip(phases, i_abc, strict=True))
    T9 = dqx.torque_constant_dqx(NPP, PHI_M) * i_q
    assert math.isclose(T3, T9, rel_tol=1e-9, abs_tol=1e-9 * (1 + abs(i_d)))


def test_sinusoidal_machine_reduces_to_dq():
    """For Φ'_ra = −Φ_m·sin θ_e (our origin) eqs. (7)–(8) give a_x = 1 and θ_x = 0 everywhere."""
    th = np.linspace(0, 2 * np.pi, 73)
    phi = np.array([-PHI_M * np.sin(th - k * 2 * np.pi / 3) for k in range(3)])
    dphi = np.array([-PHI_M * np.cos(th - k * 2 * np.pi / 3) for k in range(3)])
    c = dqx.dqx_coefficients(th, phi, dphi, PHI_M)
    assert np.allclose(c.a_x, 1.0, atol=1e-12)
    assert np.allclose(c.theta_x, 0.0, atol=1e-12)
    assert np.allclose(c.da_x, 0.0, atol=1e-12) and np.allclose(c.dtheta_x, 0.0, atol=1e-12)


def test_ideal_trapezoid_a_x_range_and_period():
    """Ideal trapezoid: |Φ'_αβ|² = Φ_m²·(2 + 2s²/3) with s the ramping phase ⇒ a_x runs from
    √(3/2)/√(8/3) = 0.75 (corners) to √(3/2)/√2 = 0.866 (mid-ramp), with a 60° period (Fig. 5).
    """
    th = np.linspace(0, 2 * np.pi, 721)
    c = dqx.ideal_coefficients(th, PHI_M)
    assert math.isclose(c.a_x.min(), 0.75, rel_tol=1e-9)
    assert math.isclose(c.a_x.max(), math.sqrt(1.5 / 2.0), rel_tol=1e-9)
    shifted = dqx.ideal_coefficients(th + np.pi / 3, PHI_M)
    assert np.allclose(shifted.a_x, c.a_x, atol=1e-12)
    assert np.allclose(shifted.theta_x, c.theta_x, atol=1e-9)
    assert np.max(np.abs(c.theta_x)) < math.radians(10.0)


def _smooth_phases(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """A smooth non-sinusoidal test EMF: −Φ_m·(sin θ + 0.15·sin 5θ) per phase, and d/dθ."""
    s = np.array([theta - k * 2 * np.pi / 3 for k in range(3)])
    return (-PHI_M * (np.sin(s) + 0.15 * np.sin(5 * s)),
            -PHI_M * (np.cos(s) + 0.75 * np.cos(5 * s)))


def test_electrical_equation_eq10_matches_abc_model():
    """Eq. (10) equals eq. (1) transformed with eq. (4) (a_x, θ_x from the same waveform),
    including the a'_x/a_x and (1 + θ'_x) terms and e_qx = √(3/2)·Φ_m·ω_e/a_x².
    """
    R, L, w_e = 2.3, 0.0125, 300.0
    i_d_f = lambda t: 1.0 + 0.5 * np.sin(40 * t)  # noqa: E731
    i_q_f = lambda t: 4.0 + np.cos(25 * t)  # noqa: E731

    def i_ab(t: float) -> complex:
        th = w_e * t
        c = dqx.dqx_coefficients(np.array([th]), *[x[:, None] for x in _smooth_phases(th)], PHI_M)
        return c.a_x[0] * np.exp(1j * (c.theta_x[0] + th)) * (i_d_f(t) + 1j * i_q_f(t))

    for t in (0.0013, 0.0071, 0.0123):
        h = 1e-7
        di = (i_ab(t + h) - i_ab(t - h)) / (2 * h)
        th = w_e * t
        phi, dphi = _smooth_phases(th)
        fa, fb = dqx.alpha_beta(*phi)
        v_ab = R * i_ab(t) + L * di + w_e * (fa + 1j * fb)
        c = dqx.dqx_coefficients(np.array([th]), phi[:, None], dphi[:, None], PHI_M)
        a, tx, da, dtx = c.a_x[0], c.theta_x[0], c.da_x[0], c.dtheta_x[0]
        v_dq = v_ab * np.exp(-1j * (tx + th)) / a
        i_d, i_q = i_d_f(t), i_q_f(t)
        di_d = 20 * np.cos(40 * t)
        di_q = -25 * np.sin(25 * t)
        v_d = R * i_d + L * di_d + L * w_e * (i_d * da / a - i_q * (1 + dtx))
        v_q = R * i_q + L * di_q + L * w_e * (i_q * da / a + i_d * (1 + dtx)) + math.sqrt(1.5) * PHI_M * w_e / a**2
        assert math.isclose(v_dq.real, v_d, rel_tol=1e-6, abs_tol=1e-5)
        assert math.isclose(v_dq.imag, v_q, rel_tol=1e-6, abs_tol=1e-5)


def test_eq12_typo_theta_r_instead_of_theta_e():
    """Eq. (12) repeats eq. (8) with θ_r (mechanical). For a sinusoidal machine with n_pp = 3
    that would give θ_x = θ_e − θ_r = (2/3)·θ_e ≠ 0, i.e. a rotating, wrong frame; eq. (8) with
    θ_e gives θ_x ≡ 0, which is physically right (dq_x must reduce to dq).
    """
    th = np.linspace(0.1, 2.0, 9)
    f = np.array([-np.sin(th - k * 2 * np.pi / 3) for k in range(3)])
    fa, fb = dqx.alpha_beta(*f)
    phi = np.arctan2(-fa, fb)
    assert np.allclose(phi - th, 0.0, atol=1e-12)  # eq. (8)
    # Physics of the two frames: steady sinusoidal currents in phase with the back-EMF must be a
    # constant i_qx (and i_dx = 0) in a frame that is right. With φ of eq. (8) (θ_e) they are; with
    # the printed eq. (12) (θ_r = θ_e/n_pp in place of θ_e) the frame rotates and i_qx oscillates.
    i_abc = np.array([10.0 * np.sin(th - k * 2 * np.pi / 3) for k in range(3)])
    ia, ib = dqx.alpha_beta(*i_abc)

    def currents(angle):
        return np.array([dqx.to_dqx(a, b, 1.0, x) for a, b, x in zip(ia, ib, angle, strict=True)])

    right = currents(phi)
    wrong = currents(phi - th + th / NPP)  # θ_x + θ_r instead of θ_x + θ_e
    assert np.ptp(right[:, 1]) < 1e-9 and np.allclose(right[:, 0], 0.0, atol=1e-9)
    assert np.ptp(wrong[:, 1]) > 1.0 and np.max(np.abs(wrong[:, 0])) > 1.0


def test_single_argument_arctan_of_eq8_flips_the_axes():
    """tan⁻¹(−Φ'_α/Φ'_β) as printed loses the quadrant: on half the period the dq_x axes are
    reversed and eq. (9) would give the wrong torque sign. atan2 (used) does not.
    """
    th = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    phi_abc, _ = dqx.ideal_phases(th, PHI_M)
    fa, fb = dqx.alpha_beta(*phi_abc)
    wrong = np.arctan(-fa / fb)
    right = np.arctan2(-fa, fb)
    flipped = np.abs(np.angle(np.exp(1j * (wrong - right)))) > 3.0
    assert 0.4 < flipped.mean() < 0.6
    assert np.all(np.abs(np.angle(np.exp(1j * (right - th)))) < 0.2)


def test_fig7_torque_constant_is_the_six_step_line_current_constant():
    """120° square currents ±I on the ideal trapezoid's flat tops give T = 2·n_pp·Φ_M·I (K_T of
    Fig. 7), while eq. (9) needs n_pp·√(3/2)·Φ_m per ampere of i_qx: K_T(Fig. 7) used for i*_qx
    would deliver only √(3/2)/2 ≈ 0.61 of the demanded torque.
    """
    I = 3.0
    for th in np.radians([40.0, 60.0, 85.0]):  # a and b on flat tops, c ramping (off)
        phases = [PHI_M * dqx.trapezoid_unit(th - k * 2 * np.pi / 3) for k in range(3)]
        i_abc = (np.sign(phases[0]) * I, np.sign(phases[1]) * I, 0.0)
        T = NPP * sum(f * i for f, i in zip(phases, i_abc, strict=True))
        assert math.isclose(abs(T), dqx.torque_constant_fig7(NPP, PHI_M) * I, rel_tol=1e-12)
    ratio = dqx.torque_constant_dqx(NPP, PHI_M) / dqx.torque_constant_fig7(NPP, PHI_M)
    assert math.isclose(ratio, math.sqrt(1.5) / 2, rel_tol=1e-12)
