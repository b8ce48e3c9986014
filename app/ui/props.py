"""Property updates that send only what changed.

Viser sends every assignment to a widget property to the browser, equal or not, and the page
re-renders the widget for each. A run of the live-tuning loop sets a dozen properties (status,
notes, tables, slider bounds), most of them unchanged from the run before; :func:`assign` skips
those.
"""

from __future__ import annotations

from typing import Any


def assign(handle: Any, **values: Any) -> None:
    """Set each property ``name=value`` of a viser handle that differs from its current value."""
    for name, value in values.items():
        if getattr(handle, name) != value:
            setattr(handle, name, value)


__all__ = ["assign"]
