"""Gains of the law that tracks a planned move (the minimum-energy optimum): as fast as the loops allow.

The tracked optimum feeds the move's acceleration forward and corrects the error with eq. (62) in
[1] sign-corrected, α_dem = α_ref + g1·(θ_ref − θ̂_r) + g2·(ω_ref − ω̂_r)
(:func:`control.fdsmc.conventional.tracking_demand`). Eq. (61)'s gains (double pole at 5.6/T_m) settle
in T_m: far too slow to hold a reference, so the tracking error — and the final approach into an
in-position window of a few encoder counts — would be left to them. Here the double pole is placed
at a = 1/(T_sα + T_so), below the FDC acceleration loop (pole 3/T_sα, eq. (13)) and the observer
(eq. (17)) that it commands through, and halved until the linearised sampled loop
(:mod:`control.fdsmc.loop_analysis`) is stable; never below eq. (61)'s pole.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses

from control.fdsmc.conventional import ConventionalGains
from control.fdsmc.loop_analysis import stability_measure
from control.fdsmc.loop_model import LoopCase

#: Most halvings of the tracking pole while the sampled loop is unstable [-].
MAX_HALVINGS = 12


def tracking_gains(loop: LoopCase, slowest: ConventionalGains) -> ConventionalGains:
    """Return the double-pole gains g1 = a², g2 = 2a of the tracking law (see the module doc).

    Parameters
    ----------
    loop : LoopCase                The case's linearised loop (``Derived.loop``).
    slowest : ConventionalGains    Eq. (61)'s gains: the slowest pole allowed [1/s², 1/s].
    """
    a = 1.0 / (loop.T_salpha + loop.T_so)
    for _ in range(MAX_HALVINGS):
        if a <= slowest.a:
            return slowest
        case = dataclasses.replace(loop, g1=a * a, g2=2.0 * a)
        if stability_measure(case, "conventional", 0.0, loop.f_s, loop.delay) < 0.0:
            return ConventionalGains(g1=a * a, g2=2.0 * a, a=a)
        a *= 0.5
    return slowest


__all__ = ["MAX_HALVINGS", "tracking_gains"]
