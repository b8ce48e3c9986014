"""Every control law the kernel inlines is the one in ``control/``: compiled == Python on random inputs."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from pmsm_commissioning.control.fdsmc import conventional, fdc, sliding_mode

finite = st.floats(-1e3, 1e3, allow_nan=False)
positive = st.floats(1e-3, 1e3, allow_nan=False)
LAWS = {
    "smc_demand": (sliding_mode.smc_demand, 6),
    "conventional_demand": (conventional.conventional_demand, 5),
    "fdc_voltages": (fdc.fdc_voltages, 18),
}
_COMPILED = {name: njit(fn) for name, (fn, _) in LAWS.items()}


def _close(a: object, b: object) -> bool:
    xs, ys = np.atleast_1d(np.asarray(a, float)), np.atleast_1d(np.asarray(b, float))
    return bool(np.allclose(xs, ys, rtol=1e-12, atol=1e-12))


@settings(max_examples=200, deadline=None)
@given(th=finite, w=finite, wp=positive, Tc=positive, K=positive, a=positive)
def test_sliding_mode_law_compiled_equals_python(th, w, wp, Tc, K, a):
    assert _close(_COMPILED["smc_demand"](th, w, wp, Tc, K, a), sliding_mode.smc_demand(th, w, wp, Tc, K, a))


@settings(max_examples=200, deadline=None)
@given(st.lists(finite, min_size=5, max_size=5))
def test_conventional_law_compiled_equals_python(x):
    assert _close(_COMPILED["conventional_demand"](*x), conventional.conventional_demand(*x))


@settings(max_examples=200, deadline=None)
@given(st.lists(finite, min_size=6, max_size=6), st.lists(positive, min_size=12, max_size=12))
def test_fdc_law_compiled_equals_python(signals, coeffs):
    args = (*signals, *coeffs)
    py = fdc.fdc_voltages(*args)
    assert all(math.isfinite(v) for v in py)
    assert _close(_COMPILED["fdc_voltages"](*args), py)


def test_kernel_source_holds_no_copy_of_the_laws():
    # The kernel calls the control/ laws; it must not spell their formulas out again.
    from pathlib import Path

    src = (Path(__file__).resolve().parents[1] / "sim" / "fdsmc" / "kernel.py").read_text()
    for formula in ("3.0 / prm[P_TSA]", "prm[P_G1] * (prm[P_THDEM]", "min(1.0, max(-1.0"):
        assert formula not in src
    for call in ("sliding_mode.smc_demand(", "conventional.conventional_demand(", "fdc.fdc_voltages("):
        assert call in src
