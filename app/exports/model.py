"""The export model shared by the page's Export menu and ``pmsm-commission export``.

:func:`export_files` turns one simulated case (a :class:`sim.fdsmc.engine.Comparison`, whose
``derived.params`` are the inputs) into the files of one format — the same bytes whoever asks:

* ``yaml`` / ``json``: the drive parameter file (schema 2): an importable preset (inputs in SI)
  plus ``units`` (the unit of every input), ``drive_gains`` (value, unit, reference), ``verdicts``
  (feasibility, warnings, run warnings, savings) and ``results`` (each run's metrics, the unit in
  each key's suffix). The loader ignores the informational sections and recomputes them, so
  export → import → export gives identical bytes;
* ``c``: the C99 controller module (:mod:`app.exports.firmware.module`);
* ``csv``: the time series of both runs (:func:`trace_csv`);
* ``html``: the offline report (:mod:`app.exports.html`);
* ``odrive`` / ``moteus`` / ``vesc`` / ``setpoints``: the files a stock drive loads
  (:mod:`app.exports.drives.files`): the same move as a trapezoid and the comparator's gains as the
  drive's cascade, each with a header naming the preset, the tool's version, the verdicts, a hash of
  the parameters and the simulated energy of the stock route next to FDSMC and the optimum.

Every format passes one gate (:func:`app.exports.provenance.gate`): a design whose simulated FDSMC
run fails a check of :func:`sim.fdsmc.design.run_checks` is refused, naming the failed checks,
unless ``force``; a forced file carries the failed checks inside (``verdicts.failed_checks`` in
YAML/JSON, a comment block in C, CSV and the stock-drive files, a banner in HTML).

Files are named after the case's ``name``; no date is written, so exports are reproducible.
"""

from __future__ import annotations

import dataclasses
import io
import json
import re
import zipfile
from dataclasses import dataclass
from html import escape
from typing import Any

import numpy as np

from pmsm_commissioning.app.exports.drives.files import DRIVE_FORMATS, ExportOptions, drive_file
from pmsm_commissioning.app.exports.firmware.module import LAWS
from pmsm_commissioning.app.exports.firmware.text import c_comment
from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.provenance import check_text, failed_checks, gate, verdict_lines
from pmsm_commissioning.app.exports.tool_id import TOOL
from pmsm_commissioning.app.io.dc_link_view import choice_json
from pmsm_commissioning.app.io.derived_view import derived_rows
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.presets import SCHEMA, annotate_units, dumps, to_raw
from pmsm_commissioning.app.io.units import SI_UNITS
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.engine import Comparison, simulate
from pmsm_commissioning.sim.fdsmc.verdicts import comparator_notes, run_warnings

FORMATS = ("yaml", "json", "c", "csv", "html") + tuple(DRIVE_FORMATS)
#: Options of an export when none are given (not forced, setpoints in rad at the drive's cycle).
DEFAULT_OPTIONS = ExportOptions()


@dataclass(frozen=True)
class Gain:
    """One value the drive firmware needs: name (C identifier), value, unit, reference."""

    name: str
    value: float
    unit: str
    ref: str


def drive_gains(d: Derived) -> list[Gain]:
    """Every derived gain and setting the drive needs, in SI units.

    K1…K4 (continuous, eq. (18)), L1…L4 and the pole for f_s (discrete observer), α_max, ω_p,
    T_a, T_c, K, g1, g2, T_si, T_sα, θ_dem, T_m.
    """
    p, pr, o = d.params, d.profile, d.observer
    units = {r.symbol: r.unit for r in derived_rows(d)}
    gains = [
        Gain("ALPHA_MAX", d.alpha.alpha_max, "rad/s²", f"alpha_max, {d.alpha.rule} rule"),
        Gain("OMEGA_P", pr.omega_p, "rad/s", "peak speed, eq. (60)"),
        Gain("T_A", pr.T_a, "s", "acceleration time, eq. (58)"),
        Gain("T_C", pr.T_c, "s", "sliding-mode time constant, eq. (59)"),
        Gain("K_BL", p.controller.K, "s/rad", "boundary-layer gain K, eq. (45)"),
        Gain("G1", d.conventional.g1, "1/s²", "conventional gain, eq. (61)"),
        Gain("G2", d.conventional.g2, "1/s", "conventional gain, eq. (61)"),
        Gain("T_SI", p.controller.T_si, "s", "d-current settling time, eq. (8)"),
        Gain("T_SALPHA", p.controller.T_salpha, "s", "acceleration settling time, eq. (13)"),
        Gain("THETA_DEM", p.manoeuvre.theta_dem, "rad", "demanded angle"),
        Gain("T_M", p.manoeuvre.T_m, "s", "manoeuvre time"),
        Gain("OBS_Q", o.q, "1/s", "observer pole magnitude, eq. (17)"),
    ]
    gains += [Gain(f"OBS_K{i}", getattr(o, f"K{i}"), units.get(f"K{i}", "-"), "observer gain, eq. (18)")
              for i in range(1, 5)]
    od = d.observer_discrete
    if od is not None:
        gains += [Gain("F_S", 1.0 / od.T_s, "Hz", "controller sample rate"),
                  Gain("OBS_Z_POLE", od.z_pole, "-", "discrete observer pole exp(-q/f_s)")]
        gains += [Gain(f"OBS_L{i + 1}", float(v), units.get(f"L{i + 1}", "-"),
                       "discrete observer gain (Ackermann)") for i, v in enumerate(od.L)]
    return gains


def verdicts(cmp: Comparison) -> dict[str, Any]:
    """Feasibility, design warnings, run warnings and savings of one case."""
    d = cmp.derived
    return {"feasible": bool(d.profile.feasible), "warnings": list(d.warnings),
            "run_warnings": run_warnings(cmp), "comparator_notes": comparator_notes(cmp),
            "saving_friction_pct": cmp.saving_friction_pct,
            "saving_electrical_pct": cmp.saving_electrical_pct,
            "dc_link": choice_json(d.params.controller),
            "failed_checks": [check_text(c) for c in failed_checks(cmp)]}


def parameter_data(cmp: Comparison) -> dict[str, Any]:
    """Return the drive parameter file as plain data (schema 2): preset + units, gains, verdicts, results."""
    params = cmp.derived.params
    raw = to_raw(params)
    raw["units"] = {sec: dict(SI_UNITS[sec]) for sec in ("motor", "load", "controller", "manoeuvre")}
    raw["drive_gains"] = {g.name: {"value": g.value, "unit": g.unit, "ref": g.ref} for g in drive_gains(cmp.derived)}
    raw["verdicts"] = verdicts(cmp)
    raw["results"] = {r.controller: to_json(r.metrics) for r in (cmp.fdsmc, cmp.conventional) if r is not None}
    raw["exported_by"] = TOOL
    return to_json(raw)


def parameter_yaml(cmp: Comparison) -> str:
    """Drive parameter file as YAML (written by :func:`app.io.presets.dumps`)."""
    head = (f"# Drive parameter file (schema {SCHEMA}) — {TOOL}. SI units; the unit and allowed range of each\n"
            "# input are in the comment beside it, the units also in `units`. Re-import: the page's Import\n"
            "# button or any command taking PRESET, e.g. `pmsm-commission derive FILE`; drive_gains, verdicts\n"
            "# and results are then recomputed.\n")
    return head + annotate_units(dumps(parameter_data(cmp)))


def parameter_json(cmp: Comparison) -> str:
    """Drive parameter file as JSON text (same data as the YAML file)."""
    return json.dumps(parameter_data(cmp), indent=2, ensure_ascii=False, allow_nan=False) + "\n"


#: CSV columns: (Trace attribute, unit).
CSV_COLUMNS = (
    ("t", "s"), ("theta_r", "rad"), ("omega_r", "rad/s"), ("i_d", "A"), ("i_q", "A"), ("u_d", "V"),
    ("u_q", "V"), ("alpha", "rad/s^2"), ("alpha_dem", "rad/s^2"), ("alpha_hat", "rad/s^2"),
    ("Gamma_L", "N*m"), ("Gamma_L_hat", "N*m"), ("theta_hat", "rad"), ("omega_hat", "rad/s"),
    ("S", "rad/s"), ("E_friction", "J"), ("E_copper", "J"), ("E_electrical", "J"), ("E_motoring", "J"),
    ("E_load", "J"),
)


def trace_csv(cmp: Comparison) -> str:
    """Time series of every simulated run as one CSV table (the format of the page and ``simulate --csv``).

    One column per signal with its unit in the header (``theta_r [rad]``), a first ``controller``
    column (``fdsmc``, ``conventional``, ``optimum``, ``stock``: every run the case holds), one row per
    controller and sample (SI units, ``%.9g``): ``pandas.read_csv`` gives typed columns directly
    (``df.groupby("controller")``), Excel filters on the first column.

    Raises
    ------
    ParameterError
        When there is no run (an infeasible manoeuvre).
    """
    runs = [r for r in (cmp.fdsmc, cmp.conventional, cmp.optimum, cmp.stock) if r is not None]
    if not runs:
        raise ParameterError("nothing to export as CSV: there is no simulated run "
                             f"(manoeuvre.T_m = {cmp.derived.params.manoeuvre.T_m:g} s is infeasible)")
    out = io.StringIO()
    out.write("controller," + ",".join(f"{a} [{u}]" for a, u in CSV_COLUMNS) + "\n")
    for run in runs:
        block = io.StringIO()
        np.savetxt(block, np.column_stack([getattr(run.trace, a) for a, _ in CSV_COLUMNS]), fmt="%.9g",
                   delimiter=",")
        out.writelines(f"{run.controller},{line}\n" for line in block.getvalue().splitlines())
    return out.getvalue()


def safe_stem(name: str) -> str:
    """Make a file-name stem from a preset/motor name (letters, digits, ``_-.`` only)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("._") or "drive"


def _warned(fmt: str, text: str, failed: list) -> str:
    """``text`` with the failed checks written inside (a forced export); unchanged when clean."""
    if not failed:
        return text
    lines = verdict_lines(failed)
    if fmt == "c":  # printable ASCII, as the generated C files
        return c_comment(lines) + text
    if fmt == "csv":
        return "".join(f"# {line}\n" for line in lines) + text
    if fmt == "html":
        banner = "<div class=\"not-clean\"><p>" + "<br>".join(escape(line) for line in lines) + "</p></div>"
        return text.replace("<body>", "<body>" + banner, 1)
    return text


def c_law(fmt: str, controller: str) -> str:
    """Return the C module's outer law of ``controller`` (``fdsmc`` for every other format's default).

    Raises
    ------
    ParameterError
        For a law without a C module, or ``optimum`` with a format other than ``c``.
    """
    if controller not in LAWS:
        raise ParameterError(f"controller = {controller!r} has no C module: allowed {', '.join(LAWS)}")
    if controller != "fdsmc" and fmt != "c":
        raise ParameterError(f"controller = {controller!r} applies to the C module only: allowed with format c "
                             f"(format {fmt!r} writes the FDSMC design)")
    return controller


def with_optimum_run(cmp: Comparison) -> Comparison:
    """Return the case with the tracked optimum simulated (as it is, when it has one or no run at all)."""
    if cmp.optimum is not None or cmp.fdsmc is None:
        return cmp
    return dataclasses.replace(cmp, optimum=simulate(cmp.derived.params, "optimum", derived=cmp.derived))


def export_files(fmt: str, cmp: Comparison, options: ExportOptions = DEFAULT_OPTIONS) -> dict[str, bytes]:
    """File name → content of one export format for the case ``cmp`` (see the module doc).

    Raises
    ------
    ParameterError
        For an unknown format; :class:`~app.exports.provenance.ExportRefusedError` naming the failed
        checks when the design is not clean and not ``options.force``; a C export in continuous
        mode, a CSV or stock-drive file without a run.
    """
    if fmt not in FORMATS:
        raise ParameterError(f"format = {fmt!r} is not allowed: one of {', '.join(FORMATS)}")
    law = c_law(fmt, options.controller)
    if law == "optimum":
        cmp = with_optimum_run(cmp)
    stem = safe_stem(cmp.derived.params.name)
    if fmt in DRIVE_FORMATS:  # gated on the stock route simulated from the file, not on the FDSMC
        name, text = drive_file(fmt, cmp, failed_checks(cmp), stem, options)
        return {name: text.encode("utf-8")}
    failed = gate(fmt, cmp, options.force, law)
    if fmt == "c":  # the gate above has refused an unclean design unless forced; the header gates the build
        run = cmp.optimum if law == "optimum" else cmp.fdsmc
        checks = run_checks(cmp.derived.params, run) if run is not None else None
        files = c_files(cmp, checks, force=True, controller=law)
        return {name: _warned(fmt, text, failed).encode("utf-8") for name, text in files.items()}
    if fmt == "html":
        from pmsm_commissioning.app.exports.html import html_report  # plotly: imported only when a report is made

        return {f"{stem}.html": _warned(fmt, html_report(cmp), failed).encode("utf-8")}
    writers = {"yaml": parameter_yaml, "json": parameter_json, "csv": trace_csv}
    return {f"{stem}.{fmt}": _warned(fmt, writers[fmt](cmp), failed).encode("utf-8")}


def export_download(fmt: str, cmp: Comparison, options: ExportOptions = DEFAULT_OPTIONS) -> tuple[str, bytes]:
    """Return one downloadable file: the single export file, or a zip of the C module's header and source.

    The zip is named ``<name>_fdsmc_controller.zip`` (the tracked optimum's module:
    ``<name>_optimum_controller.zip``).
    """
    files = export_files(fmt, cmp, options)
    if len(files) == 1:
        return next(iter(files.items()))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, content in files.items():
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))  # reproducible bytes
            zf.writestr(info, content, zipfile.ZIP_DEFLATED)
    law = "optimum" if options.controller == "optimum" else "fdsmc"
    return f"{safe_stem(cmp.derived.params.name)}_{law}_controller.zip", buf.getvalue()
