/* test_threads.c - the result does not depend on how the work is run.

   bijparam cuts every parallel loop into tasks whose boundaries depend only
   on the number of items, and combines their results in task order.  So a
   solve must give bit-identical maps -- and byte-identical OBJ files -- for
   1, 2, 3, 4 and 8 threads of the built-in pool (BP_USE_PTHREADS), and for
   a user parallel_for that runs the tasks in reverse order.  This is
   checked on real charts: camel_b (one chart, long boundary), face_holes
   (7 loops), spot (13 charts: solved in parallel as whole charts), the cow,
   bishop, and a planar grid (its start is its projection); camel_b and
   face_holes again from the mean-value start (whose weights are computed
   beside the dissection's root split); and on visibility (chapter 4),
   whose random streams are per triangle.

   The library runs small charts and small loops serially (>>threads); this
   test sets both thresholds to 1 so that every loop of these small meshes
   goes through the pool.  It also checks the pool itself under stress
   (every task of thousands of jobs runs exactly once, with more threads
   than cores, so that workers wake late), a mesh of many one-triangle
   charts, and bp_chart_init / bp_chart_optimize called alone. */
#define BP__PAR_MIN_TRIANGLES 1u
#define BP__PAR_MIN_ITEMS     1u
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A job system that runs the tasks backwards on the calling thread. */
static int reverse_calls = 0;
static int quick = 0;          /* BP_TEST_QUICK: fewer meshes and iterations (sanitizer runs) */
static bp_init start_init = BP_INIT_AUTO;   /* the start map solve() asks for */
static void reverse_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    reverse_calls++;
    for (i = count; i-- > 0;) fn(task, i);
}

static char *slurp(const char *path, long *len)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    *len = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = (char *)malloc((size_t)*len + 1);
    if (buf && fread(buf, 1, (size_t)*len, f) != (size_t)*len) { free(buf); buf = NULL; }
    fclose(f);
    return buf;
}

/* Solve with the given runner; write the OBJ; return its bytes. */
static char *solve(const bp_mesh *m, int threads, int reverse, long *len, int *used, double *energy)
{
    bp_options o;
    bp_atlas at;
    bp_error e;
    char path[64];
    char *bytes = NULL;
    memset(&o, 0, sizeof o);
    o.threads = threads;
    o.init = start_init;
    o.max_iterations = quick ? 20 : 300;
    if (reverse) o.parallel_for = reverse_for;
    if (bp_parameterize(&at, m, &o, &e) != BP_OK) { printf("  solve failed: %s\n", e.message); return NULL; }
    *used = at.charts[0].threads;
    *energy = at.charts[0].energy_end;
    snprintf(path, sizeof path, "build/tests/threads_%d_%d.obj", threads, reverse);
    if (bp_write_obj(path, m, &at, &e) == BP_OK) bytes = slurp(path, len);
    remove(path);
    bp_atlas_free(&at);
    return bytes;
}

static void check_mesh(const char *path)
{
    static const int counts[] = { 1, 2, 3, 4, 8 };
    bp_mesh m;
    bp_error e;
    long len0 = 0, len;
    char *ref;
    int k, used, same = 1, threads_ok = 1;
    double en0, en;
    if (bp_read_mesh(path, &m, NULL, &e) != BP_OK) {
        BPT_CHECK(0, "%s: read: %s", path, e.message);
        return;
    }
    ref = solve(&m, 1, 0, &len0, &used, &en0);
    BPT_CHECK(ref != NULL && used == 1, "%s: serial solve (1 thread used, energy %.6f)", path, ref ? en0 : 0.0);
    for (k = 1; ref && k < 5; k++) {
        char *b = solve(&m, counts[k], 0, &len, &used, &en);
        int eq = b && len == len0 && !memcmp(b, ref, (size_t)len);
        if (!eq) same = 0;
        if (used != counts[k]) threads_ok = 0;
        BPT_CHECK(eq, "%s: %d threads write the same %ld bytes as 1 thread (energy %.17g vs %.17g)", path, counts[k],
                  len0, en, en0);
        free(b);
    }
    BPT_CHECK(threads_ok, "%s: the pool really ran with the requested number of threads", path);
    if (ref) {
        int before = reverse_calls;
        char *b = solve(&m, 0, 1, &len, &used, &en);
        BPT_CHECK(b && len == len0 && !memcmp(b, ref, (size_t)len) && reverse_calls > before,
                  "%s: a user parallel_for running tasks backwards gives the same bytes (%d calls)", path,
                  reverse_calls - before);
        free(b);
    }
    (void)same;
    free(ref);
    bp_mesh_free(&m, NULL);
}

/* A planar chart (a tilted 40 x 40 grid, 3,042 triangles): its start is
   its own projection (>>start, 1), whose normal sums the triangles' cross
   products computed in tasks; then the same bytes on every thread count. */
static void check_planar(void)
{
    const char *path = "build/tests/threads_plane.obj";
    FILE *f = fopen(path, "w");
    bp_mesh m;
    bp_atlas at;
    bp_options o;
    bp_error e;
    int i, j, n = 40;
    if (!BPT_CHECK(f != NULL, "%s: written", path)) return;
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            double x = (double)i / (n - 1), y = 0.7 * j / (n - 1);
            fprintf(f, "v %.17g %.17g %.17g\n", 0.8 * x, y, 0.6 * x + 0.3 * y);
        }
    for (j = 0; j + 1 < n; j++)
        for (i = 0; i + 1 < n; i++) {
            int a = j * n + i + 1;
            fprintf(f, "f %d %d %d\nf %d %d %d\n", a, a + 1, a + n + 1, a, a + n + 1, a + n);
        }
    fclose(f);
    if (BPT_CHECK(bp_read_mesh(path, &m, NULL, &e) == BP_OK, "%s: read (%s)", path, e.message)) {
        memset(&o, 0, sizeof o);
        o.threads = 2;
        o.init_only = 1;
        if (BPT_CHECK(bp_parameterize(&at, &m, &o, &e) == BP_OK, "plane: start map (%s)", e.message)) {
            BPT_CHECK(at.charts[0].start_map == BP_INIT_AUTO, "plane: the start is its own projection (start_map %d)",
                      (int)at.charts[0].start_map);
            bp_atlas_free(&at);
        }
        bp_mesh_free(&m, NULL);
        check_mesh(path);
    }
    remove(path);
}

static void check_visibility(void)
{
    bp_mesh m;
    bp_error e;
    bp_options o;
    double *v1, *v2, *v3;
    uint32_t t;
    int same2 = 1, same3 = 1;
    if (bp_read_mesh("tests/data/cow_param_withSUV.obj", &m, NULL, &e) != BP_OK) { BPT_CHECK(0, "read cow"); return; }
    v1 = (double *)malloc(sizeof(double) * m.num_triangles);
    v2 = (double *)malloc(sizeof(double) * m.num_triangles);
    v3 = (double *)malloc(sizeof(double) * m.num_triangles);
    /* Three different fillers: a call that writes nothing leaves the
       buffers unequal, so it cannot pass the comparison below. */
    for (t = 0; t < m.num_triangles; t++) { v1[t] = -1.0; v2[t] = -2.0; v3[t] = -3.0; }
    memset(&o, 0, sizeof o);
    o.views.model = BP_VIEW_UNIFORM;
    o.views.samples = 16;
    o.threads = 1;
    BPT_CHECK(bp_visibility(&m, &o, v1, &e) == BP_OK, "visibility of the cow, 1 thread: BP_OK");
    o.threads = 2;
    BPT_CHECK(bp_visibility(&m, &o, v2, &e) == BP_OK, "visibility of the cow, 2 threads: BP_OK");
    o.threads = 0;
    o.parallel_for = reverse_for;
    BPT_CHECK(bp_visibility(&m, &o, v3, &e) == BP_OK, "visibility of the cow, tasks backwards: BP_OK");
    for (t = 0; t < m.num_triangles; t++) {
        if (memcmp(&v1[t], &v2[t], sizeof(double))) same2 = 0;
        if (memcmp(&v1[t], &v3[t], sizeof(double))) same3 = 0;
    }
    BPT_CHECK(same2, "visibility of the cow: 2 threads give the same bits as 1");
    BPT_CHECK(same3, "visibility of the cow: tasks run backwards give the same bits");
    free(v1); free(v2); free(v3);
    bp_mesh_free(&m, NULL);
}

/* The chunks of a loop: they cover [0, n) in order without gaps, none holds
   more than its size limit, their sizes differ by at most one, and, when
   there is more than one, their number is a multiple of four (so 2 and 4
   threads get equal blocks).  The vector passes' chunks hold whole xy
   pairs and are exactly the vertex chunks of the gradient gather, doubled.
   The sizes tried include camelhead's (22704 triangles, 11381 vertices),
   whose fixed 2048-item chunks once left one thread 18% more triangles. */
static void check_chunks(void)
{
    static const uint32_t ns[] = { 0, 1, 2, 3, 5, 127, 128, 129, 2047, 2048, 2049, 4096, 4097, 6000,
                                   11381, 22704, 38656, 89215, 1000003 };
    static const uint32_t sizes[] = { 128, 2048, 4096 };
    size_t a, b;
    int cover = 1, limit = 1, equal = 1, four = 1, vec = 1, count = 0;
    for (a = 0; a < sizeof ns / sizeof *ns; a++) {
        uint32_t n = ns[a], nc, c;
        for (b = 0; b < sizeof sizes / sizeof *sizes; b++) {
            uint32_t size = sizes[b], lo, hi, mn = UINT32_MAX, mx = 0;
            nc = bp__nchunks(n, size);
            if (n > 0 && nc == 0) cover = 0;
            if (nc > 1 && nc % 4) four = 0;
            if (bp__chunk_at(n, nc ? nc : 1, 0) != 0 || (nc && bp__chunk_at(n, nc, nc) != n)) cover = 0;
            for (c = 0; c < nc; c++) {
                lo = bp__chunk_at(n, nc, c);
                hi = bp__chunk_at(n, nc, c + 1);
                if (hi < lo) cover = 0;
                if (hi - lo > size) limit = 0;
                if (hi - lo < mn) mn = hi - lo;
                if (hi - lo > mx) mx = hi - lo;
            }
            if (nc && mx - mn > 1) equal = 0;
            count++;
        }
        /* a vector of 2 n coordinates against the gather's n vertices */
        {
            uint32_t nvec = bp__vec_nchunks(2 * n), nvert = bp__nchunks(n, BP__VERT_CHUNK);
            if (nvec != nvert) vec = 0;
            for (c = 0; c <= nvec && vec; c++)
                if (bp__vec_chunk_at(2 * n, nvec, c) != 2 * bp__chunk_at(n, nvert ? nvert : 1, c)) vec = 0;
        }
        /* an odd length: the last chunk takes the odd coordinate */
        nc = bp__vec_nchunks(2 * n + 1);
        if (bp__vec_chunk_at(2 * n + 1, nc, 0) != 0 || bp__vec_chunk_at(2 * n + 1, nc, nc) != 2 * n + 1 || nc == 0)
            vec = 0;
        for (c = 0; c < nc; c++)
            if (bp__vec_chunk_at(2 * n + 1, nc, c) > bp__vec_chunk_at(2 * n + 1, nc, c + 1)) vec = 0;
    }
    BPT_CHECK(cover, "chunks cover [0, n) in order (%d cases)", count);
    BPT_CHECK(limit, "no chunk holds more than its size limit");
    BPT_CHECK(equal, "chunk sizes differ by at most one");
    BPT_CHECK(four, "more than one chunk: a multiple of four of them");
    BPT_CHECK(vec, "vector chunks are the vertex chunks, doubled (odd lengths covered too)");
}

/* Groups of tasks run as one loop (bp__groups): every task of every group
   runs exactly once, including empty groups and single tasks. */
typedef struct { uint32_t *hits; } group_rec;
static group_rec recs[4];
static void rec_task(void *task, uint32_t i)
{
    ((group_rec *)task)->hits[i]++;
}
static void check_groups(void)
{
    static const uint32_t counts[][4] = { { 1, 12, 0, 0 }, { 1, 12, 1, 8 }, { 0, 44, 3, 22 }, { 5, 7, 0, 0 },
                                          { 1, 1, 1, 1 }, { 100, 3, 17, 64 }, { 2, 0, 9, 1 } };
    size_t c;
    int once = 1;
    for (c = 0; c < sizeof counts / sizeof *counts; c++) {
        bp__groups G;
        bp__par par;
        uint32_t k, i;
        memset(&G, 0, sizeof G);
        par.run = reverse_for; par.user = NULL; par.threads = 1;
        for (k = 0; k < 4; k++) {
            recs[k].hits = (uint32_t *)calloc(counts[c][k] + 1, sizeof(uint32_t));
            bp__groups_add(&G, rec_task, &recs[k], counts[c][k]);
        }
        bp__groups_run(&par, &G);
        for (k = 0; k < 4; k++) {
            for (i = 0; i < counts[c][k]; i++) if (recs[k].hits[i] != 1) once = 0;
            free(recs[k].hits);
        }
    }
    BPT_CHECK(once, "groups: every task of every group runs exactly once");
}

/* The pool: jobs of 2..97 tasks, one after the other, on pools of 2, 3
   and 8 threads; each task counts its runs atomically.  A worker that
   woke late and took a task of a later job for its own, or a caller that
   returned before the last task finished, shows as a count other than 1
   (the caller checks the counts right after each job returns). */
typedef struct stress_job { uint32_t *hits; uint32_t spin; } stress_job;
static void stress_task(void *task, uint32_t i)
{
    stress_job *J = (stress_job *)task;
    volatile uint32_t k;
    for (k = 0; k < J->spin * (i % 7); k++) {}
    __atomic_fetch_add(&J->hits[i], 1u, __ATOMIC_RELAXED);
}

static void check_pool_stress(void)
{
    static const int nthreads[] = { 2, 3, 8 };
    bp_allocator a;
    uint32_t hits[97];
    int k, jobs = quick ? 300 : 3000;
    memset(&a, 0, sizeof a);
    for (k = 0; k < 3; k++) {
        bp__pool *P = bp__pool_start(&a, nthreads[k]);
        int j, exact = 1, used = P ? P->nth + 1 : 1;
        for (j = 0; P && j < jobs; j++) {
            stress_job J;
            uint32_t count = 2 + (uint32_t)(j * 37 % 96), i;
            memset(hits, 0, sizeof hits);
            J.hits = hits;
            J.spin = (uint32_t)(j % 5) * 200;
            P->skip = 0;                 /* every job through the threads, however crowded the machine */
            bp__pool_for(P, stress_task, &J, count);
            for (i = 0; i < 97; i++)
                if (__atomic_load_n(&hits[i], __ATOMIC_ACQUIRE) != (i < count ? 1u : 0u)) exact = 0;
        }
        BPT_CHECK(P && used == nthreads[k] && exact,
                  "pool of %d threads (%d started): %d jobs, every task ran exactly once before the job returned",
                  nthreads[k], used, jobs);
        bp__pool_stop(&a, P);
    }
}

/* The pool's window (bp__pool_window, the essay on waiting in >>threads)
   sets how long a waiting thread polls.  A new pool polls short; the
   early look of its first window, in which the threads used 0.95 of a
   core each, sets the long poll and nothing else (no backoff, the window
   goes on); a window in which the two threads got (almost) no CPU time --
   a crowded machine -- sets the short poll and the backoff; one in which
   they used 0.6 of a core each sets the short poll without the backoff;
   after that an early look at 0.95 changes nothing (whole windows decide
   once one has been measured); a whole window at 0.95 sets the long poll
   again.  The windows are made up (their start moved back in time), so
   nothing here depends on how busy the test machine is. */
static void window_after(bp__pool *P, double wall, double cpu)
{
    P->wjobs = BP__WINDOW_JOBS;                 /* this loop closes the window */
    P->wwall = bp__seconds() - wall;
    P->wcpu = bp__cpu_seconds() - cpu;
    bp__pool_window(P);
}

static void early_look(bp__pool *P)            /* 0.95 of a core per thread so far */
{
    P->wjobs = BP__SPIN_WINDOW_JOBS - 1;
    P->wwall = bp__seconds() - 0.01;
    P->wcpu = bp__cpu_seconds() - 0.019;
    bp__pool_window(P);
}

static void check_pool_spin(void)
{
    bp_allocator a;
    bp__pool *P;
    uint32_t s0, se, je, s1, s2, sl, s3, k1, k2, k3;
    volatile double burn = 0;
    memset(&a, 0, sizeof a);
    while (bp__cpu_seconds() < 0.25) burn += 1;  /* a window's start must not be before the process's */
    P = bp__pool_start(&a, 2);
    if (!BPT_CHECK(P != NULL, "a pool of 2 threads")) return;
    s0 = P->spin;
    early_look(P);
    se = P->spin; je = P->wjobs;
    window_after(P, 0.1, 0.0);                  /* crowded: no CPU time in 0.1 s */
    s1 = P->spin; k1 = P->skip;
    P->skip = 0;
    window_after(P, 0.1, 0.12);                 /* 0.6 of a core per thread */
    s2 = P->spin; k2 = P->skip;
    early_look(P);
    sl = P->spin;
    window_after(P, 0.1, 0.19);                 /* 0.95 of a core per thread */
    s3 = P->spin; k3 = P->skip;
    BPT_CHECK(s0 == BP__SPIN_NS && se == BP__SPIN_LONG_NS && je == BP__SPIN_WINDOW_JOBS && s1 == BP__SPIN_NS &&
                  k1 == BP__BACKOFF_MIN && s2 == BP__SPIN_NS && k2 == 0 && sl == BP__SPIN_NS && s3 == BP__SPIN_LONG_NS &&
                  k3 == 0,
              "pool window: polls %u ns new, %u ns after the first early look at 0.95 core/thread (the window "
              "goes on: %u loops), %u ns crowded (skip %u), %u ns at 0.6 core/thread (skip %u), still %u ns after "
              "a later early look at 0.95, %u ns after a whole window at 0.95 (skip %u)",
              s0, se, je, s1, k1, s2, k2, sl, s3, k3);
    bp__pool_stop(&a, P);
}

/* The rest shapes are made in chunks of triangles on the threads
   (bp__solver_chart_par); an importance that is not positive and finite
   must still be reported at the first such triangle in the chart's order,
   not at the first one a task meets.  Camelhead (22,704 triangles: 12
   chunks of 2048, a pool even with the default thresholds): a NaN at a
   triangle of chunk 9 and a -1 at one of chunk 3; the error names the
   latter's mesh triangle, on 1, 2 and 3 threads and with the tasks run
   backwards. */
static void check_importance_error(void)
{
    static const int runs[4] = { 1, 2, 3, -1 };
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    double *imp;
    uint32_t t, ta = 9 * 2048 + 17, tb = 3 * 2048 + 5;
    int r;
    if (!BPT_CHECK(bp_read_mesh("tests/data/camelhead.off", &m, NULL, &e) == BP_OK, "read camelhead")) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, NULL, &e) == BP_OK && at.num_charts == 1 && at.charts[0].num_triangles > ta,
                   "camelhead: one chart of more than %u triangles", ta)) {
        bp_mesh_free(&m, NULL);
        return;
    }
    imp = (double *)malloc(m.num_triangles * sizeof *imp);
    for (t = 0; t < m.num_triangles; t++) imp[t] = 1;
    imp[at.charts[0].face[ta]] = strtod("nan", NULL);
    imp[at.charts[0].face[tb]] = -1;
    for (r = 0; r < 4; r++) {
        bp_options o;
        bp_status st;
        char want[128];
        memset(&o, 0, sizeof o);
        o.importance = imp;
        o.max_iterations = 1;
        if (runs[r] > 0) o.threads = runs[r];
        else o.parallel_for = reverse_for;
        memset(&e, 0, sizeof e);
        st = bp_chart_init(&at.charts[0], &m, &o, &e);
        if (st == BP_OK) st = bp_chart_optimize(&at.charts[0], 0, &m, &o, &e);
        snprintf(want, sizeof want, "importance of mesh triangle %u is -1", at.charts[0].face[tb]);
        BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && e.element == BP_ELEMENT_TRIANGLE &&
                      e.index == (int64_t)at.charts[0].face[tb] && strncmp(e.message, want, strlen(want)) == 0,
                  "importance -1 at chart triangle %u and NaN at %u, %s: the error names mesh triangle %u (%s: %s)",
                  tb, ta, runs[r] > 0 ? (runs[r] == 1 ? "1 thread" : runs[r] == 2 ? "2 threads" : "3 threads")
                                      : "tasks backwards",
                  at.charts[0].face[tb], bp_status_string(st), e.message);
    }
    free(imp);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* A mesh of n separate triangles, each its own chart (the bench's
   10,000-chart case, smaller), solved by bp_parameterize on 1, 2 and 3
   threads (charts as parallel tasks: the same bits as 1 thread), and
   chart by chart with bp_chart_init / bp_chart_optimize on 2 threads (the
   same bits as chart by chart on 1; bp_parameterize also packs). */
static int many_solve(const bp_mesh *m, int threads, int alone, double *uv)
{
    bp_options o;
    bp_atlas at;
    bp_error e;
    uint32_t c, i, k = 0;
    memset(&o, 0, sizeof o);
    o.threads = threads;
    if (!alone) {
        if (bp_parameterize(&at, m, &o, &e) != BP_OK) return 0;
    } else {
        if (bp_atlas_build(&at, m, &o, &e) != BP_OK) return 0;
        for (c = 0; c < at.num_charts; c++)
            if (bp_chart_init(&at.charts[c], m, &o, &e) != BP_OK ||
                bp_chart_optimize(&at.charts[c], c, m, &o, &e) != BP_OK) { bp_atlas_free(&at); return 0; }
    }
    for (c = 0; c < at.num_charts; c++)
        for (i = 0; i < 2 * at.charts[c].num_vertices; i++) uv[k++] = at.charts[c].uv[i];
    bp_atlas_free(&at);
    return k == 6 * m->num_triangles;
}

static void check_many_charts(void)
{
    enum { N = 500 };
    static double pos[9 * N], uv1[6 * N], uva[6 * N], uvk[6 * N];
    static uint32_t tri[3 * N];
    static const int runs[][2] = { { 2, 0 }, { 3, 0 }, { 2, 1 } };
    bp_mesh m;
    uint32_t i;
    int k;
    memset(&m, 0, sizeof m);
    for (i = 0; i < N; i++) {            /* triangle i: (2i, 0, 0), (2i + 1, i % 3, 0), (2i, 1, i % 5) */
        double x = 2.0 * i;
        double p[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
        p[0] = x; p[3] = x + 1; p[4] = i % 3; p[6] = x; p[8] = i % 5;
        memcpy(pos + 9 * i, p, sizeof p);
        tri[3 * i] = 3 * i; tri[3 * i + 1] = 3 * i + 1; tri[3 * i + 2] = 3 * i + 2;
    }
    m.positions = pos; m.num_vertices = 3 * N;
    m.triangles = tri; m.num_triangles = N;
    m.num_faces = N;
    BPT_CHECK(many_solve(&m, 1, 0, uv1) && many_solve(&m, 1, 1, uva), "%d one-triangle charts: serial solves", N);
    for (k = 0; k < 3; k++) {
        int ok = many_solve(&m, runs[k][0], runs[k][1], uvk);
        BPT_CHECK(ok && !memcmp(runs[k][1] ? uva : uv1, uvk, sizeof uv1), "%d one-triangle charts, %d threads, %s: the same bits as serial",
                  N, runs[k][0], runs[k][1] ? "bp_chart_init/optimize alone" : "bp_parameterize");
    }
}

int main(void)
{
    quick = getenv("BP_TEST_QUICK") != NULL;
    check_chunks();
    check_groups();
    check_pool_stress();
    check_pool_spin();
    check_importance_error();
    check_many_charts();
    if (quick) {
        check_mesh("tests/data/bishop_part_f1000.obj");
        check_mesh("tests/data/spot.obj");
        return bpt_finish();
    }
    check_mesh("tests/data/camel_b.obj");
    check_mesh("tests/data/face_holes.off");
    check_mesh("tests/data/spot.obj");
    check_mesh("tests/data/cow_param_withSUV.obj");
    check_mesh("tests/data/bishop_part_f1000.obj");
    start_init = BP_INIT_MEAN_VALUE;          /* its weights run beside the dissection's root split */
    check_mesh("tests/data/camel_b.obj");
    check_mesh("tests/data/face_holes.off");
    start_init = BP_INIT_AUTO;
    check_planar();
    check_visibility();
    return bpt_finish();
}
