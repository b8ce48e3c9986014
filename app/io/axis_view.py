"""The axis at the transmission's output: the move, load and results in load units, for the outputs.

The physics runs on the rotor's side (SI); with a transmission (:mod:`control.fdsmc.transmission`)
the engineer also wants the figures at the output: the move in degrees or mm, the load inertia or
mass, the error at T_m and the overshoot in degrees or µm, the peak speed in rpm or mm/s and the
peak torque or force delivered to the load. This module converts them (SI → display units at the
edge) for ``design``, ``simulate`` and the JSON; nothing here feeds the physics.
"""

from __future__ import annotations

import math
from typing import Any

from pmsm_commissioning.control.fdsmc import transmission as tx
from pmsm_commissioning.control.fdsmc.params import DriveParams

#: Output display units: (angle or travel, speed, inertia or mass, torque or force) per kind of axis.
_UNITS = {False: ("deg", "rpm", "kg·m²", "N·m"), True: ("mm", "mm/s", "kg", "N")}
#: SI output unit → display factor.
_SCALE = {"deg": 180.0 / math.pi, "rpm": 60.0 / (2.0 * math.pi), "mm": 1e3, "mm/s": 1e3, "kg·m²": 1.0, "kg": 1.0,
          "N·m": 1.0, "N": 1.0}
#: Run metrics shown at the output: metric key → kind (position, speed, torque).
RUN_KEYS = {"theta_error_at_Tm_rad": ("error_at_Tm_out", 0), "overshoot_rad": ("overshoot_out", 0),
            "omega_peak_rad_s": ("speed_peak_out", 1), "torque_peak_Nm": ("torque_peak_out", 3)}


def _show(x: float, kind: int, tr: tx.Transmission) -> tuple[float, str]:
    """Rotor-side SI value of ``kind`` → (output value in display units, unit)."""
    unit = _UNITS[tr.linear][kind]
    out = tx.torque_to_output(x, tr) if kind == 3 else tx.position_to_output(x, tr)
    return out * _SCALE[unit], unit


def transmission_json(params: DriveParams) -> dict[str, Any] | None:
    """Return the ``transmission`` entry of the JSON outputs: the data and the case at the output; None without one."""
    tr = params.transmission
    if tr.is_direct:
        return None
    move, move_unit = _show(params.manoeuvre.theta_dem, 0, tr)
    inertia_unit = _UNITS[tr.linear][2]
    return {"ratio": tr.ratio, "efficiency": tr.efficiency, "lead_m": tr.lead, "pulley_radius_m": tr.pulley_radius,
            "linear": tr.linear, "output_per_motor_rad": tr.k, "output_per_motor_rad_unit": "m/rad" if tr.linear
            else "rad/rad", "move": {"value": move, "unit": move_unit},
            "load_inertia": {"value": tx.inertia_to_output(params.load.J_L, tr), "unit": inertia_unit},
            "load_torque": dict(zip(("value", "unit"), _show(params.load.Gamma_Le, 3, tr), strict=True))}


def run_at_output(metrics: Any, params: DriveParams) -> dict[str, Any]:
    """Return a run's position error, overshoot, peak speed and peak torque at the output (display units)."""
    out: dict[str, Any] = {}
    for key, (name, kind) in RUN_KEYS.items():
        value = getattr(metrics, key, None)
        shown = None if value is None else _show(value, kind, params.transmission)
        out[name] = None if shown is None else {"value": shown[0], "unit": shown[1]}
    return out


def transmission_lines(params: DriveParams) -> list[str]:
    """Text lines stating the transmission and the case at the output (empty for a direct drive)."""
    j = transmission_json(params)
    if j is None:
        return []
    tr = params.transmission
    screw = (f", lead {tr.lead * 1e3:g} mm" if tr.lead else "") + (
        f", pulley radius {tr.pulley_radius * 1e3:g} mm" if tr.pulley_radius else "")
    return [f"Transmission: N = {tr.ratio:g} motor rev per output rev, η = {tr.efficiency:g}{screw} — at the output: "
            f"move {j['move']['value']:.5g} {j['move']['unit']} (motor {params.manoeuvre.theta_dem:.5g} rad), load "
            f"{j['load_inertia']['value']:.4g} {j['load_inertia']['unit']} (motor J_L {params.load.J_L:.4g} kg·m²), "
            f"load {j['load_torque']['value']:.4g} {j['load_torque']['unit']} "
            f"(motor Γ_Le {params.load.Gamma_Le:.4g} N·m)"]


def run_line(name: str, metrics: Any, params: DriveParams) -> str:
    """One text line of a run's results at the output."""
    parts = []
    for key, v in run_at_output(metrics, params).items():
        if v is not None:
            label = key.removesuffix("_out").replace("_", " ").replace("Tm", "T_m")
            if params.transmission.linear:
                label = label.replace("torque", "force")
            parts.append(f"{label} {v['value']:.4g} {v['unit']}")
    return f"{name} at the output: " + ", ".join(parts)


__all__ = ["run_at_output", "run_line", "transmission_json", "transmission_lines"]
