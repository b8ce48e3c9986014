"""C99 text of the generated controller's source ``fdsmc_controller.c`` (header: :mod:`app.exports.firmware.template`).

:data:`SOURCE` mirrors the controller of the simulator's digital mode, :func:`sim.fdsmc.kernel.step_sample`:
sensor readings in, outer law (eqs. (41)–(46) of [1] or the comparator (62)), FDC voltages (eqs. (7), (9),
(14)), the hard predictive current limit and the voltage limit of :mod:`control.fdsmc.inverter`
(:data:`LIMIT_CODE`), the computation delay, then the observer update — the same formulas in the same
order. The double build is that arithmetic operation for operation; the float build keeps the observer
scaled, θ̂ − θ_dem in counts and uses reciprocals. ``$design`` is filled by
:func:`app.exports.firmware.design.design_initializer`. The outer law is the module's: the FDSMC's
(``$set_move`` = :data:`FDSMC_MOVE`, ``$outer_call`` = ``sliding_mode``, no ``$outer_law``/``$law_init``)
or the tracked optimum's (:mod:`app.exports.firmware.optimum`).

The C texts are files beside this module (``c/*.c.in``), read once, so that they read as C.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from pathlib import Path
from string import Template

C_DIR = Path(__file__).resolve().parent / "c"


def c_text(name: str) -> str:
    """Return the text of the C file ``name`` beside this module."""
    return (C_DIR / name).read_text(encoding="utf-8")


#: The controller's source, ``$``-placeholders filled by :mod:`app.exports.firmware.module`.
SOURCE = Template(c_text("fdsmc_controller.c.in"))
#: The inverter limits of :func:`control.fdsmc.inverter.limit_voltage`, mirrored.
LIMIT_CODE = c_text("limit_voltage.c.in")
#: fdsmc_set_move of the FDSMC module: the profile of eqs. (59)-(60) computed on the target.
FDSMC_MOVE = c_text("fdsmc_set_move.c.in")
