"""Cortex-M4F build of the generated C module: cross-compile, symbol check, code size, instruction count.

Uses Debian's ``gcc-arm-none-eabi`` (installed by ``scripts/ensure_cc.sh``). The float32 build is
compiled with :data:`ARM_FLAGS`; :func:`double_symbols` lists every soft-float double helper
(``__aeabi_d*``, ``__*df*``) the object needs -- none when the build is float-only -- and
:func:`helper_symbols` adds the 64-bit integer helpers (``__aeabi_ldivmod``, ``__aeabi_uldivmod`` ...).
:func:`count_instructions` links the module with a tiny bench program (Linux ``exit`` syscall, no C
library) that replays the golden vectors, runs it under ``qemu-arm`` (``qemu-user``) with one
instruction per translation block and ``-d exec`` (the log read as it is written, never stored),
and counts the instructions executed between two calls of a marker function: every instruction of
one ``fdsmc_step`` call (prologue, inlined helpers, libgcc calls, epilogue), per segment of the
vectors. The CPU is ``-cpu cortex-m4`` where qemu-arm's user mode runs it; Debian's qemu 7.2 aborts
on M-profile CPUs in user mode, so then the Cortex-M4 binary runs unchanged on the Thumb-2/VFPv4
Cortex-A15 model (:data:`STAND_IN_CPU`): the instructions executed are the binary's own, the same on
either. Without qemu it counts statically: the instructions of the step's code in the disassembly
(each instruction once, whatever the path).
"""

from __future__ import annotations

import re
import shutil
import statistics
import subprocess
from dataclasses import dataclass
from pathlib import Path

#: Cortex-M4F, single-precision FPU, hard-float ABI; -fno-math-errno lets sqrtf be one VSQRT and
#: -ffp-contract=fast fuses multiply-adds (VFMA: one rounding instead of two; -std=c99 turns it off).
ARM_FLAGS = ("-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard", "-O2", "-fno-math-errno",
             "-ffp-contract=fast",
             "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wdouble-promotion", "-DFDSMC_USE_FLOAT")
#: qemu-arm CPU models tried in turn: the Cortex-M4 itself, then a Thumb-2/VFPv4 stand-in.
TARGET_CPU, STAND_IN_CPU = "cortex-m4", "cortex-a15"
#: Soft-float double helpers of the ARM EABI and libgcc.
DOUBLE_SYMBOL = re.compile(r"__aeabi_(d|l2d|ul2d|i2d|ui2d|f2d)\w*|__\w*df\w*")
#: 64-bit integer helpers of the ARM EABI and libgcc (division, modulo, shifts, compares, conversions).
LONG_SYMBOL = re.compile(r"__aeabi_(u?ldivmod|lmul|llsl|llsr|lasr|u?lcmp|[fd]2u?lz|u?l2[fd])"
                         r"|__(u?(div|mod)di3|u?divmoddi4|(ash|lsh)[lr]di3|u?cmpdi2|fixu?n?[sd]fdi|floatu?n?di[sd]f)")

START_C = """\
int main(void);
void _start(void) __attribute__((naked, noreturn));
void _start(void) { __asm__ volatile("bl main\\n\\tmovs r7, #1\\n\\tsvc #0\\n"); }
"""

BENCH_C = """\
#include "fdsmc_controller.h"
#include "fdsmc_vectors.h"
void fdsmc_bench_mark(void) __attribute__((noinline));
void fdsmc_bench_mark(void) { __asm__ volatile(""); }
volatile fdsmc_real fdsmc_bench_sink;
int main(void)
{
    static fdsmc_state s;
    fdsmc_output out;
    int g, k;
    for (g = 0; g < FDSMC_VEC_SEGMENTS; ++g) {
        const fdsmc_vec_segment *seg = &fdsmc_vec_seg[g];
        if (seg->fault != 0u) {
            continue; /* the fault path is short: not the budget's */
        }
        fdsmc_init(&s, &FDSMC_DESIGN, 0);
        if (seg->t_m > 0.0 && fdsmc_set_move(&s, seg->theta_dem, (fdsmc_real)seg->t_m) != FDSMC_OK) {
            return 2;
        }
        for (k = seg->start; k < seg->start + seg->n; ++k) {
            const fdsmc_count theta = fdsmc_vec_theta[k];
            const fdsmc_real i_d = fdsmc_vec_in[k][0], i_q = fdsmc_vec_in[k][1];
            fdsmc_bench_mark();
            fdsmc_step(&s, theta, i_d, i_q, &out);
            fdsmc_bench_mark();
            fdsmc_bench_sink = out.u_q;
        }
    }
    return s.status.fault != 0u;
}
"""


@dataclass(frozen=True)
class PathCount:
    """Instructions per ``fdsmc_step`` call over one segment of the golden vectors (one path of the step).

    Attributes
    ----------
    name : str      The segment (``move``, ``limits``, ``limit_u`` ...).
    median : float  Median per call [-].
    worst : int     Largest per call [-].
    calls : int     Calls counted [-].
    """

    name: str
    median: float
    worst: int
    calls: int


@dataclass(frozen=True)
class InstructionCount:
    """Instructions per ``fdsmc_step`` call on Cortex-M4F.

    Attributes
    ----------
    method : str   ``"qemu-arm -cpu <model>"`` (executed, over the golden vectors) or ``"static"`` (disassembly).
    mean : float   Mean per call [-] (static: the code's instruction count).
    median : float Median per call [-].
    max : int      Largest per call: the worst path [-].
    calls : int    Calls counted [-].
    paths : tuple of PathCount  Per segment of the vectors (empty when static).
    """

    method: str
    mean: float
    median: float
    max: int
    calls: int
    paths: tuple[PathCount, ...] = ()


def arm_compiler() -> str | None:
    """Path of ``arm-none-eabi-gcc``, or None."""
    return shutil.which("arm-none-eabi-gcc")


def _run(args: list[str], cwd: Path) -> str:
    return subprocess.run(args, cwd=cwd, check=True, capture_output=True, text=True).stdout


def cross_compile(folder: Path, extra: tuple[str, ...] = ()) -> Path:
    """Compile ``folder/fdsmc_controller.c`` for Cortex-M4F (float32); returns the object file."""
    obj = folder / "fdsmc_controller_m4f.o"
    _run(["arm-none-eabi-gcc", *ARM_FLAGS, *extra, "-c", "fdsmc_controller.c", "-o", obj.name], folder)
    return obj


def symbols(obj: Path, kind: str = "U") -> list[str]:
    """Names of the symbols of type ``kind`` (``U`` undefined, ``T`` text …) in an ARM object."""
    out = _run(["arm-none-eabi-nm", str(obj)], obj.parent)
    return [line.split()[-1] for line in out.splitlines() if line.split()[-2:-1] == [kind]]


def double_symbols(obj: Path) -> list[str]:
    """Soft-float double helpers an ARM object calls (empty for a float-only build)."""
    return [s for s in symbols(obj) if DOUBLE_SYMBOL.fullmatch(s)]


def helper_symbols(obj: Path) -> list[str]:
    """Double and 64-bit integer helpers an ARM object calls (empty for the float build, any counts/rev)."""
    return [s for s in symbols(obj) if DOUBLE_SYMBOL.fullmatch(s) or LONG_SYMBOL.fullmatch(s)]


def code_size(obj: Path) -> dict[str, int]:
    """``text`` (code and constants), ``data`` and ``bss`` of an ARM object [bytes]."""
    line = _run(["arm-none-eabi-size", str(obj)], obj.parent).splitlines()[1].split()
    return {"text": int(line[0]), "data": int(line[1]), "bss": int(line[2])}


def _segments(folder: Path) -> list[tuple[str, int]]:
    """(name, calls) of each segment the bench replays: those of ``fdsmc_vectors.h`` without a fault."""
    text = (folder / "fdsmc_vectors.h").read_text(encoding="utf-8")
    rows = re.findall(r'\{"([^"]*)", -?\d+, (\d+), -?\d+, [^,]+, (\d+)u,', text)
    return [(name, int(n)) for name, n, fault in rows if fault == "0"]


def qemu_cpu(folder: Path, elf: Path) -> str:
    """Return the qemu-arm CPU model that runs ``elf`` to its end: :data:`TARGET_CPU`, else :data:`STAND_IN_CPU`."""
    run = subprocess.run(["qemu-arm", "-cpu", TARGET_CPU, str(elf)], cwd=folder, capture_output=True, timeout=600)
    return TARGET_CPU if run.returncode == 0 else STAND_IN_CPU


def _step_counts(folder: Path, elf: Path, cpu: str) -> list[int]:
    """Instructions of each fdsmc_step call, from qemu-arm's exec log read as a stream (stderr)."""
    args = ["qemu-arm", "-cpu", cpu, "-singlestep", "-d", "exec,nochain", str(elf)]
    counts: list[int] = []
    n, prev = -1, ""  # n: -1 outside a step, else the instructions since the mark before it
    with subprocess.Popen(args, cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          errors="replace") as proc:
        assert proc.stderr is not None
        for line in proc.stderr:
            name = line.rsplit(None, 1)[-1] if line.strip() else ""
            if name == "fdsmc_bench_mark" and prev != name:  # a call of the mark: a step starts or ends
                if n > 0:
                    counts.append(n)
                n = 0 if n < 0 else -1
            elif n >= 0 and name not in ("main", "fdsmc_bench_mark"):
                n += 1
            prev = name
    if proc.returncode != 0:
        raise RuntimeError(f"the bench program failed under qemu-arm -cpu {cpu} (exit {proc.returncode})")
    return counts


def _executed(folder: Path, elf: Path) -> InstructionCount:
    cpu = qemu_cpu(folder, elf)
    counts = _step_counts(folder, elf, cpu)
    paths, start = [], 0
    for name, n in _segments(folder):
        part = counts[start:start + n]
        start += n
        if part:
            paths.append(PathCount(name, statistics.median(part), max(part), len(part)))
    return InstructionCount(f"qemu-arm -cpu {cpu}", sum(counts) / len(counts), statistics.median(counts),
                            max(counts), len(counts), tuple(paths))


def _static(folder: Path, elf: Path) -> InstructionCount:
    dis = _run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", str(elf)], folder)
    n, inside = 0, False
    for line in dis.splitlines():
        head = re.match(r"^[0-9a-f]+ <(\w+)>:", line)
        if head:
            inside = head.group(1) in ("fdsmc_step", "step")
        elif inside and re.match(r"^\s+[0-9a-f]+:\s+\w", line):
            n += 1
    return InstructionCount("static", float(n), float(n), n, 1)


def count_instructions(folder: Path, extra: tuple[str, ...] = ()) -> InstructionCount:
    """Instructions per ``fdsmc_step`` of the module and golden vectors in ``folder`` (see the module doc)."""
    (folder / "bench_start.c").write_text(START_C, encoding="utf-8")
    (folder / "bench.c").write_text(BENCH_C, encoding="utf-8")
    elf = folder / "bench_m4f.elf"
    _run(["arm-none-eabi-gcc", *ARM_FLAGS, *extra, "-nostdlib", "-nostartfiles", "-static", "bench_start.c",
          "bench.c", "fdsmc_controller.c", "-lgcc", "-o", elf.name], folder)
    return _executed(folder, elf) if shutil.which("qemu-arm") else _static(folder, elf)
