"""Control laws and derivations: pure numpy/scipy, one source per law that numba inlines."""
