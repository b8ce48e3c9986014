"""Comparator 4: six-step (120° square-wave current) commutation of the trapezoidal-EMF PMSM.

Section I and Fig. 1 of [2]: with an ideal trapezoidal back-EMF and ideal 120° square-wave
currents aligned with its flat tops, two phases conduct ±I at a time and the torque is
T = n_pp·(Φ_M·I + Φ_M·I) = K_T·I with K_T = 2·n_pp·Φ_M — the constant printed in Fig. 7 of [2],
which is right *here* (for the line current of six-step), not for i_qx
(:func:`control.bldc.dqx.torque_constant_fig7` is that constant).

Choices (stated because [2] only sketches the ideal case):

* **Commutation** from the rotor electrical angle θ_e (ideal Hall sensors, no delay beyond the
  sample hold). Six 60° sectors k = ⌊((θ_e + 30°) mod 360°)/60°⌋, so sector k is centred on
  θ_e = k·60°. With the phase origin of :mod:`control.bldc.dqx` (Φ'_ra flat at −Φ_M over 30°–150°,
  at +Φ_M over 210°–330°; b, c lag by 120°, 240°) the sector boundaries are exactly the corners
  of the ideal trapezoid: in every sector two phases sit on a flat top (one at +Φ_M, one at
  −Φ_M) and the third is on its ramp. The current sign of a phase is the sign of its flat top
  (+1, −1) and 0 on the ramp (the open, non-conducting phase) — :data:`SIGN_A` for phase a;
  phases b, c use the same table two and four sectors later.
* **Speed loop**: the paper's integral sliding surface (the same law as the paper's drive, so
  only the current shaping differs); the torque reference becomes the DC (line) current
  reference I* = T*/K_T, K_T = 2·n_pp·Φ_M.
* **Current loop**, on an averaged inverter (no PWM ripple): the line current of the conducting
  pair i_line = (s_a·i_a + s_b·i_b + s_c·i_c)/2 (= i_p = −i_n when the open phase carries no
  current) is driven by a tanh sliding-mode law on the *line voltage* v_line = v_p − v_n,
  |v_line| ≤ V_dc (the whole DC link across the pair). The **open phase is not modelled as an
  open switch** (that needs diode states and terminal-voltage clamping): instead its terminal
  voltage is commanded by a second tanh law that drives its current to zero,
  |v_fl| ≤ V_dc/2 about the pair's mid-point (the rails). Both voltages together always lie
  inside the inverter's hexagon (max − min of the phase voltages ≤ V_dc). The outgoing phase's
  current is thus forced to zero with the DC-link voltage, much as the freewheeling diodes do,
  and the commutation dips come from the finite voltage available to swap the currents.
* **Gains** are matched to the dq_x drive: the tanh slopes are chosen so that near zero error
  both loops have the same proportional gain k_I·V_dc/√2 [V/A] in the power-invariant αβ frame,
  i.e. the same per-sample discrete gain k_I·V_dc/(√2·f_s·(L_s − M_s)).

The functions use only ``math`` and module constants, so the kernel compiles this very code
with numba (one implementation of the law).

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math

SQRT2 = math.sqrt(2.0)
TWO_PI = 2.0 * math.pi
SECTOR = math.pi / 3.0  # 60° electrical per commutation sector
HALF_SECTOR = math.pi / 6.0  # sector 0 starts at θ_e = −30°
#: Current sign of phase a in sectors 0 … 5 (centres 0°, 60°, … 300°): the sign of the ideal
#: Φ'_ra on its flat tops (−Φ_M over 30°–150°, +Φ_M over 210°–330°), 0 on its ramps.
SIGN_A = (0.0, -1.0, -1.0, 0.0, 1.0, 1.0)


def commutation_sector(theta_e: float) -> int:
    """Commutation sector k ∈ {0, …, 5} of the electrical angle: θ_e ∈ [k·60° − 30°, k·60° + 30°).

    Parameters
    ----------
    theta_e : float  Rotor electrical angle [rad] (any value; wrapped).
    """
    return min(int(((theta_e + HALF_SECTOR) % TWO_PI) / SECTOR), 5)


def commutation_signs(theta_e: float) -> tuple[float, float, float]:
    """Return the current signs (s_a, s_b, s_c) of six-step at θ_e: one +1, one −1, one 0 (open phase) [-].

    The ideal 120° square-wave currents are i_x = s_x·I (they sum to zero).

    Parameters
    ----------
    theta_e : float  Rotor electrical angle [rad] (ideal Hall sensors).
    """
    k = min(int(((theta_e + HALF_SECTOR) % TWO_PI) / SECTOR), 5)
    return SIGN_A[k], SIGN_A[(k + 4) % 6], SIGN_A[(k + 2) % 6]


def open_phase_feedforward(f_a: float, f_b: float, f_c: float, s_a: float, s_b: float, s_c: float,
                           omega_e: float) -> float:
    """Open-phase terminal voltage that keeps its current at zero, v_ff = ω_e·(Φ'_o − (Φ'_p + Φ'_n)/2) [V].

    A truly open phase floats at its own back-EMF relative to the conducting pair's mid-point
    (the voltage sensorless drives watch for zero crossings). The caller passes the *ideal*
    trapezoid's Φ' (what the controller knows, as the dq_x drive uses the ideal a_x, θ_x), so on a
    distorted machine the open-phase loop of :func:`six_step_voltages` corrects the rest.

    Parameters
    ----------
    f_a, f_b, f_c : float  Ideal Φ'_ra, Φ'_rb, Φ'_rc at θ_e [Wb].
    s_a, s_b, s_c : float  Commutation signs [-].
    omega_e : float        Electrical speed n_pp·ω [rad/s].
    """
    f_open = (1.0 - abs(s_a)) * f_a + (1.0 - abs(s_b)) * f_b + (1.0 - abs(s_c)) * f_c
    f_pair = abs(s_a) * f_a + abs(s_b) * f_b + abs(s_c) * f_c
    return omega_e * (f_open - 0.5 * f_pair)


def six_step_voltages(i_ref: float, i_a: float, i_b: float, i_c: float, s_a: float, s_b: float,
                      s_c: float, v_ff: float, k_I: float, V_dc: float
                      ) -> tuple[float, float, float, float, float]:
    """Phase voltages of the six-step current loop (module docstring) and the measured currents.

    v_line = V_dc·tanh(√2·k_I·(I* − i_line)) across the conducting pair and
    v_fl = clamp(v_ff + V_dc·tanh(−(3/(2√2))·k_I·i_fl), ±V_dc/2) on the open phase, i.e.
    v_x = s_x·v_line/2 + (o_x − 1/3)·v_fl with o_x = 1 for the open phase, 0 otherwise.
    Near zero error the slopes give the αβ proportional gain k_I·V_dc/√2 of the dq_x loop on
    both the pair and the open phase.

    Parameters
    ----------
    i_ref : float                DC (line) current reference I* [A].
    i_a, i_b, i_c : float        Phase currents [A].
    s_a, s_b, s_c : float        Commutation signs from :func:`commutation_signs` [-].
    v_ff : float                 Open-phase feed-forward from :func:`open_phase_feedforward` [V].
    k_I : float                  Sliding-mode gain of the dq_x current loop [1/A].
    V_dc : float                 DC-link voltage [V].

    Returns
    -------
    tuple of float
        (v_a, v_b, v_c) [V] (zero sum), i_line [A] of the pair, i_fl [A] of the open phase.
    """
    i_line = 0.5 * (s_a * i_a + s_b * i_b + s_c * i_c)
    o_a, o_b, o_c = 1.0 - abs(s_a), 1.0 - abs(s_b), 1.0 - abs(s_c)
    i_fl = o_a * i_a + o_b * i_b + o_c * i_c
    v_line = V_dc * math.tanh(SQRT2 * k_I * (i_ref - i_line))
    v_fl = v_ff + V_dc * math.tanh(-0.75 * SQRT2 * k_I * i_fl)
    v_fl = max(-0.5 * V_dc, min(0.5 * V_dc, v_fl))
    third = 1.0 / 3.0
    return (0.5 * s_a * v_line + (o_a - third) * v_fl, 0.5 * s_b * v_line + (o_b - third) * v_fl,
            0.5 * s_c * v_line + (o_c - third) * v_fl, i_line, i_fl)
