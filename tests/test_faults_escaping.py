"""No script in the page or the report: every user string reaching Markdown or HTML goes
through :func:`app.ui.text.md_text` / :func:`app.ui.text.html_text` (the browser test in
``tests/browser/test_hostile_page.py`` shows that no script runs in a real page).
"""

from __future__ import annotations

import dataclasses
import re
from types import SimpleNamespace

import numpy as np

from pmsm_commissioning.app.exports.html import html_report
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.app.ui.log import identified_markdown, overlay_markdown
from pmsm_commissioning.app.ui.text import html_text, md_text, warnings_html
from pmsm_commissioning.control.fdsmc.identification import Estimate, Identification
from pmsm_commissioning.sim.drivelog.overlay import SignalError
from pmsm_commissioning.sim.fdsmc.engine import compare

SCRIPT = '<img src=x onerror=alert(1)><script>alert(2)</script><iframe srcdoc="x"></iframe>'
#: Raw HTML that would run or load something: never in the escaped output.
ACTIVE = re.compile(r"<(img|script|iframe|svg)\b", re.I)


def test_md_text_and_html_text_leave_no_active_markup():
    for text in (SCRIPT, f"# {SCRIPT}", f"[x](javascript:alert(1)) {SCRIPT}", '" onmouseover="alert(1)'):
        assert not ACTIVE.search(md_text(text)) and not ACTIVE.search(html_text(text))
    assert html_text('a"b\'c') == "a&quot;b&#x27;c"  # safe inside an attribute too


def test_log_summary_escapes_file_name_headers_and_notes():
    log = SimpleNamespace(name=f"x{SCRIPT}.csv", signals={"t": np.zeros(30)}, T_s=1e-4,
                          notes=(f"ignored column(s) alpha [{SCRIPT}]",))
    ov = SimpleNamespace(t0=0.0, t0_detected=True, errors=(SignalError(f"i_q{SCRIPT}", "A", 0.1, 0.2),),
                         energy_measured_J=None, energy_simulated_J=None)
    text = overlay_markdown(log, ov)
    assert not ACTIVE.search(text) and "&lt;script&gt;" in text


def test_identification_table_escapes_refusals():
    r = Identification((Estimate("R_s", "Ω", refused=f"not excited {SCRIPT}"),), None, None, None, 0, 0)
    assert not ACTIVE.search(identified_markdown(r))


def test_warning_box_escapes():
    assert not ACTIVE.search(warnings_html([SCRIPT], error=SCRIPT, notes=[SCRIPT]))


def test_html_report_escapes_name_source_and_warnings():
    params = dataclasses.replace(load_preset("paper_12kw_pmsm"), name=f"n{SCRIPT}", source=f"s{SCRIPT}")
    page = html_report(compare(params, ("fdsmc", "conventional")))
    body = page.split("<h2>Figures</h2>")[0]  # before Plotly's own script tags
    assert not ACTIVE.search(body) and "n&lt;img src=x" in body and "s&lt;img src=x" in body
    assert "alert(2)</script>" not in page.split("<h2>Figures</h2>")[1]  # figure JSON escapes "<" too
