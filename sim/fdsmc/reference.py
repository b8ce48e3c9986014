"""Plain-Python reference of the closed-loop step, built from the laws in :mod:`control`.

Readable counterpart of :mod:`sim.fdsmc.kernel` (same model, same integration scheme), used to check
the compiled kernel and to measure its speed-up. Slow: use it for short horizons only.

Model, eqs. of [1] (the FDSMC paper): plant (1)–(3), (4b), (5); FDC (7), (9), (10), (14);
observer (15) corrected (continuous) or its ZOH-exact discrete form; outer law (41)–(46) or
(62) sign-corrected.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.control.fdsmc import fdc
from pmsm_commissioning.control.fdsmc.conventional import conventional_law
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.feasibility import current_limit
from pmsm_commissioning.control.fdsmc.inverter import decay_factors, limit_voltage, predict_currents
from pmsm_commissioning.control.fdsmc.model import electromagnetic_torque
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.sliding_mode import smc_law
from pmsm_commissioning.sim.common import sensors


@dataclass(frozen=True)
class ReferenceState:
    """Plant, estimates and energies after a step (SI units: A, rad, rad/s, N·m, N·m/s, J)."""

    t: float
    i_d: float
    i_q: float
    theta_r: float
    omega_r: float
    theta_hat: float
    omega_hat: float
    L0: float
    L1: float
    E_friction: float
    E_copper: float
    E_electrical: float


class ReferenceDrive:
    """Step-by-step simulation of one controller (plain Python, mirrors the kernel).

    Parameters
    ----------
    params : DriveParams
    d : Derived
    controller : str  ``"fdsmc"`` or ``"conventional"``.
    """

    def __init__(self, params: DriveParams, d: Derived, controller: str) -> None:
        self.p, self.d, self.controller = params, d, controller
        self.c = d.coefficients
        #: Coefficients of the simulated plant: the controller's model unless a subclass simulates another drive.
        self.plant_c = d.coefficients
        # x = [i_d, i_q, θ, ω, E_f, E_cu, E_el]; xh = [θ̂, ω̂, L̂0, L̂1]
        self.x = np.zeros(7)
        self.xh = np.zeros(4)
        self.t = 0.0
        self.k = 0  # sample number: the index into the sensors' noise table
        self.u_hold = (0.0, 0.0)
        se = params.sensors
        self.noise = sensors.noise_table(se)
        self.enc_step, self.adc_step = se.encoder_step, se.adc_step
        T = d.observer_discrete.T_s if d.observer_discrete is not None else 0.0
        self.decay = decay_factors(self.c.A, T) + decay_factors(self.c.D, T)  # (φ_d, γ_d, φ_q, γ_q)

    def gamma_le(self, t: float) -> float:
        """External load torque Γ_Le(t) [N·m]."""
        ld = self.p.load
        g = ld.Gamma_Le
        for s in ld.steps:
            if t >= s.t:
                g = s.Gamma_Le
        return g + ld.Gamma_Le_ramp * t

    def measure(self, x: np.ndarray) -> tuple[float, float, float]:
        """Return the readings (θ_r [rad], i_d, i_q [A]) of the sensors at the current sample."""
        se, j = self.p.sensors, self.k % self.noise.shape[1]
        adc = [sensors.adc_current(x[i], self.noise[i, j], se.i_noise, self.adc_step, se.i_adc_range)
               for i in (0, 1)]
        return sensors.encoder_angle(x[2], self.enc_step), adc[0], adc[1]

    def voltages(self, y: tuple[float, float, float], xh: np.ndarray,
                 i0: tuple[float, float] | None = None) -> tuple[float, float]:
        """u_d, u_q [V] of eqs. (9), (14) with the outer law and the inverter limits.

        ``y`` are the readings (θ_r, i_d, i_q); ``i0`` the currents the limit starts from (default
        the readings).
        """
        d, c, ctrl = self.d, self.c, self.p.controller
        i_d, i_q = y[1], y[2]
        th_h, w_h, L0, L1 = xh
        th_dem = self.p.manoeuvre.theta_dem
        if self.controller == "fdsmc":
            a_dem = smc_law(th_h - th_dem, w_h, d.profile.omega_p, d.profile.T_c, ctrl.K,
                            d.alpha.alpha_max)
        else:
            a_dem = conventional_law(th_dem, th_h, w_h, d.conventional)
        alpha = fdc.acceleration_estimate(i_d, i_q, L0, c)
        u_d = fdc.direct_axis_voltage(i_d, i_q, w_h, c, ctrl.T_si)
        u_q = fdc.quadrature_axis_voltage(a_dem, alpha, i_d, i_q, w_h, u_d, L1, c, ctrl.T_salpha)
        u_max = ctrl.V_dc / math.sqrt(3.0)
        i0 = (i_d, i_q) if i0 is None else i0
        u_d, u_q, _ = limit_voltage(u_d, u_q, i0[0], i0[1], w_h, current_limit(self.p), u_max, *self.decay,
                                    c.B, c.C, c.E, c.F, c.G)
        return u_d, u_q

    def plant(self, t: float, x: np.ndarray, u_d: float, u_q: float) -> np.ndarray:
        """Return the derivatives of [i_d, i_q, θ, ω, E_f, E_cu, E_el], eqs. (1)–(3), (4b), (5)."""
        c, m, ld = self.plant_c, self.p.motor, self.p.load
        i_d, i_q, _, w = x[:4]
        T_em = electromagnetic_torque(m.p, m.psi_pm, m.L_d, m.L_q, i_d, i_q)
        return np.array([
            -c.A * i_d + c.B * w * i_q + c.F * u_d,
            -(c.C * i_d + c.E) * w - c.D * i_q + c.G * u_q,
            w,
            (T_em - ld.F_v * w - self.gamma_le(t)) / self.p.J_total,
            ld.F_v * w * w,
            1.5 * m.R_s * (i_d**2 + i_q**2),
            1.5 * (u_d * i_d + u_q * i_q),
        ])

    def observer(self, x: np.ndarray, xh: np.ndarray) -> np.ndarray:
        """Corrected continuous observer, eq. (15) with e_o = θ_r − θ̂_r."""
        o, c = self.d.observer, self.c
        e_o = x[2] - xh[0]
        a_em = (c.H + c.K * x[0]) * x[1]
        return np.array([xh[1] + o.K1 * e_o, a_em - c.M * xh[2] + o.K2 * e_o,
                         xh[3] + o.K3 * e_o, o.K4 * e_o])

    def _continuous_rhs(self, t: float, z: np.ndarray) -> np.ndarray:
        x, xh = z[:7], z[7:]
        u_d, u_q = self.voltages((x[2], x[0], x[1]), xh)
        return np.concatenate([self.plant(t, x, u_d, u_q), self.observer(x, xh)])

    def step_continuous(self, h: float) -> None:
        """One RK4 step [s] with the controller evaluated inside the right-hand side."""
        self.decay = decay_factors(self.c.A, h) + decay_factors(self.c.D, h)  # the limit predicts over h
        z, t = np.concatenate([self.x, self.xh]), self.t
        k1 = self._continuous_rhs(t, z)
        k2 = self._continuous_rhs(t + h / 2, z + h / 2 * k1)
        k3 = self._continuous_rhs(t + h / 2, z + h / 2 * k2)
        k4 = self._continuous_rhs(t + h, z + h * k3)
        z = z + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        self.x, self.xh, self.t = z[:7], z[7:], t + h

    def step_sample(self, n_sub: int = 1) -> None:
        """One controller sample: control, observer update, n_sub RK4 substeps with held u."""
        od = self.d.observer_discrete
        assert od is not None
        y, c = self.measure(self.x), self.c
        i0 = None
        if self.p.controller.delay_samples == 1:  # the limit starts where the held voltages leave the currents
            i0 = predict_currents(y[1], y[2], self.xh[1], *self.u_hold, *self.decay, c.B, c.C, c.E, c.F, c.G)
        u = self.voltages(y, self.xh, i0)
        if self.p.controller.delay_samples == 1:
            u, self.u_hold = self.u_hold, u
        a_em = (c.H + c.K * y[1]) * y[2]
        e_o = y[0] - self.xh[0]
        self.k += 1
        self.xh = od.Phi @ self.xh + od.Gamma * a_em + od.L * e_o
        h = od.T_s / n_sub
        for _ in range(n_sub):
            t, x = self.t, self.x
            k1 = self.plant(t, x, *u)
            k2 = self.plant(t + h / 2, x + h / 2 * k1, *u)
            k3 = self.plant(t + h / 2, x + h / 2 * k2, *u)
            k4 = self.plant(t + h, x + h * k3, *u)
            self.x, self.t = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), t + h

    def state(self) -> ReferenceState:
        """Return the current state as a frozen record."""
        x, xh = self.x, self.xh
        return ReferenceState(self.t, *(float(v) for v in x[:4]), *(float(v) for v in xh),
                              *(float(v) for v in x[4:7]))


def run_reference(
    params: DriveParams, d: Derived, controller: str, n_steps: int, h_continuous: float = 5e-6,
    n_sub: int = 1,
) -> ReferenceState:
    """Run ``n_steps`` samples (digital) or RK4 steps (continuous) from rest; final state."""
    drive = ReferenceDrive(params, d, controller)
    for _ in range(n_steps):
        if params.controller.is_continuous:
            drive.step_continuous(h_continuous)
        else:
            drive.step_sample(n_sub)
    return drive.state()

