"""Drive-log section of the position-drive tab: upload a log, overlay it, identify, apply.

The log goes through the same import as ``pmsm-commission log`` (:mod:`app.io.drive_log`) and is
compared with the session's current simulation (the FDSMC run, or the conventional one); the
identified values can be written into the inputs, which marks the parameters' ``source``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import viser

from pmsm_commissioning.app.figures.fdsmc_drive_log import make_log_overlay_figure
from pmsm_commissioning.app.io.drive_log import DriveLog, LogError, read_bytes, run_identification
from pmsm_commissioning.app.io.numbers import one_line
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.app.resources import example_log
from pmsm_commissioning.app.ui.case import CasePort
from pmsm_commissioning.app.ui.text import html_text, md_text
from pmsm_commissioning.app.ui.viser_adapter import add_figure, figure_json_of, set_figure_json
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.identification import Identification
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.drivelog.overlay import Overlay, overlay

EXAMPLE_LOG = example_log()
EXAMPLE_PRESET = "example_log_drive"
#: Identified parameter → (section, field) of the inputs; J_total goes to J_L = J_total − J_r.
TARGETS = {"R_s": ("motor", "R_s"), "L_d": ("motor", "L_d"), "L_q": ("motor", "L_q"),
           "psi_pm": ("motor", "psi_pm"), "J_total": ("load", "J_L"), "F_v": ("load", "F_v"),
           "Gamma_Le": ("load", "Gamma_Le")}


def overlay_markdown(log: DriveLog, ov: Overlay) -> str:
    """Summary of the import and the overlay errors (SI units); the file name and notes are user text."""
    lines = [f"**{md_text(log.name)}**: {log.signals['t'].size} samples at {1.0 / log.T_s:.6g} Hz, move start "
             f"t0 = {ov.t0:.4g} s ({'detected' if ov.t0_detected else 'given'}).", "",
             "| signal | RMS error | peak error | unit |", "|---|---|---|---|"]
    lines += [f"| {md_text(e.signal)} | {e.rms_error:.4g} | {e.peak_error:.4g} | {md_text(e.unit)} |"
              for e in ov.errors]
    if ov.energy_measured_J is not None:
        lines += ["", f"Electrical input energy: measured **{ov.energy_measured_J:.4g} J**, simulated "
                      f"**{ov.energy_simulated_J:.4g} J**."]
    lines += [f"\n_{md_text(note)}_" for note in log.notes]
    return "\n".join(lines)


def identified_markdown(r: Identification) -> str:
    """Table of the identified values with standard errors and 95 % intervals, or the refusals."""
    lines = ["| parameter | value | std. error | 95 % interval | unit |", "|---|---|---|---|---|"]
    for e in r.estimates:
        if e.refused is not None:
            lines.append(f"| {md_text(e.name)} | refused | | {md_text(e.refused)} | {md_text(e.unit)} |")
        else:
            lines.append(f"| {md_text(e.name)} | {e.value:.5g} | {e.stderr:.3g} | "
                         f"[{e.ci95[0]:.5g}, {e.ci95[1]:.5g}] | {md_text(e.unit)} |")
    if r.voltage_delay_samples is not None:
        lines.append(f"\nVoltage delay {r.voltage_delay_samples} sample(s); residuals "
                     f"{r.residual_electrical_V or 0:.3g} V, {r.residual_mechanical_Nm or 0:.3g} N·m.")
    return "\n".join(lines)


def apply_identified(params: DriveParams, r: Identification, log_name: str) -> DriveParams:
    """``params`` with every identified value written in, and the log named in ``source``."""
    sections: dict[str, dict[str, float]] = {"motor": {}, "load": {}}
    for e in r.estimates:
        if e.value is not None and e.name in TARGETS:
            section, name = TARGETS[e.name]
            value = e.value - params.motor.J_r if e.name == "J_total" else e.value
            if e.name == "J_total" and value < 0.0:
                raise ParameterError(f"identified J_total = {e.value:.4g} kg·m² is below J_r = "
                                     f"{params.motor.J_r:.4g} kg·m²: lower J_r first")
            sections[section][name] = value
    names = [e.name for e in r.estimates if e.value is not None]
    if not names:
        raise ParameterError(f"{log_name}: no parameter was identified, nothing to apply")
    return dataclasses.replace(
        params, motor=dataclasses.replace(params.motor, **sections["motor"]),
        load=dataclasses.replace(params.load, **sections["load"]),
        source=f"{params.source}; {', '.join(names)} identified from drive log {log_name}")


class LogPanel:
    """Folder "Drive log (measured)" of one session: upload, example, overlay, identify, apply.

    Parameters
    ----------
    port : app.ui.case.CasePort
        The position tab: the case read (its comparison, parameters, origin), its worker
        (``submit``), its inputs (``collect_inputs``, ``open_case``), a results tab, ``run`` and
        ``simulate``.
    """

    def __init__(self, port: CasePort) -> None:
        self._port, gui = port, port.client.gui
        self.identified: Identification | None = None
        self.log_name = ""
        self._figure: Any = None
        with gui.add_folder("Drive log (measured)", expand_by_default=False):
            self.upload = gui.add_upload_button("Import drive log (CSV)", icon=viser.Icon.UPLOAD,
                                                mime_type=".csv,text/csv,text/plain")
            self.upload.on_upload(lambda _: self._uploaded())
            self.example = gui.add_button("Load example log", icon=viser.Icon.FILE)
            self.example.on_click(lambda _: self._example())
            self.compare_with = gui.add_dropdown("Compare with", ("fdsmc", "conventional"))
            self.summary = gui.add_markdown("No log loaded.")
            self.table = gui.add_markdown("")
            self.apply = gui.add_button("Apply identified values", visible=False, color="orange")
            self.apply.on_click(lambda _: self._apply())

    def _uploaded(self) -> None:
        f = self.upload.value
        self._port.submit(lambda: self._process(f.name, f.content))

    def _example(self) -> None:
        params = load(EXAMPLE_PRESET)
        self._port.open_case(params, EXAMPLE_PRESET)

        def job() -> None:
            self._port.run(params)
            self._process(EXAMPLE_LOG.name, EXAMPLE_LOG.read_bytes())

        self._port.submit(job)

    def _process(self, name: str, content: bytes) -> None:
        """On the worker: import, overlay on the current run, identify, show."""
        case = self._port.case
        cmp = case.comparison
        run = cmp.fdsmc if self.compare_with.value == "fdsmc" else cmp.conventional
        try:
            if run is None:
                raise ParameterError("there is no simulated run to compare with: simulate a feasible case first")
            log = read_bytes(content, name, run=self.compare_with.value, p=case.params.motor.p)
            ov = overlay(log.signals, run.trace)
        except (LogError, ParameterError) as exc:
            self._port.client.add_notification("Log rejected", one_line(exc), color="red", auto_close_seconds=15.0)
            return
        self.identified, self.log_name = run_identification(log, case.params), name
        self._show(make_log_overlay_figure(ov, html_text(name)))
        self.table.content = identified_markdown(self.identified)
        self.apply.visible = any(e.value is not None for e in self.identified.estimates)
        self.summary.content = overlay_markdown(log, ov)

    def _show(self, fig: Any) -> None:
        if self._figure is None:
            with self._port.results_tab("Drive log", viser.Icon.CHART_LINE):
                self._figure = add_figure(self._port.client.gui, figure_json_of(fig), aspect=1.0)
        else:
            set_figure_json(self._figure, figure_json_of(fig))

    def _apply(self) -> None:
        if self.identified is None:
            return
        try:
            params = apply_identified(self._port.collect_inputs(), self.identified, self.log_name)
        except ValueError as exc:
            self._port.client.add_notification("Not applied", one_line(exc), color="red", auto_close_seconds=12.0)
            return
        self._port.open_case(params, f"{self._port.case.origin} + identified from {self.log_name}")
        self._port.simulate()
