"""Overlay of a measured drive log on a simulated run: alignment, errors and input energy.

The simulated move starts at t = 0 from θ_r = 0. In the log, the move start t0 is where θ_r
(or ∫ω_r dt) first leaves its initial value by 1 % of the travel, refined by the sample instant
(up to 0.1·the simulated horizon earlier) that minimises the RMS position error; θ_r is
referred to its value at t0. Errors are measured minus simulated on the log's samples from t0
to the end of the shorter record. The electrical input
energy is ∫ 3/2·(u_d·i_d + u_q·i_q) dt (amplitude-invariant dq, as eq. (58) in [1]) over the
same window, for both; the logged voltage is held over each sample interval (zero-order hold,
as a PWM inverter applies it) and the current is averaged over the interval.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc.identification import speed_from_angle
from pmsm_commissioning.sim.fdsmc.trace import Trace

#: Signals compared: name → SI unit.
OVERLAY_SIGNALS = {"theta_r": "rad", "omega_r": "rad/s", "i_d": "A", "i_q": "A", "u_d": "V", "u_q": "V"}


@dataclass(frozen=True)
class SignalError:
    """RMS and peak of measured − simulated for one signal [its SI unit]."""

    signal: str
    unit: str
    rms_error: float
    peak_error: float


@dataclass(frozen=True)
class Overlay:
    """Measured and simulated signals on the log's time grid from the move start.

    Attributes
    ----------
    t0 : float  Move start in the log [s]; detected unless given.
    t0_detected : bool
    t : numpy.ndarray  Time from the move start [s].
    measured, simulated : dict  signal → samples on ``t`` [SI].
    errors : tuple of SignalError
    energy_measured_J, energy_simulated_J : float or None  Electrical input energy [J] over ``t``.
    """

    t0: float
    t0_detected: bool
    t: np.ndarray
    measured: dict[str, np.ndarray]
    simulated: dict[str, np.ndarray]
    errors: tuple[SignalError, ...]
    energy_measured_J: float | None
    energy_simulated_J: float | None


def _position(signals: dict[str, np.ndarray]) -> np.ndarray | None:
    t = signals["t"]
    if "theta_r" in signals:
        return signals["theta_r"]
    if "omega_r" in signals:
        w = signals["omega_r"]
        return np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    return None


def detect_move_start(signals: dict[str, np.ndarray], trace: Trace) -> float:
    """Move start t0 in the log [s] (see the module docstring); 0 without θ_r or ω_r."""
    t, th = signals["t"], _position(signals)
    if th is None:
        return 0.0
    travel = float(np.max(np.abs(th - th[0])))
    if travel == 0.0:
        return 0.0
    coarse = float(t[int(np.argmax(np.abs(th - th[0]) > 0.01 * travel))])
    T = float(trace.t[-1])
    best, best_err = coarse, np.inf
    candidates = t[(t >= coarse - 0.1 * T) & (t <= coarse)]  # the log's own sample instants
    for t0 in candidates[:: max(1, candidates.size // 400)]:
        sel = (t >= t0) & (t - t0 <= T)
        if sel.sum() < 2:
            continue
        th0 = float(np.interp(t0, t, th))
        err = float(np.mean((th[sel] - th0 - np.interp(t[sel] - t0, trace.t, trace.theta_r)) ** 2))
        if err < best_err:
            best, best_err = float(t0), err
    return best


def _energy(t: np.ndarray, s: dict[str, np.ndarray]) -> float | None:
    if not {"u_d", "u_q", "i_d", "i_q"} <= set(s):
        return None
    i_d, i_q = 0.5 * (s["i_d"][1:] + s["i_d"][:-1]), 0.5 * (s["i_q"][1:] + s["i_q"][:-1])
    return float(np.sum(1.5 * (s["u_d"][:-1] * i_d + s["u_q"][:-1] * i_q) * np.diff(t)))


def overlay(signals: dict[str, np.ndarray], trace: Trace, t0: float | None = None) -> Overlay:
    """Align a log (SI signals with ``t``) to a simulated trace and compare them.

    Parameters
    ----------
    signals : dict
        The log's signals [SI], ``t`` from 0.
    trace : Trace
        Simulated run (move starts at t = 0).
    t0 : float or None
        Move start in the log [s]; None detects it.
    """
    detected = t0 is None
    t0 = detect_move_start(signals, trace) if t0 is None else float(t0)
    t_log = signals["t"]
    sel = (t_log >= t0) & (t_log - t0 <= trace.t[-1])
    t = t_log[sel] - t0
    meas = {k: v[sel] for k, v in signals.items() if k in OVERLAY_SIGNALS}
    if "theta_r" in meas:
        meas["theta_r"] = meas["theta_r"] - float(np.interp(t0, t_log, signals["theta_r"]))
        if "omega_r" not in meas and t.size > 7:
            meas["omega_r"] = speed_from_angle(t, meas["theta_r"])
    sim = {k: np.interp(t, trace.t, getattr(trace, k)) for k in meas}
    errors = tuple(
        SignalError(k, OVERLAY_SIGNALS[k], float(np.sqrt(np.mean((meas[k] - sim[k]) ** 2))),
                    float(np.max(np.abs(meas[k] - sim[k]))))
        for k in OVERLAY_SIGNALS if k in meas and t.size)
    e_sim = None
    if t.size > 1:
        e_sim = float(np.interp(t[-1], trace.t, trace.E_electrical) - np.interp(t[0], trace.t, trace.E_electrical))
    return Overlay(t0, detected, t, meas, sim, errors, _energy(t, meas) if t.size > 1 else None, e_sim)
