"""Input folders of the position-drive tab: nameplate, load, controller, manoeuvre.

Values are shown in commissioning units (mH, rpm, kW, ms, kHz) with the unit in every label and
converted to SI here, at the edge. Nothing is committed while typing: :meth:`InputsPanel.collect`
reads the fields when the user presses Simulate (or Enter in the form) and validates them with
the same loader as the CLI and YAML files (:func:`app.presets.parse_preset`). A field the user did
not touch keeps its exact SI value, so export → import returns identical inputs.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import viser

from app import units
from app.presets import parse_preset, to_raw
from control.params import DriveParams


@dataclass(frozen=True)
class Field:
    """One numeric input: SI field ``section.name`` shown as ``label [unit]``."""

    section: str
    name: str
    label: str
    unit: str
    to_si: Callable[[float], float] = float
    from_si: Callable[[float], float] = float
    integer: bool = False

    @property
    def text(self) -> str:
        """Label with unit, as shown on the page."""
        return f"{self.label} [{self.unit}]"


def _k(x: float) -> float:
    return x * 1e-3


FIELDS: tuple[Field, ...] = (
    Field("motor", "V_0", "V_0 rated (LL rms)", "V"),
    Field("motor", "P_r", "P_r rated power", "kW", units.kW_to_W, _k),
    Field("motor", "omega_b", "n_b base speed", "rpm", units.rpm_to_rad_s, units.rad_s_to_rpm),
    Field("motor", "Gamma_max", "Γ_max max torque", "N·m"),
    Field("motor", "psi_pm", "Ψ_PM PM flux", "Wb"),
    Field("motor", "L_d", "L_d", "mH", units.mH_to_H, lambda x: x * 1e3),
    Field("motor", "L_q", "L_q", "mH", units.mH_to_H, lambda x: x * 1e3),
    Field("motor", "R_s", "R_s", "Ω"),
    Field("motor", "p", "p pole pairs", "-", integer=True),
    Field("motor", "J_r", "J_r rotor inertia", "kg·m²"),
    Field("load", "J_L", "J_L load inertia", "kg·m²"),
    Field("load", "F_v", "F_v viscous friction", "N·m·s/rad"),
    Field("load", "Gamma_Le", "Γ_Le load torque at t=0", "N·m"),
    Field("load", "Gamma_Le_ramp", "Γ_Le ramp", "N·m/s"),
    Field("controller", "T_si", "T_si current settling", "ms", units.ms_to_s, lambda x: x * 1e3),
    Field("controller", "T_salpha", "T_sα accel. settling", "ms", units.ms_to_s, lambda x: x * 1e3),
    Field("controller", "T_so", "T_so observer settling", "ms", units.ms_to_s, lambda x: x * 1e3),
    Field("controller", "K", "K boundary-layer gain", "s/rad"),
    Field("manoeuvre", "theta_dem", "θ_dem demanded angle", "rad"),
    Field("manoeuvre", "T_m", "T_m manoeuvre time", "s"),
)
FOLDERS = (("motor", "Motor nameplate"), ("load", "Load"), ("controller", "Controller"),
           ("manoeuvre", "Manoeuvre"))
#: Decimal places a number field shows and accepts.
PRECISION = 6
TC_RULES = ("T_c = T_a, eq. (59)", "T_c given below")
FS_MODES = ("digital, sampled at f_s", "continuous")


class InputError(ValueError):
    """Invalid form input; the message names the field (with its page label) and the allowed range."""


def format_steps(steps: tuple[Any, ...]) -> str:
    """Load-torque steps → ``"t:Γ, t:Γ"`` text [s, N·m]."""
    return ", ".join(f"{s.t:g}:{s.Gamma_Le:g}" for s in steps)


def parse_steps(text: str) -> list[dict[str, float]]:
    """``"t:Γ, t:Γ"`` [s, N·m] → list of step mappings; InputError on malformed text."""
    out: list[dict[str, float]] = []
    for item in filter(None, (s.strip() for s in text.replace(";", ",").split(","))):
        t_txt, sep, g_txt = item.partition(":")
        try:
            if not sep:
                raise ValueError
            out.append({"t": float(t_txt), "Gamma_Le": float(g_txt)})
        except ValueError:
            raise InputError(
                f"Load › torque steps: {item!r} is malformed: allowed 't:Γ_Le' pairs in s and N·m, "
                "separated by commas, e.g. '0.5:10, 1.2:0'") from None
    return out


class InputsPanel:
    """The input folders on one client's GUI; build inside the current container context."""

    def __init__(self, gui: viser.GuiApi, params: DriveParams) -> None:
        self._gui = gui
        self._params = params
        self._shown: dict[str, float] = {}
        self.numbers: dict[str, viser.GuiNumberHandle] = {}
        for section, title in FOLDERS:
            with gui.add_folder(title):
                for f in (f for f in FIELDS if f.section == section):
                    handle = gui.add_number(f.text, 0 if f.integer else 0.0, step=1 if f.integer else 0.01)
                    handle.precision = 0 if f.integer else PRECISION
                    self.numbers[f"{f.section}.{f.name}"] = handle
                self._extra(section)
        self.populate(params)

    def _extra(self, section: str) -> None:
        gui = self._gui
        if section == "load":
            self.steps = gui.add_text("Γ_Le steps [t s : N·m, …]", "",
                                      hint="Later steps of the external load torque, e.g. 0.5:10, 1.2:0")
        elif section == "controller":
            self.tc_rule = gui.add_dropdown("T_c rule", TC_RULES)
            self.tc_ms = gui.add_number("T_c sliding time const. [ms]", 5.0, step=0.1)
            self.tc_ms.precision = PRECISION
            self.alpha_rule = gui.add_dropdown("α_max rule", ("paper", "torque_limit"),
                                               hint="paper: α_max = H·P_r/V_0 (sec. 5); torque_limit: eq. (4b)")
            self.fs_mode = gui.add_dropdown("Controller", FS_MODES)
            self.fs_khz = gui.add_number("f_s sample rate [kHz]", 20.0, step=1.0)
            self.fs_khz.precision = 3
            self.delay = gui.add_dropdown("Computation delay [samples]", ("0", "1"))

    def populate(self, params: DriveParams) -> None:
        """Show ``params`` in the fields; remembers them as the unchanged reference."""
        self._params = params
        raw = to_raw(params)
        for f in FIELDS:
            key = f"{f.section}.{f.name}"
            shown = f.from_si(raw[f.section][f.name])
            shown = int(shown) if f.integer else float(shown)
            self._shown[key] = shown
            self.numbers[key].value = shown
        c = params.controller
        self.steps.value = format_steps(params.load.steps)
        self.tc_rule.value = TC_RULES[0] if c.T_c == "T_a" else TC_RULES[1]
        if c.T_c != "T_a":
            self.tc_ms.value = float(c.T_c) * 1e3
        self.alpha_rule.value = c.alpha_max_rule
        self.fs_mode.value = FS_MODES[1] if c.is_continuous else FS_MODES[0]
        if not c.is_continuous:
            self.fs_khz.value = float(c.f_s) * 1e-3
        self.delay.value = str(c.delay_samples)
        self._shown["tc_ms"], self._shown["fs_khz"] = self.tc_ms.value, self.fs_khz.value

    def set_T_c(self, T_c: float) -> None:
        """Select "T_c given below" and show ``T_c`` [s] (e.g. "use T_c,min")."""
        self.tc_rule.value = TC_RULES[1]
        self.tc_ms.value = units.s_to_ms(T_c)

    def set_value(self, key: str, value_si: float) -> None:
        """Set one numeric field from an SI value (e.g. "use recommended K")."""
        f = next(f for f in FIELDS if f"{f.section}.{f.name}" == key)
        self.numbers[key].value = f.from_si(value_si)

    def _number(self, f: Field, raw_value: float) -> float:
        key = f"{f.section}.{f.name}"
        value = self.numbers[key].value
        if value == self._shown[key]:
            return raw_value  # untouched: keep the exact SI value
        if not isinstance(value, int | float) or not math.isfinite(value):
            raise InputError(f"{key} [{f.unit}] = {value!r} is not a finite number")
        return f.to_si(value) if not f.integer else value

    def collect(self) -> DriveParams:
        """Validate the fields and return the new parameters.

        Raises
        ------
        InputError
            Naming the page label, the SI field, the value and the allowed range.
        """
        raw = to_raw(self._params)
        for f in FIELDS:
            raw[f.section][f.name] = self._number(f, raw[f.section][f.name])
        raw["load"]["steps"] = parse_steps(self.steps.value)
        c = raw["controller"]
        if self.tc_rule.value == TC_RULES[0]:
            c["T_c"] = "T_a"
        elif self.tc_ms.value != self._shown["tc_ms"] or c["T_c"] == "T_a":
            c["T_c"] = units.ms_to_s(self.tc_ms.value)
        c["alpha_max_rule"] = self.alpha_rule.value
        if self.fs_mode.value == FS_MODES[1]:
            c["f_s"] = "continuous"
        elif self.fs_khz.value != self._shown["fs_khz"] or c["f_s"] == "continuous":
            c["f_s"] = units.kHz_to_Hz(self.fs_khz.value)
        c["delay_samples"] = int(self.delay.value)
        try:
            return parse_preset(raw)
        except ValueError as exc:
            raise InputError(_with_label(str(exc))) from None


def _with_label(message: str) -> str:
    """Prefix a loader message with the page label of the field it names (SI values stay in it)."""
    for f in FIELDS:
        if message.startswith(f"{f.section}.{f.name} "):
            folder = dict(FOLDERS)[f.section]
            return f"{folder} › {f.text}: {message}"
    return message


__all__ = ["FIELDS", "FOLDERS", "Field", "InputError", "InputsPanel", "format_steps", "parse_steps"]
