"""The paper in the page: Table 1 as numbers, and each erratum of [1] beside the figure it affects.

Pure text (no viser). The errata are those of ``docs/paper_reproduction.md``: the observer of
eq. (15), the sign of eq. (62), T_c against eq. (59), the reversed Table 1 and the chatter of the
printed K = 1000 s/rad. Each results tab shows the ones that concern its figures
(:data:`ERRATA_OF_TAB`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from pmsm_commissioning.app.ui.text import html_text
from pmsm_commissioning.sim.fdsmc.table1 import printed_reversed

#: Erratum id → (equation, what [1] prints and what the engine does).
ERRATA: dict[str, tuple[str, str]] = {
    "observer": ("eq. (15)", "The observer as printed (e_o = θ̂_r − θ_r, dθ̂_r/dt = ω_r + K1·e_o) is unstable "
                             "(eigenvalue +K1). The engine uses e_o = θ_r − θ̂_r and dθ̂_r/dt = ω̂_r + K1·e_o: "
                             "all four poles at −q. The estimate Γ̂_L comes from it."),
    "conventional": ("eq. (62)", "The conventional law as printed, u = g1·(θ_dem − θ̂) + g2·ω̂, has its poles at "
                                 "+5.6/T_m (unstable). The engine uses −g2·ω̂: the polynomial of eq. (61)."),
    "T_c": ("eq. (59)", "Section 5 gives T_c = 5 ms, but eq. (59) gives T_c = T_a (24.1 ms at T_m = 1 s), and "
                        "eq. (52) assumes it. The paper preset uses eq. (59): the T_c slider marks it 'eq.59'."),
    "K": ("K = 1000 s/rad", "The printed boundary-layer gain limit-cycles (chatter, ≈ 270 Hz at 20 kHz): the "
                            "observer-based inner loop is not the ideal lag assumed. Below K_limit ('lim' on the "
                            "K slider) the drive slides without chatter."),
    "table1": ("Table 1", "The printed row is in reverse column order: read right to left it agrees with the "
                          "simulation within 0.07 points; as printed it is off by up to 2.8 points, with the "
                          "opposite trend."),
}
#: Results tab → the errata shown beside its figures.
ERRATA_OF_TAB: dict[str, tuple[str, ...]] = {
    "overview": ("K", "T_c", "conventional"),
    "time_plots": ("observer", "conventional"),
    "table1": ("table1",),
}


def errata_html(tab: str) -> str:
    """Return the errata of [1] that concern the figures of results tab ``tab``, one line each with the equation."""
    items = "".join(f'<li><b>{html_text(eq)}</b>: {html_text(text)}</li>'
                    for eq, text in (ERRATA[k] for k in ERRATA_OF_TAB[tab]))
    return (f'<div data-role="errata-{html_text(tab)}" style="font-size:14px;color:#495057">'
            f'<b>Errata in the paper, beside this figure</b><ul style="margin:2px 0 0 1.1em;padding:0">'
            f'{items}</ul></div>')


def _cell(value: float | None) -> str:
    return "—" if value is None else f"{value:.1f}"


def table1_html(rows: Sequence[Any], paper: Mapping[float, float]) -> str:
    """Table 1 as numbers: friction saving [%] per T_m — printed, printed reversed, simulated.

    Parameters
    ----------
    rows : sequence of sim.fdsmc.table1.Table1Row
        The sweep (``T_m`` [s], ``saving_pct`` [%]); empty before a sweep.
    paper : mapping T_m [s] → saving [%]
        The printed row of Table 1 in [1].
    """
    simulated = {r.T_m: r.saving_pct for r in rows}
    t_m = sorted(set(paper) | set(simulated))
    back = printed_reversed(paper)
    lines = (("printed in [1]", {k: paper.get(k) for k in t_m}),
             ("printed, columns reversed", {k: back.get(k) for k in t_m}),
             ("simulated, this drive" if rows else "simulated (run the sweep)", {k: simulated.get(k) for k in t_m}))
    style = 'style="padding:2px 8px;text-align:right"'
    head = "".join(f"<th {style}>{k:g}</th>" for k in t_m)
    body = "".join(f'<tr data-row="{i}"><th style="text-align:left;padding:2px 8px">{html_text(name)}</th>'
                   + "".join(f"<td {style}>{_cell(vals[k])}</td>" for k in t_m) + "</tr>"
                   for i, (name, vals) in enumerate(lines))
    return (f'<table data-role="table1" style="border-collapse:collapse;font-size:14px">'
            f'<tr><th style="text-align:left;padding:2px 8px">friction saving [%] at T_m [s]</th>{head}</tr>'
            f"{body}</table>")


__all__ = ["ERRATA", "ERRATA_OF_TAB", "errata_html", "table1_html"]
