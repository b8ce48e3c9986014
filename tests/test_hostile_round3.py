"""Hostile input, round three: no user text adds a line, key, row or formula to a written file; one
number grammar; no traceback; ``-o`` never replaces a device, a read-only file or follows a link loop.

The writers are fed a generated corpus of hostile names and sources and their files are read back by
our own strict parsers (and by the vendor's line rule: moteus_tool splits on LF alone).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import os
import signal
import stat
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives import moteus, odrive, setpoints, vesc
from pmsm_commissioning.app.exports.drives.stock import stock_settings
from pmsm_commissioning.app.exports.provenance import header_lines
from pmsm_commissioning.app.io import atomic
from pmsm_commissioning.app.io.numbers import one_line, parse_number
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.io.user_text import check_label, csv_comment, escaped, forbidden, xml_comment
from pmsm_commissioning.app.io.yaml_text import loads_any_raw, loads_raw, plain_scalar
from pmsm_commissioning.control.common.checks import ParameterError

#: Every kind of line break, control, C1, bidi and format character.
SEPARATORS = "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"
CONTROLS = "\x00\x07\x08\x1b\x7f\x9b\x9d\u200e\u202a\u202e\u2066\u2069\ufeff"
PAYLOADS = ("servo.max_voltage 1000", "servo.max_current_A 500", "motor.Kv 9999", "servo.pwm_rate_hz 1",
            '=HYPERLINK("http://evil/x","click")', "0,999,999,999", '"axis0": {"x": 1}', "-->", "--- -- -",
            "<MCConfiguration><foc_motor_r>9</foc_motor_r>", "\x1b]0;PWNED\x07\x1b[2J", "+1", "@SUM(A1)", "-2+3")


def corpus() -> list[str]:
    """Hostile names: each payload after each separator/control, and the worst of all at once."""
    out = [f"m{sep}{PAYLOADS[i % 5]}" for i, sep in enumerate(SEPARATORS + CONTROLS)]
    out += [f"x,{p}" for p in PAYLOADS] + ["".join(f"{s}{p}" for s, p in zip(SEPARATORS, PAYLOADS, strict=False))]
    return out


@pytest.fixture(scope="module")
def base():
    cmp = case(load_preset("yaskawa_sgm7j_04a"), "odrive")
    cascade = stock_settings(cmp, "odrive")  # the writers read only the settings' fields: one tuning per law
    return cmp, {"moteus": stock_settings(cmp, "moteus"), "odrive": cascade, "vesc": cascade, "setpoints": cascade}


def _renamed(cmp, text: str):
    params = dataclasses.replace(cmp.derived.params, name=text, source=text)
    return dataclasses.replace(cmp, derived=dataclasses.replace(cmp.derived, params=params))


def _files(base, text: str) -> dict[str, str]:
    cmp, settings = base
    header = header_lines(_renamed(cmp, text), [])
    cycle = 5e-3  # a short table: the header is what is tested
    return {"moteus": moteus.moteus_text(settings["moteus"], header),
            "odrive": odrive.odrive_json(settings["odrive"], header),
            "vesc": vesc.vesc_xml(settings["vesc"], header),
            "setpoints": setpoints.setpoints_csv(settings["setpoints"], header, "rad", cycle)}


def test_no_user_text_adds_a_line_key_or_row_to_any_drive_file(base):
    clean = _files(base, "clean")
    keys = {fmt: text.count("\n") for fmt, text in clean.items()}
    for text in corpus():
        files = _files(base, text)
        for fmt, body in files.items():
            assert body.count("\n") == keys[fmt], (fmt, text)  # not one line more
            assert body.splitlines() == body.split("\n")[:-1], (fmt, text)  # no other separator anywhere
            assert not any(forbidden(ch) for ch in body.replace("\n", "")), (fmt, text)
        m = moteus.parse_moteus(files["moteus"])
        assert dict(m.values) == dict(moteus.parse_moteus(clean["moteus"]).values) and m.unknown == ()
        live = [ln for ln in files["moteus"].split("\n") if ln.strip() and not ln.startswith("#")]
        assert len(live) == len(moteus.KEYS)  # moteus_tool sends every non-# line: ours only
        o = odrive.parse_odrive(files["odrive"])
        assert {k for k, _ in o.values} == set(odrive.KEYS) and o.unknown == ()
        v = vesc.parse_vesc(files["vesc"])
        ET.fromstring(files["vesc"])  # well-formed
        assert {k for k, _ in v.values} == set(vesc.KEYS) and v.unknown == ()
        assert escaped(text) in xml_comment(escaped(text)).replace("- ", "-") or "--" in text
        rows = setpoints.parse_setpoints(files["setpoints"]).t.size
        assert rows == setpoints.parse_setpoints(clean["setpoints"]).t.size


def test_setpoint_csv_has_no_formula_cell_and_no_quoted_field(base):
    for text in corpus():
        body = _files(base, text)["setpoints"]
        for row in csv.reader(io.StringIO(body)):
            for cell in row[1:] if row and row[0].startswith("#") else []:
                assert cell.lstrip(" ")[:1] not in set("=+-@\"\t\r"), (text, cell)
            assert not (row and row[0][:1] in set("=+@\"")), (text, row)
    assert csv_comment('a,=1+1, -2,@x,"q') == "a,'=1+1, '-2,'@x,'\"q"


def test_vesc_comment_is_well_formed_and_round_trips():
    for text in ("a---b", "-", "--", "x--", "--->", "a - -- b"):
        c = xml_comment(text)
        assert "--" not in c and not c.endswith("-")
        ET.fromstring(f"<!--\n    {c}\n--><a/>")


def test_names_are_refused_at_the_edge_naming_field_value_and_allowed():
    for ch in SEPARATORS + CONTROLS:
        with pytest.raises(ParameterError, match=r"--source = '.*' holds .*allowed printable characters"):
            check_label(f"a{ch}b", "--source")
    assert check_label("Yaskawa SGM7J-04A — data sheet, 2021 (µ, Ω)", "--source")
    with pytest.raises(ValueError, match="name = 'a\\\\nb' holds"):
        loads_raw('name: "a\\nb"\nsource: x\n')
    with pytest.raises(ValueError, match="source = '\\\\u2028'"):
        loads_any_raw('{"name": "n", "source": "\\u2028"}', "p.json")
    with pytest.raises(ValueError, match="key 'k\\\\x1b'"):
        loads_raw('"k\\x1b": 1\n')


def test_page_export_source_is_refused(base):
    from pmsm_commissioning.app.ui.files import ExportRefusedError, renamed

    with pytest.raises(ExportRefusedError, match="Export › source = .*holds"):
        renamed(base[0], "ok", "x\u2028servo.max_voltage 1000")
    assert renamed(base[0], "ok", "data sheet").derived.params.source == "data sheet"


def test_cli_export_name_and_source_with_a_newline_exit_2(tmp_path, capsys):
    for opt in ("--name", "--source"):
        assert main(["export", "yaskawa_sgm7j_04a", "--format", "moteus", opt, "m\nservo.max_voltage 1000",
                     "-o", str(tmp_path / "m.cfg")]) == 2
        assert f"{opt} = 'm\\nservo.max_voltage 1000' holds" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_import_drive_writes_no_yaml_from_a_key_or_a_file_name(tmp_path, capsys):
    data = json.loads((Path(__file__).parent / "data" / "drives" / "odrive_d5065_backup.json").read_text())
    data["axis0"]["x\nplant:\n  J_L: 0.7\n#"] = 1
    src = tmp_path / "d\nplant.J_L=0.7\u2028\x1b]0;PWNED\x07.json"
    src.write_text(json.dumps(data))
    out = tmp_path / "p.yaml"
    assert main(["import-drive", str(src), "--format", "odrive", "--base", "yaskawa_sgm7j_02a", "-o", str(out)]) == 0
    text = out.read_text()
    assert "\nplant:" not in text and not any(forbidden(ch) for ch in text.replace("\n", ""))
    p = load_preset(str(out))
    assert "\n" not in p.name and "plant" not in loads_raw(text)
    printed = capsys.readouterr().out
    assert "\x1b" not in printed and "x\\nplant:" in printed  # the key listed, escaped
    assert main(["import-drive", str(src), "--format", "odrive", "--base", "yaskawa_sgm7j_02a", "-o",
                 str(tmp_path / "q.yaml"), "--name", "a\nb"]) == 2


def test_terminal_messages_show_control_sequences_escaped():
    msg = one_line("key '\x1b]0;PWNED\x07\x1b[2J' \x9b31m \u202e")
    assert not any(forbidden(ch) for ch in msg) and "\\x1b]0;PWNED\\x07" in msg


@pytest.mark.parametrize("text", ["1_0", "١", "１", "१", "١٫٥", "0x10", "1e-400", "-1e-400"])
def test_one_number_grammar_everywhere(text):
    with pytest.raises(ValueError):
        parse_number(text, "f")
    with pytest.raises(ParameterError):
        moteus.parse_moteus(f"motor.resistance_ohm {text}\n")
    with pytest.raises(ParameterError):
        vesc.parse_vesc(f"<MCConfiguration><ConfigVersion>2</ConfigVersion><foc_motor_r>{text}</foc_motor_r>"
                        "</MCConfiguration>")


@pytest.mark.parametrize("opt", ["--samples", "--seed", "--workers", "--cluster-timeout"])
def test_robustness_options_refuse_other_digits(opt, capsys):
    for text in ("1_0", "١", "１"):
        with pytest.raises(SystemExit) as exc:
            main(["robustness", "yaskawa_sgm7j_04a", opt, text])
        assert exc.value.code == 2 and opt in capsys.readouterr().err
    assert main(["robustness", "yaskawa_sgm7j_04a", "--spread", "plant.J_L=0:１", "--samples", "2"]) == 2


def test_underflow_and_hidden_comment_are_refused():
    with pytest.raises(ValueError, match="underflows to 0"):
        parse_number("1e-400", "load.Gamma_Le")
    assert parse_number("0e-400", "x") == 0.0 and parse_number("1e-310", "x") == 1e-310
    for text in ("[1, 2] # 3", "[1, # 2\n 3]"):
        with pytest.raises(ValueError, match="not a plain value"):
            plain_scalar(text, "--set x")
    assert plain_scalar("[a#, 1]", "w") == ["a#", "1"]


def test_odrive_json_nested_5000_deep_is_one_line():
    with pytest.raises(ParameterError, match="nested too deeply"):
        odrive.parse_odrive('{"axis0": ' * 5000 + "1" + "}" * 5000)
    with pytest.raises(ParameterError, match="nested deeper than"):
        odrive.parse_odrive('{"axis0":' + '{"a":' * 40 + "1" + "}" * 41)


def test_output_targets_are_refused_the_same_way(tmp_path):
    (tmp_path / "l1").symlink_to(tmp_path / "l2")
    (tmp_path / "l2").symlink_to(tmp_path / "l1")
    ro = tmp_path / "ro.yaml"
    ro.write_text("old")
    ro.chmod(0o444)
    os.mkfifo(tmp_path / "fifo")
    cases = {"/dev/null": "character device", "/dev/full": "character device", str(tmp_path / "l1"): "loop",
             str(ro): "read-only", str(tmp_path / "fifo"): "FIFO", str(tmp_path): "folder"}
    for path, what in cases.items():
        assert what in (atomic.target_problem(path) or "")
        with pytest.raises(OSError, match=what):
            atomic.write_atomic(path, b"x")
        for cmd in (["export", "yaskawa_sgm7j_04a", "--format", "yaml"], ["design", "yaskawa_sgm7j_04a"]):
            assert main([*cmd, "-o", path]) == 2
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode) and ro.read_text() == "old"


def test_c_folder_is_all_old_or_all_new_on_a_full_disk(tmp_path, monkeypatch):
    a, b = tmp_path / "a.h", tmp_path / "b.c"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = atomic._temporary
    calls = []

    def full_on_second(target, data):
        calls.append(target)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        return real(target, data)

    monkeypatch.setattr(atomic, "_temporary", full_on_second)
    with pytest.raises(OSError, match="No space"):
        atomic.write_all({a: b"new a", b: b"new b"})
    assert (a.read_bytes(), b.read_bytes()) == (b"old a", b"old b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h", "b.c"]  # no temporary file left


def test_robustness_disk_full_is_one_line(tmp_path, monkeypatch, capsys):
    import pmsm_commissioning.app.cli.robustness as rb

    def full(path, *args):
        with open(path, "wb") as fh:
            fh.write(b"partial")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(rb, "write_csv", full)
    out = tmp_path / "r.csv"
    assert main(["robustness", "yaskawa_sgm7j_04a", "--samples", "1", "--workers", "1", "--csv", str(out)]) == 2
    assert "No space left on device" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_dutycycle_huge_dwell_and_unreadable_file(tmp_path, capsys):
    moves = tmp_path / "m.yaml"
    moves.write_text("- {theta_dem: 1, T_m: 1, dwell: 1e300}\n")
    assert main(["dutycycle", "yaskawa_sgm7j_04a", str(moves)]) == 2
    assert "dwell" in capsys.readouterr().err
    if os.path.exists("/proc/self/mem"):
        assert main(["dutycycle", "yaskawa_sgm7j_04a", "/proc/self/mem"]) == 2
        assert "cannot be read" in capsys.readouterr().err


def test_pool_workers_start_with_sigint_blocked():
    from pmsm_commissioning.sim.studies.runner import RetryingPool

    with RetryingPool(1) as pool:
        mask = pool.submit(signal.pthread_sigmask, signal.SIG_BLOCK, set()).result()
    assert signal.SIGINT in mask and signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())


@pytest.mark.parametrize("kv", ["0", "-0", "-304"])
def test_a_speed_constant_that_gives_no_flux_is_refused_naming_it(kv, capsys):
    assert main(["derive", "odrive_d5065_belt", "--set", f"motor.Kv_rpm_per_V={kv}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: motor.Kv_rpm_per_V = ") and "allowed > 0 rpm/V" in err and "Traceback" not in err


@pytest.mark.parametrize("mode", ["[a, b]", "{a: 1}"])
def test_a_mode_that_is_not_a_name_is_refused(mode, tmp_path, capsys):
    path = tmp_path / "m.yaml"
    path.write_text(f"schema: 2\nmode: {mode}\n")
    assert main(["derive", str(path)]) == 2
    err = capsys.readouterr().err
    assert "mode = " in err and "allowed: position, bldc" in err and "Traceback" not in err
