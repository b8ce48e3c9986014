"""One source for every control law, with or without numba.

:func:`jitable` marks a scalar law as callable from numba-compiled code (``register_jitable``),
while it stays an ordinary Python function for the reference simulator, the derivations and the
tests. Without numba it is the identity.

The laws are compiled as functions of their own and inlined by LLVM, not by numba's IR inliner
(``inline="always"``): the IR inliner rebuilds SSA form across the inlined body and lost a variable
assigned in a branch (``NumbaIRAssumptionWarning: variable … is not in scope``), so the compiled
kernel dropped the inverter's saturation flag that the plain-Python reference kept. Kernel speed
is the same either way (``pmsm-commission bench``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

F = TypeVar("F", bound=Callable[..., object])

try:
    from numba.extending import register_jitable as _register
except ImportError:  # pragma: no cover - numba is a dependency; the laws still run as plain Python
    _register = None  # type: ignore[assignment]


def jitable(fn: F) -> F:
    """Make ``fn`` inlinable into numba kernels; returns ``fn`` itself (plain Python unchanged)."""
    if _register is None:
        return fn
    return _register(fn)


__all__ = ["jitable"]
