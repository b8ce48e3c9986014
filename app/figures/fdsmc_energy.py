"""Pure Plotly figures of the energy comparison and the Table-1 sweep.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import plotly.graph_objects as go

from pmsm_commissioning.app.figures.decimate import f32, time_axis
from pmsm_commissioning.app.figures.fdsmc_comparison import COLOURS, MAX_POINTS_TIME, runs, stride_index
from pmsm_commissioning.app.figures.style import BAD_COLOUR, GOOD_COLOUR
from pmsm_commissioning.sim.fdsmc.engine import LABELS, Comparison, RunResult
from pmsm_commissioning.sim.fdsmc.optimum_gap import saving_vs_optimum, supply_saving_vs_optimum
from pmsm_commissioning.sim.fdsmc.recommend import run_supply_J
from pmsm_commissioning.sim.fdsmc.table1 import Table1Row, printed_reversed

#: Energy kinds: (trace attribute, metric key of the horizon total, label, dash).
ENERGIES = (
    ("E_friction", "friction_total_J", "friction", "solid"),
    ("E_copper", "copper_total_J", "copper", "dot"),
    ("E_electrical", "electrical_in_total_J", "electrical input", "dash"),
)


def _styled(fig: go.Figure, fid: str, title: str, legend_y: float, **layout: Any) -> go.Figure:
    """Return the common layout of the energy figures: id in ``meta``, title, margins, legend below."""
    fig.update_layout(_layout(fid, title, legend_y, **layout))
    return fig


def _layout(fid: str, title: str, legend_y: float, **layout: Any) -> dict[str, Any]:
    return {"meta": {"id": fid}, "template": "plotly_white", "title": {"text": title, "x": 0.01},
            "margin": {"l": 60, "r": 16, "t": 40, "b": 40}, "legend": {"orientation": "h", "y": legend_y},
            **layout}


def energy_spec(comparison: Comparison) -> dict[str, Any]:
    """Cumulative energies as a plain-dict figure (see :func:`make_energy_figure`)."""
    data = []
    for key, run in runs(comparison):
        tr = run.trace
        i = stride_index(len(tr.t), MAX_POINTS_TIME)
        t = time_axis(tr.t[i])
        for attr, _, label, dash in ENERGIES:
            data.append({"type": "scatter", **t, "y": f32(getattr(tr, attr)[i]), "mode": "lines",
                         "name": f"{LABELS[key]} {label}", "legendgroup": key,
                         "line": {"color": COLOURS[key], "dash": dash, "width": 2}})
    return {"data": data, "layout": _layout("energy_time", "Energy vs time", -0.18,
                                            xaxis={"title": {"text": "t [s]"}},
                                            yaxis={"title": {"text": "energy [J]"}})}


def energy_bars_spec(comparison: Comparison) -> dict[str, Any]:
    """Energy totals as a plain-dict figure (see :func:`make_energy_bars_figure`)."""
    c = comparison.derived.params.controller
    kinds = [label for _, _, label, _ in ENERGIES] + [f"from the supply ({c.dc_link.replace('_', ' ')})"]
    data = []
    for key, run in runs(comparison):
        supply = run_supply_J(run, c)
        totals = [energy_total(run, attr, metric) for attr, metric, _, _ in ENERGIES] + [
            float("nan") if supply is None else supply]
        data.append({"type": "bar", "x": kinds, "y": totals, "name": LABELS[key], "marker": {"color": COLOURS[key]},
                     "text": [f"{v:.4g} J" for v in totals], "textposition": "outside"})
    title = (f"Totals — FDSMC saves {_pct(comparison.saving_friction_pct)} friction, "
             f"{_pct(comparison.saving_electrical_pct)} electrical input")
    gaps = optimum_gaps(comparison)
    supply_gaps = optimum_gaps(comparison, supply=True)
    extra: dict[str, Any] = {}
    if gaps:
        title += ("<br>the optimum would save " + ", ".join(f"{_pct(v)} of {LABELS[k]}'s" for k, v in gaps.items())
                  + " electrical input")
        extra["margin"] = {"l": 60, "r": 16, "t": 64, "b": 40}
    return {"data": data, "layout": _layout("energy_bars", title, -0.15, barmode="group",
                                            yaxis={"title": {"text": "energy [J]"}},
                                            meta={"id": "energy_bars", "gap_to_optimum_pct": gaps,
                                                  "gap_to_optimum_supply_pct": supply_gaps}, **extra)}


def optimum_gaps(comparison: Any, supply: bool = False) -> dict[str, float | None]:
    """Return, per controller, the share of its net electrical input [%] the optimum would save.

    See (:func:`sim.fdsmc.optimum_gap.saving_vs_optimum`); with ``supply`` the share of the energy the
    supply delivers under the DC-link choice (:func:`~sim.fdsmc.optimum_gap.supply_saving_vs_optimum`).
    Empty without an optimum run.
    """
    if getattr(comparison, "optimum", None) is None:
        return {}
    c = comparison.derived.params.controller
    return {key: supply_saving_vs_optimum(run, comparison.optimum, c) if supply else
            saving_vs_optimum(run, comparison.optimum) for key, run in runs(comparison) if key != "optimum"}


def make_energy_figure(comparison: Comparison) -> go.Figure:
    """Cumulative friction, copper and electrical input energy [J] vs time for both controllers.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return go.Figure(energy_spec(comparison))


def energy_total(run: RunResult, attr: str, metric: str) -> float:
    """Return the total of one energy kind over the horizon [J].

    That is the metric ``metric`` (a :class:`~sim.fdsmc.metrics.RunMetrics` field) if the run has
    it, else the end of the trace's channel ``attr``.
    """
    value = getattr(run.metrics, metric)
    return float(getattr(run.trace, attr)[-1]) if value is None else float(value)


def _pct(value: float | None) -> str:
    return "–" if value is None else f"{value:.1f} %"


def make_energy_bars_figure(comparison: Comparison) -> go.Figure:
    """Bar chart of the energy totals [J] per controller, titled with the savings [%].

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
        ``saving_friction_pct`` and ``saving_electrical_pct`` [%] may be None.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    return go.Figure(energy_bars_spec(comparison))


def make_table1_figure(rows: Sequence[Table1Row], paper: Mapping[float, float] | None = None) -> go.Figure:
    """Friction saving [%] vs manoeuvre time T_m [s]: simulation, eq. (52), bound (53), paper's Table 1.

    Parameters
    ----------
    rows : sequence of sim.fdsmc.table1.Table1Row
        ``T_m`` [s], ``saving_pct``, ``saving_eq52_pct``, ``bound_pct``, ``paper_pct`` [%] (None allowed).
    paper : mapping T_m [s] → saving [%], optional
        The paper's Table 1 values; drawn in full when given.

    Returns
    -------
    plotly.graph_objects.Figure
    """
    fig = go.Figure()
    t_m = [r.T_m for r in rows]
    series = (
        ("saving_pct", "simulated (FDSMC vs conventional)", COLOURS["fdsmc"], "lines+markers"),
        ("saving_eq52_pct", "predicted, eqs. (52), (61)", GOOD_COLOUR, "lines"),
        ("bound_pct", "bound 1 − 4/5.6, eq. (53)", "#555555", "lines"),
    )
    for attr, name, colour, mode in series:
        fig.add_scatter(x=t_m, y=[getattr(r, attr) for r in rows], mode=mode, name=name,
                        line={"color": colour, "dash": "dash" if attr == "bound_pct" else "solid"})
    if paper:
        xs = sorted(paper)
        fig.add_scatter(x=xs, y=[paper[x] for x in xs], mode="markers", name="paper, Table 1 as printed",
                        marker={"symbol": "x", "size": 11, "color": BAD_COLOUR})
        back = printed_reversed(dict(paper))
        fig.add_scatter(x=xs, y=[back[x] for x in xs], mode="markers", name="paper, columns reversed (erratum)",
                        marker={"symbol": "circle-open", "size": 13, "color": BAD_COLOUR, "line": {"width": 2}})
    return _styled(fig, "table1", "Friction saving vs manoeuvre time (Table 1)", -0.2,
                   xaxis_title="T_m [s]", yaxis_title="saving [%]")


__all__ = ["ENERGIES", "energy_bars_spec", "energy_spec", "energy_total", "make_energy_bars_figure",
           "make_energy_figure",
           "make_table1_figure", "optimum_gaps"]
