"""Ruff clean: app, sim, control, tests and scripts pass the pinned ruff with the rules of pyproject.toml."""

from __future__ import annotations

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_ruff_clean():
    r = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "app", "sim", "control", "tests", "scripts"],
        capture_output=True, text=True, cwd=ROOT, check=False,
    )
    assert r.returncode == 0, r.stdout + r.stderr
