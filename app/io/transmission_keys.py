"""Load-side keys at the edge: the load, move and limits typed at the transmission's output.

A preset (or ``--set``) may give the load, the move and the pass criteria at the output of the
transmission (``transmission`` section, :class:`control.fdsmc.transmission.Transmission`) instead of
at the rotor. Each such key names the rotor-side field it sets and how it is reflected; this module
converts them once, before the sections are validated, with the formulas of
:mod:`control.fdsmc.transmission` (θ_r = θ_out·N, J_L = J_out/(η·N²), J_L = m·k²/η for a linear axis
with k = ℓ/(2π·N), …). The physics receives only the rotor-side SI values.

Rotary output keys (``J_L_out``, ``theta_dem_out_deg`` …) need a rotary output; linear ones
(``mass_kg``, ``distance_mm`` …) a lead screw or a pulley (``transmission.lead_mm`` or
``transmission.pulley_radius_mm``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.app.io.units import ALIASES, Alias, spec_of
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc import transmission as tx
from pmsm_commissioning.control.fdsmc.transmission import Transmission


@dataclass(frozen=True)
class OutputKey:
    """A load-side key: the rotor-side field it sets, its reflection and its unit at the output.

    Attributes
    ----------
    field : str                    Rotor-side field of the section (SI).
    reflect : callable             (output value in SI, transmission) → rotor-side value.
    to_si : callable               Typed value → output SI (e.g. mm → m, deg → rad).
    unit : str                     The unit of the typed value, for messages.
    linear : bool                  True for a linear-axis key (needs a lead screw or pulley).
    """

    field: str
    reflect: Callable[[float, Transmission], float]
    to_si: Callable[[float], float]
    unit: str
    linear: bool


def _same(x: float) -> float:
    return x


def _k(scale: float) -> Callable[[float], float]:
    return lambda x: x * scale


_POS, _RPM = tx.position_to_motor, 2.0 * math.pi / 60.0
#: Section → load-side key → its :class:`OutputKey`.
OUTPUT_KEYS: dict[str, dict[str, OutputKey]] = {
    "load": {
        "J_L_out": OutputKey("J_L", tx.inertia_to_motor, _same, "kg·m²", False),
        "J_L_out_kgcm2": OutputKey("J_L", tx.inertia_to_motor, _k(1e-4), "kg·cm²", False),
        "F_v_out": OutputKey("F_v", tx.friction_to_motor, _same, "N·m·s/rad", False),
        "Gamma_Le_out": OutputKey("Gamma_Le", tx.torque_to_motor, _same, "N·m", False),
        "mass_kg": OutputKey("J_L", tx.inertia_to_motor, _same, "kg", True),
        "F_v_lin_Ns_per_m": OutputKey("F_v", tx.friction_to_motor, _same, "N·s/m", True),
        "force_N": OutputKey("Gamma_Le", tx.torque_to_motor, _same, "N", True),
    },
    "manoeuvre": {
        "theta_dem_out": OutputKey("theta_dem", _POS, _same, "rad", False),
        "theta_dem_out_deg": OutputKey("theta_dem", _POS, math.radians, "deg", False),
        "theta_dem_out_rev": OutputKey("theta_dem", _POS, _k(2.0 * math.pi), "rev", False),
        "distance_mm": OutputKey("theta_dem", _POS, _k(1e-3), "mm", True),
    },
    "limits": {
        "in_position_out": OutputKey("in_position", _POS, _same, "rad", False),
        "in_position_out_deg": OutputKey("in_position", _POS, math.radians, "deg", False),
        "overshoot_out": OutputKey("overshoot", _POS, _same, "rad", False),
        "overshoot_out_deg": OutputKey("overshoot", _POS, math.radians, "deg", False),
        "omega_max_out": OutputKey("omega_max", _POS, _same, "rad/s", False),
        "omega_max_out_rpm": OutputKey("omega_max", _POS, _k(_RPM), "rpm", False),
        "in_position_um": OutputKey("in_position", _POS, _k(1e-6), "µm", True),
        "overshoot_um": OutputKey("overshoot", _POS, _k(1e-6), "µm", True),
        "speed_max_mm_s": OutputKey("omega_max", _POS, _k(1e-3), "mm/s", True),
    },
}


def target_of(section: str, key: str) -> str | None:
    """Return the rotor-side field a load-side ``section.key`` sets, None if it is not one."""
    spec = OUTPUT_KEYS.get(section, {}).get(key)
    return None if spec is None else spec.field


def as_aliases(section: str) -> dict[str, Alias]:
    """Return the load-side keys of ``section`` as aliases of their rotor-side field (an override replaces either)."""
    return {k: Alias(o.field, o.to_si, o.unit) for k, o in OUTPUT_KEYS.get(section, {}).items()}


def output_keys_in(raw: Any) -> list[tuple[str, str]]:
    """(section, key) of every load-side key a raw preset mapping holds."""
    if not isinstance(raw, dict):
        return []
    return [(s, str(k)) for s, keys in OUTPUT_KEYS.items() if isinstance(raw.get(s), dict)
            for k in raw[s] if str(k) in keys]


def _where(tr: Transmission) -> str:
    return ("a linear axis (transmission.lead_mm or transmission.pulley_radius_mm > 0)" if not tr.linear
            else "a rotary output (transmission.lead_mm = transmission.pulley_radius_mm = 0)")


def to_motor_side(raw: dict[str, Any], tr: Transmission, number: Callable[[str, Any], float]) -> dict[str, Any]:
    """Return ``raw`` (a copy) with every load-side key replaced by its rotor-side field.

    Parameters
    ----------
    raw : dict            The preset mapping (its sections hold typed values).
    tr : Transmission     The preset's transmission (already validated).
    number : callable     (``section.key``, value) → float: the loader's number parser.

    Raises
    ------
    ValueError
        A key of the wrong kind of axis, or a field given both at the rotor and at the output;
        the message names the key, the value and what is allowed.
    """
    out = dict(raw)
    for section, key in output_keys_in(raw):
        spec = OUTPUT_KEYS[section][key]
        x = number(f"{section}.{key}", out[section][key])
        if spec.linear != tr.linear:
            raise ValueError(f"{section}.{key} = {x!r} {spec.unit} is not allowed here: allowed with {_where(tr)}")
        sec = {k: v for k, v in out[section].items() if k != key}
        if any(_field(section, str(k)) == spec.field for k in sec):
            raise ValueError(f"{section}.{spec.field} is given more than once (at the rotor and as {section}.{key})")
        sec[spec.field] = _checked(section, key, x, spec.reflect(spec.to_si(x), tr))
        out[section] = sec
    return out


def _field(section: str, key: str) -> str:
    """Return the rotor-side field any key of ``section`` sets (SI name, unit-suffixed or load-side)."""
    alias = ALIASES.get(section, {}).get(key)
    return alias.field if alias is not None else (target_of(section, key) or key)


def _checked(section: str, key: str, typed: float, value: float) -> float:
    """Return the reflected ``value`` if its field's range allows it, else name the typed key and value."""
    spec = OUTPUT_KEYS[section][key]
    try:
        spec_of(f"{section}.{spec.field}").check(f"{section}.{spec.field}", value)
    except ParameterError as exc:
        raise ValueError(f"{section}.{key} = {typed!r} {spec.unit} gives {exc}") from None
    return value


__all__ = ["OUTPUT_KEYS", "OutputKey", "as_aliases", "output_keys_in", "target_of", "to_motor_side"]
