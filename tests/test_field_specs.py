"""One source per field: every input field of both modes shows the same unit and range everywhere.

Each parameter field's SI unit, allowed range, label, display unit and loader units are declared
once (its ``FieldSpec``). This test walks every field of both modes' parameter dataclasses and
checks, from the spec alone, that the validation message, the preset loader (SI key and every
unit-suffixed key), the page's input fields (label, unit, range hint) and the exports (``units``
section, YAML comments, C header) agree with it.
"""

from __future__ import annotations

import copy
import dataclasses
import re
import typing

import pytest

from pmsm_commissioning.app.exports.firmware.module import INPUT_KEYS, c_unit, controller_header
from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.io.presets import (
    SCHEMA,
    annotate_units,
    dumps_preset,
    load_preset,
    loads_raw,
    parse_preset,
    to_raw,
)
from pmsm_commissioning.app.ui import bldc_tab as bldc_tab
from pmsm_commissioning.app.ui import inputs
from pmsm_commissioning.control.bldc.params import BldcParams
from pmsm_commissioning.control.common.checks import FieldSpec, ParameterError, field_specs
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams

POSITION, BLDC = "paper_12kw_pmsm", "bldc_smc_paper"


def _raw(preset: str) -> dict:
    """A preset's raw mapping with at least one item in every list section."""
    raw = to_raw(load_preset(preset))
    if "load" in raw and not raw["load"]["steps"]:
        raw["load"]["steps"] = [{"t": 0.1, "Gamma_Le": 1.0}]
    return raw


def _cases() -> list[tuple[str, str, str, FieldSpec]]:
    """(preset, section path, field, spec) of every spec'd field of both modes."""
    out = []
    for preset, cls in ((POSITION, DriveParams), (BLDC, BldcParams)):
        for path, tp in units.sections(cls):
            out += [(preset, path, name, spec) for name, spec in field_specs(tp).items()]
    return out


CASES = _cases()
IDS = [f"{path}.{name}" for _, path, name, _ in CASES]


def _section(raw: dict, path: str) -> dict:
    """The mapping of section ``path`` in a raw preset (the first item of a list section)."""
    node: typing.Any = raw
    for part in path.split("."):
        node = node[part]
        if isinstance(node, list):
            node = node[0]
    return node


def _outside(spec: FieldSpec) -> list[float]:
    """SI values just outside the allowed range (each bound that exists)."""
    out = []
    if spec.high is not None:
        out.append(spec.high + max(1.0, abs(spec.high)))
    if spec.low is not None:
        out.append(spec.low if spec.low_open else spec.low - max(1.0, abs(spec.low)))
    return out


def test_every_number_field_has_a_spec():
    """A float or int field without a spec would have no range, unit or label anywhere."""
    for cls in (DriveParams, BldcParams):
        for path, tp in units.sections(cls):
            hints = typing.get_type_hints(tp)
            for f in dataclasses.fields(tp):
                numeric = hints[f.name] in (float, int) or float in typing.get_args(hints[f.name])
                assert not numeric or f.name in field_specs(tp), f"{path}.{f.name} has no FieldSpec"


@pytest.mark.parametrize(("preset", "path", "name", "spec"), CASES, ids=IDS)
def test_validation_and_loader_name_field_value_and_spec_range(preset, path, name, spec):
    for bad in _outside(spec):
        raw = _raw(preset)
        sampled = isinstance(_section(raw, path)[name], list)  # a sampled curve: every sample checked
        _section(raw, path)[name] = [bad] if sampled else bad
        with pytest.raises(ParameterError) as exc:
            parse_preset(raw)
        message = str(exc.value)
        assert f"{path}.{name}" in message and spec.range_text() in message, message
    far = [spec.high + max(1.0, abs(spec.high))] if spec.high is not None else []
    far += [spec.low - max(1.0, abs(spec.low))] if spec.low is not None else []
    for bad in far:  # the same value written with a unit suffix: the same SI range in the message
        for unit in spec.loader_units:
            raw = _raw(preset)
            section = _section(raw, path)
            del section[name]
            section[units.alias_key(name, unit)] = units.from_si(bad, unit)
            with pytest.raises(ParameterError, match=re.escape(spec.range_text())):
                parse_preset(raw)


@pytest.mark.parametrize(("preset", "path", "name", "spec"), CASES, ids=IDS)
def test_loader_unit_keys_convert_to_the_si_value(preset, path, name, spec):
    raw = _raw(preset)
    si = _section(raw, path)[name]
    if isinstance(si, str):  # a keyword (T_c = 'T_a'): take a value inside the range
        si = spec.high / 2.0
    for unit in spec.loader_units:
        raw = _raw(preset)
        section = _section(raw, path)
        del section[name]
        section[units.alias_key(name, unit)] = units.from_si(si, unit)
        loaded = parse_preset(raw)
        node: typing.Any = loaded
        for part in path.split("."):
            node = getattr(node, part)
            node = node[0] if isinstance(node, tuple) else node
        assert getattr(node, name) == pytest.approx(si, rel=1e-12)
        assert units.alias_key(name, unit) in units.ALIASES[path]


def _hint_bounds(hint: str) -> tuple[float | None, float | None, str]:
    """(low, high, unit) read back from a range hint such as ``allowed 1e-06 ≤ value ≤ 10000 mH``."""
    m = re.fullmatch(r"allowed (?:an integer )?(\S+) (?:[<≤…]) (?:value ≤ )?(\S+) ?(.*)", hint)
    if m:
        return float(m.group(1)), float(m.group(2)), m.group(3)
    m = re.fullmatch(r"allowed ([>≥]) (\S+) ?(.*)", hint)
    assert m, hint
    return float(m.group(2)), None, m.group(3)


def _check_hint(hint: str, spec: FieldSpec, unit: str, to_si: typing.Callable[[float], float]) -> None:
    low, high, shown = _hint_bounds(hint)
    assert shown == ("" if unit == "-" else unit), (hint, unit)
    if low is not None and high is not None and to_si(low) > to_si(high):  # a decreasing unit (ω_c = 3/T_si)
        low, high = high, low
    for got, want in ((low, spec.low), (high, spec.high)):
        assert (got is None) == (want is None), hint
        if got is not None:
            assert to_si(got) == pytest.approx(want, rel=1e-5, abs=1e-300), hint


PAGE_POSITION = [*inputs.FIELDS, inputs.T_C, inputs.F_S]


@pytest.mark.parametrize("field", PAGE_POSITION, ids=[f.key for f in PAGE_POSITION])
def test_position_page_field_shows_spec_label_unit_and_range(field):
    spec = units.spec_of(field.key)
    p = load_preset(POSITION).motor.p
    choice = inputs.UNIT_GROUPS[field.group][0] if field.group else None
    text = field.text(choice)
    if field.group == "flux":  # Ψ_PM [Wb] by default; Ke/Kt are pole-pair dependent alternatives
        assert text == f"{spec.label} [{spec.unit}]"
        unit = spec.unit
    else:
        unit = field.unit_of(choice)
        assert text == f"{spec.label} [{unit}]" and unit.startswith(spec.shown_unit)
    to_si = (lambda x: choice.to_si(x, p)) if choice else (lambda x: units.to_si(x, spec.shown_unit))
    _check_hint(field.hint(choice, p), spec, unit, to_si)
    for alt in inputs.UNIT_GROUPS.get(field.group or "", ())[1:]:  # every other unit choice: same SI range
        named = "[" in alt.label  # a quantity of its own (Kt [N·m/A peak], ω_c [Hz]) names the field
        shown = alt.label.partition("[")[2].rstrip("]") if named else field.unit_of(alt)
        assert field.text(alt) == (alt.label if named else f"{spec.label} [{shown}]")
        _check_hint(field.hint(alt, p), spec, shown, lambda x, u=alt: u.to_si(x, p))


def test_position_page_covers_every_top_level_number_field():
    on_page = {f.key for f in PAGE_POSITION} | {"controller.delay_samples"}  # delay: a dropdown
    spec_keys = {f"{sec}.{n}" for sec in ("motor", "load", "controller", "sensors", "limits", "manoeuvre",
                                           "transmission")
                 for n in field_specs(units.SECTION_CLASSES[sec])}
    assert spec_keys == on_page
    spec = units.spec_of("controller.delay_samples")
    assert tuple(str(k) for k in range(int(spec.low), int(spec.high) + 1)) == inputs.DELAYS


@pytest.mark.parametrize("key", bldc_tab.FIELDS + bldc_tab.SCENARIO_FIELDS)
def test_bldc_page_field_shows_spec_label_unit_and_range(key):
    spec = units.spec_of(key)
    assert bldc_tab.field_label(key) == f"{spec.label} [{spec.shown_unit}]"
    _check_hint(units.shown_range(spec), spec, spec.shown_unit, lambda x: units.to_si(x, spec.shown_unit))


@pytest.mark.parametrize(("preset", "cls"), [(POSITION, DriveParams), (BLDC, BldcParams)])
def test_exported_units_and_yaml_comments_follow_the_specs(preset, cls):
    params = parse_preset(_raw(preset))
    text = annotate_units(dumps_preset(params))
    assert parse_preset(loads_raw(text)) == params  # the comments change nothing on import
    for path, tp in units.sections(cls):
        for name, spec in field_specs(tp).items():
            if "." not in path:
                assert units.SI_UNITS[path][name] == spec.unit_text
            if isinstance(_section(to_raw(params), path)[name], list):
                continue
            comment = rf"^ *(- )?{name}: .*  # \[{re.escape(spec.unit_text)}\] {re.escape(spec.range_text())}$"
            assert re.search(comment, text, flags=re.M), (path, name, comment)


def test_c_header_constants_carry_the_input_units_and_ranges():
    params = load_preset(POSITION)
    header = controller_header(params, derive(params), SCHEMA)
    for name, key in INPUT_KEYS.items():
        spec = units.spec_of(key)
        line = next(ln for ln in header.splitlines() if ln.startswith(f"#define FDSMC_{name} "))
        assert f"/* [{c_unit(spec.unit)}]" in line and f"; {c_unit(spec.range_text())} */" in line, line
        assert line.isascii(), line


def test_messages_of_list_sections_name_their_dotted_path():
    raw = _raw(BLDC)
    bad = copy.deepcopy(raw)
    _section(bad, "scenario.cases")["t_window"] = 0.0
    with pytest.raises(ParameterError, match=r"scenario\.cases\.t_window = 0\.0 s is out of range: allowed 0 < value"):
        parse_preset(bad)


@pytest.mark.parametrize(("group", "key"), [("inertia", "motor.J_r"), ("angle", "manoeuvre.theta_dem"),
                                            ("resistance", "motor.L_d"), ("flux", "motor.psi_pm")])
def test_unit_choice_relabels_and_rehints_the_field_and_keeps_the_si_value(gui, group, key):
    params = load_preset(POSITION)
    panel = inputs.InputsPanel(gui, params)
    field = next(f for f in inputs.FIELDS if f.key == key)
    spec = units.spec_of(key)
    for choice in inputs.UNIT_GROUPS[group]:
        panel.selectors[group].value = choice.label
        panel._unit_changed(group)
        shown = panel.numbers[key]
        unit = panel._unit(field)
        assert shown.label == field.text(unit) and spec.label in shown.label or group == "flux"
        assert shown.hint == field.hint(unit, params.motor.p)
        _check_hint(shown.hint, spec, _hint_bounds(shown.hint)[2] or "-",
                    lambda x, u=unit: u.to_si(x, params.motor.p))
        assert panel.collect() == params  # an untouched value survives every unit change exactly
