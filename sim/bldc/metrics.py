"""Metrics of one BLDC speed-control run, computed with :mod:`sim.common.signals`.

Definitions (all on the run's sample grid):

* steady windows: the last ``t_window`` seconds of each constant-load segment;
* ``speed_error_ss_rad_s``: the largest |mean(ω* − ω)| over the steady windows;
* ``overshoot_rad_s``: largest excursion beyond ω* in the direction of travel, before the first
  load step;
* ``torque_ripple_pct``: 100·(max − min)/|mean| of T_EL over the steady window with the largest
  |mean T_EL| (the most loaded one, so the ratio is not inflated by a near-zero mean);
* ``recovery_time_s``: after each load step, the time until ω stays within ±``band_recovery``
  of ω* until the next step (``recovery_times_s`` lists them; the key holds the longest, None if
  some step never recovers);
* current / voltage peaks: max |i_x|, max |v_x − v_n| over the run; copper loss ∫R_s·Σi_x² dt.

Everything is SI; the JSON edge (:mod:`app.io.bldc_view`) gives the two speeds in rpm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.sim.bldc.trace import BldcTrace
from pmsm_commissioning.sim.common import signals
from pmsm_commissioning.sim.common.energy import energy_balance


@dataclass(frozen=True)
class BldcMetrics:
    """The metrics of one run (module docstring).

    The fields are the keys of ``bldc --json`` except the two speeds, which the JSON gives in rpm
    (``speed_error_ss_rpm``, ``overshoot_rpm``).

    Attributes
    ----------
    speed_error_ss_rad_s, overshoot_rad_s : float or None  [rad/s]
    torque_ripple_pct : float or None                        [%]
    ripple_window_s : list of float or None                  (t0, t1) of the ripple window [s]
    recovery_time_s : float or None                          longest recovery [s]
    recovery_times_s : list of (float or None)               recovery after each load step [s]
    reach_time_s : float or None                             first entry into the band [s]
    i_peak_A, v_peak_V, torque_peak_Nm : float               peaks [A], [V], [N·m]
    copper_loss_J, copper_loss_mean_W : float                [J], [W]
    electrical_in_total_J, copper_total_J, friction_total_J, load_work_total_J : float   [J]
    kinetic_change_J, magnetic_end_J : float                 stored at the end [J]
    energy_balance_residual_J, energy_balance_residual_pct : float   [J], [%]
    stable : bool
    reason : str or None                                     why the run diverged
    """

    speed_error_ss_rad_s: float | None
    overshoot_rad_s: float | None
    torque_ripple_pct: float | None
    ripple_window_s: list[float] | None
    recovery_time_s: float | None
    recovery_times_s: list[float | None]
    reach_time_s: float | None
    i_peak_A: float
    v_peak_V: float
    torque_peak_Nm: float
    copper_loss_J: float
    copper_loss_mean_W: float
    electrical_in_total_J: float
    copper_total_J: float
    friction_total_J: float
    load_work_total_J: float
    kinetic_change_J: float
    magnetic_end_J: float
    energy_balance_residual_J: float
    energy_balance_residual_pct: float
    stable: bool
    reason: str | None


def _mask(t: np.ndarray, a: float, b: float) -> np.ndarray:
    return (t >= a - 1e-12) & (t < b - 1e-12)


def steady_windows(params: BldcParams, t_reach: float | None) -> list[tuple[float, float]]:
    """(t0, t1) [s] of the steady window at the end of each constant-load segment.

    Windows that start before the speed first reached ω* (``t_reach`` [s]) are left out: they
    would measure the acceleration, not a steady state. None → no window.
    """
    if t_reach is None:
        return []
    w = params.case.t_window
    return [(max(a, b - w), b) for a, b in params.case.segments if b - w >= t_reach]


def recovery_times(params: BldcParams, t: np.ndarray, omega: np.ndarray) -> list[float | None]:
    """Time after each load step until ω stays within the recovery band of ω* [s] (or None)."""
    case = params.case
    out: list[float | None] = []
    for a, b in case.segments[1:]:
        m = _mask(t, a, b)
        if np.count_nonzero(m) < 2:
            out.append(None)
            continue
        ts = signals.settling_time(t[m], omega[m], case.omega_ref, case.band_recovery)
        out.append(None if ts is None else max(0.0, ts - a))
    return out


def _window_stats(params: BldcParams, tr: BldcTrace, t_reach: float | None
                  ) -> tuple[float | None, float | None, tuple[float, float] | None]:
    err_max, ripple, best, best_mean = None, None, None, -1.0
    for a, b in steady_windows(params, t_reach):
        m = _mask(tr.t, a, b)
        if not np.any(m):
            continue
        err = abs(float(np.mean(tr.omega_ref[m] - tr.omega[m])))
        err_max = err if err_max is None else max(err_max, err)
        mean_T = abs(float(np.mean(tr.T_EL[m])))
        if mean_T > best_mean:
            best_mean, best, ripple = mean_T, (a, b), signals.ripple_pct(tr.T_EL[m])
    return err_max, ripple, best


def _slowest(rec: list[float | None]) -> float | None:
    """Return the longest recovery time [s]; None when there is no load step or one never recovers."""
    times = [r for r in rec if r is not None]
    return max(times) if times and len(times) == len(rec) else None


def _overshoot(params: BldcParams, tr: BldcTrace, t_reach: float | None) -> float:
    """Overshoot [rad/s] within the constant-load segment in which ω first reaches ω*."""
    case = params.case
    t0 = 0.0 if t_reach is None else t_reach
    seg = next(((a, b) for a, b in case.segments if a <= t0 < b), case.segments[-1])
    m = _mask(tr.t, 0.0, seg[1])
    return signals.overshoot(tr.omega[m], case.omega_0, case.omega_ref)


def energy_metrics(tr: BldcTrace) -> dict[str, float]:
    """Energies at the end of the run [J] and the residual of the balance (E_in = losses + stored)."""
    out = {
        "electrical_in_total_J": float(tr.E_in[-1]), "copper_total_J": float(tr.E_copper[-1]),
        "friction_total_J": float(tr.E_friction[-1]), "load_work_total_J": float(tr.E_load[-1]),
        "kinetic_change_J": float(tr.E_kin[-1]), "magnetic_end_J": float(tr.E_mag[-1]),
    }
    bal = energy_balance(out["electrical_in_total_J"],
                         (out["copper_total_J"], out["friction_total_J"], out["load_work_total_J"]),
                         (out["kinetic_change_J"], out["magnetic_end_J"]), out["copper_total_J"])
    return {**out, "energy_balance_residual_J": bal.residual_J, "energy_balance_residual_pct": bal.residual_pct}


def run_metrics(params: BldcParams, tr: BldcTrace, diverged: bool = False) -> BldcMetrics:
    """Return the metrics of one run (module docstring); ``stable``/``reason`` say if it diverged."""
    case = params.case
    t_reach = signals.first_entry_time(tr.t, tr.omega, case.omega_ref, case.band_recovery)
    err_ss, ripple, window = _window_stats(params, tr, t_reach)
    rec = recovery_times(params, tr.t, tr.omega)
    stable = not diverged and signals.is_finite_and_bounded(tr.omega, tr.i_abc)
    return BldcMetrics(
        speed_error_ss_rad_s=err_ss if stable else None,
        overshoot_rad_s=_overshoot(params, tr, t_reach) if stable else None,
        torque_ripple_pct=ripple if stable else None,
        ripple_window_s=list(window) if window else None,
        recovery_time_s=_slowest(rec) if stable else None,
        recovery_times_s=rec,
        reach_time_s=t_reach,
        i_peak_A=signals.peak_abs(tr.i_abc),
        v_peak_V=signals.peak_abs(tr.v_phase),
        torque_peak_Nm=signals.peak_abs(tr.T_EL),
        copper_loss_J=float(tr.E_copper[-1]),
        copper_loss_mean_W=float(tr.E_copper[-1] / max(tr.t[-1], 1e-12)),
        **energy_metrics(tr),
        stable=stable,
        reason=None if stable else f"diverged at t = {tr.t[-1]:.4g} s (a state became non-finite or left ±1e9)",
    )
