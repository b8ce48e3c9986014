"""Studies built on the engines: Monte-Carlo robustness, multi-axis and duty-cycle runs."""
