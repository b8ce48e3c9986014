"""One run of the compiled kernel: its packed parameters, reference and observer arrays, its trace and metrics.

:func:`pack_parameters` fills the kernel's flat parameter vector (indices ``P_*`` of :mod:`sim.fdsmc.layout`),
:func:`run_packed` runs :func:`sim.fdsmc.kernel_run.run_kernel` on a time grid and returns the frozen
:class:`RunResult`. The controllers' runs (:mod:`sim.fdsmc.engine`) and the stock drive's route
(:mod:`sim.stock.route`) both run through here; neither imports the other's module for it.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.fdc import mismatch_filter_factor
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.inverter import decay_factors
from pmsm_commissioning.control.fdsmc.model import model_coefficients, torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.tracking import optimum_slide, tracking_gains
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import kernel_run
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.grid import TimeGrid, continuous_step, load_steps
from pmsm_commissioning.sim.fdsmc.metrics import (
    RunMetrics,
    WindowSamples,
    chatter_window_steps,
    chatter_windows,
    run_metrics,
)
from pmsm_commissioning.sim.fdsmc.summary import decode_info
from pmsm_commissioning.sim.fdsmc.trace import CHANNELS, Trace

#: The name each simulated outer loop goes by in messages, tables and figures.
LABELS = {"fdsmc": "FDSMC", "conventional": "Conventional", "optimum": "Optimum", "stock": "Stock drive"}
#: The kernel's outer law (``prm[P_CTRL]``) of each comparator on the FDC inner loops; the stock drive runs its
#: own loops instead (``Law.DRIVE``, :mod:`sim.stock.route`).
KERNEL_LAW = {"fdsmc": lay.Law.FDSMC, "conventional": lay.Law.CONVENTIONAL, "optimum": lay.Law.OPTIMUM}
#: The kernel's law that tracks the optimum's reference to the very end, without its terminal slide:
#: the yardstick of what the slide removes (the observer's lag carries the rotor past θ_dem).
TRACKING_TO_THE_END = lay.Law.TRACKING


@dataclass(frozen=True)
class RunResult:
    """One controller's run: trace and the metrics of ``simulate --json``."""

    controller: str
    trace: Trace
    metrics: RunMetrics


def pack_parameters(params: DriveParams, d: Derived, controller: str,
                    plant: DriveParams | None = None, T_step: float | None = None) -> np.ndarray:
    """Return the kernel's flat parameter vector (indices ``P_*`` of :mod:`sim.fdsmc.layout`).

    ``params``/``d`` are the controller's model; ``plant`` (default: the same) gives the true
    motor and load values the simulated drive has (R_s, L_d, L_q, Ψ_PM, p, J_r, J_L, F_v, Γ_Le).
    ``T_step`` [s] is the interval the current limit predicts over: the sample period (default
    1/f_s), or the integration step of the continuous mode (default :func:`continuous_step`).
    """
    c, ctrl = d.coefficients, params.controller
    pl = params if plant is None else plant
    m, ld, cp = pl.motor, pl.load, c if plant is None else model_coefficients(pl.motor)
    prm = lay.PRM.empty()
    for name in "ABCDEFGHKM":  # the controller's model, then the plant's own coefficients (P_PA … P_PG)
        prm[getattr(lay, f"P_{name}")] = getattr(c, name)
    for name in "ABCDEFG":
        prm[getattr(lay, f"P_P{name}")] = getattr(cp, name)
    prm[[lay.P_RS, lay.P_LD, lay.P_LQ, lay.P_PSI, lay.P_P, lay.P_JR]] = (
        m.R_s, m.L_d, m.L_q, m.psi_pm, m.p, m.J_r)
    prm[[lay.P_JT, lay.P_FV, lay.P_TSI, lay.P_TSA]] = (pl.J_total, ld.F_v, ctrl.T_si, ctrl.T_salpha)
    prm[lay.P_CTRL] = float(KERNEL_LAW[controller])
    pr, o = d.profile, d.observer
    prm[[lay.P_THDEM, lay.P_OMP, lay.P_TC, lay.P_KB, lay.P_AMAX]] = (
        params.manoeuvre.theta_dem, pr.omega_p, pr.T_c, ctrl.K, d.alpha.alpha_max)
    gains = d.conventional
    if controller == "optimum":  # its own K (below the chatter limit), tracking gains and terminal slide's T_c
        K, T_c = optimum_slide(d.gain, ctrl.K, d.alpha.alpha_max)
        gains = tracking_gains(d.loop, d.conventional, K)
        prm[[lay.P_TC, lay.P_KB]] = (T_c, K)
    prm[[lay.P_G1, lay.P_G2]] = (gains.g1, gains.g2)
    if controller == "optimum":  # α(t) ≈ α_dem(t − T_sα/3) (eq. (13)), one more sample with a delay
        prm[lay.P_LEAD] = ctrl.T_salpha / 3.0 + (0.0 if ctrl.is_continuous else ctrl.delay_samples / float(ctrl.f_s))
    prm[[lay.P_K1, lay.P_K2, lay.P_K3, lay.P_K4]] = (o.K1, o.K2, o.K3, o.K4)
    if not ctrl.is_continuous:  # β of the q-axis voltage-mismatch estimate (0: none)
        prm[lay.P_BDV] = mismatch_filter_factor(ctrl.T_dv, float(ctrl.f_s))
    prm[[lay.P_UMAX, lay.P_IMAX]] = (ctrl.V_dc / math.sqrt(3.0), current_limit(params))  # 0 = no limit
    prm[[lay.P_TM, lay.P_GLE0, lay.P_GRAMP]] = (params.manoeuvre.T_m, ld.Gamma_Le, ld.Gamma_Le_ramp)
    m = params.motor
    w_scale = max(m.omega_b, pr.omega_p, abs(params.manoeuvre.theta_dem) / params.manoeuvre.T_m)
    i_scale = max(m.Gamma_max, d.alpha.torque_needed) / torque_constant(m)
    prm[[lay.P_WLIM, lay.P_ILIM]] = (20.0 * w_scale, 100.0 * i_scale)
    _pack_sensors(prm, params, d, T_step)
    lay.PRM.check_filled(prm)
    return prm


def _pack_sensors(prm: np.ndarray, params: DriveParams, d: Derived, T_step: float | None) -> None:
    """Sensor steps, the current predictor's factors over ``T_step`` and the in-position window."""
    se, c = params.sensors, d.coefficients
    prm[[lay.P_ENC, lay.P_INOISE, lay.P_ISTEP, lay.P_IFS]] = (
        se.encoder_step, se.i_noise, se.adc_step, se.i_adc_range)
    if T_step is None:
        ctrl = params.controller
        T_step = continuous_step(params) if ctrl.is_continuous else 1.0 / float(ctrl.f_s)
    prm[[lay.P_PHID, lay.P_GMID]] = decay_factors(c.A, T_step)
    prm[[lay.P_PHIQ, lay.P_GMIQ]] = decay_factors(c.D, T_step)
    prm[lay.P_INPOS] = pass_criteria(params).in_position


def observer_arrays(d: Derived) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the kernel's discrete observer (Φ, Γ, L), contiguous; zeros in continuous mode."""
    od = d.observer_discrete
    if od is None:
        return np.zeros((4, 4)), np.zeros(4), np.zeros(4)
    return np.ascontiguousarray(od.Phi), np.ascontiguousarray(od.Gamma), np.ascontiguousarray(od.L)


def reference_rows(d: Derived, controller: str) -> np.ndarray:
    """Return the kernel's reference rows (θ_ref, ω_ref, α_ref): the tracked optimum's, else zeros."""
    if controller != "optimum":
        return np.zeros((3, 2))
    from pmsm_commissioning.control.fdsmc.optimum import tracked_move  # imports cvxpy only when limits are active

    mv = tracked_move(d)
    return np.ascontiguousarray(np.vstack((mv.theta, mv.omega, mv.alpha)))


def run_packed(params: DriveParams, d: Derived, controller: str, g: TimeGrid, prm: np.ndarray, ref: np.ndarray,
               observer: tuple[np.ndarray, np.ndarray, np.ndarray], plant: DriveParams | None) -> RunResult:
    """Run the kernel on the grid ``g`` with the packed ``prm`` and return the run's trace and metrics.

    ``ref`` is the kernel's reference or setpoint table, ``observer`` its discrete (Φ, Γ, L); the
    sensors' noise, the load steps (of ``plant`` when given), the chatter windows and the metrics are
    those of :func:`simulate`.
    """
    T_step = g.h * g.n_sub
    step_t, step_v = load_steps(params if plant is None else plant)
    out = np.zeros((lay.N_CH, g.n_out))
    info = np.zeros(lay.N_INFO)
    windows = chatter_windows(params, d, controller, g.n_steps * T_step)
    steps = [chatter_window_steps(w, T_step, g.n_steps) for w in windows.values()]
    k_win = np.array([k0 for k0, _ in steps], dtype=np.int64)
    win = np.zeros((kn.WIN_ROWS * len(steps), max(n for _, n in steps)))
    kernel_run.run_kernel(prm, step_t, step_v, *observer, g.continuous, g.h, g.n_steps, g.n_sub,
                          params.controller.delay_samples, g.decim, out, info, k_win, win, ref,
                          sensors.noise_table(params.sensors))
    summary = decode_info(info)
    trace = _trace(out[:, : summary.n_out])
    rows = kn.WIN_ROWS
    samples = {name: WindowSamples(w, (k0 + np.arange(n)) * T_step, *win[rows * j: rows * (j + 1), :n])
               for j, ((name, w), (k0, n)) in enumerate(zip(windows.items(), steps, strict=True))}
    met = run_metrics(params, d, controller, trace.t, trace.theta_r, samples, summary, plant, T_step=T_step)
    return RunResult(controller, trace, met)


def _trace(chans: np.ndarray) -> Trace:
    """Trace from the kernel's channel-major output (each row is one contiguous channel)."""
    finite = np.all(np.isfinite(chans), axis=0)
    if not np.all(finite):
        chans = chans[:, : int(np.argmin(finite))]
    return Trace(**{name: chans[i] for i, name in enumerate(CHANNELS)})
