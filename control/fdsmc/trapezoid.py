"""The same move for a stock drive: a symmetric trapezoid, from its timing or from a planner's limits.

A stock drive (ODrive, moteus, an industrial servo) plans a trapezoidal speed profile and tracks it
with its own loops (:mod:`control.stock.loops`). This module gives the trapezoid:

* the symmetric trapezoid at acceleration α whose cruise ends the move at T_m
  (:func:`trapezoid_timing`, :func:`trapezoid_samples`):

      T_a = (T_m − √(T_m² − 4·|Δθ|/α)) / 2,   ω_c = α·T_a,   |Δθ| = ω_c·(T_m − T_a);

* the move a drive's planner makes from its speed and acceleration limits (:func:`trapezoid_from_limits`);
* its ideal-tracking friction integral ∫ω² dt = ω_c²·(T_m − 4·T_a/3) (:func:`trapezoid_omega_square_integral`);
* :class:`CascadeGains`, a P–PI position/speed cascade with inertia feed-forward and the parallel PID
  of the same law, the form the drive files carry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError


@dataclass(frozen=True)
class TrapezoidTiming:
    """A symmetric rest-to-rest trapezoid.

    Attributes
    ----------
    delta_theta : float  Move [rad] (signed).
    alpha : float        Acceleration and deceleration magnitude [rad/s²].
    T_a : float          Acceleration (and deceleration) time [s].
    T_m : float          Move time [s].
    omega_c : float      Cruise speed [rad/s] (signed like Δθ).
    """

    delta_theta: float
    alpha: float
    T_a: float
    T_m: float
    omega_c: float


@dataclass(frozen=True)
class CascadeGains:
    """A P–PI position/speed cascade with inertia feed-forward (SI units).

    Attributes
    ----------
    pos_gain : float              Speed demand per position error [1/s].
    vel_gain : float              Torque per speed error [N·m·s/rad].
    vel_integrator_gain : float   Torque per integrated speed error [N·m/rad].
    inertia : float               Torque feed-forward per demanded acceleration [kg·m²].
    kp : float                    The same law as a parallel PID on position: torque per position error [N·m/rad].
    kd : float                    Torque per speed error of the parallel PID [N·m·s/rad] (= vel_gain).
    ki : float                    Torque per integrated position error of the parallel PID [N·m/(rad·s)].
    """

    pos_gain: float
    vel_gain: float
    vel_integrator_gain: float
    inertia: float
    kp: float
    kd: float
    ki: float


def trapezoid_timing(delta_theta: float, alpha: float, T_m: float) -> TrapezoidTiming:
    """Return the symmetric trapezoid at ``alpha`` [rad/s²] that moves ``delta_theta`` [rad] in ``T_m`` [s].

    T_a = (T_m − √(T_m² − 4·|Δθ|/α))/2 (the cruise speed ω_c = α·T_a ends the move at T_m).

    Raises
    ------
    ParameterError
        When α ≤ 0 or T_m is shorter than the triangular move 2·√(|Δθ|/α).
    """
    if not alpha > 0.0:
        raise ParameterError(f"trapezoid alpha = {alpha!r} rad/s² is not allowed: allowed > 0 rad/s²")
    disc = T_m * T_m - 4.0 * abs(delta_theta) / alpha
    if disc < 0.0:
        raise ParameterError(f"manoeuvre.T_m = {T_m:g} s is too short for a trapezoid at {alpha:.5g} rad/s²: "
                             f"allowed ≥ {2.0 * math.sqrt(abs(delta_theta) / alpha):.5g} s")
    T_a = 0.5 * (T_m - math.sqrt(disc))
    return TrapezoidTiming(delta_theta, alpha, T_a, T_m, math.copysign(alpha * T_a, delta_theta))


def trapezoid_samples(tr: TrapezoidTiming, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """θ [rad], ω [rad/s], α [rad/s²] of the trapezoid at times ``t`` [s] (at rest at Δθ after T_m)."""
    t = np.clip(np.asarray(t, dtype=float), 0.0, tr.T_m)
    a = math.copysign(tr.alpha, tr.delta_theta)
    t_d = tr.T_m - tr.T_a  # start of the deceleration
    acc, dec = t < tr.T_a, t > t_d
    alpha = np.where(acc, a, np.where(dec, -a, 0.0))
    omega = np.where(acc, a * t, np.where(dec, a * (tr.T_m - t), tr.omega_c))
    theta = np.where(acc, 0.5 * a * t * t,
                     np.where(dec, tr.delta_theta - 0.5 * a * (tr.T_m - t) ** 2,
                              0.5 * a * tr.T_a ** 2 + tr.omega_c * (t - tr.T_a)))
    alpha = np.where(t >= tr.T_m, 0.0, alpha)
    return theta, omega, alpha


def trapezoid_omega_square_integral(tr: TrapezoidTiming) -> float:
    """∫ω² dt over the move [rad²/s]: ω_c²·(T_m − 4·T_a/3) (ideal tracking; friction = F_v times this)."""
    return tr.omega_c ** 2 * (tr.T_m - 4.0 * tr.T_a / 3.0)


def trapezoid_from_limits(delta_theta: float, v_max: float, a_max: float) -> TrapezoidTiming:
    """Return the rest-to-rest move a drive's planner makes from its limits (ODrive ``TrapezoidalTrajectory``).

    Cruise at ``v_max`` [rad/s] after T_a = v_max/a_max when the move is long enough,
    |Δθ| ≥ v_max²/a_max; otherwise the triangle that peaks at √(|Δθ|·a_max). T_m = 2·T_a + the cruise.

    Raises
    ------
    ParameterError
        When a limit is not > 0.
    """
    if not (v_max > 0.0 and a_max > 0.0):
        raise ParameterError(f"planner limits vel = {v_max!r} rad/s, accel = {a_max!r} rad/s² are not allowed: > 0")
    dist = abs(delta_theta)
    v = min(v_max, math.sqrt(dist * a_max))
    T_a = v / a_max
    T_m = 2.0 * T_a + (dist - v * T_a) / v if v > 0.0 else 0.0
    return TrapezoidTiming(delta_theta, a_max, T_a, T_m, math.copysign(v, delta_theta))
