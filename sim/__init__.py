"""Closed-loop simulation: plant models, compiled kernels, energies, metrics, verdicts.

The compiled kernels inline the control laws of :mod:`control` (one implementation of each law).
numba's on-disk cache keys an entry on the kernel's own source file only, so an edited law in
``control/`` would leave a stale compiled kernel in use. Before any kernel is compiled, this package
therefore points numba's cache at a folder named after a hash of every ``control/`` and ``sim/``
source file: any edit selects a fresh folder and recompiles. The folder lies below
:func:`sim.numba_cache.cache_base` (``$NUMBA_CACHE_DIR``, a clone's ``.numba_cache``, else the user's
cache folder), never in site-packages.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numba

from pmsm_commissioning.sim.numba_cache import cache_base

_ROOT = Path(__file__).resolve().parent.parent


def source_hash() -> str:
    """SHA-256 (16 hex digits) of every Python source of ``control/`` and ``sim/`` (path and bytes)."""
    h = hashlib.sha256()
    for pkg in ("control", "sim"):
        for path in sorted((_ROOT / pkg).rglob("*.py")):
            h.update(str(path.relative_to(_ROOT)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _keyed_cache_dir() -> str:
    return str(cache_base() / f"src-{source_hash()}")


numba.config.CACHE_DIR = _keyed_cache_dir()  # type: ignore[attr-defined]  # set at run time
