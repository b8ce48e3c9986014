"""Vendor files read right or refused: ODrive motor types and layouts, the encoder's cpr, VESC ConfigVersion."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.exports.drives import odrive, vesc
from pmsm_commissioning.app.exports.drives.files import ExportOptions
from pmsm_commissioning.app.exports.drives.import_drive import import_drive
from pmsm_commissioning.app.exports.drives.stock import stock_settings
from pmsm_commissioning.app.exports.model import export_files
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError

DATA = Path(__file__).parent / "data" / "drives"
ODRIVE = (DATA / "odrive_d5065_backup.json").read_text()
VESC = (DATA / "vesc_6374_mcconf.xml").read_text()
BASE = "yaskawa_sgm7j_02a"


def _text(fmt: str, cmp) -> str:
    """The exported file (forced: the format is tested, whatever the verdict)."""
    ((_, content),) = export_files(fmt, cmp, ExportOptions(force=True)).items()
    return content.decode("utf-8")


def test_gimbal_odrive_backup_is_refused_naming_the_voltage_meaning():
    """ODrive fw 0.5.x docs: with motor_type GIMBAL (2) current_lim is a voltage limit [V], not a current."""
    text = ODRIVE.replace('"motor_type": 0, "current_lim": 40.0', '"motor_type": 2, "current_lim": 10.0')
    with pytest.raises(ParameterError, match=r"axis0.motor.config.motor_type = 2 \(GIMBAL: current_lim is a voltage "
                                             r"limit \[V\].*current_lim = 10.0\) is not allowed: 0 \(HIGH_CURRENT\)"):
        import_drive(text, "odrive", load_preset(BASE))
    with pytest.raises(ParameterError, match=r"motor_type = 3 \(ACIM: an induction motor"):
        import_drive(ODRIVE.replace('"motor_type": 0', '"motor_type": 3'), "odrive", load_preset(BASE))


def test_fw_06_odrive_backup_is_refused_by_its_layout():
    text = json.dumps({"axis0": {"config": {"motor": {"motor_type": 0, "pole_pairs": 7, "torque_constant": 0.0306,
                                                      "current_soft_max": 40.0}}}})
    with pytest.raises(ParameterError, match=r"fw 0.6.x layout axis0.config.motor.… \(axis0.config.motor.motor_type\)"
                                             r": allowed fw 0.5.x"):
        import_drive(text, "odrive", load_preset(BASE))


def test_odrive_encoder_cpr_both_ways():
    """The D5065 backup's 8192-count encoder becomes sensors.encoder_cpr; an export carries the preset's cpr."""
    res = import_drive(ODRIVE, "odrive", load_preset(BASE))
    assert res.params.sensors.encoder_cpr == 8192 and res.kept == ()
    assert not {"axis0.encoder.config.cpr", "axis0.motor.config.motor_type"} & set(res.not_imported)
    cmp = case(load_preset("yaskawa_sgm7j_04a"), "odrive")
    assert stock_settings(cmp, "odrive").encoder_cpr == 2**24
    text = _text("odrive", cmp)
    data = json.loads(text)
    assert data["axis0"]["encoder"]["config"]["cpr"] == 2**24
    assert data["axis0"]["motor"]["config"]["motor_type"] == 0
    back = import_drive(text, "odrive", load_preset(BASE))
    assert back.params.sensors.encoder_cpr == 2**24


@pytest.mark.parametrize("version", ["1", "0", "5", "x"])
def test_vesc_config_version_outside_the_read_ones_is_refused_by_name(version):
    """ConfigVersion 1 (or none) may hold R and L as 2/3 of the phase values (fw ≤ 5.02): refused, not misread."""
    text = VESC.replace("<ConfigVersion>2</ConfigVersion>", f"<ConfigVersion>{version}</ConfigVersion>")
    with pytest.raises(ParameterError, match=rf"<ConfigVersion> = '{version}' is not allowed .*allowed 2, 3, 4"):
        import_drive(text, "vesc", load_preset(BASE))
    if version == "1":
        with pytest.raises(ParameterError, match=r"stored as 2/3 of the phase values"):
            vesc.parse_vesc(text)


def test_vesc_current_versions_read_and_the_export_writes_vesc_tool_s():
    for version in ("2", "3", "4"):
        text = VESC.replace("<ConfigVersion>2</ConfigVersion>", f"<ConfigVersion>{version}</ConfigVersion>")
        assert import_drive(text, "vesc", load_preset(BASE)).params.motor.R_s == 0.02733
    assert vesc.CONFIG_VERSION == 4
    cmp = case(load_preset("yaskawa_sgm7j_04a"), "vesc")
    xml = _text("vesc", cmp)
    assert "<ConfigVersion>4</ConfigVersion>" in xml
    assert odrive.MOTOR_TYPE_HIGH_CURRENT == 0
