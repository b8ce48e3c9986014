"""Sliding-mode minimum-energy outer loop, eqs. (41)–(46) in [1].

Phase-plane state: position error θ_re = θ_r − θ_rdem and speed ω_r. The switching boundary
(41) has two horizontal segments ω_r = ∓ω_p (for |θ_re| ≥ T_c·ω_p) and a sloped segment
ω_r = −θ_re/T_c through the origin. S > 0 above the boundary; u = −α_max·sat(S, K), eq. (46).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from pmsm_commissioning.control.common.jit import jitable


def boundary_speed(theta_re: np.ndarray | float, omega_p: float, T_c: float) -> np.ndarray:
    """Speed on the switching boundary of eq. (41) in [1] at position error θ_re [rad/s].

    Parameters
    ----------
    theta_re : array_like  Position error θ_r − θ_rdem [rad].
    omega_p : float        Peak speed [rad/s].
    T_c : float            Slope time constant [s].
    """
    theta_re = np.asarray(theta_re, dtype=float)
    return np.where(
        np.abs(theta_re) >= T_c * omega_p, -omega_p * np.sign(theta_re), -theta_re / T_c
    )


def in_boundary_layer(theta_re: np.ndarray | float, omega_r: np.ndarray | float, omega_p: float, T_c: float,
                      K: float) -> np.ndarray:
    """Whether each state lies inside the boundary layer |ω_r − ω_b(θ_re)| ≤ 1/K, eqs. (41), (45) in [1].

    Parameters
    ----------
    theta_re : array_like  Position error θ_r − θ_rdem [rad].
    omega_r : array_like   Speed [rad/s].
    omega_p : float        Peak speed [rad/s].
    T_c : float            Slope time constant [s].
    K : float              Boundary-layer gain [s/rad]: the layer is ±1/K wide.
    """
    distance = np.abs(np.asarray(omega_r, dtype=float) - boundary_speed(theta_re, omega_p, T_c))
    inside: npt.NDArray[np.bool_] = distance <= 1.0 / K
    return inside


@jitable
def switching_function(theta_re: float, omega_r: float, omega_p: float, T_c: float) -> float:
    """Switching function S(θ_re, ω_r) of eq. (44) in [1] [rad/s].

    Written as ω_r minus the boundary speed of eq. (41), which equals eq. (44). Scalar and
    numba-compilable: the compiled kernel (:mod:`sim.fdsmc.kernel`) inlines this very function.
    """
    if abs(theta_re) >= T_c * omega_p:
        return omega_r + omega_p * (1.0 if theta_re > 0.0 else (-1.0 if theta_re < 0.0 else 0.0))
    return omega_r + theta_re / T_c


@jitable
def sat(S: float, K: float) -> float:
    """Boundary-layer saturation sat(S, K) of eq. (45) in [1] [-]."""
    x = K * S
    return 1.0 if x >= 1.0 else (-1.0 if x <= -1.0 else x)


@jitable
def smc_demand(
    theta_re: float, omega_r: float, omega_p: float, T_c: float, K: float, alpha_max: float
) -> tuple[float, float]:
    """(u, S): demanded acceleration u = −α_max·sat(S, K) of eq. (46) and S of eq. (44) in [1].

    Scalar and numba-compilable; the kernel, the reference and :func:`smc_law` all call it.
    """
    S = switching_function(theta_re, omega_r, omega_p, T_c)
    return -alpha_max * sat(S, K), S


def smc_law(
    theta_re: float, omega_r: float, omega_p: float, T_c: float, K: float, alpha_max: float
) -> float:
    """Demanded acceleration u = −α_max·sat(S(θ_re, ω_r), K), eq. (46) in [1] [rad/s²].

    Parameters
    ----------
    theta_re : float   Position error [rad].
    omega_r : float    Speed (estimate) [rad/s].
    omega_p : float    Peak speed [rad/s].
    T_c : float        Slope time constant [s].
    K : float          Boundary-layer gain [s/rad].
    alpha_max : float  Acceleration limit [rad/s²].
    """
    return smc_demand(theta_re, omega_r, omega_p, T_c, K, alpha_max)[0]
