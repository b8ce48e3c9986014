"""The slow half of the chatter criterion: a sustained oscillation of α_dem below the smoothing band.

The chatter criterion of :mod:`sim.fdsmc.metrics` looks at α_dem less its 5 ms moving average: it
sees the switching of a too-high boundary-layer gain (hundreds of hertz) but not a limit cycle of
a few tens of hertz, which that average follows (at 11 Hz it passes ≈ 0.5 % of the swing, a few
per cent at the window's edges). Such a cycle is what a model inertia several times the true one
gives (J_r typed 10× too small on the Siemens 1FT7044 preset: α_dem swings by 2·α_max at
11–17 Hz, ω_r by 59 rad/s in the cruise window, yet no switching chatter), and a load inertia
several times the model's. So each window is also tested on r = α_dem less its least-squares
line in t (a ramp of the demand, as the tracked optimum's, leaves nothing): the loop oscillates
when r changes sign (beyond the same hysteresis) at least :data:`LIMIT_CYCLE_MIN_SIGN_CHANGES`
times — two whole periods — and still swings by more than the chatter threshold over the
window's second half (a decaying transient does not). One compiled function serves the single
runs and the batches alike.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Least hysteretic sign changes of the residual [-]: two periods within the window.
LIMIT_CYCLE_MIN_SIGN_CHANGES = 4


@njit(cache=True, nogil=True)
def limit_cycle_stats(a: np.ndarray, t: np.ndarray, hyst: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Residual statistics of each row of ``a`` [rad/s²] about its least-squares line in ``t`` [s].

    Parameters
    ----------
    a : numpy.ndarray
        Rows of α_dem sampled at ``t`` (one window) [rad/s²].
    t : numpy.ndarray
        Sample times [s].
    hyst : float
        Hysteresis of the sign changes [rad/s²].

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Per row: peak-to-peak of the residual over the window and over its second half [rad/s²],
        and the residual's sign changes counting only samples beyond ±``hyst`` [-].
    """
    rows, m = a.shape
    t_mean = 0.0
    for k in range(m):
        t_mean += t[k]
    t_mean /= m
    s_tt = 0.0
    for k in range(m):
        s_tt += (t[k] - t_mean) ** 2
    ptp, late, changes = np.zeros(rows), np.zeros(rows), np.zeros(rows, dtype=np.int64)
    for i in range(rows):
        ptp[i], late[i], changes[i] = _row_stats(a[i], t, t_mean, s_tt, hyst)
    return ptp, late, changes


@njit(cache=True, nogil=True)
def _row_stats(a: np.ndarray, t: np.ndarray, t_mean: float, s_tt: float, hyst: float) -> tuple[float, float, int]:
    """One row of :func:`limit_cycle_stats` (``t_mean`` [s], ``s_tt`` [s²]: the times' mean and spread)."""
    m = a.shape[0]
    a_mean, s_ta = 0.0, 0.0
    for k in range(m):
        a_mean += a[k]
    a_mean /= m
    for k in range(m):
        s_ta += (t[k] - t_mean) * (a[k] - a_mean)
    slope = s_ta / s_tt if s_tt > 0.0 else 0.0
    lo, hi, lo2, hi2, last, count = np.inf, -np.inf, np.inf, -np.inf, 0.0, 0
    for k in range(m):
        r = a[k] - a_mean - slope * (t[k] - t_mean)
        lo, hi = min(lo, r), max(hi, r)
        if 2 * k >= m:
            lo2, hi2 = min(lo2, r), max(hi2, r)
        if abs(r) > hyst:
            s = np.sign(r)
            count += 1 if last != 0.0 and s != last else 0
            last = s
    return hi - lo, hi2 - lo2, count


def limit_cycles(a: np.ndarray, t: np.ndarray, hyst: float,
                 ptp_min: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Whether each row of ``a`` [rad/s²] oscillates (module docstring), its residual's ptp and sign changes.

    ``ptp_min`` [rad/s²] is the least swing over the window's second half.
    """
    ptp, late, changes = limit_cycle_stats(np.ascontiguousarray(a, dtype=np.float64),
                                           np.ascontiguousarray(t, dtype=np.float64), hyst)
    return (changes >= LIMIT_CYCLE_MIN_SIGN_CHANGES) & (late > ptp_min), ptp, changes


__all__ = ["LIMIT_CYCLE_MIN_SIGN_CHANGES", "limit_cycle_stats", "limit_cycles"]
