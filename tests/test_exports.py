"""Exports: one model for page and CLI; YAML/JSON round trip (schema 2, schema 1 still read),
units and verdicts carried, one CSV format, the offline HTML report with its metrics table.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import re
import zipfile

import pytest
import yaml

from pmsm_commissioning.app.cli.export import case as export_case
from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives.files import ExportOptions
from pmsm_commissioning.app.exports.html import ROW_HEIGHT_PX, html_report
from pmsm_commissioning.app.exports.model import (
    FORMATS,
    drive_gains,
    export_download,
    export_files,
    parameter_json,
    parameter_yaml,
    trace_csv,
)
from pmsm_commissioning.app.io.presets import SCHEMA, load_preset, loads_preset, loads_raw
from pmsm_commissioning.app.io.units import SI_UNITS
from pmsm_commissioning.app.ui.files import parse_upload, safe_stem, uncommitted
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc.engine import Comparison, compare

#: The paper's case is not clean (K = 1000 chatters, torque and voltage beyond the drive's): its
#: exports pass the gate only forced (the gate itself: tests/test_stock_exports.py).
FORCE = ExportOptions(force=True)


@pytest.fixture(scope="module")
def case(paper_params) -> Comparison:
    return compare(paper_params)


@pytest.fixture(scope="module")
def motor_case(paper_params) -> Comparison:
    """A renamed motor with a different T_m: names and values must follow the inputs."""
    params = dataclasses.replace(paper_params, name="acme 7kW servo", source="ACME data sheet rev. C",
                                 manoeuvre=dataclasses.replace(paper_params.manoeuvre, T_m=1.4))
    return compare(params)


@pytest.mark.parametrize("fmt", ["yaml", "json"])
def test_parameter_file_round_trips_identically(tmp_path, motor_case, fmt):
    """export → import (CLI, path to the exported file) → export gives the same bytes."""
    ((name, first),) = export_files(fmt, motor_case, FORCE).items()
    assert name == f"acme_7kW_servo.{fmt}"
    path = tmp_path / name
    path.write_bytes(first)
    assert load_preset(str(path)) == motor_case.derived.params
    out = tmp_path / f"again.{fmt}"
    assert main(["export", str(path), "--format", fmt, "-o", str(out), "--force"]) == 0
    assert out.read_bytes() == first


def test_yaml_and_json_carry_the_same_data_with_units_gains_and_verdicts(motor_case):
    y = yaml.safe_load(parameter_yaml(motor_case))  # typed reading (the loader keeps scalars as text)
    j = json.loads(parameter_json(motor_case))
    assert y == j
    assert j["schema"] == SCHEMA == 2 and j["name"] == "acme 7kW servo" and j["source"] == "ACME data sheet rev. C"
    assert j["manoeuvre"]["T_m"] == 1.4
    for section in ("motor", "load", "controller", "manoeuvre"):  # a unit for every input
        assert set(j[section]) == set(j["units"][section])
    assert j["units"]["motor"]["L_d"] == "H" and j["units"]["load"]["F_v"] == "N·m·s/rad"
    d = motor_case.derived
    gains = j["drive_gains"]
    assert len(gains) == len(drive_gains(d))
    assert gains["OBS_K1"] == {"value": d.observer.K1, "unit": "1/s", "ref": "observer gain, eq. (18)"}
    assert gains["OBS_L4"]["value"] == float(d.observer_discrete.L[3]) and gains["OBS_L4"]["unit"] == "N·m/(rad·s)"
    v = j["verdicts"]
    assert v["feasible"] is True and any("chatter" in w.lower() for w in v["run_warnings"])  # K = 1000
    assert v["saving_friction_pct"] == pytest.approx(motor_case.saving_friction_pct)
    assert j["results"]["fdsmc"]["friction_J"] == motor_case.fdsmc.metrics.friction_J
    assert j["results"]["conventional"]["stable"] is True


def test_schema_1_preset_and_schema_1_exports_still_load(paper_params):
    """Schema 1 (the shipped presets, the earlier YAML and JSON exports) is migrated on read."""
    assert str(loads_raw((load_preset.__globals__["PRESET_DIR"] / "paper_12kw_pmsm.yaml").read_text())["schema"]) == "1"
    old_yaml = ("schema: 1\nname: old\nsource: s\n" + "\n".join(
        f"{sec}: {json.dumps(dict(vals))}" for sec, vals in _sections(paper_params).items())
        + "\nexported_from: \"paper_12kw_pmsm\"\ndrive_gains:\n  OBS_K1: 150000.0  # [1/s]\n")
    assert loads_preset(old_yaml, "old.yaml") == dataclasses.replace(paper_params, name="old", source="s")
    old_json = json.dumps({"schema": 1, "tool": "pmsm-commissioning (FDSMC)", "preset": "paper_12kw_pmsm",
                           "inputs": {"schema": 1, "name": "old", "source": "s", **_sections(paper_params)},
                           "gains": {}, "derived": {}})
    assert loads_preset(old_json, "old.json") == dataclasses.replace(paper_params, name="old", source="s")
    with pytest.raises(ValueError, match="schema = '3' is not supported: allowed schema: 1 or 2"):
        loads_preset(old_yaml.replace("schema: 1", "schema: 3"))


def _sections(params) -> dict:
    raw = json.loads(parameter_json(compare(params, ("fdsmc",))))
    return {sec: raw[sec] for sec in ("motor", "load", "controller", "manoeuvre")}


def test_units_section_must_state_si_units(case):
    text = parameter_yaml(case).replace("    L_d: H\n", "    L_d: mH\n")
    with pytest.raises(ValueError, match=r"units\.motor\.L_d = 'mH' is not allowed: .*SI \('H'\)"):
        loads_preset(text)
    assert set(SI_UNITS["controller"]) == set(json.loads(parameter_json(case))["controller"])


def test_json_rejects_non_finite_and_bad_text(case):
    with pytest.raises(ValueError, match="not valid JSON at line 1"):
        loads_preset('{"schema": 2,', "x.json")
    with pytest.raises(ValueError, match="NaN is not allowed"):
        loads_preset(parameter_json(case).replace('"T_m": 1.0', '"T_m": NaN'), "x.json")
    with pytest.raises(ValueError, match="key 'T_m' is given more than once"):
        loads_preset(parameter_json(case).replace('"T_m": 1.0', '"T_m": 1.0, "T_m": 2.0'), "x.json")


def test_csv_one_table_with_units_in_headers(case):
    rows = list(csv.reader(io.StringIO(trace_csv(case))))
    assert rows[0][:4] == ["controller", "t [s]", "theta_r [rad]", "omega_r [rad/s]"]
    assert "E_friction [J]" in rows[0] and "i_q [A]" in rows[0]
    assert {r[0] for r in rows[1:]} == {"fdsmc", "conventional"}
    assert len(rows) - 1 == len(case.fdsmc.trace.t) + len(case.conventional.trace.t)
    last = next(r for r in reversed(rows) if r[0] == "fdsmc")
    assert float(last[2]) == pytest.approx(case.fdsmc.trace.theta_r[-1], rel=1e-8)


def test_csv_of_an_infeasible_case_is_refused(paper_params):
    params = dataclasses.replace(paper_params, manoeuvre=dataclasses.replace(paper_params.manoeuvre, T_m=0.1))
    d = derive(params)
    with pytest.raises(ParameterError, match="no simulated run.*T_m = 0.1 s is infeasible"):
        export_files("csv", Comparison(d, None, None, None, None), FORCE)


def test_html_report_has_metrics_table_and_legible_plots(motor_case):
    page = html_report(motor_case)
    assert "<script src=" not in page.replace("<script src=\"data:", "")  # plotly.js inlined: offline
    assert "Plotly.newPlot" in page and "acme 7kW servo" in page and "ACME data sheet rev. C" in page
    table = page[page.index("<h2>Simulated metrics</h2>"):page.index("<h2>Inputs")]
    for label in ("Peak torque", "Peak |u_dq|", "2 % settling time", "Overshoot", "Friction loss", "Stable"):
        assert label in table
    assert f"{motor_case.fdsmc.metrics.friction_J:.5g}" in table and "40 (Γ_max)" in table
    heights = [int(h) for h in re.findall(r'"height":\s*(\d+)', page)]
    assert max(heights) >= 6 * ROW_HEIGHT_PX and ROW_HEIGHT_PX >= 250  # six time plots, ≥ 250 px each
    assert html_report(motor_case) == page  # reproducible bytes (fixed figure ids, no clock)


def test_page_and_cli_write_the_same_bytes(tmp_path, motor_case):
    params = motor_case.derived.params
    src = tmp_path / "in.yaml"
    src.write_bytes(export_files("yaml", motor_case, FORCE)["acme_7kW_servo.yaml"])
    for fmt in FORMATS:
        out = tmp_path / fmt
        out.mkdir()
        target = out if fmt == "c" else out / "x"
        assert main(["export", str(src), "--format", fmt, "-o", str(target), "--force"]) == 0
        # the runs each format needs (the report and the drive files add the optimum and stock route,
        # as the page does with its default "show the optimum")
        files = export_files(fmt, export_case(params, fmt), FORCE)
        if fmt == "c":
            assert {p.name: p.read_bytes() for p in out.iterdir()} == files
        else:
            assert target.read_bytes() == next(iter(files.values()))
    name, archive = export_download("c", motor_case, FORCE)
    assert name == f"{safe_stem(params.name)}_fdsmc_controller.zip"
    with zipfile.ZipFile(io.BytesIO(archive)) as zf:
        assert {n: zf.read(n) for n in zf.namelist()} == export_files("c", motor_case, FORCE)


def test_cli_name_and_source_options_rename_the_export(tmp_path):
    out = tmp_path / "m.json"
    assert main(["export", "paper_12kw_pmsm", "--set", "controller.K=0.3", "--format", "json", "-o", str(out),
                 "--name", "line 3 axis", "--source", "nameplate", "--force"]) == 0
    data = json.loads(out.read_text())
    assert (data["name"], data["source"], data["controller"]["K"]) == ("line 3 axis", "nameplate", 0.3)
    assert main(["export", "paper_12kw_pmsm", "--format", "c", "-o", str(out)]) == 2  # a file, not a folder
    assert main(["export", "bldc_smc_paper", "--format", "yaml", "-o", str(tmp_path / "b.yaml")]) == 2


def test_uncommitted_names_each_edited_field(paper_params):
    shown = dataclasses.replace(paper_params, manoeuvre=dataclasses.replace(paper_params.manoeuvre, T_m=1.4))
    assert uncommitted(shown, paper_params) == ["manoeuvre.T_m = 1.4 (simulated: 1.0)"]
    assert uncommitted(paper_params, paper_params) == []


def test_upload_rejects_bad_files_with_clear_messages(paper_params, case):
    with pytest.raises(ValueError, match="not valid YAML"):
        parse_upload("bad.yaml", b"motor: [1, 2")
    with pytest.raises(ValueError, match="too large"):
        parse_upload("big.yaml", b"#" * (300 * 1024))
    with pytest.raises(ValueError, match="UTF-8"):
        parse_upload("bin.yaml", b"\xff\xfe\x00")
    text = parameter_yaml(case).replace("J_r: 0.03", "J_r: -0.03")
    with pytest.raises(ParameterError, match=r"motor\.J_r .*allowed"):
        parse_upload("neg.yaml", text.encode())
    assert parse_upload("ok.yaml", parameter_yaml(case).encode()) == paper_params
    assert parse_upload("ok.json", parameter_json(case).encode()) == paper_params
    assert safe_stem("../my motor*") == "my_motor"


def test_page_rename_sets_file_name_and_refuses_blank(case):
    from pmsm_commissioning.app.ui.files import ExportRefusedError, renamed

    name, content = export_download("yaml", renamed(case, " line 3 axis ", "nameplate"), FORCE)
    assert name == "line_3_axis.yaml" and loads_raw(content.decode())["source"] == "nameplate"
    with pytest.raises(ExportRefusedError, match="name = ' ' is empty"):
        renamed(case, " ", "x")


@pytest.mark.parametrize("fmt", ["yaml", "json"])
def test_round_trip_in_continuous_mode(tmp_path, paper_params, fmt):
    """The controller evaluated continuously (no f_s): no discrete gains, same round trip."""
    params = dataclasses.replace(paper_params, controller=dataclasses.replace(paper_params.controller,
                                                                              f_s="continuous", K=0.3))
    cmp = compare(params)
    ((name, first),) = export_files(fmt, cmp, FORCE).items()
    data = loads_raw(first.decode(), name) if fmt == "yaml" else json.loads(first)
    assert data["controller"]["f_s"] == "continuous" and "OBS_L1" not in data["drive_gains"]
    assert loads_preset(first.decode(), name) == params
    assert export_files(fmt, compare(loads_preset(first.decode(), name)), FORCE)[name] == first
    with pytest.raises(ParameterError, match="controller.f_s = 'continuous' cannot be exported as C"):
        export_files("c", cmp, FORCE)


def test_bldc_mode_presets_load_from_yaml_and_json():
    from pmsm_commissioning.app.io.presets import dumps_preset, to_raw

    bldc = load_preset("bldc_smc_paper")
    assert loads_preset(dumps_preset(bldc), "b.yaml") == bldc
    assert loads_preset(json.dumps(to_raw(bldc)), "b.json") == bldc
    assert to_raw(bldc)["schema"] == SCHEMA
