"""What the user did not type: values inherited from a base preset and rated values derived.

When an engineer types a new motor over a shipped preset (``--set motor.…`` on ``yaskawa_sgm7j_04a``)
or imports a drive file onto a base (``import-drive --base``, whose preset lists them under
``inherited``), everything else — the pass criteria, the sensors and ADC, the friction and load, the
inverter, the move — still comes from the base. :func:`assumptions` lists those values, and the
rated values the loader derived (:mod:`app.io.motor_defaults`), so that ``design`` and ``simulate``
can print them: nothing is carried over silently.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.app.io import motor_defaults, units
from pmsm_commissioning.app.io.preset_schema import field_of
from pmsm_commissioning.app.io.presets import apply_overrides
from pmsm_commissioning.app.io.transmission_keys import as_aliases
from pmsm_commissioning.control.common.checks import field_specs
from pmsm_commissioning.control.fdsmc.params import DriveParams

#: Top-level key of a preset listing the fields that came from a base preset (``import-drive``).
INHERITED = "inherited"
#: Sections whose fields are listed when inherited; controller gains are left out (``design`` sets them).
_LISTED = ("motor", "load", "controller", "sensors", "limits", "manoeuvre", "transmission")
_CONTROLLER_LISTED = ("T_si", "f_s", "delay_samples", "V_dc", "i_max", "T_dv")


@dataclass(frozen=True)
class Assumed:
    """One value the user did not type: ``key`` (``section.field``), its value in ``unit``, and why."""

    key: str
    value: Any
    unit: str
    why: str

    @property
    def text(self) -> str:
        """``key = value unit`` as the outputs print it."""
        v = f"{self.value:.4g}" if isinstance(self.value, float) else str(self.value)
        return f"{self.key} = {v} {self.unit if self.unit != '-' else ''}".rstrip()


@dataclass(frozen=True)
class Assumptions:
    """Values inherited from ``base`` (None: nothing inherited) and the rated values derived."""

    base: str | None
    inherited: tuple[Assumed, ...]
    derived: tuple[Assumed, ...]

    def lines(self) -> list[str]:
        """Lines of the text outputs (empty when the user typed everything)."""
        out = [f"derived (not typed): {a.text} — {a.why}" for a in self.derived]
        if self.inherited:
            out.append(f"inherited from {self.base} (not typed; check them for this drive): "
                       + ", ".join(a.text for a in self.inherited))
        return out

    def to_json(self) -> dict[str, Any]:
        """Return the ``assumptions`` entry of the JSON outputs."""
        return {"base": self.base, "inherited": [_row(a) for a in self.inherited],
                "derived": [_row(a) for a in self.derived]}


def _row(a: Assumed) -> dict[str, Any]:
    return {"key": a.key, "value": a.value, "unit": a.unit, "why": a.why}


def _typed(overrides: tuple[str, ...]) -> set[str]:
    """``section.field`` of every override (a unit-suffixed or load-side key names its field)."""
    out = set()
    for item in overrides:
        key = item.partition("=")[0].strip()
        section, _, name = key.partition(".")
        aliases = units.ALIASES.get(section, {}) | as_aliases(section)
        out.add(f"{section}.{field_of(name, aliases, list(units.FLUX_KEYS))}")
    return out


def _value(params: DriveParams, key: str) -> Assumed:
    section, _, name = key.partition(".")
    spec = field_specs(units.SECTION_CLASSES[section])[name]
    value = getattr(getattr(params, section), name)
    unit = spec.shown_unit
    shown = units.from_si(value, unit) if isinstance(value, float) else value
    return Assumed(key, shown, unit if not isinstance(value, str) else "", "")


def _default_none(params: DriveParams, key: str) -> bool:
    """Return True for a field at its default that means "none" (the seed, no ramp, a direct drive): not listed."""
    section, _, name = key.partition(".")
    if key in ("sensors.seed", "load.Gamma_Le_ramp") or section == "transmission":
        default = next(f.default for f in dataclasses.fields(units.SECTION_CLASSES[section]) if f.name == name)
        return getattr(getattr(params, section), name) == default
    return False


def _listed_keys() -> list[str]:
    keys = []
    for section in _LISTED:
        names = field_specs(units.SECTION_CLASSES[section])
        keys += [f"{section}.{n}" for n in names if section != "controller" or n in _CONTROLLER_LISTED]
    return keys


def inherited_over(base: DriveParams, params: DriveParams) -> tuple[Assumed, ...]:
    """Return the listed values ``params`` kept from ``base`` when a motor field differs (a motor typed over it).

    The page's counterpart of :func:`assumptions`: what the engineer changed is what differs from the
    opened preset ``base``; nothing is listed while the motor is the preset's own.
    """
    def value(p: DriveParams, key: str) -> Any:
        section, _, name = key.partition(".")
        return getattr(getattr(p, section), name)

    keys = _listed_keys()
    changed = {k for k in keys if value(base, k) != value(params, k)}
    if not any(k.startswith("motor.") for k in changed):
        return ()
    return tuple(_value(params, k) for k in keys if k not in changed and not _default_none(params, k))


def inherited_block(base: str, given: set[str]) -> dict[str, Any]:
    """Return the ``inherited`` entry of a preset built over ``base``: every listed field not in ``given``.

    ``given`` holds the ``section.field`` keys the new preset's source did set (e.g. an import's
    motor values); ``design`` and ``simulate`` then list the others as inherited.
    """
    return {"base": base, "fields": [k for k in _listed_keys() if k not in given]}


def assumptions(raw: Any, params: DriveParams, overrides: tuple[str, ...] = (), base: str | None = None
                ) -> Assumptions:
    """List what ``params`` took from a base preset and what the loader derived.

    Parameters
    ----------
    raw : mapping          The preset file's raw mapping, before the overrides.
    params : DriveParams   The loaded parameters (overrides applied).
    overrides : tuple      The ``--set section.field=value`` overrides.
    base : str or None     The preset's name (the base the overrides were typed over).

    Inherited values are listed when the overrides type a motor field over ``base`` (a new motor on
    a shipped preset), or when the file itself names its ``inherited`` fields (``import-drive``).
    """
    typed = _typed(overrides)
    fields = motor_defaults.derived_fields(apply_overrides(copy.deepcopy(raw), overrides))
    derived = tuple(dataclasses.replace(_value(params, f"motor.{f}"), why=motor_defaults.RULES[f]) for f in fields)
    block = raw.get(INHERITED) if isinstance(raw, dict) else None
    if isinstance(block, dict):
        base, keys = str(block.get("base", base)), [str(k) for k in block.get("fields", [])]
    elif any(k.startswith("motor.") and k[6:] not in fields for k in typed):
        keys = _listed_keys()
    else:
        return Assumptions(None, (), derived)
    skip = typed | {f"motor.{f}" for f in fields}
    inherited = tuple(_value(params, k) for k in keys if k not in skip and k in set(_listed_keys())
                      and not _default_none(params, k))
    return Assumptions(base, inherited, derived)


__all__ = ["INHERITED", "Assumed", "Assumptions", "assumptions", "inherited_block", "inherited_over"]
