"""The linearised closed loop of the FDSMC drive as matrices: plant, FDC row, observer, sampling.

Around i_d = 0 (eq. (10) in [1]) with a constant external load the drive is linear in the states

    z = [i_q, θ_r, ω_r, θ̂_r, ω̂_r, L̂0, L̂1]   (+ the held voltage with a one-sample delay)

with the plant di_q/dt = −D·i_q − E·ω_r + G·u_q (eq. (2)), (J_r + J_L)·dω_r/dt = J_r·H·i_q −
F_v·ω_r (eq. (4b)), the FDC law u_q of eq. (14) (using ω̂_r, L̂0, L̂1), and the corrected
observer of eq. (15) — continuous, or the ZOH-exact discrete observer of
:func:`control.fdsmc.observer.discrete_observer` with the plant discretised exactly for held voltages.

:class:`LoopModel` and :class:`LoopCase` hold only the numbers these matrices are built from, so
two cases that differ elsewhere (T_m, K, the load steps …) compare and hash equal and
:mod:`control.fdsmc.loop_analysis` can reuse its verdicts for them. The sampled plant and observer
of one sample rate are cached the same way (one matrix exponential each per distinct model).
:func:`law_case` is the searches' cache key and :func:`geometric_bisect` their bisection, shared
by the stability limits (:mod:`control.fdsmc.loop_analysis`) and the sensors' noise limit
(:mod:`control.fdsmc.noise`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.common.arrays import FloatArray
from pmsm_commissioning.control.common.discrete import zoh
from pmsm_commissioning.control.fdsmc.model import ModelCoefficients
from pmsm_commissioning.control.fdsmc.observer import DiscreteObserver, ObserverGains, discrete_observer
from pmsm_commissioning.control.fdsmc.params import DriveParams

N_STATES = 7  # [i_q, θ, ω, θ̂, ω̂, L̂0, L̂1]


@dataclass(frozen=True)
class LoopModel:
    """What the linearised loop needs besides the outer law (hashable by value).

    Attributes
    ----------
    coefficients : ModelCoefficients  The controller's model, eqs. (1)–(3) in [1].
    observer : ObserverGains          Continuous observer gains, eq. (18).
    J_r : float       Rotor inertia [kg·m²].
    J_total : float   J_r + J_L, the user's estimate of the total inertia [kg·m²].
    F_v : float       Viscous friction [N·m·s/rad].
    T_si : float      Current-loop settling time [s].
    T_salpha : float  Acceleration-loop settling time [s].
    T_so : float      Observer settling time [s].
    """

    coefficients: ModelCoefficients
    observer: ObserverGains
    J_r: float
    J_total: float
    F_v: float
    T_si: float
    T_salpha: float
    T_so: float

    @classmethod
    def of(cls, coefficients: ModelCoefficients, params: DriveParams, observer: ObserverGains) -> LoopModel:
        """Return the loop model of ``params`` with its model coefficients and observer gains."""
        c = params.controller
        return cls(coefficients, observer, params.motor.J_r, params.J_total, params.load.F_v, c.T_si,
                   c.T_salpha, c.T_so)

    def model(self) -> LoopModel:
        """Return this loop's :class:`LoopModel` alone (drops a case's outer-law numbers; a cache key)."""
        return LoopModel(self.coefficients, self.observer, self.J_r, self.J_total, self.F_v, self.T_si,
                         self.T_salpha, self.T_so)


@dataclass(frozen=True)
class LoopCase(LoopModel):
    """The linearised loop of one case with its outer laws and implementation.

    Attributes
    ----------
    alpha_max : float     α_max of eqs. (41), (45) in [1] [rad/s²].
    T_c : float           Sloped-segment time constant of eq. (41) [s].
    g1 : float            Conventional gain of eq. (61) [1/s²].
    g2 : float            Conventional gain of eq. (61) [1/s].
    f_s : float or None   Controller sample rate [Hz]; None: continuous implementation.
    delay : int           Computation delay [samples].
    K : float             The case's boundary-layer gain [s/rad] (the verdict's subject).

    Built by :func:`control.fdsmc.derivations.derive` before the derived case itself, which
    then holds the verdicts of :func:`control.fdsmc.loop_analysis.recommend_K` and
    :func:`control.fdsmc.loop_analysis.sample_rate_check`.
    """

    alpha_max: float = 0.0
    T_c: float = 0.0
    g1: float = 0.0
    g2: float = 0.0
    f_s: float | None = None
    delay: int = 0
    K: float = 0.0

    @classmethod
    def of_case(cls, lm: LoopModel, params: DriveParams, alpha_max: float, T_c: float, g1: float,
                g2: float) -> LoopCase:
        """Return the case of ``params`` on the loop model ``lm``."""
        c = params.controller
        return cls(lm.coefficients, lm.observer, lm.J_r, lm.J_total, lm.F_v, lm.T_si, lm.T_salpha, lm.T_so,
                   alpha_max, T_c, g1, g2, None if c.is_continuous else float(c.f_s), c.delay_samples, c.K)


def outer_gains(d: LoopCase, law: str, K: float) -> tuple[float, float]:
    """α_dem = a_th·θ̂ + a_w·ω̂ (linear part) for the law [1/s², 1/s]."""
    a_max, T_c = d.alpha_max, d.T_c
    if law == "cruise":
        return 0.0, -a_max * K
    if law == "slope":
        return -a_max * K / T_c, -a_max * K
    return -d.g1, -d.g2


def control_row(d: LoopCase, law: str, K: float) -> np.ndarray:
    """u_q = row·z, the linear part of eq. (14) in [1] at i_d = 0 with the outer law [V per state]."""
    return fdc_row(d.coefficients, d.T_salpha, *outer_gains(d, law, K))


def fdc_row(c: ModelCoefficients, T_salpha: float, a_th: float, a_w: float) -> np.ndarray:
    """u_q = row·z of eq. (14) in [1] at i_d = 0 for α_dem = a_th·θ̂ + a_w·ω̂ [V per state].

    The demand itself enters u_q with the factor :func:`fdc_input_gain`.
    """
    f = 3.0 / T_salpha
    row = np.zeros(N_STATES)
    row[0] = (c.D - f) / c.G  # −(3/T_sα)·H·i_q/H + D·i_q
    row[3] = f * a_th / c.H / c.G
    row[4] = (f * a_w / c.H + c.E) / c.G
    row[5] = f * c.M / c.H / c.G
    row[6] = c.M / c.H / c.G
    return row


def fdc_input_gain(c: ModelCoefficients, T_salpha: float) -> float:
    """∂u_q/∂α_dem of eq. (14) in [1]: (3/T_sα)/(H·G) [V·s²/rad]."""
    return 3.0 / T_salpha / c.H / c.G


def plant_matrices(lm: LoopModel) -> tuple[np.ndarray, np.ndarray]:
    """Continuous plant [i_q, θ_r, ω_r] with input u_q, eqs. (2), (3), (4b) in [1] at i_d = 0."""
    c, J_t = lm.coefficients, lm.J_total
    A = np.array([[-c.D, 0.0, -c.E], [0.0, 0.0, 1.0], [lm.J_r * c.H / J_t, 0.0, -lm.F_v / J_t]])
    b = np.array([c.G, 0.0, 0.0])
    return A, b


def continuous_matrix(lm: LoopModel, row: np.ndarray) -> np.ndarray:
    """Closed-loop matrix (7×7) [1/s] of plant, continuous observer and the control ``row``."""
    Ap, bp = plant_matrices(lm)
    o, c = lm.observer, lm.coefficients
    A = np.zeros((N_STATES, N_STATES))
    A[:3, :3] = Ap
    A[:3, :] += np.outer(bp, row)
    e = np.zeros(N_STATES)
    e[1], e[3] = 1.0, -1.0  # e_o = θ − θ̂ (corrected eq. (15))
    A[3, 4] = 1.0
    A[4, 0], A[4, 5] = c.H, -c.M
    A[5, 6] = 1.0
    for i, k in zip((3, 4, 5, 6), (o.K1, o.K2, o.K3, o.K4), strict=True):
        A[i] += k * e
    return A


def continuous_loop(d: LoopCase, law: str, K: float) -> np.ndarray:
    """Closed-loop matrix (7×7) of the continuous implementation [1/s]."""
    return continuous_matrix(d, control_row(d, law, K))


@dataclass(frozen=True)
class SampledParts:
    """ZOH-exact plant (Ad, bd) and discrete observer for one sample rate (arrays read-only)."""

    Ad: np.ndarray
    bd: np.ndarray
    observer: DiscreteObserver


def sampled_parts(lm: LoopModel, f_s: float) -> SampledParts:
    """Plant [i_q, θ_r, ω_r] discretised exactly for held u_q, and the observer, at ``f_s`` [Hz].

    Cached per (plant numbers, observer gains, f_s): a bisection over f_s or K that revisits a
    sample rate, or a new case on the same drive, reuses the matrix exponentials.
    """
    c = lm.coefficients
    return _sampled_parts(c.D, c.E, c.G, c.H, c.M, lm.J_r, lm.J_total, lm.F_v, lm.observer, float(f_s))


@functools.lru_cache(maxsize=1024)
def _sampled_parts(D: float, E: float, G: float, H: float, M: float, J_r: float, J_total: float, F_v: float,
                   observer: ObserverGains, f_s: float) -> SampledParts:
    A = np.array([[-D, 0.0, -E], [0.0, 0.0, 1.0], [J_r * H / J_total, 0.0, -F_v / J_total]])
    Ad, bd = zoh(A, np.array([G, 0.0, 0.0]), 1.0 / f_s)
    od = discrete_observer(observer, M, f_s)
    for a in (Ad, bd, od.Phi, od.Gamma, od.L):
        a.flags.writeable = False  # shared by every caller of the cache
    return SampledParts(Ad, bd, od)


def discrete_matrix(sp: SampledParts, H: float, row7: np.ndarray, delay: int) -> np.ndarray:
    """Transition matrix (7×7, or 8×8 holding the delayed u_q) of the sampled loop with ``row7``."""
    Ad, bd, od = sp.Ad, sp.bd, sp.observer
    n = N_STATES + delay
    Z = np.zeros((n, n))
    Z[:3, :3] = Ad
    row = np.zeros(n)
    row[:N_STATES] = row7
    if delay:
        Z[:3, N_STATES] = bd
        Z[N_STATES] = row
    else:
        Z[:3] += np.outer(bd, row)
    Z[3:7, 3:7] = od.Phi
    Z[3:7, 0] += od.Gamma * H
    Z[3:7, 1] += od.L
    Z[3:7, 3] -= od.L
    return Z


def discrete_loop(d: LoopCase, law: str, K: float, f_s: float, delay: int = 0,
                  parts: SampledParts | None = None) -> np.ndarray:
    """Closed-loop transition matrix of the sampled implementation (7×7, or 8×8 with delay)."""
    sp = sampled_parts(d, f_s) if parts is None else parts
    return discrete_matrix(sp, d.coefficients.H, control_row(d, law, K), delay)


def reduce_shift_mode(M: np.ndarray) -> np.ndarray:
    """Remove the structural mode θ_r = θ̂_r = const of the cruise law (θ̂ not fed back).

    In the coordinates (e = θ − θ̂, θ̂) the θ̂ column only feeds itself; dropping it leaves the
    other eigenvalues unchanged.
    """
    n = M.shape[0]
    T = np.eye(n)
    T[1, 3] = -1.0  # new state 1 = θ − θ̂
    T_inv = np.eye(n)
    T_inv[1, 3] = 1.0
    Mt = T @ M @ T_inv
    keep = [i for i in range(n) if i != 3]
    reduced: FloatArray = Mt[np.ix_(keep, keep)]
    return reduced


def law_case(d: LoopCase, law: str) -> LoopCase:
    """``d`` with every number the loop of ``law`` does not read set to 0: the searches' cache key.

    All laws read the model, observer, inertias, friction and T_sα, and the K search reads α_max
    (its grid and the laws of eq. (46) in [1]); the sloped law reads T_c, the conventional law
    g1 and g2. The sample rate and delay are the searches' own arguments.
    """
    return dataclasses.replace(
        d, T_si=0.0, T_so=0.0, f_s=None, delay=0, K=0.0,
        T_c=d.T_c if law == "slope" else 0.0,
        g1=d.g1 if law == "conventional" else 0.0, g2=d.g2 if law == "conventional" else 0.0)


#: Resolution of the K searches (stability limit, noise limit): bisected until hi/lo ≤ this [-].
K_SEARCH_RATIO = 1.005


def K_search_grid(alpha_max: float) -> np.ndarray:
    """Return the K searches' log grid [s/rad]: 23 points over 11 decades around 1000/α_max.

    K enters the laws of eq. (46) in [1] as α_max·K, so the grid scales with 1/α_max.
    """
    return np.logspace(-5, 6, 23) * 1000.0 / alpha_max


def geometric_bisect(flips: Callable[[float], bool], lo: float, hi: float, ratio: float) -> float:
    """Smallest x in (lo, hi] with ``flips(x)`` true, given flips(lo) false and flips(hi) true.

    Bisection on a log scale until hi/lo ≤ ``ratio``; returns the upper end (where it flips).
    The midpoint √lo·√hi never overflows, and at most 200 halvings are made (enough for any
    bracket of doubles).
    """
    for _ in range(200):
        if not hi / lo > ratio:
            break
        mid = math.sqrt(lo) * math.sqrt(hi)
        if flips(mid):
            hi = mid
        else:
            lo = mid
    return hi
