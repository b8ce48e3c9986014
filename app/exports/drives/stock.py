"""The stock-drive settings of one simulated case, in SI units (the vendor writers convert at the edge).

One function, :func:`stock_settings`, decides every number a stock drive's file carries, from the
drive's own loops tuned on the simulated checks (:func:`sim.stock.tuning.tune`):

* the trapezoid ending the move at T_m at the tuned acceleration (a fraction of the design's α_max
  that leaves the drive's feedback torque headroom); the planner's speed limit is its cruise speed;
* the position/speed loop's gains (P–PI cascade, or moteus' parallel PID) with the inertia
  feed-forward J_r + J_L and the encoder PLL's bandwidth;
* the motor constants R_s, L_d, L_q, Ψ_PM, p and the current limit (the inverter's i_max, else the
  current of Γ_max);
* the current-loop bandwidth 3/T_si [rad/s] (first order, 5 % settling in T_si, eq. (8) in [1]);
* the drive's cycle time 1/f_s (1 ms for a continuous-time case).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc.trapezoid import CascadeGains, TrapezoidTiming
from pmsm_commissioning.sim.fdsmc.criteria import drive_current
from pmsm_commissioning.sim.fdsmc.engine import Comparison, simulate
from pmsm_commissioning.sim.stock.route import StockLoop
from pmsm_commissioning.sim.stock.tuning import DRIVES, StockTuning, tuned

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
    current_limit : float        Peak phase current limit [A]: the hard limit the simulation enforces,
                                 min(i_max, Γ_max/K_t) (Γ_max/K_t without an inverter limit).
    speed_limit : float          The drive's hard speed limit, max(ω_b, |ω_c|) [rad/s].
    current_bandwidth : float    Current-loop bandwidth 3/T_si [rad/s].
    cycle_s : float              The drive's cycle time [s].
    pll_bandwidth : float        Encoder PLL bandwidth [rad/s].
    f_loop : float               The drive's loop rate [Hz].
    tuning : StockTuning         The tuned route (its verifying run and checks).
    encoder_cpr : int            Encoder counts per motor revolution (``sensors.encoder_cpr``; 0 = ideal).
    ratio : float                Transmission ratio N, motor revolutions per output revolution
                                 (``transmission.ratio``; a drive that works at the output divides by it).
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
    pll_bandwidth: float
    f_loop: float
    tuning: StockTuning
    encoder_cpr: int = 0
    ratio: float = 1.0


def loop_gains(loop: StockLoop) -> CascadeGains:
    """Return the loop's gains in both forms: the cascade's (pos_gain, vel_gain, k_i) and the parallel PID's."""
    if loop.law == "pid":
        return CascadeGains(loop.kp / loop.kd, loop.kd, 0.0, loop.J_ff, loop.kp, loop.kd, loop.ki)
    return CascadeGains(loop.kp, loop.kd, loop.ki, loop.J_ff, loop.kp * loop.kd, loop.kd, loop.kp * loop.ki)


def stock_settings(cmp: Comparison, drive: str = "setpoints") -> StockSettings:
    """Return the settings of stock drive ``drive`` (a key of DRIVES) for the case ``cmp`` (see the module doc)."""
    d = cmp.derived
    p = d.params
    m, c = p.motor, p.controller
    tu = tuned(DRIVES[drive], p, d)
    tr, loop = tu.trapezoid, tu.loop
    i_lim = drive_current(p)  # the simulated hard limit min(i_max, Γ_max/K_t), else Γ_max/K_t
    cycle = CONTINUOUS_CYCLE_S if c.is_continuous else 1.0 / float(c.f_s)
    return StockSettings(tr, loop_gains(loop), m.R_s, m.L_d, m.L_q, m.psi_pm, m.p, i_lim,
                         max(m.omega_b, abs(tr.omega_c)), 3.0 / c.T_si, cycle, loop.omega_e, loop.f_loop, tu,
                         p.sensors.encoder_cpr, p.transmission.ratio)


def with_stock_runs(cmp: Comparison) -> Comparison:
    """Return ``cmp`` with the stock route and the tracked optimum simulated (when missing and feasible)."""
    if cmp.fdsmc is None:
        return cmp
    p, d = cmp.derived.params, cmp.derived
    stock = cmp.stock if cmp.stock is not None else simulate(p, "stock", d)
    optimum = cmp.optimum if cmp.optimum is not None else simulate(p, "optimum", d)
    return dataclasses.replace(cmp, stock=stock, optimum=optimum)
