"""Preset loader and writer: the only module that reads or writes YAML.

A preset is a YAML mapping with ``schema: 1``, ``name``, ``source``, an optional ``mode``
(``position``, the default, or another registered mode) and one mapping per section of the
mode's parameter dataclass. Loading is safe (``yaml.safe_load``, no aliases, size-limited),
rejects unknown keys with a "did you mean" hint, missing keys and wrong types, and converts
unit-suffixed keys (``L_d_mH``, ``omega_b_rpm``, ``Ke_Vrms_krpm`` …) through :mod:`app.io.units`.
Saving writes SI field names only, so load → save → load gives equal objects.

A position preset may carry an optional ``plant`` mapping: the true motor and load values of the
simulated drive where they differ from the controller's model (the ``motor`` and ``load``
sections), with the same keys and unit suffixes as those sections (``plant: {J_L: 0.3,
R_s: 0.12}``); see :func:`parse_plant`.
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import math
import re
import types
import typing
from pathlib import Path
from typing import Any

import yaml

from app.io import units
from app.io.numbers import NumberFormatError, parse_integer, parse_number
from control.bldc.params import BldcParams
from control.common.checks import ParameterError, field_specs
from control.fdsmc.params import DriveParams

SCHEMA = 2
#: Schemas read: 1 (inputs only) is migrated to 2 (adds the informational export sections).
SCHEMAS_READ = (1, 2)
PRESET_DIR = Path(__file__).resolve().parents[2] / "presets"
MAX_BYTES = 256 * 1024
#: The page's start-up preset: a real catalogue servo with a verified clean design.
DEFAULT_PRESET = "siemens_1ft7044_ak7"
#: The FDSMC paper's drive (section 5 of [1]), for reproduction.
PAPER_PRESET = "paper_12kw_pmsm"
_TOP_KEYS = ("schema", "name", "source", "mode")
#: Optional top-level section of a position preset: the plant's true values (see parse_plant).
PLANT = "plant"
#: The sections whose fields a plant section may give.
PLANT_SECTIONS = ("motor", "load")
#: Top-level keys an exported drive parameter file adds; informational, ignored on import (the
#: gains are recomputed from the inputs).
_EXPORT_KEYS = ("exported_by", "units", "drive_gains", "verdicts", "results")

#: Parameter dataclass per preset mode. Other modes register themselves here.
MODES: dict[str, type] = {"position": DriveParams}
MODES["bldc"] = BldcParams


class PresetError(ValueError):
    """A preset file or override that cannot be loaded; the message says what and where."""


def _hint(key: str, allowed: list[str]) -> str:
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


def _number(name: str, value: Any, tp: type) -> Any:
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
        raise PresetError(f"{name} = {value!r} has the wrong type: allowed {_describe(tp)}")
    if tp is int:  # 4.0 → 4; 2.5, nan … go to the dataclass, which names the allowed range
        return int(value) if math.isfinite(value) and float(value).is_integer() else value
    return float(value)


def _coerce(name: str, value: Any, tp: Any) -> Any:
    """Check ``value`` against the annotation ``tp``; parse nested dataclasses."""
    if tp in (float, int):
        return _number(name, value, tp)
    if tp is str and isinstance(value, str):
        return value
    if isinstance(tp, types.UnionType):  # e.g. float | str: a number, else the keyword text
        args = typing.get_args(tp)
        if float in args and isinstance(value, str) and str in args:
            try:
                return _number(name, value, float)
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
    raise PresetError(f"{name} = {value!r} has the wrong type: allowed {_describe(tp)}")


def _parse_section(cls: type, raw: Any, section: str) -> Any:
    """Build dataclass ``cls`` from mapping ``raw``; ``section`` names it in messages."""
    if not isinstance(raw, dict):
        raise PresetError(f"{section} must be a mapping of field: value, got {raw!r}")
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    aliases = units.aliases_of(cls)  # the unit-suffixed keys declared by the field specs
    extra = [units.KE_KEY] if "psi_pm" in names else []
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
                p = _number(f"{section}.p", raw.get("p"), int)
            except PresetError:
                p = 0
            if p < 1:
                raise PresetError(f"{section}.{key} needs a valid {section}.p (pole pairs) beside it")
            values[target] = units.ke_vrms_krpm_to_psi_pm(ke, p)
        else:
            raise PresetError(f"unknown key {section}.{key}{_hint(key, allowed)}")
        if sum(1 for k in raw if _field_of(str(k), aliases, extra) == target) > 1:
            raise PresetError(f"{section}.{target} is given more than once (SI and unit-suffixed forms)")
    missing = [
        f.name for f in dataclasses.fields(cls)
        if f.name not in values and f.default is dataclasses.MISSING
        and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise PresetError(f"missing key(s) in {section}: {', '.join(missing)}")
    return cls(**values)


def _field_of(key: str, aliases: dict[str, units.Alias], extra: list[str]) -> str:
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
    if mode not in MODES:
        raise PresetError(f"mode = {mode!r} is not known{_hint(str(mode), list(MODES))}")
    cls = MODES[mode]
    sections = [f.name for f in dataclasses.fields(cls) if f.name not in ("name", "source")]
    allowed = list(_TOP_KEYS) + list(_EXPORT_KEYS) + list(sections) + ([PLANT] if cls is DriveParams else [])
    for key in raw:
        if key not in allowed:
            raise PresetError(f"unknown top-level key {key!r}{_hint(str(key), allowed)}")
    hints = typing.get_type_hints(cls)
    kwargs: dict[str, Any] = {}
    for name in sections:
        if name not in raw:
            raise PresetError(f"missing section {name!r} (allowed sections: {', '.join(sections)})")
        kwargs[name] = _parse_section(hints[name], raw[name], name)
    for key in ("name", "source"):
        if key not in raw:
            raise PresetError(f"missing key {key!r}: every preset names itself and its source")
        kwargs[key] = _coerce(key, raw[key], str)
    _check_units(raw.get("units"), sections)
    params = cls(**kwargs)
    if cls is DriveParams:
        parse_plant(raw, params)  # validated with the rest of the file, even where only the model is used
    return params


def plant_fields() -> dict[str, str]:
    """Every key a plant section accepts (SI names, unit-suffixed aliases, Ke) → ``motor``/``load``."""
    out: dict[str, str] = {}
    hints = typing.get_type_hints(DriveParams)
    for section in PLANT_SECTIONS:
        names = [f.name for f in dataclasses.fields(hints[section]) if f.name != "steps"]
        out.update(dict.fromkeys(names + list(units.ALIASES.get(section, {})), section))
    out[units.KE_KEY] = "motor"
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
            raise PresetError(f"unknown key plant.{key}{_hint(str(key), list(known))}")
        split[known[str(key)]][str(key)] = value
    hints = typing.get_type_hints(DriveParams)
    parts: dict[str, Any] = {}
    for section in PLANT_SECTIONS:
        base = getattr(params, section)
        aliases = units.ALIASES.get(section, {})
        given = {_field_of(k, aliases, [units.KE_KEY]) for k in split[section]}
        if len(given) < len(split[section]):
            raise PresetError(f"plant gives a {section} field more than once (SI and unit-suffixed forms): "
                              f"{', '.join(split[section])}")
        merged = {k: v for k, v in _plain(base).items() if k not in given} | split[section]
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
        model, true = _plain(getattr(params, section)), _plain(getattr(plant, section))
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
    schema = _schema(raw.get("schema"))
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
            raise PresetError(f"units.{section} is not a section of this preset{_hint(str(section), sections)}")
        for name, unit in fields.items():
            if name in expected and unit != expected[name]:
                raise PresetError(f"units.{section}.{name} = {unit!r} is not allowed: values in this file are SI "
                                  f"({expected[name]!r}); write a unit-suffixed key (e.g. L_d_mH) for other units")


# ---- YAML front-end: text → raw mapping of texts, lists and mappings -------------------------
#: Deepest nesting of brackets / block indentation levels a preset may have (presets need 4).
MAX_DEPTH = 32
#: Widest indentation of a line [columns] (bounds block nesting the same way).
MAX_INDENT = 128


class _TextLoader(yaml.SafeLoader):
    """Safe YAML loader that keeps every scalar as text: no YAML 1.1 implicit typing.

    Without it ``1:30`` → 90, ``017`` → 15, and ``0x10``, ``1_000``, ``yes`` → True … would be converted.
    Numbers are parsed afterwards by :mod:`app.io.numbers` against the field types; duplicate keys and
    explicit tags are errors.
    """


_TextLoader.yaml_implicit_resolvers = {}


def _mark(node: yaml.Node) -> str:
    return f"line {node.start_mark.line + 1}, column {node.start_mark.column + 1}"


def _refuse_tag(loader: _TextLoader, node: yaml.Node) -> Any:
    raise PresetError(f"YAML tag {node.tag!r} at {_mark(node)} is not allowed: write plain values")


def _unique_mapping(loader: _TextLoader, node: yaml.MappingNode) -> dict[Any, Any]:
    out: dict[Any, Any] = {}
    first: dict[Any, str] = {}
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        if not isinstance(key, str):
            raise PresetError(f"key at {_mark(key_node)} is not a name: allowed text keys only")
        if key in out:
            raise PresetError(f"duplicate key {key!r} at {_mark(key_node)} (first at {first[key]}): "
                              "allowed each key once per mapping")
        first[key] = _mark(key_node)
        out[key] = loader.construct_object(value_node, deep=True)
    return out


for _tag in ("null", "bool", "int", "float", "binary", "timestamp", "omap", "pairs", "set", "merge", "value"):
    _TextLoader.add_constructor(f"tag:yaml.org,2002:{_tag}", _refuse_tag)
_TextLoader.add_constructor(None, _refuse_tag)
_TextLoader.add_constructor("tag:yaml.org,2002:map", _unique_mapping)


def check_structure(text: str, origin: str) -> None:
    """Cheap pre-scan before parsing: bracket nesting ≤ MAX_DEPTH, indentation ≤ MAX_INDENT.

    Deeply nested flow collections (``[[[[…]]]]``) make a YAML parser's time grow faster than
    the text; this linear scan refuses them first. Quotes and comments are skipped.
    """
    depth = 0
    for number, line in enumerate(text.splitlines(), 1):
        indent = len(line) - len(line.lstrip(" -"))
        if indent > MAX_INDENT:
            raise PresetError(f"{origin} line {number} is indented {indent} columns: allowed ≤ {MAX_INDENT}")
        quote = ""
        for ch in line:
            if quote:
                quote = "" if ch == quote else quote
            elif ch in "'\"":
                quote = ch
            elif ch == "#":
                break
            elif ch in "[{":
                depth += 1
                if depth > MAX_DEPTH:
                    raise PresetError(f"{origin} is nested too deeply at line {number}: allowed ≤ {MAX_DEPTH} "
                                      "levels of brackets")
            elif ch in "]}":
                depth = max(0, depth - 1)


def _check_no_aliases(text: str) -> None:
    for event in yaml.parse(text, Loader=_TextLoader):
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:  # &name too
            raise PresetError("YAML anchors/aliases (*name) are not allowed in presets")


def loads_raw(text: str, origin: str = "<text>") -> Any:
    """Parse YAML text safely into plain data whose scalars are all text (see :class:`_TextLoader`).

    Size-limited, shallow, no aliases, no duplicate keys.
    """
    if len(text) > MAX_BYTES or len(text.encode("utf-8", "replace")) > MAX_BYTES:
        raise PresetError(f"{origin} is too large: allowed ≤ {MAX_BYTES // 1024} KiB")
    check_structure(text, origin)
    try:
        _check_no_aliases(text)
        return yaml.load(text, Loader=_TextLoader)  # noqa: S506 - a SafeLoader subclass
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise PresetError(f"{origin} is not valid YAML{where}: {problem}: allowed plain YAML text") from None
    except RecursionError:
        raise PresetError(f"{origin} is nested too deeply: allowed ≤ {MAX_DEPTH} levels") from None
    except PresetError as exc:  # duplicate key, tag: say where
        raise PresetError(f"{origin}: {exc}") from None


def _schema(value: Any) -> int | None:
    """Return the schema number of a preset (text or int), None if it is not a whole number."""
    try:
        return _number("schema", value, int)
    except PresetError:
        return None


def apply_overrides(raw: Any, overrides: typing.Iterable[str]) -> Any:
    """Apply ``section.field=value`` overrides (values parsed as YAML scalars) to a raw preset."""
    if not isinstance(raw, dict):
        raise PresetError("overrides need a preset mapping to apply to")
    for item in overrides:
        key, sep, text = item.partition("=")
        section, dot, name = key.strip().partition(".")
        if not sep or not dot or not name:
            raise PresetError(f"--set {item!r} is malformed: allowed form section.field=value")
        if section == PLANT and raw.get(PLANT) is None and raw.get("mode", "position") == "position":
            raw[PLANT] = {}
        if not isinstance(raw.get(section), dict):
            known = [k for k, v in raw.items() if isinstance(v, dict)]
            raise PresetError(f"--set {item!r}: unknown section {section!r}{_hint(section, known)}")
        value = loads_raw(text, f"--set {key}") if text.strip() else None
        if value is None:
            raise PresetError(f"--set {item!r} has no value: allowed section.field=value, e.g. manoeuvre.T_m=1.4")
        aliases = units.ALIASES.get(section, {}) if section != PLANT else (
            units.ALIASES["motor"] | units.ALIASES["load"])
        target = _field_of(name, aliases, [units.KE_KEY])
        for other in [k for k in raw[section] if _field_of(str(k), aliases, [units.KE_KEY]) == target]:
            del raw[section][other]  # an override replaces the value in any unit form
        raw[section][name] = value
    return raw


#: Longest preset name or path accepted [characters].
MAX_NAME = 1024


def resolve(name_or_path: str) -> Path:
    """Preset name (file stem in ``presets/``) or path (YAML or JSON) → path; a clear error if absent."""
    if len(name_or_path) > MAX_NAME:
        raise PresetError(f"preset name {name_or_path[:40]!r}… has {len(name_or_path)} characters: "
                          f"allowed ≤ {MAX_NAME}")
    path = Path(name_or_path)
    try:
        if path.suffix in (".yaml", ".yml", ".json") and path.is_file():
            return path
        candidate = PRESET_DIR / f"{name_or_path}.yaml"
        if "/" not in name_or_path and "\\" not in name_or_path and candidate.is_file():
            return candidate
    except (OSError, ValueError):  # name too long for the file system, NUL byte …
        pass
    raise PresetError(f"preset {name_or_path!r} not found{_hint(str(name_or_path), list_presets())}")


def list_presets() -> list[str]:
    """Names of the shipped presets."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def load_raw(name_or_path: str) -> Any:
    """Read a preset file (by name or path) into raw data, without validating sections."""
    path = resolve(name_or_path)
    try:
        if path.stat().st_size > MAX_BYTES:  # before reading it
            raise PresetError(f"{path.name} is too large ({path.stat().st_size // 1024} KiB): "
                              f"allowed ≤ {MAX_BYTES // 1024} KiB")
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise PresetError(f"cannot read preset {str(path)!r}: {exc}") from None
    return loads_any_raw(text, path.name)


def load_preset(name_or_path: str = DEFAULT_PRESET, overrides: typing.Iterable[str] = ()) -> Any:
    """Load, override and validate a preset; returns its parameter object."""
    return parse_preset(apply_overrides(load_raw(name_or_path), overrides))


def load_preset_and_plant(name_or_path: str = DEFAULT_PRESET, overrides: typing.Iterable[str] = ()
                          ) -> tuple[Any, DriveParams | None]:
    """Load, override and validate a preset: (the controller's model, the plant or None).

    ``overrides`` may include ``plant.FIELD=VALUE`` (on top of the file's plant section); a
    ``motor.``/``load.`` override changes the model and, where the plant section does not give
    that field, the plant too.
    """
    raw = apply_overrides(load_raw(name_or_path), overrides)
    params = parse_preset(raw)
    return params, (parse_plant(raw, params) if isinstance(params, DriveParams) else None)


def loads_preset_and_plant(text: str, origin: str = "<upload>") -> tuple[Any, DriveParams | None]:
    """:func:`loads_preset` returning (the controller's model, the plant or None)."""
    raw = loads_any_raw(text, origin)
    params = parse_preset(raw)
    return params, (parse_plant(raw, params) if isinstance(params, DriveParams) else None)


def loads_preset(text: str, origin: str = "<upload>") -> Any:
    """Validate preset YAML or JSON text (e.g. an upload) and return its parameter object."""
    return parse_preset(loads_any_raw(text, origin))


def loads_json_raw(text: str, origin: str = "<text>") -> Any:
    """Parse a JSON preset or drive parameter file (size-limited) into plain Python data."""
    if len(text.encode("utf-8", "replace")) > MAX_BYTES:
        raise PresetError(f"{origin} is too large: allowed ≤ {MAX_BYTES // 1024} KiB")
    check_structure(text, origin)
    try:
        return json.loads(text, parse_constant=_no_constant, object_pairs_hook=_unique_keys)
    except json.JSONDecodeError as exc:
        raise PresetError(f"{origin} is not valid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
    except RecursionError:
        raise PresetError(f"{origin} is nested too deeply") from None


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    keys = [k for k, _ in pairs]
    dup = next((k for k in keys if keys.count(k) > 1), None)
    if dup is not None:
        raise PresetError(f"key {dup!r} is given more than once in a JSON object: allowed once")
    return dict(pairs)


def _no_constant(name: str) -> Any:
    raise PresetError(f"{name} is not allowed in a preset: allowed finite numbers")


def loads_any_raw(text: str, origin: str = "<text>") -> Any:
    """JSON (``*.json``, or text starting with ``{``) or YAML text → plain Python data."""
    if origin.lower().endswith(".json"):
        return loads_json_raw(text, origin)
    if text.lstrip().startswith("{"):  # JSON text; a YAML flow mapping falls back to YAML
        try:
            return loads_json_raw(text, origin)
        except PresetError:
            pass
    return loads_raw(text, origin)


def _plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    return value


def to_raw(params: Any, plant: DriveParams | None = None) -> dict[str, Any]:
    """Convert a parameter object to a preset mapping.

    Schema, name, source, mode, sections, and the ``plant`` section when a plant that differs
    from the model is given.
    """
    mode = next(m for m, cls in MODES.items() if isinstance(params, cls))
    body = _plain(params)
    raw: dict[str, Any] = {"schema": SCHEMA, "name": body.pop("name"), "source": body.pop("source")}
    if mode != "position":
        raw["mode"] = mode
    raw.update(body)
    if plant is not None and (true := plant_raw(params, plant)):
        raw[PLANT] = true
    return raw


def dumps(data: Any) -> str:
    """Any plain data → YAML text (block style, key order kept)."""
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, default_flow_style=False)


def dumps_preset(params: Any, plant: DriveParams | None = None) -> str:
    """Parameter object (and optional plant) → preset YAML text in SI field names."""
    return dumps(to_raw(params, plant))


_KEY_LINE = re.compile(r"^( *)(- )?(\w+):(.*)$")


def annotate_units(text: str) -> str:
    """YAML text of a preset → the same text with ``# [unit] allowed …`` after every input value.

    The unit and range of each value come from its field spec (the loader ignores comments, so
    the annotated text loads to the same object).
    """
    out, stack = [], []  # stack: (indent, key) of the mappings and lists the line is in
    for line in text.splitlines():
        m = _KEY_LINE.match(line)
        if m is None:
            out.append(line)
            continue
        indent = len(m.group(1)) + (2 if m.group(2) else 0)
        stack = [(i, k) for i, k in stack if i < indent]
        section = ".".join(k for _, k in stack)
        stack.append((indent, m.group(3)))
        cls = units.SECTION_CLASSES.get(section)
        spec = field_specs(cls).get(m.group(3)) if cls is not None else None
        value = m.group(4).strip()
        if spec is not None and value and not value.startswith("["):
            line = f"{line}  # [{spec.unit_text}] {spec.range_text()}"
        out.append(line)
    return "\n".join(out) + "\n"


def save_preset(params: Any, path: str | Path, plant: DriveParams | None = None) -> None:
    """Write a parameter object (and optional plant) as a preset file."""
    Path(path).write_text(dumps_preset(params, plant), encoding="utf-8")


__all__ = [
    "DEFAULT_PRESET", "MODES", "PAPER_PRESET", "PLANT", "ParameterError", "PresetError", "annotate_units",
    "apply_overrides", "dumps", "dumps_preset", "list_presets", "load_preset", "load_preset_and_plant",
    "loads_preset", "loads_preset_and_plant", "parse_plant", "parse_preset", "plant_fields", "plant_raw",
    "save_preset", "to_raw",
]


def loads_log_mapping(text: str, origin: str = "<mapping>") -> dict[str, str]:
    """Parse a drive-log column mapping (YAML ``column: signal [unit]``) into a dict of strings."""
    raw = loads_raw(text, origin)
    if not isinstance(raw, dict) or not raw:
        raise PresetError(f"{origin}: a mapping file needs lines 'column: signal [unit]', e.g. 'Iq: i_q [A]'")
    bad = [k for k, v in raw.items() if not isinstance(v, str)]
    if bad:
        raise PresetError(f"{origin}: column {str(bad[0])!r} maps to {raw[bad[0]]!r}: allowed 'signal [unit]'")
    return {str(k): v for k, v in raw.items()}
