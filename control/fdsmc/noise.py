"""Standstill ripple from the sensors: the noise gain of the sampled closed loop, in closed form.

Holding θ_dem, the FDSMC's outer loop is inside its boundary layer on the sloped segment of
eq. (41) in [1], where eq. (46) is linear: α_dem = −α_max·K·(ω̂_r + θ̂_re/T_c) (the conventional
law: α_dem = −g1·θ̂_re − g2·ω̂_r, eq. (61)). The sampled loop of
:func:`control.fdsmc.loop_model.discrete_loop` is then linear, and the measurement noise enters it
at two places:

* the encoder's quantization error n_θ (θ_r read in whole counts Δ = 2π/cpr) enters the observer's
  innovation e_o = θ_r + n_θ − θ̂_r (eq. (15), corrected);
* the current noise n_i (rms σ, plus the ADC's step q) enters the FDC law (14) through the
  measured i_q and the observer's acceleration a_em = H·i_q, and, where the controller runs the
  q-axis voltage-mismatch estimate (``controller.T_dv``, not in [1]), that estimate's comparison of
  the measured i_q with its one-sample prediction (:func:`sampled_noise_loop`).

With n_i white (σ² + q²/12), the steady-state covariance of the loop's state from it solves the
discrete Lyapunov equation P = Z·P·Zᵀ + b·σ²·bᵀ. n_θ is uniform over one count (variance Δ²/12) and
coloured by the rotor's own motion (:mod:`control.fdsmc.quantization`); white where the rotor
crosses many counts per sample. The rms ripple of i_q is √P[i_q, i_q] of the sum and that of the
applied u_q follows from the control row.

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

from pmsm_commissioning.control.common.arrays import FloatArray
from pmsm_commissioning.control.fdsmc.fdc import mismatch_filter_factor
from pmsm_commissioning.control.fdsmc.inverter import decay_factors
from pmsm_commissioning.control.fdsmc.loop_model import (
    K_SEARCH_RATIO,
    N_STATES,
    K_search_grid,
    LoopCase,
    control_row,
    geometric_bisect,
    law_case,
    outer_gains,
    sampled_parts,
)
from pmsm_commissioning.control.fdsmc.quantization import quantization_covariance

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
    i_q_rms : float            RMS ripple of i_q [A], both parts (inf when the linear loop is unstable).
    u_q_rms : float            RMS ripple of the applied u_q [V].
    i_q_quant_rms : float      Part of ``i_q_rms`` from the encoder's quantization [A].
    i_q_current_rms : float    Part of ``i_q_rms`` from the current noise and the ADC [A].
    jitter_counts : float      RMS of the rotor angle θ_r in encoder counts [-] (0 for an ideal encoder).
    alpha_dem_rms : float      RMS of the demanded acceleration α_dem of the outer law [rad/s²].
    """

    i_q_rms: float
    u_q_rms: float
    i_q_quant_rms: float
    i_q_current_rms: float
    jitter_counts: float
    alpha_dem_rms: float


def noise_gain(loop: LoopCase, law: str, K: float, count: float, i_noise_rms: float,
               T_dv: float = 0.0, coloured: bool = True) -> NoiseGain:
    """Predict the standstill ripple of i_q and u_q from encoder quantization and current noise.

    Parameters
    ----------
    loop : LoopCase       The linearised loop (``Derived.loop``); must be sampled (``loop.f_s``).
    law : str             ``"slope"`` (FDSMC holding θ_dem) or ``"conventional"``.
    K : float             Boundary-layer gain of eq. (45) in [1] [s/rad].
    count : float         Encoder count Δ = 2π/cpr [rad]; 0 for an ideal encoder.
    i_noise_rms : float   RMS of the current-measurement error, noise and ADC step [A].
    T_dv : float          Filter time of the q-axis voltage-mismatch estimate (``controller.T_dv``,
                          :func:`control.fdsmc.fdc.voltage_mismatch`; not in [1]) [s]; 0: none.
    coloured : bool       Quantization error coloured by the rotor's motion
                          (:func:`control.fdsmc.quantization.quantization_covariance`); False: white, Δ²/12.

    Returns
    -------
    NoiseGain
    """
    if loop.f_s is None:
        raise ValueError("noise_gain needs a sampled loop: loop.f_s is None")
    beta = mismatch_filter_factor(T_dv, float(loop.f_s))
    Z, B, u = sampled_noise_loop(loop, control_row(loop, law, K), beta)
    if not np.all(np.isfinite(Z)) or np.max(np.abs(np.linalg.eigvals(Z))) >= 1.0:
        return NoiseGain(math.inf, math.inf, math.inf, math.inf, math.inf, math.inf)
    P_i = i_noise_rms**2 * _covariance(Z, B[:, 1])
    P_q, jitter = _quantization(Z, B[:, 0], P_i, count, coloured)
    P = P_q + P_i
    n = Z.shape[0]
    feed = u[n] ** 2 * count**2 / 12.0 + u[n + 1] ** 2 * i_noise_rms**2  # 0 for n_θ: it enters the observer only
    u_rms = math.sqrt(max(float(u[:n] @ P @ u[:n] + feed), 0.0))
    a = np.array(outer_gains(loop, law, K))  # α_dem = a_θ·θ̂ + a_ω·ω̂ (states 3 and 4)
    alpha_rms = math.sqrt(max(float(a @ P[3:5, 3:5] @ a), 0.0))
    rms = [math.sqrt(max(float(X[0, 0]), 0.0)) for X in (P, P_q, P_i)]
    return NoiseGain(rms[0], u_rms, rms[1], rms[2], jitter, alpha_rms)


def _quantization(Z: np.ndarray, b: np.ndarray, P_i: np.ndarray, count: float,
                  coloured: bool) -> tuple[np.ndarray, float]:
    """Covariance of the state from the encoder's quantization [state units²] and the rotor's jitter [counts]."""
    if count == 0.0:
        return np.zeros_like(P_i), 0.0
    if coloured:
        q = quantization_covariance(Z, b, P_i, count)
        return q.P, q.jitter_counts
    P = count**2 / 12.0 * _covariance(Z, b)
    return P, math.sqrt(max(float((P + P_i)[1, 1]), 0.0)) / count


def sampled_noise_loop(loop: LoopCase, row: np.ndarray, beta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the sample step of the drive at standstill: s[k+1] = Z·s[k] + B·[n_θ[k], n_i[k]].

    The state s is z = [i_q, θ_r, ω_r, θ̂_r, ω̂_r, L̂0, L̂1] of :mod:`control.fdsmc.loop_model`, then
    the held u_q with a computation delay, then, with the q-axis voltage-mismatch estimate (β > 0),
    the estimate d̂ [V] and what its next update reads from this sample: the measured i_q [A], ω̂_r
    [rad/s] and the applied u_q [V]. Each sample, as the kernel's step does: read θ_r + n_θ and
    i_q + n_i; update d̂ ← d̂ + β·((i_q,meas − i_q,model)/(γ_q·G) − d̂) with i_q,model the one-sample
    prediction φ_q·i_q,meas⁻ + γ_q·(G·u_q⁻ − E·ω̂_r⁻) from the last sample's readings
    (:func:`control.fdsmc.fdc.voltage_mismatch`, :func:`control.fdsmc.inverter.predict_currents`);
    u_q = row·z − d̂ of eq. (14) in [1] (the measured i_q in row[0]), applied now or one sample
    later; the plant held over the sample (ZOH-exact) and the observer of eq. (15) updated with
    a_em = H·i_q,meas.

    Parameters
    ----------
    loop : LoopCase     The sampled loop (``loop.f_s``, ``loop.delay``).
    row : numpy.ndarray u_q = row·z of eq. (14) in [1] (:func:`control.fdsmc.loop_model.control_row`) [V per state].
    beta : float        Filter factor T_s/T_dv of the estimate (:func:`control.fdsmc.fdc.mismatch_filter_factor`);
                        0: none [-].

    Returns
    -------
    tuple of numpy.ndarray
        Z (n × n), B (n × 2) and the applied u_q as a row over [s, n_θ, n_i] (n + 2) [V per state].
    """
    if loop.f_s is None:
        raise ValueError("sampled_noise_loop needs a sampled loop: loop.f_s is None")
    f_s = float(loop.f_s)
    sp, c = sampled_parts(loop, f_s), loop.coefficients
    n0 = N_STATES + loop.delay
    n = n0 + (4 if beta > 0.0 else 0)
    e = np.eye(n + 2)  # rows: the states, then n_θ, n_i (a row of e picks one of them)
    y_th, y_i = e[1] + e[n], e[0] + e[n + 1]  # the encoder's and the ADC's readings
    u_c = row[0] * y_i + row[3:N_STATES] @ e[3:N_STATES]
    M = np.zeros((n, n + 2))
    if beta > 0.0:
        dv, y_prev, w_prev, u_prev = n0, n0 + 1, n0 + 2, n0 + 3
        phi_q, gam_q = decay_factors(c.D, 1.0 / f_s)
        i_model = phi_q * e[y_prev] + gam_q * (c.G * e[u_prev] - c.E * e[w_prev])
        M[dv] = (1.0 - beta) * e[dv] + beta * (y_i - i_model) / (gam_q * c.G)
        u_c = u_c - M[dv]
        M[y_prev], M[w_prev] = y_i, e[4]
    u = e[N_STATES] if loop.delay else u_c
    if loop.delay:
        M[N_STATES] = u_c
    if beta > 0.0:
        M[n0 + 3] = u
    M[:3] = sp.Ad @ e[:3] + np.outer(sp.bd, u)
    od = sp.observer
    M[3:N_STATES] = od.Phi @ e[3:N_STATES] + np.outer(od.Gamma * c.H, y_i) + np.outer(od.L, y_th - e[3])
    return M[:, :n], M[:, n:], u


def _covariance(Z: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Steady-state covariance of x[k+1] = Z·x[k] + b·w[k] for unit white w: P = Z·P·Zᵀ + b·bᵀ.

    The states span many orders of magnitude (θ in rad, L̂1 in N·m/s), so Z is balanced first
    (:func:`scipy.linalg.matrix_balance`, Z = D·Z_b·D⁻¹) and the equation solved for P_b = D⁻¹·P·D⁻ᵀ.
    """
    Z_b, D = matrix_balance(Z, permute=False, separate=True)
    s = D[0]
    P_b: FloatArray = solve_discrete_lyapunov(Z_b, np.outer(b / s, b / s))
    return P_b * np.outer(s, s)


def noise_gain_limit(d: LoopCase, count: float, i_noise_rms: float, fraction: float,
                     K_max: float, T_dv: float = 0.0) -> float:
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
    T_dv : float          Filter time of the q-axis voltage-mismatch estimate [s]; 0: none.

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
                             float(i_noise_rms), float(fraction), float(K_max), float(T_dv))


@functools.lru_cache(maxsize=512)
def _noise_gain_limit(case: LoopCase, f_s: float, delay: int, count: float, i_noise_rms: float,
                      fraction: float, K_max: float, T_dv: float) -> float:
    loop = dataclasses.replace(case, f_s=f_s, delay=delay)
    target = fraction * loop.alpha_max / PTP_PER_RMS

    def rms(K: float) -> float:
        return _alpha_dem_rms(loop, K, count, i_noise_rms, T_dv)

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
def _alpha_dem_rms(loop: LoopCase, K: float, count: float, i_noise_rms: float, T_dv: float) -> float:
    """α_dem rms of :func:`noise_gain` on the sloped law [rad/s²] (inf where the loop is unstable).

    The quantization error is taken as white here: :data:`PTP_PER_RMS` was measured against that
    model, and the search evaluates it at every K of its grid.
    """
    with warnings.catch_warnings():  # ill-conditioned only next to the stability limit
        warnings.simplefilter("ignore", LinAlgWarning)
        return noise_gain(loop, "slope", K, count, i_noise_rms, T_dv, coloured=False).alpha_dem_rms


__all__ = ["PTP_PER_RMS", "NoiseGain", "noise_gain", "noise_gain_limit", "sampled_noise_loop"]
