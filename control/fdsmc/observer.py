"""Load-torque observer of section 3.4 in [1]: gains, error dynamics and discrete-time design.

Erratum (eq. (15) in [1]). As printed, the observer uses e_o = θ̂_r − θ_r and
dθ̂_r/dt = ω_r + K1·e_o. With K1 = 4q > 0 (eq. (18)) the θ-error then obeys de/dt = +K1·e: an
unstable eigenvalue at +K1, and because θ̂_r is driven by the *measured* ω_r the estimates ω̂_r,
Γ̂_L, dΓ̂_L/dt never enter e_o, so they are not corrected (unobservable). The physically right
observer, for which eq. (16)'s characteristic polynomial and the gains of eq. (18) are correct, is

    e_o = θ_r − θ̂_r,  dθ̂_r/dt = ω̂_r + K1·e_o,  dω̂_r/dt = (H + K·i_d)·i_q − M·L̂0 + K2·e_o,
    dL̂0/dt = L̂1 + K3·e_o,  dL̂1/dt = K4·e_o.

:func:`printed_error_matrix` and :func:`error_matrix` give both error dynamics so that tests can
show the difference in their eigenvalues.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ObserverGains:
    """Continuous-time observer gains, eq. (18) in [1] with the corrected eq. (15).

    Attributes
    ----------
    q : float
        Multiple pole magnitude 15/(2·T_so), eq. (17) [1/s].
    K1 : float  [1/s]
    K2 : float  [1/s²]
    K3 : float  [N·m/(rad·s)]
    K4 : float  [N·m/(rad·s²)]
    """

    q: float
    K1: float
    K2: float
    K3: float
    K4: float


@dataclass(frozen=True)
class DiscreteObserver:
    """Discrete-time observer for sample period T_s, poles at z = exp(−q·T_s) (four-fold).

    Prediction form: x̂[k+1] = Phi·x̂[k] + Gamma·a_em[k] + L·(θ_r[k] − θ̂_r[k]) with
    x̂ = [θ̂_r, ω̂_r, L̂0, L̂1] and a_em = (H + K·i_d)·i_q the electromagnetic acceleration [rad/s²].

    Attributes
    ----------
    T_s : float
        Sample period [s].
    z_pole : float
        Pole location exp(−q·T_s) [-].
    Phi : numpy.ndarray
        4×4 state-transition matrix (ZOH-exact) [-].
    Gamma : numpy.ndarray
        Input vector for a_em [s², s, 0, 0].
    L : numpy.ndarray
        Correction gains [L1 -, L2 1/s, L3 N·m/rad, L4 N·m/(rad·s)].
    """

    T_s: float
    z_pole: float
    Phi: np.ndarray
    Gamma: np.ndarray
    L: np.ndarray


def observer_gains(T_so: float, M: float) -> ObserverGains:
    """Gains K1…K4 of eq. (18) in [1] for four poles at s = −q, q = 15/(2·T_so) (eq. (17)).

    Parameters
    ----------
    T_so : float
        Observer 5 % settling time [s].
    M : float
        1/J_r [1/(kg·m²)].

    Returns
    -------
    ObserverGains
        K1 = 4q, K2 = 6q², K3 = −4q³/M, K4 = −q⁴/M.
    """
    q = 15.0 / (2.0 * T_so)
    return ObserverGains(q=q, K1=4 * q, K2=6 * q**2, K3=-4 * q**3 / M, K4=-q**4 / M)


def _plant_matrices(M: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Observer's real-time model: states [θ_r, ω_r, Γ_L, dΓ_L/dt], input a_em, output θ_r."""
    A = np.array([[0, 1, 0, 0], [0, 0, -M, 0], [0, 0, 0, 1], [0, 0, 0, 0]], dtype=float)
    b = np.array([0.0, 1.0, 0.0, 0.0])
    c = np.array([1.0, 0.0, 0.0, 0.0])
    return A, b, c


def error_matrix(g: ObserverGains, M: float) -> np.ndarray:
    """Estimation-error dynamics matrix A − L·C of the corrected observer (eq. (15), erratum).

    Parameters
    ----------
    g : ObserverGains
        Gains of eq. (18).
    M : float
        1/J_r [1/(kg·m²)].

    Returns
    -------
    numpy.ndarray
        4×4 matrix whose eigenvalues are the observer poles [1/s].
    """
    A, _, c = _plant_matrices(M)
    L = np.array([g.K1, g.K2, g.K3, g.K4])
    return A - np.outer(L, c)


def printed_error_matrix(g: ObserverGains, M: float) -> np.ndarray:
    """Error dynamics of eq. (15) exactly as printed in [1] (e_o = θ̂ − θ, θ̂' = ω_r + K1·e_o).

    Error ε = x̂ − x: ε_θ' = K1·ε_θ; ε_ω' = −M·ε_L0 + K2·ε_θ; ε_L0' = ε_L1 + K3·ε_θ; ε_L1' = K4·ε_θ.

    Returns
    -------
    numpy.ndarray
        4×4 matrix [1/s]; it has the eigenvalue +K1 (unstable) and a zero column structure that
        makes ω̂, L̂0 and L̂1 unobservable from e_o.
    """
    return np.array(
        [[g.K1, 0, 0, 0], [g.K2, 0, -M, 0], [g.K3, 0, 0, 1], [g.K4, 0, 0, 0]], dtype=float
    )


def _chain_zoh(M: float, T_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH (Φ, Γ) of the observer's real-time model (:func:`_plant_matrices`) [-, (s², s, 0, 0)].

    The model is a chain of integrators, so A⁴ = 0 and e^{A·t} = I + A·t + (A·t)²/2 + (A·t)³/6
    exactly; Γ = ∫₀^{T_s} e^{A·τ}·b dτ with b = e₂ (the input a_em drives ω_r).
    """
    t = T_s
    Phi = np.array([[1.0, t, -M * t**2 / 2.0, -M * t**3 / 6.0],
                    [0.0, 1.0, -M * t, -M * t**2 / 2.0],
                    [0.0, 0.0, 1.0, t],
                    [0.0, 0.0, 0.0, 1.0]])
    return Phi, np.array([t**2 / 2.0, t, 0.0, 0.0])


def discrete_observer(g: ObserverGains, M: float, f_s: float) -> DiscreteObserver:
    """Discrete-time equivalent of the observer for sample rate ``f_s``.

    The real-time model is discretised exactly for a zero-order-held input; the gains L place
    all four poles of Φ − L·C at z = exp(−q/f_s), the image of s = −q, by Ackermann's formula.

    Parameters
    ----------
    g : ObserverGains
        Continuous gains (only ``q`` is used).
    M : float
        1/J_r [1/(kg·m²)].
    f_s : float
        Sample rate [Hz].

    Returns
    -------
    DiscreteObserver
        Matrices of the prediction-form observer.
    """
    T_s = 1.0 / f_s
    Phi, Gamma = _chain_zoh(M, T_s)
    z = math.exp(-g.q * T_s)
    # Ackermann: L = p(Φ) · O⁻¹ · e4 with p(λ) = (λ − z)⁴ and O the observability matrix, whose
    # rows c·Φ^k = c·e^{A·k·T_s} (c = e₁) are the first rows of e^{A·t} at t = k·T_s.
    O = np.array([_chain_zoh(M, k * T_s)[0][0] for k in range(4)])
    P = Phi - z * np.eye(4)
    P2 = P @ P
    L = (P2 @ P2) @ np.linalg.solve(O, np.array([0.0, 0.0, 0.0, 1.0]))
    return DiscreteObserver(T_s=T_s, z_pole=z, Phi=Phi, Gamma=Gamma, L=L)
