"""Progress of a long command on stderr: a tqdm bar on a terminal, a few plain lines elsewhere.

On a terminal the bar redraws one line in place (tqdm, at most about ten redraws a second). When stderr is a
file or a pipe (a log, a batch job, a test) redrawing would leave every update in the file, so the progress
is then a few whole lines, ``"<what> <done>/<total> (<percent> %)"``: the first update and one each time
another of :data:`PLAIN_STEPS` steps is done (at most ``PLAIN_STEPS + 1`` lines, the last at 100 %). A log
shows how far a run got, a reader of the stream can parse it line by line, and no line carries a carriage
return.
"""

from __future__ import annotations

import os
import sys
from types import TracebackType
from typing import Any, TextIO

#: Steps of the plain progress lines when stderr is not a terminal: a line per tenth done.
PLAIN_STEPS = 10

#: Columns and lines assumed of a terminal that reports no size [characters].
FALLBACK_SIZE = (80, 24)

#: Bars open on the terminal now (the interrupt message starts a new line below one).
_open_bars: list[Any] = []


def _size_known(stream: TextIO) -> bool:
    """Return True when the terminal ``stream`` writes to reports its columns and lines."""
    try:
        size = os.get_terminal_size(stream.fileno())
    except (AttributeError, OSError, ValueError):
        return False
    return size.columns > 0 and size.lines > 0


def bar_open() -> bool:
    """Return True while a progress bar is drawn on the terminal (its line not ended)."""
    return bool(_open_bars)


class Progress:
    """The ``progress(done, total)`` callback of a sweep, as a context manager that ends the bar's line.

    Parameters
    ----------
    what
        What is counted, the line's first word (``"samples"``, ``"simulated"``).
    unit
        One item, in the bar's rate (``"sample"`` → ``3.9 sample/s``).
    stream
        Where the progress goes (default: ``sys.stderr`` at the time of the call).
    """

    def __init__(self, what: str, unit: str, stream: TextIO | None = None) -> None:
        self.what, self.unit = what, unit
        self.stream = stream if stream is not None else sys.stderr
        self.terminal = bool(getattr(self.stream, "isatty", lambda: False)())
        self._bar: Any = None
        self._step = -1

    def __call__(self, done: int, total: int) -> None:
        """Show that ``done`` of ``total`` items are finished."""
        if total <= 0:
            return
        if self.terminal:
            self._draw(done, total)
            return
        step = PLAIN_STEPS * done // total
        if step > self._step:
            self._step = step
            self.stream.write(f"{self.what} {done}/{total} ({100 * done // total} %)\n")
            self.stream.flush()

    def _draw(self, done: int, total: int) -> None:
        if self._bar is None:
            from tqdm import tqdm  # only on a terminal: a command's cold start does without it

            # the terminal's size as it changes; one of no known size (a container's fresh pseudo-terminal
            # is 0 × 0, where tqdm would hide the bar as beyond the last line) gets FALLBACK_SIZE
            size: dict[str, Any] = {"dynamic_ncols": True}
            if not _size_known(self.stream):
                size = {"ncols": FALLBACK_SIZE[0], "nrows": FALLBACK_SIZE[1]}
            self._bar = tqdm(total=total, desc=self.what, unit=f" {self.unit}", file=self.stream, leave=True,
                             **size)
            _open_bars.append(self._bar)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        """End the bar's line (the bar stays as drawn last); nothing to do for plain lines."""
        if self._bar is not None:
            self._bar.close()
            _open_bars.remove(self._bar)
            self._bar = None

    def __enter__(self) -> Progress:
        """Return the callback."""
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        """End the bar's line, also when the sweep raised (its error line then starts a line of its own)."""
        self.close()
