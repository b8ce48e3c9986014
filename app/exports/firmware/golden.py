"""The golden vectors' segments: what the simulator's controller read and applied, in several runs.

Each :class:`Segment` starts from ``fdsmc_init`` at count 0 and a ``fdsmc_set_move`` and lists, per
sample, the readings (θ_r in counts, i_d, i_q) and the voltages the simulator applied (or zero after
an injected fault). :func:`segments` makes, within :data:`MAX_SAMPLES` samples in all:

- ``move``: the designed move and its hold (the whole simulated run when it fits): acceleration,
  cruise, deceleration on the sloped segment, standstill;
- ``limits``: the same move with a load step of :data:`LOAD_STEP_FACTOR` × Γ_max during the move, so
  that the hard current limit (and on most drives the voltage limit) acts, up to
  :data:`AFTER_LIMIT` samples after the last limited sample — only when the step leaves the
  module's constants unchanged (the load is the plant's, not the controller's);
- ``fault_current`` and ``fault_innovation``: the move's first :data:`FAULT_AT` samples, then a NaN
  i_q, or the encoder count jumping 1.5 × ``FDSMC_E_O_MAX``: zero voltage and the latched fault bit
  from that sample on;
- ``limit_i_d_pos``, ``limit_i_d_neg``, ``limit_u`` (FDSMC module): one call at rest, without a move,
  reading a current in which the d-axis current limit or the voltage limit acts
  (:mod:`app.exports.firmware.targeted`).

The ``move`` segment also checks ``fdsmc_set_move``'s refusals: called again right after the move was
set it must return ``FDSMC_ERR_BUSY`` (not yet taken), and at :data:`REFUSE_AT` of T_m
``FDSMC_ERR_MOVING`` -- and the move runs on unchanged.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.app.exports.firmware.module import controller_source
from pmsm_commissioning.app.exports.firmware.targeted import targeted_calls
from pmsm_commissioning.app.exports.firmware.verify import count_params, readings
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.params import DriveParams, LoadStep
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc.engine import simulate
from pmsm_commissioning.sim.fdsmc.grid import time_grid

#: Most samples of all segments together [-]: ≈ 110 bytes of text each (4 MB).
MAX_SAMPLES = 36000
#: Most samples of the ``move`` segment [-] (the rest is left to the others): the whole move and hold of
#: every shipped preset (the paper drive's 1 s move and hold at 20 kHz: 26000).
MAX_MOVE = 30000
#: Fraction of T_m at which the ``move`` segment calls ``fdsmc_set_move`` mid-move (refused: moving) [-].
REFUSE_AT = 0.25
#: The load step of ``limits``: this multiple of Γ_max [-], from 10 % to 20 % of T_m.
LOAD_STEP_FACTOR = 1.3
#: Samples kept after the last sample in which a limit acted [-].
AFTER_LIMIT = 200
#: The sample at which the fault segments inject their fault [-], and the samples after it.
FAULT_AT, FAULT_AFTER = 400, 4
#: fdsmc_status.fault bits of the injected faults (FDSMC_FAULT_CURRENT, FDSMC_FAULT_INNOVATION).
FAULT_CURRENT, FAULT_INNOVATION = 1, 2


@dataclass(frozen=True)
class Segment:
    """One replay from ``fdsmc_init(&s, &FDSMC_DESIGN, 0)`` and ``fdsmc_set_move(&s, theta_dem, T_m)``.

    Attributes
    ----------
    name : str              What it exercises.
    theta_dem : int         The move's demand [counts].
    T_m : float             The move's time [s].
    theta : numpy.ndarray   Encoder count per sample [counts].
    i_dq : numpy.ndarray    (n, 2) currents read [A] (NaN where a fault is injected).
    u_dq : numpy.ndarray    (n, 2) voltages applied by the simulator [V] (0 from a fault on).
    fault : int             Fault bits latched at the end (0: none).
    fault_at : int          Sample of the fault (-1: none).
    refuse_at : int         Sample before which ``fdsmc_set_move`` must refuse (moving), and right after the
                            move was set (busy) (-1: not checked). ``T_m`` = 0: no move is set.
    """

    name: str
    theta_dem: int
    T_m: float
    theta: np.ndarray
    i_dq: np.ndarray
    u_dq: np.ndarray
    fault: int = 0
    fault_at: int = -1
    refuse_at: int = -1


def _run(params: DriveParams, controller: str, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Return (counts, currents read, voltages applied, limited) of the first ``n`` samples of ``params``' run.

    ``limited``: the samples at which |i_dq| reached 99 % of the hard limit or |u_dq| the voltage limit.
    """
    n_steps = time_grid(params, 1, 0.0, 1).n_steps
    run = simulate(params, controller, max_points=n_steps + 1)
    trace, n = run.trace, min(n, n_steps)
    if trace.t.size < n:
        raise ParameterError(f"the simulated run stops after {trace.t.size} samples: no test vectors")
    noise = sensors.noise_table(params.sensors)
    read = np.array([readings(params, k, trace.theta_r[k], trace.i_d[k], trace.i_q[k], noise) for k in range(n)])
    i_lim, u_lim = current_limit(params), params.controller.V_dc / math.sqrt(3.0)
    limited = ((i_lim > 0.0) & (np.hypot(trace.i_d[:n], trace.i_q[:n]) >= 0.99 * i_lim)) | (
        (u_lim > 0.0) & (np.hypot(trace.u_d[:n], trace.u_q[:n]) >= (1.0 - 1e-9) * u_lim))
    return read[:, 0].astype(np.int64), read[:, 1:], np.column_stack([trace.u_d[:n], trace.u_q[:n]]), limited


def _limit_case(params: DriveParams) -> DriveParams:
    """``params`` with a load step of LOAD_STEP_FACTOR·Γ_max from 0.1·T_m to 0.2·T_m (the plant's load)."""
    T_m, gamma = params.manoeuvre.T_m, LOAD_STEP_FACTOR * params.motor.Gamma_max
    steps = (LoadStep(0.1 * T_m, gamma), LoadStep(0.2 * T_m, params.load.Gamma_Le))
    return dataclasses.replace(params, load=dataclasses.replace(params.load, steps=steps))


def _same_module(a: DriveParams, b: DriveParams) -> bool:
    """Whether the two cases give the same ``FDSMC_DESIGN`` (the vectors of one replay on the other's module)."""
    return controller_source(a, derive(a)).split("FDSMC_DESIGN")[1] == controller_source(b, derive(b)).split(
        "FDSMC_DESIGN")[1]


def _limits(params: DriveParams, count: int, controller: str, room: int) -> list[Segment]:
    """Return the ``limits`` segment (none when the step changes the module or no limit acts in ``room``)."""
    case = _limit_case(params)
    if room <= 0 or not _same_module(params, case):
        return []
    theta, i_dq, u_dq, limited = _run(case, controller, room)
    acted = np.flatnonzero(limited)
    if acted.size == 0:
        return []
    n = min(room, int(acted[-1]) + AFTER_LIMIT)
    return [Segment("limits", count, params.manoeuvre.T_m, theta[:n], i_dq[:n], u_dq[:n])]


def _faults(move: Segment, params: DriveParams) -> list[Segment]:
    """Return the two fault segments, from the first FAULT_AT samples of ``move``."""
    k, n = FAULT_AT, FAULT_AT + FAULT_AFTER
    if move.theta.size < n:
        return []
    u = move.u_dq[:n].copy()
    u[k:] = 0.0
    i_nan = move.i_dq[:n].copy()
    i_nan[k, 1] = math.nan
    e_o_max = math.pi / (2.0 * params.motor.p) * params.sensors.encoder_cpr / (2.0 * math.pi)
    jumped = move.theta[:n].copy()
    jumped[k] += math.ceil(1.5 * e_o_max)
    return [Segment("fault_current", move.theta_dem, move.T_m, move.theta[:n], i_nan, u, FAULT_CURRENT, k),
            Segment("fault_innovation", move.theta_dem, move.T_m, jumped, move.i_dq[:n], u, FAULT_INNOVATION, k)]


def segments(entered: DriveParams, controller: str = "fdsmc") -> list[Segment]:
    """Return the golden vectors' segments of the case ``entered`` (θ_dem rounded to a count), in replay order.

    Raises
    ------
    ParameterError
        When the simulated run stops early (unstable) or is infeasible.
    """
    params, count = count_params(entered)
    theta, i_dq, u_dq, _ = _run(params, controller, MAX_MOVE)
    refuse_at = round(REFUSE_AT * params.manoeuvre.T_m * float(params.controller.f_s))
    move = Segment("move", count, params.manoeuvre.T_m, theta, i_dq, u_dq,
                   refuse_at=refuse_at if 0 < refuse_at < theta.size else -1)
    faults = _faults(move, params)
    targeted = _targeted(params) if controller == "fdsmc" else []
    room = MAX_SAMPLES - move.theta.size - sum(s.theta.size for s in faults + targeted)
    return [move, *_limits(params, count, controller, room), *faults, *targeted]


def _targeted(params: DriveParams) -> list[Segment]:
    """Return the targeted limit segments (:func:`app.exports.firmware.targeted.targeted_calls`), count 0, no move."""
    segs = []
    for name, call in targeted_calls(params, derive(params)).items():
        n = 2 if params.controller.delay_samples == 1 else 1
        u = np.zeros((n, 2))
        u[-1] = (call.u_d, call.u_q)
        segs.append(Segment(name, 0, 0.0, np.zeros(n, dtype=np.int64), np.tile([call.i_d, call.i_q], (n, 1)), u))
    return segs
