"""The page draws the stock route: its figure (speed, i_q at the current limit, error in the window) and verdicts."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from tests.browser.conftest import UiServer, click_tab, figure
from tests.browser.preset_server import preset_page, preset_server

STOCK_FIGURE_DRAWN = ("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta "
                      "&& e.layout.meta.id === 'stock_route' && e._fullData && e._fullData.length >= 6)")


@pytest.fixture(scope="module")
def server() -> Iterator[UiServer]:
    with preset_server("yaskawa_sgm7j_04a") as srv:
        yield srv


@pytest.fixture
def page(browser: Any, server: UiServer) -> Iterator[Any]:
    with preset_page(browser, server) as pg:
        yield pg


def test_stock_drive_tab_draws_the_route_and_its_verdicts(page):
    click_tab(page, "Stock drive")
    page.wait_for_function(STOCK_FIGURE_DRAWN, timeout=120_000)
    fig = figure(page, "stock_route")
    assert fig is not None and fig["meta"]["clean"] is True  # the Σ-7 04A's stock route passes (tests/test_stock_route)
    assert fig["title"].startswith("Stock route (setpoint-table drive, its own loops): CLEAN")
    names = [t["name"] for t in fig["traces"] if t["name"]]
    assert "stock drive" in names and "FDSMC" in names
    assert all(len(t["y"]) > 100 for t in fig["traces"])  # traces, not numbers only
    text = page.inner_text(".stock-verdicts")
    for drive in ("ODrive fw 0.5.x", "moteus", "VESC", "setpoint table"):
        assert f"Stock route, {drive}: CLEAN" in text
