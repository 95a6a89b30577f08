/* bptest.h - the smallest test framework that can fail.

   Each test program includes this file, calls BPT_CHECK / BPT_CHECKF for
   every property it proves, and ends main() with `return bpt_finish();`.
   Each check prints one line ("ok" or "FAIL" with file:line and the reason);
   bpt_finish prints the machine-read line

       BPTEST <passed> <failed>

   which tests/run_all.sh adds up into the final "N passed, M failed".
   A test program that crashes or exits without that line counts as failed. */
#ifndef BPTEST_H
#define BPTEST_H
#include <stdio.h>
#include <stdarg.h>
#include <stdint.h>
#include <string.h>
#include <stdlib.h>
#include <math.h>

static int bpt__passed = 0, bpt__failed = 0;

static int bpt__report(int ok, const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    if (ok) bpt__passed++; else bpt__failed++;
    printf("%s %s:%d: ", ok ? "ok  " : "FAIL", file, line);
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf("\n");
    fflush(stdout);
    return ok;
}

/* BPT_CHECK(cond, "what is being proven") */
#define BPT_CHECK(cond, ...) bpt__report(!!(cond), __FILE__, __LINE__, __VA_ARGS__)

/* Seeded xorshift64* random numbers (tests never use rand()); a test sets
   bpt_rng_state to its own seed at the start of main. */
static uint64_t bpt_rng_state = 0x9E3779B97F4A7C15ull;
static inline uint64_t bpt_rng_u64(void)
{
    bpt_rng_state ^= bpt_rng_state >> 12;
    bpt_rng_state ^= bpt_rng_state << 25;
    bpt_rng_state ^= bpt_rng_state >> 27;
    return bpt_rng_state * 2685821657736338717ull;
}
static inline double bpt_rng_unit(void) { return (double)(bpt_rng_u64() >> 11) * (1.0 / 9007199254740992.0); }
static inline double bpt_rng_range(double a, double b) { return a + (b - a) * bpt_rng_unit(); }

/* The decimal number n appears in msg as a whole number (error messages
   must name the element). */
static inline int bpt_has_number(const char *msg, long long n)
{
    char num[32];
    size_t k;
    const char *p = msg;
    sprintf(num, "%lld", n);
    k = strlen(num);
    while ((p = strstr(p, num)) != NULL) {
        int before = p > msg && p[-1] >= '0' && p[-1] <= '9';
        int after = p[k] >= '0' && p[k] <= '9';
        if (!before && !after) return 1;
        p++;
    }
    return 0;
}

/* An in-memory mesh whose arrays the test owns (free with bpt_mesh_free,
   which also frees corner_uv and uvs when the test set them with malloc). */
static inline bp_mesh bpt_mesh_new(uint32_t nv, uint32_t nt)
{
    bp_mesh m;
    memset(&m, 0, sizeof m);
    m.num_vertices = nv;
    m.num_triangles = nt;
    m.num_faces = nt;
    m.positions = (double *)calloc(3 * (size_t)nv + 1, sizeof(double));
    m.triangles = (uint32_t *)calloc(3 * (size_t)nt + 1, sizeof(uint32_t));
    return m;
}

static inline void bpt_mesh_free(bp_mesh *m)
{
    free(m->positions);
    free(m->triangles);
    free(m->corner_uv);
    free(m->uvs);
    memset(m, 0, sizeof *m);
}

#ifndef BP_NO_STDIO
/* Read a mesh that must be one chart, build its atlas and, with init, its
   start map; on failure report it, free what was made and return 0. */
static inline int bpt_one_chart(const char *path, bp_mesh *mesh, bp_atlas *atlas, const bp_options *opt, int init)
{
    bp_error err;
    if (!BPT_CHECK(bp_read_obj(path, mesh, NULL, &err) == BP_OK, "read %s: %s", path, err.message)) return 0;
    if (!BPT_CHECK(bp_atlas_build(atlas, mesh, opt, &err) == BP_OK, "%s: atlas: %s", path, err.message)) {
        bp_mesh_free(mesh, NULL);
        return 0;
    }
    if (!BPT_CHECK(atlas->num_charts == 1, "%s: one chart (%u)", path, (unsigned)atlas->num_charts) ||
        (init && !BPT_CHECK(bp_chart_init(&atlas->charts[0], mesh, opt, &err) == BP_OK, "%s: start map: %s", path,
                            err.message))) {
        bp_atlas_free(atlas);
        bp_mesh_free(mesh, NULL);
        return 0;
    }
    return 1;
}
#endif

/* A 3D triangle (p0, p1, p2) in its own frame, the test's own rest shape:
   p0 at the origin, p1 at (w, 0), p2 at (x, y), y >= 0; returns its area. */
static inline double bpt_tri_frame(const double *p0, const double *p1, const double *p2, double *w, double *x,
                                   double *y)
{
    double e1[3], e2[3], c[3], a2;
    int k;
    for (k = 0; k < 3; k++) { e1[k] = p1[k] - p0[k]; e2[k] = p2[k] - p0[k]; }
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    a2 = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    *w = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    *x = (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / *w;
    *y = a2 / *w;
    return 0.5 * a2;
}

/* Mesh b appended to a (b moved by dx along x), without vt. */
static inline bp_mesh bpt_concat(const bp_mesh *a, const bp_mesh *b, double dx)
{
    bp_mesh m = bpt_mesh_new(a->num_vertices + b->num_vertices, a->num_triangles + b->num_triangles);
    uint32_t i;
    memcpy(m.positions, a->positions, 3 * a->num_vertices * sizeof(double));
    memcpy(m.triangles, a->triangles, 3 * a->num_triangles * sizeof(uint32_t));
    for (i = 0; i < 3 * b->num_vertices; i++) m.positions[3 * a->num_vertices + i] = b->positions[i] + (i % 3 ? 0 : dx);
    for (i = 0; i < 3 * b->num_triangles; i++) m.triangles[3 * a->num_triangles + i] = b->triangles[i] + a->num_vertices;
    return m;
}

/* An allocator that counts its calls and fails call number fail_at (0:
   never), and counts the blocks alive, for out-of-memory sweeps: set
   bp_allocator { bpt_oom_alloc, bpt_oom_free, &counter }. */
typedef struct bpt_oom { long calls, fail_at, live; } bpt_oom;

static inline void *bpt_oom_alloc(void *user, size_t size)
{
    bpt_oom *o = (bpt_oom *)user;
    void *p;
    o->calls++;
    if (o->fail_at && o->calls == o->fail_at) return NULL;
    p = malloc(size);
    if (p) o->live++;
    return p;
}

static inline void bpt_oom_free(void *user, void *p)
{
    bpt_oom *o = (bpt_oom *)user;
    if (p) { o->live--; free(p); }
}

/* Zero the counter and make it the options' allocator. */
static inline void bpt_oom_use(bp_options *opt, bpt_oom *counter)
{
    memset(counter, 0, sizeof *counter);
    opt->allocator.alloc = bpt_oom_alloc;
    opt->allocator.free = bpt_oom_free;
    opt->allocator.user = counter;
}

/* Painted importance for steering tests: 25 on the triangles whose
   centroid lies in the upper half of the x range, 1 elsewhere (malloc). */
static inline double *bpt_half_importance(const bp_mesh *m)
{
    double *w = (double *)malloc(m->num_triangles * sizeof(double)), lo = 1e300, hi = -1e300;
    uint32_t t, v;
    for (v = 0; v < m->num_vertices; v++) {
        if (m->positions[3 * v] < lo) lo = m->positions[3 * v];
        if (m->positions[3 * v] > hi) hi = m->positions[3 * v];
    }
    for (t = 0; w && t < m->num_triangles; t++) {
        const uint32_t *q = m->triangles + 3 * t;
        double x = (m->positions[3 * q[0]] + m->positions[3 * q[1]] + m->positions[3 * q[2]]) / 3;
        w[t] = x > (lo + hi) / 2 ? 25 : 1;
    }
    return w;
}

#ifdef BP__IMPLEMENTATION_DONE
/* For tests that build a bp__solver by hand over bare polygons: allocate
   its workspace with bp__solver_init, keeping the fields the test set
   (including its own rest shapes, which bpt_solver_free leaves to it). */
static inline void bpt_solver_workspace(bp__solver *S, uint32_t nloop_v)
{
    static const bp_allocator plain = { NULL, NULL, NULL };
    bp__solver keep = *S;
    (void)nloop_v;
    bp__solver_init(S, keep.a ? keep.a : &plain, keep.nv, keep.nt, keep.tri, keep.nloops, keep.loop_start,
                    keep.loop_vertices);
    bp__free(S->a, S->rest);
    S->rest = keep.rest;
    S->energy = keep.energy; S->barrier = keep.barrier; S->eps = keep.eps; S->mean_edge = keep.mean_edge;
}

/* Task orders a thread pool could produce, for determinism tests. */
static inline void bpt_backwards_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    (void)user;
    while (count--) fn(task, count);
}

static inline void bpt_odd_even_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    for (i = 1; i < count; i += 2) fn(task, i);
    for (i = 0; i < count; i += 2) fn(task, i);
}

static inline void bpt_solver_free(bp__solver *S)
{
    S->rest = NULL;           /* the test frees its rest shapes itself */
    bp__solver_free(S);
}

/* E_B alone at x (gradient added to g when given), as the solver's
   evaluation computes it: the points into the hash, then the edge chunks,
   then their sums and records in chunk order. */
static inline double bpt_barrier(bp__solver *S, const double *x, double *g)
{
    bp__eval_task T;
    memset(&T, 0, sizeof T);
    T.S = S;
    T.x = x;
    T.g = g;
    bp__hash_fill(S, x, NULL, 0);
    S->par.run(S->par.user, bp__barrier_task, &T, S->nchunk_b);
    return bp__barrier_finish(S, g);
}
#endif

static int bpt_finish(void)
{
    printf("BPTEST %d %d\n", bpt__passed, bpt__failed);
    return bpt__failed ? 1 : 0;
}
/* The squared diagonal of the mesh's bounding box (the scale the
   library's relative degeneracy test is measured against). */
static inline double bpt_bbox_diag2(const bp_mesh *m)
{
    double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL }, d = 0;
    uint32_t v;
    int k;
    for (v = 0; v < m->num_vertices; v++)
        for (k = 0; k < 3; k++) {
            if (m->positions[3 * v + k] < lo[k]) lo[k] = m->positions[3 * v + k];
            if (m->positions[3 * v + k] > hi[k]) hi[k] = m->positions[3 * v + k];
        }
    for (k = 0; k < 3; k++) d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return d;
}

#endif
