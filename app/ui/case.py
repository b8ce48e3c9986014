"""The case one browser tab works on, and the narrow interface its panels act through.

:class:`Case` is a frozen snapshot — parameters, origin, comparison, error, runs. The position tab
(:class:`app.ui.position_tab.PositionTab`) is the only writer: it replaces the snapshot in its
:class:`CaseState` when inputs are committed, a run finishes or an input is refused. The other panels
(drive log, studies) receive a :class:`CasePort`: they read the snapshot and ask for actions; none of
them holds another panel or writes the case.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Any, Protocol

import viser

from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import Comparison


@dataclass(frozen=True)
class Case:
    """What one browser tab shows of the position drive.

    Attributes
    ----------
    params : DriveParams
        The committed inputs (the last simulated, designed or imported ones; SI units).
    origin : str
        The preset name or file they came from, e.g. ``"siemens_1ft7044_ak7 + identified from log.csv"``.
    comparison : Comparison
        The simulated comparison shown (the derivations alone for an infeasible case).
    error : str or None
        The last input refusal, None after a successful run.
    runs : int
        Runs (simulations and designs) done in this tab.
    plant_J_L : float or None
        The plant's load inertia [kg·m²] of the run shown when it differs from the controller's
        model ``params.load.J_L`` (the live-tuning J_L slider); None: the plant is the model.
    """

    params: DriveParams
    origin: str
    comparison: Comparison
    error: str | None = None
    runs: int = 0
    plant_J_L: float | None = None


class CaseState:
    """Holder of the current :class:`Case`; each change replaces the snapshot whole."""

    def __init__(self, case: Case) -> None:
        self._case = case

    @property
    def current(self) -> Case:
        """Return the current snapshot (frozen: readers cannot change it)."""
        return self._case

    def ran(self, params: DriveParams, comparison: Comparison, plant_J_L: float | None = None) -> Case:
        """Record a finished run of ``params`` (plant J_L ``plant_J_L`` [kg·m²] if not the model's)."""
        self._case = dataclasses.replace(self._case, params=params, comparison=comparison, error=None,
                                         runs=self._case.runs + 1, plant_J_L=plant_J_L)
        return self._case

    def opened(self, params: DriveParams, origin: str) -> Case:
        """Record inputs shown from ``origin`` (a preset, an import, identified values), not yet simulated."""
        self._case = dataclasses.replace(self._case, params=params, origin=origin)
        return self._case

    def refused(self, message: str) -> Case:
        """Record an input refusal (nothing was simulated)."""
        self._case = dataclasses.replace(self._case, error=message)
        return self._case


class CasePort(Protocol):
    """What a panel of the position tab may use: the client, the case (read) and these actions."""

    @property
    def client(self) -> viser.ClientHandle:
        """The browser tab's client (its ``gui`` and notifications)."""

    @property
    def case(self) -> Case:
        """The current case (a frozen snapshot)."""

    def submit(self, fn: Callable[[], None]) -> bool:
        """Run ``fn`` on the tab's worker; False (with a note) if busy."""

    def checkpoint(self) -> None:
        """On the worker: raise Cancelled if the user cancelled the running job."""

    def cancel(self) -> bool:
        """Cancel the running job; False if nothing runs."""

    def on_cancel(self, hook: Callable[[], None]) -> Callable[[], None]:
        """Run ``hook`` when the running job is cancelled or the page closed; returns its remover."""

    def say(self, text: str) -> None:
        """Show ``text`` (markdown) on the tab's status line."""

    def collect_inputs(self) -> DriveParams:
        """Return the inputs shown, validated (InputError naming the field if not)."""

    def open_case(self, params: DriveParams, origin: str) -> None:
        """Show ``params`` in the inputs as coming from ``origin`` (not simulated yet)."""

    def run(self, params: DriveParams) -> None:
        """On the worker: simulate ``params`` and show the results."""

    def simulate(self) -> bool:
        """Commit the inputs shown and simulate them on the worker; False if not started."""

    def results_tab(self, title: str, icon: Any) -> AbstractContextManager[Any]:
        """Return a new tab of the results panel to add widgets in (``with port.results_tab(…):``)."""


__all__ = ["Case", "CasePort", "CaseState"]
