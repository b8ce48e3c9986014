"""Annotations are checked: mypy over app/, control/ and sim/ with the configuration in pyproject.toml
(``[tool.mypy]``: default strictness, a listed baseline of app/ modules not yet clean) finds no error, and
mypy --strict over control/ and sim/ finds none either.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# Temporary: files being edited now, annotated with the change under way in them (their strict errors are
# printed, not failed); remove a file once it passes. Errors elsewhere fail the tests.
BEING_ANNOTATED: frozenset[str] = frozenset()
ERROR = re.compile(r"^pmsm_commissioning/(\S+?\.py):\d+: error:", re.M)


def _mypy(tmp_path: Path, packages: tuple[str, ...], *options: str) -> tuple[str, list[str]]:
    """Run mypy on ``packages``; return its output and the files (as in the repository) of its errors.

    The module names (pmsm_commissioning.app …) exist only through setup.py's package_dir mapping: mypy
    reads a view of symlinks pmsm_commissioning/{app,control,sim} → the top-level folders.
    """
    view = tmp_path / "view" / "pmsm_commissioning"
    view.mkdir(parents=True)
    for name in ("app", "control", "sim"):
        (view / name).symlink_to(ROOT / name, target_is_directory=True)
    cmd = [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
           # one cache per strictness (the two tests may run at once, on two workers)
           "--cache-dir", str(ROOT / ".mypy_cache" / ("strict" if options else "default")), *options]
    for name in packages:
        cmd += ["-p", f"pmsm_commissioning.{name}"]
    r = subprocess.run(cmd, cwd=view.parent, capture_output=True, text=True, check=False)
    out = r.stdout + r.stderr
    assert r.returncode in (0, 1), out[-3000:]  # 2: mypy itself failed (configuration, crash)
    return out, ERROR.findall(out)


def _unexpected(out: str, files: list[str]) -> str:
    """The output's error lines outside the files being annotated (empty: none)."""
    lines = [line for line in out.splitlines() if ERROR.match(line)]
    return "\n".join(line for line, f in zip(lines, files, strict=True) if f not in BEING_ANNOTATED)


def test_mypy_finds_no_error(tmp_path: Path) -> None:
    out, files = _mypy(tmp_path, ("app", "control", "sim"))
    assert not _unexpected(out, files), _unexpected(out, files)[-3000:]


def test_mypy_strict_finds_no_error_in_control_and_sim(tmp_path: Path) -> None:
    out, files = _mypy(tmp_path, ("control", "sim"), "--strict")
    print(f"strict errors in the files being annotated: {len(files)}")
    assert not _unexpected(out, files), _unexpected(out, files)[-3000:]
    assert "checked" in out or "no issues found" in out  # mypy ran over the packages
