"""Safe YAML text: the one module that reads or writes YAML, for every file kind.

Presets, exported drive parameter files, duty-cycle moves, multi-axis lists, back-EMF tables and
drive-log column mappings are all read here: :func:`loads_raw` (YAML) and :func:`loads_any_raw`
(YAML or JSON, :mod:`app.io.json_data`) return plain data whose scalars are text, size-limited,
nesting-limited by the parser itself, without anchors, aliases, tags or duplicate keys; numbers are
parsed afterwards by :mod:`app.io.numbers` against each field's type. :func:`dumps` writes YAML.
The file kinds' own rules (sections, units, modes) are in their modules (:mod:`app.io.presets` …).
"""

from __future__ import annotations

from typing import Any

import yaml

from pmsm_commissioning.app.io.json_data import MAX_BYTES, MAX_DEPTH, check_size, loads_json_raw
from pmsm_commissioning.app.io.numbers import QuotedText, shorten
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.user_text import check_label, escaped, forbidden
from pmsm_commissioning.control.common.checks import ParameterError

#: Keys whose text is written into files (a preset's name and source): one printable line.
LABEL_KEYS = ("name", "source")

#: Most YAML nodes (scalars, keys and collections) one text may hold [-]: a preset needs ≈ 200, one
#: with a measured back-EMF table ≈ 4 300. Counted as the text is parsed, it bounds the pure-Python
#: parser's time (≈ 18 µs a node) as the size limit bounds the rest.
MAX_NODES = 10_000


# ---- YAML front-end: text → raw mapping of texts, lists and mappings -------------------------
def _too_many(origin: str, mark: Any, max_nodes: int) -> PresetError:
    return PresetError(f"{origin} has too many values at line {mark.line + 1}, column {mark.column + 1}: "
                       f"allowed ≤ {max_nodes} YAML nodes (keys, values and lists)")


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
    quotes and comments; the scanner cannot). The composer counts the nodes and refuses the
    ``max_nodes + 1``-th as it is read.
    """

    origin = "<text>"
    max_nodes = MAX_NODES
    _nodes = 0

    def fetch_flow_collection_start(self, TokenClass: Any) -> None:  # noqa: N803 - PyYAML's name
        """Refuse a bracket that would nest deeper than :data:`MAX_DEPTH`."""
        if self.flow_level >= MAX_DEPTH:
            raise _too_deep(self.origin, self.get_mark(), "brackets")
        super().fetch_flow_collection_start(TokenClass)

    def compose_node(self, parent: Any, index: Any) -> Any:
        """Refuse an anchor (``&name``) or alias (``*name``) before it is composed (one pass)."""
        event = self.peek_event()
        self._nodes += 1
        if self._nodes > self.max_nodes:
            raise _too_many(self.origin, event.start_mark, self.max_nodes)
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


def _loader(origin: str, max_nodes: int) -> type[_TextLoader]:
    """:class:`_TextLoader` naming ``origin`` in its messages, refusing more than ``max_nodes`` nodes."""
    return type("_OriginLoader", (_TextLoader,), {"origin": origin, "max_nodes": max_nodes})


def _check_events(text: str, origin: str, max_nodes: int) -> None:
    """Stream libyaml's parser events: refuse anchors, aliases, deep nesting and too many nodes.

    Nesting deeper than :data:`MAX_DEPTH` and more than ``max_nodes`` nodes are refused. The parser stops
    at the first refusal, having read only a bounded look-ahead past it.
    """
    depth = nodes = 0
    for event in yaml.parse(text, Loader=_CLoader):
        if isinstance(event, yaml.NodeEvent):
            nodes += 1
            if nodes > max_nodes:
                raise _too_many(origin, event.start_mark, max_nodes)
        if isinstance(event, yaml.AliasEvent) or getattr(event, "anchor", None) is not None:
            raise PresetError(f"YAML anchors/aliases (*name) at line {event.start_mark.line + 1} are not allowed "
                              "in presets: write each value out")
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise _too_deep(origin, event.start_mark, "nesting (brackets or indentation)")
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


def _load(text: str, origin: str, max_nodes: int) -> Any:
    """YAML text → data: libyaml after its event check, else the pure-Python guarded loader."""
    if _CLoader is None:
        return yaml.load(text, Loader=_loader(origin, max_nodes))  # noqa: S506 - a SafeLoader subclass
    _check_events(text, origin, max_nodes)
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
        if any(forbidden(ch) for ch in key):
            raise PresetError(f"key '{escaped(shorten(key))}' at {_mark(key_node)} holds a control, line-break or "
                              "bidi character: allowed printable keys")
        if key in out:
            raise PresetError(f"duplicate key {shorten(key)!r} at {_mark(key_node)} (first at {first[key]}): "
                              "allowed each key once per mapping")
        first[key] = _mark(key_node)
        out[key] = _label(key, loader.construct_object(value_node, deep=True))
    return out


def _label(key: str, value: Any) -> Any:
    """``value``, refused (PresetError) when it is a name or source that is not one printable line."""
    if key in LABEL_KEYS and isinstance(value, str):
        try:
            check_label(value, key)
        except ParameterError as exc:
            raise PresetError(str(exc)) from None
    return value


for _cls in filter(None, (_TextLoader, _CLoader)):
    for _tag in ("null", "bool", "int", "float", "binary", "timestamp", "omap", "pairs", "set", "merge", "value"):
        _cls.add_constructor(f"tag:yaml.org,2002:{_tag}", _refuse_tag)
    _cls.add_constructor(None, _refuse_tag)
    _cls.add_constructor("tag:yaml.org,2002:map", _unique_mapping)
    _cls.add_constructor("tag:yaml.org,2002:str", _text)


def loads_raw(text: str, origin: str = "<text>", max_nodes: int = MAX_NODES) -> Any:
    """Parse YAML text safely into plain data whose scalars are all text (see :class:`_TextLoader`).

    Size-limited, nesting-limited by the scanner itself, at most ``max_nodes`` nodes (counted as
    they are parsed), no aliases, no duplicate keys.
    """
    origin = shorten(origin)
    check_size(text, origin)
    try:
        return _load(text, origin, max_nodes)
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
    hidden = (isinstance(value, str) and not isinstance(value, QuotedText) and value != text.strip(" \t")) \
        or _uncovered(text)
    if hidden:
        raise PresetError(f"{where} = {shorten(text)!r} is not a plain value: allowed the value alone "
                          "(no comment, byte-order mark, line break or YAML block syntax)")
    return value


def _uncovered(text: str) -> bool:
    """Return True when some typed character is in no YAML token (a ``# …`` comment, even inside ``[…]``)."""
    covered = bytearray(len(text))
    for tok in yaml.scan(text, Loader=yaml.SafeLoader):
        covered[tok.start_mark.index: tok.end_mark.index] = b"\x01" * (tok.end_mark.index - tok.start_mark.index)
    return any(not covered[i] and not ch.isspace() for i, ch in enumerate(text))


def loads_any_raw(text: str, origin: str = "<text>") -> Any:
    """JSON (``*.json``, or text starting with ``{``) or YAML text → plain Python data."""
    if origin.lower().endswith(".json"):
        return _json_labels(loads_json_raw(text, origin))
    if text.lstrip().startswith("{"):  # JSON text; a YAML flow mapping falls back to YAML
        try:
            data = loads_json_raw(text, origin)
        except PresetError:
            pass
        else:
            return _json_labels(data)
    return loads_raw(text, origin)


def _json_labels(data: Any) -> Any:
    """JSON data with its top-level name and source checked as YAML's are (:func:`_label`)."""
    if isinstance(data, dict):
        for key in LABEL_KEYS:
            _label(key, data.get(key))
    return data


class _Dumper(yaml.SafeDumper):
    """Safe dumper that writes :class:`QuotedText` (text read from a file) as the text it is."""


_Dumper.add_representer(QuotedText, yaml.SafeDumper.represent_str)


def dumps(data: Any) -> str:
    """Any plain data → YAML text (block style, key order kept)."""
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, default_flow_style=False)


__all__ = ["MAX_BYTES", "MAX_DEPTH", "MAX_NODES", "dumps", "loads_any_raw", "loads_raw", "plain_scalar"]
