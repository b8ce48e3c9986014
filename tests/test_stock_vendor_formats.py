"""Stock-drive files: every key written is the vendor's documented key in the vendor's unit; export →
strict parser → the same values; realistic vendor files import to the expected preset.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives import moteus, odrive, setpoints, vesc
from pmsm_commissioning.app.exports.drives.files import ExportOptions
from pmsm_commissioning.app.exports.drives.import_drive import import_drive
from pmsm_commissioning.app.exports.drives.stock import stock_settings
from pmsm_commissioning.app.exports.drives.units import KV_KT, TURN_RAD
from pmsm_commissioning.app.exports.model import export_files
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError

DATA = Path(__file__).parent / "data" / "drives"
REAL_MOTORS = ("siemens_1ft7044_ak7", "yaskawa_sgm7a_50a", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a",
               "example_log_drive")
#: float32 precision of the drives (the files carry 9 significant digits).
F32 = 2e-7

#: The documented keys and units each format writes (odrive-interface.yaml fw 0.5.x and the ODrive
#: parameter docs; moteus docs/reference.md and fw/bldc_servo_structs.h; VESC parameters_mcconf.xml).
ODRIVE_KEYS = {
    "axis0.motor.config.motor_type": "-", "axis0.encoder.config.cpr": "counts/rev",
    "axis0.motor.config.pole_pairs": "-", "axis0.motor.config.phase_resistance": "Ohm",
    "axis0.motor.config.phase_inductance": "H", "axis0.motor.config.torque_constant": "Nm/A",
    "axis0.motor.config.current_lim": "A", "axis0.motor.config.current_control_bandwidth": "rad/s",
    "axis0.encoder.config.bandwidth": "rad/s", "axis0.controller.config.control_mode": "-",
    "axis0.controller.config.input_mode": "-", "axis0.controller.config.pos_gain": "(turn/s) / turn",
    "axis0.controller.config.vel_gain": "Nm/(turn/s)", "axis0.controller.config.vel_integrator_gain": "Nm/(turn/s * s)",
    "axis0.controller.config.vel_limit": "turn/s", "axis0.controller.config.inertia": "Nm/(turn/s^2)",
    "axis0.trap_traj.config.vel_limit": "turn/s", "axis0.trap_traj.config.accel_limit": "turn/s^2",
    "axis0.trap_traj.config.decel_limit": "turn/s^2",
}
MOTEUS_KEYS = {
    "motor.poles": "-", "motor.resistance_ohm": "Ohm", "servo.max_current_A": "A", "servo.pid_position.kp": "Nm/rev",
    "servo.pid_position.ki": "Nm/s/rev", "servo.pid_position.kd": "Nm/(rev/s)", "servo.pid_position.ilimit": "Nm",
    "servo.default_velocity_limit": "rev/s", "servo.default_accel_limit": "rev/s^2",
    "servo.inertia_feedforward": "kg*m^2", "motor_position.rotor_to_output_ratio": "-", "servo.pid_dq.kp": "V/A",
    "servo.pid_dq.ki": "V/A/s", "motor_position.sources.0.pll_filter_hz": "Hz", "servo.pwm_rate_hz": "Hz",
}
VESC_KEYS = {
    "motor_type": "-", "l_current_max": "A", "l_current_min": "A", "foc_motor_r": "Ohm", "foc_motor_l": "H",
    "foc_motor_ld_lq_diff": "H", "foc_motor_flux_linkage": "Wb", "si_motor_poles": "-", "foc_current_kp": "V/A",
    "foc_current_ki": "V/(A*s)", "foc_f_zv": "Hz",
}


@pytest.fixture(scope="module", params=REAL_MOTORS)
def real_case(request):
    return case(load_preset(request.param), "odrive")


def _text(fmt: str, cmp) -> str:
    """The exported file (forced: the formats are tested here whatever the verdict; the gate in test_stock_exports)."""
    ((_, content),) = export_files(fmt, cmp, ExportOptions(force=True)).items()
    return content.decode("utf-8")


def test_every_key_written_is_documented_with_the_vendors_unit():
    assert {k: v.unit for k, v in odrive.KEYS.items()} == ODRIVE_KEYS
    assert {k: v.unit for k, v in moteus.KEYS.items()} == MOTEUS_KEYS
    assert {k: v.unit for k, v in vesc.KEYS.items()} == VESC_KEYS
    for keys in (odrive.KEYS, moteus.KEYS, vesc.KEYS):
        assert all(vk.doc for vk in keys.values())


def test_odrive_round_trip_and_units(real_case):
    s = stock_settings(real_case, "odrive")
    text = _text("odrive", real_case)
    parsed = odrive.parse_odrive(text)
    ideal = real_case.derived.params.sensors.encoder_cpr == 0  # no count to write: the drive keeps its cpr
    assert set(dict(parsed.values)) == set(ODRIVE_KEYS) - ({"axis0.encoder.config.cpr"} if ideal else set())
    assert parsed.unknown == ()
    assert any("parameter hash" in c for c in parsed.comment) and any("stock route" in c for c in parsed.comment)
    for key, want in odrive.odrive_values(s).items():
        assert parsed.get(key) == pytest.approx(want, rel=F32)
    p = real_case.derived.params
    assert parsed.get("axis0.trap_traj.config.accel_limit") == pytest.approx(
        s.tuning.accel_fraction * real_case.derived.alpha.alpha_max / TURN_RAD, rel=F32)  # rad/s² → turn/s²
    w_v = s.tuning.omega_v  # the tuned speed loop: vel_gain = J·ω_v, pos_gain = ω_v/4 (sim.stock.tuning)
    assert parsed.get("axis0.controller.config.vel_gain") == pytest.approx(w_v * p.J_total * TURN_RAD, rel=F32)
    assert parsed.get("axis0.controller.config.pos_gain") == pytest.approx(w_v / 4.0, rel=F32)
    assert parsed.get("axis0.motor.config.current_control_bandwidth") == pytest.approx(3.0 / p.controller.T_si)
    assert parsed.get("axis0.motor.config.torque_constant") == pytest.approx(1.5 * p.motor.p * p.motor.psi_pm, rel=F32)
    assert parsed.get("axis0.controller.config.input_mode") == 5  # TRAP_TRAJ
    assert parsed.get("axis0.motor.config.pole_pairs") == p.motor.p
    tr = s.trapezoid  # the planner's move: cruise × (T_m − T_a) = Δθ, in turns
    assert (parsed.get("axis0.trap_traj.config.vel_limit") * (tr.T_m - tr.T_a)
            == pytest.approx(abs(p.manoeuvre.theta_dem) / TURN_RAD, rel=1e-6))


def test_moteus_round_trip_and_units(real_case):
    s = stock_settings(real_case, "moteus")
    parsed = moteus.parse_moteus(_text("moteus", real_case))
    assert set(dict(parsed.values)) == set(MOTEUS_KEYS) and parsed.unknown == ()
    for key, want in moteus.moteus_values(s).items():
        assert parsed.get(key) == pytest.approx(want, rel=F32)
    p = real_case.derived.params
    assert parsed.get("motor.poles") == 2 * p.motor.p  # poles, not pole pairs
    kp = s.tuning.omega_v ** 2 / 4.0 * p.J_total * TURN_RAD  # N·m per revolution
    assert parsed.get("servo.pid_position.kp") == pytest.approx(kp, rel=F32)
    assert parsed.get("servo.pid_position.ki") == 0.0  # no integrator for a high torque bandwidth
    assert parsed.get("servo.default_accel_limit") == pytest.approx(
        s.tuning.accel_fraction * real_case.derived.alpha.alpha_max / TURN_RAD, rel=F32)
    assert parsed.get("servo.inertia_feedforward") == pytest.approx(p.J_total, rel=F32)


def test_vesc_round_trip_and_units(real_case):
    s = stock_settings(real_case, "vesc")
    parsed = vesc.parse_vesc(_text("vesc", real_case))
    assert set(dict(parsed.values)) == set(VESC_KEYS) and parsed.unknown == ()
    for key, want in vesc.vesc_values(s).items():
        assert parsed.get(key) == pytest.approx(want, rel=F32, abs=1e-15)
    m = real_case.derived.params.motor
    assert parsed.get("foc_motor_flux_linkage") == pytest.approx(m.psi_pm, rel=F32)
    assert parsed.get("si_motor_poles") == 2 * m.p
    R, Ld, Lq, psi, p, i_max = vesc.vesc_motor(parsed)  # back to the preset's motor
    assert (R, Ld, Lq, psi, p) == (pytest.approx(m.R_s, rel=F32), pytest.approx(m.L_d, rel=F32),
                                   pytest.approx(m.L_q, rel=F32), pytest.approx(m.psi_pm, rel=F32), m.p)


@pytest.mark.parametrize("unit", ["rad", "deg", "rev"])
def test_setpoints_at_the_drive_cycle_in_the_users_unit(unit):
    cmp = case(load_preset("yaskawa_sgm7j_04a"), "setpoints")
    s = stock_settings(cmp, "setpoints")
    files = export_files("setpoints", cmp, ExportOptions(force=True, angle_unit=unit, cycle_s=1e-3))
    table = setpoints.parse_setpoints(next(iter(files.values())).decode())
    scale = {"rad": 1.0, "deg": 180.0 / math.pi, "rev": 1.0 / TURN_RAD}[unit]
    assert table.unit == unit and np.allclose(np.diff(table.t), 1e-3)
    assert table.t[-1] == pytest.approx(s.trapezoid.T_m) and table.omega[-1] == 0.0
    assert table.theta[-1] == pytest.approx(cmp.derived.params.manoeuvre.theta_dem * scale, rel=F32)
    assert np.max(np.abs(table.alpha)) == pytest.approx(s.trapezoid.alpha * scale, rel=F32)
    default = setpoints.parse_setpoints(_text("setpoints", cmp))  # default: the drive's 1/f_s, rad
    assert np.diff(default.t)[0] == pytest.approx(1.0 / 16000.0) and default.unit == "rad"


def test_strict_parsers_name_the_key_the_value_and_what_is_allowed():
    with pytest.raises(ParameterError, match=r"axis0.motor.config.pole_pairs = 7.5 is not allowed: an integer"):
        odrive.parse_odrive('{"axis0": {"motor": {"config": {"pole_pairs": 7.5}}}}')
    with pytest.raises(ParameterError, match=r"phase_resistance = 'x' is not allowed: a finite number in Ohm"):
        odrive.parse_odrive('{"axis0": {"motor": {"config": {"phase_resistance": "x"}}}}')
    with pytest.raises(ParameterError, match=r"current_lim = '40' is not allowed: a finite number in A"):
        odrive.parse_odrive('{"axis0": {"motor": {"config": {"current_lim": "40"}}}}')  # JSON: a number, not text
    with pytest.raises(ParameterError, match="given more than once"):
        odrive.parse_odrive('{"axis0": {"motor": {"config": {"current_lim": 1, "current_lim": 2}}}}')
    with pytest.raises(ParameterError, match="not an ODrive backup"):
        odrive.parse_odrive("[1, 2]")
    with pytest.raises(ParameterError, match=r"moteus line 2 = 'motor.poles=14' is not allowed: 'key value'"):
        moteus.parse_moteus("id.id 1\nmotor.poles=14\n")
    with pytest.raises(ParameterError, match=r"motor.resistance_ohm = nan is not allowed: a finite number in Ohm"):
        moteus.parse_moteus("motor.resistance_ohm nan\n")
    assert math.isnan(moteus.parse_moteus("servo.default_velocity_limit nan\n").get("servo.default_velocity_limit"))
    with pytest.raises(ParameterError, match="root element <VESC> is not allowed"):
        vesc.parse_vesc("<VESC><ConfigVersion>2</ConfigVersion></VESC>")
    with pytest.raises(ParameterError, match="ConfigVersion> is missing"):
        vesc.parse_vesc("<MCConfiguration><foc_motor_r>0.1</foc_motor_r></MCConfiguration>")
    with pytest.raises(ParameterError, match="DOCTYPE or ENTITY is not allowed"):
        vesc.parse_vesc('<!DOCTYPE x [<!ENTITY a "b">]><MCConfiguration/>')
    with pytest.raises(ParameterError, match="setpoint row 3 .* four finite numbers"):
        setpoints.parse_setpoints("t [s],theta [rad],omega [rad/s],alpha [rad/s^2]\n0,0,0,0\n1,2,3\n")


def test_odrive_backup_imports_to_the_expected_preset():
    base = load_preset("yaskawa_sgm7j_02a")
    res = import_drive((DATA / "odrive_d5065_backup.json").read_text(), "odrive", base)
    m = res.params.motor
    assert (m.R_s, m.L_d, m.L_q, m.p) == (0.03909124433994293, 1.9776541739702225e-05, 1.9776541739702225e-05, 7)
    assert m.psi_pm == pytest.approx(0.03062962926924229 / (1.5 * 7), rel=1e-15)  # Kt = 1.5·p·Ψ_PM
    assert res.params.controller.i_max == 40.0
    assert (res.params.load, res.params.manoeuvre, m.J_r) == (base.load, base.manoeuvre, base.motor.J_r)
    # every key not imported is listed, including axis 1 and the values odrivetool stores as Infinity
    assert "axis1.motor.config.phase_resistance" in res.not_imported
    assert "axis0.motor.config.torque_lim" in res.not_imported and "config.dc_max_positive_current" in res.not_imported
    assert "axis0.motor.config.phase_resistance" not in res.not_imported and res.kept == ()


def test_moteus_dump_imports_to_the_expected_preset():
    res = import_drive((DATA / "moteus_mj5208_dump.cfg").read_text(), "moteus", load_preset("yaskawa_sgm7j_02a"))
    m = res.params.motor
    assert (m.R_s, m.L_d, m.L_q, m.p) == (0.0465, 2.45e-05, 2.6e-05, 7)  # 14 poles → 7 pole pairs
    assert m.psi_pm == pytest.approx(KV_KT / 304.0 / (1.5 * 7), rel=1e-12)
    assert res.params.controller.i_max == 40.0
    assert {"servo.pid_position.kp", "motor.offset.0", "aux2.pins.0.mode"} <= set(res.not_imported)
    no_kv = import_drive("motor.poles 14\nmotor.resistance_ohm 0.05\nservo.max_current_A 20\n", "moteus",
                         load_preset("yaskawa_sgm7j_02a"))
    assert any(k.startswith("motor.psi_pm") for k in no_kv.kept) and any(k.startswith("motor.L_d") for k in no_kv.kept)


def test_vesc_mcconf_imports_to_the_expected_preset():
    res = import_drive((DATA / "vesc_6374_mcconf.xml").read_text(), "vesc", load_preset("yaskawa_sgm7j_02a"))
    m = res.params.motor
    assert (m.R_s, m.psi_pm, m.p) == (0.02733, 0.00963, 7)
    assert (m.L_d, m.L_q) == (pytest.approx(2.19e-05), pytest.approx(2.59e-05))  # L ∓ (Lq − Ld)/2
    assert res.params.controller.i_max == 60.0
    assert "foc_motor_ld_lq_diff" not in res.not_imported and "si_battery_cells" in res.not_imported


def test_import_errors_name_the_vendor_key_value_and_range():
    base = load_preset("yaskawa_sgm7j_02a")
    text = (DATA / "odrive_d5065_backup.json").read_text().replace('"phase_resistance": 0.03909124433994293',
                                                                    '"phase_resistance": -0.5')
    with pytest.raises(ParameterError, match=r"axis0.motor.config.phase_resistance = -0.5 Ohm is not allowed: .*"
                                             r"motor.R_s = -0.5 .*out of range: allowed"):
        import_drive(text, "odrive", base)
    with pytest.raises(ParameterError, match=r"motor.poles = 13 is not allowed: an even number of poles"):
        import_drive("motor.poles 13\nmotor.resistance_ohm 0.05\nservo.max_current_A 20\n", "moteus", base)
    with pytest.raises(ParameterError, match=r"foc_motor_flux_linkage is missing"):
        import_drive("<MCConfiguration><ConfigVersion>2</ConfigVersion><foc_motor_r>0.1</foc_motor_r><foc_motor_l>"
                     "1e-5</foc_motor_l><si_motor_poles>14</si_motor_poles></MCConfiguration>", "vesc", base)


def test_import_drive_cli_writes_a_loadable_preset_and_lists_unknown_keys(tmp_path, capsys):
    out = tmp_path / "d5065.yaml"
    assert main(["import-drive", str(DATA / "odrive_d5065_backup.json"), "--format", "odrive",
                 "--base", "yaskawa_sgm7j_02a", "-o", str(out)]) == 0
    text = out.read_text()
    assert "# not imported (" in text and "axis1.motor.config.current_lim" in text
    p = load_preset(str(out))
    assert p.motor.p == 7 and p.name == "odrive_d5065_backup" and "odrive" in p.source
    assert "not imported" in capsys.readouterr().out
    assert [x.name for x in tmp_path.iterdir()] == ["d5065.yaml"]  # no temporary file left behind
    bad = tmp_path / "bad.json"
    bad.write_text('{"axis0": {"motor": {"config": {"pole_pairs": "seven"}}}}')
    assert main(["import-drive", str(bad), "--format", "odrive", "--base", "yaskawa_sgm7j_02a",
                 "-o", str(tmp_path / "x.yaml")]) == 2
    assert not (tmp_path / "x.yaml").exists()


def test_exported_odrive_file_imports_back_the_motor(tmp_path):
    """export → import: the ODrive file carries the preset's motor (L as the mean of L_d, L_q)."""
    cmp = case(load_preset("yaskawa_sgm7j_04a"), "odrive")
    res = import_drive(_text("odrive", cmp), "odrive", load_preset("yaskawa_sgm7j_02a"))
    m = cmp.derived.params.motor
    assert res.params.motor.R_s == pytest.approx(m.R_s, rel=F32)
    assert res.params.motor.psi_pm == pytest.approx(m.psi_pm, rel=F32) and res.params.motor.p == m.p
    assert json.loads(_text("odrive", cmp))["_comment"][0].startswith("preset: yaskawa_sgm7j_04a")
