"""Each hook of the page into viser's markup (app/ui/page_hooks.py) matches the page viser draws.

The page opens at 1280×720 and is brought into each hook's state (``PageHook.shown``): as opened;
a notification shown; viser's software-WebGL notice at page open; the results panel floating; the
control panel folded to its rail; a slider's thumb focused; the pointer resting on a widget with
a hint. In each, every hook of that state must match an element (with the text it names), the
matched elements must carry the attribute the page reads and Mantine's CSS variables the page
sets. One failure lists every hook viser's markup no longer has. The marks ``page_marks.js`` sets
from the hooks are checked on the way: ``data-app-bldc``, ``data-app-overview-window``,
``data-app-rail-left``, ``data-app-fit`` / ``-column`` / ``-hidden``.
"""

from __future__ import annotations

import json
from typing import Any

from pmsm_commissioning.app.ui import page_hooks as hk
from tests.browser.conftest import TIMEOUT_MS, click_tab, field, open_page, session_of

#: The problems of the hooks given (``[{name, sel, attr, text, vars}]``) in the page as it is now.
CHECK_JS = """(hooks) => hooks.flatMap(h => {
  const all = [...document.querySelectorAll(h.sel)]
    .filter(el => h.text === null || el.textContent.trim() === h.text);
  if (!all.length) return [`${h.name}: nothing matches ${h.sel}` + (h.text ? ` with the text "${h.text}"` : '')];
  const out = [];
  if (h.attr && !all.some(el => el.hasAttribute(h.attr))) out.push(`${h.name}: no ${h.sel} has ${h.attr}`);
  for (const v of h.vars) if (!getComputedStyle(all[0]).getPropertyValue(v).trim()) out.push(`${h.name}: no ${v}`);
  return out; })"""

#: Runs before the page's own scripts: records the hooks of the WebGL notice whenever they match.
RECORD_JS = """(() => { const hooks = HOOKS; window.__hooksSeen = [];
  new MutationObserver(() => { for (const h of hooks) {
    if (window.__hooksSeen.includes(h.name)) continue;
    const seen = [...document.querySelectorAll(h.sel)].some(el => el.textContent.trim() === h.text);
    if (seen) window.__hooksSeen.push(h.name);
  } }).observe(document, {childList: true, subtree: true, characterData: true}); })();"""

#: The WebGL renderer as viser's page reads it (BrowserWarning.tsx), lower case.
RENDERER_JS = """() => { const gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return '';
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  return String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER)).toLowerCase(); }"""
SOFTWARE = ("swiftshader", "llvmpipe", "softpipe", "software")


def _hooks(state: str) -> list[dict[str, Any]]:
    return [{"name": n, "sel": h.selector, "attr": h.attribute, "text": h.text, "vars": list(h.variables)}
            for n, h in hk.HOOKS.items() if h.shown == state]


class Check:
    """Collects the problems of every state, so that one failure names every hook missing."""

    def __init__(self, page: Any) -> None:
        self.page, self.problems, self.states = page, [], []

    def hooks(self, state: str) -> None:
        """Check the hooks of ``state`` in the page as it is now."""
        self.states.append(state)
        self.problems += [f"[{state}] {p}" for p in self.page.evaluate(CHECK_JS, _hooks(state))]

    def wait(self, state: str, condition_js: str, what: str, arg: Any = None) -> bool:
        """Wait for ``condition_js``; a problem of ``state`` (not an exception) if it never holds."""
        try:
            self.page.wait_for_function(condition_js, arg=arg, timeout=TIMEOUT_MS)
            return True
        except Exception:  # playwright's TimeoutError: reported with the others
            self.problems.append(f"[{state}] never: {what}")
            return False


def _visible(selector: str) -> str:
    return f"() => [...document.querySelectorAll({json.dumps(selector)})].some(e => e.getClientRects().length)"


def test_every_hook_matches_the_page_in_its_state(browser, ui_server):
    before = set(ui_server.config.sessions)
    record = RECORD_JS.replace("HOOKS", json.dumps(_hooks(hk.WEBGL)))
    context, page = open_page(browser, ui_server, {"width": 1280, "height": 720}, init_script=record)
    try:
        session, check = session_of(page, ui_server, before), Check(page)
        check.hooks(hk.OPEN)
        check.wait(hk.OPEN, "() => ['fit', 'column', 'hidden'].every(m => document.querySelector(`[data-app-${m}]`))",
                   "page_marks.js marked the region shadows, columns and hidden fields")
        _webgl_notice(check)
        _notification(check, session)
        _floating(check, session)
        _rail(check, session)
        _slider_held(check)
        _hint(check)
        assert sorted(check.states) == sorted(hk.STATES), "a state of app/ui/page_hooks.py is not brought about here"
        assert check.problems == [], (f"viser {hk.READ_FROM}'s page markup (app/ui/page_hooks.py) no longer has:\n"
                                      + "\n".join(check.problems))
    finally:
        context.close()


def _webgl_notice(check: Check) -> None:
    """viser's notice of a software renderer came at page open, and page_marks.js closed it (no 3D view)."""
    check.states.append(hk.WEBGL)
    if not any(name in check.page.evaluate(RENDERER_JS) for name in SOFTWARE):
        return  # a GPU renderer: viser shows no such notice
    seen = check.page.evaluate("() => window.__hooksSeen")
    check.problems += [f"[{hk.WEBGL}] {h['name']}: never matched {h['sel']} with the text {h['text']!r}"
                       for h in _hooks(hk.WEBGL) if h["name"] not in seen]
    check.wait(hk.WEBGL, "(h) => ![...document.querySelectorAll(h.sel)].some(e => e.textContent.trim() === h.text)",
               "page_marks.js closed the software WebGL notice", _hooks(hk.WEBGL)[0])


def _notification(check: Check, session: Any) -> None:
    note = session.client.add_notification("Page hooks", "A notification of the page-hooks test.")
    check.wait(hk.NOTICE, "(sel) => [...document.querySelectorAll(sel)].some(t => t.textContent.trim() === "
               "'Page hooks')", "the notification shown", hk.NOTIFICATION_TITLE.selector)
    check.hooks(hk.NOTICE)
    note.remove()


def _floating(check: Check, session: Any) -> None:
    panel = session.results.panel
    panel.float(x=400, y=40, width=600, height=500)
    if check.wait(hk.FLOATING, _visible(hk.FLOATING_WINDOW.selector), "the results panel floating"):
        check.wait(hk.FLOATING, "() => !!document.querySelector('[data-app-overview-window]')",
                   "page_marks.js marked the floating window of the Overview tab")
    check.hooks(hk.FLOATING)
    panel.dock_right()
    check.wait(hk.FLOATING, f"() => !document.querySelector({json.dumps(hk.FLOATING_WINDOW.selector)})",
               "the results panel docked again")


def _rail(check: Check, session: Any) -> None:
    session.gui.main_panel.minimize()
    if check.wait(hk.RAIL, _visible(hk.DOCK_COLUMN_RAIL.selector), "the control panel folded to its rail"):
        check.wait(hk.RAIL, "() => document.documentElement.hasAttribute('data-app-rail-left')",
                   "page_marks.js marked the left region folded")
    check.hooks(hk.RAIL)
    session.gui.main_panel.expand()
    check.wait(hk.RAIL, f"() => !document.querySelector({json.dumps(hk.DOCK_COLUMN_RAIL.selector)})",
               "the control panel unfolded again")


def _slider_held(check: Check) -> None:
    check.page.locator(hk.SLIDER_THUMB.selector).first.focus()
    check.wait(hk.SLIDER_HELD, _visible(hk.SLIDER_VALUE_LABEL.selector), "a focused slider's value bubble")
    check.hooks(hk.SLIDER_HELD)
    check.page.locator(hk.SLIDER_THUMB.selector).first.blur()


def _hint(check: Check) -> None:
    click_tab(check.page, "BLDC speed SMC")
    check.wait(hk.HINT_HOVER, "() => document.documentElement.hasAttribute('data-app-bldc')",
               "page_marks.js marked the BLDC tab selected")
    field(check.page, "Anti-windup on λ(ε)").hover()
    check.wait(hk.HINT_HOVER, _visible(hk.TOOLTIP.selector), "the hint of 'Anti-windup on λ(ε)'")
    check.hooks(hk.HINT_HOVER)
