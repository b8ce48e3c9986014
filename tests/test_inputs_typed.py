"""The position tab's inputs build the parameter dataclasses directly (no preset-file round trip),
with the loader's results and messages: every shipped position preset comes back equal, and an
out-of-range or unknown value is refused with the message a preset file with that value gets.
"""

from __future__ import annotations

import pytest

from pmsm_commissioning.app.io.preset_schema import parse_preset
from pmsm_commissioning.app.io.presets import list_presets_of, load, to_raw
from pmsm_commissioning.app.ui.inputs import FIELDS, InputError, InputsPanel, _with_label


@pytest.mark.parametrize("name", list_presets_of("position"))
def test_untouched_inputs_give_back_the_preset(gui, name):
    params = load(name, mode="position")
    panel = InputsPanel(gui, params)
    panel.populate(params)
    assert panel.collect() == params == parse_preset(to_raw(params))


@pytest.mark.parametrize(("key", "typed", "si"), [("motor.p", "0", 0), ("manoeuvre.T_m", "-1", -1.0),
                                                  ("controller.K", "0", 0.0), ("load.F_v", "-5", -5.0)])
def test_a_refused_value_has_the_loaders_message(gui, key, typed, si):
    params = load("paper_12kw_pmsm", mode="position")
    panel = InputsPanel(gui, params)
    panel.populate(params)
    panel.numbers[key].handle.value = typed
    with pytest.raises(InputError) as page:
        panel.collect()
    raw = to_raw(params)
    section, name = key.split(".")
    raw[section][name] = si
    with pytest.raises(ValueError) as loader:
        parse_preset(raw)
    assert str(page.value) == _with_label(str(loader.value))
    assert any(str(page.value).startswith(f"{dict_label} › ") for dict_label in
               {"Motor nameplate", "Load", "Inverter and controller", "Manoeuvre"})
    assert key in {f.key for f in FIELDS}
