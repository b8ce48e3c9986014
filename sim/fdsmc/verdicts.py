"""Verdicts on simulated runs: instability, chatter, saturation and the real drive's limits.

One place composes these messages, for the CLI, the web UI and the exported report.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math

from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.flux_tolerance import flux_tolerance
from pmsm_commissioning.control.fdsmc.loop_analysis import CHATTER_PTP_FRACTION, ZETA_SLOPE_MIN
from pmsm_commissioning.sim.fdsmc.checks import TARGET_BAND, exceeded, run_checks, saturation_matters
from pmsm_commissioning.sim.fdsmc.criteria import window_below_count
from pmsm_commissioning.sim.fdsmc.engine import LABELS, Comparison, RunResult, reached_target

#: A flux tolerance of the FDC below this is warned about [-] (a datasheet's 20 °C flux vs magnets 100 K
#: warmer is ≈ 10 % apart for NdFeB).
FLUX_TOLERANCE_WARN = 0.10


def recommended_K(derived: Derived) -> float | None:
    """Recommended boundary-layer gain K [s/rad] from the loop analysis, or None if none helps."""
    g = derived.gain
    return g.K_recommended if g.K_recommended > 0.0 else None


def K_advice(comparison: Comparison) -> float | None:
    """Return the recommended K [s/rad] to offer after ``comparison``, or None.

    Offered where a run chatters (with the sensors: their noise shows there) or where the loop
    analysis expects a limit cycle (K above K_limit/margin); a verified setting above the
    noise-capped K is left alone.
    """
    d = comparison.derived
    k_rec, g = recommended_K(d), d.gain
    chatter = any(r is not None and r.metrics.chatter for r in (comparison.fdsmc, comparison.conventional))
    return k_rec if k_rec is not None and (chatter or 1.001 * g.K_margin < g.K) else None


def _chatter_hint(derived: Derived) -> str:
    """Say what to change: K above its limit, or a poorly damped sloped segment (T_c too small)."""
    g = derived.gain
    if g.K_limit <= 0.0:
        return " Reduce K, eq. (45)."
    if not g.K_ok:
        return f" Recommended K = {g.K_recommended:.4g} s/rad."
    if not g.K_noise_ok:  # said after a run that chatters: the prediction alone is conservative
        return (f" K is above the sensors' noise limit K_noise = {g.K_noise:.4g} s/rad ({g.mode}): the encoder's "
                f"counts and the current noise, through the observer and K, swing α_dem by more than "
                f"{100 * CHATTER_PTP_FRACTION:g} % of α_max. Recommended K = {g.K_recommended:.4g} s/rad, or slower "
                f"T_so and T_sα (Design chooses them).")
    if g.zeta_slope < ZETA_SLOPE_MIN and math.isfinite(g.T_c_min):
        return (f" The sloped segment is poorly damped (ζ ≈ {g.zeta_slope:.2g}): set "
                f"controller.T_c ≥ {g.T_c_min:.3g} s.")
    return f" Reduce K below the recommended {g.K_recommended:.4g} s/rad."


def T_c_advice(derived: Derived) -> float | None:
    """T_c,min [s] when the sloped segment is poorly damped even with the recommended K, else None.

    On the −1/T_c line the ideal loop is s² + α_max·K·s + α_max·K/T_c, damping √(α_max·K·T_c)/2;
    with K capped by the chatter limit, a small T_c (e.g. T_c = T_a on slow manoeuvres) limit-cycles
    about θ_dem. T_c,min gives ζ = 1 at ``GainRecommendation.K_unit_damping``
    (``control.fdsmc.loop_analysis``).
    """
    g = derived.gain
    if not math.isfinite(g.T_c_min) or g.zeta_slope_recommended >= ZETA_SLOPE_MIN:
        return None
    return g.T_c_min if derived.profile.T_c < g.T_c_min else None


def _chatter(run: RunResult, derived: Derived) -> str:
    m = run.metrics
    freq = m.chatter_frequency_Hz
    at = f" at about {freq:.3g} Hz" if freq is not None else ""
    where = ("while holding θ_dem after T_m" if m.chatter_phase == "hold"
             else "during the cruise")
    return (f"Chatter ({LABELS[run.controller]}): the demanded acceleration switches{at} {where} — "
            f"a limit cycle of the sliding-mode loop at this K and T_c.{_chatter_hint(derived)}")


def limit_warnings(run: RunResult, derived: Derived) -> list[str]:
    """List the simulated peaks that the real drive cannot deliver: torque, current, voltage, speed.

    The limits are the drive's: :func:`~control.fdsmc.feasibility.torque_limit` (Γ_max, or K_t·i_max),
    the hard current limit, the inverter's voltage (V_dc/√3, else √(2/3)·V_0) and the speed limit
    (limits.omega_max, else ω_b).

    Parameters
    ----------
    run : RunResult
        A stable run.
    derived : Derived
        Derivations of the same case (motor limits).

    Returns
    -------
    list of str
        One message per limit exceeded.
    """
    label = {"torque": "peak torque", "voltage": "peak |u_dq|", "speed": "peak speed", "current": "peak |i_dq|"}
    return [f"Not feasible on the real drive ({LABELS[run.controller]}): {label[lim.name]} {v:.4g} {lim.unit} > "
            f"{lim.label}." for lim, v in exceeded(derived.params, run.metrics)]


def criteria_warnings(run: RunResult, derived: Derived) -> list[str]:
    """List the user's pass criteria the run fails (in-position window, overshoot, standstill ripple).

    Also a window or overshoot limit narrower than one encoder count, whatever the run did
    (:func:`sim.fdsmc.criteria.window_below_count`).
    """
    names = {"in_position", "overshoot", "hold_ripple"}
    out = [f"Criterion ({LABELS[run.controller]}): {c.text}" for c in run_checks(derived.params, run)
           if c.name in names]
    narrow = window_below_count(derived.params)
    return out if narrow is None else [*out, narrow]


def _target_missed(run: RunResult) -> str | None:
    """Warning when a stable run is outside its band around θ_dem at T_m, else None."""
    err, dem = run.metrics.theta_error_at_Tm_rad, run.metrics.theta_dem_rad
    band = TARGET_BAND[run.controller]
    if err is None or abs(err) <= band * abs(dem):
        return None
    return (f"Target missed ({LABELS[run.controller]}): position error {err:.4g} rad at T_m is outside "
            f"the {100 * band:g} % band of θ_dem = {dem:g} rad; the energy comparison is between "
            "unequal manoeuvres.")


def run_warnings(comparison: Comparison) -> list[str]:
    """Return the warnings from the simulated runs.

    Unstable, chatter, target missed, the FDSMC's saturation and drive limits, and savings that are not
    comparable. The comparator's own limit violations are :func:`comparator_notes` (they do not concern the
    drive being commissioned).
    """
    out: list[str] = []
    for run in (comparison.fdsmc, comparison.conventional):
        if run is None:
            continue
        m, name = run.metrics, LABELS[run.controller]
        if not m.stable:
            out.append(f"Unstable run ({name}): {m.reason or 'diverged'}.")
            continue
        if m.chatter:
            out.append(_chatter(run, comparison.derived))
        miss = _target_missed(run)
        if miss:
            out.append(miss)
        if run.controller == "fdsmc":
            out += _saturation(run, comparison.derived) + limit_warnings(run, comparison.derived)
            out += criteria_warnings(run, comparison.derived) + flux_warnings(comparison.derived)
    return out + _saving_verdicts(comparison)


def flux_warnings(derived: Derived) -> list[str]:
    """Warn when the paper's FDC tolerates less than FLUX_TOLERANCE_WARN of flux error at ω_p.

    :mod:`control.fdsmc.flux_tolerance`: beyond it the FDSMC runs away (weaker magnets) or stalls
    (stronger ones). A digital controller with the q-axis voltage-mismatch estimate (controller.T_dv > 0)
    has no such steady offset: no warning.
    """
    c = derived.params.controller
    if c.T_dv > 0.0 and not c.is_continuous:
        return []
    x = flux_tolerance(derived.coefficients, derived.alpha.alpha_max, derived.profile.omega_p, c.T_salpha)
    if x >= FLUX_TOLERANCE_WARN:
        return []
    return [f"Flux tolerance: the FDC of eq. (14) tolerates a Ψ_PM error of only ±{100 * x:.2g} % at ω_p "
            f"(magnets ≈ {x * 1000:.0f} K warmer): a weaker flux runs the FDSMC away, a stronger one stalls it. "
            "Set controller.T_dv (the q-axis voltage-mismatch estimate, e.g. 1 ms) on a digital controller."]


def _saturation(run: RunResult, derived: Derived) -> list[str]:
    sat = run.metrics.saturated_s
    if saturation_matters(derived.params, run.metrics):
        return [f"Saturation ({LABELS[run.controller]}): voltage/current limited for {sat:.4g} s."]
    return []


def comparator_notes(comparison: Comparison) -> list[str]:
    """Note where the conventional comparator (eq. (61) gains) itself exceeds the drive's limits.

    Its energy is then not a fair baseline for the saving. The comparison's own notes (a comparator
    left out, e.g. the optimum when its solvers failed) follow.
    """
    notes = list(comparison.notes)  # e.g. an optimum left out because its solvers failed
    run = comparison.conventional
    if run is None or not run.metrics.stable:
        return notes
    issues = _saturation(run, comparison.derived) + limit_warnings(run, comparison.derived)
    if not issues:
        return notes
    return [f"Comparator: {' '.join(issues)} Its energy is not a fair baseline for the saving."] + notes


def _saving_verdicts(comparison: Comparison) -> list[str]:
    """Say so when a friction saving is not a saving.

    A friction saving above the theoretical bound 1 − 4/5.6 of eq. (53), or from a run that missed its target,
    is not a saving.
    """
    saving, bound = comparison.saving_friction_pct, comparison.derived.energy.bound_pct
    if saving is None:
        never = [r for r in (comparison.fdsmc, comparison.conventional)
                 if r is not None and r.metrics.stable and not reached_target(r)]
        if never:
            return [f"Saving not comparable: {', '.join(LABELS[r.controller] for r in never)} never reached the "
                    "2 % band around θ_dem, so no saving is given."]
        return []
    out: list[str] = []
    missed = [r for r in (comparison.fdsmc, comparison.conventional) if r is not None and _target_missed(r)]
    if missed:
        out.append(f"Saving not comparable: {', '.join(LABELS[r.controller] for r in missed)} did not arrive "
                   f"by T_m, so the {saving:.4g} % friction saving compares unequal manoeuvres.")
    elif saving > bound + 0.05:
        out.append(f"Saving {saving:.4g} % exceeds the theoretical bound {bound:.4g} % of eq. (53): the moves "
                   "are not equal (check the arrival and the comparator), so the figure is not a saving.")
    return out
