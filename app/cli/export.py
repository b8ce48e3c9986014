"""``python -m app export PRESET [--set …] --format yaml|json|c|csv|html [-o PATH]``.

Writes the same files as the page's Export menu (:func:`app.exports.model.export_files`): for ``c``,
PATH is a folder receiving ``fdsmc_controller.h`` and ``.c``; otherwise PATH is the file
(default: ``<name>.<format>`` in the current folder).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from app.cli.main import add_preset_arguments
from app.exports.model import FORMATS, export_files
from app.io.atomic import write_atomic
from app.io.preset_modes import load_mode_preset
from control.common.checks import ParameterError
from control.fdsmc.derivations import derive
from control.fdsmc.params import DriveParams
from sim.fdsmc.engine import Comparison, compare


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``export``."""
    add_preset_arguments(p)
    p.add_argument("--format", choices=FORMATS, required=True, help="file format to write")
    p.add_argument("-o", "--output", metavar="PATH",
                   help="output file (folder for --format c); default <name>.<format> here (c: this folder)")
    p.add_argument("--name", help="name written in the file and used for its file name (default: the preset's)")
    p.add_argument("--source", help="source written in the file, e.g. the motor's data sheet")


def case(params: DriveParams) -> Comparison:
    """Both controllers simulated (the derivations alone when the manoeuvre is infeasible)."""
    d = derive(params)
    return compare(params, derived=d) if d.profile.feasible else Comparison(d, None, None, None, None)


def run(args: argparse.Namespace) -> int:
    """Load, simulate, write the export; prints the paths written."""
    params = load_mode_preset(args.preset, args.overrides, mode="position")
    renamed = {k: v for k, v in (("name", args.name), ("source", args.source)) if v is not None}
    params = dataclasses.replace(params, **renamed)
    files = export_files(args.format, case(params))
    if args.format == "c":
        folder = Path(args.output or ".")
        if folder.exists() and not folder.is_dir():
            raise ParameterError(f"-o {str(folder)!r} is a file: --format c needs a folder")
        folder.mkdir(parents=True, exist_ok=True)
        targets = {folder / name: content for name, content in files.items()}
    else:
        ((name, content),) = files.items()
        targets = {Path(args.output or name): content}
    for path, content in targets.items():
        try:
            write_atomic(path, content)
        except OSError as exc:
            raise ParameterError(f"cannot write {str(path)!r}: {exc.strerror or exc}") from None
        sys.stdout.write(f"wrote {path} ({len(content)} bytes)\n")
    return 0
