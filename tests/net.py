"""Network helpers shared by the tests and the benchmark scripts."""

from __future__ import annotations

import asyncio
import socket
import threading
from collections.abc import Callable, Coroutine
from typing import Any


def free_port() -> int:
    """A currently free TCP port on 127.0.0.1."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def run_coroutine(coro_fn: Callable[[], Coroutine[Any, Any, Any]]) -> Any:
    """Run a coroutine on its own thread and return its result (None if it is still running after 120 s).

    Its own thread: the browser tests leave an event loop on the main one.
    """
    box: list[Any] = []
    t = threading.Thread(target=lambda: box.append(asyncio.run(coro_fn())))
    t.start()
    t.join(120)
    return box[0] if box else None
