"""Inverter limits applied to the FDC voltages: current limit on |i_q|, then |u_dq| ≤ u_max.

One scalar, numba-compilable law (:func:`control.common.jit.jitable`), inlined by the compiled kernel
(:mod:`sim.fdsmc.kernel`) and called by the plain-Python reference (:mod:`sim.fdsmc.reference`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper (eqs. (1)–(2) give the holding voltage).
"""

from __future__ import annotations

import math

from control.common.jit import jitable


@jitable
def limit_voltage(u_d: float, u_q: float, i_d: float, i_q: float, omega_hat: float, i_max: float,
                  u_max: float, C: float, D: float, E: float, G: float) -> tuple[float, float, bool]:
    """Apply the inverter's limits to the demanded (u_d, u_q) [V]; returns (u_d, u_q, saturated).

    Parameters
    ----------
    u_d, u_q : float       Demanded voltages of eqs. (9), (14) in [1] [V].
    i_d, i_q : float       Measured currents [A].
    omega_hat : float      Speed estimate [rad/s].
    i_max : float          Current limit on |i_q| [A]; 0 = none.
    u_max : float          Largest |u_dq| [V] (V_dc/√3); 0 = none.
    C, D, E, G : float     Coefficients of eq. (2) in [1].

    Notes
    -----
    At |i_q| ≥ i_max, u_q is held at the value that keeps di_q/dt = 0 (eq. (2)) whenever the demand
    would push |i_q| further; then the vector is scaled down to |u_dq| ≤ u_max.
    """
    sat = False
    if i_max > 0.0 and abs(i_q) >= i_max:
        u_hold = (C * omega_hat * i_d + D * i_q + E * omega_hat) / G
        if (u_q - u_hold) * i_q > 0.0:
            u_q = u_hold
            sat = True
    mag = math.sqrt(u_d * u_d + u_q * u_q)
    if u_max > 0.0 and mag > u_max:
        u_d *= u_max / mag
        u_q *= u_max / mag
        sat = True
    return u_d, u_q, sat


__all__ = ["limit_voltage"]
