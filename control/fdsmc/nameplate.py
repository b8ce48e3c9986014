"""Consistency of a motor's nameplate: check that Ψ_PM, Kt, rated torque, power, speed and voltage agree.

A typing slip in one nameplate value (Ke = 300 V/krpm on an 18 N·m servo) otherwise passes
silently into every derivation. Each check compares two routes to the same quantity, in the
amplitude-invariant dq frame of [1] (Γ = (3/2)·p·Ψ_PM·i_q, eq. (5); |u_dq| = phase-voltage peak).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.model import available_voltage
from pmsm_commissioning.control.fdsmc.params import Motor

#: Relative disagreement tolerated between two routes to the same nameplate quantity [-]:
#: catalogue values are typical values, commonly ±10 %.
NAMEPLATE_TOLERANCE = 0.10


@dataclass(frozen=True)
class Disagreement:
    """Two nameplate routes to one quantity that differ beyond the tolerance.

    Attributes
    ----------
    quantity : str   What is compared.
    value : float    From the entered data [unit].
    other : float    From the other route, or the limit [unit].
    unit : str
    text : str       One sentence with both values.
    """

    quantity: str
    value: float
    other: float
    unit: str
    text: str


def kt_from_psi(motor: Motor) -> float:
    """Torque constant (3/2)·√2·p·Ψ_PM [N·m per A_rms], eq. (5) in [1] with i_q = √2·I_rms."""
    return 1.5 * math.sqrt(2.0) * motor.p * motor.psi_pm


def emf_at_rated_speed(motor: Motor) -> float:
    """Line-to-line RMS back-EMF at the rated speed ω_b, √(3/2)·p·ω_b·Ψ_PM [V]."""
    return math.sqrt(1.5) * motor.p * motor.omega_b * motor.psi_pm


def nameplate_consistency(motor: Motor, Kt: float | None = None, T_N: float | None = None
                          ) -> tuple[Disagreement, ...]:
    """Cross-check the nameplate; one :class:`Disagreement` per check that fails.

    Parameters
    ----------
    motor : Motor
    Kt : float, optional
        Datasheet torque constant [N·m/A_rms], compared with (3/2)·√2·p·Ψ_PM.
    T_N : float, optional
        Datasheet rated torque [N·m], compared with P_r/ω_b; default P_r/ω_b.

    Returns
    -------
    tuple of Disagreement
        Checks: Kt vs Ψ_PM; T_N vs P_r/ω_b; T_N ≤ Γ_max; back-EMF at ω_b ≤ V_0; |u_dq| at the
        rated point (ω_b, T_N) ≤ √(2/3)·V_0 — each beyond :data:`NAMEPLATE_TOLERANCE`.
    """
    tol = NAMEPLATE_TOLERANCE
    out: list[Disagreement] = []
    T_P = motor.P_r / motor.omega_b
    if Kt is not None and abs(Kt - kt_from_psi(motor)) > tol * Kt:
        out.append(Disagreement("Kt", kt_from_psi(motor), Kt, "N·m/A_rms",
                                f"Ψ_PM = {motor.psi_pm:.4g} Wb with p = {motor.p} gives Kt = {kt_from_psi(motor):.4g} "
                                f"N·m/A_rms, the datasheet says {Kt:.4g} N·m/A_rms."))
    if T_N is not None and abs(T_N - T_P) > tol * T_N:
        out.append(Disagreement("rated torque", T_P, T_N, "N·m",
                                f"P_r/ω_b = {T_P:.4g} N·m but the rated torque entered is {T_N:.4g} N·m."))
    T_rated = T_N if T_N is not None else T_P
    if T_rated > motor.Gamma_max * (1.0 + tol):
        out.append(Disagreement("peak torque", T_rated, motor.Gamma_max, "N·m",
                                f"Rated torque {T_rated:.4g} N·m exceeds the peak torque "
                                f"Γ_max = {motor.Gamma_max:g} N·m."))
    emf = emf_at_rated_speed(motor)
    if emf > motor.V_0 * (1.0 + tol):
        out.append(Disagreement("back-EMF", emf, motor.V_0, "V",
                                f"Back-EMF at the rated speed is {emf:.4g} V (LL rms) > V_0 = {motor.V_0:g} V: "
                                "Ψ_PM/Ke, p or the rated speed is wrong."))
    u = _rated_voltage(motor, T_rated)
    if emf <= motor.V_0 * (1.0 + tol) and u > available_voltage(motor) * (1.0 + tol):
        out.append(Disagreement("rated voltage", u, available_voltage(motor), "V",
                                f"|u_dq| at the rated point is {u:.4g} V > √(2/3)·V_0 = "
                                f"{available_voltage(motor):.4g} V: R_s or L is too large for V_0."))
    return tuple(out)


def _rated_voltage(motor: Motor, torque: float) -> float:
    """Steady |u_dq| at ω_b and ``torque`` with i_d = 0, eqs. (1)–(2) in [1] [V]."""
    i_q = torque / (1.5 * motor.p * motor.psi_pm)
    w_e = motor.p * motor.omega_b
    return math.hypot(motor.R_s * i_q + w_e * motor.psi_pm, w_e * motor.L_q * i_q)


def rated_from_inverter(motor: Motor, V_dc: float, i_max: float) -> tuple[float, float, float]:
    """Rated values a robotics datasheet lacks, derived from the inverter: (V_0 [V], P_r [W], ω_b [rad/s]).

    * V_0 = V_dc/√2: the largest line-to-line rms voltage of a space-vector modulated inverter
      (√(2/3)·V_0 = V_dc/√3, the dq voltage limit of eqs. (1)–(2) in [1]);
    * ω_b: the speed at which the steady voltage for the peak torque at i_d = 0,
      |u_dq| = √((R_s·i + p·ω·Ψ_PM)² + (p·ω·L_q·i)²) from eqs. (1)–(2), reaches V_dc/√3, with
      i = min(i_max, Γ_max/k_t) and k_t = 3·p·Ψ_PM/2 (eq. (5));
    * P_r = Γ_lim·ω_b with Γ_lim = k_t·i (the peak-torque power at that speed; not a thermal rating).

    Raises
    ------
    ParameterError
        Without a DC link (V_dc = 0), or when R_s·i alone exceeds V_dc/√3.
    """
    if V_dc <= 0.0:
        raise ParameterError(f"controller.V_dc = {V_dc!r} V is out of range for derived rated values: "
                             "allowed > 0 V (or give motor.V_0, motor.P_r and motor.omega_b)")
    k_t = 1.5 * motor.p * motor.psi_pm
    i = min(i_max if i_max > 0.0 else math.inf, motor.Gamma_max / k_t)
    u_max, a, b = V_dc / math.sqrt(3.0), motor.p * motor.psi_pm, motor.p * motor.L_q * i
    drop = motor.R_s * i
    if drop >= u_max:
        raise ParameterError(f"motor.R_s = {motor.R_s!r} Ω drops {drop:.4g} V at {i:.4g} A: allowed < V_dc/√3 = "
                             f"{u_max:.4g} V to derive the rated speed (or give motor.omega_b)")
    c2 = a * a + b * b
    omega_b = (-drop * a + math.sqrt((drop * a) ** 2 - c2 * (drop * drop - u_max * u_max))) / c2
    return V_dc / math.sqrt(2.0), k_t * i * omega_b, omega_b


__all__ = ["NAMEPLATE_TOLERANCE", "Disagreement", "emf_at_rated_speed", "kt_from_psi", "nameplate_consistency",
           "rated_from_inverter"]
