"""Speed figures of the web UI, measured in Debian's Chromium (prints; no assertions).

* page load → usable: navigation until the Simulate button and the phase plane are drawn;
* Simulate click → both trajectories drawn: the paper preset at f_s = 20 kHz, T_m alternated so
  that every click gives a new ω_p; until the page's phase plane holds both new trajectories;
* replay frame rate actually drawn by the browser (phase plane, server-pushed);
* server memory (RSS) idle and with 5 clients connected.

The server runs as a separate ``python -m app serve`` process (as the README starts it).

Usage: ``.venv/bin/python scripts/ui_bench.py [--runs 10]``
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from playwright.sync_api import sync_playwright

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.browser.conftest import CHROMIUM, LAUNCH_ARGS, VIEWPORT, free_port  # noqa: E402

PHASE_READY = ("(w) => [...document.querySelectorAll('.js-plotly-plot')].some(e => e.layout && e.layout.meta"
               " && e.layout.meta.id === 'phase_plane' && (w === null || Math.abs(e.layout.meta.omega_p - w)"
               " < 1e-6 * w) && e.data.some(t => t.name === 'Conventional trajectory'))")
COUNT_FRAMES = """() => new Promise(resolve => {
  const el = [...document.querySelectorAll('.js-plotly-plot')].find(e => e.layout.meta.id === 'phase_plane');
  let n = 0; const on = () => { n += 1; };
  el.on('plotly_afterplot', on);
  setTimeout(() => { el.removeListener('plotly_afterplot', on); resolve(n); }, 2000);
})"""


def rss_mb(pid: int) -> float:
    """Resident memory of a process [MB]."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def start_server(port: int) -> subprocess.Popen:
    env = dict(os.environ, NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))
    proc = subprocess.Popen([sys.executable, "-m", "app", "serve", "--port", str(port)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert proc.stdout is not None
    for line in proc.stdout:
        if "http://" in line and "commissioning" in line:
            return proc
    raise RuntimeError("server did not start")


def page_load(browser, url: str) -> tuple[float, object, object]:
    ctx = browser.new_context(viewport=VIEWPORT)
    page = ctx.new_page()
    page.set_default_timeout(60_000)
    t0 = time.perf_counter()
    page.goto(url)
    page.get_by_role("button", name="Simulate").wait_for()
    page.wait_for_function(PHASE_READY, arg=None, polling="raf")
    return time.perf_counter() - t0, ctx, page


def simulate_latency(page, runs: int, gap_s: float) -> list[float]:
    from app.presets import PAPER_PRESET, load_preset
    from control.derivations import derive

    params = load_preset(PAPER_PRESET)
    out = []
    for i in range(runs):
        T_m = 1.0 + 0.05 * ((i % 2) + 1)
        p = dataclasses.replace(params, manoeuvre=dataclasses.replace(params.manoeuvre, T_m=T_m))
        omega_p = derive(p).profile.omega_p
        field = page.get_by_label("T_m manoeuvre time [s]", exact=True)
        field.fill(str(T_m))
        field.press("Tab")
        page.wait_for_timeout(150)
        t0 = time.perf_counter()
        page.get_by_role("button", name="Simulate").click()
        page.wait_for_function(PHASE_READY, arg=omega_p, polling="raf")
        out.append(time.perf_counter() - t0)
        page.wait_for_timeout(1e3 * gap_s)
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--gap", type=float, default=0.3,
                    help="wait between clicks [s] (< 6 s: the next click interrupts the replay)")
    args = ap.parse_args()
    port = free_port()
    server = start_server(port)
    url = f"http://127.0.0.1:{port}"
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS)
            print(f"server RSS idle, no client:           {rss_mb(server.pid):7.1f} MB")
            loads, pages = [], []
            for _ in range(5):
                dt, ctx, page = page_load(browser, url)
                loads.append(dt)
                pages.append((ctx, page))
            print(f"page load → usable (5 clients):       first {loads[0]:.2f} s, "
                  f"median {statistics.median(loads):.2f} s, max {max(loads):.2f} s")
            time.sleep(1.0)
            print(f"server RSS with 5 clients connected:  {rss_mb(server.pid):7.1f} MB")
            for ctx, _ in pages[1:]:
                ctx.close()
            page = pages[0][1]
            lat = simulate_latency(page, args.runs, args.gap)
            print(f"Simulate click → both trajectories drawn (paper preset, 20 kHz, {args.runs} runs, "
                  f"{args.gap:g} s apart): "
                  f"median {1e3 * statistics.median(lat):.0f} ms, min {1e3 * min(lat):.0f} ms, "
                  f"max {1e3 * max(lat):.0f} ms")
            page.get_by_role("button", name="Replay", exact=True).click()
            frames = page.evaluate(COUNT_FRAMES)
            print(f"replay: phase-plane redraws in the browser: {frames / 2.0:.1f} per second "
                  "(server pushes 20/s)")
            browser.close()
    finally:
        server.terminate()
        server.wait(timeout=10)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
