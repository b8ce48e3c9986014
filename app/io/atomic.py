"""Write every file of the tool atomically: a temporary file in the same folder, renamed when complete.

A reader (or a crash, Ctrl-C, SIGTERM, a full disk) never sees a half-written file: the target keeps
its old content until :func:`os.replace` swaps in the complete new one, which is atomic on the same
file system. Temporary files in progress are registered, so the command line's interrupt handler
can remove them (:func:`discard_partial`) before it exits.

What may be written over (:func:`target_problem`, the same rule for every command): a new file or an
existing *regular* file the user may write. A device node (``/dev/null``, ``/dev/full``), a FIFO, a
socket, a folder, a read-only file or a symbolic-link loop is refused (:class:`TargetError`, an
OSError whose text says why and what is allowed): renaming a regular file over ``/dev/null`` would
replace the device node, and writing through it would silently lose the data. A symbolic link to a
regular file is written through (its target is replaced). Several files that belong together (the C
module's folder) are written by :func:`write_all`: every file to its temporary file first, then all
renamed, so a full disk leaves every old file as it was.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
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


class TargetError(OSError):
    """A path that is not written over: a device, FIFO, socket, folder, read-only file or symbolic-link loop."""


def _kind(mode: int) -> str | None:
    kinds = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO"),
             (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a folder"))
    return next((name for test, name in kinds if test(mode)), None)


def target_problem(path: str | Path) -> str | None:
    """Return why ``path`` may not be written over (None: a new file or a writable regular file).

    The text says what the path is and what is allowed, e.g. "is a character device, not a regular
    file: allowed a new or regular, writable file".
    """
    allowed = "allowed a new or regular, writable file"
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return None  # a new file (or a dangling link: its target is created)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return f"is a symbolic-link loop: {allowed}"
        return f"cannot be checked ({exc.strerror or exc}): {allowed}"
    kind = _kind(st.st_mode)
    if kind is not None:
        return f"is {kind}, not a regular file: {allowed}"
    if not st.st_mode & 0o222 or not os.access(path, os.W_OK):  # no write bit: read-only, for root too
        return f"is read-only: {allowed} (make it writable, or write elsewhere)"
    return None


def _target(path: str | Path) -> Path:
    """Return the file to replace (a symbolic link's target); TargetError when it may not be written over."""
    problem = target_problem(path)
    if problem is not None:
        raise TargetError(errno.EINVAL, problem, str(path))
    target = Path(path)
    return Path(os.path.realpath(target)) if target.is_symlink() else target


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
        temporary file is left. :class:`TargetError` when ``path`` may not be written over
        (:func:`target_problem`).
    """
    write_all({path: data})


def _temporary(target: Path, data: bytes) -> str:
    """Write ``data`` to a new temporary file beside ``target`` (synced, with ``target``'s mode); its path."""
    folder = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name[:64]}.", suffix=".part", dir=folder)
    with _lock:
        _pending.add(tmp)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, target.stat().st_mode & 0o7777 if target.is_file() else _NEW_MODE)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        with _lock:
            _pending.discard(tmp)
        raise
    return tmp


def write_all(files: dict[str | Path, bytes]) -> None:
    """Write several files whole: every one to its temporary file first, then all renamed.

    A full disk, a refused target or Ctrl-C before the renames leaves every old file as it was and
    no temporary file; the renames themselves need no space.

    Raises
    ------
    OSError
        As :func:`write_atomic` (TargetError for a target that may not be written over).
    """
    targets = [(_target(path), data) for path, data in files.items()]
    temps: list[str] = []
    try:
        for target, data in targets:
            temps.append(_temporary(target, data))
        for tmp, (target, _) in zip(temps, targets, strict=True):
            os.replace(tmp, target)
    finally:
        for tmp in temps:
            with contextlib.suppress(OSError):
                os.unlink(tmp)  # already renamed: nothing there
        with _lock:
            _pending.difference_update(temps)


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


__all__ = ["TargetError", "discard_partial", "target_problem", "write_all", "write_atomic", "write_atomic_text"]
