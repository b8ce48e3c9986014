"""The one check of a controller name against the controllers a mode simulates."""

from __future__ import annotations

from collections.abc import Sequence

from pmsm_commissioning.control.common.checks import ParameterError


def check_controller(controller: str, allowed: Sequence[str]) -> None:
    """Raise :class:`~control.common.checks.ParameterError` unless ``controller`` is one of ``allowed``.

    Parameters
    ----------
    controller : str             The requested controller.
    allowed : sequence of str    The controllers of the mode.
    """
    if controller not in allowed:
        raise ParameterError(f"controller = {controller!r} is not allowed: one of {', '.join(allowed)}")
