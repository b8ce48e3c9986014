"""Position-drive simulation of [1]: compiled kernel, plain-Python reference, engine, metrics, verdicts."""
