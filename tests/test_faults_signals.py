"""Nothing lost: Ctrl-C (SIGINT to the process group, as a terminal sends it) or SIGTERM
stops each long command with exit 130 and one line, no traceback; a file being replaced keeps its
old content and no temporary file is left, also when the signal arrives while numba compiles (cold
cache). Every child starts with the default signal dispositions (:mod:`tests.child_signals`), so the
tests pass when pytest itself was started with SIGINT ignored. The stop latency is printed by
``scripts/bench_interrupt.py`` (not asserted here beyond the wait limit).
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from pmsm_commissioning.app.io import atomic
from pmsm_commissioning.app.io.atomic import discard_partial, write_atomic
from tests.child_signals import default_signals
from tests.net import free_port

ROOT = Path(__file__).resolve().parents[1]
OLD = b"old content that must survive\n"
FAST = ["--set", "controller.f_s_kHz=2500", "--set", "manoeuvre.T_m=1.0"]  # ≈ 1 s of compute, within budget
#: (name, command line with {out} for the file, seconds after the command starts working)
LONG_COMMANDS = [
    ("simulate --csv", ["simulate", "yaskawa_sgm7j_02a", *FAST, "--csv", "{out}"], 0.3),
    ("simulate --csv, at once", ["simulate", "yaskawa_sgm7j_02a", *FAST, "--csv", "{out}"], 0.0),
    ("export csv", ["export", "yaskawa_sgm7j_02a", *FAST, "--format", "csv", "-o", "{out}"], 0.3),
    ("export html", ["export", "paper_12kw_pmsm", "--format", "html", "-o", "{out}"], 0.1),
    ("design -o", ["design", "yaskawa_sgm7j_04a", "-o", "{out}"], 0.1),
    ("table1", ["table1", "paper_12kw_pmsm", "--set", "controller.f_s_kHz=500"], 0.3),
    ("bldc", ["bldc", "bldc_smc_paper"], 0.1),
]


def _working(pid: int) -> bool:
    """True once the command runs in its worker thread (a second thread of the process)."""
    try:
        return len(os.listdir(f"/proc/{pid}/task")) >= 2
    except OSError:
        return False


def interrupt(argv: list[str], after_s: float, sig: int = signal.SIGINT) -> tuple[subprocess.CompletedProcess, float]:
    """Run ``pmsm-commission ARGV``; ``after_s`` after its command started working, send ``sig`` to its
    process group as a terminal does. Returns (result, time from the signal to the exit [s]).
    """
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "pmsm_commissioning.app", *argv], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=default_signals)
    for _ in range(3000):  # imports, preset, argument parsing: then the worker thread starts
        if _working(proc.pid) or proc.poll() is not None:
            break
        time.sleep(0.01)  # poll the process again (a positive condition)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=after_s)
    t0 = time.perf_counter()
    if proc.poll() is None:
        os.killpg(proc.pid, sig)
    out, err = proc.communicate(timeout=30)
    return subprocess.CompletedProcess(argv, proc.returncode, out, err), time.perf_counter() - t0


def _no_part_files(folder: Path) -> list[str]:
    return [p.name for p in folder.iterdir() if p.name.endswith(".part")]


@pytest.mark.parametrize(("name", "argv", "after_s"), LONG_COMMANDS, ids=[c[0] for c in LONG_COMMANDS])
def test_sigint_stops_with_130_one_line_and_no_partial_file(tmp_path, name, argv, after_s):
    out = tmp_path / "result.out"
    out.write_bytes(OLD)
    result, _ = interrupt([a.format(out=out) for a in argv], after_s)
    assert result.returncode == 130, (name, result.returncode, result.stderr[-500:])
    # one line of message, after the whole progress lines the command wrote (stderr is not a terminal here)
    lines = [ln for ln in re.split(r"[\r\n]+", result.stderr) if ln.strip()]
    assert "Traceback" not in result.stderr and lines[-1].startswith("interrupted"), result.stderr
    assert all(ln.strip().startswith("simulated") for ln in lines[:-1]), result.stderr
    assert out.read_bytes() == OLD  # never truncated, never half-written
    assert _no_part_files(tmp_path) == []


def test_sigterm_stops_simulate_like_sigint(tmp_path):
    out = tmp_path / "run.csv"
    out.write_bytes(OLD)
    result, _ = interrupt(["simulate", "yaskawa_sgm7j_02a", *FAST, "--csv", str(out)], 0.3, signal.SIGTERM)
    assert result.returncode == 130 and "Traceback" not in result.stderr
    assert out.read_bytes() == OLD and _no_part_files(tmp_path) == []


def test_write_atomic_interrupted_at_the_rename_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "x.csv"
    target.write_bytes(OLD)

    def boom(*_: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic.os, "replace", boom)
    with pytest.raises(KeyboardInterrupt):
        write_atomic(target, b"new" * 1000)
    assert target.read_bytes() == OLD and _no_part_files(tmp_path) == []


def test_write_atomic_replaces_keeps_mode_and_writes_through_a_link(tmp_path):
    target = tmp_path / "x.yaml"
    target.write_bytes(OLD)
    target.chmod(0o640)
    link = tmp_path / "link.yaml"
    link.symlink_to(target)
    write_atomic(link, b"new\n")
    assert link.is_symlink() and target.read_bytes() == b"new\n" and target.stat().st_mode & 0o777 == 0o640
    assert _no_part_files(tmp_path) == [] and discard_partial() == []


def test_write_atomic_full_disk_leaves_nothing(tmp_path, monkeypatch):
    target = tmp_path / "x.csv"
    target.write_bytes(OLD)

    def full(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, "fsync", full)
    with pytest.raises(OSError, match="No space"):
        write_atomic(target, b"new")
    assert target.read_bytes() == OLD and _no_part_files(tmp_path) == []


#: tgkill(2) by machine: a signal to one thread of another process (the kernel's choice made ours).
TGKILL = {"x86_64": 234, "aarch64": 131}


def _to_a_side_thread(pid: int, sig: int, asleep_in: str = "hrtimer_nanosleep") -> None:
    """Send ``sig`` to a thread of ``pid`` other than its main thread (as the kernel may for a kill),
    once the main thread is seen asleep in the kernel function ``asleep_in`` (its wchan, a prefix).
    """
    def side_thread() -> int | None:  # a side thread runs; the main thread sleeps where the signal's flag goes unread
        tid = max(int(t) for t in os.listdir(f"/proc/{pid}/task"))  # the main thread's id is the pid
        asleep = Path(f"/proc/{pid}/task/{pid}/wchan").read_text().startswith(asleep_in)
        return tid if tid != pid and asleep else None

    tid = _wait_until(side_thread, 60.0, f"a side thread, the main thread asleep in {asleep_in}")
    assert os.uname().machine in TGKILL, f"no tgkill number known for {os.uname().machine}"
    number = TGKILL[os.uname().machine]
    assert ctypes.CDLL(None, use_errno=True).syscall(number, pid, tid, sig) == 0


@pytest.mark.parametrize(("sig", "side"), [(signal.SIGINT, False), (signal.SIGTERM, False), (signal.SIGTERM, True)],
                         ids=["SIGINT", "SIGTERM", "SIGTERM to a side thread"])
def test_the_server_stops_at_once_with_130_and_one_line(sig, side):
    # the web server's threads (sessions, simulations in flight) are never waited for: a SIGTERM from
    # a service manager or Ctrl-C ends it within a second, like every other command. The kernel may
    # hand a process's signal to any thread; Python then only sets a flag the main thread reads
    # when it wakes, so the serve loop must not sleep long (it slept an hour: the server ignored it)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    argv = [sys.executable, "-m", "pmsm_commissioning.app", "serve", "--port", str(free_port()), "--no-3d"]
    proc = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_signals)
    try:
        for line in proc.stdout:  # wait for the URL: the server is up
            if "http://" in line:
                break
        t0 = time.perf_counter()
        if side:
            _to_a_side_thread(proc.pid, sig)
        else:
            os.killpg(proc.pid, sig)
        _, err = proc.communicate(timeout=30)
        waited = time.perf_counter() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err[-500:]
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("interrupted"), err
    assert waited < 10.0


def test_robustness_stops_at_once_on_sigterm_to_a_side_thread_and_ends_its_workers():
    # the main thread waits for a chunk of ≈ 3000 samples (≈ 10 s); it used to read the signal's flag
    # only when that chunk ended, and then waited for the running chunks of the other worker too
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    argv = [sys.executable, "-m", "pmsm_commissioning.app", "robustness", "paper_12kw_pmsm", "--samples", "100000",
            "--workers", "2",
            "--spread", "plant.J_L=±20%"]
    proc = subprocess.Popen(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_signals)
    try:
        def started() -> list[str] | None:
            assert proc.poll() is None, proc.communicate()[1][-500:]  # ended before its pool started
            return _pool_workers(proc.pid, 2)

        workers = _wait_until(started, 120.0, "the pool's two workers")
        t0 = time.perf_counter()
        _to_a_side_thread(proc.pid, signal.SIGTERM, asleep_in="futex")  # waiting for a chunk
        _, err = proc.communicate(timeout=120)
        waited = time.perf_counter() - t0
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)  # the workers too
    assert proc.returncode == 130, err[-500:]
    assert "Traceback" not in err and "leaked" not in err and err.strip().splitlines()[-1].startswith("interrupted")
    assert waited < 3.0  # a chunk takes longer than that
    # the ended workers are gone (reaped by init once their parent exited)
    _wait_until(lambda: not _running(workers), 10.0, "the workers gone")


def _wait_until(ready: Callable[[], Any], timeout_s: float, what: str) -> Any:
    """Poll ``ready()`` until it returns a true value (returned) within ``timeout_s``; else fail naming ``what``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = ready()
        if value:
            return value
        time.sleep(0.01)  # poll again (a positive condition)
    raise AssertionError(f"not seen within {timeout_s:g} s: {what} (the case is not set up)")


def _pool_workers(pid: int, n: int) -> list[str] | None:
    """The process ids of the ``n`` pool workers of ``pid`` (spawned children; not its resource tracker)."""
    workers = []
    for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split():
        with contextlib.suppress(OSError):
            if b"spawn_main" in Path(f"/proc/{child}/cmdline").read_bytes():
                workers.append(child)
    return workers if len(workers) == n else None


def _running(pids: list[str]) -> list[str]:
    """The processes of ``pids`` that still exist and are not zombies."""
    alive = []
    for pid in pids:
        with contextlib.suppress(OSError):
            if Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z":
                alive.append(pid)
    return alive


#: ``python -c`` text: the CLI, with SIGTERM sent to itself from inside the ctypes callback through which
#: LLVM hands numba each compiled module. A signal that arrives during code generation is handled there
#: (the first Python code to run after it), and ctypes drops what a handler raises in a callback.
SIGTERM_IN_COMPILE_CALLBACK = """
import os, signal, sys
from numba.core import codegen
hook, sent = codegen.CPUCodeLibrary._object_compiled_hook.__func__, []
def notify(cls, module, buf):
    if not sent:
        sent.append(os.kill(os.getpid(), signal.SIGTERM))
    return hook(cls, module, buf)
codegen.CPUCodeLibrary._object_compiled_hook = classmethod(notify)
from pmsm_commissioning.app.cli.main import main
sys.argv[0] = "app"
sys.exit(main())
"""
#: A robustness run that compiles its kernels (the main thread compiles: no pool) and writes a CSV.
COLD_ROBUSTNESS = ["robustness", "paper_12kw_pmsm", "--samples", "2", "--workers", "1", "--spread", "plant.J_L=±20%"]


def _cold(tmp_path: Path, code: list[str], csv: Path) -> subprocess.Popen:
    """Start ``python CODE robustness … --csv CSV`` with an empty numba cache (every kernel compiles)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(tmp_path / "cold_cache")}
    return subprocess.Popen([sys.executable, *code, *COLD_ROBUSTNESS, "--csv", str(csv)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=default_signals)


def _cpu_s(pid: int) -> float:
    """CPU time [s] the process ``pid`` has used (user + system)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _assert_stopped(proc: subprocess.Popen, csv: Path) -> None:
    try:
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err[-800:]
    assert "Exception ignored" not in err and "Traceback" not in err, err[-800:]
    assert err.strip().splitlines()[-1].startswith("interrupted"), err[-800:]
    assert not csv.exists() and _no_part_files(csv.parent) == []


def test_sigterm_handled_inside_numbas_compile_callback_ends_the_run(tmp_path):
    # it was printed as "Exception ignored on calling ctypes callback"; the run went on, exit 0, CSV written
    csv = tmp_path / "samples.csv"
    _assert_stopped(_cold(tmp_path, ["-c", SIGTERM_IN_COMPILE_CALLBACK], csv), csv)


def test_sigterm_during_a_cold_compile_ends_the_run(tmp_path):
    csv = tmp_path / "samples.csv"
    proc = _cold(tmp_path, ["-m", "pmsm_commissioning.app"], csv)
    # the imports take < 1 s of CPU, a cold compile of the kernels ≈ 20 s: at 2 s it compiles
    _wait_until(lambda: proc.poll() is not None or _cpu_s(proc.pid) >= 2.0, 60.0, "2 s of CPU used")
    proc.send_signal(signal.SIGTERM)
    _assert_stopped(proc, csv)
