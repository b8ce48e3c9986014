"""Speed drive of [2]: parameters, dqx model (eqs. 4-12), current and speed SMC (eqs. 13-24), PI, six-step."""
