"""Controller model vs plant, and the Monte-Carlo robustness analysis (local and on Dask)."""

from __future__ import annotations

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.io.plant_overrides import load_model_and_plant
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.study_inputs import parse_spread, parse_spreads
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.studies.robustness import METRICS, TRACE_POINTS, Spread, draw, robustness

PRESET = "siemens_1ft7044_ak7"
ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_plant_equal_to_model_changes_nothing():
    params = load_preset(PRESET)
    a = compare(params)
    b = compare(params, plant=load_preset(PRESET))
    for ctrl in ("fdsmc", "conventional"):
        assert getattr(a, ctrl).metrics == getattr(b, ctrl).metrics


def test_plant_override_changes_the_drive_not_the_controller():
    """A heavier true load than the controller assumes: the same design, more torque and energy;
    the energy balance closes with the plant's inertia.
    """
    params, plant = load_model_and_plant(PRESET, ["plant.J_L=0.004"])
    assert pytest.approx(2.172e-3) == params.load.J_L and plant.load.J_L == 0.004
    nominal, heavy = compare(params), compare(params, plant=plant)
    assert heavy.derived.alpha.alpha_max == nominal.derived.alpha.alpha_max
    f0, f1 = nominal.fdsmc.metrics, heavy.fdsmc.metrics
    # more torque for the heavier load, never beyond the drive's hard limit (Γ_max = 15 N·m)
    assert 1.1 * f0.torque_peak_Nm < f1.torque_peak_Nm <= 15.0 * 1.01
    assert f1.copper_J > 1.2 * f0.copper_J
    assert abs(f1.energy_balance_residual_pct) < 0.5


def test_plant_override_names_a_bad_field():
    with pytest.raises(ParameterError, match="plant.K is not a plant value"):
        load_model_and_plant(PRESET, ["plant.K=3"])


@pytest.mark.parametrize(("text", "match"), [
    ("plant.R_s=±120%", "0 … <100 %"), ("plant.R_s=~50%", "σ = 50 %"), ("plant.J_L=0.3:0.1", "LO ≤ HI"),
    ("plant.J_L=abc", "LO:HI"), ("plant.J_L=0:x", "'x' is not a number"), ("R_s=±5%", "plant.FIELD=DIST"),
    ("plant.T_si=±5%", "not a plant value"),
])
def test_spread_refuses_bad_input_with_a_clear_message(text, match):
    with pytest.raises(ParameterError, match=match):
        parse_spread(text)


def test_spread_forms_and_draws():
    s = parse_spreads(["plant.J_L=0:0.3,plant.R_s=±20%", "plant.psi_pm=~5%"])
    assert s == [Spread("load", "J_L", "uniform", 0.0, 0.3), Spread("motor", "R_s", "relative", -0.2, 0.2),
                 Spread("motor", "psi_pm", "normal", 0.0, 0.05)]
    params = load_preset(PRESET)
    v = draw(params, s, 4000, seed=1)
    assert v["load.J_L"].min() >= 0.0 and v["load.J_L"].max() <= 0.3
    r = v["motor.R_s"] / params.motor.R_s
    assert r.min() >= 0.8 and r.max() <= 1.2 and abs(r.mean() - 1.0) < 0.01
    z = (v["motor.psi_pm"] / params.motor.psi_pm - 1.0) / 0.05
    assert np.abs(z).max() <= 3.0 and abs(z.std() - 1.0) < 0.05
    np.testing.assert_array_equal(draw(params, s, 10, seed=7)["load.J_L"], draw(params, s, 10, seed=7)["load.J_L"])


def test_zero_spread_reproduces_the_nominal_run_exactly():
    params = load_preset(PRESET)
    zero = [Spread("load", "J_L", "uniform", params.load.J_L, params.load.J_L),
            Spread("motor", "R_s", "relative", 0.0, 0.0)]
    res = robustness(params, zero, 3, seed=5)
    nominal = compare(params, max_points=TRACE_POINTS)  # the settling time is read from the trace
    for run in res.runs:
        for ctrl in ("fdsmc", "conventional"):
            m = getattr(nominal, ctrl).metrics
            assert run[ctrl]["theta_error_abs_at_Tm_rad"] == abs(m.theta_error_at_Tm_rad)
            for key in set(METRICS) - {"theta_error_abs_at_Tm_rad"}:
                assert run[ctrl][key] == getattr(m, key)
    assert res.summary["fdsmc"]["friction_J"]["p05"] == res.summary["fdsmc"]["friction_J"]["p95"]


_DASK_SCRIPT = """
import json
from dask.distributed import Client, LocalCluster
from pmsm_commissioning.app.io.study_inputs import parse_spreads
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.studies.robustness import robustness
params = load_preset("siemens_1ft7044_ak7")
spreads = parse_spreads(["plant.J_L=0.001:0.004,plant.R_s=±20%"])
local = robustness(params, spreads, 5, seed=3)
done = []
with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cl, \\
        Client(cl) as client:
    remote = robustness(params, spreads, 5, seed=3, executor=client, workers=2, progress=lambda d, n: done.append(d))
print(json.dumps({"same": remote.runs == local.runs, "summary": remote.summary["fdsmc"] == local.summary["fdsmc"],
                  "done": done}))
"""


@pytest.mark.cluster
def test_dask_cluster_gives_the_local_results():
    """Run in a fresh interpreter: the cluster's event loop must not outlive it in the test process."""
    r = subprocess.run([sys.executable, "-c", _DASK_SCRIPT], capture_output=True, text=True, check=False,
                       cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["same"] and out["summary"]
    assert out["done"] == sorted(out["done"]) and out["done"][-1] == 5


def test_robustness_cli_json(capsys):
    assert main(["robustness", PRESET, "--samples", "3", "--workers", "1", "--seed", "2",
                 "--spread", "plant.R_s=±10%", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["samples"] == 3 and out["seconds"] > 0.0
    for ctrl in ("fdsmc", "conventional"):
        e = out[ctrl]
        assert 0.0 <= e["chatter_probability"] <= 1.0 and 0.0 <= e["infeasible_probability"] <= 1.0
        for key in METRICS:
            s = e[key]
            assert s["p05"] <= s["p50"] <= s["p95"] <= s["worst"]


def test_parquet_and_csv_tables_hold_the_same_numbers_with_units(tmp_path):
    """Write the per-sample results as Parquet and CSV through the CLI; read both back: equal
    values (floats exactly), each column's SI unit in the Parquet schema metadata.
    """
    import csv

    from pmsm_commissioning.app.io.sample_table import read_parquet

    pq_path, csv_path = tmp_path / "r.parquet", tmp_path / "r.csv"
    assert main(["robustness", PRESET, "--samples", "3", "--workers", "1", "--seed", "4",
                 "--spread", "plant.R_s=±10%,plant.J_L=0.001:0.003", "--parquet", str(pq_path),
                 "--csv", str(csv_path), "--json"]) == 0
    cols, units, meta = read_parquet(pq_path)
    params = load_preset(PRESET)
    again = robustness(params, parse_spreads(["plant.R_s=±10%,plant.J_L=0.001:0.003"]), 3, seed=4)
    assert cols["motor.R_s"] == list(again.values["motor.R_s"])
    assert cols["fdsmc.friction_J"] == [r["fdsmc"]["friction_J"] for r in again.runs]
    assert cols["conventional.chatter"] == [r["conventional"]["chatter"] for r in again.runs]
    assert units["motor.R_s"] == "Ω" and units["load.J_L"] == "kg·m²" and units["fdsmc.friction_J"] == "J"
    assert units["fdsmc.t_2pct_settle_s"] == "s" and units["fdsmc.saving_friction_pct"] == "%"
    assert meta["seed"] == 4 and meta["samples"] == 3
    with open(csv_path, newline="", encoding="utf-8") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == list(cols)
    assert [float(r["fdsmc.copper_J"]) for r in table] == cols["fdsmc.copper_J"]


def test_parquet_to_an_unwritable_path_is_refused_before_the_run(tmp_path, capsys):
    bad = tmp_path / "no" / "dir" / "r.parquet"
    assert main(["robustness", PRESET, "--samples", "2", "--parquet", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "--parquet" in err and "does not exist or is not writable" in err and "samples" not in err
