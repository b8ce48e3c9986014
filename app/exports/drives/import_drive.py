"""Import a stock drive's own file back into a preset: the motor the user already measured.

The vendor files carry the motor's electrical data, not its nameplate, load or move, so an import
replaces the motor data of a base preset: R_s, L_d, L_q, Ψ_PM (from the torque constant, Kv or flux
linkage), the pole pairs p and the current limit (``controller.i_max``); a moteus file also gives the
transmission ratio (``transmission.ratio`` = 1/``motor_position.rotor_to_output_ratio``). Each value is checked
against the preset field's range; a bad value is reported naming the vendor key, its value and
unit, and the allowed range. Every key of the file that is not imported is listed, never silently
dropped; a preset field the file does not give (e.g. moteus without Kv) is kept and listed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from pmsm_commissioning.app.exports.drives.moteus import moteus_motor, moteus_ratio, parse_moteus
from pmsm_commissioning.app.exports.drives.odrive import odrive_motor, parse_odrive
from pmsm_commissioning.app.exports.drives.vendor_keys import VendorFile
from pmsm_commissioning.app.exports.drives.vesc import parse_vesc, vesc_motor
from pmsm_commissioning.app.io.units import spec_of
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams

IMPORT_FORMATS = ("odrive", "moteus", "vesc")
#: Preset field → (vendor key, vendor unit) per format: where each imported value comes from.
SOURCES: dict[str, dict[str, tuple[str, str]]] = {
    "odrive": {"motor.R_s": ("axis0.motor.config.phase_resistance", "Ohm"),
               "motor.L_d": ("axis0.motor.config.phase_inductance", "H"),
               "motor.L_q": ("axis0.motor.config.phase_inductance", "H"),
               "motor.psi_pm": ("axis0.motor.config.torque_constant", "Nm/A"),
               "motor.p": ("axis0.motor.config.pole_pairs", "-"),
               "controller.i_max": ("axis0.motor.config.current_lim", "A"),
               "sensors.encoder_cpr": ("axis0.encoder.config.cpr", "counts/rev")},
    "moteus": {"motor.R_s": ("motor.resistance_ohm", "Ohm"), "motor.L_d": ("motor.inductance_d_H", "H"),
               "motor.L_q": ("motor.inductance_q_H", "H"), "motor.psi_pm": ("motor.Kv", "rpm/V"),
               "motor.p": ("motor.poles", "poles"), "controller.i_max": ("servo.max_current_A", "A"),
               "transmission.ratio": ("motor_position.rotor_to_output_ratio", "output rev per rotor rev")},
    "vesc": {"motor.R_s": ("foc_motor_r", "Ohm"), "motor.L_d": ("foc_motor_l", "H"),
             "motor.L_q": ("foc_motor_l", "H"), "motor.psi_pm": ("foc_motor_flux_linkage", "Wb"),
             "motor.p": ("si_motor_poles", "poles"), "controller.i_max": ("l_current_max", "A")},
}

#: Keys that shape an imported value without being its source (VESC: L_d, L_q = L ∓ diff/2).
ALSO_USED = {"vesc": ("foc_motor_ld_lq_diff",), "odrive": ("axis0.motor.config.motor_type",)}


@dataclass(frozen=True)
class DriveImport:
    """A vendor file imported onto a base preset.

    Attributes
    ----------
    params : DriveParams       The base preset with the file's motor data.
    imported : tuple of str    ``field = value (from vendor key)`` for each imported value (SI).
    kept : tuple of str        Preset fields the file does not give (kept from the base).
    not_imported : tuple of str  Every key of the file that was not imported, escaped
        (:func:`app.io.user_text.escaped`: a key never carries a line break or a control character).
    """

    params: DriveParams
    imported: tuple[str, ...]
    kept: tuple[str, ...]
    not_imported: tuple[str, ...]


def _parse(fmt: str, text: str, origin: str) -> tuple[VendorFile, tuple]:
    if fmt == "odrive":
        f = parse_odrive(text, origin)
        return f, odrive_motor(f)
    if fmt == "moteus":
        f = parse_moteus(text)
        R, Ld, Lq, psi, p, i = moteus_motor(f)
        return f, (R, Ld, Lq, psi, p, i)
    if fmt == "vesc":
        f = parse_vesc(text, origin)
        return f, vesc_motor(f)
    raise ParameterError(f"--format = {fmt!r} is not allowed: one of {', '.join(IMPORT_FORMATS)}")


def _checked(fmt: str, field: str, value: float, f: VendorFile) -> float:
    key, unit = SOURCES[fmt][field]
    try:
        return spec_of(field).check(field, value)
    except ParameterError as exc:
        raise ParameterError(f"{key} = {f.get(key)!r} {unit} is not allowed: it gives {exc}") from None


def import_drive(text: str, fmt: str, base: DriveParams, origin: str = "<drive file>") -> DriveImport:
    """Import the vendor file ``text`` of format ``fmt`` onto the preset ``base`` (see the module doc).

    Raises
    ------
    ParameterError
        Naming the vendor key, its value and the allowed range for a bad or missing value.
    """
    f, motor = _parse(fmt, text, origin)
    if fmt == "odrive":
        R, L, psi, p, i_max = motor
        values = {"motor.R_s": R, "motor.L_d": L, "motor.L_q": L, "motor.psi_pm": psi, "motor.p": p,
                  "controller.i_max": i_max, "sensors.encoder_cpr": f.get("axis0.encoder.config.cpr")}
    else:
        R, Ld, Lq, psi, p, i_max = motor
        values = {"motor.R_s": R, "motor.L_d": Ld, "motor.L_q": Lq, "motor.psi_pm": psi, "motor.p": p,
                  "controller.i_max": i_max}
        if fmt == "moteus":
            has_ratio = f.get("motor_position.rotor_to_output_ratio") is not None
            values["transmission.ratio"] = moteus_ratio(f) if has_ratio else None
    given = {k: _checked(fmt, k, v, f) for k, v in values.items() if v is not None}
    motor_kw = {k.split(".")[1]: v for k, v in given.items() if k.startswith("motor.")}
    sensors = base.sensors if "sensors.encoder_cpr" not in given else dataclasses.replace(
        base.sensors, encoder_cpr=int(given["sensors.encoder_cpr"]))
    transmission = base.transmission if "transmission.ratio" not in given else dataclasses.replace(
        base.transmission, ratio=given["transmission.ratio"])
    params = dataclasses.replace(base, motor=dataclasses.replace(base.motor, **motor_kw), sensors=sensors,
                                 controller=dataclasses.replace(base.controller, i_max=given["controller.i_max"]),
                                 transmission=transmission)
    used = {SOURCES[fmt][k][0] for k in given} | set(ALSO_USED.get(fmt, ()))
    imported = tuple(f"{k} = {v!r} (from {SOURCES[fmt][k][0]})" for k, v in given.items())
    kept = tuple(f"{k} (not in the file; {SOURCES[fmt][k][0]} absent)" for k in values if k not in given)
    not_imported = tuple(escaped(k) for k in tuple(k for k, _ in f.values if k not in used) + f.unknown)
    return DriveImport(params, imported, kept, not_imported)
