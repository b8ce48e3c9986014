"""Where a Dask worker's CPU goes, against the local pool (prints figures, never asserts).

A real loopback cluster (``dask scheduler`` + 2 ``dask worker`` subprocesses, as
``tests/test_cluster.py``) and the 2-worker :class:`~sim.studies.runner.RetryingPool` run the same
robustness study of the paper preset at 20 kHz. Per sample [ms] it prints the CPU of every thread of
the worker processes — the thread that ran the tasks, the event loop (the process's main thread)
and the rest — of the nannies, the scheduler and the client, and the samples/s of both. The workers
run with Dask's defaults, then with the project's worker and nanny plugins
(:func:`sim.studies.dask_runner.worker_plugin`, :func:`~sim.studies.dask_runner.nanny_plugin`).

Usage: ``python scripts/bench_dask.py [--samples 1200] [--repeat 5]``. Every figure is a median
with the load average beside it: the machine may be shared.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import sys
import tempfile
import time
from collections.abc import Callable

import psutil

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from bench_scale import PRESET, SPREAD, load, start_cluster  # noqa: E402

from pmsm_commissioning.app.io.presets import load_preset  # noqa: E402
from pmsm_commissioning.app.io.study_inputs import parse_spreads  # noqa: E402
from pmsm_commissioning.sim.studies.robustness import robustness  # noqa: E402
from pmsm_commissioning.sim.studies.runner import RetryingPool  # noqa: E402

MODES = ("defaults", "plugin")


def threads_cpu(pids: list[int]) -> dict[tuple[int, int], float]:
    """CPU seconds (user + system) of every thread of the processes ``pids``, keyed (pid, tid)."""
    out = {}
    for pid in pids:
        for t in psutil.Process(pid).threads():
            out[pid, t.id] = t.user_time + t.system_time
    return out


def split(before: dict, after: dict, n: int) -> dict[str, float]:
    """CPU ms per sample: the busiest thread of each process ("task"), its main thread ("loop"), the rest."""
    per: dict[int, dict[int, float]] = {}
    for (pid, tid), c in after.items():
        per.setdefault(pid, {})[tid] = c - before.get((pid, tid), 0.0)
    got = {"task": 0.0, "loop": 0.0, "other": 0.0}
    for pid, ts in per.items():
        busiest = max(ts, key=ts.get)
        for tid, c in ts.items():
            kind = "task" if tid == busiest else "loop" if tid == pid else "other"
            got[kind] += c / n * 1e3
    return got


def measure(run: Callable[[], object], n: int, groups: dict[str, Callable[[], list[int]]]) -> dict[str, object]:
    """Samples/s of one run and the CPU split of each group of processes."""
    pids = {g: f() for g, f in groups.items()}
    before = {g: threads_cpu(p) for g, p in pids.items()}
    c0, t0 = time.process_time(), time.perf_counter()
    run()
    wall = time.perf_counter() - t0
    res: dict[str, object] = {"rate": n / wall, "client": (time.process_time() - c0) / n * 1e3}
    for g, p in pids.items():
        res[g] = split(before[g], threads_cpu(p), n)
    return res


def report(label: str, runs: list[dict[str, object]]) -> float:
    rate = statistics.median(r["rate"] for r in runs)
    print(f"{label}: {rate:.1f} samples/s (median of {len(runs)}; {load()})", flush=True)
    for g in runs[0]:
        if g == "rate":
            continue
        if g == "client":
            print(f"   client process CPU {statistics.median(r[g] for r in runs):.3f} ms/sample")
            continue
        parts = {k: statistics.median(r[g][k] for r in runs) for k in ("task", "loop", "other")}
        total = sum(parts.values())
        print(f"   {g:9s} CPU {total:.3f} ms/sample = task thread {parts['task']:.3f} + event loop "
              f"{parts['loop']:.3f} + other threads {parts['other']:.3f}")
    return rate


def dask_runs(address: str, procs, params, spreads, n: int, repeat: int, mode: str) -> list[dict[str, object]]:
    from pmsm_commissioning.sim.studies import dask_runner

    nannies = [p.pid for p in procs[1:]]

    def workers() -> list[int]:
        return [c.pid for nanny in nannies for c in psutil.Process(nanny).children(recursive=True)]

    groups = {"workers": workers, "nannies": lambda: nannies, "scheduler": lambda: [procs[0].pid]}
    runs = []
    for _ in range(repeat):
        with dask_runner.connect(address, tuned=mode != "defaults") as ex:
            ex.client.wait_for_workers(2, timeout=120)
            robustness(params, spreads, 40, 2, ex, 2)  # every worker has run a chunk
            runs.append(measure(lambda e=ex: robustness(params, spreads, n, 1, e, 2), n, groups))
            if mode != "defaults":  # back to Dask's own worker and nanny for the next figure
                ex.client.unregister_worker_plugin(dask_runner.worker_plugin().name)
                ex.client.unregister_worker_plugin(dask_runner.nanny_plugin().name, nanny=True)
                ex.client.restart()
    return runs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1200)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    params, spreads = load_preset(PRESET), parse_spreads([SPREAD])
    print(f"{PRESET}, 20 kHz, {a.samples} samples per run, spreads {SPREAD}; {os.cpu_count()} CPUs; {load()}")
    with RetryingPool(2) as pool:
        robustness(params, spreads, 40, 2, pool, 2)
        runs = [measure(lambda: robustness(params, spreads, a.samples, 1, pool, 2), a.samples,
                        {"workers": pool.processes}) for _ in range(a.repeat)]
    pool_rate = report("local pool, 2 workers", runs)
    with tempfile.TemporaryDirectory() as tmp:
        address, procs = start_cluster(pathlib.Path(tmp))
        try:
            for mode in MODES:
                rate = report(f"Dask, 2 workers, {mode}",
                              dask_runs(address, procs, params, spreads, a.samples, a.repeat, mode))
                print(f"   = {rate / pool_rate:.2f}× the pool's samples/s (target ≥ 0.9×)")
        finally:
            for p in reversed(procs):
                p.terminate()
            for p in procs:
                p.wait(timeout=30)


if __name__ == "__main__":
    main()
