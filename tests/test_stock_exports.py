"""The one gate of every export format, the forced files' warnings, the parameter hash and the file headers."""

from __future__ import annotations

import dataclasses
import json

import pytest
import yaml

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives.files import DRIVE_FORMATS, ExportOptions
from pmsm_commissioning.app.exports.drives.stock_route import file_verdict
from pmsm_commissioning.app.exports.model import FORMATS, export_download, export_files
from pmsm_commissioning.app.exports.provenance import ExportRefusedError, failed_checks, parameter_hash
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.fdsmc.design import run_checks

FORCE = ExportOptions(force=True)


@pytest.fixture(scope="module")
def paper_case(paper_params):
    """The paper's case: K = 1000 chatters and its peaks exceed the drive's limits (not clean)."""
    return case(paper_params, "odrive")


@pytest.fixture(scope="module")
def clean_case():
    return case(load_preset("yaskawa_sgm7j_04a"), "odrive")


def test_new_formats_are_in_the_one_export_model_and_the_page_menu():
    from pmsm_commissioning.app.ui.files import EXPORTS

    assert FORMATS == ("yaml", "json", "c", "csv", "html", "odrive", "moteus", "vesc", "setpoints")
    assert set(DRIVE_FORMATS) <= set(FORMATS) and set(EXPORTS.values()) == set(FORMATS)


def test_cli_setpoint_options_are_checked(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert main(["export", "yaskawa_sgm7j_04a", "--format", "setpoints", "--cycle-ms", "-1", "-o", str(out)]) == 2
    assert "--cycle-ms = '-1' is not allowed: a time > 0 ms" in capsys.readouterr().err and not out.exists()
    assert main(["export", "yaskawa_sgm7j_04a", "--format", "setpoints", "--cycle-ms", "2", "--angle-unit", "deg",
                 "-o", str(out)]) == 0
    rows = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    assert rows[0] == "t [s],theta [deg],omega [deg/s],alpha [deg/s^2]" and rows[2].startswith("0.002,")


def test_clean_verdict_is_exactly_run_checks(paper_case, clean_case):
    p = paper_case.derived.params
    assert failed_checks(paper_case) == [c for c in run_checks(p, paper_case.fdsmc) if c.violated]
    assert {c.name for c in failed_checks(paper_case)} >= {"chatter", "torque"}
    assert failed_checks(clean_case) == []


@pytest.mark.parametrize("fmt", [f for f in FORMATS if f not in DRIVE_FORMATS])
def test_every_format_is_refused_for_a_design_that_is_not_clean(paper_case, fmt):
    with pytest.raises(ExportRefusedError, match=rf"export --format {fmt} refused: .* not clean — .*chatter: 1000 "
                                                 r"s/rad.*--force"):
        export_files(fmt, paper_case)
    with pytest.raises(ExportRefusedError, match="torque: "):
        export_download(fmt, paper_case)  # the page's path


@pytest.mark.parametrize("fmt", DRIVE_FORMATS)
def test_drive_files_are_refused_on_their_own_stock_route(paper_case, fmt):
    """A drive file is gated on the route its drive runs, simulated from the file (not on the FDSMC's chatter)."""
    with pytest.raises(ExportRefusedError, match=rf"export --format {fmt} refused: the stock route .* not clean — "
                                                 r".*saturation: .*--force") as exc:
        export_download(fmt, paper_case)  # the page's path
    assert "chatter" not in str(exc.value)


def test_cli_refuses_with_exit_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "p.odrive.json"
    assert main(["export", "paper_12kw_pmsm", "--format", "odrive", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    # one line (≤ 300 characters: the first failed checks, the paper's torque first)
    assert err.startswith("error: export --format odrive refused: the stock route") and err[-1] == "\n"
    assert not out.exists()
    assert main(["export", "paper_12kw_pmsm", "--format", "c", "-o", str(tmp_path / "c")]) == 2  # C too
    assert not (tmp_path / "c").exists()


def test_forced_files_carry_the_failed_checks_inside(paper_case):
    texts = {fmt: b"".join(export_files(fmt, paper_case, FORCE).values()).decode() for fmt in FORMATS}
    y = yaml.safe_load(texts["yaml"])
    assert any(c.startswith("chatter: 1000 s/rad") for c in y["verdicts"]["failed_checks"])
    assert json.loads(texts["json"])["verdicts"]["failed_checks"] == y["verdicts"]["failed_checks"]
    assert texts["c"].startswith("/* verdict: NOT CLEAN -- written with --force")  # ASCII, as the C files
    assert texts["csv"].startswith("# verdict: NOT CLEAN") and "\ncontroller,t [s]," in texts["csv"]
    assert '<body><div class="not-clean"><p>verdict: NOT CLEAN' in texts["html"]
    assert json.loads(texts["odrive"])["_comment"][3].startswith("verdict: NOT CLEAN — stock route")
    for fmt in ("moteus", "vesc", "setpoints"):  # (an XML comment cannot hold "--": VESC's reads "- -force")
        assert "verdict: NOT CLEAN — stock route" in texts[fmt] and "saturation: " in texts[fmt]
        assert "FDSMC design (C module, not this file): NOT CLEAN" in texts[fmt]


def test_clean_files_say_clean_and_carry_preset_version_hash_and_energies(clean_case):
    p = clean_case.derived.params
    comment = json.loads(export_files("odrive", clean_case)["yaskawa_sgm7j_04a.odrive.json"])["_comment"]
    assert comment[0].startswith("preset: yaskawa_sgm7j_04a")
    assert comment[1].startswith("written by: pmsm-commissioning (FDSMC) ")
    assert comment[2].startswith(f"parameter hash: {parameter_hash(p)}")
    assert comment[3].startswith("verdict: clean")
    energies = [c for c in comment if c.startswith("simulated whole-run energy")]
    assert [e.split(":")[0].rsplit(", ", 1)[1] for e in energies] == ["FDSMC", "tracked optimum",
                                                                         "stock route (this file)"]
    text = export_files("odrive", clean_case)["yaskawa_sgm7j_04a.odrive.json"].decode()
    stock = file_verdict("odrive", text, p, clean_case.derived).run.metrics.electrical_in_total_J
    assert f"net electrical {stock:.5g} J" in energies[2]  # the route this file runs
    y = yaml.safe_load(export_files("yaml", clean_case)["yaskawa_sgm7j_04a.yaml"])
    assert y["verdicts"]["failed_checks"] == []


def test_parameter_hash_is_a_pure_function_of_the_inputs(paper_params):
    h = parameter_hash(paper_params)
    assert len(h) == 16 and int(h, 16) >= 0 and parameter_hash(paper_params) == h
    moved = dataclasses.replace(paper_params, manoeuvre=dataclasses.replace(paper_params.manoeuvre, T_m=1.4))
    assert parameter_hash(moved) != h
    assert parameter_hash(load_preset("paper_12kw_pmsm")) == h  # the same inputs loaded again


def test_exports_are_reproducible_bytes(clean_case):
    for fmt in DRIVE_FORMATS:
        assert export_files(fmt, clean_case) == export_files(fmt, clean_case)
