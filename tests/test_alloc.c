/* test_alloc.c - allocation failure everywhere in the pipeline.

   A test allocator (a bp_allocator whose user pointer is checked on every
   call) counts allocations and makes the k-th one fail.  For a call that
   makes N allocations when nothing fails, every k = 1..N is tried (and
   k = N+1, which must succeed):
     - the call returns BP_ERR_OUT_OF_MEMORY with a message, or BP_OK once
       k > N; never another status, never a crash; the one exception is
       the fallback of >>optimize: where the default direction chose
       Newton (bishop's chart) and the failure came after that choice,
       L-BFGS finishes the chart and the call returns BP_OK with a valid
       map and chart.direction PRECONDITIONED where the run without
       failures had NEWTON -- the bishop sweep must see that happen, the
       sweep with Newton asked for by name never;
     - after bp_atlas_free (harmless on the zeroed atlas a failure leaves)
       every allocation has been freed: allocator balance 0, no free of a
       pointer it did not hand out, no free(NULL) (the API promises never
       to call free with NULL);
     - a result that is returned is valid (bp_check).
   Calls covered: bp_parameterize on bishop_part_f1000.obj (20 iterations),
   on a generated 3D disk with two holes (20 iterations), on a good chart
   next to a closed one (BP_ERR_CHARTS_FAILED when nothing fails and the cut
   is off; BP_OK with the closed chart cut into a disk), with
   init_only and with normalize, with the projected Newton direction; bp_visibility on a small closed mesh;
   bp_write_obj (its table comes from the atlas's allocator); bp_check and
   bp_check_opt (the options' allocator); bp_pool_create (a pool of one
   thread here).
   The parsers' own allocation failures are covered by test_io.c.

   The library is built here without threads, so the allocation sequence is
   deterministic and N is the same on every run. */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

typedef struct counter {
    long calls, allocs, frees, wrong_user, bad_free, null_free;
    long long live_bytes;
    long fail_at;     /* 1-based allocation to fail; 0: never */
} counter;

static counter C;

static void *t_alloc(void *user, size_t size)
{
    size_t *p;
    if (user != (void *)&C) C.wrong_user++;
    C.calls++;
    if (C.fail_at && C.calls == C.fail_at) return NULL;
    p = (size_t *)malloc(size + 16);
    if (!p) return NULL;
    p[0] = size;
    p[1] = 0xa110ca7eu;
    C.allocs++;
    C.live_bytes += (long long)size;
    return (char *)p + 16;
}

static void t_free(void *user, void *ptr)
{
    size_t *p;
    if (user != (void *)&C) C.wrong_user++;
    if (!ptr) { C.null_free++; return; }
    p = (size_t *)((char *)ptr - 16);
    if (p[1] != 0xa110ca7eu) { C.bad_free++; return; }
    p[1] = 0;
    C.frees++;
    C.live_bytes -= (long long)p[0];
    free(p);
}

static bp_allocator test_allocator(void)
{
    bp_allocator a;
    a.alloc = t_alloc;
    a.free = t_free;
    a.user = &C;
    return a;
}

/* The test's cost in a unit that does not depend on the machine: library
   runs and allocation calls over the whole program (a sweep of a call
   with N allocations makes N + 1 runs and about N^2 / 2 calls). */
static long total_runs = 0;
static long long total_calls = 0;
#define BUDGET_CALLS 1000000LL     /* 156 762 when written (0.7 s of CPU) */

static void counter_reset(long fail_at)
{
    total_runs++;
    total_calls += C.calls;
    memset(&C, 0, sizeof C);
    C.fail_at = fail_at;
}

static int balanced(void)
{
    return C.allocs == C.frees && C.live_bytes == 0 && !C.wrong_user && !C.bad_free && !C.null_free;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int atlas_valid(const bp_atlas *at)
{
    uint32_t c;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        bp_check_report r;
        if (!ch->uv) continue;
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK) return 0;
        if (r.flipped || r.degenerate || r.nonfinite || r.boundary_intersections || r.loop_orientation || r.nested)
            return 0;
    }
    return 1;
}

/* ---- meshes (bpt_mesh_new in bptest.h) -------------------------------------- */

/* A curved nx x ny grid without the quads (2,2) and (nx-3, ny-3): a disk
   with two holes.  extra_tetra appends a tetrahedron (a closed chart). */
static bp_mesh holed_grid(int nx, int ny, int extra_tetra)
{
    uint32_t nt = 0, t = 0, nv = (uint32_t)((nx + 1) * (ny + 1));
    int i, j;
    bp_mesh m;
#define BP_HOLE(i, j) (((i) == 2 && (j) == 2) || ((i) == nx - 3 && (j) == ny - 3))
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            if (!BP_HOLE(i, j)) nt += 2;
    m = bpt_mesh_new(nv + (extra_tetra ? 4 : 0), nt + (extra_tetra ? 4 : 0));
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++) {
            double *p = m.positions + 3 * (size_t)(j * (nx + 1) + i);
            p[0] = i; p[1] = j; p[2] = 0.6 * sin(0.6 * i) * cos(0.4 * j);
        }
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            uint32_t a = (uint32_t)(j * (nx + 1) + i), b = a + 1, c = a + (uint32_t)nx + 2, d = a + (uint32_t)nx + 1;
            uint32_t *tr;
            if (BP_HOLE(i, j)) continue;
            tr = m.triangles + 3 * (size_t)t;
            tr[0] = a; tr[1] = b; tr[2] = c; tr[3] = a; tr[4] = c; tr[5] = d;
            t += 2;
        }
#undef BP_HOLE
    if (extra_tetra) {
        static const double P[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
        static const uint32_t T[4][3] = { { 0, 2, 1 }, { 0, 1, 3 }, { 0, 3, 2 }, { 1, 2, 3 } };
        for (i = 0; i < 4; i++) {
            m.positions[3 * (nv + i)] = P[i][0] + nx + 3;
            m.positions[3 * (nv + i) + 1] = P[i][1];
            m.positions[3 * (nv + i) + 2] = P[i][2];
            for (j = 0; j < 3; j++) m.triangles[3 * (t + i) + j] = nv + T[i][j];
        }
    }
    return m;
}

/* a followed by b (b's vertices renumbered, shifted by dx in x) */
static bp_mesh concat(const bp_mesh *a, const bp_mesh *b, double dx)
{
    bp_mesh m = bpt_mesh_new(a->num_vertices + b->num_vertices, a->num_triangles + b->num_triangles);
    uint32_t i;
    memcpy(m.positions, a->positions, 3 * a->num_vertices * sizeof(double));
    memcpy(m.triangles, a->triangles, 3 * a->num_triangles * sizeof(uint32_t));
    for (i = 0; i < b->num_vertices; i++) {
        m.positions[3 * (a->num_vertices + i)] = b->positions[3 * i] + dx;
        m.positions[3 * (a->num_vertices + i) + 1] = b->positions[3 * i + 1];
        m.positions[3 * (a->num_vertices + i) + 2] = b->positions[3 * i + 2];
    }
    for (i = 0; i < 3 * b->num_triangles; i++) m.triangles[3 * a->num_triangles + i] = b->triangles[i] + a->num_vertices;
    return m;
}

/* A user job system that runs the tasks in reverse order on the calling
   thread: bp_parameterize then solves the charts as parallel tasks (when
   no chart holds more than half of the triangles). */
static void reverse_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    (void)user;
    while (count--) fn(task, count);
}

/* ---- the sweep ----------------------------------------------------------------- */

typedef bp_status (*call_fn)(void *ctx, const bp_allocator *a, int *result_valid);

/* Run `call` with no failure to count N, then with the k-th allocation
   failing for every k in 1..N+1.  `ok_status` is what the call returns
   when nothing fails. */
static long last_fallbacks;     /* runs of the last sweep that fell back (valid == 2) */

static void sweep(const char *what, call_fn call, void *ctx, bp_status ok_status)
{
    bp_allocator a = test_allocator();
    long n, k, wrong = 0, leaks = 0, oom = 0, invalid = 0, first_wrong = 0, first_leak = 0, fallbacks = 0;
    bp_status st, wrong_st = BP_OK;
    int valid = 0;
    double t0 = now();
    counter_reset(0);
    st = call(ctx, &a, &valid);
    n = C.calls;
    if (!BPT_CHECK(st == ok_status && valid && balanced(),
                   "%s: without failures %s, valid, balanced (%ld allocations, %ld frees, %lld bytes live)", what,
                   bp_status_string(st), C.allocs, C.frees, C.live_bytes))
        return;
    for (k = 1; k <= n + 1; k++) {
        counter_reset(k);
        valid = 0;
        st = call(ctx, &a, &valid);
        if (k <= n && st == ok_status && valid == 2) fallbacks++;     /* Newton's memory refused: L-BFGS finished */
        else if (k <= n ? st != BP_ERR_OUT_OF_MEMORY : st != ok_status) {
            if (!wrong++) { first_wrong = k; wrong_st = st; }
        }
        if (k <= n && st == BP_ERR_OUT_OF_MEMORY) oom++;
        if ((st == BP_OK || st == ok_status) && !valid) invalid++;
        if (!balanced()) {
            if (!leaks++) first_leak = k;
        }
    }
    BPT_CHECK(wrong == 0, "%s: failing allocation k = 1..%ld gives BP_ERR_OUT_OF_MEMORY every time, k = %ld gives %s "
              "(%ld wrong; first at k = %ld: %s)", what, n, n + 1, bp_status_string(ok_status), wrong, first_wrong,
              bp_status_string(wrong_st));
    BPT_CHECK(leaks == 0 && invalid == 0, "%s: every run frees everything it took (%ld leaking, first at k = %ld) and "
              "every returned result is valid (%ld invalid)", what, leaks, first_leak, invalid);
    printf("     %s: %ld allocations, %ld runs", what, n, n + 1);
    if (fallbacks) printf(" (%ld fell back to L-BFGS)", fallbacks);
    printf(", %.2f s\n", now() - t0);
    last_fallbacks = fallbacks;
    (void)oom;
}

/* bp_parameterize with the given options; the atlas is freed here. */
#define REF_CHARTS 8
typedef struct param_ctx {
    const bp_mesh *m;
    bp_options opt;
    bp_direction ref[REF_CHARTS];   /* each chart's direction in the run without failures */
} param_ctx;

/* *valid: 1 a valid atlas, 2 a valid atlas where a chart that ran Newton
   without failures ran the preconditioned L-BFGS (the fallback). */
static bp_status call_parameterize(void *ctx, const bp_allocator *a, int *valid)
{
    param_ctx *P = (param_ctx *)ctx;
    bp_options o = P->opt;
    bp_atlas at;
    bp_error err;
    bp_status st;
    uint32_t c;
    o.allocator = *a;
    memset(&err, 0, sizeof err);
    st = bp_parameterize(&at, P->m, &o, &err);
    if (st != BP_OK && !err.message[0]) return BP_ERR_INVALID_ARGUMENT;   /* no message: counted as wrong */
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED || st == BP_ERR_CANCELLED) {
        *valid = atlas_valid(&at);
        for (c = 0; c < at.num_charts && c < REF_CHARTS; c++) {
            if (!C.fail_at) P->ref[c] = at.charts[c].direction;
            else if (*valid && P->ref[c] == BP_DIRECTION_NEWTON && at.charts[c].direction == BP_DIRECTION_PRECONDITIONED)
                *valid = 2;
        }
    }
    else if (at.charts || at.corner_chart || at.num_charts) return BP_ERR_INVALID_ARGUMENT;   /* not zeroed */
    bp_atlas_free(&at);
    return st;
}

static bp_status call_visibility(void *ctx, const bp_allocator *a, int *valid)
{
    param_ctx *P = (param_ctx *)ctx;
    bp_options o = P->opt;
    bp_error err;
    bp_status st;
    double *out = (double *)malloc(P->m->num_triangles * sizeof(double));
    uint32_t t;
    o.allocator = *a;
    st = bp_visibility(P->m, &o, out, &err);
    *valid = 1;
    if (st == BP_OK)
        for (t = 0; t < P->m->num_triangles; t++)
            if (!(out[t] > 0) || !isfinite(out[t])) *valid = 0;
    free(out);
    return st;
}

/* bp_write_obj: the atlas is built once (with the test allocator, nothing
   failing); only the write's own allocations are swept. */
typedef struct write_ctx {
    const bp_mesh *m;
    bp_atlas *at;
    const char *path;
} write_ctx;

static bp_status call_write(void *ctx, const bp_allocator *a, int *valid)
{
    write_ctx *W = (write_ctx *)ctx;
    bp_error err;
    (void)a;
    *valid = 1;
    return bp_write_obj(W->path, W->m, W->at, &err);
}

typedef struct check_ctx {
    const bp_chart *ch;
} check_ctx;

static bp_status call_check(void *ctx, const bp_allocator *a, int *valid)
{
    check_ctx *K = (check_ctx *)ctx;
    bp_check_report r;
    bp_status st = bp_check(K->ch->triangles, K->ch->num_triangles, K->ch->uv, K->ch->num_vertices, a, &r, NULL);
    /* out of memory: no verdict; otherwise the map is valid and must be
       found so (a verdict of "not bijective" is a wrong answer here) */
    *valid = st == BP_ERR_OUT_OF_MEMORY ||
             (st == BP_OK && !r.flipped && !r.boundary_intersections && !r.loop_orientation && !r.nested);
    return st == BP_ERR_OUT_OF_MEMORY ? st : BP_OK;
}

/* The same through bp_check_opt: the allocator comes from the options. */
static bp_status call_check_opt(void *ctx, const bp_allocator *a, int *valid)
{
    check_ctx *K = (check_ctx *)ctx;
    bp_check_report r;
    bp_options o;
    bp_status st;
    bp_options_init(&o);
    if (a) o.allocator = *a;
    st = bp_check_opt(K->ch->triangles, K->ch->num_triangles, K->ch->uv, K->ch->num_vertices, &o, &r, NULL);
    *valid = st == BP_ERR_OUT_OF_MEMORY ||
             (st == BP_OK && !r.flipped && !r.boundary_intersections && !r.loop_orientation && !r.nested);
    return st == BP_ERR_OUT_OF_MEMORY ? st : BP_OK;
}

/* bp_pool_create built without threads: a pool of one thread (the
   caller's), one allocation from the given allocator; a loop on it runs
   every task once. */
static void count_task(void *task, uint32_t i) { ((uint32_t *)task)[i]++; }
static bp_status call_pool(void *ctx, const bp_allocator *a, int *valid)
{
    bp_pool *pool;
    bp_error err;
    bp_status st = bp_pool_create(&pool, 4, a, &err);
    uint32_t n[100] = { 0 }, i;
    (void)ctx;
    *valid = st == BP_OK ? bp_pool_threads(pool) == 1 : pool == NULL && err.message[0];
    if (st != BP_OK) return st;
    bp_pool_for(pool, count_task, n, 100);
    for (i = 0; i < 100; i++) *valid = *valid && n[i] == 1;
    bp_pool_destroy(pool);
    return st;
}

int main(void)
{
    bp_mesh bishop, holed, mixed, small;
    bp_error err;
    param_ctx P;
    double t0 = now();

    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &bishop, NULL, &err) == BP_OK, "read bishop"))
        return bpt_finish();
    holed = holed_grid(12, 10, 0);
    mixed = holed_grid(6, 6, 1);

    memset(&P, 0, sizeof P);
    P.m = &bishop;
    P.opt.max_iterations = 20;
    sweep("bp_parameterize bishop (1000 triangles, 20 iterations)", call_parameterize, &P, BP_OK);
    BPT_CHECK(P.ref[0] == BP_DIRECTION_NEWTON && last_fallbacks > 0,
              "bishop: the default ran Newton (%d), and L-BFGS finished the chart after %ld of the failures",
              (int)P.ref[0], last_fallbacks);

    memset(&P, 0, sizeof P);
    P.m = &holed;
    P.opt.max_iterations = 20;
    sweep("bp_parameterize disk with 2 holes (236 triangles, 20 iterations)", call_parameterize, &P, BP_OK);

    memset(&P, 0, sizeof P);
    P.m = &holed;
    P.opt.init_only = 1;
    P.opt.init = BP_INIT_MEAN_VALUE;
    P.opt.normalize = 1;
    sweep("bp_parameterize disk with 2 holes, mean-value init_only, normalize", call_parameterize, &P, BP_OK);

    memset(&P, 0, sizeof P);
    P.m = &mixed;
    P.opt.max_iterations = 10;
    P.opt.cut = BP_CUT_NONE;
    sweep("bp_parameterize good chart + closed chart, --cut none (10 iterations)", call_parameterize, &P,
          BP_ERR_CHARTS_FAILED);

    memset(&P, 0, sizeof P);
    P.m = &mixed;
    P.opt.max_iterations = 5;
    P.opt.energy = BP_ENERGY_MIPS;
    P.opt.direction = BP_DIRECTION_LBFGS;
    P.opt.strict = 0;
    sweep("bp_parameterize good + closed (cut into a disk, >>cut), MIPS, plain L-BFGS (5 iterations)",
          call_parameterize, &P, BP_OK);

    memset(&P, 0, sizeof P);
    P.m = &holed;
    P.opt.max_iterations = 5;
    P.opt.direction = BP_DIRECTION_NEWTON;
    sweep("bp_parameterize disk with 2 holes, projected Newton (5 iterations)", call_parameterize, &P, BP_OK);
    BPT_CHECK(last_fallbacks == 0, "Newton asked for by name never falls back (%ld)", last_fallbacks);

    /* a mesh of extreme size (2^-400): solved on a rescaled copy, one more
       allocation path; and a closed chart with a zero-area triangle:
       repaired and cut by default, failing only its chart with cut none */
    {
        bp_mesh tiny = holed_grid(6, 6, 0), flat = holed_grid(6, 6, 1);
        uint32_t i;
        for (i = 0; i < 3 * tiny.num_vertices; i++) tiny.positions[i] = ldexp(tiny.positions[i], -400);
        memset(&P, 0, sizeof P);
        P.m = &tiny;
        P.opt.max_iterations = 5;
        sweep("bp_parameterize disk with 2 holes at scale 2^-400 (5 iterations)", call_parameterize, &P, BP_OK);
        /* the tetrahedron's last vertex onto its first edge: a zero-area
           triangle (and the tetrahedron is no longer the only defect) */
        for (i = 0; i < 3; i++)
            flat.positions[3 * (flat.num_vertices - 1) + i] = 0.5 * (flat.positions[3 * (flat.num_vertices - 4) + i] +
                                                                     flat.positions[3 * (flat.num_vertices - 3) + i]);
        P.m = &flat;
        sweep("bp_parameterize good chart + closed chart with a zero-area triangle (repaired and cut)",
              call_parameterize, &P, BP_OK);
        P.opt.cut = BP_CUT_NONE;          /* the closed chart then fails alone */
        sweep("bp_parameterize good chart + closed chart with a zero-area triangle, cut none",
              call_parameterize, &P, BP_ERR_CHARTS_FAILED);
        bpt_mesh_free(&tiny);
        bpt_mesh_free(&flat);
    }

    /* charts as parallel tasks (a user parallel_for): two holed disks of
       equal size and a closed chart (cut into a disk by >>cut) */
    {
        bp_mesh disk = holed_grid(6, 6, 0), twin = concat(&disk, &mixed, 20);
        memset(&P, 0, sizeof P);
        P.m = &twin;
        P.opt.max_iterations = 10;
        P.opt.parallel_for = reverse_for;
        sweep("bp_parameterize 3 charts (one cut) as tasks of a user parallel_for (10 iterations)",
              call_parameterize, &P, BP_OK);
        bpt_mesh_free(&twin);
        bpt_mesh_free(&disk);
    }

    /* visibility on a small closed mesh: a tetrahedron (the mixed mesh's
       last 4 triangles are one, and visibility needs no charts) */
    small = bpt_mesh_new(4, 4);
    memcpy(small.positions, mixed.positions + 3 * (mixed.num_vertices - 4), 12 * sizeof(double));
    {
        uint32_t i;
        for (i = 0; i < 12; i++) small.triangles[i] = mixed.triangles[3 * (mixed.num_triangles - 4) + i] -
                                                      (mixed.num_vertices - 4);
    }
    memset(&P, 0, sizeof P);
    P.m = &small;
    P.opt.views.model = BP_VIEW_UNIFORM;
    P.opt.views.samples = 16;
    sweep("bp_visibility tetrahedron (uniform views, 16 samples)", call_visibility, &P, BP_OK);
    memset(&P, 0, sizeof P);
    P.m = &holed;
    P.opt.views.model = BP_VIEW_FRONT;
    P.opt.views.samples = 8;
    sweep("bp_visibility disk with 2 holes (front views, 8 samples)", call_visibility, &P, BP_OK);
    /* visibility-driven bp_parameterize (bp_visibility inside) */
    memset(&P, 0, sizeof P);
    P.m = &holed;
    P.opt.views.model = BP_VIEW_FRONT;
    P.opt.views.samples = 8;
    P.opt.max_iterations = 5;
    sweep("bp_parameterize disk with 2 holes, front visibility (5 iterations)", call_parameterize, &P, BP_OK);

    /* bp_write_obj and bp_check */
    {
        bp_atlas at;
        bp_options o;
        char dir[] = "/tmp/bp_alloc_XXXXXX", path[128];
        memset(&o, 0, sizeof o);
        counter_reset(0);
        o.allocator = test_allocator();
        o.max_iterations = 5;
        o.cut = BP_CUT_NONE;      /* keep the closed chart failed: the writer skips it */
        if (BPT_CHECK(bp_parameterize(&at, &mixed, &o, &err) == BP_ERR_CHARTS_FAILED, "mixed atlas for the write") &&
            BPT_CHECK(mkdtemp(dir) != NULL, "mkdtemp")) {
            write_ctx W;
            check_ctx K;
            sprintf(path, "%s/out.obj", dir);
            W.m = &mixed; W.at = &at; W.path = path;
            {
                /* bp_write_obj allocates with the atlas's allocator, which is
                   the test allocator; the atlas's blocks stay live across the
                   sweep, so balance is checked as "no new live bytes". */
                long k, n, wrong = 0, leaks = 0;
                counter_reset(0);
                (void)call_write(&W, NULL, &(int){ 0 });
                n = C.calls;
                for (k = 1; k <= n + 1; k++) {
                    bp_status st;
                    counter_reset(k);
                    st = bp_write_obj(path, &mixed, &at, &err);
                    if (k <= n ? st != BP_ERR_OUT_OF_MEMORY : st != BP_OK) wrong++;
                    if (C.allocs != C.frees || C.live_bytes != 0 || C.bad_free || C.null_free) leaks++;
                }
                BPT_CHECK(n > 0 && wrong == 0 && leaks == 0,
                          "bp_write_obj: %ld allocations; failing each gives BP_ERR_OUT_OF_MEMORY and frees its "
                          "table (%ld wrong, %ld leaking)", n, wrong, leaks);
            }
            K.ch = &at.charts[0];
            sweep("bp_check on the mapped chart", call_check, &K, BP_OK);
            sweep("bp_check_opt on the mapped chart (opt's allocator)", call_check_opt, &K, BP_OK);
            sweep("bp_pool_create without threads (one thread)", call_pool, NULL, BP_OK);
            unlink(path);
            rmdir(dir);
        }
        /* the atlas was allocated before the counter resets: free it with
           the real allocator (its blocks carry the test header) */
        bp_atlas_free(&at);
    }

    bp_mesh_free(&bishop, NULL);
    bpt_mesh_free(&holed);
    bpt_mesh_free(&mixed);
    bpt_mesh_free(&small);
    /* The sweeps must stay affordable: a change that makes a covered call
       allocate much more (N grows, the sweep grows as N^2) is caught here by
       counting, not by the clock, which a loaded machine stretches. */
    total_calls += C.calls;
    BPT_CHECK(total_runs > 1000 && total_calls <= BUDGET_CALLS,
              "the sweeps made %ld runs and %lld allocation calls (budget %lld; %.1f s here)", total_runs,
              total_calls, (long long)BUDGET_CALLS, now() - t0);
    return bpt_finish();
}
