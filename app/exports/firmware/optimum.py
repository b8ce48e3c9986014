"""The tracked optimum's C module: the designed move's reference table and the law that tracks it.

The module is the FDSMC's (:mod:`app.exports.firmware.source`) with another outer law: the simulator's
``optimum`` (kernel law 3, :func:`control.fdsmc.terminal_slide.slide_in_demand`). Its reference is the
minimum-energy move of :func:`control.fdsmc.optimum.tracked_move` — the very table the simulator
reads — written as a ``const`` table of its N nodes and read as :func:`sim.fdsmc.kernel.reference_at`
does: θ_ref quadratic between nodes (the integral of the linear ω_ref), ω_ref and α_ref linear, α_ref
read ``FDSMC_REF_LEAD`` seconds ahead, after T_m the last node at rest. The law tracks it with
α_ref + g1·(θ_ref − θ̂_r) + g2·(ω_ref − ω̂_r) until the reference reaches the sloped segment of eq. (41)
in [1], then runs eq. (46) at the slide's T_c (the FDSMC's ``sliding_mode``), as the simulator.

Double build: node θ_ref − θ_start [rad], the move's clock accumulated as the kernel's time (n_sub
additions of the RK4 step per sample), every operation in the kernel's order: bit-identical to the
simulator. Float build: node θ_ref − θ_dem as int32 counts + a float fraction (so that θ_ref − θ̂ is
exact near the target, like the observer's n0 + f0), the clock as a sample count.

The table is for the designed move: ``fdsmc_set_move`` accepts only θ_dem = held demand +
``FDSMC_REF_DELTA`` counts in ``FDSMC_T_M`` (``FDSMC_ERR_TABLE`` otherwise). Its float32 size is
16 bytes per node; an export above :data:`MAX_TABLE_BYTES` is refused.

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pmsm_commissioning.app.exports.firmware.design import encoder_counts_per_rev
from pmsm_commissioning.control.common.checks import ParameterError
from pmsm_commissioning.control.fdsmc.derivations import Derived
from pmsm_commissioning.control.fdsmc.optimum import tracked_move
from pmsm_commissioning.control.fdsmc.params import DriveParams
from pmsm_commissioning.sim.fdsmc import layout as lay
from pmsm_commissioning.sim.fdsmc.engine import pack_parameters
from pmsm_commissioning.sim.fdsmc.grid import time_grid

#: Largest reference table of the float32 (target) build [bytes]: a quarter of a 256 KiB flash.
MAX_TABLE_BYTES = 64 * 1024
#: Bytes per node: float32 build (int32 count, fraction, ω_ref, α_ref) and double build (θ, ω, α).
NODE_BYTES_FLOAT, NODE_BYTES_DOUBLE = 16, 24


@dataclass(frozen=True)
class ReferenceTable:
    """The designed move's reference on its N nodes over [0, T_m].

    Attributes
    ----------
    theta : numpy.ndarray     θ_ref − θ_start [rad] (the simulator's table).
    omega : numpy.ndarray     ω_ref [rad/s].
    alpha : numpy.ndarray     α_ref [rad/s²].
    counts : numpy.ndarray    θ_ref − θ_dem, whole encoder counts (floor) [-].
    fraction : numpy.ndarray  Its fractional part [counts], in [0, 1).
    delta_counts : int        The move θ_dem − θ_start [counts].
    h : float                 Node spacing T_m/(N − 1) [s].
    """

    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    counts: np.ndarray
    fraction: np.ndarray
    delta_counts: int
    h: float

    @property
    def nodes(self) -> int:
        """Number of nodes N [-]."""
        return int(self.theta.size)

    @property
    def float_bytes(self) -> int:
        """Size of the float32 build's table [bytes]."""
        return NODE_BYTES_FLOAT * self.nodes


def reference_table(params: DriveParams, d: Derived, max_bytes: int = MAX_TABLE_BYTES) -> ReferenceTable:
    """Return the reference table of ``params`` (θ_dem a whole count) from the simulator's tracked move.

    Raises
    ------
    ParameterError
        When the float32 table would exceed ``max_bytes``.
    """
    mv = tracked_move(d)
    n = int(mv.theta.size)
    if NODE_BYTES_FLOAT * n > max_bytes:
        raise ParameterError(f"the tracked optimum's reference table ({n} nodes, {NODE_BYTES_FLOAT * n} bytes) "
                             f"exceeds the C module's limit: allowed ≤ {max_bytes} bytes")
    step = 2.0 * math.pi / encoder_counts_per_rev(params)
    rel = (mv.theta - params.manoeuvre.theta_dem) / step
    whole = np.floor(rel)
    return ReferenceTable(mv.theta, mv.omega, mv.alpha, whole.astype(np.int64), rel - whole,
                          round(params.manoeuvre.theta_dem / step), params.manoeuvre.T_m / (n - 1))


def optimum_constants(params: DriveParams, d: Derived, table: ReferenceTable) -> list[tuple]:
    """(name, value, unit, reference, integer) of the optimum's ``#define`` constants, in SI units."""
    prm = pack_parameters(params, d, "optimum")
    g = time_grid(params, 1, 0.0, 1)
    lead = float(prm[lay.P_LEAD])
    cpr = encoder_counts_per_rev(params)
    return [
        ("G1_TRACK", float(prm[lay.P_G1]), "1/s^2", "tracking gain a^2 (control/fdsmc/tracking.py)", False),
        ("G2_TRACK", float(prm[lay.P_G2]), "1/s", "tracking gain 2a (control/fdsmc/tracking.py)", False),
        ("T_C_SLIDE", float(prm[lay.P_TC]), "s",
         "terminal slide's T_c = 3.5/(alpha_max*K), K below the chatter limit, eq. (41)", False),
        ("REF_LEAD", lead, "s", "alpha_ref read ahead: T_salpha/3 + the computation delay", False),
        ("REF_NODES", table.nodes, "-", f"nodes of the reference table ({table.float_bytes} bytes float32)", True),
        ("REF_H", table.h, "s", "node spacing T_m/(REF_NODES - 1)", False),
        ("REF_DELTA", table.delta_counts, "counts", "the designed move theta_dem - theta_start", True),
        ("REF_INV_H", 1.0 / table.h, "1/s", "1/REF_H (float build)", False),
        ("REF_H_COUNTS", table.h * cpr / (2.0 * math.pi), "counts*s/rad", "REF_H in counts per rad/s", False),
        ("CLOCK_SUBSTEPS", g.n_sub, "-", "additions of CLOCK_H per sample (the simulator's clock)", True),
        ("CLOCK_H", g.h, "s", "the simulator's RK4 step T_s/CLOCK_SUBSTEPS", False),
    ]


def table_initializer(table: ReferenceTable, literal: Callable[[float], str]) -> str:
    """Return the rows of ``ref_table`` for both builds (``#ifdef FDSMC_USE_FLOAT``)."""
    single = ",\n".join(f"    {{{int(n)}, R_({literal(float(f))}), R_({literal(float(w))}), R_({literal(float(a))})}}"
                        for n, f, w, a in zip(table.counts, table.fraction, table.omega, table.alpha, strict=True))
    double = ",\n".join(f"    {{{literal(float(t))}, {literal(float(w))}, {literal(float(a))}}}"
                        for t, w, a in zip(table.theta, table.omega, table.alpha, strict=True))
    return f"#ifdef FDSMC_USE_FLOAT\n{single}\n#else\n{double}\n#endif"


#: Extra state of the optimum's module (after ``status``, so the FDSMC's layout is its prefix).
STATE_FIELDS = """\
#ifdef FDSMC_USE_FLOAT
    uint32_t ref_k;         /* samples since the move was set */
#else
    double ref_t;           /* time since the move was set [s], accumulated as the simulator's clock */
    double ref_start_rad;   /* the move's start [rad] */
#endif
    int32_t ref_on;         /* 1 once a move is set (else the slide holds theta_dem) */
"""

#: fdsmc_init's additions: the slide's T_c, no move.
LAW_INIT = """\
    s->t_c = FDSMC_T_C_SLIDE;
    s->inv_t_c = R_(1) / FDSMC_T_C_SLIDE;
    s->slope_end = FDSMC_T_C_SLIDE * FDSMC_OMEGA_P;
    s->ref_on = 0;
"""

SET_MOVE = """\
/* The tracked optimum's reference is the designed move's table: only theta_dem = the held demand +
 * FDSMC_REF_DELTA counts in FDSMC_T_M is accepted (FDSMC_ERR_TABLE otherwise); at rest, outside the ISR. */
int32_t fdsmc_set_move(fdsmc_state *s, fdsmc_count theta_dem, fdsmc_real T_m)
{
    fdsmc_real dtheta = R_(0);
    int32_t rc = move_start(s, theta_dem, &dtheta);
    if (rc == FDSMC_OK && !(within(T_m, s->p->t_m_max) && T_m > R_(0))) {
        rc = FDSMC_ERR_ARG;
    } else if (rc == FDSMC_OK && (count_diff(theta_dem, s->theta_dem) != FDSMC_REF_DELTA
                                  || FDSMC_FABS(T_m - FDSMC_T_M) > R_(1.0e-6) * FDSMC_T_M)) {
        rc = FDSMC_ERR_TABLE;
    }
    s->status.last_move = rc;
    if (rc == FDSMC_OK) {
        publish_move(s, theta_dem, s->omega_p, s->t_c); /* the slide's T_c and the designed omega_p */
    }
    return rc;
}
"""

#: What the step does when it takes a move (before the demand is re-referenced): the move's clock from 0.
TAKE_LAW = """\
#ifdef FDSMC_USE_FLOAT
    s->ref_k = 0u;
#else
    s->ref_t = 0.0;
    s->ref_start_rad = s->theta_dem_rad;
#endif
    s->ref_on = 1;
"""

OUTER_LAW = """\
/* ---- tracked optimum (control/fdsmc/terminal_slide.py): the designed move's reference table ---- */
#ifdef FDSMC_USE_FLOAT
typedef struct { fdsmc_count n; fdsmc_real f, omega, alpha; } ref_node; /* theta_ref - theta_dem = n + f counts */
#define REF_STEP FDSMC_REF_H_COUNTS /* node spacing in counts per rad/s */
#else
typedef struct { double theta, omega, alpha; } ref_node;                  /* theta_ref - theta_start [rad] */
#define REF_STEP FDSMC_REF_H
#endif
static const ref_node ref_table[FDSMC_REF_NODES] = {
$table
};

/* Node j and fraction f [-] of the reference at t [s] since the move was set, as reference_at of
 * sim/fdsmc/kernel.py; -1 from T_m on (the last node at rest). */
static int32_t ref_node_at(fdsmc_real t, fdsmc_real *f)
{
    fdsmc_real x;
    int32_t j;
    if (t >= FDSMC_T_M) {
        return -1;
    }
    x = FDSMC_DIV(t, FDSMC_REF_H, FDSMC_REF_INV_H);
    j = (int32_t)x;
    j = j < FDSMC_REF_NODES - 2 ? j : FDSMC_REF_NODES - 2;
    *f = x - (fdsmc_real)j;
    return j;
}

/* alpha_dem [rad/s^2] and S of the tracked optimum (outer_law of sim/fdsmc/kernel.py, law 3): alpha_ref
 * (read FDSMC_REF_LEAD ahead) + g1*(theta_ref - theta_hat) + g2*(omega_ref - omega_hat), S = 0, until the
 * reference reaches the sloped segment of eq. (41); from there eq. (46) at the slide's T_c. */
static fdsmc_real tracked_optimum(fdsmc_state *s, fdsmc_real theta_re, fdsmc_real omega_hat, fdsmc_real *S)
{
    fdsmc_real t, f = R_(0), f_lead = R_(0), w = R_(0), a = R_(0), dth = R_(0), th, sw, e_th;
    int32_t j, j_lead;
    if (s->ref_on == 0) {
        return sliding_mode(s, theta_re, omega_hat, S); /* no move set: the reference at rest on theta_dem */
    }
#ifdef FDSMC_USE_FLOAT
    t = (fdsmc_real)s->ref_k * FDSMC_T_S;
    s->ref_k += s->ref_k < 0x7fffffffu ? 1u : 0u;
#else
    {
        int i;
        t = s->ref_t;
        for (i = 0; i < FDSMC_CLOCK_SUBSTEPS; ++i) {
            s->ref_t += FDSMC_CLOCK_H; /* the simulator's clock, addition for addition */
        }
    }
#endif
    j = ref_node_at(t, &f);
    j_lead = ref_node_at(t + FDSMC_REF_LEAD, &f_lead);
    if (j_lead >= 0) {
        a = (R_(1) - f_lead) * ref_table[j_lead].alpha + f_lead * ref_table[j_lead + 1].alpha;
    }
    if (j >= 0) {
        const fdsmc_real w0 = ref_table[j].omega, w1 = ref_table[j + 1].omega;
        dth = REF_STEP * f * (w0 + R_(0.5) * f * (w1 - w0)); /* integral of the linear omega_ref */
        w = (R_(1) - f) * w0 + f * w1;
    } else {
        j = FDSMC_REF_NODES - 1;
    }
#ifdef FDSMC_USE_FLOAT
    th = ref_table[j].f + dth; /* fraction of theta_ref - theta_dem [counts] */
    sw = w + FDSMC_DIV(((fdsmc_real)ref_table[j].n + th) * s->p->rad_per_count, s->t_c, s->inv_t_c);
    e_th = ((fdsmc_real)count_diff(ref_table[j].n, s->n0) + (th - s->f0)) * s->p->rad_per_count;
#else
    th = s->ref_start_rad + (ref_table[j].theta + dth);
    sw = w + (th - s->theta_dem_rad) / s->t_c;
    e_th = th - s->x[0];
#endif
    if (FDSMC_REF_DELTA >= 0 ? sw >= R_(0) : sw <= R_(0)) {
        return sliding_mode(s, theta_re, omega_hat, S); /* on the sloped segment: eq. (46) */
    }
    *S = R_(0);
    return a + FDSMC_G1_TRACK * e_th + FDSMC_G2_TRACK * (w - omega_hat);
}

"""


def law_parts(table: ReferenceTable, literal: Callable[[float], str]) -> dict[str, str]:
    """Placeholders of :data:`app.exports.firmware.source.SOURCE` and the header for the tracked optimum."""
    return {"set_move": SET_MOVE, "outer_law": OUTER_LAW.replace("$table", table_initializer(table, literal)),
            "outer_call": "tracked_optimum(s, th_re, w, &S)", "law_init": LAW_INIT, "take_law": TAKE_LAW}
