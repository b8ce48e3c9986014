"""The simulator's plant driven by an external controller (firmware in the loop).

Digital mode of :func:`sim.fdsmc.engine.simulate` applies, at each sample, voltages computed by the
compiled controller and holds them for n_sub RK4 substeps of the plant. :class:`PlantInTheLoop`
exposes exactly that plant integration (same parameter vector, same time grid, same RK4 step
:func:`sim.fdsmc.kernel.rk4_plant`) with the voltages supplied from outside, so that a controller
written elsewhere — e.g. the generated C module — can be run against the very same plant and its
trajectory compared sample by sample with the simulator's.

Plant: eqs. (1)–(3), (4b), (5) of [1] (the FDSMC paper), energies as extra states.
"""

from __future__ import annotations

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc import kernel as kn
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.grid import load_steps, time_grid
from pmsm_commissioning.sim.fdsmc.run import pack_parameters


class PlantInTheLoop:
    """Plant and energy states of one digital-mode run, stepped one controller sample at a time.

    Parameters
    ----------
    params : DriveParams
        The case; ``params.controller.f_s`` must be a sample rate (digital mode).
    derived : Derived or None
        ``derive(params)`` if already computed.
    controller : str
        Only selects the divergence-limit scaling of the parameter vector; the plant itself
        does not depend on it.

    Attributes
    ----------
    x : tuple of float
        [i_d A, i_q A, θ_r rad, ω_r rad/s, E_friction J, E_copper J, E_electrical J,
        E_motoring J, E_load J] (indices ``X_*`` of :mod:`sim.fdsmc.kernel`).
    t : float
        Time [s], accumulated exactly as in the kernel.
    T_s : float
        Sample period [s].
    n_samples : int
        Samples of the simulator's horizon [0, (1 + TAIL_FRACTION)·T_m] [-].
    """

    def __init__(self, params: DriveParams, derived: Derived | None = None,
                 controller: str = "fdsmc") -> None:
        if params.controller.is_continuous:
            raise ParameterError("controller.f_s = 'continuous': the plant in the loop needs a sample rate in Hz")
        d = derive(params) if derived is None else derived
        g = time_grid(params, 1, 0.0, 1)
        self._prm = pack_parameters(params, d, controller)
        self._step_t, self._step_v = load_steps(params)
        self._h, self._n_sub = g.h, g.n_sub
        self.T_s, self.n_samples = g.h * g.n_sub, g.n_steps
        self.x: tuple[float, ...] = (0.0,) * lay.X_THH
        self.t = 0.0

    def step(self, u_d: float, u_q: float) -> None:
        """Hold u_d, u_q [V] over one sample period (n_sub RK4 substeps of the plant)."""
        for _ in range(self._n_sub):
            self.x = kn.rk4_plant(self.t, self._h, self.x, float(u_d), float(u_q), self._prm,
                                  self._step_t, self._step_v)
            self.t += self._h

    @property
    def state(self) -> np.ndarray:
        """The current plant and energy states as an array (order of :attr:`x`)."""
        return np.array(self.x)
