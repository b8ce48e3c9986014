"""Server-wide study slots: first come first served, the page told how many are ahead, Cancel leaves
the queue, studies run at lowered priority (threads and pool processes).
"""

from __future__ import annotations

import os
import threading

import pytest

from pmsm_commissioning.app.ui.studies_queue import STUDY_NICE, StudySlots, run_lowered
from pmsm_commissioning.app.ui.worker import Cancelled, Worker
from pmsm_commissioning.sim.studies.runner import RetryingPool
from tests.test_faults_disconnect import _wait as _wait_for

#: Generous bound on each queue change being seen [s].
SEEN_S = 10.0


def _wait(condition) -> bool:
    return _wait_for(condition, SEEN_S)


def _niceness() -> int:
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


class _Study:
    """A study on its own worker that runs until released; records what the queue told it."""

    def __init__(self, slots: StudySlots, label: str, order: list[str]) -> None:
        self.told: list[int] = []
        self.errors: list[Exception] = []
        self.release = threading.Event()
        self.worker = Worker(lambda busy: None, self.errors.append, slots=slots,
                             on_queued=lambda _label, ahead: self.told.append(ahead))

        def job() -> None:
            order.append(label)
            self.release.wait(30.0)

        self.future = self.worker.submit(job, study=label)


def test_studies_beyond_the_limit_queue_in_order_and_are_told_how_many_are_ahead():
    slots, order = StudySlots(max_studies=2, max_processes=4), []
    a = _Study(slots, "a", order)
    assert _wait(lambda: order == ["a"])  # a runs before b is submitted: their order is the test's, not the threads'
    b = _Study(slots, "b", order)
    assert _wait(lambda: slots.running == 2)
    c = _Study(slots, "c", order)
    assert _wait(lambda: c.told == [0])
    d = _Study(slots, "d", order)
    assert _wait(lambda: d.told == [1]) and slots.queued == 2 and slots.processes_per_study == 2
    a.release.set()
    assert _wait(lambda: order == ["a", "b", "c"]) and _wait(lambda: d.told == [1, 0])
    for s in (b, c, d):
        s.release.set()
    for s in (a, b, c, d):
        s.future.result(timeout=10.0)
        assert not s.errors
    assert order == ["a", "b", "c", "d"] and slots.running == slots.queued == 0


def test_cancel_and_close_leave_the_queue_without_running_the_study():
    slots, order = StudySlots(max_studies=1, max_processes=1), []
    a, b, c = _Study(slots, "a", order), _Study(slots, "b", order), _Study(slots, "c", order)
    assert _wait(lambda: c.told == [1])
    assert b.worker.cancel()  # Cancel pressed while queued
    b.future.result(timeout=5.0)
    assert isinstance(b.errors[0], Cancelled) and not b.worker.busy and b.told == [0, -1]
    assert _wait(lambda: c.told == [1, 0])  # c moved up
    c.worker.close()  # the page of c disconnected
    c.future.result(timeout=5.0)
    assert slots.queued == 0 and order == ["a"]
    a.release.set()
    a.future.result(timeout=5.0)
    assert order == ["a"] and slots.running == 0


def test_a_study_runs_on_a_thread_of_lower_priority_and_the_worker_keeps_its_own():
    seen: list[int] = []
    before = _niceness()
    run_lowered(lambda: seen.append(_niceness()), "study-test")
    assert seen == [min(before + STUDY_NICE, 19)] and _niceness() == before
    with pytest.raises(ValueError, match="boom"):
        run_lowered(lambda: (_ for _ in ()).throw(ValueError("boom")), "study-test")


def test_a_study_pool_s_processes_run_at_lower_priority():
    with RetryingPool(1, nice=STUDY_NICE) as pool:
        worker_nice = pool.submit(os.nice, 0).result(timeout=60.0)
    assert worker_nice == min(os.nice(0) + STUDY_NICE, 19)


def test_the_shared_run_threads_keep_normal_priority_after_a_study_used_them():
    from pmsm_commissioning.sim.fdsmc import engine

    engine.start_run_threads()
    before = _niceness()
    seen: list[int] = []
    run_lowered(lambda: [f.result() for f in [engine._RUNS.submit(lambda: seen.append(_niceness()))
                                              for _ in range(2 * engine.RUN_THREADS)]], "study-test")
    assert seen and set(seen) == {before}  # the study's own thread was lowered, not the shared ones
