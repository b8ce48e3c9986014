"""``pmsm-commission log FILE [--preset P] [--set …] [--mapping M] [--run R] [--t0 S] [--identify] [--json]``.

Imports a drive log, overlays it on the preset's simulated move and, with ``--identify``,
identifies R_s, L_d, L_q, Ψ_PM, J_total, F_v and Γ_Le from it.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.io.bounded import ReadError, read_utf8
from pmsm_commissioning.app.io.drive_log import DriveLog, read_log, run_identification
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import number_option
from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, MAX_BYTES, load_preset, loads_log_mapping
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.identification import Identification
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.drivelog.overlay import Overlay, overlay
from pmsm_commissioning.sim.fdsmc.engine import CONTROLLERS, simulate


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``log``."""
    p.add_argument("file", metavar="FILE", help="CSV log (units in the header, a units row, or --mapping)")
    p.add_argument("--preset", default=DEFAULT_PRESET, help="preset whose move is simulated for the overlay")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.FIELD=VALUE",
                   help="override a preset value, e.g. --set manoeuvre.T_m=0.4")
    p.add_argument("--mapping", metavar="YAML", help="column mapping, lines 'column: signal [unit]'")
    p.add_argument("--run", choices=CONTROLLERS, help="which run of a file holding several; also the "
                   "controller simulated for the overlay (default fdsmc)")
    p.add_argument("--t0", type=number_option("--t0"), metavar="SECONDS",
                   help="move start in the log [s] (default: detected)")
    p.add_argument("--identify", action="store_true", help="identify R_s, L_d, L_q, Ψ_PM, J_total, F_v, Γ_Le")
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")


def load(args: argparse.Namespace) -> tuple[DriveParams, DriveLog]:
    """Return the preset and the imported log of the command line."""
    params = load_preset(args.preset, args.overrides)
    if not isinstance(params, DriveParams):
        raise ParameterError(f"--preset {args.preset!r} is not a position-drive preset")
    mapping = None
    if args.mapping:
        try:
            text = read_utf8(args.mapping, MAX_BYTES, f"--mapping {escaped(args.mapping)!r}")
        except ReadError as exc:
            raise ParameterError(str(exc)) from None
        mapping = loads_log_mapping(text, Path(args.mapping).name)
    return params, read_log(args.file, mapping=mapping, run=args.run, p=params.motor.p)


def overlay_json(ov: Overlay) -> dict[str, Any]:
    """``overlay`` of the JSON contract: per signal rms_error, peak_error, unit; energies."""
    out: dict[str, Any] = {e.signal: {"rms_error": e.rms_error, "peak_error": e.peak_error, "unit": e.unit}
                           for e in ov.errors}
    out["t0_s"] = ov.t0
    out["t0_detected"] = ov.t0_detected
    out["electrical_energy"] = {"measured": ov.energy_measured_J, "simulated": ov.energy_simulated_J, "unit": "J"}
    return out


def identified_json(r: Identification) -> dict[str, Any]:
    """Return ``identified``: per parameter value, stderr, ci95, unit — or refused with the reason."""
    out: dict[str, Any] = {}
    for e in r.estimates:
        if e.refused is not None:
            out[e.name] = {"refused": e.refused, "unit": e.unit}
        else:
            out[e.name] = {"value": e.value, "stderr": e.stderr, "ci95": list(e.ci95 or ()), "unit": e.unit}
    out["voltage_delay_samples"] = r.voltage_delay_samples
    out["residual_electrical_V"] = r.residual_electrical_V
    out["residual_mechanical_Nm"] = r.residual_mechanical_Nm
    return out


def _print(log: DriveLog, ov: Overlay, ident: Identification | None) -> None:
    print(f"Log {log.name}: {log.signals['t'].size} samples at {1.0 / log.T_s:.6g} Hz; "
          f"signals {', '.join(k for k in log.signals if k != 't')}")
    for note in log.notes:
        print(f"  note: {note}")
    print(f"Move start t0 = {ov.t0:.6g} s ({'detected' if ov.t0_detected else 'given'})\n")
    print(f"{'signal':10s}{'RMS error':>14s}{'peak error':>14s}  unit")
    for e in ov.errors:
        print(f"{e.signal:10s}{e.rms_error:14.5g}{e.peak_error:14.5g}  {e.unit}")
    if ov.energy_measured_J is not None:
        print(f"\nElectrical input energy: measured {ov.energy_measured_J:.5g} J, "
              f"simulated {ov.energy_simulated_J:.5g} J")
    if ident is None:
        return
    print(f"\n{'parameter':10s}{'value':>14s}{'std. error':>14s}{'95 % interval':>30s}  unit")
    for e in ident.estimates:
        if e.refused is not None:
            print(f"{e.name:10s}  refused: {e.refused}")
        else:
            ci = f"[{e.ci95[0]:.5g}, {e.ci95[1]:.5g}]" if e.ci95 else ""
            print(f"{e.name:10s}{e.value:14.5g}{e.stderr:14.3g}{ci:>30s}  {e.unit}")


def run(args: argparse.Namespace) -> int:
    """Import, overlay, optionally identify; print a table or JSON."""
    params, log = load(args)
    result = simulate(params, args.run or "fdsmc")
    ov = overlay(log.signals, result.trace, args.t0)
    ident = run_identification(log, params) if args.identify else None
    if args.json:
        out: dict[str, Any] = {"log": {"name": log.name, "samples": int(log.signals["t"].size),
                                       "sample_rate_Hz": 1.0 / log.T_s, "notes": list(log.notes)},
                               "overlay": overlay_json(ov)}
        if ident is not None:
            out["identified"] = identified_json(ident)
        print(json.dumps(to_json(out), indent=2, ensure_ascii=False))
    else:
        _print(log, ov, ident)
    return 0
