"""``pmsm-commission export PRESET [--set …] --format FORMAT [-o PATH] [--force] [--controller LAW]``.

Writes the same files as the page's Export menu (:func:`app.exports.model.export_files`): for ``c``,
PATH is a folder receiving ``fdsmc_controller.h`` and ``.c`` (outer law ``--controller``: the FDSMC, or
the tracked optimum with its designed move's reference table); otherwise PATH is the file
(default: ``<name>.<format>`` here; the stock-drive formats ``<name>.odrive.json``,
``<name>.moteus.cfg``, ``<name>.vesc.xml``, ``<name>.setpoints.csv``). Every format is refused,
naming the failed checks, when the simulated design is not clean; ``--force`` writes it with the
failed checks inside. For ``c`` the refusal names every failed check (their names on the first line,
then one line each) and a forced export warns on stderr naming them the same way. Files are written
whole (a temporary file, then ``os.replace``); the C module's files are all written to temporary files
first and renamed only when every one is complete (:func:`app.io.atomic.write_all`: a full disk leaves
the old files). ``-o`` a device node, FIFO,
folder, read-only file or symbolic-link loop is refused before any simulation
(:func:`app.io.atomic.target_problem`).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from pmsm_commissioning.app.cli.main import add_preset_arguments, check_writable
from pmsm_commissioning.app.exports.drives.files import DRIVE_FORMATS, ExportOptions
from pmsm_commissioning.app.exports.drives.units import ANGLE_UNITS
from pmsm_commissioning.app.exports.firmware.module import LAWS
from pmsm_commissioning.app.exports.model import FORMATS, c_law, export_files, with_optimum_run
from pmsm_commissioning.app.exports.provenance import ExportRefusedError, check_text, failed_checks
from pmsm_commissioning.app.io import atomic
from pmsm_commissioning.app.io.numbers import one_line, parse_number
from pmsm_commissioning.app.io.presets import load, load_with_plant
from pmsm_commissioning.app.io.user_text import check_label, escaped
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import COMPARATORS, CONTROLLERS, Comparison, compare


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``export``."""
    add_preset_arguments(p)
    p.add_argument("--format", choices=FORMATS, required=True, help="file format to write")
    p.add_argument("-o", "--output", metavar="PATH",
                   help="output file (folder for --format c); default <name>.<format> here (c: this folder)")
    p.add_argument("--name", help="name written in the file and used for its file name (default: the preset's)")
    p.add_argument("--source", help="source written in the file, e.g. the motor's data sheet")
    p.add_argument("--force", action="store_true",
                   help="write a design that is not clean, with the failed checks inside the file")
    p.add_argument("--angle-unit", choices=tuple(ANGLE_UNITS), default="rad",
                   help="angle unit of --format setpoints (default rad)")
    p.add_argument("--controller", choices=LAWS, default="fdsmc",
                   help="outer law of --format c: fdsmc (default) or optimum (the tracked minimum-energy optimum, "
                        "its designed move only)")
    p.add_argument("--cycle-ms", metavar="MS",
                   help="cycle time of --format setpoints [ms] (default the drive's 1/f_s; 1 ms if continuous)")


def case(params: DriveParams, fmt: str = "yaml", controller: str = "fdsmc") -> Comparison:
    """Return the simulated case (the derivations alone when the manoeuvre is infeasible).

    The stock-drive formats and the HTML report also simulate the stock route and the tracked optimum
    (their energies go into the file's header, the report's headline); the optimum's C module its run.
    """
    d = derive(params)
    if not d.profile.feasible:
        return Comparison(d, None, None, None, None)
    if fmt in DRIVE_FORMATS or fmt == "html":
        return compare(params, COMPARATORS, derived=d)
    return compare(params, CONTROLLERS + (("optimum",) if controller == "optimum" else ()), derived=d)


def cycle_seconds(text: str | None) -> float | None:
    """``--cycle-ms`` → seconds; a one-line error naming the option, the value and the range."""
    if text is None:
        return None
    ms = parse_number(text, "--cycle-ms")
    if not ms > 0.0:
        raise ParameterError(f"--cycle-ms = {text!r} is not allowed: a time > 0 ms")
    return ms * 1e-3


def write_atomic(path: Path, content: bytes) -> None:
    """Write ``content`` to ``path`` whole through :func:`app.io.atomic.write_atomic`.

    A temporary file in the same folder, then ``os.replace`` (removed on Ctrl-C too); a write
    error is a one-line ParameterError.
    """
    write_files({path: content})


def write_files(targets: dict[Path, bytes]) -> None:
    """Write files that belong together through :func:`app.io.atomic.write_all`; one-line ParameterError."""
    try:
        atomic.write_all(targets)
    except OSError as exc:
        where = exc.filename if exc.filename is not None else ", ".join(str(p) for p in targets)
        raise ParameterError(f"cannot write {str(where)!r}: {exc.strerror or exc}; no file was changed") from None


def run(args: argparse.Namespace) -> int:
    """Load, simulate, pass the gate, write the export; prints the paths written."""
    params = load(args.preset, args.overrides, mode="position")
    _, plant = load_with_plant(args.preset, args.overrides)
    if plant is not None:  # the files carry the controller's model; the drive's true values are not theirs
        raise ParameterError("plant: export writes the controller's model (motor, load, controller); a plant "
                             "section or --set plant.* (the drive's true values) is not exported: allowed none — "
                             "simulate it with `pmsm-commission simulate`, or move the values into motor/load")
    renamed = {k: check_label(v, f"--{k}") for k, v in (("name", args.name), ("source", args.source))
               if v is not None}
    params = dataclasses.replace(params, **renamed)
    c_law(args.format, args.controller)  # before the simulation: a wrong combination is refused at once
    if args.output and args.format != "c":
        check_writable(args.output, "-o")
    options = ExportOptions(args.force, args.angle_unit, cycle_seconds(args.cycle_ms), args.controller)
    cmp = case(params, args.format, args.controller)
    if args.format == "c":
        return _write_c(args, cmp, options)
    ((name, content),) = export_files(args.format, cmp, options).items()
    targets = {Path(args.output or name): content}
    write_files(targets)
    _print_written(targets)
    return 0


def _print_written(targets: dict[Path, bytes]) -> None:
    for path, content in targets.items():
        sys.stdout.write(f"wrote {escaped(path)} ({len(content)} bytes)\n")


def _check_lines(failed: list) -> str:
    """One line per failed check, indented (each escaped and at most 300 characters)."""
    return "".join(f"  {one_line(check_text(c), 298)}\n" for c in failed)


def _write_c(args: argparse.Namespace, cmp: Comparison, options: ExportOptions) -> int:
    """Write the C module's export; refuse it naming every failed check (one line each, exit 2).

    Forced, the files are written and a warning on stderr names the failed checks.
    """
    if args.controller == "optimum":
        cmp = with_optimum_run(cmp)
    failed = failed_checks(cmp, args.controller)
    names = ", ".join(c.name for c in failed)
    try:
        files = export_files("c", cmp, options)
    except ExportRefusedError:
        name = one_line(repr(cmp.derived.params.name), 80)
        sys.stderr.write(f"error: export --format c refused: the design of {name} is not clean; "
                         f"{len(failed)} failed check(s): {names}. Fix the design (pmsm-commission design ...) "
                         "or export with --force to write it with these warnings inside:\n" + _check_lines(failed))
        return 2
    folder = Path(args.output or ".")
    if folder.exists() and not folder.is_dir():
        raise ParameterError(f"-o {str(folder)!r} is a file: --format c needs a folder")
    folder.mkdir(parents=True, exist_ok=True)
    targets = {folder / name: content for name, content in files.items()}
    write_files(targets)
    _print_written(targets)
    if failed:
        sys.stderr.write(f"warning: written with --force: the design is NOT CLEAN; {len(failed)} failed check(s): "
                         f"{names} (the header stops the build unless FDSMC_ACCEPT_UNCLEAN is defined as its "
                         "FDSMC_PARAM_HASH):\n" + _check_lines(failed))
    return 0
