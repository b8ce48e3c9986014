"""Server-wide limit on concurrent studies: a first-come queue, lower priority, bounded child processes.

Studies (robustness, multi-axis, Table-1 sweeps) take seconds to minutes of CPU; Simulate, Design
and a new page's first figures take a fraction of a second. So that ten pages running studies
cannot starve an eleventh:

* at most ``max_studies`` studies run at once on the server; the rest wait in one first-come
  queue, and each waiting page is told how many studies are ahead of it (a Cancel or a closed
  page leaves the queue at once);
* a study runs on a thread of its own whose scheduling priority is lowered by :data:`STUDY_NICE`
  (Linux threads have their own nice value), and its process pool's workers lower theirs by the
  same amount (:class:`sim.studies.runner.RetryingPool`), so interactive work is scheduled first;
* the study processes together are at most ``max_processes``: each study's pool gets
  :attr:`StudySlots.processes_per_study` workers.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import threading
from collections import deque
from collections.abc import Callable, Iterator
from typing import Any

from pmsm_commissioning.app.ui.worker import Cancelled
from pmsm_commissioning.sim.studies.runner import lower_priority

#: How much a study's threads and processes lower their scheduling priority (nice increment) [-].
STUDY_NICE = 10
#: How often a queued study looks for a cancel while it waits [s].
QUEUE_POLL_S = 0.05
#: Environment variables overriding the defaults of :meth:`StudySlots.for_machine`.
MAX_STUDIES_ENV, MAX_PROCESSES_ENV = "PMSM_MAX_STUDIES", "PMSM_MAX_STUDY_PROCESSES"


def run_lowered(fn: Callable[[], Any], name: str) -> None:
    """Run ``fn`` on a new thread of lowered priority and wait for it; its exception is raised here."""
    failure: list[BaseException] = []

    def body() -> None:
        lower_priority(STUDY_NICE)
        try:
            fn()
        except BaseException as exc:  # handed to the waiting thread, which reports it
            failure.append(exc)

    thread = threading.Thread(target=body, name=name, daemon=True)
    thread.start()
    thread.join()
    if failure:
        raise failure[0]


def _env_int(name: str, default: int) -> int:
    text = os.environ.get(name, "")
    return int(text) if text.isascii() and text.isdigit() and int(text) > 0 else default


class StudySlots:
    """At most ``max_studies`` studies at once, the rest queued first come, first served.

    Parameters
    ----------
    max_studies : int
        Studies running at once on the server [-].
    max_processes : int
        Worker processes of all running studies together [-].
    """

    def __init__(self, max_studies: int, max_processes: int) -> None:
        self.max_studies, self.max_processes = max(1, int(max_studies)), max(1, int(max_processes))
        self._cond = threading.Condition()
        self._queue: deque[int] = deque()
        self._running: set[int] = set()
        self._tickets = itertools.count()

    @classmethod
    def for_machine(cls) -> StudySlots:
        """Half the cores' worth of studies (at least 2) sharing one process per core.

        ``PMSM_MAX_STUDIES`` and ``PMSM_MAX_STUDY_PROCESSES`` override the two numbers.
        """
        cores = os.cpu_count() or 1
        return cls(_env_int(MAX_STUDIES_ENV, max(2, cores // 2)), _env_int(MAX_PROCESSES_ENV, cores))

    @property
    def processes_per_study(self) -> int:
        """Worker processes one study's pool may start [-]."""
        return max(1, self.max_processes // self.max_studies)

    @property
    def running(self) -> int:
        """Studies running now [-]."""
        with self._cond:
            return len(self._running)

    @property
    def queued(self) -> int:
        """Studies waiting [-]."""
        with self._cond:
            return len(self._queue)

    def _ahead(self, ticket: int) -> int | None:
        """Studies queued before ``ticket``; None once it may start (called under the lock)."""
        if self._queue[0] == ticket and len(self._running) < self.max_studies:
            return None
        return self._queue.index(ticket)

    @contextlib.contextmanager
    def hold(self, on_queued: Callable[[int], None], cancelled: Callable[[], bool]) -> Iterator[None]:
        """Wait for a slot, hold it while the block runs, then hand it to the next in the queue.

        ``on_queued(ahead)`` is called whenever the number of studies queued ahead changes while
        this one waits; :class:`~app.ui.worker.Cancelled` is raised if ``cancelled()`` turns true
        first, after ``on_queued(-1)`` (it left the queue) if it had been told a place.
        """
        ticket = next(self._tickets)
        with self._cond:
            self._queue.append(ticket)
        try:
            self._wait(ticket, on_queued, cancelled)
            yield
        finally:
            with self._cond:
                if ticket in self._queue:
                    self._queue.remove(ticket)
                self._running.discard(ticket)
                self._cond.notify_all()

    def _wait(self, ticket: int, on_queued: Callable[[int], None], cancelled: Callable[[], bool]) -> None:
        told: int | None = None
        while True:
            if cancelled():  # before taking a slot: a cancelled study never runs
                if told is not None:
                    on_queued(-1)
                raise Cancelled("cancelled while queued")
            with self._cond:
                ahead = self._ahead(ticket)
                if ahead is None:
                    self._queue.popleft()
                    self._running.add(ticket)
                    self._cond.notify_all()
                    return
                if ahead == told:
                    self._cond.wait(QUEUE_POLL_S)
                    ahead = self._ahead(ticket)
            if ahead is not None and ahead != told:
                on_queued(ahead)
                told = ahead

    def queued_text(self, label: str, ahead: int) -> str:
        """Markdown line for the study ``label`` waiting behind ``ahead`` others (-1: it left the queue)."""
        if ahead < 0:
            return f"{label} cancelled while queued: nothing ran."
        where = "next in line" if ahead == 0 else f"{ahead} {'study' if ahead == 1 else 'studies'} ahead"
        return (f"{label} queued: {where} — the server runs at most {self.max_studies} studies at once; it "
                "starts when one ends (Cancel leaves the queue).")

    def run(self, label: str, fn: Callable[[], Any], on_queued: Callable[[str, int], None],
            cancelled: Callable[[], bool]) -> None:
        """Run the study ``fn`` once a slot is free, on a thread of lowered priority (module docstring)."""
        with self.hold(lambda ahead: on_queued(label, ahead), cancelled):
            run_lowered(fn, f"study-{label}")


__all__ = ["STUDY_NICE", "StudySlots", "run_lowered"]
