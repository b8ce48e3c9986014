"""Design is solved on the simulated verdict: the binding constraint named, the shortest T_m verified, exit statuses.

The ODrive D5065 on its belt (8192 counts, 8 kHz): with the inverter's current cut to 5 A the move
cannot be made in the requested 0.5 s — the current limit sets T_m,min ≈ 1.03 s (eq. (60) in [1] at
the α_max K_t·i_max allows), which the design must say, never blaming the 8 kHz sample rate; asked
for 0.2 s at 40 A, the shortest T_m it reports must be one whose simulated run passed.
"""

from __future__ import annotations

import json

import pytest

import pmsm_commissioning.sim.fdsmc.design_verify as design_verify
from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.feasibility import alpha_max
from pmsm_commissioning.control.fdsmc.profile import shortest_manoeuvre_time
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.design import EXIT_STATUS, design_drive
from pmsm_commissioning.sim.fdsmc.design_verify import sampled_loop_stable


@pytest.fixture
def stable_only(monkeypatch):
    """Fail the test if any candidate is simulated with an unstable sampled loop; count the simulations."""
    seen = []
    real = design_verify.compare

    def checked(p, *args, **kwargs):
        d = kwargs.get("derived") or derive(p)
        assert sampled_loop_stable(d), f"unstable sampled loop simulated: T_so = {p.controller.T_so}"
        seen.append(p)
        return real(p, *args, **kwargs)

    monkeypatch.setattr(design_verify, "compare", checked)
    return seen


def test_too_little_current_is_diagnosed_as_current_not_sample_rate(stable_only):
    p = load_preset("odrive_d5065_belt", ["controller.i_max=5"])
    dd = design_drive(p)
    names = [c.name for c in dd.limiting]
    assert "sample_rate" not in names and not any("f_s" in c.text for c in dd.limiting)
    current = next(c for c in dd.limiting if c.name == "current")
    a = alpha_max(p, 1.0).alpha_max  # K_t·i_max = 0.153 N·m on J_r + J_L = 5.1e-4 kg·m²
    T_min = shortest_manoeuvre_time(p.manoeuvre.theta_dem, a)
    assert current.limit == pytest.approx(T_min, rel=0.01) and 1.0 < current.limit < 1.1
    assert "T_m,min" in current.text and "current limit" in current.text
    assert dd.verdict == "not as asked" and dd.params.manoeuvre.T_m >= current.limit
    assert run_checks(dd.params, dd.comparison.fdsmc) == []  # verified at the T_m it reports
    assert sampled_loop_stable(dd.derived) and stable_only


def test_reported_shortest_T_m_passed_its_simulation(stable_only):
    p = load_preset("odrive_d5065_belt", ["manoeuvre.T_m=0.2"])
    dd = design_drive(p)
    T = dd.params.manoeuvre.T_m
    t_m = next(c for c in dd.limiting if c.name == "T_m")
    assert t_m.value == 0.2 and t_m.limit == T and f"{T:.4g} s" in t_m.text
    assert dd.verdict == "not as asked" and run_checks(dd.params, dd.comparison.fdsmc) == []
    # the closed form's shortest (current-limited) T_m is named; the simulated search went beyond it
    current = next(c for c in dd.limiting if c.name == "current")
    assert current.limit < T
    assert sampled_loop_stable(dd.derived)


def test_in_position_by_T_m_ends_the_move_early(stable_only):
    p = load_preset("odrive_d5065_belt")  # T_m = 0.5 s: in position only at ≈ 0.6 s with the move ending at 0.5 s
    dd = design_drive(p, "torque_limit", cycle=True)
    assert dd.verdict == "clean", [c.text for c in dd.limiting]
    assert dd.in_position_s is not None and dd.in_position_s <= 0.5
    assert dd.params.manoeuvre.T_m < 0.5 and dd.T_m_asked == 0.5
    assert run_checks(dd.params, dd.comparison.fdsmc) == []
    assert sampled_loop_stable(dd.derived)


def test_design_exit_statuses_and_json_verdict(capsys):
    assert EXIT_STATUS == {"clean": 0, "not as asked": 3, "not clean": 4}
    cases = [(["yaskawa_sgm7j_04a"], "clean"),
             (["odrive_d5065_belt", "--set", "controller.i_max=5", "--objective", "friction"], "not as asked"),
             # ±1 µm window with an 8192-count encoder (a count is 7.7e-4 rad): refused, not clean
             (["yaskawa_sgm7j_04a", "--set", "sensors.encoder_cpr=8192"], "not clean")]
    for args, verdict in cases:
        assert main(["design", *args, "--json"]) == EXIT_STATUS[verdict]
        out = json.loads(capsys.readouterr().out)
        assert out["verdict"] == verdict and out["exit_status"] == EXIT_STATUS[verdict]
        assert "in_position_s" in out and "T_m_asked" in out
    assert main(["design", "yaskawa_sgm7j_04a"]) == 0
    assert "in position at" in capsys.readouterr().out
