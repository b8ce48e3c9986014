"""Shared by both modes: the ``@jitable`` decorator that lets one law run with or without numba."""
