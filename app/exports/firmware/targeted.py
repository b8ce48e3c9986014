"""Targeted golden vectors: single controller calls at rest in which a chosen inverter limit acts.

A closed-loop run hardly ever drives i_d to its limit, nor (on every drive) |u_dq| to V_dc/√3, so the
segments of :mod:`app.exports.firmware.golden` alone would let a wrong d-axis limit or voltage limit pass. Each
targeted segment starts from ``fdsmc_init`` at count 0 with no move (the estimates at rest: θ_re = 0,
ω̂ = 0, Γ̂_L = 0, so the outer law demands 0) and reads one implausible-but-allowed current: the
voltages the simulator's controller computes from it are those of :mod:`control` -- the FDC of
eqs. (9), (14) in [1] (:func:`control.fdsmc.fdc.fdc_voltages`), the q-axis voltage-mismatch estimate,
the prediction over the computation delay and :func:`control.fdsmc.inverter.limit_voltage` -- the
same functions the simulator's kernel inlines. With a computation delay of one sample the segment has
two calls (the first returns the held zero voltages, the second the first call's); without, one.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc import fdc, inverter
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.params import DriveParams

#: Currents tried for each target, as multiples of the hard limit I_LIMIT (all below the current
#: fault's 2·I_LIMIT): (i_d, i_q) pairs [-].
CANDIDATES = {
    "limit_i_d_pos": [(m, 0.3) for m in (1.0002, 1.001, 1.003, 1.01, 1.03, 1.1, 1.3, 1.6, 1.9)],
    "limit_i_d_neg": [(-m, -0.3) for m in (1.0002, 1.001, 1.003, 1.01, 1.03, 1.1, 1.3, 1.6, 1.9)],
    "limit_u": [(m, q) for q in (0.0, 0.5, -0.5) for m in (1.9, -1.9, 1.5, -1.5)],
}


@dataclass(frozen=True)
class AtRest:
    """One call at rest: the currents read [A], the voltages returned [V] and which limits acted."""

    i_d: float
    i_q: float
    u_d: float
    u_q: float
    d_limited: bool
    u_limited: bool


def call_at_rest(params: DriveParams, d: Derived, i_d: float, i_q: float) -> AtRest:
    """Return the simulator controller's voltages of the first call after init, at rest, reading (i_d, i_q) [A]."""
    c, ctrl = d.coefficients, params.controller
    T_s = 1.0 / float(ctrl.f_s)
    (phi_d, gam_d), (phi_q, gam_q) = inverter.decay_factors(c.A, T_s), inverter.decay_factors(c.D, T_s)
    model = (phi_d, gam_d, phi_q, gam_q, c.B, c.C, c.E, c.F, c.G)
    u_d, u_q, _ = fdc.fdc_voltages(0.0, i_d, i_q, 0.0, 0.0, 0.0, c.A, c.B, c.C, c.D, c.E, c.F, c.G, c.H, c.K,
                                   c.M, ctrl.T_si, ctrl.T_salpha)
    beta = fdc.mismatch_filter_factor(ctrl.T_dv, float(ctrl.f_s))
    if beta > 0.0:  # the estimate's first update: nothing was applied before, the model predicts i_q = 0
        u_q -= fdc.voltage_mismatch(0.0, i_q, 0.0, gam_q * c.G, beta)
    i0 = inverter.predict_currents(i_d, i_q, 0.0, 0.0, 0.0, *model) if ctrl.delay_samples == 1 else (i_d, i_q)
    i_max, u_max = current_limit(params), ctrl.V_dc / math.sqrt(3.0)
    i_d1 = inverter.predict_currents(i0[0], i0[1], 0.0, u_d, u_q, *model)[0]
    current_only = inverter.limit_voltage(u_d, u_q, i0[0], i0[1], 0.0, i_max, 0.0, *model)
    u = inverter.limit_voltage(u_d, u_q, i0[0], i0[1], 0.0, i_max, u_max, *model)
    return AtRest(i_d, i_q, u[0], u[1], i_max > 0.0 and abs(i_d1) > i_max,
                  u_max > 0.0 and math.hypot(current_only[0], current_only[1]) > u_max)


def targeted_calls(params: DriveParams, d: Derived) -> dict[str, AtRest]:
    """Name → the first candidate call in which its limit acts (the d-axis limit, or |u_dq|).

    Where the d-axis limit acts only with |u_dq| limited too, i_q ≠ 0 keeps the direction of the
    scaled voltage telling of u_d.

    Empty for a drive without a current limit (i_max = 0 and no torque limit) or a voltage limit.
    """
    i_lim = current_limit(params)
    if not i_lim > 0.0:
        return {}
    found = {}
    for name, pairs in CANDIDATES.items():
        for m_d, m_q in pairs:
            call = call_at_rest(params, d, m_d * i_lim, m_q * i_lim)
            if call.u_limited if name == "limit_u" else call.d_limited:
                found[name] = call
                break
    return found
