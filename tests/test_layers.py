"""House rule 1: control/ and sim/ import neither viser, plotly nor yaml; only app/presets.py uses yaml."""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_control_and_sim_do_not_import_ui_or_yaml():
    """Importing every module of control/ and sim/ imports no viser or plotly, and no project
    module of theirs imports yaml. (numba itself imports yaml to read an optional
    .numba_config.yaml file, so the yaml check records *who* imports it.)"""
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
        "import control, sim\n"
        "for pkg in (control, sim):\n"
        "    for m in pkgutil.iter_modules(pkg.__path__):\n"
        "        importlib.import_module(f'{pkg.__name__}.{m.name}')\n"
        "ui = [m for m in ('viser', 'plotly') if m in sys.modules]\n"
        "own = [c for c in culprits if c[1].startswith(('control', 'sim'))]\n"
        "print(ui, own)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert r.stdout.strip() == "[] []"


def test_only_preset_module_touches_yaml_and_only_app_touches_viser_plotly():
    pat_yaml = re.compile(r"^\s*(import yaml|from yaml)", re.M)
    pat_ui = re.compile(r"^\s*(import (viser|plotly)|from (viser|plotly))", re.M)
    for path in list(ROOT.glob("control/*.py")) + list(ROOT.glob("sim/*.py")) + list(ROOT.glob("app/*.py")):
        text = path.read_text(encoding="utf-8")
        rel = path.relative_to(ROOT).as_posix()
        if rel != "app/presets.py":
            assert not pat_yaml.search(text), f"{rel} imports yaml"
        if not rel.startswith("app/"):
            assert not pat_ui.search(text), f"{rel} imports viser/plotly"
        if rel.startswith(("control/", "sim/")):
            assert "open(" not in text and "read_text" not in text, f"{rel} does file I/O"
