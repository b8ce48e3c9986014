"""The design's text and JSON say what the user did not type: derived rated values, inherited fields."""

from __future__ import annotations

import json
import math

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset, load_raw

BASE = "odrive_d5065_belt"  # Kv 270, 7 pole pairs, V_dc 24 V, i_max 40 A
DERIVED = ["motor.V_0=derived", "motor.P_r=derived", "motor.omega_b_rpm=derived"]


def test_mj5208_class_robotics_datasheet_designs_clean_with_derived_values_labelled(capsys, tmp_path):
    """The mj5208 of tests/data/catalogue (304 Kv: Kt per A peak 8.27/304 = 0.0272 N·m/A, R 46.5 mΩ and L
    24.5/26 µH phase to neutral, peak torque Kt·40 A; no rated voltage/power/speed) typed over the D5065's
    24 V axis: clean, V_0/P_r/ω_b labelled "derived" in the JSON and the designed preset (which reloads to
    the same values), and the base's sensors, load and current limit listed as inherited.
    """
    out_file = tmp_path / "mj5208.yaml"
    args = ["design", BASE, "--set", "motor.Kt_Nm_per_A=0.027204", "--set", "motor.R_s=0.0465",
            "--set", "motor.L_d=2.45e-5", "--set", "motor.L_q=2.6e-5", "--set", "motor.Gamma_max=1.088",
            "--set", "motor.J_r=7e-5", *[x for d in DERIVED for x in ("--set", d)], "--json", "-o", str(out_file)]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["verdict"] == "clean"
    derived = {d["key"]: d for d in out["assumptions"]["derived"]}
    assert set(derived) == {"motor.V_0", "motor.P_r", "motor.omega_b"}
    assert derived["motor.V_0"]["value"] == pytest.approx(24.0 / math.sqrt(2.0))
    inherited = {d["key"] for d in out["assumptions"]["inherited"]}
    assert {"sensors.i_noise", "sensors.i_adc_range", "load.F_v", "load.J_L", "controller.i_max"} <= inherited
    assert "motor.R_s" not in inherited and "motor.psi_pm" not in inherited
    assert load_raw(str(out_file))["motor"]["omega_b"] == "derived"
    overrides = args[3:-3:2]  # the values after each --set
    assert load_preset(str(out_file)).motor.omega_b == pytest.approx(load_preset(BASE, overrides).motor.omega_b,
                                                                     rel=1e-12)


def test_an_imported_drive_names_what_it_took_from_its_base(tmp_path, capsys):
    """import-drive --base writes the base's fields it did not import under ``inherited``; they are listed."""
    from pmsm_commissioning.app.io.assumed import assumptions

    out = tmp_path / "d5065.yaml"
    data = "tests/data/drives/odrive_d5065_backup.json"
    assert main(["import-drive", data, "--format", "odrive", "--base", "yaskawa_sgm7j_04a", "-o", str(out)]) == 0
    capsys.readouterr()
    raw = load_raw(str(out))
    a = assumptions(raw, load_preset(str(out)), ())
    keys = {x.key for x in a.inherited}
    assert a.base == "yaskawa_sgm7j_04a"
    assert {"sensors.i_noise", "sensors.i_adc_range", "limits.in_position", "load.F_v", "motor.V_0"} <= keys
    assert not keys & {"motor.R_s", "motor.psi_pm", "motor.p", "controller.i_max"}
    assert "sensors.i_noise = 0.0263 A" in " ".join(a.lines())  # the Yaskawa's current noise, carried over
