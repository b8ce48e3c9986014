"""The tracked minimum-energy move with the FDSMC's terminal slide: the optimum's law.

Tracking a time-fixed reference to its very end leaves the last transient to the observer: the
copper-optimal move (:mod:`control.fdsmc.optimum`) ends with its largest deceleration, which the
load inertia J_L — unknown to the controller, seen by the observer of eq. (17) in [1] as load torque
J_L·α — turns into a step of Γ_L at T_m. The observer's lag then carries the rotor a few mrad past
θ_dem (2–18 mrad on the real presets), far outside an in-position window of 10 encoder counts.

The FDSMC arrives clean because its last phase is the sloped segment ω_r = −θ_re/T_c of
eq. (41): an exponential approach whose deceleration decays to zero, along which the boundary layer
(eqs. (44)–(46)) rejects the observer's error. The tracked optimum ends the same way. Its
reference reaches the sloped line where ω_ref·T_c = θ_dem − θ_ref (on the unlimited optimum
ω = 6Δθ·u·(T_m − u)/T_m³ that is u ≈ 2·T_c before T_m, where both tails need the same
∫α² dt = 72·Δθ²·T_c/T_m⁴ to first order in T_c/T_m: the slide costs no copper), and from there
on the law is the FDSMC's own, eq. (46), towards θ_dem. Before it, the reference is tracked by
α_ref + g1·(θ_ref − θ̂_r) + g2·(ω_ref − ω̂_r) (:func:`control.fdsmc.conventional.tracking_demand`).

The switch depends on the reference alone (on time), never on the measured state, so the law
cannot chatter between its two modes.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from pmsm_commissioning.control.common.jit import jitable
from pmsm_commissioning.control.fdsmc.conventional import tracking_demand
from pmsm_commissioning.control.fdsmc.sliding_mode import smc_demand


@jitable
def reference_on_slope(theta_ref: float, omega_ref: float, theta_dem: float, theta_start: float,
                       T_c: float) -> bool:
    """Whether the reference has reached the sloped segment ω = −θ_re/T_c of eq. (41) in [1].

    True where the reference's switching function of the sloped segment, ω_ref + (θ_ref − θ_dem)/T_c,
    has the sign of the move θ_dem − θ_start (or is zero): from the point where the reference meets the
    line to the end, and at rest on θ_dem.

    Parameters
    ----------
    theta_ref, omega_ref : float  The reference's position [rad] and speed [rad/s].
    theta_dem : float             The move's end [rad].
    theta_start : float           The move's start [rad].
    T_c : float                   Slope time constant of eq. (41) [s].
    """
    s = omega_ref + (theta_ref - theta_dem) / T_c
    return s >= 0.0 if theta_dem >= theta_start else s <= 0.0


@jitable
def slide_in_demand(theta_ref: float, omega_ref: float, alpha_ref: float, theta_start: float, theta_hat: float,
                    omega_hat: float, g1: float, g2: float, theta_dem: float, omega_p: float, T_c: float,
                    K: float, alpha_max: float) -> tuple[float, float]:
    """(α_dem [rad/s²], S [rad/s]) of the tracked move with the terminal slide (module docstring).

    Parameters
    ----------
    theta_ref, omega_ref, alpha_ref : float  The reference at this instant [rad, rad/s, rad/s²]
                                             (α_ref read ahead by the inner loops' lag).
    theta_start : float                      The move's start [rad].
    theta_hat, omega_hat : float             The observer's estimates [rad, rad/s].
    g1, g2 : float                           Tracking gains [1/s², 1/s].
    theta_dem, omega_p, T_c, K, alpha_max    The FDSMC's eqs. (41)–(46) [rad, rad/s, s, s/rad, rad/s²].

    S is 0 while the reference is tracked.
    """
    if reference_on_slope(theta_ref, omega_ref, theta_dem, theta_start, T_c):
        return smc_demand(theta_hat - theta_dem, omega_hat, omega_p, T_c, K, alpha_max)
    return tracking_demand(theta_ref, omega_ref, alpha_ref, theta_hat, omega_hat, g1, g2), 0.0


__all__ = ["reference_on_slope", "slide_in_demand"]
