"""Bounded memory: a file's size and row count are checked before and while it is read, before any
parse that grows with it. A row bomb (millions of one-character rows) and a sparse file (10 GB that
holds nothing) are refused early with one line, and the peak resident size rises by at most
:data:`MAX_PER_BYTE` times the input's bytes (measured in a child process, :mod:`tests.peak_rss`;
``scripts/bench_hostile.py`` prints the figures).
"""

from __future__ import annotations

import json
import os
import threading

import pytest

from pmsm_commissioning.app.cli.main import main
from pmsm_commissioning.app.exports.drives.odrive import parse_odrive
from pmsm_commissioning.app.io.bounded import ReadError, read_bounded
from pmsm_commissioning.app.io.drive_log import MAX_ROWS, LogError, parse_log, read_log
from pmsm_commissioning.control.common.checks import ParameterError
from tests.peak_rss import READERS, peak, row_bomb, sparse_file

#: Largest rise of the peak resident size per byte of hostile input [-].
MAX_PER_BYTE = 25.0
#: A sparse file's apparent size [B].
SPARSE_BYTES = 10 * 2**30


def _one_line(answer: str) -> None:
    assert "\n" not in answer and len(answer) <= 300 and "Traceback" not in answer, answer


@pytest.mark.parametrize("reader", ["log file (CLI)", "log upload (page)"])
@pytest.mark.parametrize("n_rows", [8_000_000, 1_900_000])
def test_row_bomb_is_refused_within_25_bytes_per_byte(tmp_path, reader, n_rows):
    # 8 M rows: over the line count, refused before any row is kept; 1.9 M rows: under it, refused at the
    # first row shorter than the header, before any is parsed
    got = peak(reader, row_bomb(tmp_path / "bomb.csv", n_rows))
    assert got.answer.startswith("LogError"), got.answer
    _one_line(got.answer)
    assert ("lines: allowed ≤" in got.answer) if n_rows > MAX_ROWS else ("line 2: 1 fields" in got.answer)
    assert got.per_byte <= MAX_PER_BYTE, (got.rise_bytes, got.input_bytes)


def test_blank_line_bomb_keeps_nothing_per_line(tmp_path):
    path = tmp_path / "blank.csv"
    path.write_bytes(b"t [s],i_q [A]\n" + b"\n" * 1_900_000)
    got = peak("log file (CLI)", path)
    assert "0 data rows" in got.answer and got.per_byte <= MAX_PER_BYTE, (got.answer, got.rise_bytes)


@pytest.mark.parametrize("reader", [r for r in READERS if r != "log upload (page)"])
def test_sparse_10_gb_file_is_refused_before_reading(tmp_path, reader):
    path = sparse_file(tmp_path / ("big.yaml" if reader == "preset file" else "big.csv"), SPARSE_BYTES)
    got = peak(reader, path)
    _one_line(got.answer)
    assert "allowed ≤" in got.answer and ("too large" in got.answer or "larger than" in got.answer
                                         or "10240.0 MB" in got.answer), got.answer
    assert got.rise_bytes <= 16 * 2**20, got  # nothing of the 10 GB was read


def test_files_without_a_true_size_are_read_no_further_than_the_limit(tmp_path):
    with pytest.raises(ReadError, match="larger than 1 KiB: allowed ≤ 1 KiB"):
        read_bounded("/dev/zero", 1024, "zero")  # endless, size 0
    assert read_bounded("/proc/self/stat", 4096)  # size 0, content read
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    box: list[BaseException] = []
    t = threading.Thread(target=lambda: box.append(pytest.raises(ReadError, read_bounded, fifo, 1024).value))
    t.start()
    t.join(30)  # opening a FIFO without a writer would wait forever
    assert not t.is_alive() and "is a FIFO: allowed a regular file" in str(box[0])


def test_cli_refuses_a_row_bomb_and_a_sparse_file_with_exit_2(tmp_path, capsys):
    bomb = row_bomb(tmp_path / "bomb.csv", 3_000_000)
    assert main(["log", str(bomb)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "3000002 lines: allowed ≤" in err, err
    moves = sparse_file(tmp_path / "moves.yaml", SPARSE_BYTES)
    assert main(["dutycycle", "paper_12kw_pmsm", str(moves)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "10240.0 MB: allowed ≤ 256 KiB" in err, err
    vendor = sparse_file(tmp_path / "backup.json", SPARSE_BYTES)
    argv = ["import-drive", str(vendor), "--format", "odrive", "--base", "odrive_d5065_belt", "-o",
            str(tmp_path / "out.yaml")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "10240.0 MB: allowed ≤ 256 KiB" in err, err
    assert not (tmp_path / "out.yaml").exists()


def test_log_rows_keep_their_line_numbers_and_line_ends():
    rows = "\r\n".join(f"{k * 1e-3:.3f},{k}" for k in range(25))
    text = "# comment\r\n\r\nt [s],i_q [A]\r\n   # indented comment\r\n" + rows + "\r\n"
    log = parse_log(text)
    assert log.signals["i_q"][-1] == 24.0 and log.T_s == pytest.approx(1e-3)
    bad = text.replace("0.010,10", "0.010,x")
    with pytest.raises(LogError, match=r"line 15, column 'i_q \[A\]'"):  # 4 lines before the rows, row 11
        parse_log(bad)
    with pytest.raises(LogError, match="line 6: 1 fields, the header has 2"):
        parse_log(text.replace("0.001,1\r\n", "0.001\r\n"))
    old_mac = text.replace("\r\n", "\r")  # bare CR line ends
    assert parse_log(old_mac).signals["i_q"][-1] == 24.0


def test_run_labels_are_bounded():
    rows = "\n".join(f"{k},{k * 1e-3},{k}" for k in range(40))
    with pytest.raises(LogError, match="more than 16 different runs"):
        parse_log("controller,t [s],i_q [A]\n" + rows)


def test_odrive_duplicate_key_found_among_many():
    keys = {f"k{i}": 1 for i in range(28_000)}
    text = json.dumps({"axis0": {"motor": {"config": keys}}})
    assert len(parse_odrive(text).unknown) >= 28_000  # read in one pass; every key listed
    dup = text[:-4] + ', "k27999": 2}}}'
    with pytest.raises(ParameterError, match="'k27999' is given more than once"):
        parse_odrive(dup)


def test_log_read_refuses_a_folder(tmp_path):
    with pytest.raises(LogError, match="cannot be read"):
        read_log(tmp_path)
