"""Minimum-energy velocity-time profile of section 4.2–4.3 in [1].

With T_d = 3·T_a the profile is: constant acceleration α_max for T_a, cruise at ω_p for
T_m − 4·T_a, exponential decay ω_p·exp(−t/T_a) (T_d/3 = T_a) while sliding along the −1/T_c line.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError

#: (5 + 2·e⁻³), the factor of T_a in eqs. (52), (57) and (60) of [1] [-].
C_57 = 5.0 + 2.0 * math.exp(-3.0)
#: (19 + 3·e⁻⁶)/6, the factor of T_a in the numerator of eq. (52) of [1] [-].
C_52 = (19.0 + 3.0 * math.exp(-6.0)) / 6.0


@dataclass(frozen=True)
class VelocityProfile:
    """Parameters of the minimum-energy profile, eqs. (57)–(60) in [1].

    Attributes
    ----------
    delta_theta : float
        Demanded position change Δθ_rdem, eq. (48) [rad].
    omega_p : float
        Peak (cruise) speed magnitude, eq. (60) [rad/s].
    T_a : float
        Acceleration time ω_p/α_max, eq. (58) [s].
    T_d : float
        Deceleration time 3·T_a [s].
    T_c : float
        Sliding-mode time constant of the sloped boundary, eq. (59) or the user's value [s].
    T_m_min : float
        Shortest feasible manoeuvre time for Δθ and α_max (root of eq. (60) vanishes) [s].
    feasible : bool
        Whether T_m ≥ T_m_min.
    """

    delta_theta: float
    omega_p: float
    T_a: float
    T_d: float
    T_c: float
    T_m_min: float
    feasible: bool


def shortest_manoeuvre_time(delta_theta: float, alpha_max: float) -> float:
    """T_m,min = sqrt(2·(5 + 2e⁻³)·|Δθ|/α_max), where the discriminant of eq. (60) in [1] is 0.

    Parameters
    ----------
    delta_theta : float
        Position change [rad].
    alpha_max : float
        Maximum acceleration [rad/s²].

    Returns
    -------
    float
        Shortest manoeuvre time [s].
    """
    return math.sqrt(2.0 * C_57 * abs(delta_theta) / alpha_max)


def infeasible_T_m(T_m: float, T_m_min: float, delta_theta: float, alpha_max: float) -> str:
    """Return the one message for a manoeuvre time below T_m,min (T_m, T_m,min [s], Δθ [rad], α_max [rad/s²])."""
    return (f"manoeuvre.T_m = {T_m:g} s is infeasible: allowed ≥ T_m,min = {T_m_min:.4g} s "
            f"for Δθ = {delta_theta:g} rad at α_max = {alpha_max:.5g} rad/s²")


def peak_speed(delta_theta: float, alpha_max: float, T_m: float) -> float:
    """Peak speed ω_p of eq. (60) in [1] (the root giving ω_p = 0 for Δθ = 0).

    Parameters
    ----------
    delta_theta : float
        Position change [rad].
    alpha_max : float
        Maximum acceleration [rad/s²].
    T_m : float
        Manoeuvre time [s].

    Returns
    -------
    float
        ω_p [rad/s].

    Raises
    ------
    ParameterError
        If T_m < T_m,min (no real root), naming T_m,min.
    """
    disc = (alpha_max * T_m) ** 2 - 2.0 * C_57 * alpha_max * abs(delta_theta)
    if -1e-12 * (alpha_max * T_m) ** 2 <= disc < 0.0:
        disc = 0.0  # T_m = T_m,min up to rounding: the double root
    if disc < 0.0:
        t_min = shortest_manoeuvre_time(delta_theta, alpha_max)
        raise ParameterError(infeasible_T_m(T_m, t_min, delta_theta, alpha_max))
    # Numerically stable form of (αT − √disc)/c: multiply by the conjugate.
    return 2.0 * alpha_max * abs(delta_theta) / (alpha_max * T_m + math.sqrt(disc))


def velocity_profile(
    delta_theta: float, alpha_max: float, T_m: float, T_c: float | str = "T_a"
) -> VelocityProfile:
    """Profile parameters for a rest-to-rest manoeuvre, eqs. (57)–(60) in [1].

    An infeasible T_m (< T_m,min) is reported with ``feasible=False`` and the profile of the
    shortest feasible manoeuvre, so that callers can still show T_m,min.

    Parameters
    ----------
    delta_theta : float
        Position change [rad].
    alpha_max : float
        Maximum acceleration [rad/s²].
    T_m : float
        Manoeuvre time [s].
    T_c : float or "T_a"
        Sliding-mode time constant [s]; ``"T_a"`` applies eq. (59).

    Returns
    -------
    VelocityProfile
    """
    T_m_min = shortest_manoeuvre_time(delta_theta, alpha_max)
    feasible = T_m >= T_m_min
    omega_p = peak_speed(delta_theta, alpha_max, max(T_m, T_m_min))
    T_a = omega_p / alpha_max
    return VelocityProfile(
        delta_theta=delta_theta,
        omega_p=omega_p,
        T_a=T_a,
        T_d=3.0 * T_a,
        T_c=T_a if T_c == "T_a" else float(T_c),
        T_m_min=T_m_min,
        feasible=feasible,
    )


def profile_position_change(omega_p: float, T_a: float, T_d: float, T_m: float) -> float:
    """Position change of the profile, eq. (49) in [1] [rad].

    Parameters
    ----------
    omega_p : float  Peak speed [rad/s].
    T_a : float      Acceleration time [s].
    T_d : float      Deceleration time [s].
    T_m : float      Manoeuvre time [s].
    """
    return omega_p * (T_m - 0.5 * T_a - (2.0 + math.exp(-3.0)) * T_d / 3.0)


def friction_energy_eq52(F_v: float, delta_theta: float, T_a: float, T_m: float) -> float:
    """Frictional energy of the FDSMC profile, eq. (52) in [1] [J].

    Parameters
    ----------
    F_v : float          Viscous friction [N·m·s/rad].
    delta_theta : float  Position change [rad].
    T_a : float          Acceleration time [s].
    T_m : float          Manoeuvre time [s].
    """
    A = F_v * delta_theta**2
    return A * (T_m - C_52 * T_a) / (T_m - 0.5 * C_57 * T_a) ** 2
