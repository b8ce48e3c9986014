"""Preset modes at the edges: every place that loads a preset for one mode refuses the others.

A BLDC preset given to ``derive``/``simulate``/``table1``/``serve`` or the FDSMC page, or a
position preset given to ``bldc``, is refused with a message naming both modes and the shipped
presets of the right one — never an AttributeError later.
"""

from __future__ import annotations

import typing
from typing import Any

from app.io.preset_schema import MODES, PresetError
from app.io.presets import list_presets, load_preset, load_raw


def mode_of(params: Any) -> str:
    """Return the preset mode of a parameter object (``"position"``, ``"bldc"`` …)."""
    return next(m for m, cls in MODES.items() if isinstance(params, cls))


def preset_mode(name: str) -> str | None:
    """Mode of the shipped or given preset ``name``; None if it cannot be read."""
    try:
        raw = load_raw(name)
    except PresetError:
        return None
    return str(raw.get("mode", "position")) if isinstance(raw, dict) else None


def list_presets_of(mode: str) -> list[str]:
    """Names of the shipped presets of ``mode``."""
    return [n for n in list_presets() if preset_mode(n) == mode]


def require_mode(params: Any, mode: str, origin: str) -> Any:
    """Return ``params`` if it belongs to ``mode``, else PresetError naming both modes."""
    found = mode_of(params)
    if found != mode:
        raise PresetError(f"preset {origin!r} is a {found}-mode preset: allowed here a {mode}-mode preset "
                          f"(shipped: {', '.join(list_presets_of(mode))})")
    return params


def load_mode_preset(name_or_path: str, overrides: typing.Iterable[str] = (), *, mode: str) -> Any:
    """:func:`app.io.presets.load_preset`, refusing a preset of another mode."""
    return require_mode(load_preset(name_or_path, overrides), mode, name_or_path)


__all__ = ["list_presets_of", "load_mode_preset", "mode_of", "preset_mode", "require_mode"]
