"""Panel widths and plot height that fit the browser window (a 1280×720 projector up to wide screens).

The page's own CSS (:func:`page_css`) sizes the docked panels from the window width, so the
browser lays out their final widths on its very first frame: the control panel left
(:data:`CONTROL_WIDTH`, :data:`CONTROL_WIDTH_WIDE` above :data:`WIDE_WINDOW`), the 3D canvas
next to it (:data:`CANVAS_SPARE` wide while the 3D view is folded, :data:`SCENE_SHARE` of the
window while shown) and the results panel right, taking the rest. The rules override the pixel
widths viser writes on its docked regions, so nothing on the server has to guess the window.

Only the overview plot's height needs the window on the server (viser draws a plot at
``width × aspect``): a small script (:func:`window_report_js`) writes the window's CSS size into a
hidden text field whenever it changes, and :class:`WindowFit` refits the plot from it. The camera
messages are not used: their canvas size is the WebGL drawing buffer, scaled by the device pixel
ratio (and by viser's adaptive resolution), not the CSS size the panels are laid out in.
"""

from __future__ import annotations

import json
import re
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from pmsm_commissioning.app.figures.style import FONT_PX
from pmsm_commissioning.app.ui import page_hooks as hk
from pmsm_commissioning.app.ui.page_hooks import with_hooks

#: Canvas width while the 3D view is folded [px]: a gutter (the results panel takes the rest).
CANVAS_SPARE = 12.0
#: Share of the window width given to the 3D view when it is shown [-], and its least width [px].
SCENE_SHARE, SCENE_MIN = 0.22, 280.0
#: viser's gutter on each side of a docked region [px]; two regions: :data:`BORDERS`.
EDGE_GAP = 2.0
BORDERS = 4 * EDGE_GAP
#: Height of the handle bar above a docked region's panel [px] (measured).
REGION_HANDLE = 15.0
#: Width of a docked region folded to viser's rail [px] (without the gutters).
RAIL = 36.0
#: Control panel width [px] on windows up to WIDE_WINDOW px wide, and beyond.
CONTROL_WIDTH, CONTROL_WIDTH_WIDE, WIDE_WINDOW = 400.0, 440.0, 1600.0
#: Least width of the results panel [px] (narrow windows scroll rather than squash it).
RESULTS_MIN = 320.0
#: The compact tab row (:func:`page_css`): a tab's padding each side and the gap from its 14 px icon to
#: its label [em of the tab's 14 px text]. With viser's 0.9 em and 0.5 em the results panel's nine tabs
#: took 966 px, two lines in the 860 px of a 1280 px window; compact they take ≈ 822 px, one line.
TAB_PAD_EM, TAB_GAP_EM = 0.45, 0.25
#: Vertical space of the results panel not available to the overview plot [px]: panel header and
#: the tab strip at 14 px (≈ 46: one line, :data:`TAB_PAD_EM`), the key numbers (16 px, three lines at
#: 1280×720 with the stock drive ≈ 68), the "Replay t" slider below the plot (≈ 40), the folded "Paper
#: errata for this figure" header (≈ 35), paddings: nothing in the results panel scrolls at 1280×720
#: (235 left it 1 px too tall; measured, tests/browser/test_results_fit.py).
CHROME_HEIGHT = 240.0
#: Horizontal padding of the results panel around a plot [px] (measured: the plot box is the results
#: panel less 18.5 px at 1280 and at 1920 px; the page fits the height to the same rule from the first draw).
PLOT_PADDING = 18.5
#: Bounds of the overview plot's aspect (height / width) [-].
ASPECT_MIN, ASPECT_MAX = 0.42, 0.85
#: Window assumed until the browser reports its size [px].
DEFAULT_WINDOW = (1280.0, 720.0)
#: Window sizes accepted from the browser [px] (anything else is not a window and is ignored).
WINDOW_LIMITS = (100.0, 20000.0)
#: Longest page-address query the window report carries [characters].
MAX_ADDRESS = 200


@dataclass(frozen=True)
class PanelLayout:
    """Widths of the docked panels [px], the overview plot's aspect [-], the 3D view shown or not.

    ``plot_aspect`` is the plot's height / width.
    """

    control_width: float
    results_width: float
    plot_aspect: float
    show_3d: bool = False


def layout_for_window(width: float, height: float, show_3d: bool = False) -> PanelLayout:
    """Size the panels for a ``width`` × ``height`` [px] window, as :func:`page_css` does.

    The control panel keeps its width, the 3D canvas gets :data:`CANVAS_SPARE` (folded) or
    :data:`SCENE_SHARE` of the width (shown), the results panel the rest; the overview plot is as
    tall as the window allows below the panel header and the key numbers.
    """
    control = CONTROL_WIDTH_WIDE if width > WIDE_WINDOW else CONTROL_WIDTH
    canvas = max(SCENE_MIN, SCENE_SHARE * width) if show_3d else CANVAS_SPARE
    results = max(RESULTS_MIN, width - control - canvas - BORDERS)
    aspect = (height - CHROME_HEIGHT) / max(results - PLOT_PADDING, 1.0)
    return PanelLayout(control, results, round(min(ASPECT_MAX, max(ASPECT_MIN, aspect)), 3), show_3d)


def page_css(show_3d: bool = False) -> str:
    """Return the page's CSS: panel widths, hidden window-size field, no 3D canvas in the BLDC tabs, compact tabs.

    The docked regions, their shadows and the canvas between them get the widths of
    :func:`layout_for_window` for the window's width (``100%``: viser's dock root, the window).
    A docked region folded to its rail keeps viser's rail width and the others take the rest.
    viser first shows a new panel floating, for a frame or more, before its dock command applies:
    the results panel's floating window gets the place and width it will have docked, so it
    appears once, where it stays. The rules select the marks :func:`page_marks_js` sets, never by
    ``:has()``: with such a rule in the page, every forced layout (each text Plotly measures)
    re-styled the whole page.
    """
    gutters = 2 * EDGE_GAP
    canvas = f"max({SCENE_MIN:g}px, {100 * SCENE_SHARE:g}%)" if show_3d else f"{CANVAS_SPARE:g}px"
    root, canvas_box, tab = hk.DOCK_ROOT.selector, hk.DOCK_CANVAS.selector, hk.TAB.selector
    railed = "[data-app-rail-{}] " + root
    left, right = hk.DOCK_REGION.at("left"), hk.DOCK_REGION.at("right")
    return (
        "[data-app-bldc] canvas {visibility: hidden} "
        "[data-app-hidden] {display: none !important} "
        f"{tab} {{padding: 0 {TAB_PAD_EM:g}em !important}} "
        f"{hk.TAB_ICON.selector} {{margin-right: {TAB_GAP_EM:g}em !important}} "
        f"{root} {{--fit-left: {CONTROL_WIDTH + gutters:g}px; --fit-canvas: {canvas}; "
        f"--fit-right: max({RESULTS_MIN + gutters:g}px, calc(100% - var(--fit-left) - var(--fit-canvas)))}} "
        f"@media (min-width: {WIDE_WINDOW + 1:g}px) {{ {root} {{--fit-left: {CONTROL_WIDTH_WIDE + gutters:g}px}} }} "
        f"{railed.format('left')} {{--fit-left: {RAIL + gutters:g}px}} "
        f"{railed.format('right')} {{--fit-right: {RAIL + gutters:g}px}} "
        f'{left}, [data-app-fit="left"] {{width: var(--fit-left) !important}} '
        f'{right}, [data-app-fit="right"] {{width: var(--fit-right) !important}} '
        "[data-app-column] {width: 100% !important} "
        f"{canvas_box} {{left: var(--fit-left) !important; right: var(--fit-right) !important}} "
        f"[data-app-overview-window] {{left: auto !important; right: {EDGE_GAP:g}px !important; "
        f"top: {REGION_HANDLE:g}px !important; height: calc(100% - {REGION_HANDLE:g}px) !important; "
        f"width: calc(var(--fit-right) - {gutters:g}px) !important}}")


#: Page CSS: no text under 14 px in the page's controls (viser draws labels, buttons, tabs and slider
#: marks at 11–13 px): labels, inputs, buttons, tabs, slider marks (#4a4a4a on white: contrast
#: 8.9:1) and the readouts under the live-tuning sliders (``data-role="…-readout"``) at ``FONT_PX``.
LEGIBILITY_CSS = (
    f"{hk.SLIDER_MARK_LABEL.selector}{{color:#4a4a4a !important;font-size:{FONT_PX}px !important;opacity:1 !important}}"
    + ",".join((*(h.selector for h in (hk.SLIDER_VALUE_LABEL, hk.BUTTON_LABEL, hk.INPUT_LABEL, hk.INPUT,
                                       hk.SELECT_OPTION, hk.CHECKBOX_LABEL, hk.TOOLTIP)),
                "[data-role$='-readout']", hk.TAB.selector, f"{hk.TAB.selector} *", hk.TEXT.selector,
                f"{hk.TEXT.selector} label", hk.PAPER.selector))
    + f"{{font-size:{FONT_PX}px !important}}")


#: The page script of :func:`page_marks_js`, read once per process (its fields filled in per page).
_PAGE_MARKS_JS = with_hooks((Path(__file__).resolve().parent / "assets" / "page_marks.js").read_text(
    encoding="utf-8")).replace("SCENE_MIN_PX", f"{SCENE_MIN - 1:g}")


def page_marks_js(hidden_fields: Sequence[str]) -> str:
    """Return the page script that marks the elements :func:`page_css` styles (installed once per page).

    After every change of the page outside the plots (a mutation observer, before the next frame
    is drawn) it sets: ``data-app-bldc`` on ``<html>`` while a tab titled "BLDC…" is selected (viser
    mounts only the selected tab and marks it ``aria-selected``), ``data-app-rail-left``/``-right``
    while that docked region is folded to its rail, ``data-app-fit`` on the shadow before each
    docked region, ``data-app-column`` on the parent of each dock column,
    ``data-app-overview-window`` on the floating window holding the "Overview" tab, and
    ``data-app-hidden`` on the row of each text field of ``hidden_fields`` (their uuids: the fields
    the page's scripts report into; ``window.__appHideField(uuid)`` adds a field made later). It
    closes viser's notice of a software WebGL while no 3D view (a canvas wider than
    :data:`SCENE_MIN` − 1 px) is shown: it would cover the results' tab row and key numbers until
    closed, for a view not in use. In the next frame after such a change it also moves a slider's
    overlapping mark labels apart.
    """
    return _PAGE_MARKS_JS.replace("HIDDEN_FIELDS", json.dumps(list(hidden_fields)))


def hide_field_js(field_uuid: str) -> str:
    """Return a script hiding the row of the text field ``field_uuid`` too (after :func:`page_marks_js`)."""
    return f"window.__appHideField({json.dumps(field_uuid)});"


def install_css_js(css: str, style_id: str = "app-page-style") -> str:
    """Return a script putting ``css`` into the page's own ``<style>`` element ``style_id`` in the document head.

    There it holds whatever viser mounts or unmounts (a folded panel's content is unmounted).
    """
    sid = json.dumps(style_id)
    return (f"(() => {{ let s = document.getElementById({sid}); if (!s) {{"
            f" s = document.createElement('style'); s.id = {sid}; document.head.appendChild(s); }}"
            f" s.textContent = {json.dumps(css)}; }})();")


def window_report_js(probe_uuid: str) -> str:
    """Return a script reporting the window's CSS size ``"<width>x<height>"`` [px] to the server.

    It writes the size into the text field ``probe_uuid`` as if typed (so viser sends it), now and
    after every resize of the window, followed by the page address's query as the page opened with
    it (``" ?demo=…"``, at most :data:`MAX_ADDRESS` characters; nothing when there is none), read
    before any run rewrites the address (:func:`page_address`).
    """
    return with_hooks("""(() => {
  const uuid = UUID;
  const H = PAGE_HOOKS;
  const search = location.search.slice(0, MAX_ADDRESS);  // as opened: before a run rewrites it
  const setValue = Object.getOwnPropertyDescriptor(HTMLInputElement.prototype, 'value').set;
  let frame = 0;
  const report = () => {
    const label = [...document.querySelectorAll(H.FIELD_LABEL.sel)]
      .find(l => l.getAttribute(H.FIELD_LABEL.attr) === uuid);
    const input = label && label.closest(H.FIELD_ROW.sel).querySelector('input');
    if (!input) {  // not mounted yet: look again next frame (for at most ≈ 1 min)
      if (++frame < 3600) requestAnimationFrame(report);
      return;
    }
    const size = `${window.innerWidth}x${window.innerHeight}` + (search ? ` ${search}` : '');
    if (input.value === size) return;
    setValue.call(input, size);
    input.dispatchEvent(new Event('input', {bubbles: true}));
  };
  if (window.__reportWindow) window.removeEventListener('resize', window.__reportWindow);
  window.__reportWindow = () => { frame = 0; report(); };
  window.addEventListener('resize', window.__reportWindow);
  report();
})();""").replace("UUID", json.dumps(probe_uuid)).replace("MAX_ADDRESS", str(MAX_ADDRESS))


#: The window report: ``"<width>x<height>"`` [px], then the page address's query (if any).
_REPORT = re.compile(r"\s*(\d{1,6})x(\d{1,6})(?: (\?\S{0,MAX}))?\s*".replace("MAX", str(MAX_ADDRESS)))


def parse_window(text: str) -> tuple[float, float] | None:
    """Window size [px] from ``"<width>x<height>[ ?query]"``; None for anything else or out of :data:`WINDOW_LIMITS`."""
    match = _REPORT.fullmatch(text)
    if match is None:
        return None
    width, height = float(match.group(1)), float(match.group(2))
    lo, hi = WINDOW_LIMITS
    return (width, height) if lo <= width <= hi and lo <= height <= hi else None


def page_address(text: str) -> str:
    """Return the page address's query (``"?demo=…"``) the window report ``text`` carries; ``""`` if none.

    The address rides in the window report's message, not in a hidden field of its own: viser's
    page sends the value changes of a panel's widgets through one 50 ms throttle that keeps only
    the first and the latest message of a burst, so a third field written with the two reports
    at page open (window, page view) dropped the one in the middle — the window size.
    """
    match = _REPORT.fullmatch(text)
    return (match.group(3) or "") if match is not None else ""


class WindowFit:
    """Keeps one client's panels fitted to its window; ``apply(layout)`` pushes a new layout."""

    def __init__(self, apply: Callable[[PanelLayout], None], show_3d: bool = False) -> None:
        self._apply = apply
        self.window = DEFAULT_WINDOW
        self.layout = layout_for_window(*DEFAULT_WINDOW, show_3d)
        self._lock = threading.Lock()  # GUI messages arrive on viser's thread pool
        apply(self.layout)

    @property
    def show_3d(self) -> bool:
        """Whether the 3D view is shown."""
        return self.layout.show_3d

    def window_reported(self, text: str) -> None:
        """Refit when the window size the browser reported (``"<width>x<height>"`` [px]) changed."""
        size = parse_window(text)
        if size is None:
            return
        with self._lock:
            self.window = size
            self._refit(self.show_3d)

    def set_3d(self, show: bool) -> None:
        """Fold (False) or show (True) the 3D view."""
        with self._lock:
            self._refit(bool(show))

    def _refit(self, show_3d: bool) -> None:
        layout = layout_for_window(*self.window, show_3d)
        if layout != self.layout:
            self.layout = layout
            self._apply(layout)


__all__ = ["LEGIBILITY_CSS", "PanelLayout", "WindowFit", "hide_field_js", "install_css_js", "layout_for_window",
           "page_css", "page_address", "page_marks_js", "parse_window", "window_report_js"]
