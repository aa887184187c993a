/* The recorder's row sink (openmotion._kernel.RowSink, Recorder.row_sink): a recorder ring
 * bound once, one call per row (a cycle-by-cycle step's, control/core/jump.record_now) or per
 * block (a jump's crossed cycles, put_block), and `ring_rows`, the one writer of recorder
 * rows in C (record_rows, _kernel_record.c, writes through it too).
 */
#include "_kernel.h"

int ring_rows(const Ring *g, Py_ssize_t head, const double *t, double origin, double period,
              long long n0, Py_ssize_t m, const int64_t *tr, const double *pv,
              const int64_t *ia, const int64_t *mover, const double *const *ends,
              const double *off, const int64_t *nc, int estop)
{
    Py_ssize_t n = g->n, R = g->R, F = g->F;
    Py_ssize_t keep = m < R - 1 ? m : R - 1;
    int finite = 1; /* Recorder.record_block's check, before any row is written */
    for (Py_ssize_t x = 0; x < n && finite; x++) {
        int64_t k = mover ? mover[x] : -1;
        if (k < 0) {
            finite = isfinite(pv[x * 2]) && isfinite(pv[x * 2 + 1]);
            continue;
        }
        const double *e = ends[k];
        for (Py_ssize_t r = m - keep; r < m; r++)
            if (!(isfinite(e[r * 2] + off[k]) && isfinite(e[r * 2 + 1]))) { finite = 0; break; }
    }
    if (!finite) {
        PyErr_SetString(PyExc_ValueError, "recorded positions/velocities must be finite");
        return -1;
    }
    double *rt = g->rt, *rf = g->rf;
    int32_t *rstate = g->rstate;
    int64_t *rio = g->rio;
    const int64_t *table = g->table;
    int64_t sp = g->sp, sf = g->sf, sv = g->sv, T = g->T;
    Py_ssize_t row = (Py_ssize_t)((head + (m - keep)) % R);
    for (Py_ssize_t r = m - keep; r < m; r++, row = row + 1 == R ? 0 : row + 1) {
        rt[row] = t ? *t : origin + (double)(n0 + 1 + r) * period;
        double *f = rf + row * F * n;
        const int64_t *trr = tr + r * n * 3;
        for (Py_ssize_t x = 0; x < n; x++) {
            int64_t k = mover ? mover[x] : -1;
            const double *e = k >= 0 ? ends[k] + r * 2 : NULL;
            const int64_t *a = ia + x * 3;
            if (sp >= 0) f[sp * n + x] = e ? e[0] + off[k] : pv[x * 2];
            if (sv >= 0) f[sv * n + x] = e ? e[1] : pv[x * 2 + 1];
            if (sf >= 0) f[sf * n + x] = (double)wrap28((a[0] ? trr[x * 3] : trr[x * 3 + 1])
                                                        + a[1]);
            if (rstate) rstate[row * n + x] = (int32_t)a[2];
            if (rio) {
                int64_t w = trr[x * 3 + 2] ^ nc[x];
                int64_t v = (w >= 0 && w < T) ? table[w] : 0;
                rio[row * n + x] = estop ? v | (1 << 6) : v;
            }
        }
    }
    return 0;
}

/* ------------------------------------------------------------------ RowSink
 * One recorder row per cycle (a cycle-by-cycle step's Controller._record, through
 * Recorder.row_sink): the ring's arrays, the channel slots, the io table and the state
 * codes are bound once, and the sink keeps the ring's head, the newest time and the rows
 * put since the Recorder last took them (`take`), so a row costs one call with the
 * cycle's values (the axes themselves: their fields are read here). */
typedef struct {
    PyObject_HEAD
    Buf b[6]; /* rt, rf, rstate, rio, slots, table */
    Ring g;
    PyObject *states, *codes; /* tuples: state objects and their codes */
    PyObject *nc_obj;     /* the nc words of the last put (their buffer held in ncb) */
    Buf ncb;
    Py_ssize_t head;      /* the ring row the next put writes */
    long long pending;    /* rows put since the last take */
    long long room;       /* rows it may put before the recorder must settle held runs */
    double last_t;        /* the newest row's time */
    int armed;
} RowSink;

/* interned attribute names of an Axis and its Counters (record_types) */
static PyObject *s_pos, *s_vel, *s_state, *s_counters, *s_cmd_off, *s_fb_internal, *s_fb_off;

static void sink_forget_nc(RowSink *s)
{
    release(&s->ncb, 1);
    s->ncb.held = 0;
    Py_CLEAR(s->nc_obj);
}

static void sink_dealloc(RowSink *s)
{
    release(s->b, 6);
    sink_forget_nc(s);
    Py_XDECREF(s->states);
    Py_XDECREF(s->codes);
    Py_TYPE(s)->tp_free((PyObject *)s);
}

static int sink_init(RowSink *s, PyObject *args, PyObject *kw)
{
    PyObject *o[6], *states, *codes;
    Py_ssize_t n;
    static char *kwlist[] = {"rt", "rf", "rstate", "rio", "slots", "table", "n_axes",
                             "states", "codes", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOOOOOnO!O!", kwlist, &o[0], &o[1], &o[2],
                                     &o[3], &o[4], &o[5], &n, &PyTuple_Type, &states,
                                     &PyTuple_Type, &codes))
        return -1;
    release(s->b, 6);
    memset(s->b, 0, sizeof s->b);
    sink_forget_nc(s);
    s->g.R = 0;
    s->armed = 0;
    static const Py_ssize_t sizes[6] = {8, 8, 4, 8, 8, 8};
    static const char *names[6] = {"rt", "rf", "rstate", "rio", "slots", "table"};
    for (int k = 0; k < 6; k++)
        if (get_buf(o[k], &s->b[k], sizes[k], names[k]) < 0) {
            release(s->b, 6);
            memset(s->b, 0, sizeof s->b);
            return -1;
        }
    Py_ssize_t R = s->b[0].b.len / 8;
    Py_ssize_t F = (R && n > 0) ? s->b[1].b.len / (8 * R * n) : 0;
    const int64_t *slots = s->b[4].b.buf;
    const char *bad = NULL;
    if (n < 1 || R < 2 || s->b[1].b.len != R * F * n * 8 || s->b[4].b.len != 3 * 8
            || (s->b[2].b.len && s->b[2].b.len != R * n * 4)
            || (s->b[3].b.len && s->b[3].b.len != R * n * 8)
            || PyTuple_GET_SIZE(states) != PyTuple_GET_SIZE(codes))
        bad = "RowSink: arrays disagree in size";
    for (int k = 0; k < 3 && !bad; k++)
        if (slots[k] < -1 || slots[k] >= F) bad = "RowSink: bad slot";
    for (Py_ssize_t k = 0; k < PyTuple_GET_SIZE(codes) && !bad; k++)
        if (!PyLong_Check(PyTuple_GET_ITEM(codes, k))) bad = "RowSink: codes must be ints";
    if (bad) {
        release(s->b, 6);
        memset(s->b, 0, sizeof s->b);
        PyErr_SetString(PyExc_ValueError, bad);
        return -1;
    }
    Py_INCREF(states);
    Py_INCREF(codes);
    Py_XSETREF(s->states, states);
    Py_XSETREF(s->codes, codes);
    Ring *g = &s->g;
    g->rt = s->b[0].b.buf;
    g->rf = s->b[1].b.buf;
    g->rstate = s->b[2].b.len ? s->b[2].b.buf : NULL;
    g->rio = s->b[3].b.len ? s->b[3].b.buf : NULL;
    g->table = s->b[5].b.buf;
    g->R = R;
    g->F = F;
    g->n = n;
    g->T = s->b[5].b.len / 8;
    g->sp = slots[0];
    g->sf = slots[1];
    g->sv = slots[2];
    return 0;
}

/* a read-only int64 C-contiguous buffer of `len` items */
static int int64s(PyObject *o, Py_buffer *b, Py_ssize_t len, const char *name)
{
    if (PyObject_GetBuffer(o, b, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return -1;
    if (b->itemsize != 8 || b->len != len * 8
            || (b->format && strcmp(b->format, "l") && strcmp(b->format, "q"))) {
        PyBuffer_Release(b);
        PyErr_Format(PyExc_ValueError, "RowSink.put: %s must hold %zd int64", name, len);
        return -1;
    }
    return 0;
}

/* the nc words (int64[n]) of a put: the buffer of the last call's object is kept, so the
 * same object (the controller keeps it until the contact logic changes) costs nothing */
static const int64_t *sink_nc(RowSink *s, PyObject *onc)
{
    if (onc != s->nc_obj || !s->ncb.held) {
        Py_buffer b;
        if (int64s(onc, &b, s->g.n, "nc") < 0) return NULL;
        sink_forget_nc(s);
        s->ncb.b = b;
        s->ncb.held = 1;
        Py_INCREF(onc);
        s->nc_obj = onc;
    }
    return s->ncb.b.buf;
}

/* Axis.position: the raw position plus the command offset, as Python adds them */
static int position(PyObject *p, PyObject *off, double *out)
{
    if (PyLong_CheckExact(p) && PyLong_CheckExact(off)) {
        PyObject *sum = PyNumber_Add(p, off);
        if (sum == NULL) return -1;
        *out = PyFloat_AsDouble(sum);
        Py_DECREF(sum);
    } else {
        double a = PyFloat_AsDouble(p);
        if (a == -1.0 && PyErr_Occurred()) return -1;
        double b = PyFloat_AsDouble(off);
        if (b == -1.0 && PyErr_Occurred()) return -1;
        *out = a + b;
    }
    return (*out == -1.0 && PyErr_Occurred()) ? -1 : 0;
}

/* One axis's fields (raw position, command offset, velocity, feedback internal?, feedback
 * offset, state object) into pv[0..1] (position, velocity) and ia[0..2] (internal?,
 * feedback offset, state code); -1 with an exception set on a bad value. */
static int axis_fields(RowSink *s, PyObject *const *v, double *pv, int64_t *ia)
{
    if (position(v[0], v[1], &pv[0]) < 0) return -1;
    pv[1] = PyFloat_AsDouble(v[2]);
    if (pv[1] == -1.0 && PyErr_Occurred()) return -1;
    int internal = PyObject_IsTrue(v[3]);
    if (internal < 0) return -1;
    ia[0] = internal;
    ia[1] = PyLong_AsLongLong(v[4]);
    if (ia[1] == -1 && PyErr_Occurred()) return -1;
    PyObject *const *st = &PyTuple_GET_ITEM(s->states, 0);
    Py_ssize_t ns = PyTuple_GET_SIZE(s->states), j = 0;
    while (j < ns && st[j] != v[5]) j++;
    if (j == ns) {
        PyErr_SetString(PyExc_ValueError, "RowSink.put: unknown axis state");
        return -1;
    }
    ia[2] = PyLong_AsLongLong(PyTuple_GET_ITEM(s->codes, j));
    return 0;
}

/* The axes' fields of a put into pv (position, velocity) and ia (internal?, feedback
 * offset, state code): `ov` a tuple of the n Axis objects (their _pos, _vel, _state and
 * counters._cmd_off, _fb_internal, _fb_off, read here) or a list of 6n values (those
 * fields, axis by axis); -1 with an exception set on a bad value. */
static int fields(RowSink *s, PyObject *ov, double *pv, int64_t *ia)
{
    Py_ssize_t n = s->g.n;
    if (PyList_Check(ov) && PyList_GET_SIZE(ov) == 6 * n) {
        PyObject **v = &PyList_GET_ITEM(ov, 0);
        for (Py_ssize_t x = 0; x < n; x++)
            if (axis_fields(s, v + 6 * x, pv + 2 * x, ia + 3 * x) < 0) return -1;
        return 0;
    }
    if (!PyTuple_Check(ov) || PyTuple_GET_SIZE(ov) != n) {
        PyErr_SetString(PyExc_ValueError, "RowSink.put: values disagree in size");
        return -1;
    }
    for (Py_ssize_t x = 0; x < n; x++) {
        PyObject *ax = PyTuple_GET_ITEM(ov, x), *v[6] = {NULL}, *cnt;
        int r = -1;
        cnt = PyObject_GetAttr(ax, s_counters);
        if (cnt && (v[0] = PyObject_GetAttr(ax, s_pos)) && (v[1] = PyObject_GetAttr(cnt, s_cmd_off))
                && (v[2] = PyObject_GetAttr(ax, s_vel))
                && (v[3] = PyObject_GetAttr(cnt, s_fb_internal))
                && (v[4] = PyObject_GetAttr(cnt, s_fb_off))
                && (v[5] = PyObject_GetAttr(ax, s_state)))
            r = axis_fields(s, v, pv + 2 * x, ia + 3 * x);
        Py_XDECREF(cnt);
        for (int k = 0; k < 6; k++) Py_XDECREF(v[k]);
        if (r < 0) return -1;
    }
    return 0;
}

/* 0 written, 1 no room (nothing written), -1 error (nothing written) */
static int sink_row(RowSink *s, double t, PyObject *ov, PyObject *orb, PyObject *onc,
                    int estop)
{
    Py_ssize_t n = s->g.n;
    if (!(isfinite(t) && t >= s->last_t)) {
        PyObject *a = PyFloat_FromDouble(s->last_t), *b = PyFloat_FromDouble(t);
        if (a && b)
            PyErr_Format(PyExc_ValueError, "t must be finite and >= the previous time %R, "
                         "got %R", a, b);
        Py_XDECREF(a);
        Py_XDECREF(b);
        return -1;
    }
    if (s->room <= 0) return 1;
    double pvs[2 * 64], *pv = pvs;
    int64_t ias[3 * 64], *ia = ias;
    if (n > 64) {
        pv = PyMem_Malloc(sizeof(double) * 2 * n + sizeof(int64_t) * 3 * n);
        if (pv == NULL) { PyErr_NoMemory(); return -1; }
        ia = (int64_t *)(pv + 2 * n);
    }
    Py_buffer rb;
    const int64_t *nc = NULL;
    int fail = fields(s, ov, pv, ia) < 0;
    if (!fail && int64s(orb, &rb, 3 * n, "readback") < 0) fail = 1;
    if (!fail && (nc = sink_nc(s, onc)) == NULL) {
        PyBuffer_Release(&rb);
        fail = 1;
    }
    if (!fail) {
        fail = ring_rows(&s->g, s->head, &t, 0.0, 0.0, 0, 1, rb.buf, pv, ia, NULL, NULL, NULL,
                         nc, estop) < 0;
        PyBuffer_Release(&rb);
    }
    if (pv != pvs) PyMem_Free(pv);
    if (fail) return -1;
    s->head = s->head + 1 == s->g.R ? 0 : s->head + 1;
    s->pending++;
    s->room--;
    s->last_t = t;
    return 0;
}

static PyObject *sink_put(RowSink *s, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "RowSink.put takes (t, values, readback, nc, estop)");
        return NULL;
    }
    if (!s->armed) Py_RETURN_FALSE; /* the recorder took the rows back: arm it again */
    double t = PyFloat_AsDouble(args[0]);
    if (t == -1.0 && PyErr_Occurred()) return NULL;
    int estop = PyObject_IsTrue(args[4]);
    if (estop < 0) return NULL;
    int r = sink_row(s, t, args[1], args[2], args[3], estop);
    if (r < 0) return NULL;
    return PyBool_FromLong(r == 0);
}


/* The m rows of cycles n0+1 .. n0+m a jump crossed (record_rows' rows, through the bound
 * ring): 0 written, 1 no room or not armed (nothing written), -1 error (nothing written). */
static int sink_block(RowSink *s, PyObject *const *a)
{
    long long n0 = PyLong_AsLongLong(a[0]);
    if (n0 == -1 && PyErr_Occurred()) return -1;
    double origin = PyFloat_AsDouble(a[1]);
    if (origin == -1.0 && PyErr_Occurred()) return -1;
    double period = PyFloat_AsDouble(a[2]);
    if (period == -1.0 && PyErr_Occurred()) return -1;
    PyObject *ov = a[4], *omov = a[5], *ends = a[6], *ooff = a[7];
    int estop = PyObject_IsTrue(a[9]);
    if (estop < 0) return -1;
    Py_ssize_t n = s->g.n;
    if (!PyList_Check(omov) || !PyTuple_Check(ends) || !PyList_Check(ooff)
            || PyTuple_GET_SIZE(ends) != PyList_GET_SIZE(omov)
            || PyList_GET_SIZE(ooff) != PyList_GET_SIZE(omov)) {
        PyErr_SetString(PyExc_ValueError, "RowSink.put_block: arrays disagree in size");
        return -1;
    }
    Py_buffer tb;
    if (PyObject_GetBuffer(a[3], &tb, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return -1;
    Py_ssize_t m = tb.itemsize == 8 ? tb.len / (8 * 3 * n) : -1;
    if (m < 0 || tb.len != m * n * 3 * 8
            || (tb.format && strcmp(tb.format, "l") && strcmp(tb.format, "q"))) {
        PyBuffer_Release(&tb);
        PyErr_SetString(PyExc_ValueError, "RowSink.put_block: trace must be int64 [m, n, 3]");
        return -1;
    }
    double t1 = origin + (double)(n0 + 1) * period, t2 = origin + (double)(n0 + m) * period;
    if (m && !(isfinite(t1) && isfinite(t2) && t1 >= s->last_t && t2 >= t1)) {
        PyBuffer_Release(&tb);
        PyObject *x = PyFloat_FromDouble(s->last_t);
        if (x)
            PyErr_Format(PyExc_ValueError, "t must be finite and non-decreasing from the "
                         "previous time %R", x);
        Py_XDECREF(x);
        return -1;
    }
    if (!s->armed || m > s->room) {
        PyBuffer_Release(&tb);
        return 1;
    }
    Py_ssize_t nk = PyList_GET_SIZE(omov);
    double *pv = PyMem_Malloc(sizeof(double) * (2 * n + nk) + sizeof(int64_t) * (4 * n + 1)
                              + sizeof(Buf) * (nk + 1) + sizeof(double *) * (nk + 1));
    if (pv == NULL) {
        PyBuffer_Release(&tb);
        PyErr_NoMemory();
        return -1;
    }
    double *off = pv + 2 * n;
    int64_t *ia = (int64_t *)(off + nk), *mover = ia + 3 * n;
    Buf *eb = (Buf *)(mover + n + 1);
    const double **ep = (const double **)(eb + nk + 1);
    memset(eb, 0, sizeof(Buf) * (nk + 1));
    const int64_t *nc = NULL;
    int fail = fields(s, ov, pv, ia) < 0;
    if (!fail && (nc = sink_nc(s, a[8])) == NULL) fail = 1;
    for (Py_ssize_t x = 0; x < n; x++) mover[x] = -1;
    for (Py_ssize_t k = 0; k < nk && !fail; k++) {
        Py_ssize_t i = PyLong_AsSsize_t(PyList_GET_ITEM(omov, k));
        if (i == -1 && PyErr_Occurred()) { fail = 1; break; }
        if (i < 0 || i >= n) {
            PyErr_SetString(PyExc_ValueError, "RowSink.put_block: bad mover index");
            fail = 1;
            break;
        }
        mover[i] = k;
        off[k] = PyFloat_AsDouble(PyList_GET_ITEM(ooff, k));
        if (off[k] == -1.0 && PyErr_Occurred()) { fail = 1; break; }
        if (PyObject_GetBuffer(PyTuple_GET_ITEM(ends, k), &eb[k].b, PyBUF_C_CONTIGUOUS) < 0) {
            fail = 1;
            break;
        }
        eb[k].held = 1;
        ep[k] = eb[k].b.buf;
        if (eb[k].b.itemsize != 8 || eb[k].b.len < m * 2 * 8) {
            PyErr_SetString(PyExc_ValueError, "RowSink.put_block: ends too short");
            fail = 1;
        }
    }
    if (!fail)
        fail = ring_rows(&s->g, s->head, NULL, origin, period, n0, m, tb.buf, pv, ia, mover,
                         ep, off, nc, estop) < 0;
    if (!fail && m) {
        s->head = (Py_ssize_t)((s->head + m) % s->g.R);
        s->pending += m;
        s->room -= m;
        s->last_t = t2;
    }
    release(eb, (int)nk);
    PyMem_Free(pv);
    PyBuffer_Release(&tb);
    return fail ? -1 : 0;
}

static PyObject *sink_put_block(RowSink *s, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 10) {
        PyErr_SetString(PyExc_TypeError, "RowSink.put_block takes (n0, origin, period, trace, "
                                         "values, movers, ends, offsets, nc, estop)");
        return NULL;
    }
    int r = sink_block(s, args);
    if (r < 0) return NULL;
    return PyBool_FromLong(r == 0);
}

static PyObject *sink_arm(RowSink *s, PyObject *args)
{
    Py_ssize_t head;
    long long room;
    double last_t;
    if (!PyArg_ParseTuple(args, "ndL", &head, &last_t, &room)) return NULL;
    if (s->g.R == 0 || head < 0 || head >= s->g.R) {
        PyErr_SetString(PyExc_ValueError, "RowSink.arm: bad head");
        return NULL;
    }
    s->head = head;
    s->last_t = last_t;
    s->room = room;
    s->pending = 0;
    s->armed = 1;
    Py_RETURN_NONE;
}

static PyObject *sink_take(RowSink *s, PyObject *noargs)
{
    PyObject *r = Py_BuildValue("(Ld)", s->pending, s->last_t);
    if (r == NULL) return NULL;
    s->pending = 0;
    s->armed = 0;
    return r;
}

static PyMethodDef sink_methods[] = {
    {"put", (PyCFunction)(void (*)(void))sink_put, METH_FASTCALL,
     "put(t, values, readback, nc, estop) -> bool\n\n"
     "Write the row of time t at the head: per axis, from values (a list of 6n: raw "
     "position, command offset, velocity, feedback from the output pulses?, feedback "
     "offset, state object), readback int64[n, 3] (pulses out, decoded count, electrical "
     "level word) and nc int64[n] (the normally-closed level bits), the command position "
     "and velocity, the feedback counter (wrapped to 28 bits), the state code and the io "
     "word (+ bit 6 on estop). False, nothing written, when it is not armed (the recorder "
     "took its rows back) or the room given to arm is used up; ValueError, nothing "
     "written, on a bad value."},
    {"put_block", (PyCFunction)(void (*)(void))sink_put_block, METH_FASTCALL,
     "put_block(n0, origin, period, trace, values, movers, ends, offsets, nc, estop) -> bool"
     "\n\nWrite the rows of cycles n0+1 .. n0+m (m = len(trace), int64 [m, n, 3] readback "
     "at each cycle end; times origin + k * period; only the last min(m, R - 1) rows): "
     "record_rows' rows, the values as put's, movers a list of axis indices whose "
     "position and velocity come from ends[k] (float64 [>= m, 2], + offsets[k]). False, "
     "nothing written, when not armed or the room is too small; ValueError, nothing "
     "written, on a bad value."},
    {"arm", (PyCFunction)sink_arm, METH_VARARGS,
     "arm(head, last_t, room) -> None: put rows from ring row head on, times >= last_t, at "
     "most room of them; forgets rows not taken."},
    {"take", (PyCFunction)sink_take, METH_NOARGS,
     "take() -> (rows, last_t): the rows put since arm (and their newest time); disarms."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject RowSinkType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "openmotion._kernel.RowSink",
    .tp_basicsize = sizeof(RowSink),
    .tp_dealloc = (destructor)sink_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "RowSink(rt, rf, rstate, rio, slots, table, n_axes, states, codes): a "
              "recorder ring's arrays bound for one row per call (put).",
    .tp_methods = sink_methods,
    .tp_init = (initproc)sink_init,
    .tp_new = PyType_GenericNew,
};

int record_types(PyObject *module)
{
    static const char *attrs[7] = {"_pos", "_vel", "_state", "counters", "_cmd_off",
                                   "_fb_internal", "_fb_off"};
    PyObject **slots[7] = {&s_pos, &s_vel, &s_state, &s_counters, &s_cmd_off, &s_fb_internal,
                           &s_fb_off};
    for (int k = 0; k < 7; k++)
        if (*slots[k] == NULL && (*slots[k] = PyUnicode_InternFromString(attrs[k])) == NULL)
            return -1;
    if (PyType_Ready(&RowSinkType) < 0) return -1;
    Py_INCREF(&RowSinkType);
    if (PyModule_AddObject(module, "RowSink", (PyObject *)&RowSinkType) < 0) {
        Py_DECREF(&RowSinkType);
        return -1;
    }
    return 0;
}
