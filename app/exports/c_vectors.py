"""Golden test vectors and the host test program of the C module, and the export's C file set.

:func:`vector_header` runs the simulator's digital mode on the design (demand rounded to a whole
encoder count, as the firmware receives it) and writes, for the first :data:`VECTOR_SAMPLES` samples,
the inputs its controller saw (θ_r as encoder counts, i_d, i_q) and the voltages it applied (u_d, u_q)
as ``fdsmc_vectors.h``. ``fdsmc_test.c`` (:data:`TEST_PROGRAM`) replays them through ``fdsmc_step`` and
exits 0 when every voltage agrees within 1e-6 (double) or 1e-4 (float32) of the peak |u|.
:func:`c_files` is the whole C export of one simulated case, the verdict gate included.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from app.exports.c_module import (
    CONTINUOUS_REFUSED,
    HEADER_NAME,
    Verdict,
    c_literal,
    controller_files,
    parameter_hash,
    verdict_of,
)
from app.exports.c_text import c_string
from app.exports.c_verify import count_params, readings
from app.io.presets import SCHEMA
from control.common.checks import ParameterError
from control.fdsmc.derivations import derive
from control.fdsmc.params import DriveParams
from sim.common import sensors
from sim.fdsmc.engine import Comparison, simulate
from sim.fdsmc.grid import time_grid

#: Most samples in the golden vectors [-] (from t = 0: the start of the move).
VECTOR_SAMPLES = 2000
VECTORS_NAME, TEST_NAME = "fdsmc_vectors.h", "fdsmc_test.c"

TEST_PROGRAM = """\
/* fdsmc_test.c -- replays the golden vectors of fdsmc_vectors.h through fdsmc_step() and compares the
 * voltages with the simulator's. Build and run on the host (add -DFDSMC_USE_FLOAT for float32, and
 * -DFDSMC_ACCEPT_UNCLEAN=<FDSMC_PARAM_HASH> for a design that is not clean):
 *   cc -std=c99 -Wall -Wextra -Werror -O2 fdsmc_test.c fdsmc_controller.c -lm -o fdsmc_test && ./fdsmc_test
 * Exit status 0: every sample within FDSMC_TEST_TOL of the peak |u|; 1: a sample is not; 2: refused. */
#include <math.h>
#include <stdio.h>
#include "fdsmc_controller.h"
#include "fdsmc_vectors.h"

#ifdef FDSMC_USE_FLOAT
#define FDSMC_TEST_TOL 1e-4
#else
#define FDSMC_TEST_TOL 1e-6
#endif

int main(void)
{
    fdsmc_state s;
    fdsmc_output out;
    double worst = 0.0;
    int k, worst_k = 0;
    int32_t rc;
    if (FDSMC_VEC_HASH != FDSMC_PARAM_HASH) {
        printf("fdsmc_test: the vectors belong to another design\\n");
        return 2;
    }
    fdsmc_init(&s, &FDSMC_DESIGN, 0);
    rc = fdsmc_set_move(&s, FDSMC_VEC_THETA_DEM, (fdsmc_real)FDSMC_VEC_T_M);
    if (rc != FDSMC_OK) {
        printf("fdsmc_test: fdsmc_set_move refused the designed move (status %d)\\n", (int)rc);
        return 2;
    }
    for (k = 0; k < FDSMC_VEC_N; ++k) {
        double e_d, e_q;
        fdsmc_step(&s, fdsmc_vec_theta[k], fdsmc_vec_in[k][0], fdsmc_vec_in[k][1], &out);
        e_d = fabs((double)out.u_d - (double)fdsmc_vec_u[k][0]);
        e_q = fabs((double)out.u_q - (double)fdsmc_vec_u[k][1]);
        if (e_d > worst || e_q > worst) {
            worst = e_d > e_q ? e_d : e_q;
            worst_k = k;
        }
    }
    worst /= FDSMC_VEC_U_PEAK;
    printf("fdsmc_test: %d samples, max |u - u_sim| / peak |u| = %.3g at sample %d (tolerance %g), faults 0x%x\\n",
           FDSMC_VEC_N, worst, worst_k, FDSMC_TEST_TOL, (unsigned)s.status.fault);
    return worst <= FDSMC_TEST_TOL && s.status.fault == 0u ? 0 : 1;
}
"""


def _rows(values: np.ndarray) -> str:
    return ",\n".join("    {" + ", ".join(f"V_({c_literal(v)})" for v in row) + "}" for row in values)


def vector_header(params: DriveParams, controller: str = "fdsmc") -> str:
    """Text of ``fdsmc_vectors.h``: the simulator's controller inputs and outputs of the first samples.

    ``controller``: the module's outer law (``"fdsmc"`` or ``"optimum"``), whose run is recorded.

    Raises
    ------
    ParameterError
        When the simulated run is unstable before :data:`VECTOR_SAMPLES` samples or infeasible.
    """
    sim_params, count = count_params(params)
    n = min(VECTOR_SAMPLES, time_grid(sim_params, 1, 0.0, 1).n_steps)
    trace = simulate(sim_params, controller, max_points=time_grid(sim_params, 1, 0.0, 1).n_steps + 1).trace
    if trace.t.size < n:
        raise ParameterError(f"the simulated run stops after {trace.t.size} samples: no test vectors")
    noise = sensors.noise_table(sim_params.sensors)
    read = np.array([readings(sim_params, k, trace.theta_r[k], trace.i_d[k], trace.i_q[k], noise) for k in range(n)])
    theta, u = read[:, 0].astype(np.int64), np.column_stack([trace.u_d[:n], trace.u_q[:n]])
    counts = ",\n".join("    " + ", ".join(str(int(c)) for c in theta[j:j + 8]) for j in range(0, n, 8))
    return (f"/* fdsmc_vectors.h -- golden vectors of {c_string(params.name)}: the first {n} samples of the\n"
            " * simulator's digital mode (demand rounded to a count): theta_r [counts], i_d, i_q [A] the\n"
            " * controller saw and the voltages u_d, u_q [V] it applied. Replayed by fdsmc_test.c. */\n"
            "#ifndef FDSMC_VECTORS_H\n#define FDSMC_VECTORS_H\n#define V_(x) ((fdsmc_real)(x))\n"
            f"#define FDSMC_VEC_HASH 0x{parameter_hash(params)}u\n#define FDSMC_VEC_N {n}\n"
            f"#define FDSMC_VEC_THETA_DEM {count}\n#define FDSMC_VEC_T_M {c_literal(params.manoeuvre.T_m)}\n"
            f"#define FDSMC_VEC_U_PEAK {c_literal(float(np.max(np.abs(u))) or 1.0)}\n"
            f"static const fdsmc_count fdsmc_vec_theta[{n}] = {{\n{counts}\n}};\n"
            f"static const fdsmc_real fdsmc_vec_in[{n}][2] = {{\n"
            f"{_rows(read[:, 1:])}\n}};\n"
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
        the tracked optimum's module, :mod:`app.exports.c_optimum`).

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
