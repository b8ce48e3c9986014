"""Compiled kernels against the same code as plain Python: the child run and the field-by-field comparison.

numba reads ``NUMBA_DISABLE_JIT`` at import, so the plain-Python side runs a test module's own
``__main__`` (``run_cases(seed, n)`` dumped as JSON) in a child process.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def plain_python_cases(script: str, seed: int, n: int, timeout: float) -> list[dict]:
    """Run ``script``'s cases ``seed``, ``n`` with NUMBA_DISABLE_JIT=1 in a child; return their metrics."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, script, str(seed), str(n)], capture_output=True, text=True, env=env,
                       cwd=ROOT, check=True, timeout=timeout)
    return json.loads(r.stdout)


def disagreements(a: dict, b: dict, rel_tol: float, abs_tol: float) -> dict:
    """Return {field: (a, b)} for every field of ``a`` that ``b`` does not match (floats within the tolerances)."""
    def same(x: object, y: object) -> bool:
        if isinstance(x, float) and isinstance(y, float):
            return math.isclose(x, y, rel_tol=rel_tol, abs_tol=abs_tol) or (math.isinf(x) and x == y)
        return x == y

    return {k: (a[k], b.get(k)) for k in a if not same(a[k], b.get(k))}
