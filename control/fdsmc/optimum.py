"""The true minimum-energy rest-to-rest move: closed form without limits, convex QP with them.

Problem. Move the rotor by Δθ in T_m from rest to rest, J·dω/dt = Γ_em − F_v·ω − Γ_Le (eq. (4b)
in [1], J = J_r + J_L), and minimise the energy the drive draws over [0, T_m]:

    W = ∫ (a·Γ_em² + F_v·ω² + Γ_Le·ω) dt,   a = (3/2)·R_s / k_t²,   k_t = (3/2)·p·Ψ_PM,

i.e. copper loss (3/2)·R_s·i_q² at i_d = 0 (i_d ≠ 0 only adds loss on a non-salient motor; the
reluctance torque of a salient one is not used), friction and the external load's work. The
kinetic energy is zero at both ends, so W is also the net electrical input. The losses are
quadratic and the mechanics linear: a convex problem.

Closed form (no active limit, Γ_Le constant). With Γ = Γ_em − Γ_Le = J·ω' + F_v·ω,
∫a·(Γ + Γ_Le)² = ∫a·Γ² + 2·a·Γ_Le·F_v·Δθ + a·Γ_Le²·T_m (∫Γ = J·[ω] + F_v·Δθ), so a constant load
does not change the optimal trajectory. The Hamiltonian of min ∫(a·Γ² + F_v·ω²) with states
(θ, ω) and costates (λ1, λ2) gives Γ = −λ2/(2·a·J), λ1 constant and the linear system
z' = M·z, z = (θ, ω, λ1, λ2) (:func:`hamiltonian_matrix`); the two-point conditions
θ(0) = ω(0) = ω(T) = 0, θ(T) = Δθ fix λ(0) through the matrix exponential e^(M·T). Its
eigenvalues are ±μ, ±0 with

    μ² = (F_v/J)² + F_v/(a·J²),

and for real drives μ·T_m reaches 50–100, so e^(M·T) (≈ e^(μT)) is far too ill-conditioned to
shoot with. Eliminating the costates gives the same solution in a stable form: the Euler–Lagrange
equation of ∫(a·(J·ω' + F_v·ω)² + F_v·ω² − ν·ω) is ω'' − μ²·ω = const, whose symmetric solution
with ω(0) = ω(T) = 0 is

    ω(t) = C·(1 − cosh(μ·(t − T/2)) / cosh(μ·T/2)),   C = Δθ / (T − (2/μ)·tanh(μ·T/2)),

(ω = 6·Δθ·t·(T − t)/T³ when F_v → 0). With th = tanh(μT/2) and s2 = sech²(μT/2):
∫ω'² = C²·μ²·(th/μ − T·s2/2), ∫ω² = C²·(T − 3·th/μ + T·s2/2), and since ∫ω·ω' = 0,
∫a·Γ² = a·J²·∫ω'² + a·F_v²·∫ω².

Numerical optimum (limits). Γ_em piecewise constant on N intervals, the mechanics discretised
exactly (zero-order hold), |Γ_em| ≤ Γ_lim (the drive's torque limit including the inverter's
i_max), solved as a QP by Clarabel through cvxpy (SCS when Clarabel fails).

Voltage limit. With a DC link (controller.V_dc > 0) the inverter applies |u_dq| ≤ u_max = V_dc/√3.
At i_d = 0 in the steady state of each interval, eqs. (1)–(2) in [1] give

    u_d = −p·ω·L_q·i_q,   u_q = R_s·i_q + p·Ψ_PM·ω,   i_q = Γ_em/k_t,

so ‖(u_d, u_q)‖ ≤ u_max is a second-order cone once the product ω·i_q of u_d is taken with ω
fixed: the problem is solved as a sequence of SOCPs (Clarabel), u_d's ω taken from the previous
solution (the first from the problem without the voltage limit), until the speed changes by less
than 1e-6 of its peak; the result is then checked against the exact |u_dq| ≤ u_max (both
interval ends' speeds). L_q·di_q/dt is not in the limit (the inner loops shape the current
within T_si ≪ T_m), nor is any voltage the inner loops need for tracking.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.model import torque_constant
from pmsm_commissioning.control.fdsmc.params import DriveParams

if TYPE_CHECKING:  # cvxpy is imported where an optimum is asked for (a heavy import)
    import cvxpy as cp

    #: The convex problem of :func:`_problem`: (problem, g = Γ_em/G_s, v = ω/w_s, the speed parameter of u_d,
    #: G_s [N·m], w_s [rad/s]).
    ConvexMove = tuple[cp.Problem, cp.Variable, cp.Variable, cp.Parameter, float, float]

#: Default number of QP intervals over [0, T_m] [-].
N_INTERVALS = 2000


@dataclass(frozen=True)
class MoveModel:
    """The move's data.

    J [kg·m²]; F_v [N·m·s/rad]; a [W/(N·m)²] copper coefficient; delta_theta [rad]; T_m [s];
    Gamma_lim [N·m] torque limit (inf = none); Gamma_Le [N·m] constant load; u_max [V] limit of
    |u_dq| (inf = none) with the motor's R_s [Ω], L_q [H], p [-], psi_pm [Wb].
    """

    J: float
    F_v: float
    a: float
    delta_theta: float
    T_m: float
    Gamma_lim: float = math.inf
    Gamma_Le: float = 0.0
    u_max: float = math.inf
    R_s: float = 0.0
    L_q: float = 0.0
    p: int = 1
    psi_pm: float = 1.0

    @property
    def k_t(self) -> float:
        """Torque constant (3/2)·p·Ψ_PM [N·m/A] (eq. (5) in [1] at i_d = 0)."""
        return 1.5 * self.p * self.psi_pm


@dataclass(frozen=True)
class OptimalMove:
    """An optimal move on the grid t [s] (N + 1 nodes).

    theta [rad], omega [rad/s], alpha [rad/s²] (dω/dt), Gamma_em [N·m]; energies over [0, T_m]
    [J]; torque_peak [N·m]; limited (a limit is active); method ("closed form" or the solver's name).
    """

    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    Gamma_em: np.ndarray
    copper_J: float
    friction_J: float
    load_J: float
    torque_peak: float
    limited: bool
    method: str

    @property
    def energy_J(self) -> float:
        """Energy drawn over the move, copper + friction + load [J]."""
        return self.copper_J + self.friction_J + self.load_J


def move_model(params: DriveParams, margin: float = 1.0) -> MoveModel:
    """Return the move of ``params`` with the torque limit divided by ``margin`` ≥ 1 [-].

    The margin leaves room for the inner loops' overshoot when the optimum is tracked.
    """
    from pmsm_commissioning.control.fdsmc.feasibility import torque_limit  # local: feasibility imports the profile

    m, ld, mv = params.motor, params.load, params.manoeuvre
    k_t = torque_constant(m)
    V_dc = params.controller.V_dc
    u_max = V_dc / math.sqrt(3.0) if V_dc > 0.0 else math.inf
    return MoveModel(params.J_total, ld.F_v, 1.5 * m.R_s / k_t**2, mv.theta_dem, mv.T_m,
                     torque_limit(params) / max(1.0, margin), ld.Gamma_Le, u_max, m.R_s, m.L_q, m.p, m.psi_pm)


def voltage_peak(mm: MoveModel, mv: OptimalMove) -> float:
    """Return the largest steady-state |u_dq| [V] of a move at i_d = 0 (module docstring).

    Over the nodes: each interval's torque with the speed at both of its ends.
    """
    i_q = mv.Gamma_em / mm.k_t
    u = 0.0
    for w in (mv.omega, np.append(mv.omega[1:], mv.omega[-1])):
        u_d, u_q = mm.p * w * mm.L_q * i_q, mm.R_s * i_q + mm.p * mm.psi_pm * w
        u = max(u, float(np.max(np.hypot(u_d, u_q))))
    return u


def hamiltonian_matrix(mm: MoveModel) -> np.ndarray:
    """M of z' = M·z, z = (θ, ω, λ1, λ2), for min ∫(a·Γ² + F_v·ω²) with J·ω' = Γ − F_v·ω [SI]."""
    J, F, a = mm.J, mm.F_v, mm.a
    return np.array([[0.0, 1.0, 0.0, 0.0],
                     [0.0, -F / J, 0.0, -1.0 / (2.0 * a * J * J)],
                     [0.0, 0.0, 0.0, 0.0],
                     [0.0, -2.0 * F, -1.0, F / J]])


def mu(mm: MoveModel) -> float:
    """μ [1/s], the positive eigenvalue of :func:`hamiltonian_matrix`: μ² = (F_v/J)² + F_v/(a·J²)."""
    return math.sqrt((mm.F_v / mm.J) ** 2 + mm.F_v / (mm.a * mm.J**2))


def closed_form(mm: MoveModel, n: int = N_INTERVALS) -> OptimalMove:
    """Return the unconstrained optimum of the module docstring on n + 1 nodes (Γ_Le constant)."""
    T, dth, m_ = mm.T_m, mm.delta_theta, mu(mm)
    t = np.linspace(0.0, T, n + 1)
    s = t - 0.5 * T
    if m_ * T < 1e-4:  # F_v → 0: the parabola
        C = 6.0 * dth / T**3
        omega, domega = C * t * (T - t), C * (T - 2.0 * t)
        theta = C * (0.5 * T * t**2 - t**3 / 3.0)
        int_w2, int_dw2 = 1.2 * dth**2 / T, 12.0 * dth**2 / T**3
    else:
        x = 0.5 * m_ * T
        th, s2 = math.tanh(x), 1.0 / math.cosh(x) ** 2 if x < 350.0 else 0.0
        C = dth / (T - 2.0 * th / m_)
        # cosh(μs)/cosh(x) and sinh(μs)/cosh(x) without overflow (|μs| ≤ x).
        e = np.exp(m_ * np.abs(s) - x)
        f, den = np.exp(-2.0 * m_ * np.abs(s)), 1.0 + math.exp(-2.0 * x)
        ch_r, sh_r = e * (1.0 + f) / den, np.sign(s) * e * (1.0 - f) / den
        omega, domega = C * (1.0 - ch_r), -C * m_ * sh_r
        theta = C * (t - (sh_r + th) / m_)
        int_dw2 = C**2 * m_**2 * (th / m_ - 0.5 * T * s2)
        int_w2 = C**2 * (T - 3.0 * th / m_ + 0.5 * T * s2)
    theta[-1] = dth  # the move ends on Δθ exactly (the terminal slide compares θ_ref with θ_dem there)
    G = mm.J * domega + mm.F_v * omega + mm.Gamma_Le
    copper = (mm.a * (mm.J**2 * int_dw2 + mm.F_v**2 * int_w2) + 2.0 * mm.a * mm.Gamma_Le * mm.F_v * dth
              + mm.a * mm.Gamma_Le**2 * T)
    peak = float(np.max(np.abs(G)))
    return OptimalMove(t, theta, omega, domega, G, float(copper), float(mm.F_v * int_w2),
                       float(mm.Gamma_Le * dth), peak, peak > mm.Gamma_lim, "closed form")


def _zoh(mm: MoveModel, h: float) -> tuple[float, float, float, float]:
    """Exact interval map: ω⁺ = e·ω + b·u, Δθ = c·ω + d·u for u = Γ_em − Γ_Le held over h [s]."""
    J, F = mm.J, mm.F_v
    if F * h / J < 1e-9:
        return 1.0, h / J, h, 0.5 * h * h / J
    e = math.exp(-F * h / J)
    c = J / F * (1.0 - e)
    return e, (1.0 - e) / F, c, (h - c) / F


#: Most SOCP solves of the voltage-limited optimum (sequential convex programming) [-].
MAX_VOLTAGE_ITERATIONS = 12
#: Converged when no node's speed changes by more than this share of the peak speed [-].
VOLTAGE_ITERATION_TOL = 1e-6


def _problem(mm: MoveModel, n: int, voltage: bool) -> ConvexMove:
    """Build the convex problem on n intervals.

    The QP of the module docstring, plus (``voltage``) the voltage cone with u_d's speed a
    parameter (n + 1 nodes, [rad/s]) so that re-solving with a new speed reuses the compiled
    problem. Returns (problem, g, v, speed parameter, G_s, w_s).
    """
    import cvxpy as cp  # heavy import, only when an optimum is asked for

    dth, h = mm.delta_theta, mm.T_m / n
    e, b, c, d = _zoh(mm, h)
    ref = closed_form(mm, 200)
    G_s, w_s = max(ref.torque_peak, 1e-12), max(float(np.max(np.abs(ref.omega))), 1e-12)
    g, v = cp.Variable(n), cp.Variable(n + 1)  # Γ_em/G_s, ω/w_s
    u = G_s * g - mm.Gamma_Le
    cons = [v[0] == 0.0, v[n] == 0.0,
            w_s * v[1:] == e * w_s * v[:-1] + b * u,
            cp.sum(c * w_s * v[:-1] + d * u) == dth]
    if math.isfinite(mm.Gamma_lim):
        cons.append(cp.abs(g) <= mm.Gamma_lim / G_s)
    w_ud = cp.Parameter(n + 1)  # p·L_q·ω/u_max·(G_s/k_t) of u_d: ω from the previous solve
    if voltage:
        i_q = (G_s / mm.k_t / mm.u_max) * g  # per unit of u_max below
        for ends in (slice(0, n), slice(1, n + 1)):  # both ends of each interval
            u_q = mm.R_s * i_q + (mm.p * mm.psi_pm * w_s / mm.u_max) * v[ends]
            cons.append(cp.norm(cp.vstack([cp.multiply(w_ud[ends], g), u_q]), 2, axis=0) <= 1.0)
    scale = max(ref.energy_J - ref.load_J, 1e-12)
    cost = (mm.a * h * G_s**2 * cp.sum_squares(g) + mm.F_v * h * w_s**2 * cp.sum_squares(v)) / scale
    return cp.Problem(cp.Minimize(cost), cons), g, v, w_ud, G_s, w_s


#: Solvers tried in turn for the QP/SOCP: Clarabel (interior point), then SCS (first-order splitting),
#: which also handles the voltage cone [-].
SOLVERS = ("CLARABEL", "SCS")


class OptimumSolverError(ParameterError):
    """Every solver of :data:`SOLVERS` failed on the optimum's problem (numerical trouble, not infeasibility)."""


def _solve(mm: MoveModel, n: int, problem: ConvexMove) -> OptimalMove:
    """Solve ``problem`` of :func:`_problem`, naming the limits if it is infeasible.

    The solvers of :data:`SOLVERS` are tried in turn; when each one fails numerically,
    :class:`OptimumSolverError` says so in one line.
    """
    import cvxpy as cp

    prob, g, v, _, G_s, w_s = problem
    failures: list[str] = []
    for solver in SOLVERS:
        try:
            prob.solve(solver=solver)
        except cp.error.SolverError:
            failures.append(f"{solver} failed")
            continue
        if prob.status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return _move(mm, n, G_s * np.asarray(g.value), w_s * np.asarray(v.value), solver.lower())
        if prob.status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
            break
        failures.append(f"{solver} status {prob.status}")
    else:
        raise OptimumSolverError(f"manoeuvre.T_m = {mm.T_m:g} s: the minimum-energy optimum could not be solved "
                            f"({'; '.join(failures)}); allowed: a move the solvers handle (a longer T_m or other "
                            "limits), else the optimum is left out")
    volt = f" and |u_dq| ≤ V_dc/√3 = {mm.u_max:.4g} V" if math.isfinite(mm.u_max) else ""
    raise ParameterError(
        f"manoeuvre.T_m = {mm.T_m:g} s: no move of Δθ = {mm.delta_theta:g} rad stays within the torque limit "
        f"{mm.Gamma_lim:.4g} N·m{volt} (solver status {prob.status}); allowed: a longer T_m"
        + (" or a larger controller.V_dc" if volt else ""))


def _move(mm: MoveModel, n: int, G: np.ndarray, omega: np.ndarray, solver: str) -> OptimalMove:
    """Return the OptimalMove of the solved torques G [N·m] (n) and speeds omega [rad/s] (n + 1)."""
    h = mm.T_m / n
    e, b, c, d = _zoh(mm, h)
    omega[0] = omega[-1] = 0.0
    dtheta = c * omega[:-1] + d * (G - mm.Gamma_Le)
    theta = np.concatenate(([0.0], np.cumsum(dtheta)))
    theta[-1] = mm.delta_theta  # the constraint's Δθ exactly, not the cumulative sum's rounding
    alpha = (np.append(G, G[-1]) - mm.F_v * omega - mm.Gamma_Le) / mm.J
    peak = float(np.max(np.abs(G)))
    return OptimalMove(np.linspace(0.0, mm.T_m, n + 1), theta, omega, alpha, np.append(G, G[-1]),
                       float(mm.a * h * np.sum(G**2)), float(mm.F_v * h * np.sum(omega**2)),
                       float(mm.Gamma_Le * np.sum(dtheta)),
                       peak, peak >= mm.Gamma_lim * (1.0 - 1e-6), solver)


def numerical_optimum(mm: MoveModel, n: int = N_INTERVALS) -> OptimalMove:
    """Solve for the optimum within the torque and voltage limits on n intervals.

    |Γ_em| ≤ Γ_lim (a QP) and, if u_max is finite, |u_dq| ≤ u_max (a sequence of SOCPs, module
    docstring), solved by Clarabel via cvxpy, else SCS (:data:`SOLVERS`).

    Raises
    ------
    ParameterError
        When no move within the limits reaches Δθ in T_m (naming the limits), or when the
        voltage iteration does not converge.
    """
    mv = _solve(mm, n, _problem(mm, n, False))
    if not math.isfinite(mm.u_max) or voltage_peak(mm, mv) <= mm.u_max:
        return mv
    problem = _problem(mm, n, True)
    for _ in range(MAX_VOLTAGE_ITERATIONS):
        problem[3].value = mm.p * mm.L_q * mv.omega / mm.u_max * problem[4] / mm.k_t
        new = _solve(mm, n, problem)
        step = float(np.max(np.abs(new.omega - mv.omega)))
        mv = dataclasses.replace(new, limited=True)
        if step <= VOLTAGE_ITERATION_TOL * float(np.max(np.abs(mv.omega))):
            return mv
    raise ParameterError(
        f"controller.V_dc = {mm.u_max * math.sqrt(3.0):g} V: the voltage-limited optimum of manoeuvre.T_m = "
        f"{mm.T_m:g} s did not converge in {MAX_VOLTAGE_ITERATIONS} iterations; allowed: a longer T_m")


def optimal_move(params: DriveParams, margin: float = 1.0, n: int = N_INTERVALS) -> OptimalMove:
    """Return the minimum-energy move of ``params`` within the limits (torque limit / ``margin``).

    See :func:`move_model`: the closed form where no limit is active, else the QP/SOCP.
    """
    return _optimum(move_model(params, margin), n)


def _optimum(mm: MoveModel, n: int) -> OptimalMove:
    """Return the closed form where it respects the torque and voltage limits, else the numerical one."""
    cf = closed_form(mm, n)
    if cf.torque_peak <= mm.Gamma_lim and (not math.isfinite(mm.u_max) or voltage_peak(mm, cf) <= mm.u_max):
        return cf
    return numerical_optimum(mm, n)


def tracked_move(d: Derived, n: int = N_INTERVALS) -> OptimalMove:
    """Return the optimum the closed-loop simulation tracks for the derived case ``d``.

    Its torque limit is the drive's (Γ_max or i_max's torque), or the FDSMC's own planned peak
    torque when that is larger (the paper's section-5 drive plans beyond Γ_max: the optimum is
    never held to a tighter limit than the controller it is compared with), divided by the
    inner loops' acceleration overshoot η so that tracking it stays within the limit.
    """
    from pmsm_commissioning.control.fdsmc.feasibility import torque_limit

    p = d.params
    lim = max(torque_limit(p), d.feasibility.torque_needed)
    mm = dataclasses.replace(move_model(p), Gamma_lim=lim / max(1.0, d.alpha.overshoot))
    return _optimum(mm, n)
