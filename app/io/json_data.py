"""The one conversion of results to JSON data: the edge every ``--json``, export and file shares.

JSON has no NaN or infinity: a non-finite float (a limit that does not exist, a run that diverged)
becomes ``null``. Frozen result dataclasses become objects keyed by their field names, numpy
scalars become Python numbers; containers are converted recursively.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np


def to_json(value: Any) -> Any:
    """JSON-safe plain data of ``value`` (see the module docstring).

    Parameters
    ----------
    value : Any
        A dataclass instance, dict, list, tuple, number, string, bool or None.

    Returns
    -------
    Any
        Dicts (string keys), lists, finite floats, ints, strings, bools and None only.
    """
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_json(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
