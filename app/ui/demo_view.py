"""What the page shows, for the demo state: its tabs and the overview's zoom, reported and restored.

The tabs and the zoom live in the browser (viser keeps no selected tab on the server and offers no
call to select one; Plotly zooms in the page). A small script (``assets/page_view.js``) writes them
as JSON into a hidden text field whenever they may have changed — after a click or key press and
after the overview's axes changed — and :class:`PageViewProbe` keeps the last valid report
(:func:`app.ui.demo_state.loads_view`). Restoring selects the tabs in the page as a key press on
them would (:func:`select_tabs_js`) and sends the overview again with the saved axis ranges
(:func:`zoomed_json`); the figure carries them in ``layout.meta.zoom`` too, so the page reports
them as the zoom shown until the user changes it or a new run draws a new figure.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import viser

from pmsm_commissioning.app.ui.demo_state import MODE_TABS, RESULTS_TABS, PageView, loads_view
from pmsm_commissioning.app.ui.page_hooks import with_hooks
from pmsm_commissioning.app.ui.viser_adapter import figure_json_shown, run_script, set_figure_json, widget_id

#: Longest report read from the page [characters] (a view with every axis zoomed is ≈ 700).
MAX_REPORT = 4000
#: Delay between selecting the mode tab and the results tab [ms]: choosing a mode tab selects its own
#: results tab first (:func:`app.ui.bldc_results.follow_tabs_js`).
RESULTS_TAB_DELAY_MS = 80
_REPORT_JS = with_hooks((Path(__file__).resolve().parent / "assets" / "page_view.js").read_text(encoding="utf-8"))


def view_report_js(field_uuid: str) -> str:
    """Return the page script reporting the page's view into the text field ``field_uuid``."""
    return (_REPORT_JS.replace("UUID", json.dumps(field_uuid)).replace("MODE_TABS", json.dumps(MODE_TABS))
            .replace("RESULTS_TABS", json.dumps(RESULTS_TABS)))


def select_tabs_js(view: PageView) -> str:
    """Return the page script selecting ``view``'s mode tab, then its results tab (None: left as is).

    viser's dock tabs take Enter on the focused tab as a choice: the script sends that key to each.
    """
    return with_hooks("""(([mode, results, delay]) => {
  const H = PAGE_HOOKS;
  const press = (title) => {
    const tab = [...document.querySelectorAll(H.TAB.sel)].find(t => t.getAttribute(H.TAB.attr) === title);
    if (tab && tab.getAttribute(H.SELECTED_TAB.attr) !== 'true') {
      tab.dispatchEvent(new KeyboardEvent('keydown', {key: 'Enter', code: 'Enter', bubbles: true}));
    }
  };
  if (mode !== null) press(mode);
  if (results !== null) setTimeout(() => press(results), delay);
})(ARGS);""").replace("ARGS", json.dumps([view.mode_tab, view.results_tab, RESULTS_TAB_DELAY_MS]))


def zoomed_json(figure_json: str, zoom: dict[str, tuple[float, float]]) -> str:
    """Return the Plotly JSON ``figure_json`` with the axes of ``zoom`` at its ranges (axis name → [min, max]).

    Axes the figure does not have are left out; ``layout.meta.zoom`` records the ranges applied.
    """
    figure = json.loads(figure_json)
    layout = figure.setdefault("layout", {})
    applied = {name: [lo, hi] for name, (lo, hi) in zoom.items() if isinstance(layout.get(name), dict)}
    for name, pair in applied.items():
        layout[name] = {**layout[name], "range": pair, "autorange": False}
    layout["meta"] = {**layout.get("meta", {}), "zoom": applied}
    return json.dumps(figure, separators=(",", ":"))


class PageViewProbe:
    """The hidden field the page reports its view into; :attr:`view` is the last valid report.

    Listeners added with :meth:`on_view` get each valid report after :attr:`view` holds it (viser
    runs each callback of a field as its own task: one added to the field itself could read the
    view before it changed).
    """

    def __init__(self, gui: viser.GuiApi) -> None:
        self._gui = gui
        self.view = PageView()
        self._listeners: list[Callable[[PageView], None]] = []
        self.field = gui.add_text("page view", "")
        self.field.on_update(lambda _: self._reported(self.field.value))
        run_script(gui, view_report_js(widget_id(self.field)))

    def on_view(self, listener: Callable[[PageView], None]) -> None:
        """Call ``listener(view)`` after each valid report of the page's view."""
        self._listeners.append(listener)

    def _reported(self, text: str) -> None:
        if len(text) > MAX_REPORT:
            return
        try:
            self.view = view = loads_view(text, "page view")
        except ValueError:
            return  # not a view (the page writes only views): the last one stays
        for listener in self._listeners:
            listener(view)

    def select_tabs(self, view: PageView) -> None:
        """Select ``view``'s tabs in the page."""
        run_script(self._gui, select_tabs_js(view))

    @staticmethod
    def zoom(phase: viser.GuiPlotlyHandle, zoom: dict[str, tuple[float, float]]) -> None:
        """Send the overview figure shown again with the axes of ``zoom`` at its ranges (none: nothing sent)."""
        if zoom:
            set_figure_json(phase, zoomed_json(figure_json_shown(phase), zoom))


__all__ = ["PageViewProbe", "select_tabs_js", "view_report_js", "zoomed_json"]
