"""Duty cycles: energy per cycle is the sum of the simulated moves plus the dwell holding loss."""

from __future__ import annotations

import json

import pytest

from app.cli.main import main
from app.io.presets import load_preset
from control.fdsmc.optimum import move_model
from sim.fdsmc.engine import compare
from sim.studies.duty import J_PER_KWH, Move, duty_cycle

PRESET = "siemens_1ft7044_ak7"


def test_cycle_energy_is_the_sum_of_the_moves_and_yearly_figures_follow(tmp_path, capsys):
    f = tmp_path / "cycle.yaml"
    f.write_text("- {theta_dem: 62.83, T_m: 0.6, dwell: 0.2}\n- {theta_dem: 31.4, T_m: 0.5}\n", encoding="utf-8")
    assert main(["dutycycle", PRESET, str(f), "--cycles-per-hour", "1000", "--hours-per-year", "2000",
                 "--price", "0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    single = compare(load_preset(PRESET, ["manoeuvre.theta_dem=31.4", "manoeuvre.T_m=0.5"]),
                     ("fdsmc", "conventional", "optimum"))
    for c in ("fdsmc", "conventional", "optimum"):
        assert out["moves_J"][1][c] == pytest.approx(getattr(single, c).metrics.electrical_in_total_J)
        assert out["cycle_J"][c] == pytest.approx(out["moves_J"][0][c] + out["moves_J"][1][c])
        assert out["kWh_per_year"][c] == pytest.approx(out["cycle_J"][c] * 1000 * 2000 / J_PER_KWH)
        assert out["cost_per_year"][c] == pytest.approx(0.3 * out["kWh_per_year"][c])
    assert out["cycle_s"] == pytest.approx(1.3)
    assert out["cycle_J"]["optimum"] <= min(out["cycle_J"]["fdsmc"], out["cycle_J"]["conventional"])


def test_dwell_holding_a_load_costs_its_copper_loss():
    p = load_preset(PRESET, ["load.Gamma_Le=1.0"])
    short, long_ = duty_cycle(p, [Move(20.0, 0.6, 0.0)]), duty_cycle(p, [Move(20.0, 0.6, 2.18)])
    mm = move_model(p)
    extra = mm.a * 1.0**2 * (2.18 - 0.3 * 0.6)
    for c in ("fdsmc", "conventional", "optimum"):
        assert long_.cycle_J[c] - short.cycle_J[c] == pytest.approx(extra, rel=1e-9)


@pytest.mark.parametrize(("text", "match"), [
    ("- {theta_dem: 1.0}\n", "T_m = None"), ("- {theta_dem: 1.0, T_m: -1}\n", "T_m > 0"),
    ("- {theta_dem: 1.0, T_m: 0.5, speed: 2}\n", "theta_dem, T_m and optional dwell"), ("{}\n", "YAML list"),
])
def test_bad_cycle_file_is_refused(tmp_path, capsys, text, match):
    f = tmp_path / "cycle.yaml"
    f.write_text(text, encoding="utf-8")
    assert main(["dutycycle", PRESET, str(f)]) == 2
    assert match in capsys.readouterr().err
