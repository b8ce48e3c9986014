"""The Table-1 sweep of [1]: friction energies and savings over manoeuvre times.

Each point is one FDSMC-vs-conventional comparison (:func:`sim.fdsmc.engine.compare`) of the case
with its T_m replaced; the cost of the whole sweep is checked before the first run.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.fdsmc.engine import compare, reached_target
from pmsm_commissioning.sim.fdsmc.grid import check_budget, run_cost, with_field

#: Paper's Table 1: manoeuvre time [s] → printed friction saving [%].
PAPER_TABLE1: dict[float, float] = {1.0: 27.9, 1.4: 27.8, 1.8: 27.5, 2.2: 26.8, 2.6: 25.1}
#: The manoeuvre times [s] of Table 1 in [1]: the default sweep.
TABLE1_T_M: tuple[float, ...] = tuple(PAPER_TABLE1)


def printed_reversed(paper: dict[float, float]) -> dict[float, float]:
    """Return the printed Table-1 row read right to left: the value under the last T_m belongs to the first.

    [1] prints the row in reverse column order (read so, it agrees with the simulation).
    """
    keys = sorted(paper)
    return dict(zip(keys, [paper[k] for k in reversed(keys)], strict=True))


@dataclass(frozen=True)
class Table1Row:
    """One column of Table 1 in [1]: friction [J] over [0, T_m] and savings [%]."""

    T_m: float
    friction_fdsmc_J: float
    friction_conventional_J: float
    saving_pct: float
    saving_eq52_pct: float
    bound_pct: float
    paper_pct: float | None


def table1_sweep(
    params: DriveParams,
    T_m_values: Sequence[float],
    progress: Callable[[int, int], None] | None = None,
    **options: Any,
) -> list[Table1Row]:
    """Friction energies and savings over manoeuvre times, as Table 1 of [1].

    Parameters
    ----------
    params : DriveParams
        The case; its T_m is replaced by each value.
    T_m_values : sequence of float
        Manoeuvre times [s].
    progress : callable or None
        Called as ``progress(done, total)`` after each point.

    Returns
    -------
    list of Table1Row

    Raises
    ------
    ParameterError
        For an infeasible T_m, or when a run is unstable (naming T_m and the reason), so that
        no row is ever computed from a diverged run.
    """
    points = [with_field(params, "manoeuvre.T_m", float(T_m)) for T_m in T_m_values]
    total = sum((run_cost(p, **options) for p in points), budget.Cost(0, 0, 0.0, 0))  # keeps CPU and memory
    if points and not (total + total).fits:  # two controllers per point
        check_budget(max(points, key=lambda p: p.manoeuvre.T_m), 2 * len(points), **options)
    rows: list[Table1Row] = []
    for i, (T_m, p) in enumerate(zip(T_m_values, points, strict=True)):
        cmp = compare(p, **options)
        assert cmp.fdsmc is not None and cmp.conventional is not None
        for run in (cmp.fdsmc, cmp.conventional):
            if not run.metrics.stable:
                raise ParameterError(
                    f"manoeuvre.T_m = {T_m:g} s: {run.controller} run unstable — {run.metrics.reason}")
            if not reached_target(run):
                raise ParameterError(f"manoeuvre.T_m = {T_m:g} s: the {run.controller} run never reached the "
                                     "2 % band around θ_dem, so its energy is not comparable")
        wf, wc = cmp.fdsmc.metrics.friction_J, cmp.conventional.metrics.friction_J
        assert wf is not None and wc is not None  # a run that reached its target has its energies
        e = cmp.derived.energy
        rows.append(Table1Row(float(T_m), wf, wc, 100.0 * (1.0 - wf / wc),
                              float(e.saving_pct) if e.saving_pct is not None else math.nan,
                              e.bound_pct, PAPER_TABLE1.get(round(float(T_m), 3))))
        if progress is not None:
            progress(i + 1, len(T_m_values))
    return rows


__all__ = ["PAPER_TABLE1", "TABLE1_T_M", "Table1Row", "table1_sweep"]
