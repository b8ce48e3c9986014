"""The K slider of the live tuning: logarithmic, K_limit and K_recommended marked, mirroring the K field.

A lecturer drags K from the paper's 1000 s/rad down through the chatter limit K_limit (0.605 s/rad
for the paper's drive) in one sweep, so the slider's position is log₁₀ K over at least
:data:`K_RANGE` and always over a range holding K, K_limit and K_recommended (whole decades). The
slider's own number box would show log₁₀ K and is hidden (:func:`hide_box_css`); a readout line
under it says K in s/rad with the two marked gains. A slider move writes K rounded to
:data:`K_DIGITS` significant digits into the K field (the slider's step is 0.01 decade, ≈ 2.3 %);
every other change of K — typed, "Use recommended K", a preset, a file, a design — moves the
slider to it (:meth:`KSlider.show`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import viser

from app.ui.props import assign
from app.ui.viser_adapter import set_slider_marks, widget_id

#: Least range of the K slider [s/rad]: the paper's K = 1000 and its chatter limit on one track.
K_RANGE = (0.01, 5000.0)
#: Step of the slider's position [decades] and the decimals it keeps.
LOG_STEP, LOG_PRECISION = 0.01, 2
#: Significant digits of a K written by the slider.
K_DIGITS = 3
#: The slider's label.
K_LABEL = "K [s/rad] (log)"


def _positive(k: float | None) -> bool:
    """Return True for a finite gain > 0 (a K_limit of 0 or ∞ means "no limit found")."""
    return k is not None and math.isfinite(k) and k > 0.0


def log_K_range(K: float, K_limit: float, K_rec: float | None) -> tuple[float, float]:
    """Return the slider's (min, max) [log₁₀(s/rad)].

    That is :data:`K_RANGE` widened to whole decades holding every positive one of ``K``,
    ``K_limit`` and ``K_rec``.
    """
    lo, hi = math.log10(K_RANGE[0]), math.log10(K_RANGE[1])
    for k in (K, K_limit, K_rec):
        if _positive(k):
            lo, hi = min(lo, math.floor(math.log10(k))), max(hi, math.ceil(math.log10(k)))
    return float(lo), float(hi)


def K_of_position(position: float) -> float:
    """K [s/rad] at slider position ``position`` [log₁₀(s/rad)], to :data:`K_DIGITS` significant digits."""
    return float(f"{10.0 ** position:.{K_DIGITS}g}")


def K_marks(lo: float, hi: float, K_limit: float, K_rec: float | None) -> tuple[tuple[float, str], ...]:
    """Return the track's marks (position [log₁₀], label): both ends, "rec" at K_rec, "lim" at K_limit."""
    marks = [(lo, f"{10.0 ** lo:g}"), (hi, f"{10.0 ** hi:g}")]
    if _positive(K_rec):
        marks.append((math.log10(K_rec), "rec"))  # type: ignore[arg-type]
    if _positive(K_limit):
        marks.append((math.log10(K_limit), "lim"))
    return tuple(marks)


def readout_html(K: float, K_limit: float, K_rec: float | None) -> str:
    """Return one line for under the slider: K [s/rad] and the marked gains, K in red at or above K_limit."""
    over = _positive(K_limit) and K_limit <= K
    parts = [f'<b style="color:{"#c92a2a" if over else "#2b8a3e"}">K = {K:.4g} s/rad</b>']
    if _positive(K_rec):
        parts.append(f"rec {K_rec:.3g}")
    if _positive(K_limit):
        parts.append(f"lim {K_limit:.3g} (chatter above)")
    return ('<div data-role="k-readout" style="font-size:0.85em;white-space:nowrap;overflow:hidden;'
            'text-overflow:ellipsis">' + " · ".join(parts) + "</div>")


def hide_box_css(slider_uuid: str) -> str:
    """CSS hiding the number box next to the slider ``slider_uuid`` (it would show log₁₀ K)."""
    return f'.mantine-Flex-root:has(> [id="{slider_uuid}"]) > :not([id="{slider_uuid}"]) {{display: none}}'


class KSlider:
    """The logarithmic K slider and its readout; a user's move calls ``moved(K)`` [s/rad].

    Parameters
    ----------
    gui : viser.GuiApi
        Where to add the slider (inside the live-tuning folder).
    moved : Callable[[float], None]
        Called with the K [s/rad] a user's move chose (not for the page's own updates).
    """

    def __init__(self, gui: viser.GuiApi, moved: Callable[[float], None]) -> None:
        self._moved = moved
        self._gains: tuple[float, float | None] = (0.0, None)
        lo, hi = (math.log10(k) for k in K_RANGE)
        self.slider = gui.add_slider(K_LABEL, min=lo, max=hi, step=LOG_STEP, initial_value=3.0,
                                     hint="Logarithmic: drag across 'lim' (K_limit) to see the chatter start")
        self.slider.precision = LOG_PRECISION
        self.readout = gui.add_html("")
        self.slider.on_update(self._on_update)

    @property
    def uuid(self) -> str:
        """The slider's DOM id."""
        return widget_id(self.slider)

    def show(self, K: float, K_limit: float, K_rec: float | None) -> None:
        """Mirror ``K`` [s/rad] (unless the slider already stands there) and mark K_limit and K_rec."""
        if not _positive(K):
            return
        self._gains = (K_limit, K_rec)
        lo, hi = log_K_range(K, K_limit, K_rec)
        assign(self.slider, min=lo, max=hi)
        set_slider_marks(self.slider, K_marks(lo, hi, K_limit, K_rec))
        position = math.log10(K)
        if abs(float(self.slider.value) - position) > LOG_STEP / 2:
            self.slider.value = position
        assign(self.readout, content=readout_html(K, K_limit, K_rec))

    def _on_update(self, event: viser.GuiEvent) -> None:
        if event.client is None:  # the page's own mirroring
            return
        K = K_of_position(float(self.slider.value))
        assign(self.readout, content=readout_html(K, *self._gains))
        self._moved(K)


__all__ = ["K_LABEL", "K_RANGE", "KSlider", "K_marks", "K_of_position", "hide_box_css", "log_K_range",
           "readout_html"]
