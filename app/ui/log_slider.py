"""A logarithmic live-tuning slider with named marks on its track, mirroring a typed field.

The slider's position is log₁₀ of the value shown (in the field's unit), over whole decades
holding the value, every marked value and a least range; its own number box would show the
logarithm and is hidden (:func:`hide_box_css`), and a readout line under it says the value in
its unit with the marked values. A user's move writes the value rounded to :data:`DIGITS`
significant digits; every other change of the value (typed and simulated, a preset, a file, a
design) moves the slider to it (:meth:`LogSlider.show`) unless it already stands there.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import viser

from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.viser_adapter import set_slider_marks, widget_id

#: Step of a slider's position [decades] and the decimals it keeps.
LOG_STEP, LOG_PRECISION = 0.01, 2
#: Significant digits of a value written by a slider.
DIGITS = 3
#: A position within this many steps of a mark gives the mark's exact value [-].
SNAP = 0.75
#: A mark on the track: (label, value in the shown unit).
Mark = tuple[str, float]


def positive(value: float | None) -> bool:
    """Return True for a finite value > 0 (0, ∞ or None mean "nothing to mark")."""
    return value is not None and math.isfinite(value) and value > 0.0


def log_range(values: Iterable[float | None], least: tuple[float, float]) -> tuple[float, float]:
    """Return a slider's (min, max) [log₁₀]: ``least`` widened to whole decades holding each positive value."""
    lo, hi = math.log10(least[0]), math.log10(least[1])
    for v in values:
        if positive(v):
            lo, hi = min(lo, math.floor(math.log10(v))), max(hi, math.ceil(math.log10(v)))  # type: ignore[arg-type]
    return float(lo), float(hi)


def value_of_position(position: float) -> float:
    """Return the value at slider position ``position`` [log₁₀], to :data:`DIGITS` significant digits."""
    return float(f"{10.0 ** position:.{DIGITS}g}")


def snapped(position: float, marks: Iterable[Mark]) -> float:
    """Return the value at ``position`` [log₁₀]: a mark's exact value within :data:`SNAP` steps of it, else rounded.

    A slider dropped on its "min" mark (T_m,min = 0.48044 s) must give T_m,min itself: the track's
    position there is a multiple of the step (log₁₀ 0.4786), and three significant digits of it
    (0.479 s) fall below the minimum, on the infeasible side.
    """
    near = [(abs(math.log10(v) - position), v) for _, v in marks if positive(v)]
    best = min(near, default=(math.inf, 0.0))
    return float(best[1]) if best[0] <= SNAP * LOG_STEP else value_of_position(position)


def track_marks(lo: float, hi: float, marks: Iterable[Mark]) -> tuple[tuple[float, str], ...]:
    """Return the track's marks (position [log₁₀], label): both ends, then each positive named value."""
    out = [(lo, f"{10.0 ** lo:g}"), (hi, f"{10.0 ** hi:g}")]
    out += [(math.log10(v), label) for label, v in marks if positive(v)]
    return tuple(out)


def hide_box_css(slider_uuid: str) -> str:
    """CSS hiding the number box next to the slider ``slider_uuid`` (it would show the logarithm).

    viser puts the box after the slider, in the same row: a sibling selector. (Not ``:has()``: with
    such a rule in the page every forced layout, e.g. each text Plotly measures, re-styled the whole
    page, ≈ 8 ms instead of 0.1 ms.)
    """
    return f'[id="{slider_uuid}"] ~ * {{display: none}}'


def default_readout(symbol: str, unit: str) -> Callable[[float, tuple[Mark, ...]], str]:
    """Return a readout ``(value, marks) -> html``: "symbol = value unit · label value …" on one line."""
    def readout(value: float, marks: tuple[Mark, ...]) -> str:
        parts = [f"<b>{symbol} = {value:.4g} {unit}</b>"] + [f"{label} {v:.3g}" for label, v in marks if positive(v)]
        return readout_line(symbol, " · ".join(parts))
    return readout


def readout_line(role: str, inner_html: str) -> str:
    """One readout line (``data-role="<role>-readout"``) that never wraps (the slider never moves)."""
    key = role.split()[0].lower().replace("_", "-")
    return (f'<div data-role="{key}-readout" style="font-size:14px;white-space:nowrap;overflow:hidden;'
            f'text-overflow:ellipsis">{inner_html}</div>')


class LogSlider:
    """A logarithmic slider and its readout; a user's move calls ``moved(value)`` [shown unit].

    Parameters
    ----------
    gui : viser.GuiApi
        Where to add the slider.
    label : str
        The slider's label (with the unit and "(log)").
    least : (float, float)
        Least range [shown unit].
    readout : callable
        ``readout(value, marks) -> html`` for the line under the slider.
    moved : callable
        Called with the value a user's move chose (not for the page's own updates).
    hint : str
        The slider's tooltip.
    """

    def __init__(self, gui: viser.GuiApi, label: str, least: tuple[float, float],
                 readout: Callable[[float, tuple[Mark, ...]], str], moved: Callable[[float], None],
                 hint: str) -> None:
        self._least, self._readout, self._moved = least, readout, moved
        self._marks: tuple[Mark, ...] = ()
        lo, hi = (math.log10(v) for v in least)
        self.slider = gui.add_slider(label, min=lo, max=hi, step=LOG_STEP, initial_value=0.5 * (lo + hi), hint=hint)
        self.slider.precision = LOG_PRECISION
        self.readout = gui.add_html("")
        self.slider.on_update(self._on_update)

    @property
    def uuid(self) -> str:
        """The slider's DOM id."""
        return widget_id(self.slider)

    @property
    def least(self) -> tuple[float, float]:
        """The least range [shown unit] (the track always holds it)."""
        return self._least

    @least.setter
    def least(self, least: tuple[float, float]) -> None:
        if all(positive(v) for v in least) and least[0] < least[1]:
            self._least = (float(least[0]), float(least[1]))

    @property
    def value(self) -> float:
        """The value the slider stands at [shown unit]: a mark's exact value on (or next to) it (:func:`snapped`)."""
        return snapped(float(self.slider.value), self._marks)

    def show(self, value: float, marks: tuple[Mark, ...] = (), least: tuple[float, float] | None = None) -> None:
        """Mirror ``value`` (unless the slider already stands there) and mark ``marks``.

        ``least``: a new least range [shown unit] (e.g. around a new drive's nominal value).
        """
        if not positive(value):
            return
        self._marks = marks
        if least is not None:
            self.least = least
        lo, hi = log_range([value, *(v for _, v in marks)], self._least)
        assign(self.slider, min=lo, max=hi)
        set_slider_marks(self.slider, track_marks(lo, hi, marks))
        position = math.log10(value)
        if abs(float(self.slider.value) - position) > LOG_STEP / 2:
            self.slider.value = position
        assign(self.readout, content=self._readout(value, marks))

    def _on_update(self, event: viser.GuiEvent) -> None:
        if event.client is None:  # the page's own mirroring
            return
        value = self.value
        assign(self.readout, content=self._readout(value, self._marks))
        self._moved(value)


__all__ = ["DIGITS", "LOG_PRECISION", "LOG_STEP", "SNAP", "LogSlider", "Mark", "default_readout", "hide_box_css",
           "log_range", "positive", "readout_line", "snapped", "track_marks", "value_of_position"]
