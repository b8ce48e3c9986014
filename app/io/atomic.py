"""Write every file of the tool atomically: a temporary file in the same folder, renamed when complete.

A reader (or a crash, Ctrl-C, SIGTERM, a full disk) never sees a half-written file: the target keeps
its old content until :func:`os.replace` swaps in the complete new one, which is atomic on the same
file system. Temporary files in progress are registered, so the command line's interrupt handler
can remove them (:func:`discard_partial`) before it exits.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
import threading
from pathlib import Path

_pending: set[str] = set()
_lock = threading.Lock()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Permissions of a new file, as ``open(path, "w")`` would give it.
_NEW_MODE = 0o666 & ~_umask()


def write_atomic(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and :func:`os.replace`.

    Parameters
    ----------
    path : str or Path
        The file to write; a symbolic link is written through (its target is replaced).
    data : bytes
        The complete content.

    Raises
    ------
    OSError
        When the folder cannot be written or the disk is full; ``path`` is then unchanged and no
        temporary file is left.
    """
    target = Path(path)
    if target.is_symlink():
        target = target.resolve()
    folder = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name[:64]}.", suffix=".part", dir=folder)
    with _lock:
        _pending.add(tmp)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        mode = target.stat().st_mode & 0o7777 if target.is_file() else _NEW_MODE
        os.chmod(tmp, mode)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    finally:
        with _lock:
            _pending.discard(tmp)


def write_atomic_text(path: str | Path, text: str) -> None:
    """:func:`write_atomic` of ``text`` as UTF-8."""
    write_atomic(path, text.encode("utf-8"))


def discard_partial() -> list[str]:
    """Remove every temporary file still being written (called on an interrupt); returns their paths."""
    with _lock:
        pending = sorted(_pending)
        _pending.clear()
    for tmp in pending:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    return pending


__all__ = ["discard_partial", "write_atomic", "write_atomic_text"]
