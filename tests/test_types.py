"""Annotations are checked: mypy over app/, control/ and sim/ with the configuration in pyproject.toml
(``[tool.mypy]``: default strictness, a listed baseline of modules not yet clean) finds no error.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_finds_no_error() -> None:
    r = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, capture_output=True, text=True, check=False)
    assert r.returncode == 0, (r.stdout + r.stderr)[-3000:]
    assert r.stdout.startswith("Success: no issues found")
