"""Print the cost model's predicted CPU time and peak memory next to measured ones (issue 28).

Each case runs ``compare`` of the three controllers in a fresh subprocess (warmed up on a small
case first), measuring CPU seconds (user + system, all threads) and the peak resident memory above
the warmed-up process (``VmHWM`` reset through ``/proc/self/clear_refs``). The promise: predicted
within 2× of measured, and every request the budget admits ≤ :data:`sim.common.budget.MAX_CPU_S`
CPU seconds and ≤ :data:`sim.common.budget.MAX_TRACE_BYTES` of memory.

Run: ``.venv/bin/python scripts/bench_budget.py [--quick]``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: (preset, overrides) of each measured case: f_s, T_m and sub-steps varied.
CASES = [
    ("paper_12kw_pmsm", []),
    ("paper_12kw_pmsm", ["controller.f_s_kHz=200"]),
    ("paper_12kw_pmsm", ["controller.f_s_kHz=1000"]),
    ("paper_12kw_pmsm", ["controller.f_s_kHz=2"]),  # plant sub-steps
    ("paper_12kw_pmsm", ["controller.f_s_kHz=1", "manoeuvre.T_m=3"]),
    ("yaskawa_sgm7j_02a", []),
    ("yaskawa_sgm7j_02a", ["controller.f_s_kHz=1000", "manoeuvre.T_m=0.35"]),
    ("yaskawa_sgm7j_02a", ["controller.f_s_kHz=3000", "manoeuvre.T_m=0.35"]),
    ("yaskawa_sgm7j_02a", ["controller.f_s_kHz=1000", "manoeuvre.T_m=1.0"]),
    ("yaskawa_sgm7j_02a", ["controller.f_s_kHz=2500", "manoeuvre.T_m=1.0"]),
    ("yaskawa_sgm7j_02a", ["controller.f_s_kHz=10000", "manoeuvre.T_m=1.0"]),  # the reproduction
    ("siemens_1ft7044_ak7", ["controller.f_s_kHz=4", "manoeuvre.T_m=2.0"]),
]

#: Below these measured figures a case is too small to judge the model (fixed costs, timer noise).
SMALL_CPU_S, SMALL_MEM = 0.1, 16 * 2**20

CHILD = r"""
import json, os, resource, sys, time
from app.io.presets import load_preset
from sim.common import budget
from sim.fdsmc.engine import compare
from sim.fdsmc.grid import predict
preset, overrides = sys.argv[1], json.loads(sys.argv[2])
ctrls = ("fdsmc", "conventional", "optimum")
compare(load_preset("paper_12kw_pmsm", ["manoeuvre.T_m=0.6"]), ctrls)  # JIT, cvxpy, caches
params = load_preset(preset, overrides)
pred = predict(params, len(ctrls))
def rss(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1]) * 1024
base = rss("VmRSS:")
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
r0 = resource.getrusage(resource.RUSAGE_SELF)
try:
    compare(params, ctrls)
    refused = ""
except budget.BudgetError as exc:
    refused = str(exc)[:60]
r1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
print(json.dumps({"cpu": cpu, "mem": rss("VmHWM:") - base, "pred_cpu": pred.cpu_s, "pred_mem": pred.memory_bytes,
                  "refused": refused}))
"""


def measure(preset: str, overrides: list[str]) -> dict:
    """Run one case in a fresh process; its measured and predicted figures."""
    out = subprocess.run([sys.executable, "-c", CHILD, preset, json.dumps(overrides)], cwd=ROOT,
                         capture_output=True, text=True, check=True, env={"PYTHONPATH": str(ROOT),
                                                                           **_env()})
    return json.loads(out.stdout.strip().splitlines()[-1])


def _env() -> dict[str, str]:
    import os

    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def main() -> None:
    """Print one line per case and the worst ratios."""
    cases = CASES[:4] if "--quick" in sys.argv else CASES
    print(f"{'case':58s} {'CPU pred':>9s} {'meas':>7s} {'ratio':>6s}  {'MiB pred':>8s} {'meas':>7s} {'ratio':>6s}")
    worst_cpu = worst_mem = 1.0
    for preset, overrides in cases:
        m = measure(preset, overrides)
        name = f"{preset} {' '.join(overrides)}"[:58]
        if m["refused"]:
            print(f"{name:58s} refused (predicted {m['pred_cpu']:.2f} s, {m['pred_mem'] / 2**20:.0f} MiB)")
            continue
        rc = m["pred_cpu"] / max(m["cpu"], 1e-3)
        rm = m["pred_mem"] / max(m["mem"], 2**20)
        if m["cpu"] >= SMALL_CPU_S:  # below: fixed costs and timer noise, far from any limit
            worst_cpu = max(worst_cpu, rc, 1 / rc)
        if m["mem"] >= SMALL_MEM:
            worst_mem = max(worst_mem, rm, 1 / rm)
        if "--raw" in sys.argv:
            print(json.dumps({"case": name, **m}))
        print(f"{name:58s} {m['pred_cpu']:8.2f}s {m['cpu']:6.2f}s {rc:6.2f}  {m['pred_mem'] / 2**20:8.1f} "
              f"{m['mem'] / 2**20:7.1f} {rm:6.2f}")
    print(f"worst factor over runs ≥ {SMALL_CPU_S} s CPU / ≥ {SMALL_MEM // 2**20} MiB: CPU {worst_cpu:.2f}×, "
          f"memory {worst_mem:.2f}× (promise ≤ 2×)")


if __name__ == "__main__":
    main()
