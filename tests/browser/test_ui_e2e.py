"""End-to-end tests of the web UI in a real Chromium."""

from __future__ import annotations

import dataclasses
import io
import re
import zipfile
from pathlib import Path

from playwright.sync_api import expect

from pmsm_commissioning.app.exports.firmware.verify import count_params
from pmsm_commissioning.app.io.presets import PAPER_PRESET, dumps_preset, load_preset, loads_preset
from pmsm_commissioning.control.fdsmc.derivations import derive
from tests.browser.conftest import ARTIFACTS, field, figure, open_page, set_number


def _phase_omega_p(page) -> float:
    return float(figure(page, "phase_plane")["meta"]["omega_p"])


def _wait_phase_omega_p(page, omega_p: float) -> None:
    page.wait_for_function(
        "(w) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
        " && e.layout.meta.id === 'phase_plane' && Math.abs(e.layout.meta.omega_p - w) < 1e-6 * w"
        " && e.data.some(t => t.name === 'Conventional trajectory'))", arg=omega_p)


def test_derived_alpha_max_of_default_preset(page):
    d = derive(load_preset(PAPER_PRESET))
    text = f"{d.alpha.alpha_max:.5g}"  # derived_rows format: 2651.2 rad/s²
    page.get_by_text(text, exact=True).first.wait_for()  # the derived-values panel is drawn
    assert "α_max" in page.content()


def test_change_T_m_simulate_draws_both_trajectories_and_new_boundary(page):
    params = load_preset(PAPER_PRESET)
    new = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=1.4))
    omega_p = derive(new).profile.omega_p
    assert abs(omega_p - _phase_omega_p(page)) > 1.0
    set_number(page, "T_m manoeuvre time [s]", 1.4)
    page.get_by_role("button", name="Simulate").click()
    _wait_phase_omega_p(page, omega_p)
    fig = figure(page, "phase_plane")
    names = {t["name"]: t for t in fig["traces"]}
    assert names["FDSMC trajectory"]["n"] > 100
    assert names["Conventional trajectory"]["n"] > 100
    boundary = names["Switching boundary, eq. (41)"]["y"]
    # Both horizontal segments of eq. (41) sit at ∓ω_p of the new manoeuvre.
    assert abs(max(boundary) - omega_p) < 1e-6 * omega_p
    assert abs(min(boundary) + omega_p) < 1e-6 * omega_p


def test_invalid_value_shows_message_and_simulates_nothing(page, ui_server):
    before = _phase_omega_p(page)
    runs_before = {cid: s.runs for cid, s in ui_server.config.sessions.items()}
    set_number(page, "J_r rotor inertia [kg·m²]", -0.1)
    page.get_by_role("button", name="Simulate").click()
    error = page.locator("[data-role=input-error]")
    error.wait_for()
    message = error.inner_text()
    assert "J_r" in message and "-0.1" in message and "allowed" in message
    # The rejection happens in the click's callback, before any job is submitted: once the message
    # is shown, no session is running a job and none has counted a run.
    sessions = ui_server.config.sessions
    assert not any(s.worker.busy for s in sessions.values())
    assert {cid: s.runs for cid, s in sessions.items() if cid in runs_before} == runs_before
    assert _phase_omega_p(page) == before


def _download(page, label: str) -> tuple[str, bytes]:
    with page.expect_download() as info:
        page.get_by_role("button", name=label).click()
    return info.value.suggested_filename, Path(info.value.path()).read_bytes()


def _set_text(page, label: str, value: str) -> None:
    """Type into the text field labelled ``label`` and wait until it shows the text."""
    box = page.locator(f'xpath=//label[normalize-space(.)="{label}"]/ancestor::*[.//input or .//textarea][1]'
                       '//*[self::input or self::textarea]').first
    box.fill(value)
    box.press("Tab")
    expect(box).to_have_value(value)
    page.wait_for_timeout(120)  # viser throttles GUI messages to one per 50 ms


def test_import_export_round_trip_and_c_header(page, tmp_path):
    params = load_preset(PAPER_PRESET)
    uploaded = dataclasses.replace(
        params, name="imported_case", source="browser test",
        manoeuvre=dataclasses.replace(params.manoeuvre, T_m=1.8),
        load=dataclasses.replace(params.load, F_v=0.3333333333333333))
    path = tmp_path / "imported_case.yaml"
    path.write_text(dumps_preset(uploaded), encoding="utf-8")
    page.locator("input[type=file][accept*='.yaml']").set_input_files(str(path))
    _wait_phase_omega_p(page, derive(uploaded).profile.omega_p)
    assert field(page, "T_m manoeuvre time [s]").input_value() == "1.8"
    page.get_by_text("Export", exact=True).click()
    downloads: list[object] = []
    page.on("download", lambda d: downloads.append(d))
    page.get_by_role("button", name="Drive parameters (YAML)").click()  # the paper's K = 1000 is not clean
    page.get_by_text(re.compile(r"export --format yaml refused: .*chatter")).wait_for(timeout=10000)
    assert downloads == []
    page.get_by_label("Export even if not clean").check()
    name, exported = _download(page, "Drive parameters (YAML)")
    assert name == "imported_case.yaml" and loads_preset(exported.decode(), "export.yaml") == uploaded
    name, archive = _download(page, "C controller module (.h + .c, zip)")
    assert name == "imported_case_fdsmc_controller.zip"
    with zipfile.ZipFile(io.BytesIO(archive)) as zf:
        assert sorted(zf.namelist()) == ["fdsmc_controller.c", "fdsmc_controller.h", "fdsmc_test.c",
                                         "fdsmc_vectors.h"]
        header = zf.read("fdsmc_controller.h").decode()
    name, archive = _download(page, "C controller module, tracked optimum (.h + .c, zip)")
    assert name == "imported_case_optimum_controller.zip"  # the same files, the tracked optimum's law
    with zipfile.ZipFile(io.BytesIO(archive)) as zf:
        assert "#define FDSMC_OUTER_LAW_OPTIMUM 1" in zf.read("fdsmc_controller.h").decode()
    # names reach the C text only as C string literals (no comment or macro can be injected)
    assert 'Drive:  "imported_case"' in header and 'Source: "browser test"' in header
    match = re.search(r"#define FDSMC_OMEGA_P\s+\(\(fdsmc_real\)([^)]+)\)", header)
    assert match is not None
    counted = count_params(uploaded)[0]  # the firmware's demand is a whole encoder count
    assert abs(float(match.group(1)) - derive(counted).profile.omega_p) <= 1e-12 * float(match.group(1))
    _set_text(page, "Name (file name)", "acme servo axis 2")  # name and source say what the motor is
    _set_text(page, "Source", "ACME data sheet")
    name, exported = _download(page, "Drive parameters (JSON)")
    assert name == "acme_servo_axis_2.json"
    assert loads_preset(exported.decode(), name) == dataclasses.replace(
        uploaded, name="acme servo axis 2", source="ACME data sheet")


def test_export_of_edited_but_unsimulated_inputs_is_refused(page):
    """An export describes the inputs shown: after an edit without Simulate it is refused with a
    message naming the uncommitted field, and nothing is downloaded.
    """
    set_number(page, "T_m manoeuvre time [s]", 1.4)
    page.get_by_text("Export", exact=True).click()
    downloads: list[object] = []
    page.on("download", lambda d: downloads.append(d))
    page.get_by_role("button", name="Drive parameters (YAML)").click()
    note = page.get_by_text(re.compile(r"Not committed: manoeuvre\.T_m = 1\.4 \(simulated: 1\.0\)"))
    note.wait_for(timeout=10000)
    assert downloads == []


def test_two_browser_contexts_keep_separate_values(browser, ui_server):
    ctx_a, page_a = open_page(browser, ui_server)
    ctx_b, page_b = open_page(browser, ui_server)
    try:
        params = load_preset(PAPER_PRESET)
        new = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=2.2))
        set_number(page_a, "T_m manoeuvre time [s]", 2.2)
        page_a.get_by_role("button", name="Simulate").click()
        _wait_phase_omega_p(page_a, derive(new).profile.omega_p)
        # A's run has finished; B's own session never ran and still holds the preset's T_m.
        session_a, session_b = sorted(ui_server.config.sessions.values(), key=lambda s: s.client.client_id)[-2:]
        assert session_a.params.manoeuvre.T_m == 2.2 and session_a.runs >= 1
        assert session_b.runs == 0 and session_b.params.manoeuvre.T_m == params.manoeuvre.T_m
        assert field(page_b, "T_m manoeuvre time [s]").input_value() == "1"
        assert abs(_phase_omega_p(page_b) - derive(params).profile.omega_p) < 1e-9
    finally:
        ctx_a.close()
        ctx_b.close()


def test_screenshot_of_main_view(page):
    """The main view after "Use recommended K" (the README's picture comes from this artifact)."""
    _click_and_wait_for_run(page, page.get_by_role("button", name=re.compile(r"^Use recommended K")))
    page.wait_for_timeout(1500)  # part of the replay
    names = {t["name"] for t in figure(page, "phase_plane")["traces"]}
    assert {"FDSMC trajectory", "Conventional trajectory"} <= names
    ARTIFACTS.mkdir(exist_ok=True)
    out = ARTIFACTS / "ui_main.png"
    page.screenshot(path=str(out))
    assert out.stat().st_size > 20_000


def _runs_done(page) -> int:
    match = re.search(r"Ready — (\d+) run\(s\) in this session", page.inner_text("body"))
    return int(match.group(1)) if match else -1


def _click_and_wait_for_run(page, button) -> None:
    n = _runs_done(page)
    button.click()
    page.wait_for_function("(n) => document.body.innerText.includes(`Ready — ${n} run(s) in this session`)",
                           arg=n + 1)


def test_recommended_K_then_T_c_min_one_click_fixes(page):
    """Slow manoeuvre (T_m = 60 s): K = 1000 chatters → "Use recommended K"; the approach to θ_dem
    is then poorly damped with T_c = T_a → "Use T_c = …" selects T_c,min and the chatter is gone.
    """
    from pmsm_commissioning.sim.fdsmc.verdicts import T_c_advice

    params = load_preset(PAPER_PRESET)
    slow = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=60.0))
    set_number(page, "T_m manoeuvre time [s]", 60)
    _click_and_wait_for_run(page, page.get_by_role("button", name="Simulate"))
    _wait_phase_omega_p(page, derive(slow).profile.omega_p)
    _click_and_wait_for_run(page, page.get_by_role("button", name=re.compile(r"^Use recommended K")))
    # with the recommended K the run still limit-cycles about θ_dem (hold phase)
    assert "Chatter (FDSMC)" in page.inner_text("body")
    use_tc = page.get_by_role("button", name=re.compile(r"^Use T_c = "))
    T_c_ms = 1e3 * T_c_advice(derive(slow))
    assert f"{T_c_ms:.4g} ms" in use_tc.inner_text()
    _click_and_wait_for_run(page, use_tc)
    assert "Chatter (FDSMC)" not in page.inner_text("body")
    assert abs(float(field(page, "T_c sliding time const. [ms]").input_value()) - T_c_ms) <= 1e-4 * T_c_ms  # 5 digits
    assert not use_tc.is_visible()
