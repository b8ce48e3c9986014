"""Closed-loop simulation engine: one run and the comparison of the controllers (Table 1: :mod:`sim.fdsmc.table1`).

The model (plant, FDC inner loops, observer, outer loop, energies) is integrated by the
compiled kernel :func:`sim.fdsmc.kernel_run.run_kernel`; this module packs the parameters, chooses the
time grid, and turns the raw arrays into frozen results with their :class:`~sim.fdsmc.metrics.RunMetrics`.

Rest-to-rest manoeuvre from θ_r = 0 to θ_dem, simulated over [0, (1 + TAIL_FRACTION)·T_m] (the time
grid and the cost budget are in :mod:`sim.fdsmc.grid`).
Energies without suffix are integrals over [0, T_m] (the paper's W_L, eq. (47) in [1]); the
``_total`` ones are over the whole simulated horizon.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.fdc import mismatch_filter_factor
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.inverter import decay_factors
from pmsm_commissioning.control.fdsmc.model import model_coefficients, torque_constant
from pmsm_commissioning.control.fdsmc.optimum import OptimumSolverError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import infeasible_T_m
from pmsm_commissioning.control.fdsmc.tracking import optimum_slide, tracking_gains
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.common.choices import check_controller
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import kernel_run
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.grid import (
    CONTINUOUS_STEP_S,
    MAX_POINTS,
    TimeGrid,
    check_budget,
    continuous_step,
    load_steps,
    time_grid,
)
from pmsm_commissioning.sim.fdsmc.metrics import (
    RunMetrics,
    WindowSamples,
    chatter_window_steps,
    chatter_windows,
    run_metrics,
)
from pmsm_commissioning.sim.fdsmc.summary import decode_info
from pmsm_commissioning.sim.fdsmc.trace import Trace as Trace  # re-exported: RunResult.trace

CONTROLLERS = ("fdsmc", "conventional")
#: Every simulated outer loop: the two controllers and the tracked minimum-energy optimum
#: (:mod:`control.fdsmc.optimum`); the kernel's P_CTRL is the index in this tuple.
COMPARATORS = CONTROLLERS + ("optimum", "stock")
#: The name each simulated outer loop goes by in messages, tables and figures.
LABELS = {"fdsmc": "FDSMC", "conventional": "Conventional", "optimum": "Optimum", "stock": "Stock drive"}
#: The kernel's outer law (P_CTRL) of each comparator on the FDC inner loops; the stock drive runs its own
#: loops instead (P_CTRL = 4, :mod:`sim.stock.route`).
KERNEL_LAW = {"fdsmc": 0.0, "conventional": 1.0, "optimum": 3.0}
#: The kernel's law that tracks the optimum's reference to the very end, without its terminal slide:
#: the yardstick of what the slide removes (the observer's lag carries the rotor past θ_dem).
TRACKING_TO_THE_END = 2.0
#: Threads that run the second and further controllers of every :func:`compare` in this process
#: (the caller's thread runs the first). Shared, so that many callers at once (one per browser
#: client) do not oversubscribe the cores, and no thread is started per call.
RUN_THREADS = max(2, os.cpu_count() or 2)
_RUNS = ThreadPoolExecutor(max_workers=RUN_THREADS, thread_name_prefix="sim-run")


def start_run_threads() -> None:
    """Start every thread of the shared run pool now, from the caller's thread.

    A new thread inherits its creator's scheduling priority, so a server calls this at start-up:
    no shared thread is then created later by a lower-priority caller (a study) and kept.
    """
    gate = threading.Barrier(RUN_THREADS)  # each task waits until all threads run one
    for f in [_RUNS.submit(gate.wait, 10.0) for _ in range(RUN_THREADS)]:
        f.result()


@dataclass(frozen=True)
class RunResult:
    """One controller's run: trace and the metrics of ``simulate --json``."""

    controller: str
    trace: Trace
    metrics: RunMetrics


@dataclass(frozen=True)
class Comparison:
    """FDSMC and conventional runs of one case and the savings [%] (None if not both stable).

    ``saving_friction_pct`` compares friction over [0, T_m] (eq. (47) in [1]);
    ``saving_electrical_pct`` compares the net electrical input over the whole horizon.
    ``optimum`` is the tracked minimum-energy move, ``stock`` the stock drive's trapezoid, when asked for;
    ``notes`` say why an asked-for comparator is missing (e.g. the optimum's solvers failed).
    """

    derived: Derived
    fdsmc: RunResult | None
    conventional: RunResult | None
    saving_friction_pct: float | None
    saving_electrical_pct: float | None
    optimum: RunResult | None = None
    stock: RunResult | None = None
    notes: tuple[str, ...] = ()


def pack_parameters(params: DriveParams, d: Derived, controller: str,
                    plant: DriveParams | None = None, T_step: float | None = None) -> np.ndarray:
    """Return the kernel's flat parameter vector (indices ``P_*`` of :mod:`sim.fdsmc.kernel`).

    ``params``/``d`` are the controller's model; ``plant`` (default: the same) gives the true
    motor and load values the simulated drive has (R_s, L_d, L_q, Ψ_PM, p, J_r, J_L, F_v, Γ_Le).
    ``T_step`` [s] is the interval the current limit predicts over: the sample period (default
    1/f_s), or the integration step of the continuous mode (default :func:`continuous_step`).
    """
    c, ctrl = d.coefficients, params.controller
    pl = params if plant is None else plant
    m, ld, cp = pl.motor, pl.load, c if plant is None else model_coefficients(pl.motor)
    prm = np.zeros(kn.N_PRM)
    for name, idx in zip("ABCDEFGHKM", (kn.P_A, kn.P_B, kn.P_C, kn.P_D, kn.P_E, kn.P_F, kn.P_G,
                                         kn.P_H, kn.P_K, kn.P_M), strict=True):
        prm[idx] = getattr(c, name)
    for name, idx in zip("ABCDEFG", (kn.P_PA, kn.P_PB, kn.P_PC, kn.P_PD, kn.P_PE, kn.P_PF, kn.P_PG),
                         strict=True):
        prm[idx] = getattr(cp, name)
    prm[[kn.P_RS, kn.P_LD, kn.P_LQ, kn.P_PSI, kn.P_P, kn.P_JR]] = (
        m.R_s, m.L_d, m.L_q, m.psi_pm, m.p, m.J_r)
    prm[[kn.P_JT, kn.P_FV, kn.P_TSI, kn.P_TSA]] = (pl.J_total, ld.F_v, ctrl.T_si, ctrl.T_salpha)
    prm[kn.P_CTRL] = KERNEL_LAW[controller]
    pr, o = d.profile, d.observer
    prm[[kn.P_THDEM, kn.P_OMP, kn.P_TC, kn.P_KB, kn.P_AMAX]] = (
        params.manoeuvre.theta_dem, pr.omega_p, pr.T_c, ctrl.K, d.alpha.alpha_max)
    gains = d.conventional
    if controller == "optimum":  # its own K (below the chatter limit), tracking gains and terminal slide's T_c
        K, T_c = optimum_slide(d.gain, ctrl.K, d.alpha.alpha_max)
        gains = tracking_gains(d.loop, d.conventional, K)
        prm[[kn.P_TC, kn.P_KB]] = (T_c, K)
    prm[[kn.P_G1, kn.P_G2]] = (gains.g1, gains.g2)
    if controller == "optimum":  # α(t) ≈ α_dem(t − T_sα/3) (eq. (13)), one more sample with a delay
        prm[kn.P_LEAD] = ctrl.T_salpha / 3.0 + (0.0 if ctrl.is_continuous else ctrl.delay_samples / float(ctrl.f_s))
    prm[[kn.P_K1, kn.P_K2, kn.P_K3, kn.P_K4]] = (o.K1, o.K2, o.K3, o.K4)
    if not ctrl.is_continuous:  # β of the q-axis voltage-mismatch estimate (0: none)
        prm[kn.P_BDV] = mismatch_filter_factor(ctrl.T_dv, float(ctrl.f_s))
    prm[[kn.P_UMAX, kn.P_IMAX]] = (ctrl.V_dc / math.sqrt(3.0), current_limit(params))  # 0 = no limit
    prm[[kn.P_TM, kn.P_GLE0, kn.P_GRAMP]] = (params.manoeuvre.T_m, ld.Gamma_Le, ld.Gamma_Le_ramp)
    m = params.motor
    w_scale = max(m.omega_b, pr.omega_p, abs(params.manoeuvre.theta_dem) / params.manoeuvre.T_m)
    i_scale = max(m.Gamma_max, d.alpha.torque_needed) / torque_constant(m)
    prm[[kn.P_WLIM, kn.P_ILIM]] = (20.0 * w_scale, 100.0 * i_scale)
    _pack_sensors(prm, params, d, T_step)
    return prm


def _pack_sensors(prm: np.ndarray, params: DriveParams, d: Derived, T_step: float | None) -> None:
    """Sensor steps, the current predictor's factors over ``T_step`` and the in-position window."""
    se, c = params.sensors, d.coefficients
    prm[[kn.P_ENC, kn.P_INOISE, kn.P_ISTEP, kn.P_IFS]] = (
        se.encoder_step, se.i_noise, se.adc_step, se.i_adc_range)
    if T_step is None:
        ctrl = params.controller
        T_step = continuous_step(params) if ctrl.is_continuous else 1.0 / float(ctrl.f_s)
    prm[[kn.P_PHID, kn.P_GMID]] = decay_factors(c.A, T_step)
    prm[[kn.P_PHIQ, kn.P_GMIQ]] = decay_factors(c.D, T_step)
    prm[kn.P_INPOS] = pass_criteria(params).in_position


def _observer_arrays(d: Derived) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    od = d.observer_discrete
    if od is None:
        return np.zeros((4, 4)), np.zeros(4), np.zeros(4)
    return np.ascontiguousarray(od.Phi), np.ascontiguousarray(od.Gamma), np.ascontiguousarray(od.L)


def _reference(d: Derived, controller: str) -> np.ndarray:
    """Return the kernel's reference rows (θ_ref, ω_ref, α_ref): the tracked optimum's, else zeros."""
    if controller != "optimum":
        return np.zeros((3, 2))
    from pmsm_commissioning.control.fdsmc.optimum import tracked_move  # imports cvxpy only when limits are active

    mv = tracked_move(d)
    return np.ascontiguousarray(np.vstack((mv.theta, mv.omega, mv.alpha)))


def _check_feasible(d: Derived) -> None:
    pr, T_m = d.profile, d.params.manoeuvre.T_m
    if not pr.feasible:
        raise ParameterError(infeasible_T_m(T_m, pr.T_m_min, pr.delta_theta, d.alpha.alpha_max))


def simulate(
    params: DriveParams,
    controller: str = "fdsmc",
    derived: Derived | None = None,
    *,
    n_sub: int = 1,
    h_continuous: float = CONTINUOUS_STEP_S,
    max_points: int = MAX_POINTS,
    plant: DriveParams | None = None,
) -> RunResult:
    """Simulate one rest-to-rest manoeuvre with the FDC inner loops and the chosen outer loop.

    Parameters
    ----------
    params : DriveParams
        The commissioning case.
    controller : str
        ``"fdsmc"`` (eqs. 41–46 in [1]), ``"conventional"`` (eq. 62 sign-corrected) or
        ``"optimum"`` (the minimum-energy move of :mod:`control.fdsmc.optimum`, tracked) or ``"stock"``
        (the trapezoid of :mod:`control.fdsmc.trapezoid` tracked by the stock drive's cascade).
    derived : Derived or None
        ``derive(params)`` if already computed.
    n_sub : int
        Least RK4 substeps per sample in digital mode [-] (more if :func:`plant_substeps` asks).
    h_continuous : float
        Largest RK4 step in continuous mode [s] (see :func:`continuous_step`).
    max_points : int
        Most trace points kept [-].
    plant : DriveParams or None
        The drive's true motor and load values when they differ from the controller's model
        ``params`` (see :func:`pack_parameters`); None: the plant is the model.

    Returns
    -------
    RunResult
        Never raises for an unstable run: ``metrics.stable`` is False with a ``reason``.

    Raises
    ------
    ParameterError
        For an unknown controller or an infeasible manoeuvre (T_m < T_m,min).
    """
    check_controller(controller, COMPARATORS)
    check_budget(params, 1, n_sub=n_sub, h_continuous=h_continuous, max_points=max_points)
    d = derive(params) if derived is None else derived
    _check_feasible(d)
    return _simulate_checked(params, controller, d, n_sub=n_sub, h_continuous=h_continuous, max_points=max_points,
                             plant=plant)


def _simulate_checked(
    params: DriveParams, controller: str, d: Derived, *, n_sub: int = 1, h_continuous: float = CONTINUOUS_STEP_S,
    max_points: int = MAX_POINTS, plant: DriveParams | None = None,
) -> RunResult:
    """:func:`simulate` once the controller, the budget and the feasibility are checked (by the caller).

    ``"stock"`` is the stock route of a setpoint-table drive: its own P–PI cascade, PLL and current PI at
    f_s, tuned on the simulated checks (:mod:`sim.stock.tuning`), run on ``plant`` when given.
    """
    if controller == "stock":
        from pmsm_commissioning.sim.stock.route import simulate_stock
        from pmsm_commissioning.sim.stock.tuning import DRIVES, tuned

        tu = tuned(DRIVES["setpoints"], params, d)
        return tu.run if plant is None else simulate_stock(params, tu.loop, d, plant)
    g = time_grid(params, int(n_sub), float(h_continuous), int(max_points))
    prm = pack_parameters(params, d, controller, plant, g.h * g.n_sub)
    return run_packed(params, d, controller, g, prm, _reference(d, controller), _observer_arrays(d), plant)


def run_packed(params: DriveParams, d: Derived, controller: str, g: TimeGrid, prm: np.ndarray, ref: np.ndarray,
               observer: tuple[np.ndarray, np.ndarray, np.ndarray], plant: DriveParams | None) -> RunResult:
    """Run the kernel on the grid ``g`` with the packed ``prm`` and return the run's trace and metrics.

    ``ref`` is the kernel's reference or setpoint table, ``observer`` its discrete (Φ, Γ, L); the
    sensors' noise, the load steps (of ``plant`` when given), the chatter windows and the metrics are
    those of :func:`simulate`.
    """
    T_step = g.h * g.n_sub
    step_t, step_v = load_steps(params if plant is None else plant)
    out = np.zeros((kn.N_CH, g.n_out))
    info = np.zeros(kn.N_INFO)
    windows = chatter_windows(params, d, controller, g.n_steps * T_step)
    steps = [chatter_window_steps(w, T_step, g.n_steps) for w in windows.values()]
    k_win = np.array([k0 for k0, _ in steps], dtype=np.int64)
    win = np.zeros((kn.WIN_ROWS * len(steps), max(n for _, n in steps)))
    kernel_run.run_kernel(prm, step_t, step_v, *observer, g.continuous, g.h, g.n_steps, g.n_sub,
                          params.controller.delay_samples, g.decim, out, info, k_win, win, ref,
                          sensors.noise_table(params.sensors))
    summary = decode_info(info)
    trace = _trace(out[:, : summary.n_out])
    rows = kn.WIN_ROWS
    samples = {name: WindowSamples(w, (k0 + np.arange(n)) * T_step, *win[rows * j: rows * (j + 1), :n])
               for j, ((name, w), (k0, n)) in enumerate(zip(windows.items(), steps, strict=True))}
    met = run_metrics(params, d, controller, trace.t, trace.theta_r, samples, summary, plant, T_step=T_step)
    return RunResult(controller, trace, met)


def run_steps(
    params: DriveParams, controller: str, n_steps: int, *, n_sub: int = 1,
    h_continuous: float = CONTINUOUS_STEP_S, derived: Derived | None = None,
) -> np.ndarray:
    """Run the kernel for ``n_steps`` samples (digital) or RK4 steps (continuous) from rest.

    Returns
    -------
    numpy.ndarray
        Final kernel state [i_d, i_q, θ_r, ω_r, E_f, E_cu, E_el, E_mot, E_load, θ̂, ω̂, L̂0, L̂1]
        (indices ``X_*`` of :mod:`sim.fdsmc.kernel`; SI units).
    """
    check_controller(controller, COMPARATORS)
    d = derive(params) if derived is None else derived
    cont = params.controller.is_continuous
    h = h_continuous if cont else 1.0 / float(params.controller.f_s) / n_sub
    prm = pack_parameters(params, d, controller, T_step=h if cont else h * n_sub)
    step_t, step_v = load_steps(params)
    Phi, Gam, Lo = _observer_arrays(d)
    out = np.zeros((kn.N_CH, 1))
    info = np.zeros(kn.N_INFO)
    kernel_run.run_kernel(prm, step_t, step_v, Phi, Gam, Lo, cont, h, int(n_steps), 1 if cont else n_sub,
                          params.controller.delay_samples, int(n_steps) + 1, out, info,
                          np.zeros(0, dtype=np.int64), np.zeros((0, 0)), _reference(d, controller),
                          sensors.noise_table(params.sensors))
    return info[kn.I_END: kn.I_END + kn.N_X].copy()


def _trace(chans: np.ndarray) -> Trace:
    """Trace from the kernel's channel-major output (each row is one contiguous channel)."""
    finite = np.all(np.isfinite(chans), axis=0)
    if not np.all(finite):
        chans = chans[:, : int(np.argmin(finite))]
    return Trace(**{name: chans[i] for i, name in enumerate(kn.CHANNELS)})


def reached_target(run: RunResult) -> bool:
    """Return True when the run is stable and θ_r entered the 2 % band around θ_dem.

    A run that never gets there (e.g. a rotor that never moves) has no energy figure worth comparing.
    """
    return run.metrics.stable and run.metrics.t_2pct_first_s is not None


def _saving(a: RunResult | None, b: RunResult | None, energy: Callable[[RunMetrics], float | None]) -> float | None:
    """100·(1 − energy(a)/energy(b)) [%], None unless both runs reached the target."""
    if a is None or b is None or not (reached_target(a) and reached_target(b)):
        return None
    va, vb = energy(a.metrics), energy(b.metrics)
    if va is None or vb is None or vb == 0.0:
        return None
    return 100.0 * (1.0 - va / vb)


#: The start of the note that says the optimum was left out of a comparison or a duty cycle.
OPTIMUM_OMITTED = "Optimum omitted"


def optimum_omitted(exc: OptimumSolverError) -> str:
    """Return the one-line note of an optimum no solver found (it is a yardstick: left out, never a stop)."""
    return f"{OPTIMUM_OMITTED}: {exc}"


def compare(
    params: DriveParams, controllers: tuple[str, ...] = CONTROLLERS, derived: Derived | None = None,
    plant: DriveParams | None = None, **options: Any,
) -> Comparison:
    """Simulate both controllers on the same case (thread-safe; the kernel releases the GIL).

    Parameters
    ----------
    params : DriveParams
    controllers : tuple of str
        Any of ``"fdsmc"``, ``"conventional"``, ``"optimum"``.
    derived : Derived or None
        ``derive(params)`` if already computed.
    plant : DriveParams or None
        The drive's true values (see :func:`simulate`); None: the controller's model.
    **options
        Passed to :func:`simulate` (``n_sub``, ``h_continuous``, ``max_points``).

    Returns
    -------
    Comparison
        Savings are None unless both runs exist, are stable and reached the 2 % band.
    """
    for name in controllers:
        check_controller(name, COMPARATORS)
    check_budget(params, len(controllers), **options)
    d = derive(params) if derived is None else derived
    _check_feasible(d)
    # checked once above for all runs (the budget of len(controllers) runs covers each one's)
    futures = {c: _RUNS.submit(_simulate_checked, params, c, d, plant=plant, **options) for c in controllers[1:]}
    runs = {c: _simulate_checked(params, c, d, plant=plant, **options) for c in controllers[:1]}
    notes: list[str] = []
    for name, fut in futures.items():
        try:
            runs[name] = fut.result()
        except OptimumSolverError as exc:  # the optimum is a yardstick: left out with a note, never a traceback
            notes.append(optimum_omitted(exc))
    f, c = runs.get("fdsmc"), runs.get("conventional")
    return Comparison(d, f, c, _saving(f, c, lambda m: m.friction_J),
                      _saving(f, c, lambda m: m.electrical_in_total_J), runs.get("optimum"), runs.get("stock"),
                      tuple(notes))
