"""mjbots moteus: the ``key value`` configuration ``moteus_tool --restore-config`` loads, and its strict parser.

A moteus configuration dump (``conf enumerate``, ``moteus_tool --dump-config``) is one ``key value``
per line; ``--restore-config`` sends every non-empty line as ``conf set key value``. The keys and
units are those of moteus' ``docs/reference.md`` (configurable parameters) and the firmware's
``fw/bldc_servo_structs.h``: the position PID in N·m per output revolution (kp), N·m/s per
revolution (ki), N·m per revolution/s (kd); the trajectory limits in rev/s and rev/s² at the
output; ``motor.poles`` counts poles, not pole pairs; ``servo.inertia_feedforward`` in kg·m².

``motor_position.rotor_to_output_ratio`` is "the number of turns of the output for one turn of the
rotor" (moteus docs/reference.md), so 1/N for this tool's ``transmission.ratio`` N (motor revolutions
per output revolution). With it moteus reads positions, speeds and torques at the output shaft
(reference.md: position "in rotations of the output shaft", torque "as measured at the output
shaft"): an output revolution is N rotor revolutions and an output torque N rotor torques, so the
rotor-side gains this tool tunes are written ×N² (kp, ki, kd, inertia: torque per angle, torque per
acceleration), the integrator clamp ×N, the speed and acceleration limits ÷N; :func:`moteus_loop`
reads them back the same way. moteus' ratio is kinematic only: the transmission's efficiency is not in it.

moteus runs a parallel PID, not a cascade; its gains, the current PI (``servo.pid_dq``), the encoder
PLL and the control rate are tuned on the simulated stock route (:mod:`sim.stock.tuning`: no
integrator, moteus' advice for a high torque bandwidth) and :func:`moteus_loop` reads them back.

The header is written as ``#`` lines, which moteus_tool would send as commands: strip them first
(``grep -v '^#' FILE > restore.cfg``, see docs/drives/moteus.md). :func:`parse_moteus` accepts them.
"""

from __future__ import annotations

import math
import re

from pmsm_commissioning.app.exports.drives.stock import StockSettings
from pmsm_commissioning.app.exports.drives.units import (
    per_rad_to_per_turn,
    per_turn_to_per_rad,
    pole_pairs_to_poles,
    poles_to_pole_pairs,
    psi_from_kv,
    rad_to_turn,
    turn_to_rad,
)
from pmsm_commissioning.app.exports.drives.vendor_keys import VendorFile, VendorKey, fmt_float, vendor_file
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.model import torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_from_limits
from pmsm_commissioning.sim.stock.route import StockLoop
from pmsm_commissioning.sim.stock.tuning import setpoint_table

_REF = "moteus docs/reference.md, configurable parameters"
_FW = "moteus fw/bldc_servo_structs.h"
#: Every key written, with its moteus type and unit.
KEYS: dict[str, VendorKey] = {vk.key: vk for vk in (
    VendorKey("motor.poles", "int", "-", f"{_FW}: BldcServoMotor::poles (uint8, poles)"),
    VendorKey("motor.resistance_ohm", "float", "Ohm", f"{_FW}: BldcServoMotor::resistance_ohm"),
    VendorKey("servo.max_current_A", "float", "A", f"{_REF}: servo.max_current_A (phase current)"),
    VendorKey("servo.pid_position.kp", "float", "Nm/rev", f"{_REF}: servo.pid_position kp, Nm per rotation"),
    VendorKey("servo.pid_position.ki", "float", "Nm/s/rev", f"{_REF}: servo.pid_position ki, Nm/s per rotation"),
    VendorKey("servo.pid_position.kd", "float", "Nm/(rev/s)", f"{_REF}: servo.pid_position kd, Nm per rotation/s"),
    VendorKey("servo.pid_position.ilimit", "float", "Nm", f"{_REF}: servo.pid_position ilimit, Nm"),
    VendorKey("servo.default_velocity_limit", "float", "rev/s", f"{_REF}: servo.default_velocity_limit", True),
    VendorKey("servo.default_accel_limit", "float", "rev/s^2", f"{_REF}: servo.default_accel_limit", True),
    VendorKey("servo.inertia_feedforward", "float", "kg*m^2", f"{_REF}: servo.inertia_feedforward"),
    VendorKey("motor_position.rotor_to_output_ratio", "float", "-", f"{_REF}: motor_position.rotor_to_output_ratio"),
    VendorKey("servo.pid_dq.kp", "float", "V/A", f"{_REF}: servo.pid_dq (current loop, kp = L·ω_c)"),
    VendorKey("servo.pid_dq.ki", "float", "V/A/s", f"{_REF}: servo.pid_dq (current loop, ki = R·ω_c)"),
    VendorKey("motor_position.sources.0.pll_filter_hz", "float", "Hz", f"{_REF}: encoder PLL bandwidth"),
    VendorKey("servo.pwm_rate_hz", "float", "Hz", f"{_REF}: servo.pwm_rate_hz (the control loop's rate)"),
)}
#: Keys only read on import (written by moteus' own calibration): Kv and the dq inductances.
READ_KEYS: dict[str, VendorKey] = {vk.key: vk for vk in (
    VendorKey("motor.Kv", "float", "rpm/V", f"{_FW}: BldcServoMotor::Kv"),
    VendorKey("motor.inductance_d_H", "float", "H", f"{_FW}: BldcServoMotor::inductance_d_H"),
    VendorKey("motor.inductance_q_H", "float", "H", f"{_FW}: BldcServoMotor::inductance_q_H"),
)}
_LINE = re.compile(r"^([A-Za-z_][A-Za-z0-9_.\[\]]*) (\S+)$")


def moteus_values(s: StockSettings) -> dict[str, float]:
    """Every written key → value in moteus' units at the output (the one conversion from SI, see the module doc)."""
    g, tr, loop, N = s.gains, s.trapezoid, s.tuning.loop, s.ratio
    values = [pole_pairs_to_poles(s.p), s.R_s, s.current_limit, per_rad_to_per_turn(g.kp) * N**2,
              per_rad_to_per_turn(g.ki) * N**2, per_rad_to_per_turn(g.kd) * N**2, loop.i_lim * N,
              rad_to_turn(abs(tr.omega_c)) / N, rad_to_turn(tr.alpha) / N, g.inertia * N**2, 1.0 / N,
              loop.current_kp, loop.current_ki, s.pll_bandwidth / (2.0 * math.pi), s.f_loop]
    return dict(zip(KEYS, values, strict=True))


#: Relative mismatch of the file's ratio with the case's 1/N that float32 storage explains.
RATIO_TOLERANCE = 1e-6


def moteus_ratio(f: VendorFile) -> float:
    """Return the transmission ratio N = 1/``motor_position.rotor_to_output_ratio`` (motor rev per output rev).

    Raises
    ------
    ParameterError
        Naming the key for a ratio that is missing, not > 0 or gives N outside ``transmission.ratio``'s range.
    """
    r = f.require("motor_position.rotor_to_output_ratio", "the ratio")
    if not (math.isfinite(r) and r > 0.0):
        raise ParameterError(f"motor_position.rotor_to_output_ratio = {r!r} is not allowed: allowed > 0 "
                             "(output turns per rotor turn)")
    return 1.0 / r


def moteus_text(s: StockSettings, header: list[str]) -> str:
    """Return the configuration text: ``# `` header lines, then one ``key value`` per line.

    Every header line is escaped (:func:`app.io.user_text.escaped`): no line break of any kind, so a
    name or source can never add a ``key value`` line.
    """
    lines = [f"# {escaped(h)}" for h in header]
    lines.append("# moteus: grep -v '^#' THIS_FILE > restore.cfg && moteus_tool -t 1 --restore-config restore.cfg")
    for key, v in moteus_values(s).items():
        lines.append(f"{key} {int(v) if KEYS[key].kind != 'float' else fmt_float(v)}")
    return "\n".join(lines) + "\n"


def parse_moteus(text: str) -> VendorFile:
    """Strict parser of a moteus configuration dump: ``key value`` lines, ``#`` comments, nothing else.

    Raises
    ------
    ParameterError
        Naming the line for anything but ``key value``, a duplicated key or a known key of the wrong type.
    """
    pairs, comment = [], []
    for n, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            comment.append(stripped.lstrip("#").strip())
            continue
        m = _LINE.match(stripped)
        if m is None:
            raise ParameterError(f"moteus line {n} = {stripped[:60]!r} is not allowed: 'key value' (one space)")
        raw = m.group(2)
        pairs.append((m.group(1), raw.lower() if raw.lower() == "nan" else raw))
    return vendor_file(pairs, {**KEYS, **READ_KEYS}, comment)


def moteus_motor(f: VendorFile) -> tuple[float, float | None, float | None, float | None, int, float]:
    """R_s [Ω], L_d, L_q [H] (None if absent), Ψ_PM [Wb] (None without Kv), p [-], i_max [A]."""
    p = poles_to_pole_pairs(f.require("motor.poles", "the pole count"), "motor.poles")
    kv = f.get("motor.Kv")
    if kv is not None and not kv > 0.0:
        raise ParameterError(f"motor.Kv = {kv!r} rpm/V is not allowed: allowed > 0 rpm/V (a calibrated motor)")
    psi = psi_from_kv(kv, p) if kv is not None else None
    return (f.require("motor.resistance_ohm", "the phase resistance [Ohm]"), f.get("motor.inductance_d_H"),
            f.get("motor.inductance_q_H"), psi, p, f.require("servo.max_current_A", "the current limit [A]"))


def moteus_loop(f: VendorFile, params: DriveParams) -> StockLoop:
    """Return the stock route of a parsed configuration: moteus' PID, current PI and PLL at its PWM rate (SI).

    The torque constant is the case's (moteus calibrates Kv on the motor itself; the file leaves it
    out); the move is the trajectory from the file's limits over the case's θ_dem.

    Raises
    ------
    ParameterError
        Naming the key, for a missing setting or a rotor-to-output ratio that is not the case's 1/N.
    """
    N = moteus_ratio(f)
    if abs(N / params.transmission.ratio - 1.0) > RATIO_TOLERANCE:
        raise ParameterError(f"motor_position.rotor_to_output_ratio = {1.0 / N!r} is not allowed here: "
                             f"{1.0 / params.transmission.ratio!r} (1/transmission.ratio, the simulated axis)")
    tr = trapezoid_from_limits(params.manoeuvre.theta_dem,
                               turn_to_rad(f.require("servo.default_velocity_limit", "the speed limit [rev/s]")) * N,
                               turn_to_rad(f.require("servo.default_accel_limit", "the acceleration [rev/s^2]")) * N)
    rate = f.require("servo.pwm_rate_hz", "the control rate [Hz]")
    gains = [per_turn_to_per_rad(f.require(f"servo.pid_position.{k}", f"the position PID's {k}")) / N**2
             for k in ("kp", "kd", "ki")]
    return StockLoop(
        "moteus", rate, "pid", *gains, f.require("servo.pid_position.ilimit", "the integrator clamp [Nm]") / N,
        math.inf, f.require("servo.inertia_feedforward", "the inertia [kg*m^2]") / N**2, torque_constant(params.motor),
        f.require("servo.max_current_A", "the current limit [A]"),
        2.0 * math.pi * f.require("motor_position.sources.0.pll_filter_hz", "the PLL bandwidth [Hz]"), False,
        f.require("servo.pid_dq.kp", "the current kp [V/A]"), f.require("servo.pid_dq.ki", "the current ki"),
        setpoint_table(tr, 1.0 / rate), 1.0 / rate)
