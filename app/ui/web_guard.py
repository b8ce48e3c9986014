"""Who may use the page: Origin/Host checks on every request and an access token off loopback.

viser offers no hook for the handshake, so :func:`guarded` puts :meth:`Guard.check` in front of
viser's own ``process_request`` while a server is being built (through the adapter of viser's
private API, :func:`app.ui.viser_adapter.wrap_requests`):

* **Host** (every HTTP request and the websocket handshake): the host name must be one the tool
  is served as — loopback names by default, the bound address, ``--allow-origin`` hosts. This
  stops DNS-rebinding pages.
* **Origin** (the websocket handshake): must be an allowed origin, so a web page from another
  site open in the engineer's browser cannot drive the tool. A missing Origin (not a browser) is
  refused too.
* **Token** (only when bound to a non-loopback address): the start-up URL carries
  ``?token=…``; the first page load sets an HttpOnly, SameSite=Strict cookie, and every later
  request (assets, websocket) must carry the token in the cookie or the query (one ``token``
  parameter only). The Host is checked in token mode too: a name the tool is served as, the
  machine's own host names, or an IP address literal (a DNS-rebinding page has a foreign name).
  Any malformed request (token text, Host, Origin) is answered 403, never an error.
* **Widget values** (every GUI update a client sends): checked against the widget's own value type
  before viser casts it — a number widget takes a finite number, a text widget text, a checkbox a
  bool, a vector a list of the same length — so a hand-made client cannot raise in the server's
  message handler or slip NaN into a field; a refused update is dropped and recorded in
  :data:`REFUSED_UPDATES`.
* **Frames**: a websocket frame that is not a message of viser's protocol (not MessagePack, a text
  frame, no or an unknown type, fields missing or of the wrong type, nested too deeply) closes its
  connection with code 1007 and one line in :data:`REFUSED_UPDATES`, never a traceback in the log.
* **Uploads** (checked while streaming): refused by their declared size before any part is kept
  (:func:`upload_limit`: 50 MB for a drive log, 512 KiB for preset and waveform files) and by their
  part count (≤ one part per :data:`MIN_PART_BYTES` declared: the page sends 512 KiB parts, so a
  transfer of millions of one-byte parts is never started), a part over :data:`MAX_PART_BYTES` or one
  that would overrun the declared size ends the transfer, and one client's unfinished uploads together
  may hold ≤ :data:`CLIENT_INFLIGHT_BYTES`, the server's ≤ :data:`SERVER_INFLIGHT_BYTES`.
"""

from __future__ import annotations

import collections
import contextlib
import hmac
import http
import ipaddress
import math
import secrets
import socket
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import parse_qs, urlsplit

from pmsm_commissioning.app.io.numbers import shorten
from pmsm_commissioning.app.ui.viser_adapter import (
    GUI_UPDATES,
    UPLOAD_PART,
    UPLOAD_START,
    input_widget,
    resolve_client,
    upload_states,
    widget_state,
    wrap_frame_reader,
    wrap_gui_handler,
    wrap_requests,
)

LOOPBACK_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
COOKIE = "pmsm_token"


def new_token() -> str:
    """Return a random URL-safe access token (128 bits)."""
    return secrets.token_urlsafe(16)


def _host_of(text: str) -> str:
    """Host name of a ``Host`` header or an origin URL, lower case, without port or brackets."""
    netloc = urlsplit(text if "//" in text else f"//{text}").hostname
    return (netloc or "").lower()


def _is_ip_literal(host: str) -> bool:
    """Tell whether ``host`` is an IPv4/IPv6 address written out (no DNS name: no DNS rebinding)."""
    try:
        ipaddress.ip_address(host)
    except ValueError:
        return False
    return True


def machine_names() -> set[str]:
    """Return the host name and fully qualified name of this machine, lower case (its names on a LAN)."""
    names = {socket.gethostname().lower()}
    with contextlib.suppress(OSError):
        names.add(socket.getfqdn().lower())
    return {n for n in names if n}


@dataclass
class Guard:
    """The access rules of one server.

    Attributes
    ----------
    hosts : set of str     Host names the page may be served as.
    origins : set of str   Extra allowed origins (scheme://host[:port]) besides same-host ones.
    token : str or None    Required access token (None on loopback).
    refused : list of str  Reasons of refused requests (most recent last; for logs and tests).
    """

    hosts: set[str]
    origins: set[str] = field(default_factory=set)
    token: str | None = None
    refused: list[str] = field(default_factory=list)

    @classmethod
    def for_host(cls, host: str, allow_origins: list[str] | tuple[str, ...] = (),
                 token: str | None = None) -> Guard:
        """Rules for a server bound to ``host`` with extra allowed origins."""
        hosts = set(LOOPBACK_HOSTS)
        if host not in ("0.0.0.0", "::", ""):
            hosts.add(host.strip("[]").lower())
        elif token is not None:  # every interface: the machine's own names too
            hosts |= machine_names()
        origins = {o.rstrip("/").lower() for o in allow_origins}
        hosts |= {_host_of(o) for o in origins}
        return cls(hosts, origins, token)

    def _token_ok(self, request: Any) -> bool:
        if self.token is None:
            return True
        queries = parse_qs(urlsplit(request.path).query, keep_blank_values=True).get("token", [])
        if len(queries) > 1:
            return False  # ?token=OK&token=x: ambiguous, refused whichever comes first
        cookies = request.headers.get("Cookie", "")
        jar = dict(c.strip().split("=", 1) for c in cookies.split(";") if "=" in c)
        given = queries[0] if queries else jar.get(COOKIE, "")
        return hmac.compare_digest(given.encode("utf-8", "surrogateescape"), self.token.encode())

    def _host_ok(self, host: str) -> bool:
        return host in self.hosts or (self.token is not None and _is_ip_literal(host))

    def reason(self, request: Any) -> str | None:
        """Why ``request`` is refused, or None if it may proceed (a malformed request is refused)."""
        try:
            return self._reason(request)
        except Exception as exc:  # noqa: BLE001 - duplicate headers, bad URL …: a refusal, never a 500
            return f"malformed request ({type(exc).__name__}): refused"

    def _reason(self, request: Any) -> str | None:
        host_header = request.headers.get("Host", "").lower()
        host = _host_of(host_header)
        if not self._host_ok(host):
            shown = host if len(host) <= 80 else host[:80] + "…"
            return f"Host {shown!r} is not one this tool is served as ({', '.join(sorted(self.hosts))})"
        if request.headers.get("Upgrade", "").lower() == "websocket":
            origin = request.headers.get("Origin", "").rstrip("/").lower()
            same = bool(origin) and urlsplit(origin).netloc == host_header
            if not origin or not (same or origin in self.origins):
                shown = origin[:80] + "…" if len(origin) > 80 else origin or "(none)"
                return f"websocket Origin {shown!r} is not allowed (allowed: this page's own host)"
        if not self._token_ok(request):
            return "missing or wrong access token: open the URL printed at start-up (…?token=…)"
        return None

    def check(self, connection: Any, request: Any) -> Any:
        """``process_request`` hook: a 403 response for a refused request, else None."""
        why = self.reason(request)
        if why is None:
            return None
        self.refused.append(why)
        return connection.respond(http.HTTPStatus.FORBIDDEN, f"Forbidden: {why}\n")

    def wrap(self, inner: Callable[[Any, Any], Any] | None) -> Callable[[Any, Any], Any]:
        """``inner`` (viser's file server) behind :meth:`check`; sets the token cookie on pages."""
        def process_request(connection: Any, request: Any) -> Any:
            refused = self.check(connection, request)
            if refused is not None:
                return refused
            response = inner(connection, request) if inner is not None else None
            if response is not None and self.token is not None:
                response.headers["Set-Cookie"] = f"{COOKIE}={self.token}; HttpOnly; SameSite=Strict; Path=/"
            return response

        return process_request


#: The most recent GUI updates refused by :func:`update_problem` (one line each; for logs and tests).
REFUSED_UPDATES: collections.deque[str] = collections.deque(maxlen=100)


def _value_problem(current: Any, value: Any) -> str | None:
    """Why ``value`` cannot replace a widget value like ``current``, or None."""
    if current is None:
        return None
    if isinstance(current, bool):
        return None if isinstance(value, bool) else "allowed true or false"
    if isinstance(current, int | float):
        ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        return None if ok else "allowed a finite number"
    if isinstance(current, str):
        return None if isinstance(value, str) else "allowed text"
    if isinstance(current, tuple):
        if not isinstance(value, list | tuple) or len(value) != len(current):
            return f"allowed a list of {len(current)} values"
        problems = [_value_problem(c, v) for c, v in zip(current, value, strict=True)]
        return next((p for p in problems if p is not None), None)
    return None


def update_problem(state: Any, updates: Any) -> str | None:
    """Why a client's GUI update of a widget (its state ``state``) is refused, or None."""
    if not isinstance(updates, dict):
        return "the update is not a mapping"
    for name, value in updates.items():
        if not isinstance(name, str) or name.startswith("_") or not hasattr(state, name):
            return f"property {str(name)[:40]!r} is not one of the widget's"
        why = _value_problem(getattr(state, name), value)
        if why is not None:
            return f"{name} = {repr(value)[:80]} has the wrong type: {why}"
    return None


def _checked_gui_updates(original: Callable[..., Any]) -> Callable[..., Any]:
    async def handle(self: Any, client_id: Any, message: Any) -> None:
        widget = input_widget(self, message.uuid)
        if widget is not None and not widget_state(widget).removed:
            why = update_problem(widget_state(widget), message.updates)
            if why is not None:
                label = str(getattr(widget_state(widget), "label", ""))[:60]
                REFUSED_UPDATES.append(f"client {client_id}: widget {label!r}: {why}")
                return
        await original(self, client_id, message)

    handle.__wrapped__ = original  # type: ignore[attr-defined]
    return handle


#: Largest drive-log upload [B] (as :data:`app.io.drive_log.MAX_BYTES`), and any other upload [B].
LOG_UPLOAD_BYTES, FILE_UPLOAD_BYTES = 50 * 2**20, 512 * 2**10
#: Smallest average part an upload may declare (parts ≤ size / this, rounded up), largest single part [B].
MIN_PART_BYTES, MAX_PART_BYTES = 64 * 2**10, 2**20
#: Most bytes one client's unfinished uploads may declare together, and all clients' [B].
CLIENT_INFLIGHT_BYTES, SERVER_INFLIGHT_BYTES = 60 * 2**20, 200 * 2**20


def upload_limit(mime_type: str) -> int:
    """Largest upload [B] an upload button taking ``mime_type`` accepts (drive logs: CSV only)."""
    kinds = str(mime_type).lower()
    return LOG_UPLOAD_BYTES if "csv" in kinds and "yaml" not in kinds else FILE_UPLOAD_BYTES


def upload_problem(gui: Any, client_id: Any, message: Any) -> str | None:
    """Why an upload announced by ``message`` is refused before any of it is kept, or None."""
    widget = input_widget(gui, message.source_component_uuid)
    if widget is None:
        return None  # viser ignores it
    size, parts = message.size_bytes, message.part_count
    limit = upload_limit(getattr(widget_state(widget).props, "mime_type", ""))
    if not isinstance(size, int) or not isinstance(parts, int) or size < 0 or parts < 0:
        return f"{shorten(message.filename, 60)!r}: malformed upload (size {size!r}, {parts!r} parts)"
    if parts > -(-size // MIN_PART_BYTES):
        return (f"{shorten(message.filename, 60)!r}: {parts} parts for {size} bytes: allowed ≤ "
                f"{-(-size // MIN_PART_BYTES)} (one part per {MIN_PART_BYTES // 1024} KiB)")
    if size > limit:
        return (f"{shorten(message.filename, 60)!r} is {size / 2**20:.1f} MB: allowed ≤ {limit / 2**20:.3g} MB "
                "for this button")
    states = upload_states(gui).values()
    mine = sum(int(st["total_bytes"]) for st in states if st["client_id"] == client_id)
    everyone = sum(int(st["total_bytes"]) for st in states)
    if mine + size > CLIENT_INFLIGHT_BYTES or everyone + size > SERVER_INFLIGHT_BYTES:
        return (f"{shorten(message.filename, 60)!r}: too many unfinished uploads at once: wait for the "
                "others to finish")
    return None


def _checked_upload_start(original: Callable[..., Any]) -> Callable[..., Any]:
    def handle(self: Any, client_id: Any, message: Any) -> None:
        why = upload_problem(self, client_id, message)
        if why is None:
            original(self, client_id, message)
            return
        REFUSED_UPDATES.append(f"client {client_id}: upload refused: {why}")
        client = resolve_client(self, client_id)
        if client is not None:
            client.add_notification("Upload refused — nothing read", why, color="red", auto_close_seconds=15.0)

    handle.__wrapped__ = original  # type: ignore[attr-defined]
    return handle


def _checked_upload_part(original: Callable[..., Any]) -> Callable[..., Any]:
    def handle(self: Any, client_id: Any, message: Any) -> None:
        state = upload_states(self).get(message.transfer_uuid)
        if state is not None and (state["client_id"] != client_id or not isinstance(message.content, bytes)
                                  or len(message.content) > MAX_PART_BYTES
                                  or state["transferred_bytes"] + len(message.content) > state["total_bytes"]):
            upload_states(self).pop(message.transfer_uuid, None)  # the parts kept are freed
            REFUSED_UPDATES.append(f"client {client_id}: upload {shorten(state['filename'], 60)!r} ended: "
                                   f"its parts overrun the declared size or {MAX_PART_BYTES // 2**20} MiB a part")
            return
        original(self, client_id, message)

    handle.__wrapped__ = original  # type: ignore[attr-defined]
    return handle


#: Close code of a connection whose frame is not a message of the protocol (RFC 6455: invalid payload).
INVALID_FRAME = 1007


def _checked_frames(original: Callable[..., Any]) -> Callable[..., Any]:
    async def consume(connection: Any, handle_message: Callable[[Any], None], message_class: Any) -> None:
        while True:
            raw = await connection.recv()
            try:
                if not isinstance(raw, bytes):
                    raise TypeError("a text frame (allowed: binary MessagePack)")
                message = message_class.deserialize(raw)
            except Exception as exc:  # noqa: BLE001 - whatever the decoder raises, the frame is refused
                REFUSED_UPDATES.append(f"connection {getattr(connection, 'id', '?')}: frame of {len(raw)} bytes "
                                       f"refused, connection closed: {type(exc).__name__}: {shorten(exc, 120)}")
                await connection.close(INVALID_FRAME, "not a message of the protocol")
                await connection.recv()  # raises ConnectionClosed: viser ends the connection as a disconnect
                return
            handle_message(message)

    consume.__wrapped__ = original  # type: ignore[attr-defined]
    return consume


_WRAPPERS = {GUI_UPDATES: _checked_gui_updates, UPLOAD_START: _checked_upload_start, UPLOAD_PART: _checked_upload_part}


def check_widget_updates() -> None:
    """Put the widget-value and upload checks in front of viser's handlers (once, for every GUI created after)."""
    for name, wrap in _WRAPPERS.items():
        wrap_gui_handler(name, wrap)
    wrap_frame_reader(_checked_frames)
    # viser warns with the client's value when a field does not match its type: hostile text, raw, in the log
    warnings.filterwarnings("ignore", message=r"\[viser\] .* does not match annotation", category=UserWarning)


@contextlib.contextmanager
def guarded(guard: Guard) -> Iterator[None]:
    """While active, every ``websockets`` server started gets ``guard`` in front of its requests.

    Widget updates are type-checked from then on (:func:`check_widget_updates`).
    """
    check_widget_updates()
    with wrap_requests(guard.wrap):
        yield


__all__ = ["COOKIE", "LOOPBACK_HOSTS", "REFUSED_UPDATES", "Guard", "check_widget_updates", "guarded", "new_token",
           "update_problem", "upload_limit", "upload_problem"]
