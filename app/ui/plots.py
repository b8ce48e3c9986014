"""Plot widgets fed with ready-made Plotly JSON (:func:`app.figures.plain.figure_json`).

Viser's ``add_plotly`` queues a creation message whose properties are the very object the
returned handle writes to, and then sets the figure (an update message). Until the creation
message has left — on every page open, where the widgets and their figures are made in one go —
each figure set on the widget therefore travels twice: inside the creation message and as an
update. :func:`add_figure` gives the handle its own copy of the properties right after creation,
so the creation message keeps the empty figure and each figure goes out once;
:func:`set_figure_json` sends nothing when the figure is unchanged.
"""

from __future__ import annotations

import dataclasses

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
    """Add a plot widget showing the Plotly JSON ``json_str`` (an empty figure if None); each figure is sent once."""
    handle = gui.add_plotly(_ReadyFigure(blank_json()), aspect=aspect)  # type: ignore[arg-type]
    handle._impl.props = dataclasses.replace(handle._impl.props)  # no longer the queued creation message's
    if json_str is not None:
        set_figure_json(handle, json_str)
    return handle


def set_figure_json(handle: viser.GuiPlotlyHandle, json_str: str) -> None:
    """Send a ready-made Plotly JSON string to a plot widget, unless it already shows exactly that.

    ``_plotly_json_str`` is the widget property that ``GuiPlotlyHandle.figure`` itself sets.
    """
    if handle._plotly_json_str != json_str:
        handle._plotly_json_str = json_str


__all__ = ["add_figure", "set_figure_json"]
