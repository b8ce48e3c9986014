"""Time grid and cost of a run: RK4 step, plant substeps, trace decimation and the cost budget.

A rest-to-rest manoeuvre is simulated over [0, (1 + TAIL_FRACTION)·T_m]. In digital mode the
controller runs at f_s with the plant integrated in RK4 substeps; in continuous mode one RK4 step
carries the controller in every stage. :func:`check_budget` refuses a request before any
derivation or allocation when its steps or trace bytes exceed :mod:`sim.common.budget`'s limits,
naming the fields that drive the cost.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.metrics import CHATTER_MAX_WINDOW_S

#: Simulated horizon beyond T_m, as a fraction of T_m [-].
TAIL_FRACTION = 0.3
#: RK4 step of continuous mode [s]; friction energies converged to < 0.05 % (see tests).
CONTINUOUS_STEP_S = 5e-6
#: Largest h·λ_max of continuous mode (λ_max the fastest designed pole) [-]; 5 µs at T_so = 0.2 ms.
CONTINUOUS_STEP_RATIO = 0.1875
#: Largest RK4 plant substep between controller samples in digital mode [s].
PLANT_STEP_MAX_S = 5e-5
#: Most trace points kept per run (energies and peaks use every step).
MAX_POINTS = 20000


@dataclass(frozen=True)
class TimeGrid:
    """Integration grid of one run: RK4 step h [s], samples/steps, substeps per sample, trace decimation."""

    continuous: bool
    h: float
    n_steps: int
    n_sub: int
    decim: int
    n_out: int


def continuous_step(params: DriveParams, h_max: float = CONTINUOUS_STEP_S) -> float:
    """RK4 step of continuous mode [s]: h_max, or less so that h·λ_max ≤ CONTINUOUS_STEP_RATIO.

    λ_max [1/s] is the fastest designed pole: the observer's q = 15/(2·T_so) (eq. (17) in [1]),
    3/T_sα (eq. (13)) or 3/T_si (eq. (8)). At the paper's T_so = 0.2 ms this gives 5 µs, where
    halving the step changes the friction energy by < 0.05 % (tests); a faster observer or inner
    loop gets a proportionally smaller step instead of a diverging integration.
    """
    c = params.controller
    lam = max(15.0 / (2.0 * c.T_so), 3.0 / c.T_salpha, 3.0 / c.T_si)
    return min(h_max, CONTINUOUS_STEP_RATIO / lam)


def plant_substeps(params: DriveParams) -> int:
    """Return the RK4 substeps per sample [-] that keep the plant step short enough.

    The plant step is ≤ PLANT_STEP_MAX_S and ≤ 0.2 rad of the fastest electrical angle
    p·max(ω_b, 2.1·|θ_dem|/T_m) (the comparator peaks at Δθ·5.6/(e·T_m)); 1 at 20 kHz for the paper's motor.
    """
    m = params.motor
    w_e = m.p * max(m.omega_b, 2.1 * abs(params.manoeuvre.theta_dem) / params.manoeuvre.T_m)
    h_max = min(PLANT_STEP_MAX_S, 0.2 / w_e)
    return max(1, int(math.ceil(1.0 / (float(params.controller.f_s) * h_max) - 1e-9)))


def time_grid(params: DriveParams, n_sub: int, h_continuous: float, max_points: int) -> TimeGrid:
    """Time grid of one run over [0, (1 + TAIL_FRACTION)·T_m]: step, substeps, decimation, points kept."""
    t_end = (1.0 + TAIL_FRACTION) * params.manoeuvre.T_m
    ctrl = params.controller
    if ctrl.is_continuous:
        h_continuous = continuous_step(params, h_continuous)
        n_steps, h, sub = int(math.ceil(t_end / h_continuous)), h_continuous, 1
    else:
        T_s = 1.0 / float(ctrl.f_s)
        sub = max(n_sub, plant_substeps(params))
        n_steps, h = int(math.ceil(t_end / T_s)), T_s / sub
    decim = max(1, int(math.ceil(n_steps / max_points)))
    return TimeGrid(ctrl.is_continuous, h, n_steps, sub, decim, n_steps // decim + 1)


def window_samples(params: DriveParams, g: TimeGrid) -> tuple[int, int]:
    """Return (samples analysed, longest window) of one run's two full-resolution chatter windows [-].

    The cruise window lies within [0.2·T_m, T_m] and the hold window within the tail after
    T_m + 0.5·TAIL_FRACTION·T_m, each ≤ CHATTER_MAX_WINDOW_S (:func:`sim.fdsmc.metrics.chatter_windows`).
    """
    T_step, T_m = g.h * g.n_sub, params.manoeuvre.T_m
    cruise = min(CHATTER_MAX_WINDOW_S, 0.8 * T_m)
    hold = min(CHATTER_MAX_WINDOW_S, 0.5 * TAIL_FRACTION * T_m)
    n_cruise, n_hold = (min(g.n_steps, int(w / T_step) + 2) for w in (cruise, hold))
    return n_cruise + n_hold, max(n_cruise, n_hold)


def run_cost(params: DriveParams, n_sub: int = 1, h_continuous: float = CONTINUOUS_STEP_S,
             max_points: int = MAX_POINTS, n_runs: int = 1) -> budget.Cost:
    """Cost of ``n_runs`` runs of one controller, from the parameters alone.

    Integration steps and trace bytes (the kernel's output, N_CH channels × kept points, and the
    chatter-window buffer, WIN_ROWS rows per window × the longer window, 8 bytes per value), and the predicted CPU
    seconds and peak memory of :func:`sim.common.budget.cpu_seconds` / ``memory_bytes``.
    """
    g = time_grid(params, int(n_sub), float(h_continuous), int(max_points))
    analysed, longest = window_samples(params, g)
    steps, samples, window = n_runs * g.n_steps * g.n_sub, n_runs * g.n_steps, n_runs * analysed
    trace = n_runs * 8 * (lay.N_CH * g.n_out + 2 * kn.WIN_ROWS * longest)
    return budget.Cost(steps, trace, budget.cpu_seconds(steps, samples, window, n_runs),
                       budget.memory_bytes(trace, window, n_runs, samples))


def predict(params: DriveParams, n_runs: int = 1, **options: Any) -> budget.Cost:
    """Predicted cost (steps, trace bytes, CPU seconds, peak memory) of ``n_runs`` runs of ``params``."""
    return run_cost(params, n_runs=n_runs, **options)


def with_field(params: DriveParams, field: str, value: float) -> DriveParams:
    """Return ``params`` with ``field`` (``"section.name"``) set to ``value``."""
    section, name = field.split(".")
    part = dataclasses.replace(getattr(params, section), **{name: value})
    return dataclasses.replace(params, **{section: part})


def _cost_drivers(params: DriveParams, request: Callable[[DriveParams], budget.Cost]) -> list[budget.Driver]:
    """Return the fields that set the step count and trace size, with the end of their range that is cheapest."""
    ctrl, m = params.controller, params.motor
    fields: list[tuple[str, float, str, float, bool]] = [("manoeuvre.T_m", params.manoeuvre.T_m, "s", 1e-4, False)]
    if ctrl.is_continuous:
        fields.append(("controller.T_so", ctrl.T_so, "s", 10.0, False))
    else:
        fields.append(("controller.f_s", float(ctrl.f_s), "Hz", 100.0, False))
        if plant_substeps(params) > 1:
            fields += [("motor.omega_b", m.omega_b, "rad/s", 1e-3, False), ("motor.p", m.p, "", 1, True)]
    return [budget.Driver(name, value, unit, _field_cost(request, params, name), limit, integer)
            for name, value, unit, limit, integer in fields]


def _field_cost(request: Callable[[DriveParams], budget.Cost], params: DriveParams,
                field: str) -> Callable[[float], budget.Cost]:
    """Return the cost of ``params`` as a function of the value of ``field`` (``"section.name"``)."""
    def cost(value: float) -> budget.Cost:
        return request(with_field(params, field, value))
    return cost


def check_budget(params: DriveParams, n_runs: int = 1, **options: Any) -> budget.Cost:
    """Raise :class:`~sim.common.budget.BudgetError` unless ``n_runs`` runs of ``params`` fit the budget.

    Called before any derivation or allocation by :func:`simulate`, :func:`compare` and
    :func:`table1_sweep` (which checks the whole sweep).
    """
    def request(p: DriveParams) -> budget.Cost:
        return run_cost(p, n_runs=n_runs, **options)

    cost = request(params)
    if cost.fits:
        return cost
    g = time_grid(params, int(options.get("n_sub", 1)), float(options.get("h_continuous", CONTINUOUS_STEP_S)),
              int(options.get("max_points", MAX_POINTS)))
    what = (f"{n_runs} run(s) × {g.n_steps:.3g} RK4 steps of {g.h:.3g} s" if g.continuous else
            f"{n_runs} run(s) × {g.n_steps:.3g} samples × {g.n_sub} sub-steps")
    return budget.check(cost, what, _cost_drivers(params, request))


def load_steps(params: DriveParams) -> tuple[np.ndarray, np.ndarray]:
    """Return the times [s] and values [N·m] of the external load-torque steps, as the kernel takes them."""
    steps = params.load.steps
    return (np.array([s.t for s in steps], dtype=float),
            np.array([s.Gamma_Le for s in steps], dtype=float))
