"""The optimum's solver failure: another solver takes over, else the optimum is left out with a note."""

from __future__ import annotations

import dataclasses
import json
import math

import cvxpy as cp
import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.ui.studies import optimum_markdown
from pmsm_commissioning.control.fdsmc.optimum import OptimumSolverError, closed_form, move_model, numerical_optimum
from pmsm_commissioning.sim.fdsmc.engine import compare

#: A drive whose tracked optimum needs the numerical (voltage-limited) solve.
VOLTAGE_LIMITED = ("siemens_1ft7044_ak7", ["controller.V_dc=120"])


def _failing(monkeypatch, failing: set[str]) -> list[str]:
    """Make cvxpy's ``solve`` raise SolverError for the named solvers; return the solvers tried."""
    tried: list[str] = []
    real = cp.Problem.solve

    def solve(self, *args, **kwargs):
        tried.append(kwargs.get("solver"))
        if kwargs.get("solver") in failing:
            raise cp.error.SolverError(f"Solver '{kwargs.get('solver')}' failed. Try another solver.")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(cp.Problem, "solve", solve)
    return tried


def _limited_paper_move():
    p = load_preset("paper_12kw_pmsm", ["manoeuvre.T_m=1.0"])
    free = dataclasses.replace(move_model(p), Gamma_lim=math.inf)
    return dataclasses.replace(free, Gamma_lim=0.5 * closed_form(free).torque_peak)


def test_a_failing_clarabel_falls_back_to_scs_with_the_same_optimum(monkeypatch):
    mm = _limited_paper_move()
    reference = numerical_optimum(mm, 400)
    tried = _failing(monkeypatch, {"CLARABEL"})
    mv = numerical_optimum(mm, 400)
    assert tried == ["CLARABEL", "SCS"] and mv.method == "scs" and reference.method == "clarabel"
    assert mv.torque_peak <= mm.Gamma_lim * (1.0 + 1e-3)
    assert mv.theta[-1] == pytest.approx(mm.delta_theta, rel=1e-6)
    assert mv.energy_J == pytest.approx(reference.energy_J, rel=1e-2)


def test_every_solver_failing_is_one_line_naming_each(monkeypatch):
    _failing(monkeypatch, {"CLARABEL", "SCS"})
    with pytest.raises(OptimumSolverError) as info:
        numerical_optimum(_limited_paper_move(), 400)
    msg = str(info.value)
    assert "\n" not in msg and "CLARABEL" in msg and "SCS" in msg and "manoeuvre.T_m" in msg and len(msg) <= 300
    assert "Try another" not in msg  # cvxpy's own text is not echoed


def test_comparison_omits_a_failed_optimum_with_a_note(monkeypatch):
    _failing(monkeypatch, {"CLARABEL", "SCS"})
    cmp = compare(load_preset(*VOLTAGE_LIMITED), ("fdsmc", "conventional", "optimum"))
    assert cmp.optimum is None and cmp.fdsmc.metrics.stable and cmp.conventional.metrics.stable
    assert len(cmp.notes) == 1 and cmp.notes[0].startswith("Optimum omitted:")
    assert "Optimum omitted" in optimum_markdown(cmp) and "<" not in optimum_markdown(cmp)


def test_simulate_cli_reports_the_omitted_optimum_without_a_traceback(monkeypatch, capsys):
    _failing(monkeypatch, {"CLARABEL", "SCS"})
    name, overrides = VOLTAGE_LIMITED
    assert main(["simulate", name, "--set", overrides[0], "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "optimum" not in out and "saving_vs_optimum_pct" not in out["fdsmc"]
    assert any(n.startswith("Optimum omitted:") for n in out["comparator_notes"])


def test_duty_cycle_omits_a_failed_optimum_with_a_note(monkeypatch, tmp_path, capsys):
    _failing(monkeypatch, {"CLARABEL", "SCS"})
    name, overrides = VOLTAGE_LIMITED
    mv = load_preset(name, overrides).manoeuvre  # the move whose optimum is the numerical (voltage-limited) one
    cycle = tmp_path / "cycle.yaml"
    cycle.write_text(f"- {{theta_dem: {mv.theta_dem!r}, T_m: {mv.T_m!r}, dwell: 0.1}}\n", encoding="utf-8")
    assert main(["dutycycle", name, str(cycle), "--set", overrides[0], "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["cycle_J"]) == {"fdsmc", "conventional"} and out["runs"]["fdsmc"]["stable"]
    assert len(out["notes"]) == 1 and out["notes"][0].startswith("Optimum omitted:") and "\n" not in out["notes"][0]
    assert main(["dutycycle", name, str(cycle), "--set", overrides[0]]) == 0
    assert "Optimum omitted:" in capsys.readouterr().out  # the text output says so too
