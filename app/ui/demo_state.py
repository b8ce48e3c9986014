"""The lecture's demo state as a file: inputs (and the plant's J_L), slider ranges and pinned runs.

Pure text in and out (no viser, no file system): the page sends :func:`dumps_state`'s text as a
download and reads an upload back with :func:`loads_state`. The file is JSON:

* ``demo_state``: 1 (the format's version);
* ``preset``: the case as preset text (:func:`app.io.presets.dumps_preset`, with a ``plant``
  section when the J_L slider's plant differs from the model) — read back by the preset loader,
  so every check of an imported preset applies;
* ``origin``: where the case came from (shown on the status line, escaped);
* ``ranges``: the least range of each logarithmic slider [its unit], e.g. ``"T_m": [0.1, 10]``;
* ``pins``: the pinned runs (label, t [s], θ_re [rad], ω_r [rad/s]).

The upload goes through the same size and depth checks as every JSON file and every number
through the project's number grammar (:func:`app.io.json_data.loads_json_raw`,
:func:`app.io.numbers.parse_number`); anything else is refused with one line naming the key.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from typing import Any

from app.figures.fdsmc_pins import MAX_PINS, Pin
from app.io.json_data import loads_json_raw
from app.io.numbers import QuotedText, parse_number, shorten
from app.io.preset_schema import PresetError
from app.io.presets import dumps_preset, loads_preset_and_plant
from control.fdsmc.params import DriveParams

#: The format's version, and the keys of a demo-state file.
VERSION = 1
KEYS = ("demo_state", "preset", "origin", "ranges", "pins")
#: Most points per pinned array.
MAX_PIN_POINTS = 4000
#: Longest text kept for a label or origin [characters].
MAX_TEXT = 200


@dataclass(frozen=True)
class DemoState:
    """A lecture's state: the case (model and the plant's J_L [kg·m²] or None), its origin, slider ranges, pins."""

    params: DriveParams
    plant_J_L: float | None
    origin: str
    ranges: dict[str, tuple[float, float]]
    pins: tuple[Pin, ...]


def dumps_state(state: DemoState) -> str:
    """Return the JSON text of ``state`` (numbers with float32 precision for the pins)."""
    plant = (None if state.plant_J_L is None else
             dataclasses.replace(state.params, load=dataclasses.replace(state.params.load, J_L=state.plant_J_L)))
    pins = [{"label": p.label, "t": [float(f"{v:.6g}") for v in p.t],
             "theta_re": [float(f"{v:.6g}") for v in p.theta_re], "omega_r": [float(f"{v:.6g}") for v in p.omega_r]}
            for p in state.pins]
    return json.dumps({"demo_state": VERSION, "preset": dumps_preset(state.params, plant), "origin": state.origin,
                       "ranges": {k: list(v) for k, v in state.ranges.items()}, "pins": pins},
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


def loads_state(text: str, origin: str = "<demo state>") -> DemoState:
    """Read a demo-state file (see the module's text); PresetError or ParameterError with one line if it is bad."""
    raw = loads_json_raw(text, origin)
    if not isinstance(raw, dict) or set(raw) != set(KEYS):
        found = ", ".join(map(shorten, raw)) if isinstance(raw, dict) else type(raw).__name__
        raise PresetError(f"{origin} is not a demo-state file: allowed exactly the keys {', '.join(KEYS)} "
                          f"(found {found})")
    if str(raw["demo_state"]) != str(VERSION):
        raise PresetError(f"{origin} › demo_state = {shorten(raw['demo_state'])!r}: allowed {VERSION}")
    try:
        params, plant = loads_preset_and_plant(_text_full(raw["preset"], f"{origin} › preset"), f"{origin} › preset")
    except ValueError as exc:  # the preset loader's own message, said of this file
        raise PresetError(f"{origin} › preset: {exc}") from None
    if not isinstance(params, DriveParams):
        raise PresetError(f"{origin} › preset is not a position-drive preset: allowed a position-drive preset")
    return DemoState(params, None if plant is None else plant.load.J_L, _text(raw["origin"], f"{origin} › origin"),
                     _ranges(raw["ranges"], origin), _pins(raw["pins"], origin))


def _text_full(value: Any, where: str) -> str:
    _text(value, where)
    return str(value)


__all__ = ["DemoState", "dumps_state", "loads_state"]
