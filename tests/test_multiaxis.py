"""Multi-axis moves finish together: common T_m, arrival on every axis, energies, bad files."""

from __future__ import annotations

import json

import pytest

from pmsm_commissioning.app.cli.main import main

AXES = ("- {preset: siemens_1ft7044_ak7, name: X}\n"
        "- {preset: yaskawa_sgm7j_04a, name: Y, set: [manoeuvre.theta_dem=31.4]}\n")


def test_axes_finish_together_within_the_arrival_band(tmp_path, capsys):
    f = tmp_path / "axes.yaml"
    f.write_text(AXES, encoding="utf-8")
    assert main(["multiaxis", str(f), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    x, y = out["axes"]
    # the common time is the slowest axis's shortest feasible time
    assert out["T_m_s"] == max(x["T_m_own_s"], y["T_m_own_s"]) == x["T_m_own_s"]
    assert y["T_m_own_s"] < out["T_m_s"]
    assert out["all_arrived"] and x["arrived"] and y["arrived"]
    # 2 % band of each axis's own θ_dem (62.83 rad and 31.4 rad)
    assert abs(x["theta_error_at_Tm_rad"]) <= 0.02 * 62.832 and abs(y["theta_error_at_Tm_rad"]) <= 0.02 * 31.4
    # the slowest axis runs its own design; the faster one, slowed down, draws less energy
    assert x["energy_common_J"] == x["energy_own_fastest_J"]
    assert y["energy_common_J"] < y["energy_own_fastest_J"]
    assert out["total_energy_common_J"] == pytest.approx(x["energy_common_J"] + y["energy_common_J"])


def test_requested_common_time_is_used_when_longer(tmp_path, capsys):
    f = tmp_path / "axes.yaml"
    f.write_text("- {preset: yaskawa_sgm7j_04a}\n", encoding="utf-8")
    assert main(["multiaxis", str(f), "--T-m", "0.6", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["T_m_s"] == 0.6 and out["axes"][0]["arrived"]


@pytest.mark.parametrize(("text", "match"), [
    ("preset: x\n", "YAML list"), ("- {presets: x}\n", "preset: NAME"),
    ("- {preset: yaskawa_sgm7j_04a, speed: 3}\n", "unknown key"), ("- {preset: yaskawa_sgm7j_04a, set: 3}\n", "'set'"),
])
def test_bad_axis_file_is_refused_with_a_clear_message(tmp_path, capsys, text, match):
    f = tmp_path / "axes.yaml"
    f.write_text(text, encoding="utf-8")
    assert main(["multiaxis", str(f)]) == 2
    assert match in capsys.readouterr().err
