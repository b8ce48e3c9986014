"""The tracked minimum-energy optimum with the FDSMC's terminal slide, and the FDC's flux tolerance.

Closed forms (control/fdsmc/terminal_slide.py, control/fdsmc/flux_tolerance.py) against the
simulator, and the energy figures of the recommended controller on the real presets.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.flux_tolerance import flux_tolerance, stall_speed
from pmsm_commissioning.control.fdsmc.optimum import MoveModel, closed_form, optimal_move
from pmsm_commissioning.control.fdsmc.terminal_slide import reference_on_slope, slide_in_demand
from pmsm_commissioning.control.fdsmc.tracking import slide_stability, slide_time_constant, tracking_gains
from pmsm_commissioning.sim.fdsmc import engine
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.engine import compare, simulate
from pmsm_commissioning.sim.fdsmc.recommend import recommend
from pmsm_commissioning.sim.fdsmc.verdicts import flux_warnings, run_warnings
from pmsm_commissioning.sim.studies.robustness import Spread, plant_for, robustness, sample_metrics, simulate_chunk

REAL = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "yaskawa_sgm7a_50a", "odrive_d5065_belt")


def test_the_reference_reaches_the_slope_once_near_the_end_both_directions():
    T, T_c = 0.6, 0.03
    for dth in (10.0, -10.0):
        mv = closed_form(MoveModel(J=1e-3, F_v=0.0, a=1.0, delta_theta=dth, T_m=T), 20_000)
        on = np.array([reference_on_slope(th, w, dth, 0.0, T_c) for th, w in zip(mv.theta, mv.omega, strict=True)])
        first = int(np.argmax(on))
        assert not on[:first].any() and on[first:].all()  # one switch, then the slide to the end
        # parabola ω = 6Δθ·u(T − u)/T³ meets ω·T_c = θ_dem − θ at 2u² − (3T + 6T_c)·u + 6·T·T_c = 0
        b = 3.0 * T + 6.0 * T_c
        u = (b - math.sqrt(b * b - 48.0 * T * T_c)) / 4.0
        assert T - mv.t[first] == pytest.approx(u, abs=T / 20_000)
        assert u == pytest.approx(2.0 * T_c, rel=0.25)
    assert reference_on_slope(10.0, 0.0, 10.0, 0.0, T_c)  # at rest on θ_dem: the FDSMC law holds it


def test_the_slide_is_the_fdsmc_law_and_the_tracking_before_it():
    fdsmc = (100.0, 20.0, 10.0, 50.0, 0.02, 0.3, 2000.0)  # g1, g2, θ_dem, ω_p, T_c, K, α_max
    # reference far from the slope: α_ref + g1·(θ_ref − θ̂) + g2·(ω_ref − ω̂), S = 0
    u, S = slide_in_demand(1.0, 30.0, 500.0, 0.0, 0.9, 29.0, *fdsmc)
    assert S == 0.0 and u == pytest.approx(500.0 + 100.0 * 0.1 + 20.0 * 1.0)
    # reference past the slope (6 + (9.9 − 10)/0.02 ≥ 0): eq. (46) on the estimates, S of eq. (44)
    u, S = slide_in_demand(9.9, 6.0, -300.0, 0.0, 9.95, 2.0, *fdsmc)
    assert pytest.approx(2.0 - 0.05 / 0.02) == S and u == pytest.approx(-2000.0 * 0.3 * S)


def test_the_slides_copper_equals_the_optimums_tail_to_first_order():
    # ∫α² of the optimum's last u before T_m vs the ideal exponential slide from the same state
    T, dth = 0.6, 60.0
    for T_c in (0.01, 0.03):
        b = 3.0 * T + 6.0 * T_c
        u = (b - math.sqrt(b * b - 48.0 * T * T_c)) / 4.0
        C = 6.0 * dth / T**3
        # α = 6Δθ·(T − 2t)/T³; over its last u: ∫(C·(T − 2s))² ds, s = T − t ∈ [0, u]
        tail = C**2 * (T**2 * u - 2.0 * T * u**2 + 4.0 * u**3 / 3.0)
        omega_s = C * u * (T - u)
        slide = omega_s**2 / (2.0 * T_c)
        assert slide == pytest.approx(tail, rel=3.0 * T_c / T)


@pytest.mark.parametrize("name", REAL)
def test_tracked_optimum_is_clean_recommended_and_within_10pct_of_the_optimum(name):
    p = load_preset(name)
    d = derive(p)
    cmp = compare(p, ("fdsmc", "conventional", "optimum"), derived=d)
    assert run_checks(p, cmp.optimum) == []
    rec = recommend(p, cmp)
    e = {x.controller: x.net_electrical_J for x in rec.energies}
    assert rec.controller == "optimum"
    assert e["optimum"] <= 1.10 * optimal_move(p).energy_J and e["optimum"] < e["conventional"]
    assert slide_stability(d.loop, p.controller.K) < 0.0  # the slide's sampled loop at its T_c and the case's K


def test_tracking_to_the_very_end_overshoots_the_window(monkeypatch):
    # without the slide (the reference tracked to the very end) the observer's lag on J_L
    # carries the rotor past θ_dem, out of a 10-count window: what the terminal slide removes
    p = load_preset("siemens_1ft7044_ak7")
    monkeypatch.setitem(engine.KERNEL_LAW, "optimum", engine.TRACKING_TO_THE_END)
    m = simulate(p, "optimum").metrics
    assert m.overshoot_rad > 3.0 * pass_criteria(p).overshoot


def test_tracking_gains_are_held_to_the_fdsmc_layer():
    for name in REAL:
        d = derive(load_preset(name))
        g = tracking_gains(d.loop, d.conventional, d.params.controller.K)
        layer = d.alpha.alpha_max * d.params.controller.K  # the FDSMC's boundary-layer gain α_max·K
        assert g.a <= layer / 3.0 + 1e-9
        assert slide_time_constant(d.alpha.alpha_max, d.params.controller.K) * layer == pytest.approx(3.5)


def _psi(p, factor):
    return dataclasses.replace(p, motor=dataclasses.replace(p.motor, psi_pm=p.motor.psi_pm * factor))


def _paper_fdc(p):
    return dataclasses.replace(p, controller=dataclasses.replace(p.controller, T_dv=0.0))


def test_fdc_flux_tolerance_predicts_runaway_and_stall():
    p = _paper_fdc(load_preset("siemens_1ft7044_ak7"))  # the paper's FDC, without the mismatch estimate
    d = derive(p)
    x = flux_tolerance(d.coefficients, d.alpha.alpha_max, d.profile.omega_p, p.controller.T_salpha)
    assert 0.03 < x < 0.06
    ok = simulate(p, "fdsmc", d, plant=_psi(p, 1.0 - 0.7 * x)).metrics
    away = simulate(p, "fdsmc", d, plant=_psi(p, 1.0 - 1.3 * x)).metrics
    assert ok.omega_peak_rad_s < 1.2 * d.profile.omega_p  # in control (though not precise: docs/energy.md)
    assert away.omega_peak_rad_s > 3.0 * d.profile.omega_p  # ran away to the voltage limit
    stalled = simulate(p, "fdsmc", d, plant=_psi(p, 1.2)).metrics  # stronger magnets: x = −0.2
    w_stall = stall_speed(d.coefficients, d.alpha.alpha_max, -0.2, p.controller.T_salpha)
    assert stalled.omega_peak_rad_s == pytest.approx(w_stall, rel=0.15)
    warned = [w for w in run_warnings(compare(p, ("fdsmc", "conventional"), derived=d)) if w.startswith("Flux")]
    assert len(warned) == 1 and f"±{100 * x:.2g} %" in warned[0]


def test_robustness_of_the_tracked_optimum_reports_p95_energy_and_chatter():
    # J_L unknown 0…10·J_r, R_s and Ψ_PM ±20 %: the study runs the optimum like the paper's controllers
    p = load_preset("yaskawa_sgm7j_04a")
    spreads = [Spread("load", "J_L", "uniform", 0.0, 10.0 * p.motor.J_r), Spread("motor", "R_s", "relative", -0.2, 0.2),
               Spread("motor", "psi_pm", "relative", -0.2, 0.2)]
    res = robustness(p, spreads, 6, seed=3, controllers=("fdsmc", "optimum"))
    s = res.summary["optimum"]
    assert res.controllers == ("fdsmc", "optimum") and "conventional" not in res.summary
    assert math.isfinite(s["electrical_in_total_J"]["p95"]) and 0.0 <= s["chatter_probability"] <= 1.0
    # the batched study gives exactly the runs one at a time
    d = derive(p)
    rows = [{k: float(v[i]) for k, v in res.values.items()} for i in range(2)]
    one = [sample_metrics(p, plant_for(p, r), d, ("fdsmc", "optimum")) for r in rows]
    assert simulate_chunk(p, rows, d, controllers=("fdsmc", "optimum")) == one


def test_the_voltage_mismatch_estimate_keeps_the_design_clean_off_nameplate_flux():
    # the shipped design (T_dv = 1 ms) passes every check with the motor's flux 10 % off either way, where the
    # paper's FDC (T_dv = 0) ran away or stalled; nominal energy within 1.5 %
    p = load_preset("siemens_1ft7044_ak7")
    assert p.controller.T_dv == pytest.approx(1e-3)
    d, d0 = derive(p), derive(_paper_fdc(p))
    for factor in (0.9, 1.1):
        for ctrl in ("fdsmc", "optimum"):
            assert run_checks(p, simulate(p, ctrl, d, plant=_psi(p, factor))) == []
        assert run_checks(p, simulate(_paper_fdc(p), "fdsmc", d0, plant=_psi(p, factor)))
    assert simulate(p, "fdsmc", d).metrics.electrical_in_total_J == pytest.approx(
        simulate(_paper_fdc(p), "fdsmc", d0).metrics.electrical_in_total_J, rel=0.015)
    assert flux_warnings(d) == [] and flux_warnings(d0)
