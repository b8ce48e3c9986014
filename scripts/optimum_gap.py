"""Print how close the FDSMC and the conventional controller come to the tracked minimum-energy
optimum: Table 1's five T_m on the paper's drive, and each real-motor preset at its own T_m.

Usage: ``python scripts/optimum_gap.py [--paper-K 0.3]`` (K = 0.3 s/rad: a chatter-free gain for
the paper's drive at 20 kHz; the preset's K = 1000 chatters).
"""

from __future__ import annotations

import argparse

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.optimum_gap import saving_vs_optimum
from pmsm_commissioning.sim.fdsmc.table1 import TABLE1_T_M

REAL = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_04a", "yaskawa_sgm7j_02a", "yaskawa_sgm7a_50a")


def row(label: str, name: str, overrides: list[str]) -> None:
    """One line: energies [J] of the three runs and the gaps [%]."""
    c = compare(load_preset(name, overrides), ("fdsmc", "conventional", "optimum"))
    f, v, o = (r.metrics for r in (c.fdsmc, c.conventional, c.optimum))
    print(f"{label:28s} {f.electrical_in_total_J:10.4g} {v.electrical_in_total_J:10.4g} "
          f"{o.electrical_in_total_J:10.4g} {saving_vs_optimum(c.fdsmc, c.optimum):8.1f} "
          f"{saving_vs_optimum(c.conventional, c.optimum):8.1f}   F/Cu FDSMC {f.friction_J:.4g}/"
          f"{f.copper_J:.4g}, opt {o.friction_J:.4g}/{o.copper_J:.4g}; "
          f"opt peak {o.torque_peak_Nm:.4g} N·m, θ err {o.theta_error_at_Tm_rad:.3g} rad")


def main() -> None:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paper-K", type=float, default=0.3)
    a = ap.parse_args()
    print(f"{'case':28s} {'W FDSMC':>10s} {'W conv':>10s} {'W opt':>10s} {'gap F %':>8s} {'gap C %':>8s}")
    print("(W: net electrical input over the whole run [J]; gap: share of it the optimum saves)")
    for T_m in TABLE1_T_M:
        row(f"paper T_m = {T_m:g} s", "paper_12kw_pmsm", [f"manoeuvre.T_m={T_m}", f"controller.K={a.paper_K}"])
    for name in REAL:
        row(name, name, [])


if __name__ == "__main__":
    main()
