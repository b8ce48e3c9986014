"""The encoder's quantization error as coloured noise (control.fdsmc.quantization): its autocorrelation
in closed form against the series and against the sawtooth sampled directly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.control.fdsmc.quantization import autocorrelation

COUNT = 2.0 * math.pi / 2**17  # [rad]


def _series(s2: float, count: float) -> float:
    n = np.arange(1, 400_000, dtype=float)
    return float((np.exp(-(n * n) * 2.0 * math.pi**2 * s2 / count**2) / (n * n)).sum() * count**2 / (2.0 * math.pi**2))


def test_at_zero_lag_the_variance_of_a_uniform_count_error():
    assert autocorrelation(np.array([0.0]), COUNT)[0] == pytest.approx(COUNT**2 / 12.0, rel=1e-12)


@pytest.mark.parametrize("s_counts", [1e-3, 0.05, 0.159, 0.16, 0.3, 1.0])
def test_the_closed_form_is_the_fourier_series_of_the_sawtooth(s_counts):
    s2 = (s_counts * COUNT) ** 2
    assert autocorrelation(np.array([s2]), COUNT)[0] == pytest.approx(_series(s2, COUNT), rel=1e-4, abs=1e-6 * COUNT**2)


@pytest.mark.parametrize("s_counts", [0.05, 0.2, 0.5])
def test_it_is_the_sawtooth_sampled_at_a_uniform_phase_and_a_gaussian_displacement(s_counts):
    rng = np.random.default_rng(7)
    theta = rng.uniform(0.0, 1.0, 400_000) * COUNT
    moved = theta + rng.normal(0.0, s_counts * COUNT, theta.size)

    def error(a: np.ndarray) -> np.ndarray:
        return np.floor(a / COUNT) * COUNT - a + COUNT / 2.0  # zero-mean sawtooth

    sampled = float(np.mean(error(theta) * error(moved)))
    assert autocorrelation(np.array([(s_counts * COUNT) ** 2]), COUNT)[0] == pytest.approx(sampled, abs=2e-3 * COUNT**2)
