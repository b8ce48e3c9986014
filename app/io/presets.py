"""Preset loader and writer: one ``load(name_or_path, overrides, mode)``; YAML text via :mod:`app.io.yaml_text`.

A preset is a YAML mapping with ``schema: 1``, ``name``, ``source``, an optional ``mode``
(``position``, the default, or another registered mode) and one mapping per section of the
mode's parameter dataclass. Loading is safe (``yaml.safe_load``, no aliases, size-limited) and
every scalar is kept as text; :mod:`app.io.preset_schema` then rejects unknown keys with a "did
you mean" hint, missing keys and wrong types, and converts unit-suffixed keys (``L_d_mH``,
``omega_b_rpm``, ``Ke_Vrms_krpm`` …) through :mod:`app.io.units`. Saving writes SI field names
only, so load → save → load gives equal objects.

A position preset may carry an optional ``plant`` mapping: the true motor and load values of the
simulated drive where they differ from the controller's model (the ``motor`` and ``load``
sections), with the same keys and unit suffixes as those sections (``plant: {J_L: 0.3,
R_s: 0.12}``); see :func:`app.io.preset_schema.parse_plant`.
"""

from __future__ import annotations

import copy
import functools
import re
import typing
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.io.atomic import write_atomic_text
from pmsm_commissioning.app.io.bounded import ReadError, read_bounded
from pmsm_commissioning.app.io.json_data import MAX_BYTES, MAX_DEPTH, loads_json_raw  # noqa: F401 - re-exported
from pmsm_commissioning.app.io.modes import mode_for
from pmsm_commissioning.app.io.numbers import shown
from pmsm_commissioning.app.io.preset_schema import (
    MODES,
    PLANT,
    SCHEMA,
    PresetError,
    field_of,
    hint,
    optional_sections,
    parse_plant,
    parse_preset,
    plain,
    plant_raw,
)
from pmsm_commissioning.app.io.transmission_keys import as_aliases
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.app.io.yaml_text import dumps, loads_any_raw, loads_raw, plain_scalar
from pmsm_commissioning.app.resources import preset_dir
from pmsm_commissioning.control.common.checks import field_specs
from pmsm_commissioning.control.fdsmc.params import DriveParams

#: Folder of the shipped presets (package data, :mod:`app.resources`).
PRESET_DIR = preset_dir()
#: The page's start-up preset: a real catalogue servo with a verified clean design.
DEFAULT_PRESET = "siemens_1ft7044_ak7"
#: The FDSMC paper's drive (section 5 of [1]), for reproduction.
PAPER_PRESET = "paper_12kw_pmsm"


def apply_overrides(raw: Any, overrides: typing.Iterable[str]) -> Any:
    """Apply ``section.field=value`` overrides (values parsed as YAML scalars) to a raw preset."""
    if not isinstance(raw, dict):
        raise PresetError("overrides need a preset mapping to apply to")
    for item in overrides:
        key, sep, text = item.partition("=")
        section, dot, name = key.strip().partition(".")
        if not sep or not dot or not name:
            raise PresetError(f"--set {shown(item)} is malformed: allowed form section.field=value")
        if section == PLANT and raw.get(PLANT) is None and raw.get("mode", "position") == "position":
            raw[PLANT] = {}
        if section not in raw and section in optional_sections(MODES.get(str(raw.get("mode", "position")))):
            raw[section] = {}  # an optional section (sensors, limits) set from the command line
        if not isinstance(raw.get(section), dict):
            known = [k for k, v in raw.items() if isinstance(v, dict)]
            raise PresetError(f"--set {shown(item)}: unknown section {shown(section)}{hint(section, known)}")
        value = plain_scalar(text, f"--set {key}") if text.strip() else None
        if value is None:
            raise PresetError(f"--set {shown(item)} has no value: allowed section.field=value, e.g. manoeuvre.T_m=1.4")
        aliases = units.ALIASES.get(section, {}) | as_aliases(section) if section != PLANT else (
            units.ALIASES["motor"] | units.ALIASES["load"])
        target = field_of(name, aliases, list(units.FLUX_KEYS))
        for other in [k for k in raw[section] if field_of(str(k), aliases, list(units.FLUX_KEYS)) == target]:
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
    raise PresetError(f"preset {shown(name_or_path)} not found{hint(str(name_or_path), list_presets())}")


def list_presets() -> list[str]:
    """Names of the shipped presets."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def load_raw(name_or_path: str) -> Any:
    """Read a preset file (by name or path) into raw data, without validating sections."""
    path = resolve(name_or_path)
    try:  # never more than MAX_BYTES read (a sparse, /proc or device file)
        text = read_bounded(path, MAX_BYTES, escaped(path.name)).decode("utf-8")
    except ReadError as exc:
        if exc.size is None:
            raise PresetError(f"cannot read preset: {exc}") from None
        raise PresetError(f"{escaped(path.name)} is too large ({'over ' if exc.size == MAX_BYTES + 1 else ''}"
                          f"{exc.size // 1024} KiB): allowed ≤ {MAX_BYTES // 1024} KiB") from None
    except UnicodeDecodeError as exc:
        raise PresetError(f"cannot read preset {escaped(str(path))!r}: {exc}") from None
    return copy.deepcopy(_parsed_file(text, path.name))  # the caller may apply overrides to it


@functools.lru_cache(maxsize=32)
def _parsed_file(text: str, origin: str) -> Any:
    """Return :func:`loads_any_raw` of a file's text, kept by its exact text.

    Every page open lists the presets' modes and loads the BLDC preset; parsing the same text
    again would give the same data.
    """
    return loads_any_raw(text, origin)


def load(name_or_path: str = DEFAULT_PRESET, overrides: typing.Iterable[str] = (), mode: str | None = None) -> Any:
    """Load a preset: the one way from a name or path to a parameter object.

    Parameters
    ----------
    name_or_path : str
        A shipped preset's name (``presets/NAME.yaml``) or a YAML/JSON file path.
    overrides : iterable of str
        ``section.field=value`` overrides (unit-suffixed keys allowed), applied before validation.
    mode : str or None
        The preset mode this caller takes (``"position"``, ``"bldc"``); a preset of another mode
        is refused naming both. None takes any mode.

    Returns
    -------
    DriveParams or BldcParams
        The validated parameter object.
    """
    params = parse_preset(apply_overrides(load_raw(name_or_path), overrides))
    return params if mode is None else require_mode(params, mode, name_or_path)


def load_with_plant(name_or_path: str = DEFAULT_PRESET, overrides: typing.Iterable[str] = ()
                    ) -> tuple[Any, DriveParams | None]:
    """:func:`load` returning (the controller's model, the plant or None).

    ``overrides`` may include ``plant.FIELD=VALUE`` (on top of the file's plant section); a
    ``motor.``/``load.`` override changes the model and, where the plant section does not give
    that field, the plant too.
    """
    raw = apply_overrides(load_raw(name_or_path), overrides)
    params = parse_preset(raw)
    return params, (parse_plant(raw, params) if isinstance(params, DriveParams) else None)


def load_preset(name_or_path: str = DEFAULT_PRESET, overrides: typing.Iterable[str] = ()) -> Any:
    """Alias of :func:`load` for any mode (kept for scripts and tests)."""
    return load(name_or_path, overrides)


#: Alias of :func:`load_with_plant` (kept for scripts and tests).
load_preset_and_plant = load_with_plant


def preset_mode(name: str) -> str | None:
    """Mode of the shipped or given preset ``name``; None if it cannot be read."""
    try:
        raw = load_raw(name)
    except PresetError:
        return None
    return str(raw.get("mode", "position")) if isinstance(raw, dict) else None


def list_presets_of(mode: str) -> list[str]:
    """Names of the shipped presets of ``mode``."""
    return [n for n in list_presets() if preset_mode(n) == mode]


def require_mode(params: Any, mode: str, origin: str) -> Any:
    """Return ``params`` if it belongs to ``mode``, else PresetError naming both modes."""
    found = mode_for(params).name
    if found != mode:
        raise PresetError(f"preset {origin!r} is a {found}-mode preset: allowed here a {mode}-mode preset "
                          f"(shipped: {', '.join(list_presets_of(mode))})")
    return params


def loads_preset_and_plant(text: str, origin: str = "<upload>") -> tuple[Any, DriveParams | None]:
    """:func:`loads_preset` returning (the controller's model, the plant or None)."""
    raw = loads_any_raw(text, origin)
    params = parse_preset(raw)
    return params, (parse_plant(raw, params) if isinstance(params, DriveParams) else None)


def loads_preset(text: str, origin: str = "<upload>") -> Any:
    """Validate preset YAML or JSON text (e.g. an upload) and return its parameter object."""
    return parse_preset(loads_any_raw(text, origin))


def to_raw(params: Any, plant: DriveParams | None = None) -> dict[str, Any]:
    """Convert a parameter object to a preset mapping.

    Schema, name, source, mode, sections, and the ``plant`` section when a plant that differs
    from the model is given.
    """
    mode = mode_for(params).name
    body = plain(params)
    raw: dict[str, Any] = {"schema": SCHEMA, "name": body.pop("name"), "source": body.pop("source")}
    if mode != "position":
        raw["mode"] = mode
    raw.update(body)
    if plant is not None and (true := plant_raw(params, plant)):
        raw[PLANT] = true
    return raw


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
    write_atomic_text(path, dumps_preset(params, plant))


__all__ = [
    "DEFAULT_PRESET", "PAPER_PRESET", "annotate_units", "apply_overrides", "dumps", "dumps_preset", "list_presets",
    "list_presets_of", "load", "load_preset", "load_preset_and_plant", "load_with_plant", "preset_mode",
    "require_mode", "loads_preset", "loads_preset_and_plant", "save_preset", "to_raw",
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
