"""Drive-log import: a CSV of sampled signals with units → SI arrays, validated.

Accepted layouts (comma, semicolon or tab separated; ``#`` lines are comments):

* units in the header names: ``t [ms], theta_r [rad], omega_r [rpm], i_q [A], …``;
* a header row of names followed by a row of units (this tool's older ``simulate --csv``);
* unit suffixes in the names (``t_s``, ``omega_r_rad_s``, ``i_q_A``), with a ``controller``
  column naming each row's run (the page's CSV export);
* any header plus a mapping (YAML ``column: signal [unit]``, read by :mod:`app.io.presets`).

Signals: t, theta_r, omega_r, i_d, i_q, u_d, u_q, or phase currents i_a, i_b (i_c) and phase
voltages u_a, u_b (u_c) with theta_e (or theta_r and the pole pairs) instead of the dq ones
(a missing third phase is −(a + b): no neutral current). Columns of this tool's own export
that are not signals (alpha, S, E_friction …) are ignored; a file with several runs
(``fdsmc.theta_r``, ``theta_r (conventional)`` …) needs ``run`` to pick one. Nothing is
filled in or resampled silently: NaNs, gaps, unsorted time or a unit that is not allowed for
the signal are refused with the line and column named.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pmsm_commissioning.app.io import units
from pmsm_commissioning.app.io.bounded import ReadError, read_bounded, too_large
from pmsm_commissioning.app.io.log_rows import Rows, RowsError, check_widths, split_rows
from pmsm_commissioning.app.io.numbers import FORMS, NumberFormatError, parse_number, shorten, shown
from pmsm_commissioning.app.io.user_text import escaped
from pmsm_commissioning.control.fdsmc.identification import Identification, identify
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.trace import CHANNELS

#: Largest log file accepted [bytes]; checked before reading
MAX_BYTES = 50 * 1024 * 1024
#: Most data rows accepted [-]; counted before any row is kept (:func:`app.io.log_rows.split_rows`).
MAX_ROWS = 2_000_000
#: Cell texts that mark a gap (refused by :func:`_check_finite`, which counts them).
_GAPS = frozenset({"", "nan", "inf", "infinity"})
#: Shortest sample interval accepted [s] (1 GHz).
MIN_SAMPLE_S = 1e-9
#: Fewest data rows accepted [-].
MIN_ROWS = 20
#: Largest sample interval accepted, relative to the median one [-] (larger is a gap).
GAP_RATIO = 1.5
RUNS = ("fdsmc", "conventional")

#: signal → physical kind
SIGNALS = {"t": "time", "theta_r": "angle", "theta_e": "angle", "omega_r": "speed", "i_d": "current",
           "i_q": "current", "u_d": "voltage", "u_q": "voltage", "i_a": "current", "i_b": "current",
           "i_c": "current", "u_a": "voltage", "u_b": "voltage", "u_c": "voltage"}
_ALIASES = {"time": "t", "theta": "theta_r", "omega": "omega_r", "id": "i_d", "iq": "i_q", "ud": "u_d",
            "uq": "u_q", "v_d": "u_d", "v_q": "u_q", "ia": "i_a", "ib": "i_b", "ic": "i_c", "ua": "u_a",
            "ub": "u_b", "uc": "u_c", "v_a": "u_a", "v_b": "u_b", "v_c": "u_c"}
#: kind → unit → factor to SI
UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": units.ms_to_s(1.0), "us": 1e-6, "µs": 1e-6},
    "angle": {"rad": 1.0, "deg": units.deg_to_rad(1.0), "rev": units.rev_to_rad(1.0)},
    "speed": {"rad/s": 1.0, "rpm": units.rpm_to_rad_s(1.0), "rev/s": units.rev_to_rad(1.0),
              "deg/s": units.deg_to_rad(1.0)},
    "current": {"A": 1.0, "mA": 1e-3},
    "voltage": {"V": 1.0, "mV": 1e-3},
}
#: Columns of this tool's own export that are not log signals (ignored).
TOOL_COLUMNS = frozenset(CHANNELS) - frozenset(SIGNALS)
#: Unit suffixes of names such as ``omega_r_rad_s`` (the page's CSV export).
_SUFFIX_UNITS = {"s": "s", "ms": "ms", "us": "us", "rad": "rad", "deg": "deg", "rev": "rev", "rad_s": "rad/s",
                 "rpm": "rpm", "A": "A", "mA": "mA", "V": "V", "mV": "mV"}
#: Header names of a row-label column holding the run of each row.
_RUN_LABELS = ("controller", "run")
_UNIT_RE = re.compile(r"^(.*?)\s*\[\s*([^\]]*?)\s*\]\s*$")
_RUN_RE = re.compile(r"(?:^|[\s._:(\[])(" + "|".join(RUNS) + r")(?:$|[\s._:)\]])")
_SEP_RE = re.compile(r"[\s._:]*(\(\s*\)|\[\s*\])|^[\s._:]+|[\s._:]+(?=\s*\[)|[\s._:]+$")


class LogError(ValueError):
    """A log that cannot be imported; the message names the line, column, value and rule."""


@dataclass(frozen=True)
class DriveLog:
    """An imported log in SI units.

    Attributes
    ----------
    name : str  File name.
    signals : dict  signal → samples [SI]; always ``t`` [s].
    columns : dict  signal → the column it came from (or how it was derived).
    T_s : float  Median sample interval [s].
    notes : tuple of str  What was derived or ignored.
    """

    name: str
    signals: dict[str, np.ndarray]
    columns: dict[str, str]
    T_s: float
    notes: tuple[str, ...]


@dataclass(frozen=True)
class _Column:
    index: int
    header: str
    signal: str
    unit: str | None
    run: str | None


def _split_unit(head: str) -> tuple[str, str | None]:
    """(name, unit) of ``name [unit]``, or of ``name_unit`` for a known signal or tool column."""
    m = _UNIT_RE.match(head)
    if m:
        return m.group(1).strip(), m.group(2)
    name = head.strip()
    for known in sorted([*SIGNALS, *TOOL_COLUMNS], key=len, reverse=True):
        rest = name[len(known) + 1:]
        if name.startswith(known + "_") and (rest in _SUFFIX_UNITS or known in TOOL_COLUMNS):
            return known, _SUFFIX_UNITS.get(rest, rest)
    return name, None


def _split_run(head: str) -> tuple[str, str | None]:
    """Split a header name into (header without the run, run).

    E.g. ``fdsmc.theta_r [rad]``, ``i_q [A] (conventional)``, ``omega_r_fdsmc [rad/s]``.
    """
    m = _RUN_RE.search(head)
    if not m:
        return head.strip(), None
    return _SEP_RE.sub("", head[: m.start(1)] + head[m.end(1):]).strip(), m.group(1)


def _signal_name(name: str) -> str:
    """Return the signal a header name stands for (aliases such as ``iq``, ``ω_r`` resolved)."""
    key = name.strip().lower().replace("ω", "omega").replace("θ", "theta")
    key = _ALIASES.get(key, key)
    return key if key in SIGNALS else name.strip()


def _is_number(text: str) -> bool:
    try:
        parse_number(text, "cell")
    except NumberFormatError:
        return False
    return True


def _columns_from_header(header: list[str], unit_row: list[str] | None) -> list[_Column]:
    cols = []
    for i, head in enumerate(header):
        if head.strip().lower() in _RUN_LABELS:
            continue
        bare, run = _split_run(head)
        name, unit = _split_unit(bare)
        if unit is None and unit_row is not None:
            unit = unit_row[i].strip() or None
        cols.append(_Column(i, head.strip(), _signal_name(name), unit, run))
    return cols


def _columns_from_mapping(header: list[str], mapping: dict[str, str]) -> list[_Column]:
    by_name = {h.strip(): i for i, h in enumerate(header)}
    by_name.update({_split_unit(h)[0]: i for i, h in enumerate(header)})
    cols = []
    for column, target in mapping.items():
        if column not in by_name:
            raise LogError(f"mapping: column {column!r} is not in the log's header "
                           f"({', '.join(repr(h.strip()) for h in header)})")
        name, unit = _split_unit(target)
        signal = _signal_name(name)
        if signal not in SIGNALS:
            raise LogError(f"mapping: {column!r} maps to {name!r}: allowed signals {', '.join(SIGNALS)}")
        cols.append(_Column(by_name[column], column, signal, unit, None))
    return cols


def _select(cols: list[_Column], run: str | None, mapped: bool) -> tuple[list[_Column], list[str]]:
    """Return the signal columns of the chosen run; unknown columns are an error unless mapped."""
    unknown = [c.header for c in cols if c.signal not in SIGNALS and c.signal not in TOOL_COLUMNS]
    if unknown and not mapped:
        raise LogError(f"unknown column(s) {', '.join(map(repr, unknown))}: allowed signals "
                       f"{', '.join(SIGNALS)} (with a unit, e.g. 'i_q [A]'), or give a mapping file "
                       "with lines 'column: signal [unit]'")
    runs = sorted({c.run for c in cols if c.run is not None})
    if run is not None and runs and run not in runs:
        raise LogError(f"run = {run!r} is not in the file: allowed {', '.join(runs)}")
    if run is None and len(runs) > 1:
        raise LogError(f"the file holds the runs {', '.join(runs)}: choose one (--run {'|'.join(runs)})")
    chosen = run if run is not None else (runs[0] if runs else None)
    used = [c for c in cols if c.signal in SIGNALS and c.run in (None, chosen)]
    notes = [f"ignored column(s) {', '.join(c.header for c in cols if c.signal in TOOL_COLUMNS)}"] if any(
        c.signal in TOOL_COLUMNS for c in cols) else []
    seen: dict[str, str] = {}
    for c in used:
        if c.signal in seen:
            raise LogError(f"columns {seen[c.signal]!r} and {c.header!r} are both {c.signal}: keep one")
        seen[c.signal] = c.header
        allowed = UNITS[SIGNALS[c.signal]]
        if c.unit is None:
            raise LogError(f"column {c.header!r} has no unit: write it in the header, e.g. "
                           f"'{c.signal} [{next(iter(allowed))}]' (allowed {', '.join(allowed)})")
        if c.unit not in allowed:
            raise LogError(f"column {c.header!r}: unit {c.unit!r} is not allowed for {c.signal}: "
                           f"allowed {', '.join(allowed)}")
    if "t" not in seen:
        raise LogError("the log has no time column: name one 't [s]' (or ms, us)")
    if len(seen) < 2:
        raise LogError("the log has a time column but no signal: allowed " + ", ".join(list(SIGNALS)[1:]))
    return used, notes


def _parse_rows(rows: Rows, delim: str, width: int, used: list[_Column]) -> np.ndarray:
    """Read the used columns as floats: numpy's fast reader, or a row-by-row scan naming the bad cell."""
    if check_widths(rows, delim, width):  # a short row is refused here, before any is parsed
        try:
            return np.loadtxt(rows.lines(), delimiter=delim, usecols=[c.index for c in used], ndmin=2,
                              dtype=float, comments=None)  # "#" lines are gone already; a "#" in a cell is no number
        except ValueError:
            pass  # an empty or non-numeric cell: the scan names it
    return _scan_rows(rows, delim, width, used)


def _scan_rows(rows: Rows, delim: str, width: int, used: list[_Column]) -> np.ndarray:
    data, r, line_no = np.empty((len(rows), len(used))), 0, rows.line_no
    try:
        for r, row in enumerate(csv.reader(rows.lines(), delimiter=delim)):
            if len(row) != width:
                raise LogError(f"line {line_no[r]}: {len(row)} fields, the header has {width}")
            for j, c in enumerate(used):
                cell = row[c.index].strip()
                try:  # the one number grammar (ASCII digits only); gaps and NaN/inf: counted by _check_finite
                    data[r, j] = math.nan if cell.lower().lstrip("+-") in _GAPS else parse_number(cell, "cell")
                except NumberFormatError:
                    raise LogError(f"line {line_no[r]}, column {shown(c.header)}: {shown(cell)} is not a number: "
                                   f"allowed {FORMS}") from None
    except csv.Error as exc:  # e.g. an unterminated quote swallowing the rest of the file
        raise LogError(f"line {line_no[min(r, len(line_no) - 1)] if len(line_no) else 1}: not valid CSV "
                       f"({shorten(exc, 80)}): allowed one row per line, quotes closed") from None
    return data


def _check_finite(data: np.ndarray, used: list[_Column], line_no: np.ndarray) -> None:
    for j, c in enumerate(used):
        bad = ~np.isfinite(data[:, j])
        if bad.any():
            first = int(np.argmax(bad))
            raise LogError(f"column {c.header!r}: {int(bad.sum())} empty/NaN/inf value(s), first at line "
                           f"{line_no[first]}: gaps are not filled in — repair or cut those rows")


def _check_time(t: np.ndarray, line_no: np.ndarray, header: str) -> float:
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.argmax(dt <= 0))
        raise LogError(f"column {header!r}: time does not increase at line {line_no[k + 1]} "
                       f"({t[k + 1]:g} after {t[k]:g}): the rows must be sorted by time, without repeats")
    T_s = float(np.median(dt))
    if not T_s >= MIN_SAMPLE_S:
        raise LogError(f"column {shown(header)}: sample interval {T_s:.3g} s: allowed ≥ {MIN_SAMPLE_S:g} s "
                       "(is the time column's unit right?)")
    k = int(np.argmax(dt))
    if dt[k] > GAP_RATIO * T_s:
        raise LogError(f"column {header!r}: gap of {dt[k]:.6g} s before line {line_no[k + 1]} (sample period "
                       f"{T_s:.6g} s): allowed ≤ {GAP_RATIO:g}× the period; the log must be evenly sampled")
    return T_s


def _park(a: np.ndarray, b: np.ndarray, c: np.ndarray, th_e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude-invariant Park transform (as eq. (58) in [1]): phase quantities → (d, q)."""
    s = 2.0 * np.pi / 3.0
    d = 2.0 / 3.0 * (a * np.cos(th_e) + b * np.cos(th_e - s) + c * np.cos(th_e + s))
    q = -2.0 / 3.0 * (a * np.sin(th_e) + b * np.sin(th_e - s) + c * np.sin(th_e + s))
    return d, q


def _dq_from_phases(sig: dict[str, np.ndarray], cols: dict[str, str], p: int | None) -> list[str]:
    """i_d, i_q (u_d, u_q) from phase currents (voltages) and θ_e = p·θ_r when the log has no dq."""
    notes = []
    for x in ("i", "u"):
        a, b, c = f"{x}_a", f"{x}_b", f"{x}_c"
        if f"{x}_d" in sig or a not in sig or b not in sig:
            continue
        if "theta_e" in sig:
            th_e = sig["theta_e"]
        elif "theta_r" in sig and p is not None:
            th_e = p * sig["theta_r"]
        else:
            raise LogError(f"phase signals {a}, {b} need theta_e (or theta_r and the pole pairs) for {x}_d, {x}_q")
        sig[f"{x}_d"], sig[f"{x}_q"] = _park(sig[a], sig[b], sig.get(c, -sig[a] - sig[b]), th_e)
        cols[f"{x}_d"] = cols[f"{x}_q"] = f"Park transform of {a}, {b}" + (f", {c}" if c in sig else "")
        notes.append(f"{x}_d, {x}_q computed from the phase {'currents' if x == 'i' else 'voltages'} "
                     "(amplitude-invariant Park transform)")
    return notes


def _check_speed_units(sig: dict[str, np.ndarray], cols: dict[str, str]) -> None:
    """ω_r and θ_r must agree: ∫|ω_r|dt within 25 % of the travelled angle (catches rpm vs rad/s)."""
    if "omega_r" not in sig or "theta_r" not in sig:
        return
    travelled = float(np.sum(np.abs(np.diff(sig["theta_r"]))))
    w = sig["omega_r"]
    integral = float(np.sum(0.5 * np.abs(w[1:] + w[:-1]) * np.diff(sig["t"])))
    if travelled > 0.5 and not 0.8 < integral / travelled < 1.25:
        raise LogError(f"columns {cols['omega_r']!r} and {cols['theta_r']!r} disagree: ∫|ω_r|dt = "
                       f"{integral:.4g} rad but θ_r travels {travelled:.4g} rad (ratio {integral / travelled:.3g}): "
                       "check their units (rpm vs rad/s, deg vs rad)")


#: Most different run labels a row-label column may hold [-].
MAX_RUN_LABELS = 16


def _rows_of_run(rows: Rows, delim: str, header: list[str], run: str | None) -> tuple[Rows, str | None]:
    """Only the rows of one run when a column labels each row's run (the page's CSV export)."""
    idx = next((i for i, h in enumerate(header) if h.strip().lower() in _RUN_LABELS), None)
    if idx is None:
        return rows, run
    found: set[str] = set()
    for r in csv.reader(rows.lines(), delimiter=delim):
        found.add(r[idx].strip() if len(r) > idx else "")
        if len(found) > MAX_RUN_LABELS:
            raise LogError(f"column {shown(header[idx])} holds more than {MAX_RUN_LABELS} different runs: "
                           f"allowed ≤ {MAX_RUN_LABELS} (e.g. {', '.join(RUNS)})")
    if run is None and len(found) > 1:
        raise LogError(f"the file holds the runs {', '.join(sorted(found))}: choose one "
                       f"(--run {'|'.join(sorted(found))})")
    chosen = run if run is not None else min(found, default="")
    if chosen not in found:
        raise LogError(f"run = {chosen!r} is not in the file: allowed {', '.join(sorted(found))}")
    keep = np.fromiter(((r[idx].strip() if len(r) > idx else "") == chosen
                        for r in csv.reader(rows.lines(), delimiter=delim)), dtype=bool, count=len(rows))
    return rows.take(keep), None


def parse_log(text: str, name: str = "<log>", *, mapping: dict[str, str] | None = None, run: str | None = None,
              p: int | None = None) -> DriveLog:
    """Validate and convert a log's text (see the module docstring); raises :class:`LogError`."""
    try:
        return _parse_log(text, name, mapping=mapping, run=run, p=p)
    except csv.Error as exc:  # an unterminated quote swallowing the rest of the file, a NUL byte …
        raise LogError(f"{shown(name)} is not valid CSV ({shorten(exc, 80)}): allowed one row per line, "
                       "every quote closed") from None


def _parse_log(text: str, name: str, *, mapping: dict[str, str] | None, run: str | None,
               p: int | None) -> DriveLog:
    if len(text) > MAX_BYTES:
        raise LogError(too_large(escaped(name), len(text), MAX_BYTES))
    try:
        head, _, rows = split_rows(text, MAX_ROWS)
    except RowsError as exc:
        raise LogError(f"{shown(name)}: {exc}") from None
    delim = max((",", ";", "\t"), key=head.count)
    header = next(csv.reader([head], delimiter=delim))
    unit_row = None
    if len(rows):
        first = next(csv.reader([rows.line(0)], delimiter=delim))
        if len(first) == len(header) and not any(_is_number(x) for x in first if x.strip()):
            unit_row, rows = first, rows.take(slice(1, None))
    rows, run = _rows_of_run(rows, delim, header, run)
    cols = _columns_from_mapping(header, mapping) if mapping else _columns_from_header(header, unit_row)
    used, notes = _select(cols, run, mapping is not None)
    if len(rows) < MIN_ROWS:
        raise LogError(f"{name} has {len(rows)} data rows: allowed ≥ {MIN_ROWS}")
    try:
        data = _parse_rows(rows, delim, len(header), used)
    except RowsError as exc:
        raise LogError(str(exc)) from None
    line_no = rows.line_no
    _check_finite(data, used, line_no)
    sig = {c.signal: data[:, j] * UNITS[SIGNALS[c.signal]][c.unit] for j, c in enumerate(used)}  # type: ignore[index]
    src = {c.signal: c.header for c in used}
    T_s = _check_time(sig["t"], line_no, src["t"])
    sig["t"] = sig["t"] - sig["t"][0]
    notes += _dq_from_phases(sig, src, p)
    _check_speed_units(sig, src)
    return DriveLog(name, sig, src, T_s, tuple(notes))


def read_bytes(data: bytes, name: str, **options: object) -> DriveLog:
    """Import an uploaded log (size checked before decoding)."""
    if len(data) > MAX_BYTES:
        raise LogError(too_large(escaped(name), len(data), MAX_BYTES))
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise LogError(f"{name} is not UTF-8 text (byte {exc.start}): export the log as CSV") from None
    return parse_log(text, name, **options)  # type: ignore[arg-type]


def read_log(path: str | Path, **options: object) -> DriveLog:
    """Import a log file (size checked before reading); options as :func:`parse_log`."""
    path = Path(path)
    try:  # a sparse, /proc or device file: never more than MAX_BYTES read
        data = read_bounded(path, MAX_BYTES, escaped(path.name))
    except ReadError as exc:
        raise LogError(str(exc)) from None
    return read_bytes(data, path.name, **options)


def run_identification(log: DriveLog, params: DriveParams) -> Identification:
    """Identification with the preset's Ψ_PM, L_d, L_q as the fall-back for Γ_em of eq. (5)."""
    m = params.motor
    return identify(log.signals, m.p, psi_pm_prior=m.psi_pm, L_d_prior=m.L_d, L_q_prior=m.L_q)
