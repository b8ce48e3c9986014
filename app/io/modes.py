"""The one registry of preset modes: name, parameter dataclass, how messages name it, its page tab.

Every other table of modes is a view of :data:`REGISTRY` (the loader's name → dataclass map
:data:`MODES`, the unit layer's dataclasses, the page's import messages). A new mode is one entry
here.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.control.fdsmc.params import DriveParams


@dataclass(frozen=True)
class Mode:
    """One preset mode.

    Attributes
    ----------
    name : str
        The preset's ``mode`` value (``"position"`` is the default when a file gives none).
    params : type
        Its parameter dataclass.
    kind : str
        How an import message names its presets (``"position-drive preset"``).
    tab : str
        The page tab that imports them.
    """

    name: str
    params: type
    kind: str
    tab: str


REGISTRY: tuple[Mode, ...] = (
    Mode("position", DriveParams, "position-drive preset", "Position drive (FDSMC)"),
    Mode("bldc", BldcParams, "BLDC speed-drive preset", "BLDC speed SMC"),
)
#: Mode name → parameter dataclass (the loader's view).
MODES: dict[str, type] = {m.name: m.params for m in REGISTRY}
#: Parameter dataclass of each mode, in registry order.
MODE_CLASSES: tuple[type, ...] = tuple(m.params for m in REGISTRY)


def mode_for(params_or_class: object) -> Mode:
    """Return the registered mode of a parameter object or dataclass (KeyError if none)."""
    cls = params_or_class if isinstance(params_or_class, type) else type(params_or_class)
    for mode in REGISTRY:
        if issubclass(cls, mode.params):
            return mode
    raise KeyError(f"{cls.__name__} is not a registered preset mode")


__all__ = ["MODES", "MODE_CLASSES", "REGISTRY", "Mode", "mode_for"]
