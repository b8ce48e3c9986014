"""One BLAS thread for the whole process: the drive's linear algebra is 2×2 … 8×8 matrices.

OpenBLAS by default starts a worker per core; for the tiny matrices of ``derive()`` (``expm`` of
the loop models, eigenvalues of the sampled loops) a second thread costs more than it computes,
and its spinning worker takes the core that another client's simulation needs. Measured on a
2-core machine: a warm comparison takes ≈ 290 ms CPU with the default BLAS pool and ≈ 30 ms with
one thread.

Two ways, both applied by :func:`limit_blas_threads`: the ``*_NUM_THREADS`` environment variables
(read by a BLAS library when it loads, so they cover numpy and scipy imported later, and cost
nothing — the CLI sets them before importing numpy), and ``threadpoolctl`` for libraries already
loaded (it scans the process's shared libraries, ≈ 20–60 ms, so it runs only when numpy is
already imported).

:func:`release_memory` hands memory freed by finished work back to the system: glibc keeps freed
heap pages of every thread's arena for reuse, so a server whose pages have closed would stay at its
peak size; ``malloc_trim`` returns them.
"""

from __future__ import annotations

import contextlib
import ctypes
import gc
import os
import sys

#: Environment variables read by the BLAS / OpenMP libraries numpy and scipy may load.
THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")

_limiter: object | None = None


def limit_blas_threads() -> None:
    """Limit every BLAS library, loaded now or later, to one thread for this process (idempotent)."""
    global _limiter
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    if _limiter is None and "numpy" in sys.modules:
        import scipy.linalg  # noqa: F401  (loads scipy's BLAS so that threadpoolctl limits it too)
        from threadpoolctl import threadpool_limits

        _limiter = threadpool_limits(limits=1, user_api="blas")


def release_memory() -> None:
    """Collect garbage and return the C heap's free pages to the system (glibc; elsewhere only the collection)."""
    gc.collect()
    with contextlib.suppress(OSError, AttributeError):  # not glibc: nothing to trim
        ctypes.CDLL("libc.so.6").malloc_trim(0)
