"""Flat arrays of a compiled kernel declared by name: each slot once, its index generated.

A numba kernel takes its parameters, state and results as flat float arrays, and reads them by
module-level integer constants (numba folds those into the compiled code, so a named index costs
nothing). :class:`Layout` generates the constants from one ordered declaration: each
:meth:`Layout.slot` call names a slot, says what it holds (with its unit) and returns the next
index, so no index is ever typed as a number and a new slot is one line. A slot without a default
must be written by the packer: :meth:`Layout.empty` starts such slots at NaN and
:meth:`Layout.check_filled` names every slot left unwritten, so a forgotten slot cannot pass as 0.

The constants' values depend on the declaration's order only; the kernels' on-disk cache is keyed on
every source file of the package (:mod:`sim`), so a changed declaration always recompiles them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Slot:
    """One named slot (or block of slots) of a flat array.

    Attributes
    ----------
    name : str
        The index constant's name (e.g. ``"P_RS"``).
    index : int
        Its first index in the array.
    size : int
        Number of consecutive values (1 for a scalar slot).
    doc : str
        What it holds, with its unit in brackets.
    default : float
        Its value when the packer does not write it; NaN: the packer must write it.
    """

    name: str
    index: int
    size: int
    doc: str
    default: float


class Layout:
    """An ordered declaration of a flat array's slots (built once, at import, by its module).

    Parameters
    ----------
    what : str
        The array's name in messages (e.g. ``"the FDSMC kernel's parameters"``).
    """

    def __init__(self, what: str) -> None:
        self.what = what
        self._slots: list[Slot] = []

    @property
    def size(self) -> int:
        """Number of values in the array."""
        return sum(s.size for s in self._slots)

    @property
    def slots(self) -> tuple[Slot, ...]:
        """The declared slots, in order."""
        return tuple(self._slots)

    def slot(self, name: str, doc: str, default: float = math.nan) -> int:
        """Declare the next scalar slot and return its index."""
        return self.block(name, 1, doc, default)

    def block(self, name: str, size: int, doc: str, default: float = math.nan) -> int:
        """Declare ``size`` consecutive values and return the first one's index."""
        if any(s.name == name for s in self._slots):
            raise ValueError(f"{self.what}: slot {name} declared twice")
        index = self.size
        self._slots.append(Slot(name, index, int(size), doc, float(default)))
        return index

    def empty(self) -> np.ndarray:
        """Return a new array with every slot at its default (NaN where the packer must write it)."""
        out = np.empty(self.size)
        for s in self._slots:
            out[s.index: s.index + s.size] = s.default
        return out

    def check_filled(self, values: np.ndarray) -> None:
        """Raise ValueError naming every slot of ``values`` still NaN (not written by the packer)."""
        missing = [s.name for s in self._slots if np.isnan(values[s.index: s.index + s.size]).any()]
        if missing:
            raise ValueError(f"{self.what}: not packed (NaN): {', '.join(missing)}")


__all__ = ["Layout", "Slot"]
