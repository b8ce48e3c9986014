"""``pmsm-commission serve [--host 127.0.0.1] [--port 8080] [--preset NAME]``: start the web UI.

Binds to the loopback interface by default (viser's own default, 0.0.0.0, would expose the tool
to the plant network); a non-loopback host prints a warning. If the port is taken viser moves to
the next free one, and the URL printed is the one actually used.
"""

from __future__ import annotations

import argparse
import ipaddress
import sys
import time

from pmsm_commissioning.app.io.numbers import integer_option
from pmsm_commissioning.app.io.presets import DEFAULT_PRESET, load
from pmsm_commissioning.app.ui.web_guard import Guard, new_token
from pmsm_commissioning.control.fdsmc.derivations import derive


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``serve``."""
    p.add_argument("--host", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1, this machine only; 0.0.0.0 = all interfaces)")
    p.add_argument("--port", type=integer_option("--port"), default=8080,
                   help="TCP port (default 8080; the next free one if taken)")
    p.add_argument("--preset", default=DEFAULT_PRESET,
                   help=f"start-up preset name or YAML path (default {DEFAULT_PRESET})")
    p.add_argument("--no-3d", action="store_true", help="do not show the 3D rotor view")
    p.add_argument("--allow-origin", action="append", default=[], metavar="URL",
                   help="also accept the page from this origin, e.g. https://hmi.plant.local (repeatable)")


def is_loopback(host: str) -> bool:
    """Return True for localhost / 127.x / ::1."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


#: Longest the main thread sleeps between looks for Ctrl-C or SIGTERM [s].
SIGNAL_POLL_S = 0.2


def run(args: argparse.Namespace) -> int:
    """Start the server, print the URL and serve until Ctrl-C."""
    if not 1 <= args.port <= 65535:
        raise ValueError(f"--port = {args.port} is out of range: allowed 1 … 65535")
    params = load(args.preset, mode="position")
    derive(params)  # a preset the derivations reject fails here, with its message
    token = None if is_loopback(args.host) else new_token()
    if token is not None:
        print(f"warning: binding to {args.host}: the tool is reachable from other machines on the "
              "network; only browsers that open the URL below (with its token) get in. Use --host "
              "127.0.0.1 unless you need this.", file=sys.stderr)
    from pmsm_commissioning.app.ui.page import create_server  # imports viser; keep `--help` fast

    guard = Guard.for_host(args.host, args.allow_origin, token)
    try:
        server, _ = create_server(params, args.preset, host=args.host, port=args.port,
                                  scene_3d=not args.no_3d, guard=guard)
    except OSError as exc:
        raise ValueError(f"--host {args.host} --port {args.port}: cannot start the server: {exc}") from None
    port = server.get_port()
    if port != args.port:
        print(f"note: port {args.port} is in use; using port {port} instead.", file=sys.stderr)
    shown = "127.0.0.1" if args.host in ("0.0.0.0", "::") else args.host
    query = f"/?token={token}" if token else ""
    print(f"PMSM commissioning tool: http://{shown}:{port}{query}  (preset {args.preset}; Ctrl-C to stop)",
          flush=True)
    try:
        while True:  # short sleeps: a signal the kernel hands to another thread only sets Python's flag,
            time.sleep(SIGNAL_POLL_S)  # which the main thread reads when its sleep ends
    except KeyboardInterrupt:
        server.stop()
        raise  # the CLI then ends the process at once: a run still simulating is not waited for
