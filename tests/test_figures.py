"""Pure figure functions: traces, boundary of eq. (41), decimation, meta ids."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pmsm_commissioning.app.figures.decimate import BINS_PHASE
from pmsm_commissioning.app.figures.fdsmc_comparison import (
    cursor_index,
    decimate_index,
    layer_entry_index,
    make_phase_plane_figure,
    make_time_plots_figure,
    phase_plane_spec,
)
from pmsm_commissioning.app.figures.fdsmc_energy import make_energy_bars_figure, make_energy_figure, make_table1_figure
from pmsm_commissioning.app.figures.fdsmc_replay import KEY_RATE, MAX_FRAMES, SPEEDS
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.figures.style import FONT_PX, TEMPLATE_LAYOUT
from pmsm_commissioning.app.ui.replay import phase_plane_json
from pmsm_commissioning.sim.fdsmc.engine import Comparison, compare
from pmsm_commissioning.sim.fdsmc.table1 import PAPER_TABLE1, Table1Row


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
    # −1/T_c line through the origin; x and y are drawn as float32 (each rounded to 2⁻²⁴ relative)
    np.testing.assert_allclose(y[sloped], -x[sloped] / prof.T_c, rtol=2.5e-7)
    for name in ("FDSMC", "Conventional"):
        traj = traces[f"{name} trajectory"]
        assert 100 < len(traj.x) <= 2 * BINS_PHASE + 2
        theta_dem = comparison.derived.params.manoeuvre.theta_dem
        assert traj.x[0] == pytest.approx(-theta_dem)  # starts at rest, θ_re = −θ_dem
    assert fig.layout.meta["id"] == "phase_plane"
    assert fig.layout.meta["omega_p"] == pytest.approx(prof.omega_p)


def test_replay_frames_put_the_markers_on_the_trajectories(comparison):
    """Each speed's in-browser frames move the "now" markers along θ_r(t), ω_r(t) at the frame times."""
    spec = json.loads(phase_plane_json(comparison))
    names = [t["name"] for t in spec["data"]]
    now = [names.index("FDSMC now"), names.index("Conventional now")]
    buttons = spec["layout"]["updatemenus"][0]["buttons"]
    assert [b["label"] for b in buttons] == [f"▶ {k}" for k in SPEEDS] + ["Pause"]
    t_end = float(comparison.fdsmc.trace.t[-1])
    th = comparison.derived.params.manoeuvre.theta_dem
    for button, speed in zip(buttons, SPEEDS.values(), strict=False):
        frames, opts = button["args"]
        assert all(f["traces"][:2] == now for f in frames)  # then the time cursors
        n = len(frames)
        assert 2 <= n <= MAX_FRAMES
        # wall time of the whole replay = simulated time / speed
        assert opts["frame"]["duration"] * (n - 1) == pytest.approx(1e3 * t_end / speed, rel=1e-9)
        k = n // 3
        t_k = t_end * k / (n - 1)
        tr = comparison.conventional.trace
        assert frames[k]["data"][1]["x"][0] == pytest.approx(np.interp(t_k, tr.t, tr.theta_r) - th, rel=1e-4, abs=1e-6)
        assert frames[k]["data"][1]["y"][0] == pytest.approx(np.interp(t_k, tr.t, tr.omega_r), rel=1e-4, abs=1e-6)
        assert frames[-1]["data"][0]["text"] == [f"t = {t_end:.3f} s"]
        # the browser glides linearly between key frames, each glide lasting one frame; the first jumps
        glides = opts["transition"]
        assert len(glides) == n and glides[0]["duration"] == 0
        assert all(g == {"duration": opts["frame"]["duration"], "easing": "linear"} for g in glides[1:])
        assert opts["frame"]["redraw"] is False
    # at 0.25× a key frame comes at least KEY_RATE times per wall second unless capped
    frames, opts = buttons[1]["args"]
    assert opts["frame"]["duration"] <= 1e3 / KEY_RATE + 1e-9 or len(frames) == MAX_FRAMES


def test_dict_figure_json_matches_plotly(comparison):
    """The plain-dict encoder gives the same figure as Plotly's validated go.Figure."""
    spec = phase_plane_spec(comparison)
    ours = json.loads(figure_json(spec))
    theirs = json.loads(make_phase_plane_figure(comparison).to_json())
    assert [t["name"] for t in ours["data"]] == [t["name"] for t in theirs["data"]]
    for a, b in zip(ours["data"], theirs["data"], strict=True):
        for key in ("x", "y"):
            if isinstance(a[key], dict):
                assert a[key] == b[key]  # identical base64 typed arrays
    # the template is plotly_white cut to what cartesian scatter/bar figures use, every kept value as Plotly's
    mine, full = ours["layout"]["template"], theirs["layout"]["template"]
    assert set(mine["data"]) == {"scatter", "bar"} and all(mine["data"][k] == full["data"][k] for k in mine["data"])
    assert {"xaxis", "yaxis", "colorway", "plot_bgcolor", "paper_bgcolor", "font"} <= set(mine["layout"])
    # every kept value as Plotly's, but tick labels that are not measured for overflow on each redraw
    # and the page's font sizes (app.figures.style: ≥ 14 px on plots, titles 16 px)
    for axis in ("xaxis", "yaxis"):
        title = {**full["layout"][axis].get("title", {}), "font": {"size": FONT_PX}}
        assert mine["layout"][axis] == {**full["layout"][axis], "ticklabeloverflow": "allow",
                                        "tickfont": {"size": FONT_PX}, "title": title}
    styled = {"xaxis", "yaxis", *TEMPLATE_LAYOUT}
    assert all(mine["layout"][k] == full["layout"][k] for k in mine["layout"] if k not in styled)
    assert mine["layout"]["font"]["size"] >= FONT_PX
    assert all(mine["layout"][k]["font"]["size"] >= FONT_PX for k in ("legend", "annotationdefaults", "hoverlabel"))
    assert len(json.dumps(mine)) < 0.2 * len(json.dumps(full))


def test_phase_plane_marks_boundary_layer_entry(comparison):
    """The FDSMC marker of the boundary-layer entry lies within ±1/K of the switching boundary, eq. (45)."""
    from pmsm_commissioning.control.fdsmc.sliding_mode import boundary_speed

    k = layer_entry_index(comparison, comparison.fdsmc)
    assert k is not None and 0 < k < len(comparison.fdsmc.trace.t) - 1
    tr, d = comparison.fdsmc.trace, comparison.derived
    th_re = tr.theta_r - d.params.manoeuvre.theta_dem
    gap = np.abs(tr.omega_r - boundary_speed(th_re, d.profile.omega_p, d.profile.T_c))
    assert gap[k] <= 1.0 / d.params.controller.K < gap[k - 1]
    fig = make_phase_plane_figure(comparison)
    entry = next(t for t in fig.data if t.name == "FDSMC enters boundary layer")
    # the label leans into the plot, away from the nearer edge of the θ_re axis
    lo, hi = fig.layout.xaxis.range
    assert entry.textposition == ("top right" if entry.x[0] < (lo + hi) / 2 else "top left")


def test_time_plots_have_all_signals_of_both_controllers(comparison):
    fig = make_time_plots_figure(comparison)
    names = {t.name for t in fig.data}
    for label in ("θ_r", "ω_r", "i_d", "i_q", "u_d", "u_q", "α", "α_dem", "Γ_L", "Γ̂_L"):
        assert f"{label} FDSMC" in names and f"{label} Conventional" in names
    assert {"θ_dem", "ω_p, eq. (60)"} <= names


def test_energy_figures_show_totals_and_saving(comparison):
    bars = make_energy_bars_figure(comparison)
    fdsmc = next(t for t in bars.data if t.name == "FDSMC")
    assert fdsmc.y[0] == pytest.approx(comparison.fdsmc.metrics.friction_total_J)
    assert f"{comparison.saving_friction_pct:.1f} %" in bars.layout.title.text
    energy = make_energy_figure(comparison)
    assert len(energy.data) == 6


def test_table1_figure_plots_paper_values():
    rows = [Table1Row(1.0, 1600.0, 2150.0, 25.6, 25.1, 28.57, 27.9)]
    fig = make_table1_figure(rows, PAPER_TABLE1)
    paper = next(t for t in fig.data if t.name == "paper, Table 1 as printed")
    assert list(paper.x) == sorted(PAPER_TABLE1)
    back = next(t for t in fig.data if t.name.startswith("paper, columns reversed"))
    assert list(back.y) == list(paper.y)[::-1]  # the erratum: the printed row read right to left
    assert make_table1_figure([]).layout.meta["id"] == "table1"


def test_decimation_and_cursor():
    idx = decimate_index(13001, 2000)
    assert len(idx) <= 2000 and idx[0] == 0 and idx[-1] == 13000
    assert list(decimate_index(5)) == [0, 1, 2, 3, 4]
    t = np.array([0.0, 0.1, 0.2])
    assert cursor_index(t, -1.0) == 0 and cursor_index(t, 0.15) == 1 and cursor_index(t, 9.0) == 2
