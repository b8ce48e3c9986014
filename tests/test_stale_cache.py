"""A compiled kernel never runs stale code: editing a law in ``control/`` recompiles the kernel.

numba keys its on-disk cache on the kernel's own file only; ``sim/__init__.py`` keys the cache
folder on a hash of every ``control/`` and ``sim/`` source. The test copies the packages to a
temporary folder, runs a short conventional move there (filling a shared cache), halves the
conventional law's position gain in the copy and runs again with the same cache folder: the
result must follow the edit.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = """
import json, dataclasses
from pmsm_commissioning.control.fdsmc.params import Controller, DriveParams, Load, Manoeuvre, Motor
from pmsm_commissioning.sim.fdsmc.engine import simulate
m = Motor(V_0=430.0, P_r=12e3, omega_b=150.0, Gamma_max=40.0, psi_pm=0.38, L_d=5.4e-3, L_q=5.4e-3, R_s=0.1,
          p=5, J_r=0.03)
p = DriveParams(m, Load(J_L=0.12, F_v=0.4), Controller(T_si=5e-3, T_salpha=1e-3, T_so=2e-4, K=0.3, f_s=20e3),
                Manoeuvre(theta_dem=1.0, T_m=0.2))
run = simulate(p, "conventional")
print(json.dumps(float(run.trace.theta_r[len(run.trace.theta_r) // 4])))
"""


def _run(pkg: Path, cache: Path) -> float:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(pkg)}
    out = subprocess.run([sys.executable, "-c", SCRIPT], cwd=pkg, env=env, capture_output=True, text=True,
                         timeout=600, check=True)
    return float(json.loads(out.stdout.strip().splitlines()[-1]))


def test_editing_a_control_law_recompiles_the_kernel(tmp_path):
    pkg = tmp_path / "pkg"
    for name in ("control", "sim"):
        shutil.copytree(ROOT / name, pkg / "pmsm_commissioning" / name, ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "numba_cache"
    before = _run(pkg, cache)
    law = pkg / "pmsm_commissioning" / "control" / "fdsmc" / "conventional.py"
    text = law.read_text()
    assert "return g1 * (theta_dem - theta_hat)" in text
    law.write_text(text.replace("return g1 * (theta_dem - theta_hat)", "return 0.5 * g1 * (theta_dem - theta_hat)"))
    after = _run(pkg, cache)
    assert before > 0.0 and after > 0.0
    assert abs(after - before) > 0.05 * before  # the halved gain moves the rotor visibly less early on
    assert len([d for d in cache.iterdir() if d.name.startswith("src-")]) == 2
