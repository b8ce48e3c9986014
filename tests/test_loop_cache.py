"""The loop-analysis caches return exactly what a fresh computation gives.

The searches of :mod:`control.fdsmc.loop_analysis` and the overshoot η of
:mod:`control.fdsmc.transient` are cached on the numbers the loop is built from
(:func:`~control.fdsmc.loop_model.law_case`, :meth:`~control.fdsmc.loop_model.LoopCase.model`).
A key that left out a number the search reads would hand one case another's verdict; these tests
change each number the key drops and check the uncached result does not move, and check that
cached and fresh results are equal to the last bit.
"""

from __future__ import annotations

import dataclasses

import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc import loop_analysis as la
from pmsm_commissioning.control.fdsmc import loop_model as lm
from pmsm_commissioning.control.fdsmc import transient
from pmsm_commissioning.control.fdsmc.derivations import derive


def _case(*overrides: str):
    return derive(load_preset("siemens_1ft7044_ak7", list(overrides))).loop


@pytest.mark.parametrize("law", la.LAWS)
def test_numbers_the_key_drops_do_not_change_the_search(law):
    d = _case()
    fresh = la._gain_limit.__wrapped__
    f_s = d.f_s
    base = fresh(d, law, f_s, d.delay)
    dropped = {"T_si": 1e-3, "T_so": 7e-3, "K": 123.0, "f_s": 1.0, "delay": 1}
    if law != "slope":
        dropped |= {"T_c": 0.123}
    if law != "conventional":
        dropped |= {"g1": 5.0, "g2": 7.0}
    for name, value in dropped.items():
        assert fresh(dataclasses.replace(d, **{name: value}), law, f_s, d.delay) == base, name


def test_minimum_sample_rate_ignores_what_its_key_drops():
    d = _case()
    fresh = la._minimum_sample_rate.__wrapped__
    base = fresh(d, d.delay)
    for name, value in {"alpha_max": 1.0, "T_c": 0.5, "K": 9.0, "T_si": 1e-3, "f_s": 1.0}.items():
        assert fresh(dataclasses.replace(d, **{name: value}), d.delay) == base, name
    # …and the key keeps what it reads: the conventional gains of eq. (61) in [1] enter the loop
    assert lm.law_case(dataclasses.replace(d, g1=2 * d.g1), "conventional") != lm.law_case(d, "conventional")


def test_cached_verdicts_equal_fresh_ones_bit_for_bit():
    """Derive one case, then a second that differs in T_m and K only, then the first again."""
    la._gain_limit.cache_clear()
    la._minimum_sample_rate.cache_clear()
    transient._acceleration_overshoot.cache_clear()
    first = derive(load_preset("siemens_1ft7044_ak7"))
    derive(load_preset("siemens_1ft7044_ak7", ["manoeuvre.T_m=0.8", "controller.K=0.01"]))
    again = derive(load_preset("siemens_1ft7044_ak7"))
    assert la._gain_limit.cache_info().hits > 0
    assert again.gain == first.gain and again.sample_rate == first.sample_rate and again.alpha == first.alpha
    d = first.loop
    for law in la.LAWS:
        assert la.gain_limit(d, law, d.f_s, d.delay) == la._gain_limit.__wrapped__(d, law, d.f_s, d.delay)
    lm = d.model()
    assert transient.acceleration_overshoot(d, d.f_s, d.delay) == transient._acceleration_overshoot.__wrapped__(
        lm, d.f_s, d.delay)


def test_a_different_drive_is_a_different_key():
    """J_L enters every law (eq. (4b) in [1]): a new load inertia must not reuse the old verdict."""
    a, b = _case(), _case("load.J_L=1e-3")
    for law in la.LAWS:
        assert lm.law_case(a, law) != lm.law_case(b, law)
    assert a.model() != b.model()
