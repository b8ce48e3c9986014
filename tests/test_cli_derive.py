"""``pmsm-commission derive``: JSON contract, human table, and bad input → exit 2 with one line."""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pmsm_commissioning.app.cli.main import main


def test_derive_json_keys_and_values(capsys):
    assert main(["derive", "paper_12kw_pmsm", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("alpha_max", "alpha_max_rule", "observer", "omega_p", "T_a", "T_c", "T_m_min", "g1", "g2",
                "W_fdsmc_eq52_J", "W_conventional_J", "W_min_J", "saving_predicted_pct", "warnings"):
        assert key in out
    assert set(out["observer"]) >= {"q", "K1", "K2", "K3", "K4"}
    assert out["alpha_max"] == pytest.approx(2651.16, abs=0.01)
    assert out["g1"] == pytest.approx(31.36)
    assert isinstance(out["warnings"], list) and out["warnings"]
    # every key the README lists under ``loop``; the paper preset's exact sensors leave K to the loop's margin
    loop = out["loop"]
    assert set(loop) >= {"K_limit", "K_limit_cruise", "K_limit_slope", "K_recommended", "zeta_slope",
                         "zeta_slope_recommended", "T_c_min", "K_noise", "noise_limited"}
    assert loop["noise_limited"] is False
    assert loop["K_recommended"] == pytest.approx(loop["K_limit"] / loop["margin"])


def test_derive_table(capsys):
    assert main(["derive", "paper_12kw_pmsm", "--set", "manoeuvre.T_m=1.4"]) == 0
    out = capsys.readouterr().out
    assert "eq. (60)" in out and "ω_p" in out and "Warnings:" in out


def test_bad_input_exit_2_single_line_subprocess():
    r = subprocess.run(
        [sys.executable, "-m", "pmsm_commissioning.app", "derive", "paper_12kw_pmsm", "--set", "motor.J_r=-1"],
        capture_output=True, text=True, check=False,
    )
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0
    assert "motor.J_r = -1.0" in r.stderr and "allowed 1e-09 ≤ value ≤ 10000" in r.stderr
    assert "Traceback" not in r.stderr


@settings(max_examples=120, deadline=None)
@given(key=st.text(max_size=20), value=st.text(max_size=20))
def test_random_set_never_tracebacks(key, value):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(["derive", "paper_12kw_pmsm", "--set", f"{key}={value}", "--json"])
        except SystemExit as exc:  # argparse usage errors
            code = exc.code
    assert code in (0, 2)
    if code == 2:
        assert err.getvalue().startswith("error: ") and "Traceback" not in err.getvalue()
    else:
        assert json.loads(out.getvalue())["alpha_max"] > 0


def test_missing_preset(capsys):
    assert main(["derive", "no_such_preset"]) == 2
    assert "not found" in capsys.readouterr().err
