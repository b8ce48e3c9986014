"""One design candidate at a fixed T_m: K and T_c chosen, the sampled loop checked, verified by simulation.

:func:`verify_at` is the verdict the T_m search of :mod:`sim.fdsmc.design_search` bisects on: the
candidate's K (K_limit/margin of the sampled loop), its T_c (T_a, or T_c,min where the sloped
segment is poorly damped; scanned when the run overshoots or misses the window), each candidate's
**sampled loop checked stable before it is simulated** (:func:`sampled_loop_stable`), and the
simulated run with the sensors checked by :func:`sim.fdsmc.checks.run_checks`.
"""

from __future__ import annotations

import math

from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.feasibility import alpha_max, feasibility
from pmsm_commissioning.control.fdsmc.loop_analysis import (
    ZETA_SLOPE_MIN,
    slope_damping,
    stability_measure,
    unit_damping_T_c,
)
from pmsm_commissioning.control.fdsmc.loop_model import LoopModel
from pmsm_commissioning.control.fdsmc.model import model_coefficients
from pmsm_commissioning.control.fdsmc.observer import observer_gains
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import shortest_manoeuvre_time, velocity_profile
from pmsm_commissioning.control.fdsmc.transient import acceleration_overshoot
from pmsm_commissioning.sim.fdsmc.checks import Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.design_result import DriveDesign, refused, round_up, verified, with_field
from pmsm_commissioning.sim.fdsmc.engine import Comparison, compare

#: Most K halvings while the verified run still chatters [-].
MAX_K_HALVINGS = 4
#: T_c raise per step and the most steps when the verified run overshoots θ_dem.
T_C_STEP, MAX_T_C_STEPS = 1.25, 10
#: Steps of the T_c scan without fewer violations after which it stops (a T_m the search then lengthens) [-].
T_C_PATIENCE = 3

Verified = tuple[DriveParams, Derived, Comparison]


def inner_overshoot(params: DriveParams) -> float:
    """Return η ≥ 1, the inner loops' acceleration overshoot at the drive's f_s and delay [-].

    From :mod:`control.fdsmc.transient`.
    """
    c = params.controller
    coeff = model_coefficients(params.motor)
    lm = LoopModel.of(coeff, params, observer_gains(c.T_so, coeff.M))
    return acceleration_overshoot(lm, None if c.is_continuous else float(c.f_s), c.delay_samples)


def fits(params: DriveParams, eta: float, T_m: float) -> bool:
    """Profile exists, ω_p within the speed limit and the voltage at ω_p fits, for manoeuvre time ``T_m`` [s]."""
    p = with_field(params, "manoeuvre", T_m=T_m)
    a = alpha_max(p, eta)
    if T_m < shortest_manoeuvre_time(p.manoeuvre.theta_dem, a.alpha_max):
        return False
    prof = velocity_profile(p.manoeuvre.theta_dem, a.alpha_max, T_m)
    f = feasibility(p, a, prof.omega_p)
    return f.speed_ok and f.voltage_ok


def shortest_fitting_T_m(params: DriveParams, eta: float) -> float | None:
    """Return the requested T_m if it fits (:func:`fits`), else the shortest that does [s]; None if none ≤ 1e4 s.

    Closed form (profile of eq. (60) in [1], speed and voltage at ω_p): the search on the simulated
    verdict (:mod:`sim.fdsmc.design_search`) starts here.
    """
    lo = params.manoeuvre.T_m
    if fits(params, eta, lo):
        return lo
    hi = lo
    while not fits(params, eta, hi):
        hi *= 2.0
        if hi > 1e4:
            return None
    while hi - lo > 1e-3 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if fits(params, eta, mid) else (mid, hi)
    return round_up(hi)


def planned(p: DriveParams) -> DriveParams | None:
    """``p`` at the T_m the design starts from (the requested one if it fits, else the shortest that does)."""
    eta = inner_overshoot(p)
    if not math.isfinite(eta):
        return p
    T_m = shortest_fitting_T_m(p, eta)
    return None if T_m is None else with_field(p, "manoeuvre", T_m=T_m)


def gain_and_T_c(params: DriveParams, d: Derived) -> DriveParams:
    """K = K_limit/margin (or 10/ω_p when the loop has no limit); T_c of ζ = 1 at K_limit_cruise/margin if ζ < ζ_min."""
    g = d.gain
    if g is None or g.K_limit <= 0.0:
        return params
    K = g.K_margin if math.isfinite(g.K_limit) else 10.0 / d.profile.omega_p
    a_max, T_c_unit = d.alpha.alpha_max, unit_damping_T_c(d.alpha.alpha_max, g.K_limit_cruise, g.margin)
    T_c: float | str = "T_a"
    if slope_damping(a_max, g.K_margin, d.loop.T_c) < ZETA_SLOPE_MIN and math.isfinite(T_c_unit):
        T_c = max(T_c_unit, d.profile.T_a)
    return with_field(params, "controller", K=K, T_c=T_c)


def sampled_loop_stable(d: Derived) -> bool:
    """Return True when the sampled loop of ``d``'s case is stable: inner loops + observer, and both outer laws at K.

    The spectral radius of the linearised sampled loop (:func:`control.fdsmc.loop_analysis.stability_measure`)
    below 1 for the conventional law (the sample-rate check), the cruise and the sloped segment of
    eq. (46) in [1] at the case's K. A continuous controller is judged by the real parts instead.
    """
    if d.sample_rate is not None and not d.sample_rate.stable:
        return False
    lc, K = d.loop, d.params.controller.K
    try:
        return all(stability_measure(lc, law, K, lc.f_s, lc.delay) < 0.0 for law in ("cruise", "slope"))
    except (ValueError, ZeroDivisionError, FloatingPointError):
        return False


def simulate(p: DriveParams) -> Verified | None:
    """Simulate ``p`` (its sampled loop checked stable first); halve K while the FDSMC run chatters.

    Returns None when a candidate's sampled loop is unstable: it is never simulated or offered.
    """
    for _ in range(MAX_K_HALVINGS + 1):
        d = derive(p)
        if not sampled_loop_stable(d):
            return None
        cmp = compare(p, ("fdsmc",), derived=d)  # the comparator is run once, on the design kept
        if cmp.fdsmc is None or not cmp.fdsmc.metrics.chatter:
            break
        p = with_field(p, "controller", K=p.controller.K / 2.0)
    return p, d, cmp


def verify_at(p: DriveParams, asked: DriveParams) -> DriveDesign:
    """Set K and T_c for ``p``'s loops at its T_m, check the sampled loop, simulate with the sensors, scan T_c.

    Overshoot or the in-position window failing: the sloped segment's T_c is scanned from T_a
    (×T_C_STEP up for an overshoot — a slower, better damped approach the lagging inner loops
    follow — or down when the approach is too slow for the simulated tail), the first T_c that passes
    taken, else the one with the fewest violations. Refused (nothing simulated) when the sampled loop
    is unstable or the move infeasible.
    """
    d = derive(p)
    if d.sample_rate is not None and not d.sample_rate.stable:
        return refused(p, [unstable_rate(d)], asked)
    got = simulate(gain_and_T_c(p, d))
    if got is None:
        return refused(p, [unstable_rate(d)], asked)
    q, d, cmp = got
    if cmp.fdsmc is None:
        return refused(q, [Constraint("T_m", q.manoeuvre.T_m, d.profile.T_m_min, "s", True,
                                      "The manoeuvre is infeasible at the designed α_max.")], asked)
    failed = {c.name for c in run_checks(q, cmp.fdsmc)}
    if failed & {"overshoot", "in_position"}:
        step = T_C_STEP if "overshoot" in failed else 1.0 / T_C_STEP
        q, d, cmp = _scan_T_c(q, (q, d, cmp), len(failed), step)
    return verified(q, d, cmp, asked)


def unstable_rate(d: Derived) -> Constraint:
    """Return the constraint of a sampled loop unstable at the drive's f_s, with the slowest stable f_s."""
    rate = d.sample_rate
    f_s = float(rate.f_s or 0.0) if rate is not None else 0.0
    f_min = rate.f_s_min if rate is not None else None
    rho = rate.spectral_radius if rate is not None else math.nan
    need = f"f_s ≥ {f_min:.4g} Hz" if f_min else "a faster controller"
    return Constraint("sample_rate", f_s, float(f_min or math.inf), "Hz", True,
                      f"f_s = {f_s:g} Hz is too slow for T_so = {d.params.controller.T_so * 1e3:.4g} ms and "
                      f"T_sα = {d.params.controller.T_salpha * 1e3:.4g} ms (sampled loop unstable, spectral radius "
                      f"{rho:.4f}): use {need}, or longer T_so and T_sα.")


def _scan_T_c(p: DriveParams, best: Verified, n_best: int, step: float) -> Verified:
    """Scan T_c = T_a·step^k (k = 0 …, K = K_limit/margin each): the first clean case, else the fewest violations.

    Stops after T_C_PATIENCE steps without fewer violations.
    """
    T_a, since = derive(p).profile.T_a, 0
    for k in range(MAX_T_C_STEPS + 1):
        got = simulate(_with_T_c(p, T_a * step**k))
        n = n_best if got is None or got[2].fdsmc is None else len(run_checks(got[0], got[2].fdsmc))
        since = 0 if n < n_best else since + 1
        if got is not None and n < n_best:
            best, n_best = got, n
        if n == 0 or since > T_C_PATIENCE:
            break
    return best


def _with_T_c(p: DriveParams, T_c: float) -> DriveParams:
    """``p`` with the sloped segment's T_c [s] and the design's K for it."""
    q = with_field(p, "controller", T_c=T_c)
    g = derive(q).gain
    return with_field(q, "controller", K=g.K_margin) if g is not None and g.K_limit > 0.0 else q


__all__ = ["fits", "gain_and_T_c", "inner_overshoot", "planned", "sampled_loop_stable", "shortest_fitting_T_m",
           "simulate", "unstable_rate", "verify_at"]
