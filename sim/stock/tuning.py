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

The free choices are searched on the **simulated checks** of the drive's own loops
(:func:`sim.stock.route.simulate_stock` with the case's sensors, limits and pass criteria): the
planner's acceleration as a fraction of the design's α_max (ACCEL_FRACTIONS: the drive's feedback
needs torque headroom above J·α) and ω_v as a fraction of its ceiling (BANDWIDTH_FRACTIONS: slower
loops pass the encoder's quantization less, faster ones track tighter). The search starts from the
fastest move and loops and lets each failure choose the next step (:func:`next_step`): a limit or
saturation lowers the acceleration, anything else (the sensors' ripple, the window, overshoot)
lowers ω_v first; each setting's cost is predicted before it runs and the search stops at the
request budget.
The first setting whose nominal run passes every check **and** that stays stable, within the
drive's limits, unsaturated and free of chatter with the load inertia J_L at ×0.5 and ×2
(ROBUST_J_L, the robustness margin) is the tuned one. A guided pass/fail search is what the checks
allow: they are not smooth in the gains, so a gradient optimiser has nothing to follow.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.model import torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.trapezoid import TrapezoidTiming, trapezoid_samples, trapezoid_timing
from pmsm_commissioning.sim.common.budget import MAX_CPU_S
from pmsm_commissioning.sim.fdsmc.checks import Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.criteria import drive_current
from pmsm_commissioning.sim.fdsmc.grid import check_budget
from pmsm_commissioning.sim.fdsmc.run import RunResult
from pmsm_commissioning.sim.stock.route import StockLoop, at_loop_rate, simulate_stock

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
#: Failed checks that ask for a gentler move (torque headroom) rather than slower loops.
LIMITS = frozenset({"torque", "current", "voltage", "speed", "saturation"})
#: The search's most nominal runs, each with at most len(ROBUST_J_L) detuned ones [-].
MAX_TRIES = len(ACCEL_FRACTIONS) * len(BANDWIDTH_FRACTIONS)
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
    budget_stop : bool           The search stopped at the request budget before a setting passed.
    """

    trapezoid: TrapezoidTiming
    loop: StockLoop
    omega_v: float
    accel_fraction: float
    run: RunResult
    checks: tuple[Constraint, ...]
    robust: bool
    tried: int
    budget_stop: bool = False

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


def robust_failures(params: DriveParams, loop: StockLoop, d: Derived) -> set[str]:
    """Return the checks the route fails with J_L at any ROBUST_J_L factor (ROBUST_EXEMPT aside); empty: robust."""
    failed: set[str] = set()
    for factor in ROBUST_J_L:
        run = simulate_stock(params, loop, d, plant=with_load_inertia(params, factor))
        failed |= {c.name for c in run_checks(params, run) if c.name not in ROBUST_EXEMPT}
    return failed


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


def next_step(failed: set[str], ia: int, js: int) -> tuple[int, int]:
    """Return the search's next (acceleration index, bandwidth index) after a setting failed ``failed``.

    A limit of the drive or the saturation asks for a gentler move (more torque headroom: the next
    acceleration, the same loops); anything else — the sensors' ripple, chatter, the window, the
    overshoot, a detuned-inertia failure — for slower loops, and once the slowest has failed, for the
    next acceleration from the fastest loops again.
    """
    if failed & LIMITS:
        return ia + 1, js
    if js + 1 < len(BANDWIDTH_FRACTIONS):
        return ia, js + 1
    return ia + 1, 0


def tune(spec: DriveSpec, params: DriveParams, d: Derived) -> StockTuning:
    """Return the first setting of the guided search that passes (see the module doc).

    From the fastest move and loops, each failure steps the acceleration or the bandwidth down
    (:func:`next_step`), at most MAX_TRIES settings. The cost of each setting's runs (nominal and
    detuned) is predicted before they start: the search stops where the next setting would take the
    whole search past the request budget (:data:`sim.common.budget.MAX_CPU_S`), and ``budget_stop``
    says so. When none passes, the trial that failed fewest checks is returned with its checks.

    Raises
    ------
    BudgetError
        When even one run of the drive's loops exceeds the run budget (naming the fields that set it).
    """
    f = loop_rate(spec, params)
    one = check_budget(at_loop_rate(params, f), 1).cpu_s or 0.0  # a single run must fit: else nothing runs
    per_setting = (1 + len(ROBUST_J_L)) * one
    ceiling, moves = bandwidth_ceiling(params, f), trapezoids(params, d)
    if not moves:  # no feasible trapezoid: the design's own α_max move, as it is
        moves = [(1.0, trapezoid_timing(params.manoeuvre.theta_dem, d.alpha.alpha_max, params.manoeuvre.T_m))]
    best: StockTuning | None = None
    ia = js = tried = 0
    while ia < len(moves) and js < len(BANDWIDTH_FRACTIONS):
        if (tried + 1) * per_setting > MAX_CPU_S and best is not None:
            return dataclasses.replace(best, tried=tried, budget_stop=True)
        (frac, tr), w_v = moves[ia], BANDWIDTH_FRACTIONS[js] * ceiling
        loop = make_loop(spec, params, tr, w_v)
        run = simulate_stock(params, loop, d)
        tried += 1
        checks = tuple(run_checks(params, run))
        failed = {c.name for c in checks} or robust_failures(params, loop, d)
        cand = StockTuning(tr, loop, w_v, frac, run, checks, not failed, tried)
        if not failed:
            return cand
        if best is None or len(checks) < len(best.checks):
            best = cand
        ia, js = next_step(failed, ia, js)
    assert best is not None
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
