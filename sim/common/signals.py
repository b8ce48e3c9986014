"""Shared post-processing of simulated time series: response metrics.

Used by both modes (FDSMC position control and BLDC speed control) so that metrics are computed
one way only (energies are integrated as extra states of each kernel). All inputs are numpy
arrays in SI units on a common time grid ``t``.
"""

from __future__ import annotations

import numpy as np


def first_entry_time(t: np.ndarray, y: np.ndarray, target: float, band: float) -> float | None:
    """First time |y − target| ≤ band [s], or None if never.

    Parameters
    ----------
    t : numpy.ndarray  Time [s].
    y : numpy.ndarray  Signal.
    target : float     Final value.
    band : float       Half-width of the band (same unit as y).
    """
    inside = np.abs(y - target) <= band
    idx = np.flatnonzero(inside)
    return float(t[idx[0]]) if idx.size else None


def settling_time(t: np.ndarray, y: np.ndarray, target: float, band: float) -> float | None:
    """Time after which |y − target| ≤ band for the rest of the record [s], or None.

    None also when the signal is outside the band at the end of the record.
    """
    outside = np.abs(y - target) > band
    if outside[-1]:
        return None
    idx = np.flatnonzero(outside)
    return float(t[0]) if idx.size == 0 else float(t[min(idx[-1] + 1, t.size - 1)])


def overshoot(y: np.ndarray, start: float, target: float) -> float:
    """Largest excursion beyond ``target`` in the direction of travel from ``start`` (≥ 0)."""
    direction = 1.0 if target >= start else -1.0
    return max(0.0, float(np.max(direction * (y - target))))


def peak_abs(y: np.ndarray) -> float:
    """Return max |y| (0 for an empty array)."""
    return float(np.max(np.abs(y))) if y.size else 0.0


def ripple_pct(y: np.ndarray) -> float:
    """Peak-to-peak ripple relative to the mean magnitude, 100·(max − min)/|mean| [%]."""
    mean = float(np.mean(y))
    if mean == 0.0:
        return float("inf")
    return 100.0 * float(np.ptp(y)) / abs(mean)


def is_finite_and_bounded(*arrays: np.ndarray, limit: float = 1e9) -> bool:
    """Return True when every array is finite and within ±limit (a run that did not diverge)."""
    return all(np.all(np.isfinite(a)) and np.all(np.abs(a) < limit) for a in arrays)
