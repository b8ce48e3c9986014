"""The run-time design constants of the C module: ``const fdsmc_params FDSMC_DESIGN`` and its limits.

:func:`design_constants` adds what the firmware needs beyond the derived design to accept or refuse a
move set at run time and to detect faults: the largest peak speed (base speed and inverter voltage, by
:func:`control.fdsmc.feasibility.feasibility`), the smallest sliding-mode time constant (damping of the
sloped segment, :data:`control.fdsmc.loop_analysis.ZETA_SLOPE_MIN`), the observer-innovation and current
plausibility limits. :func:`design_initializer` writes the struct with precomputed products and
reciprocals (``3/T_si``, ``1/F``, ``1/G``, ``u_max²`` …) so that the step divides only by (H + K·i_d).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from pmsm_commissioning.app.io.units import spec_of
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.fdc import mismatch_filter_factor
from pmsm_commissioning.control.fdsmc.feasibility import current_limit, feasibility
from pmsm_commissioning.control.fdsmc.inverter import decay_factors
from pmsm_commissioning.control.fdsmc.loop_analysis import ZETA_SLOPE_MIN
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import C_57

#: Encoder resolution of the C module when the preset's encoder is ideal [counts/rev]: 2^22 resolves
#: 1.5 µrad and leaves ±512 revolutions in an int32 count.
IDEAL_COUNTS_PER_REV = 1 << 22
#: Largest |count| the demand may reach, and the largest resolution (int32, with headroom) [counts].
COUNT_RANGE = 2**30
#: Current plausibility bound as a multiple of i_max [-] (the limit keeps |i_dq| ≤ i_max; noise, ringing).
I_FAULT_FACTOR = 2.0
#: "At rest" for a new move: |θ̂ − θ_dem| ≤ this fraction of the innovation fault's quarter electrical
#: turn, and |ω̂| ≤ this fraction of the designed move's peak speed [-].
REST_FRACTION_E_O, REST_FRACTION_OMEGA = 0.125, 0.01
#: Bound on |u_dq|² and |i_dq|² used only to catch non-finite values when no limit is given [V², A²].
NON_FINITE_BOUND = 1e30


def encoder_counts_per_rev(params: DriveParams) -> int:
    """Return the counts per mechanical revolution of the angle the C module takes (the preset's encoder, or 2^22).

    Raises
    ------
    ParameterError
        When the designed θ_dem does not fit the int32 count.
    """
    cpr = int(params.sensors.encoder_cpr or IDEAL_COUNTS_PER_REV)
    if cpr > COUNT_RANGE:
        raise ParameterError(f"sensors.encoder_cpr = {cpr} is out of range for the C module's int32 counts: "
                             f"allowed 0 (ideal) or 1 … {COUNT_RANGE} counts/rev")
    limit = COUNT_RANGE * 2.0 * math.pi / cpr
    if abs(params.manoeuvre.theta_dem) >= limit:
        raise ParameterError(f"manoeuvre.theta_dem = {params.manoeuvre.theta_dem:g} rad does not fit the C module's "
                             f"int32 encoder count: allowed |θ_dem| < {limit:.6g} rad at {cpr} counts/rev")
    return cpr


def peak_speed_limit(params: DriveParams, d: Derived) -> float:
    """Largest ω_p [rad/s] a run-time move may have: ω_p ≤ ω_b and |u_dq| at ω_p within the inverter's.

    Bisection (1e-9) on :func:`control.fdsmc.feasibility.feasibility` at the design's α_max; never below
    the designed move's ω_p (an accepted unclean design keeps its own move).
    """
    def ok(w: float) -> bool:
        f = feasibility(params, d.alpha, w)
        return f.speed_ok and f.voltage_ok

    lo, hi = 0.0, params.motor.omega_b * 1.01
    if ok(hi):
        lo = hi
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return max(lo, d.profile.omega_p)


def design_constants(params: DriveParams, d: Derived) -> list[tuple[str, float, str, str]]:
    """(name, value, unit, reference) of the run-time limits and the constants of eq. (60)."""
    K, a = params.controller.K, d.alpha.alpha_max
    t_c_min = min(4.0 * ZETA_SLOPE_MIN**2 / (a * K), d.profile.T_c)
    i_max = current_limit(params)
    return [
        ("C_57", C_57, "-", "5 + 2*exp(-3), eqs. (57), (60) of [1]"),
        ("TWO_PI", 2.0 * math.pi, "rad", "one revolution"),
        ("OMEGA_P_MAX", peak_speed_limit(params, d), "rad/s", "largest peak speed of a move (omega_b, voltage)"),
        ("T_C_MIN", t_c_min, "s", f"smallest T_c of a move: damping sqrt(alpha_max*K*T_c)/2 >= {ZETA_SLOPE_MIN}"),
        ("T_M_MAX", float(spec_of("manoeuvre.T_m").high or 1e4), "s", "longest move"),
        ("E_O_MAX", math.pi / (2.0 * params.motor.p), "rad",
         "innovation fault: a quarter electrical turn (field orientation lost)"),
        ("REST_ANGLE", REST_FRACTION_E_O * math.pi / (2.0 * params.motor.p), "rad",
         "fdsmc_set_move: at rest when |theta_hat - theta_dem| <= this (E_O_MAX/8)"),
        ("REST_SPEED", REST_FRACTION_OMEGA * d.profile.omega_p, "rad/s",
         "fdsmc_set_move: at rest when |omega_hat| <= this (1 % of the designed move's omega_p)"),
        ("I_LIMIT", i_max, "A", "hard |i_dq| limit min(i_max, Gamma_max/K_t) (0 = none)"),
        ("I_FAULT", I_FAULT_FACTOR * i_max if i_max > 0.0 else math.sqrt(NON_FINITE_BOUND), "A",
         f"current fault: {I_FAULT_FACTOR:g}*I_LIMIT (no limit: non-finite only)"),
    ]


def _fields(params: DriveParams, d: Derived, K: float) -> dict[str, Any]:
    """Field name → value of ``fdsmc_params`` in its declaration order (C++ needs designators in that order).

    ``K``: the law's gain.
    """
    c, ctrl, od = d.coefficients, params.controller, d.observer_discrete
    assert od is not None
    lim = {n: v for n, v, _, _ in design_constants(params, d)}
    f_s, u_max, cpr = 1.0 / od.T_s, ctrl.V_dc / math.sqrt(3.0), encoder_counts_per_rev(params)
    i_lim = lim["I_LIMIT"]
    (phi_d, gam_d), (phi_q, gam_q) = (decay_factors(rate, 1.0 / float(ctrl.f_s)) for rate in (c.A, c.D))
    t_c = 0.0 if params.controller.T_c == "T_a" else float(params.controller.T_c)
    return {
        "alpha_max": d.alpha.alpha_max, "inv_alpha_max": 1.0 / d.alpha.alpha_max, "k_bl": K,
        "t_c_fixed": t_c, "t_c_min": lim["T_C_MIN"], "omega_p_max": lim["OMEGA_P_MAX"], "t_m_max": lim["T_M_MAX"],
        "a": c.A, "b": c.B, "c": c.C, "d": c.D, "e": c.E, "f": c.F, "g": c.G, "inv_f": 1.0 / c.F, "inv_g": 1.0 / c.G,
        "h": c.H, "k": c.K, "m": c.M, "three_inv_t_si": 3.0 / ctrl.T_si, "three_inv_t_salpha": 3.0 / ctrl.T_salpha,
        "g1": d.conventional.g1, "g2": d.conventional.g2, "f_s": f_s, "f_s2": f_s**2, "f_s3": f_s**3,
        "t_s2": od.T_s**2, "j_r": params.motor.J_r,
        "u_max": u_max, "u_max2": u_max**2, "i_max": i_lim, "i_max2": i_lim * i_lim,
        "phi_d": phi_d, "inv_gam_d": 1.0 / gam_d, "gam_d": gam_d, "phi_q": phi_q, "inv_gam_q": 1.0 / gam_q,
        "gam_q": gam_q, "beta_dv": mismatch_filter_factor(ctrl.T_dv, float(ctrl.f_s)),
        "gain_dv": gam_q * c.G, "inv_gain_dv": 1.0 / (gam_q * c.G),
        "i_fault2": lim["I_FAULT"] ** 2, "u_fault2": NON_FINITE_BOUND,
        "e_o_max_counts": lim["E_O_MAX"] * cpr / (2.0 * math.pi),
        "rad_per_count": 2.0 * math.pi / cpr, "counts_per_rad": cpr / (2.0 * math.pi),
        "rest_angle": lim["REST_ANGLE"], "rest_speed": lim["REST_SPEED"],
    }


def design_initializer(params: DriveParams, d: Derived, so: Any, literal: Callable[[float], str], K: float) -> str:
    """Designated initializer of ``FDSMC_DESIGN`` (``so``: the :class:`~app.exports.firmware.module.ScaledObserver`).

    ``K`` is the boundary-layer gain of the module's law: the case's for the FDSMC, the tracked optimum's
    (:func:`control.fdsmc.tracking.slide_gain`) for its module.

    The observer matrices are the scaled ones in the float build and the simulator's (Φ, Γ, L of
    :func:`control.fdsmc.observer.discrete_observer`) in the double build.
    """
    if not 0 < d.alpha.alpha_max < math.inf:
        raise ParameterError(f"α_max = {d.alpha.alpha_max:g} rad/s² cannot be exported: allowed > 0")
    lines = [f"    .{k} = R_({literal(v)})," for k, v in _fields(params, d, K).items()]
    od = d.observer_discrete
    assert od is not None

    def row(values: Any) -> str:
        return "{" + ", ".join(f"R_({literal(float(v))})" for v in values) + "}"

    for build, (Phi, Gam, L) in (("#ifdef FDSMC_USE_FLOAT", (so.Phi, so.Gamma, so.L)),
                                 ("#else", (od.Phi, od.Gamma, od.L))):
        lines.append(build)
        lines.append("    .phi = {" + ",\n            ".join(row(r) for r in Phi) + "},")
        lines += [f"    .gamma = {row(Gam)},", f"    .l = {row(L)},"]
    lines.append("#endif")
    return "\n".join(lines)
