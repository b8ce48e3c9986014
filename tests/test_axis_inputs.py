"""The page's axis inputs: a robotics datasheet (Kt per A peak, no rated values), the drive's current-loop
bandwidth, a lead-screw axis typed at its output, the DC link, and what was kept from the opened preset.
"""

from __future__ import annotations

import math
import re

import pytest

from pmsm_commissioning.app.io.display_units import UNIT_GROUPS
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.app.ui.axis_inputs import axis_markdown
from pmsm_commissioning.app.ui.inputs import InputError, InputsPanel
from pmsm_commissioning.control.fdsmc.nameplate import rated_from_inverter

PRESET = "odrive_d5065_belt"



@pytest.fixture
def panel(gui) -> InputsPanel:
    params = load(PRESET, mode="position")
    out = InputsPanel(gui, params)
    out.populate(params)
    return out


def _plain(markdown: str) -> str:
    """The text the readout shows (its Markdown escapes removed)."""
    return re.sub(r"\\(.)", r"\1", markdown)


def _unit(group: str, label: str):
    return next(u for u in UNIT_GROUPS[group] if u.label == label)


def test_kt_per_a_peak_and_the_current_loop_bandwidth_convert_in_closed_form():
    kt = _unit("flux", "Kt [N·m/A peak]")
    assert kt.to_si(0.0306, 7) == pytest.approx(0.0306 / (1.5 * 7), rel=1e-15)  # Γ = 1.5·p·Ψ·i_q
    assert kt.from_si(kt.to_si(0.0306, 7), 7) == pytest.approx(0.0306, rel=1e-15)
    hz = _unit("settling", "ω_c current-loop bandwidth [Hz]")
    assert hz.to_si(1000.0, 7) == pytest.approx(3.0 / (2.0 * math.pi * 1000.0), rel=1e-15)  # T_si = 3/ω_c
    assert _unit("settling", "ω_c current-loop bandwidth [rad/s]").from_si(1e-3, 7) == pytest.approx(3000.0)


def test_a_robotics_datasheet_typed_on_the_page_derives_the_rated_values(panel):
    """Kt per A peak and no V_0, P_r, n_b: the fields left empty are derived from V_dc and the current limit."""
    panel.selectors["flux"].value = "Kt [N·m/A peak]"
    panel._unit_changed("flux")
    panel.numbers["motor.psi_pm"].handle.value = "0.0306"
    for key in ("motor.V_0", "motor.P_r", "motor.omega_b"):
        panel.numbers[key].handle.value = ""
    panel.selectors["settling"].value = "ω_c current-loop bandwidth [Hz]"
    panel._unit_changed("settling")
    panel.numbers["controller.T_si"].handle.value = "1000"
    p = panel.collect()
    assert p.motor.psi_pm == pytest.approx(0.0306 / (1.5 * p.motor.p), rel=1e-12)
    assert p.controller.T_si == pytest.approx(3.0 / (2000.0 * math.pi), rel=1e-12)
    V_0, P_r, omega_b = rated_from_inverter(p.motor, p.controller.V_dc, p.controller.i_max)
    assert (p.motor.V_0, p.motor.P_r, p.motor.omega_b) == (V_0, P_r, omega_b)
    assert panel.rated_derived == ("V_0", "P_r", "omega_b")
    text = _plain(axis_markdown(p, panel.rated_derived, PRESET))
    assert text.count("**derived** (not typed)") == 3 and "motor.V_0 = 16.97 V (derived: V_dc/√2)" in text
    # the motor differs from the preset's: what the run kept of it is listed, the typed fields are not
    assert f"inherited from {PRESET}" in text and "sensors.i_noise" in text and "limits.in_position" in text
    assert "motor.psi_pm" not in text and "controller.T_si" not in text


def test_a_lead_screw_axis_typed_at_its_output_is_reflected(panel):
    """10 mm lead, 20 kg, 100 mm travel, ±5 µm window: J_L = m·(ℓ/2π)², θ_dem = 2π·x/ℓ."""
    panel.numbers["transmission.lead"].handle.value = "10"
    panel.output_side.numbers["load.mass_kg"].handle.value = "20"
    panel.output_side.numbers["manoeuvre.distance_mm"].handle.value = "100"
    panel.output_side.numbers["limits.in_position_um"].handle.value = "5"
    p = panel.collect()
    k = 0.01 / (2.0 * math.pi)
    assert p.transmission.lead == pytest.approx(0.01, rel=1e-12)
    assert math.isclose(p.load.J_L, 20.0 * k**2, rel_tol=1e-12)
    assert p.manoeuvre.theta_dem == pytest.approx(0.1 / k, rel=1e-12)
    assert p.limits.in_position == pytest.approx(5e-6 / k, rel=1e-12)
    assert "move 100 mm" in _plain(axis_markdown(p, (), "a file"))


def test_a_rotary_key_on_a_linear_axis_and_the_dc_link_choice(panel):
    panel.numbers["transmission.lead"].handle.value = "10"
    panel.output_side.numbers["load.J_L_out"].handle.value = "0.5"
    with pytest.raises(InputError, match=r"Transmission › load.J_L_out = 0.5 kg·m² is not allowed here: allowed "
                                         r"with a rotary output"):
        panel.collect()
    panel.output_side.clear()
    panel.dc_link.value = "battery"
    panel.numbers["controller.charge_efficiency"].handle.value = "0.8"
    c = panel.collect().controller
    assert (c.dc_link, c.charge_efficiency) == ("battery", 0.8)
    panel.dc_link.value = "supercap"  # a value never offered (a hostile client)
    with pytest.raises(InputError, match="DC link = 'supercap' is not one of the offered options"):
        panel.collect()
