"""Back-EMF shapes Φ'_r(θ_e) of the BLDC machine model (eq. (2) and Figs. 2, 4 of [2]).

A shape is one electrical period of Φ'_ra = e_a/ω_e [Wb] sampled on the uniform grid
θ_e = 2π·k/N (k = 0 … N−1, N = :data:`N_TABLE`); phases b and c lag by 120° and 240°.

* ideal: the trapezoid of Fig. 2 (exact on the grid, its corners fall on samples);
* distorted (built-in example of a *real* machine, Fig. 4): the ideal trapezoid with rounded
  corners — circular convolution with a 30°-wide Hann window — plus a 3rd harmonic of 5 % and
  a 5th harmonic of 3 % of Φ_M. The result is smooth (every derivative exists), keeps the
  half-wave symmetry of a real machine (odd harmonics only) and has a dip in the middle of its
  flat tops, as measured BLDC back-EMFs often do.
* measured: a user's table, checked and resampled by :func:`resample_measured`.

[2] Monteiro, de Castro, de Almeida, the SMC-BLDC paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.bldc.dqx import trapezoid_unit
from pmsm_commissioning.control.bldc.params import EMF_SAMPLES_MIN, BldcMachine
from pmsm_commissioning.control.common.arrays import FloatArray
from pmsm_commissioning.control.common.checks import ParameterError

N_TABLE = 720  # 0.5° electrical per sample; a multiple of 12 keeps the trapezoid corners exact
HANN_WIDTH = math.radians(30.0)
HARMONICS = ((3, 0.05), (5, 0.03))  # (order, amplitude / Φ_M) of the distorted example
SHIFT_TOL_DEG = 10.0  # allowed deviation of the measured phase shift from 120° / 240°


def grid(n: int = N_TABLE) -> np.ndarray:
    """Uniform electrical-angle grid 2π·k/n, k = 0 … n−1 [rad]."""
    return 2.0 * math.pi * np.arange(n) / n


def ideal_table(Phi_m: float, n: int = N_TABLE) -> np.ndarray:
    """Ideal trapezoid Φ'_ra on :func:`grid` [Wb] (Fig. 2 of [2])."""
    return Phi_m * np.array([trapezoid_unit(t) for t in grid(n)])


def distorted_table(Phi_m: float, n: int = N_TABLE) -> np.ndarray:
    """Built-in smooth distorted example of a real back-EMF [Wb] (module docstring)."""
    theta = grid(n)
    width = max(3, int(round(HANN_WIDTH / (2.0 * math.pi) * n)))
    window = np.hanning(width + 2)[1:-1]
    kernel = np.zeros(n)
    kernel[:width] = window / window.sum()
    kernel = np.roll(kernel, -(width // 2))
    smooth = np.real(np.fft.ifft(np.fft.fft(ideal_table(Phi_m, n)) * np.fft.fft(kernel)))
    extra = sum(-a * Phi_m * np.sin(h * theta) for h, a in HARMONICS)
    table: FloatArray = smooth + extra
    return table


def machine_table(machine: BldcMachine, n: int = N_TABLE) -> np.ndarray:
    """Return the machine's Φ'_ra table [Wb] for its ``emf`` choice."""
    if machine.emf == "ideal":
        return ideal_table(machine.Phi_m, n)
    if machine.emf == "distorted":
        return distorted_table(machine.Phi_m, n)
    return periodic_resample(np.asarray(machine.emf_samples, dtype=float), n)


def periodic_resample(samples: np.ndarray, n: int) -> np.ndarray:
    """Linear periodic interpolation of one period given on a uniform grid onto n points."""
    m = samples.size
    if m == n:
        return samples.copy()
    x = np.arange(n) * m / n
    resampled: FloatArray = np.interp(x, np.arange(m + 1), np.append(samples, samples[0]))
    return resampled


def table_phases(table: np.ndarray, theta_e: np.ndarray) -> np.ndarray:
    """Φ'_ra, Φ'_rb, Φ'_rc at θ_e by periodic linear interpolation, shape (3, n) [Wb]."""
    theta_e = np.asarray(theta_e, dtype=float)
    n = table.size
    closed = np.append(table, table[0])
    pos = np.arange(n + 1)
    out = [np.interp(((theta_e - s) % (2 * math.pi)) * n / (2 * math.pi), pos, closed)
           for s in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)]
    return np.array(out)


def table_slopes(table: np.ndarray, theta_e: np.ndarray) -> np.ndarray:
    """d/dθ_e of the three phases [Wb/rad] (periodic central differences of the table)."""
    n = table.size
    slope = (np.roll(table, -1) - np.roll(table, 1)) * n / (4.0 * math.pi)
    return table_phases(slope, theta_e)


@dataclass(frozen=True)
class MeasuredEmf:
    """A validated measured back-EMF period.

    Attributes
    ----------
    samples : numpy.ndarray   Φ'_ra on :func:`grid` [Wb] (phase b, c averaged in when given).
    n_phases : int            Number of phase columns given (1 or 3).
    shifts_deg : tuple        Measured lag of phases b and c behind a [deg] (empty for 1 phase).
    offset_deg : float        Angle by which the fundamental leads the ideal trapezoid's [deg];
                              non-zero means the θ_e origin differs from the controller's.
    """

    samples: np.ndarray
    n_phases: int
    shifts_deg: tuple[float, ...]
    offset_deg: float


def resample_measured(theta_deg: np.ndarray, values: np.ndarray, n: int = N_TABLE) -> MeasuredEmf:
    """Check one measured electrical period and resample it onto :func:`grid`.

    Parameters
    ----------
    theta_deg : numpy.ndarray  Electrical angles of the rows, increasing [deg].
    values : numpy.ndarray     Φ'_r of phase a, or of phases a, b, c: shape (rows,) or
                               (rows, 3) [Wb].

    Raises
    ------
    ParameterError
        Too few rows, non-finite values, angles not increasing, a span other than one
        electrical period (360°), a waveform that does not join up at the period's end, a zero
        waveform, or phases b, c not lagging a by 120° / 240° (± 10°).
    """
    theta = np.asarray(theta_deg, dtype=float)
    vals = np.asarray(values, dtype=float)
    vals = vals[:, None] if vals.ndim == 1 else vals
    _check_rows(theta, vals)
    span, step = theta[-1] - theta[0], float(np.median(np.diff(theta)))
    closed = abs(span - 360.0) <= 0.5 * step
    if not closed and abs(span + step - 360.0) > 0.5 * step:
        raise ParameterError(
            f"emf waveform: the θ_e column spans {span:g}° (+ one step {step:g}°) but one electrical "
            "period is 360°: allowed rows from θ_0 to θ_0 + 360° (last row optional); use electrical "
            "degrees (mechanical × pole pairs)"
        )
    ptp = float(np.ptp(vals[:, 0]))
    if ptp <= 0.0:
        raise ParameterError("emf waveform: phase a is constant: allowed a waveform with a non-zero amplitude")
    jump = np.abs(vals[-1] - vals[0])
    limit = (0.05 * ptp) if closed else (3.0 * float(np.max(np.abs(np.diff(vals, axis=0)))) + 0.02 * ptp)
    if np.any(jump > limit):
        raise ParameterError(
            f"emf waveform does not join up over one period: first and last rows differ by "
            f"{float(np.max(jump)):.4g} Wb, allowed ≤ {limit:.4g} Wb — is it exactly one electrical period?"
        )
    if closed:
        theta, vals = theta[:-1], vals[:-1]
    grid_deg = np.degrees(grid(n))
    res = np.array([np.interp(grid_deg, theta, col, period=360.0) for col in vals.T])
    shifts = _phase_shifts(res)
    aligned = res[0] if res.shape[0] == 1 else np.mean(
        [np.roll(res[k], -round(k * n / 3)) for k in range(3)], axis=0)
    return MeasuredEmf(aligned, vals.shape[1], shifts, _fundamental_offset(aligned))


def _check_rows(theta: np.ndarray, vals: np.ndarray) -> None:
    if theta.ndim != 1 or vals.shape[0] != theta.size or vals.shape[1] not in (1, 3):
        raise ParameterError(
            f"emf waveform has {vals.shape[1] if vals.ndim == 2 else '?'} value columns: "
            "allowed 1 (phase a) or 3 (a, b, c)")
    if theta.size < EMF_SAMPLES_MIN:
        raise ParameterError(f"emf waveform has {theta.size} rows: allowed ≥ {EMF_SAMPLES_MIN} rows per period")
    bad = np.flatnonzero(~np.isfinite(theta) | ~np.all(np.isfinite(vals), axis=1))
    if bad.size:
        raise ParameterError(
            f"emf waveform row {bad[0] + 1} is not a finite number (NaN or inf): allowed finite values only")
    if np.any(np.diff(theta) <= 0.0):
        k = int(np.flatnonzero(np.diff(theta) <= 0.0)[0])
        raise ParameterError(f"emf waveform θ_e = {theta[k + 1]:g}° at row {k + 2} does not increase: "
                             "allowed strictly increasing angles")


def _phase_shifts(res: np.ndarray) -> tuple[float, ...]:
    if res.shape[0] == 1:
        return ()
    spectra = np.fft.fft(res, axis=1)[:, 1]
    shifts = []
    for k, name, expected in ((1, "b", 120.0), (2, "c", 240.0)):
        lag = float(np.degrees(np.angle(spectra[0] / spectra[k]))) % 360.0
        if abs(lag - expected) > SHIFT_TOL_DEG:
            raise ParameterError(
                f"emf waveform phase {name} lags phase a by {lag:.1f}°: allowed {expected:g}° ± "
                f"{SHIFT_TOL_DEG:g}° (columns in the order a, b, c?)"
            )
        shifts.append(lag)
    return tuple(shifts)


def _fundamental_offset(samples: np.ndarray) -> float:
    ideal = np.array([trapezoid_unit(t) for t in grid(samples.size)])
    c_m, c_i = np.fft.fft(samples)[1], np.fft.fft(ideal)[1]
    return float(np.degrees(np.angle(c_m / c_i)))
