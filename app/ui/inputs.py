"""Input folders of the position-drive tab: nameplate, load, inverter/controller, manoeuvre.

Values are shown in nameplate units with the unit in every label and converted to SI here, at the
edge. Every number is a text field parsed on the server (:mod:`app.ui.number_fields`): what reaches the
physics is exactly what was typed, or nothing runs and the message names the field, the value and
the allowed range. Unit selectors (inertia in kg·m² or kg·cm², move in rad/deg/rev, R_s and L per
phase or line-to-line, Ψ_PM or Ke or Kt) convert the shown values; nothing is committed while
typing: :meth:`InputsPanel.collect` reads the fields on Simulate (or Enter) and validates them with
the same dataclasses (and so the same messages) as the CLI and YAML files, with no preset-file
round trip (:func:`built`).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import viser

from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.io.display_units import UNIT_GROUPS, Field, Unit
from pmsm_commissioning.app.io.numbers import NumberFormatError
from pmsm_commissioning.app.io.presets import to_raw
from pmsm_commissioning.app.ui.axis_inputs import InputError, OutputSideInputs, rated_left_out, with_rated_derived
from pmsm_commissioning.app.ui.choices import checked_choice
from pmsm_commissioning.app.ui.number_fields import NumberInput
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.common.dc_link import DC_LINK_MEANING, DC_LINKS
from pmsm_commissioning.control.fdsmc.nameplate import nameplate_consistency
from pmsm_commissioning.control.fdsmc.params import ALPHA_MAX_RULES, DriveParams, LoadStep, Motor
from pmsm_commissioning.control.fdsmc.transmission import Transmission

SELECTORS = (("flux", "Flux given as"), ("resistance", "R_s, L_d, L_q given"), ("inertia", "Inertia unit"),
             ("angle", "Move unit"), ("current", "i_max given as"), ("settling", "T_si given as"))


FIELDS: tuple[Field, ...] = (
    Field("motor", "V_0"), Field("motor", "P_r"), Field("motor", "omega_b"), Field("motor", "Gamma_max"),
    Field("motor", "psi_pm", "flux"), Field("motor", "p"), Field("motor", "R_s", "resistance"),
    Field("motor", "L_d", "inductance"), Field("motor", "L_q", "inductance"), Field("motor", "J_r", "inertia"),
    Field("load", "J_L", "inertia"), Field("load", "F_v"), Field("load", "Gamma_Le"), Field("load", "Gamma_Le_ramp"),
    Field("transmission", "ratio"), Field("transmission", "efficiency"), Field("transmission", "lead"),
    Field("transmission", "pulley_radius"),
    Field("controller", "V_dc"), Field("controller", "i_max", "current"), Field("controller", "T_si", "settling"),
    Field("controller", "T_salpha"), Field("controller", "T_so"), Field("controller", "T_dv"), Field("controller", "K"),
    Field("controller", "charge_efficiency"),
    Field("sensors", "encoder_cpr"), Field("sensors", "i_noise"), Field("sensors", "i_adc_bits"),
    Field("sensors", "i_adc_range"), Field("sensors", "seed"),
    Field("limits", "omega_max"), Field("limits", "in_position"), Field("limits", "overshoot"),
    Field("limits", "hold_i_rms"),
    Field("manoeuvre", "theta_dem", "angle"), Field("manoeuvre", "T_m"),
)
#: Inputs with a keyword alternative (a dropdown beside them): T_c ('T_a' rule) and f_s ('continuous').
T_C, F_S = Field("controller", "T_c"), Field("controller", "f_s")
FOLDERS = (("motor", "Motor nameplate"), ("load", "Load"), ("transmission", "Transmission"),
           ("controller", "Inverter and controller"),
           ("sensors", "Sensors"), ("limits", "Pass criteria"), ("manoeuvre", "Manoeuvre"))
TC_RULES = ("T_c = T_a, eq. (59)", "T_c given below")
FS_MODES = ("digital, sampled at f_s", "continuous")
ALPHA_RULES = ALPHA_MAX_RULES  # the parameter model's own list: every rule a preset may hold
DELAYS = ("0", "1")
#: Optional datasheet values used only to cross-check the nameplate (label → key).
CHECKS = (("Kt datasheet [N·m/A_rms] (optional check)", "Kt"), ("T_N rated torque [N·m] (optional check)", "T_N"))


def format_steps(steps: tuple[Any, ...]) -> str:
    """Load-torque steps → ``"t:Γ, t:Γ"`` text [s, N·m]."""
    return ", ".join(f"{s.t:g}:{s.Gamma_Le:g}" for s in steps)


def parse_steps(text: str) -> list[dict[str, float]]:
    """``"t:Γ, t:Γ"`` [s, N·m] → list of step mappings; InputError on malformed text."""
    from pmsm_commissioning.app.io.numbers import parse_number

    out: list[dict[str, float]] = []
    for item in filter(None, (s.strip() for s in text.replace(";", ",").split(","))):
        t_txt, sep, g_txt = item.partition(":")
        try:
            if not sep:
                raise NumberFormatError(item)
            out.append({"t": parse_number(t_txt, "t"), "Gamma_Le": parse_number(g_txt, "Γ_Le")})
        except NumberFormatError:
            raise InputError(
                f"Load › torque steps: {item!r} is malformed: allowed 't:Γ_Le' pairs in s and N·m, "
                "separated by commas, e.g. '0.5:10, 1.2:0'") from None
    return out


class InputsPanel:
    """The input folders on one client's GUI; build inside the current container context."""

    def __init__(self, gui: viser.GuiApi, params: DriveParams) -> None:
        self._gui = gui
        self._params = params
        self.numbers: dict[str, NumberInput] = {}
        self.selectors: dict[str, viser.GuiDropdownHandle] = {}
        self._choice = {g: units_[0] for g, units_ in UNIT_GROUPS.items()}
        for section, title in FOLDERS:
            with gui.add_folder(title):
                self._selectors(section)
                for f in (f for f in FIELDS if f.section == section):
                    self.numbers[f.key] = NumberInput(gui, f.text(self._unit(f)),
                                                      hint=f.hint(self._unit(f), self._params.motor.p))
                self._extra(section)
        self.populate(params)

    def _selectors(self, section: str) -> None:
        wanted = {"motor": ("flux", "resistance", "inertia"), "controller": ("current", "settling"),
                  "manoeuvre": ("angle",)}.get(section, ())
        for group, title in SELECTORS:
            if group in wanted:
                handle = self._gui.add_dropdown(title, tuple(u.label for u in UNIT_GROUPS[group]))
                handle.on_update(lambda _e, g=group: self._unit_changed(g))
                self.selectors[group] = handle

    def _extra(self, section: str) -> None:
        gui = self._gui
        if section == "motor":
            self.checks = {key: NumberInput(gui, label, hint="Leave empty to skip this cross-check")
                           for label, key in CHECKS}
        elif section == "load":
            self.steps = gui.add_text("Γ_Le steps [t s : N·m, …]", "",
                                      hint="Later steps of the external load torque, e.g. 0.5:10, 1.2:0")
        elif section == "transmission":
            self.output_side = OutputSideInputs(gui)
        elif section == "controller":
            self.dc_link = gui.add_dropdown("DC link", DC_LINKS, hint="; ".join(
                f"{k}: {v}" for k, v in DC_LINK_MEANING.items()) + " (η_ch: the charge efficiency below)")
            self.tc_rule = gui.add_dropdown("T_c rule", TC_RULES)
            self.tc_ms = NumberInput(gui, T_C.text(), hint=T_C.hint(None, 0))
            self.alpha_rule = gui.add_dropdown("α_max rule", ALPHA_RULES,
                                               hint="torque_limit: largest α within Γ_max/i_max incl. friction, "
                                                    "load and inner-loop overshoot; min_energy: the α below it that "
                                                    "draws least copper + friction; paper: α_max = H·P_r/V_0")
            self.fs_mode = gui.add_dropdown("Controller", FS_MODES)
            self.fs_khz = NumberInput(gui, F_S.text(), hint=F_S.hint(None, 0))
            self.delay = gui.add_dropdown("Computation delay [samples]", DELAYS)

    # ---- units --------------------------------------------------------------------------------
    def _unit(self, f: Field) -> Unit | None:
        return self._choice[f.group] if f.group else None

    def _p(self) -> int:
        try:
            return int(self.numbers["motor.p"].read("motor.p", integer=True))
        except NumberFormatError:
            return self._params.motor.p

    def _show(self, f: Field, si: float) -> None:
        u = self._unit(f)
        shown = u.from_si(si, self._p()) if u is not None else (si if f.integer else units.from_si(si, f.unit))
        self.numbers[f.key].show(int(shown) if f.integer else float(shown), exact=si)

    def _unit_changed(self, group: str) -> None:
        groups = ("resistance", "inductance") if group == "resistance" else (group,)
        fields = [f for f in FIELDS if f.group in groups]
        try:
            values = {f.key: self._read(f) for f in fields}
        except InputError:
            values = {}  # unparsable text stays as typed; it is reported on Simulate
        label, offered = self.selectors[group].value, [u.label for u in UNIT_GROUPS[group]]
        if label not in offered:  # never offered: refused on Simulate by collect()
            return
        for g in groups:
            idx = offered.index(label)
            self._choice[g] = UNIT_GROUPS[g][idx]
        for f in fields:
            self.numbers[f.key].label = f.text(self._unit(f))
            self.numbers[f.key].hint = f.hint(self._unit(f), self._p())
            if f.key in values:
                self._show(f, values[f.key])

    # ---- values -------------------------------------------------------------------------------
    def populate(self, params: DriveParams) -> None:
        """Show ``params`` in the fields; remembers them as the unchanged reference."""
        self._params = params
        raw = to_raw(params)
        self.numbers["motor.p"].show(params.motor.p)
        for f in FIELDS:
            self._show(f, raw[f.section][f.name])
        c = params.controller
        self.steps.value = format_steps(params.load.steps)
        self.tc_rule.value = TC_RULES[0] if c.T_c == "T_a" else TC_RULES[1]
        if c.T_c != "T_a":
            self.tc_ms.show(units.from_si(float(c.T_c), T_C.unit), exact=float(c.T_c))
        self.alpha_rule.value = c.alpha_max_rule
        self.dc_link.value = c.dc_link
        self.output_side.clear()
        self.rated_derived: tuple[str, ...] = ()
        self.fs_mode.value = FS_MODES[1] if c.is_continuous else FS_MODES[0]
        if not c.is_continuous:
            self.fs_khz.show(units.from_si(float(c.f_s), F_S.unit), exact=float(c.f_s))
        self.delay.value = str(c.delay_samples)

    def show_T_c_in_force(self, T_c: float) -> None:
        """With the rule T_c = T_a, show the T_a in force [s] in the T_c field (read-only meaning)."""
        if self.tc_rule.value == TC_RULES[0]:
            self.tc_ms.show(units.from_si(T_c, T_C.unit), exact=T_c)

    def set_T_c(self, T_c: float) -> None:
        """Select "T_c given below" and show ``T_c`` [s] (e.g. "use T_c,min")."""
        self.tc_rule.value = TC_RULES[1]
        self.tc_ms.show(units.from_si(T_c, T_C.unit), exact=T_c)

    def set_value(self, key: str, value_si: float) -> None:
        """Set one numeric field from an SI value (e.g. "use recommended K")."""
        self._show(next(f for f in FIELDS if f.key == key), value_si)

    def _read(self, f: Field) -> float:
        u, page = self._unit(f), f"{dict(FOLDERS)[f.section]} › {f.text(self._unit(f))}"
        try:
            if f.integer:
                return self.numbers[f.key].read(page, integer=True)
            conv = (lambda x: u.to_si(x, self._p())) if u is not None else (lambda x: units.to_si(x, f.unit))
            return self.numbers[f.key].read(page, conv)
        except NumberFormatError as exc:
            raise InputError(str(exc)) from None

    def nameplate_warnings(self, motor: Motor) -> list[str]:
        """Disagreements of ``motor`` with the optional datasheet Kt / rated torque typed on the page.

        Only those that :func:`derive` does not already report from the nameplate itself.
        """
        try:
            extra = self.nameplate_checks()
        except InputError as exc:
            return [str(exc)]
        if not extra:
            return []
        general = {x.text for x in nameplate_consistency(motor)}
        return [f"Nameplate: {x.text}" for x in nameplate_consistency(motor, **extra) if x.text not in general]

    def nameplate_checks(self) -> dict[str, float]:
        """Return the optional datasheet values typed for the cross-check (empty fields left out)."""
        out: dict[str, float] = {}
        for label, key in CHECKS:
            field = self.checks[key]
            if field.handle.value.strip():
                try:
                    out[key] = float(field.read(label))
                except NumberFormatError as exc:
                    raise InputError(str(exc)) from None
        return out

    def collect(self) -> DriveParams:
        """Validate the fields and return the new parameters, built directly as dataclasses.

        The sections are made in the loader's order (motor, load with its steps, controller,
        manoeuvre, sensors, limits, then the whole), so the first error is the one a preset file
        with these values would report, with the same message.

        Raises
        ------
        InputError
            Naming the page label, the SI field, the value and the allowed range.
        """
        values: dict[str, dict[str, Any]] = {}
        left_out = rated_left_out(self.numbers)  # derived from the inverter below
        for f in FIELDS:
            derived = f.section == "motor" and f.name in left_out
            values.setdefault(f.section, {})[f.name] = 1.0 if derived else self._read(f)
        steps = parse_steps(self.steps.value)
        c = values["controller"]
        try:  # dropdown values are checked against the options offered (a client may send anything)
            c["dc_link"] = checked_choice(self.dc_link.value, DC_LINKS, "DC link")
            reflected = self.output_side.reflected(Transmission(**values["transmission"]))
            tc_rule = checked_choice(self.tc_rule.value, TC_RULES, "T_c rule")
            fs_mode = checked_choice(self.fs_mode.value, FS_MODES, "Controller")
            c["alpha_max_rule"] = checked_choice(self.alpha_rule.value, ALPHA_RULES, "α_max rule")
            c["delay_samples"] = int(checked_choice(self.delay.value, DELAYS, "Computation delay"))
            for group, _title in SELECTORS:
                checked_choice(self.selectors[group].value, [u.label for u in UNIT_GROUPS[group]], _title)
            c["T_c"] = "T_a" if tc_rule == TC_RULES[0] else self.tc_ms.read(
                f"Controller › {T_C.text()}", lambda x: units.to_si(x, T_C.unit))
            c["f_s"] = "continuous" if fs_mode == FS_MODES[1] else self.fs_khz.read(
                f"Controller › {F_S.text()}", lambda x: units.to_si(x, F_S.unit))
        except (NumberFormatError, ParameterError) as exc:
            raise InputError(_with_label(str(exc))) from None
        self.nameplate_checks()
        for section, given in reflected.items():
            values[section].update(given)
        try:
            params = with_rated_derived(built(self._params, values, steps), left_out)
        except InputError:
            raise
        except ValueError as exc:
            raise InputError(_with_label(str(exc))) from None
        for section, given in reflected.items():  # the rotor-side fields show what the output's values give
            for name, si in given.items():
                self.set_value(f"{section}.{name}", si)
        self.rated_derived = left_out
        return params


def built(base: DriveParams, values: dict[str, dict[str, Any]], steps: list[dict[str, float]]) -> DriveParams:
    """Return ``base`` with the sections' ``values`` [SI] and the load ``steps``, validated by the dataclasses.

    Sections are replaced in :class:`DriveParams`' field order (the loader's), the load steps
    before the load; a ParameterError names the field, the value and the allowed range.
    """
    sections: dict[str, Any] = {}
    for f in dataclasses.fields(DriveParams):
        if f.name in ("name", "source"):
            continue
        given = dict(values.get(f.name, {}))
        if f.name == "load":
            given["steps"] = tuple(LoadStep(**s) for s in steps)
        sections[f.name] = dataclasses.replace(getattr(base, f.name), **given)
    return dataclasses.replace(base, **sections)


def _with_label(message: str) -> str:
    """Prefix a loader message with the page label of the field it names (SI values stay in it)."""
    for f in FIELDS:
        if message.startswith(f"{f.key} "):
            return f"{dict(FOLDERS)[f.section]} › {f.label}: {message}"
    return message


__all__ = ["FIELDS", "FOLDERS", "Field", "InputError", "InputsPanel", "format_steps", "parse_steps"]
