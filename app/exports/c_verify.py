"""Run the generated C controller in closed loop against the simulator's plant and measure agreement.

The module is compiled with the system C compiler (``cc``) into a shared object and called through
:mod:`ctypes` — standard library, no build step or extra package — once per controller sample,
between the RK4 steps of :class:`sim.fdsmc.plant.PlantInTheLoop` (the plant integration of the
simulator's digital mode). Agreement = max |C − simulator| / max |simulator| over the run, per
signal (error relative to the signal's peak), at every sample.

``python -m app.exports.c_verify`` prints the figures for the paper preset (double and float32 builds).
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from app.exports.c_module import controller_files
from app.io.presets import SCHEMA, load_preset
from control.fdsmc.derivations import derive
from control.fdsmc.params import DriveParams
from sim.fdsmc.engine import simulate
from sim.fdsmc.plant import PlantInTheLoop

#: Warnings the generated module must compile cleanly with.
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wdouble-promotion", "-Wconversion")
#: Signals compared: name → index in PlantInTheLoop.x (the same name as the Trace channel).
SIGNALS = {"theta_r": 2, "omega_r": 3, "i_q": 1, "E_friction": 4, "E_copper": 5, "E_electrical": 6}


def compiler() -> str | None:
    """Path of the system C compiler, or None."""
    return shutil.which("cc") or shutil.which("gcc")


def write_module(folder: Path, params: DriveParams) -> None:
    """Generate ``fdsmc_controller.h``/``.c`` for ``params`` into ``folder``."""
    for name, text in controller_files(params, derive(params), SCHEMA).items():
        (folder / name).write_text(text, encoding="utf-8")


def build(folder: Path, single: bool) -> ctypes.CDLL:
    """Compile the module in ``folder`` (float32 if ``single``) as a shared object and load it."""
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler (cc) found: scripts/ensure_cc.sh installs it")
    so = folder / ("libfdsmc_f.so" if single else "libfdsmc_d.so")
    defines = ["-DFDSMC_USE_FLOAT"] if single else []
    subprocess.run([cc, *CFLAGS, *defines, "-shared", "-fPIC", "-O2", str(folder / "fdsmc_controller.c"),
                    "-o", str(so), "-lm"], check=True, capture_output=True, text=True)
    return ctypes.CDLL(str(so))


def _types(single: bool) -> tuple[type, type, type, type]:
    real, angle = (ctypes.c_float if single else ctypes.c_double), ctypes.c_double

    class State(ctypes.Structure):
        _fields_ = [("z0", angle), ("z", real * 3), ("theta_ref", angle), ("u_hold", real * 2)]

    class Output(ctypes.Structure):
        _fields_ = [("u_d", real), ("u_q", real), ("theta_hat", angle), ("omega_hat", real),
                    ("Gamma_L_hat", real), ("alpha_dem", real), ("S", real), ("saturated", ctypes.c_int)]

    return real, angle, State, Output


def closed_loop(lib: ctypes.CDLL, single: bool, params: DriveParams, controller: str = "fdsmc") -> np.ndarray:
    """Plant states [i_d, i_q, θ_r, ω_r, E_f, E_cu, E_el, …] at every sample, C module in the loop."""
    real, angle, State, Output = _types(single)
    step = lib.fdsmc_step if controller == "fdsmc" else lib.fdsmc_step_conventional
    lib.fdsmc_init.argtypes = [ctypes.POINTER(State), angle]
    step.argtypes = [ctypes.POINTER(State), angle, real, real, angle, ctypes.POINTER(Output)]
    state, out = State(), Output()
    lib.fdsmc_init(ctypes.byref(state), 0.0)
    plant, theta_dem = PlantInTheLoop(params), params.manoeuvre.theta_dem
    rows = np.zeros((plant.n_samples, len(plant.x)))
    for k in range(plant.n_samples):
        x = plant.x
        rows[k] = x
        step(ctypes.byref(state), x[2], x[0], x[1], theta_dem, ctypes.byref(out))
        plant.step(out.u_d, out.u_q)
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
    """Generate, compile, run and compare one build for ``params``."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write_module(folder, params)
        return agreement(params, closed_loop(build(folder, single), single, params, controller), controller)


def main() -> None:
    """Print the agreement figures of the paper preset (paper K and recommended K)."""
    for label, sets in (("paper preset, K = 1000", []), ("paper preset, recommended K = 0.3", ["controller.K=0.3"])):
        params = load_preset("paper_12kw_pmsm", sets)
        for single in (False, True):
            err = measure(params, single)
            text = "  ".join(f"{k} {v:.2e}" for k, v in err.items())
            print(f"{label:36s} {'float32' if single else 'double ':8s} {text}")


if __name__ == "__main__":
    main()
