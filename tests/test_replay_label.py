"""The replay's time label stands above the FDSMC marker, right of it, and left of it near the phase
plane's right edge (where a label on the right was cut at the end of a replay).
"""

from __future__ import annotations

import json

import pytest

from pmsm_commissioning.app.figures.fdsmc_comparison import phase_plane_extent
from pmsm_commissioning.app.figures.fdsmc_overview import overview_spec
from pmsm_commissioning.app.figures.fdsmc_replay import (
    LABEL_LEFT_SHARE,
    ScrubTargets,
    label_sides,
    replay_layout,
    scrub_update,
)
from pmsm_commissioning.app.io.presets import PAPER_PRESET, load_preset
from pmsm_commissioning.sim.fdsmc.engine import compare


@pytest.fixture(scope="module")
def comparison():
    return compare(load_preset(PAPER_PRESET), ("fdsmc", "conventional"))


def test_the_label_goes_left_of_the_marker_only_near_the_right_edge(comparison):
    lo, hi = phase_plane_extent(comparison)
    edge = hi - LABEL_LEFT_SHARE * (hi - lo)
    assert label_sides(comparison, [lo, edge - 1e-9, edge + 1e-6, hi]) == ["top right"] * 2 + ["top left"] * 2


def test_frames_and_scrub_put_the_label_on_its_side(comparison):
    spec = overview_spec(comparison)
    targets = ScrubTargets.of(spec["data"])
    layout, raw = replay_layout(comparison, spec["data"], targets)
    for placeholder in raw:
        frames = json.loads(raw[placeholder])
        first, last = frames[0]["data"][0], frames[-1]["data"][0]
        assert first["textposition"] == label_sides(comparison, first["x"]) == ["top right"]  # the start: left
        assert last["textposition"] == label_sides(comparison, last["x"]) == ["top left"]  # the end: θ_re ≈ 0
        assert all("textposition" not in f["data"][1] for f in frames)  # the other markers carry no label
    t_end = float(comparison.fdsmc.trace.t[-1])
    update, _ = scrub_update(comparison, targets, t_end)
    assert update["textposition"][0] == ["top left"] and len(update["textposition"]) == len(update["text"])
    assert scrub_update(comparison, targets, 0.0)[0]["textposition"][0] == ["top right"]
