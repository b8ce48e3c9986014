"""UI logic without a browser: worker (no overlapping runs), text panels, input parsing, serve args."""

from __future__ import annotations

import dataclasses
import math
import threading
import time

import pytest

from pmsm_commissioning.app.cli.serve import is_loopback
from pmsm_commissioning.app.io.numbers import parse_T_m_list
from pmsm_commissioning.app.ui.inputs import InputError, parse_steps
from pmsm_commissioning.app.ui.savings import annual_savings
from pmsm_commissioning.app.ui.text import derived_markdown, warnings_html
from pmsm_commissioning.app.ui.worker import Worker
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.sim.fdsmc import grid
from pmsm_commissioning.sim.fdsmc.engine import compare
from pmsm_commissioning.sim.fdsmc.verdicts import recommended_K, run_warnings


def test_worker_refuses_a_second_job_while_one_runs():
    busy: list[bool] = []
    gate, ran = threading.Event(), []
    w = Worker(busy.append, lambda exc: None)
    assert w.submit(lambda: (gate.wait(5), ran.append(1))) is not None
    assert w.submit(lambda: ran.append(2)) is None  # double-click: refused
    gate.set()
    for _ in range(100):
        if not w.busy:
            break
        time.sleep(0.01)
    assert ran == [1] and busy == [True, False]
    assert w.submit(lambda: ran.append(3)).result(5) is None and ran == [1, 3]
    w.close()


def test_worker_reports_errors_instead_of_losing_them():
    errors: list[Exception] = []
    w = Worker(lambda b: None, errors.append)
    w.submit(lambda: 1 / 0).result(5)
    assert isinstance(errors[0], ZeroDivisionError) and not w.busy
    w.close()


def test_derived_markdown_lists_alpha_max_and_recommended_K(paper_params):
    d = derive(paper_params)
    text = derived_markdown(d)
    assert f"| {d.alpha.alpha_max:.5g} | rad/s² |" in text
    k_rec = recommended_K(d)
    assert k_rec is not None and k_rec < paper_params.controller.K
    assert f"{k_rec:.5g}" in text


def test_warnings_html_escapes_and_flags_errors():
    box = warnings_html(["T_m < T_m,min"], error="motor.J_r = -0.1 <bad>")
    assert 'data-role="input-error"' in box and "&lt;bad&gt;" in box and "T_m &lt; T_m,min" in box
    assert "No warnings" in warnings_html([])


def test_run_warnings_and_savings(paper_params):
    c = compare(paper_params)
    warnings = run_warnings(c)
    assert any(w.startswith("Chatter (FDSMC)") and "Recommended K" in w for w in warnings)
    s = annual_savings(c, 600.0, 4000.0, 0.25)  # default DC link: a braking resistor, the supply gives the drawn energy
    e_f = c.fdsmc.metrics.motoring_total_J
    e_c = c.conventional.metrics.motoring_total_J
    assert s.per_cycle_J == pytest.approx(e_c - e_f)
    assert s.kWh_per_year == pytest.approx((e_c - e_f) * 600 * 4000 / 3.6e6)
    assert s.money_per_year == pytest.approx(0.25 * s.kWh_per_year)
    assert annual_savings(dataclasses.replace(c, fdsmc=None), 1, 1, 1) is None
    regen = dataclasses.replace(c, derived=dataclasses.replace(
        c.derived, params=grid.with_field(paper_params, "controller.dc_link", "regenerative")))
    net = c.conventional.metrics.electrical_in_total_J - c.fdsmc.metrics.electrical_in_total_J
    assert annual_savings(regen, 600.0, 4000.0, 0.25).per_cycle_J == pytest.approx(net)


def test_parse_steps_and_T_m_list():
    assert parse_steps("0.5:10, 1.2:0") == [{"t": 0.5, "Gamma_Le": 10.0}, {"t": 1.2, "Gamma_Le": 0.0}]
    assert parse_steps("  ") == []
    with pytest.raises(InputError, match="allowed 't:Γ_Le' pairs"):
        parse_steps("0.5-10")
    assert parse_T_m_list("1.0, 1.4;1.8", "Table 1 › T_m list") == [1.0, 1.4, 1.8]
    with pytest.raises(ValueError, match="allowed 0 < T_m"):
        parse_T_m_list("1.0, -2", "Table 1 › T_m list")
    with pytest.raises(ValueError, match="not a number"):
        parse_T_m_list("1.0, x", "Table 1 › T_m list")


def test_loopback_detection():
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.5")


def test_tune_runner_runs_the_latest_value_and_draws_the_rest_once_the_drag_stops():
    """Moves faster than a run: no stale value is queued, the last move's value is what runs last,
    and the rest of the results is drawn once, only after no move came for TUNE_SETTLE_S.
    """
    from pmsm_commissioning.app.ui.tuning import TUNE_SETTLE_S, TuneRunner

    value, ran, finished = [0], [], []
    runner: TuneRunner

    def run_latest() -> bool:
        ran.append((value[0], time.monotonic()))
        time.sleep(0.03)  # a run slower than the moves
        return True

    w = Worker(lambda busy: busy or runner.resume(), lambda exc: None)
    runner = TuneRunner(w, run_latest, lambda: finished.append(time.monotonic()))
    for k in range(1, 21):  # a drag: a move every 10 ms
        value[0] = k
        runner.request()
        time.sleep(0.01)
    t_last_move = time.monotonic()
    for _ in range(300):
        if finished and not w.busy:
            break
        time.sleep(0.01)
    assert ran[-1][0] == 20  # the latest value ran
    assert len(ran) < 20  # moves during a run were merged, not queued
    assert [v for v, _ in ran] == sorted({v for v, _ in ran})  # never an older value after a newer one
    assert len(finished) == 1 and finished[0] - t_last_move >= TUNE_SETTLE_S - 0.02
    w.close()


def test_tune_runner_stops_on_an_input_error_without_drawing_the_rest():
    from pmsm_commissioning.app.ui.tuning import TuneRunner

    finished: list[int] = []
    w = Worker(lambda busy: None, lambda exc: None)
    runner = TuneRunner(w, lambda: False, lambda: finished.append(1))
    runner.request()
    for _ in range(200):
        if not w.busy:
            break
        time.sleep(0.01)
    assert not w.busy and finished == []
    w.close()


def test_assign_sends_only_changed_properties():
    """Viser sends every assignment; assign() leaves equal values alone (nothing re-sent, nothing re-drawn)."""
    from pmsm_commissioning.app.ui.props import assign

    class Handle:
        def __init__(self) -> None:
            object.__setattr__(self, "sent", [])
            object.__setattr__(self, "content", "a")
            object.__setattr__(self, "visible", True)

        def __setattr__(self, name: str, value: object) -> None:
            self.sent.append(name)
            object.__setattr__(self, name, value)

    h = Handle()
    assign(h, content="a", visible=True)
    assert h.sent == []
    assign(h, content="b", visible=True)
    assert h.sent == ["content"] and h.content == "b"


@pytest.mark.parametrize("value", [0.0431, 4.86e-5, 2.6, 21.72, 1000.0])
def test_a_live_tuning_key_step_moves_the_value_whatever_its_size(value):
    """The page rounds a slider position to the slider's precision: one key step up or down must
    move the value by one step of the logarithmic track (≈ 2.3 %) whatever its size (a K of
    0.043 s/rad was rounded back to 0.04 on a linear track).
    """
    from pmsm_commissioning.app.ui.log_slider import LOG_PRECISION, LOG_STEP, value_of_position

    position = round(math.log10(value), LOG_PRECISION)
    for sign in (1, -1):
        moved = value_of_position(round(position + sign * LOG_STEP, LOG_PRECISION))
        ratio = moved / value_of_position(position)
        assert ratio == pytest.approx(10.0 ** (sign * LOG_STEP), rel=5e-3)
