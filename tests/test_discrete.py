"""Exact zero-order-hold discretisation (control.common.discrete): closed-form cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from pmsm_commissioning.control.common.discrete import block_exponential, zoh


def test_double_integrator() -> None:
    """θ'' = u held for T_s: Φ = [[1, T_s], [0, 1]], Γ = [T_s²/2, T_s]."""
    T_s = 1e-3
    Phi, Gamma = zoh(np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([0.0, 1.0]), T_s)
    np.testing.assert_allclose(Phi, [[1.0, T_s], [0.0, 1.0]], rtol=1e-15, atol=1e-18)
    np.testing.assert_allclose(Gamma, [T_s**2 / 2.0, T_s], rtol=1e-15)


@pytest.mark.parametrize("a", [0.5, 60.0, 2.0e4])
def test_first_order_lag(a: float) -> None:
    """x' = −a·x + u: Φ = e^{−a·T_s}, Γ = (1 − e^{−a·T_s})/a."""
    T_s = 5e-5
    Phi, Gamma = zoh(np.array([[-a]]), np.array([1.0]), T_s)
    assert Phi[0, 0] == pytest.approx(math.exp(-a * T_s), rel=1e-14)
    assert Gamma[0] == pytest.approx(-math.expm1(-a * T_s) / a, rel=1e-12)
    assert Gamma.shape == (1,)


def test_observer_chain_matches_expm() -> None:
    """The observer's model θ_r, ω_r, Γ_L, dΓ_L/dt (integrator chain): Φ, Γ are the blocks of e^M."""
    M, T_s = 1.0 / 0.012, 1.0 / 20e3
    A = np.array([[0, 1, 0, 0], [0, 0, -M, 0], [0, 0, 0, 1], [0, 0, 0, 0]], dtype=float)
    b = np.array([0.0, 1.0, 0.0, 0.0])
    Phi, Gamma = zoh(A, b, T_s)
    aug = np.zeros((5, 5))
    aug[:4, :4], aug[:4, 4] = A * T_s, b * T_s
    E = expm(aug)
    np.testing.assert_allclose(Phi, E[:4, :4], rtol=1e-13, atol=1e-18)
    np.testing.assert_allclose(Gamma, E[:4, 4], rtol=1e-13, atol=1e-22)
    assert Phi[0, 3] == pytest.approx(-M * T_s**3 / 6.0, rel=1e-12)  # the exact cubic term (A⁴ = 0)


def test_block_exponential_of_a_rotation() -> None:
    """e^{[[0, −w], [w, 0]]} is the rotation by w."""
    w = 0.3
    np.testing.assert_allclose(block_exponential(np.array([[0.0, -w], [w, 0.0]])),
                               [[math.cos(w), -math.sin(w)], [math.sin(w), math.cos(w)]], rtol=1e-14)


def test_input_matrix_keeps_its_shape() -> None:
    """Two inputs: Γ is n×m, each column the ZOH of one input."""
    A = np.array([[-2.0, 0.0], [0.0, -3.0]])
    B = np.array([[1.0, 0.0], [0.0, 2.0]])
    T_s = 0.1
    _, Gamma = zoh(A, B, T_s)
    np.testing.assert_allclose(Gamma, np.diag([-math.expm1(-0.2) / 2.0, 2.0 * -math.expm1(-0.3) / 3.0]),
                               rtol=1e-13)
