"""The stock route's figure: what a stock drive running its own loops does with the move.

Three rows on one time axis, from the ``stock`` run of a comparison (a setpoint-table drive's P–PI
cascade, PLL and current PI, tuned on the simulated checks: :mod:`sim.stock.tuning`), the FDSMC's
run beside it where there is one:

* ω_r [rad/s];
* i_q [A] with the drive's current limit ±i_lim;
* the position error θ_r − θ_dem [rad] at the scale of the in-position window (shaded), where the
  verdict is decided.

The title carries the route's verdict and the time the axis is in position.
"""

from __future__ import annotations

from typing import Any

from pmsm_commissioning.app.figures.decimate import f32, time_axis
from pmsm_commissioning.app.figures.fdsmc_comparison import MAX_POINTS_TIME, stride_index
from pmsm_commissioning.app.figures.style import BAD_COLOUR, GOOD_COLOUR, POSITION_COLOURS, POSITION_DASHES, fmt
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.criteria import drive_current, pass_criteria
from pmsm_commissioning.sim.fdsmc.engine import Comparison, RunResult

#: Half-height of the error row, in in-position windows [-].
ERROR_ROW_WINDOWS = 12.0
#: The rows' vertical domains (top to bottom).
ROWS = ((0.70, 1.0), (0.37, 0.63), (0.0, 0.30))


def _traces(key: str, run: RunResult, label: str, theta_dem: float) -> list[dict[str, Any]]:
    tr = run.trace
    i = stride_index(len(tr.t), MAX_POINTS_TIME)
    t = time_axis(tr.t[i])
    style = {"mode": "lines", "legendgroup": key,
             "line": {"color": POSITION_COLOURS[key], "dash": POSITION_DASHES[key], "width": 2}}
    return [{"type": "scatter", **t, "y": f32(tr.omega_r[i]), "name": label, "yaxis": "y", **style},
            {"type": "scatter", **t, "y": f32(tr.i_q[i]), "showlegend": False, "yaxis": "y2", **style},
            {"type": "scatter", **t, "y": f32(tr.theta_r[i] - theta_dem), "showlegend": False, "yaxis": "y3",
             **style}]


def stock_title(comparison: Comparison) -> tuple[str, bool]:
    """Return the figure's title (verdict, in-position time) and whether the route is clean."""
    run = comparison.stock
    if run is None:
        return "Stock route: not simulated", False
    failed = [c for c in run_checks(comparison.derived.params, run) if c.violated]
    when = run.metrics.in_position_s
    settled = "never in position" if when is None else f"in position at {fmt(when, 's')}"
    word = "CLEAN" if not failed else "NOT CLEAN: " + ", ".join(c.name for c in failed)
    return f"Stock route (setpoint-table drive, its own loops): {word} — {settled}", not failed


def stock_route_spec(comparison: Comparison) -> dict[str, Any]:
    """Return the stock route's figure as a plain dict (see the module doc); only the FDSMC without a stock run."""
    p = comparison.derived.params
    title, clean = stock_title(comparison)
    data: list[dict[str, Any]] = []
    for key, label in (("fdsmc", "FDSMC"), ("stock", "stock drive")):
        run = getattr(comparison, key)
        if run is not None:
            data += _traces(key, run, label, p.manoeuvre.theta_dem)
    window, i_lim = pass_criteria(p).in_position, drive_current(p)
    half = ERROR_ROW_WINDOWS * window
    shapes = [{"type": "rect", "xref": "paper", "x0": 0, "x1": 1, "yref": "y3", "y0": -window, "y1": window,
               "fillcolor": GOOD_COLOUR, "opacity": 0.15, "line": {"width": 0}}]
    shapes += [{"type": "line", "xref": "paper", "x0": 0, "x1": 1, "yref": "y2", "y0": s * i_lim, "y1": s * i_lim,
                "line": {"color": BAD_COLOUR, "dash": "dash", "width": 1}} for s in (-1.0, 1.0)]
    axes = {f"yaxis{n if n > 1 else ''}": {"domain": list(d), "title": {"text": text}, **extra}
            for n, (d, text, extra) in enumerate(((ROWS[0], "ω_r [rad/s]", {}), (ROWS[1], "i_q [A]", {}),
                                                  (ROWS[2], "θ_r − θ_dem [rad]", {"range": [-half, half]})), 1)}
    return {"data": data, "layout": {
        "meta": {"id": "stock_route", "clean": clean, "in_position_window_rad": window},
        "template": "plotly_white", "title": {"text": title, "x": 0.01, "font": {"color": GOOD_COLOUR if clean
                                                                                 else BAD_COLOUR}},
        "margin": {"l": 70, "r": 16, "t": 44, "b": 40}, "legend": {"orientation": "h", "y": -0.12},
        "xaxis": {"title": {"text": "t [s]"}, "anchor": "y3"}, "shapes": shapes, **axes}}
