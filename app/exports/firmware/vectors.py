"""Golden test vectors and the host test program of the C module, and the export's C file set.

:func:`vector_header` writes the segments of :func:`app.exports.firmware.golden.segments` -- the designed move
and hold, the limits acting, injected faults -- as ``fdsmc_vectors.h``: per sample the inputs the
simulator's controller saw (θ_r as encoder counts, i_d, i_q) and the voltages it applied (u_d, u_q).
``fdsmc_test.c`` (:data:`TEST_PROGRAM`) replays each segment through ``fdsmc_step`` and exits 0 when
every voltage agrees within 1e-6 (double) or 1e-4 (float32) of the peak |u|, every fault is latched
as recorded and ``fdsmc_set_move`` refuses where the segment says (busy, moving). :func:`c_files` is the
whole C export of one simulated case, the verdict gate included.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from pmsm_commissioning.app.exports.firmware.golden import Segment, segments
from pmsm_commissioning.app.exports.firmware.module import (
    CONTINUOUS_REFUSED,
    HEADER_NAME,
    Verdict,
    c_literal,
    controller_files,
    parameter_hash,
    verdict_of,
)
from pmsm_commissioning.app.exports.firmware.source import c_text
from pmsm_commissioning.app.exports.firmware.text import c_string
from pmsm_commissioning.app.exports.firmware.verify import count_params
from pmsm_commissioning.app.io.presets import SCHEMA
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import derive
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc.engine import Comparison

VECTORS_NAME, TEST_NAME = "fdsmc_vectors.h", "fdsmc_test.c"

#: The host test program (``c/fdsmc_test.c.in``, read as C).
TEST_PROGRAM = c_text("fdsmc_test.c.in")


def _real(x: float) -> str:
    return "V_(NAN)" if math.isnan(x) else f"V_({c_literal(x)})"


def _rows(values: np.ndarray) -> str:
    return ",\n".join("    {" + ", ".join(_real(float(v)) for v in row) + "}" for row in values)


def _segment_table(segs: list[Segment]) -> str:
    """Return the ``fdsmc_vec_seg`` initializer: where each segment starts in the arrays, its move and fault."""
    rows, start = [], 0
    for s in segs:
        rows.append(f"    {{{c_string(s.name)}, {start}, {s.theta.size}, {s.theta_dem}, {c_literal(s.T_m)}, "
                    f"{s.fault}u, {s.fault_at}, {s.refuse_at}}}")
        start += s.theta.size
    return ",\n".join(rows)


#: The segment descriptor of fdsmc_vectors.h.
SEGMENT_TYPE = """\
typedef struct {
    const char *name;
    int32_t start, n;      /* first sample in the arrays, samples [-] */
    fdsmc_count theta_dem; /* the move set after fdsmc_init(&s, &FDSMC_DESIGN, 0) [counts] */
    double t_m;            /* its T_m [s]; 0: no move (at rest at count 0) */
    uint32_t fault;        /* fault bits latched at the end (0: none) */
    int32_t fault_at;      /* the sample that latches it (-1: none) */
    int32_t refuse_at;     /* fdsmc_set_move refused: BUSY right after the move, MOVING before this sample */
} fdsmc_vec_segment;
"""


def vector_header(params: DriveParams, controller: str = "fdsmc") -> str:
    """Return the text of ``fdsmc_vectors.h``: the simulator's controller inputs and outputs per segment.

    The segments are :func:`app.exports.firmware.golden.segments` (at most
    :data:`app.exports.firmware.golden.MAX_SAMPLES` samples); ``controller``: the module's outer law
    (``"fdsmc"`` or ``"optimum"``), whose runs are recorded.

    Raises
    ------
    ParameterError
        When the simulated run is unstable or infeasible.
    """
    segs = segments(params, controller)
    theta = np.concatenate([s.theta for s in segs])
    i_dq, u = np.concatenate([s.i_dq for s in segs]), np.concatenate([s.u_dq for s in segs])
    n, names = theta.size, ", ".join(f"{s.name} ({s.theta.size})" for s in segs)
    counts = ",\n".join("    " + ", ".join(str(int(c)) for c in theta[j:j + 8]) for j in range(0, n, 8))
    return (f"/* fdsmc_vectors.h -- golden vectors of {c_string(params.name)}: {n} samples of the simulator's\n"
            f" * digital mode (demand rounded to a count) in {len(segs)} segments, {c_string(names)}:\n"
            " * theta_r [counts], i_d, i_q [A] the controller saw and the voltages u_d, u_q [V] it applied.\n"
            " * Replayed by fdsmc_test.c. */\n"
            "#ifndef FDSMC_VECTORS_H\n#define FDSMC_VECTORS_H\n#include <math.h>\n#define V_(x) ((fdsmc_real)(x))\n"
            f"#define FDSMC_VEC_HASH 0x{parameter_hash(params)}u\n#define FDSMC_VEC_N {n}\n"
            f"#define FDSMC_VEC_SEGMENTS {len(segs)}\n"
            f"#define FDSMC_VEC_U_PEAK {c_literal(float(np.max(np.abs(u))) or 1.0)}\n{SEGMENT_TYPE}"
            f"static const fdsmc_vec_segment fdsmc_vec_seg[{len(segs)}] = {{\n{_segment_table(segs)}\n}};\n"
            f"static const fdsmc_count fdsmc_vec_theta[{n}] = {{\n{counts}\n}};\n"
            f"static const fdsmc_real fdsmc_vec_in[{n}][2] = {{\n{_rows(i_dq)}\n}};\n"
            f"static const fdsmc_real fdsmc_vec_u[{n}][2] = {{\n{_rows(u)}\n}};\n#endif\n")


def c_files(cmp: Comparison, checks: Sequence | None, force: bool = False,
            controller: str = "fdsmc") -> dict[str, str]:
    """File name → text of the C export of a simulated case: module, golden vectors, host test program.

    Parameters
    ----------
    cmp : Comparison
        The simulated case (``cmp.derived.params`` are the inputs).
    checks : sequence of Constraint or None
        ``sim.fdsmc.design.run_checks(params, run)`` of the module's law's run (None when there is no run).
    force : bool
        Export a design that is not clean (the header still stops the build unless accepted).
    controller : str
        The module's outer law: ``"fdsmc"`` (its run ``cmp.fdsmc``) or ``"optimum"`` (``cmp.optimum``,
        the tracked optimum's module, :mod:`app.exports.firmware.optimum`).

    Raises
    ------
    ParameterError
        When the design is not clean and ``force`` is False, naming the failed checks.
    """
    entered = cmp.derived.params
    if entered.controller.is_continuous:  # before the counted case, which needs a sample rate for its encoder
        raise ParameterError(CONTINUOUS_REFUSED)
    params, _ = count_params(entered)  # the firmware's demand is a whole count
    run = cmp.optimum if controller == "optimum" else cmp.fdsmc
    verdict: Verdict = verdict_of(checks if run is not None else None)
    if not verdict.clean and not force:
        names = ", ".join(f"{n} ({t})" for n, t in verdict.failed)
        raise ParameterError(f"the design is not clean: {names}; export with --force to write it anyway "
                             "(the header then stops the build unless FDSMC_ACCEPT_UNCLEAN is defined)")
    files = controller_files(params, derive(params), SCHEMA, verdict, inputs=entered, law=controller)
    assert HEADER_NAME in files
    if run is not None:
        files[VECTORS_NAME] = vector_header(entered, controller)
        files[TEST_NAME] = TEST_PROGRAM
    return files
