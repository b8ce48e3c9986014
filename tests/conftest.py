"""Shared fixtures, and the ``browser`` marker on every test under tests/browser/.

Markers (registered in pyproject.toml): ``browser`` (drives the page in Chromium), ``cluster`` (starts a Dask
scheduler), ``slow`` (over ≈ 20 s on a 2-core machine). ``pytest -m "not browser and not cluster and not slow"``
is the fast run for development; the README's command and CI run every test.
"""

from __future__ import annotations

import pathlib
import socket
from collections.abc import Iterator
from typing import Any

import pytest
import viser

from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.fdsmc.params import DriveParams


@pytest.fixture(scope="module")
def gui() -> Iterator[viser.GuiApi]:
    """A viser server's GUI API on a free local port, for the page's panels without a browser."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = int(s.getsockname()[1])
    server = viser.ViserServer(host="127.0.0.1", port=port, verbose=False)
    try:
        yield server.gui
    finally:
        server.stop()


@pytest.fixture(scope="module")
def served() -> Iterator[tuple[str, Any, Any]]:
    """The page's server on the default preset (no 3D scene) on a free port: ("127.0.0.1:port", server, config)."""
    from pmsm_commissioning.app.io.presets import DEFAULT_PRESET
    from pmsm_commissioning.app.ui.page import create_server
    from tests.net import free_port

    server, config = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False)
    try:
        yield f"127.0.0.1:{server.get_port()}", server, config
    finally:
        server.stop()


@pytest.fixture(scope="session")
def paper_params() -> DriveParams:
    """The paper's section-5 preset (FDSMC paper, section 5)."""
    return load_preset("paper_12kw_pmsm")


BROWSER_TESTS = pathlib.Path(__file__).resolve().parent / "browser"

#: Tests over ≈ 20 s, marked ``slow`` (every parameter of a listed function): file → functions. Measured with
#: pytest's --durations, one test at a time on the 2-core machine beside other work (load average 7–12).
#: tests/test_markers.py checks that each listed function exists.
SLOW = {
    "test_c_optimum.py": {"test_float_build_for_cortex_m4f"},
    "test_compiled_vs_python.py": {"test_compiled_and_plain_python_agree_on_every_metric_and_flag"},
    "test_datasheet_keys.py": {"test_cli_design_writes_the_users_name_and_source_and_the_sensor_figures"},
    "test_design.py": {"test_an_infeasible_T_m_is_never_clean", "test_real_presets_are_clean_as_shipped"},
    "test_design_assumptions.py": {
        "test_mj5208_class_robotics_datasheet_designs_clean_with_derived_values_labelled"},
    "test_design_search.py": {"test_design_exit_statuses_and_json_verdict",
                              "test_in_position_by_T_m_ends_the_move_early",
                              "test_too_little_current_is_diagnosed_as_current_not_sample_rate"},
    "test_duty.py": {"test_cycle_energy_is_the_sum_of_the_moves_and_yearly_figures_follow"},
    "test_energy_objective.py": {"test_electrical_objective_draws_less_than_the_papers_and_the_conventional"},
    "test_engine_cli.py": {"test_bench_prints_figures"},
    "test_exports.py": {"test_page_and_cli_write_the_same_bytes"},
    "test_faults_disconnect.py": {"test_disconnected_page_ends_its_robustness_pool"},
    "test_install.py": {"test_console_entry_point_designs_a_shipped_preset"},
    "test_multiaxis.py": {"test_axes_finish_together_within_the_arrival_band",
                          "test_requested_common_time_is_used_when_longer"},
    "test_optimum_fallback.py": {"test_duty_cycle_omits_a_failed_optimum_with_a_note"},
    "test_robustness_batch.py": {"test_compiled_and_interpreted_batch_agree"},
    "test_stale_cache.py": {"test_editing_a_control_law_recompiles_the_kernel"},
    "test_stock_compiled.py": {"test_stock_loops_compiled_and_plain_python_agree"},
    "test_studies_figures.py": {"test_multiaxis_figure_shows_every_axis_arriving_at_the_common_time"},
    "test_types.py": {"test_mypy_finds_no_error", "test_mypy_strict_finds_no_error_in_control_and_sim"},
}


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark every test of tests/browser/ ``browser`` (by its folder: a new browser test needs no mark), and
    the tests of :data:`SLOW` ``slow``.
    """
    for item in items:
        path = item.path.resolve()
        if BROWSER_TESTS in path.parents:
            item.add_marker(pytest.mark.browser)
        if getattr(item, "originalname", item.name) in SLOW.get(path.name, ()) and path.parent == BROWSER_TESTS.parent:
            item.add_marker(pytest.mark.slow)
