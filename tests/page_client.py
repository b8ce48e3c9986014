"""A hand-written page client (no browser) for load tests: connects over the websocket, reads every
message, finds widgets by label, clicks buttons and sets values as the page would.

Used by ``tests/test_load_pages.py`` and ``scripts/load_test.py``.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import time
from collections.abc import AsyncIterator, Callable
from typing import Any

import msgspec
import viser
import websockets
import zstandard

PROTOCOL = f"viser-v{viser.__version__}"
#: The first message a page sends: viser counts a client after its first camera.
CAMERA = {"type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0], "position": [0.0, 0.0, 1.0],
          "fov": 1.0, "near": 0.01, "far": 100.0, "image_height": 600, "image_width": 800,
          "look_at": [0.0, 0.0, 0.0], "up_direction": [0.0, 0.0, 1.0]}


def decode_frame(frame: bytes) -> list[dict[str, Any]]:
    """Return the messages of one server frame (16-byte header of sizes, zstd-compressed msgpack)."""
    n_in, n_c = int.from_bytes(frame[:8], "little"), int.from_bytes(frame[8:16], "little")
    raw = zstandard.ZstdDecompressor().decompress(frame[16:16 + n_c], max_output_size=n_in)
    return list(msgspec.msgpack.decode(raw)["messages"])


@contextlib.asynccontextmanager
async def raw_session(hostport: str, config: Any) -> AsyncIterator[tuple[Any, Any]]:
    """Connect as a hand-written client that never reads; yield (its socket, the page session it opened).

    ``config`` is the server's :class:`app.ui.page` configuration (its ``sessions`` by client). The
    closing handshake cannot complete for a client that never reads, so the socket closes at once.
    """
    known = set(config.sessions)
    async with websockets.connect(f"ws://{hostport}", origin=f"http://{hostport}", subprotocols=[PROTOCOL],
                                  max_size=None, close_timeout=0.2) as ws:
        await ws.send(msgspec.msgpack.encode(CAMERA))  # viser counts a client after its first camera
        new: set[Any] = set()
        for _ in range(600):
            new = set(config.sessions) - known
            if new:
                break
            await asyncio.sleep(0.05)
        yield ws, config.sessions[new.pop()]


async def wait_until(done: Callable[[], bool], tries: int = 200) -> None:
    """Poll ``done`` every 50 ms, at most ``tries`` times (the caller asserts what it waited for)."""
    for _ in range(tries):
        if done():
            return
        await asyncio.sleep(0.05)


def upload_start(uuid: str, name: str, size: int, parts: int) -> dict[str, Any]:
    """The message that starts an upload of ``size`` bytes in ``parts`` parts into the widget ``uuid``."""
    return {"type": "FileTransferStartUpload", "source_component_uuid": uuid, "transfer_uuid": name,
            "filename": name, "mime_type": "text/csv", "part_count": parts, "size_bytes": size}


class PageClient:
    """One page: its widgets by label, the markdown they show and when its first figure arrived."""

    def __init__(self, hostport: str) -> None:
        self.hostport = hostport
        self.uuids: dict[str, str] = {}  # label → uuid (the first widget of that label)
        self.content: dict[str, str] = {}  # markdown/html uuid → text shown
        self.shown: list[str] = []  # every markdown/html text shown, in order
        self.opened = self.first_figure_s = 0.0
        self._ws: Any = None
        self._reader: asyncio.Task | None = None

    async def open(self) -> None:
        """Connect, announce the camera and start reading."""
        self.opened = time.monotonic()
        self._ws = await websockets.connect(f"ws://{self.hostport}", origin=f"http://{self.hostport}",
                                            subprotocols=[PROTOCOL], max_size=None, close_timeout=0.2)
        await self._ws.send(msgspec.msgpack.encode(CAMERA))
        self._reader = asyncio.ensure_future(self._read())

    async def _read(self) -> None:
        try:
            async for frame in self._ws:
                for m in decode_frame(frame):
                    self._record(m)
        except websockets.exceptions.ConnectionClosed:
            return

    def _record(self, m: dict[str, Any]) -> None:
        props = m.get("props") or {}
        updates = m.get("updates") or {}
        if isinstance(props.get("label"), str):
            self.uuids.setdefault(props["label"], m["uuid"])
        for key in ("_markdown", "content"):  # markdown, html
            if key in props or key in updates:
                self.content[m["uuid"]] = props.get(key, updates.get(key))
                self.shown.append(str(self.content[m["uuid"]]))
        fig = props.get("_plotly_json_str") or updates.get("_plotly_json_str")
        if fig and not self.first_figure_s and json.loads(fig).get("data"):
            self.first_figure_s = time.monotonic() - self.opened

    async def wait_for(self, label: str, limit_s: float = 60.0) -> str:
        """Return the uuid of the widget ``label`` once the page has it."""
        end = time.monotonic() + limit_s
        while label not in self.uuids:
            if time.monotonic() > end:
                raise TimeoutError(f"no widget {label!r} within {limit_s} s")
            await asyncio.sleep(0.05)
        return self.uuids[label]

    async def set_value(self, label: str, value: Any) -> None:
        """Set the widget ``label`` to ``value`` (a click for a button: ``True``)."""
        uuid = await self.wait_for(label)
        await self._ws.send(msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": uuid,
                                                    "updates": {"value": value}}))

    def says(self, text: str) -> bool:
        """True when some markdown of the page contains ``text`` now."""
        return any(text in c for c in self.content.values() if isinstance(c, str))

    def said(self, text: str) -> bool:
        """True when some markdown of the page has contained ``text`` (now or before)."""
        return any(text in c for c in self.shown)

    async def close(self) -> None:
        """Close the websocket (the page is gone)."""
        if self._ws is not None:
            await self._ws.close()
        if self._reader is not None:
            await self._reader


__all__ = ["CAMERA", "PROTOCOL", "PageClient", "decode_frame"]
