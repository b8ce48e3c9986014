"""Simulate a stock drive running its own loops on the move it was given: the stock route.

A :class:`StockLoop` holds every number of a stock drive's control structure in SI units — its
cycle, the encoder PLL, the position/speed law and its gains, the current PI, the limits and the
setpoint table it follows (:mod:`control.stock.loops`). The vendor files are read back into one
(:mod:`app.exports`), so what :func:`simulate_stock` runs is what the drive loads.

The plant, the sensors (encoder counts, current noise and ADC), the energy bookkeeping, the
metrics and the checks are the FDSMC run's (:mod:`sim.fdsmc.kernel`, :mod:`sim.fdsmc.metrics`,
:mod:`sim.fdsmc.checks`); the drive's cycle replaces the controller's f_s, with one cycle of
computation delay (the voltages computed in a cycle are applied in the next, as on ODrive, moteus
and VESC).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived, derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.stock.loops import LAW_CASCADE, LAW_PID
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.grid import MAX_POINTS, check_budget, time_grid
from pmsm_commissioning.sim.fdsmc.run import RunResult, pack_parameters, run_packed

#: Position/speed laws by name.
LAWS = {"cascade": LAW_CASCADE, "pid": LAW_PID}


@dataclass(frozen=True)
class StockLoop:
    """A stock drive's control structure and settings, SI units (what its file sets, read back).

    Attributes
    ----------
    drive : str            Which drive runs it (``odrive``, ``moteus``, ``vesc``, ``setpoints``).
    f_loop : float         Cycle rate of the position, speed and current loops [Hz].
    law : str              ``cascade`` (P–PI) or ``pid`` (parallel PID on position).
    kp : float             pos_gain [1/s] (cascade) or kp [N·m/rad] (pid).
    kd : float             vel_gain or kd [N·m·s/rad].
    ki : float             Speed integrator gain [N·m/rad] (cascade) or ki [N·m/(rad·s)] (pid).
    i_lim : float          Integrator clamp [N·m] (pid; inf: none).
    omega_lim : float      Speed-demand clamp [rad/s] (cascade; inf: none).
    J_ff : float           Inertia feed-forward [kg·m²] (0: none).
    K_t : float            Torque per ampere of i_q the drive assumes [N·m/A].
    current_limit : float  Clamp of the i_q demand [A].
    omega_e : float        Encoder PLL bandwidth [rad/s].
    snap : bool            The PLL's speed is snapped to 0 below 0.5·T·ki counts/s (ODrive).
    current_kp : float     Current PI proportional gain [V/A].
    current_ki : float     Current PI integral gain [V/(A·s)].
    table : numpy.ndarray  Setpoints, 3 × n: θ_ref [rad], ω_ref [rad/s], α_ref [rad/s²] …
    table_dt : float       … one row per table_dt [s] from t = 0, interpolated linearly between rows.
    """

    drive: str
    f_loop: float
    law: str
    kp: float
    kd: float
    ki: float
    i_lim: float
    omega_lim: float
    J_ff: float
    K_t: float
    current_limit: float
    omega_e: float
    snap: bool
    current_kp: float
    current_ki: float
    table: np.ndarray = dataclasses.field(repr=False)
    table_dt: float = 1e-3

    def __post_init__(self) -> None:
        """Refuse a law or a setting outside its range, naming it."""
        if self.law not in LAWS:
            raise ParameterError(f"stock law = {self.law!r} is not allowed: one of {', '.join(LAWS)}")
        for name in ("f_loop", "K_t", "current_limit", "omega_e", "current_kp", "table_dt"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ParameterError(f"{self.drive} {name} = {v!r} is not allowed: a finite number > 0")
        for name in ("kp", "kd", "ki", "J_ff", "current_ki"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ParameterError(f"{self.drive} {name} = {v!r} is not allowed: a finite number ≥ 0")


def at_loop_rate(params: DriveParams, f_loop: float) -> DriveParams:
    """Return ``params`` with the controller sampled at the drive's cycle rate with one cycle of delay."""
    ctrl = dataclasses.replace(params.controller, f_s=float(f_loop), delay_samples=1)
    return dataclasses.replace(params, controller=ctrl)


def pack_loop(prm: np.ndarray, loop: StockLoop, u_max: float, encoder_step: float) -> None:
    """Write the stock drive's indices ``P_D*`` of the kernel's parameter vector (P_CTRL = 4)."""
    T = 1.0 / loop.f_loop
    snap = 0.5 * T * 0.25 * (2.0 * loop.omega_e) ** 2 * encoder_step if loop.snap else 0.0
    prm[lay.P_CTRL] = float(lay.Law.DRIVE)
    prm[[lay.P_DLAW, lay.P_DKP, lay.P_DKD, lay.P_DKI, lay.P_DILIM, lay.P_DWLIM, lay.P_DJFF]] = (
        LAWS[loop.law], loop.kp, loop.kd, loop.ki, loop.i_lim, loop.omega_lim, loop.J_ff)
    prm[[lay.P_DKT, lay.P_DIMAX, lay.P_DWE, lay.P_DSNAP]] = (loop.K_t, loop.current_limit, loop.omega_e, snap)
    prm[[lay.P_DCKP, lay.P_DCKI, lay.P_DUMAX, lay.P_DT, lay.P_DREFDT]] = (
        loop.current_kp, loop.current_ki, u_max, T, loop.table_dt)


def simulate_stock(params: DriveParams, loop: StockLoop, derived: Derived | None = None,
                   plant: DriveParams | None = None) -> RunResult:
    """Simulate the stock drive ``loop`` on the case ``params`` (its plant, sensors, limits, criteria).

    Parameters
    ----------
    params : DriveParams   The case; its controller's f_s is replaced by the drive's cycle.
    loop : StockLoop       The drive's loops and setpoints (read back from its file).
    derived : Derived      ``derive(params)`` if already computed (only its model coefficients are used).
    plant : DriveParams    The drive's true motor and load when they differ from ``params``.

    Returns
    -------
    RunResult
        Controller ``"stock"``; never raises for an unstable run (``metrics.stable`` False).
    """
    p = at_loop_rate(params, loop.f_loop)  # its delay_samples = 1: the drive's one cycle of delay
    check_budget(p, 1)
    d = derive(params) if derived is None else derived
    g = time_grid(p, 1, 0.0, MAX_POINTS)
    prm = pack_parameters(params, d, "fdsmc", plant, g.h * g.n_sub)  # the plant, sensors and limits
    V_dc = params.controller.V_dc  # 0: no voltage limit
    pack_loop(prm, loop, V_dc / math.sqrt(3.0) if V_dc > 0.0 else math.inf, params.sensors.encoder_step)
    no_observer = (np.zeros((4, 4)), np.zeros(4), np.zeros(4))
    return run_packed(p, d, "stock", g, prm, np.ascontiguousarray(loop.table), no_observer, plant)
