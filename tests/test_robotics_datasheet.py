"""Robotics datasheets: Kt per A peak, rated values derived from the inverter, the current-loop bandwidth."""

from __future__ import annotations

import math

import pytest

from pmsm_commissioning.app.io.preset_schema import parse_preset
from pmsm_commissioning.app.io.presets import PresetError, load_preset, load_raw
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.nameplate import nameplate_consistency, rated_from_inverter

BASE = "odrive_d5065_belt"  # Kv 270, 7 pole pairs, V_dc 24 V, i_max 40 A
DERIVED = ["motor.V_0=derived", "motor.P_r=derived", "motor.omega_b_rpm=derived"]


def test_d5065_kt_per_a_peak_gives_the_alpha_max_of_kv_270():
    """ODrive quotes torque_constant 8.27/Kv = 0.0306 N·m/A (per A peak): α_max as with Kv 270; the same
    number typed per A_rms gives Ψ_PM √2 too small (the 1695 vs 2401 rad/s² of a misread datasheet).
    """
    kv = derive(load_preset(BASE)).alpha.alpha_max
    for key in ("Kt_Nm_per_A", "Kt_Nm_per_Apeak"):
        p = load_preset(BASE, [f"motor.{key}=0.0306"])
        assert p.motor.psi_pm == pytest.approx(0.0306 / (1.5 * 7), rel=1e-15)
        assert derive(p).alpha.alpha_max == pytest.approx(kv, rel=2e-3)  # 0.0306 vs 8.27/270 = 0.03063
    rms = derive(load_preset(BASE, ["motor.Kt_Nm_per_Arms=0.0306"])).alpha.alpha_max
    assert rms == pytest.approx(kv / math.sqrt(2.0), rel=2e-3)


def test_a_misspelt_torque_constant_is_never_pointed_at_a_key_of_another_unit():
    with pytest.raises(PresetError) as exc:
        load_preset(BASE, ["motor.Kt_Nm_A=0.0306"])
    text = str(exc.value)
    assert "did you mean" not in text
    assert "Kt_Nm_per_Arms [N·m/A rms]" in text and "Kt_Nm_per_Apeak [N·m/A peak]" in text
    assert len(text) <= 300


@pytest.mark.parametrize(("key", "value"), [("current_bandwidth_rad_s", 1000.0),
                                            ("current_bandwidth_Hz", 1000.0 / (2 * math.pi))])
def test_current_loop_bandwidth_gives_t_si_by_eq_8(key, value):
    """Eq. (8): di_d/dt = (3/T_si)(i_dem − i_d), a pole at ω_c = 3/T_si: ODrive's 1000 rad/s → T_si = 3 ms."""
    p = load_preset(BASE, [f"controller.{key}={value!r}"])
    assert p.controller.T_si == pytest.approx(3e-3, rel=1e-12)


def test_bandwidth_out_of_range_is_named():
    with pytest.raises(ValueError, match=r"controller.current_bandwidth_rad_s = 0.0 rad/s is out of range: "
                                         r"allowed 0.3 ≤ value ≤ 3e\+06 rad/s"):
        load_preset(BASE, ["controller.current_bandwidth_rad_s=0"])


def test_rated_values_derived_from_the_inverter_close_the_voltage_equation():
    """ω_b derived: |u_dq| at ω_b and the peak current (i_d = 0, eqs. (1)–(2)) equals V_dc/√3 exactly."""
    p = load_preset(BASE, DERIVED)
    m, c = p.motor, p.controller
    i = min(c.i_max, m.Gamma_max / (1.5 * m.p * m.psi_pm))
    w_e = m.p * m.omega_b
    u = math.hypot(m.R_s * i + w_e * m.psi_pm, w_e * m.L_q * i)
    assert u == pytest.approx(c.V_dc / math.sqrt(3.0), rel=1e-12)
    assert pytest.approx(24.0 / math.sqrt(2.0), rel=1e-15) == m.V_0
    assert pytest.approx(1.5 * m.p * m.psi_pm * i * m.omega_b, rel=1e-12) == m.P_r
    assert rated_from_inverter(m, c.V_dc, c.i_max) == pytest.approx((m.V_0, m.P_r, m.omega_b), rel=1e-15)
    assert {x.name for x in nameplate_consistency(m)} <= {"rated torque"}  # consistent by construction


def test_left_out_rated_values_need_a_dc_link_and_a_rule_that_does_not_use_them():
    raw = load_raw(BASE)
    for key in ("V_0", "P_r", "omega_b_rpm"):
        del raw["motor"][key]
    assert pytest.approx(24.0 / math.sqrt(2.0)) == parse_preset(raw).motor.V_0
    raw["controller"]["V_dc"] = 0.0
    with pytest.raises(PresetError, match=r"missing key\(s\) in motor: V_0, P_r, omega_b \(allowed to be left out "
                                          r"only with controller.V_dc > 0"):
        parse_preset(raw)
    with pytest.raises(PresetError, match=r"controller.alpha_max_rule = 'paper' needs the datasheet's motor.P_r"):
        load_preset(BASE, [*DERIVED, "controller.alpha_max_rule=paper"])
