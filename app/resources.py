"""Data shipped inside the package: the presets and the example drive log.

Read through :mod:`importlib.resources`, so the page and the CLI find them from an installed wheel
as from a clone; nothing in production code reads ``tests/``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: File name of the drive log behind the page's Example button (a copy is in ``tests/data``).
EXAMPLE_LOG_NAME = "drive_log_dq.csv"


def _package_dir(name: str) -> Path:
    """Return the folder ``app/<name>`` of the installed package as a file-system path."""
    return Path(str(resources.files("app").joinpath(name)))


def preset_dir() -> Path:
    """Return the folder holding the shipped presets (``app/presets/*.yaml``)."""
    return _package_dir("presets")


def example_log() -> Path:
    """Return the path of the example drive log (dq signals, 6800 samples at 10 kHz)."""
    return _package_dir("examples") / EXAMPLE_LOG_NAME
