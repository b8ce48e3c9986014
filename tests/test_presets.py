"""Preset loader: round trip, strictness, unit aliases, and garbage never raising a traceback."""

from __future__ import annotations

import dataclasses
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pmsm_commissioning.app.io import presets
from pmsm_commissioning.app.io.preset_schema import PresetError, parse_preset
from pmsm_commissioning.app.io.presets import dumps_preset, load_preset, loads_preset, to_raw
from pmsm_commissioning.control.common.checks import ParameterError

RAW_OK = dict  # alias for readability


def _raw():
    return to_raw(load_preset("paper_12kw_pmsm"))


def test_paper_preset_values(paper_params):
    m, ld = paper_params.motor, paper_params.load
    assert (m.V_0, m.P_r, m.omega_b, m.Gamma_max, m.psi_pm) == (430.0, 12000.0, 150.0, 40.0, 0.38)
    assert (m.L_d, m.L_q, m.R_s, m.p, m.J_r) == (5.4e-3, 5.4e-3, 0.1, 5, 0.03)
    assert pytest.approx(4 * m.J_r) == ld.J_L
    assert ld.F_v == pytest.approx(0.8 * m.P_r / m.omega_b**2)
    c = paper_params.controller
    assert (c.T_si, c.T_salpha, c.T_so, c.K, c.alpha_max_rule) == (5e-3, 1e-3, 2e-4, 1000.0, "paper")
    assert paper_params.manoeuvre.theta_dem == 60.0


@pytest.mark.parametrize("name", presets.list_presets())
def test_round_trip_every_preset(name, tmp_path):
    p1 = load_preset(name)
    path = tmp_path / "p.yaml"
    presets.save_preset(p1, path)
    p2 = load_preset(str(path))
    assert p1 == p2
    assert loads_preset(dumps_preset(p2)) == p1


def test_unknown_key_did_you_mean():
    raw = _raw()
    raw["motor"]["Ld"] = raw["motor"].pop("L_d")
    with pytest.raises(PresetError, match=r"unknown key motor.Ld — did you mean 'L_d'"):
        parse_preset(raw)


def test_missing_key_and_section():
    raw = _raw()
    del raw["motor"]["R_s"]
    with pytest.raises(PresetError, match="missing key.*R_s"):
        parse_preset(raw)
    raw = _raw()
    del raw["load"]
    with pytest.raises(PresetError, match="missing section 'load'"):
        parse_preset(raw)


def test_wrong_type():
    raw = _raw()
    raw["motor"]["L_d"] = "five"
    with pytest.raises(PresetError, match=r"motor.L_d = 'five' is not a number: allowed decimal or scientific"):
        parse_preset(raw)


@pytest.mark.parametrize(
    ("section", "key", "value", "match"),
    [
        ("motor", "J_r", -0.1, r"motor.J_r = -0.1 .*allowed 1e-09 ≤ value ≤ 10000"),
        ("motor", "R_s", 0.0, r"motor.R_s = 0.0 .*allowed 0 < value ≤ 10000"),
        ("motor", "p", 2.5, r"motor.p = 2.5 .*integer"),
        ("motor", "psi_pm", math.nan, r"motor.psi_pm = nan"),
        ("controller", "T_so", math.inf, r"controller.T_so = inf"),
        ("load", "J_L", -1.0, r"load.J_L = -1.0 .*allowed 0 ≤ value ≤ 10000"),
        ("controller", "alpha_max_rule", "fast", r"alpha_max_rule = 'fast' .*paper, torque_limit"),
        ("controller", "f_s", "fast", r"controller.f_s = 'fast'"),
    ],
)
def test_impossible_values_named(section, key, value, match):
    raw = _raw()
    raw[section][key] = value
    with pytest.raises(ParameterError, match=match):
        parse_preset(raw)


def test_unit_aliases_convert_at_the_edge():
    raw = _raw()
    raw["motor"]["L_d_mH"] = 5.4
    del raw["motor"]["L_d"]
    raw["motor"]["P_r_kW"] = 12
    del raw["motor"]["P_r"]
    raw["motor"]["omega_b_rpm"] = 150 * 60 / (2 * math.pi)
    del raw["motor"]["omega_b"]
    p = parse_preset(raw)
    assert p.motor.L_d == pytest.approx(5.4e-3)
    assert p.motor.P_r == pytest.approx(12000.0)
    assert p.motor.omega_b == pytest.approx(150.0)


def test_si_and_alias_both_given_is_an_error():
    raw = _raw()
    raw["motor"]["L_d_mH"] = 5.4
    with pytest.raises(PresetError, match="more than once"):
        parse_preset(raw)


def test_overrides():
    p = load_preset("paper_12kw_pmsm", ["manoeuvre.T_m=1.4", "controller.f_s=continuous", "motor.L_q_mH=6"])
    assert p.manoeuvre.T_m == 1.4
    assert p.controller.is_continuous
    assert p.motor.L_q == pytest.approx(6e-3)
    with pytest.raises(PresetError, match="malformed"):
        load_preset("paper_12kw_pmsm", ["T_m=1"])


def test_exponent_numbers_without_a_dot_are_numbers():
    """PyYAML (YAML 1.1) reads 2e-4 as text; engineers write it so, the loader takes it as a number."""
    p = load_preset("paper_12kw_pmsm", ["controller.T_so=2e-4", "motor.J_r=3E-2"])
    assert p.controller.T_so == 2e-4 and p.motor.J_r == 0.03
    raw = _raw()
    raw["controller"]["T_so"] = "2e-4"
    assert parse_preset(raw).controller.T_so == 2e-4
    raw["controller"]["T_so"] = "2e-4 s"
    with pytest.raises(PresetError, match=r"controller.T_so = '2e-4 s' is not a number: allowed decimal"):
        parse_preset(raw)


def test_yaml_safety_and_size():
    with pytest.raises(PresetError, match="not valid YAML at line"):
        loads_preset("schema: 1\nmotor: [\n")
    with pytest.raises(PresetError, match="too large"):
        loads_preset("a: " + "x" * (300 * 1024))
    with pytest.raises(PresetError, match="aliases"):
        loads_preset("a: &x [1, 2]\nb: *x\n")
    with pytest.raises(PresetError):
        loads_preset("!!python/object/apply:os.system ['true']")
    with pytest.raises(PresetError, match="schema"):
        loads_preset("schema: 3\n")


def test_load_steps_parse():
    raw = _raw()
    raw["load"]["steps"] = [{"t": 0.5, "Gamma_Le": 3.0}, {"t": 0.8, "Gamma_Le": -1.0}]
    p = parse_preset(raw)
    assert p.load.steps[1].Gamma_Le == -1.0
    assert loads_preset(dumps_preset(p)) == p
    raw["load"]["steps"] = [{"t": 0.8, "Gamma_Le": 3.0}, {"t": 0.5, "Gamma_Le": -1.0}]
    with pytest.raises(ParameterError, match="increasing"):
        parse_preset(raw)


_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(), st.floats(allow_nan=True), st.text(max_size=8)
)
_values = st.recursive(
    _scalars, lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=6), c, max_size=3), max_leaves=8
)


@settings(max_examples=150, deadline=None)
@given(section=st.sampled_from(["motor", "load", "controller", "manoeuvre"]), key=st.text(max_size=10), value=_values)
def test_garbage_in_a_section_gives_clear_error_only(section, key, value):
    raw = _raw()
    raw[section][key] = value
    try:
        parse_preset(raw)
    except ValueError as exc:  # PresetError or ParameterError, with a message
        assert str(exc)


@settings(max_examples=150, deadline=None)
@given(text=st.text(max_size=200))
def test_garbage_text_gives_clear_error_only(text):
    with pytest.raises(ValueError) as info:
        loads_preset(text)
    assert str(info.value)


def test_replace_keeps_validation(paper_params):
    with pytest.raises(ParameterError, match="motor.L_q"):
        dataclasses.replace(paper_params.motor, L_q=-1.0)
