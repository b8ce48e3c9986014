"""The lecture's logic without a browser: trail phases, pieces and frames, the sliding-region zoom,
pins, the demo-state file, Table 1 as numbers and the errata.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from pmsm_commissioning.app.figures.fdsmc_overview import overview_spec
from pmsm_commissioning.app.figures.fdsmc_pins import MAX_PINS, ghost_traces, pin_of, pinned
from pmsm_commissioning.app.figures.fdsmc_replay import ScrubTargets, replay_layout
from pmsm_commissioning.app.figures.fdsmc_trail import phase_of, pieces
from pmsm_commissioning.app.figures.fdsmc_zoom import zoom_window
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.ui.demo_state import DemoState, dumps_state, loads_state
from pmsm_commissioning.app.ui.log_slider import log_range, track_marks
from pmsm_commissioning.app.ui.paper_text import ERRATA, errata_html, table1_html
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.table1 import PAPER_TABLE1, Table1Row, printed_reversed


@pytest.fixture(scope="module")
def comparison():
    params = load_preset("paper_12kw_pmsm")
    return compare(dataclasses.replace(params, controller=dataclasses.replace(params.controller, K=0.3)))


def test_phases_are_reaching_before_the_layer_then_sliding_beyond_the_knee_then_linear():
    omega_p, T_c, K = 10.0, 0.1, 2.0  # knee at |θ_re| = 1 rad, layer ±0.5 rad/s
    theta = np.array([-5.0, -4.0, -3.0, -2.0, -0.5, -0.1, -3.0])
    omega = np.array([0.0, 5.0, 9.8, 12.0, 5.0, 1.0, 0.0])
    # out of the layer at 12 rad/s but already entered: still sliding; the last sample is far off, still not reaching
    assert phase_of(theta, omega, omega_p, T_c, K).tolist() == [0, 0, 1, 1, 2, 2, 1]
    assert phase_of(theta[:2], omega[:2], omega_p, T_c, K).tolist() == [0, 0]  # never entered


def test_pieces_cover_each_run_in_time_order_without_gaps(comparison):
    parts = pieces(comparison)
    for key in ("fdsmc", "conventional"):
        mine = [p for p in parts if p.key == key]
        assert [p.t_end for p in mine] == sorted(p.t_end for p in mine)
        for a, b in zip(mine, mine[1:], strict=False):  # each piece starts where the one before ends
            assert (a.theta_re[-1], a.omega_r[-1]) == (b.theta_re[0], b.omega_r[0])
        assert mine[-1].t_end == pytest.approx(float(getattr(comparison, key).trace.t[-1]))
    assert {p.phase for p in parts if p.key == "fdsmc"} == {"reaching", "sliding", "linear"}  # K = 0.3 slides


def test_each_replay_frame_shows_the_pieces_it_passed_once_after_emptying_them_all(comparison):
    spec = overview_spec(comparison)
    layout, raw = replay_layout(comparison, spec["data"])
    targets = ScrubTargets.of(spec["data"])
    frames = json.loads(raw[layout["updatemenus"][0]["buttons"][0]["args"][0]])
    trail = {i for i, *_ in targets.trail}
    first = dict(zip(frames[0]["traces"], frames[0]["data"], strict=True))
    assert trail <= set(first) and all(len(first[i]["x"]) == 1 for i in trail)  # a point: no line drawn
    shown = [i for f in frames[1:] for i in f["traces"] if i in trail]
    assert sorted(shown) == sorted(trail)  # every piece appears exactly once
    # the Γ_L axis and the zoom inset keep a trace in every frame (else Plotly blanks them while replaying)
    keep = {i for i, _ in targets.keep}
    assert len(keep) == 2 and all(keep <= set(f["traces"]) for f in frames)
    names = [t["name"] for t in spec["data"]]
    assert "FDSMC enters boundary layer" in names and "Conventional enters boundary layer" not in names


def test_the_zoom_window_holds_the_layer_and_the_excursions_of_the_cruise():
    theta = np.linspace(-10.0, 0.0, 2001)
    omega = np.where(theta < -1.0, 10.0 + 0.3 * np.sin(40 * theta), -theta * 10.0)
    x0, x1, y0, y1 = zoom_window(theta, omega, 10.0, 1.0, 1000.0)
    assert -10.0 < x0 < x1 < -1.0 and x1 - x0 < 2.0  # a short stretch of the cruise
    assert y0 < 10.0 - 0.29 and y1 > 10.0 + 0.29 and y1 - y0 < 1.0  # the chatter fills the inset
    assert zoom_window(theta, omega * 0.0, 10.0, 1.0, 1000.0) is None  # no cruise, no inset


def test_pins_keep_the_latest_four_and_draw_grey_ghosts_outside_the_legend(comparison):
    pin = pin_of(comparison, plant_J_L=0.2)
    assert pin is not None and "J_L plant = 0.2 kg·m² (model 0.12)" in pin.label
    pins = ()
    for _ in range(MAX_PINS + 2):
        pins = pinned(pins, pin)
    assert len(pins) == MAX_PINS
    ghosts = ghost_traces(pins[:1])
    assert [g["name"] for g in ghosts] == ["pin 1 trajectory", "pin 1 ω_r"]
    assert not any(g["showlegend"] for g in ghosts) and ghosts[1]["yaxis"] == "y2"


def test_demo_state_round_trip_keeps_inputs_plant_ranges_and_pins(comparison):
    state = DemoState(comparison.derived.params, 0.2, "paper_12kw_pmsm", {"T_m": (0.1, 10.0)},
                      (pin_of(comparison),))
    back = loads_state(dumps_state(state), "lecture.json")
    assert back.params == state.params and back.plant_J_L == 0.2 and back.ranges == {"T_m": (0.1, 10.0)}
    assert back.pins[0].label == state.pins[0].label
    assert np.allclose(back.pins[0].omega_r, state.pins[0].omega_r, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("edit, words", [
    (lambda d: d.pop("pins"), "not a demo-state file"),
    (lambda d: d.update(demo_state=3), "demo_state = '3': allowed 1 or 2"),
    (lambda d: d["pins"][0].update(t=["1e999"]), "pins[1].t"),
    (lambda d: d["pins"][0].update(t=[1.0]), "different lengths"),
    (lambda d: d.update(ranges={"T_m": [10, 1]}), "allowed 0 < min < max"),
    (lambda d: d.update(preset="schema: 2\nmotor: {p: -1}"), "preset"),
])
def test_a_bad_demo_state_is_refused_with_one_line(comparison, edit, words):
    raw = json.loads(dumps_state(DemoState(comparison.derived.params, None, "x", {}, (pin_of(comparison),))))
    edit(raw)
    with pytest.raises(ValueError) as info:
        loads_state(json.dumps(raw), "bad.json")
    assert words in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(PresetError):
        loads_state("[" * 100, "deep.json")  # the JSON edge's depth check


def test_table1_numbers_have_the_printed_row_reversed_row_and_simulation():
    assert list(printed_reversed(PAPER_TABLE1).values()) == list(PAPER_TABLE1.values())[::-1]
    html = table1_html([Table1Row(1.0, 1600.0, 2150.0, 25.16, 25.1, 28.57, 27.9)], PAPER_TABLE1)
    assert html.count("<tr") == 4 and "printed, columns reversed" in html and "25.2" in html
    assert "run the sweep" in table1_html([], PAPER_TABLE1)


def test_each_erratum_names_its_equation_beside_its_figure():
    assert {eq for eq, _ in ERRATA.values()} >= {"eq. (15)", "eq. (62)", "eq. (59)", "Table 1", "K = 1000 s/rad"}
    for tab, eqs in (("overview", ("eq. (59)", "eq. (62)", "K = 1000")), ("time_plots", ("eq. (15)",)),
                     ("table1", ("Table 1",))):
        assert all(eq in errata_html(tab) for eq in eqs)


def test_log_slider_ranges_are_whole_decades_with_named_marks():
    assert log_range([0.48, 1.4], (0.1, 10.0)) == (-1.0, 1.0)
    assert log_range([250.0], (0.1, 10.0)) == (-1.0, 3.0)
    marks = track_marks(-1.0, 1.0, (("min", 0.48), ("none", math.nan)))
    assert [m[1] for m in marks] == ["0.1", "10", "min"] and marks[2][0] == pytest.approx(math.log10(0.48))


def test_the_J_L_slider_changes_the_plant_and_not_the_controllers_model(comparison):
    from pmsm_commissioning.app.ui.position_tab import comparison_or_derived

    params = comparison.derived.params
    heavier = comparison_or_derived(params, plant_J_L=3.0 * params.load.J_L)
    assert heavier.derived.params == params  # the controllers keep the typed J_L as their model
    # a heavier plant than modelled: the same law gives a slower, different motion
    assert not np.allclose(heavier.fdsmc.trace.omega_r[:200], comparison.fdsmc.trace.omega_r[:200])
    assert heavier.fdsmc.metrics.torque_peak_Nm > 0.0


def test_a_slider_dropped_on_its_min_mark_gives_T_m_min_itself_and_simulates():
    import math

    from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
    from pmsm_commissioning.app.ui.log_slider import LOG_STEP, snapped, value_of_position
    from pmsm_commissioning.control.fdsmc.derivations import derive

    params = load_preset(PAPER_PRESET)
    T_m_min = derive(params).profile.T_m_min
    on_mark = round(math.log10(T_m_min) / LOG_STEP) * LOG_STEP  # where the track's step puts the thumb
    assert value_of_position(on_mark) < T_m_min  # rounded: the wrong side (0.479 < 0.4804)
    assert snapped(on_mark, (("min", T_m_min),)) == T_m_min
    assert snapped(on_mark + 2 * LOG_STEP, (("min", T_m_min),)) == value_of_position(on_mark + 2 * LOG_STEP)
    q = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=T_m_min))
    assert derive(q).profile.feasible
