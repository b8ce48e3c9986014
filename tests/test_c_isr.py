"""The generated C controller in an interrupt-driven drive: the electrical angle of any encoder across
the 32-bit counter's wrap (no 64-bit division on the target), and the move handed over from a
lower-priority context to the PWM interrupt that steps the controller (no torn move, no fault).
"""

from __future__ import annotations

import ctypes
import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from pmsm_commissioning.app.exports.firmware.verify import (
    CFLAGS,
    CModule,
    accept_flag,
    build,
    compiler,
    count_params,
    readings,
    write_module,
)
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc.plant import PlantInTheLoop
from scripts.c_arm import LONG_SYMBOL, arm_compiler, cross_compile, helper_symbols, symbols
from tests.toolchain import need

PRESET = "yaskawa_sgm7j_04a"


def _module(folder: Path, cpr: int) -> int:
    """Write the module of the preset with ``cpr`` counts/rev into ``folder``; returns its pole pairs."""
    need(compiler(), "cc")
    params, _ = count_params(load_preset(PRESET, [f"sensors.encoder_cpr={cpr}"]))
    write_module(folder, params)
    return params.motor.p


def _wrapped(n: int) -> int:
    """The int32 a free-running 32-bit counter shows for the unwrapped count ``n``."""
    return (n + 2**31) % 2**32 - 2**31


# ---- any encoder: the electrical angle across the counter's wrap ---------------------------------


@pytest.mark.parametrize("cpr", [10000, 2**14])
@pytest.mark.parametrize("single", [False, True])
def test_electrical_angle_is_continuous_across_the_counter_wrap(tmp_path, cpr, single):
    """10 000 counts/rev (2500 lines x 4) and 2^14: the tracker follows p*theta_r mod 2*pi through 2^31."""
    p = _module(tmp_path, cpr)
    m = CModule(build(tmp_path, single), single)
    offset, start, step = 1234, 2**31 - 3000, 7
    a = m.Angle()
    m.lib.fdsmc_angle_init(ctypes.byref(a), _wrapped(start), offset)
    got, want = [], []
    for k in range(1000):  # crosses 2^31 at k = 429
        n = start + k * step
        got.append(m.lib.fdsmc_angle_update(ctypes.byref(a), _wrapped(n)))
        want.append((p * (n - offset)) % cpr * 2.0 * math.pi / cpr)
    err = np.abs(np.angle(np.exp(1j * (np.array(got) - np.array(want)))))
    assert err.max() < (2e-6 if single else 1e-12), err.max()
    jumps = np.abs(np.angle(np.exp(1j * np.diff(got))))
    assert jumps.max() < 1.01 * p * step * 2.0 * math.pi / cpr  # no jump at the wrap
    assert all(0.0 <= g < 2.0 * math.pi for g in got)
    # The stateless form is exact across the wrap (of theta_r - offset) only when cpr divides 2^32.
    before, after = (m.lib.fdsmc_electrical_angle(_wrapped(n), offset) for n in (offset + 2**31 - 1, offset + 2**31))
    stateless_jump = abs(np.angle(np.exp(1j * (after - before))))
    one_count = abs(stateless_jump - p * 2.0 * math.pi / cpr) < 1e-5
    assert one_count == (2**32 % cpr == 0), stateless_jump


def test_the_tracker_takes_any_step_without_overflow(tmp_path):
    """Large steps (the slow path: |d mod cpr| * p beyond int32) give the same angle as small ones."""
    p = _module(tmp_path, 10000)
    m = CModule(build(tmp_path, False), False)
    a = m.Angle()
    m.lib.fdsmc_angle_init(ctypes.byref(a), 0, 0)
    n = 0
    for d in (2**31 - 1, -(2**31) + 5, 9999, -9999, 1, 2**30 + 17):
        n += d
        got = m.lib.fdsmc_angle_update(ctypes.byref(a), _wrapped(n))
        assert got == pytest.approx((p * n) % 10000 * 2.0 * math.pi / 10000, abs=1e-12), d


def test_helper_check_knows_the_64_bit_division_helpers():
    for name in ("__aeabi_ldivmod", "__aeabi_uldivmod", "__divdi3", "__moddi3", "__udivdi3", "__umoddi3"):
        assert LONG_SYMBOL.fullmatch(name), name
    assert not LONG_SYMBOL.fullmatch("__aeabi_fdiv")


@pytest.mark.parametrize("cpr", [10000, 2**14])
def test_no_64_bit_or_double_helper_in_the_float_object_for_any_encoder(tmp_path, cpr):
    """arm-none-eabi-gcc, Cortex-M4F: the object calls no helper at all, 64-bit division included."""
    need(arm_compiler(), "arm-none-eabi-gcc")
    _module(tmp_path, cpr)
    obj = cross_compile(tmp_path, (accept_flag(tmp_path),))
    assert helper_symbols(obj) == [] and symbols(obj) == []
    assert {"fdsmc_angle_update", "fdsmc_electrical_angle"} <= set(symbols(obj, "T"))


# ---- the move hand-over ----------------------------------------------------------------------------

HOOK_C = """\
#include <stdio.h>
#include <stdlib.h>
#include "fdsmc_controller.h"
static fdsmc_state s;
static fdsmc_output out;
static int point, preempt_at, isr_runs;
void fdsmc_test_isr(void) /* the PWM interrupt, run where fdsmc_set_move may be preempted */
{
    if (point++ == preempt_at) {
        fdsmc_step(&s, 0, 0.0, 0.0, &out);
        isr_runs++;
    }
}
int main(int argc, char **argv)
{
    const fdsmc_count target = (fdsmc_count)atol(argv[1]);
    int32_t rc;
    (void)argc;
    preempt_at = atoi(argv[2]);
    fdsmc_init(&s, &FDSMC_DESIGN, 0);
    fdsmc_step(&s, 0, 0.0, 0.0, &out);
    rc = fdsmc_set_move(&s, target, (fdsmc_real)FDSMC_T_M);
    preempt_at = -1;
    fdsmc_step(&s, 0, 0.0, 0.0, &out); /* the next interrupt */
    printf("rc %d points %d isr %d fault %u pending %u theta_dem %ld omega_p %.17g t_c %.17g samples %u\\n",
           (int)rc, point, isr_runs, (unsigned)(s.status.fault | out.fault), (unsigned)s.move_pending,
           (long)s.theta_dem, (double)s.omega_p, (double)s.t_c, (unsigned)s.status.samples);
    return 0;
}
"""


def _preemption_program(folder: Path, single: bool) -> Path:
    """The module with its preemption points running the interrupt (``fdsmc_test_isr``) at one of them."""
    (folder / "hook.c").write_text(HOOK_C, encoding="utf-8")
    (folder / "hook.h").write_text("void fdsmc_test_isr(void);\n", encoding="utf-8")
    exe = folder / ("hook_f" if single else "hook_d")
    run = subprocess.run([compiler() or "cc", *CFLAGS, *(["-DFDSMC_USE_FLOAT"] if single else []),
                          accept_flag(folder), "-DFDSMC_PREEMPTION_POINT()=fdsmc_test_isr()", "-include", "hook.h",
                          "-O2", "hook.c", "fdsmc_controller.c", "-lm", "-o", exe.name],
                         cwd=folder, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return exe


@pytest.mark.parametrize("single", [False, True])
def test_an_interrupt_at_any_point_of_set_move_takes_the_whole_move_once(tmp_path, single):
    """The interrupt runs at each point where fdsmc_set_move may be preempted: no fault, the same move."""
    _module(tmp_path, 2**24)
    exe = _preemption_program(tmp_path, single)
    target = 10 * 2**24

    def run(at: int) -> dict[str, str]:
        text = subprocess.run([str(exe), str(target), str(at)], capture_output=True, text=True, check=True).stdout
        return dict(re.findall(r"(\w+) (\S+)", text))

    ref = run(-1)
    assert ref["rc"] == "0" and ref["isr"] == "0" and int(ref["points"]) >= 6
    for at in range(int(ref["points"])):
        got = run(at)
        assert got["isr"] == "1" and got["fault"] == "0" and got["rc"] == "0", (at, got)
        assert got["pending"] == "0" and got["theta_dem"] == str(target), (at, got)
        assert (got["omega_p"], got["t_c"]) == (ref["omega_p"], ref["t_c"]), (at, got)
        assert int(got["samples"]) == int(ref["samples"]) + 1


def test_a_move_is_refused_until_the_last_one_ended_and_accepted_at_rest(tmp_path):
    """Closed loop on the simulator's plant: -7 (moving) during the move, accepted once it has settled."""
    _module(tmp_path, 2**24)
    params, count = count_params(load_preset(PRESET))
    m = CModule(build(tmp_path, False), False)
    s, out = m.new_state(0), m.Output()
    assert m.lib.fdsmc_set_move(ctypes.byref(s), count, params.manoeuvre.T_m) == 0
    plant, noise = PlantInTheLoop(params), sensors.noise_table(params.sensors)
    shadow, codes = (0.0, 0.0), set()
    for k in range(plant.n_samples):
        x = plant.x
        m.lib.fdsmc_step(ctypes.byref(s), *readings(params, k, x[2], x[0], x[1], noise), ctypes.byref(out))
        plant.step(*shadow)
        shadow = (out.u_d_next, out.u_q_next)
        if k % 500 == 250 and k < 0.9 * params.manoeuvre.T_m * params.controller.f_s:
            codes.add(m.lib.fdsmc_set_move(ctypes.byref(s), 0, params.manoeuvre.T_m))
    assert codes == {-7} and out.fault == 0 and s.status.last_move == -7
    assert m.lib.fdsmc_set_move(ctypes.byref(s), 0, params.manoeuvre.T_m) == 0  # at rest: back to 0
