"""What a firmware engineer relies on in the generated C module: the verdict gate stops a bad design at
compile time, faults give a safe zero output, the header links from C++, the parameter hash ties the
.h to the YAML/JSON export, hostile preset names cannot inject code, and the float32 build fits a
Cortex-M4F at 20 kHz without one double operation.
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from pmsm_commissioning.app.exports.firmware.module import HEADER_NAME, Verdict, controller_files, parameter_hash
from pmsm_commissioning.app.exports.firmware.text import MAX_CHARS, c_string
from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.firmware.verify import (
    CFLAGS,
    CModule,
    accept_flag,
    build,
    compiler,
    count_params,
    write_module,
)
from pmsm_commissioning.app.exports.model import parameter_yaml
from pmsm_commissioning.app.io.presets import SCHEMA, load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare
from scripts.c_arm import (
    arm_compiler,
    count_instructions,
    cross_compile,
    double_symbols,
    symbols,
)
from tests.toolchain import need

ROOT = Path(__file__).resolve().parent.parent
#: The designed move of yaskawa_sgm7j_04a (10 rev in 0.5 s) in counts of its module.
TEN_REV = 10 * count_params(load_preset("yaskawa_sgm7j_04a"))[0].sensors.encoder_cpr
CI = os.environ.get("CI") == "true"


def _tool(name: str) -> str:
    return need(shutil.which(name), name)


def _cc(folder: Path, *args: str) -> subprocess.CompletedProcess:
    cc = compiler() or _tool("cc")
    return subprocess.run([cc, *CFLAGS, *args], cwd=folder, capture_output=True, text=True)


def _module(folder: Path, preset: str = "yaskawa_sgm7j_04a", verdict: Verdict | None = None, sets=()) -> None:
    _tool("cc")
    params, _ = count_params(load_preset(preset, list(sets)))
    write_module(folder, params, verdict)


# ---- verdict gate -------------------------------------------------------------------------------


def test_unverified_module_stops_the_build_naming_the_accept_macro(tmp_path):
    _module(tmp_path)
    run = _cc(tmp_path, "-c", "fdsmc_controller.c")
    assert run.returncode != 0 and "not verified" in run.stderr
    assert accept_flag(tmp_path).split("=")[1] in run.stderr  # the message says what to define
    assert _cc(tmp_path, accept_flag(tmp_path), "-c", "fdsmc_controller.c").returncode == 0


def test_unclean_module_names_the_failed_checks_and_needs_this_designs_hash(tmp_path):
    failed = Verdict(True, (("torque", "Simulated peak torque 595 N·m > 40 N·m: needs a larger motor."),
                            ("chatter", "Still chatters at K = 1000 s/rad.")))
    _module(tmp_path, verdict=failed)
    header = (tmp_path / HEADER_NAME).read_text(encoding="utf-8")
    assert '#define FDSMC_FAILED_CHECKS "torque, chatter"' in header and "595 N\\302\\267m" in header
    run = _cc(tmp_path, "-c", "fdsmc_controller.c")
    assert run.returncode != 0 and "torque, chatter" in run.stderr and "not clean" in run.stderr
    wrong = _cc(tmp_path, "-DFDSMC_ACCEPT_UNCLEAN=0x1234u", "-c", "fdsmc_controller.c")
    assert wrong.returncode != 0 and "does not equal" in wrong.stderr
    assert _cc(tmp_path, accept_flag(tmp_path), "-c", "fdsmc_controller.c").returncode == 0


def test_clean_verified_module_compiles_without_acceptance(tmp_path):
    _module(tmp_path, verdict=Verdict(True))
    assert "#define FDSMC_CLEAN 1" in (tmp_path / HEADER_NAME).read_text(encoding="utf-8")
    run = _cc(tmp_path, "-c", "fdsmc_controller.c")
    assert run.returncode == 0, run.stderr


def test_export_refuses_an_unclean_design_without_force_naming_the_checks():
    params = load_preset("paper_12kw_pmsm")
    cmp = compare(params)
    checks = run_checks(params, cmp.fdsmc)
    names = [c.name for c in checks if c.violated]
    assert names  # the paper's K = 1000 on its drive is not clean
    with pytest.raises(ParameterError, match="not clean") as err:
        c_files(cmp, checks)
    assert all(n in str(err.value) for n in names) and "--force" in str(err.value)
    header = c_files(cmp, checks, force=True)[HEADER_NAME]
    assert "#define FDSMC_CLEAN 0" in header and f'"{", ".join(names)}"' in header


# ---- faults -------------------------------------------------------------------------------------


@pytest.mark.parametrize("single", [False, True])
def test_non_finite_or_implausible_currents_latch_a_fault_with_zero_output(tmp_path, single):
    _module(tmp_path)
    m = CModule(build(tmp_path, single), single)
    d = derive(load_preset("yaskawa_sgm7j_04a"))
    i_fault = 2.0 * min(d.params.controller.i_max, d.params.motor.Gamma_max / (1.5 * d.params.motor.p
                                                                              * d.params.motor.psi_pm))
    for i_d, i_q in ((0.0, math.nan), (math.inf, 1.0), (0.0, 1.01 * i_fault)):
        s, out = m.new_state(0), m.Output()
        assert m.lib.fdsmc_set_move(ctypes.byref(s), TEN_REV, 0.5) == 0
        for _ in range(5):
            m.lib.fdsmc_step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))
        assert out.fault == 0 and out.u_q != 0.0
        m.lib.fdsmc_step(ctypes.byref(s), 0, i_d, i_q, ctypes.byref(out))
        assert out.fault == 1 and out.u_d == 0.0 and out.u_q == 0.0  # FDSMC_FAULT_CURRENT, zero voltage
        m.lib.fdsmc_step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))  # latched: still safe
        assert out.fault == 1 and out.u_q == 0.0 and s.status.fault_sample == 5 and s.status.samples == 7
        assert m.lib.fdsmc_set_move(ctypes.byref(s), 0, 0.5) == -5  # FDSMC_ERR_FAULT
        m.lib.fdsmc_init(ctypes.byref(s), m.design, 0)  # recovery is explicit
        m.lib.fdsmc_step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))
        assert out.fault == 0 and all(math.isfinite(v) for v in (out.u_d, out.u_q, out.omega_hat))


def test_lost_counts_latch_the_innovation_fault(tmp_path):
    """An encoder jump beyond a quarter electrical turn (FDSMC_E_O_MAX) is a fault, not a move."""
    _module(tmp_path)
    m = CModule(build(tmp_path, True), True)
    p = load_preset("yaskawa_sgm7j_04a").motor.p
    cpr = count_params(load_preset("yaskawa_sgm7j_04a"))[0].sensors.encoder_cpr
    s, out = m.new_state(1000), m.Output()
    m.lib.fdsmc_step(ctypes.byref(s), 1000 + int(0.9 * cpr / (4 * p)), 0.0, 0.0, ctypes.byref(out))
    assert out.fault == 0 and s.status.e_o_peak == pytest.approx(0.9 * 2 * math.pi / (4 * p), rel=1e-3)
    m.lib.fdsmc_step(ctypes.byref(s), 1000 + int(1.1 * cpr / (4 * p)) + cpr // 10, 0.0, 0.0, ctypes.byref(out))
    assert out.fault == 2 and out.u_d == 0.0 and out.u_q == 0.0


def test_a_non_finite_estimate_latches_the_state_fault(tmp_path):
    _module(tmp_path)
    m = CModule(build(tmp_path, True), True)
    s, out = m.new_state(0), m.Output()
    s.z[1] = math.inf  # a corrupted load estimate (e.g. a memory fault)
    m.lib.fdsmc_step(ctypes.byref(s), 0, 0.0, 0.0, ctypes.byref(out))
    assert out.fault == 4 and out.u_d == 0.0 and out.u_q == 0.0


# ---- integration -------------------------------------------------------------------------------


def _doc_example() -> str:
    text = (ROOT / "docs" / "firmware.md").read_text(encoding="utf-8")
    match = re.search(r"```c\n(.*?)```", text, re.S)
    assert match, "docs/firmware.md has no ```c example"
    return match.group(1)


@pytest.mark.parametrize("defines", [(), ("-DFDSMC_USE_FLOAT",)])
def test_the_documented_interrupt_routine_compiles(tmp_path, defines):
    _module(tmp_path)
    (tmp_path / "isr.c").write_text(_doc_example(), encoding="utf-8")
    for src in ("isr.c", "fdsmc_controller.c"):
        run = _cc(tmp_path, *defines, accept_flag(tmp_path), "-c", src)
        assert run.returncode == 0, run.stderr


def test_header_links_from_cpp(tmp_path):
    """extern "C": a C++ program includes the header and links the C object (g++)."""
    _module(tmp_path)
    gxx = _tool("g++")
    (tmp_path / "main.cpp").write_text(
        '#include "fdsmc_controller.h"\n#include <cstdio>\n'
        "int main() {\n  static fdsmc_state s;\n  fdsmc_output out;\n  fdsmc_init(&s, &FDSMC_DESIGN, 0);\n"
        "  if (fdsmc_set_move(&s, 10 * FDSMC_COUNTS_PER_REV, 0.5) != FDSMC_OK) return 3;\n"
        "  fdsmc_step(&s, 0, 0.0, 0.0, &out);\n  std::printf(\"%u\\n\", (unsigned)out.fault);\n"
        "  return (int)out.fault;\n}\n", encoding="utf-8")
    assert _cc(tmp_path, accept_flag(tmp_path), "-c", "fdsmc_controller.c").returncode == 0
    link = subprocess.run([gxx, "-std=c++11", "-Wall", "-Wextra", "-Werror", "-pedantic", accept_flag(tmp_path),
                           "main.cpp", "fdsmc_controller.o", "-o", "main_cpp"], cwd=tmp_path, capture_output=True,
                          text=True)
    assert link.returncode == 0, link.stderr
    assert subprocess.run(["./main_cpp"], cwd=tmp_path).returncode == 0


def test_electrical_angle_is_p_times_the_mechanical_angle_wrapped(tmp_path):
    _module(tmp_path)
    m = CModule(build(tmp_path, False), False)
    params = count_params(load_preset("yaskawa_sgm7j_04a"))[0]
    n, p = params.sensors.encoder_cpr, params.motor.p
    for count in (0, 1, -5, n // 3, n - 1, n, 10 * n + 7, -(2**31), 2**31 - 1):
        for offset in (0, 12345, -n // 7):
            expect = (p * ((count - offset) % n) % n) * 2.0 * math.pi / n
            assert m.lib.fdsmc_electrical_angle(count, offset) == pytest.approx(expect, abs=1e-12)


def test_parameter_hash_ties_the_header_to_the_yaml_export(tmp_path):
    params = load_preset("yaskawa_sgm7j_04a")
    cmp = compare(params)
    header = c_files(cmp, run_checks(params, cmp.fdsmc), force=True)[HEADER_NAME]
    path = tmp_path / "drive.yaml"
    path.write_text(parameter_yaml(cmp), encoding="utf-8")
    h = parameter_hash(load_preset(str(path)))
    assert f"#define FDSMC_PARAM_HASH 0x{h}u" in header and h == parameter_hash(params)
    assert parameter_hash(load_preset("yaskawa_sgm7j_04a", ["controller.K=0.01"])) != h  # any input changes it


def test_header_states_every_constant_exactly():
    params = load_preset("paper_12kw_pmsm")
    d = derive(params)
    header = controller_files(params, d, SCHEMA)[HEADER_NAME]
    assert f"#define FDSMC_SCHEMA {SCHEMA}" in header and "Observer state" in header
    defines = dict(re.findall(r"#define FDSMC_(\w+)\s+\(\(fdsmc_real\)([^)]+)\)", header))
    assert float(defines["ALPHA_MAX"]) == d.alpha.alpha_max and float(defines["T_C"]) == d.profile.T_c
    for name in ("R_S", "L_D", "L_Q", "PSI_PM", "J_R", "K_BL", "OMEGA_P", "F_S", "U_MAX", "I_MAX", "T_SO",
                 "OMEGA_P_MAX", "T_C_MIN", "E_O_MAX", "I_FAULT", "I_LIMIT"):
        assert name in defines


def test_continuous_mode_is_refused_with_the_field_named():
    params = load_preset("paper_12kw_pmsm", ["controller.f_s=continuous"])
    with pytest.raises(ParameterError, match="controller.f_s"):
        controller_files(params, derive(params), SCHEMA)


# ---- C injection (user text in C) ---------------------------------------------------------------------

HOSTILE = [
    "x *\\\n/\n#ifndef INJ\n#define INJ\nint fdsmc_injected(void){return 42;}\n#endif\n/* ",
    "*/ int fdsmc_injected2(void) { return 1; } /*",
    "??/\n#define EVIL 1 ??= ??' ??( \"quoted\" \\ back\\",
    "ctrl \x00\x01\x07\x1b[31m\r\n\t\x7f end",
    "Ω·µ 日本語 🚀 \ud800 ß",
    "// line comment \\",
    "x" * (2 * MAX_CHARS),
]


def test_c_string_gives_the_same_bytes_for_any_text(tmp_path):
    """Every hostile text is a literal whose bytes are its UTF-8, also when placed in a comment."""
    body = "".join(f"/* {c_string(t)} */ static const char s{i}[] = {c_string(t)};\n" for i, t in enumerate(HOSTILE))
    body += "#include <stdio.h>\nint main(void) {\n"
    body += "    size_t j;\n"
    body += "".join(f'    for (j = 0; j + 1 < sizeof s{i}; ++j) printf("%02x", (unsigned)(unsigned char)s{i}[j]);\n'
                    '    putchar(10);\n' for i in range(len(HOSTILE)))
    (tmp_path / "s.c").write_text(body + "    return 0;\n}\n", encoding="ascii")
    run = _cc(tmp_path, "-trigraphs", "s.c", "-o", "s")
    assert run.returncode == 0, run.stderr
    printed = subprocess.run(["./s"], cwd=tmp_path, capture_output=True, text=True).stdout
    out = [bytes.fromhex(x) for x in printed.split()]
    cut = [t if len(t) <= MAX_CHARS else t[: MAX_CHARS - 3] + "..." for t in HOSTILE]
    assert out == [t.encode("utf-8", "surrogatepass") for t in cut]


def test_hostile_names_compile_strictly_and_define_no_extra_symbol(tmp_path):
    _tool("cc")
    params = load_preset("yaskawa_sgm7j_04a")
    params = dataclasses.replace(params, name=HOSTILE[0] + HOSTILE[2], source=HOSTILE[1] + HOSTILE[3] + HOSTILE[4])
    cmp = compare(params)
    for name, text in c_files(cmp, run_checks(params, cmp.fdsmc), force=True).items():
        assert text.isascii()
        (tmp_path / name).write_text(text, encoding="ascii")
    for src in ("fdsmc_controller.c", "fdsmc_test.c"):
        run = _cc(tmp_path, "-trigraphs", accept_flag(tmp_path), "-c", src)
        assert run.returncode == 0, run.stderr
    nm = subprocess.run(["nm", "-g", "--defined-only", "fdsmc_controller.o"], cwd=tmp_path, capture_output=True,
                        text=True, check=True).stdout
    assert {line.split()[-1] for line in nm.splitlines()} == {
        "FDSMC_DESIGN", "fdsmc_init", "fdsmc_set_move", "fdsmc_step", "fdsmc_step_conventional",
        "fdsmc_electrical_angle", "fdsmc_angle_init", "fdsmc_angle_update"}
    pre = _cc(tmp_path, "-trigraphs", "-E", "-dM", accept_flag(tmp_path), "fdsmc_controller.c")
    macros = {line.split()[1].split("(")[0] for line in pre.stdout.splitlines() if line.startswith("#define ")}
    assert not {"INJ", "EVIL"} & macros and "FDSMC_DRIVE_NAME" in macros


# ---- Cortex-M4F ---------------------------------------------------------------------------------


def _arm_export(folder: Path, preset: str) -> tuple[str, ...]:
    if arm_compiler() is None:
        _tool("arm-none-eabi-gcc")
    params = load_preset(preset)
    cmp = compare(params)
    checks = run_checks(params, cmp.fdsmc)
    for name, text in c_files(cmp, checks, force=True).items():
        (folder / name).write_text(text, encoding="utf-8")
    return () if not any(c.violated for c in checks) else (accept_flag(folder),)


@pytest.mark.parametrize("preset", ["yaskawa_sgm7j_04a", "paper_12kw_pmsm"])
def test_float_build_for_cortex_m4f_has_no_double_operation(tmp_path, preset):
    obj = cross_compile(tmp_path, _arm_export(tmp_path, preset))
    assert double_symbols(obj) == [] and symbols(obj) == []  # no helper at all: sqrtf is VSQRT
    assert "fdsmc_step" in symbols(obj, "T")


def test_float_build_fits_300_instructions_per_step(tmp_path):
    """Counted under qemu-arm over the golden vectors (scripts/c_bench.py prints the figures): -cpu cortex-m4
    where qemu-arm's user mode runs it, else the Thumb-2/VFPv4 Cortex-A15 running the same binary.
    """
    extra = _arm_export(tmp_path, "yaskawa_sgm7j_04a")
    if shutil.which("qemu-arm") is None and CI:
        pytest.fail("qemu-arm missing: scripts/ensure_cc.sh installs qemu-user (CI needs it)")
    n = count_instructions(tmp_path, extra)
    assert n.max <= 300, n  # the worst path: measured 299 (the sample that takes a move; all limits at once 293)
    if n.method.startswith("qemu-arm"):  # per path: the move and hold, the limits, each targeted limit
        assert n.calls >= 10000 and n.method in ("qemu-arm -cpu cortex-m4", "qemu-arm -cpu cortex-a15")
        assert [p.name for p in n.paths] == ["move", "limits", "limit_i_d_pos", "limit_i_d_neg", "limit_u"]
        assert all(p.worst <= 300 and p.median <= p.worst for p in n.paths) and n.median <= n.max
