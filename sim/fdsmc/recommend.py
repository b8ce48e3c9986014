"""The supply's energy per controller, and the controller to recommend for the user's drive.

The headline figure of a comparison is the **energy the supply delivers** to the DC link over the
whole run (rest to rest), under the drive's DC-link choice ``controller.dc_link``
(:func:`control.common.dc_link.supply_energy`): the energy drawn with a braking resistor (the
default, a stock servo drive), the net electrical input with a regenerative link, drawn minus
η_ch × returned with a battery — not the paper's friction loss (eq. (47) in [1]): on servo drives
the copper loss dominates. The recommended controller is the one whose supply energy is least
among those whose run passes every check on the real drive (:func:`sim.fdsmc.checks.run_checks`:
limits, sensors, in-position, overshoot, ripple).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.dc_link import dc_link_text, supply_energy
from pmsm_commissioning.control.fdsmc.params import Controller, DriveParams
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
    dc_link_J : float           Energy the supply delivers under the drive's DC-link choice [J].
    """

    controller: str
    net_electrical_J: float
    copper_J: float
    friction_J: float
    failed: tuple[str, ...]
    drawn_J: float = math.nan
    returned_J: float = math.nan
    dc_link_J: float = math.nan

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
    dc_link : str                     The DC-link choice the energies were ranked under, in words
                                      (:func:`control.common.dc_link.dc_link_text`).
    """

    controller: str | None
    why: str
    energies: tuple[ControllerEnergy, ...]
    dc_link: str = ""


def runs_of(cmp: Comparison) -> list[RunResult]:
    """Return the comparison's runs in order: FDSMC, conventional, optimum, stock (those simulated)."""
    return [r for r in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock) if r is not None]


def run_supply_J(run: RunResult | None, controller: Controller) -> float | None:
    """Return the energy the supply delivers over ``run`` (whole run) under ``controller.dc_link`` [J].

    None unless the run is stable with its drawn and net energies.
    """
    if run is None or not run.metrics.stable:
        return None
    drawn, net = run.metrics.motoring_total_J, run.metrics.electrical_in_total_J
    if drawn is None or net is None:
        return None
    return supply_energy(drawn, drawn - net, controller.dc_link, controller.charge_efficiency)


def controller_energies(params: DriveParams, cmp: Comparison) -> tuple[ControllerEnergy, ...]:
    """Return the energy headline of every stable run of ``cmp`` (whole run) with its failed checks."""
    out = []
    c = params.controller
    for run in runs_of(cmp):
        m = run.metrics
        if m.stable and m.electrical_in_total_J is not None:
            failed = tuple(x.name for x in run_checks(params, run))
            drawn = m.motoring_total_J if m.motoring_total_J is not None else math.nan
            returned = drawn - m.electrical_in_total_J
            out.append(ControllerEnergy(run.controller, m.electrical_in_total_J, m.copper_total_J or 0.0,
                                        m.friction_total_J or 0.0, failed, drawn, returned,
                                        supply_energy(drawn, returned, c.dc_link, c.charge_efficiency)))
    return tuple(out)


def recommend(params: DriveParams, cmp: Comparison) -> Recommendation:
    """Recommend the clean run whose supply energy is least under the DC-link choice (see the module doc)."""
    return rank(controller_energies(params, cmp), params.controller)


def rank(energies: tuple[ControllerEnergy, ...], controller: Controller) -> Recommendation:
    """Recommend the clean run of ``energies`` with the least ``dc_link_J``, said under ``controller.dc_link``."""
    link = dc_link_text(controller.dc_link, controller.charge_efficiency)
    clean = sorted((e for e in energies if e.clean and e.dc_link_J == e.dc_link_J), key=lambda e: e.dc_link_J)
    if not clean:
        fails = "; ".join(f"{LABELS[e.controller]}: {', '.join(e.failed)}" for e in energies)
        return Recommendation(None, f"No controller passes every check on this drive ({fails}).", energies, link)
    best = clean[0]
    others = [e for e in energies if e.controller != best.controller]
    beaten = ", ".join(f"{LABELS[e.controller]} {e.dc_link_J:.4g} J"
                       + ("" if e.clean else f" (fails {', '.join(e.failed)})") for e in others)
    why = (f"{LABELS[best.controller]} takes the least energy from the supply, {best.dc_link_J:.4g} J "
           f"(copper {best.copper_J:.3g} J, friction {best.friction_J:.3g} J), of the controllers that pass "
           f"every check ({link})" + (f"; {beaten}." if beaten else "."))
    return Recommendation(best.controller, why, energies, link)


__all__ = ["ControllerEnergy", "Recommendation", "controller_energies", "rank", "recommend", "run_supply_J",
           "runs_of"]
