"""Compiled simulation loop of the BLDC speed drive (numba, ``cache=True``).

Plant: the abc model of eq. (1) in [2] for a star without neutral (L = L_s − M_s, the neutral
voltage v_n follows from i_a + i_b + i_c = 0), back-EMF e_x = ω_e·Φ'_rx(θ_e) of eq. (2) from a
periodic table, torque eq. (3), mechanics eq. (17). Averaged inverter: the controller's αβ
voltage, limited to |v_αβ| ≤ V_dc/√2, is held for one sample 1/f_s (zero-order hold) while
RK4 integrates the plant with ``n_sub`` steps; the electrical input energy ∫Σv_x·i_x dt is
integrated as a state (as are the copper, friction and load energies), so the energy
balance is exact to the RK4 error.

Controllers (codes ``C_*``) reuse the control laws of ``control/`` compiled here with numba,
so there is one implementation of each law. The vector drives command an αβ voltage limited to
the inscribed circle; six-step (``C_SIX_STEP``) commands phase voltages whose line voltage is
limited by its own law to V_dc (inside the inverter's hexagon, see :mod:`control.bldc.six_step`).

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pmsm_commissioning.control.bldc import current_smc as cur
from pmsm_commissioning.control.bldc import dqx
from pmsm_commissioning.control.bldc import pi_vector as piv
from pmsm_commissioning.control.bldc import plain_smc as plain
from pmsm_commissioning.control.bldc import six_step as six
from pmsm_commissioning.control.bldc import speed_smc as spd
from pmsm_commissioning.sim.common.layout import Layout

_jit = njit(cache=True)
_trap = _jit(dqx.trapezoid_unit)
_ab = _jit(dqx.alpha_beta)
_abc = _jit(dqx.abc_from_alpha_beta)
_gain_angle = _jit(dqx.dqx_gain_angle)
_to_dqx = _jit(dqx.to_dqx)
_from_dqx = _jit(dqx.from_dqx)
_v_tanh = _jit(cur.tanh_current_voltage)
_v_avail = _jit(cur.available_voltage_dqx)
_limit = _jit(cur.limit_vector)
_i_rate = _jit(spd.integral_rate)
_t_ref = _jit(spd.torque_reference)
_t_plain = _jit(plain.plain_torque_reference)
_pi_out = _jit(piv.pi_output)
_pi_int = _jit(piv.pi_integrate)
_six_signs = _jit(six.commutation_signs)
_six_ff = _jit(six.open_phase_feedforward)
_six_v = _jit(six.six_step_voltages)

TWO_PI = 2.0 * math.pi
C_SMC_INTEGRAL, C_SMC_PLAIN, C_PI_SINUSOIDAL, C_SIX_STEP = 0, 1, 2, 3

# ---- the parameter vector, declared by name (indices generated: sim.common.layout) ------------
PRM = Layout("the BLDC kernel's parameters")
P_R = PRM.slot("P_R", "phase resistance R_s [Ω]")
P_L = PRM.slot("P_L", "L_s − M_s [H]")
P_NPP = PRM.slot("P_NPP", "pole pairs n_pp [-]")
P_PHIM = PRM.slot("P_PHIM", "PM flux amplitude Φ_m [Wb]")
P_J = PRM.slot("P_J", "inertia J [kg·m²]")
P_B = PRM.slot("P_B", "viscous friction B [N·m·s/rad]")
P_VDC = PRM.slot("P_VDC", "DC link V_dc [V]")
P_TS = PRM.slot("P_TS", "sample period 1/f_s [s]")
P_KI = PRM.slot("P_KI", "current SMC gain k_I of eq. (14) [1/A]")
P_KW = PRM.slot("P_KW", "speed SMC gain k_ω [s/rad]")
P_TMAX = PRM.slot("P_TMAX", "torque limit T_max [N·m]")
P_LAM0 = PRM.slot("P_LAM0", "integral-surface gain λ₀ [1/s]")
P_EPSL = PRM.slot("P_EPSL", "anti-windup width ε_λ [rad/s]")
P_WREF = PRM.slot("P_WREF", "speed reference ω* [rad/s]")
P_W0 = PRM.slot("P_W0", "initial speed ω_0 [rad/s]")
P_KPW = PRM.slot("P_KPW", "speed PI K_p,ω (PI comparator) [N·m·s/rad]")
P_KIW = PRM.slot("P_KIW", "speed PI K_i,ω (PI comparator) [N·m/rad]")
P_KPI = PRM.slot("P_KPI", "current PI K_p,i (PI comparator) [V/A]")
P_KII = PRM.slot("P_KII", "current PI K_i,i (PI comparator) [V/(A·s)]")
P_KTS = PRM.slot("P_KTS", "torque constant the controller divides by [N·m/A]")
P_CTRL = PRM.slot("P_CTRL", "controller code C_* [-]")
N_PRM = PRM.size

#: Recorded channels (one row per sample, at the start of the sample interval).
CHANNELS = ("t", "omega", "T_L", "T_EL", "T_ref", "sigma", "i_a", "i_b", "i_c", "i_dx", "i_qx",
            "i_qx_ref", "v_a", "v_b", "v_c", "v_n", "E_in", "theta_e", "E_copper", "E_friction",
            "E_load")
N_CH = len(CHANNELS)
N_X = 8  # state: i_a, i_b, ω, θ_m and the energies E_in, E_copper, E_friction, E_load


@njit(cache=True)
def emf_lookup(table: np.ndarray, theta_e: float) -> float:
    """Φ'_r(θ_e) by periodic linear interpolation of a uniform one-period table [Wb]."""
    n = table.size
    x = (theta_e % TWO_PI) * n / TWO_PI
    i0 = int(x)
    f = x - i0
    i0 = i0 % n
    i1 = (i0 + 1) % n
    phi: float = table[i0] + f * (table[i1] - table[i0])
    return phi


@njit(cache=True)
def plant_derivative(y: np.ndarray, v_a: float, v_b: float, v_c: float, T_L: float,
                     prm: np.ndarray, table: np.ndarray, dy: np.ndarray) -> float:
    """Write dy/dt of the state (see ``N_X``) into ``dy``; return T_EL of eq. (3) [N·m]."""
    i_a, i_b, w = y[0], y[1], y[2]
    i_c = -i_a - i_b
    npp = prm[P_NPP]
    th = npp * y[3]
    fa = emf_lookup(table, th)
    fb = emf_lookup(table, th - TWO_PI / 3.0)
    fc = emf_lookup(table, th - 2.0 * TWO_PI / 3.0)
    we = npp * w
    v_n = (v_a + v_b + v_c - we * (fa + fb + fc)) / 3.0
    dy[0] = (v_a - v_n - prm[P_R] * i_a - we * fa) / prm[P_L]
    dy[1] = (v_b - v_n - prm[P_R] * i_b - we * fb) / prm[P_L]
    T_el: float = npp * (fa * i_a + fb * i_b + fc * i_c)
    dy[2] = (T_el - prm[P_B] * w - T_L) / prm[P_J]
    dy[3] = w
    dy[4] = v_a * i_a + v_b * i_b + v_c * i_c
    dy[5] = prm[P_R] * (i_a * i_a + i_b * i_b + i_c * i_c)
    dy[6] = prm[P_B] * w * w
    dy[7] = T_L * w
    return T_el


@njit(cache=True)
def rk4_hold(y: np.ndarray, v_a: float, v_b: float, v_c: float, T_L: float, prm: np.ndarray,
             table: np.ndarray, h: float, n_sub: int, work: np.ndarray) -> None:
    """Advance ``y`` in place by n_sub RK4 steps of h [s] with the voltages held.

    ``work`` is a scratch array of shape (5, N_X).
    """
    k1, k2, k3, k4, tmp = work[0], work[1], work[2], work[3], work[4]
    for _ in range(n_sub):  # explicit loops: no temporary arrays in the hot path
        plant_derivative(y, v_a, v_b, v_c, T_L, prm, table, k1)
        for j in range(N_X):
            tmp[j] = y[j] + 0.5 * h * k1[j]
        plant_derivative(tmp, v_a, v_b, v_c, T_L, prm, table, k2)
        for j in range(N_X):
            tmp[j] = y[j] + 0.5 * h * k2[j]
        plant_derivative(tmp, v_a, v_b, v_c, T_L, prm, table, k3)
        for j in range(N_X):
            tmp[j] = y[j] + h * k3[j]
        plant_derivative(tmp, v_a, v_b, v_c, T_L, prm, table, k4)
        for j in range(N_X):
            y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])


@njit(cache=True)
def speed_law(ctrl: int, eps: float, z: np.ndarray, prm: np.ndarray) -> tuple[float, float]:
    """Torque reference T* [N·m] and σ_ω [rad/s] of the chosen speed loop; updates z[0]."""
    T_s, T_max = prm[P_TS], prm[P_TMAX]
    if ctrl in (C_SMC_INTEGRAL, C_SIX_STEP):  # eq. (16) in [2], integral by forward Euler
        sigma = z[0] + eps
        z[0] += T_s * _i_rate(eps, prm[P_LAM0], prm[P_EPSL])
        return _t_ref(sigma, prm[P_KW], T_max), sigma
    if ctrl == C_SMC_PLAIN:
        return _t_plain(eps, prm[P_KW], T_max), eps
    sigma = eps + z[0] / prm[P_KPW]
    T_ref = _pi_out(z[0], eps, prm[P_KPW], T_max)
    z[0] = _pi_int(z[0], eps, prm[P_KPW], prm[P_KIW], T_s, T_max)
    return T_ref, sigma


@njit(cache=True)
def vector_current_step(ctrl: int, y: np.ndarray, z: np.ndarray, i_q_ref: float, prm: np.ndarray
                        ) -> tuple[float, float, float, float]:
    """Run the current loop of the vector drives: return (v_α, v_β) [V] and (i_dx, i_qx) [A]; update z[1:3]."""
    T_s = prm[P_TS]
    i_al, i_be = _ab(y[0], y[1], -y[0] - y[1])
    th = prm[P_NPP] * y[3]
    V_lim = prm[P_VDC] / math.sqrt(2.0)
    if ctrl == C_PI_SINUSOIDAL:
        a_x, phi = 1.0, th
    else:
        Pm = prm[P_PHIM]
        f_al, f_be = _ab(Pm * _trap(th), Pm * _trap(th - TWO_PI / 3.0), Pm * _trap(th - 2.0 * TWO_PI / 3.0))
        a_x, phi = _gain_angle(f_al, f_be, Pm)
    i_d, i_q = _to_dqx(i_al, i_be, a_x, phi)
    if ctrl == C_PI_SINUSOIDAL:
        e_d, e_q = -i_d, i_q_ref - i_q
        v_d = _pi_out(z[1], e_d, prm[P_KPI], V_lim)
        v_q = _pi_out(z[2], e_q, prm[P_KPI], V_lim)
        z[1] = _pi_int(z[1], e_d, prm[P_KPI], prm[P_KII], T_s, V_lim)
        z[2] = _pi_int(z[2], e_q, prm[P_KPI], prm[P_KII], T_s, V_lim)
    else:
        V_ax = _v_avail(prm[P_VDC], a_x)
        v_d = _v_tanh(0.0, i_d, prm[P_KI], V_ax)
        v_q = _v_tanh(i_q_ref, i_q, prm[P_KI], V_ax)
    v_al, v_be = _from_dqx(v_d, v_q, a_x, phi)
    v_al, v_be = _limit(v_al, v_be, V_lim)
    return v_al, v_be, i_d, i_q


@njit(cache=True)
def six_step_current_step(y: np.ndarray, i_ref: float, prm: np.ndarray) -> tuple[float, float, float, float]:
    """Six-step current loop: (v_α, v_β) [V], open-phase current and line current [A]."""
    i_a, i_b = y[0], y[1]
    th, Pm = prm[P_NPP] * y[3], prm[P_PHIM]
    s_a, s_b, s_c = _six_signs(th)
    v_ff = _six_ff(Pm * _trap(th), Pm * _trap(th - TWO_PI / 3.0), Pm * _trap(th - 2.0 * TWO_PI / 3.0),
                   s_a, s_b, s_c, prm[P_NPP] * y[2])
    v_a, v_b, v_c, i_line, i_fl = _six_v(i_ref, i_a, i_b, -i_a - i_b, s_a, s_b, s_c, v_ff, prm[P_KI], prm[P_VDC])
    v_al, v_be = _ab(v_a, v_b, v_c)
    return v_al, v_be, i_fl, i_line


@njit(cache=True)
def control_step(y: np.ndarray, z: np.ndarray, prm: np.ndarray, out: np.ndarray) -> None:
    """One sample of the chosen drive; updates integrators ``z`` = [I_ω, I_d, I_q] in place.

    ``out`` receives [v_α, v_β, T*, σ_ω, i_dx, i_qx, i*_qx] (SI units); for six-step the last
    three are the open-phase current, the line current of the conducting pair and I*.
    """
    ctrl = int(prm[P_CTRL])
    T_ref, sigma = speed_law(ctrl, prm[P_WREF] - y[2], z, prm)
    i_q_ref = T_ref / prm[P_KTS]
    if ctrl == C_SIX_STEP:
        v_al, v_be, i_d, i_q = six_step_current_step(y, i_q_ref, prm)
    else:
        v_al, v_be, i_d, i_q = vector_current_step(ctrl, y, z, i_q_ref, prm)
    out[0], out[1], out[2], out[3], out[4], out[5], out[6] = v_al, v_be, T_ref, sigma, i_d, i_q, i_q_ref


@njit(cache=True, nogil=True)
def run_kernel(prm: np.ndarray, table: np.ndarray, step_t: np.ndarray, step_v: np.ndarray,
               T_L0: float, n_ticks: int, n_sub: int, rec: np.ndarray) -> int:
    """Simulate n_ticks samples; fill ``rec`` (n_ticks + 1, N_CH); return rows written.

    Stops early (returning fewer rows) when a state becomes non-finite or leaves ±1e9.
    """
    y = np.zeros(N_X)
    y[2] = prm[P_W0]
    z = np.zeros(3)
    u = np.zeros(7)
    dy = np.zeros(N_X)
    work = np.zeros((5, N_X))
    T_s = prm[P_TS]
    h = T_s / n_sub
    k_step = 0
    T_L = T_L0
    for k in range(n_ticks + 1):
        t = k * T_s
        while k_step < step_t.size and t >= step_t[k_step] - 1e-12:
            T_L = step_v[k_step]
            k_step += 1
        control_step(y, z, prm, u)
        v_a, v_b, v_c = _abc(u[0], u[1], 0.0)
        T_el = plant_derivative(y, v_a, v_b, v_c, T_L, prm, table, dy)
        npp, th = prm[P_NPP], prm[P_NPP] * y[3]
        we = npp * y[2]
        e_sum = we * (emf_lookup(table, th) + emf_lookup(table, th - TWO_PI / 3.0)
                      + emf_lookup(table, th - 2.0 * TWO_PI / 3.0))
        r = rec[k]
        r[0], r[1], r[2], r[3], r[4], r[5] = t, y[2], T_L, T_el, u[2], u[3]
        r[6], r[7], r[8] = y[0], y[1], -y[0] - y[1]
        r[9], r[10], r[11] = u[4], u[5], u[6]
        r[12], r[13], r[14], r[15] = v_a, v_b, v_c, (v_a + v_b + v_c - e_sum) / 3.0
        r[16], r[17], r[18], r[19], r[20] = y[4], th, y[5], y[6], y[7]
        for j in range(N_X):
            if not math.isfinite(y[j]) or abs(y[j]) > 1e9:
                return k
        if k < n_ticks:
            rk4_hold(y, v_a, v_b, v_c, T_L, prm, table, h, n_sub, work)
    return n_ticks + 1
