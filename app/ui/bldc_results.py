"""The BLDC tab's results: metrics, speed, torque per drive with its loaded-window ripple, anti-windup.

The figures live in the results panel's "BLDC figures" tab; choosing the "BLDC speed SMC" tab on
the left selects it (and choosing the position tab selects "Overview"): :func:`follow_tabs_js`.
The first screen holds what a comparison is read by (metrics, speed, torque per drive, and the
anti-windup comparison when asked for); σ_ω, the phase currents and the design figures (back-EMF,
dq_x coefficients, reachability) are in a folded folder below.
"""

from __future__ import annotations

from typing import Any

import viser

from pmsm_commissioning.app.figures.bldc_panels import make_antiwindup_figure, make_torque_grid_figure
from pmsm_commissioning.app.figures.bldc_speed_smc import make_currents_figure, make_sigma_figure, make_speed_figure
from pmsm_commissioning.app.figures.plain import placeholder_json
from pmsm_commissioning.app.io.bldc_view import metric_table
from pmsm_commissioning.app.ui.page_hooks import with_hooks
from pmsm_commissioning.app.ui.viser_adapter import add_figure, figure_json_of, set_figure_json
from pmsm_commissioning.sim.bldc.engine import LABELS, BldcComparison, BldcRunResult

#: Plot aspects (height / width) of the speed, torque-grid and anti-windup figures.
ASPECT_SPEED, ASPECT_TORQUE, ASPECT_AW, ASPECT_MORE = 0.55, 0.8, 0.6, 0.6


def _placeholder(gui: viser.GuiApi, figure_id: str, title: str, aspect: float) -> viser.GuiPlotlyHandle:
    return add_figure(gui, placeholder_json(figure_id, f"{title} — press “Simulate BLDC”"), aspect)


def comparison_json(comp: BldcComparison) -> tuple[str, str, str, str]:
    """JSON of the speed, torque-grid, σ_ω and phase-current figures of ``comp``."""
    makers = (make_speed_figure, make_torque_grid_figure, make_sigma_figure, make_currents_figure)
    speed, torque, sigma, currents = (figure_json_of(make(comp)) for make in makers)
    return speed, torque, sigma, currents


def metrics_markdown(comp: BldcComparison) -> str:
    """Return the side-by-side metrics as a Markdown table (shared rows with the CLI)."""
    rows = metric_table(comp)
    head = "| " + " | ".join(rows[0]) + " |"
    lines = [head, "|" + "---|" * len(rows[0])] + ["| " + " | ".join(r) + " |" for r in rows[1:]]
    names = "; ".join(f"**{r.controller}** = {LABELS[r.controller]}" for r in comp.runs)
    return "\n".join(lines) + f"\n\n{names}"


class BldcResults:
    """The figure widgets of one client's BLDC tab, in ``container`` (a results-panel tab or a folder)."""

    def __init__(self, gui: viser.GuiApi, container: Any, design: tuple[str, str, str]) -> None:
        with container:
            self.metrics = gui.add_markdown("No run yet — press **Simulate BLDC**.")
            self.speed = _placeholder(gui, "bldc_speed", "Speed", ASPECT_SPEED)
            self.torque = _placeholder(gui, "bldc_torque", "Torque per drive", ASPECT_TORQUE)
            self.antiwindup = _placeholder(gui, "bldc_antiwindup", "Anti-windup side by side", ASPECT_AW)
            self.antiwindup.visible = False
            with gui.add_folder("More: σ_ω, phase currents, back-EMF, dq_x, reachability", expand_by_default=False):
                self.sigma = _placeholder(gui, "bldc_sigma", "σ_ω", ASPECT_MORE)
                self.currents = _placeholder(gui, "bldc_currents", "Phase currents", ASPECT_MORE)
                self.emf, self.dqx, self.reach = (add_figure(gui, j, a) for j, a in zip(design, (0.6, 0.9, 0.6),
                                                                                        strict=True))

    def show_design(self, design: tuple[str, str, str]) -> None:
        """Show the back-EMF, a_x/θ_x and reachability figures (JSON)."""
        for handle, json_str in zip((self.emf, self.dqx, self.reach), design, strict=True):
            set_figure_json(handle, json_str)

    def show(self, comp: BldcComparison, pair: tuple[BldcRunResult, BldcRunResult] | None) -> None:
        """Show a comparison; ``pair`` = the paper drive with and without anti-windup, or None."""
        for handle, json_str in zip((self.speed, self.torque, self.sigma, self.currents), comparison_json(comp),
                                    strict=True):
            set_figure_json(handle, json_str)
        self.metrics.content = metrics_markdown(comp)
        if pair is not None:
            figure = make_antiwindup_figure(*pair, comp.params.gains.eps_lambda)
            set_figure_json(self.antiwindup, figure_json_of(figure))
        self.antiwindup.visible = pair is not None


def follow_tabs_js() -> str:
    """Page script: choosing a left-panel mode tab selects that mode's results tab on the right.

    "BLDC speed SMC" → "BLDC figures"; the position tab → "Overview". Installed once per page.
    """
    return with_hooks("""(() => {
  if (window.__appFollowTabs) return;
  window.__appFollowTabs = true;
  const H = PAGE_HOOKS;
  document.addEventListener("click", (ev) => {
    const tab = ev.target.closest ? ev.target.closest(H.TAB.sel) : null;
    const region = tab && tab.closest(H.DOCK_REGION.sel);
    if (!region || region.getAttribute(H.DOCK_REGION.attr) !== "left") return;
    const title = tab.getAttribute(H.TAB.attr) || tab.textContent.trim();
    const want = title.startsWith("BLDC") ? "BLDC figures" : title.startsWith("Position") ? "Overview" : null;
    if (want === null) return;
    setTimeout(() => {
      const target = [...document.querySelectorAll(H.TAB.sel)].find(t => t.getAttribute(H.TAB.attr) === want);
      if (target && target.getAttribute(H.SELECTED_TAB.attr) !== "true") {  // viser's dock tabs: Enter activates
        target.dispatchEvent(new KeyboardEvent("keydown", {key: "Enter", code: "Enter", bubbles: true}));
      }
    }, 0);
  }, true);
})();""")


__all__ = ["BldcResults", "comparison_json", "follow_tabs_js", "metrics_markdown"]
