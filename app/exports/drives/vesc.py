"""VESC: the motor part of an mcconf XML ``vesc_tool --setMcConf FILE.xml`` (or VESC Tool's "Load XML") loads.

VESC Tool saves the motor configuration as ``<MCConfiguration>`` with a ``<ConfigVersion>`` and one
element per parameter of ``parameters_mcconf.xml`` (the firmware's ``mc_configuration`` in
``datatypes.h``), each value in the stored (SI) unit, not the editor's scaled one: ``foc_motor_r``
[Ω] (shown in mΩ), ``foc_motor_l`` and ``foc_motor_ld_lq_diff`` [H] (shown in µH; L is the mean of
L_d and L_q, the difference L_q − L_d), ``foc_motor_flux_linkage`` [Wb] (shown in mWb; the
amplitude-invariant Ψ_PM), ``l_current_max``/``l_current_min`` [A] (motor current), ``si_motor_poles``
(poles, not pole pairs), ``foc_current_kp`` [V/A] and ``foc_current_ki`` [V/(A·s)] (the current PI,
bandwidth 3/T_si: kp = L·ω_c, ki = R·ω_c, VESC Tool's own rule).

VESC has no position trajectory planner: the file writes the motor part and, as ``cascade.*`` comment
lines (:mod:`app.exports.drives.stock_lines`), the trapezoid and the position/speed cascade that a VESC app or
the host runs on VESC's current loop; :func:`vesc_loop` reads all of it back for the stock route.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from pmsm_commissioning.app.exports.drives.stock import StockSettings
from pmsm_commissioning.app.exports.drives.stock_lines import cascade_lines, parse_cascade
from pmsm_commissioning.app.exports.drives.units import pole_pairs_to_poles, poles_to_pole_pairs
from pmsm_commissioning.app.exports.drives.vendor_keys import VendorFile, VendorKey, fmt_float, vendor_file
from pmsm_commissioning.app.io.user_text import xml_comment
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_from_limits
from pmsm_commissioning.sim.stock.route import StockLoop
from pmsm_commissioning.sim.stock.tuning import setpoint_table

_DOC = "VESC Tool res/config parameters_mcconf.xml (fw 5.03+ / 6.x)"
#: Root element and version element of VESC Tool's mcconf XML.
ROOT, VERSION_TAG = "MCConfiguration", "ConfigVersion"
#: The ConfigVersion written: VESC Tool's VT_CONFIG_VERSION (vesc_tool.pro) of VESC Tool 6.06 and 7.0x
#: (fw 6.06+), which load the file without their "different firmware and/or different version of VESC
#: Tool" dialog (vescinterface.cpp mcconfUpdated: shown when fw ≥ 5.03 and the file's version differs).
#: VESC Tool 3.01–6.05 (fw 5.03–6.05) wrote 2; they show the dialog for this file but read the same
#: keys in the same units.
CONFIG_VERSION = 4
#: ConfigVersions read: 2 (VESC Tool 3.01–6.05), 3 (6.06 betas), 4 (6.06+). Before fw 5.03 (bldc
#: CHANGELOG 5.03 "Correct scaling for resistance and inductance", mcpwm_foc.c of 2021-10-15) the
#: firmware stored foc_motor_r, foc_motor_l and foc_motor_ld_lq_diff as 2/3 of the phase values; a
#: file from then has no ConfigVersion (VESC Tool ≤ 3.00) or 1 (a VESC Tool 3.01 test build of
#: 2021-10-31 only): which scaling it holds is not known, so it is refused.
CONFIG_VERSIONS_READ = (2, 3, 4)
#: Every key written, with its VESC type and stored unit.
KEYS: dict[str, VendorKey] = {vk.key: vk for vk in (
    VendorKey("motor_type", "enum", "-", f"{_DOC}: motor_type (2 = FOC)"),
    VendorKey("l_current_max", "float", "A", f"{_DOC}: l_current_max, Motor Current Max"),
    VendorKey("l_current_min", "float", "A", f"{_DOC}: l_current_min, Motor Current Max Brake (negative)"),
    VendorKey("foc_motor_r", "float", "Ohm", f"{_DOC}: foc_motor_r, Motor Resistance"),
    VendorKey("foc_motor_l", "float", "H", f"{_DOC}: foc_motor_l, Motor Inductance (mean of Ld, Lq)"),
    VendorKey("foc_motor_ld_lq_diff", "float", "H", f"{_DOC}: foc_motor_ld_lq_diff, Lq − Ld"),
    VendorKey("foc_motor_flux_linkage", "float", "Wb", f"{_DOC}: foc_motor_flux_linkage"),
    VendorKey("si_motor_poles", "int", "-", f"{_DOC}: si_motor_poles, Motor Poles"),
    VendorKey("foc_current_kp", "float", "V/A", f"{_DOC}: foc_current_kp, Current Controller Kp"),
    VendorKey("foc_current_ki", "float", "V/(A*s)", f"{_DOC}: foc_current_ki, Current Controller Ki"),
    VendorKey("foc_f_zv", "float", "Hz", f"{_DOC}: foc_f_zv, Zero Vector Frequency (current loop once per 2/f_zv)"),
)}
FOC = 2


def vesc_values(s: StockSettings) -> dict[str, float]:
    """Every written key → value in VESC's stored units (the one conversion from SI)."""
    L = 0.5 * (s.L_d + s.L_q)
    values = [FOC, s.current_limit, -s.current_limit, s.R_s, L, s.L_q - s.L_d, s.psi_pm, pole_pairs_to_poles(s.p),
              L * s.current_bandwidth, s.R_s * s.current_bandwidth, 2.0 * s.f_loop]
    return dict(zip(KEYS, values, strict=True))


#: The cascade lines of a VESC file.
CASCADE_KEYS = ("pos_gain", "vel_gain", "vel_integrator_gain", "inertia", "pll_bandwidth", "vel_limit", "accel_limit")


def cascade_values(s: StockSettings) -> dict[str, float]:
    """Return the stock route's cascade and trapezoid (SI) that a VESC file carries as comment lines."""
    g = s.gains
    return dict(zip(CASCADE_KEYS, (g.pos_gain, g.vel_gain, g.vel_integrator_gain, g.inertia, s.pll_bandwidth,
                                   abs(s.trapezoid.omega_c), s.trapezoid.alpha), strict=True))


def vesc_xml(s: StockSettings, header: list[str]) -> str:
    """Return the mcconf XML: declaration, the header as an XML comment, ``<MCConfiguration>`` with the motor part.

    Each comment line goes through :func:`app.io.user_text.xml_comment` (escaped, never ``--``): the
    XML stays well-formed and :func:`parse_vesc` reads the comment back line by line.
    """
    note = header + ["VESC: motor part (VESC has no position trajectory planner); load it in VESC Tool "
                     "(Motor Settings, Load XML) or with vesc_tool's setMcConf option, see docs/drives/vesc.md",
                     "the move's trapezoid and the position/speed cascade a VESC app or the host runs each "
                     "current-loop cycle (SI units):"] + cascade_lines(cascade_values(s))
    body = "\n".join(f"    {xml_comment(line)}" for line in note)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', f"<!--\n{body}\n-->", f"<{ROOT}>",
             f"    <{VERSION_TAG}>{CONFIG_VERSION}</{VERSION_TAG}>"]
    for key, v in vesc_values(s).items():
        text = str(int(v)) if KEYS[key].kind != "float" else fmt_float(v)
        lines.append(f"    <{key}>{text}</{key}>")
    lines.append(f"</{ROOT}>")
    return "\n".join(lines) + "\n"


def parse_vesc(text: str, origin: str = "<mcconf>") -> VendorFile:
    """Strict parser of an mcconf XML: root ``MCConfiguration``, a ``ConfigVersion``, flat scalar elements.

    Raises
    ------
    ParameterError
        For malformed XML, another root, a missing ConfigVersion, a nested or duplicated element,
        or a known key of the wrong type.
    """
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise ParameterError(f"{origin}: a DOCTYPE or ENTITY is not allowed in an mcconf XML")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ParameterError(f"{origin} is not well-formed XML: {exc}") from None
    if root.tag != ROOT:
        raise ParameterError(f"{origin}: root element <{root.tag}> is not allowed: <{ROOT}>")
    version = root.find(VERSION_TAG)
    if version is None:
        raise ParameterError(f"{origin}: <{VERSION_TAG}> is missing: an mcconf XML of VESC Tool ≥ 3.01 states its "
                             "version (an older file may hold R and L as 2/3 of the phase values, fw ≤ 5.02)")
    _check_version((version.text or "").strip(), origin)
    pairs = []
    for el in root:
        if len(el):
            raise ParameterError(f"<{el.tag}> has child elements: allowed a flat list of values")
        if el.tag != VERSION_TAG:
            pairs.append((el.tag, (el.text or "").strip()))
    comment = tuple(line.strip() for line in _comments(text))
    return vendor_file(pairs, KEYS, comment)


def _check_version(text: str, origin: str) -> None:
    """Refuse a ConfigVersion this reader cannot interpret (see :data:`CONFIG_VERSIONS_READ`)."""
    allowed = ", ".join(map(str, CONFIG_VERSIONS_READ))
    if not text.isdigit() or int(text) not in CONFIG_VERSIONS_READ:
        old = text.isdigit() and int(text) < CONFIG_VERSIONS_READ[0]
        why = ("before fw 5.03 foc_motor_r, foc_motor_l and foc_motor_ld_lq_diff were stored as 2/3 of the phase "
               "values; re-save the configuration with VESC Tool ≥ 3.01 on fw ≥ 5.03, or re-measure"
               if old else "a version this reader does not know")
        raise ParameterError(f"{origin}: <{VERSION_TAG}> = {text[:20]!r} is not allowed ({why}): allowed {allowed}")


def _comments(text: str) -> list[str]:
    out: list[str] = []
    start = text.find("<!--")
    while start >= 0:
        end = text.find("-->", start)
        out += text[start + 4: end].strip().splitlines()
        start = text.find("<!--", end)
    return out


def vesc_motor(f: VendorFile) -> tuple[float, float, float, float, int, float]:
    """R_s [Ω], L_d, L_q [H], Ψ_PM [Wb], p [-], i_max [A] of a parsed mcconf."""
    L = f.require("foc_motor_l", "the motor inductance [H]")
    diff = f.get("foc_motor_ld_lq_diff") or 0.0
    p = poles_to_pole_pairs(f.require("si_motor_poles", "the pole count"), "si_motor_poles")
    return (f.require("foc_motor_r", "the motor resistance [Ohm]"), L - 0.5 * diff, L + 0.5 * diff,
            f.require("foc_motor_flux_linkage", "the flux linkage [Wb]"), p,
            f.require("l_current_max", "the motor current limit [A]"))


def vesc_loop(f: VendorFile, params: DriveParams) -> StockLoop:
    """Return the stock route of a parsed mcconf: VESC's current PI each switching period, the file's cascade.

    Raises
    ------
    ParameterError
        Naming the key or comment line for a missing or malformed setting.
    """
    c = parse_cascade(f.comment, CASCADE_KEYS)
    rate = 0.5 * f.require("foc_f_zv", "the zero-vector frequency [Hz]")
    _, _, _, psi, p, i_lim = vesc_motor(f)
    tr = trapezoid_from_limits(params.manoeuvre.theta_dem, c["vel_limit"], c["accel_limit"])
    return StockLoop("vesc", rate, "cascade", c["pos_gain"], c["vel_gain"], c["vel_integrator_gain"], math.inf,
                     math.inf, c["inertia"], 1.5 * p * psi, i_lim, c["pll_bandwidth"], False,
                     f.require("foc_current_kp", "the current kp [V/A]"), f.require("foc_current_ki", "the current ki"),
                     setpoint_table(tr, 1.0 / rate), 1.0 / rate)
