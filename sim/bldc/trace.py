"""The time series of one BLDC speed-drive run (:func:`sim.bldc.engine.simulate_bldc`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BldcTrace:
    """Time series of one run, one row per controller sample (SI units).

    Attributes
    ----------
    t [s]; omega [rad/s] mechanical speed; omega_ref [rad/s]; T_L [N·m] load torque;
    T_EL [N·m] electromagnetic torque, eq. (3); T_ref [N·m] torque reference; sigma [rad/s]
    σ_ω of eq. (16) (ε_ω for the plain law, ε + I/K_p for PI); i_abc [A] shape (3, n);
    i_dx, i_qx [A] currents in the controller's frame (six-step: open-phase current and line
    current of the conducting pair); i_qx_ref [A] (six-step: I*); v_phase [V] winding
    voltages v_x − v_n, shape (3, n); theta_e [rad]; E_in [J] electrical input energy;
    E_copper, E_friction, E_load [J] cumulative losses / load work (integrated with the plant);
    E_kin [J] ½·J·(ω² − ω_0²); E_mag [J] ½·(L_s − M_s)·Σi_x².
    """

    t: np.ndarray
    omega: np.ndarray
    omega_ref: np.ndarray
    T_L: np.ndarray
    T_EL: np.ndarray
    T_ref: np.ndarray
    sigma: np.ndarray
    i_abc: np.ndarray
    i_dx: np.ndarray
    i_qx: np.ndarray
    i_qx_ref: np.ndarray
    v_phase: np.ndarray
    theta_e: np.ndarray
    E_in: np.ndarray
    E_copper: np.ndarray
    E_friction: np.ndarray
    E_load: np.ndarray
    E_kin: np.ndarray
    E_mag: np.ndarray
