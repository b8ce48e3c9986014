"""The stock route: a stock drive's own loops, simulated from its written file's own numbers, and the gate."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.exports.drives.files import DRIVE_FORMATS
from pmsm_commissioning.app.exports.drives.stock_route import file_loop, file_verdict
from pmsm_commissioning.app.exports.model import export_files
from pmsm_commissioning.app.exports.provenance import ExportRefusedError
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_from_limits, trapezoid_timing
from pmsm_commissioning.control.stock import loops
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.stock.route import simulate_stock

CATALOGUE = Path(__file__).parent / "data" / "catalogue"
#: The shipped real presets and two catalogue motors typed from their vendor files (tests/data/catalogue).
CASES = ("siemens_1ft7044_ak7", "yaskawa_sgm7a_50a", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "odrive_d5065_belt",
         str(CATALOGUE / "mjbots_mj5208_moteus.yaml"), str(CATALOGUE / "vesc_6374.yaml"))
_CASES: dict[str, object] = {}


def _case(name: str):
    if name not in _CASES:
        _CASES[name] = case(load(name, [], mode="position"), "odrive")
    return _CASES[name]


def test_pll_follows_a_ramp_with_no_steady_error():
    """A type-2 loop (kp = 2ω_e, ki = ω_e²): constant speed is tracked with zero speed and position error."""
    T, w_e, w0 = 1.0 / 8000.0, 500.0, 37.0
    th, w = 0.0, 0.0
    for k in range(1, 8000):
        th, w = loops.pll_update(th, w, w0 * k * T, w_e, T, 0.0)
    assert w == pytest.approx(w0, rel=1e-9) and th == pytest.approx(w0 * 7999 * T, abs=1e-9)


def test_current_pi_with_pole_zero_cancellation_is_first_order_at_its_bandwidth():
    """kp = L·ω_c, ki = R·ω_c on L di/dt = u − R·i (exact ZOH step): i(t) = 1 − exp(−ω_c·t) to 2 %."""
    R, L, w_c, T = 0.5, 2e-3, 1000.0, 2e-5
    a = math.exp(-R / L * T)
    i, v = 0.0, 0.0
    worst = 0.0
    for k in range(1, 400):
        _, u, _, v, sat = loops.current_pi(0.0, 1.0, 0.0, i, 0.0, v, L * w_c, R * w_c, math.inf, T)
        i = a * i + (1.0 - a) * u / R
        worst = max(worst, abs(i - (1.0 - math.exp(-w_c * k * T))))
        assert not sat
    assert worst < 0.02


def test_cascade_without_integrator_is_the_pid_of_the_same_gains():
    args = (1.3, 20.0, 400.0, 1.2, 19.0, 0.0)  # θ_ref, ω_ref, α_ref, θ̂, ω̂, integrator
    pos_gain, vel_gain, J = 40.0, 0.05, 3e-4
    c = loops.position_torque(loops.LAW_CASCADE, *args, pos_gain, vel_gain, 0.0, 0.0, math.inf, J, 100.0, 1e-4)
    p = loops.position_torque(loops.LAW_PID, *args, vel_gain * pos_gain, vel_gain, 0.0, 0.0, math.inf, J, 100.0, 1e-4)
    assert c[0] == pytest.approx(p[0], rel=1e-14) and c[0] == pytest.approx(J * 400.0 + 0.05 * (20.0 + 4.0 - 19.0))


@pytest.mark.parametrize("delta, alpha, T_m", [(62.8, 3225.0, 0.5), (31.4, 2400.0, 0.5), (-3.0, 200.0, 0.45)])
def test_planner_from_its_limits_rebuilds_the_move(delta, alpha, T_m):
    tr = trapezoid_timing(delta, alpha, T_m)
    back = trapezoid_from_limits(delta, abs(tr.omega_c), alpha)
    assert back.T_m == pytest.approx(T_m, rel=1e-12) and back.T_a == pytest.approx(tr.T_a, rel=1e-12)
    tri = trapezoid_from_limits(delta, 1e9, alpha)  # never reaches the speed limit: the triangle
    assert tri.T_m == pytest.approx(2.0 * math.sqrt(abs(delta) / alpha), rel=1e-12)


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("fmt", DRIVE_FORMATS)
def test_every_drive_file_passes_its_own_route_without_force(name, fmt):
    """Written without --force; read back by the strict parser, simulated: every check passes."""
    cmp = _case(name)
    p = cmp.derived.params
    ((_, content),) = export_files(fmt, cmp).items()
    text = content.decode()
    loop = file_loop(fmt, text, p)
    run = simulate_stock(p, loop, cmp.derived)
    assert run.metrics.stable and run_checks(p, run) == []
    assert run.metrics.in_position_s is not None and run.metrics.in_position_s < 1.3 * p.manoeuvre.T_m
    assert "verdict: clean — stock route" in text
    if fmt == "odrive":  # what runs is what the file says
        cfg = json.loads(text)["axis0"]["controller"]["config"]
        assert loop.kp == cfg["pos_gain"] and loop.kd == pytest.approx(cfg["vel_gain"] / (2 * math.pi), rel=1e-15)


def test_a_detuned_file_fails_the_gate():
    """pos_gain × 0.2 in a written ODrive file: the route simulated from it fails (lags out of its window)."""
    cmp = _case("odrive_d5065_belt")
    p = cmp.derived.params
    text = export_files("odrive", cmp)["odrive_d5065_belt.odrive.json"].decode()
    data = json.loads(text)
    data["axis0"]["controller"]["config"]["pos_gain"] *= 0.2
    verdict = file_verdict("odrive", json.dumps(data), p, cmp.derived)
    assert not verdict.clean and {"in_position"} & {c.name for c in verdict.failed}


def test_the_stock_route_of_the_paper_case_is_refused_naming_its_checks():
    cmp = case(load("paper_12kw_pmsm", [], mode="position"), "odrive")
    with pytest.raises(ExportRefusedError, match=r"the stock route of 'paper_12kw_pmsm' .* not clean — .*--force"):
        export_files("moteus", cmp)


def test_the_file_runs_the_tuned_route():
    """The 9-digit file and the tuned settings give the same run (the file is the tuning, written)."""
    from pmsm_commissioning.app.exports.drives.stock import stock_settings

    cmp = _case("yaskawa_sgm7j_04a")
    p = cmp.derived.params
    tuned = stock_settings(cmp, "moteus").tuning.run.metrics
    text = export_files("moteus", cmp)["yaskawa_sgm7j_04a.moteus.cfg"].decode()
    run = file_verdict("moteus", text, p, cmp.derived).run.metrics
    assert run.in_position_s == pytest.approx(tuned.in_position_s, abs=2.0 / 15000.0)
    assert run.electrical_in_total_J == pytest.approx(tuned.electrical_in_total_J, rel=1e-5)


def test_stock_energy_balance_closes():
    """Net electrical input = copper + friction + load work + stored kinetic and magnetic energy at the end."""
    cmp = _case("yaskawa_sgm7j_02a")
    m = cmp.stock.metrics
    stored = m.kinetic_end_J + m.magnetic_end_J
    lhs = m.electrical_in_total_J
    rhs = m.copper_total_J + m.friction_total_J + m.load_work_total_J + stored
    assert lhs == pytest.approx(rhs, rel=1e-5, abs=1e-9)
    assert np.all(np.diff(cmp.stock.trace.E_copper) >= -1e-12)


def test_the_tuning_search_stops_at_the_run_budget_and_says_so():
    """A 60 s move at 20 kHz: each setting costs ≈ 0.6 s predicted; the search stops before 3 s of CPU."""
    import dataclasses

    from pmsm_commissioning.app.io.presets import load_preset
    from pmsm_commissioning.control.fdsmc.derivations import derive
    from pmsm_commissioning.sim.common.budget import MAX_CPU_S
    from pmsm_commissioning.sim.fdsmc.grid import predict
    from pmsm_commissioning.sim.stock.route import at_loop_rate
    from pmsm_commissioning.sim.stock.tuning import DRIVES, ROBUST_J_L, tune

    p = load_preset("paper_12kw_pmsm")
    p = dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, T_m=60.0))
    tu = tune(DRIVES["setpoints"], p, derive(p))
    per_setting = (1 + len(ROBUST_J_L)) * predict(at_loop_rate(p, 20000.0)).cpu_s
    assert tu.budget_stop and tu.tried >= 1 and tu.tried * per_setting <= MAX_CPU_S < (tu.tried + 1) * per_setting
