"""Min/max decimation: draw no more points than a plot can show, and keep chatter visible as a band.

A comparison holds ~10⁴ samples per signal; a plot is ~10³ pixels wide. Taking every k-th sample
(a stride) would alias a chattering signal (an α_dem or i_q switching every few samples) into a
thin random line, or hide it. Here the samples are cut into ``n_bins`` consecutive bins and each
bin keeps its smallest and its largest value, in the order they occur: the drawn line then spans
exactly the band the signal covers in each bin (what the eye sees at one bin per pixel). The first
and the last sample are always kept, so the drawn endpoints are the run's.

Full resolution stays in the :class:`sim.fdsmc.engine.Comparison` (exports use it); this is for
drawing only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: Bins (two points each) of the page's figures: about one per pixel of the plot's drawing width.
BINS_TIME_PLOTS, BINS_OVERVIEW_ROWS, BINS_PHASE = 400, 300, 500


def f32(a: np.ndarray) -> np.ndarray:
    """Return ``a`` as float32: halves the figure JSON (base64 typed arrays) at ample drawing precision."""
    return np.asarray(a, dtype=np.float32)


def time_axis(t: np.ndarray) -> dict[str, Any]:
    """Trace keys for the time axis: ``x0``/``dx`` if ``t`` [s] is uniform (half the bytes), else ``x``."""
    if len(t) > 2:
        dt = np.diff(t)
        if np.ptp(dt) <= 1e-6 * abs(float(dt.mean())):
            return {"x0": float(t[0]), "dx": float(t[-1] - t[0]) / (len(t) - 1)}
    return {"x": f32(t)}


def _bin_extremes(y: np.ndarray, n_bins: int) -> np.ndarray:
    """Return the indices (m, 2) of each bin's min and max of ``y``, the earlier one first.

    Bins hold ``k = ceil(n / n_bins)`` samples each (the last one fewer), so ``m = ceil(n / k) ≤ n_bins``.
    """
    n = len(y)
    k = -(-n // n_bins)
    n_bins = -(-n // k)
    pad = k * n_bins - n
    yy = np.concatenate([y, np.full(pad, y[-1])]) if pad else y
    yy = yy.reshape(n_bins, k)
    base = np.arange(n_bins) * k
    lo, hi = base + np.argmin(yy, axis=1), base + np.argmax(yy, axis=1)
    pair = np.sort(np.stack([lo, hi], axis=1), axis=1)
    return np.minimum(pair, n - 1)


def minmax_index(y: np.ndarray, n_bins: int) -> np.ndarray:
    """Sorted sample indices: the first, the last, and each bin's min and max of ``y``.

    Parameters
    ----------
    y : numpy.ndarray
        The signal whose band is kept (for a phase-plane curve, the chattering coordinate ω_r).
    n_bins : int
        Number of bins (≥ 1); at most ``2 n_bins + 2`` indices are returned.

    Returns
    -------
    numpy.ndarray
        Strictly increasing indices into ``y`` (all of them if ``len(y) <= 2 n_bins + 2``).
    """
    n = len(y)
    if n <= 2 * n_bins + 2:
        return np.arange(n)
    idx = np.concatenate([[0], _bin_extremes(np.asarray(y), n_bins).ravel(), [n - 1]])
    return np.unique(idx)


def envelope(t: np.ndarray, y: np.ndarray, n_bins: int) -> tuple[dict[str, Any], np.ndarray]:
    """Min/max envelope of ``y(t)`` on a uniform time grid (``x0``/``dx``, no x array to send).

    The output holds ``y[0]`` at ``t[0]``, then each bin's two extremes (in the order they occur) on
    the next two grid points, then ``y[-1]`` at ``t[-1]``: at most ``2 n_bins + 2`` points, evenly
    spaced from ``t[0]`` to ``t[-1]``. The values are the run's samples; their times move by
    less than one bin (≈ one pixel), the price of a uniform grid that halves the bytes.

    Parameters
    ----------
    t : numpy.ndarray
        Sample times [s], increasing.
    y : numpy.ndarray
        Samples (any unit).
    n_bins : int
        Number of bins (≥ 1).

    Returns
    -------
    (dict, numpy.ndarray)
        Trace keys of the time axis (``x0``/``dx`` or ``x`` if not decimated) and the drawn values.
    """
    n = len(y)
    if n <= 2 * n_bins + 2:
        return time_axis(t), np.asarray(y)
    y = np.asarray(y)
    inner = y[_bin_extremes(y, n_bins).ravel()]
    out = np.concatenate([y[:1], inner, y[-1:]])
    t0, t1 = float(t[0]), float(t[-1])
    return {"x0": t0, "dx": (t1 - t0) / (len(out) - 1)}, out


__all__ = ["BINS_OVERVIEW_ROWS", "BINS_PHASE", "BINS_TIME_PLOTS", "envelope", "f32", "minmax_index", "time_axis"]
