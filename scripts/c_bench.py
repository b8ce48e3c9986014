"""Print the Cortex-M4F figures of the generated C controller: instructions per step, code size, doubles.

Usage: ``.venv/bin/python scripts/c_bench.py [PRESET …] [--set section.field=value …]``
(default: every shipped position-drive preset; ``--controller optimum``: the tracked optimum's
module, whose code size includes its reference table). For each preset the case is simulated, the C export
written (module, golden vectors), the float32 build cross-compiled with Debian's arm-none-eabi-gcc
(``-mcpu=cortex-m4 -mfpu=fpv4-sp-d16 -mfloat-abi=hard -O2``) and the step run over the golden vectors
under qemu-arm, counting every instruction of each ``fdsmc_step`` call (a static count of the step's
code when qemu-arm is missing; the line says which). The CPU model is ``-cpu cortex-m4`` where
qemu-arm's user mode runs it, else the Thumb-2/VFPv4 Cortex-A15 running the same Cortex-M4 binary
(the line names it). It prints the median and the worst call over all the vectors and per segment --
each segment one path of the step: ``move`` (the designed move and hold; its worst is the sample that
takes the move), ``limits`` (the current limit acting), ``limit_i_d_*``/``limit_u`` (the d-axis
current limit, the voltage limit, with the q-axis limit, acting at once). Budget: 300 instructions
on the worst path; at 20 kHz on a 168 MHz Cortex-M4F they leave > 90 % of the period free. Needs
``bash scripts/ensure_cc.sh``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from pmsm_commissioning.app.exports.firmware.vectors import c_files  # noqa: E402
from pmsm_commissioning.app.exports.firmware.verify import accept_flag  # noqa: E402
from pmsm_commissioning.app.io.presets import list_presets, load_preset  # noqa: E402
from pmsm_commissioning.control.fdsmc.params import DriveParams  # noqa: E402
from pmsm_commissioning.sim.fdsmc.design import run_checks  # noqa: E402
from pmsm_commissioning.sim.fdsmc.engine import compare  # noqa: E402
from scripts.c_arm import (  # noqa: E402
    arm_compiler,
    code_size,
    count_instructions,
    cross_compile,
    double_symbols,
)

#: Instructions per step the float32 build must stay within on Cortex-M4F [-].
BUDGET = 300


def bench(preset: str, sets: list[str], controller: str = "fdsmc") -> str:
    """One line of figures for ``preset`` (``controller``: the module's outer law, fdsmc or optimum)."""
    params = load_preset(preset, sets)
    cmp = compare(params, ("fdsmc", "conventional") + (("optimum",) if controller == "optimum" else ()))
    run = cmp.optimum if controller == "optimum" else cmp.fdsmc
    checks = run_checks(params, run) if run is not None else None
    clean = checks is not None and not any(c.violated for c in checks)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, text in c_files(cmp, checks, force=True, controller=controller).items():
            (folder / name).write_text(text, encoding="utf-8")
        extra = () if clean else (accept_flag(folder),)
        obj = cross_compile(folder, extra)
        size, doubles = code_size(obj), double_symbols(obj)
        n = count_instructions(folder, extra)
    paths = "; ".join(f"{p.name} {p.median:.0f}/{p.worst}" for p in n.paths)
    return (f"{preset:24s} f_s {params.controller.f_s / 1e3:5.1f} kHz  {'clean' if clean else 'NOT clean'}  "
            f"instructions/step ({n.method}): median {n.median:.0f}, worst {n.max} over {n.calls} calls "
            f"[budget {BUDGET}: {'within' if n.max <= BUDGET else 'OVER'}]; per path median/worst: {paths or '-'}  "
            f"code {size['text']} B text, {size['data']} B data, {size['bss']} B bss  "
            f"double helpers: {', '.join(doubles) or 'none'}")


def main() -> None:
    """Parse the command line and print one line per preset."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("presets", nargs="*")
    ap.add_argument("--set", action="append", default=[], dest="sets")
    ap.add_argument("--controller", choices=("fdsmc", "optimum"), default="fdsmc",
                    help="outer law of the module (optimum: the tracked optimum's module)")
    args = ap.parse_args()
    if arm_compiler() is None:
        sys.exit("arm-none-eabi-gcc missing: run bash scripts/ensure_cc.sh")
    names = args.presets or [n for n in list_presets() if isinstance(load_preset(n), DriveParams)]
    for name in names:
        print(bench(name, args.sets, args.controller), flush=True)


if __name__ == "__main__":
    main()
