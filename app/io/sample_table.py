"""Per-sample tables of the robustness sweep: CSV and Parquet (with the column units).

One row per sampled plant: the drawn plant values (``motor.R_s`` …), then each controller's
metrics (``fdsmc.friction_J`` …). The Parquet file keeps the numbers as 64-bit floats (or
booleans) exactly and states every column's SI unit in its schema metadata (``unit``), and the
run's seed, sample count and spreads in the file's metadata.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

from pmsm_commissioning.app.io.atomic import write_atomic, write_atomic_text
from pmsm_commissioning.sim.studies.robustness import METRICS, RobustnessResult

#: SI unit of each per-sample column, by the key's last part (plant fields and metrics).
UNITS: dict[str, str] = {
    "R_s": "Ω", "L_d": "H", "L_q": "H", "psi_pm": "Wb", "J_r": "kg·m²", "J_L": "kg·m²", "F_v": "N·m·s/rad",
    "Gamma_Le": "N·m", "Gamma_Le_ramp": "N·m/s", "V_0": "V", "P_r": "W", "omega_b": "rad/s",
    "Gamma_max": "N·m", "p": "-", "friction_J": "J", "copper_J": "J", "electrical_in_total_J": "J",
    "torque_peak_Nm": "N·m", "theta_error_abs_at_Tm_rad": "rad", "t_2pct_settle_s": "s", "chatter": "-",
    "infeasible": "-", "saving_friction_pct": "%",
}
#: Per-controller columns after the drawn values.
FLAGS = ("chatter", "infeasible")


def columns(res: RobustnessResult) -> list[tuple[str, str]]:
    """(column name, SI unit) of the table, in order."""
    cols = [(k, UNITS.get(k.split(".")[-1], "")) for k in res.values]
    cols += [(f"{c}.{m}", UNITS[m]) for c in res.controllers for m in (*METRICS, *FLAGS)]
    return cols + ([("fdsmc.saving_friction_pct", "%")] if _saving(res) else [])


def rows(res: RobustnessResult) -> list[list[Any]]:
    """Return the table's values, one list per sample (floats, booleans or None)."""
    out = []
    for i, r in enumerate(res.runs):
        drawn = [float(res.values[k][i]) for k in res.values]
        metrics = [r[c][m] for c in res.controllers for m in (*METRICS, *FLAGS)]
        out.append(drawn + metrics + ([r["fdsmc"].get("saving_friction_pct")] if _saving(res) else []))
    return out


def _saving(res: RobustnessResult) -> bool:
    """Whether the table has the FDSMC's friction saving (both controllers of [1] ran)."""
    return {"fdsmc", "conventional"} <= set(res.controllers)


def write_csv(path: str | Path, res: RobustnessResult) -> None:
    """One row per sample; the header names the columns (units in :data:`UNITS`)."""
    out = io.StringIO(newline="")
    w = csv.writer(out)
    w.writerow([name for name, _ in columns(res)])
    for row in rows(res):
        w.writerow([repr(v) if isinstance(v, float) else v for v in row])
    write_atomic_text(path, out.getvalue())  # a temporary file renamed when complete


#: pip extra that installs pyarrow, the optional Parquet writer (pyproject.toml).
PARQUET_EXTRA = "parquet"


def require_parquet() -> None:
    """Raise ValueError naming the pip extra to install when pyarrow (the Parquet writer) is missing."""
    import importlib.util

    if importlib.util.find_spec("pyarrow") is None:
        raise ValueError(f"--parquet needs pyarrow, which is not installed: allowed after pip install "
                         f"'pmsm-commissioning[{PARQUET_EXTRA}]' (or pip install pyarrow); --csv needs none")


def write_parquet(path: str | Path, res: RobustnessResult, meta: dict[str, Any] | None = None) -> None:
    """Write the table as Parquet.

    Float64/bool columns, each with ``unit`` in its field metadata; ``meta`` (e.g. seed, samples,
    spreads) as JSON in the file's ``robustness`` metadata.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols, data = columns(res), rows(res)
    fields, arrays = [], []
    for j, (name, unit) in enumerate(cols):
        values = [row[j] for row in data]
        kind = pa.bool_() if name.split(".")[-1] in FLAGS else pa.float64()
        fields.append(pa.field(name, kind, nullable=True, metadata={"unit": unit}))
        arrays.append(pa.array(values, type=kind))
    schema = pa.schema(fields, metadata={"robustness": json.dumps(meta or {}, ensure_ascii=False)})
    sink = pa.BufferOutputStream()
    pq.write_table(pa.Table.from_arrays(arrays, schema=schema), sink)
    write_atomic(path, sink.getvalue().to_pybytes())  # a temporary file renamed when complete


def read_parquet(path: str | Path) -> tuple[dict[str, list[Any]], dict[str, str], dict[str, Any]]:
    """(columns → values, columns → unit, the run's metadata) of a file written by write_parquet."""
    import pyarrow.parquet as pq

    table = pq.read_table(str(path))
    units = {f.name: (f.metadata or {}).get(b"unit", b"").decode("utf-8") for f in table.schema}
    meta = json.loads((table.schema.metadata or {}).get(b"robustness", b"{}").decode("utf-8"))
    return table.to_pydict(), units, meta
