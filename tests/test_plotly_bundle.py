"""The basic plotly.js bundle the page can send instead of the full one: same version, every trace type drawn."""

from __future__ import annotations

import re
from pathlib import Path

from plotly.offline.offline import get_plotlyjs_version

from pmsm_commissioning.app.figures.fdsmc_comparison import time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_energy import energy_bars_spec, energy_spec, make_table1_figure
from pmsm_commissioning.app.figures.fdsmc_overview import overview_spec
from pmsm_commissioning.app.ui.plotly_js import (
    BUNDLE,
    REACT_JS,
    TRACE_TYPES,
    bundle_source,
    bundle_version,
    use_basic_plotly,
)
from pmsm_commissioning.sim.fdsmc.engine import compare

APP = Path(__file__).resolve().parents[1] / "app"
#: ``fig.add_…`` helpers that add layout items or a prebuilt trace, not a trace type.
LAYOUT_HELPERS = {"figure", "trace", "traces", "vrect", "hrect", "vline", "hline", "shape", "annotation"}


def test_bundle_is_plotlys_basic_bundle_of_the_installed_version():
    """A plotly upgrade must bring the matching basic bundle (else figures could use missing features)."""
    assert bundle_version() == get_plotlyjs_version()
    assert BUNDLE.stat().st_size < 0.3 * (Path(__import__("plotly").__file__).parent
                                          / "package_data" / "plotly.min.js").stat().st_size
    assert (BUNDLE.parent / "plotly-basic.LICENSE").read_text().startswith("MIT License")


def test_every_figure_uses_only_trace_types_of_the_basic_bundle(paper_params):
    c = compare(paper_params)
    specs = [overview_spec(c), time_plots_spec(c), energy_spec(c), energy_bars_spec(c)]
    used = {t.get("type", "scatter") for spec in specs for t in spec["data"]}
    used |= {t.type for t in make_table1_figure([]).data}
    assert used <= TRACE_TYPES
    # and no module builds any other trace: go.<Trace>(…), fig.add_<trace>(…), {"type": "<trace>", "x": …}
    pattern = re.compile(r"go\.([A-Z][a-z]+)\(|fig\.add_([a-z]+)\(|\"type\": \"([a-z0-9]+)\", \"[xy]\":")
    for path in APP.rglob("*.py"):
        for m in pattern.finditer(path.read_text()):
            name = next(g for g in m.groups() if g).lower()
            assert name in TRACE_TYPES | LAYOUT_HELPERS, f"{path.name}: trace type {name!r} not in the basic bundle"


class _Queue:
    def __init__(self) -> None:
        self.messages: list = []

    def queue_message(self, m) -> None:
        self.messages.append(m)


class _Gui:
    def __init__(self) -> None:
        self._websock_interface = _Queue()
        self._setup_plotly_js = False


def test_use_basic_plotly_sends_the_bundle_once_and_stops_viser_sending_the_full_one():
    gui = _Gui()
    use_basic_plotly(gui)
    use_basic_plotly(gui)
    assert len(gui._websock_interface.messages) == 1
    assert gui._websock_interface.messages[0].source == bundle_source() + "\n" + REACT_JS  # with its wrapper
    assert gui._setup_plotly_js is True  # viser's own flag: add_plotly then sends no plotly.min.js
