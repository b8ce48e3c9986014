"""``pmsm-commission derive PRESET [--set …] [--json]``."""

from __future__ import annotations

import argparse
import json

from pmsm_commissioning.app.cli.main import add_preset_arguments
from pmsm_commissioning.app.io.derived_view import derived_json, derived_rows, format_table
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.control.fdsmc.derivations import derive


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``derive``."""
    add_preset_arguments(p)
    p.add_argument("--json", action="store_true", help="print a machine-readable JSON object")


def run(args: argparse.Namespace) -> int:
    """Print the derived values (table or JSON) and warnings."""
    params = load(args.preset, args.overrides, mode="position")
    d = derive(params)
    if args.json:
        print(json.dumps(to_json(derived_json(d)), indent=2, ensure_ascii=False, allow_nan=False))
        return 0
    print(f"Preset: {params.name}  ({params.source})\n")
    print(format_table(derived_rows(d)))
    print("\nWarnings:" if d.warnings else "\nNo warnings.")
    for w in d.warnings:
        print(f"  ! {w}")
    return 0
