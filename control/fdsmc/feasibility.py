"""α_max rules and feasibility checks of a manoeuvre against the real drive's limits.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.model import available_voltage, model_coefficients, torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import peak_speed, shortest_manoeuvre_time
from pmsm_commissioning.control.fdsmc.profile_energy import min_energy_alpha

#: Relative precision of the steady-state limit checks [-]: the model's torque and voltage estimates
#: are not more exact than this, so a peak within it of a limit is not reported as exceeding it.
LIMIT_TOLERANCE = 0.005


def exceeds(value: float, limit: float) -> bool:
    """Return True when ``value`` exceeds ``limit`` by more than :data:`LIMIT_TOLERANCE` (relative)."""
    return value > limit * (1.0 + LIMIT_TOLERANCE)


def torque_limit(params: DriveParams) -> float:
    """Torque the drive can deliver [N·m]: Γ_max, or less where the inverter's i_max caps i_q.

    Γ = (3/2)·p·Ψ_PM·i_q at i_d = 0 (eq. (5) in [1]); ``controller.i_max`` = 0 means no inverter limit.
    """
    g = params.motor.Gamma_max
    i_max = params.controller.i_max
    return min(g, torque_constant(params.motor) * i_max) if i_max > 0.0 else g


def current_limit(params: DriveParams) -> float:
    """Return the hard limit on |i_dq| the drive enforces [A]; 0 = none (the paper, ``controller.i_max`` = 0).

    A drive set up for its motor never commands more current than the motor's peak torque needs:
    min(i_max, Γ_max/K_t) with K_t = (3/2)·p·Ψ_PM of eq. (5) in [1] (i_d = 0). Where K_t·i_max > Γ_max
    the motor's torque, not the inverter, sets the limit.
    """
    i_max = params.controller.i_max
    return min(i_max, params.motor.Gamma_max / torque_constant(params.motor)) if i_max > 0.0 else 0.0


def speed_limit(params: DriveParams) -> float:
    """Return the largest allowed |ω_r| [rad/s]: the motor's maximum speed ``limits.omega_max``, else ω_b."""
    return params.limits.omega_max or params.motor.omega_b


def voltage_limit(params: DriveParams) -> float:
    """Largest |u_dq| [V]: V_dc/√3 of the inverter (space-vector limit) when given, else √(2/3)·V_0."""
    V_dc = params.controller.V_dc
    return V_dc / math.sqrt(3.0) if V_dc > 0.0 else available_voltage(params.motor)


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
        Torque to accelerate the **total** inertia at α_max against the external load, including
        the inner loops' overshoot: η·α_max·(J_r + J_L) + |Γ_Le| [N·m].
    torque_ok : bool
        torque_needed ≤ the drive's torque limit (Γ_max, or i_max's torque), within the tolerance.
    overshoot : float
        η, peak of the true acceleration over a step of α_dem (:mod:`control.fdsmc.transient`) [-].
    """

    alpha_max: float
    rule: str
    torque_needed: float
    torque_ok: bool
    overshoot: float = 1.0


def alpha_max(params: DriveParams, overshoot: float = 1.0) -> AlphaMax:
    """α_max under the preset's rule and the torque it needs on the total inertia.

    ``paper``: α_max = H·P_r/V_0 (section 5 of [1]; H from eq. (4)). ``min_energy``: the α within
    the torque limit that minimises the profile's copper + friction loss
    (:func:`control.fdsmc.profile_energy.min_energy_alpha`). ``torque_limit``: the
    largest α_max whose peak torque η·α_max·(J_r + J_L) + F_v·ω_p + |Γ_Le| stays within the drive's
    torque limit Γ_lim (:func:`torque_limit`), eq. (4b) with the inner loops' overshoot η, the
    friction at the peak speed ω_p of eq. (60) (itself a function of α_max) and the external load.

    Parameters
    ----------
    params : DriveParams
    overshoot : float
        η ≥ 1 of :func:`control.fdsmc.transient.acceleration_overshoot` [-].

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
    eta = overshoot if math.isfinite(overshoot) else 1.0
    rule = params.controller.alpha_max_rule
    if rule == "paper":
        a = model_coefficients(m).H * m.P_r / m.V_0
    else:
        a = _torque_limited_alpha(params, eta)
        if rule == "min_energy":  # below the torque limit where copper + friction are least
            a = min_energy_alpha(params, a)
    needed = eta * a * params.J_total + Gamma_Le
    return AlphaMax(a, params.controller.alpha_max_rule, needed, not exceeds(needed, torque_limit(params)), eta)


def _torque_limited_alpha(params: DriveParams, eta: float) -> float:
    """Largest α [rad/s²] with η·α·J + F_v·ω_p(α) + |Γ_Le| ≤ Γ_lim (bisection to 1e-9)."""
    lim, Gamma_Le, J = torque_limit(params), abs(params.load.Gamma_Le), params.J_total
    if lim <= Gamma_Le:
        raise ParameterError(
            f"load.Gamma_Le = {params.load.Gamma_Le:g} N·m leaves no torque for acceleration: "
            f"allowed |Γ_Le| < the drive's torque limit {lim:g} N·m (Γ_max, i_max)"
        )
    th, T_m, F_v = params.manoeuvre.theta_dem, params.manoeuvre.T_m, params.load.F_v

    def peak(a: float) -> float:
        w_p = peak_speed(th, a, max(T_m, shortest_manoeuvre_time(th, a)))
        return eta * a * J + F_v * w_p + Gamma_Le

    lo, hi = 0.0, (lim - Gamma_Le) / (eta * J)
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if peak(mid) <= lim else (lo, mid)
    return lo


@dataclass(frozen=True)
class Feasibility:
    """Whether the planned manoeuvre fits the drive (steady-state dq estimates, i_d = 0).

    Attributes
    ----------
    omega_p : float            Peak speed [rad/s].
    omega_b : float            Speed limit [rad/s]: the maximum speed n_max, else the base speed ω_b.
    speed_ok : bool            ω_p ≤ the speed limit.
    torque_needed : float      Peak torque: η·α_max·J_total + F_v·ω_p + |Γ_Le| [N·m].
    Gamma_max : float          The drive's torque limit, Γ_max or i_max's torque [N·m].
    torque_ok : bool           torque_needed ≤ Gamma_max (within LIMIT_TOLERANCE).
    i_q_needed : float         Quadrature current for torque_needed [A].
    u_needed_peak : float      |u_dq| at ω_p with torque_needed (end of acceleration) [V].
    u_needed_cruise : float    |u_dq| at ω_p with the cruise torque F_v·ω_p + |Γ_Le| [V].
    u_available : float        V_dc/√3, or √(2/3)·V_0 without an inverter limit [V].
    voltage_ok : bool          u_needed_peak ≤ u_available (within LIMIT_TOLERANCE).
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
    peak = alpha.overshoot * alpha.alpha_max * params.J_total + cruise
    lim = torque_limit(params)
    u_peak = dq_voltage(params, omega_p, peak)
    u_avail = voltage_limit(params)
    return Feasibility(
        omega_p=omega_p,
        omega_b=speed_limit(params),
        speed_ok=not exceeds(omega_p, speed_limit(params)),
        torque_needed=peak,
        Gamma_max=lim,
        torque_ok=not exceeds(peak, lim),
        i_q_needed=peak / torque_constant(m),
        u_needed_peak=u_peak,
        u_needed_cruise=dq_voltage(params, omega_p, cruise),
        u_available=u_avail,
        voltage_ok=not exceeds(u_peak, u_avail),
    )
