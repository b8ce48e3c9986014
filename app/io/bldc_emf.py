"""Reading a measured back-EMF period (CSV or YAML) for the BLDC mode.

Accepted forms (one electrical period, angles in electrical degrees):

* CSV (``,``, ``;``, tab or spaces): rows ``theta_e_deg, phi_a[, phi_b, phi_c]``; an optional
  first header row (no number in it) and ``#`` comment lines are skipped;
* YAML: a list of numbers (phase a on a uniform grid starting at 0°), a list of rows as in
  the CSV, or a mapping with ``theta_e_deg`` and ``phi_a`` (and optionally ``phi_b``, ``phi_c``).

Values are Φ'_r = e/ω_e [Wb = V·s/rad]. A waveform recorded in volts at a known speed can be
given with ``n_rpm`` and ``n_pp``: Φ' = e/(n_pp·n_rpm·2π/60). The checks (period, NaN,
periodicity, 120° shifts) are those of :func:`sim.bldc.emf.resample_measured`; every problem
raises :class:`~control.common.checks.ParameterError` naming row, value and what is allowed.
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

import numpy as np

from pmsm_commissioning.app.io.numbers import NumberFormatError, parse_number
from pmsm_commissioning.app.io.presets import loads_raw
from pmsm_commissioning.app.io.units import rpm_to_rad_s
from pmsm_commissioning.control.bldc.params import EMF_SAMPLES_MAX, BldcParams
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.sim.bldc.emf import MeasuredEmf, resample_measured

STORE_SAMPLES = 360  # samples per period kept in a preset (1° electrical)
MAX_BYTES = 512 * 1024
#: Most YAML nodes of a waveform file: 4 columns and a row list per sample, and a few keys [-].
EMF_YAML_NODES = 6 * EMF_SAMPLES_MAX
_SPLIT = re.compile(r"[,;\t ]+")


def _number(text: str, row: int, col: int) -> float:
    try:
        return parse_number(text, "cell")
    except NumberFormatError:
        raise ParameterError(
            f"emf waveform row {row}, column {col}: {text!r} is not a number: allowed numeric rows "
            "θ_e [deg], Φ'_a[, Φ'_b, Φ'_c] [Wb] (one optional header row)") from None


def parse_csv(text: str) -> tuple[np.ndarray, np.ndarray]:
    """CSV text → (θ_e [deg], values (rows, 1 or 3) [Wb as given]); rejects non-numeric rows."""
    if len(text.encode("utf-8", "replace")) > MAX_BYTES:
        raise ParameterError(f"emf waveform file is too large: allowed ≤ {MAX_BYTES // 1024} KiB")
    rows: list[list[float]] = []
    for k, line in enumerate(text.splitlines(), start=1):
        cells = [c for c in _SPLIT.split(line.strip()) if c]
        if not cells or cells[0].startswith("#"):
            continue
        if not rows and k == _first_content_line(text) and not any(_is_number(c) for c in cells):
            continue  # header
        rows.append([_number(c, k, j + 1) for j, c in enumerate(cells)])
    return _to_arrays(rows)


def _first_content_line(text: str) -> int:
    for k, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if s and not s.startswith("#"):
            return k
    return 0


def _is_number(text: str) -> bool:
    try:
        parse_number(text, "cell")
    except NumberFormatError:
        return False
    return True


def _to_arrays(rows: list[list[float]]) -> tuple[np.ndarray, np.ndarray]:
    if not rows:
        raise ParameterError("emf waveform has no numeric rows: allowed rows θ_e [deg], Φ'_a[, Φ'_b, Φ'_c]")
    widths = {len(r) for r in rows}
    if len(widths) != 1 or widths.pop() not in (2, 4):
        raise ParameterError(f"emf waveform rows have {sorted({len(r) for r in rows})} columns: allowed "
                             "2 (θ_e, Φ'_a) or 4 (θ_e, Φ'_a, Φ'_b, Φ'_c) in every row")
    if len(rows) > EMF_SAMPLES_MAX:
        raise ParameterError(f"emf waveform has {len(rows)} rows: allowed ≤ {EMF_SAMPLES_MAX}")
    data = np.array(rows, dtype=float)
    return data[:, 0], data[:, 1:]


def parse_yaml(text: str) -> tuple[np.ndarray, np.ndarray]:
    """YAML text (module docstring forms) → (θ_e [deg], values (rows, 1 or 3))."""
    data: Any = loads_raw(text, "emf waveform", max_nodes=EMF_YAML_NODES)
    if isinstance(data, dict):
        keys = ["theta_e_deg", "phi_a"] + [k for k in ("phi_b", "phi_c") if k in data]
        if "theta_e_deg" not in data or "phi_a" not in data:
            raise ParameterError("emf waveform mapping needs keys theta_e_deg and phi_a (phi_b, phi_c optional)")
        cols = [data[k] for k in keys]
        if not all(isinstance(c, list) and len(c) == len(cols[0]) for c in cols):
            raise ParameterError("emf waveform columns theta_e_deg, phi_a … must be lists of equal length")
        data = [list(r) for r in zip(*cols, strict=True)]
    if not isinstance(data, list) or not data:
        raise ParameterError("emf waveform YAML must be a list of numbers, a list of rows, or a mapping")
    if all(not isinstance(v, list) for v in data):
        n = len(data)
        data = [[360.0 * k / n, v] for k, v in enumerate(data)]
    rows = [[_yaml_number(v, i + 1, j + 1) for j, v in enumerate(r if isinstance(r, list) else [r])]
            for i, r in enumerate(data)]
    return _to_arrays(rows)


def _yaml_number(v: Any, row: int, col: int) -> float:
    if isinstance(v, str):  # YAML scalars arrive as text: decimal or scientific notation only
        return parse_number(v, f"emf waveform row {row}, column {col}")
    if isinstance(v, bool) or not isinstance(v, int | float):
        raise ParameterError(f"emf waveform row {row}, column {col}: {v!r} is not a number: allowed numbers only")
    return float(v)


def read_measured(text: str, filename: str = "upload.csv", n_pp: int | None = None,
                  n_rpm: float | None = None) -> MeasuredEmf:
    """Parse, check and resample a measured period (CSV unless the name ends in .yaml/.yml).

    Parameters
    ----------
    text : str             File contents.
    filename : str         Name, for the format.
    n_pp : int or None     Pole pairs, with ``n_rpm`` when the values are volts.
    n_rpm : float or None  Speed at which volts were recorded [rpm].
    """
    is_yaml = filename.lower().endswith((".yaml", ".yml"))
    theta, values = parse_yaml(text) if is_yaml else parse_csv(text)
    if n_rpm is not None:
        if not n_pp or not n_rpm or n_rpm <= 0.0:
            raise ParameterError(f"n_rpm = {n_rpm!r} needs a positive speed and the pole pairs: allowed > 0 rpm")
        values = values / (n_pp * rpm_to_rad_s(n_rpm))
    return resample_measured(theta, values, STORE_SAMPLES)


def with_measured(params: BldcParams, measured: MeasuredEmf) -> BldcParams:
    """``params`` with the machine's back-EMF replaced by the measured period."""
    machine = dataclasses.replace(params.machine, emf="measured",
                                  emf_samples=tuple(float(v) for v in measured.samples))
    return dataclasses.replace(params, machine=machine)
