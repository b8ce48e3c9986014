"""Where numba's on-disk cache of the compiled kernels goes.

By default numba writes a kernel's cache beside its module, in ``__pycache__``: for an installed
wheel that is site-packages, which needs write access there, is shared by every user and is left
behind by ``pip uninstall``. The cache goes instead to, in this order:

1. ``$NUMBA_CACHE_DIR`` when it is set (numba's own variable: the user's choice is kept);
2. a clone's ``.numba_cache/`` folder (a source checkout: ``scripts/setup.sh`` warms it);
3. the user's cache folder by the XDG rule: ``$XDG_CACHE_HOME/pmsm-commissioning/numba`` (an absolute
   ``XDG_CACHE_HOME`` only), else ``~/.cache/pmsm-commissioning/numba`` (``%LOCALAPPDATA%`` on Windows).

So the first command after an install compiles the kernels once per user (≈ 20–35 s of CPU) and
every later one loads them. :mod:`sim` keys a sub-folder on a hash of the sources (``src-<hash>``);
the folders of older versions may be deleted at any time (they are only caches).
"""

from __future__ import annotations

import os
from pathlib import Path

#: Folder name below the user's cache directory.
APP_NAME = "pmsm-commissioning"
_ROOT = Path(__file__).resolve().parent.parent


def user_cache_dir() -> Path:
    """Return the user's cache folder for the compiled kernels (the XDG rule; ``%LOCALAPPDATA%`` on Windows)."""
    if os.name == "nt" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"]) / APP_NAME / "numba"
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if xdg and Path(xdg).is_absolute() else Path.home() / ".cache"
    return base / APP_NAME / "numba"


def cache_base() -> Path:
    """Return the folder numba's cache goes into: ``$NUMBA_CACHE_DIR``, a clone's ``.numba_cache``, or the user's."""
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if chosen:
        return Path(chosen)
    if (_ROOT / "pyproject.toml").is_file() and (_ROOT / "sim").is_dir():  # a source checkout
        return _ROOT / ".numba_cache"
    return user_cache_dir()


__all__ = ["APP_NAME", "cache_base", "user_cache_dir"]
