"""Coordinated multi-axis moves: several axes (each its own motor, load and move) finishing together.

The common manoeuvre time is the largest of the axes' shortest feasible times
(:func:`sim.fdsmc.design.design_drive` with a vanishing requested T_m), or the requested one when longer.
Each axis is then designed for that T_m (torque-limit α_max, recommended K, verified by
simulation) and simulated; its energy is compared with the axis running at its own fastest time.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.checks import TARGET_BAND
from pmsm_commissioning.sim.fdsmc.design import DriveDesign, design_drive

#: Requested T_m [s] that makes the design return the axis's shortest feasible time.
SHORTEST_REQUEST_S = 1e-3


@dataclass(frozen=True)
class AxisResult:
    """One axis: its own fastest design and its design at the common T_m."""

    name: str
    fastest: DriveDesign
    common: DriveDesign

    def energy(self, which: str) -> float | None:
        """FDSMC net electrical input over the whole run [J] of ``fastest`` or ``common``."""
        cmp = getattr(self, which).comparison
        run = cmp.fdsmc if cmp is not None else None
        v = run.metrics.electrical_in_total_J if run is not None else None
        return float(v) if isinstance(v, float) else None

    @property
    def theta_error_at_Tm_rad(self) -> float | None:
        """Position error at the common T_m [rad]."""
        cmp = self.common.comparison
        v = cmp.fdsmc.metrics.theta_error_at_Tm_rad if cmp is not None and cmp.fdsmc else None
        return float(v) if isinstance(v, float) else None

    @property
    def arrived(self) -> bool:
        """|θ error at T_m| within the FDSMC's arrival band (fraction of θ_dem)."""
        err = self.theta_error_at_Tm_rad
        band = TARGET_BAND["fdsmc"] * abs(self.common.params.manoeuvre.theta_dem)
        return err is not None and abs(err) <= band


@dataclass(frozen=True)
class MultiAxisResult:
    """The common T_m [s] and every axis."""

    T_m: float
    axes: tuple[AxisResult, ...]


def _with_T_m(p: DriveParams, T_m: float) -> DriveParams:
    return dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, T_m=T_m))


def coordinate(axes: Sequence[tuple[str, DriveParams]], T_m: float | None = None,
               checkpoint: Callable[[], None] = lambda: None) -> MultiAxisResult:
    """Design and simulate every axis at the common T_m (see the module docstring).

    ``checkpoint()`` is called before each axis's design (it may raise to stop the run, e.g. a Cancel).

    Raises
    ------
    ParameterError
        For no axis, or an axis with no feasible design (naming it and why).
    """
    if not axes:
        raise ParameterError("axes: allowed at least one axis")
    fastest = []
    for name, p in axes:
        checkpoint()
        dd = design_drive(_with_T_m(p, SHORTEST_REQUEST_S))
        if dd.comparison is None:
            why = "; ".join(c.text for c in dd.limiting if c.violated)
            raise ParameterError(f"axis {name!r} has no feasible design: {why}")
        fastest.append(dd)
    T_common = max(dd.params.manoeuvre.T_m for dd in fastest)
    if T_m is not None:
        T_common = max(T_common, float(T_m))
    out = []
    for (name, p), dd in zip(axes, fastest, strict=True):
        checkpoint()
        common = dd if dd.params.manoeuvre.T_m == T_common else design_drive(_with_T_m(p, T_common))
        out.append(AxisResult(name, dd, common))
    return MultiAxisResult(T_common, tuple(out))
