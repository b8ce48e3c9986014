"""Monte-Carlo robustness: the controllers designed on the nominal model, run on sampled plants.

Each sample draws the plant's true motor/load values from stated distributions (the controller
keeps its model: the preset), simulates the FDSMC and the conventional controller on it, and
the distributions of the run metrics are summarised. Samples are drawn from one
``numpy.random.default_rng(seed)`` in a fixed order before any work is handed out, so the result
depends only on (params, spreads, samples, seed) — not on the executor, the number of workers
or the chunking. Work is handed to any executor with ``submit(fn, *args) -> future`` and
``future.result()`` (``concurrent.futures.ProcessPoolExecutor`` locally, a
``dask.distributed.Client`` on a cluster), chunk by chunk; results are collected in order.

The controller's model is the nominal one, so its design ``derive(params)`` is computed once and
handed to every task; a task runs its samples in batches of compiled calls
(:func:`sim.studies.batch.simulate_batch`). A Monte-Carlo without a spread is refused unless it is
one sample (the nominal run, said so in the summary). When a task fails (a cluster lost, a pool
broken twice), :class:`IncompleteRunError` carries the samples finished before it, in order.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.feasibility import LIMIT_TOLERANCE, torque_limit
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import CONTROLLERS, RunResult, _check_feasible, reached_target, simulate
from pmsm_commissioning.sim.fdsmc.grid import check_budget
from pmsm_commissioning.sim.studies.batch import simulate_batch
from pmsm_commissioning.sim.studies.runner import ExecutorError

#: The controllers a study can run: the two of [1] and the tracked minimum-energy optimum.
STUDY_CONTROLLERS = ("fdsmc", "conventional", "optimum")
#: Metrics summarised per controller; the worst case is the largest value (errors as |·|).
METRICS = ("friction_J", "copper_J", "electrical_in_total_J", "torque_peak_Nm",
           "theta_error_abs_at_Tm_rad", "t_2pct_settle_s")
#: Each task should compute for at least this long [s] (scheduling overhead stays small).
MIN_TASK_S = 0.1
#: Tasks per worker a run is cut into at most [-]: enough for progress, cancelling and balancing
#: the load, few enough that handing out tasks (and pickling their arguments) costs nothing.
TASKS_PER_WORKER = 16
#: Trace points kept per run (metrics only; the 2 % settling time is read from this trace).
TRACE_POINTS = 2000
#: Largest σ of a normal spread, relative to the nominal value [-] (kept well away from ≤ 0).
MAX_NORMAL_SIGMA = 0.3


@dataclass(frozen=True)
class Spread:
    """Distribution of one plant value.

    section "motor"/"load"; field the parameter's name; kind "uniform" (absolute lo…hi in SI),
    "relative" (uniform nominal·(1 + lo…hi)) or "normal" (nominal·(1 + σ·N(0, 1)) with σ = hi,
    truncated at ±3σ by redrawing).
    """

    section: str
    field: str
    kind: str
    lo: float
    hi: float


@dataclass(frozen=True)
class RobustnessResult:
    """Per-sample metrics (``runs[i][controller][metric]``), the drawn values and the summary.

    ``complete`` is False for the part of a run that failed (``runs`` then holds its first samples);
    ``controllers`` are those run on every sample.
    """

    values: dict[str, np.ndarray]
    runs: list[dict[str, dict[str, Any]]]
    summary: dict[str, Any]
    complete: bool = True
    controllers: tuple[str, ...] = CONTROLLERS


class IncompleteRunError(RuntimeError):
    """A run stopped by a failure of its executor; ``partial`` holds the samples finished before it."""

    def __init__(self, message: str, partial: RobustnessResult) -> None:
        super().__init__(message)
        self.partial = partial


def draw(params: DriveParams, spreads: Sequence[Spread], n: int, seed: int) -> dict[str, np.ndarray]:
    """N values [SI] of each spread's field, keyed ``section.field``, from one seeded generator."""
    rng = np.random.default_rng(seed)
    out: dict[str, np.ndarray] = {}
    for s in spreads:
        nominal = float(getattr(getattr(params, s.section), s.field))
        if s.kind == "uniform":
            v = rng.uniform(s.lo, s.hi, n) if s.hi > s.lo else np.full(n, s.lo)
        elif s.kind == "relative":
            v = nominal * (1.0 + (rng.uniform(s.lo, s.hi, n) if s.hi > s.lo else np.full(n, s.lo)))
        else:
            z = rng.standard_normal(n)
            while np.any(bad := np.abs(z) > 3.0):
                z[bad] = rng.standard_normal(int(np.count_nonzero(bad)))
            v = nominal * (1.0 + s.hi * z)
        out[f"{s.section}.{s.field}"] = v
    return out


def plant_for(params: DriveParams, values: dict[str, float]) -> DriveParams:
    """``params`` with the plant values ``{"section.field": value}`` replaced (validated)."""
    changes: dict[str, dict[str, Any]] = {"motor": {}, "load": {}}  # replace() fields of any type
    for key, v in values.items():
        section, field = key.split(".")
        changes[section][field] = float(v)
    return dataclasses.replace(params, motor=dataclasses.replace(params.motor, **changes["motor"]),
                               load=dataclasses.replace(params.load, **changes["load"]))


def _friction_saving(f: RunResult, c: RunResult) -> float | None:
    """Return FDSMC's friction saving vs the conventional controller [%].

    Eq. (47) in [1] over [0, T_m]; None unless both runs are stable and reached the 2 % band.
    """
    if not (reached_target(f) and reached_target(c)):
        return None
    wf, wc = f.metrics.friction_J, c.metrics.friction_J
    if wf is None or wc is None or wc == 0.0:
        return None
    return 100.0 * (1.0 - wf / wc)


def sample_metrics(params: DriveParams, plant: DriveParams, d: Derived | None = None,
                   controllers: tuple[str, ...] = CONTROLLERS) -> dict[str, dict[str, Any]]:
    """Return the controllers' metrics on one plant, plus ``infeasible`` and ``saving_friction_pct``.

    ``infeasible``: unstable, or the peak torque beyond the plant's torque limit; ``d`` = derive(params).

    The two runs are simulated one after the other in the calling thread: the parallelism of a
    sweep is across samples (processes), and a thread pool per sample would only add overhead.
    """
    d = derive(params) if d is None else d
    runs = [simulate(params, c, d, plant=plant, max_points=TRACE_POINTS) for c in controllers]
    lim = torque_limit(plant)
    out: dict[str, dict[str, Any]] = {}
    for run in runs:
        m: dict[str, Any] = dataclasses.asdict(run.metrics)
        err, peak = run.metrics.theta_error_at_Tm_rad, run.metrics.torque_peak_Nm
        m["theta_error_abs_at_Tm_rad"] = None if err is None else abs(err)
        m["infeasible"] = not run.metrics.stable or (peak is not None and peak > lim * (1.0 + LIMIT_TOLERANCE))
        out[run.controller] = {k: m[k] for k in (*METRICS, "chatter", "stable", "infeasible")}
    if "fdsmc" in out and "conventional" in out:
        out["fdsmc"]["saving_friction_pct"] = _friction_saving(runs[0], runs[1])
    return out


def simulate_chunk(params: DriveParams, rows: list[dict[str, float]], d: Derived | None = None,
                   plant: DriveParams | None = None, threads: int = 1,
                   controllers: tuple[str, ...] = CONTROLLERS) -> list[dict[str, dict[str, Any]]]:
    """Return the metrics of several samples (one task); module-level so that it pickles.

    ``d`` = derive(params), the controller's design (the same for every sample; computed if None);
    ``plant`` the nominal plant the rows' values replace values of (None: the model); ``threads``
    numba threads over the samples [-]; ``controllers`` those run. The same numbers as
    :func:`sample_metrics` per row (tests).
    """
    d = derive(params) if d is None else d
    base = params if plant is None else plant
    return simulate_batch(params, d, [plant_for(base, r) for r in rows], TRACE_POINTS, threads, controllers)


def chunk_size(seconds_per_sample: float, n: int, workers: int) -> int:
    """Return the samples per task [-].

    Each task ≥ MIN_TASK_S and at most TASKS_PER_WORKER tasks per worker, unless that leaves a
    worker idle.
    """
    size = max(1, math.ceil(MIN_TASK_S / max(seconds_per_sample, 1e-6)),
               math.ceil(n / (TASKS_PER_WORKER * max(1, workers))))
    if n > 0 and math.ceil(n / size) < workers:
        size = max(1, math.ceil(n / workers))  # every worker gets work, even if tasks are short
    return size


def _stats(x: np.ndarray, worst: str) -> dict[str, float | None]:
    if x.size == 0:
        return {"mean": None, "p05": None, "p50": None, "p95": None, "worst": None}
    p05, p50, p95 = np.percentile(x, [5.0, 50.0, 95.0])
    w = float(np.max(x) if worst == "max" else np.min(x))
    return {"mean": float(np.mean(x)), "p05": float(p05), "p50": float(p50), "p95": float(p95), "worst": w}


def summarise(runs: list[dict[str, dict[str, Any]]], seconds: float) -> dict[str, Any]:
    """Summarise the runs.

    Per controller, per metric mean/p05/p50/p95/worst over the stable samples, chatter and
    infeasible probabilities; the friction saving's distribution (worst = smallest).
    """
    out: dict[str, Any] = {"samples": len(runs), "seconds": seconds}
    for ctrl in (tuple(runs[0]) if runs else ()):
        rs = [r[ctrl] for r in runs]
        entry: dict[str, Any] = {}
        for key in METRICS:
            entry[key] = _stats(np.array([r[key] for r in rs if isinstance(r[key], float)]), "max")
        entry["chatter_probability"] = float(np.mean([bool(r["chatter"]) for r in rs])) if rs else None
        entry["infeasible_probability"] = float(np.mean([bool(r["infeasible"]) for r in rs])) if rs else None
        out[ctrl] = entry
    sav = np.array([r["fdsmc"].get("saving_friction_pct") for r in runs if "fdsmc" in r
                    and isinstance(r["fdsmc"].get("saving_friction_pct"), float)])
    out["saving_friction_pct"] = _stats(sav, "min")
    return out


def check_request(params: DriveParams, spreads: Sequence[Spread], samples: int,
                  controllers: tuple[str, ...] = CONTROLLERS) -> None:
    """Raise ParameterError for a run that cannot be made or would only repeat one run.

    ≥ 1 sample; one to three distinct controllers of STUDY_CONTROLLERS; more than one sample needs a
    spread (else every sample is the nominal plant); one sample (all its controllers) must fit the
    single-request budget.
    """
    if not controllers or len(set(controllers)) != len(controllers) or not set(controllers) <= set(STUDY_CONTROLLERS):
        raise ParameterError(f"controllers = {','.join(controllers)[:80]!r} is not allowed: one or more distinct "
                             f"of {', '.join(STUDY_CONTROLLERS)}")
    if samples < 1:
        raise ParameterError(f"samples = {samples} is not allowed: ≥ 1")
    if not spreads and samples > 1:
        raise ParameterError(f"samples = {samples} without a spread is not allowed: every sample would be the "
                             "nominal plant; allowed: at least one spread (e.g. plant.R_s=±20%), or samples = 1 "
                             "for one nominal run")
    check_budget(params, len(controllers), max_points=TRACE_POINTS)


def _result(values: dict[str, np.ndarray], runs: list[dict[str, dict[str, Any]]], seconds: float,
            nominal: bool, controllers: tuple[str, ...], complete: bool = True) -> RobustnessResult:
    summary = {**summarise(runs, seconds), "nominal_run": nominal, "complete": complete}
    return RobustnessResult({k: v[: len(runs)] for k, v in values.items()}, runs, summary, complete, controllers)


def robustness(
    params: DriveParams, spreads: Sequence[Spread], samples: int, seed: int = 0, executor: Any = None,
    workers: int = 1, progress: Callable[[int, int], None] | None = None,
    cancelled: Callable[[], bool] | None = None, plant: DriveParams | None = None, threads: int = 1,
    controllers: tuple[str, ...] = CONTROLLERS,
) -> RobustnessResult:
    """Run the Monte-Carlo analysis (see the module docstring).

    Parameters
    ----------
    params : DriveParams          The controller's model (and the nominal plant).
    spreads : sequence of Spread  Distributions of the plant's values (none: one nominal sample only).
    samples : int                 Number of sampled plants [-], ≥ 1.
    seed : int                    Seed of the generator.
    executor                      Object with ``submit``; None: computed here.
    workers : int                 Workers behind the executor (for the chunk size) [-].
    progress : callable or None   ``progress(done, total)`` as samples complete, in order.
    cancelled : callable or None  Polled between chunks; True stops (ParameterError raised).
    plant : DriveParams or None   The nominal plant (a preset's plant section) the spreads are
                                  drawn around and applied to; None: the controller's model.
    threads : int                 numba threads of the samples computed in this process [-].
    controllers : tuple of str    The controllers run on every sample (of STUDY_CONTROLLERS).

    Raises
    ------
    ParameterError      Bad request (see :func:`check_request`), an infeasible T_m, or cancelled.
    IncompleteRunError  The executor failed (:class:`~sim.studies.runner.ExecutorError`); it holds
                        the samples finished before the failure.
    """
    check_request(params, spreads, samples, controllers)
    t0 = time.perf_counter()
    values = draw(params if plant is None else plant, spreads, samples, seed)
    rows = [{k: float(v[i]) for k, v in values.items()} for i in range(samples)]
    d = derive(params)
    _check_feasible(d)
    runs = simulate_chunk(params, rows[:1], d, plant, threads, controllers)  # warm-up (compiled kernel loaded) …
    t1 = time.perf_counter()
    runs += simulate_chunk(params, rows[1:2], d, plant, threads, controllers)  # … and one timed sample
    done = len(runs)
    size = chunk_size(time.perf_counter() - t1, samples - done, workers)
    chunks = [rows[i: i + size] for i in range(done, samples, size)]
    if progress is not None:
        progress(done, samples)
    futures = ([executor.submit(simulate_chunk, params, c, d, plant, 1, controllers) for c in chunks]
               if executor is not None else None)
    try:
        for j, c in enumerate(chunks):
            if cancelled is not None and cancelled():
                raise ParameterError(f"robustness run cancelled after {len(runs)} of {samples} samples")
            runs.extend(futures[j].result() if futures is not None
                        else simulate_chunk(params, c, d, plant, threads, controllers))
            if progress is not None:
                progress(len(runs), samples)
    except ExecutorError as exc:
        raise IncompleteRunError(f"robustness run stopped after {len(runs)} of {samples} samples: {exc}",
                            _result(values, runs, time.perf_counter() - t0, not spreads, controllers, False)) from None
    finally:
        for f in futures or []:
            f.cancel()
    return _result(values, runs, time.perf_counter() - t0, not spreads, controllers)
