"""One source for every control law, with or without numba.

:func:`jitable` marks a scalar law as callable from numba-compiled code, where it is inlined
(``register_jitable(inline="always")``), while it stays an ordinary Python function for the
reference simulator, the derivations and the tests. Without numba it is the identity.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

F = TypeVar("F", bound=Callable[..., object])

try:
    from numba.extending import register_jitable as _register
except ImportError:  # pragma: no cover - numba is a dependency; the laws still run as plain Python
    _register = None


def jitable(fn: F) -> F:
    """Make ``fn`` inlinable into numba kernels; returns ``fn`` itself (plain Python unchanged)."""
    if _register is None:
        return fn
    return _register(inline="always")(fn)


__all__ = ["jitable"]
