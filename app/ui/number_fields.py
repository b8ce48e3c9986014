"""Number fields that keep exactly what the engineer typed.

viser's number widget rounds to a fixed number of decimals and reads ``1e3`` as 13, so every
numeric input of the page is a text field parsed on the server by :func:`app.io.numbers.parse_number`
(the same parser as the CLI and the preset loader). A field the user did not touch returns the exact
SI value it was showing, so export → import returns identical inputs.
"""

from __future__ import annotations

from collections.abc import Callable

import viser

from pmsm_commissioning.app.figures.style import fmt
from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_integer, parse_number
from pmsm_commissioning.app.ui.props import assign

#: Significant digits a field shows (the exact value stays behind an untouched field).
FIELD_DIGITS = 5


def shown_text(value: float | int) -> str:
    """Display text of a value, rounded to its meaning (:func:`app.figures.style.fmt`, 5 significant digits).

    1432.39448783 rpm shows as 1432.4; an untouched field still reads back its exact value.
    """
    return fmt(value, digits=FIELD_DIGITS)


class NumberInput:
    """A text input holding one number; ``read`` returns the exact value shown or the parsed text."""

    def __init__(self, gui: viser.GuiApi, label: str, hint: str | None = None) -> None:
        self.handle = gui.add_text(label, "", hint=hint)
        self._shown = ""
        self._value: float | int = 0.0

    @property
    def label(self) -> str:
        """The label shown on the page."""
        return self.handle.label

    @label.setter
    def label(self, text: str) -> None:
        self.handle.label = text

    @property
    def hint(self) -> str | None:
        """The hover hint (e.g. the allowed range in the shown unit)."""
        return self.handle.hint

    @hint.setter
    def hint(self, text: str | None) -> None:
        self.handle.hint = text

    def show(self, value: float | int, exact: float | int | None = None) -> None:
        """Display ``value``; :meth:`read` returns ``exact`` (default ``value``) while untouched.

        ``exact`` is the SI value behind a converted display (e.g. 5.4 mH shown for 0.0054 H), so
        that an untouched field never changes by a round trip through the display unit.
        """
        self._shown = shown_text(value)
        self._value = value if exact is None else exact
        assign(self.handle, value=self._shown)

    @property
    def touched(self) -> bool:
        """True when the text differs from what was last shown."""
        return self.handle.value != self._shown

    def read(self, field: str, convert: Callable[[float], float] | None = None, integer: bool = False) -> float | int:
        """Return the exact value if untouched, else the typed text parsed (and converted by ``convert``).

        Raises
        ------
        NumberFormatError
            Naming ``field`` when the text is not a number.
        """
        if not self.touched:
            return self._value
        text = self.handle.value
        x: float | int = parse_integer(text, field) if integer else parse_number(text, field)
        return convert(x) if convert is not None else x


__all__ = ["NumberFormatError", "NumberInput", "shown_text"]
