"""Compiled run loop: one closed-loop run from rest, sample after sample, and its bookkeeping.

:func:`run_kernel` integrates a whole manoeuvre with the per-sample step of
:mod:`sim.fdsmc.kernel` (controller, observer, plant and their RK4 integration, all inlined
here) and records what the run's metrics need: the decimated trace (channels
:data:`sim.fdsmc.trace.CHANNELS`), full-resolution windows, running peaks, the position checks
of the pass criteria (time over i_max, last time outside the in-position window, overshoot),
divergence, and the state at T_m and at the end. The parameter, state and info layouts are those
declared in :mod:`sim.fdsmc.layout`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pmsm_commissioning.sim.common.borrowed import borrowed
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.kernel import (
    HOLD0,
    WIN_ROWS,
    Floats,
    electromagnetic_torque,
    inlined,
    plant_rhs,
    rk4_continuous,
    rk4_plant,
    step_sample,
)


@inlined
def record(row: np.ndarray, t: float, p: Floats, o: Floats, u: Floats, prm: np.ndarray,
           step_t: np.ndarray, step_v: np.ndarray) -> None:
    """Write one trace sample (channels in CHANNELS order); u = (u_d, u_q, α_dem, α̂, S)."""
    dp = plant_rhs(t, p, u[0], u[1], prm, step_t, step_v)
    T_em = electromagnetic_torque(p[lay.X_ID], p[lay.X_IQ], prm)
    row[lay.C_T], row[lay.C_THETA_R], row[lay.C_OMEGA_R] = t, p[lay.X_TH], p[lay.X_W]
    row[lay.C_I_D], row[lay.C_I_Q], row[lay.C_U_D], row[lay.C_U_Q] = p[lay.X_ID], p[lay.X_IQ], u[0], u[1]
    row[lay.C_ALPHA], row[lay.C_ALPHA_DEM], row[lay.C_ALPHA_HAT], row[lay.C_S] = dp[lay.X_W], u[2], u[3], u[4]
    row[lay.C_GAMMA_L] = T_em - prm[lay.P_JR] * dp[lay.X_W]  # Γ_L of eq. (4a)
    row[lay.C_GAMMA_L_HAT], row[lay.C_THETA_HAT], row[lay.C_OMEGA_HAT] = o[2], o[0], o[1]
    row[lay.C_E_FRICTION], row[lay.C_E_COPPER], row[lay.C_E_ELECTRICAL] = p[lay.X_EF], p[lay.X_ECU], p[lay.X_EEL]
    row[lay.C_E_MOTORING], row[lay.C_E_LOAD] = p[lay.X_EMOT], p[lay.X_ELOAD]


@inlined
def peaks(pk: Floats, p: Floats, u_d: float, u_q: float, prm: np.ndarray) -> Floats:
    """Return the running peaks updated with this step (|ω_r|, |i_q|, |u_dq|, |Γ_em|, |i_d|, |i_dq|)."""
    return (max(pk[0], abs(p[lay.X_W])), max(pk[1], abs(p[lay.X_IQ])),
            max(pk[2], math.sqrt(u_d * u_d + u_q * u_q)),
            max(pk[3], abs(electromagnetic_torque(p[lay.X_ID], p[lay.X_IQ], prm))),
            max(pk[4], abs(p[lay.X_ID])), max(pk[5], math.sqrt(p[lay.X_ID] * p[lay.X_ID] + p[lay.X_IQ] * p[lay.X_IQ])))


@inlined
def position_checks(pc: Floats, t: float, p: Floats, dt: float, prm: np.ndarray) -> Floats:
    """Update (time over i_max [s], last time outside the in-position window [s], overshoot [rad]) at t."""
    i_dq = math.sqrt(p[lay.X_ID] * p[lay.X_ID] + p[lay.X_IQ] * p[lay.X_IQ])
    over = prm[lay.P_IMAX] > 0.0 and i_dq > prm[lay.P_IMAX]
    err = p[lay.X_TH] - prm[lay.P_THDEM]
    out = abs(err) > prm[lay.P_INPOS]
    return (pc[0] + (dt if over else 0.0), t if out else pc[1],
            max(pc[2], err if prm[lay.P_THDEM] > 0.0 else -err))


@inlined
def diverged(p: Floats, o: Floats, prm: np.ndarray) -> bool:
    """Return True when a state is not finite or beyond the divergence limits."""
    total = 0.0
    for v in p:
        total += v
    total += o[0] + o[1] + o[2] + o[3]
    if not math.isfinite(total):  # one NaN/inf anywhere makes the sum non-finite
        return True
    beyond: bool = (abs(p[lay.X_W]) > prm[lay.P_WLIM] or abs(p[lay.X_IQ]) > prm[lay.P_ILIM]
                    or abs(p[lay.X_ID]) > prm[lay.P_ILIM] or abs(o[1]) > 10.0 * prm[lay.P_WLIM])
    return beyond


@inlined
def store_state(info: np.ndarray, at: int, p: Floats, o: Floats, w: float, p0: Floats) -> None:
    """info[at:at+N_X] = (1 − w)·p0 + w·p (plant, linear interpolation) followed by o."""
    for i in range(lay.X_THH):
        info[at + i] = (1.0 - w) * p0[i] + w * p[i]
    for i in range(4):
        info[at + lay.X_THH + i] = o[i]


@njit(cache=True, nogil=True, error_model="numpy")
def run_kernel(prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray, Phi: np.ndarray,
               Gam: np.ndarray, Lo: np.ndarray, continuous: bool, h: float, n_steps: int,
               n_sub: int, delay: int, decim: int, out: np.ndarray, info: np.ndarray,
               k_win: np.ndarray, win: np.ndarray, ref: np.ndarray, noise: np.ndarray) -> None:
    """Integrate one run from rest; fills ``out`` (N_CH × samples) and ``info`` (I_* indices).

    ``ref`` (3 × n: θ_ref, ω_ref, α_ref) is read only by the tracked optimum (``Law.OPTIMUM``: equally
    spaced nodes over [0, T_m]) and a stock drive's own loops (``Law.DRIVE``: its setpoint table, one row per
    ``prm[P_DREFDT]``); pass a 3 × 2 array of zeros otherwise.

    For each window j, rows WIN_ROWS·j … WIN_ROWS·j + 3 of ``win`` receive α_dem, ω_r, i_q and the
    applied u_q of every step k_win[j] … k_win[j] + n − 1 at full resolution (the chatter and
    standstill-ripple windows, independent of the trace decimation). ``noise`` is the sensors'
    standard-normal table (:func:`sim.common.sensors.noise_table`).

    Digital mode: ``n_steps`` samples of period n_sub·h; controller and observer at each
    sample, voltages held (one sample later if ``delay``), n_sub RK4 substeps in between.
    Continuous mode: ``n_steps`` RK4 steps of size h with the controller inside the RHS.
    """
    prm, step_t, step_v, Phi, Gam, Lo = (borrowed(prm), borrowed(step_t), borrowed(step_v), borrowed(Phi),
                                         borrowed(Gam), borrowed(Lo))  # no reference counts in the loop
    out, info, k_win, win, ref, noise = (borrowed(out), borrowed(info), borrowed(k_win), borrowed(win),
                                         borrowed(ref), borrowed(noise))
    p: Floats = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    o: Floats = (0.0, 0.0, 0.0, 0.0)
    hold: Floats = HOLD0
    pk: Floats = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    pc: Floats = (0.0, -1.0, 0.0)
    n_out, t, t_sat, T_m, hit = 0, 0.0, 0.0, prm[lay.P_TM], False
    info[:] = 0.0
    for k in range(n_steps):
        u, o_next, hold, rec, sat = step_sample(k, t, p, o, hold, continuous, delay, prm, Phi, Gam, Lo, ref,
                                                noise)
        if k % decim == 0 and n_out < out.shape[1]:
            record(out[:, n_out], t, p, o, rec, prm, step_t, step_v)
            n_out += 1
        for j in range(k_win.size):
            i = k - k_win[j]
            if 0 <= i < win.shape[1]:
                r = WIN_ROWS * j
                win[r, i], win[r + 1, i], win[r + 2, i], win[r + 3, i] = rec[2], p[lay.X_W], p[lay.X_IQ], u[1]
        pk = peaks(pk, p, u[0], u[1], prm)
        pc = position_checks(pc, t, p, h * n_sub, prm)
        t_sat += h * n_sub if sat else 0.0
        p0, o, t0 = p, o_next, t
        for _ in range(n_sub):
            if continuous:
                p, o = rk4_continuous(t, h, p, o, prm, step_t, step_v, ref)
            else:
                p = rk4_plant(t, h, p, u[0], u[1], prm, step_t, step_v)
            t += h
        if not hit and t0 < T_m <= t:
            store_state(info, lay.I_SNAP, p, o, (T_m - t0) / (t - t0), p0)
            hit = True
        if diverged(p, o, prm):
            info[lay.I_FAILED], info[lay.I_TFAIL] = 1.0, t
            break
    info[lay.I_NOUT], info[lay.I_TSAT], info[lay.I_TM_HIT] = n_out, t_sat, 1.0 if hit else 0.0
    pc = position_checks(pc, t, p, 0.0, prm)  # the final state counts too: outside at the end → inf
    if pc[1] == t:
        pc = (pc[0], math.inf, pc[2])
    info[lay.I_PW], info[lay.I_PIQ], info[lay.I_PU], info[lay.I_PTQ], info[lay.I_PID], info[lay.I_PIDQ] = pk
    info[lay.I_TOVER], info[lay.I_TOUT], info[lay.I_OVS] = pc
    store_state(info, lay.I_END, p, o, 1.0, p)
