"""The axis as the engineer has it, on the page: load-side inputs, rated values derived, what was inherited.

The load, move and pass criteria may be typed at the transmission's output (the CLI's and the preset
files' load-side keys, :data:`app.io.transmission_keys.OUTPUT_KEYS`): they are reflected onto the
rotor by the same :func:`~app.io.transmission_keys.to_motor_side` as a preset. V_0, P_r and the
rated speed may be left empty (or ``derived``) with a DC link: they are then derived by the loader's
rule (:mod:`app.io.motor_defaults`) and labelled "derived" in the derived-values readout, which also
lists what the run took from the opened preset when a new motor was typed over it
(:func:`app.io.assumed.inherited_over`). No viser here beyond building the fields.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import Any

import viser

from pmsm_commissioning.app.io.assumed import Assumptions, inherited_over
from pmsm_commissioning.app.io.axis_view import transmission_lines
from pmsm_commissioning.app.io.motor_defaults import DERIVABLE, DERIVED, derive_motor, derived_text
from pmsm_commissioning.app.io.numbers import NumberFormatError
from pmsm_commissioning.app.io.presets import list_presets_of, load
from pmsm_commissioning.app.io.transmission_keys import OUTPUT_KEYS, to_motor_side
from pmsm_commissioning.app.ui.number_fields import NumberInput
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.transmission import Transmission

#: The load-side keys the page offers (section, key, label); the rest stay in preset files and ``--set``.
PAGE_OUTPUT_KEYS = (
    ("load", "J_L_out", "J at the output"), ("load", "mass_kg", "Moved mass (linear axis)"),
    ("load", "Gamma_Le_out", "Load torque at the output"), ("load", "force_N", "Load force (linear axis)"),
    ("manoeuvre", "theta_dem_out_deg", "Move at the output"), ("manoeuvre", "distance_mm", "Travel (linear axis)"),
    ("limits", "in_position_out_deg", "In-position window at the output"),
    ("limits", "in_position_um", "In-position window (linear axis)"),
)


class InputError(ValueError):
    """Invalid form input; the message names the field and the allowed range (as :class:`app.ui.inputs.InputError`)."""


class OutputSideInputs:
    """Optional load-side fields in the Transmission folder; an empty field leaves the rotor-side value."""

    def __init__(self, gui: viser.GuiApi) -> None:
        self.numbers = {f"{s}.{k}": NumberInput(gui, f"{label} [{OUTPUT_KEYS[s][k].unit}]",
                                                hint=f"Optional: sets {s}.{OUTPUT_KEYS[s][k].field} through the "
                                                     f"transmission ({s}.{k} in a preset)")
                        for s, k, label in PAGE_OUTPUT_KEYS}
        self.clear()

    def clear(self) -> None:
        """Empty every load-side field (a new case opened)."""
        for n in self.numbers.values():
            assign(n.handle, value="")

    def reflected(self, tr: Transmission) -> dict[str, dict[str, float]]:
        """Return the rotor-side values [SI] of the load-side fields typed, per section.

        Raises
        ------
        InputError
            A field that is not a number, a key of the other kind of axis, or a reflected value out of range.
        """
        raw: dict[str, Any] = {}
        for key, n in self.numbers.items():
            if n.handle.value.strip():
                section, _, name = key.partition(".")
                try:
                    raw.setdefault(section, {})[name] = float(n.read(f"Transmission › {n.label}"))
                except NumberFormatError as exc:
                    raise InputError(str(exc)) from None
        try:
            return {s: dict(v) for s, v in to_motor_side(raw, tr, lambda _k, x: x).items()}
        except ValueError as exc:
            raise InputError(f"Transmission › {exc}") from None


def rated_left_out(numbers: dict[str, NumberInput]) -> tuple[str, ...]:
    """Return the motor's rated fields left empty or ``derived`` on the page (derived from the inverter)."""
    return tuple(f for f in DERIVABLE if numbers[f"motor.{f}"].handle.value.strip() in ("", DERIVED))


def with_rated_derived(params: DriveParams, fields: tuple[str, ...]) -> DriveParams:
    """Return ``params`` with the rated ``fields`` derived from the inverter (InputError naming why not)."""
    try:
        motor = derive_motor(params.motor, params.controller, fields)
    except ParameterError as exc:
        raise InputError(f"Motor nameplate › {exc}") from None
    return dataclasses.replace(params, motor=motor)


@functools.lru_cache(maxsize=16)
def shipped_preset(name: str) -> DriveParams | None:
    """Return the shipped position preset ``name`` as loaded (None for anything else: a file, an upload)."""
    return load(name, mode="position") if name in list_presets_of("position") else None


def axis_markdown(params: DriveParams, derived_fields: tuple[str, ...], origin: str) -> str:
    """Return the derived-values readout's lines below the table: rated values derived, transmission, inherited.

    Inherited values are listed against the shipped preset ``origin`` the case was opened from.
    """
    lines = [f"- **derived** (not typed): {md_text(t)}" for t in derived_text(params.motor, derived_fields)]
    lines += [f"- {md_text(t)}" for t in transmission_lines(params)]
    base = shipped_preset(origin)
    inherited = inherited_over(base, params) if base is not None else ()
    if inherited:
        lines += [f"- ⚠ {md_text(t)}" for t in Assumptions(origin, inherited, ()).lines()]
    return "\n".join(lines)


__all__ = ["PAGE_OUTPUT_KEYS", "InputError", "OutputSideInputs", "axis_markdown", "rated_left_out",
           "shipped_preset", "with_rated_derived"]
