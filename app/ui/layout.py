"""Panel widths and plot height that fit the browser window (a 1280×720 projector up to wide screens).

viser places docked panels in pixels and keeps the 3D canvas at least :data:`CANVAS_MIN` wide,
shrinking every docked panel when they do not fit. The server learns the window only through
the camera messages, which carry the canvas size. So the page starts with widths that fit a
1280×720 window, and each reported canvas size (unclamped: wider than :data:`CANVAS_MIN`) gives
the window size (the very first report of a page comes before the panels are placed: it is the
whole window), from which :func:`layout_for_window` sizes the panels: the control panel left,
the results panel right using the rest of the width, and the canvas — the 3D view — between
them, :data:`CANVAS_SPARE` wide while the 3D view is folded away.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

#: Narrowest 3D canvas viser's client keeps [px] (measured: 121 px at any window size).
CANVAS_MIN = 121.0
#: Canvas width while the 3D view is folded [px]: above CANVAS_MIN, so the canvas width reported
#: by the camera still tells the window width.
CANVAS_SPARE = 140.0
#: Share of the window width given to the 3D view when it is shown [-], and its least width [px].
SCENE_SHARE, SCENE_MIN = 0.22, 280.0
#: Panel borders and resize handles between the docked panels [px] (measured).
BORDERS = 8.0
#: Control panel width [px] on windows up to WIDE_WINDOW px wide, and beyond.
CONTROL_WIDTH, CONTROL_WIDTH_WIDE, WIDE_WINDOW = 400.0, 440.0, 1600.0
#: Vertical space of the results panel not available to the overview plot [px]: panel header and
#: tab strip (≈ 78), the key-numbers line (≈ 44), paddings.
CHROME_HEIGHT = 150.0
#: Horizontal padding of the results panel around a plot [px] (padding and scroll bar).
PLOT_PADDING = 36.0
#: Bounds of the overview plot's aspect (height / width) [-].
ASPECT_MIN, ASPECT_MAX = 0.42, 0.85
#: Window assumed until the browser reports its canvas [px].
DEFAULT_WINDOW = (1280.0, 720.0)


@dataclass(frozen=True)
class PanelLayout:
    """Widths of the docked panels [px] and the overview plot's aspect (height / width) [-]."""

    control_width: float
    results_width: float
    plot_aspect: float


def layout_for_window(width: float, height: float, show_3d: bool = False) -> PanelLayout:
    """Size the panels for a ``width`` × ``height`` [px] window.

    The control panel keeps its width, the 3D canvas gets :data:`CANVAS_SPARE` (folded) or
    :data:`SCENE_SHARE` of the width (shown), the results panel the rest; the overview plot is as
    tall as the window allows below the panel header and the key numbers.
    """
    control = CONTROL_WIDTH_WIDE if width > WIDE_WINDOW else CONTROL_WIDTH
    canvas = max(SCENE_MIN, SCENE_SHARE * width) if show_3d else CANVAS_SPARE
    results = max(320.0, width - control - canvas - BORDERS)
    aspect = (height - CHROME_HEIGHT) / max(results - PLOT_PADDING, 1.0)
    return PanelLayout(control, results, round(min(ASPECT_MAX, max(ASPECT_MIN, aspect)), 3))


def window_size(canvas_width: float, canvas_height: float, shown: PanelLayout) -> tuple[float, float] | None:
    """Window size [px] from the canvas size the camera reports under the layout ``shown``.

    None when the canvas is at viser's minimum width (the panels were shrunk to fit, so the
    window is narrower than they ask for and its width is unknown).
    """
    if canvas_width <= CANVAS_MIN + 1.0 or canvas_height <= 0:
        return None
    return canvas_width + shown.control_width + shown.results_width + BORDERS, float(canvas_height)


class WindowFit:
    """Keeps one client's panels fitted to its window; ``apply(layout)`` pushes a new layout."""

    def __init__(self, apply: Callable[[PanelLayout], None], show_3d: bool = False) -> None:
        self._apply = apply
        self.show_3d = show_3d
        self.window = DEFAULT_WINDOW
        self.layout = layout_for_window(*DEFAULT_WINDOW, show_3d)
        self._first = True
        self._lock = threading.Lock()  # camera messages arrive on viser's thread pool
        apply(self.layout)

    def canvas_reported(self, canvas_width: float, canvas_height: float) -> None:
        """Refit when the window implied by a camera message (its canvas size [px]) changed."""
        with self._lock:
            self._canvas_reported(canvas_width, canvas_height)

    def _canvas_reported(self, canvas_width: float, canvas_height: float) -> None:
        first, self._first = self._first, False
        if first and canvas_width > CANVAS_MIN + 1.0 and canvas_height > 0:
            size: tuple[float, float] | None = (float(canvas_width), float(canvas_height))  # whole window
        else:
            size = window_size(canvas_width, canvas_height, self.layout)
        if size is None:  # squeezed: back to widths that fit the smallest window, then measure again
            size = DEFAULT_WINDOW if self.window != DEFAULT_WINDOW else None
        if size is not None and (abs(size[0] - self.window[0]) > 2 or abs(size[1] - self.window[1]) > 2):
            self.window = size
            self._refit()

    def set_3d(self, show: bool) -> None:
        """Fold (False) or show (True) the 3D view."""
        with self._lock:
            self.show_3d = bool(show)
            self._refit()

    def _refit(self) -> None:
        layout = layout_for_window(*self.window, self.show_3d)
        if layout != self.layout:
            self.layout = layout
            self._apply(layout)


__all__ = ["PanelLayout", "WindowFit", "layout_for_window", "window_size"]
