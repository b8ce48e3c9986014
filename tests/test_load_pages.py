"""Bounded load test (loopback): three pages start robustness studies on a server that runs one at a
time; the later two are told their place in the queue; two disconnect, the third then runs; when all
have gone, no study process is left. ``scripts/load_test.py`` is the full-size version with figures.
"""

from __future__ import annotations

import asyncio
import multiprocessing
import threading
import time

from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, load_preset
from pmsm_commissioning.app.ui.page import create_server
from pmsm_commissioning.app.ui.studies_queue import StudySlots
from tests.net import free_port, run_coroutine
from tests.page_client import PageClient

#: Generous bound on a closed page's processes and study slot being gone [s] (the promise is 2 s).
GONE_S = 5.0
RUN = "Run robustness study"


async def _until(condition, limit_s: float) -> bool:
    end = time.monotonic() + limit_s
    while time.monotonic() < end:
        if condition():
            return True
        await asyncio.sleep(0.05)
    return condition()


def test_three_pages_queue_their_studies_and_leave_no_process_behind():
    server, config = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False)
    config.slots = StudySlots(max_studies=1, max_processes=1)
    hostport, before = f"127.0.0.1:{server.get_port()}", set(multiprocessing.active_children())
    seen: dict[str, object] = {}

    def children() -> set:
        return set(multiprocessing.active_children()) - before

    async def go() -> None:
        pages = [PageClient(hostport) for _ in range(3)]
        for page in pages:
            await page.open()
            await page.set_value("Samples", 20_000)  # minutes of work: still running when closed
        for page in pages:
            await page.set_value(RUN, True)
            await asyncio.sleep(0.3)  # in this order
        seen["pool"] = await _until(lambda: bool(children()), 60.0)
        seen["queued"] = await _until(lambda: pages[1].said("next in line") and pages[2].said("1 study ahead"), 10.0)
        first_pool = children()
        await pages[0].close()  # the running study's page
        await pages[1].close()  # a queued one
        seen["third runs"] = await _until(lambda: bool(children() - first_pool) and config.slots.running == 1, 60.0)
        await pages[2].close()

    try:
        run_coroutine(go)
        gone = _wait_gone(lambda: children() or config.slots.running or config.slots.queued)
        assert seen == {"pool": True, "queued": True, "third runs": True}
        assert gone, (children(), config.slots.running, config.slots.queued)
        assert not config.sessions
    finally:
        server.stop()


def _wait_gone(left) -> bool:
    """True once ``left()`` is empty (processes, studies), polled up to :data:`GONE_S`."""
    end = time.monotonic() + GONE_S
    while time.monotonic() < end:
        if not left():
            return True
        time.sleep(0.05)  # poll again (a positive condition)
    return not left()


def test_a_table1_sweep_is_a_study_it_waits_for_a_slot_and_then_runs():
    server, config = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False)
    config.slots = StudySlots(max_studies=1, max_processes=1)
    hostport, release, seen = f"127.0.0.1:{server.get_port()}", threading.Event(), {}
    holding = threading.Thread(target=_hold, args=(config.slots, release), daemon=True)
    holding.start()  # another page's study holds the only slot

    async def go() -> None:
        page = PageClient(hostport)
        await page.open()
        await page.set_value("T_m list [s]", "1.0")
        await page.set_value("Run Table-1 sweep", True)
        seen["queued"] = await _until(lambda: page.says("next in line"), 30.0)  # on the status line
        session = next(iter(config.sessions.values()))
        seen["waiting"] = session.worker.busy and not session.results.progress.value
        release.set()
        seen["ran"] = await _until(lambda: session.results.progress.value == 100.0 and not session.worker.busy, 60.0)
        await page.close()

    try:
        run_coroutine(go)
        assert seen == {"queued": True, "waiting": True, "ran": True}
        assert config.slots.running == config.slots.queued == 0
    finally:
        release.set()
        server.stop()


def _hold(slots: StudySlots, release: threading.Event) -> None:
    with slots.hold(lambda ahead: None, lambda: False):
        release.wait(60.0)
