"""Inner-loop overshoot, nameplate consistency and run verdicts for real drives."""

from __future__ import annotations

import dataclasses
import math

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.units import kt_nm_per_arms_to_psi_pm, psi_pm_to_ke_vrms_krpm, psi_pm_to_kt_nm_per_arms
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.feasibility import LIMIT_TOLERANCE, current_limit, exceeds
from pmsm_commissioning.control.fdsmc.nameplate import nameplate_consistency
from pmsm_commissioning.control.fdsmc.transient import acceleration_overshoot
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.verdicts import run_warnings


def _replace(p, section, **kw):
    return dataclasses.replace(p, **{section: dataclasses.replace(getattr(p, section), **kw)})


def test_no_overshoot_when_the_controller_knows_the_whole_inertia(paper_params):
    # J_L = 0 and F_v = 0: the observer has nothing to learn, the FDC acceleration loop of eq. (13)
    # is first order (3/T_sα) and never overshoots: η = 1 exactly (continuous implementation).
    p = _replace(_replace(paper_params, "load", J_L=0.0, F_v=0.0), "controller", f_s="continuous")
    # (the step response is summed numerically: 1.4e-9 of rounding seen, so 1e-8)
    assert acceleration_overshoot(derive(p).loop, None) == pytest.approx(1.0, abs=1e-8)


def test_overshoot_predicts_the_simulated_start_of_acceleration(paper_params):
    # Torque-limit rule, paper drive at 20 kHz: the simulated peak torque is η·α_max·J + F_v·ω(t_peak)
    # + |Γ_Le|, bounded by the rule's η·α_max·J + F_v·ω_p; the linear prediction is within 2 %.
    p = _replace(paper_params, "controller", alpha_max_rule="torque_limit", K=0.3, delay_samples=1)
    p = _replace(p, "manoeuvre", T_m=3.0)
    d = derive(p)
    run = compare(p, derived=d).fdsmc
    inertial = d.alpha.overshoot * d.alpha.alpha_max * p.J_total
    assert inertial <= run.metrics.torque_peak_Nm <= d.feasibility.torque_needed * (1 + LIMIT_TOLERANCE)
    # without friction the peak is the inertial transient alone: the linear η predicts it within 1 %
    p0 = _replace(p, "load", F_v=0.0)
    d0 = derive(p0)
    peak0 = compare(p0, derived=d0).fdsmc.metrics.torque_peak_Nm
    assert peak0 == pytest.approx(d0.alpha.overshoot * d0.alpha.alpha_max * p.J_total, rel=0.01)


def test_kt_ke_psi_round_trip():
    # Kt = (3/2)·√2·p·Ψ_PM [N·m/A_rms] (eq. (5), i_q = √2·I_rms); Ke ↔ Ψ_PM of app.io.units
    assert psi_pm_to_kt_nm_per_arms(kt_nm_per_arms_to_psi_pm(0.544, 5), 5) == pytest.approx(0.544, rel=1e-15)
    psi = kt_nm_per_arms_to_psi_pm(0.544, 5)
    # For a sinusoidal PMSM Kt [N·m/A_rms] = √3·Ke [V/(rad/s)] (LL rms): both routes agree
    ke_si = psi_pm_to_ke_vrms_krpm(psi, 5) / (1000 * math.pi / 30)
    assert pytest.approx(math.sqrt(3) * ke_si, rel=1e-12) == 0.544


def test_nameplate_disagreements_name_both_values(paper_params):
    m = load_preset("siemens_1ft7044_ak7").motor
    assert nameplate_consistency(m, Kt=0.88, T_N=2.0) == ()  # datasheet values agree within 10 %
    # A typing slip: Ke = 300 V/krpm on this motor (Ψ_PM ≈ 0.78 Wb) — back-EMF far above V_0
    slip = dataclasses.replace(m, psi_pm=0.78)
    kinds = {x.quantity: x for x in nameplate_consistency(slip, Kt=0.88)}
    assert "back-EMF" in kinds and "Kt" in kinds
    assert "0.88" in kinds["Kt"].text and "400" in kinds["back-EMF"].text
    # The paper's section-5 nameplate: P_r/ω_b = 12 kW/150 rad/s = 80 N·m > Γ_max = 40 N·m
    paper = {x.quantity: x for x in nameplate_consistency(paper_params.motor)}
    assert paper["peak torque"].value == pytest.approx(80.0) and paper["peak torque"].other == 40.0


def test_limit_tolerance_ignores_differences_below_model_precision():
    assert not exceeds(4.462, 4.46) and exceeds(4.5, 4.46)


def test_torque_limit_caps_the_hard_current_limit(paper_params):
    # The Siemens module's i_max (25.46 A) would give K_t·i_max = 17.0 N·m > Γ_max = 15 N·m: the drive's
    # hard limit is min(i_max, Γ_max/K_t), so neither controller's torque passes Γ_max, and the
    # designed preset runs without a warning.
    p = load_preset("siemens_1ft7044_ak7")
    assert current_limit(p) == pytest.approx(15.0 / (1.5 * 3 * p.motor.psi_pm))
    assert current_limit(p) < p.controller.i_max
    cmp = compare(p)
    assert [w for w in run_warnings(cmp) if not w.startswith("Flux tolerance")] == []  # no limit warning
    for run in (cmp.fdsmc, cmp.conventional):
        assert run.metrics.torque_peak_Nm <= 15.0 * 1.005
        assert run.metrics.i_peak_A <= (current_limit(p) + 3 * p.sensors.reading_noise) * 1.005


def test_saving_from_a_short_move_is_not_presented_as_a_saving(paper_params):
    # A too-slow sloped segment (T_c ≫ T_a) arrives short at T_m: the friction "saving" then compares
    # unequal moves and is flagged, whatever its value.
    p = _replace(load_preset("yaskawa_sgm7j_04a"), "controller", T_c=0.2)
    cmp = compare(p)
    msgs = [w for w in run_warnings(cmp) if w.startswith("Saving not comparable")]
    assert msgs and "FDSMC" in msgs[0]


def test_boundary_layer_wider_than_omega_p_is_said():
    d = derive(load_preset("yaskawa_sgm7j_04a", ["controller.K=0.001"]))
    assert any(w.startswith("Boundary layer ±1/K = ±1000 rad/s") for w in d.warnings)
