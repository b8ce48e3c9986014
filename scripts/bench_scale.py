"""Scale-out figures of the robustness study (prints figures, never asserts) against their targets.

1. one sample's CPU in this process: one run at a time (``sample_metrics``) vs the batch kernel;
2. samples/s of the local pool on 1 and 2 workers (pre-started, kernels loaded), 2-vs-1 scaling;
3. samples/s on a real loopback Dask cluster (``dask scheduler`` + 2 ``dask worker`` subprocesses)
   with the project's worker tuning (allocator kept, profiler off) and without it, vs the pool;
4. the 10 000-sample robustness of the paper preset at 20 kHz through the CLI (pool start-up included);
5. cold start of ``pmsm-commission simulate paper_12kw_pmsm --json`` (wall, new process each time).

Every figure is the median of ``--repeat`` (≥ 5) runs, printed with its range and the load average:
the machine may be shared, so read the figures with the load beside them.

Usage: ``python scripts/bench_scale.py [--samples 1200] [--repeat 5] [--full 10000] [--skip-full]``.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.studies.robustness import draw, plant_for, robustness, sample_metrics, simulate_chunk
from pmsm_commissioning.sim.studies.runner import RetryingPool

ROOT = pathlib.Path(__file__).resolve().parent.parent
PRESET = "paper_12kw_pmsm"
SPREAD = "plant.J_L=0:0.3,plant.R_s=±20%,plant.psi_pm=±20%"


def load() -> str:
    return "load avg " + "/".join(f"{x:.2f}" for x in os.getloadavg())


def figure(label: str, values: list[float], unit: str) -> float:
    m = statistics.median(values)
    print(f"{label:44s} {m:9.2f} {unit}  (median of {len(values)}, {min(values):.2f}…{max(values):.2f}; {load()})",
          flush=True)
    return m


def cpu_s(pids: list[int]) -> float:
    """CPU seconds (user + system) the processes ``pids`` have used so far."""
    import psutil

    total = 0.0
    for pid in pids:
        t = psutil.Process(pid).cpu_times()
        total += t.user + t.system
    return total


def rate(run: Callable[[], object], n: int, repeat: int, pids: Callable[[], list[int]] = list,
         cpu: list[float] | None = None) -> list[float]:
    """Samples/s of ``repeat`` runs of n samples; the workers' CPU ms per sample appended to ``cpu``."""
    out = []
    for _ in range(repeat):
        procs = pids()
        c0, t0 = cpu_s(procs), time.perf_counter()
        run()
        out.append(n / (time.perf_counter() - t0))
        if cpu is not None:
            cpu.append((cpu_s(procs) - c0) / n * 1e3)
    return out


def per_sample_cpu(params, spreads, repeat: int) -> None:
    d = derive(params)
    v = draw(params, spreads, 64, 1)
    rows = [{k: float(x[i]) for k, x in v.items()} for i in range(64)]
    simulate_chunk(params, rows[:2], d)
    one, batch = [], []
    for _ in range(repeat):
        c0 = time.process_time()
        for r in rows[:16]:
            sample_metrics(params, plant_for(params, r), d)
        one.append((time.process_time() - c0) / 16 * 1e3)
        c0 = time.process_time()
        simulate_chunk(params, rows, d)
        batch.append((time.process_time() - c0) / 64 * 1e3)
    figure("CPU per sample, one run at a time", one, "ms")
    figure("CPU per sample, batch kernel (1 thread)", batch, "ms")
    for threads in (1, 2):
        figure(f"in one process, {threads} numba thread(s)",
               rate(lambda t=threads: simulate_chunk(params, rows, d, threads=t), len(rows), repeat), "samples/s")


def pool_rates(params, spreads, n: int, repeat: int) -> dict[int, float]:
    rates = {}
    for w in (1, 2):
        with RetryingPool(w) as pool:
            [f.result() for f in [pool.submit(simulate_chunk, params, [{}]) for _ in range(2 * w)]]
            cpu: list[float] = []
            rates[w] = figure(f"local pool, {w} worker(s)", rate(
                lambda p=pool, w=w: robustness(params, spreads, n, 1, p, w), n, repeat, pool.processes, cpu),
                "samples/s")
            figure(f"   its workers' CPU per sample, {w} worker(s)", cpu, "ms")
    print(f"pool scaling 2 vs 1 worker: {rates[2] / rates[1]:.2f}×  (target ≥ 1.9×)")
    return rates


def start_cluster(tmp: pathlib.Path) -> tuple[str, list[subprocess.Popen]]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    file = tmp / "scheduler.json"
    procs = [subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(file)], env=env, cwd=tmp,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    while not file.exists():
        time.sleep(0.2)
    for _ in range(2):
        procs.append(subprocess.Popen([sys.executable, "-m", "dask", "worker", "--scheduler-file", str(file),
                                       "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"], env=env,
                                      cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    return json.loads(file.read_text(encoding="utf-8"))["address"], procs


def worker_pids(nannies: list[int]) -> list[int]:
    """The worker processes under the nannies (their pids change when a worker is restarted)."""
    import psutil

    return [c.pid for n in nannies for c in psutil.Process(n).children(recursive=True)]


def dask_rates(params, spreads, n: int, repeat: int, pool2: float) -> None:
    from pmsm_commissioning.sim.studies.dask_runner import connect, nanny_plugin, worker_plugin

    with tempfile.TemporaryDirectory() as tmp:
        address, procs = start_cluster(pathlib.Path(tmp))
        try:
            got: dict[bool, list[float]] = {False: [], True: []}
            cpu: dict[bool, list[float]] = {False: [], True: []}
            nannies = [p.pid for p in procs[1:]]
            for _ in range(repeat):
                for tuned in (False, True):
                    with connect(address, tuned=tuned) as ex:
                        ex.client.wait_for_workers(2, timeout=120)
                        robustness(params, spreads, 40, 2, ex, 2)  # every worker has run a chunk
                        got[tuned] += rate(lambda e=ex: robustness(params, spreads, n, 1, e, 2), n, 1,
                                           lambda: worker_pids(nannies), cpu[tuned])
                        if tuned:  # back to the nanny's environment for the next untuned figure
                            ex.client.unregister_worker_plugin(worker_plugin().name)
                            ex.client.unregister_worker_plugin(nanny_plugin().name, nanny=True)
                            ex.client.restart()
            for tuned in (False, True):
                r = figure(f"Dask, 2 workers, {'tuned' if tuned else 'Dask defaults'}", got[tuned], "samples/s")
                print(f"   = {r / pool2:.2f}× the 2-worker pool (target ≥ 0.9×)")
                figure(f"   workers' CPU per sample, {'tuned' if tuned else 'Dask defaults'}", cpu[tuned], "ms")
        finally:
            for p in reversed(procs):
                p.terminate()
            for p in procs:
                p.wait(timeout=30)


def full_run(samples: int, repeat: int) -> None:
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "robustness", PRESET, "--samples", str(samples),
                        "--spread",
                        SPREAD, "--workers", "2", "--json"], check=True, cwd=ROOT, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, env={**os.environ, "PYTHONPATH": str(ROOT)})
        walls.append(time.perf_counter() - t0)
    figure(f"{samples} samples, CLI, 2-worker pool (wall)", walls, "s")


def cold_start(repeat: int) -> None:
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "simulate", PRESET, "--json"], check=True,
                       cwd=ROOT,
                       stdout=subprocess.DEVNULL, env={**os.environ, "PYTHONPATH": str(ROOT)})
        walls.append(time.perf_counter() - t0)
    figure("cold start: simulate --json (wall)", walls, "s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=1200)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--full", type=int, default=10_000)
    ap.add_argument("--skip-full", action="store_true")
    ap.add_argument("--only", choices=("cpu", "pool", "dask", "full", "cold"), action="append")
    a = ap.parse_args()
    repeat, only = max(5, a.repeat), set(a.only or ("cpu", "pool", "dask", "full", "cold"))
    params = load_preset(PRESET)
    spreads = parse_spreads([SPREAD])
    print(f"{PRESET}, 20 kHz, spreads {SPREAD}; {os.cpu_count()} CPUs; {load()}")
    if "cpu" in only:
        per_sample_cpu(params, spreads, repeat)
    pool2 = pool_rates(params, spreads, a.samples, repeat)[2] if only & {"pool", "dask"} else 0.0
    if "dask" in only:
        dask_rates(params, spreads, a.samples, repeat, pool2)
    if "full" in only and not a.skip_full:
        full_run(a.full, repeat)
    if "cold" in only:
        cold_start(repeat)


if __name__ == "__main__":
    main()
