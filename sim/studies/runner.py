"""Local executor of the studies: a process pool that retries the chunks of a lost worker once.

:class:`RetryingPool` has the ``submit(fn, *args) -> future`` / ``future.result()`` interface that
:func:`sim.studies.robustness.robustness` hands its chunks to. When a worker process dies (killed,
out of memory) ``concurrent.futures`` marks the whole pool broken and fails every pending future;
the pool is then replaced by a new one and every chunk not finished is submitted again, once. A
chunk that the pool loses a second time raises :class:`ExecutorError` (one line: which chunk, what
happened, what is allowed). Workers are started with ``spawn`` (no fork of a threaded parent) and
each runs its chunks on one numba thread: the processes are the parallelism. ``nice`` lowers the
workers' scheduling priority (so that a server's interactive work comes first). Workers start
with SIGINT and SIGHUP blocked (:class:`_QuietSpawn`): a Ctrl-C typed as the pool starts, or a closed
terminal's hang-up, reaches the whole process group, and the parent alone answers it (ending the
workers), so no worker prints a traceback. Every worker ends itself once its parent is gone
(:func:`exit_with_parent`): a parent killed with SIGKILL (the OOM killer, a CI timeout) leaves no
worker behind, nor the resource tracker (which ends when the last process holding its pipe does).
The resource tracker is started with SIGHUP blocked too (:func:`_start_resource_tracker`): it ignores
SIGINT and SIGTERM itself, and a hang-up that killed it made the parent start a new one, which then
printed a KeyError traceback for every semaphore the pool released. Its warning about the
semaphores of a parent that exited at once (an interrupted run: they are removed all the same) is off.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
import weakref
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import resource_tracker
from multiprocessing.context import SpawnContext, SpawnProcess
from typing import Any

#: How often a chunk may be submitted again after its worker was lost [-].
RETRIES = 1
#: Longest single wait for a chunk without a timeout [s]. The operating system may hand a process's
#: signal to any of its threads; Python's handler then only sets a flag, which the main thread reads when it
#: wakes: a wait in slices keeps Ctrl-C and SIGTERM prompt however long the chunk runs.
WAIT_SLICE_S = 0.2
#: How often a worker looks whether its parent process is still there [s].
PARENT_POLL_S = 0.25
#: Signals a worker starts with blocked: the parent answers them for the whole pool.
BLOCKED_IN_WORKERS = frozenset({signal.SIGINT, signal.SIGHUP})


#: Signals whose Python handlers wait while a worker is started on the main thread.
HELD_WHILE_STARTING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


@contextlib.contextmanager
def _handlers_held() -> Iterator[None]:
    """On the main thread, hold the stop signals' Python handlers until the block ends, then run them.

    A handler that raises (Ctrl-C's KeyboardInterrupt) between the start of a spawned worker and
    the writing of its start data left the worker reading an empty pipe: an EOFError traceback.
    """
    if threading.current_thread() is not threading.main_thread():
        yield  # handlers run on the main thread only: this thread is not interrupted
        return
    caught: list[int] = []
    held = {sig: signal.signal(sig, lambda signum, _: caught.append(signum))
            for sig in HELD_WHILE_STARTING if callable(signal.getsignal(sig))}
    try:
        yield
    finally:
        for sig, handler in held.items():
            signal.signal(sig, handler)
        if caught:
            signal.raise_signal(caught[0])  # now its own handler runs


class _QuietProcess(SpawnProcess):
    """A spawned process that inherits SIGINT and SIGHUP blocked (the mask survives fork and exec)."""

    def start(self) -> None:
        """Start the process with those signals blocked in this thread meanwhile (a pending one is then delivered)."""
        old = signal.pthread_sigmask(signal.SIG_BLOCK, BLOCKED_IN_WORKERS)
        try:
            with _handlers_held():
                super().start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


#: Warning filter of the resource tracker (its ``-W`` option): no "leaked semaphore objects" after a
#: parent that exited at once on Ctrl-C or SIGTERM (the tracker removes them all the same).
QUIET_TRACKER = "ignore:resource_tracker:UserWarning"


def _start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker (if not running) with the workers' signals blocked.

    The tracker unblocks only SIGINT and SIGTERM (which it ignores): SIGHUP stays blocked in it. It is
    started with the interpreter's ``-W`` options, and :data:`QUIET_TRACKER` among them.
    """
    old = signal.pthread_sigmask(signal.SIG_BLOCK, BLOCKED_IN_WORKERS)
    sys.warnoptions.append(QUIET_TRACKER)
    try:
        resource_tracker.ensure_running()
    finally:
        sys.warnoptions.remove(QUIET_TRACKER)
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class _QuietSpawn(SpawnContext):
    """The ``spawn`` start method whose processes never see Ctrl-C (their parent ends them)."""

    Process = _QuietProcess


class ExecutorError(RuntimeError):
    """The executor failed (workers lost, cluster gone): the message is one line naming what happened."""


class RetryingFuture:
    """Result of one chunk on a :class:`RetryingPool`; ``result()`` resubmits it once after a lost worker."""

    def __init__(self, pool: RetryingPool, index: int, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self._pool, self.index, self._fn, self._args = pool, index, fn, args
        self.attempts = 0
        self.future: Future[Any] = pool.raw_submit(fn, *args)
        self.generation = pool.generation

    def resubmit(self) -> None:
        """Submit again on the pool's current generation (one more attempt)."""
        self.attempts += 1
        self.future = self._pool.raw_submit(self._fn, *self._args)
        self.generation = self._pool.generation

    def result(self, timeout: float | None = None) -> Any:
        """Return the chunk's result, replacing a broken pool once; ExecutorError after that."""
        while True:
            try:
                return self._wait(timeout)
            except BrokenProcessPool as exc:
                if self._pool.ended:
                    raise ExecutorError(f"chunk {self.index} stopped: the local pool was ended (the run was "
                                        "cancelled); allowed: a pool left running") from None
                if self.attempts >= RETRIES:
                    raise ExecutorError(
                        f"chunk {self.index} lost its worker process {self.attempts + 1} times ({exc}): allowed "
                        f"{RETRIES} retry; see the system log for a process killed (e.g. out of memory)") from None
                self._pool.renew(self.generation)

    def _wait(self, timeout: float | None) -> Any:
        """``future.result(timeout)``; without a timeout in slices of :data:`WAIT_SLICE_S`."""
        if timeout is not None:
            return self.future.result(timeout)
        while True:
            try:
                return self.future.result(WAIT_SLICE_S)
            except TimeoutError:
                if self.future.done():
                    raise  # the chunk's own TimeoutError
                # not done yet: back to the interpreter, which runs a pending signal's handler

    def cancel(self) -> bool:
        """Cancel the chunk if it has not started."""
        return self.future.cancel()


def lower_priority(increment: int) -> None:
    """Lower the calling thread's scheduling priority by ``increment`` (no-op where unsupported).

    On Linux a priority is per thread: a study's thread, or a pool worker's main thread (its
    initializer), so the worker's own threads start lowered as well.
    """
    if increment > 0:
        with contextlib.suppress(AttributeError, OSError):
            tid = threading.get_native_id()
            os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + increment)


def _watch_parent(parent: int) -> None:
    """End this process once its parent ``parent`` is gone (it is then reparented: init or a subreaper)."""
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    os._exit(1)  # nothing of the worker's is kept: its chunk's result would have no reader


def exit_with_parent(parent: int | None = None) -> None:
    """Make the calling process (a pool worker) exit within :data:`PARENT_POLL_S` of its parent's death.

    ``parent``: the process id the worker's parent must have (the pool's process for ``spawn``; None:
    the parent it has now, e.g. a forkserver). A watchdog thread compares ``os.getppid()`` with it.
    (Linux's parent-death signal, ``prctl(PR_SET_PDEATHSIG)``, fires when the parent's *thread* that
    started the worker ends, and a pool starts workers from whichever thread submits first: it could
    end a worker of a living parent.)
    """
    now = os.getppid()
    if parent is not None and now != parent:  # the parent died before this worker got here
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(now,), name="parent-watchdog", daemon=True).start()


def start_worker(nice: int, parent: int) -> None:
    """Start a pool worker: exit with the parent ``parent`` (:func:`exit_with_parent`), lowered priority."""
    exit_with_parent(parent)
    lower_priority(nice)


#: Every pool of this process not yet garbage (for :func:`end_all_pools`).
_POOLS: weakref.WeakSet[RetryingPool] = weakref.WeakSet()


def end_all_pools() -> None:
    """End every :class:`RetryingPool` of this process now (a command stopped by a signal exits next).

    Each is marked ended under its lock before its workers are terminated, so a chunk that sees its
    worker gone does not start a new pool (a worker half-started as the process exits prints an
    EOFError traceback).
    """
    for pool in list(_POOLS):
        pool.terminate()


class RetryingPool:
    """A spawn-context process pool of ``workers`` processes that survives one lost worker per chunk.

    ``nice`` [-] lowers each worker's scheduling priority by that much (0: unchanged).
    """

    def __init__(self, workers: int, nice: int = 0) -> None:
        self.workers, self.nice = int(workers), int(nice)
        self.generation = 0
        self.ended = False
        self._lock = threading.RLock()  # renew() submits again while holding it
        self._pool = self._new_pool()
        self._futures: list[RetryingFuture] = []
        _POOLS.add(self)

    def _new_pool(self) -> ProcessPoolExecutor:
        _start_resource_tracker()
        return ProcessPoolExecutor(self.workers, mp_context=_QuietSpawn(), initializer=start_worker,
                                   initargs=(self.nice, os.getpid()))

    def raw_submit(self, fn: Callable[..., Any], *args: Any) -> Future[Any]:
        """Submit to the current process pool (no retry); :class:`ExecutorError` once the pool was ended.

        Under the lock :meth:`terminate` takes: a worker is never started after the pool was ended
        (the pool starts its workers as chunks are submitted, so a study cancelled before its first
        chunk, or its page closed then, would otherwise start them and run on without a page).
        """
        with self._lock:
            if self.ended:
                raise ExecutorError("no chunk started: the local pool was ended (the run was cancelled); "
                                    "allowed: a pool left running")
            return self._pool.submit(fn, *args)

    def submit(self, fn: Callable[..., Any], *args: Any) -> RetryingFuture:
        """Submit one chunk; its index is the order of submission."""
        f = RetryingFuture(self, len(self._futures), fn, args)
        self._futures.append(f)
        return f

    def renew(self, broken_generation: int) -> None:
        """Replace the pool broken in ``broken_generation`` and resubmit every chunk not finished."""
        with self._lock:
            if broken_generation != self.generation or self.ended:
                return  # another chunk already replaced it, or the pool was ended on purpose
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = self._new_pool()
            self.generation += 1
            for f in self._futures:
                if f.generation < self.generation and not _finished(f.future):
                    f.resubmit()

    def terminate(self) -> None:
        """End the workers now (a cancelled run): their chunks are not waited for, nor run again."""
        with self._lock:
            self.ended = True
            for proc in list((self._pool._processes or {}).values()):
                proc.terminate()
            self._pool.shutdown(wait=False, cancel_futures=True)  # nothing more starts

    def processes(self) -> list[int]:
        """Process ids of the current workers (for tests and diagnostics)."""
        return [p.pid for p in (self._pool._processes or {}).values() if p.pid is not None]

    def shutdown(self, wait: bool = True, cancel_futures: bool = False) -> None:
        """Shut the current pool down."""
        self._pool.shutdown(wait=wait, cancel_futures=cancel_futures)

    def __enter__(self) -> RetryingPool:
        """Return self."""
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *exc: object) -> None:
        """Shut down, cancelling what has not started; after an error or an interrupt, end the workers now.

        Nothing of a run that stops early is kept, so its running chunks are not waited for
        (Ctrl-C or a SIGTERM from a service manager ends the command at once).
        """
        if exc_type is not None:
            self.terminate()
        self.shutdown(wait=True, cancel_futures=True)  # ended workers: returns at once


def _finished(f: Future[Any]) -> bool:
    """Return True when ``f`` holds a result (not an exception such as BrokenProcessPool)."""
    return f.done() and not f.cancelled() and f.exception() is None
