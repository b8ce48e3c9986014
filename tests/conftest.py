"""Shared fixtures."""

from __future__ import annotations

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.params import DriveParams


@pytest.fixture(scope="session")
def paper_params() -> DriveParams:
    """The paper's section-5 preset (FDSMC paper, section 5)."""
    return load_preset("paper_12kw_pmsm")
