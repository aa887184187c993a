/* The simulator's stepper pipeline over a chunk of cycles (openmotion._kernel.run), called
 * by hw/sim/kernel.py with flat arrays over all axes. For each cycle of the chunk it does
 * what SimMachine.advance does for stepper axes without an armed stop or a pitch table:
 * start queued pieces at their t0, cut the command into monotone stretches (velocity
 * zeros, pull-out cuts), count pulses by the half-pulse rule, apply the stepper plant
 * (stalls lose pulses), the backlash, the switches and the quadrature decoder. Crossings
 * of switches nobody listens to (`wake` 0) only toggle the switch; a crossing that must be
 * reported (`wake` 1) rolls that cycle back and runs it again in report mode, where every
 * crossing of every switch becomes an edge with its exact time (the threshold solved on the
 * stretch's cubic), the level and the own decoded count at that instant, and every other
 * axis's decoded count at that instant (from the cycle's per-axis piece records); the chunk
 * ends after that cycle. Every formula repeats the operation order of the Python pipeline
 * (hw/sim/simaxis.py, pulses.py, plant.py, encoder.py, switches.py, cubic.py: the oracle of
 * tests/test_kernel_*.py) exactly (compiled with -ffp-contract=off), so the floats are
 * bit-identical.
 */
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

/* cubic.quadratic_roots: real roots strictly inside (lo, hi), ascending, no duplicates */
static int quadratic_roots(double c2, double c1, double c0, double lo, double hi, double *out)
{
    double r[2];
    int n = 0, m = 0;
    if (c2 == 0.0) {
        if (c1 == 0.0) return 0;
        r[n++] = -c0 / c1;
    } else {
        double disc = c1 * c1 - 4.0 * c2 * c0;
        if (disc < 0.0) return 0;
        double sq = sqrt(disc);
        double q = -0.5 * (c1 + copysign(sq, c1));
        if (q != 0.0) {
            r[n++] = q / c2;
            r[n++] = c0 / q;
            if (r[1] == r[0]) n = 1;
        } else {
            r[n++] = 0.0;
        }
    }
    if (n == 2 && r[1] < r[0]) { double t = r[0]; r[0] = r[1]; r[1] = t; }
    for (int k = 0; k < n; k++)
        if (lo < r[k] && r[k] < hi) out[m++] = r[k];
    return m;
}

/* pulses.limit_cuts */
static int limit_cuts(const double *d, double vmax, double amax, double lo, double hi,
                      double *out)
{
    int n = 0;
    if (vmax > 0.0) {
        n += quadratic_roots(d[D_J] / 2.0, d[D_A0], d[D_V0] - vmax, lo, hi, out + n);
        n += quadratic_roots(d[D_J] / 2.0, d[D_A0], d[D_V0] + vmax, lo, hi, out + n);
    }
    if (amax > 0.0 && d[D_J] != 0.0) {
        double as[2] = {amax, -amax};
        for (int k = 0; k < 2; k++) {
            double s = (as[k] - d[D_A0]) / d[D_J];
            if (lo < s && s < hi) out[n++] = s;
        }
    }
    return n;
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

/* cubic.solve_monotone with f = the cubic's position, df = its velocity */
static double solve_monotone(const double *c, double lo, double hi, double target)
{
    double flo = cpos(c, lo) - target, fhi = cpos(c, hi) - target;
    if (flo == 0.0) return lo;
    if (fhi == 0.0) return hi;
    if ((flo > 0.0) == (fhi > 0.0)) return fabs(flo) <= fabs(fhi) ? lo : hi;
    double lo_neg, hi_pos;
    if (flo > 0.0) { lo_neg = hi; hi_pos = lo; }
    else { lo_neg = lo; hi_pos = hi; }
    double s = lo - flo * (hi - lo) / (fhi - flo);
    for (int it = 0; it < 100; it++) {
        double fs = cpos(c, s) - target;
        if (fs == 0.0) return s;
        if (fs < 0.0) lo_neg = s;
        else hi_pos = s;
        double width = fabs(hi_pos - lo_neg);
        if (width <= TIME_TOL * pmax(1.0, fabs(s))) return 0.5 * (lo_neg + hi_pos);
        double d = cvel(c, s);
        int step_ok = 0;
        if (d != 0.0) {
            double s_new = s - fs / d;
            if (pmin(lo_neg, hi_pos) < s_new && s_new < pmax(lo_neg, hi_pos)
                    && fabs(s_new - s) < 0.5 * width) {
                s = s_new;
                step_ok = 1;
            }
        }
        if (!step_ok) s = 0.5 * (lo_neg + hi_pos);
    }
    return s;
}

/* cubic.cubic_time_at */
static double cubic_time_at(const double *c, double level, double lo, double hi)
{
    if (c[D_J] == 0.0 && c[D_A0] == 0.0 && c[D_V0] != 0.0) {
        double s = (level - c[D_P0]) / c[D_V0];
        return pmin(pmax(s, lo), hi);
    }
    return solve_monotone(c, lo, hi, level);
}

/* Piece.time_at: the time the motor first reaches `level` on the piece, and m there */
static int piece_time_at(const PRec *p, double level, double *t, int64_t *m)
{
    if (p->kind == 0) { *t = p->t0; *m = p->m1; return OK; }
    double kk = ceil(level + (double)p->lost);
    if (!(fabs(kk) < BIG)) return BAIL;
    int64_t k = (int64_t)kk - (p->dir > 0 ? 0 : 1);
    double u = p->dir > 0 ? (double)k - p->half : (double)k + p->half;
    double c[4] = {p->p0, p->v0, p->a0, p->j};
    double s = cubic_time_at(c, u, p->t0 - p->tc, p->t1 - p->tc);
    *t = pmin(pmax(p->tc + s, p->t0), p->t1);
    *m = k - p->lost;
    return OK;
}

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

/* SimAxis.encoder_at: axis x's decoded count at time t within the current stretch */
static int encoder_at(const Axis *a, const Report *r, Py_ssize_t x, double t, int64_t *out)
{
    const PRec *rec = r->pr + r->rbeg[x];
    Py_ssize_t k = r->rcnt[x] - 1;
    while (k >= 0 && rec[k].t0 > t) k--;
    if (k < 0) { *out = r->rcnt[x] ? rec[0].count : r->start[x]; return OK; }
    int64_t m;
    if (piece_m_at(rec + k, t, &m)) return BAIL;
    return peek(a, rec + k, (double)m, out);
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

/* simaxis.SimAxis.scan for one motor piece ending at m1 in direction d; in report mode
 * (r->on) `p` describes the piece and every crossing is an edge (SimAxis._scan_switch) */
static int scan(Axis *a, double m1, int d, Report *r, PRec *p)
{
    double *ad = a->d;
    int64_t *ai = a->i;
    double z0 = ad[D_Z], z1;
    if (r->on && !r->dry) { /* the record SimAxis.scan keeps for encoder_at */
        if (r->rcnt[r->axis] >= MAXPREC) return BAIL;
        p->z0 = z0; p->q = ai[I_Q]; p->lastdir = ai[I_LASTDIR]; p->count = ai[I_DCOUNT];
        r->pr[r->rbeg[r->axis] + r->rcnt[r->axis]++] = *p;
    }
    if (d > 0) {
        z1 = m1 > z0 ? m1 : z0;
    } else {
        double mb = m1 + ad[D_BACKLASH];
        z1 = mb < z0 ? mb : z0;
    }
    double y1 = pitch_forward(a, z1), y = ad[D_Y];
    r->hit_s = -1;
    if (y1 != y || r->dry) {
        int nsw = (int)ai[I_NSW];
        for (int s = 0; s < nsw; s++) {
            double *sw = a->sd + s * NSD;
            int64_t *si = a->si + s * NSI;
            double thr;
            if (!next_threshold(sw, (int)si[S_ACTIVE], y, d, &thr)) continue;
            if (d > 0 ? y1 < thr : y1 >= thr) continue;
            if (si[S_WAKE] && !r->on && !r->dry) return WAKE; /* again, reporting */
            double yy = y;
            for (int k = 0; k < MAX_TOGGLES; k++) {
                if (!next_threshold(sw, (int)si[S_ACTIVE], yy, d, &thr)) break;
                if (d > 0 ? y1 < thr : y1 >= thr) break;
                double et = 0.0;
                int64_t em = 0;
                if (r->dry) { /* SimAxis._first_armed */
                    si[S_ACTIVE] = !si[S_ACTIVE];
                    int64_t lv = ((ai[I_LEVELS] >> si[S_BIT]) & 1) ^ si[S_ACTIVE];
                    if (si[S_ARM] && lv == si[S_ARMLEVEL]
                            && (si[S_ARMDIR] == 0 || si[S_ARMDIR] == d)) {
                        double level = motor_level(a, thr, d);
                        if (piece_time_at(p, level, &et, &em)) return BAIL;
                        if (r->hit_s < 0 || et < r->hit_t
                                || (et == r->hit_t && si[S_ARM] < r->hit_rank)) {
                            r->hit_t = et; r->hit_s = s; r->hit_rank = (int)si[S_ARM];
                        }
                        break;
                    }
                    yy = thr;
                    continue;
                }
                if (r->on) {
                    double level = motor_level(a, thr, d);
                    if (piece_time_at(p, level, &et, &em)) return BAIL;
                }
                si[S_ACTIVE] = !si[S_ACTIVE];
                if (r->on) {
                    int64_t own, bit = si[S_BIT], act = si[S_ACTIVE];
                    if (peek(a, p, (double)em, &own)) return BAIL;
                    int st = add_edge(r, et, bit, ((ai[I_LEVELS] >> bit) & 1) ^ act, own);
                    if (st) return st;
                    if (si[S_LEVELBITS] && si[S_LEVELBITS] != ((int64_t)1 << bit)) {
                        /* SD is also LTC */
                        st = add_edge(r, et, LTC_BIT, ((ai[I_LEVELS] >> LTC_BIT) & 1) ^ act,
                                      own);
                        if (st) return st;
                    }
                }
                yy = thr;
            }
        }
    }
    if (r->dry && r->hit_s >= 0) return HIT;
    ad[D_Z] = z1;
    ad[D_Y] = y1;
    return decoder_advance(a, y1, d);
}

static inline int record(Rec *rec, int kind, double t0, double t1, double tc, const double *d,
                         int dir, int64_t c0, int64_t c1)
{
    if (rec->n >= rec->cap) return BAIL;
    double *r = rec->rows + rec->n * NREC;
    r[0] = rec->axis; r[1] = kind; r[2] = t0; r[3] = t1; r[4] = tc;
    if (kind) { r[5] = d[D_P0]; r[6] = d[D_V0]; r[7] = d[D_A0]; r[8] = d[D_J]; }
    else { r[5] = r[6] = r[7] = r[8] = 0.0; }
    r[9] = dir; r[10] = (double)c0; r[11] = (double)c1;
    rec->n++;
    return OK;
}

/* StepperPlant.pieces (with PulseGenerator.stretches) + scan over [ta, tb] */
static int run_axis(Axis *a, double ta, double tb, Rec *rec, Report *r)
{
    PRec pr;
    double *ad = a->d;
    int64_t *ai = a->i;
    double tc = ad[D_TC], te = ad[D_TE], half = ad[D_HALF];
    double vmax = ad[D_VMAX], amax = ad[D_AMAX];
    int ideal = (int)ai[I_IDEAL], enabled = (int)ai[I_ENABLED], rec_on = (int)ai[I_RECORD];
    int bad = 0;
    double cuts[8];
    int ncut = 0;
    if (vmax > 0.0 || amax > 0.0) ncut = limit_cuts(ad, vmax, amax, ta - tc, tb - tc, cuts);
    /* PulseGenerator.pos(ta), then _jump_to */
    double x = ta - tc;
    double mx = 0.0 > x ? 0.0 : x;
    double lim = te - tc;
    double s = lim < mx ? lim : mx;
    double u = cpos(ad, s);
    int64_t c0 = ai[I_COUNT];
    int64_t c1 = count_after(u, c0, u > (double)c0 ? 1 : -1, half, &bad);
    if (bad) return BAIL;
    if (c1 != c0) {
        ai[I_COUNT] = c1;
        int dir = c1 > c0 ? 1 : -1;
        if (rec_on && record(rec, 0, ta, ta, ta, ad, dir, c0, c1)) return BAIL;
        if (enabled && ideal) {
            if (r->on || r->dry) { /* JumpPiece(ta, c0 - lost, c1 - lost) */
                pr.kind = 0; pr.dir = dir; pr.t0 = pr.t1 = pr.tc = ta;
                pr.m1 = c1 - ai[I_LOST];
            }
            int st = scan(a, (double)(c1 - ai[I_LOST]), dir, r, &pr);
            if (st) return st;
        } else {
            ai[I_LOST] += c1 - c0;
        }
    }
    double lo = tc > ta ? tc : ta, hi = te < tb ? te : tb;
    if (!(hi > lo)) return OK;
    double s_lo = lo - tc, s_hi = hi - tc;
    double pts[12];
    int np = 0;
    pts[np++] = s_lo;
    np += quadratic_roots(ad[D_J] / 2.0, ad[D_A0], ad[D_V0], s_lo, s_hi, pts + np);
    for (int k = 0; k < ncut; k++)
        if (s_lo < cuts[k] && cuts[k] < s_hi) pts[np++] = cuts[k];
    for (int k = 1; k < np; k++) { /* insertion sort (a handful of points) */
        double v = pts[k];
        int m = k - 1;
        while (m >= 0 && pts[m] > v) { pts[m + 1] = pts[m]; m--; }
        pts[m + 1] = v;
    }
    pts[np++] = s_hi;
    for (int k = 0; k + 1 < np; k++) {
        double s0 = pts[k], s1 = pts[k + 1];
        if (s1 <= s0) continue;
        double p0 = cpos(ad, s0), p1 = cpos(ad, s1);
        int d = p1 > p0 ? 1 : (p1 < p0 ? -1 : 0);
        c0 = ai[I_COUNT];
        c1 = count_after(p1, c0, d, half, &bad);
        if (bad) return BAIL;
        ai[I_COUNT] = c1;
        double t0 = tc + s0, t1 = tc + s1;
        if (rec_on && c1 != c0 && record(rec, 1, t0, t1, tc, ad, d, c0, c1)) return BAIL;
        if (d == 0) continue;
        double mid = 0.5 * (t0 + t1) - tc;
        int over = (vmax > 0.0 && fabs(cvel(ad, mid)) > vmax)
                   || (amax > 0.0 && fabs(cacc(ad, mid)) > amax);
        if (!enabled || over) {
            ai[I_LOST] += c1 - c0;
            continue;
        }
        if (c1 == c0) continue;
        if (r->on || r->dry) { /* StepPiece(cubic, tc, t0, t1, c0, c1, lost, d, half) */
            pr.kind = 1; pr.dir = d; pr.t0 = t0; pr.t1 = t1; pr.tc = tc;
            pr.p0 = ad[D_P0]; pr.v0 = ad[D_V0]; pr.a0 = ad[D_A0]; pr.j = ad[D_J];
            pr.half = half; pr.c0 = c0; pr.lost = ai[I_LOST]; pr.m1 = c1 - ai[I_LOST];
        }
        int st = scan(a, (double)(c1 - ai[I_LOST]), d, r, &pr);
        if (st) return st;
    }
    return OK;
}

/* SimAxis.run over [ta, tb]: with an armed stop (and the command not over by ta) the dry
 * scan finds the first armed edge; then the axis runs up to its time, the edge is made if
 * rounding left it a hair short, the pulse output stops (the command holds the count
 * emitted, SimAxis.cut_pulses) and the axis runs on to tb. Outside report mode a hit
 * returns WAKE (the cycle is run again reporting). */
static int run_axis_armed(Axis *a, double ta, double tb, Rec *rec, Report *r)
{
    double *ad = a->d;
    int64_t *ai = a->i, *si = a->si;
    if (!ai[I_ARMED] || !(ad[D_TE] > ta)) return run_axis(a, ta, tb, rec, r);
    double sd_[ND];
    int64_t si_[MAXSW * NSI], ai_[NI];
    memcpy(sd_, ad, sizeof sd_);
    memcpy(ai_, ai, sizeof ai_);
    memcpy(si_, si, sizeof si_);
    Py_ssize_t rows0 = rec->n;
    int on = r->on;
    r->dry = 1;
    r->on = 0;
    int st = run_axis(a, ta, tb, rec, r);
    r->dry = 0;
    r->on = on;
    double ts = r->hit_t;
    int hs = r->hit_s;
    memcpy(ad, sd_, sizeof sd_); /* the dry scan leaves no trace */
    memcpy(ai, ai_, sizeof ai_);
    memcpy(si, si_, sizeof si_);
    rec->n = rows0;
    if (st == OK) return run_axis(a, ta, tb, rec, r);
    if (st != HIT) return st;
    if (!r->on) return WAKE;
    if (ai[I_RECORD]) return BAIL; /* the cut command goes into the pulse record: Python */
    Py_ssize_t e0 = r->ne;
    st = run_axis(a, ta, ts, rec, r);
    if (st) return st;
    int64_t *sw = si + hs * NSI, bit = sw[S_BIT];
    int seen = 0;
    for (Py_ssize_t k = e0; k < r->ne; k++)
        if (r->ei[k * NEI] == r->axis && r->ei[k * NEI + 1] == bit) seen = 1;
    if (!seen) { /* rounding left the motor a hair short of the switch: the edge is at ts */
        sw[S_ACTIVE] = !sw[S_ACTIVE];
        st = add_edge(r, ts, bit, ((ai[I_LEVELS] >> bit) & 1) ^ sw[S_ACTIVE], ai[I_DCOUNT]);
        if (st) return st;
    }
    ad[D_P0] = (double)ai[I_COUNT];
    ad[D_V0] = ad[D_A0] = ad[D_J] = 0.0;
    ad[D_TC] = ad[D_TE] = ts;
    ad[D_STOP] = ts;
    return run_axis(a, ts, tb, rec, r);
}

const char kernel_run_doc[] =
"run(ad, ai, sd, si, pieces, popt, rows, trace, et, ei, enc, pitch, origin, period, start,\n"
"    stop, now, limit, report, paced)\n"
"-> (cycle reached, hardware time, record rows used, edges, edge room short)\n\n"
"Run cycles start+1..stop over float64 ad[n, ND], int64 ai[n, NI], float64 sd[n, 8, NSD],\n"
"int64 si[n, 8, NSI], float64 pieces[P, 6] (t0, dt, p0, v0, a0, j) with each axis's range\n"
"and cursor in ai, popt[P] (the time each piece started; empty: not wanted), rows[R, 12]\n"
"(pulse record), int64 trace[stop - start, n, 3] (per cycle: pulse count, decoded count,\n"
"input levels; an empty array: no trace), the edges of the last cycle run: float64 et[E]\n"
"(times), int64 ei[E, 4] (axis, signal bit, level, own count), int64 enc[E, n] (every\n"
"axis's decoded count at the edge), float64 pitch[...] (the pitch-error tables, each axis's\n"
"at ai's I_PITCH). `report` 1: every cycle reports its edges (advance);\n"
"0: a cycle reports only when a switch with `wake` set is crossed. `paced` 0: no\n"
"real-time slot waits. Stops before the first cycle ending at or after `limit` or one the\n"
"kernel cannot run exactly (the caller runs it), or after the first cycle with edges; with\n"
"`edge room short` the edge arrays were too small for that cycle (not run: call again\n"
"with larger ones).";

/* axis x's view of the flat arrays */
static inline Axis axis_at(double *AD, int64_t *AI, double *SD, int64_t *SI, const double *PZ,
                           Py_ssize_t x)
{
    int64_t *ai = AI + x * NI;
    Axis a = {AD + x * ND, ai, SD + x * MAXSW * NSD, SI + x * MAXSW * NSI,
              ai[I_NPITCH] ? PZ + ai[I_PITCH] : NULL};
    return a;
}

/* the edges of one stretch [now, tn] in time order (stable, as SimMachine._advance sorts
 * them) with every axis's decoded count at each edge's instant */
static int finish_edges(Report *r, Py_ssize_t e0, double *AD, int64_t *AI, double *SD,
                        int64_t *SI, const double *PZ)
{
    for (Py_ssize_t k = e0 + 1; k < r->ne; k++) { /* insertion sort: stable */
        double t = r->et[k];
        int64_t row[NEI];
        memcpy(row, r->ei + k * NEI, sizeof row);
        Py_ssize_t m = k - 1;
        while (m >= e0 && r->et[m] > t) {
            r->et[m + 1] = r->et[m];
            memcpy(r->ei + (m + 1) * NEI, r->ei + m * NEI, sizeof row);
            m--;
        }
        r->et[m + 1] = t;
        memcpy(r->ei + (m + 1) * NEI, row, sizeof row);
    }
    for (Py_ssize_t k = e0; k < r->ne; k++) {
        int64_t *enc = r->enc + k * r->n, axis = r->ei[k * NEI];
        for (Py_ssize_t x = 0; x < r->n; x++) {
            if (x == axis && r->ei[k * NEI + 1] < HIDDEN_BIT) {
                enc[x] = r->ei[k * NEI + 3]; /* (a hidden switch's: encoder_at, as Python) */
                continue;
            }
            Axis a = axis_at(AD, AI, SD, SI, PZ, x);
            if (encoder_at(&a, r, x, r->et[k], enc + x)) return BAIL;
        }
    }
    return OK;
}

#define NBUF 12

PyObject *kernel_run(PyObject *self, PyObject *args)
{
    PyObject *o[NBUF];
    double origin, period, now, limit;
    long long start, stop;
    int report_all, paced;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOOddLLddpp", &o[0], &o[1], &o[2], &o[3], &o[4],
                          &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11], &origin, &period,
                          &start, &stop, &now, &limit, &report_all, &paced))
        return NULL;
    Buf bufs[NBUF];
    memset(bufs, 0, sizeof bufs);
    static const char *names[NBUF] = {"ad", "ai", "sd", "si", "pieces", "popt", "rows",
                                      "trace", "et", "ei", "enc", "pitch"};
    for (int k = 0; k < NBUF; k++)
        if (get_buf(o[k], &bufs[k], 8, names[k]) < 0) { release(bufs, NBUF); return NULL; }
    Py_ssize_t n = bufs[0].b.len / (8 * ND);
    Py_ssize_t ecap = bufs[8].b.len / 8;
    if (bufs[1].b.len != n * 8 * NI || bufs[2].b.len != n * 8 * MAXSW * NSD
            || bufs[3].b.len != n * 8 * MAXSW * NSI || bufs[9].b.len != ecap * 8 * NEI
            || bufs[10].b.len != ecap * 8 * n) {
        release(bufs, NBUF);
        PyErr_SetString(PyExc_ValueError, "run: axis or edge arrays disagree in size");
        return NULL;
    }
    double *AD = bufs[0].b.buf, *SD = bufs[2].b.buf, *PC = bufs[4].b.buf;
    int64_t *AI = bufs[1].b.buf, *SI = bufs[3].b.buf;
    Py_ssize_t npieces = bufs[4].b.len / (8 * 6);
    const double *PZ = bufs[11].b.buf;
    Py_ssize_t npitch = bufs[11].b.len / 8;
    /* piece start times only when the caller passes room for them (pulse recording) */
    double *PT = bufs[5].b.len >= npieces * 8 ? bufs[5].b.buf : NULL;
    for (Py_ssize_t x = 0; x < n; x++) {
        int64_t *ai = AI + x * NI, *si = SI + x * MAXSW * NSI;
        if (ai[I_PBEGIN] < 0 || ai[I_PEND] > npieces || ai[I_CURSOR] < ai[I_PBEGIN]
                || ai[I_CURSOR] > ai[I_PEND] || ai[I_NSW] < 0 || ai[I_NSW] > MAXSW
                || ai[I_DPERIOD] < 1 || ai[I_DPERIOD] > 4 || ai[I_NPITCH] < 0
                || ai[I_PITCH] < 0 || ai[I_PITCH] + 3 * ai[I_NPITCH] > npitch) {
            release(bufs, NBUF);
            PyErr_SetString(PyExc_ValueError, "run: bad axis layout");
            return NULL;
        }
        for (int sw = 0; sw < ai[I_NSW]; sw++)
            if (si[sw * NSI + S_BIT] < 0 || si[sw * NSI + S_BIT] > 62) {
                release(bufs, NBUF);
                PyErr_SetString(PyExc_ValueError, "run: bad switch bit");
                return NULL;
            }
    }
    Rec rec = {bufs[6].b.buf, 0, bufs[6].b.len / (8 * NREC), 0};
    /* trace[cycle - start - 1, axis] = (pulse count, decoded count, input levels: I_LEVELS
     * with the S_LEVELBITS of every active switch flipped) when the
     * caller asks for it (a buffer large enough for every cycle), else none */
    int64_t *TR = bufs[7].b.len >= (stop - start) * n * 3 * 8 ? bufs[7].b.buf : NULL;
    double *save_d = PyMem_Malloc(sizeof(double) * (n * ND + 1));
    int64_t *save_i = PyMem_Malloc(sizeof(int64_t) * (n * NI + n * MAXSW * NSI + 1));
    PRec *prec = PyMem_Malloc(sizeof(PRec) * (n * MAXPREC + 1));
    Py_ssize_t *rix = PyMem_Malloc(sizeof(Py_ssize_t) * (2 * n + 1));
    int64_t *rstart = PyMem_Malloc(sizeof(int64_t) * (n + 1));
    if (!save_d || !save_i || !prec || !rix || !rstart) {
        PyMem_Free(save_d); PyMem_Free(save_i); PyMem_Free(prec); PyMem_Free(rix);
        PyMem_Free(rstart); release(bufs, NBUF);
        return PyErr_NoMemory();
    }
    Report rep = {0, 0, 0.0, -1, 0, bufs[8].b.buf, bufs[9].b.buf, bufs[10].b.buf, 0, ecap, n, prec, 0,
                  rix, rix + n, rstart, 0};
    for (Py_ssize_t x = 0; x < n; x++) rix[x] = x * MAXPREC;
    long long k = start;
    int full = 0;
    Py_BEGIN_ALLOW_THREADS
    while (k < stop) {
        double t = origin + (double)(k + 1) * period;
        if (paced && rt_before_cycle(k + 1, k == start)) break; /* real time: its slot (_kernel_rt.c) */
        if (t >= limit) break;
        int report = report_all;
    redo:
        memcpy(save_d, AD, sizeof(double) * n * ND);
        memcpy(save_i, AI, sizeof(int64_t) * n * NI);
        memcpy(save_i + n * NI, SI, sizeof(int64_t) * n * MAXSW * NSI);
        Py_ssize_t rows0 = rec.n;
        double now0 = now;
        int status = OK;
        rep.on = report;
        rep.ne = 0;
        for (;;) { /* SimMachine.advance: start due pieces, run to the next start or t */
            double tn = t;
            for (Py_ssize_t x = 0; x < n; x++) {
                double *ad = AD + x * ND;
                int64_t *ai = AI + x * NI;
                while (ai[I_CURSOR] < ai[I_PEND] && PC[ai[I_CURSOR] * 6] <= now) {
                    const double *pc = PC + ai[I_CURSOR] * 6;
                    ad[D_P0] = pc[2]; ad[D_V0] = pc[3]; ad[D_A0] = pc[4]; ad[D_J] = pc[5];
                    ad[D_TC] = pc[0]; ad[D_TE] = pc[0] + pc[1];
                    if (PT != NULL) PT[ai[I_CURSOR]] = now;
                    ai[I_CURSOR]++;
                }
                if (ai[I_CURSOR] < ai[I_PEND] && PC[ai[I_CURSOR] * 6] < tn)
                    tn = PC[ai[I_CURSOR] * 6];
            }
            Py_ssize_t e0 = rep.ne;
            if (rep.on)
                for (Py_ssize_t x = 0; x < n; x++) {
                    rix[n + x] = 0;
                    rstart[x] = AI[x * NI + I_DCOUNT];
                }
            for (Py_ssize_t x = 0; x < n && status == OK; x++) {
                Axis a = axis_at(AD, AI, SD, SI, PZ, x);
                rec.axis = (int)x;
                rep.axis = (int)x;
                AD[x * ND + D_STOP] = NAN; /* SimMachine._advance: stop_time = None */
                status = run_axis_armed(&a, now, tn, &rec, &rep);
            }
            if (status == OK && rep.on && rep.ne > e0)
                status = finish_edges(&rep, e0, AD, AI, SD, SI, PZ);
            if (status != OK) break;
            now = tn;
            if (tn >= t) break;
        }
        if (status != OK) { /* roll the cycle back */
            memcpy(AD, save_d, sizeof(double) * n * ND);
            memcpy(AI, save_i, sizeof(int64_t) * n * NI);
            memcpy(SI, save_i + n * NI, sizeof(int64_t) * n * MAXSW * NSI);
            rec.n = rows0;
            now = now0;
            rep.ne = 0;
            if (status == WAKE && !report) { /* the same cycle again, reporting */
                report = 1;
                goto redo;
            }
            full = status == FULL;
            break; /* BAIL: the caller runs this cycle; FULL: again with more room */
        }
        if (TR != NULL) {
            int64_t *tr = TR + (k - start) * n * 3;
            for (Py_ssize_t x = 0; x < n; x++) {
                const int64_t *ai = AI + x * NI, *si = SI + x * MAXSW * NSI;
                int64_t levels = ai[I_LEVELS];
                for (int sw = 0; sw < ai[I_NSW]; sw++)
                    if (si[sw * NSI + S_ACTIVE]) levels ^= si[sw * NSI + S_LEVELBITS];
                tr[x * 3] = ai[I_COUNT];
                tr[x * 3 + 1] = ai[I_DCOUNT];
                tr[x * 3 + 2] = levels;
            }
        }
        if (paced) rt_after_cycle(k + 1);
        k++;
        if (rep.ne) break; /* edges: the caller's hooks see them at this cycle's end */
    }
    Py_END_ALLOW_THREADS
    PyMem_Free(save_d);
    PyMem_Free(save_i);
    PyMem_Free(prec);
    PyMem_Free(rix);
    PyMem_Free(rstart);
    release(bufs, NBUF);
    return Py_BuildValue("LdNni", k, now, PyLong_FromSsize_t(rec.n), rep.ne, full);
}

int kernel_layout(PyObject *m)
{
    return (PyModule_AddIntConstant(m, "ND", ND) < 0 || PyModule_AddIntConstant(m, "NI", NI) < 0
            || PyModule_AddIntConstant(m, "MAXSW", MAXSW) < 0
            || PyModule_AddIntConstant(m, "NSD", NSD) < 0
            || PyModule_AddIntConstant(m, "NSI", NSI) < 0
            || PyModule_AddIntConstant(m, "NREC", NREC) < 0) ? -1 : 0;
}

const char kernel_readback_doc[] =
"readback(ai, si, out) -> None\n\n"
"out int64[n, 3] = (pulse count, decoded count, input level bits) of every axis of the\n"
"kernel's arrays ai[n, NI], si[n, 8, NSI] (the level base word with the bits of every\n"
"active switch flipped), as a trace row.";

PyObject *kernel_readback(PyObject *self, PyObject *args)
{
    PyObject *o[3];
    if (!PyArg_ParseTuple(args, "OOO", &o[0], &o[1], &o[2])) return NULL;
    Buf bufs[3];
    memset(bufs, 0, sizeof bufs);
    static const char *names[3] = {"ai", "si", "out"};
    for (int k = 0; k < 3; k++)
        if (get_buf(o[k], &bufs[k], 8, names[k]) < 0) { release(bufs, 3); return NULL; }
    Py_ssize_t n = bufs[0].b.len / (8 * NI);
    if (bufs[0].b.len != n * 8 * NI || bufs[1].b.len != n * 8 * MAXSW * NSI
            || bufs[2].b.len != n * 8 * 3) {
        release(bufs, 3);
        PyErr_SetString(PyExc_ValueError, "readback: arrays disagree in size");
        return NULL;
    }
    const int64_t *AI = bufs[0].b.buf, *SI = bufs[1].b.buf;
    int64_t *out = bufs[2].b.buf;
    for (Py_ssize_t x = 0; x < n; x++) {
        const int64_t *ai = AI + x * NI, *si = SI + x * MAXSW * NSI;
        int64_t levels = ai[I_LEVELS];
        int nsw = ai[I_NSW] < 0 ? 0 : (ai[I_NSW] > MAXSW ? MAXSW : (int)ai[I_NSW]);
        for (int sw = 0; sw < nsw; sw++)
            if (si[sw * NSI + S_ACTIVE]) levels ^= si[sw * NSI + S_LEVELBITS];
        out[x * 3] = ai[I_COUNT];
        out[x * 3 + 1] = ai[I_DCOUNT];
        out[x * 3 + 2] = levels;
    }
    release(bufs, 3);
    Py_RETURN_NONE;
}
