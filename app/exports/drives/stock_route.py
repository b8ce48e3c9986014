"""The stock route of a written drive file: read back by the strict parser, simulated, judged, gated.

:func:`file_loop` turns a drive file's text into the :class:`~sim.stock.route.StockLoop` its drive
runs (ODrive fw 0.5.x, moteus, VESC or a setpoint table), :func:`file_verdict` simulates that loop on
the case's plant, sensors and limits and returns its run and violated checks: the verdict a drive
file's header carries and its export gate uses. What runs is what the drive loads.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmsm_commissioning.app.exports.drives.moteus import moteus_loop, parse_moteus
from pmsm_commissioning.app.exports.drives.odrive import odrive_loop, parse_odrive
from pmsm_commissioning.app.exports.drives.setpoints import setpoints_loop
from pmsm_commissioning.app.exports.drives.vesc import parse_vesc, vesc_loop
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.checks import Constraint, run_checks
from pmsm_commissioning.sim.fdsmc.engine import RunResult
from pmsm_commissioning.sim.stock.route import StockLoop, simulate_stock

#: The firmware each drive format's route models, as the header names it.
ROUTE_NAMES = {"odrive": "ODrive fw 0.5.x loops at 8 kHz", "moteus": "moteus PID, current PI and PLL",
               "vesc": "VESC current loop with the cascade below", "setpoints": "a P–PI cascade drive on this table"}


@dataclass(frozen=True)
class FileVerdict:
    """The stock route simulated from a drive file's own numbers.

    Attributes
    ----------
    fmt : str                  The drive format.
    loop : StockLoop           What the file sets, read back.
    run : RunResult            The simulated run.
    failed : tuple             Its violated checks (empty: clean).
    """

    fmt: str
    loop: StockLoop
    run: RunResult
    failed: tuple[Constraint, ...]

    @property
    def clean(self) -> bool:
        """True when the route passes every check."""
        return not self.failed


def file_loop(fmt: str, text: str, params: DriveParams) -> StockLoop:
    """Return the loops the drive of format ``fmt`` runs from the file ``text`` (strict parsers)."""
    if fmt == "odrive":
        return odrive_loop(parse_odrive(text), params)
    if fmt == "moteus":
        return moteus_loop(parse_moteus(text), params)
    if fmt == "vesc":
        return vesc_loop(parse_vesc(text), params)
    return setpoints_loop(text)


def file_verdict(fmt: str, text: str, params: DriveParams, derived: Derived | None = None) -> FileVerdict:
    """Simulate the file's own stock route on the case ``params`` and return its verdict."""
    loop = file_loop(fmt, text, params)
    run = simulate_stock(params, loop, derived)
    return FileVerdict(fmt, loop, run, tuple(c for c in run_checks(params, run) if c.violated))
