"""``python -m app bench``: speed figures of the simulation engine (prints, never asserts).

1. one FDSMC-vs-conventional comparison, paper preset, T_m = 2.6 s + tail, f_s = 20 kHz (warm);
2. the five-point Table-1 sweep in digital mode (20 kHz) and in continuous mode;
3. the compiled kernel's throughput in steps/s against the plain-Python reference step.
"""

from __future__ import annotations

import argparse
import statistics
import time

from app.cli import add_preset_arguments
from app.cli_bldc import bench_figure
from app.preset_modes import load_mode_preset
from app.presets import load_preset
from control.derivations import derive
from sim.engine import CONTINUOUS_STEP_S, compare, run_steps, table1_sweep
from sim.reference import run_reference

TM_SWEEP = (1.0, 1.4, 1.8, 2.2, 2.6)


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``bench``."""
    add_preset_arguments(p, default="paper_12kw_pmsm")
    p.add_argument("--repeat", type=int, default=7, help="repetitions of the comparison (median)")


def _timed(fn: object, *args: object, **kw: object) -> float:
    t0 = time.perf_counter()
    fn(*args, **kw)  # type: ignore[operator]
    return time.perf_counter() - t0


def run(args: argparse.Namespace) -> int:
    """Print the speed figures."""
    base = args.overrides
    p = load_mode_preset(args.preset, [*base, "manoeuvre.T_m=2.6", "controller.f_s=20000"], mode="position")
    first = _timed(compare, p)
    times = [_timed(compare, p) for _ in range(max(1, args.repeat))]
    print(f"comparison T_m = 2.6 s (+30 % tail), f_s = 20 kHz: first call {first * 1e3:.0f} ms "
          f"(JIT load/compile), warm median {statistics.median(times) * 1e3:.1f} ms, "
          f"best {min(times) * 1e3:.1f} ms   [target ≤ 50 ms, stretch 20 ms]")
    pd = load_preset(args.preset, [*base, "controller.f_s=20000"])
    table1_sweep(pd, TM_SWEEP[:1])
    t_d = _timed(table1_sweep, pd, TM_SWEEP)
    print(f"Table-1 sweep, 5 points, digital 20 kHz: {t_d:.3f} s   [target ≤ 0.5 s]")
    pc = load_preset(args.preset, [*base, "controller.f_s=continuous"])
    table1_sweep(pc, TM_SWEEP[:1])
    t_c = _timed(table1_sweep, pc, TM_SWEEP)
    print(f"Table-1 sweep, 5 points, continuous (RK4 h = {CONTINUOUS_STEP_S * 1e6:g} µs): {t_c:.3f} s   "
          "[target ≤ 3 s]")
    d = derive(pd)
    n_k, n_r = 200_000, 4_000
    run_steps(pd, "fdsmc", 10, derived=d)
    tk = _timed(run_steps, pd, "fdsmc", n_k, derived=d)
    tr = _timed(run_reference, pd, d, "fdsmc", n_r)
    sk, sr = n_k / tk, n_r / tr
    print(f"kernel throughput (digital, 1 RK4 substep/sample): compiled {sk:,.0f} samples/s, "
          f"plain-Python reference {sr:,.0f} samples/s, speed-up ×{sk / sr:,.0f}")
    print(bench_figure())  # BLDC mode: 2000 rpm scenario, simulated s per wall s
    return 0
