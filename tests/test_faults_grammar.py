"""One number grammar: the same table of accepted and refused texts through every edge —
the parser itself (page fields), ``--set``, a YAML file or page upload, a JSON file, a drive-log CSV
cell and the numeric CLI options. ASCII decimal or scientific notation only; nothing else is a
number anywhere, and an accepted text means the same value everywhere.
"""

from __future__ import annotations

import argparse
import json
import re

import pytest

from pmsm_commissioning.app.io.drive_log import LogError, parse_log
from pmsm_commissioning.app.io.numbers import NumberFormatError, integer_option, number_option, parse_number
from pmsm_commissioning.app.io.presets import PRESET_DIR, PresetError, load_preset, loads_preset
from pmsm_commissioning.app.ui.files import parse_upload

PAPER = "paper_12kw_pmsm"
PAPER_TEXT = (PRESET_DIR / f"{PAPER}.yaml").read_text(encoding="utf-8")

#: Texts every edge accepts, with their value (as motor.R_s [Ω]).
ACCEPTED = [("0.15", 0.15), ("1.5e-1", 0.15), ("15E-2", 0.15), (".15", 0.15), ("+0.15", 0.15), ("0.150", 0.15),
            ("1 000", 1000.0), ("2", 2.0)]
#: Texts no edge accepts as a number.
REFUSED = ["０.15", "0.１5", "०.१५", "𝟎.𝟏𝟓", "\ufeff0.15", "0.1_5", "1_0", "0x1", "nan", "inf", "-inf", "1e400",
           "0,15", "0.15.1", "abc", "1:30", "'0.15'", '"0.15"', ">\n  0.15", "|\n  0.15", "0.15j"]
#: Refused where the value stands alone (``--set``, a CSV cell, a CLI option); a YAML or JSON file
#: may carry a comment after a value.
REFUSED_ALONE = ["0.15 # c"]
#: JSON's own syntax is stricter than the grammar: these are refused there as invalid JSON.
NOT_JSON = {"1 000", ".15", "+0.15"}


def _yaml_with(text: str) -> str:
    return re.sub(r"(?m)^  R_s: .*$", lambda _: "  R_s: " + text.replace("\n", "\n  "), PAPER_TEXT)


def _json_with(text: str) -> str:
    from pmsm_commissioning.app.io.presets import to_raw

    data = to_raw(load_preset(PAPER))
    data["motor"]["R_s"] = "@@"
    return json.dumps(data).replace('"@@"', text)


def _log_with(text: str) -> str:
    rows = [f"{k * 1e-3!r},{k * 1e-3!r},1.0" for k in range(40)]
    rows[5] = f"{5e-3!r},{5e-3!r},{text}"
    return "t [s],theta_r [rad],i_q [A]\n" + "\n".join(rows) + "\n"


def edge_value(edge: str, text: str) -> float:
    """The value ``text`` gets through ``edge`` (raises the edge's error when refused)."""
    if edge == "parser":
        return parse_number(text, "motor.R_s")
    if edge == "--set":
        return load_preset(PAPER, [f"motor.R_s={text}"]).motor.R_s
    if edge == "yaml":
        return loads_preset(_yaml_with(text), "x.yaml").motor.R_s
    if edge == "upload":
        return parse_upload("x.yaml", _yaml_with(text).encode()).motor.R_s
    if edge == "json":
        return loads_preset(_json_with(text), "x.json").motor.R_s
    if edge == "csv":
        return float(parse_log(_log_with(text), "x.csv").signals["i_q"][5])
    if edge == "option":
        return number_option("--price")(text)
    raise AssertionError(edge)


EDGES = ["parser", "--set", "yaml", "upload", "json", "csv", "option"]
ERRORS = (NumberFormatError, PresetError, LogError, argparse.ArgumentTypeError)


@pytest.mark.parametrize("edge", EDGES)
@pytest.mark.parametrize(("text", "value"), ACCEPTED)
def test_accepted_text_means_the_same_value_at_every_edge(edge, text, value):
    if edge == "json" and text in NOT_JSON:
        with pytest.raises(PresetError, match="not valid JSON"):
            edge_value(edge, text)
        return
    assert edge_value(edge, text) == value


@pytest.mark.parametrize("edge", EDGES)
@pytest.mark.parametrize("text", REFUSED + REFUSED_ALONE)
def test_refused_text_is_refused_at_every_edge_with_one_short_line(edge, text):
    if text in REFUSED_ALONE and edge in ("yaml", "upload"):
        assert edge_value(edge, text) == 0.15  # a comment in a file is a comment
        return
    if text == '"0.15"' and edge == "csv":
        assert edge_value(edge, text) == 0.15  # CSV quoting: the cell's text is 0.15
        return
    with pytest.raises(ERRORS) as info:
        edge_value(edge, text)
    message = str(info.value)
    assert len(message) <= 300 and message.count("\n") == 0, message


@pytest.mark.parametrize(("text", "value"), [("10", 10), ("1e1", 10), ("10.0", 10), (" 7 ", 7)])
def test_integer_options_take_whole_numbers_in_the_grammar(text, value):
    assert integer_option("--samples")(text) == value


@pytest.mark.parametrize("text", ["1_0", "１０", "10.5", "0x10", "nan", "", "1e400", "١٠"])
def test_integer_options_refuse_everything_else(text):
    with pytest.raises(argparse.ArgumentTypeError, match="--samples"):
        integer_option("--samples")(text)


@pytest.mark.parametrize("argv", [["dutycycle", PAPER, "x.yaml", "--cycles-per-hour", "1_0"],
                                  ["dutycycle", PAPER, "x.yaml", "--price", "０.25"],
                                  ["log", "x.csv", "--t0", "nan"], ["serve", "--port", "8_080"]])
def test_cli_options_refuse_outside_the_grammar_with_exit_2(argv, capsys):
    from pmsm_commissioning.app.cli.main import main

    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1 and "is not a number" in err and len(err) <= 300
