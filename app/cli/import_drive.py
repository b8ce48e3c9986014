"""``pmsm-commission import-drive FILE --format odrive|moteus|vesc --base PRESET -o preset.yaml``.

Reads a stock drive's own file (ODrive backup JSON, moteus configuration dump, VESC mcconf XML) and
writes a preset: the base preset with the file's motor data (:func:`app.exports.drives.import_drive.import_drive`).
Every key of the file that is not imported is listed (on the terminal and in the preset's header
comment). The preset is written whole (a temporary file, then ``os.replace``).

Text from the file (its keys) and its name reaches the written preset and the terminal only escaped
(:func:`app.io.user_text.escaped`): a key or a file name with a line break cannot add a YAML line;
``--name`` with one is refused (:func:`app.io.user_text.check_label`).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from pmsm_commissioning.app.cli.export import write_atomic
from pmsm_commissioning.app.cli.main import check_writable
from pmsm_commissioning.app.exports.drives.import_drive import IMPORT_FORMATS, import_drive
from pmsm_commissioning.app.io.assumed import INHERITED, inherited_block
from pmsm_commissioning.app.io.bounded import ReadError, read_bounded
from pmsm_commissioning.app.io.presets import MAX_BYTES, dumps, load, to_raw
from pmsm_commissioning.app.io.user_text import check_label, escaped
from pmsm_commissioning.control.common.checks import ParameterError


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``import-drive``."""
    p.add_argument("file", metavar="FILE", help="the drive's file: ODrive backup JSON, moteus config dump, VESC XML")
    p.add_argument("--format", choices=IMPORT_FORMATS, required=True, help="the file's format")
    p.add_argument("--base", metavar="PRESET", required=True,
                   help="preset giving everything the file does not (nameplate, load, controller, move)")
    p.add_argument("-o", "--output", metavar="FILE", required=True, help="preset file to write (YAML)")
    p.add_argument("--name", help="name of the new preset (default: the file's stem)")


def read_text(path: str) -> str:
    """Return the file's UTF-8 text; a one-line error naming the file when it cannot be read."""
    try:  # never more than MAX_BYTES read (a sparse, /proc or device file)
        data = read_bounded(path, MAX_BYTES, f"FILE {escaped(path)!r}")
    except ReadError as exc:
        raise ParameterError(str(exc)) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise ParameterError(f"FILE {path!r} is not UTF-8 text: allowed a text file") from None


def run(args: argparse.Namespace) -> int:
    """Import, write the preset, list what was imported, kept and not imported."""
    check_writable(args.output, "-o")
    name = check_label(args.name, "--name") if args.name is not None else escaped(Path(args.file).stem)
    base = load(args.base, (), mode="position")
    result = import_drive(read_text(args.file), args.format, base, escaped(args.file))
    params = dataclasses.replace(result.params, name=name[:400],
                                 source=f"motor data imported from {args.format} file "
                                        f"{escaped(Path(args.file).name)[:200]} onto preset {escaped(base.name)}")
    notes = [escaped(n) for n in ([f"imported: {x}" for x in result.imported]
                                  + [f"kept from {base.name}: {x}" for x in result.kept]
                                  + [f"not imported ({len(result.not_imported)} keys): "
                                     + ", ".join(result.not_imported)])]
    command = escaped(f"pmsm-commission import-drive {args.file} --format {args.format} --base {args.base}")
    head = "".join(f"# {line}\n" for line in [command] + notes)
    raw = to_raw(params)
    raw[INHERITED] = inherited_block(base.name, {x.partition(" = ")[0] for x in result.imported})
    write_atomic(Path(args.output), (head + dumps(raw)).encode("utf-8"))
    sys.stdout.write("\n".join(notes) + f"\nwrote {escaped(args.output)}\n")
    return 0
