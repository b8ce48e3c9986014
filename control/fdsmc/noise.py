"""Standstill ripple from the sensors: the noise gain of the sampled closed loop, in closed form.

Holding θ_dem, the FDSMC's outer loop is inside its boundary layer on the sloped segment of
eq. (41) in [1], where eq. (46) is linear: α_dem = −α_max·K·(ω̂_r + θ̂_re/T_c) (the conventional
law: α_dem = −g1·θ̂_re − g2·ω̂_r, eq. (61)). The sampled loop of
:func:`control.fdsmc.loop_model.discrete_loop` is then linear, and the measurement noise enters it
at two places:

* the encoder's quantization error n_θ (θ_r read in whole counts Δ = 2π/cpr) enters the observer's
  innovation e_o = θ_r + n_θ − θ̂_r (eq. (15), corrected);
* the current noise n_i (rms σ, plus the ADC's step q) enters the FDC law (14) through the
  measured i_q and the observer's acceleration a_em = H·i_q.

With n_θ modelled as white, uniform over one count (variance Δ²/12, the usual model once the
rotor jitters over several counts) and n_i white (σ² + q²/12), the steady-state covariance P of
the loop's state solves the discrete Lyapunov equation P = Z·P·Zᵀ + B·W·Bᵀ; the rms ripple of i_q
is √P[i_q, i_q] and that of the applied u_q follows from the control row.

The same covariance gives the rms of the demanded acceleration, α_dem = a_θ·θ̂ + a_ω·ω̂ of the
outer law; its expected swing over a chatter window is :data:`PTP_PER_RMS` times the rms. Where
that swing reaches the chatter criterion's amplitude, the noise alone makes α_dem chatter without
any instability (:func:`noise_gain_limit`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgWarning, matrix_balance, solve_discrete_lyapunov

from control.fdsmc.loop_model import (
    K_SEARCH_RATIO,
    K_search_grid,
    LoopCase,
    control_row,
    discrete_matrix,
    geometric_bisect,
    law_case,
    outer_gains,
    sampled_parts,
)

#: Peak-to-peak of the sampled noise of α_dem over a chatter window per rms [-]. A few thousand
#: Gaussian samples span ≈ 2 × 3.5 rms; the high-passed α_dem of the chatter criterion spans
#: 6.1 rms on a Σ-7 servo with an 8192-count encoder and only 3.5 rms (a uniform distribution's
#: √12) on the belt-driven D5065, whose observer passes the counts' error nearly unfiltered
#: (``tests/test_noise_limit.py``). The Gaussian-like case sets the number.
PTP_PER_RMS = 6.0


@dataclass(frozen=True)
class NoiseGain:
    """Standstill ripple predicted from the sensors' noise (rms values).

    Attributes
    ----------
    i_q_rms : float           RMS ripple of i_q [A] (inf when the linear loop is unstable).
    u_q_rms : float           RMS ripple of the applied u_q [V].
    i_q_per_rad : float       i_q rms from quantization alone per radian of encoder count [A/rad]:
                              the quantization ripple is i_q_per_rad·Δ for a count Δ = 2π/cpr.
    alpha_dem_rms : float     RMS of the demanded acceleration α_dem of the outer law [rad/s²].
    """

    i_q_rms: float
    u_q_rms: float
    i_q_per_rad: float
    alpha_dem_rms: float


def noise_gain(loop: LoopCase, law: str, K: float, count: float, i_noise_rms: float) -> NoiseGain:
    """Predict the standstill ripple of i_q and u_q from encoder quantization and current noise.

    Parameters
    ----------
    loop : LoopCase       The linearised loop (``Derived.loop``); must be sampled (``loop.f_s``).
    law : str             ``"slope"`` (FDSMC holding θ_dem) or ``"conventional"``.
    K : float             Boundary-layer gain of eq. (45) in [1] [s/rad].
    count : float         Encoder count Δ = 2π/cpr [rad]; 0 for an ideal encoder.
    i_noise_rms : float   RMS of the current-measurement error, noise and ADC step [A].

    Returns
    -------
    NoiseGain
    """
    if loop.f_s is None:
        raise ValueError("noise_gain needs a sampled loop: loop.f_s is None")
    parts = sampled_parts(loop, loop.f_s)
    row = control_row(loop, law, K)
    Z = discrete_matrix(parts, loop.coefficients.H, row, loop.delay)
    if not np.all(np.isfinite(Z)) or np.max(np.abs(np.linalg.eigvals(Z))) >= 1.0:
        return NoiseGain(math.inf, math.inf, math.inf, math.inf)
    B = _noise_inputs(parts, loop, row)
    var_theta, var_i = count**2 / 12.0, i_noise_rms**2
    P_theta, P_i = (_covariance(Z, B[:, j]) for j in (0, 1))
    P = var_theta * P_theta + var_i * P_i
    u_rms = math.sqrt(max(P[-1, -1], 0.0)) if loop.delay else math.sqrt(
        max(float(row @ P[:7, :7] @ row) + row[0] ** 2 * var_i, 0.0))
    per_rad = math.sqrt(max(P_theta[0, 0], 0.0) / 12.0)
    a = np.array(outer_gains(loop, law, K))  # α_dem = a_θ·θ̂ + a_ω·ω̂ (states 3 and 4)
    alpha_rms = math.sqrt(max(float(a @ P[3:5, 3:5] @ a), 0.0))
    return NoiseGain(math.sqrt(max(P[0, 0], 0.0)), u_rms, per_rad, alpha_rms)


def _covariance(Z: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Steady-state covariance of x[k+1] = Z·x[k] + b·w[k] for unit white w: P = Z·P·Zᵀ + b·bᵀ.

    The states span many orders of magnitude (θ in rad, L̂1 in N·m/s), so Z is balanced first
    (:func:`scipy.linalg.matrix_balance`, Z = D·Z_b·D⁻¹) and the equation solved for P_b = D⁻¹·P·D⁻ᵀ.
    """
    Z_b, D = matrix_balance(Z, permute=False, separate=True)
    s = D[0]
    P_b = solve_discrete_lyapunov(Z_b, np.outer(b / s, b / s))
    return P_b * np.outer(s, s)


def _noise_inputs(parts, loop: LoopCase, row: np.ndarray) -> np.ndarray:
    """Input columns (n × 2) of the encoder error n_θ and the i_q measurement error n_i."""
    n = 7 + loop.delay
    B = np.zeros((n, 2))
    od = parts.observer
    B[3:7, 0] = od.L  # innovation e_o = θ + n_θ − θ̂
    B[3:7, 1] = od.Gamma * loop.coefficients.H  # a_em = H·(i_q + n_i)
    if loop.delay:
        B[7, 1] = row[0]  # the held u_q is computed from the measured i_q
    else:
        B[:3, 1] += parts.bd * row[0]
    return B


def noise_gain_limit(d: LoopCase, count: float, i_noise_rms: float, fraction: float,
                     K_max: float) -> float:
    """Smallest K ≤ K_max [s/rad] at which the sensors' noise swings α_dem by ``fraction``·α_max.

    The predicted swing of α_dem holding θ_dem is PTP_PER_RMS × its rms
    (:func:`control.fdsmc.noise.noise_gain`, sloped law of eq. (46) in [1]); it grows with K
    (α_dem = −α_max·K·(ω̂_r + θ̂_re/T_c)). In the cruise the swing is the same to ≈ 1 % (θ̂_re/T_c
    is small against ω̂_r), so one limit serves both windows of the chatter criterion.

    Parameters
    ----------
    d : LoopCase          The linearised loop; continuous: no limit.
    count : float         Encoder count Δ = 2π/cpr [rad]; 0 for an ideal encoder.
    i_noise_rms : float   RMS of the current-measurement error [A].
    fraction : float      Allowed swing of α_dem [fraction of α_max].
    K_max : float         Upper end of the search [s/rad], e.g. the stability limit.

    Returns
    -------
    float
        inf when the sensors are ideal, the controller continuous, the swing stays below
        ``fraction`` up to K_max, or the crossing is only the loop's own instability. Cached on the
        numbers the search reads (K is not one of them); so is the rms at each K, which the searches
        for several fractions share.
    """
    if d.f_s is None or (count == 0.0 and i_noise_rms == 0.0) or not K_max > 0.0:
        return math.inf
    return _noise_gain_limit(law_case(d, "slope"), float(d.f_s), int(d.delay), float(count),
                             float(i_noise_rms), float(fraction), float(K_max))


@functools.lru_cache(maxsize=512)
def _noise_gain_limit(case: LoopCase, f_s: float, delay: int, count: float, i_noise_rms: float,
                      fraction: float, K_max: float) -> float:
    loop = dataclasses.replace(case, f_s=f_s, delay=delay)
    target = fraction * loop.alpha_max / PTP_PER_RMS

    def rms(K: float) -> float:
        return _alpha_dem_rms(loop, K, count, i_noise_rms)

    def swings(K: float) -> bool:
        return not rms(K) < target

    Ks = [float(K) for K in K_search_grid(loop.alpha_max) if K_max > K] + ([K_max] if math.isfinite(K_max) else [])
    lo = None
    for K in Ks:
        if not swings(K):
            lo = K
        elif lo is None:  # the noise swings α_dem even at the smallest K searched
            return K
        else:
            K_hi = geometric_bisect(swings, lo, K, K_SEARCH_RATIO)
            return K_hi if math.isfinite(rms(K_hi)) else math.inf  # the loop's own limit came first
    return math.inf


@functools.lru_cache(maxsize=2048)
def _alpha_dem_rms(loop: LoopCase, K: float, count: float, i_noise_rms: float) -> float:
    """α_dem rms of :func:`noise_gain` on the sloped law [rad/s²] (inf where the loop is unstable)."""
    with warnings.catch_warnings():  # ill-conditioned only next to the stability limit
        warnings.simplefilter("ignore", LinAlgWarning)
        return noise_gain(loop, "slope", K, count, i_noise_rms).alpha_dem_rms


__all__ = ["PTP_PER_RMS", "NoiseGain", "noise_gain", "noise_gain_limit"]
