"""Conventional linear state-feedback comparator, eqs. (61)–(62) in [1].

Erratum (eq. (62) in [1]). Printed as u = g1·(θ_rdem − θ̂_r) + g2·ω̂_r, the velocity feedback
has the wrong sign: with the plant θ̈ = u the closed loop is s² − g2·s + g1 (unstable, poles in
the right half plane). The characteristic polynomial s² + g2·s + g1 of eq. (61) needs
u = g1·(θ_rdem − θ̂_r) − g2·ω̂_r, which is implemented here.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.common.jit import jitable


@dataclass(frozen=True)
class ConventionalGains:
    """Gains of eq. (61) in [1]: double pole at s = −a, a = 5.6/T_m (Dodds 2 % formula, n = 2).

    Attributes
    ----------
    g1 : float  784/(25·T_m²) [1/s²]
    g2 : float  56/(5·T_m) [1/s]
    a : float   Pole magnitude 5.6/T_m [1/s]
    """

    g1: float
    g2: float
    a: float


def conventional_gains(T_m: float) -> ConventionalGains:
    """Coincident-pole gains of eq. (61) in [1] for 2 % settling time ``T_m`` [s]."""
    a = 4.0 * (3.0 + 2.0 * 2) / (5.0 * T_m)
    return ConventionalGains(g1=a * a, g2=2.0 * a, a=a)


def conventional_law(
    theta_dem: float, theta_hat: float, omega_hat: float, gains: ConventionalGains
) -> float:
    """Demanded acceleration u = g1·(θ_rdem − θ̂_r) − g2·ω̂_r, eq. (62) in [1] sign-corrected.

    Parameters
    ----------
    theta_dem : float  Demanded angle [rad].
    theta_hat : float  Estimated angle [rad].
    omega_hat : float  Estimated speed [rad/s].
    gains : ConventionalGains

    Returns
    -------
    float
        Demanded acceleration α_dem [rad/s²].
    """
    return conventional_demand(theta_dem, theta_hat, omega_hat, gains.g1, gains.g2)


@jitable
def conventional_demand(theta_dem: float, theta_hat: float, omega_hat: float, g1: float, g2: float) -> float:
    """g1·(θ_rdem − θ̂_r) − g2·ω̂_r [rad/s²]: :func:`conventional_law` on scalars (numba-compilable)."""
    return g1 * (theta_dem - theta_hat) - g2 * omega_hat


@jitable
def tracking_demand(theta_ref: float, omega_ref: float, alpha_ref: float, theta_hat: float, omega_hat: float,
                    g1: float, g2: float) -> float:
    """Return α_ref + g1·(θ_ref − θ̂_r) + g2·(ω_ref − ω̂_r) [rad/s²]: eq. (62) tracking a reference move.

    Eq. (62) sign-corrected, acting on the error from a time-varying reference move, its acceleration fed
    forward (numba-compilable).

    With θ_ref = θ_rdem constant and ω_ref = α_ref = 0 it is :func:`conventional_demand`.
    """
    return alpha_ref + g1 * (theta_ref - theta_hat) + g2 * (omega_ref - omega_hat)


def friction_energy_conventional(F_v: float, delta_theta: float, T_m: float) -> float:
    """Frictional energy of the ideal critically damped step response, F_v·Δθ²·a/4 [J].

    With ω(t) = Δθ·a²·t·e^(−a·t), ∫ω² dt = Δθ²·a/4 (a = 5.6/T_m).
    """
    return F_v * delta_theta**2 * conventional_gains(T_m).a / 4.0
