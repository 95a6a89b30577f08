/* fuzz_pipeline.c - libFuzzer harness for the whole pipeline.

   The input is a small OBJ (at most 16 KB, at most 400 triangles); if it
   parses, bp_parameterize runs on it with max_iterations 20 (and a 5 s
   safety limit per chart) and options picked from the input length
   (energy, start map, search direction, history, normalize, strict,
   importance).  Properties:
     - never crash, leak (LeakSanitizer) or hang;
     - a failure returns a status in range with a message, and leaves the
       atlas zeroed;
     - BP_OK / BP_ERR_CHARTS_FAILED: every chart with a map passes bp_check
       (flipped, degenerate, non-finite, boundary intersections, loop
       orientation, nesting all 0), the mapped charts together pass it as
       one triangulation (the packed atlas does not overlap), a chart
       without a map has chart.error set, num_failed counts them, and
       BP_OK means none failed.
   bp_check is given the atlas's triangles and uvs only, so it is an
   independent verdict on what the library returned. */
#ifndef BP_FUZZ_EXTERNAL_IMPL  /* else bijparam.h is compiled once, separately */
#define BP_IMPLEMENTATION
#endif
#include "bijparam.h"
#include "fuzz_common.h"

#include <math.h>

static void check_atlas(const bp_atlas *at, bp_status st, const bp_mesh *m)
{
    uint32_t c, failed = 0, nt = 0, nv = 0, ot = 0, ov = 0, i;
    uint32_t *tri;
    double *uv;
    bp_check_report r;
    bp_error ce;
    if (at->num_corners != 3 * m->num_triangles) fuzz_fail("num_corners %u", at->num_corners);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (!ch->uv) {
            if (ch->error.status == BP_OK) fuzz_fail("chart %u has no map and no error", c);
            failed++;
            continue;
        }
        if (ch->error.status != BP_OK) fuzz_fail("chart %u has a map and an error", c);
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, &ce) != BP_OK)
            fuzz_fail("%s with chart %u NOT BIJECTIVE: %s", bp_status_string(st), c, ce.message);
        if (!fuzz_report_valid(&r))
            fuzz_fail("%s with chart %u NOT BIJECTIVE: flipped %u degenerate %u nonfinite %u boundary %u loops %u nested %u",
                      bp_status_string(st), c, r.flipped, r.degenerate, r.nonfinite, r.boundary_intersections,
                      r.loop_orientation, r.nested);
        nt += ch->num_triangles;
        nv += ch->num_vertices;
    }
    if (failed != at->num_failed) fuzz_fail("num_failed %u but %u charts without a map", at->num_failed, failed);
    if (st == BP_OK && failed) fuzz_fail("BP_OK with %u failed charts", failed);
    if (st == BP_ERR_CHARTS_FAILED && !failed) fuzz_fail("BP_ERR_CHARTS_FAILED without a failed chart");
    if (!nt) return;
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri);
    uv = (double *)malloc(2 * (size_t)nv * sizeof *uv);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (!ch->uv) continue;
        for (i = 0; i < 3 * ch->num_triangles; i++) tri[3 * (size_t)ot + i] = ch->triangles[i] + ov;
        for (i = 0; i < 2 * ch->num_vertices; i++) uv[2 * (size_t)ov + i] = ch->uv[i];
        ot += ch->num_triangles;
        ov += ch->num_vertices;
    }
    if (bp_check(tri, nt, uv, nv, NULL, &r, &ce) != BP_OK)
        fuzz_fail("%s with the packed atlas NOT BIJECTIVE: %s", bp_status_string(st), ce.message);
    free(tri);
    free(uv);
    if (!fuzz_report_valid(&r))
        fuzz_fail("%s with the packed atlas NOT BIJECTIVE: flipped %u degenerate %u boundary %u loops %u nested %u",
                  bp_status_string(st), r.flipped, r.degenerate, r.boundary_intersections, r.loop_orientation, r.nested);
}

/* bp_check decides exactly only while products of coordinate differences
   neither overflow nor underflow (|uv| below about 2^510).  A mesh near
   1e308 gets a map of that size (bp_parameterize solves a rescaled copy
   and scales the map back), valid but not checkable in place: check it
   scaled by the power of two that brings it near 1, when every coordinate
   survives the scaling exactly (else in place). */
static void check_atlas_at_unit_scale(const bp_atlas *at, bp_status st, const bp_mesh *m)
{
    bp_atlas s = *at;
    uint32_t c, i;
    double big = 0;
    int e = 0, exact = 1;
    for (c = 0; c < at->num_charts; c++)
        for (i = 0; at->charts[c].uv && i < 2 * at->charts[c].num_vertices; i++)
            if (fabs(at->charts[c].uv[i]) > big) big = fabs(at->charts[c].uv[i]);
    (void)frexp(big, &e);
    if (e < 500) { check_atlas(at, st, m); return; }
    s.charts = (bp_chart *)malloc(at->num_charts * sizeof(bp_chart));
    memcpy(s.charts, at->charts, at->num_charts * sizeof(bp_chart));
    for (c = 0; c < at->num_charts; c++) {
        const double *u = at->charts[c].uv;
        if (!u) continue;
        s.charts[c].uv = (double *)malloc(2 * (size_t)at->charts[c].num_vertices * sizeof(double));
        for (i = 0; i < 2 * at->charts[c].num_vertices; i++) {
            s.charts[c].uv[i] = ldexp(u[i], -e);
            if (ldexp(s.charts[c].uv[i], e) != u[i]) exact = 0;
        }
    }
    check_atlas(exact ? &s : at, st, m);
    for (c = 0; c < at->num_charts; c++)
        if (at->charts[c].uv) free(s.charts[c].uv);
    free(s.charts);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text;
    bp_mesh m;
    bp_atlas at;
    bp_error err;
    bp_options o;
    bp_status st;
    double *imp = NULL;
    unsigned sel = (unsigned)(size % 97);
    if (size > 16384) return 0;
    text = fuzz_copy(data, size);
    st = bp_parse_obj(text, size, &m, NULL, &err);
    free(text);
    if (st != BP_OK) return 0;
    if (m.num_triangles > 400) { bp_mesh_free(&m, NULL); return 0; }
    memset(&o, 0, sizeof o);
    o.max_iterations = 20;
    o.max_seconds = 5;
    o.energy = (bp_energy)(sel % 5);
    o.init = (sel / 5) % 2 ? BP_INIT_MEAN_VALUE : BP_INIT_TUTTE;
    o.direction = (bp_direction)((sel / 10) % 3);
    o.history = (int)(sel % 7);
    o.normalize = (sel / 3) % 2;
    o.strict = sel % 11 == 0;
    if (sel % 13 == 1) {
        uint32_t t;
        imp = (double *)malloc(m.num_triangles * sizeof(double));
        for (t = 0; t < m.num_triangles; t++) imp[t] = 0.25 + (t % 5);
        o.importance = imp;
    }
    memset(&err, 0, sizeof err);
    st = bp_parameterize(&at, &m, &o, &err);
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) {
        if (st == BP_ERR_CHARTS_FAILED) fuzz_check_error(st, &err);
        check_atlas_at_unit_scale(&at, st, &m);
    } else {
        fuzz_check_error(st, &err);
        if (st == BP_ERR_NOT_BIJECTIVE) fuzz_fail("BP_ERR_NOT_BIJECTIVE (internal check caught a bad map): %s", err.message);
        if (at.charts || at.num_charts || at.corner_chart) fuzz_fail("failed bp_parameterize left the atlas non-zero");
    }
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
    free(imp);
    return 0;
}
