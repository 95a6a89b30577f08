/* test_repair.c - defects repaired instead of rejected (bp_atlas_build,
   "repair" in >>charts, the regularized rest shape in >>rest).

   For each defect a real mesh (bishop_part_f1000.obj) or a small built one
   is damaged on purpose, and then, by default:
     - bp_parameterize returns BP_OK and every chart and the packed atlas
       pass the exact check (bp_check),
     - atlas.repairs reports the right count and the right first elements
       (worked out here from how the mesh was damaged, not from the library),
       and its message names them as the file numbers them (from 1),
     - corner_chart / corner_vertex still give every mesh corner a chart
       vertex of its own mesh vertex, and a chart triangle runs the same
       way as its mesh triangle exactly when that triangle was not flipped;
   and with opt.strict the call fails naming the element, as before.
   Where the repair leaves the glued surface unchanged (a tie in the
   orientation vote, dropped duplicates) the map must be bit-identical to
   the clean mesh's.  The energies of repaired against clean meshes are
   printed for the record (not asserted: they are results, not truths). */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const bishop_path = "tests/data/bishop_part_f1000.obj";

/* ---- validity (the exact check) ------------------------------------------ */

static int report_valid(const bp_check_report *r)
{
    return !r->flipped && !r->degenerate && !r->nonfinite && !r->boundary_intersections &&
           !r->loop_orientation && !r->nested;
}

/* Every chart mapped, each valid, and all of them together (the packed
   atlas) valid as one triangulation: no two charts overlap. */
static int all_valid(const bp_atlas *at)
{
    uint32_t c, nt = 0, nv = 0, ot = 0, ov = 0, i;
    uint32_t *tri;
    double *uv;
    bp_check_report r;
    int ok = at->num_charts > 0;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (!ch->uv) return 0;
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK ||
            !report_valid(&r))
            ok = 0;
        nt += ch->num_triangles;
        nv += ch->num_vertices;
    }
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri);
    uv = (double *)malloc(2 * (size_t)nv * sizeof *uv);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
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

/* The corners against the charts.  Every mesh corner must name a chart
   vertex of its own mesh vertex, and all three corners of a triangle the
   same chart.  A triangle in a chart is "flipped" when its chart triangle
   runs (corner 0, corner 2, corner 1) of the mesh triangle; flipped[t] is
   set to 1 then, 0 when it runs (0, 1, 2), 2 when it is in no chart (a
   dropped copy).  Returns 0 on any inconsistency. */
static int corners_consistent(const bp_atlas *at, const bp_mesh *m, unsigned char *flipped)
{
    uint32_t t, k, c, ct;
    uint32_t *chart_tri = (uint32_t *)malloc(m->num_triangles * sizeof(uint32_t));
    int ok = at->num_corners == 3 * m->num_triangles;
    for (t = 0; t < m->num_triangles; t++) chart_tri[t] = UINT32_MAX;
    for (c = 0; c < at->num_charts; c++)
        for (ct = 0; ct < at->charts[c].num_triangles; ct++) {
            uint32_t f = at->charts[c].face[ct];
            if (chart_tri[f] != UINT32_MAX || at->corner_chart[3 * f] != c) ok = 0;
            chart_tri[f] = ct;
        }
    for (t = 0; ok && t < m->num_triangles; t++) {
        const bp_chart *ch = &at->charts[at->corner_chart[3 * t]];
        uint32_t cv[3];
        for (k = 0; k < 3; k++) {
            cv[k] = at->corner_vertex[3 * t + k];
            if (at->corner_chart[3 * t + k] != at->corner_chart[3 * t] || cv[k] >= ch->num_vertices ||
                ch->vertex[cv[k]] != m->triangles[3 * t + k])
                ok = 0;
        }
        if (!ok) break;
        if (chart_tri[t] == UINT32_MAX) { flipped[t] = 2; continue; }
        {
            const uint32_t *tr = ch->triangles + 3 * (size_t)chart_tri[t];
            if (tr[0] == cv[0] && tr[1] == cv[1] && tr[2] == cv[2]) flipped[t] = 0;
            else if (tr[0] == cv[0] && tr[1] == cv[2] && tr[2] == cv[1]) flipped[t] = 1;
            else ok = 0;
        }
    }
    free(chart_tri);
    return ok;
}

static double mean_energy(const bp_atlas *at)
{
    double s = 0, a = 0;
    uint32_t c;
    for (c = 0; c < at->num_charts; c++) {
        s += at->charts[c].energy_end * at->charts[c].area3d;
        a += at->charts[c].area3d;
    }
    return a > 0 ? s / a : 0;
}

static bp_options options(int strict)
{
    bp_options o;
    memset(&o, 0, sizeof o);
    o.max_iterations = 300;
    o.threads = 1;
    o.strict = strict;
    return o;
}

/* A copy of m with room for `extra` more triangles. */
static bp_mesh copy_mesh(const bp_mesh *m, uint32_t extra)
{
    bp_mesh c = bpt_mesh_new(m->num_vertices, m->num_triangles + extra);
    memcpy(c.positions, m->positions, 3 * (size_t)m->num_vertices * sizeof(double));
    memcpy(c.triangles, m->triangles, 3 * (size_t)m->num_triangles * sizeof(uint32_t));
    return c;
}

static int same_maps(const bp_atlas *a, const bp_atlas *b)
{
    uint32_t c;
    if (a->num_charts != b->num_charts) return 0;
    for (c = 0; c < a->num_charts; c++)
        if (a->charts[c].num_vertices != b->charts[c].num_vertices || !a->charts[c].uv || !b->charts[c].uv ||
            memcmp(a->charts[c].uv, b->charts[c].uv, 2 * (size_t)a->charts[c].num_vertices * sizeof(double)))
            return 0;
    return 1;
}

/* first[0..min(count,4)) == want[...], the rest -1 */
static int firsts_are(const bp_repair *r, const int64_t *want, const int64_t *want2, uint32_t count)
{
    uint32_t i;
    for (i = 0; i < BP_REPAIR_FIRST; i++) {
        int64_t w = i < count ? want[i] : -1, w2 = i < count && want2 ? want2[i] : -1;
        if (r->first[i] != w || r->first2[i] != w2) return 0;
    }
    return 1;
}

/* ---- orientation ---------------------------------------------------------- */

/* Flip triangle t of m (swap corners 1 and 2). */
static void flip_tri(bp_mesh *m, uint32_t t)
{
    uint32_t x = m->triangles[3 * t + 1];
    m->triangles[3 * t + 1] = m->triangles[3 * t + 2];
    m->triangles[3 * t + 2] = x;
}

/* bishop, some triangles flipped by `pick`: the repair must flip back
   exactly the minority (on a tie, the triangles unlike triangle 0). */
static void test_orientation_case(const bp_mesh *clean, const bp_atlas *ref, const char *what, int mod)
{
    bp_mesh m = copy_mesh(clean, 0);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t t, nt = m.num_triangles, ndamaged = 0, nwant = 0, got_flips = 0;
    unsigned char *damaged = (unsigned char *)calloc(nt, 1), *fl = (unsigned char *)calloc(nt, 1), want_set;
    int64_t want[4];
    /* mod 2: every odd triangle flipped (a tie); mod 3: two of every three
       (the flipped ones are the majority) */
    for (t = 0; t < nt; t++)
        if ((mod == 2 && t % 2 == 1) || (mod == 3 && t % 3 != 0)) { flip_tri(&m, t); damaged[t] = 1; ndamaged++; }
    want_set = 2 * ndamaged > nt ? 0 : 1;    /* the repair flips the minority: damaged == want_set */
    for (t = 0; t < nt; t++)
        if (damaged[t] == want_set) { if (nwant < 4) want[nwant] = t; nwant++; }
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at), "%s: BP_OK and a valid atlas (%s: %s)", what, bp_status_string(st),
                  err.message)) {
        const bp_repair *r = &at.repairs.kind[BP_REPAIR_FLIPPED];
        int corners = corners_consistent(&at, &m, fl);
        int exact = corners;
        for (t = 0; corners && t < nt; t++) {
            got_flips += fl[t] == 1;
            if ((fl[t] == 1) != (damaged[t] == want_set)) exact = 0;
        }
        BPT_CHECK(corners && exact && got_flips == nwant,
                  "%s: corners consistent, the chart triangles reversed are exactly the %u minority ones (got %u)",
                  what, (unsigned)nwant, (unsigned)got_flips);
        BPT_CHECK(r->count == nwant && at.repairs.total == nwant && firsts_are(r, want, NULL, nwant < 4 ? nwant : 4) &&
                      r->element == BP_ELEMENT_TRIANGLE && bpt_has_number(r->message, want[0] + 1) &&
                      bpt_has_number(r->message, (long long)nwant),
                  "%s: reported %u flipped (want %u), first %lld %lld ...: \"%s\"", what, (unsigned)r->count,
                  (unsigned)nwant, (long long)r->first[0], (long long)r->first[1], r->message);
        if (mod == 2)
            BPT_CHECK(same_maps(&at, ref), "%s: a tie keeps triangle 0's orientation: the map is bit-identical "
                      "to the clean mesh's", what);
        printf("     %s: mean energy %.6f (clean %.6f), %u charts\n", what, mean_energy(&at), mean_energy(ref),
               (unsigned)at.num_charts);
    }
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_ORIENTATION && err.element == BP_ELEMENT_EDGE && at.charts == NULL &&
                  bpt_has_number(err.message, err.index + 1) && bpt_has_number(err.message, err.index2 + 1),
              "%s, strict: BP_ERR_ORIENTATION naming the edge (%s: \"%s\")", what, bp_status_string(st), err.message);
    bp_atlas_free(&at);
    free(damaged);
    free(fl);
    bpt_mesh_free(&m);
}

/* A Moebius band of n quads: no orientation agrees everywhere.  The
   repair cuts the edges where the walk meets itself reversed; the rest is
   a disk, mapped validly. */
static void test_moebius(void)
{
    const uint32_t n = 24;
    bp_mesh m = bpt_mesh_new(2 * n, 2 * n);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t i;
    for (i = 0; i < n; i++) {
        double u = 2 * 3.14159265358979 * i / n, w;
        for (w = -1; w <= 1; w += 2) {
            uint32_t v = 2 * i + (w > 0);
            double r = 3 + 0.6 * w * cos(u / 2);
            m.positions[3 * v] = r * cos(u);
            m.positions[3 * v + 1] = r * sin(u);
            m.positions[3 * v + 2] = 0.6 * w * sin(u / 2);
        }
    }
    for (i = 0; i < n; i++) {
        uint32_t a = 2 * i, b = 2 * i + 1, c = 2 * ((i + 1) % n), d = c + 1;
        if (i == n - 1) { uint32_t x = c; c = d; d = x; }   /* the half twist */
        m.triangles[6 * i] = a; m.triangles[6 * i + 1] = c; m.triangles[6 * i + 2] = d;
        m.triangles[6 * i + 3] = a; m.triangles[6 * i + 4] = d; m.triangles[6 * i + 5] = b;
    }
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_OK && all_valid(&at) && at.repairs.kind[BP_REPAIR_NONORIENTABLE].count >= 1 &&
                  at.repairs.kind[BP_REPAIR_NONORIENTABLE].element == BP_ELEMENT_EDGE &&
                  bpt_has_number(at.repairs.kind[BP_REPAIR_NONORIENTABLE].message,
                                 at.repairs.kind[BP_REPAIR_NONORIENTABLE].first[0] + 1),
              "Moebius band: cut (%u edges), mapped validly (%s: %s; \"%s\")",
              (unsigned)at.repairs.kind[BP_REPAIR_NONORIENTABLE].count, bp_status_string(st), err.message,
              at.repairs.kind[BP_REPAIR_NONORIENTABLE].message);
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_ORIENTATION && err.element == BP_ELEMENT_EDGE,
              "Moebius band, strict: BP_ERR_ORIENTATION (%s: \"%s\")", bp_status_string(st), err.message);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* ---- duplicates ----------------------------------------------------------- */

static void test_duplicates(const bp_mesh *clean, const bp_atlas *ref)
{
    /* copies of triangles 10 (same order), 20 (rotated), 30 (reversed) */
    bp_mesh m = copy_mesh(clean, 3);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t nt = clean->num_triangles, i;
    const uint32_t *T = clean->triangles;
    int64_t want[3], want2[3] = { 10, 20, 30 };
    unsigned char *fl = (unsigned char *)calloc(nt + 3, 1);
    for (i = 0; i < 3; i++) want[i] = nt + i;
    memcpy(m.triangles + 3 * nt, T + 30, 3 * sizeof(uint32_t));
    m.triangles[3 * nt + 3] = T[61]; m.triangles[3 * nt + 4] = T[62]; m.triangles[3 * nt + 5] = T[60];
    m.triangles[3 * nt + 6] = T[92]; m.triangles[3 * nt + 7] = T[91]; m.triangles[3 * nt + 8] = T[90];
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at), "bishop + 3 duplicate faces: BP_OK, valid (%s: %s)",
                  bp_status_string(st), err.message)) {
        const bp_repair *r = &at.repairs.kind[BP_REPAIR_DUPLICATE];
        int corners = corners_consistent(&at, &m, fl);
        BPT_CHECK(r->count == 3 && at.repairs.total == 3 && firsts_are(r, want, want2, 3) &&
                      bpt_has_number(r->message, nt + 1) && bpt_has_number(r->message, 11) &&
                      bpt_has_number(r->message, nt + 3) && bpt_has_number(r->message, 31),
                  "  reported: 3 duplicates, triangles %u %u %u repeating 11 21 31: \"%s\"", (unsigned)nt + 1,
                  (unsigned)nt + 2, (unsigned)nt + 3, r->message);
        BPT_CHECK(corners && fl[nt] == 2 && fl[nt + 1] == 2 && fl[nt + 2] == 2 &&
                      at.corner_vertex[3 * nt + 2] == at.corner_vertex[3 * 10 + 2] &&
                      at.corner_vertex[3 * nt + 6] == at.corner_vertex[3 * 30 + 2],
                  "  the copies are in no chart; their corners take the twin's chart vertices");
        BPT_CHECK(same_maps(&at, ref), "  the map is bit-identical to the clean mesh's");
    }
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_DUPLICATE_FACE && err.element == BP_ELEMENT_TRIANGLE && err.index == nt &&
                  err.index2 == 10 && bpt_has_number(err.message, nt + 1) && bpt_has_number(err.message, 11),
              "  strict: BP_ERR_DUPLICATE_FACE naming triangles %u and 11 (%s: \"%s\")", (unsigned)nt + 1,
              bp_status_string(st), err.message);
    bp_atlas_free(&at);
    free(fl);
    bpt_mesh_free(&m);
}

/* ---- non-manifold edges and vertices -------------------------------------- */

/* Three fins on a spine of three vertices 0 1 2 along x: fin f is a strip
   of two quads in direction (0, cos 120f, sin 120f).  Edges 0-1 and 1-2
   have three triangles each. */
static void test_fins(void)
{
    bp_mesh m = bpt_mesh_new(3 + 3 * 3, 3 * 4);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t f, i, t = 0;
    int64_t want[2] = { 0, 1 }, want2[2] = { 1, 2 };
    for (i = 0; i < 3; i++) { m.positions[3 * i] = i; m.positions[3 * i + 1] = 0; m.positions[3 * i + 2] = 0; }
    for (f = 0; f < 3; f++) {
        double a = 2 * 3.14159265358979 * f / 3;
        for (i = 0; i < 3; i++) {
            uint32_t v = 3 + 3 * f + i;
            m.positions[3 * v] = i;
            m.positions[3 * v + 1] = cos(a);
            m.positions[3 * v + 2] = sin(a);
        }
        for (i = 0; i < 2; i++) {
            uint32_t a0 = i, a1 = i + 1, b0 = 3 + 3 * f + i, b1 = b0 + 1;
            m.triangles[3 * t] = a0; m.triangles[3 * t + 1] = a1; m.triangles[3 * t + 2] = b1; t++;
            m.triangles[3 * t] = a0; m.triangles[3 * t + 1] = b1; m.triangles[3 * t + 2] = b0; t++;
        }
    }
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_OK && all_valid(&at) && at.num_charts == 3, "three fins: BP_OK, 3 charts, valid (%s: %s)",
              bp_status_string(st), err.message);
    BPT_CHECK(at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE].count == 2 &&
                  firsts_are(&at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE], want, want2, 2) &&
                  strstr(at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE].message, "edge 1-2") &&
                  strstr(at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE].message, "edge 2-3"),
              "  reported: 2 non-manifold edges, 1-2 and 2-3 as the file numbers them: \"%s\"",
              at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE].message);
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_NONMANIFOLD && err.element == BP_ELEMENT_EDGE && err.index == 0 && err.index2 == 1 &&
                  strstr(err.message, "edge 1-2"),
              "  strict: BP_ERR_NONMANIFOLD naming edge 1-2 (%s: \"%s\")", bp_status_string(st), err.message);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* Two open cones touching at their tips (vertex 0): a non-manifold vertex.
   The charts are the edge-connected pieces, so the tip is one chart vertex
   in each cone; no repair is needed and strict accepts it too. */
static void test_cones(void)
{
    const uint32_t n = 8;
    bp_mesh m = bpt_mesh_new(1 + 2 * n, 2 * n);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    uint32_t i, s, t = 0;
    int strict;
    for (s = 0; s < 2; s++)
        for (i = 0; i < n; i++) {
            double a = 2 * 3.14159265358979 * i / n;
            uint32_t v = 1 + s * n + i;
            m.positions[3 * v] = cos(a);
            m.positions[3 * v + 1] = sin(a);
            m.positions[3 * v + 2] = s ? -1 : 1;
            /* outward normals: the top cone's fan runs the other way */
            m.triangles[3 * t] = 0;
            m.triangles[3 * t + 1] = s ? 1 + s * n + i : 1 + s * n + (i + 1) % n;
            m.triangles[3 * t + 2] = s ? 1 + s * n + (i + 1) % n : 1 + s * n + i;
            t++;
        }
    for (strict = 0; strict < 2; strict++) {
        bp_status st;
        o.strict = strict;
        st = bp_parameterize(&at, &m, &o, &err);
        BPT_CHECK(st == BP_OK && all_valid(&at) && at.num_charts == 2 && at.repairs.total == 0,
                  "two cones touching at the tip%s: BP_OK, 2 charts, valid, nothing to repair (%s: %s)",
                  strict ? " (strict)" : "", bp_status_string(st), err.message);
        bp_atlas_free(&at);
    }
    bpt_mesh_free(&m);
}

/* ---- degenerate triangles ------------------------------------------------- */

static double area2(const bp_mesh *m, uint32_t t)
{
    const double *a = m->positions + 3 * m->triangles[3 * t], *b = m->positions + 3 * m->triangles[3 * t + 1],
                 *c = m->positions + 3 * m->triangles[3 * t + 2];
    double u[3], v[3], n[3];
    int k;
    for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = c[k] - a[k]; }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* bishop with triangle 100 made collinear (its third vertex moved to the
   midpoint of the other two), triangle 400 a needle of relative area
   1e-14 (below the 1e-12 threshold), and triangle 700 collapsed to a point
   (all three vertices at one position, so its neighbours on two of them
   collapse too).  The degenerate set is counted here by its own area test
   (twice the area at most 1e-12 diag^2; the damaged ones are far from the
   threshold either way). */
static void test_degenerate(const bp_mesh *clean, const bp_atlas *ref)
{
    bp_mesh m = copy_mesh(clean, 0);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t t, nt = m.num_triangles, k, ndeg = 0;
    int64_t want[4];
    double d2 = bpt_bbox_diag2(clean), *P = m.positions;
    const uint32_t *T = m.triangles;
    {   /* 100: collinear */
        uint32_t a = T[300], b = T[301], c = T[302];
        for (k = 0; k < 3; k++) P[3 * c + k] = 0.5 * (P[3 * a + k] + P[3 * b + k]);
    }
    {   /* 400: a needle, the apex h above the midpoint of its base, 2A = |ab| h = 1e-14 diag^2 */
        uint32_t a = T[1200], b = T[1201], c = T[1202];
        double ab[3], len = 0, n[3], nl, h;
        for (k = 0; k < 3; k++) { ab[k] = P[3 * b + k] - P[3 * a + k]; len += ab[k] * ab[k]; }
        len = sqrt(len);
        n[0] = ab[1]; n[1] = -ab[0]; n[2] = 0;          /* perpendicular to ab */
        nl = sqrt(n[0] * n[0] + n[1] * n[1]);
        h = 1e-14 * d2 / len;
        for (k = 0; k < 3; k++) P[3 * c + k] = 0.5 * (P[3 * a + k] + P[3 * b + k]) + h * n[k] / nl;
    }
    {   /* 700: to a point */
        uint32_t a = T[2100], b = T[2101], c = T[2102];
        for (k = 0; k < 3; k++) P[3 * b + k] = P[3 * c + k] = P[3 * a + k];
    }
    for (t = 0; t < nt; t++)
        if (area2(&m, t) <= 1e-12 * d2) { if (ndeg < 4) want[ndeg] = t; ndeg++; }
    BPT_CHECK(ndeg >= 3 && area2(&m, 100) <= 1e-12 * d2 && area2(&m, 400) <= 1e-12 * d2 &&
                  area2(&m, 400) > 0 && area2(&m, 700) == 0,
              "bishop damaged: %u degenerate triangles (100, 400, 700 among them)", (unsigned)ndeg);
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at), "bishop with zero-area and needle triangles: BP_OK, valid (%s: %s)",
                  bp_status_string(st), err.message)) {
        const bp_repair *r = &at.repairs.kind[BP_REPAIR_DEGENERATE];
        uint32_t c, nside = 0, nreg = 0;
        for (c = 0; c < at.num_charts; c++)
            for (t = 0; t < at.charts[c].num_triangles; t++) {
                int deg = area2(&m, at.charts[c].face[t]) <= 1e-12 * d2;
                nreg += deg;
                if (at.charts[c].rest_side && (at.charts[c].rest_side[t] > 0) == deg) nside++;
                else if (!at.charts[c].rest_side && !deg) nside++;
            }
        BPT_CHECK(r->count == ndeg && at.repairs.total == ndeg && firsts_are(r, want, NULL, ndeg < 4 ? ndeg : 4) &&
                      bpt_has_number(r->message, want[0] + 1),
                  "  reported: %u degenerate (want %u), first %lld (want %lld): \"%s\"", (unsigned)r->count,
                  (unsigned)ndeg, (long long)r->first[0], (long long)want[0], r->message);
        BPT_CHECK(nside == nt && nreg == ndeg,
                  "  exactly the degenerate triangles have a regularized rest shape (%u of %u agree)", (unsigned)nside,
                  (unsigned)nt);
        printf("     bishop, %u degenerate triangles repaired: mean energy %.6f (clean %.6f), %u charts\n",
               (unsigned)ndeg, mean_energy(&at), mean_energy(ref), (unsigned)at.num_charts);
    }
    bp_atlas_free(&at);
    o.strict = 1;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_DEGENERATE && err.element == BP_ELEMENT_TRIANGLE && err.index == want[0] &&
                  bpt_has_number(err.message, want[0] + 1),
              "  strict: BP_ERR_DEGENERATE naming triangle %lld (%s: \"%s\")", (long long)want[0] + 1,
              bp_status_string(st), err.message);
    bp_atlas_free(&at);
    bpt_mesh_free(&m);
}

/* Everything at once, in a file: the messages name triangles and lines.
   Triangles 3, 4 and 7 form one component (edge 2-5 has three triangles,
   1, 4 and 6, and is a seam): 3 runs against both others, so it is the
   minority and flipped. */
static void test_obj_file(void)
{
    static const char text[] =
        "# a 2x1 strip, one face flipped, one duplicated, one fin, one zero-area\n"
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 1 0.5 1\nv 3 0 0\n"
        "f 1 2 5\n"      /* line 10, triangle 1 */
        "f 1 5 4\n"      /* 11 */
        "f 2 6 3\n"      /* 12, clockwise seen from +z: flipped */
        "f 2 6 5\n"      /* 13 */
        "f 5 1 2\n"      /* 14, a copy of triangle 1 */
        "f 2 5 7\n"      /* 15, fin on edge 2-5 */
        "f 2 8 3\n";     /* 16, zero area: 2, 8, 3 on the x axis */
    bp_mesh m;
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st = bp_parse_obj(text, strlen(text), &m, NULL, &err);
    if (!BPT_CHECK(st == BP_OK, "parse the defect strip (%s)", err.message)) return;
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at), "defect strip: BP_OK, valid (%s: %s)", bp_status_string(st),
                  err.message)) {
        const bp_repair *K = at.repairs.kind;
        BPT_CHECK(K[BP_REPAIR_DUPLICATE].count == 1 && strstr(K[BP_REPAIR_DUPLICATE].message, "triangle 5 (line 14)") &&
                      strstr(K[BP_REPAIR_DUPLICATE].message, "triangle 1 (line 10)"),
                  "  duplicate named with lines: \"%s\"", K[BP_REPAIR_DUPLICATE].message);
        BPT_CHECK(K[BP_REPAIR_NONMANIFOLD_EDGE].count == 1 && strstr(K[BP_REPAIR_NONMANIFOLD_EDGE].message, "edge 2-5"),
                  "  fin edge named: \"%s\"", K[BP_REPAIR_NONMANIFOLD_EDGE].message);
        BPT_CHECK(K[BP_REPAIR_DEGENERATE].count == 1 && strstr(K[BP_REPAIR_DEGENERATE].message, "triangle 7 (line 16)"),
                  "  zero-area triangle named with its line: \"%s\"", K[BP_REPAIR_DEGENERATE].message);
        BPT_CHECK(K[BP_REPAIR_FLIPPED].count == 1 && strstr(K[BP_REPAIR_FLIPPED].message, "triangle 3 (line 12)"),
                  "  flipped triangle named with its line: \"%s\"", K[BP_REPAIR_FLIPPED].message);
    }
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* A repaired degenerate triangle on a mesh of extreme size (solved on a
   copy rescaled by a power of two, >>driver): the map is valid and the
   rest side is in the mesh's units, 2^200 times that at scale 1. */
static void test_degenerate_scaled(void)
{
    static const char text[] =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
        "f 1 2 3\nf 1 3 4\nf 1 5 2\n";       /* 1 5 2: zero area, on the x axis */
    bp_mesh m;
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    double side1 = -1, side2 = -2;
    uint32_t i;
    int pass;
    if (!BPT_CHECK(bp_parse_obj(text, strlen(text), &m, NULL, &err) == BP_OK, "parse the square with a zero-area triangle"))
        return;
    for (pass = 0; pass < 2; pass++) {
        bp_status st;
        if (pass) for (i = 0; i < 3 * m.num_vertices; i++) m.positions[i] = ldexp(m.positions[i], 200);
        st = bp_parameterize(&at, &m, &o, &err);
        if (st == BP_OK && at.num_charts == 1 && at.charts[0].rest_side && all_valid(&at)) {
            if (pass) side2 = at.charts[0].rest_side[2];
            else side1 = at.charts[0].rest_side[2];
        }
        bp_atlas_free(&at);
    }
    BPT_CHECK(side1 == 4.0 / 3 && side2 == ldexp(side1, 200),
              "square + zero-area triangle at scale 1 and 2^200: valid, rest side 4/3 (%.17g) and 2^200 times it "
              "(ratio %.17g / 2^200)", side1, ldexp(side2, -200));
    bp_mesh_free(&m, NULL);
}

/* Allocation failure inside the repairs: the defect strip (every kind at
   once) with the k-th allocation failing,
   for every k up to the number made: BP_ERR_OUT_OF_MEMORY (or BP_OK past
   the last), and everything freed. */
typedef struct counter { long calls, live, fail_at, bad; } counter;

static void *c_alloc(void *user, size_t size)
{
    counter *C = (counter *)user;
    if (++C->calls == C->fail_at) return NULL;
    C->live++;
    return malloc(size);
}

static void c_free(void *user, void *p)
{
    counter *C = (counter *)user;
    if (!p) C->bad++;
    C->live--;
    free(p);
}

static void test_alloc_failures(void)
{
    static const char text[] =
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nv 1 0.5 1\nv 3 0 0\n"
        "f 1 2 5\nf 1 5 4\nf 2 6 3\nf 2 6 5\nf 5 1 2\nf 2 5 7\nf 2 8 3\n";
    bp_mesh m;
    bp_error err;
    bp_options o = options(0);
    counter C;
    long k, n = 0, bad = 0;
    if (!BPT_CHECK(bp_parse_obj(text, strlen(text), &m, NULL, &err) == BP_OK, "parse the defect strip")) return;
    o.threads = 1;
    o.allocator.alloc = c_alloc;
    o.allocator.free = c_free;
    o.allocator.user = &C;
    for (k = 1;; k++) {
        bp_atlas at;
        bp_status st;
        memset(&C, 0, sizeof C);
        C.fail_at = k;
        st = bp_parameterize(&at, &m, &o, &err);
        if (st == BP_OK && (at.repairs.total != 4 || !all_valid(&at))) bad++;
        bp_atlas_free(&at);
        if (C.live != 0 || C.bad || (st != BP_OK && st != BP_ERR_OUT_OF_MEMORY)) bad++;
        if (st == BP_OK) break;
        n++;
        if (k > 100000) { bad++; break; }
    }
    BPT_CHECK(bad == 0 && n > 10, "defect strip: each of its %ld allocations failing gives BP_ERR_OUT_OF_MEMORY and "
              "frees everything; past the last, the 4 repairs and a valid map (%ld bad)", n, bad);
    bp_mesh_free(&m, NULL);
}

int main(void)
{
    bp_mesh clean;
    bp_atlas ref;
    bp_error err;
    bp_options o = options(0);
    memset(&ref, 0, sizeof ref);
    if (BPT_CHECK(bp_read_obj(bishop_path, &clean, NULL, &err) == BP_OK, "read %s (%s)", bishop_path, err.message)) {
        if (BPT_CHECK(bp_parameterize(&ref, &clean, &o, &err) == BP_OK && all_valid(&ref) && ref.repairs.total == 0,
                      "clean bishop: BP_OK, valid, nothing repaired (%s)", err.message)) {
            test_orientation_case(&clean, &ref, "bishop, odd triangles flipped (a tie)", 2);
            test_orientation_case(&clean, &ref, "bishop, two of three triangles flipped (majority)", 3);
            test_duplicates(&clean, &ref);
            test_degenerate(&clean, &ref);
        }
        bp_atlas_free(&ref);
        bp_mesh_free(&clean, NULL);
    }
    test_moebius();
    test_fins();
    test_cones();
    test_obj_file();
    test_degenerate_scaled();
    test_alloc_failures();
    return bpt_finish();
}
