"""A real Dask cluster on loopback: ``dask scheduler`` and two ``dask worker`` processes (each under its
nanny) started here, the CLI pointed at it with ``--scheduler``. Same numbers as the local pool; a
worker killed mid-run (kill -9) is restarted by its nanny and the run finishes with the same
numbers; every worker killed: exit 2, one line, the finished samples in the Parquet file marked
incomplete; a worker running other source is refused by name before anything runs.
"""

from __future__ import annotations

import contextlib
import json
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator

import psutil
import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.sample_table import read_parquet
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.studies.robustness import METRICS, draw, simulate_chunk
from tests.child_signals import default_signals

pytestmark = pytest.mark.cluster  # every test here starts a scheduler (or checks one is refused)

ROOT = pathlib.Path(__file__).resolve().parent.parent
PRESET = "paper_12kw_pmsm"
SPREAD = "plant.J_L=0:0.3,plant.R_s=±20%,plant.psi_pm=±10%"
START_S = 120.0


#: ``python -m dask scheduler …`` on loopback, writing its address to ``{file}``.
SCHEDULER = ["-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
             "{file}"]


def read_scheduler_file(file: pathlib.Path, proc: subprocess.Popen, timeout_s: float) -> str:
    """Poll until the scheduler file parses and holds an address (the scheduler writes it in pieces:
    a missing or half-written file means "not yet"); fail when the scheduler exited or time is up.
    """
    deadline = time.monotonic() + timeout_s
    while True:
        with contextlib.suppress(OSError, ValueError, KeyError, TypeError):  # JSONDecodeError is a ValueError
            return str(json.loads(file.read_text(encoding="utf-8"))["address"])
        assert proc.poll() is None, f"the scheduler exited ({proc.returncode}) before writing {file.name}"
        assert time.monotonic() < deadline, f"{file.name} not complete within {timeout_s:g} s"
        time.sleep(0.1)  # poll again (a positive condition)


class Cluster:
    """A scheduler and its workers as subprocesses; every process is ended by ``close``.

    ``scheduler`` is the scheduler's command after the interpreter (``{file}``: the scheduler file).
    Use :func:`running_cluster`, which ends everything it started whatever fails.
    """

    def __init__(self, tmp: pathlib.Path, scheduler: list[str] | None = None, start_s: float = START_S) -> None:
        self.tmp, self.procs, self.workers, self.address, self.start_s = tmp, [], [], "", start_s
        self.env = {**os.environ, "PYTHONPATH": str(ROOT),
                    "NUMBA_CACHE_DIR": os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache"))}
        self.file = tmp / "scheduler.json"
        self.scheduler = [a.replace("{file}", str(self.file)) for a in (scheduler or SCHEDULER)]
        self.logs: list = []

    def start(self) -> None:
        """Start the scheduler and wait for its complete scheduler file."""
        proc = self._spawn("scheduler", self.scheduler, self.env)
        self.address = read_scheduler_file(self.file, proc, self.start_s)

    def _spawn(self, name: str, args: list[str], env: dict[str, str]) -> subprocess.Popen:
        log = open(self.tmp / f"{name}.log", "w", encoding="utf-8")  # noqa: SIM115 — closed by close()
        self.logs.append(log)
        p = subprocess.Popen([sys.executable, *args], stdout=log, stderr=log, env=env, cwd=self.tmp,
                             preexec_fn=default_signals)
        self.procs.append(p)
        return p

    def add_worker(self, pythonpath: pathlib.Path = ROOT) -> None:
        """Start one ``dask worker`` (a nanny and its worker process) and wait until it registered."""
        name = f"worker{len(self.workers)}"
        self.workers.append(self._spawn(name, ["-m", "dask", "worker", "--scheduler-file", str(self.file),
                                               "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"],
                                        {**self.env, "PYTHONPATH": str(pythonpath)}))
        deadline = time.monotonic() + START_S
        while "Registered to" not in (self.tmp / f"{name}.log").read_text(encoding="utf-8"):
            assert self.workers[-1].poll() is None, f"{name} exited ({self.workers[-1].returncode})"
            assert time.monotonic() < deadline, f"{name} did not start"
            time.sleep(0.2)

    def kill_worker_process(self, i: int) -> None:
        """kill -9 the worker process under nanny ``i`` (the nanny restarts it)."""
        for child in psutil.Process(self.workers[i].pid).children(recursive=True):
            child.send_signal(signal.SIGKILL)

    def kill_all_workers(self) -> None:
        """kill -9 every nanny and worker process."""
        for w in self.workers:
            kids = psutil.Process(w.pid).children(recursive=True)
            w.send_signal(signal.SIGKILL)
            for child in kids:
                child.send_signal(signal.SIGKILL)

    def tree(self) -> list[psutil.Process]:
        """Every process started here that still runs, with its descendants."""
        found = []
        for p in self.procs:
            with contextlib.suppress(psutil.NoSuchProcess):
                if p.poll() is None:
                    root = psutil.Process(p.pid)
                    found += [root, *root.children(recursive=True)]
        return found

    def close(self) -> None:
        """Stop the cluster: SIGTERM, then (test clean-up, not under test) SIGKILL what is left after 2 s."""
        tree = self.tree()
        for q in tree:
            with contextlib.suppress(psutil.NoSuchProcess):
                q.terminate()
        _, alive = psutil.wait_procs(tree, timeout=2)
        for q in alive:
            with contextlib.suppress(psutil.NoSuchProcess):
                q.kill()
        psutil.wait_procs(alive, timeout=5)
        for p in self.procs:
            p.wait()
        for log in self.logs:
            log.close()


@contextlib.contextmanager
def running_cluster(tmp: pathlib.Path, workers: int, pythonpath: pathlib.Path = ROOT,
                    scheduler: list[str] | None = None, start_s: float = START_S) -> Iterator[Cluster]:
    """A started cluster of ``workers`` workers; everything started is ended on leaving, whatever failed."""
    c = Cluster(tmp, scheduler, start_s)
    try:
        c.start()
        for _ in range(workers):
            c.add_worker(pythonpath)
        yield c
    finally:
        c.close()


@pytest.fixture
def cluster(tmp_path):
    with running_cluster(tmp_path, 2) as c:
        yield c


#: A scheduler that writes its file in two pieces ``argv[2]`` s apart (``argv[2]`` "exit": half, then exit 3)
#: and otherwise runs on with a process of its own, as a slow ``dask scheduler`` start on a loaded machine
#: does; ``pids`` beside the file names the processes.
_SLOW_SCHEDULER = """
import json, os, pathlib, subprocess, sys, time
file, pids = pathlib.Path(sys.argv[1]), [os.getpid()]
if sys.argv[2] != "exit":
    pids.append(subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"]).pid)
(file.parent / "pids").write_text(" ".join(map(str, pids)))
text = json.dumps({"address": "tcp://127.0.0.1:1", "type": "Scheduler"})
with open(file, "w", encoding="utf-8") as fh:
    fh.write(text[:12])
    fh.flush()
    if sys.argv[2] == "exit":
        sys.exit(3)
    time.sleep(float(sys.argv[2]))
    fh.write(text[12:])
time.sleep(120)
"""


def _running(pid: int) -> bool:
    with contextlib.suppress(psutil.NoSuchProcess):
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    return False


@pytest.mark.parametrize(("second_half", "start_s", "error"), [
    ("1.0", START_S, None),
    ("exit", START_S, "the scheduler exited (3) before writing scheduler.json"),
    ("30", 1.0, "scheduler.json not complete within 1 s"),
], ids=["slow start", "exits half-written", "never complete"])
def test_the_cluster_waits_for_a_complete_scheduler_file_and_always_cleans_up(tmp_path, second_half, start_s, error):
    fake = ["-c", _SLOW_SCHEDULER, "{file}", second_half]
    with contextlib.ExitStack() as stack:
        if error:
            stack.enter_context(pytest.raises(AssertionError, match=re.escape(error)))
        c = stack.enter_context(running_cluster(tmp_path, 0, scheduler=fake, start_s=start_s))
        assert c.address == "tcp://127.0.0.1:1" and len(c.tree()) == 2  # the scheduler and its own process
    pids = [int(p) for p in (tmp_path / "pids").read_text().split()]
    assert len(pids) == (1 if second_half == "exit" else 2) and not any(_running(pid) for pid in pids)


class CliRun:
    """``pmsm-commission robustness … --scheduler`` in a subprocess; its stderr is read as it comes."""

    def __init__(self, address: str, samples: int, parquet: pathlib.Path, *extra: str) -> None:
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        self.p = subprocess.Popen([sys.executable, "-m", "pmsm_commissioning.app", "robustness", PRESET, "--samples",
                                   str(samples),
                                   "--spread", SPREAD, "--seed", "9", "--scheduler", address, "--parquet",
                                   str(parquet), "--json", *extra], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env, preexec_fn=default_signals)
        self.err = ""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for ch in iter(lambda: self.p.stderr.read(1), ""):
            self.err += ch

    def done_samples(self) -> int:
        marks = [m for m in self.err.replace("\r", "\n").splitlines() if m.startswith("samples ")]
        return int(marks[-1].split()[1].split("/")[0]) if marks else 0

    def wait_for(self, done: int) -> None:
        deadline = time.monotonic() + 600
        while self.done_samples() < done:
            assert self.p.poll() is None, self.err[-2000:]
            assert time.monotonic() < deadline
            time.sleep(0.05)

    def finish(self) -> tuple[int, str, str]:
        out = self.p.stdout.read()  # stderr is the reader thread's
        self.p.wait(timeout=900)
        self._reader.join(timeout=30)
        return self.p.returncode, out, self.err


def _local_rows(indices: list[int], samples: int):
    """The metrics of some of the run's samples, computed here one chunk at a time."""
    params = load_preset(PRESET)
    v = draw(params, parse_spreads([SPREAD]), samples, 9)
    rows = [{k: float(x[i]) for k, x in v.items()} for i in indices]
    return simulate_chunk(params, rows, derive(params))


def _check_rows(cols: dict, indices: list[int], samples: int) -> None:
    for i, r in zip(indices, _local_rows(indices, samples), strict=True):
        for ctrl in ("fdsmc", "conventional"):
            for key in (*METRICS, "chatter", "infeasible"):
                assert cols[f"{ctrl}.{key}"][i] == r[ctrl][key], (i, ctrl, key)
        assert cols["fdsmc.saving_friction_pct"][i] == r["fdsmc"]["saving_friction_pct"]


def test_cluster_gives_the_pool_results(cluster, tmp_path):
    rc, out, err = CliRun(cluster.address, 120, tmp_path / "dask.parquet").finish()
    assert rc == 0, err[-2000:]
    assert main(["robustness", PRESET, "--samples", "120", "--spread", SPREAD, "--seed", "9", "--workers", "2",
                 "--parquet", str(tmp_path / "pool.parquet")]) == 0
    dask_cols, _, meta = read_parquet(tmp_path / "dask.parquet")
    pool_cols, _, _ = read_parquet(tmp_path / "pool.parquet")
    assert dask_cols == pool_cols and meta["complete"] is True and meta["completed_samples"] == 120
    assert json.loads(out)["samples"] == 120


def test_a_killed_worker_is_replaced_and_the_run_finishes_the_same(cluster, tmp_path):
    run = CliRun(cluster.address, 2000, tmp_path / "r.parquet")
    run.wait_for(100)
    cluster.kill_worker_process(0)
    rc, out, err = run.finish()
    assert rc == 0, err[-2000:]
    cols, _, meta = read_parquet(tmp_path / "r.parquet")
    assert meta["complete"] is True and len(cols["motor.R_s"]) == 2000
    _check_rows(cols, [0, 1, 2, 777, 1999], 2000)
    assert cluster.workers[0].poll() is None  # the nanny lives on and restarted its worker
    assert "Worker process" in (tmp_path / "worker0.log").read_text(encoding="utf-8")


def test_every_worker_killed_fails_cleanly_with_the_finished_samples(cluster, tmp_path):
    run = CliRun(cluster.address, 4000, tmp_path / "r.parquet", "--cluster-timeout", "3")
    run.wait_for(100)
    cluster.kill_all_workers()
    rc, out, err = run.finish()
    last = err.replace("\r", "\n").strip().splitlines()[-1]
    assert rc == 2 and out == ""
    assert last.startswith("error: robustness run stopped after ") and "has had no worker for 3 s" in last
    assert "Traceback" not in err
    cols, _, meta = read_parquet(tmp_path / "r.parquet")
    k = meta["completed_samples"]
    assert meta["complete"] is False and 100 <= k < 4000 and len(cols["motor.R_s"]) == k
    assert f"stopped after {k} of 4000 samples" in last
    _check_rows(cols, [0, k - 1], 4000)


def test_a_worker_with_other_source_is_refused_by_name(tmp_path):
    other = tmp_path / "other"
    for pkg in ("control", "sim"):
        shutil.copytree(ROOT / pkg, other / "pmsm_commissioning" / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    with open(other / "pmsm_commissioning" / "sim" / "studies" / "batch.py", "a", encoding="utf-8") as fh:
        fh.write("# another version\n")
    with running_cluster(tmp_path, 1, pythonpath=other) as c:
        rc, out, err = CliRun(c.address, 10, tmp_path / "r.parquet").finish()
    assert rc == 2 and out == ""
    line = err.strip().splitlines()[-1]
    assert line.startswith(f"error: the Dask cluster at {c.address} is refused: worker tcp://127.0.0.1:")
    assert "runs source" in line and "allowed only workers with the same control/ and sim/" in line
    assert not (tmp_path / "r.parquet").exists()


def test_no_scheduler_is_one_line_and_exit_2(capsys):
    assert main(["robustness", PRESET, "--samples", "4", "--spread", SPREAD, "--scheduler", "tcp://127.0.0.1:9",
                 "--cluster-timeout", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'")


_PAGE = """
import json, os, sys
from types import SimpleNamespace
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.app.ui.studies_robustness import SCHEDULER_ENV, RobustnessView
from pmsm_commissioning.sim.studies import dask_runner
from pmsm_commissioning.sim.studies.robustness import robustness
used = []
connect = dask_runner.connect
dask_runner.connect = lambda address, *a: used.append(address) or connect(address, *a)
view = RobustnessView.__new__(RobustnessView)
view._done, view.progress, view.status = 0, SimpleNamespace(value=0.0), SimpleNamespace(content="")
view._s = SimpleNamespace(checkpoint=lambda: None)  # the case port the view receives
params = load_preset("siemens_1ft7044_ak7")
spreads = parse_spreads(["plant.J_L=0.001:0.004,plant.R_s=±20%"])
res = view._run(params, spreads, 80, 5)
print(json.dumps({"used": used, "env": os.environ[SCHEDULER_ENV], "done": view._done,
                  "same": res.runs == robustness(params, spreads, 80, 5).runs}))
"""


def test_the_page_runs_large_studies_on_the_configured_cluster(cluster):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PMSM_DASK_SCHEDULER": cluster.address}
    r = subprocess.run([sys.executable, "-c", _PAGE], capture_output=True, text=True, cwd=ROOT, env=env,
                       timeout=600, check=False)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["used"] == [cluster.address] and out["done"] == 80 and out["same"]


def test_a_lost_scheduler_is_one_line_and_exit_2(cluster, tmp_path):
    run = CliRun(cluster.address, 4000, tmp_path / "r.parquet", "--cluster-timeout", "5")
    run.wait_for(100)
    cluster.procs[0].send_signal(signal.SIGKILL)  # the scheduler
    rc, out, err = run.finish()
    last = err.replace("\r", "\n").strip().splitlines()[-1]
    assert rc == 2 and out == "" and "Traceback" not in err
    assert last.startswith("error: robustness run stopped after ")
    assert f"lost the Dask scheduler at {cluster.address}" in last
    _, _, meta = read_parquet(tmp_path / "r.parquet")
    assert meta["complete"] is False and meta["completed_samples"] >= 100


_KILLER = """
import os, sys
from pmsm_commissioning.sim.studies.dask_runner import connect
from pmsm_commissioning.sim.studies.runner import ExecutorError
def kill_my_worker(x):
    os._exit(1)
with connect(sys.argv[1], 60.0) as ex:
    try:
        ex.submit(kill_my_worker, 1).result()
    except ExecutorError as exc:
        print(exc)
"""


def test_a_task_that_kills_its_workers_is_one_line(cluster):
    """distributed.scheduler.allowed-failures = 3: the fourth lost worker gives up the task (KilledWorker)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", _KILLER, cluster.address], capture_output=True, text=True, cwd=ROOT,
                       env=env, timeout=600, check=False)
    assert r.returncode == 0, r.stderr[-2000:]
    line = r.stdout.strip()
    assert "\n" not in line and line.startswith(f"chunk 0 killed the workers that ran it on the Dask cluster at "
                                                f"{cluster.address} (KilledWorker: ")
    assert line.endswith("allowed fewer than distributed.scheduler.allowed-failures losses per task")


_PERIODS = """
import json, sys
from pmsm_commissioning.sim.studies.dask_runner import QUIET_MS, connect, nanny_plugin
def periods(dask_worker):
    return {k: dask_worker.periodic_callbacks[k].callback_time for k in QUIET_MS}
with connect(sys.argv[1], 60.0) as ex:
    tuned = list(ex.client.run(periods).values()) + list(ex.client.run(periods, nanny=True).values())
    ex.client.unregister_worker_plugin(nanny_plugin().name, nanny=True)
    print(json.dumps({"tuned": tuned, "nanny_after": list(ex.client.run(periods, nanny=True).values())}))
"""


def test_workers_and_nannies_housekeep_less_while_tuned(cluster):
    """The worker and nanny plugins slow the tick, memory and system monitors; removing the nanny's restores it."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", _PERIODS, cluster.address], capture_output=True, text=True, cwd=ROOT,
                       env=env, timeout=600, check=False)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert len(out["tuned"]) == 4  # two workers, two nannies
    assert all(p == {"tick": 1000.0, "memory_monitor": 500.0, "monitor": 2000.0} for p in out["tuned"])
    assert all(p["tick"] == 20.0 and p["memory_monitor"] == 100.0 for p in out["nanny_after"])  # Dask's own
