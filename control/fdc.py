"""Forced dynamic control (FDC) inner loops of section 3 in [1]: eqs. (7), (9), (10) and (14).

The direct-axis law (9) forces di_d/dt = (3/T_si)·(i_d,dem − i_d) with i_d,dem = 0 (eq. 10);
the acceleration law (14) forces dα/dt = (3/T_sα)·(α_dem − α) (eq. 13). Both laws use the
observer's speed estimate ω̂_r for the back-EMF terms, and (14) uses the observer's dΓ̂_L/dt
(L̂1); α itself comes from eq. (7) with Γ̂_L = L̂0. These scalar functions are the readable
reference; the compiled kernel in :mod:`sim.kernel` implements the same formulas.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from control.model import ModelCoefficients


def acceleration_estimate(i_d: float, i_q: float, Gamma_L_hat: float, c: ModelCoefficients) -> float:
    """Rotor acceleration α = (H + K·i_d)·i_q − M·Γ̂_L, eq. (7) in [1] [rad/s²].

    Parameters
    ----------
    i_d, i_q : float
        Measured dq currents [A].
    Gamma_L_hat : float
        Estimated total load torque L̂0 [N·m].
    c : ModelCoefficients
        Coefficients of eqs. (1)–(4).
    """
    return (c.H + c.K * i_d) * i_q - c.M * Gamma_L_hat


def direct_axis_voltage(
    i_d: float, i_q: float, omega_r: float, c: ModelCoefficients, T_si: float, i_d_dem: float = 0.0
) -> float:
    """FDC direct-axis voltage law, eq. (9) with i_d,dem = 0 (eq. (10)) in [1] [V].

    Parameters
    ----------
    i_d, i_q : float
        Measured dq currents [A].
    omega_r : float
        Rotor speed (observer estimate) [rad/s].
    c : ModelCoefficients
        Coefficients of eqs. (1)–(4).
    T_si : float
        5 % settling time of the direct-axis current [s].
    i_d_dem : float
        Demanded direct-axis current [A]; 0 for the vector-control condition (10).

    Returns
    -------
    float
        u_d = (1/F)·[(3/T_si)·(i_d,dem − i_d) + A·i_d − B·ω_r·i_q] [V].
    """
    return (3.0 / T_si * (i_d_dem - i_d) + c.A * i_d - c.B * omega_r * i_q) / c.F


def quadrature_axis_voltage(
    alpha_dem: float,
    alpha: float,
    i_d: float,
    i_q: float,
    omega_r: float,
    u_d: float,
    dGamma_L: float,
    c: ModelCoefficients,
    T_salpha: float,
) -> float:
    """FDC acceleration law, eq. (14) in [1] [V].

    Parameters
    ----------
    alpha_dem : float
        Demanded acceleration from the outer loop [rad/s²].
    alpha : float
        Acceleration of eq. (7) (with the observer's Γ̂_L) [rad/s²].
    i_d, i_q : float
        Measured dq currents [A].
    omega_r : float
        Rotor speed (observer estimate) [rad/s].
    u_d : float
        Direct-axis voltage of eq. (9) [V].
    dGamma_L : float
        Estimated load-torque derivative L̂1 [N·m/s].
    c : ModelCoefficients
        Coefficients of eqs. (1)–(4).
    T_salpha : float
        5 % settling time of the acceleration loop [s].

    Returns
    -------
    float
        u_q [V].
    """
    forced = 3.0 / T_salpha * (alpha_dem - alpha)
    coupling = c.K * i_q * (c.A * i_d - c.B * omega_r * i_q - c.F * u_d)
    return (
        (forced + coupling + c.M * dGamma_L) / (c.H + c.K * i_d)
        + c.C * omega_r * i_d + c.D * i_q + c.E * omega_r
    ) / c.G
