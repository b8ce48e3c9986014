"""``pmsm-commission bench``: speed figures of the simulation engine (prints, never asserts).

1. one FDSMC-vs-conventional comparison, paper preset, T_m = 2.6 s + tail, f_s = 20 kHz (warm);
2. the five-point Table-1 sweep in digital mode (20 kHz) and in continuous mode;
3. the compiled kernel's throughput in steps/s against the plain-Python reference step;
4. concurrency: N comparisons on N threads at once against the same N one after the other;
5. cold start: ``pmsm-commission simulate PRESET --json`` in a new process (imports, cache load).
"""

from __future__ import annotations

import argparse
import dataclasses
import multiprocessing
import os
import resource
import statistics
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

from pmsm_commissioning.app.cli.bldc import bench_figure
from pmsm_commissioning.app.cli.main import add_preset_arguments
from pmsm_commissioning.app.io.numbers import integer_option
from pmsm_commissioning.app.io.presets import load, load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import clear_caches, derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import compare, run_steps
from pmsm_commissioning.sim.fdsmc.grid import CONTINUOUS_STEP_S
from pmsm_commissioning.sim.fdsmc.reference import run_reference
from pmsm_commissioning.sim.fdsmc.table1 import TABLE1_T_M, table1_sweep
from pmsm_commissioning.sim.studies.runner import exit_with_parent

#: Most repetitions of each figure [-]: a figure takes up to ≈ 5 s a repetition, so 100 is ≈ 10 min of work.
MAX_REPEAT = 100


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``bench``."""
    add_preset_arguments(p, default="paper_12kw_pmsm")
    p.add_argument("--repeat", type=integer_option("--repeat"), default=7,
                   help=f"repetitions of each figure (median; 5 … {MAX_REPEAT}, fewer count as 5)")
    p.add_argument("--smoke", action="store_true",
                   help="one repetition of each figure: checks that every figure runs (not figures of record)")


def _timed(fn: object, *args: object, **kw: object) -> float:
    t0 = time.perf_counter()
    fn(*args, **kw)  # type: ignore[operator]
    return time.perf_counter() - t0


def _medians(repeat: int, fn: object, *args: object, **kw: object) -> tuple[float, float]:
    """Median wall time and median process CPU time (all threads) [s] of ``repeat`` calls."""
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn(*args, **kw)  # type: ignore[operator]
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus)


def _ms(wall_cpu: tuple[float, float]) -> str:
    return f"median {wall_cpu[0] * 1e3:.1f} ms wall, {wall_cpu[1] * 1e3:.1f} ms CPU"


def run(args: argparse.Namespace) -> int:
    """Print the speed figures."""
    base = args.overrides
    if not 1 <= args.repeat <= MAX_REPEAT:  # before any work: the loops run that many times
        raise ParameterError(f"--repeat = {args.repeat} is not allowed: 1 … {MAX_REPEAT} (each figure is timed "
                             "that many times)")
    rep = 1 if args.smoke else max(5, args.repeat)
    if args.smoke:
        print("smoke run: one repetition of each figure, so these are single timings, not medians")
    for t_m in ([], ["manoeuvre.T_m=2.6"]):  # the preset's own move (what the page opens with), a long one
        p = load(args.preset, [*base, *t_m, "controller.f_s=20000"], mode="position")
        print(comparison_figure(p, rep))
    pd = load_preset(args.preset, [*base, "controller.f_s=20000"])
    table1_sweep(pd, TABLE1_T_M[:1])
    print(f"Table-1 sweep, 5 points, digital 20 kHz: {_ms(_medians(rep, table1_sweep, pd, TABLE1_T_M))}   "
          "[target ≤ 0.5 s]")
    pc = load_preset(args.preset, [*base, "controller.f_s=continuous"])
    table1_sweep(pc, TABLE1_T_M[:1])
    print(f"Table-1 sweep, 5 points, continuous (RK4 h = {CONTINUOUS_STEP_S * 1e6:g} µs): "
          f"{_ms(_medians(rep, table1_sweep, pc, TABLE1_T_M))}   [target ≤ 3 s]")
    d = derive(pd)
    n_k, n_r = 200_000, 4_000
    run_steps(pd, "fdsmc", 10, derived=d)
    tk = statistics.median(_timed(run_steps, pd, "fdsmc", n_k, derived=d) for _ in range(rep))
    tr = _timed(run_reference, pd, d, "fdsmc", n_r)
    sk, sr = n_k / tk, n_r / tr
    print(f"kernel throughput (digital, 1 RK4 substep/sample): compiled {sk:,.0f} samples/s "
          f"({1e9 / sk:.1f} ns per sample), plain-Python reference {sr:,.0f} samples/s, speed-up ×{sk / sr:,.0f}")
    print(bench_figure())  # BLDC mode: 2000 rpm scenario, simulated s per wall s
    print(concurrency_figure(p, rep))
    print(cold_start_figure(args.preset, base, rep))
    return 0


def _varied(p: DriveParams, rep: int, what: str, first: int = 1) -> list[DriveParams]:
    """``rep`` cases from ``p``: a new drive (J_L), a new K or a new T_m each, as the page's sliders make.

    Case i scales the value by 1 + 0.01·(first + i), so distinct ``first`` give distinct cases.
    """
    out = []
    for i in range(rep):
        f = 1.0 + 0.01 * (first + i)
        if what == "K":
            out.append(dataclasses.replace(p, controller=dataclasses.replace(p.controller, K=p.controller.K * f)))
        elif what == "T_m":
            out.append(dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, T_m=p.manoeuvre.T_m * f)))
        else:
            out.append(dataclasses.replace(p, load=dataclasses.replace(p.load, J_L=p.load.J_L * f + 1e-9 * i)))
    return out


def _each(cases: list[DriveParams], fn: object, cold: bool = False) -> tuple[float, float]:
    """Median wall and CPU time [s] of ``fn(case)`` over ``cases`` (caches cleared first if ``cold``)."""
    walls, cpus = [], []
    for case in cases:
        if cold:
            clear_caches()
        w0, c0 = time.perf_counter(), time.process_time()
        fn(case)  # type: ignore[operator]
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus)


def comparison_figure(p: DriveParams, rep: int) -> str:
    """Lines: one comparison (derive included) for a new drive, a new K and a new T_m each run.

    derive() caches its loop searches on the numbers they read, so a new K (the live-tuning
    slider) costs less than a new drive; "new drive" clears the caches, which is what a single
    CLI call pays.
    """
    first = _timed(compare, p)
    lines = [f"comparison T_m = {p.manoeuvre.T_m:g} s (+30 % tail), f_s = 20 kHz, derive included ({rep} runs "
             f"each): first call {first * 1e3:.0f} ms"]
    for what, label in (("drive", "new drive (J_L) each run, caches cleared — one CLI call"),
                        ("K", "new K each run (K slider)"), ("T_m", "new T_m each run (T_m slider)")):
        cases = _varied(p, rep, what)
        run = _each(cases, compare, cold=what == "drive")
        der = _each(_varied(p, rep, what, first=rep + 1), derive, cold=what == "drive")
        lines.append(f"  {label}: {_ms(run)}; derive() alone {_ms(der)}   [target ≤ 15 ms CPU]")
    return "\n".join(lines)


def _parallel(n: int, fn: object, *args: object) -> None:
    with ThreadPoolExecutor(max_workers=n) as pool:
        for f in [pool.submit(fn, *args) for _ in range(n)]:  # type: ignore[arg-type]
            f.result()


def _compare_in_process(p: object) -> object:
    """One comparison in a worker process; the Comparison (traces included) is pickled back."""
    from pmsm_commissioning.app.threads import limit_blas_threads

    limit_blas_threads()
    return compare(p)  # type: ignore[arg-type]


def concurrency_figure(p: object, repeat: int) -> str:
    """One line: N = 4 × cores comparisons one after the other, on N threads, on a process pool.

    Threads share the process: the kernels release the GIL, derive() and the metrics hold it.
    The process pool (one per core, started and warmed before timing) runs everything in
    parallel but pickles each Comparison (≈ 4 MB of traces) back to the caller.
    """
    cores = os.cpu_count() or 1
    n = 4 * cores
    serial = _medians(repeat, lambda: [compare(p) for _ in range(n)])  # type: ignore[arg-type]
    threads = _medians(repeat, _parallel, n, compare, p)
    with ProcessPoolExecutor(cores, mp_context=multiprocessing.get_context("forkserver"),
                             initializer=exit_with_parent) as pool:
        list(pool.map(_compare_in_process, [p] * cores))  # imports + kernel cache load in each worker
        procs = _medians(repeat, lambda: list(pool.map(_compare_in_process, [p] * n)))
    return (f"{n} comparisons (derive included): one after the other {_ms(serial)}; on {n} threads "
            f"{_ms(threads)} (×{serial[0] / threads[0]:.2f}); on {cores} processes {_ms(procs)} "
            f"(×{serial[0] / procs[0]:.2f}; CPU = this process only) — {cores} cores, "
            f"load average {os.getloadavg()[0]:.1f}")


def cold_start_figure(preset: str, overrides: list[str], repeat: int) -> str:
    """One line: wall and CPU time of ``pmsm-commission simulate PRESET --json`` in a new process."""
    cmd = [sys.executable, "-m", "pmsm_commissioning.app", "simulate", preset, "--json"]
    for o in overrides:
        cmd += ["--set", o]
    walls, cpus = [], []
    for _ in range(repeat):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
    return (f"cold start `pmsm-commission simulate {preset} --json` (new process, {len(walls)} runs): "
            f"{_ms((statistics.median(walls), statistics.median(cpus)))}, min {min(walls) * 1e3:.0f} ms, "
            f"max {max(walls) * 1e3:.0f} ms wall   [target ≤ 1.5 s]")
