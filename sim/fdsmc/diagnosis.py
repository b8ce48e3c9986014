"""Why a design is not as asked or not clean: the binding constraint with its figure, and verified alternatives.

The constraint that binds is named with the figure that shows it:

* **current** / **torque**: the requested T_m is below T_m,min = √(2·(5 + 2e⁻³)·|Δθ|/α_max)
  (eq. (60) in [1]) at the α_max the drive's torque allows; "current" where the inverter's i_max
  (K_t·i_max < Γ_max) sets it, with the current the requested T_m would need;
* **speed** / **voltage**: the profile's peak speed ω_p (eq. (60)) or the voltage at ω_p exceeds
  the limit at that T_m,min, so the shortest T_m that fits is longer;
* **simulated**: the closed form fits, but the verified run fails at that T_m (the inner loops'
  lag, the sensors): the checks it failed at the longest failing T_m tried, and the shortest T_m
  whose simulated run passed;
* **sensors**: the standstill ripple the encoder's quantization and the current noise cause
  exceeds the criterion at the slowest stable loops, with the encoder resolution and the ripple
  criterion that would pass (each verified, :func:`alternatives`);
* **sample rate**: only where no stable sampled loop exists at the drive's f_s.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from collections.abc import Callable

from pmsm_commissioning.control.fdsmc.feasibility import (
    alpha_max,
    feasibility,
    speed_limit,
    torque_limit,
    voltage_limit,
)
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import shortest_manoeuvre_time, velocity_profile
from pmsm_commissioning.sim.fdsmc.checks import Constraint
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.design_result import Alternative, DriveDesign, round_up, with_field
from pmsm_commissioning.sim.fdsmc.design_verify import inner_overshoot

#: Checks the sensors' noise fails (the observer and loops amplify the encoder's count and current noise).
SENSOR_FAILS = frozenset({"hold_ripple", "chatter"})
#: Margin on a simulated figure when an alternative criterion is proposed (then verified) [-].
CRITERION_MARGIN = 1.25


def closed_form_binding(asked: DriveParams, p: DriveParams) -> list[Constraint]:
    """Name what makes the requested T_m infeasible in closed form (current, torque, speed, voltage); [] if it fits.

    ``p`` is the candidate (its loops give η); ``asked`` the request.
    """
    T_asked, theta = asked.manoeuvre.T_m, asked.manoeuvre.theta_dem
    q = with_field(p, "controller", alpha_max_rule="torque_limit")
    eta = inner_overshoot(q)
    a = alpha_max(q, eta)
    T_min = shortest_manoeuvre_time(theta, a.alpha_max)
    out: list[Constraint] = []
    if T_asked < T_min:
        out.append(_torque_or_current(q, T_asked, T_min, a.alpha_max))
    T_check = max(T_asked, T_min)
    f = feasibility(q, a, velocity_profile(theta, a.alpha_max, T_check).omega_p)
    if not f.speed_ok:
        out.append(Constraint("speed", f.omega_p, speed_limit(q), "rad/s", False,
                              f"At T_m = {T_check:.4g} s the profile's peak speed ω_p = {f.omega_p:.4g} rad/s "
                              f"(eq. (60)) exceeds the speed limit {speed_limit(q):.4g} rad/s: the shortest T_m "
                              f"is longer."))
    if not f.voltage_ok:
        out.append(Constraint("voltage", f.u_needed_peak, voltage_limit(q), "V", False,
                              f"At T_m = {T_check:.4g} s the voltage at ω_p = {f.omega_p:.4g} rad/s, "
                              f"{f.u_needed_peak:.4g} V, exceeds the {voltage_limit(q):.4g} V available: the "
                              "shortest T_m is longer (or a higher V_dc)."))
    return out


def _torque_or_current(q: DriveParams, T_asked: float, T_min: float, a: float) -> Constraint:
    lim, g_max = torque_limit(q), q.motor.Gamma_max
    scale = (T_min / T_asked) ** 2  # α ∝ 1/T_m² at the shortest time of eq. (60)
    if lim < g_max:
        i_max, i_need = q.controller.i_max, q.controller.i_max * scale
        more = (f"would need i_max ≈ {i_need:.3g} A" if i_need * lim / i_max <= g_max else
                f"is out of reach even at Γ_max = {g_max:.4g} N·m ({g_max / lim * i_max:.3g} A)")
        return Constraint("current", T_asked, T_min, "s", False,
                          f"Current: T_m = {T_asked:g} s is shorter than T_m,min = {T_min:.4g} s by the current "
                          f"limit (i_max = {i_max:.4g} A gives K_t·i_max = {lim:.4g} N·m < Γ_max = {g_max:.4g} N·m, "
                          f"α_max = {a:.5g} rad/s²); T_m = {T_asked:g} s {more}: use T_m ≥ {T_min:.4g} s.")
    return Constraint("torque", T_asked, T_min, "s", False,
                      f"Torque: T_m = {T_asked:g} s is shorter than T_m,min = {T_min:.4g} s by the motor's peak "
                      f"torque Γ_max = {g_max:.4g} N·m (α_max = {a:.5g} rad/s²): use T_m ≥ {T_min:.4g} s or a "
                      "stronger motor.")


def simulated_binding(dd: DriveDesign, fail: DriveDesign | None, T_fit: float) -> list[Constraint]:
    """Name what the simulation found between the closed-form T_m ``T_fit`` [s] and the design's T_m."""
    T_m = dd.params.manoeuvre.T_m
    if fail is None or fail is dd or fail.refused or T_m <= T_fit:
        return []
    bad = [c for c in fail.limiting if c.violated]
    if not bad:
        return []
    what = "; ".join(c.text for c in bad)
    return [Constraint(bad[0].name, bad[0].value, bad[0].limit, bad[0].unit, False,
                       f"Simulated with the sensors: at T_m = {fail.params.manoeuvre.T_m:.4g} s the run fails "
                       f"({what}); "
                       f"the shortest T_m found to pass by simulation is {T_m:.4g} s.")]


def T_m_constraint(dd: DriveDesign, asked: DriveParams) -> list[Constraint]:
    """Return the binding "T_m" constraint of a design at a longer T_m than asked (not as asked)."""
    T_asked, T_m = asked.manoeuvre.T_m, dd.params.manoeuvre.T_m
    if dd.refused or T_m == T_asked or dd.T_m_asked != T_asked or _cycle_objective(dd):
        return []
    return [Constraint("T_m", T_asked, T_m, "s", False,
                       f"Requested T_m = {T_asked:g} s does not pass with these limits and sensors; the shortest "
                       f"T_m whose simulated run passed is {T_m:.4g} s (used): not as asked.")]


def _cycle_objective(dd: DriveDesign) -> bool:
    return any(c.name == "in_position_by_T_m" for c in dd.limiting)


def sensors_binding(dd: DriveDesign, alts: tuple[Alternative, ...]) -> list[Constraint]:
    """Name the sensors where the ripple (or chatter) check fails, with the encoder and criterion that would pass."""
    bad = [c for c in dd.limiting if c.violated and c.name in SENSOR_FAILS]
    if dd.refused or not bad:
        return []
    se, c = dd.params.sensors, dd.params.controller
    crit = pass_criteria(dd.params).hold_i_rms
    fixes = [a.text for a in alts if a.field in ("sensors.encoder_cpr", "limits.hold_i_rms")]
    need = f" Verified alternatives: {' '.join(fixes)}" if fixes else (
        f" An encoder of ≥ {dd.encoder_cpr_needed} counts/rev is predicted to pass." if dd.encoder_cpr_needed else "")
    return [Constraint("sensors", bad[0].value, bad[0].limit, bad[0].unit, True,
                       f"Sensors: with the {se.encoder_cpr}-count encoder and {se.reading_noise:.3g} A of current "
                       f"noise the slowest stable loops tried (T_so = {c.T_so * 1e3:.4g} ms, T_sα = "
                       f"{c.T_salpha * 1e3:.4g} ms) still fail: {bad[0].text} (criterion {crit:.3g} A)." + need)]


Changes = dict[str, dict[str, float]]


def _candidates(dd: DriveDesign) -> list[tuple[str, float, str, Changes]]:
    """Return the changes that may mend ``dd``'s failed checks: (field, value, unit, {section: {key: value}})."""
    p, fails = dd.params, {c.name for c in dd.limiting if c.violated}
    m = dd.comparison.fdsmc.metrics if dd.comparison is not None and dd.comparison.fdsmc else None
    crit, se = pass_criteria(p), p.sensors
    out: list[tuple[str, float, str, Changes]] = []
    if "hold_ripple" in fails and m is not None and m.hold_i_q_rms_A:
        value = round_up(CRITERION_MARGIN * m.hold_i_q_rms_A, 2)
        out.append(("limits.hold_i_rms", value, "A", {"limits": {"hold_i_rms": value}}))
    if fails & SENSOR_FAILS and se.encoder_cpr > 0:
        need = dd.encoder_cpr_needed
        cpr = need if need and need > se.encoder_cpr else 4 * se.encoder_cpr
        window = {"in_position": crit.in_position, "overshoot": crit.overshoot}  # the same window in rad
        out.append(("sensors.encoder_cpr", float(cpr), "counts/rev",
                    {"sensors": {"encoder_cpr": cpr}, "limits": window}))
    if fails & {"in_position", "overshoot"}:
        value = round_up(4.0 * max(crit.in_position, crit.overshoot), 2)
        out.append(("limits.in_position", value, "rad", {"limits": {"in_position": value, "overshoot": value}}))
    return out


def alternatives(dd: DriveDesign, asked: DriveParams,
                 design: Callable[[DriveParams], DriveDesign]) -> tuple[Alternative, ...]:
    """Return verified alternatives for a design that is not clean: each change designed and simulated by ``design``.

    ``design`` designs a request without looking for alternatives itself. Only the changed fields
    differ from the request. Returns those whose verified verdict is clean or clean at a longer T_m
    (not as asked).
    """
    out = []
    for field, value, unit, changes in _candidates(dd):
        q = asked
        for section, kv in changes.items():
            q = with_field(q, section, **kv)
        alt = design(q)
        if alt.verdict == "not clean":
            continue
        t_in = alt.in_position_s or float("nan")
        T = alt.params.manoeuvre.T_m
        out.append(Alternative(field, value, unit, alt.verdict, T, t_in,
                               f"{field} = {value:.4g} {unit}: verified {alt.verdict} by simulation (T_m = {T:.4g} s, "
                               f"in position at {t_in:.4g} s)."))
    return tuple(out)


__all__ = ["alternatives", "closed_form_binding", "sensors_binding", "simulated_binding", "T_m_constraint"]
