"""Unit conversion at the edge: nameplate units → SI. The only place non-SI units are converted.

A preset or ``--set`` key may carry a unit suffix instead of the SI field name, e.g.
``omega_b_rpm: 1432``, ``L_d_mH: 5.4``, ``P_r_kW: 12``, or ``Ke_Vrms_krpm`` instead of ``psi_pm``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass


def rpm_to_rad_s(n_rpm: float) -> float:
    """Speed [rpm] → [rad/s]: n·2π/60."""
    return n_rpm * 2.0 * math.pi / 60.0


def rad_s_to_rpm(omega: float) -> float:
    """Speed [rad/s] → [rpm]."""
    return omega * 60.0 / (2.0 * math.pi)


def mH_to_H(L_mH: float) -> float:
    """Inductance [mH] → [H]."""
    return L_mH * 1e-3


def kW_to_W(P_kW: float) -> float:
    """Power [kW] → [W]."""
    return P_kW * 1e3


def ms_to_s(t_ms: float) -> float:
    """Time [ms] → [s]."""
    return t_ms * 1e-3


def s_to_ms(t: float) -> float:
    """Time [s] → [ms]."""
    return t * 1e3


def kHz_to_Hz(f_kHz: float) -> float:
    """Frequency [kHz] → [Hz]."""
    return f_kHz * 1e3


def deg_to_rad(x_deg: float) -> float:
    """Angle [deg] → [rad]."""
    return math.radians(x_deg)


def rev_to_rad(x_rev: float) -> float:
    """Angle [rev] → [rad]."""
    return x_rev * 2.0 * math.pi


def ke_vrms_krpm_to_psi_pm(Ke_Vrms_krpm: float, p: int) -> float:
    """Back-EMF constant Ke [V_rms line-to-line per 1000 rpm] → Ψ_PM [Wb] (amplitude-invariant dq).

    The phase back-EMF peak at mechanical speed ω is p·ω·Ψ_PM, and the line-to-line RMS value is
    √3/√2 times the phase peak, so Ke/1000 rpm = √(3/2)·p·Ψ_PM·(2π·1000/60), i.e.
    Ψ_PM = Ke·√(2/3) / (p·2π·1000/60).

    Parameters
    ----------
    Ke_Vrms_krpm : float  Back-EMF constant [V_rms(LL)/krpm].
    p : int               Pole pairs [-].

    Returns
    -------
    float
        Ψ_PM [Wb].
    """
    return Ke_Vrms_krpm * math.sqrt(2.0 / 3.0) / (p * rpm_to_rad_s(1000.0))


def kgcm2_to_kgm2(J_kgcm2: float) -> float:
    """Inertia [kg·cm²] → [kg·m²]."""
    return J_kgcm2 * 1e-4


@dataclass(frozen=True)
class Alias:
    """A unit-suffixed input key that maps onto an SI field."""

    field: str
    convert: Callable[[float], float]
    unit: str


#: Unit-suffixed keys accepted per section, mapping to the SI field and its converter.
ALIASES: dict[str, dict[str, Alias]] = {
    "motor": {
        "omega_b_rpm": Alias("omega_b", rpm_to_rad_s, "rpm"),
        "P_r_kW": Alias("P_r", kW_to_W, "kW"),
        "L_d_mH": Alias("L_d", mH_to_H, "mH"),
        "L_q_mH": Alias("L_q", mH_to_H, "mH"),
        "J_r_kgcm2": Alias("J_r", kgcm2_to_kgm2, "kg·cm²"),
    },
    "load": {"J_L_kgcm2": Alias("J_L", kgcm2_to_kgm2, "kg·cm²")},
    "controller": {
        "T_si_ms": Alias("T_si", ms_to_s, "ms"),
        "T_salpha_ms": Alias("T_salpha", ms_to_s, "ms"),
        "T_so_ms": Alias("T_so", ms_to_s, "ms"),
        "f_s_kHz": Alias("f_s", kHz_to_Hz, "kHz"),
    },
    # BLDC speed-control mode (control/bldc/params.py); nested lists use the dotted path
    "machine": {"L_s_minus_M_s_mH": Alias("L_s_minus_M_s", mH_to_H, "mH")},
    "inverter": {"f_s_kHz": Alias("f_s", kHz_to_Hz, "kHz")},
    "gains": {"eps_lambda_rpm": Alias("eps_lambda", rpm_to_rad_s, "rpm")},
    "scenario.cases": {
        "omega_0_rpm": Alias("omega_0", rpm_to_rad_s, "rpm"),
        "omega_ref_rpm": Alias("omega_ref", rpm_to_rad_s, "rpm"),
        "band_recovery_rpm": Alias("band_recovery", rpm_to_rad_s, "rpm"),
        "t_window_ms": Alias("t_window", ms_to_s, "ms"),
    },
    "manoeuvre": {
        "theta_dem_deg": Alias("theta_dem", deg_to_rad, "deg"),
        "theta_dem_rev": Alias("theta_dem", rev_to_rad, "rev"),
    },
}

#: Keys needing more than one field to convert (Ke needs the pole pairs).
KE_KEY = "Ke_Vrms_krpm"

def kt_nm_per_arms_to_psi_pm(Kt_Nm_Arms: float, p: int) -> float:
    """Torque constant Kt [N·m per A_rms] → Ψ_PM [Wb] (amplitude-invariant dq, i_d = 0).

    Γ = (3/2)·p·Ψ_PM·i_q with i_q the phase-current peak √2·I_rms (eq. (5) in [1]), so
    Kt = (3/2)·√2·p·Ψ_PM.
    """
    return Kt_Nm_Arms / (1.5 * math.sqrt(2.0) * p)


def psi_pm_to_kt_nm_per_arms(psi_pm: float, p: int) -> float:
    """Ψ_PM [Wb] → Kt [N·m per A_rms]; inverse of :func:`kt_nm_per_arms_to_psi_pm`."""
    return psi_pm * 1.5 * math.sqrt(2.0) * p


def psi_pm_to_ke_vrms_krpm(psi_pm: float, p: int) -> float:
    """Ψ_PM [Wb] → Ke [V_rms line-to-line per krpm]; inverse of :func:`ke_vrms_krpm_to_psi_pm`."""
    return psi_pm * p * rpm_to_rad_s(1000.0) / math.sqrt(2.0 / 3.0)


def H_to_mH(L: float) -> float:
    """Inductance [H] → [mH] (display): inverse of :func:`mH_to_H`."""
    return L * (1.0 / mH_to_H(1.0))


def Hz_to_kHz(f: float) -> float:
    """Frequency [Hz] → [kHz] (display): inverse of :func:`kHz_to_Hz`."""
    return f * (1.0 / kHz_to_Hz(1.0))


#: SI unit of every input field of the position-drive parameter model (control/fdsmc/params.py), as
#: written in exported parameter files (``units`` section).
SI_UNITS: dict[str, dict[str, str]] = {
    "motor": {"V_0": "V", "P_r": "W", "omega_b": "rad/s", "Gamma_max": "N·m", "psi_pm": "Wb", "L_d": "H",
              "L_q": "H", "R_s": "Ω", "p": "-", "J_r": "kg·m²"},
    "load": {"J_L": "kg·m²", "F_v": "N·m·s/rad", "Gamma_Le": "N·m", "steps": "t: s, Gamma_Le: N·m",
             "Gamma_Le_ramp": "N·m/s"},
    "controller": {"T_si": "s", "T_salpha": "s", "T_so": "s", "K": "s/rad", "T_c": "s or 'T_a'",
                   "alpha_max_rule": "-", "f_s": "Hz or 'continuous'", "delay_samples": "samples",
                   "V_dc": "V", "i_max": "A"},
    "manoeuvre": {"theta_dem": "rad", "T_m": "s"},
}
