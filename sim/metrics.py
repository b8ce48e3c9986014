"""Run metrics of one closed-loop simulation: energies, response figures, chatter detection.

Chatter criterion (documented in ``docs/paper_reproduction.md``): inside the evaluation window
(the middle 60 % of the planned cruise segment for the FDSMC, [0.2·T_m, T_m] for the
conventional law) take the high-pass part r = α_dem − (moving average of α_dem over 5 ms). The
loop chatters when r swings by more than 20 % of α_max peak-to-peak **and** r changes sign (with
a hysteresis of 2.5 % of α_max) at least 8 times, i.e. a sustained oscillation of the demanded
acceleration at ≥ 100 Hz-scale frequencies with an amplitude comparable to the control range —
the limit cycle of a too-high boundary-layer gain K — not a single transient.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim import signals

#: Thresholds of the chatter criterion (fractions of α_max) and the smoothing window [s].
CHATTER_PTP_FRACTION = 0.2
CHATTER_HYSTERESIS_FRACTION = 0.025
CHATTER_MIN_SIGN_CHANGES = 8
CHATTER_SMOOTHING_S = 0.005


@dataclass(frozen=True)
class ChatterVerdict:
    """Result of the chatter test.

    Attributes
    ----------
    chatter : bool              Whether the criterion is met.
    ptp : float                 Peak-to-peak of the high-pass α_dem in the window [rad/s²].
    sign_changes : int          Hysteretic sign changes of the high-pass α_dem [-].
    frequency_Hz : float        Estimated oscillation frequency sign_changes/(2·window) [Hz].
    omega_ptp : float           Peak-to-peak of ω_r in the window [rad/s].
    window : tuple of float     Evaluation window (t0, t1) [s].
    """

    chatter: bool
    ptp: float
    sign_changes: int
    frequency_Hz: float
    omega_ptp: float
    window: tuple[float, float]


def hysteretic_sign_changes(r: np.ndarray, hyst: float) -> int:
    """Number of sign changes of ``r`` counting only swings beyond ±``hyst``."""
    state, count = 0, 0
    for v in r:
        s = 1 if v > hyst else (-1 if v < -hyst else 0)
        if s != 0 and s != state:
            if state != 0:
                count += 1
            state = s
    return count


def detect_chatter(
    t: np.ndarray, alpha_dem: np.ndarray, omega_r: np.ndarray, window: tuple[float, float],
    alpha_max: float,
) -> ChatterVerdict:
    """Apply the chatter criterion of this module's docstring.

    Parameters
    ----------
    t : numpy.ndarray          Time [s].
    alpha_dem : numpy.ndarray  Demanded acceleration [rad/s²].
    omega_r : numpy.ndarray    Rotor speed [rad/s].
    window : tuple of float    Evaluation window [s].
    alpha_max : float          Acceleration limit [rad/s²].
    """
    t0, t1 = window
    sel = (t >= t0) & (t <= t1)
    if np.count_nonzero(sel) < 8 or t1 <= t0:
        return ChatterVerdict(False, 0.0, 0, 0.0, 0.0, window)
    ts, a = t[sel], alpha_dem[sel]
    dt = float(np.median(np.diff(ts)))
    n = max(1, int(round(CHATTER_SMOOTHING_S / dt)))
    kernel = np.ones(n) / n
    smooth = np.convolve(np.pad(a, (n // 2, n - 1 - n // 2), mode="edge"), kernel, mode="valid")
    r = a - smooth
    ptp = float(np.ptp(r))
    changes = hysteretic_sign_changes(r, CHATTER_HYSTERESIS_FRACTION * alpha_max)
    chatter = ptp > CHATTER_PTP_FRACTION * alpha_max and changes >= CHATTER_MIN_SIGN_CHANGES
    return ChatterVerdict(chatter, ptp, changes, changes / (2.0 * (t1 - t0)),
                          float(np.ptp(omega_r[sel])), window)


def response_metrics(
    t: np.ndarray, theta_r: np.ndarray, theta_dem: float, theta_at_Tm: float
) -> dict[str, float | None]:
    """2 % band entry and settling times, position error at T_m and overshoot.

    Parameters
    ----------
    t : numpy.ndarray        Time [s].
    theta_r : numpy.ndarray  Rotor angle [rad].
    theta_dem : float        Demanded angle [rad] (start at 0).
    theta_at_Tm : float      θ_r at T_m [rad].
    """
    band = 0.02 * abs(theta_dem)
    return {
        "t_2pct_first_s": signals.first_entry_time(t, theta_r, theta_dem, band),
        "t_2pct_settle_s": signals.settling_time(t, theta_r, theta_dem, band),
        "theta_error_at_Tm_rad": theta_at_Tm - theta_dem,
        "overshoot_rad": signals.overshoot(theta_r, 0.0, theta_dem),
    }
