"""Browser test of the "BLDC speed SMC" tab: open it, run the paper scenario, read the
metrics table and a figure. Uses the UI fixtures of ``tests/browser/conftest.py`` (fails, not
skips, under CI=true when Chromium is missing).
"""

from __future__ import annotations

from tests.browser.conftest import click_tab, field, figure

FIG_JS = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
          " && e.layout.meta.id === id && e.data.length >= 4)")


def _open_tab(page) -> None:
    click_tab(page, "BLDC speed SMC")
    page.get_by_role("button", name="Simulate BLDC").wait_for()


def test_bldc_tab_runs_paper_scenario_and_shows_metrics_and_speed_figure(page):
    _open_tab(page)
    page.get_by_role("button", name="Simulate BLDC").click()
    click_tab(page, "BLDC figures")  # the figures live in the wide results panel
    page.wait_for_function(FIG_JS, arg="bldc_speed", timeout=60_000)
    page.get_by_text("Steady-state speed error").first.wait_for()
    # metrics table: one row per metric, one column per drive
    row = page.locator("tr", has_text="Steady-state speed error").first
    cells = [c.strip() for c in row.locator("td").all_inner_texts()]
    assert cells[1] == "rpm" and len(cells) == 6  # metric, unit, then the four drives
    integral, plain, six_step = float(cells[2]), float(cells[3]), float(cells[5])
    assert integral < 0.5 < plain and six_step < 0.5
    ripple = [c.strip() for c in page.locator("tr", has_text="Torque ripple").first.locator("td").all_inner_texts()]
    assert float(ripple[2]) < float(ripple[4])  # dq_x SMC vs sinusoidal dq PI
    assert float(ripple[2]) < float(ripple[5])  # dq_x SMC vs six-step
    fig = figure(page, "bldc_speed")
    names = {t["name"]: t for t in fig["traces"]}
    assert {"ω*", "T_L"} <= set(names)
    paper = names["dq_x + SMC, integral surface (paper)"]
    assert len(paper["y"]) > 500 and max(paper["y"]) > 990.0  # reaches 1000 rpm (x0/dx: no x array)
    assert figure(page, "bldc_torque") is not None
    # in the folded folder: drawn once it is unfolded (a plot in a box of width 0 is not drawn)
    assert figure(page, "bldc_reach") is None
    page.get_by_text("More: σ_ω, phase currents, back-EMF, dq_x, reachability").click()
    page.wait_for_function(VISIBLE_JS, arg="bldc_reach")
    assert figure(page, "bldc_reach") is not None and figure(page, "bldc_dqx") is not None


VISIBLE_JS = ("(id) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
              " && e.layout.meta.id === id && e.getBoundingClientRect().width > 0)")
SELECTED_JS = ("(name) => document.querySelector(`[role=\"tab\"][title=\"${name}\"]`)"
               "?.getAttribute('aria-selected') === 'true'")


def test_choosing_the_bldc_tab_shows_its_own_results_and_back(page):
    """The BLDC tab selects its results tab on the right; the position tab brings the overview back."""
    assert page.evaluate(VISIBLE_JS, "phase_plane")
    _open_tab(page)
    page.wait_for_function(SELECTED_JS, arg="BLDC figures")
    page.wait_for_function(VISIBLE_JS, arg="bldc_torque")
    assert page.evaluate(VISIBLE_JS, "bldc_speed")
    assert not page.evaluate(VISIBLE_JS, "phase_plane")  # the FDSMC overview is no longer what the right panel shows
    click_tab(page, "Position drive (FDSMC)")
    page.wait_for_function(SELECTED_JS, arg="Overview")
    page.wait_for_function(VISIBLE_JS, arg="phase_plane")
    assert not page.evaluate(VISIBLE_JS, "bldc_speed")


def test_anti_windup_toggle_runs_the_paper_drive_with_and_without_side_by_side(page):
    """Side by side, the paper drive without anti-windup (λ = λ_0) overshoots 1000 rpm; with it, it does not."""
    _open_tab(page)
    page.get_by_text("Paper drive with / without anti-windup, side by side", exact=True).click()
    page.wait_for_timeout(150)  # viser sends GUI updates every 50 ms
    page.get_by_role("button", name="Simulate BLDC").click()
    page.wait_for_function(FIG_JS, arg="bldc_antiwindup", timeout=60_000)
    traces = figure(page, "bldc_antiwindup")["traces"]
    speed = {t["name"]: max(t["y"]) for t in traces if t["name"].startswith(("with anti-windup", "without"))}
    (with_name, with_max), (without_name, without_max) = sorted(speed.items())
    assert with_name.startswith("with anti-windup") and without_name.startswith("without")
    assert with_max < 1010.0 < 1100.0 < without_max  # ω* = 1000 rpm: the wound-up integral overshoots
    torque = figure(page, "bldc_torque")["traces"]  # one panel per drive: 4 drives × (T_EL, T*) × 2 columns
    assert len(torque) == 16 and {t["name"] for t in torque} >= {"T* (reference)"}


def test_anti_windup_off_keeps_the_typed_eps_lambda_in_the_inputs_and_the_downloaded_preset(page):
    """Unticking the anti-windup runs λ = λ_0; ε_λ stays what was typed (it was replaced by 1e5 rad/s)."""
    from pathlib import Path

    from pmsm_commissioning.app.io.presets import load_preset, loads_preset

    typed = load_preset("bldc_smc_paper").gains.eps_lambda
    _open_tab(page)
    page.get_by_text("Anti-windup on λ(ε)", exact=True).click()
    page.wait_for_timeout(150)  # viser sends GUI updates every 50 ms
    page.get_by_role("button", name="Simulate BLDC").click()
    page.get_by_text("anti-windup off", exact=False).first.wait_for(timeout=60_000)  # the run had it off
    click_tab(page, "BLDC figures")
    overshoot = page.locator("tr", has_text="Overshoot").first.locator("td").all_inner_texts()
    assert float(overshoot[2]) > 500.0  # the paper drive's integral wound up [rpm]
    with page.expect_download() as info:
        page.get_by_role("button", name="Download BLDC preset (YAML)").click()
    exported = loads_preset(Path(info.value.path()).read_text(encoding="utf-8"), "export.yaml")
    assert exported.gains.eps_lambda == typed


def test_bldc_tab_rejects_bad_input_with_message(page):
    _open_tab(page)
    page.get_by_text("Machine, load, inverter, gains", exact=True).click()
    inp = field(page, "V_dc [V]")
    inp.fill("-5")
    inp.press("Tab")
    page.wait_for_timeout(200)
    page.get_by_role("button", name="Simulate BLDC").click()
    msg = page.get_by_text("Rejected", exact=False).first
    msg.wait_for()
    text = msg.inner_text() + page.content()
    assert "inverter.V_dc" in text and "allowed" in text


def test_bldc_import_scenario_switch_and_export_round_trip(page, tmp_path):
    import dataclasses
    from pathlib import Path

    from pmsm_commissioning.app.io.presets import dumps_preset, load_preset, loads_preset

    params = load_preset("bldc_smc_paper")
    uploaded = dataclasses.replace(params, name="bldc_imported", source="browser test",
                                   inverter=dataclasses.replace(params.inverter, V_dc=310.0),
                                   scenario=dataclasses.replace(params.scenario, active="2000rpm"))
    path = tmp_path / "bldc_imported.yaml"
    path.write_text(dumps_preset(uploaded), encoding="utf-8")
    _open_tab(page)
    with page.expect_file_chooser() as chooser:
        page.get_by_role("button", name="Import BLDC preset (YAML)").click()
    chooser.value.set_files(str(path))
    page.get_by_text("Imported", exact=False).first.wait_for()
    page.get_by_text("Machine, load, inverter, gains", exact=True).click()
    assert float(field(page, "V_dc [V]").input_value()) == 310.0
    page.get_by_text("Scenario", exact=True).nth(1).click()  # the folder (index 0 is the dropdown label)
    assert abs(float(field(page, "ω* [rpm]").input_value()) - 2000.0) < 1e-6
    with page.expect_download() as info:
        page.get_by_role("button", name="Download BLDC preset (YAML)").click()
    exported = loads_preset(Path(info.value.path()).read_text(encoding="utf-8"), "export.yaml")
    assert exported == uploaded


def test_bldc_import_of_a_position_preset_is_rejected_and_changes_nothing(page, tmp_path):
    from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, PRESET_DIR

    _open_tab(page)
    page.get_by_text("Machine, load, inverter, gains", exact=True).click()
    with page.expect_file_chooser() as chooser:
        page.get_by_role("button", name="Import BLDC preset (YAML)").click()
    chooser.value.set_files(str(PRESET_DIR / f"{DEFAULT_PRESET}.yaml"))
    msg = page.locator("p", has_text="Import rejected").first
    msg.wait_for()
    assert "position-drive preset" in msg.inner_text()
    assert float(field(page, "V_dc [V]").input_value()) == 300.0  # unchanged
