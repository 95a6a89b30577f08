/* test_optimize.c - the optimizer keeps the map bijective at every iteration.

   The central promise of chapter 3: an interior point method that starts
   from a bijective map and never leaves the bijective maps, while the
   boundary moves freely.  Every claim is checked with bp_check (exact):

     (a) bp_check on chart->uv inside the progress callback after EVERY
         iteration (bishop, the 13 spot charts, face_holes with 300
         iterations, camel_b with 200): 0 invalid iterations, the callback
         runs exactly chart->iterations times with iterations 1, 2, 3, ...
         and the total objective E_D + E_B, recomputed in the callback with
         the solver set up by hand, never increases (Armijo line search);
     (b) the mean energy ends below where it started and the final map is
         valid;
     (c) the boundary is free: the outer loop starts on a circle and ends
         far from one (camel_b: spread of radii about the centroid > 5%, and
         its length approaches the 3D length; bishop, whose 3D boundary is
         itself a circle, only has to leave the exact circle);
     (d) the wavy cone of fig 3.3, built here (apex angle > 2 pi, cut along
         one generator so the apex is on the boundary): without the barrier
         the injective optimum overlaps itself (bp_check reports boundary
         intersections); with the barrier the map is valid;
     (e) cancelling from the callback at iteration 7: BP_ERR_CANCELLED,
         iterations == 7, stop == BP_STOP_CANCELLED, valid map;
     (f) gradient descent also ends valid with a lower energy;
     (g) bp_parameterize on spot.obj: the packed charts do not overlap each
         other (bp_check on the union of all charts' triangles);
     (h) scale: bishop scaled by 2^10 and 2^-10 gives the same map scaled
         (bit for bit: every operation scales exactly), and scaled by 1e3
         and 1e-3 the same map up to rounding of the input (to 1e-6 of the
         chart size after 20 iterations; same energy to 1e-6 at convergence,
         see test_scale for the measured divergence in between);
     (i) the L-BFGS direction (four passes with the Gram matrix s_i.y_j)
         equals the textbook two-loop recursion on the same pairs. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <string.h>
#include <stdlib.h>

static const double PI = 3.14159265358979323846;

static int map_valid(const bp_chart *ch, const double *uv, bp_check_report *out)
{
    bp_check_report rep;
    bp_status st = bp_check(ch->triangles, ch->num_triangles, uv, ch->num_vertices, NULL, &rep, NULL);
    if (out) *out = rep;
    return st == BP_OK && !rep.flipped && !rep.degenerate && !rep.nonfinite && !rep.boundary_intersections;
}

/* ---- the solver, set up by hand as bp_chart_optimize does ------------------ */

static void solver_for_chart(bp__solver *S, const bp_allocator *a, const bp_chart *ch, const bp_mesh *m, bp_energy energy)
{
    /* the library's own set-up (bp__solver_chart, as bp_chart_optimize) */
    bp_options o;
    memset(&o, 0, sizeof o);
    o.energy = energy;
    bp__solver_chart(S, a, ch, m, &o, NULL, NULL);
}

static void solver_free(bp__solver *S)
{
    bp__solver_free(S);       /* frees the rest shapes too */
}

/* ---- the progress callback ------------------------------------------------- */

typedef struct watch {
    bp_chart *ch;
    bp__solver *S;          /* optional: recompute the objective */
    int calls, invalid, bad_seq, nonmono, cancel_at, bad_args;
    double fprev, worst_rise;
} watch;

static int on_progress(void *user, uint32_t chart, int iteration, double mean_energy, double step)
{
    watch *w = (watch *)user;
    (void)chart;
    w->calls++;
    if (iteration != w->calls) w->bad_seq++;
    if (!(step > 0) || !(mean_energy >= 1) || !(mean_energy < HUGE_VAL)) w->bad_args++;
    if (!map_valid(w->ch, w->ch->uv, NULL)) w->invalid++;
    if (w->S) {
        double ed, f = bp__objective(w->S, w->ch->uv, NULL, &ed);
        if (w->calls > 1 && f > w->fprev) {
            double rise = (f - w->fprev) / w->fprev;
            if (rise > w->worst_rise) w->worst_rise = rise;
            if (rise > 1e-12) w->nonmono++;
        }
        if (!(fabs(ed / w->S->nt - mean_energy) <= 1e-9 * mean_energy)) w->bad_args++;
        w->fprev = f;
    }
    return w->cancel_at > 0 && iteration == w->cancel_at;
}

/* Optimize one chart under the watch; returns the status. */
static bp_status watched_optimize(bp_chart *ch, uint32_t c, const bp_mesh *m, bp_options opt, int with_objective, watch *w)
{
    bp__solver S;
    bp_allocator a;
    bp_error err;
    bp_status st;
    memset(&a, 0, sizeof a);
    memset(w, 0, sizeof *w);
    w->ch = ch;
    if (with_objective) {
        solver_for_chart(&S, &a, ch, m, opt.energy);
        w->S = &S;
    }
    opt.progress = on_progress;
    opt.progress_user = w;
    st = bp_chart_optimize(ch, c, m, &opt, &err);
    if (with_objective) solver_free(&S);
    w->S = NULL;
    return st;
}

static int load(const char *path, bp_mesh *mesh, bp_atlas *atlas, int init)
{
    bp_error err;
    bp_options opt;
    uint32_t c;
    memset(&opt, 0, sizeof opt);
    if (bp_read_mesh(path, mesh, NULL, &err) != BP_OK) { printf("  %s: %s\n", path, err.message); return 0; }
    if (bp_atlas_build(atlas, mesh, &opt, &err) != BP_OK) {
        printf("  %s: %s\n", path, err.message);
        bp_mesh_free(mesh, NULL);
        return 0;
    }
    opt.init = init == 2 ? BP_INIT_MEAN_VALUE : BP_INIT_AUTO;    /* 2: the barycentric start, on a circle */
    if (init)
        for (c = 0; c < atlas->num_charts; c++)
            if (bp_chart_init(&atlas->charts[c], mesh, &opt, &err) != BP_OK) {
                printf("  %s chart %u: %s\n", path, c, err.message);
                bp_atlas_free(atlas);
                bp_mesh_free(mesh, NULL);
                return 0;
            }
    return 1;
}

/* ---- (a), (b), (c) ---------------------------------------------------------- */

static void test_every_iteration(const char *path, int max_iterations, int check_objective, bp_direction direction)
{
    bp_mesh mesh;
    bp_atlas atlas;
    uint32_t c;
    int calls = 0, iters = 0, invalid = 0, bad_seq = 0, nonmono = 0, bad_args = 0, final_bad = 0, not_lower = 0, errors = 0;
    double worst_rise = 0, e0 = 0, e1 = 0;
    if (!BPT_CHECK(load(path, &mesh, &atlas, 1), "%s: read, charts and start maps", path)) return;
    for (c = 0; c < atlas.num_charts; c++) {
        bp_options opt;
        watch w;
        bp_chart *ch = &atlas.charts[c];
        memset(&opt, 0, sizeof opt);
        opt.max_iterations = max_iterations;
        opt.direction = direction;
        if (watched_optimize(ch, c, &mesh, opt, check_objective, &w) != BP_OK) errors++;
        calls += w.calls;
        iters += ch->iterations;
        invalid += w.invalid;
        bad_seq += w.bad_seq + (w.calls != ch->iterations);
        nonmono += w.nonmono;
        bad_args += w.bad_args;
        if (w.worst_rise > worst_rise) worst_rise = w.worst_rise;
        if (!map_valid(ch, ch->uv, NULL)) final_bad++;
        if (!(ch->energy_end < ch->energy_start)) not_lower++;
        e0 += ch->energy_start / atlas.num_charts;
        e1 += ch->energy_end / atlas.num_charts;
    }
    printf("  %s, direction %s, max_iterations %d:\n", path,
           direction == BP_DIRECTION_LBFGS ? "L-BFGS (scalar H0)" : direction == BP_DIRECTION_GRADIENT ? "gradient" : "preconditioned L-BFGS",
           max_iterations);
    BPT_CHECK(errors == 0, "%s: bp_chart_optimize returned BP_OK for all %u charts", path, atlas.num_charts);
    BPT_CHECK(invalid == 0 && calls > 0, "%s: the map passed bp_check after every one of %d iterations (%d invalid)", path,
              calls, invalid);
    BPT_CHECK(bad_seq == 0 && calls == iters, "%s: the callback ran once per iteration, numbered 1, 2, ... (%d calls, "
              "chart->iterations sum %d)", path, calls, iters);
    BPT_CHECK(bad_args == 0, "%s: callback arguments: step > 0, mean energy >= 1, finite%s", path,
              check_objective ? " and == E_D / nt recomputed" : "");
    if (check_objective)
        BPT_CHECK(nonmono == 0, "%s: the objective E_D + E_B never increases between iterations (worst relative rise %.3g)",
                  path, worst_rise);
    BPT_CHECK(final_bad == 0 && not_lower == 0, "%s: final maps valid and E_D end < start on every chart (mean over charts "
              "%.6g -> %.6g)", path, e0, e1);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* Outer loop of chart 0: spread of the radii (max - min) / mean about
   `centre` (NULL: the loop's centroid), and perimeter over the 3D one. */
static void loop_shape(const bp_chart *ch, const bp_mesh *m, const double *centre, double *spread, double *perim_ratio)
{
    uint32_t n = ch->loop_start[1], k;
    double cx = 0, cy = 0, mean = 0, lo = HUGE_VAL, hi = 0, p2 = 0, p3 = 0;
    for (k = 0; k < n; k++) { cx += ch->uv[2 * ch->loop_vertices[k]] / n; cy += ch->uv[2 * ch->loop_vertices[k] + 1] / n; }
    if (centre) { cx = centre[0]; cy = centre[1]; }
    for (k = 0; k < n; k++) {
        uint32_t a = ch->loop_vertices[k], b = ch->loop_vertices[(k + 1) % n];
        double r = hypot(ch->uv[2 * a] - cx, ch->uv[2 * a + 1] - cy);
        mean += r / n;
        if (r < lo) lo = r;
        if (r > hi) hi = r;
        p2 += hypot(ch->uv[2 * a] - ch->uv[2 * b], ch->uv[2 * a + 1] - ch->uv[2 * b + 1]);
        p3 += bp__dist3(bp__pos(m, ch->vertex[a]), bp__pos(m, ch->vertex[b]));
    }
    *spread = (hi - lo) / mean;
    *perim_ratio = p2 / p3;
}

/* The mean-value start map (asked for: the default start is the conformal
   map of >>conformal, whose boundary is free already) puts the outer loop
   on a circle about the origin; a free
   boundary must leave it.  Measured on bishop and camel_b.  Bishop's
   boundary (16 vertices) is itself a circle in 3D (its radii about the 3D
   centroid spread by 0.95%) around a nearly closed, rotationally symmetric
   piece, so its free-boundary optimum stays round: measured spread 0.87%
   about the centroid, perimeter 4.66 -> 4.70 times the 3D one.  The 5%
   criterion is therefore checked on camel_b, whose boundary is far from a
   circle (486 vertices); bishop only has to leave the exact circle. */
static void test_free_boundary(void)
{
    const char *files[2] = { "tests/data/bishop_part_f1000.obj", "tests/data/camel_b.obj" };
    int f;
    for (f = 0; f < 2; f++) {
        bp_mesh mesh;
        bp_atlas atlas;
        bp_error err;
        bp_options opt;
        double origin[2] = { 0, 0 }, s0, s1, p0, p1;
        if (!BPT_CHECK(load(files[f], &mesh, &atlas, 2), "%s: read and start map", files[f])) continue;
        memset(&opt, 0, sizeof opt);
        opt.max_iterations = 0;                  /* to convergence */
        loop_shape(&atlas.charts[0], &mesh, origin, &s0, &p0);
        bp_chart_optimize(&atlas.charts[0], 0, &mesh, &opt, &err);
        loop_shape(&atlas.charts[0], &mesh, NULL, &s1, &p1);
        BPT_CHECK(s0 < 1e-12, "%s start map: the outer loop is on a circle about the origin (radius spread %.3g)", files[f], s0);
        if (f == 0)
            BPT_CHECK(s1 > 1e-3, "%s optimized: the boundary left the circle (radius spread about the centroid %.3g; "
                      "perimeter / 3D perimeter %.4g -> %.4g)", files[f], s1, p0, p1);
        else
            BPT_CHECK(s1 > 0.05 && fabs(p1 - 1) < 0.25 && fabs(p1 - 1) < fabs(p0 - 1),
                      "%s optimized (converged): the free boundary is far from a circle (radius spread %.3g of the "
                      "mean radius) and its length approaches the 3D length (perimeter / 3D perimeter %.4g -> %.4g)",
                      files[f], s1, p0, p1);
        bp_atlas_free(&atlas);
        bp_mesh_free(&mesh, NULL);
    }
}

/* ---- (d) the wavy cone ---------------------------------------------------- */

/* Apex 0; ring r = 1..R has N+1 vertices j = 0..N (j = N duplicates j = 0:
   the cut along the generator theta = 0).  d(theta) = (cos, sin, A sin(k theta)). */
static void make_wavy_cone(bp_mesh *m, int R, int N, int kk, double A)
{
    int r, j;
    uint32_t nt = 0;
    memset(m, 0, sizeof *m);
    m->num_vertices = (uint32_t)(1 + R * (N + 1));
    m->num_triangles = (uint32_t)(N + 2 * N * (R - 1));
    m->positions = (double *)malloc(3 * m->num_vertices * sizeof(double));
    m->triangles = (uint32_t *)malloc(3 * m->num_triangles * sizeof(uint32_t));
    m->num_faces = m->num_triangles;
    m->positions[0] = m->positions[1] = m->positions[2] = 0;
#define VID(r, j) ((uint32_t)(1 + ((r) - 1) * (N + 1) + (j)))
    for (r = 1; r <= R; r++)
        for (j = 0; j <= N; j++) {
            double th = 2 * PI * (j % N) / N, s = (double)r / R;
            double *p = m->positions + 3 * VID(r, j);
            p[0] = s * cos(th); p[1] = s * sin(th); p[2] = s * A * sin(kk * th);
        }
    for (j = 0; j < N; j++) {
        m->triangles[3 * nt] = 0; m->triangles[3 * nt + 1] = VID(1, j); m->triangles[3 * nt + 2] = VID(1, j + 1); nt++;
    }
    for (r = 1; r < R; r++)
        for (j = 0; j < N; j++) {
            uint32_t a = VID(r, j), b = VID(r + 1, j), c = VID(r + 1, j + 1), d = VID(r, j + 1);
            m->triangles[3 * nt] = a; m->triangles[3 * nt + 1] = b; m->triangles[3 * nt + 2] = c; nt++;
            m->triangles[3 * nt] = a; m->triangles[3 * nt + 1] = c; m->triangles[3 * nt + 2] = d; nt++;
        }
#undef VID
}

static void test_wavy_cone(void)
{
    bp_mesh m;
    int R = 8, N = 60, kk = 5, pass;
    double A = 0.8, angle = 0;
    int j;
    make_wavy_cone(&m, R, N, kk, A);
    for (j = 0; j < N; j++) {
        const double *p = m.positions + 3 * (1 + j), *q = m.positions + 3 * (1 + j + 1);
        double dot = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
        angle += acos(dot / sqrt((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2])));
    }
    BPT_CHECK(angle > 2 * PI * 1.05, "wavy cone (k = %d, A = %.1f, %u triangles): total 3D angle at the apex %.4f > 2 pi", kk, A,
              m.num_triangles, angle);
    for (pass = 0; pass < 2; pass++) {
        bp_atlas atlas;
        bp_error err;
        bp_options opt;
        bp_status st;
        bp_check_report rep;
        memset(&opt, 0, sizeof opt);
        opt.no_barrier = pass == 0;
        opt.max_iterations = 2000;
        memset(&rep, 0, sizeof rep);
        if (!BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1 &&
                       atlas.charts[0].num_loops == 1, "wavy cone: one disk chart (%s)", err.message))
            break;
        st = bp_chart_init(&atlas.charts[0], &m, &opt, &err);
        BPT_CHECK(st == BP_OK && map_valid(&atlas.charts[0], atlas.charts[0].uv, NULL), "wavy cone: valid start map");
        st = bp_chart_optimize(&atlas.charts[0], 0, &m, &opt, &err);
        map_valid(&atlas.charts[0], atlas.charts[0].uv, &rep);
        if (pass == 0)
            /* a cone is developable: the injective optimum is an isometry,
               symmetric Dirichlet energy 4 */
            BPT_CHECK(atlas.charts[0].energy_end < 4.001, "wavy cone without the barrier reaches the isometric energy 4 "
                      "(mean energy %.9g)", atlas.charts[0].energy_end);
        if (pass == 0)
            BPT_CHECK(st == BP_OK && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections > 0,
                      "wavy cone without the barrier (no_barrier = 1): locally injective (0 flipped) but the boundary "
                      "overlaps itself: %u boundary intersections (%d iterations, stop %s, energy %.6g -> %.6g)",
                      rep.boundary_intersections, atlas.charts[0].iterations, bp_stop_string(atlas.charts[0].stop),
                      atlas.charts[0].energy_start, atlas.charts[0].energy_end);
        else
            BPT_CHECK(st == BP_OK && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections == 0,
                      "wavy cone with the barrier: bijective (%u flipped, %u boundary intersections; %d iterations, stop %s, "
                      "energy %.6g -> %.6g)", rep.flipped, rep.boundary_intersections, atlas.charts[0].iterations,
                      bp_stop_string(atlas.charts[0].stop), atlas.charts[0].energy_start, atlas.charts[0].energy_end);
        bp_atlas_free(&atlas);
    }
    free(m.positions);
    free(m.triangles);
}

/* ---- (e) cancel, (f) gradient descent --------------------------------------- */

static void test_cancel_and_gradient(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_options opt;
    watch w;
    bp_status st;
    bp_chart *ch;
    if (!BPT_CHECK(load("tests/data/bishop_part_f1000.obj", &mesh, &atlas, 1), "bishop: read and start map")) return;
    ch = &atlas.charts[0];
    memset(&opt, 0, sizeof opt);
    {
        bp__solver S;
        bp_allocator a;
        bp_error err;
        memset(&a, 0, sizeof a);
        memset(&w, 0, sizeof w);
        w.ch = ch;
        w.cancel_at = 7;
        opt.progress = on_progress;
        opt.progress_user = &w;
        solver_for_chart(&S, &a, ch, &mesh, BP_ENERGY_SYMMETRIC_DIRICHLET);
        st = bp_chart_optimize(ch, 0, &mesh, &opt, &err);
        solver_free(&S);
        BPT_CHECK(st == BP_ERR_CANCELLED && err.status == BP_ERR_CANCELLED, "cancel at iteration 7: BP_ERR_CANCELLED (%s)",
                  err.message);
        BPT_CHECK(ch->iterations == 7 && w.calls == 7 && ch->stop == BP_STOP_CANCELLED,
                  "cancel: iterations == 7 (%d), 7 callbacks (%d), stop == cancelled (%s)", ch->iterations, w.calls,
                  bp_stop_string(ch->stop));
        BPT_CHECK(map_valid(ch, ch->uv, NULL) && w.invalid == 0 && ch->energy_end < ch->energy_start,
                  "cancel: the kept map is valid and lower (%.6g -> %.6g)", ch->energy_start, ch->energy_end);
    }
    /* gradient descent from a fresh start map */
    {
        bp_error err;
        memset(&opt, 0, sizeof opt);
        bp_chart_init(ch, &mesh, &opt, &err);
        opt.direction = BP_DIRECTION_GRADIENT;
        opt.max_iterations = 300;
        st = watched_optimize(ch, 0, &mesh, opt, 1, &w);
        BPT_CHECK(st == BP_OK && w.invalid == 0 && w.calls == ch->iterations && map_valid(ch, ch->uv, NULL),
                  "gradient descent: valid after each of %d iterations and at the end (stop %s)", ch->iterations,
                  bp_stop_string(ch->stop));
        BPT_CHECK(ch->energy_end < ch->energy_start && w.nonmono == 0,
                  "gradient descent: energy %.6g -> %.6g, objective non-increasing", ch->energy_start, ch->energy_end);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* ---- (g) packing --------------------------------------------------------------- */

static void test_packed_spot(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_status st;
    uint32_t c, nv = 0, nt = 0, *tri, *p;
    double *uv, *q;
    bp_check_report rep;
    int each_bad = 0;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_read_obj("tests/data/spot.obj", &mesh, NULL, &err) == BP_OK, "read spot: %s", err.message)) return;
    st = bp_parameterize(&atlas, &mesh, &opt, &err);
    if (!BPT_CHECK(st == BP_OK, "bp_parameterize(spot): %s", err.message)) { bp_mesh_free(&mesh, NULL); return; }
    for (c = 0; c < atlas.num_charts; c++) {
        nv += atlas.charts[c].num_vertices;
        nt += atlas.charts[c].num_triangles;
        if (!map_valid(&atlas.charts[c], atlas.charts[c].uv, NULL)) each_bad++;
    }
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof(uint32_t));
    uv = (double *)malloc(2 * (size_t)nv * sizeof(double));
    p = tri;
    q = uv;
    nv = 0;
    for (c = 0; c < atlas.num_charts; c++) {
        const bp_chart *ch = &atlas.charts[c];
        uint32_t k;
        for (k = 0; k < 3 * ch->num_triangles; k++) *p++ = ch->triangles[k] + nv;
        memcpy(q, ch->uv, 2 * ch->num_vertices * sizeof(double));
        q += 2 * ch->num_vertices;
        nv += ch->num_vertices;
    }
    st = bp_check(tri, nt, uv, nv, NULL, &rep, NULL);
    BPT_CHECK(atlas.num_charts == 13 && each_bad == 0, "spot: 13 charts, each valid after packing (%u charts, %d invalid)",
              atlas.num_charts, each_bad);
    BPT_CHECK(st == BP_OK && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections == 0,
              "spot packed atlas: bp_check on the union of all %u triangles: no flips, no boundary edges of any two "
              "charts meet (%u intersections)", nt, rep.boundary_intersections);
    free(tri);
    free(uv);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
}

/* ---- (h) scale --------------------------------------------------------------------- */

static int run_scaled(const bp_mesh *base, double s, int iters, double **uv_out, uint32_t *nv_out, int *iterations,
                      double *energy)
{
    bp_mesh m = *base;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    uint32_t i;
    m.positions = (double *)malloc(3 * base->num_vertices * sizeof(double));
    for (i = 0; i < 3 * base->num_vertices; i++) m.positions[i] = base->positions[i] * s;
    memset(&opt, 0, sizeof opt);
    opt.max_iterations = iters;
    if (bp_atlas_build(&atlas, &m, &opt, &err) != BP_OK || bp_chart_init(&atlas.charts[0], &m, &opt, &err) != BP_OK ||
        bp_chart_optimize(&atlas.charts[0], 0, &m, &opt, &err) != BP_OK) {
        free(m.positions);
        return 0;
    }
    *nv_out = atlas.charts[0].num_vertices;
    *uv_out = (double *)malloc(2 * *nv_out * sizeof(double));
    for (i = 0; i < 2 * *nv_out; i++) (*uv_out)[i] = atlas.charts[0].uv[i] / s;
    *iterations = atlas.charts[0].iterations;
    *energy = atlas.charts[0].energy_end;
    bp_atlas_free(&atlas);
    free(m.positions);
    return 1;
}

/* Scale invariance.  Every quantity of the method is scale-free (energies
   of J, weights area / mean area, eps and the step lengths follow the
   scale), so:
   - a power-of-two scale changes no rounding at all: the maps must be
     equal bit for bit, at every iteration count;
   - a decimal scale (1e3, 1e-3) rounds each input coordinate, so the two
     runs start 1e-16 apart.  Measured on bishop: after 20 iterations the
     maps differ by ~5e-8 of the chart size (checked: < 1e-6); between 40
     and 60 iterations one discrete decision of the line search (how many
     halvings) comes out differently and the paths separate by up to 1.7% of
     the chart size; both then converge to the same minimum (85-87
     iterations; maps within 8e-4 of the chart size, which is the accuracy
     the stopping rule -- relative decrease 1e-7 -- determines positions to
     in the flat directions of the energy: ~sqrt(1e-7) = 3e-4).  So the
     converged runs are checked for energies equal to 1e-6 and maps within
     1e-2 of the chart size, not 1e-6. */
static void test_scale(void)
{
    bp_mesh mesh;
    bp_error err;
    double scales[4] = { 1024.0, 1.0 / 1024.0, 1e3, 1e-3 };
    int budgets[2] = { 20, 0 }, b;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &mesh, NULL, &err) == BP_OK, "read bishop")) return;
    for (b = 0; b < 2; b++) {
        double *ref = NULL, size = 0, e0 = 0;
        uint32_t nv = 0, i;
        int it0 = 0, k;
        if (!BPT_CHECK(run_scaled(&mesh, 1.0, budgets[b], &ref, &nv, &it0, &e0), "bishop at scale 1 (%s)",
                       budgets[b] ? "20 iterations" : "to convergence"))
            continue;
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
        for (k = 0; k < 4; k++) {
            double *uv = NULL, diff = 0, e = 0;
            uint32_t nv2 = 0;
            int it = 0;
            if (!run_scaled(&mesh, scales[k], budgets[b], &uv, &nv2, &it, &e) || nv2 != nv) {
                BPT_CHECK(0, "bishop at scale %g: optimization failed", scales[k]);
                free(uv);
                continue;
            }
            for (i = 0; i < 2 * nv; i++) if (fabs(uv[i] - ref[i]) > diff) diff = fabs(uv[i] - ref[i]);
            if (k < 2)
                BPT_CHECK(diff == 0 && it == it0 && e == e0, "bishop scaled by %g (%s): map / scale identical bit for bit "
                          "(%d iterations, max diff %.3g of the chart size)", scales[k],
                          budgets[b] ? "20 iterations" : "converged", it, diff / size);
            else if (budgets[b])
                BPT_CHECK(diff <= 1e-6 * size, "bishop scaled by %g, 20 iterations: map / scale equal to 1e-6 of the "
                          "chart size (max diff %.3g)", scales[k], diff / size);
            else
                BPT_CHECK(diff <= 1e-2 * size && fabs(e - e0) <= 1e-6 * e0,
                          "bishop scaled by %g, converged (%d vs %d iterations): mean energy equal to 1e-6 (%.9g vs %.9g), "
                          "map / scale within 1e-2 of the chart size (max diff %.3g)", scales[k], it, it0, e, e0,
                          diff / size);
            free(uv);
        }
        free(ref);
    }
    bp_mesh_free(&mesh, NULL);
}

/* (i) The vector-free two-loop recursion (bp__lbfgs_direction, which keeps
   the Gram matrix s_i.y_j and makes four passes) against the textbook
   recursion written out here, on the same pairs: random steps on camel_b's
   vertices with positive curvature, two pairs of negative curvature (one
   while the memory is filling, which is dropped, one when it is full,
   which also loses the oldest pair), with H0 the scaled identity and the
   scaled Laplacian preconditioner.  Same direction to 1e-10 (rounding). */
static double dotn(const double *a, const double *b, uint32_t n)
{
    double d = 0;
    uint32_t i;
    for (i = 0; i < n; i++) d += a[i] * b[i];
    return d;
}

static void reference_direction(int np, double *const *Sv, double *const *Yv, const double *g, double *v, uint32_t n,
                                const bp__sparse *K, const bp__factor *KF, const bp__par *par, double *z)
{
    double a[16], scale, *q = v;
    uint32_t i, j, p;
    int k;
    for (i = 0; i < n; i++) q[i] = g[i];
    for (k = np - 1; k >= 0; k--) {                   /* newest first */
        a[k] = dotn(Sv[k], q, n) / dotn(Sv[k], Yv[k], n);
        for (i = 0; i < n; i++) q[i] -= a[k] * Yv[k][i];
    }
    if (K) {                                          /* s.Ks / s.y of the newest pair */
        double sks = 0;
        for (j = 0; j < K->n; j++)
            for (p = K->colp[j]; p < K->colp[j + 1]; p++)
                sks += Sv[np - 1][2 * K->row[p]] * K->val[p] * Sv[np - 1][2 * j] +
                       Sv[np - 1][2 * K->row[p] + 1] * K->val[p] * Sv[np - 1][2 * j + 1];
        scale = sks / dotn(Sv[np - 1], Yv[np - 1], n);
        bp__precondition(KF, par, q, q, z);
    } else {
        scale = dotn(Sv[np - 1], Yv[np - 1], n) / dotn(Yv[np - 1], Yv[np - 1], n);
    }
    for (i = 0; i < n; i++) q[i] *= scale;
    for (k = 0; k < np; k++) {                        /* oldest first */
        double b = dotn(Yv[k], q, n) / dotn(Sv[k], Yv[k], n);
        for (i = 0; i < n; i++) q[i] += (a[k] - b) * Sv[k][i];
    }
    for (i = 0; i < n; i++) v[i] = -q[i];
}

static void test_lbfgs_direction(void)
{
    bp_mesh m;
    bp_atlas at;
    bp_error e;
    bp_options o;
    bp_allocator a = bp__allocator_of(NULL);
    bp__solver S;
    bp__sparse K;
    bp__factor KF;
    bp__lbfgs L;
    double *rw, *x, *xn, *g, *gn, *v, *vr, *z, *Sv[8], *Yv[8], worst = 0;
    uint32_t n, i;
    int push, np = 0, k, hist = 5, same_count = 1, checks = 0, pre;
    memset(&o, 0, sizeof o);
    memset(&S, 0, sizeof S);
    memset(&K, 0, sizeof K);
    bpt_rng_state = 0x1bf5;
    if (!BPT_CHECK(bp_read_mesh("tests/data/camel_b.obj", &m, NULL, &e) == BP_OK, "camel_b: %s", e.message)) return;
    if (!BPT_CHECK(bp_atlas_build(&at, &m, &o, &e) == BP_OK, "camel_b charts: %s", e.message)) {
        bp_mesh_free(&m, NULL);
        return;
    }
    rw = (double *)malloc(3 * sizeof(double) * at.charts[0].num_triangles);
    bp__solver_chart(&S, &a, &at.charts[0], &m, &o, rw, &e);
    BPT_CHECK(bp__laplacian(&a, &S, rw, NULL, &K, &KF, NULL, NULL) == BP_OK, "camel_b: Laplacian factored");
    n = 2 * S.nv;
    x = (double *)malloc(n * sizeof(double)); xn = (double *)malloc(n * sizeof(double));
    g = (double *)malloc(n * sizeof(double)); gn = (double *)malloc(n * sizeof(double));
    v = (double *)malloc(n * sizeof(double)); vr = (double *)malloc(n * sizeof(double));
    z = (double *)malloc(4 * S.nv * sizeof(double));
    for (k = 0; k < 8; k++) { Sv[k] = (double *)malloc(n * sizeof(double)); Yv[k] = (double *)malloc(n * sizeof(double)); }
    BPT_CHECK(bp__lbfgs_init(&a, &L, hist, n), "L-BFGS memory allocated");
    for (i = 0; i < n; i++) { x[i] = bpt_rng_range(-1, 1); g[i] = bpt_rng_range(-1, 1); }
    for (push = 0; push < 11; push++) {
        int bad = push == 3 || push == 8;             /* negative curvature */
        double *t;
        for (i = 0; i < n; i++) {
            double s = bpt_rng_range(-0.1, 0.1);
            xn[i] = x[i] + s;
            gn[i] = g[i] + (bad ? -s : s * bpt_rng_range(0.5, 2) + bpt_rng_range(-1e-3, 1e-3));
        }
        bp__lbfgs_push(&L, &S.par, x, xn, g, gn);
        if (!bad) {                                    /* the reference memory: append, drop the oldest */
            if (np == hist) { t = Sv[0]; memmove(Sv, Sv + 1, (size_t)(hist - 1) * sizeof *Sv); Sv[hist - 1] = t;
                              t = Yv[0]; memmove(Yv, Yv + 1, (size_t)(hist - 1) * sizeof *Yv); Yv[hist - 1] = t; np--; }
            for (i = 0; i < n; i++) { Sv[np][i] = xn[i] - x[i]; Yv[np][i] = gn[i] - g[i]; }
            np++;
        } else if (np == hist) {                       /* its slot held the oldest pair */
            t = Sv[0]; memmove(Sv, Sv + 1, (size_t)(hist - 1) * sizeof *Sv); Sv[hist - 1] = t;
            t = Yv[0]; memmove(Yv, Yv + 1, (size_t)(hist - 1) * sizeof *Yv); Yv[hist - 1] = t;
            np--;
        }
        same_count &= L.nh == np;
        t = x; x = xn; xn = t;
        t = g; g = gn; gn = t;
        if (L.nh != np || np == 0) continue;
        for (pre = 0; pre < 2; pre++) {
            double gv, gvr, big = 0, diff = 0;
            gv = bp__lbfgs_direction(&L, &S.par, g, v, pre ? &K : NULL, &KF, z, vr);
            reference_direction(np, Sv, Yv, g, vr, n, pre ? &K : NULL, &KF, &S.par, z);
            gvr = dotn(g, vr, n);
            for (i = 0; i < n; i++) {
                if (fabs(vr[i]) > big) big = fabs(vr[i]);
                if (fabs(v[i] - vr[i]) > diff) diff = fabs(v[i] - vr[i]);
            }
            if (diff / big > worst) worst = diff / big;
            if (fabs(gv - gvr) > 1e-10 * fabs(gvr)) worst = 1;
            checks++;
        }
    }
    BPT_CHECK(same_count, "L-BFGS keeps the pairs the textbook rule keeps (a pair of negative curvature is dropped, "
              "and takes the oldest with it when the memory is full)");
    BPT_CHECK(checks == 22 && worst < 1e-10, "the four-pass recursion gives the textbook two-loop direction and g.v "
              "(%d directions, identity and preconditioned H0; largest difference %.2g of max |v|)", checks, worst);
    bp__lbfgs_free(&a, &L);
    for (k = 0; k < 8; k++) { free(Sv[k]); free(Yv[k]); }
    free(x); free(xn); free(g); free(gn); free(v); free(vr); free(z); free(rw);
    bp__factor_free(&a, &KF);
    bp__sparse_free(&a, &K);
    bp__solver_free(&S);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

int main(void)
{
    test_every_iteration("tests/data/bishop_part_f1000.obj", 0, 1, BP_DIRECTION_PRECONDITIONED);
    test_every_iteration("tests/data/bishop_part_f1000.obj", 300, 1, BP_DIRECTION_LBFGS);
    test_every_iteration("tests/data/spot.obj", 0, 1, BP_DIRECTION_PRECONDITIONED);
    test_every_iteration("tests/data/face_holes.off", 300, 1, BP_DIRECTION_PRECONDITIONED);
    test_every_iteration("tests/data/camel_b.obj", 200, 0, BP_DIRECTION_PRECONDITIONED);
    test_free_boundary();
    test_wavy_cone();
    test_cancel_and_gradient();
    test_packed_spot();
    test_scale();
    test_lbfgs_direction();
    return bpt_finish();
}
