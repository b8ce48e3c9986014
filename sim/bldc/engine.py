"""BLDC speed-drive simulation: one run, and the comparison of the speed drives of [2] and their comparators.

Mirrors :mod:`sim.fdsmc.engine` (Trace / RunResult / Comparison shapes): :func:`simulate_bldc`
returns a :class:`BldcRunResult` (controller, trace, metrics); :func:`compare_bldc` a
:class:`BldcComparison` with the runs in the order of ``controllers``.

Controllers:

* ``smc_integral`` — the paper's drive [2]: dq_x (ideal a_x, θ_x) + tanh current SMC
  (eqs. (13)–(14)) + integral sliding surface with anti-windup (eqs. (15)–(16));
* ``smc_plain`` — the same without the integral term (σ_ω = ε_ω);
* ``pi_sinusoidal`` — conventional sinusoidal dq vector control with PI loops;
* ``six_step`` — 120° square-wave current commutation from θ_e (Fig. 1 of [2]) with the paper's
  integral speed surface, I* = T*/(2·n_pp·Φ_M) (:mod:`control.bldc.six_step`).

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.bldc.design import BldcDesign, bldc_design
from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.control.bldc.speed_smc import NO_ANTI_WINDUP
from pmsm_commissioning.sim.bldc import kernel as kn
from pmsm_commissioning.sim.bldc.emf import machine_table
from pmsm_commissioning.sim.bldc.metrics import BldcMetrics, run_metrics
from pmsm_commissioning.sim.bldc.trace import BldcTrace
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.common.choices import check_controller

CONTROLLERS = ("smc_integral", "smc_plain", "pi_sinusoidal", "six_step")
LABELS = {
    "smc_integral": "dq_x + SMC, integral surface (paper)",
    "smc_plain": "dq_x + SMC, plain tanh (no integral)",
    "pi_sinusoidal": "sinusoidal dq + PI",
    "six_step": "six-step 120° commutation + integral surface",
}
#: RK4 steps per controller sample [-]: at 20 kHz, 1 step (h = 50 µs, ω_e·h ≤ 0.03 rad at
#: 2000 rpm) gives the same metrics as 4 steps to < 1e-3 relative (tests/test_bldc_model.py).
N_SUB = 1


@dataclass(frozen=True)
class BldcRunResult:
    """One controller's run: trace and metrics."""

    controller: str
    trace: BldcTrace
    metrics: BldcMetrics


@dataclass(frozen=True)
class BldcComparison:
    """Runs of several drives on the same machine, back-EMF and scenario.

    Attributes
    ----------
    params : BldcParams        The case.
    design : BldcDesign        Derived values and warnings.
    table : numpy.ndarray      The machine's Φ'_ra table [Wb] (one period).
    runs : tuple               :class:`BldcRunResult` in the requested order.
    wall_s : float             Wall-clock time of the simulations [s].
    anti_windup : bool         The integral surfaces had the anti-windup λ(ε) of eq. (16) (else λ = λ_0).
    """

    params: BldcParams
    design: BldcDesign
    table: np.ndarray
    runs: tuple[BldcRunResult, ...]
    wall_s: float
    anti_windup: bool = True

    def run(self, controller: str) -> BldcRunResult:
        """Return the run of ``controller``."""
        return next(r for r in self.runs if r.controller == controller)


def pack_parameters(params: BldcParams, design: BldcDesign, controller: str, anti_windup: bool = True) -> np.ndarray:
    """Return the kernel's flat parameter vector (indices ``P_*`` of :mod:`sim.bldc.kernel`).

    Without ``anti_windup`` the integral surfaces run with λ = λ_0 (ε_λ = :data:`NO_ANTI_WINDUP`);
    ``params`` keeps its ε_λ.
    """
    m, mech, g, inv, case = params.machine, params.mechanics, params.gains, params.inverter, params.case
    prm = kn.PRM.empty()
    prm[[kn.P_R, kn.P_L, kn.P_NPP, kn.P_PHIM, kn.P_J, kn.P_B]] = (
        m.R_s, m.L_s_minus_M_s, m.n_pp, m.Phi_m, mech.J, mech.B)
    prm[[kn.P_VDC, kn.P_TS, kn.P_KI, kn.P_KW, kn.P_TMAX, kn.P_LAM0, kn.P_EPSL]] = (
        inv.V_dc, 1.0 / inv.f_s, g.k_I, g.k_omega, g.T_max, g.lambda_0,
        g.eps_lambda if anti_windup else NO_ANTI_WINDUP)
    prm[[kn.P_WREF, kn.P_W0]] = (case.omega_ref, case.omega_0)
    pi = design.pi
    prm[[kn.P_KPW, kn.P_KIW, kn.P_KPI, kn.P_KII]] = (pi.K_p_w, pi.K_i_w, pi.K_p_i, pi.K_i_i)
    K_T = {"pi_sinusoidal": pi.K_T, "six_step": design.K_T_fig7}
    prm[kn.P_KTS] = K_T.get(controller, design.K_Tx)
    prm[kn.P_CTRL] = CONTROLLERS.index(controller)
    kn.PRM.check_filled(prm)
    return prm


#: Bytes of trace memory per recorded sample and controller: the kernel's record row (N_CH
#: doubles), the trace's contiguous copies of it and the derived rows (ω*, i_abc, v_phase and
#: its temporary, E_kin, E_mag) [B].
TRACE_BYTES_PER_SAMPLE = 8 * (2 * kn.N_CH + 12)
#: Cost model, fitted by ``scripts/bench_budget.py --bldc`` (compiled kernel, one thread per drive, CPU
#: summed): CPU seconds per RK4 sub-step beyond the first of a sample, per sample (its first step,
#: the controller, the record row, the trace and the metrics) and per run; the peak memory above
#: the idle process is the trace bytes times :data:`MEM_PER_TRACE_BYTE` plus :data:`MEM_PER_RUN` [B].
CPU_PER_STEP_S = 3.0e-7
CPU_PER_SAMPLE_S = 1.1e-6
CPU_PER_RUN_S = 0.002
MEM_PER_TRACE_BYTE = 1.0
MEM_PER_RUN = 1 * 2**20


def _cost(n_runs: int, n_ticks: int, n_sub: int) -> budget.Cost:
    """Cost of ``n_runs`` runs of ``n_ticks`` samples of ``n_sub`` RK4 steps: steps, bytes, CPU, memory."""
    trace = n_runs * (n_ticks + 1) * TRACE_BYTES_PER_SAMPLE
    cpu = n_runs * (CPU_PER_STEP_S * n_ticks * (n_sub - 1) + CPU_PER_SAMPLE_S * n_ticks + CPU_PER_RUN_S)
    return budget.Cost(n_runs * n_ticks * n_sub, trace, cpu, int(MEM_PER_TRACE_BYTE * trace + MEM_PER_RUN * n_runs))


def n_ticks_of(t_end: float, f_s: float) -> int:
    """Return the number of controller samples [-] of a run of ``t_end`` [s] at ``f_s`` [Hz]."""
    return int(math.ceil(t_end * f_s - 1e-9))


def run_cost(params: BldcParams, n_runs: int = 1, n_sub: int = N_SUB) -> budget.Cost:
    """Cost of ``n_runs`` runs of the active scenario (parameters only): see :func:`_cost`."""
    return _cost(n_runs, n_ticks_of(params.case.t_end, params.inverter.f_s), int(n_sub))


def check_budget(params: BldcParams, n_runs: int = 1, n_sub: int = N_SUB) -> budget.Cost:
    """Raise :class:`~sim.common.budget.BudgetError` unless ``n_runs`` runs fit the budget (before any work)."""
    cost = run_cost(params, n_runs, n_sub)
    if cost.fits:
        return cost
    case, f_s = params.case, params.inverter.f_s
    i = next(k for k, c in enumerate(params.scenario.cases) if c.name == case.name)

    def with_t_end(t_end: float) -> budget.Cost:
        return _cost(n_runs, n_ticks_of(t_end, f_s), n_sub)

    def with_f_s(rate: float) -> budget.Cost:
        return _cost(n_runs, n_ticks_of(case.t_end, rate), n_sub)

    drivers = [budget.Driver(f"scenario.cases[{i}].t_end", case.t_end, "s", with_t_end, 1e-6),
               budget.Driver("inverter.f_s", f_s, "Hz", with_f_s, 1e3)]
    what = f"{n_runs} controller(s) × {case.t_end:g} s at f_s = {f_s:g} Hz, scenario {case.name!r}"
    return budget.check(cost, what, drivers)


def simulate_bldc(params: BldcParams, controller: str = "smc_integral",
                  design: BldcDesign | None = None, table: np.ndarray | None = None,
                  n_sub: int = N_SUB, anti_windup: bool = True) -> BldcRunResult:
    """Simulate the active scenario with one drive.

    Parameters
    ----------
    params : BldcParams     The case.
    controller : str        One of :data:`CONTROLLERS`.
    design : BldcDesign     ``bldc_design(params)`` if already computed.
    table : numpy.ndarray   The machine's Φ'_ra table [Wb]; default from ``params.machine``.
    n_sub : int             RK4 steps per sample [-].
    anti_windup : bool      λ(ε) of eq. (16) in the integral surfaces; False: λ = λ_0.

    Returns
    -------
    BldcRunResult
        Never raises for a diverging run: ``metrics.stable`` is False with a ``reason``.
    """
    check_controller(controller, CONTROLLERS)
    check_budget(params, 1, n_sub)
    d = bldc_design(params) if design is None else design
    tab = machine_table(params.machine) if table is None else np.ascontiguousarray(table, dtype=float)
    case = params.case
    n_ticks = n_ticks_of(case.t_end, params.inverter.f_s)
    rec = np.zeros((n_ticks + 1, kn.N_CH))
    step_t = np.array([s.t for s in case.T_L_steps], dtype=float)
    step_v = np.array([s.T_L for s in case.T_L_steps], dtype=float)
    rows = kn.run_kernel(pack_parameters(params, d, controller, anti_windup), tab, step_t, step_v,
                         float(case.T_L_0), n_ticks, int(n_sub), rec)
    trace = _trace(params, rec[: max(rows, 2)])
    return BldcRunResult(controller, trace, run_metrics(params, trace, diverged=rows <= n_ticks))


def anti_windup_pair(comp: BldcComparison) -> tuple[BldcRunResult, BldcRunResult]:
    """Return the paper's drive (``smc_integral``) with the anti-windup of eq. (16) and without.

    The comparison's own run serves for its setting; the other setting is simulated.
    """
    shown = comp.run("smc_integral")
    other = simulate_bldc(comp.params, "smc_integral", comp.design, comp.table, anti_windup=not comp.anti_windup)
    return (shown, other) if comp.anti_windup else (other, shown)


def _trace(params: BldcParams, rec: np.ndarray) -> BldcTrace:
    c = {name: np.ascontiguousarray(rec[:, i]) for i, name in enumerate(kn.CHANNELS)}
    m, mech = params.machine, params.mechanics
    i_abc = np.vstack([c["i_a"], c["i_b"], c["i_c"]])
    v_phase = np.vstack([c["v_a"], c["v_b"], c["v_c"]]) - c["v_n"]
    t, w = c["t"], c["omega"]
    return BldcTrace(
        t=t, omega=w, omega_ref=np.full_like(t, params.case.omega_ref), T_L=c["T_L"],
        T_EL=c["T_EL"], T_ref=c["T_ref"], sigma=c["sigma"], i_abc=i_abc, i_dx=c["i_dx"],
        i_qx=c["i_qx"], i_qx_ref=c["i_qx_ref"], v_phase=v_phase, theta_e=c["theta_e"],
        E_in=c["E_in"],
        E_copper=c["E_copper"], E_friction=c["E_friction"], E_load=c["E_load"],
        E_kin=0.5 * mech.J * (w**2 - w[0] ** 2),
        E_mag=0.5 * m.L_s_minus_M_s * np.sum(i_abc**2, axis=0),
    )


def compare_bldc(params: BldcParams, controllers: tuple[str, ...] = CONTROLLERS,
                 table: np.ndarray | None = None, anti_windup: bool = True) -> BldcComparison:
    """Simulate several drives on the same case (threads; the kernel is compiled numba code).

    Parameters
    ----------
    params : BldcParams            The case.
    controllers : tuple of str     Any of :data:`CONTROLLERS`.
    table : numpy.ndarray or None  Machine Φ'_ra table [Wb]; default from ``params.machine``.
    anti_windup : bool             λ(ε) of eq. (16) in the integral surfaces; False: λ = λ_0.
    """
    for c in controllers:
        check_controller(c, CONTROLLERS)
    check_budget(params, len(controllers))
    d = bldc_design(params)
    tab = machine_table(params.machine) if table is None else np.asarray(table, dtype=float)
    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=max(1, len(controllers))) as pool:
        futures = [pool.submit(simulate_bldc, params, c, d, tab, N_SUB, anti_windup) for c in controllers]
        runs = tuple(f.result() for f in futures)
    return BldcComparison(params, d, tab, runs, time.perf_counter() - t0, anti_windup)
