/* test_cut.c - automatic seams (>>cut): charts that are closed or have
   handles are cut into disks, and the result is flattened bijectively.

   Every property is proven by code written here, independently of the
   library's own bookkeeping:
     - the input's topology from its triangles alone: chi = V - E + F with
       E counted as distinct vertex pairs, boundary loops walked on the
       half-edges without a reverse twin, so genus and loop counts are
       known before the library sees the mesh (fertility: genus 4 closed;
       torus_with_holes: genus 1, 2 loops; the cow without vt, polyhedra:
       closed genus 0; a torus built here: genus 1);
     - after bp_atlas_build, each chart's topology the same way on its
       chart vertices: chi = 2 - b with b >= 1 (a disk, or a disk with
       holes), b equal to chart.num_loops, and the chart consistent with the
       mesh (every chart triangle on the mesh triangle's vertices, the
       atlas's corner_vertex naming the chart's corners);
     - chart.cut_edges equals the number of mesh edges between two
       triangles of the chart that the chart no longer glues (on meshes
       without vt, every such edge is an automatic seam), and is 0 where a
       chart needed no cut (spot.obj with its 13 vt charts; a torus with a
       vt seam that makes it an annulus);
     - after bp_parameterize, a brute-force bijectivity check of the packed
       atlas: every triangle positive (exact orient2d), no two boundary
       edges of any charts meeting except consecutive ones at their shared
       vertex (exact segment test; all pairs), exactly one positive
       (counter-clockwise) loop per chart, and no chart inside another;
     - several closed components in one mesh are each cut into their own
       disk and packed without overlap;
     - importance steers the seams: painted importance (25 on one half of
       the cow) and front-view visibility both lower the mean importance /
       visibility along the cut compared with the plain cut;
     - BP_CUT_NONE keeps the rejection (BP_ERR_TOPOLOGY naming the chart,
       the genus in the message);
     - the cut does not depend on the thread count (1 vs 2 threads: the
       same charts, bit for bit the same map);
     - junction moves (bp__cut_smooth, white box): a tree cut made here by
       edge count on the closed cow gets strictly shorter in 3D and stays
       a tree between the same three far vertices.
   Times and mean symmetric Dirichlet energies are printed (not asserted). */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#define BP_USE_PTHREADS
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* ---- topology of a triangle set, from scratch ---------------------------- */

typedef struct topo { long long v, e, f, chi, loops, boundary_edges; int ok; } topo;

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int has_u64(const uint64_t *s, size_t n, uint64_t k)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (s[mid] < k) lo = mid + 1; else hi = mid;
    }
    return lo < n && s[lo] == k;
}

/* Topology of nt triangles on vertices [0, nv) (only used vertices count).
   next_out (nv entries, may be NULL) receives the end of the boundary
   half-edge leaving each vertex (UINT32_MAX if none). */
static topo topology(const uint32_t *tri, uint32_t nt, uint32_t nv, uint32_t *next_out)
{
    topo r;
    size_t n = 3 * (size_t)nt, i, k;
    uint64_t *he = (uint64_t *)malloc(n * sizeof *he), *un = (uint64_t *)malloc(n * sizeof *un);
    uint32_t *next = (uint32_t *)malloc((nv + 1) * sizeof *next);
    unsigned char *used = (unsigned char *)calloc(nv + 1, 1), *seen = (unsigned char *)calloc(nv + 1, 1);
    memset(&r, 0, sizeof r);
    r.ok = 1;
    for (i = 0; i < nv; i++) next[i] = UINT32_MAX;
    for (i = 0; i < nt; i++)
        for (k = 0; k < 3; k++) {
            uint64_t a = tri[3 * i + k], b = tri[3 * i + (k + 1) % 3];
            he[3 * i + k] = a << 32 | b;
            un[3 * i + k] = a < b ? a << 32 | b : b << 32 | a;
            used[a] = 1;
        }
    qsort(he, n, sizeof *he, cmp_u64);
    qsort(un, n, sizeof *un, cmp_u64);
    for (i = 0; i < n; i++) if (i == 0 || un[i] != un[i - 1]) r.e++;
    for (i = 0; i < nv; i++) r.v += used[i];
    r.f = nt;
    r.chi = r.v - r.e + r.f;
    for (i = 0; i < n; i++) {
        uint32_t a = (uint32_t)(he[i] >> 32), b = (uint32_t)he[i];
        if (i > 0 && he[i] == he[i - 1]) r.ok = 0;                 /* repeated half-edge */
        if (has_u64(he, n, (uint64_t)b << 32 | a)) continue;
        r.boundary_edges++;
        if (next[a] != UINT32_MAX) r.ok = 0;                        /* two boundary edges leave a */
        next[a] = b;
    }
    for (i = 0; i < nv; i++) {
        uint32_t w = (uint32_t)i, steps = 0;
        if (next[i] == UINT32_MAX || seen[i]) continue;
        do { seen[w] = 1; w = next[w]; steps++; } while (w != UINT32_MAX && w != i && !seen[w] && steps <= nv);
        if (w != i) r.ok = 0;
        r.loops++;
    }
    if (next_out) memcpy(next_out, next, nv * sizeof *next);
    free(he); free(un); free(next); free(used); free(seen);
    return r;
}

/* ---- meshes built here ---------------------------------------------------- */

/* The convex hull of points given as a triangle list: every triple whose
   plane has all the other points strictly on one side, oriented outward.
   (For the regular polyhedra below every face is a triangle.) */
static bp_mesh hull(const double *p, uint32_t n)
{
    uint32_t i, j, k, l, nt = 0;
    bp_mesh m = bpt_mesh_new(n, 2 * n);
    memcpy(m.positions, p, 3 * n * sizeof(double));
    for (i = 0; i < n; i++)
        for (j = i + 1; j < n; j++)
            for (k = j + 1; k < n; k++) {
                double u[3], v[3], nn[3];
                int pos = 0, neg = 0, d;
                for (d = 0; d < 3; d++) { u[d] = p[3 * j + d] - p[3 * i + d]; v[d] = p[3 * k + d] - p[3 * i + d]; }
                nn[0] = u[1] * v[2] - u[2] * v[1]; nn[1] = u[2] * v[0] - u[0] * v[2]; nn[2] = u[0] * v[1] - u[1] * v[0];
                for (l = 0; l < n; l++) {
                    double s = 0;
                    if (l == i || l == j || l == k) continue;
                    for (d = 0; d < 3; d++) s += nn[d] * (p[3 * l + d] - p[3 * i + d]);
                    if (s > 1e-9) pos++; else if (s < -1e-9) neg++; else pos = neg = 1;
                }
                if (pos && neg) continue;
                m.triangles[3 * nt] = i;
                m.triangles[3 * nt + 1] = pos ? k : j;             /* the others behind: outward */
                m.triangles[3 * nt + 2] = pos ? j : k;
                nt++;
            }
    m.num_triangles = m.num_faces = nt;
    return m;
}

static bp_mesh tetrahedron(void)
{
    static const double p[] = { 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1 };
    return hull(p, 4);
}

static bp_mesh icosahedron(void)
{
    const double f = (1 + sqrt(5.0)) / 2;
    double p[36];
    int i, s1, s2, w = 0;
    for (i = 0; i < 3; i++)
        for (s1 = -1; s1 <= 1; s1 += 2)
            for (s2 = -1; s2 <= 1; s2 += 2) {     /* cyclic permutations of (0, +-1, +-f) */
                double q[3];
                q[i] = 0; q[(i + 1) % 3] = s1; q[(i + 2) % 3] = s2 * f;
                memcpy(p + 3 * w++, q, sizeof q);
            }
    return hull(p, 12);
}

/* A torus of n x k quads (two triangles each), radii 3 and 1.  With
   seam != 0 it carries vt indices that cut it along theta = 0 (an annulus). */
static bp_mesh torus(uint32_t n, uint32_t k, int seam)
{
    bp_mesh m = bpt_mesh_new(n * k, 2 * n * k);
    uint32_t i, j, t = 0;
    for (i = 0; i < n; i++)
        for (j = 0; j < k; j++) {
            double th = 6.283185307179586 * i / n, ph = 6.283185307179586 * j / k;
            double *q = m.positions + 3 * (i * k + j);
            q[0] = (3 + cos(ph)) * cos(th); q[1] = (3 + cos(ph)) * sin(th); q[2] = sin(ph);
        }
    if (seam) {
        m.corner_uv = (uint32_t *)malloc(6 * (size_t)n * k * sizeof(uint32_t));
        m.num_uvs = (n + 1) * k;
        m.uvs = (double *)calloc(2 * (size_t)m.num_uvs, sizeof(double));
    }
    for (i = 0; i < n; i++)
        for (j = 0; j < k; j++) {
            uint32_t i1 = (i + 1) % n, j1 = (j + 1) % k;
            uint32_t a = i * k + j, b = i1 * k + j, c = i1 * k + j1, d = i * k + j1;
            uint32_t ua = i * k + j, ub = (i + 1) * k + j, uc = (i + 1) * k + j1, ud = i * k + j1;
            uint32_t v6[6] = { a, b, c, a, c, d }, u6[6] = { ua, ub, uc, ua, uc, ud };
            memcpy(m.triangles + 3 * t, v6, sizeof v6);
            if (seam) memcpy(m.corner_uv + 3 * t, u6, sizeof u6);
            t += 2;
        }
    return m;
}

/* ---- checks ----------------------------------------------------------------- */

/* Every chart of a built atlas: a disk (with holes) by its own topology,
   num_loops right, consistent with the mesh; cut_edges equal to the mesh
   edges inside the chart that it does not glue, minus vt seams.  Returns
   the total of cut_edges. */
static long long check_charts(const char *what, const bp_mesh *m, const bp_atlas *at)
{
    uint32_t c, t, k;
    long long total = 0;
    int topo_ok = 1, consistent = 1, counted = 1;
    char why[200] = "";
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        topo r = topology(ch->triangles, ch->num_triangles, ch->num_vertices, NULL);
        long long seams = 0;
        if (!(r.ok && r.v == ch->num_vertices && r.loops >= 1 && r.chi == 2 - r.loops &&
              r.loops == (long long)ch->num_loops && ch->error.status == BP_OK)) {
            if (topo_ok) sprintf(why, "chart %u: chi %lld, %lld loops (chart says %u), status %s", c, r.chi, r.loops,
                                 ch->num_loops, bp_status_string(ch->error.status));
            topo_ok = 0;
        }
        for (t = 0; t < ch->num_triangles; t++)
            for (k = 0; k < 3; k++) {
                uint32_t mt = ch->face[t], cv = ch->triangles[3 * t + k];
                if (ch->vertex[cv] != m->triangles[3 * mt + k] || at->corner_chart[3 * mt + k] != c ||
                    at->corner_vertex[3 * mt + k] != cv)
                    consistent = 0;
            }
        /* edges of the mesh between two triangles of this chart, as mesh
           vertex pairs, against the chart's own edges */
        {
            size_t n = 3 * (size_t)ch->num_triangles, i, j;
            uint64_t *ce = (uint64_t *)malloc(n * sizeof *ce);
            for (t = 0; t < ch->num_triangles; t++)
                for (k = 0; k < 3; k++) {
                    uint64_t a = ch->triangles[3 * t + k], b = ch->triangles[3 * t + (k + 1) % 3];
                    ce[3 * t + k] = a << 32 | b;
                }
            qsort(ce, n, sizeof *ce, cmp_u64);
            /* a half-edge whose chart reverse is missing but whose mesh
               reverse lies in this chart: an edge the chart does not glue */
            for (i = 0; i < n; i++) {
                uint32_t a = (uint32_t)(ce[i] >> 32), b = (uint32_t)ce[i];
                int mesh_twin = 0, uv_seam = 0;
                if (has_u64(ce, n, (uint64_t)b << 32 | a)) continue;
                for (j = 0; j < n && !mesh_twin; j++) {
                    uint32_t tt = (uint32_t)(j / 3), kk = (uint32_t)(j % 3);
                    uint32_t x = ch->triangles[3 * tt + kk], y = ch->triangles[3 * tt + (kk + 1) % 3];
                    if (ch->vertex[x] == ch->vertex[b] && ch->vertex[y] == ch->vertex[a]) {
                        mesh_twin = 1;
                        uv_seam = ch->vertex_uv[x] != ch->vertex_uv[b] || ch->vertex_uv[y] != ch->vertex_uv[a];
                    }
                }
                if (mesh_twin && !uv_seam) seams++;           /* counted from both sides */
            }
            free(ce);
        }
        if (seams != 2 * (long long)ch->cut_edges) {
            if (counted) fprintf(stdout, "     %s chart %u: %lld unglued half-edges, cut_edges %u\n", what, c, seams,
                                 ch->cut_edges);
            counted = 0;
        }
        total += ch->cut_edges;
    }
    BPT_CHECK(topo_ok, "%s: every chart is a disk or a disk with holes by its own V - E + F and loops %s", what, why);
    BPT_CHECK(consistent, "%s: chart triangles lie on their mesh triangles' vertices, corner maps agree", what);
    BPT_CHECK(counted, "%s: cut_edges = the chart's unglued interior mesh edges that are no vt seam", what);
    return total;
}

/* Brute-force bijectivity of the packed atlas (see the header comment). */
typedef struct bseg { double a[2], b[2], lo[2], hi[2]; uint32_t chart, va, vb; } bseg;

static int atlas_bijective(const bp_atlas *at, char *why)
{
    uint32_t c, t, k, nseg = 0, cap = 0, i, j;
    bseg *s = NULL;
    for (c = 0; c < at->num_charts; c++) cap += 3 * at->charts[c].num_triangles;
    s = (bseg *)malloc((cap + 1) * sizeof *s);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        uint32_t *next = (uint32_t *)malloc((ch->num_vertices + 1) * sizeof *next);
        unsigned char *seen;
        int positive = 0;
        topo r;
        if (!ch->uv) { sprintf(why, "chart %u has no map", c); free(next); free(s); return 0; }
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *v = ch->triangles + 3 * t;
            if (bp_orient2d(ch->uv + 2 * v[0], ch->uv + 2 * v[1], ch->uv + 2 * v[2]) <= 0) {
                sprintf(why, "chart %u triangle %u is not positive", c, t);
                free(next); free(s);
                return 0;
            }
        }
        r = topology(ch->triangles, ch->num_triangles, ch->num_vertices, next);
        (void)r;
        seen = (unsigned char *)calloc(ch->num_vertices + 1, 1);
        for (i = 0; i < ch->num_vertices; i++) {
            double area = 0;
            uint32_t w = i;
            if (next[i] == UINT32_MAX || seen[i]) continue;
            do {
                const double *p = ch->uv + 2 * w, *q = ch->uv + 2 * next[w];
                bseg *g = &s[nseg++];
                memcpy(g->a, p, sizeof g->a); memcpy(g->b, q, sizeof g->b);
                for (k = 0; k < 2; k++) { g->lo[k] = p[k] < q[k] ? p[k] : q[k]; g->hi[k] = p[k] < q[k] ? q[k] : p[k]; }
                g->chart = c; g->va = w; g->vb = next[w];
                area += p[0] * q[1] - p[1] * q[0];
                seen[w] = 1;
                w = next[w];
            } while (w != i);
            positive += area > 0;
        }
        free(seen);
        free(next);
        if (positive != 1) { sprintf(why, "chart %u has %d counter-clockwise loops", c, positive); free(s); return 0; }
    }
    for (i = 0; i < nseg; i++)
        for (j = i + 1; j < nseg; j++) {
            const bseg *x = &s[i], *y = &s[j];
            if (x->hi[0] < y->lo[0] || y->hi[0] < x->lo[0] || x->hi[1] < y->lo[1] || y->hi[1] < x->lo[1]) continue;
            if (x->chart == y->chart && (x->vb == y->va || y->vb == x->va)) {
                /* consecutive: they may only share the common vertex */
                const double *o = x->vb == y->va ? x->b : x->a, *p = x->vb == y->va ? x->a : x->b,
                             *q = x->vb == y->va ? y->b : y->a;
                if (bp_orient2d(o, p, q) == 0 && (p[0] - o[0]) * (q[0] - o[0]) + (p[1] - o[1]) * (q[1] - o[1]) > 0) {
                    sprintf(why, "chart %u: boundary folds back at vertex %u", x->chart, x->vb == y->va ? x->vb : x->va);
                    free(s);
                    return 0;
                }
                continue;
            }
            if (bp_segments_intersect(x->a, x->b, y->a, y->b)) {
                sprintf(why, "boundary edges of charts %u and %u meet", x->chart, y->chart);
                free(s);
                return 0;
            }
        }
    /* no chart inside another: a vertex of each against every other's
       boundary (even-odd crossing count) */
    for (c = 0; c < at->num_charts; c++) {
        const double *p = at->charts[c].uv;
        uint32_t d;
        for (d = 0; d < at->num_charts; d++) {
            int inside = 0;
            if (d == c) continue;
            for (i = 0; i < nseg; i++) {
                const bseg *g = &s[i];
                if (g->chart != d || (g->a[1] > p[1]) == (g->b[1] > p[1])) continue;
                if (p[0] < g->a[0] + (p[1] - g->a[1]) * (g->b[0] - g->a[0]) / (g->b[1] - g->a[1])) inside ^= 1;
            }
            if (inside) { sprintf(why, "chart %u lies inside chart %u", c, d); free(s); return 0; }
        }
    }
    free(s);
    return 1;
}

/* Build, check the charts, parameterize with 2 threads, check the map;
   prints time and mean symmetric Dirichlet energy. */
static void run_iters(const char *what, const bp_mesh *m, long long want_cut_min, long long want_cut_max, int iters)
{
    bp_atlas at;
    bp_error err;
    bp_options o;
    bp_status st;
    double t0, sec, e = 0, area = 0;
    long long cut;
    uint32_t c;
    char why[200] = "";
    memset(&o, 0, sizeof o);
    o.threads = 2;
    o.max_iterations = iters;          /* the map is bijective at every iteration */
    st = bp_atlas_build(&at, m, &o, &err);
    if (!BPT_CHECK(st == BP_OK, "%s: bp_atlas_build with the default cut: %s (%s)", what, bp_status_string(st),
                   st ? err.message : ""))
        return;
    cut = check_charts(what, m, &at);
    BPT_CHECK(cut >= want_cut_min && cut <= want_cut_max, "%s: %lld edges cut (expected %lld..%lld)", what, cut,
              want_cut_min, want_cut_max);
    bp_atlas_free(&at);
    t0 = now();
    st = bp_parameterize(&at, m, &o, &err);
    sec = now() - t0;
    if (!BPT_CHECK(st == BP_OK, "%s: bp_parameterize: %s (%s)", what, bp_status_string(st), st ? err.message : ""))
        return;
    for (c = 0; c < at.num_charts; c++) { e += at.charts[c].energy_end * at.charts[c].area3d; area += at.charts[c].area3d; }
    BPT_CHECK(atlas_bijective(&at, why), "%s: the packed atlas is bijective by brute force (%u charts) %s", what,
              at.num_charts, why);
    printf("     %s: %u triangles, %lld edges cut, %.2f s (cut + flatten + pack, 2 threads%s), mean symmetric "
           "Dirichlet %.4f\n", what, m->num_triangles, cut, sec, iters ? ", iterations capped" : "", e / area);
    bp_atlas_free(&at);
}

static void run(const char *what, const bp_mesh *m, long long want_cut_min, long long want_cut_max)
{
    run_iters(what, m, want_cut_min, want_cut_max, 0);
}

/* The input's own topology, proven here. */
static void expect_input(const char *what, const bp_mesh *m, long long genus, long long loops)
{
    topo r = topology(m->triangles, m->num_triangles, m->num_vertices, NULL);
    BPT_CHECK(r.ok && r.loops == loops && r.chi == 2 - 2 * genus - loops,
              "%s input: chi %lld, %lld boundary loops: genus %lld (expected genus %lld, %lld loops)", what, r.chi,
              r.loops, (2 - r.loops - r.chi) / 2, genus, loops);
}

static void expect_rejected(const char *what, const bp_mesh *m, long long genus)
{
    bp_atlas at;
    bp_error err;
    bp_options o;
    bp_status st;
    char g[32];
    memset(&o, 0, sizeof o);
    o.cut = BP_CUT_NONE;
    st = bp_parameterize(&at, m, &o, &err);
    sprintf(g, genus ? "genus %lld" : "closed", genus);
    BPT_CHECK(st == BP_ERR_TOPOLOGY && err.element == BP_ELEMENT_CHART && err.index == 0 && strstr(err.message, g) &&
                  at.charts == NULL,
              "%s, BP_CUT_NONE: rejected (BP_ERR_TOPOLOGY, chart 0, says '%s'): %s \"%s\"", what, g,
              bp_status_string(st), err.message);
    bp_atlas_free(&at);
}

/* 1 and 2 threads: the same cut and bit for bit the same map. */
static void determinism(const char *what, const bp_mesh *m)
{
    bp_atlas a1, a2;
    bp_error err;
    bp_options o;
    int same = 1;
    uint32_t c;
    memset(&o, 0, sizeof o);
    o.max_iterations = 30;
    o.threads = 1;
    if (bp_parameterize(&a1, m, &o, &err) != BP_OK) { BPT_CHECK(0, "%s: 1 thread: %s", what, err.message); return; }
    o.threads = 2;
    if (bp_parameterize(&a2, m, &o, &err) != BP_OK) {
        BPT_CHECK(0, "%s: 2 threads: %s", what, err.message);
        bp_atlas_free(&a1);
        return;
    }
    same = a1.num_charts == a2.num_charts;
    for (c = 0; same && c < a1.num_charts; c++) {
        const bp_chart *x = &a1.charts[c], *y = &a2.charts[c];
        same = x->num_vertices == y->num_vertices && x->cut_edges == y->cut_edges &&
               !memcmp(x->triangles, y->triangles, 3 * (size_t)x->num_triangles * sizeof(uint32_t)) &&
               !memcmp(x->uv, y->uv, 2 * (size_t)x->num_vertices * sizeof(double));
    }
    BPT_CHECK(same, "%s: 1 and 2 threads give the same cut and the same map bit for bit", what);
    bp_atlas_free(&a1);
    bp_atlas_free(&a2);
}

/* The length-weighted mean of w (per mesh triangle) along the automatic
   seams of an atlas built without vt: every chart half-edge without a chart
   twin whose mesh twin exists (found by brute force on mesh vertex pairs)
   is one side of a cut edge. */
static double mean_along_cut(const bp_mesh *m, const bp_atlas *at, const double *w, double *length)
{
    uint32_t c, t, k, nt = m->num_triangles;
    size_t n = 3 * (size_t)nt, i;
    uint64_t *mh = (uint64_t *)malloc(n * sizeof *mh);
    double num = 0, den = 0;
    for (i = 0; i < n; i++) {
        uint64_t a = m->triangles[i], b = m->triangles[i - i % 3 + (i % 3 + 1) % 3];
        mh[i] = a << 32 | b;
    }
    qsort(mh, n, sizeof *mh, cmp_u64);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        size_t cn = 3 * (size_t)ch->num_triangles;
        uint64_t *h = (uint64_t *)malloc(cn * sizeof *h);
        for (i = 0; i < cn; i++) h[i] = (uint64_t)ch->triangles[i] << 32 | ch->triangles[i - i % 3 + (i % 3 + 1) % 3];
        qsort(h, cn, sizeof *h, cmp_u64);
        for (t = 0; t < ch->num_triangles; t++)
            for (k = 0; k < 3; k++) {
                uint32_t a = ch->triangles[3 * t + k], b = ch->triangles[3 * t + (k + 1) % 3], s2;
                uint64_t ma = ch->vertex[a], mb = ch->vertex[b];
                const double *p = m->positions + 3 * ma, *q = m->positions + 3 * mb;
                double len = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
                if (has_u64(h, cn, (uint64_t)b << 32 | a) || !has_u64(mh, n, mb << 32 | ma)) continue;
                /* the other triangle: the mesh triangle holding half-edge mb -> ma */
                for (s2 = 0; s2 < nt; s2++) {
                    const uint32_t *v = m->triangles + 3 * s2;
                    if ((v[0] == mb && v[1] == ma) || (v[1] == mb && v[2] == ma) || (v[2] == mb && v[0] == ma)) break;
                }
                num += len * 0.5 * (w[ch->face[t]] + w[s2]);
                den += len;
            }
        free(h);
    }
    free(mh);
    *length = den / 2;
    return den > 0 ? num / den : 0;
}

/* Seams prefer low importance: the cow without vt with importance 25 on the
   triangles above the middle of its bounding box in x (1 elsewhere) puts
   less of its cut there than with uniform importance; with a front view
   model, bp_parameterize's seams go where visibility (bp_visibility) is
   lower than where the plain cut runs, and the atlas is valid. */
static void test_importance(const bp_mesh *m)
{
    bp_atlas at;
    bp_error err;
    bp_options o;
    double *w = bpt_half_importance(m), len0, len1, plain, steered;
    char why[200] = "";
    memset(&o, 0, sizeof o);
    if (bp_atlas_build(&at, m, &o, &err) != BP_OK) { BPT_CHECK(0, "importance: build %s", err.message); free(w); return; }
    plain = mean_along_cut(m, &at, w, &len0);
    bp_atlas_free(&at);
    o.importance = w;
    if (bp_atlas_build(&at, m, &o, &err) != BP_OK) { BPT_CHECK(0, "importance: build %s", err.message); free(w); return; }
    check_charts("cow without vt, painted importance", m, &at);
    steered = mean_along_cut(m, &at, w, &len1);
    BPT_CHECK(steered < plain, "painted importance (25 on one half, 1 on the other): mean importance along the cut "
              "%.2f < %.2f without it (cut length %.3g vs %.3g)", steered, plain, len1, len0);
    bp_atlas_free(&at);
    /* visibility */
    memset(&o, 0, sizeof o);
    o.views.model = BP_VIEW_FRONT;
    o.views.samples = 16;
    o.max_iterations = 20;
    o.threads = 2;
    if (BPT_CHECK(bp_visibility(m, &o, w, &err) == BP_OK, "visibility of the cow (front, 16 samples)")) {
        bp_options b;
        memset(&b, 0, sizeof b);
        bp_atlas_build(&at, m, &b, &err);
        plain = mean_along_cut(m, &at, w, &len0);
        bp_atlas_free(&at);
        if (BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_OK, "bp_parameterize with front views: %s",
                      err.message)) {
            steered = mean_along_cut(m, &at, w, &len1);
            BPT_CHECK(steered < plain, "front views: mean visibility along the seams %.3f < %.3f of the plain cut "
                      "(length %.3g vs %.3g)", steered, plain, len1, len0);
            BPT_CHECK(atlas_bijective(&at, why), "front views: the packed atlas is bijective by brute force %s", why);
            bp_atlas_free(&at);
        }
    }
    free(w);
}


/* ---- junction moves (bp__cut_smooth), white box ---------------------------

   On the closed cow (genus 0, one chart built with BP_CUT_NONE), a cut is
   made here as a tree: the paths from vertex 0 to three far-apart vertices
   A0, A1, A2 in a shortest-path tree by *edge count* (not length), so its
   junctions are in poor places and its pieces are not shortest in 3D.
   bp__cut_smooth must then move at least one junction, make the cut
   strictly shorter in 3D, and leave a tree (connected, edges = vertices -
   1, counted here) whose leaves are among A0, A1, A2 and which still
   reaches all three: a tree cut opens a sphere into a disk. */
typedef struct ekey { uint32_t lo, hi, ce; } ekey;
static int ekey_cmp(const void *pa, const void *pb)
{
    const ekey *a = (const ekey *)pa, *b = (const ekey *)pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->ce > b->ce) - (a->ce < b->ce);
}

static uint32_t uf_root(uint32_t *p, uint32_t x) { while (p[x] != x) x = p[x] = p[p[x]]; return x; }

static void test_junction_moves(const bp_mesh *m)
{
    bp_atlas at;
    bp_error err;
    bp_options o;
    bp_allocator a;
    bp__cut K;
    const bp_chart *ch;
    uint32_t nt, nv, big, i, ce, A[3], moved, *glued, *deg, *uf, nedge = 0, nvert = 0, comps = 0, leaves_ok = 1, reach = 0;
    double *ones, before = 0, after = 0;
    ekey *ek;
    unsigned char *src;
    memset(&o, 0, sizeof o);
    o.cut = BP_CUT_NONE;
    o.threads = 1;
    {   /* the cow and one open triangle: the triangle's chart keeps the atlas
           (BP_ERR_CHARTS_FAILED) while the cow's stays closed and uncut */
        bp_mesh tri = bpt_mesh_new(3, 1), both;
        tri.positions[3] = 1; tri.positions[7] = 1;
        tri.triangles[0] = 0; tri.triangles[1] = 1; tri.triangles[2] = 2;
        tri.num_vertices = 3; tri.num_triangles = tri.num_faces = 1;
        both = bpt_concat(m, &tri, 1000);
        bpt_mesh_free(&tri);
        bp_atlas_build(&at, &both, &o, &err);
        bpt_mesh_free(&both);
    }
    if (!BPT_CHECK(at.num_charts == 2 && at.charts[0].num_loops == 0 && at.charts[0].error.status == BP_ERR_TOPOLOGY &&
                   at.charts[0].num_triangles == m->num_triangles,
                   "junction moves: the cow as one closed chart (%s)", err.message)) {
        if (at.num_charts) bp_atlas_free(&at);
        return;
    }
    ch = &at.charts[0];
    a = at.allocator;
    nt = ch->num_triangles; nv = ch->num_vertices; big = (3 * nt > nv ? 3 * nt : nv) + 1;
    glued = (uint32_t *)malloc(3 * (size_t)m->num_triangles * sizeof(uint32_t));
    ek = (ekey *)malloc(3 * (size_t)m->num_triangles * sizeof(ekey));
    for (ce = 0; ce < 3 * m->num_triangles; ce++) {
        uint32_t u = m->triangles[ce], v = m->triangles[ce - ce % 3 + (ce % 3 + 1) % 3];
        ek[ce].lo = u < v ? u : v; ek[ce].hi = u < v ? v : u; ek[ce].ce = ce;
        glued[ce] = BP__NONE;
    }
    qsort(ek, 3 * (size_t)m->num_triangles, sizeof *ek, ekey_cmp);
    for (i = 0; i + 1 < 3 * m->num_triangles; i++)
        if (ek[i].lo == ek[i + 1].lo && ek[i].hi == ek[i + 1].hi) { glued[ek[i].ce] = ek[i + 1].ce; glued[ek[i + 1].ce] = ek[i].ce; }
    memset(&K, 0, sizeof K);
    K.twin = (uint32_t *)malloc(3 * (size_t)nt * sizeof(uint32_t));
    K.adj_start = (uint32_t *)malloc(((size_t)nv + 1) * sizeof(uint32_t));
    K.adj = (uint32_t *)malloc(6 * (size_t)nt * sizeof(uint32_t));
    K.len = (double *)malloc(6 * (size_t)nt * sizeof(double));
    K.glen = K.len + 3 * (size_t)nt;
    K.dist = (double *)malloc(nv * sizeof(double));
    K.parent = (uint32_t *)malloc(nv * sizeof(uint32_t));
    K.cut = (unsigned char *)calloc(3 * (size_t)nt, 1);
    K.in_tree = (unsigned char *)calloc(3 * (size_t)nt, 1);
    K.deg = (uint32_t *)malloc(nv * sizeof(uint32_t));
    K.work = (uint32_t *)malloc(big * sizeof(uint32_t));
    K.work2 = (uint32_t *)malloc(big * sizeof(uint32_t));
    K.heap_d = (double *)malloc((6 * (size_t)nt + 1) * sizeof(double));
    K.heap_v = (uint32_t *)malloc((6 * (size_t)nt + 1) * sizeof(uint32_t));
    ones = (double *)malloc(3 * (size_t)nt * sizeof(double));
    src = (unsigned char *)calloc(nv, 1);
    BPT_CHECK(bp__cut_adjacency(&a, &K, ch, m, glued, NULL), "junction moves: adjacency");
    for (ce = 0; ce < 3 * nt; ce++) ones[ce] = 1;
    A[0] = bp__cut_dijkstra(&K, ch, K.glen, NULL, 0);
    A[1] = bp__cut_dijkstra(&K, ch, K.glen, NULL, A[0]);
    src[A[0]] = src[A[1]] = 1;
    A[2] = bp__cut_dijkstra(&K, ch, K.glen, src, 0);
    bp__cut_dijkstra(&K, ch, ones, NULL, 0);          /* the tree by edge count */
    for (i = 0; i < 3; i++) {
        uint32_t v = A[i];
        while (v != 0 && K.parent[v] != BP__NONE) {
            uint32_t e = K.parent[v];
            bp__cut_mark(&K, e);
            v = bp__ce_from(ch, e) == v ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
        }
    }
    for (ce = 0; ce < 3 * nt; ce++) if (K.cut[ce] && ce < K.twin[ce]) before += K.glen[ce];
    {
        int oom = 0;
        moved = bp__cut_smooth(&a, &K, ch, &oom);
        BPT_CHECK(!oom, "junction moves: scratch allocated");
    }
    deg = (uint32_t *)calloc(nv, sizeof(uint32_t));
    uf = (uint32_t *)malloc(nv * sizeof(uint32_t));
    for (i = 0; i < nv; i++) uf[i] = i;
    for (ce = 0; ce < 3 * nt; ce++)
        if (K.cut[ce] && ce < K.twin[ce]) {
            uint32_t u = bp__ce_from(ch, ce), v = bp__ce_to(ch, ce);
            after += K.glen[ce];
            nedge++;
            deg[u]++; deg[v]++;
            if (uf_root(uf, u) != uf_root(uf, v)) uf[uf_root(uf, u)] = uf_root(uf, v);
        }
    for (i = 0; i < nv; i++)
        if (deg[i]) {
            nvert++;
            comps += uf_root(uf, i) == i;
            if (deg[i] == 1 && i != A[0] && i != A[1] && i != A[2]) leaves_ok = 0;
        }
    for (i = 0; i < 3; i++) reach += deg[A[i]] > 0;
    BPT_CHECK(moved > 0 && after < before, "junction moves: %u junctions moved, the cut's 3D length %.6g -> %.6g (shorter)",
              moved, before, after);
    BPT_CHECK(comps == 1 && nedge == nvert - 1 && leaves_ok && reach == 3,
              "junction moves: the cut is still one tree (%u component, %u edges on %u vertices) with its leaves among "
              "the three far vertices, reaching all %u", comps, nedge, nvert, reach);
    free(deg); free(uf); free(ones); free(src); free(glued); free(ek);
    free(K.twin); free(K.adj_start); free(K.adj); free(K.len); free(K.dist); free(K.parent); free(K.cut);
    free(K.in_tree); free(K.deg); free(K.work); free(K.work2); free(K.heap_d); free(K.heap_v);
    bp_atlas_free(&at);
}

/* How often each mesh vertex of chart 0 lies on its boundary loops: the
   largest count, and how many vertices are there once. */
static void loop_counts(const bp_atlas *at, uint32_t nv, uint32_t *most, uint32_t *once)
{
    const bp_chart *ch = &at->charts[0];
    uint32_t *n = (uint32_t *)calloc(nv, sizeof(uint32_t)), i;
    for (i = 0; i < ch->loop_start[ch->num_loops]; i++) n[ch->vertex[ch->loop_vertices[i]]]++;
    *most = *once = 0;
    for (i = 0; i < nv; i++) {
        if (n[i] > *most) *most = n[i];
        *once += n[i] == 1;
    }
    free(n);
}

/* With segmentation to follow (an atlas: bp__cut_whole false) a closed
   genus-0 chart is only opened, along one path: each cut vertex lies on
   the boundary loop at most twice, the path's two ends once.  Cut to be
   flattened whole (no atlas) the same chart gets extremity branches: a
   junction lies on the loop three times or more.  The atlas grown on the
   opened chart is bijective (brute force). */
static void test_opening_cut(const bp_mesh *m)
{
    bp_atlas at;
    bp_error err;
    bp_options o;
    uint32_t most, once;
    char why[200] = "";
    memset(&o, 0, sizeof o);
    o.threads = 1;
    if (BPT_CHECK(bp_atlas_build(&at, m, &o, &err) == BP_OK && at.num_charts == 1, "whole cut built (%s)", err.message)) {
        loop_counts(&at, m->num_vertices, &most, &once);
        BPT_CHECK(most >= 3, "cut to be flattened whole: branches (a vertex %u times on the loop)", most);
        bp_atlas_free(&at);
    }
    o.atlas_resolution = 512;
    if (BPT_CHECK(bp_atlas_build(&at, m, &o, &err) == BP_OK && at.num_charts == 1, "opening cut built (%s)", err.message)) {
        loop_counts(&at, m->num_vertices, &most, &once);
        BPT_CHECK(most == 2 && once == 2 && at.charts[0].num_loops == 1,
                  "cut to be segmented: one path (vertices at most %u times on the loop, %u once, %u loop)", most, once,
                  at.charts[0].num_loops);
        bp_atlas_free(&at);
    }
    if (BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_OK, "atlas on the opened chart (%s)", err.message)) {
        BPT_CHECK(at.num_charts > 1 && atlas_bijective(&at, why), "atlas on the opened chart: %u charts, bijective %s",
                  at.num_charts, why);
        bp_atlas_free(&at);
    }
}

static int read_mesh(const char *path, bp_mesh *m)
{
    bp_error err;
    bp_status st = bp_read_mesh(path, m, NULL, &err);
    return BPT_CHECK(st == BP_OK, "read %s: %s", path, st ? err.message : "ok");
}

int main(void)
{
    bp_mesh m;
    /* built here */
    m = tetrahedron();
    expect_input("tetrahedron", &m, 0, 0);
    /* the cut of a closed genus-0 chart is a tree with at least two edges
       (a boundary of at least 4) and at most V - 1 */
    run("tetrahedron", &m, 2, 3);
    expect_rejected("tetrahedron", &m, 0);
    bpt_mesh_free(&m);
    m = icosahedron();
    BPT_CHECK(m.num_triangles == 20, "icosahedron: 20 hull triangles (%u)", m.num_triangles);
    expect_input("icosahedron", &m, 0, 0);
    run("icosahedron", &m, 2, 11);
    bpt_mesh_free(&m);
    m = torus(24, 12, 0);
    expect_input("torus 24x12", &m, 1, 0);
    run("torus 24x12", &m, 12 + 1, 24 + 12);           /* two generators through one point */
    expect_rejected("torus 24x12", &m, 1);
    determinism("torus 24x12", &m);
    bpt_mesh_free(&m);
    {
        /* three closed components in one mesh: each its own chart, each cut */
        bp_mesh t4 = tetrahedron(), i20 = icosahedron(), to = torus(12, 6, 0), a = bpt_concat(&t4, &i20, 5);
        bp_mesh b = bpt_concat(&a, &to, 12);
        bp_atlas at;
        bp_error err;
        bp_options o;
        uint32_t c;
        int all_cut = 1;
        memset(&o, 0, sizeof o);
        if (BPT_CHECK(bp_atlas_build(&at, &b, &o, &err) == BP_OK && at.num_charts == 3,
                      "tetrahedron + icosahedron + torus in one mesh: 3 charts built (%s)", err.message)) {
            for (c = 0; c < 3; c++) all_cut &= at.charts[c].cut_edges > 0;
            BPT_CHECK(all_cut, "three closed components: each chart has its own cut");
            bp_atlas_free(&at);
        }
        /* at least: 2, 2 and the torus's shorter generator plus one edge;
           at most: V - 1 for each polyhedron (a tree), every torus edge */
        run("tetrahedron + icosahedron + torus 12x6", &b, 2 + 2 + 6 + 1, 3 + 11 + 3 * 144 / 2);
        bpt_mesh_free(&t4); bpt_mesh_free(&i20); bpt_mesh_free(&to); bpt_mesh_free(&a); bpt_mesh_free(&b);
    }
    m = torus(24, 12, 1);
    run_iters("torus 24x12 with a vt seam (an annulus)", &m, 0, 0, 100);
    bpt_mesh_free(&m);

    /* real meshes */
    if (read_mesh("tests/data/fertility.off", &m)) {
        expect_input("fertility", &m, 4, 0);
        run("fertility (closed, genus 4)", &m, 8, 100000);
        expect_rejected("fertility", &m, 4);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/torus_with_holes.obj", &m)) {
        expect_input("torus_with_holes", &m, 1, 2);
        run("torus_with_holes (genus 1, 2 loops)", &m, 2, 100000);
        expect_rejected("torus_with_holes", &m, 1);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/cow_param_withSUV.obj", &m)) {
        uint32_t *keep = m.corner_uv;
        m.corner_uv = NULL;                            /* read without its vt */
        expect_input("cow without vt", &m, 0, 0);
        run("cow without vt (closed, genus 0)", &m, 2, 100000);
        test_importance(&m);
        test_junction_moves(&m);
        test_opening_cut(&m);
        m.corner_uv = keep;
        run_iters("cow with its vt seam (one disk)", &m, 0, 0, 100);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/spot.obj", &m)) {
        run("spot with its 13 vt charts", &m, 0, 0);
        bp_mesh_free(&m, NULL);
    }
    return bpt_finish();
}
