"""The stock route: the trapezoid's formulas and the simulated "stock" run of the engine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.profile import friction_energy_eq52
from pmsm_commissioning.control.fdsmc.trapezoid import (
    trapezoid_omega_square_integral,
    trapezoid_samples,
    trapezoid_timing,
)
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, compare, simulate
from pmsm_commissioning.sim.stock.tuning import DRIVES, tuned

REAL_MOTORS = ("siemens_1ft7044_ak7", "yaskawa_sgm7a_50a", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a",
               "example_log_drive")


def test_trapezoid_moves_the_demand_in_T_m_at_the_given_acceleration():
    tr = trapezoid_timing(-10.0, 50.0, 1.0)
    assert tr.omega_c == pytest.approx(-50.0 * tr.T_a)
    assert abs(tr.omega_c) * (tr.T_m - tr.T_a) == pytest.approx(10.0, rel=1e-12)  # area = |Δθ|
    t = np.linspace(0.0, 1.0, 200001)
    theta, omega, alpha = trapezoid_samples(tr, t)
    assert theta[-1] == pytest.approx(-10.0, abs=1e-12) and omega[-1] == 0.0 and alpha[-1] == 0.0
    assert np.max(np.abs(alpha)) == 50.0 and np.max(np.abs(omega)) == pytest.approx(abs(tr.omega_c))
    assert np.all(np.abs(np.gradient(theta, t) - omega) < 1e-3 * abs(tr.omega_c))  # θ' = ω
    w2 = np.sum((omega[1:] ** 2 + omega[:-1] ** 2) / 2 * np.diff(t))
    assert trapezoid_omega_square_integral(tr) == pytest.approx(w2, rel=1e-8)  # ω_c²(T_m − 4T_a/3)


def test_trapezoid_refuses_a_move_shorter_than_the_triangle():
    with pytest.raises(ParameterError, match=r"manoeuvre.T_m = 0.5 s is too short.*allowed ≥ 0.8944"):
        trapezoid_timing(10.0, 50.0, 0.5)
    with pytest.raises(ParameterError, match="alpha = 0.0 rad/s² is not allowed"):
        trapezoid_timing(10.0, 0.0, 1.0)


@pytest.mark.parametrize("name", REAL_MOTORS)
def test_trapezoid_friction_is_within_a_few_percent_of_the_fdsmc_profile(name):
    """At α_max the trapezoid's ∫ω²dt is below the FDSMC profile's (eq. (52) with F_v = 1).

    A few % on the four servo motors (T_a ≪ T_m), 14 % on the slower example_log_drive move. At the
    torque limit's α_max: the presets' min_energy α makes T_a longer, where the trapezoid's lead grows.
    """
    p = load_preset(name, ["controller.alpha_max_rule=torque_limit"])
    d = derive(p)
    tr = trapezoid_timing(p.manoeuvre.theta_dem, d.alpha.alpha_max, p.manoeuvre.T_m)
    i_fdsmc = friction_energy_eq52(1.0, p.manoeuvre.theta_dem, d.profile.T_a, p.manoeuvre.T_m)
    ratio = trapezoid_omega_square_integral(tr) / i_fdsmc
    assert (0.80 if name == "example_log_drive" else 0.90) < ratio < 1.0


def test_stock_is_the_tuned_setpoint_route():
    assert "stock" in COMPARATORS


@pytest.mark.parametrize("name", ("yaskawa_sgm7j_04a", "example_log_drive"))
def test_simulated_stock_route_arrives_and_balances_its_energy(name):
    p = load_preset(name)
    cmp = compare(p, ("fdsmc", "stock"))
    run = cmp.stock
    assert run is not None and run.controller == "stock" and run.metrics.stable and not run.metrics.chatter
    m = run.metrics
    assert abs(m.theta_error_at_Tm_rad) < 0.02 * abs(p.manoeuvre.theta_dem)  # tracked to the 2 % band
    assert abs(m.energy_balance_residual_J) < 1e-3 * m.motoring_total_J
    d = cmp.derived
    tr = tuned(DRIVES["setpoints"], p, d).trapezoid  # the planner's move at the tuned acceleration
    ideal = p.load.F_v * trapezoid_omega_square_integral(tr)
    assert m.friction_J == pytest.approx(ideal, rel=0.05)  # tracking: friction close to the ideal trapezoid's
    # the speed loop lags the step of α_ref: the speed overshoots the cruise speed at the corner, a little
    assert 0.99 * abs(tr.omega_c) <= m.omega_peak_rad_s <= 1.15 * abs(tr.omega_c)
    assert math.isfinite(m.electrical_in_total_J) and m.electrical_in_total_J > m.friction_total_J
    # the same run through simulate(): deterministic
    again = simulate(p, "stock", d)
    assert again.metrics.electrical_in_total_J == m.electrical_in_total_J
