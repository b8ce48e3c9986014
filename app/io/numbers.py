"""The one parser for numbers typed by engineers: every edge of the tool.

Page fields, ``--set`` overrides, YAML and JSON presets, drive-log CSV cells, uploads and the
numeric CLI options (:func:`number_option`, :func:`integer_option`) all parse here.

A number means what it looks like: ASCII decimal or scientific notation, an optional sign, and
spaces (or thin spaces) only as thousands separators between groups of three digits (``1 000``).
Nothing else is a number: ``1,5`` (a decimal comma is ambiguous), ``1.2.3``, ``0x10``, ``1_000``,
``1:30`` (YAML 1.1 sexagesimal), ``nan``, ``inf``, empty text, non-ASCII digits (``１２``,
``१.२``, ``𝟏``), a byte-order mark, and text a file wrote as text (:class:`QuotedText`: a quoted
YAML scalar, a YAML block scalar, a JSON string). The value is Python's correctly rounded
``float`` of the digits as typed — never rounded to a display precision.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable

from pmsm_commissioning.app.io.user_text import escaped

_GROUPED = r"[0-9]{1,3}(?:[ \u2009\u202f][0-9]{3})+"
_NUMBER = re.compile(rf"[+-]?(?:(?:{_GROUPED}|[0-9]+)(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
#: Longest value quoted in a message [characters]; longer ones are shortened with "…".
SHOWN_MAX = 80
FORMS = "decimal or scientific notation, e.g. 4.86e-5, -0.5, 1e3 or 1 000"


class NumberFormatError(ValueError):
    """Text that is not a number in decimal or scientific notation; the message names the field."""


class QuotedText(str):
    """Text a file wrote as text — a quoted or block YAML scalar, a JSON string: never a number."""


def shorten(text: object, limit: int = SHOWN_MAX) -> str:
    """``text`` for a message: at most ``limit`` characters, the rest replaced by "…"."""
    flat = str(text)
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"


#: Longest message of a refusal [characters].
MESSAGE_MAX = 300


def one_line(message: object, limit: int = MESSAGE_MAX) -> str:
    """Return a refusal as one line of at most ``limit`` characters.

    Line breaks become spaces, every other control, escape or bidi character is shown escaped
    (:func:`app.io.user_text.escaped`: nothing reaches a terminal raw); an overlong message keeps its
    start (the field and value) and its end (what is allowed), joined by "…".
    """
    flat = escaped(" ".join(str(message).split()))
    if len(flat) <= limit:
        return flat
    tail = (limit - 3) * 2 // 5
    return f"{flat[: limit - 3 - tail]} … {flat[-tail:]}"


def shown(text: object) -> str:
    """``repr`` of a value for a message, at most :data:`SHOWN_MAX` characters."""
    r = repr(str(text)) if isinstance(text, str) else repr(text)
    return shorten(r)


def parse_number(text: str, field: str) -> float:
    """Parse ``text`` typed for ``field`` into a float, exactly as typed.

    Parameters
    ----------
    text : str
        What the user typed; surrounding white space is ignored.
    field : str
        Field name shown in the message, e.g. ``"motor.J_r"``.

    Returns
    -------
    float
        The correctly rounded double of the decimal number written.

    Raises
    ------
    NumberFormatError
        When ``text`` is not decimal or scientific notation, overflows a double or underflows to 0
        (``1e-400``: a non-zero number typed must not silently become 0).
    """
    if isinstance(text, QuotedText):
        raise NumberFormatError(f"{field} = {shown(text)} is quoted text: allowed a number written without "
                                f"quotes, in {FORMS}")
    stripped = text.strip(" \t\r\n")
    if not _NUMBER.fullmatch(stripped):
        raise NumberFormatError(f"{field} = {shown(text) if stripped else 'empty'} is not a number: allowed {FORMS}")
    value = float(re.sub(r"[ \u2009\u202f]", "", stripped))
    if not math.isfinite(value):
        raise NumberFormatError(f"{field} = {shown(text)} is too large: allowed |value| < 1.8e308")
    if value == 0.0 and re.search(r"[1-9]", re.split(r"[eE]", stripped)[0]):
        raise NumberFormatError(f"{field} = {shown(text)} underflows to 0: allowed 0 or |value| ≥ 5e-324")
    return value


def parse_integer(text: str, field: str) -> int:
    """Parse ``text`` as a whole number (``4``, ``4.0`` or ``1e1``); :class:`NumberFormatError` otherwise."""
    value = parse_number(text, field)
    if not value.is_integer():
        raise NumberFormatError(f"{field} = {shown(text)} is not a whole number: allowed integers, e.g. 4")
    return int(value)


def _option(convert: Callable[[str, str], float], option: str, kind: str) -> Callable[[str], float]:
    """Return an argparse ``type`` that converts with ``convert`` and reports a one-line error."""
    def parse(text: str) -> float:
        try:
            return convert(text, option)
        except NumberFormatError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parse.__name__ = kind
    return parse


def number_option(option: str) -> Callable[[str], float]:
    """Return an argparse ``type`` for a numeric CLI option: :func:`parse_number`, one-line error."""
    return _option(parse_number, option, "number")


def integer_option(option: str) -> Callable[[str], int]:
    """Return an argparse ``type`` for a whole-number CLI option: :func:`parse_integer`, one-line error."""
    return _option(parse_integer, option, "integer")  # type: ignore[return-value]


#: Longest list of manoeuvre times one sweep takes [-].
T_M_LIST_MAX = 40


def parse_T_m_list(text: str, field: str) -> list[float]:
    """Manoeuvre times [s] from ``"1.0, 1.4; 1.8"`` (commas or semicolons; empty items skipped).

    Parameters
    ----------
    text : str   What the user typed.
    field : str  Field name shown in the message, e.g. ``"--tm"``.

    Raises
    ------
    NumberFormatError
        Naming ``field``, the bad item and the allowed form: every time 0 < T_m ≤ 10000 s,
        1 … :data:`T_M_LIST_MAX` of them.
    """
    values: list[float] = []
    for item in filter(None, (s.strip() for s in text.replace(";", ",").split(","))):
        try:
            value = parse_number(item, field)
        except NumberFormatError:
            raise NumberFormatError(f"{field}: {shown(item)} is not a number: allowed a comma-separated "
                                    "list of times > 0 s, e.g. 1.0, 1.4, 1.8") from None
        if not 0.0 < value <= 1e4:
            raise NumberFormatError(f"{field}: {value:g} s is out of range: allowed 0 < T_m ≤ 10000 s")
        values.append(value)
    if not 1 <= len(values) <= T_M_LIST_MAX:
        raise NumberFormatError(f"{field} has {len(values)} values: allowed 1 … {T_M_LIST_MAX}")
    return values


def format_metric(value: float | int | bool | str | None, fmt: str = ".5g") -> str:
    """Format a result cell as text.

    "—" for None or a non-finite number, "yes"/"no" for a flag, a float in ``fmt``, anything else
    as it is.
    """
    if value is None or isinstance(value, float) and not math.isfinite(value):
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return format(value, fmt) if isinstance(value, float) else str(value)


def format_number(value: float) -> str:
    """Shortest text that parses back to exactly ``value`` (``repr`` of the double)."""
    if isinstance(value, int) or float(value).is_integer() and abs(value) < 1e16:
        return str(int(value))
    return repr(float(value))


__all__ = ["FORMS", "MESSAGE_MAX", "SHOWN_MAX", "T_M_LIST_MAX", "NumberFormatError", "QuotedText", "format_metric",
           "format_number", "integer_option", "number_option", "one_line", "parse_T_m_list", "parse_integer",
           "parse_number", "shorten", "shown"]
