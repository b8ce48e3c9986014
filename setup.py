"""Build script: one import package, ``pmsm_commissioning``, from the top-level folders.

Everything else (metadata, package data, entry points) is in ``pyproject.toml``. The product's layout
keeps the folders ``app/``, ``control/``, ``sim/`` and ``presets/`` at the top level; they are installed
as ``pmsm_commissioning.app``, ``pmsm_commissioning.control``, ``pmsm_commissioning.sim`` and the data-only package
``pmsm_commissioning.presets`` (``package_dir`` maps each), so nothing named ``app``, ``control`` or ``sim``
lands in site-packages (python-control's ``control`` stays intact). ``pmsm_commissioning`` has no
``__init__.py``: a namespace package. :mod:`pmsm_commissioning.app.resources` finds the presets with
:mod:`importlib.resources` whatever the install kind (venv, ``--user``, ``--target``, ``--prefix``, editable).
"""

from setuptools import find_namespace_packages, setup

NAME = "pmsm_commissioning"
PARTS = ("app", "control", "sim")

# namespace packages too: the data folders app/examples, app/ui/assets, app/exports/firmware/c
found = find_namespace_packages(include=[p for part in PARTS for p in (part, f"{part}.*")], exclude=["*__pycache__*"])

setup(
    packages=[*(f"{NAME}.{p}" for p in found), f"{NAME}.presets"],
    package_dir={f"{NAME}.{part}": part for part in (*PARTS, "presets")},
)
