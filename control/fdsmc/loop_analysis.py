"""Linearised closed-loop analysis: recommended boundary-layer gain K and the sample-rate check.

The FDSMC outer loop is linear inside its boundary layer: on the cruise segment eq. (46) of [1]
reads α_dem = −α_max·K·(ω̂_r − ω_p), on the sloped segment α_dem = −α_max·K·(ω̂_r + θ̂_re/T_c).
The loop around i_d = 0 is built by :mod:`control.fdsmc.loop_model` (plant eqs. (2), (4b), FDC
eq. (14), corrected observer eq. (15), continuous or sampled). The inertia is the user's estimate
J_r + J_L from the preset; the controller knows only J_r.

* K_limit: the smallest K at which that loop becomes unstable (a closed-loop eigenvalue crosses
  the imaginary axis / unit circle); the loop then limit-cycles against the saturation of
  eq. (45) — the chatter seen with the paper's K = 1000.
* K_noise: the smallest K at which the sensors' noise alone swings α_dem as much as the chatter
  criterion allows (:func:`control.fdsmc.noise.noise_gain_limit`; inf for ideal sensors).
* Recommended K = K_limit / margin, lowered where the sensors' noise would swing α_dem by more than
  the criterion / margin: the K the real drive's sensors allow.
* Sample-rate check: the same sampled loop with the slow conventional outer law of eq. (61)
  (i.e. inner loops + observer); its spectral radius ≥ 1 means f_s is too slow for T_so/T_sα.

The searches (:func:`gain_limit`, :func:`minimum_sample_rate`) are pure functions of the numbers
the loop is built from, and are cached on exactly those numbers: a case that differs only in
what the search does not read (K, T_m for the cruise limit, the load steps …) reuses the verdict
computed for it, bit for bit. That is what makes a live slider drag cheap.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc.loop_model import (
    K_SEARCH_RATIO,
    K_search_grid,
    LoopCase,
    SampledParts,
    continuous_loop,
    discrete_loop,
    geometric_bisect,
    law_case,
    reduce_shift_mode,
    sampled_parts,
)
from pmsm_commissioning.control.fdsmc.noise import noise_gain_limit

#: Default gain margin of the recommended K [-] (2 = 6 dB).
GAIN_MARGIN = 2.0
#: The chatter criterion's amplitude: α_dem swinging by more than this fraction of α_max
#: peak-to-peak over a window is chatter (``sim.fdsmc.metrics``) [-].
CHATTER_PTP_FRACTION = 0.2
#: Smallest acceptable damping ratio of the ideal sloped-segment loop [-].
ZETA_SLOPE_MIN = 0.5
LAWS = ("cruise", "slope", "conventional")


@dataclass(frozen=True)
class GainRecommendation:
    """Recommended boundary-layer gain, from the linearised loop.

    Attributes
    ----------
    K_limit : float          Smallest unstable K of the linearised loop [s/rad].
    K_limit_cruise : float   Limit of the cruise segment alone [s/rad].
    K_limit_slope : float    Limit of the sloped segment alone [s/rad].
    margin : float           Gain margin applied to K_limit and to the noise's swing [-].
    K_recommended : float    [s/rad].
    K : float                The preset's K [s/rad].
    K_ok : bool              K < K_limit (no limit cycle expected).
    margin_of_K : float      K_limit/K, the gain margin of the preset's K [-].
    mode : str               "continuous" or "f_s = … Hz".
    zeta_slope : float       Damping ratio √(α_max·K·T_c)/2 of the ideal sloped-segment loop
                             s² + α_max·K·s + α_max·K/T_c, with the preset's K if K_ok, else with
                             K_recommended [-].
    T_c_min : float          T_c giving ζ = 1 at :attr:`K_unit_damping`, 4/(α_max·K) [s].
    zeta_slope_recommended : float  The same damping ratio with K_recommended [-].
    K_noise : float          Smallest K at which the sensors' noise makes α_dem chatter [s/rad];
                             inf for ideal sensors or when the stability limit comes first.
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
    K_noise: float = math.inf

    @property
    def K_margin(self) -> float:
        """K_limit/margin, the loop's own recommendation before the sensors' noise [s/rad]."""
        return self.K_limit / self.margin

    @property
    def noise_limited(self) -> bool:
        """True when the sensors' noise, not K_limit/margin, sets K_recommended."""
        return self.K_recommended < self.K_margin

    @property
    def K_unit_damping(self) -> float:
        """The K that :attr:`T_c_min` damps critically [s/rad].

        K_recommended where the sensors' noise sets it, else K_limit_cruise/margin: a sloped
        segment unstable for every K is a damping problem, which T_c_min cures, so its own limit
        does not bound the K it is cured with.
        """
        return self.K_recommended if self.noise_limited else self.K_limit_cruise / self.margin

    @property
    def K_noise_ok(self) -> bool:
        """K below the noise limit where it binds: the sensors' noise alone does not make α_dem chatter."""
        return self.K_noise_binding > self.K

    @property
    def K_noise_binding(self) -> float:
        """K_noise where the sensors' noise sets the recommendation, else inf [s/rad].

        With fine sensors the noise's swing grows steeply only next to K_limit (the loop's poor
        damping there), and K_noise falls just below K_limit: that is not a noise limit to show.
        """
        return self.K_noise if self.noise_limited else math.inf


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


def stability_measure(
    d: LoopCase, law: str, K: float, f_s: float | None, delay: int = 0,
    parts: SampledParts | None = None,
) -> float:
    """Largest Re(s) [1/s] (continuous) or largest |z| − 1 [-] (sampled); < 0 means stable."""
    if f_s is not None and parts is None:
        parts = sampled_parts(d, f_s)
    M0, M1 = affine_loop(d, law, f_s, delay, parts)
    return _measure(M0 + float(K) * M1, f_s is not None)


def affine_loop(d: LoopCase, law: str, f_s: float | None, delay: int = 0,
                parts: SampledParts | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(M0, M1): the loop matrix of ``law`` at the gain K is M0 + K·M1.

    The outer laws of eq. (46) in [1] are linear in K and the loop is linear in the outer law,
    so two matrices serve a whole search over K (the conventional law does not read K: M1 = 0).
    The cruise loop is returned without its structural shift mode (:func:`reduce_shift_mode`).
    """
    def at(K: float) -> np.ndarray:
        M = continuous_loop(d, law, K) if f_s is None else discrete_loop(d, law, K, f_s, delay, parts)
        return reduce_shift_mode(M) if law == "cruise" else M

    M0 = at(0.0)
    return M0, (np.zeros_like(M0) if law == "conventional" else at(1.0) - M0)


def _measure(M: np.ndarray, sampled: bool) -> float:
    """Stability measure of one loop matrix (inf where a huge gain overflowed it)."""
    if not np.isfinite(M).all():
        return math.inf
    ev = np.linalg.eigvals(M)
    return float(np.abs(ev).max() - 1.0) if sampled else float(ev.real.max())


def _measures(M0: np.ndarray, M1: np.ndarray, Ks: list[float] | np.ndarray, sampled: bool) -> np.ndarray:
    """Stability measure of M0 + K·M1 for each K (inf where a huge gain overflows the matrix)."""
    mats = M0 + np.asarray(Ks, dtype=float)[:, None, None] * M1
    out = np.full(len(mats), math.inf)
    finite = np.all(np.isfinite(mats), axis=(1, 2))
    if finite.any():
        ev = np.linalg.eigvals(mats[finite])
        out[finite] = np.max(np.abs(ev), axis=1) - 1.0 if sampled else np.max(ev.real, axis=1)
    return out


def gain_limit(d: LoopCase, law: str, f_s: float | None, delay: int = 0) -> float:
    """Upper stability limit in K [s/rad] of the linearised loop with ``law``.

    K is scanned on a log grid (2 points per decade, 1e−5 … 1e6 s/rad, scaled by
    1000/α_max); above the largest stable grid K the first unstable one is refined by bisection
    to 0.5 %. Returns 0 if the loop is unstable for every K (inner loops unstable, or a sloped
    segment too poorly damped, see :func:`slope_damping`) and ``inf`` if it never is.
    Cached on :func:`control.fdsmc.loop_model.law_case`.
    """
    return _gain_limit(law_case(d, law), law, None if f_s is None else float(f_s), int(delay))


@functools.lru_cache(maxsize=512)
def _gain_limit(d: LoopCase, law: str, f_s: float | None, delay: int) -> float:
    M0, M1 = affine_loop(d, law, f_s, delay, None if f_s is None else sampled_parts(d, f_s))
    sampled = f_s is not None
    grid = K_search_grid(d.alpha_max)
    flags = _measures(M0, M1, grid, sampled) >= 0.0
    if flags.all():
        return 0.0
    last_stable = int(np.flatnonzero(~flags)[-1])
    if last_stable == len(grid) - 1:
        return math.inf
    return geometric_bisect(lambda K: _measure(M0 + K * M1, sampled) >= 0.0,
                            float(grid[last_stable]), float(grid[last_stable + 1]), K_SEARCH_RATIO)


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


def recommend_K(d: LoopCase, margin: float = GAIN_MARGIN, count: float = 0.0,
                i_noise_rms: float = 0.0, T_dv: float = 0.0) -> GainRecommendation:
    """Recommended boundary-layer gain K for the preset's implementation and sensors.

    K_limit/margin, or less where the sensors' noise would swing α_dem by more than the chatter
    criterion/margin (:func:`control.fdsmc.noise.noise_gain_limit`).

    Parameters
    ----------
    d : LoopCase
        Derivations of the case (inertia J_r + J_L, observer, α_max, T_c, f_s).
    margin : float
        Gain margin [-], default 2 (6 dB).
    count : float
        Encoder count Δ = 2π/cpr [rad]; 0 for an ideal encoder.
    i_noise_rms : float
        RMS of the current-measurement error [A].
    T_dv : float
        Filter time of the q-axis voltage-mismatch estimate (``controller.T_dv``) [s]; 0: none.

    Returns
    -------
    GainRecommendation
    """
    f_s, delay = d.f_s, d.delay
    k_c = gain_limit(d, "cruise", f_s, delay)
    k_s = gain_limit(d, "slope", f_s, delay)
    # A sloped segment unstable for every K is a damping problem (see slope_damping), reported
    # by zeta_slope/T_c_min; the limit-cycle bound is then the cruise segment's.
    k_lim = min(k_c, k_s) if k_s > 0.0 else k_c
    K, a_max = d.K, d.alpha_max
    mode = "continuous" if f_s is None else f"f_s = {f_s:g} Hz"
    k_ok = k_lim > K
    K_noise = noise_gain_limit(d, count, i_noise_rms, CHATTER_PTP_FRACTION, k_lim, T_dv)
    k_quiet = noise_gain_limit(d, count, i_noise_rms, CHATTER_PTP_FRACTION / margin, k_lim / margin, T_dv)
    k_rec = min(k_lim / margin, k_quiet) if k_lim > 0.0 else 0.0
    zeta = slope_damping(a_max, K if k_ok else k_rec, d.T_c)
    zeta_rec = slope_damping(a_max, k_rec, d.T_c)
    g = GainRecommendation(k_lim, k_c, k_s, margin, k_rec, K, k_ok, k_lim / K, mode, zeta, math.nan,
                           zeta_rec, K_noise)
    return dataclasses.replace(g, T_c_min=unit_damping_T_c(a_max, g.K_unit_damping, 1.0))  # no margin left to take


def unit_damping_T_c(alpha_max: float, K_limit: float, margin: float) -> float:
    """T_c [s] giving the ideal sloped-segment loop ζ = 1 at K = K_limit/margin: 4·margin/(α_max·K_limit).

    :func:`slope_damping` solved for T_c. NaN where K_limit is 0 or unbounded (no such T_c).

    Parameters
    ----------
    alpha_max : float  [rad/s²]
    K_limit : float    [s/rad]
    margin : float     Gain margin [-].
    """
    return 4.0 * margin / (alpha_max * K_limit) if 0.0 < K_limit < math.inf else math.nan


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
        fix = (f"Set controller.T_c ≥ {g.T_c_min:.3g} s (ζ = 1 at K = {g.K_unit_damping:.4g} s/rad; "
               f"T_c ≪ T_m keeps the timing).")
    return (f"Sloped segment (eq. 41, deceleration) poorly damped with K = {k:.4g} s/rad: "
            f"ζ ≈ √(α_max·K·T_c)/2 = {g.zeta_slope:.2g} ({lin}). α_max·T_c is small (= ω_p when "
            f"T_c = T_a, eq. 59), so the drive will oscillate about θ_dem. {fix}")


def sample_rate_check(d: LoopCase) -> SampleRateCheck:
    """Spectral radius of the sampled inner loops + observer and the slowest stable f_s.

    Parameters
    ----------
    d : LoopCase

    Returns
    -------
    SampleRateCheck
        In continuous mode: stable, spectral radius 0, no f_s.
    """
    f_s, delay = d.f_s, d.delay
    if f_s is None:
        return SampleRateCheck(None, 0.0, True, None, delay)
    rho = 1.0 + stability_measure(d, "conventional", 0.0, f_s, delay)
    return SampleRateCheck(f_s, rho, rho < 1.0, minimum_sample_rate(d, delay), delay)


def minimum_sample_rate(d: LoopCase, delay: int = 0) -> float | None:
    """Smallest f_s [Hz] for which the sampled inner loops + observer are stable (1 % steps).

    Searched between 100 Hz and 10 MHz; None if even 10 MHz is unstable. Cached on
    :func:`control.fdsmc.loop_model.law_case` without α_max (the conventional law does not read it).
    """
    return _minimum_sample_rate(dataclasses.replace(law_case(d, "conventional"), alpha_max=0.0), int(delay))


@functools.lru_cache(maxsize=256)
def _minimum_sample_rate(d: LoopCase, delay: int) -> float | None:
    def unstable(fs: float) -> bool:
        return stability_measure(d, "conventional", 0.0, fs, delay) >= 0.0

    hi = 1e7
    if unstable(hi):
        return None
    lo = 100.0
    if not unstable(lo):
        return lo
    return geometric_bisect(lambda fs: not unstable(fs), lo, hi, 1.01)

