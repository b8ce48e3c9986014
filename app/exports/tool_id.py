"""The tool's name and version as the exported files state them (the C header, the drive files' headers).

:func:`tool_version` reads the installed package's version, so a generated file names the code that
wrote it; the C module's parameter hash covers it (:func:`app.exports.firmware.module.parameter_hash`).
"""

from __future__ import annotations

import importlib.metadata

#: The tool's name in every exported file.
TOOL = "pmsm-commissioning (FDSMC)"


def tool_version() -> str:
    """Return ``"<tool> <version>"`` (the installed package's version, else ``unknown``)."""
    try:
        version = importlib.metadata.version("pmsm-commissioning")
    except importlib.metadata.PackageNotFoundError:
        version = "unknown"
    return f"{TOOL} {version}"
