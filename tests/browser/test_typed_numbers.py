"""Typed numbers reach the physics exactly as typed, or nothing runs and a message names the field.

The strings are what engineers type from datasheets; the value checked is the one the session's
derivations received (``Session.params``), read from the server after Simulate.
"""

from __future__ import annotations

import pytest

from tests.browser.conftest import set_number

J_R = "J_r rotor inertia [kg·m²]"
T_M = "T_m manoeuvre time [s]"


def _session(ui_server, page):
    page.wait_for_function("() => true")
    sessions = list(ui_server.config.sessions.values())
    return max(sessions, key=lambda s: s.client.client_id)


def _simulate_and_wait(page, session, runs_before):
    page.get_by_role("button", name="Simulate").click()
    page.wait_for_function("() => document.body.innerText.includes('run(s) in this session')")
    for _ in range(600):
        if session.runs > runs_before or session.error:
            return
        page.wait_for_timeout(100)


@pytest.mark.parametrize(("label", "text", "field", "si"), [
    (J_R, "4.86e-5", ("motor", "J_r"), 4.86e-5),
    (J_R, "0.0000486", ("motor", "J_r"), 4.86e-5),
    (J_R, "4.86E-5", ("motor", "J_r"), 4.86e-5),
    (T_M, "2.5", ("manoeuvre", "T_m"), 2.5),
    ("V_dc inverter DC link (0 = ideal) [V]", "1e3", ("controller", "V_dc"), 1000.0),
    ("V_0 rated (LL rms) [V]", "1 000", ("motor", "V_0"), 1000.0),
])
def test_typed_number_reaches_the_physics_exactly(page, ui_server, label, text, field, si):
    session = _session(ui_server, page)
    set_number(page, label, text)
    _simulate_and_wait(page, session, session.runs)
    assert session.error is None, session.error
    section, name = field
    assert getattr(getattr(session.params, section), name) == si  # exact, not approx


@pytest.mark.parametrize("text", ["1,5", "1.2.3", "abc", "", "NaN", "inf", "-0.5"])
def test_invalid_text_is_refused_and_nothing_runs(page, ui_server, text):
    session = _session(ui_server, page)
    before_params, before_runs = session.params, session.runs
    set_number(page, T_M, text)
    page.get_by_role("button", name="Simulate").click()
    page.wait_for_function("() => document.body.innerText.includes('nothing simulated')")
    body = page.inner_text("body")
    assert "T_m" in body and "allowed" in body
    assert session.runs == before_runs and session.params is before_params
