"""Preset loader and writer: the only module that reads or writes YAML.

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

import yaml

from app.io import units
from app.io.atomic import write_atomic_text
from app.io.json_data import MAX_BYTES, MAX_DEPTH, check_size, loads_json_raw
from app.io.numbers import QuotedText, shorten, shown
from app.io.preset_schema import (
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
from control.common.checks import field_specs
from control.fdsmc.params import DriveParams

PRESET_DIR = Path(__file__).resolve().parents[2] / "presets"
#: The page's start-up preset: a real catalogue servo with a verified clean design.
DEFAULT_PRESET = "siemens_1ft7044_ak7"
#: The FDSMC paper's drive (section 5 of [1]), for reproduction.
PAPER_PRESET = "paper_12kw_pmsm"


# ---- YAML front-end: text → raw mapping of texts, lists and mappings -------------------------
def _too_deep(origin: str, mark: Any, kind: str) -> PresetError:
    return PresetError(f"{origin} is nested too deeply at line {mark.line + 1}, column {mark.column + 1}: "
                       f"allowed ≤ {MAX_DEPTH} levels of {kind}")


class _TextLoader(yaml.SafeLoader):
    """Safe YAML loader that keeps every scalar as text: no YAML 1.1 implicit typing.

    Without it ``1:30`` → 90, ``017`` → 15, and ``0x10``, ``1_000``, ``yes`` → True … would be converted.
    Numbers are parsed afterwards by :mod:`app.io.numbers` against the field types; duplicate keys and
    explicit tags are errors. A quoted or block scalar (``"1.5"``, a ``>`` block) becomes
    :class:`~app.io.numbers.QuotedText`, which is never a number.

    The scanner counts the nesting as it reads: the ``MAX_DEPTH + 1``-th bracket or indentation level
    is refused on the spot, so no text costs more than its size (a pre-scan can be fooled by
    quotes and comments; the scanner cannot).
    """

    origin = "<text>"

    def fetch_flow_collection_start(self, TokenClass: Any) -> None:  # noqa: N803 - PyYAML's name
        """Refuse a bracket that would nest deeper than :data:`MAX_DEPTH`."""
        if self.flow_level >= MAX_DEPTH:
            raise _too_deep(self.origin, self.get_mark(), "brackets")
        super().fetch_flow_collection_start(TokenClass)

    def compose_node(self, parent: Any, index: Any) -> Any:
        """Refuse an anchor (``&name``) or alias (``*name``) before it is composed (one pass)."""
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:
            raise PresetError(f"YAML anchors/aliases (*name) at line {event.start_mark.line + 1} are not allowed "
                              "in presets: write each value out")
        return super().compose_node(parent, index)

    def add_indent(self, column: int) -> bool:
        """Refuse a block indentation level deeper than :data:`MAX_DEPTH`."""
        if self.indent < column and len(self.indents) >= MAX_DEPTH:
            raise _too_deep(self.origin, self.get_mark(), "indentation")
        return bool(super().add_indent(column))


_TextLoader.yaml_implicit_resolvers = {}
#: libyaml's parser (≈ 10× faster), when PyYAML was built with it: the same constructors, the nesting
#: and anchors checked on its event stream first (:func:`_check_events`).
_CLoader: Any = None
if getattr(yaml, "__with_libyaml__", False):
    _CLoader = type("_CTextLoader", (yaml.CSafeLoader,), {"yaml_implicit_resolvers": {}})


def _loader(origin: str) -> type[_TextLoader]:
    """:class:`_TextLoader` naming ``origin`` in its messages."""
    return type("_OriginLoader", (_TextLoader,), {"origin": origin})


def _check_events(text: str, origin: str) -> None:
    """Stream libyaml's parser events: refuse anchors, aliases and nesting deeper than :data:`MAX_DEPTH`.

    The parser stops at the first refusal, having read only a bounded look-ahead past it.
    """
    depth = 0
    for event in yaml.parse(text, Loader=_CLoader):
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:
            raise PresetError(f"YAML anchors/aliases (*name) at line {event.start_mark.line + 1} are not allowed "
                              "in presets: write each value out")
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise _too_deep(origin, event.start_mark, "nesting (brackets or indentation)")
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


def _load(text: str, origin: str) -> Any:
    """YAML text → data: libyaml after its event check, else the pure-Python guarded loader."""
    if _CLoader is None:
        return yaml.load(text, Loader=_loader(origin))  # noqa: S506 - a SafeLoader subclass
    _check_events(text, origin)
    return yaml.load(text, Loader=_CLoader)  # noqa: S506 - a CSafeLoader subclass, tags refused


def _mark(node: yaml.Node) -> str:
    return f"line {node.start_mark.line + 1}, column {node.start_mark.column + 1}"


def _refuse_tag(loader: _TextLoader, node: yaml.Node) -> Any:
    raise PresetError(f"YAML tag {shorten(node.tag)!r} at {_mark(node)} is not allowed: write plain values")


def _text(loader: _TextLoader, node: yaml.ScalarNode) -> str:
    value = loader.construct_scalar(node)
    return QuotedText(value) if node.style else str(value)


def _unique_mapping(loader: _TextLoader, node: yaml.MappingNode) -> dict[Any, Any]:
    out: dict[Any, Any] = {}
    first: dict[Any, str] = {}
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        if not isinstance(key, str):
            raise PresetError(f"key at {_mark(key_node)} is not a name: allowed text keys only")
        key = str(key)
        if key in out:
            raise PresetError(f"duplicate key {shorten(key)!r} at {_mark(key_node)} (first at {first[key]}): "
                              "allowed each key once per mapping")
        first[key] = _mark(key_node)
        out[key] = loader.construct_object(value_node, deep=True)
    return out


for _cls in filter(None, (_TextLoader, _CLoader)):
    for _tag in ("null", "bool", "int", "float", "binary", "timestamp", "omap", "pairs", "set", "merge", "value"):
        _cls.add_constructor(f"tag:yaml.org,2002:{_tag}", _refuse_tag)
    _cls.add_constructor(None, _refuse_tag)
    _cls.add_constructor("tag:yaml.org,2002:map", _unique_mapping)
    _cls.add_constructor("tag:yaml.org,2002:str", _text)


def loads_raw(text: str, origin: str = "<text>") -> Any:
    """Parse YAML text safely into plain data whose scalars are all text (see :class:`_TextLoader`).

    Size-limited, nesting-limited by the scanner itself, no aliases, no duplicate keys.
    """
    origin = shorten(origin)
    check_size(text, origin)
    try:
        return _load(text, origin)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise PresetError(f"{origin} is not valid YAML{where}: {shorten(problem)}: allowed plain YAML text") from None
    except RecursionError:  # not reachable within MAX_DEPTH; kept as a last line of defence
        raise PresetError(f"{origin} is nested too deeply: allowed ≤ {MAX_DEPTH} levels") from None
    except PresetError as exc:  # duplicate key, tag, nesting: say where
        raise PresetError(str(exc) if str(exc).startswith(origin) else f"{origin}: {exc}") from None


def plain_scalar(text: str, where: str) -> Any:
    """Parse one ``--set`` value: a plain YAML scalar or flow collection, nothing hidden.

    A comment (``1.5 # x``), a byte-order mark, line folding or a block scalar would make the value
    differ from what was typed; those are refused, naming ``where``.
    """
    value = loads_raw(text, where)
    if isinstance(value, str) and not isinstance(value, QuotedText) and value != text.strip(" \t"):
        raise PresetError(f"{where} = {shorten(text)!r} is not a plain value: allowed the value alone "
                          "(no comment, byte-order mark, line break or YAML block syntax)")
    return value


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
        aliases = units.ALIASES.get(section, {}) if section != PLANT else (
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
    try:
        if path.stat().st_size > MAX_BYTES:  # before reading it
            raise PresetError(f"{path.name} is too large ({path.stat().st_size // 1024} KiB): "
                              f"allowed ≤ {MAX_BYTES // 1024} KiB")
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise PresetError(f"cannot read preset {str(path)!r}: {exc}") from None
    return copy.deepcopy(_parsed_file(text, path.name))  # the caller may apply overrides to it


@functools.lru_cache(maxsize=32)
def _parsed_file(text: str, origin: str) -> Any:
    """Return :func:`loads_any_raw` of a file's text, kept by its exact text.

    Every page open lists the presets' modes and loads the BLDC preset; parsing the same text
    again would give the same data.
    """
    return loads_any_raw(text, origin)


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


def to_raw(params: Any, plant: DriveParams | None = None) -> dict[str, Any]:
    """Convert a parameter object to a preset mapping.

    Schema, name, source, mode, sections, and the ``plant`` section when a plant that differs
    from the model is given.
    """
    mode = next(m for m, cls in MODES.items() if isinstance(params, cls))
    body = plain(params)
    raw: dict[str, Any] = {"schema": SCHEMA, "name": body.pop("name"), "source": body.pop("source")}
    if mode != "position":
        raw["mode"] = mode
    raw.update(body)
    if plant is not None and (true := plant_raw(params, plant)):
        raw[PLANT] = true
    return raw


class _Dumper(yaml.SafeDumper):
    """Safe dumper that writes :class:`QuotedText` (text read from a file) as the text it is."""


_Dumper.add_representer(QuotedText, yaml.SafeDumper.represent_str)


def dumps(data: Any) -> str:
    """Any plain data → YAML text (block style, key order kept)."""
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, default_flow_style=False)


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
    "load_preset", "load_preset_and_plant", "loads_preset", "loads_preset_and_plant", "save_preset", "to_raw",
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
