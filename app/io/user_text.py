r"""User text (names, sources, file names, keys) on its way into a written file or a terminal.

One policy, used by every writer and every message:

* **Refused at the edge** (:func:`check_label`): a preset's ``name`` or ``source`` typed on the
  command line (``export --name/--source``, ``import-drive --name``), in the page's Export folder or
  in a YAML/JSON file may not hold a line break of any kind (LF, CR, NEL U+0085, U+2028/U+2029, VT,
  FF, the separators U+001C–U+001E), another control character (C0, DEL, C1, ESC, BEL) or a
  format/bidi character (U+200E/F, U+202A–U+202E, U+2066–U+2069, U+FEFF …): every character of
  Unicode categories Cc, Cf, Cs, Co, Cn, Zl and Zp. The message names the field, the value
  (escaped) and what is allowed.
* **Escaped defensively by every writer** (:func:`escaped`), whatever reached it: each such
  character is written as a visible escape (``\n``, ``\x1b``, ``\u2028``), so no text can add a line,
  a key or a row to a file, nor a control sequence to a terminal. On top of that each format has its
  own rule: :func:`csv_comment` (no cell a spreadsheet would read as a formula or a quoted field)
  and :func:`xml_comment` (no ``--`` inside an XML comment).
"""

from __future__ import annotations

import html
import re
import unicodedata

from pmsm_commissioning.control.common.checks import ParameterError

#: Unicode categories never written raw: controls, format (bidi) characters, surrogates,
#: private-use and unassigned code points, line and paragraph separators.
FORBIDDEN_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})
#: What a name or source may hold, as a refusal says it.
ALLOWED = ("printable characters on one line: no line break (LF, CR, NEL, U+2028/U+2029, VT, FF), "
           "no control (ESC, BEL, C1) and no bidi or format character")
#: Longest name or source [characters].
LABEL_MAX = 400
_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}
#: First characters that make a spreadsheet read a cell as a formula (or open a quoted field).
_CSV_ACTIVE = frozenset("=+-@\"'")


def forbidden(ch: str) -> bool:
    """Return True when the character ``ch`` is never written raw (see :data:`FORBIDDEN_CATEGORIES`)."""
    return unicodedata.category(ch) in FORBIDDEN_CATEGORIES


def _escape_char(ch: str) -> str:
    code = ord(ch)
    if ch in _NAMED:
        return _NAMED[ch]
    if code < 0x100:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def escaped(text: object) -> str:
    r"""Return ``text`` on one line with every forbidden character as a visible escape (``\n``, ``\x1b``)."""
    s = str(text)
    if s.isprintable() or not any(forbidden(ch) for ch in s):
        return s
    return "".join(_escape_char(ch) if forbidden(ch) else ch for ch in s)


def check_label(text: str, field: str) -> str:
    """Return ``text`` when it may be written as a name or source; ParameterError naming the field otherwise.

    Parameters
    ----------
    text : str   The name or source as given.
    field : str  Where it was given, e.g. ``"--source"`` or ``"Export › Source"``.

    Raises
    ------
    ParameterError
        Naming the field, the value (escaped, shortened) and :data:`ALLOWED`.
    """
    bad = next((ch for ch in text if forbidden(ch)), None)
    if bad is not None:
        shown = escaped(text if len(text) <= 80 else text[:79] + "…")
        raise ParameterError(f"{field} = '{shown}' holds {_escape_char(bad)} (U+{ord(bad):04X}, "
                             f"{unicodedata.category(bad)}): allowed {ALLOWED}")
    if len(text) > LABEL_MAX:
        raise ParameterError(f"{field} is {len(text)} characters long: allowed ≤ {LABEL_MAX}")
    return text


def csv_comment(line: str) -> str:
    """Return a ``#`` comment line's text safe in a CSV file opened by a spreadsheet.

    Escaped (:func:`escaped`: no row can be added); every comma-separated cell whose first
    non-blank character is ``= + - @ " '`` gets a leading ``'`` (a spreadsheet shows it as text,
    never a formula, and no cell opens a quoted field that would swallow the rows below).
    """
    cells = escaped(line).split(",")
    out = []
    for i, cell in enumerate(cells):
        body = cell.lstrip(" ")
        if i > 0 and body[:1] in _CSV_ACTIVE:
            cell = cell[: len(cell) - len(body)] + "'" + body
        out.append(cell)
    return ",".join(out)


def xml_comment(line: str) -> str:
    """Return text safe inside an XML comment: escaped, no ``--`` (written ``- -``), not ending in ``-``."""
    text = re.sub(r"-(?=-)", "- ", escaped(line))
    return text + " " if text.endswith("-") else text


def html_text(text: object) -> str:
    """Make user-provided text safe inside HTML or a Plotly label: ``& < > " '`` become entities.

    The escaping of every user string (file name, column header, note, preset name or source, log
    mapping) that goes into HTML: the page's HTML boxes, Plotly titles and legends, the HTML report.
    """
    return html.escape(str(text), quote=True)


def terminal(text: object) -> str:
    """Return ``text`` for a terminal: escape sequences, BEL, C1 and bidi characters shown escaped."""
    return escaped(text)


__all__ = ["ALLOWED", "FORBIDDEN_CATEGORIES", "LABEL_MAX", "check_label", "csv_comment", "escaped", "forbidden",
           "html_text", "terminal", "xml_comment"]
