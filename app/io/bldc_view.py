"""Presentation of a BLDC comparison: the side-by-side metric table and the stable JSON form.

Shared by the page's BLDC tab and ``pmsm-commission bldc``.
"""

from __future__ import annotations

from typing import Any

from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.app.io.numbers import format_metric
from pmsm_commissioning.app.io.units import rad_s_to_rpm
from pmsm_commissioning.control.bldc.design import BldcDesign
from pmsm_commissioning.sim.bldc.engine import LABELS, BldcComparison
from pmsm_commissioning.sim.bldc.metrics import BldcMetrics

#: (JSON key, label, unit, format) of the side-by-side table, in reading order.
METRIC_ROWS: tuple[tuple[str, str, str, str], ...] = (
    ("speed_error_ss_rpm", "Steady-state speed error", "rpm", ".3f"),
    ("overshoot_rpm", "Overshoot", "rpm", ".2f"),
    ("recovery_time_s", "Recovery after load steps (longest)", "s", ".4f"),
    ("torque_ripple_pct", "Torque ripple (p-p / mean)", "%", ".2f"),
    ("reach_time_s", "Time to reach ω*", "s", ".4f"),
    ("i_peak_A", "Peak phase current", "A", ".2f"),
    ("v_peak_V", "Peak phase voltage", "V", ".1f"),
    ("torque_peak_Nm", "Peak torque", "N·m", ".2f"),
    ("copper_loss_J", "Copper loss", "J", ".3f"),
    ("copper_loss_mean_W", "Mean copper loss power", "W", ".2f"),
    ("energy_balance_residual_pct", "Energy-balance residual", "%", ".2e"),
)


#: Speed scale of the rpm keys [rpm per rad/s].
RPM_PER_RAD_S = rad_s_to_rpm(1.0)


def _rpm(omega: float | None) -> float | None:
    return None if omega is None else omega * RPM_PER_RAD_S


def metrics_json(m: BldcMetrics) -> dict[str, Any]:
    """One run's metrics as JSON data: the dataclass fields, the two speeds in rpm."""
    rpm_keys = {"speed_error_ss_rad_s": "speed_error_ss_rpm", "overshoot_rad_s": "overshoot_rpm"}
    return {rpm_keys.get(k, k): _rpm(v) if k in rpm_keys else v for k, v in to_json(m).items()}


def metric_table(comp: BldcComparison) -> list[list[str]]:
    """Header + one row per metric, one column per controller (text cells)."""
    head = ["metric", "unit"] + [r.controller for r in comp.runs]
    rows = [head]
    values = [metrics_json(r.metrics) for r in comp.runs]
    for key, label, unit, fmt in METRIC_ROWS:
        rows.append([label, unit] + [format_metric(v[key], fmt) for v in values])
    return rows


def design_json(d: BldcDesign) -> dict[str, Any]:
    """Return the derived values of a case as plain JSON data (SI units)."""
    return {
        "K_Tx_Nm_per_A": d.K_Tx, "K_T_fig7_Nm_per_A": d.K_T_fig7, "i_qx_max_A": d.i_qx_max,
        "current_loop_gain_V_per_A": d.current.gain, "current_loop_bandwidth_rad_s": d.current.bandwidth,
        "current_loop_discrete_gain": d.current.discrete_gain, "T_L_max_Nm": d.T_L_max,
        "eps_plain_ss_predicted_rad_s": d.eps_plain_ss, "E_line_peak_V": d.E_line_peak,
        "pi_gains": {"K_p_i": d.pi.K_p_i, "K_i_i": d.pi.K_i_i, "K_p_w": d.pi.K_p_w, "K_i_w": d.pi.K_i_w,
                     "K_T": d.pi.K_T},
        "reachability_ok": d.reachability.ok,
        "reachability_violated_rad_s": [list(v) for v in d.reachability.violated],
    }


def anti_windup_text(comp: BldcComparison) -> str:
    """``"anti-windup on"`` or ``"anti-windup off (λ = λ_0)"``: how the integral surfaces of eq. (16) ran."""
    return "anti-windup on" if comp.anti_windup else "anti-windup off (λ = λ_0)"


def comparison_json(comp: BldcComparison) -> dict[str, Any]:
    """Return the stable JSON form: scenario, design, per-controller metrics, warnings."""
    case = comp.params.case
    return {
        "preset": comp.params.name,
        "scenario": {"name": case.name, "omega_0_rad_s": case.omega_0, "omega_ref_rad_s": case.omega_ref,
                     "t_end_s": case.t_end, "emf": comp.params.machine.emf},
        "design": design_json(comp.design),
        "anti_windup": comp.anti_windup,
        "controllers": {r.controller: {"label": LABELS[r.controller], **metrics_json(r.metrics)}
                        for r in comp.runs},
        "warnings": list(comp.design.warnings),
    }
