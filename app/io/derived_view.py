"""Presentation of :class:`control.fdsmc.derivations.Derived`: rows for tables and the stable JSON form.

Shared by the CLI (``derive``), the web UI's derived-values panel and the parameter exports.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pmsm_commissioning.app.io.json_data import to_json
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.loop_analysis import CHATTER_PTP_FRACTION


@dataclass(frozen=True)
class Row:
    """One derived value for display."""

    label: str
    symbol: str
    value: float | None
    unit: str
    ref: str

    def text(self) -> str:
        """Return the value formatted to 5 significant digits."""
        return f"{self.value:.5g}"


def derived_rows(d: Derived) -> list[Row]:
    """Return the derived values with units and equation references, in reading order."""
    o, pr, e, c = d.observer, d.profile, d.energy, d.conventional
    rows = [
        Row("Torque gain of acceleration", "H", d.coefficients.H, "rad/s²/A", "eq. (4)"),
        Row(f"Max. acceleration ({d.alpha.rule} rule)", "α_max", d.alpha.alpha_max, "rad/s²",
            "sec. 5" if d.alpha.rule == "paper" else "eq. (4b)"),
        Row("Torque α_max needs on J_r + J_L", "Γ(α_max)", d.alpha.torque_needed, "N·m", "eq. (4b)"),
        Row("Observer pole magnitude", "q", o.q, "1/s", "eq. (17)"),
        Row("Observer gain", "K1", o.K1, "1/s", "eq. (18)"),
        Row("Observer gain", "K2", o.K2, "1/s²", "eq. (18)"),
        Row("Observer gain", "K3", o.K3, "N·m/(rad·s)", "eq. (18)"),
        Row("Observer gain", "K4", o.K4, "N·m/(rad·s²)", "eq. (18)"),
        Row("Peak speed", "ω_p", pr.omega_p, "rad/s", "eq. (60)"),
        Row("Acceleration time", "T_a", pr.T_a, "s", "eq. (58)"),
        Row("Deceleration time 3·T_a", "T_d", pr.T_d, "s", "sec. 4.2"),
        Row("Sliding-mode time constant", "T_c", pr.T_c, "s", "eq. (59)"),
        Row("Shortest feasible manoeuvre", "T_m,min", pr.T_m_min, "s", "eq. (60)"),
        Row("Conventional gain", "g1", c.g1, "1/s²", "eq. (61)"),
        Row("Conventional gain", "g2", c.g2, "1/s", "eq. (61)"),
        Row("Friction energy, FDSMC", "W_L", e.W_fdsmc, "J", "eq. (52)"),
        Row("Friction energy, conventional", "W_conv", e.W_conventional, "J", "F_v·Δθ²·a/4"),
        Row("Friction energy, lower bound", "W_min", e.W_min, "J", "eq. (53)"),
        Row("Predicted friction saving", "saving", e.saving_pct, "%", "eqs. (52), (61)"),
        Row("Saving bound 1 − 4/5.6", "bound", e.bound_pct, "%", "eq. (53)"),
    ]
    if d.observer_discrete is not None:
        od = d.observer_discrete
        rows += [Row("Discrete observer pole", "z_o", od.z_pole, "-", "exp(−q/f_s)")] + [
            Row("Discrete observer gain", f"L{i + 1}", float(v), u, "Ackermann")
            for i, (v, u) in enumerate(zip(od.L, ("-", "1/s", "N·m/rad", "N·m/(rad·s)"), strict=True))
        ]
    rows += _loop_rows(d)
    return [r for r in rows if r.value is not None]


def _loop_rows(d: Derived) -> list[Row]:
    """Recommended K and sample-rate verdict of :mod:`control.fdsmc.loop_analysis`."""
    g, s = d.gain, d.sample_rate
    rows = [
        Row(f"K stability limit, linearised loop ({g.mode})", "K_limit", g.K_limit, "s/rad", "loop analysis"),
        Row(f"K noise limit, sensors (α_dem swings ≥ {100 * CHATTER_PTP_FRACTION:g} % of α_max)", "K_noise",
            g.K_noise_binding if math.isfinite(g.K_noise_binding) else None, "s/rad", "loop analysis"),
        Row(f"Recommended K (gain margin {g.margin:g}{', sensors' if g.noise_limited else ''})", "K_rec",
            g.K_recommended, "s/rad", "loop analysis"),
    ]
    if s.f_s is not None:
        rows += [
            Row("Spectral radius, sampled inner loops", "ρ", s.spectral_radius, "-", "loop analysis"),
            Row("Slowest stable sample rate", "f_s,min", s.f_s_min, "Hz", "loop analysis"),
        ]
    return rows


def derived_json(d: Derived) -> dict[str, Any]:
    """Return the stable JSON contract of ``derive --json`` (keys listed in the README)."""
    o, pr, e = d.observer, d.profile, d.energy
    out: dict[str, Any] = {
        "alpha_max": d.alpha.alpha_max,
        "alpha_max_rule": d.alpha.rule,
        "alpha_max_torque_Nm": d.alpha.torque_needed,
        "H": d.coefficients.H,
        "observer": {"q": o.q, "K1": o.K1, "K2": o.K2, "K3": o.K3, "K4": o.K4},
        "omega_p": pr.omega_p,
        "T_a": pr.T_a,
        "T_d": pr.T_d,
        "T_c": pr.T_c,
        "T_m_min": pr.T_m_min,
        "feasible": pr.feasible,
        "g1": d.conventional.g1,
        "g2": d.conventional.g2,
        "W_fdsmc_eq52_J": e.W_fdsmc,
        "W_conventional_J": e.W_conventional,
        "W_min_J": e.W_min,
        "saving_predicted_pct": e.saving_pct,
        "saving_bound_pct": e.bound_pct,
        "feasibility": to_json(d.feasibility),
        "warnings": list(d.warnings),
        # a K limit that does not exist (the loop is never or always unstable) becomes null
        "loop": {**to_json(d.gain), "noise_limited": d.gain.noise_limited},
        "sample_rate": to_json(d.sample_rate),
    }
    if d.observer_discrete is not None:
        od = d.observer_discrete
        out["observer_discrete"] = {
            "f_s": 1.0 / od.T_s, "z_pole": od.z_pole,
            **{f"L{i + 1}": float(v) for i, v in enumerate(od.L)},
        }
    return out


def format_table(rows: list[Row]) -> str:
    """Plain-text table of rows for the terminal."""
    w_label = max(len(r.label) for r in rows)
    w_sym = max(len(r.symbol) for r in rows)
    lines = [
        f"{r.label:<{w_label}}  {r.symbol:<{w_sym}}  {r.text():>12} {r.unit:<14} {r.ref}" for r in rows
    ]
    return "\n".join(lines)
