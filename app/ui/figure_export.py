"""Figure export for slides and papers: SVG or a 1920×1080 PNG, drawn by the browser without the page's UI.

Both are laid out at 1280×720 (a 720p slide); the PNG is drawn at scale 1.5, so its 1920×1080 pixels
carry the page's 14 px text as 21 px, 14 px again on a 720p slide (at scale 1 it was 9 px there).

The modebar's camera button writes the plot as it is on screen (≈ 840×540 px, replay buttons
included). Here the server takes the figure of the run in force (the one it last sent, or for a
tab not shown yet the one it would send: :mod:`app.ui.tab_figures`), removes the interactive parts
(:data:`UI_KEYS`: the replay buttons and their inline frames, sliders) and sends it with the
image options to the page, where ``Plotly.toImage`` draws it off screen and the browser saves
it — no image library on the server. The figure need not be on screen (a folded tab works).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable
from typing import Any

import viser

from pmsm_commissioning.app.figures.style import EXPORT_SCALE, EXPORT_SIZE
from pmsm_commissioning.app.ui.viser_adapter import run_script

#: Layout keys of the interactive UI a figure carries in the page, left out of an export.
UI_KEYS: tuple[str, ...] = ("updatemenus", "sliders")
#: Export formats: key → (label, Plotly format).
FORMATS: dict[str, str] = {"svg": f"SVG (vector, {EXPORT_SIZE[0]}×{EXPORT_SIZE[1]})",
                           "png": f"PNG {EXPORT_SIZE[0] * EXPORT_SCALE:.0f}×{EXPORT_SIZE[1] * EXPORT_SCALE:.0f}"}
_ID = re.compile(r'"meta":\{"id":"([^"]+)"')


def figure_id(json_str: str) -> str | None:
    """Return ``layout.meta.id`` of a figure's JSON (None if it has none)."""
    match = _ID.search(json_str)
    return match.group(1) if match else None


def export_figure(json_str: str, fmt: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """Return (figure without its UI, ``Plotly.toImage`` options) for exporting a figure's JSON as ``fmt``.

    Parameters
    ----------
    json_str : str  The figure's Plotly JSON as the page shows it.
    fmt : str       "svg" or "png"; ValueError naming the allowed formats otherwise.
    """
    if fmt not in FORMATS:
        raise ValueError(f"export format = {fmt!r} is not offered: allowed {', '.join(FORMATS)}")
    spec = json.loads(json_str)
    layout = {k: v for k, v in spec.get("layout", {}).items() if k not in UI_KEYS}
    layout.pop("width", None)
    layout.pop("height", None)
    width, height = EXPORT_SIZE
    name = figure_id(json_str) or "figure"
    scale = EXPORT_SCALE if fmt == "png" else 1
    options = {"format": fmt, "width": width, "height": height, "scale": scale, "filename": name}
    return {"data": spec.get("data", []), "layout": layout}, options


def export_js(figure: dict[str, Any], options: dict[str, Any]) -> str:
    """Return the page script that draws ``figure`` off screen with ``options`` and saves the file."""
    payload = json.dumps({"figure": figure, "options": options}, separators=(",", ":"))
    return f"""(() => {{
  const job = {payload};
  Plotly.toImage(job.figure, job.options).then((url) => {{
    const a = document.createElement("a");
    a.href = url;
    a.download = `${{job.options.filename}}.${{job.options.format}}`;
    document.body.appendChild(a);
    a.click();
    a.remove();
  }});
}})();"""


class FigureExport:
    """Dropdown of the page's figures and one button per format, in the current GUI container.

    ``figures`` returns the Plotly JSON of each figure the page offers, of the run in force.
    """

    def __init__(self, gui: viser.GuiApi, figures: Callable[[], Iterable[str]]) -> None:
        self.gui, self._figures = gui, figures
        gui.add_markdown("Export a figure for slides: drawn again at full size, without the replay buttons.")
        self.choice = gui.add_dropdown("Figure", tuple(self.figures()) or ("—",))
        self.buttons = {}
        for fmt, label in FORMATS.items():
            button = gui.add_button(f"Save {label}", icon=viser.Icon.PHOTO)
            button.on_click(lambda _, fmt=fmt: self.export(fmt))
            self.buttons[fmt] = button

    def figures(self) -> dict[str, str]:
        """Map figure id → JSON of every figure of the page that has one (placeholders included)."""
        return {fid: j for j in self._figures() if (fid := figure_id(j)) is not None}

    def export(self, fmt: str) -> bool:
        """Send the chosen figure to the page to be saved as ``fmt``; False if it is not there."""
        figures = self.figures()
        self.choice.options = tuple(figures) or ("—",)
        json_str = figures.get(self.choice.value)
        if json_str is None:
            return False
        run_script(self.gui, export_js(*export_figure(json_str, fmt)))
        return True


__all__ = ["FORMATS", "UI_KEYS", "FigureExport", "export_figure", "export_js", "figure_id"]
