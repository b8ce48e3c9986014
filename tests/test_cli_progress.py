"""The long commands' progress (``robustness``, ``table1``) on stderr: a tqdm bar redrawn in place on a
terminal; a few whole lines when stderr is a file (no carriage return, not a line per update); and the
results the same whichever stderr is.
"""

from __future__ import annotations

import fcntl
import io
import json
import os
import pty
import re
import struct
import subprocess
import sys
import termios
import threading
from pathlib import Path

from pmsm_commissioning.app.cli import progress as pg

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = 24
ROBUSTNESS = ["robustness", "paper_12kw_pmsm", "--samples", str(SAMPLES), "--spread", "plant.J_L=±20%",
              "--seed", "3", "--workers", "1", "--json"]
PLAIN = re.compile(r"(\w+) (\d+)/(\d+) \((\d+) %\)")


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _plain_lines(err: str, what: str, total: int) -> list[int]:
    """The counts of the plain progress lines, checked to be whole, well-formed and in order."""
    assert "\r" not in err, repr(err[:300])
    lines = err.splitlines()
    assert 1 <= len(lines) <= pg.PLAIN_STEPS + 1, err
    done = []
    for line in lines:
        m = PLAIN.fullmatch(line)
        assert m and m[1] == what and int(m[3]) == total, line
        assert int(m[4]) == 100 * int(m[2]) // total
        done.append(int(m[2]))
    assert done == sorted(done) and done[-1] == total
    return done


def test_plain_lines_in_a_file_a_few_whole_lines_whatever_the_updates():
    out = io.StringIO()
    with pg.Progress("samples", "sample", out) as progress:
        for k in range(1001):
            progress(k, 1000)
    done = _plain_lines(out.getvalue(), "samples", 1000)
    assert done == [100 * s for s in range(pg.PLAIN_STEPS + 1)]  # the first update, then each tenth
    assert not pg.bar_open()


def test_a_bar_redrawn_in_place_on_a_terminal_its_line_ended_when_done():
    term = _Terminal()
    with pg.Progress("samples", "sample", term) as progress:
        progress(0, 50)
        assert pg.bar_open()
        for k in range(1, 51):
            progress(k, 50)
    assert not pg.bar_open()
    text = term.getvalue()
    assert text.startswith("\rsamples:") and text.count("\n") == 1 and text.endswith("\n")  # one line, redrawn
    assert "50/50" in text.rsplit("\r", 1)[-1] and "sample/s" in text


def test_a_failing_sweep_still_ends_the_bars_line():
    term = _Terminal()
    try:
        with pg.Progress("samples", "sample", term) as progress:
            progress(3, 10)
            raise RuntimeError("executor lost")
    except RuntimeError:
        pass
    assert term.getvalue().endswith("\n") and not pg.bar_open()


def _read_all(fd: int) -> bytes:
    """What a pseudo-terminal's other end wrote, up to its close."""
    chunks = []
    while True:
        try:
            data = os.read(fd, 4096)
        except OSError:  # EIO: every writer closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks)


def test_a_terminal_of_no_known_size_still_shows_the_bar():
    main_fd, term_fd = pty.openpty()  # 0 columns × 0 lines, as a container's fresh pseudo-terminal
    try:
        with os.fdopen(term_fd, "w", encoding="utf-8") as term:
            assert os.get_terminal_size(term.fileno()) == (0, 0)
            with pg.Progress("simulated", "run", term) as progress:
                for k in range(5):
                    progress(k, 4)
        text = _read_all(main_fd).decode("utf-8")
    finally:
        os.close(main_fd)
    assert "\r" in text and "4/4" in text.rsplit("\r", 2)[-2] and "%|" in text, repr(text)
    assert len(text.rsplit("\r", 2)[-2]) <= pg.FALLBACK_SIZE[0]


def _run(argv: list[str], terminal: bool, tmp_path: Path) -> tuple[str, str]:
    """The command's stdout and stderr, its stderr a pseudo-terminal or a file."""
    cmd = [sys.executable, "-m", "pmsm_commissioning.app", *argv]
    env = {**os.environ, "COLUMNS": "100"}
    if not terminal:
        err_file = tmp_path / "stderr.txt"
        with err_file.open("w", encoding="utf-8") as fh:
            r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=fh, text=True, cwd=ROOT, env=env, timeout=600,
                               check=False)
        err = err_file.read_text(encoding="utf-8")
        assert r.returncode == 0, err[-2000:]
        return r.stdout, err
    main_fd, term_fd = pty.openpty()
    fcntl.ioctl(term_fd, termios.TIOCSWINSZ, struct.pack("HHHH", 30, 100, 0, 0))  # 100 columns, 30 lines
    chunks: list[bytes] = []
    # the terminal read as it is written (a full pseudo-terminal would block the command)
    reader = threading.Thread(target=lambda: chunks.append(_read_all(main_fd)), daemon=True)
    reader.start()
    try:
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=term_fd, text=True, cwd=ROOT, env=env)
        os.close(term_fd)
        out, _ = proc.communicate(timeout=600)
        reader.join(timeout=30)
    finally:
        os.close(main_fd)
    err = b"".join(chunks).decode("utf-8", "replace")
    assert proc.returncode == 0, err[-2000:]
    return out, err


def _summary(out: str) -> dict:
    summary = json.loads(out)
    summary.pop("seconds")  # the run's wall time
    return summary


def test_robustness_progress_in_a_file_is_a_few_lines_and_the_results_are_the_terminals(tmp_path):
    out_file, err_file = _run(ROBUSTNESS + ["--csv", str(tmp_path / "file.csv")], False, tmp_path)
    _plain_lines(err_file, "samples", SAMPLES)
    out_term, err_term = _run(ROBUSTNESS + ["--csv", str(tmp_path / "term.csv")], True, tmp_path)
    assert "\r" in err_term and f"{SAMPLES}/{SAMPLES}" in err_term and "%|" in err_term  # tqdm's bar
    assert _summary(out_file) == _summary(out_term)
    assert (tmp_path / "file.csv").read_bytes() == (tmp_path / "term.csv").read_bytes()


def test_table1_progress_in_a_file_is_whole_lines_and_the_table_on_stdout(tmp_path):
    out, err = _run(["table1", "paper_12kw_pmsm", "--tm", "1.0,2.6"], False, tmp_path)
    _plain_lines(err, "simulated", 2)
    rows = [line for line in out.splitlines() if re.match(r"\s+(1|2\.6)\s", line)]
    assert out.startswith("Preset: ") and len(rows) == 2
