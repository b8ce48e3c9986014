"""Child processes of the tests start with the default signal dispositions, whatever the shell gave pytest.

A non-interactive shell starts a background job with SIGINT ignored, and an ignored signal stays
ignored across ``exec``: Python then installs no KeyboardInterrupt handler, and a test that stops a
command with Ctrl-C would see it run on. Pass :func:`default_signals` as ``preexec_fn``.
"""

from __future__ import annotations

import signal

#: Signals a terminal or a service manager sends to stop a command.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGQUIT, signal.SIGHUP)


def default_signals() -> None:
    """Reset the stop signals to their default action (run in the child, between fork and exec)."""
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_DFL)
