"""Forced dynamic control (FDC) inner loops of section 3 in [1]: eqs. (7), (9), (10) and (14).

The direct-axis law (9) forces di_d/dt = (3/T_si)·(i_d,dem − i_d) with i_d,dem = 0 (eq. 10);
the acceleration law (14) forces dα/dt = (3/T_sα)·(α_dem − α) (eq. 13). Both laws use the
observer's speed estimate ω̂_r for the back-EMF terms, and (14) uses the observer's dΓ̂_L/dt
(L̂1); α itself comes from eq. (7) with Γ̂_L = L̂0. These scalar functions are the readable
reference API; the scalar forms at the end are the single implementation, inlined by the compiled
kernel in :mod:`sim.fdsmc.kernel`.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from pmsm_commissioning.control.common.jit import jitable
from pmsm_commissioning.control.fdsmc.model import ModelCoefficients


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
    return acceleration(i_d, i_q, Gamma_L_hat, c.H, c.K, c.M)


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
    return u_d_law(i_d, i_q, omega_r, c.A, c.B, c.F, T_si, i_d_dem)


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
    return u_q_law(alpha_dem, alpha, i_d, i_q, omega_r, u_d, dGamma_L, c.A, c.B, c.C, c.D, c.E, c.F, c.G,
                   c.H, c.K, c.M, T_salpha)


# ---- scalar forms: numba-compilable, inlined by the compiled kernel (sim.fdsmc.kernel) -------------------


@jitable
def acceleration(i_d: float, i_q: float, L0: float, H: float, K: float, M: float) -> float:
    """α = (H + K·i_d)·i_q − M·L̂0, eq. (7) in [1] [rad/s²] (scalar coefficients)."""
    return (H + K * i_d) * i_q - M * L0


@jitable
def u_d_law(i_d: float, i_q: float, omega: float, A: float, B: float, F: float, T_si: float,
            i_d_dem: float = 0.0) -> float:
    """u_d of eq. (9) in [1] [V] (scalar coefficients)."""
    return (3.0 / T_si * (i_d_dem - i_d) + A * i_d - B * omega * i_q) / F


@jitable
def u_q_law(alpha_dem: float, alpha: float, i_d: float, i_q: float, omega: float, u_d: float, L1: float,
            A: float, B: float, C: float, D: float, E: float, F: float, G: float, H: float, K: float,
            M: float, T_salpha: float) -> float:
    """u_q of eq. (14) in [1] [V] (scalar coefficients)."""
    forced = 3.0 / T_salpha * (alpha_dem - alpha)
    coupling = K * i_q * (A * i_d - B * omega * i_q - F * u_d)
    return ((forced + coupling + M * L1) / (H + K * i_d) + C * omega * i_d + D * i_q + E * omega) / G


@jitable
def fdc_voltages(alpha_dem: float, i_d: float, i_q: float, omega: float, L0: float, L1: float,
                 A: float, B: float, C: float, D: float, E: float, F: float, G: float, H: float, K: float,
                 M: float, T_si: float, T_salpha: float) -> tuple[float, float, float]:
    """(u_d, u_q, α): the FDC inner loops of eqs. (7), (9), (10), (14) in [1] for one sample."""
    alpha = acceleration(i_d, i_q, L0, H, K, M)
    u_d = u_d_law(i_d, i_q, omega, A, B, F, T_si)
    u_q = u_q_law(alpha_dem, alpha, i_d, i_q, omega, u_d, L1, A, B, C, D, E, F, G, H, K, M, T_salpha)
    return u_d, u_q, alpha


@jitable
def voltage_mismatch(dv_hat: float, i_q: float, i_q_model: float, gain: float, beta: float) -> float:
    """Return the updated estimate of the q-axis voltage the model of eq. (2) in [1] misses [V].

    The paper's acceleration law (14) inverts eq. (2) with the model's R_s, L_q and Ψ_PM and is
    proportional in α: a voltage the model misses — p·ΔΨ_PM·ω_r of a flux a few per cent off, ΔR_s·i_q
    — leaves the acceleration offset by H·(that voltage)/L_q·T_sα/3 (:mod:`control.fdsmc.flux_tolerance`),
    which the FDSMC's bounded demand cannot overcome. Not in [1]: each sample compares the measured
    i_q with the model's prediction over the last sample (:func:`control.fdsmc.inverter.predict_currents`,
    the voltages that were applied), converts the difference to volts with the prediction's gain
    γ_q·G [A/V] and low-pass filters it, d̂ ← d̂ + β·((i_q − i_q,model)/(γ_q·G) − d̂); the FDC subtracts
    d̂ from its u_q. With the exact model the difference is only the sensors' noise (and the speed's change
    within a sample, which the prediction holds constant), so the linearised loop of
    :mod:`control.fdsmc.loop_analysis` (K limit) leaves it out; the noise gain of
    :mod:`control.fdsmc.noise` (standstill ripple, K_noise) includes it, since the estimate feeds the
    current noise back against itself, and so does the design's verification by simulation.

    Parameters
    ----------
    dv_hat : float     The estimate so far [V].
    i_q : float        The measured i_q [A].
    i_q_model : float  The model's prediction of this i_q from the last sample [A].
    gain : float       γ_q·G, the predicted i_q's change per volt of u_q held over one sample [A/V].
    beta : float       Filter factor T_s/T_dv (≤ 1) [-].
    """
    return dv_hat + beta * ((i_q - i_q_model) / gain - dv_hat)


def mismatch_filter_factor(T_dv: float, f_s: float) -> float:
    """β = T_s/T_dv ≤ 1 of :func:`voltage_mismatch` for the sample rate f_s [Hz] (0 when T_dv = 0: none) [-]."""
    return min(1.0, 1.0 / (f_s * T_dv)) if T_dv > 0.0 else 0.0
