"""The axis as the engineer has it, on the page: a geared axis typed at its output, and the DC-link choice.

On the Σ-7 SGM7J-02A the tracked optimum returns the most energy to the DC link: netted it is the least
(recommended with a regenerative link), drawn the stock drive's trapezoid is (recommended with the default
braking resistor), so flipping the DC link changes the headline and the recommendation.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import pytest

from pmsm_commissioning.app.figures.style import fmt
from pmsm_commissioning.app.ui.number_fields import shown_text
from tests.browser.conftest import UiServer, field, set_number
from tests.browser.preset_server import preset_page, preset_server
from tests.browser.test_design import choose

PRESET = "yaskawa_sgm7j_02a"
HEADLINE = '[data-role="key-numbers"]'


@pytest.fixture(scope="module")
def server() -> Iterator[UiServer]:
    with preset_server(PRESET) as srv:
        yield srv


@pytest.fixture
def page(browser: Any, server: UiServer) -> Iterator[Any]:
    with preset_page(browser, server) as pg:
        yield pg


def _session(server: UiServer) -> Any:
    return max(server.config.sessions.values(), key=lambda s: s.client.client_id)


def _wait_run(page: Any, session: Any, runs_before: int) -> None:
    for _ in range(1800):
        if (session.runs > runs_before and not session.tab.busy) or session.error:
            break
        page.wait_for_timeout(100)
    assert session.error is None, session.error
    assert session.runs > runs_before


def test_a_geared_axis_typed_at_its_output_is_reflected_onto_the_rotor(page, server):
    """10:1 gearbox at 90 %: 0.02 kg·m² at the output is J_L = 0.02/(0.9·10²) on the rotor, 36° a 1-rev move."""
    session = _session(server)
    page.locator(HEADLINE).wait_for()
    before = session.runs
    set_number(page, "N transmission ratio (motor rev per output rev) [-]", "10")
    set_number(page, "η transmission efficiency [-]", "0.9")
    set_number(page, "J at the output [kg·m²]", "0.02")
    set_number(page, "Move at the output [deg]", "36")
    page.get_by_role("button", name="Simulate").click()
    _wait_run(page, session, before)
    p = session.params
    reflected = 0.02 / (0.9 * 10**2)
    assert p.transmission.ratio == 10.0 and p.transmission.efficiency == 0.9
    assert math.isclose(p.load.J_L, reflected, rel_tol=1e-12)
    assert p.manoeuvre.theta_dem == pytest.approx(10.0 * math.radians(36.0), rel=1e-12)
    # the rotor-side fields show what the output's values give; the readout states the axis at the output
    assert field(page, "J_L load inertia [kg·m²]").input_value() == shown_text(reflected)
    page.get_by_text("Transmission: N = 10 motor rev per output rev", exact=False).first.wait_for()
    readout = page.get_by_text("Transmission: N = 10", exact=False).first.inner_text()
    assert "move 36 deg" in readout and "load 0.02 kg·m²" in readout


def test_flipping_the_dc_link_changes_the_headline_and_the_recommendation(page, server):
    session = _session(server)
    page.locator(HEADLINE).wait_for()
    head = page.inner_text(HEADLINE)
    assert "DC link: braking resistor" in head and "recommended: Stock drive" in head  # the default
    drawn = session.comparison.stock.metrics.motoring_total_J
    assert f"Stock drive {fmt(drawn, 'J', 3)}" in head  # the energy drawn: the supply's with a braking resistor
    before = session.runs
    choose(page, "DC link", "regenerative")  # the choice re-runs by itself
    _wait_run(page, session, before)
    page.wait_for_function("(s) => document.querySelector(s).innerText.includes('DC link: regenerative')",
                           arg=HEADLINE)
    head = page.inner_text(HEADLINE)
    assert session.params.controller.dc_link == "regenerative"
    assert "recommended: Optimum" in head
    net = session.comparison.optimum.metrics.electrical_in_total_J
    assert f"Optimum {fmt(net, 'J', 3)}" in head  # now the net electrical input
