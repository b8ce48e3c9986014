"""The generated C controller under the firmware engineer's build flags and integration text.

Fast-math flags (-ffast-math, -Ofast, -ffinite-math-only) stop the build naming the flag to add, with
gcc and with clang; when accepted anyway, the NaN/inf checks (on the bit pattern) still latch the fault.
The timing the header documents -- out.u_d_next/u_q_next to the PWM shadow registers, acting over
[k+1, k+2] -- is the one the closed-loop verification runs, and there it is the simulator's, the hard
current limit included.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pmsm_commissioning.app.exports.firmware.module import HEADER_NAME, parameter_hash
from pmsm_commissioning.app.exports.firmware.verify import (
    CFLAGS,
    CModule,
    accept_flag,
    agreement,
    build,
    closed_loop,
    compiler,
    count_params,
    readings,
    write_module,
)
from pmsm_commissioning.app.exports.tool_id import tool_version
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc.plant import PlantInTheLoop
from scripts.c_arm import arm_compiler, double_symbols
from tests.toolchain import need

ROOT = Path(__file__).resolve().parent.parent
FAST_MATH = [("-ffast-math",), ("-Ofast",), ("-O2", "-ffinite-math-only")]


def _module(folder: Path, preset: str = "yaskawa_sgm7j_04a", sets: tuple[str, ...] = ()) -> None:
    need(compiler(), "C compiler")
    params, _ = count_params(load_preset(preset, list(sets)))
    write_module(folder, params)


@pytest.fixture(params=["gcc", "clang"])
def cc(request) -> str:
    """Path of the host compiler (gcc, clang); a failure under CI=true, else a skip, when it is missing."""
    return need(shutil.which(request.param), request.param)


def _compile(folder: Path, cc: str, *flags: str) -> subprocess.CompletedProcess:
    return subprocess.run([cc, *CFLAGS, accept_flag(folder), *flags, "-shared", "-fPIC",
                           "fdsmc_controller.c", "-o", "lib.so", "-lm"], cwd=folder, capture_output=True, text=True)


@pytest.mark.parametrize("flags", FAST_MATH)
def test_fast_math_builds_stop_naming_the_flag_to_add(tmp_path, cc, flags):
    _module(tmp_path)
    run = _compile(tmp_path, cc, *flags)
    assert run.returncode != 0 and "#error" in run.stderr and "-fno-finite-math-only" in run.stderr, run.stderr
    assert _compile(tmp_path, cc, *flags, "-fno-finite-math-only").returncode == 0


@pytest.mark.parametrize("flags", FAST_MATH + [("-ffast-math", "-fno-finite-math-only")])
@pytest.mark.parametrize("single", [False, True])
def test_nan_and_inf_latch_the_fault_under_fast_math(tmp_path, cc, flags, single):
    """Accepted anyway (FDSMC_ALLOW_FINITE_MATH): the checks on the bit pattern still see NaN and inf.

    The fast-math library is loaded in a child process: a shared object built with -ffast-math or -Ofast
    sets flush-to-zero for the whole process that loads it (crtfastmath), which would change every later
    test's arithmetic (subnormals read as 0).
    """
    _module(tmp_path)
    defines = ("-DFDSMC_ALLOW_FINITE_MATH",) + (("-DFDSMC_USE_FLOAT",) if single else ())
    run = _compile(tmp_path, cc, *flags, *defines)
    assert run.returncode == 0, run.stderr
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    child = subprocess.run([sys.executable, __file__, str(tmp_path / "lib.so"), "1" if single else "0"],
                           capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
    assert child.returncode == 0 and child.stdout.strip() == "ok", child.stdout + child.stderr


def _check_fault_latch(lib_path: str, single: bool) -> None:
    """In this (child) process: NaN/inf currents latch fault 1, a NaN estimate fault 4, a NaN T_m is refused."""
    m = CModule(ctypes.CDLL(lib_path), single)
    for i_d, i_q in ((0.0, math.nan), (math.inf, 1.0), (0.0, -math.nan), (-math.inf, 0.0)):
        s, out = m.new_state(0), m.Output()
        for _ in range(3):
            m.lib.fdsmc_step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))
        assert out.fault == 0
        m.lib.fdsmc_step(ctypes.byref(s), 0, i_d, i_q, ctypes.byref(out))
        assert out.fault == 1 and (out.u_d, out.u_q, out.u_d_next, out.u_q_next) == (0.0, 0.0, 0.0, 0.0), (i_d, i_q)
        assert math.isfinite(out.theta_re) and out.saturated == 0
    s, out = m.new_state(0), m.Output()
    if single:
        s.z[1] = math.nan  # a corrupted estimate: the state fault
    else:
        s.x[2] = math.nan
    m.lib.fdsmc_step(ctypes.byref(s), 0, 0.0, 0.0, ctypes.byref(out))
    assert out.fault == 4 and out.u_q == 0.0
    assert m.lib.fdsmc_set_move(ctypes.byref(m.new_state(0)), 1000, math.nan) == -1  # FDSMC_ERR_ARG


# ---- the documented timing is the verified one ---------------------------------------------------


def _header(folder: Path) -> str:
    return (folder / HEADER_NAME).read_text(encoding="utf-8")


def test_header_and_docs_state_the_timing_the_verification_runs(tmp_path):
    """The header and docs/firmware.md say: write u_next to shadow registers, it acts over [k+1, k+2]."""
    _module(tmp_path)
    header = re.sub(r"\s*\n\s*\*\s*", " ", _header(tmp_path))
    assert "out.u_d, out.u_q are the voltages computed at call k-1; the simulator applies them over [k, k+1]" in header
    assert "out.u_d_next, out.u_q_next (computed now) are the ones for [k+1, k+2]: write THEM to the PWM shadow " \
           "registers loaded at the next period start (k+1)" in header
    assert "theta_e(k) + p*out.omega_hat*1.5*T_s" in header
    doc = (ROOT / "docs" / "firmware.md").read_text(encoding="utf-8")
    example = re.search(r"```c\n(.*?)```", doc, re.S)
    assert example and "out.u_d_next, out.u_q_next" in example.group(1) and "1.5 * FDSMC_T_S" in example.group(1)
    assert "out.u_d, out.u_q)" not in example.group(1)  # the held voltages are not what the shadow registers get


def test_the_documented_isr_sequence_keeps_the_hard_current_limit_and_the_simulators_run(tmp_path):
    """Shadow registers loaded at k+1 with call k's u_next (firmware.verify.closed_loop): bit-identical to the
    simulator with the limits acting, |i_dq| <= I_LIMIT (0.1 %); writing the held out.u_d/u_q instead
    (two samples late) breaks the limit.
    """
    sets = ("controller.K=0.3", "controller.delay_samples=1", "controller.V_dc=300", "controller.i_max=40")
    _module(tmp_path, "paper_12kw_pmsm", sets)
    params, count = count_params(load_preset("paper_12kw_pmsm", list(sets)))
    lib = build(tmp_path, False)
    rows = closed_loop(lib, False, params)
    assert max(agreement(params, rows).values()) == 0.0
    i_limit = current_limit(params)
    # Measured: 1.00027*I_LIMIT (the limit's ZOH prediction against the RK4 plant); two samples late 1.153.
    assert np.hypot(rows[:, 0], rows[:, 1]).max() <= i_limit * 1.001
    late = _two_samples_late(lib, params, count)
    assert np.hypot(late[:, 0], late[:, 1]).max() > i_limit * 1.05


def _two_samples_late(lib: ctypes.CDLL, params, count: int) -> np.ndarray:
    """The closed loop with out.u_d/u_q written to shadow registers (the old, wrong reading of the header)."""
    m = CModule(lib, False)
    s, out = m.new_state(0), m.Output()
    assert lib.fdsmc_set_move(ctypes.byref(s), count, params.manoeuvre.T_m) == 0
    plant, noise = PlantInTheLoop(params), sensors.noise_table(params.sensors)
    rows, shadow = np.zeros((plant.n_samples, len(plant.x))), (0.0, 0.0)
    for k in range(plant.n_samples):
        rows[k] = x = plant.x
        lib.fdsmc_step(ctypes.byref(s), *readings(params, k, x[2], x[0], x[1], noise), ctypes.byref(out))
        plant.step(*shadow)
        shadow = (out.u_d, out.u_q)
    return rows


def test_accepting_by_the_macros_own_name_is_refused(tmp_path):
    """-DFDSMC_ACCEPT_UNCLEAN=FDSMC_PARAM_HASH does not bypass the gate: only the literal hash does."""
    _module(tmp_path)
    run = subprocess.run([compiler() or "cc", *CFLAGS, "-DFDSMC_ACCEPT_UNCLEAN=FDSMC_PARAM_HASH", "-c",
                          "fdsmc_controller.c"], cwd=tmp_path, capture_output=True, text=True)
    assert run.returncode != 0 and "does not equal" in run.stderr


def test_the_hash_covers_the_tool_version(tmp_path, monkeypatch):
    """Another version of the tool (its code may differ) gives another FDSMC_PARAM_HASH: the old
    acceptance no longer builds the new module, only the new literal does.
    """
    _module(tmp_path)
    params = count_params(load_preset("yaskawa_sgm7j_04a"))[0]
    old_flag, h = accept_flag(tmp_path), parameter_hash(params)
    assert h == parameter_hash(params, tool_version()) and f"0x{h}u" in old_flag
    assert parameter_hash(params, tool_version() + ".post1") != h
    monkeypatch.setattr(importlib.metadata, "version", lambda name: "99.0.0")
    assert tool_version().endswith(" 99.0.0") and parameter_hash(params) != h
    new = tmp_path / "new"
    new.mkdir()
    write_module(new, params)  # unverified: the gate needs the acceptance
    assert "99.0.0" in _header(new)
    for flag, ok in ((old_flag, False), (accept_flag(new), True)):
        run = subprocess.run([compiler() or "cc", *CFLAGS, flag, "-c", "fdsmc_controller.c"], cwd=new,
                             capture_output=True, text=True)
        assert (run.returncode == 0) == ok, run.stderr


def test_float32_is_the_default_on_a_single_precision_fpu(tmp_path):
    """Cortex-M4F without -DFDSMC_USE_FLOAT: the float build (no double helper); -DFDSMC_USE_DOUBLE opts out."""
    need(arm_compiler(), "arm-none-eabi-gcc")
    _module(tmp_path)
    base = ["arm-none-eabi-gcc", "-mcpu=cortex-m4", "-mthumb", "-mfpu=fpv4-sp-d16", "-mfloat-abi=hard", "-O2",
            "-std=c99", accept_flag(tmp_path), "-c", "fdsmc_controller.c"]
    subprocess.run([*base, "-o", "f.o"], cwd=tmp_path, check=True, capture_output=True)
    subprocess.run([*base, "-DFDSMC_USE_DOUBLE", "-o", "d.o"], cwd=tmp_path, check=True, capture_output=True)
    assert double_symbols(tmp_path / "f.o") == [] and double_symbols(tmp_path / "d.o") != []


if __name__ == "__main__":
    _check_fault_latch(sys.argv[1], sys.argv[2] == "1")
    print("ok")
