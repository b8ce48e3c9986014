"""The pass criteria a simulated design is judged by, with their defaults resolved.

A commissioning engineer sets them in the ``limits`` section (:class:`control.fdsmc.params.Limits`);
a field left at 0 takes the default stated there, resolved here once for the kernel, the metrics,
the verdicts and the design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc.feasibility import current_limit, speed_limit
from pmsm_commissioning.control.fdsmc.model import torque_constant
from pmsm_commissioning.control.fdsmc.params import ENCODER_CPR_MAX, DriveParams

#: Default in-position window [encoder counts].
IN_POSITION_COUNTS = 10
#: Encoder resolution the default window assumes for an ideal encoder [counts per rev]: 2²⁰.
IDEAL_ENCODER_CPR = 2**20
#: Default standstill ripple limit as a fraction of the drive's current limit [-].
HOLD_RIPPLE_FRACTION = 0.05


@dataclass(frozen=True)
class PassCriteria:
    """Resolved pass criteria of one case (SI units).

    Attributes
    ----------
    omega_max : float     Largest allowed |ω_r| [rad/s].
    in_position : float   In-position window ± around θ_dem [rad].
    overshoot : float     Largest allowed overshoot beyond θ_dem [rad].
    hold_i_rms : float    Largest allowed rms ripple of i_q at standstill [A].
    i_limit : float       The drive's current limit [A]: i_max, else Γ_max/Kt.
    """

    omega_max: float
    in_position: float
    overshoot: float
    hold_i_rms: float
    i_limit: float


def drive_current(params: DriveParams) -> float:
    """Return the drive's current limit [A].

    The hard limit of :func:`control.fdsmc.feasibility.current_limit`, else the current of Γ_max
    (Γ_max/K_t, eq. (5) in [1]).
    """
    return current_limit(params) or params.motor.Gamma_max / torque_constant(params.motor)


def pass_criteria(params: DriveParams) -> PassCriteria:
    """Return the pass criteria of ``params`` with every 0 (default) replaced as documented in ``Limits``."""
    lim, cpr = params.limits, params.sensors.encoder_cpr
    count = 2.0 * math.pi / (cpr if cpr > 0 else IDEAL_ENCODER_CPR)
    window = lim.in_position if lim.in_position > 0.0 else IN_POSITION_COUNTS * count
    i_lim = drive_current(params)
    return PassCriteria(
        omega_max=speed_limit(params),
        in_position=window,
        overshoot=lim.overshoot if lim.overshoot > 0.0 else window,
        hold_i_rms=lim.hold_i_rms if lim.hold_i_rms > 0.0 else HOLD_RIPPLE_FRACTION * i_lim,
        i_limit=i_lim,
    )


def encoder_cpr_for(counts_per_rev: float) -> int | None:
    """Smallest power-of-two encoder resolution ≥ ``counts_per_rev`` [counts/rev]; None above the largest allowed."""
    cpr = 2 ** max(0, math.ceil(math.log2(counts_per_rev)))
    return cpr if cpr <= ENCODER_CPR_MAX else None


def window_below_count(params: DriveParams) -> str | None:
    """Say why the in-position window or the overshoot limit is narrower than one encoder count, else None.

    The controller reads θ_r in whole counts Δ = 2π/cpr, so it cannot tell positions within one count
    apart: a window narrower than Δ is held, if at all, by chance. The remedy names two counts, or
    the encoder resolution (a power of two) that puts two counts inside the window.
    """
    cpr = params.sensors.encoder_cpr
    if cpr <= 0:
        return None
    crit, count = pass_criteria(params), params.sensors.encoder_step
    field, width = min((("limits.in_position", crit.in_position), ("limits.overshoot", crit.overshoot)),
                       key=lambda fw: fw[1])
    if width >= count:
        return None
    need = encoder_cpr_for(2.0 * 2.0 * math.pi / width)
    finer = f" or use an encoder with ≥ {need} counts/rev" if need is not None else ""
    return (f"{field} = {width:.4g} rad is narrower than one count of the {cpr}-count encoder ({count:.4g} rad): "
            f"the controller cannot tell positions within a count apart, so a run holds it only by chance. Widen it to "
            f"≥ {2.0 * count:.4g} rad (two counts){finer}.")


__all__ = ["HOLD_RIPPLE_FRACTION", "IDEAL_ENCODER_CPR", "IN_POSITION_COUNTS", "PassCriteria", "drive_current",
           "encoder_cpr_for", "pass_criteria", "window_below_count"]
