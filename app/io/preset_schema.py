"""Preset schema: raw mappings (texts, lists, mappings) → the modes' parameter dataclasses.

What a preset may hold and how each value is checked, independent of the file format: the top-level
keys, one section per field group of the mode's dataclass, unit-suffixed keys converted through
:mod:`app.io.units`, the optional ``plant`` section of a position preset, the ``units`` table of an
exported file and the schema-1 → 2 migration. :mod:`app.io.presets` (the only YAML reader and
writer) turns text into the raw mapping this module parses.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import types
import typing
from typing import Any

from pmsm_commissioning.app.io import motor_defaults, transmission_keys, units
from pmsm_commissioning.app.io.modes import MODES as _MODES
from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_integer, parse_number, shorten, shown
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.transmission import Transmission

SCHEMA = 2
#: Schemas read: 1 (inputs only) is migrated to 2 (adds the informational export sections).
SCHEMAS_READ = (1, 2)
_TOP_KEYS = ("schema", "name", "source", "mode")
#: Optional top-level section of a position preset: the plant's true values (see parse_plant).
PLANT = "plant"
#: The sections whose fields a plant section may give.
PLANT_SECTIONS = ("motor", "load")
#: Top-level keys an exported drive parameter file adds; informational, ignored on import (the
#: gains are recomputed from the inputs).
_EXPORT_KEYS = ("exported_by", "units", "drive_gains", "verdicts", "results", "inherited")

#: Parameter dataclass per preset mode: a view of the one registry :mod:`app.io.modes`.
MODES: dict[str, type] = dict(_MODES)


class PresetError(ValueError):
    """A preset file or override that cannot be loaded; the message says what and where."""


def hint(key: str, allowed: list[str]) -> str:
    """Return a " — did you mean …?" (or the allowed keys) suffix for an unknown ``key``."""
    close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.5)
    return f" — did you mean '{close[0]}'?" if close else f" (allowed: {', '.join(allowed)})"


def _describe(tp: Any) -> str:
    if tp is float:
        return "a number"
    if tp is int:
        return "an integer"
    if tp is str:
        return "a text"
    if isinstance(tp, types.UnionType):
        return " or ".join(_describe(a) for a in typing.get_args(tp))
    return "a list of mappings"


def number_of(name: str, value: Any, tp: type) -> Any:
    """Return a number field's value: text is parsed, a number from JSON/Python data is kept.

    Text is parsed by :mod:`app.io.numbers` (decimal or scientific notation only; an integer field takes whole
    numbers only).
    """
    try:
        if isinstance(value, str):
            return parse_integer(value, name) if tp is int else parse_number(value, name)
    except NumberFormatError as exc:
        raise PresetError(str(exc)) from None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise PresetError(f"{name} = {shown(value)} has the wrong type: allowed {_describe(tp)}")
    if tp is int:  # 4.0 → 4; 2.5, nan … go to the dataclass, which names the allowed range
        return int(value) if math.isfinite(value) and float(value).is_integer() else value
    return float(value)


def _coerce(name: str, value: Any, tp: Any) -> Any:
    """Check ``value`` against the annotation ``tp``; parse nested dataclasses."""
    if tp in (float, int):
        return number_of(name, value, tp)
    if tp is str and isinstance(value, str):
        return str(value)  # plain text, whether the file quoted it or not
    if isinstance(tp, types.UnionType):  # e.g. float | str: a number, else the keyword text
        args = typing.get_args(tp)
        if float in args and isinstance(value, str) and str in args:
            try:
                return number_of(name, value, float)
            except PresetError:
                return value
        for arg in args:
            try:
                return _coerce(name, value, arg)
            except PresetError:
                continue
    if typing.get_origin(tp) is tuple and isinstance(value, list):
        item = typing.get_args(tp)[0]
        if item is float:  # a list of numbers, e.g. a sampled back-EMF period
            return tuple(_coerce(f"{name}[{i}]", v, float) for i, v in enumerate(value))
        return tuple(_parse_section(item, v, f"{name}[{i}]") for i, v in enumerate(value))
    raise PresetError(f"{name} = {shown(value)} has the wrong type: allowed {_describe(tp)}")


def _parse_section(cls: type, raw: Any, section: str) -> Any:
    """Build dataclass ``cls`` from mapping ``raw``; ``section`` names it in messages."""
    if not isinstance(raw, dict):
        raise PresetError(f"{section} must be a mapping of field: value, got {raw!r}")
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    aliases = units.aliases_of(cls)  # the unit-suffixed keys declared by the field specs
    extra = list(units.FLUX_KEYS) if "psi_pm" in names else []
    allowed = names + list(aliases) + extra
    values: dict[str, Any] = {}
    for key, value in raw.items():
        key = str(key)
        if key in names:
            target = key
            values[key] = _coerce(f"{section}.{key}", value, hints[key])
        elif key in aliases:
            target = aliases[key].field
            number = _coerce(f"{section}.{key}", value, float)
            values[target] = aliases[key].convert(number)
        elif key in extra:
            target = "psi_pm"
            ke = _coerce(f"{section}.{key}", value, float)
            try:
                p = number_of(f"{section}.p", raw.get("p"), int)
            except PresetError:
                p = 0
            if p < 1:
                raise PresetError(f"{section}.{key} needs a valid {section}.p (pole pairs) beside it")
            values[target] = units.FLUX_KEYS[key](ke, p)
        else:
            raise PresetError(f"unknown key {shorten(f'{section}.{key}')}{key_hint(key, allowed)}")
        if sum(1 for k in raw if field_of(str(k), aliases, extra) == target) > 1:
            raise PresetError(f"{section}.{target} is given more than once (SI and unit-suffixed forms)")
    missing = [
        f.name for f in dataclasses.fields(cls)
        if f.name not in values and f.default is dataclasses.MISSING
        and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise PresetError(f"missing key(s) in {section}: {', '.join(missing)}")
    return cls(**values)


def key_hint(key: str, allowed: list[str]) -> str:
    """Return :func:`hint`, except near a flux key: then every flux key with its unit, never one guess.

    The flux keys differ by their unit only (Kt per A rms or per A peak, Ke rms or peak): pointing
    a per-A-peak value at the rms key would make Ψ_PM √2 too small.
    """
    close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.5)
    if close and close[0] in units.FLUX_KEY_MEANING:
        keys = ", ".join(f"{k} [{m}]" for k, m in units.FLUX_KEY_MEANING.items())
        return f" — flux keys: {keys}"
    return hint(key, allowed)


def position_edge(raw: dict[str, Any]) -> tuple[dict[str, Any], tuple[str, ...]]:
    """Return (``raw`` with load-side keys reflected to the rotor, the motor fields to derive).

    Load-side keys (:mod:`app.io.transmission_keys`) are converted with the preset's transmission;
    absent or ``derived`` rated values (:mod:`app.io.motor_defaults`) get a stand-in, replaced by
    :func:`~app.io.motor_defaults.derive_motor` once the controller section is validated.
    """
    fields = motor_defaults.derived_fields(raw)
    raw = motor_defaults.with_placeholders(raw, fields)
    if transmission_keys.output_keys_in(raw):
        tr = _parse_section(Transmission, raw.get("transmission", {}), "transmission")
        try:
            raw = transmission_keys.to_motor_side(raw, tr, lambda name, v: number_of(name, v, float))
        except ValueError as exc:
            raise PresetError(str(exc)) from None
    return raw, fields


def field_of(key: str, aliases: dict[str, units.Alias], extra: list[str]) -> str:
    """Return the field a preset key sets (a unit-suffixed alias names its SI field)."""
    if key in aliases:
        return aliases[key].field
    return "psi_pm" if key in extra else key


def parse_preset(raw: Any) -> Any:
    """Validate a preset mapping and return its parameter object (e.g. :class:`DriveParams`).

    Raises
    ------
    PresetError, ParameterError
        With a message naming the field, the value and the allowed range or type.
    """
    if not isinstance(raw, dict):
        raise PresetError("a preset must be a mapping: allowed a YAML or JSON mapping with schema, name, "
                          "source and sections")
    raw = migrate(raw)
    mode = raw.get("mode", "position")
    if not isinstance(mode, str) or mode not in MODES:
        raise PresetError(f"mode = {shown(mode)} is not known{hint(str(mode), list(MODES))}")
    cls = MODES[mode]
    sections = [f.name for f in dataclasses.fields(cls) if f.name not in ("name", "source")]
    allowed = list(_TOP_KEYS) + list(_EXPORT_KEYS) + list(sections) + ([PLANT] if cls is DriveParams else [])
    for key in raw:
        if key not in allowed:
            raise PresetError(f"unknown top-level key {shown(key)}{hint(str(key), allowed)}")
    derived: tuple[str, ...] = ()
    if cls is DriveParams:
        raw, derived = position_edge(raw)
    hints = typing.get_type_hints(cls)
    kwargs: dict[str, Any] = {}
    optional = optional_sections(cls)
    for name in sections:
        if name not in raw and name in optional:
            continue  # an optional section (sensors, limits): its defaults
        if name not in raw:
            raise PresetError(f"missing section {name!r} (allowed sections: {', '.join(sections)})")
        kwargs[name] = _parse_section(hints[name], raw[name], name)
    for key in ("name", "source"):
        if key not in raw:
            raise PresetError(f"missing key {key!r}: every preset names itself and its source")
        kwargs[key] = _coerce(key, raw[key], str)
    _check_units(raw.get("units"), sections)
    if derived:
        try:
            kwargs["motor"] = motor_defaults.derive_motor(kwargs["motor"], kwargs["controller"], derived)
        except ParameterError as exc:
            raise PresetError(str(exc)) from None
    params = cls(**kwargs)
    if cls is DriveParams:
        parse_plant(raw, params)  # validated with the rest of the file, even where only the model is used
    return params


def optional_sections(cls: type) -> tuple[str, ...]:
    """Sections of a mode's dataclass that a preset may leave out (they have defaults, e.g. ``sensors``)."""
    if not dataclasses.is_dataclass(cls):
        return ()
    return tuple(f.name for f in dataclasses.fields(cls) if dataclasses.is_dataclass(f.default))


def plant_fields() -> dict[str, str]:
    """Every key a plant section accepts (SI names, unit-suffixed aliases, Ke) → ``motor``/``load``."""
    out: dict[str, str] = {}
    hints = typing.get_type_hints(DriveParams)
    for section in PLANT_SECTIONS:
        names = [f.name for f in dataclasses.fields(hints[section]) if f.name != "steps"]
        out.update(dict.fromkeys(names + list(units.ALIASES.get(section, {})), section))
    out.update(dict.fromkeys(units.FLUX_KEYS, "motor"))
    return out


def _plant_error(exc: Exception, section: str) -> PresetError:
    """Return the message of a motor/load error, naming the field as ``plant.FIELD``."""
    return PresetError(str(exc).replace(f"{section}.", f"{PLANT}.", 1))


def parse_plant(raw: Any, params: DriveParams) -> DriveParams | None:
    """Return the plant of a raw preset.

    That is ``params`` with the motor and load values of its ``plant`` mapping; None without one
    (or when it equals the controller's model).

    Raises
    ------
    PresetError
        For a key that is not a motor or load field, a wrong type or a value out of range; the
        message names ``plant.FIELD``, the value and what is allowed.
    """
    block = raw.get(PLANT) if isinstance(raw, dict) else None
    if block is None or block == {}:
        return None
    if not isinstance(block, dict):
        raise PresetError(f"plant must be a mapping of FIELD: value (motor and load fields), got {block!r}")
    known = plant_fields()
    split: dict[str, dict[str, Any]] = {s: {} for s in PLANT_SECTIONS}
    for key, value in block.items():
        if str(key) not in known:
            raise PresetError(f"unknown key {shorten(f'plant.{key}')}{hint(str(key), list(known))}")
        split[known[str(key)]][str(key)] = value
    hints = typing.get_type_hints(DriveParams)
    parts: dict[str, Any] = {}
    for section in PLANT_SECTIONS:
        base = getattr(params, section)
        aliases = units.ALIASES.get(section, {})
        given = {field_of(k, aliases, list(units.FLUX_KEYS)) for k in split[section]}
        if len(given) < len(split[section]):
            raise PresetError(f"plant gives a {section} field more than once (SI and unit-suffixed forms): "
                              f"{', '.join(split[section])}")
        merged = {k: v for k, v in plain(base).items() if k not in given} | split[section]
        try:
            parts[section] = _parse_section(hints[section], merged, section)
        except (PresetError, ParameterError) as exc:
            raise _plant_error(exc, section) from None
    plant = dataclasses.replace(params, **parts)
    return None if plant == params else plant


def plant_raw(params: DriveParams, plant: DriveParams | None) -> dict[str, Any]:
    """Return the ``plant`` mapping of a preset.

    That is the plant's motor and load values (SI) that differ from the controller's model
    ``params``; empty when there is no plant.
    """
    if plant is None:
        return {}
    out: dict[str, Any] = {}
    for section in PLANT_SECTIONS:
        model, true = plain(getattr(params, section)), plain(getattr(plant, section))
        if true.get("steps", []) != model.get("steps", []):
            raise PresetError("plant.steps is not allowed: the load steps are the load section's")
        out.update({k: v for k, v in true.items() if k != "steps" and v != model[k]})
    return out


def migrate(raw: dict[str, Any]) -> dict[str, Any]:
    """Upgrade a schema-1 mapping to schema 2 (a copy); schema 2 unchanged; other schemas refused.

    Schema 1 holds the inputs only; its drive parameter exports added ``exported_from`` and a flat
    ``drive_gains`` (YAML) or wrapped the inputs as ``{"tool", "preset", "inputs", "gains",
    "derived"}`` (JSON). Their informational parts are dropped (the gains are recomputed).
    """
    schema = schema_of(raw.get("schema"))
    if schema not in SCHEMAS_READ:
        raise PresetError(f"schema = {raw.get('schema')!r} is not supported: allowed schema: "
                          f"{' or '.join(map(str, SCHEMAS_READ))}")
    if schema == SCHEMA:
        return raw
    if isinstance(raw.get("inputs"), dict) and "tool" in raw:  # schema-1 JSON export
        raw = raw["inputs"]
    out = {k: v for k, v in raw.items() if k not in ("exported_from", "drive_gains")}
    out["schema"] = SCHEMA
    return out


def _check_units(table: Any, sections: list[str]) -> None:
    """Check that an exported file's ``units`` section states the SI unit of each value it names."""
    if table is None:
        return
    if not isinstance(table, dict):
        raise PresetError(f"units must be a mapping of section: {{field: unit}}, got {table!r}")
    for section, fields in table.items():
        expected = units.SI_UNITS.get(str(section))
        if section not in sections or expected is None or not isinstance(fields, dict):
            raise PresetError(f"units.{section} is not a section of this preset{hint(str(section), sections)}")
        for name, unit in fields.items():
            if name in expected and unit != expected[name]:
                raise PresetError(f"units.{section}.{name} = {unit!r} is not allowed: values in this file are SI "
                                  f"({expected[name]!r}); write a unit-suffixed key (e.g. L_d_mH) for other units")


def schema_of(value: Any) -> int | None:
    """Return the schema number of a preset (text or int), None if it is not a whole number."""
    try:
        return number_of("schema", value, int)
    except PresetError:
        return None


def plain(value: Any) -> Any:
    """Return ``value`` with dataclasses as dicts and tuples as lists (what a YAML/JSON writer takes)."""
    if dataclasses.is_dataclass(value):
        return {f.name: plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, tuple | list):
        return [plain(v) for v in value]
    return value
