/* test_build_threads.c - bp_atlas_build on several threads (>>charts, "the
   build on several threads").

   The build's tasks (the validation, the local defects, the duplicate and
   edge buckets, the gluing's decisions, the areas) must give the atlas of
   one thread, whatever runs them.  Here every pass goes through the runner
   (BP__PAR_MIN_TRIANGLES and BP__PAR_MIN_ITEMS are 1), and each build is
   compared with the serial one (opt.threads = 1) field by field -- the
   charts and their numbering, vertex maps and orders, triangles, loops,
   areas (bits), rest shapes, corner maps, the repair report with its
   messages, the status, the error and its message -- for the tasks run
   backwards, odd then even, and on pools of 2 and 3 threads:
     (a) real meshes: bishop, camelhead (22704 triangles: 12 triangle
         chunks, 8 vertex chunks), the cow and spot with their vt seams,
         fertility (closed, genus 4: cut), and camelhead with made-up vt
         seams (every seventh triangle a chart of its own: 3244 charts);
     (b) camelhead damaged after triangles 2500, 2600, 15000 and 21000
         (triangle chunks 1, 1, 7 and 11 of 12), or for duplicates at the
         ends of four vertex chunks (of 8), with one kind of defect
         each time -- a duplicate, a fin (a third triangle on an edge), a
         flipped triangle, a near-zero-area triangle (the last far out, so
         that it widens the box the area is measured against), one that
         repeats a vertex -- which is repaired by default, the repairs'
         first elements being those worked out here from the damage; and
         with opt.strict, where the error must name the first defect in
         the serial order, worked out here by brute force (the smallest
         triangle, key or edge), not the first one a task finds, and a
         near-zero area must be given relative to the box of the serial
         loop (bp__validate_global);
     (c) invalid meshes (a vertex index out of range, a NaN coordinate) at
         the same places: the error names the first in triangle order, and
         bp_parameterize (which validates before it builds, to rescale)
         gives the same error on any runner.
   Prints "BPTEST <passed> <failed>". */
#define _POSIX_C_SOURCE 200809L
#define BP__PAR_MIN_TRIANGLES 1u
#define BP__PAR_MIN_ITEMS     1u
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NDEF 4
static const uint32_t damage_at[NDEF] = { 2500, 2600, 15000, 21000 };   /* triangle chunks 1, 1, 7, 11 */

/* ---- comparing two builds ----------------------------------------------- */

static int same_u32(const uint32_t *a, const uint32_t *b, size_t n)
{
    return (!a && !b) || (a && b && !memcmp(a, b, n * sizeof *a));
}

static int same_chart(const bp_chart *a, const bp_chart *b)
{
    if (a->num_vertices != b->num_vertices || a->num_triangles != b->num_triangles || a->num_loops != b->num_loops ||
        a->split_vertices != b->split_vertices || a->cut_edges != b->cut_edges)
        return 0;
    if (!same_u32(a->vertex, b->vertex, a->num_vertices) || !same_u32(a->vertex_uv, b->vertex_uv, a->num_vertices) ||
        !same_u32(a->triangles, b->triangles, 3 * (size_t)a->num_triangles) ||
        !same_u32(a->face, b->face, a->num_triangles) || !same_u32(a->loop_start, b->loop_start, a->num_loops + 1) ||
        !same_u32(a->loop_vertices, b->loop_vertices, a->loop_start ? a->loop_start[a->num_loops] : 0))
        return 0;
    if (memcmp(&a->area3d, &b->area3d, sizeof a->area3d)) return 0;
    if ((a->rest_side == NULL) != (b->rest_side == NULL)) return 0;
    if (a->rest_side && memcmp(a->rest_side, b->rest_side, a->num_triangles * sizeof(double))) return 0;
    return a->error.status == b->error.status && !strcmp(a->error.message, b->error.message);
}

/* Everything bp_atlas_build gave: the status, the error, the atlas. */
static int same_build(bp_status sa, const bp_error *ea, const bp_atlas *a, bp_status sb, const bp_error *eb,
                      const bp_atlas *b)
{
    uint32_t c;
    if (sa != sb) return 0;
    if (sa != BP_OK)
        if (ea->status != eb->status || ea->element != eb->element || ea->index != eb->index ||
            ea->index2 != eb->index2 || ea->line != eb->line || strcmp(ea->message, eb->message))
            return 0;
    if (sa != BP_OK && sa != BP_ERR_CHARTS_FAILED) return 1;
    if (a->num_charts != b->num_charts || a->num_corners != b->num_corners || a->num_split != b->num_split ||
        a->num_failed != b->num_failed || memcmp(&a->repairs, &b->repairs, sizeof a->repairs))
        return 0;
    if (!same_u32(a->corner_chart, b->corner_chart, a->num_corners) ||
        !same_u32(a->corner_vertex, b->corner_vertex, a->num_corners))
        return 0;
    for (c = 0; c < a->num_charts; c++)
        if (!same_chart(&a->charts[c], &b->charts[c])) return 0;
    return 1;
}

/* The serial build (ref, ref_err, its status returned), then the same on
   every runner; returns how many runners differed, naming them in why. */
#define NRUN 4
static const char *const run_name[NRUN] = { "backwards", "odd-even", "2 threads", "3 threads" };

static bp_status build_with(int r, bp_atlas *at, const bp_mesh *m, int strict, bp_error *err)
{
    bp_options o;
    memset(&o, 0, sizeof o);
    o.strict = strict;
    if (r < 0) o.threads = 1;
    else if (r == 0) o.parallel_for = bpt_backwards_for;
    else if (r == 1) o.parallel_for = bpt_odd_even_for;
    else o.threads = r;
    memset(err, 0, sizeof *err);
    return bp_atlas_build(at, m, &o, err);
}

static int runners_differ(const bp_mesh *m, int strict, bp_atlas *ref, bp_error *ref_err, bp_status *ref_st,
                          char *why, size_t cap)
{
    int r, bad = 0;
    why[0] = 0;
    *ref_st = build_with(-1, ref, m, strict, ref_err);
    for (r = 0; r < NRUN; r++) {
        bp_atlas at;
        bp_error e;
        bp_status st = build_with(r, &at, m, strict, &e);
        if (!same_build(*ref_st, ref_err, ref, st, &e, &at)) {
            size_t len = strlen(why);
            snprintf(why + len, cap - len, "%s%s", bad ? ", " : " differ: ", run_name[r]);
            bad++;
        }
        bp_atlas_free(&at);
    }
    return bad;
}

/* ---- (a) real meshes ----------------------------------------------------- */

/* The charts of a clean mesh worked out here another way, to hold the
   serial build to: the corner edges sorted by qsort, two triangles joined
   across an edge they run along in opposite directions with the same uvs
   at both ends (a plain union-find over triangles and over corners), the
   charts numbered by their smallest triangle, the chart vertices by first
   appearance of their corner class, the areas added in triangle order.
   Returns 1 when the atlas's corner_chart, corner_vertex, vertex counts,
   pinch splits and areas (bits) are those. */
typedef struct cedge { uint32_t lo, hi, ce; } cedge;

static int cedge_cmp(const void *pa, const void *pb)
{
    const cedge *a = (const cedge *)pa, *b = (const cedge *)pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->ce < b->ce ? -1 : a->ce > b->ce;
}

static uint32_t root(uint32_t *p, uint32_t x)
{
    while (p[x] != x) x = p[x];
    return x;
}

static void join(uint32_t *p, uint32_t a, uint32_t b)
{
    a = root(p, a);
    b = root(p, b);
    if (a < b) p[b] = a; else p[a] = b;
}

static uint32_t uv_of(const bp_mesh *m, uint32_t c) { return m->corner_uv ? m->corner_uv[c] : 0; }

/* Pinch splits by brute force: per chart, its vertices beyond one per
   (mesh vertex, uv), from a qsort of the triples, against the chart's
   split_vertices (0 when they agree; a cut chart has more copies). */
typedef struct vtrip { uint32_t c, v, uv; } vtrip;

static int vtrip_cmp(const void *pa, const void *pb)
{
    const vtrip *a = (const vtrip *)pa, *b = (const vtrip *)pb;
    if (a->c != b->c) return a->c < b->c ? -1 : 1;
    if (a->v != b->v) return a->v < b->v ? -1 : 1;
    return a->uv < b->uv ? -1 : a->uv > b->uv;
}

static uint32_t split_count(const bp_atlas *at)
{
    uint32_t c, i, n = 0, w = 0, split = 0;
    vtrip *x;
    for (c = 0; c < at->num_charts; c++) n += at->charts[c].num_vertices;
    x = (vtrip *)malloc((n ? n : 1) * sizeof *x);
    for (c = 0; c < at->num_charts; c++)
        for (i = 0; i < at->charts[c].num_vertices && !at->charts[c].cut_edges; i++, w++) {
            x[w].c = c; x[w].v = at->charts[c].vertex[i]; x[w].uv = at->charts[c].vertex_uv[i];
        }
    qsort(x, w, sizeof *x, vtrip_cmp);
    for (i = 1; i < w; i++) split += !vtrip_cmp(&x[i], &x[i - 1]);
    for (c = 0; c < at->num_charts; c++) split -= at->charts[c].cut_edges ? 0 : at->charts[c].split_vertices;
    free(x);
    return split;
}

static int reference_charts(const bp_mesh *m, const bp_atlas *at)
{
    uint32_t nt = m->num_triangles, nc = 3 * nt, i, t, k, nchart = 0, ok = 1;
    cedge *e = (cedge *)malloc(nc * sizeof *e);
    uint32_t *tp = (uint32_t *)malloc(nt * sizeof *tp), *cp = (uint32_t *)malloc(nc * sizeof *cp);
    uint32_t *chart = (uint32_t *)malloc(nt * sizeof *chart), *vert = (uint32_t *)malloc(nc * sizeof *vert);
    uint32_t *count = (uint32_t *)calloc(nt, sizeof *count);
    double *area = (double *)calloc(nt, sizeof *area);
    for (t = 0; t < nt; t++) tp[t] = t;
    for (i = 0; i < nc; i++) {
        uint32_t a = m->triangles[i], b = m->triangles[i - i % 3 + (i % 3 + 1) % 3];
        cp[i] = i;
        e[i].lo = a < b ? a : b; e[i].hi = a < b ? b : a; e[i].ce = i;
    }
    qsort(e, nc, sizeof *e, cedge_cmp);
    for (i = 0; i + 1 < nc; i++) {
        uint32_t c0 = e[i].ce, c1 = e[i + 1].ce, n0 = c0 - c0 % 3 + (c0 % 3 + 1) % 3, n1 = c1 - c1 % 3 + (c1 % 3 + 1) % 3;
        if (e[i].lo != e[i + 1].lo || e[i].hi != e[i + 1].hi) continue;
        if (m->triangles[c0] != m->triangles[n1] || uv_of(m, c0) != uv_of(m, n1) || uv_of(m, n0) != uv_of(m, c1)) continue;
        join(tp, c0 / 3, c1 / 3);
        join(cp, c0, n1);
        join(cp, n0, c1);
    }
    for (t = 0; t < nt; t++) chart[t] = BP__NONE;
    for (i = 0; i < nc; i++) vert[i] = BP__NONE;
    for (t = 0; t < nt; t++) {
        uint32_t r = root(tp, t);
        if (chart[r] == BP__NONE) chart[r] = nchart++;
        for (k = 0; k < 3; k++) {
            uint32_t c = root(cp, 3 * t + k);
            if (vert[c] == BP__NONE) vert[c] = count[chart[r]]++;
            if (at->corner_chart[3 * t + k] != chart[r]) ok = 0;
            else if (!at->charts[chart[r]].cut_edges && at->corner_vertex[3 * t + k] != vert[c]) ok = 0;
        }
    }
    ok &= nchart == at->num_charts && split_count(at) == 0;
    for (t = 0; ok && t < nt; t++) {          /* the areas, added in each chart's triangle order */
        const double *p0 = m->positions + 3 * (size_t)m->triangles[3 * t], *p1 = m->positions + 3 * (size_t)m->triangles[3 * t + 1];
        const double *p2 = m->positions + 3 * (size_t)m->triangles[3 * t + 2];
        double u[3], v[3], n[3];
        for (k = 0; k < 3; k++) { u[k] = p1[k] - p0[k]; v[k] = p2[k] - p0[k]; }
        n[0] = u[1] * v[2] - u[2] * v[1]; n[1] = u[2] * v[0] - u[0] * v[2]; n[2] = u[0] * v[1] - u[1] * v[0];
        area[chart[root(tp, t)]] += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    for (i = 0; ok && i < nchart; i++) ok &= area[i] == at->charts[i].area3d;
    for (i = 0; ok && i < nchart; i++) ok &= at->charts[i].num_vertices == count[i] || at->charts[i].cut_edges > 0;
    free(e); free(tp); free(cp); free(chart); free(vert); free(count); free(area);
    return ok;
}

static void check_real(const char *path, const char *what, int seams7)
{
    bp_mesh m;
    bp_atlas ref;
    bp_error err, re;
    bp_status st;
    char why[200];
    uint32_t *uv = NULL, t, k;
    int bad;
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &err) == BP_OK, "read %s (%s)", path, err.message)) return;
    if (seams7) {            /* every seventh triangle its own uvs: its own chart */
        uv = (uint32_t *)malloc(3 * (size_t)m.num_triangles * sizeof *uv);
        for (t = 0; t < m.num_triangles; t++)
            for (k = 0; k < 3; k++) uv[3 * t + k] = m.triangles[3 * t + k] + (t % 7 == 0 ? m.num_vertices : 0);
        m.corner_uv = uv;
        m.num_uvs = 2 * m.num_vertices;
    }
    bad = runners_differ(&m, 0, &ref, &re, &st, why, sizeof why);
    BPT_CHECK(st == BP_OK && !bad, "%s (%u triangles, %u charts): every runner builds the serial atlas%s", what,
              m.num_triangles, ref.num_charts, why);
    if (st == BP_OK)
        BPT_CHECK(reference_charts(&m, &ref), "%s: the charts, corner maps, vertex counts, splits and areas of a plain "
                  "union-find over qsorted edges", what);
    bp_atlas_free(&ref);
    if (seams7) { m.corner_uv = NULL; m.num_uvs = 0; free(uv); }
    bp_mesh_free(&m, NULL);
}

/* ---- (b), (c) damaged camelhead ----------------------------------------- */

enum { D_DUP, D_FIN, D_FLIP, D_ZERO, D_REPEAT, D_INDEX, D_NAN, D_KINDS };
static const char *const kind_name[D_KINDS] = { "a duplicate", "a fin", "a flipped triangle",
                                                "a zero-area triangle", "a repeated vertex",
                                                "an index out of range", "a NaN" };

static void sorted3(const uint32_t *t, uint32_t *v);

typedef struct damage {
    bp_mesh m;                  /* owns positions and triangles            */
    uint32_t at[NDEF];          /* the new index of each damaged triangle   */
    uint32_t orig[NDEF];        /* duplicate: the new index of the original */
    uint32_t lo[NDEF], hi[NDEF];/* fin: its edge                            */
} damage;

static void damage_free(damage *d)
{
    free(d->m.positions);
    free(d->m.triangles);
}

/* Where to damage: damage_at[], or for duplicates the first triangle
   whose smallest vertex is the last of its vertex chunk, in the first four
   chunks where there is one (the chunks of the library's buckets: the
   edge of a chunk is where a task could stop short), or for flips the
   first at or after damage_at[] whose vertices are all beyond the first
   vertex chunk (no flag of chunk 0 may stand for them). */
static void damage_where(const bp_mesh *m, int kind, uint32_t *at)
{
    uint32_t nv = m->num_vertices, size = nv / BP__BUILD_TASKS + 1, j, t, c;
    uint32_t nch = bp__nchunks(nv, size > BP__TRI_CHUNK ? size : BP__TRI_CHUNK);
    for (j = 0; j < NDEF; j++) at[j] = damage_at[j];
    if (kind == 2) {                                 /* flips: off the first vertex chunk */
        for (j = 0; j < NDEF; j++) {
            uint32_t v[3];
            for (t = at[j]; t < m->num_triangles; t++) {
                sorted3(m->triangles + 3 * (size_t)t, v);
                if (v[0] >= bp__chunk_at(nv, nch, 1)) break;
            }
            at[j] = t;
        }
        return;
    }
    if (kind != 0) return;
    for (j = 0, c = 1; j < NDEF && c <= nch; c++) {  /* chunks whose last vertex is some triangle's smallest */
        uint32_t last = bp__chunk_at(nv, nch, c) - 1, v[3];
        for (t = 0; t < m->num_triangles; t++) {
            sorted3(m->triangles + 3 * (size_t)t, v);
            if (v[0] == last) break;
        }
        if (t < m->num_triangles) at[j++] = t;
    }
    for (j = 1; j < NDEF; j++)                       /* in triangle order */
        for (t = j; t > 0 && at[t - 1] > at[t]; t--) { uint32_t x = at[t]; at[t] = at[t - 1]; at[t - 1] = x; }
}

/* m with `kind` at each place of damage_where (an added triangle goes
   right after). */
static void damage_make(damage *d, const bp_mesh *m, int kind)
{
    uint32_t t, j = 0, nt = 0, nv = m->num_vertices, where[NDEF];
    double *p = (double *)malloc(3 * ((size_t)nv + 3 * NDEF) * sizeof *p);
    uint32_t *tri = (uint32_t *)malloc(3 * ((size_t)m->num_triangles + NDEF) * sizeof *tri);
    memset(d, 0, sizeof *d);
    damage_where(m, kind, where);
    memcpy(p, m->positions, 3 * (size_t)nv * sizeof *p);
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *s = m->triangles + 3 * (size_t)t;
        uint32_t *q = tri + 3 * (size_t)nt;
        memcpy(q, s, 3 * sizeof *q);
        nt++;
        if (j == NDEF || t != where[j]) continue;
        d->at[j] = nt - 1;
        if (kind == D_FLIP) { q[1] = s[2]; q[2] = s[1]; }
        if (kind == D_INDEX) q[1] = nv + 7 + j;
        if (kind == D_NAN) p[3 * (size_t)s[2] + 1] = NAN;
        if (kind == D_DUP || kind == D_FIN || kind == D_ZERO || kind == D_REPEAT) {
            uint32_t *r = tri + 3 * (size_t)nt;
            d->orig[j] = nt - 1;
            d->at[j] = nt;
            if (kind == D_DUP) { r[0] = s[1]; r[1] = s[2]; r[2] = s[0]; }
            if (kind == D_REPEAT) { r[0] = s[0]; r[1] = s[1]; r[2] = s[0]; }
            if (kind == D_FIN) {        /* a third triangle on edge s0-s1, to a new vertex above it */
                uint32_t w = nv++, k;
                for (k = 0; k < 3; k++)
                    p[3 * (size_t)w + k] = (m->positions[3 * (size_t)s[0] + k] + m->positions[3 * (size_t)s[1] + k]) / 2 + 0.01 * (k + 1);
                r[0] = s[0]; r[1] = s[1]; r[2] = w;
                d->lo[j] = s[0] < s[1] ? s[0] : s[1];
                d->hi[j] = s[0] < s[1] ? s[1] : s[0];
            }
            if (kind == D_ZERO) {       /* three new points on a line: a zero-area triangle of its own */
                uint32_t k, i;
                for (i = 0; i < 3; i++)
                    for (k = 0; k < 3; k++) p[3 * ((size_t)nv + i) + k] = m->positions[3 * (size_t)s[0] + k] + 0.001 * i;
                p[3 * ((size_t)nv + 1)] += 1e-12;     /* a near-zero area, which the message gives */
                if (j == NDEF - 1)                    /* the last one far out: it widens the box */
                    for (i = 0; i < 9; i++) p[3 * (size_t)nv + i] += 50;
                r[0] = nv; r[1] = nv + 1; r[2] = nv + 2;
                nv += 3;
            }
            nt++;
        }
        j++;
    }
    d->m.positions = p;
    d->m.triangles = tri;
    d->m.num_vertices = nv;
    d->m.num_triangles = nt;
}

static int key_less(const uint32_t *a, const uint32_t *b)
{
    return a[0] != b[0] ? a[0] < b[0] : a[1] != b[1] ? a[1] < b[1] : a[2] < b[2];
}

static void sorted3(const uint32_t *t, uint32_t *v)
{
    uint32_t x;
    v[0] = t[0]; v[1] = t[1]; v[2] = t[2];
    if (v[0] > v[1]) { x = v[0]; v[0] = v[1]; v[1] = x; }
    if (v[1] > v[2]) { x = v[1]; v[1] = v[2]; v[2] = x; }
    if (v[0] > v[1]) { x = v[0]; v[0] = v[1]; v[1] = x; }
}

/* Triangles of m on edge (a, b), by brute force. */
static uint32_t on_edge(const bp_mesh *m, uint32_t a, uint32_t b)
{
    uint32_t t, k, n = 0;
    for (t = 0; t < m->num_triangles; t++) {
        int ha = 0, hb = 0;
        for (k = 0; k < 3; k++) { ha |= m->triangles[3 * t + k] == a; hb |= m->triangles[3 * t + k] == b; }
        n += ha && hb;
    }
    return n;
}

/* The error strict mode must give, by brute force: status, index, index2. */
static void expected_error(const damage *d, int kind, bp_status *st, int64_t *i1, int64_t *i2)
{
    const bp_mesh *m = &d->m;
    uint32_t j, k, t, best = 0, key[3], bk[3], lo = BP__NONE, hi = BP__NONE;
    *i2 = -1;
    switch (kind) {
    case D_DUP:                 /* the copy with the smallest sorted key, and its original */
        for (j = 0; j < NDEF; j++) {
            sorted3(m->triangles + 3 * (size_t)d->at[j], key);
            if (j == 0 || key_less(key, bk)) { memcpy(bk, key, sizeof key); best = j; }
        }
        *st = BP_ERR_DUPLICATE_FACE; *i1 = d->at[best]; *i2 = d->orig[best];
        return;
    case D_FIN:                 /* the smallest fin edge */
        for (j = 0; j < NDEF; j++)
            if (d->lo[j] < lo || (d->lo[j] == lo && d->hi[j] < hi)) { lo = d->lo[j]; hi = d->hi[j]; }
        *st = BP_ERR_NONMANIFOLD; *i1 = lo; *i2 = hi;
        return;
    case D_FLIP:                /* the smallest interior edge of a flipped triangle */
        for (j = 0; j < NDEF; j++)
            for (k = 0; k < 3; k++) {
                uint32_t a = m->triangles[3 * (size_t)d->at[j] + k], b = m->triangles[3 * (size_t)d->at[j] + (k + 1) % 3];
                uint32_t l = a < b ? a : b, h = a < b ? b : a;
                if (on_edge(m, a, b) == 2 && (l < lo || (l == lo && h < hi))) { lo = l; hi = h; }
            }
        *st = BP_ERR_ORIENTATION; *i1 = lo; *i2 = hi;
        return;
    case D_ZERO: case D_REPEAT:
        *st = BP_ERR_DEGENERATE; *i1 = d->at[0];
        return;
    case D_INDEX:
        *st = BP_ERR_INDEX; *i1 = d->at[0];
        return;
    default:                    /* D_NAN: the first triangle on a NaN vertex, and that vertex */
        for (t = 0; t < m->num_triangles; t++)
            for (k = 0; k < 3; k++) {
                uint32_t v = m->triangles[3 * t + k];
                if (isnan(m->positions[3 * (size_t)v + 1])) { *st = BP_ERR_NONFINITE; *i1 = v; return; }
            }
    }
}

/* The repairs the default build must report for `kind`. */
static int expected_repairs(const damage *d, int kind, const bp_repair_report *r)
{
    const bp_repair *p;
    uint32_t j, i, ord[NDEF];
    int ok = 1;
    if (kind == D_FIN) {                              /* edges in (lo, hi) order */
        for (j = 0; j < NDEF; j++) ord[j] = j;
        for (j = 1; j < NDEF; j++)
            for (i = j; i > 0 && (d->lo[ord[i - 1]] > d->lo[ord[i]] ||
                                  (d->lo[ord[i - 1]] == d->lo[ord[i]] && d->hi[ord[i - 1]] > d->hi[ord[i]])); i--) {
                uint32_t x = ord[i]; ord[i] = ord[i - 1]; ord[i - 1] = x;
            }
        p = &r->kind[BP_REPAIR_NONMANIFOLD_EDGE];
        for (j = 0; j < NDEF; j++) ok &= p->first[j] == d->lo[ord[j]] && p->first2[j] == d->hi[ord[j]];
        return ok && p->count == NDEF && r->total == NDEF;
    }
    p = &r->kind[kind == D_DUP ? BP_REPAIR_DUPLICATE : kind == D_FLIP ? BP_REPAIR_FLIPPED : BP_REPAIR_DEGENERATE];
    for (j = 0; j < NDEF; j++)
        ok &= p->first[j] == d->at[j] && p->first2[j] == (kind == D_DUP ? (int64_t)d->orig[j] : -1);
    return ok && p->count == NDEF && r->total == NDEF;
}

static void check_damaged(const bp_mesh *clean, int kind)
{
    damage d;
    bp_atlas ref;
    bp_error re;
    bp_status st, want_st = BP_OK;
    int64_t i1 = -1, i2 = -1;
    char why[200];
    int bad, strict;
    damage_make(&d, clean, kind);
    for (strict = 0; strict < 2; strict++) {
        if (!strict && kind >= D_INDEX) continue;     /* invalid input is an error in both modes */
        bad = runners_differ(&d.m, strict, &ref, &re, &st, why, sizeof why);
        if (!strict && kind < D_INDEX) {
            BPT_CHECK(st == BP_OK && !bad && expected_repairs(&d, kind, &ref.repairs),
                      "camelhead, %s at 4 places in 3 or 4 chunks, repaired: every runner builds the serial atlas%s; the "
                      "repairs name the damaged elements (%s)", kind_name[kind], why,
                      ref.repairs.total ? ref.repairs.kind[kind == D_FIN ? BP_REPAIR_NONMANIFOLD_EDGE : kind == D_DUP ? BP_REPAIR_DUPLICATE : kind == D_FLIP ? BP_REPAIR_FLIPPED : BP_REPAIR_DEGENERATE].message : "none");
        } else {
            bp__mesh_scale sc;
            bp_error se;
            int same_msg = 1;
            expected_error(&d, kind, &want_st, &i1, &i2);
            if (kind == D_ZERO) {    /* the ratio in the message needs the serial loop's box (bp__validate_global) */
                same_msg = bp__validate_global(&d.m, &sc, NULL) == BP_OK &&
                           bp__tri_defect_error(&d.m, (uint32_t)i1, &sc, &se) == BP_ERR_DEGENERATE &&
                           !strcmp(se.message, re.message);
            }
            BPT_CHECK(st == want_st && re.index == i1 && re.index2 == i2 && !bad && same_msg,
                      "camelhead, %s at 4 places in 3 or 4 chunks%s: every runner gives the serial error%s, the first in "
                      "the serial order (%lld %lld): %s", kind_name[kind], strict ? ", strict" : "", why,
                      (long long)i1, (long long)i2, re.message);
        }
        if (kind >= D_INDEX) {      /* bp_parameterize validates first (bp__rescaled_mesh, serial): the same error */
            int r, same = 0;
            for (r = 0; r < 4; r++) {
                bp_options o;
                bp_atlas at;
                bp_error e;
                bp_status ps;
                bp_options_init(&o);
                o.max_iterations = 1;
                if (r < 3) o.threads = r + 1; else o.parallel_for = bpt_backwards_for;
                ps = bp_parameterize(&at, &d.m, &o, &e);
                same += ps == st && e.index == re.index && e.index2 == re.index2 && !strcmp(e.message, re.message);
                if (ps == BP_OK || ps == BP_ERR_CHARTS_FAILED || ps == BP_ERR_CANCELLED) bp_atlas_free(&at);
            }
            BPT_CHECK(same == 4, "camelhead, %s: bp_parameterize on 1, 2, 3 threads and backwards gives bp_atlas_build's "
                      "error (%d of 4)", kind_name[kind], same);
        }
        bp_atlas_free(&ref);
    }
    damage_free(&d);
}

int main(void)
{
    bp_mesh cam;
    bp_error err;
    int kind;
    check_real("tests/data/bishop_part_f1000.obj", "bishop", 0);
    check_real("tests/data/camelhead.off", "camelhead", 0);
    check_real("tests/data/cow_param_withSUV.obj", "the cow with its vt seam", 0);
    check_real("tests/data/spot.obj", "spot with its 13 vt charts", 0);
    check_real("tests/data/fertility.off", "fertility (closed, genus 4: cut)", 0);
    check_real("tests/data/camelhead.off", "camelhead, every seventh triangle its own vt chart", 1);
    if (BPT_CHECK(bp_read_mesh("tests/data/camelhead.off", &cam, NULL, &err) == BP_OK, "read camelhead (%s)",
                  err.message)) {
        for (kind = 0; kind < D_KINDS; kind++) check_damaged(&cam, kind);
        bp_mesh_free(&cam, NULL);
    }
    return bpt_finish();
}
