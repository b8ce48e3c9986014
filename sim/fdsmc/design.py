"""Design for this drive: a clean FDSMC setting from the nameplate, the load and the inverter.

:func:`design_drive` chooses α_max, T_m, K and T_c, then **verifies by simulation**: the design is
called clean only when the simulated FDSMC run stays within the drive's torque, current, voltage
and speed limits, arrives at θ_dem by T_m (2 % band) and does not chatter. Otherwise the result
names each constraint that prevents a clean design, with its value, its limit and the remedy.

The choices, each from the drive model rather than a fudge factor:

* α_max: the ``torque_limit`` rule (:func:`control.fdsmc.feasibility.alpha_max`): the largest
  acceleration whose peak torque η·α_max·(J_r + J_L) + F_v·ω_p + |Γ_Le| stays within Γ_max and the
  inverter's i_max, η being the inner loops' overshoot (:mod:`control.fdsmc.transient`).
* T_m: the requested time when feasible (profile of eq. (60) in [1] exists, ω_p ≤ ω_b, voltage
  at ω_p within the inverter's); else the shortest feasible time (bisection, 0.1 %).
* K: K_limit/2 (gain margin 2 below the chatter limit of the sampled loop at the drive's f_s and
  delay, :mod:`control.fdsmc.loop_analysis`), halved while the simulation with the sensors still
  chatters. Not the recommended K, which is also capped for the sensors' noise at the loops as
  given: the design slows the loops for the noise instead, and verifies.
* T_c: T_a (eq. (59)) unless the sloped segment is then poorly damped; then T_c,min.
* T_so, T_sα for the sensors: the standstill ripple the encoder's quantization and the current
  noise cause is predicted in closed form (:func:`control.fdsmc.noise.noise_gain`); where it exceeds
  the user's criterion, the observer and acceleration loop are slowed (the same factor on both)
  until it does not, and the setting is then verified by simulation **with the sensors**.
* T_m stretched by 3 % steps (up to 6) where the verified peak speed or voltage exceeds its limit by
  the inner loops' lag; the design then says it is **not as asked**.

Verdicts: *clean* (every check of :mod:`sim.fdsmc.checks` holds at the requested T_m), *not as
asked* (they hold only at a longer T_m than requested) or *not clean* (the constraints say why).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from control.fdsmc.derivations import Derived, derive
from control.fdsmc.feasibility import alpha_max, feasibility, torque_limit
from control.fdsmc.loop_analysis import ZETA_SLOPE_MIN, slope_damping, unit_damping_T_c
from control.fdsmc.loop_model import LoopModel
from control.fdsmc.model import model_coefficients
from control.fdsmc.noise import NoiseGain, noise_gain
from control.fdsmc.observer import observer_gains
from control.fdsmc.params import DriveParams
from control.fdsmc.profile import shortest_manoeuvre_time, velocity_profile
from control.fdsmc.transient import acceleration_overshoot
from sim.fdsmc.checks import TARGET_BAND, Constraint, run_checks
from sim.fdsmc.criteria import encoder_cpr_for, pass_criteria, window_below_count
from sim.fdsmc.engine import Comparison, RunResult, compare
from sim.fdsmc.verdicts import comparator_notes, flux_warnings

#: Most K halvings while the verified run still chatters [-].
MAX_K_HALVINGS = 4
#: Factors applied to T_so and T_sα when the sensors' ripple exceeds the criterion [-].
SENSOR_SLOWDOWN = (1.0, 1.5, 2.25, 3.4, 5.0, 7.6, 11.4)
#: The predicted ripple a candidate may have, as a fraction of the criterion (the prediction is
#: within ≈ 20 % of the simulation, ``tests/test_sensors.py``) [-].
PREDICTION_MARGIN = 0.8
#: T_m stretch per step and the most steps when the verified speed/voltage peak exceeds its limit.
T_M_STRETCH, MAX_STRETCHES = 1.03, 6
#: T_c raise per step and the most steps when the verified run overshoots θ_dem.
T_C_STEP, MAX_T_C_STEPS = 1.25, 10
#: Checks that slower observer and acceleration loops can mend (the sensors' noise amplified).
SENSOR_CHECKS = frozenset({"hold_ripple", "in_position", "current", "chatter", "saturation"})

__all__ = ["Constraint", "DriveDesign", "TARGET_BAND", "design_drive", "run_checks", "shortest_fitting_T_m"]


@dataclass(frozen=True)
class DriveDesign:
    """A designed setting, its verification run and the constraints that shaped it.

    Attributes
    ----------
    params : DriveParams            The designed inputs (a complete preset).
    derived : Derived               Their derivations.
    comparison : Comparison | None  The verification runs, with the sensors (None when not simulated).
    clean : bool                    True when the FDSMC run passed every check at the requested T_m.
    limiting : tuple of Constraint  Binding and violated constraints.
    notes : tuple of str            Statements that do not make the design unclean.
    comparator : tuple of str       Where the conventional comparator fails the drive's checks.
    as_asked : bool                 False when the requested T_m had to be lengthened.
    noise : NoiseGain or None       Predicted standstill ripple of the designed loop.
    encoder_cpr_needed : int or None  Smallest power-of-two encoder resolution whose quantization
                                    alone keeps the predicted ripple within the criterion [counts/rev].
    """

    params: DriveParams
    derived: Derived
    comparison: Comparison | None
    clean: bool
    limiting: tuple[Constraint, ...]
    notes: tuple[str, ...]
    comparator: tuple[str, ...] = ()
    as_asked: bool = True
    noise: NoiseGain | None = None
    encoder_cpr_needed: int | None = None

    @property
    def refused(self) -> bool:
        """True when the design was refused before any run (nothing designed or simulated)."""
        return self.comparison is None

    @property
    def verdict(self) -> str:
        """``"clean"``, ``"not as asked"`` (clean only at a longer T_m) or ``"not clean"``."""
        if any(c.violated for c in self.limiting):
            return "not clean"
        return "clean" if self.as_asked else "not as asked"


def _with(params: DriveParams, section: str, **changes: object) -> DriveParams:
    return dataclasses.replace(params, **{section: dataclasses.replace(getattr(params, section), **changes)})


def _fits(params: DriveParams, eta: float, T_m: float) -> bool:
    """Profile exists, ω_p within the speed limit and the voltage at ω_p fits, for manoeuvre time ``T_m`` [s]."""
    p = _with(params, "manoeuvre", T_m=T_m)
    a = alpha_max(p, eta)
    if T_m < shortest_manoeuvre_time(p.manoeuvre.theta_dem, a.alpha_max):
        return False
    prof = velocity_profile(p.manoeuvre.theta_dem, a.alpha_max, T_m)
    f = feasibility(p, a, prof.omega_p)
    return f.speed_ok and f.voltage_ok


def shortest_fitting_T_m(params: DriveParams, eta: float) -> float | None:
    """Return the requested T_m if it fits (:func:`_fits`), else the shortest that does [s]; None if none ≤ 1e4 s."""
    lo = params.manoeuvre.T_m
    if _fits(params, eta, lo):
        return lo
    hi = lo
    while not _fits(params, eta, hi):
        hi *= 2.0
        if hi > 1e4:
            return None
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _fits(params, eta, mid) else (mid, hi)
    return _round_up(hi)


def _round_up(x: float, digits: int = 3) -> float:
    """``x`` rounded up to ``digits`` significant digits (a time an engineer can type) [-]."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return float(round(math.ceil(x * scale - 1e-9) / scale, 12))


def _overshoot(params: DriveParams) -> float:
    c = params.controller
    coeff = model_coefficients(params.motor)
    lm = LoopModel.of(coeff, params, observer_gains(c.T_so, coeff.M))
    return acceleration_overshoot(lm, None if c.is_continuous else float(c.f_s), c.delay_samples)


def _gain_and_T_c(params: DriveParams, d: Derived) -> DriveParams:
    """K = K_limit/margin (or 10/ω_p when the loop has no limit); T_c of ζ = 1 at K_limit_cruise/margin if ζ < ζ_min."""
    g = d.gain
    if g is None or g.K_limit <= 0.0:
        return params
    K = g.K_margin if math.isfinite(g.K_limit) else 10.0 / d.profile.omega_p
    a_max, T_c_unit = d.alpha.alpha_max, unit_damping_T_c(d.alpha.alpha_max, g.K_limit_cruise, g.margin)
    T_c: float | str = "T_a"
    if slope_damping(a_max, g.K_margin, d.loop.T_c) < ZETA_SLOPE_MIN and math.isfinite(T_c_unit):
        T_c = max(T_c_unit, d.profile.T_a)
    return _with(params, "controller", K=K, T_c=T_c)


def predicted_noise(p: DriveParams, d: Derived) -> NoiseGain | None:
    """Standstill ripple of ``p``'s FDSMC loop from its sensors (None for a continuous controller)."""
    if d.loop.f_s is None:
        return None
    se = p.sensors
    return noise_gain(d.loop, "slope", p.controller.K, se.encoder_step, se.reading_noise)


def encoder_needed(noise: NoiseGain | None, criterion: float) -> int | None:
    """Smallest power-of-two counts per rev whose quantization alone gives ≤ ``criterion`` [A] of ripple."""
    if noise is None or not math.isfinite(noise.i_q_per_rad) or noise.i_q_per_rad <= 0.0:
        return None
    return encoder_cpr_for(2.0 * math.pi * noise.i_q_per_rad / criterion)


def design_drive(params: DriveParams, alpha_rule: str = "torque_limit") -> DriveDesign:
    """Design α_max, T_m, K, T_c (and T_so, T_sα for the sensors) for ``params``'s drive; verify by simulation.

    Parameters
    ----------
    params : DriveParams
        Nameplate, load, inverter limits, sensors, pass criteria, sample rate and delay,
        T_si/T_sα/T_so and the manoeuvre (θ_dem, requested T_m). K, T_c and the α_max rule are
        replaced by the design; T_so and T_sα are lengthened where the sensors need it.
    alpha_rule : str
        The α_max rule of the design: ``"torque_limit"`` (the fastest profile the torque allows:
        least friction, eqs. (47)–(60) in [1]) or ``"min_energy"`` (the profile's least friction +
        copper, :mod:`control.fdsmc.profile_energy`).

    Returns
    -------
    DriveDesign
    """
    base = _with(params, "controller", alpha_max_rule=alpha_rule, T_c="T_a")
    narrow = window_below_count(params)
    if narrow is not None:  # no setting holds it: say so at once, inputs as they are, not after every slowdown
        crit = pass_criteria(params)
        return _refused(params, [Constraint("in_position", min(crit.in_position, crit.overshoot),
                                          params.sensors.encoder_step, "rad", True, narrow)])
    first: DriveDesign | None = None
    for factor in _slowdowns(base):
        dd = _design_at(_slowed(base, factor), params)
        first = first or dd
        if not dd.refused and not _sensor_limited(dd):
            return dd
    return first if first is not None else _design_at(base, params)


def _slowed(p: DriveParams, factor: float) -> DriveParams:
    c = p.controller
    return _with(p, "controller", T_so=c.T_so * factor, T_salpha=c.T_salpha * factor)


def _slowdowns(p: DriveParams) -> list[float]:
    """Return the slowdown factors to verify: from the first whose predicted ripple meets the criterion on."""
    if p.sensors.ideal or p.controller.is_continuous:
        return [1.0]
    crit = pass_criteria(p).hold_i_rms
    for i, factor in enumerate(SENSOR_SLOWDOWN):
        q = _planned(_slowed(p, factor))
        if q is None:
            continue
        d = derive(q)
        if d.sample_rate is not None and not d.sample_rate.stable:
            continue
        ng = predicted_noise(_gain_and_T_c(q, d), d)
        if ng is not None and ng.i_q_rms <= PREDICTION_MARGIN * crit:
            return list(SENSOR_SLOWDOWN[i:])
    return [SENSOR_SLOWDOWN[-1]]


def _planned(p: DriveParams) -> DriveParams | None:
    """``p`` at the T_m the design uses (the requested one if it fits, else the shortest that does); None if none."""
    eta = _overshoot(p)
    if not math.isfinite(eta):
        return p
    T_m = shortest_fitting_T_m(p, eta)
    return None if T_m is None else _with(p, "manoeuvre", T_m=T_m)


def _sensor_limited(dd: DriveDesign) -> bool:
    return not dd.params.sensors.ideal and any(c.violated and c.name in SENSOR_CHECKS for c in dd.limiting)


def _design_at(p: DriveParams, asked: DriveParams) -> DriveDesign:
    """Choose T_m, check the sample rate, set K and T_c for ``p``'s loops, and verify."""
    limiting: list[Constraint] = []
    planned = _planned(p)
    if planned is None:
        return _refused(p, [Constraint("T_m", asked.manoeuvre.T_m, 1e4, "s", True,
                                       "No manoeuvre time up to 1e4 s fits the speed/voltage limits.")])
    p = planned
    d = derive(p)
    rate = d.sample_rate
    if rate is not None and not rate.stable:
        need = f"f_s ≥ {rate.f_s_min:.4g} Hz" if rate.f_s_min else "a faster controller"
        return _refused(p, limiting + [Constraint(
            "sample_rate", float(rate.f_s or 0.0), float(rate.f_s_min or math.inf), "Hz", True,
            f"f_s = {rate.f_s:g} Hz is too slow for T_so/T_sα (sampled loop unstable, spectral radius "
            f"{rate.spectral_radius:.4f}): use {need}, or longer T_so and T_sα.")])
    p = dataclasses.replace(_gain_and_T_c(p, d), source=_designed_source(asked.source))
    return _verify(p, asked)


def _designed_source(source: str) -> str:
    tag = "design: α_max by its rule, recommended K, verified by simulation with the sensors"
    return source if tag in source else f"{source}; {tag}"


def _refused(p: DriveParams, limiting: list[Constraint]) -> DriveDesign:
    return DriveDesign(p, derive(p), None, False, tuple(limiting), ())


def _simulate(p: DriveParams) -> tuple[DriveParams, Derived, Comparison]:
    """Simulate; halve K while the FDSMC run chatters."""
    for _ in range(MAX_K_HALVINGS + 1):
        d = derive(p)
        cmp = compare(p, derived=d)
        if cmp.fdsmc is None or not cmp.fdsmc.metrics.chatter:
            break
        p = _with(p, "controller", K=p.controller.K / 2.0)
    return p, d, cmp


def _verify(p: DriveParams, asked: DriveParams) -> DriveDesign:
    """Simulate with the sensors and mend what a longer T_m or T_c mends; collect the checks.

    Only speed/voltage failing: T_m stretched (T_M_STRETCH, at most MAX_STRETCHES times). Overshoot
    or the in-position window failing: the sloped segment's T_c scanned upwards from T_a (T_C_STEP,
    at most MAX_T_C_STEPS) — a slower, better damped final approach that the lagging inner loops
    follow — and the first T_c that passes taken (else the one with the fewest violations).
    """
    for _ in range(MAX_STRETCHES + 1):
        p, d, cmp = _simulate(p)
        if cmp.fdsmc is None:  # infeasible after all: derive's warnings say why
            return _refused(p, [Constraint("T_m", p.manoeuvre.T_m, d.profile.T_m_min, "s", True,
                                           "The manoeuvre is infeasible at the designed α_max.")])
        failed = {c.name for c in run_checks(p, cmp.fdsmc)}
        if not failed or not failed <= {"speed", "voltage"}:
            break
        q = _with(p, "manoeuvre", T_m=_round_up(p.manoeuvre.T_m * T_M_STRETCH))
        p = _gain_and_T_c(q, derive(q))
    if failed & {"overshoot", "in_position"}:
        step = T_C_STEP if "overshoot" in failed else 1.0 / T_C_STEP
        p, d, cmp = _scan_T_c(p, (p, d, cmp), len(failed), step)
    return _result(p, d, cmp, asked)


def _scan_T_c(p: DriveParams, best: tuple[DriveParams, Derived, Comparison], n_best: int,
              step: float) -> tuple[DriveParams, Derived, Comparison]:
    """Scan T_c = T_a·step^k (k = 0 …, K = K_limit/margin for each) for the first that passes every check.

    ``step`` > 1 (an overshoot: a slower, better damped approach) or < 1 (too slow to get in position
    within the simulated tail: a faster one). Returns the first clean case, else the one with the
    fewest violations.
    """
    T_a = derive(p).profile.T_a
    for k in range(MAX_T_C_STEPS + 1):
        q, d, cmp = _simulate(_with_T_c(p, T_a * step**k))
        if cmp.fdsmc is None:
            continue
        n = len(run_checks(q, cmp.fdsmc))
        if n < n_best:
            best, n_best = (q, d, cmp), n
        if n == 0:
            break
    return best


def _with_T_c(p: DriveParams, T_c: float) -> DriveParams:
    """``p`` with the sloped segment's T_c [s] and the design's K for it."""
    q = _with(p, "controller", T_c=T_c)
    g = derive(q).gain
    return _with(q, "controller", K=g.K_margin) if g is not None and g.K_limit > 0.0 else q


def _result(p: DriveParams, d: Derived, cmp: Comparison, asked: DriveParams) -> DriveDesign:
    assert cmp.fdsmc is not None
    T_asked, T_m = asked.manoeuvre.T_m, p.manoeuvre.T_m
    limiting = [] if T_m == T_asked else [Constraint(
        "T_m", T_asked, T_m, "s", False, f"Requested T_m = {T_asked:g} s is not feasible with these limits; "
                                         f"the shortest that passes is {T_m:.4g} s (used): not as asked.")]
    limiting += [_torque_binding(p, d, cmp.fdsmc)] + run_checks(p, cmp.fdsmc)
    ng = predicted_noise(p, d)
    crit = pass_criteria(p).hold_i_rms
    need = encoder_needed(ng, crit)
    as_asked = T_m == T_asked
    clean = as_asked and not any(c.violated for c in limiting)
    notes = _notes(d) + _sensor_notes(p, asked, ng, crit, need)
    return DriveDesign(p, d, cmp, clean, tuple(limiting), notes, tuple(comparator_notes(cmp)), as_asked, ng, need)


def _torque_binding(p: DriveParams, d: Derived, run: RunResult) -> Constraint:
    lim = torque_limit(p)
    peak = run.metrics.torque_peak_Nm or 0.0
    a = d.alpha.alpha_max  # derive's α_max: the rule with the inner loops' overshoot η
    why = ("is set by the torque limit" if p.controller.alpha_max_rule == "torque_limit" else
           "minimises the profile's friction + copper loss (rule min_energy) within the torque limit")
    return Constraint("torque", peak, lim, "N·m", False,
                      f"α_max = {a:.5g} rad/s² {why} {lim:.4g} N·m (Γ_max or i_max); simulated peak {peak:.4g} N·m.")


def _sensor_notes(p: DriveParams, asked: DriveParams, ng: NoiseGain | None, crit: float,
                  need: int | None) -> tuple[str, ...]:
    out = []
    c, a = p.controller, asked.controller
    if c.T_so != a.T_so:
        out.append(f"T_so {a.T_so * 1e3:.4g} → {c.T_so * 1e3:.4g} ms and T_sα {a.T_salpha * 1e3:.4g} → "
                   f"{c.T_salpha * 1e3:.4g} ms: slower observer and acceleration loop for the sensors' noise.")
    if ng is not None and math.isfinite(ng.i_q_rms):
        out.append(f"Predicted standstill ripple {ng.i_q_rms:.3g} A rms of i_q, {ng.u_q_rms:.3g} V rms of u_q "
                   f"(criterion {crit:.3g} A)" + (f"; the encoder needs ≥ {need} counts/rev." if need else "."))
    return tuple(out)


def _notes(d: Derived) -> tuple[str, ...]:
    notes: list[str] = []
    K, w_p = d.params.controller.K, d.profile.omega_p
    if w_p <= 1.0 / K:
        notes.append(f"Boundary layer ±1/K = ±{1.0 / K:.4g} rad/s is wider than ω_p = {w_p:.4g} rad/s: the "
                     "outer loop is linear (never sliding) on this manoeuvre; the K limit of the sampled "
                     "loop allows no larger K.")
    return tuple(notes + flux_warnings(d))
