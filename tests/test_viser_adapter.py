"""viser's private API is used in app/ui/viser_adapter.py only, for the viser release it was written for.

A viser upgrade fails here first: the version pin, then each private name the adapter relies on,
exercised on a real (local, verbose-off) server; and no other module of app/ touches a private
name of viser.
"""

from __future__ import annotations

import re
from pathlib import Path

import viser
from viser import _icons

from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.ui import viser_adapter as va
from pmsm_commissioning.app.ui.viser_adapter import PAGE_ICONS, warm_icons

ROOT = Path(__file__).resolve().parents[1]


def test_viser_is_the_release_the_adapter_was_written_for():
    assert viser.__version__ == va.WRITTEN_FOR



def test_a_figure_is_shown_and_an_unchanged_one_not_sent_again(gui, monkeypatch):
    first = figure_json({"data": [{"type": "scatter", "x": [0, 1], "y": [1, 2]}], "layout": {}})
    handle = va.add_figure(gui, first, aspect=0.5)
    assert handle._plotly_json_str == first and handle.aspect == 0.5
    sent: list[str] = []
    original = type(handle)._queue_update

    def spy(self, name, value):
        sent.append(name)
        return original(self, name, value)

    monkeypatch.setattr(type(handle), "_queue_update", spy)
    va.set_figure_json(handle, first)  # unchanged: nothing sent
    second = figure_json({"data": [], "layout": {"title": {"text": "b"}}})
    va.set_figure_json(handle, second)
    assert sent == ["_plotly_json_str"] and handle._plotly_json_str == second


def test_widget_id_script_and_plotly_flag(gui):
    text = gui.add_text("probe", "")
    assert va.widget_id(text) == text._impl.uuid and va.widget_id(text)
    va.run_script(gui, "void 0;")  # viser's own message type still exists and queues
    va.mark_plotly_js_sent(gui)
    assert va.plotly_js_sent(gui) is True and gui._setup_plotly_js is True
    assert va.input_widget(gui, va.widget_id(text)) is text and va.widget_state(text).removed is False
    assert va.widget_state(text).props.label == "probe" and isinstance(va.upload_states(gui), dict)
    for name in (va.GUI_UPDATES, va.UPLOAD_START, va.UPLOAD_PART):  # the handlers web_guard wraps exist
        assert callable(getattr(viser.GuiApi, name))


def _viser_private_names() -> set[str]:
    root = Path(viser.__file__).parent
    names: set[str] = set()
    for f in root.rglob("*.py"):
        names |= set(re.findall(r"self\.(_[a-zA-Z]\w*)", f.read_text(encoding="utf-8")))
    return {n for n in names if not n.startswith("__")}


def test_no_other_module_touches_viser_privates():
    names = _viser_private_names()
    assert {"_impl", "_plotly_json_str", "_websock_interface", "_setup_plotly_js"} <= names
    attr = re.compile(r"(?<!self)(?<!cls)\.(" + "|".join(sorted(names)) + r")\b")
    module = re.compile(r"from viser import _|viser\._|import viser\._")
    offenders = []
    for path in sorted((ROOT / "app").rglob("*.py")):
        if path.name == "viser_adapter.py":
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if attr.search(line) or module.search(line):
                offenders.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert offenders == []


def test_the_icons_warmed_at_server_start_are_all_the_page_shows():
    """Every ``viser.Icon.X`` the UI modules use is in PAGE_ICONS (read at server start, not on the first page)."""
    used = set()
    for path in (Path(__file__).resolve().parents[1] / "app" / "ui").rglob("*.py"):
        used |= set(re.findall(r"viser\.Icon\.([A-Z0-9_]+)", path.read_text(encoding="utf-8")))
    assert used == set(PAGE_ICONS)
    warm_icons()
    assert _icons.svg_from_icon.cache_info().currsize >= len(PAGE_ICONS)  # viser's cache holds them all
    assert all(_icons.svg_from_icon(getattr(viser.Icon, name)).lstrip().startswith("<svg") for name in PAGE_ICONS)


def test_the_request_wrapper_sees_every_request_of_a_server_built_under_it():
    """viser still serves through ``websockets``' ``serve``: the wrapped handler sees the page's GET."""
    import socket
    import urllib.request

    seen: list[str] = []

    def wrap(process_request):
        def check(connection, request):
            seen.append(request.path)
            return process_request(connection, request) if process_request else None
        return check

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = int(s.getsockname()[1])
    with va.wrap_requests(wrap):
        server = viser.ViserServer(host="127.0.0.1", port=port, verbose=False)
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/?probe=1", timeout=10) as response:
            assert response.status == 200
        assert "/?probe=1" in seen
    finally:
        server.stop()
