"""The generated C controller runs in closed loop against the simulator's plant and reproduces the
simulator's digital mode, sensors included: what the drive will run is what was simulated.

The module is compiled with the system C compiler and loaded with :mod:`ctypes` (app/exports/firmware/verify.py):
called sample by sample between RK4 steps of :class:`sim.fdsmc.plant.PlantInTheLoop`, it reads what the
simulator's controller reads (encoder counts, noisy ADC currents). The double build is the simulator's
arithmetic operation for operation, so the closed loop is bit-identical even though a quantized encoder
makes the loop chaotic (a 1e-16 difference would flip a count and grow). The float32 build cannot be
bit-identical: on the same readings (golden vectors) its voltages agree to ≤ 3e-5 of the peak, and in
closed loop its trajectory is an equally valid one a few count flips away (θ_r ≤ 1e-4 of its peak,
friction energy ≤ 1e-4, net electrical ≤ 5e-3; i_q by a count's effect, ≤ 3e-2 of its peak).
"""

from __future__ import annotations

import ctypes
import dataclasses
import subprocess
from pathlib import Path

import pytest

from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.firmware.verify import (
    CFLAGS,
    CModule,
    accept_flag,
    agreement,
    build,
    closed_loop,
    compiler,
    count_params,
    write_module,
)
from pmsm_commissioning.app.io.presets import list_presets, load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.profile import velocity_profile
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare, simulate
from tests.toolchain import need


def _compiler() -> str:
    return need(compiler(), "C compiler")


def _run_closed_loop(tmp_path: Path, params: DriveParams, single: bool, controller: str = "fdsmc") -> dict:
    _compiler()
    params, _ = count_params(params)
    write_module(tmp_path, params)
    return agreement(params, closed_loop(build(tmp_path, single), single, params, controller), controller)


PAPER_K_REC = ["controller.K=0.3"]  # the recommended K of the paper preset (0.302 s/rad)
#: Real sensors: a 17-bit encoder, 0.05 A rms noise, a 12-bit ADC of ±60 A (with 8192 counts the
#: real-motor presets chatter at standstill: the simulator says so, and such a loop is chaotic).
SENSORS = ["sensors.encoder_cpr=131072", "sensors.i_noise=0.05", "sensors.i_adc_bits=12", "sensors.i_adc_range=60"]
#: The loops the cases were measured with, pinned: the torque-limit α (whose peak touches the hard
#: current limit) and each preset's design for it, independent of later re-designs of the presets.
SIEMENS_LOOPS = ["controller.alpha_max_rule=torque_limit", "controller.T_so_ms=1", "controller.T_salpha_ms=3",
                 "controller.K=0.043075511186974044", "controller.T_c=T_a"]
YASKAWA_04A_LOOPS = ["controller.alpha_max_rule=torque_limit", "controller.K=0.014854420229048012",
                     "controller.T_c=0.02164492066201568"]
CASES = {
    "paper_limits": ("paper_12kw_pmsm", PAPER_K_REC + ["controller.delay_samples=1", "controller.V_dc=300",
                                                      "controller.i_max=40"]),
    "siemens_sensors": ("siemens_1ft7044_ak7", SENSORS + SIEMENS_LOOPS),
}


@pytest.mark.parametrize("case", CASES)
def test_double_build_is_bit_identical_in_closed_loop(tmp_path, case):
    """Quantized encoder, noisy ADC currents, delay, hard current and voltage limits: zero difference."""
    preset, sets = CASES[case]
    params = load_preset(preset, sets)
    err = _run_closed_loop(tmp_path, params, False)
    assert max(err.values()) == 0.0, err
    assert simulate(count_params(params)[0], "fdsmc").metrics.saturated_s > 0.0  # the limits acted


def test_double_build_conventional_step_is_bit_identical(tmp_path):
    err = _run_closed_loop(tmp_path, load_preset("paper_12kw_pmsm", PAPER_K_REC), False, "conventional")
    assert max(err.values()) == 0.0, err


def test_float32_closed_loop_reaches_the_same_place(tmp_path):
    """Count flips make the float32 trajectory another valid one, shifted by microseconds.

    Measured (17-bit encoder, noise, ADC), relative to each peak: θ_r 2.2e-5, ω_r 8e-4, i_q 1.1e-2,
    E_friction 4.5e-5, E_electrical 2.0e-3.
    """
    params = load_preset("yaskawa_sgm7j_04a", SENSORS + YASKAWA_04A_LOOPS)
    err = _run_closed_loop(tmp_path, params, True)
    assert err["theta_r"] < 1e-4 and err["E_friction"] < 1e-4, err
    assert err["E_copper"] < 1e-3 and err["E_electrical"] < 5e-3, err
    assert err["omega_r"] < 2e-3 and err["i_q"] < 3e-2, err


#: The shipped real-motor presets.
REAL_MOTORS = [n for n in list_presets() if n != "paper_12kw_pmsm" and isinstance(load_preset(n), DriveParams)]


def _export(folder: Path, params: DriveParams) -> bool:
    """Write the whole C export of ``params`` (simulated) into ``folder``; returns the clean verdict."""
    cmp = compare(params)
    checks = run_checks(params, cmp.fdsmc)
    for name, text in c_files(cmp, checks, force=True).items():
        (folder / name).write_text(text, encoding="utf-8")
    return not any(c.violated for c in checks)


def _host_test(folder: Path, defines: tuple[str, ...]) -> subprocess.CompletedProcess:
    subprocess.run([_compiler(), *CFLAGS, *defines, accept_flag(folder), "-O2", "fdsmc_test.c", "fdsmc_controller.c",
                    "-lm", "-o", "fdsmc_test"], cwd=folder, check=True, capture_output=True, text=True)
    return subprocess.run(["./fdsmc_test"], cwd=folder, capture_output=True, text=True)


@pytest.mark.parametrize("preset", REAL_MOTORS)
def test_golden_vectors_pass_the_host_test_program(tmp_path, preset):
    """The export's host program (gcc -Werror) replays the simulator's readings: double 1e-6, float 1e-4."""
    _compiler()
    _export(tmp_path, load_preset(preset, SENSORS[:1]))
    for defines in ((), ("-DFDSMC_USE_FLOAT",)):
        run = _host_test(tmp_path, defines)
        assert run.returncode == 0, (defines, run.stdout)
        worst = float(run.stdout.split("peak |u| = ")[1].split()[0])
        assert worst <= (1e-4 if defines else 1e-12), run.stdout


def test_golden_vectors_detect_a_wrong_constant(tmp_path):
    """The host program fails when the module is not the one the vectors were simulated with."""
    _compiler()
    _export(tmp_path, load_preset("yaskawa_sgm7j_04a"))
    src = tmp_path / "fdsmc_controller.c"
    text = src.read_text(encoding="utf-8")
    k_line = next(line for line in text.splitlines() if line.strip().startswith(".k_bl ="))
    src.write_text(text.replace(k_line, "    .k_bl = R_(0.9),"), encoding="utf-8")
    assert _host_test(tmp_path, ()).returncode == 1


#: Moves set at run time on the paper design (α_max by the paper rule, independent of the move).
MOVES = [(20.0, 1.0), (-35.0, 1.2), (5.0, 0.5)]


@pytest.mark.parametrize("single", [False, True])
def test_set_move_computes_the_profile_of_eq_60(tmp_path, single):
    """fdsmc_set_move reproduces control/fdsmc/profile.py (ω_p of eq. (60), T_c = T_a of eq. (59))."""
    params, _ = count_params(load_preset("paper_12kw_pmsm", PAPER_K_REC))
    _compiler()
    write_module(tmp_path, params)
    m = CModule(build(tmp_path, single), single)
    alpha, step = derive(params).alpha.alpha_max, 2.0 * 3.141592653589793 / params.sensors.encoder_cpr
    for theta, T_m in MOVES:
        s = m.new_state(0)
        count = round(theta / step)
        assert m.lib.fdsmc_set_move(ctypes.byref(s), count, T_m) == 0
        pr = velocity_profile(count * step, alpha, T_m)
        rel = 1e-6 if single else 1e-15
        req = s.move_req  # handed over, taken by the next step
        assert req.omega_p == pytest.approx(pr.omega_p, rel=rel) and req.t_c == pytest.approx(pr.T_c, rel=rel)
        assert s.move_pending == 1 and s.theta_dem == 0


def test_run_time_moves_run_as_simulated(tmp_path):
    """Three moves other than the designed one, set at run time: bit-identical to simulating each move."""
    base, _ = count_params(load_preset("paper_12kw_pmsm", PAPER_K_REC))
    _compiler()
    write_module(tmp_path, base)
    lib = build(tmp_path, False)
    for theta, T_m in MOVES:
        man = dataclasses.replace(base.manoeuvre, theta_dem=theta, T_m=T_m)
        params, _ = count_params(dataclasses.replace(base, manoeuvre=man))
        err = agreement(params, closed_loop(lib, False, params))
        assert max(err.values()) == 0.0, (theta, T_m, err)


def test_set_move_refuses_with_a_status_and_keeps_the_move(tmp_path):
    params, _ = count_params(load_preset("paper_12kw_pmsm", PAPER_K_REC))
    _compiler()
    write_module(tmp_path, params)
    m = CModule(build(tmp_path, True), True)
    d, step = derive(params), 2.0 * 3.141592653589793 / params.sensors.encoder_cpr
    s = m.new_state(0)
    count = round(60.0 / step)
    before = (s.omega_p, s.t_c, s.theta_dem, s.move_pending)
    # The rotor is at rest at θ̂ = 0: moves are measured from there.
    t_min = velocity_profile(120.0, d.alpha.alpha_max, 1.0).T_m_min
    far = round(1000.0 / step)
    t_far = velocity_profile(1000.0, d.alpha.alpha_max, 1.0).T_m_min
    cases = [(2 * count, 0.9 * t_min, -2), (2 * count, float("nan"), -1), (2 * count, -1.0, -1),
             (2 * count, float("inf"), -1), (far, 1.01 * t_far, -3), (3, 1e3, -4)]
    for target, T_m, code in cases:
        assert m.lib.fdsmc_set_move(ctypes.byref(s), target, T_m) == code, (target, T_m)
        assert (s.omega_p, s.t_c, s.theta_dem, s.move_pending) == before and s.status.last_move == code
    out = m.Output()
    assert m.lib.fdsmc_set_move(ctypes.byref(s), count, 1.3) == 0
    assert m.lib.fdsmc_set_move(ctypes.byref(s), 2 * count, 1.3) == -8  # FDSMC_ERR_BUSY: not yet taken
    m.lib.fdsmc_step(ctypes.byref(s), 0, 0.0, 0.0, ctypes.byref(out))
    assert s.theta_dem == count and s.move_pending == 0 and out.fault == 0  # taken at the step's start
    assert m.lib.fdsmc_set_move(ctypes.byref(s), 2 * count, 1.3) == -7  # FDSMC_ERR_MOVING: θ̂ far from θ_dem
    assert s.theta_dem == count and s.status.last_move == -7
