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
* K: the recommended K (gain margin 2 below the chatter limit of the sampled loop at the drive's
  f_s and delay, :mod:`control.fdsmc.loop_analysis`); halved while the simulation still chatters.
* T_c: T_a (eq. (59)) unless the sloped segment is then poorly damped; then T_c,min.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from control.fdsmc.derivations import Derived, derive
from control.fdsmc.feasibility import alpha_max, exceeds, feasibility, torque_limit, voltage_limit
from control.fdsmc.loop_analysis import ZETA_SLOPE_MIN
from control.fdsmc.loop_model import LoopModel
from control.fdsmc.model import model_coefficients
from control.fdsmc.observer import observer_gains
from control.fdsmc.params import DriveParams
from control.fdsmc.profile import shortest_manoeuvre_time, velocity_profile
from control.fdsmc.transient import acceleration_overshoot
from sim.fdsmc.engine import Comparison, RunResult, compare
from sim.fdsmc.verdicts import TARGET_BAND, comparator_notes

#: Most K halvings while the verified run still chatters [-].
MAX_K_HALVINGS = 4


@dataclass(frozen=True)
class Constraint:
    """A constraint that binds the design or prevents a clean one.

    Attributes
    ----------
    name : str        Short key, e.g. ``"torque"``, ``"sample_rate"``, ``"T_m"``.
    value : float     The design's (or simulation's) value [unit].
    limit : float     The limit it is compared with [unit].
    unit : str
    violated : bool   True when it prevents a clean design; False when it only binds.
    text : str        One sentence: what binds and, when violated, what would fix it.
    """

    name: str
    value: float
    limit: float
    unit: str
    violated: bool
    text: str


@dataclass(frozen=True)
class DriveDesign:
    """A designed setting, its verification run and the constraints that shaped it.

    Attributes
    ----------
    params : DriveParams            The designed inputs (a complete preset).
    derived : Derived               Their derivations.
    comparison : Comparison | None  The verification runs (None when not simulated).
    clean : bool                    True when the FDSMC run passed every check.
    limiting : tuple of Constraint  Binding and violated constraints.
    notes : tuple of str            Statements that do not make the design unclean.
    comparator : tuple of str       Where the conventional comparator exceeds the drive's limits.
    """

    params: DriveParams
    derived: Derived
    comparison: Comparison | None
    clean: bool
    limiting: tuple[Constraint, ...]
    notes: tuple[str, ...]
    comparator: tuple[str, ...] = ()


def _with(params: DriveParams, section: str, **changes: object) -> DriveParams:
    return dataclasses.replace(params, **{section: dataclasses.replace(getattr(params, section), **changes)})


def _fits(params: DriveParams, eta: float, T_m: float) -> bool:
    """Profile exists, ω_p ≤ ω_b and the voltage at ω_p fits, for manoeuvre time ``T_m`` [s]."""
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
    """K = recommended K (or 10/ω_p when the loop has no limit); T_c = T_c,min if ζ < ζ_min."""
    g = d.gain
    if g is None or g.K_limit <= 0.0:
        return params
    K = g.K_recommended if math.isfinite(g.K_limit) else 10.0 / d.profile.omega_p
    T_c: float | str = "T_a"
    if g.zeta_slope_recommended < ZETA_SLOPE_MIN and math.isfinite(g.T_c_min):
        T_c = max(g.T_c_min, d.profile.T_a)
    return _with(params, "controller", K=K, T_c=T_c)


def design_drive(params: DriveParams) -> DriveDesign:
    """Design α_max, T_m, K and T_c for ``params``'s drive and verify the result by simulation.

    Parameters
    ----------
    params : DriveParams
        Nameplate, load, inverter limits, sample rate and delay, T_si/T_sα/T_so and the manoeuvre
        (θ_dem, requested T_m). K, T_c and the α_max rule are replaced by the design.

    Returns
    -------
    DriveDesign
    """
    p = _with(params, "controller", alpha_max_rule="torque_limit", T_c="T_a")
    eta = _overshoot(p)
    limiting: list[Constraint] = []
    if math.isfinite(eta):
        T_m = shortest_fitting_T_m(p, eta)
        if T_m is None:
            return _refused(p, [Constraint("T_m", params.manoeuvre.T_m, 1e4, "s", True,
                                           "No manoeuvre time up to 1e4 s fits the speed/voltage limits.")])
        if T_m != params.manoeuvre.T_m:
            limiting.append(Constraint("T_m", params.manoeuvre.T_m, T_m, "s", False,
                                       f"Requested T_m = {params.manoeuvre.T_m:g} s is infeasible on this drive; "
                                       f"the shortest feasible is {T_m:.4g} s (used)."))
            p = _with(p, "manoeuvre", T_m=T_m)
    d = derive(p)
    rate = d.sample_rate
    if rate is not None and not rate.stable:
        need = f"f_s ≥ {rate.f_s_min:.4g} Hz" if rate.f_s_min else "a faster controller"
        return _refused(p, limiting + [Constraint(
            "sample_rate", float(rate.f_s or 0.0), float(rate.f_s_min or math.inf), "Hz", True,
            f"f_s = {rate.f_s:g} Hz is too slow for T_so/T_sα (sampled loop unstable, spectral radius "
            f"{rate.spectral_radius:.4f}): use {need}, or longer T_so and T_sα.")])
    p = dataclasses.replace(_gain_and_T_c(p, d), source=_designed_source(params.source))
    return _verify(p, limiting)


def _designed_source(source: str) -> str:
    tag = "design: torque-limit α_max, recommended K, verified by simulation"
    return source if tag in source else f"{source}; {tag}"


def _refused(p: DriveParams, limiting: list[Constraint]) -> DriveDesign:
    return DriveDesign(p, derive(p), None, False, tuple(limiting), ())


def _verify(p: DriveParams, limiting: list[Constraint]) -> DriveDesign:
    """Simulate; halve K while the FDSMC run chatters; collect the checks."""
    for _ in range(MAX_K_HALVINGS + 1):
        d = derive(p)
        cmp = compare(p, derived=d)
        if cmp.fdsmc is None or not cmp.fdsmc.metrics.chatter:
            break
        p = _with(p, "controller", K=p.controller.K / 2.0)
    if cmp.fdsmc is None:  # infeasible after all: derive's warnings say why
        return _refused(p, limiting + [Constraint("T_m", p.manoeuvre.T_m, d.profile.T_m_min, "s", True,
                                                  "The manoeuvre is infeasible at the designed α_max.")])
    limiting = limiting + [_torque_binding(p, cmp.fdsmc)] + run_checks(p, cmp.fdsmc)
    clean = not any(c.violated for c in limiting)
    return DriveDesign(p, d, cmp, clean, tuple(limiting), _notes(d), tuple(comparator_notes(cmp)))


def _torque_binding(p: DriveParams, run: RunResult) -> Constraint:
    lim = torque_limit(p)
    peak = run.metrics.torque_peak_Nm or 0.0
    return Constraint("torque", peak, lim, "N·m", False,
                      f"α_max = {alpha_max(p, _overshoot(p)).alpha_max:.5g} rad/s² is set by the torque limit "
                      f"{lim:.4g} N·m (Γ_max or i_max); simulated peak {peak:.4g} N·m.")


def run_checks(p: DriveParams, run: RunResult) -> list[Constraint]:
    """Return the simulated run's violations of the drive's limits, the arrival band and chatter."""
    m = run.metrics
    if not m.stable:
        return [Constraint("stable", 1.0, 0.0, "-", True, f"Unstable run: {m.reason}.")]
    out: list[Constraint] = []
    i_max = p.controller.i_max
    peaks = [("torque", m.torque_peak_Nm, torque_limit(p), "N·m", "lower T_m demand or a larger motor"),
             ("voltage", m.u_peak_V, voltage_limit(p), "V", "a longer T_m (lower ω_p) or a higher V_dc"),
             ("speed", m.omega_peak_rad_s, p.motor.omega_b, "rad/s", "a longer T_m")]
    if i_max > 0.0:
        peaks.append(("current", m.i_q_peak_A, i_max, "A", "a larger inverter"))
    for name, peak, lim, unit, fix in peaks:
        v = peak or 0.0
        if exceeds(v, lim):
            out.append(Constraint(name, v, lim, unit, True, f"Simulated peak {name} {v:.4g} {unit} > {lim:.4g} "
                                                            f"{unit}: needs {fix}."))
    sat = m.saturated_s
    if sat > 0.0:
        out.append(Constraint("saturation", sat, 0.0, "s", True,
                              f"The inverter limits the voltage/current for {sat:.3g} s."))
    frac = TARGET_BAND[run.controller]
    err, band = abs(m.theta_error_at_Tm_rad or 0.0), frac * abs(p.manoeuvre.theta_dem)
    if err > band:
        out.append(Constraint("arrival", err, band, "rad", True, f"Position error {err:.4g} rad at T_m is outside "
                                                                 f"the {100 * frac:g} % band ({band:.4g} rad)."))
    if m.chatter:
        out.append(Constraint("chatter", p.controller.K, 0.0, "s/rad", True,
                              f"Still chatters at K = {p.controller.K:.4g} s/rad."))
    return out


def _notes(d: Derived) -> tuple[str, ...]:
    notes: list[str] = []
    K, w_p = d.params.controller.K, d.profile.omega_p
    if w_p <= 1.0 / K:
        notes.append(f"Boundary layer ±1/K = ±{1.0 / K:.4g} rad/s is wider than ω_p = {w_p:.4g} rad/s: the "
                     "outer loop is linear (never sliding) on this manoeuvre; the K limit of the sampled "
                     "loop allows no larger K.")
    return tuple(notes)
