"""The generated C module builds and passes its golden test program with gcc and clang, as C99 and as C++17.

Firmware is built with either compiler, and C++ firmware includes the module's source in its own
build: the source compiles as C++17 with -Wall -Wextra -Werror (designated initializers in declaration
order), and the host test program built that way still agrees with the simulator. With CI=true a
missing compiler fails (``scripts/ensure_cc.sh`` installs gcc, g++, clang and clang++).
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from pmsm_commissioning.app.exports.firmware.vectors import c_files
from pmsm_commissioning.app.exports.firmware.verify import CFLAGS, accept_flag
from pmsm_commissioning.app.io.presets import load_preset
from pmsm_commissioning.sim.fdsmc.design import run_checks
from pmsm_commissioning.sim.fdsmc.engine import compare
from tests.toolchain import need

CXXFLAGS = ("-x", "c++", "-std=c++17", "-Wall", "-Wextra", "-Werror")
BUILDS = {"double": (), "float": ("-DFDSMC_USE_FLOAT",)}


def tool(name: str) -> str:
    """Path of the compiler ``name``; a failure under CI=true, else a skip, when it is missing."""
    return need(shutil.which(name), name)


def _export(folder: Path, law: str) -> Path:
    """Write the four files of the C export of yaskawa_sgm7j_04a (``law``: the module's outer law)."""
    params = load_preset("yaskawa_sgm7j_04a")
    cmp = compare(params, ("fdsmc", "conventional") + (("optimum",) if law == "optimum" else ()))
    run = cmp.optimum if law == "optimum" else cmp.fdsmc
    for name, text in c_files(cmp, run_checks(params, run), force=True, controller=law).items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder


@pytest.fixture(scope="module")
def export(tmp_path_factory) -> Path:
    """The FDSMC module's export."""
    return _export(tmp_path_factory.mktemp("export"), "fdsmc")


def _golden(folder: Path, cc: str, flags: tuple[str, ...], build: str) -> str:
    """Build the golden test program with ``cc flags`` and run it; its last line (asserts exit 0)."""
    exe = f"fdsmc_test_{Path(cc).name}_{build}"
    make = subprocess.run([cc, *flags, *BUILDS[build], accept_flag(folder), "-O2", "fdsmc_test.c",
                           "fdsmc_controller.c", "-lm", "-o", exe], cwd=folder, capture_output=True, text=True)
    assert make.returncode == 0, make.stderr
    run = subprocess.run([f"./{exe}"], cwd=folder, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout
    return run.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize("build", BUILDS)
@pytest.mark.parametrize("cc", ["gcc", "clang"])
def test_c99_build_passes_the_golden_vectors(export, cc, build):
    last = _golden(export, tool(cc), CFLAGS, build)
    assert "faults and refusals as recorded" in last


@pytest.mark.parametrize("build", BUILDS)
@pytest.mark.parametrize("cxx", ["g++", "clang++"])
def test_the_source_compiles_as_cpp17_and_passes_the_golden_vectors(export, cxx, build):
    """-x c++ -std=c++17 -Wall -Wextra -Werror, test program and module both compiled as C++."""
    last = _golden(export, tool(cxx), CXXFLAGS, build)
    assert "faults and refusals as recorded" in last


@pytest.mark.parametrize("cxx", ["g++", "clang++"])
def test_the_tracked_optimums_source_compiles_as_cpp17(tmp_path, cxx):
    """Its reference table and law too: the module's source alone, both builds."""
    folder = _export(tmp_path, "optimum")
    for build in BUILDS:
        run = subprocess.run([tool(cxx), *CXXFLAGS, *BUILDS[build], accept_flag(folder), "-fsyntax-only",
                              "fdsmc_controller.c"], cwd=folder, capture_output=True, text=True)
        assert run.returncode == 0, (build, run.stderr)
