"""How far a controller's run is from the tracked minimum-energy optimum (:mod:`control.fdsmc.optimum`)."""

from __future__ import annotations

from pmsm_commissioning.control.fdsmc.params import Controller
from pmsm_commissioning.sim.fdsmc.engine import RunResult
from pmsm_commissioning.sim.fdsmc.recommend import run_supply_J

#: Energy compared with the optimum: the net electrical input over the whole simulated horizon.
OPTIMUM_BASIS = "electrical_in_total_J"
#: The alternative basis: the energy drawn from the DC link over the whole horizon, ∫max(p_el, 0) dt
#: (what the supply delivers when a braking resistor burns the regenerated energy).
DRAWN_BASIS = "motoring_total_J"


def saving_vs_optimum(run: RunResult | None, optimum: RunResult | None, basis: str = OPTIMUM_BASIS
                      ) -> float | None:
    """Return 100·(1 − W_opt/W) [%]: the share of ``run``'s energy the tracked optimum would save.

    W is the net electrical input over the whole horizon [J] (:data:`OPTIMUM_BASIS`), or with
    ``basis`` = :data:`DRAWN_BASIS` the energy drawn from the DC link; None unless both runs are stable.
    """
    if run is None or optimum is None or not (run.metrics.stable and optimum.metrics.stable):
        return None
    w: float | None = getattr(run.metrics, basis)
    w_opt: float | None = getattr(optimum.metrics, basis)
    if w is None or w_opt is None or w <= 0.0:
        return None
    return 100.0 * (1.0 - w_opt / w)


def supply_saving_vs_optimum(run: RunResult | None, optimum: RunResult | None, controller: Controller
                             ) -> float | None:
    """Return 100·(1 − W_opt/W) [%] with W the energy the supply delivers under ``controller.dc_link``.

    The headline basis (:func:`sim.fdsmc.recommend.run_supply_J`); None unless both runs are stable
    and W > 0.
    """
    w, w_opt = run_supply_J(run, controller), run_supply_J(optimum, controller)
    if w is None or w_opt is None or w <= 0.0:
        return None
    return 100.0 * (1.0 - w_opt / w)


__all__ = ["DRAWN_BASIS", "OPTIMUM_BASIS", "saving_vs_optimum", "supply_saving_vs_optimum"]
