"""The display-unit layer of both tabs: what a number field shows, in which unit, and its SI value.

Conversions are :mod:`app.io.units`'s (one table, driven by each field's
:class:`~control.common.checks.FieldSpec`); this module adds what the page needs on top: the unit
choices of a selector (inertia in kg·m² or kg·cm², R_s and L per phase or line-to-line, Ψ_PM or Ke,
Kt per A_rms or per A peak, Kv; T_si or the drive's current-loop bandwidth), a field's label with
its unit, and its allowed range written in the shown unit. The position tab's :class:`Field` and the
BLDC tab's :func:`field_label`/:func:`shown_value`/:func:`si_value` are the same layer.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from pmsm_commissioning.app.io import units
from pmsm_commissioning.control.common.checks import FieldSpec

Conv = Callable[[float, int], float]  # (value, pole pairs) → value


def _same(x: float, _p: int) -> float:
    return x


@dataclass(frozen=True)
class Unit:
    """A display unit: label and converters to/from SI (they may need the pole pairs p)."""

    label: str
    to_si: Conv = _same
    from_si: Conv = _same


def _named(unit: str) -> Unit:
    """Make a display unit converted by :mod:`app.io.units` (``"kg·cm²"``, ``"deg"`` …; an SI unit as is)."""
    return Unit(unit, lambda x, _p: units.to_si(x, unit), lambda x, _p: units.from_si(x, unit))


def _choices(key: str) -> tuple[Unit, ...]:
    """List the units a field's spec offers: its shown unit first, then the loader's other units."""
    spec = units.spec_of(key)
    return tuple(_named(u) for u in dict.fromkeys((spec.shown_unit, spec.unit, *spec.loader_units)))


def _winding(label: str, k: float, key: str) -> Unit:
    """Per phase (k = 1) or line-to-line (k = 2) in the spec's display unit of ``key``."""
    unit = units.spec_of(key).shown_unit
    return Unit(label, lambda x, _p: units.to_si(x, unit) / k, lambda x, _p: units.from_si(x, unit) * k)


#: Unit choices per selector; the first is the default.
UNIT_GROUPS: dict[str, tuple[Unit, ...]] = {
    "inertia": _choices("motor.J_r"),
    "angle": _choices("manoeuvre.theta_dem"),
    "flux": (Unit("Ψ_PM [Wb]"),
             Unit("Ke [V_rms LL/krpm]", lambda x, p: units.ke_vrms_krpm_to_psi_pm(x, p),
                  lambda x, p: units.psi_pm_to_ke_vrms_krpm(x, p)),
             Unit("Kt [N·m/A_rms]", lambda x, p: units.kt_nm_per_arms_to_psi_pm(x, p),
                  lambda x, p: units.psi_pm_to_kt_nm_per_arms(x, p)),
             Unit("Kt [N·m/A peak]", lambda x, p: units.kt_nm_per_apeak_to_psi_pm(x, p),
                  lambda x, p: units.psi_pm_to_kt_nm_per_apeak(x, p)),
             Unit("Kv [rpm/V LL peak]", lambda x, p: units.kv_rpm_per_v_to_psi_pm(x, p),
                  lambda x, p: units.psi_pm_to_kv_rpm_per_v(x, p))),
    "current": (Unit("A peak"),
                Unit("A_rms", lambda x, _p: units.to_si(x, "Arms"), lambda x, _p: units.from_si(x, "Arms"))),
    "resistance": (_winding("per phase", 1.0, "motor.R_s"), _winding("line-to-line", 2.0, "motor.R_s")),
    # T_si, or the drive's current-loop bandwidth ω_c it follows from: T_si = 3/ω_c (eq. (8) of [1])
    "settling": (_named(units.spec_of("controller.T_si").shown_unit),
                 Unit("ω_c current-loop bandwidth [Hz]", lambda x, _p: units.bandwidth_to_T_si(2.0 * math.pi * x),
                      lambda x, _p: units.bandwidth_to_T_si(x) / (2.0 * math.pi)),
                 Unit("ω_c current-loop bandwidth [rad/s]", lambda x, _p: units.bandwidth_to_T_si(x),
                      lambda x, _p: units.bandwidth_to_T_si(x))),
    "inductance": (_winding("per phase", 1.0, "motor.L_d"), _winding("line-to-line", 2.0, "motor.L_d")),
}
@dataclass(frozen=True)
class Field:
    """One numeric input: SI field ``section.name`` shown as ``label [unit]``.

    Label, display unit and allowed range come from the field's spec (:func:`app.io.units.spec_of`);
    ``group`` names the selector whose unit choice applies instead of the spec's display unit.
    """

    section: str
    name: str
    group: str | None = None

    @property
    def key(self) -> str:
        """``section.name``."""
        return f"{self.section}.{self.name}"

    @property
    def spec(self) -> FieldSpec:
        """The field's one declaration (unit, range, label)."""
        return units.spec_of(self.key)

    @property
    def label(self) -> str:
        """The page label without unit."""
        return self.spec.label

    @property
    def unit(self) -> str:
        """The fixed display unit (fields without a selector)."""
        return self.spec.shown_unit

    @property
    def integer(self) -> bool:
        """True for a whole-number field."""
        return self.spec.integer

    def unit_of(self, choice: Unit | None) -> str:
        """Display unit text for the selector's ``choice``."""
        if self.group in ("resistance", "inductance") and choice is not None:
            return f"{self.spec.shown_unit}, {choice.label}"
        return choice.label if choice is not None else self.unit

    def text(self, choice: Unit | None = None) -> str:
        """Label with unit, as shown on the page; a choice that names a quantity (``Kt [N·m/A peak]``) replaces it."""
        if choice is not None and "[" in choice.label:
            return choice.label
        return f"{self.label} [{self.unit_of(choice)}]"

    def hint(self, choice: Unit | None, p: int) -> str:
        """Write the allowed range in the shown unit, e.g. ``"allowed 1e-06 ≤ value ≤ 10000 mH"``."""
        if choice is None:
            return units.shown_range(self.spec)
        named = "[" in choice.label
        unit = choice.label.partition("[")[2].rstrip("]") if named else self.unit_of(choice)
        return units.range_in(self.spec, lambda b: choice.from_si(b, p), unit)


def field_label(key: str) -> str:
    """Return the page label of ``section.field``: spec label and display unit, e.g. ``"L_s − M_s [mH]"``."""
    spec = units.spec_of(key)
    return f"{spec.label} [{spec.shown_unit}]"


def field_hint(key: str) -> str:
    """Return the allowed range of ``section.field`` in its display unit (a page hint)."""
    return units.shown_range(units.spec_of(key))


def shown_value(key: str, si: float) -> float | int:
    """Return an SI value of ``section.field`` in its display unit (an integer field as an int)."""
    spec = units.spec_of(key)
    return int(si) if spec.integer else units.from_si(si, spec.shown_unit)


def si_value(key: str, shown: float) -> float:
    """Return the SI value of a number given in the display unit of ``section.field``."""
    return units.to_si(shown, units.spec_of(key).shown_unit)


__all__ = ["UNIT_GROUPS", "Field", "Unit", "field_hint", "field_label", "shown_value", "si_value"]
