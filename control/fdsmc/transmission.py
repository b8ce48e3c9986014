"""Transmission between the motor and the load: gearbox or belt ratio, lead screw, belt/rack pulley.

The physics of the drive (eqs. (1)–(6) of [1]) stays on the motor side in SI units: the load
inertia, friction, load torque and the move of :class:`~control.fdsmc.params.DriveParams` are the
values the rotor sees. This module holds the transmission's data and the one set of formulas that
reflect load-side quantities onto the rotor and back (the edge, :mod:`app.io.transmission_keys`,
turns what the engineer typed at the output into the motor-side fields with them).

Reflection through a rigid transmission of ratio N (motor revolutions per output revolution) and
efficiency η, the motor driving the load (the sizing convention of servo catalogues, e.g. Siemens
SIZER, and of [2] section 3.2):

* angle, speed: θ_r = N·θ_out, ω_r = N·ω_out;
* inertia: J_L = J_out/(η·N²); viscous friction F_v = F_v,out/(η·N²); load torque Γ_Le = Γ_out/(η·N).

A linear axis (lead screw of lead ℓ per screw revolution, or a belt/rack pulley of radius r, ℓ = 2π·r)
moves x = ℓ·θ_out/(2π), so the travel per motor radian is k = ℓ/(2π·N) [m/rad] and

* x = k·θ_r; v = k·ω_r; J_L = m·k²/η; F_v = c·k²/η (c [N·s/m]); Γ_Le = F·k/η.

E.g. a 10 mm lead screw moving 20 kg directly (N = 1, η = 1): J_L = 20·(0.01/2π)² = 5.07e-5 kg·m².
Backlash and compliance are not modelled (the transmission is rigid); η is applied in the motoring
direction throughout, so the reflected load is on the safe side when the load drives the motor.

References
----------
[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper (``../shared/papers/``).
[2] G. Ellis, *Control System Design Guide*, 4th ed., ch. 16 (reflected inertia J/N², lead screws).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmsm_commissioning.control.common.checks import ParameterError, check_fields, spec_field


@dataclass(frozen=True)
class Transmission:
    """The mechanical transmission from the rotor to the load (rigid; motor side is the physics).

    Attributes
    ----------
    ratio : float
        Motor revolutions per output (or screw / pulley) revolution N [-]; 1 = direct drive.
    efficiency : float
        Efficiency η of the transmission [-], 0 < η ≤ 1; applied as the motor drives the load.
    lead : float
        Lead of a lead screw: travel per screw revolution [m]; 0 = no lead screw.
    pulley_radius : float
        Pitch radius of a belt or rack-and-pinion pulley driving a linear axis [m]; 0 = none.
    """

    ratio: float = spec_field("-", 1e-3, 1e5, default=1.0, low_open=False,
                              label="N transmission ratio (motor rev per output rev)")
    efficiency: float = spec_field("-", 0.0, 1.0, default=1.0, label="η transmission efficiency")
    lead: float = spec_field("m", 0.0, 10.0, default=0.0, low_open=False, display="mm",
                             label="Lead screw lead (0 = none)")
    pulley_radius: float = spec_field("m", 0.0, 10.0, default=0.0, low_open=False, display="mm",
                                      label="Belt/rack pulley radius (0 = none)")

    def __post_init__(self) -> None:
        """Check the ranges; a lead screw and a pulley are alternatives."""
        check_fields(self, "transmission")
        if self.lead > 0.0 and self.pulley_radius > 0.0:
            raise ParameterError(f"transmission.pulley_radius = {self.pulley_radius!r} m is not allowed with "
                                 f"transmission.lead = {self.lead!r} m: allowed one of them (the other 0)")

    @property
    def linear(self) -> bool:
        """True when the output is a linear axis (lead screw or pulley)."""
        return self.lead > 0.0 or self.pulley_radius > 0.0

    @property
    def is_direct(self) -> bool:
        """True for no transmission at all (N = 1, η = 1, rotary output)."""
        return self.ratio == 1.0 and self.efficiency == 1.0 and not self.linear

    @property
    def travel_per_rev(self) -> float:
        """Linear travel per output (screw or pulley) revolution ℓ [m]: the lead or 2π·r; 0 if rotary."""
        return self.lead if self.lead > 0.0 else 2.0 * math.pi * self.pulley_radius

    @property
    def k(self) -> float:
        """Output displacement per motor radian: 1/N [rad/rad] (rotary) or ℓ/(2π·N) [m/rad] (linear)."""
        per_rad = self.travel_per_rev / (2.0 * math.pi) if self.linear else 1.0
        return per_rad / self.ratio


def inertia_to_motor(J_or_m: float, tr: Transmission) -> float:
    """Reflect the output's inertia [kg·m²] (rotary) or mass [kg] (linear) onto the rotor: X·k²/η [kg·m²]."""
    return J_or_m * tr.k**2 / tr.efficiency


def friction_to_motor(c: float, tr: Transmission) -> float:
    """Reflect viscous friction [N·m·s/rad] or [N·s/m] onto the rotor: c·k²/η [N·m·s/rad]."""
    return c * tr.k**2 / tr.efficiency


def torque_to_motor(load: float, tr: Transmission) -> float:
    """Reflect an output torque [N·m] or force [N] onto the rotor: Γ·k/η [N·m]."""
    return load * tr.k / tr.efficiency


def position_to_motor(x: float, tr: Transmission) -> float:
    """Output angle [rad] or travel [m] → rotor angle [rad]: x/k (also speeds, per second)."""
    return x / tr.k


def position_to_output(theta_r: float, tr: Transmission) -> float:
    """Rotor angle [rad] → output angle [rad] or travel [m]: k·θ_r (also speeds); inverse of position_to_motor."""
    return theta_r * tr.k


def inertia_to_output(J_L: float, tr: Transmission) -> float:
    """Rotor-side load inertia [kg·m²] → output inertia [kg·m²] or mass [kg]: inverse of inertia_to_motor."""
    return J_L * tr.efficiency / tr.k**2


def torque_to_output(Gamma: float, tr: Transmission) -> float:
    """Rotor torque [N·m] → output torque [N·m] or force [N] delivered to the load: Γ·η/k."""
    return Gamma * tr.efficiency / tr.k


__all__ = ["Transmission", "friction_to_motor", "inertia_to_motor", "inertia_to_output", "position_to_motor",
           "position_to_output", "torque_to_motor", "torque_to_output"]
