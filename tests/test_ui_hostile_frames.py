"""The page against hostile websocket frames and uploads (no browser): a frame that is no message of
the protocol closes its connection with code 1007 and one refusal line, never a traceback in the
server's log; an upload's part count and part size are bounded, not only its declared bytes.
"""

from __future__ import annotations

import asyncio
import logging

import msgspec
import pytest
import websockets

from pmsm_commissioning.app.ui.web_guard import INVALID_FRAME, MAX_PART_BYTES, MIN_PART_BYTES, REFUSED_UPDATES
from tests.net import run_coroutine
from tests.page_client import CAMERA, PROTOCOL, raw_session, upload_start, wait_until

enc = msgspec.msgpack.encode
#: name -> a frame that is no message of viser's protocol
HOSTILE_FRAMES = {
    "not MessagePack": b"\xc1\xc1\xc1",
    "truncated": enc(CAMERA)[:-5],
    "text frame": "hello",
    "a list": enc([1, 2, 3]),
    "an integer": enc(5),
    "a huge integer": b"\xcf" + b"\xff" * 8,
    "no type": enc({"wxyz": 1}),
    "unknown type": enc({"type": "NoSuchMessage"}),
    "type not a string": enc({"type": 5}),
    "wrong field types": enc({**CAMERA, "fov": "x", "wxyz": "abc"}),
    "fields missing": enc({"type": "ViewerCameraMessage"}),
    "update without fields": enc({"type": "GuiUpdateMessage"}),
    "upload start of wrong types": enc({"type": "FileTransferStartUpload", "source_component_uuid": 1,
                                        "transfer_uuid": [], "filename": 3, "mime_type": None, "part_count": "x",
                                        "size_bytes": -1}),
    "upload part of wrong types": enc({"type": "FileTransferPart", "source_component_uuid": "a",
                                       "transfer_uuid": "b", "part_index": "x", "content": 5}),
    "nested 100 000 deep": b"\x91" * 100_000 + b"\x00",
}




class _Records(logging.Handler):
    """Every log record of every logger while installed (viser, websockets, asyncio)."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


def _send(hostport: str, frame: bytes | str, wait_s: float = 10.0) -> int | None:
    """Open a connection, send ``frame``; return the close code the server answered with (None: still open)."""
    async def go() -> int | None:
        async with websockets.connect(f"ws://{hostport}", origin=f"http://{hostport}", subprotocols=[PROTOCOL],
                                      max_size=None, close_timeout=0.5) as ws:
            await ws.send(frame)
            try:
                while True:
                    await asyncio.wait_for(ws.recv(), timeout=wait_s)
            except websockets.exceptions.ConnectionClosed as exc:
                return exc.rcvd.code if exc.rcvd is not None else -1
            except TimeoutError:
                return None

    return run_coroutine(go)


@pytest.mark.parametrize("name", list(HOSTILE_FRAMES))
def test_a_hostile_frame_closes_its_connection_with_one_line_and_no_traceback(served, name):
    hostport, _, _ = served
    records, root = _Records(), logging.getLogger()
    root.addHandler(records)
    before = len(REFUSED_UPDATES)
    try:
        code = _send(hostport, HOSTILE_FRAMES[name])
    finally:
        root.removeHandler(records)
    assert code == INVALID_FRAME, (name, code)
    refused = list(REFUSED_UPDATES)[before:]
    assert len(refused) == 1 and "refused" in refused[0] and "\n" not in refused[0], refused
    assert not [r for r in records.records if r.exc_info or r.levelno >= logging.ERROR], \
        [r.getMessage() for r in records.records]


def test_the_server_still_serves_after_hostile_frames(served):
    hostport, _, _ = served
    for frame in list(HOSTILE_FRAMES.values())[:3]:
        assert _send(hostport, frame) == INVALID_FRAME
    assert _send(hostport, enc(CAMERA), wait_s=3.0) is None  # a good page opens and stays open


def test_uploads_are_bounded_by_part_count_and_part_size(served):
    hostport, _, config = served
    before = len(REFUSED_UPDATES)
    box: list[object] = []

    async def go() -> None:
        async with raw_session(hostport, config) as (ws, session):
            log_uuid = session.log_panel.upload._impl.uuid
            size = 300_000  # 300 000 one-byte parts
            msgs = [upload_start(log_uuid, "parts.csv", size, size),
                    upload_start(log_uuid, "page.csv", 3 * 2**20, 6),  # as the page sends it: 512 KiB parts
                    {"type": "FileTransferPart", "source_component_uuid": log_uuid, "transfer_uuid": "page.csv",
                     "part_index": 0, "content": b"x" * (MAX_PART_BYTES + 1)}]  # one part over the bound
            for m in msgs:
                await ws.send(enc(m))
            await wait_until(lambda: len(REFUSED_UPDATES) - before >= 2)
            box.extend([session, dict(session.client.gui._current_file_upload_states)])

    run_coroutine(go)
    refused = list(REFUSED_UPDATES)[before:]
    allowed = -(-300_000 // MIN_PART_BYTES)
    assert len(refused) == 2, refused
    assert "parts.csv" in refused[0] and f"300000 parts for 300000 bytes: allowed ≤ {allowed}" in refused[0]
    assert "page.csv" in refused[1] and "MiB a part" in refused[1]
    assert box[1] == {}  # neither transfer holds state: no part was kept
