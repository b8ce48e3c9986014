"""Parameter model of the FDSMC position drive: frozen dataclasses in SI units.

Every input field is declared once with :func:`control.common.checks.spec_field` (SI unit, allowed
range, page label, display unit, loader units); construction rejects impossible values with a
:class:`~control.common.checks.ParameterError` whose message names the field, the value and the
allowed range.

References
----------
[1] S. J. Dodds, G. Sooriyakumar, R. Perryman, "A Robust Forced Dynamic Sliding Mode Minimum
    Energy Position Controller for Permanent Magnet Synchronous Motor Drives" (the FDSMC paper).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError, check_fields, spec_field
from pmsm_commissioning.control.common.dc_link import DC_LINKS
from pmsm_commissioning.control.fdsmc.transmission import Transmission

ALPHA_MAX_RULES = ("paper", "torque_limit", "min_energy")


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

    V_0: float = spec_field("V", 1.0, 1e5, low_open=False, label="V_0 rated (LL rms)")
    P_r: float = spec_field("W", 1e-3, 1e8, low_open=False, label="P_r rated power", display="kW")
    omega_b: float = spec_field("rad/s", 0.0, 1e5, label="n_b rated speed", display="rpm")
    Gamma_max: float = spec_field("N·m", 1e-6, 1e6, low_open=False, label="Γ_max peak torque")
    psi_pm: float = spec_field("Wb", 1e-6, 100.0, low_open=False, label="Ψ_PM")
    L_d: float = spec_field("H", 1e-9, 10.0, low_open=False, label="L_d", display="mH", aliases=("mH LL",))
    L_q: float = spec_field("H", 1e-9, 10.0, low_open=False, label="L_q", display="mH", aliases=("mH LL",))
    R_s: float = spec_field("Ω", 0.0, 1e4, label="R_s", aliases=("Ω LL",))
    p: int = spec_field("-", 1, 100, integer=True, label="p pole pairs")
    J_r: float = spec_field("kg·m²", 1e-9, 1e4, low_open=False, label="J_r rotor inertia", aliases=("kg·cm²",))

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "motor")


@dataclass(frozen=True)
class LoadStep:
    """A step of the external load torque: from time ``t`` [s] on, Γ_Le = ``Gamma_Le`` [N·m]."""

    t: float = spec_field("s", 0.0, None, low_open=False, label="t step time")
    Gamma_Le: float = spec_field("N·m", -1e6, 1e6, label="Γ_Le load torque")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "load.steps")


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

    J_L: float = spec_field("kg·m²", 0.0, 1e4, low_open=False, label="J_L load inertia", aliases=("kg·cm²",))
    F_v: float = spec_field("N·m·s/rad", 0.0, 1e4, low_open=False, label="F_v viscous friction")
    Gamma_Le: float = spec_field("N·m", -1e6, 1e6, default=0.0, label="Γ_Le load torque at t=0")
    steps: tuple[LoadStep, ...] = ()
    Gamma_Le_ramp: float = spec_field("N·m/s", -1e6, 1e6, default=0.0, label="Γ_Le ramp")

    def __post_init__(self) -> None:
        """Check the fields' ranges, turn mapping load steps into :class:`LoadStep`, check their times increase."""
        check_fields(self, "load")
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
        ``"paper"`` (α_max = H·P_r/V_0, section 5), ``"torque_limit"`` (the largest α within the
        drive's torque) or ``"min_energy"`` (the α ≤ the torque limit's that minimises the profile's
        friction + copper loss, :mod:`control.fdsmc.profile_energy`).
    f_s : float or "continuous"
        Controller sample rate [Hz], or ``"continuous"`` to evaluate the controller continuously.
    delay_samples : int
        Computation delay of the digital controller [samples] (0 or 1).
    V_dc : float
        Inverter DC-link voltage [V]; limits |u_dq| ≤ V_dc/√3. 0 = ideal inverter (the paper).
    i_max : float
        Inverter current limit: amplitude of the phase current, |i_dq| ≤ i_max (amplitude-invariant
        dq) [A]; a datasheet's A_rms value is √2 times smaller (loader key ``i_max_Arms``). 0 = none
        (the paper).
    T_dv : float
        Time constant of the q-axis voltage-mismatch estimate (:func:`control.fdsmc.fdc.voltage_mismatch`)
        [s]; 0 = none (the paper's FDC). Digital controllers only.
    dc_link : str
        What the DC link does with regenerated energy, one of :data:`control.common.dc_link.DC_LINKS`:
        ``braking_resistor`` (default, a stock servo drive: burnt), ``regenerative`` (returned to the
        supply) or ``battery`` (charged at ``charge_efficiency``); sets the supply's energy of every run.
    charge_efficiency : float
        Battery charge efficiency η_ch [-]; used only with ``dc_link = battery``.
    """

    T_si: float = spec_field("s", T_MIN_S, 10.0, low_open=False, label="T_si current settling", display="ms")
    T_salpha: float = spec_field("s", T_MIN_S, 10.0, low_open=False, label="T_sα accel. settling", display="ms")
    T_so: float = spec_field("s", T_MIN_S, 10.0, low_open=False, label="T_so observer settling", display="ms")
    K: float = spec_field("s/rad", 0.0, 1e9, label="K boundary-layer gain")
    T_c: float | str = spec_field("s", 0.0, 100.0, default="T_a", keywords=("T_a",),
                                label="T_c sliding time const.", display="ms")
    alpha_max_rule: str = "paper"
    f_s: float | str = spec_field("Hz", 100.0, 1e7, default=20000.0, low_open=False, keywords=("continuous",),
                                  label="f_s sample rate", display="kHz")
    delay_samples: int = spec_field("samples", 0, 1, default=0, integer=True, label="Computation delay")
    V_dc: float = spec_field("V", 0.0, 1e5, default=0.0, low_open=False, label="V_dc inverter DC link (0 = ideal)")
    i_max: float = spec_field("A", 0.0, 1e6, default=0.0, low_open=False, aliases=("Arms",),
                              label="i_max inverter current (0 = none)")
    T_dv: float = spec_field("s", 0.0, 10.0, default=0.0, low_open=False, display="ms",
                             label="T_dv q-voltage mismatch estimate (0 = none)")
    dc_link: str = DC_LINKS[0]
    charge_efficiency: float = spec_field("-", 0.0, 1.0, default=0.9, low_open=False,
                                          label="η_ch battery charge efficiency")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        if isinstance(self.T_c, str) and self.T_c != "T_a":
            raise ParameterError(f"controller.T_c = {self.T_c!r} is not allowed: a time > 0 s or 'T_a'")
        if isinstance(self.f_s, str) and self.f_s != "continuous":
            raise ParameterError(f"controller.f_s = {self.f_s!r} is not allowed: a rate in Hz or 'continuous'")
        check_fields(self, "controller")
        if self.alpha_max_rule not in ALPHA_MAX_RULES:
            raise ParameterError(
                f"controller.alpha_max_rule = {self.alpha_max_rule!r} is not allowed: "
                f"one of {', '.join(ALPHA_MAX_RULES)}"
            )
        if self.dc_link not in DC_LINKS:
            raise ParameterError(f"controller.dc_link = {self.dc_link!r} is not allowed: one of {', '.join(DC_LINKS)}")

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

    theta_dem: float = spec_field("rad", -1e6, 1e6, label="θ_dem demanded angle", aliases=("deg", "rev"))
    T_m: float = spec_field("s", 1e-4, 1e4, low_open=False, label="T_m manoeuvre time")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "manoeuvre")
        if abs(self.theta_dem) < THETA_DEM_MIN:
            raise ParameterError(f"manoeuvre.theta_dem = {self.theta_dem!r} rad is out of range: allowed "
                                 f"{THETA_DEM_MIN:g} ≤ |value| ≤ 1e+06 rad")


#: Largest encoder resolution [counts per mechanical revolution] (2³¹: a 31-bit absolute encoder).
ENCODER_CPR_MAX = 2**31


@dataclass(frozen=True)
class Sensors:
    """What the digital controller measures: a quantized encoder and noisy, quantized currents.

    The controller (FDC laws, observer, current limit) sees only these signals; the simulated
    physics stays exact. The noise is a seeded, reproducible sequence.

    Attributes
    ----------
    encoder_cpr : int
        Encoder counts per mechanical revolution [-] (e.g. 8192, 2²⁰); 0 = ideal (no quantization).
        The controller sees θ_r quantized down to a whole count: 2π/cpr·floor(θ_r·cpr/2π).
    i_noise : float
        Current-measurement noise, rms of each measured phase-current component i_d, i_q [A].
    i_adc_bits : int
        Resolution of the current ADC [bits]; 0 = ideal.
    i_adc_range : float
        Full-scale amplitude of the current ADC, ±i_adc_range [A] (needed when ``i_adc_bits`` > 0);
        one step is 2·i_adc_range/2^bits and readings clip at the full scale.
    seed : int
        Seed of the noise sequence [-].
    """

    encoder_cpr: int = spec_field("counts/rev", 0, ENCODER_CPR_MAX, default=0, integer=True,
                                  label="Encoder counts per rev (0 = ideal)")
    i_noise: float = spec_field("A", 0.0, 1e4, default=0.0, low_open=False, aliases=("A_rms",),
                                label="Current noise [rms] (0 = none)")
    i_adc_bits: int = spec_field("bits", 0, 24, default=0, integer=True, label="Current ADC bits (0 = ideal)")
    i_adc_range: float = spec_field("A", 0.0, 1e6, default=0.0, low_open=False, label="Current ADC full scale ±")
    seed: int = spec_field("-", 0, 2**31 - 1, default=1, integer=True, label="Noise seed")

    def __post_init__(self) -> None:
        """Check every field's range; an ADC resolution needs its full scale."""
        check_fields(self, "sensors")
        if self.i_adc_bits > 0 and self.i_adc_range <= 0.0:
            raise ParameterError(f"sensors.i_adc_range = {self.i_adc_range!r} A is out of range with "
                                 f"sensors.i_adc_bits = {self.i_adc_bits}: allowed > 0 A (the ADC's full scale)")

    @property
    def ideal(self) -> bool:
        """True when the controller measures θ_r, i_d and i_q exactly."""
        return self.encoder_cpr == 0 and self.i_noise == 0.0 and self.i_adc_bits == 0

    @property
    def encoder_step(self) -> float:
        """One encoder count [rad]: 2π/cpr; 0 for an ideal encoder."""
        return 2.0 * math.pi / self.encoder_cpr if self.encoder_cpr > 0 else 0.0

    @property
    def adc_step(self) -> float:
        """One step of the current ADC [A]: 2·range/2^bits; 0 for an ideal ADC."""
        return 2.0 * self.i_adc_range / 2.0**self.i_adc_bits if self.i_adc_bits > 0 else 0.0

    @property
    def reading_noise(self) -> float:
        """RMS error of a current reading [A]: the noise and the ADC's rounding, √(σ² + q²/12)."""
        return math.hypot(self.i_noise, self.adc_step / math.sqrt(12.0))


@dataclass(frozen=True)
class Limits:
    """The commissioning engineer's pass criteria; 0 selects the documented default.

    Attributes
    ----------
    omega_max : float
        Largest allowed |ω_r|: the motor's maximum speed n_max [rad/s]; 0 = the rated speed ω_b.
    in_position : float
        In-position window ±[rad] around θ_dem; 0 = ±10 encoder counts (an ideal encoder: ±10 counts
        of a 2²⁰ encoder, 6.0e-5 rad).
    overshoot : float
        Largest allowed overshoot beyond θ_dem [rad]; 0 = the in-position window.
    hold_i_rms : float
        Largest allowed rms ripple of i_q while holding θ_dem [A]; 0 = 5 % of the drive's current
        limit (i_max, else Γ_max/Kt).
    """

    omega_max: float = spec_field("rad/s", 0.0, 1e5, default=0.0, low_open=False, display="rpm",
                                  label="n_max maximum speed (0 = rated)")
    in_position: float = spec_field("rad", 0.0, 1e3, default=0.0, low_open=False, aliases=("deg",),
                                    label="In-position window ± (0 = 10 counts)")
    overshoot: float = spec_field("rad", 0.0, 1e3, default=0.0, low_open=False, aliases=("deg",),
                                  label="Overshoot limit (0 = in-position window)")
    hold_i_rms: float = spec_field("A", 0.0, 1e6, default=0.0, low_open=False,
                                   label="Standstill i_q ripple limit [rms] (0 = 5 % of i_max)")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "limits")


__all__ = ["ALPHA_MAX_RULES", "ENCODER_CPR_MAX", "Controller", "DriveParams", "Limits", "Load", "LoadStep",
           "Manoeuvre", "Motor", "ParameterError", "Sensors", "T_MIN_S", "THETA_DEM_MIN", "Transmission"]


@dataclass(frozen=True)
class DriveParams:
    """Everything one FDSMC commissioning case needs: motor, load, controller, manoeuvre.

    ``sensors``, ``limits`` and ``transmission`` are optional sections (ideal sensors, default pass
    criteria, direct drive). The load and the manoeuvre are always the rotor's side (SI); the
    transmission says how they map onto the output (:mod:`control.fdsmc.transmission`).
    """

    motor: Motor
    load: Load
    controller: Controller
    manoeuvre: Manoeuvre
    name: str = "custom"
    source: str = "user input"
    sensors: Sensors = Sensors()
    limits: Limits = Limits()
    transmission: Transmission = Transmission()

    def __post_init__(self) -> None:
        """Sensor models need a sampled controller (measurements are taken at the sample instants)."""
        if not self.sensors.ideal and self.controller.is_continuous:
            raise ParameterError("controller.f_s = 'continuous' cannot be used with sensors (encoder_cpr, i_noise, "
                                 "i_adc_bits): allowed a sample rate in Hz, or ideal sensors")

    @property
    def J_total(self) -> float:
        """Total inertia J_r + J_L turned by the motor, eq. (4b) [kg·m²]."""
        return self.motor.J_r + self.load.J_L
