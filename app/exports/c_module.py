"""C99 controller module generator: ``fdsmc_controller.h`` and ``fdsmc_controller.c``.

The constants come from one derived design (:class:`control.fdsmc.derivations.Derived`): motor model,
coefficients A…M of eqs. (1)–(4) in [1], FDC settling times, sliding-mode K, T_c, ω_p, α_max, the
comparator's g1, g2, the inverter limits, the computation delay and the discrete observer at the
drive's f_s — the observer in a scaled state-space form (:func:`scaled_observer`) so that float32
firmware is accurate. The C code itself is in :mod:`app.exports.c_template`.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from control.fdsmc.derivations import Derived
from control.fdsmc.params import DriveParams, ParameterError

from .c_template import HEADER, SOURCE

TOOL = "pmsm-commissioning (FDSMC)"
#: File names of the generated module.
HEADER_NAME, SOURCE_NAME = "fdsmc_controller.h", "fdsmc_controller.c"


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
        raise ParameterError("controller.f_s = 'continuous' cannot be exported as C firmware: "
                             "allowed a sample rate in Hz (100 … 1e7)")
    f_s, J_r = 1.0 / od.T_s, d.params.motor.J_r
    scale = np.array([1.0, f_s, f_s**2 * J_r, f_s**3 * J_r])
    Phi = od.Phi * scale[np.newaxis, :] / scale[:, np.newaxis]
    return ScaledObserver(scale, Phi, od.Gamma * f_s**2 / scale, od.L / scale)


def _model_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Motor model: nameplate values and the coefficients A…M of eqs. (1)–(4) in [1]."""
    m, c = params.motor, d.coefficients
    k = [CConstant("R_S", m.R_s, "Ohm", "stator resistance"), CConstant("L_D", m.L_d, "H", "d inductance"),
         CConstant("L_Q", m.L_q, "H", "q inductance"), CConstant("PSI_PM", m.psi_pm, "Wb", "magnet flux"),
         CConstant("POLE_PAIRS", m.p, "-", "pole pairs p", integer=True),
         CConstant("J_R", m.J_r, "kg*m^2", "rotor inertia (the load J_L is unknown to the controller)")]
    units = {"A": "1/s", "B": "-", "C": "-", "D": "1/s", "E": "A/rad", "F": "1/H", "G": "1/H",
             "H": "rad/s^2/A", "K": "rad/s^2/A^2", "M": "1/(kg*m^2)"}
    return k + [CConstant(f"COEF_{n}", getattr(c, n), u, "model coefficient, eqs. (1)-(4)") for n, u in units.items()]


def _loop_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Inner loops, sliding-mode outer loop, comparator and the designed manoeuvre."""
    ctrl, pr = params.controller, d.profile
    return [CConstant("T_SI", ctrl.T_si, "s", "d-current settling time, eq. (8)"),
            CConstant("T_SALPHA", ctrl.T_salpha, "s", "acceleration settling time, eq. (13)"),
            CConstant("T_SO", ctrl.T_so, "s", "observer settling time, eq. (17)"),
            CConstant("K_BL", ctrl.K, "s/rad", "boundary-layer gain K, eq. (45)"),
            CConstant("T_C", pr.T_c, "s", "sliding-mode time constant, eqs. (41), (59)"),
            CConstant("OMEGA_P", pr.omega_p, "rad/s", "peak speed, eq. (60)"),
            CConstant("ALPHA_MAX", d.alpha.alpha_max, "rad/s^2", f"acceleration limit ({d.alpha.rule} rule)"),
            CConstant("G1", d.conventional.g1, "1/s^2", "comparator gain, eq. (61)"),
            CConstant("G2", d.conventional.g2, "1/s", "comparator gain, eq. (61)"),
            CConstant("THETA_DEM", params.manoeuvre.theta_dem, "rad", "designed manoeuvre angle"),
            CConstant("T_M", params.manoeuvre.T_m, "s", "designed manoeuvre time")]


def _sampling_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Sample rate, delay, the discrete observer (information) and the inverter limits."""
    ctrl, od = params.controller, d.observer_discrete
    if od is None:
        scaled_observer(d)  # raises the continuous-mode message
    assert od is not None
    f_s, u_max = 1.0 / od.T_s, ctrl.V_dc / math.sqrt(3.0)
    k = [CConstant("F_S", f_s, "Hz", "sample rate"), CConstant("T_S", od.T_s, "s", "sample period"),
         CConstant("F_S2", f_s**2, "1/s^2", "f_s^2 (observer scaling)"),
         CConstant("F_S3", f_s**3, "1/s^3", "f_s^3 (observer scaling)"),
         CConstant("T_S2", od.T_s**2, "s^2", "T_s^2 (observer scaling)"),
         CConstant("DELAY_SAMPLES", ctrl.delay_samples, "samples", "computation delay", integer=True),
         CConstant("OBS_Q", d.observer.q, "1/s", "observer bandwidth 15/(2*T_so), eq. (17)"),
         CConstant("OBS_Z_POLE", od.z_pole, "-", "discrete observer pole exp(-q*T_s), four-fold")]
    k += [CConstant(f"OBS_L{i + 1}", float(v), u, "discrete observer gain (unscaled, information)")
          for i, (v, u) in enumerate(zip(od.L, ("-", "1/s", "N*m/rad", "N*m/(rad*s)"), strict=True))]
    return k + [CConstant("V_DC", ctrl.V_dc, "V", "DC link (0 = ideal inverter)"),
                CConstant("U_MAX", u_max, "V", "|u_dq| limit V_dc/sqrt(3)"),
                CConstant("HAS_U_MAX", int(u_max > 0.0), "-", "voltage limit active", integer=True),
                CConstant("I_MAX", ctrl.i_max, "A", "|i_q| limit (0 = none)"),
                CConstant("HAS_I_MAX", int(ctrl.i_max > 0.0), "-", "current limit active", integer=True),
                CConstant("GAMMA_MAX", params.motor.Gamma_max, "N*m", "motor torque limit (information)")]


def controller_constants(params: DriveParams, d: Derived) -> list[CConstant]:
    """Every constant the controller module defines, in SI units, in header order."""
    return _model_constants(params, d) + _loop_constants(params, d) + _sampling_constants(params, d)


def c_literal(x: float) -> str:
    """Format a C double literal that reads back exactly (17 significant digits), e.g. ``1.5e-05``."""
    text = repr(float(x))
    if not math.isfinite(float(x)):
        raise ParameterError(f"constant {x!r} is not finite: a C module needs finite values")
    return text if any(ch in text for ch in ".e") else text + ".0"


def _ascii(text: str) -> str:
    """Comment-safe ASCII: non-ASCII as '?', and no comment terminator."""
    return text.encode("ascii", "replace").decode("ascii").replace("*/", "* /")


def _define(k: CConstant) -> str:
    value = str(int(k.value)) if k.integer else f"((fdsmc_real){c_literal(k.value)})"
    return f"#define FDSMC_{k.name:<13} {value:<32} /* [{k.unit}] {_ascii(k.ref)} */"


def controller_header(params: DriveParams, d: Derived, schema: int) -> str:
    """Text of ``fdsmc_controller.h`` for the derived design ``d`` of ``params``."""
    defines = "\n".join(_define(k) for k in controller_constants(params, d))
    return HEADER.substitute(tool=TOOL, name=_ascii(params.name),
                             source=_ascii(params.source), schema=schema, constants=defines)


def _row(values: np.ndarray) -> str:
    return ", ".join(f"R_({c_literal(v)})" for v in values)


def controller_source(params: DriveParams, d: Derived) -> str:
    """Text of ``fdsmc_controller.c`` for the derived design ``d`` of ``params``."""
    so = scaled_observer(d)
    phi = ",\n".join(f"    {{{_row(r)}}}" for r in so.Phi)
    return SOURCE.substitute(name=_ascii(params.name), phi=phi, gamma=_row(so.Gamma), gain=_row(so.L))


def controller_files(params: DriveParams, d: Derived, schema: int) -> dict[str, str]:
    """File name → text of the controller module (header and source)."""
    return {HEADER_NAME: controller_header(params, d, schema), SOURCE_NAME: controller_source(params, d)}
