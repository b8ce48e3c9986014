"""One source per law and per record: Γ_em of eq. (5) is the one law the compiled kernel and the
plain-Python reference call; the kernel's summary and state vectors are decoded by name once; the
trace has exactly the kernel's channels, in its order.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmsm_commissioning.control.fdsmc.model import electromagnetic_torque
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.engine import Trace
from pmsm_commissioning.sim.fdsmc.summary import STATE_INDEX, KernelState, decode_info, decode_state


def test_trace_fields_are_the_kernels_channels():
    assert tuple(f.name for f in dataclasses.fields(Trace)) == lay.CHANNELS


def test_every_state_index_is_decoded_once_by_name():
    assert sorted(STATE_INDEX.values()) == list(range(lay.N_X))
    assert set(STATE_INDEX) == {f.name for f in dataclasses.fields(KernelState)}
    x = np.arange(lay.N_X, dtype=float) * 1.5
    state = decode_state(x)
    assert state.theta_r == x[lay.X_TH] and state.E_electrical == x[lay.X_EEL] and x[lay.X_L1] == state.L1


def test_the_summary_reads_each_info_slot():
    info = np.arange(lay.N_INFO, dtype=float) + 0.25
    info[lay.I_NOUT], info[lay.I_FAILED] = 7.0, 1.0
    s = decode_info(info)
    assert s.n_out == 7 and s.failed is True
    assert (s.t_fail, s.saturated_s, s.torque_peak, s.overshoot) == (
        info[lay.I_TFAIL], info[lay.I_TSAT], info[lay.I_PTQ], info[lay.I_OVS])
    assert s.at_Tm.theta_r == info[lay.I_SNAP + lay.X_TH] and s.end.omega_r == info[lay.I_END + lay.X_W]
    assert (s.i_dq_peak, s.over_i_max_s, s.t_out) == (info[lay.I_PIDQ], info[lay.I_TOVER], info[lay.I_TOUT])


@pytest.mark.parametrize(("i_d", "i_q"), [(0.0, 10.0), (-3.7, 12.25), (1e-3, -250.0)])
def test_the_kernel_uses_the_one_torque_law(i_d, i_q):
    prm = np.zeros(lay.N_PRM)
    prm[lay.P_P], prm[lay.P_PSI], prm[lay.P_LD], prm[lay.P_LQ] = 3.0, 0.172, 5.4e-3, 6.1e-3
    law = electromagnetic_torque(3.0, 0.172, 5.4e-3, 6.1e-3, i_d, i_q)
    assert kn.electromagnetic_torque(i_d, i_q, prm) == law  # compiled: bit-identical
    assert law == 1.5 * 3.0 * (0.172 + (5.4e-3 - 6.1e-3) * i_d) * i_q  # eq. (5) of [1]
