"""The stock route: a stock drive's own loops on the simulator's plant and sensors (:mod:`.route`), tuned."""
