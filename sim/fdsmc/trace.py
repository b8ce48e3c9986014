"""The time series of one run: one field per channel the compiled kernel records, declared once.

The field order is the kernel's channel order (:data:`sim.fdsmc.kernel.CHANNELS` is read from it, and
:func:`sim.fdsmc.kernel_run.record` writes a sample's row in it).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from pmsm_commissioning.control.common.arrays import FloatArray


@dataclass(frozen=True)
class Trace:
    """Time series of one run on a common grid, SI units; energies cumulative from t = 0.

    Attributes
    ----------
    t : numpy.ndarray            Time [s].
    theta_r, omega_r : numpy.ndarray  Rotor angle [rad] and speed [rad/s].
    i_d, i_q : numpy.ndarray     dq currents [A].
    u_d, u_q : numpy.ndarray     dq voltages applied [V].
    alpha : numpy.ndarray        True rotor acceleration dω_r/dt [rad/s²].
    alpha_dem : numpy.ndarray    Outer-loop demand [rad/s²].
    Gamma_L : numpy.ndarray      True total load torque, eq. (4a)/(6) in [1] [N·m].
    Gamma_L_hat : numpy.ndarray  Observer's L̂0 [N·m].
    theta_hat, omega_hat : numpy.ndarray  Observer's θ̂_r [rad] and ω̂_r [rad/s].
    S : numpy.ndarray            Switching function [rad/s] (0 for the conventional law).
    E_friction, E_copper, E_electrical : numpy.ndarray  Friction, copper and electrical input energy [J].
    alpha_hat : numpy.ndarray    α of eq. (7) in [1] with Γ̂_L [rad/s²].
    E_motoring, E_load : numpy.ndarray  Energy drawn from the DC link and done on the load [J].

    The energies are extra states of the plant's RK4 integration (:func:`sim.fdsmc.kernel.plant_rhs`),
    so that the balance closes.
    """

    t: FloatArray
    theta_r: FloatArray
    omega_r: FloatArray
    i_d: FloatArray
    i_q: FloatArray
    u_d: FloatArray
    u_q: FloatArray
    alpha: FloatArray
    alpha_dem: FloatArray
    Gamma_L: FloatArray
    Gamma_L_hat: FloatArray
    theta_hat: FloatArray
    omega_hat: FloatArray
    S: FloatArray
    E_friction: FloatArray
    E_copper: FloatArray
    E_electrical: FloatArray
    alpha_hat: FloatArray
    E_motoring: FloatArray
    E_load: FloatArray


#: The channel names in the kernel's order.
CHANNELS: tuple[str, ...] = tuple(f.name for f in fields(Trace))

__all__ = ["CHANNELS", "Trace"]
