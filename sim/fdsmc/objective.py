"""Design for the energy the user cares about: net electrical input (default) or the paper's friction.

The paper's profile (section 4 of [1]) minimises the friction loss and runs at the largest α the
torque allows. On servo drives the copper loss dominates and falls with α, so for the objective
``electrical`` the FDSMC is designed twice — at the torque limit's α and at the α that minimises the
profile's friction + copper (``alpha_max_rule = min_energy``) — and the clean design that draws the
least net electrical energy in its verification run is kept. ``friction`` is the paper's choice
(``torque_limit``), unchanged.

Either way the design's case is then simulated with every comparator (conventional, the tracked
minimum-energy optimum, the stock drive's trapezoid) on the same plant and sensors, and
:func:`sim.fdsmc.recommend.recommend` names the controller to run and why.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

from control.common.checks import ParameterError
from control.fdsmc.params import DriveParams
from sim.fdsmc.design import DriveDesign, design_drive
from sim.fdsmc.engine import COMPARATORS, Comparison, compare
from sim.fdsmc.recommend import Recommendation, recommend

#: Design objectives: the first is the default.
OBJECTIVES = ("electrical", "friction")


@dataclass(frozen=True)
class ObjectiveDesign:
    """A design for an objective, every comparator's run on it, and the recommendation.

    Attributes
    ----------
    objective : str                 ``electrical`` or ``friction``.
    design : DriveDesign            The FDSMC design kept.
    rejected : DriveDesign or None  The other α rule's design (objective ``electrical``), for the record.
    comparison : Comparison or None The design's case with every comparator (None when not simulated).
    recommendation : Recommendation or None
    """

    objective: str
    design: DriveDesign
    rejected: DriveDesign | None
    comparison: Comparison | None
    recommendation: Recommendation | None


def _net(dd: DriveDesign) -> float:
    run = dd.comparison.fdsmc if dd.comparison is not None else None
    e = run.metrics.electrical_in_total_J if run is not None else None
    return e if e is not None else float("inf")


def design_for(params: DriveParams, objective: str = OBJECTIVES[0]) -> ObjectiveDesign:
    """Design the FDSMC for ``objective`` and compare every controller on the design (see the module doc)."""
    if objective not in OBJECTIVES:
        raise ParameterError(f"objective = {objective!r} is not allowed: one of {', '.join(OBJECTIVES)}")
    paper = design_drive(params, "torque_limit")
    kept, rejected = paper, None
    if objective == "electrical":
        lean = design_drive(params, "min_energy")
        if (lean.clean, -_net(lean)) > (paper.clean, -_net(paper)):
            kept, rejected = lean, paper
        else:
            rejected = lean
    if kept.comparison is None:
        return ObjectiveDesign(objective, kept, rejected, None, None)
    cmp = compare(kept.params, COMPARATORS, derived=kept.derived)
    return ObjectiveDesign(objective, kept, rejected, cmp, recommend(kept.params, cmp))


__all__ = ["OBJECTIVES", "ObjectiveDesign", "design_for"]
