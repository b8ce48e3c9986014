"""Benchmark of the Monte-Carlo robustness sweep (prints figures, never asserts).

Samples/s in-process, on a local process pool of 1 and 2 workers and on a 2-worker Dask
``LocalCluster``; the scaling efficiency 2 vs 1 worker; the results' memory per 10 000 samples
(pickled size) and the peak resident memory of this process; optionally (``--full N``) the wall
time of one N-sample run through the CLI's own path (pool start-up included).

Usage: ``python scripts/bench_robustness.py [--samples 200] [--full 10000] [--preset paper_12kw_pmsm]``.
The paper's drive at 20 kHz, J_L unknown to the controller (0 … 10·J_r), ±20 % R_s and Ψ_PM.
Wall figures depend on what else runs on the machine: the load average is printed beside them.
"""

from __future__ import annotations

import argparse
import os
import pickle
import resource
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.sim.studies.robustness import robustness, simulate_chunk


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.1f}"


def timed(label: str, params, spreads, n: int, executor, workers: int) -> float:
    """Run once and print samples/s (wall, and CPU of this process); returns the wall rate."""
    t0, c0 = time.perf_counter(), time.process_time()
    res = robustness(params, spreads, n, seed=1, executor=executor, workers=workers)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    mem = len(pickle.dumps((res.values, res.runs))) / n * 10_000 / 2**20
    cpu_txt = f", {1e3 * cpu / n:.1f} ms CPU/sample here" if executor is None else ""
    print(f"{label:32s} {n / wall:8.1f} samples/s{cpu_txt}   (results {mem:.1f} MiB per 10 000 "
          f"samples; {_load()})", flush=True)
    return n / wall


def main() -> None:
    """Print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--full", type=int, default=0, help="also time one run of this many samples on 2 workers")
    ap.add_argument("--preset", default="paper_12kw_pmsm")
    ap.add_argument("--set", dest="overrides", action="append", default=[])
    a = ap.parse_args()
    params = load_preset(a.preset, a.overrides)
    J_r = params.motor.J_r
    spreads = parse_spreads([f"plant.J_L=0:{10 * J_r},plant.R_s=±20%,plant.psi_pm=±20%"])
    timed("in-process (1 core)", params, spreads, a.samples, None, 1)
    rates = {}
    for w in (1, 2):
        with ProcessPoolExecutor(w, mp_context=get_context("spawn")) as pool:
            list(pool.map(simulate_chunk, [params] * 2 * w, [[{}]] * 2 * w))  # start + load the kernel
            rates[w] = timed(f"process pool, {w} worker(s)", params, spreads, a.samples, pool, w)
    print(f"scaling 2 vs 1 worker: {rates[2] / rates[1]:.2f}× (efficiency {50 * rates[2] / rates[1]:.0f} %)")
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            Client(cl) as client:
        client.gather(client.map(simulate_chunk, [params] * 4, [[{}]] * 4, pure=False))
        timed("Dask LocalCluster, 2 workers", params, spreads, a.samples, client, 2)
    if a.full:
        t0 = time.perf_counter()
        with ProcessPoolExecutor(2, mp_context=get_context("spawn")) as pool:
            res = robustness(params, spreads, a.full, seed=1, executor=pool, workers=2)
        wall = time.perf_counter() - t0
        print(f"{a.full} samples, 2-worker pool, start-up included: {wall:.1f} s wall "
              f"({a.full / wall:.1f} samples/s; {_load()}); friction saving p50 "
              f"{res.summary['saving_friction_pct']['p50']:.1f} %")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak resident memory of this process: {peak:.0f} MiB")


if __name__ == "__main__":
    main()
