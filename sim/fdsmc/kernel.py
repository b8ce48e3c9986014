"""Compiled closed-loop kernel: PMSM + FDC inner loops + observer + outer loop, one sample step.

Everything a run needs is packed into flat float arrays (indices declared by name in
:mod:`sim.fdsmc.layout`) so that one numba
function, :func:`sim.fdsmc.kernel_run.run_kernel`, integrates the whole manoeuvre with the step
written here (:func:`step_sample`, the plant's RK4 steps). :mod:`sim.fdsmc.reference` holds the readable plain-Python
version of the same step, built from the laws in :mod:`control`, and the tests check that both
agree. Formulas (see [1], the FDSMC paper):

* plant: eqs. (1)–(3) with the mechanics of eq. (4b), Γ_em of eq. (5), Γ_L of eq. (4a);
* sensors (digital mode): the controller sees the encoder's whole counts of θ_r and noisy,
  quantized i_d, i_q (:mod:`sim.common.sensors`); the plant stays exact;
* inverter: the hard, predictive |i_dq| ≤ i_max and |u_dq| ≤ u_max of
  :func:`control.fdsmc.inverter.limit_voltage`;
* FDC: eqs. (7), (9), (10), (14) with ω̂_r, L̂0, L̂1 from the observer;
* observer: eq. (15) corrected (e_o = θ_r − θ̂_r, dθ̂/dt = ω̂ + K1·e_o); digital mode uses the
  ZOH-exact prediction form x̂[k+1] = Φ·x̂[k] + Γ·a_em[k] + L·e_o[k];
* outer loop: eqs. (41)–(46) (FDSMC), eq. (62) sign-corrected (conventional), or tracking of a
  reference move (θ_ref, ω_ref, α_ref) by α_ref fed forward plus gains on the tracking error — the
  minimum-energy optimum ending on the FDSMC's terminal slide (``Law.OPTIMUM``,
  :mod:`control.fdsmc.terminal_slide`), or tracked to the very end without it (``Law.TRACKING``);
* or, instead of all of the above but the plant and sensors, a stock drive's own loops (``Law.DRIVE``,
  :mod:`control.stock.loops`): encoder PLL, position/speed law on a setpoint table interpolated between
  its rows, dq current PI;
* the FDC's u_q corrected by the q-axis voltage-mismatch estimate where ``P_BDV`` > 0 (not in [1],
  :func:`control.fdsmc.fdc.voltage_mismatch`);
* **the energies** (friction, copper, electrical in, motoring, load work) as extra states ``X_EF`` …
  ``X_ELOAD`` of the same RK4 integration (their rates in :func:`plant_rhs`), so that the balance closes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from pmsm_commissioning.control.fdsmc import conventional, fdc, inverter, model, sliding_mode, terminal_slide
from pmsm_commissioning.control.stock import loops
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc import layout as lay

#: A tuple of float states or values (the plant's first X_THH states, the observer's four, the memory ``hold``).
Floats = tuple[float, ...]
#: What :func:`step_sample` returns: the voltages applied over the step (u_d, u_q) [V], the new observer
#: state, the new controller memory ``hold``, the recorded outputs (u_d, u_q, α_dem, α̂, S), the limited flag.
SampleStep = tuple[tuple[float, float], Floats, Floats, Floats, bool]
#: The controller's memory ``hold`` of :func:`step_sample` at rest.
HOLD0 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
#: Rows of ``win`` per chatter window: α_dem [rad/s²], ω_r [rad/s], i_q [A], u_q [V] (applied).
WIN_ROWS = 4


# No fast-math: the compiled kernel computes every operation in the order written, IEEE-exactly,
# as the same code run as plain Python (NUMBA_DISABLE_JIT=1) does. A chattering loop with a
# quantized encoder is chaotic — last-bit differences (fused multiply-adds, re-association) grow
# into different trajectories — so only bit-identical arithmetic lets both agree on every metric
# and flag (tests/test_compiled_vs_python.py).
# The hot path works on tuples of scalars (plant p = the first X_THH states, observer o = the
# last four) and every helper is inlined into the run loop (inline="always"), so numba keeps the
# states in registers. The earlier array-based version (states in small arrays, stores inside
# the loop) took ≈ 240 ns per 20 kHz sample; this one ≈ 75 ns (``pmsm-commission bench``).
inlined = njit(cache=True, error_model="numpy", inline="always")


@inlined
def gamma_le(t: float, prm: np.ndarray, step_t: np.ndarray, step_v: np.ndarray) -> float:
    """External load torque Γ_Le(t) [N·m]: last step value (or Γ_Le0) plus the ramp."""
    g: float = prm[lay.P_GLE0]
    for j in range(step_t.size):
        if t >= step_t[j]:
            g = step_v[j]
    ramp: float = prm[lay.P_GRAMP]
    return g + ramp * t


@inlined
def reference_at(t: float, ref: np.ndarray, T_m: float) -> tuple[float, float, float]:
    """Return θ_ref [rad], ω_ref [rad/s], α_ref [rad/s²] at t [s] between the rows of ``ref``.

    The rows are equally spaced nodes over [0, T_m]; after T_m the final node's θ at rest. ω_ref and
    α_ref are linear between nodes and θ_ref is the integral of that ω_ref from the node before
    (quadratic): a θ_ref linear between nodes would lag the move's own ω by up to α·h²/8 — a few
    mrad on a 200-node move, which the tracking law turned into an overshoot of the end point.
    """
    n = ref.shape[1]
    if t >= T_m:
        return ref[0, n - 1], 0.0, 0.0
    h = T_m / (n - 1)
    x = max(t, 0.0) / h
    j = min(int(x), n - 2)
    f = x - j
    w0, w1 = ref[1, j], ref[1, j + 1]
    return (ref[0, j] + h * f * (w0 + 0.5 * f * (w1 - w0)), (1.0 - f) * w0 + f * w1,
            (1.0 - f) * ref[2, j] + f * ref[2, j + 1])


@inlined
def outer_law(t: float, theta_hat: float, omega_hat: float, prm: np.ndarray,
              ref: np.ndarray) -> tuple[float, float]:
    """Return the outer loop's demanded acceleration [rad/s²] and S [rad/s].

    Eqs. (44)–(46), (62), the tracked optimum's :func:`control.fdsmc.terminal_slide.slide_in_demand`
    (``Law.OPTIMUM``) or the same reference tracked to the very end without the slide,
    :func:`control.fdsmc.conventional.tracking_demand` (``Law.TRACKING``, the yardstick of what the slide
    removes), all of :mod:`control`.
    """
    law = int(prm[lay.P_CTRL])
    g1, g2, th_dem = prm[lay.P_G1], prm[lay.P_G2], prm[lay.P_THDEM]
    if law >= lay.Law.TRACKING:  # α_ref fed forward P_LEAD ahead, so the lagging inner loops deliver it on time
        th_r, w_r, _ = reference_at(t, ref, prm[lay.P_TM])
        a_r = reference_at(t + prm[lay.P_LEAD], ref, prm[lay.P_TM])[2]
        if law == lay.Law.TRACKING:
            return conventional.tracking_demand(th_r, w_r, a_r, theta_hat, omega_hat, g1, g2), 0.0
        return terminal_slide.slide_in_demand(th_r, w_r, a_r, ref[0, 0], theta_hat, omega_hat, g1, g2, th_dem,
                                              prm[lay.P_OMP], prm[lay.P_TC], prm[lay.P_KB], prm[lay.P_AMAX])
    if law == lay.Law.CONVENTIONAL:
        return conventional.conventional_demand(th_dem, theta_hat, omega_hat, g1, g2), 0.0
    return sliding_mode.smc_demand(theta_hat - th_dem, omega_hat, prm[lay.P_OMP], prm[lay.P_TC], prm[lay.P_KB],
                                   prm[lay.P_AMAX])


@inlined
def fdc_voltages(alpha_dem: float, i_d: float, i_q: float, omega_hat: float, L0: float,
                 L1: float, prm: np.ndarray) -> tuple[float, float, float]:
    """u_d of eq. (9), u_q of eq. (14) [V] and α of eq. (7) [rad/s²]: :func:`control.fdsmc.fdc.fdc_voltages`."""
    return fdc.fdc_voltages(alpha_dem, i_d, i_q, omega_hat, L0, L1, prm[lay.P_A], prm[lay.P_B], prm[lay.P_C],
                            prm[lay.P_D], prm[lay.P_E], prm[lay.P_F], prm[lay.P_G], prm[lay.P_H], prm[lay.P_K],
                            prm[lay.P_M], prm[lay.P_TSI], prm[lay.P_TSA])


@inlined
def predict_currents(i_d: float, i_q: float, omega_hat: float, u: tuple[float, float],
                     prm: np.ndarray) -> tuple[float, float]:
    """Currents [A] one sample on with the voltages u held: :func:`control.fdsmc.inverter.predict_currents`."""
    return inverter.predict_currents(i_d, i_q, omega_hat, u[0], u[1], prm[lay.P_PHID], prm[lay.P_GMID],
                                     prm[lay.P_PHIQ], prm[lay.P_GMIQ], prm[lay.P_B], prm[lay.P_C], prm[lay.P_E],
                                     prm[lay.P_F], prm[lay.P_G])


@inlined
def limit_voltage(u_d: float, u_q: float, i_d: float, i_q: float, omega_hat: float,
                  prm: np.ndarray) -> tuple[float, float, bool]:
    """Apply the inverter limits of :func:`control.fdsmc.inverter.limit_voltage`; return u_d, u_q, flag."""
    return inverter.limit_voltage(u_d, u_q, i_d, i_q, omega_hat, prm[lay.P_IMAX], prm[lay.P_UMAX],
                                  prm[lay.P_PHID], prm[lay.P_GMID], prm[lay.P_PHIQ], prm[lay.P_GMIQ], prm[lay.P_B],
                                  prm[lay.P_C], prm[lay.P_E], prm[lay.P_F], prm[lay.P_G])


@inlined
def measure(k: int, p: Floats, prm: np.ndarray, noise: np.ndarray) -> tuple[float, float, float]:
    """Return what the controller reads at sample k: (θ_r [rad], i_d, i_q [A]) through :mod:`sim.common.sensors`."""
    j = k % noise.shape[1]
    return (sensors.encoder_angle(p[lay.X_TH], prm[lay.P_ENC]),
            sensors.adc_current(p[lay.X_ID], noise[0, j], prm[lay.P_INOISE], prm[lay.P_ISTEP], prm[lay.P_IFS]),
            sensors.adc_current(p[lay.X_IQ], noise[1, j], prm[lay.P_INOISE], prm[lay.P_ISTEP], prm[lay.P_IFS]))


@inlined
def control_output(t: float, y: Floats, i0: Floats, o: Floats, prm: np.ndarray,
                   ref: np.ndarray, dv: float) -> tuple[float, float, float, float, float, bool]:
    """u_d, u_q [V], α_dem, α [rad/s²], S [rad/s], limited, from the readings y and the estimates o.

    ``i0`` are the currents [A] at the start of the sample the voltages will act over (the readings,
    or their prediction over a computation delay): the current limit's starting point. ``dv`` [V] is the
    q-axis voltage-mismatch estimate the FDC's u_q is corrected by (0 without one).
    """
    alpha_dem, S = outer_law(t, o[0], o[1], prm, ref)
    u_d, u_q, alpha = fdc_voltages(alpha_dem, y[1], y[2], o[1], o[2], o[3], prm)
    u_d, u_q, sat = limit_voltage(u_d, u_q - dv, i0[0], i0[1], o[1], prm)
    return u_d, u_q, alpha_dem, alpha, S, sat


@inlined
def electromagnetic_torque(i_d: float, i_q: float, prm: np.ndarray) -> float:
    """Γ_em of eq. (5) [N·m] (:func:`control.fdsmc.model.electromagnetic_torque` on the packed parameters)."""
    return model.electromagnetic_torque(prm[lay.P_P], prm[lay.P_PSI], prm[lay.P_LD], prm[lay.P_LQ], i_d, i_q)


@inlined
def plant_rhs(t: float, p: Floats, u_d: float, u_q: float, prm: np.ndarray, step_t: np.ndarray,
              step_v: np.ndarray) -> Floats:
    """Return the derivatives of the plant and energy states p (eqs. 1–3, 4b, 5) [SI/s]."""
    i_d, i_q, w = p[lay.X_ID], p[lay.X_IQ], p[lay.X_W]
    g_le = gamma_le(t, prm, step_t, step_v)
    T_em = electromagnetic_torque(i_d, i_q, prm)
    p_el = 1.5 * (u_d * i_d + u_q * i_q)
    return (-prm[lay.P_PA] * i_d + prm[lay.P_PB] * w * i_q + prm[lay.P_PF] * u_d,
            -(prm[lay.P_PC] * i_d + prm[lay.P_PE]) * w - prm[lay.P_PD] * i_q + prm[lay.P_PG] * u_q,
            w,
            (T_em - prm[lay.P_FV] * w - g_le) / prm[lay.P_JT],
            prm[lay.P_FV] * w * w,
            1.5 * prm[lay.P_RS] * (i_d * i_d + i_q * i_q),
            p_el,
            max(p_el, 0.0),
            g_le * w)


@inlined
def observer_rhs(p: Floats, o: Floats, prm: np.ndarray) -> tuple[float, float, float, float]:
    """Corrected continuous observer, eq. (15) with e_o = θ_r − θ̂_r [rad/s, rad/s², …]."""
    e_o = p[lay.X_TH] - o[0]
    a_em = (prm[lay.P_H] + prm[lay.P_K] * p[lay.X_ID]) * p[lay.X_IQ]
    return (o[1] + prm[lay.P_K1] * e_o, a_em - prm[lay.P_M] * o[2] + prm[lay.P_K2] * e_o,
            o[3] + prm[lay.P_K3] * e_o, prm[lay.P_K4] * e_o)


@inlined
def axpy9(x: Floats, a: float, k: Floats) -> Floats:
    """Return x + a·k for 9-tuples."""
    return (x[0] + a * k[0], x[1] + a * k[1], x[2] + a * k[2], x[3] + a * k[3], x[4] + a * k[4],
            x[5] + a * k[5], x[6] + a * k[6], x[7] + a * k[7], x[8] + a * k[8])


@inlined
def axpy4(x: Floats, a: float, k: Floats) -> Floats:
    """Return x + a·k for 4-tuples."""
    return (x[0] + a * k[0], x[1] + a * k[1], x[2] + a * k[2], x[3] + a * k[3])


@inlined
def rk4_sum9(x: Floats, h: float, k1: Floats, k2: Floats, k3: Floats, k4: Floats) -> Floats:
    """Return x + h/6·(k1 + 2k2 + 2k3 + k4) for 9-tuples."""
    return axpy9(x, h / 6.0, axpy9(axpy9(k1, 2.0, axpy9(k2, 1.0, k3)), 1.0, k4))


@inlined
def rk4_sum4(x: Floats, h: float, k1: Floats, k2: Floats, k3: Floats, k4: Floats) -> Floats:
    """Return x + h/6·(k1 + 2k2 + 2k3 + k4) for 4-tuples."""
    return axpy4(x, h / 6.0, axpy4(axpy4(k1, 2.0, axpy4(k2, 1.0, k3)), 1.0, k4))


@inlined
def rk4_plant(t: float, h: float, p: Floats, u_d: float, u_q: float, prm: np.ndarray,
              step_t: np.ndarray, step_v: np.ndarray) -> Floats:
    """One classical Runge–Kutta step [s] of the plant with held voltages (digital mode)."""
    k1 = plant_rhs(t, p, u_d, u_q, prm, step_t, step_v)
    k2 = plant_rhs(t + 0.5 * h, axpy9(p, 0.5 * h, k1), u_d, u_q, prm, step_t, step_v)
    k3 = plant_rhs(t + 0.5 * h, axpy9(p, 0.5 * h, k2), u_d, u_q, prm, step_t, step_v)
    k4 = plant_rhs(t + h, axpy9(p, h, k3), u_d, u_q, prm, step_t, step_v)
    return rk4_sum9(p, h, k1, k2, k3, k4)


@inlined
def full_rhs(t: float, p: Floats, o: Floats, prm: np.ndarray, step_t: np.ndarray,
             step_v: np.ndarray, ref: np.ndarray) -> tuple[Floats, Floats]:
    """Continuous mode: plant and observer derivatives with the controller inside (ideal sensors)."""
    i = (p[lay.X_ID], p[lay.X_IQ])
    u_d, u_q, _, _, _, _ = control_output(t, (p[lay.X_TH], p[lay.X_ID], p[lay.X_IQ]), i, o, prm, ref, 0.0)
    return plant_rhs(t, p, u_d, u_q, prm, step_t, step_v), observer_rhs(p, o, prm)


@inlined
def rk4_continuous(t: float, h: float, p: Floats, o: Floats, prm: np.ndarray, step_t: np.ndarray,
                   step_v: np.ndarray, ref: np.ndarray) -> tuple[Floats, Floats]:
    """One RK4 step [s] of plant + observer with the controller evaluated in every stage."""
    a1, b1 = full_rhs(t, p, o, prm, step_t, step_v, ref)
    a2, b2 = full_rhs(t + 0.5 * h, axpy9(p, 0.5 * h, a1), axpy4(o, 0.5 * h, b1), prm, step_t, step_v, ref)
    a3, b3 = full_rhs(t + 0.5 * h, axpy9(p, 0.5 * h, a2), axpy4(o, 0.5 * h, b2), prm, step_t, step_v, ref)
    a4, b4 = full_rhs(t + h, axpy9(p, h, a3), axpy4(o, h, b3), prm, step_t, step_v, ref)
    return rk4_sum9(p, h, a1, a2, a3, a4), rk4_sum4(o, h, b1, b2, b3, b4)


@inlined
def _row4(M: np.ndarray, i: int, o: Floats) -> float:
    """Row i of the 4×4 matrix M times the 4-tuple o."""
    row: float = M[i, 0] * o[0] + M[i, 1] * o[1] + M[i, 2] * o[2] + M[i, 3] * o[3]
    return row


@inlined
def observer_update(theta_m: float, o: Floats, a_em: float, Phi: np.ndarray, Gam: np.ndarray,
                    Lo: np.ndarray) -> tuple[float, float, float, float]:
    """Discrete observer x̂[k+1] = Φ·x̂[k] + Γ·a_em[k] + L·(θ_r,meas[k] − θ̂_r[k])."""
    e_o = theta_m - o[0]
    return (Gam[0] * a_em + Lo[0] * e_o + _row4(Phi, 0, o),
            Gam[1] * a_em + Lo[1] * e_o + _row4(Phi, 1, o),
            Gam[2] * a_em + Lo[2] * e_o + _row4(Phi, 2, o),
            Gam[3] * a_em + Lo[3] * e_o + _row4(Phi, 3, o))


@inlined
def step_sample(k: int, t: float, p: Floats, o: Floats, hold: Floats, continuous: bool, delay: int,
                prm: np.ndarray, Phi: np.ndarray, Gam: np.ndarray, Lo: np.ndarray, ref: np.ndarray,
                noise: np.ndarray) -> SampleStep:
    """Run the controller (and, digital, the observer update) at sample k or one continuous step.

    Returns (voltages applied over the step, new observer state, new controller memory ``hold``, the
    recorded outputs (u_d, u_q, α_dem, α̂, S), limited flag). Digital: the controller reads the
    sensors (:func:`measure`); with a computation delay the current limit starts from the
    currents predicted at the end of the held voltages' sample. ``hold`` = (held u_d, u_q [V]; the
    last sample's readings i_d, i_q [A], ω̂ [rad/s] and applied u_d, u_q [V]; the q-axis
    voltage-mismatch estimate [V]), HOLD0 at rest.
    """
    if int(prm[lay.P_CTRL]) == lay.Law.DRIVE:
        return drive_sample(k, t, p, o, hold, delay, prm, ref, noise)
    if continuous:
        y = (p[lay.X_TH], p[lay.X_ID], p[lay.X_IQ])
        u_d, u_q, a_dem, a_hat, S, sat = control_output(t, y, (y[1], y[2]), o, prm, ref, 0.0)
        return (u_d, u_q), o, hold, (u_d, u_q, a_dem, a_hat, S), sat
    y = measure(k, p, prm, noise)
    dv = hold[7]
    if prm[lay.P_BDV] > 0.0:
        i_model = predict_currents(hold[2], hold[3], hold[4], (hold[5], hold[6]), prm)[1]
        dv = fdc.voltage_mismatch(dv, y[2], i_model, prm[lay.P_GMIQ] * prm[lay.P_G], prm[lay.P_BDV])
    held = (hold[0], hold[1])
    i0 = predict_currents(y[1], y[2], o[1], held, prm) if delay == 1 else (y[1], y[2])
    u_d, u_q, a_dem, a_hat, S, sat = control_output(t, y, i0, o, prm, ref, dv)
    if delay == 1:
        held, (u_d, u_q) = (u_d, u_q), held
    a_em = (prm[lay.P_H] + prm[lay.P_K] * y[1]) * y[2]
    memory = (held[0], held[1], y[1], y[2], o[1], u_d, u_q, dv)
    return (u_d, u_q), observer_update(y[0], o, a_em, Phi, Gam, Lo), memory, (u_d, u_q, a_dem, a_hat, S), sat


@inlined
def table_at(t: float, ref: np.ndarray, dt: float) -> tuple[float, float, float]:
    """Return the setpoint table at t [s]: θ_ref [rad], ω_ref [rad/s], α_ref [rad/s²].

    The rows are k·dt apart from t = 0; between two rows each value is interpolated linearly (a drive's
    interpolated position mode, CiA 402), after the last row the last row holds.
    """
    x = t / dt + 1e-9
    j = int(x)
    n = ref.shape[1]
    if j >= n - 1:
        return ref[0, n - 1], ref[1, n - 1], ref[2, n - 1]
    f = min(x - j, 1.0)
    return (ref[0, j] + f * (ref[0, j + 1] - ref[0, j]), ref[1, j] + f * (ref[1, j + 1] - ref[1, j]),
            ref[2, j] + f * (ref[2, j + 1] - ref[2, j]))


@inlined
def drive_sample(k: int, t: float, p: Floats, o: Floats, hold: Floats, delay: int, prm: np.ndarray,
                 ref: np.ndarray, noise: np.ndarray) -> SampleStep:
    """One cycle of a stock drive's own loops (:mod:`control.stock.loops`); returns as :func:`step_sample`.

    ``o`` = (PLL θ̂ [rad], ω̂ [rad/s], the position/speed law's integrator [N·m], 0); ``hold`` = (held
    u_d, u_q [V]; the current PI's integrators v_d, v_q [V]; 0, 0, 0, 0). The recorded α_dem is the
    torque demand over J_ff (over the plant's J without feed-forward).
    """
    T = prm[lay.P_DT]
    y = measure(k, p, prm, noise)
    th, w = loops.pll_update(o[0], o[1], y[0], prm[lay.P_DWE], T, prm[lay.P_DSNAP])
    th_r, w_r, a_r = table_at(t, ref, prm[lay.P_DREFDT])
    torque, integ, lim = loops.position_torque(prm[lay.P_DLAW], th_r, w_r, a_r, th, w, o[2], prm[lay.P_DKP],
                                               prm[lay.P_DKD], prm[lay.P_DKI], prm[lay.P_DILIM], prm[lay.P_DWLIM],
                                               prm[lay.P_DJFF],
                                               prm[lay.P_DKT] * prm[lay.P_DIMAX], T)
    i_q_dem = loops.clamp(torque / prm[lay.P_DKT], prm[lay.P_DIMAX])
    u_d, u_q, v_d, v_q, sat = loops.current_pi(0.0, i_q_dem, y[1], y[2], hold[2], hold[3], prm[lay.P_DCKP],
                                               prm[lay.P_DCKI], prm[lay.P_DUMAX], T)
    held = (hold[0], hold[1])
    if delay == 1:
        held, (u_d, u_q) = (u_d, u_q), held
    a_dem = torque / (prm[lay.P_DJFF] if prm[lay.P_DJFF] > 0.0 else prm[lay.P_JT])
    return ((u_d, u_q), (th, w, integ, 0.0), (held[0], held[1], v_d, v_q, 0.0, 0.0, 0.0, 0.0),
            (u_d, u_q, a_dem, a_dem, 0.0), sat or lim)
