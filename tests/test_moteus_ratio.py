"""moteus works at the output: ``motor_position.rotor_to_output_ratio`` = 1/N and every output-side value in it.

moteus docs/reference.md: the ratio is "the number of turns of the output for one turn of the rotor";
positions are "rotations of the output shaft", torque "as measured at the output shaft". An 8:1
gearbox is written as 0.125, its position gains ×64, its limits ÷8; read back, the same rotor-side
loop runs the same move.
"""

from __future__ import annotations

import pytest

from pmsm_commissioning.app.cli.export import case
from pmsm_commissioning.app.exports.drives import moteus
from pmsm_commissioning.app.exports.drives.import_drive import import_drive
from pmsm_commissioning.app.exports.drives.stock import stock_settings
from pmsm_commissioning.app.exports.drives.stock_route import file_verdict
from pmsm_commissioning.app.exports.model import export_files
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError

PRESET = "yaskawa_sgm7j_04a"  # its stock route is clean (tests/test_stock_route.py)
N = 8.0
F32 = 2e-7  # the file's 9 significant digits


@pytest.fixture(scope="module")
def geared():
    """The preset with an 8:1 gearbox in front of the same rotor-side load (the physics is unchanged)."""
    return case(load_preset(PRESET, [f"transmission.ratio={N:g}"]), "moteus")


@pytest.fixture(scope="module")
def direct():
    return case(load_preset(PRESET), "moteus")


def _file(cmp) -> str:
    ((_, content),) = export_files("moteus", cmp).items()
    return content.decode("utf-8")


def test_the_ratio_and_the_output_side_values_are_written(geared, direct):
    f, g = moteus.parse_moteus(_file(geared)), moteus.parse_moteus(_file(direct))
    assert f.get("motor_position.rotor_to_output_ratio") == pytest.approx(1.0 / N, rel=F32)
    assert g.get("motor_position.rotor_to_output_ratio") == 1.0
    for key, scale in (("servo.pid_position.kp", N**2), ("servo.pid_position.kd", N**2),
                       ("servo.inertia_feedforward", N**2), ("servo.pid_position.ilimit", N),
                       ("servo.default_velocity_limit", 1.0 / N), ("servo.default_accel_limit", 1.0 / N),
                       ("servo.max_current_A", 1.0), ("servo.pid_dq.kp", 1.0), ("servo.pwm_rate_hz", 1.0)):
        assert f.get(key) == pytest.approx(scale * g.get(key), rel=1e-6), key


def test_read_back_the_same_rotor_side_loop_runs_the_same_move(geared):
    p = geared.derived.params
    tuned = stock_settings(geared, "moteus").tuning
    verdict = file_verdict("moteus", _file(geared), p, geared.derived)
    assert verdict.clean
    for name in ("kp", "kd", "J_ff", "i_lim"):
        assert getattr(verdict.loop, name) == pytest.approx(getattr(tuned.loop, name), rel=1e-6), name
    # the 9-digit file rounds kp·N², v/N …: the move ends within a few of the drive's cycles of the tuned one
    cycles = 5.0 / tuned.loop.f_loop
    assert verdict.run.metrics.in_position_s == pytest.approx(tuned.run.metrics.in_position_s, abs=cycles)
    assert verdict.run.metrics.electrical_in_total_J == pytest.approx(tuned.run.metrics.electrical_in_total_J,
                                                                       rel=1e-3)


def test_a_file_of_another_ratio_is_refused_and_the_import_takes_the_ratio(geared, direct):
    with pytest.raises(ParameterError, match=r"motor_position.rotor_to_output_ratio = 0.125 is not allowed here: "
                                             r"1.0 \(1/transmission.ratio"):
        file_verdict("moteus", _file(geared), direct.derived.params, direct.derived)
    imported = import_drive(_file(geared), "moteus", load_preset(PRESET))
    assert imported.params.transmission.ratio == pytest.approx(N, rel=F32)
    assert any(s.startswith("transmission.ratio = ") for s in imported.imported)
    bad = _file(geared).replace("rotor_to_output_ratio 0.125", "rotor_to_output_ratio -0.125")
    with pytest.raises(ParameterError, match=r"rotor_to_output_ratio = -0.125 is not allowed: allowed > 0"):
        import_drive(bad, "moteus", load_preset(PRESET))
