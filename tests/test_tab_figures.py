"""The figures of a results tab not shown go out when the tab is chosen, once per run; the shown tab's with each run."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from pmsm_commissioning.app.ui import tab_figures
from pmsm_commissioning.app.ui.tab_figures import TabFigures


class _Widget:
    """A plot widget: the JSON it shows."""

    def __init__(self, shown: str = "") -> None:
        self.shown = shown


@pytest.fixture
def sent(monkeypatch: pytest.MonkeyPatch) -> list[tuple[_Widget, str]]:
    """Every figure sent to a widget, in order (the adapter's send-unless-shown rule kept)."""
    log: list[tuple[_Widget, str]] = []

    def send(widget: _Widget, json_str: str) -> None:
        if widget.shown != json_str:
            widget.shown = json_str
            log.append((widget, json_str))

    monkeypatch.setattr(tab_figures, "set_figure_json", send)
    monkeypatch.setattr(tab_figures, "figure_json_shown", lambda widget: widget.shown)
    return log


class _Builder:
    """Builds "<name> of <run>" and counts its builds per run."""

    def __init__(self, name: str) -> None:
        self.name, self.builds = name, {}

    def __call__(self, run: Any) -> str | None:
        self.builds[run] = self.builds.get(run, 0) + 1
        return None if run == "infeasible" else f"{self.name} of {run}"


def test_a_run_sends_only_the_shown_tabs_figures_and_a_tab_chosen_later_gets_that_run_once(sent):
    figures = TabFigures("start")
    time_plots, energy = _Widget("time of start"), _Widget("energy of start")
    build_time, build_energy = _Builder("time"), _Builder("energy")
    figures.add("Time plots", time_plots, build_time, "time of start")
    figures.add("Energy", energy, build_energy, "energy of start")
    figures.show("run 1")  # on the Overview: nothing of the other tabs goes out, nothing is built
    figures.show("run 2")
    assert sent == [] and build_time.builds == {} and build_energy.builds == {}
    figures.tab_shown("Time plots")
    assert sent == [(time_plots, "time of run 2")]  # the run in force, not the first one
    figures.tab_shown("Overview")
    figures.tab_shown("Time plots")  # chosen again: neither built nor sent again
    assert build_time.builds == {"run 2": 1} and len(sent) == 1
    figures.show("run 3")  # the tab is shown: at once
    assert sent[-1] == (time_plots, "time of run 3") and energy.shown == "energy of start"
    assert figures.figure_json(energy) == "energy of run 3" and len(sent) == 2  # for an export: built, not sent
    figures.tab_shown("Energy")
    assert sent[-1] == (energy, "energy of run 3") and build_energy.builds == {"run 3": 1}


def test_a_builder_returning_none_leaves_the_figure_shown(sent):
    figures = TabFigures("run 1", tab="Energy")
    energy = _Widget("energy of run 1")
    figures.add("Energy", energy, _Builder("energy"), "energy of run 1")
    figures.show("infeasible")  # no runs to draw: the last run's figure stays
    assert sent == [] and figures.figure_json(energy) == "energy of run 1"
    figures.tab_shown(None)  # a tab the page does not name: nothing sent
    assert sent == []


def test_a_tab_chosen_during_a_run_ends_with_the_runs_figure(sent):
    """A tab report (viser's thread) and a run (the worker) at once: the last figure sent is the run's."""
    figures = TabFigures("run 0")
    widget = _Widget()
    started = threading.Event()

    def build(run: Any) -> str:
        started.set()  # the run below comes while this build holds the lock, or after it
        return f"time of {run}"

    figures.add("Time plots", widget, build)
    chooser = threading.Thread(target=figures.tab_shown, args=("Time plots",))
    chooser.start()
    started.wait(5.0)
    figures.show("run 1")
    chooser.join(5.0)
    assert [json_str for _, json_str in sent] == ["time of run 0", "time of run 1"]
