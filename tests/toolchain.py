"""The tools the C tests need (compilers, the ARM cross-compiler, qemu): present, or a failure under CI=true.

``scripts/ensure_cc.sh`` installs them; on CI a missing one is a failure, never a skip, and elsewhere the
test is skipped with the command that installs it.
"""

from __future__ import annotations

import os

import pytest


def need(tool: str | None, name: str) -> str:
    """Return ``tool`` (its path or name) when present; else fail under CI=true, skip elsewhere."""
    if tool is None:
        if os.environ.get("CI") == "true":
            pytest.fail(f"{name} missing: scripts/ensure_cc.sh installs it (CI needs it)")
        pytest.skip(f"{name} missing (run scripts/ensure_cc.sh)")
    return tool
