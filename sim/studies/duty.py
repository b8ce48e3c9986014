"""Duty cycles: a sequence of rest-to-rest moves with dwell times, energy per cycle and per year.

Every move of the cycle starts and ends at rest (the simulated horizon 1.3·T_m includes the
settling tail), so the cycle's energy is the sum of the moves' net electrical inputs over their
whole runs plus the dwell: holding a constant external load Γ_Le at rest costs the copper loss
a·Γ_Le²·t_hold (a = (3/2)·R_s/k_t²; t_hold = the dwell less the simulated tail 0.3·T_m, which the
run already contains), nothing without a load. The cycle lasts Σ(T_m + dwell). A move's position change is its
own θ_dem (relative moves; the absolute position does not change the energy).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

from control.fdsmc.optimum import move_model
from control.fdsmc.params import DriveParams, ParameterError
from sim.fdsmc.engine import TAIL_FRACTION, compare

#: Joules per kilowatt-hour [J/kWh].
J_PER_KWH = 3.6e6
COMPARATORS = ("fdsmc", "conventional", "optimum")


@dataclass(frozen=True)
class Move:
    """One move of the cycle: theta_dem [rad], T_m [s], dwell after it [s]."""

    theta_dem: float
    T_m: float
    dwell: float = 0.0


@dataclass(frozen=True)
class DutyResult:
    """Return the energy per cycle [J] per comparator (None if a run was unstable) and the cycle time [s].

    Also the per-move energies ``moves[i][comparator]`` [J].
    """

    cycle_J: dict[str, float | None]
    cycle_s: float
    moves: tuple[dict[str, float | None], ...]

    def per_year(self, cycles_per_hour: float, hours_per_year: float, price_per_kWh: float
                 ) -> dict[str, tuple[float, float] | None]:
        """(kWh per year, cost per year [currency]) per comparator."""
        out: dict[str, tuple[float, float] | None] = {}
        for c, w in self.cycle_J.items():
            kwh = None if w is None else w * cycles_per_hour * hours_per_year / J_PER_KWH
            out[c] = None if kwh is None else (kwh, kwh * price_per_kWh)
        return out


def duty_cycle(params: DriveParams, moves: Sequence[Move]) -> DutyResult:
    """Simulate each move with the three comparators and add the dwell losses (module docstring).

    Raises
    ------
    ParameterError
        For an empty cycle or a negative dwell (naming the move).
    """
    if not moves:
        raise ParameterError("moves: allowed at least one move")
    per_move: list[dict[str, float | None]] = []
    for i, mv in enumerate(moves):
        if not mv.dwell >= 0.0:
            raise ParameterError(f"move {i + 1}: dwell = {mv.dwell:g} s is not allowed: ≥ 0 s")
        p = dataclasses.replace(params, manoeuvre=dataclasses.replace(
            params.manoeuvre, theta_dem=float(mv.theta_dem), T_m=float(mv.T_m)))
        cmp = compare(p, COMPARATORS)
        mm = move_model(p)
        hold = mm.a * mm.Gamma_Le**2 * max(0.0, mv.dwell - TAIL_FRACTION * mv.T_m)
        row: dict[str, float | None] = {}
        for c in COMPARATORS:
            run = getattr(cmp, c)
            w = run.metrics.get("electrical_in_total_J") if run is not None and run.metrics["stable"] else None
            row[c] = float(w) + hold if isinstance(w, float) else None
        per_move.append(row)
    total = {c: (None if any(r[c] is None for r in per_move) else float(sum(r[c] for r in per_move)))  # type: ignore[misc]
             for c in COMPARATORS}
    t_cycle = sum(m.T_m + m.dwell for m in moves)
    return DutyResult(total, t_cycle, tuple(per_move))
