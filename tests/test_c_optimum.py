"""The tracked optimum's C module (``export --format c --controller optimum``) runs what the simulator runs.

Its outer law is the simulator's ``optimum`` (the minimum-energy move tracked with the FDSMC's terminal
slide) on the FDSMC module's inner loops, observer and limits; the reference is the simulator's own table
of :func:`control.fdsmc.optimum.tracked_move`. The double build is bit-identical to the simulator in closed
loop with the real presets' sensors, the float32 build replays the golden vectors of the optimum's run
within 1e-4 of the peak voltage, the verdict gate reads the optimum's checks, and a move other than the
designed one is refused with a status.
"""

from __future__ import annotations

import ctypes
import io
import subprocess
import zipfile
from pathlib import Path

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives.files import ExportOptions
from pmsm_commissioning.app.exports.firmware import verify as cv
from pmsm_commissioning.app.exports.firmware.module import HEADER_NAME
from pmsm_commissioning.app.exports.firmware.optimum import NODE_BYTES_FLOAT, reference_table
from pmsm_commissioning.app.exports.model import export_download, export_files
from pmsm_commissioning.app.exports.provenance import ExportRefusedError
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.optimum import tracked_move
from pmsm_commissioning.control.fdsmc.tracking import slide_time_constant
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare, simulate
from scripts.c_arm import (
    arm_compiler,
    code_size,
    count_instructions,
    cross_compile,
    double_symbols,
)
from tests.toolchain import need

OPTIMUM = ExportOptions(force=True, controller="optimum")


def _compiler() -> str:
    return need(cv.compiler(), "C compiler")


def _closed_loop(folder: Path, preset: str, single: bool) -> dict[str, float]:
    _compiler()
    params, _ = cv.count_params(load_preset(preset))
    cv.write_module(folder, params, law="optimum")
    return cv.agreement(params, cv.closed_loop(cv.build(folder, single), single, params, "optimum"), "optimum")


@pytest.mark.parametrize("preset", ["yaskawa_sgm7j_04a", "odrive_d5065_belt"])
def test_double_build_is_bit_identical_to_the_simulated_optimum(tmp_path, preset):
    """The presets' own encoders (2^24 and 8192 counts), current noise and ADC, delay and limits: zero difference."""
    err = _closed_loop(tmp_path, preset, False)
    assert max(err.values()) == 0.0, err
    S = simulate(cv.count_params(load_preset(preset))[0], "optimum").trace.S
    assert (S == 0.0).mean() > 0.5 and (S != 0.0).any()  # the run tracked the table, then slid in


def test_float32_closed_loop_reaches_the_same_place(tmp_path):
    """Measured on Yaskawa Σ-7 (24-bit encoder), relative to each peak: θ_r 4.5e-6, ω_r 1.5e-4, i_q 2.9e-3,
    E_electrical 2.2e-4.
    """
    err = _closed_loop(tmp_path, "yaskawa_sgm7j_04a", True)
    assert err["theta_r"] < 1e-4 and err["E_friction"] < 1e-4 and err["E_electrical"] < 5e-3, err
    assert err["omega_r"] < 2e-3 and err["i_q"] < 3e-2, err


def _export(folder: Path, preset: str) -> None:
    params = load_preset(preset)
    for name, content in export_files("c", compare(params), OPTIMUM).items():
        (folder / name).write_bytes(content)


@pytest.mark.parametrize("preset", ["yaskawa_sgm7j_02a", "siemens_1ft7044_ak7"])
def test_golden_vectors_of_the_optimum_pass_the_host_test_program(tmp_path, preset):
    """The export's host program (gcc -Werror) replays the optimum's run: double exact, float32 within 1e-4."""
    cc = _compiler()
    _export(tmp_path, preset)
    assert "#define FDSMC_OUTER_LAW_OPTIMUM 1" in (tmp_path / HEADER_NAME).read_text(encoding="utf-8")
    for defines, tol in (((), 0.0), (("-DFDSMC_USE_FLOAT",), 1e-4)):
        subprocess.run([cc, *cv.CFLAGS, *defines, cv.accept_flag(tmp_path), "-O2", "fdsmc_test.c", "fdsmc_controller.c",
                        "-lm", "-o", "fdsmc_test"], cwd=tmp_path, check=True, capture_output=True, text=True)
        run = subprocess.run(["./fdsmc_test"], cwd=tmp_path, capture_output=True, text=True)
        assert run.returncode == 0, (defines, run.stdout)
        assert float(run.stdout.split("peak |u| = ")[1].split()[0]) <= tol, run.stdout


def test_set_move_accepts_only_the_designed_move_and_keeps_the_move(tmp_path):
    _compiler()
    params, delta = cv.count_params(load_preset("yaskawa_sgm7j_04a"))
    cv.write_module(tmp_path, params, law="optimum")
    m = cv.CModule(cv.build(tmp_path, True), True)
    T_m = params.manoeuvre.T_m
    s = m.new_state(1000)
    T_c = slide_time_constant(derive(params).alpha.alpha_max, params.controller.K)
    assert s.ref_on == 0 and s.t_c == pytest.approx(T_c, rel=1e-6)  # no move yet: the slide holds
    for target, t in ((1000 + delta + 1, T_m), (1000 - delta, T_m), (1000 + delta, 1.01 * T_m),
                      (1000 + delta, float("nan"))):
        code = m.lib.fdsmc_set_move(ctypes.byref(s), target, t)
        assert code == (-1 if t != t else -6), (target, t)
        assert s.status.last_move == code and s.ref_on == 0 and s.theta_dem == 1000
    assert m.lib.fdsmc_set_move(ctypes.byref(s), 1000 + delta, T_m) == 0
    assert s.ref_on == 0 and s.theta_dem == 1000  # handed over: the next step takes it
    out = m.Output()
    m.lib.fdsmc_step(ctypes.byref(s), 1000, 0.0, 0.0, ctypes.byref(out))
    assert s.ref_on == 1 and s.theta_dem == 1000 + delta and s.ref_k == 1 and out.fault == 0
    assert m.lib.fdsmc_set_move(ctypes.byref(s), 1000 + 2 * delta, T_m) == -7  # FDSMC_ERR_MOVING
    r = m.new_state(1000 + delta)  # at rest on the held demand: the next move goes from there
    r.theta_dem = 1000 + delta
    assert m.lib.fdsmc_set_move(ctypes.byref(r), 1000 + 2 * delta, T_m) == 0


def test_the_table_is_the_simulators_and_its_size_is_limited():
    params, _ = cv.count_params(load_preset("yaskawa_sgm7j_04a"))
    d = derive(params)
    table, mv = reference_table(params, d), tracked_move(d)
    assert (table.theta == mv.theta).all() and (table.omega == mv.omega).all() and (table.alpha == mv.alpha).all()
    assert table.float_bytes == NODE_BYTES_FLOAT * mv.theta.size
    counts = (table.counts + table.fraction) * (2.0 * 3.141592653589793 / params.sensors.encoder_cpr)
    assert counts == pytest.approx(mv.theta - params.manoeuvre.theta_dem, abs=1e-12)
    with pytest.raises(ParameterError, match=r"reference table \(2001 nodes, 32016 bytes\).*allowed ≤ 30000") as err:
        reference_table(params, d, max_bytes=30000)
    assert "\n" not in str(err.value)


def test_the_gate_reads_the_optimums_checks():
    """Paper drive: the optimum's run fails checks; the export names them and the header carries them."""
    params = load_preset("paper_12kw_pmsm")
    cmp = compare(params, ("fdsmc", "conventional", "optimum"))
    names = [c.name for c in run_checks(params, cmp.optimum) if c.violated]
    assert names
    with pytest.raises(ExportRefusedError, match="tracked optimum's run") as err:
        export_files("c", cmp, ExportOptions(controller="optimum"))
    assert all(n in str(err.value) for n in names)
    header = export_files("c", cmp, OPTIMUM)[HEADER_NAME].decode()
    assert "#define FDSMC_CLEAN 0" in header and f'"{", ".join(names)}"' in header


def test_cli_writes_the_optimum_module_and_refuses_it_for_other_formats(tmp_path, capsys):
    assert main(["export", "yaskawa_sgm7j_04a", "--format", "c", "--controller", "optimum",
                 "-o", str(tmp_path)]) == 0
    header = (tmp_path / HEADER_NAME).read_text(encoding="utf-8")
    assert "#define FDSMC_OUTER_LAW_OPTIMUM 1" in header and "#define FDSMC_CLEAN 1" in header
    capsys.readouterr()
    assert main(["export", "yaskawa_sgm7j_04a", "--format", "yaml", "--controller", "optimum",
                 "-o", str(tmp_path / "x.yaml")]) == 2
    err = capsys.readouterr().err.strip()
    assert "controller = 'optimum'" in err and "format c" in err and "\n" not in err
    assert not (tmp_path / "x.yaml").exists()


def test_the_page_offers_the_optimum_module_as_its_own_zip():
    """The page's Export button of the optimum's module downloads the same files as the CLI, named apart."""
    from pmsm_commissioning.app.ui.files import LAW_EXPORTS

    assert list(LAW_EXPORTS.values()) == [("c", "optimum")]
    cmp = compare(load_preset("yaskawa_sgm7j_04a"))  # the optimum is simulated on demand
    name, archive = export_download("c", cmp, OPTIMUM)
    assert name == "yaskawa_sgm7j_04a_optimum_controller.zip"
    with zipfile.ZipFile(io.BytesIO(archive)) as zf:
        assert b"#define FDSMC_OUTER_LAW_OPTIMUM 1" in zf.read(HEADER_NAME)
        assert zf.read(HEADER_NAME) == export_files("c", cmp, OPTIMUM)[HEADER_NAME]


def test_float_build_for_cortex_m4f(tmp_path):
    """No double operation; the table is in .text (flash); instructions per step under qemu-arm."""
    need(arm_compiler(), "arm-none-eabi-gcc")
    _export(tmp_path, "yaskawa_sgm7j_04a")
    obj = cross_compile(tmp_path)
    assert double_symbols(obj) == []
    assert code_size(obj)["text"] > NODE_BYTES_FLOAT * 2001 and code_size(obj)["data"] == 0
    n = count_instructions(tmp_path)
    assert n.max <= 385, n  # measured: median 362, 381 on the sample that takes the move (FDSMC module: 283)
