"""A good neighbour: the wheel installs one top-level package, ``pmsm_commissioning``, so a control
engineer's python-control (top-level package ``control``) survives installing and uninstalling it.

A stand-in for python-control (``control/__init__.py`` defining ``tf``, with its dist-info) is put into a
fresh venv's site-packages; the built wheel is installed beside it (``--no-deps --no-index``, the
dependencies come from this interpreter through a ``.pth`` line): ``import control; control.tf`` still
works, ``pmsm_commissioning.control`` imports from the venv, the console command runs from another
folder, and uninstalling the wheel leaves python-control intact.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

from tests.test_install import build_wheel

ROOT = Path(__file__).resolve().parents[1]
STUB = ('"""Stand-in for python-control."""\n\n__version__ = "0.10.1"\n\n\n'
        'def tf(num, den):\n    return ("tf", num, den)\n')


def _run(cmd: list[str], cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_wheel(tmp_path_factory.mktemp("neighbour_build"), no_isolation=True)


def _venv_with_python_control(env_dir: Path) -> tuple[Path, Path]:
    """A new venv holding the python-control stand-in; its python and site-packages."""
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    purelib = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                        cwd=env_dir).stdout.strip())
    (purelib / "control").mkdir()
    (purelib / "control" / "__init__.py").write_text(STUB, encoding="utf-8")
    dist = purelib / "control-0.10.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: control\nVersion: 0.10.1\n", encoding="utf-8")
    (dist / "INSTALLER").write_text("pip\n", encoding="utf-8")
    (dist / "RECORD").write_text("control/__init__.py,,\ncontrol-0.10.1.dist-info/METADATA,,\n"
                                 "control-0.10.1.dist-info/INSTALLER,,\ncontrol-0.10.1.dist-info/RECORD,,\n",
                                 encoding="utf-8")
    deps = {sysconfig.get_path("purelib"), sysconfig.get_path("platlib")}
    (purelib / "_test_dependencies.pth").write_text("\n".join(sorted(deps)) + "\n", encoding="utf-8")
    return py, purelib


def _pip(py: Path, *args: str) -> None:
    r = _run([sys.executable, "-m", "pip", "--python", str(py), *args], cwd=py.parent)
    assert r.returncode == 0, r.stderr


CHECK = ("import control, pmsm_commissioning.control as pc, pmsm_commissioning.app.cli.main as m;"
         "print(control.tf([1], [1, 1])); print(control.__file__); print(pc.__file__); print(m.__file__)")


def test_the_wheel_installs_beside_python_control(wheel: Path, tmp_path: Path) -> None:
    env_dir = tmp_path / "venv"
    py, purelib = _venv_with_python_control(env_dir)
    _pip(py, "install", "--no-deps", "--no-index", "--quiet", str(wheel))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    drop = ("PYTHONPATH", "PYTHONHOME", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PYTHONUSERBASE")
    env = {**{k: v for k, v in os.environ.items() if k not in drop}, "HOME": str(tmp_path / "home")}
    r = _run([str(py), "-c", CHECK], cwd=elsewhere, env=env)
    assert r.returncode == 0, r.stderr
    tf, control_file, pc_file, main_file = r.stdout.splitlines()
    assert tf == "('tf', [1], [1, 1])"  # python-control's control.tf, untouched
    assert Path(control_file) == purelib / "control" / "__init__.py"
    assert (purelib / "control" / "__init__.py").read_text(encoding="utf-8") == STUB
    assert Path(pc_file) == purelib / "pmsm_commissioning" / "control" / "__init__.py"
    assert Path(main_file).is_relative_to(purelib / "pmsm_commissioning" / "app")
    # nothing generic in site-packages: no app/ or sim/, and control/ is python-control's alone
    assert not (purelib / "app").exists() and not (purelib / "sim").exists()
    assert sorted(p.name for p in (purelib / "control").iterdir() if p.name != "__pycache__") == ["__init__.py"]
    assert not (purelib / "pmsm_commissioning" / "__init__.py").exists()  # a namespace package
    # the console command from another folder
    r = _run([str(env_dir / "bin" / "pmsm-commission"), "derive", "yaskawa_sgm7j_04a", "--json"], cwd=elsewhere,
             env=env)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["feasible"] is True
    # uninstalling the wheel leaves python-control in place
    _pip(py, "uninstall", "--yes", "--quiet", "pmsm-commissioning")
    r = _run([str(py), "-c", "import control; print(control.tf([2], [1]))"], cwd=elsewhere, env=env)
    assert r.returncode == 0 and r.stdout.strip() == "('tf', [2], [1])", r.stderr
    assert not list((purelib / "pmsm_commissioning").rglob("*.py"))  # (pip may leave empty folders)
