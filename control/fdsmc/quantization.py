"""The encoder's quantization error as coloured noise: its autocorrelation from the rotor's own motion.

Holding θ_dem, the controller reads θ_r in whole counts Δ = 2π/cpr, so its innovation carries the
error n_θ = Q(θ_r) − θ_r, a sawtooth of θ_r. The white model of :func:`control.fdsmc.noise.noise_gain`
(variance Δ²/12, uncorrelated from sample to sample) holds where the rotor crosses many counts per
sample. On a fine encoder it does not: the rotor moves a tenth of a count per sample, and the error
is correlated over tens of samples.

Writing the sawtooth as its Fourier series, n_θ = Σ_{n≠0} Δ/(2πjn)·exp(j2πnθ_r/Δ), and taking the
rotor's displacement over m samples, d_m = θ_r[k+m] − θ_r[k], as Gaussian with variance s_m² and the
count's phase as uniform, the autocorrelation is

    R(m) = Σ_{n≥1} Δ²/(2π²n²) · exp(−2π²n²·s_m²/Δ²),

which is Δ²/12 at m = 0 (Σ 1/n² = π²/6) and falls as the rotor wanders over a count. The stationary
loop x[k+1] = Z·x[k] + b·n_θ[k] then has the covariance

    P = R(0)·P₀ + Σ_{m≥1} R(m)·(Zᵐ·P₀ + P₀·Zᵐᵀ),     P₀ = Z·P₀·Zᵀ + b·bᵀ,

and s_m² = 2·(P_θθ − (Zᵐ·P)_θθ) comes from the same covariance, the current noise's (the dither that
moves the rotor) plus the quantization's own: a fixed point, solved by iteration.

Where the rotor's jitter is under one count the rotor crosses count edges only through the loop's own
reaction to the last crossing, not as the Gaussian process assumed above; the error then decorrelates
at the loop's own rate, and the white model is the better one (on the shipped real presets at 2¹⁷
counts: white 0.89–1.09 × the simulated ripple, coloured 1.3–1.6 ×; at 2²⁰ counts, with 0.9–21 counts
of jitter: white 1.06–1.32 ×, coloured 1.01–1.10 ×, ``tests/test_noise_tdv.py``). The covariance returned
blends the two by the jitter σ_θ/Δ: weight min(1, (σ_θ/Δ)²) on the coloured one, so the prediction is
continuous in the encoder's resolution.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import matrix_balance, solve_discrete_lyapunov

#: Index of the rotor angle θ_r in the loop's state (:mod:`control.fdsmc.loop_model`).
THETA = 1
#: Relative size of the loop's slowest mode's last term kept in the lag sums [-].
TAIL = 1e-10
#: Longest lag summed [samples] (a loop slower than this is summed up to it).
MAX_LAGS = 2**17
#: Fixed-point iterations of the rotor's jitter and their relative tolerance [-].
ITERATIONS, TOLERANCE = 12, 1e-4


@dataclass(frozen=True)
class Quantization:
    """Covariance of the loop's state from the encoder's quantization error.

    Attributes
    ----------
    P : numpy.ndarray      Covariance of the state from n_θ alone [state units²].
    jitter_counts : float  RMS of the rotor angle θ_r, all noise included, in counts σ_θ/Δ [-].
    weight : float         Weight of the coloured model in ``P`` [-] (1 − weight on the white one).
    """

    P: np.ndarray
    jitter_counts: float
    weight: float


def autocorrelation(s2: np.ndarray, count: float) -> np.ndarray:
    """R(m) [rad²] of the sawtooth error for Gaussian displacements of variance ``s2`` [rad²] (module doc).

    With x = 2π²·s²/Δ², R = Δ²/(2π²)·S(x), S(x) = Σ_{n≥1} exp(−n²·x)/n². For x ≤ 1 the series is slow
    and S(x) = π²/6 − √(π·x) + x/2 instead (Poisson summation of the theta function; the terms left
    out are O(exp(−π²/x)), below 1e-4 of S there); above, six terms of the series (exp(−36) left out).
    """
    x = 2.0 * math.pi**2 * np.asarray(s2, dtype=float) / count**2
    small = math.pi**2 / 6.0 - np.sqrt(math.pi * np.minimum(x, 1.0)) + np.minimum(x, 1.0) / 2.0
    n = np.arange(1, 7, dtype=float)
    large = (np.exp(-np.outer(np.maximum(x, 1.0), n * n)) / (n * n)).sum(axis=-1)
    return np.where(x <= 1.0, small, large) * count**2 / (2.0 * math.pi**2)


def quantization_covariance(Z: np.ndarray, b: np.ndarray, P_dither: np.ndarray, count: float) -> Quantization:
    """Covariance of x[k+1] = Z·x[k] + b·n_θ[k] for the coloured quantization error of a count Δ.

    Parameters
    ----------
    Z : numpy.ndarray         Stable sample step of the loop (n × n) [-].
    b : numpy.ndarray         Input column of n_θ (n) [state units per rad].
    P_dither : numpy.ndarray  Covariance of the state from the other noise (the current noise) [state units²].
    count : float             Encoder count Δ = 2π/cpr [rad]; > 0.

    Returns
    -------
    Quantization
    """
    Z_b, (s, _) = matrix_balance(Z, permute=False, separate=True)
    P0 = solve_discrete_lyapunov(Z_b, np.outer(b / s, b / s))
    white = count**2 / 12.0 * P0
    lam, V = np.linalg.eig(Z_b)
    Vi = np.linalg.inv(V)
    rho = float(np.max(np.abs(lam)))
    lags = int(min(MAX_LAGS, max(64, math.ceil(math.log(TAIL) / math.log(rho))))) if rho > 0.0 else 64
    powers = np.cumprod(np.broadcast_to(lam, (lags, lam.size)), axis=0)  # λⱼᵐ, m = 1 … lags
    Pd = P_dither / np.outer(s, s)
    Pq, weight, jitter = white, 0.0, 0.0
    for _ in range(ITERATIONS):
        P = Pd + Pq
        corr = (powers @ (V[THETA, :] * (Vi @ P)[:, THETA])).real  # (Zᵐ·P)_θθ
        s2 = np.maximum(2.0 * (P[THETA, THETA] - corr), 0.0) * s[THETA] ** 2
        X = ((V * (autocorrelation(s2, count) @ powers)) @ Vi @ P0).real  # Σ R(m)·Zᵐ·P₀
        coloured = white + X + X.T
        jitter = math.sqrt(max(P[THETA, THETA], 0.0)) * s[THETA] / count
        weight = min(1.0, jitter**2)
        new = weight * coloured + (1.0 - weight) * white
        done = abs(new[THETA, THETA] - Pq[THETA, THETA]) <= TOLERANCE * abs(new[THETA, THETA])
        Pq = new
        if done:
            break
    return Quantization(Pq * np.outer(s, s), jitter, weight)


__all__ = ["Quantization", "autocorrelation", "quantization_covariance"]
