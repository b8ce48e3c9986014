"""Sensor models of the simulated drive: a quantized encoder and noisy, quantized current readings.

The controller sees only these readings; the simulated physics stays exact. The noise is read from
a seeded table of standard-normal samples (:func:`noise_table`), indexed by the sample number, so
that the compiled kernel and the plain-Python reference see the very same sequence.

Scalar laws are :func:`control.common.jit.jitable`: inlined by the compiled kernels, plain Python
for the reference.
"""

from __future__ import annotations

import math

import numpy as np

from pmsm_commissioning.control.common.jit import jitable
from pmsm_commissioning.control.fdsmc.params import Sensors

#: Samples per noise channel [-]: 2¹⁷, 6.6 s of distinct noise at 20 kHz (then it repeats).
NOISE_SAMPLES = 2**17
#: Noise channels: the measured i_d and i_q.
NOISE_CHANNELS = 2


def noise_table(sensors: Sensors) -> np.ndarray:
    """Standard-normal samples (NOISE_CHANNELS × NOISE_SAMPLES) of the seeded sequence [-].

    An all-zero 2 × 1 table when the currents are measured without noise.
    """
    if sensors.i_noise == 0.0:
        return np.zeros((NOISE_CHANNELS, 1))
    return np.random.default_rng(sensors.seed).standard_normal((NOISE_CHANNELS, NOISE_SAMPLES))


@jitable
def encoder_angle(theta: float, step: float) -> float:
    """Angle the encoder reports for θ [rad]: whole counts, step·floor(θ/step); θ itself for step = 0."""
    return step * math.floor(theta / step) if step > 0.0 else theta


@jitable
def adc_current(i: float, noise: float, sigma: float, step: float, full_scale: float) -> float:
    """Return the current the ADC reports [A]: i + σ·noise, rounded to the ADC step and clipped at ±full scale.

    Parameters
    ----------
    i : float           True current [A].
    noise : float       Standard-normal sample [-].
    sigma : float       Noise rms [A].
    step : float        ADC step [A]; 0 = ideal (no rounding, no clipping).
    full_scale : float  ADC full-scale amplitude [A].
    """
    x = i + sigma * noise
    if step <= 0.0:
        return x
    return min(max(step * math.floor(x / step + 0.5), -full_scale), full_scale)


__all__ = ["NOISE_CHANNELS", "NOISE_SAMPLES", "adc_current", "encoder_angle", "noise_table"]
