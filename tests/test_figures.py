"""Pure figure functions: traces, boundary of eq. (41), decimation, meta ids."""

from __future__ import annotations

import numpy as np
import pytest

from app.figures import (
    MAX_POINTS,
    cursor_index,
    decimate_index,
    make_phase_plane_figure,
    make_time_plots_figure,
)
from app.figures_energy import make_energy_bars_figure, make_energy_figure, make_table1_figure
from app.ui_replay import PhaseTemplate, time_template
from sim.engine import PAPER_TABLE1, Comparison, Table1Row, compare


@pytest.fixture(scope="module")
def comparison(paper_params) -> Comparison:
    return compare(paper_params)


def _by_name(fig):
    return {t.name: t for t in fig.data}


def test_phase_plane_has_boundary_band_and_both_trajectories(comparison):
    fig = make_phase_plane_figure(comparison)
    traces = _by_name(fig)
    prof = comparison.derived.profile
    y = np.asarray(traces["Switching boundary, eq. (41)"].y)
    assert y.max() == pytest.approx(prof.omega_p) and y.min() == pytest.approx(-prof.omega_p)
    x = np.asarray(traces["Switching boundary, eq. (41)"].x)
    sloped = np.abs(x) < 0.5 * prof.T_c * prof.omega_p
    np.testing.assert_allclose(y[sloped], -x[sloped] / prof.T_c)  # −1/T_c line through the origin
    for name in ("FDSMC", "Conventional"):
        traj = traces[f"{name} trajectory"]
        assert 100 < len(traj.x) <= MAX_POINTS
        theta_dem = comparison.derived.params.manoeuvre.theta_dem
        assert traj.x[0] == pytest.approx(-theta_dem)  # starts at rest, θ_re = −θ_dem
    assert fig.layout.meta["id"] == "phase_plane"
    assert fig.layout.meta["omega_p"] == pytest.approx(prof.omega_p)


def test_phase_plane_replay_time_draws_part_of_the_trajectory(comparison):
    fig = make_phase_plane_figure(comparison, t_now=0.3)
    traces = _by_name(fig)
    so_far, whole = traces["FDSMC so far"], traces["FDSMC trajectory"]
    assert 1 < len(so_far.x) < len(whole.x)
    assert len(traces["FDSMC now"].x) == 1
    assert traces["FDSMC now"].x[0] == so_far.x[-1]


def test_phase_template_frame_matches_figure(comparison):
    import json
    tpl = PhaseTemplate(comparison)
    data = json.loads(tpl.frame(0.3))
    names = {t["name"]: t for t in data["data"]}
    expected = _by_name(make_phase_plane_figure(comparison, t_now=0.3))
    assert len(names["FDSMC so far"]["x"]) == len(expected["FDSMC so far"].x)
    assert names["Conventional now"]["y"][0] == pytest.approx(float(expected["Conventional now"].y[0]), rel=1e-5)
    cursor = json.loads(time_template(comparison).replace('"__cursor__"', "0.25"))
    assert cursor["layout"]["shapes"][0]["x0"] == 0.25


def test_time_plots_have_all_signals_of_both_controllers(comparison):
    fig = make_time_plots_figure(comparison)
    names = {t.name for t in fig.data}
    for label in ("θ_r", "ω_r", "i_d", "i_q", "u_d", "u_q", "α", "α_dem", "Γ_L", "Γ̂_L"):
        assert f"{label} FDSMC" in names and f"{label} Conventional" in names
    assert {"θ_dem", "ω_p, eq. (60)"} <= names
    assert fig.layout.shapes[0].x0 == 0.0


def test_energy_figures_show_totals_and_saving(comparison):
    bars = make_energy_bars_figure(comparison)
    fdsmc = next(t for t in bars.data if t.name == "FDSMC")
    assert fdsmc.y[0] == pytest.approx(comparison.fdsmc.metrics["friction_total_J"])
    assert f"{comparison.saving_friction_pct:.1f} %" in bars.layout.title.text
    energy = make_energy_figure(comparison)
    assert len(energy.data) == 6


def test_table1_figure_plots_paper_values():
    rows = [Table1Row(1.0, 1600.0, 2150.0, 25.6, 25.1, 28.57, 27.9)]
    fig = make_table1_figure(rows, PAPER_TABLE1)
    paper = next(t for t in fig.data if t.name == "paper, Table 1")
    assert list(paper.x) == sorted(PAPER_TABLE1)
    assert make_table1_figure([]).layout.meta["id"] == "table1"


def test_decimation_and_cursor():
    idx = decimate_index(13001, 2000)
    assert len(idx) <= 2000 and idx[0] == 0 and idx[-1] == 13000
    assert list(decimate_index(5)) == [0, 1, 2, 3, 4]
    t = np.array([0.0, 0.1, 0.2])
    assert cursor_index(t, -1.0) == 0 and cursor_index(t, 0.15) == 1 and cursor_index(t, 9.0) == 2
