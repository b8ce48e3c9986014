"""The DC link's energies as every output writes them: the choice used, per-run figures, text lines.

The figures are :class:`sim.fdsmc.recommend.ControllerEnergy`; the choice and its physics are
:mod:`control.common.dc_link`. ``simulate``, ``design``, the HTML report and the page say the same.
"""

from __future__ import annotations

from typing import Any

from pmsm_commissioning.control.common.dc_link import dc_link_text
from pmsm_commissioning.control.fdsmc.params import Controller
from pmsm_commissioning.sim.fdsmc.engine import LABELS
from pmsm_commissioning.sim.fdsmc.recommend import ControllerEnergy, Recommendation

#: Which energy the headline, savings, optimum gap and recommendation use (said in every output).
ENERGY_BASIS = ("dc_link_J: the energy the supply delivers over the whole run under controller.dc_link "
                "(braking_resistor: drawn; regenerative: net = drawn − returned; battery: drawn − "
                "charge_efficiency × returned); the headline, the *_dc_link_pct savings, the design objective and "
                "the recommendation use it; *_pct without a suffix compare the net electrical input, *_drawn_pct "
                "the energy drawn")


def choice_json(c: Controller) -> dict[str, Any]:
    """Return the ``dc_link`` entry of the JSON outputs: the choice, η_ch and the words."""
    return {"choice": c.dc_link, "charge_efficiency": c.charge_efficiency,
            "text": dc_link_text(c.dc_link, c.charge_efficiency)}


def run_json(e: ControllerEnergy) -> dict[str, float]:
    """Return a run's energies at the DC link [J]: drawn ∫max(p, 0) dt, returned, net and the supply's."""
    return {"drawn_J": e.drawn_J, "returned_J": e.returned_J, "net_J": e.net_electrical_J,
            "braking_resistor_supply_J": e.drawn_J, "dc_link_J": e.dc_link_J}


def energy_lines(rec: Recommendation) -> list[str]:
    """Return the text outputs' energy lines: the supply's energy (headline), then drawn / returned / net."""
    best = rec.controller
    return [
        f"Energy from the supply, whole run ({rec.dc_link}): " + ", ".join(
            f"{LABELS[e.controller]} {e.dc_link_J:.4g} J{' (recommended)' if e.controller == best else ''}"
            for e in rec.energies),
        "Drawn from / returned to the DC link / net electrical input, whole run: " + ", ".join(
            f"{LABELS[e.controller]} {e.drawn_J:.4g} / {e.returned_J:.4g} / {e.net_electrical_J:.4g} J "
            f"(copper {e.copper_J:.3g}, friction {e.friction_J:.3g})" for e in rec.energies),
    ]


__all__ = ["ENERGY_BASIS", "choice_json", "energy_lines", "run_json"]
