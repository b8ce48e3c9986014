"""Every field of fdsmc_output is written on a faulting call, as the header promises.

The output struct is filled with a poison byte pattern (a large finite value, then NaN) before the
call; after a call that latches or keeps a fault, every voltage and diagnostic must be exactly 0,
``saturated`` 0 and ``fault`` the latched bits -- for each fault (current not finite or implausible,
innovation, state), for a call after the fault, with either outer law entry point, in both builds.
"""

from __future__ import annotations

import ctypes
import math
from pathlib import Path

import pytest

from pmsm_commissioning.app.exports.firmware.verify import CModule, build, compiler, count_params, write_module
from pmsm_commissioning.app.io.presets import load_preset
from tests.toolchain import need

PRESET = "yaskawa_sgm7j_04a"
#: Poison bytes: 0x7f.. is a large finite float/double and int, 0xff.. a NaN and -1.
POISONS = (0x7F, 0xFF)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The preset's module (unverified: built with its acceptance)."""
    need(compiler(), "C compiler")
    path = tmp_path_factory.mktemp("fault_outputs")
    write_module(path, count_params(load_preset(PRESET))[0])
    return path


def _poisoned(m: CModule, byte: int) -> ctypes.Structure:
    out = m.Output()
    ctypes.memset(ctypes.addressof(out), byte, ctypes.sizeof(out))
    return out


def _assert_written(m: CModule, out: ctypes.Structure, fault: int) -> None:
    for name, _ in m.Output._fields_:
        value = getattr(out, name)
        expected = fault if name == "fault" else 0
        assert value == expected and not (isinstance(value, float) and math.isnan(value)), (name, value)


def _warm(m: CModule, s, step) -> None:
    """Three good samples (a current of 2 A, at the start count): a running state, no fault."""
    out = m.Output()
    for _ in range(3):
        step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))
    assert out.fault == 0


def _inputs(m: CModule, case: str, single: bool):
    """(state, theta_r, i_d, i_q, fault bits) of the faulting call ``case``."""
    s = m.new_state(0)
    if case == "current_nan":
        return s, 0, 0.0, math.nan, 1
    if case == "current_large":
        return s, 0, 0.0, 1e6, 1
    if case == "innovation":
        return s, 2**30, 0.0, 0.0, 2
    if single:
        s.z[1] = math.inf  # a corrupted estimate: the state fault
    else:
        s.x[1] = math.inf
    return s, 0, 0.0, 0.0, 4


@pytest.mark.parametrize("single", [False, True])
@pytest.mark.parametrize("law", ["fdsmc_step", "fdsmc_step_conventional"])
@pytest.mark.parametrize("case", ["current_nan", "current_large", "innovation", "state"])
def test_every_output_field_is_written_on_a_faulting_call(folder, single, law, case):
    m = CModule(build(folder, single), single)
    step = getattr(m.lib, law)
    for byte in POISONS:
        s, theta, i_d, i_q, bits = _inputs(m, case, single)
        if case != "state":
            _warm(m, s, step)
        out = _poisoned(m, byte)
        step(ctypes.byref(s), theta, i_d, i_q, ctypes.byref(out))
        _assert_written(m, out, bits)
        out = _poisoned(m, byte)  # the next call: the fault stays latched, the outputs written again
        step(ctypes.byref(s), 0, 0.1, 2.0, ctypes.byref(out))
        _assert_written(m, out, bits)
        assert s.status.fault == bits
