"""Parameter fields declared once: SI unit, allowed range, label, display unit and loader units.

Every input field of both modes' parameter dataclasses (:mod:`control.fdsmc.params`,
:mod:`control.bldc.params`) is declared with :func:`spec_field`, which stores a :class:`FieldSpec`
in the dataclass field's metadata. The same spec then drives

* validation: :func:`check_fields` in ``__post_init__`` (the range check and its message);
* the preset loader's unit-suffixed keys (``L_d_mH``): the loader units of :attr:`FieldSpec.loader_units`;
* the page's input fields: label, display unit and the allowed range as a hint;
* the exports: the unit of each input in the parameter file and the C header.

This module names display units but never converts them: conversions live at the edge
(``app/io/units.py``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

#: Metadata key of a dataclass field holding its :class:`FieldSpec`.
SPEC_KEY = "spec"


class ParameterError(ValueError):
    """An input value outside its allowed range; the message names field, value and range."""


@dataclass(frozen=True)
class FieldSpec:
    """The one declaration of a parameter field.

    Attributes
    ----------
    unit : str
        SI unit of the stored value, e.g. ``"H"`` (``"-"`` for a dimensionless count).
    low, high : float or None
        Allowed range in ``unit`` (``None`` = unbounded); ``low`` is exclusive when ``low_open``,
        ``high`` is inclusive.
    low_open : bool
        True when ``low`` itself is not allowed.
    label : str
        What the page calls the field, e.g. ``"L_d"`` or ``"n_b rated speed"``.
    display : str
        Nameplate unit the page shows by default (``""`` = the SI unit), e.g. ``"mH"``.
    aliases : tuple of str
        Further units the preset loader accepts as unit-suffixed keys (besides ``display``).
    integer : bool
        True for a whole-number field (pole pairs); ``low`` and ``high`` are then inclusive.
    keywords : tuple of str
        Texts allowed instead of a number, e.g. ``("T_a",)``; the dataclass gives them meaning.
    """

    unit: str
    low: float | None = None
    high: float | None = None
    low_open: bool = True
    label: str = ""
    display: str = ""
    aliases: tuple[str, ...] = ()
    integer: bool = False
    keywords: tuple[str, ...] = ()

    @property
    def unit_text(self) -> str:
        """The SI unit with the keyword alternatives, e.g. ``"s or 'T_a'"`` (exported ``units``)."""
        return " or ".join([self.unit] + [repr(k) for k in self.keywords])

    @property
    def shown_unit(self) -> str:
        """The unit the page shows by default: ``display`` or else the SI unit."""
        return self.display or self.unit

    @property
    def loader_units(self) -> tuple[str, ...]:
        """Non-SI units the loader accepts as ``<field>_<unit>`` keys, the display unit first."""
        extra = (self.display,) if self.display and self.display != self.unit else ()
        return extra + tuple(a for a in self.aliases if a not in extra and a != self.unit)

    def range_text(self, unit: str | None = None) -> str:
        """Write the allowed range as in messages, e.g. ``"allowed 0 < value ≤ 10 H"``.

        ``unit`` replaces the SI unit in the text (bounds are given in SI units; a caller that shows
        another unit converts the bounds first and builds a new spec).
        """
        return range_text(self.low, self.high, self.low_open, self.unit if unit is None else unit,
                          integer=self.integer)

    def check(self, name: str, value: Any) -> float | int:
        """Return ``value`` checked against the range (an ``int`` for integer fields).

        Raises
        ------
        ParameterError
            Naming ``name``, the value and the allowed range.
        """
        if self.integer:
            return check_integer(name, value, self)
        return check_range(name, value, self.low, self.high, low_open=self.low_open, unit=self.unit)


def spec_field(unit: str, low: float | None = None, high: float | None = None, *, default: Any = dataclasses.MISSING,
               **kwargs: Any) -> Any:
    """Declare a dataclass field carrying its :class:`FieldSpec` (keyword arguments as in ``FieldSpec``)."""
    if kwargs.get("integer"):
        kwargs["low_open"] = False  # an integer range is inclusive at both ends
    spec = FieldSpec(unit, low, high, **kwargs)
    return dataclasses.field(default=default, metadata={SPEC_KEY: spec})


def field_specs(cls: Any) -> dict[str, FieldSpec]:
    """Field name → :class:`FieldSpec` of a parameter dataclass (class or instance), in field order."""
    return {f.name: f.metadata[SPEC_KEY] for f in dataclasses.fields(cls) if SPEC_KEY in f.metadata}


def check_fields(obj: Any, section: str) -> None:
    """Check every spec'd field of ``obj``; integer fields are stored back as ``int``, lists as tuples.

    Raises
    ------
    ParameterError
        Naming ``section.field``, the value and the allowed range of the first bad field.
    """
    for name, spec in field_specs(obj).items():
        value = getattr(obj, name)
        if isinstance(value, str) and value in spec.keywords:  # e.g. T_c = 'T_a': meaning given by the dataclass
            continue
        if isinstance(value, tuple | list):  # a sampled curve: every sample in range
            object.__setattr__(obj, name, tuple(spec.check(f"{section}.{name}[{i}]", v) for i, v in enumerate(value)))
            continue
        checked = spec.check(f"{section}.{name}", value)
        if spec.integer:
            object.__setattr__(obj, name, checked)


def check_range(
    name: str,
    value: Any,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = True,
    unit: str = "",
) -> float:
    """Return ``value`` as float or raise :class:`ParameterError` naming the allowed range.

    Parameters
    ----------
    name : str
        Dotted field name shown to the user, e.g. ``"motor.L_d"``.
    value : Any
        The value to check.
    low, high : float or None
        Bounds (``None`` = unbounded). ``low`` is exclusive when ``low_open`` else inclusive;
        ``high`` is inclusive.
    unit : str
        Unit shown in the message.

    Returns
    -------
    float
        The checked value.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{name} = {value!r} is not a number: {range_text(low, high, low_open, unit)}")
    x = float(value)
    bad = not math.isfinite(x)
    bad = bad or (low is not None and (x <= low if low_open else x < low))
    bad = bad or (high is not None and x > high)
    if bad:
        shown = f"{name} = {value!r} {_unit_word(unit)}".rstrip()
        raise ParameterError(f"{shown} is out of range: {range_text(low, high, low_open, unit)}")
    return x


def check_integer(name: str, value: Any, spec: FieldSpec) -> int:
    """Return a whole number within ``spec``'s inclusive bounds as ``int`` (``4.0`` → 4).

    Raises
    ------
    ParameterError
        Naming ``name``, the value and the allowed range.
    """
    ok = not isinstance(value, bool) and isinstance(value, int | float) and math.isfinite(value)
    ok = ok and float(value).is_integer()
    ok = ok and (spec.low is None or value >= spec.low) and (spec.high is None or value <= spec.high)
    if not ok:
        raise ParameterError(f"{name} = {value!r} is out of range: {spec.range_text()}")
    return int(value)


def _unit_word(unit: str) -> str:
    return "" if unit == "-" else unit


def range_text(low: float | None, high: float | None, low_open: bool, unit: str, *, integer: bool = False) -> str:
    """Write ``"allowed …"``: the range in the words of every range message (unit ``"-"`` not shown)."""
    u = f" {_unit_word(unit)}".rstrip()
    if integer:
        return f"allowed an integer {low:g} … {high:g}{u}"
    if low is not None and high is not None:
        op = "<" if low_open else "≤"
        return f"allowed {low:g} {op} value ≤ {high:g}{u}"
    if low is not None:
        return f"allowed {'>' if low_open else '≥'} {low:g}{u}"
    if high is not None:
        return f"allowed ≤ {high:g}{u}"
    return "allowed any finite number"


__all__ = ["FieldSpec", "ParameterError", "check_fields", "check_integer", "check_range", "field_specs",
           "range_text", "spec_field"]
