"""How far the FDC inner loop of [1] tolerates a wrong magnet flux: closed form.

The acceleration law (14) in [1] forces dα/dt = (3/T_sα)·(α_dem − α) by inverting the model of
eq. (2): it applies the back-EMF p·Ψ_PM·ω_r of the *model*. When the motor's flux is Ψ_PM·(1 − x)
(magnets x warmer, a datasheet value at another temperature), the q-axis current equation has the
unmodelled voltage p·x·Ψ_PM·ω_r; the law is proportional in α (no integral action, and the
observer of eq. (17) estimates a torque, not a voltage), so the loop settles where the forcing
term cancels it:

    Δα = α − α_dem = H·E·x·ω_r·T_sα/3,   H = 3·p·Ψ_PM/(2·J_r),   E = p·Ψ_PM/L_q,

an acceleration offset that grows with the speed. The FDSMC's demand is bounded by α_max (eq. (46)),
so once Δα > α_max it can no longer decelerate: the rotor runs away to the speed where the
inverter's voltage limit meets the back-EMF. With x < 0 (stronger magnets) the offset brakes: the
rotor cannot pass the speed where −Δα = α_max (it stalls short of θ_dem). The flux error the FDSMC
tolerates at its peak speed ω_p is therefore

    x_max = 3·α_max/(H·E·ω_p·T_sα).

On the real servo presets x_max is 3–9 %: a flux 5 % off (NdFeB loses ≈ 0.1 %/K, so magnets
50 K warmer than the datasheet's 20 °C) already runs the Siemens 1FT7044 preset away in simulation,
as this formula predicts (tests). A faster acceleration loop (smaller T_sα) or a slower move
(smaller ω_p) widens it; a tracking outer law that is not bounded by α_max (the tracked optimum)
is not limited by it. The cure is in the inner loop: the q-axis voltage-mismatch estimate of
:func:`control.fdsmc.fdc.voltage_mismatch` (controller.T_dv) removes the steady offset; with
T_dv = 1 ms the real presets pass every check for flux errors of ±10–20 % (docs/energy.md).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from pmsm_commissioning.control.fdsmc.model import ModelCoefficients


def alpha_offset(c: ModelCoefficients, x: float, omega_r: float, T_salpha: float) -> float:
    """Steady acceleration offset Δα [rad/s²] of the FDC with the flux Ψ_PM·(1 − x) (module docstring).

    Parameters
    ----------
    c : ModelCoefficients  The controller's model (H, E).
    x : float              Relative flux error of the motor, (Ψ_model − Ψ_motor)/Ψ_model [-].
    omega_r : float        Rotor speed [rad/s].
    T_salpha : float       Settling time of the acceleration loop, eq. (13) in [1] [s].
    """
    return c.H * c.E * x * omega_r * T_salpha / 3.0


def flux_tolerance(c: ModelCoefficients, alpha_max: float, omega_p: float, T_salpha: float) -> float:
    """Return the relative flux error x_max [-] at which Δα reaches α_max at ω_p (module docstring).

    Parameters
    ----------
    c : ModelCoefficients  The controller's model (H, E).
    alpha_max : float      α_max of eq. (46) in [1] [rad/s²].
    omega_p : float        Peak speed of the profile [rad/s].
    T_salpha : float       Settling time of the acceleration loop [s].
    """
    return 3.0 * alpha_max / (c.H * c.E * omega_p * T_salpha)


def stall_speed(c: ModelCoefficients, alpha_max: float, x: float, T_salpha: float) -> float:
    """Speed [rad/s] where the offset of a stronger flux (x < 0) cancels α_max: the FDSMC stalls there."""
    return 3.0 * alpha_max / (c.H * c.E * abs(x) * T_salpha)


__all__ = ["alpha_offset", "flux_tolerance", "stall_speed"]
