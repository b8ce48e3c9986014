"""The lecture's demo state as a file: inputs (and the plant's J_L), slider ranges, pinned runs, tabs and zoom.

Pure text in and out (no viser, no file system): the page sends :func:`dumps_state`'s text as a
download and reads an upload back with :func:`loads_state`. The file is JSON:

* ``demo_state``: 2 (the format's version; a version-1 file, without ``tab`` and ``zoom``, still loads);
* ``preset``: the case as preset text (:func:`app.io.presets.dumps_preset`, with a ``plant``
  section when the J_L slider's plant differs from the model) — read back by the preset loader,
  so every check of an imported preset applies;
* ``origin``: where the case came from (shown on the status line, escaped);
* ``ranges``: the least range of each logarithmic slider [its unit], e.g. ``"T_m": [0.1, 10]``;
* ``pins``: the pinned runs (label, t [s], θ_re [rad], ω_r [rad/s]);
* ``tab``: the tabs shown, ``{"mode": …, "results": …}``: the mode tab of the control panel (one of
  :data:`MODE_TABS`) and the results panel's tab (one of :data:`RESULTS_TABS`), each null if unknown;
* ``zoom``: the overview's axes the user zoomed, axis name → [min, max] in the axis' unit (θ_re
  [rad], ω_r [rad/s], t [s], Γ [N·m]), e.g. ``"xaxis": [-62, -28]``; ``{}`` when not zoomed.

The upload goes through the same size and depth checks as every JSON file and every number
through the project's number grammar (:func:`app.io.json_data.loads_json_raw`,
:func:`app.io.numbers.parse_number`); anything else is refused with one line naming the key.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from typing import Any

from pmsm_commissioning.app.figures.fdsmc_pins import MAX_PINS, Pin
from pmsm_commissioning.app.io.json_data import loads_json_raw
from pmsm_commissioning.app.io.numbers import QuotedText, parse_number, shorten
from pmsm_commissioning.app.io.plant_overrides import with_plant_J_L
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.presets import dumps_preset, loads_preset_and_plant
from pmsm_commissioning.control.fdsmc.params import DriveParams

#: The format's version, and the keys of a demo-state file of each version read.
VERSION = 2
KEYS_V1 = ("demo_state", "preset", "origin", "ranges", "pins")
KEYS = (*KEYS_V1, "tab", "zoom")
#: The page's tabs a demo state may show: the control panel's mode tabs, the results panel's tabs.
MODE_TABS = ("Position drive (FDSMC)", "BLDC speed SMC")
RESULTS_TABS = ("Overview", "K sweep", "Time plots", "Energy", "Stock drive", "Table 1 sweep", "Studies",
                "BLDC figures", "Share")
#: The overview's axis names (Plotly's ``xaxis``, ``yaxis2``, …) a zoom may name.
AXIS_NAME = re.compile(r"[xy]axis[2-9]?")
#: Most points per pinned array.
MAX_PIN_POINTS = 4000
#: Longest text kept for a label or origin [characters].
MAX_TEXT = 200


@dataclass(frozen=True)
class PageView:
    """What the page shows: the mode tab and results tab (None if unknown), the overview's zoom.

    ``zoom`` maps an axis name of the overview (:data:`AXIS_NAME`) to its range [min, max] in the
    axis' unit; an axis not named keeps the range the figure gives it.
    """

    mode_tab: str | None = None
    results_tab: str | None = None
    zoom: dict[str, tuple[float, float]] = field(default_factory=dict)

    def as_json(self) -> dict[str, Any]:
        """Return the ``tab`` and ``zoom`` entries of a demo-state file."""
        return {"tab": {"mode": self.mode_tab, "results": self.results_tab},
                "zoom": {k: [float(v) for v in r] for k, r in self.zoom.items()}}


@dataclass(frozen=True)
class DemoState:
    """A lecture's state: the case (model, the plant's J_L [kg·m²] or None), origin, slider ranges, pins, view."""

    params: DriveParams
    plant_J_L: float | None
    origin: str
    ranges: dict[str, tuple[float, float]]
    pins: tuple[Pin, ...]
    view: PageView = field(default_factory=PageView)


def dumps_state(state: DemoState) -> str:
    """Return the JSON text of ``state`` (numbers with float32 precision for the pins)."""
    plant = None if state.plant_J_L is None else with_plant_J_L(state.params, state.plant_J_L)
    pins = [{"label": p.label, "t": [float(f"{v:.6g}") for v in p.t],
             "theta_re": [float(f"{v:.6g}") for v in p.theta_re], "omega_r": [float(f"{v:.6g}") for v in p.omega_r]}
            for p in state.pins]
    return json.dumps({"demo_state": VERSION, "preset": dumps_preset(state.params, plant), "origin": state.origin,
                       "ranges": {k: list(v) for k, v in state.ranges.items()}, "pins": pins,
                       **state.view.as_json()},
                      ensure_ascii=False, separators=(",", ":"))


def _text(value: Any, where: str) -> str:
    if not isinstance(value, QuotedText):
        raise PresetError(f"{where} = {shorten(value)!r} is not text: allowed a quoted string")
    return str(value)[:MAX_TEXT]


def _numbers(value: Any, where: str, limit: int) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) > limit:
        raise PresetError(f"{where} is not a list of at most {limit} numbers")
    if any(not isinstance(v, str) or isinstance(v, QuotedText) for v in value):
        raise PresetError(f"{where} holds a value that is not a number: allowed finite numbers")
    out = tuple(parse_number(v, where) for v in value)
    if not all(math.isfinite(v) for v in out):
        raise PresetError(f"{where} holds a value that is not a finite number: allowed finite numbers")
    return out


def _pins(value: Any, origin: str) -> tuple[Pin, ...]:
    if not isinstance(value, list) or len(value) > MAX_PINS:
        raise PresetError(f"{origin} › pins is not a list of at most {MAX_PINS} pinned runs")
    out = []
    for n, item in enumerate(value, start=1):
        where = f"{origin} › pins[{n}]"
        if not isinstance(item, dict) or set(item) != {"label", "t", "theta_re", "omega_r"}:
            raise PresetError(f"{where} is not an object with exactly label, t, theta_re and omega_r")
        arrays = [_numbers(item[k], f"{where}.{k}", MAX_PIN_POINTS) for k in ("t", "theta_re", "omega_r")]
        if len({len(a) for a in arrays}) != 1:
            raise PresetError(f"{where}: t, theta_re and omega_r have different lengths: allowed equal lengths")
        out.append(Pin(_text(item["label"], f"{where}.label"), *arrays))
    return tuple(out)


def _ranges(value: Any, origin: str) -> dict[str, tuple[float, float]]:
    if not isinstance(value, dict):
        raise PresetError(f"{origin} › ranges is not an object of slider name → [min, max]")
    out = {}
    for name, pair in value.items():
        lo, hi = (_numbers(pair, f"{origin} › ranges.{shorten(name)}", 2) + (math.nan, math.nan))[:2]
        if not 0.0 < lo < hi:
            raise PresetError(f"{origin} › ranges.{shorten(name)} = [{lo:g}, {hi:g}]: allowed 0 < min < max")
        out[str(name)] = (lo, hi)
    return out


def _tab(value: Any, where: str, allowed: tuple[str, ...]) -> str | None:
    if value is None:
        return None
    if not isinstance(value, QuotedText) or str(value) not in allowed:
        raise PresetError(f"{where} = {shorten(value)!r}: allowed null or one of {', '.join(allowed)}")
    return str(value)


def _zoom(value: Any, origin: str) -> dict[str, tuple[float, float]]:
    if not isinstance(value, dict) or len(value) > 16:
        raise PresetError(f"{origin} › zoom is not an object of at most 16 axis name → [min, max]")
    out = {}
    for name, pair in value.items():
        where = f"{origin} › zoom.{shorten(name)}"
        if not AXIS_NAME.fullmatch(str(name)):
            raise PresetError(f"{where}: allowed axis names xaxis, yaxis, xaxis2 … yaxis9")
        lo, hi = (_numbers(pair, where, 2) + (math.nan, math.nan))[:2]
        if not lo < hi:
            raise PresetError(f"{where} = [{lo:g}, {hi:g}]: allowed finite numbers with min < max")
        out[str(name)] = (lo, hi)
    return out


def view_of(raw: dict[str, Any], origin: str) -> PageView:
    """Return the :class:`PageView` of the ``tab`` and ``zoom`` entries of ``raw`` (a parsed JSON object)."""
    tab = raw["tab"]
    if not isinstance(tab, dict) or set(tab) != {"mode", "results"}:
        raise PresetError(f"{origin} › tab is not an object with exactly mode and results")
    return PageView(_tab(tab["mode"], f"{origin} › tab.mode", MODE_TABS),
                    _tab(tab["results"], f"{origin} › tab.results", RESULTS_TABS), _zoom(raw["zoom"], origin))


def loads_view(text: str, origin: str = "<page view>") -> PageView:
    """Read ``{"tab": …, "zoom": …}`` (the page's report, see the module's text); PresetError if it is bad."""
    raw = loads_json_raw(text, origin)
    if not isinstance(raw, dict) or set(raw) != {"tab", "zoom"}:
        raise PresetError(f"{origin} is not a page view: allowed exactly the keys tab, zoom")
    return view_of(raw, origin)


def _check_keys(raw: Any, origin: str) -> None:
    """Refuse anything but a demo-state file of version 1 (:data:`KEYS_V1`) or 2 (:data:`KEYS`)."""
    version = str(raw.get("demo_state")) if isinstance(raw, dict) else None
    keys = KEYS_V1 if version == "1" else KEYS
    if not isinstance(raw, dict) or set(raw) != set(keys):
        found = ", ".join(map(shorten, raw)) if isinstance(raw, dict) else type(raw).__name__
        raise PresetError(f"{origin} is not a demo-state file: allowed exactly the keys {', '.join(keys)} "
                          f"(found {found})")
    if version not in ("1", str(VERSION)):
        raise PresetError(f"{origin} › demo_state = {shorten(raw['demo_state'])!r}: allowed 1 or {VERSION}")


def loads_state(text: str, origin: str = "<demo state>") -> DemoState:
    """Read a demo-state file (see the module's text); PresetError or ParameterError with one line if it is bad."""
    raw = loads_json_raw(text, origin)
    _check_keys(raw, origin)
    try:
        params, plant = loads_preset_and_plant(_text_full(raw["preset"], f"{origin} › preset"), f"{origin} › preset")
    except ValueError as exc:  # the preset loader's own message, said of this file
        raise PresetError(f"{origin} › preset: {exc}") from None
    if not isinstance(params, DriveParams):
        raise PresetError(f"{origin} › preset is not a position-drive preset: allowed a position-drive preset")
    view = view_of(raw, origin) if "tab" in raw else PageView()
    return DemoState(params, None if plant is None else plant.load.J_L, _text(raw["origin"], f"{origin} › origin"),
                     _ranges(raw["ranges"], origin), _pins(raw["pins"], origin), view)


def _text_full(value: Any, where: str) -> str:
    _text(value, where)
    return str(value)


__all__ = ["MODE_TABS", "RESULTS_TABS", "DemoState", "PageView", "dumps_state", "loads_state", "loads_view",
           "view_of"]
