"""Observer of section 3.4 / eq. (15)–(18) of the FDSMC paper: printed form vs corrected form."""

from __future__ import annotations

import numpy as np
import pytest

from pmsm_commissioning.control.common.discrete import zoh
from pmsm_commissioning.control.fdsmc.observer import (
    discrete_observer,
    error_matrix,
    observer_gains,
    printed_error_matrix,
)

M = 1 / 0.03


def test_corrected_observer_has_fourfold_pole_at_minus_q():
    g = observer_gains(2e-4, M)
    eig = np.linalg.eigvals(error_matrix(g, M))
    # 4-fold root: numerically split by ~(ε)^(1/4); real parts all at −q within 0.1 %
    assert np.allclose(eig.real, -g.q, rtol=1e-3)
    # characteristic polynomial of eq. (16)/(17): s⁴ + 4q s³ + 6q² s² + 4q³ s + q⁴
    coeffs = np.poly(error_matrix(g, M))
    assert np.allclose(coeffs, np.poly([-g.q] * 4), rtol=1e-6)


def test_printed_observer_is_unstable_and_unobservable():
    """Erratum: eq. (15) as printed (e_o = θ̂ − θ, dθ̂/dt = ω_r + K1·e_o) cannot work."""
    g = observer_gains(2e-4, M)
    A = printed_error_matrix(g, M)
    eig = np.linalg.eigvals(A)
    assert np.max(eig.real) == pytest.approx(g.K1)  # unstable eigenvalue +K1 = 4q
    # θ-error evolves alone: ω̂, L̂0, L̂1 errors never reach e_o → unobservable from e_o
    c = np.array([1.0, 0, 0, 0])
    obs = np.vstack([c @ np.linalg.matrix_power(A, k) for k in range(4)])
    assert np.linalg.matrix_rank(obs) == 1


@pytest.mark.parametrize("f_s", [10e3, 20e3, 50e3])
def test_discrete_observer_poles_at_exp_minus_q_Ts(f_s):
    g = observer_gains(2e-4, M)
    d = discrete_observer(g, M, f_s)
    z = np.exp(-g.q / f_s)
    assert d.z_pole == pytest.approx(z)
    coeffs = np.poly(d.Phi - np.outer(d.L, [1, 0, 0, 0]))
    assert np.allclose(coeffs, np.poly([z] * 4), atol=1e-9)


def test_discrete_observer_tracks_constant_load_exactly():
    """Deadbeat-free but exact: a constant Γ_L with the ZOH model is estimated with no bias."""
    g = observer_gains(2e-4, M)
    d = discrete_observer(g, M, 20e3)
    x = np.array([0.0, 0.0, 5.0, 0.0])  # true θ, ω, Γ_L, dΓ_L/dt; a_em = 0
    xh = np.zeros(4)
    for _ in range(400):
        e = x[0] - xh[0]
        xh = d.Phi @ xh + d.L * e
        x = d.Phi @ x
    assert xh[2] == pytest.approx(5.0, rel=1e-6)
    assert xh[1] == pytest.approx(x[1], rel=1e-6)


@pytest.mark.parametrize("f_s", [100.0, 8e3, 20e3, 1e6])
def test_discrete_observer_model_is_the_exact_zoh(f_s):
    """Φ, Γ of the integrator chain in closed form (A⁴ = 0) equal the matrix exponential (Van Loan)."""
    A = np.array([[0, 1, 0, 0], [0, 0, -M, 0], [0, 0, 0, 1], [0, 0, 0, 0]], dtype=float)
    b = np.array([0.0, 1.0, 0.0, 0.0])
    Phi, Gamma = zoh(A, b, 1.0 / f_s)
    d = discrete_observer(observer_gains(2e-4, M), M, f_s)
    np.testing.assert_allclose(d.Phi, Phi, rtol=1e-14, atol=0.0)
    np.testing.assert_allclose(d.Gamma, Gamma, rtol=1e-14, atol=0.0)
