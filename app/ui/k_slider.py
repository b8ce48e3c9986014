"""The K slider of the live tuning: logarithmic, K_limit and K_recommended marked, mirroring the K field.

A lecturer drags K from the paper's 1000 s/rad down through the chatter limit K_limit (0.605 s/rad
for the paper's drive) in one sweep, so the slider (:class:`app.ui.log_slider.LogSlider`) spans
log₁₀ K over at least :data:`K_RANGE` and always a range holding K, K_limit and K_recommended
(whole decades). Where the sensors' noise sets the recommendation, their noise limit K_noise is
marked too ("noise", below K_limit). The readout under it says K in s/rad (red at or above
K_limit, or above K_noise) with the marked gains. A slider move writes K rounded to three
significant digits into the K field (the slider's step is 0.01 decade, ≈ 2.3 %); every other
change of K — typed, "Use recommended K", a preset, a file, a design — moves the slider to it
(:meth:`KSlider.show`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import viser

from pmsm_commissioning.app.figures.style import BAD_COLOUR, POSITION_COLOURS
from pmsm_commissioning.app.ui.log_slider import (
    LogSlider,
    Mark,
    hide_box_css,
    log_range,
    positive,
    readout_line,
    track_marks,
    value_of_position,
)

#: Least range of the K slider [s/rad]: the paper's K = 1000 and its chatter limit on one track.
K_RANGE = (0.01, 5000.0)
#: The slider's label.
K_LABEL = "K [s/rad] (log)"
#: Colour of a K below the chatter limit in the readout (the FDSMC's blue; red above it).
OK_COLOUR = POSITION_COLOURS["fdsmc"]


def log_K_range(K: float, K_limit: float, K_rec: float | None) -> tuple[float, float]:
    """Return the slider's (min, max) [log₁₀(s/rad)]: :data:`K_RANGE` widened to whole decades holding the gains."""
    return log_range((K, K_limit, K_rec), K_RANGE)


def K_of_position(position: float) -> float:
    """K [s/rad] at slider position ``position`` [log₁₀(s/rad)], to three significant digits."""
    return value_of_position(position)


def _gain_marks(K_limit: float, K_rec: float | None, K_noise: float = math.inf) -> tuple[Mark, ...]:
    noise = (("noise", K_noise),) if K_noise < K_limit else ()
    return (("rec", K_rec if K_rec is not None else 0.0), *noise, ("lim", K_limit))


def K_marks(lo: float, hi: float, K_limit: float, K_rec: float | None,
            K_noise: float = math.inf) -> tuple[tuple[float, str], ...]:
    """Return the track's marks (position [log₁₀], label).

    Both ends, "rec" at K_rec, "noise" at the sensors' noise limit K_noise where it is below
    K_limit, and "lim" at K_limit.
    """
    return track_marks(lo, hi, _gain_marks(K_limit, K_rec, K_noise))


def readout_html(K: float, K_limit: float, K_rec: float | None, K_noise: float = math.inf) -> str:
    """Return one line for under the slider: K [s/rad] and the marked gains, K in red where it chatters.

    K is red with "✗ chatters" at or above K_limit, or above the sensors' noise limit K_noise; blue
    with "✓ no chatter" below (:data:`OK_COLOUR`).
    """
    over = (positive(K_limit) and K_limit <= K) or K_noise < K
    # a word and a sign besides the colour; red against blue (ΔE ≥ 40 for deutan and protan viewers:
    # the red/green pair of before was 6.2 for deutans)
    word = "✗ chatters" if over else "✓ no chatter"
    parts = [f'<b style="color:{BAD_COLOUR if over else OK_COLOUR}">K = {K:.4g} s/rad {word}</b>']
    if positive(K_rec):
        parts.append(f"rec {K_rec:.3g}")
    if K_noise < K_limit:
        parts.append(f"noise {K_noise:.3g} (sensors)")
    if positive(K_limit):
        parts.append(f"lim {K_limit:.3g} (chatter above)")
    return readout_line("K", " · ".join(parts))


def _readout(K: float, marks: tuple[Mark, ...]) -> str:
    gains = dict(marks)
    return readout_html(K, gains.get("lim", 0.0), gains.get("rec"), gains.get("noise", math.inf))


class KSlider(LogSlider):
    """The logarithmic K slider and its readout; a user's move calls ``moved(K)`` [s/rad]."""

    def __init__(self, gui: viser.GuiApi, moved: Callable[[float], None]) -> None:
        super().__init__(gui, K_LABEL, K_RANGE, _readout, moved,
                         hint="Logarithmic: drag across 'lim' (K_limit) to see the chatter start")

    def show_gains(self, K: float, K_limit: float, K_rec: float | None, K_noise: float = math.inf) -> None:
        """Mirror ``K`` [s/rad] with K_limit, K_rec and (below K_limit) the noise limit K_noise marked."""
        self.show(K, _gain_marks(K_limit, K_rec, K_noise))


__all__ = ["K_LABEL", "K_RANGE", "OK_COLOUR", "KSlider", "K_marks", "K_of_position", "hide_box_css", "log_K_range",
           "readout_html"]
