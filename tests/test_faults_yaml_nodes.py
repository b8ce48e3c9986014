"""Wide YAML: the node limit bounds the parse on both paths, libyaml's and the pure-Python fallback.

The fallback is the only parser where PyYAML lacks libyaml; without a limit a 20 000-key mapping
cost it ≈ 0.7 s. Timings are printed by ``scripts/bench_hostile.py --pure`` (not asserted here).
"""

from __future__ import annotations

import numpy as np
import pytest

from pmsm_commissioning.app.io import yaml_text
from pmsm_commissioning.app.io.bldc_emf import parse_yaml
from pmsm_commissioning.app.io.presets import PresetError, loads_preset
from pmsm_commissioning.control.bldc.params import EMF_SAMPLES_MAX


@pytest.fixture(params=["libyaml", "pure"])
def path(request, monkeypatch) -> list[str]:
    """Run the test on one parser path; returns the origins the pure-Python loader was built for."""
    built: list[str] = []
    if request.param == "pure":
        real = yaml_text._loader
        monkeypatch.setattr(yaml_text, "_CLoader", None)
        monkeypatch.setattr(yaml_text, "_loader", lambda origin, n: built.append(origin) or real(origin, n))
    elif yaml_text._CLoader is None:
        pytest.fail("PyYAML here lacks libyaml: the libyaml path cannot be tested")
    return built


def _flow_list(items: int) -> str:
    """A mapping of one key holding a flow list: 3 + items nodes."""
    return "k: [" + "1," * (items - 1) + "1]\n"


def test_the_limit_is_exact_on_both_paths(path):
    n = yaml_text.MAX_NODES - 3
    assert len(yaml_text.loads_raw(_flow_list(n), "wide.yaml")["k"]) == n
    with pytest.raises(PresetError, match=f"wide.yaml has too many values at line 1, column .*: allowed ≤ "
                                          f"{yaml_text.MAX_NODES} YAML nodes"):
        yaml_text.loads_raw(_flow_list(n + 1), "wide.yaml")
    assert path in ([], ["wide.yaml", "wide.yaml"])  # the pure loader ran on the pure path


def test_the_issue_s_20000_key_mapping_is_refused_in_one_line_naming_the_line(path):
    text = "".join(f"k{i}: 1\n" for i in range(20_000))
    with pytest.raises(PresetError) as info:
        loads_preset(text, "attack.yaml")
    message = str(info.value)
    limit_line = yaml_text.MAX_NODES // 2  # a key and its value per line
    assert message.startswith(f"attack.yaml has too many values at line {limit_line},")
    assert "\n" not in message and len(message) <= 300
    assert path in ([], ["attack.yaml"])


def test_a_full_measured_emf_table_still_loads_on_both_paths(path):
    theta = np.arange(EMF_SAMPLES_MAX) * 360.0 / EMF_SAMPLES_MAX
    rows = "".join(f"- [{t:.6g}, {np.sin(np.radians(t)):.6g}, 0.1, -0.1]\n" for t in theta)
    th, values = parse_yaml(rows)
    assert th.shape == (EMF_SAMPLES_MAX,) and values.shape == (EMF_SAMPLES_MAX, 3)
    assert values[EMF_SAMPLES_MAX // 4, 0] == pytest.approx(1.0)
    assert path in ([], ["emf waveform"])
