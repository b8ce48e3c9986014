"""ODrive (firmware 0.5.x): the backup JSON ``odrivetool restore-config FILE`` loads, and its strict parser.

``odrivetool backup-config`` writes the device's ``config`` objects as nested JSON: every object
that has a ``config`` child keeps its path (``{"axis0": {"motor": {"config": {...}}}}``), the leaves
are the properties of ``odrive-interface.yaml`` (fw 0.5.x) in their declared types and units; enums
are integers (ControlMode POSITION_CONTROL = 3, InputMode TRAP_TRAJ = 5). :func:`odrive_json` writes
axis 0's motor constants, current limit, the P–PI cascade (pos_gain, vel_gain, vel_integrator_gain,
inertia feed-forward, speed limit), the current-loop and encoder-PLL bandwidths and the trapezoidal
planner's limits (turn, turn/s, turn/s²), all tuned on the simulated stock route (:mod:`sim.stock.tuning`),
with a ``_comment`` key holding the header (odrivetool reports it as "property not found" and
restores the rest). Firmware 0.6.x moved the motor settings to ``axis0.config.motor`` and is not
written; a 0.6.x backup is refused naming its layout (:func:`odrive_motor`). The file carries the encoder's
``cpr`` (counts per motor revolution, 4× the pulses per revolution) and ``motor_type`` 0 (HIGH_CURRENT);
a backup with ``motor_type`` 2 (GIMBAL), where ``current_lim`` is a voltage limit [V] ("When using gimbal
motors, current_lim and calibration_current actually mean voltage limit and calibration voltage",
ODrive docs/getting-started.rst, fw 0.5.6), or 3 (ACIM, an induction motor) is refused.
"""

from __future__ import annotations

import json
import math
from typing import Any

from pmsm_commissioning.app.exports.drives.stock import StockSettings
from pmsm_commissioning.app.exports.drives.units import (
    per_rad_to_per_turn,
    per_turn_to_per_rad,
    psi_from_torque_constant,
    rad_to_turn,
    torque_constant,
    turn_to_rad,
)
from pmsm_commissioning.app.exports.drives.vendor_keys import VendorFile, VendorKey, vendor_file
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_from_limits
from pmsm_commissioning.sim.stock.route import StockLoop
from pmsm_commissioning.sim.stock.tuning import DRIVES, setpoint_table

_IF = "odrive-interface.yaml (fw 0.5.x)"
#: Every key written, with its ODrive type and unit (units as the interface file states them, those
#: of the motor config from the ODrive docs' parameter reference).
KEYS: dict[str, VendorKey] = {vk.key: vk for vk in (
    VendorKey("axis0.motor.config.motor_type", "enum", "-", f"{_IF}: ODrive.Motor.MotorType (0 = HIGH_CURRENT; "
              "2 = GIMBAL: current_lim is then a voltage)"),
    VendorKey("axis0.motor.config.pole_pairs", "int", "-", f"{_IF}: ODrive.Motor config pole_pairs int32"),
    VendorKey("axis0.motor.config.phase_resistance", "float", "Ohm", f"{_IF}: phase_resistance float32"),
    VendorKey("axis0.motor.config.phase_inductance", "float", "H", f"{_IF}: phase_inductance float32"),
    VendorKey("axis0.motor.config.torque_constant", "float", "Nm/A", f"{_IF}: torque_constant float32"),
    VendorKey("axis0.motor.config.current_lim", "float", "A", f"{_IF}: current_lim float32"),
    VendorKey("axis0.motor.config.current_control_bandwidth", "float", "rad/s",
              f"{_IF}: current_control_bandwidth (current PI kp = L·bw, ki = R·bw)"),
    VendorKey("axis0.encoder.config.bandwidth", "float", "rad/s", f"{_IF}: Encoder config bandwidth (PLL)"),
    VendorKey("axis0.encoder.config.cpr", "int", "counts/rev",
              f"{_IF}: Encoder config cpr int32, counts per revolution (4× the pulses per revolution)"),
    VendorKey("axis0.controller.config.control_mode", "enum", "-", f"{_IF}: ControlMode (3 = POSITION_CONTROL)"),
    VendorKey("axis0.controller.config.input_mode", "enum", "-", f"{_IF}: InputMode (5 = TRAP_TRAJ)"),
    VendorKey("axis0.controller.config.pos_gain", "float", "(turn/s) / turn", f"{_IF}: pos_gain"),
    VendorKey("axis0.controller.config.vel_gain", "float", "Nm/(turn/s)", f"{_IF}: vel_gain"),
    VendorKey("axis0.controller.config.vel_integrator_gain", "float", "Nm/(turn/s * s)", f"{_IF}: vel_integrator_gain"),
    VendorKey("axis0.controller.config.vel_limit", "float", "turn/s", f"{_IF}: controller vel_limit"),
    VendorKey("axis0.controller.config.inertia", "float", "Nm/(turn/s^2)", f"{_IF}: inertia"),
    VendorKey("axis0.trap_traj.config.vel_limit", "float", "turn/s", f"{_IF}: TrapezoidalTrajectory vel_limit"),
    VendorKey("axis0.trap_traj.config.accel_limit", "float", "turn/s^2", f"{_IF}: accel_limit"),
    VendorKey("axis0.trap_traj.config.decel_limit", "float", "turn/s^2", f"{_IF}: decel_limit"),
)}
CONTROL_MODE_POSITION_CONTROL = 3
INPUT_MODE_TRAP_TRAJ = 5
#: ODrive.Motor.MotorType of odrive-interface.yaml (fw 0.5.x): the one this tool reads and writes.
MOTOR_TYPE_HIGH_CURRENT = 0
#: The other motor types and why a backup with one is refused.
MOTOR_TYPES_REFUSED = {2: "GIMBAL: current_lim is a voltage limit [V] in gimbal mode, not a current",
                       3: "ACIM: an induction motor, not a PMSM"}


def odrive_values(s: StockSettings) -> dict[str, float]:
    """Every written key → value in ODrive's units (the one conversion from SI)."""
    tr, g = s.trapezoid, s.gains
    accel = rad_to_turn(tr.alpha)
    values = [MOTOR_TYPE_HIGH_CURRENT, s.p, s.R_s, 0.5 * (s.L_d + s.L_q), torque_constant(s.psi_pm, s.p),
              s.current_limit, s.current_bandwidth, s.pll_bandwidth, s.encoder_cpr, CONTROL_MODE_POSITION_CONTROL,
              INPUT_MODE_TRAP_TRAJ, g.pos_gain, per_rad_to_per_turn(g.vel_gain),
              per_rad_to_per_turn(g.vel_integrator_gain), rad_to_turn(s.speed_limit), per_rad_to_per_turn(g.inertia),
              rad_to_turn(abs(tr.omega_c)), accel, accel]
    out = dict(zip(KEYS, values, strict=True))
    if s.encoder_cpr <= 0:  # an ideal encoder has no count to write: the drive's own cpr stays
        del out["axis0.encoder.config.cpr"]
    return out


def _nest(flat: dict[str, Any]) -> dict[str, Any]:
    tree: dict[str, Any] = {}
    for key, value in flat.items():
        node = tree
        *path, leaf = key.split(".")
        for part in path:
            node = node.setdefault(part, {})
        node[leaf] = value
    return tree


def odrive_json(s: StockSettings, header: list[str]) -> str:
    """Return the backup JSON (``_comment`` first, then the ``axis0`` tree), floats to 9 significant digits.

    The keys are this module's constants; the header lines are escaped (:func:`app.io.user_text.escaped`).
    """
    flat = {k: (int(v) if KEYS[k].kind != "float" else float(f"{v:.9g}")) for k, v in odrive_values(s).items()}
    note = ("ODrive fw 0.5.x: odrivetool restore-config THIS_FILE (units: turn, turn/s, turn/s², N·m; the motor "
            "must still be calibrated)")
    data = {"_comment": [escaped(h) for h in header] + [note]}
    data.update(_nest(flat))
    return json.dumps(data, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


#: Deepest nesting of an ODrive backup read [levels] (odrivetool writes ≈ 5).
MAX_DEPTH = 32


def _leaves(node: Any, prefix: str = "", depth: int = 0) -> list[tuple[str, Any]]:
    if depth > MAX_DEPTH:
        raise ParameterError(f"ODrive JSON {escaped(prefix)[:80]!r} is nested deeper than {MAX_DEPTH} levels: "
                             f"allowed ≤ {MAX_DEPTH}")
    if isinstance(node, dict):
        out: list[tuple[str, Any]] = []
        for k, v in node.items():
            out += _leaves(v, f"{prefix}.{k}" if prefix else str(k), depth + 1)
        return out
    return [(prefix, node)]


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    data = dict(pairs)  # one pass: a key given twice leaves fewer entries than pairs
    if len(data) < len(pairs):
        seen: set[str] = set()
        dup = next(k for k, _ in pairs if k in seen or seen.add(k))  # type: ignore[func-returns-value]
        raise ParameterError(f"ODrive JSON key {escaped(dup)[:80]!r} is given more than once: allowed once")
    return data


def parse_odrive(text: str, origin: str = "<odrive>") -> VendorFile:
    """Strict parser of an ODrive backup JSON (fw 0.5.x): the known keys typed, every other leaf listed.

    ``Infinity``/``NaN`` (which odrivetool writes for disabled limits) are accepted only for keys
    this tool does not use. The ``_comment`` key is the file's comment.

    Raises
    ------
    ParameterError
        For text that is not a JSON object, a duplicated key, or a known key of the wrong type.
    """
    try:
        data = json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=lambda c: float(c))
    except json.JSONDecodeError as exc:
        raise ParameterError(f"{origin} is not valid JSON at line {exc.lineno}: {exc.msg}") from None
    except RecursionError:
        raise ParameterError(f"{origin} is nested too deeply: allowed ≤ {MAX_DEPTH} levels") from None
    if not isinstance(data, dict) or "axis0" not in data:
        raise ParameterError(f"{origin} is not an ODrive backup: allowed a JSON object with an 'axis0' object")
    comment = data.pop("_comment", [])
    if isinstance(comment, str):
        comment = [comment]
    pairs = _leaves(data)
    for key, raw in pairs:
        if key in KEYS and (isinstance(raw, str) or isinstance(raw, float) and not math.isfinite(raw)):
            what = f"a finite number in {KEYS[key].unit}" if KEYS[key].kind == "float" else "an integer"
            raise ParameterError(f"{key} = {raw!r} is not allowed: {what} (a JSON number)")
    return vendor_file(pairs, KEYS, (str(c) for c in comment))


#: A leaf of the fw 0.6.x layout (motor settings under axis0.config.motor).
LAYOUT_06 = "axis0.config.motor."


def _check_layout_and_type(f: VendorFile) -> None:
    """Refuse a fw 0.6.x backup by its layout, and a motor type whose current_lim is not a current.

    Raises
    ------
    ParameterError
        Naming the layout or the key, its value and what is allowed.
    """
    keys = [k for k, _ in f.values] + list(f.unknown)
    new = next((k for k in keys if k.startswith(LAYOUT_06)), None)
    if new is not None and f.get("axis0.motor.config.pole_pairs") is None:
        raise ParameterError(f"the backup has the fw 0.6.x layout axis0.config.motor.… ({new}): allowed fw 0.5.x "
                             "(axis0.motor.config.…); read the motor values off the 0.6 device by hand")
    kind = f.get("axis0.motor.config.motor_type")
    if kind is not None and kind != MOTOR_TYPE_HIGH_CURRENT:
        why = MOTOR_TYPES_REFUSED.get(int(kind), "not a motor type of fw 0.5.x")
        lim = f.get("axis0.motor.config.current_lim")
        raise ParameterError(f"axis0.motor.config.motor_type = {kind:g} ({why}; current_lim = {lim!r}) is not "
                             f"allowed: {MOTOR_TYPE_HIGH_CURRENT} (HIGH_CURRENT); give controller.i_max from the "
                             "motor's datasheet instead")


def odrive_motor(f: VendorFile) -> tuple[float, float, float, int, float]:
    """R_s [Ω], L [H], Ψ_PM [Wb], p [-], i_max [A] of a parsed backup (axis 0), after :func:`_check_layout_and_type`."""
    _check_layout_and_type(f)
    p = int(f.require("axis0.motor.config.pole_pairs", "the pole pairs"))
    if p < 1:
        raise ParameterError(f"axis0.motor.config.pole_pairs = {p} is not allowed: allowed ≥ 1")
    kt = f.require("axis0.motor.config.torque_constant", "the torque constant [Nm/A]")
    return (f.require("axis0.motor.config.phase_resistance", "the phase resistance [Ohm]"),
            f.require("axis0.motor.config.phase_inductance", "the phase inductance [H]"),
            psi_from_torque_constant(kt, p), p, f.require("axis0.motor.config.current_lim", "the current limit [A]"))


def _key(f: VendorFile, leaf: str, what: str) -> float:
    return f.require(f"axis0.{leaf}", what)


def odrive_loop(f: VendorFile, params: DriveParams) -> StockLoop:
    """Return the stock route of a parsed backup: ODrive fw 0.5.x's loops at 8 kHz with the file's settings (SI).

    The move is the planner's trapezoid from the file's limits over the case's θ_dem.

    Raises
    ------
    ParameterError
        Naming the key, for a missing setting, another control/input mode or accel ≠ decel.
    """
    for leaf, want in (("controller.config.control_mode", CONTROL_MODE_POSITION_CONTROL),
                       ("controller.config.input_mode", INPUT_MODE_TRAP_TRAJ)):
        if _key(f, leaf, "the mode") != want:
            raise ParameterError(f"axis0.{leaf} = {f.get('axis0.' + leaf)!r} is not allowed: {want} (trap move)")
    accel = _key(f, "trap_traj.config.accel_limit", "the planner's acceleration [turn/s^2]")
    if _key(f, "trap_traj.config.decel_limit", "the planner's deceleration [turn/s^2]") != accel:
        raise ParameterError("axis0.trap_traj.config.decel_limit is not allowed to differ from accel_limit: "
                             "the simulated planner is symmetric")
    tr = trapezoid_from_limits(params.manoeuvre.theta_dem,
                               turn_to_rad(_key(f, "trap_traj.config.vel_limit", "the planner's speed [turn/s]")),
                               turn_to_rad(accel))
    bw = _key(f, "motor.config.current_control_bandwidth", "the current-loop bandwidth [rad/s]")
    R = _key(f, "motor.config.phase_resistance", "the phase resistance [Ohm]")
    L = _key(f, "motor.config.phase_inductance", "the phase inductance [H]")
    rate = DRIVES["odrive"].f_loop
    return StockLoop(
        "odrive", rate, "cascade", _key(f, "controller.config.pos_gain", "pos_gain"),
        per_turn_to_per_rad(_key(f, "controller.config.vel_gain", "vel_gain")),
        per_turn_to_per_rad(_key(f, "controller.config.vel_integrator_gain", "vel_integrator_gain")), math.inf,
        turn_to_rad(_key(f, "controller.config.vel_limit", "the speed limit [turn/s]")),
        per_turn_to_per_rad(_key(f, "controller.config.inertia", "the inertia feed-forward")),
        _key(f, "motor.config.torque_constant", "the torque constant [Nm/A]"),
        _key(f, "motor.config.current_lim", "the current limit [A]"),
        _key(f, "encoder.config.bandwidth", "the encoder PLL bandwidth [rad/s]"), True, L * bw, R * bw,
        setpoint_table(tr, 1.0 / rate), 1.0 / rate)
