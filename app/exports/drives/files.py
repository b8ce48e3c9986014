"""The stock-drive export formats of the one export model: ODrive, moteus, VESC and the setpoint table.

:func:`drive_file` writes the format from the drive's tuned SI settings
(:func:`app.exports.drives.stock.stock_settings`), reads the draft back with the strict parser and simulates
the drive's own loops from it (:func:`app.exports.drives.stock_route.file_verdict`): **that** verdict gates
the export (refused unless ``force`` when a check fails) and heads the file, next to the energies of
the FDSMC and the tracked optimum (:func:`app.exports.provenance.header_lines`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from pmsm_commissioning.app.exports.drives.moteus import moteus_text
from pmsm_commissioning.app.exports.drives.odrive import odrive_json
from pmsm_commissioning.app.exports.drives.setpoints import setpoints_csv
from pmsm_commissioning.app.exports.drives.stock import StockSettings, stock_settings, with_stock_runs
from pmsm_commissioning.app.exports.drives.stock_route import ROUTE_NAMES, file_verdict
from pmsm_commissioning.app.exports.drives.vesc import vesc_xml
from pmsm_commissioning.app.exports.provenance import ExportRefusedError, check_text, header_lines
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.fdsmc.design import Constraint
from pmsm_commissioning.sim.fdsmc.engine import Comparison

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


def _write(fmt: str, s: StockSettings, header: list[str], options: ExportOptions) -> str:
    if fmt == "odrive":
        return odrive_json(s, header)
    if fmt == "moteus":
        return moteus_text(s, header)
    if fmt == "vesc":
        return vesc_xml(s, header)
    return setpoints_csv(s, header, options.angle_unit, options.cycle_s)


def drive_file(fmt: str, cmp: Comparison, failed: Sequence[Constraint], stem: str,
               options: ExportOptions) -> tuple[str, str]:
    """Return (file name, text) of stock-drive format ``fmt`` for the case ``cmp``.

    ``failed`` are the FDSMC design's failed checks (named in the header, not the gate).

    Raises
    ------
    ParameterError
        For an infeasible manoeuvre (there is no move to write) or a bad setpoint option;
        :class:`~app.exports.provenance.ExportRefusedError` naming the stock route's failed checks
        unless ``options.force``.
    """
    if cmp.fdsmc is None:
        raise ParameterError(f"nothing to export as {fmt}: manoeuvre.T_m = {cmp.derived.params.manoeuvre.T_m:g} s "
                             "is infeasible, there is no move")
    full = with_stock_runs(cmp)
    s = stock_settings(full, fmt)
    p = full.derived.params
    verdict = file_verdict(fmt, _write(fmt, s, header_lines(full, failed), options), p, full.derived)
    if verdict.failed and not options.force:
        names = "; ".join(check_text(c) for c in verdict.failed)
        raise ExportRefusedError(f"export --format {fmt} refused: the stock route of {p.name!r} "
                                 f"({ROUTE_NAMES[fmt]}, simulated from the file) is not clean — {names}. "
                                 "Lengthen T_m or widen the pass criteria, or export with --force to write it "
                                 "with these warnings inside")
    header = header_lines(full, failed, (ROUTE_NAMES[fmt], verdict.run, verdict.failed))
    return stem + DRIVE_FORMATS[fmt], _write(fmt, s, header, options)
