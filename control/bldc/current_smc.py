"""First-order sliding-mode current controllers C_dx, C_qx with tanh, eqs. (13)–(14) in [2].

Eq. (14) prints v = tanh(k_I·σ): a dimensionless number in (−1, 1), not a voltage. The law is
implemented as v = V_max·tanh(k_I·σ), scaled by the voltage the inverter can deliver on the
dq_x axis, V_max = V_dc/(√2·a_x): the largest power-invariant αβ vector of a space-vector
modulated two-level inverter is V_dc/√2, and eq. (4) maps a dq_x vector of length V to an αβ
vector of length a_x·V. The product V_max·k_I is then the loop's proportional gain [V/A], the
same on every axis and at every angle.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

SQRT2 = math.sqrt(2.0)


def tanh_current_voltage(i_ref: float, i: float, k_I: float, V_max: float) -> float:
    """Axis voltage v = V_max·tanh(k_I·σ) with σ = i* − i, eqs. (13)–(14) in [2] [V].

    Parameters
    ----------
    i_ref : float  Current reference i*_dx or i*_qx [A].
    i : float      Measured current i_dx or i_qx [A].
    k_I : float    Sliding-mode gain [1/A].
    V_max : float  Available axis voltage [V].
    """
    return V_max * math.tanh(k_I * (i_ref - i))


def available_voltage_dqx(V_dc: float, a_x: float) -> float:
    """V_max = V_dc/(√2·a_x), the dq_x voltage that maps onto the inverter's limit [V].

    Parameters
    ----------
    V_dc : float  DC-link voltage [V].
    a_x : float   dq_x axis size, eq. (7) in [2] [-].
    """
    return V_dc / (SQRT2 * a_x)


def limit_vector(v_alpha: float, v_beta: float, V_lim: float) -> tuple[float, float]:
    """Scale (v_α, v_β) radially onto the circle |v| ≤ V_lim when it lies outside [V]."""
    mag = math.hypot(v_alpha, v_beta)
    if mag <= V_lim:
        return v_alpha, v_beta
    return v_alpha * V_lim / mag, v_beta * V_lim / mag


@dataclass(frozen=True)
class CurrentLoopDesign:
    """Small-signal figures of the sampled tanh current loop.

    Attributes
    ----------
    V_lim : float          Inverter voltage limit |v_αβ| ≤ V_dc/√2 [V].
    gain : float           Proportional gain near σ = 0 in the αβ frame, k_I·V_dc/√2 [V/A].
    bandwidth : float      Continuous-time closed-loop bandwidth gain/(L_s − M_s) [rad/s].
    discrete_gain : float  gain/(f_s·(L_s − M_s)): the sampled loop converges for < 2 and
                           without oscillation for ≤ 1 [-].
    """

    V_lim: float
    gain: float
    bandwidth: float
    discrete_gain: float


def current_loop_design(k_I: float, V_dc: float, f_s: float, L: float) -> CurrentLoopDesign:
    """Linearised tanh current loop: i(k+1) − i* = (1 − g)·(i(k) − i*), g = k_I·V_dc/(√2·f_s·L).

    Parameters
    ----------
    k_I : float   Sliding-mode gain [1/A].
    V_dc : float  DC-link voltage [V].
    f_s : float   Sample rate [Hz].
    L : float     L_s − M_s [H].
    """
    V_lim = V_dc / SQRT2
    gain = k_I * V_lim
    return CurrentLoopDesign(V_lim, gain, gain / L, gain / (f_s * L))
