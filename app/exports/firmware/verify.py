"""Run the generated C controller in closed loop against the simulator's plant and measure agreement.

The module is compiled with the system C compiler (``cc``) into a shared object and called through
:mod:`ctypes` — standard library, no build step or extra package — once per controller sample,
between the RK4 steps of :class:`sim.fdsmc.plant.PlantInTheLoop` (the plant integration of the
simulator's digital mode). The C module takes the angle as encoder counts: the harness feeds it what
the simulator's controller reads (:func:`readings`: the encoder's whole counts of θ_r, the currents with
the seeded noise and ADC of :mod:`sim.common.sensors`), sets the move with the demand rounded to a count,
and the simulator runs on the same demand and encoder (:func:`count_params`). Agreement = max |C − simulator|
/ max |simulator| over the run, per signal (error relative to the signal's peak), at every sample.

``python scripts/c_verify.py [--controller optimum]`` prints the figures for the paper
preset and the real-motor presets (of the FDSMC's module, or the tracked optimum's).
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from pmsm_commissioning.app.exports.firmware.design import encoder_counts_per_rev
from pmsm_commissioning.app.exports.firmware.module import Verdict, controller_files
from pmsm_commissioning.app.io.presets import SCHEMA
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.common import sensors
from pmsm_commissioning.sim.fdsmc.engine import simulate
from pmsm_commissioning.sim.fdsmc.plant import PlantInTheLoop

#: Warnings the generated module must compile cleanly with.
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wdouble-promotion", "-Wconversion")
#: Signals compared: name → index in PlantInTheLoop.x (the same name as the Trace channel).
SIGNALS = {"theta_r": 2, "omega_r": 3, "i_q": 1, "E_friction": 4, "E_copper": 5, "E_electrical": 6}


def compiler() -> str | None:
    """Path of the system C compiler, or None."""
    return shutil.which("cc") or shutil.which("gcc")


def count_params(params: DriveParams) -> tuple[DriveParams, int]:
    """Return the case as the firmware runs it, and the demand in counts.

    θ_dem is rounded to a whole encoder count; an ideal encoder becomes the module's resolution
    (:data:`app.exports.firmware.design.IDEAL_COUNTS_PER_REV`), so that the simulator reads the same counts.
    """
    cpr = encoder_counts_per_rev(params)
    se = dataclasses.replace(params.sensors, encoder_cpr=cpr)
    step = se.encoder_step
    count = round(params.manoeuvre.theta_dem / step)
    man = dataclasses.replace(params.manoeuvre, theta_dem=count * step)
    return dataclasses.replace(params, manoeuvre=man, sensors=se), count


def readings(params: DriveParams, k: int, theta: float, i_d: float, i_q: float,
             noise: np.ndarray) -> tuple[int, float, float]:
    """Return what the controller reads at sample k: (encoder count, i_d [A], i_q [A]), as the simulator's sensors.

    ``noise`` is :func:`sim.common.sensors.noise_table` of ``params.sensors``; the encoder must not be ideal.
    """
    se, j = params.sensors, k % noise.shape[1]
    i_step = se.adc_step
    return (math.floor(theta / se.encoder_step),
            sensors.adc_current(i_d, noise[0, j], se.i_noise, i_step, se.i_adc_range),
            sensors.adc_current(i_q, noise[1, j], se.i_noise, i_step, se.i_adc_range))


def write_module(folder: Path, params: DriveParams, verdict: Verdict | None = None, law: str = "fdsmc") -> None:
    """Generate ``fdsmc_controller.h``/``.c`` for ``params`` into ``folder`` (unverified unless ``verdict``).

    ``law``: the module's outer law, ``"fdsmc"`` or ``"optimum"`` (the tracked optimum's module).
    """
    kw = {} if verdict is None else {"verdict": verdict}
    for name, text in controller_files(params, derive(params), SCHEMA, law=law, **kw).items():
        (folder / name).write_text(text, encoding="utf-8")


def accept_flag(folder: Path) -> str:
    """``-DFDSMC_ACCEPT_UNCLEAN=<hash>``: the explicit acceptance of the module in ``folder``."""
    text = (folder / "fdsmc_controller.h").read_text(encoding="utf-8")
    match = re.search(r"#define FDSMC_PARAM_HASH (0x[0-9a-f]+u)", text)
    assert match, "no FDSMC_PARAM_HASH in the header"
    return f"-DFDSMC_ACCEPT_UNCLEAN={match.group(1)}"


def build(folder: Path, single: bool) -> ctypes.CDLL:
    """Compile the module in ``folder`` (float32 if ``single``, the gate accepted) as a shared object and load it."""
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc) found: scripts/ensure_cc.sh installs it")
    so = folder / ("libfdsmc_f.so" if single else "libfdsmc_d.so")
    defines = ["-DFDSMC_USE_FLOAT"] if single else []
    subprocess.run([cc, *CFLAGS, *defines, accept_flag(folder), "-shared", "-fPIC", "-O2",
                    str(folder / "fdsmc_controller.c"), "-o", str(so), "-lm"],
                   check=True, capture_output=True, text=True)
    return ctypes.CDLL(str(so))


class CModule:
    """ctypes view of one compiled module: its structs and functions (``single``: float32 build)."""

    def __init__(self, lib: ctypes.CDLL, single: bool) -> None:
        real = ctypes.c_float if single else ctypes.c_double
        i32, u32 = ctypes.c_int32, ctypes.c_uint32

        class Status(ctypes.Structure):
            _fields_ = [("fault", u32), ("fault_sample", u32), ("samples", u32), ("saturated_samples", u32),
                        ("e_o_peak", real), ("last_move", i32)]

        observer = ([("n0", i32), ("f0", real), ("z", real * 3)] if single
                    else [("theta_dem_rad", ctypes.c_double), ("x", ctypes.c_double * 4)])

        # The tracked optimum's module appends its move clock (the FDSMC's struct is the prefix).
        clock = ([("ref_k", u32)] if single else [("ref_t", ctypes.c_double), ("ref_start_rad", ctypes.c_double)])

        class Move(ctypes.Structure):
            _fields_ = [("theta_dem", i32), ("omega_p", real), ("t_c", real), ("inv_t_c", real), ("slope_end", real)]

        class State(ctypes.Structure):
            _fields_ = [("p", ctypes.c_void_p), ("theta_dem", i32), *observer, ("u_hold", real * 2),
                        ("dv_mem", real * 6), ("omega_p", real), ("t_c", real), ("inv_t_c", real), ("slope_end", real),
                        ("status", Status), ("move_req", Move), ("move_pending", u32), *clock,
                        ("ref_on", i32)]

        class Angle(ctypes.Structure):
            _fields_ = [("last", i32), ("e", i32)]

        class Output(ctypes.Structure):
            _fields_ = [("u_d", real), ("u_q", real), ("u_d_next", real), ("u_q_next", real), ("theta_re", real),
                        ("omega_hat", real),
                        ("Gamma_L_hat", real), ("alpha_dem", real), ("S", real), ("saturated", i32), ("fault", u32)]

        self.lib, self.State, self.Output, self.Angle = lib, State, Output, Angle
        self.design = ctypes.addressof(ctypes.c_char.in_dll(lib, "FDSMC_DESIGN"))
        ps = ctypes.POINTER(State)
        lib.fdsmc_init.argtypes = [ps, ctypes.c_void_p, i32]
        lib.fdsmc_set_move.argtypes, lib.fdsmc_set_move.restype = [ps, i32, real], i32
        for f in (lib.fdsmc_step, lib.fdsmc_step_conventional):
            f.argtypes = [ps, i32, real, real, ctypes.POINTER(Output)]
        lib.fdsmc_electrical_angle.argtypes, lib.fdsmc_electrical_angle.restype = [i32, i32], real
        lib.fdsmc_angle_init.argtypes = [ctypes.POINTER(Angle), i32, i32]
        lib.fdsmc_angle_update.argtypes, lib.fdsmc_angle_update.restype = [ctypes.POINTER(Angle), i32], real

    def new_state(self, theta_r0: int = 0) -> ctypes.Structure:
        """Return an initialised state at the count ``theta_r0``."""
        s = self.State()
        self.lib.fdsmc_init(ctypes.byref(s), self.design, theta_r0)
        return s


def closed_loop(lib: ctypes.CDLL, single: bool, params: DriveParams, controller: str = "fdsmc") -> np.ndarray:
    """Plant states [i_d, i_q, θ_r, ω_r, E_f, E_cu, E_el, …] at every sample, C module in the loop.

    ``params`` as :func:`count_params` returns them; the move is set at run time (``fdsmc_set_move``
    to θ_dem in counts, in T_m); the module reads the sensors of :func:`readings`. ``controller``:
    ``"conventional"`` runs ``fdsmc_step_conventional``, else ``fdsmc_step`` (the module's outer law:
    the FDSMC, or the tracked optimum in its module).

    The voltages reach the plant as the header documents for a PWM with shadow registers: call k
    writes ``out.u_d_next``/``u_q_next`` to the shadow registers, which load at instant k+1 and act
    over [k+1, k+2] (with no computation delay, ``out.u_d``/``u_q`` act at once over [k, k+1]). The
    voltage loaded at k must be the ``out.u_d``/``u_q`` of call k: checked at every sample.
    """
    m = CModule(lib, single)
    state, out = m.new_state(0), m.Output()
    _, count = count_params(params)
    rc = lib.fdsmc_set_move(ctypes.byref(state), count, params.manoeuvre.T_m)
    if rc != 0:
        raise RuntimeError(f"fdsmc_set_move refused the designed move: status {rc}")
    step = lib.fdsmc_step_conventional if controller == "conventional" else lib.fdsmc_step
    plant, noise = PlantInTheLoop(params), sensors.noise_table(params.sensors)
    rows = np.zeros((plant.n_samples, len(plant.x)))
    shadow, delayed = (0.0, 0.0), params.controller.delay_samples == 1
    for k in range(plant.n_samples):
        x = plant.x
        rows[k] = x
        step(ctypes.byref(state), *readings(params, k, x[2], x[0], x[1], noise), ctypes.byref(out))
        active = shadow if delayed else (out.u_d_next, out.u_q_next)  # loaded at k / written at once
        if out.fault != 0:
            active = (0.0, 0.0)  # the inverter opened: no voltage
        elif active != (out.u_d, out.u_q):
            raise RuntimeError(f"call {k}: the voltage acting over [k, k+1] {active} is not out.u {out.u_d, out.u_q}")
        plant.step(*active)
        shadow = (out.u_d_next, out.u_q_next)
    return rows


def agreement(params: DriveParams, rows: np.ndarray, controller: str = "fdsmc") -> dict[str, float]:
    """Max error relative to the peak of each signal, C closed loop vs. the simulator's digital mode."""
    trace = simulate(params, controller, max_points=rows.shape[0] + 1).trace
    if trace.t.size < rows.shape[0]:
        raise RuntimeError(f"the simulator kept {trace.t.size} of {rows.shape[0]} samples")
    n = rows.shape[0]
    return {name: float(np.max(np.abs(rows[:, i] - getattr(trace, name)[:n])) / np.max(np.abs(getattr(trace, name))))
            for name, i in SIGNALS.items()}


def measure(params: DriveParams, single: bool, controller: str = "fdsmc") -> dict[str, float]:
    """Generate, compile, run and compare one build for ``params`` (demand rounded to a count).

    ``controller`` ``"optimum"`` generates the tracked optimum's module.
    """
    params, _ = count_params(params)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write_module(folder, params, law="optimum" if controller == "optimum" else "fdsmc")
        return agreement(params, closed_loop(build(folder, single), single, params, controller), controller)


def replay(folder: Path, single: bool) -> float:
    """Build and run the export's host test program in ``folder``; returns max |u − u_sim| / peak |u| [-]."""
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc) found: scripts/ensure_cc.sh installs it")
    defines = ["-DFDSMC_USE_FLOAT"] if single else []
    subprocess.run([cc, *CFLAGS, *defines, accept_flag(folder), "-O2", "fdsmc_test.c", "fdsmc_controller.c", "-lm",
                    "-o", "fdsmc_test"], cwd=folder, check=True, capture_output=True, text=True)
    out = subprocess.run(["./fdsmc_test"], cwd=folder, capture_output=True, text=True).stdout
    return float(out.split("peak |u| = ")[1].split()[0])
