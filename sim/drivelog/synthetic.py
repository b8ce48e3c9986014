"""Synthetic drive logs from the project's own plant, for testing identification and import.

A drive tuned for the nominal parameters (FDC inner loops, observer and FDSMC outer loop of
:mod:`sim.fdsmc.reference`) controls a plant whose true parameters differ from them. The log starts
with a motor-ID d-axis current injection at standstill (i_d,dem steps, as drives' motor
identification routines do — without it L_d is not excited, because the FDC keeps i_d = 0,
eq. (10) in [1]), then the rest-to-rest move. The logged signals carry what a real drive
adds: Gaussian current noise, ADC quantisation, encoder quantisation of θ_r, quantised
commanded voltages, and a one-sample computation delay between the logged (commanded) and the
applied voltage.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from pmsm_commissioning.control.fdsmc import fdc
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.model import model_coefficients
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.control.fdsmc.sliding_mode import smc_law
from pmsm_commissioning.sim.fdsmc.reference import ReferenceDrive


@dataclass(frozen=True)
class LogNoise:
    """Measurement imperfections of a synthetic log.

    Attributes
    ----------
    sigma_i : float  Gaussian current noise [A] (before quantisation).
    adc_bits : int  Current ADC resolution [bits] over ±i_full_scale.
    i_full_scale : float  ADC full scale [A].
    encoder_counts : int  Encoder counts per mechanical revolution [-].
    u_lsb : float  Resolution of the logged voltages [V].
    """

    sigma_i: float = 0.05
    adc_bits: int = 12
    i_full_scale: float = 100.0
    encoder_counts: int = 16384
    u_lsb: float = 0.01


@dataclass(frozen=True)
class Injection:
    """Standstill d-axis current injection before the move: i_d,dem = levels[k] for ``dwell`` [s] each."""

    levels: tuple[float, ...] = (10.0, -10.0, 10.0, -10.0, 10.0, -10.0, 5.0, 0.0)
    dwell: float = 0.015


#: Overrides of the nominal preset for the example logs: a short move the torque limit allows,
#: a slower acceleration loop and observer for a 10 kHz drive with one sample of delay, and a
#: boundary-layer gain K below the loop's stability limit (no chatter).
LOG_OVERRIDES = (
    "manoeuvre.theta_dem=3", "manoeuvre.T_m=0.45", "controller.K=1.0", "controller.f_s=10000",
    "controller.delay_samples=1",
    "controller.alpha_max_rule=torque_limit", "controller.T_salpha=0.005", "controller.T_so=0.001",
)
#: True plant of the example logs (SI): differs from the paper's motor and load.
TRUE_MOTOR = {"R_s": 0.12, "L_d": 0.0048, "L_q": 0.006, "psi_pm": 0.36}
TRUE_LOAD = {"J_L": 0.10, "F_v": 0.5, "Gamma_Le": 1.5}
#: Duration of the example logs [s]: injection (8 × 15 ms), the move (0.45 s) and a short tail.
LOG_DURATION = 0.68


def perturbed(nominal: DriveParams, motor: Mapping[str, Any] = TRUE_MOTOR,
              load: Mapping[str, Any] = TRUE_LOAD) -> DriveParams:
    """Return the true plant: ``nominal`` with the motor and load fields replaced."""
    return dataclasses.replace(nominal, motor=dataclasses.replace(nominal.motor, **motor),
                               load=dataclasses.replace(nominal.load, **load), source="synthetic plant")


class _InjectingDrive(ReferenceDrive):
    """Reference drive whose plant has the true parameters and whose i_d,dem follows an injection."""

    def __init__(self, true: DriveParams, d_nominal: Derived, injection: Injection) -> None:
        super().__init__(true, d_nominal, "fdsmc")
        self.plant_c = model_coefficients(true.motor)  # the true plant; the controller keeps d_nominal's
        self.inj = injection
        self.t_move = injection.dwell * len(injection.levels)

    def voltages(self, y: tuple[float, float, float], xh: np.ndarray,
                 i0: tuple[float, float] | None = None) -> tuple[float, float]:
        """u_d, u_q [V] from the readings y = (θ_r, i_d, i_q): the injection, then the FDSMC (no limits)."""
        d, c, ctrl = self.d, self.c, self.p.controller
        i_d, i_q = y[1], y[2]
        th_h, w_h, L0, L1 = xh
        if self.t < self.t_move:
            k = min(len(self.inj.levels) - 1, int(self.t / self.inj.dwell + 1e-9))
            a_dem, i_d_dem = 0.0, self.inj.levels[k]
        else:
            a_dem = smc_law(th_h - self.p.manoeuvre.theta_dem, w_h, d.profile.omega_p, d.profile.T_c,
                            ctrl.K, d.alpha.alpha_max)
            i_d_dem = 0.0
        alpha = fdc.acceleration_estimate(i_d, i_q, L0, c)
        u_d = fdc.direct_axis_voltage(i_d, i_q, w_h, c, ctrl.T_si, i_d_dem)
        u_q = fdc.quadrature_axis_voltage(a_dem, alpha, i_d, i_q, w_h, u_d, L1, c, ctrl.T_salpha)
        return u_d, u_q


def clean_log(true: DriveParams, d_nominal: Derived, t_end: float, injection: Injection = Injection(),
              n_sub: int = 2) -> dict[str, np.ndarray]:
    """Noise-free samples of the drive (SI): t, theta_r, omega_r, i_d, i_q and the logged u_d, u_q.

    The controller runs at ``true.controller.f_s`` with ``true.controller.delay_samples``; the
    logged voltage at sample k is the one *commanded* at k (applied one sample later when the
    delay is 1), as a drive's scope records it.
    """
    drive = _InjectingDrive(true, d_nominal, injection)
    n = int(round(t_end * float(true.controller.f_s)))
    rec = np.zeros((7, n))
    for k in range(n):
        rec[:5, k] = (drive.t, *drive.x[:4])
        rec[5:, k] = drive.voltages(drive.measure(drive.x), drive.xh)
        drive.step_sample(n_sub)
    return dict(zip(("t", "i_d", "i_q", "theta_r", "omega_r", "u_d", "u_q"), rec, strict=True))


def add_noise(clean: dict[str, np.ndarray], noise: LogNoise, seed: int) -> dict[str, np.ndarray]:
    """Return the measured log: noisy, quantised currents; encoder θ_r; ω_r by the drive's difference.

    ω_r is the drive's speed signal: the encoder difference averaged over 1 ms (lagging and
    noisy, as logged by drives); identification uses θ_r when both are present.
    """
    rng = np.random.default_rng(seed)
    lsb_i = 2.0 * noise.i_full_scale / 2**noise.adc_bits
    lsb_th = 2.0 * np.pi / noise.encoder_counts
    out = {"t": clean["t"].copy()}
    for k in ("i_d", "i_q"):
        out[k] = np.round((clean[k] + rng.normal(0.0, noise.sigma_i, clean[k].size)) / lsb_i) * lsb_i
    out["theta_r"] = np.floor(clean["theta_r"] / lsb_th + rng.uniform(0, 1)) * lsb_th
    for k in ("u_d", "u_q"):
        out[k] = np.round(clean[k] / noise.u_lsb) * noise.u_lsb
    T_s = float(np.median(np.diff(clean["t"])))
    m = max(1, int(round(1e-3 / T_s)))
    dth = np.diff(out["theta_r"], prepend=out["theta_r"][0]) / T_s
    out["omega_r"] = np.convolve(dth, np.ones(m) / m)[: dth.size]
    return out
