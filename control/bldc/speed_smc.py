"""Speed controller C_ω: integral sliding surface with anti-windup, eqs. (15)–(16), (22)–(24) in [2].

σ_ω = ∫λ(ε_ω)·ε_ω dt + ε_ω (eq. (16), r = 2 in eq. (15)), ε_ω = ω* − ω. The torque reference
is T* = T_max·tanh(k_ω·σ_ω) and i*_qx = T*/(n_pp·√(3/2)·Φ_m) (eq. (9); see
:func:`control.bldc.dqx.torque_constant_fig7` for why Fig. 7's K_T = 2·n_pp·Φ_M is not used there).

Choice of λ(ε) (the paper leaves it open): the Lorentzian λ(ε) = λ_0/(1 + (ε/ε_λ)²). It
decays as |ε| grows, so the integrand λ(ε)·ε is bounded by λ_0·ε_λ/2 and vanishes for large
errors — the gradual "conditional integration" anti-windup described in section V of [2] — and
it decays like 1/ε², faster than the 1/ε reachability hyperbola of eq. (24), so it can stay
inside the hyperbola for all errors. ε_λ = ∞ (:data:`NO_ANTI_WINDUP`) switches the anti-windup
off: ε/∞ = 0 in IEEE arithmetic, so λ(ε) = λ_0 exactly for every error.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.common.arrays import FloatOrArray

#: ε_λ [rad/s] without anti-windup: λ(ε) = λ_0 for every error, exactly (the integral of eq. (16)
#: is never relieved).
NO_ANTI_WINDUP = math.inf


def lambda_of_error(eps: FloatOrArray, lambda_0: float, eps_lambda: float) -> FloatOrArray:
    """λ(ε) = λ_0/(1 + (ε/ε_λ)²), the integral weight of eq. (16) in [2] [1/s].

    Parameters
    ----------
    eps : float or numpy.ndarray  Speed error ε_ω [rad/s] (an array gives λ at each error).
    lambda_0 : float    λ(0) [1/s].
    eps_lambda : float  Half-value error ε_λ [rad/s].
    """
    r = eps / eps_lambda
    return lambda_0 / (1.0 + r * r)


def integral_rate(eps: float, lambda_0: float, eps_lambda: float) -> float:
    """d/dt of the integral part of eq. (16) in [2]: λ(ε)·ε [rad/s²].

    :func:`lambda_of_error` written out, because the BLDC kernel compiles this function alone.
    """
    r = eps / eps_lambda
    return lambda_0 * eps / (1.0 + r * r)


def torque_reference(sigma: float, k_omega: float, T_max: float) -> float:
    """T* = T_max·tanh(k_ω·σ_ω), the tanh switching function of C_ω (Fig. 7 of [2]) [N·m].

    Parameters
    ----------
    sigma : float    Sliding variable σ_ω [rad/s].
    k_omega : float  Gain [s/rad].
    T_max : float    Torque limit [N·m].
    """
    return T_max * math.tanh(k_omega * sigma)


def reachability_bound(eps: np.ndarray, omega_ref: float, J: float, B: float, T_max: float,
                       T_L_max: float) -> np.ndarray:
    """Upper bound on λ(ε) from eq. (24) in [2] at the operating limits [1/s].

    For ε > 0 (accelerate) the worst case is T_EL = +T_max against T_L = +T_L,max; for ε < 0
    (decelerate) T_EL = −T_max with T_L = −T_L,max favouring the motion:
    λ < B/J + (T_max − T_L,max − sign(ε)·B·ω*)/(J·|ε|). NaN at ε = 0 (unbounded).

    Parameters
    ----------
    eps : numpy.ndarray  Speed errors [rad/s].
    omega_ref : float    Speed reference ω* [rad/s].
    J : float            Inertia [kg·m²].
    B : float            Viscous friction [N·m·s/rad].
    T_max : float        Largest electromagnetic torque [N·m].
    T_L_max : float      Largest |load torque| [N·m].
    """
    eps = np.asarray(eps, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = B / J + (T_max - T_L_max - np.sign(eps) * B * omega_ref) / (J * np.abs(eps))
    return np.where(eps == 0.0, np.nan, bound)


@dataclass(frozen=True)
class ReachabilityCheck:
    """λ(ε) against the hyperbola of eq. (24) in [2] on a grid of errors (Fig. 8).

    Attributes
    ----------
    eps : numpy.ndarray        Speed errors [rad/s].
    lam : numpy.ndarray        λ(ε) [1/s].
    bound : numpy.ndarray      Hyperbola of eq. (24) [1/s].
    violated : tuple           (ε_from, ε_to) intervals [rad/s] where λ(ε) ≥ bound.
    ok : bool                  True when λ stays inside the hyperbola on the whole grid.
    """

    eps: np.ndarray
    lam: np.ndarray
    bound: np.ndarray
    violated: tuple[tuple[float, float], ...]
    ok: bool


def reachability_check(lambda_0: float, eps_lambda: float, omega_ref: float, J: float, B: float,
                       T_max: float, T_L_max: float, eps_span: float | None = None,
                       n: int = 801) -> ReachabilityCheck:
    """Evaluate λ(ε) inside the reachability hyperbola, eqs. (22)–(24) in [2].

    Parameters
    ----------
    lambda_0, eps_lambda : float  λ(ε) parameters [1/s], [rad/s].
    omega_ref : float             Speed reference ω* [rad/s].
    J, B : float                  Inertia [kg·m²], friction [N·m·s/rad].
    T_max, T_L_max : float        Torque limit and largest |load torque| [N·m].
    eps_span : float or None      Grid covers ±eps_span [rad/s]; default max(|ω*|, 20·ε_λ).
    n : int                       Grid points (odd, so ε = 0 is on the grid).
    """
    span = eps_span if eps_span is not None else max(abs(omega_ref), 20.0 * eps_lambda)
    eps = np.linspace(-span, span, n)
    lam = lambda_of_error(eps, lambda_0, eps_lambda)
    bound = reachability_bound(eps, omega_ref, J, B, T_max, T_L_max)
    bad = np.where(np.isnan(bound), False, lam >= bound)
    return ReachabilityCheck(eps, lam, bound, _intervals(eps, bad), not bool(bad.any()))


def _intervals(x: np.ndarray, mask: np.ndarray) -> tuple[tuple[float, float], ...]:
    """(first, last) x of each run of True in ``mask``."""
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return tuple((float(x[a]), float(x[b])) for a, b in zip(starts, stops, strict=True))
