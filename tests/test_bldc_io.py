"""BLDC parameters, preset and measured back-EMF input: clear messages for bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmsm_commissioning.app.io.bldc_emf import read_measured, with_measured
from pmsm_commissioning.app.io.preset_schema import PresetError
from pmsm_commissioning.app.io.presets import dumps_preset, load_preset, loads_preset
from pmsm_commissioning.app.io.units import rad_s_to_rpm
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.bldc import emf as bldc_emf
from pmsm_commissioning.sim.bldc.engine import simulate_bldc


def _csv(theta_deg, cols, header="theta_e_deg,phi_a,phi_b,phi_c"):
    lines = [header] + [",".join(f"{v:.9g}" for v in (t, *c)) for t, c in zip(theta_deg, cols, strict=True)]
    return "\n".join(lines)


def _three_phase(n=180, end=False):
    tab = bldc_emf.distorted_table(0.12)
    th = np.linspace(0, 360, n + 1 if end else n, endpoint=end)
    vals = bldc_emf.table_phases(tab, np.radians(th)).T
    return th, vals


def test_preset_loads_with_table1_values_and_round_trips():
    p = load_preset("bldc_smc_paper")
    assert (p.machine.R_s, p.machine.L_s_minus_M_s, p.machine.n_pp, p.machine.Phi_m) == (2.3, 0.0125, 3, 0.12)
    assert (p.mechanics.J, p.mechanics.B) == (0.0042, 0.003032)
    assert p.case.omega_ref == pytest.approx(1000 * math.pi / 30)
    assert loads_preset(dumps_preset(p)) == p
    q = load_preset("bldc_smc_paper", ["machine.L_s_minus_M_s_mH=10", "scenario.active=2000rpm"])
    assert q.machine.L_s_minus_M_s == pytest.approx(0.010) and q.case.omega_0 == pytest.approx(1000 * math.pi / 30)


@pytest.mark.parametrize("override, words", [
    ("machine.n_pp=2.5", ["machine.n_pp", "2.5", "integer"]),
    ("machine.emf=square", ["machine.emf", "square", "ideal"]),
    ("inverter.V_dc=0", ["inverter.V_dc", "allowed"]),
    ("gains.T_max=.nan", ["gains.T_max", "allowed"]),
    ("scenario.active=9rpm", ["scenario.active", "1000rpm"]),
    ("machine.emf=measured", ["machine.emf_samples", "0 samples"]),
])
def test_bad_parameters_name_field_value_range(override, words):
    with pytest.raises((ParameterError, PresetError)) as exc:
        load_preset("bldc_smc_paper", [override])
    for w in words:
        assert w in str(exc.value)


def test_measured_csv_with_three_phases_and_header_round_trips():
    """A measured file made from the built-in distorted waveform gives the same table and
    the same simulation as the built-in example (resampling is faithful).
    """
    th, vals = _three_phase()
    m = read_measured(_csv(th, vals))
    assert m.n_phases == 3 and m.shifts_deg == pytest.approx((120.0, 240.0), abs=0.5)
    assert abs(m.offset_deg) < 1.0
    ref = bldc_emf.periodic_resample(bldc_emf.distorted_table(0.12), m.samples.size)
    assert np.max(np.abs(m.samples - ref)) < 2e-3 * 0.12
    p = load_preset("bldc_smc_paper")
    a = simulate_bldc(with_measured(p, m)).metrics
    b = simulate_bldc(p).metrics
    assert rad_s_to_rpm(a.speed_error_ss_rad_s) < 0.5
    assert a.torque_ripple_pct == pytest.approx(b.torque_ripple_pct, rel=0.1)


def test_measured_yaml_list_of_numbers():
    vals = bldc_emf.ideal_table(0.12, 72)
    m = read_measured("[" + ", ".join(f"{v:.12g}" for v in vals) + "]", "emf.yaml")
    assert m.n_phases == 1
    assert np.allclose(m.samples, bldc_emf.ideal_table(0.12, m.samples.size), atol=1e-9)


def test_wrong_period_is_rejected():
    th, vals = _three_phase()
    with pytest.raises(ParameterError, match=r"spans .*one electrical period is 360°"):
        read_measured(_csv(th / 2.0, vals))  # 0 … 179°: half a period


def test_waveform_that_does_not_join_up_is_rejected():
    th, vals = _three_phase(end=True)
    vals = vals.copy()
    vals[-1] += 0.05
    with pytest.raises(ParameterError, match="does not join up"):
        read_measured(_csv(th, vals))


def test_nan_row_is_rejected():
    th, vals = _three_phase()
    vals = vals.copy()
    vals[17, 1] = np.nan
    with pytest.raises(ParameterError, match=r"row 19, column 3: 'nan' is not a number"):  # line 1: header
        read_measured(_csv(th, vals))


def test_non_numeric_row_is_rejected():
    th, vals = _three_phase()
    text = _csv(th, vals).splitlines()
    text[10] = "50.0,0.1,abc,0.2"
    with pytest.raises(ParameterError, match=r"row 11, column 3: 'abc' is not a number"):
        read_measured("\n".join(text))


def test_wrong_phase_shift_is_rejected():
    th, vals = _three_phase()
    swapped = vals[:, [0, 2, 1]]
    with pytest.raises(ParameterError, match=r"phase b lags phase a by 240.0°: allowed 120°"):
        read_measured(_csv(th, swapped))


def test_too_few_rows_and_ragged_rows_are_rejected():
    with pytest.raises(ParameterError, match="rows: allowed ≥"):
        read_measured("0,0\n90,1\n180,0\n270,-1\n")
    with pytest.raises(ParameterError, match="columns"):
        read_measured("0,0\n90,1,2\n")
