"""Unit conversions at the edge, each against a hand calculation."""

from __future__ import annotations

import math

import pytest

from pmsm_commissioning.app.io import units


def test_rpm():
    # 1500 rpm = 1500·2π/60 = 157.0796 rad/s
    assert units.rpm_to_rad_s(1500) == pytest.approx(157.07963, rel=1e-6)
    assert units.rad_s_to_rpm(units.rpm_to_rad_s(1234.5)) == pytest.approx(1234.5)


def test_mH_kW_ms_kHz_deg():
    assert units.mH_to_H(5.4) == pytest.approx(0.0054)
    assert units.kW_to_W(12) == 12000.0
    assert units.ms_to_s(0.2) == pytest.approx(2e-4)
    assert units.kHz_to_Hz(20) == 20000.0
    assert units.deg_to_rad(180) == pytest.approx(math.pi)
    assert units.rev_to_rad(1) == pytest.approx(2 * math.pi)


def test_ke_to_psi_pm_hand_calculation():
    # Paper motor: Ψ = 0.38 Wb, p = 5. At 1000 rpm ω_m = 104.72 rad/s, ω_e = 523.6 rad/s,
    # phase peak = 523.6·0.38 = 198.97 V, line-line RMS = 198.97·√3/√2 = 243.69 V → Ke = 243.69 V/krpm
    ke = 523.5988 * 0.38 * math.sqrt(3) / math.sqrt(2)
    assert ke == pytest.approx(243.69, abs=0.01)
    assert units.ke_vrms_krpm_to_psi_pm(ke, 5) == pytest.approx(0.38, rel=1e-6)


def test_ke_in_preset(paper_params):
    from pmsm_commissioning.app.io.preset_schema import parse_preset
    from pmsm_commissioning.app.io.presets import to_raw

    raw = to_raw(paper_params)
    del raw["motor"]["psi_pm"]
    raw["motor"]["Ke_Vrms_krpm"] = 243.6848  # 0.38·5·104.72·√1.5
    assert parse_preset(raw).motor.psi_pm == pytest.approx(0.38, rel=1e-5)
