"""The preset's optional ``plant`` section: the plant's true values beside the controller's model."""

from __future__ import annotations

import json
import pathlib

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.plant_overrides import load_model_and_plant
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.presets import (
    PRESET_DIR,
    dumps_preset,
    load_preset,
    load_preset_and_plant,
    loads_preset,
    loads_preset_and_plant,
)
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.studies.robustness import Spread, robustness

DATA = pathlib.Path(__file__).resolve().parent / "data"
MISMATCH = str(DATA / "paper_unknown_load.yaml")  # the paper's drive, plant J_L = 10·J_r, R_s + 20 %


def test_plant_section_gives_the_plant_and_leaves_the_model():
    params, plant = load_preset_and_plant(MISMATCH)
    assert params == load_preset("paper_12kw_pmsm").__class__(**{**params.__dict__})
    assert params.load.J_L == 0.12 and params.motor.R_s == 0.1  # the controller's model: section 5 of [1]
    assert plant.load.J_L == 0.3 and plant.motor.R_s == 0.12
    assert plant.motor.L_q == params.motor.L_q == 0.0054  # 5.4 mH given with its unit suffix
    assert plant.controller == params.controller and plant.manoeuvre == params.manoeuvre


def test_plant_section_round_trips_exactly():
    params, plant = load_preset_and_plant(MISMATCH)
    text = dumps_preset(params, plant)
    again = loads_preset_and_plant(text)
    assert again == (params, plant)
    assert loads_preset_and_plant(dumps_preset(*again)) == again
    assert "plant:" in text and "L_q" not in text.split("plant:")[1]  # only what differs, SI names


def test_set_plant_goes_on_top_of_the_section():
    params, plant = load_model_and_plant(MISMATCH, ["plant.J_L=0.06", "plant.L_d_mH=6", "load.F_v=0.5"])
    assert plant.load.J_L == 0.06 and plant.motor.L_d == pytest.approx(0.006) and plant.motor.R_s == 0.12
    assert params.load.J_L == 0.12 and params.motor.L_d == 0.0054
    # a model override the plant section does not give reaches the plant too
    assert params.load.F_v == plant.load.F_v == 0.5


def test_simulate_uses_the_plant_section():
    """The controller's design is the model's; the heavier plant needs more torque, and the energy
    balance closes with the plant's inertia.
    """
    params, plant = load_preset_and_plant(MISMATCH, ["controller.K=0.3"])
    nominal, mismatch = compare(params), compare(params, plant=plant)
    assert mismatch.derived.alpha.alpha_max == nominal.derived.alpha.alpha_max
    assert mismatch.fdsmc.metrics.torque_peak_Nm > 1.5 * nominal.fdsmc.metrics.torque_peak_Nm
    assert abs(mismatch.fdsmc.metrics.energy_balance_residual_pct) < 0.5


def test_simulate_cli_reads_the_plant_section(capsys):
    assert main(["simulate", MISMATCH, "--set", "controller.K=0.3", "--json"]) == 0
    with_plant = json.loads(capsys.readouterr().out)
    assert main(["simulate", "paper_12kw_pmsm", "--set", "controller.K=0.3", "--json"]) == 0
    without = json.loads(capsys.readouterr().out)
    assert with_plant["fdsmc"]["torque_peak_Nm"] > 1.5 * without["fdsmc"]["torque_peak_Nm"]


def test_robustness_draws_around_the_plant_section():
    """Zero spread on R_s around the plant section's R_s = 0.12 Ω reproduces the plant's run."""
    params, plant = load_preset_and_plant(MISMATCH, ["controller.K=0.3", "manoeuvre.T_m=0.4",
                                                     "manoeuvre.theta_dem=10"])
    res = robustness(params, [Spread("motor", "R_s", "relative", 0.0, 0.0)], 2, seed=1, plant=plant)
    assert list(res.values["motor.R_s"]) == [0.12, 0.12]
    run = compare(params, plant=plant, max_points=2000)
    assert res.runs[0]["fdsmc"]["friction_J"] == run.fdsmc.metrics.friction_J


def _with_plant(block: str) -> str:
    return (DATA / "paper_unknown_load.yaml").read_text(encoding="utf-8").split("plant:")[0] + "plant:\n" + block


@pytest.mark.parametrize(("block", "match"), [
    ("  R_s: -0.1\n", r"plant\.R_s = -0\.1 Ω is out of range: allowed 0 < value ≤ 10000 Ω"),
    ("  J_L: heavy\n", r"plant\.J_L = 'heavy'"),
    ("  K: 3\n", r"unknown key plant\.K"),
    ("  J_L: 0.3\n  J_L_kgcm2: 3000\n", r"more than once"),
    ("  - 1\n", r"plant must be a mapping"),
    ("  p: 2.5\n", r"plant\.p"),
])
def test_bad_plant_values_are_refused_naming_the_field(block, match):
    with pytest.raises((PresetError, ValueError), match=match):
        loads_preset(_with_plant(block), "upload.yaml")


def test_bldc_presets_have_no_plant_section():
    with pytest.raises(PresetError, match="unknown top-level key 'plant'"):
        loads_preset((PRESET_DIR / "bldc_smc_paper.yaml").read_text(encoding="utf-8")
                     + "plant:\n  J: 0.1\n", "bldc.yaml")
