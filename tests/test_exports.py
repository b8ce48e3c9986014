"""Exports: YAML re-imports exactly, JSON/C header carry the gains, CSV, offline HTML report."""

from __future__ import annotations

import csv
import io
import json
import re

import pytest

from app.exports import (
    drive_gains,
    html_report,
    parameter_c_header,
    parameter_json,
    parameter_yaml,
    trace_csv,
)
from app.figures import make_phase_plane_figure
from app.presets import loads_preset, loads_raw
from app.ui_files import parse_upload, safe_stem
from control.derivations import derive
from control.params import ParameterError
from sim.engine import compare


@pytest.fixture(scope="module")
def derived(paper_params):
    return derive(paper_params)


def test_yaml_export_reimports_to_identical_inputs(paper_params, derived):
    text = parameter_yaml(paper_params, derived, "paper_12kw_pmsm")
    assert loads_preset(text, "export.yaml") == paper_params
    raw = loads_raw(text, "export.yaml")
    gains = raw["drive_gains"]  # the gains are data the drive can read, not comments
    assert raw["exported_from"] == "paper_12kw_pmsm"
    assert float(gains["OBS_K1"]) == derived.observer.K1  # raw YAML scalars are text, parsed exactly
    assert float(gains["ALPHA_MAX"]) == derived.alpha.alpha_max
    assert float(gains["OBS_L4"]) == float(derived.observer_discrete.L[3])
    assert f"OBS_K1: {derived.observer.K1!r}  # [1/s]" in text  # unit on the same line


def test_json_export_holds_inputs_and_every_gain(paper_params, derived):
    data = json.loads(parameter_json(paper_params, derived, "paper_12kw_pmsm"))
    assert data["schema"] == 1 and data["preset"] == "paper_12kw_pmsm"
    assert data["inputs"]["load"]["F_v"] == paper_params.load.F_v
    gains = data["gains"]
    for name in ("OBS_K1", "OBS_K2", "OBS_K3", "OBS_K4", "OBS_L1", "OBS_L4", "F_S", "ALPHA_MAX",
                 "OMEGA_P", "T_A", "T_C", "K_BL", "G1", "G2", "T_SI", "T_SALPHA"):
        assert name in gains
    assert gains["G1"]["value"] == pytest.approx(derived.conventional.g1)
    assert gains["OBS_L2"]["value"] == pytest.approx(float(derived.observer_discrete.L[1]))
    assert data["derived"]["alpha_max"] == derived.alpha.alpha_max


def test_c_header_defines_upper_case_gains_with_units(paper_params, derived):
    header = parameter_c_header(paper_params, derived, "paper */ evil")
    defines = re.findall(r"#define (FDSMC_[A-Z0-9_]+)\s+\(([^)]+)\) /\* \[([^\]]+)\]", header)
    names = {n: (float(v), u) for n, v, u in defines}
    assert names["FDSMC_ALPHA_MAX"][0] == derived.alpha.alpha_max
    assert names["FDSMC_OBS_K3"][1] == "N·m/(rad·s)"
    assert len(names) == len(drive_gains(derived))
    assert header.count("*/") == header.count("/*")  # origin cannot close the comment early


def test_csv_has_both_controllers_with_units(paper_params):
    c = compare(paper_params)
    rows = list(csv.reader(io.StringIO(trace_csv(c))))
    assert rows[0][:3] == ["controller", "t_s", "theta_r_rad"]
    kinds = {r[0] for r in rows[1:]}
    assert kinds == {"fdsmc", "conventional"}
    assert len(rows) - 1 == len(c.fdsmc.trace.t) + len(c.conventional.trace.t)
    last = next(r for r in reversed(rows) if r[0] == "fdsmc")
    assert float(last[2]) == pytest.approx(c.fdsmc.trace.theta_r[-1], rel=1e-8)


def test_html_report_is_self_contained(paper_params, derived):
    c = compare(paper_params)
    page = html_report(paper_params, derived, "paper_12kw_pmsm", ["a <warning>"],
                       [make_phase_plane_figure(c)])
    assert "<script src=" not in page.replace("<script src=\"data:", "")  # plotly.js inlined
    assert "a &lt;warning&gt;" in page and "α_max" in page and "Plotly.newPlot" in page


def test_upload_rejects_bad_files_with_clear_messages(paper_params):
    with pytest.raises(ValueError, match="not valid YAML"):
        parse_upload("bad.yaml", b"motor: [1, 2")
    with pytest.raises(ValueError, match="too large"):
        parse_upload("big.yaml", b"#" * (300 * 1024))
    with pytest.raises(ValueError, match="UTF-8"):
        parse_upload("bin.yaml", b"\xff\xfe\x00")
    text = parameter_yaml(paper_params, derive(paper_params), "x").replace("J_r: 0.03", "J_r: -0.03")
    with pytest.raises(ParameterError, match=r"motor\.J_r .*allowed 1e-09 ≤ value"):
        parse_upload("neg.yaml", text.encode())
    assert parse_upload("ok.yaml", parameter_yaml(paper_params, derive(paper_params), "x").encode()) == paper_params
    assert safe_stem("../my motor*") == "my_motor"
