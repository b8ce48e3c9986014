"""``simulate``, ``table1`` and ``bench`` command lines: JSON contract, CSV, bad input."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest

from pmsm_commissioning.app.cli.main import main

RUN_KEYS = {
    "friction_J", "copper_J", "electrical_in_J", "regenerated_J", "friction_total_J",
    "copper_total_J", "electrical_in_total_J", "kinetic_end_J", "energy_balance_residual_J",
    "t_2pct_first_s", "t_2pct_settle_s", "theta_error_at_Tm_rad", "overshoot_rad",
    "omega_peak_rad_s", "i_q_peak_A", "u_peak_V", "chatter", "stable", "saturated_s", "reason",
}


def _strict(token: str) -> float:
    raise AssertionError(f"{token} is not valid JSON")


def _json(capsys, *argv: str) -> dict:
    """Parse the command's stdout as strict JSON (NaN/Infinity rejected)."""
    assert main(list(argv)) == 0
    return json.loads(capsys.readouterr().out, parse_constant=_strict)


def test_simulate_json_contract(capsys):
    out = _json(capsys, "simulate", "paper_12kw_pmsm", "--set", "controller.K=0.3", "--json")
    assert {"derived", "fdsmc", "conventional", "saving_friction_pct", "saving_electrical_pct"} <= set(out)
    for ctrl in ("fdsmc", "conventional"):
        assert set(out[ctrl]) >= RUN_KEYS
        assert out[ctrl]["stable"] is True and out[ctrl]["chatter"] is False
    assert 24.0 < out["saving_friction_pct"] < 26.5
    assert "loop" in out["derived"] and "sample_rate" in out["derived"]
    # energy over [0, T_m] of the FDSMC is the eq. (52) value within 0.3 %
    assert out["fdsmc"]["friction_J"] == pytest.approx(out["derived"]["W_fdsmc_eq52_J"], rel=3e-3)


def test_simulate_unstable_reports_reason_not_numbers(capsys):
    out = _json(capsys, "simulate", "paper_12kw_pmsm", "--set", "controller.f_s=10000",
                "--controller", "fdsmc", "--json")
    assert out["fdsmc"]["stable"] is False
    assert "too slow" in out["fdsmc"]["reason"]
    assert out["fdsmc"]["friction_J"] is None
    assert "conventional" not in out


def test_simulate_csv_is_the_export_format(tmp_path, capsys):
    """One CSV format: a controller column, one column per signal, units in the header names,
    numbers from the second row on (no units row, so pandas/Excel read typed columns).
    """
    path = tmp_path / "run.csv"
    assert main(["simulate", "paper_12kw_pmsm", "--controller", "fdsmc", "--csv", str(path)]) == 0
    text = capsys.readouterr().out
    assert "chatter" in text  # the paper's K = 1000 is flagged in the summary
    with path.open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:4] == ["controller", "t [s]", "theta_r [rad]", "omega_r [rad/s]"]
    assert rows[1][0] == "fdsmc" and float(rows[1][1]) == 0.0
    assert len(rows) > 1000
    assert float(rows[-1][2]) == pytest.approx(60.0, rel=0.02)


def test_simulate_csv_dash_writes_the_csv_alone_to_stdout(tmp_path, capsys, monkeypatch):
    """``--csv -`` is the usual "stdout": the same CSV as a file gets, no table around it, no file named '-'."""
    monkeypatch.chdir(tmp_path)
    args = ["simulate", "paper_12kw_pmsm", "--controller", "fdsmc"]
    assert main([*args, "--csv", "-"]) == 0
    piped = capsys.readouterr().out
    assert not (tmp_path / "-").exists()
    assert main([*args, "--csv", "run.csv"]) == 0
    capsys.readouterr()
    assert piped == (tmp_path / "run.csv").read_text()
    assert main([*args, "--csv", "-", "--json"]) == 2  # both on stdout: refused, naming the two options
    err = capsys.readouterr().err
    assert "--csv -" in err and "--json" in err


def test_table1_json_rows(capsys):
    out = _json(capsys, "table1", "paper_12kw_pmsm", "--set", "controller.K=0.3", "--tm", "1.0,2.6", "--json")
    rows = out["rows"]
    assert [r["T_m"] for r in rows] == [1.0, 2.6]
    for r in rows:
        assert {"T_m", "friction_fdsmc_J", "friction_conventional_J", "saving_pct", "saving_eq52_pct",
                "bound_pct"} <= set(r)
        assert r["saving_pct"] == pytest.approx(r["saving_eq52_pct"], abs=0.4)
    assert rows[0]["saving_pct"] < rows[1]["saving_pct"]  # rises with T_m (the printed row falls)
    assert rows[0]["paper_pct"] == 27.9 and rows[0]["paper_reversed_pct"] == 25.1


@pytest.mark.parametrize("argv", [
    ["table1", "paper_12kw_pmsm", "--tm", "1.0,abc"],
    ["table1", "paper_12kw_pmsm", "--tm", "0.1"],
    ["simulate", "paper_12kw_pmsm", "--set", "manoeuvre.T_m=0.2"],
    ["simulate", "paper_12kw_pmsm", "--set", "controller.f_s=fast"],
])
def test_bad_input_exits_2_with_one_line(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1 and "Traceback" not in err


def test_bench_prints_figures():
    r = subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "bench", "--smoke"], capture_output=True,
                       text=True, check=False, timeout=120)
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert "samples/s" in out
    # the comparison for a new drive (caches cleared), a new K and a new T_m, each with CPU time
    for case in ("new drive", "new K each run", "new T_m each run"):
        lines = [x for x in out.splitlines() if case in x]
        assert len(lines) == 2 and all("ms CPU" in x and "derive() alone" in x for x in lines)
    # at the preset's own move (T_m = 1 s of Table 1's first column) and at a long one
    assert "comparison T_m = 1 s" in out and "comparison T_m = 2.6 s" in out
