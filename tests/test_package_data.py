"""Production code reads package data only: the example drive log shipped in ``app/examples`` is the
same file as the tests' copy in ``tests/data``, and no module of app/, control/ or sim/ names ``tests/``.
"""

from __future__ import annotations

import re
from pathlib import Path

from app.io.presets import PRESET_DIR
from app.resources import example_log, preset_dir

ROOT = Path(__file__).resolve().parents[1]


def test_example_log_is_the_tests_copy() -> None:
    assert example_log().read_bytes() == (ROOT / "tests" / "data" / example_log().name).read_bytes()


def test_presets_come_from_the_top_level_folder_of_a_clone() -> None:
    # the product's layout: presets/ at the top; a wheel installs them as data files (tests/test_install.py)
    assert PRESET_DIR == preset_dir() == ROOT / "presets"
    assert (PRESET_DIR / "paper_12kw_pmsm.yaml").is_file()


def test_no_production_module_reads_the_tests_folder() -> None:
    pattern = re.compile(r"""["'/]tests["'/]""")
    offenders = [str(p.relative_to(ROOT)) for pkg in ("app", "control", "sim") for p in (ROOT / pkg).rglob("*.py")
                 if pattern.search(p.read_text(encoding="utf-8"))]
    assert offenders == []
