/* test_pool.c - small work runs on the calling thread.

   With the default thresholds of >>threads (BP__PAR_MIN_TRIANGLES = 8192):
     - a chart below 8192 triangles is solved with serial loops and no pool:
       bp_chart_init / bp_chart_optimize / bp_parameterize on 2 threads make
       exactly the allocations of 1 thread (the pool would add its own),
       report chart.threads == 1, and never call a user parallel_for;
     - a chart of 8192 triangles or more uses the threads: chart.threads == 2
       and a user parallel_for is called, with the same bits as 1 thread;
     - many small charts are solved as parallel tasks (chart.threads == 2),
       one pool for the whole call, also after a dominant large chart;
     - bp_parameterize on 2 threads starts one pool for all its stages
       (build, solve, pack, check), not one per stage;
     - a bp_pool kept across calls (bp_pool_create): the calls see its
       real thread count (chart.threads 2, not 0 as for a foreign
       parallel_for), start no pools of their own (fewer allocations than
       threads = 2), give the same bits as 1 thread, and run every task
       exactly once; two threads sharing one pool, and a call from inside
       a callback of a call on the pool, finish with the same bits (the
       loop that finds the pool busy runs on its own thread); bad
       arguments and every failed allocation of bp_pool_create are
       reported, with nothing leaked.
   Allocations are counted by a bp_allocator that wraps malloc (a pool is
   four allocations); a count cannot be flaky the way a time can. */
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static long n_alloc = 0;              /* only counted from the calling thread's calls below */
static void *count_alloc(void *user, size_t size)
{
    (void)user;
    __atomic_fetch_add(&n_alloc, 1, __ATOMIC_RELAXED);
    return malloc(size);
}
static void count_free(void *user, void *p)
{
    (void)user;
    free(p);
}

static long pf_calls = 0;
static void user_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    __atomic_fetch_add(&pf_calls, 1, __ATOMIC_RELAXED);
    for (i = 0; i < count; i++) fn(task, i);
}

static bp_options options(int threads, int user_pf)
{
    bp_options o;
    memset(&o, 0, sizeof o);
    o.threads = threads;
    o.max_iterations = 5;
    o.allocator.alloc = count_alloc;
    o.allocator.free = count_free;
    if (user_pf) o.parallel_for = user_for;
    return o;
}

/* bp_atlas_build, then bp_chart_init + bp_chart_optimize on every chart.
   Returns the allocations counted and the largest chart.threads; the
   charts' uv are appended to uv (if not NULL). */
static long chart_by_chart(const bp_mesh *m, const bp_options *o, int *threads, double *uv, int *ok)
{
    bp_atlas at;
    bp_error e;
    uint32_t c, i;
    size_t k = 0;
    n_alloc = 0;
    *threads = 0;
    *ok = bp_atlas_build(&at, m, o, &e) == BP_OK;
    for (c = 0; *ok && c < at.num_charts; c++) {
        *ok = bp_chart_init(&at.charts[c], m, o, &e) == BP_OK &&
              bp_chart_optimize(&at.charts[c], c, m, o, &e) == BP_OK;
        if (at.charts[c].threads > *threads) *threads = at.charts[c].threads;
        for (i = 0; *ok && uv && i < 2 * at.charts[c].num_vertices; i++) uv[k++] = at.charts[c].uv[i];
    }
    if (!*ok) printf("  failed: %s\n", e.message);
    bp_atlas_free(&at);
    return n_alloc;
}

static long whole(const bp_mesh *m, const bp_options *o, int *threads, int *ok)
{
    bp_atlas at;
    bp_error e;
    uint32_t c;
    n_alloc = 0;
    *threads = 0;
    *ok = bp_parameterize(&at, m, o, &e) == BP_OK;
    for (c = 0; *ok && c < at.num_charts; c++)
        if (at.charts[c].threads > *threads) *threads = at.charts[c].threads;
    if (*ok) bp_atlas_free(&at);
    else printf("  failed: %s\n", e.message);
    return n_alloc;
}

/* An n x n grid of squares with a bump: 2 n^2 triangles, one chart. */
static bp_mesh grid(uint32_t n)
{
    bp_mesh m = bpt_mesh_new((n + 1) * (n + 1), 2 * n * n);
    uint32_t i, j, k = 0;
    for (j = 0; j <= n; j++)
        for (i = 0; i <= n; i++) {
            double *p = m.positions + 3 * (j * (n + 1) + i), x = (double)i / n, y = (double)j / n;
            p[0] = x; p[1] = y; p[2] = 0.4 * x * (1 - x) * y * (1 - y) + 0.1 * x * y;
        }
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            m.triangles[k++] = a; m.triangles[k++] = b; m.triangles[k++] = c;
            m.triangles[k++] = a; m.triangles[k++] = c; m.triangles[k++] = d;
        }
    return m;
}

static void check_small_chart(void)
{
    bp_mesh m;
    bp_error e;
    bp_options o1 = options(1, 0), o2 = options(2, 0), ou = options(0, 1);
    long a1, a2;
    int t1, t2, ok1, ok2, oku;
    if (bp_read_mesh("tests/data/camel_b.obj", &m, NULL, &e) != BP_OK) {
        BPT_CHECK(0, "read tests/data/camel_b.obj: %s", e.message);
        return;
    }
    a1 = chart_by_chart(&m, &o1, &t1, NULL, &ok1);
    a2 = chart_by_chart(&m, &o2, &t2, NULL, &ok2);
    BPT_CHECK(ok1 && ok2 && a1 == a2 && t2 == 1,
              "camel_b (%u triangles, below 8192), chart by chart: 2 threads make the allocations of 1 "
              "(%ld and %ld: no pool) and report 1 thread (%d)", m.num_triangles, a2, a1, t2);
    a1 = whole(&m, &o1, &t1, &ok1);
    a2 = whole(&m, &o2, &t2, &ok2);
    BPT_CHECK(ok1 && ok2 && a1 == a2 && t2 == 1,
              "camel_b, bp_parameterize: 2 threads make the allocations of 1 (%ld and %ld) and report 1 thread (%d)",
              a2, a1, t2);
    pf_calls = 0;
    chart_by_chart(&m, &ou, &t1, NULL, &oku);
    BPT_CHECK(oku && pf_calls == 0, "camel_b: a user parallel_for is not called for a small chart (%ld calls)", pf_calls);
    bp_mesh_free(&m, NULL);
}

static void check_large_chart(void)
{
    bp_mesh m = grid(64);                      /* 8192 triangles: the threshold itself */
    bp_options o1 = options(1, 0), o2 = options(2, 0), ou = options(0, 1);
    size_t nuv = 2 * (size_t)m.num_vertices;
    double *u1 = (double *)calloc(nuv, sizeof(double)), *u2 = (double *)calloc(nuv, sizeof(double));
    long a1, a2;
    int t1, t2, ok1, ok2, oku;
    a1 = chart_by_chart(&m, &o1, &t1, u1, &ok1);
    a2 = chart_by_chart(&m, &o2, &t2, u2, &ok2);
    BPT_CHECK(ok1 && ok2 && t1 == 1 && t2 == 2 && a2 > a1 && !memcmp(u1, u2, nuv * sizeof(double)),
              "a %u-triangle grid chart: 2 threads are used (%d, %ld allocations against %ld: the pools), "
              "with the same bits as 1", m.num_triangles, t2, a2, a1);
    pf_calls = 0;
    chart_by_chart(&m, &ou, &t1, NULL, &oku);
    BPT_CHECK(oku && pf_calls > 0, "the grid chart: a user parallel_for is called (%ld calls)", pf_calls);
    free(u1); free(u2);
    bpt_mesh_free(&m);
}

static void check_many_charts(void)
{
    enum { N = 200 };
    bp_mesh m = bpt_mesh_new(3 * N, N);
    bp_options o2 = options(2, 0);
    uint32_t i;
    int t2, ok2;
    for (i = 0; i < N; i++) {
        double *p = m.positions + 9 * i;
        p[0] = 2.0 * i; p[1] = 0; p[2] = 0;
        p[3] = 2.0 * i + 1; p[4] = 0; p[5] = 0;
        p[6] = 2.0 * i; p[7] = 1; p[8] = 0.5;
        m.triangles[3 * i] = 3 * i; m.triangles[3 * i + 1] = 3 * i + 1; m.triangles[3 * i + 2] = 3 * i + 2;
    }
    whole(&m, &o2, &t2, &ok2);
    BPT_CHECK(ok2 && t2 == 2, "%d one-triangle charts, bp_parameterize on 2 threads: solved as parallel tasks "
              "(chart.threads %d)", N, t2);
    bpt_mesh_free(&m);
}

/* A dominant chart (the 8192-triangle grid, more than half the
   triangles) and 200 one-triangle charts, bp_parameterize: on 2 threads
   the grid's loops use the threads and then the small charts are the
   parallel tasks (every chart.threads 2, not one by one on the caller),
   with the same bits as 1 thread. */
static void check_dominant_chart(void)
{
    enum { N = 200 };
    bp_mesh g = grid(64), m = bpt_mesh_new(g.num_vertices + 3 * N, g.num_triangles + N);
    bp_options o1 = options(1, 0), o2 = options(2, 0);
    bp_atlas a1, a2;
    bp_error e1, e2;
    uint32_t i, c, small2 = 0, nsmall = 0, same = 1;
    int ok;
    memcpy(m.positions, g.positions, 3 * (size_t)g.num_vertices * sizeof(double));
    memcpy(m.triangles, g.triangles, 3 * (size_t)g.num_triangles * sizeof(uint32_t));
    for (i = 0; i < N; i++) {
        double *p = m.positions + 3 * ((size_t)g.num_vertices + 3 * i);
        uint32_t *t = m.triangles + 3 * ((size_t)g.num_triangles + i);
        p[0] = 3.0 + 2.0 * i; p[1] = 0; p[2] = 0;
        p[3] = 4.0 + 2.0 * i; p[4] = 0; p[5] = 0;
        p[6] = 3.0 + 2.0 * i; p[7] = 1; p[8] = 0.5;
        t[0] = g.num_vertices + 3 * i; t[1] = t[0] + 1; t[2] = t[0] + 2;
    }
    ok = bp_parameterize(&a1, &m, &o1, &e1) == BP_OK;
    ok = ok && bp_parameterize(&a2, &m, &o2, &e2) == BP_OK;
    if (!BPT_CHECK(ok && a1.num_charts == N + 1 && a2.num_charts == N + 1, "a grid and %d small charts: solved (%s)", N,
                   ok ? "ok" : e1.message))
        return;
    for (c = 0; c < a2.num_charts; c++) {
        const bp_chart *x = &a1.charts[c], *y = &a2.charts[c];
        same = same && x->num_vertices == y->num_vertices &&
               !memcmp(x->uv, y->uv, 2 * (size_t)x->num_vertices * sizeof(double));
        if (y->num_triangles < 8192) { nsmall++; small2 += y->threads == 2; }
        else BPT_CHECK(y->threads == 2, "the dominant grid chart's loops on 2 threads (chart.threads %d)", y->threads);
    }
    BPT_CHECK(same && nsmall == N && small2 == N,
              "a dominant grid chart and %d small charts on 2 threads: the small ones are the parallel tasks "
              "(%u of %u report 2 threads), every chart the same bits as 1 thread (%s)", N, small2, nsmall,
              same ? "yes" : "no");
    bp_atlas_free(&a1);
    bp_atlas_free(&a2);
    bpt_mesh_free(&g);
    bpt_mesh_free(&m);
}

/* ---- a bp_pool kept across calls ------------------------------------- */

/* bp_pool_for directly: each of `count` tasks adds one to its own slot. */
typedef struct hits { uint32_t *n; } hits;
static void hit_task(void *task, uint32_t i)
{
    __atomic_fetch_add(&((hits *)task)->n[i], 1u, __ATOMIC_RELAXED);
}

static int once_each(bp_pool *pool, uint32_t count)
{
    hits h;
    uint32_t i;
    int ok = 1;
    h.n = (uint32_t *)calloc(count, sizeof(uint32_t));
    bp_pool_for(pool, hit_task, &h, count);
    for (i = 0; i < count; i++) ok = ok && h.n[i] == 1;
    free(h.n);
    return ok;
}

/* A loop on the pool whose tasks each run a loop on the same pool: the
   inner loops find it busy and run on their own threads. */
typedef struct outer { bp_pool *pool; uint32_t bad; } outer;
static void outer_task(void *task, uint32_t i)
{
    outer *O = (outer *)task;
    if (!once_each(O->pool, 50 + i)) __atomic_fetch_add(&O->bad, 1u, __ATOMIC_RELAXED);
}

/* A whole run of bp_parameterize with o; 1 when its charts' uv equal ref's
   (ref NULL: kept in *out, the caller frees it). */
static int same_run(const bp_mesh *m, const bp_options *o, const bp_atlas *ref, bp_atlas *out, int *threads)
{
    bp_atlas at;
    bp_error e;
    uint32_t c;
    int ok = bp_parameterize(&at, m, o, &e) == BP_OK;
    *threads = 0;
    for (c = 0; ok && c < at.num_charts; c++) {
        if (at.charts[c].threads > *threads) *threads = at.charts[c].threads;
        ok = !ref || (ref->num_charts == at.num_charts && ref->charts[c].num_vertices == at.charts[c].num_vertices &&
                      !memcmp(ref->charts[c].uv, at.charts[c].uv, 2 * (size_t)at.charts[c].num_vertices * sizeof(double)));
    }
    if (!ok && !e.message[0]) printf("  a run gave other bits\n");
    else if (!ok) printf("  failed: %s\n", e.message);
    if (out) *out = at;
    else bp_atlas_free(&at);
    return ok;
}

typedef struct sharer {
    const bp_mesh *m;
    bp_options o;
    const bp_atlas *ref;
    int ok, threads;
} sharer;

static void *share_run(void *arg)
{
    sharer *S = (sharer *)arg;
    int r;
    S->ok = 1;
    for (r = 0; r < 3 && S->ok; r++) S->ok = same_run(S->m, &S->o, S->ref, NULL, &S->threads);
    return NULL;
}

/* A run_progress that checks the map of a small mesh on the same pool,
   from inside the call on the pool (the callback may run inside a loop's
   task: the pool is then busy). */
typedef struct nested { bp_pool *pool; const bp_mesh *small; const bp_atlas *small_ref; long calls, ok; } nested;
static int nested_progress(void *user, bp_stage stage, double fraction, uint32_t chart)
{
    nested *N = (nested *)user;
    bp_options o;
    int t;
    (void)stage; (void)fraction; (void)chart;
    N->calls++;
    bp_options_init(&o);
    o.max_iterations = 5;
    o.parallel_for = bp_pool_for;
    o.parallel_user = N->pool;
    if (same_run(N->small, &o, N->small_ref, NULL, &t)) N->ok++;
    return 0;
}

/* An allocator whose k-th allocation fails (k = 0: none), with balance. */
static long fa_k, fa_n, fa_live;
static void *fail_alloc(void *user, size_t size)
{
    (void)user;
    if (++fa_n == fa_k) return NULL;
    fa_live++;
    return malloc(size);
}
static void fail_free(void *user, void *p)
{
    (void)user;
    if (p) fa_live--;
    free(p);
}

static void check_pool_arguments(void)
{
    bp_pool *pool = (bp_pool *)&pool;
    bp_allocator fa;
    bp_error e;
    long n, k, wrong = 0;
    int ok;
    BPT_CHECK(bp_pool_create(NULL, 2, NULL, &e) == BP_ERR_INVALID_ARGUMENT && strstr(e.message, "pool"),
              "bp_pool_create(NULL, ...): BP_ERR_INVALID_ARGUMENT (%s)", e.message);
    BPT_CHECK(bp_pool_create(&pool, -3, NULL, &e) == BP_ERR_INVALID_ARGUMENT && bpt_has_number(e.message, -3) &&
              pool == NULL, "bp_pool_create with threads -3: BP_ERR_INVALID_ARGUMENT naming -3, *pool NULL (%s)",
              e.message);
    BPT_CHECK(bp_pool_threads(NULL) == 1, "bp_pool_threads(NULL) is 1");
    bp_pool_destroy(NULL);
    ok = bp_pool_create(&pool, 1, NULL, &e) == BP_OK;
    BPT_CHECK(ok && bp_pool_threads(pool) == 1 && once_each(pool, 1000),
              "a pool of 1 thread: 1 thread, every task of a loop run once");
    bp_pool_destroy(pool);
    ok = bp_pool_create(&pool, 0, NULL, &e) == BP_OK;     /* created before its count is printed */
    BPT_CHECK(ok && bp_pool_threads(pool) >= 1 && once_each(pool, 1000),
              "a pool of all cores (0): %d threads, every task of a loop run once", ok ? bp_pool_threads(pool) : 0);
    bp_pool_destroy(pool);
    fa.alloc = fail_alloc; fa.free = fail_free; fa.user = NULL;
    fa_k = 0; fa_n = 0; fa_live = 0;
    if (!BPT_CHECK(bp_pool_create(&pool, 3, &fa, &e) == BP_OK && bp_pool_threads(pool) == 3, "a pool of 3 threads"))
        return;
    n = fa_n;
    bp_pool_destroy(pool);
    for (k = 1; k <= n; k++) {
        fa_k = k; fa_n = 0; fa_live = 0;
        pool = (bp_pool *)&pool;
        if (bp_pool_create(&pool, 3, &fa, &e) != BP_ERR_OUT_OF_MEMORY || pool != NULL || fa_live != 0 ||
            !strstr(e.message, "pool"))
            wrong++;
    }
    BPT_CHECK(n >= 2 && fa_live == 0 && wrong == 0,
              "bp_pool_create on 3 threads: %ld allocations through its allocator, each one failing gives "
              "BP_ERR_OUT_OF_MEMORY, *pool NULL and nothing leaked (%ld wrong)", n, wrong);
}

static void check_shared_pool(void)
{
    bp_mesh m = grid(64), small;
    bp_options o1 = options(1, 0), o2 = options(2, 0), op = options(1, 0);
    bp_pool *pool = NULL;
    bp_atlas ref, small_ref;
    bp_error e;
    long a2, ap;
    int t = 0, tp = 0, ok;
    pthread_t th[2];
    sharer S[2];
    nested N;
    uint32_t k;
    if (!BPT_CHECK(bp_read_mesh("tests/data/camel_b.obj", &small, NULL, &e) == BP_OK, "read camel_b"))
        return;
    if (!BPT_CHECK(bp_pool_create(&pool, 2, NULL, &e) == BP_OK && bp_pool_threads(pool) == 2, "a pool of 2 threads"))
        return;
    op.parallel_for = bp_pool_for;
    op.parallel_user = pool;
    ok = same_run(&m, &o1, NULL, &ref, &t);
    n_alloc = 0;
    ok = ok && same_run(&m, &o2, &ref, NULL, &t);
    a2 = n_alloc;
    n_alloc = 0;
    ok = ok && same_run(&m, &op, &ref, NULL, &tp);
    ap = n_alloc;
    BPT_CHECK(ok && t == 2 && tp == 2 && ap < a2,
              "the %u-triangle grid through a bp_pool: the same bits as 1 thread, chart.threads %d (the pool's "
              "count), no pools of its own (%ld allocations against %ld with threads = 2)", m.num_triangles, tp, ap,
              a2);
    {   /* bp_parameterize on threads = 2 keeps one pool for all its stages */
        bp_pool *one;
        n_alloc = 0;
        if (bp_pool_create(&one, 2, &o2.allocator, &e) == BP_OK) bp_pool_destroy(one);
        BPT_CHECK(a2 - ap == n_alloc, "bp_parameterize on threads = 2 starts one pool for all its stages: %ld "
                  "allocations more than on a kept pool, one pool's %ld", a2 - ap, n_alloc);
    }
    for (ok = 1, k = 0; k < 200 && ok; k++) ok = once_each(pool, 1 + k * 37);
    BPT_CHECK(ok, "200 loops of 1 to 7364 tasks on the kept pool: every task run exactly once");
    {
        outer O;
        O.pool = pool; O.bad = 0;
        bp_pool_for(pool, outer_task, &O, 64);
        BPT_CHECK(O.bad == 0 && once_each(pool, 1000), "64 tasks on the pool, each running a loop of 50 to 113 tasks "
                  "on the same pool: every inner task run once (%u loops wrong), and the pool works after", O.bad);
    }
    /* a call on a kept pool starts over as a new pool would (the time
       between calls, or a call's serial end, is no measure of the
       machine): decisions of an earlier call (set here by hand) are
       dropped, only the threads are kept */
    {
        bp__par par;
        void *own = NULL;
        for (k = 0; k < 300; k++) once_each(pool, 4);
        pool->P->looked = 1;
        pool->P->skip = 100;
        pool->P->backoff = BP__BACKOFF_MIN;
        pool->P->spin = BP__SPIN_LONG_NS;
        par = bp__par_begin(&op.allocator, &op, &own);
        BPT_CHECK(pool->P->wjobs == 0 && !pool->P->looked && pool->P->skip == 0 && pool->P->backoff == 0 &&
                  pool->P->spin == BP__SPIN_NS && own == NULL && par.threads == 2 && par.run == bp_pool_for,
                  "a call's start on a kept pool: a new window (%u loops in it) with the early look, no backoff "
                  "(%u loops to skip), the short poll (%u ns), no pool of its own, 2 threads", pool->P->wjobs,
                  pool->P->skip, pool->P->spin);
    }
    /* two threads sharing the pool: 3 runs each, at once */
    for (k = 0; k < 2; k++) {
        S[k].m = &m; S[k].o = op; S[k].ref = &ref; S[k].ok = 0; S[k].threads = 0;
        pthread_create(&th[k], NULL, share_run, &S[k]);
    }
    for (k = 0; k < 2; k++) pthread_join(th[k], NULL);
    BPT_CHECK(S[0].ok && S[1].ok, "two threads running bp_parameterize on one pool at once, 3 times each: "
              "the same bits as 1 thread (%d, %d)", S[0].ok, S[1].ok);
    /* a call on the pool from inside a callback of a call on the pool */
    {
        bp_options on = op;
        N.pool = pool; N.small = &small; N.calls = 0; N.ok = 0;
        ok = same_run(&small, &o1, NULL, &small_ref, &t);
        N.small_ref = &small_ref;
        on.run_progress = nested_progress;
        on.run_progress_user = &N;
        ok = ok && same_run(&m, &on, &ref, NULL, &tp);
        BPT_CHECK(ok && N.calls >= 3 && N.ok == N.calls,
                  "bp_parameterize on the pool, its run_progress parameterizing camel_b on the same pool (%ld of %ld "
                  "inner runs the same bits as 1 thread): both finish, the same bits", N.ok, N.calls);
        bp_atlas_free(&small_ref);
    }
    bp_pool_destroy(pool);
    bp_atlas_free(&ref);
    bp_mesh_free(&small, NULL);
    bpt_mesh_free(&m);
}

int main(void)
{
    check_small_chart();
    check_large_chart();
    check_many_charts();
    check_dominant_chart();
    check_pool_arguments();
    check_shared_pool();
    return bpt_finish();
}
