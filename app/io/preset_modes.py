"""Preset modes at the edges: every place that loads a preset for one mode refuses the others.

A BLDC preset given to ``derive``/``simulate``/``table1``/``serve`` or the FDSMC page, or a
position preset given to ``bldc``, is refused with a message naming both modes and the shipped
presets of the right one — never an AttributeError later. The functions live in
:mod:`app.io.presets` (``load(name_or_path, overrides, mode)``); the registry in :mod:`app.io.modes`.
"""

from __future__ import annotations

import typing
from typing import Any

from pmsm_commissioning.app.io.modes import mode_for
from pmsm_commissioning.app.io.presets import list_presets_of, load, preset_mode, require_mode


def mode_of(params: Any) -> str:
    """Return the preset mode of a parameter object (``"position"``, ``"bldc"`` …)."""
    return mode_for(params).name


def load_mode_preset(name_or_path: str, overrides: typing.Iterable[str] = (), *, mode: str) -> Any:
    """Alias of :func:`app.io.presets.load` with a mode (kept for tests)."""
    return load(name_or_path, overrides, mode)


__all__ = ["list_presets_of", "load_mode_preset", "mode_of", "preset_mode", "require_mode"]
