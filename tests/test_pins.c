/* test_pins.c - pinned vertices and the input uvs as the start map.

   Pins (opt.pins, see >>pins):
     (a) random pinned subsets -- boundary and interior vertices -- on real
         charts (bishop, camel_b, the largest chart of spot), the targets
         the free result moved by a similarity and jittered (so the start
         map must travel to them): bp_parameterize returns BP_OK, the whole
         atlas passes bp_check (union of the charts), every pinned chart
         vertex is EXACTLY (==) at its target, chart.num_pins counts them
         and the pinned chart is left in place by packing; also on bishop
         scaled by 2^120 (solved on a rescaled copy: the pins follow it);
     (a') three arbitrary pins on camel_b (targets unrelated to its free
         map) are reached, and the result with a job system that runs its
         tasks backwards is bit-identical to the serial one;
     (b) every accepted iterate (progress callback, bishop) is bijective
         (bp_check) with the pins exactly in place; the same with the
         projected Newton direction on bishop and camel_b (its system holds
         the pinned rows fixed, >>newton);
     (c) infeasible pins are rejected with the elements named (from 1): a
         pinned triangle whose targets are clockwise / collinear, two
         pinned boundary edges that cross, two pins at one point, a vertex
         outside the mesh, a vertex pinned twice, a NaN target;
     (d) pins that pass those necessary checks but admit no map (the
         neighbours of an interior vertex pinned in clockwise order around
         it) fail that chart with a message naming a vertex, never a wrong
         map; pins + normalize is refused;
     (e) bp_chart_optimize refuses a start map whose pins are not at their
         targets (the vertex named).
   Input start (BP_INIT_INPUT):
     (f) the cow's own vt: init_used = 1, the final energy <= the start's,
         the result bijective; with init_only the packed result IS the
         input map, bit for bit (placement kept);
     (g) spot's vt (one mirrored chart): each chart reports init_used = 1
         exactly when its own input map passes bp_check, else -1, and the
         result is bijective;
     (h) a deliberately overlapping input (one cow vt thrown across the
         chart) falls back to Tutte (init_used = -1, not in place) and the
         result is bijective; a mesh without vt falls back too. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

static int read_mesh(const char *path, bp_mesh *m)
{
    bp_error err;
    if (bp_read_mesh(path, m, NULL, &err) != BP_OK) { printf("  %s: %s\n", path, err.message); return 0; }
    return 1;
}

/* The whole atlas (every mapped chart) as one triangulation: BP_OK from
   bp_check proves each chart bijective and no two overlapping. */
static int atlas_valid(const bp_atlas *at)
{
    uint32_t c, nt = 0, nv = 0, ot = 0, ov = 0, k;
    uint32_t *tri;
    double *uv;
    bp_check_report rep;
    bp_status st;
    for (c = 0; c < at->num_charts; c++)
        if (at->charts[c].uv) { nt += at->charts[c].num_triangles; nv += at->charts[c].num_vertices; }
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri + 1);
    uv = (double *)malloc(2 * (size_t)nv * sizeof *uv + 1);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        if (!ch->uv) continue;
        for (k = 0; k < 3 * ch->num_triangles; k++) tri[3 * (size_t)ot + k] = ch->triangles[k] + ov;
        memcpy(uv + 2 * (size_t)ov, ch->uv, 2 * (size_t)ch->num_vertices * sizeof(double));
        ot += ch->num_triangles;
        ov += ch->num_vertices;
    }
    st = bp_check(tri, nt, uv, nv, NULL, &rep, NULL);
    free(tri);
    free(uv);
    return st == BP_OK;
}

/* How many charts each mesh vertex has a chart vertex in. */
static uint32_t *charts_per_vertex(const bp_atlas *at, const bp_mesh *m)
{
    uint32_t *n = (uint32_t *)calloc(m->num_vertices + 1, sizeof *n), c, i;
    for (c = 0; c < at->num_charts; c++)
        for (i = 0; i < at->charts[c].num_vertices; i++) n[at->charts[c].vertex[i]]++;
    return n;
}

/* ---- (a), (b): random pins on real charts --------------------------------- */

typedef struct pin_watch {
    const bp_atlas *atlas;
    const bp_pin *pins;
    uint32_t npins;
    int iterations, invalid, moved;
} pin_watch;

static int watch_pins(void *user, uint32_t chart, int iteration, double energy, double step)
{
    pin_watch *w = (pin_watch *)user;
    const bp_chart *ch = &w->atlas->charts[chart];
    bp_check_report rep;
    uint32_t i, k;
    (void)iteration; (void)energy; (void)step;
    w->iterations++;
    if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK) w->invalid++;
    for (i = 0; ch->num_pins && i < ch->num_vertices; i++)
        for (k = 0; k < w->npins; k++)
            if (w->pins[k].vertex == ch->vertex[i] && (ch->uv[2 * i] != w->pins[k].u || ch->uv[2 * i + 1] != w->pins[k].v))
                w->moved++;
    return 0;
}

/* Pin nb boundary and ni interior vertices of the largest chart, at the
   free result's positions rotated by 0.2 rad, scaled by 1.05 and jittered
   by 2% of the mean boundary edge in uv.  A vertex on a seam (spot's
   boundaries are all seams) is pinned on this chart's side only (bp_pin.uv),
   so no other chart is pinned. */
static void test_random_pins(const char *path, uint32_t nb, uint32_t ni, uint64_t seed, int watch, int scale_exp,
                             bp_direction dir)
{
    bp_mesh m;
    bp_atlas free_at, at;
    bp_options opt;
    bp_error err;
    bp_pin *pins;
    uint32_t c, big = 0, i, k, np = 0, tries, *cpv, exact = 0, counted = 0;
    const bp_chart *fc;
    double jitter = 0, cs = cos(0.2) * 1.05, sn = sin(0.2) * 1.05;
    bp_status st;
    pin_watch w;
    memset(&w, 0, sizeof w);
    if (!BPT_CHECK(read_mesh(path, &m), "%s: read", path)) return;
    for (i = 0; i < 3 * m.num_vertices; i++) m.positions[i] = ldexp(m.positions[i], scale_exp);
    memset(&opt, 0, sizeof opt);
    st = bp_parameterize(&free_at, &m, &opt, &err);
    if (!BPT_CHECK(st == BP_OK, "%s: free map: %s", path, err.message)) { bp_mesh_free(&m, NULL); return; }
    for (c = 0; c < free_at.num_charts; c++)
        if (free_at.charts[c].num_triangles > free_at.charts[big].num_triangles) big = c;
    fc = &free_at.charts[big];
    cpv = charts_per_vertex(&free_at, &m);
    for (k = fc->loop_start[0]; k < fc->loop_start[1]; k++) {
        const double *a = fc->uv + 2 * (size_t)fc->loop_vertices[k];
        const double *b = fc->uv + 2 * (size_t)fc->loop_vertices[k + 1 < fc->loop_start[1] ? k + 1 : fc->loop_start[0]];
        jitter += hypot(a[0] - b[0], a[1] - b[1]);
    }
    jitter = 0.02 * jitter / (fc->loop_start[1] - fc->loop_start[0]);
    pins = (bp_pin *)malloc((nb + ni) * sizeof *pins);
    bpt_rng_state = seed;
    for (tries = 0; np < nb + ni && tries < 100000; tries++) {
        int want_boundary = np < nb, on_boundary = 0;
        uint32_t cv = (uint32_t)(bpt_rng_u64() % fc->num_vertices), v = fc->vertex[cv];
        for (k = 0; k < fc->loop_start[fc->num_loops]; k++) if (fc->loop_vertices[k] == cv) on_boundary = 1;
        if (on_boundary != want_boundary || (cpv[v] != 1 && !fc->vertex_uv)) continue;
        for (k = 0; k < np; k++) if (pins[k].vertex == v) break;
        if (k < np) continue;
        for (k = 0; k < fc->num_vertices; k++) if (k != cv && fc->vertex[k] == v) break;
        if (k < fc->num_vertices) continue;                           /* a pinch vertex */
        pins[np].vertex = v;
        pins[np].uv = cpv[v] != 1 ? fc->vertex_uv[cv] + 1 : 0;    /* a seam: this chart's side only */
        pins[np].u = cs * fc->uv[2 * cv] - sn * fc->uv[2 * cv + 1] + bpt_rng_range(-jitter, jitter) + 0.125;
        pins[np].v = sn * fc->uv[2 * cv] + cs * fc->uv[2 * cv + 1] + bpt_rng_range(-jitter, jitter) - 0.375;
        np++;
    }
    BPT_CHECK(np == nb + ni, "%s: %u boundary + %u interior vertices chosen", path, nb, ni);
    opt.pins = pins;
    opt.num_pins = np;
    opt.direction = dir;
    if (watch) { opt.progress = watch_pins; opt.progress_user = &w; w.atlas = &at; w.pins = pins; w.npins = np; }
    st = bp_parameterize(&at, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK, "%s: %u pins: %s", path, np, st == BP_OK ? "ok" : err.message)) {
        const bp_chart *ch = &at.charts[big];
        BPT_CHECK(atlas_valid(&at), "%s: the pinned atlas passes bp_check (all charts, no overlap)", path);
        for (i = 0; i < ch->num_vertices; i++)
            for (k = 0; k < np; k++)
                if (pins[k].vertex == ch->vertex[i]) {
                    counted++;
                    exact += ch->uv[2 * i] == pins[k].u && ch->uv[2 * i + 1] == pins[k].v;
                }
        BPT_CHECK(counted == np && exact == np, "%s: %u of %u pins exactly (==) at their targets", path, exact, np);
        BPT_CHECK(ch->num_pins == np && ch->in_place, "%s: chart.num_pins = %u, left in place by packing", path,
                  ch->num_pins);
        printf("  %s: chart %u (%u triangles): energy %.6g free (%d iterations), %.6g with %u pins (%d iterations, "
               "start %.6g, %s)\n", path, big, ch->num_triangles, fc->energy_end, fc->iterations, ch->energy_end, np,
               ch->iterations, ch->energy_start, dir == BP_DIRECTION_NEWTON ? "Newton" : "default direction");
        if (watch)
            BPT_CHECK(w.iterations == ch->iterations && w.iterations > 0 && w.invalid == 0 && w.moved == 0,
                      "%s: all %d iterates bijective with the pins in place (%d invalid, %d pin moves)", path,
                      w.iterations, w.invalid, w.moved);
        bp_atlas_free(&at);
    }
    free(cpv);
    free(pins);
    bp_atlas_free(&free_at);
    bp_mesh_free(&m, NULL);
}

/* A job system that runs the tasks backwards: results must not change. */
static void reverse_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(task, i);
}

/* (a') the same pins solved serially and with the backwards job system:
   bit-identical maps (the homotopy keeps the library's determinism). */
static void test_pins_deterministic(void)
{
    bp_mesh m;
    bp_atlas a1, a2;
    bp_options opt;
    bp_error err;
    bp_pin p[3];
    int same = 0;
    if (!BPT_CHECK(read_mesh("tests/data/camel_b.obj", &m), "camel_b: read")) return;
    memset(&opt, 0, sizeof opt);
    memset(p, 0, sizeof p);
    p[0].vertex = 10; p[0].u = 0; p[0].v = 0;
    p[1].vertex = 1000; p[1].u = 40; p[1].v = 10;
    p[2].vertex = 1500; p[2].u = 20; p[2].v = 60;
    opt.pins = p;
    opt.num_pins = 3;
    opt.max_iterations = 100;
    if (BPT_CHECK(bp_parameterize(&a1, &m, &opt, &err) == BP_OK, "camel_b, 3 arbitrary pins: %s", err.message)) {
        opt.parallel_for = reverse_for;
        if (BPT_CHECK(bp_parameterize(&a2, &m, &opt, &err) == BP_OK, "... with a backwards job system")) {
            same = !memcmp(a1.charts[0].uv, a2.charts[0].uv, 2 * sizeof(double) * a1.charts[0].num_vertices);
            bp_atlas_free(&a2);
        }
        BPT_CHECK(same, "camel_b with pins: serial and backwards job system give bit-identical maps");
        BPT_CHECK(atlas_valid(&a1),
                  "... and the map passes bp_check");
        bp_atlas_free(&a1);
    }
    bp_mesh_free(&m, NULL);
}

/* ---- (c), (d), (e): infeasible pins ------------------------------------ */

/* bp_parameterize with these pins on camel_b (one chart). */
static bp_status run_pins(const bp_mesh *m, const bp_pin *pins, uint32_t np, bp_error *err)
{
    bp_options opt;
    bp_atlas at;
    bp_status st;
    memset(&opt, 0, sizeof opt);
    opt.pins = pins;
    opt.num_pins = np;
    opt.max_iterations = 50;
    st = bp_parameterize(&at, m, &opt, err);
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED || st == BP_ERR_CANCELLED) {
        int all = 1;
        uint32_t c;
        for (c = 0; c < at.num_charts; c++) if (at.charts[c].error.status != BP_OK) { all = 0; *err = at.charts[c].error; }
        if (!all && st == BP_OK) st = BP_ERR_CHARTS_FAILED;
        if (st == BP_ERR_CHARTS_FAILED)
            BPT_CHECK(atlas_valid(&at), "a failed pinned chart leaves no wrong map (the rest passes bp_check)");
        bp_atlas_free(&at);
    }
    return st;
}

static void test_infeasible(void)
{
    bp_mesh m;
    bp_atlas at;
    bp_options opt;
    bp_error err;
    bp_pin p[8];
    const bp_chart *ch;
    uint32_t t, a, b, c, d, nloop, l0;
    bp_status st;
    memset(p, 0, sizeof p);
    if (!BPT_CHECK(read_mesh("tests/data/camel_b.obj", &m), "camel_b: read")) return;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &opt, &err) == BP_OK && at.num_charts == 1, "camel_b: one chart")) return;
    ch = &at.charts[0];

    /* a triangle with its three vertices pinned clockwise, then collinear */
    t = ch->num_triangles / 2;
    p[0].vertex = ch->vertex[ch->triangles[3 * t]];     p[0].u = 0; p[0].v = 0;
    p[1].vertex = ch->vertex[ch->triangles[3 * t + 1]]; p[1].u = 0; p[1].v = 1;
    p[2].vertex = ch->vertex[ch->triangles[3 * t + 2]]; p[2].u = 1; p[2].v = 0;
    st = run_pins(&m, p, 3, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(err.message, "flipped") && bpt_has_number(err.message, ch->face[t] + 1) &&
              bpt_has_number(err.message, p[0].vertex + 1) && bpt_has_number(err.message, p[1].vertex + 1) &&
              bpt_has_number(err.message, p[2].vertex + 1),
              "clockwise pinned triangle rejected, triangle %u and its vertices named: %s", ch->face[t] + 1, err.message);
    p[2].u = 0; p[2].v = 2;
    st = run_pins(&m, p, 3, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(err.message, "degenerate") && bpt_has_number(err.message, ch->face[t] + 1),
              "collinear pinned triangle rejected: %s", err.message);

    /* two boundary edges a-b and c-d, far apart on the outer loop, crossing */
    l0 = ch->loop_start[0];
    nloop = ch->loop_start[1] - l0;
    a = ch->loop_vertices[l0]; b = ch->loop_vertices[l0 + 1];
    c = ch->loop_vertices[l0 + nloop / 2]; d = ch->loop_vertices[l0 + nloop / 2 + 1];
    p[0].vertex = ch->vertex[a]; p[0].u = 0; p[0].v = 0;
    p[1].vertex = ch->vertex[b]; p[1].u = 1; p[1].v = 1;
    p[2].vertex = ch->vertex[c]; p[2].u = 0; p[2].v = 1;
    p[3].vertex = ch->vertex[d]; p[3].u = 1; p[3].v = 0;
    st = run_pins(&m, p, 4, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(err.message, "cross") && bpt_has_number(err.message, p[0].vertex + 1) &&
              bpt_has_number(err.message, p[1].vertex + 1) && bpt_has_number(err.message, p[2].vertex + 1) &&
              bpt_has_number(err.message, p[3].vertex + 1),
              "crossing pinned boundary edges %u-%u and %u-%u rejected: %s", p[0].vertex + 1, p[1].vertex + 1,
              p[2].vertex + 1, p[3].vertex + 1, err.message);
    /* the same edges apart: accepted (the check is not just "reject 4 pins") */
    p[2].u = 5; p[2].v = 0; p[3].u = 5; p[3].v = 1;
    st = run_pins(&m, p, 4, &err);
    BPT_CHECK(st == BP_OK, "the same four pins with the edges apart are reached: %s", st == BP_OK ? "ok" : err.message);

    /* two pins at one point */
    p[0].vertex = ch->vertex[a]; p[0].u = 0.5; p[0].v = 0.25;
    p[1].vertex = ch->vertex[c]; p[1].u = 0.5; p[1].v = 0.25;
    st = run_pins(&m, p, 2, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, p[0].vertex + 1) &&
              bpt_has_number(err.message, p[1].vertex + 1) && strstr(err.message, "same point"),
              "two pins at one point rejected: %s", err.message);

    /* the list itself */
    p[0].uv = p[1].uv = 0;
    p[0].vertex = m.num_vertices + 4;
    st = run_pins(&m, p, 1, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, m.num_vertices + 5),
              "a vertex outside the mesh is named: %s", err.message);
    p[0].vertex = ch->vertex[a]; p[1].vertex = ch->vertex[a]; p[1].u = 2;
    st = run_pins(&m, p, 2, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, p[0].vertex + 1) && strstr(err.message, "twice"),
              "a vertex pinned twice is named: %s", err.message);
    p[1].vertex = ch->vertex[c]; p[1].u = NAN;
    st = run_pins(&m, p, 2, &err);
    BPT_CHECK(st == BP_ERR_NONFINITE && bpt_has_number(err.message, p[1].vertex + 1), "a NaN target is named: %s", err.message);

    /* (d) the ring of an interior vertex pinned clockwise around it: every
       check above passes, no map exists */
    {
        uint32_t v = BP__NONE, ring[64] = { 0 }, nr = 0, i, k, cur, onb;
        for (i = 0; i < ch->num_vertices && v == BP__NONE; i++) {
            for (onb = 0, k = 0; k < ch->loop_start[ch->num_loops]; k++) if (ch->loop_vertices[k] == i) onb = 1;
            if (!onb) v = i;
        }
        /* walk the fan of v: from a triangle (v, x, y) to the one with (v, y, .) */
        for (t = 0; t < ch->num_triangles; t++)
            for (k = 0; k < 3; k++) if (ch->triangles[3 * t + k] == v && nr == 0) ring[nr++] = ch->triangles[3 * t + (k + 1) % 3];
        cur = ring[0];
        while (nr < 64) {
            uint32_t next = BP__NONE;
            for (t = 0; t < ch->num_triangles && next == BP__NONE; t++)
                for (k = 0; k < 3; k++)
                    if (ch->triangles[3 * t + k] == v && ch->triangles[3 * t + (k + 1) % 3] == cur)
                        next = ch->triangles[3 * t + (k + 2) % 3];
            if (next == ring[0] || next == BP__NONE) break;
            ring[nr++] = cur = next;
        }
        BPT_CHECK(nr >= 3 && nr < 8, "camel_b: interior vertex %u has a ring of %u", ch->vertex[v] + 1, nr);
        for (i = 0; i < nr && i < 8; i++) {   /* the ring clockwise on a circle: v cannot be placed */
            p[i].vertex = ch->vertex[ring[i]];
            p[i].u = cos(-2 * 3.14159265358979 * i / nr);
            p[i].v = sin(-2 * 3.14159265358979 * i / nr);
        }
        st = run_pins(&m, p, nr, &err);
        BPT_CHECK((st == BP_ERR_CHARTS_FAILED || st == BP_ERR_INVALID_ARGUMENT) && strstr(err.message, "cannot be reached") && err.element == BP_ELEMENT_VERTEX &&
                  bpt_has_number(err.message, err.index + 1),
                  "a ring pinned clockwise: the chart fails, no wrong map, a vertex named: %s", err.message);
    }

    /* pins and normalize together */
    p[0].vertex = ch->vertex[a]; p[0].u = 0; p[0].v = 0;
    memset(&opt, 0, sizeof opt);
    opt.pins = p; opt.num_pins = 1; opt.normalize = 1; opt.max_iterations = 5;
    {
        bp_atlas a2;
        st = bp_parameterize(&a2, &m, &opt, &err);
        BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(err.message, "normalize"), "pins + normalize refused: %s", err.message);
        if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) bp_atlas_free(&a2);
    }

    /* (e) bp_chart_optimize with a start map whose pin is not at its target */
    memset(&opt, 0, sizeof opt);
    st = bp_chart_init(&at.charts[0], &m, &opt, &err);
    p[0].vertex = ch->vertex[c]; p[0].u = ch->uv[2 * c] + 1; p[0].v = ch->uv[2 * c + 1];
    opt.pins = p; opt.num_pins = 1; opt.max_iterations = 5;
    st = bp_chart_optimize(&at.charts[0], 0, &m, &opt, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, p[0].vertex + 1),
              "bp_chart_optimize: a start map with a pin off its target is refused: %s", err.message);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* ---- (f), (g), (h): the input uvs as the start ------------------------- */

static void test_input_start(const char *path, int expect_all_used)
{
    bp_mesh m;
    bp_atlas at, built;
    bp_options opt;
    bp_error err;
    uint32_t c, used = 0, agree = 0, better = 0, n = 0, kept = 0, moved = 0;
    bp_status st;
    if (!BPT_CHECK(read_mesh(path, &m), "%s: read", path)) return;
    memset(&opt, 0, sizeof opt);
    opt.init = BP_INIT_INPUT;
    /* independently: which charts' input maps pass bp_check */
    st = bp_atlas_build(&built, &m, &opt, &err);
    st = bp_parameterize(&at, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK, "%s: --init input: %s", path, st == BP_OK ? "ok" : err.message)) {
        BPT_CHECK(atlas_valid(&at), "%s: the result passes bp_check", path);
        for (c = 0; c < at.num_charts; c++) {
            const bp_chart *ch = &at.charts[c], *bc = &built.charts[c];
            double *uv = (double *)malloc(2 * (size_t)bc->num_vertices * sizeof(double) + 1);
            uint32_t i;
            bp_check_report rep;
            int valid;
            for (i = 0; i < bc->num_vertices; i++) {
                uv[2 * i] = m.uvs[2 * (size_t)bc->vertex_uv[i]];
                uv[2 * i + 1] = m.uvs[2 * (size_t)bc->vertex_uv[i] + 1];
            }
            valid = bp_check(bc->triangles, bc->num_triangles, uv, bc->num_vertices, NULL, &rep, NULL) == BP_OK;
            free(uv);
            n++;
            used += ch->init_used == 1;
            agree += ch->init_used == (valid ? 1 : -1);
            kept += ch->init_used == 1 && ch->in_place;
            moved += ch->init_used != 1 && ch->in_place;
            better += ch->energy_end <= ch->energy_start;
            if (c < 3 || ch->init_used != 1)
                printf("  %s chart %u: init_used %d, energy %.6g -> %.6g in %d iterations\n", path, c, ch->init_used,
                       ch->energy_start, ch->energy_end, ch->iterations);
        }
        BPT_CHECK(agree == n, "%s: %u of %u charts report init_used = 1 exactly when their input map passes bp_check",
                  path, agree, n);
        BPT_CHECK(moved == 0 && (expect_all_used ? kept == used : 1),
                  "%s: %u charts started from their input kept in place, %u others claim to be", path, kept, moved);
        BPT_CHECK(better == n, "%s: final energy <= start energy on %u of %u charts", path, better, n);
        BPT_CHECK(expect_all_used ? used == n : (used > 0 && used < n), "%s: %u of %u input maps used", path, used, n);
        bp_atlas_free(&at);
    }
    /* init_only: the result is the input map itself, where it was */
    opt.init_only = 1;
    st = bp_parameterize(&at, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK, "%s: --init input --init-only", path)) {
        uint32_t same = 0, total = 0, i;
        for (c = 0; c < at.num_charts; c++) {
            const bp_chart *ch = &at.charts[c];
            if (ch->init_used != 1) continue;
            for (i = 0; i < ch->num_vertices; i++, total++)
                same += ch->uv[2 * i] == m.uvs[2 * (size_t)ch->vertex_uv[i]] &&
                        ch->uv[2 * i + 1] == m.uvs[2 * (size_t)ch->vertex_uv[i] + 1];
        }
        BPT_CHECK(total > 0 && same == total, "%s: init_only keeps the input map in place bit for bit (%u of %u)", path,
                  same, total);
        bp_atlas_free(&at);
    }
    bp_atlas_free(&built);
    bp_mesh_free(&m, NULL);
}

static void test_input_overlapping(void)
{
    bp_mesh m;
    bp_atlas at;
    bp_options opt;
    bp_error err;
    bp_status st;
    if (!BPT_CHECK(read_mesh("tests/data/cow_param_withSUV.obj", &m), "cow: read")) return;
    m.uvs[2 * 99] = 50;                        /* vt 100 thrown far across the chart */
    m.uvs[2 * 99 + 1] = 50;
    memset(&opt, 0, sizeof opt);
    opt.init = BP_INIT_INPUT;
    opt.max_iterations = 200;
    st = bp_parameterize(&at, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK, "cow with vt 100 moved: %s", st == BP_OK ? "ok" : err.message)) {
        BPT_CHECK(at.num_charts == 1 && at.charts[0].init_used == -1 && !at.charts[0].in_place,
                  "the overlapping input map falls back to Tutte (init_used %d)", at.charts[0].init_used);
        BPT_CHECK(atlas_valid(&at), "... and the result is bijective");
        bp_atlas_free(&at);
    }
    bp_mesh_free(&m, NULL);
    if (!BPT_CHECK(read_mesh("tests/data/camelhead.off", &m), "camelhead: read")) return;
    opt.max_iterations = 20;
    st = bp_parameterize(&at, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK, "camelhead (no vt) with BP_INIT_INPUT: %s", st == BP_OK ? "ok" : err.message)) {
        BPT_CHECK(at.charts[0].init_used == -1 && atlas_valid(&at), "no vt: falls back (init_used %d), bijective",
                  at.charts[0].init_used);
        bp_atlas_free(&at);
    }
    bp_mesh_free(&m, NULL);
}

int main(void)
{
    test_random_pins("tests/data/bishop_part_f1000.obj", 4, 6, 11, 1, 0, BP_DIRECTION_PRECONDITIONED);
    /* Newton (>>newton): the pinned rows are identity rows of its system */
    test_random_pins("tests/data/bishop_part_f1000.obj", 4, 6, 11, 1, 0, BP_DIRECTION_NEWTON);
    test_random_pins("tests/data/camel_b.obj", 6, 10, 13, 1, 0, BP_DIRECTION_NEWTON);
    test_random_pins("tests/data/bishop_part_f1000.obj", 1, 0, 12, 0, 0, BP_DIRECTION_PRECONDITIONED);
    test_random_pins("tests/data/bishop_part_f1000.obj", 2, 3, 15, 0, 120, BP_DIRECTION_PRECONDITIONED);   /* solved rescaled: pins follow */
    test_random_pins("tests/data/camel_b.obj", 6, 10, 13, 0, 0, BP_DIRECTION_PRECONDITIONED);
    test_random_pins("tests/data/spot.obj", 3, 5, 14, 0, 0, BP_DIRECTION_PRECONDITIONED);
    test_pins_deterministic();
    test_infeasible();
    test_input_start("tests/data/cow_param_withSUV.obj", 1);
    test_input_start("tests/data/spot.obj", 0);
    test_input_overlapping();
    return bpt_finish();
}
