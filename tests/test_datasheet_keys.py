"""Datasheet-native keys: the CLI's --set and the YAML loader take a catalogue servo as printed.

i_max in A_rms or as the dq amplitude, Kv [rpm/V], Kt [N·m/A_rms], Ke [V_rms/krpm], the sensors and
the pass criteria; each key lands on its SI field exactly, and a bad value names key, value and range.
"""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from pmsm_commissioning.app.io.presets import PresetError, load_preset, load_raw, parse_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.model import torque_constant

BASE = "yaskawa_sgm7j_02a"


@pytest.mark.parametrize(("key", "value", "field", "si"), [
    ("sensors.encoder_cpr", "8192", ("sensors", "encoder_cpr"), 8192),
    ("sensors.i_noise_A_rms", "0.05", ("sensors", "i_noise"), 0.05),
    ("limits.omega_max_rpm", "6000", ("limits", "omega_max"), 6000 * math.pi / 30),
    ("limits.in_position_rad", "1e-4", ("limits", "in_position"), 1e-4),
    ("limits.in_position_deg", "0.01", ("limits", "in_position"), math.radians(0.01)),
    ("limits.overshoot_rad", "2e-4", ("limits", "overshoot"), 2e-4),
    ("limits.hold_i_rms_A", "0.3", ("limits", "hold_i_rms"), 0.3),
    ("controller.i_max_Arms", "5.8", ("controller", "i_max"), 5.8 * math.sqrt(2.0)),
])
def test_cli_keys_land_on_their_si_field(key, value, field, si):
    p = load_preset(BASE, [f"{key}={value}"])
    assert getattr(getattr(p, field[0]), field[1]) == pytest.approx(si, rel=1e-15)


def test_kv_and_kt_give_the_flux_through_the_pole_pairs():
    # Kv = 270 rpm/V (line-to-line peak) on 7 pole pairs: Ψ_PM = 60/(2π·√3·7·270) and K_t = 8.27/Kv.
    kv = load_preset("odrive_d5065_belt").motor
    assert kv.psi_pm == pytest.approx(60.0 / (2 * math.pi * math.sqrt(3.0) * 7 * 270.0), rel=1e-12)
    assert torque_constant(kv) == pytest.approx(60.0 / (2 * math.pi) * math.sqrt(3.0) / 2 / 270.0, rel=1e-12)
    assert torque_constant(kv) == pytest.approx(8.27 / 270.0, rel=1e-3)
    # Kt of a datasheet in N·m/A_rms: K_t(dq amplitude) = Kt_rms/√2
    kt = load_preset(BASE, ["motor.Kt_Nm_per_Arms=0.63"]).motor
    assert torque_constant(kt) == pytest.approx(0.63 / math.sqrt(2.0), rel=1e-12)


@pytest.mark.parametrize(("key", "value"), [("Ke_Vrms_krpm", 57.0), ("Ke_Vpk_krpm", 57.0 * math.sqrt(2.0)),
                                            ("Ke_ph_Vrms_krpm", 57.0 / math.sqrt(3.0)),
                                            ("Ke_ph_Vpk_krpm", 57.0 * math.sqrt(2.0 / 3.0))])
def test_ke_in_any_datasheet_form_gives_the_same_flux(key, value):
    # 57 V_rms LL/krpm (Siemens 1FT7044) written as LL peak, phase rms and phase peak
    ref = load_preset("siemens_1ft7044_ak7").motor.psi_pm
    raw = load_raw("siemens_1ft7044_ak7")
    raw["motor"].pop("Ke_Vrms_krpm")
    raw["motor"][key] = value
    assert parse_preset(raw).motor.psi_pm == pytest.approx(ref, rel=1e-12)


def test_line_to_line_winding_values_are_halved():
    p = load_preset(BASE, ["motor.R_s_LL_Ohm=3.68", "motor.L_d_LL_mH=27.2", "motor.L_q_LL_mH=27.2"])
    assert p.motor.R_s == pytest.approx(1.84) and p.motor.L_d == pytest.approx(13.6e-3)


def test_a_flux_key_and_psi_pm_together_are_refused():
    raw = load_raw("odrive_d5065_belt")
    raw["motor"]["psi_pm"] = 0.003
    with pytest.raises(PresetError, match="more than once"):
        parse_preset(raw)


@pytest.mark.parametrize(("key", "message"), [
    ("sensors.encoder_cpr=-1", r"sensors.encoder_cpr = -1 is out of range: allowed an integer 0 … 2\.14748e\+09"),
    ("sensors.encoder_cpr=1.5", r"sensors.encoder_cpr = '1.5' is not a whole number"),
    ("limits.in_position_rad=-1", r"limits.in_position = -1.0 rad is out of range: allowed 0 ≤ value ≤ 1000 rad"),
    ("controller.i_max_Arms=-2", r"controller.i_max = -2.8\d* A is out of range: allowed 0 ≤ value ≤ 1e\+06 A"),
])
def test_bad_values_name_the_field_value_and_range(key, message):
    with pytest.raises((ParameterError, PresetError), match=message):
        load_preset(BASE, [key])


def test_cli_design_writes_the_users_name_and_source_and_the_sensor_figures(tmp_path):
    out = tmp_path / "my_axis.yaml"
    r = subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "design", "odrive_d5065_belt", "--json", "-o",
                        str(out),
                        "--name", "my_axis", "--source", "D5065 on the lab arm"],
                       capture_output=True, text=True, check=True)
    import json

    data = json.loads(r.stdout)
    v = data["verified"]["fdsmc"]
    assert data["clean"] is True and data["verdict"] == "clean"
    assert {"i_peak_A", "hold_i_q_rms_A", "overshoot_rad", "in_position_s"} <= set(v)
    assert v["i_peak_A"] <= 40.5 and v["hold_i_q_rms_A"] <= 2.0
    designed = load_preset(str(out))
    assert designed.name == "my_axis" and designed.source.startswith("D5065 on the lab arm")
    assert designed.sensors.encoder_cpr == 8192
