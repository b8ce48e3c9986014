"""Input checks of the page's choices: a dropdown value must be one the server offered (no viser here)."""

from __future__ import annotations

from pmsm_commissioning.control.common.checks import ParameterError


def checked_choice(value: object, options: tuple[str, ...] | list[str], label: str) -> str:
    """Check a dropdown value the server received against the options it offered.

    Raises
    ------
    ParameterError
        When a (hostile or stale) client sent a value that was never offered.
    """
    if not isinstance(value, str) or value not in options:
        shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:80] + "…"
        raise ParameterError(f"{label} = {shown} is not one of the offered options: allowed {', '.join(options)}")
    return value


__all__ = ["checked_choice"]
