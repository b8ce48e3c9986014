"""Hostile and extreme input at the CLI and the loader: every case answers with exit 2 and one line
naming the field, the value and the allowed range — before any simulation work starts.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import MAX_BYTES, PRESET_DIR, PresetError, load_preset, loads_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.bldc.engine import check_budget as bldc_check_budget
from pmsm_commissioning.sim.bldc.engine import compare_bldc
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.fdsmc import engine, grid

PAPER = (PRESET_DIR / "paper_12kw_pmsm.yaml").read_text(encoding="utf-8")
BLDC = (PRESET_DIR / "bldc_smc_paper.yaml").read_text(encoding="utf-8")


def _fails(argv: list[str], capsys: pytest.CaptureFixture[str], *needles: str) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, err
    return err


@pytest.mark.parametrize(("override", "needles"), [
    ("controller.T_so=1e-200", ("controller.T_so = 1e-200", "allowed 1e-06 ≤ value ≤ 10")),
    ("motor.P_r=1e171", ("motor.P_r = 1e+171", "allowed 0.001 ≤ value ≤ 1e+08")),
    ("motor.J_r=1e-300", ("motor.J_r = 1e-300", "allowed 1e-09 ≤ value")),
    ("manoeuvre.theta_dem=5e-324", ("manoeuvre.theta_dem = 5e-324", "allowed 1e-06 ≤ |value|")),
    ("motor.omega_b=1e300", ("motor.omega_b = 1e+300", "allowed 0 < value ≤ 100000")),
    ("load.F_v=1e300", ("load.F_v = 1e+300", "allowed 0 ≤ value ≤ 10000")),
    ("manoeuvre.T_m=1:30", ("manoeuvre.T_m = '1:30' is not a number", "allowed decimal")),
    ("motor.P_r=0x10", ("motor.P_r = '0x10'", "allowed decimal")),
    ("motor.P_r=1_000", ("motor.P_r = '1_000'", "allowed decimal")),
    ("motor.p=2.5", ("motor.p = '2.5' is not a whole number", "allowed integers")),
    ("manoeuvre.T_m=1e999", ("manoeuvre.T_m = '1e999' is too large",)),
    ("motor.p=" + "9" * 400, ("motor.p = '999", "allowed")),
])
def test_overflow_and_odd_numbers_exit_2(override, needles, capsys):
    _fails(["simulate", "paper_12kw_pmsm", "--set", override], capsys, *needles)


def test_whole_number_fields_take_integers_and_mean_what_they_look_like():
    p = load_preset("paper_12kw_pmsm", ["controller.delay_samples=1.0", "motor.p=017"])
    assert p.controller.delay_samples == 1 and type(p.controller.delay_samples) is int
    assert p.motor.p == 17  # never 15 (YAML 1.1 octal)
    p = load_preset("paper_12kw_pmsm", ["motor.P_r=1.5e3", "controller.f_s=2e4"])
    assert p.motor.P_r == 1500.0 and p.controller.f_s == 20000.0


def test_delay_samples_one_point_zero_simulates():
    p = load_preset("paper_12kw_pmsm", ["controller.delay_samples=1.0", "manoeuvre.T_m=0.5",
                                        "controller.K=0.1"])
    run = engine.simulate(p, "fdsmc")
    assert run.metrics.stable is True


@pytest.mark.parametrize(("edit", "needles"), [
    (("  T_m: 1.0 ", "  T_m: 1:30 "), ("manoeuvre.T_m = '1:30' is not a number",)),
    (("  p: 5 ", "  p: 0x10 "), ("motor.p = '0x10'",)),
    (("schema: 1", "schema: true"), ("schema = 'true' is not supported", "allowed schema: 1")),
    (("  V_0: 430.0 ", "  V_0: 430\n  V_0: 1 "), ("duplicate key 'V_0' at line 9", "first at line 8")),
    (("  P_r: 12000.0 ", "  P_r: 1_000 "), ("motor.P_r = '1_000'",)),
    (("  T_m: 1.0 ", "  T_m: !!float 1 "), ("YAML tag", "not allowed")),
])
def test_yaml_1_1_forms_and_duplicates_refused(edit, needles, tmp_path, capsys):
    old, new = edit
    assert old in PAPER
    path = tmp_path / "case.yaml"
    path.write_text(PAPER.replace(old, new, 1), encoding="utf-8")
    _fails(["derive", str(path)], capsys, *needles)


def test_scientific_forms_both_accepted():
    a = loads_preset(PAPER.replace("  P_r: 12000.0 ", "  P_r: 1.2e4 "))
    b = loads_preset(PAPER.replace("  P_r: 12000.0 ", "  P_r: 12e3 "))
    assert a.motor.P_r == b.motor.P_r == 12000.0


def test_nested_brackets_refused_by_the_pre_scan(tmp_path, capsys):
    path = tmp_path / "d.yaml"
    path.write_text("[" * 10000 + "]" * 10000 + "\n", encoding="utf-8")
    _fails(["derive", str(path)], capsys, "nested too deeply", "allowed ≤ 32")
    with pytest.raises(PresetError, match="nested too deeply"):
        loads_preset("{a: " * 40 + "1" + "}" * 40)


def test_oversized_file_refused_before_reading(tmp_path, capsys):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * (MAX_BYTES + 1))
    _fails(["derive", str(path)], capsys, "too large", "allowed ≤ 256 KiB")


@pytest.mark.parametrize(("argv", "needle"), [
    (["bldc", "paper_12kw_pmsm"], "allowed here a bldc-mode preset"),
    (["derive", "bldc_smc_paper"], "allowed here a position-mode preset"),
    (["simulate", "bldc_smc_paper"], "allowed here a position-mode preset"),
    (["table1", "bldc_smc_paper"], "allowed here a position-mode preset"),
    (["serve", "--preset", "bldc_smc_paper"], "allowed here a position-mode preset"),
    (["derive", "a" * 300], "not found"),
    (["derive", "b" * 2000], "allowed ≤ 1024"),
    (["derive", "../../tmp/x"], "not found"),
])
def test_wrong_mode_and_bad_names(argv, needle, capsys):
    _fails(argv, capsys, needle)


def test_csv_path_checked_before_the_simulation(capsys, monkeypatch):
    def boom(*_a, **_k):
        raise AssertionError("the simulation must not run")

    monkeypatch.setattr("pmsm_commissioning.app.cli.simulate.compare", boom)
    _fails(["simulate", "paper_12kw_pmsm", "--csv", "/nonexistent/x.csv"], capsys, "--csv", "/nonexistent")


def test_substeps_count_in_the_budget_and_are_refused_before_work(monkeypatch, capsys):
    """ω_b = 1e5 rad/s at p = 100 asks for 2500 RK4 sub-steps per sample: over budget, no kernel call."""
    monkeypatch.setattr("pmsm_commissioning.sim.fdsmc.kernel_run.run_kernel",
                        lambda *a: (_ for _ in ()).throw(AssertionError("ran")))
    err = _fails(["simulate", "paper_12kw_pmsm", "--set", "motor.omega_b=1e5", "--set", "motor.p=100"],
                 capsys, "integration steps", "motor.omega_b = 100000 rad/s → largest accepted",
                 "motor.p = 100 → largest accepted")
    p = load_preset("paper_12kw_pmsm", ["motor.omega_b=1e5", "motor.p=100"])
    best = float(err.split("motor.omega_b = 100000 rad/s → largest accepted ")[1].split()[0])
    runs = len(engine.COMPARATORS)  # simulate runs the FDSMC, the conventional law and the optimum
    assert grid.check_budget(dataclasses.replace(p, motor=dataclasses.replace(p.motor, omega_b=best)), runs).fits
    over = dataclasses.replace(p, motor=dataclasses.replace(p.motor, omega_b=best * 1.01))
    with pytest.raises(budget.BudgetError):
        grid.check_budget(over, runs)


def test_budget_counts_every_substep_exactly():
    p = load_preset("paper_12kw_pmsm", ["motor.omega_b=1e4", "motor.p=20"])
    n_sub = grid.plant_substeps(p)
    n_samples = int(-(-1.3 * p.manoeuvre.T_m * 20000 // 1))
    assert n_sub > 1
    assert grid.run_cost(p).steps == n_sub * n_samples


def test_bldc_long_run_refused_before_allocation(monkeypatch):
    """t_end = 100 s at 20 kHz would hold ≈ 3 GB of traces for four drives: refused first."""
    monkeypatch.setattr("numpy.zeros", lambda *a, **k: (_ for _ in ()).throw(AssertionError("allocated")))
    p = loads_preset(BLDC.replace("t_end: 0.7 ", "t_end: 100 "))
    with pytest.raises(budget.BudgetError, match=r"scenario.cases\[0\].t_end = 100 s → largest accepted"):
        compare_bldc(p)
    fast = loads_preset(BLDC.replace("f_s: 20000.0 ", "f_s: 1000000.0 ").replace("t_end: 0.7 ", "t_end: 100 "))
    with pytest.raises(budget.BudgetError, match="inverter.f_s = 1e"):
        bldc_check_budget(fast, 4)


def test_bldc_largest_accepted_t_end_fits():
    p = loads_preset(BLDC.replace("t_end: 0.7 ", "t_end: 100 "))
    with pytest.raises(budget.BudgetError) as exc:
        bldc_check_budget(p, 4)
    best = float(str(exc.value).split("t_end = 100 s → largest accepted ")[1].split()[0])
    ok = loads_preset(BLDC.replace("t_end: 0.7 ", f"t_end: {best} "))
    assert bldc_check_budget(ok, 4).fits


def test_infeasible_message_quotes_the_users_numbers(capsys):
    p = load_preset("paper_12kw_pmsm", ["manoeuvre.theta_dem=37.626", "manoeuvre.T_m=0.2"])
    d = derive(p)
    assert not d.profile.feasible
    with pytest.raises(ParameterError, match=r"manoeuvre.T_m = 0.2 s is infeasible"):
        engine.compare(p)


def test_derive_at_exactly_t_m_min_is_answered_not_raised():
    p = load_preset("paper_12kw_pmsm", ["manoeuvre.theta_dem=37.626"])
    t_min = derive(p).profile.T_m_min
    for T_m in (t_min, t_min * (1 - 1e-15), t_min * (1 + 1e-15)):
        q = dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, T_m=T_m))
        d = derive(q)
        assert d.profile.omega_p > 0.0
        assert d.profile.feasible == (T_m >= d.profile.T_m_min)


def test_rotor_that_never_moves_has_no_saving():
    p = load_preset("paper_12kw_pmsm", ["controller.K=1e-300", "manoeuvre.T_m=0.5"])
    cmp = engine.compare(p)
    assert cmp.fdsmc is not None and cmp.fdsmc.metrics.stable is True
    assert cmp.fdsmc.metrics.t_2pct_first_s is None  # never reached θ_dem
    assert cmp.saving_friction_pct is None and cmp.saving_electrical_pct is None


def test_json_is_strict_json(capsys):
    assert main(["derive", "paper_12kw_pmsm", "--set", "controller.T_so=1e-6", "--json"]) == 0
    out = capsys.readouterr().out
    json.loads(out, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))


def test_subprocess_one_line_exit_2():
    r = subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "bldc", "paper_12kw_pmsm"], capture_output=True,
                       text=True, check=False, cwd=Path(__file__).resolve().parent.parent)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr


LONG = "x" * 5000


@pytest.mark.parametrize("argv", [
    ["derive", "paper_12kw_pmsm", "--set", f"motor.R_s={LONG}"],
    ["derive", "paper_12kw_pmsm", "--set", f"{LONG}=1"],
    ["derive", "paper_12kw_pmsm", "--set", f"motor.{LONG}=1"],
    ["derive", "paper_12kw_pmsm", "--set", "motor.R_s=" + "1" * 5000],
    ["derive", LONG[:1000]],
    ["dutycycle", "paper_12kw_pmsm", "x.yaml", "--price", LONG],
])
def test_every_refusal_is_one_line_of_at_most_300_characters(argv, capsys):
    with pytest.raises(SystemExit) if "--price" in argv else _no_raise() as _:
        code = main(argv)
        assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and len(err.rstrip("\n")) <= 300 and "x" * 81 not in err, err


class _no_raise:  # noqa: N801 - a context manager used like pytest.raises
    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: object) -> bool:
        return False


def test_long_file_key_is_shortened(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(PAPER + f"\n{'k' * 1000}: 1\n", encoding="utf-8")
    err = _fails(["derive", str(path)], capsys, "unknown top-level key")
    assert len(err) <= 301 and "k" * 81 not in err


def test_the_issue_budget_reproduction_is_refused_before_work(capsys):
    err = _fails(["simulate", "yaskawa_sgm7j_02a", "--set", "controller.f_s_kHz=1e4", "--set", "manoeuvre.T_m=1.0"],
                 capsys, "too large", "s CPU", "allowed ≤ 3 s, 256 MiB", "controller.f_s = 1e+07 Hz → largest accepted")
    assert len(err) <= 301


def test_budget_prediction_grows_with_f_s_t_m_and_substeps():
    p = load_preset("yaskawa_sgm7j_02a")
    base = grid.predict(p, 3)
    faster = grid.predict(grid.with_field(p, "controller.f_s", 100 * float(p.controller.f_s)), 3)
    longer = grid.predict(grid.with_field(p, "manoeuvre.T_m", 2 * p.manoeuvre.T_m), 3)
    sub = grid.predict(p, 3, n_sub=8)
    assert faster.cpu_s > 3 * base.cpu_s and faster.memory_bytes > base.memory_bytes
    assert longer.cpu_s > base.cpu_s and sub.cpu_s > base.cpu_s and sub.steps > 2 * base.steps
    assert base.fits and not grid.predict(grid.with_field(p, "controller.f_s", 1e7), 3).fits
