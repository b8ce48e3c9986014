"""Inputs of the studies shared by the command line and the page: robustness spreads and multi-axis sets.

Spreads, each on a plant value (see :mod:`app.io.plant_overrides`), in SI: ``plant.J_L=0:0.3``
uniform between 0 and 0.3; ``plant.R_s=±20%`` (or ``+-20%``) uniform within ±20 % of the preset's
value; ``plant.psi_pm=~5%`` normal with σ = 5 % of it (truncated at ±3σ).

A multi-axis set is a YAML list of axes, each ``{preset: NAME_OR_PATH, set: [SECTION.FIELD=VALUE, …],
name: LABEL}`` (``set`` and ``name`` optional).
"""

from __future__ import annotations

from typing import Any

from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_number
from pmsm_commissioning.app.io.plant_overrides import plant_section
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.studies.robustness import MAX_NORMAL_SIGMA, Spread

#: Most axes of one multi-axis set [-].
MAX_AXES = 16


def _number(text: str, item: str) -> float:
    """Return a number of a ``--spread`` item, parsed by the one grammar (:func:`app.io.numbers.parse_number`)."""
    try:
        return parse_number(text, f"--spread {item!r}")
    except NumberFormatError as exc:
        raise ParameterError(str(exc)) from None


def parse_spread(item: str) -> Spread:
    """One ``plant.FIELD=DIST`` item → :class:`Spread` (see the module docstring)."""
    key, sep, dist = item.strip().partition("=")
    if not sep or not key.startswith("plant."):
        raise ParameterError(f"--spread {item!r} is not allowed: the form is plant.FIELD=DIST")
    field, dist = key[len("plant."):], dist.strip()
    section = plant_section(field)
    if dist.startswith(("±", "+-", "~")) and dist.endswith("%"):
        x = _number(dist.lstrip("±+-~")[:-1], item) / 100.0
        if dist.startswith("~"):
            if not 0.0 <= x <= MAX_NORMAL_SIGMA:
                raise ParameterError(f"--spread {item!r}: σ = {100 * x:g} % is not allowed: 0 … "
                                     f"{100 * MAX_NORMAL_SIGMA:g} %")
            return Spread(section, field, "normal", 0.0, x)
        if not 0.0 <= x < 1.0:
            raise ParameterError(f"--spread {item!r}: ±{100 * x:g} % is not allowed: 0 … <100 %")
        return Spread(section, field, "relative", -x, x)
    lo, colon, hi = dist.partition(":")
    if not colon:
        raise ParameterError(f"--spread {item!r}: {dist!r} is not allowed: LO:HI, ±X% or ~X%")
    a, b = _number(lo, item), _number(hi, item)
    if b < a:
        raise ParameterError(f"--spread {item!r}: the range {a:g}:{b:g} is not allowed: LO ≤ HI")
    return Spread(section, field, "uniform", a, b)


def parse_spreads(items: list[str]) -> list[Spread]:
    """All ``--spread`` options (each may hold a comma-separated list)."""
    return [parse_spread(x) for item in items for x in item.split(",") if x.strip()]



def parse_axes(raw: Any, origin: str) -> list[tuple[str, DriveParams]]:
    """Parse the YAML list into (name, params) per axis, with clear messages for a bad entry."""
    if not isinstance(raw, list) or not 1 <= len(raw) <= MAX_AXES:
        raise ParameterError(f"{origin}: expected a YAML list of 1 … {MAX_AXES} axes")
    axes = []
    for i, item in enumerate(raw):
        where = f"{origin}: axis {i + 1}"
        if not isinstance(item, dict) or not isinstance(item.get("preset"), str):
            raise ParameterError(f"{where}: expected a mapping with 'preset: NAME' (and optional set, name)")
        unknown = set(item) - {"preset", "set", "name"}
        if unknown:
            raise ParameterError(f"{where}: unknown key(s) {', '.join(sorted(map(str, unknown)))}: "
                                 "allowed preset, set, name")
        sets = item.get("set", [])
        if not isinstance(sets, list) or not all(isinstance(s, str) for s in sets):
            raise ParameterError(f"{where}: 'set' must be a list of SECTION.FIELD=VALUE strings")
        params = load_preset(item["preset"], sets)
        if not isinstance(params, DriveParams):
            raise ParameterError(f"{where}: preset {item['preset']!r} is not a position drive")
        axes.append((str(item.get("name", f"axis {i + 1}")), params))
    return axes

__all__ = ["MAX_AXES", "parse_axes", "parse_spread", "parse_spreads"]
