"""One background worker per browser client: runs jobs off the GUI event loop, one at a time.

A second submission while a job runs is refused (a double-click never starts two overlapping
runs). Errors a job raises are handed to ``on_error`` so the page can show them instead of a
traceback.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor


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
    """

    def __init__(self, on_busy: Callable[[bool], None], on_error: Callable[[Exception], None],
                 name: str = "ui-worker") -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix=name)
        self._lock = threading.Lock()
        self._busy = False
        self._closed = False
        self._on_busy = on_busy
        self._on_error = on_error

    @property
    def busy(self) -> bool:
        """True while a job runs."""
        return self._busy

    def submit(self, fn: Callable[[], None]) -> Future | None:
        """Run ``fn`` on the worker unless a job is running; returns its future or None if refused."""
        with self._lock:
            if self._busy or self._closed:
                return None
            self._busy = True
        self._safe_busy(True)
        return self._pool.submit(self._run, fn)

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
        """Refuse new jobs and let the thread end after the current one."""
        with self._lock:
            self._closed = True
        self._pool.shutdown(wait=False, cancel_futures=True)
