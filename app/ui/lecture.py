"""The lecture's controls of the position tab: pin runs to compare, and save / load the demo state.

*Compare runs* (under the live-tuning sliders): **Pin this run** keeps the FDSMC run shown as a
grey ghost in the overview (:mod:`app.figures.fdsmc_pins`; at most four, oldest dropped), so a
change of K, load, the plant's J_L or the anti-windup can be seen against it; **Clear pins**
removes them. *Demo state (lecture)*: **Save demo state** downloads the inputs, the plant's J_L,
the slider ranges and the pins as one JSON file (:mod:`app.ui.demo_state`); **Load demo state**
reads one back through the upload checks of every file and simulates it. A bad file is refused
with one line and changes nothing.
"""

from __future__ import annotations

from typing import Any

import viser

from app.exports.model import safe_stem
from app.figures.fdsmc_pins import MAX_PINS, Pin, pin_of, pinned
from app.ui.demo_state import DemoState, dumps_state, loads_state
from app.ui.files import upload_text
from app.ui.props import assign
from app.ui.text import pins_html


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
        """Keep ``pins`` and draw the overview shown again with them (on the worker)."""
        self.keep(pins)
        self._tab.submit(lambda: self._tab.results.replay.show_pins(self.pins))

    def _clicked(self, label: str) -> None:
        if label == "Clear pins":
            self.show(())
            return
        case = self._tab.case
        pin = pin_of(case.comparison, case.plant_J_L)
        if pin is not None:
            self.show(pinned(self.pins, pin))


class DemoStateFiles:
    """The "Demo state (lecture)" folder: save to a download, load from an upload; ``tab`` is the position tab."""

    def __init__(self, gui: viser.GuiApi, tab: Any) -> None:
        self._tab = tab
        with gui.add_folder("Demo state (lecture)", expand_by_default=False):
            self.save = gui.add_button("Save demo state", icon=viser.Icon.DOWNLOAD,
                                       hint="The inputs, the plant's J_L, the slider ranges and the pinned runs "
                                            "as one file, to load at the next lecture")
            self.load = gui.add_upload_button("Load demo state", icon=viser.Icon.UPLOAD,
                                              mime_type=".json,application/json,text/plain")
        self.save.on_click(lambda _: self._save())
        self.load.on_upload(lambda _: self._uploaded())

    def state(self) -> DemoState:
        """Return the lecture's state shown: the case committed, the plant's J_L, slider ranges, pins."""
        tab = self._tab
        case = tab.case
        return DemoState(case.params, case.plant_J_L, case.origin, tab.tuning.ranges, tab.lecture.pins)

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
        """Show ``state`` (inputs, slider ranges, pins) and simulate it with its plant; False if busy."""
        tab = self._tab
        if tab.busy:
            return tab.submit(lambda: None)  # refused, with the "busy" note
        tab.files.show_names(state.params)
        tab.open_case(state.params, state.origin)
        tab.tuning.ranges = state.ranges
        tab.hold_ranges()
        tab.lecture.keep(state.pins)
        return tab.submit(lambda: tab.run_with_plant(state.params, state.plant_J_L))


__all__ = ["DemoStateFiles", "LecturePins"]
