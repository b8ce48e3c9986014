"""Shared by both modes: response metrics of signals and the cost budget checked before any run."""
