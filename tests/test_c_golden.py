"""What the golden vectors cover: the whole move and hold, the limits, faults and targeted calls at rest.

The ``move`` segment is the whole simulated run (the paper drive's 1 s move and hold at 20 kHz, 26 000
samples, included) and asks ``fdsmc_set_move`` to refuse mid-move; the targeted segments are single
calls at rest whose readings make the d-axis current limit or the voltage limit act, with the
voltages of the simulator's controller functions.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.app.exports.firmware.golden import REFUSE_AT, segments
from pmsm_commissioning.app.exports.firmware.targeted import call_at_rest, targeted_calls
from pmsm_commissioning.app.exports.firmware.verify import count_params
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.sim.fdsmc.grid import time_grid


def test_the_move_segment_is_the_whole_run_with_the_hold():
    params = load_preset("paper_12kw_pmsm")
    segs = {s.name: s for s in segments(params)}
    n_steps = time_grid(count_params(params)[0], 1, 0.0, 1).n_steps
    move = segs["move"]
    assert move.theta.size == n_steps > params.manoeuvre.T_m * params.controller.f_s  # the hold after T_m
    assert move.refuse_at == round(REFUSE_AT * params.manoeuvre.T_m * params.controller.f_s)
    assert abs(move.theta[-1] - move.theta_dem) < 1e-4 * move.theta_dem  # it ends in the hold at the demand


@pytest.mark.parametrize("preset, names", [("yaskawa_sgm7j_04a", {"limit_i_d_pos", "limit_i_d_neg", "limit_u"}),
                                           ("odrive_d5065_belt", {"limit_i_d_pos", "limit_i_d_neg"})])
def test_targeted_calls_make_their_limit_act(preset, names):
    params = count_params(load_preset(preset))[0]
    d = derive(params)
    calls = targeted_calls(params, d)
    assert set(calls) == names
    i_lim, u_max = current_limit(params), params.controller.V_dc / math.sqrt(3.0)
    for name, call in calls.items():
        assert i_lim < math.hypot(call.i_d, call.i_q) < 2.0 * i_lim  # beyond the limit, below the fault
        assert call.d_limited if name.startswith("limit_i_d") else call.u_limited
        assert math.hypot(call.u_d, call.u_q) <= u_max * (1.0 + 1e-12)
    unlimited = call_at_rest(params, d, 0.5 * i_lim, 0.0)
    assert not unlimited.d_limited and not unlimited.u_limited


def test_targeted_segments_hold_the_call_after_the_delay():
    """Delay 1: the first call returns the held zero voltages, the second the first call's."""
    params = load_preset("yaskawa_sgm7j_04a")
    segs = {s.name: s for s in segments(params)}
    calls = targeted_calls(count_params(params)[0], derive(count_params(params)[0]))
    for name, call in calls.items():
        seg = segs[name]
        assert seg.T_m == 0.0 and seg.theta.tolist() == [0, 0]
        assert np.array_equal(seg.u_dq, [[0.0, 0.0], [call.u_d, call.u_q]])
