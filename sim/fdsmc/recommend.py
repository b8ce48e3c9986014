"""Net electrical energy per controller, and the controller to recommend for the user's drive.

The headline figure of a comparison is the **net electrical input** of each simulated run over the
whole move (rest to rest: what the drive draws from its DC link, friction + copper + the load's work,
regeneration netted), not the paper's friction loss (eq. (47) in [1]): on servo drives the copper
loss dominates. The recommended controller is the one that draws the least net electrical energy
among those whose run passes every check on the real drive (:func:`sim.fdsmc.checks.run_checks`:
limits, sensors, in-position, overshoot, ripple).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.engine import LABELS, Comparison, RunResult


@dataclass(frozen=True)
class ControllerEnergy:
    """One run's energy headline (whole run) [J] and whether it passes every check.

    Attributes
    ----------
    controller : str            ``fdsmc``, ``conventional``, ``optimum`` or ``stock``.
    net_electrical_J : float    Net electrical input [J].
    copper_J, friction_J : float  Its copper and friction losses [J].
    failed : tuple of str       Names of the checks the run fails (empty: clean).
    drawn_J : float             Energy drawn from the DC link, ∫max(p_el, 0) dt [J]: what the supply
                                delivers when a braking resistor burns the regenerated energy.
    returned_J : float          Energy returned to the DC link (regenerated), drawn − net [J].
    """

    controller: str
    net_electrical_J: float
    copper_J: float
    friction_J: float
    failed: tuple[str, ...]
    drawn_J: float = math.nan
    returned_J: float = math.nan

    @property
    def clean(self) -> bool:
        """True when the run passes every check."""
        return not self.failed


@dataclass(frozen=True)
class Recommendation:
    """The controller to run on this drive and why.

    Attributes
    ----------
    controller : str or None          The recommended controller; None when no run passes every check.
    why : str                         One sentence.
    energies : tuple of ControllerEnergy  Every stable run, in the comparison's order.
    """

    controller: str | None
    why: str
    energies: tuple[ControllerEnergy, ...]


def runs_of(cmp: Comparison) -> list[RunResult]:
    """Return the comparison's runs in order: FDSMC, conventional, optimum, stock (those simulated)."""
    return [r for r in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock) if r is not None]


def controller_energies(params: DriveParams, cmp: Comparison) -> tuple[ControllerEnergy, ...]:
    """Return the energy headline of every stable run of ``cmp`` (whole run) with its failed checks."""
    out = []
    for run in runs_of(cmp):
        m = run.metrics
        if m.stable and m.electrical_in_total_J is not None:
            failed = tuple(c.name for c in run_checks(params, run))
            drawn = m.motoring_total_J if m.motoring_total_J is not None else math.nan
            out.append(ControllerEnergy(run.controller, m.electrical_in_total_J, m.copper_total_J or 0.0,
                                        m.friction_total_J or 0.0, failed, drawn, drawn - m.electrical_in_total_J))
    return tuple(out)


def recommend(params: DriveParams, cmp: Comparison) -> Recommendation:
    """Recommend the clean run with the least net electrical input (see the module doc)."""
    energies = controller_energies(params, cmp)
    clean = sorted((e for e in energies if e.clean), key=lambda e: e.net_electrical_J)
    if not clean:
        fails = "; ".join(f"{LABELS[e.controller]}: {', '.join(e.failed)}" for e in energies)
        return Recommendation(None, f"No controller passes every check on this drive ({fails}).", energies)
    best = clean[0]
    others = [e for e in energies if e.controller != best.controller]
    beaten = ", ".join(f"{LABELS[e.controller]} {e.net_electrical_J:.4g} J"
                       + ("" if e.clean else f" (fails {', '.join(e.failed)})") for e in others)
    why = (f"{LABELS[best.controller]} draws the least net electrical energy, {best.net_electrical_J:.4g} J "
           f"(copper {best.copper_J:.3g} J, friction {best.friction_J:.3g} J), of the controllers that pass "
           f"every check" + (f"; {beaten}." if beaten else "."))
    return Recommendation(best.controller, why, energies)


def least_drawn(energies: tuple[ControllerEnergy, ...]) -> ControllerEnergy | None:
    """Return the clean run that draws the least from the DC link (None: no clean run).

    With a braking resistor (no regeneration into the supply) the supply delivers the drawn energy,
    not the net one, so this is the controller a drive without regeneration would be given.
    """
    clean = [e for e in energies if e.clean and e.drawn_J == e.drawn_J]  # NaN: no drawn figure
    return min(clean, key=lambda e: e.drawn_J) if clean else None


__all__ = ["ControllerEnergy", "Recommendation", "controller_energies", "least_drawn", "recommend", "runs_of"]
