"""Every hook of the page's scripts and CSS into viser's page markup, declared once.

viser (React + Mantine) draws the page; the page's own scripts (``app/ui/assets/*.js`` and the
scripts of :mod:`app.ui.layout`, :mod:`app.ui.demo_view`, :mod:`app.ui.bldc_results`) and CSS
(:func:`app.ui.layout.page_css`, :data:`app.ui.layout.LEGIBILITY_CSS`) find viser's elements by
the selectors below, read from the client of viser :data:`READ_FROM` (its sources ship with the
package: ``viser/client/src``, the file named in each hook's ``what``). A script names a hook as
``H.<NAME>`` (``.sel``: its selector, ``.attr``: the attribute whose value it reads, ``.text``: the
text it looks for, ``.vars``: Mantine's CSS variables it sets); :func:`with_hooks` puts the hooks it
names into its ``PAGE_HOOKS`` placeholder.

``tests/browser/test_page_hooks.py`` opens the page, brings it into each hook's state
(:attr:`PageHook.shown`) and fails naming every hook viser's markup no longer has;
``tests/test_page_hooks.py`` fails on a selector of viser's markup written anywhere else.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass

from pmsm_commissioning.app.ui.viser_adapter import WRITTEN_FOR

#: The viser release whose page markup the hooks were read from.
READ_FROM = WRITTEN_FOR

#: The page states a hook is shown in (:attr:`PageHook.shown`), as the browser test brings them about.
OPEN = "the page as it opens (position mode)"
NOTICE = "a notification shown (viser's notices; the test sends one with ClientHandle.add_notification)"
WEBGL = "page open with a software WebGL renderer (headless Chromium: SwiftShader), until page_marks.js closes it"
FLOATING = "a panel floating (PanelHandle.float(); viser floats a new panel for a frame before it docks)"
RAIL = "a docked region folded to its rail (its handle clicked, or PanelHandle.minimize())"
SLIDER_HELD = "a slider's thumb focused or held (viser turns Mantine's display on hover off)"
HINT_HOVER = "the pointer resting (≥ 0.5 s) on a widget with a hint (the BLDC tab's 'Anti-windup on λ(ε)')"
STATES = (OPEN, NOTICE, WEBGL, FLOATING, RAIL, SLIDER_HELD, HINT_HOVER)


@dataclass(frozen=True)
class PageHook:
    """One element of viser's page the page's scripts or CSS find.

    ``selector`` matches it; ``attribute`` is the attribute whose value a script reads or matches
    (None: none); ``text`` the text a script looks for in it; ``variables`` Mantine's CSS variables
    a script sets on it; ``what`` says what it is in viser's page (and where viser draws it),
    ``used_in`` where the page uses it, ``shown`` the page state it appears in (:data:`STATES`).
    """

    selector: str
    what: str
    used_in: tuple[str, ...]
    attribute: str | None = None
    shown: str = OPEN
    text: str | None = None
    variables: tuple[str, ...] = ()

    def at(self, value: str) -> str:
        """Return the selector with its attribute at ``value`` (``[data-dock-region="left"]``)."""
        if self.attribute is None or not self.selector.endswith(f"[{self.attribute}]"):
            raise ValueError(f"hook {self.selector!r}: no attribute selector to give the value {value!r}")
        return f'{self.selector[:-1]}="{value}"]'


_MARKS, _VIEW, _REPLAY = "assets/page_marks.js", "assets/page_view.js", "assets/replay_buttons.js"
_CSS, _LEGIBLE = "layout.page_css", "layout.LEGIBILITY_CSS"
_WINDOW, _TABS, _FOLLOW = "layout.window_report_js", "demo_view.select_tabs_js", "bldc_results.follow_tabs_js"

# ---- the dock (viser/client/src/dock) ----------------------------------------------------------
DOCK_ROOT = PageHook("[data-dock-root]", "the dock's root box, the whole page (DockManager.tsx)",
                     (_MARKS, _CSS), attribute="data-dock-root")
DOCK_CANVAS = PageHook("[data-dock-root] > div:first-child",
                       "the box of the 3D canvas between the docked regions, the dock root's first child "
                       "(DockManager.tsx)", (_CSS,))
DOCK_REGION = PageHook("[data-dock-region]", "a docked region, value its edge left/right; the div just before it, "
                       "a child of the dock root, is its shadow (DockManager.tsx)", (_MARKS, _CSS, _FOLLOW),
                       attribute="data-dock-region")
DOCK_COLUMN = PageHook("[data-dock-region] [data-dock-column]",
                       "a column of a docked region; its parent div is the region's column row (SplitView.tsx)",
                       (_MARKS,), attribute="data-dock-column")
DOCK_COLUMN_RAIL = PageHook("[data-dock-column-rail]",
                            "the handle bar of a column folded to its rail (VerticalMinimizedColumn.tsx)",
                            (_MARKS,), attribute="data-dock-column-rail", shown=RAIL)
FLOATING_WINDOW = PageHook("[data-floating-window]", "a floating panel's window (FloatingWindowView.tsx)",
                           (_MARKS,), attribute="data-floating-window", shown=FLOATING)
TAB = PageHook('[role="tab"]', "a dock tab; its title attribute is the pane's title (TabGroupFrame.tsx)",
               (_MARKS, _VIEW, _TABS, _FOLLOW, _CSS, _LEGIBLE), attribute="title")
SELECTED_TAB = PageHook('[role="tab"][aria-selected="true"]', "the selected tab of a tab group (TabGroupFrame.tsx)",
                        (_MARKS, _VIEW, _TABS, _FOLLOW), attribute="aria-selected")
TAB_ICON = PageHook('[role="tab"] > div:first-child:not(:last-child)',
                    "the icon box before a tab's label, in a tab with an icon (TabGroupFrame.tsx)", (_CSS,))

# ---- widgets (viser/client/src/components) -----------------------------------------------------
FIELD_LABEL = PageHook("label[for]", "a widget's label, its for attribute the widget's uuid (common.tsx)",
                       (_MARKS, _VIEW, _WINDOW, _REPLAY), attribute="for")
FIELD_ROW = PageHook(".mantine-Flex-root", "the Flex row of a widget's label and input (common.tsx LabeledInput)",
                     (_MARKS, _VIEW, _WINDOW, _REPLAY))
SLIDER = PageHook(".mantine-Slider-root", "a slider's Mantine root (Slider.tsx)", (_MARKS,))
SLIDER_MARK_LABEL = PageHook(".mantine-Slider-markLabel", "the label of a mark on a slider's track (Slider.tsx)",
                             (_MARKS, _LEGIBLE))
SLIDER_THUMB = PageHook('[role="slider"]', "a slider's thumb: aria-valuemax its maximum; Mantine's "
                        "--slider-thumb-offset places it (Slider.tsx)", (_REPLAY,), attribute="aria-valuemax",
                        variables=("--slider-thumb-offset",))
SLIDER_BAR = PageHook(".mantine-Slider-bar", "a slider's filled bar: Mantine's --slider-bar-width, in units of "
                      "--slider-size (Slider.tsx)", (_REPLAY,), variables=("--slider-bar-width", "--slider-size"))
SLIDER_VALUE_LABEL = PageHook(".mantine-Slider-label", "the value bubble over a slider's thumb (Slider.tsx)",
                              (_LEGIBLE,), shown=SLIDER_HELD)
NUMBER_INPUT = PageHook("input.mantine-NumberInput-input", "the number box of a slider or number field "
                        "(Slider.tsx, NumberInput.tsx)", (_REPLAY,))
INPUT = PageHook(".mantine-Input-input", "a text, number or select input's box (Mantine Input)", (_LEGIBLE,))
INPUT_LABEL = PageHook(".mantine-InputWrapper-label", "a Mantine input's own label (Mantine InputWrapper)",
                       (_LEGIBLE,))
BUTTON_LABEL = PageHook(".mantine-Button-label", "a button's label (Button.tsx)", (_LEGIBLE,))
SELECT_OPTION = PageHook(".mantine-Select-option", "an option of a dropdown (Dropdown.tsx, Mantine Select)",
                         (_LEGIBLE,))
CHECKBOX_LABEL = PageHook(".mantine-Checkbox-label", "a checkbox's label (Checkbox.tsx)", (_LEGIBLE,))
TOOLTIP = PageHook(".mantine-Tooltip-tooltip", "the hint of a widget (common.tsx ViserInputComponent)",
                   (_LEGIBLE,), shown=HINT_HOVER)
TEXT = PageHook(".mantine-Text-root", "a Mantine Text: a widget's label line (common.tsx) and texts", (_LEGIBLE,))
PAPER = PageHook(".mantine-Paper-root", "a Mantine Paper: a folder's box (Folder.tsx) and panels", (_LEGIBLE,))

# ---- notices (viser/client/src/BrowserWarning.tsx, @mantine/notifications) ---------------------
NOTIFICATION = PageHook(".mantine-Notification-root", "a notification's box", (_MARKS,), shown=NOTICE)
NOTIFICATION_TITLE = PageHook(".mantine-Notification-title", "a notification's title", (_MARKS,), shown=NOTICE)
NOTIFICATION_CLOSE = PageHook(".mantine-Notification-closeButton", "a notification's close button",
                              (_MARKS,), shown=NOTICE)
SOFTWARE_WEBGL_NOTICE = PageHook(".mantine-Notification-title", "the title of viser's notice of a software WebGL "
                                 "renderer (BrowserWarning.tsx)", (_MARKS,), shown=WEBGL,
                                 text="Software WebGL rendering detected")

#: Every hook by name (the name a page script uses: ``H.DOCK_REGION``).
HOOKS: dict[str, PageHook] = {name: hook for name, hook in dict(globals()).items() if isinstance(hook, PageHook)}

#: The placeholder of a page script replaced by the hooks it names (:func:`with_hooks`).
PLACEHOLDER = "PAGE_HOOKS"
_NAMED = re.compile(r"\bH\.([A-Z][A-Z_]*)\b(?:\.(\w+))?")


def _fields(hook: PageHook) -> dict[str, object]:
    """Return the hook as a page script reads it: ``sel``, and ``attr``, ``text``, ``vars`` where it has them."""
    out: dict[str, object] = {"sel": hook.selector, "attr": hook.attribute, "text": hook.text,
                              "vars": list(hook.variables) or None}
    return {key: value for key, value in out.items() if value is not None}


def hooks_named(source: str) -> list[str]:
    """Return the names of the hooks a page script uses (``H.<NAME>.<field>``), sorted.

    ValueError naming the hook for one not declared here, or a field it does not have.
    """
    uses = set(_NAMED.findall(source))
    unknown = sorted({name for name, _ in uses if name not in HOOKS})
    if unknown:
        raise ValueError(f"page script names undeclared hooks {unknown}: declare them in app/ui/page_hooks.py")
    missing = sorted(f"H.{name}.{field}" for name, field in uses if field and field not in _fields(HOOKS[name]))
    if missing:
        raise ValueError(f"page script reads {missing}: fields those hooks do not have (app/ui/page_hooks.py)")
    return sorted({name for name, _ in uses})


def with_hooks(source: str) -> str:
    """Return the page script ``source`` with its ``PAGE_HOOKS`` placeholder replaced by the hooks it names.

    Each hook becomes ``{"sel": selector, "attr": attribute, "text": text, "vars": [CSS variables]}``
    (JSON; only the fields it has).
    """
    table = {name: _fields(HOOKS[name]) for name in hooks_named(source)}
    if PLACEHOLDER not in source:
        raise ValueError(f"page script has no {PLACEHOLDER} placeholder for its hooks {sorted(table)}")
    return source.replace(PLACEHOLDER, json.dumps(table, ensure_ascii=False))


__all__ = ["HOOKS", "PLACEHOLDER", "READ_FROM", "STATES", "PageHook", "hooks_named", "with_hooks",
           *sorted(HOOKS)]
