"""Gains of the law that tracks a planned move (the minimum-energy optimum) and of its terminal slide.

The tracked optimum (:mod:`control.fdsmc.terminal_slide`) feeds the move's acceleration forward and
corrects the error with eq. (62) in [1] sign-corrected, α_dem = α_ref + g1·(θ_ref − θ̂_r) +
g2·(ω_ref − ω̂_r) (:func:`control.fdsmc.conventional.tracking_demand`), then ends on the FDSMC's
sloped segment with the boundary layer of eq. (46).

Tracking gains. Eq. (61)'s gains (double pole at 5.6/T_m) settle in T_m: far too slow to hold a
reference. The double pole a (g1 = a², g2 = 2a) is placed as fast as the loops and the sensors allow:

* a ≤ 1/(T_sα + T_so), below the FDC acceleration loop (pole 3/T_sα, eq. (13)) and the observer
  (eq. (17)) that it commands through;
* a ≤ α_max·K/3: the FDSMC's boundary-layer gain α_max·K (eq. (45)) is the largest gain on ω̂ the
  design verified free of chatter with the case's encoder and current noise; the tracking law also
  feeds θ̂ back (g1, which the FDSMC's horizontal segment does not), so its speed gain g2 = 2a is
  kept at 2/3 of it (with 1/2, the D5065 preset's 8192-count encoder drove α_dem's high-frequency
  peak-to-peak to 21 % of α_max, past the chatter criterion);
* halved until the linearised sampled loop (:mod:`control.fdsmc.loop_analysis`) is stable;
* never below eq. (61)'s pole.

Terminal slide. Inside the boundary layer the slide is the linear law α_dem = −α_max·K·(ω̂ +
θ̂_re/T_c), the characteristic polynomial s² + α_max·K·s + α_max·K/T_c (ideal inner loops). With
T_c = 4/(α_max·K) its poles meet (critical damping): the fastest approach without overshoot. The
slide uses T_c = SLIDE_RATIO/(α_max·K) with SLIDE_RATIO = 3.5, damping ζ = √3.5/2 = 0.94: on the
D5065 preset the critically damped slide had not reached its in-position window by the end of the
run, while 3.5 overshoots by ≤ 0.3 mrad on every real preset (windows 0.3–7.7 mrad).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses

from pmsm_commissioning.control.fdsmc.conventional import ConventionalGains
from pmsm_commissioning.control.fdsmc.loop_analysis import GainRecommendation, stability_measure
from pmsm_commissioning.control.fdsmc.loop_model import LoopCase

#: Most halvings of the tracking pole while the sampled loop is unstable [-].
MAX_HALVINGS = 12
#: The tracking pole's bound as a share of the FDSMC's boundary-layer gain α_max·K [-].
LAYER_SHARE = 1.0 / 3.0
#: T_c·α_max·K of the terminal slide [-] (module docstring).
SLIDE_RATIO = 3.5


def slide_gain(gain: GainRecommendation | None, K: float) -> float:
    """Return the boundary-layer gain K [s/rad] of the tracked optimum (its layer bound and its slide).

    The case's K where it is below the chatter limit of :mod:`control.fdsmc.loop_analysis`, else the
    recommended K: the tracked optimum is the tool's own controller and never runs a K that
    limit-cycles (the paper's K = 1000 does).

    Parameters
    ----------
    gain : GainRecommendation or None  ``Derived.gain`` (None: no analysis, the case's K).
    K : float                          The case's K [s/rad].
    """
    if gain is None or gain.K_ok or gain.K_recommended <= 0.0:
        return K
    return gain.K_recommended


def tracking_gains(loop: LoopCase, slowest: ConventionalGains, K: float) -> ConventionalGains:
    """Return the double-pole gains g1 = a², g2 = 2a of the tracking law (see the module doc).

    Parameters
    ----------
    loop : LoopCase                The case's linearised loop (``Derived.loop``), with α_max.
    slowest : ConventionalGains    Eq. (61)'s gains: the slowest pole allowed [1/s², 1/s].
    K : float                      The tracked optimum's boundary-layer gain (:func:`slide_gain`) [s/rad].
    """
    a = 1.0 / (loop.T_salpha + loop.T_so)
    if K > 0.0:
        a = min(a, LAYER_SHARE * loop.alpha_max * K)
    for _ in range(MAX_HALVINGS):
        if a <= slowest.a:
            return slowest
        case = dataclasses.replace(loop, g1=a * a, g2=2.0 * a)
        if stability_measure(case, "conventional", 0.0, loop.f_s, loop.delay) < 0.0:
            return ConventionalGains(g1=a * a, g2=2.0 * a, a=a)
        a *= 0.5
    return slowest


def slide_time_constant(alpha_max: float, K: float) -> float:
    """T_c of the terminal slide [s]: SLIDE_RATIO/(α_max·K) (module docstring).

    Parameters
    ----------
    alpha_max : float  α_max of eq. (45) in [1] [rad/s²].
    K : float          Boundary-layer gain of eq. (45) [s/rad].
    """
    return SLIDE_RATIO / (alpha_max * K)


def optimum_slide(gain: GainRecommendation | None, K: float, alpha_max: float) -> tuple[float, float]:
    """Return the tracked optimum's boundary-layer gain K [s/rad] and its terminal slide's T_c [s].

    :func:`slide_gain` of the case's ``K`` [s/rad], and :func:`slide_time_constant` with it for
    α_max [rad/s²].
    """
    K_slide = slide_gain(gain, K)
    return K_slide, slide_time_constant(alpha_max, K_slide)


def slide_stability(loop: LoopCase, K: float) -> float:
    """Stability measure of the terminal slide's linearised sampled loop (< 0: stable).

    The sloped-segment law of eq. (46) in [1] at the gain K (:func:`slide_gain`) and T_c =
    :func:`slide_time_constant` (:func:`control.fdsmc.loop_analysis.stability_measure`, law ``slope``).
    """
    case = dataclasses.replace(loop, T_c=slide_time_constant(loop.alpha_max, K))
    return stability_measure(case, "slope", K, loop.f_s, loop.delay)


__all__ = ["LAYER_SHARE", "MAX_HALVINGS", "SLIDE_RATIO", "optimum_slide", "slide_gain", "slide_stability",
           "slide_time_constant", "tracking_gains"]
