"""A reader that goes away (``pmsm-commission simulate … | head -1``) ends the command quietly.

The first line is read, the pipe closed; the command's next writes fail with EPIPE. It must end with
128 + SIGPIPE, as a shell reports a process the pipe ended, and no traceback on stderr.
"""

from __future__ import annotations

import subprocess
import sys

from tests.child_signals import default_signals


def test_a_closed_pipe_ends_the_command_without_a_traceback():
    cmd = [sys.executable, "-m", "pmsm_commissioning.app", "simulate", "paper_12kw_pmsm"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=default_signals)
    assert proc.stdout is not None and proc.stderr is not None
    first = proc.stdout.readline()
    proc.stdout.close()  # the reader goes away after one line, as ``head -1`` does
    err = proc.stderr.read().decode()
    rc = proc.wait(timeout=300)
    assert first.startswith(b"Preset: paper_12kw_pmsm")
    assert "Traceback" not in err and "BrokenPipeError" not in err, err
    assert rc == 141, (rc, err)
