"""Print the stock route's verdict per preset and drive, before and after tuning (docs/real_drive.md).

.venv/bin/python scripts/stock_table.py

*Before*: the gains the drive files used to carry — the comparator's eq. (61) gains g1, g2 of [1]
transcribed as a P–PI cascade (pos_gain = g1/g2, vel_gain = g2·J, speed-integrator zero at 0.1·g2/2;
moteus: kp = g1·J, kd = g2·J, ki = kp·0.1·g2/2, ilimit 10 % of the torque limit) on the trapezoid at
the design's α_max — run on each drive's own loops with the drive's defaults for what those files
did not set (ODrive's encoder PLL 1000 rad/s, moteus' pll_filter_hz 400 Hz; the current loop at 3/T_si).
*After*: the tuned route (:mod:`sim.stock.tuning`), as the files now carry it.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

from pmsm_commissioning.app.io.presets import load
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.trapezoid import trapezoid_timing
from pmsm_commissioning.sim.fdsmc.checks import run_checks
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.stock.route import StockLoop, simulate_stock
from pmsm_commissioning.sim.stock.tuning import DRIVES, make_loop, tuned

CATALOGUE = Path(__file__).resolve().parent.parent / "tests" / "data" / "catalogue"
CASES = ("siemens_1ft7044_ak7", "yaskawa_sgm7a_50a", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "odrive_d5065_belt",
         str(CATALOGUE / "mjbots_mj5208_moteus.yaml"), str(CATALOGUE / "vesc_6374.yaml"))
#: The drives' own defaults for what the old files did not set: encoder PLL bandwidth [rad/s].
OLD_PLL = {"odrive": 1000.0, "moteus": 2.0 * math.pi * 400.0, "vesc": 1000.0, "setpoints": 1000.0}


def old_loop(name: str, p, d) -> StockLoop:
    """The loop the old files ran: eq. (61)'s g1, g2 transcribed (see the module doc)."""
    tr = trapezoid_timing(p.manoeuvre.theta_dem, d.alpha.alpha_max, p.manoeuvre.T_m)
    base = make_loop(DRIVES[name], p, tr, 1.0)
    g1, g2, J = d.conventional.g1, d.conventional.g2, p.J_total
    zero = 0.1 * 0.5 * g2
    if base.law == "pid":
        gains = {"kp": g1 * J, "kd": g2 * J, "ki": g1 * J * zero, "i_lim": 0.1 * base.K_t * base.current_limit}
    else:
        gains = {"kp": g1 / g2, "kd": g2 * J, "ki": g2 * J * zero}
    return dataclasses.replace(base, omega_e=OLD_PLL[name], **gains)


def cell(p, run) -> str:
    """Verdict, failed checks and the in-position time of one run."""
    failed = [c.name for c in run_checks(p, run) if c.violated]
    m = run.metrics
    when = "never" if m.in_position_s is None else f"{m.in_position_s:.3f} s"
    ovs = f"{m.overshoot_rad:.3g} rad" if m.overshoot_rad is not None else "—"
    return ("clean" if not failed else "NOT CLEAN: " + ", ".join(failed)) + f"; overshoot {ovs}; in position {when}"


def main() -> None:
    """Print the markdown table."""
    print("| case | T_m [s] | window [rad] | drive | before (eq. (61) transcribed) | after (tuned) | "
          "α/α_max | ω_v [rad/s] |")
    print("|" + "---|" * 8)
    for name in CASES:
        p = load(name, [], mode="position")
        d = derive(p)
        for drive in DRIVES:
            before = simulate_stock(p, old_loop(drive, p, d), d)
            tu = tuned(DRIVES[drive], p, d)
            head = f"| {p.name} | {p.manoeuvre.T_m:g} | {pass_criteria(p).in_position:.3g} | {drive} |"
            print(f"{head} {cell(p, before)} | {cell(p, tu.run)} | "
                  f"{tu.accel_fraction:g} | {tu.omega_v:.4g} |")


if __name__ == "__main__":
    main()
