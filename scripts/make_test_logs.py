"""Write the two example drive logs of tests/data/ reproducibly (seeded).

Both come from :mod:`sim.drivelog.synthetic`: a drive tuned for the paper's 12 kW motor
(``presets/paper_12kw_pmsm.yaml`` with ``LOG_OVERRIDES``) controls a plant with other
parameters (``TRUE_MOTOR``, ``TRUE_LOAD``): 120 ms of motor-ID d-axis current injection at
standstill (i_d,dem steps of 15 ms: ±10 A three times, 5 A, 0 A), then a 3 rad move in 0.45 s
(``presets/example_log_drive.yaml``); 10 kHz, one-sample delay,
σ = 50 mA current noise, 12-bit ADC over ±100 A, 14-bit encoder, 10 mV voltage resolution.

* ``drive_log_dq.csv``: dq signals, units in the header names (``t [ms]``, ``theta_r [rad]`` …).
* ``drive_log_phases.csv`` + ``drive_log_phases.map.yaml``: a vendor-style scope export (µs,
  degrees, two phase currents) with a mapping file.

Usage: ``.venv/bin/python scripts/make_test_logs.py [OUT_DIR]`` (default tests/data).
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.resources import example_log
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.drivelog.synthetic import (
    LOG_DURATION,
    LOG_OVERRIDES,
    LogNoise,
    add_noise,
    clean_log,
    perturbed,
)

ROOT = Path(__file__).resolve().parent.parent
HEADER = "# Synthetic drive log made by scripts/make_test_logs.py from the project's plant (seed {seed}).\n"


def phase_log(clean: dict[str, np.ndarray], noise: LogNoise, seed: int, p: int) -> dict[str, np.ndarray]:
    """Measured phase currents i_a, i_b (noise and ADC per phase) and the encoder angle."""
    rng = np.random.default_rng(seed)
    log = add_noise(clean, noise, seed)
    th_e = p * clean["theta_r"]
    lsb = 2.0 * noise.i_full_scale / 2**noise.adc_bits
    for name, shift in (("i_a", 0.0), ("i_b", -2.0 * np.pi / 3.0)):
        i = clean["i_d"] * np.cos(th_e + shift) - clean["i_q"] * np.sin(th_e + shift)
        log[name] = np.round((i + rng.normal(0.0, noise.sigma_i, i.size)) / lsb) * lsb
    return log


def main(out: Path) -> None:
    nominal = load_preset("paper_12kw_pmsm", LOG_OVERRIDES)
    true = perturbed(nominal)
    clean = clean_log(true, derive(nominal), LOG_DURATION)
    out.mkdir(parents=True, exist_ok=True)
    a = add_noise(clean, LogNoise(), 1)
    rows = np.column_stack([a["t"] * 1e3, a["theta_r"], a["i_d"], a["i_q"], a["u_d"], a["u_q"]])
    with open(out / "drive_log_dq.csv", "w", encoding="utf-8") as fh:
        fh.write(HEADER.format(seed=1))
        np.savetxt(fh, rows, fmt=["%.1f", "%.5f", "%.2f", "%.2f", "%.2f", "%.2f"], delimiter=",",
                   header="t [ms],theta_r [rad],i_d [A],i_q [A],u_d [V],u_q [V]", comments="")
    b = phase_log(clean, LogNoise(), 2, true.motor.p)
    rows = np.column_stack([np.round(b["t"] * 1e6), np.degrees(b["theta_r"]), b["i_a"], b["i_b"], b["u_d"], b["u_q"]])
    with open(out / "drive_log_phases.csv", "w", encoding="utf-8") as fh:
        fh.write(HEADER.format(seed=2))
        np.savetxt(fh, rows, fmt=["%d", "%.4f", "%.2f", "%.2f", "%.2f", "%.2f"], delimiter=";",
                   header="Time;Pos;Ia;Ib;Vd_ref;Vq_ref", comments="")
    (out / "drive_log_phases.map.yaml").write_text(
        "# Mapping of drive_log_phases.csv's columns (column: signal [unit])\n"
        "Time: t [us]\nPos: theta_r [deg]\nIa: i_a [A]\nIb: i_b [A]\nVd_ref: u_d [V]\nVq_ref: u_q [V]\n",
        encoding="utf-8")
    if out.resolve() == (ROOT / "tests" / "data").resolve():  # the page's Example button reads the shipped copy
        shutil.copyfile(out / "drive_log_dq.csv", example_log())


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "tests" / "data")
