/* test_conformal.c - the conformal start map (>>conformal).

   Everything is measured here by the test's own formulas: each triangle
   flattened in its own 3D frame, J = [U2 - U1, U3 - U1] R^-1 with R the
   frame's edge matrix, the conformal energy E_C = sum A ((a - d)^2 +
   (b + c)^2) and its gradient through dE/dJ, and the symmetric Dirichlet
   energy from |J|^2 and det J; nothing of the library's assembly.

   (a) On face_holes (8,288 triangles, six holes) and bishop, the default
       start is the conformal map (chart.start_map), exactly bijective
       (bp_check), and it is the least squares conformal map: two boundary
       vertices are held, one at the origin and one on the positive u axis
       (their 3D distance at least half the boundary's diameter, found by
       brute force), and at every other vertex the gradient of E_C is zero
       (below 1e-7 of the held vertices' reaction); the map's scale is the
       one that minimizes the symmetric Dirichlet energy (1.001 times
       larger or smaller is worse).
   (b) Where the conformal map folds (camel_b) the start is the mean-value
       map, exactly bijective; BP_INIT_CONFORMAL asks for the same; the
       barycentric inits are unchanged (BP_INIT_MEAN_VALUE gives the
       mean-value map on face_holes), and a value outside bp_init acts as
       BP_INIT_AUTO (the conformal map there).
   (c) The same bits whatever the schedule of the tasks (serial, backwards,
       odd then even) on face_holes, above the size where the start map's
       phases run on a pool.
   (d) The size rule: this file is compiled with BP__CONFORMAL_MAX 20000,
       so beetle (38,656 triangles, 1,136 of its 19,887 vertices on its
       eleven loops: more than 2.5 sqrt(V), no Schur complement) starts
       from the mean-value map, while face_holes (8,288) starts conformal
       in (a), and so does camelhead (22,704 triangles but 56 boundary
       vertices: the Schur complement, at any size); asked for by name (BP_INIT_CONFORMAL, no size limit)
       beetle starts conformal, so its map is bijective and only the rule
       kept it out.
   (e) A planar chart asked for BP_START_PLAIN with BP_INIT_CONFORMAL: the
       conformal map of a flat chart is a similarity, so its energy at the
       optimal scale is 4 to rounding.
   (f) The start's factor handed to Newton (bp__handoff, bp_chart_solve):
       on a grid lifted onto a bump (its conformal map solved in 2x2
       blocks), by projected Newton, bp_chart_solve gives the very
       bits, iterations and energy of bp_chart_init then bp_chart_optimize;
       the internal path hands the conformal factor over (made by the
       start, taken by Newton's first factorization); a handed pattern
       that is not H's (one unknown fewer) is refused and freed, with the
       same bits again; where no conformal map was kept (camel_b: it
       folds; the bump asked for the mean-value map; bishop, whose map
       is solved by the boundary's Schur complement, with no 2x2 factor)
       nothing is handed, and bishop's bits are bp_chart_solve's; with
       init_only, bp_chart_solve stops at bp_chart_init's map.
   (g) The boundary's Schur complement (>>conformal): camelhead and
       bishop, with few boundary vertices, are solved that way, face_holes
       (304 of 4,291 vertices on its loops) by the 2x2 factor; on each the
       two solves, asked for in turn, give the same map to 1e-9 of its
       extent, and the chosen one is the same bits on every schedule.
       (a) also runs on camelhead asked for BP_INIT_CONFORMAL: the Schur
       complement's map is the least squares conformal map, by the
       test's own gradient.
   (h) Where the Schur complement is planned (camelhead, bishop) the
       columns' pass fills the scalar Laplacian and the boundary's xy
       entries instead of K; K built afterwards (the 2x2 solve's need)
       holds exactly those values, bit for bit, and the same right-hand
       side; on face_holes K is filled by the pass itself. */
#define BP__CONFORMAL_MAX 20000u
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include "bpt_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double *P3(const bp_mesh *m, const bp_chart *ch, uint32_t v)
{
    return m->positions + 3 * (size_t)ch->vertex[v];
}

/* Triangle t's J = D R^-1 in its own frame (x along edge 1), its area. */
static double tri_jacobian(const bp_mesh *m, const bp_chart *ch, const double *uv, uint32_t t, double J[4],
                           double Ri[4])
{
    const uint32_t *tr = ch->triangles + 3 * (size_t)t;
    double w, x, y, D[4], area = bpt_tri_frame(P3(m, ch, tr[0]), P3(m, ch, tr[1]), P3(m, ch, tr[2]), &w, &x, &y);
    /* R = [w x; 0 y], R^-1 = [1/w, -x/(w y); 0, 1/y] */
    Ri[0] = 1 / w; Ri[1] = -x / (w * y); Ri[2] = 0; Ri[3] = 1 / y;
    D[0] = uv[2 * tr[1]] - uv[2 * tr[0]];     D[1] = uv[2 * tr[2]] - uv[2 * tr[0]];
    D[2] = uv[2 * tr[1] + 1] - uv[2 * tr[0] + 1]; D[3] = uv[2 * tr[2] + 1] - uv[2 * tr[0] + 1];
    J[0] = D[0] * Ri[0] + D[1] * Ri[2]; J[1] = D[0] * Ri[1] + D[1] * Ri[3];
    J[2] = D[2] * Ri[0] + D[3] * Ri[2]; J[3] = D[2] * Ri[1] + D[3] * Ri[3];
    return area;
}

/* E_C and its gradient (2 nv, zeroed here) by the chain rule through J. */
static double conformal_energy(const bp_mesh *m, const bp_chart *ch, const double *uv, double *g)
{
    double e = 0;
    uint32_t t, i;
    for (i = 0; i < 2 * ch->num_vertices; i++) g[i] = 0;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        double J[4], Ri[4], A = tri_jacobian(m, ch, uv, t, J, Ri), r1 = J[0] - J[3], r2 = J[1] + J[2], G[4], GD[4];
        int k;
        e += A * (r1 * r1 + r2 * r2);
        G[0] = 2 * A * r1; G[1] = 2 * A * r2; G[2] = 2 * A * r2; G[3] = -2 * A * r1;   /* dE/dJ */
        GD[0] = G[0] * Ri[0] + G[1] * Ri[1]; GD[1] = G[0] * Ri[2] + G[1] * Ri[3];       /* dE/dD = dE/dJ R^-T */
        GD[2] = G[2] * Ri[0] + G[3] * Ri[1]; GD[3] = G[2] * Ri[2] + G[3] * Ri[3];
        for (k = 0; k < 2; k++) {
            g[2 * tr[1] + k] += GD[2 * k];
            g[2 * tr[2] + k] += GD[2 * k + 1];
            g[2 * tr[0] + k] -= GD[2 * k] + GD[2 * k + 1];
        }
    }
    return e;
}

/* The area-weighted mean symmetric Dirichlet energy of uv scaled by s. */
static double sd_energy(const bp_mesh *m, const bp_chart *ch, const double *uv, double s)
{
    double e = 0, area = 0;
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        double J[4], Ri[4], A = tri_jacobian(m, ch, uv, t, J, Ri), f, det;
        int k;
        for (k = 0; k < 4; k++) J[k] *= s;
        f = J[0] * J[0] + J[1] * J[1] + J[2] * J[2] + J[3] * J[3];
        det = J[0] * J[3] - J[1] * J[2];
        e += A * (f + f / (det * det));
        area += A;
    }
    return e / area;
}

static int load(const char *path, bp_mesh *m, bp_atlas *atlas)
{
    bp_error err;
    bp_options opt;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_read_mesh(path, m, NULL, &err) == BP_OK, "read %s (%s)", path, err.message)) return 0;
    if (!BPT_CHECK(bp_atlas_build(atlas, m, &opt, &err) == BP_OK && atlas->num_charts == 1, "%s: one chart (%s)", path,
                   err.message)) {
        bp_mesh_free(m, NULL);
        return 0;
    }
    return 1;
}

static int init_with(bp_chart *ch, const bp_mesh *m, bp_init init, const bp__par *par)
{
    bp_options opt;
    bp_error err;
    bp__par serial = bp__par_serial();
    bp_options_init(&opt);
    opt.init = init;
    return BPT_CHECK(bp__chart_init(ch, m, &opt, par ? par : &serial, NULL, &err) == BP_OK, "start map (%s)", err.message);
}

static int exactly_valid(const bp_chart *ch)
{
    bp_check_report rep;
    return bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) == BP_OK;
}

static int on_boundary(const bp_chart *ch, uint32_t v)
{
    uint32_t j;
    for (j = ch->loop_start[0]; j < ch->loop_start[ch->num_loops]; j++)
        if (ch->loop_vertices[j] == v) return 1;
    return 0;
}

/* ---- (a) ------------------------------------------------------------------ */

static void check_lscm(const char *path, bp_init init)
{
    bp_mesh m;
    bp_atlas atlas;
    bp_chart *ch;
    uint32_t v, p0 = BP__NONE, p1 = BP__NONE, n0 = 0, n1 = 0, i, j, nv;
    double *g, gfree = 0, gheld = 0, diam = 0, e, s;
    if (!load(path, &m, &atlas)) return;
    ch = &atlas.charts[0];
    nv = ch->num_vertices;
    if (init_with(ch, &m, init, NULL) &&
        BPT_CHECK(ch->start_map == BP_INIT_CONFORMAL && exactly_valid(ch),
                  "%s, init %d: the start is the conformal map (start_map %d), exactly bijective", path, (int)init,
                  ch->start_map)) {
        for (v = 0; v < nv; v++) {
            if (ch->uv[2 * v] == 0 && ch->uv[2 * v + 1] == 0) { p0 = v; n0++; }
            else if (ch->uv[2 * v + 1] == 0 && ch->uv[2 * v] > 0) { p1 = v; n1++; }
        }
        for (i = ch->loop_start[0]; i < ch->loop_start[ch->num_loops]; i++)
            for (j = i + 1; j < ch->loop_start[ch->num_loops]; j++) {
                double d = bp__dist3(P3(&m, ch, ch->loop_vertices[i]), P3(&m, ch, ch->loop_vertices[j]));
                if (d > diam) diam = d;
            }
        if (BPT_CHECK(n0 == 1 && n1 == 1 && on_boundary(ch, p0) && on_boundary(ch, p1) &&
                      bp__dist3(P3(&m, ch, p0), P3(&m, ch, p1)) >= 0.5 * diam,
                      "%s: one boundary vertex held at the origin (%u found), one on the positive u axis (%u), %.4g "
                      "apart in 3D (boundary diameter %.4g)", path, n0, n1,
                      n0 == 1 && n1 == 1 ? bp__dist3(P3(&m, ch, p0), P3(&m, ch, p1)) : -1.0, diam)) {
            g = (double *)malloc(2 * (size_t)nv * sizeof(double));
            e = conformal_energy(&m, ch, ch->uv, g);
            for (v = 0; v < nv; v++) {
                double gv = hypot(g[2 * v], g[2 * v + 1]);
                if (v == p0 || v == p1) { if (gv > gheld) gheld = gv; }
                else if (gv > gfree) gfree = gv;
            }
            BPT_CHECK(gheld > 0 && gfree <= 1e-7 * gheld,
                      "%s: E_C = %.6g is stationary at every free vertex (largest gradient %.3g, held vertices' %.3g)",
                      path, e, gfree, gheld);
            free(g);
        }
        s = sd_energy(&m, ch, ch->uv, 1);
        BPT_CHECK(s < sd_energy(&m, ch, ch->uv, 1.001) && s < sd_energy(&m, ch, ch->uv, 1 / 1.001),
                  "%s: the scale minimizes the symmetric Dirichlet energy (%.8g; x1.001 %.8g, /1.001 %.8g)", path, s,
                  sd_energy(&m, ch, ch->uv, 1.001), sd_energy(&m, ch, ch->uv, 1 / 1.001));
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* ---- (b), (d) ------------------------------------------------------------- */

static void check_start_map(const char *path, bp_init init, bp_init expect, const char *why)
{
    bp_mesh m;
    bp_atlas atlas;
    if (!load(path, &m, &atlas)) return;
    if (init_with(&atlas.charts[0], &m, init, NULL))
        BPT_CHECK(atlas.charts[0].start_map == (int)expect && exactly_valid(&atlas.charts[0]),
                  "%s (%u triangles), init %d: start map %d, expected %d (%s), exactly bijective", path,
                  atlas.charts[0].num_triangles, (int)init, atlas.charts[0].start_map, (int)expect, why);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* A ramp winding twice around the z axis (r in [1, 2], two turns, rising
   0.05 per radian): its conformal map winds about twice too, every
   triangle positive, the boundary over itself. */
static bp_mesh make_ramp(void)
{
    const uint32_t W = 4, H = 96;
    bp_mesh m = bpt_mesh_new((W + 1) * (H + 1), 2 * W * H);
    uint32_t i, j, t = 0;
    for (j = 0; j <= H; j++)
        for (i = 0; i <= W; i++) {
            double r = 1 + (double)i / W, th = 4 * 3.14159265358979323846 * j / H;
            double *p = m.positions + 3 * (size_t)(j * (W + 1) + i);
            p[0] = r * cos(th); p[1] = r * sin(th); p[2] = 0.05 * th;
        }
    for (j = 0; j < H; j++)
        for (i = 0; i < W; i++) {
            uint32_t a = j * (W + 1) + i, b = a + 1, c = a + W + 1, d = c + 1;
            m.triangles[3 * t] = a; m.triangles[3 * t + 1] = b; m.triangles[3 * t + 2] = d; t++;
            m.triangles[3 * t] = a; m.triangles[3 * t + 1] = d; m.triangles[3 * t + 2] = c; t++;
        }
    return m;
}

/* (b) continued: the exact check, not only the scale's sign test, stands
   between a conformal map and the optimizer.  The conformal start itself
   (bp__conformal_begin, its columns beside the dissection, then
   bp__conformal_end) on the ramp: it answers 0 (not used) and leaves behind a map with every
   triangle positive whose boundary crosses itself; the start the library
   then makes is the mean-value map. */
static void check_overlap(void)
{
    bp_mesh m = make_ramp();
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp__tutte T;
    bp__ndnode tree[BP__ND_NODES];
    bp_check_report rep;
    uint32_t *order;
    int got = -2;
    bp_allocator al;
    bp_options_init(&opt);
    al = bp__allocator_of(&opt);
    if (!BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "ramp: one chart (%s)",
                   err.message)) { bpt_mesh_free(&m); return; }
    memset(&T, 0, sizeof T);
    T.par = bp__par_serial();
    order = (uint32_t *)malloc(((size_t)atlas.charts[0].num_vertices + 6 * BP__ND_NODES) * sizeof(uint32_t));
    atlas.charts[0].uv = (double *)malloc(2 * (size_t)atlas.charts[0].num_vertices * sizeof(double));
    if (bp__tutte_fill(&al, &T, &atlas.charts[0], &m) && bp__tutte_adjacency(&al, &T)) {
        bp__conformal C;
        bp__loop cols;
        int cf = bp__conformal_begin(&al, &T, &atlas.charts[0], &m, NULL, 0, &C);
        cols.fn = bp__conformal_task_run;      /* the columns, beside the dissection as bp__tutte_map does */
        cols.task = &C.J;
        cols.count = C.J.nc;
        if (BPT_CHECK(cf == 1, "ramp: the conformal system is set up (%d)", cf) &&
            bp__tutte_order(&al, &T, NULL, &cols) && bp__tutte_chart_order(&al, &T, order, tree))
            got = bp__conformal_end(&al, &C, &atlas.charts[0], &m, NULL, order, tree, NULL);
        bp__conformal_free(&al, &C);
    }
    bp_check(atlas.charts[0].triangles, atlas.charts[0].num_triangles, atlas.charts[0].uv,
             atlas.charts[0].num_vertices, NULL, &rep, NULL);
    BPT_CHECK(got == 0 && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections > 0,
              "ramp of two turns: the conformal start refuses (%d) a map with every triangle positive (%u flipped, %u "
              "degenerate) whose boundary crosses itself (%u intersections)", got, rep.flipped, rep.degenerate,
              rep.boundary_intersections);
    bp__tutte_free(&al, &T);
    free(order);
    if (BPT_CHECK(bp_chart_init(&atlas.charts[0], &m, &opt, &err) == BP_OK, "ramp: start map (%s)", err.message))
        BPT_CHECK(atlas.charts[0].start_map == BP_INIT_MEAN_VALUE && exactly_valid(&atlas.charts[0]),
                  "ramp: the default start is the mean-value map (%d), exactly bijective", atlas.charts[0].start_map);
    bp_atlas_free(&atlas);
    bpt_mesh_free(&m);
}

/* ---- (c) ------------------------------------------------------------------ */

static void check_schedules(const char *path)
{
    bp_mesh m;
    bp_atlas atlas;
    bp__par par[3];
    double *uv0 = NULL;
    int k, same = 1;
    if (!load(path, &m, &atlas)) return;
    par[0] = bp__par_serial();
    par[1] = par[0]; par[1].run = bpt_backwards_for; par[1].threads = 2;
    par[2] = par[0]; par[2].run = bpt_odd_even_for; par[2].threads = 2;
    for (k = 0; k < 3; k++) {
        bp_chart *ch = &atlas.charts[0];
        if (!init_with(ch, &m, BP_INIT_CONFORMAL, &par[k]) || ch->start_map != BP_INIT_CONFORMAL) { same = 0; break; }
        if (!uv0) {
            uv0 = (double *)malloc(2 * (size_t)ch->num_vertices * sizeof(double));
            memcpy(uv0, ch->uv, 2 * (size_t)ch->num_vertices * sizeof(double));
        } else if (memcmp(uv0, ch->uv, 2 * (size_t)ch->num_vertices * sizeof(double)) != 0)
            same = 0;
    }
    BPT_CHECK(same && atlas.charts[0].num_triangles >= BP__PAR_MIN_TRIANGLES,
              "%s (%u triangles): the conformal map is the same bits serially, backwards and odd then even", path,
              atlas.charts[0].num_triangles);
    free(uv0);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* ---- (f) ------------------------------------------------------------------ */

/* A mesh of bpt_add_grid's w x h grid (kind, cell side s, turned by a,
   at ox, oy) whose point (x, y) goes to lift(x, y) in 3D. */
static bp_mesh grid_mesh(int w, int h, int kind, double s, double a, double ox, double oy,
                         void (*lift)(double x, double y, double *p))
{
    bpt_gen g;
    bp_mesh m;
    uint32_t i;
    double *pos = (double *)malloc(3 * (size_t)(w + 1) * (h + 1) * sizeof(double));
    uint32_t *tri = (uint32_t *)malloc(6 * (size_t)w * h * sizeof(uint32_t));
    g.pos = pos; g.tri = tri; g.nv = 0; g.nt = 0;
    bpt_add_grid(&g, w, h, kind, s, a, ox, oy);
    m = bpt_mesh_new(g.nv, g.nt);
    for (i = 0; i < g.nv; i++) lift(pos[3 * i], pos[3 * i + 1], m.positions + 3 * i);
    memcpy(m.triangles, tri, 3 * (size_t)g.nt * sizeof(uint32_t));
    free(pos);
    free(tri);
    return m;
}

/* A 20 x 20 grid of the unit square lifted onto the bump z = 0.4 (x^2 +
   y^2): a disk with 80 of its 441 vertices on the loop, more than
   BP__CONFORMAL_SCHUR_K sqrt(nv), so its conformal map is solved in 2x2
   blocks, and a boundary that stays far from itself. */
static void bump(double x, double y, double *p) { p[0] = x; p[1] = y; p[2] = 0.4 * (x * x + y * y); }

static bp_mesh make_bump(void) { return grid_mesh(20, 20, 0, 0.05, 0, -0.5, -0.5, bump); }

typedef struct solved { double *uv; int iterations; double energy; } solved;

static int same_as(const bp_chart *ch, const solved *r)
{
    return memcmp(ch->uv, r->uv, 2 * (size_t)ch->num_vertices * sizeof(double)) == 0 &&
           ch->iterations == r->iterations && ch->energy_end == r->energy;
}

/* The internal path with a handoff; `spoil`: the handed pattern made one
   unknown short of H's.  Returns 1 when both calls succeeded. */
static int solve_handed(bp_chart *ch, const bp_mesh *m, const bp_options *opt, int spoil, int *made, int *used)
{
    bp__handoff h;
    bp__par serial = bp__par_serial();
    bp_error err;
    bp_allocator a;
    int ok;
    *made = *used = 0;
    memset(&h, 0, sizeof h);
    memset(&a, 0, sizeof a);
    ok = bp__chart_init(ch, m, opt, &serial, &h, &err) == BP_OK;
    *made = h.F.sn != NULL;
    if (spoil && h.F.sn) h.n -= 2;
    ok = ok && bp__chart_optimize_pen(ch, 0, m, opt, NULL, NULL, &h, &err) == BP_OK;
    *used = h.used;
    bp__handoff_free(&a, &h);
    return ok;
}

static void check_handoff(void)
{
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_chart *ch;
    solved r;
    int made = 0, used = 0, ok;
    size_t bytes;
    m = make_bump();
    bp_options_init(&opt);
    if (!BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "bump: one chart (%s)",
                   err.message)) { bpt_mesh_free(&m); return; }
    ch = &atlas.charts[0];
    bytes = 2 * (size_t)ch->num_vertices * sizeof(double);
    bp_options_init(&opt);
    opt.direction = BP_DIRECTION_NEWTON;
    opt.start = BP_START_PLAIN;              /* (its projection would be the start: >>start, 1) */
    if (!BPT_CHECK(bp_chart_init(ch, &m, &opt, &err) == BP_OK && ch->start_map == BP_INIT_CONFORMAL &&
                   bp_chart_optimize(ch, 0, &m, &opt, &err) == BP_OK, "bump: init, then optimize (%s)", err.message))
        goto out;
    r.uv = (double *)malloc(bytes);
    memcpy(r.uv, ch->uv, bytes);
    r.iterations = ch->iterations;
    r.energy = ch->energy_end;
    BPT_CHECK(bp_chart_solve(ch, 0, &m, &opt, &err) == BP_OK && same_as(ch, &r),
              "bump: bp_chart_solve, the same bits, %d iterations, energy %.9g", ch->iterations, ch->energy_end);
    ok = solve_handed(ch, &m, &opt, 0, &made, &used);
    BPT_CHECK(ok && made && used && same_as(ch, &r),
              "bump (80 of 441 vertices on its loop: solved in 2x2 blocks): the conformal factor handed over (made %d, taken %d), the same bits", made, used);
    ok = solve_handed(ch, &m, &opt, 1, &made, &used);
    BPT_CHECK(ok && made && !used && same_as(ch, &r),
              "bump: a handed pattern not H's is refused (made %d, taken %d), the same bits", made, used);
    opt.init = BP_INIT_MEAN_VALUE;
    ok = solve_handed(ch, &m, &opt, 0, &made, &used);
    BPT_CHECK(ok && !made && !used && ch->start_map == BP_INIT_MEAN_VALUE,
              "bump, the mean-value start asked for: nothing handed (made %d)", made);
    opt.init = BP_INIT_AUTO;
    opt.init_only = 1;
    BPT_CHECK(bp_chart_solve(ch, 0, &m, &opt, &err) == BP_OK && ch->iterations == 0 && ch->start_map == BP_INIT_CONFORMAL &&
              memcmp(ch->uv, r.uv, bytes) != 0 && exactly_valid(ch),
              "bump, init_only: bp_chart_solve stops at the start map");
    free(r.uv);
out:
    bp_atlas_free(&atlas);
    bpt_mesh_free(&m);
    if (!load("tests/data/bishop_part_f1000.obj", &m, &atlas)) return;
    ch = &atlas.charts[0];
    bp_options_init(&opt);
    opt.direction = BP_DIRECTION_NEWTON;
    if (BPT_CHECK(bp_chart_solve(ch, 0, &m, &opt, &err) == BP_OK && ch->start_map == BP_INIT_CONFORMAL,
                  "bishop: solved from the conformal start (%s)", err.message)) {
        bytes = 2 * (size_t)ch->num_vertices * sizeof(double);
        r.uv = (double *)malloc(bytes);
        memcpy(r.uv, ch->uv, bytes);
        r.iterations = ch->iterations;
        r.energy = ch->energy_end;
        ok = solve_handed(ch, &m, &opt, 0, &made, &used);
        BPT_CHECK(ok && !made && !used && same_as(ch, &r),
                  "bishop (solved by the boundary's Schur complement): nothing handed (made %d, taken %d), the same "
                  "bits", made, used);
        free(r.uv);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    if (!load("tests/data/camel_b.obj", &m, &atlas)) return;
    bp_options_init(&opt);
    opt.direction = BP_DIRECTION_NEWTON;
    ok = solve_handed(&atlas.charts[0], &m, &opt, 0, &made, &used);
    BPT_CHECK(ok && !made && !used && atlas.charts[0].start_map == BP_INIT_MEAN_VALUE,
              "camel_b (its conformal map folds): nothing handed (made %d)", made);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* ---- (g) ------------------------------------------------------------------ */

/* The conformal map of atlas chart 0 by bp__tutte_map's own steps (as
   check_overlap), with `how` set before bp__conformal_end (0: its
   choice, 2: the 2x2 factor); the map (unchecked: bp__conformal_end's
   own verdict in *got) into uv, the solve taken returned (0 on a failure
   before the solve). */
static int conformal_by(const bp_mesh *m, bp_chart *ch, int how, const bp__par *par, double *uv, int *got)
{
    bp_options opt;
    bp_allocator al;
    bp__tutte T;
    bp__ndnode tree[BP__ND_NODES];
    uint32_t *order = (uint32_t *)malloc(((size_t)ch->num_vertices + 6 * BP__ND_NODES) * sizeof(uint32_t));
    double *keep = ch->uv;
    int took = 0;
    bp_options_init(&opt);
    al = bp__allocator_of(&opt);
    memset(&T, 0, sizeof T);
    T.par = par ? *par : bp__par_serial();
    *got = -2;
    ch->uv = uv;
    if (order && bp__tutte_fill(&al, &T, ch, m) && bp__tutte_adjacency(&al, &T)) {
        bp__conformal C;
        bp__loop cols;
        if (bp__conformal_begin(&al, &T, ch, m, par, 1, &C) == 1) {
            cols.fn = bp__conformal_task_run;
            cols.task = &C.J;
            cols.count = C.J.nc;
            C.how = how;
            if (bp__tutte_order(&al, &T, par, &cols) && bp__tutte_chart_order(&al, &T, order, tree)) {
                *got = bp__conformal_end(&al, &C, ch, m, par, order, tree, NULL);
                took = C.how;
            }
        }
        bp__conformal_free(&al, &C);
    }
    ch->uv = keep;
    bp__tutte_free(&al, &T);
    free(order);
    return took;
}

/* The boundary's Schur complement against the 2x2 factor: on charts with
   few boundary vertices (camelhead: 54 of 11,381, bishop) the start takes
   the Schur complement, on face_holes (304 of 4,291, above
   BP__CONFORMAL_SCHUR_K sqrt(nv)) the 2x2 factor; both solves give the
   same map to 1e-9 of its extent (two exact methods for one linear
   system, rounded differently), both maps pass bp__conformal_end's check,
   and the Schur path is the same bits serially, backwards and odd then
   even. */
static void check_schur(const char *path, int expect)
{
    bp_mesh m;
    bp_atlas atlas;
    bp__par par[3];
    double *uv1, *uv2, *uv3, ext = 0, dif = 0;
    uint32_t n, i;
    int got1, got2, got3, how1, how2, how3, k, same = 1;
    if (!load(path, &m, &atlas)) return;
    n = 2 * atlas.charts[0].num_vertices;
    uv1 = (double *)malloc(n * sizeof(double));
    uv2 = (double *)malloc(n * sizeof(double));
    uv3 = (double *)malloc(n * sizeof(double));
    how1 = conformal_by(&m, &atlas.charts[0], 0, NULL, uv1, &got1);
    how2 = conformal_by(&m, &atlas.charts[0], 2, NULL, uv2, &got2);
    for (i = 0; i < n; i++) {
        if (fabs(uv2[i]) > ext) ext = fabs(uv2[i]);
        if (fabs(uv1[i] - uv2[i]) > dif) dif = fabs(uv1[i] - uv2[i]);
    }
    BPT_CHECK(how1 == expect && how2 == 2 && got1 == 1 && got2 == 1,
              "%s: the start's own choice is solve %d (expected %d: 1 the Schur complement, 2 the 2x2 factor), the "
              "2x2 factor asked for is %d; both maps pass the check (%d, %d)", path, how1, expect, how2, got1, got2);
    BPT_CHECK(dif <= 1e-9 * ext, "%s: the two solves give the same map, largest difference %.3g (extent %.4g)", path,
              dif, ext);
    par[0] = bp__par_serial();
    par[1] = par[0]; par[1].run = bpt_backwards_for; par[1].threads = 2;
    par[2] = par[0]; par[2].run = bpt_odd_even_for; par[2].threads = 2;
    for (k = 1; k < 3; k++) {
        how3 = conformal_by(&m, &atlas.charts[0], 0, &par[k], uv3, &got3);
        if (how3 != how1 || got3 != got1 || memcmp(uv1, uv3, n * sizeof(double)) != 0) same = 0;
    }
    BPT_CHECK(same, "%s: solve %d is the same bits serially, backwards and odd then even", path, how1);
    free(uv1); free(uv2); free(uv3);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* ---- (h) ------------------------------------------------------------------ */

/* The Schur complement's system without K: where bp__conformal_schur
   will be tried, the columns' pass fills the scalar Laplacian L, the
   boundary columns' xy entries and the right-hand side, and K is not
   allocated; bp__conformal_full then builds K after all (as the 2x2
   solve needs it), and every value of L must be bit for bit K's entry
   (2u, 2v), every kept xy entry K's (2u, 2v + 1), and the right-hand side
   the same.  Where the Schur complement is not planned (face_holes), K is
   built by the pass itself. */
static void check_scalar_pass(const char *path, int planned)
{
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_allocator al;
    bp__tutte T;
    bp__conformal C;
    bp__par par = bp__par_serial();
    bp_chart *ch;
    uint32_t v, i, nv, bad_l = 0, bad_xy = 0, bad_rhs = 0, nxy = 0, nl = 0;
    double *lv = NULL, *xy = NULL, *rhs = NULL;
    if (!load(path, &m, &atlas)) return;
    ch = &atlas.charts[0];
    bp_options_init(&opt);
    al = bp__allocator_of(&opt);
    memset(&T, 0, sizeof T);
    T.par = par;
    if (!BPT_CHECK(bp__tutte_fill(&al, &T, ch, &m) && bp__tutte_adjacency(&al, &T) &&
                   bp__conformal_begin(&al, &T, ch, &m, NULL, 1, &C) == 1, "%s: the conformal system set up", path)) {
        bp__tutte_free(&al, &T); bp_atlas_free(&atlas); bp_mesh_free(&m, NULL);
        return;
    }
    nv = C.L.n;
    BPT_CHECK(C.J.scalar == planned && (C.K.row == NULL) == planned,
              "%s: the columns' pass fills %s (scalar %d, K %s)", path, planned ? "L alone" : "K", C.J.scalar,
              C.K.row ? "allocated" : "not allocated");
    bp__serial_for(NULL, bp__conformal_task_run, &C.J, C.J.nc);
    if (planned) {
        lv = (double *)malloc(((size_t)C.L.colp[nv] + 1) * sizeof(double));
        xy = (double *)malloc(((size_t)C.L.colp[nv] + 1) * sizeof(double));
        rhs = (double *)malloc(2 * (size_t)nv * sizeof(double));
        memcpy(lv, C.L.val, C.L.colp[nv] * sizeof(double));
        memcpy(rhs, C.buf, 2 * (size_t)nv * sizeof(double));
        for (v = 0; v < nv; v++)
            if (C.bxp[v] != BP__NONE)
                for (i = 0; i < C.L.colp[v + 1] - C.L.colp[v]; i++) xy[C.L.colp[v] + i] = C.bxy[C.bxp[v] + i];
        if (BPT_CHECK(bp__conformal_full(&al, &C, &par) && C.K.row, "%s: K built after all", path)) {
            for (v = 0; v < nv; v++) {
                uint32_t c0 = C.K.colp[2 * v], c1 = C.K.colp[2 * v + 1], len = C.L.colp[v + 1] - C.L.colp[v];
                for (i = 0; i < len; i++) {
                    uint32_t p = C.L.colp[v] + i;
                    nl++;
                    if (C.K.row[c0 + 2 * i] != 2 * C.L.row[p] || memcmp(&C.K.val[c0 + 2 * i], &lv[p], sizeof(double)))
                        bad_l++;
                    if (C.bxp[v] == BP__NONE) continue;
                    nxy++;
                    if (memcmp(&C.K.val[c1 + 2 * i], &xy[p], sizeof(double))) bad_xy++;
                }
            }
            for (i = 0; i < 2 * nv; i++) bad_rhs += memcmp(&rhs[i], &C.buf[i], sizeof(double)) != 0;
            BPT_CHECK(bad_l == 0 && bad_xy == 0 && bad_rhs == 0 && nxy > 0,
                      "%s: L is K's xx entries bit for bit (%u of %u differ), the kept xy entries K's (%u of %u), "
                      "the right-hand side the same (%u of %u)", path, bad_l, nl, bad_xy, nxy, bad_rhs, 2 * nv);
        }
    }
    free(lv); free(xy); free(rhs);
    bp__conformal_free(&al, &C);
    bp__tutte_free(&al, &T);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

/* ---- (e) ------------------------------------------------------------------ */

/* A tilted plane, not the uv plane. */
static void tilted(double x, double y, double *p) { p[0] = x; p[1] = 0.6 * y; p[2] = 0.3 * x + 0.8 * y; }

static void check_flat(void)
{
    bp_mesh m = grid_mesh(10, 10, 2, 0.1, 0.3, 0, 0, tilted);   /* with a hole */
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_options_init(&opt);
    opt.init = BP_INIT_CONFORMAL;
    opt.start = BP_START_PLAIN;
    if (BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "flat grid: one chart (%s)", err.message)) {
        if (BPT_CHECK(bp_chart_init(&atlas.charts[0], &m, &opt, &err) == BP_OK, "flat grid: start (%s)", err.message))
            BPT_CHECK(atlas.charts[0].start_map == BP_INIT_CONFORMAL &&
                      fabs(sd_energy(&m, &atlas.charts[0], atlas.charts[0].uv, 1) - 4) < 1e-9,
                      "flat grid, BP_START_PLAIN: the conformal map is a similarity (energy %.15g = 4)",
                      sd_energy(&m, &atlas.charts[0], atlas.charts[0].uv, 1));
        bp_atlas_free(&atlas);
    }
    bpt_mesh_free(&m);
}

/* bp__start_apart against brute force: the bump's chart (one loop of 80
   vertices) with its planar layout as the map, one boundary vertex moved
   to 2^-e mean boundary edges (e from 10 to 30) from another; the map's
   boundary vertices are apart unless some two of them lie within a box of
   half-side 2^-20 of the mean boundary edge, counted over every pair. */
static void check_start_apart(void)
{
    bp_mesh m = make_bump();
    bp_atlas atlas;
    bp_error err;
    bp_allocator a = bp__allocator_of(NULL);
    int trial, wrong = 0, near = 0, far = 0;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &m, NULL, &err) == BP_OK && atlas.num_charts == 1, "bump: one chart (%s)",
                   err.message)) {
        bpt_mesh_free(&m);
        return;
    }
    {
        bp_chart *ch = &atlas.charts[0];
        uint32_t nb = ch->loop_start[ch->num_loops], i, j;
        ch->uv = (double *)malloc(2 * (size_t)ch->num_vertices * sizeof(double));
        for (trial = 0; trial < 400; trial++) {
            uint32_t k1 = (uint32_t)(bpt_rng_u64() % nb), k2 = (uint32_t)(bpt_rng_u64() % nb);
            uint32_t u1 = ch->loop_vertices[k1], u2 = ch->loop_vertices[k2];
            double len = 0, tol, d, th = 6.283185307179586 * bpt_rng_unit();
            int found = 0, got;
            for (i = 0; i < ch->num_vertices; i++) {
                ch->uv[2 * i] = m.positions[3 * (size_t)ch->vertex[i]];
                ch->uv[2 * i + 1] = m.positions[3 * (size_t)ch->vertex[i] + 1];
            }
            d = ldexp(0.05, -(10 + (int)(bpt_rng_u64() % 21)));
            if (u1 != u2) { ch->uv[2 * u2] = ch->uv[2 * u1] + d * cos(th); ch->uv[2 * u2 + 1] = ch->uv[2 * u1 + 1] + d * sin(th); }
            for (i = 0; i < nb; i++) {
                uint32_t p = ch->loop_vertices[i], q = ch->loop_vertices[(i + 1) % nb];
                len += hypot(ch->uv[2 * p] - ch->uv[2 * q], ch->uv[2 * p + 1] - ch->uv[2 * q + 1]);
            }
            tol = ldexp(len / nb, -20);
            for (i = 0; i < nb; i++)
                for (j = i + 1; j < nb; j++) {
                    uint32_t p = ch->loop_vertices[i], q = ch->loop_vertices[j];
                    found |= p != q && fabs(ch->uv[2 * p] - ch->uv[2 * q]) < tol && fabs(ch->uv[2 * p + 1] - ch->uv[2 * q + 1]) < tol;
                }
            got = bp__start_apart(&a, ch);
            wrong += got != !found;
            near += found;
            far += !found;
        }
    }
    BPT_CHECK(wrong == 0 && near > 50 && far > 50,
              "start maps: two boundary vertices within 2^-20 of the mean boundary edge found as brute force finds "
              "them (%d wrong of 400; %d maps with such a pair, %d without)", wrong, near, far);
    bp_atlas_free(&atlas);
    bpt_mesh_free(&m);
}

int main(void)
{
    check_lscm("tests/data/face_holes.off", BP_INIT_AUTO);
    check_lscm("tests/data/bishop_part_f1000.obj", BP_INIT_AUTO);
    check_lscm("tests/data/camelhead.off", BP_INIT_CONFORMAL);
    check_schur("tests/data/camelhead.off", 1);
    check_schur("tests/data/bishop_part_f1000.obj", 1);
    check_schur("tests/data/face_holes.off", 2);
    check_scalar_pass("tests/data/camelhead.off", 1);
    check_scalar_pass("tests/data/bishop_part_f1000.obj", 1);
    check_scalar_pass("tests/data/face_holes.off", 0);
    check_start_map("tests/data/camel_b.obj", BP_INIT_AUTO, BP_INIT_MEAN_VALUE, "its conformal map folds");
    check_start_map("tests/data/camel_b.obj", BP_INIT_CONFORMAL, BP_INIT_MEAN_VALUE, "its conformal map folds");
    check_overlap();
    check_start_map("tests/data/face_holes.off", BP_INIT_MEAN_VALUE, BP_INIT_MEAN_VALUE, "asked for");
    check_start_map("tests/data/face_holes.off", BP_INIT_TUTTE, BP_INIT_TUTTE, "asked for");
    check_start_map("tests/data/face_holes.off", (bp_init)99, BP_INIT_CONFORMAL, "an unknown value acts as AUTO");
    check_start_map("tests/data/beetle.off", BP_INIT_AUTO, BP_INIT_MEAN_VALUE,
                    "above BP__CONFORMAL_MAX here, a long boundary");
    check_start_map("tests/data/beetle.off", BP_INIT_CONFORMAL, BP_INIT_CONFORMAL, "asked by name: any size");
    check_start_map("tests/data/camelhead.off", BP_INIT_AUTO, BP_INIT_CONFORMAL,
                    "above BP__CONFORMAL_MAX here, a short boundary: the Schur complement");
    check_schedules("tests/data/face_holes.off");
    check_flat();
    check_handoff();
    check_start_apart();
    return bpt_finish();
}
