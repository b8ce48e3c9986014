"""The stock-drive export formats of the one export model: ODrive, moteus, VESC and the setpoint table.

:func:`drive_file` simulates the stock route (and the tracked optimum) when the case lacks them, so
that every file's header carries the energy it promises next to FDSMC and the optimum
(:func:`app.exports.provenance.header_lines`), then writes the format from the one set of SI
settings (:func:`app.exports.stock.stock_settings`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from app.exports.moteus import moteus_text
from app.exports.odrive import odrive_json
from app.exports.provenance import header_lines
from app.exports.setpoints import setpoints_csv
from app.exports.stock import stock_settings, with_stock_runs
from app.exports.vesc import vesc_xml
from control.common.checks import ParameterError
from sim.fdsmc.design import Constraint
from sim.fdsmc.engine import Comparison

#: Stock-drive format → file-name suffix (after the case's stem).
DRIVE_FORMATS = {"odrive": ".odrive.json", "moteus": ".moteus.cfg", "vesc": ".vesc.xml",
                 "setpoints": ".setpoints.csv"}


@dataclass(frozen=True)
class ExportOptions:
    """Options of an export.

    Attributes
    ----------
    force : bool              Write a design that is not clean, with the failed checks inside.
    angle_unit : str          Angle unit of the setpoint table: rad, deg or rev.
    cycle_s : float | None    Cycle time of the setpoint table [s]; None: the drive's 1/f_s.
    controller : str          Outer law of the C module: ``"fdsmc"`` or ``"optimum"`` (the tracked optimum).
    """

    force: bool = False
    angle_unit: str = "rad"
    cycle_s: float | None = None
    controller: str = "fdsmc"


def drive_file(fmt: str, cmp: Comparison, failed: Sequence[Constraint], stem: str,
               options: ExportOptions) -> tuple[str, str]:
    """Return (file name, text) of stock-drive format ``fmt`` for the case ``cmp``.

    Raises
    ------
    ParameterError
        For an infeasible manoeuvre (there is no move to write) or a bad setpoint option.
    """
    if cmp.fdsmc is None:
        raise ParameterError(f"nothing to export as {fmt}: manoeuvre.T_m = {cmp.derived.params.manoeuvre.T_m:g} s "
                             "is infeasible, there is no move")
    full = with_stock_runs(cmp)
    s = stock_settings(full)
    header = header_lines(full, failed)
    name = stem + DRIVE_FORMATS[fmt]
    if fmt == "odrive":
        return name, odrive_json(s, header)
    if fmt == "moteus":
        return name, moteus_text(s, header)
    if fmt == "vesc":
        return name, vesc_xml(s, header)
    return name, setpoints_csv(s, header, options.angle_unit, options.cycle_s)
