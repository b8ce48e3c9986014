"""Closed-loop simulation engine: one run and the comparison of the controllers (Table 1: :mod:`sim.fdsmc.table1`).

The model (plant, FDC inner loops, observer, outer loop, energies) is integrated by the
compiled kernel :func:`sim.fdsmc.kernel_run.run_kernel`; this module checks the request, chooses the
time grid and runs each controller through :mod:`sim.fdsmc.run` (the packed parameters, the frozen
:class:`~sim.fdsmc.run.RunResult` with its :class:`~sim.fdsmc.metrics.RunMetrics`), the stock drive through
:mod:`sim.stock`.

Rest-to-rest manoeuvre from θ_r = 0 to θ_dem, simulated over [0, (1 + TAIL_FRACTION)·T_m] (the time
grid and the cost budget are in :mod:`sim.fdsmc.grid`).
Energies without suffix are integrals over [0, T_m] (the paper's W_L, eq. (47) in [1]); the
``_total`` ones are over the whole simulated horizon.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.optimum import OptimumSolverError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import infeasible_T_m
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.common.choices import check_controller
from pmsm_commissioning.sim.fdsmc import kernel_run
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.grid import CONTINUOUS_STEP_S, MAX_POINTS, check_budget, load_steps, time_grid
from pmsm_commissioning.sim.fdsmc.metrics import RunMetrics

# One run's parts, re-exported where the callers of simulate() and compare() read them.
from pmsm_commissioning.sim.fdsmc.run import KERNEL_LAW as KERNEL_LAW
from pmsm_commissioning.sim.fdsmc.run import LABELS as LABELS
from pmsm_commissioning.sim.fdsmc.run import TRACKING_TO_THE_END as TRACKING_TO_THE_END
from pmsm_commissioning.sim.fdsmc.run import RunResult as RunResult
from pmsm_commissioning.sim.fdsmc.run import observer_arrays, pack_parameters, reference_rows, run_packed
from pmsm_commissioning.sim.fdsmc.trace import Trace as Trace
from pmsm_commissioning.sim.stock.route import simulate_stock
from pmsm_commissioning.sim.stock.tuning import DRIVES, tuned

CONTROLLERS = ("fdsmc", "conventional")
#: Every simulated outer loop: the two controllers and the tracked minimum-energy optimum
#: (:mod:`control.fdsmc.optimum`); the kernel's P_CTRL is the index in this tuple.
COMPARATORS = CONTROLLERS + ("optimum", "stock")
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
        tu = tuned(DRIVES["setpoints"], params, d)
        return tu.run if plant is None else simulate_stock(params, tu.loop, d, plant)
    g = time_grid(params, int(n_sub), float(h_continuous), int(max_points))
    prm = pack_parameters(params, d, controller, plant, g.h * g.n_sub)
    return run_packed(params, d, controller, g, prm, reference_rows(d, controller), observer_arrays(d), plant)


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
    Phi, Gam, Lo = observer_arrays(d)
    out = np.zeros((lay.N_CH, 1))
    info = np.zeros(lay.N_INFO)
    kernel_run.run_kernel(prm, step_t, step_v, Phi, Gam, Lo, cont, h, int(n_steps), 1 if cont else n_sub,
                          params.controller.delay_samples, int(n_steps) + 1, out, info,
                          np.zeros(0, dtype=np.int64), np.zeros((0, 0)), reference_rows(d, controller),
                          sensors.noise_table(params.sensors))
    return info[lay.I_END: lay.I_END + lay.N_X].copy()


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
