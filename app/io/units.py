"""Unit conversion at the edge: nameplate units → SI. The only place non-SI units are converted.

A preset or ``--set`` key may carry a unit suffix instead of the SI field name, e.g.
``omega_b_rpm: 1432``, ``L_d_mH: 5.4``, ``P_r_kW: 12``, or ``Ke_Vrms_krpm`` instead of ``psi_pm``.
Which units a field accepts is declared once, next to the field (its
:class:`~control.common.checks.FieldSpec`); this module only knows how to convert each unit
(:data:`CONVERSIONS`) and derives the loader's key table :data:`ALIASES` and the exported
:data:`SI_UNITS` from the specs.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from pmsm_commissioning.app.io.modes import MODE_CLASSES as _MODE_CLASSES
from pmsm_commissioning.control.common.checks import FieldSpec, ParameterError, field_specs, range_text


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


def W_to_kW(P: float) -> float:
    """Power [W] → [kW]."""
    return P * 1e-3


def H_to_mH(L: float) -> float:
    """Inductance [H] → [mH]."""
    return L * 1e3


def Hz_to_kHz(f: float) -> float:
    """Frequency [Hz] → [kHz]."""
    return f * 1e-3


def rad_to_deg(x: float) -> float:
    """Angle [rad] → [deg]."""
    return math.degrees(x)


def rad_to_rev(x: float) -> float:
    """Angle [rad] → [rev]."""
    return x / (2.0 * math.pi)


def kgm2_to_kgcm2(J: float) -> float:
    """Inertia [kg·m²] → [kg·cm²]."""
    return J * 1e4


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


def arms_to_amplitude(I_rms: float) -> float:
    """RMS value of a sinusoidal phase current [A_rms] → its amplitude [A] (the dq current scale): ×√2."""
    return I_rms * math.sqrt(2.0)


def amplitude_to_arms(I: float) -> float:
    """Amplitude of a sinusoidal phase current [A] → its RMS value [A_rms]: inverse of :func:`arms_to_amplitude`."""
    return I / math.sqrt(2.0)


def _identity(x: float) -> float:
    """Return the value itself: the key suffix only states the unit the field already has."""
    return x


def kgcm2_to_kgm2(J_kgcm2: float) -> float:
    """Inertia [kg·cm²] → [kg·m²]."""
    return J_kgcm2 * 1e-4


@dataclass(frozen=True)
class Alias:
    """A unit-suffixed input key that maps onto an SI field."""

    field: str
    convert: Callable[[float], float]
    unit: str


#: Non-SI unit → (to SI, from SI). Every display or loader unit a field spec names must be here.
CONVERSIONS: dict[str, tuple[Callable[[float], float], Callable[[float], float]]] = {
    "kW": (kW_to_W, W_to_kW),
    "rpm": (rpm_to_rad_s, rad_s_to_rpm),
    "mH": (mH_to_H, H_to_mH),
    "ms": (ms_to_s, s_to_ms),
    "kHz": (kHz_to_Hz, Hz_to_kHz),
    "deg": (deg_to_rad, rad_to_deg),
    "rev": (rev_to_rad, rad_to_rev),
    "kg·cm²": (kgcm2_to_kgm2, kgm2_to_kgcm2),
    "mm": (lambda x_mm: x_mm * 1e-3, lambda x: x * 1e3),
    "µm": (lambda x_um: x_um * 1e-6, lambda x: x * 1e6),
    # a datasheet's rms current for a field that holds the amplitude (controller.i_max_Arms)
    "Arms": (arms_to_amplitude, amplitude_to_arms),
    # a field that already holds an rms value in A (sensors.i_noise_A_rms): the suffix only states it
    "A_rms": (_identity, _identity),
    # line-to-line winding values of a star winding are twice the per-phase value (motor.R_s_LL_Ohm)
    "Ω LL": (lambda R_LL: R_LL / 2.0, lambda R: 2.0 * R),
    "mH LL": (lambda L_LL_mH: mH_to_H(L_LL_mH) / 2.0, lambda L: 2.0 * H_to_mH(L)),
}
#: Key suffix of a unit whose name is not an identifier (``J_r_kgcm2``).
KEY_SUFFIX = {"kg·cm²": "kgcm2", "Ω LL": "LL_Ohm", "mH LL": "LL_mH", "µm": "um"}


def to_si(x: float, unit: str) -> float:
    """Convert a value in ``unit`` to SI (a unit without a conversion is the SI unit itself)."""
    return CONVERSIONS[unit][0](x) if unit in CONVERSIONS else x


def from_si(x: float, unit: str) -> float:
    """Convert an SI value to ``unit`` (a unit without a conversion is the SI unit itself)."""
    return CONVERSIONS[unit][1](x) if unit in CONVERSIONS else x


def alias_key(name: str, unit: str) -> str:
    """Return the loader key of field ``name`` given in ``unit``, e.g. ``L_d_mH``, ``J_r_kgcm2``."""
    return f"{name}_{KEY_SUFFIX.get(unit, unit)}"


def _bandwidth(factor: float, unit: str) -> Callable[[float], float]:
    """Return the converter current-loop bandwidth → T_si = 3/ω_c (eq. (8) of [1]: the d-current pole is 3/T_si)."""
    def convert(x: float) -> float:
        omega_c = x * factor
        if not 0.3 <= omega_c <= 3e6:  # T_si's range 1e-6 … 10 s
            raise ParameterError(f"controller.current_bandwidth_{unit.replace('/', '_')} = {x!r} {unit} is out of "
                                 f"range: allowed {0.3 / factor:.4g} ≤ value ≤ {3e6 / factor:.4g} {unit} "
                                 "(T_si = 3/ω_c, eq. (8))")
        return bandwidth_to_T_si(omega_c)
    return convert


#: Keys that give T_si as the drive's current-loop bandwidth ω_c (rad/s or Hz): T_si = 3/ω_c.
BANDWIDTH_KEYS: dict[str, Alias] = {
    "current_bandwidth_rad_s": Alias("T_si", _bandwidth(1.0, "rad/s"), "rad/s"),
    "current_bandwidth_Hz": Alias("T_si", _bandwidth(2.0 * math.pi, "Hz"), "Hz"),
}


def aliases_of(cls: type) -> dict[str, Alias]:
    """Unit-suffixed keys of a parameter dataclass, from its field specs.

    Besides each spec's loader units, a key may name the SI unit itself when it is a plain word
    (``limits.in_position_rad``, ``limits.hold_i_rms_A``): the value is taken as it is.
    """
    table = {alias_key(name, u): Alias(name, CONVERSIONS[u][0], u)
             for name, spec in field_specs(cls).items() for u in spec.loader_units}
    for name, spec in field_specs(cls).items():
        if spec.unit.isidentifier():
            table.setdefault(alias_key(name, spec.unit), Alias(name, _identity, spec.unit))
    if "T_si" in field_specs(cls):
        table.update(BANDWIDTH_KEYS)
    return table


def sections(cls: type, prefix: str = "") -> Iterator[tuple[str, type]]:
    """(dotted section path, dataclass) of every nested parameter dataclass of ``cls``.

    A dataclass field is a section (``motor``); a tuple of dataclasses is a list section
    (``load.steps``, ``scenario.cases``), walked further (``scenario.cases.T_L_steps``).
    """
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        tp = hints[f.name]
        if typing.get_origin(tp) is tuple:
            tp = typing.get_args(tp)[0]
        if dataclasses.is_dataclass(tp):
            path = f"{prefix}{f.name}"
            yield path, tp
            yield from sections(tp, f"{path}.")


#: Parameter dataclass of each mode (the one registry is :mod:`app.io.modes`).
MODE_CLASSES: tuple[type, ...] = _MODE_CLASSES
#: Section path → parameter dataclass, both modes (section names are unique across modes).
SECTION_CLASSES: dict[str, type] = {path: tp for cls in MODE_CLASSES for path, tp in sections(cls)}


def spec_of(key: str) -> FieldSpec:
    """Return the :class:`~control.common.checks.FieldSpec` of ``section.field``, e.g. ``"motor.L_d"``."""
    section, _, name = key.rpartition(".")
    return field_specs(SECTION_CLASSES[section])[name]


def range_in(spec: FieldSpec, to_shown: Callable[[float], float], unit: str) -> str:
    """Write the allowed range of ``spec`` in a shown unit; ``to_shown`` converts (monotonic).

    E.g. L_d's range 1e-09 ≤ value ≤ 10 H shown in mH: ``"allowed 1e-06 ≤ value ≤ 10000 mH"``. A
    decreasing conversion (T_si shown as the bandwidth 3/T_si) swaps the ends of a closed range.
    """
    lo, hi = (None if b is None else to_shown(b) for b in (spec.low, spec.high))
    if lo is not None and hi is not None and lo > hi and not spec.low_open:
        lo, hi = hi, lo
    return range_text(lo, hi, spec.low_open, unit, integer=spec.integer)


def shown_range(spec: FieldSpec, unit: str | None = None) -> str:
    """Write the allowed range of ``spec`` in ``unit`` (default its display unit), e.g. for a page hint."""
    unit = unit or spec.shown_unit
    return range_in(spec, lambda b: from_si(b, unit), unit)


#: Unit-suffixed keys accepted per section, mapping to the SI field and its converter.
ALIASES: dict[str, dict[str, Alias]] = {path: table for path, tp in SECTION_CLASSES.items()
                                        if (table := aliases_of(tp))}

#: Keys needing more than one field to convert (Ke needs the pole pairs).
KE_KEY = "Ke_Vrms_krpm"


def kv_rpm_per_v_to_psi_pm(Kv_rpm_per_V: float, p: int) -> float:
    """Speed constant Kv [rpm per V] → Ψ_PM [Wb] (amplitude-invariant dq).

    Kv is the speed per volt of line-to-line **peak** back-EMF (the hobby/robotics convention; ODrive's
    torque_constant = 8.27/Kv follows from it). The line-to-line peak at mechanical speed ω is
    √3·p·ω·Ψ_PM, so Ψ_PM = 1/(√3·p·Kv·2π/60); then Kt = (3/2)·p·Ψ_PM = 8.27/Kv [N·m/A].

    Raises
    ------
    ParameterError
        For Kv ≤ 0 or not finite (no flux follows from it), naming ``motor.Kv_rpm_per_V``.
    """
    if not (math.isfinite(Kv_rpm_per_V) and Kv_rpm_per_V > 0.0):
        raise ParameterError(f"motor.Kv_rpm_per_V = {Kv_rpm_per_V!r} rpm/V is not allowed: allowed > 0 rpm/V")
    return 1.0 / (math.sqrt(3.0) * p * rpm_to_rad_s(Kv_rpm_per_V))


def psi_pm_to_kv_rpm_per_v(psi_pm: float, p: int) -> float:
    """Ψ_PM [Wb] → Kv [rpm per V line-to-line peak]; inverse of :func:`kv_rpm_per_v_to_psi_pm`."""
    return rad_s_to_rpm(1.0 / (math.sqrt(3.0) * p * psi_pm))


#: Keys that give Ψ_PM through the pole pairs: key → converter (value, p) → Ψ_PM [Wb]. Ke is the
#: line-to-line rms value unless the key says peak (×√2 less) or phase (×√3 more than LL).
FLUX_KEYS: dict[str, Callable[[float, int], float]] = {
    KE_KEY: lambda x, p: ke_vrms_krpm_to_psi_pm(x, p),
    "Ke_Vpk_krpm": lambda x, p: ke_vrms_krpm_to_psi_pm(x / math.sqrt(2.0), p),
    "Ke_ph_Vrms_krpm": lambda x, p: ke_vrms_krpm_to_psi_pm(x * math.sqrt(3.0), p),
    "Ke_ph_Vpk_krpm": lambda x, p: ke_vrms_krpm_to_psi_pm(x * math.sqrt(1.5), p),
    "Kv_rpm_per_V": lambda x, p: kv_rpm_per_v_to_psi_pm(x, p),
    "Kt_Nm_per_Arms": lambda x, p: kt_nm_per_arms_to_psi_pm(x, p),
    # per A of phase-current amplitude, the dq amplitude-invariant scale (ODrive's torque_constant,
    # moteus and VESC quote it so): Kt = (3/2)·p·Ψ_PM; Kt_Nm_per_A is the same, as those vendors write it
    "Kt_Nm_per_Apeak": lambda x, p: kt_nm_per_apeak_to_psi_pm(x, p),
    "Kt_Nm_per_A": lambda x, p: kt_nm_per_apeak_to_psi_pm(x, p),
}
#: What each flux key means, for the loader's hint when a flux key is misspelt (never one other key,
#: which could be of another unit: a per-A-peak value typed under the rms key is 41 % off).
FLUX_KEY_MEANING = {
    "psi_pm": "Wb", KE_KEY: "V/krpm LL rms", "Ke_Vpk_krpm": "LL peak", "Ke_ph_Vrms_krpm": "phase rms",
    "Ke_ph_Vpk_krpm": "phase peak", "Kv_rpm_per_V": "rpm/V", "Kt_Nm_per_Arms": "N·m/A rms",
    "Kt_Nm_per_Apeak": "N·m/A peak", "Kt_Nm_per_A": "peak, as ODrive quotes it",
}


def kt_nm_per_apeak_to_psi_pm(Kt_Nm_Apk: float, p: int) -> float:
    """Torque constant Kt [N·m per A of phase-current amplitude] → Ψ_PM [Wb] (amplitude-invariant dq).

    Γ = (3/2)·p·Ψ_PM·i_q with i_q the phase-current amplitude (eq. (5) in [1]), so Ψ_PM = Kt/(1.5·p).
    ODrive's torque_constant 8.27/Kv is this Kt (e.g. the D5065: 8.27/270 = 0.0306 N·m/A).
    """
    return Kt_Nm_Apk / (1.5 * p)



def psi_pm_to_kt_nm_per_apeak(psi_pm: float, p: int) -> float:
    """Ψ_PM [Wb] → Kt [N·m per A peak]; inverse of :func:`kt_nm_per_apeak_to_psi_pm`."""
    return psi_pm * 1.5 * p


def bandwidth_to_T_si(omega_c: float) -> float:
    """Current-loop bandwidth ω_c [rad/s] → T_si = 3/ω_c [s] (eq. (8) of [1]: the d-current pole is 3/T_si)."""
    return 3.0 / omega_c


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


def _unit_text(cls: type, name: str) -> str:
    """Return the exported SI unit of ``name``: its spec, a list section's fields, or ``-`` (a choice)."""
    spec = field_specs(cls).get(name)
    if spec is not None:
        return spec.unit_text
    nested = [tp for path, tp in sections(cls) if path == name]
    if nested:
        return ", ".join(f"{n}: {s.unit_text}" for n, s in field_specs(nested[0]).items())
    return "-"


#: SI unit of every input field of both modes' top-level sections, as written in exported
#: parameter files (``units`` section); generated from the field specs.
SI_UNITS: dict[str, dict[str, str]] = {
    path: {f.name: _unit_text(tp, f.name) for f in dataclasses.fields(tp)}
    for path, tp in SECTION_CLASSES.items() if "." not in path
}
