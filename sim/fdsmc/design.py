"""Design for this drive: a clean FDSMC setting from the nameplate, the load and the inverter.

:func:`design_drive` chooses α_max, T_m, K and T_c (and T_so, T_sα for the sensors), then
**verifies by simulation** with the sensors: the design is called clean only when the simulated
FDSMC run stays within the drive's torque, current, voltage and speed limits, arrives at θ_dem by
T_m (2 % band), settles in the in-position window without overshoot, holds with little ripple and
does not chatter (:mod:`sim.fdsmc.checks`). Otherwise the result names the constraint that binds,
with its figure (:mod:`sim.fdsmc.diagnosis`), and offers verified alternatives.

The choices, each from the drive model rather than a fudge factor:

* α_max: the ``torque_limit`` rule (:func:`control.fdsmc.feasibility.alpha_max`): the largest
  acceleration whose peak torque η·α_max·(J_r + J_L) + F_v·ω_p + |Γ_Le| stays within Γ_max and the
  inverter's i_max, η being the inner loops' overshoot (:mod:`control.fdsmc.transient`); or
  ``min_energy``.
* T_so, T_sα for the sensors: the standstill ripple the encoder's quantization and the current
  noise cause is predicted in closed form (:func:`control.fdsmc.noise.noise_gain`); where it exceeds
  the user's criterion the observer and acceleration loop are slowed (the same factor on both).
  Only factors whose **sampled loop is stable** are candidates
  (:func:`sim.fdsmc.design_verify.sampled_loop_stable`); an unstable one is never simulated or offered.
* T_m: **searched on the simulated verdict** (:mod:`sim.fdsmc.design_search`): from the closed-form
  T_m (the requested one when the profile of eq. (60) in [1] exists and its speed and voltage fit,
  else the shortest that does), bracketed upwards and bisected until the verified run passes. The
  T_m reported is always one whose simulated run passed.
* K: K_limit/2 (gain margin 2 below the chatter limit of the sampled loop), halved while the
  simulation with the sensors still chatters. T_c: T_a (eq. (59)) unless the sloped segment is then
  poorly damped (then T_c,min); scanned where the run overshoots or misses the window.
* Objective "in position by T_m" (``cycle=True``): the requested T_m is when the axis must be in
  position; the move ends early enough that the verified run is (:func:`~sim.fdsmc.design_search.in_position_by`).

Verdicts: *clean* (every check holds as asked), *not as asked* (they hold only at a longer T_m, or
in position later than asked) or *not clean* (the diagnosis says why, with verified alternatives).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses

from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.checks import TARGET_BAND, Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria, window_below_count
from pmsm_commissioning.sim.fdsmc.design_result import (
    EXIT_STATUS,
    Alternative,
    DriveDesign,
    encoder_needed,
    predicted_noise,
    refused,
    with_field,
)
from pmsm_commissioning.sim.fdsmc.design_search import in_position_by, passes, shortest_clean
from pmsm_commissioning.sim.fdsmc.design_verify import (
    gain_and_T_c,
    planned,
    sampled_loop_stable,
    shortest_fitting_T_m,
    unstable_rate,
)
from pmsm_commissioning.sim.fdsmc.diagnosis import (
    T_m_constraint,
    alternatives,
    closed_form_binding,
    sensors_binding,
    simulated_binding,
)
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.verdicts import comparator_notes

#: Factors applied to T_so and T_sα when the sensors' ripple exceeds the criterion [-].
SENSOR_SLOWDOWN = (1.0, 1.5, 2.25, 3.4, 5.0, 7.6, 11.4)
#: The predicted ripple a candidate may have, as a fraction of the criterion (the prediction is
#: within ≈ 20 % of the simulation, ``tests/test_sensors.py``) [-].
PREDICTION_MARGIN = 0.8
#: Stable slowdowns verified when none is predicted to meet the ripple criterion (the quietest) [-].
QUIETEST = 2

__all__ = ["Alternative", "Constraint", "DriveDesign", "EXIT_STATUS", "TARGET_BAND", "design_drive",
           "encoder_needed", "predicted_noise", "run_checks", "shortest_fitting_T_m"]


def design_drive(params: DriveParams, alpha_rule: str = "torque_limit", cycle: bool = False,
                 offer: bool = True) -> DriveDesign:
    """Design α_max, T_m, K, T_c (and T_so, T_sα for the sensors) for ``params``'s drive; verify by simulation.

    Parameters
    ----------
    params : DriveParams
        Nameplate, load, inverter limits, sensors, pass criteria, sample rate and delay,
        T_si/T_sα/T_so and the manoeuvre (θ_dem, requested T_m). K, T_c and the α_max rule are
        replaced by the design; T_so and T_sα are lengthened where the sensors need it.
    alpha_rule : str
        ``"torque_limit"`` (the fastest profile the torque allows: least friction, eqs. (47)–(60)
        in [1]) or ``"min_energy"`` (the profile's least friction + copper).
    cycle : bool
        True: the requested T_m is the time by which the axis must be in position (the move ends earlier).
    offer : bool
        Look for verified alternatives when the design is not clean.

    Returns
    -------
    DriveDesign
    """
    base = with_field(params, "controller", alpha_max_rule=alpha_rule, T_c="T_a")
    narrow = window_below_count(params)
    if narrow is not None:  # no setting holds it: say so at once, inputs as they are
        crit = pass_criteria(params)
        return refused(params, [Constraint("in_position", min(crit.in_position, crit.overshoot),
                                           params.sensors.encoder_step, "rad", True, narrow)])
    factors = _stable_slowdowns(base)
    if not factors:
        return _no_stable_loop(base, params)
    tried = []
    for factor in factors:
        p = planned(_slowed(base, factor))
        assert p is not None  # a stable factor has a planned T_m
        dd, fail = (in_position_by if cycle else shortest_clean)(p, params)
        tried.append((dd, fail, p.manoeuvre.T_m))
        if passes(dd) or not _sensor_limited(dd):
            break
    dd, fail, T_fit = min(tried, key=_rank)
    return _diagnosed(dd, fail, T_fit, params, alpha_rule, cycle, offer)


def _rank(entry: tuple[DriveDesign, DriveDesign | None, float]) -> tuple[int, float]:
    """Order the tried designs: passing first, then fewest violations, then least standstill ripple."""
    dd = entry[0]
    run = dd.comparison.fdsmc if dd.comparison is not None else None
    ripple = run.metrics.hold_i_q_rms_A or 0.0 if run is not None else float("inf")
    return sum(c.violated for c in dd.limiting) + (100 if dd.refused else 0), ripple


def _diagnosed(dd: DriveDesign, fail: DriveDesign | None, T_fit: float, asked: DriveParams, rule: str,
               cycle: bool, offer: bool) -> DriveDesign:
    """``dd`` with its diagnosis first in ``limiting`` and, when not clean, verified alternatives."""
    alts: tuple[Alternative, ...] = ()
    if offer and dd.verdict == "not clean" and not dd.refused:
        alts = alternatives(dd, asked, lambda q: design_drive(q, rule, cycle, offer=False))
    binding = T_m_constraint(dd, asked) + closed_form_binding(asked, dd.params) + simulated_binding(dd, fail, T_fit)
    sensors = sensors_binding(dd, alts)
    limiting = tuple(binding) + dd.limiting + tuple(sensors)
    cmp = dd.comparison
    if cmp is not None and cmp.conventional is None:  # the comparator on the design kept (same FDSMC run)
        cmp = compare(dd.params, derived=dd.derived)
    return dataclasses.replace(dd, limiting=limiting, alternatives=alts, comparison=cmp,
                               comparator=tuple(comparator_notes(cmp)) if cmp is not None else ())


def _no_stable_loop(base: DriveParams, asked: DriveParams) -> DriveDesign:
    """Refuse: no T_m fits, or no slowdown gives a stable sampled loop (then the sample rate binds)."""
    p = planned(base)
    if p is None:
        return refused(base, closed_form_binding(asked, base) + [Constraint(
            "T_m", asked.manoeuvre.T_m, 1e4, "s", True,
            "No manoeuvre time up to 1e4 s fits the speed/voltage limits.")])
    return refused(p, [unstable_rate(derive(p))], asked)


def _slowed(p: DriveParams, factor: float) -> DriveParams:
    c = p.controller
    return with_field(p, "controller", T_so=c.T_so * factor, T_salpha=c.T_salpha * factor)


def _stable_slowdowns(p: DriveParams) -> list[float]:
    """Slowdown factors to verify, each with a stable sampled loop at the planned T_m.

    From the first whose predicted ripple meets the criterion on; where none does, the QUIETEST
    stable ones by predicted ripple (their verified runs then say by how much the sensors fail).
    """
    if p.sensors.ideal or p.controller.is_continuous:
        return [1.0] if _stable(p, 1.0) is not None else []
    crit = pass_criteria(p).hold_i_rms
    stable = [(f, r) for f in SENSOR_SLOWDOWN if (r := _stable(p, f)) is not None]
    ok = [f for f, r in stable if r <= PREDICTION_MARGIN * crit]
    if ok:
        return [f for f, _ in stable if f >= ok[0]]
    return [f for f, _ in sorted(stable, key=lambda fr: fr[1])[:QUIETEST]]


def _stable(p: DriveParams, factor: float) -> float | None:
    """Predicted standstill ripple [A rms] of the slowed candidate, or None when its sampled loop is unstable."""
    q = planned(_slowed(p, factor))
    if q is None:
        return None
    d = derive(q)
    if d.sample_rate is not None and not d.sample_rate.stable:
        return None
    q = gain_and_T_c(q, d)
    d = derive(q)
    if not sampled_loop_stable(d):
        return None
    ng = predicted_noise(q, d)
    return ng.i_q_rms if ng is not None else 0.0


def _sensor_limited(dd: DriveDesign) -> bool:
    """Return True when the sensors' noise may be what fails (slower loops may mend it)."""
    names = {c.name for c in dd.limiting if c.violated}
    return not dd.params.sensors.ideal and bool(names & {"hold_ripple", "in_position", "current", "chatter",
                                                         "saturation"})
