"""Websocket bytes per Simulate, by message kind (prints; no assertions; a measurement, never a test).

One ``pmsm-commission serve`` process (paper preset, no 3D view), one page in Debian's Chromium. First
the page open: bytes received until the page is usable, then 5 s later, and where they go by message
kind. After the page has settled, ``--runs`` Simulates on the Overview tab (T_m alternated, so each gives a new run),
each followed by ``--replay-wait`` seconds (the replay's and the K sweep's messages arrive then). Per
Simulate: the bytes as the page receives them (viser's zstd-compressed frames) and the messages, median
(min, max); then, for the last Simulate, where they go — per kind of viser message (each figure by its
``layout.meta.id``), bytes as sent and decoded (:func:`ui_bench.breakdown`). Then the tabs whose figures
wait until they are shown (:mod:`app.ui.tab_figures`) are chosen in turn, each with what it brought.
The load average is printed at start and end.

Usage: ``.venv/bin/python scripts/ui_bench_bytes.py [--runs 5] [--replay-wait 6]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from ui_bench import breakdown, click_all, load_average, med, open_page, start_server  # noqa: E402

from tests.browser.conftest import CHROMIUM, LAUNCH_ARGS, click_tab  # noqa: E402
from tests.net import free_port  # noqa: E402

#: The results tabs whose figures go out when the tab is chosen, not with each Simulate.
TABS_LATER = ("Time plots", "Energy", "Stock drive")


def tab_bytes(page, ws, tab: str, wait_s: float) -> None:
    """Choose the results tab ``tab`` and print the bytes and messages it brought within ``wait_s`` [s]."""
    ws.payloads.clear()
    b0, m0 = ws.bytes, ws.messages
    click_tab(page, tab)
    page.wait_for_timeout(1e3 * wait_s)
    print(f"  then the tab {tab!r} chosen: {(ws.bytes - b0) / 1e3:.1f} kB in {ws.messages - m0} messages")
    print(breakdown(ws.payloads, top=4))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5, help="Simulates measured (median)")
    ap.add_argument("--replay-wait", type=float, default=6.0, help="time allowed after each Simulate [s]")
    args = ap.parse_args()
    t_start = time.perf_counter()
    print(f"start: {load_average()}")
    port = free_port()
    server = start_server(port, scene_3d=False)
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
            _, opened_bytes, _, page, ws = open_page(browser, f"http://127.0.0.1:{port}", keep=True)
            print(f"page open → usable (Simulate button and phase plane drawn): {opened_bytes / 1e3:.0f} kB")
            page.wait_for_timeout(5000)  # the page's own K sweep and figures have arrived
            print(f"page open, 5 s later: {ws.bytes / 1e3:.0f} kB in {ws.messages} messages; by message kind:")
            print(breakdown(ws.payloads, top=30))
            sizes, msgs = [], []
            for k in range(args.runs):
                ws.payloads.clear()
                b0, m0 = ws.bytes, ws.messages
                click_all([page], k)
                page.wait_for_timeout(1e3 * args.replay_wait)
                sizes.append(ws.bytes - b0)
                msgs.append(ws.messages - m0)
            print(f"per Simulate, paper preset ({args.runs} runs, incl. {args.replay_wait:g} s after): "
                  f"{med(sizes, 1e-3, '.1f')} kB in {statistics.median(msgs):.0f} messages (median)")
            print("  the last Simulate by message kind:")
            print(breakdown(ws.payloads, top=30))
            for tab in TABS_LATER:
                tab_bytes(page, ws, tab, args.replay_wait / 3)
            browser.close()
    finally:
        server.terminate()
        server.wait(timeout=10)
    print(f"end: {load_average()}; {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
