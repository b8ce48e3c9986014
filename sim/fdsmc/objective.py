"""Design for the energy the user cares about: the supply's energy (default) or the paper's friction.

The paper's profile (section 4 of [1]) minimises the friction loss and runs at the largest α the
torque allows. On servo drives the copper loss dominates and falls with α, so for the objective
``electrical`` (and ``in_position_by_T_m``) the FDSMC is designed twice — at the torque limit's α
and at the α that minimises the profile's friction + copper (``alpha_max_rule = min_energy``) — and
the clean design whose verification run takes the least energy from the supply under the drive's
DC-link choice (:func:`sim.fdsmc.recommend.run_supply_J`: drawn with a braking resistor, net with a
regenerative link) is kept.
``friction`` is the paper's choice (``torque_limit``), unchanged. ``in_position_by_T_m`` reads the
requested T_m as the time by which the axis must be in position (cycle time): the move ends early
enough that the verified run is inside the window by then
(:func:`sim.fdsmc.design_search.in_position_by`), least energy kept.

Either way the design's case is then simulated with every comparator (conventional, the tracked
minimum-energy optimum, the stock drive's trapezoid) on the same plant and sensors, and
:func:`sim.fdsmc.recommend.recommend` names the controller to run and why.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.design import DriveDesign, design_drive
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, Comparison, compare
from pmsm_commissioning.sim.fdsmc.recommend import Recommendation, recommend, run_supply_J

#: Design objectives: the first is the default.
OBJECTIVES = ("electrical", "friction", "in_position_by_T_m")


@dataclass(frozen=True)
class ObjectiveDesign:
    """A design for an objective, every comparator's run on it, and the recommendation.

    Attributes
    ----------
    objective : str                 ``electrical``, ``friction`` or ``in_position_by_T_m``.
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


def _supply(dd: DriveDesign) -> float:
    """Return the supply's energy of the design's verification run [J] (inf: none)."""
    run = dd.comparison.fdsmc if dd.comparison is not None else None
    e = run_supply_J(run, dd.params.controller)
    return e if e is not None else float("inf")


def _rank(dd: DriveDesign) -> int:
    """Return 2 for a clean design, 1 for one clean only not as asked, 0 for one not clean."""
    return {"clean": 2, "not as asked": 1, "not clean": 0}[dd.verdict]


def design_for(params: DriveParams, objective: str = OBJECTIVES[0]) -> ObjectiveDesign:
    """Design the FDSMC for ``objective`` and compare every controller on the design (see the module doc)."""
    if objective not in OBJECTIVES:
        raise ParameterError(f"objective = {objective!r} is not allowed: one of {', '.join(OBJECTIVES)}")
    cycle = objective == "in_position_by_T_m"
    paper = design_drive(params, "torque_limit", cycle)
    kept, rejected = paper, None
    if objective != "friction":
        lean = design_drive(params, "min_energy", cycle)
        if (_rank(lean), -_supply(lean)) > (_rank(paper), -_supply(paper)):
            kept, rejected = lean, paper
        else:
            rejected = lean
    if kept.comparison is None:
        return ObjectiveDesign(objective, kept, rejected, None, None)
    cmp = compare(kept.params, COMPARATORS, derived=kept.derived)
    return ObjectiveDesign(objective, kept, rejected, cmp, recommend(kept.params, cmp))


__all__ = ["OBJECTIVES", "ObjectiveDesign", "design_for"]
