"""Load test of the page server (loopback only, bounded): studies from many pages, then the pages leave.

Run: ``.venv/bin/python scripts/load_test.py [--pages 10] [--disconnect 5] [--samples 20000]
[--study robustness|multiaxis]`` (``multiaxis``: 16-axis moves, run in the server's threads).

Starts ``pmsm-commission serve`` on a free loopback port, warms it with one page and measures the
idle server. Then ``--pages`` pages (hand-written websocket clients, :mod:`tests.page_client`) each
start a robustness study of ``--samples`` samples (or a multi-axis move); an extra page opens while
they run and its first figure is timed; ``--disconnect`` pages leave, then all the rest. Prints the
study processes and the queue, the server's RSS with its children (idle / peak / after close), the
time until study processes and CPU are back to idle after the last disconnect, and the extra
page's first-figure time. Targets: processes and CPU idle within 5 s, RSS after close within 20 %
of idle, first figure ≤ 1 s. Linux only (reads /proc). Every wait is bounded by ``--limit`` seconds.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.net import free_port  # noqa: E402
from tests.page_client import PageClient  # noqa: E402

RUN = {"robustness": "Run robustness study", "multiaxis": "Run multi-axis move"}
#: The multi-axis study: 16 axes of the shipped real-motor presets.
AXES = "".join(f"- {{preset: {p}, name: A{k}}}\n" for k, p in enumerate(
    ["yaskawa_sgm7j_02a", "yaskawa_sgm7j_04a", "siemens_1ft7044_ak7", "odrive_d5065_belt"] * 4))
TICK_S = os.sysconf("SC_CLK_TCK")


def _descendants(pid: int) -> list[int]:
    """Process ids below ``pid`` (children, grandchildren …) from /proc."""
    parent: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parent[int(entry.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    out, frontier = [], [pid]
    while frontier:
        p = frontier.pop()
        kids = [c for c, pp in parent.items() if pp == p]
        out += kids
        frontier += kids
    return out


def _read(pid: int, name: str) -> str:
    try:
        return (Path("/proc") / str(pid) / name).read_bytes().decode(errors="replace")
    except OSError:
        return ""


def study_processes(pid: int) -> list[int]:
    """The server's study worker processes (spawned pool workers; not multiprocessing's resource tracker)."""
    return [p for p in _descendants(pid) if "spawn_main" in _read(p, "cmdline")]


def _rss_kib(pid: int) -> int:
    for line in _read(pid, "status").splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


def rss_mib(pid: int, tree: bool = True) -> float:
    """Resident memory of the server (and all its descendants when ``tree``) [MiB]."""
    return sum(_rss_kib(p) for p in [pid, *(_descendants(pid) if tree else ())]) / 1024.0


def cpu_s(pid: int) -> float:
    """CPU time of the server and its live descendants [s]."""
    total = 0
    for p in [pid, *_descendants(pid)]:
        fields = _read(p, "stat").rsplit(")", 1)[-1].split()
        if len(fields) > 12:
            total += int(fields[11]) + int(fields[12])
    return total / TICK_S


async def cpu_share(pid: int, window_s: float = 0.5) -> float:
    """CPU share of the server tree over ``window_s`` [cores]."""
    c0, t0 = cpu_s(pid), time.monotonic()
    await asyncio.sleep(window_s)
    return (cpu_s(pid) - c0) / (time.monotonic() - t0)


def start_server(port: int) -> subprocess.Popen:
    """Start ``pmsm-commission serve`` on ``port`` and wait for its URL line."""
    env = dict(os.environ, NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")))
    proc = subprocess.Popen([sys.executable, "-m", "pmsm_commissioning.app", "serve", "--port", str(port), "--no-3d"],
                            cwd=ROOT,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    for line in proc.stdout or ():  # viser's banner first, then the tool's URL line
        if line.startswith("PMSM commissioning tool: http://"):
            return proc
    proc.kill()
    raise SystemExit("the server did not start")


async def _until(condition, limit_s: float, poll_s: float = 0.1) -> float | None:
    """Seconds until ``condition()`` holds (None if not within ``limit_s``)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < limit_s:
        if condition():
            return time.monotonic() - t0
        await asyncio.sleep(poll_s)
    return None


async def _first_figure(hostport: str, limit_s: float) -> tuple[PageClient, float | None]:
    page = PageClient(hostport)
    await page.open()
    await _until(lambda: page.first_figure_s > 0, limit_s, 0.01)
    return page, page.first_figure_s or None


async def _idle(pid: int, hostport: str) -> tuple[float, float, float | None]:
    """Warm the server with one page, then return (idle RSS [MiB], idle CPU [cores], that page's first figure [s])."""
    page, first = await _first_figure(hostport, 60.0)
    await page.close()
    await asyncio.sleep(3.0)
    return rss_mib(pid), await cpu_share(pid, 1.0), first


async def run(args: argparse.Namespace, pid: int, hostport: str) -> None:
    """The load sequence (module docstring); prints one line per figure."""
    idle_rss, idle_cpu, warm_first = await _idle(pid, hostport)
    print(f"idle: RSS {idle_rss:.0f} MiB (server + children), CPU {100 * idle_cpu:.0f} %, "
          f"a lone page's first figure {warm_first or float('nan'):.2f} s")
    peak = [idle_rss]

    async def sample() -> None:
        while True:
            peak[0] = max(peak[0], rss_mib(pid))
            await asyncio.sleep(0.2)

    sampler = asyncio.ensure_future(sample())
    pages = [PageClient(hostport) for _ in range(args.pages)]
    for page in pages:
        await page.open()
        if args.study == "robustness":
            await page.set_value("Samples", args.samples)
        else:
            await page.set_value("Axes (YAML list)", AXES)
        await page.set_value(RUN[args.study], True)
    if args.study == "robustness":
        await _until(lambda: bool(study_processes(pid)), 60.0)
    await asyncio.sleep(3.0)
    queued = sum(page.says("queued") for page in pages)
    print(f"{args.pages} pages started studies: {len(study_processes(pid))} study processes, {queued} pages "
          f"show their place in the queue, CPU {100 * await cpu_share(pid):.0f} %")
    extra, first = await _first_figure(hostport, 30.0)
    print(f"extra page's first figure while the studies run: {first or float('nan'):.2f} s (target ≤ 1 s)")
    for page in pages[:args.disconnect]:
        await page.close()
    await asyncio.sleep(2.0)
    print(f"{args.disconnect} pages left: {len(study_processes(pid))} study processes 2 s later")
    for page in [*pages[args.disconnect:], extra]:
        await page.close()
    gone = await _until(lambda: not study_processes(pid), args.limit)
    quiet = None
    t0 = time.monotonic()
    while time.monotonic() - t0 < args.limit:
        if await cpu_share(pid) <= idle_cpu + 0.05:
            quiet = time.monotonic() - t0
            break
    sampler.cancel()
    await asyncio.sleep(5.0)
    after = rss_mib(pid)
    print(f"after the last disconnect: study processes gone in {_s(gone)}, CPU idle in {_s(quiet)} (target ≤ 5 s)")
    print(f"RSS: idle {idle_rss:.0f} MiB, peak {peak[0]:.0f} MiB, 5 s after close {after:.0f} MiB "
          f"({100 * (after / idle_rss - 1):+.0f} % of idle; target within ±20 %); the server alone "
          f"{rss_mib(pid, tree=False):.0f} MiB, {len(_descendants(pid))} other processes")


def _s(x: float | None) -> str:
    return "never" if x is None else f"{x:.1f} s"


def main() -> None:
    """Parse the options, start the server, run the sequence, stop the server."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pages", type=int, default=10)
    ap.add_argument("--disconnect", type=int, default=5)
    ap.add_argument("--samples", type=int, default=20_000)
    ap.add_argument("--study", choices=tuple(RUN), default="robustness")
    ap.add_argument("--limit", type=float, default=60.0, help="longest wait of each step [s]")
    args = ap.parse_args()
    port = free_port()
    server = start_server(port)
    try:
        asyncio.run(asyncio.wait_for(run(args, server.pid, f"127.0.0.1:{port}"), 20 * args.limit))
    finally:
        server.send_signal(signal.SIGINT)
        try:
            server.wait(10.0)
        except subprocess.TimeoutExpired:
            server.kill()


if __name__ == "__main__":
    main()
