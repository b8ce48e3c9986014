"""BLDC speed-drive simulation of [2]: compiled kernel, engine, metrics and back-EMF shapes."""
