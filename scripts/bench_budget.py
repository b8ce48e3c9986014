"""Print the cost model's predicted CPU time and peak memory next to measured ones.

Each case runs ``compare`` of the three controllers in a fresh subprocess (warmed up on a small
case first), measuring CPU seconds (user + system, all threads) and the peak resident memory above
the warmed-up process (``VmHWM`` reset through ``/proc/self/clear_refs``). The promise: predicted
within 2× of measured, and every request the budget admits ≤ :data:`sim.common.budget.MAX_CPU_S`
CPU seconds and ≤ :data:`sim.common.budget.MAX_TRACE_BYTES` of memory.

``--bldc`` measures the BLDC comparison instead (``compare_bldc`` of the chosen drives, or one
drive with RK4 sub-steps), across f_s, t_end, sub-steps, scenarios, back-EMF shapes and the number
of drives.

Run: ``.venv/bin/python scripts/bench_budget.py [--quick] [--bldc] [--raw]``.
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

#: BLDC cases: (f_s [Hz], t_end [s] or None (the preset's), n_sub, active scenario, emf, drives).
ALL = "smc_integral,smc_plain,pi_sinusoidal,six_step"
BLDC_CASES = [
    (20_000.0, None, 1, "1000rpm", "distorted", ALL),
    (20_000.0, 2.0, 1, "1000rpm", "distorted", ALL),
    (100_000.0, None, 1, "1000rpm", "distorted", ALL),
    (100_000.0, 1.5, 1, "1000rpm", "distorted", ALL),
    (50_000.0, 1.0, 1, "2000rpm", "ideal", ALL),
    (20_000.0, 2.0, 1, "1000rpm", "distorted", "smc_integral"),
    (100_000.0, 3.0, 1, "1000rpm", "distorted", "six_step,pi_sinusoidal"),
    (20_000.0, 1.0, 8, "1000rpm", "distorted", "smc_integral"),
    (20_000.0, 2.0, 32, "2000rpm", "distorted", "pi_sinusoidal"),
    (200_000.0, 6.0, 1, "1000rpm", "distorted", "smc_integral"),
    (500_000.0, 1.0, 4, "1000rpm", "distorted", ALL),  # over the budget: refused
    (20_000.0, 15.0, 32, "1000rpm", "distorted", "smc_integral"),  # over the CPU promise only: refused
    (20_000.0, 4.0, 32, "1000rpm", "distorted", "smc_integral"),
]

#: Below these measured figures a case is too small to judge the model (fixed costs, timer noise).
SMALL_CPU_S, SMALL_MEM = 0.1, 16 * 2**20

#: Measures ``run()`` after the engine's set-up (which defines ``params``, ``pred`` and ``run``).
MEASURE = r"""
def rss(key):
    for line in open("/proc/self/status"):
        if line.startswith(key):
            return int(line.split()[1]) * 1024
base = rss("VmRSS:")
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")
r0 = resource.getrusage(resource.RUSAGE_SELF)
try:
    run()
    refused = ""
except budget.BudgetError as exc:
    refused = str(exc)[:60]
r1 = resource.getrusage(resource.RUSAGE_SELF)
cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
print(json.dumps({"cpu": cpu, "mem": rss("VmHWM:") - base, "pred_cpu": pred.cpu_s, "pred_mem": pred.memory_bytes,
                  "refused": refused}))
"""

CHILD = r"""
import json, resource, sys
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.grid import predict
preset, overrides = sys.argv[1], json.loads(sys.argv[2])
ctrls = ("fdsmc", "conventional", "optimum")
compare(load_preset("paper_12kw_pmsm", ["manoeuvre.T_m=0.6"]), ctrls)  # JIT, cvxpy, caches
params = load_preset(preset, overrides)
pred = predict(params, len(ctrls))
def run():
    compare(params, ctrls)
""" + MEASURE

BLDC_CHILD = r"""
import dataclasses, json, resource, sys
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.bldc.engine import check_budget, compare_bldc, run_cost, simulate_bldc
f_s, t_end, n_sub, active, emf, drives = json.loads(sys.argv[1])
def case(f_s, t_end, active, emf):
    p = load("bldc_smc_paper", [f"scenario.active={active}", f"inverter.f_s={f_s}", f"machine.emf={emf}"],
             mode="bldc")
    if t_end is not None:  # the active case's t_end (no --set for it), its load steps scaled along
        c = p.case
        steps = tuple(dataclasses.replace(s, t=s.t * t_end / c.t_end) for s in c.T_L_steps)
        new = dataclasses.replace(c, t_end=t_end, T_L_steps=steps)
        p = dataclasses.replace(p, scenario=dataclasses.replace(
            p.scenario, cases=tuple(new if x.name == active else x for x in p.scenario.cases)))
    return p
compare_bldc(case(2000.0, None, "1000rpm", emf))  # JIT and caches
simulate_bldc(case(2000.0, None, "1000rpm", emf), n_sub=2)
params, ctrls = case(f_s, t_end, active, emf), tuple(drives.split(","))
pred = run_cost(params, len(ctrls), n_sub)
def run():
    check_budget(params, len(ctrls), n_sub)
    if n_sub == 1:
        compare_bldc(params, ctrls)
    else:
        for c in ctrls:
            simulate_bldc(params, c, n_sub=n_sub)
""" + MEASURE


def measure(preset: str, overrides: list[str]) -> dict:
    """Run one case in a fresh process; its measured and predicted figures."""
    return _child(CHILD, preset, json.dumps(overrides))


def measure_bldc(case: tuple) -> dict:
    """Run one BLDC case in a fresh process; its measured and predicted figures."""
    return _child(BLDC_CHILD, json.dumps(case))


def _child(code: str, *args: str) -> dict:
    out = subprocess.run([sys.executable, "-c", code, *args], cwd=ROOT,
                         capture_output=True, text=True, check=True, env={"PYTHONPATH": str(ROOT),
                                                                           **_env()})
    return json.loads(out.stdout.strip().splitlines()[-1])


def _env() -> dict[str, str]:
    import os

    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def _cases() -> list[tuple[str, dict]]:
    """(name, measured figures) of each case of the chosen engine."""
    if "--bldc" in sys.argv:
        cases = BLDC_CASES[:3] if "--quick" in sys.argv else BLDC_CASES
        for f_s, t_end, n_sub, active, emf, drives in cases:
            name = (f"bldc {f_s / 1e3:g} kHz {t_end if t_end else 'preset'} s ×{n_sub} {active} {emf} "
                    f"{len(drives.split(','))} drive(s)")
            yield name[:58], measure_bldc((f_s, t_end, n_sub, active, emf, drives))
        return
    for preset, overrides in (CASES[:4] if "--quick" in sys.argv else CASES):
        yield f"{preset} {' '.join(overrides)}"[:58], measure(preset, overrides)


def main() -> None:
    """Print one line per case and the worst ratios."""
    print(f"{'case':58s} {'CPU pred':>9s} {'meas':>7s} {'ratio':>6s}  {'MiB pred':>8s} {'meas':>7s} {'ratio':>6s}")
    worst_cpu = worst_mem = 1.0
    for name, m in _cases():
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
