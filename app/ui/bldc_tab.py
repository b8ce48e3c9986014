"""The "BLDC speed SMC" tab: inputs with units, back-EMF upload, comparison run, figures, metrics.

Built by :func:`build_bldc_tab` inside the tab container of one client (``client.gui``). The
simulations run through ``submit`` on that client's worker (one job at a time); every input
error is shown in the tab's status line, never as a traceback.
"""

from __future__ import annotations

import dataclasses
import functools
import threading
from collections.abc import Callable
from typing import Any

import viser

from pmsm_commissioning.app.figures.bldc_speed_smc import make_dqx_figure, make_emf_figure, make_reachability_figure
from pmsm_commissioning.app.io.bldc_emf import read_measured, with_measured
from pmsm_commissioning.app.io.bldc_view import anti_windup_text
from pmsm_commissioning.app.io.display_units import field_hint, field_label, shown_value, si_value
from pmsm_commissioning.app.io.numbers import NumberFormatError
from pmsm_commissioning.app.io.presets import annotate_units, dumps_preset, load
from pmsm_commissioning.app.io.units import s_to_ms, spec_of
from pmsm_commissioning.app.ui.bldc_results import BldcResults
from pmsm_commissioning.app.ui.choices import checked_choice
from pmsm_commissioning.app.ui.files import parse_upload, upload_text
from pmsm_commissioning.app.ui.number_fields import NumberInput
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.app.ui.viser_adapter import figure_json_of
from pmsm_commissioning.app.ui.worker import Cancelled, Worker
from pmsm_commissioning.control.bldc.design import bldc_design
from pmsm_commissioning.control.bldc.params import EMF_SHAPES, BldcParams
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.bldc.emf import machine_table
from pmsm_commissioning.sim.bldc.engine import CONTROLLERS, BldcComparison, anti_windup_pair, compare_bldc

PRESET = "bldc_smc_paper"

#: The machine, load, inverter and gain inputs (``section.field``); label, display unit and allowed
#: range come from each field's spec (:func:`app.io.units.spec_of`).
FIELDS: tuple[str, ...] = (
    "machine.R_s", "machine.L_s_minus_M_s", "machine.n_pp", "machine.Phi_m", "mechanics.J", "mechanics.B",
    "inverter.V_dc", "inverter.f_s", "gains.k_I", "gains.k_omega", "gains.T_max", "gains.lambda_0",
    "gains.eps_lambda",
)
#: The scenario inputs shown beside the scenario dropdown.
SCENARIO_FIELDS: tuple[str, ...] = ("scenario.cases.omega_ref", "scenario.cases.t_end")


def number_input(gui: viser.GuiApi, key: str) -> NumberInput:
    """Add a number field for ``key`` with its label and its allowed range (display unit) as hint."""
    return NumberInput(gui, field_label(key), hint=field_hint(key))


def show_si(field: NumberInput, key: str, si: float) -> None:
    """Show an SI value in the field's display unit; an untouched field reads back ``si`` exactly."""
    field.show(shown_value(key, si), exact=si)


def read_si(field: NumberInput, key: str) -> float | int:
    """Read the field's value in SI units; NumberFormatError naming the field and its label."""
    return field.read(f"{key} ({field_label(key)})", lambda x: si_value(key, x), integer=spec_of(key).integer)


def _warnings_markdown(warnings: tuple[str, ...]) -> str:
    return "\n".join(f"⚠ {md_text(w)}  " for w in warnings)


@functools.lru_cache(maxsize=16)
def design_view(p: BldcParams) -> tuple[str, str, str, tuple[str, ...]]:
    """Return the JSON of the back-EMF, a_x/θ_x and reachability figures of ``p`` and its design warnings.

    Pure and kept per parameter set: every page opens on the same preset.
    """
    table = machine_table(p.machine)
    design = bldc_design(p)
    figures = (make_emf_figure(table, p.machine.Phi_m), make_dqx_figure(table, p.machine.Phi_m),
               make_reachability_figure(design))
    emf, dqx, reach = (figure_json_of(f) for f in figures)
    return emf, dqx, reach, tuple(design.warnings)


class BldcTab:
    """Widgets and actions of the BLDC tab of one client."""

    def __init__(self, client: viser.ClientHandle, submit: Callable[[Callable[[], None]], Any],
                 figures_container: Any = None, worker: Worker | None = None) -> None:
        self.client, self.gui, self._submit, self._worker = client, client.gui, submit, worker
        self._figures_container = figures_container
        self.params: BldcParams = load(PRESET, mode="bldc")
        self.comparison: BldcComparison | None = None
        self._build()

    # ---- layout -------------------------------------------------------------------------------
    def _build(self) -> None:
        gui, p = self.gui, self.params
        gui.add_markdown("Sliding-mode vector speed control of a trapezoidal-EMF PMSM (Monteiro et al.): "
                         "paper drive vs plain tanh SMC vs sinusoidal dq PI vs six-step (120° currents).")
        names = [c.name for c in p.scenario.cases]
        self.scenario = gui.add_dropdown("Scenario", names, initial_value=p.scenario.active)
        self.scenario.on_update(lambda _: self._scenario_chosen())
        self.emf = gui.add_dropdown("Machine back-EMF", ("ideal", "distorted", "measured"),
                                    initial_value=p.machine.emf)
        self.emf.on_update(self._emf_chosen)
        self.upload = gui.add_upload_button("Upload measured back-EMF (CSV/YAML)", icon=viser.Icon.UPLOAD,
                                            mime_type=".csv,.txt,.yaml,.yml,text/csv,text/plain")
        self.upload.on_upload(self._uploaded)
        self.run_button = gui.add_button("Simulate BLDC", icon=viser.Icon.PLAYER_PLAY, color="green")
        self.run_button.on_click(lambda _: self.simulate())
        self.anti_windup = gui.add_checkbox(
            "Anti-windup on λ(ε)", True, hint="λ(ε) = λ_0/(1 + (ε/ε_λ)²) of eq. (16); off: λ = λ_0 (ε_λ → ∞)")
        self.side_by_side = gui.add_checkbox(
            "Paper drive with / without anti-windup, side by side", False,
            hint="Also runs the paper's drive with the other anti-windup setting; figure beside the others")
        self.cancel_button = gui.add_button("Cancel BLDC run", icon=viser.Icon.PLAYER_STOP, color="red",
                                            visible=False)
        self.cancel_button.on_click(lambda _: self._cancel())
        self.status = gui.add_markdown("Ready — press **Simulate BLDC**; the metrics and figures are in "
                                       "the results panel's **BLDC figures** tab.")
        emf, dqx, reach, warnings = design_view(p)  # the preset's design, in the widgets' first messages
        self.warnings = gui.add_markdown(_warnings_markdown(warnings))
        with gui.add_folder("Scenario", expand_by_default=False):
            self.w_ref, self.t_end = (number_input(gui, key) for key in SCENARIO_FIELDS)
            self._scenario_chosen()
        self.inputs: dict[str, NumberInput] = {}
        with gui.add_folder("Machine, load, inverter, gains", expand_by_default=False):
            for key in FIELDS:
                self.inputs[key] = number_input(gui, key)
            self._show_inputs(p)
        self.results = BldcResults(gui, self._figures_container or gui.add_folder("Figures"), (emf, dqx, reach))
        self.download = gui.add_button("Download BLDC preset (YAML)", icon=viser.Icon.DOWNLOAD)
        self.download.on_click(lambda _: self._download())
        self.import_preset = gui.add_upload_button("Import BLDC preset (YAML)", icon=viser.Icon.UPLOAD,
                                                   mime_type=".yaml,.yml,text/yaml,text/plain")
        self.import_preset.on_upload(lambda _: self._imported())

    # ---- inputs -------------------------------------------------------------------------------
    def collect(self) -> BldcParams:
        """Parameters from the widgets; ParameterError naming field, value and range if bad."""
        p = self.params
        sections: dict[str, dict[str, Any]] = {"machine": {}, "mechanics": {}, "inverter": {}, "gains": {}}
        try:
            for key in FIELDS:
                # an untouched field keeps its exact SI value (export → import gives back the same inputs)
                sec, name = key.split(".")
                sections[sec][name] = read_si(self.inputs[key], key)
            omega_ref, t_end = (read_si(f, key) for f, key in zip((self.w_ref, self.t_end), SCENARIO_FIELDS,
                                                                     strict=True))
        except NumberFormatError as exc:
            raise ParameterError(str(exc)) from None
        sections["machine"]["emf"] = checked_choice(self.emf.value, EMF_SHAPES, "Machine back-EMF")
        new = {sec: dataclasses.replace(getattr(p, sec), **vals) for sec, vals in sections.items()}
        names = tuple(c.name for c in p.scenario.cases)
        case = p.scenario.cases[names.index(checked_choice(self.scenario.value, names, "Scenario"))]
        case = dataclasses.replace(case, omega_ref=omega_ref, t_end=t_end)
        cases = tuple(case if c.name == case.name else c for c in p.scenario.cases)
        scen = dataclasses.replace(p.scenario, active=case.name, cases=cases)
        return dataclasses.replace(p, scenario=scen, **new)

    def _show_design(self) -> None:
        emf, dqx, reach, warnings = design_view(self.params)
        self.results.show_design((emf, dqx, reach))
        self.warnings.content = _warnings_markdown(warnings)

    # ---- actions ------------------------------------------------------------------------------
    def simulate(self) -> bool:
        """Commit the inputs and run the comparison on the worker; False if rejected or busy."""
        try:
            params = self.collect()
        except (ParameterError, ValueError, TypeError) as exc:
            self.status.content = f"**Rejected — nothing simulated:** {md_text(exc)}"
            return False
        anti_windup, pair = bool(self.anti_windup.value), bool(self.side_by_side.value)
        return bool(self._submit(lambda: self._run(params, anti_windup, pair)))

    def _run(self, params: BldcParams, anti_windup: bool = True, pair: bool = False) -> None:
        self.status.content = f"Simulating… ({len(CONTROLLERS)} drives)"
        self.run_button.disabled, self.cancel_button.visible = True, self._worker is not None
        try:
            comp = compare_bldc(params, anti_windup=anti_windup)
            runs = anti_windup_pair(comp) if pair else None
            if self._worker is not None:
                self._worker.checkpoint()
        except (ParameterError, ValueError) as exc:
            self.status.content = f"**Rejected:** {md_text(exc)}"
            return
        except Cancelled:
            self.status.content = "Cancelled — the previous results are kept."
            return
        finally:
            self.run_button.disabled, self.cancel_button.visible = False, False
        self.params, self.comparison = params, comp
        self._show_design()
        self.results.show(comp, runs)
        sim_s = params.case.t_end * len(comp.runs)
        aw = "" if comp.anti_windup else f", {anti_windup_text(comp)}"
        self.status.content = (f"Done: scenario **{md_text(params.case.name)}**, back-EMF **{params.machine.emf}**"
                               f"{aw}, {sim_s:g} s simulated in {s_to_ms(comp.wall_s):.0f} ms.")

    def _cancel(self) -> None:
        if self._worker is not None and self._worker.cancel():
            self.status.content = "Cancelling…"

    def _scenario_chosen(self) -> None:
        """Show the chosen scenario's reference speed and duration."""
        case = next((c for c in self.params.scenario.cases if c.name == self.scenario.value), None)
        if case is not None:
            show_si(self.w_ref, SCENARIO_FIELDS[0], case.omega_ref)
            show_si(self.t_end, SCENARIO_FIELDS[1], case.t_end)

    def _show_inputs(self, params: BldcParams) -> None:
        for key in FIELDS:
            sec, name = key.split(".")
            show_si(self.inputs[key], key, getattr(getattr(params, sec), name))

    def _emf_chosen(self, event: viser.GuiEvent) -> None:
        if event.client is None:
            return
        if self.emf.value not in EMF_SHAPES:  # never offered: a hostile or stale client
            self.status.content = (f"**Rejected:** Machine back-EMF = {md_text(repr(self.emf.value))} is not one "
                                   f"of the offered options: allowed {', '.join(EMF_SHAPES)}")
            self.emf.value = self.params.machine.emf
            return
        if self.emf.value == "measured" and not self.params.machine.emf_samples:
            self.status.content = ("**Rejected:** machine back-EMF = 'measured' needs a waveform: "
                                   "upload a CSV/YAML file first")
            self.emf.value = self.params.machine.emf
            return
        try:
            self.params = dataclasses.replace(
                self.params, machine=dataclasses.replace(self.params.machine, emf=self.emf.value))
        except ParameterError as exc:
            self.status.content = f"**Rejected:** {md_text(exc)}"
            return
        self._show_design()

    def _uploaded(self, _: viser.GuiEvent) -> None:
        f = self.upload.value
        try:
            measured = read_measured(upload_text(f.name, f.content, "CSV or YAML"), f.name)
            self.params = with_measured(self.params, measured)
        except (ParameterError, ValueError) as exc:
            self.status.content = f"**Upload rejected — nothing changed:** {md_text(exc)}"
            return
        self.emf.value = "measured"
        shifts = ", ".join(f"{s:.1f}°" for s in measured.shifts_deg) or "one phase given"
        note = (f"Loaded **{md_text(f.name)}**: phase shifts {shifts}; fundamental offset vs the ideal trapezoid "
                f"{measured.offset_deg:+.1f}° (the controller assumes 0°).")
        self.status.content = note
        self._show_design()

    def _imported(self) -> None:
        f = self.import_preset.value
        try:
            params = parse_upload(f.name, f.content, BldcParams)
        except (ParameterError, ValueError) as exc:
            self.status.content = f"**Import rejected — nothing changed:** {md_text(exc)}"
            return
        self.apply(params)
        self.status.content = (f"Imported **{md_text(params.name)}** ({md_text(f.name)}) — press "
                               "**Simulate BLDC**.")

    def apply(self, params: BldcParams) -> None:
        """Show ``params`` in every widget of the tab and make them the tab's parameters."""
        self.params = params
        self._show_inputs(params)
        self.scenario.options = [c.name for c in params.scenario.cases]
        self.scenario.value = params.scenario.active
        self._scenario_chosen()
        self.emf.value = params.machine.emf
        self._show_design()

    def _download(self) -> None:
        try:
            params = self.collect()
        except (ParameterError, ValueError, TypeError) as exc:
            self.status.content = f"**Rejected:** {md_text(exc)}"
            return
        self.client.send_file_download(f"{params.name}.yaml", annotate_units(dumps_preset(params)).encode("utf-8"),
                                       save_immediately=True)


def warm_bldc() -> None:
    """Prepare the BLDC tab before the first page: the preset's design figures now, its kernels in the background.

    The design figures are in every page's first messages; the kernels' first load (≈ 1–5 s of
    numba cache reading) would otherwise fall on the first "Simulate BLDC".
    """
    params = load(PRESET, mode="bldc")
    design_view(params)
    threading.Thread(target=lambda: compare_bldc(params), name="bldc-warm-up", daemon=True).start()


def add_bldc_tab(client: viser.ClientHandle, tabs: viser.GuiTabGroupHandle,
                 submit: Callable[[Callable[[], None]], Any], results: Any, worker: Worker) -> BldcTab:
    """Add the second mode: a "BLDC speed SMC" tab of ``tabs`` (inputs) and a "BLDC figures" tab of ``results``."""
    figures_tab = results.add_tab("BLDC figures", viser.Icon.ENGINE)
    with tabs.add_tab("BLDC speed SMC", viser.Icon.ENGINE):
        return build_bldc_tab(client, submit, figures_tab, worker)


def build_bldc_tab(client: viser.ClientHandle, submit: Callable[[Callable[[], None]], Any],
                   figures_container: Any = None, worker: Worker | None = None) -> BldcTab:
    """Build the BLDC tab in the current GUI container of ``client``; returns its handle object.

    ``figures_container`` (e.g. a tab of the wide results panel) receives the figures; without
    it they go into a folder of the current container.
    """
    return BldcTab(client, submit, figures_container, worker)
