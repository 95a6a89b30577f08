/* _native.c - the C extension behind the bijparam Python package.

   It compiles bijparam.h (the whole library, with its thread pool) and
   examples/bp_gltf.h (its glTF reader and writer) into one module on the
   CPython and numpy C APIs.  The Python layer (__init__.py)
   turns the user's arrays and keywords into exact types -- float64 (N,3)
   positions, uint32 (M,3) indices, option numbers -- and this file checks
   them again (a direct call with anything else raises, never crashes), copies
   them into memory of its own, and runs the library.

   Every library call runs on a native worker thread while the calling
   thread, with the GIL released, waits on a condition variable in slices
   of 20 ms.  Between slices it hands the progress the worker kept to the
   Python callable (so the callable runs on the calling thread, with the
   GIL), and calls PyErr_CheckSignals (so Ctrl-C raises KeyboardInterrupt
   there).  An exception from either raises the run's cancel flag, which the
   library's run_progress callback returns at its next report: every chart
   stops at its next iteration (bijparam.h, >>progress), the worker returns,
   and the exception propagates.  Two Python threads calling the library at
   once each get a worker of their own and run in parallel.

   Failures come back to Python as a tuple (status name, message, element,
   index, index2, line), which __init__.py raises as the matching exception;
   the library's messages are kept as written. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>

#define BP_IMPLEMENTATION
#define BP_STATIC
#define BP_USE_PTHREADS
#include "bijparam.h"
#define BPG_IMPLEMENTATION
#include "bp_gltf.h"

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds of the whole process, every thread (the tool's cpu_timings) */
static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* When each stage first and last reported, and when the call began and
   the library returned: on the wall clock and on the CPU clock. */
typedef struct stamps {
    double first[BP_STAGE_COUNT], last[BP_STAGE_COUNT];
    double begin, solved;
} stamps;

/* ---- an allocator with a budget (the memory_limit option) ----------------

   Every block carries its size in a 16-byte header, so the count of live
   bytes is exact; a request that would pass the limit gets NULL, which the
   library reports as BP_ERR_OUT_OF_MEMORY (MemoryError in Python).  The
   library calls it from several threads: the count is atomic. */
typedef struct budget {
    size_t limit;
    size_t used;      /* atomic */
    size_t peak;      /* atomic (max) */
} budget;

static void *budget_alloc(void *user, size_t size)
{
    budget *b = (budget *)user;
    size_t need = size + 16, used, peak;
    unsigned char *p;
    if (need < size) return NULL;
    used = __atomic_add_fetch(&b->used, need, __ATOMIC_RELAXED);
    if (used > b->limit || used < need) {
        __atomic_sub_fetch(&b->used, need, __ATOMIC_RELAXED);
        return NULL;
    }
    p = (unsigned char *)malloc(need);
    if (!p) {
        __atomic_sub_fetch(&b->used, need, __ATOMIC_RELAXED);
        return NULL;
    }
    peak = __atomic_load_n(&b->peak, __ATOMIC_RELAXED);
    while (used > peak && !__atomic_compare_exchange_n(&b->peak, &peak, used, 1, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {}
    memcpy(p, &need, sizeof need);
    return p + 16;
}

static void budget_free(void *user, void *ptr)
{
    budget *b = (budget *)user;
    unsigned char *p = (unsigned char *)ptr - 16;
    size_t need;
    memcpy(&need, p, sizeof need);
    __atomic_sub_fetch(&b->used, need, __ATOMIC_RELAXED);
    free(p);
}

/* ---- the worker thread and the calling thread's wait ---------------------- */

enum { JOB_PARAMETERIZE, JOB_READ, JOB_WRITE, JOB_CHECK, JOB_GLTF_READ, JOB_GLTF_ENCODE };

typedef struct job {
    int kind;
    bp_options opt;            /* run_progress set to job_progress          */
    int threads;               /* the pool's size (opt.threads)             */
    bp_mesh *mesh;
    bp_atlas *atlas;
    const char *path, *source;
    /* JOB_CHECK */
    struct check_job *check;
    /* JOB_GLTF_READ, JOB_GLTF_ENCODE (examples/bp_gltf.h) */
    bpg_file *gltf;
    bpg_options gltf_read;
    bpg_write_options gltf_write;
    bpg_output gltf_out;
    /* the outcome */
    bp_status st;
    bp_error err;
    /* the worker's end: done, under mu, signalled on cv */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int done;
    /* shared with the calling thread through atomics (job_progress) */
    int cancel;                /* the calling thread asks the run to stop  */
    int want_progress;         /* the calling thread takes reports         */
    uint64_t fraction_bits[BP_STAGE_COUNT];   /* each stage's latest fraction */
    uint32_t reports[BP_STAGE_COUNT];         /* ... and its count of reports */
    uint32_t first_order[BP_STAGE_COUNT];     /* the order of its first report, 1-based; 0: none yet */
    /* written by the library's threads, one at a time (job_progress), read
       after the worker is joined */
    uint32_t stages_seen, start_reports;
    stamps wall, cpu;
    double t_begin, t_end, cpu_end;
    /* JOB_PARAMETERIZE: what is made from the atlas on the worker, while
       the call's pool is still up (see parameterize_job) */
    int f64;                   /* uvs as float64, else float32             */
    struct chart_extra *extra; /* per chart: the report's numbers          */
    uint64_t num_out;          /* output vertices                          */
    uint32_t *vmapping, *indices;
    void *uvs;
    unsigned char *failed_faces;
    double seams[3];           /* seam edges, their 3D length, over sqrt(area) */
    int seams_ok;
    bp_status round_st;        /* bp_check of the float32 map              */
    bp_error round_err;
    int oom;                   /* a buffer above could not be allocated    */
} job;

/* bp_options.run_progress: records the stage times, leaves the report for
   the calling thread, and answers the cancel flag.  It is called at every
   iteration of every chart, by the library's threads one at a time: a
   thread that finds another inside it waits, spinning (>>progress).  So it
   must not block or enter the kernel -- a thread descheduled in it on a
   busy machine would hold the others spinning for its time slice (with a
   mutex and the process's CPU clock here, lucy's two-thread optimization
   took 0.45 s of CPU where the tool took 0.23): atomics and the wall clock
   (vDSO) only, and the CPU clock (a system call) at a handful of reports,
   a stage's first, the charts stage's two, a single chart's start.  The
   calling thread reads each stage's latest fraction every 20 ms. */
static int job_progress(void *user, bp_stage stage, double fraction, uint32_t chart)
{
    job *J = (job *)user;
    double t = now_seconds();
    (void)chart;
    if ((int)stage >= 0 && stage < BP_STAGE_COUNT) {
        int first = J->wall.first[stage] == 0;
        int clock = first || stage == BP_STAGE_CHARTS || (stage == BP_STAGE_START && J->start_reports < 2);
        double c = clock ? cpu_seconds() : 0;
        uint64_t bits;
        if (first) { J->wall.first[stage] = t; J->cpu.first[stage] = c; }
        J->wall.last[stage] = t;
        if (clock) J->cpu.last[stage] = c;
        if (stage == BP_STAGE_START) J->start_reports++;
        if (__atomic_load_n(&J->want_progress, __ATOMIC_RELAXED)) {
            memcpy(&bits, &fraction, sizeof bits);
            __atomic_store_n(&J->fraction_bits[stage], bits, __ATOMIC_RELAXED);
            if (first) __atomic_store_n(&J->first_order[stage], ++J->stages_seen, __ATOMIC_RELAXED);
            __atomic_add_fetch(&J->reports[stage], 1, __ATOMIC_RELEASE);
        }
    }
    return __atomic_load_n(&J->cancel, __ATOMIC_ACQUIRE);
}

static void run_check_job(job *J);
static void parameterize_job(job *J);

static void *job_main(void *arg)
{
    job *J = (job *)arg;
    bp_pool *pool = NULL;
    J->t_begin = J->wall.begin = now_seconds();
    J->cpu.begin = cpu_seconds();
    /* one pool for the call, as the tool keeps one for its stages */
    if (J->threads != 1 && bp_pool_create(&pool, J->threads, NULL, NULL) == BP_OK) {
        J->opt.parallel_for = bp_pool_for;
        J->opt.parallel_user = pool;
    }
    switch (J->kind) {
    case JOB_PARAMETERIZE:
        parameterize_job(J);
        break;
    case JOB_READ:
        J->st = bp_read_mesh_opt(J->path, J->mesh, &J->opt, &J->err);
        break;
    case JOB_WRITE:
        J->st = bp_write_obj_opt(J->path, J->source, J->mesh, J->atlas, &J->opt, &J->err);
        break;
    case JOB_CHECK:
        run_check_job(J);
        break;
    case JOB_GLTF_READ:
        J->st = bpg_read(J->gltf, J->path, &J->gltf_read, &J->err);
        break;
    case JOB_GLTF_ENCODE:
        J->gltf_write.check = &J->opt;             /* the rounded map's check on the call's threads */
        J->st = bpg_encode(J->gltf, J->atlas, &J->gltf_write, &J->gltf_out, &J->err);
        break;
    }
    bp_pool_destroy(pool);
    J->t_end = now_seconds();
    J->cpu_end = cpu_seconds();
    pthread_mutex_lock(&J->mu);
    J->done = 1;
    pthread_cond_signal(&J->cv);
    pthread_mutex_unlock(&J->mu);
    return NULL;
}

static void job_init(job *J, int kind, int threads, PyObject *progress)
{
    memset(J, 0, sizeof *J);
    J->kind = kind;
    J->threads = threads;
    bp_options_init(&J->opt);
    J->opt.threads = threads;
    J->opt.run_progress = job_progress;
    J->opt.run_progress_user = J;
    J->want_progress = progress != NULL && progress != Py_None;
}

/* Run J on a worker thread and wait for it, as the header of this file
   says.  Returns 0 when it ran to its end with no Python exception, -1 with
   the exception set (the callable's, KeyboardInterrupt, or a failure to
   start the thread); the worker has finished either way. */
static int job_run(job *J, PyObject *progress)
{
    pthread_t th;
    sigset_t all, old;
    int rc, failed = 0;
    uint32_t delivered[BP_STAGE_COUNT];
    PyObject *exc_type = NULL, *exc_value = NULL, *exc_tb = NULL;

    pthread_mutex_init(&J->mu, NULL);
    {
        pthread_condattr_t ca;
        pthread_condattr_init(&ca);
        pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
        pthread_cond_init(&J->cv, &ca);
        pthread_condattr_destroy(&ca);
    }
    /* The worker (and the library's pool threads it starts) block every
       signal: Python's handlers run on the main thread, and a system call
       of the library's reader or writer is never interrupted. */
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    rc = pthread_create(&th, NULL, job_main, J);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (rc != 0) {
        pthread_cond_destroy(&J->cv);
        pthread_mutex_destroy(&J->mu);
        errno = rc;
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    memset(delivered, 0, sizeof delivered);
    for (;;) {
        int n = 0, done, k, s_;
        bp_stage items[BP_STAGE_COUNT];
        double fractions[BP_STAGE_COUNT];
        Py_BEGIN_ALLOW_THREADS
        pthread_mutex_lock(&J->mu);
        if (!J->done) {
            struct timespec ts;
            clock_gettime(CLOCK_MONOTONIC, &ts);
            ts.tv_nsec += 20000000L;
            if (ts.tv_nsec >= 1000000000L) { ts.tv_sec++; ts.tv_nsec -= 1000000000L; }
            pthread_cond_timedwait(&J->cv, &J->mu, &ts);
        }
        done = J->done;
        pthread_mutex_unlock(&J->mu);
        Py_END_ALLOW_THREADS
        /* the stages with news, in the order they began */
        for (s_ = 0; s_ < BP_STAGE_COUNT; s_++) {
            uint32_t r = __atomic_load_n(&J->reports[s_], __ATOMIC_ACQUIRE);
            uint64_t bits;
            if (r == delivered[s_]) continue;
            delivered[s_] = r;
            bits = __atomic_load_n(&J->fraction_bits[s_], __ATOMIC_RELAXED);
            for (k = n; k > 0 && __atomic_load_n(&J->first_order[items[k - 1]], __ATOMIC_RELAXED) >
                                 __atomic_load_n(&J->first_order[s_], __ATOMIC_RELAXED); k--) {
                items[k] = items[k - 1];
                fractions[k] = fractions[k - 1];
            }
            items[k] = (bp_stage)s_;
            memcpy(&fractions[k], &bits, sizeof bits);
            n++;
        }
        for (k = 0; k < n && !failed; k++) {
            PyObject *r = PyObject_CallFunction(progress, "sd", bp_stage_name(items[k]), fractions[k]);
            if (!r) failed = 1;
            Py_XDECREF(r);
        }
        if (!failed && PyErr_CheckSignals() < 0) failed = 1;
        if (failed && !exc_type) {
            PyErr_Fetch(&exc_type, &exc_value, &exc_tb);   /* kept until the worker is done */
            __atomic_store_n(&J->want_progress, 0, __ATOMIC_RELAXED);
            __atomic_store_n(&J->cancel, 1, __ATOMIC_RELEASE);
        }
        if (done) break;
    }
    Py_BEGIN_ALLOW_THREADS
    pthread_join(th, NULL);
    Py_END_ALLOW_THREADS
    pthread_cond_destroy(&J->cv);
    pthread_mutex_destroy(&J->mu);
    if (exc_type) {
        PyErr_Restore(exc_type, exc_value, exc_tb);
        return -1;
    }
    return 0;
}

/* ---- failures as Python values -------------------------------------------- */

static const char *status_name(bp_status s)
{
    switch (s) {
#define BPPY_NAME(name, text) case name: return #name;
    BP_STATUS_LIST(BPPY_NAME)
#undef BPPY_NAME
    default: return "BP_ERR_UNKNOWN";
    }
}

static const char *element_name(bp_element e)
{
    switch (e) {
    case BP_ELEMENT_VERTEX: return "vertex";
    case BP_ELEMENT_TRIANGLE: return "triangle";
    case BP_ELEMENT_EDGE: return "edge";
    case BP_ELEMENT_CHART: return "chart";
    case BP_ELEMENT_LINE: return "line";
    default: return "none";
    }
}

/* A message of the library as str: it may quote a file's bytes, which need
   not be UTF-8 (replaced, never an error). */
static PyObject *message_str(const char *m)
{
    return PyUnicode_DecodeUTF8(m, (Py_ssize_t)strlen(m), "replace");
}

/* ("error", status, message, element, index, index2, line) */
static PyObject *error_tuple(bp_status st, const bp_error *err)
{
    return Py_BuildValue("(sssNsLLL)", "error", status_name(st), bp_status_string(st),
                         message_str(err->message[0] ? err->message : bp_status_string(st)), element_name(err->element),
                         (long long)err->index, (long long)err->index2, (long long)err->line);
}

/* ---- arrays in ------------------------------------------------------------- */

/* `obj` must be a C-contiguous aligned array of `type` with `ndim`
   dimensions and, when cols > 0, shape[1] == cols.  Returns its row count,
   or -1 with TypeError / ValueError set. */
static Py_ssize_t check_array(PyObject *obj, const char *name, int type, int ndim, npy_intp cols)
{
    PyArrayObject *a;
    if (!PyArray_Check(obj)) {
        PyErr_Format(PyExc_TypeError, "%s must be a numpy array", name);
        return -1;
    }
    a = (PyArrayObject *)obj;
    if (PyArray_TYPE(a) != type || PyArray_NDIM(a) != ndim ||
        !PyArray_IS_C_CONTIGUOUS(a) || !PyArray_ISALIGNED(a) || !PyArray_ISNOTSWAPPED(a) ||
        (ndim == 2 && cols > 0 && PyArray_DIM(a, 1) != cols)) {
        PyErr_Format(PyExc_ValueError, "%s: expected a C-contiguous %s array of %d dimension%s%s", name,
                     type == NPY_DOUBLE ? "float64" : "uint32", ndim, ndim == 1 ? "" : "s",
                     ndim == 2 && cols == 3 ? " with 3 columns" : ndim == 2 && cols == 2 ? " with 2 columns" :
                     ndim == 2 && cols == 4 ? " with 4 columns" : "");
        return -1;
    }
    return (Py_ssize_t)PyArray_DIM(a, 0);
}

/* A copy of the array's data in malloc'd memory (at least 1 byte). */
static void *copy_data(PyObject *obj)
{
    size_t n = (size_t)PyArray_NBYTES((PyArrayObject *)obj);
    void *p = malloc(n ? n : 1);
    if (!p) { PyErr_NoMemory(); return NULL; }
    if (n) memcpy(p, PyArray_DATA((PyArrayObject *)obj), n);
    return p;
}

/* ---- the result handle: the mesh and atlas a result keeps for writing ----- */

typedef struct {
    PyObject_HEAD
    bp_mesh mesh;              /* malloc'd copies of the arrays           */
    bp_atlas atlas;
    int has_atlas;
    int writing;               /* writes under way (release waits for none) */
    budget *budget;            /* memory_limit: the allocator the atlas records */
} AtlasObject;

static void mesh_free_owned(bp_mesh *m)
{
    free(m->positions); free(m->triangles); free(m->corner_uv); free(m->uvs);
    free(m->triangle_line); free(m->triangle_face);
    memset(m, 0, sizeof *m);
}

static void Atlas_clear(AtlasObject *self)
{
    if (self->has_atlas) bp_atlas_free(&self->atlas);
    self->has_atlas = 0;
    mesh_free_owned(&self->mesh);
    free(self->budget);
    self->budget = NULL;
}

static void Atlas_dealloc(AtlasObject *self)
{
    Atlas_clear(self);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *Atlas_release(PyObject *self, PyObject *noargs)
{
    (void)noargs;
    if (((AtlasObject *)self)->writing) {       /* another thread's write reads them */
        PyErr_SetString(PyExc_RuntimeError, "the result is being written: release it after the write");
        return NULL;
    }
    Atlas_clear((AtlasObject *)self);
    Py_RETURN_NONE;
}

static PyObject *Atlas_write(PyObject *self, PyObject *args);

static PyMethodDef Atlas_methods[] = {
    {"write", Atlas_write, METH_VARARGS,
     "write(path, source, threads, progress): bp_write_obj_opt into path (the caller renames it)"},
    {"release", Atlas_release, METH_NOARGS, "free the mesh and atlas now"},
    {NULL, NULL, 0, NULL}
};

static PyTypeObject AtlasType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "bijparam._native.Atlas",
    .tp_basicsize = sizeof(AtlasObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "the library's mesh and atlas behind a result (for writing it)",
    .tp_dealloc = (destructor)Atlas_dealloc,
    .tp_methods = Atlas_methods,
};

/* ---- options ---------------------------------------------------------------- */

static int opt_get_double(PyObject *d, const char *key, double *out)
{
    PyObject *v = PyDict_GetItemString(d, key);
    if (!v) return 0;
    *out = PyFloat_AsDouble(v);
    return *out == -1.0 && PyErr_Occurred() ? -1 : 0;
}

static int opt_get_long(PyObject *d, const char *key, long long lo, long long hi, long long *out)
{
    PyObject *v = PyDict_GetItemString(d, key);
    long long x;
    if (!v) return 0;
    x = PyLong_AsLongLong(v);
    if (x == -1 && PyErr_Occurred()) return -1;
    if (x < lo || x > hi) {
        PyErr_Format(PyExc_ValueError, "option %s = %lld is out of range [%lld, %lld]", key, x, lo, hi);
        return -1;
    }
    *out = x;
    return 0;
}

static int opt_get_vec3(PyObject *d, const char *key, double *out)
{
    PyObject *v = PyDict_GetItemString(d, key);
    int k;
    if (!v) return 0;
    if (!PyTuple_Check(v) || PyTuple_GET_SIZE(v) != 3) {
        PyErr_Format(PyExc_ValueError, "option %s needs 3 numbers", key);
        return -1;
    }
    for (k = 0; k < 3; k++) {
        out[k] = PyFloat_AsDouble(PyTuple_GET_ITEM(v, k));
        if (out[k] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

/* The option dict of __init__.py (already named and ranged there; checked
   again here) into bp_options.  Integers are read into long long first. */
static int options_from_dict(PyObject *d, bp_options *o, size_t *memory_limit)
{
    long long x;
    double y = 0;
#define BPPY_INT(key, field, lo, hi, T) \
    do { x = 0; if (opt_get_long(d, key, lo, hi, &x) < 0) return -1; \
         if (PyDict_GetItemString(d, key)) o->field = (T)x; } while (0)
#define BPPY_DBL(key, field) \
    do { if (PyDict_GetItemString(d, key)) { if (opt_get_double(d, key, &y) < 0) return -1; o->field = y; } } while (0)
    if (!PyDict_Check(d)) { PyErr_SetString(PyExc_TypeError, "options must be a dict"); return -1; }
    BPPY_INT("init", init, 0, 4, bp_init);
    BPPY_INT("init_only", init_only, 0, 1, int);
    BPPY_INT("energy", energy, 0, BP_ENERGY_COUNT - 1, bp_energy);
    BPPY_INT("no_barrier", no_barrier, 0, 1, int);
    BPPY_DBL("epsilon", epsilon);
    BPPY_INT("direction", direction, 0, 4, bp_direction);
    BPPY_INT("history", history, 0, 1000000, int);
    BPPY_INT("max_iterations", max_iterations, 0, INT32_MAX, int);
    BPPY_DBL("tolerance", tolerance);
    BPPY_DBL("max_seconds", max_seconds);
    BPPY_INT("normalize", normalize, 0, 1, int);
    BPPY_INT("threads", threads, 0, 256, int);
    BPPY_INT("strict", strict, 0, 1, int);
    BPPY_INT("atlas_resolution", atlas_resolution, 0, INT32_MAX, int);
    BPPY_INT("padding", padding, INT32_MIN, INT32_MAX, int);
    BPPY_INT("no_rotation", no_rotation, 0, 1, int);
    BPPY_INT("cut", cut, 0, 1, bp_cut);
    BPPY_INT("segment", segment, -1, 1, int);
    BPPY_DBL("max_distortion", max_distortion);
    BPPY_INT("max_charts", max_charts, 0, UINT32_MAX, uint32_t);
    BPPY_INT("start", start, 0, 2, bp_start);
    BPPY_INT("views_model", views.model, 0, BP_VIEW_LIST, int);
    if (opt_get_vec3(d, "view_dir", o->views.direction) < 0) return -1;
    if (opt_get_vec3(d, "up", o->views.up) < 0) return -1;
    BPPY_DBL("elevation", views.elevation);
    BPPY_INT("samples", views.samples, 0, UINT32_MAX, uint32_t);
    BPPY_INT("seed", views.seed, 0, INT64_MAX, uint64_t);
    BPPY_DBL("floor", views.floor);
#undef BPPY_INT
#undef BPPY_DBL
    x = 0;
    if (opt_get_long(d, "memory_limit", 0, INT64_MAX, &x) < 0) return -1;
    *memory_limit = (size_t)x;
    return 0;
}

/* ---- the report (the tool's --json, as a dict) ------------------------------ */

/* A finite double, else None (the tool writes null). */
static PyObject *number_or_none(double x)
{
    if (isfinite(x)) return PyFloat_FromDouble(x);
    Py_RETURN_NONE;
}

/* Set d[key] = value, stealing the reference; -1 on failure. */
static int put(PyObject *d, const char *key, PyObject *value)
{
    int r;
    if (!value) return -1;
    r = PyDict_SetItemString(d, key, value);
    Py_DECREF(value);
    return r;
}

/* V - E + F of a chart: its edges counted once each, by the smaller end. */
static long chart_euler(const bp_chart *c)
{
    size_t n = 3 * (size_t)c->num_triangles, k, edges = 0;
    uint32_t nv = c->num_vertices, v;
    uint32_t *start = (uint32_t *)calloc((size_t)nv + 2, sizeof *start);
    uint32_t *hi = (uint32_t *)malloc((n ? n : 1) * sizeof *hi);
    uint32_t *mark = (uint32_t *)malloc(((size_t)nv + 1) * sizeof *mark);
    if (!start || !hi || !mark) { free(start); free(hi); free(mark); return 0; }
    for (k = 0; k < n; k++) {
        uint32_t a = c->triangles[k], b = c->triangles[k - k % 3 + (k + 1) % 3];
        start[(a < b ? a : b) + 2]++;
    }
    for (v = 2; v <= nv + 1; v++) start[v] += start[v - 1];
    for (k = 0; k < n; k++) {
        uint32_t a = c->triangles[k], b = c->triangles[k - k % 3 + (k + 1) % 3];
        hi[start[(a < b ? a : b) + 1]++] = a < b ? b : a;
    }
    for (v = 0; v < nv; v++) mark[v] = 0xffffffffu;
    for (v = 0; v < nv; v++)
        for (k = start[v]; k < start[v + 1]; k++)
            if (mark[hi[k]] != v) { mark[hi[k]] = v; edges++; }
    free(start); free(hi); free(mark);
    return (long)c->num_vertices - (long)edges + (long)c->num_triangles;
}

static PyObject *repairs_dict(const bp_repair_report *r)
{
    PyObject *d = PyDict_New();
    int k;
    uint32_t i;
    if (!d || put(d, "total", PyLong_FromUnsignedLong(r->total)) < 0) goto fail;
    for (k = 0; k < BP_REPAIR_KINDS; k++) {
        const bp_repair *p = &r->kind[k];
        uint32_t n = p->count < BP_REPAIR_FIRST ? p->count : BP_REPAIR_FIRST;
        PyObject *e = PyDict_New(), *first = PyList_New(0);
        if (!e || !first) { Py_XDECREF(e); Py_XDECREF(first); goto fail; }
        for (i = 0; i < n; i++) {     /* numbered as the tool's --json: from 1 */
            PyObject *item = p->first2[i] >= 0
                ? Py_BuildValue("[LL]", (long long)p->first[i] + 1, (long long)p->first2[i] + 1)
                : PyLong_FromLongLong((long long)p->first[i] + 1);
            if (!item || PyList_Append(first, item) < 0) { Py_XDECREF(item); Py_DECREF(first); Py_DECREF(e); goto fail; }
            Py_DECREF(item);
        }
        if (put(e, "count", PyLong_FromUnsignedLong(p->count)) < 0 || put(e, "first", first) < 0 ||
            (k == BP_REPAIR_FLIPPED && put(e, "written_reordered", PyLong_FromLong(0)) < 0) ||
            put(e, "message", PyUnicode_DecodeUTF8(p->message, (Py_ssize_t)strlen(p->message), "replace")) < 0 ||
            put(d, bp_repair_name((bp_repair_kind)k), e) < 0)
            goto fail;
    }
    return d;
fail:
    Py_XDECREF(d);
    return NULL;
}

static const char *start_map_name(const bp_chart *ch)
{
    return ch->start_map == BP_INIT_CONFORMAL ? "conformal" : ch->start_map == BP_INIT_MEAN_VALUE ? "mvc" :
           ch->start_map == BP_INIT_TUTTE ? "tutte" : ch->start_map == BP_INIT_INPUT ? "input" : "planar";
}

static const char *direction_name(bp_direction d)
{
    return d == BP_DIRECTION_NEWTON ? "newton" : d == BP_DIRECTION_PRECONDITIONED ? "precond" :
           d == BP_DIRECTION_GRADIENT ? "gd" : "lbfgs";
}

/* The report's numbers for one chart, made on the worker: the exact check
   of its map (the tool's per-chart check), its Euler characteristic, and
   for a chart left at its start map (init_only) that map's distortion. */
typedef struct chart_extra {
    bp_check_report rep;
    long euler;
    double e_start, e_end, e_max;
} chart_extra;

/* The arrays out.  One output vertex per chart vertex, chart after chart
   (the library's order, which bp_write_obj gives the vt lines too); each
   face keeps its place and its corners' order, corner k of face t getting
   the output vertex of (corner_chart[3t+k], corner_vertex[3t+k]).  A failed
   chart's vertices come last with NaN coordinates (they are seen only in
   the result a ChartsFailedError carries).  Then the map as the caller gets
   it, rounded to float32, is checked exactly: the charts' own triangles
   (their repaired orientation) on the rounded coordinates, all charts
   together.  In float64 it is the library's map, which bp_parameterize has
   verified already. */
static int make_outputs(job *J, const bp_options *cop)
{
    const bp_atlas *at = J->atlas;
    uint32_t c, i, nt = J->mesh->num_triangles;
    uint64_t k = 0, nmapped = 0, ntri = 0;
    uint64_t *base = (uint64_t *)malloc(((size_t)at->num_charts + 1) * sizeof *base);
    if (!base) return -1;
    for (c = 0; c < at->num_charts; c++)
        if (at->charts[c].uv) { base[c] = k; k += at->charts[c].num_vertices; ntri += at->charts[c].num_triangles; }
    nmapped = k;
    for (c = 0; c < at->num_charts; c++) if (!at->charts[c].uv) { base[c] = k; k += at->charts[c].num_vertices; }
    J->num_out = k;
    if (k > UINT32_MAX) { free(base); return -2; }
    J->vmapping = (uint32_t *)malloc(k * sizeof(uint32_t) + 1);
    J->uvs = malloc(2 * k * (J->f64 ? sizeof(double) : sizeof(float)) + 1);
    J->indices = (uint32_t *)malloc(3 * (size_t)nt * sizeof(uint32_t) + 1);
    J->failed_faces = (unsigned char *)malloc((size_t)nt + 1);
    if (!J->vmapping || !J->uvs || !J->indices || !J->failed_faces) { free(base); return -1; }
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        uint64_t b = base[c];
        for (i = 0; i < ch->num_vertices; i++) {
            double u = ch->uv ? ch->uv[2 * (size_t)i] : NAN, v = ch->uv ? ch->uv[2 * (size_t)i + 1] : NAN;
            J->vmapping[b + i] = ch->vertex[i];
            if (J->f64) {
                ((double *)J->uvs)[2 * (b + i)] = u;
                ((double *)J->uvs)[2 * (b + i) + 1] = v;
            } else {
                ((float *)J->uvs)[2 * (b + i)] = (float)u;
                ((float *)J->uvs)[2 * (b + i) + 1] = (float)v;
            }
        }
    }
    for (i = 0; i < nt; i++) {
        int q, bad = 0;
        for (q = 0; q < 3; q++) {
            size_t cc = 3 * (size_t)i + q;
            uint32_t ch = at->corner_chart[cc];
            J->indices[cc] = (uint32_t)(base[ch] + at->corner_vertex[cc]);
            if (!at->charts[ch].uv) bad = 1;
        }
        J->failed_faces[i] = (unsigned char)bad;
    }
    J->round_st = BP_OK;
    if (!J->f64 && ntri) {
        uint32_t *tri = (uint32_t *)malloc(3 * (size_t)ntri * sizeof *tri);
        double *uv = (double *)malloc(2 * (size_t)nmapped * sizeof *uv + 1);
        const float *fu = (const float *)J->uvs;
        size_t t = 0;
        bp_check_report rep;
        if (!tri || !uv) { free(tri); free(uv); free(base); return -1; }
        for (i = 0; i < 2 * nmapped; i++) uv[i] = fu[i];          /* mapped charts come first */
        for (c = 0; c < at->num_charts; c++) {
            const bp_chart *ch = &at->charts[c];
            if (!ch->uv) continue;
            for (i = 0; i < 3 * ch->num_triangles; i++) tri[t++] = (uint32_t)(base[c] + ch->triangles[i]);
        }
        J->round_st = bp_check_opt(tri, (uint32_t)ntri, uv, (uint32_t)nmapped, cop, &rep, &J->round_err);
        free(tri);
        free(uv);
        if (J->round_st == BP_ERR_OUT_OF_MEMORY) { free(base); return -1; }
    }
    free(base);
    return 0;
}

/* The tool's "seams": mesh edges with a chart boundary on both sides (a
   chart's boundary edge is a seam where another boundary edge runs between
   the same two mesh vertices; alone, it is the mesh's own boundary), their
   3D length, and that over the square root of the mesh's area (free of
   the mesh's scale).  0 when out of memory. */
typedef struct seam_edge { uint32_t lo, hi; } seam_edge;

static int seam_edge_cmp(const void *pa, const void *pb)
{
    const seam_edge *a = (const seam_edge *)pa, *b = (const seam_edge *)pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    return (a->hi > b->hi) - (a->hi < b->hi);
}

static int seam_stats(const bp_mesh *m, const bp_atlas *at, double out[3])
{
    size_t n = 0, i, j;
    uint32_t c, l, k, t;
    double area = 0;
    seam_edge *e;
    out[0] = out[1] = out[2] = 0;
    for (c = 0; c < at->num_charts; c++)
        if (at->charts[c].num_loops) n += at->charts[c].loop_start[at->charts[c].num_loops];
    if (!(e = (seam_edge *)malloc((n ? n : 1) * sizeof *e))) return 0;
    for (c = 0, n = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        for (l = 0; l < ch->num_loops; l++) {
            uint32_t a0 = ch->loop_start[l], a1 = ch->loop_start[l + 1];
            for (k = a0; k < a1; k++) {
                uint32_t u = ch->vertex[ch->loop_vertices[k]], v = ch->vertex[ch->loop_vertices[k + 1 < a1 ? k + 1 : a0]];
                e[n].lo = u < v ? u : v;
                e[n].hi = u < v ? v : u;
                n++;
            }
        }
    }
    qsort(e, n, sizeof *e, seam_edge_cmp);
    for (i = 0; i < n; i = j) {
        for (j = i + 1; j < n && e[j].lo == e[i].lo && e[j].hi == e[i].hi; j++) {}
        if (j - i >= 2) {
            const double *p = m->positions + 3 * (size_t)e[i].lo, *q = m->positions + 3 * (size_t)e[i].hi;
            double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
            out[0] += (double)((j - i) / 2);
            out[1] += (double)((j - i) / 2) * sqrt(dx * dx + dy * dy + dz * dz);
        }
    }
    free(e);
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *tr = m->triangles + 3 * (size_t)t;
        const double *a = m->positions + 3 * (size_t)tr[0], *b = m->positions + 3 * (size_t)tr[1],
                     *d = m->positions + 3 * (size_t)tr[2];
        double u[3], v[3], x, y, z;
        for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = d[k] - a[k]; }
        x = u[1] * v[2] - u[2] * v[1]; y = u[2] * v[0] - u[0] * v[2]; z = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * sqrt(x * x + y * y + z * z);
    }
    if (area > 0) out[2] = out[1] / sqrt(area);
    return 1;
}

/* The worker's part of a parameterization: bp_parameterize, then, on the
   same pool, the report's numbers and the arrays out. */
static void parameterize_job(job *J)
{
    bp_options cop;
    uint32_t c;
    int r;
    J->st = bp_parameterize(J->atlas, J->mesh, &J->opt, &J->err);
    J->wall.solved = now_seconds();
    J->cpu.solved = cpu_seconds();
    if (J->st != BP_OK && J->st != BP_ERR_CHARTS_FAILED) return;
    cop = J->opt;                         /* the call's threads, no callback, malloc */
    memset(&cop.allocator, 0, sizeof cop.allocator);
    cop.run_progress = NULL;
    cop.run_progress_user = NULL;
    if (!(J->extra = (chart_extra *)calloc((size_t)J->atlas->num_charts + 1, sizeof *J->extra))) { J->oom = 1; return; }
    for (c = 0; c < J->atlas->num_charts; c++) {
        const bp_chart *ch = &J->atlas->charts[c];
        chart_extra *x = &J->extra[c];
        x->e_start = ch->energy_start;
        x->e_end = ch->energy_end;
        x->e_max = ch->energy_max;
        if (ch->uv && ch->stop == BP_STOP_NONE &&
            bp_chart_distortion(ch, J->mesh, J->opt.energy, &x->e_start, &x->e_max, NULL, NULL) == BP_OK)
            x->e_end = x->e_start;            /* not optimized: the start map's distortion */
        if (ch->uv) bp_check_opt(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, &cop, &x->rep, NULL);
        x->euler = chart_euler(ch);
    }
    J->seams_ok = seam_stats(J->mesh, J->atlas, J->seams);
    if ((r = make_outputs(J, &cop)) < 0) J->oom = r == -2 ? 2 : 1;
}

static void free_outputs(job *J)
{
    free(J->extra); free(J->vmapping); free(J->indices); free(J->uvs); free(J->failed_faces);
    J->extra = NULL; J->vmapping = J->indices = NULL; J->uvs = NULL; J->failed_faces = NULL;
}

static PyObject *chart_dict(const bp_chart *ch, uint32_t c, const chart_extra *x)
{
    PyObject *d = PyDict_New(), *loops;
    uint32_t l;
    if (!d) return NULL;
    if (!(loops = PyList_New(ch->num_loops))) goto fail;
    for (l = 0; l < ch->num_loops; l++) {
        PyObject *n = PyLong_FromUnsignedLong(ch->loop_start[l + 1] - ch->loop_start[l]);
        if (!n) { Py_DECREF(loops); goto fail; }
        PyList_SET_ITEM(loops, l, n);
    }
    if (put(d, "index", PyLong_FromUnsignedLong(c)) < 0 ||
        put(d, "vertices", PyLong_FromUnsignedLong(ch->num_vertices)) < 0 ||
        put(d, "faces", PyLong_FromUnsignedLong(ch->num_triangles)) < 0 ||
        put(d, "loops", loops) < 0 ||
        put(d, "euler", PyLong_FromLong(x->euler)) < 0 ||
        put(d, "split_vertices", PyLong_FromUnsignedLong(ch->split_vertices)) < 0 ||
        put(d, "cut_edges", PyLong_FromUnsignedLong(ch->cut_edges)) < 0 ||
        put(d, "energy_start", number_or_none(x->e_start)) < 0 ||
        put(d, "energy_end", number_or_none(x->e_end)) < 0 ||
        put(d, "energy_max", number_or_none(x->e_max)) < 0 ||
        put(d, "iterations", PyLong_FromLong(ch->iterations)) < 0 ||
        put(d, "stop", PyUnicode_FromString(bp_stop_string(ch->stop))) < 0 ||
        put(d, "error", ch->error.status != BP_OK
                ? PyUnicode_DecodeUTF8(ch->error.message, (Py_ssize_t)strlen(ch->error.message), "replace")
                : (Py_INCREF(Py_None), Py_None)) < 0 ||
        put(d, "init_used", PyLong_FromLong(ch->init_used)) < 0 ||
        put(d, "start_map", ch->uv ? PyUnicode_FromString(start_map_name(ch)) : (Py_INCREF(Py_None), Py_None)) < 0 ||
        put(d, "direction", ch->direction == BP_DIRECTION_DEFAULT ? (Py_INCREF(Py_None), Py_None)
                                                                  : PyUnicode_FromString(direction_name(ch->direction))) < 0 ||
        put(d, "pins", PyLong_FromUnsignedLong(ch->num_pins)) < 0 ||
        put(d, "in_place", PyLong_FromLong(ch->in_place)) < 0 ||
        put(d, "seconds", number_or_none(ch->seconds)) < 0)
        goto fail;
    if (ch->uv) {
        if (put(d, "flipped", PyLong_FromUnsignedLong(x->rep.flipped)) < 0 ||
            put(d, "degenerate", PyLong_FromUnsignedLong(x->rep.degenerate)) < 0 ||
            put(d, "boundary_intersections", PyLong_FromUnsignedLong(x->rep.boundary_intersections)) < 0)
            goto fail;
    } else {
        if (PyDict_SetItemString(d, "flipped", Py_None) < 0 || PyDict_SetItemString(d, "degenerate", Py_None) < 0 ||
            PyDict_SetItemString(d, "boundary_intersections", Py_None) < 0)
            goto fail;
    }
    return d;
fail:
    Py_DECREF(d);
    return NULL;
}

static double peak_rss_bytes(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return (double)ru.ru_maxrss * 1024.0;
}

/* The stages' seconds as the tool's "timings" (or, on the CPU clock,
   "cpu_timings"): "cut" is bp_atlas_build (its charts stage), "segment"
   what follows until the first chart starts, "charts" their sum; one
   chart's solve is split into its start map and its optimization, charts
   solved together all count as "optimize"; "pack" runs from the last
   report of the solve (the outline packer of atlas_resolution reports no
   stage of its own) to the library's return.  "read" and "write" are
   filled by read_mesh and write; "total" (wall only) is the library
   call. */
static PyObject *timings_dict(const stamps *s, uint32_t num_charts, int total)
{
    const double *f = s->first, *l = s->last;
    double t_solve = f[BP_STAGE_START] ? f[BP_STAGE_START] : f[BP_STAGE_OPTIMIZE];
    double t_pack = f[BP_STAGE_PACK] ? f[BP_STAGE_PACK]
                  : l[BP_STAGE_OPTIMIZE] > l[BP_STAGE_START] ? l[BP_STAGE_OPTIMIZE]
                  : l[BP_STAGE_START] ? l[BP_STAGE_START] : s->solved;
    double cut = 0, segment = 0, init = 0, optimize = 0;
    if (f[BP_STAGE_CHARTS]) {
        cut = l[BP_STAGE_CHARTS] - f[BP_STAGE_CHARTS];
        segment = (t_solve ? t_solve : t_pack) - l[BP_STAGE_CHARTS];
    }
    if (t_solve) {
        if (num_charts == 1 && l[BP_STAGE_START] > 0) {     /* its start's last report */
            init = l[BP_STAGE_START] - t_solve;
            optimize = t_pack - l[BP_STAGE_START];
        } else optimize = t_pack - t_solve;
    }
    if (total)
        return Py_BuildValue("{s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d}", "read", 0.0, "charts", cut + segment,
                             "cut", cut, "segment", segment, "init", init, "optimize", optimize,
                             "pack", s->solved - t_pack, "write", 0.0, "total", s->solved - s->begin);
    return Py_BuildValue("{s:d,s:d,s:d,s:d,s:d,s:d,s:d,s:d}", "read", 0.0, "charts", cut + segment,
                         "cut", cut, "segment", segment, "init", init, "optimize", optimize,
                         "pack", s->solved - t_pack, "write", 0.0);
}

/* The tool's --json as a dict: the same keys in the same order, "input",
   "format" and "output" left to the Python layer, plus "timings"."total"
   (the call's wall time). */
static PyObject *report_dict(const job *J)
{
    const bp_atlas *at = J->atlas;
    const bp_options *opt = &J->opt;
    PyObject *d = PyDict_New(), *charts = NULL, *tm = NULL;
    int threads = 0;
    uint32_t c;
    if (!d) return NULL;
    if (put(d, "input", (Py_INCREF(Py_None), Py_None)) < 0 ||
        put(d, "format", (Py_INCREF(Py_None), Py_None)) < 0 ||
        put(d, "output", (Py_INCREF(Py_None), Py_None)) < 0 ||
        put(d, "status", PyUnicode_FromString(bp_status_string(J->st))) < 0)
        goto fail;
    if (J->st != BP_OK && J->st != BP_ERR_CHARTS_FAILED &&
        put(d, "error", PyUnicode_DecodeUTF8(J->err.message, (Py_ssize_t)strlen(J->err.message), "replace")) < 0)
        goto fail;
    if (put(d, "charts", PyLong_FromUnsignedLong(at->num_charts)) < 0 ||
        put(d, "failed_charts", PyLong_FromUnsignedLong(at->num_failed)) < 0 ||
        put(d, "split_vertices", PyLong_FromUnsignedLong(at->num_split)) < 0 ||
        put(d, "repairs", repairs_dict(&at->repairs)) < 0)
        goto fail;
    if (!(charts = PyList_New(at->num_charts))) goto fail;
    for (c = 0; c < at->num_charts; c++) {
        PyObject *cd = chart_dict(&at->charts[c], c, &J->extra[c]);
        if (!cd) goto fail;
        PyList_SET_ITEM(charts, c, cd);
        if (at->charts[c].threads > threads) threads = at->charts[c].threads;
    }
    if (put(d, "per_chart", charts) < 0) { charts = NULL; goto fail; }
    charts = NULL;
    if (!(tm = timings_dict(&J->wall, at->num_charts, 1))) goto fail;
    if (put(d, "timings", tm) < 0) { tm = NULL; goto fail; }
    tm = NULL;
    if (put(d, "cpu_timings", timings_dict(&J->cpu, at->num_charts, 0)) < 0) goto fail;
    if (put(d, "atlas_resolution", PyLong_FromLong(opt->atlas_resolution)) < 0 ||
        put(d, "padding", PyLong_FromLong(opt->atlas_resolution ? opt->padding : 0)) < 0 ||
        put(d, "utilization", number_or_none(at->utilization)) < 0 ||
        put(d, "threads", PyLong_FromLong(threads)) < 0 ||
        put(d, "peak_rss_bytes", PyFloat_FromDouble(peak_rss_bytes())) < 0 ||
        put(d, "bytes_per_face", PyFloat_FromDouble(J->mesh->num_triangles ? peak_rss_bytes() / J->mesh->num_triangles : 0)) < 0)
        goto fail;
    if (J->seams_ok &&
        put(d, "seams", Py_BuildValue("{s:d,s:N,s:N}", "edges", J->seams[0], "length", number_or_none(J->seams[1]),
                                      "relative", number_or_none(J->seams[2]))) < 0)
        goto fail;
    return d;
fail:
    Py_XDECREF(charts);
    Py_XDECREF(tm);
    Py_DECREF(d);
    return NULL;
}

static void capsule_free(PyObject *cap)
{
    free(PyCapsule_GetPointer(cap, NULL));
}

/* A numpy array over data (malloc'd; NULL gives None), owning it: the
   block is freed with the array (or here, on a failure). */
static PyObject *owned_array(void *data, int nd, npy_intp *dims, int type)
{
    PyObject *a, *cap;
    if (!data) Py_RETURN_NONE;
    if (!(cap = PyCapsule_New(data, NULL, capsule_free))) { free(data); return NULL; }
    if (!(a = PyArray_SimpleNewFromData(nd, dims, type, data))) { Py_DECREF(cap); return NULL; }
    if (PyArray_SetBaseObject((PyArrayObject *)a, cap) < 0) { Py_DECREF(a); return NULL; }
    return a;
}

/* ---- _parametrize -------------------------------------------------------------

   _parametrize(positions, indices, uv_indices, uvs, lines, faces, num_faces,
                options, importance, pins, views, float64, progress)
   Arrays exactly typed (see check_array); uv_indices, uvs, lines, faces,
   importance, pins, views may be None.  Returns
   ("ok" | "charts_failed", handle, vmapping, indices, uvs, failed_faces,
    report, check_status, check_message) or an error tuple. */

/* pins: (vertex uint32 (P,), uv side uint32 (P,), targets float64 (P,2)) */
static bp_pin *pins_from(PyObject *pins, uint32_t *count)
{
    Py_ssize_t n, k;
    const uint32_t *vx, *side;
    const double *tg;
    bp_pin *list;
    if (!PyTuple_Check(pins) || PyTuple_GET_SIZE(pins) != 3) {
        PyErr_SetString(PyExc_TypeError, "pins must be (vertices, uv_sides, targets)");
        return NULL;
    }
    if ((n = check_array(PyTuple_GET_ITEM(pins, 0), "pin vertices", NPY_UINT32, 1, 0)) < 0) return NULL;
    if (check_array(PyTuple_GET_ITEM(pins, 1), "pin uv sides", NPY_UINT32, 1, 0) != n ||
        check_array(PyTuple_GET_ITEM(pins, 2), "pin targets", NPY_DOUBLE, 2, 2) != n) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "pins: the three arrays differ in length");
        return NULL;
    }
    if (n > (Py_ssize_t)UINT32_MAX) { PyErr_SetString(PyExc_ValueError, "more than 2^32 - 1 pins"); return NULL; }
    vx = (const uint32_t *)PyArray_DATA((PyArrayObject *)PyTuple_GET_ITEM(pins, 0));
    side = (const uint32_t *)PyArray_DATA((PyArrayObject *)PyTuple_GET_ITEM(pins, 1));
    tg = (const double *)PyArray_DATA((PyArrayObject *)PyTuple_GET_ITEM(pins, 2));
    if (!(list = (bp_pin *)malloc(((size_t)n + 1) * sizeof *list))) { PyErr_NoMemory(); return NULL; }
    for (k = 0; k < n; k++) {
        list[k].vertex = vx[k];
        list[k].uv = side[k];
        list[k].u = tg[2 * k];
        list[k].v = tg[2 * k + 1];
    }
    *count = (uint32_t)n;
    return list;
}

/* An optional 1-D array with one entry per face, or None. */
static int per_face(PyObject *obj, const char *name, int type, Py_ssize_t nt)
{
    Py_ssize_t n;
    if (obj == Py_None) return 0;
    if ((n = check_array(obj, name, type, 1, 0)) < 0) return -1;
    if (n != nt) {
        PyErr_Format(PyExc_ValueError, "%s must have one entry per face (%zd), not %zd", name, nt, n);
        return -1;
    }
    return 0;
}

static PyObject *py_parametrize(PyObject *self, PyObject *args)
{
    PyObject *positions, *triangles, *corner_uv, *uvs, *lines, *faces, *options, *importance, *pins, *views,
             *progress;
    int f64 = 0;
    unsigned long num_faces = 0;
    Py_ssize_t nv, nt, nuv = 0;
    AtlasObject *handle = NULL;
    bp_pin *pin_list = NULL;
    double *imp = NULL, *view_list = NULL;
    size_t memory_limit = 0;
    job J;
    PyObject *report = NULL, *result = NULL;
    (void)self;
    memset(&J, 0, sizeof J);
    if (!PyArg_ParseTuple(args, "OOOOOOkOOOOpO", &positions, &triangles, &corner_uv, &uvs, &lines, &faces,
                          &num_faces, &options, &importance, &pins, &views, &f64, &progress))
        return NULL;
    if ((nv = check_array(positions, "positions", NPY_DOUBLE, 2, 3)) < 0) return NULL;
    if ((nt = check_array(triangles, "indices", NPY_UINT32, 2, 3)) < 0) return NULL;
    if (nv > (Py_ssize_t)UINT32_MAX || nt > (Py_ssize_t)UINT32_MAX || num_faces > UINT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "more than 2^32 - 1 vertices or faces");
        return NULL;
    }
    if (corner_uv != Py_None) {
        Py_ssize_t n = check_array(corner_uv, "uv_indices", NPY_UINT32, 2, 3);
        if (n < 0) return NULL;
        if (n != nt) { PyErr_SetString(PyExc_ValueError, "uv_indices must have one row per face"); return NULL; }
        if ((nuv = check_array(uvs, "uvs", NPY_DOUBLE, 2, 2)) < 0) return NULL;
        if (nuv > (Py_ssize_t)UINT32_MAX) { PyErr_SetString(PyExc_ValueError, "more than 2^32 - 1 uvs"); return NULL; }
    }
    if (per_face(lines, "lines", NPY_UINT32, nt) < 0 || per_face(faces, "faces", NPY_UINT32, nt) < 0 ||
        per_face(importance, "importance", NPY_DOUBLE, nt) < 0)
        return NULL;
    if (progress != Py_None && !PyCallable_Check(progress)) {
        PyErr_SetString(PyExc_TypeError, "progress must be callable");
        return NULL;
    }
    job_init(&J, JOB_PARAMETERIZE, 0, progress);
    if (options_from_dict(options, &J.opt, &memory_limit) < 0) return NULL;
    J.threads = J.opt.threads;
    J.f64 = f64;
    if (pins != Py_None && !(pin_list = pins_from(pins, &J.opt.num_pins))) return NULL;
    J.opt.pins = pin_list;
    if (views != Py_None) {
        Py_ssize_t nd = check_array(views, "views", NPY_DOUBLE, 2, 4);
        if (nd < 0 || nd > (Py_ssize_t)UINT32_MAX) {
            if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "more than 2^32 - 1 view directions");
            goto done;
        }
        if (!(view_list = (double *)copy_data(views))) goto done;
        J.opt.views.list = view_list;
        J.opt.views.list_count = (uint32_t)nd;
    }
    if (importance != Py_None) {
        if (!(imp = (double *)copy_data(importance))) goto done;
        J.opt.importance = imp;
    }
    /* the mesh, copied into the handle that keeps it for writing */
    if (!(handle = PyObject_New(AtlasObject, &AtlasType))) goto done;
    memset(&handle->mesh, 0, sizeof handle->mesh);
    memset(&handle->atlas, 0, sizeof handle->atlas);
    handle->has_atlas = 0;
    handle->writing = 0;
    handle->budget = NULL;
    if (memory_limit) {
        if (!(handle->budget = (budget *)calloc(1, sizeof *handle->budget))) { PyErr_NoMemory(); goto done; }
        handle->budget->limit = memory_limit;
        J.opt.allocator.alloc = budget_alloc;
        J.opt.allocator.free = budget_free;
        J.opt.allocator.user = handle->budget;
    }
    handle->mesh.num_vertices = (uint32_t)nv;
    handle->mesh.num_triangles = (uint32_t)nt;
    handle->mesh.num_faces = num_faces ? (uint32_t)num_faces : (uint32_t)nt;
    if (!(handle->mesh.positions = (double *)copy_data(positions)) ||
        !(handle->mesh.triangles = (uint32_t *)copy_data(triangles)))
        goto done;
    if (corner_uv != Py_None) {
        handle->mesh.num_uvs = (uint32_t)nuv;
        if (!(handle->mesh.corner_uv = (uint32_t *)copy_data(corner_uv)) ||
            !(handle->mesh.uvs = (double *)copy_data(uvs)))
            goto done;
    }
    if (lines != Py_None && !(handle->mesh.triangle_line = (uint32_t *)copy_data(lines))) goto done;
    if (faces != Py_None && !(handle->mesh.triangle_face = (uint32_t *)copy_data(faces))) goto done;
    J.mesh = &handle->mesh;
    J.atlas = &handle->atlas;
    if (job_run(&J, progress) < 0) {           /* a Python exception: the atlas goes */
        bp_atlas_free(&handle->atlas);
        goto done;
    }
    if (J.st != BP_OK && J.st != BP_ERR_CHARTS_FAILED) {
        bp_atlas_free(&handle->atlas);
        result = error_tuple(J.st, &J.err);
        goto done;
    }
    handle->has_atlas = 1;
    if (J.oom == 2) {
        PyErr_SetString(PyExc_ValueError, "the atlas has more than 2^32 - 1 vertices, beyond uint32 indices");
        goto done;
    }
    if (J.oom) { PyErr_NoMemory(); goto done; }
    if (!(report = report_dict(&J))) goto done;
    {
        npy_intp dims[2];
        PyObject *vm, *ix, *uv, *ff;
        dims[0] = (npy_intp)J.num_out;
        vm = owned_array(J.vmapping, 1, dims, NPY_UINT32); J.vmapping = NULL;
        dims[1] = 2;
        uv = owned_array(J.uvs, 2, dims, f64 ? NPY_DOUBLE : NPY_FLOAT32); J.uvs = NULL;
        dims[0] = nt; dims[1] = 3;
        ix = owned_array(J.indices, 2, dims, NPY_UINT32); J.indices = NULL;
        ff = owned_array(J.failed_faces, 1, dims, NPY_BOOL); J.failed_faces = NULL;
        if (vm && ix && uv && ff)
            result = Py_BuildValue("(sOOOOOOsN)", J.st == BP_OK ? "ok" : "charts_failed", (PyObject *)handle,
                                   vm, ix, uv, ff, report, status_name(J.round_st),
                                   J.round_st == BP_OK ? (Py_INCREF(Py_None), Py_None)
                                       : PyUnicode_DecodeUTF8(J.round_err.message, (Py_ssize_t)strlen(J.round_err.message), "replace"));
        Py_XDECREF(vm); Py_XDECREF(ix); Py_XDECREF(uv); Py_XDECREF(ff);
    }
done:
    free_outputs(&J);
    Py_XDECREF(report);
    Py_XDECREF((PyObject *)handle);
    free(pin_list);
    free(view_list);
    free(imp);
    return result;
}

/* ---- write ----------------------------------------------------------------------

   handle.write(path, source, threads, progress): bp_write_obj_opt into
   `path` (the Python layer made it, next to the target, and renames it);
   `source` the OBJ file the mesh was read from, or None.  Returns
   ("ok", seconds) or an error tuple. */
static PyObject *Atlas_write(PyObject *obj, PyObject *args)
{
    AtlasObject *self = (AtlasObject *)obj;
    PyObject *path = NULL, *source = NULL, *progress;
    int threads, rc;
    job J;
    PyObject *result = NULL;
    if (!PyArg_ParseTuple(args, "O&O&iO", PyUnicode_FSConverter, &path, PyUnicode_FSConverter, &source,
                          &threads, &progress))
        goto done;
    if (!self->has_atlas) {
        PyErr_SetString(PyExc_ValueError, "this result's atlas was released: nothing to write");
        goto done;
    }
    if (threads < 0 || threads > 256) { PyErr_SetString(PyExc_ValueError, "threads must be in [0, 256]"); goto done; }
    if (progress != Py_None && !PyCallable_Check(progress)) {
        PyErr_SetString(PyExc_TypeError, "progress must be callable");
        goto done;
    }
    job_init(&J, JOB_WRITE, threads, progress);
    J.mesh = &self->mesh;
    J.atlas = &self->atlas;
    J.path = PyBytes_AS_STRING(path);
    J.source = PyBytes_GET_SIZE(source) ? PyBytes_AS_STRING(source) : NULL;
    self->writing++;
    rc = job_run(&J, progress);
    self->writing--;
    if (rc < 0) goto done;
    result = J.st == BP_OK ? Py_BuildValue("(sdd)", "ok", J.t_end - J.t_begin, J.cpu_end - J.cpu.begin)
                           : error_tuple(J.st, &J.err);
done:
    Py_XDECREF(path);
    Py_XDECREF(source);
    return result;
}

/* ---- _read_mesh -------------------------------------------------------------------

   _read_mesh(path, threads, progress) -> ("ok", dict) | error tuple.  The
   arrays the reader allocated become the numpy arrays (no copy): each owns
   its block through a capsule that frees it. */

static PyObject *py_read_mesh(PyObject *self, PyObject *args)
{
    PyObject *path = NULL, *progress, *d = NULL, *result = NULL;
    int threads;
    bp_mesh m;
    job J;
    npy_intp dims[2];
    (void)self;
    if (!PyArg_ParseTuple(args, "O&iO", PyUnicode_FSConverter, &path, &threads, &progress)) goto done;
    if (threads < 0 || threads > 256) { PyErr_SetString(PyExc_ValueError, "threads must be in [0, 256]"); goto done; }
    if (progress != Py_None && !PyCallable_Check(progress)) {
        PyErr_SetString(PyExc_TypeError, "progress must be callable");
        goto done;
    }
    memset(&m, 0, sizeof m);
    job_init(&J, JOB_READ, threads, progress);
    J.mesh = &m;
    J.path = PyBytes_AS_STRING(path);
    if (job_run(&J, progress) < 0) { bp_mesh_free(&m, NULL); goto done; }
    if (J.st != BP_OK) { result = error_tuple(J.st, &J.err); goto done; }
    if (!(d = PyDict_New())) { bp_mesh_free(&m, NULL); goto done; }
    /* each block handed to its array (or freed here on a failure) */
    {
        PyObject *a;
        int ok = 1;
        dims[0] = m.num_vertices; dims[1] = 3;
        a = owned_array(m.positions, 2, dims, NPY_DOUBLE); m.positions = NULL;
        ok = ok && put(d, "positions", a) == 0;
        dims[0] = m.num_triangles; dims[1] = 3;
        a = owned_array(m.triangles, 2, dims, NPY_UINT32); m.triangles = NULL;
        ok = ok && put(d, "indices", a) == 0;
        a = owned_array(m.corner_uv, 2, dims, NPY_UINT32); m.corner_uv = NULL;
        ok = ok && put(d, "uv_indices", a) == 0;
        dims[0] = m.num_uvs; dims[1] = 2;
        a = owned_array(m.uvs, 2, dims, NPY_DOUBLE); m.uvs = NULL;
        ok = ok && put(d, "uvs", a) == 0;
        dims[0] = m.num_triangles;
        a = owned_array(m.triangle_line, 1, dims, NPY_UINT32); m.triangle_line = NULL;
        ok = ok && put(d, "lines", a) == 0;
        a = owned_array(m.triangle_face, 1, dims, NPY_UINT32); m.triangle_face = NULL;
        ok = ok && put(d, "faces", a) == 0;
        ok = ok && put(d, "num_faces", PyLong_FromUnsignedLong(m.num_faces)) == 0;
        ok = ok && put(d, "seconds", PyFloat_FromDouble(J.t_end - J.t_begin)) == 0;
        ok = ok && put(d, "cpu_seconds", PyFloat_FromDouble(J.cpu_end - J.cpu.begin)) == 0;
        bp_mesh_free(&m, NULL);               /* whatever was not handed over */
        if (!ok) goto done;
    }
    result = Py_BuildValue("(sO)", "ok", d);
done:
    Py_XDECREF(d);
    Py_XDECREF(path);
    return result;
}

/* ---- _check -------------------------------------------------------------------------

   The exact check of a map given as arrays, as the tool's --check decides a
   file's own vt: the charts are the mesh's pieces cut where the uv indices
   differ (bp_atlas_build, which also repairs what it repairs for the
   solver), each chart's coordinates are its uv, and bp_check decides every
   chart, then all of them together (two charts overlapping).  Elements are
   named in the caller's 0-based array indices.

   _check(positions, indices, uv_indices, uvs, threads) ->
       ("ok", dict) | error tuple (a mesh the charts cannot be built on) */

typedef struct check_job {
    bp_atlas atlas;
    bp_status st;             /* the first verdict that is not BP_OK         */
    bp_error err;
    bp_check_report rep;
    uint32_t bad_charts;
    int overlap;
    int64_t chart;            /* the chart of the first bad verdict, -1: all */
    uint32_t *first;          /* all charts: first global vertex of each     */
    uint32_t *tri;            /* all charts: triangles                       */
    double *uv;               /* all charts: coordinates                     */
    uint32_t num_tri, num_v;
    int oom;
} check_job;

static void run_check_job(job *J)
{
    check_job *K = J->check;
    bp_mesh *m = J->mesh;
    uint32_t c, i;
    uint64_t nt = 0, nv = 0;
    K->chart = -1;
    J->opt.cut = BP_CUT_NONE;          /* a closed chart is reported, not cut */
    J->st = bp_atlas_build(&K->atlas, m, &J->opt, &J->err);
    if (J->st == BP_ERR_CHARTS_FAILED) J->st = BP_OK;
    if (J->st != BP_OK) return;
    for (c = 0; c < K->atlas.num_charts; c++) { nt += K->atlas.charts[c].num_triangles; nv += K->atlas.charts[c].num_vertices; }
    K->first = (uint32_t *)calloc((size_t)K->atlas.num_charts + 1, sizeof *K->first);
    K->tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *K->tri + 1);
    K->uv = (double *)malloc(2 * (size_t)nv * sizeof *K->uv + 1);
    if (!K->first || !K->tri || !K->uv || nv > UINT32_MAX || nt > UINT32_MAX) { K->oom = 1; return; }
    nt = nv = 0;
    for (c = 0; c < K->atlas.num_charts; c++) {
        const bp_chart *ch = &K->atlas.charts[c];
        double *uv = K->uv + 2 * (size_t)nv;
        bp_check_report r;
        bp_error e;
        bp_status s;
        K->first[c] = (uint32_t)nv;
        for (i = 0; i < ch->num_vertices; i++) {
            uv[2 * i] = m->uvs[2 * (size_t)ch->vertex_uv[i]];
            uv[2 * i + 1] = m->uvs[2 * (size_t)ch->vertex_uv[i] + 1];
        }
        for (i = 0; i < 3 * ch->num_triangles; i++) K->tri[3 * (size_t)nt + i] = ch->triangles[i] + (uint32_t)nv;
        nt += ch->num_triangles;
        nv += ch->num_vertices;
        if (ch->error.status != BP_OK) {       /* closed or higher-genus chart */
            if (!K->bad_charts++) { K->st = ch->error.status; K->err = ch->error; K->chart = c; }
            continue;
        }
        memset(&r, 0, sizeof r);
        s = bp_check_opt(ch->triangles, ch->num_triangles, uv, ch->num_vertices, &J->opt, &r, &e);
        if (s != BP_OK) {
            if (s == BP_ERR_OUT_OF_MEMORY) { K->oom = 1; return; }
            if (!K->bad_charts++) { K->st = s; K->err = e; K->rep = r; K->chart = c; }
        }
    }
    K->first[K->atlas.num_charts] = (uint32_t)nv;
    K->num_tri = (uint32_t)nt;
    K->num_v = (uint32_t)nv;
    if (!K->bad_charts && K->atlas.num_charts > 1) {
        bp_check_report r;
        bp_error e;
        bp_status s;
        memset(&r, 0, sizeof r);
        s = bp_check_opt(K->tri, K->num_tri, K->uv, K->num_v, &J->opt, &r, &e);
        if (s == BP_ERR_OUT_OF_MEMORY) { K->oom = 1; return; }
        if (s != BP_OK) { K->overlap = 1; K->st = s; K->err = e; K->rep = r; K->chart = -1; }
    }
}

/* global vertex of the all-charts check -> chart and its local vertex */
static uint32_t chart_of_vertex(const check_job *K, int64_t g, uint32_t *local)
{
    uint32_t lo = 0, hi = K->atlas.num_charts - 1;
    while (lo < hi) {                      /* the last chart whose first <= g */
        uint32_t mid = lo + (hi - lo + 1) / 2;
        if (K->first[mid] <= (uint64_t)g) lo = mid; else hi = mid - 1;
    }
    *local = (uint32_t)(g - K->first[lo]);
    return lo;
}

static void name_vertex(const check_job *K, uint32_t c, uint32_t i, char *out, size_t cap)
{
    const bp_chart *ch = &K->atlas.charts[c];
    snprintf(out, cap, "vertex %lu (uv %lu)", (unsigned long)ch->vertex[i], (unsigned long)ch->vertex_uv[i]);
}

/* One sentence naming what the check found first, in the caller's 0-based
   array indices (faces are rows of `indices`, vertices rows of `positions`,
   uvs rows of `uvs`). */
static void check_message(const check_job *K, const bp_mesh *m, char *msg, size_t cap)
{
    const bp_error *e = &K->err;
    char a[96], b[96], d[96];
    uint32_t ca, cb, la, lb;
    const char *where = K->overlap ? "all charts together: " : "";
    if (K->chart >= 0 && K->atlas.charts[K->chart].error.status != BP_OK) {
        snprintf(msg, cap, "chart %lld cannot be flattened: %s", (long long)K->chart, e->message);
        return;
    }
    if (e->element == BP_ELEMENT_TRIANGLE && e->index >= 0) {
        uint32_t c = K->chart >= 0 ? (uint32_t)K->chart : 0, t = (uint32_t)e->index, f;
        const uint32_t *tr, *uvi;
        const double *uv;
        const char *what;
        if (K->chart < 0)                      /* global triangle -> chart, local */
            while (c + 1 < K->atlas.num_charts && t >= K->atlas.charts[c].num_triangles) t -= K->atlas.charts[c++].num_triangles;
        f = K->atlas.charts[c].face[t];
        tr = m->triangles + 3 * (size_t)f;
        uvi = m->corner_uv + 3 * (size_t)f;
        {
            const bp_chart *ch = &K->atlas.charts[c];
            const uint32_t *ct = ch->triangles + 3 * (size_t)t;
            double p[3][2];
            int k;
            for (k = 0; k < 3; k++) {
                uv = m->uvs + 2 * (size_t)ch->vertex_uv[ct[k]];
                p[k][0] = uv[0]; p[k][1] = uv[1];
            }
            what = K->rep.nonfinite ? "has a NaN or infinite uv coordinate"
                 : bp_orient2d(p[0], p[1], p[2]) < 0 ? "is flipped (negative area in UV)" : "has zero area in UV";
        }
        snprintf(msg, cap, "%sface %lu (vertices %lu %lu %lu, uvs %lu %lu %lu) %s", where, (unsigned long)f,
                 (unsigned long)tr[0], (unsigned long)tr[1], (unsigned long)tr[2],
                 (unsigned long)uvi[0], (unsigned long)uvi[1], (unsigned long)uvi[2], what);
        return;
    }
    if (e->index < 0) { snprintf(msg, cap, "%s%s", where, e->message); return; }
    ca = cb = K->chart >= 0 ? (uint32_t)K->chart : 0;
    la = (uint32_t)e->index;
    lb = (uint32_t)(e->index2 >= 0 ? e->index2 : 0);
    if (K->chart < 0) { ca = chart_of_vertex(K, e->index, &la); if (e->index2 >= 0) cb = chart_of_vertex(K, e->index2, &lb); }
    name_vertex(K, ca, la, a, sizeof a);
    if (e->index2 >= 0) name_vertex(K, cb, lb, b, sizeof b);
    if (e->status == BP_ERR_NONMANIFOLD || e->status == BP_ERR_ORIENTATION)
        snprintf(msg, cap, "%sthe edge %s - %s is used by more than two faces or twice in one direction", where, a, b);
    else if (K->rep.boundary_intersections && K->rep.first_bad_edge[1] >= 0) {
        uint32_t cc = ca, lc = (uint32_t)K->rep.first_bad_edge[1];
        if (K->chart < 0) cc = chart_of_vertex(K, K->rep.first_bad_edge[1], &lc);
        name_vertex(K, cc, lc, d, sizeof d);
        snprintf(msg, cap, "%sboundary edges meet: the edge %s - %s and the edge from %s%s", where, a,
                 e->index2 >= 0 ? b : "?", d, K->chart < 0 && ca != cc ? " (another chart)" : "");
    } else if (K->rep.nested)
        snprintf(msg, cap, "%sthe piece with %s lies on the piece with %s", where, a, e->index2 >= 0 ? b : "?");
    else
        snprintf(msg, cap, "%sat %s: the boundary is pinched, or the piece is mirrored or wraps around twice", where, a);
}

static PyObject *check_report_dict(const bp_check_report *r)
{
    return Py_BuildValue("{s:k,s:k,s:k,s:k,s:k,s:k,s:k,s:k}", "flipped", (unsigned long)r->flipped,
                         "degenerate", (unsigned long)r->degenerate, "nonfinite", (unsigned long)r->nonfinite,
                         "boundary_intersections", (unsigned long)r->boundary_intersections,
                         "loop_orientation", (unsigned long)r->loop_orientation, "nested", (unsigned long)r->nested,
                         "nonmanifold_edges", (unsigned long)r->nonmanifold_edges,
                         "misoriented_edges", (unsigned long)r->misoriented_edges);
}

static PyObject *py_check(PyObject *self, PyObject *args)
{
    PyObject *positions, *triangles, *corner_uv, *uvs, *result = NULL;
    int threads;
    Py_ssize_t nv, nt, nuv;
    bp_mesh m;
    check_job K;
    job J;
    char msg[600];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOi", &positions, &triangles, &corner_uv, &uvs, &threads)) return NULL;
    if ((nv = check_array(positions, "positions", NPY_DOUBLE, 2, 3)) < 0 ||
        (nt = check_array(triangles, "indices", NPY_UINT32, 2, 3)) < 0 ||
        (nuv = check_array(uvs, "uvs", NPY_DOUBLE, 2, 2)) < 0)
        return NULL;
    if (check_array(corner_uv, "uv_indices", NPY_UINT32, 2, 3) != nt) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "uv_indices must have one row per face");
        return NULL;
    }
    if (nv > (Py_ssize_t)UINT32_MAX || nt > (Py_ssize_t)UINT32_MAX || nuv > (Py_ssize_t)UINT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "more than 2^32 - 1 vertices, faces or uvs");
        return NULL;
    }
    if (threads < 0 || threads > 256) { PyErr_SetString(PyExc_ValueError, "threads must be in [0, 256]"); return NULL; }
    memset(&m, 0, sizeof m);
    memset(&K, 0, sizeof K);
    m.num_vertices = (uint32_t)nv;
    m.num_triangles = (uint32_t)nt;
    m.num_faces = (uint32_t)nt;
    m.num_uvs = (uint32_t)nuv;
    if (!(m.positions = (double *)copy_data(positions)) || !(m.triangles = (uint32_t *)copy_data(triangles)) ||
        !(m.corner_uv = (uint32_t *)copy_data(corner_uv)) || !(m.uvs = (double *)copy_data(uvs)))
        goto done;
    job_init(&J, JOB_CHECK, threads, Py_None);
    J.mesh = &m;
    J.check = &K;
    if (job_run(&J, Py_None) < 0) goto done;
    if (K.oom) { PyErr_NoMemory(); goto done; }
    if (J.st != BP_OK) { result = error_tuple(J.st, &J.err); goto done; }
    msg[0] = 0;
    if (K.st != BP_OK) check_message(&K, &m, msg, sizeof msg);
    result = Py_BuildValue("(s{s:O,s:k,s:k,s:O,s:s,s:N,s:N,s:L})", "ok",
                           "bijective", K.st == BP_OK ? Py_True : Py_False,
                           "charts", (unsigned long)K.atlas.num_charts, "bad_charts", (unsigned long)K.bad_charts,
                           "overlap", K.overlap ? Py_True : Py_False,
                           "status", status_name(K.st), "message", message_str(msg),
                           "counts", check_report_dict(&K.rep), "chart", (long long)K.chart);
done:
    bp_atlas_free(&K.atlas);
    free(K.first); free(K.tri); free(K.uv);
    mesh_free_owned(&m);
    return result;
}

/* ---- glTF (examples/bp_gltf.h) ---------------------------------------------------

   A .gltf or .glb is read by bpg_read into a GltfFile, which keeps what the
   writer needs; its mesh's arrays are handed to Python as read-only views
   that keep the GltfFile alive.  A result of that mesh is written back by
   bpg_encode (every vertex attribute, node, material and byte of the file
   kept, the new TEXCOORD_n added, the float map checked exactly and
   repaired by a few floats where rounding broke it); the Python layer
   writes the bytes it returns, whole or not at all. */

typedef struct {
    PyObject_HEAD
    bpg_file file;
    int encoding;              /* bpg_encode reports through the file's state:
                                  one at a time */
} GltfObject;

static void Gltf_dealloc(GltfObject *self)
{
    bpg_free(&self->file);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* name(kind, index): "mesh 1 ('Body') primitive 0 triangle 17 (vertices 4 5
   9)" for kind "triangle", "accessor 3 vertex 12 (...)" for "vertex": the
   element as the file numbers it ("" out of range). */
static PyObject *Gltf_name(PyObject *obj, PyObject *args)
{
    GltfObject *self = (GltfObject *)obj;
    const char *kind;
    long long index;
    char buf[512] = "";
    if (!PyArg_ParseTuple(args, "sL", &kind, &index)) return NULL;
    if (index >= 0 && index <= (long long)UINT32_MAX) {
        if (!strcmp(kind, "triangle")) bpg_name_triangle(&self->file, (uint32_t)index, buf, sizeof buf);
        else if (!strcmp(kind, "vertex")) bpg_name_vertex(&self->file, (uint32_t)index, buf, sizeof buf);
    }
    return PyUnicode_DecodeUTF8(buf, (Py_ssize_t)strlen(buf), "replace");
}

/* external_files(): the files the input reads (buffers, images) */
static PyObject *Gltf_external_files(PyObject *obj, PyObject *noargs)
{
    GltfObject *self = (GltfObject *)obj;
    PyObject *list = PyList_New(0);
    const char *x;
    uint32_t i;
    (void)noargs;
    if (!list) return NULL;
    for (i = 0; (x = bpg_external_file(&self->file, i)) != NULL; i++) {
        PyObject *p = PyUnicode_DecodeFSDefault(x);
        if (!p || PyList_Append(list, p) < 0) { Py_XDECREF(p); Py_DECREF(list); return NULL; }
        Py_DECREF(p);
    }
    return list;
}

static PyMethodDef Gltf_methods[] = {
    {"name", Gltf_name, METH_VARARGS, "name(kind, index): a mesh triangle or vertex as the file numbers it"},
    {"external_files", Gltf_external_files, METH_NOARGS, "the files the input reads"},
    {NULL, NULL, 0, NULL}
};

static PyTypeObject GltfType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "bijparam._native.GltfFile",
    .tp_basicsize = sizeof(GltfObject),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "a glTF file read by examples/bp_gltf.h, kept for writing it back",
    .tp_dealloc = (destructor)Gltf_dealloc,
    .tp_methods = Gltf_methods,
};

/* A read-only numpy view of memory the GltfFile owns (None for NULL). */
static PyObject *gltf_view(GltfObject *owner, void *data, int nd, npy_intp *dims, int type)
{
    PyObject *a;
    if (!data) Py_RETURN_NONE;
    if (!(a = PyArray_New(&PyArray_Type, nd, dims, type, NULL, data, 0, NPY_ARRAY_CARRAY_RO, NULL))) return NULL;
    Py_INCREF(owner);
    if (PyArray_SetBaseObject((PyArrayObject *)a, (PyObject *)owner) < 0) { Py_DECREF(a); return NULL; }
    return a;
}

/* _read_gltf(path, texcoord) -> ("ok", GltfFile, dict) | error tuple */
static PyObject *py_read_gltf(PyObject *self, PyObject *args)
{
    PyObject *path = NULL, *d = NULL, *result = NULL;
    GltfObject *g = NULL;
    int texcoord;
    job J;
    npy_intp dims[2];
    (void)self;
    if (!PyArg_ParseTuple(args, "O&i", PyUnicode_FSConverter, &path, &texcoord)) goto done;
    if (texcoord < 0) { PyErr_SetString(PyExc_ValueError, "texcoord must be 0 or more"); goto done; }
    if (!(g = PyObject_New(GltfObject, &GltfType))) goto done;
    memset(&g->file, 0, sizeof g->file);
    g->encoding = 0;
    job_init(&J, JOB_GLTF_READ, 1, Py_None);
    J.gltf = &g->file;
    J.gltf_read.texcoord = texcoord;
    J.path = PyBytes_AS_STRING(path);
    if (job_run(&J, Py_None) < 0) goto done;
    if (J.st != BP_OK) { result = error_tuple(J.st, &J.err); goto done; }
    {
        bp_mesh *m = &g->file.mesh;
        int ok = (d = PyDict_New()) != NULL;
        dims[0] = m->num_vertices; dims[1] = 3;
        ok = ok && put(d, "positions", gltf_view(g, m->positions, 2, dims, NPY_DOUBLE)) == 0;
        dims[0] = m->num_triangles;
        ok = ok && put(d, "indices", gltf_view(g, m->triangles, 2, dims, NPY_UINT32)) == 0;
        ok = ok && put(d, "uv_indices", gltf_view(g, m->corner_uv, 2, dims, NPY_UINT32)) == 0;
        ok = ok && put(d, "faces", gltf_view(g, m->triangle_face, 1, dims, NPY_UINT32)) == 0;
        dims[0] = m->num_uvs; dims[1] = 2;
        ok = ok && put(d, "uvs", gltf_view(g, m->uvs, 2, dims, NPY_DOUBLE)) == 0;
        ok = ok && put(d, "num_faces", PyLong_FromUnsignedLong(m->num_faces)) == 0;
        ok = ok && put(d, "has_uv", PyBool_FromLong(g->file.has_uv)) == 0;
        ok = ok && put(d, "glb", PyBool_FromLong(g->file.glb)) == 0;
        ok = ok && put(d, "meshes", PyLong_FromUnsignedLong(g->file.num_meshes)) == 0;
        ok = ok && put(d, "primitives", PyLong_FromUnsignedLong(g->file.num_primitives)) == 0;
        ok = ok && put(d, "buffer_files", PyLong_FromUnsignedLong(g->file.num_buffer_files)) == 0;
        ok = ok && put(d, "seconds", PyFloat_FromDouble(J.t_end - J.t_begin)) == 0;
        ok = ok && put(d, "cpu_seconds", PyFloat_FromDouble(J.cpu_end - J.cpu.begin)) == 0;
        if (!ok) goto done;
    }
    result = Py_BuildValue("(sOO)", "ok", (PyObject *)g, d);
done:
    Py_XDECREF(d);
    Py_XDECREF((PyObject *)g);
    Py_XDECREF(path);
    return result;
}

/* _encode_gltf(gltf, atlas, glb, bin_uri, uri_prefix, threads) ->
   ("ok", data, bin | None, vertices_in, vertices_out, rounding_fixed,
    seconds, cpu_seconds, (accessors_removed, views_removed, bytes_removed))
   | error tuple.  The atlas must be the result of
   this file's mesh (the Python layer keeps them together). */
static PyObject *py_encode_gltf(PyObject *self, PyObject *args)
{
    PyObject *gobj, *aobj, *bin_uri, *prefix, *result = NULL;
    GltfObject *g;
    AtlasObject *at;
    int glb, threads, rc;
    job J;
    (void)self;
    if (!PyArg_ParseTuple(args, "O!O!pOOi", &GltfType, &gobj, &AtlasType, &aobj, &glb, &bin_uri, &prefix, &threads))
        return NULL;
    g = (GltfObject *)gobj;
    at = (AtlasObject *)aobj;
    if ((bin_uri != Py_None && !PyUnicode_Check(bin_uri)) || (prefix != Py_None && !PyUnicode_Check(prefix))) {
        PyErr_SetString(PyExc_TypeError, "bin_uri and uri_prefix must be str or None");
        return NULL;
    }
    if (threads < 0 || threads > 256) { PyErr_SetString(PyExc_ValueError, "threads must be in [0, 256]"); return NULL; }
    if (!at->has_atlas) { PyErr_SetString(PyExc_ValueError, "this result's atlas was released: nothing to write"); return NULL; }
    if (at->atlas.num_corners != 3 * (uint64_t)g->file.mesh.num_triangles) {
        PyErr_SetString(PyExc_ValueError, "the result is not of this glTF file's mesh");
        return NULL;
    }
    if (g->encoding) { PyErr_SetString(PyExc_RuntimeError, "this glTF file is being written by another thread"); return NULL; }
    job_init(&J, JOB_GLTF_ENCODE, threads, Py_None);
    J.gltf = &g->file;
    J.atlas = &at->atlas;
    J.gltf_write.glb = glb;
    J.gltf_write.bin_uri = bin_uri == Py_None ? NULL : PyUnicode_AsUTF8(bin_uri);
    J.gltf_write.uri_prefix = prefix == Py_None ? NULL : PyUnicode_AsUTF8(prefix);
    if ((bin_uri != Py_None && !J.gltf_write.bin_uri) || (prefix != Py_None && !J.gltf_write.uri_prefix)) return NULL;
    g->encoding = 1;
    at->writing++;
    rc = job_run(&J, Py_None);
    at->writing--;
    g->encoding = 0;
    if (rc < 0) { bpg_output_free(&J.gltf_out); return NULL; }
    if (J.st != BP_OK) return error_tuple(J.st, &J.err);
    result = Py_BuildValue("(sy#Okkkdd(kkK))", "ok", (const char *)J.gltf_out.data, (Py_ssize_t)J.gltf_out.size, Py_None,
                           (unsigned long)J.gltf_out.vertices_in, (unsigned long)J.gltf_out.vertices_out,
                           (unsigned long)J.gltf_out.rounding_fixed, J.t_end - J.t_begin, J.cpu_end - J.cpu.begin,
                           (unsigned long)J.gltf_out.accessors_removed, (unsigned long)J.gltf_out.views_removed,
                           (unsigned long long)J.gltf_out.bytes_removed);
    if (result && J.gltf_out.bin) {
        PyObject *b = PyBytes_FromStringAndSize((const char *)J.gltf_out.bin, (Py_ssize_t)J.gltf_out.bin_size);
        if (!b) Py_CLEAR(result);
        else PyTuple_SetItem(result, 2, b);
    }
    bpg_output_free(&J.gltf_out);
    return result;
}

/* ---- the module ----------------------------------------------------------------------- */

static PyObject *py_status_strings(PyObject *self, PyObject *noargs)
{
    PyObject *d = PyDict_New();
    int s;
    (void)self; (void)noargs;
    if (!d) return NULL;
    for (s = 0; s < BP_STATUS_COUNT; s++)
        if (put(d, status_name((bp_status)s), PyUnicode_FromString(bp_status_string((bp_status)s))) < 0) {
            Py_DECREF(d);
            return NULL;
        }
    return d;
}

static PyMethodDef module_methods[] = {
    {"parametrize", py_parametrize, METH_VARARGS, "the library's bp_parameterize on exact arrays (see __init__.py)"},
    {"read_mesh", py_read_mesh, METH_VARARGS, "bp_read_mesh_opt(path) into arrays"},
    {"check", py_check, METH_VARARGS, "the exact check of a map given as arrays"},
    {"read_gltf", py_read_gltf, METH_VARARGS, "bpg_read(path) into a GltfFile and its mesh's arrays"},
    {"encode_gltf", py_encode_gltf, METH_VARARGS, "bpg_encode: a result written back into its glTF file's bytes"},
    {"status_strings", py_status_strings, METH_NOARGS, "status name -> bp_status_string"},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module_def = {
    PyModuleDef_HEAD_INIT, "bijparam._native", "bijparam.h compiled for Python", -1, module_methods,
    NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC PyInit__native(void)
{
    PyObject *m;
    import_array();
    if (PyType_Ready(&AtlasType) < 0 || PyType_Ready(&GltfType) < 0) return NULL;
    if (!(m = PyModule_Create(&module_def))) return NULL;
    Py_INCREF(&AtlasType);
    if (PyModule_AddObject(m, "Atlas", (PyObject *)&AtlasType) < 0 ||
        PyModule_AddStringConstant(m, "LIBRARY_VERSION", BP_VERSION_STRING) < 0) {
        Py_DECREF(&AtlasType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
