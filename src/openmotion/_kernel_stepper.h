/* Private to the stepper pipeline (_kernel_stepper.c and the _stepper_*.c files): the
 * layout of the kernel's arrays, the structs one cycle works with, the small exact
 * formulas every part shares (pitch table, transmission, cubic, pulse counts, decoder),
 * and the calls between the parts. Every formula repeats the Python pipeline's operation
 * order (hw/sim/ modules; compiled with -ffp-contract=off), so the floats are bit-identical. */
#ifndef OPENMOTION_KERNEL_STEPPER_H
#define OPENMOTION_KERNEL_STEPPER_H

#include "_kernel.h"

#define EPS_PULSE 1e-9
#define MAX_TOGGLES 100000
#define BIG 4.0e15 /* beyond this the Python path (unbounded ints) takes over */

/* per-axis double fields */
enum { D_P0, D_V0, D_A0, D_J, D_TC, D_TE, D_HALF, D_VMAX, D_AMAX, D_BACKLASH, D_Z, D_Y,
       D_UPP, D_STOP, D_SPACING, ND };
/* per-axis int64 fields */
enum { I_COUNT, I_LOST, I_IDEAL, I_ENABLED, I_Q, I_LASTDIR, I_DCOUNT, I_DPERIOD, I_NSW,
       I_TURNF, I_TURNB, I_FWD, I_BWD = I_FWD + 5, I_PBEGIN = I_BWD + 5, I_PEND, I_CURSOR,
       I_RECORD, I_LEVELS, I_ARMED, I_PITCH, I_NPITCH, NI };
/* I_PITCH, I_NPITCH: the axis's pitch-error table in the flat `pitch` buffer (n nominal
 * positions z_k, then the n errors e_k, then the n load positions y_k = z_k + e_k, from
 * I_PITCH on; I_NPITCH 0: no table), D_SPACING its spacing (mechanics.PitchTable) */
#define MAXSW 8
/* per-switch double fields: kind (0 span, 1 index), lo|period, hi|width, hysteresis */
enum { S_KIND, S_A, S_B, S_H, NSD };
/* per-switch int64 fields: active, reported, the input-level bits it flips when active,
 * the bit of its own signal (AXIS_INPUTS index) */
enum { S_ACTIVE, S_WAKE, S_LEVELBITS, S_BIT, S_ARM, S_ARMLEVEL, S_ARMDIR, NSI };
/* S_ARM: 0 not armed, else 1 + the switch's rank in the order the stops were armed (ties
 * at one instant go to the first armed, as SimAxis._first_armed) */
#define LTC_BIT 4 /* AXIS_INPUTS.index("ltc"): SD shares its pin while no LTC is placed */
/* a hidden switch (a probe's interval bound, hw/sim/probe.py) has S_BIT = HIDDEN_BIT + its
 * slot and flips no input level (S_LEVELBITS 0): its edges feed the machine's edge filters */
#define HIDDEN_BIT 9
#define TIME_TOL 1e-13
/* edge row (int64): axis, signal bit, level, own decoded count */
#define NEI 4
#define MAXPREC 32 /* motor pieces per axis and stretch of a cycle (<= 2 x 12: armed) */
/* record row: axis, kind (0 jump, 1 cubic), t0, t1, tc, p0, v0, a0, j, d, c0, c1 */
#define NREC 12

enum { OK = 0, BAIL = 1, WAKE = 2, FULL = 3, HIT = 4 };

/* a motor piece scanned in report mode (simref's StepPiece / JumpPiece with the load and
 * decoder state at its start), for the own count at an edge and encoder_at */
typedef struct {
    int kind, dir; /* kind 0 jump, 1 step */
    double t0, t1, tc, p0, v0, a0, j, half, z0;
    int64_t c0, lost, m1, q, lastdir, count;
} PRec;

typedef struct {
    int on;
    int dry;          /* the dry scan for an armed stop: no edges, no wake, no records */
    double hit_t;     /* its result: the first armed edge's time and switch */
    int hit_s, hit_rank;
    double *et;       /* edge times */
    int64_t *ei;      /* edge rows [cap, NEI] */
    int64_t *enc;     /* every axis's decoded count at each edge [cap, n] */
    Py_ssize_t ne, cap, n;
    PRec *pr;         /* the current stretch's piece records, per axis contiguous */
    Py_ssize_t np, *rbeg, *rcnt;
    int64_t *start;   /* per axis: decoded count at the stretch's start */
    int axis;
} Report;

typedef struct {
    double *d;
    int64_t *i;
    double *sd;
    int64_t *si;
    const double *pt; /* the pitch table (z, e, y rows of I_NPITCH each) or NULL */
} Axis;

/* mechanics.PitchTable.forward: y = z + e(z), piecewise linear (bisect_right) */
static inline double pitch_forward(const Axis *a, double z)
{
    int64_t n = a->i[I_NPITCH];
    if (n == 0) return z;
    const double *zs = a->pt, *e = a->pt + n;
    if (z <= zs[0]) return z + e[0];
    if (z >= zs[n - 1]) return z + e[n - 1];
    int64_t lo = 0, hi = n;
    while (lo < hi) { int64_t mid = (lo + hi) / 2; if (z < zs[mid]) hi = mid; else lo = mid + 1; }
    int64_t k = lo - 1;
    double f = (z - zs[k]) / a->d[D_SPACING];
    return z + e[k] + f * (e[k + 1] - e[k]);
}

/* mechanics.PitchTable.inverse */
static inline double pitch_inverse(const Axis *a, double y)
{
    int64_t n = a->i[I_NPITCH];
    if (n == 0) return y;
    const double *zs = a->pt, *e = a->pt + n, *ys = a->pt + 2 * n;
    if (y <= ys[0]) return y - e[0];
    if (y >= ys[n - 1]) return y - e[n - 1];
    int64_t lo = 0, hi = n;
    while (lo < hi) { int64_t mid = (lo + hi) / 2; if (y < ys[mid]) hi = mid; else lo = mid + 1; }
    int64_t k = lo - 1;
    return zs[k] + (y - ys[k]) * a->d[D_SPACING] / (ys[k + 1] - ys[k]);
}

/* Transmission.motor_level: the motor level whose crossing in direction d makes y cross
 * y_level */
static inline double motor_level(const Axis *a, double y_level, int d)
{
    double z = pitch_inverse(a, y_level);
    return d > 0 ? z : z - a->d[D_BACKLASH];
}

typedef struct {
    double *rows;
    Py_ssize_t n, cap;
    int axis;
} Rec;

static inline double cpos(const double *d, double s)
{
    return d[D_P0] + s * (d[D_V0] + s * (d[D_A0] / 2.0 + s * d[D_J] / 6.0));
}

static inline double cvel(const double *d, double s)
{
    return d[D_V0] + s * (d[D_A0] + s * d[D_J] / 2.0);
}

static inline double cacc(const double *d, double s) { return d[D_A0] + s * d[D_J]; }

/* pieces.count_after; *bad set when the value leaves the exact integer range */
static inline int64_t count_after(double u, int64_t count, int dir, double half, int *bad)
{
    if (dir > 0) {
        double k = floor(u + half + EPS_PULSE);
        if (!(fabs(k) < BIG)) { *bad = 1; return count; }
        return (int64_t)k > count ? (int64_t)k : count;
    }
    if (dir < 0) {
        double k = ceil(u - half - EPS_PULSE);
        if (!(fabs(k) < BIG)) { *bad = 1; return count; }
        return (int64_t)k < count ? (int64_t)k : count;
    }
    return count;
}

/* switches.Switch / IndexSwitch.next_threshold; returns 0 for None */
static inline int next_threshold(const double *sw, int active, double y, int d, double *thr)
{
    if (sw[S_KIND] == 0.0) {
        if (active) { *thr = d > 0 ? sw[S_B] + sw[S_H] : sw[S_A] - sw[S_H]; return 1; }
        if (d > 0) { if (y < sw[S_A]) { *thr = sw[S_A]; return 1; } return 0; }
        if (y >= sw[S_B]) { *thr = sw[S_B]; return 1; }
        return 0;
    }
    double p = sw[S_A], w = sw[S_B];
    double base = floor(y / p) * p;
    if (d > 0) { *thr = active ? base + w : base + p; return 1; }
    if (active) { *thr = base; return 1; }
    *thr = y >= base + w ? base + w : base - p + w;
    return 1;
}

/* encoder._run_sum */
static inline int64_t run_sum(const int64_t *pre, int64_t p, int64_t k0, int64_t n)
{
    int64_t full = n / p, rest = n % p;
    int64_t total = full * pre[p];
    int64_t start = ((k0 % p) + p) % p;
    int64_t end = start + rest;
    if (end <= p) total += pre[end] - pre[start];
    else total += pre[p] - pre[start] + pre[end - p];
    return total;
}

/* encoder.Decoder.advance */
static inline int decoder_advance(Axis *a, double y, int d)
{
    int64_t *ai = a->i;
    double x = y * a->d[D_UPP];
    int64_t q = ai[I_Q], q1 = q;
    if (d > 0) {
        double k = floor(x + EPS_PULSE);
        if (!(fabs(k) < BIG)) return BAIL;
        if ((int64_t)k > q) q1 = (int64_t)k;
    } else if (d < 0) {
        double k = ceil(x - EPS_PULSE);
        if (!(fabs(k) < BIG)) return BAIL;
        if ((int64_t)k < q) q1 = (int64_t)k;
    }
    if (q1 == q) return OK;
    int dd = q1 > q ? 1 : -1;
    int64_t inc = dd != ai[I_LASTDIR] ? (dd > 0 ? ai[I_TURNF] : ai[I_TURNB]) : 0;
    int64_t n = q1 > q ? q1 - q : q - q1;
    int64_t p = ai[I_DPERIOD];
    if (dd > 0) inc += run_sum(ai + I_FWD, p, q, n);
    else inc += run_sum(ai + I_BWD, p, q - n + 1, n);
    ai[I_DCOUNT] += inc;
    ai[I_LASTDIR] = dd;
    ai[I_Q] = q1;
    return OK;
}

/* Python's min/max of two floats (the first argument wins ties: signed zeros stay) */
static inline double pmax(double a, double b) { return b > a ? b : a; }
static inline double pmin(double a, double b) { return b < a ? b : a; }

/* encoder.Decoder.index_after */
static inline int index_after(const Axis *a, double y, int64_t q, int d, int64_t *out)
{
    double x = y * a->d[D_UPP];
    *out = q;
    if (d > 0) {
        double k = floor(x + EPS_PULSE);
        if (!(fabs(k) < BIG)) return BAIL;
        if ((int64_t)k > q) *out = (int64_t)k;
    } else if (d < 0) {
        double k = ceil(x - EPS_PULSE);
        if (!(fabs(k) < BIG)) return BAIL;
        if ((int64_t)k < q) *out = (int64_t)k;
    }
    return OK;
}

/* encoder.Decoder.increment */
static inline int64_t increment(const Axis *a, int64_t q0, int64_t q1, int64_t last_dir)
{
    const int64_t *ai = a->i;
    if (q1 == q0) return 0;
    int dd = q1 > q0 ? 1 : -1;
    int64_t inc = dd != last_dir ? (dd > 0 ? ai[I_TURNF] : ai[I_TURNB]) : 0;
    int64_t n = q1 > q0 ? q1 - q0 : q0 - q1;
    int64_t p = ai[I_DPERIOD];
    if (dd > 0) return inc + run_sum(ai + I_FWD, p, q0, n);
    return inc + run_sum(ai + I_BWD, p, q0 - n + 1, n);
}

/* simaxis.SimAxis._peek: the decoded count with the motor at m on piece p */
static inline int peek(const Axis *a, const PRec *p, double m, int64_t *out)
{
    double z;
    if (p->dir > 0) z = m > p->z0 ? m : p->z0;
    else if (p->dir < 0) { double mb = m + a->d[D_BACKLASH]; z = mb < p->z0 ? mb : p->z0; }
    else z = p->z0;
    int64_t q1;
    if (index_after(a, pitch_forward(a, z), p->q, p->dir, &q1)) return BAIL;
    *out = p->count + increment(a, p->q, q1, p->lastdir);
    return OK;
}

/* StepPiece.m_at / JumpPiece.m_at */
static inline int piece_m_at(const PRec *p, double t, int64_t *m)
{
    if (p->kind == 0 || t >= p->t1) { *m = p->m1; return OK; }
    double c[4] = {p->p0, p->v0, p->a0, p->j};
    int bad = 0;
    int64_t cnt = count_after(cpos(c, t - p->tc), p->c0, p->dir, p->half, &bad);
    if (bad) return BAIL;
    *m = cnt - p->lost;
    return OK;
}

static inline int add_edge(Report *r, double t, int64_t bit, int64_t level, int64_t own)
{
    if (r->ne >= r->cap) return FULL;
    int64_t *e = r->ei + r->ne * NEI;
    r->et[r->ne] = t;
    e[0] = r->axis; e[1] = bit; e[2] = level; e[3] = own;
    r->ne++;
    return OK;
}

/* axis x's view of the flat arrays */
static inline Axis axis_at(double *AD, int64_t *AI, double *SD, int64_t *SI, const double *PZ,
                           Py_ssize_t x)
{
    int64_t *ai = AI + x * NI;
    Axis a = {AD + x * ND, ai, SD + x * MAXSW * NSD, SI + x * MAXSW * NSI,
              ai[I_NPITCH] ? PZ + ai[I_PITCH] : NULL};
    return a;
}

/* _stepper_solve.c: roots and exact times on a cubic */
int stp_quadratic_roots(double c2, double c1, double c0, double lo, double hi, double *out);
int stp_limit_cuts(const double *d, double vmax, double amax, double lo, double hi,
                   double *out);
int stp_piece_time_at(const PRec *p, double level, double *t, int64_t *m);
/* _stepper_scan.c: switches, decoder and edges along a motor piece */
int stp_scan(Axis *a, double m1, int d, Report *r, PRec *p);
int stp_finish_edges(Report *r, Py_ssize_t e0, double *AD, int64_t *AI, double *SD,
                     int64_t *SI, const double *PZ);
/* _stepper_axis.c: one axis over a stretch (generator, plant, armed stops) */
int stp_run_axis_armed(Axis *a, double ta, double tb, Rec *rec, Report *r);

#endif
