/* test_pack.c - the outline packer (>>pack), checked from outside.

   Every packed atlas here is checked by brute force, independently of the
   packer's own reasoning:
   - all UVs finite and in [0,1];
   - padding: the smallest distance between boundary segments of two
     different charts, over all pairs, is at least padding / RES (and > 0
     with padding 0);
   - border: every uv is at least ceil(padding / 2) / RES from each edge
     of the square (min(u, 1 - u, v, 1 - v) over all uvs, exact in double:
     no tolerance), so the atlas tiled with wrap-around keeps the padding
     across its edges too;
   - no overlap: every triangle positively oriented (exact orient2d), and no
     vertex of one chart inside or on a triangle of another, which with
     disjoint boundaries rules out any overlap; and the library's own exact
     whole-atlas check (bp__atlas_verify) agrees;
   - the reported utilization equals the shoelace area of all triangles;
   - one texel density: UV area / 3D area is the same for every chart;
   - 1 and 2 threads give bit-identical atlases.
   And, inside: a bijective chart's raster made from its boundary loops
   (bp__raster_outline) is bit for bit the raster of its triangles, on the
   solved maps of face_holes (one chart, seven loops) and spot at sizes
   from 40 to 1,500 texels, rotated and shifted by fractions of a texel.
   The charts are small planar pieces (triangles, rectangles, L-shapes, thin
   strips, a square with a hole) at arbitrary angles. */
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

/* bp__atlas_verify's runner: the serial loop. */
static const bp__par serial_par = { bp__serial_for, NULL, 1 };
#include "bpt_grid.h"
#include <math.h>


/* n charts of assorted shapes; uv (when asked) = the x, y of each vertex. */
static bp_mesh make_charts(int n, int with_uv)
{
    bpt_gen g;
    bp_mesh m = bpt_mesh_new(60 * (uint32_t)n, 80 * (uint32_t)n);
    int k;
    g.pos = m.positions; g.tri = m.triangles; g.nv = 0; g.nt = 0;
    for (k = 0; k < n; k++) {
        int kind = k % 5;
        double a = bpt_rng_range(0, 6.283185307179586), s = bpt_rng_range(0.5, 1.5), ox = (k % 10) * 20.0, oy = (k / 10) * 20.0;
        if (kind == 0) bpt_add_grid(&g, 1 + k % 3, 1 + k % 2, 0, s, a, ox, oy);
        else if (kind == 1) bpt_add_grid(&g, 4, 4, 1, s * 0.7, a, ox, oy);
        else if (kind == 2) bpt_add_grid(&g, 3, 3, 2, s * 0.8, a, ox, oy);
        else if (kind == 3) bpt_add_grid(&g, 8, 1, 0, s * 0.5, a, ox, oy);
        else {
            uint32_t b = g.nv;
            g.pos[3 * b] = ox; g.pos[3 * b + 1] = oy;
            g.pos[3 * b + 3] = ox + 2 * s * cos(a); g.pos[3 * b + 4] = oy + 2 * s * sin(a);
            g.pos[3 * b + 6] = ox + s * cos(a + 1); g.pos[3 * b + 7] = oy + s * sin(a + 1);
            g.nv += 3;
            g.tri[3 * g.nt] = b; g.tri[3 * g.nt + 1] = b + 1; g.tri[3 * g.nt + 2] = b + 2; g.nt++;
        }
    }
    m.num_vertices = g.nv; m.num_triangles = g.nt; m.num_faces = g.nt;
    if (with_uv) {
        m.corner_uv = (uint32_t *)malloc(sizeof(uint32_t) * 3 * g.nt);
        m.uvs = (double *)malloc(sizeof(double) * 2 * g.nv);
        m.num_uvs = g.nv;
        memcpy(m.corner_uv, m.triangles, sizeof(uint32_t) * 3 * g.nt);
        for (k = 0; k < (int)g.nv; k++) { m.uvs[2 * k] = m.positions[3 * k]; m.uvs[2 * k + 1] = m.positions[3 * k + 1]; }
    }
    return m;
}

static double pt_seg(const double *p, const double *a, const double *b)
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy, t = 0, x, y;
    if (l2 > 0) t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    x = a[0] + t * dx - p[0]; y = a[1] + t * dy - p[1];
    return sqrt(x * x + y * y);
}

static double seg_seg(const double *a, const double *b, const double *c, const double *d)
{
    double m;
    if (bp_segments_intersect(a, b, c, d)) return 0;
    m = pt_seg(a, c, d);
    if (pt_seg(b, c, d) < m) m = pt_seg(b, c, d);
    if (pt_seg(c, a, b) < m) m = pt_seg(c, a, b);
    if (pt_seg(d, a, b) < m) m = pt_seg(d, a, b);
    return m;
}

/* Boundary edges of a chart: directed edges whose reverse is absent. */
static uint32_t boundary_edges(const bp_chart *ch, uint32_t *out)
{
    uint32_t t, k, u, l, n = 0;
    for (t = 0; t < ch->num_triangles; t++)
        for (k = 0; k < 3; k++) {
            uint32_t a = ch->triangles[3 * t + k], b = ch->triangles[3 * t + (k + 1) % 3];
            int twin = 0;
            for (u = 0; u < ch->num_triangles && !twin; u++)
                for (l = 0; l < 3; l++)
                    if (ch->triangles[3 * u + l] == b && ch->triangles[3 * u + (l + 1) % 3] == a) twin = 1;
            if (!twin) { out[2 * n] = a; out[2 * n + 1] = b; n++; }
        }
    return n;
}

/* Closed point-in-triangle with exact orientation. */
static int in_triangle(const double *p, const double *a, const double *b, const double *c)
{
    return bp_orient2d(a, b, p) >= 0 && bp_orient2d(b, c, p) >= 0 && bp_orient2d(c, a, p) >= 0;
}

/* The brute-force checks of the header comment on one packed atlas. */
static void check_atlas(const char *what, const bp_atlas *at, int res, int pad, int same_density)
{
    uint32_t c, d, i, t, e, f, bad_range = 0, flipped = 0, inside = 0;
    uint32_t **be = (uint32_t **)calloc(at->num_charts, sizeof *be), *nb = (uint32_t *)calloc(at->num_charts, sizeof *nb);
    double mind = HUGE_VAL, area = 0, rmin = HUGE_VAL, rmax = 0, border = HUGE_VAL, want_border = ((pad + 1) / 2) / (double)res;
    bp_error err;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        double ca = 0;
        if (!ch->uv) continue;
        for (i = 0; i < 2 * ch->num_vertices; i++) {
            if (!(ch->uv[i] >= 0 && ch->uv[i] <= 1)) bad_range++;
            if (ch->uv[i] < border) border = ch->uv[i];
            if (1 - ch->uv[i] < border) border = 1 - ch->uv[i];
        }
        for (t = 0; t < ch->num_triangles; t++) {
            const double *p0 = ch->uv + 2 * ch->triangles[3 * t], *p1 = ch->uv + 2 * ch->triangles[3 * t + 1], *p2 = ch->uv + 2 * ch->triangles[3 * t + 2];
            if (bp_orient2d(p0, p1, p2) <= 0) flipped++;
            ca += 0.5 * ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]));
        }
        area += ca;
        if (ca / ch->area3d < rmin) rmin = ca / ch->area3d;
        if (ca / ch->area3d > rmax) rmax = ca / ch->area3d;
        be[c] = (uint32_t *)malloc(sizeof(uint32_t) * 6 * ch->num_triangles + 1);
        nb[c] = boundary_edges(ch, be[c]);
    }
    for (c = 0; c < at->num_charts; c++)
        for (d = c + 1; d < at->num_charts; d++) {
            const bp_chart *A = &at->charts[c], *B = &at->charts[d];
            if (!A->uv || !B->uv) continue;
            for (e = 0; e < nb[c]; e++)
                for (f = 0; f < nb[d]; f++) {
                    double s = seg_seg(A->uv + 2 * be[c][2 * e], A->uv + 2 * be[c][2 * e + 1],
                                       B->uv + 2 * be[d][2 * f], B->uv + 2 * be[d][2 * f + 1]);
                    if (s < mind) mind = s;
                }
            for (i = 0; i < A->num_vertices; i++)          /* A's vertices in B's triangles */
                for (t = 0; t < B->num_triangles; t++)
                    inside += in_triangle(A->uv + 2 * i, B->uv + 2 * B->triangles[3 * t], B->uv + 2 * B->triangles[3 * t + 1], B->uv + 2 * B->triangles[3 * t + 2]);
            for (i = 0; i < B->num_vertices; i++)
                for (t = 0; t < A->num_triangles; t++)
                    inside += in_triangle(B->uv + 2 * i, A->uv + 2 * A->triangles[3 * t], A->uv + 2 * A->triangles[3 * t + 1], A->uv + 2 * A->triangles[3 * t + 2]);
        }
    BPT_CHECK(bad_range == 0, "%s: every uv in [0,1] (%u outside)", what, bad_range);
    BPT_CHECK(flipped == 0, "%s: every triangle positively oriented (%u not)", what, flipped);
    BPT_CHECK(inside == 0, "%s: no vertex of a chart inside another chart (%u are)", what, inside);
    if (pad > 0)
        BPT_CHECK(mind >= pad / (double)res * (1 - 1e-9), "%s: boundary distance between charts %.6g >= padding %d / %d = %.6g",
                  what, mind, pad, res, pad / (double)res);
    else
        BPT_CHECK(mind > 0, "%s: charts apart with padding 0 (distance %.3g)", what, mind);
    BPT_CHECK(border >= want_border, "%s: every uv %.9g texels or more from the edge of the square (>= ceil(%d / 2))",
              what, border * res, pad);
    BPT_CHECK(bp__atlas_verify(at, &serial_par, &err) == BP_OK, "%s: the whole atlas passes the exact check", what);
    BPT_CHECK(fabs(at->utilization - area) <= 1e-12 * area, "%s: utilization %.15g == shoelace area %.15g", what,
              at->utilization, area);
    if (same_density)
        BPT_CHECK(rmax <= rmin * (1 + 1e-9), "%s: one texel density (uv/3D area from %.12g to %.12g)", what, rmin, rmax);
    for (c = 0; c < at->num_charts; c++) free(be[c]);
    free(be); free(nb);
}

/* Pack n charts (their maps taken from x, y) at res/pad. */
static bp_status pack_input(bp_mesh *m, bp_atlas *at, int res, int pad, int no_rotation, bp_error *err)
{
    bp_options o;
    bp_status st;
    memset(&o, 0, sizeof o);
    o.atlas_resolution = res;
    o.padding = pad;
    o.no_rotation = no_rotation;
    st = bp_atlas_build(at, m, &o, err);
    if (st == BP_OK) st = bp_atlas_use_input_uvs(at, m, err);
    if (st == BP_OK) st = bp_atlas_pack(at, &o, err);
    return st;
}

static void test_padding_and_validity(void)
{
    static const int cases[][3] = { { 40, 64, 3 }, { 40, 128, 2 }, { 25, 96, 0 }, { 12, 50, 5 } };
    unsigned k;
    for (k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        bp_mesh m = make_charts(cases[k][0], 1);
        bp_atlas at;
        bp_error err;
        char what[80];
        bp_status st = pack_input(&m, &at, cases[k][1], cases[k][2], 0, &err);
        snprintf(what, sizeof what, "%d charts at %d px, padding %d", cases[k][0], cases[k][1], cases[k][2]);
        BPT_CHECK(st == BP_OK, "%s: packed (%s)", what, st == BP_OK ? "ok" : err.message);
        if (st == BP_OK) check_atlas(what, &at, cases[k][1], cases[k][2], 1);
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
}

/* A thin strip (10 x 1) at 30 degrees, alone in the square atlas: turning
   it (onto the diagonal, its smallest bounding square) must pack it denser
   than its own orientation, where its bounding box is mostly empty. */
static void test_rotation(void)
{
    bpt_gen g;
    bp_mesh m = bpt_mesh_new(40, 40);
    bp_atlas a1, a2;
    bp_error err;
    bp_status s1, s2;
    g.pos = m.positions; g.tri = m.triangles; g.nv = 0; g.nt = 0;
    bpt_add_grid(&g, 10, 1, 0, 1.0, 0.5235987755982988, 0, 0);
    m.num_vertices = g.nv; m.num_triangles = g.nt; m.num_faces = g.nt;
    m.corner_uv = (uint32_t *)malloc(sizeof(uint32_t) * 3 * g.nt);
    m.uvs = (double *)malloc(sizeof(double) * 2 * g.nv);
    m.num_uvs = g.nv;
    memcpy(m.corner_uv, m.triangles, sizeof(uint32_t) * 3 * g.nt);
    for (g.nv = 0; g.nv < m.num_vertices; g.nv++) { m.uvs[2 * g.nv] = m.positions[3 * g.nv]; m.uvs[2 * g.nv + 1] = m.positions[3 * g.nv + 1]; }
    s1 = pack_input(&m, &a1, 256, 2, 0, &err);
    s2 = pack_input(&m, &a2, 256, 2, 1, &err);
    BPT_CHECK(s1 == BP_OK && s2 == BP_OK, "strip packed with and without rotation");
    if (s1 == BP_OK && s2 == BP_OK) {
        BPT_CHECK(a1.utilization > 1.2 * a2.utilization, "rotated strip utilization %.3f > 1.2 x unrotated %.3f",
                  a1.utilization, a2.utilization);
        check_atlas("rotated strip", &a1, 256, 2, 1);
        check_atlas("unrotated strip", &a2, 256, 2, 1);
    }
    bp_atlas_free(&a1); bp_atlas_free(&a2);
    bpt_mesh_free(&m);
}

/* bp_parameterize with the packer: 1 and 2 threads, bit-identical. */
static void test_threads(void)
{
    bp_mesh m = make_charts(12, 0);
    bp_atlas a[2];
    bp_options o;
    bp_error err;
    int k, same = 1;
    uint32_t c;
    for (k = 0; k < 2; k++) {
        memset(&o, 0, sizeof o);
        o.atlas_resolution = 128;
        o.padding = 2;
        o.threads = k + 1;
        BPT_CHECK(bp_parameterize(&a[k], &m, &o, &err) == BP_OK, "parameterize + pack with %d thread(s)", k + 1);
    }
    for (c = 0; c < a[0].num_charts && c < a[1].num_charts; c++)
        if (!a[0].charts[c].uv || !a[1].charts[c].uv ||
            memcmp(a[0].charts[c].uv, a[1].charts[c].uv, 2 * sizeof(double) * a[0].charts[c].num_vertices)) same = 0;
    BPT_CHECK(same && a[0].num_charts == a[1].num_charts && a[0].utilization == a[1].utilization,
              "1 and 2 threads: bit-identical atlas (%u charts, utilization %.4f)", a[0].num_charts, a[0].utilization);
    check_atlas("optimized charts", &a[0], 128, 2, 0);
    bp_atlas_free(&a[0]); bp_atlas_free(&a[1]);
    bpt_mesh_free(&m);
}

/* Bad options and an atlas too small are errors, and leave the maps alone. */
static void test_errors(void)
{
    bp_mesh m = make_charts(30, 1);
    bp_atlas at;
    bp_options o;
    bp_error err;
    bp_status st;
    double keep;
    memset(&o, 0, sizeof o);
    st = bp_atlas_build(&at, &m, &o, &err);
    if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &err);
    BPT_CHECK(st == BP_OK, "charts from the input uvs");
    if (st != BP_OK) { bpt_mesh_free(&m); return; }
    keep = at.charts[3].uv[1];
    o.atlas_resolution = 64; o.padding = -1;
    BPT_CHECK(bp_atlas_pack(&at, &o, &err) == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, -1),
              "padding -1 rejected: %s", err.message);
    o.atlas_resolution = -5; o.padding = 0;
    BPT_CHECK(bp_atlas_pack(&at, &o, &err) == BP_ERR_INVALID_ARGUMENT, "resolution -5 rejected: %s", err.message);
    o.atlas_resolution = 8; o.padding = 2;
    st = bp_atlas_pack(&at, &o, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, 30) && bpt_has_number(err.message, 8),
              "30 charts in 8 x 8 with padding 2: an error naming both (%s)", err.message);
    BPT_CHECK(at.charts[3].uv[1] == keep, "a failed packing leaves the maps as they were");
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* --repack: a chart whose input map is mirrored is reported by its
   triangle (1-based) and not packed; the others are packed and valid. */
static void test_repack(void)
{
    bp_mesh m = make_charts(10, 1);
    bp_atlas at;
    bp_options o;
    bp_error err;
    bp_status st;
    uint32_t c, bad;
    memset(&o, 0, sizeof o);
    st = bp_atlas_build(&at, &m, &o, &err);
    BPT_CHECK(st == BP_OK, "charts built");
    if (st != BP_OK) { bpt_mesh_free(&m); return; }
    for (c = 0; c < at.charts[4].num_vertices; c++) m.uvs[2 * at.charts[4].vertex_uv[c]] *= -1;   /* mirrored */
    bad = at.charts[4].face[0];
    st = bp_atlas_use_input_uvs(&at, &m, &err);
    BPT_CHECK(st == BP_ERR_CHARTS_FAILED && at.num_failed == 1 && at.charts[4].error.status == BP_ERR_NOT_BIJECTIVE,
              "the mirrored chart fails (%s)", at.charts[4].error.message);
    BPT_CHECK(bpt_has_number(at.charts[4].error.message, (long long)bad + 1) && bpt_has_number(at.charts[4].error.message, 4),
              "its message names chart 4 and triangle %u: %s", bad + 1, at.charts[4].error.message);
    o.atlas_resolution = 128; o.padding = 3;
    st = bp_atlas_pack(&at, &o, &err);
    BPT_CHECK(st == BP_OK && at.charts[4].uv == NULL, "the other charts pack (%s)", st == BP_OK ? "ok" : err.message);
    if (st == BP_OK) check_atlas("repacked", &at, 128, 3, 1);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* Out of memory at every allocation of bp_atlas_pack in turn: the call
   returns BP_ERR_OUT_OF_MEMORY, frees what it took, and leaves the maps as
   they were; with no failure it packs. */
static void test_out_of_memory(void)
{
    bp_mesh m = make_charts(8, 1);
    bp_options o;
    bp_error err;
    bpt_oom counter;
    long k, total = 0, wrong = 0, leaks = 0, moved = 0;
    memset(&o, 0, sizeof o);
    bpt_oom_use(&o, &counter);
    for (k = 0;; k++) {
        bp_atlas at;
        bp_status st;
        long before;
        double keep;
        counter.fail_at = 0;
        st = bp_atlas_build(&at, &m, &o, &err);
        if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &err);
        if (st != BP_OK) { BPT_CHECK(0, "set-up for the out-of-memory sweep: %s", err.message); break; }
        o.atlas_resolution = 64; o.padding = 2;
        keep = at.charts[5].uv[0];
        before = counter.live;
        counter.calls = 0;
        counter.fail_at = k;
        st = bp_atlas_pack(&at, &o, &err);
        if (k == 0) {
            total = counter.calls;
            BPT_CHECK(st == BP_OK, "without a failure the pack succeeds (%ld allocations)", total);
        } else {
            if (st != BP_ERR_OUT_OF_MEMORY) wrong++;
            if (counter.live != before) leaks++;
            if (at.charts[5].uv[0] != keep) moved++;
        }
        o.atlas_resolution = 0; o.padding = 0;
        bp_atlas_free(&at);
        if (k > 0 && k >= total) break;
    }
    BPT_CHECK(total > 0 && wrong == 0 && leaks == 0 && moved == 0,
              "failing each of the %ld allocations of bp_atlas_pack: out of memory every time (%ld not), "
              "no leak (%ld leaked), maps unchanged (%ld moved)", total, wrong, leaks, moved);
    bpt_mesh_free(&m);
}

/* A 200 x 1 strip among small charts: at the first densities it is far
   wider than the atlas (those orientations must be skipped, not
   allocated), and it ends on the diagonal or along a side. */
static void test_long_strip(void)
{
    bpt_gen g;
    bp_mesh m = bpt_mesh_new(2000, 2000);
    bp_atlas at;
    bp_error err;
    bp_status st;
    int k;
    g.pos = m.positions; g.tri = m.triangles; g.nv = 0; g.nt = 0;
    bpt_add_grid(&g, 200, 1, 0, 1.0, 0.3, 0, 0);
    for (k = 0; k < 10; k++) bpt_add_grid(&g, 2, 2, 0, 1.5, k * 0.7, 300.0 + 10 * k, 0);
    m.num_vertices = g.nv; m.num_triangles = g.nt; m.num_faces = g.nt;
    m.corner_uv = (uint32_t *)malloc(sizeof(uint32_t) * 3 * g.nt);
    m.uvs = (double *)malloc(sizeof(double) * 2 * g.nv);
    m.num_uvs = g.nv;
    memcpy(m.corner_uv, m.triangles, sizeof(uint32_t) * 3 * g.nt);
    for (k = 0; k < (int)g.nv; k++) { m.uvs[2 * k] = m.positions[3 * k]; m.uvs[2 * k + 1] = m.positions[3 * k + 1]; }
    st = pack_input(&m, &at, 128, 2, 0, &err);
    BPT_CHECK(st == BP_OK, "a 200 x 1 strip and 10 squares at 128 px: packed (%s)", st == BP_OK ? "ok" : err.message);
    if (st == BP_OK) check_atlas("long strip", &at, 128, 2, 1);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* Sliver k of test_slivers (below): a triangle whose apex is one (k even)
   or two (k odd) ulps off its long edge of slope 0.3 + k / 1000, at uv
   near 1e6, beside an ordinary triangle; the uvs are the input map. */
static bp_mesh sliver_mesh(int k)
{
    bp_mesh m = bpt_mesh_new(6, 2);
    double slope = 0.3 + k * 1e-3;
    uint32_t i;
    m.positions[3] = 1; m.positions[7] = 1;
    m.positions[9] = 5; m.positions[12] = 6; m.positions[15] = 5; m.positions[16] = 1;
    for (i = 0; i < 6; i++) m.triangles[i] = i;
    m.corner_uv = (uint32_t *)malloc(6 * sizeof(uint32_t));
    memcpy(m.corner_uv, m.triangles, 6 * sizeof(uint32_t));
    m.uvs = (double *)calloc(12, sizeof(double));
    m.num_uvs = 6;
    m.uvs[0] = 1e6; m.uvs[1] = 1e6; m.uvs[2] = 1e6 + 1; m.uvs[3] = 1e6 + slope;
    m.uvs[4] = 1e6 + 0.5; m.uvs[5] = nextafter(1e6 + slope * 0.5, 2e6);
    if (k % 2) m.uvs[5] = nextafter(m.uvs[5], 2e6);
    m.uvs[6] = 5; m.uvs[8] = 6; m.uvs[10] = 5; m.uvs[11] = 1;
    return m;
}

/* Slivers: a triangle whose apex is one or two ulps off its long edge, far
   from the origin (uv near 1e6), next to an ordinary triangle.  Its input
   map is exactly valid, but rotating and scaling it rounds by about as much
   as its height.  Each pack must either give an atlas that passes the exact
   check or fail with BP_ERR_NUMERICAL naming the sliver's chart, leaving
   the maps as they were.  Some slivers keep their own orientation (the
   fallback when the rotated copy is not exactly valid): the packed long
   edge then has the input's slope. */
static void test_slivers(void)
{
    int k, ok = 0, numerical = 0, other = 0, invalid = 0, fallback = 0, named = 0, moved = 0;
    for (k = 0; k < 200; k++) {
        bp_mesh m = sliver_mesh(k);
        bp_atlas at;
        bp_options o;
        bp_error e;
        bp_status st;
        double keep;
        memset(&o, 0, sizeof o);
        st = bp_atlas_build(&at, &m, &o, &e);
        if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &e);
        if (st != BP_OK) { other++; bpt_mesh_free(&m); continue; }
        keep = at.charts[0].uv[5];
        o.atlas_resolution = 64; o.padding = 2;
        st = bp_atlas_pack(&at, &o, &e);
        if (st == BP_OK) {
            const double *uv = at.charts[0].uv;
            ok++;
            if (bp__atlas_verify(&at, &serial_par, &e) != BP_OK) invalid++;
            if (fabs((uv[3] - uv[1]) / (uv[2] - uv[0]) - (m.uvs[3] - m.uvs[1]) / (m.uvs[2] - m.uvs[0])) < 1e-6) fallback++;
        } else if (st == BP_ERR_NUMERICAL) {
            numerical++;
            named += e.element == BP_ELEMENT_CHART && e.index == 0 && bpt_has_number(e.message, 0);
            moved += at.charts[0].uv[5] != keep;
        } else other++;
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
    BPT_CHECK(other == 0 && invalid == 0 && ok + numerical == 200,
              "200 slivers: %d packed and exactly valid (%d invalid), %d BP_ERR_NUMERICAL, %d other", ok, invalid,
              numerical, other);
    BPT_CHECK(named == numerical && moved == 0, "each BP_ERR_NUMERICAL names chart 0 (%d of %d) and moves nothing (%d moved)",
              named, numerical, moved);
    BPT_CHECK(fallback > 0, "the unrotated fallback was taken and gave valid atlases (%d times)", fallback);
}

/* Texel density with importance: the input maps of the 10 charts are
   scaled by 1, 2, ..., 10.  Without importance the packer equalizes UV
   area / 3D area; with importance (the optimized map already carries it)
   the charts keep their relative scale: packed area / input area is the
   same for every chart. */
/* The shelves (no atlas_resolution, normalize on): a moved chart is
   checked once, and the map as it was only when the moved one has a count
   (bp__move_chart).  (a) The 200 slivers of test_slivers: each pack gives
   exactly valid charts in [0,1]^2 or fails with BP_ERR_NUMERICAL and moves
   nothing.  (b) A chart given a mirrored triangle after
   bp_atlas_use_input_uvs (1 flipped, its loop clockwise) still packs: the
   moved map has the same counts, no worse than the map it had, and the
   other charts stay valid. */
static void test_shelf_counts(void)
{
    int k, ok = 0, numerical = 0, other = 0, invalid = 0, moved = 0;
    uint32_t i, c;
    bp_mesh m;
    bp_atlas at;
    bp_options o;
    bp_error e;
    bp_status st;
    bp_check_report before, after;
    for (k = 0; k < 200; k++) {
        double keep;
        m = sliver_mesh(k);
        memset(&o, 0, sizeof o);
        st = bp_atlas_build(&at, &m, &o, &e);
        if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &e);
        if (st != BP_OK) { other++; bpt_mesh_free(&m); continue; }
        keep = at.charts[0].uv[5];
        o.normalize = 1;
        st = bp_atlas_pack(&at, &o, &e);
        if (st == BP_OK) {
            ok++;
            for (c = 0; c < at.num_charts; c++) {
                const bp_chart *ch = &at.charts[c];
                invalid += bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &after, NULL) != BP_OK;
                for (i = 0; i < 2 * ch->num_vertices; i++) invalid += !(ch->uv[i] >= 0 && ch->uv[i] <= 1);
            }
        } else if (st == BP_ERR_NUMERICAL) {
            numerical++;
            moved += at.charts[0].uv[5] != keep;
        } else other++;
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
    BPT_CHECK(other == 0 && invalid == 0 && ok + numerical == 200 && moved == 0,
              "200 slivers on shelves: %d packed and exactly valid in [0,1]^2 (%d invalid), %d BP_ERR_NUMERICAL "
              "(%d moved), %d other", ok, invalid, numerical, moved, other);

    m = make_charts(10, 1);
    memset(&o, 0, sizeof o);
    st = bp_atlas_build(&at, &m, &o, &e);
    if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &e);
    if (!BPT_CHECK(st == BP_OK && at.num_charts == 10 && at.charts[4].num_triangles == 1,
                   "10 charts from their input uvs, chart 4 one triangle (%s)", st == BP_OK ? "ok" : e.message)) {
        if (st == BP_OK) bp_atlas_free(&at);
        bpt_mesh_free(&m);
        return;
    }
    for (i = 0; i < 3; i++) at.charts[4].uv[2 * i] *= -1;            /* mirrored after the input check */
    bp_check(at.charts[4].triangles, 1, at.charts[4].uv, 3, NULL, &before, NULL);
    o.normalize = 1;
    st = bp_atlas_pack(&at, &o, &e);
    BPT_CHECK(st == BP_OK, "the charts with a mirrored one pack on shelves (%s)", st == BP_OK ? "ok" : e.message);
    if (st == BP_OK) {
        bp_check(at.charts[4].triangles, 1, at.charts[4].uv, 3, NULL, &after, NULL);
        BPT_CHECK(before.flipped == 1 && after.flipped == 1 && after.loop_orientation == before.loop_orientation &&
                  after.degenerate == 0 && after.boundary_intersections == 0,
                  "the mirrored chart keeps its counts: flipped %u -> %u, loop orientation %u -> %u",
                  before.flipped, after.flipped, before.loop_orientation, after.loop_orientation);
        for (c = 0, invalid = 0; c < at.num_charts; c++) {
            const bp_chart *ch = &at.charts[c];
            if (c != 4) invalid += bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &after, NULL) != BP_OK;
            for (i = 0; i < 2 * ch->num_vertices; i++) invalid += !(ch->uv[i] >= 0 && ch->uv[i] <= 1);
        }
        BPT_CHECK(invalid == 0, "the other 9 charts are exactly valid and every uv is in [0,1] (%d problems)", invalid);
    }
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

static void test_importance_density(void)
{
    bp_mesh m = make_charts(10, 1);
    bp_atlas at;
    bp_options o;
    bp_error err;
    bp_status st;
    double *imp = (double *)malloc(sizeof(double) * m.num_triangles), *in_area, lo = HUGE_VAL, hi = 0, lo3 = HUGE_VAL, hi3 = 0;
    uint32_t c, t, i;
    int pass;
    for (t = 0; t < m.num_triangles; t++) imp[t] = 1 + (t % 3);
    for (pass = 0; pass < 2; pass++) {
        memset(&o, 0, sizeof o);
        st = bp_atlas_build(&at, &m, &o, &err);
        if (st == BP_OK) st = bp_atlas_use_input_uvs(&at, &m, &err);
        if (st != BP_OK) { BPT_CHECK(0, "importance set-up: %s", err.message); break; }
        in_area = (double *)calloc(at.num_charts, sizeof(double));
        for (c = 0; c < at.num_charts; c++) {
            bp_chart *ch = &at.charts[c];
            for (i = 0; i < 2 * ch->num_vertices; i++) ch->uv[i] *= 1 + c;
            in_area[c] = bp__chart_uv_area(ch);
        }
        o.atlas_resolution = 128; o.padding = 2;
        o.importance = pass ? imp : NULL;
        st = bp_atlas_pack(&at, &o, &err);
        BPT_CHECK(st == BP_OK, "pack with%s importance", pass ? "" : "out");
        for (c = 0; st == BP_OK && c < at.num_charts; c++) {
            double r = bp__chart_uv_area(&at.charts[c]) / (pass ? in_area[c] : at.charts[c].area3d);
            if (pass) { if (r < lo) lo = r; if (r > hi) hi = r; }
            else { if (r < lo3) lo3 = r; if (r > hi3) hi3 = r; }
        }
        if (st == BP_OK) check_atlas(pass ? "with importance" : "input scaled 1..10", &at, 128, 2, !pass);
        free(in_area);
        bp_atlas_free(&at);
    }
    BPT_CHECK(hi3 <= lo3 * (1 + 1e-9), "without importance: UV / 3D area equal across charts (%.12g .. %.12g)", lo3, hi3);
    BPT_CHECK(hi <= lo * (1 + 1e-9), "with importance: the relative scales kept (packed / input area %.12g .. %.12g)", lo, hi);
    free(imp);
    bpt_mesh_free(&m);
}

/* The outline raster against the triangles' (the header comment). */
static void test_outline_raster(void)
{
    static const char *files[2] = { "tests/data/face_holes.off", "tests/data/spot.obj" };
    static const double sizes[3] = { 40, 300, 1500 };
    int f, k, j, n = 0, same = 0;
    for (f = 0; f < 2; f++) {
        bp_mesh m;
        bp_atlas at;
        bp_error err;
        uint32_t c, i;
        if (!BPT_CHECK(bp_read_mesh(files[f], &m, NULL, &err) == BP_OK, "read %s (%s)", files[f], err.message)) continue;
        if (!BPT_CHECK(bp_parameterize(&at, &m, NULL, &err) == BP_OK, "%s flattened (%s)", files[f], err.message)) {
            bp_mesh_free(&m, NULL);
            continue;
        }
        for (c = 0; c < at.num_charts; c++) {
            const bp_chart *ch = &at.charts[c];
            double *L = (double *)malloc(2 * sizeof(double) * ch->num_vertices), lo[2], hi[2];
            for (k = 0; k < 3; k++)
                for (j = 0; j < 4; j++) {
                    double a = bpt_rng_range(0, 6.283185307179586), cs = cos(a), sn = sin(a), sc;
                    double sx = bpt_rng_range(0, 1), sy = bpt_rng_range(0, 1);
                    bp__shape S1, S2;
                    bp_status s1, s2;
                    lo[0] = lo[1] = HUGE_VAL; hi[0] = hi[1] = -HUGE_VAL;
                    for (i = 0; i < ch->num_vertices; i++) {
                        double x = cs * ch->uv[2 * i] - sn * ch->uv[2 * i + 1], y = sn * ch->uv[2 * i] + cs * ch->uv[2 * i + 1];
                        L[2 * i] = x; L[2 * i + 1] = y;
                        if (x < lo[0]) lo[0] = x;
                        if (x > hi[0]) hi[0] = x;
                        if (y < lo[1]) lo[1] = y;
                        if (y > hi[1]) hi[1] = y;
                    }
                    sc = sizes[k] / (hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1]);
                    for (i = 0; i < ch->num_vertices; i++) {
                        L[2 * i] = (L[2 * i] - lo[0]) * sc + BP__PACK_SHIFT + sx;
                        L[2 * i + 1] = (L[2 * i + 1] - lo[1]) * sc + BP__PACK_SHIFT + sy;
                    }
                    s1 = bp__shape_make(&at.allocator, ch, L, 4096, 1, &S1);
                    s2 = bp__shape_make(&at.allocator, ch, L, 4096, 0, &S2);
                    n++;
                    if (s1 == BP_OK && s2 == BP_OK && S1.r.w == S2.r.w && S1.r.h == S2.r.h && S1.rstar == S2.rstar &&
                        !memcmp(S1.r.b, S2.r.b, sizeof(uint64_t) * S1.r.words * S1.r.h) &&
                        !memcmp(S1.rowrun, S2.rowrun, sizeof(int) * S1.r.h))
                        same++;
                    if (s1 == BP_OK) bp__shape_free(&at.allocator, &S1);
                    if (s2 == BP_OK) bp__shape_free(&at.allocator, &S2);
                }
            free(L);
        }
        bp_atlas_free(&at);
        bp_mesh_free(&m, NULL);
    }
    BPT_CHECK(n > 0 && same == n, "a bijective chart's raster from its outline is its triangles' raster (%d of %d)", same, n);
}

int main(void)
{
    test_outline_raster();
    test_padding_and_validity();
    test_rotation();
    test_long_strip();
    test_slivers();
    test_shelf_counts();
    test_importance_density();
    test_threads();
    test_errors();
    test_repack();
    test_out_of_memory();
    return bpt_finish();
}
