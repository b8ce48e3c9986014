"""The demo link: a demo state kept under a short token, named by the page's address, read from the window report."""

from __future__ import annotations

import json

import pytest

from pmsm_commissioning.app.ui import demo_link
from pmsm_commissioning.app.ui.demo_link import MAX_STATES, DemoLink, address_js, keep_state, state_of
from pmsm_commissioning.app.ui.layout import MAX_ADDRESS, page_address, parse_window


def test_a_kept_state_is_found_by_its_token_in_any_query_position():
    token = keep_state('{"demo_state": 2, "x": 1}')
    assert len(token) == 16 and int(token, 16) >= 0
    assert keep_state('{"demo_state": 2, "x": 1}') == token  # the same state: the same token
    for search in (f"?demo={token}", f"?token=abc&demo={token}", f"?demo={token}&token=abc"):
        assert state_of(search) == '{"demo_state": 2, "x": 1}'


@pytest.mark.parametrize("search", ["", "?", "?demo=", "?demo=0123456789abcdeg", "?demo=0123456789abcdef0",
                                    "?xdemo=0123456789abcdef", "?demo=ffffffffffffffff"])
def test_an_address_naming_no_kept_state_opens_nothing(search):
    assert state_of(search) is None


def test_the_server_keeps_the_latest_states_only():
    first = keep_state("first state")
    for i in range(MAX_STATES):
        keep_state(f"state {i}")
    assert state_of(f"?demo={first}") is None
    assert state_of(f"?demo={keep_state(f'state {MAX_STATES - 1}')}") == f"state {MAX_STATES - 1}"


def test_the_address_script_sets_the_token_and_keeps_the_rest_of_the_query():
    js = address_js("0123456789abcdef")
    assert "q.set('demo', \"0123456789abcdef\")" in js and "history.replaceState" in js
    assert "new URLSearchParams(location.search)" in js and "location.hash" in js


@pytest.mark.parametrize(("text", "size", "address"), [
    ("1280x720", (1280.0, 720.0), ""),
    ("1280x720 ?demo=0123456789abcdef", (1280.0, 720.0), "?demo=0123456789abcdef"),
    ("1920x1080 ?token=a%20b&demo=1", (1920.0, 1080.0), "?token=a%20b&demo=1"),
])
def test_the_window_report_carries_the_address_the_page_opened_with(text, size, address):
    assert parse_window(text) == size and page_address(text) == address


@pytest.mark.parametrize("text", ["1280x720 demo=1", "1280x720 ?a b", "1280x720 ?" + "a" * (MAX_ADDRESS + 1), "junk"])
def test_a_report_with_anything_else_after_the_size_is_not_read(text):
    assert parse_window(text) is None and page_address(text) == ""


class _Files:
    def __init__(self, state_text):
        self.text, self.opened = state_text, []

    def state(self):
        return self.text

    def open(self, state):
        self.opened.append(state)


class _Client:
    def __init__(self):
        self.gui, self.notes = object(), []

    def add_notification(self, title, body, **_):
        self.notes.append((title, body))


def test_the_link_is_read_once_and_written_only_after_it(monkeypatch):
    scripts = []
    monkeypatch.setattr(demo_link, "run_script", lambda gui, js: scripts.append(js))
    monkeypatch.setattr(demo_link, "dumps_state", lambda state: json.dumps({"s": state}))
    monkeypatch.setattr(demo_link, "loads_state", lambda text, origin: ("loaded", text))
    files, client = _Files("case A"), _Client()
    link = DemoLink(client, files)
    link.remember()  # the address the page opened with is not read yet: it must not be overwritten
    assert scripts == []
    token = keep_state(json.dumps({"s": "case B"}))
    link.opened(f"?demo={token}")
    assert files.opened == [("loaded", json.dumps({"s": "case B"}))]
    link.opened(f"?demo={token}")  # a later window report (a resize) opens nothing again
    assert len(files.opened) == 1
    link.remember()
    link.remember()  # the same state: the address is not written again
    assert len(scripts) == 1 and keep_state(json.dumps({"s": "case A"})) in scripts[0]


def test_a_kept_state_that_does_not_load_is_refused_in_one_line(monkeypatch):
    def refuse(text, origin):
        raise ValueError(f"{origin}: preset: missing")

    monkeypatch.setattr(demo_link, "loads_state", refuse)
    files, client = _Files("x"), _Client()
    DemoLink(client, files).opened(f"?demo={keep_state('not a state')}")
    assert files.opened == []
    assert client.notes == [("Demo link refused — nothing changed", "demo link: preset: missing")]
