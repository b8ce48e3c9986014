"""The K demo's verdict, computed from the FDSMC run: "CHATTER 270 Hz" or "sliding, no chatter".

A lecturer drags K across the chatter limit K_limit of the sampled loop
(:mod:`control.fdsmc.loop_analysis`); the overview figure then says, in large letters on the phase
plane, what the run did — from the run's own chatter test (:mod:`sim.fdsmc.metrics`), not from the
prediction — and where K stands against K_limit.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.app.figures.style import BAD_COLOUR, GOOD_COLOUR

#: Font size of the verdict on the plot [px] (a projector's back row).
VERDICT_FONT_PX = 20
#: Font size of the line below it (K against K_limit) [px].
DETAIL_FONT_PX = 16


@dataclass(frozen=True)
class Verdict:
    """What the FDSMC run did: ``headline``, ``detail`` (K vs K_limit), ``chatter`` (True: chatters or unstable)."""

    headline: str
    detail: str
    chatter: bool

    @property
    def text(self) -> str:
        """The verdict on one line: ``"CHATTER 270 Hz (K ≥ K_limit = 0.605)"``."""
        return f"{self.headline} ({self.detail})"


def _k_vs_limit(K: float, K_limit: float, K_noise: float = math.inf) -> str:
    """Say where K [s/rad] stands against the chatter limit [s/rad]: the sensors' K_noise where lower."""
    if K_noise < K_limit:
        return f"K {'≤' if K_noise >= K else '>'} K_noise = {K_noise:.3g} (sensors)"
    if not K_limit > 0.0:
        return f"K = {K:.3g}"
    return f"K {'<' if K_limit > K else '≥'} K_limit = {K_limit:.3g}"


def _plant_note(d: Any, plant_J_L: float | None) -> str:
    """Say that K_limit is the model's where the plant's load inertia [kg·m²] differs from it."""
    if plant_J_L is None:
        return ""
    model = d.params.load.J_L
    if abs(plant_J_L - model) <= 1e-9 * max(abs(model), 1e-30):
        return ""
    ratio = f"×{plant_J_L / model:.3g}" if model > 0.0 else f"= {plant_J_L:.3g} kg·m²"
    return f", the model's (plant J_L {ratio})"


def chatter_verdict(comparison: Any, plant_J_L: float | None = None) -> Verdict | None:
    """Verdict of the FDSMC run of ``comparison`` (:class:`sim.fdsmc.engine.Comparison`), None if not run.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
        The derivations and the runs; the run's metrics decide, K_limit (the loop analysis) explains.
    plant_J_L : float or None
        The plant's load inertia [kg·m²] the run had (None: the model's). Where it differs from the
        controller's J_L, K_limit is still computed for the model's: the detail says so
        (``K < K_limit = 0.605, the model's (plant J_L ×3)``).

    Returns
    -------
    Verdict or None
        Headline ``CHATTER 270 Hz``, ``sliding, no chatter`` or ``UNSTABLE``, detail
        ``K < K_limit = 0.605``; None when the FDSMC was not simulated (an infeasible manoeuvre).
    """
    run = comparison.fdsmc
    if run is None:
        return None
    m, d = run.metrics, comparison.derived
    where = _k_vs_limit(d.params.controller.K, d.gain.K_limit, d.gain.K_noise_binding) + _plant_note(d, plant_J_L)
    if not m.stable:
        return Verdict("UNSTABLE", where, True)
    if m.chatter:
        freq = "" if m.chatter_frequency_Hz is None else f" {m.chatter_frequency_Hz:.0f} Hz"
        return Verdict(f"CHATTER{freq}", where, True)
    return Verdict("sliding, no chatter", where, False)


def verdict_annotation(verdict: Verdict, x: float) -> dict[str, Any]:
    """Return the Plotly annotation of ``verdict`` at the top right of a plot domain ending at ``x`` [paper].

    Named ``"verdict"`` (the page's tests find it by name), red or green on a white box: the
    headline in :data:`VERDICT_FONT_PX`, K against K_limit below it in :data:`DETAIL_FONT_PX`.
    """
    colour = BAD_COLOUR if verdict.chatter else GOOD_COLOUR
    text = (f"<b>{html.escape(verdict.headline)}</b><br>"  # "<" would open a tag in Plotly's text
            f"<span style=\"font-size:{DETAIL_FONT_PX}px\">{html.escape(verdict.detail)}</span>")
    return {"name": "verdict", "text": text, "x": x, "y": 1.0, "xref": "paper",
            "yref": "paper", "xanchor": "right", "yanchor": "top", "showarrow": False,
            "font": {"size": VERDICT_FONT_PX, "color": colour}, "bgcolor": "rgba(255,255,255,0.85)",
            "bordercolor": colour, "borderwidth": 2, "borderpad": 4}


__all__ = ["VERDICT_FONT_PX", "Verdict", "chatter_verdict", "verdict_annotation"]
