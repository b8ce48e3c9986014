"""Pure text for the page: derived-values table, warnings, key numbers, the design verdict (no viser here).

Input checks are in :mod:`app.ui.choices`, the savings estimate in :mod:`app.ui.savings`.

The derived values are rendered generically from :func:`app.io.derived_view.derived_rows` so that
new rows appear on the page without changes here.
"""

from __future__ import annotations

import html
import re
from typing import Any

from pmsm_commissioning.app.figures.fdsmc_pins import pins_note
from pmsm_commissioning.app.figures.style import BAD_COLOUR, GOOD_COLOUR, KEY_PX, fmt
from pmsm_commissioning.app.io.derived_view import derived_rows
from pmsm_commissioning.app.io.user_text import html_text
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.feasibility import torque_limit
from pmsm_commissioning.sim.fdsmc.criteria import pass_criteria
from pmsm_commissioning.sim.fdsmc.engine import LABELS
from pmsm_commissioning.sim.fdsmc.recommend import recommend

_MARKDOWN_SPECIAL = re.compile(r"([\\`*_{}\[\]()#+\-.!|~>=:])")


def md_text(text: object) -> str:
    """Make user-provided text safe to put in Markdown or HTML: shown literally, never as markup.

    User-provided text is a preset name/source, a file name, a column header or a message quoting
    them; it never becomes markup, links, images or code. Viser renders raw HTML inside Markdown,
    so every user string reaching a Markdown widget goes through here.

    HTML special characters become entities, Markdown punctuation is backslash-escaped and line breaks become
    spaces (a name cannot start a heading or a table row).
    """
    flat = " ".join(str(text).split())
    return _MARKDOWN_SPECIAL.sub(r"\\\1", html.escape(flat, quote=False))


def derived_markdown(derived: Derived) -> str:
    """Markdown table of the derived values with units and equation numbers."""
    lines = ["| quantity | symbol | value | unit | ref. |", "|---|---|--:|---|---|"]
    for r in derived_rows(derived):
        lines.append(f"| {r.label} | {r.symbol} | {r.text()} | {r.unit} | {r.ref} |")
    return "\n".join(lines)


def warnings_html(items: list[str], error: str | None = None, notes: list[str] | None = None,
                  folded: bool = False) -> str:
    """Render the input error and the warnings in a red box, or a green line when there are none.

    The ``notes`` (e.g. about the comparator) go in a grey box below. The warnings are an HTML
    ``<details>`` list, open unless ``folded``: a click on its summary line ("⚠ 6 warning(s) — first
    warning…") folds it to that one line in the browser, and a second click opens it again.
    """
    extra = "".join(f'<div data-role="note" style="margin-top:4px;padding:4px 10px;border-radius:6px;'
                    f'background:#f1f3f5;color:#495057;font-size:14px">ℹ {html_text(n)}</div>'
                    for n in notes or [])
    if error is None and not items:
        return (f'<div style="padding:6px 10px;border-radius:6px;background:#ebfbee;color:{GOOD_COLOUR};'
                'font-size:14px">✔ No warnings.</div>' + extra)
    parts = []
    if error is not None:
        parts.append(f'<div data-role="input-error" style="font-weight:600">⛔ Input error — nothing '
                     f'simulated: {html_text(error)}</div>')
    if items:
        lis = "".join(f"<li>{html_text(w)}</li>" for w in items)
        parts.append(f'<details{"" if folded else " open"} data-role="warnings-list">'
                     '<summary data-role="warnings-summary" '
                     'style="cursor:pointer;white-space:nowrap;overflow:hidden;text-overflow:ellipsis">'
                     f'<b>⚠ {len(items)} warning(s)</b> <span style="font-weight:400">— {html_text(items[0])}'
                     f'</span></summary><ul style="margin:4px 0 0 0;padding-left:18px">{lis}</ul></details>')
    return ('<div data-role="warnings" style="padding:8px 10px;border-radius:6px;background:#fff5f5;'
            f'border:2px solid #e03131;color:{BAD_COLOUR};font-size:14px">' + "".join(parts) + "</div>" + extra)


def _saves(pct: float | None) -> str:
    """Word a saving [%]: "saves 25.2 %", "costs 3.1 % more" or "saving –" (not both runs stable)."""
    if pct is None:
        return "saving –"
    return f"saves {pct:.1f} %" if pct >= 0 else f"costs {-pct:.1f} % more"


def pins_html(pins: Any) -> str:
    """Return the pinned runs for under the pin buttons: one small grey line each (labels escaped), or nothing."""
    if not pins:
        return ""
    lines = "".join(f"<div>{html_text(line)}</div>" for line in pins_note(tuple(pins)).splitlines())
    return f'<div data-role="pins" style="font-size:14px;color:#495057">{lines}</div>'


def key_numbers_html(comparison: Any) -> str:
    """Render the key numbers above the overview figure: the supply's energy first.

    The energy the supply delivers [J] (whole run) under the DC-link choice ``controller.dc_link``
    (named) of every simulated controller with its copper and friction losses, the recommended
    controller (:func:`sim.fdsmc.recommend.recommend`), then the paper's friction saving and the
    peak torques [N·m] vs the drive's limit (red when above).
    """
    f, c = comparison.fdsmc, comparison.conventional
    if f is None:
        return '<div data-role="key-numbers" style="font-size:16px">Not simulated (infeasible manoeuvre).</div>'
    g_max = torque_limit(comparison.derived.params)
    rec = recommend(comparison.derived.params, comparison)

    def peak(r: Any) -> str:
        v = r.metrics.torque_peak_Nm if r is not None else None
        if v is None:
            return "–"
        return f'<b style="color:{BAD_COLOUR}">{fmt(v, digits=3)} ⚠</b>' if v > g_max * 1.001 else fmt(v, digits=3)

    energies = " · ".join(
        f"{'<b>' if e.controller == rec.controller else ''}{LABELS[e.controller]} {fmt(e.dc_link_J, 'J', 3)}"
        f"{'</b>' if e.controller == rec.controller else ''} ({fmt(e.copper_J, digits=2)} Cu + "
        f"{fmt(e.friction_J, digits=2)} fr.)"
        for e in rec.energies)
    best = f"recommended: <b>{LABELS[rec.controller]}</b>" if rec.controller else "no controller passes every check"
    ctrl = comparison.derived.params.controller
    link = ctrl.dc_link.replace("_", " ") + (f" η_ch {ctrl.charge_efficiency:g}" if ctrl.dc_link == "battery" else "")
    head = f'<b>From the supply</b> <span data-role="dc-link">(DC link: {html_text(link)})</span>'
    parts = [f"{head} {energies}", best,
             f"FDSMC {_saves(comparison.saving_friction_pct)} friction vs conventional",
             f"peak Γ {peak(f)} / {peak(c)} N·m vs Γ_max {fmt(g_max, digits=3)} N·m"]
    return (f'<div data-role="key-numbers" style="font-size:{KEY_PX}px;line-height:1.3;padding:2px 2px 4px 2px">'
            + " · ".join(parts) + "</div>")


def design_markdown(dd: Any) -> str:
    """Verdict of "Design for this drive" (:class:`sim.fdsmc.design.DriveDesign`) with the verified figures.

    Clean (every check holds with the sensors at the requested T_m), not as asked (only at a longer
    T_m) or not clean (the constraints say why); then the peak current, overshoot, in-position time
    and standstill ripple of the verification run against their limits.
    """
    c = dd.params.controller
    head = {"clean": "**Design: CLEAN** — with the sensors: limits, in-position, overshoot and ripple all hold.",
            "not as asked": "**Design: NOT AS ASKED** — clean only at a longer T_m than requested.",
            "not clean": "**Design: NOT CLEAN** — see the constraints below."}[dd.verdict]
    if dd.refused:  # there is no setting to show
        lines = [head, "Nothing designed or simulated; the inputs stay as they were."]
    else:
        lines = [head, f"α_max = {dd.derived.alpha.alpha_max:.5g} rad/s², T_m = {dd.params.manoeuvre.T_m:g} s, "
                       f"K = {c.K:.4g} s/rad, T_c = {dd.derived.profile.T_c * 1e3:.4g} ms, "
                       f"T_so = {c.T_so * 1e3:.4g} ms, T_sα = {c.T_salpha * 1e3:.4g} ms"]
    if dd.comparison is not None and dd.comparison.fdsmc is not None:
        lines.append(_verified_figures(dd))
    lines += [f"- {'✗' if x.violated else '·'} {md_text(x.text)}" for x in dd.limiting]
    lines += [f"- note: {md_text(n)}" for n in dd.notes]
    return "\n\n".join(lines[:3]) + "\n\n" + "\n".join(lines[3:])


def _verified_figures(dd: Any) -> str:
    """One line of the verification run's figures against the pass criteria."""
    m, crit = dd.comparison.fdsmc.metrics, pass_criteria(dd.params)
    inpos = "never" if m.in_position_s is None else f"{m.in_position_s:.3g} s"
    return (f"Verified: peak |i_dq| {m.i_peak_A:.3g} A (limit {crit.i_limit:.3g} A) · overshoot "
            f"{m.overshoot_rad:.2g} rad (≤ {crit.overshoot:.2g}) · in position {inpos} (±{crit.in_position:.2g} rad) · "
            f"standstill ripple {m.hold_i_q_rms_A:.2g} A rms (≤ {crit.hold_i_rms:.2g})")


def design_failure_items(dd: Any) -> list[str]:
    """Return the warnings of a design that is not clean: its verdict, the constraints and the verified alternatives."""
    head = ("Design refused before any run — nothing designed or simulated" if dd.refused else
            f"Design: {dd.verdict.upper()}")
    named = ("T_m", "current", "in_position_by_T_m")
    items = [f"{head}: {c.text}" for c in dd.limiting if c.violated or c.name in named]
    if not items:
        items = [f"{head}."]
    return items + [f"Alternative: {a.text}" for a in dd.alternatives]


def stale_results_html(dd: Any) -> str:
    """Return the banner that replaces the key numbers when a design fails: the figures below are not current."""
    why = next((c.text for c in dd.limiting if c.violated), dd.verdict)
    return ('<div data-role="stale-results" style="padding:6px 10px;border-radius:6px;background:#fff4e6;'
            f'color:#a33b00;font-weight:600">⚠ Stale results: the figures below are of the previous run, not of '
            f'these inputs — the design failed: {html_text(why)}</div>')


__all__ = ["derived_markdown", "design_failure_items", "design_markdown", "html_text", "key_numbers_html", "md_text",
           "stale_results_html", "warnings_html"]


def stock_html(comparison: Any) -> str:
    """Return the stock routes' verdicts, one line per drive (ODrive, moteus, VESC, setpoint table), green or red."""
    from pmsm_commissioning.app.io.stock_view import stock_lines  # tunes the vendor routes (cached per case)

    if getattr(comparison, "stock", None) is None:
        return "<p>Stock route: not simulated for this case.</p>"
    items = []
    for line in stock_lines(comparison):
        colour = GOOD_COLOUR if ": CLEAN," in line else BAD_COLOUR
        items.append(f'<li style="color:{colour}">{html_text(line)}</li>')
    return ('<div class="stock-verdicts" style="font-size:14px"><p>Each drive file runs its own loops, '
            "tuned and simulated with this case's sensors, limits and pass criteria; the export gate uses "
            "that verdict.</p><ul>" + "".join(items) + "</ul></div>")
