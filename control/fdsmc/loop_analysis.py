"""Linearised closed-loop analysis: recommended boundary-layer gain K and the sample-rate check.

The FDSMC outer loop is linear inside its boundary layer: on the cruise segment eq. (46) of [1]
reads α_dem = −α_max·K·(ω̂_r − ω_p), on the sloped segment α_dem = −α_max·K·(ω̂_r + θ̂_re/T_c).
Around i_d = 0 (eq. (10)) with a constant external load the drive is linear in the states

    z = [i_q, θ_r, ω_r, θ̂_r, ω̂_r, L̂0, L̂1]   (+ the held voltage with a one-sample delay)

with the plant di_q/dt = −D·i_q − E·ω_r + G·u_q (eq. (2)), (J_r + J_L)·dω_r/dt = J_r·H·i_q −
F_v·ω_r (eq. (4b)), the FDC law u_q of eq. (14) (using ω̂_r, L̂0, L̂1), and the corrected
observer of eq. (15) — continuous, or the ZOH-exact discrete observer of
:func:`control.fdsmc.observer.discrete_observer` with the plant discretised exactly for held voltages.
The inertia is the user's estimate J_r + J_L from the preset; the controller knows only J_r.

* K_limit: the smallest K at which that loop becomes unstable (a closed-loop eigenvalue crosses
  the imaginary axis / unit circle); the loop then limit-cycles against the saturation of
  eq. (45) — the chatter seen with the paper's K = 1000. Recommended K = K_limit / margin.
* Sample-rate check: the same sampled loop with the slow conventional outer law of eq. (61)
  (i.e. inner loops + observer); its spectral radius ≥ 1 means f_s is too slow for T_so/T_sα.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.linalg import expm

from control.fdsmc.model import ModelCoefficients
from control.fdsmc.observer import DiscreteObserver, ObserverGains, discrete_observer
from control.fdsmc.params import DriveParams

if TYPE_CHECKING:  # derivations imports this module
    from control.fdsmc.derivations import Derived

#: Default gain margin of the recommended K [-] (2 = 6 dB).
GAIN_MARGIN = 2.0
#: Smallest acceptable damping ratio of the ideal sloped-segment loop [-].
ZETA_SLOPE_MIN = 0.5
LAWS = ("cruise", "slope", "conventional")
_N = 7  # [i_q, θ, ω, θ̂, ω̂, L̂0, L̂1]


@dataclass(frozen=True)
class GainRecommendation:
    """Recommended boundary-layer gain, from the linearised loop.

    Attributes
    ----------
    K_limit : float          Smallest unstable K of the linearised loop [s/rad].
    K_limit_cruise : float   Limit of the cruise segment alone [s/rad].
    K_limit_slope : float    Limit of the sloped segment alone [s/rad].
    margin : float           Gain margin applied, K_recommended = K_limit/margin [-].
    K_recommended : float    [s/rad].
    K : float                The preset's K [s/rad].
    K_ok : bool              K < K_limit (no limit cycle expected).
    margin_of_K : float      K_limit/K, the gain margin of the preset's K [-].
    mode : str               "continuous" or "f_s = … Hz".
    zeta_slope : float       Damping ratio √(α_max·K·T_c)/2 of the ideal sloped-segment loop
                             s² + α_max·K·s + α_max·K/T_c, with the preset's K if K_ok, else with
                             K_recommended [-].
    T_c_min : float          T_c giving ζ = 1 with K_limit_cruise/margin, 4/(α_max·K) [s].
    zeta_slope_recommended : float  The same damping ratio with K_recommended [-].
    """

    K_limit: float
    K_limit_cruise: float
    K_limit_slope: float
    margin: float
    K_recommended: float
    K: float
    K_ok: bool
    margin_of_K: float
    mode: str
    zeta_slope: float = math.nan
    T_c_min: float = math.nan
    zeta_slope_recommended: float = math.nan


@dataclass(frozen=True)
class SampleRateCheck:
    """Stability of the sampled inner loops + observer (conventional outer law).

    Attributes
    ----------
    f_s : float or None          Sample rate [Hz]; None in continuous mode.
    spectral_radius : float      max |z| of the linearised sampled loop [-] (0 if continuous).
    stable : bool                spectral radius < 1.
    f_s_min : float or None      Smallest stable rate found (bisection, 1 % resolution) [Hz].
    delay_samples : int          Computation delay assumed [samples].
    """

    f_s: float | None
    spectral_radius: float
    stable: bool
    f_s_min: float | None
    delay_samples: int


def _outer_gains(d: Derived, law: str, K: float) -> tuple[float, float]:
    """α_dem = a_th·θ̂ + a_w·ω̂ (linear part) for the law [1/s², 1/s]."""
    a_max, T_c = d.alpha.alpha_max, d.profile.T_c
    if law == "cruise":
        return 0.0, -a_max * K
    if law == "slope":
        return -a_max * K / T_c, -a_max * K
    return -d.conventional.g1, -d.conventional.g2


def control_row(d: Derived, law: str, K: float) -> np.ndarray:
    """u_q = row·z, the linear part of eq. (14) in [1] at i_d = 0 with the outer law [V per state]."""
    return fdc_row(d.coefficients, d.params.controller.T_salpha, *_outer_gains(d, law, K))


def fdc_row(c: ModelCoefficients, T_salpha: float, a_th: float, a_w: float) -> np.ndarray:
    """u_q = row·z of eq. (14) in [1] at i_d = 0 for α_dem = a_th·θ̂ + a_w·ω̂ [V per state].

    The demand itself enters u_q with the factor :func:`fdc_input_gain`.
    """
    f = 3.0 / T_salpha
    row = np.zeros(_N)
    row[0] = (c.D - f) / c.G  # −(3/T_sα)·H·i_q/H + D·i_q
    row[3] = f * a_th / c.H / c.G
    row[4] = (f * a_w / c.H + c.E) / c.G
    row[5] = f * c.M / c.H / c.G
    row[6] = c.M / c.H / c.G
    return row


def fdc_input_gain(c: ModelCoefficients, T_salpha: float) -> float:
    """∂u_q/∂α_dem of eq. (14) in [1]: (3/T_sα)/(H·G) [V·s²/rad]."""
    return 3.0 / T_salpha / c.H / c.G


def plant_matrices(d: Derived) -> tuple[np.ndarray, np.ndarray]:
    """Continuous plant [i_q, θ_r, ω_r] with input u_q, eqs. (2), (3), (4b) at i_d = 0."""
    return plant_matrices_of(d.coefficients, d.params)


def plant_matrices_of(c: ModelCoefficients, p: DriveParams) -> tuple[np.ndarray, np.ndarray]:
    """:func:`plant_matrices` from the model coefficients and the parameters alone."""
    J_r, J_t = p.motor.J_r, p.J_total
    A = np.array([[-c.D, 0.0, -c.E], [0.0, 0.0, 1.0], [J_r * c.H / J_t, 0.0, -p.load.F_v / J_t]])
    b = np.array([c.G, 0.0, 0.0])
    return A, b


@dataclass(frozen=True)
class LoopModel:
    """What the linearised loop needs besides the outer law: model, parameters, observer gains."""

    coefficients: ModelCoefficients
    params: DriveParams
    observer: ObserverGains


def loop_model(d: Derived) -> LoopModel:
    """Return the :class:`LoopModel` of a derived case."""
    return LoopModel(d.coefficients, d.params, d.observer)


def continuous_loop(d: Derived, law: str, K: float) -> np.ndarray:
    """Closed-loop matrix (7×7) of the continuous implementation [1/s]."""
    return continuous_matrix(loop_model(d), control_row(d, law, K))


def continuous_matrix(lm: LoopModel, row: np.ndarray) -> np.ndarray:
    """Closed-loop matrix (7×7) [1/s] of plant, continuous observer and the control ``row``."""
    Ap, bp = plant_matrices_of(lm.coefficients, lm.params)
    o, c = lm.observer, lm.coefficients
    A = np.zeros((_N, _N))
    A[:3, :3] = Ap
    A[:3, :] += np.outer(bp, row)
    e = np.zeros(_N)
    e[1], e[3] = 1.0, -1.0  # e_o = θ − θ̂ (corrected eq. (15))
    A[3, 4] = 1.0
    A[4, 0], A[4, 5] = c.H, -c.M
    A[5, 6] = 1.0
    for i, k in zip((3, 4, 5, 6), (o.K1, o.K2, o.K3, o.K4), strict=True):
        A[i] += k * e
    return A


@dataclass(frozen=True)
class SampledParts:
    """ZOH-exact plant (Ad, bd) and discrete observer for one sample rate."""

    Ad: np.ndarray
    bd: np.ndarray
    observer: DiscreteObserver


def sampled_parts(d: Derived | LoopModel, f_s: float) -> SampledParts:
    """Plant [i_q, θ_r, ω_r] discretised exactly for held u_q, and the observer, at ``f_s`` [Hz]."""
    T_s = 1.0 / f_s
    Ap, bp = plant_matrices_of(d.coefficients, d.params)
    aug = np.zeros((4, 4))
    aug[:3, :3], aug[:3, 3] = Ap * T_s, bp * T_s
    E = expm(aug)
    return SampledParts(E[:3, :3], E[:3, 3], discrete_observer(d.observer, d.coefficients.M, f_s))


def discrete_loop(
    d: Derived, law: str, K: float, f_s: float, delay: int = 0, parts: SampledParts | None = None
) -> np.ndarray:
    """Closed-loop transition matrix of the sampled implementation (7×7, or 8×8 with delay)."""
    sp = sampled_parts(d, f_s) if parts is None else parts
    return discrete_matrix(sp, d.coefficients.H, control_row(d, law, K), delay)


def discrete_matrix(sp: SampledParts, H: float, row7: np.ndarray, delay: int) -> np.ndarray:
    """Transition matrix (7×7, or 8×8 holding the delayed u_q) of the sampled loop with ``row7``."""
    Ad, bd, od = sp.Ad, sp.bd, sp.observer
    n = _N + delay
    Z = np.zeros((n, n))
    Z[:3, :3] = Ad
    row = np.zeros(n)
    row[:_N] = row7
    if delay:
        Z[:3, _N] = bd
        Z[_N] = row
    else:
        Z[:3] += np.outer(bd, row)
    Z[3:7, 3:7] = od.Phi
    Z[3:7, 0] += od.Gamma * H
    Z[3:7, 1] += od.L
    Z[3:7, 3] -= od.L
    return Z


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
    return Mt[np.ix_(keep, keep)]


def stability_measure(
    d: Derived, law: str, K: float, f_s: float | None, delay: int = 0,
    parts: SampledParts | None = None,
) -> float:
    """Largest Re(s) [1/s] (continuous) or largest |z| − 1 [-] (sampled); < 0 means stable."""
    M = continuous_loop(d, law, K) if f_s is None else discrete_loop(d, law, K, f_s, delay, parts)
    if law == "cruise":
        M = reduce_shift_mode(M)
    if not np.all(np.isfinite(M)):  # a gain so large (or a model so extreme) that the loop overflows
        return math.inf
    ev = np.linalg.eigvals(M)
    return float(np.max(ev.real)) if f_s is None else float(np.max(np.abs(ev)) - 1.0)


def gain_limit(d: Derived, law: str, f_s: float | None, delay: int = 0) -> float:
    """Upper stability limit in K [s/rad] of the linearised loop with ``law``.

    K is scanned on a log grid (2 points per decade, 1e−5 … 1e6 s/rad, scaled by
    1000/α_max); above the largest stable grid K the first unstable one is refined by bisection
    to 0.5 %. Returns 0 if the loop is unstable for every K (inner loops unstable, or a sloped
    segment too poorly damped, see :func:`slope_damping`) and ``inf`` if it never is.
    """
    parts = None if f_s is None else sampled_parts(d, f_s)

    def unstable(K: float) -> bool:
        return stability_measure(d, law, K, f_s, delay, parts) >= 0.0

    grid = [float(K) for K in np.logspace(-5, 6, 23) * 1000.0 / d.alpha.alpha_max]
    flags = [unstable(K) for K in grid]
    if all(flags):
        return 0.0
    last_stable = max(i for i, f in enumerate(flags) if not f)
    if last_stable == len(grid) - 1:
        return math.inf
    return geometric_bisect(unstable, grid[last_stable], grid[last_stable + 1], 1.005)


def slope_damping(alpha_max: float, K: float, T_c: float) -> float:
    """Damping ratio of the ideal sloped-segment loop, √(α_max·K·T_c)/2 [-].

    Inside the boundary layer on the sloped segment of eq. (41) in [1], eq. (46) gives
    α_dem = −α_max·K·(ω_r + θ_re/T_c); with α = α_dem (eq. (15), plant θ̈ = u) the loop is
    s² + α_max·K·s + α_max·K/T_c. With T_c = T_a (eq. (59)) α_max·T_c = ω_p, so a slow
    manoeuvre (small ω_p) needs K·ω_p ≳ 4 for a non-oscillating approach to θ_dem.

    Parameters
    ----------
    alpha_max : float  [rad/s²]
    K : float          [s/rad]
    T_c : float        [s]
    """
    return math.sqrt(alpha_max * K * T_c) / 2.0


def _f_s(d: Derived) -> float | None:
    ctrl = d.params.controller
    return None if ctrl.is_continuous else float(ctrl.f_s)


def recommend_K(d: Derived, margin: float = GAIN_MARGIN) -> GainRecommendation:
    """Recommended boundary-layer gain K = K_limit/margin for the preset's implementation.

    Parameters
    ----------
    d : Derived
        Derivations of the case (inertia J_r + J_L, observer, α_max, T_c, f_s).
    margin : float
        Gain margin [-], default 2 (6 dB).

    Returns
    -------
    GainRecommendation
    """
    f_s, delay = _f_s(d), d.params.controller.delay_samples
    k_c = gain_limit(d, "cruise", f_s, delay)
    k_s = gain_limit(d, "slope", f_s, delay)
    # A sloped segment unstable for every K is a damping problem (see slope_damping), reported
    # by zeta_slope/T_c_min; the limit-cycle bound is then the cruise segment's.
    k_lim = min(k_c, k_s) if k_s > 0.0 else k_c
    K, a_max = d.params.controller.K, d.alpha.alpha_max
    mode = "continuous" if f_s is None else f"f_s = {f_s:g} Hz"
    k_ok = k_lim > K
    zeta = slope_damping(a_max, K if k_ok else k_lim / margin, d.profile.T_c)
    T_c_min = 4.0 * margin / (a_max * k_c) if 0.0 < k_c < math.inf else math.nan
    zeta_rec = slope_damping(a_max, k_lim / margin, d.profile.T_c)
    return GainRecommendation(k_lim, k_c, k_s, margin, k_lim / margin, K, k_ok, k_lim / K, mode,
                              zeta, T_c_min, zeta_rec)


def loop_warnings(g: GainRecommendation, s: SampleRateCheck) -> tuple[str, ...]:
    """Human-readable verdicts of :func:`recommend_K` and :func:`sample_rate_check`."""
    w: list[str] = []
    if not s.stable:
        need = f"≥ {s.f_s_min:.4g} Hz" if s.f_s_min is not None else "a faster controller"
        w.append(
            f"Sample rate f_s = {s.f_s:g} Hz is too slow for T_so/T_sα: the sampled inner loops + "
            f"observer are unstable (spectral radius {s.spectral_radius:.4f} ≥ 1, "
            f"delay {s.delay_samples} sample(s)); needs {need}. The simulation will diverge.")
    elif g.K_limit > 0.0 and not g.K_ok:
        w.append(
            f"Boundary-layer gain K = {g.K:g} s/rad exceeds the stability limit K_limit = "
            f"{g.K_limit:.4g} s/rad of the linearised FDSMC loop ({g.mode}): the outer loop will "
            f"chatter (limit cycle) and waste copper energy. Recommended K = {g.K_recommended:.4g} "
            f"s/rad (gain margin {g.margin:g}).")
    if s.stable and g.zeta_slope < ZETA_SLOPE_MIN:
        w.append(_slope_warning(g))
    return tuple(w)


def _slope_warning(g: GainRecommendation) -> str:
    """Advice when the ideal sloped-segment loop is poorly damped (ζ < ZETA_SLOPE_MIN)."""
    k = g.K if g.K_ok else g.K_recommended
    lin = ("the linearised sloped segment is unstable for every K" if g.K_limit_slope == 0.0
           else f"linearised slope limit K = {g.K_limit_slope:.4g} s/rad")
    if g.zeta_slope_recommended >= ZETA_SLOPE_MIN:
        fix = f"Raise K to the recommended {g.K_recommended:.4g} s/rad (ζ = {g.zeta_slope_recommended:.2g})."
    else:
        fix = (f"Set controller.T_c ≥ {g.T_c_min:.3g} s (ζ = 1 at K = "
               f"{g.K_limit_cruise / g.margin:.4g} s/rad; T_c ≪ T_m keeps the timing).")
    return (f"Sloped segment (eq. 41, deceleration) poorly damped with K = {k:.4g} s/rad: "
            f"ζ ≈ √(α_max·K·T_c)/2 = {g.zeta_slope:.2g} ({lin}). α_max·T_c is small (= ω_p when "
            f"T_c = T_a, eq. 59), so the drive will oscillate about θ_dem. {fix}")


def sample_rate_check(d: Derived) -> SampleRateCheck:
    """Spectral radius of the sampled inner loops + observer and the slowest stable f_s.

    Parameters
    ----------
    d : Derived

    Returns
    -------
    SampleRateCheck
        In continuous mode: stable, spectral radius 0, no f_s.
    """
    f_s, delay = _f_s(d), d.params.controller.delay_samples
    if f_s is None:
        return SampleRateCheck(None, 0.0, True, None, delay)
    rho = 1.0 + stability_measure(d, "conventional", 0.0, f_s, delay)
    return SampleRateCheck(f_s, rho, rho < 1.0, minimum_sample_rate(d, delay), delay)


def minimum_sample_rate(d: Derived, delay: int = 0) -> float | None:
    """Smallest f_s [Hz] for which the sampled inner loops + observer are stable (1 % steps).

    Searched between 100 Hz and 10 MHz; None if even 10 MHz is unstable.
    """
    def unstable(fs: float) -> bool:
        return stability_measure(d, "conventional", 0.0, fs, delay) >= 0.0

    hi = 1e7
    if unstable(hi):
        return None
    lo = 100.0
    if not unstable(lo):
        return lo
    return geometric_bisect(lambda fs: not unstable(fs), lo, hi, 1.01)


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
