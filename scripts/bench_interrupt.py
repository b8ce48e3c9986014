"""Print how fast each long command stops on Ctrl-C (SIGINT to its process group) and on SIGTERM.

The promise: ≤ 1 s, exit 130, one line, no partial file. Uses the fault suite's
commands (``tests/test_faults_signals.py``). Run: ``.venv/bin/python scripts/bench_interrupt.py``.
"""

from __future__ import annotations

import signal
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tests.test_faults_signals import LONG_COMMANDS, OLD, interrupt  # noqa: E402


def main() -> None:
    """One line per command and signal: stop time, exit code, whether the old file survived."""
    worst = 0.0
    for name, argv, after_s in LONG_COMMANDS:
        for sig in (signal.SIGINT, signal.SIGTERM):
            with tempfile.TemporaryDirectory() as tmp:
                out = Path(tmp) / "result.out"
                out.write_bytes(OLD)
                result, stop_s = interrupt([a.format(out=out) for a in argv], after_s, sig)
                kept = out.read_bytes() == OLD and not list(Path(tmp).glob("*.part"))
            worst = max(worst, stop_s)
            print(f"{stop_s * 1e3:7.0f} ms  rc {result.returncode:3d}  file kept {kept!s:5s}  "
                  f"{signal.Signals(sig).name:7s} {name}: {result.stderr.strip()[:60]}")
    print(f"worst stop {worst * 1e3:.0f} ms (promise ≤ 1000 ms)")


if __name__ == "__main__":
    main()
