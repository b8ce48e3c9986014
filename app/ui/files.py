"""Export menu and preset upload of the position-drive tab.

Downloads go to the one client that asked (``client.send_file_download``) and are produced by the
export model shared with the CLI (:func:`app.exports.model.export_download`), so the page and
``pmsm-commission export`` write the same bytes. An export describes the simulated case; when the
inputs shown differ from it (edited but not simulated) the export is refused with a message naming
the uncommitted fields. An export of a design that is not clean
is refused with the failed checks named, unless "Export even if not clean" is ticked. An upload
(YAML or JSON) is validated by the same loader as the CLI
(:func:`app.io.presets.loads_preset`); a bad file gets a notification naming the problem and
changes nothing.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import viser

from pmsm_commissioning.app.exports.drives.files import ExportOptions
from pmsm_commissioning.app.exports.model import export_download, safe_stem
from pmsm_commissioning.app.io.modes import REGISTRY
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.presets import MAX_BYTES, loads_preset, to_raw
from pmsm_commissioning.app.io.user_text import check_label
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import Comparison

#: Export label → format of :func:`app.exports.model.export_files`.
EXPORTS = {
    "Drive parameters (YAML)": "yaml",
    "Drive parameters (JSON)": "json",
    "C controller module (.h + .c, zip)": "c",
    "Time series (CSV)": "csv",
    "HTML report (offline)": "html",
    "ODrive 0.5 backup (JSON)": "odrive",
    "moteus config (key value)": "moteus",
    "VESC motor config (XML)": "vesc",
    "Setpoint table (CSV)": "setpoints",
}

#: Export label → (format, controller) of the exports that take another outer law: the tracked optimum's C module.
LAW_EXPORTS = {"C controller module, tracked optimum (.h + .c, zip)": ("c", "optimum")}


class ExportRefusedError(ValueError):
    """An export that would not describe the inputs shown; the message says why."""


def _flat(params: DriveParams) -> dict[str, Any]:
    raw = to_raw(params)
    out: dict[str, Any] = {}
    for section, fields in raw.items():
        if isinstance(fields, dict):
            out.update({f"{section}.{k}": v for k, v in fields.items()})
    return out


def uncommitted(shown: DriveParams, committed: DriveParams) -> list[str]:
    """List ``field = shown (simulated: value)`` for every input that differs (SI units).

    Name and source are not simulated inputs (the Export folder sets them).
    """
    a, b = _flat(shown), _flat(committed)
    return [f"{k} = {a[k]!r} (simulated: {b.get(k)!r})" for k in a if a[k] != b.get(k)]


#: Each mode's presets as an import message names them, and the tab that imports them (:mod:`app.io.modes`).
PRESET_KINDS: dict[type, tuple[str, str]] = {m.params: (m.kind, m.tab) for m in REGISTRY}


def upload_text(name: str, content: bytes, allowed: str) -> str:
    """Return the text of an uploaded file.

    Raises PresetError naming the file if it is over MAX_BYTES or not UTF-8 (``allowed`` says what
    the upload takes, e.g. "a YAML or JSON preset file").
    """
    if len(content) > MAX_BYTES:
        raise PresetError(f"{name} is too large ({len(content) // 1024} KiB): allowed ≤ {MAX_BYTES // 1024} KiB")
    try:
        return content.decode("utf-8")
    except UnicodeDecodeError:
        raise PresetError(f"{name} is not UTF-8 text: allowed {allowed}") from None


def parse_upload(name: str, content: bytes, mode: type = DriveParams) -> Any:
    """Validate an uploaded preset file of ``mode`` (DriveParams or BldcParams).

    Raises PresetError or ParameterError with a clear message if it is bad, or if it is the other
    mode's preset.
    """
    params = loads_preset(upload_text(name, content, "a YAML or JSON preset file"), name or "<upload>")
    if not isinstance(params, mode):
        kind, tab = PRESET_KINDS[type(params)]
        raise PresetError(f"{name} is a {kind}: allowed a {PRESET_KINDS[mode][0]}; import it in the {tab} tab")
    return params


def renamed(cmp: Comparison, name: str, source: str) -> Comparison:
    """Return the case with the name and source written into the exports (both must be non-blank)."""
    for field, text in (("name", name), ("source", source)):
        if not text.strip():
            raise ExportRefusedError(f"Export › {field} = {text!r} is empty: allowed any non-blank text "
                                     "(the file name and the file's header come from it)")
        try:
            check_label(text, f"Export › {field}")
        except ParameterError as exc:
            raise ExportRefusedError(str(exc)) from None
    params = dataclasses.replace(cmp.derived.params, name=name.strip(), source=source.strip())
    return dataclasses.replace(cmp, derived=dataclasses.replace(cmp.derived, params=params))


class FilesPanel:
    """"Export" folder (name, source and one button per export format), and the upload button.

    ``state`` returns the simulated case to export or raises :class:`ExportRefusedError`; the
    name and source typed in the folder replace the case's in every file (and the file name).
    """

    def __init__(self, client: viser.ClientHandle, state: Callable[[], Comparison],
                 on_import: Callable[[DriveParams, str], None], params: DriveParams) -> None:
        self._client, self._state, self._on_import = client, state, on_import
        gui = client.gui
        self.upload = gui.add_upload_button("Import preset (YAML/JSON)", icon=viser.Icon.UPLOAD,
                                            mime_type=".yaml,.yml,.json,text/yaml,application/json,text/plain")
        self.upload.on_upload(self._uploaded)
        with gui.add_folder("Export", expand_by_default=False):
            self.name = gui.add_text("Name (file name)", params.name)
            self.source = gui.add_text("Source", params.source)
            self.force = gui.add_checkbox("Export even if not clean", False,
                                          hint="Write a design whose simulated run fails a check, with the failed "
                                               "checks inside the file (the CLI's --force)")
            self.buttons = {}
            choices = {label: (fmt, "fdsmc") for label, fmt in EXPORTS.items()} | LAW_EXPORTS
            for label, (fmt, law) in choices.items():
                button = gui.add_button(label, icon=viser.Icon.DOWNLOAD)
                button.on_click(lambda _, fmt=fmt, law=law: self._export(fmt, law))
                self.buttons[label] = button

    def _export(self, fmt: str, controller: str = "fdsmc") -> None:
        try:
            name, content = export_download(fmt, renamed(self._state(), self.name.value, self.source.value),
                                            ExportOptions(force=bool(self.force.value), controller=controller))
        except (ExportRefusedError, ParameterError) as exc:
            self._client.add_notification("Not exported", str(exc), color="yellow", auto_close_seconds=12.0)
            return
        self._client.send_file_download(name, content, save_immediately=True)

    def _uploaded(self, _: viser.GuiEvent) -> None:
        f = self.upload.value
        try:
            params = parse_upload(f.name, f.content)
        except (PresetError, ParameterError) as exc:
            self._client.add_notification("Import rejected — nothing changed", str(exc), color="red",
                                          auto_close_seconds=15.0)
            return
        self._on_import(params, f.name)

    def show_names(self, params: DriveParams) -> None:
        """Show the name and source of newly loaded inputs (a preset chosen or a file imported)."""
        self.name.value, self.source.value = params.name, params.source


__all__ = ["EXPORTS", "LAW_EXPORTS", "ExportRefusedError", "FilesPanel", "parse_upload", "renamed", "safe_stem",
           "uncommitted"]
