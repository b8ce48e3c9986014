"""Plot widgets fed with ready-made Plotly JSON (:func:`app.figures.plain.figure_json`).

Viser's ``add_plotly`` queues a creation message whose properties are the very object the
returned handle writes to. A figure set on a new widget before that message has left — as on
every page open, where the widgets and their first figures are made in one go — is therefore
sent twice: inside the creation message and again as an update. :func:`add_figure` creates the
widget with its figure from the start, and :func:`set_figure_json` sends nothing when the figure
is unchanged.
"""

from __future__ import annotations

import viser

from app.figures.plain import blank_json


class _ReadyFigure:
    """What ``GuiApi.add_plotly`` reads of a figure (``to_json()``), carrying ready-made JSON."""

    def __init__(self, json_str: str) -> None:
        self._json = json_str

    def to_json(self) -> str:
        """Return the figure's Plotly JSON."""
        return self._json


def add_figure(gui: viser.GuiApi, json_str: str | None = None, aspect: float = 1.0) -> viser.GuiPlotlyHandle:
    """Add a plot widget showing the Plotly JSON ``json_str`` (an empty figure if None) from its first message."""
    return gui.add_plotly(_ReadyFigure(blank_json() if json_str is None else json_str),  # type: ignore[arg-type]
                          aspect=aspect)


def set_figure_json(handle: viser.GuiPlotlyHandle, json_str: str) -> None:
    """Send a ready-made Plotly JSON string to a plot widget, unless it already shows exactly that.

    ``_plotly_json_str`` is the widget property that ``GuiPlotlyHandle.figure`` itself sets.
    """
    if handle._plotly_json_str != json_str:
        handle._plotly_json_str = json_str


__all__ = ["add_figure", "set_figure_json"]
