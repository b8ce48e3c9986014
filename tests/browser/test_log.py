"""Drive-log section of the web UI: example log, upload, overlay, identified values, apply."""

from __future__ import annotations

import re
import shutil

from pmsm_commissioning.app.ui.log import EXAMPLE_LOG
from pmsm_commissioning.sim.drivelog.synthetic import TRUE_MOTOR
from tests.browser.conftest import click_tab, figure


def _session(ui_server, page):
    """The server-side session of ``page`` (the newest one)."""
    return ui_server.config.sessions[max(ui_server.config.sessions)]


def _runs_text(page, n: int) -> None:
    page.wait_for_function("(n) => document.body.innerText.includes(`Ready — ${n} run(s) in this session`)",
                           arg=n)


def test_upload_log_overlay_identify_apply_and_simulate_again(page, ui_server, tmp_path):
    session = _session(ui_server, page)
    runs = session.runs
    page.get_by_text("Drive log (measured)").click()
    page.get_by_role("button", name="Load example log").click()
    page.get_by_text(re.compile(r"drive_log_dq\.csv: 6800 samples at 10000 Hz")).wait_for()
    click_tab(page, "Drive log")
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')]"
                           ".some(e => e.layout && e.layout.meta && e.layout.meta.id === 'log-overlay')")
    _runs_text(page, runs + 1)

    mine = tmp_path / "bench_log.csv"  # an upload, through the browser's file input
    shutil.copy(EXAMPLE_LOG, mine)
    page.locator("input[type=file][accept*='.csv']").set_input_files(str(mine))
    page.get_by_text(re.compile(r"bench_log\.csv: 6800 samples at 10000 Hz")).wait_for()
    page.wait_for_function("() => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && "
                           "e.layout.meta && e.layout.meta.id === 'log-overlay' && "
                           "e.layout.title.text.includes('bench_log.csv'))")
    fig = figure(page, "log-overlay")
    assert "bench_log.csv" in fig["title"] and {t["name"] for t in fig["traces"]} == {"measured", "simulated"}
    body = page.inner_text("body")
    assert "Electrical input energy: measured" in body
    row = re.search(r"R_s\s+([0-9.]+)\s+([0-9.e-]+)\s+\[([0-9.]+), ([0-9.]+)\]", body)
    assert row is not None and float(row.group(3)) <= TRUE_MOTOR["R_s"] <= float(row.group(4))

    page.get_by_role("button", name="Apply identified values").click()
    _runs_text(page, runs + 2)
    params = session.params  # the new run's inputs, collected from the page's fields
    assert abs(params.motor.R_s / TRUE_MOTOR["R_s"] - 1.0) < 0.02
    assert abs(params.motor.L_q / TRUE_MOTOR["L_q"] - 1.0) < 0.02
    assert "identified from drive log bench_log.csv" in params.source


def test_bad_log_upload_is_rejected_with_the_reason(page, tmp_path):
    page.get_by_text("Drive log (measured)").click()
    bad = tmp_path / "unsorted.csv"
    bad.write_text("t [s],i_q [A]\n" + "\n".join(f"{1 - k * 1e-3},{k}" for k in range(30)), encoding="utf-8")
    page.locator("input[type=file][accept*='.csv']").set_input_files(str(bad))
    page.get_by_text(re.compile(r"time does not increase at line 3")).wait_for()
    assert "No log loaded." in page.inner_text("body")
