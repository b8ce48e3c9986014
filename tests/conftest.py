"""Shared fixtures, and the ``browser`` marker on every test under tests/browser/.

Markers (registered in pyproject.toml): ``browser`` (drives the page in Chromium), ``cluster`` (starts a Dask
scheduler), ``slow`` (over ≈ 20 s on a 2-core machine). ``pytest -m "not browser and not cluster and not slow"``
is the fast run for development; the README's command and CI run every test.
"""

from __future__ import annotations

import pathlib

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.params import DriveParams


@pytest.fixture(scope="session")
def paper_params() -> DriveParams:
    """The paper's section-5 preset (FDSMC paper, section 5)."""
    return load_preset("paper_12kw_pmsm")


BROWSER_TESTS = pathlib.Path(__file__).resolve().parent / "browser"


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark every test of tests/browser/ ``browser`` (by its folder: a new browser test needs no mark)."""
    for item in items:
        if BROWSER_TESTS in item.path.resolve().parents:
            item.add_marker(pytest.mark.browser)
