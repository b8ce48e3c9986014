"""Power-invariant αβ transform and the dq_x transformation, eqs. (4)–(12) in [2].

Conventions (stated because Fig. 2 of [2] gives no phase origin): the magnet flux Φ_ra is
aligned with phase a at θ_e = 0, so the ideal Φ'_ra(θ_e) is "−sine-like": flat at −Φ_M for
θ_e ∈ [30°, 150°] and at +Φ_M for θ_e ∈ [210°, 330°], with linear 60° ramps. Phases b and c lag
by 120° and 240°. With this origin a sinusoidal machine gives a_x = 1 and θ_x = 0, i.e. dq_x
reduces to the usual dq frame with the back-EMF on the q axis.

Complex form of eq. (4): x_αβ = a_x·e^{jφ}·x_dqx with φ = θ_x + θ_e. Eq. (8) is evaluated as
φ = atan2(−Φ'_rα, Φ'_rβ): the single-argument tan⁻¹ printed in [2] loses the quadrant and
would flip the axes by π on half of the period. Eq. (12) repeats eq. (8) with θ_r in place of
θ_e; that is a typo (θ_x is an electrical angle, θ_r is mechanical) — eq. (8) is used.

The scalar functions (``alpha_beta``, ``to_dqx`` …) use only ``math`` so that the simulation
kernel can compile the very same code with numba.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SQRT_2_3 = math.sqrt(2.0 / 3.0)
SQRT_3_2 = math.sqrt(1.5)
RAMP = math.pi / 6.0  # half-width of the ideal trapezoid's ramp: 30° electrical


def trapezoid_unit(theta_e: float) -> float:
    """Ideal Φ'_ra(θ_e)/Φ_M of Fig. 2 in [2] (120° flat tops, 60° linear ramps) [-].

    Parameters
    ----------
    theta_e : float  Electrical angle [rad].
    """
    x = theta_e % (2.0 * math.pi)
    if x < RAMP:
        s = x / RAMP
    elif x < 5.0 * RAMP:
        s = 1.0
    elif x < 7.0 * RAMP:
        s = (math.pi - x) / RAMP
    elif x < 11.0 * RAMP:
        s = -1.0
    else:
        s = (x - 2.0 * math.pi) / RAMP
    return -s


def trapezoid_unit_slope(theta_e: float) -> float:
    """d/dθ_e of :func:`trapezoid_unit` (±1/30° on the ramps, 0 on the flats) [1/rad]."""
    x = theta_e % (2.0 * math.pi)
    if x < RAMP or x >= 11.0 * RAMP:
        return -1.0 / RAMP
    if 5.0 * RAMP <= x < 7.0 * RAMP:
        return 1.0 / RAMP
    return 0.0


def alpha_beta(x_a: float, x_b: float, x_c: float) -> tuple[float, float]:
    """Power-invariant αβ components of eq. (5) in [2] (units of x).

    Returns (x_α, x_β) = real and imaginary part of √(2/3)·(x_a + x_b·e^{j2π/3} + x_c·e^{−j2π/3}).
    """
    return SQRT_2_3 * (x_a - 0.5 * x_b - 0.5 * x_c), (x_b - x_c) / math.sqrt(2.0)


def zero_sequence(x_a: float, x_b: float, x_c: float) -> float:
    """Zero component x_0 = √(2/3)·(√2/2)·(x_a + x_b + x_c) of eq. (6) in [2] (units of x)."""
    return (x_a + x_b + x_c) / math.sqrt(3.0)


def abc_from_alpha_beta(x_alpha: float, x_beta: float, x_0: float) -> tuple[float, float, float]:
    """Inverse of eqs. (5)–(6) in [2]: (x_a, x_b, x_c) from x_α, x_β, x_0 (units of x)."""
    z = x_0 / math.sqrt(3.0)
    a = SQRT_2_3 * x_alpha + z
    b = SQRT_2_3 * (-0.5 * x_alpha) + x_beta / math.sqrt(2.0) + z
    c = SQRT_2_3 * (-0.5 * x_alpha) - x_beta / math.sqrt(2.0) + z
    return a, b, c


def dqx_gain_angle(phi_alpha: float, phi_beta: float, Phi_m: float) -> tuple[float, float]:
    """a_x of eq. (7) [-] and φ = θ_x + θ_e of eq. (8) [rad] in [2] from Φ'_rα, Φ'_rβ [Wb].

    φ = atan2(−Φ'_rα, Φ'_rβ) (four-quadrant form of eq. (8)); a_x = √(3/2)·Φ_m/|Φ'_rαβ|.
    """
    return SQRT_3_2 * Phi_m / math.hypot(phi_alpha, phi_beta), math.atan2(-phi_alpha, phi_beta)


def to_dqx(x_alpha: float, x_beta: float, a_x: float, phi: float) -> tuple[float, float]:
    """x_dqx = e^{−jφ}·x_αβ/a_x, the inverse of eq. (4) in [2] (units of x)."""
    c, s = math.cos(phi), math.sin(phi)
    return (c * x_alpha + s * x_beta) / a_x, (-s * x_alpha + c * x_beta) / a_x


def from_dqx(x_d: float, x_q: float, a_x: float, phi: float) -> tuple[float, float]:
    """x_αβ = a_x·e^{jφ}·x_dqx, eq. (4) in [2] with φ = θ_x + θ_e (units of x)."""
    c, s = math.cos(phi), math.sin(phi)
    return a_x * (c * x_d - s * x_q), a_x * (s * x_d + c * x_q)


@dataclass(frozen=True)
class DqxCoefficients:
    """a_x, θ_x and their θ_e-derivatives on a grid of electrical angles (Figs. 5–6 of [2]).

    Attributes
    ----------
    theta_e : numpy.ndarray    Electrical angle [rad].
    a_x : numpy.ndarray        Axis size, eq. (7) [-].
    theta_x : numpy.ndarray    Axis angle, eq. (8), wrapped to (−π, π] [rad].
    da_x : numpy.ndarray       a'_x = da_x/dθ_e [1/rad].
    dtheta_x : numpy.ndarray   θ'_x = dθ_x/dθ_e [-].
    """

    theta_e: np.ndarray
    a_x: np.ndarray
    theta_x: np.ndarray
    da_x: np.ndarray
    dtheta_x: np.ndarray


def dqx_coefficients(theta_e: np.ndarray, phi_abc: np.ndarray, dphi_abc: np.ndarray,
                     Phi_m: float) -> DqxCoefficients:
    """a_x, θ_x (eqs. (7)–(8) in [2]) and their derivatives for any back-EMF shape.

    Parameters
    ----------
    theta_e : numpy.ndarray   Electrical angles, shape (n,) [rad].
    phi_abc : numpy.ndarray   Φ'_ra, Φ'_rb, Φ'_rc at θ_e, shape (3, n) [Wb].
    dphi_abc : numpy.ndarray  Their derivatives d/dθ_e, shape (3, n) [Wb/rad].
    Phi_m : float             Trapezoid amplitude Φ_M [Wb].

    Returns
    -------
    DqxCoefficients
        With a'_x = −a_x·(Φ'·Φ'')/|Φ'|² and φ' = (Φ'_α·Φ''_β − Φ'_β·Φ''_α)/|Φ'|², θ'_x = φ' − 1.
    """
    theta_e = np.asarray(theta_e, dtype=float)
    fa, fb = _alpha_beta_arrays(np.asarray(phi_abc, dtype=float))
    ga, gb = _alpha_beta_arrays(np.asarray(dphi_abc, dtype=float))
    mag2 = fa**2 + fb**2
    a_x = SQRT_3_2 * Phi_m / np.sqrt(mag2)
    theta_x = np.angle(np.exp(1j * (np.arctan2(-fa, fb) - theta_e)))
    return DqxCoefficients(theta_e, a_x, theta_x, -a_x * (fa * ga + fb * gb) / mag2,
                           (fa * gb - fb * ga) / mag2 - 1.0)


def _alpha_beta_arrays(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return SQRT_2_3 * (x[0] - 0.5 * x[1] - 0.5 * x[2]), (x[1] - x[2]) / math.sqrt(2.0)


def ideal_phases(theta_e: np.ndarray, Phi_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Ideal-trapezoid Φ'_r,abc(θ_e) [Wb] and d/dθ_e [Wb/rad], each of shape (3, n).

    Parameters
    ----------
    theta_e : numpy.ndarray  Electrical angles [rad].
    Phi_m : float            Trapezoid amplitude Φ_M [Wb].
    """
    theta_e = np.atleast_1d(np.asarray(theta_e, dtype=float))
    shifts = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)
    f = np.array([[trapezoid_unit(t - s) for t in theta_e] for s in shifts])
    g = np.array([[trapezoid_unit_slope(t - s) for t in theta_e] for s in shifts])
    return Phi_m * f, Phi_m * g


def ideal_coefficients(theta_e: np.ndarray, Phi_m: float) -> DqxCoefficients:
    """a_x, θ_x and derivatives for the ideal trapezoid, the controller's choice in [2]."""
    phi, dphi = ideal_phases(theta_e, Phi_m)
    return dqx_coefficients(theta_e, phi, dphi, Phi_m)


def torque_constant_dqx(n_pp: int, Phi_m: float) -> float:
    """T_EL/i_qx = n_pp·√(3/2)·Φ_m, eq. (9) in [2] [N·m/A]."""
    return n_pp * SQRT_3_2 * Phi_m


def torque_constant_fig7(n_pp: int, Phi_m: float) -> float:
    """K_T = 2·n_pp·Φ_M of Fig. 7 in [2] [N·m/A].

    This is the six-step torque per ampere of *line current* (two phases conduct ±I on the flat
    tops: T = n_pp·(Φ_M·I + Φ_M·I)). The power-invariant i_qx of eq. (9) needs
    :func:`torque_constant_dqx` instead; using 2·n_pp·Φ_M to turn a torque reference into i_qx*
    would deliver only √(3/2)/2 ≈ 0.61 of the demanded torque.
    """
    return 2.0 * n_pp * Phi_m
