"""C99 controller module generator: ``fdsmc_controller.h`` and ``fdsmc_controller.c``.

The constants come from one derived design (:class:`control.fdsmc.derivations.Derived`): motor model,
coefficients A…M of eqs. (1)–(4) in [1], FDC settling times, sliding-mode K, the designed move's T_c and
ω_p, α_max, the comparator's g1, g2, the inverter limits, the computation delay, the encoder resolution
and the discrete observer at the drive's f_s in a scaled state-space form (:func:`scaled_observer`) so
that float32 firmware is accurate. They are written twice: as ``#define FDSMC_<NAME>`` with unit and
reference (documentation, and for the integrator's code) and as the ``const fdsmc_params FDSMC_DESIGN``
the step reads (with precomputed products and reciprocals). The C code is in
:mod:`app.exports.firmware.template`; every text goes through :func:`app.exports.firmware.text.c_string`.

The header carries the verdict (:class:`Verdict`): an unverified or not clean design stops the
compiler with ``#error`` unless ``FDSMC_ACCEPT_UNCLEAN`` equals the design's :func:`parameter_hash` (of the
inputs and the tool's version) as a literal.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.app.exports.firmware.design import design_constants, design_initializer, encoder_counts_per_rev
from pmsm_commissioning.app.exports.firmware.optimum import (
    STATE_FIELDS,
    ReferenceTable,
    law_parts,
    optimum_constants,
    reference_table,
)
from pmsm_commissioning.app.exports.firmware.source import FDSMC_MOVE, LIMIT_CODE, SOURCE
from pmsm_commissioning.app.exports.firmware.template import HEADER
from pmsm_commissioning.app.exports.firmware.text import c_string
from pmsm_commissioning.app.exports.tool_id import tool_version
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.presets import to_raw
from pmsm_commissioning.app.io.units import spec_of
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.tracking import slide_gain

#: File names of the generated module.
HEADER_NAME, SOURCE_NAME = "fdsmc_controller.h", "fdsmc_controller.c"

#: The outer laws the C module can run.
LAWS = ("fdsmc", "optimum")

#: Why a continuous-mode case has no C export.
CONTINUOUS_REFUSED = ("controller.f_s = 'continuous' cannot be exported as C firmware: "
                      "allowed a sample rate in Hz (100 … 1e7)")


@dataclass(frozen=True)
class CConstant:
    """One ``#define FDSMC_<name>``: value (SI), unit and reference; ``integer`` for counts/flags."""

    name: str
    value: float
    unit: str
    ref: str
    integer: bool = False


@dataclass(frozen=True)
class ScaledObserver:
    """Discrete observer in the scaled coordinates z = S⁻¹·x̂ (every z_i in rad).

    Attributes
    ----------
    scale : numpy.ndarray
        Diagonal of S: [1 -, f_s 1/s, f_s²·J_r N·m/rad, f_s³·J_r N·m/(rad·s)], x̂ = S·z.
    Phi : numpy.ndarray   S⁻¹·Φ·S [-].
    Gamma : numpy.ndarray S⁻¹·Γ·f_s² (input a_em·T_s² in rad) [-].
    L : numpy.ndarray     S⁻¹·L [-].
    """

    scale: np.ndarray
    Phi: np.ndarray
    Gamma: np.ndarray
    L: np.ndarray


@dataclass(frozen=True)
class Verdict:
    """What the header says about the design's verification.

    Attributes
    ----------
    verified : bool
        True when the tool simulated the design (the FDSMC run exists).
    failed : tuple of (str, str)
        (name, text) of each violated check of :func:`sim.fdsmc.design.run_checks`; empty when clean.
    """

    verified: bool
    failed: tuple[tuple[str, str], ...] = ()

    @property
    def clean(self) -> bool:
        """True when verified and no check failed."""
        return self.verified and not self.failed


#: The verdict of a module made without a simulation: it does not compile unless accepted.
UNVERIFIED = Verdict(False, (("unverified", "The design was not simulated by the tool."),))


def verdict_of(checks: Sequence | None) -> Verdict:
    """Verdict from :func:`sim.fdsmc.design.run_checks` (objects with .name, .text, .violated); None: unverified."""
    if checks is None:
        return UNVERIFIED
    return Verdict(True, tuple((c.name, c.text) for c in checks if c.violated))


def scaled_observer(d: Derived) -> ScaledObserver:
    """Return the derived discrete observer in coordinates where each state is the angle it moves in one sample.

    The observer is the prediction form of :func:`control.fdsmc.observer.discrete_observer`; each state is
    scaled to the angle [rad] it moves in one sample.

    Raises
    ------
    ParameterError
        In continuous mode (no sample rate, so no discrete observer).
    """
    od = d.observer_discrete
    if od is None:
        raise ParameterError(CONTINUOUS_REFUSED)
    f_s, J_r = 1.0 / od.T_s, d.params.motor.J_r
    scale = np.array([1.0, f_s, f_s**2 * J_r, f_s**3 * J_r])
    Phi = od.Phi * scale[np.newaxis, :] / scale[:, np.newaxis]
    Gamma = od.Gamma * f_s**2 / scale
    # The float C advances the angle in counts and leaves out the zero terms of the chain of integrators.
    if not (np.array_equal(Phi[:, 0], [1.0, 0.0, 0.0, 0.0]) and not np.tril(Phi, -1).any() and not Gamma[2:].any()):
        raise ParameterError("the discrete observer is not an upper-triangular chain (Φ column 0 = (1, 0, 0, 0), "
                             "Γ = (g0, g1, 0, 0)): the C module cannot export it")
    return ScaledObserver(scale, Phi, Gamma, od.L / scale)


#: Constants that are inputs of the preset: C name → ``section.field`` (unit and range from its spec).
INPUT_KEYS: dict[str, str] = {
    "R_S": "motor.R_s", "L_D": "motor.L_d", "L_Q": "motor.L_q", "PSI_PM": "motor.psi_pm", "POLE_PAIRS": "motor.p",
    "J_R": "motor.J_r", "T_SI": "controller.T_si", "T_SALPHA": "controller.T_salpha", "T_SO": "controller.T_so",
    "K_BL": "controller.K", "THETA_DEM": "manoeuvre.theta_dem", "T_M": "manoeuvre.T_m",
    "DELAY_SAMPLES": "controller.delay_samples", "V_DC": "controller.V_dc", "I_MAX": "controller.i_max",
    "GAMMA_MAX": "motor.Gamma_max", "T_DV": "controller.T_dv",
}


#: Non-ASCII unit and range symbols → their ASCII spelling.
_ASCII_UNITS = (("Ω", "Ohm"), ("·", "*"), ("²", "^2"), ("≤", "<="), ("≥", ">="), ("…", "..."))


def c_unit(text: str) -> str:
    """Spell a unit or range text in ASCII, e.g. ``"kg·m²"`` → ``"kg*m^2"``."""
    for old, new in _ASCII_UNITS:
        text = text.replace(old, new)
    return text


def _input(name: str, params: DriveParams, ref: str) -> CConstant:
    """Make an input of the preset a constant, with the unit and allowed range of the field's spec."""
    spec = spec_of(INPUT_KEYS[name])
    section, field = INPUT_KEYS[name].split(".")
    value = getattr(getattr(params, section), field)
    return CConstant(name, value, c_unit(spec.unit), f"{ref}; {c_unit(spec.range_text())}", integer=spec.integer)


def _model_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Motor model: nameplate values and the coefficients A…M of eqs. (1)–(4) in [1]."""
    c = d.coefficients
    k = [_input("R_S", params, "stator resistance"), _input("L_D", params, "d inductance"),
         _input("L_Q", params, "q inductance"), _input("PSI_PM", params, "magnet flux"),
         _input("POLE_PAIRS", params, "pole pairs p"),
         _input("J_R", params, "rotor inertia (the load J_L is unknown to the controller)")]
    units = {"A": "1/s", "B": "-", "C": "-", "D": "1/s", "E": "A/rad", "F": "1/H", "G": "1/H",
             "H": "rad/s^2/A", "K": "rad/s^2/A^2", "M": "1/(kg*m^2)"}
    return k + [CConstant(f"COEF_{n}", getattr(c, n), u, "model coefficient, eqs. (1)-(4)") for n, u in units.items()]


def _loop_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Inner loops, sliding-mode outer loop, comparator and the designed manoeuvre."""
    pr = d.profile
    return [_input("T_SI", params, "d-current settling time, eq. (8)"),
            _input("T_SALPHA", params, "acceleration settling time, eq. (13)"),
            _input("T_SO", params, "observer settling time, eq. (17)"),
            _input("K_BL", params, "boundary-layer gain K, eq. (45)"),
            CConstant("T_C", pr.T_c, "s", "designed move's sliding-mode time constant, eqs. (41), (59)"),
            CConstant("OMEGA_P", pr.omega_p, "rad/s", "designed move's peak speed, eq. (60)"),
            CConstant("ALPHA_MAX", d.alpha.alpha_max, "rad/s^2", f"acceleration limit ({d.alpha.rule} rule)"),
            CConstant("G1", d.conventional.g1, "1/s^2", "comparator gain, eq. (61)"),
            CConstant("G2", d.conventional.g2, "1/s", "comparator gain, eq. (61)"),
            _input("THETA_DEM", params, "designed manoeuvre angle (information: moves are set at run time)"),
            _input("T_M", params, "designed manoeuvre time (information)")]


def _sampling_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Sample rate, delay, the discrete observer (information) and the inverter limits."""
    ctrl, od = params.controller, d.observer_discrete
    if od is None:
        scaled_observer(d)  # raises the continuous-mode message
    assert od is not None
    f_s, u_max = 1.0 / od.T_s, ctrl.V_dc / math.sqrt(3.0)
    k = [CConstant("F_S", f_s, "Hz", "sample rate"), CConstant("T_S", od.T_s, "s", "sample period"),
         _input("DELAY_SAMPLES", params, "computation delay"),
         CConstant("OBS_Q", d.observer.q, "1/s", "observer bandwidth 15/(2*T_so), eq. (17)"),
         CConstant("OBS_Z_POLE", od.z_pole, "-", "discrete observer pole exp(-q*T_s), four-fold")]
    k += [CConstant(f"OBS_L{i + 1}", float(v), u, "discrete observer gain (unscaled, information)")
          for i, (v, u) in enumerate(zip(od.L, ("-", "1/s", "N*m/rad", "N*m/(rad*s)"), strict=True))]
    return k + [_input("V_DC", params, "DC link (0 = ideal inverter)"),
                CConstant("U_MAX", u_max, "V", "|u_dq| limit V_dc/sqrt(3) (0 = none)"),
                _input("I_MAX", params, "inverter current amplitude (0 = none)"),
                _input("T_DV", params, "q-axis voltage-mismatch estimate's time constant (0 = none, the paper)"),
                CConstant("VOLTAGE_MISMATCH", 1 if ctrl.T_dv > 0.0 else 0, "-",
                          "1: u_q corrected by the q-axis voltage-mismatch estimate", integer=True),
                _input("GAMMA_MAX", params, "motor torque limit (information)"),
                CConstant("COUNTS_PER_REV", encoder_counts_per_rev(params), "1/rev",
                          "encoder counts per mechanical revolution", integer=True)]


def controller_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Every constant the controller module defines, in SI units, in header order."""
    runtime = [CConstant(n, v, u, r) for n, v, u, r in design_constants(params, d)]
    return _model_constants(params, d) + _loop_constants(params, d) + _sampling_constants(params, d) + runtime


def c_literal(x: float) -> str:
    """Format a C double literal that reads back exactly (17 significant digits), e.g. ``1.5e-05``."""
    text = repr(float(x))
    if not math.isfinite(float(x)):
        raise ParameterError(f"constant {x!r} is not finite: a C module needs finite values")
    return text if any(ch in text for ch in ".e") else text + ".0"


def _comment(text: str) -> str:
    """Return the tool's own reference text for a comment: ASCII as is when plainly safe, else :func:`c_string`."""
    text = c_unit(text)
    plain = text.isascii() and text.isprintable() and not any(s in text for s in ("*/", "/*", "//", "??", "\\"))
    return text if plain else c_string(text)


def _define(k: CConstant) -> str:
    value = str(int(k.value)) if k.integer else f"((fdsmc_real){c_literal(k.value)})"
    return f"#define FDSMC_{k.name:<15} {value:<32} /* [{_comment(k.unit)}] {_comment(k.ref)} */"


def parameter_hash(params: DriveParams, tool: str | None = None) -> str:
    """Hash of a design: 16 hex digits of SHA-256 over the preset's canonical JSON and the tool's version.

    ``tool``: ``"<tool> <version>"`` (default :func:`app.exports.tool_id.tool_version`, the installed
    package's). The same inputs give the same hash whether exported as YAML, JSON or C (the loader reads
    every format back to the same :class:`DriveParams`), so the hash ties a ``.h`` to its file; another
    version of the tool, whose generated code may differ, gives another hash (an accepted unclean
    design must be accepted again).
    """
    data = {"inputs": to_json(to_raw(params)), "tool": tool_version() if tool is None else tool}
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return hashlib.sha256(text.encode("ascii")).hexdigest()[:16]


def _gate_texts(v: Verdict, hash_value: str, label: str = "FDSMC") -> dict[str, str]:
    """Header placeholders of the verdict gate (``label``: the outer law whose run was checked)."""
    names = ", ".join(n for n, _ in v.failed)
    if v.clean:
        verdict = f"CLEAN -- the simulated {label} run of this design passed every check."
    else:
        verdict = ("UNVERIFIED" if not v.verified else "NOT CLEAN") + " -- this header stops the build (#error)" \
                  " unless FDSMC_ACCEPT_UNCLEAN is defined as FDSMC_PARAM_HASH. Failed checks:"
    checks = "".join(f" *   {c_string(f'{n}: {t}')}\n" for n, t in v.failed)
    error = (f"fdsmc_controller.h: design {'not verified' if not v.verified else 'not clean'} (failed: {names});"
             f" see the header; to build it anyway define FDSMC_ACCEPT_UNCLEAN={hash_value}")
    return {"verdict": verdict, "checks": checks, "verified": str(int(v.verified)), "clean": str(int(v.clean)),
            "failed": c_string(names), "error_text": c_string(error)}


#: The outer law's line in the header: FDSMC, or the tracked optimum.
LAW_TEXT = {False: "FDSMC, eqs. (41)-(46) of [1] (fdsmc_step).",
            True: "tracked minimum-energy optimum with the FDSMC's terminal slide (fdsmc_step;\n"
                  " *   control/fdsmc/terminal_slide.py): the reference table of the designed move only,\n"
                  " *   FDSMC_REF_DELTA counts in FDSMC_T_M (fdsmc_set_move refuses others: FDSMC_ERR_TABLE)."}


def controller_header(params: DriveParams, d: Derived, schema: int, verdict: Verdict = UNVERIFIED,
                      inputs: DriveParams | None = None, table: ReferenceTable | None = None) -> str:
    """Text of ``fdsmc_controller.h`` for the derived design ``d`` of ``params``.

    ``inputs``: the preset as entered, whose :func:`parameter_hash` the header carries (default ``params``;
    the export passes the entered preset when ``params`` has θ_dem rounded to a count). ``table``: the
    tracked optimum's reference (:func:`app.exports.firmware.optimum.reference_table`) for its module; None: FDSMC.
    """
    constants = controller_constants(params, d)
    if table is not None:
        constants += [CConstant(*k) for k in optimum_constants(params, d, table)]
    defines = "\n".join(_define(k) for k in constants)
    tool = tool_version()
    h = parameter_hash(params if inputs is None else inputs, tool)
    optimum = table is not None
    return HEADER.substitute(tool=c_string(tool)[1:-1], name=c_string(params.name), source=c_string(params.source),
                             schema=schema, constants=defines, hash_text=h, hash_value=f"0x{h}u",
                             law_text=LAW_TEXT[optimum], optimum=int(optimum),
                             state_fields=STATE_FIELDS if optimum else "",
                             **_gate_texts(verdict, f"0x{h}u", "tracked optimum" if optimum else "FDSMC"))


def controller_source(params: DriveParams, d: Derived, table: ReferenceTable | None = None) -> str:
    """Text of ``fdsmc_controller.c`` for the derived design ``d`` of ``params`` (``table``: the optimum's)."""
    so = scaled_observer(d)
    law = (law_parts(table, c_literal) if table is not None else
           {"set_move": FDSMC_MOVE, "outer_law": "", "outer_call": "sliding_mode(s, th_re, w, &S)", "law_init": "",
            "take_law": ""})
    K = slide_gain(d.gain, params.controller.K) if table is not None else params.controller.K
    return SOURCE.substitute(name=c_string(params.name), design=design_initializer(params, d, so, c_literal, K),
                             limit_code=LIMIT_CODE, **law)


def controller_files(params: DriveParams, d: Derived, schema: int, verdict: Verdict = UNVERIFIED,
                     inputs: DriveParams | None = None, law: str = "fdsmc") -> dict[str, str]:
    """File name → text of the controller module (header and source); unverified unless ``verdict`` says.

    ``law``: ``"fdsmc"``, or ``"optimum"`` for the tracked optimum's module (its reference table from
    :func:`control.fdsmc.optimum.tracked_move`, as the simulator's).
    """
    if law not in LAWS:
        raise ParameterError(f"controller = {law!r} has no C module: allowed {', '.join(LAWS)}")
    table = reference_table(params, d) if law == "optimum" else None
    return {HEADER_NAME: controller_header(params, d, schema, verdict, inputs, table),
            SOURCE_NAME: controller_source(params, d, table)}
