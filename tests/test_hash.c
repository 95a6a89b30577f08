/* test_hash.c - the spatial hash of fig 3.6 and the barrier sum it feeds.

   The barrier E_B and the step bound only ever look at what the hash
   returns, so a lost item is a lost barrier term or a missed collision.

     (a) bp__hash_build / bp__hash_query against brute force on random boxes
         (points, small boxes, boxes spanning many cells, negative
         coordinates), random cell sizes and table sizes (tiny tables force
         collisions): the query returns EXACTLY the items having a cell whose
         bucket is the bucket of one of the query's cells (or every item when
         the query covers more than twice the table), hence at least every
         item whose cells meet the query's cells and every item whose box
         overlaps the query box; each item once.  Also across the stamp
         wrap-around, and build refusing a too-small capacity.  Also with
         the small groups left out of the table (scan_max): their queries
         scan them and must answer the same.
     (b) E_B through the hash (bpt_barrier) equals a brute-force O(n^2) sum written here
         (each loop, each edge, each vertex of the same loop not on the edge,
         max(0, eps/dist - 1)^2) to 1e-12 relative, gradient included, on
         jittered polygons and on the 7 real loops of face_holes.off (start
         map and partly optimized), for eps from tiny to larger than the
         chart; each case three times: small loops scanned (the solver's
         default, BP__SCAN_MAX), every loop in the table, every loop
         scanned.
     (c) The step bound's swept hash, built by parallel count and place
         tasks, is the table of the serial bp__hash_build (same bucket
         offsets, same items in the same order) under three task orders, on
         the real charts of face_holes (7 loops) and camelhead, for random
         directions and sweep times that force the cells to grow; with every
         loop in the table, and with the small loops scanned (not entered).
     (d) The linear-time sorts of the chart builder (a counting sort by
         the smallest vertex in record order, then each bucket by
         insertion on the rest of the key, or qsort above 32) put corner
         edges and triangle keys in exactly qsort's order, for few vertices
         (large buckets, one vertex of very high valence) and many (small
         ones).  (The exact check's sort of the directed edges is tested
         in test_check.) */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

/* ---- (a) the hash ------------------------------------------------------------ */

typedef struct visit_log { uint32_t *count; uint32_t n; } visit_log;

static void log_visit(void *user, uint32_t item)
{
    visit_log *L = (visit_log *)user;
    if (item < L->n) L->count[item]++;
    else L->count[L->n]++;          /* out of range: counted in a spare slot */
}

static int64_t cell(double x, double h) { return (int64_t)floor(x / h); }

/* Items fall in 1-3 groups (the loops of a chart, each with its own cell
   size, all in one table).  A query for group g must report exactly the
   items of g whose box overlaps the query box (closed boxes), each once. */
static void test_hash(void)
{
    int round, bad_exact = 0, bad_repeat = 0, bad_range = 0, queries = 0, fallback = 0, bad_cap = 0, scanned_groups = 0;
    long returned_total = 0, overlap_total = 0;
    for (round = 0; round < 300; round++) {
        uint32_t n = 1 + (uint32_t)(bpt_rng_unit() * (round % 3 == 0 ? 40 : 600)), i, q, ng = 1 + (uint32_t)(bpt_rng_unit() * 3);
        uint32_t mask = (1u << (1 + (int)(bpt_rng_unit() * 11))) - 1;   /* 2 .. 4096 buckets */
        double hs[3], *box = (double *)malloc(4 * n * sizeof(double));
        uint32_t *group = (uint32_t *)malloc(n * sizeof(uint32_t)), gstart[4];
        size_t need = 0;
        bp__hash H;
        visit_log L;
        for (i = 0; i < 3; i++) hs[i] = exp(bpt_rng_range(log(0.01), log(1.0)));
        /* items sorted by group, as boundary positions are by loop */
        for (i = 0; i <= ng; i++) gstart[i] = (uint32_t)((uint64_t)n * i / ng);
        for (q = 0; q < ng; q++)
            for (i = gstart[q]; i < gstart[q + 1]; i++) group[i] = q;
        for (i = 0; i < n; i++) {
            double h = hs[group[i]], cx = bpt_rng_range(-3, 3), cy = bpt_rng_range(-3, 3), wx, wy;
            int kind = (int)(bpt_rng_unit() * 3);
            wx = kind == 0 ? 0 : kind == 1 ? bpt_rng_range(0, h) : bpt_rng_range(0, 8 * h);
            wy = kind == 0 ? 0 : kind == 1 ? bpt_rng_range(0, h) : bpt_rng_range(0, 8 * h);
            box[4 * i] = cx; box[4 * i + 1] = cy; box[4 * i + 2] = cx + wx; box[4 * i + 3] = cy + wy;
            need += (size_t)(cell(cx + wx, h) - cell(cx, h) + 1) * (size_t)(cell(cy + wy, h) - cell(cy, h) + 1);
        }
        memset(&H, 0, sizeof H);
        H.mask = mask;
        H.start = (uint32_t *)calloc((size_t)mask + 2, sizeof(uint32_t));
        H.box = box;
        H.group = group;
        H.group_start = gstart;
        H.h = hs;
        H.cell0 = (int64_t *)malloc(2 * (size_t)n * sizeof(int64_t));
        /* capacity: one short must be refused, exact must be accepted */
        H.cap = need - 1;
        H.items = (uint32_t *)calloc(need + 1, sizeof(uint32_t));
        if (need > 0 && bp__hash_build(&H, n)) bad_cap++;
        H.cap = need;
        if (!bp__hash_build(&H, n)) bad_cap++;
        if (round % 4 == 1) {
            /* groups of at most scan_max items left out of the table: their
               queries scan them (the solver's small loops, >>barrier) */
            H.scan_max = (uint32_t)(bpt_rng_unit() * n);
            if (!bp__hash_build(&H, n)) bad_cap++;
            for (q = 0; q < ng; q++) scanned_groups += gstart[q + 1] - gstart[q] <= H.scan_max;
        }
        L.n = n;
        L.count = (uint32_t *)calloc(n + 1, sizeof(uint32_t));
        for (q = 0; q < 40; q++) {
            uint32_t g = (uint32_t)(bpt_rng_unit() * ng);
            double h = hs[g], qx = bpt_rng_range(-4, 4), qy = bpt_rng_range(-4, 4), qw, qh;
            int big = q % 13 == 12;
            qw = big ? bpt_rng_range(3, 8) : bpt_rng_range(0, 3 * h);
            qh = big ? bpt_rng_range(3, 8) : bpt_rng_range(0, 3 * h);
            if (q % 7 == 3 && n > 0) {        /* a query box that touches an item's box exactly */
                uint32_t j = gstart[g] + (uint32_t)(bpt_rng_unit() * (gstart[g + 1] - gstart[g]));
                if (j < gstart[g + 1]) { qx = box[4 * j + 2]; qy = box[4 * j + 3]; }
            }
            memset(L.count, 0, (n + 1) * sizeof(uint32_t));
            bp__hash_query(&H, g, qx, qy, qx + qw, qy + qh, log_visit, &L);
            queries++;
            if ((double)(cell(qx + qw, h) - cell(qx, h) + 1) * (double)(cell(qy + qh, h) - cell(qy, h) + 1) > 2.0 * (mask + 1))
                fallback++;
            if (L.count[n]) bad_range++;
            for (i = 0; i < n; i++) {
                const double *b = box + 4 * i;
                int geo = group[i] == g && !(b[2] < qx || b[0] > qx + qw || b[3] < qy || b[1] > qy + qh);
                if (L.count[i] > 1) bad_repeat++;
                if ((L.count[i] != 0) != geo) bad_exact++;
                if (L.count[i]) returned_total++;
                if (geo) overlap_total++;
            }
        }
        free(L.count); free(box); free(group); free(H.start); free(H.items); free(H.cell0);
    }
    BPT_CHECK(bad_cap == 0, "bp__hash_build refuses capacity one below the cell count and accepts the exact count (300 tables)");
    BPT_CHECK(bad_range == 0, "bp__hash_query never reports an item index out of range");
    BPT_CHECK(bad_repeat == 0, "bp__hash_query reports every item at most once (%d queries)", queries);
    BPT_CHECK(bad_exact == 0 && overlap_total > 1000 && scanned_groups > 20,
              "bp__hash_query returns exactly the items of the queried loop whose box overlaps the query box "
              "(%d queries, %d whole-loop fallbacks, %d groups scanned instead of entered, %ld overlaps, %ld returned)",
              queries, fallback, scanned_groups, overlap_total, returned_total);
}

/* ---- (b) the barrier sum -------------------------------------------------------- */



/* The brute force, written from sec 3.3: for each loop, each edge (a, b),
   each vertex p of the same loop not on the edge, max(0, eps/dist - 1)^2,
   and its gradient (dist = |p - c|, c the closest point of the segment). */
static double brute_barrier(uint32_t nloops, const uint32_t *ls, const uint32_t *lv, const double *x, double eps,
                            double *g, uint32_t *pairs_in)
{
    double total = 0;
    uint32_t L;
    *pairs_in = 0;
    for (L = 0; L < nloops; L++) {
        uint32_t s0 = ls[L], n = ls[L + 1] - s0, e, k;
        for (e = 0; e < n; e++) {
            uint32_t va = lv[s0 + e], vb = lv[s0 + (e + 1) % n];
            const double *a = x + 2 * va, *b = x + 2 * vb;
            for (k = 0; k < n; k++) {
                uint32_t vp;
                const double *p;
                double ex, ey, l2, s, dx, dy, d, r;
                if (k == e || k == (e + 1) % n) continue;
                vp = lv[s0 + k];
                p = x + 2 * vp;
                ex = b[0] - a[0]; ey = b[1] - a[1];
                l2 = ex * ex + ey * ey;
                s = l2 > 0 ? ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / l2 : 0;
                s = s < 0 ? 0 : s > 1 ? 1 : s;
                dx = p[0] - (a[0] + s * ex); dy = p[1] - (a[1] + s * ey);
                d = sqrt(dx * dx + dy * dy);
                if (d >= eps) continue;
                (*pairs_in)++;
                if (d == 0) return HUGE_VAL;
                r = eps / d - 1;
                total += r * r;
                if (g) {
                    double c = -2 * r * eps / (d * d * d);      /* dE/dd / d */
                    g[2 * vp] += c * dx; g[2 * vp + 1] += c * dy;
                    g[2 * va] -= c * (1 - s) * dx; g[2 * va + 1] -= c * (1 - s) * dy;
                    g[2 * vb] -= c * s * dx; g[2 * vb + 1] -= c * s * dy;
                }
            }
        }
    }
    return total;
}

typedef struct cmp_stats { int cases, bad, bad_g, nonzero, tabled, scanned; double worst, worst_g; long pairs; } cmp_stats;

static void compare_barrier(uint32_t nloops, const uint32_t *ls, const uint32_t *lv, uint32_t nv, const double *x,
                            double eps, cmp_stats *st)
{
    bp__solver S;
    bp_allocator a;
    double *g1 = (double *)calloc(2 * nv, sizeof(double)), *g2 = (double *)calloc(2 * nv, sizeof(double)), f1, f2, f3, gmax = 0;
    uint32_t pairs, i;
    int mode;
    memset(&S, 0, sizeof S);
    memset(&a, 0, sizeof a);
    S.a = &a;
    S.nv = nv;
    S.nloops = nloops;
    S.loop_start = ls;
    S.loop_vertices = lv;
    S.nb = ls[nloops];
    S.barrier = 1;
    S.eps = eps;
    bpt_solver_workspace(&S, S.nb);
    f2 = brute_barrier(nloops, ls, lv, x, eps, g2, &pairs);
    for (i = 0; i < 2 * nv; i++) if (fabs(g2[i]) > gmax) gmax = fabs(g2[i]);
    for (mode = 0; mode < 3; mode++) {
        /* small loops scanned (the default), none scanned, all scanned */
        bp__hash_set_scan(&S.hash, nloops, mode == 0 ? BP__SCAN_MAX : mode == 1 ? 0 : 0xffffffffu);
        if (mode == 0) {
            if (S.hash.entered) st->tabled++;
            if (S.hash.entered < S.nb) st->scanned++;
        }
        memset(g1, 0, 2 * nv * sizeof(double));
        f1 = bpt_barrier(&S, x, g1);
        f3 = bpt_barrier(&S, x, NULL);
        st->cases++;
        st->pairs += pairs;
        if (f2 > 0) st->nonzero++;
        if (!(fabs(f1 - f2) <= 1e-12 * f2) && !(f1 == f2) ) st->bad++;
        if (f1 != f3) st->bad++;
        if (f2 > 0 && fabs(f1 - f2) / f2 > st->worst) st->worst = fabs(f1 - f2) / f2;
        for (i = 0; i < 2 * nv; i++) {
            double e = fabs(g1[i] - g2[i]) / (gmax > 0 ? gmax : 1);
            if (e > st->worst_g) st->worst_g = e;
            if (!(e <= 1e-12)) st->bad_g++;
        }
    }
    bpt_solver_free(&S);
    free(g1); free(g2);
}

static void test_barrier_polygons(void)
{
    cmp_stats st;
    int rep;
    double eps_list[6] = { 0.005, 0.05, 0.2, 0.6, 2.5, 20 };
    memset(&st, 0, sizeof st);
    for (rep = 0; rep < 120; rep++) {
        uint32_t n = 10 + (uint32_t)(bpt_rng_unit() * 150), nh = rep % 3 == 0 ? 5 + (uint32_t)(bpt_rng_unit() * 30) : 0, N = n + nh, i;
        uint32_t ls[3], *lv = (uint32_t *)malloc(N * sizeof(uint32_t));
        double *x = (double *)malloc(2 * N * sizeof(double));
        int kind = rep % 3, e;
        for (i = 0; i < n; i++) {
            double th = 2 * PI * (i + bpt_rng_range(-0.3, 0.3)) / n, r = 1 + bpt_rng_range(-0.05, 0.05);
            if (kind == 1) { x[2 * i] = r * cos(th); x[2 * i + 1] = 0.1 * r * sin(th); }
            else if (kind == 2) { r *= 1 + 0.4 * cos(5 * th); x[2 * i] = r * cos(th); x[2 * i + 1] = r * sin(th); }
            else { x[2 * i] = r * cos(th); x[2 * i + 1] = r * sin(th); }
        }
        for (i = 0; i < nh; i++) {
            double th = -2 * PI * i / nh;
            x[2 * (n + i)] = 0.15 * cos(th);
            x[2 * (n + i) + 1] = 0.15 * sin(th);
        }
        /* vertex numbering shuffled: loop order != index order */
        for (i = 0; i < N; i++) lv[i] = i;
        for (i = N - 1; i > 0; i--) {
            uint32_t j = (uint32_t)(bpt_rng_unit() * (i + 1)), t = lv[i];
            double tx = x[2 * i], ty = x[2 * i + 1];
            lv[i] = lv[j]; lv[j] = t;
            (void)tx; (void)ty;
        }
        {
            /* lv[k] is the vertex at loop position k: move the coordinates so
               position k keeps its geometry */
            double *y = (double *)malloc(2 * N * sizeof(double));
            for (i = 0; i < N; i++) { y[2 * lv[i]] = x[2 * i]; y[2 * lv[i] + 1] = x[2 * i + 1]; }
            memcpy(x, y, 2 * N * sizeof(double));
            free(y);
        }
        ls[0] = 0; ls[1] = n; ls[2] = N;
        for (e = 0; e < 6; e++) compare_barrier(nh ? 2 : 1, ls, lv, N, x, eps_list[e], &st);
        free(lv); free(x);
    }
    BPT_CHECK(st.bad == 0 && st.tabled > 50 && st.scanned > 50,
              "E_B (hash) == brute-force O(n^2) sum to 1e-12 on %d polygon/eps cases (eps 0.005 .. 20 "
              "on unit-size loops, %d nonzero, %ld pairs inside eps; by default %d with a loop in the table, %d with one "
              "scanned), worst rel %.3g", st.cases, st.nonzero, st.pairs, st.tabled, st.scanned, st.worst);
    BPT_CHECK(st.bad_g == 0, "E_B gradient (hash) == brute-force gradient to 1e-12 of max |g| (worst %.3g)", st.worst_g);
}

static void test_barrier_face_holes(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    cmp_stats st;
    int phase;
    memset(&opt, 0, sizeof opt);
    memset(&st, 0, sizeof st);
    if (!BPT_CHECK(bp_read_off("tests/data/face_holes.off", &mesh, NULL, &err) == BP_OK, "read face_holes: %s", err.message))
        return;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK && atlas.num_charts == 1 &&
                   atlas.charts[0].num_loops == 7, "face_holes: one chart with 7 loops")) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    BPT_CHECK(bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) == BP_OK, "face_holes start map: %s", err.message);
    for (phase = 0; phase < 2; phase++) {
        bp_chart *ch = &atlas.charts[0];
        double mean = 0, mult[6] = { 0.25, 1, 3, 10, 50, 400 };
        uint32_t k, nb = ch->loop_start[ch->num_loops], L;
        int e;
        if (phase == 1) {
            opt.max_iterations = 15;
            bp_chart_optimize(ch, 0, &mesh, &opt, &err);
        }
        for (L = 0; L < ch->num_loops; L++) {
            uint32_t s0 = ch->loop_start[L], n = ch->loop_start[L + 1] - s0;
            for (k = 0; k < n; k++) {
                const double *p = ch->uv + 2 * ch->loop_vertices[s0 + k], *q = ch->uv + 2 * ch->loop_vertices[s0 + (k + 1) % n];
                mean += sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1])) / nb;
            }
        }
        for (e = 0; e < 6; e++)
            compare_barrier(ch->num_loops, ch->loop_start, ch->loop_vertices, ch->num_vertices, ch->uv, mult[e] * mean, &st);
    }
    BPT_CHECK(st.bad == 0 && st.nonzero >= 8, "face_holes (7 loops, start and optimized maps, eps 0.25 .. 400 mean uv "
              "boundary edges): E_B (hash) == brute force to 1e-12 (%d cases, %d nonzero, %ld pairs inside eps, worst rel %.3g)",
              st.cases, st.nonzero, st.pairs, st.worst);
    BPT_CHECK(st.bad_g == 0, "face_holes: barrier gradient == brute force to 1e-12 of max |g| (worst %.3g)", st.worst_g);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

static void test_swept_hash(const char *path)
{
    static const bp_parallel_for_fn orders[3] = { bp__serial_for, bpt_backwards_for, bpt_odd_even_for };
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_allocator a = bp__allocator_of(NULL);
    bp__solver S;
    double *v, *box, sweeps[4] = { 0, 0.3, 3, 300 };
    uint32_t *start, *items, i, nb, bad = 0, cases = 0, grown = 0, scanned_only = 0;
    int k, r, o, scan;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_read_mesh(path, &mesh, NULL, &err) == BP_OK, "read %s: %s", path, err.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK &&
                   bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) == BP_OK, "%s: start map", path)) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    bp__solver_chart(&S, &a, &atlas.charts[0], &mesh, &opt, NULL, &err);
    nb = S.nb;
    v = (double *)malloc(2 * sizeof(double) * S.nv);
    start = (uint32_t *)malloc(((size_t)S.hash.mask + 2) * sizeof(uint32_t));
    items = (uint32_t *)malloc(S.hash.cap * sizeof(uint32_t));
    box = (double *)malloc(4 * (size_t)nb * sizeof(double));
    for (scan = 0; scan < 2; scan++) {
    /* scan 0: every loop in the table; 1: the solver's default, small loops
       scanned (not entered; camelhead's one loop of 56 is then not hashed at
       all, and the two builds must still agree on the boxes) */
    bp__hash_set_scan(&S.hash, S.nloops, scan ? BP__SCAN_MAX : 0);
    for (r = 0; r < 3; r++)
        for (k = 0; k < 4; k++) {
            double h0;
            for (i = 0; i < 2 * S.nv; i++) v[i] = bpt_rng_range(-1, 1) * S.mean_edge;
            memset(S.box, 0, 4 * (size_t)nb * sizeof(double));
            bp__hash_fill(&S, atlas.charts[0].uv, v, sweeps[k]);          /* serial reference */
            memcpy(start, S.hash.start, ((size_t)S.hash.mask + 2) * sizeof(uint32_t));
            memcpy(items, S.hash.items, S.hash.start[S.hash.mask + 1] * sizeof(uint32_t));
            memcpy(box, S.box, 4 * (size_t)nb * sizeof(double));
            h0 = S.hs[0];
            if (!scan && h0 > bp__loop_cell(&S, atlas.charts[0].uv, 0)) grown++;
            for (o = 0; o < 3; o++) {
                S.par.run = orders[o];
                memset(S.hash.items, 0xff, S.hash.cap * sizeof(uint32_t));
                memset(S.box, 0, 4 * (size_t)nb * sizeof(double));
                bp__step_hash(&S, atlas.charts[0].uv, v, sweeps[k]);
                cases++;
                if (S.hash.entered == 0) scanned_only++;
                if (S.hs[0] != h0 || memcmp(box, S.box, 4 * (size_t)nb * sizeof(double)) ||
                    (S.hash.entered && (memcmp(start, S.hash.start, ((size_t)S.hash.mask + 2) * sizeof(uint32_t)) ||
                                        memcmp(items, S.hash.items, start[S.hash.mask + 1] * sizeof(uint32_t)))))
                    bad++;
            }
            S.par.run = bp__serial_for;
        }
    }
    BPT_CHECK(bad == 0 && grown > 0, "%s (%u boundary vertices): the parallel swept hash equals the serial build in %u of "
              "%u cases (3 task orders, all loops in the table or the small ones scanned, same swept boxes; %u with grown "
              "cells, %u with no table at all)", path, nb, cases - bad, cases, grown, scanned_only);
    free(v); free(start); free(items); free(box);
    bp__solver_free(&S);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* The builder's counting sort (bp__sort_edges, bp__find_duplicates): the
   records placed in their bucket of the smallest vertex in the order they
   come (corner edge or triangle order, increasing), then each bucket
   sorted by the rest of the key. */
static void bucket_sort_edges(bp__edge_rec *e, bp__edge_rec *out, uint32_t n, uint32_t nv, uint32_t *start)
{
    uint32_t i, v;
    memset(start, 0, ((size_t)nv + 2) * sizeof *start);
    for (i = 0; i < n; i++) start[e[i].lo + 2]++;
    bp__bucket_offsets(start, nv);
    for (i = 0; i < n; i++) out[start[e[i].lo + 1]++] = e[i];
    for (v = 0; v < nv; v++) bp__edge_recs_sort(out + start[v], start[v + 1] - start[v]);
}

static void bucket_sort_keys(bp__tri_key *t, bp__tri_key *out, uint32_t n, uint32_t nv, uint32_t *start)
{
    uint32_t i, v;
    memset(start, 0, ((size_t)nv + 2) * sizeof *start);
    for (i = 0; i < n; i++) start[t[i].v[0] + 2]++;
    bp__bucket_offsets(start, nv);
    for (i = 0; i < n; i++) out[start[t[i].v[0] + 1]++] = t[i];
    for (v = 0; v < nv; v++) bp__tri_keys_sort(out + start[v], start[v + 1] - start[v]);
}

static void test_bucket_sort(void)
{
    static const uint32_t nvs[] = { 1, 3, 40, 1000, 100000 };
    size_t c, k;
    int same_e = 1, same_t = 1, big = 0;
    for (c = 0; c < sizeof nvs / sizeof *nvs; c++) {
        uint32_t nv = nvs[c], n = 3000, i;
        bp__edge_rec *e = (bp__edge_rec *)malloc(n * sizeof *e), *e2 = (bp__edge_rec *)malloc(n * sizeof *e), *te = (bp__edge_rec *)malloc(n * sizeof *e);
        bp__tri_key *t = (bp__tri_key *)malloc(n * sizeof *t), *t2 = (bp__tri_key *)malloc(n * sizeof *t), *tt = (bp__tri_key *)malloc(n * sizeof *t);
        uint32_t *start = (uint32_t *)malloc(((size_t)nv + 2) * sizeof(uint32_t)), *cnt = (uint32_t *)calloc(nv, sizeof(uint32_t));
        for (i = 0; i < n; i++) {
            uint32_t a = (uint32_t)(bpt_rng_u64() % nv), b = (uint32_t)(bpt_rng_u64() % nv), x = (uint32_t)(bpt_rng_u64() % nv);
            if (i % 5 == 0) a = 0;                        /* a vertex of high valence */
            e[i].lo = a < b ? a : b; e[i].hi = a < b ? b : a;
            e[i].ce = 3 * i + (uint32_t)(bpt_rng_u64() % 3);          /* unique and increasing, as placed */
            t[i].v[0] = a < b ? (a < x ? a : x) : (b < x ? b : x); t[i].v[1] = b; t[i].v[2] = x; t[i].t = i;
            cnt[e[i].lo]++;
        }
        for (k = 0; k < nv; k++) if (cnt[k] > 32) big = 1;
        memcpy(e2, e, n * sizeof *e); memcpy(t2, t, n * sizeof *t);
        qsort(e2, n, sizeof *e2, bp__edge_cmp);
        qsort(t2, n, sizeof *t2, bp__tri_key_cmp);
        bucket_sort_edges(e, te, n, nv, start);
        bucket_sort_keys(t, tt, n, nv, start);
        if (memcmp(te, e2, n * sizeof *e)) same_e = 0;
        if (memcmp(tt, t2, n * sizeof *t)) same_t = 0;
        free(e); free(e2); free(te); free(t); free(t2); free(tt); free(start); free(cnt);
    }
    BPT_CHECK(big, "bucket sort: some bucket holds more than 32 records (the qsort branch ran)");
    BPT_CHECK(same_e, "the builder's bucket sort: corner edges in qsort's order (1 to 100000 vertices)");
    BPT_CHECK(same_t, "the builder's bucket sort: triangle keys in qsort's order");
    /* bp_check's sort of the directed edges (bp__check_par's key ranges)
       is tested against qsort's order in test_check */
}

int main(void)
{
    bpt_rng_state = 0x2545F4914F6CDD1Dull;
    test_hash();
    test_barrier_polygons();
    test_barrier_face_holes();
    test_swept_hash("tests/data/face_holes.off");
    test_swept_hash("tests/data/camelhead.off");
    test_bucket_sort();
    return bpt_finish();
}
