"""Derived values of a BLDC speed-control case: torque constants, loop figures, checks, warnings.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.bldc.current_smc import CurrentLoopDesign, current_loop_design
from pmsm_commissioning.control.bldc.dqx import torque_constant_dqx, torque_constant_fig7
from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.control.bldc.pi_vector import PiVectorDesign, pi_vector_design
from pmsm_commissioning.control.bldc.plain_smc import steady_state_error
from pmsm_commissioning.control.bldc.speed_smc import ReachabilityCheck, reachability_check


@dataclass(frozen=True)
class BldcDesign:
    """Everything derived from :class:`BldcParams` before simulating.

    Attributes
    ----------
    K_Tx : float                 n_pp·√(3/2)·Φ_m, eq. (9) [N·m/A] (used for i*_qx).
    K_T_fig7 : float             2·n_pp·Φ_M of Fig. 7 (six-step line-current constant, used for
                                 the six-step drive's I* = T*/K_T) [N·m/A].
    i_qx_max : float             T_max/K_Tx [A].
    current : CurrentLoopDesign  Sampled tanh current loop figures.
    pi : PiVectorDesign          Matched gains of the sinusoidal PI comparator.
    reachability : ReachabilityCheck  λ(ε) against eq. (24) at the scenario's ω*, T_L,max.
    T_L_max : float              Largest |T_L| of the scenario [N·m].
    eps_plain_ss : float or None Predicted steady-state error of the plain tanh law at T_L,max,
                                 atanh((B·ω* + T_L,max)/T_max)/k_ω [rad/s] (None if ≥ T_max).
    E_line_peak : float          Line-to-line back-EMF peak 2·n_pp·Φ_M·|ω*| (ideal) [V].
    warnings : tuple of str      Plain-language problems with the chosen values.
    """

    K_Tx: float
    K_T_fig7: float
    i_qx_max: float
    current: CurrentLoopDesign
    pi: PiVectorDesign
    reachability: ReachabilityCheck
    T_L_max: float
    eps_plain_ss: float | None
    E_line_peak: float
    warnings: tuple[str, ...]


def bldc_design(params: BldcParams) -> BldcDesign:
    """Derive the torque constants, loop figures and checks of a BLDC case (see attributes)."""
    m, mech, g, case = params.machine, params.mechanics, params.gains, params.case
    K_Tx = torque_constant_dqx(m.n_pp, m.Phi_m)
    T_L_max = max([abs(case.T_L_0)] + [abs(s.T_L) for s in case.T_L_steps])
    w_ref = case.omega_ref
    cl = current_loop_design(g.k_I, params.inverter.V_dc, params.inverter.f_s, m.L_s_minus_M_s)
    reach = reachability_check(g.lambda_0, g.eps_lambda, w_ref, mech.J, mech.B, g.T_max, T_L_max)
    T_eq = mech.B * abs(w_ref) + T_L_max
    eps_plain = steady_state_error(T_eq, g.k_omega, g.T_max) if T_eq < g.T_max else None
    E_line = 2.0 * m.n_pp * m.Phi_m * abs(w_ref)
    warnings = _warnings(params, cl, reach, T_eq, E_line, K_Tx)
    return BldcDesign(K_Tx, torque_constant_fig7(m.n_pp, m.Phi_m), g.T_max / K_Tx, cl,
                      pi_vector_design(params), reach, T_L_max, eps_plain, E_line, warnings)


def _warnings(params: BldcParams, cl: CurrentLoopDesign, reach: ReachabilityCheck, T_eq: float,
              E_line: float, K_Tx: float) -> tuple[str, ...]:
    g, m, V_dc = params.gains, params.machine, params.inverter.V_dc
    out: list[str] = []
    if cl.discrete_gain >= 2.0:
        out.append(f"current loop unstable when sampled: k_I·V_dc/(√2·f_s·L) = {cl.discrete_gain:.3g}, "
                   "allowed < 2 (≤ 1 for no oscillation): lower gains.k_I or raise inverter.f_s")
    elif cl.discrete_gain > 1.0:
        out.append(f"current loop oscillates per sample: k_I·V_dc/(√2·f_s·L) = {cl.discrete_gain:.3g} > 1")
    if T_eq >= g.T_max:
        out.append(f"T_max = {g.T_max:g} N·m cannot hold B·ω* + T_L,max = {T_eq:.4g} N·m (eq. (21))")
    drop = 2.0 * m.R_s * g.T_max / (2.0 * m.n_pp * m.Phi_m)
    if E_line + drop >= V_dc:
        out.append(f"V_dc = {V_dc:g} V is below the line back-EMF {E_line:.4g} V plus the resistive "
                   f"drop {drop:.3g} V at T_max: the speed reference is not reachable at full torque")
    for a, b in reach.violated:
        out.append(f"λ(ε) leaves the reachability hyperbola of eq. (24) for ε in "
                   f"[{a:.4g}, {b:.4g}] rad/s")
    if not math.isfinite(K_Tx) or K_Tx <= 0.0:
        out.append("torque constant is not positive")
    return tuple(out)
