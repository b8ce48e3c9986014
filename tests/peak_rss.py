"""Peak memory of one reader call on a hostile file, measured in a child process.

The child imports the reader, resets its peak resident size (``/proc/self/clear_refs``, Linux), calls
the reader on the file and reports the rise of the peak over the resident size before the call and
the reader's answer. The figure per input byte is what the bounded-memory rule limits (≤ 25×).
Used by the tests and by ``scripts/bench_hostile.py`` (which prints the figures).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: reader name -> (import line, call on ``path``); each returns or raises with one line
READERS = {
    "log file (CLI)": ("from pmsm_commissioning.app.io.drive_log import read_log", "read_log(path)"),
    "log upload (page)": ("from pmsm_commissioning.app.io.drive_log import read_bytes",
                          "read_bytes(data, 'upload.csv')"),
    "moves file (dutycycle)": ("from pmsm_commissioning.app.cli.duty import read_moves", "read_moves(path)"),
    "vendor file (import-drive)": ("from pmsm_commissioning.app.cli.import_drive import read_text",
                                   "read_text(path)"),
    "preset file": ("from pmsm_commissioning.app.io.presets import load_raw", "load_raw(path)"),
}

_CHILD = """
import json, sys
def kb(field):
    with open('/proc/self/status') as fh:
        return next(int(ln.split()[1]) for ln in fh if ln.startswith(field))
{imp}
path = sys.argv[1]
data = open(path, 'rb').read() if {upload} else None
with open('/proc/self/clear_refs', 'w') as fh:
    fh.write('5')
base = kb('VmRSS')
try:
    {call}
    answer = 'accepted'
except Exception as exc:
    answer = type(exc).__name__ + ': ' + str(exc)
print(json.dumps({{'base_kb': base, 'peak_kb': kb('VmHWM'), 'answer': answer}}))
"""


@dataclass(frozen=True)
class Peak:
    """Peak memory of one reader call: rise of the peak resident size [B] and the reader's answer."""

    reader: str
    input_bytes: int
    rise_bytes: int
    answer: str

    @property
    def per_byte(self) -> float:
        """Rise of the peak per byte of input [-]."""
        return self.rise_bytes / max(self.input_bytes, 1)


def peak(reader: str, path: Path) -> Peak:
    """Run ``reader`` of :data:`READERS` on ``path`` in a child process and return its :class:`Peak`."""
    imp, call = READERS[reader]
    code = _CHILD.format(imp=imp, call=call, upload="data" in call)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code, str(path)], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300, check=True).stdout
    got = json.loads(out.strip().splitlines()[-1])
    return Peak(reader, path.stat().st_size, max(0, got["peak_kb"] - got["base_kb"]) * 1024, got["answer"])


def row_bomb(path: Path, n_rows: int, header: str = "t [s],i_q [A]") -> Path:
    """Write a log of a valid header and ``n_rows`` one-character rows (2 bytes each)."""
    path.write_bytes(header.encode() + b"\n" + b"1\n" * n_rows)
    return path


def sparse_file(path: Path, n_bytes: int) -> Path:
    """Write a sparse file that claims ``n_bytes`` and holds (almost) none."""
    with open(path, "wb") as fh:
        fh.seek(n_bytes - 1)
        fh.write(b"\n")
    return path
