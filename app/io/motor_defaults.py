"""Rated values a robotics datasheet lacks: V_0, P_r and ω_b derived from the inverter, at the edge.

A hobby or robotics datasheet (ODrive, moteus, VESC motors) gives Kv or Kt, R, L, the pole pairs and
a peak torque, but no rated voltage, power or speed. A preset may then leave ``motor.V_0``,
``motor.P_r`` and ``motor.omega_b`` out (or write ``derived``) when ``controller.V_dc`` > 0; the
loader fills them with :func:`control.fdsmc.nameplate.rated_from_inverter` (V_0 = V_dc/√2; ω_b the
speed where the peak torque's voltage reaches V_dc/√3; P_r = Γ_lim·ω_b). Every output labels them
"derived"; the nameplate checks that compare them (rated torque P_r/ω_b ≤ Γ_max, back-EMF and
voltage at ω_b) then hold by construction and check nothing, and the paper's α_max rule
(H·P_r/V_0) is refused.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from pmsm_commissioning.app.io import units
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.nameplate import rated_from_inverter
from pmsm_commissioning.control.fdsmc.params import Controller, Motor

#: The motor fields that may be derived, and the text that asks for it explicitly.
DERIVABLE = ("V_0", "P_r", "omega_b")
DERIVED = "derived"
#: A valid stand-in while the other sections are validated (replaced before anything uses it).
_PLACEHOLDER = 1.0


def _field(key: str) -> str:
    alias = units.ALIASES["motor"].get(key)
    return alias.field if alias is not None else key


def _asks(value: Any) -> bool:
    return isinstance(value, str) and value.strip() == DERIVED


def derived_fields(raw: Any) -> tuple[str, ...]:
    """Motor fields of ``raw`` (a preset mapping) that are absent or ``derived``: the loader derives them."""
    motor = raw.get("motor") if isinstance(raw, dict) else None
    if not isinstance(motor, dict):
        return ()
    given = {_field(str(k)) for k, v in motor.items() if not _asks(v)}
    return tuple(f for f in DERIVABLE if f not in given)


def with_placeholders(raw: dict[str, Any], fields: tuple[str, ...]) -> dict[str, Any]:
    """Return ``raw`` (a copy) with the derived ``fields`` set to a valid stand-in."""
    if not fields:
        return raw
    motor = {k: v for k, v in raw["motor"].items() if _field(str(k)) not in fields}
    return {**raw, "motor": motor | dict.fromkeys(fields, _PLACEHOLDER)}


def derive_motor(motor: Motor, controller: Controller, fields: tuple[str, ...]) -> Motor:
    """Return ``motor`` with the derived ``fields`` computed from the inverter (see the module doc).

    Raises
    ------
    ParameterError
        Without a DC link, with the paper's α_max rule (it needs the datasheet's P_r and V_0), or when
        the winding's resistive drop leaves no voltage for a rated speed.
    """
    if not fields:
        return motor
    if controller.V_dc <= 0.0:
        raise ParameterError(f"missing key(s) in motor: {', '.join(fields)} (allowed to be left out only with "
                             f"controller.V_dc > 0, then derived from it; controller.V_dc = {controller.V_dc!r} V)")
    if controller.alpha_max_rule == "paper" and ("P_r" in fields or "V_0" in fields):
        raise ParameterError("controller.alpha_max_rule = 'paper' needs the datasheet's motor.P_r and motor.V_0 "
                             "(H·P_r/V_0), here derived: allowed torque_limit or min_energy")
    V_0, P_r, omega_b = rated_from_inverter(motor, controller.V_dc, controller.i_max)
    values = {"V_0": V_0, "P_r": P_r, "omega_b": omega_b}
    return dataclasses.replace(motor, **{f: values[f] for f in fields})


#: The rule of each derived field, as every output states it.
RULES = {"V_0": "V_dc/√2", "P_r": "Γ_lim·ω_b, the peak torque's power at ω_b, not a thermal rating",
         "omega_b": "the speed where the peak torque's voltage reaches V_dc/√3"}


def derived_text(motor: Motor, fields: tuple[str, ...]) -> list[str]:
    """One line per derived field with its value and rule, for every output ("derived" label)."""
    shown = {"V_0": (motor.V_0, "V"), "P_r": (motor.P_r, "W"), "omega_b": (units.rad_s_to_rpm(motor.omega_b), "rpm")}
    return [f"motor.{f} = {shown[f][0]:.4g} {shown[f][1]} (derived: {RULES[f]})" for f in fields]


__all__ = ["DERIVABLE", "DERIVED", "RULES", "derive_motor", "derived_fields", "derived_text", "with_placeholders"]
