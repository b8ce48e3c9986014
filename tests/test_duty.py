"""Duty cycles: energy per cycle is the sum of the simulated moves plus the dwell holding loss."""

from __future__ import annotations

import json

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.optimum import move_model
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.studies.duty import J_PER_KWH, Move, duty_cycle

PRESET = "siemens_1ft7044_ak7"


def test_cycle_energy_is_the_sum_of_the_moves_and_yearly_figures_follow(tmp_path, capsys):
    f = tmp_path / "cycle.yaml"
    f.write_text("- {theta_dem: 62.83, T_m: 0.6, dwell: 0.2}\n- {theta_dem: 31.4, T_m: 0.5}\n", encoding="utf-8")
    assert main(["dutycycle", PRESET, str(f), "--cycles-per-hour", "1000", "--hours-per-year", "2000",
                 "--price", "0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for c in ("fdsmc", "conventional", "optimum"):
        assert out["cycle_J"][c] == pytest.approx(out["moves_J"][0][c] + out["moves_J"][1][c], rel=1e-12)
        assert out["kWh_per_year"][c] == pytest.approx(out["cycle_J"][c] * 1000 * 2000 / J_PER_KWH)
        assert out["cost_per_year"][c] == pytest.approx(0.3 * out["kWh_per_year"][c])
        assert out["runs"][c]["stable"] and out["runs"][c]["electrical_in_J"] == out["cycle_J"][c]
    assert out["cycle_s"] == pytest.approx(1.3)
    assert out["cycle_J"]["optimum"] <= min(out["cycle_J"]["fdsmc"], out["cycle_J"]["conventional"])


def test_moves_energies_add_up_to_the_runs_closed_energy_balance():
    """Back to back, the moves' energies (differences of the one run's electrical-input integral)
    sum to the run's input, and that input equals copper + friction + load work + the kinetic and
    magnetic energy stored at the end (the balance of the whole continuous run).
    """
    p = load_preset(PRESET, ["load.Gamma_Le=0.5"])
    res = duty_cycle(p, [Move(40.0, 0.6, 0.1), Move(20.0, 0.4, 0.0), Move(-30.0, 0.5, 0.2)])
    for c, run in res.runs.items():
        assert run.stable
        assert sum(run.moves_J) == pytest.approx(run.electrical_in_J, rel=1e-12)
        assert res.cycle_J[c] == run.electrical_in_J
        assert abs(run.balance_residual_J) < 1e-4 * run.electrical_in_J
        assert run.load_work_J == pytest.approx(0.5 * 30.0, rel=1e-2)  # Γ_Le·net Δθ, ≈ at rest at the end


def test_cycle_returning_to_its_start_ends_there():
    res = duty_cycle(load_preset(PRESET), [Move(62.83, 0.6, 0.2), Move(-62.83, 0.6, 0.3)])
    for c, run in res.runs.items():
        assert abs(run.theta_error_end_rad) < 0.005 * 62.83, c  # within 0.5 % of the stroke
        assert abs(run.trace["theta_r"][-1]) < 0.005 * 62.83
        assert run.trace["theta_r"].max() == pytest.approx(62.83, rel=0.02)


def test_one_move_with_the_tail_as_dwell_is_the_single_move_run():
    """A cycle of one move whose dwell is the single-move simulation's tail (0.3·T_m) is that
    simulation: the same kernel steps from rest, the same energy.
    """
    p = load_preset(PRESET, ["manoeuvre.theta_dem=31.4", "manoeuvre.T_m=0.5"])
    single = compare(p, ("fdsmc", "conventional", "optimum"))
    res = duty_cycle(p, [Move(31.4, 0.5, 0.3 * 0.5)])
    for c in ("fdsmc", "conventional", "optimum"):
        assert res.cycle_J[c] == pytest.approx(getattr(single, c).metrics.electrical_in_total_J, rel=1e-9)


def test_back_to_back_differs_from_moves_started_at_rest():
    """Without dwell the second move starts while the first has not settled: its energy differs
    from the same move started from rest (the former independent-move estimate).
    """
    p = load_preset(PRESET)
    b2b = duty_cycle(p, [Move(40.0, 0.5, 0.0), Move(40.0, 0.5, 0.15)])
    alone = duty_cycle(p, [Move(40.0, 0.5, 0.15)])
    assert b2b.moves[1]["conventional"] != pytest.approx(alone.moves[0]["conventional"], rel=1e-3)


def test_dwell_holding_a_load_costs_its_copper_loss():
    """Two more seconds at rest holding Γ_Le = 1 N·m cost a·Γ_Le²·2 s (a = (3/2)·R_s/k_t²)."""
    p = load_preset(PRESET, ["load.Gamma_Le=1.0"])
    short, long_ = duty_cycle(p, [Move(20.0, 0.6, 0.5)]), duty_cycle(p, [Move(20.0, 0.6, 2.5)])
    mm = move_model(p)
    extra = mm.a * 1.0**2 * 2.0
    for c in ("fdsmc", "conventional", "optimum"):
        assert long_.cycle_J[c] - short.cycle_J[c] == pytest.approx(extra, rel=1e-2)


@pytest.mark.parametrize(("text", "match"), [
    ("- {theta_dem: 1.0}\n", "T_m = None"), ("- {theta_dem: 1.0, T_m: -1}\n", "0 < T_m"),
    ("- {theta_dem: 1.0, T_m: 0.5, speed: 2}\n", "theta_dem, T_m and optional dwell"), ("{}\n", "YAML list"),
])
def test_bad_cycle_file_is_refused(tmp_path, capsys, text, match):
    f = tmp_path / "cycle.yaml"
    f.write_text(text, encoding="utf-8")
    assert main(["dutycycle", PRESET, str(f)]) == 2
    assert match in capsys.readouterr().err
