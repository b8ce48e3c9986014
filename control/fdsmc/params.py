"""Parameter model of the FDSMC position drive: frozen dataclasses in SI units.

Every field carries its unit in the docstring. Construction rejects impossible values with a
:class:`ParameterError` whose message names the field, the value and the allowed range.

References
----------
[1] S. J. Dodds, G. Sooriyakumar, R. Perryman, "A Robust Forced Dynamic Sliding Mode Minimum
    Energy Position Controller for Permanent Magnet Synchronous Motor Drives" (the FDSMC paper).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

ALPHA_MAX_RULES = ("paper", "torque_limit")


class ParameterError(ValueError):
    """An input value outside its allowed range; the message names field, value and range."""


def check_range(
    name: str,
    value: Any,
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = True,
    unit: str = "",
) -> float:
    """Return ``value`` as float or raise :class:`ParameterError` naming the allowed range.

    Parameters
    ----------
    name : str
        Dotted field name shown to the user, e.g. ``"motor.L_d"``.
    value : Any
        The value to check.
    low, high : float or None
        Bounds (``None`` = unbounded). ``low`` is exclusive when ``low_open`` else inclusive;
        ``high`` is inclusive.
    unit : str
        Unit shown in the message.

    Returns
    -------
    float
        The checked value.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{name} = {value!r} is not a number{_range_text(low, high, low_open, unit)}")
    x = float(value)
    bad = not math.isfinite(x)
    bad = bad or (low is not None and (x <= low if low_open else x < low))
    bad = bad or (high is not None and x > high)
    if bad:
        shown = f"{name} = {value!r} {unit}".rstrip()
        raise ParameterError(f"{shown} is out of range{_range_text(low, high, low_open, unit)}")
    return x


def _range_text(low: float | None, high: float | None, low_open: bool, unit: str) -> str:
    u = f" {unit}" if unit else ""
    if low is not None and high is not None:
        op = "<" if low_open else "≤"
        return f": allowed {low:g} {op} value ≤ {high:g}{u}"
    if low is not None:
        return f": allowed {'>' if low_open else '≥'} {low:g}{u}"
    if high is not None:
        return f": allowed ≤ {high:g}{u}"
    return ": allowed any finite number"


def _check_fields(obj: Any, section: str, spec: dict[str, tuple[float | None, float | None, bool, str]]) -> None:
    for f in fields(obj):
        if f.name in spec:
            low, high, low_open, unit = spec[f.name]
            check_range(f"{section}.{f.name}", getattr(obj, f.name), low, high, low_open=low_open, unit=unit)


#: Shortest settling time of the inner loops and the observer [s]. With T_so ≥ 1 µs the observer
#: pole q = 15/(2·T_so) ≤ 7.5e6 1/s, so q⁴·J_r (eq. (18) in [1], J_r ≤ 1e4 kg·m²) ≤ 3.2e31 and
#: q·T_s ≤ 7.5e4 at f_s ≥ 100 Hz: exp(−q·T_s) is representable (it may round to 0, a dead-beat
#: pole, which is harmless). The range bounds of every field below keep the derivations finite
#: (e.g. α_max = H·P_r/V_0 ≤ 1.5e13·1e8/1 and T_m,min > 0).
T_MIN_S = 1e-6
#: Smallest demanded angle [rad]: about 3 counts of a 24-bit encoder (2π/2²⁴ = 3.7e-7 rad); far
#: below it Δθ/T_m, the 2 % band and the profile's divisions underflow.
THETA_DEM_MIN = 1e-6


@dataclass(frozen=True)
class Motor:
    """PMSM nameplate and model data, eqs. (1)–(5) and section 5 of [1].

    Attributes
    ----------
    V_0 : float
        Rated voltage, line-to-line RMS [V].
    P_r : float
        Rated power [W].
    omega_b : float
        Base speed [rad/s] (mechanical).
    Gamma_max : float
        Maximum electromagnetic torque [N·m].
    psi_pm : float
        Permanent-magnet flux linkage Ψ_PM [Wb] (amplitude-invariant dq, eq. (5)).
    L_d, L_q : float
        Direct / quadrature-axis inductance [H].
    R_s : float
        Stator resistance per phase [Ω].
    p : int
        Pole pairs [-].
    J_r : float
        Rotor moment of inertia [kg·m²].
    """

    V_0: float
    P_r: float
    omega_b: float
    Gamma_max: float
    psi_pm: float
    L_d: float
    L_q: float
    R_s: float
    p: int
    J_r: float

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        spec = {
            "V_0": (1.0, 1e5, False, "V"), "P_r": (1e-3, 1e8, False, "W"), "omega_b": (0.0, 1e5, True, "rad/s"),
            "Gamma_max": (1e-6, 1e6, False, "N·m"), "psi_pm": (1e-6, 100.0, False, "Wb"),
            "L_d": (1e-9, 10.0, False, "H"), "L_q": (1e-9, 10.0, False, "H"), "R_s": (0.0, 1e4, True, "Ω"),
            "J_r": (1e-9, 1e4, False, "kg·m²"),
        }
        _check_fields(self, "motor", spec)
        if isinstance(self.p, bool) or not isinstance(self.p, int | float) or not (
            math.isfinite(self.p) and float(self.p).is_integer() and 1 <= self.p <= 100
        ):
            raise ParameterError(f"motor.p = {self.p!r} is out of range: allowed an integer 1 … 100 pole pairs")
        object.__setattr__(self, "p", int(self.p))


@dataclass(frozen=True)
class LoadStep:
    """A step of the external load torque: from time ``t`` [s] on, Γ_Le = ``Gamma_Le`` [N·m]."""

    t: float
    Gamma_Le: float

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_range("load.steps.t", self.t, 0.0, None, low_open=False, unit="s")
        check_range("load.steps.Gamma_Le", self.Gamma_Le, -1e6, 1e6, unit="N·m")


@dataclass(frozen=True)
class Load:
    """Mechanical load referred to the rotor, eqs. (4b) and (6) of [1].

    Attributes
    ----------
    J_L : float
        Load inertia referred to the rotor [kg·m²] (≥ 0; unknown to the controller).
    F_v : float
        Viscous friction coefficient [N·m·s/rad].
    Gamma_Le : float
        External load torque at t = 0 [N·m].
    steps : tuple of LoadStep
        Later steps of the external load torque (time-ordered) [s, N·m].
    Gamma_Le_ramp : float
        Ramp rate added to the external load torque from t = 0 [N·m/s].
    """

    J_L: float
    F_v: float
    Gamma_Le: float = 0.0
    steps: tuple[LoadStep, ...] = ()
    Gamma_Le_ramp: float = 0.0

    def __post_init__(self) -> None:
        """Check the fields' ranges, turn mapping load steps into :class:`LoadStep`, check their times increase."""
        _check_fields(self, "load", {
            "J_L": (0.0, 1e4, False, "kg·m²"), "F_v": (0.0, 1e4, False, "N·m·s/rad"),
            "Gamma_Le": (-1e6, 1e6, True, "N·m"), "Gamma_Le_ramp": (-1e6, 1e6, True, "N·m/s"),
        })
        steps = tuple(s if isinstance(s, LoadStep) else LoadStep(**s) for s in self.steps)
        times = [s.t for s in steps]
        if times != sorted(times):
            raise ParameterError(f"load.steps times = {times} must be in increasing order")
        object.__setattr__(self, "steps", steps)


@dataclass(frozen=True)
class Controller:
    """FDC inner loops, observer and sliding-mode outer loop settings of [1].

    Attributes
    ----------
    T_si : float
        Direct-axis current settling time (5 %), eq. (8) [s].
    T_salpha : float
        Acceleration-loop settling time (5 %), eq. (13) [s].
    T_so : float
        Observer settling time (5 %), eq. (17) [s].
    K : float
        Boundary-layer gain, eq. (45) [s/rad].
    T_c : float or "T_a"
        Sliding-mode time constant of the sloped boundary segment, eq. (41) [s]; ``"T_a"``
        applies eq. (59), T_c = T_a.
    alpha_max_rule : str
        ``"paper"`` (α_max = H·P_r/V_0, section 5) or ``"torque_limit"``
        (α_max = (Γ_max − |Γ_Le|)/(J_r + J_L)).
    f_s : float or "continuous"
        Controller sample rate [Hz], or ``"continuous"`` to evaluate the controller continuously.
    delay_samples : int
        Computation delay of the digital controller [samples] (0 or 1).
    V_dc : float
        Inverter DC-link voltage [V]; limits |u_dq| ≤ V_dc/√3. 0 = ideal inverter (the paper).
    i_max : float
        Inverter current limit on |i_q| [A]. 0 = none (the paper).
    """

    T_si: float
    T_salpha: float
    T_so: float
    K: float
    T_c: float | str = "T_a"
    alpha_max_rule: str = "paper"
    f_s: float | str = 20000.0
    delay_samples: int = 0
    V_dc: float = 0.0
    i_max: float = 0.0

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        _check_fields(self, "controller", {
            "T_si": (T_MIN_S, 10.0, False, "s"), "T_salpha": (T_MIN_S, 10.0, False, "s"),
            "T_so": (T_MIN_S, 10.0, False, "s"), "K": (0.0, 1e9, True, "s/rad"),
            "V_dc": (0.0, 1e5, False, "V"), "i_max": (0.0, 1e6, False, "A"),
        })
        if self.T_c != "T_a":
            if isinstance(self.T_c, str):
                raise ParameterError(f"controller.T_c = {self.T_c!r} is not allowed: a time > 0 s or 'T_a'")
            check_range("controller.T_c", self.T_c, 0.0, 100.0, unit="s")
        if self.alpha_max_rule not in ALPHA_MAX_RULES:
            raise ParameterError(
                f"controller.alpha_max_rule = {self.alpha_max_rule!r} is not allowed: "
                f"one of {', '.join(ALPHA_MAX_RULES)}"
            )
        if self.f_s != "continuous":
            if isinstance(self.f_s, str):
                raise ParameterError(f"controller.f_s = {self.f_s!r} is not allowed: a rate in Hz or 'continuous'")
            check_range("controller.f_s", self.f_s, 100.0, 1e7, low_open=False, unit="Hz")
        if self.delay_samples not in (0, 1) or isinstance(self.delay_samples, bool):
            raise ParameterError(f"controller.delay_samples = {self.delay_samples!r} is out of range: allowed 0 or 1")
        object.__setattr__(self, "delay_samples", int(self.delay_samples))  # 1.0 → 1: the kernel needs an int

    @property
    def is_continuous(self) -> bool:
        """True when the controller is evaluated continuously (no sampling)."""
        return self.f_s == "continuous"


@dataclass(frozen=True)
class Manoeuvre:
    """Rest-to-rest manoeuvre from θ_r = 0.

    Attributes
    ----------
    theta_dem : float
        Demanded rotor angle [rad].
    T_m : float
        Demanded manoeuvre time [s].
    """

    theta_dem: float
    T_m: float

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_range("manoeuvre.theta_dem", self.theta_dem, -1e6, 1e6, unit="rad")
        if abs(self.theta_dem) < THETA_DEM_MIN:
            raise ParameterError(f"manoeuvre.theta_dem = {self.theta_dem!r} rad is out of range: allowed "
                                 f"{THETA_DEM_MIN:g} ≤ |value| ≤ 1e+06 rad")
        check_range("manoeuvre.T_m", self.T_m, 1e-4, 1e4, low_open=False, unit="s")


@dataclass(frozen=True)
class DriveParams:
    """Everything one FDSMC commissioning case needs: motor, load, controller, manoeuvre."""

    motor: Motor
    load: Load
    controller: Controller
    manoeuvre: Manoeuvre
    name: str = "custom"
    source: str = "user input"

    @property
    def J_total(self) -> float:
        """Total inertia J_r + J_L turned by the motor, eq. (4b) [kg·m²]."""
        return self.motor.J_r + self.load.J_L
