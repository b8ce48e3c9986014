"""The demo in the page's address: a reload (or the link, sent to another browser) opens the same demo.

viser gives the server no page address (its client handle carries none), so the page reports it:
a small script writes ``location.search`` into a hidden text field once the page is open, as the
page's view is reported (:mod:`app.ui.demo_view`). After every committed run the server keeps the
lecture's demo state (:func:`app.ui.demo_state.dumps_state`: the case, the plant, slider ranges,
pins, tabs, zoom) under a short token — the first 16 hex digits of its SHA-256 — and writes
``?demo=<token>`` into the address bar (``history.replaceState``: no reload). A page opened with
such an address loads that state as *Load demo state* does (the same checks). The tokens live in
this server's memory (the last :data:`MAX_STATES`): a link outlives a reload, not a server restart —
*Save demo state* writes a file for that.
"""

from __future__ import annotations

import hashlib
import json
import re
import threading
from collections import OrderedDict

import viser

from app.ui.demo_state import dumps_state, loads_state
from app.ui.layout import hide_field_js
from app.ui.viser_adapter import run_script, widget_id

#: Demo states kept by the server (the oldest goes first).
MAX_STATES = 128
_TOKEN = re.compile(r"[?&]demo=([0-9a-f]{16})(?:&|$)")
_STATES: OrderedDict[str, str] = OrderedDict()
_LOCK = threading.Lock()

#: Writes the page's ``location.search`` into the hidden field UUID, as if typed (viser sends it).
REPORT_JS = """(() => { const uuid = UUID, search = location.search || '?';  // before any run rewrites it
  const setValue = Object.getOwnPropertyDescriptor(HTMLInputElement.prototype, 'value').set;
  const report = () => { const label = document.querySelector(`label[for="${uuid}"]`);
    const flex = label && label.closest('.mantine-Flex-root'), input = flex && flex.querySelector('input');
    if (!input) { setTimeout(report, 100); return; }
    setValue.call(input, search); input.dispatchEvent(new Event('input', {bubbles: true})); };
  report(); })();"""


def keep_state(text: str) -> str:
    """Keep the demo-state JSON ``text``; return its token."""
    token = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    with _LOCK:
        _STATES[token] = text
        _STATES.move_to_end(token)
        while len(_STATES) > MAX_STATES:
            _STATES.popitem(last=False)
    return token


def state_of(search: str) -> str | None:
    """Return the demo-state JSON a page address's query ``search`` names (None: none, or not kept)."""
    match = _TOKEN.search(search[:200])
    if match is None:
        return None
    with _LOCK:
        return _STATES.get(match.group(1))


def address_js(token: str) -> str:
    """Return the page script writing ``?demo=<token>`` into the address bar (no reload)."""
    return f"history.replaceState(null, '', location.pathname + '?demo=' + {json.dumps(token)});"


class DemoLink:
    """The hidden field the page reports its address into; :meth:`remember` after each committed run."""

    def __init__(self, gui: viser.GuiApi, files: object) -> None:
        self._gui, self._files, self._opened = gui, files, False
        self.field = gui.add_text("page address", "")
        run_script(gui, hide_field_js(widget_id(self.field)))
        self.field.on_update(lambda _: self._reported(str(self.field.value)))
        run_script(gui, REPORT_JS.replace("UUID", json.dumps(widget_id(self.field))))

    def _reported(self, search: str) -> None:
        if self._opened:  # the address is read once, when the page opens
            return
        self._opened = True
        text = state_of(search)
        if text is not None:
            self._files.open(loads_state(text, "demo link"))  # type: ignore[attr-defined]

    def remember(self) -> None:
        """Keep the demo state shown and put its token into the page's address (once the page reported its own)."""
        if not self._opened:  # the address the page opened with is not read yet: it must not be overwritten
            return
        token = keep_state(dumps_state(self._files.state()))  # type: ignore[attr-defined]
        run_script(self._gui, address_js(token))


__all__ = ["MAX_STATES", "DemoLink", "address_js", "keep_state", "state_of"]
