"""The golden vectors kill mutants of the generated C: each mutation of the controller's source must
make the export's host test program (fdsmc_test.c) fail, in the double and the float32 build.

The vectors (app/exports/firmware/golden.py, targeted.py) cover the designed move and hold, the limits acting,
two injected faults, calls at rest in which the d-axis current limit or the voltage limit acts, and
fdsmc_set_move's refusals (busy, moving), so a wrong gain on the sloped segment, a sign error in the
q-axis or d-axis current limit, a voltage limit off by 1 %, an innovation threshold 100 times too large,
a move accepted while one is pending or running and a sign flip of a gain are all caught.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.firmware.verify import CFLAGS, accept_flag, compiler
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare
from tests.toolchain import need

PRESET = "yaskawa_sgm7j_04a"
BUILDS = {"double": (), "float": ("-DFDSMC_USE_FLOAT",)}


def _flip(field: str):
    """Mutation: the sign of the design constant ``field`` (its first element for an array) flipped."""
    def mutate(text: str) -> str:
        out, n = re.subn(rf"(\.{field} = \{{?R_\()(-?)", lambda m: m.group(1) + ("" if m.group(2) else "-"), text)
        assert n >= 1, field
        return out
    return mutate


def _flip_element(field: str, index: int):
    """Mutation: the sign of element ``index`` of the design's array ``field`` flipped (both builds' rows)."""
    def mutate(text: str) -> str:
        pattern = rf"(\.{field} = \{{(?:R_\([^)]*\), ){{{index}}}R_\()(-?)"
        out, n = re.subn(pattern, lambda m: m.group(1) + ("" if m.group(2) else "-"), text)
        assert n == 2, (field, index, n)
        return out
    return mutate


def _replace(old: str, new: str):
    def mutate(text: str) -> str:
        assert text.count(old) == 1, old
        return text.replace(old, new)
    return mutate


MUTANTS = {
    "sloped segment gain x1.5": _replace("*S = omega_hat + FDSMC_DIV(theta_re, s->t_c, s->inv_t_c);",
                                         "*S = omega_hat + R_(1.5) * FDSMC_DIV(theta_re, s->t_c, s->inv_t_c);"),
    "q-limit sign": _replace("(i_q1 > R_(0) ? room : -room)", "(i_q1 > R_(0) ? -room : room)"),
    "innovation threshold x100": _replace("!below(e_abs, p->e_o_max_counts)",
                                          "!below(e_abs, R_(100) * p->e_o_max_counts)"),
    "NaN passes the current check": _replace("!below(i_d * i_d + i_q * i_q, p->i_fault2)",
                                             "i_d * i_d + i_q * i_q > p->i_fault2"),
    "d-limit sign": _replace("i_d_end = i_d1 > R_(0) ? p->i_max : -p->i_max;",
                             "i_d_end = i_d1 > R_(0) ? -p->i_max : p->i_max;"),
    "d-limit left out": _replace("if (FDSMC_FABS(i_d1) > p->i_max) {", "if (0) {"),
    "voltage limit x1.01": _replace("const fdsmc_real scale = p->u_max / FDSMC_SQRT(mag2);",
                                    "const fdsmc_real scale = R_(1.01) * p->u_max / FDSMC_SQRT(mag2);"),
    "voltage limit left out": _replace("if (p->u_max > R_(0) && mag2 > p->u_max2) {", "if (0) {"),
    "set_move accepts while moving": _replace("return FDSMC_ERR_MOVING;", "(void)0;"),
    "set_move accepts while busy": _replace("return FDSMC_ERR_BUSY;", "(void)0;"),
    **{f"sign of {f}": _flip(f) for f in ("k_bl", "alpha_max", "three_inv_t_si", "three_inv_t_salpha", "l")},
    **{f"sign of l[{i}]": _flip_element("l", i) for i in (1, 2, 3)},
}


@pytest.fixture(scope="module")
def export(tmp_path_factory) -> Path:
    """The preset's export with the test program's object compiled once per build (the vectors are large)."""
    need(compiler(), "C compiler")
    folder = tmp_path_factory.mktemp("mutants")
    params = load_preset(PRESET)
    cmp = compare(params)
    for name, text in c_files(cmp, run_checks(params, cmp.fdsmc), force=True).items():
        (folder / name).write_text(text, encoding="utf-8")
    for build, defines in BUILDS.items():
        _cc(folder, *defines, "-c", "fdsmc_test.c", "-o", f"test_{build}.o")
    return folder


def _cc(folder: Path, *args: str) -> None:
    run = subprocess.run([compiler() or "cc", *CFLAGS, accept_flag(folder), "-O2", *args], cwd=folder,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def _test_program(folder: Path, build: str) -> subprocess.CompletedProcess:
    _cc(folder, *BUILDS[build], "-c", "fdsmc_controller.c", "-o", f"ctl_{build}.o")
    _cc(folder, f"test_{build}.o", f"ctl_{build}.o", "-lm", "-o", f"fdsmc_test_{build}")
    return subprocess.run([f"./fdsmc_test_{build}"], cwd=folder, capture_output=True, text=True)


def test_the_unmutated_module_passes(export):
    for build in BUILDS:
        run = _test_program(export, build)
        assert run.returncode == 0, run.stdout
        assert all(f"segment {name} " in run.stdout for name in ("move", "limits", "fault_current",
                                                                   "fault_innovation", "limit_i_d_pos",
                                                                   "limit_i_d_neg", "limit_u"))


@pytest.mark.parametrize("name", MUTANTS)
def test_each_mutant_fails_the_golden_test_in_both_builds(export, tmp_path, name):
    for item in export.iterdir():
        if item.is_file():
            shutil.copy(item, tmp_path / item.name)
    src = tmp_path / "fdsmc_controller.c"
    src.write_text(MUTANTS[name](src.read_text(encoding="utf-8")), encoding="utf-8")
    for build in BUILDS:
        run = _test_program(tmp_path, build)
        assert run.returncode == 1, (name, build, run.stdout)
