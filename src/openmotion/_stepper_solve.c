/* Roots and exact times on a cubic for the stepper pipeline (_kernel_stepper.h):
 * cubic.quadratic_roots, pulses.limit_cuts, cubic.solve_monotone / cubic_time_at and
 * Piece.time_at, in the Python operation order. */
#include "_kernel_stepper.h"

/* cubic.quadratic_roots: real roots strictly inside (lo, hi), ascending, no duplicates */
int stp_quadratic_roots(double c2, double c1, double c0, double lo, double hi, double *out)
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
int stp_limit_cuts(const double *d, double vmax, double amax, double lo, double hi,
                      double *out)
{
    int n = 0;
    if (vmax > 0.0) {
        n += stp_quadratic_roots(d[D_J] / 2.0, d[D_A0], d[D_V0] - vmax, lo, hi, out + n);
        n += stp_quadratic_roots(d[D_J] / 2.0, d[D_A0], d[D_V0] + vmax, lo, hi, out + n);
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
int stp_piece_time_at(const PRec *p, double level, double *t, int64_t *m)
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
