"""The stock-drive settings of one simulated case, in SI units (the vendor writers convert at the edge).

One function, :func:`stock_settings`, decides every number a stock drive's file carries:

* the trapezoid at the designed α_max whose cruise ends the move at T_m
  (:func:`control.fdsmc.trapezoid.trapezoid_timing`); the planner's speed limit is its cruise speed;
* the P–PI cascade of the comparator's gains g1, g2 (eq. (61) in [1]) for the total inertia
  J_r + J_L (:func:`control.fdsmc.trapezoid.cascade_gains`);
* the motor constants R_s, L_d, L_q, Ψ_PM, p and the current limit (the inverter's i_max, else the
  current of Γ_max);
* the current-loop bandwidth 3/T_si [rad/s] (first order, 5 % settling in T_si, eq. (8) in [1]);
* the drive's cycle time 1/f_s (1 ms for a continuous-time case).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from control.fdsmc.trapezoid import CascadeGains, TrapezoidTiming, cascade_gains, trapezoid_timing
from sim.fdsmc.engine import Comparison, simulate

#: Cycle time of a continuous-time case's setpoint table [s].
CONTINUOUS_CYCLE_S = 1e-3


@dataclass(frozen=True)
class StockSettings:
    """Every number of a stock drive's file, SI units.

    Attributes
    ----------
    trapezoid : TrapezoidTiming  The move (Δθ [rad], α [rad/s²], T_a, T_m [s], ω_c [rad/s]).
    gains : CascadeGains         The cascade (and its parallel-PID form) for J = J_r + J_L.
    R_s : float                  Phase resistance [Ω].
    L_d, L_q : float             Phase inductances [H].
    psi_pm : float               Ψ_PM [Wb].
    p : int                      Pole pairs [-].
    current_limit : float        Peak phase current (|i_q|) limit [A].
    speed_limit : float          The drive's hard speed limit, max(ω_b, |ω_c|) [rad/s].
    current_bandwidth : float    Current-loop bandwidth 3/T_si [rad/s].
    cycle_s : float              The drive's cycle time [s].
    """

    trapezoid: TrapezoidTiming
    gains: CascadeGains
    R_s: float
    L_d: float
    L_q: float
    psi_pm: float
    p: int
    current_limit: float
    speed_limit: float
    current_bandwidth: float
    cycle_s: float


def stock_settings(cmp: Comparison) -> StockSettings:
    """Return the stock-drive settings of the simulated case ``cmp`` (see the module doc)."""
    d = cmp.derived
    p = d.params
    m, c = p.motor, p.controller
    tr = trapezoid_timing(p.manoeuvre.theta_dem, d.alpha.alpha_max, p.manoeuvre.T_m)
    gains = cascade_gains(d.conventional.g1, d.conventional.g2, p.J_total)
    kt = 1.5 * m.p * m.psi_pm
    i_lim = c.i_max if c.i_max > 0.0 else m.Gamma_max / kt
    cycle = CONTINUOUS_CYCLE_S if c.is_continuous else 1.0 / float(c.f_s)
    return StockSettings(tr, gains, m.R_s, m.L_d, m.L_q, m.psi_pm, m.p, i_lim, max(m.omega_b, abs(tr.omega_c)),
                         3.0 / c.T_si, cycle)


def with_stock_runs(cmp: Comparison) -> Comparison:
    """Return ``cmp`` with the stock route and the tracked optimum simulated (when missing and feasible)."""
    if cmp.fdsmc is None:
        return cmp
    p, d = cmp.derived.params, cmp.derived
    stock = cmp.stock if cmp.stock is not None else simulate(p, "stock", d)
    optimum = cmp.optimum if cmp.optimum is not None else simulate(p, "optimum", d)
    return dataclasses.replace(cmp, stock=stock, optimum=optimum)
