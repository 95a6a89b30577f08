/* test_badinput.c - the bad-input matrix of the whole pipeline.

   Every malformed mesh must be rejected with the exact status, and the
   error must name the offending element: err.element says what kind,
   err.index / err.index2 / err.line say which, and the message contains
   that number.  Every unusual but legal mesh must be flattened into a map
   that bp_check proves valid (no flipped or degenerate triangle, no
   boundary intersection, one counter-clockwise loop per piece, no nesting).

   Covered (test_io.c covers the parsers' own syntax errors; here the focus
   is what reaches bp_parameterize):
     empty file / empty mesh, only vertices, NaN and Inf (file and memory,
     used and unused vertices), OBJ index 0 / out of range / negative past
     the start, in-memory index out of range, a triangle repeating a vertex,
     collinear (zero-area) triangles, needles just above and below the
     degeneracy threshold, duplicate faces (same, rotated, reversed order),
     a non-manifold edge, a bowtie (two charts) and a pinched vertex inside
     one chart (repaired: split_vertices), inconsistent orientation, a closed
     chart (tetrahedron) by default and strict, a genus-1 chart
     (torus_with_holes.obj), unreferenced vertices, duplicated vertices at
     one position (a cut, a slit), a single triangle, a chart with ~2000
     holes (timed), coordinates scaled by 1e-6 and 1e6 (and by 2^+-200 with
     atlas_resolution: the atlas stays in [0,1]^2), vt seams that pinch
     (spot.obj), a good chart next to a closed one (uv, bp_check,
     bp_write_obj), every bp_status string, cancellation at many
     iterations, max_iterations and max_seconds. */
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

/* Sanitizer builds (make asan) run several times slower: time limits that
   include fixed costs are scaled by BPT_SLOW. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define BPT_SLOW 3
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define BPT_SLOW 3
#endif
#endif
#ifndef BPT_SLOW
#define BPT_SLOW 1
#endif

/* ---- helpers -------------------------------------------------------------- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int report_valid(const bp_check_report *r)
{
    return !r->flipped && !r->degenerate && !r->nonfinite && !r->boundary_intersections &&
           !r->loop_orientation && !r->nested;
}

static int chart_valid(const bp_chart *ch)
{
    bp_check_report r;
    if (!ch->uv) return 0;
    if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK) return 0;
    return report_valid(&r);
}

/* Every mapped chart valid, and the mapped charts together (the packed
   atlas) valid as one triangulation: no two charts overlap. */
static int atlas_valid(const bp_atlas *at)
{
    uint32_t c, nt = 0, nv = 0, ot = 0, ov = 0, i;
    uint32_t *tri;
    double *uv;
    bp_check_report r;
    int ok = 1;
    for (c = 0; c < at->num_charts; c++) {
        if (!at->charts[c].uv) continue;
        if (!chart_valid(&at->charts[c])) ok = 0;
        nt += at->charts[c].num_triangles;
        nv += at->charts[c].num_vertices;
    }
    if (!nt) return ok;
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri);
    uv = (double *)malloc(2 * (size_t)nv * sizeof *uv);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (!ch->uv) continue;
        for (i = 0; i < 3 * ch->num_triangles; i++) tri[3 * ot + i] = ch->triangles[i] + ov;
        for (i = 0; i < 2 * ch->num_vertices; i++) uv[2 * ov + i] = ch->uv[i];
        ot += ch->num_triangles;
        ov += ch->num_vertices;
    }
    if (bp_check(tri, nt, uv, nv, NULL, &r, NULL) != BP_OK || !report_valid(&r)) ok = 0;
    free(tri);
    free(uv);
    return ok;
}

static int all_mapped_valid(const bp_atlas *at)
{
    uint32_t c;
    for (c = 0; c < at->num_charts; c++)
        if (!at->charts[c].uv) return 0;
    return at->num_charts > 0 && atlas_valid(at);
}

static void set_v(bp_mesh *m, uint32_t v, double x, double y, double z)
{
    m->positions[3 * v] = x; m->positions[3 * v + 1] = y; m->positions[3 * v + 2] = z;
}

static void set_t(bp_mesh *m, uint32_t t, uint32_t a, uint32_t b, uint32_t c)
{
    m->triangles[3 * t] = a; m->triangles[3 * t + 1] = b; m->triangles[3 * t + 2] = c;
}

/* A gently curved grid of nx x ny quads (two triangles each, CCW seen from
   +z) on [0,nx] x [0,ny]; quads for which hole(i,j) is nonzero are left
   out.  Vertex (i,j) is j*(nx+1)+i. */
typedef int (*hole_fn)(int i, int j, int nx, int ny);

static bp_mesh grid(int nx, int ny, hole_fn hole, double bump)
{
    uint32_t nt = 0, t = 0;
    int i, j;
    bp_mesh m;
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++)
            if (!hole || !hole(i, j, nx, ny)) nt += 2;
    m = bpt_mesh_new((uint32_t)((nx + 1) * (ny + 1)), nt);
    for (j = 0; j <= ny; j++)
        for (i = 0; i <= nx; i++)
            set_v(&m, (uint32_t)(j * (nx + 1) + i), i, j, bump * sin(0.7 * i) * cos(0.5 * j));
    for (j = 0; j < ny; j++)
        for (i = 0; i < nx; i++) {
            uint32_t a = (uint32_t)(j * (nx + 1) + i), b = a + 1, c = a + (uint32_t)nx + 2, d = a + (uint32_t)nx + 1;
            if (hole && hole(i, j, nx, ny)) continue;
            set_t(&m, t++, a, b, c);
            set_t(&m, t++, a, c, d);
        }
    return m;
}

static bp_options defaults(void)
{
    bp_options o;
    memset(&o, 0, sizeof o);
    return o;
}

/* Parse OBJ text (from an exact-length heap copy, no NUL). */
static bp_status parse_obj(const char *text, bp_mesh *m, bp_error *err)
{
    size_t n = strlen(text);
    char *buf = (char *)malloc(n ? n : 1);
    bp_status st;
    memcpy(buf, text, n);
    st = bp_parse_obj(buf, n, m, NULL, err);
    free(buf);
    return st;
}

/* Parse, then (if parsing worked) parameterize: the first failure's
   status, with err filled.  *parsed says whether the parser accepted it. */
static bp_status pipeline_obj(const char *text, const bp_options *opt, bp_error *err, int *parsed)
{
    bp_mesh m;
    bp_atlas at;
    bp_status st = parse_obj(text, &m, err);
    *parsed = st == BP_OK;
    if (st != BP_OK) return st;
    st = bp_parameterize(&at, &m, opt, err);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
    return st;
}

/* Messages name vertices and triangles as the file numbers them, from 1,
   while bp_error.index is 0-based (charts keep their 0-based index): the
   number a message must contain for element el with index i. */
static long long named(bp_element el, int64_t i)
{
    return el == BP_ELEMENT_VERTEX || el == BP_ELEMENT_TRIANGLE || el == BP_ELEMENT_EDGE ? i + 1 : i;
}

/* Expect status `want` from OBJ text, naming file line `line`.  A parser
   error names the line in its message ("line N: ...").  An error found
   later by bp_parameterize names the element (triangle, edge, chart) in
   the message -- checked: element `el` with index `index` (and `index2`
   unless < -1) whose number the message contains -- and carries the
   file line of the offending triangle in err.line (the message itself
   does not repeat the line; the tool prints FILE:LINE from err.line).
   Runs with opt.strict: the defects that are repaired by default (see
   test_repair.c) are errors there. */
static void expect_obj_el(const char *what, const char *text, bp_status want, int want_parsed, long long line,
                          bp_element el, int64_t index, int64_t index2)
{
    bp_error err;
    bp_options o = defaults();
    int parsed = 0;
    bp_status st;
    o.strict = 1;
    memset(&err, 0, sizeof err);
    st = pipeline_obj(text, &o, &err, &parsed);
    BPT_CHECK(st == want && err.status == st && parsed == want_parsed,
              "%s: %s from the %s (got %s, parsed %d): \"%s\"", what, bp_status_string(want),
              want_parsed ? "pipeline" : "parser", bp_status_string(st), parsed, err.message);
    if (!want_parsed && line > 0)
        BPT_CHECK(err.line == line && err.element == BP_ELEMENT_LINE && err.index == line &&
                      bpt_has_number(err.message, line),
                  "%s: names line %lld (err.line %lld, element %d, index %lld): \"%s\"", what, line, (long long)err.line,
                  (int)err.element, (long long)err.index, err.message);
    if (want_parsed)
        BPT_CHECK(err.line == line && err.element == el && err.index == index &&
                      bpt_has_number(err.message, named(el, index)) &&
                      (index2 < -1 || (err.index2 == index2 && (index2 < 0 || bpt_has_number(err.message, named(el, index2))))),
                  "%s: err.line %lld (want %lld), element %d index %lld/%lld (want %d %lld/%lld) named in \"%s\"",
                  what, (long long)err.line, line, (int)err.element, (long long)err.index, (long long)err.index2,
                  (int)el, (long long)index, (long long)index2, err.message);
}

static void expect_obj(const char *what, const char *text, bp_status want, int want_parsed, long long line)
{
    expect_obj_el(what, text, want, want_parsed, line, BP_ELEMENT_NONE, -1, -2);
}

/* bp_parameterize on an in-memory mesh, strict (as expect_obj_el); expect
   `want` with element and index. */
static void expect_mem(const char *what, const bp_mesh *m, bp_status want, bp_element el, int64_t index,
                       int64_t index2)
{
    bp_error err;
    bp_atlas at;
    bp_options o = defaults();
    bp_status st;
    o.strict = 1;
    memset(&err, 0, sizeof err);
    st = bp_parameterize(&at, m, &o, &err);
    BPT_CHECK(st == want && err.status == want, "%s: %s (got %s: \"%s\")", what, bp_status_string(want),
              bp_status_string(st), err.message);
    BPT_CHECK(err.element == el && err.index == index && (index2 < -1 || err.index2 == index2) &&
                  (index < 0 || bpt_has_number(err.message, named(el, index))) &&
                  (index2 < 0 || bpt_has_number(err.message, named(el, index2))),
              "%s: names element %d index %lld/%lld (got element %d index %lld/%lld): \"%s\"", what, (int)el,
              (long long)index, (long long)index2, (int)err.element, (long long)err.index, (long long)err.index2,
              err.message);
    BPT_CHECK(at.charts == NULL && at.num_charts == 0 && at.corner_chart == NULL,
              "%s: the failed call left the atlas zeroed", what);
    bp_atlas_free(&at);
}

/* bp_parameterize must succeed and every chart be valid. */
static int expect_fine(const char *what, const bp_mesh *m, const bp_options *opt, bp_atlas *keep)
{
    bp_error err;
    bp_atlas at;
    bp_status st = bp_parameterize(&at, m, opt, &err);
    int ok = BPT_CHECK(st == BP_OK, "%s: BP_OK (%s: %s)", what, bp_status_string(st), err.message);
    if (ok) ok = BPT_CHECK(all_mapped_valid(&at), "%s: every chart and the packed atlas pass bp_check (%u charts)",
                           what, (unsigned)at.num_charts);
    if (keep && st == BP_OK) *keep = at;
    else bp_atlas_free(&at);
    return ok;
}

/* ---- empty and non-finite ------------------------------------------------- */

static void test_empty(void)
{
    bp_mesh m;
    bp_error err;
    bp_status st;
    expect_obj("empty OBJ file", "", BP_ERR_EMPTY, 0, 0);
    expect_obj("OBJ with only comments", "# nothing\n\n", BP_ERR_EMPTY, 0, 0);
    expect_obj("OBJ with only vertices", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", BP_ERR_EMPTY, 0, 0);
    /* in memory: no arrays at all, and vertices without triangles */
    memset(&m, 0, sizeof m);
    expect_mem("zeroed bp_mesh", &m, BP_ERR_EMPTY, BP_ELEMENT_NONE, -1, -1);
    m = bpt_mesh_new(3, 0);
    expect_mem("bp_mesh with 3 vertices and 0 triangles", &m, BP_ERR_EMPTY, BP_ELEMENT_NONE, -1, -1);
    bpt_mesh_free(&m);
    st = bp_parameterize(NULL, NULL, NULL, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && err.message[0], "bp_parameterize(NULL atlas): invalid argument (%s)",
              err.message);
}

static void test_nonfinite(void)
{
    static const char *const bad[] = { "nan", "inf", "-inf", "1e999" };
    char text[256];
    int i;
    for (i = 0; i < 4; i++) {
        char what[64];
        sprintf(what, "OBJ coordinate %s", bad[i]);
        sprintf(text, "v 0 0 0\nv 1 0 0\n# c\nv 0 %s 0\nf 1 2 3\n", bad[i]);
        expect_obj(what, text, BP_ERR_NONFINITE, 0, 4);
    }
    /* in memory: the used vertex 2 of triangle 1 */
    {
        double vals[3] = { NAN, INFINITY, -INFINITY };
        for (i = 0; i < 3; i++) {
            bp_mesh m = grid(2, 1, NULL, 0);   /* 6 vertices, 4 triangles */
            char what[64];
            m.positions[3 * 4 + 2] = vals[i];  /* vertex 4: used by triangles 2, 3 */
            sprintf(what, "in-memory vertex 4 with z = %g", vals[i]);
            expect_mem(what, &m, BP_ERR_NONFINITE, BP_ELEMENT_VERTEX, 4, -2);
            bpt_mesh_free(&m);
        }
    }
    /* an unused vertex may hold anything */
    {
        bp_mesh m = grid(2, 2, NULL, 0.2), m2 = bpt_mesh_new(m.num_vertices + 2, m.num_triangles);
        memcpy(m2.positions, m.positions, 3 * m.num_vertices * sizeof(double));
        memcpy(m2.triangles, m.triangles, 3 * m.num_triangles * sizeof(uint32_t));
        set_v(&m2, m.num_vertices, NAN, INFINITY, -INFINITY);
        set_v(&m2, m.num_vertices + 1, 1e300, -1e300, 0);   /* far away: must not change the size scale */
        expect_fine("unreferenced vertices (one NaN/Inf, one at 1e300)", &m2, NULL, NULL);
        bpt_mesh_free(&m);
        bpt_mesh_free(&m2);
    }
}

/* ---- indices --------------------------------------------------------------- */

static void test_indices(void)
{
    expect_obj("OBJ index 0", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 0 1 2\n", BP_ERR_INDEX, 0, 5);
    expect_obj("OBJ index past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n", BP_ERR_INDEX, 0, 5);
    expect_obj("OBJ negative index before the start", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", BP_ERR_INDEX, 0, 4);
    expect_obj("OBJ vt index past the end", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/2\n", BP_ERR_INDEX, 0, 5);
    {
        bp_mesh m = grid(2, 1, NULL, 0);
        bp_atlas at;
        bp_error err;
        m.triangles[3 * 2 + 1] = 99;       /* triangle 2 */
        expect_mem("in-memory vertex index 99 (of 6)", &m, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, 2, -1);
        bp_parameterize(&at, &m, NULL, &err);
        BPT_CHECK(bpt_has_number(err.message, 100) && bpt_has_number(err.message, 3) && bpt_has_number(err.message, 6),
                  "in-memory vertex index 99: the message names vertex 100 and triangle 3 as a file numbers them, "
                  "and the 6 vertices: \"%s\"", err.message);
        bpt_mesh_free(&m);
    }
    {
        bp_mesh m = grid(2, 1, NULL, 0);
        uint32_t i;
        m.corner_uv = (uint32_t *)calloc(3 * m.num_triangles, sizeof(uint32_t));
        m.uvs = (double *)calloc(2 * 6, sizeof(double));
        m.num_uvs = 6;
        for (i = 0; i < 3 * m.num_triangles; i++) m.corner_uv[i] = m.triangles[i];
        m.corner_uv[3 * 3] = 6;            /* triangle 3 */
        expect_mem("in-memory uv index 6 (of 6)", &m, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, 3, -1);
        bpt_mesh_free(&m);
    }
}

/* ---- degenerate triangles and needles ------------------------------------- */

/* A 4x4 curved grid plus one needle triangle hanging off the bottom edge
   between vertices 1 and 2: apex at the edge's midpoint, h below it, so
   twice its area is h (the edge has length 1). */
static bp_mesh grid_with_needle(double h)
{
    bp_mesh g = grid(4, 4, NULL, 0.3), m = bpt_mesh_new(g.num_vertices + 1, g.num_triangles + 1);
    memcpy(m.positions, g.positions, 3 * g.num_vertices * sizeof(double));
    memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
    set_v(&m, g.num_vertices, 0.5 * (g.positions[3] + g.positions[6]), -h, 0.5 * (g.positions[5] + g.positions[8]));
    set_t(&m, g.num_triangles, 1, g.num_vertices, 2);
    bpt_mesh_free(&g);
    return m;
}

static void test_degenerate(void)
{
    /* a repeated vertex, in a file (line) and in memory (triangle) */
    expect_obj_el("OBJ triangle 1 1 2", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n", BP_ERR_DEGENERATE, 1, 5,
                  BP_ELEMENT_TRIANGLE, 1, -1);
    expect_obj_el("OBJ collinear triangle", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 3 2\n",
                  BP_ERR_DEGENERATE, 1, 6, BP_ELEMENT_TRIANGLE, 1, -1);
    {
        bp_mesh m = grid(3, 3, NULL, 0.2);
        /* triangle 5: make its three vertices collinear in 3D (exactly) */
        uint32_t a = m.triangles[15], b = m.triangles[16], c = m.triangles[17];
        set_v(&m, c, 2 * m.positions[3 * b] - m.positions[3 * a], 2 * m.positions[3 * b + 1] - m.positions[3 * a + 1],
              2 * m.positions[3 * b + 2] - m.positions[3 * a + 2]);
        expect_mem("in-memory collinear triangle 5", &m, BP_ERR_DEGENERATE, BP_ELEMENT_TRIANGLE, 5, -1);
        bpt_mesh_free(&m);
    }
    /* Needles.  The library rejects a triangle when twice its area is
       <= 1e-12 x the squared bounding-box diagonal of the used vertices.
       Relative areas 1e-6 and 1e-10 are legal and must be flattened (the
       needle's 1e6:1 / 1e10:1 aspect ratio is kept in the map, distortion
       and all); 1e-13 is below the threshold and gives BP_ERR_DEGENERATE
       naming the needle (the last triangle, 32). */
    {
        double rel[3] = { 1e-6, 1e-10, 1e-13 };
        int i;
        for (i = 0; i < 3; i++) {
            bp_mesh m = grid_with_needle(1.0);
            double d2 = bpt_bbox_diag2(&m), h;
            char what[96];
            bpt_mesh_free(&m);
            h = rel[i] * d2;               /* twice the area / diag^2 = rel */
            m = grid_with_needle(h);
            sprintf(what, "needle with 2A = %g diag^2", rel[i]);
            if (rel[i] > 1e-12) {
                bp_options o = defaults();
                bp_atlas at;
                memset(&at, 0, sizeof at);
                o.max_iterations = 200;
                if (expect_fine(what, &m, &o, &at))
                    BPT_CHECK(at.charts[0].iterations >= 1 && at.charts[0].iterations <= 200 &&
                                  at.charts[0].stop != BP_STOP_NONE && at.charts[0].stop != BP_STOP_CANCELLED,
                              "%s: optimized (%d iterations, stop %s)", what, at.charts[0].iterations,
                              bp_stop_string(at.charts[0].stop));
                bp_atlas_free(&at);
            } else {
                expect_mem(what, &m, BP_ERR_DEGENERATE, BP_ELEMENT_TRIANGLE, 32, -1);
            }
            bpt_mesh_free(&m);
        }
    }
}

/* ---- topology --------------------------------------------------------------- */

static void test_topology(void)
{
    /* duplicate faces: the same, rotated and reversed vertex order */
    {
        static const uint32_t dup[3][3] = { { 5, 6, 10 }, { 6, 10, 5 }, { 10, 6, 5 } };
        static const char *const name[3] = { "same order", "rotated", "reversed" };
        int i;
        for (i = 0; i < 3; i++) {
            bp_mesh g = grid(3, 3, NULL, 0.2), m = bpt_mesh_new(g.num_vertices, g.num_triangles + 1);
            char what[80];
            memcpy(m.positions, g.positions, 3 * g.num_vertices * sizeof(double));
            memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
            /* grid triangle 8 is (5, 6, 10) */
            set_t(&m, 18, dup[i][0], dup[i][1], dup[i][2]);
            sprintf(what, "duplicate of triangle 8 as triangle 18 (%s)", name[i]);
            BPT_CHECK(g.triangles[24] == 5 && g.triangles[25] == 6 && g.triangles[26] == 10, "grid triangle 8 is 5 6 10");
            expect_mem(what, &m, BP_ERR_DUPLICATE_FACE, BP_ELEMENT_TRIANGLE, 18, 8);
            bpt_mesh_free(&g);
            bpt_mesh_free(&m);
        }
    }
    expect_obj_el("OBJ duplicate face", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 2 3 1\n",
                  BP_ERR_DUPLICATE_FACE, 1, 7, BP_ELEMENT_TRIANGLE, 2, 0);
    /* non-manifold edge 5-7: three triangles on it */
    {
        bp_mesh m = bpt_mesh_new(8, 3);
        set_v(&m, 5, 0, 0, 0); set_v(&m, 7, 1, 0, 0);
        set_v(&m, 0, 0.5, 1, 0); set_v(&m, 1, 0.5, -1, 0); set_v(&m, 2, 0.5, 0, 1);
        set_v(&m, 3, 9, 9, 9); set_v(&m, 4, 9, 8, 9); set_v(&m, 6, 8, 9, 9);   /* unused */
        set_t(&m, 0, 5, 7, 0);
        set_t(&m, 1, 7, 5, 1);
        set_t(&m, 2, 5, 7, 2);
        expect_mem("three triangles on edge 5-7", &m, BP_ERR_NONMANIFOLD, BP_ELEMENT_EDGE, 5, 7);
        bpt_mesh_free(&m);
    }
    expect_obj_el("OBJ non-manifold edge",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\n# third\nf 1 5 2\n",
                  BP_ERR_NONMANIFOLD, 1, 9, BP_ELEMENT_EDGE, 0, 1);
    /* inconsistent orientation: triangles 0 (0 1 2) and 1 (0 1 3) both run 0->1 */
    {
        bp_mesh m = bpt_mesh_new(4, 2);
        set_v(&m, 0, 0, 0, 0); set_v(&m, 1, 1, 0, 0); set_v(&m, 2, 0, 1, 0); set_v(&m, 3, 0, -1, 0.1);
        set_t(&m, 0, 0, 1, 2);
        set_t(&m, 1, 0, 1, 3);
        expect_mem("neighbours with opposite orientation on edge 0-1", &m, BP_ERR_ORIENTATION, BP_ELEMENT_EDGE, 0, 1);
        bpt_mesh_free(&m);
    }
    expect_obj_el("OBJ flipped neighbour", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n",
                  BP_ERR_ORIENTATION, 1, 6, BP_ELEMENT_EDGE, 1, 2);
}

/* The bowtie.  (a) Two triangles sharing only a vertex are two charts (the
   charts are the edge-connected components): both flattened.  (b) A pinch
   inside one chart: a 4x4 grid without the quads (1,1) and (2,2), which
   touch at vertex 12; the two remaining fans at vertex 12 are connected
   through the rest of the grid.  The library splits the vertex (one chart
   vertex per fan, split_vertices 1) and maps the chart as a disk with one
   hole; the map must be bijective. */
static int diagonal_holes(int i, int j, int nx, int ny)
{
    (void)nx; (void)ny;
    return (i == 1 && j == 1) || (i == 2 && j == 2);
}

static void test_bowtie(void)
{
    bp_atlas at;
    {
        bp_mesh m = bpt_mesh_new(5, 2);
        set_v(&m, 0, 0, 0, 0);
        set_v(&m, 1, 1, 0.2, 0); set_v(&m, 2, 1, -0.2, 0.1);   /* (0 2 1) faces +z... any orientation */
        set_v(&m, 3, -1, 0.3, 0); set_v(&m, 4, -1, -0.3, 0.2);
        set_t(&m, 0, 0, 2, 1);
        set_t(&m, 1, 0, 3, 4);
        memset(&at, 0, sizeof at);
        if (expect_fine("bowtie of two triangles (two charts)", &m, NULL, &at))
            BPT_CHECK(at.num_charts == 2 && at.num_split == 0, "bowtie: 2 charts, 0 split (%u, %u)",
                      (unsigned)at.num_charts, (unsigned)at.num_split);
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
    {
        bp_mesh m = grid(4, 4, diagonal_holes, 0.25);
        memset(&at, 0, sizeof at);
        if (expect_fine("pinched vertex inside one chart", &m, NULL, &at)) {
            const bp_chart *ch = &at.charts[0];
            uint32_t v, copies = 0;
            for (v = 0; v < ch->num_vertices; v++) copies += ch->vertex[v] == 12;
            BPT_CHECK(at.num_charts == 1 && at.num_split == 1 && ch->split_vertices == 1 && copies == 2,
                      "pinch: 1 chart, num_split 1, split_vertices 1, mesh vertex 12 has 2 chart vertices "
                      "(%u, %u, %u, %u)", (unsigned)at.num_charts, (unsigned)at.num_split,
                      (unsigned)ch->split_vertices, (unsigned)copies);
            BPT_CHECK(ch->num_loops == 2 && ch->num_vertices == m.num_vertices + 1,
                      "pinch: repaired into a disk with one hole (%u loops, %u chart vertices)",
                      (unsigned)ch->num_loops, (unsigned)ch->num_vertices);
        }
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
}

static void tetra(bp_mesh *m, uint32_t v0, uint32_t t0, double ox)
{
    set_v(m, v0 + 0, ox + 0, 0, 0);
    set_v(m, v0 + 1, ox + 1, 0, 0);
    set_v(m, v0 + 2, ox + 0, 1, 0);
    set_v(m, v0 + 3, ox + 0, 0, 1);
    set_t(m, t0 + 0, v0 + 0, v0 + 2, v0 + 1);
    set_t(m, t0 + 1, v0 + 0, v0 + 1, v0 + 3);
    set_t(m, t0 + 2, v0 + 0, v0 + 3, v0 + 2);
    set_t(m, t0 + 3, v0 + 1, v0 + 2, v0 + 3);
}

static void test_closed(void)
{
    bp_mesh m = bpt_mesh_new(4, 4);
    bp_atlas at;
    bp_error err;
    bp_options o = defaults();
    bp_status st;
    o.cut = BP_CUT_NONE;      /* the rejection; the default cuts (test_cut.c) */
    tetra(&m, 0, 0, 0);
    /* the mesh's only chart fails: nothing is usable, so the call fails
       with the chart's own status (not "some charts failed") and the atlas
       is freed, in the default mode as in strict mode */
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_TOPOLOGY && err.status == st && err.element == BP_ELEMENT_CHART && err.index == 0 &&
                  at.charts == NULL && strstr(err.message, "closed") && !strstr(err.message, "others") &&
                  bpt_has_number(err.message, 0),
              "tetrahedron (its only chart fails): BP_ERR_TOPOLOGY naming chart 0, says closed, atlas freed (%s, "
              "element %d, index %lld): \"%s\"",
              bp_status_string(st), (int)err.element, (long long)err.index, err.message);
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_TOPOLOGY && err.status == st && err.element == BP_ELEMENT_CHART && err.index == 0 &&
                  at.charts == NULL,
              "tetrahedron, strict: BP_ERR_TOPOLOGY naming chart 0, atlas freed (%s): \"%s\"", bp_status_string(st),
              err.message);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);

    /* genus 1 with two boundary loops */
    {
        bp_mesh t;
        if (BPT_CHECK(bp_read_obj("tests/data/torus_with_holes.obj", &t, NULL, &err) == BP_OK, "read torus_with_holes")) {
            o = defaults();
            o.cut = BP_CUT_NONE;
            st = bp_parameterize(&at, &t, &o, &err);
            BPT_CHECK(st == BP_ERR_TOPOLOGY && at.charts == NULL && strstr(err.message, "genus 1") &&
                          strstr(err.message, "seams") && err.element == BP_ELEMENT_CHART && err.index == 0 &&
                          bpt_has_number(err.message, 0) && err.line > 0,
                      "torus_with_holes: BP_ERR_TOPOLOGY 'genus 1', says seams, names chart 0, err.line %lld: \"%s\"",
                      (long long)err.line, err.message);
            bp_atlas_free(&at);
            o.strict = 1;
            st = bp_parameterize(&at, &t, &o, &err);
            BPT_CHECK(st == BP_ERR_TOPOLOGY && err.element == BP_ELEMENT_CHART && err.index == 0,
                      "torus_with_holes, strict: BP_ERR_TOPOLOGY chart 0 (%s)", bp_status_string(st));
            bp_atlas_free(&at);
            bp_mesh_free(&t, NULL);
        }
    }
}

/* One good chart (a curved grid) and one closed chart (a tetrahedron):
   the grid is mapped and valid, the tetrahedron has no uv, and
   bp_write_obj writes the tetrahedron's faces without vt. */
static void test_mixed(void)
{
    bp_mesh g = grid(3, 3, NULL, 0.2), m = bpt_mesh_new(g.num_vertices + 4, g.num_triangles + 4);
    bp_atlas at;
    bp_error err;
    bp_options o = defaults();
    bp_status st;
    char dir[] = "/tmp/bp_badinput_XXXXXX", path[128], line[256];
    memcpy(m.positions, g.positions, 3 * g.num_vertices * sizeof(double));
    memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
    tetra(&m, g.num_vertices, g.num_triangles, 10);
    o.cut = BP_CUT_NONE;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_CHARTS_FAILED && err.element == BP_ELEMENT_CHART && err.index == 1 &&
                  bpt_has_number(err.message, 1),
              "grid + tetrahedron: BP_ERR_CHARTS_FAILED naming chart 1 (%s): \"%s\"", bp_status_string(st), err.message);
    if (st != BP_ERR_CHARTS_FAILED) { bpt_mesh_free(&g); bpt_mesh_free(&m); bp_atlas_free(&at); return; }
    BPT_CHECK(at.num_charts == 2 && at.num_failed == 1 && at.charts[0].uv && at.charts[0].error.status == BP_OK &&
                  chart_valid(&at.charts[0]) && atlas_valid(&at),
              "grid + tetrahedron: the grid is mapped and passes bp_check");
    BPT_CHECK(at.charts[1].uv == NULL && at.charts[1].error.status == BP_ERR_TOPOLOGY,
              "grid + tetrahedron: the tetrahedron has uv NULL and chart.error BP_ERR_TOPOLOGY");
    if (BPT_CHECK(mkdtemp(dir) != NULL, "mkdtemp")) {
        FILE *f;
        int faces = 0, with_vt = 0, bad = 0;
        sprintf(path, "%s/mixed.obj", dir);
        st = bp_write_obj(path, &m, &at, &err);
        BPT_CHECK(st == BP_OK, "grid + tetrahedron: bp_write_obj (%s)", err.message);
        f = fopen(path, "r");
        while (f && fgets(line, sizeof line, f)) {
            if (line[0] != 'f' || line[1] != ' ') continue;
            if (faces < (int)g.num_triangles) { if (strchr(line, '/')) with_vt++; else bad++; }
            else if (strchr(line, '/')) bad++;
            faces++;
        }
        if (f) fclose(f);
        BPT_CHECK(faces == (int)m.num_triangles && with_vt == (int)g.num_triangles && bad == 0,
                  "written OBJ: %d faces, the grid's %d with vt, the tetrahedron's 4 without (%d wrong)", faces, with_vt,
                  bad);
        /* and it reads back */
        {
            bp_mesh r;
            st = bp_read_obj(path, &r, NULL, &err);
            BPT_CHECK(st == BP_OK && r.num_triangles == m.num_triangles, "written OBJ reads back (%s)", err.message);
            bp_mesh_free(&r, NULL);
        }
        unlink(path);
        rmdir(dir);
    }
    bp_atlas_free(&at);
    bpt_mesh_free(&g);
    bpt_mesh_free(&m);
}

/* ---- legal but unusual --------------------------------------------------------- */

static void test_legal(void)
{
    bp_atlas at;
    /* a single triangle */
    {
        bp_mesh m = bpt_mesh_new(3, 1);
        set_v(&m, 0, 0, 0, 0); set_v(&m, 1, 3, 0, 1); set_v(&m, 2, 0.2, 1, -1);
        set_t(&m, 0, 0, 1, 2);
        expect_fine("a single triangle", &m, NULL, NULL);
        bpt_mesh_free(&m);
    }
    /* duplicated vertices at one position: a cut from the boundary to the
       middle of a 4x4 grid (vertices 1, 6, 11 on column 1... here the
       quads left of the cut use copies of the column-2 vertices of rows
       0..2).  The chart stays one disk with a slit; the two sides of the
       slit coincide in 3D. */
    {
        bp_mesh g = grid(4, 4, NULL, 0.2), m;
        uint32_t t, k, extra = 3, copy[25];
        m = bpt_mesh_new(g.num_vertices + extra, g.num_triangles);
        memcpy(m.positions, g.positions, 3 * g.num_vertices * sizeof(double));
        memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
        for (k = 0; k < 25; k++) copy[k] = k;
        /* column i = 2, rows j = 0..2: vertices 2, 7, 12 */
        for (k = 0; k < 3; k++) {
            uint32_t v = 2 + 5 * k;
            copy[v] = g.num_vertices + k;
            set_v(&m, copy[v], g.positions[3 * v], g.positions[3 * v + 1], g.positions[3 * v + 2]);
        }
        /* the quads with i < 2 and j < 2 use the copies (vertex 12 is the
           slit's end: only triangles of quad (1,1) may use its copy... keep
           12 shared so the slit ends there) */
        copy[12] = 12;
        for (t = 0; t < m.num_triangles; t++) {
            uint32_t q = t / 2, qi = q % 4, qj = q / 4;
            if (qi < 2 && qj < 2)
                for (k = 0; k < 3; k++) m.triangles[3 * t + k] = copy[m.triangles[3 * t + k]];
        }
        memset(&at, 0, sizeof at);
        if (expect_fine("duplicated vertices at one position (a slit cut from the boundary)", &m, NULL, &at))
            BPT_CHECK(at.num_charts == 1 && at.charts[0].num_loops == 1 && at.charts[0].num_vertices == 27,
                      "slit: one disk chart with 27 vertices (%u charts, %u loops, %u vertices)",
                      (unsigned)at.num_charts, (unsigned)at.charts[0].num_loops, (unsigned)at.charts[0].num_vertices);
        bp_atlas_free(&at);
        /* an interior slit: copies of 7 only (6 and 8... vertices 7, 12 on
           column 2 between rows 1 and 2), used by quads (1,1), (1,2)... a
           closed slit 7-12-17 with both ends shared: a hole of zero 3D area */
        memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
        for (k = 0; k < 25; k++) copy[k] = k;
        copy[12] = g.num_vertices;
        set_v(&m, copy[12], g.positions[36], g.positions[37], g.positions[38]);
        for (t = 0; t < m.num_triangles; t++) {
            uint32_t q = t / 2, qi = q % 4, qj = q / 4;
            if (qi < 2 && (qj == 1 || qj == 2))
                for (k = 0; k < 3; k++) m.triangles[3 * t + k] = copy[m.triangles[3 * t + k]];
        }
        m.num_vertices = g.num_vertices + 1;
        memset(&at, 0, sizeof at);
        if (expect_fine("duplicated vertex at one position (an interior slit 7-12-17: a hole of zero area)", &m, NULL,
                        &at))
            BPT_CHECK(at.num_charts == 1 && at.charts[0].num_loops == 2,
                      "interior slit: one chart with an outer loop and a hole (%u charts, %u loops)",
                      (unsigned)at.num_charts, (unsigned)at.charts[0].num_loops);
        bp_atlas_free(&at);
        /* and a full cut: column 2 duplicated on every row -> two charts */
        memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
        bpt_mesh_free(&m);
        m = bpt_mesh_new(g.num_vertices + 5, g.num_triangles);
        memcpy(m.positions, g.positions, 3 * g.num_vertices * sizeof(double));
        memcpy(m.triangles, g.triangles, 3 * g.num_triangles * sizeof(uint32_t));
        for (k = 0; k < 25; k++) copy[k] = k;
        for (k = 0; k < 5; k++) {
            uint32_t v = 2 + 5 * k;
            copy[v] = g.num_vertices + k;
            set_v(&m, copy[v], g.positions[3 * v], g.positions[3 * v + 1], g.positions[3 * v + 2]);
        }
        for (t = 0; t < m.num_triangles; t++)
            if ((t / 2) % 4 < 2)
                for (k = 0; k < 3; k++) m.triangles[3 * t + k] = copy[m.triangles[3 * t + k]];
        memset(&at, 0, sizeof at);
        if (expect_fine("duplicated vertices along a full column: two charts that touch in 3D", &m, NULL, &at))
            BPT_CHECK(at.num_charts == 2, "full cut: two charts (%u)", (unsigned)at.num_charts);
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
        bpt_mesh_free(&g);
    }
    /* vt seams that pinch: spot.obj has 4 pinch vertices */
    {
        bp_mesh m;
        bp_error err;
        if (BPT_CHECK(bp_read_obj("tests/data/spot.obj", &m, NULL, &err) == BP_OK, "read spot.obj")) {
            bp_options o = defaults();
            o.max_iterations = 30;
            memset(&at, 0, sizeof at);
            if (expect_fine("spot.obj (vt seams with pinches), 30 iterations", &m, &o, &at)) {
                uint32_t c, sum = 0;
                for (c = 0; c < at.num_charts; c++) sum += at.charts[c].split_vertices;
                BPT_CHECK(at.num_split == 4 && sum == 4, "spot: 4 pinch vertices repaired (num_split %u, sum %u)",
                          (unsigned)at.num_split, (unsigned)sum);
            }
            bp_atlas_free(&at);
            bp_mesh_free(&m, NULL);
        }
    }
}

/* ~2000 single-quad holes: an 90 x 90 grid without every quad (i, j) with
   i and j odd, 1 <= i, j <= 87: 44 x 44 = 1936 holes. */
static int many_holes(int i, int j, int nx, int ny)
{
    return (i & 1) && (j & 1) && i < nx - 2 && j < ny - 2;
}

static void test_many_holes(void)
{
    bp_mesh m = grid(90, 90, many_holes, 0.5);
    bp_options o = defaults();
    bp_atlas at;
    double t0 = now();
    memset(&at, 0, sizeof at);
    if (expect_fine("grid with 1936 holes, default options", &m, &o, &at)) {
        BPT_CHECK(at.num_charts == 1 && at.charts[0].num_loops == 1937,
                  "many holes: one chart with 1937 loops (%u)", (unsigned)at.charts[0].num_loops);
        /* states, not wall time (a loaded machine is slow, not wrong) */
        BPT_CHECK(at.charts[0].iterations >= 1 && (at.charts[0].stop == BP_STOP_CONVERGED ||
                                                   at.charts[0].stop == BP_STOP_NO_PROGRESS ||
                                                   at.charts[0].stop == BP_STOP_MAX_ITERATIONS),
                  "many holes: %u triangles, %u loops, optimized: %d iterations, stop %s (%.2f s, not asserted)",
                  (unsigned)m.num_triangles, (unsigned)at.charts[0].num_loops, at.charts[0].iterations,
                  bp_stop_string(at.charts[0].stop), now() - t0);
    }
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* Scale: the method is scale-free (see test_optimize.c test_scale for the
   argument and the measured divergences at 1e3).  At 1e-6 and 1e6 each
   input coordinate is rounded, so the runs start ~1e-16 apart; after 20
   iterations they may differ by rounding amplified through 20 line
   searches, measured ~1e-8 of the chart size on bishop: checked < 1e-6.
   Here a holed curved grid (two holes) through the whole pipeline (packing
   included), so the barrier on hole loops is scaled too. */
static int two_holes(int i, int j, int nx, int ny)
{
    (void)nx; (void)ny;
    return (i == 2 && j == 2) || (i == 6 && j == 5);
}

static void test_scale(void)
{
    bp_mesh base = grid(9, 8, two_holes, 0.8);
    double scales[2] = { 1e-6, 1e6 }, *ref = NULL, size;
    uint32_t nv = 0, i;
    int k, it0 = 0;
    bp_options o = defaults();
    bp_atlas at;
    bp_error err;
    o.max_iterations = 20;
    if (!BPT_CHECK(bp_parameterize(&at, &base, &o, &err) == BP_OK && all_mapped_valid(&at), "two-hole grid at scale 1"))
    {
        bp_atlas_free(&at);
        bpt_mesh_free(&base);
        return;
    }
    nv = at.charts[0].num_vertices;
    it0 = at.charts[0].iterations;
    ref = (double *)malloc(2 * nv * sizeof(double));
    memcpy(ref, at.charts[0].uv, 2 * nv * sizeof(double));
    {
        double lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL };
        for (i = 0; i < nv; i++) {
            int c;
            for (c = 0; c < 2; c++) {
                if (ref[2 * i + c] < lo[c]) lo[c] = ref[2 * i + c];
                if (ref[2 * i + c] > hi[c]) hi[c] = ref[2 * i + c];
            }
        }
        size = hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1];
    }
    bp_atlas_free(&at);
    for (k = 0; k < 2; k++) {
        bp_mesh m = grid(9, 8, two_holes, 0.8);
        double diff = 0;
        for (i = 0; i < 3 * m.num_vertices; i++) m.positions[i] *= scales[k];
        if (BPT_CHECK(bp_parameterize(&at, &m, &o, &err) == BP_OK && all_mapped_valid(&at) &&
                          at.charts[0].num_vertices == nv,
                      "two-hole grid scaled by %g: BP_OK and valid (%s)", scales[k], err.message)) {
            for (i = 0; i < 2 * nv; i++) {
                double d = fabs(at.charts[0].uv[i] / scales[k] - ref[i]);
                if (!(d <= diff)) diff = d;
            }
            BPT_CHECK(diff <= 1e-6 * size && at.charts[0].iterations == it0,
                      "two-hole grid scaled by %g: map / scale equals the unscaled map to 1e-6 of the chart size "
                      "(max diff %.3g of the size, %d vs %d iterations)", scales[k], diff / size,
                      at.charts[0].iterations, it0);
        }
        bp_atlas_free(&at);
        bpt_mesh_free(&m);
    }
    free(ref);
    bpt_mesh_free(&base);
}

/* ---- status strings ----------------------------------------------------------- */

static void test_strings(void)
{
    int s, bad = 0;
    for (s = 0; s < BP_STATUS_COUNT; s++) {
        const char *str = bp_status_string((bp_status)s);
        if (!str || !str[0] || !strcmp(str, "unknown status")) bad++;
    }
    BPT_CHECK(bad == 0, "every one of the %d bp_status values has its own non-empty string", (int)BP_STATUS_COUNT);
    BPT_CHECK(!strcmp(bp_status_string(BP_OK), "ok") &&
                  !strcmp(bp_status_string(BP_ERR_CHARTS_FAILED), "some charts failed; the others are valid"),
              "strings match BP_STATUS_LIST");
    {
        const char *a = bp_status_string((bp_status)-1), *b = bp_status_string(BP_STATUS_COUNT),
                   *c = bp_status_string((bp_status)1000000), *d = bp_status_string((bp_status)INT32_MIN);
        BPT_CHECK(a && b && c && d && a[0] && !strcmp(a, b) && !strcmp(c, d),
                  "out-of-range statuses (-1, COUNT, 1e6, INT_MIN) give \"%s\" without crashing", a ? a : "(null)");
    }
    BPT_CHECK(bp_stop_string((bp_stop)-1)[0] && bp_energy_name((bp_energy)99)[0],
              "bp_stop_string / bp_energy_name out of range: non-empty");
}

/* ---- cancellation and limits --------------------------------------------------- */

typedef struct cancel_state {
    int at, calls, invalid;
    bp_atlas *atlas;
} cancel_state;

static int cancel_cb(void *user, uint32_t chart, int iteration, double e, double step)
{
    cancel_state *s = (cancel_state *)user;
    (void)e; (void)step; (void)chart;
    s->calls++;
    return iteration >= s->at;
}

static void test_cancel_sweep(void)
{
    bp_mesh m;
    bp_error err;
    static const int ks[] = { 1, 2, 3, 4, 5, 8, 13, 21, 34, 55 };
    int i, bad = 0, valid = 0, exact = 0;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &m, NULL, &err) == BP_OK, "read bishop")) return;
    /* the preconditioned L-BFGS (bishop's default is Newton, 12 iterations
       in all: too few for k = 13 .. 55), then Newton up to k = 8 */
    for (i = 0; i < (int)(sizeof ks / sizeof ks[0]) + 6; i++) {
        bp_options o = defaults();
        bp_atlas at;
        cancel_state s;
        bp_status st;
        int newton = i >= (int)(sizeof ks / sizeof ks[0]);
        memset(&s, 0, sizeof s);
        s.at = ks[newton ? i - (int)(sizeof ks / sizeof ks[0]) : i];
        o.direction = newton ? BP_DIRECTION_DEFAULT : BP_DIRECTION_PRECONDITIONED;
        o.progress = cancel_cb;
        o.progress_user = &s;
        st = bp_parameterize(&at, &m, &o, &err);
        if (st != BP_ERR_CANCELLED || !at.charts) { bad++; bp_atlas_free(&at); continue; }
        if (all_mapped_valid(&at)) valid++;
        if (at.charts[0].iterations == s.at && at.charts[0].stop == BP_STOP_CANCELLED && s.calls == s.at) exact++;
        bp_atlas_free(&at);
    }
    BPT_CHECK(bad == 0 && valid == 16 && exact == 16,
              "cancel at k = 1..55 (10 values, the preconditioned L-BFGS) and 1..8 (6 values, the default: Newton) on "
              "bishop: BP_ERR_CANCELLED, atlas kept, %d/16 valid, %d/16 stopped exactly at k", valid, exact);
    /* several charts (spot): cancel every chart at its k-th iteration */
    bp_mesh_free(&m, NULL);
    if (!BPT_CHECK(bp_read_obj("tests/data/spot.obj", &m, NULL, &err) == BP_OK, "read spot")) return;
    for (i = 0; i < 4; i++) {
        bp_options o = defaults();
        bp_atlas at;
        cancel_state s;
        bp_status st;
        memset(&s, 0, sizeof s);
        s.at = ks[i * 2];
        o.progress = cancel_cb;
        o.progress_user = &s;
        st = bp_parameterize(&at, &m, &o, &err);
        BPT_CHECK(st == BP_ERR_CANCELLED && at.charts && all_mapped_valid(&at),
                  "spot, cancel every chart at iteration %d: BP_ERR_CANCELLED and the packed atlas is valid (%s)",
                  s.at, bp_status_string(st));
        bp_atlas_free(&at);
    }
    bp_mesh_free(&m, NULL);
}

/* ---- cancellation: every chart valid or reported --------------------------------- */

/* After any bp_parameterize that keeps the atlas, every chart is either a
   valid map (error BP_OK, uv checked exactly) or a reported failure (error
   set, uv NULL), num_failed counts the failures, and the mapped charts are
   packed without overlap.  Returns the number of charts that break it. */
static uint32_t charts_in_a_state(const bp_atlas *at)
{
    uint32_t c, broken = 0, failed = 0;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (ch->error.status != BP_OK) { failed++; broken += ch->uv != NULL; }
        else broken += !chart_valid(ch);
    }
    return broken + (failed != at->num_failed) + !atlas_valid(at);
}

typedef struct chart_cancel { uint32_t chart; int at, calls_after; } chart_cancel;

static int cancel_chart_cb(void *user, uint32_t chart, int iteration, double e, double step)
{
    chart_cancel *s = (chart_cancel *)user;
    (void)e; (void)step;
    return chart == s->chart && iteration >= s->at;
}

/* spot (13 charts): cancel one chart at its k-th iteration, while another
   chart -- before or after it -- fails in the solve (a negative importance
   on one of its triangles: BP_ERR_INVALID_ARGUMENT from the optimizer,
   after its start map was made).  The call returns BP_ERR_CANCELLED with
   the atlas kept; the cancelled chart keeps its last valid map
   (BP_STOP_CANCELLED at iteration k); the failing chart is reported with uv
   NULL, whatever its place; every other chart is valid; the packed atlas
   is valid as a whole. */
static void test_cancel_states(void)
{
    static const uint32_t cancel_chart[4] = { 0, 0, 6, 12 }, fail_chart[4] = { 12, 5, 2, 1 };
    static const int ks[4] = { 1, 5, 20, 3 };
    bp_mesh m;
    bp_error err;
    bp_atlas at;
    double *imp;
    int i;
    uint32_t t;
    if (!BPT_CHECK(bp_read_obj("tests/data/spot.obj", &m, NULL, &err) == BP_OK, "read spot")) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, NULL, &err) == BP_OK && at.num_charts == 13, "spot: 13 charts")) {
        bp_atlas_free(&at);
        bp_mesh_free(&m, NULL);
        return;
    }
    imp = (double *)malloc(m.num_triangles * sizeof *imp);
    for (i = 0; i < 4; i++) {
        bp_options o = defaults();
        chart_cancel s;
        bp_status st;
        bp_atlas r;
        uint32_t bad_face = at.charts[fail_chart[i]].face[0], broken;
        const bp_chart *cc, *fc;
        for (t = 0; t < m.num_triangles; t++) imp[t] = 1;
        imp[bad_face] = -1;
        s.chart = cancel_chart[i];
        s.at = ks[i];
        o.progress = cancel_chart_cb;
        o.progress_user = &s;
        o.importance = imp;
        o.max_iterations = 60;
        st = bp_parameterize(&r, &m, &o, &err);
        if (!BPT_CHECK(st == BP_ERR_CANCELLED && r.charts && r.num_charts == 13,
                       "spot, cancel chart %u at iteration %d, chart %u fails: BP_ERR_CANCELLED, atlas kept (%s: %s)",
                       (unsigned)s.chart, s.at, (unsigned)fail_chart[i], bp_status_string(st), err.message)) {
            bp_atlas_free(&r);
            continue;
        }
        cc = &r.charts[s.chart];
        fc = &r.charts[fail_chart[i]];
        broken = charts_in_a_state(&r);
        BPT_CHECK(err.element == BP_ELEMENT_CHART && err.index == (int64_t)s.chart && cc->stop == BP_STOP_CANCELLED &&
                      cc->iterations == s.at && cc->error.status == BP_OK && chart_valid(cc),
                  "  the cancelled chart %u: named in err, stop %s at %d, its last map valid", (unsigned)s.chart,
                  bp_stop_string(cc->stop), cc->iterations);
        BPT_CHECK(fc->error.status == BP_ERR_INVALID_ARGUMENT && fc->uv == NULL && r.num_failed == 1,
                  "  the failing chart %u: reported (%s), uv %s, num_failed %u", (unsigned)fail_chart[i],
                  bp_status_string(fc->error.status), fc->uv ? "kept" : "NULL", (unsigned)r.num_failed);
        BPT_CHECK(broken == 0, "  every chart valid or reported, the packed atlas valid (%u broken)", (unsigned)broken);
        bp_atlas_free(&r);
    }
    free(imp);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* ---- local defects: repaired by default, errors in strict mode ----------------- */

/* Two squares far apart (charts 0 and 1); the second also holds a zero-area
   triangle, f 5 9 6 on line 15 (x = 5, 7, 6 on one line), glued to it along
   edge 5-6.  Default: the triangle is repaired (a regularized rest shape,
   >>rest), reported as the file names it (triangle 5, line 15; index 4),
   and stays in its neighbours' chart, which is mapped validly.  Strict:
   the whole call fails with the triangle. */
static const char two_squares_obj[] =
    "# two squares, the second with a zero-area triangle\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "v 5 0 0\nv 6 0 0\nv 6 1 0\nv 5 1 0\nv 7 0 0\n"
    "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n"
    "f 5 9 6\n";

static void test_local_defects(void)
{
    bp_mesh m;
    bp_error err;
    bp_atlas at;
    bp_options o = defaults();
    bp_status st;
    if (!BPT_CHECK(parse_obj(two_squares_obj, &m, &err) == BP_OK, "parse two squares")) return;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_OK && at.num_charts == 2 && all_mapped_valid(&at),
              "square + square with a zero-area triangle: repaired, both charts mapped and valid (%s): \"%s\"",
              bp_status_string(st), err.message);
    if (st == BP_OK && at.num_charts == 2) {
        const bp_repair *r = &at.repairs.kind[BP_REPAIR_DEGENERATE];
        BPT_CHECK(r->count == 1 && r->first[0] == 4 && r->first[1] == -1 && at.repairs.total == 1 &&
                      strstr(r->message, "triangle 5 (line 15)") && r->element == BP_ELEMENT_TRIANGLE,
                  "  reported: 1 degenerate, first index 4, message names triangle 5 (line 15): \"%s\"", r->message);
        BPT_CHECK(at.charts[1].num_triangles == 3 && at.charts[1].rest_side && at.charts[0].rest_side == NULL &&
                      at.charts[1].face[2] == 4 && at.charts[1].rest_side[2] > 0 && at.charts[1].rest_side[0] == 0,
                  "  the triangle stays in its neighbours' chart (3 triangles) with an equilateral rest shape "
                  "(side %g), the others keep theirs", at.charts[1].rest_side ? at.charts[1].rest_side[2] : -1.0);
    }
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_DEGENERATE && err.element == BP_ELEMENT_TRIANGLE && err.index == 4 && err.line == 15 &&
                  at.charts == NULL,
              "strict: BP_ERR_DEGENERATE for the whole call, triangle index 4 line 15, atlas zeroed (%s): \"%s\"",
              bp_status_string(st), err.message);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
    /* a triangle repeating a vertex inside the second of two grids: it
       cannot be glued (two corners would be one chart vertex) and becomes
       a chart of its own; everything is mapped */
    {
        bp_mesh g = grid(3, 3, NULL, 0.2);
        uint32_t nv = g.num_vertices, nt = g.num_triangles, i;
        bp_mesh two = bpt_mesh_new(2 * nv, 2 * nt);
        for (i = 0; i < nv; i++) {
            set_v(&two, i, g.positions[3 * i], g.positions[3 * i + 1], g.positions[3 * i + 2]);
            set_v(&two, nv + i, g.positions[3 * i] + 10, g.positions[3 * i + 1], g.positions[3 * i + 2]);
        }
        for (i = 0; i < 3 * nt; i++) {
            two.triangles[i] = g.triangles[i];
            two.triangles[3 * nt + i] = g.triangles[i] + nv;
        }
        two.triangles[3 * (nt + 7) + 2] = two.triangles[3 * (nt + 7)];   /* triangle nt+7: a b a */
        st = bp_parameterize(&at, &two, NULL, &err);
        BPT_CHECK(st == BP_OK && at.num_charts == 3 && all_mapped_valid(&at) &&
                      at.repairs.kind[BP_REPAIR_DEGENERATE].count == 1 &&
                      at.repairs.kind[BP_REPAIR_DEGENERATE].first[0] == nt + 7 &&
                      bpt_has_number(at.repairs.kind[BP_REPAIR_DEGENERATE].message, nt + 8),
                  "two grids, the second with a triangle that repeats a vertex: repaired as a chart of its own "
                  "(%u charts), every chart valid, reported naming triangle %u (%s: \"%s\")",
                  (unsigned)at.num_charts, (unsigned)(nt + 8), bp_status_string(st),
                  at.repairs.kind[BP_REPAIR_DEGENERATE].message);
        bp_atlas_free(&at);
        {
            bp_options so = defaults();
            so.strict = 1;
            st = bp_parameterize(&at, &two, &so, &err);
            BPT_CHECK(st == BP_ERR_DEGENERATE && err.index == nt + 7 && bpt_has_number(err.message, nt + 8) &&
                          strstr(err.message, "twice"),
                      "  strict: rejected naming triangle %u (%s: \"%s\")", (unsigned)(nt + 8), bp_status_string(st),
                      err.message);
            bp_atlas_free(&at);
        }
        bpt_mesh_free(&two);
        bpt_mesh_free(&g);
    }
}

/* ---- extreme scales ------------------------------------------------------------------ */

/* Is the chart's map, divided by 2^e (exact when it round-trips), valid?
   Scaling by a power of two is exact, so validity is unchanged, and the
   check then runs at a size where its products cannot over- or underflow. */
static int chart_valid_at(const bp_chart *ch, int e)
{
    bp_chart copy = *ch;
    uint32_t i;
    int ok;
    if (!ch->uv) return 0;
    copy.uv = (double *)malloc(2 * ch->num_vertices * sizeof(double));
    for (i = 0; i < 2 * ch->num_vertices; i++) {
        copy.uv[i] = ldexp(ch->uv[i], -e);
        if (ldexp(copy.uv[i], e) != ch->uv[i]) { free(copy.uv); return 0; }
    }
    ok = chart_valid(&copy);
    free(copy.uv);
    return ok;
}

/* bishop_part_f1000 (1 chart) and the needle grids scaled by powers of two
   and by 1e150, 1e-150, 1e300, 1e-300: bp_atlas_build judges each as at
   scale 1 (the needle of relative area 1e-6 is legal, 1e-13 degenerate,
   with a relative area in the message, not "nan" or "0"); bp_parameterize
   gives a valid map (checked after an exact rescale) or fails with
   BP_ERR_NUMERICAL saying why -- never a wrong map. */
static void test_extreme_scales(void)
{
    static const double factors[8] = { 0x1p500, 0x1p-500, 1e150, 1e-150, 1e300, 1e-300, 0x1p1000, 0x1p-1000 };
    bp_mesh base, m;
    bp_error err;
    int f;
    double *ref = NULL;
    uint32_t ref_nv = 0;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &base, NULL, &err) == BP_OK, "read bishop")) return;
    {
        bp_options o = defaults();
        bp_atlas at;
        o.max_iterations = 20;
        if (BPT_CHECK(bp_parameterize(&at, &base, &o, &err) == BP_OK, "bishop at scale 1 (%s)", err.message)) {
            ref_nv = at.charts[0].num_vertices;
            ref = (double *)malloc(2 * ref_nv * sizeof(double));
            memcpy(ref, at.charts[0].uv, 2 * ref_nv * sizeof(double));
        }
        bp_atlas_free(&at);
    }
    for (f = 0; f < 8; f++) {
        bp_options o = defaults(), strict_opt = defaults();
        bp_atlas at;
        bp_status st;
        uint32_t i;
        strict_opt.strict = 1;   /* the 1e-13 needle is an error only in strict mode */
        int e;
        (void)frexp(factors[f], &e);
        e -= 1;                                   /* 2^e <= factor < 2^(e+1) */
        m = base;
        m.positions = (double *)malloc(3 * base.num_vertices * sizeof(double));
        for (i = 0; i < 3 * base.num_vertices; i++) m.positions[i] = base.positions[i] * factors[f];
        st = bp_atlas_build(&at, &m, NULL, &err);
        BPT_CHECK(st == BP_OK && at.num_charts == 1 && at.num_failed == 0,
                  "bishop x %g: bp_atlas_build agrees with scale 1 (%s: %s)", factors[f], bp_status_string(st),
                  err.message);
        bp_atlas_free(&at);
        o.max_iterations = 20;
        st = bp_parameterize(&at, &m, &o, &err);
        if (st == BP_OK) {
            BPT_CHECK(chart_valid_at(&at.charts[0], e) && at.charts[0].iterations >= 1,
                      "bishop x %g: bp_parameterize BP_OK and the map (/ 2^%d) is valid, %d iterations", factors[f], e,
                      at.charts[0].iterations);
            if (ldexp(1, e) == factors[f] && ref) {
                /* a power of two is exact all the way: the same map, bit for bit */
                uint32_t same = at.charts[0].num_vertices == ref_nv;
                for (i = 0; same && i < 2 * ref_nv; i++) same = ldexp(at.charts[0].uv[i], -e) == ref[i];
                BPT_CHECK(same, "bishop x 2^%d: the map is the scale-1 map times 2^%d, bit for bit", e, e);
            }
        }
        else
            BPT_CHECK(st == BP_ERR_NUMERICAL && strstr(err.message, "scale") && at.charts == NULL,
                      "bishop x %g: not solvable, says why (%s: \"%s\")", factors[f], bp_status_string(st),
                      err.message);
        bp_atlas_free(&at);
        free(m.positions);
        /* the needles of test_degenerate, scaled */
        {
            double rel[2] = { 1e-6, 1e-13 };
            int k;
            for (k = 0; k < 2; k++) {
                bp_mesh n = grid_with_needle(1.0);
                double d2 = bpt_bbox_diag2(&n);
                bpt_mesh_free(&n);
                n = grid_with_needle(rel[k] * d2);
                for (i = 0; i < 3 * n.num_vertices; i++) n.positions[i] *= factors[f];
                st = bp_atlas_build(&at, &n, &strict_opt, &err);
                if (k == 0)
                    BPT_CHECK(st == BP_OK, "needle 2A = 1e-6 diag^2 x %g: legal as at scale 1 (%s: %s)", factors[f],
                              bp_status_string(st), err.message);
                else
                    BPT_CHECK(st == BP_ERR_DEGENERATE && err.index == 32 && !strstr(err.message, "nan") &&
                                  !strstr(err.message, "inf") && strstr(err.message, "e-13"),
                              "needle 2A = 1e-13 diag^2 x %g: degenerate as at scale 1, with its relative area: \"%s\"",
                              factors[f], err.message);
                bp_atlas_free(&at);
                bpt_mesh_free(&n);
            }
        }
    }
    free(ref);
    bp_mesh_free(&base, NULL);
}

/* camel_b without its texture coordinates (3,576 faces, one disk) scaled
   by 1e100, 1e200, 1e300, 1e-100, 1e-200 and 1e-300 (one rounding per
   coordinate): bp_parameterize must give BP_OK, the same charts, a map
   that is exactly valid at its own scale (checked after an exact rescale
   by a power of two), and that map divided by the factor must be the map
   at scale 1 to 1e-7 of its diameter (the copies differ from the original
   by the rounding of the scaled coordinates, which the solve carries). */
static void test_camel_scales(void)
{
    static const double factors[6] = { 1e100, 1e200, 1e300, 1e-100, 1e-200, 1e-300 };
    bp_mesh base, m;
    bp_error err;
    bp_atlas ref;
    uint32_t *cuv;
    double *uvs, diam = 0, lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL };
    uint32_t i, c;
    int f;
    bp_options o = defaults();
    o.max_iterations = 30;
    if (!BPT_CHECK(bp_read_obj("tests/data/camel_b.obj", &base, NULL, &err) == BP_OK, "read camel_b")) return;
    cuv = base.corner_uv; uvs = base.uvs;                 /* flattened from scratch, as without its vt */
    base.corner_uv = NULL; base.uvs = NULL;
    if (!BPT_CHECK(bp_parameterize(&ref, &base, &o, &err) == BP_OK && ref.num_failed == 0,
                   "camel_b at scale 1 (%s)", err.message)) {
        base.corner_uv = cuv; base.uvs = uvs;
        bp_mesh_free(&base, NULL);
        return;
    }
    for (c = 0; c < ref.num_charts; c++)
        for (i = 0; i < ref.charts[c].num_vertices; i++) {
            int k;
            for (k = 0; k < 2; k++) {
                double u = ref.charts[c].uv[2 * i + k];
                if (u < lo[k]) lo[k] = u;
                if (u > hi[k]) hi[k] = u;
            }
        }
    diam = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]));
    for (f = 0; f < 6; f++) {
        bp_atlas at;
        bp_status st;
        double worst = 0;
        int e, same = 1, valid = 1;
        (void)frexp(factors[f], &e);
        e -= 1;
        m = base;
        m.positions = (double *)malloc(3 * base.num_vertices * sizeof(double));
        for (i = 0; i < 3 * base.num_vertices; i++) m.positions[i] = base.positions[i] * factors[f];
        st = bp_parameterize(&at, &m, &o, &err);
        if (BPT_CHECK(st == BP_OK && at.num_failed == 0 && at.num_charts == ref.num_charts,
                      "camel_b x %g: bp_parameterize BP_OK, %u charts as at scale 1 (%s: %s)", factors[f],
                      ref.num_charts, bp_status_string(st), err.message)) {
            for (c = 0; c < at.num_charts; c++) {
                const bp_chart *a = &at.charts[c], *r = &ref.charts[c];
                valid &= chart_valid_at(a, e);
                same &= a->num_vertices == r->num_vertices;
                for (i = 0; same && i < 2 * a->num_vertices; i++) {
                    double d = fabs(a->uv[i] / factors[f] - r->uv[i]);
                    if (!(d <= worst)) worst = d;
                }
            }
            BPT_CHECK(valid, "camel_b x %g: every chart's map exactly valid (/ 2^%d)", factors[f], e);
            BPT_CHECK(same && worst <= 1e-7 * diam,
                      "camel_b x %g: the map / %g is the map at scale 1 (farthest vertex %.3g of the diameter)",
                      factors[f], factors[f], worst / diam);
        }
        bp_atlas_free(&at);
        free(m.positions);
    }
    bp_atlas_free(&ref);
    base.corner_uv = cuv; base.uvs = uvs;
    bp_mesh_free(&base, NULL);
}

/* The outline packer puts the charts into [0,1]^2 (atlas_resolution), so
   the map of a mesh solved on a rescaled copy must not be scaled back:
   bishop x 2^200 and x 2^-200 with atlas_resolution 256 give an atlas in
   [0,1]^2 that fills it about as the scale-1 one does (max coordinate
   above 0.5), and all of it valid. */
static void test_extreme_scale_atlas(void)
{
    static const int exps[2] = { 200, -200 };
    bp_mesh base, m;
    bp_error err;
    int f;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &base, NULL, &err) == BP_OK, "read bishop")) return;
    for (f = 0; f < 2; f++) {
        bp_options o = defaults();
        bp_atlas at;
        bp_status st;
        uint32_t i, c;
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        m = base;
        m.positions = (double *)malloc(3 * base.num_vertices * sizeof(double));
        for (i = 0; i < 3 * base.num_vertices; i++) m.positions[i] = ldexp(base.positions[i], exps[f]);
        o.max_iterations = 20;
        o.atlas_resolution = 256;
        st = bp_parameterize(&at, &m, &o, &err);
        if (BPT_CHECK(st == BP_OK, "bishop x 2^%d, atlas_resolution 256: BP_OK (%s)", exps[f], err.message)) {
            for (c = 0; c < at.num_charts; c++)
                for (i = 0; at.charts[c].uv && i < 2 * at.charts[c].num_vertices; i++) {
                    if (at.charts[c].uv[i] < lo) lo = at.charts[c].uv[i];
                    if (at.charts[c].uv[i] > hi) hi = at.charts[c].uv[i];
                }
            BPT_CHECK(lo >= 0 && hi <= 1 && hi > 0.5 && all_mapped_valid(&at),
                      "bishop x 2^%d, atlas_resolution 256: the atlas lies in [0,1]^2 and fills it "
                      "(coordinates %g .. %g), valid", exps[f], lo, hi);
        }
        bp_atlas_free(&at);
        free(m.positions);
    }
    bp_mesh_free(&base, NULL);
}

static void test_limits(void)
{
    bp_mesh m;
    bp_error err;
    bp_atlas at;
    int iters[3] = { 1, 7, 40 }, i;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &m, NULL, &err) == BP_OK, "read bishop")) return;
    for (i = 0; i < 3; i++) {
        bp_options o = defaults();
        o.max_iterations = iters[i];
        if (iters[i] > 10) o.direction = BP_DIRECTION_PRECONDITIONED;   /* bishop's default (Newton) converges in 12 */
        if (BPT_CHECK(bp_parameterize(&at, &m, &o, &err) == BP_OK, "bishop, max_iterations %d: BP_OK", iters[i]))
            BPT_CHECK(at.charts[0].iterations == iters[i] && at.charts[0].stop == BP_STOP_MAX_ITERATIONS &&
                          all_mapped_valid(&at),
                      "bishop, max_iterations %d: %d iterations, stop %s, valid", iters[i], at.charts[0].iterations,
                      bp_stop_string(at.charts[0].stop));
        bp_atlas_free(&at);
    }
    bp_mesh_free(&m, NULL);
    /* max_seconds: a limit far below one iteration stops every chart after
       its first iteration (the limit is checked after each one), with a
       valid map, on bishop (1 chart) and spot (13 charts); without it the
       same charts run on (so the limit is what stopped them). */
    {
        static const char *const files[2] = { "tests/data/bishop_part_f1000.obj", "tests/data/spot.obj" };
        int f;
        for (f = 0; f < 2; f++) {
            bp_options o = defaults();
            uint32_t c, stopped = 0, ran_on = 0;
            if (!BPT_CHECK(bp_read_obj(files[f], &m, NULL, &err) == BP_OK, "read %s", files[f])) continue;
            o.max_seconds = 1e-300;
            if (BPT_CHECK(bp_parameterize(&at, &m, &o, &err) == BP_OK, "%s, max_seconds 1e-300: BP_OK (%s)", files[f],
                          err.message)) {
                for (c = 0; c < at.num_charts; c++)
                    stopped += at.charts[c].stop == BP_STOP_MAX_SECONDS && at.charts[c].iterations == 1;
                BPT_CHECK(stopped == at.num_charts && all_mapped_valid(&at),
                          "%s, max_seconds 1e-300: %u of %u charts stopped by the limit after 1 iteration, valid",
                          files[f], (unsigned)stopped, (unsigned)at.num_charts);
            }
            bp_atlas_free(&at);
            o.max_seconds = 0;
            o.max_iterations = 3;
            if (bp_parameterize(&at, &m, &o, &err) == BP_OK)
                for (c = 0; c < at.num_charts; c++) ran_on += at.charts[c].iterations > 1;
            BPT_CHECK(ran_on > 0, "%s without the limit: %u charts run past 1 iteration", files[f], (unsigned)ran_on);
            bp_atlas_free(&at);
            bp_mesh_free(&m, NULL);
        }
    }
}

int main(void)
{
    test_strings();
    test_empty();
    test_nonfinite();
    test_indices();
    test_degenerate();
    test_topology();
    test_bowtie();
    test_closed();
    test_mixed();
    test_legal();
    test_scale();
    test_cancel_sweep();
    test_cancel_states();
    test_local_defects();
    test_extreme_scales();
    test_camel_scales();
    test_extreme_scale_atlas();
    test_limits();
    test_many_holes();
    return bpt_finish();
}
