"""The stock drive's loops compiled and as plain Python (``NUMBA_DISABLE_JIT=1``) agree on every metric and flag.

Random cases (fixed seed): each drive's structure (ODrive's cascade with speed clamp and PLL snap,
moteus' PID, the plain cascade), random speed-loop bandwidths — slow and fast enough to limit and
saturate —, encoders, current noise and ADCs, a plant inertia the drive does not know, tight current
limits. The plain-Python side runs in a subprocess (tests/compiled_agreement.py).
"""

from __future__ import annotations

import dataclasses
import json
import sys

import numpy as np

from tests.compiled_agreement import disagreements, plain_python_cases

N_CASES = 16
PRESETS = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_04a", "odrive_d5065_belt")


def _case(rng: np.random.Generator):
    """One random (params, plant, loop) case with a short move."""
    from pmsm_commissioning.app.io.presets import load_preset
    from pmsm_commissioning.control.fdsmc.derivations import derive
    from pmsm_commissioning.control.fdsmc.params import Sensors
    from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_timing
    from pmsm_commissioning.sim.stock.tuning import DRIVES, bandwidth_ceiling, loop_rate, make_loop

    base = load_preset(PRESETS[rng.integers(len(PRESETS))])
    c = base.controller
    ctrl = dataclasses.replace(c, f_s=float(rng.choice([4000.0, 8000.0])), i_max=c.i_max * float(rng.uniform(0.3, 1.0)))
    sensors = Sensors(encoder_cpr=int(rng.choice([0, 2**12, 2**17])), i_noise=float(rng.choice([0.0, 0.01])) * c.i_max,
                      i_adc_bits=int(rng.choice([0, 12])), i_adc_range=1.5 * c.i_max, seed=int(rng.integers(100)))
    theta = float(rng.uniform(1.0, 6.0))
    p = dataclasses.replace(base, controller=ctrl, sensors=sensors,
                            manoeuvre=dataclasses.replace(base.manoeuvre, theta_dem=theta, T_m=0.12))
    d = derive(p)
    alpha = max(d.alpha.alpha_max, 4.0 * theta / 0.12 ** 2 * 1.05)
    tr = trapezoid_timing(theta, alpha, 0.12)
    spec = list(DRIVES.values())[rng.integers(len(DRIVES))]
    spec = dataclasses.replace(spec, f_loop=None)  # the case's f_s: a few thousand samples
    w_v = bandwidth_ceiling(p, loop_rate(spec, p)) * float(rng.uniform(0.1, 2.5))
    plant = dataclasses.replace(p, load=dataclasses.replace(p.load, J_L=p.load.J_L * float(rng.uniform(0.5, 2.0))))
    return p, plant, make_loop(spec, p, tr, w_v)


def run_cases(seed: int, n: int) -> list[dict]:
    """Metrics of the n cases of ``seed`` as plain data (JSON-able)."""
    from pmsm_commissioning.sim.stock.route import simulate_stock

    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        p, plant, loop = _case(rng)
        out.append(dataclasses.asdict(simulate_stock(p, loop, plant=plant).metrics))
    return out


def test_stock_loops_compiled_and_plain_python_agree():
    compiled = run_cases(35, N_CASES)
    plain = plain_python_cases(__file__, 35, N_CASES, timeout=900)
    assert len(plain) == len(compiled) == N_CASES
    for i, (a, b) in enumerate(zip(compiled, plain, strict=True)):
        bad = disagreements(a, b, rel_tol=1e-9, abs_tol=1e-12)
        assert not bad, f"case {i}: {bad}"
    saturated = sum(a["saturated_s"] > 0 for a in compiled if a["stable"])
    settled = sum(a["in_position_s"] is not None for a in compiled if a["stable"])
    assert 0 < saturated < N_CASES and 0 < settled < N_CASES  # both ways, or the agreement proves little


if __name__ == "__main__":
    json.dump(run_cases(int(sys.argv[1]), int(sys.argv[2])), sys.stdout)
