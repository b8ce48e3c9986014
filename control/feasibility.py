"""α_max rules and feasibility checks of a manoeuvre against the real drive's limits.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from control.model import available_voltage, model_coefficients, torque_constant
from control.params import DriveParams, ParameterError


@dataclass(frozen=True)
class AlphaMax:
    """Maximum acceleration magnitude α_max and what it demands of the motor.

    Attributes
    ----------
    alpha_max : float
        Acceleration limit of the outer loop [rad/s²].
    rule : str
        ``"paper"`` (α_max = H·P_r/V_0, section 5 of [1]) or ``"torque_limit"``.
    torque_needed : float
        Torque to accelerate the **total** inertia at α_max against the external load,
        α_max·(J_r + J_L) + |Γ_Le| [N·m].
    torque_ok : bool
        torque_needed ≤ Γ_max.
    """

    alpha_max: float
    rule: str
    torque_needed: float
    torque_ok: bool


def alpha_max(params: DriveParams) -> AlphaMax:
    """α_max under the preset's rule and the torque it needs on the total inertia.

    ``paper``: α_max = H·P_r/V_0 (section 5 of [1]; H from eq. (4)). ``torque_limit``:
    α_max = (Γ_max − |Γ_Le|)/(J_r + J_L), the largest acceleration the motor can hold for the
    whole inertia, eq. (4b), with the external load torque subtracted.

    Parameters
    ----------
    params : DriveParams

    Returns
    -------
    AlphaMax

    Raises
    ------
    ParameterError
        If the torque-limit rule leaves no torque for acceleration.
    """
    m, load = params.motor, params.load
    Gamma_Le = abs(load.Gamma_Le)
    if params.controller.alpha_max_rule == "paper":
        a = model_coefficients(m).H * m.P_r / m.V_0
    else:
        if m.Gamma_max <= Gamma_Le:
            raise ParameterError(
                f"load.Gamma_Le = {load.Gamma_Le:g} N·m leaves no torque for acceleration: "
                f"allowed |Γ_Le| < Γ_max = {m.Gamma_max:g} N·m"
            )
        a = (m.Gamma_max - Gamma_Le) / params.J_total
    needed = a * params.J_total + Gamma_Le
    return AlphaMax(a, params.controller.alpha_max_rule, needed, needed <= m.Gamma_max * (1 + 1e-9))


@dataclass(frozen=True)
class Feasibility:
    """Whether the planned manoeuvre fits the drive (steady-state dq estimates, i_d = 0).

    Attributes
    ----------
    omega_p : float            Peak speed [rad/s].
    omega_b : float            Base speed [rad/s].
    speed_ok : bool            ω_p ≤ ω_b.
    torque_needed : float      Peak torque: α_max·J_total + F_v·ω_p + |Γ_Le| [N·m].
    Gamma_max : float          Motor torque limit [N·m].
    torque_ok : bool           torque_needed ≤ Γ_max.
    i_q_needed : float         Quadrature current for torque_needed [A].
    u_needed_peak : float      |u_dq| at ω_p with torque_needed (end of acceleration) [V].
    u_needed_cruise : float    |u_dq| at ω_p with the cruise torque F_v·ω_p + |Γ_Le| [V].
    u_available : float        √(2/3)·V_0 [V].
    voltage_ok : bool          u_needed_peak ≤ u_available.
    """

    omega_p: float
    omega_b: float
    speed_ok: bool
    torque_needed: float
    Gamma_max: float
    torque_ok: bool
    i_q_needed: float
    u_needed_peak: float
    u_needed_cruise: float
    u_available: float
    voltage_ok: bool


def dq_voltage(params: DriveParams, omega_r: float, torque: float) -> float:
    """Steady-state |u_dq| [V] at speed ω_r [rad/s] and torque [N·m] with i_d = 0, eqs. (1)–(2).

    u_d = −p·ω_r·L_q·i_q, u_q = R_s·i_q + p·ω_r·Ψ_PM (di/dt = 0).
    """
    m = params.motor
    i_q = torque / torque_constant(m)
    u_d = -m.p * omega_r * m.L_q * i_q
    u_q = m.R_s * i_q + m.p * omega_r * m.psi_pm
    return math.hypot(u_d, u_q)


def feasibility(params: DriveParams, alpha: AlphaMax, omega_p: float) -> Feasibility:
    """Check peak speed, torque and voltage of a planned manoeuvre.

    Parameters
    ----------
    params : DriveParams
    alpha : AlphaMax
    omega_p : float
        Peak speed of eq. (60) in [1] [rad/s].

    Returns
    -------
    Feasibility
    """
    m, load = params.motor, params.load
    cruise = load.F_v * omega_p + abs(load.Gamma_Le)
    peak = alpha.alpha_max * params.J_total + cruise
    u_peak = dq_voltage(params, omega_p, peak)
    u_avail = available_voltage(m)
    return Feasibility(
        omega_p=omega_p,
        omega_b=m.omega_b,
        speed_ok=omega_p <= m.omega_b,
        torque_needed=peak,
        Gamma_max=m.Gamma_max,
        torque_ok=peak <= m.Gamma_max,
        i_q_needed=peak / torque_constant(m),
        u_needed_peak=u_peak,
        u_needed_cruise=dq_voltage(params, omega_p, cruise),
        u_available=u_avail,
        voltage_ok=u_peak <= u_avail,
    )
