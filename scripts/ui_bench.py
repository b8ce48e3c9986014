"""Speed figures of the web UI, measured in Debian's Chromium (prints; no assertions).

* page open: time until the Simulate button and the phase plane are drawn, websocket bytes received;
* per Simulate (paper preset, f_s = 20 kHz, T_m alternated so that every click gives a new ω_p):
  server CPU (user + system of the server process, all threads, including the replay that
  follows), websocket bytes received by the page including a full replay, and the round trip
  click → both new trajectories drawn;
* the same round trip with 1, 5 and 10 pages clicking at once;
* page open broken down by message kind (plotly.js itself, each figure, the rest);
* the round trip split into click → overview message arrived → drawn;
* replay frame rate actually drawn by the browser (animation frames in which the phase-plane marker
  moved, at 0.1× and 0.01×) and the server traffic meanwhile;
* live tuning: re-simulated phase planes drawn per second while the K slider is moved
  (one key step every 50 ms, paper preset at 20 kHz); the K sweep's redraws per second while its
  own slider is dragged, its CPU and bytes (``scripts/ui_bench_sweep.py``);
  these two with one page open (the concurrency rounds' other pages are closed first: nine idle
  pages share the same two cores, which is the concurrency figure's business, not these);
* server memory (RSS) idle and with the pages connected.

Bytes per Simulate by message kind (which figure takes what): ``scripts/ui_bench_bytes.py``.

**What a user gets** comes first: ``--runs`` rounds, each on a NEW server process with ONE new
page (fresh browser context, nothing else open): page open → usable, the first Simulate → drawn,
and K-slider redraws per second, each printed per round with the load average, then their
medians. The later figures (many pages, warm server) are the server's behaviour under repetition:
there every cache is warm (derive's searches, the kernels, the preset files, Chromium's
compiled plotly.js), which is why they are better than what one user opening the page sees.

Every figure is the median of ``--runs`` rounds (≥ 3; 5 for the record) with its min and max; the machine's load
average is printed at the start and at the end (figures from a shared machine are pessimistic).
The whole script takes about 3–5 minutes. It is a measurement, never a test.

Websocket bytes are the decoded message payloads (msgpack) as the page receives them; the wire
carries them deflate-compressed. The server runs as a separate ``pmsm-commission serve`` process
(as the README starts it).

Usage: ``.venv/bin/python scripts/ui_bench.py [--runs 5] [--clients 1,5,10]``
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pmsm_commissioning.app.ui.k_slider import K_LABEL  # noqa: E402
from tests.browser.conftest import CHROMIUM, LAUNCH_ARGS, VIEWPORT, field  # noqa: E402
from tests.net import free_port  # noqa: E402

sys.path.insert(0, str(ROOT / "scripts"))
from ui_bench_sweep import sweep_cost, sweep_redraws  # noqa: E402

PRESET = "paper_12kw_pmsm"
PHASE_READY = ("(w) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
               " && e.layout.meta.id === 'phase_plane' && (w === null || Math.abs(e.layout.meta.omega_p - w)"
               " < 1e-6 * w) && e.data.some(t => t.name === 'Conventional trajectory'))")
#: The same with the overview's replay controls drawn (after a Simulate the page first gets the
#: overview without them, which it draws in a third of the time, and the whole figure right after).
PHASE_FULL = PHASE_READY.replace("e.data.some(", "(e.layout.updatemenus || []).length > 0 && e.data.some(")
#: Installs (without waiting) ``window.__ready`` and ``window.__full``: promises of the Date.now() at which
#: the phase plane shows ω_p = w (:data:`PHASE_READY`, :data:`PHASE_FULL`; polled every frame), or NaN
#: after 60 s.
WATCH_READY = ("(w) => { const t0 = Date.now(); const watch = (ok) => new Promise(r => { const f = () => ok(w)"
               " ? r(Date.now()) : (Date.now() - t0 > 60000 ? r(NaN) : requestAnimationFrame(f)); f(); });"
               " window.__ready = watch(" + PHASE_READY + "); window.__full = watch(" + PHASE_FULL + "); }")
#: Resolves with the number of browser animation frames, within ``ms``, in which the drawn FDSMC marker
#: (its SVG transform) moved: key frames and Plotly's glides between them alike.
COUNT_FRAMES = """(ms) => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const pos = () => { const g = [...el.querySelectorAll('g.trace.scatter')]
      .find(g => g.__data__[0].trace.name === 'FDSMC now');
    const p = g && g.querySelector('path.point'); return p && p.getAttribute('transform'); };
  let n = 0, last = pos(); const t0 = performance.now();
  const f = () => { const p = pos(); if (p !== last) { n += 1; last = p; }
                    if (performance.now() - t0 < ms) requestAnimationFrame(f); else resolve(n); };
  requestAnimationFrame(f);
})"""
PLAY_IN_PLOT = """(label) => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  const menu = (el.layout.updatemenus || [])[0];
  if (!menu) return false;
  const b = menu.buttons.find(x => x.label === label);
  window.Plotly.animate(el, ...b.args);
  return true;
}"""


class WsCounter:
    """Bytes and messages a page receives over its websockets, with their arrival times [ms since epoch]."""

    def __init__(self, page, keep: bool = False) -> None:
        self.bytes = 0
        self.messages = 0
        self.arrivals: list[tuple[float, int]] = []
        self.payloads: list[bytes] = [] if keep else None  # type: ignore[assignment]
        page.on("websocket", lambda ws: ws.on("framereceived", self._add))

    def _add(self, payload) -> None:
        self.bytes += len(payload)
        self.messages += 1
        self.arrivals.append((time.time() * 1e3, len(payload)))
        if self.payloads is not None and isinstance(payload, bytes):
            self.payloads.append(payload)


def breakdown(payloads: list[bytes], top: int = 8) -> str:
    """Per kind of viser message: bytes as sent (zstd) and decoded, biggest first (one line each)."""
    import msgspec
    import zstandard

    z, c = zstandard.ZstdDecompressor(), zstandard.ZstdCompressor(level=1)
    kinds: dict[str, list[float]] = {}
    for f in payloads:
        n_in, n_c = int.from_bytes(f[:8], "little"), int.from_bytes(f[8:16], "little")
        for m in msgspec.msgpack.decode(z.decompress(f[16:16 + n_c], max_output_size=n_in))["messages"]:
            raw = msgspec.msgpack.encode(m)
            fig = (m.get("props") or {}).get("_plotly_json_str") or (m.get("updates") or {}).get("_plotly_json_str")
            name = m.get("type", "?")
            if fig:
                meta = json.loads(fig).get("layout", {}).get("meta") or {}
                name = f"figure {meta.get('id', '(empty)')}"
            k = kinds.setdefault(name, [0, 0.0, 0.0])
            k[0] += 1
            k[1] += len(c.compress(raw))
            k[2] += len(raw)
    rows = sorted(kinds.items(), key=lambda kv: -kv[1][1])
    return "\n".join(f"    {v[1] / 1e3:8.1f} kB sent ({v[2] / 1e3:8.1f} kB decoded) ×{v[0]:<3d} {k}"
                     for k, v in rows[:top])


def cpu_s(pid: int) -> float:
    """User + system CPU time of a process (all threads) [s]."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rss_mb(pid: int) -> float:
    """Resident memory of a process [MB]."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def start_server(port: int, scene_3d: bool) -> subprocess.Popen:
    env = dict(os.environ, NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))
    extra = [] if scene_3d else ["--no-3d"]
    # UI_BENCH_SERVER: what python runs instead of "-m pmsm_commissioning.app" (e.g. a script timing the server's calls)
    server = os.environ.get("UI_BENCH_SERVER", "-m pmsm_commissioning.app").split()
    proc = subprocess.Popen([sys.executable, *server, "serve", "--port", str(port), "--preset", PRESET, *extra],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert proc.stdout is not None
    for line in proc.stdout:
        if "http://" in line and "commissioning" in line:
            return proc
    raise RuntimeError("server did not start")


def open_page(browser, url: str, keep: bool = False) -> tuple[float, int, object, object, WsCounter]:
    ctx = browser.new_context(viewport=VIEWPORT)
    page = ctx.new_page()
    page.set_default_timeout(120_000)
    ws = WsCounter(page, keep)
    t0 = time.perf_counter()
    page.goto(url)
    page.get_by_role("button", name="Simulate").wait_for()
    page.wait_for_function(PHASE_READY, arg=None, polling="raf")
    return time.perf_counter() - t0, ws.bytes, ctx, page, ws


def omega_p_of(T_m: float) -> float:
    from pmsm_commissioning.app.io.presets import load_preset
    from pmsm_commissioning.control.fdsmc.derivations import derive

    params = load_preset(PRESET)
    return derive(dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=T_m))).profile.omega_p


def type_T_m(page, T_m: float) -> None:
    box = field(page, "T_m manoeuvre time [s]")
    box.fill(f"{T_m:g}")
    box.press("Tab")
    page.wait_for_timeout(200)


_CLICKS = itertools.count()


def click_all(pages: list, k: int) -> list[float]:
    """Every page types a new T_m, then all click Simulate at once; per-page round trip [s].

    Timed from the button's ``pointerdown`` in the page (what the user does) to the frame that shows
    both new trajectories; Playwright's own work before the click (actionability checks, ≈ 50–100 ms
    on this machine) is left out, and its median is kept in :data:`CLICK_OVERHEAD`.
    """
    T_m = 1.0 + 0.05 * (next(_CLICKS) % 2 + 1)  # alternates over all calls: every click changes ω_p
    w = omega_p_of(T_m)
    for page in pages:
        type_T_m(page, T_m)
    starts = []
    for page in pages:
        page.evaluate(WATCH_READY, w)  # watcher installed before the click
        page.evaluate(WATCH_DOWN)
    for page in pages:
        starts.append(time.time() * 1e3)
        page.get_by_role("button", name="Simulate").click(no_wait_after=True)
    ends = [page.evaluate("() => window.__ready") for page in pages]
    downs = [page.evaluate("() => window.__down") for page in pages]
    fulls = [page.evaluate("() => window.__full") for page in pages]
    CLICK_OVERHEAD.extend(d - s for d, s in zip(downs, starts, strict=True))
    WITH_REPLAY.extend((f - d) / 1e3 for f, d in zip(fulls, downs, strict=True) if f == f)
    LAST_CLICK[:] = [downs[0], ends[0]]
    return [(t1 - t0) / 1e3 for t1, t0 in zip(ends, downs, strict=True) if t1 == t1]  # NaN: not drawn in 60 s


#: Playwright's time from the call to the page's pointerdown, per click [ms].
CLICK_OVERHEAD: list[float] = []
#: Per click: pointerdown → the overview drawn with its replay controls [s].
WITH_REPLAY: list[float] = []
#: Per user round: K-slider redraws per second while dragged with the mouse [1/s].
MOUSE: list[float] = []
SWEEP: list[float] = []  # the K sweep figure's redraws per second (its own slider, frames in the browser)
#: Records the Date.now() of the next pointerdown in the page as ``window.__down``.
WATCH_DOWN = ("() => { window.__down = NaN; document.addEventListener('pointerdown', "
              "() => { window.__down = Date.now(); }, {capture: true, once: true}); }")


#: [click, drawn] of the first page's last click [ms since epoch].
LAST_CLICK: list[float] = []


def split(ws: WsCounter) -> tuple[float, float] | None:
    """(click → the overview's message arrived, arrived → drawn) [s] of the last click of ``ws``'s page.

    The overview is the first message of ≥ 20 kB after the click (it goes out first, then the time plots).
    """
    t0, t1 = LAST_CLICK
    within = [t for t, n in ws.arrivals if t0 <= t <= t1 and n >= 20_000]
    if not within or t1 != t1:
        return None
    t_arrived = within[0]
    return (t_arrived - t0) / 1e3, (t1 - t_arrived) / 1e3


def med(xs: list[float], scale: float = 1e3, fmt: str = ".0f") -> str:
    """'median m (min a, max b)' of ``xs`` scaled by ``scale``."""
    if not xs:
        return "none measured"
    m, lo, hi = (scale * statistics.median(xs), scale * min(xs), scale * max(xs))
    return f"median {m:{fmt}} (min {lo:{fmt}}, max {hi:{fmt}})"


def load_average() -> str:
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(*os.getloadavg(), os.cpu_count())


BAND_NAME = """() => [...document.querySelectorAll('.js-plotly-plot')]
  .find(e => e.layout.meta && e.layout.meta.id === 'phase_plane').data[0].name"""
#: Moves the K slider by one key step every ``ms`` [ms], ``n`` times (key events dispatched in the page,
#: so the pace is the page's, not Playwright's), and counts the phase-plane redraws with a new boundary
#: layer (a new K) meanwhile; resolves with [redraws, elapsed ms].
DRAG_K = """([ms, n, key]) => new Promise(resolve => {
  const label = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === '""" + K_LABEL + """');
  let box = label; while (box && !box.querySelector('[role="slider"]')) box = box.parentElement;
  const thumb = box.querySelector('[role="slider"]');
  const band = """ + BAND_NAME + """;
  let last = band(), redraws = 0, k = 0; const t0 = performance.now();
  const id = setInterval(() => { if (k < n) { thumb.focus();
    thumb.dispatchEvent(new KeyboardEvent('keydown', {key, code: key, bubbles: true})); k += 1; } }, ms);
  const f = () => { const b = band(); if (b !== last) { redraws += 1; last = b; }
    if (performance.now() - t0 < n * ms) requestAnimationFrame(f);
    else { clearInterval(id); resolve([redraws, performance.now() - t0]); } };
  f(); })"""


#: Drags the K slider with the mouse: a press on its thumb, then one move of ``px`` [px] per animation
#: frame (as a browser delivers a real drag's moves: at most one per frame, none while the page is
#: busy), for ``ms`` [ms]; counts the phase-plane redraws with a new boundary layer meanwhile;
#: resolves with [redraws, elapsed ms].
DRAG_K_MOUSE = """([ms, px]) => new Promise(resolve => {
  const label = [...document.querySelectorAll('label')].find(l => l.textContent.trim() === '""" + K_LABEL + """');
  let box = label; while (box && !box.querySelector('[role="slider"]')) box = box.parentElement;
  const thumb = box.querySelector('[role="slider"]'), r = thumb.getBoundingClientRect();
  let x = r.x + r.width / 2; const y = r.y + r.height / 2;
  const ev = (type, target) => target.dispatchEvent(new MouseEvent(type, {clientX: x, clientY: y, bubbles: true,
                                                                         buttons: type === 'mouseup' ? 0 : 1}));
  ev('mousedown', thumb);  // bubbles to the track, where the slider listens
  const band = """ + BAND_NAME + """;
  let last = band(), redraws = 0; const t0 = performance.now();
  const f = () => { const b = band(); if (b !== last) { redraws += 1; last = b; }
    if (performance.now() - t0 < ms) { x -= px; ev('mousemove', document); requestAnimationFrame(f); }
    else { ev('mouseup', document); resolve([redraws, performance.now() - t0]); } };
  requestAnimationFrame(f); })"""


def mouse_redraws(page, seconds: float) -> float:
    """Re-simulated phase planes drawn per second while the K slider is dragged with the mouse (1 px per frame)."""
    n, ms = page.evaluate(DRAG_K_MOUSE, [1e3 * seconds, 1.0])
    page.wait_for_timeout(1500)
    return n / (ms / 1e3)


def slider_redraws(page, seconds: float, direction: str) -> float:
    """Re-simulated phase planes drawn per second while the K slider moves one step every 50 ms.

    Counted over the drag itself (the redraws after the last move are not counted, nor is the time).
    """
    n, ms = page.evaluate(DRAG_K, [50, int(seconds / 0.05), direction])
    page.wait_for_timeout(1500)  # the drag's last run and the rest of the results, before the next round
    return n / (ms / 1e3)


def per_simulate(page, ws: WsCounter, pid: int, runs: int, replay_wait: float) -> None:
    """Server CPU, websocket bytes (incl. the replay that follows) and round trip of one page."""
    cpus, sizes, msgs, lat, arrive, draw = [], [], [], [], [], []
    for k in range(runs):
        b0, m0, c0 = ws.bytes, ws.messages, cpu_s(pid)
        lat += click_all([page], k)
        parts = split(ws)
        if parts is not None:
            arrive.append(parts[0])
            draw.append(parts[1])
        page.wait_for_timeout(1e3 * replay_wait)  # the full replay, if the server pushes it
        cpus.append(cpu_s(pid) - c0)
        sizes.append(ws.bytes - b0)
        msgs.append(ws.messages - m0)
    print(f"per Simulate, 1 page ({runs} runs, incl. {replay_wait:g} s of replay): server CPU "
          f"{med(cpus)} ms [target ≤ 60]; websocket {med(sizes, 1e-3)} kB in "
          f"{statistics.median(msgs):.0f} messages [target ≤ 500 kB]; round trip {med(lat)} ms from the "
          f"page's pointerdown (Playwright's click before it: median {statistics.median(CLICK_OVERHEAD):.0f} ms)")
    print(f"  round trip split: click → overview message arrived {med(arrive)} ms (server: inputs, simulate, "
          f"figure JSON, send); arrived → drawn {med(draw)} ms (browser: decode, Plotly.react)")


def replay_rate(page, ws: WsCounter, runs: int) -> None:
    """Phase-plane frames/s drawn by the browser during the in-plot replay, server bytes meanwhile."""
    for label in ("▶ 0.1×", "▶ 0.01×"):
        rates, traffic = [], []
        for _ in range(runs):
            b0 = ws.bytes
            if not page.evaluate(PLAY_IN_PLOT, label):
                print("replay: no in-plot replay buttons found")
                return
            page.wait_for_timeout(800)  # past the first key frame (a jump to t = 0)
            rates.append(page.evaluate(COUNT_FRAMES, 2000) / 2.0)
            traffic.append((ws.bytes - b0) / 2.8)
        print(f"replay {label[2:]} (client-side animation, {runs} runs): {med(rates, 1, '.1f')} frames/s with the "
              f"marker moved; {med(traffic, 1e-3, '.2f')} kB/s from the server   [target ≥ 30 frames/s, ≤ 1 kB/frame]")
    frame_rate = page.evaluate("""() => new Promise(r => { let n = 0; const t0 = performance.now();
      const f = () => { n += 1; if (performance.now() - t0 < 2000) requestAnimationFrame(f); else r(n / 2); };
      requestAnimationFrame(f); })""")
    print(f"  the page's own animation frame rate meanwhile: {frame_rate:.1f} frames/s (the ceiling of the above)")


def open_pages(browser, url: str, n: int, timed: int, pid: int) -> list:
    """``timed`` pages opened one after the other (timed), then the rest of ``n`` all at once."""
    opened = [open_page(browser, url, keep=k == 0) for k in range(min(n, timed))]
    print(f"page open → usable ({len(opened)} pages, one after the other): {med([o[0] for o in opened], 1, '.2f')} s;"
          f" websocket bytes {med([o[1] for o in opened], 1e-6, '.2f')} MB   [target ≤ 1 MB]")
    first = opened[0][4]
    print("  page open, first page, by message kind:\n" + breakdown(first.payloads))
    first.payloads = None  # type: ignore[assignment]
    rest = []
    for _ in range(n - len(opened)):
        ctx = browser.new_context(viewport=VIEWPORT)
        page = ctx.new_page()
        page.set_default_timeout(120_000)
        ws = WsCounter(page)
        page.goto(url, wait_until="commit")
        rest.append((0.0, 0, ctx, page, ws))
    for o in rest:
        o[3].get_by_role("button", name="Simulate").wait_for()
        o[3].wait_for_function(PHASE_READY, arg=None, polling="raf")
    print(f"server RSS with {n} pages: {rss_mb(pid):.1f} MB")
    return opened + rest


def cold_round(browser, with_3d: bool) -> tuple[float, float, float, float]:
    """One user: a new server, one new page.

    Returns (page open → usable [s], first Simulate → drawn [s], second Simulate → drawn [s], K-slider redraws per s).
    """
    port = free_port()
    server = start_server(port, with_3d)
    try:
        opened, _, ctx, page, _ = open_page(browser, f"http://127.0.0.1:{port}")
        first = click_all([page], 0)
        page.wait_for_timeout(1000)
        second = click_all([page], 1)
        page.wait_for_timeout(1000)
        rate = slider_redraws(page, 2.0, "ArrowLeft")
        MOUSE.append(mouse_redraws(page, 2.0))
        SWEEP.append(sweep_redraws(page, 2.0))
        ctx.close()
    finally:
        server.terminate()
        server.wait(timeout=10)
    nan = float("nan")
    return opened, (first or [nan])[0], (second or [nan])[0], rate


def cold_rounds(browser, runs: int, with_3d: bool) -> None:
    """What a user gets: ``runs`` rounds of :func:`cold_round`, each printed with the load average, then medians."""
    warm = cold_round(browser, with_3d)  # fills numba's on-disk cache (keyed on the source path), as set-up does
    print(f"  untimed first round (numba's on-disk cache filled for this checkout): page open {warm[0]:.2f} s")
    rows = []
    for k in range(runs):
        row = cold_round(browser, with_3d)
        rows.append(row)
        print(f"  user {k + 1}: page open → usable {row[0]:.2f} s, first Simulate → drawn {1e3 * row[1]:.0f} ms, "
              f"second {1e3 * row[2]:.0f} ms, K slider {row[3]:.1f} redraws/s   ({load_average()})")
    cols = list(zip(*rows, strict=True))
    print(f"WHAT A USER GETS (new server, one new page, {runs} rounds): page open → usable "
          f"{med(list(cols[0]), 1, '.2f')} s [target ≤ 1.5]; first Simulate → drawn {med(list(cols[1]))} ms, "
          f"second {med(list(cols[2]))} ms [target ≤ 100]; K slider {med(list(cols[3]), 1, '.1f')} redraws/s "
          f"[target ≥ 20]")
    print(f"  K slider dragged with the mouse (a move per animation frame): {med(MOUSE, 1, '.1f')} redraws/s")
    print(f"  K sweep's own slider dragged with the mouse (frames in the browser): {med(SWEEP, 1, '.1f')} "
          f"redraws/s [target ≥ 25]; {sweep_cost()}")
    print(f"  Simulate → the overview drawn again with its replay controls: {med(WITH_REPLAY)} ms (all clicks); "
          f"the K slider's ceiling is 20 redraws/s: viser sends a slider's value at most every "
          f"50 ms (and the key drag moves it every 50 ms)")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5, help="rounds per figure (median; at least 3, 5 for the record)")
    ap.add_argument("--clients", default="1,5,10", help="numbers of pages clicking at once")
    ap.add_argument("--replay-wait", type=float, default=4.0, help="time allowed for a full replay [s]")
    ap.add_argument("--user-only", action="store_true", help="only the new-server, one-page rounds")
    ap.add_argument("--with-3d", action="store_true",
                    help="serve the 3D rotor view too (each headless page then renders WebGL in software on "
                         "the server's cores, which distorts the server figures on a small machine)")
    args = ap.parse_args()
    runs, counts, t_start = max(3, args.runs), [int(c) for c in args.clients.split(",")], time.perf_counter()
    print(f"start: {load_average()}; 3D view {'on' if args.with_3d else 'off (--no-3d)'}")
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
        cold_rounds(browser, runs, args.with_3d)
        browser.close()
    if args.user_only:
        print(f"end: {load_average()}; the benchmark took {time.perf_counter() - t_start:.0f} s")
        return 0
    port = free_port()
    server = start_server(port, args.with_3d)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
            print(f"server RSS idle, no client: {rss_mb(server.pid):.1f} MB")
            opened = open_pages(browser, f"http://127.0.0.1:{port}", max(counts), runs, server.pid)
            page, ws = opened[0][3], opened[0][4]
            page.wait_for_timeout(5000)  # the pages opened all at once finish drawing before anything is timed
            per_simulate(page, ws, server.pid, runs, args.replay_wait)
            for n in counts:
                pages = [o[3] for o in opened[:n]]
                rts = [t for k in range(runs) for t in (click_all(pages, k), pages[0].wait_for_timeout(500))[0]]
                print(f"Simulate → drawn, {n:2d} pages clicking at once ({runs} rounds): {med(rts)} ms"
                      f"   [target: 1 page ≤ 150, 10 pages median ≤ 600]")
            for o in opened[1:]:  # the replay and the slider are one page's figures: the others leave
                o[2].close()
            page.wait_for_timeout(2000)
            replay_rate(page, ws, runs)
            rates = [slider_redraws(page, 2.0, "ArrowLeft" if k % 2 else "ArrowRight") for k in range(runs)]
            print(f"live tuning, K slider moved (key events) every 50 ms for 2 s ({runs} rounds): redraws "
                  f"{med(rates, 1, '.1f')} per s   [target ≥ 10]")
            browser.close()
    finally:
        server.terminate()
        server.wait(timeout=10)
    print(f"end: {load_average()}; the benchmark took {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
