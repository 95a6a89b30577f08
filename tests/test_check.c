/* test_check.c - bp_check against an independent brute force.

   The brute force knows nothing of boundary loops, winding numbers or
   grids.  A map of a triangulation is bijective when (1) the triangles
   form an oriented manifold (each directed edge once, each undirected edge
   at most twice), (2) every coordinate is finite and every triangle is
   positive (exact orient2d), (3) no boundary vertex is pinched (bp_check's
   documented choice: two boundary edges leaving one vertex are refused),
   and (4) every pair of triangles meets exactly in the face they share:
   disjoint closed triangles when they share nothing, only the vertex when
   they share one, opposite sides of the edge when they share two.  (4) is
   decided exactly with separating edge lines (two convex polygons have
   disjoint interiors iff one's edge line weakly separates them, disjoint
   closures iff one strictly does) and exact segment tests.

   Thousands of random small layouts, valid and invalid, are compared:
   grids with holes, pieces placed at random (inside holes: valid; on a
   piece: nested), moved vertices, vertices snapped onto others, reversed
   and duplicated triangles, a third triangle on an edge.  Coordinates on a
   coarse lattice make exact touching common.  The grid-free test of (b)
   that the line search uses on small charts counts the same pairs as the
   grid (conflict_scan_agreement). */
#define BP_IMPLEMENTATION
#define BP_USE_PTHREADS
#define BP__CHECK_CHUNK 16u          /* many chunks and key ranges on small */
#define BP__CHECK_RANGE_SHIFT 2u     /* layouts, every loop on the runners  */
#define BP__PAR_MIN_ITEMS 1u         /* (see par_random)                    */
#define BP__PAR_MIN_TRIANGLES 1u     /* bp_check_opt's threads on them too  */
#include "bijparam.h"
#include "bptest.h"
#include <math.h>

#define MAXV 400
#define MAXT 700

typedef struct layout {
    uint32_t nv, nt;
    double uv[2 * MAXV];
    uint32_t tri[3 * MAXT];
} layout;

/* ---- the brute force ------------------------------------------------------ */

static int orient(const layout *L, uint32_t a, uint32_t b, uint32_t c)
{
    return bp_orient2d(L->uv + 2 * a, L->uv + 2 * b, L->uv + 2 * c);
}

/* every vertex of t2 on the outer side of some edge of t1 (strict or weak) */
static int separated(const layout *L, const uint32_t *t1, const uint32_t *t2, int strict)
{
    int e, k;
    for (e = 0; e < 3; e++) {
        int all = 1;
        for (k = 0; k < 3; k++) {
            int o = orient(L, t1[e], t1[(e + 1) % 3], t2[k]);
            if (strict ? o >= 0 : o > 0) all = 0;
        }
        if (all) return 1;
    }
    return 0;
}

static int sgn(double x) { return (x > 0) - (x < 0); }

static int pair_ok(const layout *L, const uint32_t *t1, const uint32_t *t2)
{
    int i, j, ns = 0, si = -1, sj = -1;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            if (t1[i] == t2[j]) { ns++; si = i; sj = j; }
    if (ns == 3) return 0;
    if (ns == 0) return separated(L, t1, t2, 1) || separated(L, t2, t1, 1);
    if (ns == 2) {
        uint32_t u = 0, v = 0, w1 = 0, w2 = 0;
        int c = 0;
        for (i = 0; i < 3; i++) {
            int in2 = t1[i] == t2[0] || t1[i] == t2[1] || t1[i] == t2[2];
            if (!in2) w1 = t1[i]; else if (c++ == 0) u = t1[i]; else v = t1[i];
        }
        for (j = 0; j < 3; j++)
            if (t2[j] != u && t2[j] != v) w2 = t2[j];
        return orient(L, u, v, w1) * orient(L, u, v, w2) < 0;
    }
    /* one shared vertex s: interiors disjoint, and edges meet only at s */
    {
        uint32_t s = t1[si];
        (void)sj;
        if (!separated(L, t1, t2, 0) && !separated(L, t2, t1, 0)) return 0;
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                uint32_t a = t1[i], b = t1[(i + 1) % 3], c = t2[j], d = t2[(j + 1) % 3];
                int hs1 = a == s || b == s, hs2 = c == s || d == s;
                if (hs1 && hs2) {
                    uint32_t p = a == s ? b : a, q = c == s ? d : c;
                    const double *S = L->uv + 2 * s, *P = L->uv + 2 * p, *Q = L->uv + 2 * q;
                    if (orient(L, s, p, q) == 0 && sgn(P[0] - S[0]) == sgn(Q[0] - S[0]) &&
                        sgn(P[1] - S[1]) == sgn(Q[1] - S[1]))
                        return 0;                 /* the two edges overlap beyond s */
                } else if (bp_segments_intersect(L->uv + 2 * a, L->uv + 2 * b, L->uv + 2 * c, L->uv + 2 * d)) {
                    return 0;
                }
            }
        return 1;
    }
}

/* 0 valid; 1 precondition; 2 non-finite; 3 other invalid */
static int brute(const layout *L)
{
    uint32_t t, u, k, m, v;
    static uint32_t outdeg[MAXV];
    for (t = 0; t < L->nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t a = L->tri[3 * t + k], b = L->tri[3 * t + (k + 1) % 3], same = 0, rev = 0;
            for (u = 0; u < L->nt; u++)
                for (m = 0; m < 3; m++) {
                    uint32_t c = L->tri[3 * u + m], d = L->tri[3 * u + (m + 1) % 3];
                    if (c == a && d == b) same++;
                    if (c == b && d == a) rev++;
                }
            if (a != b && (same > 1 || same + rev > 2)) return 1;
        }
    for (t = 0; t < L->nt; t++)
        for (k = 0; k < 6; k++)
            if (!isfinite(L->uv[2 * L->tri[3 * t + k / 2] + k % 2])) return 2;
    for (t = 0; t < L->nt; t++)
        if (orient(L, L->tri[3 * t], L->tri[3 * t + 1], L->tri[3 * t + 2]) <= 0) return 3;
    for (v = 0; v < L->nv; v++) outdeg[v] = 0;
    for (t = 0; t < L->nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t a = L->tri[3 * t + k], b = L->tri[3 * t + (k + 1) % 3], rev = 0;
            for (u = 0; u < L->nt; u++)
                for (m = 0; m < 3; m++)
                    if (L->tri[3 * u + m] == b && L->tri[3 * u + (m + 1) % 3] == a) rev++;
            if (!rev && ++outdeg[a] > 1) return 3;      /* pinched */
        }
    for (t = 0; t < L->nt; t++)
        for (u = t + 1; u < L->nt; u++)
            if (!pair_ok(L, L->tri + 3 * t, L->tri + 3 * u)) return 3;
    return 0;
}

/* ---- random layouts ------------------------------------------------------- */

static double coord(double x, int lattice)
{
    return lattice ? floor(x * 8 + 0.5) / 8 : x;
}

/* an m x n grid of cells at (ox, oy) with cell size h, each cell kept with
   probability keep, except the cells of the hole [h0, h1)^2 */
static void add_grid(layout *L, double ox, double oy, double h, int m, int n, double keep, int h0, int h1,
                     int lattice)
{
    uint32_t base = L->nv, i, j;
    if (L->nv + (uint32_t)((m + 1) * (n + 1)) > MAXV || L->nt + (uint32_t)(2 * m * n) > MAXT) return;
    for (j = 0; j <= (uint32_t)n; j++)
        for (i = 0; i <= (uint32_t)m; i++) {
            double jx = lattice ? 0 : bpt_rng_range(-0.25, 0.25), jy = lattice ? 0 : bpt_rng_range(-0.25, 0.25);
            L->uv[2 * L->nv] = coord(ox + h * (i + jx), lattice);
            L->uv[2 * L->nv + 1] = coord(oy + h * (j + jy), lattice);
            L->nv++;
        }
    for (j = 0; j < (uint32_t)n; j++)
        for (i = 0; i < (uint32_t)m; i++) {
            uint32_t a = base + j * (m + 1) + i, b = a + 1, c = a + (m + 1) + 1, d = a + (m + 1);
            if ((int)i >= h0 && (int)i < h1 && (int)j >= h0 && (int)j < h1) continue;
            if (bpt_rng_unit() > keep) continue;
            if (bpt_rng_unit() < 0.5) {
                uint32_t t1[6] = { a, b, c, a, c, d };
                memcpy(L->tri + 3 * L->nt, t1, sizeof t1);
            } else {
                uint32_t t2[6] = { a, b, d, b, c, d };
                memcpy(L->tri + 3 * L->nt, t2, sizeof t2);
            }
            L->nt += 2;
        }
}

static uint32_t rnd(uint32_t n) { return (uint32_t)(bpt_rng_u64() % n); }

static void random_layout(layout *L, int kind)
{
    int lattice = bpt_rng_unit() < 0.4, mut, nm;
    memset(L, 0, sizeof *L);
    /* a main piece: a grid, sometimes with a hole, sometimes with cells missing */
    {
        int m = 2 + (int)rnd(4), n = 2 + (int)rnd(4), hole = m >= 4 && n >= 4 && bpt_rng_unit() < 0.6;
        add_grid(L, 0, 0, 1, m, n, bpt_rng_unit() < 0.5 ? 1.0 : 0.8, hole ? 1 : 0, hole ? (m < n ? m : n) - 1 : 0,
                 lattice);
    }
    /* a second piece at a random place: inside the hole, outside, on top */
    if (kind >= 1 && bpt_rng_unit() < 0.7) {
        double h = bpt_rng_unit() < 0.5 ? 0.5 : bpt_rng_range(0.2, 1.2);
        add_grid(L, bpt_rng_range(-1, 5), bpt_rng_range(-1, 5), h, 1 + (int)rnd(2), 1 + (int)rnd(2), 1.0, 0, 0, lattice);
    }
    if (kind < 2) return;
    /* mutations */
    nm = 1 + (int)rnd(2);
    for (mut = 0; mut < nm && L->nt > 0; mut++) {
        uint32_t t = rnd(L->nt), v = L->tri[3 * t + rnd(3)];
        switch (rnd(7)) {
        case 0:              /* move a vertex anywhere */
            L->uv[2 * v] = coord(bpt_rng_range(-1, 6), lattice);
            L->uv[2 * v + 1] = coord(bpt_rng_range(-1, 6), lattice);
            break;
        case 1:              /* move a vertex a little */
            L->uv[2 * v] = coord(L->uv[2 * v] + bpt_rng_range(-0.6, 0.6), lattice);
            L->uv[2 * v + 1] = coord(L->uv[2 * v + 1] + bpt_rng_range(-0.6, 0.6), lattice);
            break;
        case 2: {            /* snap onto another vertex's place */
            uint32_t w = L->tri[rnd(3 * L->nt)];
            L->uv[2 * v] = L->uv[2 * w];
            L->uv[2 * v + 1] = L->uv[2 * w + 1];
            break;
        }
        case 3:              /* a triangle listed twice */
            if (L->nt < MAXT) { memcpy(L->tri + 3 * L->nt, L->tri + 3 * t, 3 * sizeof(uint32_t)); L->nt++; }
            break;
        case 4: {            /* reversed triangle */
            uint32_t x = L->tri[3 * t];
            L->tri[3 * t] = L->tri[3 * t + 1];
            L->tri[3 * t + 1] = x;
            break;
        }
        case 5:              /* a new triangle on an edge, in either direction */
            if (L->nt < MAXT && L->nv < MAXV) {
                uint32_t a = L->tri[3 * t], b = L->tri[3 * t + 1], nvx = L->nv++;
                L->uv[2 * nvx] = coord(bpt_rng_range(-1, 6), lattice);
                L->uv[2 * nvx + 1] = coord(bpt_rng_range(-1, 6), lattice);
                if (bpt_rng_unit() < 0.5) { uint32_t x = a; a = b; b = x; }
                L->tri[3 * L->nt] = a; L->tri[3 * L->nt + 1] = b; L->tri[3 * L->nt + 2] = nvx;
                if (orient(L, a, b, nvx) < 0) { L->tri[3 * L->nt] = b; L->tri[3 * L->nt + 1] = a; }
                L->nt++;
            }
            break;
        default: {           /* mirror the whole layout (valid stays valid) */
            uint32_t k;
            for (k = 0; k < L->nv; k++) L->uv[2 * k] = -L->uv[2 * k];
            for (k = 0; k < L->nt; k++) { uint32_t x = L->tri[3 * k]; L->tri[3 * k] = L->tri[3 * k + 1]; L->tri[3 * k + 1] = x; }
            break;
        }
        }
    }
}

/* the message names the element the error's fields name */
static int names_element(const bp_error *e)
{
    if (e->element == BP_ELEMENT_TRIANGLE) return bpt_has_number(e->message, e->index) && strstr(e->message, "triangle index");
    if (e->element == BP_ELEMENT_EDGE) return bpt_has_number(e->message, e->index) && bpt_has_number(e->message, e->index2);
    if (e->element == BP_ELEMENT_VERTEX) return bpt_has_number(e->message, e->index);
    return 0;
}

static void random_agreement(void)
{
    static layout L, S;
    int i, disagree = 0, nvalid = 0, ninvalid = 0, badstatus = 0, badname = 0, scaled_diff = 0, kinds[4] = { 0, 0, 0, 0 };
    const int N = 4000;
    for (i = 0; i < N; i++) {
        bp_check_report r, rs;
        bp_error e, es;
        bp_status st, sts;
        int b, s, k;
        random_layout(&L, i % 3);
        b = brute(&L);
        st = bp_check(L.tri, L.nt, L.uv, L.nv, NULL, &r, &e);
        kinds[b]++;
        if ((b == 0) != (st == BP_OK)) {
            if (disagree++ < 3) {
                uint32_t t;
                printf("  disagreement on layout %d: brute %d, bp_check %s: %s\n  ", i, b, bp_status_string(st), e.message);
                for (t = 0; t < L.nt; t++) printf("(%u %u %u) ", L.tri[3 * t], L.tri[3 * t + 1], L.tri[3 * t + 2]);
                printf("\n");
            }
        }
        if (b == 0) nvalid++; else ninvalid++;
        if (b == 1 && st != BP_ERR_NONMANIFOLD && st != BP_ERR_ORIENTATION) badstatus++;
        if (b == 3 && st != BP_ERR_NOT_BIJECTIVE) badstatus++;
        if (b != 0 && (e.status != st || !names_element(&e))) {
            if (badname++ < 3) printf("  message does not name its element (%d): %s\n", (int)e.element, e.message);
        }
        /* the same layout scaled by 2^900 and 2^-900: the same verdict and counts */
        for (s = -1; s <= 1; s += 2) {
            S = L;
            for (k = 0; k < (int)(2 * L.nv); k++) S.uv[k] = ldexp(L.uv[k], 900 * s);
            sts = bp_check(S.tri, S.nt, S.uv, S.nv, NULL, &rs, &es);
            if (sts != st || rs.flipped != r.flipped || rs.degenerate != r.degenerate ||
                rs.boundary_intersections != r.boundary_intersections || rs.loop_orientation != r.loop_orientation ||
                rs.nested != r.nested)
                scaled_diff++;
        }
    }
    BPT_CHECK(disagree == 0, "%d random layouts: bp_check == BP_OK exactly when the brute force finds the map "
              "bijective (%d valid, %d invalid: %d precondition, %d other; %d disagreements)", N, nvalid, ninvalid,
              kinds[1], kinds[3], disagree);
    BPT_CHECK(nvalid > N / 5 && kinds[1] > N / 50 && kinds[3] > N / 5, "the random layouts cover valid maps, "
              "precondition failures and invalid maps (%d, %d, %d)", nvalid, kinds[1], kinds[3]);
    BPT_CHECK(badstatus == 0, "the status is NONMANIFOLD/ORIENTATION for a broken precondition and NOT_BIJECTIVE "
              "otherwise (%d wrong)", badstatus);
    BPT_CHECK(badname == 0, "every invalid verdict's message names the element of err.index/index2 (%d do not)", badname);
    BPT_CHECK(scaled_diff == 0, "scaling each layout by 2^900 and 2^-900 changes no verdict and no count (%d changed)",
              scaled_diff);
}

/* ---- the directed edges, as bp_check classified them before its tasks ----- */

static int ref_dedge_cmp(const void *pa, const void *pb)
{
    const bp__dedge *x = (const bp__dedge *)pa, *y = (const bp__dedge *)pb;
    uint32_t x0 = x->a < x->b ? x->a : x->b, y0 = y->a < y->b ? y->a : y->b;
    uint32_t x1 = x->a < x->b ? x->b : x->a, y1 = y->a < y->b ? y->b : y->a;
    if (x0 != y0) return x0 < y0 ? -1 : 1;
    if (x1 != y1) return x1 < y1 ? -1 : 1;
    return x->a < y->a ? -1 : x->a > y->a;
}

/* A serial classification of bp_check's edges (qsort of the directed
   edges by (smaller end, larger end, start), then each group): the
   boundary edges in order into the returned array (*nb of them), the
   nonmanifold and misoriented groups counted into r, the first bad group
   into first.  The reference of the tasks' two-level sort. */
static bp__dedge *ref_edges(const uint32_t *tri, uint32_t nt, bp_check_report *r, bp__check_first *first,
                            uint32_t *nb)
{
    size_t m = 3 * (size_t)nt, e, g, t;
    bp__dedge *de = (bp__dedge *)malloc(m * sizeof *de + 1);
    *nb = 0;
    for (t = 0; t < m; t++) { de[t].a = tri[t]; de[t].b = tri[t % 3 == 2 ? t - 2 : t + 1]; }
    qsort(de, m, sizeof *de, ref_dedge_cmp);
    for (e = 0; e < m; e = g) {
        for (g = e + 1; g < m && ((de[g].a == de[e].a && de[g].b == de[e].b) || (de[g].a == de[e].b && de[g].b == de[e].a)); g++) {}
        if (g - e == 1) de[(*nb)++] = de[e];
        else if (g - e > 2 || (de[e].a == de[e + 1].a && de[e].a != de[e].b)) {
            int nonman = g - e > 2;
            if (!r->nonmanifold_edges && !r->misoriented_edges) {
                first->kind = nonman ? BP__BAD_NONMANIFOLD : BP__BAD_MISORIENTED;
                first->v0 = de[e].a; first->v1 = de[e].b; first->count = (uint32_t)(g - e);
            }
            if (nonman) r->nonmanifold_edges++; else r->misoriented_edges++;
        }
    }
    return de;
}

/* ---- the check in tasks against a serial check ---------------------------

   bp_check's work runs in tasks (bp__check_par: triangle chunks, key ranges
   of the directed edges, the pieces' union-find) on the library's runners,
   and must give the serial result for any runner and task order.  Its
   reference here is bp_check written serially: the library's parts that
   have no tasks (the scaling, (b), (c) and (d), the verdict) and, written
   out serially here, the index check,
   the finiteness pass, (a) in triangle order, the directed edges by qsort
   (ref_edges) and a union-find of three unions per triangle.  The reports
   (every count and first element), the status and the message must be the
   same bytes, with the tasks run serially, backwards, odd then even and
   on pools of 2 and 3 threads.  This file sets the chunks to 16 triangles
   and the key ranges to 4 vertices (BP__CHECK_CHUNK,
   BP__CHECK_RANGE_SHIFT above), and BP__PAR_MIN_ITEMS to 1, so that the
   small random layouts run in many chunks and ranges on the runners too. */

static bp_status ref_check(const uint32_t *tris, uint32_t nt, const double *uv, uint32_t nv, bp_check_report *rep,
                           bp_error *err)
{
    bp_allocator a = bp__allocator_of(NULL);
    bp__check_first first;
    bp__dedge *de;
    double *scaled = NULL, maxabs = 0, minabs = HUGE_VAL;
    const double *x;
    uint32_t t, k, nb = 0;
    bp_status st = BP_OK;
    memset(&first, 0, sizeof first);
    memset(rep, 0, sizeof *rep);
    rep->first_bad_triangle = rep->first_bad_edge[0] = rep->first_bad_edge[1] = -1;
    rep->first_nonmanifold_edge[0] = rep->first_nonmanifold_edge[1] = -1;
    for (t = 0; t < nt; t++)
        for (k = 0; k < 3; k++)
            if (tris[3 * (size_t)t + k] >= nv)
                return bp__fail(err, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, t, -1, 0,
                                "bp_check: triangle index %u uses vertex %u, but there are %u vertices", t,
                                tris[3 * (size_t)t + k], nv);
    for (t = 0; t < nt; t++) {
        int fin = 1;
        for (k = 0; k < 6; k++) {
            double c = uv[2 * (size_t)tris[3 * (size_t)t + k / 2] + k % 2], m = fabs(c);
            if (!(c - c == 0)) { fin = 0; continue; }
            if (m > maxabs) maxabs = m;
            if (m > 0 && m < minabs) minabs = m;
        }
        if (!fin) {
            if (!rep->nonfinite) rep->first_bad_triangle = t;
            rep->nonfinite++;
        }
    }
    if ((st = bp__check_scale(&a, uv, nv, maxabs, minabs, &scaled, err)) != BP_OK) return st;
    x = scaled ? scaled : uv;
    for (t = 0; t < nt; t++) {
        const uint32_t *tr = tris + 3 * (size_t)t;
        int o, fin = 1;
        for (k = 0; k < 6; k++) if (!(x[2 * (size_t)tr[k / 2] + k % 2] - x[2 * (size_t)tr[k / 2] + k % 2] == 0)) fin = 0;
        if (!fin) continue;
        o = bp_orient2d(x + 2 * (size_t)tr[0], x + 2 * (size_t)tr[1], x + 2 * (size_t)tr[2]);
        if (o <= 0) {
            if (o < 0) rep->flipped++; else rep->degenerate++;
            if (!rep->nonfinite && rep->first_bad_triangle < 0) { rep->first_bad_triangle = t; first.count = o < 0; }
        }
    }
    de = ref_edges(tris, nt, rep, &first, &nb);
    if (rep->nonmanifold_edges || rep->misoriented_edges) {
        rep->first_nonmanifold_edge[0] = first.v0;
        rep->first_nonmanifold_edge[1] = first.v1;
    }
    if (!rep->nonfinite && !rep->nonmanifold_edges && !rep->misoriented_edges) {
        st = bp__boundary_conflicts(&a, x, de, nb, rep, NULL, first.pair);
        if (st == BP_OK && !rep->flipped && !rep->degenerate && !rep->boundary_intersections) {
            uint32_t *piece = (uint32_t *)malloc((size_t)nv * sizeof *piece + 1);
            for (k = 0; k < nv; k++) piece[k] = k;
            for (t = 0; t < 3 * nt; t++) bp__uf_union(piece, tris[t], tris[t % 3 == 2 ? t - 2 : t + 1]);
            st = bp__loop_topology(&a, x, nv, piece, de, nb, rep, &first);
            free(piece);
        }
    }
    free(de);
    bp__free(&a, scaled);
    if (st != BP_OK) return bp__fail(err, st, BP_ELEMENT_NONE, -1, -1, 0, "bp_check: the boundary's extent overflows");
    return bp__check_verdict(tris, nt, rep, &first, err);
}

static int same_report(const bp_check_report *x, const bp_check_report *y)
{
    return x->flipped == y->flipped && x->degenerate == y->degenerate && x->nonfinite == y->nonfinite &&
           x->boundary_intersections == y->boundary_intersections && x->loop_orientation == y->loop_orientation &&
           x->nested == y->nested && x->first_bad_triangle == y->first_bad_triangle &&
           x->first_bad_edge[0] == y->first_bad_edge[0] && x->first_bad_edge[1] == y->first_bad_edge[1] &&
           x->nonmanifold_edges == y->nonmanifold_edges && x->misoriented_edges == y->misoriented_edges &&
           x->first_nonmanifold_edge[0] == y->first_nonmanifold_edge[0] &&
           x->first_nonmanifold_edge[1] == y->first_nonmanifold_edge[1];
}

/* The runners: serial, backwards, odd then even, pools of 2 and 3. */
#define NRUN 5
static bp__par runners[NRUN];
static void *pools[NRUN];
static const char *runner_name[NRUN] = { "serial", "backwards", "odd-even", "2 threads", "3 threads" };

static void runners_start(void)
{
    bp_allocator a = bp__allocator_of(NULL);
    bp_options o;
    int i;
    memset(&o, 0, sizeof o);
    runners[0] = bp__par_serial();
    runners[1] = runners[0]; runners[1].run = bpt_backwards_for;
    runners[2] = runners[0]; runners[2].run = bpt_odd_even_for;
    for (i = 3; i < NRUN; i++) {
        o.threads = i - 1;
        runners[i] = bp__par_begin(&a, &o, &pools[i]);
    }
}

static void runners_stop(void)
{
    bp_allocator a = bp__allocator_of(NULL);
    int i;
    for (i = 3; i < NRUN; i++) bp__par_end(&a, pools[i]);
}

/* The check of one map on every runner and bp_check against ref_check:
   the number that differ (each one printed, up to a few); *st: the
   reference status. */
static int par_disagree(const char *what, const uint32_t *tri, uint32_t nt, const double *uv, uint32_t nv,
                        bp_status *st)
{
    static int printed = 0;
    bp_check_report r0, r;
    bp_error e0, e;
    int i, bad = 0;
    bp_options o;
    *st = ref_check(tri, nt, uv, nv, &r0, &e0);
    bp_options_init(&o);
    for (i = 0; i <= NRUN + 2; i++) {
        bp_status s;
        if (i == NRUN + 1) o.threads = 2;                    /* bp_check_opt on a pool of its own */
        if (i == NRUN + 2) { o.threads = 0; o.parallel_for = bpt_backwards_for; }   /* on the caller's runner */
        s = i < NRUN ? bp__check_par(tri, nt, uv, nv, NULL, &runners[i], &r, &e)
          : i == NRUN ? bp_check(tri, nt, uv, nv, NULL, &r, &e) : bp_check_opt(tri, nt, uv, nv, &o, &r, &e);
        int same = s == *st && strcmp(e.message, e0.message) == 0 && e.element == e0.element && e.index == e0.index &&
                   e.index2 == e0.index2 && (*st == BP_ERR_INDEX || *st == BP_ERR_INVALID_ARGUMENT || same_report(&r, &r0));
        if (!same) {
            bad++;
            if (printed++ < 4)
                printf("  %s (%s): %s / %s\n    reference: %s / %s\n", what,
                       i < NRUN ? runner_name[i] : i == NRUN ? "bp_check" : "bp_check_opt",
                       bp_status_string(s), e.message, bp_status_string(*st), e0.message);
        }
    }
    return bad;
}

/* The random layouts above (valid, nonmanifold, misoriented, flipped,
   nested, touching; also scaled by 2^900 and 2^-900): the tasks' result
   equals the reference on every runner. */
static void par_random(void)
{
    static layout L, S;
    int i, bad = 0, n = 0, kinds[8] = { 0, 0, 0, 0, 0, 0, 0, 0 };
    for (i = 0; i < 3000; i++) {
        bp_status st;
        int s, k;
        random_layout(&L, i % 3);
        bad += par_disagree("random layout", L.tri, L.nt, L.uv, L.nv, &st) != 0;
        kinds[st == BP_OK ? 0 : st == BP_ERR_NONMANIFOLD ? 1 : st == BP_ERR_ORIENTATION ? 2 : 3]++;
        n++;
        for (s = -1; s <= 1; s += 2) {
            S = L;
            for (k = 0; k < (int)(2 * L.nv); k++) S.uv[k] = ldexp(L.uv[k], 900 * s);
            bad += par_disagree("scaled layout", S.tri, S.nt, S.uv, S.nv, &st) != 0;
            n++;
        }
    }
    BPT_CHECK(bad == 0 && kinds[0] > 300 && kinds[1] > 30 && kinds[2] > 30 && kinds[3] > 300,
              "%d random layouts (and each scaled by 2^900 and 2^-900; %d valid, %d nonmanifold, %d misoriented, %d "
              "not bijective), chunks of %u triangles, key ranges of %u vertices: bp__check_par on 5 runners, "
              "bp_check and bp_check_opt (2 threads; a caller's parallel_for) give the serial reference's status, "
              "report and message (%d differ)",
              n, kinds[0], kinds[1], kinds[2], kinds[3], BP__CHECK_CHUNK, 1u << BP__CHECK_RANGE_SHIFT, bad);
}

/* A triangle of chunk c (of the check's chunks over nt triangles), at
   fraction f of it. */
static uint32_t in_chunk(uint32_t nt, uint32_t c, double f)
{
    uint32_t nc = bp__nchunks(nt, BP__CHECK_CHUNK), t0 = bp__chunk_at(nt, nc, c), t1 = bp__chunk_at(nt, nc, c + 1);
    return t0 + (uint32_t)(f * (t1 - t0 - 1));
}

/* Real charts (tests/data) with their start maps, and broken versions
   with bad elements in several chunks (given from the last chunk to the
   first, so that the last written is not the first): flipped triangles,
   NaNs, indices out of range, reversed triangles (misoriented edges),
   triangles added on interior edges (nonmanifold), a second copy of the
   chart laid over the first (boundary intersections) or beside it
   (valid, two pieces), the flipped map scaled by 2^600 (the scaled
   path). */
static void par_meshes(void)
{
    static const char *paths[] = { "tests/data/camelhead.off", "tests/data/face_holes.off",
                                   "tests/data/mech-holes-shark.off", "tests/data/cow_param_withSUV.obj",
                                   "tests/data/torus_with_holes.obj" };
    size_t p;
    int bad = 0, n = 0, kinds[6] = { 0, 0, 0, 0, 0, 0 };
    for (p = 0; p < sizeof paths / sizeof *paths; p++) {
        bp_mesh m;
        bp_atlas at;
        bp_error e;
        uint32_t c;
        if (!BPT_CHECK(bp_read_mesh(paths[p], &m, NULL, &e) == BP_OK && bp_atlas_build(&at, &m, NULL, &e) == BP_OK,
                       "%s: read and charts (%s)", paths[p], e.message))
            continue;
        for (c = 0; c < at.num_charts; c++) {
            bp_chart *ch = &at.charts[c];
            uint32_t nt = ch->num_triangles, nv = ch->num_vertices, nc, v, t, j, k;
            uint32_t *tri = (uint32_t *)malloc((6 * (size_t)nt + 12) * sizeof *tri);
            double *uv = (double *)malloc((4 * (size_t)nv + 8) * sizeof *uv), lo[2] = { HUGE_VAL, HUGE_VAL },
                   hi[2] = { -HUGE_VAL, -HUGE_VAL };
            bp_status st;
            if (ch->error.status != BP_OK || bp_chart_init(ch, &m, NULL, &e) != BP_OK || nt < 64) {
                free(tri); free(uv);
                continue;
            }
            nc = bp__nchunks(nt, BP__CHECK_CHUNK);
            for (v = 0; v < nv; v++)
                for (k = 0; k < 2; k++) {
                    if (ch->uv[2 * v + k] < lo[k]) lo[k] = ch->uv[2 * v + k];
                    if (ch->uv[2 * v + k] > hi[k]) hi[k] = ch->uv[2 * v + k];
                }
#define RESET() (memcpy(tri, ch->triangles, 3 * (size_t)nt * sizeof *tri), \
                 memcpy(uv, ch->uv, 2 * (size_t)nv * sizeof *uv))
#define RUN(what, ntri, nvert) (bad += par_disagree(what, tri, ntri, uv, nvert, &st) != 0, n++, \
                                kinds[st == BP_OK ? 0 : st == BP_ERR_NOT_BIJECTIVE ? 1 : st == BP_ERR_NONFINITE ? 2 : \
                                      st == BP_ERR_INDEX ? 3 : st == BP_ERR_ORIENTATION ? 4 : 5]++)
            RESET();
            RUN("start map", nt, nv);
            /* flipped: a corner reflected across its opposite edge */
            for (j = 0; j < 3; j++) {
                uint32_t cc = j == 0 ? nc - 1 : j == 1 ? nc / 2 : 1;
                const uint32_t *tr = tri + 3 * (size_t)in_chunk(nt, cc, 0.7);
                double *a = uv + 2 * (size_t)tr[0], *b = uv + 2 * (size_t)tr[1], *d = uv + 2 * (size_t)tr[2];
                double ex = d[0] - b[0], ey = d[1] - b[1], s = ((a[0] - b[0]) * ex + (a[1] - b[1]) * ey) / (ex * ex + ey * ey);
                a[0] = 2 * (b[0] + s * ex) - a[0];
                a[1] = 2 * (b[1] + s * ey) - a[1];
            }
            RUN("flipped in 3 chunks", nt, nv);
            for (k = 0; k < 2 * nv; k++) uv[k] = ldexp(uv[k], 600);
            RUN("flipped, scaled by 2^600", nt, nv);
            RESET();
            for (j = 0; j < 2; j++) uv[2 * (size_t)tri[3 * (size_t)in_chunk(nt, j ? 1 : nc - 2, 0.5) + 1] + 1] = NAN;
            RUN("NaN in 2 chunks", nt, nv);
            RESET();
            for (j = 0; j < 2; j++) tri[3 * (size_t)in_chunk(nt, j ? 2 : nc - 1, 0.3) + 2] = nv + j;
            RUN("index out of range in 2 chunks", nt, nv);
            RESET();
            for (j = 0; j < 3; j++) {
                uint32_t *tr = tri + 3 * (size_t)in_chunk(nt, j == 0 ? nc - 1 : j == 1 ? nc / 3 : 0, 0.6), x = tr[0];
                tr[0] = tr[1];
                tr[1] = x;
            }
            RUN("3 triangles reversed", nt, nv);
            RESET();
            for (j = 0; j < 3; j++) {      /* a triangle on an edge of a triangle late, middle, early */
                const uint32_t *tr = tri + 3 * (size_t)in_chunk(nt, j == 0 ? nc - 1 : j == 1 ? nc / 2 : 0, 0.4);
                tri[3 * (size_t)(nt + j)] = tr[0];
                tri[3 * (size_t)(nt + j) + 1] = tr[1];
                tri[3 * (size_t)(nt + j) + 2] = (tr[2] + 1) % nv;
            }
            RUN("3 triangles added on edges", nt + 3, nv);
            /* a second copy of the chart: laid over the first, moved by a
               third of its width, and beside it */
            for (j = 0; j < 3; j++) {
                double dx = j == 0 ? 0 : j == 1 ? (hi[0] - lo[0]) / 3 : 1.5 * (hi[0] - lo[0]);
                RESET();
                for (t = 0; t < 3 * nt; t++) tri[3 * (size_t)nt + t] = ch->triangles[t] + nv;
                for (v = 0; v < nv; v++) {
                    uv[2 * (size_t)(nv + v)] = ch->uv[2 * v] + dx;
                    uv[2 * (size_t)(nv + v) + 1] = ch->uv[2 * v + 1];
                }
                RUN(j == 2 ? "two copies side by side" : "two copies overlapping", 2 * nt, 2 * nv);
            }
#undef RUN
#undef RESET
            free(tri);
            free(uv);
        }
        bp_atlas_free(&at);
        bp_mesh_free(&m, NULL);
    }
    BPT_CHECK(bad == 0 && kinds[0] > 5 && kinds[1] > 10 && kinds[2] > 3 && kinds[3] > 3 && kinds[4] > 3 && kinds[5] > 3,
              "%d maps of the charts of 5 meshes (start maps and broken: %d valid, %d not bijective, %d NaN, %d bad "
              "index, %d misoriented, %d nonmanifold): bp__check_par on 5 runners, bp_check and bp_check_opt give the serial "
              "reference's status, report and message (%d differ)",
              n, kinds[0], kinds[1], kinds[2], kinds[3], kinds[4], kinds[5], bad);
}

/* ---- condition (b) without the grid ---------------------------------------- */

/* The line search decides (b) for a chart of at most BP__CONFLICT_SCAN
   boundary edges by testing every pair of overlapping boxes
   (bp__conflicts_scan) instead of the grid of bp__boundary_conflicts.  Both
   must count the same conflicting pairs: on the random layouts above (their
   boundary edges: pieces, holes, moved and snapped vertices, lattice
   coordinates that make edges touch and overlap), and on soups of small
   random polygons (many loops, from one to dozens of edges, crossing each
   other and themselves), up to the scan's limit of edges. */
static void conflict_scan_agreement(void)
{
    static layout L;
    bp_allocator a = bp__allocator_of(NULL);
    int i, cases = 0, differ = 0, with_conflicts = 0, many_loops = 0;
    for (i = 0; i < 6000; i++) {
        bp_check_report r;
        bp__dedge *de = NULL, soup[BP__CONFLICT_SCAN];
        bp__check_first first;
        uint32_t nb = 0, scan, k;
        memset(&r, 0, sizeof r);
        memset(&first, 0, sizeof first);
        if (i % 2 == 0) {
            random_layout(&L, i % 3);
            de = ref_edges(L.tri, L.nt, &r, &first, &nb);
            memset(&r, 0, sizeof r);
        } else {
            /* polygons of 1..12 edges with lattice or random corners */
            int lattice = i % 4 == 1;
            uint32_t target = 2 + rnd(BP__CONFLICT_SCAN - 1), loops = 0;
            memset(&L, 0, sizeof L);
            while (L.nv < target) {
                uint32_t n = 1 + rnd(12), base = L.nv;
                double cx = bpt_rng_range(0, 5), cy = bpt_rng_range(0, 5), rad = bpt_rng_range(0.1, 1.5);
                if (L.nv + n > target) n = target - L.nv;
                for (k = 0; k < n; k++) {
                    double th = 6.283185307179586 * (k + bpt_rng_range(-0.4, 0.4)) / n;
                    L.uv[2 * L.nv] = coord(cx + rad * cos(th) * bpt_rng_range(0.3, 1.2), lattice);
                    L.uv[2 * L.nv + 1] = coord(cy + rad * sin(th) * bpt_rng_range(0.3, 1.2), lattice);
                    soup[L.nv].a = L.nv;
                    soup[L.nv].b = k + 1 < n ? L.nv + 1 : base;
                    L.nv++;
                }
                loops++;
            }
            nb = L.nv;
            if (loops >= 8) many_loops++;
        }
        if (nb <= BP__CONFLICT_SCAN) {
            scan = bp__conflicts_scan(L.uv, de ? de : soup, nb);
            if (bp__boundary_conflicts(&a, L.uv, de ? de : soup, nb, &r, NULL, NULL) == BP_OK) {
                cases++;
                if (scan != r.boundary_intersections) differ++;
                if (scan) with_conflicts++;
            }
        }
        free(de);
    }
    BPT_CHECK(differ == 0 && cases > 5000 && with_conflicts > 1000 && many_loops > 500,
              "condition (b) by scanning every pair (charts of <= %u boundary edges) counts the same conflicting pairs "
              "as the grid in %d of %d layouts (%d with conflicts, %d polygon soups of 8 loops or more)",
              BP__CONFLICT_SCAN, cases - differ, cases, with_conflicts, many_loops);
}

/* ---- named cases ---------------------------------------------------------- */

static void named_cases(void)
{
    /* a unit square: two triangles 0 1 2, 0 2 3 */
    double sq[8] = { 0, 0, 1, 0, 1, 1, 0, 1 }, uv[16];
    uint32_t tri[12] = { 0, 1, 2, 0, 2, 3 }, t3[12];
    bp_check_report r;
    bp_error e;
    bp_status st;
    int k;

    st = bp_check(tri, 2, sq, 4, NULL, &r, &e);
    BPT_CHECK(st == BP_OK && e.status == BP_OK, "unit square: BP_OK (%s)", e.message);
    BPT_CHECK(bp_check(tri, 2, sq, 4, NULL, &r, NULL) == BP_OK, "err may be NULL");

    memcpy(uv, sq, sizeof sq);
    uv[4] = -1; uv[5] = -1;                                   /* vertex 2 behind 0: triangle 0 flipped */
    st = bp_check(tri, 2, uv, 4, NULL, &r, &e);
    BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && r.flipped >= 1 && e.element == BP_ELEMENT_TRIANGLE && e.index == 0 &&
              strstr(e.message, "triangle index 0") && strstr(e.message, "flipped"),
              "a flipped triangle: BP_ERR_NOT_BIJECTIVE naming triangle index 0, report kept (%u flipped): %s",
              r.flipped, e.message);

    memcpy(uv, sq, sizeof sq);
    uv[6] = NAN;
    st = bp_check(tri, 2, uv, 4, NULL, &r, &e);
    BPT_CHECK(st == BP_ERR_NONFINITE && r.nonfinite == 1 && e.index == 1 && strstr(e.message, "triangle index 1"),
              "a NaN coordinate: BP_ERR_NONFINITE naming triangle index 1: %s", e.message);

    memcpy(t3, tri, 6 * sizeof *tri);
    memcpy(t3 + 6, tri, 3 * sizeof *tri);                     /* triangle 0 listed twice */
    st = bp_check(t3, 3, sq, 4, NULL, &r, &e);
    /* 0->1 and 1->2 twice in one direction; 2-0 three times (with 0->2 of triangle 1) */
    BPT_CHECK(st == BP_ERR_ORIENTATION && r.misoriented_edges == 2 && r.nonmanifold_edges == 1 && e.element == BP_ELEMENT_EDGE &&
              bpt_has_number(e.message, e.index) && bpt_has_number(e.message, e.index2) && bpt_has_number(e.message, 2),
              "a triangle listed twice never passes: BP_ERR_ORIENTATION, 2 + 1 edges, naming the edge and triangle index 2: %s",
              e.message);
    st = bp_check(t3 + 6, 1, sq, 4, NULL, &r, &e);
    BPT_CHECK(st == BP_OK, "(one copy alone is valid)");
    {
        uint32_t d[6] = { 0, 1, 2, 0, 1, 2 };
        st = bp_check(d, 2, sq, 4, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_ORIENTATION && r.flipped == 0 && r.degenerate == 0,
                  "a single triangle listed twice (a double cover with no boundary edge left): %s, %s",
                  bp_status_string(st), e.message);
    }
    {
        /* three triangles on edge 0-2 */
        double u5[10] = { 0, 0, 1, 0, 1, 1, 0, 1, 2, -1 };
        uint32_t tt[9] = { 0, 1, 2, 0, 2, 3, 0, 4, 2 };
        st = bp_check(tt, 3, u5, 5, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_NONMANIFOLD && r.nonmanifold_edges == 1 && e.element == BP_ELEMENT_EDGE &&
                  ((e.index == 0 && e.index2 == 2) || (e.index == 2 && e.index2 == 0)) &&
                  r.first_nonmanifold_edge[0] >= 0,
                  "three triangles on one edge: BP_ERR_NONMANIFOLD naming edge 0-2: %s", e.message);
    }
    {
        /* a small triangle on top of the square: nested */
        double u7[14] = { 0, 0, 4, 0, 4, 4, 0, 4, 1, 1, 2, 1, 1, 2 };
        uint32_t tt[9] = { 0, 1, 2, 0, 2, 3, 4, 5, 6 };
        st = bp_check(tt, 3, u7, 7, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && r.nested == 1 && e.element == BP_ELEMENT_VERTEX &&
                  bpt_has_number(e.message, e.index) && bpt_has_number(e.message, e.index2),
                  "a piece on another: BP_ERR_NOT_BIJECTIVE naming a vertex of each: %s", e.message);
        /* the same triangle mirrored in place, so its triangle is flipped */
        tt[7] = 6; tt[8] = 5;
        st = bp_check(tt, 3, u7, 7, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && r.flipped == 1 && e.index == 2, "its reversed copy: flipped, triangle index 2");
    }
    {
        /* two boundary edges crossing: a bow of two triangles sharing no vertex */
        double u6[12] = { 0, 0, 2, 0, 1, 2, 0, 1, 2, 1, 1, -1 };
        uint32_t tt[6] = { 0, 1, 2, 3, 5, 4 };
        st = bp_check(tt, 2, u6, 6, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && r.boundary_intersections > 0 && e.element == BP_ELEMENT_EDGE &&
                  strstr(e.message, "meet"), "crossing boundary edges: named: %s", e.message);
    }
    {
        uint32_t bad[3] = { 0, 1, 7 };
        st = bp_check(bad, 1, sq, 4, NULL, &r, &e);
        BPT_CHECK(st == BP_ERR_INDEX && bpt_has_number(e.message, 7), "an index out of range: BP_ERR_INDEX: %s", e.message);
        BPT_CHECK(bp_check(tri, 2, sq, 4, NULL, NULL, &e) == BP_ERR_INVALID_ARGUMENT, "no report: invalid argument");
    }
    /* extreme scales: every finite map is decided, the same as at scale 1 */
    {
        const double scales[5] = { 1.7e308 / 1.0, 1e300, 1e-300, 4.9e-322, 1e154 };
        for (k = 0; k < 5; k++) {
            int j;
            for (j = 0; j < 8; j++) uv[j] = sq[j] * scales[k] - (j % 2 ? 0 : scales[k] * 0.5);
            st = bp_check(tri, 2, uv, 4, NULL, &r, &e);
            BPT_CHECK(st == BP_OK, "the square at scale %g (coordinates up to %g): BP_OK: %s", scales[k],
                      scales[k], e.message);
            uv[4] = -uv[4];                                       /* vertex 2 to the other side */
            uv[5] = -uv[5];
            st = bp_check(tri, 2, uv, 4, NULL, &r, &e);
            BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && r.flipped >= 1, "... and flipped at that scale: %s", e.message);
        }
        /* -1.7e308 .. 1.7e308: the extent overflows without rescaling */
        {
            double big[8] = { -1.7e308, -1.7e308, 1.7e308, -1.7e308, 1.7e308, 1.7e308, -1.7e308, 1.7e308 };
            st = bp_check(tri, 2, big, 4, NULL, &r, &e);
            BPT_CHECK(st == BP_OK, "the square from -1.7e308 to 1.7e308: BP_OK (%s)", e.message);
        }
        {
            double mixed[8] = { 0, 0, 1e300, 0, 1e300, 1e300, 0, 1e-300 };
            st = bp_check(tri, 2, mixed, 4, NULL, &r, &e);
            BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(e.message, "2^994"),
                      "coordinates from 1e-300 to 1e300: refused clearly: %s", e.message);
        }
    }
}

/* ---- a start map that overlaps itself, given to bp_chart_optimize --------- */

static void overlapping_start(void)
{
    /* a strip of n quads in 3D (a long rectangle), mapped in UV around a
       spiral of 1.6 turns: every triangle positive, the strip on itself */
    const uint32_t n = 40;
    bp_mesh m = bpt_mesh_new(2 * (n + 1), 2 * n);
    bp_atlas at;
    bp_options opt;
    bp_error e;
    bp_status st;
    uint32_t i, c;
    double *saved;
    memset(&opt, 0, sizeof opt);
    for (i = 0; i <= n; i++) {
        m.positions[6 * i] = i; m.positions[6 * i + 1] = 0;
        m.positions[6 * i + 3] = i; m.positions[6 * i + 4] = 1;
    }
    for (i = 0; i < n; i++) {
        uint32_t a = 2 * i, b = 2 * i + 2, cc = 2 * i + 3, d = 2 * i + 1;
        uint32_t t[6] = { a, b, cc, a, cc, d };
        memcpy(m.triangles + 6 * i, t, sizeof t);
    }
    st = bp_atlas_build(&at, &m, &opt, &e);
    if (!BPT_CHECK(st == BP_OK && at.num_charts == 1, "strip: one chart (%s)", e.message)) return;
    st = bp_chart_init(&at.charts[0], &m, &opt, &e);
    BPT_CHECK(st == BP_OK, "strip: start map (%s)", e.message);
    for (c = 0; c < at.charts[0].num_vertices; c++) {
        uint32_t v = at.charts[0].vertex[c], k = v / 2;
        double ang = 2 * 3.14159265358979 * 1.6 * k / n, rad = (v % 2) ? 1.4 : 2.0;
        at.charts[0].uv[2 * c] = rad * cos(ang);             /* y = 0 side at radius 2: CCW triangles */
        at.charts[0].uv[2 * c + 1] = rad * sin(ang);
    }
    saved = (double *)malloc(2 * at.charts[0].num_vertices * sizeof(double));
    memcpy(saved, at.charts[0].uv, 2 * at.charts[0].num_vertices * sizeof(double));
    {
        bp_check_report r;
        bp_status cs = bp_check(at.charts[0].triangles, at.charts[0].num_triangles, at.charts[0].uv,
                                at.charts[0].num_vertices, NULL, &r, NULL);
        BPT_CHECK(cs == BP_ERR_NOT_BIJECTIVE && r.flipped == 0 && r.degenerate == 0 && r.boundary_intersections > 0,
                  "the spiral start map: every triangle positive, the boundary overlaps (%u pairs)", r.boundary_intersections);
    }
    st = bp_chart_optimize(&at.charts[0], 0, &m, &opt, &e);
    BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && e.element == BP_ELEMENT_EDGE && bpt_has_number(e.message, e.index + 1) &&
              bpt_has_number(e.message, e.index2 + 1) && strstr(e.message, "overlaps"),
              "bp_chart_optimize refuses the overlapping start map, naming the two edges' vertices: %s", e.message);
    BPT_CHECK(memcmp(saved, at.charts[0].uv, 2 * at.charts[0].num_vertices * sizeof(double)) == 0,
              "... and leaves the map untouched");
    /* a flipped triangle in the start map: named as the file numbers it */
    {
        uint32_t t = 5, v = at.charts[0].triangles[3 * t + 2];
        double *p = at.charts[0].uv + 2 * v, *q = at.charts[0].uv + 2 * at.charts[0].triangles[3 * t];
        p[0] = 2 * q[0] - p[0] + 50; p[1] = 2 * q[1] - p[1] + 50;     /* far away: triangles flip */
        st = bp_chart_optimize(&at.charts[0], 0, &m, &opt, &e);
        BPT_CHECK(st == BP_ERR_NOT_BIJECTIVE && e.element == BP_ELEMENT_TRIANGLE && bpt_has_number(e.message, e.index + 1) &&
                  strstr(e.message, "triangle"),
                  "a start map with a flipped triangle: BP_ERR_NOT_BIJECTIVE naming triangle %lld (from 1): %s",
                  (long long)e.index + 1, e.message);
    }
    /* without the barrier an overlapping map with positive triangles is accepted */
    memcpy(at.charts[0].uv, saved, 2 * at.charts[0].num_vertices * sizeof(double));
    opt.no_barrier = 1;
    opt.max_iterations = 3;
    st = bp_chart_optimize(&at.charts[0], 0, &m, &opt, &e);
    BPT_CHECK(st == BP_OK, "no_barrier: the same overlapping start map is accepted (locally injective only): %s",
              e.message);
    free(saved);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* ---- the loop count of the line search ------------------------------------ */

/* bp__loop_sign on random star-shaped polygons (simple by construction:
   increasing angles around a centre, counter-clockwise; reversed,
   clockwise), on a coarse lattice so that ties of the lexicographic
   minimum and collinear neighbours occur. */
static void loop_signs(void)
{
    int i, wrong = 0, skipped = 0;
    for (i = 0; i < 2000; i++) {
        double uv[2 * 40];
        bp__dedge e[40], r[40];
        uint32_t n = 3 + rnd(30), k, start[2] = { 0, 0 };
        int lattice = i % 2;
        double step = 2 * 3.14159265358979 / n;
        for (k = 0; k < n; k++) {
            double ang = step * (k + bpt_rng_range(0.05, 0.95)), rad = bpt_rng_range(0.3, 1.0);
            uv[2 * k] = lattice ? floor(rad * cos(ang) * 64) / 64 : rad * cos(ang);
            uv[2 * k + 1] = lattice ? floor(rad * sin(ang) * 64) / 64 : rad * sin(ang);
        }
        for (k = 0; k < n; k++) {
            e[k].a = k; e[k].b = (k + 1) % n;
            r[k].a = (n - k) % n; r[k].b = (2 * n - k - 1) % n;
        }
        /* lattice rounding may make the polygon non-simple: use it only if
           bp_check says the fan around an added centre is valid */
        if (lattice) {
            double fan[2 * 41];
            uint32_t tri[3 * 40];
            memcpy(fan, uv, sizeof(double) * 2 * n);
            fan[2 * n] = 0; fan[2 * n + 1] = 0;
            for (k = 0; k < n; k++) { tri[3 * k] = n; tri[3 * k + 1] = k; tri[3 * k + 2] = (k + 1) % n; }
            {
                bp_check_report rep;
                if (bp_check(tri, n, fan, n + 1, NULL, &rep, NULL) != BP_OK) { skipped++; continue; }
            }
        }
        start[1] = n;
        if (bp__loop_sign(uv, e, n, NULL) != 1 || bp__loop_sign(uv, r, n, NULL) != -1 ||
            bp__ccw_loops(uv, e, start, 1) != 1 || bp__ccw_loops(uv, r, start, 1) != 0)
            wrong++;
    }
    BPT_CHECK(wrong == 0 && skipped < 200, "bp__loop_sign: +1 on %d random counter-clockwise simple polygons, -1 "
              "reversed (%d wrong; %d lattice polygons not simple after rounding, left out)", 2000 - skipped, wrong, skipped);
}

/* The line search's acceptance (bp__evaluate with `valid`) rejects a map
   whose loop count is wrong even though its triangles are positive and its
   boundary edges do not meet: a disk chart given its loop reversed (so the
   only loop runs clockwise).  The objective stays finite, so the rejection
   is the loop count's. */
static void acceptance_counts_loops(void)
{
    const uint32_t n = 6;
    bp_mesh m = bpt_mesh_new((n + 1) * (n + 1), 2 * n * n);
    bp_atlas at;
    bp_options opt;
    bp_error e;
    bp_allocator a;
    bp__solver S;
    bp_chart *ch;
    uint32_t i, j, nl;
    int valid = -1, valid_rev = -1;
    double ed, f, frev;
    memset(&opt, 0, sizeof opt);
    memset(&a, 0, sizeof a);
    for (j = 0; j <= n; j++)
        for (i = 0; i <= n; i++) {
            m.positions[3 * (j * (n + 1) + i)] = i;
            m.positions[3 * (j * (n + 1) + i) + 1] = j;
        }
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++) {
            uint32_t v = j * (n + 1) + i, t[6] = { v, v + 1, v + n + 2, v, v + n + 2, v + n + 1 };
            memcpy(m.triangles + 6 * (j * n + i), t, sizeof t);
        }
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &opt, &e) == BP_OK && bp_chart_init(&at.charts[0], &m, &opt, &e) == BP_OK,
                   "grid disk: chart and start map (%s)", e.message)) { bpt_mesh_free(&m); return; }
    ch = &at.charts[0];
    bp__solver_chart(&S, &a, ch, &m, &opt, NULL, NULL);
    f = bp__evaluate(&S, ch->uv, NULL, &ed, HUGE_VAL, &valid);
    bp__solver_free(&S);
    nl = ch->loop_start[1];
    for (i = 0; i < nl / 2; i++) {                 /* reverse the loop in place */
        uint32_t x = ch->loop_vertices[i];
        ch->loop_vertices[i] = ch->loop_vertices[nl - 1 - i];
        ch->loop_vertices[nl - 1 - i] = x;
    }
    bp__solver_chart(&S, &a, ch, &m, &opt, NULL, NULL);
    frev = bp__evaluate(&S, ch->uv, NULL, &ed, HUGE_VAL, &valid_rev);
    bp__solver_free(&S);
    BPT_CHECK(valid == 1 && f < HUGE_VAL, "the Tutte map of a grid disk is accepted by the line search's exact check");
    BPT_CHECK(valid_rev == 0 && frev < HUGE_VAL, "the same map with its only loop reversed (clockwise): finite "
              "objective (%g), positive triangles, no meeting edges, but rejected: no counter-clockwise loop", frev);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* bp_check_opt's options: NULL is the defaults (all cores), a struct_size
   of 8 bytes is refused and named, a set byte beyond this version's struct
   is refused; the verdict with good options is bp_check's. */
static void check_opt_args(void)
{
    static layout L;
    unsigned char big[sizeof(bp_options) + 16];
    bp_check_report r0, r;
    bp_error e0, e;
    bp_options o;
    bp_status s0, s;
    int i, same = 0;
    for (i = 0; i < 20; i++) {
        random_layout(&L, i % 3);
        s0 = bp_check(L.tri, L.nt, L.uv, L.nv, NULL, &r0, &e0);
        s = bp_check_opt(L.tri, L.nt, L.uv, L.nv, NULL, &r, &e);
        same += s == s0 && same_report(&r, &r0) && strcmp(e.message, e0.message) == 0;
    }
    BPT_CHECK(same == 20, "bp_check_opt with NULL options: bp_check's status, report and message (%d of 20)", same);
    bp_options_init(&o);
    o.struct_size = 8;
    s = bp_check_opt(L.tri, L.nt, L.uv, L.nv, &o, &r, &e);
    BPT_CHECK(s == BP_ERR_INVALID_ARGUMENT && bpt_has_number(e.message, 8), "bp_check_opt: struct_size 8 refused: %s",
              e.message);
    memset(big, 0, sizeof big);
    bp_options_init(&o);
    o.struct_size = sizeof big;
    memcpy(big, &o, sizeof o);
    big[sizeof(bp_options) + 5] = 1;
    s = bp_check_opt(L.tri, L.nt, L.uv, L.nv, (const bp_options *)(const void *)big, &r, &e);
    BPT_CHECK(s == BP_ERR_INVALID_ARGUMENT && bpt_has_number(e.message, (long long)sizeof(bp_options) + 5),
              "bp_check_opt: a set byte beyond this version's struct is refused, named: %s", e.message);
}

int main(void)
{
    bpt_rng_state = 0x5EED0C4ECull;
    check_opt_args();
    named_cases();
    random_agreement();
    overlapping_start();
    loop_signs();
    acceptance_counts_loops();
    conflict_scan_agreement();
    runners_start();
    par_random();
    par_meshes();
    runners_stop();
    return bpt_finish();
}
