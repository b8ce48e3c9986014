"""The JSON edge: results → JSON data (every ``--json``, export and file), and JSON text → data.

JSON has no NaN or infinity: a non-finite float (a limit that does not exist, a run that diverged)
becomes ``null``. Frozen result dataclasses become objects keyed by their field names, numpy
scalars become Python numbers; containers are converted recursively.

Reading (:func:`loads_json_raw`, used by :mod:`app.io.presets` for every JSON preset, parameter
file and upload) is size- and depth-limited before the parser runs, and keeps every number as the
text written so that :mod:`app.io.numbers` parses it like every other edge.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from typing import Any

import numpy as np

from pmsm_commissioning.app.io.numbers import QuotedText, shorten
from pmsm_commissioning.app.io.preset_schema import PresetError

#: Largest preset or parameter file accepted [bytes] (YAML or JSON).
MAX_BYTES = 256 * 1024
#: Deepest nesting a preset may have: brackets (and, in YAML, block indentation levels, counted
#: separately by the YAML scanner); presets need 4.
MAX_DEPTH = 32


def to_json(value: Any) -> Any:
    """JSON-safe plain data of ``value`` (see the module docstring).

    Parameters
    ----------
    value : Any
        A dataclass instance, dict, list, tuple, number, string, bool or None.

    Returns
    -------
    Any
        Dicts (string keys), lists, finite floats, ints, strings, bools and None only.
    """
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_json(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def check_size(text: str, origin: str) -> None:
    """Refuse text larger than :data:`MAX_BYTES` (characters or UTF-8 bytes)."""
    if len(text) > MAX_BYTES or len(text.encode("utf-8", "replace")) > MAX_BYTES:
        raise PresetError(f"{origin} is too large: allowed ≤ {MAX_BYTES // 1024} KiB")


def check_json_depth(text: str, origin: str) -> None:
    """Refuse JSON nested deeper than :data:`MAX_DEPTH`, in one linear pass that skips strings.

    Strings are skipped as JSON defines them (backslash escapes included), so brackets inside a
    string never count and an escaped quote never ends one; an unterminated string ends the scan (the
    parser then reports it).
    """
    depth, pos = 0, 0
    while (m := _JSON_STRUCT.search(text, pos)) is not None:
        ch = m.group()
        if ch == '"':
            end = _JSON_STRING_REST.match(text, m.end())
            if end is None:
                return
            pos = end.end()
            continue
        depth += 1 if ch in "[{" else -1
        if depth > MAX_DEPTH:
            line = text.count("\n", 0, m.start()) + 1
            raise PresetError(f"{origin} is nested too deeply at line {line}: allowed ≤ {MAX_DEPTH} levels "
                              "of brackets")
        pos = m.end()


_JSON_STRUCT = re.compile(r'["\[\]{}]')
_JSON_STRING_REST = re.compile(r'[^"\\]*(?:\\.[^"\\]*)*"', re.S)


def loads_json_raw(text: str, origin: str = "<text>") -> Any:
    """Parse a JSON preset or drive parameter file (size- and depth-limited) into plain Python data.

    Strings become :class:`~app.io.numbers.QuotedText` (never a number); numbers are kept as the
    text written, to be parsed by :mod:`app.io.numbers` like every other edge (a 5000-digit
    integer is then "too large", not an error of Python's int conversion).
    """
    origin = shorten(origin)
    check_size(text, origin)
    check_json_depth(text, origin)
    try:
        return _quote_strings(json.loads(text, parse_constant=_no_constant, object_pairs_hook=_unique_keys,
                                         parse_int=_JsonNumber, parse_float=_JsonNumber))
    except json.JSONDecodeError as exc:
        raise PresetError(f"{origin} is not valid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
    except RecursionError:  # not reachable within MAX_DEPTH; kept as a last line of defence
        raise PresetError(f"{origin} is nested too deeply: allowed ≤ {MAX_DEPTH} levels") from None


class _JsonNumber(str):
    """A JSON number token, as written."""


def _quote_strings(value: Any) -> Any:
    """JSON data with every string value (not key) marked :class:`QuotedText`; numbers as plain text."""
    if isinstance(value, dict):
        return {k: _quote_strings(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_quote_strings(v) for v in value]
    if isinstance(value, _JsonNumber):
        return str(value)
    return QuotedText(value) if isinstance(value, str) else value


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:  # linear: a file of 30 000 keys costs no more than its size
        if key in out:
            raise PresetError(f"key {shorten(key)!r} is given more than once in a JSON object: allowed once")
        out[key] = value
    return out


def _no_constant(name: str) -> Any:
    raise PresetError(f"{name} is not allowed in a preset: allowed finite numbers")
