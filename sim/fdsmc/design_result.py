"""The result of "Design for this drive": the designed setting, its verification run and its words.

:class:`DriveDesign` holds the designed preset, the simulated verification run with the sensors,
the constraints that bind or fail (the diagnosis, :mod:`sim.fdsmc.diagnosis`) and the verified
alternatives offered where the request cannot be met. The builders here turn one verified run into
a result; the search for the setting is in :mod:`sim.fdsmc.design_verify` and
:mod:`sim.fdsmc.design_search`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.control.fdsmc.noise import NoiseGain, noise_gain
from pmsm_commissioning.control.fdsmc.params import ENCODER_CPR_MAX, DriveParams
from pmsm_commissioning.sim.fdsmc.checks import Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.engine import Comparison, RunResult
from pmsm_commissioning.sim.fdsmc.verdicts import comparator_notes, flux_warnings

#: Exit status of ``design`` per verdict (documented in README.md and docs/real_drive.md).
EXIT_STATUS = {"clean": 0, "not as asked": 3, "not clean": 4}


@dataclass(frozen=True)
class Alternative:
    """A change of the request that the design verified clean (or clean at a longer T_m) by simulation.

    Attributes
    ----------
    field : str            The preset key changed, e.g. ``"limits.hold_i_rms"``.
    value : float          Its value in SI units [unit].
    unit : str
    verdict : str          The verified verdict with the change (``clean`` or ``not as asked``).
    T_m : float            The move time of the verified design [s].
    in_position_s : float  When its verified run is in position for good [s].
    text : str             One sentence.
    """

    field: str
    value: float
    unit: str
    verdict: str
    T_m: float
    in_position_s: float
    text: str


@dataclass(frozen=True)
class DriveDesign:
    """A designed setting, its verification run and the constraints that shaped it.

    Attributes
    ----------
    params : DriveParams            The designed inputs (a complete preset).
    derived : Derived               Their derivations.
    comparison : Comparison | None  The verification runs, with the sensors (None when not simulated).
    clean : bool                    True when the FDSMC run passed every check as asked.
    limiting : tuple of Constraint  Binding and violated constraints (the diagnosis first).
    notes : tuple of str            Statements that do not make the design unclean.
    comparator : tuple of str       Where the conventional comparator fails the drive's checks.
    as_asked : bool                 False when the requested T_m (or cycle time) had to be lengthened.
    noise : NoiseGain or None       Predicted standstill ripple of the designed loop.
    encoder_cpr_needed : int or None  Smallest power-of-two encoder resolution whose quantization
                                    alone keeps the predicted ripple within the criterion [counts/rev].
    T_m_asked : float or None       The requested T_m [s] (for the objective "in position by T_m" the
                                    time by which the axis must be in position).
    alternatives : tuple of Alternative  Verified changes of the request that pass (a design that
                                    is not clean only).
    """

    params: DriveParams
    derived: Derived
    comparison: Comparison | None
    clean: bool
    limiting: tuple[Constraint, ...]
    notes: tuple[str, ...]
    comparator: tuple[str, ...] = ()
    as_asked: bool = True
    noise: NoiseGain | None = None
    encoder_cpr_needed: int | None = None
    T_m_asked: float | None = None
    alternatives: tuple[Alternative, ...] = ()

    @property
    def refused(self) -> bool:
        """True when the design was refused before any run (nothing designed or simulated)."""
        return self.comparison is None

    @property
    def verdict(self) -> str:
        """``"clean"``, ``"not as asked"`` (clean only at a longer T_m) or ``"not clean"``."""
        if self.refused or any(c.violated for c in self.limiting):
            return "not clean"
        return "clean" if self.as_asked else "not as asked"

    @property
    def exit_status(self) -> int:
        """Exit status of ``design`` for this verdict (:data:`EXIT_STATUS`)."""
        return EXIT_STATUS[self.verdict]

    @property
    def in_position_s(self) -> float | None:
        """When the verification run is inside the in-position window for good [s]; None: never/not run."""
        run = self.comparison.fdsmc if self.comparison is not None else None
        return None if run is None else run.metrics.in_position_s


def with_field(params: DriveParams, section: str, **changes: object) -> DriveParams:
    """``params`` with ``changes`` in ``section`` (a frozen dataclass replaced)."""
    return dataclasses.replace(params, **{section: dataclasses.replace(getattr(params, section), **changes)})


def round_up(x: float, digits: int = 3) -> float:
    """``x`` rounded up to ``digits`` significant digits (a time an engineer can type) [-]."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return float(round(math.ceil(x * scale - 1e-9) / scale, 12))


def round_down(x: float, digits: int = 3) -> float:
    """``x`` rounded down to ``digits`` significant digits [-]."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return float(round(math.floor(x * scale + 1e-9) / scale, 12))


def predicted_noise(p: DriveParams, d: Derived, encoder_cpr: int | None = None) -> NoiseGain | None:
    """Standstill ripple of ``p``'s FDSMC loop from its sensors (None for a continuous controller).

    ``encoder_cpr`` replaces the preset's encoder resolution [counts/rev] (0: an ideal encoder).
    """
    if d.loop.f_s is None:
        return None
    se, c = p.sensors, p.controller
    count = se.encoder_step if encoder_cpr is None else (2.0 * math.pi / encoder_cpr if encoder_cpr else 0.0)
    return noise_gain(d.loop, "slope", c.K, count, se.reading_noise, c.T_dv)


def encoder_needed(p: DriveParams, d: Derived, criterion: float) -> int | None:
    """Smallest power-of-two counts per rev at which the predicted standstill ripple is ≤ ``criterion`` [A].

    None for a continuous controller, or where the current noise alone (an ideal encoder) exceeds the
    criterion. The ripple falls as the count shrinks (:func:`control.fdsmc.noise.noise_gain`), so the
    exponent is bisected between 2⁴ and :data:`control.fdsmc.params.ENCODER_CPR_MAX`.
    """
    ideal = predicted_noise(p, d, 0)
    if ideal is None or not ideal.i_q_rms <= criterion:
        return None

    def passes(bits: int) -> bool:
        g = predicted_noise(p, d, 2**bits)
        return g is not None and g.i_q_rms <= criterion

    lo, hi = 4, int(math.log2(ENCODER_CPR_MAX))
    if passes(lo):
        return 1 << lo
    if not passes(hi):
        return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if passes(mid) else (mid, hi)
    return 1 << hi


def refused(p: DriveParams, limiting: list[Constraint], asked: DriveParams | None = None) -> DriveDesign:
    """Return a design refused before any run: ``p`` as it stands, the constraints that refuse it."""
    T_asked = (asked or p).manoeuvre.T_m
    return DriveDesign(p, derive(p), None, False, tuple(limiting), (), T_m_asked=T_asked)


def verified(p: DriveParams, d: Derived, cmp: Comparison, asked: DriveParams) -> DriveDesign:
    """Return the result of the verified setting ``p`` for the request ``asked`` (as asked at the asked T_m)."""
    assert cmp.fdsmc is not None
    limiting = [torque_binding(p, d, cmp.fdsmc)] + run_checks(p, cmp.fdsmc)
    ng = predicted_noise(p, d)
    crit = pass_criteria(p).hold_i_rms
    need = encoder_needed(p, d, crit)
    as_asked = p.manoeuvre.T_m == asked.manoeuvre.T_m
    clean = as_asked and not any(c.violated for c in limiting)
    notes = _notes(d) + _sensor_notes(p, asked, ng, crit, need)
    return DriveDesign(p, d, cmp, clean, tuple(limiting), notes, tuple(comparator_notes(cmp)), as_asked, ng, need,
                       asked.manoeuvre.T_m)


def torque_binding(p: DriveParams, d: Derived, run: RunResult) -> Constraint:
    """α_max and the torque limit it is set by, with the simulated peak (binding, not violated)."""
    lim = torque_limit(p)
    peak = run.metrics.torque_peak_Nm or 0.0
    a = d.alpha.alpha_max  # derive's α_max: the rule with the inner loops' overshoot η
    why = ("is set by the torque limit" if p.controller.alpha_max_rule == "torque_limit" else
           "minimises the profile's friction + copper loss (rule min_energy) within the torque limit")
    return Constraint("torque", peak, lim, "N·m", False,
                      f"α_max = {a:.5g} rad/s² {why} {lim:.4g} N·m (Γ_max or i_max); simulated peak {peak:.4g} N·m.")


def _sensor_notes(p: DriveParams, asked: DriveParams, ng: NoiseGain | None, crit: float,
                  need: int | None) -> tuple[str, ...]:
    out = []
    c, a = p.controller, asked.controller
    if c.T_so != a.T_so:
        out.append(f"T_so {a.T_so * 1e3:.4g} → {c.T_so * 1e3:.4g} ms and T_sα {a.T_salpha * 1e3:.4g} → "
                   f"{c.T_salpha * 1e3:.4g} ms: slower observer and acceleration loop for the sensors' noise.")
    if ng is not None and math.isfinite(ng.i_q_rms):
        out.append(f"Predicted standstill ripple {ng.i_q_rms:.3g} A rms of i_q, {ng.u_q_rms:.3g} V rms of u_q "
                   f"(criterion {crit:.3g} A)" + (f"; the encoder needs ≥ {need} counts/rev." if need else "."))
    return tuple(out)


def _notes(d: Derived) -> tuple[str, ...]:
    notes: list[str] = []
    K, w_p = d.params.controller.K, d.profile.omega_p
    if w_p <= 1.0 / K:
        notes.append(f"Boundary layer ±1/K = ±{1.0 / K:.4g} rad/s is wider than ω_p = {w_p:.4g} rad/s: the "
                     "outer loop is linear (never sliding) on this manoeuvre; the K limit of the sampled "
                     "loop allows no larger K.")
    return tuple(notes + flux_warnings(d))


__all__ = ["Alternative", "DriveDesign", "EXIT_STATUS", "encoder_needed", "predicted_noise", "refused", "round_down",
           "round_up", "torque_binding", "verified", "with_field"]
