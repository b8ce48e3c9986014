"""Benchmark of the Monte-Carlo robustness sweep: samples/s in-process, on a local process pool of
1 and 2 workers and on a 2-worker Dask ``LocalCluster``; scaling efficiency; result memory.

Usage: ``python scripts/bench_robustness.py [--samples 200] [--preset paper_12kw_pmsm]``. The
paper's drive at 20 kHz with J_L unknown to the controller (0 … 10·J_r) and ±20 % R_s and Ψ_PM.
"""

from __future__ import annotations

import argparse
import pickle
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

from app.cli.robustness import parse_spreads
from app.io.presets import load_preset
from sim.studies.robustness import robustness, simulate_chunk


def timed(label: str, params, spreads, n: int, executor, workers: int) -> float:
    """Run once and print samples/s; returns it."""
    t0 = time.perf_counter()
    res = robustness(params, spreads, n, seed=1, executor=executor, workers=workers)
    rate = n / (time.perf_counter() - t0)
    mem = len(pickle.dumps(res.runs)) / n * 10_000 / 2**20
    print(f"{label:34s} {rate:8.1f} samples/s   (results {mem:.1f} MiB per 10 000 samples)", flush=True)
    return rate


def main() -> None:
    """Print the figures."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=200)
    ap.add_argument("--preset", default="paper_12kw_pmsm")
    ap.add_argument("--set", dest="overrides", action="append", default=["controller.K=0.3"])
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


if __name__ == "__main__":
    main()
