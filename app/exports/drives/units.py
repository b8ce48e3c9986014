"""Drive units at the edge: the one place SI values become a stock drive's units and back.

Stock drives count in turns (ODrive: turn, turn/s, turn/s², N·m/(turn/s)), revolutions at the output
(moteus: rev, rev/s, rev/s², N·m/rev), poles rather than pole pairs (moteus, VESC) and a torque
constant per ampere of q-axis current (ODrive). Every conversion is a pure function here; the
writers and the strict parsers of :mod:`app.exports.drives.odrive`, :mod:`app.exports.drives.moteus`,
:mod:`app.exports.drives.vesc` and :mod:`app.exports.drives.setpoints` use nothing else.

Currents are the amplitude of the phase current (amplitude-invariant dq, |i_q| as in the
controller's ``i_max``), the convention of ODrive's ``current_lim``/``torque_constant``, moteus'
``servo.max_current_A`` and VESC's ``l_current_max``; torque Γ = 1.5·p·Ψ_PM·i_q (eq. (5) in [1]).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math

from pmsm_commissioning.control.common.checks import ParameterError

#: One turn (revolution) [rad].
TURN_RAD = 2.0 * math.pi
#: ODrive's and the hobby drives' Kv–Kt relation: Kt [N·m/A] = KV_KT / Kv [rpm/V] = (√3/2)·60/(2π).
KV_KT = math.sqrt(3.0) / 2.0 * 60.0 / (2.0 * math.pi)


def rad_to_turn(x: float) -> float:
    """Angle [rad] → [turn]; also rad/s → turn/s and rad/s² → turn/s²."""
    return x / TURN_RAD


def turn_to_rad(x_turn: float) -> float:
    """Angle [turn] → [rad]; also turn/s → rad/s and turn/s² → rad/s²."""
    return x_turn * TURN_RAD


def per_rad_to_per_turn(k: float) -> float:
    """Convert a gain per radian → per turn: N·m·s/rad → N·m/(turn/s), N·m/rad → N·m/turn, kg·m² → N·m/(turn/s²)."""
    return k * TURN_RAD


def per_turn_to_per_rad(k_turn: float) -> float:
    """Convert a gain per turn → per radian (inverse of :func:`per_rad_to_per_turn`)."""
    return k_turn / TURN_RAD


def pole_pairs_to_poles(p: int) -> int:
    """Pole pairs [-] → poles [-] (moteus ``motor.poles``, VESC ``si_motor_poles``)."""
    return 2 * int(p)


def poles_to_pole_pairs(poles: float, key: str) -> int:
    """Poles [-] → pole pairs [-].

    Raises
    ------
    ParameterError
        Naming ``key`` when the count is not a positive even integer.
    """
    if not (float(poles).is_integer() and poles >= 2 and int(poles) % 2 == 0):
        raise ParameterError(f"{key} = {poles!r} is not allowed: an even number of poles ≥ 2")
    return int(poles) // 2


def torque_constant(psi_pm: float, p: int) -> float:
    """Torque per ampere of i_q, Kt = 1.5·p·Ψ_PM [N·m/A] (ODrive ``torque_constant``), eq. (5) in [1]."""
    return 1.5 * p * psi_pm


def psi_from_torque_constant(kt: float, p: int) -> float:
    """Ψ_PM [Wb] from Kt [N·m/A per A of i_q]; inverse of :func:`torque_constant`."""
    return kt / (1.5 * p)


def kv_rpm_per_v(psi_pm: float, p: int) -> float:
    """Speed constant Kv [rpm/V] of the hobby convention Kt = KV_KT/Kv (ODrive's 8.27/Kv)."""
    return KV_KT / torque_constant(psi_pm, p)


def psi_from_kv(kv: float, p: int) -> float:
    """Ψ_PM [Wb] from Kv [rpm/V]; inverse of :func:`kv_rpm_per_v`."""
    return psi_from_torque_constant(KV_KT / kv, p)


#: Angle units of the setpoint table: unit → [rad] per unit.
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0, "rev": TURN_RAD}


def rad_to_angle_unit(x: float, unit: str) -> float:
    """Angle (or its rate) [rad] → ``unit`` (rad, deg or rev)."""
    if unit not in ANGLE_UNITS:
        raise ParameterError(f"angle unit = {unit!r} is not allowed: one of {', '.join(ANGLE_UNITS)}")
    return x / ANGLE_UNITS[unit]
