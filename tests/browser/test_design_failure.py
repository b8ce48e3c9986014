"""A design that fails after a good run never leaves the good run's results or "No warnings" as if current.

The default page (Siemens 1FT7044, 2^20 counts, ±6.3e-4 rad window) runs clean; the engineer then
types an 8192-count encoder (a count is 7.7e-4 rad, wider than the window) and asks for a design:
it is refused before any run, and the page must say why in the warnings box and mark the key
numbers of the previous run stale.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from tests.browser.conftest import UiServer, set_number
from tests.browser.preset_server import preset_page, preset_server


@pytest.fixture(scope="module")
def server() -> Iterator[UiServer]:
    from pmsm_commissioning.app.io.presets import DEFAULT_PRESET

    with preset_server(DEFAULT_PRESET) as srv:
        yield srv


@pytest.fixture
def page(browser: Any, server: UiServer) -> Iterator[Any]:
    with preset_page(browser, server) as pg:
        yield pg


def test_failing_design_after_a_good_run_marks_results_stale_and_shows_the_diagnosis(page):
    page.get_by_text("No warnings.", exact=False).first.wait_for(timeout=120_000)  # the good run
    assert page.locator('[data-role="stale-results"]').count() == 0
    set_number(page, "Encoder counts per rev (0 = ideal) [counts/rev]", "8192")
    page.get_by_role("button", name="Design for this drive").click()
    page.locator('[data-role="stale-results"]').wait_for(timeout=120_000)
    assert "Stale results" in page.inner_text('[data-role="stale-results"]')
    assert page.locator('[data-role="key-numbers"]').count() == 0  # the previous run's headline is gone
    warnings = page.inner_text('[data-role="warnings-list"]')
    assert "Design refused" in warnings and "8192" in warnings and "counts/rev" in warnings
    assert page.get_by_text("No warnings.", exact=False).count() == 0
