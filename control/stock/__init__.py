"""A stock drive's own loops: encoder PLL, position/speed cascade or PID, dq current PI (see :mod:`.loops`)."""
