"""The energy balance of a simulated run, shared by both modes.

Each kernel integrates the electrical input and every sink (copper, friction, load work) as extra
states of its own RK4 steps — the position drive's in :func:`sim.fdsmc.kernel.plant_rhs` (states
``X_EF`` … ``X_ELOAD`` of :mod:`sim.fdsmc.layout`), the BLDC drive's in :mod:`sim.bldc.kernel` (its
state's E_in, E_copper, E_friction, E_load) — and this module only reads them; what the rotor and the
windings still hold at the end closes the balance

    E_in = Σ losses + Σ stored,

so the residual E_in − Σ losses − Σ stored measures the integration error of the run [J].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


@dataclass(frozen=True)
class EnergyBalance:
    """Residual of the energy balance of one run.

    Attributes
    ----------
    residual_J : float    E_in − Σ losses − Σ stored [J].
    residual_pct : float  100·|residual| / max(|E_in|, scale) [%].
    """

    residual_J: float
    residual_pct: float


def energy_balance(
    electrical_in: float, losses: Sequence[float], stored: Sequence[float], scale: float
) -> EnergyBalance:
    """Residual of E_in = Σ losses + Σ stored, absolute [J] and relative [%].

    Parameters
    ----------
    electrical_in : float       Net electrical input energy E_in [J].
    losses : sequence of float  Copper and friction losses and the load work [J].
    stored : sequence of float  Energy still held at the end (kinetic, magnetic) [J].
    scale : float               Second reference of the relative residual (the largest energy
                                that flowed, in case E_in nets out near 0) [J].
    """
    residual = electrical_in - sum(losses) - sum(stored)
    ref = max(abs(electrical_in), scale, 1e-12)
    return EnergyBalance(float(residual), float(100.0 * abs(residual) / ref))
