"""The compiled kernel's outputs decoded once into typed records.

:mod:`sim.fdsmc.kernel` writes its state vectors (``X_*``) and its run summary ``info`` (``I_*``)
as flat float arrays, the only form a numba kernel can fill. :func:`decode_state` and
:func:`decode_info` turn them into :class:`KernelState` and :class:`RunSummary`, which metrics,
energies and the duty-cycle study read by name. The values keep their numpy float64 type, so any
arithmetic on them is bit-for-bit the arithmetic on the array elements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.sim.fdsmc import layout as lay


@dataclass(frozen=True)
class KernelState:
    """One kernel state vector (``X_*`` of :mod:`sim.fdsmc.kernel`), SI units.

    Attributes
    ----------
    i_d, i_q : float         dq currents [A].
    theta_r : float          Rotor angle [rad].
    omega_r : float          Rotor speed [rad/s].
    E_friction, E_copper, E_electrical, E_motoring, E_load : float
        Energies since t = 0 [J]: friction, copper, electrical input (net), motoring (input while
        positive), work done on the external load.
    theta_hat, omega_hat : float   Observer's angle [rad] and speed [rad/s].
    L0, L1 : float           Observer's load-torque states.
    """

    i_d: float
    i_q: float
    theta_r: float
    omega_r: float
    E_friction: float
    E_copper: float
    E_electrical: float
    E_motoring: float
    E_load: float
    theta_hat: float
    omega_hat: float
    L0: float
    L1: float


#: Field of :class:`KernelState` → index in the kernel's state vector.
STATE_INDEX: dict[str, int] = {
    "i_d": lay.X_ID, "i_q": lay.X_IQ, "theta_r": lay.X_TH, "omega_r": lay.X_W, "E_friction": lay.X_EF,
    "E_copper": lay.X_ECU, "E_electrical": lay.X_EEL, "E_motoring": lay.X_EMOT, "E_load": lay.X_ELOAD,
    "theta_hat": lay.X_THH, "omega_hat": lay.X_WH, "L0": lay.X_L0, "L1": lay.X_L1,
}


def decode_state(x: np.ndarray) -> KernelState:
    """Return the :class:`KernelState` of a state vector of length ``lay.N_X``."""
    return KernelState(**{name: x[i] for name, i in STATE_INDEX.items()})


@dataclass(frozen=True)
class RunSummary:
    """The kernel's run summary ``info`` (``I_*`` of :mod:`sim.fdsmc.kernel`), SI units.

    Attributes
    ----------
    n_out : int               Trace columns written [-].
    failed : bool             True when a state became non-finite or left its bound.
    t_fail : float            Time of the failure [s].
    saturated_s : float       Time the voltage limiter was active [s].
    omega_peak, i_q_peak, i_d_peak, u_peak, torque_peak, i_dq_peak : float
        Peaks of |ω_r| [rad/s], |i_q|, |i_d| [A], |u_dq| [V], |Γ_em| [N·m], |i_dq| [A].
    Tm_reached : float        Whether the run reached T_m (1) or not (0) [-].
    at_Tm, end : KernelState  The state interpolated at T_m, and the final state.
    over_i_max_s : float      Time with |i_dq| above i_max [s].
    t_out : float             Last sample time outside the in-position window [s] (−1: never).
    overshoot : float         Largest overshoot beyond θ_dem [rad].
    """

    n_out: int
    failed: bool
    t_fail: float
    saturated_s: float
    omega_peak: float
    i_q_peak: float
    u_peak: float
    torque_peak: float
    i_d_peak: float
    Tm_reached: float
    at_Tm: KernelState
    end: KernelState
    i_dq_peak: float
    over_i_max_s: float
    t_out: float
    overshoot: float


def decode_info(info: np.ndarray) -> RunSummary:
    """Return the :class:`RunSummary` of the kernel's ``info`` vector (length ``lay.N_INFO``)."""
    return RunSummary(
        n_out=int(info[lay.I_NOUT]), failed=bool(info[lay.I_FAILED]), t_fail=info[lay.I_TFAIL],
        saturated_s=info[lay.I_TSAT], omega_peak=info[lay.I_PW], i_q_peak=info[lay.I_PIQ], u_peak=info[lay.I_PU],
        torque_peak=info[lay.I_PTQ], i_d_peak=info[lay.I_PID], Tm_reached=info[lay.I_TM_HIT],
        at_Tm=decode_state(info[lay.I_SNAP: lay.I_SNAP + lay.N_X]),
        end=decode_state(info[lay.I_END: lay.I_END + lay.N_X]),
        i_dq_peak=info[lay.I_PIDQ], over_i_max_s=info[lay.I_TOVER], t_out=info[lay.I_TOUT], overshoot=info[lay.I_OVS])


__all__ = ["STATE_INDEX", "KernelState", "RunSummary", "decode_info", "decode_state"]
