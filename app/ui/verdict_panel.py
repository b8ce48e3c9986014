"""The verdicts under the Simulate button: the warnings box (foldable) and the one-click remedies.

Shows the derivation's and the runs' warnings, the comparator notes and any input error in one
box (:func:`app.ui.text.warnings_html`), folded to one line over every later run when the user
ticks "Fold warnings to one line", and offers "Use recommended K" / "Use T_c" when the loop
analysis has a remedy.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import viser

from pmsm_commissioning.app.ui.props import assign
from pmsm_commissioning.app.ui.text import design_failure_items, warnings_html
from pmsm_commissioning.sim.fdsmc.engine import Comparison
from pmsm_commissioning.sim.fdsmc.verdicts import K_advice, T_c_advice, comparator_notes, run_warnings

#: What the warnings box shows: warnings, input error (or None) and grey notes.
WarningParts = tuple[list[str], str | None, list[str]]


class VerdictPanel:
    """Warnings box with its fold choice, and the remedy buttons, of one client."""

    def __init__(self, gui: viser.GuiApi, use_K: Callable[[], None], use_T_c: Callable[[], None]) -> None:
        # the remedies first, right under the lecture's controls (the first screen at 1280×720),
        # then the box: its height changes with the warnings, and nothing of the K demo sits below it
        self.use_k = gui.add_button("Use recommended K", visible=False, color="orange")
        self.use_k.on_click(lambda _: use_K())
        self.use_tc = gui.add_button("Use T_c,min", visible=False, color="orange")
        self.use_tc.on_click(lambda _: use_T_c())
        self._parts: WarningParts = ([], None, [])
        self.box = gui.add_html("")
        self.fold = gui.add_checkbox("Fold warnings to one line", False,
                                     hint="Keeps the warnings box folded over new runs; a click on its first "
                                          "line still opens it once")
        self.fold.on_update(lambda _: self.render())

    def render(self, parts: WarningParts | None = None) -> None:
        """Show the warnings (new ``parts``, or the last ones), folded to one line if the user asked."""
        if parts is not None:
            self._parts = parts
        items, error, notes = self._parts
        assign(self.box, content=warnings_html(items, error, notes, folded=bool(self.fold.value)))

    def reject(self, message: str) -> None:
        """Show an input error: nothing was simulated."""
        self.render(([], message, []))

    def design_failed(self, dd: Any, comparison: Comparison | None = None) -> None:
        """Show why a design (:class:`sim.fdsmc.design.DriveDesign`) is not clean, above the run's own warnings."""
        items = design_failure_items(dd)
        if comparison is not None:
            d = comparison.derived
            items += list(d.warnings) + run_warnings(comparison)
        self.render((items, None, comparator_notes(comparison) if comparison is not None else []))

    def show(self, comparison: Comparison, error: str | None, extra: list[str]) -> None:
        """Show the verdicts of ``comparison`` and its remedies (:func:`~sim.fdsmc.verdicts.K_advice`, T_c)."""
        d = comparison.derived
        items = list(d.warnings) + run_warnings(comparison) + extra
        if comparison.fdsmc is None:
            items.append("Not simulated: the manoeuvre is infeasible (see above).")
        self.render((items, error, comparator_notes(comparison)))
        k_rec = K_advice(comparison)
        assign(self.use_k, visible=k_rec is not None)
        if k_rec is not None:
            assign(self.use_k, label=f"Use recommended K = {k_rec:.4g} s/rad")
        T_c = T_c_advice(d)
        assign(self.use_tc, visible=T_c is not None)
        if T_c is not None:
            assign(self.use_tc, label=f"Use T_c = {T_c * 1e3:.4g} ms (damps the approach to θ_dem)")
