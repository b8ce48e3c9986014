"""Print the Monte-Carlo table of docs/energy.md ("Robustness: where the FDSMC's energy buys something").

Per real preset, with the q-axis voltage-mismatch estimate as shipped (T_dv = 1 ms) and without it
(T_dv = 0, the paper's FDC), and with Ψ_PM uniform ±2 % and ±20 %: 200 plants (seed 1) with J_L
uniform in [0, 10·J_r] and R_s uniform ±20 %; for the FDSMC, the tracked optimum and the
conventional comparator each cell is net electrical input p50 / p95 [J] · p95 of |θ_r(T_m) − θ_dem|
[rad] · chatter probability · infeasible probability. Runs on a local process pool of all cores
(≈ 1–3 min per preset on two cores). Usage: ``.venv/bin/python scripts/robustness_table.py [--samples 200]``
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pmsm_commissioning.app.io.presets import load_preset  # noqa: E402
from pmsm_commissioning.app.io.study_inputs import parse_spreads  # noqa: E402
from pmsm_commissioning.sim.studies.robustness import robustness  # noqa: E402
from pmsm_commissioning.sim.studies.runner import RetryingPool  # noqa: E402

PRESETS = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "yaskawa_sgm7a_50a", "odrive_d5065_belt")
CONTROLLERS = ("fdsmc", "optimum", "conventional")


def cell(entry: dict) -> str:
    """One table cell from a controller's summary."""
    e, err = entry["electrical_in_total_J"], entry["theta_error_abs_at_Tm_rad"]
    return (f"{e['p50']:.3g} / {e['p95']:.3g} · {err['p95']:.2g} · {entry['chatter_probability']:.2f} · "
            f"{entry['infeasible_probability']:.2f}")


def row(name: str, T_dv_ms: float, samples: int, pool: RetryingPool, workers: int) -> str:
    """The table row of preset ``name`` with T_dv [ms]: Ψ ±2 % then ±20 %, each controller."""
    params = load_preset(name, [f"controller.T_dv_ms={T_dv_ms:g}"])
    J_L_max = 10.0 * params.motor.J_r
    cells = []
    for psi in ("2%", "20%"):
        spreads = parse_spreads([f"plant.J_L=0:{J_L_max:.6g}", "plant.R_s=±20%", f"plant.psi_pm=±{psi}"])
        result = robustness(params, spreads, samples, seed=1, executor=pool, workers=workers,
                            controllers=("fdsmc", "conventional", "optimum"))
        cells += [cell(result.summary[c]) for c in CONTROLLERS]
    label = "1 ms" if T_dv_ms else "0 (paper)"
    return f"| `{name}` | {label} | " + " | ".join(cells) + " |"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=200)
    args = ap.parse_args()
    workers = os.cpu_count() or 1
    t0 = time.perf_counter()
    with RetryingPool(workers) as pool:
        for name in PRESETS:
            for T_dv_ms in (1.0, 0.0):
                print(row(name, T_dv_ms, args.samples, pool, workers), flush=True)
    print(f"({time.perf_counter() - t0:.0f} s on {workers} workers)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
