"""A newcomer's install: the built wheel runs from any folder, installed into a fresh venv, with
``pip install --user`` and with ``--target``.

The wheel is built from a copy of the sources (nothing written into the clone), installed with
``--no-deps --no-index`` into a new environment whose dependencies come from this interpreter's
site-packages (a ``.pth`` line: no network), and its console entry point is run from a folder
that holds no source: ``design`` on a shipped preset, ``derive``, ``serve --help``, ``--help`` and
``--version``. The presets and the example drive log must then come from the installed package
(importlib.resources), the compiled kernels' cache must go to the user's cache folder (a temporary
HOME), never into site-packages, and the wheel's metadata must carry the licence.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
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


#: Files of the clone a wheel is built from (the product's top-level folders and the packaging files).
SOURCES = ("app", "control", "sim", "presets", "pyproject.toml", "setup.py", "README.md", "LICENSE")


@pytest.fixture(scope="module")
def base(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("install")


def build_wheel(base: Path, no_isolation: bool) -> Path:
    """Copy the project's :data:`SOURCES` below ``base`` and build its wheel there; the wheel's path.

    ``no_isolation``: build with this interpreter's setuptools (no download of a build environment).
    """
    src = base / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", ".numba_cache")
    for name in SOURCES:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, src / name, ignore=ignore)
        else:
            shutil.copy(ROOT / name, src / name)
    dist = base / "dist"
    build = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(dist), str(src)]
    r = _run(build + (["--no-build-isolation"] if no_isolation else []), cwd=base)
    assert r.returncode == 0, r.stderr
    wheels = list(dist.glob("pmsm_commissioning-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="module")
def wheel(base: Path) -> Path:
    return build_wheel(base, _offline_build())


def _new_env(env_dir: Path, user_site: bool = False) -> Path:
    """A new venv without pip whose dependencies are this interpreter's (a ``.pth`` line); its python."""
    venv.EnvBuilder(with_pip=False, system_site_packages=user_site).create(env_dir)  # user site: needs system's
    py = env_dir / "bin" / "python"
    purelib = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                        cwd=env_dir).stdout.strip())
    deps = {sysconfig.get_path("purelib"), sysconfig.get_path("platlib")}
    (purelib / "_test_dependencies.pth").write_text("\n".join(sorted(deps)) + "\n", encoding="utf-8")
    return py


def _pip_install(py: Path, wheel: Path, *options: str, env: dict[str, str] | None = None) -> None:
    r = _run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "--no-index", "--quiet",
              *options, str(wheel)], cwd=wheel.parent, env=env)
    assert r.returncode == 0, r.stderr


@pytest.fixture(scope="module")
def installed(base: Path, wheel: Path) -> dict[str, Path]:
    env_dir = base / "venv"
    py = _new_env(env_dir)
    _pip_install(py, wheel)
    elsewhere = base / "elsewhere"
    elsewhere.mkdir()
    return {"python": py, "script": env_dir / "bin" / "pmsm-commission", "cwd": elsewhere, "venv": env_dir,
            "home": base / "home"}


def _env(installed: dict[str, Path]) -> dict[str, str]:
    """The user's environment less any cache or path setting: HOME is a temporary folder."""
    drop = ("PYTHONPATH", "PYTHONHOME", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PYTHONUSERBASE")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env["HOME"] = str(installed["home"])
    return env


def test_the_installed_package_is_the_one_imported_with_its_data(installed: dict[str, Path]) -> None:
    code = ("import pmsm_commissioning.app as app, pmsm_commissioning.app.resources as r, "
            "pmsm_commissioning.app.io.presets as p;"
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
    # the kernels compiled into the user's cache folder, nothing into the environment (site-packages)
    assert list((installed["home"] / ".cache" / "pmsm-commissioning" / "numba").rglob("*.nbi"))
    assert list(installed["venv"].rglob("*.nbi")) == [] and list(installed["venv"].rglob("*.nbc")) == []
    clone = _run([sys.executable, "-m", "pmsm_commissioning.app", "design", "yaskawa_sgm7j_04a", "--json"], cwd=ROOT)
    assert clone.returncode == 0, clone.stderr
    assert r.stdout == clone.stdout  # the installed package designs exactly as the clone


def test_the_installed_package_writes_the_c_controller_and_has_the_pages_scripts(installed: dict[str, Path],
                                                                                 tmp_path: Path) -> None:
    """The C texts (app/exports/firmware/c) and the page's scripts (app/ui/assets) are package data of the wheel."""
    out = tmp_path / "c"
    r = _run([str(installed["script"]), "export", "yaskawa_sgm7j_04a", "--format", "c", "-o", str(out)],
             cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert "fdsmc_step" in (out / "fdsmc_controller.c").read_text(encoding="utf-8")
    code = ("import pmsm_commissioning.app.ui.plotly_js as p, pmsm_commissioning.app.ui.replay as r; "
            "print(len(p.bundle_source()), len(r.BUTTONS_JS))")
    r = _run([str(installed["python"]), "-c", code], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert all(int(n) > 100 for n in r.stdout.split())



def test_the_wheel_carries_the_licence_and_the_metadata(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as z:
        info = next(n for n in z.namelist() if n.endswith(".dist-info/METADATA"))
        meta = z.read(info).decode("utf-8")
        names = z.namelist()
    assert "License-Expression: BSD-3-Clause" in meta and "License-File: LICENSE" in meta
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    assert "Author: The pmsm-commissioning developers" in meta and "Description-Content-Type: text/markdown" in meta
    assert "Classifier: Intended Audience :: Manufacturing" in meta
    assert "Provides-Extra: parquet" in meta and "Requires-Dist: pyarrow" in meta.split("Provides-Extra: parquet")[1]
    # one top-level package (nothing named app, control or sim in site-packages); the presets beside the code
    top = {n.split("/")[0] for n in names if not n.startswith("pmsm_commissioning-")}
    assert top == {"pmsm_commissioning"}, top
    parts = {n.split("/")[1] for n in names if n.startswith("pmsm_commissioning/")}
    assert parts == {"app", "control", "sim", "presets"}, parts
    assert "pmsm_commissioning/__init__.py" not in names  # a namespace package
    assert sorted(n for n in names if n.startswith("pmsm_commissioning/presets/")) == sorted(
        f"pmsm_commissioning/presets/{p.name}" for p in (ROOT / "presets").glob("*.yaml"))


def test_the_wheel_ships_the_c_texts_and_not_the_arm_bench_helpers(wheel: Path) -> None:
    """The C controller's texts are package data beside their reader; the ARM cross-compile helpers
    (scripts/c_arm.py, used by scripts/c_bench.py and the tests) are a developer's tool, not the product's.
    """
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
    texts = ROOT / "app" / "exports" / "firmware" / "c"
    assert sorted(n for n in names if n.endswith(".c.in")) == sorted(
        f"pmsm_commissioning/app/exports/firmware/c/{p.name}" for p in texts.glob("*.c.in"))
    assert len(list(texts.glob("*.c.in"))) >= 4
    assert [n for n in names if n.rsplit("/", 1)[-1] == "c_arm.py"] == []


def test_console_help_names_the_program_and_every_command_and_version(installed: dict[str, Path]) -> None:
    from pmsm_commissioning.app.cli.main import COMMANDS

    r = _run([str(installed["script"]), "--help"], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("usage: pmsm-commission ")
    listed = {line.split()[0] for line in r.stdout.splitlines() if re.match(r"    \S", line)}  # not wrapped lines
    assert listed == set(COMMANDS)
    r = _run([str(installed["script"]), "--version"], cwd=installed["cwd"], env=_env(installed))
    assert r.returncode == 0 and r.stdout.strip() == "pmsm-commission 0.1.0", (r.stdout, r.stderr)


#: Run in an installed environment: where the package, the presets and numba's cache are.
_WHERE = ("import pmsm_commissioning.app as app, numba, pmsm_commissioning.sim as sim, "
          "pmsm_commissioning.app.io.presets as p; print(app.__file__); print(numba.config.CACHE_DIR);"
          "print(','.join(p.list_presets()))")


def _check_other_install(py: Path, script: Path, env: dict[str, str], home: Path, lib: Path, cwd: Path,
                         launcher: list[str] | tuple[()] = ()) -> None:
    """The package imported from ``lib``, every preset found, numba's cache below ``home``; derive runs."""
    r = _run([str(py), "-c", _WHERE], cwd=cwd, env=env)
    assert r.returncode == 0, r.stderr
    where, cache, names = r.stdout.splitlines()
    assert Path(where).is_relative_to(lib)
    assert Path(cache).is_relative_to(home / ".cache" / "pmsm-commissioning" / "numba")
    assert names.split(",") == sorted(p.stem for p in (ROOT / "presets").glob("*.yaml"))
    r = _run([*launcher, str(script), "derive", "yaskawa_sgm7j_04a", "--json"], cwd=cwd, env=env)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["feasible"] is True


def test_pip_install_user_finds_the_presets(base: Path, wheel: Path) -> None:
    # the interpreter's data path is not the user base: the presets were "not found (allowed: )"
    py = _new_env(base / "user_venv", user_site=True)
    home, userbase = base / "user_home", base / "userbase"
    drop = ("PYTHONPATH", "PYTHONHOME", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PIP_USER", "PIP_TARGET")
    env = {**{k: v for k, v in os.environ.items() if k not in drop}, "HOME": str(home), "PYTHONUSERBASE": str(userbase)}
    _pip_install(py, wheel, "--user", env=env)
    _check_other_install(py, userbase / "bin" / "pmsm-commission", env, home, userbase, _empty(base / "user_cwd"))


def test_pip_install_target_finds_the_presets(base: Path, wheel: Path) -> None:
    py = _new_env(base / "target_venv")
    target, home = base / "target", base / "target_home"
    _pip_install(py, wheel, "--target", str(target))
    drop = ("PYTHONHOME", "NUMBA_CACHE_DIR", "XDG_CACHE_HOME")
    env = {**{k: v for k, v in os.environ.items() if k not in drop}, "HOME": str(home), "PYTHONPATH": str(target)}
    # --target writes target/bin/pmsm-commission for the interpreter that ran pip: run it with this one
    _check_other_install(py, target / "bin" / "pmsm-commission", env, home, target, _empty(base / "target_cwd"),
                         launcher=[str(py)])


def _empty(path: Path) -> Path:
    """A new empty folder to run from (no source of the clone in reach)."""
    path.mkdir()
    return path
