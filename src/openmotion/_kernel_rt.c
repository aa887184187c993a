/* Real-time pacing of the compiled cycles (openmotion._kernel, control/core/realtime.py).
 *
 * The real-time executor (a Python thread) binds a pacing context to its own thread with
 * `rt_paced(st, busy, late, work, cpu, lead, fn, args)` and calls fn(*args) - a
 * virtual-time jump - inside it. Every cycle the compiled stepper loop (_kernel_stepper.c) then runs on that
 * thread calls `rt_before_cycle(k)`, which sleeps (GIL released, the kernel runs without
 * it) until cycle k's slot on the wall clock, and `rt_after_cycle(k)`, which records the
 * cycle's busy time. `rt_before_cycle` returns 1 instead of waiting when another thread
 * waits for the controller's lock or the executor is asked to stop (st[RT_WAITERS],
 * st[RT_STOPPING]): the kernel then returns at that cycle boundary and the Python side
 * lands there, so a command from another thread takes effect at the next cycle, as with
 * a cycle stepped in Python. Never at the first cycle of a kernel run (`first`): a jump
 * fed in chunks (control/core/jump.py) then always lands on a cycle it ran, whichever
 * chunk the request comes in; the waiter waits at most one cycle more. A cycle the Python path runs (an edge to report, a landing)
 * stays "pending" from its slot until `rt_close` (or the next cycle) ends it, so its
 * busy time includes the Python work. Cycle k's slot starts at st[RT_WALL0] + k * period
 * (CLOCK_MONOTONIC seconds); a late cycle is never skipped (catch-up, as RealtimePacer).
 * The landing lead: the last st[RT_LEAD] cycles before st[RT_LAND], the cycle the compiled
 * run in progress lands on (or a cycle the Python path steps), do not wait for their own
 * slots but run back to back from the slot of cycle RT_LAND - RT_LEAD, so the landing's
 * Python work has RT_LEAD + 1 periods before the next slot (`planned_slot`); a cycle
 * never starts more than RT_LEAD periods before its slot.
 *
 * The context lives in float64 numpy arrays owned by the executor: st[RT_NFIELDS], the
 * rings busy/late/work/cpu/lead (same length): per cycle the busy time, the start
 * lateness against its planned start, the Python work done between the previous cycle's
 * end and the wait for this one (landing and feeding the piece queue ahead), the executor
 * thread's CPU time from the cycle's start to the wait for the next one (the cycle and the
 * work after it, without the time the thread was preempted: the controller's own cost on
 * a loaded machine), and the periods it was planned ahead of its slot (the lead).
 */
#include "_kernel.h"
#include <time.h>
#include <errno.h>

enum { RT_WALL0, RT_PERIOD, RT_COUNT, RT_WAITERS, RT_STOPPING, RT_PENDING, RT_START,
       RT_LASTEND, RT_OVERRUNS, RT_LATECYC, RT_BEHIND, RT_BURSTS, RT_INBURST,
       RT_INTERRUPTED, RT_LASTK, RT_LASTSTART, RT_LASTOVER, RT_EXTEND, RT_CPU0, RT_LAND,
       RT_LEAD, RT_DUE, RT_NFIELDS };

#define NRINGS 5

typedef struct {
    double *st, *busy, *late, *work, *cpu, *lead;
    Py_ssize_t cap;
} RtCtx;

static _Thread_local RtCtx *rt_cur = NULL;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* this thread's CPU time (s) */
static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static inline double vread(double *p) { return *(volatile double *)p; }

/* The cycle whose slot cycle k waits for: k itself, or, for the last st[RT_LEAD] cycles
 * before the landing st[RT_LAND] of the compiled run in progress, the cycle
 * RT_LAND - RT_LEAD: those cycles run back to back from that slot on, so the Python work
 * of the landing has RT_LEAD + 1 periods before the next cycle's slot (never earlier
 * than RT_LEAD periods ahead of its own slot). */
static double planned_slot(const double *st, double k)
{
    double land = st[RT_LAND], lead = st[RT_LEAD];
    if (lead > 0.0 && land > 0.0 && k <= land && k > land - lead) return land - lead;
    return k;
}

/* cycle k ends at t after `busy` seconds of work: an overrun when it ends after the next
 * slot began (counted once per cycle: `over` says it was counted already) */
static void set_end(RtCtx *c, Py_ssize_t i, double k, double busy, double t, int over)
{
    double *st = c->st, period = st[RT_PERIOD];
    double next = st[RT_WALL0] + (k + 1.0) * period;
    c->busy[i] = busy;
    if (t > next) {
        if (!over) {
            st[RT_OVERRUNS] += 1.0;
            if (st[RT_INBURST] == 0.0) st[RT_BURSTS] += 1.0;
        }
        double behind = floor((t - next) / period) + 1.0;
        if (behind > st[RT_BEHIND]) st[RT_BEHIND] = behind;
        st[RT_INBURST] = 1.0;
        st[RT_LASTOVER] = 1.0;
    } else if (!over) {
        st[RT_INBURST] = 0.0;
        st[RT_LASTOVER] = 0.0;
    }
    st[RT_LASTEND] = t;
}

/* end the pending cycle at time t: its lateness, busy time, overrun counts */
static void close_pending(RtCtx *c, double t)
{
    double *st = c->st;
    if (st[RT_PENDING] < 0.0) return;
    double k = st[RT_PENDING], period = st[RT_PERIOD];
    Py_ssize_t i = (Py_ssize_t)((long long)st[RT_COUNT] % (long long)c->cap);
    double start = st[RT_START];
    c->late[i] = start - st[RT_DUE];  /* against the instant it was planned for */
    if (start - (st[RT_WALL0] + k * period) >= period) st[RT_LATECYC] += 1.0;
    st[RT_COUNT] += 1.0;
    st[RT_PENDING] = -1.0;
    st[RT_LASTK] = k;
    st[RT_LASTSTART] = start;
    st[RT_EXTEND] = 1.0;
    set_end(c, i, k, t - start, t, 0);
}

/* the Python work that finishes the last ended cycle (a landing: write-back, the
 * reactions of its hooks) belongs to it: add the time since RT_LASTEND to its busy time
 * (only until the next cycle begins: RT_EXTEND) */
static void extend_last(RtCtx *c, double t)
{
    double *st = c->st;
    if (st[RT_COUNT] < 1.0 || st[RT_EXTEND] == 0.0) return;
    Py_ssize_t i = (Py_ssize_t)((long long)(st[RT_COUNT] - 1.0) % (long long)c->cap);
    set_end(c, i, st[RT_LASTK], c->busy[i] + (t - st[RT_LASTEND]), t,
            st[RT_LASTOVER] != 0.0);
}

/* How a cycle's wait may end early: never (the first cycle of a kernel run), when the
 * executor stops, or also when another thread waits for the lock. */
enum { WAIT_FIRM, WAIT_STOP, WAIT_ANY };

/* sleep until `due` (absolute, CLOCK_MONOTONIC s) in steps of at most 1 ms, watching the
 * stop flag and the lock waiters as `mode` says; 1 when woken by them. A waiter is seen
 * within a period; inside a cycle's wait it is one absolute sleep, as a plain pacer's. */
static int wait_until(RtCtx *c, double due, int mode)
{
    for (;;) {
        if ((mode >= WAIT_STOP && vread(&c->st[RT_STOPPING]) != 0.0)
                || (mode == WAIT_ANY && vread(&c->st[RT_WAITERS]) > 0.0))
            return 1;
        double t = now_s();
        if (t >= due) return 0;
        double target = due - t > 1e-3 ? t + 1e-3 : due;
        struct timespec ts;
        ts.tv_sec = (time_t)floor(target);
        ts.tv_nsec = (long)((target - floor(target)) * 1e9);
        if (ts.tv_nsec >= 1000000000L) { ts.tv_sec++; ts.tv_nsec -= 1000000000L; }
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {}
    }
}

/* start cycle k at its slot: the work since the last cycle ended is recorded with it */
static int begin(RtCtx *c, long long k, int mode)
{
    double *st = c->st;
    if (st[RT_PENDING] == (double)k) return 0; /* already in progress (begun by the kernel) */
    double t = now_s();
    close_pending(c, t);
    double work = st[RT_LASTEND] > 0.0 ? t - st[RT_LASTEND] : 0.0;
    if (st[RT_COUNT] >= 1.0 && st[RT_CPU0] > 0.0)  /* the last cycle and the work after it */
        c->cpu[(Py_ssize_t)((long long)(st[RT_COUNT] - 1.0) % (long long)c->cap)] =
            cpu_s() - st[RT_CPU0];
    double slot = planned_slot(st, (double)k);
    double due = st[RT_WALL0] + slot * st[RT_PERIOD];
    if (wait_until(c, due, mode)) {
        /* no cycle begins: the landing work that follows still belongs to the last
         * cycle, the time spent here (planning, the wait) does not */
        st[RT_INTERRUPTED] = 1.0;
        st[RT_LASTEND] = now_s();
        return 1;
    }
    st[RT_EXTEND] = 0.0;
    Py_ssize_t i = (Py_ssize_t)((long long)st[RT_COUNT] % (long long)c->cap);
    c->work[i] = work;
    c->cpu[i] = 0.0;
    c->lead[i] = (double)k - slot;
    st[RT_PENDING] = (double)k;
    st[RT_DUE] = due;
    st[RT_START] = now_s();
    st[RT_CPU0] = cpu_s();
    return 0;
}

int rt_before_cycle(long long k, int first)
{
    RtCtx *c = rt_cur;
    return c == NULL ? 0 : begin(c, k, first ? WAIT_FIRM : WAIT_ANY);
}

void rt_after_cycle(long long k)
{
    RtCtx *c = rt_cur;
    (void)k;
    if (c != NULL) close_pending(c, now_s());
}

static int get_ctx(PyObject *const *o, Buf *bufs, RtCtx *c)
{
    static const char *names[NRINGS + 1] = {"st", "busy", "late", "work", "cpu", "lead"};
    for (int k = 0; k <= NRINGS; k++)
        if (get_buf(o[k], &bufs[k], 8, names[k]) < 0) return -1;
    int ok = bufs[0].b.len == 8 * RT_NFIELDS && bufs[1].b.len > 0;
    for (int k = 2; k <= NRINGS; k++) ok = ok && bufs[k].b.len == bufs[1].b.len;
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "rt: context arrays have the wrong sizes");
        return -1;
    }
    double **rings[NRINGS] = {&c->busy, &c->late, &c->work, &c->cpu, &c->lead};
    c->st = bufs[0].b.buf;
    for (int k = 0; k < NRINGS; k++) *rings[k] = bufs[k + 1].b.buf;
    c->cap = bufs[1].b.len / 8;
    return 0;
}

/* The six context arrays as a call's only arguments (st, busy, late, work, cpu, lead);
 * on failure the buffers are released and a Python error is set. */
static int ctx_args(PyObject *args, Buf *bufs, RtCtx *c)
{
    PyObject *o[NRINGS + 1];
    memset(bufs, 0, (NRINGS + 1) * sizeof *bufs);
    if (!PyArg_ParseTuple(args, "OOOOOO", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5]))
        return -1;
    if (get_ctx(o, bufs, c) < 0) { release(bufs, NRINGS + 1); return -1; }
    return 0;
}

const char rt_paced_doc[] =
"rt_paced(st, busy, late, work, cpu, lead, fn, args) -> fn(*args)\n\n"
"Call fn(*args) with the pacing context bound to this thread: every compiled cycle run\n"
"inside waits for its slot on the wall clock and records its busy time.";

PyObject *rt_paced(PyObject *self, PyObject *args)
{
    PyObject *o[NRINGS + 1], *fn, *fargs;
    if (!PyArg_ParseTuple(args, "OOOOOOOO!", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &fn,
                          &PyTuple_Type, &fargs))
        return NULL;
    Buf bufs[NRINGS + 1];
    memset(bufs, 0, sizeof bufs);
    RtCtx c;
    if (get_ctx(o, bufs, &c) < 0) { release(bufs, NRINGS + 1); return NULL; }
    RtCtx *outer = rt_cur;
    rt_cur = &c;
    PyObject *res = PyObject_Call(fn, fargs, NULL);
    rt_cur = outer;
    release(bufs, NRINGS + 1);
    return res;
}

const char rt_wait_doc[] =
"rt_wait(st, busy, late, work, cpu, lead, k) -> True when interrupted instead\n\n"
"End the pending cycle, then sleep (GIL released) until cycle k's slot and make k the\n"
"pending cycle (a cycle the Python path runs; `rt_close` ends it). Returns True without\n"
"beginning k when the executor stops or another thread waits for the lock.";

PyObject *rt_wait(PyObject *self, PyObject *args)
{
    PyObject *o[NRINGS + 1];
    long long k;
    if (!PyArg_ParseTuple(args, "OOOOOOL", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &k))
        return NULL;
    Buf bufs[NRINGS + 1];
    memset(bufs, 0, sizeof bufs);
    RtCtx c;
    if (get_ctx(o, bufs, &c) < 0) { release(bufs, NRINGS + 1); return NULL; }
    int stopped;
    Py_BEGIN_ALLOW_THREADS
    stopped = begin(&c, k, WAIT_ANY);
    Py_END_ALLOW_THREADS
    release(bufs, NRINGS + 1);
    return PyBool_FromLong(stopped);
}

const char rt_close_doc[] =
"rt_close(st, busy, late, work, cpu, lead)\n\nEnd the pending cycle now, or, with none pending,\n"
"extend the last ended cycle's busy time to now (the Python work that landed it).";

PyObject *rt_close(PyObject *self, PyObject *args)
{
    Buf bufs[NRINGS + 1];
    RtCtx c;
    if (ctx_args(args, bufs, &c) < 0) return NULL;
    if (c.st[RT_PENDING] >= 0.0) close_pending(&c, now_s());
    else extend_last(&c, now_s());
    release(bufs, NRINGS + 1);
    Py_RETURN_NONE;
}

const char rt_now_doc[] = "rt_now() -> the pacing clock (CLOCK_MONOTONIC) in seconds";

PyObject *rt_now(PyObject *self, PyObject *args)
{
    return PyFloat_FromDouble(now_s());
}

const char rt_poll_doc[] =
"rt_poll() -> None when no pacing context is bound to this thread, else whether a cycle\n"
"wait was interrupted (st[RT_INTERRUPTED]; the executor clears it)";

PyObject *rt_poll(PyObject *self, PyObject *args)
{
    RtCtx *c = rt_cur;
    if (c == NULL) Py_RETURN_NONE;
    return PyBool_FromLong(c->st[RT_INTERRUPTED] != 0.0);
}

const char rt_slot_doc[] =
"rt_slot(k)\n\nIn a bound pacing context: begin cycle k at its slot (GIL released while\n"
"waiting) before the Python path runs it; nothing when k is already in progress or no\n"
"context is bound.";

PyObject *rt_slot(PyObject *self, PyObject *args)
{
    long long k;
    if (!PyArg_ParseTuple(args, "L", &k)) return NULL;
    RtCtx *c = rt_cur;
    if (c != NULL && c->st[RT_PENDING] != (double)k) {
        Py_BEGIN_ALLOW_THREADS
        begin(c, k, WAIT_STOP);
        Py_END_ALLOW_THREADS
    }
    Py_RETURN_NONE;
}

const char rt_yield_doc[] =
"rt_yield(st, busy, late, work, cpu, lead)\n\nSleep (GIL released) while another thread waits for\n"
"the controller's lock (st[RT_WAITERS] > 0), so it gets the lock; at most 20 ms.";

PyObject *rt_yield(PyObject *self, PyObject *args)
{
    Buf bufs[NRINGS + 1];
    RtCtx c;
    if (ctx_args(args, bufs, &c) < 0) return NULL;
    Py_BEGIN_ALLOW_THREADS
    double end = now_s() + 0.02;
    while (vread(&c.st[RT_WAITERS]) > 0.0 && vread(&c.st[RT_STOPPING]) == 0.0
           && now_s() < end) {
        struct timespec ts = {0, 20000};
        nanosleep(&ts, NULL);
    }
    Py_END_ALLOW_THREADS
    release(bufs, NRINGS + 1);
    Py_RETURN_NONE;
}
