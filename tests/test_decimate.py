"""Min/max decimation of the drawn traces: the band of a chattering signal survives, the ends are the run's."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pmsm_commissioning.app.figures.decimate import BINS_PHASE, BINS_TIME_PLOTS, envelope, minmax_index
from pmsm_commissioning.app.figures.fdsmc_comparison import TIME_ROWS, time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_overview import motor_torque, overview_spec
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.sim.fdsmc.engine import LABELS, compare


def _chatter(n: int = 20_001) -> tuple[np.ndarray, np.ndarray]:
    """A slow ramp with a ±1 switching component every sample (a bang-bang α_dem at f_s)."""
    t = np.linspace(0.0, 0.5, n)
    return t, 10.0 * t + np.where(np.arange(n) % 2 == 0, 1.0, -1.0)


def test_minmax_index_keeps_every_bins_extremes_and_the_ends():
    rng = np.random.default_rng(3)
    y = np.cumsum(rng.normal(size=10_007))
    idx = minmax_index(y, 200)
    assert idx[0] == 0 and idx[-1] == len(y) - 1
    assert np.all(np.diff(idx) > 0)  # strictly increasing: time stays monotone
    assert len(idx) <= 2 * 200 + 2
    # each bin's min and max are among the kept samples
    k = -(-len(y) // 200)
    for b in range(0, 200, 17):
        seg = slice(b * k, min((b + 1) * k, len(y)))
        assert y[seg].max() in y[idx] and y[seg].min() in y[idx]
    assert y[idx].max() == y.max() and y[idx].min() == y.min()


def test_short_signals_are_not_decimated():
    y = np.arange(10.0)
    assert list(minmax_index(y, 4)) == list(range(10))
    axis, out = envelope(np.linspace(0, 1, 10), y, 4)
    assert axis == {"x0": 0.0, "dx": pytest.approx(1 / 9)} and list(out) == list(y)


def test_chatter_band_survives_envelope_where_a_stride_would_lose_it():
    t, y = _chatter()
    axis, out = envelope(t, y, 300)
    assert 2 * 290 + 2 <= len(out) <= 2 * 300 + 2
    assert out[0] == y[0] and out[-1] == y[-1]  # the drawn endpoints are the run's
    assert axis["x0"] == t[0] and axis["x0"] + axis["dx"] * (len(out) - 1) == pytest.approx(t[-1])
    # the ±1 switching is drawn as a band 2 wide all along: in every bin the top and bottom samples
    pairs = out[1:-1].reshape(-1, 2)
    assert np.all(np.ptp(pairs, axis=1) >= 2.0 - 1e-9)
    # a stride of the same size would alias the switching away (every kept sample has one sign)
    stride = y[:: -(-len(y) // 602)]
    assert np.ptp(stride - 10.0 * t[:: -(-len(y) // 602)]) < 1e-9


def test_phase_trajectory_keeps_the_chatter_band_of_omega():
    t, w = _chatter(30_001)
    idx = minmax_index(w, BINS_PHASE)
    assert len(idx) <= 2 * BINS_PHASE + 2 and idx[0] == 0 and idx[-1] == len(w) - 1
    assert w[idx].max() == w.max() and w[idx].min() == w.min()
    # every bin of the drawn curve still spans the ±1 switching (a band, not a line)
    assert np.all(np.abs(np.diff(w[idx[1:-1]]))[::2] >= 2.0 - 1e-9)


@pytest.fixture(scope="module")
def comparison(paper_params):
    return compare(paper_params)


def test_drawn_time_plots_span_the_runs_range_and_end_at_its_ends(comparison):
    """Every drawn trace of the time plots covers exactly the run's min..max and starts/ends at its samples."""
    spec = json.loads(figure_json(time_plots_spec(comparison)))
    traces = {t["name"]: t for t in spec["data"]}
    for key in ("fdsmc", "conventional"):
        tr = getattr(comparison, key).trace
        for _, _, signals in TIME_ROWS:
            for attr, label, _ in signals:
                d = traces[f"{label} {LABELS[key]}"]
                y = np.frombuffer(__import__("base64").b64decode(d["y"]["bdata"]), dtype=np.float32)
                full = np.asarray(getattr(tr, attr), dtype=np.float32)
                assert len(y) <= 2 * BINS_TIME_PLOTS + 2
                assert y.max() == full.max() and y.min() == full.min(), (key, attr)
                assert y[0] == full[0] and y[-1] == full[-1]
                assert d["x0"] == pytest.approx(tr.t[0]) and d["x0"] + d["dx"] * (len(y) - 1) == pytest.approx(tr.t[-1])


def test_overview_torque_row_keeps_the_peak_torque(comparison):
    """The compact Γ row draws the run's peak motor torque of eq. (5), however it is decimated."""
    spec = overview_spec(comparison)
    tr, motor = comparison.fdsmc.trace, comparison.derived.params.motor
    gamma = motor_torque(motor, tr.i_d, tr.i_q)
    drawn = next(t for t in spec["data"] if t["name"] == "Γ FDSMC")["y"]
    assert float(np.max(drawn)) == pytest.approx(float(gamma.max()), rel=1e-6)
    assert float(np.min(drawn)) == pytest.approx(float(gamma.min()), rel=1e-6)
