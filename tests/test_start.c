/* test_start.c - the start maps of >>start.

   (a) Thin strips, a 1 x 1e-7 and a 1 x 1e-4 strip
       of 398 triangles (two rows of 200 vertices), flat in z = 0 and
       rotated into a general 3D plane, through bp_parameterize with the
       default options: the result passes bp_check and its area-weighted
       mean symmetric Dirichlet energy, computed here from the 3D triangles
       and the uvs (not by the library), is <= 4.01 (the isometry has 4).
       The 1e-4 strip also from the plain Tutte start (BP_START_PLAIN): the
       barrier width of thin charts alone lets it reach the isometry.
   (b) The barrier width: on the strips eps is at most the strip's width,
       and it is the median altitude 2 A / |e| onto the boundary edges
       computed here in 3D (also on a 1 x 1e-3 strip with every
       triangle's corners turned once and twice, so that the boundary
       edges lie in each place of their triangles);
       on every chart of the meshes of tests/data it is a quarter of the
       mean boundary edge exactly (the bound never acts there).
   (c) A planar chart (a rotated grid with a hole) starts from its own
       projection: bp_chart_init's map already has energy 4.
   (d) A nearly planar chart whose projection overlaps itself (a band
       wound 1.5 times around a helix of tiny pitch): the projection,
       computed here, fails bp_check, and the start map of bp_chart_init
       passes it (the projection was refused, Tutte used).
   (e) The progressive start (BP_START_PROGRESSIVE) on real meshes (camel_b,
       cow, and face_holes, whose 8,288 triangles run the parallel loops):
       the start map passes bp_check, has a lower mean energy than the plain
       Tutte start, and the same bits with 1 and 2 threads and with the
       parallel loops run backwards.  AUTO on these meshes gives the Tutte
       map itself (they are not planar): the same bits as PLAIN.
   (f) A crushed start enlarged (>>start, 4): a 16 x 16 grid whose top half
       the start map squeezes by 1e-5 (mean energy ~5e9, above
       BP__START_SCALE_E0), optimized by Newton: every accepted iterate
       passes bp_check (checked in the progress callback), the chart's
       energy_start is the start map's own energy computed here (not the
       enlarged map's), and the result is bijective with a mean energy
       (computed here) within 1e-3 of the isometry's 4.
   (g) The start's own exact check handed to the optimizer
       (bp__handoff.checked, which makes bp_chart_solve skip the second
       check): on camel_b, face_holes and camelhead (conformal by the
       Schur complement), with the default start, Tutte's and the
       mean-value map, the flag is set and the map passes bp_check here;
       after the progressive start, with a pin, and on the planar grid
       (its projection, not bp__tutte_map's) it is clear.  With
       BP_TEST_QUICK set (make test) camelhead's progressive start is left
       to make check. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include "bpt_grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NSTRIP 200

/* Independent energy: each 3D triangle in its own frame, J from the uvs,
   E = |J|_F^2 + |J^-1|_F^2; the area-weighted mean. */
static double mean_sd_energy(const bp_chart *ch, const bp_mesh *m, const double *uv)
{
    double sum = 0, area = 0;
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        const double *p0 = m->positions + 3 * (size_t)ch->vertex[tr[0]];
        const double *p1 = m->positions + 3 * (size_t)ch->vertex[tr[1]];
        const double *p2 = m->positions + 3 * (size_t)ch->vertex[tr[2]];
        double w, x, y, a = bpt_tri_frame(p0, p1, p2, &w, &x, &y), u1[2], u2[2], j00, j01, j10, j11, det, fro;
        int k;
        for (k = 0; k < 2; k++) {
            u1[k] = uv[2 * (size_t)tr[1] + k] - uv[2 * (size_t)tr[0] + k];
            u2[k] = uv[2 * (size_t)tr[2] + k] - uv[2 * (size_t)tr[0] + k];
        }
        /* J [w x; 0 y] = [u1 u2]  ->  J = [u1 u2] [1/w  -x/(w y); 0  1/y] */
        j00 = u1[0] / w; j10 = u1[1] / w;
        j01 = (u2[0] - x * j00) / y; j11 = (u2[1] - x * j10) / y;
        det = j00 * j11 - j01 * j10;
        fro = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11;
        sum += a * (fro + fro / (det * det));
        area += a;
    }
    return sum / area;
}

static int map_valid(const bp_chart *ch, const double *uv)
{
    bp_check_report rep;
    return bp_check(ch->triangles, ch->num_triangles, uv, ch->num_vertices, NULL, &rep, NULL) == BP_OK;
}

/* Two rows of NSTRIP vertices, 1 long and h wide; rot: turned into the
   plane through the origin spanned by two unit vectors in general position. */
static bp_mesh make_strip(double h, int rot)
{
    bp_mesh m = bpt_mesh_new(2 * NSTRIP, 2 * (NSTRIP - 1));
    const double a[3] = { 0.48, 0.6, 0.64 }, b0[3] = { -0.8, 0.6, 0 };
    double b[3], d = b0[0] * a[0] + b0[1] * a[1] + b0[2] * a[2], len;
    uint32_t i, r, k;
    for (k = 0; k < 3; k++) b[k] = b0[k] - d * a[k];
    len = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    for (k = 0; k < 3; k++) b[k] /= len;
    for (r = 0; r < 2; r++)
        for (i = 0; i < NSTRIP; i++) {
            double x = (double)i / (NSTRIP - 1), y = r * h, *p = m.positions + 3 * (size_t)(r * NSTRIP + i);
            if (!rot) { p[0] = x; p[1] = y; p[2] = 0; }
            else for (k = 0; k < 3; k++) p[k] = x * a[k] + y * b[k];
        }
    for (i = 0; i + 1 < NSTRIP; i++) {
        uint32_t *t = m.triangles + 6 * (size_t)i, v0 = i, v1 = i + 1, v2 = NSTRIP + i, v3 = NSTRIP + i + 1;
        t[0] = v0; t[1] = v1; t[2] = v3;
        t[3] = v0; t[4] = v3; t[5] = v2;
    }
    return m;
}

/* ---- (a), (b) ------------------------------------------------------------ */

static void check_strip(double h, int rot, bp_start start)
{
    bp_mesh m = make_strip(h, rot);
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_status st;
    memset(&opt, 0, sizeof opt);
    opt.start = start;
    st = bp_parameterize(&atlas, &m, &opt, &err);
    if (BPT_CHECK(st == BP_OK && atlas.num_charts == 1, "strip 1 x %g%s%s: parameterized (%s)", h, rot ? " (3D)" : "",
                  start == BP_START_PLAIN ? " from plain Tutte" : "", err.message)) {
        const bp_chart *ch = &atlas.charts[0];
        double e = mean_sd_energy(ch, &m, ch->uv);
        BPT_CHECK(map_valid(ch, ch->uv) && e <= 4.01, "strip 1 x %g%s%s: bijective (bp_check), mean energy %.9g <= 4.01 "
                  "(%d iterations, %s)", h, rot ? " (3D)" : "", start == BP_START_PLAIN ? " from plain Tutte" : "", e,
                  ch->iterations, bp_stop_string(ch->stop));
        bp_atlas_free(&atlas);
    }
    bpt_mesh_free(&m);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* eps of the optimizer's solver for chart c, and the mean boundary edge */
static double solver_eps(const bp_chart *ch, const bp_mesh *m, double *mean_edge)
{
    bp__solver S;
    bp_options o;
    bp_error err;
    double eps = -1;
    static const bp_allocator plain = { NULL, NULL, NULL };
    memset(&S, 0, sizeof S);
    memset(&o, 0, sizeof o);
    if (bp__solver_chart(&S, &plain, ch, m, &o, NULL, &err) == BP_OK) {
        eps = S.eps;
        *mean_edge = S.mean_edge;
        bp__solver_free(&S);
    }
    return eps;
}

static void check_strip_eps(double h, int turn)
{
    bp_mesh m = make_strip(h, 1);
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    double me = 0, eps;
    uint32_t i;
    for (i = 0; turn && i < m.num_triangles; i++) {     /* every triangle's corners turned: its edges in other places */
        uint32_t *t = m.triangles + 3 * (size_t)i, r, keep;
        for (r = 0; r < (uint32_t)turn; r++) { keep = t[0]; t[0] = t[1]; t[1] = t[2]; t[2] = keep; }
    }
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK, "strip atlas (%s)", err.message)) { bpt_mesh_free(&m); return; }
    eps = solver_eps(&atlas.charts[0], &m, &me);
    BPT_CHECK(eps > 0 && eps <= h * (1 + 1e-6) && eps < me / 4, "strip 1 x %g: barrier width %.3g <= the width (mean "
              "boundary edge / 4 = %.3g)", h, eps, me / 4);
    {   /* the median altitude onto the boundary edges, 2 A / |e| in 3D, by brute force */
        const bp_chart *ch = &atlas.charts[0];
        double *alt = (double *)malloc(3 * (size_t)ch->num_triangles * sizeof(double)), med;
        uint32_t t, c, L, k, n = 0;
        for (t = 0; t < ch->num_triangles; t++)
            for (c = 0; c < 3; c++) {
                uint32_t vi = ch->triangles[3 * t + c], vj = ch->triangles[3 * t + (c + 1) % 3];
                uint32_t vk = ch->triangles[3 * t + (c + 2) % 3];
                int on = 0;
                for (L = 0; L < ch->num_loops && !on; L++)
                    for (k = ch->loop_start[L]; k < ch->loop_start[L + 1] && !on; k++) {
                        uint32_t a0 = ch->loop_vertices[k];
                        uint32_t a1 = ch->loop_vertices[k + 1 < ch->loop_start[L + 1] ? k + 1 : ch->loop_start[L]];
                        on = (a0 == vi && a1 == vj) || (a0 == vj && a1 == vi);
                    }
                if (on) {
                    const double *p = m.positions + 3 * (size_t)ch->vertex[vi], *q = m.positions + 3 * (size_t)ch->vertex[vj];
                    const double *r = m.positions + 3 * (size_t)ch->vertex[vk];
                    double e[3], f[3], x[3];
                    int d;
                    for (d = 0; d < 3; d++) { e[d] = q[d] - p[d]; f[d] = r[d] - p[d]; }
                    x[0] = e[1] * f[2] - e[2] * f[1]; x[1] = e[2] * f[0] - e[0] * f[2]; x[2] = e[0] * f[1] - e[1] * f[0];
                    alt[n++] = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
                }
            }
        qsort(alt, n, sizeof(double), cmp_double);
        med = n ? alt[n / 2] : 0;
        BPT_CHECK(n > 0 && fabs(eps - med) <= 1e-9 * med, "strip 1 x %g%s: the barrier width %.12g is the median altitude "
                  "onto the %u boundary edges, %.12g by brute force", h, turn == 1 ? ", corners turned once" : turn == 2 ? ", corners turned twice" : "", eps, n, med);
        free(alt);
    }
    bp_atlas_free(&atlas);
    bpt_mesh_free(&m);
}

static void check_mesh_eps(const char *path)
{
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    uint32_t c, same = 0, n = 0;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &err) == BP_OK, "%s read (%s)", path, err.message)) return;
    if (bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK) {
        for (c = 0; c < atlas.num_charts; c++) {
            double me = 0, eps;
            if (atlas.charts[c].error.status != BP_OK) continue;
            eps = solver_eps(&atlas.charts[c], &m, &me);
            n++;
            same += eps == me / 4;
        }
        bp_atlas_free(&atlas);
    }
    BPT_CHECK(n > 0 && same == n, "%s: the barrier width is the mean boundary edge / 4 on %u of %u charts", path, same, n);
    bp_mesh_free(&m, NULL);
}

/* ---- (c), (d) ------------------------------------------------------------ */

/* A 10 x 10 grid with a hole in the tilted plane z = 0.3 x - 0.2 y
   (bpt_mesh_free it). */
static bp_mesh tilted_grid(void)
{
    double pos[3 * 121];
    uint32_t tri[3 * 200];
    bpt_gen g;
    bp_mesh m;
    uint32_t i;
    g.pos = pos; g.tri = tri; g.nv = 0; g.nt = 0;
    bpt_add_grid(&g, 10, 10, 2, 0.1, 0.3, 0, 0);
    m = bpt_mesh_new(g.nv, g.nt);
    for (i = 0; i < g.nv; i++) {
        m.positions[3 * i] = pos[3 * i];
        m.positions[3 * i + 1] = pos[3 * i + 1];
        m.positions[3 * i + 2] = 0.3 * pos[3 * i] - 0.2 * pos[3 * i + 1];
    }
    memcpy(m.triangles, tri, 3 * (size_t)g.nt * sizeof(uint32_t));
    return m;
}

static void check_planar_grid(void)
{
    bp_mesh m = tilted_grid();
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    memset(&opt, 0, sizeof opt);
    if (BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1 &&
                  atlas.charts[0].num_loops == 2, "tilted grid with a hole: one chart, two loops (%s)", err.message)) {
        int pass;
        for (pass = 0; pass < 3; pass++) {     /* default options, NULL options, BP_START_PLAIN */
            bp_status st;
            double e;
            opt.start = pass == 2 ? BP_START_PLAIN : BP_START_AUTO;
            opt.init = pass == 2 ? BP_INIT_MEAN_VALUE : BP_INIT_AUTO;   /* PLAIN: the barycentric map as asked */
            st = bp_chart_init(&atlas.charts[0], &m, pass == 1 ? NULL : &opt, &err);
            e = st == BP_OK ? mean_sd_energy(&atlas.charts[0], &m, atlas.charts[0].uv) : -1;
            if (pass < 2)
                BPT_CHECK(st == BP_OK && map_valid(&atlas.charts[0], atlas.charts[0].uv) && fabs(e - 4) < 1e-9,
                          "tilted planar grid (%s options): the start map is its own projection (bijective, energy "
                          "%.12g = 4)", pass ? "NULL" : "default", e);
            else
                BPT_CHECK(st == BP_OK && map_valid(&atlas.charts[0], atlas.charts[0].uv) && e > 4.01,
                          "tilted planar grid, BP_START_PLAIN, mean-value: the barycentric map (bijective, energy %.6g > 4)", e);
        }
        bp_atlas_free(&atlas);
    }
    bpt_mesh_free(&m);
}

static void check_helix(void)
{
    /* 1.5 turns of a band between radii 1 and 1.05, rising 1e-3 per turn */
    const int n = 120;
    bp_mesh m = bpt_mesh_new(2 * (uint32_t)n, 2 * (uint32_t)(n - 1));
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    int i, r;
    for (r = 0; r < 2; r++)
        for (i = 0; i < n; i++) {
            double th = 3 * 3.14159265358979323846 * i / (n - 1), rad = 1 + 0.05 * r;
            double *p = m.positions + 3 * (size_t)(r * n + i);
            p[0] = rad * cos(th); p[1] = rad * sin(th); p[2] = 1e-3 * th / (2 * 3.14159265358979323846);
        }
    for (i = 0; i + 1 < n; i++) {
        uint32_t *t = m.triangles + 6 * (size_t)i, v0 = (uint32_t)(n + i), v1 = (uint32_t)(n + i + 1), v2 = (uint32_t)i,
                 v3 = (uint32_t)(i + 1);   /* outer row first: counter-clockwise seen from +z */
        t[0] = v2; t[1] = v0; t[2] = v1;
        t[3] = v2; t[4] = v1; t[5] = v3;
    }
    memset(&opt, 0, sizeof opt);
    if (BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "helix band: one chart (%s)",
                  err.message)) {
        bp_chart *ch = &atlas.charts[0];
        double *proj = (double *)malloc(2 * (size_t)ch->num_vertices * sizeof(double));
        uint32_t v;
        bp_check_report rep;
        bp_status st;
        for (v = 0; v < ch->num_vertices; v++) {      /* the plane is z = const */
            proj[2 * v] = m.positions[3 * (size_t)ch->vertex[v]];
            proj[2 * v + 1] = m.positions[3 * (size_t)ch->vertex[v] + 1];
        }
        st = bp_check(ch->triangles, ch->num_triangles, proj, ch->num_vertices, NULL, &rep, NULL);
        BPT_CHECK(st != BP_OK && rep.flipped == 0 && rep.degenerate == 0 && rep.boundary_intersections > 0,
                  "helix band: its projection has positive triangles but overlaps itself (%u boundary intersections)",
                  rep.boundary_intersections);
        st = bp_chart_init(ch, &m, &opt, &err);
        BPT_CHECK(st == BP_OK && map_valid(ch, ch->uv), "helix band: the start map is bijective (%s)", err.message);
        free(proj);
        bp_atlas_free(&atlas);
    }
    bpt_mesh_free(&m);
}

/* ---- (e) ----------------------------------------------------------------- */

static void check_progressive(const char *path)
{
    bp_mesh m;
    bp_error err;
    double e_plain = 0, *plain = NULL, *prog = NULL;
    int variant;
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &err) == BP_OK, "%s read (%s)", path, err.message)) return;
    /* 0 plain; 1 progressive, 1 thread; 2 with 2 threads; 3 tasks backwards; 4 auto */
    for (variant = 0; variant < 5; variant++) {
        static const char *what[5] = { "plain", "progressive", "progressive, 2 threads", "progressive, backwards", "auto" };
        bp_atlas atlas;
        bp_options opt;
        bp_chart *ch;
        size_t bytes;
        memset(&opt, 0, sizeof opt);
        opt.init = BP_INIT_TUTTE;                /* the rounds relax a crushed Tutte start */
        opt.start = variant == 0 ? BP_START_PLAIN : variant == 4 ? BP_START_AUTO : BP_START_PROGRESSIVE;
        opt.threads = variant == 2 ? 2 : 1;
        if (variant == 3) opt.parallel_for = bpt_backwards_for;
        if (bp_atlas_build(&atlas, &m, &opt, &err) != BP_OK || atlas.num_charts != 1) {
            BPT_CHECK(0, "%s: one chart (%s)", path, err.message);
            break;
        }
        ch = &atlas.charts[0];
        bytes = 2 * (size_t)ch->num_vertices * sizeof(double);
        if (!BPT_CHECK(bp_chart_init(ch, &m, &opt, &err) == BP_OK && map_valid(ch, ch->uv), "%s: start map (%s) "
                       "bijective by bp_check (%s)", path, what[variant], err.message)) {
            bp_atlas_free(&atlas);
            break;
        }
        if (variant == 0) {
            plain = (double *)malloc(bytes);
            prog = (double *)malloc(bytes);
            memcpy(plain, ch->uv, bytes);
            e_plain = mean_sd_energy(ch, &m, ch->uv);
        } else if (variant == 1) {
            double e = mean_sd_energy(ch, &m, ch->uv);
            BPT_CHECK(e < e_plain, "%s: the progressive start has a lower mean energy than Tutte (%.6g < %.6g)", path, e,
                      e_plain);
            memcpy(prog, ch->uv, bytes);
        } else {
            BPT_CHECK(!memcmp(variant == 4 ? plain : prog, ch->uv, bytes), "%s: %s gives the same start map bits as %s",
                      path, what[variant], variant == 4 ? "plain (not planar)" : "progressive with 1 thread");
        }
        bp_atlas_free(&atlas);
    }
    free(plain);
    free(prog);
    bp_mesh_free(&m, NULL);
}

/* ---- (f) ------------------------------------------------------------------ */

typedef struct crushed_watch { const bp_chart *ch; int iterations, invalid; } crushed_watch;

static int crushed_progress(void *user, uint32_t chart, int iteration, double energy, double step)
{
    crushed_watch *w = (crushed_watch *)user;
    (void)chart; (void)iteration; (void)energy; (void)step;
    w->iterations++;
    if (!map_valid(w->ch, w->ch->uv)) w->invalid++;
    return 0;
}

static void check_crushed(void)
{
    enum { W = 16 };
    double pos[3 * (W + 1) * (W + 1)];
    uint32_t tri[3 * 2 * W * W];
    bpt_gen g;
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_chart *ch;
    crushed_watch w;
    double e0, e;
    uint32_t i;
    g.pos = pos; g.tri = tri; g.nv = g.nt = 0;
    bpt_add_grid(&g, W, W, 0, 1.0 / W, 0, 0, 0);
    memset(&m, 0, sizeof m);
    m.positions = pos; m.num_vertices = g.nv; m.triangles = tri; m.num_triangles = g.nt;
    memset(&opt, 0, sizeof opt);
    opt.direction = BP_DIRECTION_NEWTON;
    if (!BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "crushed grid: one chart (%s)",
                   err.message))
        return;
    ch = &atlas.charts[0];
    if (!BPT_CHECK(bp_chart_init(ch, &m, &opt, &err) == BP_OK, "crushed grid: start (%s)", err.message)) {
        bp_atlas_free(&atlas);
        return;
    }
    for (i = 0; i < ch->num_vertices; i++) {              /* the top half squeezed by 1e-5 */
        const double *p = pos + 3 * (size_t)ch->vertex[i];
        ch->uv[2 * (size_t)i] = p[0];
        ch->uv[2 * (size_t)i + 1] = p[1] <= 0.5 ? p[1] : 0.5 + (p[1] - 0.5) * 1e-5;
    }
    e0 = mean_sd_energy(ch, &m, ch->uv);
    BPT_CHECK(map_valid(ch, ch->uv) && e0 > 1e9, "crushed grid: the squeezed start is bijective, mean energy %.6g > 1e9", e0);
    w.ch = ch; w.iterations = 0; w.invalid = 0;
    opt.progress = crushed_progress;
    opt.progress_user = &w;
    if (BPT_CHECK(bp_chart_optimize(ch, 0, &m, &opt, &err) == BP_OK, "crushed grid: optimized (%s)", err.message)) {
        e = mean_sd_energy(ch, &m, ch->uv);
        BPT_CHECK(w.iterations > 0 && w.invalid == 0, "crushed grid: all %d accepted iterates pass bp_check (%d do not)",
                  w.iterations, w.invalid);
        BPT_CHECK(fabs(ch->energy_start - e0) <= 1e-9 * e0, "crushed grid: energy_start %.9g is the start map's %.9g",
                  ch->energy_start, e0);
        BPT_CHECK(map_valid(ch, ch->uv) && e <= 4.004, "crushed grid: bijective, mean energy %.9g <= 4.004 (%d iterations, %s)",
                  e, ch->iterations, bp_stop_string(ch->stop));
    }
    bp_atlas_free(&atlas);
}

static void check_handoff(const char *path, int progressive)
{
    bp_mesh m;
    bp_error err;
    bp_allocator a;                       /* the default one */
    int variant;
    memset(&a, 0, sizeof a);
    if (!BPT_CHECK(bp_read_mesh(path, &m, NULL, &err) == BP_OK, "%s read (%s)", path, err.message)) return;
    /* 0 default; 1 Tutte; 2 mean-value; 3 progressive; 4 a pin */
    for (variant = 0; variant < 5; variant++) {
        static const char *what[5] = { "default", "Tutte", "mean-value", "progressive", "a pin" };
        if (variant == 3 && !progressive) continue;
        bp_atlas atlas;
        bp_options opt;
        bp_pin pin;
        bp__handoff h;
        bp_status st;
        int want = variant < 3;
        memset(&opt, 0, sizeof opt);
        memset(&h, 0, sizeof h);
        opt.init = variant == 1 || variant == 3 ? BP_INIT_TUTTE : variant == 2 ? BP_INIT_MEAN_VALUE : BP_INIT_AUTO;
        opt.start = variant == 3 ? BP_START_PROGRESSIVE : BP_START_AUTO;
        if (variant == 4) {
            pin.vertex = m.triangles[0]; pin.uv = 0; pin.u = 0.25; pin.v = -0.5;
            opt.pins = &pin; opt.num_pins = 1;
        }
        if (bp_atlas_build(&atlas, &m, &opt, &err) != BP_OK || atlas.num_charts != 1) {
            BPT_CHECK(0, "%s: one chart (%s)", path, err.message);
            break;
        }
        st = bp__chart_start(&atlas.charts[0], &m, &opt, &h, &err);
        BPT_CHECK(st == BP_OK && h.checked == want && (!h.checked || map_valid(&atlas.charts[0], atlas.charts[0].uv)),
                  "%s, %s start: the start's exact check handed over %s (flag %d)%s", path, what[variant],
                  want ? "(and the map passes bp_check here)" : "not: the map changed after it", h.checked,
                  st == BP_OK ? "" : err.message);
        bp__handoff_free(&a, &h);
        bp_atlas_free(&atlas);
    }
    bp_mesh_free(&m, NULL);
}

/* (g) on the planar grid: its own projection, no hand-over. */
static void check_handoff_planar(void)
{
    bp_mesh m = tilted_grid();
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp__handoff h;
    bp_allocator a;
    memset(&a, 0, sizeof a);
    memset(&opt, 0, sizeof opt);
    memset(&h, 0, sizeof h);
    h.checked = 1;
    if (BPT_CHECK(bp_atlas_build(&atlas, &m, &opt, &err) == BP_OK && atlas.num_charts == 1, "grid: one chart")) {
        bp_status st = bp__chart_start(&atlas.charts[0], &m, &opt, &h, &err);
        BPT_CHECK(st == BP_OK && atlas.charts[0].start_map == BP_INIT_AUTO && h.checked == 0,
                  "tilted planar grid: its projection is the start, the start's check is not handed over (flag %d)",
                  h.checked);
        bp__handoff_free(&a, &h);
        bp_atlas_free(&atlas);
    }
    bpt_mesh_free(&m);
}

int main(void)
{
    int rot;
    for (rot = 0; rot < 2; rot++) {
        check_strip(1e-7, rot, BP_START_AUTO);
        check_strip(1e-4, rot, BP_START_AUTO);
    }
    check_strip(1e-4, 1, BP_START_PLAIN);
    check_strip_eps(1e-7, 0);
    check_strip_eps(1e-4, 0);
    check_strip_eps(1e-3, 0);
    check_strip_eps(1e-3, 1);
    check_strip_eps(1e-3, 2);
    check_mesh_eps("tests/data/camel_b.obj");
    check_mesh_eps("tests/data/cow_param_withSUV.obj");
    check_mesh_eps("tests/data/face_holes.off");
    check_mesh_eps("tests/data/mech-holes-shark.off");
    check_mesh_eps("tests/data/spot.obj");
    check_mesh_eps("tests/data/bishop_part_f1000.obj");
    check_planar_grid();
    check_helix();
    check_progressive("tests/data/camel_b.obj");
    check_progressive("tests/data/cow_param_withSUV.obj");
    check_progressive("tests/data/face_holes.off");
    check_crushed();
    check_handoff("tests/data/camel_b.obj", 1);
    check_handoff("tests/data/face_holes.off", 1);
    check_handoff("tests/data/camelhead.off", getenv("BP_TEST_QUICK") == NULL);   /* its progressive start: 10 s */
    check_handoff_planar();
    return bpt_finish();
}
