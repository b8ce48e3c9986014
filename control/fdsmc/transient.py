"""Transient of the inner loops: how far the true acceleration overshoots a step of α_dem.

When the outer loop of [1] switches α_dem from 0 to ±α_max (start of acceleration, eq. (45)
saturated), the FDC acceleration loop of eq. (13) and the load-torque observer of eq. (15) must
also learn the load inertia J_L, which the controller does not know (it uses J_r only, eq. (7)):
until L̂ has caught up, the delivered acceleration — and so the motor torque — overshoots the
demand. The linearised loop of :mod:`control.fdsmc.loop_analysis` (continuous, or sampled with the
drive's f_s and computation delay) gives the overshoot factor η ≥ 1 exactly, so the torque-limit
rule for α_max can leave room for it instead of a fudge factor.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.common.discrete import zoh
from pmsm_commissioning.control.fdsmc.loop_model import (
    LoopModel,
    continuous_matrix,
    discrete_matrix,
    fdc_input_gain,
    fdc_row,
    sampled_parts,
)

#: Samples per fastest designed time constant for the continuous step response [-].
_STEPS_PER_TAU = 40
#: Most steps of the continuous step response [-].
_MAX_STEPS = 3000
#: Most samples of the sampled step response [-]: ≈ 2 s of CPU at ≈ 50 ns per sample.
MAX_RESPONSE_SAMPLES = 40_000_000
#: Samples of the step response computed at once [-] (memory ≈ rows × states × 8 B).
_BLOCK = 4096


def _horizon(lm: LoopModel) -> float:
    """Step-response horizon: 6 times the slowest of T_si, T_sα, T_so [s]."""
    return 6.0 * max(lm.T_si, lm.T_salpha, lm.T_so)


def _step_system(lm: LoopModel, f_s: float | None, delay: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(Φ, γ, h): z_{k+1} = Φ·z_k + γ·α_dem of the loop with the outer law open (α_dem input)."""
    c = lm.coefficients
    row = fdc_row(c, lm.T_salpha, 0.0, 0.0)
    g_in = fdc_input_gain(c, lm.T_salpha)
    if f_s is not None:
        sp = sampled_parts(lm, f_s)
        Z = discrete_matrix(sp, c.H, row, delay)
        gamma = np.zeros(Z.shape[0])
        if delay:
            gamma[-1] = g_in  # the demand reaches the held voltage one sample later
        else:
            gamma[:3] = sp.bd * g_in
        return Z, gamma, 1.0 / f_s
    A = continuous_matrix(lm, row)
    b = np.zeros(A.shape[0])
    b[0] = c.G * g_in
    tau = min(lm.T_si, lm.T_salpha, lm.T_so) / 3.0
    h = max(tau / _STEPS_PER_TAU, _horizon(lm) / _MAX_STEPS)
    Phi, gamma = zoh(A, b, h)
    return Phi, gamma, h


def acceleration_overshoot(lm: LoopModel, f_s: float | None, delay: int = 0) -> float:
    """Peak of the true acceleration dω_r/dt after a unit step of α_dem [-] (η ≥ 1).

    Parameters
    ----------
    lm : LoopModel
        Model, parameters (J_r + J_L, F_v) and observer gains.
    f_s : float or None
        Controller sample rate [Hz]; None for the continuous implementation.
    delay : int
        Computation delay [samples].

    Returns
    -------
    float
        max_t α(t)/α_dem over 6 times the slowest of T_si, T_sα, T_so; 1 if it never overshoots.
        ``inf`` if the loop is unstable (the sample-rate check reports that case).

    Notes
    -----
    α = (J_r·H·i_q − F_v·ω_r)/(J_r + J_L), eq. (4b) in [1] at Γ_Le = 0. The torque the motor must
    deliver at the start of an acceleration is then ≈ η·α_max·(J_r + J_L) plus friction and load.
    Cached on the loop model (a new T_m, K or load step on the same drive reuses η).
    """
    return _acceleration_overshoot(lm.model(), None if f_s is None else float(f_s), int(delay))


@functools.lru_cache(maxsize=256)
def _acceleration_overshoot(lm: LoopModel, f_s: float | None, delay: int) -> float:
    Phi, gamma, h = _step_system(lm, f_s, delay)
    if np.max(np.abs(np.linalg.eigvals(Phi))) >= 1.0 + 1e-6:  # θ, ω: marginal (open outer loop)
        return math.inf
    n = int(math.ceil(_horizon(lm) / h)) + delay + 2
    if n > MAX_RESPONSE_SAMPLES:  # sampled: n = 6·max(T_si, T_sα, T_so)·f_s
        raise ParameterError(
            f"controller.f_s = {f_s:g} Hz with the slowest settling time max(T_si, T_sα, T_so) = "
            f"{_horizon(lm) / 6.0:g} s needs {n:.3g} samples of the inner-loop step response; allowed "
            f"≤ {MAX_RESPONSE_SAMPLES:.3g} (lower f_s or that settling time)")
    w = np.zeros(Phi.shape[0])
    w[0], w[2] = lm.J_r * lm.coefficients.H / lm.J_total, -lm.F_v / lm.J_total
    return max(1.0, step_peak(Phi, gamma, w, n))


def step_peak(Phi: np.ndarray, gamma: np.ndarray, w: np.ndarray, n: int) -> float:
    """Return max over k = 1 … n of w·z_k, where z_{k+1} = Φ·z_k + γ from z_0 = 0.

    z_k = Σ_{j<k} Φ^j·γ. The terms of the first block (j < B, B a power of 2) are made by doubling:
    rows j ≥ m are Φ^m times rows j − m, about log₂ B matrix products instead of B steps. Each next
    block's terms are Φ^B times the last block's, and the running sum carries z_k across blocks.
    Memory is bounded by the block (:data:`_BLOCK` rows).
    """
    terms, Phi_m = gamma[None, :], Phi  # invariant: Phi_m = Φ^len(terms)
    while len(terms) < min(n, _BLOCK):
        terms = np.vstack([terms, terms @ Phi_m.T])
        Phi_m = Phi_m @ Phi_m
    z_end, peak, done = np.zeros_like(gamma), -math.inf, 0
    while done < n:
        z = z_end + np.cumsum(terms[: n - done], axis=0)
        peak = max(peak, float(np.max(z @ w)))
        z_end, done = z[-1], done + len(z)
        terms = terms @ Phi_m.T
    return peak


__all__ = ["MAX_RESPONSE_SAMPLES", "acceleration_overshoot", "step_peak"]
