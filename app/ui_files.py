"""Export buttons and preset upload of the position-drive tab.

Downloads go to the one client that asked (``client.send_file_download``). An upload is
validated by the same loader as the CLI (:func:`app.presets.loads_preset`); a bad file gets a
notification naming the problem and changes nothing.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import viser

from app import exports
from app.figures import make_phase_plane_figure, make_time_plots_figure
from app.figures_energy import make_energy_bars_figure, make_energy_figure
from app.presets import MAX_BYTES, PresetError, loads_preset
from control.params import DriveParams, ParameterError

#: Export label → (file suffix, needs a simulation).
EXPORTS = {
    "Drive parameters (YAML)": (".yaml", False),
    "Drive parameters (JSON)": (".json", False),
    "C header for firmware": (".h", False),
    "Time series (CSV)": (".csv", True),
    "HTML report (offline)": (".html", False),
}


def safe_stem(name: str) -> str:
    """A file-name stem from a preset name (letters, digits, ``_-.`` only)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "drive"


def export_text(kind: str, params: DriveParams, comparison: Any, origin: str,
                warnings: list[str]) -> str:
    """Text of one export kind (a key of :data:`EXPORTS`)."""
    d = comparison.derived
    if kind.endswith("(YAML)"):
        return exports.parameter_yaml(params, d, origin)
    if kind.endswith("(JSON)"):
        return exports.parameter_json(params, d, origin)
    if kind.startswith("C header"):
        return exports.parameter_c_header(params, d, origin)
    if kind.startswith("Time series"):
        return exports.trace_csv(comparison)
    figures = [make_phase_plane_figure(comparison)]
    if comparison.fdsmc is not None:
        figures += [make_time_plots_figure(comparison), make_energy_figure(comparison),
                    make_energy_bars_figure(comparison)]
    return exports.html_report(params, d, origin, warnings, figures)


def parse_upload(name: str, content: bytes) -> DriveParams:
    """Validate an uploaded preset file; PresetError/ParameterError with a clear message if bad."""
    if len(content) > MAX_BYTES:
        raise PresetError(f"{name} is too large ({len(content) // 1024} KiB): allowed ≤ {MAX_BYTES // 1024} KiB")
    try:
        text = content.decode("utf-8")
    except UnicodeDecodeError:
        raise PresetError(f"{name} is not UTF-8 text: allowed a YAML preset file") from None
    params = loads_preset(text, name or "<upload>")
    if not isinstance(params, DriveParams):
        raise PresetError(f"{name} is a preset for another mode: allowed a position-drive (FDSMC) preset")
    return params


class FilesPanel:
    """"Export" folder with one button per export kind, and the upload button."""

    def __init__(self, client: viser.ClientHandle, state: Callable[[], tuple[DriveParams, Any, str, list[str]]],
                 on_import: Callable[[DriveParams, str], None]) -> None:
        self._client, self._state, self._on_import = client, state, on_import
        gui = client.gui
        self.upload = gui.add_upload_button("Import preset (YAML)", icon=viser.Icon.UPLOAD,
                                            mime_type=".yaml,.yml,text/yaml,text/plain")
        self.upload.on_upload(self._uploaded)
        with gui.add_folder("Export", expand_by_default=False):
            self.buttons = {}
            for label in EXPORTS:
                button = gui.add_button(label, icon=viser.Icon.DOWNLOAD)
                button.on_click(lambda _, label=label: self._export(label))
                self.buttons[label] = button

    def _export(self, kind: str) -> None:
        params, comparison, origin, warnings = self._state()
        suffix, needs_run = EXPORTS[kind]
        if needs_run and comparison.fdsmc is None:
            self._client.add_notification("Nothing to export", "Simulate first: there is no time series yet.",
                                          color="yellow", auto_close_seconds=6.0)
            return
        text = export_text(kind, params, comparison, origin, warnings)
        self._client.send_file_download(f"{safe_stem(params.name)}{suffix}", text.encode("utf-8"),
                                        save_immediately=True)

    def _uploaded(self, _: viser.GuiEvent) -> None:
        f = self.upload.value
        try:
            params = parse_upload(f.name, f.content)
        except (PresetError, ParameterError) as exc:
            self._client.add_notification("Import rejected — nothing changed", str(exc), color="red",
                                          auto_close_seconds=15.0)
            return
        self._on_import(params, f.name)
