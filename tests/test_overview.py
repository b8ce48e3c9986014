"""Overview figure (phase plane + compact time plot, one replay); the panel layout: tests/test_layout.py."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app.figures.overview import CURSORS, motor_torque, overview_spec
from app.ui.replay import phase_plane_json
from sim.fdsmc.engine import Comparison, compare


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
    assert names[:2] == ["Boundary layer ±1/K = ±0.001 rad/s, eq. (45)", "Switching boundary, eq. (41)"]
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
            assert f["traces"][-2:] == cursors
            t = float(f["data"][0]["text"][0].split()[2])  # "t = 0.123 s"
            for d in f["data"][-2:]:
                assert d["x"][0] == d["x"][1] == pytest.approx(t, abs=1e-3)
        assert frames[-1]["data"][-1]["x"][0] == pytest.approx(t_end, rel=1e-5)
    # the scrub slider moves the cursors too and keeps their vertical extent
    step = spec["layout"]["sliders"][0]["steps"][0]
    assert step["args"][1][-2:] == cursors and step["args"][0]["x"][-1] == [0.0, 0.0]
    assert step["args"][0]["y"][-1] == spec["data"][cursors[1]]["y"]
