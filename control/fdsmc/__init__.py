"""Position drive of [1]: model (eqs. 1-4), FDC (eqs. 7-14), observer, sliding mode (eqs. 41-46), profile."""
