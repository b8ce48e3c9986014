"""Model coefficients A…M of the PMSM state equations, eqs. (1)–(4) in [1].

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper (``../shared/papers``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.arrays import FloatOrArray
from pmsm_commissioning.control.common.jit import jitable
from pmsm_commissioning.control.fdsmc.params import Motor


@dataclass(frozen=True)
class ModelCoefficients:
    """Constant coefficients of eqs. (1)–(4) in [1].

    Attributes
    ----------
    A : float  R_s/L_d [1/s]
    B : float  p·L_q/L_d [-]
    C : float  p·L_d/L_q [-]
    D : float  R_s/L_q [1/s]
    E : float  p·Ψ_PM/L_q [A/rad]
    F : float  1/L_d [1/H]
    G : float  1/L_q [1/H]
    H : float  3·p·Ψ_PM/(2·J_r) [rad/s²/A]
    K : float  3·p·(L_d − L_q)/(2·J_r) [rad/s²/A²]
    M : float  1/J_r [1/(kg·m²)]
    """

    A: float
    B: float
    C: float
    D: float
    E: float
    F: float
    G: float
    H: float
    K: float
    M: float


def model_coefficients(motor: Motor) -> ModelCoefficients:
    """Coefficients A…M of eqs. (1)–(4) in [1] (the list below eq. (4)).

    Parameters
    ----------
    motor : Motor
        Motor data [SI].

    Returns
    -------
    ModelCoefficients
        The ten coefficients, each in the unit given on the class.
    """
    m = motor
    return ModelCoefficients(
        A=m.R_s / m.L_d,
        B=m.p * m.L_q / m.L_d,
        C=m.p * m.L_d / m.L_q,
        D=m.R_s / m.L_q,
        E=m.p * m.psi_pm / m.L_q,
        F=1.0 / m.L_d,
        G=1.0 / m.L_q,
        H=3.0 * m.p * m.psi_pm / (2.0 * m.J_r),
        K=3.0 * m.p * (m.L_d - m.L_q) / (2.0 * m.J_r),
        M=1.0 / m.J_r,
    )


@jitable
def electromagnetic_torque(p: float, psi_pm: float, L_d: float, L_q: float, i_d: FloatOrArray,
                          i_q: FloatOrArray) -> FloatOrArray:
    """Electromagnetic torque Γ_em = (3/2)·p·(Ψ_PM + (L_d − L_q)·i_d)·i_q, eq. (5) in [1] [N·m].

    The one implementation of eq. (5): the compiled kernel, the plain-Python reference, the
    figures and the drive-log identification call it (scalars or numpy arrays).

    Parameters
    ----------
    p : float
        Pole pairs [-].
    psi_pm : float
        Permanent-magnet flux linkage Ψ_PM [Wb].
    L_d, L_q : float
        d- and q-axis inductances [H].
    i_d, i_q : float or numpy.ndarray
        d- and q-axis currents [A] (amplitude-invariant dq), both scalars or both arrays.

    Returns
    -------
    float or numpy.ndarray
        Γ_em [N·m].
    """
    return 1.5 * p * (psi_pm + (L_d - L_q) * i_d) * i_q


def torque_constant(motor: Motor) -> float:
    """Torque per quadrature-axis ampere at i_d = 0, 3·p·Ψ_PM/2 from eq. (5) in [1] [N·m/A]."""
    return 1.5 * motor.p * motor.psi_pm


def available_voltage(motor: Motor) -> float:
    """Largest dq voltage magnitude the inverter can apply at rated voltage [V].

    The dq transform of [1] is amplitude-invariant (eq. (58) uses the factor 1.5), so the voltage
    vector magnitude equals the phase-voltage peak, √2·V_0/√3 for a line-to-line RMS rating V_0.
    """
    return math.sqrt(2.0 / 3.0) * motor.V_0
