"""One cost budget for every simulation request, checked before any work starts.

A request (one comparison of several controllers, a Table-1 sweep, a BLDC comparison) costs

* **integration steps** — every RK4 step the kernels take, sub-steps included, summed over the
  controllers (and sweep points) of the request; CPU time is proportional to it;
* **trace bytes** — the arrays the kernels fill and the traces built from them; peak memory is
  proportional to it.

Both are computed from the parameters alone (no derivation, no allocation) and compared with
:data:`MAX_STEPS` and :data:`MAX_TRACE_BYTES`. A request over budget raises
:class:`BudgetError` naming the fields that drive the cost and, for each, the largest (or
smallest) value that fits with the other values kept.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from control.fdsmc.params import ParameterError

#: Most RK4 integration steps of one request, sub-steps and all controllers included [-].
#: About 2–3 s of CPU for either kernel on one core (``python -m app bench`` prints the rates).
MAX_STEPS = 40_000_000
#: Most bytes of trace memory of one request (kernel output arrays and the traces built from them).
MAX_TRACE_BYTES = 256 * 2**20


class BudgetError(ParameterError):
    """A request whose cost exceeds the budget; the message names the fields and the largest value."""


@dataclass(frozen=True)
class Cost:
    """Cost of one request.

    Attributes
    ----------
    steps : int         RK4 integration steps, all controllers and sub-steps [-].
    trace_bytes : int   Bytes of trace memory [B].
    """

    steps: int
    trace_bytes: int

    def __add__(self, other: Cost) -> Cost:
        """Add two costs field by field."""
        return Cost(self.steps + other.steps, self.trace_bytes + other.trace_bytes)

    @property
    def fits(self) -> bool:
        """True when both figures are within the budget."""
        return self.steps <= MAX_STEPS and self.trace_bytes <= MAX_TRACE_BYTES


@dataclass(frozen=True)
class Driver:
    """A field that drives the cost and how to vary it.

    Attributes
    ----------
    name : str            Dotted field name, e.g. ``"manoeuvre.T_m"``.
    value : float         The value the user gave.
    unit : str            Unit shown in the message.
    cost : callable       Cost of the request with this field set to a value (others kept).
    limit : float         The other end of the field's allowed range (bisection bracket).
    integer : bool        True for whole-number fields (pole pairs).
    """

    name: str
    value: float
    unit: str
    cost: Callable[[float], Cost]
    limit: float
    integer: bool = False


def _fits(driver: Driver, v: float) -> bool:
    try:
        return driver.cost(v).fits
    except (ParameterError, ArithmeticError):
        return False


def best_value(driver: Driver) -> float | None:
    """Return the value nearest the user's that fits the budget, the other fields kept.

    Searches between the field's permitted extreme ``driver.limit`` (where the cost is lowest)
    and the user's value (over budget) by bisection in log space; None when even the extreme is
    over budget.
    """
    good, bad = driver.limit, driver.value
    if not _fits(driver, good):
        return None
    for _ in range(60):
        if driver.integer:
            if abs(bad - good) <= 1:
                break
            mid = float(round(math.sqrt(good * bad)))
            mid = mid if mid not in (good, bad) else float(math.floor((good + bad) / 2))
        else:
            mid = math.sqrt(good * bad)
            if abs(bad - good) <= 1e-4 * abs(good):
                break
        if _fits(driver, mid):
            good = mid
        else:
            bad = mid
    return good


def _describe(cost: Cost) -> str:
    return (f"{cost.steps:.3g} integration steps and {cost.trace_bytes / 2**20:.4g} MiB of traces: "
            f"allowed ≤ {MAX_STEPS:.3g} steps and ≤ {MAX_TRACE_BYTES // 2**20} MiB per request")


def check(cost: Cost, what: str, drivers: Sequence[Driver]) -> Cost:
    """Raise :class:`BudgetError` if ``cost`` is over budget; otherwise return it.

    Parameters
    ----------
    cost : Cost
        The request's cost.
    what : str
        Short description of the request, e.g. ``"2 controllers × 26 000 samples × 25 sub-steps"``.
    drivers : sequence of Driver
        The fields that drive the cost; each gets the value that would fit.
    """
    if cost.fits:
        return cost
    hints = []
    for d in drivers:
        best = best_value(d)
        word = "largest" if d.limit < d.value else "smallest"
        if best is None:
            hints.append(f"no value of {d.name} alone fits")
        else:
            shown = f"{int(best)}" if d.integer else f"{best:.4g}"
            hints.append(f"{d.name} = {d.value:g} {d.unit}".rstrip() + f" → {word} accepted {shown} {d.unit}".rstrip())
    names = ", ".join(d.name for d in drivers)
    raise BudgetError(f"this run is too large ({what}): it needs {_describe(cost)}. The cost grows with "
                      f"{names}; with the other values kept: " + "; ".join(hints))


__all__ = ["MAX_STEPS", "MAX_TRACE_BYTES", "BudgetError", "Cost", "Driver", "best_value", "check"]
