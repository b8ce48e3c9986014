"""Exports: the export menu (``model``), the C99 controller (``firmware``), the stock drives' files (``drives``).

Common to both sub-packages and kept here: ``model`` (every format, dispatching to either), ``provenance``
(the gate every export passes and the drive files' header), ``tool_id`` (the tool's name and version in every
file) and ``html`` (the offline report, neither firmware nor a drive file).
"""
