"""C99 text of the generated controller's source ``fdsmc_controller.c`` (header: :mod:`app.exports.c_template`).

:data:`SOURCE` mirrors the controller of the simulator's digital mode, :func:`sim.fdsmc.kernel.step_sample`:
sensor readings in, outer law (eqs. (41)–(46) of [1] or the comparator (62)), FDC voltages (eqs. (7), (9),
(14)), the hard predictive current limit and the voltage limit of :mod:`control.fdsmc.inverter`
(:data:`LIMIT_CODE`), the computation delay, then the observer update — the same formulas in the same
order. The double build is that arithmetic operation for operation; the float build keeps the observer
scaled, θ̂ − θ_dem in counts and uses reciprocals. ``$design`` is filled by
:func:`app.exports.c_design.design_initializer`. The outer law is the module's: the FDSMC's
(``$set_move`` = :data:`FDSMC_MOVE`, ``$outer_call`` = ``sliding_mode``, no ``$outer_law``/``$law_init``)
or the tracked optimum's (:mod:`app.exports.c_optimum`).

[1] Dodds, Sooriyakumar, Perryman, the FDSMC paper.
"""

from __future__ import annotations

from string import Template

SOURCE = Template("""\
/* fdsmc_controller.c -- generated with fdsmc_controller.h (see there); drive: $name.
 * Two number builds of one controller. Double (default): the simulator's arithmetic operation for
 * operation (absolute observer state, divisions), so that on the same readings it is bit-identical to
 * sim/fdsmc/kernel.py. Float (-DFDSMC_USE_FLOAT): the observer scaled to order-1 angles with theta_hat
 * - theta_dem as counts + fraction, and precomputed reciprocals (FDSMC_DIV), so that no double
 * operation is needed. */
#include <math.h>
#include "fdsmc_controller.h"

#ifdef FDSMC_USE_FLOAT
#define FDSMC_SQRT(x) sqrtf(x)
#define FDSMC_FABS(x) fabsf(x)
#define FDSMC_DIV(x, d, inv_d) ((x) * (inv_d))
#define FDSMC_DISC_TOL 1.0e-6 /* relative rounding of the discriminant of eq. (60) */
#else
#define FDSMC_SQRT(x) sqrt(x)
#define FDSMC_FABS(x) fabs(x)
#define FDSMC_DIV(x, d, inv_d) ((x) / (d))
#define FDSMC_DISC_TOL 1.0e-12
#endif
#define R_(x) ((fdsmc_real)(x))

const fdsmc_params FDSMC_DESIGN = {
$design
};

/* a - b for counts, wrapping modulo 2^32 (no signed overflow). */
static fdsmc_count count_diff(fdsmc_count a, fdsmc_count b)
{
    const uint32_t d = (uint32_t)a - (uint32_t)b;
    return d <= 0x7fffffffu ? (fdsmc_count)d : -(fdsmc_count)(~d) - 1;
}

/* ---- observer state: the two representations (see the header, "Observer state") ---- */
#ifdef FDSMC_USE_FLOAT
static void observer_reset(fdsmc_state *s, fdsmc_count theta_r0)
{
    s->theta_dem = theta_r0;
    s->n0 = 0;
    s->f0 = R_(0);
    s->z[0] = s->z[1] = s->z[2] = R_(0);
}

/* |theta_dem - theta_hat| [rad] for a new demand, and theta_hat - theta_dem re-referenced to it. */
static fdsmc_real move_distance(fdsmc_state *s, fdsmc_count theta_dem, int commit)
{
    const fdsmc_count shift = count_diff(theta_dem, s->theta_dem);
    if (commit) {
        s->n0 = count_diff(s->n0, shift);
        s->theta_dem = theta_dem;
        return R_(0);
    }
    return FDSMC_FABS(((fdsmc_real)count_diff(shift, s->n0) - s->f0) * s->p->rad_per_count);
}

/* Innovation e_o = theta_r - theta_hat [counts] (exact integer part, then the fraction). */
static fdsmc_real innovation_counts(const fdsmc_state *s, fdsmc_count theta_r)
{
    return (fdsmc_real)count_diff(count_diff(theta_r, s->theta_dem), s->n0) - s->f0;
}

/* theta_hat - theta_dem [rad], omega_hat [rad/s], M*L0_hat [rad/s^2], M*L1_hat [rad/s^3]. */
static void estimates(const fdsmc_state *s, fdsmc_real *th_re, fdsmc_real *w, fdsmc_real *mL0, fdsmc_real *mL1)
{
    *th_re = ((fdsmc_real)s->n0 + s->f0) * s->p->rad_per_count;
    *w = s->z[0] * s->p->f_s;
    *mL0 = s->z[1] * s->p->f_s2;
    *mL1 = s->z[2] * s->p->f_s3;
}

/* z[k+1] = PHI_S*z[k] + GAMMA_S*a_em*T_s^2 + L_S*e_o [rad], PHI_S upper triangular with column 0 =
 * (1, 0, 0, 0) and GAMMA_S = (g0, g1, 0, 0) (the exporter checks it): the zero terms are left out and
 * the angle row advances n0 + f0 in counts. Returns 0, or FDSMC_FAULT_STATE. */
static uint32_t observer_update(fdsmc_state *s, fdsmc_real e_o, fdsmc_real a_em)
{
    const fdsmc_params *p = s->p;
    const fdsmc_real a_s = a_em * p->t_s2, z0 = s->z[0], z1 = s->z[1], z2 = s->z[2];
    fdsmc_real step_counts;
    fdsmc_count whole;
    step_counts = (p->gamma[0] * a_s + p->l[0] * e_o + (p->phi[0][1] * z0 + p->phi[0][2] * z1 + p->phi[0][3] * z2))
                  * p->counts_per_rad + s->f0;
    if (!(FDSMC_FABS(step_counts) < R_(1.0e9))) {
        return FDSMC_FAULT_STATE; /* not finite (NaN fails every comparison) or beyond range */
    }
    whole = (fdsmc_count)step_counts;
    s->f0 = step_counts - (fdsmc_real)whole;
    s->n0 = (fdsmc_count)((uint32_t)s->n0 + (uint32_t)whole);
    s->z[0] = p->gamma[1] * a_s + p->l[1] * e_o + (p->phi[1][1] * z0 + p->phi[1][2] * z1 + p->phi[1][3] * z2);
    s->z[1] = p->l[2] * e_o + (p->phi[2][2] * z1 + p->phi[2][3] * z2);
    s->z[2] = p->l[3] * e_o + p->phi[3][3] * z2;
    return 0u;
}
#else
static void observer_reset(fdsmc_state *s, fdsmc_count theta_r0)
{
    s->theta_dem = theta_r0;
    s->theta_dem_rad = (double)theta_r0 * s->p->rad_per_count;
    s->x[0] = s->theta_dem_rad;
    s->x[1] = s->x[2] = s->x[3] = 0.0;
}

static fdsmc_real move_distance(fdsmc_state *s, fdsmc_count theta_dem, int commit)
{
    const double theta = (double)theta_dem * s->p->rad_per_count;
    if (commit) {
        s->theta_dem = theta_dem;
        s->theta_dem_rad = theta;
    }
    return fabs(theta - s->x[0]);
}

static fdsmc_real innovation_counts(const fdsmc_state *s, fdsmc_count theta_r)
{
    return ((double)theta_r * s->p->rad_per_count - s->x[0]) * s->p->counts_per_rad;
}

static void estimates(const fdsmc_state *s, fdsmc_real *th_re, fdsmc_real *w, fdsmc_real *mL0, fdsmc_real *mL1)
{
    *th_re = s->x[0] - s->theta_dem_rad;
    *w = s->x[1];
    *mL0 = s->p->m * s->x[2];
    *mL1 = s->p->m * s->x[3];
}

/* x[k+1] = Phi*x[k] + Gamma*a_em + L*e_o with e_o = theta_r*step - theta_hat, as sim/fdsmc/kernel.py. */
static uint32_t observer_update_abs(fdsmc_state *s, double theta_m, fdsmc_real a_em)
{
    const fdsmc_params *p = s->p;
    const double e_o = theta_m - s->x[0];
    double x[4];
    int i;
    for (i = 0; i < 4; ++i) {
        x[i] = p->gamma[i] * a_em + p->l[i] * e_o
               + (p->phi[i][0] * s->x[0] + p->phi[i][1] * s->x[1] + p->phi[i][2] * s->x[2] + p->phi[i][3] * s->x[3]);
    }
    if (!(fabs(x[0] - s->x[0]) + fabs(x[1]) + fabs(x[2]) + fabs(x[3]) < 1.0e300)) {
        return FDSMC_FAULT_STATE;
    }
    for (i = 0; i < 4; ++i) {
        s->x[i] = x[i];
    }
    return 0u;
}
#endif

void fdsmc_init(fdsmc_state *s, const fdsmc_params *p, fdsmc_count theta_r0)
{
    s->p = p;
    observer_reset(s, theta_r0);
    s->u_hold[0] = R_(0);
    s->u_hold[1] = R_(0);
    for (int i = 0; i < 6; i++) {
        s->dv_mem[i] = R_(0);
    }
    s->omega_p = FDSMC_OMEGA_P;
    s->t_c = FDSMC_T_C;
    s->inv_t_c = R_(1) / FDSMC_T_C;
    s->slope_end = FDSMC_T_C * FDSMC_OMEGA_P;
    s->status.fault = 0u;
    s->status.fault_sample = 0u;
    s->status.samples = 0u;
    s->status.saturated_samples = 0u;
    s->status.e_o_peak = R_(0);
    s->status.last_move = FDSMC_OK;
$law_init}

$set_move
/* Demanded acceleration of eqs. (44)-(46) of [1], -alpha_max*sat(K*S); theta_re = theta_hat - theta_dem. */
static fdsmc_real sliding_mode(const fdsmc_state *s, fdsmc_real theta_re, fdsmc_real omega_hat, fdsmc_real *S)
{
    fdsmc_real x;
    if (FDSMC_FABS(theta_re) < s->slope_end) {
        *S = omega_hat + FDSMC_DIV(theta_re, s->t_c, s->inv_t_c);
    } else {
        *S = omega_hat + (theta_re > R_(0) ? s->omega_p : (theta_re < R_(0) ? -s->omega_p : R_(0)));
    }
    x = s->p->k_bl * *S;
    x = x >= R_(1) ? R_(1) : (x <= R_(-1) ? R_(-1) : x);
    return -s->p->alpha_max * x;
}

$outer_law
/* u_d of eq. (9) with i_d,dem = 0 and u_q of eq. (14) of [1]; mL0 = M*Gamma_L_hat, mL1 = M*dGamma_L_hat/dt. */
static void fdc_voltages(const fdsmc_params *p, fdsmc_real alpha_dem, fdsmc_real i_d, fdsmc_real i_q,
                         fdsmc_real w, fdsmc_real mL0, fdsmc_real mL1, fdsmc_real *u_d, fdsmc_real *u_q)
{
    const fdsmc_real hk = p->h + p->k * i_d;
    const fdsmc_real alpha = hk * i_q - mL0;                                  /* eq. (7) */
    const fdsmc_real forced = p->three_inv_t_salpha * (alpha_dem - alpha);    /* eq. (13) */
    fdsmc_real coupling;
    *u_d = FDSMC_DIV(-p->three_inv_t_si * i_d + p->a * i_d - p->b * w * i_q, p->f, p->inv_f); /* eq. (9) */
    coupling = p->k * i_q * (p->a * i_d - p->b * w * i_q - p->f * *u_d);
    *u_q = FDSMC_DIV((forced + coupling + mL1) / hk + p->c * w * i_d + p->d * i_q + p->e * w,
                     p->g, p->inv_g);                                          /* eq. (14) */
}

$limit_code

static void fault(fdsmc_state *s, uint32_t bits, fdsmc_output *out)
{
    if (s->status.fault == 0u) {
        s->status.fault_sample = s->status.samples - 1u; /* this call's index */
    }
    s->status.fault |= bits;
    out->u_d = R_(0);
    out->u_q = R_(0);
    out->fault = s->status.fault;
}

/* Checks the readings; sets the innovation e_o = theta_r - theta_hat [rad] or returns the fault bits. */
static uint32_t check_inputs(fdsmc_state *s, fdsmc_count theta_r, fdsmc_real i_d, fdsmc_real i_q,
                             fdsmc_real *e_o)
{
    const fdsmc_params *p = s->p;
    fdsmc_real e_abs;
    if (!(i_d * i_d + i_q * i_q <= p->i_fault2)) {
        return FDSMC_FAULT_CURRENT; /* also NaN and inf */
    }
    *e_o = innovation_counts(s, theta_r);
    e_abs = FDSMC_FABS(*e_o);
    if (!(e_abs <= p->e_o_max_counts)) {
        return FDSMC_FAULT_INNOVATION;
    }
    e_abs *= p->rad_per_count;
    *e_o *= p->rad_per_count;
    s->status.e_o_peak = e_abs > s->status.e_o_peak ? e_abs : s->status.e_o_peak;
    return 0u;
}

static void step(fdsmc_state *s, fdsmc_count theta_r, fdsmc_real i_d, fdsmc_real i_q, int conventional,
                 fdsmc_output *out)
{
    const fdsmc_params *p = s->p;
    fdsmc_real e_o = R_(0), th_re, w, S = R_(0), alpha_dem, u_d, u_q, mL0, mL1, i_d0, i_q0;
    uint32_t bad = s->status.fault != 0u ? s->status.fault : check_inputs(s, theta_r, i_d, i_q, &e_o);
    s->status.samples++;
    if (bad != 0u) {
        fault(s, bad, out);
        return;
    }
    estimates(s, &th_re, &w, &mL0, &mL1);
    alpha_dem = conventional ? -p->g1 * th_re - p->g2 * w : $outer_call;
    fdc_voltages(p, alpha_dem, i_d, i_q, w, mL0, mL1, &u_d, &u_q);
#if FDSMC_VOLTAGE_MISMATCH
    u_q -= voltage_mismatch(s, i_q);
#endif
#if FDSMC_DELAY_SAMPLES == 1
    predict_currents(p, s->u_hold, i_d, i_q, w, &i_d0, &i_q0); /* where the new voltages start acting */
#else
    i_d0 = i_d;
    i_q0 = i_q;
#endif
    out->saturated = limit_voltage(p, &u_d, &u_q, i_d0, i_q0, w);
#ifdef FDSMC_USE_FLOAT
    bad = observer_update(s, e_o, (p->h + p->k * i_d) * i_q);
#else
    bad = observer_update_abs(s, (double)theta_r * p->rad_per_count, (p->h + p->k * i_d) * i_q);
#endif
    if (bad != 0u || !(u_d * u_d + u_q * u_q <= p->u_fault2)) {
        fault(s, FDSMC_FAULT_STATE, out);
        return;
    }
    s->status.saturated_samples += (uint32_t)out->saturated;
#if FDSMC_DELAY_SAMPLES == 1
    out->u_d = s->u_hold[0];
    out->u_q = s->u_hold[1];
    s->u_hold[0] = u_d;
    s->u_hold[1] = u_q;
#else
    out->u_d = u_d;
    out->u_q = u_q;
#endif
#if FDSMC_VOLTAGE_MISMATCH
    s->dv_mem[0] = i_d; /* this call's readings and speed, and the voltages applied until the next */
    s->dv_mem[1] = i_q;
    s->dv_mem[2] = w;
    s->dv_mem[3] = out->u_d;
    s->dv_mem[4] = out->u_q;
#endif
    out->theta_re = th_re;
    out->omega_hat = w;
    out->Gamma_L_hat = mL0 * p->j_r;
    out->alpha_dem = alpha_dem;
    out->S = S;
    out->fault = 0u;
}

void fdsmc_step(fdsmc_state *s, fdsmc_count theta_r, fdsmc_real i_d, fdsmc_real i_q, fdsmc_output *out)
{
    step(s, theta_r, i_d, i_q, 0, out);
}

void fdsmc_step_conventional(fdsmc_state *s, fdsmc_count theta_r, fdsmc_real i_d, fdsmc_real i_q,
                             fdsmc_output *out)
{
    step(s, theta_r, i_d, i_q, 1, out);
}

fdsmc_real fdsmc_electrical_angle(fdsmc_count theta_r, fdsmc_count offset)
{
    const int32_t n = FDSMC_COUNTS_PER_REV;
    int32_t m = count_diff(theta_r, offset) % n;
    m = m < 0 ? m + n : m;
    return (fdsmc_real)(int32_t)(((int64_t)m * FDSMC_POLE_PAIRS) % n) * (R_(FDSMC_TWO_PI) / R_(n));
}
""")

#: The inverter limits of :func:`control.fdsmc.inverter.limit_voltage`, mirrored.
LIMIT_CODE = """\
/* Inverter limits of control/fdsmc/inverter.py: the currents one sample on are predicted from eqs. (1)-(2)
 * of [1] with the voltages held (ZOH factors phi, gam of the rates A and D); where the prediction leaves
 * |i_dq| <= I_MAX the voltage that ends the sample on the circle replaces the demand (i_d first, then
 * i_q in the room left); then |u_dq| <= U_MAX. Squares are compared; a root only when a limit acts.
 * i_d0, i_q0: currents at the start of the sample the voltages act over [A]. Returns 1 if limited. */
static int32_t limit_voltage(const fdsmc_params *p, fdsmc_real *u_d, fdsmc_real *u_q, fdsmc_real i_d0,
                             fdsmc_real i_q0, fdsmc_real w)
{
    int32_t sat = 0;
    fdsmc_real mag2;
    if (p->i_max > R_(0)) {
        const fdsmc_real back_q = (p->c * i_d0 + p->e) * w;
        const fdsmc_real i_d1 = p->phi_d * i_d0 + p->gam_d * (p->b * w * i_q0 + p->f * *u_d);
        const fdsmc_real i_q1 = p->phi_q * i_q0 + p->gam_q * (p->g * *u_q - back_q);
        fdsmc_real room2 = p->i_max2, i_d_end = i_d1;
        if (FDSMC_FABS(i_d1) > p->i_max) {
            i_d_end = i_d1 > R_(0) ? p->i_max : -p->i_max;
            *u_d = FDSMC_DIV(FDSMC_DIV(i_d_end - p->phi_d * i_d0, p->gam_d, p->inv_gam_d) - p->b * w * i_q0, p->f,
                             p->inv_f);
            sat = 1;
        }
        room2 -= i_d_end * i_d_end;
        room2 = room2 > R_(0) ? room2 : R_(0);
        if (i_q1 * i_q1 > room2) {
            const fdsmc_real room = FDSMC_SQRT(room2);
            *u_q = FDSMC_DIV(FDSMC_DIV((i_q1 > R_(0) ? room : -room) - p->phi_q * i_q0, p->gam_q, p->inv_gam_q)
                             + back_q, p->g, p->inv_g);
            sat = 1;
        }
    }
    mag2 = *u_d * *u_d + *u_q * *u_q;
    if (p->u_max > R_(0) && mag2 > p->u_max2) {
        const fdsmc_real scale = p->u_max / FDSMC_SQRT(mag2);
        *u_d *= scale;
        *u_q *= scale;
        sat = 1;
    }
    return sat;
}

#if FDSMC_DELAY_SAMPLES == 1 || FDSMC_VOLTAGE_MISMATCH
/* Currents [A] one sample after (i_d, i_q) with the voltages u held (eqs. (1)-(2) of [1]). */
static void predict_currents(const fdsmc_params *p, const fdsmc_real *u, fdsmc_real i_d, fdsmc_real i_q,
                             fdsmc_real w, fdsmc_real *i_d1, fdsmc_real *i_q1)
{
    *i_d1 = p->phi_d * i_d + p->gam_d * (p->b * w * i_q + p->f * u[0]);
    *i_q1 = p->phi_q * i_q + p->gam_q * (p->g * u[1] - (p->c * i_d + p->e) * w);
}
#endif

#if FDSMC_VOLTAGE_MISMATCH
/* q-axis voltage-mismatch estimate of control/fdsmc/fdc.py (not in [1]), updated with this call's i_q [A]:
 * dv += beta*((i_q - i_q predicted from the last call's readings and applied voltages)/(gam_q*G) - dv) [V]. */
static fdsmc_real voltage_mismatch(fdsmc_state *s, fdsmc_real i_q)
{
    const fdsmc_params *p = s->p;
    fdsmc_real i_d1, i_q1;
    predict_currents(p, &s->dv_mem[3], s->dv_mem[0], s->dv_mem[1], s->dv_mem[2], &i_d1, &i_q1);
    (void)i_d1;
    s->dv_mem[5] = s->dv_mem[5] + p->beta_dv * (FDSMC_DIV(i_q - i_q1, p->gain_dv, p->inv_gain_dv) - s->dv_mem[5]);
    return s->dv_mem[5];
}
#endif"""

#: fdsmc_set_move of the FDSMC module: the profile of eqs. (59)-(60) computed on the target.
FDSMC_MOVE = """\
/* Peak speed of eq. (60) of [1] for |dtheta| [rad] in T_m [s] (stable root); FDSMC_ERR_T_M if none. */
static int32_t peak_speed(const fdsmc_params *p, fdsmc_real dtheta, fdsmc_real T_m, fdsmc_real *omega_p)
{
    const fdsmc_real at = p->alpha_max * T_m;
    fdsmc_real disc = at * at - R_(2) * FDSMC_C_57 * p->alpha_max * dtheta;
    if (disc < R_(0)) {
        if (disc < -R_(FDSMC_DISC_TOL) * at * at) {
            return FDSMC_ERR_T_M;
        }
        disc = R_(0); /* T_m = T_m,min up to rounding: the double root */
    }
    *omega_p = R_(2) * p->alpha_max * dtheta / (at + FDSMC_SQRT(disc));
    return FDSMC_OK;
}

int32_t fdsmc_set_move(fdsmc_state *s, fdsmc_count theta_dem, fdsmc_real T_m)
{
    const fdsmc_params *p = s->p;
    fdsmc_real omega_p = R_(0), t_c;
    int32_t rc = FDSMC_OK;
    if (s->status.fault != 0u) {
        rc = FDSMC_ERR_FAULT;
    } else if (!(T_m > R_(0) && T_m <= p->t_m_max)) {
        rc = FDSMC_ERR_ARG;
    } else {
        rc = peak_speed(p, move_distance(s, theta_dem, 0), T_m, &omega_p);
    }
    t_c = p->t_c_fixed > R_(0) ? p->t_c_fixed : FDSMC_DIV(omega_p, p->alpha_max, p->inv_alpha_max); /* (59) */
    if (rc == FDSMC_OK && omega_p > p->omega_p_max) {
        rc = FDSMC_ERR_SPEED;
    } else if (rc == FDSMC_OK && t_c < p->t_c_min) {
        rc = FDSMC_ERR_T_C;
    }
    s->status.last_move = rc;
    if (rc == FDSMC_OK) {
        (void)move_distance(s, theta_dem, 1);
        s->omega_p = omega_p;
        s->t_c = t_c;
        s->inv_t_c = R_(1) / t_c;
        s->slope_end = t_c * omega_p;
    }
    return rc;
}
"""
