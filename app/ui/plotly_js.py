"""Plotly.js for the page: the official *basic* bundle (scatter, bar, pie) instead of the full one.

Viser sends ``plotly.min.js`` (the full bundle, 4.8 MB; ≈1.7 MB after viser's zstd) over the
websocket the first time a client gets a plot widget — on this page that was ≈86 % of the bytes
to open it. Every figure of the page uses only ``scatter`` and ``bar`` traces with core layout
features (annotations, shapes, updatemenus, sliders, transitions), all of which the basic bundle
carries (1.2 MB; ≈0.45 MB after zstd). The bundle is plotly.js's own ``plotly.js-basic-dist-min``
of the same version as the plotly.js inside the installed plotly package (MIT licence, see
``assets/plotly-basic.LICENSE``); a test checks both the version and the trace types in use.

Call :func:`use_basic_plotly` once per client, before its first ``gui.add_plotly``.

With the bundle goes :data:`REACT_JS`: viser's plot widget calls ``Plotly.react`` once before its
box is measured (layout width 0) and again for every prop change until it is; Plotly lays such a
figure out at its default 700×450 px, all for nothing. On page open that was two whole draws of
the overview (≈ 0.7 s, cold) before the one at the real width; a plot in a hidden tab (width 0)
is now drawn when its tab is shown. The overview's height follows the window from its first draw
(viser's height is width × the aspect the server sets once the page has reported its window:
one more whole draw on page open).
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import viser

from pmsm_commissioning.app.ui.viser_adapter import mark_plotly_js_sent, plotly_js_sent, run_script

BUNDLE = Path(__file__).resolve().parent / "assets" / "plotly-basic.min.js"
#: Trace types the basic bundle draws (scatter comes with plotly.js's core).
TRACE_TYPES = frozenset({"scatter", "bar", "pie"})


@functools.cache
def bundle_source() -> str:
    """Text of the basic bundle, read once per process."""
    return BUNDLE.read_text(encoding="utf-8")


#: Wraps ``Plotly.react`` (``assets/plotly_react.js``): a call with layout width 0 (a box not measured
#: yet) draws nothing; a figure with ``layout.meta.fit_height = [chrome, least, most]`` is as tall
#: as the window's height less ``chrome`` [px], within [least, most] × its width (the height
#: :func:`app.ui.layout.layout_for_window` gives it with the server's aspect, known here on the first
#: draw instead of after the window report); a call with the data, layout and config of the last
#: one draws nothing; a figure waits until the last one drawn is painted (the light overview is
#: seen before the one with its replay) and a static one (a slider's) for the next animation
#: frame; of the figures waiting only the latest is drawn.
REACT_JS = (Path(__file__).resolve().parent / "assets" / "plotly_react.js").read_text(encoding="utf-8")


def bundle_version() -> str:
    """plotly.js version stated in the bundle's header (e.g. ``"4.1.1"``)."""
    match = re.search(r"plotly\.js \(basic - minified\) v(\d+\.\d+\.\d+)", bundle_source()[:400])
    if match is None:
        raise ValueError(f"{BUNDLE.name}: no 'plotly.js (basic - minified) vX.Y.Z' header")
    return match.group(1)


def use_basic_plotly(gui: viser.GuiApi) -> None:
    """Send the basic plotly.js bundle to this client instead of viser's full one.

    Must run before the client's first ``add_plotly`` (viser sends the full bundle then, once,
    unless viser's own flag says plotly.js is sent: :mod:`app.ui.viser_adapter`).
    """
    if plotly_js_sent(gui):
        return
    run_script(gui, bundle_source() + "\n" + REACT_JS)
    mark_plotly_js_sent(gui)


__all__ = ["BUNDLE", "REACT_JS", "TRACE_TYPES", "bundle_source", "bundle_version", "use_basic_plotly"]
