"""The project's modules import each other without circles, and app's parts import only the parts below them.

Every ``import`` counts: at module level, inside functions (a deferred import is still a dependency) and
under ``if TYPE_CHECKING:``. The layers are control/ → nothing of the project's other folders, sim/ →
control/, app/ → sim/ and control/ (tests/test_layers.py checks what they import from outside). Inside app/,
each part imports only the parts below it, from the bottom:

* ``app/resources.py``, ``app/threads.py`` — the package's data and the thread settings;
* ``app/io`` — reading and writing the user's files, units, text (no figure, no page);
* ``app/figures`` — pure ``make_*_figure(result)`` functions;
* ``app/exports`` — the files written for firmware and drives (may draw a figure into a report);
* ``app/ui`` — the page (offers the exports and figures);
* ``app/cli`` — the commands (``serve`` starts the page); ``app/__main__.py`` runs them.

A part importing one at its own level or above (``figures`` → ``ui``, ``exports`` → ``ui``) is a sideways or
upward import: what both need belongs in the lower part. Inside ``app/exports``, ``firmware`` (the C module and
its checks) and ``drives`` (the stock drives' files and the stock route) import neither the other: what both
use (``provenance``, ``tool_id``) is in ``app/exports`` itself, and ``model`` dispatches to both.
"""

from __future__ import annotations

import ast
import functools
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
PKG = "pmsm_commissioning"

#: app's parts and their level from the bottom; a part imports only parts of a lower level (and itself).
APP_LEVEL = {"resources": 0, "threads": 0, "io": 1, "figures": 2, "exports": 3, "ui": 4, "cli": 5, "__main__": 6}

#: No exception: every circle and every sideways import fails the tests.
KNOWN_CIRCLES: frozenset[frozenset[str]] = frozenset()
KNOWN_SIDEWAYS: frozenset[tuple[str, str]] = frozenset()


def _module_name(path: pathlib.Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules() -> dict[str, pathlib.Path]:
    return {_module_name(p): p for top in ("app", "control", "sim") for p in (ROOT / top).rglob("*.py")
            if "__pycache__" not in p.parts}


def _imports(path: pathlib.Path, known: set[str]) -> set[str]:
    """The project's modules ``path`` imports (``from pkg import sub`` counts as importing ``pkg.sub`` only)."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            subs = [f"{node.module}.{a.name}" for a in node.names]
            names = [s for s in subs if s.removeprefix(PKG + ".") in known] or [node.module]
        else:
            continue
        found |= {n.removeprefix(PKG + ".") for n in names if n.startswith(PKG + ".")}
    return found & known


@functools.cache
def _graph() -> dict[str, set[str]]:
    mods = _modules()
    return {m: _imports(p, set(mods)) - {m} for m, p in mods.items()}


def _circles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """Strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[frozenset[str]] = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            w = next(children, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = set()
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.add(w)
                    if w == v:
                        break
                if len(component) > 1:
                    found.append(frozenset(component))
    return found


def _app_part(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "app" and len(parts) > 1 else None


def test_no_import_circles():
    circles = _circles(_graph())
    new = [sorted(c) for c in circles if c not in KNOWN_CIRCLES]
    assert not new, f"import circles: {new}"


def test_the_circle_finder_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _circles(graph) == [frozenset({"a", "b", "c"})]


def test_app_parts_import_only_the_parts_below_them():
    graph = _graph()
    assert {_app_part(m) for m in graph} - {None, *APP_LEVEL} == set(), "a new part of app/: give it its level"
    wrong = []
    for module, deps in graph.items():
        part = _app_part(module)
        for dep in deps:
            dep_part = _app_part(dep)
            if part is None or dep_part is None or dep_part == part or (module, dep) in KNOWN_SIDEWAYS:
                continue
            if APP_LEVEL[dep_part] >= APP_LEVEL[part]:
                wrong.append(f"{module} imports {dep}")
    assert not wrong, "\n".join(sorted(wrong))


def test_control_and_sim_import_nothing_above_them():
    graph = _graph()
    up = [f"{m} imports {d}" for m, deps in graph.items() for d in deps
          if (m.startswith("control") and not d.startswith("control"))
          or (m.startswith("sim") and d.startswith("app"))]
    assert not up, "\n".join(sorted(up))


#: Sub-packages of app/exports that import neither the other.
EXPORT_SIBLINGS = ("app.exports.firmware", "app.exports.drives")


def test_firmware_and_drives_import_neither_the_other():
    graph = _graph()
    assert all(any(m.startswith(s + ".") for m in graph) for s in EXPORT_SIBLINGS), "a sub-package is gone"
    wrong = [f"{m} imports {d}" for m, deps in graph.items() for d in deps
             for a, b in (EXPORT_SIBLINGS, EXPORT_SIBLINGS[::-1])
             if (m == a or m.startswith(a + ".")) and (d == b or d.startswith(b + "."))]
    assert not wrong, "\n".join(sorted(wrong))
