"""Overview figure (phase plane + compact time plot, one replay); the panel layout: tests/test_layout.py."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from pmsm_commissioning.app.figures.fdsmc_overview import CURSORS, motor_torque, overview_spec
from pmsm_commissioning.app.ui.layout import ASPECT_MAX, ASPECT_MIN, CHROME_HEIGHT
from pmsm_commissioning.app.ui.replay import overview_json, phase_plane_json, prebuild_figures, time_plots_json
from pmsm_commissioning.sim.fdsmc.engine import Comparison, compare


@pytest.fixture(scope="module")
def comparison(paper_params) -> Comparison:
    return compare(paper_params)


def test_motor_torque_is_eq5_and_kt_times_iq_for_a_round_rotor(paper_params):
    m = paper_params.motor
    i_q, i_d = np.array([0.0, 10.0, -20.0]), np.array([0.0, 3.0, 1.0])
    # L_d = L_q (surface magnets): Γ = (3/2)·p·Ψ_PM·i_q whatever i_d
    np.testing.assert_allclose(motor_torque(m, i_d, i_q), 1.5 * m.p * m.psi_pm * i_q)


def test_overview_keeps_the_phase_plane_and_adds_the_time_rows(comparison):
    spec = overview_spec(comparison)
    names = [t["name"] for t in spec["data"]]
    assert spec["layout"]["meta"]["id"] == "phase_plane" and spec["layout"]["meta"]["overview"]
    assert names[:2] == ["Layer ±1/K = ±0.001 rad/s (45)", "Switching boundary, eq. (41)"]
    assert {"FDSMC trajectory", "FDSMC now", "Conventional now", "ω_r FDSMC", "Γ Conventional", *CURSORS} <= set(names)
    # the two plots sit side by side, the time rows one above the other
    lay = spec["layout"]
    assert lay["xaxis"]["domain"][1] < lay["xaxis2"]["domain"][0]
    assert lay["yaxis3"]["domain"][1] < lay["yaxis2"]["domain"][0]
    # the torque row shows the motor torque of eq. (5) of the FDSMC run at its first sample
    tr, m = comparison.fdsmc.trace, comparison.derived.params.motor
    gamma = next(t for t in spec["data"] if t["name"] == "Γ FDSMC")
    assert float(gamma["y"][0]) == pytest.approx(float(motor_torque(m, tr.i_d[:1], tr.i_q[:1])[0]), rel=1e-5, abs=1e-6)


def test_every_replay_frame_puts_the_cursors_at_the_markers_time(comparison):
    spec = json.loads(phase_plane_json(comparison))
    names = [t["name"] for t in spec["data"]]
    cursors = [names.index(n) for n in CURSORS]
    t_end = float(comparison.fdsmc.trace.t[-1])
    for button in spec["layout"]["updatemenus"][0]["buttons"][:-1]:
        frames, _ = button["args"]
        for k in (0, len(frames) // 2, len(frames) - 1):
            f = frames[k]
            moved = dict(zip(f["traces"], f["data"], strict=True))  # markers, cursors, the trail it shows
            t = float(f["data"][0]["text"][0].split()[2])  # "t = 0.123 s"
            for i in cursors:
                assert moved[i]["x"][0] == moved[i]["x"][1] == pytest.approx(t, abs=1e-3)
        assert dict(zip(frames[-1]["traces"], frames[-1]["data"], strict=True))[cursors[-1]]["x"][0] == \
            pytest.approx(t_end, rel=1e-5)
    # no Plotly slider: it would be drawn again with every redraw of the figure
    assert "sliders" not in spec["layout"]


def test_a_scrub_puts_the_markers_on_the_trajectories_at_that_time(comparison):
    """The "Replay t" scrub: markers at (θ_r(t) − θ_dem, ω_r(t)) of each run, cursors at x = [t, t]
    with their vertical extent kept, the time in the first marker's text.
    """
    from pmsm_commissioning.app.figures.fdsmc_replay import ScrubTargets, scrub_update

    spec = overview_spec(comparison)
    names = [t["name"] for t in spec["data"]]
    targets = ScrubTargets.of(spec["data"])
    assert [names[i] for i in targets.now] == ["FDSMC now", "Conventional now"]
    assert [names[i] for i in targets.cursors] == list(CURSORS)
    th = comparison.derived.params.manoeuvre.theta_dem
    for t in (0.0, 0.2345, float(comparison.fdsmc.trace.t[-1])):
        update, indices = scrub_update(comparison, targets, t)
        assert indices == [*targets.now, *targets.cursors]
        for j, run in enumerate((comparison.fdsmc, comparison.conventional)):
            tr = run.trace
            # 5 significant digits, as the key frames
            assert update["x"][j][0] == pytest.approx(np.interp(t, tr.t, tr.theta_r) - th, rel=1e-4, abs=1e-9)
            assert update["y"][j][0] == pytest.approx(np.interp(t, tr.t, tr.omega_r), rel=1e-4, abs=1e-6)
        for k, i in enumerate(targets.cursors, start=len(targets.now)):
            assert update["x"][k] == pytest.approx([t, t], abs=1e-6)
            assert update["y"][k] == list(spec["data"][i]["y"])
        assert update["text"][0] == [f"t = {t:.3f} s"]


def test_the_drag_overview_draws_the_same_curves_statically(comparison):
    """While a slider is dragged: the same curves, a static plot, no replay, no empty text layers;
    the plain trajectories instead of the replay's trail, and nothing only a replay moves.
    """
    full, drag = (json.loads(overview_json(comparison, replay)[0]) for replay in (True, False))
    assert drag["config"] == {"staticPlot": True}
    assert full["config"] == {}  # explicit: Plotly.react would keep the drag figure's static config
    assert "updatemenus" not in drag["layout"] and not drag.get("frames")
    replay_only = [t["name"] for t in full["data"] if "trail" in (t.get("meta") or {})
                   or t["name"].endswith(" now") or t["name"].startswith("time cursor")]
    assert len(replay_only) > 30  # mostly the trail pieces
    assert [t["name"] for t in drag["data"]] == [t["name"] for t in full["data"] if t["name"] not in replay_only]
    by_name = {t["name"]: t for t in full["data"]}
    for b in drag["data"]:
        a = by_name[b["name"]]
        assert a.get("x") == b.get("x") and a.get("y") == b.get("y")
        if a["name"].endswith(" trajectory"):
            assert b["opacity"] == 1.0 and a.get("opacity", 1.0) in (0.0, 1.0)
        assert b.get("mode") == a.get("mode")
    targets = overview_json(comparison, replay=False)[1]
    assert targets.now == targets.cursors == targets.trail == ()  # a scrub of the drag figure moves nothing
    # drawn first after a Simulate: the same light figure with Plotly's default config (as the whole one's)
    first = json.loads(overview_json(comparison, replay=False, static=False)[0])
    assert first["config"] == {} and first["data"] == drag["data"] and first["layout"] == drag["layout"]
    assert next(t for t in drag["data"] if t["name"] == "FDSMC enters boundary layer")["mode"] == "markers+text"


def test_the_overview_tells_the_page_how_to_fit_its_height(comparison):
    """``layout.meta.fit_height``: the page sizes the plot from the window on its first draw, with the
    rule of ``layout_for_window`` (checked against the server's aspect in tests/browser/test_layout_steady.py).
    """
    for replay in (True, False):
        meta = json.loads(overview_json(comparison, replay)[0])["layout"]["meta"]
        assert meta["fit_height"] == [CHROME_HEIGHT, ASPECT_MIN, ASPECT_MAX]


def test_the_start_up_figures_are_built_once_and_a_new_comparison_builds_its_own(comparison):
    """Every new page shows the start-up comparison: its figures come from the build at server start."""
    prebuild_figures(comparison)
    first = overview_json(comparison)
    assert overview_json(comparison) is first and time_plots_json(comparison) is time_plots_json(comparison)
    other = dataclasses.replace(comparison)  # equal, but another result object: built again
    again = overview_json(other)
    assert again is not first and again[0] == first[0]
