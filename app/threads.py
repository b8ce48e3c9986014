"""One BLAS thread for the whole process: the drive's linear algebra is 2×2 … 6×6 matrices.

OpenBLAS by default starts a worker per core; for the tiny matrices of ``derive()`` (``expm`` of
the observer and loop models) a second thread costs more than it computes, and its spinning
worker takes the core that another client's simulation needs. Measured on a 2-core machine:
a warm comparison takes ≈ 290 ms CPU with the default BLAS pool and ≈ 30 ms with one thread.
"""

from __future__ import annotations

import scipy.linalg  # noqa: F401  (loads the BLAS library so threadpoolctl can find it)
from threadpoolctl import threadpool_limits

_limiter: object | None = None


def limit_blas_threads() -> None:
    """Limit every loaded BLAS library to one thread for the rest of the process (idempotent)."""
    global _limiter
    if _limiter is None:
        _limiter = threadpool_limits(limits=1, user_api="blas")
