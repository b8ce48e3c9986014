"""Pure figures and tables of the studies beyond the paper: Monte-Carlo robustness and multi-axis moves.

Plain-dict figures (see :mod:`app.figures.plain`), each with ``layout.meta.id``. Histograms are
binned here (numpy) and drawn as bars, so the figure carries counts, not every sample.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import html
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import plotly.graph_objects as go

from pmsm_commissioning.app.figures.decimate import f32, time_axis
from pmsm_commissioning.app.figures.fdsmc_comparison import COLOURS, LABELS, MAX_POINTS_TIME, stride_index
from pmsm_commissioning.app.figures.plain import to_figure
from pmsm_commissioning.app.figures.style import FONT_PX
from pmsm_commissioning.sim.fdsmc.verdicts import TARGET_BAND
from pmsm_commissioning.sim.studies.multiaxis import MultiAxisResult
from pmsm_commissioning.sim.studies.robustness import RobustnessResult

#: The two controllers compared by the robustness study, in drawing order.
CONTROLLERS = ("fdsmc", "conventional")
#: Histogram bins per panel [-].
N_BINS = 24
#: Robustness panels: (key, title, unit, per-controller?).
PANELS = (
    ("saving_friction_pct", "Friction saving FDSMC vs conventional", "%", False),
    ("saving_electrical_pct", "Electrical-input saving FDSMC vs conventional", "%", False),
    ("torque_ratio", "Peak torque / Γ_max", "-", True),
    ("theta_error_abs_at_Tm_rad", "|θ error| at T_m", "rad", True),
)
#: Axis colours of the multi-axis figure (cycled).
AXIS_COLOURS = ("#1f6fd1", "#e8590c", "#2f9e44", "#9c36b5", "#c92a2a", "#1098ad", "#f08c00", "#495057")


def _value(x: Any) -> float:
    """Return a metric as float; NaN when missing (None, bool, non-finite)."""
    return float(x) if isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x) else math.nan


def sample_values(result: RobustnessResult, torque_limit_Nm: float) -> dict[str, dict[str, np.ndarray]]:
    """Per panel key, per controller (``"fdsmc"`` only for the savings), one value per sample (NaN if none).

    ``saving_electrical_pct`` = 100·(1 − W_FDSMC/W_conv) with W the net electrical input over the
    whole run [J]; ``torque_ratio`` = peak |Γ_em| / ``torque_limit_Nm`` (the drive's Γ_max) [-].
    """
    runs = result.runs
    w_f = np.array([_value(r["fdsmc"]["electrical_in_total_J"]) for r in runs])
    w_c = np.array([_value(r["conventional"]["electrical_in_total_J"]) for r in runs])
    with np.errstate(divide="ignore", invalid="ignore"):
        elec = np.where(w_c > 0.0, 100.0 * (1.0 - w_f / w_c), np.nan)
    out: dict[str, dict[str, np.ndarray]] = {
        "saving_friction_pct": {"fdsmc": np.array([_value(r["fdsmc"].get("saving_friction_pct")) for r in runs])},
        "saving_electrical_pct": {"fdsmc": elec},
    }
    out["torque_ratio"] = {c: np.array([_value(r[c]["torque_peak_Nm"]) for r in runs]) / torque_limit_Nm
                           for c in CONTROLLERS}
    out["theta_error_abs_at_Tm_rad"] = {c: np.array([_value(r[c]["theta_error_abs_at_Tm_rad"]) for r in runs])
                                        for c in CONTROLLERS}
    return out


def histogram(values: Sequence[np.ndarray], n_bins: int = N_BINS) -> tuple[np.ndarray, list[np.ndarray]]:
    """Return common bin edges of the finite values of every array, and each array's counts on them."""
    finite = [v[np.isfinite(v)] for v in values]
    both = np.concatenate(finite) if finite else np.empty(0)
    if both.size == 0:
        return np.array([0.0, 1.0]), [np.zeros(1, dtype=int) for _ in finite]
    lo, hi = float(both.min()), float(both.max())
    if hi <= lo:
        half = max(abs(lo) * 1e-3, 1e-12)
        lo, hi = lo - half, hi + half
    edges = np.linspace(lo, hi, n_bins + 1)
    return edges, [np.histogram(v, bins=edges)[0] for v in finite]


def _grid_axes(n_rows: int, n_cols: int, gap: float = 0.1) -> dict[str, Any]:
    """Layout axes of an ``n_rows`` × ``n_cols`` grid of subplots, numbered row by row."""
    w, h = (1.0 - gap * (n_cols - 1)) / n_cols, (1.0 - gap * 2.0 * (n_rows - 1)) / n_rows
    out: dict[str, Any] = {}
    for k in range(n_rows * n_cols):
        r, c = divmod(k, n_cols)
        sfx = "" if k == 0 else str(k + 1)
        x0, y1 = c * (w + gap), 1.0 - r * (h + 2.0 * gap)
        out[f"xaxis{sfx}"] = {"domain": [round(x0, 9), round(x0 + w, 9)], "anchor": f"y{sfx}"}
        out[f"yaxis{sfx}"] = {"domain": [round(max(y1 - h, 0.0), 9), round(y1, 9)], "anchor": f"x{sfx}",
                              "title": {"text": "samples"} if c == 0 else {}}
    return out


def robustness_spec(result: RobustnessResult, torque_limit_Nm: float) -> dict[str, Any]:
    """Histograms of the robustness study as a plain-dict figure (see :func:`make_robustness_figure`)."""
    values = sample_values(result, torque_limit_Nm)
    data: list[dict[str, Any]] = []
    layout = _grid_axes(2, 2)
    drawn: dict[str, dict[str, int]] = {}
    notes: list[dict[str, Any]] = []
    for k, (key, title, unit, _) in enumerate(PANELS):
        sfx = "" if k == 0 else str(k + 1)
        series = values[key]
        edges, counts = histogram(list(series.values()))
        centres, width = 0.5 * (edges[:-1] + edges[1:]), float(edges[1] - edges[0])
        for ctrl, n in zip(series, counts, strict=True):
            name = LABELS[ctrl] if len(series) > 1 else "FDSMC vs conventional"
            data.append({"type": "bar", "x": centres, "y": n, "width": width, "name": name,
                         "legendgroup": ctrl, "showlegend": k == 2, "opacity": 0.6,
                         "marker": {"color": COLOURS[ctrl]}, "xaxis": f"x{sfx}", "yaxis": f"y{sfx}",
                         "meta": {"panel": key, "controller": ctrl},
                         "hovertemplate": f"%{{x:.4g}} {unit}: %{{y}} samples<extra>{name}</extra>"})
        n = len(result.runs)
        missing = max(n - int(c.sum()) for c in counts)
        dom_x, dom_y = layout[f"xaxis{sfx}"]["domain"], layout[f"yaxis{sfx}"]["domain"]
        notes.append({"text": f"{title} [{unit}]" + (f"<br>({missing} of {n} samples without a value)"
                                                       if missing else ""),
                      "x": 0.5 * (dom_x[0] + dom_x[1]), "y": dom_y[1], "xref": "paper", "yref": "paper",
                      "xanchor": "center", "yanchor": "bottom", "showarrow": False, "font": {"size": FONT_PX}})
        drawn[key] = {ctrl: int(c.sum()) for ctrl, c in zip(series, counts, strict=True)}
    n = len(result.runs)
    return {"data": data, "layout": {
        **layout, "annotations": notes, "barmode": "overlay", "template": "plotly_white",
        "meta": {"id": "robustness", "samples": n, "drawn": drawn},
        "title": {"text": f"Robustness — {n} sampled plants (controller designed on the nominal model)", "x": 0.01},
        "margin": {"l": 60, "r": 16, "t": 70, "b": 40}, "legend": {"orientation": "h", "y": -0.08},
        "font": {"size": FONT_PX}}}


def make_robustness_figure(result: RobustnessResult, torque_limit_Nm: float) -> go.Figure:
    """Histograms of the Monte-Carlo robustness study: FDSMC vs conventional on the sampled plants.

    Panels: friction saving [%] (over [0, T_m], eq. (47) in [1]), electrical-input saving [%]
    (whole run), peak torque / Γ_max [-] and |θ error| at T_m [rad] for both controllers.

    Parameters
    ----------
    result : sim.studies.robustness.RobustnessResult
    torque_limit_Nm : float
        The drive's torque limit Γ_max [N·m] the peak torques are divided by.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return to_figure(robustness_spec(result, torque_limit_Nm))


#: Summary rows: (metric key of the summary, label, unit).
SUMMARY_ROWS = (
    ("friction_J", "Friction over [0, T_m]", "J"),
    ("electrical_in_total_J", "Electrical input, whole run", "J"),
    ("torque_peak_Nm", "Peak torque", "N·m"),
    ("theta_error_abs_at_Tm_rad", "|θ error| at T_m", "rad"),
    ("t_2pct_settle_s", "2 % settling time", "s"),
)
STATS = ("mean", "p05", "p50", "p95", "worst")


def _cell(v: Any) -> str:
    return "—" if v is None or not math.isfinite(v) else f"{v:.4g}"


def robustness_table_markdown(summary: dict[str, Any]) -> str:
    """Return a Markdown table of the study's summary per metric and controller.

    Mean, p05, p50, p95, worst per metric and controller, the friction saving's distribution and
    the chatter / infeasible probabilities.
    """
    head = "| metric | controller | " + " | ".join(STATS) + " |\n|---|---|" + "---|" * len(STATS) + "\n"
    sav = summary["saving_friction_pct"]
    rows = ["| Friction saving [%] | FDSMC vs conv. | " + " | ".join(_cell(sav[s]) for s in STATS) + " |"]
    for key, label, unit in SUMMARY_ROWS:
        for ctrl in CONTROLLERS:
            e = summary[ctrl][key]
            rows.append(f"| {label} [{unit}] | {LABELS[ctrl]} | " + " | ".join(_cell(e[s]) for s in STATS) + " |")
    probs = "; ".join(f"{LABELS[c]}: chatter probability **{_cell(summary[c]['chatter_probability'])}**, "
                      f"infeasible probability {_cell(summary[c]['infeasible_probability'])}" for c in CONTROLLERS)
    return (f"**{summary['samples']} samples in {summary['seconds']:.1f} s.** {probs}.\n\n" + head
            + "\n".join(rows) + "\n\n_worst = largest value (smallest for the saving)._")


def multiaxis_spec(result: MultiAxisResult) -> dict[str, Any]:
    """Axes' position and speed vs time as a plain-dict figure (see :func:`make_multiaxis_figure`)."""
    data: list[dict[str, Any]] = []
    errors = []
    for k, a in enumerate(result.axes):
        cmp = a.common.comparison
        run = cmp.fdsmc if cmp is not None else None
        if run is None:
            continue
        tr, th = run.trace, a.common.params.manoeuvre.theta_dem
        i = stride_index(len(tr.t), MAX_POINTS_TIME)
        colour = AXIS_COLOURS[k % len(AXIS_COLOURS)]
        for ax, y in (("", tr.theta_r[i] / th), ("2", tr.omega_r[i])):
            data.append({"type": "scatter", **time_axis(tr.t[i]), "y": f32(y), "mode": "lines",
                         "name": html.escape(a.name),
                         "legendgroup": a.name, "showlegend": ax == "", "line": {"color": colour, "width": 2},
                         "xaxis": f"x{ax}", "yaxis": f"y{ax}"})
        err = a.theta_error_at_Tm_rad
        errors.append(None if err is None else abs(err / th))
    band = TARGET_BAND["fdsmc"]
    grey = {"color": "#555", "width": 1.5, "dash": "dash"}
    shapes = [{"type": "line", "xref": "x", "yref": "paper", "x0": result.T_m, "x1": result.T_m, "y0": 0.0,
               "y1": 1.0, "line": grey},
              {"type": "rect", "xref": "paper", "yref": "y", "x0": 0.0, "x1": 1.0, "y0": 1.0 - band, "y1": 1.0 + band,
               "fillcolor": "rgba(47, 158, 68, 0.15)", "line": {"width": 0}}]
    return {"data": data, "layout": {
        "xaxis": {"anchor": "y", "showticklabels": False},
        "yaxis": {"domain": [0.54, 1.0], "title": {"text": "θ_r/θ_dem [-]"}},
        "xaxis2": {"anchor": "y2", "matches": "x", "title": {"text": "t [s]"}},
        "yaxis2": {"domain": [0.0, 0.46], "title": {"text": "ω_r [rad/s]"}},
        "shapes": shapes, "template": "plotly_white", "hovermode": "x unified",
        "meta": {"id": "multiaxis", "T_m": result.T_m, "band": band, "theta_error_frac_at_T_m": errors,
                 "names": [html.escape(a.name) for a in result.axes]},
        "title": {"text": f"Axes finishing together at T_m = {result.T_m:.4g} s (band ±{100 * band:g} % of θ_dem)",
                  "x": 0.01},
        "margin": {"l": 60, "r": 16, "t": 40, "b": 40}, "legend": {"orientation": "h", "y": -0.12},
        "font": {"size": FONT_PX}}}


def make_multiaxis_figure(result: MultiAxisResult) -> go.Figure:
    """θ_r/θ_dem and ω_r vs time of every axis at the common T_m (FDSMC), the arrival band and T_m.

    Parameters
    ----------
    result : sim.studies.multiaxis.MultiAxisResult

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return to_figure(multiaxis_spec(result))


def multiaxis_table_markdown(result: MultiAxisResult, text: Callable[[str], str] = str) -> str:
    """Return a Markdown table per axis: own shortest T_m, energies at it and at the common T_m, arrival.

    ``text`` makes the user's axis names safe to show (the page passes :func:`app.ui.text.md_text`).
    """
    rows = ["| axis | own shortest T_m [s] | W at own T_m [J] | W at common T_m [J] | θ error at T_m [rad] | arrived |",
            "|---|---|---|---|---|---|"]
    tot_own, tot_com = 0.0, 0.0
    for a in result.axes:
        own, com = a.energy("fastest"), a.energy("common")
        tot_own += own if own is not None else math.nan
        tot_com += com if com is not None else math.nan
        rows.append(f"| {text(a.name)} | {a.fastest.params.manoeuvre.T_m:.4g} | {_cell(own)} | {_cell(com)} | "
                    f"{_cell(a.theta_error_at_Tm_rad)} | {'yes' if a.arrived else '**no**'} |")
    rows.append(f"| **total** | | {_cell(tot_own)} | {_cell(tot_com)} | | |")
    return (f"**Common T_m = {result.T_m:.4g} s** (the longest of the axes' shortest feasible times, or the "
            "requested one). W = FDSMC net electrical input over the whole run.\n\n" + "\n".join(rows))


__all__ = ["AXIS_COLOURS", "PANELS", "histogram", "make_multiaxis_figure", "make_robustness_figure",
           "multiaxis_spec", "multiaxis_table_markdown", "robustness_spec", "robustness_table_markdown",
           "sample_values"]
