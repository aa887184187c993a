/* The simulator's stepper pipeline over a chunk of cycles (openmotion._kernel.run), called
 * by hw/sim/kernel.py with flat arrays over all axes. For each cycle of the chunk it does
 * what SimMachine.advance does for stepper axes (armed edge stops and pitch tables too):
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
 *
 * This file: the cycle loop (`run`: queued pieces started at their t0, every axis run
 * over each stretch, a cycle rolled back and run again reporting, the trace), the layout
 * constants and `readback`. The parts: _stepper_axis.c (one axis over a stretch),
 * _stepper_scan.c (switches, decoder, edges), _stepper_solve.c (roots and times on a
 * cubic), _kernel_stepper.h (layout, structs, shared formulas).
 */
#include "_kernel_stepper.h"

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
    /* the rollback copy: AD, AI and the only field of SI a cycle writes (S_ACTIVE) */
    int64_t *save_i = PyMem_Malloc(sizeof(int64_t) * (n * NI + n * MAXSW + 1));
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
        for (Py_ssize_t q = 0; q < n * MAXSW; q++) save_i[n * NI + q] = SI[q * NSI + S_ACTIVE];
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
                status = stp_run_axis_armed(&a, now, tn, &rec, &rep);
            }
            if (status == OK && rep.on && rep.ne > e0)
                status = stp_finish_edges(&rep, e0, AD, AI, SD, SI, PZ);
            if (status != OK) break;
            now = tn;
            if (tn >= t) break;
        }
        if (status != OK) { /* roll the cycle back */
            memcpy(AD, save_d, sizeof(double) * n * ND);
            memcpy(AI, save_i, sizeof(int64_t) * n * NI);
            for (Py_ssize_t q = 0; q < n * MAXSW; q++) SI[q * NSI + S_ACTIVE] = save_i[n * NI + q];
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
