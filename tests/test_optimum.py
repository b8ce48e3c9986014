"""The minimum-energy move: closed form vs Hamiltonian vs QP, limits, and the tracked optimum
never drawing more energy than the FDSMC or the conventional controller on the same move.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from scipy.linalg import expm

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.feasibility import LIMIT_TOLERANCE, torque_limit
from pmsm_commissioning.control.fdsmc.optimum import (
    MoveModel,
    closed_form,
    hamiltonian_matrix,
    move_model,
    numerical_optimum,
)
from pmsm_commissioning.sim.fdsmc.engine import compare

PAPER_TM = (1.0, 1.4, 1.8, 2.2, 2.6)  # Table 1 of the FDSMC paper
REAL = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_04a", "yaskawa_sgm7j_02a", "yaskawa_sgm7a_50a")


def _paper_model(T_m: float, **changes: float) -> MoveModel:
    p = load_preset("paper_12kw_pmsm", [f"manoeuvre.T_m={T_m}"])
    return dataclasses.replace(move_model(p), Gamma_lim=math.inf, **changes)


def test_closed_form_meets_the_boundary_conditions():
    cf = closed_form(_paper_model(1.4))
    assert cf.theta[0] == 0.0 and cf.theta[-1] == pytest.approx(60.0, rel=1e-12)
    assert abs(cf.omega[0]) < 1e-9 and abs(cf.omega[-1]) < 1e-9
    # ∫ω dt by the trapezoid rule reaches Δθ as well
    assert np.trapezoid(cf.omega, cf.t) == pytest.approx(60.0, rel=1e-5)


def test_closed_form_equals_the_hamiltonian_two_point_solution():
    """Where e^(M·T) is well conditioned, shooting with the Hamiltonian's matrix exponential gives
    the same ω(t) and Γ(t) = −λ2/(2·a·J) as the stable closed form.
    """
    mm = MoveModel(J=1.0, F_v=0.5, a=0.2, delta_theta=2.0, T_m=1.5)
    cf = closed_form(mm, 300)
    M = hamiltonian_matrix(mm)
    lam = np.linalg.solve(expm(M * mm.T_m)[:2, 2:], [mm.delta_theta, 0.0])
    z = np.array([expm(M * t) @ np.r_[0.0, 0.0, lam] for t in cf.t])
    np.testing.assert_allclose(z[:, 1], cf.omega, atol=1e-9)
    np.testing.assert_allclose(-z[:, 3] / (2.0 * mm.a * mm.J), cf.Gamma_em, atol=1e-9)


def test_frictionless_limit_is_the_parabola():
    """F_v = 0: ω = 6·Δθ·t·(T − t)/T³ and W = 12·a·J²·Δθ²/T³."""
    mm = MoveModel(J=0.2, F_v=0.0, a=0.05, delta_theta=3.0, T_m=0.8)
    cf = closed_form(mm)
    assert cf.energy_J == pytest.approx(12.0 * 0.05 * 0.2**2 * 9.0 / 0.8**3, rel=1e-12)
    assert float(np.max(cf.omega)) == pytest.approx(1.5 * 3.0 / 0.8, rel=1e-6)


@pytest.mark.parametrize("T_m", PAPER_TM)
def test_qp_matches_closed_form_where_no_limit_is_active(T_m):
    mm = _paper_model(T_m)
    cf, qp = closed_form(mm), numerical_optimum(mm)
    assert qp.energy_J == pytest.approx(cf.energy_J, rel=1e-3)
    assert qp.friction_J == pytest.approx(cf.friction_J, rel=1e-3)
    assert qp.theta[-1] == pytest.approx(60.0, rel=1e-6)


def test_constant_load_torque_keeps_the_trajectory_and_adds_its_closed_form_cost():
    base = _paper_model(1.8)
    loaded = dataclasses.replace(base, Gamma_Le=5.0)
    cf0, cf, qp = closed_form(base), closed_form(loaded), numerical_optimum(loaded)
    np.testing.assert_allclose(cf.omega, cf0.omega)
    assert cf.load_J == pytest.approx(5.0 * 60.0)
    assert qp.energy_J == pytest.approx(cf.energy_J, rel=1e-3)


def test_qp_respects_an_active_torque_limit_and_costs_more():
    free = _paper_model(1.0)
    cf = closed_form(free)
    lim = 0.5 * cf.torque_peak
    qp = numerical_optimum(dataclasses.replace(free, Gamma_lim=lim))
    assert qp.limited and qp.torque_peak <= lim * (1.0 + 1e-6)
    assert qp.theta[-1] == pytest.approx(60.0, rel=1e-6)
    assert abs(qp.omega[-1]) < 1e-9
    assert qp.energy_J > cf.energy_J


def test_qp_refuses_an_unreachable_move_naming_the_limit():
    with pytest.raises(ValueError, match="torque limit"):
        numerical_optimum(dataclasses.replace(_paper_model(1.0), Gamma_lim=5.0))


def _check_tracked(name: str, overrides: list[str]) -> None:
    p = load_preset(name, overrides)
    cmp = compare(p, ("fdsmc", "conventional", "optimum"))
    opt = cmp.optimum.metrics
    assert opt.stable and not opt.chatter
    for run in (cmp.fdsmc, cmp.conventional):
        assert run.metrics.stable
        assert opt.electrical_in_total_J <= run.metrics.electrical_in_total_J
        assert opt.copper_total_J + opt.friction_total_J <= (
            run.metrics.copper_total_J + run.metrics.friction_total_J)
    lim = max(torque_limit(p), cmp.derived.feasibility.torque_needed)
    assert opt.torque_peak_Nm <= lim * (1.0 + LIMIT_TOLERANCE)
    assert abs(opt.theta_error_at_Tm_rad) < 0.01 * p.manoeuvre.theta_dem


@pytest.mark.parametrize("name", REAL)
def test_tracked_optimum_never_draws_more_than_either_controller_real_motors(name):
    _check_tracked(name, [])


def test_tracked_optimum_paper_drive_and_energy_achieved():
    """Table 1's longest move: the simulated optimum draws within 2 % of the planned optimum."""
    _check_tracked("paper_12kw_pmsm", ["manoeuvre.T_m=2.6", "controller.K=0.3"])
    p = load_preset("paper_12kw_pmsm", ["manoeuvre.T_m=2.6", "controller.K=0.3"])
    planned = closed_form(move_model(p)).energy_J
    run = compare(p, ("optimum",)).optimum
    assert run.metrics.electrical_in_total_J == pytest.approx(planned, rel=0.02)


def test_simulate_json_has_optimum_and_gap(capsys):
    assert main(["simulate", "siemens_1ft7044_ak7", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    keys = {"friction_J", "copper_J", "electrical_in_J", "torque_peak_Nm", "theta_error_at_Tm_rad"}
    assert keys <= set(out["optimum"]) and keys <= set(out["fdsmc"])
    for ctrl in ("fdsmc", "conventional"):
        w, w_opt = out[ctrl]["electrical_in_total_J"], out["optimum"]["electrical_in_total_J"]
        assert out[ctrl]["saving_vs_optimum_pct"] == pytest.approx(100.0 * (1.0 - w_opt / w))
        assert out[ctrl]["saving_vs_optimum_pct"] >= 0.0


def _exact_voltage_peak(mm, mv) -> float:
    """max |u_dq| [V] at i_d = 0, eqs. (1)–(2) of the FDSMC paper in the steady state of each interval
    (u_d = −p·ω·L_q·i_q, u_q = R_s·i_q + p·Ψ_PM·ω), with the speed at both ends of each interval.
    """
    i_q = mv.Gamma_em[:-1] / (1.5 * mm.p * mm.psi_pm)
    peaks = []
    for w in (mv.omega[:-1], mv.omega[1:]):
        peaks.append(np.max(np.hypot(mm.p * w * mm.L_q * i_q, mm.R_s * i_q + mm.p * mm.psi_pm * w)))
    return float(max(peaks))


def test_voltage_limit_binds_and_is_respected():
    """Siemens servo with a 95 V DC link (u_max = 54.8 V): the unconstrained optimum needs 69 V
    (its back-EMF alone reaches 69 V at the peak speed); the voltage-limited optimum stays within
    u_max, still arrives, and costs more.
    """
    from pmsm_commissioning.control.fdsmc.optimum import optimal_move, voltage_peak

    p = load_preset("siemens_1ft7044_ak7", ["controller.V_dc=95"])
    mm = move_model(p)
    assert mm.u_max == pytest.approx(95.0 / math.sqrt(3.0))
    cf = closed_form(mm, 400)
    assert _exact_voltage_peak(mm, cf) > 1.2 * mm.u_max
    mv = optimal_move(p, n=400)
    assert mv.method == "clarabel" and mv.limited  # the first of SOLVERS
    assert _exact_voltage_peak(mm, mv) <= mm.u_max * (1.0 + 1e-6)
    assert _exact_voltage_peak(mm, mv) >= mm.u_max * (1.0 - 1e-4)  # it binds
    assert voltage_peak(mm, mv) == pytest.approx(_exact_voltage_peak(mm, mv), rel=1e-12)
    assert mv.theta[-1] == pytest.approx(mm.delta_theta, rel=1e-6) and abs(mv.omega[-1]) < 1e-12
    assert mv.energy_J > 1.1 * cf.energy_J


def test_voltage_cone_that_does_not_bind_changes_nothing():
    """With u_max 20 % above what the unconstrained optimum needs, the cone is in the problem but
    inactive: the same energy and trajectory as the problem without it; and a drive whose DC link
    never binds gets the closed form, exactly as without a DC link.
    """
    from pmsm_commissioning.control.fdsmc.optimum import _problem, _solve, optimal_move, voltage_peak

    free = dataclasses.replace(move_model(load_preset("siemens_1ft7044_ak7")), u_max=math.inf)
    ref = numerical_optimum(free, 400)
    mm = dataclasses.replace(free, u_max=1.2 * voltage_peak(free, ref))
    problem = _problem(mm, 400, True)
    problem[3].value = mm.p * mm.L_q * ref.omega / mm.u_max * problem[4] / mm.k_t
    with_cone = _solve(mm, 400, problem)
    assert with_cone.energy_J == pytest.approx(ref.energy_J, rel=1e-6)
    np.testing.assert_allclose(with_cone.omega, ref.omega, atol=1e-5 * float(np.max(ref.omega)))
    a = optimal_move(load_preset("siemens_1ft7044_ak7"))  # V_dc = 540 V in the preset
    b = optimal_move(load_preset("siemens_1ft7044_ak7", ["controller.V_dc=0"]))
    assert a.method == b.method == "closed form" and a.energy_J == b.energy_J


def test_voltage_limit_below_the_back_emf_is_refused_naming_v_dc():
    """Δθ/T_m needs at least p·Ψ_PM·Δθ/T_m of back-EMF: below it no move exists."""
    p = load_preset("siemens_1ft7044_ak7", ["controller.V_dc=40"])
    mm = move_model(p)
    assert mm.p * mm.psi_pm * mm.delta_theta / mm.T_m > mm.u_max
    with pytest.raises(ParameterError, match=r"V_dc"):
        numerical_optimum(mm, 200)
