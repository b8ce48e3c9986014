"""Linearised loop analysis: K limit, recommended K, sample-rate check — against closed forms
and against the nonlinear simulation.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.loop_analysis import (
    affine_loop,
    gain_limit,
    minimum_sample_rate,
    recommend_K,
    sample_rate_check,
    stability_measure,
)
from pmsm_commissioning.control.fdsmc.loop_model import continuous_loop, discrete_loop, reduce_shift_mode
from pmsm_commissioning.control.fdsmc.transient import step_peak
from pmsm_commissioning.sim.fdsmc.engine import simulate


def _params(*overrides: str):
    return load_preset("paper_12kw_pmsm", list(overrides))


def test_ideal_plant_closed_loop_poles_are_closed_form():
    """J_L = 0, F_v = 0 (model exact): separation principle — the cruise loop has the poles of
    s² + (3/T_sα)·s + (3/T_sα)·α_max·K (eqs. 13, 46 of [1]) plus the observer's four at −q
    (eq. 17).
    """
    d = derive(_params("load.J_L=0", "load.F_v=0", "controller.f_s=continuous"))
    K = 0.5
    ev = np.linalg.eigvals(reduce_shift_mode(continuous_loop(d.loop, "cruise", K)))
    f = 3.0 / d.params.controller.T_salpha
    expected = np.concatenate([np.roots([1.0, f, f * d.alpha.alpha_max * K]), [-d.observer.q] * 4])
    got = np.sort_complex(ev)
    exp = np.sort_complex(expected)
    # the four-fold observer pole is numerically split by ~eps^(1/4): compare with 0.5 %
    assert np.allclose(got, exp, rtol=5e-3, atol=5e-3 * d.observer.q)


def test_paper_K_limit_continuous_near_reported_value():
    """The reported chatter bound is K_limit ≈ 0.9 s/rad for J_L = 4·J_r; this linearisation gives ≈ 0.96."""
    g = recommend_K(derive(_params("controller.f_s=continuous")).loop)
    assert 0.85 < g.K_limit < 1.05
    assert g.K_recommended == pytest.approx(g.K_limit / 2.0)
    assert not g.K_ok and g.margin_of_K < 1e-3  # the paper's K = 1000 is far beyond it


def test_K_limit_shrinks_with_inertia_ratio():
    limits = [gain_limit(derive(_params(f"load.J_L={J}", "controller.f_s=continuous")).loop, "cruise", None)
              for J in (0.0, 0.12, 0.3)]
    assert limits[0] > 10 * limits[1]  # J_L = 0: model exact, only the inner-loop lag limits K
    assert limits[1] > limits[2]


def test_sampled_loop_tends_to_continuous_loop():
    d_c = derive(_params("controller.f_s=continuous"))
    d_f = derive(_params("controller.f_s=1000000"))
    assert gain_limit(d_f.loop, "cruise", 1e6) == pytest.approx(gain_limit(d_c.loop, "cruise", None), rel=0.03)


def test_K_limit_predicts_nonlinear_chatter_onset():
    """Below K_limit the simulated cruise is quiet, 15 % above it the loop chatters."""
    for mode in ("continuous", "20000"):
        g = derive(_params(f"controller.f_s={mode}")).gain
        below = simulate(_params(f"controller.f_s={mode}", f"controller.K={0.85 * g.K_limit}"), "fdsmc")
        above = simulate(_params(f"controller.f_s={mode}", f"controller.K={1.15 * g.K_limit}"), "fdsmc")
        assert not below.metrics.chatter
        assert above.metrics.chatter


def test_sample_rate_limits_with_and_without_delay():
    """Reported: 10 kHz unstable with T_so = 0.2 ms, ≈ 15 kHz needed — the 15 kHz figure is the
    limit with a one-sample computation delay; without delay this discretisation needs ≈ 10.7 kHz.
    """
    d0 = derive(_params())
    assert 10.0e3 < minimum_sample_rate(d0.loop, 0) < 11.5e3
    assert 14.0e3 < minimum_sample_rate(d0.loop, 1) < 16.0e3
    assert not sample_rate_check(derive(_params("controller.f_s=10000")).loop).stable
    assert sample_rate_check(d0.loop).stable
    assert not sample_rate_check(derive(_params("controller.f_s=14000", "controller.delay_samples=1")).loop).stable


def test_sample_rate_check_agrees_with_simulation():
    d = derive(_params())
    f_min = minimum_sample_rate(d.loop, 0)
    slow = simulate(_params(f"controller.f_s={0.93 * f_min}", "controller.K=0.3"), "conventional")
    fast = simulate(_params(f"controller.f_s={1.1 * f_min}", "controller.K=0.3"), "conventional")
    assert slow.metrics.stable is False
    assert fast.metrics.stable is True


def test_faster_observer_needs_faster_sampling():
    a = minimum_sample_rate(derive(_params("controller.T_so=0.0002")).loop, 0)
    b = minimum_sample_rate(derive(_params("controller.T_so=0.0004")).loop, 0)
    assert b < a


def test_stability_measure_sign_convention():
    d = derive(_params())
    assert stability_measure(d.loop, "conventional", 0.0, 20000.0) < 0.0
    assert stability_measure(d.loop, "cruise", 1000.0, 20000.0) > 0.0


def test_derived_carries_verdicts_and_warning():
    d = derive(_params())
    assert d.gain == recommend_K(d.loop, T_dv=d.params.controller.T_dv)  # one construction
    assert d.sample_rate == sample_rate_check(d.loop)
    assert any("Recommended K" in w for w in d.warnings)
    ok = derive(dataclasses.replace(d.params, controller=dataclasses.replace(d.params.controller, K=0.3)))
    assert not any("Boundary-layer gain" in w for w in ok.warnings)


def test_slope_damping_matches_ideal_loop_eigenvalues():
    """ζ of s² + α_max·K·s + α_max·K/T_c (eqs. 41, 46 with the plant θ̈ = u of eq. (15))."""
    from pmsm_commissioning.control.fdsmc.loop_analysis import slope_damping

    for a_max, K, T_c in ((2651.0, 0.3, 0.024), (2651.0, 0.3, 3.8e-4), (100.0, 2.0, 0.05)):
        s = np.roots([1.0, a_max * K, a_max * K / T_c])
        zeta = -s.real.max() / abs(s[0]) if np.iscomplex(s[0]) else None
        z = slope_damping(a_max, K, T_c)
        if zeta is not None:
            assert z == pytest.approx(zeta, rel=1e-9)
        else:  # real roots ⇔ ζ ≥ 1
            assert z >= 1.0


def test_slow_manoeuvre_sloped_segment_needs_larger_T_c():
    """T_m = 60 s: ω_p = α_max·T_a ≈ 1 rad/s, so with T_c = T_a (eq. 59) the sloped segment is
    poorly damped for every K below the limit cycle bound. The analysis still recommends K from
    the cruise limit, warns, and its T_c advice removes the oscillation in the simulation.
    """
    d = derive(_params("manoeuvre.T_m=60"))
    g = d.gain
    assert g.K_limit == g.K_limit_cruise > 0.1  # not "no K helps"
    assert g.zeta_slope_recommended < 0.5
    assert any("Sloped segment" in w and "controller.T_c ≥" in w for w in d.warnings)
    base = ["manoeuvre.T_m=60", f"controller.K={g.K_recommended}"]
    bad = simulate(_params(*base), "fdsmc").metrics
    assert bad.chatter and bad.chatter_phase == "hold"  # limit cycle about θ_dem
    fixed_p = _params(*base, f"controller.T_c={g.T_c_min}")
    assert not any("Sloped segment" in w for w in derive(fixed_p).warnings)
    good = simulate(fixed_p, "fdsmc").metrics
    assert not good.chatter
    assert good.copper_total_J < 1e-2 * bad.copper_total_J
    assert abs(good.theta_error_at_Tm_rad) < 0.02 * 60.0


@pytest.mark.parametrize("f_s", [None, 20000.0])
@pytest.mark.parametrize("law", ["cruise", "slope", "conventional"])
def test_loop_is_affine_in_K(law, f_s):
    """The searches build the loop at K as M0 + K·M1; that is the loop built at K directly."""
    loop = derive(_params()).loop
    M0, M1 = affine_loop(loop, law, f_s, 1)
    for K in (1e-3, 0.3, 40.0, 1e4):
        M = continuous_loop(loop, law, K) if f_s is None else discrete_loop(loop, law, K, f_s, 1)
        M = reduce_shift_mode(M) if law == "cruise" else M
        np.testing.assert_allclose(M0 + K * M1, M, rtol=1e-12, atol=1e-12 * np.max(np.abs(M)))


@pytest.mark.parametrize("n", [1, 777, 4096, 10_001])
def test_step_peak_by_blocks_equals_the_recursion(n):
    """max_k w·z_k from doubling and blocks (4096 rows) equals z_{k+1} = Φ·z_k + γ stepped n times."""
    rng = np.random.default_rng(7)
    Phi = rng.normal(size=(6, 6))
    Phi *= 0.999 / np.max(np.abs(np.linalg.eigvals(Phi)))
    gamma, w = rng.normal(size=6), rng.normal(size=6)
    z, ref = np.zeros(6), -np.inf
    for _ in range(n):
        z = Phi @ z + gamma
        ref = max(ref, float(w @ z))
    assert step_peak(Phi, gamma, w, n) == pytest.approx(ref, rel=1e-10)


def test_an_overlong_step_response_is_refused_naming_the_fields():
    """6·max(T_si, T_sα, T_so)·f_s samples: 10 MHz with T_so = 1 s would be 6e7; refused, not run."""
    p = _params("controller.f_s=1e7", "controller.T_so=1.0")
    with pytest.raises(ValueError, match=r"controller\.f_s = 1e\+07 Hz .* allowed ≤ 4e\+07"):
        derive(p)
