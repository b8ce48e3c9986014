"""``pmsm-commission robustness PRESET --samples N [--seed S] [--spread …] [--json] [--scheduler …]``.

Spreads (comma-separated or repeated), each on a plant value (see :mod:`app.io.plant_overrides`), in SI:
``plant.J_L=0:0.3`` uniform between 0 and 0.3; ``plant.R_s=±20%`` (or ``+-20%``) uniform within
±20 % of the nominal plant's value (the preset's plant section and ``--set plant.*``, else its
motor and load); ``plant.psi_pm=~5%`` normal with σ = 5 % of it (truncated at ±3σ).
Runs on a local process pool (all cores; a chunk whose worker is lost is run again once) or, with
``--scheduler tcp://HOST:PORT`` or the environment variable ``PMSM_DASK_SCHEDULER``, on a Dask
distributed cluster (checked, tuned and warmed first: :mod:`sim.studies.dask_runner`, docs/cluster.md).
Without a spread only one sample (the nominal run) is allowed. A run whose cluster or pool fails
exits 2 with one line; the samples finished before are written to ``--parquet``/``--csv`` with
``complete: false`` in the Parquet metadata.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable
from typing import Any

from pmsm_commissioning.app.cli.main import add_preset_arguments, check_writable
from pmsm_commissioning.app.cli.progress import Progress
from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import integer_option, number_option
from pmsm_commissioning.app.io.plant_overrides import load_model_and_plant
from pmsm_commissioning.app.io.sample_table import require_parquet, write_csv, write_parquet
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.studies.robustness import (
    CONTROLLERS,
    METRICS,
    STUDY_CONTROLLERS,
    IncompleteRunError,
    RobustnessResult,
    robustness,
)
from pmsm_commissioning.sim.studies.runner import ExecutorError, RetryingPool

SCHEDULER_ENV = "PMSM_DASK_SCHEDULER"
MAX_SAMPLES = 1_000_000


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``robustness``."""
    add_preset_arguments(p)
    p.add_argument("--samples", type=integer_option("--samples"), default=100,
                   help="number of sampled plants (default 100)")
    p.add_argument("--seed", type=integer_option("--seed"), default=0, help="seed of the sampling (default 0)")
    p.add_argument("--spread", action="append", default=[], metavar="plant.FIELD=DIST[,…]",
                   help="plant.J_L=0:0.3 (uniform), plant.R_s=±20%% (uniform relative), "
                        "plant.psi_pm=~5%% (normal, relative σ)")
    p.add_argument("--workers", type=integer_option("--workers"), default=os.cpu_count() or 1,
                   help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=os.environ.get(SCHEDULER_ENV),
                   help=f"Dask scheduler address tcp://HOST:PORT (or ${SCHEDULER_ENV})")
    p.add_argument("--cluster-timeout", type=number_option("--cluster-timeout"), default=60.0, metavar="S",
                   help="seconds the Dask cluster may have no worker before the run stops (default 60)")
    p.add_argument("--controllers", default=",".join(CONTROLLERS), metavar="NAME[,NAME…]",
                   help=f"controllers run on every sample, of {', '.join(STUDY_CONTROLLERS)} "
                        f"(default {','.join(CONTROLLERS)}; optimum: the tracked minimum-energy move)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--csv", metavar="FILE", help="write one row per sample (drawn values and metrics)")
    p.add_argument("--parquet", metavar="FILE",
                   help="write the same rows as Parquet, with each column's unit in the schema metadata")


def _print_table(summary: dict[str, Any]) -> None:
    nominal = " (one nominal run: no spread)" if summary.get("nominal_run") else ""
    print(f"{summary['samples']} samples in {summary['seconds']:.1f} s{nominal}")
    for ctrl in [c for c in STUDY_CONTROLLERS if c in summary]:
        e = summary[ctrl]
        print(f"\n{ctrl}: chatter probability {e['chatter_probability']:.3f}, "
              f"infeasible probability {e['infeasible_probability']:.3f}")
        print(f"  {'metric':28s}{'mean':>12s}{'p05':>12s}{'p50':>12s}{'p95':>12s}{'worst':>12s}")
        for key in METRICS:
            row = e[key]
            print(f"  {key:28s}" + "".join(f"{row[s]:12.5g}" if row[s] is not None else f"{'—':>12s}"
                                          for s in ("mean", "p05", "p50", "p95", "worst")))


def _check(args: argparse.Namespace) -> None:
    if not 1 <= args.samples <= MAX_SAMPLES:
        raise ParameterError(f"--samples = {args.samples} is not allowed: 1 … {MAX_SAMPLES}")
    if not 1 <= args.workers <= 1024:
        raise ParameterError(f"--workers = {args.workers} is not allowed: 1 … 1024")
    if not 0 <= args.seed < 2**63:
        raise ParameterError(f"--seed = {args.seed} is not allowed: 0 … 2^63 − 1")
    if not 1.0 <= args.cluster_timeout <= 86400.0:
        raise ParameterError(f"--cluster-timeout = {args.cluster_timeout:g} s is not allowed: 1 … 86400 s")
    for opt, path in (("--csv", args.csv), ("--parquet", args.parquet)):
        if path:
            check_writable(path, opt)  # before hours of simulation, not after
    if args.parquet:
        require_parquet()  # an optional dependency (the "parquet" extra)


def _quiet_dask() -> None:
    """Silence Dask's own client logging: a lost cluster is reported in one line, not its reconnect tracebacks."""
    import logging

    import distributed  # noqa: F401 — configures its loggers, which are then raised to CRITICAL

    for name in [n for n in logging.root.manager.loggerDict if n.split(".")[0] in ("distributed", "tornado")]:
        logging.getLogger(name).setLevel(logging.CRITICAL)


def _compute(args: argparse.Namespace, progress: Progress) -> RobustnessResult:
    params, plant = load_model_and_plant(args.preset, args.overrides)  # plant: the nominal plant
    spreads = parse_spreads(args.spread)
    ctrl = tuple(c.strip() for c in args.controllers.split(","))
    if args.scheduler:
        from pmsm_commissioning.sim.studies.dask_runner import connect

        _quiet_dask()
        with connect(args.scheduler, args.cluster_timeout) as ex:
            return robustness(params, spreads, args.samples, args.seed, ex, ex.workers, progress, plant=plant,
                              controllers=ctrl)
    if args.workers == 1:
        return robustness(params, spreads, args.samples, args.seed, None, 1, progress, plant=plant,
                          controllers=ctrl)
    with RetryingPool(args.workers) as pool:
        return robustness(params, spreads, args.samples, args.seed, pool, args.workers, progress, plant=plant,
                          controllers=ctrl)


def _atomic(path: str, write: Callable[[str], None]) -> None:
    """Write through a temporary file in the same folder, then rename it over ``path``.

    A write error (disk full, quota, a folder gone) is one line naming the file; the old file, if
    any, is left as it was and no temporary file remains.
    """
    tmp = f"{path}.tmp-{os.getpid()}"
    try:
        write(tmp)
        os.replace(tmp, path)
    except OSError as exc:
        raise ParameterError(f"cannot write {path!r}: {exc.strerror or exc}; nothing was written there") from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def _write(args: argparse.Namespace, res: RobustnessResult) -> None:
    if args.csv:
        _atomic(args.csv, lambda p: write_csv(p, res))
    if args.parquet:
        meta = {"preset": args.preset, "overrides": list(args.overrides), "spreads": list(args.spread),
                "seed": args.seed, "samples": args.samples, "complete": res.complete,
                "completed_samples": len(res.runs)}
        _atomic(args.parquet, lambda p: write_parquet(p, res, meta))


def run(args: argparse.Namespace) -> int:
    """Run the Monte-Carlo analysis and print the summary; 2 with one line when the executor fails."""
    _check(args)
    try:
        with Progress("samples", "sample") as progress:  # the bar's line ended before any error line
            res = _compute(args, progress)
    except IncompleteRunError as exc:
        _write(args, exc.partial)
        written = " (finished samples written, marked incomplete)" if args.csv or args.parquet else ""
        sys.stderr.write(f"error: {exc}{written}\n")
        return 2
    except ExecutorError as exc:
        sys.stderr.write(f"error: {exc}\n")
        return 2
    _write(args, res)
    if args.json:
        print(json.dumps(to_json(res.summary), indent=2, ensure_ascii=False))
    else:
        _print_table(res.summary)
    return 0
