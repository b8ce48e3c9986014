"""Data shipped with the package: the presets and the example drive log.

The presets live in the project's top-level ``presets/`` folder (the product's layout); a wheel
installs that folder as the data-only package ``pmsm_commissioning.presets`` (``setup.py`` maps it), so every
install kind (a venv, ``pip install --user``, ``--target``, ``--prefix``) finds them beside the code
through :mod:`importlib.resources`, never through the interpreter's data path (which is not where
``--user`` puts data files). The example drive log is package data too. So the page and the CLI find
both from an installed wheel as from a clone; nothing in production code reads ``tests/``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: File name of the drive log behind the page's Example button (a copy is in ``tests/data``).
EXAMPLE_LOG_NAME = "drive_log_dq.csv"


def _package_dir(name: str) -> Path:
    """Return the folder ``pmsm_commissioning/app/<name>`` of the installed package as a file-system path."""
    return Path(str(resources.files("pmsm_commissioning.app").joinpath(name)))


def preset_dir() -> Path:
    """Return the folder holding the shipped presets: the clone's ``presets/``, else the installed package's."""
    root = Path(__file__).resolve().parents[1]
    if (root / "pyproject.toml").is_file() and (root / "presets").is_dir():  # a clone (editable install)
        return root / "presets"
    return Path(str(resources.files("pmsm_commissioning.app"))).parent / "presets"  # pmsm_commissioning.presets


def example_log() -> Path:
    """Return the path of the example drive log (dq signals, 6800 samples at 10 kHz)."""
    return _package_dir("examples") / EXAMPLE_LOG_NAME
