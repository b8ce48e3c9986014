"""One background worker per browser client: runs jobs off the GUI event loop, one at a time.

A second submission while a job runs is refused (a double-click never starts two overlapping
runs). Errors a job raises are handed to ``on_error`` so the page can show them instead of a
traceback.

Cancel is cooperative: :meth:`Worker.cancel` sets a flag that jobs test with
:meth:`Worker.checkpoint` between kernel calls (after a comparison, between Table-1 points), and
the result of a cancelled job is discarded. The cost budget (:mod:`sim.common.budget`) bounds every
kernel call to a few seconds of CPU, so a cancel takes effect within that; killing a subprocess
instead would need the JIT-compiled kernels warmed in each process and the traces (up to the
budget's bytes) pickled back, for a gain of at most those seconds.

A job submitted as a study (``submit(fn, study=label)``, or any submission inside
``with worker.as_study(label):``) first waits for a server-wide slot and then runs at lower
priority (:class:`app.ui.studies_queue.StudySlots`); while it waits, ``on_queued(label, ahead)``
tells the page how many studies are ahead of it (-1 once a Cancel took it out of the queue).
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, Protocol


class StudySlots(Protocol):
    """What the worker needs of :class:`app.ui.studies_queue.StudySlots`: run a study once a slot is free."""

    def run(self, label: str, fn: Callable[[], Any], on_queued: Callable[[str, int], None],
            cancelled: Callable[[], bool]) -> None:
        """Run ``fn`` once a slot is free, telling ``on_queued(label, ahead)`` while it waits."""


class Cancelled(Exception):  # noqa: N818 - an outcome, not an error
    """Raised at a checkpoint of a job whose Cancel was pressed; its result is discarded."""


class Worker:
    """Single-thread job runner with a busy flag.

    Parameters
    ----------
    on_busy : callable(bool)
        Called with True when a job starts and False when it ends (e.g. to disable buttons).
    on_error : callable(Exception)
        Called (on the worker thread) with any exception a job raised.
    name : str
        Thread-name prefix, for debugging.
    slots : StudySlots or None
        The server's study slots (None: studies run at once, like any job).
    on_queued : callable(str, int) or None
        Called (on the worker thread) with a queued study's label and the studies ahead of it.
    """

    def __init__(self, on_busy: Callable[[bool], None], on_error: Callable[[Exception], None],
                 name: str = "ui-worker", slots: StudySlots | None = None,
                 on_queued: Callable[[str, int], None] | None = None) -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix=name)
        self._lock = threading.Lock()
        self._busy = False
        self._closed = False
        self._cancel = threading.Event()
        self._hooks: list[Callable[[], None]] = []
        self._on_busy = on_busy
        self._on_error = on_error
        self._slots, self._on_queued = slots, on_queued or (lambda label, ahead: None)
        self._study: str | None = None
        self._tail_cancel = threading.Event()

    @property
    def busy(self) -> bool:
        """True while a job runs."""
        return self._busy

    def submit(self, fn: Callable[[], None], study: str | None = None) -> Future | None:
        """Run ``fn`` on the worker unless a job is running; returns its future or None if refused.

        ``study`` (or an enclosing :meth:`as_study`) names a study: it waits for a server-wide slot.
        """
        label = study or self._study
        with self._lock:
            if self._busy or self._closed:
                return None
            self._busy = True
            self._cancel.clear()
            self._tail_cancel.set()  # a tail still running yields to the new job
        self._safe_busy(True)
        if label is not None and self._slots is not None:
            slots, job = self._slots, fn
            fn = lambda: slots.run(label, job, self._on_queued, self._cancel.is_set)  # noqa: E731
        return self._pool.submit(self._run, fn)

    def submit_tail(self, fn: Callable[[], None]) -> None:
        """Queue ``fn`` after the running job as background work: not busy, and yielding to any new job.

        A tail (e.g. the K sweep after a run) leaves the buttons enabled; the next :meth:`submit`
        makes its next :meth:`tail_checkpoint` raise :class:`Cancelled` (its result is discarded),
        and the new job runs once it has stopped. A cancelled tail is not an error.
        """
        with self._lock:
            if self._closed:
                return
            self._tail_cancel.clear()
        self._pool.submit(self._run_tail, fn)

    def tail_checkpoint(self) -> None:
        """Raise :class:`Cancelled` in a tail once a new job was submitted (or the page closed)."""
        if self._tail_cancel.is_set():
            raise Cancelled("a new job came")

    def _run_tail(self, fn: Callable[[], None]) -> None:
        try:
            self.tail_checkpoint()
            fn()
        except Cancelled:
            pass
        except Exception as exc:  # shown to the user by on_error, never lost
            self._on_error(exc)

    @contextlib.contextmanager
    def as_study(self, label: str) -> Iterator[None]:
        """Within the block, jobs submitted (from this, the GUI thread) are the study ``label``."""
        self._study = label
        try:
            yield
        finally:
            self._study = None

    def cancel(self) -> bool:
        """Ask the running job to stop at its next checkpoint (and run its stop hooks); False if nothing runs."""
        with self._lock:
            if not self._busy:
                return False
            self._cancel.set()
        self._run_hooks()
        return True

    def on_cancel(self, hook: Callable[[], None]) -> Callable[[], None]:
        """Register ``hook`` to run when the job is cancelled or the worker closed; returns its remover.

        E.g. to end a process pool the job waits on, instead of waiting for its next checkpoint.
        """
        with self._lock:
            self._hooks.append(hook)
            cancelled = self._cancel.is_set()
        if cancelled:
            hook()

        def remove() -> None:
            with self._lock:
                if hook in self._hooks:
                    self._hooks.remove(hook)

        return remove

    def _run_hooks(self) -> None:
        with self._lock:
            hooks = list(self._hooks)
        for hook in hooks:
            try:
                hook()
            except Exception as exc:  # a failing hook must not stop the others
                self._on_error(exc)

    def checkpoint(self) -> None:
        """Raise :class:`Cancelled` after :meth:`cancel`; jobs call this between pieces of work."""
        if self._cancel.is_set():
            raise Cancelled("cancelled by the user")

    def _run(self, fn: Callable[[], None]) -> None:
        try:
            fn()
        except Exception as exc:  # shown to the user by on_error, never lost
            self._on_error(exc)
        finally:
            with self._lock:
                self._busy = False
            self._safe_busy(False)

    def _safe_busy(self, busy: bool) -> None:
        try:
            self._on_busy(busy)
        except Exception as exc:  # a closed client must not break the worker
            self._on_error(exc)

    def close(self) -> None:
        """Refuse new jobs and stop the current one at its next checkpoint (the page disconnected).

        A study's process pool is shut down by the job itself as it ends, so no work outlives the page.
        """
        with self._lock:
            self._closed = True
            self._cancel.set()
            self._tail_cancel.set()
        self._run_hooks()
        self._pool.shutdown(wait=False, cancel_futures=True)
