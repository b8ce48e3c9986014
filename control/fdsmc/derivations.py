"""All commissioning derivations for one :class:`~control.fdsmc.params.DriveParams`, in one call.

:func:`derive` is pure: it returns a frozen :class:`Derived` holding every value the drive, the
UI and the CLI need, plus human-readable warnings.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc import loop_analysis, loop_model, noise, transient
from pmsm_commissioning.control.fdsmc.conventional import (
    ConventionalGains,
    conventional_gains,
    friction_energy_conventional,
)
from pmsm_commissioning.control.fdsmc.feasibility import AlphaMax, Feasibility, alpha_max, feasibility
from pmsm_commissioning.control.fdsmc.loop_analysis import (
    GainRecommendation,
    SampleRateCheck,
    loop_warnings,
    recommend_K,
    sample_rate_check,
)
from pmsm_commissioning.control.fdsmc.loop_model import LoopCase, LoopModel
from pmsm_commissioning.control.fdsmc.model import ModelCoefficients, model_coefficients
from pmsm_commissioning.control.fdsmc.nameplate import nameplate_consistency
from pmsm_commissioning.control.fdsmc.observer import DiscreteObserver, ObserverGains, discrete_observer, observer_gains
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import VelocityProfile, friction_energy_eq52, velocity_profile
from pmsm_commissioning.control.fdsmc.transient import acceleration_overshoot


@dataclass(frozen=True)
class EnergyPrediction:
    """Predicted frictional energy of a manoeuvre [J] and the saving [%].

    Attributes
    ----------
    W_fdsmc : float or None  FDSMC profile, eq. (52) in [1] [J]; None if T_m < T_m,min.
    W_conventional : float   Critically damped comparator, F_v·Δθ²·a/4, a = 5.6/T_m [J].
    W_min : float            Absolute lower bound F_v·Δθ²/T_m, eq. (53) [J].
    saving_pct : float or None  100·(1 − W_fdsmc/W_conventional) [%]; None if infeasible.
    bound_pct : float        100·(1 − W_min/W_conventional) = 100·(1 − 4/5.6) [%].
    """

    W_fdsmc: float | None
    W_conventional: float
    W_min: float
    saving_pct: float | None
    bound_pct: float


@dataclass(frozen=True)
class Derived:
    """Every derived quantity of a commissioning case (see the field types for units).

    ``gain`` and ``sample_rate`` are the verdicts of the linearised loop
    (:mod:`control.fdsmc.loop_analysis`) on :attr:`loop`.
    """

    params: DriveParams
    coefficients: ModelCoefficients
    alpha: AlphaMax
    observer: ObserverGains
    observer_discrete: DiscreteObserver | None
    profile: VelocityProfile
    conventional: ConventionalGains
    energy: EnergyPrediction
    feasibility: Feasibility
    warnings: tuple[str, ...]
    gain: GainRecommendation
    sample_rate: SampleRateCheck

    @property
    def loop(self) -> LoopCase:
        """The linearised loop of this case (model, observer and outer laws)."""
        return LoopCase.of_case(LoopModel.of(self.coefficients, self.params, self.observer), self.params,
                                self.alpha.alpha_max, self.profile.T_c, self.conventional.g1, self.conventional.g2)


def predicted_energy(params: DriveParams, profile: VelocityProfile) -> EnergyPrediction:
    """Frictional energies of eq. (52), the conventional comparator and eq. (53) of [1]."""
    F_v, T_m, dth = params.load.F_v, params.manoeuvre.T_m, profile.delta_theta
    w_c = friction_energy_conventional(F_v, dth, T_m)
    w_min = F_v * dth**2 / T_m
    bound = 100.0 * (1.0 - w_min / w_c) if w_c > 0.0 else 0.0
    if not profile.feasible:
        return EnergyPrediction(None, w_c, w_min, None, bound)
    w_f = friction_energy_eq52(F_v, dth, profile.T_a, T_m)
    saving = 100.0 * (1.0 - w_f / w_c) if w_c > 0.0 else 0.0
    return EnergyPrediction(w_f, w_c, w_min, saving, bound)


def derive(params: DriveParams) -> Derived:
    """Derive α_max, observer gains, profile, comparator gains, energies and feasibility.

    Parameters
    ----------
    params : DriveParams

    Returns
    -------
    Derived
    """
    coeff = model_coefficients(params.motor)
    obs = observer_gains(params.controller.T_so, coeff.M)
    ctrl = params.controller
    f_s = None if ctrl.is_continuous else float(ctrl.f_s)
    lm = LoopModel.of(coeff, params, obs)
    eta = acceleration_overshoot(lm, f_s, ctrl.delay_samples)
    alpha = alpha_max(params, eta)
    obs_d = None if ctrl.is_continuous else discrete_observer(obs, coeff.M, float(ctrl.f_s))
    prof = velocity_profile(params.manoeuvre.theta_dem, alpha.alpha_max, params.manoeuvre.T_m, ctrl.T_c)
    feas = feasibility(params, alpha, prof.omega_p)
    conv = conventional_gains(params.manoeuvre.T_m)
    loop = LoopCase.of_case(lm, params, alpha.alpha_max, prof.T_c, conv.g1, conv.g2)
    se = params.sensors
    gain = recommend_K(loop, count=se.encoder_step, i_noise_rms=se.reading_noise, T_dv=ctrl.T_dv)
    rate = sample_rate_check(loop)
    return Derived(
        params=params,
        coefficients=coeff,
        alpha=alpha,
        observer=obs,
        observer_discrete=obs_d,
        profile=prof,
        conventional=conv,
        energy=predicted_energy(params, prof),
        feasibility=feas,
        warnings=(_warnings(params, alpha, prof, feas) + loop_warnings(gain, rate)
                  + _layer_warning(ctrl.K, gain, prof)),
        gain=gain,
        sample_rate=rate,
    )


def clear_caches() -> None:
    """Forget every cached loop verdict and sampled model (benchmarks: what a new drive costs)."""
    for cached in (loop_analysis._gain_limit, loop_analysis._minimum_sample_rate, loop_model._sampled_parts,
                   transient._acceleration_overshoot, noise._noise_gain_limit, noise._alpha_dem_rms):
        cached.cache_clear()


def _layer_warning(K: float, gain: GainRecommendation, prof: VelocityProfile) -> tuple[str, ...]:
    """Warn when the boundary layer |S| < 1/K of eq. (45) in [1] is wider than ω_p: the outer loop never slides.

    Warned only when a K within the chatter limit would slide (K_recommended·ω_p > 1); otherwise the
    linear outer loop is the best this sample rate allows, which the design reports as a note.
    """
    if not prof.feasible or K * prof.omega_p > 1.0 or gain.K_recommended * prof.omega_p <= 1.0:
        return ()
    return (f"Boundary layer ±1/K = ±{1.0 / K:.4g} rad/s is wider than ω_p = {prof.omega_p:.4g} rad/s: the outer "
            f"loop is linear, never sliding, on this manoeuvre. K = {gain.K_recommended:.4g} s/rad (recommended) "
            "would slide.",)


def _warnings(
    params: DriveParams, alpha: AlphaMax, prof: VelocityProfile, feas: Feasibility
) -> tuple[str, ...]:
    w: list[str] = []
    if not prof.feasible:
        w.append(
            f"Infeasible manoeuvre: T_m = {params.manoeuvre.T_m:g} s is shorter than "
            f"T_m,min = {prof.T_m_min:.4g} s for Δθ = {prof.delta_theta:g} rad at "
            f"α_max = {alpha.alpha_max:.5g} rad/s² (eq. 60 has no real root)."
        )
    if not alpha.torque_ok:
        w.append(
            f"α_max = {alpha.alpha_max:.5g} rad/s² ({alpha.rule} rule) needs "
            f"{alpha.torque_needed:.4g} N·m on the total inertia J_r + J_L = "
            f"{params.J_total:.4g} kg·m² (inner-loop overshoot η = {alpha.overshoot:.3g} included), "
            f"more than the drive's {feas.Gamma_max:.4g} N·m: the inverter/motor will saturate during "
            "acceleration (use alpha_max_rule: torque_limit, or Design for this drive)."
        )
    elif not feas.torque_ok:
        w.append(
            f"Peak torque {feas.torque_needed:.4g} N·m (acceleration with the inner-loop overshoot "
            f"η = {alpha.overshoot:.3g}, friction at ω_p and load) exceeds the drive's {feas.Gamma_max:.4g} N·m."
        )
    if not feas.speed_ok:
        w.append(f"Peak speed ω_p = {feas.omega_p:.4g} rad/s exceeds the speed limit {feas.omega_b:g} rad/s "
                 "(limits.omega_max, else ω_b).")
    if not feas.voltage_ok:
        w.append(
            f"Voltage needed at ω_p with the peak torque, {feas.u_needed_peak:.4g} V, exceeds the "
            f"available {feas.u_available:.4g} V (V_dc/√3, or √(2/3)·V_0 without V_dc)."
        )
    w += [f"Nameplate: {x.text}" for x in nameplate_consistency(params.motor)]
    return tuple(w)
