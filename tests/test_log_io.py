"""Drive-log import: the shipped example logs, this tool's own CSV export, and bad logs."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from pmsm_commissioning.app.cli.simulate import write_csv
from pmsm_commissioning.app.io import drive_log as log_io
from pmsm_commissioning.app.io.drive_log import LogError, parse_log, read_log
from pmsm_commissioning.app.io.presets import load_preset, loads_log_mapping
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.identification import identify
from pmsm_commissioning.sim.drivelog.synthetic import LOG_OVERRIDES, TRUE_LOAD, TRUE_MOTOR, perturbed
from pmsm_commissioning.sim.fdsmc.engine import Comparison, simulate

DATA = Path(__file__).resolve().parent / "data"
TOLERANCE = {"R_s": 0.02, "L_d": 0.02, "L_q": 0.02, "psi_pm": 0.02, "J_total": 0.03, "F_v": 0.10}


def _truth() -> dict[str, float]:
    true = perturbed(load_preset("paper_12kw_pmsm", LOG_OVERRIDES))
    return {**TRUE_MOTOR, "J_total": true.J_total, "F_v": TRUE_LOAD["F_v"], "Gamma_Le": TRUE_LOAD["Gamma_Le"]}


@pytest.mark.parametrize("name, mapping", [("drive_log_dq.csv", None),
                                           ("drive_log_phases.csv", "drive_log_phases.map.yaml")])
def test_shipped_logs_identify_the_true_plant(name, mapping):
    """Through the same import path as a real log: R_s, L, Ψ_PM within 2 %, J within 3 %,
    F_v within 10 %, and every true value inside its 95 % interval.
    """
    mp = loads_log_mapping((DATA / mapping).read_text(encoding="utf-8")) if mapping else None
    log = read_log(DATA / name, mapping=mp, p=5)
    assert (DATA / name).stat().st_size < 300_000
    assert log.T_s == pytest.approx(1e-4)
    r = identify(log.signals, 5)
    truth = _truth()
    for key, value in truth.items():
        e = r.get(key)
        assert e.ci95[0] <= value <= e.ci95[1], (key, e)
        if key in TOLERANCE:
            assert abs(e.value / value - 1.0) < TOLERANCE[key], (key, e.value)


def test_park_transform_of_phase_currents_and_voltages_is_exact():
    """Three phase currents and two phase voltages (u_c = −u_a − u_b) of known dq values."""
    t = np.arange(100) * 1e-3
    th = 0.3 * t * 100
    i_d, i_q, u_d, u_q, p = 2.0 + 0.0 * t, 5.0 * np.sin(t * 30), -1.0 + t, 40.0 + 0.0 * t, 4
    cols = []
    for d, q, shifts in ((i_d, i_q, (0.0, -2 * math.pi / 3, 2 * math.pi / 3)), (u_d, u_q, (0.0, -2 * math.pi / 3))):
        cols += [d * np.cos(p * th + s) - q * np.sin(p * th + s) for s in shifts]
    lines = ["t [s],theta_r [rad],i_a [A],i_b [A],i_c [A],u_a [V],u_b [V]"] + [
        ",".join(f"{v:.12g}" for v in row) for row in zip(t, th, *cols, strict=True)]
    log = parse_log("\n".join(lines), p=p)
    for name, want in (("i_d", i_d), ("i_q", i_q), ("u_d", u_d), ("u_q", u_q)):
        assert np.allclose(log.signals[name], want, atol=1e-9), name


def test_units_in_header_are_converted_to_si():
    rows = [f"{k * 0.5},{k * 0.1},12000,{k}" for k in range(30)]  # 0.1 rev per 0.5 ms = 12000 rpm
    log = parse_log("t [ms],theta_r [rev],omega_r [rpm],i_q [mA]\n" + "\n".join(rows))
    assert log.signals["t"][2] == pytest.approx(1e-3)
    assert log.signals["theta_r"][1] == pytest.approx(0.1 * 2 * math.pi)
    assert log.signals["i_q"][3] == pytest.approx(3e-3)
    assert log.signals["omega_r"][0] == pytest.approx(400 * math.pi)


def test_own_simulate_csv_is_accepted_without_mapping(tmp_path):
    """``simulate --csv`` output (both runs in one file) is a log: --run picks one, and its
    signals equal the simulated trace.
    """
    params = load_preset("paper_12kw_pmsm", ["manoeuvre.theta_dem=3", "manoeuvre.T_m=0.6",
                                             "controller.f_s=5000", "controller.T_so=0.002",
                                             "controller.T_salpha=0.005"])
    runs = [simulate(params, c, max_points=2000) for c in ("fdsmc", "conventional")]
    path = tmp_path / "sim.csv"
    write_csv(str(path), Comparison(derive(params), runs[0], runs[1], None, None))
    with pytest.raises(LogError, match="choose one"):
        read_log(path)
    log = read_log(path, run="conventional")
    n = log.signals["t"].size
    assert np.allclose(log.signals["i_q"], runs[1].trace.i_q[:n], rtol=1e-8, atol=1e-9)
    assert {"theta_r", "omega_r", "i_d", "u_q"} <= set(log.signals)


def _log(lines: list[str], header: str = "t [s],i_q [A]") -> str:
    return "\n".join([header, *lines])


GOOD = [f"{k * 1e-3},{k}" for k in range(40)]


@pytest.mark.parametrize("text, match", [
    (_log(GOOD[:5] + [GOOD[3]] + GOOD[6:]), r"time does not increase at line 7"),
    (_log(GOOD[:10] + ["0.010,", "0.011,nan"] + GOOD[12:]), r"2 empty/NaN/inf value\(s\), first at line 12"),
    (_log(GOOD, "t [s],i_q [A],torque [N*m]").replace("\n", ",1\n") + ",1", r"unknown column\(s\) 'torque \[N\*m\]'"),
    (_log(GOOD, "t [s],i_q [furlong]"), r"unit 'furlong' is not allowed for i_q: allowed A, mA"),
    (_log(GOOD, "t [s],i_q"), r"column 'i_q' has no unit"),
    (_log(GOOD[:10] + GOOD[15:]), r"gap of 0.006 s before line 12"),
    (_log(GOOD[:10] + ["0.010,abc"] + GOOD[11:]), r"line 12, column 'i_q \[A\]': 'abc' is not a number"),
    (_log(GOOD[:10] + ["0.010,1,2"] + GOOD[11:]), r"line 12: 3 fields, the header has 2"),
    (_log(GOOD, "i_d [A],i_q [A]"), r"no time column"),
    (_log(GOOD[:5]), r"5 data rows: allowed ≥ 20"),
    ("", r"the log is empty"),
])
def test_bad_logs_get_a_clear_error_naming_line_and_column(text, match):
    with pytest.raises(LogError, match=match):
        parse_log(text)


def test_speed_logged_in_rpm_but_labelled_rad_s_is_caught():
    rows = [f"{k * 1e-3},{k * 1e-2},{10.0 * 60 / (2 * math.pi)}" for k in range(100)]
    with pytest.raises(LogError, match=r"disagree.*check their units"):
        parse_log("t [s],theta_r [rad],omega_r [rad/s]\n" + "\n".join(rows))


def test_too_many_rows_and_too_large_files_are_refused_before_parsing(tmp_path, monkeypatch):
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:  # sparse: 10^7 rows of ~60 bytes would be 600 MB
        fh.seek(600 * 2**20)
        fh.write(b"\n")
    with pytest.raises(LogError, match=r"big.csv is 600.0 MB: allowed ≤ 50 MB"):
        read_log(big)
    monkeypatch.setattr(log_io, "MAX_ROWS", 30)
    with pytest.raises(LogError, match=r"the log has 40 rows: allowed ≤ 30"):
        parse_log(_log(GOOD))


def test_mapping_names_columns_and_unknown_mapped_column_is_an_error():
    text = "Zeit;Strom\n" + "\n".join(f"{k};{k * 2}" for k in range(30))
    log = parse_log(text, mapping=loads_log_mapping("Zeit: t [ms]\nStrom: i_q [mA]\n"))
    assert log.signals["i_q"][5] == pytest.approx(10e-3) and log.columns["i_q"] == "Strom"
    with pytest.raises(LogError, match=r"column 'Spannung' is not in the log's header"):
        parse_log(text, mapping={"Spannung": "u_q [V]", "Zeit": "t [ms]"})


def test_cli_log_json_overlay_of_own_export_is_exact_and_identifies_the_shipped_log(tmp_path, capsys):
    """A log that is this tool's own simulation of the same preset overlays with zero error
    and equal input energy; a rest period before the move is found as the move start.
    """
    import json

    from pmsm_commissioning.app.cli.main import main

    params = load_preset("example_log_drive")
    run = simulate(params, "fdsmc")
    path = tmp_path / "own.csv"
    write_csv(str(path), Comparison(derive(params), run, None, None, None))
    assert main(["log", str(path), "--preset", "example_log_drive", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ov = out["overlay"]
    assert ov["t0_s"] == pytest.approx(0.0, abs=1e-9)
    assert ov["theta_r"]["rms_error"] < 1e-6 and ov["i_q"]["peak_error"] < 1e-6 and ov["i_q"]["unit"] == "A"
    e = ov["electrical_energy"]
    assert e["measured"] == pytest.approx(e["simulated"], rel=2e-3)

    assert main(["log", str(DATA / "drive_log_dq.csv"), "--preset", "example_log_drive", "--identify",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["overlay"]["t0_s"] == pytest.approx(0.12, abs=2e-3)  # after 8 × 15 ms of injection
    ident = out["identified"]
    assert ident["voltage_delay_samples"] == 1
    assert ident["R_s"]["ci95"][0] <= TRUE_MOTOR["R_s"] <= ident["R_s"]["ci95"][1]
    assert ident["L_d"]["unit"] == "H" and ident["J_total"]["stderr"] > 0


def test_cli_log_bad_file_is_one_line_exit_2(tmp_path, capsys):
    from pmsm_commissioning.app.cli.main import main

    bad = tmp_path / "bad.csv"
    bad.write_text("t [s],i_q [A]\n" + "\n".join(f"{1 - k * 1e-3},{k}" for k in range(30)), encoding="utf-8")
    assert main(["log", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: column 't [s]': time does not increase at line 3") and "Traceback" not in err


def test_apply_identified_writes_values_sets_J_L_and_names_the_log_in_source():
    from pmsm_commissioning.app.ui.log import apply_identified

    params = load_preset("example_log_drive")
    r = identify(read_log(DATA / "drive_log_dq.csv").signals, params.motor.p)
    new = apply_identified(params, r, "drive_log_dq.csv")
    assert new.motor.R_s == r.get("R_s").value and new.load.F_v == r.get("F_v").value
    assert new.J_total == pytest.approx(r.get("J_total").value, rel=1e-12)  # J_L = J_total − J_r
    assert new.motor.J_r == params.motor.J_r and new.controller == params.controller
    assert "identified from drive log drive_log_dq.csv" in new.source
    heavy_rotor = dataclasses.replace(params, motor=dataclasses.replace(params.motor, J_r=0.5))
    with pytest.raises(ValueError, match=r"J_total = 0.1\d* kg·m² is below J_r = 0.5 kg·m²: lower J_r first"):
        apply_identified(heavy_rotor, r, "x.csv")


def test_overlay_figure_draws_measured_and_simulated_and_its_energy_matches_the_overlay():
    from pmsm_commissioning.app.figures.fdsmc_drive_log import cumulative_input_energy, make_log_overlay_figure
    from pmsm_commissioning.sim.drivelog.overlay import overlay

    params = load_preset("example_log_drive")
    ov = overlay(read_log(DATA / "drive_log_dq.csv").signals, simulate(params, "fdsmc").trace)
    fig = make_log_overlay_figure(ov, "drive_log_dq.csv")
    assert fig.layout.meta["id"] == "log-overlay" and {t.name for t in fig.data} == {"measured", "simulated"}
    assert cumulative_input_energy(ov.t, ov.measured)[-1] == pytest.approx(ov.energy_measured_J, rel=1e-12)
    assert cumulative_input_energy(ov.t, ov.simulated)[-1] == pytest.approx(ov.energy_simulated_J, rel=0.01)


def test_page_csv_export_with_unit_suffixes_and_run_column_is_accepted():
    from pmsm_commissioning.app.exports.model import trace_csv
    from pmsm_commissioning.sim.fdsmc.engine import compare

    params = load_preset("example_log_drive")
    cmp = compare(params)
    text = trace_csv(cmp)
    with pytest.raises(LogError, match="choose one"):
        parse_log(text)
    log = parse_log(text, "page.csv", run="conventional")
    assert np.allclose(log.signals["omega_r"], cmp.conventional.trace.omega_r, rtol=1e-8, atol=1e-9)
    assert np.allclose(log.signals["t"], cmp.conventional.trace.t, rtol=1e-8, atol=1e-12)


def test_given_move_start_shifts_the_overlay_and_a_wrong_one_shows_in_the_errors():
    """The own simulation behind 50 ms of rest: detected t0 = 50 ms with zero error; a t0 given
    10 ms late leaves a position error of about ω·10 ms.
    """
    from pmsm_commissioning.sim.drivelog.overlay import overlay

    run = simulate(load_preset("example_log_drive"), "fdsmc")
    tr = run.trace
    T_s = float(tr.t[1] - tr.t[0])
    n0 = int(round(0.05 / T_s))
    sig = {"t": np.concatenate([np.arange(n0) * T_s, tr.t + n0 * T_s]),
           "theta_r": np.concatenate([np.zeros(n0), tr.theta_r]) + 1.0}
    ov = overlay(sig, tr)
    assert ov.t0_detected and ov.t0 == pytest.approx(0.05, abs=T_s)
    assert ov.errors[0].signal == "theta_r" and ov.errors[0].rms_error < 1e-9
    late = overlay(sig, tr, t0=0.06)
    assert not late.t0_detected
    assert late.errors[0].peak_error == pytest.approx(0.01 * np.max(np.abs(tr.omega_r)), rel=0.1)


@pytest.mark.parametrize("fmt", ["{run}.{sig} [{unit}]", "{sig} [{unit}] ({run})", "{sig}_{run} [{unit}]",
                                 "{sig} ({run}) [{unit}]"])
def test_wide_csv_with_units_in_header_and_two_runs_picks_the_run(fmt):
    """A wide export with both runs side by side and units in the names (any of the usual
    spellings of the run) is a log; ``run`` picks one.
    """
    heads = ["t [s]"] + [fmt.format(run=r, sig=s, unit=u) for r in RUNS_ for s, u in (("theta_r", "rad"),
                                                                                      ("i_q", "A"))]
    rows = [f"{k * 1e-3},{k * 0.01},{k * 0.1},{-k * 0.01},{-k * 0.1}" for k in range(30)]
    text = ",".join(heads) + "\n" + "\n".join(rows)
    with pytest.raises(LogError, match="choose one"):
        parse_log(text)
    log = parse_log(text, run="conventional")
    assert log.signals["theta_r"][3] == pytest.approx(-0.03) and log.signals["i_q"][3] == pytest.approx(-0.3)


RUNS_ = ("fdsmc", "conventional")
