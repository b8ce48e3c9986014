"""The manoeuvre time of a design, searched on the simulated verdict (not on a closed form).

:func:`shortest_clean` starts at the closed-form T_m (the requested one when its profile, speed and
voltage fit; else the shortest that does) and, when the verified run fails a check a longer move
can mend, brackets the shortest clean T_m by growing it (×GROWTH) until a verified run passes, then
bisects the bracket. The T_m it returns is always one whose simulated run passed: the verdict is
not assumed monotonic in T_m, so only simulated passes are reported.

:func:`in_position_by` serves the objective "in position by T_m": the requested T_m is the time by
which the axis must be inside the in-position window, and the move is ended earlier (the move time
scaled by T_m/in-position time, then bisected) until the verified run is in position by then.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.checks import Constraint
from pmsm_commissioning.sim.fdsmc.design_result import DriveDesign, round_down, round_up, with_field
from pmsm_commissioning.sim.fdsmc.design_verify import planned, verify_at

#: T_m growth per step while bracketing the shortest clean T_m, and the most steps (×4.3 in all) [-].
GROWTH, MAX_GROWTHS = 1.2, 8
#: Bisections of a bracket (its width then ≤ 1/16 of the first step) [-].
BISECTIONS = 4
#: Checks a longer (or earlier-ending) move can mend; the others (ripple, chatter) it cannot.
TIMING_CHECKS = frozenset({"speed", "voltage", "current", "torque", "saturation", "arrival", "overshoot",
                           "in_position", "stable", "T_m"})
#: Most move-time reductions while looking for a move in position by the requested time [-].
MAX_EARLIER = 6
#: First guess of the in-position time over the move time (the approach takes 15–25 % of T_m) [-].
CYCLE_LEAD = 1.2
#: Extra shortening per step of the move time when the run is in position too late [-].
EARLIER_MARGIN = 0.99

Evaluate = Callable[[DriveParams, DriveParams], DriveDesign]


def passes(dd: DriveDesign) -> bool:
    """Return True when ``dd`` was simulated and its run violates no check."""
    return not dd.refused and not any(c.violated for c in dd.limiting)


def _violated(dd: DriveDesign) -> set[str]:
    return {c.name for c in dd.limiting if c.violated}


def _at(p: DriveParams, T_m: float, asked: DriveParams, evaluate: Evaluate) -> DriveDesign:
    return evaluate(with_field(p, "manoeuvre", T_m=T_m), asked)


def shortest_clean(p: DriveParams, asked: DriveParams,
                   evaluate: Evaluate = verify_at) -> tuple[DriveDesign, DriveDesign | None]:
    """Return the design at the shortest T_m ≥ ``p``'s whose simulated run passed, and the last that failed.

    Parameters
    ----------
    p : DriveParams         The candidate at its closed-form T_m (loops already chosen).
    asked : DriveParams     The request (its T_m decides whether the result is as asked).
    evaluate : callable     The verdict of one T_m (:func:`sim.fdsmc.design_verify.verify_at`).

    Returns
    -------
    (DriveDesign, DriveDesign or None)
        The passing design at the shortest T_m found (bracket, then BISECTIONS bisections), or the
        design at ``p``'s T_m when none up to ×GROWTH^MAX_GROWTHS passes or the failure is not one a
        longer move mends; and the failing design at the largest T_m tried below it (None if none).
    """
    first = evaluate(p, asked)
    if passes(first):
        return first, None
    if first.refused or not _violated(first) <= TIMING_CHECKS:
        return first, first
    lo, hi, T = first, None, p.manoeuvre.T_m
    for _ in range(MAX_GROWTHS):
        T = round_up(T * GROWTH)
        cand = _at(p, T, asked, evaluate)
        if passes(cand):
            hi = cand
            break
        lo = cand
    if hi is None:
        return first, lo
    for _ in range(BISECTIONS):
        mid = round_up(0.5 * (lo.params.manoeuvre.T_m + hi.params.manoeuvre.T_m))
        if not lo.params.manoeuvre.T_m < mid < hi.params.manoeuvre.T_m:
            break
        cand = _at(p, mid, asked, evaluate)
        lo, hi = (lo, cand) if passes(cand) else (cand, hi)
    return hi, lo


def in_position_by(p: DriveParams, asked: DriveParams,
                   evaluate: Evaluate = verify_at) -> tuple[DriveDesign, DriveDesign | None]:
    """Return the design whose verified run is in position by the requested T_m, ending the move early.

    The search starts at the move time T_m/CYCLE_LEAD (not below the closed-form shortest move),
    takes the shortest passing move from there (:func:`shortest_clean`), ends it earlier while its run
    is in position too late (scaled by T_m/in-position time) and bisects towards the longest move
    (least energy) still in position by ``asked.manoeuvre.T_m`` [s]. Where none is, the passing design
    in position earliest, marked not as asked. Also returns the last failing design tried (None if none).
    """
    T_cycle = asked.manoeuvre.T_m
    fastest = planned(with_field(p, "manoeuvre", T_m=1e-3))  # the closed-form shortest move
    T_min = fastest.manoeuvre.T_m if fastest is not None else 0.0
    start = with_field(p, "manoeuvre", T_m=max(T_min, round_down(T_cycle / CYCLE_LEAD)))
    best, fail = shortest_clean(start, asked, evaluate)
    if not passes(best):
        return _cycle(best, T_cycle), fail
    late, early, T = best, None, best.params.manoeuvre.T_m
    for _ in range(MAX_EARLIER):
        t_in = late.in_position_s
        if t_in is not None and t_in <= T_cycle:
            early = late
            break
        T_new = max(round_down(EARLIER_MARGIN * T * T_cycle / (t_in or 1.3 * T)), T_min)
        if T_new >= T:
            break
        T, cand = T_new, _at(p, T_new, asked, evaluate)
        if passes(cand):
            late = cand
        else:  # the verdict is not monotonic in T_m: keep the passing one, try a shorter move still
            fail = cand
    if early is None:
        return _cycle(late, T_cycle), fail
    if early is best and T_cycle > best.params.manoeuvre.T_m:  # in time at the start: try a longer move
        late = _at(p, round_down(T_cycle), asked, evaluate)
        if passes(late) and late.in_position_s is not None and late.in_position_s <= T_cycle:
            return _cycle(late, T_cycle), fail
    return _cycle(_longest_in_time(p, asked, early, late, T_cycle, evaluate), T_cycle), fail


def _longest_in_time(p: DriveParams, asked: DriveParams, early: DriveDesign, late: DriveDesign, T_cycle: float,
                     evaluate: Evaluate) -> DriveDesign:
    """Bisect the move time between ``early`` (in position by T_cycle) and ``late`` (not): the longest in time."""
    if early is late:
        return early
    for _ in range(BISECTIONS):
        lo, hi = early.params.manoeuvre.T_m, late.params.manoeuvre.T_m
        mid = round_down(0.5 * (lo + hi))
        if not lo < mid < hi:
            break
        cand = _at(p, mid, asked, evaluate)
        t_in = cand.in_position_s
        if passes(cand) and t_in is not None and t_in <= T_cycle:
            early = cand
        else:
            late = cand
    return early


def _cycle(dd: DriveDesign, T_cycle: float) -> DriveDesign:
    """Mark ``dd`` for the objective "in position by T_m": as asked when its run is in position by ``T_cycle``."""
    if dd.refused:
        return dd
    t_in, T_m = dd.in_position_s, dd.params.manoeuvre.T_m
    ok = passes(dd) and t_in is not None and t_in <= T_cycle
    when = "never" if t_in is None else f"at {t_in:.4g} s"
    text = (f"Objective in position by T_m = {T_cycle:g} s: the move ends at {T_m:.4g} s and the verified run is "
            f"in position {when}" + ("." if ok else ", later than asked: not as asked (the earliest found)."))
    c = Constraint("in_position_by_T_m", t_in if t_in is not None else float("inf"), T_cycle, "s", False, text)
    return dataclasses.replace(dd, limiting=(c, *dd.limiting), as_asked=ok, clean=ok, T_m_asked=T_cycle)


__all__ = ["BISECTIONS", "GROWTH", "MAX_GROWTHS", "TIMING_CHECKS", "in_position_by", "passes", "shortest_clean"]
