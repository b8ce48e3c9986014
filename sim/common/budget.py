"""One cost budget for every simulation request, checked before any work starts.

A request (one comparison of several controllers, a Table-1 sweep, a BLDC comparison) costs

* **integration steps** — every RK4 step the kernels take, sub-steps included, summed over the
  controllers (and sweep points) of the request; CPU time is proportional to it;
* **trace bytes** — the arrays the kernels fill and the traces built from them; peak memory is
  proportional to it.

Both are computed from the parameters alone (no derivation, no allocation) and compared with
:data:`MAX_STEPS` and :data:`MAX_TRACE_BYTES`. A request whose cost model also predicts CPU seconds
and peak memory (the position drive, :func:`sim.fdsmc.grid.predict`: controller samples, RK4
sub-steps and full-resolution chatter-window samples; the BLDC drive, :func:`sim.bldc.engine.run_cost`:
samples, sub-steps and trace bytes; both calibrated by ``scripts/bench_budget.py [--bldc]`` to
within 2× of measured runs) is held to the promised figures themselves: ≤ :data:`MAX_CPU_S`
CPU seconds and ≤ :data:`MAX_TRACE_BYTES` of memory above the idle process. A request over budget
raises :class:`BudgetError` naming the fields that drive the cost and, for each, the largest (or
smallest) value that fits with the other values kept.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError

#: Most RK4 integration steps of one request, sub-steps and all controllers included [-].
#: The bound for engines without a calibrated CPU model; the position and BLDC drives are held to
#: :data:`MAX_CPU_S` by their models as well.
MAX_STEPS = 40_000_000
#: Most bytes of trace memory of one request (kernel output arrays and the traces built from them).
MAX_TRACE_BYTES = 256 * 2**20


#: Most CPU seconds a request may be predicted to take (the promise of the page and the CLI).
MAX_CPU_S = 3.0
#: Cost model of the position drive, fitted by ``scripts/bench_budget.py`` (one core, compiled
#: kernels, the three controllers of ``compare``): CPU seconds per RK4 step beyond the first of a
#: sample, per controller sample (its first RK4 step, controller, observer, trace), per
#: full-resolution chatter-window sample (recorded and analysed), and per run (derivation, metrics).
CPU_PER_STEP_S = 2.0e-8
CPU_PER_SAMPLE_S = 1.1e-7
CPU_PER_WINDOW_SAMPLE_S = 2.0e-7
CPU_PER_RUN_S = 0.025
#: Bytes per controller sample (no full-rate array is kept: 0), of analysis temporaries per
#: chatter-window sample, and fixed bytes per run (parameter arrays, sensor-noise tables) [B].
MEM_PER_SAMPLE = 0
MEM_PER_WINDOW_SAMPLE = 21
MEM_PER_RUN = 2 * 2**20


def cpu_seconds(steps: int, samples: int, window: int, runs: int) -> float:
    """Predicted CPU time [s] of a request (RK4 steps, controller samples, chatter-window samples, runs)."""
    return (CPU_PER_STEP_S * max(0, steps - samples) + CPU_PER_SAMPLE_S * samples
            + CPU_PER_WINDOW_SAMPLE_S * window + CPU_PER_RUN_S * runs)


def memory_bytes(trace_bytes: int, window: int, runs: int, samples: int = 0) -> int:
    """Predicted peak memory [B] above the idle process: traces, full-rate and window arrays, per-run arrays."""
    return int(trace_bytes + MEM_PER_SAMPLE * samples + MEM_PER_WINDOW_SAMPLE * window + MEM_PER_RUN * runs)


class BudgetError(ParameterError):
    """A request whose cost exceeds the budget; the message names the fields and the largest value."""


@dataclass(frozen=True)
class Cost:
    """Cost of one request.

    Attributes
    ----------
    steps : int         RK4 integration steps, all controllers and sub-steps [-].
    trace_bytes : int   Bytes of trace memory [B].
    cpu_s : float or None         Predicted CPU time [s], when the engine has a calibrated model.
    memory_bytes : int or None    Predicted peak memory above the idle process [B], likewise.
    """

    steps: int
    trace_bytes: int
    cpu_s: float | None = None
    memory_bytes: int | None = None

    def __add__(self, other: Cost) -> Cost:
        """Add two costs field by field (a prediction only when both have one)."""
        both = self.cpu_s is not None and other.cpu_s is not None
        return Cost(self.steps + other.steps, self.trace_bytes + other.trace_bytes,
                    (self.cpu_s or 0.0) + (other.cpu_s or 0.0) if both else None,
                    (self.memory_bytes or 0) + (other.memory_bytes or 0) if both else None)

    @property
    def fits(self) -> bool:
        """True when every figure is within the budget (the predicted CPU and memory too, if known)."""
        base = self.steps <= MAX_STEPS and self.trace_bytes <= MAX_TRACE_BYTES
        if self.cpu_s is None or self.memory_bytes is None:
            return base
        return base and self.cpu_s <= MAX_CPU_S and self.memory_bytes <= MAX_TRACE_BYTES


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
    if cost.cpu_s is not None and cost.memory_bytes is not None:
        return (f"≈ {cost.cpu_s:.2g} s CPU, {cost.memory_bytes / 2**20:.3g} MiB, {cost.steps:.3g} integration steps: "
                f"allowed ≤ {MAX_CPU_S:g} s, {MAX_TRACE_BYTES // 2**20} MiB, {MAX_STEPS:.3g} steps")
    return (f"{cost.steps:.3g} integration steps and {cost.trace_bytes / 2**20:.4g} MiB of traces: "
            f"allowed ≤ {MAX_STEPS:.3g} steps and ≤ {MAX_TRACE_BYTES // 2**20} MiB per request")


def _toward(value: float, limit: float) -> float:
    """``value`` to 4 significant digits, rounded towards ``limit`` (the cheap end) so that it still fits."""
    if value == 0.0 or not math.isfinite(value):
        return value
    unit = 10.0 ** (math.floor(math.log10(abs(value))) - 3)
    return (math.floor if limit < value else math.ceil)(value / unit) * unit


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
            hints.append(f"no {d.name} alone fits")
        else:
            shown = f"{int(best)}" if d.integer else f"{_toward(best, d.limit):.4g}"
            hints.append(f"{d.name} = {d.value:g} {d.unit}".rstrip() + f" → {word} accepted {shown} {d.unit}".rstrip())
    raise BudgetError(f"this run is too large ({what}): {_describe(cost)}. With the other values kept: "
                      + "; ".join(hints))


__all__ = ["MAX_CPU_S", "MAX_STEPS", "MAX_TRACE_BYTES", "BudgetError", "Cost", "Driver", "best_value", "check",
           "cpu_seconds", "memory_bytes"]
