"""The page against hostile clients (no browser): a raw websocket client, foreign origins and hosts,
the access token, dropdown values never offered, markup in user text, cancel.
"""

from __future__ import annotations

import asyncio
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

import msgspec
import pytest
import websockets

from pmsm_commissioning.app.figures.fdsmc_comparison import time_plots_spec
from pmsm_commissioning.app.figures.fdsmc_energy import energy_spec
from pmsm_commissioning.app.figures.plain import figure_json
from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, PRESET_DIR, load_preset
from pmsm_commissioning.app.ui.choices import checked_choice
from pmsm_commissioning.app.ui.page import create_server
from pmsm_commissioning.app.ui.text import md_text
from pmsm_commissioning.app.ui.web_guard import COOKIE, REFUSED_UPDATES, Guard
from pmsm_commissioning.app.ui.worker import Cancelled, Worker
from pmsm_commissioning.control.common.checks import ParameterError
from tests.net import free_port, run_coroutine
from tests.page_client import CAMERA, PROTOCOL, decode_frame, raw_session, upload_start, wait_until


def _ws_status(hostport: str, origin: str | None, headers: dict[str, str] | None = None,
               path: str = "/") -> str:
    async def go() -> str:
        try:
            async with websockets.connect(f"ws://{hostport}{path}", origin=origin, subprotocols=[PROTOCOL],
                                          additional_headers=headers or {}):
                return "open"
        except websockets.exceptions.InvalidStatus as exc:
            return str(exc.response.status_code)

    return run_coroutine(go)


def _http_status(url: str, headers: dict[str, str] | None = None) -> tuple[int, str]:
    try:
        with urllib.request.urlopen(urllib.request.Request(url, headers=headers or {})) as r:
            return r.status, r.headers.get("Set-Cookie", "")
    except urllib.error.HTTPError as exc:
        return exc.code, ""


def test_foreign_origin_and_missing_origin_refused(served):
    hostport, _, config = served
    assert _ws_status(hostport, "http://evil.example") == "403"
    assert _ws_status(hostport, "http://localhost:1") == "403"  # another port is another origin
    assert _ws_status(hostport, None) == "403"
    assert any("evil.example" in r for r in config.guard.refused)
    assert _ws_status(hostport, f"http://{hostport}") == "open"


def test_dns_rebinding_host_refused(served):
    hostport, _, _ = served
    assert _http_status(f"http://{hostport}/")[0] == 200
    assert _http_status(f"http://{hostport}/", {"Host": "evil.example:80"})[0] == 403


def test_allow_list_admits_a_configured_origin():
    guard = Guard.for_host("127.0.0.1", ["https://hmi.plant.local"])
    server, _ = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, port=free_port(), scene_3d=False,
                              guard=guard)
    try:
        hostport = f"127.0.0.1:{server.get_port()}"
        assert _ws_status(hostport, "https://hmi.plant.local") == "open"
        assert _ws_status(hostport, "https://other.plant.local") == "403"
    finally:
        server.stop()


def test_token_required_when_not_on_loopback():
    guard = Guard.for_host("0.0.0.0", token="s3cret-token")
    server, _ = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, host="127.0.0.1", port=free_port(),
                              scene_3d=False, guard=guard)
    try:
        hostport = f"127.0.0.1:{server.get_port()}"
        assert _http_status(f"http://{hostport}/")[0] == 403
        assert _http_status(f"http://{hostport}/?token=wrong")[0] == 403
        status, cookie = _http_status(f"http://{hostport}/?token=s3cret-token")
        assert status == 200 and f"{COOKIE}=s3cret-token" in cookie and "HttpOnly" in cookie
        origin = f"http://{hostport}"
        assert _ws_status(hostport, origin) == "403"
        assert _ws_status(hostport, origin, {"Cookie": f"{COOKIE}=s3cret-token"}) == "open"
        assert _ws_status(hostport, origin, path="/?token=s3cret-token") == "open"
        assert _ws_status(hostport, "http://evil.example", {"Cookie": f"{COOKIE}=s3cret-token"}) == "403"
    finally:
        server.stop()



def _raw_status(hostport: str, path: bytes, host: bytes | None = None) -> int:
    """Status code of a GET written byte by byte (any bytes in the path and Host header)."""
    import socket

    h, port = hostport.rsplit(":", 1)
    with socket.create_connection((h, int(port)), timeout=10) as s:
        s.sendall(b"GET " + path + b" HTTP/1.1\r\nHost: " + (host or hostport.encode()) + b"\r\n\r\n")
        return int(s.recv(64).split(b" ", 2)[1])


def test_token_mode_checks_host_one_token_parameter_and_any_token_text_is_403():
    guard = Guard.for_host("0.0.0.0", token="s3cret-token")
    server, _ = create_server(load_preset(DEFAULT_PRESET), DEFAULT_PRESET, host="127.0.0.1", port=free_port(),
                              scene_3d=False, guard=guard)
    try:
        hostport = f"127.0.0.1:{server.get_port()}"
        ok = f"{COOKIE}=s3cret-token"
        assert _http_status(f"http://{hostport}/", {"Cookie": ok})[0] == 200
        # DNS rebinding with a leaked cookie: a foreign host name is refused even with the token
        assert _http_status(f"http://{hostport}/", {"Cookie": ok, "Host": "evil.example"})[0] == 403
        assert _ws_status(hostport, "http://evil.example", {"Cookie": ok, "Host": "evil.example"}) == "403"
        assert _http_status(f"http://{hostport}/", {"Cookie": ok, "Host": "192.0.2.7:8080"})[0] == 200  # LAN IP
        # one token parameter only, in either order
        assert _http_status(f"http://{hostport}/?token=s3cret-token&token=x")[0] == 403
        assert _http_status(f"http://{hostport}/?token=x&token=s3cret-token")[0] == 403
        for token in (b"%FF%FE", b"\xc3\xa9t\xc3\xa9", b"%00", b"%ED%A0%80", b"a" * 5000, b"[", b"%25"):
            assert _raw_status(hostport, b"/?token=" + token) == 403, token
        for host in (b"[", b"\xff\xfe", b"a:b:c", b"[::1", b"x" * 3000):
            assert _raw_status(hostport, b"/?token=s3cret-token", host) in (400, 403), host
        assert all(len(r) <= 300 for r in guard.refused)
    finally:
        server.stop()


def _send_update(hostport: str, config: object, handle_of: str, value: str, wait_error: bool = True) -> object:
    """Connect as a hand-written client, set a GUI value by uuid (``handle_of`` a dotted attribute path of
    the session), return the session.
    """
    done = threading.Event()
    session_box: list[object] = []

    async def go() -> None:
        async with raw_session(hostport, config) as (ws, session):
            session_box.append(session)
            handle = session
            for attr in handle_of.split("."):
                handle = getattr(handle, attr)
            msg = {"type": "GuiUpdateMessage", "uuid": handle._impl.uuid, "updates": {"value": value}}
            await ws.send(msgspec.msgpack.encode(msg))
            if wait_error:
                await wait_until(lambda: session.error is not None, 600)
            else:  # let the server apply the update before the socket closes
                await wait_until(lambda: handle.value == value)
            done.set()

    run_coroutine(go)
    assert done.is_set()
    return session_box[0]


HOSTILE_UPDATES = [("results.cycles", {"value": "abc"}), ("results.cycles", {"value": float("nan")}),
                   ("results.cycles", {"value": True}), ("results.cycles", {"value": [1, 2]}),
                   ("inputs.alpha_rule", {"value": 5}), ("results.cycles", {"nonexistent": 1}),
                   ("results.cycles", {"__class__": 1}), ("results.cycles", ["value", 1])]


def test_widget_values_are_type_checked_before_viser_casts_them(served):
    hostport, _, config = served
    before = len(REFUSED_UPDATES)
    box: list[object] = []

    async def go() -> None:
        async with raw_session(hostport, config) as (ws, session):
            box.append(session)
            for path, updates in [*HOSTILE_UPDATES, ("results.cycles", {"value": 601.0})]:  # last: a valid one
                handle = session
                for attr in path.split("."):
                    handle = getattr(handle, attr)
                await ws.send(msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": handle._impl.uuid,
                                                      "updates": updates}))
            await wait_until(lambda: session.results.cycles.value == 601.0)  # handled in order: the valid one last

    run_coroutine(go)
    session = box[0]
    assert session.results.cycles.value == 601.0 and session.inputs.alpha_rule.value != 5
    refused = list(REFUSED_UPDATES)[before:]
    assert len(refused) == len(HOSTILE_UPDATES), refused
    assert all(len(r) <= 300 for r in refused) and any("allowed a finite number" in r for r in refused)


def test_uploads_are_refused_by_declared_size_and_overrun_while_streaming(served):
    hostport, _, config = served
    before = len(REFUSED_UPDATES)
    box: list[object] = []

    async def go() -> None:
        async with raw_session(hostport, config) as (ws, session):
            log_uuid, preset_uuid = session.log_panel.upload._impl.uuid, session.files.upload._impl.uuid
            msgs = [upload_start(log_uuid, "huge.csv", 300 * 2**20, 300),  # over 50 MB: refused at once
                    upload_start(preset_uuid, "big.yaml", 2 * 2**20, 2),  # over 512 KiB for a preset
                    upload_start(log_uuid, "a.csv", 40 * 2**20, 40),  # accepted, held open
                    upload_start(log_uuid, "b.csv", 40 * 2**20, 40),  # 80 MB unfinished: refused
                    upload_start(log_uuid, "small.csv", 10, 1),
                    {"type": "FileTransferPart", "source_component_uuid": log_uuid, "transfer_uuid": "small.csv",
                     "part_index": 0, "content": b"x" * 1000}]  # overruns its 10 bytes: ended
            for m in msgs:
                await ws.send(msgspec.msgpack.encode(m))
            await wait_until(lambda: len(REFUSED_UPDATES) - before >= 4)
            box.extend([session, dict(session.client.gui._current_file_upload_states)])

    run_coroutine(go)
    refused = list(REFUSED_UPDATES)[before:]
    assert len(refused) == 4, refused
    assert "huge.csv" in refused[0] and "allowed ≤ 50 MB" in refused[0]
    assert "big.yaml" in refused[1] and "allowed ≤ 0.5 MB" in refused[1]
    assert "b.csv" in refused[2] and "unfinished uploads" in refused[2]
    assert "small.csv" in refused[3] and "overrun" in refused[3]
    assert set(box[1]) == {"a.csv"}  # only the accepted transfer holds state (no parts yet)

def test_hostile_client_cannot_load_a_file_through_the_preset_dropdown(served, tmp_path):
    hostport, _, config = served
    target = tmp_path / "x.yaml"
    target.write_text((PRESET_DIR / "paper_12kw_pmsm.yaml").read_text().replace(
        "name: paper_12kw_pmsm", "name: HACKED"), encoding="utf-8")
    rel = Path("..") / Path(*([".."] * len(PRESET_DIR.parts))) / str(target.with_suffix(""))[1:]
    session = _send_update(hostport, config, "preset", str(rel))
    assert "is not one of the offered options" in session.error
    assert session.params.name != "HACKED" and session.origin != str(rel)


def test_input_dropdowns_refuse_values_never_offered(served):
    hostport, _, config = served
    session = _send_update(hostport, config, "inputs.alpha_rule", "fast", wait_error=False)
    params, runs = session.params, session.runs
    assert session.simulate() is False
    assert "α_max rule = 'fast' is not one of the offered options" in session.error
    assert session.params is params and session.runs == runs


def test_fdsmc_preset_dropdown_offers_position_presets_only(served):
    hostport, _, config = served
    session = _send_update(hostport, config, "preset", "bldc_smc_paper")
    assert "bldc_smc_paper" not in session.preset.options
    assert "paper_12kw_pmsm" in session.preset.options
    assert "is not one of the offered options" in session.error


def test_md_text_shows_markup_as_text():
    shown = md_text("# GAINS VERIFIED <b>USE K=50</b> `x` ![i](http://e/i.png) a|b\n## h")
    assert "<" not in shown and ">" not in shown and "&lt;b&gt;" in shown
    for ch in "#`![]()|":
        assert f"\\{ch}" in shown
    assert "\n" not in shown


def test_checked_choice():
    assert checked_choice("a", ("a", "b"), "Preset") == "a"
    with pytest.raises(ParameterError, match=r"Preset = '\.\./x' is not one of the offered options: allowed a, b"):
        checked_choice("../x", ("a", "b"), "Preset")
    with pytest.raises(ParameterError, match="allowed a, b"):
        checked_choice(3, ("a", "b"), "Preset")


def test_worker_cancel_stops_at_the_next_checkpoint():
    errors: list[Exception] = []
    worker = Worker(lambda _: None, errors.append)
    reached = []

    def job() -> None:
        for i in range(1000):
            worker.checkpoint()
            reached.append(i)
            time.sleep(0.005)

    future = worker.submit(job)
    while not reached:
        time.sleep(0.005)
    assert worker.cancel()
    future.result(timeout=10)
    assert len(reached) < 1000 and isinstance(errors[0], Cancelled)
    assert not worker.busy and not worker.cancel()
    worker.close()


#: The figures of the results tabs a page does not open on: sent when their tab is chosen, not with the page.
TAB_FIGURES = {"Time plots": ("time_plots",), "Energy": ("energy_time", "energy_bars"), "Stock drive": ("stock_route",)}


def test_page_open_sends_each_figure_once(served):
    """A new page gets each figure at most once, and only those of the tab it opens on (the Overview),
    the K demo and the other mode's: viser's creation message of a plot widget shares its properties
    with the handle, so a figure set before that message left used to travel twice. The figures of
    the *Time plots*, *Energy* and *Stock drive* tabs go out when the page reports the tab chosen:
    once, the start-up run's.
    """
    import json

    from pmsm_commissioning.app.ui.viser_adapter import widget_id

    hostport, _, config = served
    known = set(config.sessions)
    figures: list[tuple[str, str]] = []  # (widget uuid, figure id) per figure JSON received
    shown: dict[str, str] = {}  # figure id → the JSON last received
    chosen: dict[str, list[str]] = {}  # results tab → the figure ids received after it was chosen
    opened: list[str] = []  # the figure ids received with the page

    async def settle(ws, until: str | None = None) -> None:
        """Read the server's messages until 1 s without one (the page's session registered, ``until`` received)."""
        quiet = 0
        while quiet < 10 or not set(config.sessions) - known or (until is not None and until not in shown):
            try:
                frame = await asyncio.wait_for(ws.recv(), 0.1)
            except TimeoutError:
                quiet += 1
                continue
            quiet = 0
            for m in decode_frame(frame):
                fig = (m.get("props") or {}).get("_plotly_json_str") or (m.get("updates") or {}).get(
                    "_plotly_json_str")
                meta = json.loads(fig).get("layout", {}).get("meta") if fig else None
                if meta:
                    figures.append((m["uuid"], meta["id"]))
                    shown[meta["id"]] = fig

    async def choose(ws, tab: str) -> None:
        """Report ``tab`` shown, as the page's view probe does, and record the figures it brought."""
        session = config.sessions[next(iter(set(config.sessions) - known))]
        view = json.dumps({"tab": {"mode": "Position drive (FDSMC)", "results": tab}, "zoom": {}})
        n = len(figures)
        await ws.send(msgspec.msgpack.encode({"type": "GuiUpdateMessage", "updates": {"value": view},
                                              "uuid": widget_id(session.tab.demo_files.probe.field)}))
        await settle(ws)
        chosen.setdefault(tab, []).extend(fid for _, fid in figures[n:])

    async def go() -> None:
        async with websockets.connect(f"ws://{hostport}", origin=f"http://{hostport}", subprotocols=[PROTOCOL],
                                      max_size=None, close_timeout=0.2) as ws:
            await ws.send(msgspec.msgpack.encode(CAMERA))
            await settle(ws, "k_sweep")  # the K demo's figure: the page's worker computes it after the page
            opened.extend(fid for _, fid in figures)
            for tab in (*TAB_FIGURES, "Overview", *TAB_FIGURES):  # each tab twice: the second time, nothing
                await choose(ws, tab)

    run_coroutine(go)
    ids = [fid for _, fid in figures]
    assert len(figures) == len(set(figures)), sorted(f for f in ids if ids.count(f) > 1)
    waiting = [fid for tab_ids in TAB_FIGURES.values() for fid in tab_ids]
    assert {"phase_plane", "k_sweep", "bldc_emf"} <= set(opened) and not set(waiting) & set(opened), opened
    for tab, tab_ids in TAB_FIGURES.items():
        assert sorted(chosen[tab]) == sorted(tab_ids), (tab, chosen[tab])  # once each, nothing else
    assert chosen["Overview"] == []
    initial = config.initial()  # the tabs show the start-up run, the one the page opened with
    assert shown["time_plots"] == figure_json(time_plots_spec(initial))
    assert shown["energy_time"] == figure_json(energy_spec(initial))
