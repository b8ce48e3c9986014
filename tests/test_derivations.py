"""Derivations against values computed by hand from the FDSMC paper (section 5, eqs. 4, 18, 52–61)."""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.conventional import conventional_gains, friction_energy_conventional
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.model import model_coefficients
from pmsm_commissioning.control.fdsmc.profile import (
    C_52,
    C_57,
    friction_energy_eq52,
    peak_speed,
    profile_position_change,
    shortest_manoeuvre_time,
    velocity_profile,
)


def test_model_coefficients_paper(paper_params):
    c = model_coefficients(paper_params.motor)
    # H = 3·p·Ψ/(2·J_r) = 3·5·0.38/(2·0.03) = 95 rad/s²/A (eq. 4 coefficients, section-5 motor)
    assert pytest.approx(95.0, rel=1e-12) == c.H
    assert c.K == 0.0  # non-salient: L_d = L_q
    assert pytest.approx(0.1 / 5.4e-3) == c.A
    assert pytest.approx(5 * 0.38 / 5.4e-3) == c.E
    assert pytest.approx(1 / 0.03) == c.M


def test_alpha_max_paper_rule_and_torque(paper_params):
    d = derive(paper_params)
    # α_max = H·P_r/V_0 = 95·12000/430 (section 5)
    assert d.alpha.alpha_max == pytest.approx(2651.16, abs=0.01)
    # torque on the total inertia J_r + 4·J_r = 0.15 kg·m²: 397.67 N·m ≫ Γ_max = 40 N·m, times the
    # inner loops' overshoot η (about 1.2 at 20 kHz, control.fdsmc.transient)
    assert 1.1 < d.alpha.overshoot < 1.4
    assert d.alpha.torque_needed == pytest.approx(397.67 * d.alpha.overshoot, abs=0.01)
    assert not d.alpha.torque_ok
    assert any("40 N·m" in w for w in d.warnings)


def _torque_rule(params, **load):
    return dataclasses.replace(
        params,
        controller=dataclasses.replace(params.controller, alpha_max_rule="torque_limit"),
        load=dataclasses.replace(params.load, **load),
    )


def test_alpha_max_torque_limit_rule_without_friction(paper_params):
    # F_v = 0: the rule reduces to eq. (4b) with the overshoot, α = (Γ_max − |Γ_Le|)/(η·(J_r + J_L))
    d = derive(_torque_rule(paper_params, Gamma_Le=4.0, F_v=0.0))
    assert d.alpha.alpha_max == pytest.approx((40.0 - 4.0) / (d.alpha.overshoot * 0.15), rel=1e-8)
    assert d.alpha.torque_ok
    assert d.alpha.torque_needed == pytest.approx(40.0, rel=1e-8)


def test_alpha_max_torque_limit_rule_leaves_room_for_friction_at_omega_p(paper_params):
    # With friction the peak torque η·α·J + F_v·ω_p(α) + |Γ_Le| of the planned move equals Γ_max
    # (ω_p at T_m,min when the requested T_m is too short for that α, eq. (60)).
    d = derive(_torque_rule(paper_params, Gamma_Le=4.0))
    a, th, T_m = d.alpha.alpha_max, 60.0, 1.0
    t_min = shortest_manoeuvre_time(th, a)
    w_p = peak_speed(th, a, T_m) if T_m > t_min else 2.0 * th / t_min
    peak = d.alpha.overshoot * a * 0.15 + paper_params.load.F_v * w_p + 4.0
    assert peak == pytest.approx(40.0, rel=1e-7)
    assert d.feasibility.torque_ok  # the steady-state check agrees that it fits


def test_torque_limit_includes_inverter_current_limit(paper_params):
    # Γ_lim = min(Γ_max, (3/2)·p·Ψ_PM·i_max) = min(40, 1.5·5·0.38·10) = 28.5 N·m (eq. (5))
    p = _torque_rule(paper_params, F_v=0.0)
    p = dataclasses.replace(p, controller=dataclasses.replace(p.controller, i_max=10.0))
    d = derive(p)
    assert d.alpha.torque_needed == pytest.approx(28.5, rel=1e-8)


def test_observer_gains_eq18(paper_params):
    d = derive(paper_params)
    q = 15 / (2 * 2e-4)
    assert d.observer.q == pytest.approx(37_500.0)
    assert pytest.approx(4 * q) == d.observer.K1
    assert pytest.approx(6 * q**2) == d.observer.K2
    assert pytest.approx(-4 * q**3 * 0.03) == d.observer.K3
    assert pytest.approx(-(q**4) * 0.03) == d.observer.K4


def test_profile_paper_T_m_1s(paper_params):
    d = derive(paper_params)
    assert d.profile.omega_p == pytest.approx(63.93, abs=0.005)  # eq. (60)
    assert d.profile.T_a == pytest.approx(24.11e-3, abs=0.005e-3)  # eq. (58)
    assert d.profile.T_d == pytest.approx(3 * d.profile.T_a)
    assert d.profile.T_c == d.profile.T_a  # eq. (59)
    assert d.profile.feasible


def test_eq54_factor():
    # W_L(T_m/4)/(A/T_m) = 1.5826, eq. (54)
    factor = friction_energy_eq52(1.0, 1.0, 0.25, 1.0)
    assert factor == pytest.approx(1.5826, abs=5e-5)
    assert pytest.approx((19 + 3 * math.exp(-6)) / 6) == C_52


def test_eq52_at_Ta_zero_is_lower_bound():
    # eq. (53): W_L(0) = A/T_m
    assert friction_energy_eq52(0.4, 60.0, 0.0, 2.0) == pytest.approx(0.4 * 3600 / 2.0)


def test_conventional_gains_eq61():
    g = conventional_gains(1.0)
    assert g.g1 == pytest.approx(31.36)
    assert g.g2 == pytest.approx(11.2)
    # the conventional friction energy is 1.4× the lower bound for every T_m (a/4 = 1.4/T_m)
    assert friction_energy_conventional(1.0, 1.0, 2.0) == pytest.approx(1.4 / 2.0)


def test_predicted_saving_below_bound(paper_params):
    e = derive(paper_params).energy
    assert e.bound_pct == pytest.approx(100 * (1 - 4 / 5.6))
    assert 0 < e.saving_pct < e.bound_pct
    assert e.W_min < e.W_fdsmc < e.W_conventional


def test_shortest_manoeuvre_time_is_where_root_vanishes():
    t_min = shortest_manoeuvre_time(60.0, 2651.16)
    assert (2651.16 * t_min) ** 2 == pytest.approx(2 * C_57 * 2651.16 * 60.0)
    peak_speed(60.0, 2651.16, t_min * (1 + 1e-12))  # feasible just above
    with pytest.raises(ParameterError, match="T_m,min"):
        peak_speed(60.0, 2651.16, 0.99 * t_min)


def test_infeasible_T_m_reported(paper_params):
    p = dataclasses.replace(paper_params, manoeuvre=dataclasses.replace(paper_params.manoeuvre, T_m=0.3))
    d = derive(p)
    assert not d.profile.feasible
    assert d.energy.saving_pct is None
    assert any("T_m,min" in w and "0.4804" in w for w in d.warnings)


@settings(max_examples=200, deadline=None)
@given(
    dtheta=st.floats(1e-3, 1e4),
    alpha=st.floats(1.0, 1e5),
    stretch=st.floats(1.0001, 50.0),
)
def test_eq60_gives_back_delta_theta_through_eq49(dtheta, alpha, stretch):
    """Property: ω_p of eq. (60) with T_a = ω_p/α_max, T_d = 3·T_a makes eq. (49) return Δθ."""
    T_m = stretch * shortest_manoeuvre_time(dtheta, alpha)
    prof = velocity_profile(dtheta, alpha, T_m)
    assert profile_position_change(prof.omega_p, prof.T_a, prof.T_d, T_m) == pytest.approx(dtheta, rel=1e-9)
    assert 4 * prof.T_a <= T_m  # a cruise phase of non-negative length exists


def test_feasibility_voltage_and_speed(paper_params):
    f = derive(paper_params).feasibility
    assert f.speed_ok  # 63.9 < 150 rad/s
    assert f.u_available == pytest.approx(430 * math.sqrt(2 / 3))
    # at ω_p with friction only: u_q = R·i_q + p·ω·Ψ (eq. 2 steady state) dominates
    assert f.u_needed_cruise > 5 * f.omega_p * 0.38
    assert f.voltage_ok
