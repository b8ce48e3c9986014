"""A newcomer's install: the built wheel, installed into a fresh venv, runs from any folder.

The wheel is built from a copy of the sources (nothing written into the clone), installed with
``--no-deps --no-index`` into a new venv whose dependencies come from this interpreter's
site-packages (a ``.pth`` line: no network), and its console entry point is run from a folder
that holds no source: ``design`` on a shipped preset and ``serve --help``. The presets and the
example drive log must then come from the installed package (importlib.resources).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _offline_build() -> bool:
    """True when this interpreter can build the wheel without fetching build requirements."""
    try:
        import setuptools
        from packaging.version import Version
    except ImportError:
        return False
    if Version(setuptools.__version__) < Version("68"):
        return False
    if Version(setuptools.__version__) >= Version("70.1"):  # bdist_wheel built in
        return True
    try:
        import wheel  # noqa: F401
    except ImportError:
        return False
    return True


def _run(cmd: list[str], cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    base = tmp_path_factory.mktemp("install")
    src = base / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".numba_cache")
    for pkg in ("app", "control", "sim"):
        shutil.copytree(ROOT / pkg, src / pkg, ignore=ignore)
    shutil.copytree(ROOT / "presets", src / "presets", ignore=ignore)
    shutil.copy(ROOT / "pyproject.toml", src / "pyproject.toml")
    dist = base / "dist"
    build = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(dist), str(src)]
    r = _run(build + (["--no-build-isolation"] if _offline_build() else []), cwd=base)
    assert r.returncode == 0, r.stderr
    wheels = list(dist.glob("pmsm_commissioning-*.whl"))
    assert len(wheels) == 1, wheels
    env_dir = base / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    r = _run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "--no-index", "--quiet",
              str(wheels[0])], cwd=base)
    assert r.returncode == 0, r.stderr
    purelib = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                        cwd=base).stdout.strip())
    deps = {sysconfig.get_path("purelib"), sysconfig.get_path("platlib")}
    (purelib / "_test_dependencies.pth").write_text("\n".join(sorted(deps)) + "\n", encoding="utf-8")
    elsewhere = base / "elsewhere"
    elsewhere.mkdir()
    return {"python": py, "script": env_dir / "bin" / "pmsm-commission", "cwd": elsewhere, "venv": env_dir}


def _env(installed: dict[str, Path]) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["NUMBA_CACHE_DIR"] = str(installed["venv"] / "numba_cache")
    return env


def test_the_installed_package_is_the_one_imported_with_its_data(installed: dict[str, Path]) -> None:
    code = ("import app, app.resources as r, app.io.presets as p;"
            "print(app.__file__); print(r.example_log().is_file()); print(','.join(p.list_presets()))")
    r = _run([str(installed["python"]), "-c", code], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    where, has_log, names = r.stdout.splitlines()
    assert Path(where).is_relative_to(installed["venv"])
    assert has_log == "True"
    assert names.split(",") == sorted(p.stem for p in (ROOT / "presets").glob("*.yaml"))


def test_console_entry_point_serve_help(installed: dict[str, Path]) -> None:
    r = _run([str(installed["script"]), "serve", "--help"], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert "--port" in r.stdout and "--preset" in r.stdout


def test_console_entry_point_designs_a_shipped_preset(installed: dict[str, Path]) -> None:
    r = _run([str(installed["script"]), "design", "yaskawa_sgm7j_04a", "--json"], cwd=installed["cwd"],
             env=_env(installed))
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["clean"] is True and out["preset"]["name"] == "yaskawa_sgm7j_04a"
    clone = _run([sys.executable, "-m", "app", "design", "yaskawa_sgm7j_04a", "--json"], cwd=ROOT)
    assert clone.returncode == 0, clone.stderr
    assert r.stdout == clone.stdout  # the installed package designs exactly as the clone


def test_the_installed_package_writes_the_c_controller_and_has_the_pages_scripts(installed: dict[str, Path],
                                                                                 tmp_path: Path) -> None:
    """The C texts (app/exports/c) and the page's scripts (app/ui/assets) are package data of the wheel."""
    out = tmp_path / "c"
    r = _run([str(installed["script"]), "export", "yaskawa_sgm7j_04a", "--format", "c", "-o", str(out)],
             cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert "fdsmc_step" in (out / "fdsmc_controller.c").read_text(encoding="utf-8")
    code = "import app.ui.plotly_js as p, app.ui.replay as r; print(len(p.bundle_source()), len(r.BUTTONS_JS))"
    r = _run([str(installed["python"]), "-c", code], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert all(int(n) > 100 for n in r.stdout.split())

