/* test_pool.c - small work runs on the calling thread (issue 13).

   With the default thresholds of >>threads (BP__PAR_MIN_TRIANGLES = 8192):
     - a chart below 8192 triangles is solved with serial loops and no pool:
       bp_chart_init / bp_chart_optimize / bp_parameterize on 2 threads make
       exactly the allocations of 1 thread (the pool would add its own),
       report chart.threads == 1, and never call a user parallel_for;
     - a chart of 8192 triangles or more uses the threads: chart.threads == 2
       and a user parallel_for is called, with the same bits as 1 thread;
     - many small charts are solved as parallel tasks (chart.threads == 2),
       one pool for the whole call, also after a dominant large chart.
   Allocations are counted by a bp_allocator that wraps malloc (a pool is
   four allocations); a count cannot be flaky the way a time can. */
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

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
   parallel tasks (every chart.threads 2; they used to follow one by one on
   the caller), with the same bits as 1 thread. */
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

int main(void)
{
    check_small_chart();
    check_large_chart();
    check_many_charts();
    check_dominant_chart();
    return bpt_finish();
}
