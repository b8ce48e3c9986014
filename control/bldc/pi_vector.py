"""Comparator 3: conventional sinusoidal dq vector control with PI loops.

The controller assumes a sinusoidal machine: Park transform with φ = θ_e and a_x = 1 (what
eqs. (7)–(8) of [2] give for a sine wave), torque constant from the *fundamental* of the ideal
trapezoid, PI speed and current loops with conditional-integration anti-windup. On a
trapezoidal machine the 5th and 7th EMF harmonics meet sinusoidal currents and give a 6th-
harmonic torque ripple, which is what the comparison shows.

Gains are not free choices but matched to the sliding-mode drive so that only the structure
differs: near zero error C_ω of eq. (16) is a PI with K_p = T_max·k_ω and K_i = K_p·λ_0, and
the tanh current law of eq. (14) has the proportional gain k_I·V_dc/√2; the current PI keeps
that gain and cancels the winding pole (K_i = K_p·R_s/(L_s − M_s)).

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.bldc.params import BldcParams


def pi_output(integ: float, err: float, K_p: float, u_lim: float) -> float:
    """Return u = clamp(K_p·err + integ, ±u_lim) (units of u).

    Parameters
    ----------
    integ : float  Integrator state (units of u).
    err : float    Error (units of the loop's input).
    K_p : float    Proportional gain.
    u_lim : float  Output limit (> 0).
    """
    u = K_p * err + integ
    return max(-u_lim, min(u_lim, u))


def pi_integrate(integ: float, err: float, K_p: float, K_i: float, T_s: float, u_lim: float) -> float:
    """Integrator update with conditional integration: hold when saturated and still pushing.

    Parameters
    ----------
    integ : float  Integrator state (units of u).
    err : float    Error.
    K_p, K_i : float  Proportional gain, integral gain [units of u per error, per error·s].
    T_s : float    Sample time [s].
    u_lim : float  Output limit.
    """
    u = K_p * err + integ
    if (u > u_lim and err > 0.0) or (u < -u_lim and err < 0.0):
        return integ
    return integ + K_i * T_s * err


@dataclass(frozen=True)
class PiVectorDesign:
    """Gains of the sinusoidal dq PI drive.

    Attributes
    ----------
    Phi_1 : float    Fundamental amplitude of the ideal trapezoid, (4/π)·(sin 30°/30°)·Φ_M [Wb].
    K_T : float      Assumed torque constant n_pp·√(3/2)·Φ_1 [N·m/A].
    K_p_i : float    Current PI proportional gain [V/A].
    K_i_i : float    Current PI integral gain [V/(A·s)].
    K_p_w : float    Speed PI proportional gain [N·m·s/rad].
    K_i_w : float    Speed PI integral gain [N·m/rad].
    """

    Phi_1: float
    K_T: float
    K_p_i: float
    K_i_i: float
    K_p_w: float
    K_i_w: float


def pi_vector_design(params: BldcParams) -> PiVectorDesign:
    """PI gains matched to the sliding-mode drive's small-signal gains (module docstring)."""
    m, g = params.machine, params.gains
    ramp = math.pi / 6.0
    Phi_1 = 4.0 / math.pi * math.sin(ramp) / ramp * m.Phi_m
    K_p_i = g.k_I * params.inverter.V_dc / math.sqrt(2.0)
    K_p_w = g.T_max * g.k_omega
    return PiVectorDesign(Phi_1, m.n_pp * math.sqrt(1.5) * Phi_1, K_p_i,
                          K_p_i * m.R_s / m.L_s_minus_M_s, K_p_w, K_p_w * g.lambda_0)
