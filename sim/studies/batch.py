"""Many Monte-Carlo samples per compiled call: :func:`sim.fdsmc.kernel_run.run_kernel` under ``prange``.

A robustness sample is one plant (the controller keeps its model ``params`` and its design ``d``),
so every sample of one controller shares the time grid, the observer matrices, the load steps and
the chatter windows; only the kernel's parameter vector differs. :func:`run_batch` runs the kernel
for a stack of parameter vectors in one compiled call, the samples spread over numba's threads
(``prange``); the numbers are the kernel's own, bit for bit (tests). The metrics the study needs
(:data:`sim.studies.robustness.METRICS`) are then read from the kernel's ``info`` vector and traces
with the functions of :mod:`sim.fdsmc.metrics` and :mod:`sim.common.signals`; the chatter criterion of
:func:`sim.fdsmc.metrics.detect_chatter` is evaluated for the whole batch at once (same windows,
same arithmetic, same verdicts: tests).

Buffers are allocated once per call and reused for every sub-batch of :data:`BATCH` samples, so the
memory of a call is bounded (≈ 0.5 MiB per sample of a sub-batch at 20 kHz) whatever its length.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import numpy.typing as npt
from numba import njit, prange

from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.feasibility import LIMIT_TOLERANCE, torque_limit
from pmsm_commissioning.control.fdsmc.loop_analysis import CHATTER_PTP_FRACTION
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common import sensors, signals
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import kernel_run
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.engine import CONTROLLERS
from pmsm_commissioning.sim.fdsmc.grid import CONTINUOUS_STEP_S, TimeGrid, load_steps, time_grid
from pmsm_commissioning.sim.fdsmc.limit_cycle import limit_cycles
from pmsm_commissioning.sim.fdsmc.metrics import (
    CHATTER_HYSTERESIS_FRACTION,
    CHATTER_MIN_SIGN_CHANGES,
    CHATTER_SMOOTHING_S,
    chatter_window_steps,
    chatter_windows,
)
from pmsm_commissioning.sim.fdsmc.run import observer_arrays, pack_parameters, reference_rows

#: Samples per compiled call [-]: bounds the trace buffers; ≥ 8 keeps two threads busy.
BATCH = 16
_T, _THETA, _ALPHA_DEM = lay.CHANNELS.index("t"), lay.CHANNELS.index("theta_r"), lay.CHANNELS.index("alpha_dem")


@njit(parallel=True, cache=True, nogil=True)
def run_batch(prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray, Phi: np.ndarray, Gam: np.ndarray,
              Lo: np.ndarray, continuous: bool, h: float, n_steps: int, n_sub: int, delay: int, decim: int,
              out: np.ndarray, info: np.ndarray, k_win: np.ndarray, win: np.ndarray, ref: np.ndarray,
              noise: np.ndarray, n: int) -> None:
    """Run :func:`sim.fdsmc.kernel_run.run_kernel` for rows 0 … n − 1 of ``prm`` (one sample each).

    ``prm`` (samples × N_PRM), ``out`` (samples × N_CH × points), ``info`` (samples × N_INFO) and
    ``win`` (samples × WIN_ROWS·windows × steps) stack the kernel's per-run arrays; the other arguments
    are shared and mean what they mean for ``run_kernel`` (SI units).
    """
    for i in prange(n):
        kernel_run.run_kernel(prm[i], step_t, step_v, Phi, Gam, Lo, continuous, h, n_steps, n_sub, delay,
                              decim, out[i], info[i], k_win, win[i], ref, noise)


@dataclass(frozen=True)
class Setup:
    """What every sample of one controller shares: grid, observer, load steps, sensors, chatter windows."""

    controller: str
    grid: TimeGrid
    arrays: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # step_t, step_v, Phi, Gam, Lo
    ref: np.ndarray
    noise: np.ndarray  # the sensors' noise table (the model's sensors, as simulate())
    windows: tuple[tuple[float, float], ...]  # cruise, hold [s]
    steps: tuple[tuple[int, int], ...]  # first step, number of steps of each window [-]


def setup(params: DriveParams, d: Derived, controller: str, plant: DriveParams, max_points: int) -> Setup:
    """Return the shared part of ``controller``'s runs on plants like ``plant`` (the grid is the model's)."""
    g = time_grid(params, 1, CONTINUOUS_STEP_S, max_points)
    T_step = g.h * g.n_sub
    windows = tuple(chatter_windows(params, d, controller, g.n_steps * T_step).values())
    steps = tuple(chatter_window_steps(w, T_step, g.n_steps) for w in windows)
    return Setup(controller, g, (*load_steps(plant), *observer_arrays(d)), reference_rows(d, controller),
                 sensors.noise_table(params.sensors), windows, steps)


@njit(cache=True, nogil=True)
def chatter_stats(a: np.ndarray, n: int, hyst: float) -> tuple[np.ndarray, np.ndarray]:
    """Peak-to-peak [rad/s²] and hysteretic sign changes [-] of each row's high-pass part.

    Row by row the arithmetic of :func:`sim.fdsmc.metrics.detect_chatter`: r = a − the centred
    moving average of ``n`` samples (edges padded, running sum in the same order as ``np.cumsum``),
    the sign changes of r counting only samples beyond ±``hyst`` (the same numbers: tests).
    """
    rows, m = a.shape
    ptp, changes = np.zeros(rows), np.zeros(rows, dtype=np.int64)
    lo = n // 2
    c = np.zeros(m + n)
    for i in range(rows):
        for k in range(m + n - 1):  # running sum of the edge-padded row
            c[k + 1] = c[k] + a[i, min(max(k - lo, 0), m - 1)]
        r_min, r_max, last, count = np.inf, -np.inf, 0.0, 0
        for k in range(m):
            r = a[i, k] - (c[k + n] - c[k]) / n
            r_min, r_max = min(r_min, r), max(r_max, r)
            if abs(r) > hyst:
                s = np.sign(r)
                count += 1 if last != 0.0 and s != last else 0
                last = s
        ptp[i], changes[i] = r_max - r_min, count
    return ptp, changes


def chatter_rows(t: np.ndarray, alpha_dem: np.ndarray, window: tuple[float, float], alpha_max: float) -> np.ndarray:
    """Chatter verdict of each row of ``alpha_dem`` [rad/s²] sampled at ``t`` [s]: see :mod:`sim.fdsmc.metrics`.

    The rows share ``t`` and the window, so the selection, the step and the smoothing length are
    those :func:`~sim.fdsmc.metrics.detect_chatter` computes for each of them.
    """
    t0, t1 = window
    sel = (t >= t0) & (t <= t1)
    if np.count_nonzero(sel) < 8 or t1 <= t0:
        return np.zeros(alpha_dem.shape[0], dtype=bool)
    n = max(1, int(round(CHATTER_SMOOTHING_S / float(np.median(np.diff(t[sel]))))))
    rows = np.ascontiguousarray(alpha_dem[:, sel])
    hyst, ptp_min = CHATTER_HYSTERESIS_FRACTION * alpha_max, CHATTER_PTP_FRACTION * alpha_max
    ptp, changes = chatter_stats(rows, n, hyst)
    verdict: npt.NDArray[np.bool_] = ((ptp > ptp_min) & (changes >= CHATTER_MIN_SIGN_CHANGES)
                                      | limit_cycles(rows, t[sel], hyst, ptp_min)[0])
    return verdict


def _buffers(s: Setup, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (np.zeros((n, lay.N_CH, s.grid.n_out)), np.zeros((n, lay.N_INFO)),
            np.zeros((n, kn.WIN_ROWS * len(s.steps), max(k for _, k in s.steps))))


def _run(params: DriveParams, d: Derived, s: Setup, plants: list[DriveParams],
         bufs: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Fill the first len(plants) rows of the buffers with the runs of ``s.controller`` on ``plants``."""
    out, info, win = bufs
    g, k_win = s.grid, np.array([k0 for k0, _ in s.steps], dtype=np.int64)
    prm = np.stack([pack_parameters(params, d, s.controller, p, g.h * g.n_sub) for p in plants])
    run_batch(prm, *s.arrays, g.continuous, g.h, g.n_steps, g.n_sub, params.controller.delay_samples,
              g.decim, out, info, k_win, win, s.ref, s.noise, len(plants))


def _metrics(params: DriveParams, d: Derived, s: Setup, plants: list[DriveParams],
             bufs: tuple[np.ndarray, np.ndarray, np.ndarray]) -> list[dict[str, Any]]:
    """Return the study's metrics of each run in the buffers (as :func:`sim.studies.robustness.sample_metrics`)."""
    out, info, win = bufs
    n, T_step, theta_dem = len(plants), s.grid.h * s.grid.n_sub, params.manoeuvre.theta_dem
    chatter = np.zeros(n, dtype=bool)
    for j, (w, (k0, m)) in enumerate(zip(s.windows, s.steps, strict=True)):
        chatter |= chatter_rows((k0 + np.arange(m)) * T_step, win[:n, kn.WIN_ROWS * j, :m], w, d.alpha.alpha_max)
    rows = []
    for i, plant in enumerate(plants):
        x = info[i]
        if x[lay.I_FAILED]:
            rows.append({**dict.fromkeys(("friction_J", "copper_J", "electrical_in_total_J", "torque_peak_Nm",
                                          "theta_error_abs_at_Tm_rad", "t_2pct_settle_s", "t_2pct_first_s")),
                         "chatter": False, "stable": False, "infeasible": True})
            continue
        chans = out[i, :, : int(x[lay.I_NOUT])]
        finite = np.all(np.isfinite(chans), axis=0)
        k_end = chans.shape[1] if np.all(finite) else int(np.argmin(finite))
        t, theta, band = chans[_T, :k_end], chans[_THETA, :k_end], 0.02 * abs(theta_dem)
        peak = float(x[lay.I_PTQ])
        rows.append({
            "friction_J": float(x[lay.I_SNAP + lay.X_EF]), "copper_J": float(x[lay.I_SNAP + lay.X_ECU]),
            "electrical_in_total_J": float(x[lay.I_END + lay.X_EEL]), "torque_peak_Nm": peak,
            "theta_error_abs_at_Tm_rad": abs(float(x[lay.I_SNAP + lay.X_TH]) - theta_dem),
            "t_2pct_settle_s": signals.settling_time(t, theta, theta_dem, band),
            "t_2pct_first_s": signals.first_entry_time(t, theta, theta_dem, band),
            "chatter": bool(chatter[i]), "stable": True,
            "infeasible": peak > torque_limit(plant) * (1.0 + LIMIT_TOLERANCE)})
    return rows


def _saving(f: dict[str, Any], c: dict[str, Any]) -> float | None:
    """FDSMC's friction saving [%] (eq. (47) in [1]); None unless both runs reached the 2 % band."""
    if f["t_2pct_first_s"] is None or c["t_2pct_first_s"] is None or not c["friction_J"]:
        return None
    saving: float = 100.0 * (1.0 - f["friction_J"] / c["friction_J"])
    return saving


def simulate_batch(params: DriveParams, d: Derived, plants: list[DriveParams], max_points: int,
                   threads: int = 1, controllers: tuple[str, ...] = CONTROLLERS) -> list[dict[str, dict[str, Any]]]:
    """Return the controllers' metrics on each plant (the entries of ``RobustnessResult.runs``).

    Parameters
    ----------
    params : DriveParams        The controller's model.
    d : Derived                 derive(params), the controller's design.
    plants : list of DriveParams  The sampled plants (true motor and load values).
    max_points : int            Trace points per run [-] (the 2 % settling time is read from them).
    threads : int               numba threads over the samples of a sub-batch [-] (1 in a worker
                                process of a pool: the processes are the parallelism).
    controllers : tuple of str  The controllers run on every plant (the FDSMC's friction saving is
                                added where the conventional one runs too).
    """
    if not plants:
        return []
    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))  # type: ignore[attr-defined]
    per: dict[str, list[dict[str, Any]]] = {}
    for ctrl in controllers:
        s = setup(params, d, ctrl, plants[0], max_points)
        bufs = _buffers(s, min(BATCH, len(plants)))
        per[ctrl] = []
        for k in range(0, len(plants), BATCH):
            _run(params, d, s, plants[k: k + BATCH], bufs)
            per[ctrl] += _metrics(params, d, s, plants[k: k + BATCH], bufs)
    runs = [{ctrl: per[ctrl][i] for ctrl in controllers} for i in range(len(plants))]
    for r in runs:
        if "fdsmc" in r and "conventional" in r:
            f, c = r["fdsmc"], r["conventional"]
            f["saving_friction_pct"] = _saving(f, c) if f["stable"] and c["stable"] else None
        for m in r.values():
            m.pop("t_2pct_first_s")
    return runs
