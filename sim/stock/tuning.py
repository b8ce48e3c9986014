"""Tune a stock drive's loops for the move: a loop-shaping rule, verified by simulating the drive's own loops.

The rule (closed form, one free bandwidth ω_v [rad/s], total inertia J = J_r + J_L of the model):

* speed loop crossover ω_v: vel_gain = J·ω_v, the speed integrator's zero a decade and a half below,
  k_i = vel_gain·ω_v/INTEGRATOR_RATIO; position loop pos_gain = ω_v/POSITION_RATIO (the cascade's
  position pole well inside the speed loop); the parallel PID of the same law kp = vel_gain·pos_gain,
  kd = vel_gain and **no integrator** (ki = 0, ilimit = 0: moteus' own advice for a high torque
  bandwidth; with one, the position error integrated over the move overshot precision windows by
  3–5 mrad on the servo presets), so a static load torque Γ_Le leaves Γ_Le/kp, which the simulation checks;
* the encoder PLL at PLL_RATIO·ω_v (it sets how much of the encoder's quantization reaches the torque);
* the inertia feed-forward J·α_ref and the planner's speed feed-forward ω_ref;
* the current loop at the drive's bandwidth 3/T_si (eq. (8) in [1]), kp = L·ω_c, ki = R·ω_c;
* ω_v at most ω_c/4 and 2π·f_loop/40 (a decade and more inside the current loop and the cycle).

The free choices are searched, fastest first, on the **simulated checks** of the drive's own loops
(:func:`sim.stock.route.simulate_stock` with the case's sensors, limits and pass criteria): the
planner's acceleration as a fraction of the design's α_max (ACCEL_FRACTIONS: the drive's feedback
needs torque headroom above J·α) and ω_v as a fraction of its ceiling (BANDWIDTH_FRACTIONS: slower
loops pass the encoder's quantization less, faster ones track tighter). The first setting whose
nominal run passes every check **and** that stays stable, within the drive's limits and settles in
the window with the load inertia J_L at ×0.5 and ×2 (ROBUST_J_L) is the tuned one. A pass/fail
search over a monotone two-parameter family is what the checks allow: they are not smooth in the
gains, so a gradient optimiser has nothing to follow.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from dataclasses import dataclass

import numpy as np

from control.fdsmc.derivations import Derived
from control.fdsmc.model import torque_constant
from control.fdsmc.params import DriveParams
from control.fdsmc.trapezoid import TrapezoidTiming, trapezoid_samples, trapezoid_timing
from sim.fdsmc.checks import Constraint, run_checks
from sim.fdsmc.criteria import drive_current
from sim.fdsmc.engine import RunResult
from sim.stock.route import StockLoop, simulate_stock

#: pos_gain = ω_v/POSITION_RATIO [-].
POSITION_RATIO = 4.0
#: Speed integrator zero at ω_v/INTEGRATOR_RATIO [-].
INTEGRATOR_RATIO = 40.0
#: PLL bandwidth = PLL_RATIO·ω_v [-].
PLL_RATIO = 4.0
#: Planner accelerations tried, as fractions of the design's α_max [-].
ACCEL_FRACTIONS = (1.0, 0.85, 0.7, 0.6, 0.5, 0.4)
#: Speed-loop bandwidths tried, as fractions of the ceiling min(ω_c/4, 2π·f_loop/40) [-].
BANDWIDTH_FRACTIONS = (1.0, 0.7, 0.5, 0.35, 0.25, 0.18, 0.125)
#: Load-inertia factors the tuned route must stay stable and in position with [-].
ROBUST_J_L = (0.5, 2.0)
#: Checks the detuned-inertia runs may fail: the window, its overshoot and the 2 % band at T_m (what the
#: inertia feed-forward buys); they must stay stable, within the limits, unsaturated and free of chatter.
ROBUST_EXEMPT = ("overshoot", "arrival", "in_position")


@dataclass(frozen=True)
class DriveSpec:
    """A stock drive's fixed control structure.

    Attributes
    ----------
    name : str           ``odrive``, ``moteus``, ``vesc`` or ``setpoints``.
    f_loop : float|None  Its cycle rate [Hz]; None: the case's controller f_s.
    law : str            ``cascade`` or ``pid`` (:mod:`control.stock.loops`).
    snap : bool          The PLL snaps small speeds to 0 (ODrive).
    speed_clamp : bool   The cascade clamps the speed demand at the drive's speed limit (ODrive).
    """

    name: str
    f_loop: float | None
    law: str
    snap: bool = False
    speed_clamp: bool = False


#: ODrive fw 0.5.x: 8 kHz loops; moteus at the file's 15 kHz PWM; VESC's current loop once per
#: switching period (foc_f_zv/2 of its file); a setpoint-table drive at the case's own f_s.
DRIVES = {"odrive": DriveSpec("odrive", 8000.0, "cascade", True, True),
          "moteus": DriveSpec("moteus", 15000.0, "pid"),
          "vesc": DriveSpec("vesc", 12500.0, "cascade"),
          "setpoints": DriveSpec("setpoints", None, "cascade")}


@dataclass(frozen=True)
class StockTuning:
    """The tuned stock route: the move, the loops and the verifying runs.

    Attributes
    ----------
    trapezoid : TrapezoidTiming  The planner's move (α [rad/s²], cruise ω_c [rad/s], T_m [s]).
    loop : StockLoop             The drive's settings (SI).
    omega_v : float              Speed-loop bandwidth [rad/s].
    accel_fraction : float       α/α_max [-].
    run : RunResult              The nominal run.
    checks : tuple               Its violated checks (empty: the route passes).
    robust : bool                Stable, within limits and settling at J_L ×ROBUST_J_L.
    tried : int                  Settings simulated [-].
    """

    trapezoid: TrapezoidTiming
    loop: StockLoop
    omega_v: float
    accel_fraction: float
    run: RunResult
    checks: tuple[Constraint, ...]
    robust: bool
    tried: int

    @property
    def clean(self) -> bool:
        """True when the nominal run passes every check and the detuned ones hold (see the module doc)."""
        return not self.checks and self.robust


def loop_rate(spec: DriveSpec, params: DriveParams) -> float:
    """Return the drive's cycle rate [Hz] (the case's f_s for a setpoint-table drive; 1 kHz if continuous)."""
    if spec.f_loop is not None:
        return spec.f_loop
    f_s = params.controller.f_s
    return 1000.0 if isinstance(f_s, str) else float(f_s)


def setpoint_table(tr: TrapezoidTiming, dt: float) -> np.ndarray:
    """Return the trapezoid sampled every ``dt`` [s] from 0 to just past T_m: 3 × n rows θ, ω, α (SI)."""
    n = int(math.ceil(tr.T_m / dt - 1e-9)) + 2
    return np.ascontiguousarray(np.vstack(trapezoid_samples(tr, np.arange(n) * dt)))


def make_loop(spec: DriveSpec, params: DriveParams, tr: TrapezoidTiming, omega_v: float) -> StockLoop:
    """Return the drive's settings for speed-loop bandwidth ``omega_v`` [rad/s] (the module's rule)."""
    J, m = params.J_total, params.motor
    f = loop_rate(spec, params)
    w_c = 3.0 / params.controller.T_si
    vel_gain, pos_gain = J * omega_v, omega_v / POSITION_RATIO
    i_lim, K_t = drive_current(params), torque_constant(m)
    if spec.law == "pid":
        kp = vel_gain * pos_gain
        gains = (kp, vel_gain, 0.0, 0.0, math.inf)
    else:
        w_lim = max(m.omega_b, abs(tr.omega_c)) if spec.speed_clamp else math.inf
        gains = (pos_gain, vel_gain, vel_gain * omega_v / INTEGRATOR_RATIO, math.inf, w_lim)
    L = 0.5 * (m.L_d + m.L_q)
    return StockLoop(spec.name, f, spec.law, *gains, J, K_t, i_lim, PLL_RATIO * omega_v, spec.snap,
                     L * w_c, m.R_s * w_c, setpoint_table(tr, 1.0 / f), 1.0 / f)


def bandwidth_ceiling(params: DriveParams, f_loop: float) -> float:
    """ω_v's ceiling min(ω_c/4, 2π·f_loop/40) [rad/s], ω_c = 3/T_si."""
    return min(0.75 / params.controller.T_si, 2.0 * math.pi * f_loop / 40.0)


def with_load_inertia(params: DriveParams, factor: float) -> DriveParams:
    """``params`` with J_L scaled by ``factor`` (the detuned plant)."""
    return dataclasses.replace(params, load=dataclasses.replace(params.load, J_L=factor * params.load.J_L))


def robust(params: DriveParams, loop: StockLoop, d: Derived) -> bool:
    """Return True when the route stays stable, within limits and settles with J_L at every ROBUST_J_L factor."""
    for factor in ROBUST_J_L:
        run = simulate_stock(params, loop, d, plant=with_load_inertia(params, factor))
        if any(c.name not in ROBUST_EXEMPT for c in run_checks(params, run)):
            return False
    return True


def trapezoids(params: DriveParams, d: Derived) -> list[tuple[float, TrapezoidTiming]]:
    """Return the feasible planner moves (α fraction, trapezoid) within the speed limit, fastest α first."""
    out = []
    for frac in ACCEL_FRACTIONS:
        disc = params.manoeuvre.T_m ** 2 - 4.0 * abs(params.manoeuvre.theta_dem) / (frac * d.alpha.alpha_max)
        if disc < 0.0:
            break
        tr = trapezoid_timing(params.manoeuvre.theta_dem, frac * d.alpha.alpha_max, params.manoeuvre.T_m)
        out.append((frac, tr))
    return out


def tune(spec: DriveSpec, params: DriveParams, d: Derived) -> StockTuning:
    """Return the fastest setting of the family that passes (see the module doc), else the last one tried.

    The trial that failed least (fewest violated checks) is returned when none passes, with its checks.
    """
    f = loop_rate(spec, params)
    ceiling = bandwidth_ceiling(params, f)
    best: StockTuning | None = None
    tried = 0
    for frac, tr in trapezoids(params, d):
        for s in BANDWIDTH_FRACTIONS:
            loop = make_loop(spec, params, tr, s * ceiling)
            run = simulate_stock(params, loop, d)
            tried += 1
            checks = tuple(run_checks(params, run))
            ok = not checks and robust(params, loop, d)
            cand = StockTuning(tr, loop, s * ceiling, frac, run, checks, ok, tried)
            if ok:
                return cand
            if best is None or len(checks) < len(best.checks):
                best = cand
    if best is None:  # no feasible trapezoid: the design's own α_max move
        tr = trapezoid_timing(params.manoeuvre.theta_dem, d.alpha.alpha_max, params.manoeuvre.T_m)
        loop = make_loop(spec, params, tr, ceiling)
        run = simulate_stock(params, loop, d)
        best = StockTuning(tr, loop, ceiling, 1.0, run, tuple(run_checks(params, run)), False, tried + 1)
    return dataclasses.replace(best, tried=tried)




#: Tuned routes by (drive, case without its K and T_c); the oldest dropped beyond CACHE_SIZE.
_CACHE: dict[tuple[DriveSpec, DriveParams], StockTuning] = {}
_CACHE_LOCK = threading.Lock()
CACHE_SIZE = 64


def tuned(spec: DriveSpec, params: DriveParams, d: Derived) -> StockTuning:
    """:func:`tune`, remembered per drive and case (a change of the FDSMC's K or T_c does not re-tune it)."""
    ctrl = dataclasses.replace(params.controller, K=1.0, T_c="T_a")
    key = (spec, dataclasses.replace(params, controller=ctrl))
    with _CACHE_LOCK:
        hit = _CACHE.get(key)
    if hit is not None:
        return hit
    result = tune(spec, params, d)
    with _CACHE_LOCK:
        if len(_CACHE) >= CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = result
    return result
