"""Pure Plotly figure of a measured drive log overlaid on the simulated run."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from pmsm_commissioning.app.figures.decimate import f32
from pmsm_commissioning.app.figures.fdsmc_comparison import decimate_index
from pmsm_commissioning.sim.drivelog.overlay import Overlay

MEASURED, SIMULATED = "#2b2b2b", "#1f6fd1"
#: Panels: (row, col, signals, y title).
PANELS = (
    (1, 1, ("theta_r",), "θ_r [rad]"),
    (1, 2, ("omega_r",), "ω_r [rad/s]"),
    (2, 1, ("i_q", "i_d"), "i_q, i_d [A]"),
    (2, 2, ("u_q", "u_d"), "u_q, u_d [V]"),
)


def cumulative_input_energy(t: np.ndarray, s: dict[str, np.ndarray]) -> np.ndarray | None:
    """∫ 3/2·(u_d·i_d + u_q·i_q) dt from t[0] [J], voltage held over each interval (as the overlay)."""
    if not {"u_d", "u_q", "i_d", "i_q"} <= set(s) or t.size < 2:
        return None
    i_d, i_q = 0.5 * (s["i_d"][1:] + s["i_d"][:-1]), 0.5 * (s["i_q"][1:] + s["i_q"][:-1])
    p = 1.5 * (s["u_d"][:-1] * i_d + s["u_q"][:-1] * i_q)
    return np.concatenate([[0.0], np.cumsum(p * np.diff(t))])


def _line(fig: go.Figure, x: np.ndarray, y: np.ndarray, name: str, colour: str, dash: str, row: int, col: int,
          show: bool) -> None:
    idx = decimate_index(x.size)
    fig.add_trace(go.Scatter(x=f32(x[idx]), y=f32(y[idx]), name=name, legendgroup=name, showlegend=show,
                             line={"color": colour, "dash": dash, "width": 1.4}, mode="lines"), row=row, col=col)


def make_log_overlay_figure(ov: Overlay, log_name: str = "log") -> go.Figure:
    """Measured (black) and simulated (blue, dashed) time plots, phase plane and input energy.

    Parameters
    ----------
    ov : sim.drivelog.overlay.Overlay
    log_name : str  Shown in the title.

    Returns
    -------
    plotly.graph_objects.Figure  ``layout.meta.id == "log-overlay"``.
    """
    fig = make_subplots(rows=3, cols=2, vertical_spacing=0.09, horizontal_spacing=0.1,
                        subplot_titles=("position", "speed", "currents (i_d dotted)", "voltages (u_d dotted)",
                                        "phase plane ω_r over θ_r", "electrical input energy"))
    first = True
    for row, col, names, title in PANELS:
        for j, name in enumerate(names):
            if name not in ov.measured:
                continue
            dash_m, dash_s = ("solid", "dash") if j == 0 else ("dot", "dashdot")
            _line(fig, ov.t, ov.measured[name], "measured", MEASURED, dash_m, row, col, first)
            _line(fig, ov.t, ov.simulated[name], "simulated", SIMULATED, dash_s, row, col, first)
            first = False
        fig.update_yaxes(title_text=title, row=row, col=col)
    if {"theta_r", "omega_r"} <= set(ov.measured):
        for src, colour, dash in ((ov.measured, MEASURED, "solid"), (ov.simulated, SIMULATED, "dash")):
            _line(fig, src["theta_r"], src["omega_r"], "measured" if src is ov.measured else "simulated",
                  colour, dash, 3, 1, False)
        fig.update_xaxes(title_text="θ_r [rad]", row=3, col=1)
        fig.update_yaxes(title_text="ω_r [rad/s]", row=3, col=1)
    for src, colour, dash in ((ov.measured, MEASURED, "solid"), (ov.simulated, SIMULATED, "dash")):
        e = cumulative_input_energy(ov.t, src)
        if e is not None:
            _line(fig, ov.t, e, "measured" if src is ov.measured else "simulated", colour, dash, 3, 2, False)
    fig.update_yaxes(title_text="E [J]", row=3, col=2)
    for row, col in ((2, 1), (2, 2), (3, 2)):
        fig.update_xaxes(title_text="t − t0 [s]", row=row, col=col)
    fig.update_layout(meta={"id": "log-overlay"}, template="plotly_white", height=760,
                      title={"text": f"{log_name}: measured vs simulated (t0 = {ov.t0:.4g} s)", "x": 0.01},
                      margin={"l": 60, "r": 16, "t": 60, "b": 40}, legend={"orientation": "h", "y": -0.06})
    return fig
