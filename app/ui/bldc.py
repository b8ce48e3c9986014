"""The "BLDC speed SMC" tab: inputs with units, back-EMF upload, comparison run, figures, metrics.

Built by :func:`build_bldc_tab` inside the tab container of one client (``client.gui``). The
simulations run through ``submit`` on that client's worker (one job at a time); every input
error is shown in the tab's status line, never as a traceback.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import plotly.graph_objects as go
import viser

from app.figures.bldc import (
    make_currents_figure,
    make_dqx_figure,
    make_emf_figure,
    make_reachability_figure,
    make_sigma_figure,
    make_speed_figure,
    make_torque_figure,
)
from app.io.bldc_emf import read_measured, with_measured
from app.io.bldc_view import metric_table
from app.io.numbers import NumberFormatError
from app.io.preset_modes import load_mode_preset
from app.io.presets import dumps_preset, loads_preset
from app.io.units import kHz_to_Hz, mH_to_H, rad_s_to_rpm, rpm_to_rad_s
from app.ui.number_fields import NumberInput
from app.ui.text import checked_choice, md_text
from app.ui.worker import Cancelled, Worker
from control.bldc.design import bldc_design
from control.bldc.params import EMF_SHAPES, BldcParams
from control.fdsmc.params import ParameterError
from sim.bldc.emf import machine_table
from sim.bldc.engine import CONTROLLERS, LABELS, BldcComparison, compare_bldc

PRESET = "bldc_smc_paper"
ASPECT = 0.75

#: (label, section, field, to-SI converter, from-SI converter, step) of the number inputs.
FIELDS: tuple[tuple[str, str, str, Callable[[float], float], Callable[[float], float], float], ...] = (
    ("R_s [Ω]", "machine", "R_s", float, float, 0.01),
    ("L_s − M_s [mH]", "machine", "L_s_minus_M_s", mH_to_H, lambda x: x * 1e3, 0.1),
    ("n_pp (pole pairs)", "machine", "n_pp", int, int, 1),
    ("Φ_m [Wb]", "machine", "Phi_m", float, float, 0.001),
    ("J [kg·m²]", "mechanics", "J", float, float, 1e-4),
    ("B [N·m·s/rad]", "mechanics", "B", float, float, 1e-4),
    ("V_dc [V]", "inverter", "V_dc", float, float, 1.0),
    ("f_s [kHz]", "inverter", "f_s", kHz_to_Hz, lambda x: x * 1e-3, 1.0),
    ("k_I [1/A]", "gains", "k_I", float, float, 0.1),
    ("k_ω [s/rad]", "gains", "k_omega", float, float, 0.1),
    ("T_max [N·m]", "gains", "T_max", float, float, 0.1),
    ("λ₀ [1/s]", "gains", "lambda_0", float, float, 1.0),
    ("ε_λ [rpm]", "gains", "eps_lambda", rpm_to_rad_s, rad_s_to_rpm, 0.1),
)


def _placeholder(fid: str, title: str) -> go.Figure:
    fig = go.Figure()
    fig.update_layout(meta={"id": fid}, title={"text": f"{title} — press “Simulate BLDC”", "font": {"size": 13}},
                      height=260, template="plotly_white", margin={"l": 40, "r": 10, "t": 40, "b": 30})
    return fig


def metrics_markdown(comp: BldcComparison) -> str:
    """Return the side-by-side metrics as a Markdown table (shared rows with the CLI)."""
    rows = metric_table(comp)
    head = "| " + " | ".join(rows[0]) + " |"
    lines = [head, "|" + "---|" * len(rows[0])] + ["| " + " | ".join(r) + " |" for r in rows[1:]]
    names = "; ".join(f"**{r.controller}** = {LABELS[r.controller]}" for r in comp.runs)
    return "\n".join(lines) + f"\n\n{names}"


class BldcTab:
    """Widgets and actions of the BLDC tab of one client."""

    def __init__(self, client: viser.ClientHandle, submit: Callable[[Callable[[], None]], Any],
                 figures_container: Any = None, worker: Worker | None = None) -> None:
        self.client, self.gui, self._submit, self._worker = client, client.gui, submit, worker
        self._figures_container = figures_container
        self.params: BldcParams = load_mode_preset(PRESET, mode="bldc")
        self.comparison: BldcComparison | None = None
        self._build()
        self._show_design()

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
        self.cancel_button = gui.add_button("Cancel BLDC run", icon=viser.Icon.PLAYER_STOP, color="red",
                                            visible=False)
        self.cancel_button.on_click(lambda _: self._cancel())
        self.status = gui.add_markdown("Ready — press **Simulate BLDC**; the metrics and figures are in "
                                       "the results panel's **BLDC figures** tab.")
        self.warnings = gui.add_markdown("")
        with gui.add_folder("Scenario", expand_by_default=False):
            self.w_ref = NumberInput(gui, "ω* [rpm]")
            self.w_ref.show(rad_s_to_rpm(p.case.omega_ref), exact=p.case.omega_ref)
            self.t_end = NumberInput(gui, "t_end [s]")
            self.t_end.show(p.case.t_end)
        self.inputs: dict[str, NumberInput] = {}
        with gui.add_folder("Machine, load, inverter, gains", expand_by_default=False):
            for label, sec, name, _, from_si, _step in FIELDS:
                si = getattr(getattr(p, sec), name)
                self.inputs[label] = NumberInput(gui, label)
                self.inputs[label].show(from_si(si), exact=si)
        with self._figures_container or gui.add_folder("Figures", expand_by_default=True):
            with gui.add_folder("Metrics", expand_by_default=True):
                self.metrics = gui.add_markdown("No run yet — press **Simulate BLDC**.")
            self.fig_speed = gui.add_plotly(_placeholder("bldc_speed", "Speed"), aspect=ASPECT)
            self.fig_torque = gui.add_plotly(_placeholder("bldc_torque", "Torque"), aspect=ASPECT)
            self.fig_sigma = gui.add_plotly(_placeholder("bldc_sigma", "σ_ω"), aspect=ASPECT)
            self.fig_currents = gui.add_plotly(_placeholder("bldc_currents", "Phase currents"), aspect=ASPECT)
            self.fig_emf = gui.add_plotly(_placeholder("bldc_emf", "Back-EMF"), aspect=ASPECT)
            self.fig_dqx = gui.add_plotly(_placeholder("bldc_dqx", "a_x, θ_x"), aspect=1.0)
            self.fig_reach = gui.add_plotly(_placeholder("bldc_reach", "Reachability"), aspect=ASPECT)
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
            for label, sec, name, to_si, _from_si, _ in FIELDS:
                # an untouched field keeps its exact SI value (export → import gives back the same inputs)
                sections[sec][name] = self.inputs[label].read(f"{sec}.{name} ({label})", to_si,
                                                              integer=to_si is int)
            omega_ref = self.w_ref.read("scenario ω* [rpm]", rpm_to_rad_s)
            t_end = self.t_end.read("scenario t_end [s]")
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
        p = self.params
        table = machine_table(p.machine)
        self.fig_emf.figure = make_emf_figure(table, p.machine.Phi_m)
        self.fig_dqx.figure = make_dqx_figure(table, p.machine.Phi_m)
        design = bldc_design(p)
        self.fig_reach.figure = make_reachability_figure(design)
        self.warnings.content = "\n".join(f"⚠ {md_text(w)}  " for w in design.warnings)

    # ---- actions ------------------------------------------------------------------------------
    def simulate(self) -> bool:
        """Commit the inputs and run the comparison on the worker; False if rejected or busy."""
        try:
            params = self.collect()
        except (ParameterError, ValueError, TypeError) as exc:
            self.status.content = f"**Rejected — nothing simulated:** {md_text(exc)}"
            return False
        return bool(self._submit(lambda: self._run(params)))

    def _run(self, params: BldcParams) -> None:
        self.status.content = f"Simulating… ({len(CONTROLLERS)} drives)"
        self.run_button.disabled, self.cancel_button.visible = True, self._worker is not None
        try:
            comp = compare_bldc(params)
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
        self.fig_speed.figure = make_speed_figure(comp)
        self.fig_torque.figure = make_torque_figure(comp)
        self.fig_sigma.figure = make_sigma_figure(comp)
        self.fig_currents.figure = make_currents_figure(comp)
        self.metrics.content = metrics_markdown(comp)
        sim_s = params.case.t_end * len(comp.runs)
        self.status.content = (f"Done: scenario **{md_text(params.case.name)}**, back-EMF **{params.machine.emf}**, "
                               f"{sim_s:g} s simulated in {comp.wall_s * 1e3:.0f} ms.")

    def _cancel(self) -> None:
        if self._worker is not None and self._worker.cancel():
            self.status.content = "Cancelling…"

    def _scenario_chosen(self) -> None:
        """Show the chosen scenario's reference speed and duration."""
        case = next((c for c in self.params.scenario.cases if c.name == self.scenario.value), None)
        if case is not None:
            self.w_ref.show(rad_s_to_rpm(case.omega_ref), exact=case.omega_ref)
            self.t_end.show(case.t_end)

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
            text = f.content.decode("utf-8")
            measured = read_measured(text, f.name)
            self.params = with_measured(self.params, measured)
        except UnicodeDecodeError:
            self.status.content = f"**Upload rejected:** {md_text(f.name)} is not UTF-8 text: allowed CSV or YAML"
            return
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
            params = loads_preset(f.content.decode("utf-8"), f.name)
        except UnicodeDecodeError:
            self.status.content = f"**Import rejected — nothing changed:** {md_text(f.name)} is not UTF-8 text"
            return
        except (ParameterError, ValueError) as exc:
            self.status.content = f"**Import rejected — nothing changed:** {md_text(exc)}"
            return
        if not isinstance(params, BldcParams):
            self.status.content = (f"**Import rejected — nothing changed:** {md_text(f.name)} is a position-drive "
                                   "preset: import it in the *Position drive (FDSMC)* tab")
            return
        self.apply(params)
        self.status.content = (f"Imported **{md_text(params.name)}** ({md_text(f.name)}) — press "
                               "**Simulate BLDC**.")

    def apply(self, params: BldcParams) -> None:
        """Show ``params`` in every widget of the tab and make them the tab's parameters."""
        self.params = params
        for label, sec, name, _, from_si, _ in FIELDS:
            si = getattr(getattr(params, sec), name)
            self.inputs[label].show(from_si(si), exact=si)
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
        self.client.send_file_download(f"{params.name}.yaml", dumps_preset(params).encode("utf-8"),
                                       save_immediately=True)


def build_bldc_tab(client: viser.ClientHandle, submit: Callable[[Callable[[], None]], Any],
                   figures_container: Any = None, worker: Worker | None = None) -> BldcTab:
    """Build the BLDC tab in the current GUI container of ``client``; returns its handle object.

    ``figures_container`` (e.g. a tab of the wide results panel) receives the figures; without
    it they go into a folder of the current container.
    """
    return BldcTab(client, submit, figures_container, worker)
