"""Energy economics of repeated moves: energy per year and its cost (one place for both modes' studies)."""

from __future__ import annotations

#: Joules per kilowatt-hour [J/kWh].
J_PER_KWH = 3.6e6


def kwh_per_year(energy_per_cycle_J: float, cycles_per_hour: float, hours_per_year: float) -> float:
    """Return the yearly energy [kWh] of ``energy_per_cycle_J`` [J] per cycle.

    ``cycles_per_hour`` [1/h] cycles for ``hours_per_year`` [h] a year.
    """
    return energy_per_cycle_J * cycles_per_hour * hours_per_year / J_PER_KWH


def cost_per_year(kwh: float, price_per_kWh: float) -> float:
    """Return the cost of ``kwh`` [kWh] at ``price_per_kWh`` [currency/kWh] [currency]."""
    return kwh * price_per_kWh


__all__ = ["J_PER_KWH", "cost_per_year", "kwh_per_year"]
