"""Parser blow-ups: every nesting attack is refused by the parser itself, with one clear
line, never a RecursionError; YAML (files, uploads, ``--set``) and JSON alike.

Timings are printed by ``scripts/bench_hostile.py`` (not asserted here).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from pmsm_commissioning.app.io.presets import MAX_DEPTH, PRESET_DIR, PresetError, load_preset, loads_preset, to_raw
from pmsm_commissioning.app.ui.files import parse_upload
from tests.hostile_inputs import attacks

PAPER = "paper_12kw_pmsm"
ATTACKS = attacks()


def _load(kind: str, text: str) -> None:
    if kind == "set":
        load_preset(PAPER, [text])
    else:
        loads_preset(text, f"attack.{kind}")


@pytest.mark.parametrize("name", list(ATTACKS))
def test_nesting_attack_is_refused_with_one_clear_line(name):
    kind, text, says = ATTACKS[name]
    with pytest.raises(PresetError) as info:
        _load(kind, text)
    message = str(info.value)
    assert says in message and "\n" not in message and len(message) <= 300, message
    if says == "nested too deeply":
        assert f"allowed ≤ {MAX_DEPTH}" in message


@pytest.mark.parametrize("name", [n for n in ATTACKS if ATTACKS[n][0] != "set"])
def test_nesting_attack_in_a_page_upload_is_refused(name):
    kind, text, says = ATTACKS[name]
    with pytest.raises(PresetError, match=says):
        parse_upload(f"attack.{kind}", text.encode())


def test_the_issue_json_reproduction_names_the_nesting():
    with pytest.raises(PresetError, match=r"attack\.json is nested too deeply at line 1: allowed ≤ 32"):
        loads_preset('{"name":"\\"","x":' + "[" * 600, "attack.json")


def test_depth_within_the_limit_still_parses():
    text = (PRESET_DIR / f"{PAPER}.yaml").read_text(encoding="utf-8")
    ok = "x: " + "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1)  # inside the top-level mapping: 32 levels
    assert "nested" not in _message(lambda: loads_preset(text + "\nextra_" + ok, "deep.yaml"))
    with pytest.raises(PresetError, match="nested too deeply"):
        loads_preset(text + "\nextra_x: " + "[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1), "deep.yaml")


def _message(call) -> str:
    try:
        call()
    except PresetError as exc:
        return str(exc)
    return ""


@pytest.mark.parametrize("digits", [400, 5000])
def test_json_huge_integer_is_a_message_not_an_overflow(digits):
    data = to_raw(load_preset(PAPER))
    data["motor"]["R_s"] = "@@"
    body = json.dumps(data).replace('"@@"', "9" * digits)
    with pytest.raises(PresetError) as info:
        loads_preset(body, "big.json")
    message = str(info.value)
    assert "motor.R_s" in message and "too large" in message and len(message) <= 300, message


def test_cli_set_reproduction_exits_2_with_one_line():
    value = "motor.R_s=[a#, " + "[" * 10_000 + "]" * 10_000 + "]"
    proc = subprocess.run([sys.executable, "-m", "pmsm_commissioning.app", "derive", PAPER, "--set", value],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") == 1 and "nested too deeply" in proc.stderr and len(proc.stderr) <= 300


@pytest.mark.parametrize("name", [n for n in ATTACKS if ATTACKS[n][2] == "nested too deeply"])
def test_pure_python_yaml_path_refuses_the_same_attacks(name, monkeypatch):
    """Without libyaml the guarded pure-Python scanner refuses the same texts (its own counting)."""
    from pmsm_commissioning.app.io import yaml_text as presets  # the YAML module (moved out of app.io.presets)

    monkeypatch.setattr(presets, "_CLoader", None)
    kind, text, says = ATTACKS[name]
    with pytest.raises(PresetError, match=says):
        _load(kind, text)


def test_anchors_and_aliases_refused_on_both_paths(monkeypatch):
    from pmsm_commissioning.app.io import yaml_text as presets  # the YAML module (moved out of app.io.presets)

    text = "a: &x 1\nb: *x\n"
    with pytest.raises(PresetError, match="anchors/aliases"):
        presets.loads_raw(text, "a.yaml")
    monkeypatch.setattr(presets, "_CLoader", None)
    with pytest.raises(PresetError, match="anchors/aliases"):
        presets.loads_raw(text, "a.yaml")


@pytest.mark.parametrize("value", ["1.5 # note", "\ufeff1.5", "1\n 5", ">\n 1.5", "'1.5'"])
def test_set_value_with_hidden_parts_is_refused(value):
    with pytest.raises(PresetError, match="motor.R_s"):
        load_preset(PAPER, [f"motor.R_s={value}"])
