"""Energy of the FDSMC velocity profile on the user's drive, and the acceleration that minimises it.

The paper chooses the profile of section 4.2 in [1] to minimise the friction loss. On servo drives
the copper loss dominates, and it falls with the acceleration: with the same T_m, a lower α makes
T_a longer and the peak torque lower. With ideal tracking of the profile of eqs. (57)–(60)
(constant α for T_a, cruise at ω_p, exponential decay ω_p·e^(−τ/T_a) along the sloped segment with
T_c = T_a, eq. (59)) and Γ = J·dω/dt + F_v·ω (eq. (4b), J = J_r + J_L), the losses are, in closed form,

    friction  F_v·∫ω²  = F_v·ω_p²·(T_a/3 + (T_m − 4·T_a) + T_a/2)
    copper    a·∫Γ²    = a·[α²·(J²·T_a + J·F_v·T_a² + F_v²·T_a³/3) + F_v²·ω_p²·(T_m − 4·T_a)
                            + (F_v − J/T_a)²·ω_p²·T_a/2]

with a = (3/2)·R_s/k_t², k_t = (3/2)·p·Ψ_PM (eq. (5) at i_d = 0), the decay integrated to rest. A
constant external load adds a·Γ_Le²·T + 2·a·Γ_Le·F_v·Δθ + Γ_Le·Δθ, the same for every α.

:func:`min_energy_alpha` returns the α in [α_lo, α_hi] that minimises friction + copper
(:func:`scipy.optimize.minimize_scalar`, bounded), α_lo being the smallest α for which T_m is
feasible (T_m = T_m,min(α)) and α_hi the drive's torque-limited α_max.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc.model import torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import C_57, peak_speed

#: How far above the feasibility bound α_lo the search starts [-] (at α_lo the cruise vanishes).
ALPHA_LO_MARGIN = 1.02


@dataclass(frozen=True)
class ProfileEnergy:
    """Losses of the ideally tracked FDSMC profile [J] (to rest, external load excluded).

    Attributes
    ----------
    friction : float    F_v·∫ω² dt [J].
    copper : float      (3/2)·R_s·∫i_q² dt at i_d = 0 [J].
    """

    friction: float
    copper: float

    @property
    def total(self) -> float:
        """Friction + copper [J]: the net electrical input of a rest-to-rest move without external load."""
        return self.friction + self.copper


def profile_energy(params: DriveParams, alpha: float) -> ProfileEnergy:
    """Losses of the profile of eqs. (57)–(60) in [1] at acceleration ``alpha`` [rad/s²] (see module doc)."""
    m, T_m = params.motor, params.manoeuvre.T_m
    J, F_v = params.J_total, params.load.F_v
    w_p = peak_speed(params.manoeuvre.theta_dem, alpha, T_m)
    T_a = w_p / alpha
    cruise = T_m - 4.0 * T_a
    a = 1.5 * m.R_s / torque_constant(m) ** 2
    friction = F_v * w_p**2 * (T_a / 3.0 + cruise + T_a / 2.0)
    copper = a * (alpha**2 * (J**2 * T_a + J * F_v * T_a**2 + F_v**2 * T_a**3 / 3.0)
                  + F_v**2 * w_p**2 * cruise + (F_v - J / T_a) ** 2 * w_p**2 * T_a / 2.0)
    return ProfileEnergy(friction, copper)


def feasible_alpha(params: DriveParams) -> float:
    """Smallest α [rad/s²] for which T_m is feasible: T_m = T_m,min(α) = √(2·C_57·|Δθ|/α), eq. (60) in [1]."""
    return 2.0 * C_57 * abs(params.manoeuvre.theta_dem) / params.manoeuvre.T_m**2


def min_energy_alpha(params: DriveParams, alpha_hi: float) -> float:
    """Return the α in [ALPHA_LO_MARGIN·α_lo, α_hi] minimising :func:`profile_energy` [rad/s²].

    Returns ``alpha_hi`` itself when T_m is not feasible below it (α_lo·margin ≥ α_hi).
    """
    lo = ALPHA_LO_MARGIN * feasible_alpha(params)
    if lo >= alpha_hi:
        return alpha_hi
    from scipy.optimize import minimize_scalar  # 0.1 s of import: only where the rule is min_energy

    res = minimize_scalar(lambda a: profile_energy(params, a).total, bounds=(lo, alpha_hi), method="bounded",
                          options={"xatol": 1e-6 * lo})
    best = float(res.x)
    return alpha_hi if profile_energy(params, alpha_hi).total <= profile_energy(params, best).total else best


__all__ = ["ALPHA_LO_MARGIN", "ProfileEnergy", "feasible_alpha", "min_energy_alpha", "profile_energy"]
