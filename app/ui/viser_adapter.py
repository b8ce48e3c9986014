"""Every use of viser's private API, in one file (written for viser 1.1.1, pinned by a test).

The page needs four things viser's public API does not offer:

* **a figure sent once**: ``GuiApi.add_plotly`` queues a creation message whose properties are the
  very object the returned handle writes to, and then sets the figure (an update message). Until
  the creation message has left — on every page open, where the widgets and their figures are made
  in one go — each figure set on the widget therefore travels twice. :func:`add_figure` gives the
  handle its own copy of the properties right after creation, so the creation message keeps the
  empty figure and each figure goes out once; :func:`set_figure_json` sends ready-made Plotly JSON
  (``_plotly_json_str``, the property ``GuiPlotlyHandle.figure`` itself sets) and nothing when the
  figure is unchanged. Every figure of the page goes through these two functions.
* **a script run in the page** (:func:`run_script`, viser's own ``RunJavascriptMessage``);
* **plotly.js sent by the page** (:func:`plotly_js_sent`, :func:`mark_plotly_js_sent`: viser's
  ``GuiApi._setup_plotly_js`` flag, so ``add_plotly`` does not send its full bundle);
* **slider marks changed after creation** (:func:`set_slider_marks`: viser's ``_marks`` property,
  public only as ``add_slider(marks=…)``);
* **a widget's DOM id** (:func:`widget_id`: the uuid the page's CSS and scripts address);
* **checks in front of viser's message handlers** (:func:`wrap_gui_handler`, used by
  :mod:`app.ui.web_guard`: widget values type-checked, uploads bounded) and what they read: a
  widget by uuid (:func:`input_widget`), its state (:func:`widget_state`), the uploads in flight
  (:func:`upload_states`), the client of a message (:func:`resolve_client`), and in front of its
  loop reading each client's websocket frames (:func:`wrap_frame_reader`: a frame that is no message
  of the protocol is refused in one line, never a traceback in the server's log);
* **a check in front of every HTTP request and websocket handshake** (:func:`wrap_requests`: viser
  serves both through ``websockets.asyncio.server.serve`` and offers no hook for the handshake, so its
  ``process_request`` argument is wrapped while a server is being built);
* **viser's icons read at server start** (:func:`warm_icons`: its cached ``svg_from_icon``).

A viser upgrade is checked here and in ``tests/test_viser_adapter.py`` only.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
from collections.abc import Callable, Iterator
from typing import Any, Protocol

import viser
import viser._gui_api as _viser_gui
import viser.infra._infra as _viser_infra
import websockets.asyncio.server as ws_server
from viser import _icons, _messages

from pmsm_commissioning.app.figures.plain import blank_json

#: The viser release this adapter was written for (``tests/test_viser_adapter.py`` pins it).
WRITTEN_FOR = "1.1.1"


class _Figure(Protocol):
    def to_json(self) -> str: ...


class _ReadyFigure:
    """What ``GuiApi.add_plotly`` reads of a figure (``to_json()``), carrying ready-made JSON."""

    def __init__(self, json_str: str) -> None:
        self._json = json_str

    def to_json(self) -> str:
        """Return the figure's Plotly JSON."""
        return self._json


def add_figure(gui: viser.GuiApi, json_str: str | None = None, aspect: float = 1.0) -> viser.GuiPlotlyHandle:
    """Add a plot widget showing the Plotly JSON ``json_str`` (an empty figure if None); each figure is sent once."""
    handle = gui.add_plotly(_ReadyFigure(blank_json()), aspect=aspect)  # type: ignore[arg-type]
    handle._impl.props = dataclasses.replace(handle._impl.props)  # no longer the queued creation message's
    if json_str is not None:
        set_figure_json(handle, json_str)
    return handle


def set_figure_json(handle: viser.GuiPlotlyHandle, json_str: str) -> None:
    """Send a ready-made Plotly JSON string to a plot widget, unless it already shows exactly that."""
    if handle._plotly_json_str != json_str:
        handle._plotly_json_str = json_str


def figure_json_shown(handle: viser.GuiPlotlyHandle) -> str:
    """Return the Plotly JSON a plot widget last sent to the page."""
    return handle._plotly_json_str


def figure_json_of(figure: _Figure) -> str:
    """Return the Plotly JSON of a ``go.Figure`` exactly as ``GuiPlotlyHandle.figure`` would send it."""
    return figure.to_json()


def run_script(gui: viser.GuiApi, source: str) -> None:
    """Run the JavaScript ``source`` in the page of ``gui``'s client (viser's own script message)."""
    gui._websock_interface.queue_message(_messages.RunJavascriptMessage(source=source))


def plotly_js_sent(gui: viser.GuiApi) -> bool:
    """Return True once plotly.js is in this client's page (viser's own flag ``_setup_plotly_js``)."""
    return bool(getattr(gui, "_setup_plotly_js", False))


def mark_plotly_js_sent(gui: viser.GuiApi) -> None:
    """Record that plotly.js is in this client's page: ``add_plotly`` then sends no bundle of its own."""
    gui._setup_plotly_js = True


def widget_id(handle: Any) -> str:
    """Return the id of a GUI widget (the uuid its element carries in the page)."""
    return str(handle._impl.uuid)


def set_slider_marks(handle: viser.GuiSliderHandle, marks: tuple[tuple[float, str], ...]) -> None:
    """Show ``marks`` ((value, label) pairs) on a slider's track instead of its min/max labels.

    Nothing is sent when the slider already shows exactly these marks.
    """
    new = tuple(_messages.GuiSliderMark(value=float(v), label=label) for v, label in marks)
    if handle._impl.props._marks != new:
        handle._marks = new  # type: ignore[attr-defined]  # viser's props setter queues the update


#: viser's ``GuiApi`` message handlers that :mod:`app.ui.web_guard` puts its checks in front of.
GUI_UPDATES = "_handle_gui_updates"
UPLOAD_START, UPLOAD_PART = "_handle_file_transfer_start", "_handle_file_transfer_part"


def wrap_gui_handler(name: str, wrap: Any) -> None:
    """Put ``wrap(handler)`` in front of viser's ``GuiApi`` handler ``name``, once (every GUI created after)."""
    current = getattr(_viser_gui.GuiApi, name)
    if not hasattr(current, "__wrapped__"):
        setattr(_viser_gui.GuiApi, name, wrap(current))


def wrap_frame_reader(wrap: Any) -> None:
    """Replace viser's loop reading a client's frames by ``wrap(loop)``, once.

    The loop is ``async (connection, handle_message, message_class) -> None``: it receives each frame,
    decodes it with ``message_class.deserialize`` and hands the message to ``handle_message``.
    """
    current = _viser_infra._message_consumer
    if not hasattr(current, "__wrapped__"):
        _viser_infra._message_consumer = wrap(current)


_serve_lock = threading.Lock()


@contextlib.contextmanager
def wrap_requests(wrap: Callable[[Any], Any]) -> Iterator[None]:
    """While active, every server viser starts gets ``wrap(process_request)`` in front of its requests.

    ``process_request`` is viser's own handler of a request (None where it has none); ``wrap`` returns
    the handler the server runs instead, for every HTTP request and websocket handshake.
    """
    with _serve_lock:
        original = ws_server.serve

        def serve(*args: Any, **kwargs: Any) -> Any:
            kwargs["process_request"] = wrap(kwargs.get("process_request"))
            return original(*args, **kwargs)

        ws_server.serve = serve  # type: ignore[assignment]
        try:
            yield
        finally:
            ws_server.serve = original  # type: ignore[assignment]


def input_widget(gui: Any, uuid: Any) -> Any | None:
    """Return the input widget of ``gui`` with ``uuid`` (None if unknown)."""
    return gui._gui_input_handle_from_uuid.get(uuid, None)


def widget_state(widget: Any) -> Any:
    """Return a widget's state: its ``props`` (value, label, mime_type …) and ``removed`` flag."""
    return widget._impl


def upload_states(gui: Any) -> dict[str, Any]:
    """Return ``gui``'s uploads in flight: transfer id → state (client_id, filename, total/transferred bytes)."""
    return gui._current_file_upload_states


def resolve_client(gui: Any, client_id: Any) -> Any | None:
    """Return the client handle of ``client_id`` (None if gone)."""
    return gui._resolve_client(client_id)

#: Every icon the page shows (a test checks the UI modules use no other).
PAGE_ICONS = ("ARROWS_MAXIMIZE", "BOLT", "CHART_DOTS", "CHART_HISTOGRAM", "CHART_LINE", "DOWNLOAD", "ENGINE", "FILE",
              "FLASK", "PHOTO", "PLAYER_PLAY", "PLAYER_STOP", "PLUS", "ROUTE", "SHARE", "TABLE", "UPLOAD", "WAND")


def warm_icons(names: tuple[str, ...] = PAGE_ICONS) -> None:
    """Read viser's icons ``names`` into its icon cache now, at server start.

    Each icon's first use opens viser's icon archive (≈ 73 000 entries) again: ≈ 35 ms per icon,
    ≈ 0.5 s of the first page's build after a server start.
    """
    for name in names:
        _icons.svg_from_icon(getattr(viser.Icon, name))


__all__ = ["GUI_UPDATES", "PAGE_ICONS", "UPLOAD_PART", "UPLOAD_START", "WRITTEN_FOR", "add_figure", "figure_json_of",
           "figure_json_shown",
           "input_widget", "mark_plotly_js_sent", "plotly_js_sent", "resolve_client", "run_script",
           "set_figure_json", "set_slider_marks", "upload_states", "warm_icons", "widget_id", "widget_state",
           "wrap_gui_handler"]
