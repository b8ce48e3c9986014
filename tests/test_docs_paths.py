"""Every file the README and the docs name exists, and every ``module.attribute`` they name is there.

A manual that names a moved or renamed file sends its reader nowhere; this keeps the names true
after a re-room (the paths are written as in the docs: ``app/ui/worker.py``, ``app/ui/worker.Worker``).
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").rglob("*.md"))]
#: A project path as the docs write it (not part of a longer path or address).
PATH = re.compile(r"(?<![\w/.:-])((?:app|sim|control|scripts|tests|presets|docs|\.ci)/[\w/.-]*\w)")
#: Files of a vendor's own repository that docs/drives/ quotes (ODrive's and moteus's docs), not ours.
VENDOR_FILES = {"docs/control.md", "docs/getting-started.rst", "docs/reference.md"}


def _resolves(path: str) -> bool:
    """True when ``path`` is a file or folder, or ``module/path.attr`` names an attribute of that module."""
    if (ROOT / path).exists() or (ROOT / "docs" / path).exists():
        return True
    module, _, attr = path.rpartition(".")
    if not module or not (ROOT / f"{module}.py").is_file():
        return False
    mod = importlib.import_module("pmsm_commissioning." + module.replace("/", "."))
    return hasattr(mod, attr)


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_named_paths_exist(doc: Path) -> None:
    """Each path in ``doc`` exists (a file, a folder, or a module's attribute)."""
    named = {m.group(1).rstrip(".") for m in PATH.finditer(doc.read_text(encoding="utf-8"))}
    missing = sorted(p for p in named - VENDOR_FILES if "*" not in p and not _resolves(p))
    assert not missing, f"{doc.relative_to(ROOT)} names what does not exist: {missing}"
