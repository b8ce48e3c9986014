"""Read a file the user named, never more than a limit: the size is checked before and while reading.

A file's size in ``stat`` can lie: a sparse file claims 10 GB it does not hold (and reading it
would make them), a ``/proc`` or device file claims 0 and streams without end, a FIFO has none.
:func:`read_bounded` refuses a regular file whose ``stat`` size is over the limit before reading a
byte, then reads at most ``limit + 1`` bytes whatever the kind of file, so the memory it takes is
bounded by the limit, never by the file. A FIFO is refused (opening it would wait for a
writer). Every refusal is one line naming the file, its size and the
allowed size.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from pmsm_commissioning.app.io.user_text import escaped


class ReadError(ValueError):
    """A file that cannot be read within its limit; the message is one line naming it.

    ``size`` [B]: the size found when the file is too large (at least the limit + 1 when read), else None.
    """

    def __init__(self, message: str, size: int | None = None) -> None:
        super().__init__(message)
        self.size = size


def size_text(n_bytes: float) -> str:
    """``n_bytes`` [B] as a short text: B, KiB or MB."""
    if n_bytes < 1024:
        return f"{n_bytes:.0f} B"
    if n_bytes < 2**20:
        return f"{n_bytes / 1024:.0f} KiB"
    return f"{n_bytes / 2**20:.1f} MB"


def limit_text(limit: int) -> str:
    """Return a limit [B] as a short text in whole MB or KiB when it is one (``50 MB``, ``256 KiB``)."""
    if limit % 2**20 == 0:
        return f"{limit // 2**20} MB"
    return f"{limit // 1024} KiB" if limit % 1024 == 0 else f"{limit} B"


def too_large(what: str, size: float, limit: int) -> str:
    """Return the one-line refusal of a file of ``size`` [B] over ``limit`` [B]."""
    return f"{what} is {size_text(size)}: allowed ≤ {limit_text(limit)}"


def read_bounded(path: str | os.PathLike[str], limit: int, what: str | None = None) -> bytes:
    """Return the bytes of ``path``: at most ``limit`` [B], else :class:`ReadError` (nothing more is read).

    ``what`` names the file in the message (default: its path, escaped for the terminal).
    """
    name = what or f"{escaped(str(path))!r}"
    try:
        if stat.S_ISFIFO(os.stat(path).st_mode):  # opening one would wait for a writer
            raise ReadError(f"{name} is a FIFO: allowed a regular file")
        with open(Path(path), "rb") as fh:
            info = os.fstat(fh.fileno())
            if stat.S_ISREG(info.st_mode) and info.st_size > limit:
                raise ReadError(too_large(name, info.st_size, limit), info.st_size)  # before reading (sparse too)
            data = fh.read(limit + 1)  # a /proc file, a FIFO, a device: never more than this
    except OSError as exc:
        raise ReadError(f"{name} cannot be read: {exc.strerror or exc}: allowed a readable file") from None
    if len(data) > limit:
        raise ReadError(f"{name} is larger than {limit_text(limit)}: allowed ≤ {limit_text(limit)}", len(data))
    return data


def read_utf8(path: str | os.PathLike[str], limit: int, what: str | None = None) -> str:
    """Return the UTF-8 text of ``path``, read as :func:`read_bounded`; :class:`ReadError` if it is not UTF-8."""
    data = read_bounded(path, limit, what)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ReadError(f"{what or repr(escaped(str(path)))} is not UTF-8 text (byte {exc.start}): allowed a "
                        "UTF-8 text file") from None


__all__ = ["ReadError", "limit_text", "read_bounded", "read_utf8", "size_text", "too_large"]
