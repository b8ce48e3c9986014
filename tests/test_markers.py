"""The slow-test list of tests/conftest.py names functions that exist (a renamed test would silently join the
fast run), and the listed tests are marked ``slow``.
"""

from __future__ import annotations

import ast
import pathlib
import subprocess
import sys

from tests.conftest import SLOW

TESTS = pathlib.Path(__file__).resolve().parent


def test_every_listed_slow_test_exists():
    missing = []
    for file, names in SLOW.items():
        tree = ast.parse((TESTS / file).read_text(encoding="utf-8"))
        defined = {n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)}
        missing += [f"{file}::{name}" for name in sorted(names - defined)]
    assert not missing, missing


def test_the_listed_tests_are_marked_slow():
    r = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "--co", "-m", "slow",
                        str(TESTS / "test_types.py"), str(TESTS / "test_docs_index.py")],
                       capture_output=True, text=True, cwd=TESTS.parent, check=False)
    assert "2/4 tests collected (2 deselected)" in r.stdout, r.stdout[-2000:]
