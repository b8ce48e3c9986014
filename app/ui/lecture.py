"""The lecture's controls of the position tab: pin runs to compare, and save / load the demo state.

*Compare runs* (under the live-tuning sliders): **Pin this run** keeps the FDSMC run shown as a
grey ghost in the overview (:mod:`app.figures.fdsmc_pins`; at most four, oldest dropped), so a
change of K, load, the plant's J_L or the anti-windup can be seen against it; **Clear pins**
removes them. *Demo state (lecture)*: **Save demo state** downloads the inputs, the plant's J_L,
the slider ranges, the pins, the tabs shown and the overview's zoom as one JSON file
(:mod:`app.ui.demo_state`; the page reports its tabs and zoom through :mod:`app.ui.demo_view`);
**Load demo state** reads one back through the upload checks of every file, selects its tabs,
simulates it and draws the overview at its zoom. A bad file is refused with one line and changes
nothing.
"""

from __future__ import annotations

from typing import Any

import viser

from pmsm_commissioning.app.exports.model import safe_stem
from pmsm_commissioning.app.figures.fdsmc_pins import MAX_PINS, Pin, pin_of, pinned
from pmsm_commissioning.app.ui.demo_state import DemoState, PageView, dumps_state, loads_state
from pmsm_commissioning.app.ui.demo_view import PageViewProbe
from pmsm_commissioning.app.ui.files import upload_text
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.text import pins_html


class LecturePins:
    """The "Compare runs" buttons and the line listing the pins; ``tab`` is the position tab."""

    def __init__(self, gui: viser.GuiApi, tab: Any) -> None:
        self._tab = tab
        self.pins: tuple[Pin, ...] = ()
        self.buttons = gui.add_button_group("Compare runs", ("Pin this run", "Clear pins"))
        self.buttons.on_click(lambda _: self._clicked(self.buttons.value))
        self.line = gui.add_html("")

    def keep(self, pins: tuple[Pin, ...]) -> None:
        """Keep ``pins`` for every overview drawn from now on (the next run draws them)."""
        self.pins = pins[-MAX_PINS:]
        assign(self.line, content=pins_html(self.pins))
        self._tab.results.replay.pins = self.pins

    def show(self, pins: tuple[Pin, ...]) -> None:
        """Keep ``pins`` and draw the overview shown again with them.

        Drawn here, not on the worker: a click during a run would be refused there while the pins
        already changed. The replay sends one overview at a time, so this waits for a run's
        figures and then draws that run with ``pins``.
        """
        self.keep(pins)
        self._tab.results.replay.show_pins(self.pins)

    def _clicked(self, label: str) -> None:
        if label == "Clear pins":
            self.show(())
            return
        case = self._tab.case
        pin = pin_of(case.comparison, case.plant_J_L)
        if pin is not None:
            self.show(pinned(self.pins, pin))


class DemoStateFiles:
    """The "Demo state (lecture)" folder: save to a download, load from an upload; ``tab`` is the position tab.

    :attr:`probe` (set by the page, outside the mode tabs: it must stay in the page whichever tab is
    shown) reports the page's tabs and zoom; without one a state has no view.
    """

    def __init__(self, gui: viser.GuiApi, tab: Any) -> None:
        self._tab = tab
        self.probe: PageViewProbe | None = None
        with gui.add_folder("Demo state (lecture)", expand_by_default=False):
            self.save = gui.add_button("Save demo state", icon=viser.Icon.DOWNLOAD,
                                       hint="The inputs, the plant's J_L, the slider ranges, the pinned runs, "
                                            "the tabs shown and the overview's zoom as one file, to load at "
                                            "the next lecture")
            self.load = gui.add_upload_button("Load demo state", icon=viser.Icon.UPLOAD,
                                              mime_type=".json,application/json,text/plain")
        self.save.on_click(lambda _: self._save())
        self.load.on_upload(lambda _: self._uploaded())

    def state(self) -> DemoState:
        """Return the lecture's state shown: the case committed, the plant's J_L, slider ranges, pins, view."""
        tab = self._tab
        case = tab.case
        view = self.probe.view if self.probe is not None else PageView()
        return DemoState(case.params, case.plant_J_L, case.origin, tab.tuning.ranges, tab.lecture.pins, view)

    def _save(self) -> None:
        name = f"{safe_stem(self._tab.case.params.name or 'fdsmc')}_demo_state.json"
        self._tab.client.send_file_download(name, dumps_state(self.state()).encode("utf-8"), save_immediately=True)

    def _uploaded(self) -> None:
        f = self.load.value
        try:
            state = loads_state(upload_text(f.name, f.content, "a demo-state file (JSON)"), f.name or "<upload>")
        except ValueError as exc:
            self._tab.client.add_notification("Demo state rejected — nothing changed", str(exc), color="red",
                                              auto_close_seconds=15.0)
            return
        self.open(state)

    def open(self, state: DemoState) -> bool:
        """Show ``state`` (inputs, slider ranges, pins), simulate it with its plant, tabs, zoom; False if busy."""
        tab = self._tab
        if tab.busy:
            return tab.submit(lambda: None)  # refused, with the "busy" note
        tab.files.show_names(state.params)
        tab.open_case(state.params, state.origin)
        tab.tuning.ranges = state.ranges
        tab.hold_ranges()
        tab.lecture.keep(state.pins)
        return tab.submit(lambda: self._run(state))

    def _run(self, state: DemoState) -> None:
        """On the worker: simulate ``state`` with its plant, then select its tabs and draw the overview at its zoom.

        The tabs are selected after the run: a tab whose figures wait until it is shown
        (:mod:`app.ui.tab_figures`) then gets the state's run only, not the run it replaces first.
        """
        tab = self._tab
        try:
            tab.run_with_plant(state.params, state.plant_J_L)
        finally:
            if self.probe is not None:
                self.probe.select_tabs(state.view)
        if self.probe is not None and tab.case.comparison.fdsmc is not None:
            self.probe.zoom(tab.results.phase, state.view.zoom)


__all__ = ["DemoStateFiles", "LecturePins"]
