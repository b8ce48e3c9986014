"""Layers: control/ and sim/ (every sub-package) import neither viser, plotly nor yaml; only app/io/yaml_text.py
uses yaml; the page (app/ui) never imports the command line (app/cli).
"""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_control_and_sim_do_not_import_ui_or_yaml():
    """Importing every module of control/ and sim/ imports no viser or plotly, and no project
    module of theirs imports yaml. (numba itself imports yaml to read an optional
    .numba_config.yaml file, so the yaml check records *who* imports it.)
    """
    code = (
        "import sys, pkgutil, importlib\n"
        "culprits = []\n"
        "class Spy:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name.split('.')[0] in ('viser', 'plotly', 'yaml'):\n"
        "            f = sys._getframe(1)\n"
        "            while f and f.f_globals.get('__name__', '').startswith(('importlib', '_frozen')):\n"
        "                f = f.f_back\n"
        "            culprits.append((name, f.f_globals.get('__name__', '?') if f else '?'))\n"
        "        return None\n"
        "sys.meta_path.insert(0, Spy())\n"
        "import pmsm_commissioning.control as control, pmsm_commissioning.sim as sim\n"
        "n = 0\n"
        "for pkg in (control, sim):\n"
        "    for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + '.'):\n"
        "        importlib.import_module(m.name)\n"
        "        n += not m.ispkg\n"
        "ui = [m for m in ('viser', 'plotly') if m in sys.modules]\n"
        "own = [c for c in culprits if c[1].startswith(('pmsm_commissioning.control', 'pmsm_commissioning.sim'))]\n"
        "print(ui, own, n)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    n = int(r.stdout.split()[-1])
    assert r.stdout.strip() == f"[] [] {n}"
    # every module of every sub-package was imported, not only the top level
    assert n == len(_modules("control")) + len(_modules("sim"))


def test_only_preset_module_touches_yaml_and_only_app_touches_viser_plotly():
    pat_yaml = re.compile(r"^\s*(import yaml|from yaml)", re.M)
    pat_ui = re.compile(r"^\s*(import (viser|plotly)|from (viser|plotly))", re.M)
    for path in [p for pkg in ("control", "sim", "app") for p in ROOT.glob(f"{pkg}/**/*.py")]:
        text = path.read_text(encoding="utf-8")
        rel = path.relative_to(ROOT).as_posix()
        if rel != "app/io/yaml_text.py":
            assert not pat_yaml.search(text), f"{rel} imports yaml"
        if not rel.startswith("app/"):
            assert not pat_ui.search(text), f"{rel} imports viser/plotly"
        if rel.startswith(("control/", "sim/")):
            assert "open(" not in text and "read_text" not in text, f"{rel} does file I/O"


def _modules(pkg: str) -> list[pathlib.Path]:
    """Every module below ``pkg`` except the package markers themselves."""
    return [p for p in (ROOT / pkg).rglob("*.py") if p.name != "__init__.py" and "__pycache__" not in p.parts]


def test_page_never_imports_command_line():
    pat = re.compile(r"^\s*(from pmsm_commissioning\.app\.cli\b|import pmsm_commissioning\.app\.cli\b)", re.M)
    for path in (ROOT / "app" / "ui").rglob("*.py"):
        assert not pat.search(path.read_text(encoding="utf-8")), f"{path.relative_to(ROOT)} imports app.cli"
