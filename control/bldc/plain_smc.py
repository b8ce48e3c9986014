"""Comparator 2: plain tanh sliding-mode speed control without the integral term.

The surface of eq. (16) in [2] without its integral, σ_ω = ε_ω, through the same tanh:
T* = T_max·tanh(k_ω·ε_ω). In steady state the torque T_eq = B·ω + T_L of eq. (21) needs
tanh(k_ω·ε) = T_eq/T_max, i.e. a speed error ε_ss = atanh(T_eq/T_max)/k_ω ≠ 0 — the
"non-zero steady-state error" of the analog switching function that section V of [2] cites.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math


def plain_torque_reference(eps: float, k_omega: float, T_max: float) -> float:
    """T* = T_max·tanh(k_ω·ε_ω) [N·m].

    Parameters
    ----------
    eps : float      Speed error ε_ω = ω* − ω [rad/s].
    k_omega : float  Gain [s/rad].
    T_max : float    Torque limit [N·m].
    """
    return T_max * math.tanh(k_omega * eps)


def steady_state_error(T_eq: float, k_omega: float, T_max: float) -> float:
    """ε_ss = atanh(T_eq/T_max)/k_ω, the speed error the plain law needs to hold T_eq [rad/s].

    Parameters
    ----------
    T_eq : float     Equivalent control B·ω + T_L, eq. (21) in [2] [N·m]; |T_eq| < T_max.
    k_omega : float  Gain [s/rad].
    T_max : float    Torque limit [N·m].
    """
    return math.atanh(T_eq / T_max) / k_omega
