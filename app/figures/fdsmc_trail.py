"""The replay's trail: each trajectory in short pieces that appear as the replay passes them.

A replay draws the phase-plane trajectories progressively: each run's decimated trajectory is cut
into about :data:`N_PIECES` pieces in time (a :class:`Piece` each, one Plotly trace), and a
replay's key frame shows the pieces it has passed (:mod:`app.figures.fdsmc_replay`); the first
frame empties them all. The FDSMC's pieces are also cut where its phase changes
(:func:`phase_of`) and coloured by phase, so the trail teaches the three phases of [1]:

* **reaching** — before the first entry into the boundary layer |ω_r − ω_b(θ_re)| ≤ 1/K
  (eqs. (41), (45));
* **sliding** — after it, on the constant-speed segment of the boundary (|θ_re| > T_c·ω_p);
* **linear** — after it, on the sloped segment ω_b = −θ_re/T_c: the linear, exponential approach
  to θ_dem.

The conventional law and the tracked optimum have no boundary layer: one phase, their own colour.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.app.figures.decimate import f32, minmax_index
from pmsm_commissioning.app.figures.fdsmc_comparison import runs
from pmsm_commissioning.app.figures.style import (
    POSITION_COLOURS,
    POSITION_DASHES,
    TRAIL_PHASE_COLOURS,
    TRAIL_PHASE_DASHES,
)
from pmsm_commissioning.control.fdsmc.sliding_mode import in_boundary_layer
from pmsm_commissioning.sim.fdsmc.engine import LABELS

#: Pieces per trajectory in time (more where the FDSMC changes phase), and min/max bins of the
#: trail's points (each key frame of each replay speed carries them once).
N_PIECES, BINS_TRAIL = 40, 250
#: The FDSMC's phases in order, with their legend names, colours and dashes (:mod:`app.figures.style`).
PHASES = ("reaching", "sliding", "linear")
PHASE_STYLE = dict(zip(PHASES, zip(("FDSMC reaching", "FDSMC sliding (ω_p)", "FDSMC linear (−θ_re/T_c)"),
                                   TRAIL_PHASE_COLOURS, TRAIL_PHASE_DASHES,
                                   strict=True), strict=True))


@dataclass(frozen=True)
class Piece:
    """One piece of a trajectory: run key, phase ("" without phases), end time [s] and its points."""

    key: str
    phase: str
    t_end: float
    theta_re: np.ndarray
    omega_r: np.ndarray


def phase_of(theta_re: np.ndarray, omega_r: np.ndarray, omega_p: float, T_c: float, K: float) -> np.ndarray:
    """Phase index per sample (0 reaching, 1 sliding, 2 linear; see the module's text).

    Parameters
    ----------
    theta_re : ndarray  Position error θ_r − θ_dem [rad].
    omega_r : ndarray   Rotor speed [rad/s].
    omega_p : float     Peak speed of the boundary, eq. (41) [rad/s].
    T_c : float         Slope time constant [s].
    K : float           Boundary-layer gain [s/rad]: the layer is ±1/K [rad/s] wide.
    """
    theta_re = np.asarray(theta_re, dtype=float)
    entered = np.cumsum(in_boundary_layer(theta_re, omega_r, omega_p, T_c, K)) > 0
    linear = np.abs(theta_re) <= T_c * omega_p
    return np.where(~entered, 0, np.where(linear, 2, 1))


def _cuts(t: np.ndarray, phase: np.ndarray, n: int) -> list[int]:
    """Sample indices where pieces start: every 1/n of the run's time, and at each phase change."""
    grid = np.searchsorted(t, np.linspace(t[0], t[-1], n + 1)[1:-1])
    changes = np.flatnonzero(np.diff(phase)) + 1
    return sorted({0, *grid.tolist(), *changes.tolist()} - {len(t)})


def pieces(comparison: Any, n: int = N_PIECES) -> list[Piece]:
    """Cut each run's decimated trajectory into pieces (each holds the first point of the next: no gaps)."""
    d = comparison.derived
    prof, th = d.profile, d.params.manoeuvre.theta_dem
    out: list[Piece] = []
    for key, run in runs(comparison):
        tr = run.trace
        i = minmax_index(tr.omega_r, BINS_TRAIL)
        t, x, y = tr.t[i], tr.theta_r[i] - th, tr.omega_r[i]
        # classified at full resolution: a chattering run's bin extremes all lie outside a thin layer
        phase = (phase_of(tr.theta_r - th, tr.omega_r, prof.omega_p, prof.T_c, d.params.controller.K)[i]
                 if key == "fdsmc" else np.zeros(len(t), dtype=int))
        starts = _cuts(t, phase, n)
        for a, b in zip(starts, [*starts[1:], len(t) - 1], strict=True):
            name = PHASES[int(phase[a])] if key == "fdsmc" else ""
            out.append(Piece(key, name, float(t[b]), x[a:b + 1], y[a:b + 1]))
    return out


def piece_traces(parts: list[Piece]) -> list[dict[str, Any]]:
    """One trace per piece (``meta.trail`` = its end time [s]); the first of each kind names the legend entry.

    The first piece of a kind is named by its legend text (e.g. ``"FDSMC sliding (ω_p)"``),
    the others ``"<run> <phase> trail"``.
    """
    out, seen = [], set()
    for p in parts:
        if p.key == "fdsmc":
            legend, colour, dash = PHASE_STYLE[p.phase]
        else:
            legend, colour, dash = LABELS[p.key], POSITION_COLOURS[p.key], POSITION_DASHES[p.key]
        first = (p.key, p.phase) not in seen
        seen.add((p.key, p.phase))
        out.append({"type": "scatter", "mode": "lines", "x": f32(p.theta_re), "y": f32(p.omega_r),
                    "name": legend if first else " ".join(filter(None, (LABELS[p.key], p.phase, "trail"))),
                    "legendgroup": legend, "showlegend": first, "hoverinfo": "skip", "meta": {"trail": p.t_end},
                    "line": {"color": colour, "width": 3 if p.key == "fdsmc" else 2.2, "dash": dash}})
    return out


__all__ = ["N_PIECES", "PHASES", "PHASE_STYLE", "Piece", "phase_of", "piece_traces", "pieces"]
