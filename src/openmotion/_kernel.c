/* openmotion's compiled inner loops (openmotion._kernel): one extension, three entry
 * points over arrays (`pieces` and `run` release the GIL while they run).
 *
 * `pieces` (control/motion.py, ActiveMotion.pieces): the cubic piece of every cycle of a
 * chunk, exactly as ActiveMotion.piece computes it one cycle at a time.
 * `check_rows` (hw/sim/piecequeue.py): the first malformed piece of a block.
 * `run` (hw/sim/kernel.py; in _kernel_stepper.c): the simulator's stepper pipeline over a
 * chunk of cycles, with flat arrays over all axes.
 *
 * Every formula repeats the Python operation order exactly, so the floats are bit-identical
 * (compiled with -ffp-contract=off: no fused multiply-add).
 */
#include "_kernel.h"

/* ActiveMotion.piece(t0, t1) for one cycle; seg arrays ts, sp, sv, sa, sj of length ns */
static void piece(const double *ts, const double *sp, const double *sv, const double *sa,
                  const double *sj, Py_ssize_t ns, double t_start, double dur, double ep,
                  double ev, double left_v, double t0, double t1, double *o)
{
    double u0 = t0 - t_start, u1 = t1 - t_start;
    if (u0 >= dur || ns == 0) {
        double p0 = ep + ev * (u0 - dur);
        o[0] = p0; o[1] = ev; o[2] = 0.0; o[3] = 0.0; o[4] = p0 + ev * (u1 - u0); o[5] = ev;
        return;
    }
    /* ActiveMotion._seg: the last segment starting at or before u0 (Python's index -1,
     * the last segment, when none does) */
    Py_ssize_t lo = 0, hi = ns;
    while (lo < hi) { Py_ssize_t mid = (lo + hi) / 2; if (u0 < ts[mid]) hi = mid; else lo = mid + 1; }
    Py_ssize_t k = lo - 1;
    Py_ssize_t ke = k < 0 ? k + ns : k;
    double s = u0 - ts[ke];
    double j = sj[ke], a = sa[ke], v = sv[ke];
    double p0 = sp[ke] + s * (v + s * (a * 0.5 + s * j / 6.0));
    double v0 = v + s * (a + s * j * 0.5);
    double a0 = a + s * j;
    double nxt = k + 1 < ns ? ts[k + 1] : dur;
    if (u1 <= nxt && u1 < dur) {
        double h = u1 - u0;
        o[0] = p0; o[1] = v0; o[2] = a0; o[3] = j;
        o[4] = p0 + h * (v0 + h * (a0 * 0.5 + h * j / 6.0));
        o[5] = v0 + h * (a0 + h * j * 0.5);
        return;
    }
    double p1, v1;
    if (u1 >= dur) {
        p1 = ep + ev * (u1 - dur);
        v1 = u1 == dur ? left_v : ev;
    } else { /* ActiveMotion._left(u1): bisect_left */
        lo = 0; hi = ns;
        while (lo < hi) { Py_ssize_t mid = (lo + hi) / 2; if (ts[mid] < u1) lo = mid + 1; else hi = mid; }
        Py_ssize_t k2 = lo - 1 > 0 ? lo - 1 : 0;
        double s2 = u1 - ts[k2];
        double j2 = sj[k2], a2 = sa[k2], v2 = sv[k2];
        p1 = sp[k2] + s2 * (v2 + s2 * (a2 * 0.5 + s2 * j2 / 6.0));
        v1 = v2 + s2 * (a2 + s2 * j2 * 0.5);
    }
    double h = u1 - u0, dp = p1 - p0;
    o[0] = p0; o[1] = v0;
    o[2] = (6.0 * dp - h * (4.0 * v0 + 2.0 * v1)) / (h * h);
    o[3] = (6.0 * h * (v0 + v1) - 12.0 * dp) / (h * h * h);
    o[4] = p1; o[5] = v1;
}

PyDoc_STRVAR(pieces_doc,
"pieces(seg, t_start, dur, end_p, end_v, left_v, t0, origin, period, n, rows, ends)\n\n"
"seg: float64[5, ns] (t0, p0, v0, a0, j of the profile's segments). For cycles n+1..n+m\n"
"(m = len(rows); cycle k ends at origin + k * period, the first starts at t0) fill\n"
"rows[m, 6] with (t0, dt, p0, v0, a0, j) and ends[m, 2] with (p1, v1), exactly as\n"
"ActiveMotion.piece gives them one cycle at a time.");

static PyObject *pieces(PyObject *self, PyObject *args)
{
    PyObject *o[3];
    double t_start, dur, ep, ev, left_v, t0, origin, period;
    long long n;
    if (!PyArg_ParseTuple(args, "OddddddddLOO", &o[0], &t_start, &dur, &ep, &ev, &left_v,
                          &t0, &origin, &period, &n, &o[1], &o[2]))
        return NULL;
    Buf bufs[3];
    memset(bufs, 0, sizeof bufs);
    static const char *names[3] = {"seg", "rows", "ends"};
    for (int k = 0; k < 3; k++)
        if (get_buf(o[k], &bufs[k], 8, names[k]) < 0) { release(bufs, 3); return NULL; }
    Py_ssize_t ns = bufs[0].b.len / (8 * 5);
    Py_ssize_t m = bufs[1].b.len / (8 * 6);
    if (bufs[0].b.len != ns * 8 * 5 || bufs[1].b.len != m * 8 * 6
            || bufs[2].b.len != m * 8 * 2) {
        release(bufs, 3);
        PyErr_SetString(PyExc_ValueError, "pieces: array sizes disagree");
        return NULL;
    }
    const double *seg = bufs[0].b.buf;
    double *rows = bufs[1].b.buf, *ends = bufs[2].b.buf;
    Py_BEGIN_ALLOW_THREADS
    double ta = t0;
    for (Py_ssize_t i = 0; i < m; i++) {
        double t1 = origin + (double)(n + 1 + i) * period;
        double out[6];
        piece(seg, seg + ns, seg + 2 * ns, seg + 3 * ns, seg + 4 * ns, ns, t_start, dur, ep,
              ev, left_v, ta, t1, out);
        double *r = rows + i * 6;
        r[0] = ta; r[1] = t1 - ta; r[2] = out[0]; r[3] = out[1]; r[4] = out[2]; r[5] = out[3];
        ends[i * 2] = out[4];
        ends[i * 2 + 1] = out[5];
        ta = t1;
    }
    Py_END_ALLOW_THREADS
    release(bufs, 3);
    Py_RETURN_NONE;
}

PyDoc_STRVAR(check_rows_doc,
"check_rows(rows, end, slack) -> index of the first bad piece, or -1\n\n"
"rows: float64[n, 6] (t0, dt, p0, v0, a0, j). A piece is bad when a field is not finite,\n"
"dt < 0, or t0 < (the end of the piece before, `end` for the first) - slack.");

static PyObject *check_rows(PyObject *self, PyObject *args)
{
    PyObject *o;
    double end, slack;
    if (!PyArg_ParseTuple(args, "Odd", &o, &end, &slack)) return NULL;
    Py_buffer b;
    if (PyObject_GetBuffer(o, &b, PyBUF_C_CONTIGUOUS) < 0) return NULL;
    if (b.itemsize != 8 || b.len % (8 * 6)) {
        PyBuffer_Release(&b);
        PyErr_SetString(PyExc_ValueError, "check_rows: rows must be float64[n, 6]");
        return NULL;
    }
    const double *r = b.buf;
    Py_ssize_t n = b.len / (8 * 6), bad = -1;
    for (Py_ssize_t k = 0; k < n && bad < 0; k++, r += 6) {
        for (int f = 0; f < 6; f++)
            if (!isfinite(r[f])) { bad = k; break; }
        if (bad < 0 && (r[1] < 0.0 || r[0] < end - slack)) bad = k;
        end = r[0] + r[1];
    }
    PyBuffer_Release(&b);
    return PyLong_FromSsize_t(bad);
}

static PyMethodDef methods[] = {
    {"check_rows", check_rows, METH_VARARGS, check_rows_doc},
    {"run", kernel_run, METH_VARARGS, kernel_run_doc},
    {"readback", kernel_readback, METH_VARARGS, kernel_readback_doc},
    {"pieces", pieces, METH_VARARGS, pieces_doc},
    {"record_rows", record_rows, METH_VARARGS, record_rows_doc},
    {"rt_paced", rt_paced, METH_VARARGS, rt_paced_doc},
    {"rt_wait", rt_wait, METH_VARARGS, rt_wait_doc},
    {"rt_close", rt_close, METH_VARARGS, rt_close_doc},
    {"rt_poll", rt_poll, METH_NOARGS, rt_poll_doc},
    {"rt_now", rt_now, METH_NOARGS, rt_now_doc},
    {"rt_slot", rt_slot, METH_VARARGS, rt_slot_doc},
    {"rt_yield", rt_yield, METH_VARARGS, rt_yield_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_kernel",
    "openmotion's compiled inner loops: motion pieces per cycle (control/motion.py) and the "
    "simulator's stepper pipeline (hw/sim/kernel.py).", -1,
    methods,
};

PyMODINIT_FUNC PyInit__kernel(void)
{
    PyObject *m = PyModule_Create(&module);
    if (m == NULL) return NULL;
    if (kernel_layout(m) < 0 || record_types(m) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
