"""One source of truth for every metric and flag: the compiled kernel and the same kernel run as
plain Python (``NUMBA_DISABLE_JIT=1``) agree on every RunMetrics field, on random cases.

The cases (drawn from a fixed seed) span the real-motor presets with random moves, sample rates,
computation delays, encoders, current noise and ADCs, plant inertia the controller does not know,
tight current and voltage limits (so the limit flags are exercised) and all three controllers.
The plain-Python side runs in a subprocess (numba reads NUMBA_DISABLE_JIT at import).
"""

from __future__ import annotations

import dataclasses
import json
import sys

import numpy as np

from tests.compiled_agreement import disagreements, plain_python_cases

N_CASES = 120  # every flag both ways already (chatter 85, saturated 42, over i_max 3, in position 1 of 120)
PRESETS = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "yaskawa_sgm7a_50a")
CONTROLLERS = ("fdsmc", "conventional")


def _case(rng: np.random.Generator):
    """One random (params, plant, controller) case with a short horizon (few thousand samples)."""
    from pmsm_commissioning.app.io.presets import load_preset
    from pmsm_commissioning.control.fdsmc.derivations import derive
    from pmsm_commissioning.control.fdsmc.params import Limits, Sensors

    base = load_preset(PRESETS[rng.integers(len(PRESETS))])
    theta = float(rng.uniform(0.5, 6.0)) * (1 if rng.random() < 0.8 else -1)
    c = base.controller
    ctrl = dataclasses.replace(c, f_s=float(rng.choice([4000.0, 5000.0, 8000.0])),
                               delay_samples=int(rng.integers(2)),
                               i_max=c.i_max * float(rng.uniform(0.4, 1.2)),
                               V_dc=c.V_dc * float(rng.uniform(0.3, 1.0)), T_so=c.T_so * float(rng.uniform(1, 4)),
                               T_salpha=c.T_salpha * float(rng.uniform(1, 3)))
    sensors = Sensors(encoder_cpr=int(rng.choice([0, 2**11, 2**13, 2**17])),
                      i_noise=float(rng.choice([0.0, 0.01, 0.1])) * c.i_max,
                      i_adc_bits=int(rng.choice([0, 12])), i_adc_range=1.5 * c.i_max, seed=int(rng.integers(100)))
    p = dataclasses.replace(base, controller=ctrl, sensors=sensors, limits=Limits(in_position=1e-3))
    T_min = derive(dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, theta_dem=theta))).profile.T_m_min
    p = dataclasses.replace(p, manoeuvre=dataclasses.replace(p.manoeuvre, theta_dem=theta,
                                                             T_m=round(T_min * float(rng.uniform(1.1, 2.5)), 4)))
    plant = dataclasses.replace(p, load=dataclasses.replace(p.load, J_L=p.load.J_L * float(rng.uniform(0.5, 2.0))))
    ctrl_name = CONTROLLERS[rng.integers(len(CONTROLLERS))]
    # the q-axis voltage-mismatch estimate on half the cases, against a motor whose flux is a few % off
    T_dv = float(rng.choice([0.0, 2.0 * c.T_si]))
    p = dataclasses.replace(p, controller=dataclasses.replace(p.controller, T_dv=T_dv))
    plant = dataclasses.replace(plant, motor=dataclasses.replace(plant.motor, psi_pm=plant.motor.psi_pm
                                                                 * float(rng.uniform(0.97, 1.03))))
    return p, plant, ctrl_name


def run_cases(seed: int, n: int) -> list[dict]:
    """Metrics of the n cases of ``seed`` as plain data (JSON-able, None for a refused case)."""
    from pmsm_commissioning.control.common.checks import ParameterError
    from pmsm_commissioning.sim.fdsmc.engine import simulate

    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        p, plant, ctrl = _case(rng)
        try:
            out.append(dataclasses.asdict(simulate(p, ctrl, plant=plant, max_points=2000).metrics))
        except ParameterError as exc:
            out.append({"refused": str(exc)})
    return out


def test_compiled_and_plain_python_agree_on_every_metric_and_flag():
    compiled = run_cases(2026, N_CASES)
    plain = plain_python_cases(__file__, 2026, N_CASES, timeout=1800)
    assert len(plain) == len(compiled) == N_CASES
    flags = {"chatter": 0, "saturated": 0, "over_i_max": 0, "in_position": 0}
    for i, (a, b) in enumerate(zip(compiled, plain, strict=True)):
        bad = disagreements(a, b, rel_tol=1e-6, abs_tol=1e-9)
        assert not bad, f"case {i}: {bad}"
        if "refused" in a:
            continue
        if not a["stable"]:
            continue
        flags["chatter"] += a["chatter"]
        flags["saturated"] += a["saturated_s"] > 0
        flags["over_i_max"] += (a["over_i_max_s"] or 0) > 0
        flags["in_position"] += a["in_position_s"] is not None
    # the random cases exercise every flag both ways, or the agreement would prove little
    assert all(0 < v < N_CASES for v in flags.values()), flags


if __name__ == "__main__":
    json.dump(run_cases(int(sys.argv[1]), int(sys.argv[2])), sys.stdout)
