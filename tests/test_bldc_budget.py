"""The BLDC drive's cost model: CPU time and peak memory predicted from the parameters, requests
beyond the promised figures refused in one line. Measured against runs by
``scripts/bench_budget.py --bldc`` (within 2×; not timed here).
"""

from __future__ import annotations

import dataclasses

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.bldc import engine
from pmsm_commissioning.sim.common import budget


def _case(f_s: float, t_end: float):
    p = load_preset("bldc_smc_paper", [f"inverter.f_s={f_s}"])
    c = p.case
    steps = tuple(dataclasses.replace(s, t=s.t * t_end / c.t_end) for s in c.T_L_steps)
    new = dataclasses.replace(c, t_end=t_end, T_L_steps=steps)
    return dataclasses.replace(p, scenario=dataclasses.replace(
        p.scenario, cases=tuple(new if x.name == c.name else x for x in p.scenario.cases)))


def test_the_prediction_grows_with_samples_sub_steps_and_drives():
    p = _case(20_000.0, 1.0)
    one = engine.run_cost(p, 1, 1)
    assert one.cpu_s is not None and one.memory_bytes >= one.trace_bytes
    assert engine.run_cost(p, 4, 1).cpu_s == pytest.approx(4 * one.cpu_s)
    assert engine.run_cost(_case(40_000.0, 1.0), 1, 1).cpu_s == pytest.approx(
        2 * one.cpu_s - engine.CPU_PER_RUN_S, rel=1e-3)
    sub = engine.run_cost(p, 1, 8)
    assert sub.trace_bytes == one.trace_bytes  # sub-steps are not recorded
    assert sub.cpu_s - one.cpu_s == pytest.approx(7 * 20_000 * engine.CPU_PER_STEP_S, rel=1e-3)


def test_sub_steps_beyond_the_cpu_promise_are_refused_in_one_line_naming_the_fields():
    p = _case(20_000.0, 15.0)
    cost = engine.run_cost(p, 1, 32)
    assert cost.memory_bytes < budget.MAX_TRACE_BYTES < cost.memory_bytes * 3  # memory alone would pass
    assert cost.cpu_s > budget.MAX_CPU_S and cost.steps < budget.MAX_STEPS  # the step count too
    with pytest.raises(budget.BudgetError) as info:
        engine.simulate_bldc(p, n_sub=32)
    msg = str(info.value)
    assert "\n" not in msg and f"allowed ≤ {budget.MAX_CPU_S:g} s" in msg
    assert "scenario.cases[0].t_end = 15 s → largest accepted" in msg and "inverter.f_s" in msg
    best = float(msg.split("t_end = 15 s → largest accepted ")[1].split()[0])
    assert engine.run_cost(_case(20_000.0, best), 1, 32).cpu_s <= budget.MAX_CPU_S


def test_memory_beyond_the_promise_is_refused_before_any_work():
    p = _case(200_000.0, 6.0)
    assert engine.run_cost(p, 1).memory_bytes > budget.MAX_TRACE_BYTES
    with pytest.raises(budget.BudgetError, match="MiB"):
        engine.compare_bldc(p, ("smc_integral",))
