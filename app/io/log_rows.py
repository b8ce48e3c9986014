r"""The rows of a drive log, found without one Python object per row: memory bounded by the file's size.

A log of millions of one-character rows (a row bomb) used to become a list of millions of strings,
and a list of (line number, text) pairs besides: 16 MB of text took 1.3 GB before its row count was
refused. Here the rows are counted before anything grows with them (refused over the row limit
plus :data:`SPARE_LINES`), then kept as three integer arrays (start, end, line number: 24 bytes a
row) over the file's UTF-8 bytes, and handed to the readers lazily (:meth:`Rows.lines`). A row
with fewer fields than the header is refused by :func:`check_widths` before any row is parsed.

Lines end at ``\n``, ``\r\n`` or (a file without ``\n``) ``\r``, as Python's ``csv`` module ends
rows; ``#`` lines and blank lines are skipped (their line numbers still count).
"""

from __future__ import annotations

import csv
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

#: Lines of other kinds (header, unit row, comments, blank lines) allowed besides the data rows [-].
SPARE_LINES = 10_000
#: Rows handed to a reader per slice of the index arrays [-] (bounds the Python integers alive at once).
_SLICE = 65_536
_BLANK = b" \t\f\v"
#: Bytes searched for line breaks at a time [B].
_CHUNK = 2**20


class RowsError(ValueError):
    """The file's rows cannot be read within the limits; the message is one line."""


@dataclass(frozen=True)
class Rows:
    """Data rows of a log: ``data[start[k]:end[k]]`` is row ``k``, found on line ``line_no[k]`` (1-based)."""

    data: bytes
    start: np.ndarray
    end: np.ndarray
    line_no: np.ndarray

    def __len__(self) -> int:
        """Return the number of rows."""
        return int(self.start.size)

    def line(self, k: int) -> str:
        """Text of row ``k``."""
        return self.data[int(self.start[k]):int(self.end[k])].decode("utf-8", "replace")

    def lines(self) -> Iterator[str]:
        """Yield the rows' texts, one at a time."""
        for i in range(0, len(self), _SLICE):
            for s, e in zip(self.start[i:i + _SLICE].tolist(), self.end[i:i + _SLICE].tolist(), strict=True):
                yield self.data[s:e].decode("utf-8", "replace")

    def take(self, keep: np.ndarray | slice) -> Rows:
        """Return the rows selected by a boolean mask or a slice."""
        return Rows(self.data, self.start[keep], self.end[keep], self.line_no[keep])


def _keep(data: bytes, start: np.ndarray, end: np.ndarray, line0: int, out: tuple[np.ndarray, ...], n: int,
          crlf: bool) -> int:
    r"""Append the lines of ``data[start:end]`` that are neither blank nor ``#`` comments; return the new count.

    ``out`` = (start, end, line number) arrays holding ``n`` lines so far; the lines given are numbered
    from ``line0 + 1``; ``crlf``: a ``\r`` before the line break is not part of the row.
    """
    buf = np.frombuffer(data, dtype=np.uint8)
    if crlf:  # \r\n: the \r is not part of the row
        cr = end > start
        cr[cr] = buf[end[cr] - 1] == 13
        end = end - cr
    filled = end > start
    first = np.full(start.size, ord("#"), dtype=np.uint8)
    first[filled] = buf[start[filled]]
    kept = first != ord("#")
    for k in np.flatnonzero(kept & np.isin(first, np.frombuffer(_BLANK, dtype=np.uint8))):
        text = data[start[k]:end[k]].lstrip(_BLANK)  # rare: a line that starts with blanks
        kept[k] = bool(text) and not text.startswith(b"#")
    index = np.flatnonzero(kept)
    m = n + index.size
    out[0][n:m], out[1][n:m], out[2][n:m] = start[index], end[index], index + (line0 + 1)
    return m


def _kept_lines(data: bytes, max_rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(start, end, line number) of the lines of ``data`` that are neither blank nor comments.

    The lines are counted before any array is filled, and found a chunk at a time: memory is a few
    bytes per kept line (the arrays are reserved for every line but only the kept part is touched).
    """
    buf = np.frombuffer(data, dtype=np.uint8)
    brk = 10 if b"\n" in data or b"\r" not in data else 13  # a file of bare \r (old Mac) ends rows at \r
    count = data.count(bytes([brk])) + 1
    if count > max_rows + SPARE_LINES:  # before any array grows with the lines
        raise RowsError(f"the log has {count} lines: allowed ≤ {max_rows + SPARE_LINES} ({max_rows} rows and "
                        f"{SPARE_LINES} others; cut or decimate it)")
    offset = np.int32 if buf.size < 2**31 else np.int64  # 4 bytes a line for any file we accept
    out = tuple(np.empty(count, dtype=offset) for _ in range(3))
    n, line0, pos = 0, 0, 0
    for i in range(0, buf.size, _CHUNK):
        end = (np.flatnonzero(buf[i:i + _CHUNK] == brk) + i).astype(offset)
        if end.size:
            start = np.empty_like(end)
            start[0], start[1:] = pos, end[:-1] + 1
            n, line0, pos = _keep(data, start, end, line0, out, n, brk == 10), line0 + end.size, int(end[-1]) + 1
    n = _keep(data, np.array([pos], offset), np.array([buf.size], offset), line0, out, n, brk == 10)
    return out[0][:n], out[1][:n], out[2][:n]


def split_rows(text: str, max_rows: int) -> tuple[str, int, Rows]:
    """(header line, its line number, data rows) of a log's text; comments and blank lines skipped.

    Raises :class:`RowsError` over ``max_rows`` + :data:`SPARE_LINES` lines or ``max_rows`` + 1 rows
    (a unit row may follow the header), or when the file holds no header.
    """
    data = text.encode("utf-8", "surrogateescape")
    start, end, line_no = _kept_lines(data, max_rows)
    if start.size == 0:
        raise RowsError("the log is empty: expected a header row such as 't [s], theta_r [rad], i_q [A]'")
    if start.size - 1 > max_rows + 1:
        raise RowsError(f"the log has {start.size - 1} rows: allowed ≤ {max_rows} (cut or decimate it)")
    header = data[start[0]:end[0]].decode("utf-8", "replace")
    return header, int(line_no[0]), Rows(data, start[1:], end[1:], line_no[1:])


def check_widths(rows: Rows, delim: str, width: int) -> bool:
    """Refuse the first row with fewer fields than the header's ``width`` (found by counting delimiters).

    Returns True when every row holds exactly ``width - 1`` delimiters (numpy's fast reader may read them).
    """
    d, data, plain = delim.encode(), rows.data, True
    for i in range(0, len(rows), _SLICE):
        for s, e in zip(rows.start[i:i + _SLICE].tolist(), rows.end[i:i + _SLICE].tolist(), strict=True):
            n = data.count(d, s, e)
            if n < width - 1:  # quotes only ever join fields: this row is short
                k = i + int(np.searchsorted(rows.start[i:i + _SLICE], s))
                fields = len(next(csv.reader([rows.line(k)], delimiter=delim), []))
                raise RowsError(f"line {int(rows.line_no[k])}: {fields} fields, the header has {width}")
            plain = plain and n == width - 1
    return plain


__all__ = ["SPARE_LINES", "Rows", "RowsError", "check_widths", "split_rows"]
