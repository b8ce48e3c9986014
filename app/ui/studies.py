"""The studies beyond the paper in the position-drive page: optimum toggle, robustness, multi-axis.

* :class:`OptimumToggle` (left panel): when ticked, every Simulate also runs the tracked
  minimum-energy optimum (:mod:`control.fdsmc.optimum`), drawn as a third trajectory, time-plot
  line and energy bar, and the share of each controller's energy it would save is shown.
* :class:`StudiesSection` adds the "Studies" result tab with its "Robustness" and "Multi-axis" tabs
  (:mod:`app.ui.studies_robustness`, :mod:`app.ui.studies_multiaxis`). Their runs go to the
  session's worker like every Simulate (one job per client at a time) as studies: they wait for a
  server-wide slot (:mod:`app.ui.studies_queue`) and can be cancelled, queued or running.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Any

import viser

from pmsm_commissioning.app.figures.fdsmc_comparison import LABELS
from pmsm_commissioning.app.figures.fdsmc_energy import optimum_gaps
from pmsm_commissioning.app.ui.case import CasePort
from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.studies_multiaxis import MultiAxisView
from pmsm_commissioning.app.ui.studies_robustness import RobustnessView
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.sim.fdsmc.engine import OPTIMUM_OMITTED
from pmsm_commissioning.sim.fdsmc.optimum_gap import OPTIMUM_BASIS


def optimum_markdown(comparison: Any) -> str:
    """One line: the optimum's energy [J] and the share of each controller's it would save [%]."""
    opt = getattr(comparison, "optimum", None)
    if opt is None:  # left out (its solvers failed): say why
        return " ".join(md_text(n) for n in getattr(comparison, "notes", ()) if n.startswith(OPTIMUM_OMITTED))
    w = getattr(opt.metrics, OPTIMUM_BASIS)
    gaps = optimum_gaps(comparison)
    parts = [f"{LABELS[k]}'s by **{v:.1f} %**" for k, v in gaps.items() if v is not None]
    head = f"Optimum (tracked): **{w:.4g} J** net electrical input" if isinstance(w, float) else "Optimum (tracked)"
    supply = [f"{LABELS[k]}'s by {v:.1f} %" for k, v in optimum_gaps(comparison, supply=True).items() if v is not None]
    link = md_text(comparison.derived.params.controller.dc_link)
    return head + ("; it undercuts " + ", ".join(parts) + "." if parts else " (no stable comparison).") + (
        f" From the supply (DC link {link}): " + ", ".join(supply) + "." if supply else "")


class OptimumToggle:
    """Checkbox "Show the minimum-energy optimum" and a line of numbers under it."""

    def __init__(self, gui: viser.GuiApi, on_change: Callable[[], Any]) -> None:
        self.checkbox = gui.add_checkbox(
            "Show the minimum-energy optimum", True,
            hint="Also simulate the true minimum-energy move (copper + friction + load, torque limit) tracked "
                 "in closed loop, and the stock drive's trapezoid: on by default (≈ 2× the CPU of a Simulate); "
                 "the optimum is drawn in green as a third trajectory, line and bar")
        self.checkbox.on_update(lambda event: on_change() if event.client is not None else None)
        self.numbers = gui.add_markdown("")

    @property
    def wanted(self) -> bool:
        """True when the optimum should be simulated with the two controllers."""
        return bool(self.checkbox.value)

    def show(self, comparison: Any) -> None:
        """Return the optimum's numbers of the comparison shown (empty without an optimum run)."""
        assign(self.numbers, content=optimum_markdown(comparison))


class StudiesSection:
    """The "Studies" tab of a session's results panel: "Robustness" and "Multi-axis".

    ``port`` is the position tab's :class:`~app.ui.case.CasePort`: the studies read the simulated
    inputs (``port.case.params``), run on its worker (``submit``, ``checkpoint``, ``cancel``) and
    report on its status line (``say``). ``as_study(label)`` marks the submissions in its block as
    the study ``label`` (:meth:`app.ui.worker.Worker.as_study`); a robustness pool starts at most
    ``processes`` workers.
    """

    def __init__(self, port: CasePort, as_study: Callable[[str], AbstractContextManager[Any]],
                 processes: int) -> None:
        with port.results_tab("Studies", viser.Icon.FLASK):  # one tab: the results' tab row stays one line
            tabs = port.client.gui.add_tab_group()
            with tabs.add_tab("Robustness", viser.Icon.CHART_HISTOGRAM):
                self.robustness = RobustnessView(port, as_study, processes)
            with tabs.add_tab("Multi-axis", viser.Icon.ARROWS_MAXIMIZE):
                self.multiaxis = MultiAxisView(port, as_study)

    def queued(self, label: str, text: str) -> None:
        """Show ``text`` (markdown) in the status of the study ``label`` while it waits for a slot."""
        for view in (self.robustness, self.multiaxis):
            if label == view.LABEL:
                view.status.content = text


__all__ = ["OptimumToggle", "StudiesSection", "optimum_markdown"]
