"""Print the per-preset table of docs/drives/odrive.md: the stock route's settings and simulated energies.

.venv/bin/python scripts/stock_table.py
"""

from __future__ import annotations

import math

from app.cli.export import case
from app.exports.stock import stock_settings
from app.io.presets import load_preset
from sim.fdsmc.checks import saturation_matters

PRESETS = ("siemens_1ft7044_ak7", "yaskawa_sgm7a_50a", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "odrive_d5065_belt",
           "example_log_drive")


def main() -> None:
    """Print the markdown table."""
    print("| preset | T_m [s] | trap vel_limit [turn/s] | accel = decel [turn/s²] | pos_gain [1/s] | "
          "vel_gain [N·m/(turn/s)] | FDSMC [J] | optimum [J] | stock [J] | conventional [J] | stock route limited |")
    print("|" + "---|" * 11)
    for name in PRESETS:
        p = load_preset(name)
        cmp = case(p, "odrive")
        s = stock_settings(cmp)
        turn = 2.0 * math.pi
        e = [f"{r.metrics.electrical_in_total_J:.4g}" for r in (cmp.fdsmc, cmp.optimum, cmp.stock, cmp.conventional)]
        sat = cmp.stock.metrics.saturated_s
        limited = f"{sat * 1e3:.2g} ms" + (" (> 1 % of T_m)" if saturation_matters(p, cmp.stock.metrics) else "")
        print(f"| {name} | {p.manoeuvre.T_m:g} | {s.trapezoid.omega_c / turn:.4g} | {s.trapezoid.alpha / turn:.4g} | "
              f"{s.gains.pos_gain:.4g} | {s.gains.vel_gain * turn:.4g} | " + " | ".join(e) + f" | {limited} |")


if __name__ == "__main__":
    main()
