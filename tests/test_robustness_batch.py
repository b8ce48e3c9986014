"""Many samples per compiled call (sim/studies/batch.py), the refusal without spreads, partial results,
and the local pool that runs a lost worker's chunk again once.
"""

from __future__ import annotations

import json
import os
import pathlib
import signal
import subprocess
import sys

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc.metrics import detect_chatter, hysteretic_sign_changes, moving_average
from pmsm_commissioning.sim.studies.batch import chatter_stats
from pmsm_commissioning.sim.studies.robustness import (
    IncompleteRunError,
    draw,
    plant_for,
    robustness,
    sample_metrics,
    simulate_chunk,
)
from pmsm_commissioning.sim.studies.runner import ExecutorError, RetryingPool

PRESET = "siemens_1ft7044_ak7"
ROOT = pathlib.Path(__file__).resolve().parent.parent
#: Wide enough that some sampled plants chatter and some do not.
SPREADS = ["plant.J_L=0.0005:0.02,plant.R_s=±30%,plant.psi_pm=±20%"]


def _rows(params, n, seed=3):
    v = draw(params, parse_spreads(SPREADS), n, seed)
    return [{k: float(x[i]) for k, x in v.items()} for i in range(n)]


@pytest.mark.parametrize("sensors", [[], ["sensors.encoder_cpr=4096", "sensors.i_noise=0.05", "sensors.seed=3"]])
def test_batch_gives_the_numbers_of_one_run_at_a_time(sensors):
    """The compiled batch (run_kernel under prange, batch chatter statistics) returns exactly the
    metrics of simulate() + run_metrics() sample by sample, for chattering and quiet plants alike,
    with ideal and with real sensors (encoder counts, current noise), on one and on two numba
    threads, across sub-batch boundaries (20 > BATCH = 16).
    """
    # K well below the nominal K_limit (0.107): the plants with the most load inertia limit-cycle at
    # 11–20 Hz, the others do not
    params = load_preset(PRESET, ["controller.K=0.03", *sensors])
    d = derive(params)
    rows = _rows(params, 20)
    one_by_one = [sample_metrics(params, plant_for(params, r), d) for r in rows]
    chatter = [r["fdsmc"]["chatter"] for r in one_by_one]
    assert (any(chatter) and not all(chatter)) or sensors  # ideal sensors: both kinds of plant
    assert simulate_chunk(params, rows, d, threads=1) == one_by_one
    assert simulate_chunk(params, rows, d, threads=2) == one_by_one


def test_batch_chatter_statistics_equal_detect_chatter():
    rng = np.random.default_rng(0)
    t = np.arange(3000) * 1e-4
    rows = np.vstack([rng.standard_normal(3000) * 50.0,
                      400.0 * np.sign(np.sin(2 * np.pi * 120.0 * t)) + rng.standard_normal(3000),
                      np.full(3000, 7.0)])
    n = int(round(0.005 / 1e-4))
    ptp, changes = chatter_stats(rows, n, 10.0)
    for i, a in enumerate(rows):
        r = a - moving_average(a, n)
        assert ptp[i] == np.ptp(r) and changes[i] == hysteretic_sign_changes(r, 10.0)
        v = detect_chatter(t, a, np.zeros_like(a), (0.0, 1.0), 400.0)
        assert v.ptp == ptp[i] and v.sign_changes == changes[i]
    assert changes[1] == 2 * 36 and changes[2] == 0 and ptp[2] == 0.0


_NOJIT = """
import json, sys
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.studies.robustness import simulate_chunk
params = load_preset("siemens_1ft7044_ak7", ["controller.f_s_kHz=2", "manoeuvre.T_m=0.5"])
rows = json.loads(sys.argv[1])
print(json.dumps(simulate_chunk(params, rows, derive(params), threads=2)))
"""


def test_compiled_and_interpreted_batch_agree():
    """NUMBA_DISABLE_JIT=1 (prange → range, the kernel in Python) gives the compiled numbers."""
    params = load_preset(PRESET)
    rows = _rows(params, 2, seed=11)
    out = {}
    for jit in ("0", "1"):
        env = {**os.environ, "NUMBA_DISABLE_JIT": jit, "PYTHONPATH": str(ROOT)}
        r = subprocess.run([sys.executable, "-c", _NOJIT, json.dumps(rows)], capture_output=True, text=True,
                           cwd=ROOT, env=env, timeout=900, check=False)
        assert r.returncode == 0, r.stderr[-2000:]
        out[jit] = json.loads(r.stdout.strip().splitlines()[-1])
    for a, b in zip(out["0"], out["1"], strict=True):
        for ctrl in ("fdsmc", "conventional"):
            assert a[ctrl]["chatter"] == b[ctrl]["chatter"] and a[ctrl]["stable"] == b[ctrl]["stable"]
            for key, x in a[ctrl].items():
                if isinstance(x, float):
                    assert b[ctrl][key] == pytest.approx(x, rel=1e-9, abs=1e-12), key


def test_monte_carlo_without_a_spread_is_refused_or_one_nominal_run():
    params = load_preset(PRESET)
    with pytest.raises(ParameterError, match=r"samples = 5 without a spread is not allowed: .*samples = 1"):
        robustness(params, [], 5)
    one = robustness(params, [], 1)
    assert one.summary["nominal_run"] is True and one.summary["samples"] == 1 and one.complete


class _FailingExecutor:
    """Runs chunks here; the chunk `fail_at` raises ExecutorError (a lost cluster)."""

    def __init__(self, fail_at):
        self.fail_at, self.n = fail_at, 0

    def submit(self, fn, *args):
        j, self.n = self.n, self.n + 1
        return _Done(None if j == self.fail_at else fn(*args))

    def shutdown(self):
        pass


class _Done:
    def __init__(self, value):
        self.value = value

    def result(self):
        if self.value is None:
            raise ExecutorError("the cluster went away: allowed a cluster that stays up")
        return self.value

    def cancel(self):
        return False


def test_a_failed_executor_keeps_the_finished_samples_in_order():
    params = load_preset(PRESET)
    spreads = parse_spreads(SPREADS)
    full = robustness(params, spreads, 12, seed=4)
    with pytest.raises(IncompleteRunError, match=r"stopped after (\d+) of 12 samples: the cluster went away") as e:
        robustness(params, spreads, 12, seed=4, executor=_FailingExecutor(fail_at=2), workers=8)
    part = e.value.partial
    k = len(part.runs)
    assert 2 < k < 12 and not part.complete and part.summary["complete"] is False
    assert part.runs == full.runs[:k] and part.summary["samples"] == k
    np.testing.assert_array_equal(part.values["motor.R_s"], full.values["motor.R_s"][:k])


def _square(x):
    return x * x


def _die_once(marker, x):
    if not os.path.exists(marker):
        with open(marker, "w", encoding="utf-8") as fh:
            fh.write("died")
        os.kill(os.getpid(), signal.SIGKILL)
    return x * x


def _die_always(x):
    os.kill(os.getpid(), signal.SIGKILL)


def test_pool_runs_a_lost_workers_chunk_again_once(tmp_path):
    marker = str(tmp_path / "died")
    with RetryingPool(2) as pool:
        futures = [pool.submit(_square, 3), pool.submit(_die_once, marker, 4), pool.submit(_square, 5)]
        assert [f.result() for f in futures] == [9, 16, 25]
        assert pool.generation == 1 and os.path.exists(marker)


def test_pool_gives_up_on_a_chunk_lost_twice():
    with RetryingPool(1) as pool, pytest.raises(ExecutorError, match=r"chunk 0 lost its worker process 2 times"):
        pool.submit(_die_always, 1).result()


def test_robustness_survives_a_killed_pool_worker():
    """kill -9 of a pool process mid-run: the broken pool is replaced, the chunks run again, and the
    results are those of the run in one process.
    """
    params = load_preset(PRESET)
    spreads = parse_spreads(SPREADS)
    serial = robustness(params, spreads, 40, seed=6)
    killed = []
    with RetryingPool(2) as pool:
        def kill_one(done, total):
            if done > 2 and not killed and pool.processes():
                killed.append(pool.processes()[0])
                os.kill(killed[0], signal.SIGKILL)
        res = robustness(params, spreads, 40, seed=6, executor=pool, workers=8, progress=kill_one)
        assert killed and pool.generation == 1
    assert res.runs == serial.runs and res.complete
