"""Nothing orphaned, nothing half-written: a robustness run's pool workers and multiprocessing's
resource tracker end when their parent is killed with SIGKILL (the OOM killer, a CI timeout); SIGHUP
(a closed terminal) stops a command like SIGTERM (exit 130, one line, no process left, the old file
intact); Ctrl-C at any point of a long run (before the pool, as it starts, mid-run; an export)
leaves the output file whole (the previous content) and no temporary file; ``bench --repeat`` is
bounded before any work. Children start with the default signal dispositions
(:mod:`tests.child_signals`), so the tests pass however pytest itself was started.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.sim.studies.runner import PARENT_POLL_S, ExecutorError, RetryingPool, exit_with_parent
from tests.child_signals import default_signals
from tests.test_faults_signals import _no_part_files, _pool_workers, _running, _wait_until, interrupt

ROOT = Path(__file__).resolve().parents[1]
OLD = b"old content that must survive\n"
#: A robustness run long enough to be stopped at any point (each chunk ≈ seconds).
LONG_ROBUSTNESS = ["robustness", "paper_12kw_pmsm", "--samples", "100000", "--workers", "2",
                   "--spread", "plant.J_L=±20%"]


def _start(argv: list[str]) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "pmsm_commissioning.app", *argv], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=default_signals)


def _children(pid: int, marker: bytes) -> list[str]:
    """Child process ids of ``pid`` whose command line holds ``marker``."""
    found = []
    for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split():
        with contextlib.suppress(OSError):
            if marker in Path(f"/proc/{child}/cmdline").read_bytes():
                found.append(child)
    return found


def _workers_started(proc: subprocess.Popen) -> list[str]:
    def started() -> list[str] | None:
        assert proc.poll() is None, proc.communicate()[1][-500:]  # ended before its pool started
        return _pool_workers(proc.pid, 2)

    return _wait_until(started, 120.0, "the pool's two workers")


def _kill_group(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)  # whatever of the group is left (a failed test's workers)


def test_sigkill_of_the_parent_leaves_no_worker_and_no_resource_tracker():
    proc = _start(LONG_ROBUSTNESS)
    try:
        workers = _workers_started(proc)
        tracker = _children(proc.pid, b"resource_tracker")
        os.kill(proc.pid, signal.SIGKILL)  # no handler runs: the workers are orphaned at once
        proc.communicate(timeout=30)
        _wait_until(lambda: not _running(workers + tracker), 30.0, "the workers and the resource tracker gone")
    finally:
        _kill_group(proc)
    assert tracker, "the run's resource tracker was not found"


@pytest.mark.parametrize("sig", [signal.SIGHUP, signal.SIGTERM], ids=["SIGHUP", "SIGTERM"])
def test_sighup_stops_a_pool_run_like_sigterm(tmp_path, sig):
    out = tmp_path / "samples.csv"
    out.write_bytes(OLD)
    proc = _start([*LONG_ROBUSTNESS, "--csv", str(out)])
    try:
        workers = _workers_started(proc)
        os.killpg(proc.pid, sig)  # the whole group, as a terminal's hang-up reaches it
        _, err = proc.communicate(timeout=60)
        _wait_until(lambda: not _running(workers), 30.0, "the workers gone")
    finally:
        _kill_group(proc)
    assert proc.returncode == 130, err[-800:]
    lines = [ln for ln in re.split(r"[\r\n]+", err) if ln.strip()]
    assert "Traceback" not in err and "leaked" not in err and lines[-1].startswith("interrupted"), err[-800:]
    assert out.read_bytes() == OLD and _no_part_files(tmp_path) == []


#: (name, command with {out}, seconds after the command starts working): Ctrl-C at several points
CTRL_C_POINTS = [
    ("robustness --csv, at once", [*LONG_ROBUSTNESS, "--csv", "{out}"], 0.0),
    ("robustness --csv, while starting", [*LONG_ROBUSTNESS, "--csv", "{out}"], 0.5),
    ("robustness --csv, mid-run", [*LONG_ROBUSTNESS, "--csv", "{out}"], "workers"),
    ("export csv, at once", ["export", "yaskawa_sgm7j_02a", "--set", "controller.f_s_kHz=2500", "--format", "csv",
                             "-o", "{out}"], 0.0),
    ("export csv, later", ["export", "yaskawa_sgm7j_02a", "--set", "controller.f_s_kHz=2500", "--format", "csv",
                           "-o", "{out}"], 0.6),
    # --force: the paper's K = 1000 chatters, and a refused export ends (exit 2) before the signal lands
    ("export html, later", ["export", "paper_12kw_pmsm", "--format", "html", "--force", "-o", "{out}"], 0.3),
]


@pytest.mark.parametrize(("name", "argv", "when"), CTRL_C_POINTS, ids=[c[0] for c in CTRL_C_POINTS])
def test_ctrl_c_at_any_point_leaves_the_old_file_whole(tmp_path, name, argv, when):
    out = tmp_path / "result.out"
    out.write_bytes(OLD)
    argv = [a.format(out=out) for a in argv]
    if when == "workers":  # once the pool's workers run chunks, one second into the work
        proc = _start(argv)
        try:
            workers = _workers_started(proc)
            time.sleep(1.0)  # the chunks are running (each takes seconds): the signal lands mid-run
            os.killpg(proc.pid, signal.SIGINT)
            _, err = proc.communicate(timeout=60)
            _wait_until(lambda: not _running(workers), 30.0, "the workers gone")
        finally:
            _kill_group(proc)
        rc = proc.returncode
    else:
        result, _ = interrupt(argv, when)
        rc, err = result.returncode, result.stderr
    assert rc == 130, (name, rc, err[-800:])
    lines = [ln for ln in re.split(r"[\r\n]+", err) if ln.strip()]
    assert "Traceback" not in err and "leaked" not in err and lines[-1].startswith("interrupted"), err[-800:]
    assert out.read_bytes() == OLD, name  # never truncated, never half-written
    assert _no_part_files(tmp_path) == []


def test_bench_repeat_is_bounded_before_any_work(capsys):
    for text in ("1e9", "101", "0"):
        assert main(["bench", "--repeat", text]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--repeat" in err and "allowed: 1 … 100" in err, err


def test_a_worker_whose_parent_is_gone_ends_itself():
    # the check a worker runs at start: a parent other than the pool's process means it is gone already
    code = ("import os\n"
            "from pmsm_commissioning.sim.studies.runner import exit_with_parent\n"
            "exit_with_parent(os.getppid() + 1)\n"
            "print('still running')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, preexec_fn=default_signals)
    assert done.returncode == 1 and "still running" not in done.stdout
    assert PARENT_POLL_S <= 1.0
    exit_with_parent(os.getppid())  # this process's own parent is alive: nothing happens
    with RetryingPool(1) as pool:
        assert pool.submit(os.getppid).result() == os.getpid()  # a worker's parent is the pool's process


def test_a_pool_ended_before_its_first_chunk_starts_no_worker():
    # a study cancelled (or its page closed) before its first chunk: the chunks used to start the
    # workers anyway and the study ran on without a page
    pool = RetryingPool(2)
    pool.terminate()
    with pytest.raises(ExecutorError, match="no chunk started: the local pool was ended"):
        pool.submit(os.getpid)
    assert pool.processes() == []
    pool.shutdown()


def test_a_stop_signal_waits_while_a_worker_is_started_on_the_main_thread():
    # a handler raising between a spawned worker's start and the writing of its start data left the
    # worker reading an empty pipe (an EOFError traceback as Ctrl-C hit the pool's start)
    from pmsm_commissioning.sim.studies.runner import _handlers_held

    seen: list[str] = []

    def handler(signum: int, frame: object) -> None:
        seen.append("handled")

    previous = signal.signal(signal.SIGHUP, handler)
    try:
        with _handlers_held():
            signal.raise_signal(signal.SIGHUP)
            for _ in range(1000):  # bytecode boundaries: a pending handler would run here
                pass
            seen.append("started")
        assert seen == ["started", "handled"]
        assert signal.getsignal(signal.SIGHUP) is handler  # the handler is back in place
    finally:
        signal.signal(signal.SIGHUP, previous)
