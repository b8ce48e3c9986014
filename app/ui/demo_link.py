"""The demo in the page's address: a reload (or the link, opened in another browser) opens the same demo.

viser gives the server no page address (its client handle carries none), so the page reports it:
the window-size report (:func:`app.ui.layout.window_report_js`) carries the address's query
``location.search`` as the page opened with it, in the same message (see
:func:`app.ui.layout.page_address` for why not a field of its own). After every committed run the
server keeps the lecture's demo state (:func:`app.ui.demo_state.dumps_state`: the case — preset,
every typed field, K, T_m —, the plant, slider ranges, pins, tabs, zoom) under a short token — the
first 16 hex digits of its SHA-256 — and writes ``?demo=<token>`` into the address bar
(``history.replaceState``: no reload). A page opened with such an address loads that state as
*Load demo state* does (the same checks). The tokens live in this server's memory (the last
:data:`MAX_STATES`): a link outlives a reload, not a server restart — *Save demo state* writes a
file for that.
"""

from __future__ import annotations

import hashlib
import json
import re
import threading
from collections import OrderedDict
from typing import Any

import viser

from pmsm_commissioning.app.ui.demo_state import dumps_state, loads_state
from pmsm_commissioning.app.ui.viser_adapter import run_script

#: Demo states kept by the server (the oldest goes first).
MAX_STATES = 128
#: The query parameter naming a kept demo state, and the token's form (16 hex digits).
_TOKEN = re.compile(r"[?&]demo=([0-9a-f]{16})(?:&|$)")
#: Longest address query read [characters].
MAX_SEARCH = 200
_STATES: OrderedDict[str, str] = OrderedDict()
_LOCK = threading.Lock()


def keep_state(text: str) -> str:
    """Keep the demo-state JSON ``text`` in the server's memory; return its token."""
    token = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    with _LOCK:
        _STATES[token] = text
        _STATES.move_to_end(token)
        while len(_STATES) > MAX_STATES:
            _STATES.popitem(last=False)
    return token


def state_of(search: str) -> str | None:
    """Return the demo-state JSON the address query ``search`` names (None: none named, or not kept)."""
    match = _TOKEN.search(search[:MAX_SEARCH])
    if match is None:
        return None
    with _LOCK:
        return _STATES.get(match.group(1))


def address_js(token: str) -> str:
    """Return the page script writing ``demo=<token>`` into the address's query (no reload, no history entry).

    Other parameters of the query (an access ``token``) stay.
    """
    return ("(() => { const q = new URLSearchParams(location.search);"
            f" q.set('demo', {json.dumps(token)});"
            " history.replaceState(null, '', location.pathname + '?' + q.toString() + location.hash); })();")


class DemoLink:
    """A page's demo link: :meth:`opened` with the address the page reported, :meth:`remember` after each run.

    ``files`` is the page's :class:`~app.ui.lecture.DemoStateFiles` (``state()`` and ``open(state)``).
    """

    def __init__(self, client: viser.ClientHandle, files: Any) -> None:
        self._client, self._files = client, files
        self._opened = False
        self._lock = threading.Lock()
        self.token: str | None = None  # the token last written into the address

    def opened(self, search: str) -> None:
        """Read the address query ``search`` the page opened with (once): a kept demo state is loaded."""
        with self._lock:
            if self._opened:
                return
            self._opened = True
        text = state_of(search)
        if text is None:
            return
        try:
            state = loads_state(text, "demo link")
        except ValueError as exc:  # kept by this server, so not expected: said, nothing changed
            self._client.add_notification("Demo link refused — nothing changed", str(exc), color="red",
                                          auto_close_seconds=15.0)
            return
        self._files.open(state)

    def remember(self) -> None:
        """Keep the demo state shown and put its token into the page's address.

        Nothing before the page reported its address: the address it opened with must be read first.
        """
        with self._lock:
            if not self._opened:
                return
        token = keep_state(dumps_state(self._files.state()))
        if token != self.token:
            self.token = token
            run_script(self._client.gui, address_js(token))


__all__ = ["MAX_STATES", "DemoLink", "address_js", "keep_state", "state_of"]
