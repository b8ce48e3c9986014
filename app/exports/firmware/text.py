r"""The one way text reaches generated C: :func:`c_string`, a C string literal safe anywhere.

Every user-supplied string (a preset's ``name`` and ``source``) and every sentence the tool writes into
``fdsmc_controller.h``/``.c`` (check texts, references) goes through :func:`c_string`. Its result is a
valid C99 string literal for any input, and it is also safe inside a ``/* … */`` comment: it holds only
printable ASCII, never a newline, ``*/``, ``/*``, ``//``, a trigraph (``??``) or a backslash that does
not start an escape — non-ASCII, control characters, ``\``, ``"``, ``?``, ``*`` and ``/`` are written
as octal escapes of their UTF-8 bytes (``\052`` for ``*``). A backslash-newline, ``*/`` or a
``#define`` inside a name therefore cannot end a comment or start a preprocessor line.
:func:`c_comment` writes the tool's own lines (a forced export's failed checks) as an ASCII comment block.
"""

from __future__ import annotations

import unicodedata

#: Characters written as themselves; every other byte becomes a 3-digit octal escape.
_PLAIN = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 !#%&'()+,-.:;<=>[]^_{|}~")
#: Longest text kept [characters]; longer text is cut and marked with "...".
MAX_CHARS = 400


def c_string(text: str) -> str:
    r"""Return ``text`` as a C99 string literal that is also safe inside a C comment.

    Parameters
    ----------
    text : str
        Any text (user input included); cut to :data:`MAX_CHARS` characters.

    Returns
    -------
    str
        ``"…"``: printable ASCII only; bytes outside :data:`_PLAIN` as ``\ooo`` octal escapes
        of the UTF-8 encoding (three digits, so a following digit is never part of the escape).
    """
    if len(text) > MAX_CHARS:
        text = text[: MAX_CHARS - 3] + "..."
    out = []
    for ch in text:
        if ch in _PLAIN:
            out.append(ch)
        else:
            out.extend(f"\\{b:03o}" for b in ch.encode("utf-8", "surrogatepass"))
    return '"' + "".join(out) + '"'


#: Non-ASCII characters of the tool's own texts (check texts, units) → their ASCII spelling in a comment.
_ASCII = {"—": "--", "–": "-", "·": "*", "²": "^2", "³": "^3", "≤": "<=", "≥": ">=", "±": "+/-", "…": "...",
          "Ω": "Ohm", "µ": "u", "×": "x", "−": "-", "°": " deg", "→": "->", "≈": "~", "’": "'", "‘": "'",
          "“": '"', "”": '"'}


def _ascii_char(ch: str) -> str:
    """One character of a comment in ASCII: itself, its spelling, a Greek letter's name, or ``<U+XXXX>``."""
    if " " <= ch <= "~":
        return ch
    if ch in _ASCII:
        return _ASCII[ch]
    name = unicodedata.name(ch, "")
    if name.startswith("GREEK ") and " LETTER " in name:
        letter = name.rsplit(" ", 1)[-1].lower()
        return letter.capitalize() if " CAPITAL " in name else letter
    return f"<U+{ord(ch):04X}>"


def c_comment(lines: list[str]) -> str:
    """Return ``lines`` as one C block comment in printable ASCII (``/* … */`` and a newline).

    Non-ASCII characters are spelled in ASCII (``—`` → ``--``, ``N·m`` → ``N*m``, ``Γ`` → ``Gamma``,
    anything else ``<U+XXXX>``), control characters likewise, and ``*/``, ``/*`` cannot occur inside.
    """
    def plain(line: str) -> str:
        text = "".join(_ascii_char(ch) for ch in line)
        while "*/" in text or "/*" in text:
            text = text.replace("*/", "* /").replace("/*", "/ *")
        return text

    return "/* " + "\n * ".join(plain(line) for line in lines) + "\n */\n"
