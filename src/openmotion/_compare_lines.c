/* The compare engine's solvers (openmotion._compare): output lines: OutputLine.set, send and end bookkeeping, cycle records. */
#include "_compare.h"

/* ------------------------------------------------------------------ output lines */
/* compare_io.OutputLine.set applied to a sequence of (time, level): the edge lists t (floats,
 * time-ordered) and lv (bools) are edited in place exactly as by one `set` call after the
 * other. Times <= sent_until of sets that changed something are appended to `late`. */
static int lv_of(PyObject *lst, Py_ssize_t k, int initial)
{
    if (k < 0) return initial;
    PyObject *o = PyList_GET_ITEM(lst, k);
    return o == Py_True ? 1 : o == Py_False ? 0 : PyObject_IsTrue(o) > 0;
}

static inline double as_double(PyObject *o)
{
    return PyFloat_Check(o) ? PyFloat_AS_DOUBLE(o) : PyFloat_AsDouble(o);
}

int line_set_one(PyObject *tl, PyObject *ll, int initial, double t, int level,
                        double sent_until, PyObject *late)
{
    Py_ssize_t n = PyList_GET_SIZE(tl), lo = 0, hi = n;
    while (lo < hi) {  /* bisect_right */
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < as_double(PyList_GET_ITEM(tl, mid))) hi = mid; else lo = mid + 1;
    }
    Py_ssize_t k = lo;
    int before = lv_of(ll, k - 1, initial);
    int after_same = k < n && lv_of(ll, k, initial) == level;
    if (before == level && !after_same) return 0;
    if (t <= sent_until) {
        PyObject *f = PyFloat_FromDouble(t);
        if (f == NULL || PyList_Append(late, f) < 0) { Py_XDECREF(f); return -1; }
        Py_DECREF(f);
    }
    /* the insertion and OutputLine._merge, without moving the lists twice: the new edge
     * at k is followed by edge k (old); drop k+1 (old k) if it repeats the new level, then
     * the new one if it repeats the level before it */
    int drop_next = after_same;  /* lv[k+1] == lv[k] == level */
    int drop_new = before == level;
    if (drop_next && drop_new) {  /* the old edge k goes, nothing is inserted */
        if (PySequence_DelItem(tl, k) < 0 || PySequence_DelItem(ll, k) < 0) return -1;
        return 0;
    }
    if (drop_next) {  /* the new edge replaces the old one at k */
        PyObject *f = PyFloat_FromDouble(t);
        if (f == NULL) return -1;
        if (PyList_SetItem(tl, k, f) < 0) return -1;
        return 0;
    }
    if (drop_new) return 0;  /* unreachable: handled by the early return above */
    PyObject *f = PyFloat_FromDouble(t);
    if (f == NULL) return -1;
    int r = PyList_Insert(tl, k, f);
    Py_DECREF(f);
    if (r < 0 || PyList_Insert(ll, k, level ? Py_True : Py_False) < 0) return -1;
    return 0;
}

CMP_DOC(line_set_doc,
"line_set(t, lv, initial, times, levels, sent_until, late)\n\n"
"OutputLine.set(times[i], levels[i]) for i in order, on the edge lists t (floats) and lv\n"
"(bools) in place; set times <= sent_until that changed the waveform go to `late`.");

PyObject *line_set(PyObject *self, PyObject *args)
{
    PyObject *tl, *ll, *ts_o, *lvs_o, *late;
    int initial;
    double sent_until;
    if (!PyArg_ParseTuple(args, "O!O!pOOdO!", &PyList_Type, &tl, &PyList_Type, &ll, &initial,
                          &ts_o, &lvs_o, &sent_until, &PyList_Type, &late))
        return NULL;
    if (PyList_GET_SIZE(tl) != PyList_GET_SIZE(ll)) {
        PyErr_SetString(PyExc_ValueError, "line_set: t and lv differ in length");
        return NULL;
    }
    PyObject *ts = PySequence_Fast(ts_o, "times must be a sequence");
    if (ts == NULL) return NULL;
    PyObject *lvs = PySequence_Fast(lvs_o, "levels must be a sequence");
    if (lvs == NULL) { Py_DECREF(ts); return NULL; }
    Py_ssize_t m = PySequence_Fast_GET_SIZE(ts);
    PyObject *res = NULL;
    if (PySequence_Fast_GET_SIZE(lvs) != m) {
        PyErr_SetString(PyExc_ValueError, "line_set: one level per time");
        goto done;
    }
    for (Py_ssize_t i = 0; i < m; i++) {
        double t = as_double(PySequence_Fast_GET_ITEM(ts, i));
        if (t == -1.0 && PyErr_Occurred()) goto done;
        int level = PyObject_IsTrue(PySequence_Fast_GET_ITEM(lvs, i));
        if (level < 0 || line_set_one(tl, ll, initial, t, level, sent_until, late) < 0)
            goto done;
    }
    res = Py_NewRef(Py_None);
done:
    Py_DECREF(lvs);
    Py_DECREF(ts);
    return res;
}

CMP_DOC(lines_send_doc,
"lines_send(lines, t0, t1) -> (times, signals, levels) or None\n\n"
"OutputLine.send's bookkeeping for every line at once, when each line's physical level\n"
"(`_written`) is its waveform's level at t0 (nothing late or stretched pending): sets\n"
"_sent, _written, _sent_until = t1, clears _late and _hold, and returns the edges in\n"
"(t0, t1] of every line, line after line, as three flat lists (the form of\n"
"SimMachine.write_outputs_many). None (nothing changed) when a line needs send.");

static int lv_at(PyObject *tl, PyObject *ll, int initial, double t, Py_ssize_t lo,
                 Py_ssize_t *k_out)
{
    Py_ssize_t hi = PyList_GET_SIZE(tl);
    while (lo < hi) {  /* bisect_right */
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < as_double(PyList_GET_ITEM(tl, mid))) hi = mid; else lo = mid + 1;
    }
    *k_out = lo;
    return lv_of(ll, lo - 1, initial);
}

/* extend list `dst` by src[a:b] */
static int extend_slice(PyObject *dst, PyObject *src, Py_ssize_t a, Py_ssize_t b)
{
    for (Py_ssize_t k = a; k < b; k++)
        if (PyList_Append(dst, PyList_GET_ITEM(src, k)) < 0) return -1;
    return 0;
}

PyObject *lines_send(PyObject *self, PyObject *args)
{
    PyObject *lines_o;
    double t0, t1;
    if (!PyArg_ParseTuple(args, "Odd", &lines_o, &t0, &t1)) return NULL;
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Py_ssize_t *ab = malloc((size_t)(2 * n + 1) * sizeof(Py_ssize_t));
    int *wr = malloc((size_t)(n + 1) * sizeof(int));
    LineRef *LR = malloc((size_t)(n + 1) * sizeof(LineRef));
    PyObject *res = NULL, *ot = NULL, *os = NULL, *ol = NULL, *t1o = NULL;
    if (ab == NULL || wr == NULL || LR == NULL) { PyErr_NoMemory(); goto done; }
    for (Py_ssize_t i = 0; i < n; i++) {  /* check every line first: all or nothing */
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        LineRef *L = &LR[i];
        if (line_ref(line, L) < 0) goto done;
        PyObject *w = PyObject_GetAttr(line, S__written);
        if (w == NULL) goto done;
        int written = PyObject_IsTrue(w);
        Py_DECREF(w);
        if (PyList_GET_SIZE(L->tl) != PyList_GET_SIZE(L->ll)) {
            PyErr_SetString(PyExc_ValueError, "OutputLine: t and lv differ in length");
            goto done;
        }
        Py_ssize_t a, b;
        int l0 = lv_at(L->tl, L->ll, L->initial, t0, 0, &a);
        if (l0 != written) { res = Py_NewRef(Py_None); goto done; }
        wr[i] = lv_at(L->tl, L->ll, L->initial, t1, a, &b);
        ab[2 * i] = a;
        ab[2 * i + 1] = b;
    }
    ot = PyList_New(0); os = PyList_New(0); ol = PyList_New(0);
    t1o = PyFloat_FromDouble(t1);
    if (!ot || !os || !ol || !t1o) goto done;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        const LineRef *L = &LR[i];
        Py_ssize_t a = ab[2 * i], b = ab[2 * i + 1];
        PyObject *ts = PyList_GetSlice(L->tl, a, b);
        PyObject *ls = PyList_GetSlice(L->ll, a, b);
        PyObject *sent = ts && ls ? PyTuple_Pack(2, ts, ls) : NULL;
        int bad = sent == NULL
            || PyObject_SetAttr(line, S__sent, sent) < 0
            || PyObject_SetAttr(line, S__written, wr[i] ? Py_True : Py_False) < 0
            || PyObject_SetAttr(line, S__sent_until, t1o) < 0
            || PyObject_SetAttr(line, S__hold, Py_False) < 0
            || PyList_SetSlice(L->late, 0, PyList_GET_SIZE(L->late), NULL) < 0;
        if (!bad && b > a) {
            PyObject *sig = PyObject_GetAttr(line, S_signal);
            bad = sig == NULL || extend_slice(ot, L->tl, a, b) < 0
                  || extend_slice(ol, L->ll, a, b) < 0;
            for (Py_ssize_t k = a; !bad && k < b; k++) bad = PyList_Append(os, sig) < 0;
            Py_XDECREF(sig);
        }
        Py_XDECREF(sent);
        Py_XDECREF(ts);
        Py_XDECREF(ls);
        if (bad) goto done;
    }
    res = PyTuple_Pack(3, ot, os, ol);
done:
    Py_XDECREF(ot); Py_XDECREF(os); Py_XDECREF(ol); Py_XDECREF(t1o);
    free(ab);
    free(wr);
    free(LR);
    Py_DECREF(seq);
    return res;
}

/* ------------------------------------------------------------------ cycle bookkeeping */
CMP_DOC(plan_records_doc,
"plan_records(hists, t1, old=None) -> bytes, or bool with old\n\n"
"The record in force just before t1 (MotionHistory.record_at(axis, nextafter(t1, -inf)))\n"
"of every history record store in hists (history._Track), as bytes; with `old` (bytes of\n"
"an earlier call on the same stores): True when every one is still the same record.");

PyObject *plan_records(PyObject *self, PyObject *args)
{
    PyObject *hs_o, *old = Py_None;
    double t1;
    if (!PyArg_ParseTuple(args, "Od|O", &hs_o, &t1, &old)) return NULL;
    PyObject *seq = PySequence_Fast(hs_o, "hists must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    double *rec = malloc((size_t)(6 * n + 1) * sizeof(double));
    PyObject *res = NULL;
    if (rec == NULL) { PyErr_NoMemory(); goto done; }
    double tb = nextafter(t1, -INFINITY);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *h = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *x = PyObject_GetAttr(h, S_lo);
        long long lo = x ? PyLong_AsLongLong(x) : -1;
        Py_XDECREF(x);
        x = PyErr_Occurred() ? NULL : PyObject_GetAttr(h, S_hi);
        long long hi = x ? PyLong_AsLongLong(x) : -1;
        Py_XDECREF(x);
        if (PyErr_Occurred()) goto done;
        PyObject *names[5] = {S_ts, S_p0, S_v0, S_a0, S_j};
        Py_buffer b[5];
        int held = 0, bad = 0;
        for (int k = 0; k < 5 && !bad; k++) {
            PyObject *a = PyObject_GetAttr(h, names[k]);
            bad = a == NULL || get_vec(a, &b[k], "history column") < 0;
            Py_XDECREF(a);
            if (!bad) held++;
            if (!bad && b[k].len / 8 < hi) {
                PyErr_SetString(PyExc_ValueError, "history track: rows beyond its arrays");
                bad = 1;
            }
        }
        if (!bad && !(0 <= lo && lo <= hi)) {
            PyErr_SetString(PyExc_ValueError, "history track: bad live rows");
            bad = 1;
        }
        if (!bad) {
            const double *ts = b[0].buf;
            Py_ssize_t k = (Py_ssize_t)lo + search_right(ts + lo, 0, (Py_ssize_t)(hi - lo), tb)
                           - 1;
            double *r = rec + 6 * i;
            if (k < lo) {
                memset(r, 0, 6 * sizeof(double));
            } else {
                r[0] = 1.0;
                for (int q = 0; q < 5; q++) r[1 + q] = ((const double *)b[q].buf)[k];
            }
        }
        for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
        if (bad) goto done;
    }
    if (old == Py_None) {
        res = PyBytes_FromStringAndSize((const char *)rec, (Py_ssize_t)(6 * n * sizeof(double)));
    } else {
        if (!PyBytes_Check(old) || PyBytes_GET_SIZE(old) != (Py_ssize_t)(6 * n * sizeof(double))) {
            PyErr_SetString(PyExc_ValueError, "plan_records: old must be bytes of these stores");
            goto done;
        }
        const double *o = (const double *)PyBytes_AS_STRING(old);
        int same = 1;  /* (as the tuples compare: floats by value) */
        for (Py_ssize_t i = 0; i < n && same; i++) {
            if (o[6 * i] != rec[6 * i]) same = 0;
            else if (rec[6 * i] != 0.0)
                for (int q = 1; q < 6 && same; q++) same = o[6 * i + q] == rec[6 * i + q];
        }
        res = PyBool_FromLong(same);
    }
done:
    free(rec);
    Py_DECREF(seq);
    return res;
}

CMP_DOC(lines_snapshot_doc,
"lines_snapshot(lines, t) -> list of OutputLine.snapshot(t), one per line");

PyObject *lines_snapshot(PyObject *self, PyObject *args)
{
    PyObject *lines_o;
    double t;
    if (!PyArg_ParseTuple(args, "Od", &lines_o, &t)) return NULL;
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject *res = PyList_New(n);
    for (Py_ssize_t i = 0; res != NULL && i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        LineRef L;
        if (line_ref(line, &L) < 0) { Py_CLEAR(res); break; }
        Py_ssize_t lo = 0, hi = PyList_GET_SIZE(L.tl);
        while (lo < hi) {  /* bisect_left */
            Py_ssize_t mid = (lo + hi) / 2;
            if (as_double(PyList_GET_ITEM(L.tl, mid)) < t) lo = mid + 1; else hi = mid;
        }
        PyObject *ts = PyList_GetSlice(L.tl, lo, PyList_GET_SIZE(L.tl));
        PyObject *ls = PyList_GetSlice(L.ll, lo, PyList_GET_SIZE(L.ll));
        PyObject *it = ts && ls ? PyTuple_Pack(3, L.initial ? Py_True : Py_False, ts, ls) : NULL;
        Py_XDECREF(ts);
        Py_XDECREF(ls);
        if (it == NULL) { Py_CLEAR(res); break; }
        PyList_SET_ITEM(res, i, it);
    }
    Py_DECREF(seq);
    return res;
}

CMP_DOC(lines_end_doc,
"lines_end(lines, hw, t0, t1, keep)\n\n"
"The cycle end of every line: line.flush(hw, t0, t1) and line.forget_before(keep), each\n"
"called only when it has something to do (a timed line with nothing late needs no\n"
"flush; a waveform with no edge before keep needs no forget).");

PyObject *lines_end(PyObject *self, PyObject *args)
{
    PyObject *lines_o, *hw, *t0o, *t1o, *keepo;
    if (!PyArg_ParseTuple(args, "OOO!O!O!", &lines_o, &hw, &PyFloat_Type, &t0o, &PyFloat_Type,
                          &t1o, &PyFloat_Type, &keepo))
        return NULL;
    double keep = PyFloat_AS_DOUBLE(keepo);
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *o = PyObject_GetAttr(line, S_timed);
        int timed = o ? PyObject_IsTrue(o) : -1;
        Py_XDECREF(o);
        if (timed < 0) goto fail;
        int need = !timed;
        if (timed) {
            if ((o = PyObject_GetAttr(line, S__late)) == NULL) goto fail;
            Py_ssize_t nl = PyObject_Length(o);
            Py_DECREF(o);
            if (nl < 0) goto fail;
            need = nl > 0;
        }
        if (need) {
            PyObject *r = PyObject_CallMethodObjArgs(line, S_flush, hw, t0o, t1o, NULL);
            if (r == NULL) goto fail;
            Py_DECREF(r);
        }
        if ((o = PyObject_GetAttr(line, S__t)) == NULL) goto fail;
        int forget = 0;
        if (PyList_Check(o) && PyList_GET_SIZE(o) > 0) {
            forget = as_double(PyList_GET_ITEM(o, 0)) < keep;
        } else if (!PyList_Check(o)) {
            forget = 1;  /* (not a list: let the method decide) */
        }
        Py_DECREF(o);
        if (PyErr_Occurred()) goto fail;
        if (forget) {
            PyObject *r = PyObject_CallMethodObjArgs(line, S_forget_before, keepo, NULL);
            if (r == NULL) goto fail;
            Py_DECREF(r);
        }
    }
    Py_DECREF(seq);
    Py_RETURN_NONE;
fail:
    Py_DECREF(seq);
    return NULL;
}
