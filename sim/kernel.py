"""Compiled closed-loop kernel: PMSM + FDC inner loops + observer + outer loop, one run.

Everything a run needs is packed into flat float arrays (indices below) so that one numba
function integrates the whole manoeuvre. :mod:`sim.reference` holds the readable plain-Python
version of the same step, built from the laws in :mod:`control`, and the tests check that both
agree. Formulas (see [1], the FDSMC paper):

* plant: eqs. (1)–(3) with the mechanics of eq. (4b), Γ_em of eq. (5), Γ_L of eq. (4a);
* FDC: eqs. (7), (9), (10), (14) with ω̂_r, L̂0, L̂1 from the observer;
* observer: eq. (15) corrected (e_o = θ_r − θ̂_r, dθ̂/dt = ω̂ + K1·e_o); digital mode uses the
  ZOH-exact prediction form x̂[k+1] = Φ·x̂[k] + Γ·a_em[k] + L·e_o[k];
* outer loop: eqs. (41)–(46) (FDSMC) or eq. (62) sign-corrected (conventional);
* energies as extra states of the same RK4 integration, so that the balance closes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# ---- prm indices -------------------------------------------------------------------------
(P_A, P_B, P_C, P_D, P_E, P_F, P_G, P_H, P_K, P_M, P_RS, P_LD, P_LQ, P_PSI, P_P, P_JR, P_JT,
 P_FV, P_TSI, P_TSA, P_CTRL, P_THDEM, P_OMP, P_TC, P_KB, P_AMAX, P_G1, P_G2, P_K1, P_K2, P_K3,
 P_K4, P_UMAX, P_IMAX, P_TM, P_GLE0, P_GRAMP, P_WLIM, P_ILIM) = range(39)
N_PRM = 39

# ---- state indices -----------------------------------------------------------------------
(X_ID, X_IQ, X_TH, X_W, X_EF, X_ECU, X_EEL, X_EMOT, X_ELOAD, X_THH, X_WH, X_L0, X_L1) = range(13)
N_X = 13

# ---- trace channels ----------------------------------------------------------------------
CHANNELS = ("t", "theta_r", "omega_r", "i_d", "i_q", "u_d", "u_q", "alpha", "alpha_dem",
            "Gamma_L", "Gamma_L_hat", "theta_hat", "omega_hat", "S", "E_friction", "E_copper",
            "E_electrical", "alpha_hat", "E_motoring", "E_load")
N_CH = len(CHANNELS)

# ---- info indices ------------------------------------------------------------------------
(I_NOUT, I_FAILED, I_TFAIL, I_TSAT, I_PW, I_PIQ, I_PU, I_PTQ, I_PID, I_TM_HIT) = range(10)
I_SNAP = 10  # then N_X values of the state interpolated at T_m
I_END = I_SNAP + N_X  # then N_X values of the final state
N_INFO = I_END + N_X


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def gamma_le(t: float, prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray) -> float:
    """External load torque Γ_Le(t) [N·m]: last step value (or Γ_Le0) plus the ramp."""
    g = prm[P_GLE0]
    for j in range(step_t.size):
        if t >= step_t[j]:
            g = step_v[j]
    return g + prm[P_GRAMP] * t


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def outer_law(theta_hat: float, omega_hat: float, prm: np.ndarray) -> tuple[float, float]:
    """Demanded acceleration [rad/s²] and switching function S [rad/s] (eqs. 44–46 or 62)."""
    if prm[P_CTRL] == 1.0:
        return prm[P_G1] * (prm[P_THDEM] - theta_hat) - prm[P_G2] * omega_hat, 0.0
    th_re = theta_hat - prm[P_THDEM]
    w_p, T_c = prm[P_OMP], prm[P_TC]
    on_slope = abs(th_re) < T_c * w_p
    S = omega_hat + th_re / T_c if on_slope else omega_hat + w_p * np.sign(th_re)
    x = prm[P_KB] * S
    x = min(1.0, max(-1.0, x))
    return -prm[P_AMAX] * x, S


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def fdc_voltages(alpha_dem: float, i_d: float, i_q: float, omega_hat: float, L0: float,
                 L1: float, prm: np.ndarray) -> tuple[float, float, float]:
    """u_d of eq. (9), u_q of eq. (14) [V] and α of eq. (7) [rad/s²]."""
    A, B, C, D, E = prm[P_A], prm[P_B], prm[P_C], prm[P_D], prm[P_E]
    F, G, H, K, M = prm[P_F], prm[P_G], prm[P_H], prm[P_K], prm[P_M]
    alpha = (H + K * i_d) * i_q - M * L0
    u_d = (-3.0 / prm[P_TSI] * i_d + A * i_d - B * omega_hat * i_q) / F
    forced = 3.0 / prm[P_TSA] * (alpha_dem - alpha)
    coupling = K * i_q * (A * i_d - B * omega_hat * i_q - F * u_d)
    u_q = ((forced + coupling + M * L1) / (H + K * i_d)
           + C * omega_hat * i_d + D * i_q + E * omega_hat) / G
    return u_d, u_q, alpha


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def limit_voltage(u_d: float, u_q: float, i_d: float, i_q: float, omega_hat: float,
                  prm: np.ndarray) -> tuple[float, float, bool]:
    """Optional inverter limits: current limit on i_q, then |u_dq| ≤ u_max. Returns flag."""
    sat = False
    i_max = prm[P_IMAX]
    if i_max > 0.0 and abs(i_q) >= i_max:
        # u_q that holds di_q/dt = 0 (eq. 2); do not push |i_q| further.
        u_hold = (prm[P_C] * omega_hat * i_d + prm[P_D] * i_q + prm[P_E] * omega_hat) / prm[P_G]
        if (u_q - u_hold) * i_q > 0.0:
            u_q = u_hold
            sat = True
    u_max = prm[P_UMAX]
    mag = math.sqrt(u_d * u_d + u_q * u_q)
    if u_max > 0.0 and mag > u_max:
        u_d *= u_max / mag
        u_q *= u_max / mag
        sat = True
    return u_d, u_q, sat


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def control_output(x: np.ndarray, prm: np.ndarray) -> tuple[float, float, float, float, float, bool]:
    """u_d, u_q [V], α_dem, α [rad/s²], S [rad/s], saturated, from measured i and estimates."""
    alpha_dem, S = outer_law(x[X_THH], x[X_WH], prm)
    u_d, u_q, alpha = fdc_voltages(alpha_dem, x[X_ID], x[X_IQ], x[X_WH], x[X_L0], x[X_L1], prm)
    u_d, u_q, sat = limit_voltage(u_d, u_q, x[X_ID], x[X_IQ], x[X_WH], prm)
    return u_d, u_q, alpha_dem, alpha, S, sat


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def plant_rhs(t: float, x: np.ndarray, u_d: float, u_q: float, prm: np.ndarray,
              step_t: np.ndarray, step_v: np.ndarray, dx: np.ndarray) -> float:
    """Plant + energy derivatives into ``dx`` (eqs. 1–3, 4b, 5); returns Γ_em [N·m]."""
    i_d, i_q, w = x[X_ID], x[X_IQ], x[X_W]
    g_le = gamma_le(t, prm, step_t, step_v)
    P = prm[P_P]
    T_em = 1.5 * P * (prm[P_PSI] + (prm[P_LD] - prm[P_LQ]) * i_d) * i_q
    dx[X_ID] = -prm[P_A] * i_d + prm[P_B] * w * i_q + prm[P_F] * u_d
    dx[X_IQ] = -(prm[P_C] * i_d + prm[P_E]) * w - prm[P_D] * i_q + prm[P_G] * u_q
    dx[X_TH] = w
    dx[X_W] = (T_em - prm[P_FV] * w - g_le) / prm[P_JT]
    p_el = 1.5 * (u_d * i_d + u_q * i_q)
    dx[X_EF] = prm[P_FV] * w * w
    dx[X_ECU] = 1.5 * prm[P_RS] * (i_d * i_d + i_q * i_q)
    dx[X_EEL] = p_el
    dx[X_EMOT] = max(p_el, 0.0)
    dx[X_ELOAD] = g_le * w
    return T_em


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def full_rhs(t: float, x: np.ndarray, u_d: float, u_q: float, continuous: bool,
             prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray, dx: np.ndarray) -> None:
    """Derivatives of all states; in continuous mode the controller and observer are inside."""
    if continuous:
        u_d, u_q, _, _, _, _ = control_output(x, prm)
    plant_rhs(t, x, u_d, u_q, prm, step_t, step_v, dx)
    if continuous:
        e_o = x[X_TH] - x[X_THH]
        a_em = (prm[P_H] + prm[P_K] * x[X_ID]) * x[X_IQ]
        dx[X_THH] = x[X_WH] + prm[P_K1] * e_o
        dx[X_WH] = a_em - prm[P_M] * x[X_L0] + prm[P_K2] * e_o
        dx[X_L0] = x[X_L1] + prm[P_K3] * e_o
        dx[X_L1] = prm[P_K4] * e_o


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def rk4_step(t: float, h: float, x: np.ndarray, u_d: float, u_q: float, continuous: bool,
             prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray, wk: np.ndarray) -> None:
    """One classical Runge–Kutta step of size h [s], in place; ``wk`` is a 5×N_X workspace.

    In digital mode only the plant and energy states are integrated (the observer is discrete).
    """
    n = N_X if continuous else X_THH
    k1, k2, k3, k4, xs = wk[0], wk[1], wk[2], wk[3], wk[4]
    xs[n:] = x[n:]
    full_rhs(t, x, u_d, u_q, continuous, prm, step_t, step_v, k1)
    for i in range(n):
        xs[i] = x[i] + 0.5 * h * k1[i]
    full_rhs(t + 0.5 * h, xs, u_d, u_q, continuous, prm, step_t, step_v, k2)
    for i in range(n):
        xs[i] = x[i] + 0.5 * h * k2[i]
    full_rhs(t + 0.5 * h, xs, u_d, u_q, continuous, prm, step_t, step_v, k3)
    for i in range(n):
        xs[i] = x[i] + h * k3[i]
    full_rhs(t + h, xs, u_d, u_q, continuous, prm, step_t, step_v, k4)
    for i in range(n):
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def observer_update(x: np.ndarray, a_em: float, Phi: np.ndarray, Gam: np.ndarray,
                    Lo: np.ndarray) -> None:
    """Discrete observer x̂[k+1] = Φ·x̂[k] + Γ·a_em[k] + L·(θ_r[k] − θ̂_r[k]), in place."""
    e_o = x[X_TH] - x[X_THH]
    o0, o1, o2, o3 = x[X_THH], x[X_WH], x[X_L0], x[X_L1]
    for i in range(4):
        x[X_THH + i] = (Gam[i] * a_em + Lo[i] * e_o + Phi[i, 0] * o0 + Phi[i, 1] * o1
                        + Phi[i, 2] * o2 + Phi[i, 3] * o3)


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def record(out: np.ndarray, n: int, t: float, x: np.ndarray, u_d: float, u_q: float,
           alpha_dem: float, alpha_hat: float, S: float, prm: np.ndarray, step_t: np.ndarray,
           step_v: np.ndarray, dx: np.ndarray) -> None:
    """Write one trace row (channels in CHANNELS order)."""
    T_em = plant_rhs(t, x, u_d, u_q, prm, step_t, step_v, dx)
    row = out[n]
    row[0], row[1], row[2], row[3], row[4] = t, x[X_TH], x[X_W], x[X_ID], x[X_IQ]
    row[5], row[6], row[7], row[8] = u_d, u_q, dx[X_W], alpha_dem
    row[9] = T_em - prm[P_JR] * dx[X_W]  # Γ_L of eq. (4a)
    row[10], row[11], row[12], row[13] = x[X_L0], x[X_THH], x[X_WH], S
    row[14], row[15], row[16], row[17] = x[X_EF], x[X_ECU], x[X_EEL], alpha_hat
    row[18], row[19] = x[X_EMOT], x[X_ELOAD]


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def track_peaks(info: np.ndarray, x: np.ndarray, u_d: float, u_q: float, prm: np.ndarray) -> None:
    """Update the peak |ω_r|, |i_q|, |u_dq|, |Γ_em|, |i_d| kept in ``info``."""
    info[I_PW] = max(info[I_PW], abs(x[X_W]))
    info[I_PIQ] = max(info[I_PIQ], abs(x[X_IQ]))
    info[I_PU] = max(info[I_PU], math.sqrt(u_d * u_d + u_q * u_q))
    T_em = 1.5 * prm[P_P] * (prm[P_PSI] + (prm[P_LD] - prm[P_LQ]) * x[X_ID]) * x[X_IQ]
    info[I_PTQ] = max(info[I_PTQ], abs(T_em))
    info[I_PID] = max(info[I_PID], abs(x[X_ID]))


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def diverged(x: np.ndarray, prm: np.ndarray) -> bool:
    """True when a state is not finite or beyond the divergence limits."""
    for i in range(N_X):
        if not math.isfinite(x[i]):
            return True
    return (abs(x[X_W]) > prm[P_WLIM] or abs(x[X_IQ]) > prm[P_ILIM]
            or abs(x[X_ID]) > prm[P_ILIM] or abs(x[X_WH]) > 10.0 * prm[P_WLIM])


@njit(cache=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def snapshot(info: np.ndarray, x_prev: np.ndarray, x: np.ndarray, t0: float, t1: float,
             T_m: float) -> None:
    """Store the state linearly interpolated at T_m when t0 < T_m ≤ t1."""
    if info[I_TM_HIT] == 0.0 and t0 < T_m <= t1:
        w = (T_m - t0) / (t1 - t0)
        for i in range(N_X):
            info[I_SNAP + i] = (1.0 - w) * x_prev[i] + w * x[i]
        info[I_TM_HIT] = 1.0


@njit(cache=True, nogil=True, error_model="numpy", fastmath={"nsz", "arcp", "contract", "afn", "reassoc"})
def run_kernel(prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray, Phi: np.ndarray,
               Gam: np.ndarray, Lo: np.ndarray, continuous: bool, h: float, n_steps: int,
               n_sub: int, delay: int, decim: int, out: np.ndarray, info: np.ndarray) -> None:
    """Integrate one run from rest; fills ``out`` (trace rows) and ``info`` (see I_* indices).

    Digital mode: ``n_steps`` samples of period n_sub·h; controller and observer at each
    sample, voltages held (one sample later if ``delay``), n_sub RK4 substeps in between.
    Continuous mode: ``n_steps`` RK4 steps of size h with the controller inside the RHS.
    """
    x = np.zeros(N_X)
    x_prev = np.zeros(N_X)
    wk = np.zeros((5, N_X))
    dx = np.zeros(N_X)
    u_d_hold, u_q_hold = 0.0, 0.0
    n_out, t = 0, 0.0
    T_m = prm[P_TM]
    info[:] = 0.0
    for k in range(n_steps):
        u_d, u_q, a_dem, a_hat, S, sat = control_output(x, prm)
        if not continuous:
            a_em = (prm[P_H] + prm[P_K] * x[X_ID]) * x[X_IQ]
            if delay == 1:
                u_d, u_d_hold = u_d_hold, u_d
                u_q, u_q_hold = u_q_hold, u_q
            if k % decim == 0 and n_out < out.shape[0]:
                record(out, n_out, t, x, u_d, u_q, a_dem, a_hat, S, prm, step_t, step_v, dx)
                n_out += 1
            observer_update(x, a_em, Phi, Gam, Lo)
        elif k % decim == 0 and n_out < out.shape[0]:
            record(out, n_out, t, x, u_d, u_q, a_dem, a_hat, S, prm, step_t, step_v, dx)
            n_out += 1
        track_peaks(info, x, u_d, u_q, prm)
        if sat:
            info[I_TSAT] += h * n_sub
        x_prev[:] = x
        # observer states of x_prev must be the pre-update values only for continuous mode;
        # the snapshot uses plant/energy states, which are unaffected.
        for _ in range(n_sub):
            rk4_step(t, h, x, u_d, u_q, continuous, prm, step_t, step_v, wk)
            t += h
        snapshot(info, x_prev, x, t - h * n_sub, t, T_m)
        if diverged(x, prm):
            info[I_FAILED] = 1.0
            info[I_TFAIL] = t
            break
    info[I_NOUT] = n_out
    for i in range(N_X):
        info[I_END + i] = x[i]
