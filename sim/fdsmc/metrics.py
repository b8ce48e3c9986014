"""Run metrics of one closed-loop simulation: energies, response figures, chatter detection.

Chatter criterion (documented in ``docs/paper_reproduction.md``), applied to two windows:
``cruise`` — the middle 60 % of the planned cruise segment for the FDSMC, [0.2·T_m, T_m] for the
conventional law and the stock cascade, [0.2·T_m, T_m − 3·T_c] for the tracked optimum (its tracking
phase, before the terminal slide's switch; T_c of :func:`control.fdsmc.tracking.slide_time_constant`),
each at most its central 0.25 s — and ``hold`` — the second half of the tail after
T_m (at most its last 0.25 s), where the drive should rest at θ_dem. Each window is sampled at
every controller step (not the decimated trace, so that a limit cycle is never aliased away).
Take the high-pass part r = α_dem − (moving average of α_dem over 5 ms). The loop chatters when
r swings by more than 20 % of α_max peak-to-peak **and** r changes sign (with a hysteresis of
2.5 % of α_max) at least 8 times, i.e. a sustained oscillation of the demanded acceleration with
an amplitude comparable to the control range — the limit cycle of a too-high boundary-layer gain
K or of a poorly damped sloped segment — not a single transient. A slower limit cycle, which the
5 ms average follows, chatters too: α_dem less its least-squares line changes sign (same
hysteresis) at least 4 times and swings by more than 20 % of α_max over the window's second half
(:mod:`sim.fdsmc.limit_cycle`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.loop_analysis import CHATTER_PTP_FRACTION
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.tracking import optimum_slide
from pmsm_commissioning.sim.common import signals
from pmsm_commissioning.sim.common.energy import energy_balance
from pmsm_commissioning.sim.fdsmc.limit_cycle import limit_cycles
from pmsm_commissioning.sim.fdsmc.summary import KernelState, RunSummary

#: Thresholds of the chatter criterion (fractions of α_max; its amplitude CHATTER_PTP_FRACTION is
#: the loop analysis's) and the smoothing window [s].
CHATTER_HYSTERESIS_FRACTION = 0.025
CHATTER_MIN_SIGN_CHANGES = 8
CHATTER_SMOOTHING_S = 0.005
#: Longest chatter evaluation window [s] (its centre part is kept).
CHATTER_MAX_WINDOW_S = 0.25


@dataclass(frozen=True)
class WindowSamples:
    """Full-resolution samples of one window (t0, t1) [s].

    t [s], α_dem [rad/s²], ω_r [rad/s], i_q [A] (true), u_q [V] (applied).
    """

    window: tuple[float, float]
    t: np.ndarray
    alpha_dem: np.ndarray
    omega_r: np.ndarray
    i_q: np.ndarray
    u_q: np.ndarray


@dataclass(frozen=True)
class ChatterVerdict:
    """Result of the chatter test.

    Attributes
    ----------
    chatter : bool              Whether the criterion is met.
    ptp : float                 Peak-to-peak of the high-pass α_dem in the window [rad/s²] (of α_dem
                                less its line for a slower limit cycle).
    sign_changes : int          Hysteretic sign changes of the same signal [-].
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
    """Count the sign changes of ``r``, counting only swings beyond ±``hyst``.

    Samples inside ±hyst are ignored; every change between consecutive remaining signs counts.
    """
    s = np.sign(r)[np.abs(r) > hyst]
    return int(np.count_nonzero(s[1:] != s[:-1]))


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
    r = a - moving_average(a, max(1, int(round(CHATTER_SMOOTHING_S / dt))))
    ptp = float(np.ptp(r))
    hyst, ptp_min = CHATTER_HYSTERESIS_FRACTION * alpha_max, CHATTER_PTP_FRACTION * alpha_max
    changes = hysteretic_sign_changes(r, hyst)
    chatter = ptp > ptp_min and changes >= CHATTER_MIN_SIGN_CHANGES
    if not chatter:  # a slower limit cycle, which the moving average follows
        cycle, cycle_ptp, cycle_changes = limit_cycles(a[None, :], ts, hyst, ptp_min)
        if cycle[0]:
            chatter, ptp, changes = True, float(cycle_ptp[0]), int(cycle_changes[0])
    return ChatterVerdict(chatter, ptp, changes, changes / (2.0 * (t1 - t0)),
                          float(np.ptp(omega_r[sel])), window)


@dataclass(frozen=True)
class RunMetrics:
    """The metrics of one run; the field names are the keys of ``simulate --json``.

    Energies [J] without suffix are over [0, T_m] (W_L of eq. (47) in [1]), ``_total`` over the
    whole run; ``regenerated`` = motoring − net electrical input. A diverged run has every number
    None (except ``saturated_s`` and ``theta_dem_rad``), ``stable`` False and a ``reason``.

    Attributes
    ----------
    friction_J, copper_J, electrical_in_J, motoring_J, regenerated_J, load_work_J : float or None
        Energies over [0, T_m] [J].
    friction_total_J … load_work_total_J : float or None
        The same over the whole run [J].
    kinetic_at_Tm_J, kinetic_end_J, magnetic_end_J : float or None
        Stored energies at T_m and at the end [J].
    energy_balance_residual_J, energy_balance_residual_pct : float or None
        Residual of the balance (:func:`sim.common.energy.energy_balance`) [J], [%].
    t_2pct_first_s, t_2pct_settle_s : float or None
        First entry into, and settling in, the 2 % band around θ_dem [s].
    theta_error_at_Tm_rad, overshoot_rad, theta_dem_rad : float or None
        θ_r(T_m) − θ_dem, overshoot beyond θ_dem (at every sample), the demand [rad].
    omega_peak_rad_s, i_q_peak_A, i_d_peak_A, u_peak_V, torque_peak_Nm : float or None
        Peaks of |ω_r| [rad/s], |i_q|, |i_d| [A], |u_dq| [V], |Γ| [N·m].
    i_peak_A : float or None
        Peak of the true current vector |i_dq| [A].
    over_i_max_s : float or None
        Time the true |i_dq| exceeded the hard current limit min(i_max, Γ_max/K_t) [s] (0 without one).
    hold_i_q_rms_A, hold_u_q_ptp_V : float or None
        While holding θ_dem (the ``hold`` window): rms ripple of i_q about its mean [A] and the
        peak-to-peak of the applied u_q [V].
    in_position_s : float or None
        First time θ_r is inside the in-position window for good [s]; None if it ends outside.
    saturated_s : float
        Time the inverter limited the voltage or current [s].
    chatter : bool
        Whether the chatter criterion of this module is met in a window.
    chatter_phase : str or None
        ``cruise`` or ``hold``: the window that chatters.
    chatter_alpha_ptp_rad_s2, chatter_frequency_Hz : float or None
        Peak-to-peak of the high-pass α_dem [rad/s²] and its frequency [Hz] in that window.
    cruise_omega_ptp_rad_s, hold_omega_ptp_rad_s : float or None
        Peak-to-peak of ω_r in each window [rad/s].
    stable : bool
    reason : str or None
        Why the run diverged.
    """

    friction_J: float | None
    copper_J: float | None
    electrical_in_J: float | None
    motoring_J: float | None
    regenerated_J: float | None
    load_work_J: float | None
    friction_total_J: float | None
    copper_total_J: float | None
    electrical_in_total_J: float | None
    motoring_total_J: float | None
    regenerated_total_J: float | None
    load_work_total_J: float | None
    kinetic_at_Tm_J: float | None
    kinetic_end_J: float | None
    magnetic_end_J: float | None
    energy_balance_residual_J: float | None
    energy_balance_residual_pct: float | None
    t_2pct_first_s: float | None
    t_2pct_settle_s: float | None
    theta_error_at_Tm_rad: float | None
    overshoot_rad: float | None
    theta_dem_rad: float
    omega_peak_rad_s: float | None
    i_q_peak_A: float | None
    i_d_peak_A: float | None
    u_peak_V: float | None
    torque_peak_Nm: float | None
    i_peak_A: float | None
    over_i_max_s: float | None
    hold_i_q_rms_A: float | None
    hold_u_q_ptp_V: float | None
    in_position_s: float | None
    saturated_s: float
    chatter: bool
    chatter_phase: str | None
    chatter_alpha_ptp_rad_s2: float | None
    chatter_frequency_Hz: float | None
    cruise_omega_ptp_rad_s: float | None
    hold_omega_ptp_rad_s: float | None
    stable: bool
    reason: str | None


def response_metrics(
    t: np.ndarray, theta_r: np.ndarray, theta_dem: float, theta_at_Tm: float
) -> dict[str, float | None]:
    """2 % band entry and settling times, position error at T_m and overshoot (RunMetrics fields).

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
    }


def kernel_checks(s: RunSummary, T_step: float) -> dict[str, float | None]:
    """Return the current, in-position and overshoot figures the kernel tracks at every sample (RunMetrics fields).

    Parameters
    ----------
    s : RunSummary        The kernel's summary, decoded (:mod:`sim.fdsmc.summary`).
    T_step : float        Sample period (integration step in continuous mode) [s].
    """
    t_out = float(s.t_out)
    return {
        "i_peak_A": float(s.i_dq_peak),
        "over_i_max_s": float(s.over_i_max_s),
        "overshoot_rad": float(s.overshoot),
        "in_position_s": None if math.isinf(t_out) else (0.0 if t_out < 0.0 else t_out + T_step),
    }


def hold_ripple(s: WindowSamples) -> dict[str, float | None]:
    """Standstill ripple in the ``hold`` window: rms of i_q about its mean [A], peak-to-peak of u_q [V]."""
    if s.i_q.size < 2:
        return {"hold_i_q_rms_A": None, "hold_u_q_ptp_V": None}
    return {"hold_i_q_rms_A": float(np.std(s.i_q)), "hold_u_q_ptp_V": float(np.ptp(s.u_q))}


def kinetic_energy(params: DriveParams, x: KernelState) -> float:
    """Kinetic energy ½·(J_r + J_L)·ω_r² of state ``x`` [J]."""
    return float(0.5 * params.J_total * x.omega_r ** 2)


def magnetic_energy(params: DriveParams, x: KernelState) -> float:
    """Magnetic energy (3/4)·(L_d·i_d² + L_q·i_q²) of state ``x`` (amplitude-invariant dq) [J]."""
    m = params.motor
    return float(0.75 * (m.L_d * x.i_d ** 2 + m.L_q * x.i_q ** 2))


def energy_metrics(params: DriveParams, s: RunSummary) -> dict[str, float]:
    """Return the energies at T_m and at the end, stored energies and the balance residual [J].

    The keys are :class:`RunMetrics` fields.
    """
    snap, end = s.at_Tm, s.end
    out: dict[str, float] = {}
    for suffix, x in (("", snap), ("_total", end)):
        out[f"friction{suffix}_J"] = float(x.E_friction)
        out[f"copper{suffix}_J"] = float(x.E_copper)
        out[f"electrical_in{suffix}_J"] = float(x.E_electrical)
        out[f"motoring{suffix}_J"] = float(x.E_motoring)
        out[f"regenerated{suffix}_J"] = float(x.E_motoring - x.E_electrical)
        out[f"load_work{suffix}_J"] = float(x.E_load)
    out["kinetic_at_Tm_J"] = float(kinetic_energy(params, snap))
    out["kinetic_end_J"] = kinetic_energy(params, end)
    out["magnetic_end_J"] = magnetic_energy(params, end)
    bal = energy_balance(out["electrical_in_total_J"],
                         (out["copper_total_J"], out["friction_total_J"], out["load_work_total_J"]),
                         (out["kinetic_end_J"], out["magnetic_end_J"]), out["motoring_total_J"])
    out["energy_balance_residual_J"] = bal.residual_J
    out["energy_balance_residual_pct"] = bal.residual_pct
    return out


def moving_average(a: np.ndarray, n: int) -> np.ndarray:
    """Centred moving average of ``a`` over ``n`` samples (edges padded), O(len(a))."""
    c = np.concatenate(([0.0], np.cumsum(np.pad(a, (n // 2, n - 1 - n // 2), mode="edge"))))
    return (c[n:] - c[:-n]) / n


def chatter_windows(
    params: DriveParams, d: Derived, controller: str, t_end: float
) -> dict[str, tuple[float, float]]:
    """Chatter evaluation windows (t0, t1) [s] ``cruise`` and ``hold``: see the module docstring.

    Parameters
    ----------
    params : DriveParams
    d : Derived
    controller : str
    t_end : float  End of the simulated horizon [s].
    """
    T_m, T_a = params.manoeuvre.T_m, d.profile.T_a
    if controller == "optimum":  # tracking until the terminal slide (≈ 2·T_c before T_m): not its switch
        t0 = 0.2 * T_m
        T_c = optimum_slide(d.gain, params.controller.K, d.alpha.alpha_max)[1]
        t1 = max(T_m - 3.0 * T_c, 0.5 * T_m)
    elif controller != "fdsmc":  # the conventional law and the stock cascade: no cruise segment
        t0, t1 = 0.2 * T_m, T_m
    else:
        cruise = T_m - 4.0 * T_a
        t0, t1 = T_a + 0.2 * cruise, T_a + 0.8 * cruise
    if t1 - t0 > CHATTER_MAX_WINDOW_S:
        mid = 0.5 * (t0 + t1)
        t0, t1 = mid - 0.5 * CHATTER_MAX_WINDOW_S, mid + 0.5 * CHATTER_MAX_WINDOW_S
    h0 = max(T_m + 0.5 * (t_end - T_m), t_end - CHATTER_MAX_WINDOW_S)
    return {"cruise": (t0, t1), "hold": (h0, t_end)}


def chatter_window_steps(window: tuple[float, float], T_step: float, n_steps: int) -> tuple[int, int]:
    """First step index and number of steps [-] of ``window`` [s] for steps of T_step [s].

    Only steps 0 … n_steps − 1 are recorded by the kernel: a window ending at the horizon
    n_steps·T_step must not count the step at the horizon itself (it would stay 0.0 and inflate the
    peak-to-peak figures).
    """
    t0, t1 = window
    if t1 <= t0:
        return 0, 0
    k0 = int(np.ceil(t0 / T_step))
    k1 = min(int(np.floor(t1 / T_step)), n_steps - 1)
    return k0, max(0, k1 - k0 + 1)


def run_metrics(
    params: DriveParams, d: Derived, controller: str, t: np.ndarray, theta_r: np.ndarray,
    samples: dict[str, WindowSamples], s: RunSummary, plant: DriveParams | None = None, *,
    T_step: float,
) -> RunMetrics:
    """Return all metrics of one run.

    They come from the (decimated) trace, the full-resolution chatter-window ``samples`` and the kernel's
    summary ``s`` (:func:`sim.fdsmc.summary.decode_info`); ``T_step`` [s] is the sample period (the
    in-position time's resolution).

    Energies without suffix are over [0, T_m], ``_total`` over the whole run. For a diverged run
    every number becomes None, ``stable`` False and ``reason`` says why. Stored energies use the
    ``plant``'s true values when given.
    """
    failed = s.failed
    energies = energy_metrics(params if plant is None else plant, s)
    theta_Tm = float(s.at_Tm.theta_r)
    resp = response_metrics(t, theta_r, params.manoeuvre.theta_dem, theta_Tm)
    verdicts = {name: detect_chatter(w.t, w.alpha_dem, w.omega_r, w.window, d.alpha.alpha_max)
                for name, w in samples.items()}
    phase = None if failed else next((name for name, v in verdicts.items() if v.chatter), None)
    cv = verdicts[phase or "cruise"]
    figures: dict[str, float | None] = {
        **energies, **resp, **kernel_checks(s, T_step), **hold_ripple(samples["hold"]),
        "omega_peak_rad_s": float(s.omega_peak),
        "i_q_peak_A": float(s.i_q_peak),
        "i_d_peak_A": float(s.i_d_peak),
        "u_peak_V": float(s.u_peak),
        "torque_peak_Nm": float(s.torque_peak),
        "chatter_alpha_ptp_rad_s2": cv.ptp,
        "chatter_frequency_Hz": cv.frequency_Hz,
        "cruise_omega_ptp_rad_s": verdicts["cruise"].omega_ptp,
        "hold_omega_ptp_rad_s": verdicts["hold"].omega_ptp,
    }
    if failed:
        figures = dict.fromkeys(figures)
    return RunMetrics(
        **figures, theta_dem_rad=float(params.manoeuvre.theta_dem), saturated_s=float(s.saturated_s),
        chatter=phase is not None, chatter_phase=phase, stable=not failed,
        reason=_unstable_reason(d, controller, float(s.t_fail)) if failed else None)


def _unstable_reason(d: Derived, controller: str, t_fail: float) -> str:
    text = f"diverged at t = {t_fail:.4g} s (a state became non-finite or left its bound)"
    s = d.sample_rate
    if not s.stable:
        need = f"≥ {s.f_s_min:.4g} Hz" if s.f_s_min is not None else "a faster controller"
        text += (f": f_s = {s.f_s:g} Hz is too slow for T_so/T_sα (sampled inner loops + observer "
                 f"have spectral radius {s.spectral_radius:.4f} ≥ 1; needs {need})")
    elif controller == "fdsmc" and not d.gain.K_ok:
        g = d.gain
        text += (f": K = {g.K:g} s/rad exceeds the limit K_limit = {g.K_limit:.4g} s/rad of the "
                 f"linearised FDSMC loop ({g.mode}); recommended K = {g.K_recommended:.4g} s/rad")
    return text
