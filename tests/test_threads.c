/* test_threads.c - the result does not depend on how the work is run.

   bijparam cuts every parallel loop into tasks whose boundaries depend only
   on the number of items, and combines their results in task order.  So a
   solve must give bit-identical maps -- and byte-identical OBJ files -- for
   1, 2, 3, 4 and 8 threads of the built-in pool (BP_USE_PTHREADS), and for
   a user parallel_for that runs the tasks in reverse order.  This is
   checked on real charts: camel_b (one chart, long boundary), face_holes
   (7 loops), spot (13 charts: solved in parallel as whole charts), the cow,
   and bishop; and on visibility (chapter 4), whose random streams are per
   triangle. */
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

int main(void)
{
    quick = getenv("BP_TEST_QUICK") != NULL;
    check_chunks();
    check_groups();
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
    check_visibility();
    return bpt_finish();
}
