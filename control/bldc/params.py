"""Parameters of the BLDC speed-control mode: frozen dataclasses in SI units.

The second mode of the tool: sliding-mode vector speed control of a surface-mount PMSM with a
trapezoidal (non-sinusoidal) back-EMF, after [2]. Every input field is declared once with
:func:`control.common.checks.spec_field`; construction rejects impossible values with a
:class:`~control.common.checks.ParameterError` naming the field, the value and the allowed range.

References
----------
[2] J. R. B. A. Monteiro, A. G. de Castro, T. E. P. de Almeida, "Sliding Mode Vector Control of
    Non-Sinusoidal Permanent Magnet Synchronous Machine" (the SMC-BLDC paper).
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError, check_fields, spec_field

#: Back-EMF shapes of the machine model: the ideal trapezoid of Fig. 2 in [2], the built-in
#: smooth distorted example, or a measured table (``BldcMachine.emf_samples``).
EMF_SHAPES = ("ideal", "distorted", "measured")
#: Minimum / maximum number of samples of a measured back-EMF period.
EMF_SAMPLES_MIN, EMF_SAMPLES_MAX = 24, 4096


@dataclass(frozen=True)
class BldcMachine:
    """Three-phase star-connected machine without neutral, eqs. (1)–(3) and Table I of [2].

    Attributes
    ----------
    R_s : float
        Stator phase resistance [Ω].
    L_s_minus_M_s : float
        Self minus mutual inductance L_s − M_s [H]; with i_a + i_b + i_c = 0 eq. (1) only needs
        this difference.
    n_pp : int
        Pole pairs [-].
    Phi_m : float
        Amplitude Φ_M of the ideal trapezoid Φ'_r(θ_e) = e/ω_e [Wb] (= V·s/rad), Fig. 2.
    emf : str
        Back-EMF shape of the *machine*: ``"ideal"``, ``"distorted"`` (built-in example) or
        ``"measured"`` (``emf_samples``). The controller always uses the ideal trapezoid.
    emf_samples : tuple of float
        One electrical period of Φ'_ra(θ_e) [Wb] on a uniform grid θ_e = 2π·k/N, k = 0 … N−1
        (used when ``emf == "measured"``; phases b, c lag by 120° and 240°).
    """

    R_s: float = spec_field("Ω", 0.0, 1e3, low_open=False, label="R_s")
    L_s_minus_M_s: float = spec_field("H", 0.0, 10.0, label="L_s − M_s", display="mH")
    n_pp: int = spec_field("-", 1, 100, integer=True, label="n_pp (pole pairs)")
    Phi_m: float = spec_field("Wb", 0.0, 100.0, label="Φ_m")
    emf: str = "distorted"
    emf_samples: tuple[float, ...] = spec_field("Wb", -1e3, 1e3, default=(), label="Φ'_ra samples")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "machine")
        if self.emf not in EMF_SHAPES:
            raise ParameterError(f"machine.emf = {self.emf!r} is not allowed: one of {', '.join(EMF_SHAPES)}")
        samples = self.emf_samples
        if self.emf == "measured" and not EMF_SAMPLES_MIN <= len(samples) <= EMF_SAMPLES_MAX:
            raise ParameterError(
                f"machine.emf_samples has {len(samples)} samples: allowed {EMF_SAMPLES_MIN} … "
                f"{EMF_SAMPLES_MAX} samples of one electrical period when machine.emf = 'measured'"
            )


@dataclass(frozen=True)
class BldcMechanics:
    """Mechanical load of eq. (17) in [2] (Table I).

    Attributes
    ----------
    J : float
        Combined inertia of rotor and load [kg·m²].
    B : float
        Viscous friction coefficient [N·m·s/rad] (Table I prints kg·m²/s, which is the same
        SI dimension).
    """

    J: float = spec_field("kg·m²", 0.0, 1e4, label="J")
    B: float = spec_field("N·m·s/rad", 0.0, 1e4, low_open=False, label="B")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "mechanics")


@dataclass(frozen=True)
class BldcInverter:
    """Two-level voltage-source inverter with a finite DC link (averaged model).

    Attributes
    ----------
    V_dc : float
        DC-link voltage [V]; the largest voltage vector (linear space-vector modulation) is
        |v_αβ| = V_dc/√2 in the power-invariant frame of eq. (5) in [2].
    f_s : float
        Controller sample rate = PWM frequency [Hz]; the voltage is held for 1/f_s.
    """

    V_dc: float = spec_field("V", 0.0, 1e5, label="V_dc")
    f_s: float = spec_field("Hz", 1e3, 1e6, low_open=False, label="f_s", display="kHz")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "inverter")


@dataclass(frozen=True)
class BldcGains:
    """Controller settings, eqs. (13)–(16) in [2] and Fig. 7.

    Attributes
    ----------
    k_I : float
        Current SMC gain k_I of eq. (14) [1/A]; the tanh is scaled by the available voltage.
    k_omega : float
        Gain of the tanh from σ_ω to the torque reference [s/rad].
    T_max : float
        Torque reference limit (the tanh amplitude) [N·m].
    lambda_0 : float
        λ(0), the integral weight of eq. (16) at zero error [1/s].
    eps_lambda : float
        Error at which λ has fallen to λ_0/2: λ(ε) = λ_0/(1 + (ε/ε_λ)²) [rad/s].
    """

    k_I: float = spec_field("1/A", 0.0, 1e4, label="k_I")
    k_omega: float = spec_field("s/rad", 0.0, 1e4, label="k_ω")
    T_max: float = spec_field("N·m", 0.0, 1e5, label="T_max")
    lambda_0: float = spec_field("1/s", 0.0, 1e5, low_open=False, label="λ₀")
    eps_lambda: float = spec_field("rad/s", 0.0, 1e5, label="ε_λ", display="rpm")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "gains")


@dataclass(frozen=True)
class TorqueStep:
    """From time ``t`` [s] on, the load torque is ``T_L`` [N·m] (positive opposes motion)."""

    t: float = spec_field("s", 0.0, 100.0, low_open=False, label="t step time")
    T_L: float = spec_field("N·m", -1e5, 1e5, label="T_L load torque")

    def __post_init__(self) -> None:
        """Check every field's range: a ParameterError names the field, the value and the allowed range."""
        check_fields(self, "scenario.cases.T_L_steps")


@dataclass(frozen=True)
class BldcScenario:
    """One speed-control run: initial speed, speed reference step, load-torque steps.

    Attributes
    ----------
    name : str
        Label, e.g. ``"1000rpm"``.
    omega_0 : float
        Initial mechanical speed (steady, currents zero) [rad/s].
    omega_ref : float
        Speed reference ω* from t = 0 [rad/s].
    t_end : float
        Simulated time [s].
    T_L_0 : float
        Load torque at t = 0 [N·m].
    T_L_steps : tuple of TorqueStep
        Later load-torque steps, time-ordered [s, N·m].
    t_window : float
        Length of the steady window at the end of each constant-load segment used for the
        steady-state error and the torque ripple [s].
    band_recovery : float
        Speed band around ω* that counts as recovered after a load step [rad/s].
    """

    name: str
    omega_0: float = spec_field("rad/s", -1e4, 1e4, label="ω_0", display="rpm")
    omega_ref: float = spec_field("rad/s", -1e4, 1e4, label="ω*", display="rpm")
    t_end: float = spec_field("s", 0.0, 100.0, label="t_end")
    T_L_0: float = spec_field("N·m", -1e5, 1e5, default=0.0, label="T_L at t=0")
    T_L_steps: tuple[TorqueStep, ...] = ()
    t_window: float = spec_field("s", 0.0, 10.0, default=0.02, label="t_window", aliases=("ms",))
    band_recovery: float = spec_field("rad/s", 0.0, 1e4, default=0.1, label="recovery band", aliases=("rpm",))

    def __post_init__(self) -> None:
        """Check the fields' ranges, turn mapping load steps into :class:`TorqueStep`, check their times increase."""
        check_fields(self, "scenario.cases")
        steps = tuple(s if isinstance(s, TorqueStep) else TorqueStep(**s) for s in self.T_L_steps)
        times = [s.t for s in steps]
        if times != sorted(times) or any(t >= self.t_end for t in times):
            raise ParameterError(
                f"scenario.cases.T_L_steps times = {times} s are out of order or too late: allowed increasing "
                f"times below t_end = {self.t_end} s"
            )
        object.__setattr__(self, "T_L_steps", steps)

    @property
    def segments(self) -> tuple[tuple[float, float], ...]:
        """Constant-load intervals (t_start, t_stop) [s]."""
        edges = [0.0] + [s.t for s in self.T_L_steps] + [self.t_end]
        return tuple((a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a)


@dataclass(frozen=True)
class BldcScenarios:
    """The scenarios of a preset and the one that runs.

    Attributes
    ----------
    active : str
        Name of the scenario to simulate.
    cases : tuple of BldcScenario
        All scenarios (section IV of [2] has two).
    """

    active: str
    cases: tuple[BldcScenario, ...]

    def __post_init__(self) -> None:
        """Turn mapping cases into :class:`BldcScenario` and check that ``active`` names one of them."""
        cases = tuple(c if isinstance(c, BldcScenario) else BldcScenario(**c) for c in self.cases)
        if not cases:
            raise ParameterError("scenario.cases is empty: allowed one or more scenarios")
        names = [c.name for c in cases]
        if self.active not in names:
            raise ParameterError(f"scenario.active = {self.active!r} is not allowed: one of {', '.join(names)}")
        object.__setattr__(self, "cases", cases)

    @property
    def selected(self) -> BldcScenario:
        """The active scenario."""
        return next(c for c in self.cases if c.name == self.active)


@dataclass(frozen=True)
class BldcParams:
    """Everything one BLDC speed-control case needs (preset ``mode: bldc``)."""

    machine: BldcMachine
    mechanics: BldcMechanics
    inverter: BldcInverter
    gains: BldcGains
    scenario: BldcScenarios
    name: str = "custom"
    source: str = "user input"

    @property
    def case(self) -> BldcScenario:
        """The active scenario."""
        return self.scenario.selected
