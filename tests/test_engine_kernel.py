"""The compiled kernel agrees with the plain-Python reference built from :mod:`control` laws."""

from __future__ import annotations

import numpy as np
import pytest

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.engine import run_steps
from pmsm_commissioning.sim.fdsmc.reference import run_reference

CASES = [
    ("fdsmc", ["controller.K=0.3"]),
    ("conventional", ["controller.K=0.3"]),
    ("fdsmc", ["controller.K=1000", "controller.delay_samples=1", "load.Gamma_Le=5", "load.Gamma_Le_ramp=20"]),
    ("fdsmc", ["controller.f_s=continuous", "controller.K=0.45"]),
    ("conventional", ["controller.f_s=continuous", "load.Gamma_Le=-8"]),
    # inverter limits active: the conventional law's start hits i_max, the FDSMC's the voltage limit
    ("conventional", ["controller.K=0.3", "controller.i_max=40", "controller.V_dc=600"]),
    ("fdsmc", ["controller.K=0.3", "controller.V_dc=120", "controller.i_max=500"]),
]


@pytest.mark.parametrize(("controller", "overrides"), CASES)
def test_kernel_matches_reference(controller, overrides):
    p = load_preset("paper_12kw_pmsm", overrides)
    d = derive(p)
    n = 1500  # 75 ms digital (through the end of the acceleration) / 7.5 ms continuous
    ref = run_reference(p, d, controller, n)
    ker = run_steps(p, controller, n, derived=d)
    pairs = [(ref.i_d, lay.X_ID, 1e-3), (ref.i_q, lay.X_IQ, 1e-3), (ref.theta_r, lay.X_TH, 1e-6),
             (ref.omega_r, lay.X_W, 1e-6), (ref.theta_hat, lay.X_THH, 1e-6),
             (ref.omega_hat, lay.X_WH, 1e-6), (ref.L0, lay.X_L0, 1e-3),
             (ref.E_friction, lay.X_EF, 1e-6), (ref.E_copper, lay.X_ECU, 1e-6),
             (ref.E_electrical, lay.X_EEL, 1e-6)]
    for value, idx, atol in pairs:
        assert ker[idx] == pytest.approx(value, rel=1e-8, abs=atol)
    assert abs(ker[lay.X_W]) > 1.0  # the drive actually moved


def test_kernel_run_is_deterministic_and_thread_safe():
    from concurrent.futures import ThreadPoolExecutor

    p = load_preset("paper_12kw_pmsm", ["controller.K=0.3"])
    d = derive(p)
    with ThreadPoolExecutor(4) as pool:
        outs = list(pool.map(lambda c: run_steps(p, c, 5000, derived=d), ["fdsmc", "conventional"] * 2))
    assert np.array_equal(outs[0], outs[2]) and np.array_equal(outs[1], outs[3])
