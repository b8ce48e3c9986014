"""The demo state's view (tabs and the overview's zoom) without a browser: the file format, its
versions and refusals, the page's report, and the overview sent again at a saved zoom.
"""

from __future__ import annotations

import json

import pytest

from pmsm_commissioning.app.figures.fdsmc_pins import Pin
from pmsm_commissioning.app.ui.demo_state import (
    MODE_TABS,
    RESULTS_TABS,
    DemoState,
    PageView,
    dumps_state,
    loads_state,
    loads_view,
)
from pmsm_commissioning.app.ui.demo_view import PageViewProbe, select_tabs_js, view_report_js, zoomed_json

VIEW = PageView("BLDC speed SMC", "Time plots", {"xaxis": (-62.5, -28.0), "yaxis2": (40.0, 80.0)})


def _state(params, view: PageView = VIEW) -> DemoState:
    pin = Pin("pin 1", (0.0, 0.5, 1.0), (-60.0, -30.0, 0.0), (0.0, 63.9, 0.0))
    return DemoState(params, None, "paper_12kw_pmsm", {"K": (0.01, 5000.0)}, (pin,), view)


def test_tabs_and_zoom_round_trip_through_the_file(paper_params):
    back = loads_state(dumps_state(_state(paper_params)), "lecture.json")
    assert back.view == VIEW
    assert back.params == paper_params and back.ranges == {"K": (0.01, 5000.0)} and back.pins[0].label == "pin 1"
    unknown = loads_state(dumps_state(_state(paper_params, PageView())), "lecture.json").view
    assert unknown == PageView(None, None, {})  # a page that reported nothing: no tab chosen, no zoom


def test_a_version_1_file_without_tab_and_zoom_still_loads(paper_params):
    raw = json.loads(dumps_state(_state(paper_params)))
    assert raw["demo_state"] == 2 and raw["tab"] == {"mode": "BLDC speed SMC", "results": "Time plots"}
    del raw["tab"], raw["zoom"]
    raw["demo_state"] = 1
    old = loads_state(json.dumps(raw), "old.json")
    assert old.view == PageView() and old.params == paper_params and len(old.pins) == 1


@pytest.mark.parametrize("edit, words", [
    (lambda d: d["tab"].update(mode="Robustness"),
     "old.json › tab.mode = 'Robustness': allowed null or one of Position drive (FDSMC), BLDC speed SMC"),
    (lambda d: d["tab"].update(results=3), "tab.results = '3': allowed null or one of Overview"),
    (lambda d: d["tab"].pop("results"), "tab is not an object with exactly mode and results"),
    (lambda d: d["zoom"].update(xaxis=[5, 1]), "zoom.xaxis = [5, 1]: allowed finite numbers with min < max"),
    (lambda d: d["zoom"].update(xaxis=["1", 2]), "zoom.xaxis holds a value that is not a number: allowed finite"),
    (lambda d: d["zoom"].update(xaxis=[1, 2, 3]), "zoom.xaxis is not a list of at most 2 numbers"),
    (lambda d: d["zoom"].update(zaxis=[1, 2]), "zoom.zaxis: allowed axis names xaxis, yaxis, xaxis2 … yaxis9"),
    (lambda d: d.update(zoom=[1, 2]), "zoom is not an object of at most 16 axis name → [min, max]"),
    (lambda d: d.update(demo_state=1), "not a demo-state file: allowed exactly the keys demo_state, preset, "
                                       "origin, ranges, pins (found"),
    (lambda d: d.pop("zoom"), "allowed exactly the keys demo_state, preset, origin, ranges, pins, tab, zoom"),
])
def test_a_bad_tab_or_zoom_is_refused_with_one_line_naming_key_value_and_range(paper_params, edit, words):
    raw = json.loads(dumps_state(_state(paper_params)))
    edit(raw)
    with pytest.raises(ValueError) as info:
        loads_state(json.dumps(raw), "old.json")
    assert words in str(info.value) and "\n" not in str(info.value)


def test_the_pages_report_is_read_with_the_files_checks():
    text = json.dumps({"tab": {"mode": MODE_TABS[0], "results": "Overview"}, "zoom": {"yaxis": [55, 70]}})
    assert loads_view(text) == PageView(MODE_TABS[0], "Overview", {"yaxis": (55.0, 70.0)})
    for bad in ('{"tab": {"mode": null, "results": null}}', '{"tab": {"mode": "x", "results": null}, "zoom": {}}',
                "not json"):
        with pytest.raises(ValueError):
            loads_view(bad)


def test_the_probe_keeps_the_last_valid_report_and_tells_its_listeners_of_it():
    probe = PageViewProbe.__new__(PageViewProbe)  # its logic only: no page to report into
    probe.view, probe._listeners = PageView(), []
    heard: list[tuple[PageView, PageView]] = []
    probe.on_view(lambda view: heard.append((view, probe.view)))
    probe._reported(json.dumps({"tab": {"mode": None, "results": "Energy"}, "zoom": {}}))
    assert probe.view == PageView(None, "Energy", {})
    assert heard == [(probe.view, probe.view)]  # told after the probe holds the view
    long_text = json.dumps({"tab": {"mode": None, "results": None}, "zoom": {}}) + " " * 5000
    for bad in ("", long_text, '{"tab": 1, "zoom": {}}', "[" * 100, '{"tab": {"mode": null, "results": "Nope"}}'):
        probe._reported(bad)
        assert probe.view == PageView(None, "Energy", {})
    assert len(heard) == 1  # nothing told of a report that is no view


def test_the_overview_is_sent_again_with_the_zoomed_axes_only():
    figure = {"data": [{"x": [0, 1], "y": [0, 1]}],
              "layout": {"meta": {"id": "phase_plane"}, "xaxis": {"range": [-70, 5], "title": {"text": "θ_re"}},
                         "yaxis": {"autorange": True}, "xaxis2": {"range": [0, 1.3]}}}
    out = json.loads(zoomed_json(json.dumps(figure), {"xaxis": (-62.5, -28.0), "yaxis": (40.0, 80.0),
                                                      "yaxis5": (1.0, 2.0)}))
    layout = out["layout"]
    assert layout["xaxis"] == {"range": [-62.5, -28.0], "autorange": False, "title": {"text": "θ_re"}}
    assert layout["yaxis"] == {"range": [40.0, 80.0], "autorange": False}
    assert layout["xaxis2"] == {"range": [0, 1.3]} and "yaxis5" not in layout  # an axis the figure lacks: left out
    assert layout["meta"] == {"id": "phase_plane", "zoom": {"xaxis": [-62.5, -28.0], "yaxis": [40.0, 80.0]}}
    assert out["data"] == figure["data"]


def test_the_page_scripts_name_the_field_and_the_tabs():
    report = view_report_js("1234-abcd")
    assert '"1234-abcd"' in report and json.dumps(RESULTS_TABS) in report and "UUID" not in report
    select = select_tabs_js(VIEW)
    assert '["BLDC speed SMC", "Time plots", 80]' in select
    assert "[null, null, 80]" in select_tabs_js(PageView())
