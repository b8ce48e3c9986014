"""No orphaned work: a page that disconnects stops its running job — a robustness study
ends its process pool — within 2 s (the wait limits below are the promise, polled, not timed).
"""

from __future__ import annotations

import asyncio
import multiprocessing
import time

import msgspec
import websockets

from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, load_preset
from pmsm_commissioning.app.ui.page import create_server
from pmsm_commissioning.app.ui.worker import Cancelled, Worker
from tests.net import free_port, run_coroutine
from tests.test_ui_hostile import CAMERA, PROTOCOL

#: The promise: a disconnected page's work is gone within this time [s].
GONE_S = 2.0


def _wait(condition, limit_s: float) -> bool:
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.02)  # poll again (a positive condition)
    return condition()


def test_closing_the_worker_stops_the_running_job_at_its_next_checkpoint():
    errors: list[Exception] = []
    worker = Worker(lambda _: None, errors.append)
    reached: list[int] = []

    def job() -> None:
        for i in range(100_000):
            worker.checkpoint()
            reached.append(i)
            time.sleep(0.005)

    future = worker.submit(job)
    assert _wait(lambda: bool(reached), 10.0)
    worker.close()  # what a page disconnect does
    future.result(timeout=GONE_S)
    assert len(reached) < 100_000 and isinstance(errors[0], Cancelled)
    assert worker.submit(lambda: None) is None  # closed: no new work


def test_disconnected_page_ends_its_robustness_pool():
    server, config = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False)
    hostport, box = f"127.0.0.1:{server.get_port()}", []
    before = set(multiprocessing.active_children())

    def pool_children() -> set:
        return set(multiprocessing.active_children()) - before

    async def page() -> None:
        known = set(config.sessions)
        async with websockets.connect(f"ws://{hostport}", origin=f"http://{hostport}", subprotocols=[PROTOCOL],
                                      max_size=None, close_timeout=0.2) as ws:
            await ws.send(msgspec.msgpack.encode(CAMERA))
            for _ in range(600):
                if set(config.sessions) - known:
                    box.append(config.sessions[(set(config.sessions) - known).pop()])
                    break
                await asyncio.sleep(0.05)
            view = box[0].studies.robustness
            view.samples.value = 20_000  # minutes of work in a process pool
            assert view.start()
            for _ in range(1200):
                if pool_children():
                    break
                await asyncio.sleep(0.05)
            assert pool_children(), "the pool never started"
        # leaving the block closes the websocket: the page is gone

    try:
        run_coroutine(page)
        assert _wait(lambda: not pool_children(), GONE_S + 3.0), pool_children()
        assert _wait(lambda: not box[0].worker.busy, GONE_S)
    finally:
        server.stop()


def test_cancel_and_close_run_the_jobs_stop_hooks_once_each():
    errors: list[Exception] = []
    worker = Worker(lambda _: None, errors.append)
    calls: list[str] = []
    started = []

    def job() -> None:
        remove = worker.on_cancel(lambda: calls.append("stop"))
        started.append(True)
        try:
            while True:
                worker.checkpoint()
                time.sleep(0.005)
        finally:
            remove()

    future = worker.submit(job)
    assert _wait(lambda: bool(started), 10.0)
    assert worker.cancel()
    future.result(timeout=GONE_S)
    assert calls == ["stop"] and isinstance(errors[0], Cancelled)
    worker.close()
    assert calls == ["stop"]  # the hook was removed with its job
