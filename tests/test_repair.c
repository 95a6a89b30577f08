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
   and with opt.strict the call fails naming the element.
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

/* ---- duplicates in a segmented atlas -------------------------------------- */

/* Every triangle of spot written twice (every other copy reversed, every
   third rotated), then segmented (atlas_resolution): segmentation splits
   charts, and a chart vertex on a new seam becomes one piece vertex on each
   side.  A copy is in no chart, so it must follow its twin into the twin's
   piece: at each of its mesh vertices, the same chart and chart vertex as
   the twin's corner at that vertex (else the copy's written vt straddle a
   seam and the file's map folds). */
static void test_duplicates_segmented(void)
{
    bp_mesh sp, m;
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t nt, t, k, j, bad = 0, onseam = 0, *seen;
    unsigned char *fl, *shared;
    if (!BPT_CHECK(bp_read_obj("tests/data/spot.obj", &sp, NULL, &err) == BP_OK, "read spot (%s)", err.message))
        return;
    nt = sp.num_triangles;
    m = copy_mesh(&sp, nt);
    for (t = 0; t < nt; t++) {
        const uint32_t *a = sp.triangles + 3 * (size_t)t;
        uint32_t *c = m.triangles + 3 * ((size_t)nt + t), r = t % 3;
        for (k = 0; k < 3; k++) c[k] = a[(k + r) % 3];
        if (t % 2) { uint32_t x = c[1]; c[1] = c[2]; c[2] = x; }
    }
    o.atlas_resolution = 512;
    fl = (unsigned char *)calloc(2 * (size_t)nt, 1);
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at) && corners_consistent(&at, &m, fl),
                  "spot with every triangle twice, segmented: BP_OK, valid, corners on their own mesh vertices (%s: %s)",
                  bp_status_string(st), err.message)) {
        for (t = 0; t < nt; t++)
            for (k = 0; k < 3; k++) {
                size_t ci = 3 * ((size_t)nt + t) + k, cj;
                for (j = 0; j < 3 && sp.triangles[3 * (size_t)t + j] != m.triangles[ci]; j++) {}
                cj = 3 * (size_t)t + j;
                bad += j == 3 || at.corner_chart[ci] != at.corner_chart[cj] || at.corner_vertex[ci] != at.corner_vertex[cj];
            }
        /* the case that matters: twin corners on mesh vertices that two charts share */
        seen = (uint32_t *)malloc(sp.num_vertices * sizeof(uint32_t));
        shared = (unsigned char *)calloc(sp.num_vertices, 1);
        for (t = 0; t < sp.num_vertices; t++) seen[t] = UINT32_MAX;
        for (t = 0; t < 3 * nt; t++) {
            uint32_t v = sp.triangles[t];
            if (seen[v] == UINT32_MAX) seen[v] = at.corner_chart[t];
            else if (seen[v] != at.corner_chart[t]) shared[v] = 1;
        }
        for (t = 0; t < 3 * nt; t++) onseam += shared[sp.triangles[t]];
        free(seen);
        free(shared);
        BPT_CHECK(bad == 0 && at.num_charts > 13 && onseam > 100,
                  "  %u charts; every copy's corners are its twin's (chart, chart vertex) (%u differ; %u twin corners "
                  "on mesh vertices shared by two charts)", at.num_charts, bad, onseam);
    }
    bp_atlas_free(&at);
    free(fl);
    bpt_mesh_free(&m);
    bp_mesh_free(&sp, NULL);
}

/* ---- a slit closed at both ends ------------------------------------------- */

/* Two unit cubes sharing one edge (7-8, as voxel models have them): the
   repair makes that non-manifold edge a seam of all four triangles at it,
   and each cube is left a disk whose only boundary loop has two edges,
   both between 7 and 8.  No map with straight edges opens that loop, so it
   needs a seam; with cutting off the chart fails, naming the loop.  Each
   run's map is proved with the exact check. */
static void test_closed_slit(void)
{
    static const double P[14][3] = { {0,0,0}, {0,0,1}, {0,1,0}, {0,1,1}, {1,0,0}, {1,0,1}, {1,1,0},
                                     {1,1,1}, {1,2,0}, {1,2,1}, {2,1,0}, {2,1,1}, {2,2,0}, {2,2,1} };
    static const uint32_t F[24][3] = {
        {1,2,4}, {1,4,3}, {5,7,8}, {5,8,6}, {1,5,6}, {1,6,2}, {3,4,8}, {3,8,7}, {1,3,7}, {1,7,5}, {2,6,8}, {2,8,4},
        {7,8,10}, {7,10,9}, {11,13,14}, {11,14,12}, {7,11,12}, {7,12,8}, {9,10,14}, {9,14,13}, {7,9,13},
        {7,13,11}, {8,12,14}, {8,14,10} };
    bp_mesh m = bpt_mesh_new(14, 24);
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    uint32_t i, k;
    int res;
    for (i = 0; i < 14; i++) for (k = 0; k < 3; k++) m.positions[3 * i + k] = P[i][k];
    for (i = 0; i < 24; i++) for (k = 0; k < 3; k++) m.triangles[3 * i + k] = F[i][k] - 1;
    for (res = 0; res <= 256; res += 256) {
        o.atlas_resolution = res;
        st = bp_parameterize(&at, &m, &o, &err);
        BPT_CHECK(st == BP_OK && all_valid(&at) && at.repairs.kind[BP_REPAIR_NONMANIFOLD_EDGE].count == 1,
                  "two cubes sharing edge 7-8%s: the edge a seam, each cube's 2-edge loop cut open, BP_OK, "
                  "valid by the exact check (%s: %s)", res ? ", segmented" : "", bp_status_string(st), err.message);
        bp_atlas_free(&at);
    }
    o.atlas_resolution = 0;
    o.cut = BP_CUT_NONE;
    st = bp_parameterize(&at, &m, &o, &err);
    BPT_CHECK(st == BP_ERR_TOPOLOGY && err.element == BP_ELEMENT_CHART && strstr(err.message, "loop of 2 edges") &&
                  bpt_has_number(err.message, 7) && bpt_has_number(err.message, 8),
              "  without cutting: no chart can be mapped, BP_ERR_TOPOLOGY naming the 2-edge loop at 7 and 8 (%s: \"%s\")",
              bp_status_string(st), err.message);
    bp_atlas_free(&at);
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


/* ---- the writers and re-oriented faces ------------------------------------

   A closed box of 6 x 3 x 3 quads with a vn per face, written as OBJ text,
   every quad whose index is 1 mod 3 (a minority) wound the other way, and
   the last face of each side given as two triangles: the repair re-orients
   them, and the automatic cut opens the closed box (the cut renumbers the
   chart vertices of re-oriented triangles too).  Both writers are read
   back here, as text, and each output face is checked against the input
   face it comes from:
     - its corners are the input's corners (v, and vn for bp_write_obj_from,
       as written): the same order for a face kept, corner 0 and then the
       rest reversed for a re-oriented one -- a permutation, never an
       altered triple -- or, when the writer split a polygon into its fan
       triangles (a seam along a diagonal), each line a subset of them;
     - every fan triangle of every output line is counter-clockwise in its
       written vt (exact orient2d on the parsed coordinates), so the faces
       agree with their uvs as an outside checker sees them;
     - every vt is used with one v only;
     - the faces reversed are exactly the ones damaged here. */
static void box_obj(char *buf, size_t cap, uint32_t *nflipped_tris)
{
    size_t n = 0;
    int side, i, j, q = 0;
    uint32_t nv = 0;
    *nflipped_tris = 0;
    n += (size_t)snprintf(buf + n, cap - n, "# a closed box of quads, some wound the other way\n");
    /* the vertices: the 4 x 4 x 4 lattice points on the surface; side s
       lies at coordinate a = s / 2 equal to 0 (s even) or 3 (s odd), its
       quads in the (u, w) = (a + 1, a + 2) plane, counter-clockwise seen
       from outside */
    {
        int x, y, z;
        int id[4][4][4];
        for (x = 0; x < 4; x++)
            for (y = 0; y < 4; y++)
                for (z = 0; z < 4; z++) {
                    id[x][y][z] = 0;
                    if (x == 0 || x == 3 || y == 0 || y == 3 || z == 0 || z == 3) {
                        id[x][y][z] = (int)++nv;
                        n += (size_t)snprintf(buf + n, cap - n, "v %d %d %d\n", x, y, z);
                    }
                }
        for (side = 0; side < 6; side++)
            n += (size_t)snprintf(buf + n, cap - n, "vn %d %d %d\n", side == 0 ? -1 : side == 1 ? 1 : 0,
                                  side == 2 ? -1 : side == 3 ? 1 : 0, side == 4 ? -1 : side == 5 ? 1 : 0);
        for (side = 0; side < 6; side++)
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++, q++) {
                    int c[4][3], k, a = side / 2, fixed = side % 2 ? 3 : 0, u = (a + 1) % 3, w = (a + 2) % 3, fl;
                    int corner[4], ord[4];
                    for (k = 0; k < 4; k++) {
                        c[k][a] = fixed;
                        c[k][u] = i + (k == 1 || k == 2);
                        c[k][w] = j + (k >= 2);
                        corner[k] = id[c[k][0]][c[k][1]][c[k][2]];
                    }
                    /* outward: (u, w) counter-clockwise seen from outside when the side is at 3 */
                    for (k = 0; k < 4; k++) ord[k] = side % 2 ? k : (4 - k) % 4;
                    fl = q % 3 == 1;
                    if (fl) { int t = ord[1]; ord[1] = ord[3]; ord[3] = t; *nflipped_tris += 2; }
                    if (i == 2 && j == 2) {      /* the last of each side as two triangles */
                        n += (size_t)snprintf(buf + n, cap - n, "f %d//%d %d//%d %d//%d\nf %d//%d %d//%d %d//%d\n",
                                              corner[ord[0]], side + 1, corner[ord[1]], side + 1, corner[ord[2]], side + 1,
                                              corner[ord[0]], side + 1, corner[ord[2]], side + 1, corner[ord[3]], side + 1);
                    } else {
                        n += (size_t)snprintf(buf + n, cap - n, "f %d//%d  %d//%d %d//%d\t%d//%d # quad %d\n",
                                              corner[ord[0]], side + 1, corner[ord[1]], side + 1, corner[ord[2]], side + 1,
                                              corner[ord[3]], side + 1, q + 1);
                    }
                }
    }
}

typedef struct face_line { int n; char v[8][16], vn[8][16]; long vt[8]; } face_line;

/* The f lines (corners split into v, vt, vn text) and vt lines of OBJ text. */
static int read_faces(const char *path, face_line *f, int cap, double *vt, int vcap, int *nvt)
{
    FILE *fp = fopen(path, "rb");
    char line[512];
    int n = 0;
    *nvt = 0;
    if (!fp) return -1;
    while (fgets(line, sizeof line, fp)) {
        if (!strncmp(line, "vt ", 3) && *nvt < vcap) {
            char *e;
            vt[2 * *nvt] = strtod(line + 3, &e);
            vt[2 * *nvt + 1] = strtod(e, NULL);
            (*nvt)++;
        } else if (!strncmp(line, "f ", 2) && n < cap) {
            char *tok, *save = NULL, *hash = strchr(line, '#');
            face_line *F = &f[n++];
            if (hash) *hash = 0;
            F->n = 0;
            for (tok = strtok_r(line + 2, " \t\r\n", &save); tok && F->n < 8; tok = strtok_r(NULL, " \t\r\n", &save)) {
                char *s1 = strchr(tok, '/'), *s2 = s1 ? strchr(s1 + 1, '/') : NULL;
                F->vt[F->n] = s1 && s1[1] != '/' && s1[1] ? strtol(s1 + 1, NULL, 10) : 0;
                if (s1) *s1 = 0;
                snprintf(F->v[F->n], sizeof F->v[0], "%s", tok);
                snprintf(F->vn[F->n], sizeof F->vn[0], "%s", s2 ? s2 + 1 : "");
                F->n++;
            }
        }
    }
    fclose(fp);
    return n;
}

static int corner_in(const face_line *in, const face_line *out, int k, int with_vn)
{
    int i;
    for (i = 0; i < in->n; i++)
        if (!strcmp(in->v[i], out->v[k]) && (!with_vn || !strcmp(in->vn[i], out->vn[k]))) return i;
    return -1;
}

static void check_written(const char *what, const char *in_path, const char *out_path, int with_vn,
                          const unsigned char *damaged)
{
    static face_line in[256], out[512];
    static double vt[2 * 4096];
    static char vt_v[4096][16];
    int nin, nout, nvt, nvt_in, i, o = 0, k, bad_perm = 0, bad_rev = 0, negative = 0, shared = 0, reversed = 0;
    double dummy[2];
    nin = read_faces(in_path, in, 256, dummy, 0, &nvt_in);
    nout = read_faces(out_path, out, 512, vt, 4096, &nvt);
    if (!BPT_CHECK(nin > 0 && nout >= nin && nvt > 0 && nvt <= 4096, "%s: read back (%d faces in, %d out, %d vt)",
                   what, nin, nout, nvt))
        return;
    for (i = 0; i < nvt; i++) vt_v[i][0] = 0;
    for (i = 0; i < nout; i++)
        for (k = 0; k < out[i].n; k++) {
            long t = out[i].vt[k];
            if (t < 1 || t > nvt) { negative++; continue; }
            if (!vt_v[t - 1][0]) snprintf(vt_v[t - 1], sizeof vt_v[0], "%s", out[i].v[k]);
            else if (strcmp(vt_v[t - 1], out[i].v[k])) shared++;
        }
    for (i = 0; i < nout; i++)                  /* every fan triangle counter-clockwise */
        for (k = 1; k + 1 < out[i].n; k++) {
            long a = out[i].vt[0], b = out[i].vt[k], c = out[i].vt[k + 1];
            if (a < 1 || b < 1 || c < 1 || a > nvt || b > nvt || c > nvt ||
                bp_orient2d(vt + 2 * (a - 1), vt + 2 * (b - 1), vt + 2 * (c - 1)) <= 0)
                negative++;
        }
    for (i = 0; i < nin; i++) {
        int tris = 0, rev = -1;
        while (tris < in[i].n - 2 && o < nout) {
            const face_line *F = &out[o++];
            int m[8];
            tris += F->n - 2;
            for (k = 0; k < F->n; k++)
                if ((m[k] = corner_in(&in[i], F, k, with_vn)) < 0) bad_perm++;
            if (F->n == in[i].n) {               /* one line: the same order, or reversed after corner 0 */
                int same = 1, back = 1;
                for (k = 0; k < F->n; k++) {
                    same &= m[k] == k;
                    back &= m[k] == (k ? F->n - k : 0);
                }
                if (!same && !back) bad_perm++;
                rev = back && !same;
            } else if (F->n == 3 && m[0] == 0 && m[1] > 0 && m[2] > 0 && (m[2] == m[1] + 1 || m[1] == m[2] + 1)) {
                int back = m[1] == m[2] + 1;     /* fan triangle (0, j+1, j+2), or reversed */
                if (rev >= 0 && rev != back) bad_perm++;   /* one face, one orientation */
                rev = back;
            } else {
                bad_perm++;
            }
        }
        if (tris != in[i].n - 2) bad_perm++;
        if (rev == 1) reversed++;
        if ((rev == 1) != (damaged[i] != 0)) bad_rev++;
    }
    BPT_CHECK(o == nout && bad_perm == 0, "%s: every output line's corners are its input face's corners "
              "(v%s as written), in the same order or reversed after corner 0 (%d not; %d of %d lines used)",
              what, with_vn ? " and vn" : "", bad_perm, o, nout);
    BPT_CHECK(negative == 0, "%s: every written fan triangle is counter-clockwise in its vt, exact (%d not)", what,
              negative);
    BPT_CHECK(shared == 0, "%s: every vt belongs to one v (%d corners disagree)", what, shared);
    BPT_CHECK(bad_rev == 0, "%s: the faces written reversed (%d) are exactly the ones wound the other way (%d differ)",
              what, reversed, bad_rev);
}

static void test_write_reoriented(void)
{
    static char text[65536];
    const char *src = "/tmp/bptest_repair_box.obj", *o1 = "/tmp/bptest_repair_box_from.obj",
               *o2 = "/tmp/bptest_repair_box_plain.obj";
    unsigned char damaged[256];
    uint32_t nflip, i;
    int nin = 0, q = 0;
    FILE *fp;
    bp_mesh m;
    bp_atlas at;
    bp_error err;
    bp_options o = options(0);
    bp_status st;
    memset(&at, 0, sizeof at);
    box_obj(text, sizeof text, &nflip);
    fp = fopen(src, "wb");
    if (!BPT_CHECK(fp && fputs(text, fp) >= 0 && fclose(fp) == 0, "write the box to %s", src)) return;
    /* which input faces are damaged: quad q with q % 3 == 1; the split last
       quad of a side is two faces */
    {
        int side, ij;
        for (side = 0; side < 6; side++)
            for (ij = 0; ij < 9; ij++, q++) {
                damaged[nin++] = q % 3 == 1;
                if (ij == 8) damaged[nin++] = q % 3 == 1;
            }
    }
    if (!BPT_CHECK(bp_read_obj(src, &m, NULL, &err) == BP_OK, "read the box (%s)", err.message)) return;
    st = bp_parameterize(&at, &m, &o, &err);
    if (BPT_CHECK(st == BP_OK && all_valid(&at), "box with re-wound faces: parameterized, valid (%s)", err.message)) {
        unsigned char *fl = (unsigned char *)malloc(m.num_triangles);
        uint32_t cut = 0;
        for (i = 0; i < at.num_charts; i++) cut += at.charts[i].cut_edges;
        BPT_CHECK(at.repairs.kind[BP_REPAIR_FLIPPED].count == nflip && cut > 0,
                  "box: %u triangles re-oriented (want %u), and cut along %u edges", at.repairs.kind[BP_REPAIR_FLIPPED].count,
                  nflip, cut);
        BPT_CHECK(corners_consistent(&at, &m, fl), "box: corners consistent with the charts after the cut");
        BPT_CHECK(strstr(at.repairs.kind[BP_REPAIR_FLIPPED].message, "corners in that order") != NULL,
                  "box: the repair message says how the writers write them (\"%s\")",
                  at.repairs.kind[BP_REPAIR_FLIPPED].message);
        free(fl);
        st = bp_write_obj_from(o1, src, &m, &at, &err);
        if (BPT_CHECK(st == BP_OK, "box: bp_write_obj_from (%s)", err.message))
            check_written("bp_write_obj_from", src, o1, 1, damaged);
        st = bp_write_obj(o2, &m, &at, &err);
        if (BPT_CHECK(st == BP_OK, "box: bp_write_obj (%s)", err.message))
            check_written("bp_write_obj", src, o2, 0, damaged);
    }
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
    remove(src); remove(o1); remove(o2);
}

/* The rescaled differences of the defect test (bp__scaled_diff) are
   products by powers of two where those are doubles; they must be the
   bits of the ldexp form ldexp(ldexp(b, -e1) - ldexp(a, -e1), -e2) they
   replace, on meshes of every magnitude, from subnormal coordinates to
   2^1020, and of every extent relative to their position. */
static void test_scaled_diff(void)
{
    double pos[12];
    uint32_t tri[6] = { 0, 1, 2, 0, 2, 3 };
    bp_mesh m;
    bp_error err;
    long bad = 0, meshes = 0, fast = 0;
    int ex, spread, i, k, j;
    uint64_t r = 0x9e3779b97f4a7c15ull;
    memset(&m, 0, sizeof m);
    m.positions = pos;
    m.triangles = tri;
    m.num_vertices = 4;
    m.num_triangles = 2;
    for (ex = -1074; ex <= 1020; ex += 7)
        for (spread = 0; spread <= 60; spread += 20) {
            bp__mesh_scale sc;
            for (i = 0; i < 12; i++) {
                r ^= r << 13; r ^= r >> 7; r ^= r << 17;
                pos[i] = ldexp(1.0 + (double)(r >> 11) / 9007199254740992.0, ex) *
                         (1.0 + ldexp((double)(r & 1023) - 512, -spread));
                if (r & 2048) pos[i] = -pos[i];
            }
            if (bp__validate_global(&m, &sc, &err) != BP_OK) continue;
            meshes++;
            fast += sc.s1 != 0 && sc.s2 != 0;
            for (i = 0; i < 4; i++)
                for (j = 0; j < 4; j++) {
                    double d[3];
                    bp__scaled_diff(pos + 3 * i, pos + 3 * j, &sc, d);
                    for (k = 0; k < 3; k++) {
                        double want = ldexp(ldexp(pos[3 * j + k], -sc.e1) - ldexp(pos[3 * i + k], -sc.e1), -sc.e2);
                        if (memcmp(&want, &d[k], sizeof want)) bad++;
                    }
                }
        }
    BPT_CHECK(bad == 0 && meshes > 1000 && fast > 0 && fast < meshes,
              "rescaled differences on %ld meshes from 2^-1074 to 2^1020 (%ld by products): the bits of the ldexp form (%ld differ)",
              meshes, fast, bad);
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
    test_duplicates_segmented();
    test_closed_slit();
    test_moebius();
    test_fins();
    test_cones();
    test_obj_file();
    test_write_reoriented();
    test_degenerate_scaled();
    test_scaled_diff();
    test_alloc_failures();
    return bpt_finish();
}
