"""Build script: the packages of ``app/``, ``control/``, ``sim/`` and the top-level ``presets/`` folder.

Everything else (metadata, package data, entry points) is in ``pyproject.toml``. The product's layout
keeps the presets in a top-level folder; they are installed as the data-only package ``app.presets``
(``package_dir`` maps it to ``presets/``), so :mod:`app.resources` finds them with
:mod:`importlib.resources` whatever the install kind (venv, ``--user``, ``--target``, ``--prefix``).
"""

from setuptools import find_namespace_packages, setup

setup(
    # namespace packages too: the data folders app/examples, app/ui/assets, app/exports/c
    packages=[*find_namespace_packages(include=["app*", "control*", "sim*"], exclude=["*__pycache__*"]), "app.presets"],
    package_dir={"app.presets": "presets"},
)
