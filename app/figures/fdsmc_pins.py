"""Pinned runs: an FDSMC run kept as a grey ghost in the overview, to compare before and after.

A lecturer pins the run shown, changes K, the load, the plant's J_L or the anti-windup, and sees
the new trajectory over the pinned one in the phase plane and in the ω_r row of the compact time
plot (:mod:`app.figures.fdsmc_overview`). A :class:`Pin` holds only what the ghost draws (a
decimated trajectory) and a label saying what was set, so pins are small, survive any later
case and go into the saved demo state as plain numbers.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.decimate import BINS_PHASE, f32, minmax_index

#: Most pins kept (the oldest goes first).
MAX_PINS = 4
#: Ghost colour and dashes, one per pin in order (grey; the dash tells pins apart). Dark enough to
#: stay ΔE ≥ 10 from the linear phase's reddish purple for deutan and protan viewers (≈ #656565 on
#: white: ΔE 17–19; the lighter grey of before, ≈ #929292, was 6.5).
GHOST_COLOUR = "rgba(80, 80, 80, 0.85)"
GHOST_DASHES = ("dot", "dash", "dashdot", "longdash")


@dataclass(frozen=True)
class Pin:
    """A pinned FDSMC run: what was set, and its trajectory.

    Attributes
    ----------
    label : str
        What was set, e.g. ``"K = 1000 s/rad, T_m = 1 s, J_L plant = 0.1 kg·m²"``.
    t : tuple of float
        Sample times [s].
    theta_re : tuple of float
        Position error θ_r − θ_dem [rad] at ``t``.
    omega_r : tuple of float
        Rotor speed [rad/s] at ``t``.
    """

    label: str
    t: tuple[float, ...]
    theta_re: tuple[float, ...]
    omega_r: tuple[float, ...]


def pin_label(params: Any, plant_J_L: float | None = None) -> str:
    """Say what a run was set to: K, T_c rule or value, T_m, the plant's J_L (and the model's if different)."""
    c, J_L = params.controller, params.load.J_L
    T_c = "T_a" if c.T_c == "T_a" else f"{float(c.T_c) * 1e3:.3g} ms"
    plant = "" if plant_J_L is None else f" (model {J_L:.3g})"
    return (f"K = {c.K:.4g} s/rad, T_c = {T_c}, T_m = {params.manoeuvre.T_m:.4g} s, "
            f"J_L plant = {J_L if plant_J_L is None else plant_J_L:.3g} kg·m²{plant}, "
            f"{len(params.load.steps)} load step(s)")


def pin_of(comparison: Any, plant_J_L: float | None = None) -> Pin | None:
    """Return a pin of ``comparison``'s FDSMC run (None when nothing was simulated)."""
    run = comparison.fdsmc
    if run is None:
        return None
    tr, params = run.trace, comparison.derived.params
    i = minmax_index(tr.omega_r, BINS_PHASE)  # a chattering ω_r stays a band
    th = params.manoeuvre.theta_dem

    def rounded(a: np.ndarray) -> tuple[float, ...]:
        return tuple(float(v) for v in np.asarray(a, dtype=np.float32))
    return Pin(pin_label(params, plant_J_L), rounded(tr.t[i]), rounded(tr.theta_r[i] - th), rounded(tr.omega_r[i]))


def pinned(pins: tuple[Pin, ...], pin: Pin) -> tuple[Pin, ...]:
    """Return ``pins`` with ``pin`` added last, keeping at most :data:`MAX_PINS` (the oldest dropped)."""
    return (*pins, pin)[-MAX_PINS:]


def _plain(label: str) -> str:
    """``label`` without the characters Plotly's hover template would read as markup or fields."""
    return re.sub(r"[<>{}%&]", "", label)


def ghost_traces(pins: tuple[Pin, ...], time_row: bool = True) -> list[dict[str, Any]]:
    """Grey ghost traces of ``pins``: trajectory in the phase plane, and ω_r(t) in the time plot's top row.

    Named ``"pin <n> …"`` (never "now" or "time cursor": a replay does not move them), out of the legend.
    """
    out: list[dict[str, Any]] = []
    for n, pin in enumerate(pins, start=1):
        line = {"color": GHOST_COLOUR, "width": 2.5, "dash": GHOST_DASHES[(n - 1) % len(GHOST_DASHES)]}
        ghost = {"type": "scatter", "mode": "lines", "showlegend": False, "line": line,
                 "hovertemplate": f"pin {n}: {_plain(pin.label)}<extra></extra>"}
        out.append({**ghost, "x": f32(pin.theta_re), "y": f32(pin.omega_r), "name": f"pin {n} trajectory"})
        if time_row:
            out.append({**ghost, "x": f32(pin.t), "y": f32(pin.omega_r), "name": f"pin {n} ω_r",
                        "xaxis": "x2", "yaxis": "y2"})
    return out


def pins_note(pins: tuple[Pin, ...]) -> str:
    """One line per pin for under the figure: its number, dash and label (plain text)."""
    return "\n".join(f"pin {n} ({GHOST_DASHES[(n - 1) % len(GHOST_DASHES)]}, grey): {pin.label}"
                     for n, pin in enumerate(pins, start=1))


__all__ = ["GHOST_COLOUR", "MAX_PINS", "Pin", "ghost_traces", "pin_label", "pin_of", "pinned", "pins_note"]
