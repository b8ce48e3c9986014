"""Shared pieces of the vendor writers and strict parsers: documented keys, typed values, parsed files.

Each vendor module declares the keys it writes or reads as :class:`VendorKey` (the key exactly as
the vendor spells it, its type and the vendor's unit, and where the vendor documents it). The
strict parsers return a :class:`VendorFile`: the values of the known keys (checked against their
type), every other key *listed* in ``unknown`` (never silently dropped) and the file's comment.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_number
from pmsm_commissioning.control.common.checks import ParameterError

#: Value kinds of a vendor key.
KINDS = ("float", "int", "enum")


@dataclass(frozen=True)
class VendorKey:
    """One key of a vendor format.

    Attributes
    ----------
    key : str    The key (dotted path, config name or XML tag) exactly as the vendor spells it.
    kind : str   ``float`` (a finite number), ``int`` (an integer) or ``enum`` (an integer code).
    unit : str   The vendor's unit as the vendor writes it (``-`` for counts and codes).
    doc : str    Where the vendor documents it.
    nan_unset : bool  ``nan`` is the vendor's documented "not set" (e.g. moteus' trajectory limits).
    """

    key: str
    kind: str
    unit: str
    doc: str
    nan_unset: bool = False


@dataclass(frozen=True)
class VendorFile:
    """A parsed vendor file: known keys' values (vendor units), the unknown keys, the comment lines."""

    values: tuple[tuple[str, float], ...]
    unknown: tuple[str, ...]
    comment: tuple[str, ...] = ()

    def get(self, key: str) -> float | None:
        """Return the value of ``key`` (vendor units), None when the file does not hold it."""
        return next((v for k, v in self.values if k == key), None)

    def require(self, key: str, what: str) -> float:
        """Return the value of ``key``; ParameterError naming the key when it is missing."""
        v = self.get(key)
        if v is None:
            raise ParameterError(f"{key} is missing: the file must give {what}")
        return v


def _from_text(vk: VendorKey, raw: str, allowed: str) -> float:
    """Parse a vendor file's text value with the one number grammar (:func:`app.io.numbers.parse_number`)."""
    if raw.strip().lower() == "nan":
        return math.nan  # allowed only where the vendor documents it as "not set" (checked by the caller)
    try:
        return parse_number(raw, vk.key)
    except NumberFormatError as exc:
        if "underflows" in str(exc):
            raise ParameterError(str(exc)) from None
        raise ParameterError(f"{vk.key} = {raw[:80]!r} is not allowed: {allowed} (ASCII digits, decimal or "
                             "scientific notation)") from None


def typed_value(vk: VendorKey, raw: object) -> float:
    """Check a raw value against its key's kind; ParameterError naming the key, the value and what is allowed.

    Text goes through the one number grammar (ASCII digits; ``1_0``, full-width or Arabic-Indic
    digits are refused); ``nan`` only for a key whose vendor documents it as "not set".
    """
    allowed = {"float": f"a finite number in {vk.unit}", "int": "an integer",
               "enum": "an integer code"}[vk.kind]
    if isinstance(raw, str):
        raw = _from_text(vk, raw, allowed)
    if isinstance(raw, bool) or not isinstance(raw, int | float):
        raise ParameterError(f"{vk.key} = {raw!r} is not allowed: {allowed}")
    if vk.nan_unset and isinstance(raw, float) and math.isnan(raw):
        return raw
    if not math.isfinite(raw) or (vk.kind != "float" and not float(raw).is_integer()):
        raise ParameterError(f"{vk.key} = {raw!r} is not allowed: {allowed}")
    return int(raw) if vk.kind != "float" else float(raw)


def vendor_file(pairs: Iterable[tuple[str, object]], known: Mapping[str, VendorKey],
                comment: Iterable[str] = ()) -> VendorFile:
    """Split (key, raw value) pairs into typed known values and listed unknown keys.

    Raises
    ------
    ParameterError
        For a key given twice or a known key whose value is not of its kind.
    """
    values: list[tuple[str, float]] = []
    unknown: list[str] = []
    seen: set[str] = set()
    for key, raw in pairs:
        if key in seen:
            raise ParameterError(f"{key} is given more than once: allowed once")
        seen.add(key)
        if key in known:
            values.append((key, typed_value(known[key], raw)))
        else:
            unknown.append(key)
    return VendorFile(tuple(values), tuple(unknown), tuple(comment))


def fmt_float(x: float) -> str:
    """Write a float with 9 significant digits (float32 round-trips exactly; no exponent surprises)."""
    text = f"{x:.9g}"
    return text if any(ch in text for ch in ".en") else f"{text}.0"
