"""Production code reads package data only: the example drive log shipped in ``app/examples`` is the
same file as the tests' copy in ``tests/data``, and no module of app/, control/ or sim/ names ``tests/``.
"""

from __future__ import annotations

import re
from pathlib import Path

from pmsm_commissioning.app.io.presets import PRESET_DIR
from pmsm_commissioning.app.resources import example_log, preset_dir

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


def test_parquet_without_pyarrow_names_the_extra(tmp_path, monkeypatch, capsys) -> None:
    import importlib.util

    from pmsm_commissioning.app.cli.main import main

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pyarrow" else real(name, *a))
    rc = main(["robustness", "paper_12kw_pmsm", "--samples", "4", "--spread", "plant.J_L=±20%",
               "--parquet", str(tmp_path / "r.parquet")])
    err = capsys.readouterr().err
    assert rc == 2 and "pmsm-commissioning[parquet]" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "r.parquet").exists()


def test_numba_cache_goes_to_the_chosen_the_clones_or_the_users_folder(tmp_path, monkeypatch) -> None:
    from pmsm_commissioning.sim import numba_cache

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "chosen"))
    assert numba_cache.cache_base() == tmp_path / "chosen"
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    assert numba_cache.cache_base() == ROOT / ".numba_cache"  # a clone
    monkeypatch.setattr(numba_cache, "_ROOT", tmp_path / "site-packages")  # an installed wheel
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/ignored")
    assert numba_cache.cache_base() == tmp_path / "home" / ".cache" / "pmsm-commissioning" / "numba"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert numba_cache.cache_base() == tmp_path / "xdg" / "pmsm-commissioning" / "numba"
