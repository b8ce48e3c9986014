"""Figures of the results tabs not shown: sent when their tab is chosen, not with every run.

After a Simulate the page shows the *Overview* (and the K demo its *K sweep*); the time plots
(≈ 86 kB sent, a quarter of a Simulate's bytes), the energy figures and the stock drive's route sit
in tabs the user may never open. :class:`TabFigures` keeps, for the comparison in force, the
figures of such tabs and sends a tab's figures only while that tab is shown: after a run if it is
the tab shown, or when the page reports the tab chosen (:class:`app.ui.demo_view.PageViewProbe`).
Each figure's JSON is built at most once per run (choosing the tab again neither rebuilds nor
resends it: :func:`app.ui.viser_adapter.set_figure_json` sends nothing for the figure shown).

Runs (the session's worker) and tab reports (viser's callback threads) may come at once: one lock
orders them, so the figure a tab ends with is always the one of the last comparison shown.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import viser

from pmsm_commissioning.app.ui.viser_adapter import figure_json_shown, set_figure_json

#: A figure's builder: Plotly JSON of a comparison, or None to leave the figure shown as it is.
Build = Callable[[Any], "str | None"]


@dataclass
class _Entry:
    """One figure of a tab: its widget, its builder, and the JSON built for the comparison ``built_for``."""

    handle: viser.GuiPlotlyHandle
    build: Build
    built_for: Any = None
    json: str | None = None


class TabFigures:
    """The figures of tabs not shown by default, each sent only while its tab is shown.

    Parameters
    ----------
    comparison : Any
        The comparison the figure widgets show at first (the page's start-up one).
    tab : str or None
        The results tab shown at first (the page opens on the *Overview*).
    """

    def __init__(self, comparison: Any, tab: str | None = "Overview") -> None:
        self._lock = threading.Lock()
        self._entries: dict[str, list[_Entry]] = {}
        self._comparison, self._tab = comparison, tab

    def add(self, tab: str, handle: viser.GuiPlotlyHandle, build: Build, shown: str | None = None) -> None:
        """Register the figure ``handle`` of the tab ``tab``; ``shown``: its JSON of the comparison in force."""
        with self._lock:
            entry = _Entry(handle, build)
            if shown is not None:
                entry.built_for, entry.json = self._comparison, shown
            self._entries.setdefault(tab, []).append(entry)

    def show(self, comparison: Any) -> None:
        """Make ``comparison`` the one in force; send its figures of the tab shown (the others wait)."""
        with self._lock:
            self._comparison = comparison
            for entry in self._all():
                if entry.built_for is not comparison:  # an older run's JSON: never sent again, not kept
                    entry.built_for = entry.json = None
            self._send(self._tab)

    def tab_shown(self, tab: str | None) -> None:
        """Send the figures of the results tab ``tab`` the page shows (None: unknown) for the comparison in force."""
        with self._lock:
            self._tab = tab
            self._send(tab)

    def figure_json(self, handle: viser.GuiPlotlyHandle) -> str:
        """Return the JSON of ``handle``'s figure of the comparison in force (built if need be, not sent)."""
        with self._lock:
            for entry in self._all():
                if entry.handle is handle:
                    return self._json(entry) or figure_json_shown(handle)
        return figure_json_shown(handle)

    def _all(self) -> list[_Entry]:
        return [e for entries in self._entries.values() for e in entries]

    def _send(self, tab: str | None) -> None:
        for entry in self._entries.get(tab, ()) if tab is not None else ():
            json_str = self._json(entry)
            if json_str is not None:
                set_figure_json(entry.handle, json_str)

    def _json(self, entry: _Entry) -> str | None:
        """Return the figure's JSON of the comparison in force, built once per comparison (the lock is held)."""
        if entry.built_for is not self._comparison:
            entry.json, entry.built_for = entry.build(self._comparison), self._comparison
        return entry.json


__all__ = ["Build", "TabFigures"]
