"""The control loops a stock drive's firmware runs each cycle, written once for the kernel and the tests.

A stock servo drive (ODrive fw 0.5.x, moteus, a VESC or any drive fed a setpoint table) runs, every
cycle of period T [s], three laws on its sensor readings, none of them from [1]:

* an encoder **PLL** estimating position and speed from the counts (:func:`pll_update`): ODrive's
  ``Encoder::update`` (gains kp = 2·ω_e, ki = kp²/4 = ω_e², a critically damped pair at ω_e [rad/s], the
  speed snapped to zero below 0.5·T·ki counts/s), moteus' ``motor_position`` PLL at ``pll_filter_hz``;
* a **position/speed law** giving the torque demand (:func:`position_torque`), one of

  - the P–PI cascade (ODrive ``Controller::update``, the setpoint table's cascade)::

        ω_des = clamp(ω_ref + pos_gain·(θ_ref − θ̂), ±ω_lim),  e_ω = ω_des − ω̂
        Γ = J_ff·α_ref + vel_gain·e_ω + I;   I ← 0.99·I if Γ was limited, else I + k_i·T·e_ω

  - the parallel PID on position (moteus ``pid_position``)::

        Γ = J_ff·α_ref + kp·e_θ + kd·(ω_ref − ω̂) + I,   I ← clamp(I + ki·T·e_θ, ±I_lim)

  clamped to the torque of the current limit, Γ_lim = K_t·i_lim;
* a **dq current PI** per axis with i_d* = 0 and i_q* = Γ/K_t (:func:`current_pi`): kp = L·ω_c,
  ki = R·ω_c (pole–zero cancellation: a first-order loop of bandwidth ω_c [rad/s], the rule of
  ODrive's ``current_control_bandwidth``, moteus_tool's ``--cal-bw-hz`` and VESC Tool's), the voltage
  vector limited to the circle u_max with the integrators decayed by 0.99 while it is (ODrive's
  anti-windup).

Scalar functions only, :func:`control.common.jit.jitable`: inlined into the compiled kernel
(:mod:`sim.fdsmc.kernel`), plain Python elsewhere.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper (whose loops these are not).
"""

from __future__ import annotations

import math

from pmsm_commissioning.control.common.jit import jitable

#: Position/speed law codes: the P–PI cascade (ODrive, the setpoint table) and the parallel PID (moteus).
LAW_CASCADE, LAW_PID = 0.0, 1.0
#: Integrator decay factor per cycle while the output is limited (ODrive's anti-windup) [-].
WINDUP_DECAY = 0.99


@jitable
def pll_gains(omega_e: float) -> tuple[float, float]:
    """Return the PLL's (kp [1/s], ki [1/s²]) for bandwidth ``omega_e`` [rad/s]: 2·ω_e, kp²/4 = ω_e²."""
    kp = 2.0 * omega_e
    return kp, 0.25 * kp * kp


@jitable
def pll_update(theta_hat: float, omega_hat: float, theta_meas: float, omega_e: float, T: float,
               snap: float) -> tuple[float, float]:
    """One PLL step: return (θ̂ [rad], ω̂ [rad/s]) after reading ``theta_meas`` [rad].

    θ̂ ← θ̂ + T·ω̂; δ = θ_meas − θ̂; θ̂ ← θ̂ + T·kp·δ; ω̂ ← ω̂ + T·ki·δ; ω̂ ← 0 where |ω̂| < ``snap``
    [rad/s] (ODrive's 0.5·T·ki counts/s, 0 for none).
    """
    kp, ki = pll_gains(omega_e)
    th = theta_hat + T * omega_hat
    delta = theta_meas - th
    th += T * kp * delta
    w = omega_hat + T * ki * delta
    if abs(w) < snap:
        w = 0.0
    return th, w


@jitable
def clamp(x: float, lim: float) -> float:
    """Return x limited to ±lim (lim = inf: no limit)."""
    return min(max(x, -lim), lim)


@jitable
def position_torque(law: float, theta_ref: float, omega_ref: float, alpha_ref: float, theta_hat: float,
                    omega_hat: float, integ: float, kp: float, kd: float, ki: float, i_lim: float,
                    omega_lim: float, J_ff: float, torque_lim: float, T: float) -> tuple[float, float, bool]:
    """Return (torque demand Γ [N·m], the integrator's next value [N·m], limited) of one cycle.

    ``law`` LAW_CASCADE: ``kp`` is pos_gain [1/s], ``kd`` vel_gain [N·m·s/rad], ``ki`` the speed
    integrator gain [N·m/rad], ``omega_lim`` the speed-demand clamp [rad/s]; ``i_lim`` is unused.
    ``law`` LAW_PID: ``kp`` [N·m/rad], ``kd`` [N·m·s/rad], ``ki`` [N·m/(rad·s)], ``i_lim`` the
    integrator clamp [N·m]; ``omega_lim`` is unused. Both feed J_ff·α_ref [N·m] forward and limit Γ
    to ±``torque_lim`` (see the module doc).
    """
    e_th = theta_ref - theta_hat
    ff = J_ff * alpha_ref
    if law == LAW_CASCADE:
        e_w = clamp(omega_ref + kp * e_th, omega_lim) - omega_hat
        torque = ff + kd * e_w + integ
        limited = abs(torque) > torque_lim
        nxt = WINDUP_DECAY * integ if limited else integ + ki * T * e_w
        return clamp(torque, torque_lim), nxt, limited
    torque = ff + kp * e_th + kd * (omega_ref - omega_hat) + integ
    limited = abs(torque) > torque_lim
    return clamp(torque, torque_lim), clamp(integ + ki * T * e_th, i_lim), limited


@jitable
def current_pi(i_d_dem: float, i_q_dem: float, i_d: float, i_q: float, v_d: float, v_q: float, kp: float,
               ki: float, u_max: float, T: float) -> tuple[float, float, float, float, bool]:
    """Return (u_d, u_q [V], next integrators v_d, v_q [V], limited) of the dq current PI.

    u = v + kp·(i* − i) per axis; |u| is scaled onto the circle ``u_max`` [V] where it exceeds it, and
    the integrators then decay by WINDUP_DECAY; otherwise v ← v + ki·T·(i* − i).
    """
    e_d, e_q = i_d_dem - i_d, i_q_dem - i_q
    u_d, u_q = v_d + kp * e_d, v_q + kp * e_q
    mag = math.sqrt(u_d * u_d + u_q * u_q)
    if mag > u_max:
        s = u_max / mag
        return s * u_d, s * u_q, WINDUP_DECAY * v_d, WINDUP_DECAY * v_q, True
    return u_d, u_q, v_d + ki * T * e_d, v_q + ki * T * e_q, False


__all__ = ["LAW_CASCADE", "LAW_PID", "WINDUP_DECAY", "clamp", "current_pi", "pll_gains", "pll_update",
           "position_torque"]
