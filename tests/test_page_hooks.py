"""The page's hooks into viser's page markup are declared once, in app/ui/page_hooks.py.

Every page script gets the hooks it names from the declaration; no selector of viser's markup is
written anywhere else in app/ (Python string literals, docstrings aside, and the page's own
JavaScript files, comments aside); and each hook names an attribute, Mantine component or text
that viser's shipped client sources (``viser/client/src``) still have. Whether the page drawn by
viser matches each hook is checked in a browser: ``tests/browser/test_page_hooks.py``.
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import pytest
import viser

from pmsm_commissioning.app.ui import page_hooks as hk
from pmsm_commissioning.app.ui.bldc_results import follow_tabs_js
from pmsm_commissioning.app.ui.demo_state import PageView
from pmsm_commissioning.app.ui.demo_view import select_tabs_js, view_report_js
from pmsm_commissioning.app.ui.layout import LEGIBILITY_CSS, page_css, page_marks_js, window_report_js
from pmsm_commissioning.app.ui.replay import BUTTONS_JS

ROOT = Path(__file__).resolve().parents[1]
CLIENT_SRC = Path(viser.__file__).parent / "client" / "src"

#: What a hook into viser's markup looks like in code: its dock attributes, Mantine's class names,
#: ARIA roles and states, a label's ``for``, Mantine's slider variables, viser's notice text.
MARKUP = re.compile(r"data-dock|data-floating|mantine-|(?<![-\w])role\s*=|\baria-|label\[for|--slider-"
                    r"|Software WebGL")


def _scripts() -> dict[str, str]:
    return {"page_marks": page_marks_js(["uuid-a"]), "page_view": view_report_js("uuid-b"),
            "select_tabs": select_tabs_js(PageView(mode_tab="BLDC speed SMC", results_tab="Overview")),
            "follow_tabs": follow_tabs_js(), "window_report": window_report_js("uuid-c"), "replay": BUTTONS_JS}


def test_the_hooks_are_read_from_the_viser_the_adapter_was_written_for():
    assert viser.__version__ == hk.READ_FROM
    for name, hook in hk.HOOKS.items():
        assert hook.shown in hk.STATES, f"{name}: unknown state {hook.shown!r}"
        assert hook.used_in and hook.what, f"{name}: say what it is and where the page uses it"


@pytest.mark.parametrize("name", sorted(_scripts()))
def test_each_page_script_gets_the_hooks_it_names(name):
    script = _scripts()[name]
    assert hk.PLACEHOLDER not in script
    start = script.index("H = ") + len("H = ")
    table, end = json.JSONDecoder().raw_decode(script, start)
    assert sorted(table) == hk.hooks_named(script) and table
    assert {h["sel"] for h in table.values()} <= {h.selector for h in hk.HOOKS.values()}
    rest = script[:start] + script[end:]  # the script without its hooks: no markup of viser's of its own
    assert not MARKUP.search(rest), MARKUP.search(rest)


def test_a_script_naming_an_undeclared_hook_or_field_is_refused():
    with pytest.raises(ValueError, match="H.NO_SUCH_HOOK|NO_SUCH_HOOK"):
        hk.with_hooks("const H = PAGE_HOOKS; H.NO_SUCH_HOOK.sel")
    with pytest.raises(ValueError, match=r"H\.FIELD_ROW\.attr"):
        hk.with_hooks("const H = PAGE_HOOKS; H.FIELD_ROW.attr")
    with pytest.raises(ValueError, match="placeholder"):
        hk.with_hooks("H.TAB.sel")


def test_the_page_css_selects_viser_only_by_the_declared_hooks():
    css = page_css() + page_css(show_3d=True) + LEGIBILITY_CSS
    for name in ("DOCK_ROOT", "DOCK_CANVAS", "TAB", "TAB_ICON", "SLIDER_MARK_LABEL", "TOOLTIP"):
        assert hk.HOOKS[name].selector in css, name
    assert hk.DOCK_REGION.at("left") in css and hk.DOCK_REGION.at("right") in css


#: Where a hook says it is used (``PageHook.used_in``) → the script's name in :func:`_scripts`.
SCRIPT_OF = {"assets/page_marks.js": "page_marks", "assets/page_view.js": "page_view",
             "assets/replay_buttons.js": "replay", "layout.window_report_js": "window_report",
             "demo_view.select_tabs_js": "select_tabs", "bldc_results.follow_tabs_js": "follow_tabs"}


def test_each_hook_says_truly_where_the_page_uses_it():
    scripts = {name: set(hk.hooks_named(text)) for name, text in _scripts().items()}
    css = {"layout.page_css": page_css() + page_css(show_3d=True), "layout.LEGIBILITY_CSS": LEGIBILITY_CSS}
    claimed = {(name, place) for name, hook in hk.HOOKS.items() for place in hook.used_in}
    used = {(name, place) for place, script in SCRIPT_OF.items() for name in scripts[script]}
    used |= {(name, place) for place, text in css.items() for name, hook in hk.HOOKS.items()
             if hook.selector in text or (hook.attribute and hook.selector[:-1] + "=" in text)}
    assert claimed - used == set(), "hooks said to be used where they are not"
    assert used - claimed == set(), "hooks used where their used_in does not say"


def _string_literals(path: Path) -> list[tuple[int, str]]:
    """String constants of a module (f-strings' literal parts too), docstrings left out."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings]


def test_no_selector_of_viser_markup_is_written_outside_the_declaration():
    offenders = []
    for path in sorted((ROOT / "app").rglob("*.py")):
        if path.name == "page_hooks.py":
            continue
        offenders += [f"{path.relative_to(ROOT)}:{line}: {m.group(0)!r}" for line, text in _string_literals(path)
                      for m in MARKUP.finditer(text)]
    for path in sorted((ROOT / "app" / "ui" / "assets").glob("*.js")):
        if path.name.startswith("plotly-basic"):
            continue  # plotly.js itself
        for line, text in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            code = re.sub(r"//.*$", "", text)
            offenders += [f"{path.relative_to(ROOT)}:{line}: {m.group(0)!r}" for m in MARKUP.finditer(code)]
    assert offenders == [], "declare these hooks in app/ui/page_hooks.py and use them from there"


def _client_sources() -> str:
    assert CLIENT_SRC.is_dir(), f"viser {viser.__version__} ships no client sources at {CLIENT_SRC}"
    return "\n".join(p.read_text(encoding="utf-8", errors="replace")
                     for p in sorted(CLIENT_SRC.rglob("*.ts*")))


#: Mantine parts drawn inside another component (their class prefix is no component viser imports).
DRAWN_BY = {"Notification": "Notifications", "Input": "NumberInput", "InputWrapper": "NumberInput"}
#: ARIA roles Mantine's components set (not viser's own markup).
ROLE_OF = {"slider": "Slider"}


def _imports_mantine(src: str, component: str) -> bool:
    return re.search(rf"\b{DRAWN_BY.get(component, component)}\b[^;]*from \"@mantine/", src) is not None


def _missing_in(src: str, name: str, hook: hk.PageHook) -> list[str]:
    missing = [f"attribute {a}" for a in re.findall(r"\[(data-[\w-]+)", hook.selector) if a not in src]
    missing += [f"Mantine component {c}" for c in re.findall(r"\.mantine-(\w+)-", hook.selector)
                if not _imports_mantine(src, c)]
    for role in re.findall(r'role="(\w+)"', hook.selector):
        drawn = _imports_mantine(src, ROLE_OF[role]) if role in ROLE_OF else f'role="{role}"' in src
        missing += [] if drawn else [f"role {role}"]
    if hook.attribute is not None and hook.attribute.startswith("data-") and hook.attribute not in src:
        missing.append(f"attribute {hook.attribute}")
    if hook.text is not None and hook.text not in src:
        missing.append(f"text {hook.text!r}")
    return [f"{name}: {m}" for m in sorted(set(missing))]


def test_each_hook_names_what_viser_s_client_sources_still_have():
    src = _client_sources()
    missing = [m for name, hook in hk.HOOKS.items() for m in _missing_in(src, name, hook)]
    assert missing == [], f"viser {viser.__version__}'s client no longer has these hooks (app/ui/page_hooks.py)"
