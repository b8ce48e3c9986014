"""Figures, tables and page inputs of the studies beyond the paper (optimum, robustness, multi-axis)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmsm_commissioning.app.figures.fdsmc_comparison import phase_plane_spec, time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_energy import energy_bars_spec, optimum_gaps
from pmsm_commissioning.app.figures.fdsmc_studies import (
    histogram,
    multiaxis_spec,
    multiaxis_table_markdown,
    robustness_spec,
    robustness_table_markdown,
    sample_values,
)
from pmsm_commissioning.app.figures.plain import to_figure
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.ui.studies import optimum_markdown
from pmsm_commissioning.app.ui.studies_multiaxis import axis_line, check_axes, default_axes, parse_page_axes
from pmsm_commissioning.app.ui.studies_robustness import STUDY_MAX_STEPS, check_study, parse_page_spreads
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.sim.common.budget import BudgetError
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, CONTROLLERS, LABELS, compare
from pmsm_commissioning.sim.fdsmc.grid import check_budget
from pmsm_commissioning.sim.fdsmc.optimum_gap import saving_vs_optimum
from pmsm_commissioning.sim.fdsmc.verdicts import TARGET_BAND
from pmsm_commissioning.sim.studies.multiaxis import coordinate
from pmsm_commissioning.sim.studies.robustness import TRACE_POINTS, robustness

PRESET = "siemens_1ft7044_ak7"
PRESETS = ("paper_12kw_pmsm", "siemens_1ft7044_ak7", "yaskawa_sgm7j_04a")


@pytest.fixture(scope="module")
def with_optimum():
    return compare(load_preset(PRESET), COMPARATORS)


def test_histogram_counts_every_finite_sample_on_common_bins():
    a, b = np.array([0.0, 1.0, 2.0, np.nan, 3.0]), np.array([1.5, 2.5, np.inf])
    edges, (na, nb) = histogram([a, b], n_bins=6)
    assert edges[0] == 0.0 and edges[-1] == 3.0 and len(edges) == 7
    assert na.sum() == 4 and nb.sum() == 2  # NaN and inf are not drawn


def test_histogram_of_identical_values_is_one_bar():
    edges, (n,) = histogram([np.full(5, 2.5)])
    assert n.sum() == 5 and np.count_nonzero(n) == 1
    k = int(np.flatnonzero(n)[0])
    assert edges[k] <= 2.5 <= edges[k + 1]


def test_third_trace_line_and_bar_of_the_optimum(with_optimum):
    names = [t["name"] for t in phase_plane_spec(with_optimum)["data"]]
    assert {"Optimum trajectory", "Optimum now"} <= set(names)
    assert "Optimum enters boundary layer" not in names  # the optimum is tracked, not sliding
    time_names = {t["name"] for t in time_plots_spec(with_optimum)["data"]}
    assert "θ_r Optimum" in time_names and "i_q Optimum" in time_names
    bars = {t["name"]: t for t in energy_bars_spec(with_optimum)["data"]}
    assert list(bars) == ["FDSMC", "Conventional", "Optimum"]
    electrical = {k: b["y"][2] for k, b in bars.items()}
    # the minimum-energy move draws less electrical input than either controller on the same move
    assert electrical["Optimum"] < electrical["FDSMC"] and electrical["Optimum"] < electrical["Conventional"]


def test_gap_to_the_optimum_in_the_numbers(with_optimum):
    gaps = optimum_gaps(with_optimum)
    w = {k: getattr(with_optimum, k).metrics.electrical_in_total_J for k in COMPARATORS}
    assert gaps["fdsmc"] == pytest.approx(100.0 * (1.0 - w["optimum"] / w["fdsmc"]))
    assert gaps["conventional"] == pytest.approx(saving_vs_optimum(with_optimum.conventional, with_optimum.optimum))
    spec = energy_bars_spec(with_optimum)
    assert spec["layout"]["meta"]["gap_to_optimum_pct"] == gaps
    assert f"{gaps['fdsmc']:.1f} %" in spec["layout"]["title"]["text"]
    assert f"{gaps['fdsmc']:.1f} %" in optimum_markdown(with_optimum)
    to_figure(spec)  # a valid Plotly figure


def test_the_supplys_energy_is_a_bar_and_a_gap_under_the_dc_link(with_optimum):
    """Default DC link (braking resistor): the fourth bar is the energy drawn, its gap the drawn basis."""
    bars = {t["name"]: t for t in energy_bars_spec(with_optimum)["data"]}
    assert bars["FDSMC"]["x"][3] == "from the supply (braking resistor)"
    for key in ("fdsmc", "conventional", "optimum"):
        run = getattr(with_optimum, key)
        assert bars[LABELS[key]]["y"][3] == run.metrics.motoring_total_J
    drawn = {k: getattr(with_optimum, k).metrics.motoring_total_J for k in COMPARATORS}
    gaps = energy_bars_spec(with_optimum)["layout"]["meta"]["gap_to_optimum_supply_pct"]
    assert gaps["fdsmc"] == pytest.approx(100.0 * (1.0 - drawn["optimum"] / drawn["fdsmc"]))
    assert f"{gaps['fdsmc']:.1f} %" in optimum_markdown(with_optimum).split("From the supply")[1]


def test_no_optimum_numbers_without_the_optimum_run():
    cmp = compare(load_preset(PRESET), CONTROLLERS)
    assert optimum_gaps(cmp) == {} and optimum_markdown(cmp) == ""
    assert [t["name"] for t in energy_bars_spec(cmp)["data"]] == ["FDSMC", "Conventional"]


@pytest.fixture(scope="module")
def zero_spread():
    params = load_preset(PRESET)
    spreads = parse_page_spreads({"R_s spread": "±0%"})
    return params, robustness(params, spreads, 6, seed=3)


def test_zero_spread_histograms_sit_on_the_nominal_run(zero_spread):
    params, res = zero_spread
    nominal = compare(params, CONTROLLERS, max_points=TRACE_POINTS)
    lim = torque_limit(params)
    values = sample_values(res, lim)
    np.testing.assert_allclose(values["saving_friction_pct"]["fdsmc"], nominal.saving_friction_pct, rtol=1e-12)
    w_f, w_c = (getattr(nominal, k).metrics.electrical_in_total_J for k in CONTROLLERS)
    np.testing.assert_allclose(values["saving_electrical_pct"]["fdsmc"], 100.0 * (1.0 - w_f / w_c), rtol=1e-12)
    np.testing.assert_allclose(values["torque_ratio"]["conventional"],
                               nominal.conventional.metrics.torque_peak_Nm / lim, rtol=1e-12)
    spec = robustness_spec(res, lim)
    assert spec["layout"]["meta"]["samples"] == 6
    for t in spec["data"]:  # every panel: all 6 samples in one bar (no spread)
        assert int(np.sum(t["y"])) == 6 and np.count_nonzero(t["y"]) == 1
    to_figure(spec)


def test_summary_table_lists_the_statistics(zero_spread):
    _, res = zero_spread
    md = robustness_table_markdown(res.summary)
    s = res.summary
    assert "| mean | p05 | p50 | p95 | worst |" in md
    assert f"{s['saving_friction_pct']['p50']:.4g}" in md
    assert f"{s['fdsmc']['torque_peak_Nm']['worst']:.4g}" in md
    assert "chatter probability" in md and md.startswith("**6 samples")


def test_page_spreads_use_the_command_line_syntax_and_name_the_field():
    s = parse_page_spreads({"J_L spread": "0:0.3", "L_d, L_q spread": "~5%", "R_s spread": ""})
    assert [(x.field, x.kind, x.lo, x.hi) for x in s] == [("J_L", "uniform", 0.0, 0.3),
                                                          ("L_d", "normal", 0.0, 0.05), ("L_q", "normal", 0.0, 0.05)]
    with pytest.raises(ParameterError, match=r"Robustness › R_s spread = '±150%'.*0 … <100 %"):
        parse_page_spreads({"R_s spread": "±150%"})
    with pytest.raises(ParameterError, match=r"Ψ_PM spread = 'abc'"):
        parse_page_spreads({"Ψ_PM spread": "abc"})


def test_study_over_budget_names_samples_and_allowed_range():
    params = load_preset("paper_12kw_pmsm")
    steps = check_budget(params, 2, max_points=TRACE_POINTS).steps
    n_max = STUDY_MAX_STEPS // steps
    assert check_study(params, n_max, 7) == (n_max, 7)
    with pytest.raises(BudgetError, match=rf"samples = {n_max + 1} is too many.*allowed 1 … {n_max} samples"):
        check_study(params, n_max + 1, 0)
    with pytest.raises(ParameterError, match=r"samples = 2.5 is out of range: allowed a whole number"):
        check_study(params, 2.5, 0)
    with pytest.raises(ParameterError, match=r"seed = -1 is out of range"):
        check_study(params, 10, -1)


def test_page_axes_are_the_cli_list_restricted_to_shipped_presets():
    text = default_axes(PRESETS) + axis_line("paper_12kw_pmsm", "Z", 3.0)
    axes = parse_page_axes(text, PRESETS)
    assert [n for n, _ in axes] == ["X", "Y", "Z"] and axes[2][1].manoeuvre.theta_dem == 3.0
    with pytest.raises(ParameterError, match=r"axis 1: preset '/etc/passwd' is not allowed"):
        parse_page_axes("- {preset: /etc/passwd}\n", PRESETS)
    with pytest.raises(ParameterError, match=r"common T_m = -1 s is out of range"):
        check_axes(axes, -1.0)
    assert check_axes(axes, 0.0) is None and check_axes(axes, 2.0) == 2.0


@pytest.fixture(scope="module")
def coordinated():
    return coordinate(parse_page_axes(default_axes(PRESETS), PRESETS))


def test_multiaxis_figure_shows_every_axis_arriving_at_the_common_time(coordinated):
    res = coordinated
    spec = multiaxis_spec(res)
    band = TARGET_BAND["fdsmc"]
    positions = [t for t in spec["data"] if t["yaxis"] == "y"]
    assert [t["name"] for t in positions] == [a.name for a in res.axes]
    for t in positions:  # θ_r/θ_dem read off the drawn trace at the common T_m
        k = int(round((res.T_m - t["x0"]) / t["dx"]))
        assert abs(float(t["y"][k]) - 1.0) <= band + 1e-3
    assert all(e <= band for e in spec["layout"]["meta"]["theta_error_frac_at_T_m"])
    md = multiaxis_table_markdown(res)
    assert md.count("| yes |") == len(res.axes) and f"{res.T_m:.4g} s" in md
    to_figure(spec)


def test_axis_names_are_shown_as_text_not_markup(coordinated):
    evil = "<img src=x onerror=alert(1)>|**bold**"
    res = dataclasses.replace(coordinated, axes=(dataclasses.replace(coordinated.axes[0], name=evil),))
    md = multiaxis_table_markdown(res, md_text)
    assert "<img" not in md and "**bold**" not in md and "&lt;img" in md
    spec = multiaxis_spec(res)
    assert spec["data"][0]["name"].startswith("&lt;img") and spec["layout"]["meta"]["names"][0].startswith("&lt;")
