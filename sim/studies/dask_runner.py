"""Dask executor of the studies: one connection checked, tuned and warmed before any chunk is sent.

Imports dask only inside its functions (``control/`` and ``sim/`` stay importable without it).
:func:`connect` opens a client on a running ``dask scheduler`` and:

* waits at most ``no_worker_s`` for a worker (else :class:`~sim.studies.runner.ExecutorError`);
* compares each worker's :func:`sim.source_hash` with the client's, before anything is compiled:
  a worker running other source is refused, by name;
* registers :func:`worker_plugin` (unless ``tuned=False``): on every worker, now and joining later,
  glibc's allocator keeps freed trace buffers for reuse (Dask's nanny starts workers with
  ``MALLOC_TRIM_THRESHOLD_=65536``, which turns every ≥ 128 KiB array into a fresh ``mmap`` and
  its page faults) and the statistical profiler is stopped (it samples every thread each 10 ms);
* loads the compiled kernels on every worker (``client.run``);
* submits each chunk with ``pure=False`` under a key holding the run and chunk index (two equal
  chunks are two tasks), and the task checks the source hash again (a worker restarted later).

Waiting for a chunk, a cluster without workers for ``no_worker_s``, a task that killed
``allowed-failures`` workers (``KilledWorker``) and a lost scheduler each raise ExecutorError
with one line.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import threading
import time
import uuid
from collections.abc import Callable
from typing import Any

import numpy as np

from pmsm_commissioning.sim.studies.runner import ExecutorError

#: Seconds the cluster may have no worker before a run is abandoned (and the default wait at start).
NO_WORKER_S = 60.0
#: Polling period of a waiting chunk [s] (worker count, scheduler alive).
POLL_S = 1.0
#: glibc allocator settings of a tuned worker [bytes]: arrays below stay in the heap, freed memory is kept.
MMAP_THRESHOLD_B = 64 << 20
TRIM_THRESHOLD_B = 256 << 20
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Least period [ms] of the housekeeping callbacks of a tuned worker and its nanny (Dask: 20, 100, 500):
#: the event-loop health tick, the memory monitor (pause/spill/terminate checks) and the system monitor
#: (dashboard figures). At Dask's rates an idle worker and its nanny take ≈ 30 ms of CPU per second
#: between them, ≈ 10 % of a study's CPU on a 2-core machine.
QUIET_MS = {"tick": 1000.0, "memory_monitor": 500.0, "monitor": 2000.0}


class SourceMismatchError(RuntimeError):
    """A worker runs other ``control/``/``sim/`` source than the client."""


@functools.lru_cache(maxsize=1)
def local_hash() -> str:
    """Return :func:`sim.source_hash` of this process (read once)."""
    import pmsm_commissioning.sim as sim

    return sim.source_hash()


def warm() -> float:
    """Load (or compile) the batch kernel in this process; returns the seconds it took."""
    from pmsm_commissioning.sim.fdsmc import kernel as kn
    from pmsm_commissioning.sim.fdsmc import layout as lay
    from pmsm_commissioning.sim.studies.batch import run_batch

    t0 = time.perf_counter()
    z1 = np.zeros(0)
    run_batch(np.zeros((1, lay.N_PRM)), z1, z1, np.zeros((4, 4)), np.zeros(4), np.zeros(4), False, 1e-4, 1, 1,
              0, 1, np.zeros((1, lay.N_CH, 1)), np.zeros((1, lay.N_INFO)), np.zeros(1, dtype=np.int64),
              np.zeros((1, kn.WIN_ROWS, 1)), np.zeros((3, 2)), np.zeros((2, 1)), 0)
    return time.perf_counter() - t0


def tune_allocator() -> bool:
    """Keep freed arrays in glibc's heap (undo ``MALLOC_TRIM_THRESHOLD_``); False where not glibc."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        return bool(libc.mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_B)) and bool(
            libc.mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_B))
    except (OSError, AttributeError):
        return False


def quiet(server: Any, periods: dict[str, float] | None = None) -> dict[str, float]:
    """Slow ``server``'s housekeeping callbacks to ``periods`` [ms] (default :data:`QUIET_MS`, never faster).

    Returns the periods they had, for :func:`quiet` to restore them.
    """
    before = {}
    for name, ms in (QUIET_MS if periods is None else periods).items():
        pc = server.periodic_callbacks.get(name)
        if pc is not None:
            before[name] = pc.callback_time
            pc.callback_time = max(pc.callback_time, ms) if periods is None else ms
    return before


def tune_worker(worker: Any) -> None:
    """Keep the allocator's freed memory, stop the statistical profiler, slow the housekeeping (:func:`quiet`).

    The worker plugin's setup.

    The kernels are not loaded here (that would block the worker's event loop for a compilation
    on a worker without a cache): :func:`connect` loads them with ``client.run``, a worker that
    joins later loads them with its first chunk.
    """
    tune_allocator()
    quiet(worker)
    for name in ("profile", "profile-cycle"):
        pc = worker.periodic_callbacks.pop(name, None)
        if pc is not None:
            pc.stop()


def worker_plugin() -> Any:
    """Return the WorkerPlugin that runs :func:`tune_worker` on every worker (dask imported here)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class StudyWorker(WorkerPlugin):
        name = "pmsm-study-worker"

        def setup(self, worker: Any) -> None:
            tune_worker(worker)

    return StudyWorker()


def nanny_plugin() -> Any:
    """Return the NannyPlugin that slows each nanny's housekeeping (:func:`quiet`) until it is removed."""
    from distributed.diagnostics.plugin import NannyPlugin

    class StudyNanny(NannyPlugin):
        name, restart, idempotent = "pmsm-study-nanny", False, True

        def setup(self, nanny: Any) -> None:
            self.before = quiet(nanny)

        def teardown(self, nanny: Any) -> None:
            quiet(nanny, getattr(self, "before", {}))

    return StudyNanny()


def checked_chunk(expected: str, fn: Callable[..., Any], *args: Any) -> Any:
    """Run ``fn(*args)`` on a worker after checking that it runs the client's source."""
    if local_hash() != expected:
        raise SourceMismatchError(f"a worker runs source {local_hash()} but the client {expected}: allowed only "
                             "workers with the client's version of control/ and sim/")
    return fn(*args)


def _line(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".split())


class DaskChunk:
    """One submitted chunk; ``result()`` watches the cluster while it waits."""

    def __init__(self, ex: DaskExecutor, index: int, future: Any) -> None:
        self._ex, self.index, self.future = ex, index, future

    def result(self) -> Any:
        """Return the chunk's result; ExecutorError for no workers, KilledWorker, a lost scheduler, other source."""
        from distributed import CancelledError, KilledWorker

        box: dict[str, Any] = {}
        self._watch(box)
        try:
            if "error" in box:
                raise box["error"]
            return box["value"]
        except KilledWorker as exc:
            raise ExecutorError(f"chunk {self.index} killed the workers that ran it on the Dask cluster at "
                                f"{self._ex.address} ({_line(exc)}): allowed fewer than "
                                "distributed.scheduler.allowed-failures losses per task") from None
        except SourceMismatchError as exc:
            raise ExecutorError(str(exc)) from None
        except (CancelledError, OSError) as exc:
            raise ExecutorError(self._ex.lost_message(exc)) from None

    def _watch(self, box: dict[str, Any]) -> None:
        """Fetch the result into ``box`` on a helper thread, asking the scheduler for workers every POLL_S.

        A finished result whose worker dies before it is fetched is "lost" again and recomputed, so
        the fetch itself is watched; it is never awaited with a timeout (an abandoned timed wait
        leaves a pending coroutine that logs a traceback when the run is given up). A fetch still
        blocked when the run is abandoned ends when the client closes.
        """
        def fetch() -> None:
            try:
                box["value"] = self.future.result()
            except BaseException as exc:  # noqa: BLE001 — handed to the caller's thread
                box["error"] = exc

        helper = threading.Thread(target=fetch, name=f"fetch-chunk-{self.index}", daemon=True)
        helper.start()
        since: float | None = None
        while helper.is_alive():
            helper.join(POLL_S)
            if not helper.is_alive():
                break
            since = None if self._ex.worker_count() else since or time.monotonic()
            if since is not None and time.monotonic() - since > self._ex.no_worker_s:
                raise ExecutorError(self._ex.no_workers_message())

    def cancel(self) -> None:
        """Cancel the task unless it is done (a finished one is released with its future)."""
        if not self.future.done():
            self.future.cancel()


class DaskExecutor:
    """``submit``/``result`` on a checked Dask cluster (see the module docstring)."""

    def __init__(self, client: Any, address: str, no_worker_s: float, workers: int) -> None:
        self.client, self.address, self.no_worker_s, self.workers = client, address, no_worker_s, workers
        self.run_id, self._n = uuid.uuid4().hex[:8], 0
        self.warm_s: dict[str, float] = {}  # worker → seconds its kernels took to load

    def submit(self, fn: Callable[..., Any], *args: Any) -> DaskChunk:
        """Submit one chunk (key ``robustness-RUN-chunk-J``, never deduplicated)."""
        j, self._n = self._n, self._n + 1
        key = f"robustness-{self.run_id}-chunk-{j}"
        return DaskChunk(self, j, self.client.submit(checked_chunk, local_hash(), fn, *args, key=key, pure=False))

    def worker_count(self) -> int:
        """Workers the scheduler has now; ExecutorError when the scheduler cannot be asked."""
        try:
            return len(self.client.nthreads())
        except Exception as exc:  # noqa: BLE001 — any failure to ask is a lost scheduler
            raise ExecutorError(self.lost_message(exc)) from None

    def no_workers_message(self) -> str:
        """One line: the cluster had no workers for too long."""
        return (f"the Dask cluster at {self.address} has had no worker for {self.no_worker_s:g} s: allowed at most "
                f"{self.no_worker_s:g} s (--cluster-timeout); start workers with `dask worker {self.address}`")

    def lost_message(self, exc: BaseException) -> str:
        """One line: the connection to the scheduler is gone."""
        return f"lost the Dask scheduler at {self.address} ({_line(exc)}): allowed a scheduler that stays up"

    def close(self) -> None:
        """Close the client (never raises)."""
        with contextlib.suppress(Exception):  # closing the client of a dead scheduler may fail: nothing to do
            self.client.close(timeout=5)

    def __enter__(self) -> DaskExecutor:
        """Return self."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Close the client."""
        self.close()


def connect(address: str, no_worker_s: float = NO_WORKER_S, tuned: bool = True) -> DaskExecutor:
    """Open, check, tune and warm a cluster (see the module docstring); ExecutorError with one line."""
    from distributed import Client

    try:
        client = Client(address, timeout=f"{max(1.0, min(no_worker_s, 30.0))}s")
    except (OSError, TimeoutError) as exc:
        raise ExecutorError(f"cannot reach the Dask scheduler at {address!r} ({_line(exc)}): allowed the address "
                            "tcp://HOST:PORT of a running `dask scheduler`") from None
    from distributed import CancelledError

    ex = DaskExecutor(client, address, no_worker_s, 0)
    try:
        _check_workers(ex, tuned)
    except ExecutorError:
        ex.close()
        raise
    except (Exception, CancelledError) as exc:  # a worker or the scheduler lost while checking
        ex.close()
        raise ExecutorError(f"the Dask cluster at {address} failed while its workers were checked and warmed "
                            f"({_line(exc)}): allowed a cluster whose workers stay up") from None
    return ex


def _check_workers(ex: DaskExecutor, tuned: bool) -> None:
    """Wait for a worker, refuse other source (before anything is compiled), then tune and warm."""
    try:
        ex.client.wait_for_workers(1, timeout=ex.no_worker_s)
    except TimeoutError:
        raise ExecutorError(ex.no_workers_message()) from None
    found = ex.client.run(local_hash)
    mine = local_hash()
    bad = {addr: h for addr, h in found.items() if h != mine}
    if bad:
        addr, h = next(iter(bad.items()))
        raise ExecutorError(f"the Dask cluster at {ex.address} is refused: worker {addr} runs source {h} "
                            f"({len(bad)} of {len(found)} differ) but this client runs {mine}: allowed only "
                            "workers with the same control/ and sim/ (install the same commit everywhere)")
    if tuned:
        ex.client.register_plugin(worker_plugin())
        ex.client.register_plugin(nanny_plugin())
    ex.warm_s = ex.client.run(warm)
    ex.workers = len(ex.warm_s)
