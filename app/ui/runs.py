"""What the position tab runs: the comparison of a case, the Table-1 sweep job, the design objectives' words."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pmsm_commissioning.app.io.plant_overrides import with_plant_J_L
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, CONTROLLERS, Comparison, compare
from pmsm_commissioning.sim.fdsmc.table1 import PAPER_TABLE1, table1_sweep

#: The page's words for the design objectives (same order as :data:`sim.fdsmc.objective.OBJECTIVES`).
OBJECTIVE_LABELS = ("minimum energy from the supply", "minimum friction (paper)")


def comparison_or_derived(params: DriveParams, optimum: bool = False, plant_J_L: float | None = None) -> Comparison:
    """Simulate both controllers, the stock route (and the tracked optimum if ``optimum``) on ``plant_J_L`` [kg·m²].

    The controllers' model stays ``params`` (``plant_J_L`` None: the plant is the model). For an
    infeasible case, return the derivations alone (no runs).
    """
    d = derive(params)  # a ParameterError here is an input error for the caller
    if not d.profile.feasible:
        return Comparison(d, None, None, None, None)
    plant = None if plant_J_L is None else with_plant_J_L(params, plant_J_L)
    return compare(params, COMPARATORS if optimum else CONTROLLERS + ("stock",), derived=d, plant=plant)


def table1_job(tab: Any, results: Any, T_m_values: list[float]) -> Callable[[], None]:
    """Return the worker job of the Table-1 sweep of ``tab``'s case over ``T_m_values`` [s], shown in ``results``."""
    params = tab.case.params

    def progress(done: int, total: int) -> None:
        tab.checkpoint()
        results.set_progress(done, total)

    def job() -> None:
        progress(0, len(T_m_values))
        rows = table1_sweep(params, T_m_values, progress=progress)
        results.show_table1(rows, PAPER_TABLE1)
        tab.say(f"Ready — Table 1: {len(rows)} manoeuvre time(s) simulated.")

    return job


__all__ = ["OBJECTIVE_LABELS", "comparison_or_derived", "table1_job"]
