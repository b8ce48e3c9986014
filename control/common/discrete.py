"""Exact zero-order-hold (ZOH) discretisation of a linear model, written once.

For x' = A·x + B·u with u held constant over each sample period T_s,

    x[k+1] = Φ·x[k] + Γ·u[k],   Φ = e^{A·T_s},   Γ = ∫₀^{T_s} e^{A·τ} dτ · B,

and both come from one matrix exponential of the block matrix (Van Loan's identity)

    exp([[A, B], [0, 0]]·T_s) = [[Φ, Γ], [0, I]].

One ``scipy.linalg.expm`` call per model and sample period. (The observer's integrator chain
has an exact finite series instead, :func:`control.fdsmc.observer.discrete_observer`; it agrees with
this function to ≈ 1e-16 relative.)
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from pmsm_commissioning.control.common.arrays import FloatArray


def block_exponential(M: np.ndarray) -> np.ndarray:
    """Return e^M of a square matrix [-] (one ``scipy.linalg.expm`` call).

    Parameters
    ----------
    M : numpy.ndarray
        n×n matrix (already multiplied by the sample period, so dimensionless).

    Returns
    -------
    numpy.ndarray
        n×n matrix exponential.
    """
    e: FloatArray = expm(M)
    return e


def zoh(A: np.ndarray, B: np.ndarray, T_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH equivalent (Φ, Γ) of x' = A·x + B·u for the sample period ``T_s``.

    Parameters
    ----------
    A : numpy.ndarray
        n×n system matrix [1/s].
    B : numpy.ndarray
        Input matrix, n or n×m [state unit / (input unit · s)].
    T_s : float
        Sample period [s], > 0.

    Returns
    -------
    Phi : numpy.ndarray
        n×n transition matrix e^{A·T_s} [-].
    Gamma : numpy.ndarray
        Input matrix of the same shape as ``B`` [state unit / input unit].
    """
    A = np.asarray(A, dtype=float)
    B_in = np.asarray(B, dtype=float)
    B2 = B_in.reshape(A.shape[0], -1)
    n, m = B2.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = A * T_s
    aug[:n, n:] = B2 * T_s
    E = block_exponential(aug)
    return E[:n, :n], E[:n, n:].reshape(B_in.shape)


__all__ = ["block_exponential", "zoh"]
