"""The "Multi-axis" tab: several axes that must finish together (:mod:`sim.studies.multiaxis`).

The axes are the YAML list the command line's ``multiaxis FILE`` takes (parsed by
:func:`app.io.study_inputs.parse_axes`), edited in a text box, built row by row with "Add axis"
or loaded from a file. On the page an axis names one of the shipped presets (no server paths).
The move is a study: it waits for a server-wide slot and runs at lowered priority
(:mod:`app.ui.studies_queue`); Cancel takes effect between axes.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

import viser

from pmsm_commissioning.app.figures.fdsmc_studies import multiaxis_spec, multiaxis_table_markdown
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.io.preset_modes import list_presets_of
from pmsm_commissioning.app.io.presets import MAX_BYTES, loads_raw
from pmsm_commissioning.app.io.study_inputs import parse_axes
from pmsm_commissioning.app.ui.case import CasePort
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.app.ui.viser_adapter import add_figure, set_figure_json
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.grid import check_budget
from pmsm_commissioning.sim.studies.multiaxis import MultiAxisResult, coordinate

#: Where the axes come from in messages.
ORIGIN = "Multi-axis › axes"
#: Largest requested common T_m [s].
MAX_T_M = 1e4


def default_axes(presets: tuple[str, ...]) -> str:
    """Return a two-axis example of the YAML list (the first two real-motor presets, else the first two)."""
    real = [p for p in presets if p not in ("paper_12kw_pmsm", "example_log_drive")] or list(presets)
    names = (real * 2)[:2]
    return "".join(f"- {{preset: {p}, name: {chr(ord('X') + k)}}}\n" for k, p in enumerate(names))


def axis_line(preset: str, name: str, theta_dem: float | None) -> str:
    """One YAML line of the axes list (θ_dem [rad] as a ``set`` override when given)."""
    sets = f", set: [manoeuvre.theta_dem={theta_dem!r}]" if theta_dem is not None else ""
    return f"- {{preset: {preset}, name: {name!r}{sets}}}\n"


def parse_page_axes(text: str, presets: tuple[str, ...]) -> list[tuple[str, DriveParams]]:
    """Return the axes typed on the page; ParameterError naming the axis and the problem.

    Every ``preset`` must be one of ``presets`` (the page never reads a path on the server).
    """
    if len(text.encode("utf-8")) > MAX_BYTES:
        raise ParameterError(f"{ORIGIN}: the text is too long: allowed ≤ {MAX_BYTES // 1024} KiB")
    raw = loads_raw(text, ORIGIN)
    if isinstance(raw, list):
        for i, item in enumerate(raw):
            name = item.get("preset") if isinstance(item, dict) else None
            if isinstance(name, str) and name not in presets:
                raise ParameterError(f"{ORIGIN}: axis {i + 1}: preset {name!r} is not allowed: one of "
                                     + ", ".join(presets))
    return parse_axes(raw, ORIGIN)


def check_axes(axes: list[tuple[str, DriveParams]], T_m: float) -> float | None:
    """Return the requested common T_m [s] (None: the shortest all can do) once every axis fits the budget."""
    if isinstance(T_m, bool) or not isinstance(T_m, int | float) or not 0.0 <= T_m <= MAX_T_M:
        shown = f"{T_m:g}" if isinstance(T_m, int | float) else repr(T_m)
        raise ParameterError(f"Multi-axis › common T_m = {shown} s is out of range: allowed 0 (the shortest "
                             f"all axes can do) or 0 < T_m ≤ {MAX_T_M:g} s")
    for name, p in axes:
        try:
            check_budget(p, 2)
        except ParameterError as exc:
            raise ParameterError(f"Multi-axis › axis {name!r}: {exc}") from None
    return T_m if T_m > 0.0 else None


class MultiAxisView:
    """Axes editor, Run, per-axis table and the axes' motion figure of one session."""

    #: The study's name in the queue's messages.
    LABEL = "Multi-axis move"

    def __init__(self, port: CasePort, as_study: Callable[[str], AbstractContextManager[Any]]) -> None:
        self._s = port
        self._as_study = as_study
        gui = port.client.gui
        self._presets = tuple(list_presets_of("position"))
        self.axes = gui.add_text("Axes (YAML list)", default_axes(self._presets), multiline=True,
                                 hint="The list `pmsm-commission multiaxis FILE` takes: - {preset: NAME, name: LABEL, "
                                      "set: [manoeuvre.theta_dem=31.4]}")
        with gui.add_folder("Add an axis", expand_by_default=False):
            self.add_preset = gui.add_dropdown("Axis preset", self._presets, initial_value=self._presets[0])
            self.add_name = gui.add_text("Axis name", "Z")
            self.add_theta = gui.add_number("Axis θ_dem [rad] (0 = preset's)", 0.0, step=0.1)
            self.add_button = gui.add_button("Add axis", icon=viser.Icon.PLUS)
        self.upload = gui.add_upload_button("Load axes file (YAML)", icon=viser.Icon.UPLOAD,
                                            mime_type=".yaml,.yml,text/yaml,text/plain")
        self.T_m = gui.add_number("Common T_m [s] (0 = shortest all can do)", 0.0, min=0.0, step=0.01)
        self.run_button = gui.add_button("Run multi-axis move", icon=viser.Icon.PLAYER_PLAY, color="green")
        self.status = gui.add_markdown("Not run yet.")
        self.table = gui.add_markdown("")
        self.figure = add_figure(gui, aspect=0.8)
        self.add_button.on_click(lambda _: self._add_axis())
        self.upload.on_upload(lambda _: self._uploaded())
        self.run_button.on_click(lambda _: self.start())

    def _add_axis(self) -> None:
        theta, preset = self.add_theta.value, self.add_preset.value
        if preset not in self._presets:  # a value the dropdown never offered
            self._s.client.add_notification("Axis not added", f"Axis preset {preset!r} is not allowed: one of "
                                            + ", ".join(self._presets), color="red", auto_close_seconds=12.0)
            return
        line = axis_line(preset, str(self.add_name.value).strip() or "axis",
                         float(theta) if isinstance(theta, int | float) and theta != 0 else None)
        text = str(self.axes.value)
        self.axes.value = text + ("" if not text or text.endswith("\n") else "\n") + line

    def _uploaded(self) -> None:
        f = self.upload.value
        try:
            text = f.content.decode("utf-8")
            parse_page_axes(text, self._presets)
        except (UnicodeDecodeError, ParameterError) as exc:
            msg = f"{f.name} is not UTF-8 text" if isinstance(exc, UnicodeDecodeError) else str(exc)
            self._s.client.add_notification("Axes file rejected — nothing changed", msg, color="red",
                                            auto_close_seconds=12.0)
            return
        self.axes.value = text

    def start(self) -> bool:
        """Parse and check the axes, then coordinate them on the session's worker; False if refused."""
        try:
            axes = parse_page_axes(str(self.axes.value), self._presets)
            T_m = check_axes(axes, self.T_m.value)
        except ParameterError as exc:
            self.status.content = f"**Not started:** {md_text(exc)}"
            self._s.client.add_notification("Multi-axis move not started", str(exc), color="red",
                                            auto_close_seconds=12.0)
            return False
        with self._as_study(self.LABEL):
            return bool(self._s.submit(lambda: self._job(axes, T_m)))

    def _job(self, axes: list[tuple[str, DriveParams]], T_m: float | None) -> None:
        self.status.content = f"Designing and simulating {len(axes)} axes…"
        self.run_button.disabled = True
        try:
            result = coordinate(axes, T_m, self._s.checkpoint)
            self._s.checkpoint()
        except ParameterError as exc:
            self.status.content = f"**Failed:** {md_text(exc)}"
            self._s.client.add_notification("Multi-axis move failed", str(exc), color="red", auto_close_seconds=12.0)
            self._s.say("Ready — the multi-axis move failed (see its tab).")
            return
        finally:
            self.run_button.disabled = False
        self.show(result)
        self._s.say(f"Ready — {len(axes)} axes coordinated at T_m = {result.T_m:.4g} s.")

    def show(self, result: MultiAxisResult) -> None:
        """Draw the per-axis table and the axes' motion."""
        self.table.content = multiaxis_table_markdown(result, md_text)
        set_figure_json(self.figure, figure_json(multiaxis_spec(result)))
        arrived = sum(a.arrived for a in result.axes)
        self.status.content = f"Done: {arrived} of {len(result.axes)} axes arrived at T_m = {result.T_m:.4g} s."


__all__ = ["MultiAxisView", "axis_line", "check_axes", "default_axes", "parse_page_axes"]
