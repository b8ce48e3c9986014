"""Fuzzing every way numbers and files get in: ``--set`` overrides, YAML preset files, measured
back-EMF CSV/YAML uploads and page-input text (≥ 1000 cases, deterministic).

Every case ends in exactly one of two ways:

* **accepted** — the stored value is exactly the number written (no silent change) or the keyword
  written, and the request fits the cost budget (the budget is asserted, not a wall time);
* **rejected** — a ``ValueError`` (PresetError, ParameterError, NumberFormatError, BudgetError)
  whose one-line message names the field, the value and what is allowed.

Any other exception (OverflowError, ZeroDivisionError, TypeError, RecursionError …) fails.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.io.bldc_emf import read_measured
from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_integer, parse_number, parse_T_m_list
from pmsm_commissioning.app.io.presets import PRESET_DIR, PresetError, load_preset, loads_preset
from pmsm_commissioning.app.ui.choices import checked_choice
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive, predicted_energy
from pmsm_commissioning.control.fdsmc.feasibility import alpha_max, feasibility
from pmsm_commissioning.control.fdsmc.model import model_coefficients
from pmsm_commissioning.control.fdsmc.observer import discrete_observer, observer_gains
from pmsm_commissioning.control.fdsmc.profile import velocity_profile
from pmsm_commissioning.sim.bldc.engine import check_budget as bldc_check_budget
from pmsm_commissioning.sim.common import budget
from pmsm_commissioning.sim.fdsmc import engine, grid

PAPER = (PRESET_DIR / "paper_12kw_pmsm.yaml").read_text(encoding="utf-8")
BLDC = (PRESET_DIR / "bldc_smc_paper.yaml").read_text(encoding="utf-8")
FUZZ = settings(deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])

# ---- value texts ---------------------------------------------------------------------------
YAML11 = ["1:30", "017", "0o17", "0x10", "0b101", "1_000", "yes", "no", "on", "off", "true", "false",
          "~", "null", ".inf", "-.inf", ".nan", "nan", "inf", "Infinity", "1e999", "-1e999", "1e-400",
          "5e-324", "1,5", "1.2.3", "1e", "e3", "--1", "+", "", "  ", "2001-12-14", "!!float 1", "&a 1",
          "*a", "[1, 2]", "{a: 1}", "'1'", '"2e4"', "1.5e3", "2e4", "1 000", "0", "-0", "1e308", "-1e308",
          "9" * 400, "1" + "0" * 30, "0.1e-10", "T_a", "continuous", "paper", "torque_limit", "\x00", "é"]
numbers = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.floats(min_value=1e-12, max_value=1e12).map(lambda x: f"{x:.6g}"),
    st.integers(min_value=-10**30, max_value=10**30).map(str),
    st.tuples(st.integers(-9, 9), st.integers(-330, 330)).map(lambda t: f"{t[0]}e{t[1]}"),
)
value_texts = st.one_of(st.sampled_from(YAML11), numbers, st.text(max_size=12))

POSITION_FIELDS = [f"{sec}.{f.name}" for sec in ("motor", "load", "controller", "manoeuvre")
                   for f in dataclasses.fields(getattr(load_preset("paper_12kw_pmsm"), sec))
                   if f.name != "steps"]
ALIAS_FIELDS = [f"{sec}.{key}" for sec, table in units.ALIASES.items() if sec in ("motor", "load", "controller",
                                                                                   "manoeuvre") for key in table]
KEYWORDS = {"controller.T_c": {"T_a"}, "controller.f_s": {"continuous"},
            "controller.alpha_max_rule": {"paper", "torque_limit"}}


def _is_number(text: str) -> bool:
    try:
        parse_number(text, "x")
    except NumberFormatError:
        return False
    return True


def _names_field_and_allowed(message: str, *names: str) -> None:
    assert "\n" not in message.strip(), message
    assert any(n in message for n in names), (names, message)
    assert "allowed" in message or "not found" in message, message


def _stored(params: object, field: str) -> object:
    section, name = field.split(".")
    return getattr(getattr(params, section), name)


def _closed_form(params: object) -> tuple[float, float]:
    """The derivations without the (slow) linearised-loop scan: α_max, profile, observer, energy."""
    m, c = params.motor, params.controller
    alpha = alpha_max(params)
    prof = velocity_profile(params.manoeuvre.theta_dem, alpha.alpha_max, params.manoeuvre.T_m, c.T_c)
    coeff = model_coefficients(m)
    obs = observer_gains(c.T_so, coeff.M)
    if not c.is_continuous:
        assert np.all(np.isfinite(discrete_observer(obs, coeff.M, float(c.f_s)).L))
    feasibility(params, alpha, prof.omega_p)
    predicted_energy(params, prof)
    assert all(math.isfinite(v) for v in (obs.K1, obs.K2, obs.K3, obs.K4, prof.omega_p, prof.T_a))
    return alpha.alpha_max, prof.T_m_min


@settings(FUZZ, max_examples=450)
@given(field=st.sampled_from(POSITION_FIELDS + ALIAS_FIELDS), text=value_texts)
def test_fuzz_set_overrides(field, text):
    _check_override(field, text, full=False)


@settings(FUZZ, max_examples=30)
@given(field=st.sampled_from(POSITION_FIELDS), text=numbers)
def test_fuzz_set_overrides_full_derivation(field, text):
    """A smaller sample through the whole derivation (loop analysis included)."""
    _check_override(field, text, full=True)


def _check_override(field: str, text: str, full: bool) -> None:
    item = f"{field}={text}"
    try:
        params = load_preset("paper_12kw_pmsm", [item])
        cost = grid.check_budget(params, 2)
        a_max, t_min = (lambda d: (d.alpha.alpha_max, d.profile.T_m_min))(derive(params)) if full \
            else _closed_form(params)
    except ValueError as exc:
        msg = str(exc)
        section, name = field.split(".")
        alias = units.ALIASES.get(section, {}).get(name)
        si = f"{section}.{alias.field}" if alias else field  # range errors name the SI field set
        _names_field_and_allowed(msg, field, si, "--set", "integration steps")
        if isinstance(exc, budget.BudgetError):
            assert "largest accepted" in msg or "no value of" in msg or "smallest accepted" in msg
        return
    assert cost.fits and cost.steps <= budget.MAX_STEPS and cost.trace_bytes <= budget.MAX_TRACE_BYTES
    assert math.isfinite(a_max) and math.isfinite(t_min)
    section, name = field.split(".")
    if name in units.ALIASES.get(section, {}):  # unit-suffixed: stored = converted number written
        alias = units.ALIASES[section][name]
        assert _stored(params, f"{section}.{alias.field}") == pytest.approx(
            alias.convert(parse_number(_unquoted(text), field)), rel=1e-12)
        return
    stored = _stored(params, field)
    written = _unquoted(text)
    if _is_number(written) and not isinstance(stored, str):
        assert stored == parse_number(written, field)  # exactly the number written, never rounded
    else:
        assert stored == written and written in KEYWORDS.get(field, set()), (field, text, stored)


def _unquoted(text: str) -> str:
    """The scalar a YAML value text stands for (quotes removed)."""
    t = text.strip()
    return t[1:-1] if len(t) >= 2 and t[0] == t[-1] and t[0] in "'\"" else t


# ---- YAML files -------------------------------------------------------------------------------
_SCALAR_LINE = re.compile(r"^(  [A-Za-z_]+: )([^#\n]*?)(\s*#.*)?$", re.M)
SCALAR_SPANS = [(m.start(2), m.end(2), m.group(1).strip().rstrip(":")) for m in _SCALAR_LINE.finditer(PAPER)]


@st.composite
def yaml_files(draw: st.DrawFn) -> tuple[str, str]:
    kind = draw(st.sampled_from(["scalar", "duplicate", "nesting", "flow", "alias", "garbage", "indent"]))
    if kind == "scalar":
        a, b, key = draw(st.sampled_from(SCALAR_SPANS))
        return kind, PAPER[:a] + draw(value_texts).replace("\n", " ") + PAPER[b:]
    if kind == "duplicate":
        a, b, key = draw(st.sampled_from(SCALAR_SPANS))
        line_end = PAPER.index("\n", b)
        return kind, PAPER[:line_end + 1] + f"  {key}: {draw(numbers)}\n" + PAPER[line_end + 1:]
    if kind == "nesting":
        n = draw(st.integers(1, 3000))
        return kind, draw(st.sampled_from(["[", "{a: "])) * n + "1" + "]" * n
    if kind == "flow":
        n = draw(st.integers(1, 40))
        return kind, PAPER.replace("  J_L: 0.12 ", "  J_L: " + "[" * n + "0.12" + "]" * n + " ", 1)
    if kind == "alias":
        return kind, PAPER.replace("  L_q: 0.0054 ", "  L_q: *x ").replace("  L_d: 0.0054 ", "  L_d: &x 0.0054 ")
    if kind == "indent":
        n = draw(st.integers(1, 400))
        return kind, "a:\n" + "".join(" " * (i + 1) + f"b{i}:\n" for i in range(n)) + " " * (n + 1) + "1\n"
    return kind, draw(st.text(max_size=300))


@settings(FUZZ, max_examples=300)
@given(case=yaml_files())
def test_fuzz_yaml_files(case):
    kind, text = case
    try:
        params = loads_preset(text, "fuzz.yaml")
    except ValueError as exc:
        msg = str(exc)
        assert "\n" not in msg.strip() and msg
        if kind == "duplicate":
            assert "duplicate key" in msg and "allowed each key once" in msg
        elif kind == "nesting" and text.count("[") + text.count("{") > 32:
            assert "nested too deeply" in msg and "allowed ≤ 32" in msg
        elif kind == "alias":
            assert "aliases" in msg
        else:
            assert "allowed" in msg or "not valid YAML" in msg or "missing" in msg or "unknown" in msg, msg
        return
    assert kind in ("scalar", "flow") and params.name == "paper_12kw_pmsm"
    assert grid.run_cost(params).steps >= 1


# ---- measured back-EMF uploads ---------------------------------------------------------------
def _emf_csv(rows: int, three: bool) -> list[list[str]]:
    th = np.linspace(0.0, 360.0, rows, endpoint=False)
    out = []
    for t in th:
        vals = [np.clip(1.2 * np.sin(np.radians(t - k)), -1, 1) * 0.1 for k in ((0, 120, 240) if three else (0,))]
        out.append([f"{t:.6g}"] + [f"{v:.6g}" for v in vals])
    return out


@settings(FUZZ, max_examples=120)
@given(rows=st.integers(0, 200), three=st.booleans(), edits=st.lists(
    st.tuples(st.integers(0, 10**6), st.integers(0, 3), value_texts), max_size=3),
    sep=st.sampled_from([",", ";", "\t", " "]), header=st.booleans(), yaml=st.booleans())
def test_fuzz_emf_uploads(rows, three, edits, sep, header, yaml):
    table = _emf_csv(rows, three)
    for r, c, text in edits:
        if table:
            row = table[r % len(table)]
            row[c % len(row)] = text.replace("\n", " ")
    if yaml:
        body = "\n".join("- [" + ", ".join(r) + "]" for r in table)
        name = "emf.yaml"
    else:
        body = ("theta_e_deg" + sep + "phi_a\n" if header else "") + "\n".join(sep.join(r) for r in table)
        name = "emf.csv"
    try:
        measured = read_measured(body, name)
    except ValueError as exc:
        msg = str(exc)
        assert "emf waveform" in msg and "\n" not in msg.strip(), msg
        return
    assert np.all(np.isfinite(measured.samples)) and len(measured.samples) > 0


# ---- page-input text ---------------------------------------------------------------------------
@settings(FUZZ, max_examples=150)
@given(text=st.one_of(value_texts, st.lists(value_texts, max_size=5).map(", ".join)),
       choice=st.one_of(st.sampled_from(["paper_12kw_pmsm", "bldc_smc_paper", "../../../../tmp/x", ""]),
                        st.text(max_size=20)))
def test_fuzz_page_inputs(text, choice):
    for label in ("Table 1 › T_m list", "--tm"):
        try:
            values = parse_T_m_list(text, label)
        except ValueError as exc:
            _names_field_and_allowed(str(exc), label)
        else:
            items = [s.strip() for s in text.replace(";", ",").split(",") if s.strip()]
            assert values == [parse_number(s, "x") for s in items]  # exactly as typed
    try:
        n = parse_integer(text, "motor.p")
    except NumberFormatError as exc:
        _names_field_and_allowed(str(exc), "motor.p")
    else:
        assert n == parse_number(text, "x") and isinstance(n, int)
    try:
        assert checked_choice(choice, ("paper_12kw_pmsm",), "Preset") == "paper_12kw_pmsm"
    except ParameterError as exc:
        _names_field_and_allowed(str(exc), "Preset")


@settings(FUZZ, max_examples=60)
@given(t_end=st.floats(0.51, 100.0), f_s=st.floats(1e3, 1e6), n=st.integers(1, 4))  # load steps end at 0.5 s
def test_fuzz_bldc_budget(t_end, f_s, n):
    text = BLDC.replace("t_end: 0.7 ", f"t_end: {t_end!r} ").replace("f_s: 20000.0 ", f"f_s: {f_s!r} ")
    params = loads_preset(text)
    assert params.case.t_end == t_end and params.inverter.f_s == f_s
    try:
        cost = bldc_check_budget(params, n)
    except budget.BudgetError as exc:
        assert "t_end" in str(exc) and "inverter.f_s" in str(exc) and "allowed ≤" in str(exc)
        return
    assert cost.steps <= budget.MAX_STEPS and cost.trace_bytes <= budget.MAX_TRACE_BYTES
    assert cost.cpu_s <= budget.MAX_CPU_S and cost.memory_bytes <= budget.MAX_TRACE_BYTES  # the promise


def test_accepted_runs_take_no_more_steps_than_the_budget_counted(monkeypatch):
    """The kernel is called with exactly the steps the budget counted (sub-steps included)."""
    import pmsm_commissioning.sim.fdsmc.kernel_run as kernel_run

    real, seen = kernel_run.run_kernel, []

    def counting(*args):
        seen.append(int(args[8]) * int(args[9]))  # n_steps × n_sub
        return real(*args)

    monkeypatch.setattr(kernel_run, "run_kernel", counting)
    for over in (["motor.omega_b=2000", "motor.p=10", "manoeuvre.T_m=0.5"], ["controller.f_s=continuous",
                                                                           "manoeuvre.T_m=0.5"]):
        p = load_preset("paper_12kw_pmsm", [*over, "controller.K=0.2"])
        cost = grid.check_budget(p, 2)
        seen.clear()
        engine.compare(p)
        assert sum(seen) == cost.steps and cost.fits


def test_preset_error_is_a_value_error():
    assert issubclass(PresetError, ValueError) and issubclass(budget.BudgetError, ValueError)
    assert Path(PRESET_DIR).is_dir()
