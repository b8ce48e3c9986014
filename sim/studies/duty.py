"""Duty cycles: a sequence of moves with dwell times, simulated back to back as one run.

Each comparator (FDSMC, conventional, the tracked minimum-energy optimum) drives the whole cycle
in one continuous simulation (:func:`sim.studies.cycle_kernel.run_cycle`): a move starts where
the previous move and its dwell left the drive — position, speed, currents, the observer's
estimates — not from rest. Move i lasts T_m,i + dwell_i; its θ_dem is relative (the target is
the previous target plus θ_dem,i) and its design (profile, gains, reference) is that of a single
move of θ_dem,i in T_m,i on the preset's drive. The energy of a move is the net electrical input
over its segment; the cycle's energy is their sum, which is the run's own integral, and the
run's energy balance (input = copper + friction + load work + the stored kinetic and magnetic
energy at the end) is reported. A constant external load held during a dwell costs what the
simulation says (the copper loss of the holding current).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.optimum import OptimumSolverError
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.common.economics import J_PER_KWH, cost_per_year, kwh_per_year  # noqa: F401 - J_PER_KWH re-exported
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.engine import optimum_omitted
from pmsm_commissioning.sim.fdsmc.grid import continuous_step, plant_substeps
from pmsm_commissioning.sim.fdsmc.metrics import kinetic_energy, magnetic_energy
from pmsm_commissioning.sim.fdsmc.run import pack_parameters
from pmsm_commissioning.sim.fdsmc.summary import decode_state
from pmsm_commissioning.sim.studies.cycle_kernel import run_cycle

COMPARATORS = ("fdsmc", "conventional", "optimum")
#: Most trace points kept per comparator's run [-].
TRACE_POINTS = 4000
#: Most integration steps of one comparator's cycle [-] (≈ 20 s of CPU).
MAX_CYCLE_STEPS = 40_000_000


@dataclass(frozen=True)
class Move:
    """One move of the cycle: theta_dem [rad] (relative), T_m [s], dwell after it [s]."""

    theta_dem: float
    T_m: float
    dwell: float = 0.0


@dataclass(frozen=True)
class CycleRun:
    """One comparator's cycle.

    Per-move net electrical input [J], the run's totals [J] (electrical in, copper, friction, load
    work, stored kinetic + magnetic at the end), the final position error against the last target
    [rad], a trace (t [s], theta_r [rad], omega_r [rad/s], E_electrical [J]) and ``stable``
    (False: diverged; then the energies are None).
    """

    moves_J: tuple[float, ...] | None
    electrical_in_J: float | None
    copper_J: float | None
    friction_J: float | None
    load_work_J: float | None
    stored_end_J: float | None
    theta_error_end_rad: float | None
    trace: dict[str, np.ndarray]
    stable: bool

    @property
    def balance_residual_J(self) -> float | None:
        """Electrical input − (copper + friction + load work + stored at the end) [J]."""
        if not self.stable:
            return None
        return self.electrical_in_J - (self.copper_J + self.friction_J + self.load_work_J  # type: ignore[operator]
                                       + self.stored_end_J)


@dataclass(frozen=True)
class DutyResult:
    """A duty cycle's energies.

    Energy per cycle [J] per comparator (None if its run diverged), the cycle time [s], the
    per-move energies ``moves[i][comparator]`` [J], each comparator's run and ``notes`` (one line
    each: a comparator left out, e.g. an optimum no solver could find).
    """

    cycle_J: dict[str, float | None]
    cycle_s: float
    moves: tuple[dict[str, float | None], ...]
    runs: dict[str, CycleRun]
    notes: tuple[str, ...] = ()

    def per_year(self, cycles_per_hour: float, hours_per_year: float, price_per_kWh: float
                 ) -> dict[str, tuple[float, float] | None]:
        """(kWh per year, cost per year [currency]) per comparator."""
        out: dict[str, tuple[float, float] | None] = {}
        for c, w in self.cycle_J.items():
            kwh = None if w is None else kwh_per_year(w, cycles_per_hour, hours_per_year)
            out[c] = None if kwh is None else (kwh, cost_per_year(kwh, price_per_kWh))
        return out


def _designs(params: DriveParams, moves: Sequence[Move]) -> list[tuple[DriveParams, Derived]]:
    """Each move's case (the preset with its θ_dem and T_m) and design; bad moves named."""
    if not moves:
        raise ParameterError("moves: allowed at least one move")
    out = []
    for i, mv in enumerate(moves):
        if not (math.isfinite(mv.dwell) and mv.dwell >= 0.0):
            raise ParameterError(f"move {i + 1}: dwell = {mv.dwell:g} s is not allowed: ≥ 0 s")
        p = dataclasses.replace(params, manoeuvre=dataclasses.replace(
            params.manoeuvre, theta_dem=float(mv.theta_dem), T_m=float(mv.T_m)))
        d = derive(p)
        if not d.profile.feasible:
            raise ParameterError(f"move {i + 1}: T_m = {mv.T_m:g} s is infeasible: allowed ≥ T_m,min = "
                                 f"{d.profile.T_m_min:.4g} s for Δθ = {mv.theta_dem:g} rad")
        out.append((p, d))
    return out


def _segments(params: DriveParams, moves: Sequence[Move]) -> tuple[bool, float, int, np.ndarray]:
    """(continuous, RK4 step h [s], substeps per sample, steps per segment) of the cycle."""
    ctrl = params.controller
    if ctrl.is_continuous:
        if params.load.steps or params.load.Gamma_Le_ramp != 0.0:
            raise ParameterError("load.steps / load.Gamma_Le_ramp with controller.f_s = continuous are not "
                                 "allowed in a duty cycle: allowed a digital f_s, or a constant Γ_Le")
        h, sub, T_step = continuous_step(params), 1, continuous_step(params)
    else:
        T_s = 1.0 / float(ctrl.f_s)
        sub = max(plant_substeps(dataclasses.replace(params, manoeuvre=dataclasses.replace(
            params.manoeuvre, theta_dem=float(m.theta_dem), T_m=float(m.T_m)))) for m in moves)
        h, T_step = T_s / sub, T_s
    steps = np.array([max(1, round((m.T_m + m.dwell) / T_step)) for m in moves], dtype=np.int64)
    if int(steps.sum()) * sub > MAX_CYCLE_STEPS:
        raise ParameterError(f"the cycle of {sum(m.T_m + m.dwell for m in moves):g} s needs "
                             f"{int(steps.sum()) * sub:.3g} integration steps: allowed ≤ {MAX_CYCLE_STEPS:.3g} "
                             "(shorter dwells or fewer moves, or a lower controller.f_s)")
    return ctrl.is_continuous, h, sub, steps


def _pack(cases: list[tuple[DriveParams, Derived]], moves: Sequence[Move], controller: str
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-segment parameters (absolute targets) and the concatenated references with offsets."""
    from pmsm_commissioning.control.fdsmc.optimum import tracked_move  # cvxpy only where a limit is active

    prm_all, refs, start = [], [], 0.0
    for (p, d), mv in zip(cases, moves, strict=True):
        prm = pack_parameters(p, d, controller)
        prm[lay.P_THDEM] = start + mv.theta_dem
        if controller == "optimum":
            tm = tracked_move(d)
            refs.append(np.vstack((start + tm.theta, tm.omega, tm.alpha)))
        else:
            refs.append(np.zeros((3, 2)))
        prm_all.append(prm)
        start += mv.theta_dem
    off = np.cumsum([0] + [r.shape[1] for r in refs]).astype(np.int64)
    return np.ascontiguousarray(prm_all), np.ascontiguousarray(np.hstack(refs)), off


def cycle_run(params: DriveParams, moves: Sequence[Move], controller: str) -> CycleRun:
    """One comparator's back-to-back run of the cycle (module docstring)."""
    cases = _designs(params, moves)
    continuous, h, sub, steps = _segments(params, moves)
    prm_all, ref_all, off = _pack(cases, moves, controller)
    od = cases[0][1].observer_discrete
    Phi, Gam, Lo = ((np.ascontiguousarray(od.Phi), np.ascontiguousarray(od.Gamma), np.ascontiguousarray(od.L))
                    if od is not None else (np.zeros((4, 4)), np.zeros(4), np.zeros(4)))
    step_t = np.array([s.t for s in params.load.steps], dtype=float)
    step_v = np.array([s.Gamma_Le for s in params.load.steps], dtype=float)
    total = int(steps.sum())
    decim = max(1, math.ceil(total / TRACE_POINTS))
    out = np.zeros((lay.N_CH, total // decim + 1))
    seg = np.zeros((len(moves), lay.N_X))
    n = run_cycle(prm_all, steps, ref_all, off, step_t, step_v, Phi, Gam, Lo, continuous, h, sub,
                  params.controller.delay_samples, decim, out, seg, sensors.noise_table(params.sensors))
    chans = {name: out[lay.CHANNELS.index(name), : abs(n) - (1 if n < 0 else 0)]
             for name in ("t", "theta_r", "omega_r", "E_electrical")}
    if n < 0:
        return CycleRun(None, None, None, None, None, None, None, chans, False)
    e_el = np.concatenate(([0.0], seg[:, lay.X_EEL]))
    end = decode_state(seg[-1])
    stored = kinetic_energy(params, end) + magnetic_energy(params, end)
    return CycleRun(tuple(float(x) for x in np.diff(e_el)), float(end.E_electrical), float(end.E_copper),
                    float(end.E_friction), float(end.E_load), float(stored),
                    float(end.theta_r - sum(mv.theta_dem for mv in moves)), chans, True)


def duty_cycle(params: DriveParams, moves: Sequence[Move]) -> DutyResult:
    """Simulate the cycle back to back with each comparator (module docstring).

    Raises
    ------
    ParameterError
        For an empty cycle, a negative dwell or an infeasible move (naming the move), or a
        cycle beyond the step budget.
    """
    runs: dict[str, CycleRun] = {}
    notes: list[str] = []
    for c in COMPARATORS:
        try:
            runs[c] = cycle_run(params, moves, c)
        except OptimumSolverError as exc:  # the optimum is a yardstick: left out with a note, never a stop
            notes.append(optimum_omitted(exc))
    per_move = tuple({c: (r.moves_J[i] if r.moves_J is not None else None) for c, r in runs.items()}
                     for i in range(len(moves)))
    total = {c: r.electrical_in_J for c, r in runs.items()}
    return DutyResult(total, float(sum(m.T_m + m.dwell for m in moves)), per_move, runs, tuple(notes))
