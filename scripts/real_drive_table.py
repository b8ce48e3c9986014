"""Print the real-drive verdict table of docs/real_drive.md: every real preset designed with its sensors.

For each preset: the design (T_so, T_sα, K, T_c), the verdict, and the verification run's peak |i_dq|
against the hard limit, standstill i_q ripple (simulated and predicted), overshoot and in-position
time — with the preset's sensors, and the same design run with ideal sensors.

    .venv/bin/python scripts/real_drive_table.py
"""

from __future__ import annotations

import dataclasses

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.params import Sensors
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.engine import simulate
from pmsm_commissioning.sim.fdsmc.objective import design_for

PRESETS = ("siemens_1ft7044_ak7", "yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "yaskawa_sgm7a_50a",
           "odrive_d5065_belt")


def _row(name: str) -> list[str]:
    # a regenerative DC link: the net electrical input, the objective the shipped presets were designed for
    od = design_for(load_preset(name, ["controller.dc_link=regenerative"]))
    dd = od.design
    p, c = dd.params, dd.params.controller
    e = {x.controller: x.net_electrical_J for x in od.recommendation.energies}
    m = dd.comparison.fdsmc.metrics
    crit = pass_criteria(p)
    same_window = dataclasses.replace(p.limits, in_position=crit.in_position)  # not the ideal encoder's default
    ideal = simulate(dataclasses.replace(p, sensors=Sensors(), limits=same_window), "fdsmc").metrics

    def inpos(x: float | None) -> str:
        return "never" if x is None else f"{x:.3f}"

    tc = "T_a" if c.T_c == "T_a" else f"{float(c.T_c) * 1e3:.3g} ms"
    energy = " / ".join(f"{e[k]:.3g}" for k in ("fdsmc", "optimum", "stock", "conventional"))
    return [f"`{name}`", f"{p.sensors.encoder_cpr}", dd.verdict, c.alpha_max_rule, energy,
            f"{c.T_so * 1e3:.3g} / {c.T_salpha * 1e3:.3g}",
            f"{c.K:.4g}", tc, f"{m.i_peak_A:.4g} / {current_limit(p):.4g}",
            f"{m.hold_i_q_rms_A:.3g} ({dd.noise.i_q_rms:.3g}) / {crit.hold_i_rms:.3g}",
            f"{ideal.hold_i_q_rms_A:.2g}", f"{m.overshoot_rad:.2g} / {ideal.overshoot_rad:.2g} / {crit.overshoot:.2g}",
            f"{inpos(m.in_position_s)} / {inpos(ideal.in_position_s)} (T_m {p.manoeuvre.T_m:g})"]


def main() -> None:
    """Print the markdown table."""
    head = ["preset", "encoder [counts/rev]", "verdict", "α rule",
            "net electrical FDSMC / optimum / stock / conv. [J]", "T_so / T_sα [ms]", "K [s/rad]", "T_c",
            "peak |i_dq| / limit [A]", "ripple sim (predicted) / limit [A rms]", "ripple, ideal sensors",
            "overshoot sensors / ideal / limit [rad]", "in position sensors / ideal [s]"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for name in PRESETS:
        print("| " + " | ".join(_row(name)) + " |")


if __name__ == "__main__":
    main()
