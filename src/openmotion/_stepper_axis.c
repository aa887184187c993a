/* One axis over a stretch for the stepper pipeline (_kernel_stepper.h): the pulse
 * generator's monotone stretches (velocity zeros, pull-out cuts), pulses by the half-pulse
 * rule, the stepper plant (a stall loses them), the pulse record's rows, and the armed edge
 * stop (dry scan, run up to the edge, cut, run on), as StepperPlant.pieces,
 * PulseGenerator.stretches and SimAxis.run / _run_armed. */
#include "_kernel_stepper.h"

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
    if (vmax > 0.0 || amax > 0.0) ncut = stp_limit_cuts(ad, vmax, amax, ta - tc, tb - tc, cuts);
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
            int st = stp_scan(a, (double)(c1 - ai[I_LOST]), dir, r, &pr);
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
    np += stp_quadratic_roots(ad[D_J] / 2.0, ad[D_A0], ad[D_V0], s_lo, s_hi, pts + np);
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
        int st = stp_scan(a, (double)(c1 - ai[I_LOST]), d, r, &pr);
        if (st) return st;
    }
    return OK;
}

/* SimAxis.run over [ta, tb]: with an armed stop (and the command not over by ta) the dry
 * scan finds the first armed edge; then the axis runs up to its time, the edge is made if
 * rounding left it a hair short, the pulse output stops (the command holds the count
 * emitted, SimAxis.cut_pulses) and the axis runs on to tb. Outside report mode a hit
 * returns WAKE (the cycle is run again reporting). */
int stp_run_axis_armed(Axis *a, double ta, double tb, Rec *rec, Report *r)
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
