/* Switches, decoder and edges along a motor piece for the stepper pipeline
 * (_kernel_stepper.h): SimAxis.scan (every switch threshold crossed, toggled or reported
 * as an edge with its exact time and own count; the dry scan for an armed stop),
 * SimAxis.encoder_at from the stretch's piece records, and a stretch's edges put in time
 * order with every axis's count at each. */
#include "_kernel_stepper.h"

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

/* simaxis.SimAxis.scan for one motor piece ending at m1 in direction d; in report mode
 * (r->on) `p` describes the piece and every crossing is an edge (SimAxis._scan_switch) */
int stp_scan(Axis *a, double m1, int d, Report *r, PRec *p)
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
                        if (stp_piece_time_at(p, level, &et, &em)) return BAIL;
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
                    if (stp_piece_time_at(p, level, &et, &em)) return BAIL;
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

/* the edges of one stretch [now, tn] in time order (stable, as SimMachine._advance sorts
 * them) with every axis's decoded count at each edge's instant */
int stp_finish_edges(Report *r, Py_ssize_t e0, double *AD, int64_t *AI, double *SD,
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
