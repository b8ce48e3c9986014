"""Pure text for the page: derived-values table, warnings, savings estimate (no viser here).

The derived values are rendered generically from :func:`app.io.derived_view.derived_rows` so that
new rows appear on the page without changes here.
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass
from typing import Any

from app.io.derived_view import derived_rows
from control.fdsmc.derivations import Derived
from control.fdsmc.params import ParameterError

#: Joules per kilowatt-hour [J/kWh].
J_PER_KWH = 3.6e6


_MARKDOWN_SPECIAL = re.compile(r"([\\`*_{}\[\]()#+\-.!|~>=:])")


def md_text(text: object) -> str:
    """Make user-provided text safe to put in Markdown or HTML: shown literally, never as markup.

    User-provided text is a preset name/source, a file name or a message quoting them; it never becomes
    markup, links, images or code.

    HTML special characters become entities, Markdown punctuation is backslash-escaped and line breaks become
    spaces (a name cannot start a heading or a table row).
    """
    flat = " ".join(str(text).split())
    return _MARKDOWN_SPECIAL.sub(r"\\\1", html.escape(flat, quote=False))


def checked_choice(value: object, options: tuple[str, ...] | list[str], label: str) -> str:
    """Check a dropdown value the server received against the options it offered.

    Raises
    ------
    ParameterError
        When a (hostile or stale) client sent a value that was never offered.
    """
    if not isinstance(value, str) or value not in options:
        shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:80] + "…"
        raise ParameterError(f"{label} = {shown} is not one of the offered options: allowed {', '.join(options)}")
    return value


def derived_markdown(derived: Derived) -> str:
    """Markdown table of the derived values with units and equation numbers."""
    lines = ["| quantity | symbol | value | unit | ref. |", "|---|---|--:|---|---|"]
    for r in derived_rows(derived):
        lines.append(f"| {r.label} | {r.symbol} | {r.text()} | {r.unit} | {r.ref} |")
    return "\n".join(lines)


def warnings_html(items: list[str], error: str | None = None, notes: list[str] | None = None) -> str:
    """Render the input error and the warnings in a red box, or a green line when there are none.

    The ``notes`` (e.g. about the comparator) go in a grey box below.
    """
    extra = "".join(f'<div data-role="note" style="margin-top:4px;padding:4px 10px;border-radius:6px;'
                    f'background:#f1f3f5;color:#495057;font-size:0.8em">ℹ {html.escape(n)}</div>'
                    for n in notes or [])
    if error is None and not items:
        return ('<div style="padding:6px 10px;border-radius:6px;background:#ebfbee;color:#2b8a3e;'
                'font-size:0.85em">✔ No warnings.</div>' + extra)
    parts = []
    if error is not None:
        parts.append(f'<div data-role="input-error" style="font-weight:600">⛔ Input error — nothing '
                     f'simulated: {html.escape(error)}</div>')
    if items:
        lis = "".join(f"<li>{html.escape(w)}</li>" for w in items)
        parts.append(f'<div style="font-weight:600">⚠ {len(items)} warning(s)</div>'
                     f'<ul style="margin:4px 0 0 0;padding-left:18px">{lis}</ul>')
    return ('<div data-role="warnings" style="padding:8px 10px;border-radius:6px;background:#fff5f5;'
            'border:2px solid #e03131;color:#c92a2a;font-size:0.85em">' + "".join(parts) + "</div>" + extra)


@dataclass(frozen=True)
class AnnualSavings:
    """Energy and money the FDSMC saves per axis and year vs the conventional controller.

    Attributes
    ----------
    per_cycle_J : float   Electrical input energy saved per manoeuvre [J] (negative = costs more).
    kWh_per_year : float  Saved energy per year [kWh].
    money_per_year : float  Saved money per year [currency].
    """

    per_cycle_J: float
    kWh_per_year: float
    money_per_year: float


def design_markdown(dd: Any) -> str:
    """Verdict of "Design for this drive" (:class:`sim.fdsmc.design.DriveDesign`): clean, or what prevents it."""
    c = dd.params.controller
    head = ("**Design: clean** — simulated peaks within the drive's limits, on target at T_m, no chatter."
            if dd.clean else "**Design: not clean** — see the constraints below.")
    lines = [head, f"α_max = {dd.derived.alpha.alpha_max:.5g} rad/s², T_m = {dd.params.manoeuvre.T_m:g} s, "
                   f"K = {c.K:.4g} s/rad, T_c = {dd.derived.profile.T_c * 1e3:.4g} ms"]
    lines += [f"- {'✗' if x.violated else '·'} {md_text(x.text)}" for x in dd.limiting]
    lines += [f"- note: {md_text(n)}" for n in dd.notes]
    return "\n\n".join(lines[:2]) + "\n\n" + "\n".join(lines[2:])


def annual_savings(comparison: Any, cycles_per_hour: float, hours_per_year: float,
                   price_per_kWh: float) -> AnnualSavings | None:
    """Return the savings on the net electrical input energy over the simulated horizon; None without both runs.

    Parameters
    ----------
    comparison : sim.fdsmc.engine.Comparison
    cycles_per_hour : float  Manoeuvres per hour [1/h].
    hours_per_year : float   Operating hours per year [h].
    price_per_kWh : float    Energy price [currency/kWh].
    """
    f, c = comparison.fdsmc, comparison.conventional
    if f is None or c is None or not (f.metrics.get("stable") and c.metrics.get("stable")):
        return None
    e_f, e_c = f.metrics.get("electrical_in_total_J"), c.metrics.get("electrical_in_total_J")
    if not isinstance(e_f, float) or not isinstance(e_c, float):
        return None
    per_cycle = e_c - e_f
    kwh = per_cycle * cycles_per_hour * hours_per_year / J_PER_KWH
    return AnnualSavings(per_cycle, kwh, kwh * price_per_kWh)


def savings_markdown(s: AnnualSavings | None, currency: str = "€") -> str:
    """Markdown summary of :func:`annual_savings`."""
    if s is None:
        return "_Simulate both controllers (stable runs) to estimate the savings._"
    verb = "saves" if s.per_cycle_J >= 0 else "**costs more**:"
    return (f"FDSMC {verb} **{abs(s.per_cycle_J):.4g} J** electrical input per cycle → "
            f"**{s.kWh_per_year:.4g} kWh/year** and **{s.money_per_year:.4g} {currency}/year** per axis "
            "(negative = the conventional controller is cheaper).")


__all__ = ["AnnualSavings", "design_markdown", "annual_savings", "checked_choice", "derived_markdown", "md_text",
           "savings_markdown", "warnings_html"]
