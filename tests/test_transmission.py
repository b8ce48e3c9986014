"""Transmission: gearbox, belt and lead screw reflected onto the rotor once, at the edge (closed forms)."""

from __future__ import annotations

import math

import pytest

from pmsm_commissioning.app.io.axis_view import run_at_output, transmission_json
from pmsm_commissioning.app.io.presets import dumps_preset, load_preset, loads_preset, to_raw
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc import transmission as tx
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.transmission import Transmission

BASE = "odrive_d5065_belt"


def test_gearbox_with_efficiency_closed_form():
    """10:1 gear: J_out 1 kg·m² → 0.01 kg·m² (η = 1), /η with losses; torque /(N·η); angle ×N."""
    g = Transmission(ratio=10.0)
    assert tx.inertia_to_motor(1.0, g) == pytest.approx(0.01, rel=1e-15)
    assert tx.position_to_motor(math.pi / 2, g) == pytest.approx(5.0 * math.pi, rel=1e-15)
    lossy = Transmission(ratio=10.0, efficiency=0.8)
    assert tx.inertia_to_motor(1.0, lossy) == pytest.approx(0.01 / 0.8, rel=1e-15)
    assert tx.friction_to_motor(2.0, lossy) == pytest.approx(2.0 / (0.8 * 100.0), rel=1e-15)
    assert tx.torque_to_motor(50.0, lossy) == pytest.approx(50.0 / (0.8 * 10.0), rel=1e-15)
    # what the motor's torque delivers at the output: Γ·N·η; round trips are exact inverses
    assert tx.torque_to_output(tx.torque_to_motor(50.0, lossy), lossy) == pytest.approx(50.0, rel=1e-15)
    assert tx.inertia_to_output(tx.inertia_to_motor(3.0, lossy), lossy) == pytest.approx(3.0, rel=1e-15)


def test_lead_screw_and_belt_closed_form():
    """Lead 10 mm, 20 kg: J = m·(ℓ/2π)² = 5.07e-5 kg·m²; a 20 mm pulley: J = m·r²; a belt ratio divides by N²."""
    screw = Transmission(lead=0.010)
    assert tx.inertia_to_motor(20.0, screw) == pytest.approx(20.0 * (0.010 / (2 * math.pi)) ** 2, rel=1e-15)
    assert tx.inertia_to_motor(20.0, screw) == pytest.approx(5.066e-5, rel=1e-3)
    assert tx.torque_to_motor(100.0, screw) == pytest.approx(100.0 * 0.010 / (2 * math.pi), rel=1e-15)
    assert tx.position_to_motor(0.100, screw) == pytest.approx(20.0 * math.pi, rel=1e-15)  # 100 mm = 10 rev
    belt = Transmission(ratio=3.0, pulley_radius=0.020)
    assert tx.inertia_to_motor(2.0, belt) == pytest.approx(2.0 * 0.020**2 / 9.0, rel=1e-15)
    assert tx.position_to_output(tx.position_to_motor(0.3, belt), belt) == pytest.approx(0.3, rel=1e-15)
    with pytest.raises(ParameterError, match=r"transmission.pulley_radius = 0.02 m is not allowed with "
                                             r"transmission.lead = 0.01 m"):
        Transmission(lead=0.010, pulley_radius=0.020)
    with pytest.raises(ParameterError, match=r"transmission.efficiency = 0.0 is out of range: allowed 0 < value ≤ 1"):
        Transmission(efficiency=0.0)


def test_the_same_move_typed_on_either_side_is_the_same_physics():
    """The D5065 preset's belt (5:1): J_L 4e-4 at the rotor = 0.01 kg·m² at the arm; 5 rev = 1 output rev."""
    motor_side = load_preset(BASE)
    out_side = load_preset(BASE, ["transmission.ratio=5", "load.J_L_out=0.01", "manoeuvre.theta_dem_out_deg=360",
                                  "limits.in_position_out_deg=0.05"])
    assert pytest.approx(motor_side.load.J_L, rel=1e-12) == out_side.load.J_L
    assert out_side.manoeuvre.theta_dem == pytest.approx(motor_side.manoeuvre.theta_dem, rel=1e-12)
    assert out_side.limits.in_position == pytest.approx(math.radians(0.25), rel=1e-12)
    assert derive(out_side).alpha.alpha_max == pytest.approx(derive(motor_side).alpha.alpha_max, rel=1e-9)
    # an override in the other form replaces the file's value (no "given twice")
    assert pytest.approx(0.02, rel=1e-15) == load_preset(BASE, ["load.J_L_out=0.02"]).load.J_L


def test_linear_axis_from_mm_and_kg_round_trips():
    p = load_preset(BASE, ["transmission.lead_mm=10", "load.mass_kg=20", "load.force_N=50",
                           "manoeuvre.distance_mm=100", "limits.in_position_um=10", "limits.speed_max_mm_s=500"])
    k = 0.010 / (2 * math.pi)
    assert pytest.approx(20.0 * k * k, rel=1e-12) == p.load.J_L
    assert pytest.approx(50.0 * k, rel=1e-12) == p.load.Gamma_Le
    assert p.manoeuvre.theta_dem == pytest.approx(0.1 / k, rel=1e-12)
    assert p.limits.in_position == pytest.approx(10e-6 / k, rel=1e-12)
    assert p.limits.omega_max == pytest.approx(0.5 / k, rel=1e-12)
    assert loads_preset(dumps_preset(p)) == p  # written in rotor-side SI with the transmission section
    assert to_raw(p)["transmission"]["lead"] == 0.010
    assert to_raw(load_preset(BASE))["transmission"] == {"ratio": 1.0, "efficiency": 1.0, "lead": 0.0,
                                                         "pulley_radius": 0.0}  # a direct drive, said so
    j = transmission_json(p)
    assert j["move"] == {"value": pytest.approx(100.0, rel=1e-12), "unit": "mm"}
    assert j["load_inertia"]["value"] == pytest.approx(20.0, rel=1e-12)


@pytest.mark.parametrize(("overrides", "match"), [
    (["load.mass_kg=20"], r"load.mass_kg = 20.0 kg is not allowed here: allowed with a linear axis"),
    (["transmission.lead_mm=10", "load.J_L_out=1"], r"load.J_L_out = 1.0 kg·m² is not allowed here: allowed with "
                                                    r"a rotary output"),
    (["transmission.lead_mm=10", "load.mass_kg=-2"], r"load.mass_kg = -2.0 kg gives load.J_L = -5.06.*e-06 "
                                                     r"kg·m² is out of range: allowed 0 ≤ value"),
    (["transmission.ratio=0"], r"transmission.ratio = 0.0 is out of range: allowed 0.001 ≤ value ≤ 100000"),
])
def test_bad_transmission_input_names_key_value_and_range(overrides, match):
    with pytest.raises(ValueError, match=match):
        load_preset(BASE, overrides)


def test_run_results_at_the_output():
    """Error, speed and torque of a run shown at a 10:1 gearbox's output: /10, /10, ×10·η."""
    p = load_preset(BASE, ["transmission.ratio=10", "transmission.efficiency=0.9"])

    class M:
        theta_error_at_Tm_rad, overshoot_rad, omega_peak_rad_s, torque_peak_Nm = 0.1, 0.0, 100.0, 1.0

    out = run_at_output(M, p)
    assert out["error_at_Tm_out"]["value"] == pytest.approx(math.degrees(0.01), rel=1e-12)
    assert out["speed_peak_out"] == {"value": pytest.approx(10.0 * 60 / (2 * math.pi), rel=1e-12), "unit": "rpm"}
    assert out["torque_peak_out"]["value"] == pytest.approx(9.0, rel=1e-12)
