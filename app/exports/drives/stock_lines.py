"""The stock route's settings a drive file carries as comment lines, written and read back strictly.

A VESC mcconf and a setpoint table have no keys for the position/speed loop that runs the move (a
host, a PLC or a VESC app runs it): the file carries them as ``cascade.<key> = <value> <unit>``
comment lines (SI units), which :func:`parse_cascade` reads back — every key once, a finite number,
the unit as written — so that the stock route simulated from the file runs the file's own numbers.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

from pmsm_commissioning.control.common.checks import ParameterError

#: The comment lines' keys and units, in the order written.
CASCADE_UNITS = {"pos_gain": "1/s", "vel_gain": "N*m*s/rad", "vel_integrator_gain": "N*m/rad",
                 "inertia": "kg*m^2", "pll_bandwidth": "rad/s", "loop_rate": "Hz", "vel_limit": "rad/s",
                 "accel_limit": "rad/s^2", "current_bandwidth": "rad/s", "torque_constant": "N*m/A",
                 "current_limit": "A", "resistance": "Ohm", "inductance": "H"}
PREFIX = "cascade."
_LINE = re.compile(r"^cascade\.([a-z_]+) = (\S+) (\S+)$")


def cascade_lines(values: dict[str, float]) -> list[str]:
    """Return one ``cascade.<key> = <value> <unit>`` line per given key (9 significant digits)."""
    return [f"{PREFIX}{k} = {values[k]:.9g} {unit}" for k, unit in CASCADE_UNITS.items() if k in values]


def parse_cascade(comment: Iterable[str], keys: Iterable[str]) -> dict[str, float]:
    """Read the ``cascade.*`` comment lines; every key of ``keys`` must be there once.

    Raises
    ------
    ParameterError
        Naming the line for a malformed one, an unknown key, a wrong unit, a value that is not a finite
        number, a key given twice or one missing.
    """
    out: dict[str, float] = {}
    for line in comment:
        text = line.strip()
        if not text.startswith(PREFIX):
            continue
        m = _LINE.match(text)
        if m is None or m.group(1) not in CASCADE_UNITS:
            raise ParameterError(f"comment line {text[:60]!r} is not allowed: 'cascade.<key> = <number> <unit>' "
                                 f"with a key of {', '.join(CASCADE_UNITS)}")
        key, raw, unit = m.groups()
        if unit != CASCADE_UNITS[key]:
            raise ParameterError(f"cascade.{key} unit = {unit!r} is not allowed: {CASCADE_UNITS[key]}")
        if key in out:
            raise ParameterError(f"cascade.{key} is given more than once: allowed once")
        try:
            value = float(raw) if re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|inf", raw) else math.nan
        except ValueError:
            value = math.nan
        if math.isnan(value):
            raise ParameterError(f"cascade.{key} = {raw!r} is not allowed: a number in {unit}")
        out[key] = value
    missing = [k for k in keys if k not in out]
    if missing:
        raise ParameterError(f"cascade.{missing[0]} is missing: the file must give the stock route's "
                             f"{', '.join(missing)}")
    return out
