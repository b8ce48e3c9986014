"""The page's savings estimate: energy and money the FDSMC saves per axis and year (no viser here).

The economics (kWh per year, cost) are :mod:`sim.common.economics`, shared with the duty-cycle study.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.sim.common.economics import cost_per_year, kwh_per_year
from pmsm_commissioning.sim.fdsmc.recommend import run_supply_J


@dataclass(frozen=True)
class AnnualSavings:
    """Energy and money the FDSMC saves per axis and year vs the conventional controller.

    Attributes
    ----------
    per_cycle_J : float   Supply energy saved per manoeuvre [J] (negative = costs more), under the DC-link choice.
    kWh_per_year : float  Saved energy per year [kWh].
    money_per_year : float  Saved money per year [currency].
    """

    per_cycle_J: float
    kWh_per_year: float
    money_per_year: float


def annual_savings(comparison: Any, cycles_per_hour: float, hours_per_year: float,
                   price_per_kWh: float) -> AnnualSavings | None:
    """Return the savings on the supply's energy over the simulated horizon; None without both runs.

    The supply's energy is :func:`sim.fdsmc.recommend.run_supply_J` under the case's ``controller.dc_link``.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
    cycles_per_hour : float  Manoeuvres per hour [1/h].
    hours_per_year : float   Operating hours per year [h].
    price_per_kWh : float    Energy price [currency/kWh].
    """
    f, c = comparison.fdsmc, comparison.conventional
    if f is None or c is None or not (f.metrics.stable and c.metrics.stable):
        return None
    link = comparison.derived.params.controller
    e_f, e_c = run_supply_J(f, link), run_supply_J(c, link)
    if e_f is None or e_c is None:
        return None
    per_cycle = e_c - e_f
    kwh = kwh_per_year(per_cycle, cycles_per_hour, hours_per_year)
    return AnnualSavings(per_cycle, kwh, cost_per_year(kwh, price_per_kWh))


def savings_markdown(s: AnnualSavings | None, currency: str = "€") -> str:
    """Markdown summary of :func:`annual_savings`."""
    if s is None:
        return "_Simulate both controllers (stable runs) to estimate the savings._"
    verb = "saves" if s.per_cycle_J >= 0 else "**costs more**:"
    return (f"FDSMC {verb} **{abs(s.per_cycle_J):.4g} J** from the supply per cycle → "
            f"**{s.kWh_per_year:.4g} kWh/year** and **{s.money_per_year:.4g} {currency}/year** per axis "
            "(negative = the conventional controller is cheaper).")


__all__ = ["AnnualSavings", "annual_savings", "savings_markdown"]
