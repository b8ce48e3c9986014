"""Array types of the annotations, written once.

``FloatArray`` is a float64 numpy array (a signal over samples, a matrix). ``FloatOrArray`` is the
argument of a scalar law that is also evaluated on whole signals (the figures, the identification): a
float in, a float out; a float64 array in, one out.
"""

from __future__ import annotations

from typing import TypeAlias, TypeVar

import numpy as np
import numpy.typing as npt

FloatArray: TypeAlias = npt.NDArray[np.float64]
FloatOrArray = TypeVar("FloatOrArray", float, FloatArray)

__all__ = ["FloatArray", "FloatOrArray"]
