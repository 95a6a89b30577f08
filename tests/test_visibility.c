/* tests/test_visibility.c - chapter 4: BVH, visibility, importance energy.

   1. BVH == brute force: bp__bvh_occluded against a loop over every
      triangle with bp__ray_triangle, on random triangle soups, the cow and
      spot: random rays and segments, rays aimed exactly at vertices and edge
      midpoints (grazing), axis-parallel rays (zero direction components),
      rays starting on the surface (with and without skipping their own
      triangle).  Watertightness: rays from inside a closed convex mesh (a
      UV sphere, a cube with dyadic grid faces) through every vertex and
      every edge midpoint must hit; so must rays from outside aimed
      radially at them.
   2. Uniform view model on a closed convex sphere: the raw (unnormalized)
      V_t is E[max(0, n.r)] = 1/4 for every face: mean over faces within 5
      standard errors, every face within 5 sigma, sample variance of the
      face values as predicted; the side model gives exactly max(0, n.d),
      the ring model sin(elevation) on the faces facing up; after
      bp_visibility every face is 1 within 5 sigma and the area-weighted
      mean is 1.
   3. Occlusion: a thick cup; the inner bottom is seen only through the
      opening (about sin^2(theta)/4 with theta the opening half-angle)
      while the outer wall gets the full 1/4.
   4. Every view model (uniform, front, ring, side, list) gives a bijective
      map (bp_check on every chart) on the cow and on the four-chart cup,
      and the side-optimized map has more texels per screen area than the
      isometric map under the side view (ratio > 1).
   5. Eq 4.1: the energy bp_chart_optimize uses with opt.importance equals
      I (s1^2/I + s2^2/I + I/s1^2 + I/s2^2) from independently computed
      singular values (and its reported energy_start is their area-weighted
      mean); the gradient of sum_t weight_t E_t (bp__triangle_energy) with
      that rest data matches central differences; constant importance I on a flat chart
      gives a map with I times the 3D area.
   6. Determinism: bp_visibility and bp_texture_to_screen are bit-identical
      with a parallel_for that runs the tasks in reverse or interleaved
      order.
   With BP_TEST_QUICK set (make test) the soup of 2000 triangles, the cow
   and spot get 4000 rays against brute force instead of 20000 (500 of each
   kind), and the cow only the uniform and side models (front, ring and list
   on the cup); make check runs the full form. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static int quick = 0;   /* BP_TEST_QUICK: the short form (make test) */

/* ---- random numbers: xorshift64* --------------------------------------- */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t xs(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return rng_state * 0x2545F4914F6CDD1Dull;
}
static double urand(void) { return (double)(xs() >> 11) * (1.0 / 9007199254740992.0); }
static double srand1(void) { return 2 * urand() - 1; }

/* ---- meshes built in the test -------------------------------------------- */
typedef struct tmesh {
    bp_mesh m;
    uint32_t cv, ct;
} tmesh;

static uint32_t tm_v(tmesh *T, double x, double y, double z)
{
    if (T->m.num_vertices == T->cv) {
        T->cv = T->cv ? 2 * T->cv : 256;
        T->m.positions = (double *)realloc(T->m.positions, sizeof(double) * 3 * T->cv);
    }
    T->m.positions[3 * T->m.num_vertices] = x;
    T->m.positions[3 * T->m.num_vertices + 1] = y;
    T->m.positions[3 * T->m.num_vertices + 2] = z;
    return T->m.num_vertices++;
}

static void tm_t(tmesh *T, uint32_t a, uint32_t b, uint32_t c, uint32_t chart)
{
    if (T->m.num_triangles == T->ct) {
        T->ct = T->ct ? 2 * T->ct : 256;
        T->m.triangles = (uint32_t *)realloc(T->m.triangles, sizeof(uint32_t) * 3 * T->ct);
        T->m.corner_uv = (uint32_t *)realloc(T->m.corner_uv, sizeof(uint32_t) * 3 * T->ct);
    }
    T->m.triangles[3 * T->m.num_triangles] = a;
    T->m.triangles[3 * T->m.num_triangles + 1] = b;
    T->m.triangles[3 * T->m.num_triangles + 2] = c;
    /* uv index = (vertex, chart): charts are separated by seams */
    T->m.corner_uv[3 * T->m.num_triangles] = 4 * a + chart;
    T->m.corner_uv[3 * T->m.num_triangles + 1] = 4 * b + chart;
    T->m.corner_uv[3 * T->m.num_triangles + 2] = 4 * c + chart;
    T->m.num_triangles++;
}

/* finish: corner_uv kept only if `seams`; uvs are placeholders (zeros) */
static void tm_finish(tmesh *T, int seams)
{
    T->m.num_faces = T->m.num_triangles;
    if (seams) {
        T->m.num_uvs = 4 * T->m.num_vertices;
        T->m.uvs = (double *)calloc(2 * (size_t)T->m.num_uvs, sizeof(double));
    } else {
        free(T->m.corner_uv);
        T->m.corner_uv = NULL;
    }
}

static void tm_free(tmesh *T)
{
    free(T->m.positions); free(T->m.triangles); free(T->m.corner_uv); free(T->m.uvs);
    memset(T, 0, sizeof *T);
}

/* Surface of revolution about +y: profile (r_j, y_j), j = 0..K, r_0 = r_K = 0
   are poles; N columns; column i belongs to chart i * charts / N.  The
   triangles are oriented so that the profile traversed with the solid on
   the left... the caller checks the orientation by the signed volume. */
static void revolve(tmesh *T, const double *r, const double *y, int K, int N, int charts)
{
    int j, i;
    uint32_t p0, pK, *ring = (uint32_t *)malloc(sizeof(uint32_t) * (K + 1) * N);
    p0 = tm_v(T, 0, y[0], 0);
    for (j = 1; j < K; j++)
        for (i = 0; i < N; i++)
            ring[j * N + i] = tm_v(T, r[j] * cos(2 * PI * i / N), y[j], r[j] * sin(2 * PI * i / N));
    pK = tm_v(T, 0, y[K], 0);
    for (i = 0; i < N; i++) {
        int i1 = (i + 1) % N;
        uint32_t c = (uint32_t)(i * charts / N);
        tm_t(T, p0, ring[N + i1], ring[N + i], c);
        tm_t(T, pK, ring[(K - 1) * N + i], ring[(K - 1) * N + i1], c);
        for (j = 1; j + 1 < K; j++) {
            tm_t(T, ring[j * N + i], ring[j * N + i1], ring[(j + 1) * N + i1], c);
            tm_t(T, ring[j * N + i], ring[(j + 1) * N + i1], ring[(j + 1) * N + i], c);
        }
    }
    free(ring);
}

static double signed_volume(const bp_mesh *m)
{
    double v = 0;
    uint32_t t;
    for (t = 0; t < m->num_triangles; t++) {
        const double *a = m->positions + 3 * m->triangles[3 * t], *b = m->positions + 3 * m->triangles[3 * t + 1];
        const double *c = m->positions + 3 * m->triangles[3 * t + 2];
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return v / 6;
}

static void orient_outward(bp_mesh *m)
{
    uint32_t t;
    if (signed_volume(m) > 0) return;
    for (t = 0; t < m->num_triangles; t++) {
        uint32_t k = m->triangles[3 * t + 1];
        m->triangles[3 * t + 1] = m->triangles[3 * t + 2]; m->triangles[3 * t + 2] = k;
        k = m->corner_uv[3 * t + 1];
        m->corner_uv[3 * t + 1] = m->corner_uv[3 * t + 2]; m->corner_uv[3 * t + 2] = k;
    }
}

static void make_sphere(tmesh *T, int K, int N, int charts)
{
    double r[257], y[257];
    int j;
    for (j = 0; j <= K; j++) { r[j] = sin(PI * j / K); y[j] = -cos(PI * j / K); }
    r[0] = r[K] = 0;
    revolve(T, r, y, K, N, charts);
    orient_outward(&T->m);
    tm_finish(T, charts > 1);
}

/* append samples of a profile segment (end included) */
static int seg(double *r, double *y, int k, double r1, double y1, double h)
{
    double r0 = r[k], y0 = y[k];
    int n = (int)ceil(sqrt((r1 - r0) * (r1 - r0) + (y1 - y0) * (y1 - y0)) / h - 1e-9), i;
    if (n < 1) n = 1;
    for (i = 1; i <= n; i++) { r[k + i] = r0 + (r1 - r0) * i / n; y[k + i] = y0 + (y1 - y0) * i / n; }
    return k + n;
}

/* thick cup about +y, opening at +y: radius 1, height 2, wall w; four
   quadrant charts (as bench/shapes.c) */
static void make_cup(tmesh *T, double h, int N, double w)
{
    double r[1024], y[1024];
    int K = 0;
    r[0] = 0; y[0] = 0;
    K = seg(r, y, K, 1, 0, h);
    K = seg(r, y, K, 1, 2, h);
    K = seg(r, y, K, 1 - w, 2, h);
    K = seg(r, y, K, 1 - w, w, h);
    K = seg(r, y, K, 0, w, h);
    revolve(T, r, y, K, N, 4);
    orient_outward(&T->m);
    tm_finish(T, 1);
}

/* closed cube [-1,1]^3, each face an n x n grid (dyadic coordinates when n
   is a power of two) */
static void make_cube(tmesh *T, int n)
{
    int f, i, j;
    uint32_t *id = (uint32_t *)malloc(sizeof(uint32_t) * (n + 1) * (n + 1) * (n + 1));
    for (i = 0; i < (n + 1) * (n + 1) * (n + 1); i++) id[i] = UINT32_MAX;
    for (f = 0; f < 6; f++) {
        int ax = f / 2, sg = f % 2, u = (ax + 1) % 3, w = (ax + 2) % 3;
        for (i = 0; i < n; i++)
            for (j = 0; j < n; j++) {
                uint32_t q[4];
                int k;
                for (k = 0; k < 4; k++) {
                    int c[3];
                    c[ax] = sg ? n : 0;
                    c[u] = i + (k == 1 || k == 2);
                    c[w] = j + (k >= 2);
                    {
                        uint32_t *slot = &id[(c[0] * (n + 1) + c[1]) * (n + 1) + c[2]];
                        if (*slot == UINT32_MAX) *slot = tm_v(T, -1 + 2.0 * c[0] / n, -1 + 2.0 * c[1] / n, -1 + 2.0 * c[2] / n);
                        q[k] = *slot;
                    }
                }
                if (sg) { tm_t(T, q[0], q[1], q[2], 0); tm_t(T, q[0], q[2], q[3], 0); }
                else { tm_t(T, q[0], q[2], q[1], 0); tm_t(T, q[0], q[3], q[2], 0); }
            }
    }
    free(id);
    tm_finish(T, 0);
}

/* ---- 1. BVH against brute force ------------------------------------------ */
static int brute(const bp_mesh *m, const double *o, const double *d, double tmin, double tmax, uint32_t skip)
{
    uint32_t t;
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *tv = m->triangles + 3 * (size_t)t;
        if (t == skip) continue;
        if (bp__ray_triangle(o, d, bp__pos(m, tv[0]), bp__pos(m, tv[1]), bp__pos(m, tv[2]), tmin, tmax)) return 1;
    }
    return 0;
}

static void bbox(const bp_mesh *m, double *lo, double *hi)
{
    uint32_t v;
    int k;
    for (k = 0; k < 3; k++) { lo[k] = HUGE_VAL; hi[k] = -HUGE_VAL; }
    for (v = 0; v < m->num_vertices; v++)
        for (k = 0; k < 3; k++) {
            if (m->positions[3 * v + k] < lo[k]) lo[k] = m->positions[3 * v + k];
            if (m->positions[3 * v + k] > hi[k]) hi[k] = m->positions[3 * v + k];
        }
}

/* kinds of rays */
enum { R_RANDOM, R_SEGMENT, R_VERTEX, R_EDGE_MID, R_AXIS, R_AXIS_VERTEX, R_SURFACE, R_SURFACE_NOSKIP, R_KINDS };
static const char *ray_kind_name[R_KINDS] = { "random rays", "random segments", "aimed at vertices",
                                              "through edge midpoints", "axis-parallel", "axis-parallel through vertices",
                                              "from the surface (own triangle skipped)", "from the surface (no skip)" };

static void bvh_vs_brute(const char *name, const bp_mesh *m, int nrays)
{
    bp_allocator a = bp__allocator_of(NULL);
    bp__bvh B;
    double lo[3], hi[3], ext[3];
    int i, k, mismatch[R_KINDS] = { 0 }, count[R_KINDS] = { 0 }, hits[R_KINDS] = { 0 };
    uint32_t maxleaf = 0, n, covered = 0;
    char *seen;
    if (!BPT_CHECK(bp__bvh_build(&a, &B, m) == BP_OK, "%s: BVH built", name)) return;
    /* structure: every triangle in exactly one leaf, boxes contain their triangles */
    seen = (char *)calloc(m->num_triangles, 1);
    {
        int box_ok = 1, dup = 0;
        for (n = 0; n < B.num_nodes; n++) {
            const bp__bvh_node *N = &B.nodes[n];
            uint32_t j;
            if (!N->count) continue;
            if (N->count > maxleaf) maxleaf = N->count;
            for (j = N->first; j < N->first + N->count; j++) {
                uint32_t t = B.tri[j];
                if (seen[t]) dup = 1;
                seen[t] = 1;
                covered++;
                for (k = 0; k < 3; k++) {
                    const double *p = bp__pos(m, m->triangles[3 * (size_t)t + k]);
                    int c;
                    for (c = 0; c < 3; c++) if (p[c] < N->lo[c] || p[c] > N->hi[c]) box_ok = 0;
                }
            }
        }
        BPT_CHECK(!dup && covered == m->num_triangles && box_ok,
                  "%s: BVH leaves hold each of %u triangles once, inside their boxes (%u nodes, largest leaf %u)", name,
                  m->num_triangles, B.num_nodes, maxleaf);
    }
    free(seen);
    bbox(m, lo, hi);
    for (k = 0; k < 3; k++) ext[k] = hi[k] - lo[k];
    for (i = 0; i < nrays; i++) {
        int kind = i % R_KINDS;
        double o[3], d[3], tmin = 0, tmax = HUGE_VAL;
        uint32_t skip = UINT32_MAX, t = (uint32_t)(xs() % m->num_triangles);
        const uint32_t *tv = m->triangles + 3 * (size_t)t;
        int bv, bb;
        for (k = 0; k < 3; k++) o[k] = lo[k] - 0.25 * ext[k] + 1.5 * ext[k] * urand();
        switch (kind) {
        case R_RANDOM:
            for (k = 0; k < 3; k++) d[k] = srand1();
            break;
        case R_SEGMENT:
            for (k = 0; k < 3; k++) d[k] = srand1() * ext[k];
            tmin = 0.5 * urand();
            tmax = tmin + urand();
            break;
        case R_VERTEX: case R_EDGE_MID: {
            uint32_t i0 = (uint32_t)(xs() % 3), i1 = (i0 + 1 + (uint32_t)(xs() % 2)) % 3;
            const double *p = bp__pos(m, tv[i0]), *q = bp__pos(m, tv[i1]);
            double target[3];
            for (k = 0; k < 3; k++) target[k] = kind == R_VERTEX ? p[k] : 0.5 * (p[k] + q[k]);
            for (k = 0; k < 3; k++) d[k] = target[k] - o[k];
            /* the target at t = 1: segments ending before, exactly at and after it */
            switch (xs() % 4) {
            case 0: tmax = 1; break;
            case 1: tmax = 0.999; break;
            case 2: tmin = 1; break;
            default: break;
            }
            break;
        }
        case R_AXIS: case R_AXIS_VERTEX: {
            int ax = (int)(xs() % 3);
            d[0] = d[1] = d[2] = 0;
            d[ax] = xs() & 1 ? 1 : -1;
            if (kind == R_AXIS_VERTEX) {
                const double *p = bp__pos(m, tv[xs() % 3]);
                for (k = 0; k < 3; k++) if (k != ax) o[k] = p[k];
            }
            if (xs() & 1) { tmin = urand() * ext[ax]; tmax = tmin + urand() * ext[ax]; }
            break;
        }
        default: {                             /* from a point of triangle t */
            double u = urand(), v = urand();
            if (u + v > 1) { u = 1 - u; v = 1 - v; }
            for (k = 0; k < 3; k++)
                o[k] = (1 - u - v) * bp__pos(m, tv[0])[k] + u * bp__pos(m, tv[1])[k] + v * bp__pos(m, tv[2])[k];
            for (k = 0; k < 3; k++) d[k] = srand1();
            if (kind == R_SURFACE) skip = t;
            tmin = (xs() & 1) ? 0 : 1e-9;
            break;
        }
        }
        bv = bp__bvh_occluded(&B, o, d, tmin, tmax, skip);
        bb = brute(m, o, d, tmin, tmax, skip);
        count[kind]++;
        hits[kind] += bb;
        if (bv != bb) {
            if (mismatch[kind] < 3)
                printf("  %s: %s: bvh %d brute %d: o = (%.17g, %.17g, %.17g) d = (%.17g, %.17g, %.17g) t in (%.17g, %.17g) skip %u\n",
                       name, ray_kind_name[kind], bv, bb, o[0], o[1], o[2], d[0], d[1], d[2], tmin, tmax, skip);
            mismatch[kind]++;
        }
    }
    for (k = 0; k < R_KINDS; k++)
        BPT_CHECK(mismatch[k] == 0 && (hits[k] > 0 || m->num_triangles < 100) && (hits[k] < count[k] || k == R_SURFACE_NOSKIP),
                  "%s: %s: BVH == brute force on %d rays (%d hit, %d mismatches)", name, ray_kind_name[k], count[k],
                  hits[k], mismatch[k]);
    bp__bvh_free(&a, &B);
}

static void random_soup(tmesh *T, int nt, uint64_t seed)
{
    int i;
    rng_state = seed;
    for (i = 0; i < nt; i++) {
        double c[3], s = 0.02 + 0.2 * urand();
        uint32_t v[3];
        int j;
        for (j = 0; j < 3; j++) c[j] = 4 * urand() - 2 + (j == 0 ? 1 : 0);   /* box [-1,3]x[-2,2]^2 */
        for (j = 0; j < 3; j++) v[j] = tm_v(T, c[0] + s * srand1(), c[1] + s * srand1(), c[2] + s * srand1());
        tm_t(T, v[0], v[1], v[2], 0);
    }
    tm_finish(T, 0);
}

/* Rays through every vertex and every edge midpoint of a closed convex mesh,
   from an interior point and radially from outside: none may slip through. */
static void watertight(const char *name, const bp_mesh *m, int from_random_inside)
{
    bp_allocator a = bp__allocator_of(NULL);
    bp__bvh B;
    uint32_t t, miss_in = 0, miss_out = 0, miss_bvh = 0, rays = 0;
    int k, rep;
    if (!BPT_CHECK(bp__bvh_build(&a, &B, m) == BP_OK, "%s: BVH built", name)) return;
    for (rep = 0; rep < (from_random_inside ? 4 : 1); rep++) {
        double c[3] = { 0, 0, 0 };
        if (rep) for (k = 0; k < 3; k++) c[k] = 0.3 * srand1();
        for (t = 0; t < m->num_triangles; t++)
            for (k = 0; k < 6; k++) {
                const double *p = bp__pos(m, m->triangles[3 * (size_t)t + k % 3]);
                const double *q = bp__pos(m, m->triangles[3 * (size_t)t + (k + 1) % 3]);
                double target[3], d[3], o[3];
                int j;
                for (j = 0; j < 3; j++) target[j] = k < 3 ? p[j] : 0.5 * (p[j] + q[j]);
                /* from inside, through the target */
                for (j = 0; j < 3; j++) d[j] = target[j] - c[j];
                if (!brute(m, c, d, 0, HUGE_VAL, UINT32_MAX)) miss_in++;
                if (!bp__bvh_occluded(&B, c, d, 0, HUGE_VAL, UINT32_MAX)) miss_bvh++;
                /* from outside, radially toward the target */
                for (j = 0; j < 3; j++) { o[j] = 3 * target[j]; d[j] = -target[j]; }
                if (!brute(m, o, d, 0, HUGE_VAL, UINT32_MAX)) miss_out++;
                if (!bp__bvh_occluded(&B, o, d, 0, HUGE_VAL, UINT32_MAX)) miss_bvh++;
                rays += 2;
            }
    }
    BPT_CHECK(miss_in == 0, "%s: watertight: %u rays from inside through vertices and edge midpoints, %u slip through",
              name, rays / 2, miss_in);
    BPT_CHECK(miss_out == 0, "%s: watertight: %u rays from outside aimed at vertices and edge midpoints, %u slip through",
              name, rays / 2, miss_out);
    BPT_CHECK(miss_bvh == 0, "%s: watertight through the BVH: %u misses of %u", name, miss_bvh, rays);
    bp__bvh_free(&a, &B);
}

static void test_bvh(void)
{
    tmesh T;
    bp_mesh mesh;
    bp_error err;
    const char *files[2] = { "tests/data/cow_param_withSUV.obj", "tests/data/spot.obj" };
    int f;
    memset(&T, 0, sizeof T);
    random_soup(&T, 2000, 12345);
    bvh_vs_brute("soup of 2000 triangles", &T.m, quick ? 4000 : 20000);
    tm_free(&T);
    random_soup(&T, 37, 777);            /* small: a few leaves */
    bvh_vs_brute("soup of 37 triangles", &T.m, 4000);
    tm_free(&T);
    for (f = 0; f < 2; f++) {
        if (!BPT_CHECK(bp_read_obj(files[f], &mesh, NULL, &err) == BP_OK, "read %s: %s", files[f], err.message)) continue;
        rng_state = 99 + (uint64_t)f;
        bvh_vs_brute(files[f], &mesh, quick ? 4000 : 20000);
        bp_mesh_free(&mesh, NULL);
    }
    make_cube(&T, 8);
    watertight("cube 8x8 per face", &T.m, 1);
    tm_free(&T);
    make_sphere(&T, 24, 48, 1);
    watertight("UV sphere 48x24", &T.m, 1);
    tm_free(&T);
    /* the ray/triangle test itself on exact cases */
    {
        double v0[3] = { 0, 0, 0 }, v1[3] = { 1, 0, 0 }, v2[3] = { 0, 1, 0 }, o[3] = { 0.25, 0.25, 1 }, d[3] = { 0, 0, -1 };
        double oe[3] = { 0.5, 0.5, 1 }, par[3] = { 1, 0, 0 }, op[3] = { -1, 0.25, 0 };
        BPT_CHECK(bp__ray_triangle(o, d, v0, v1, v2, 0, HUGE_VAL) && bp__ray_triangle(o, d, v0, v2, v1, 0, HUGE_VAL),
                  "ray/triangle: hit from either side (both windings)");
        BPT_CHECK(!bp__ray_triangle(o, d, v0, v1, v2, 0, 1) && bp__ray_triangle(o, d, v0, v1, v2, 0, 1.0000001) &&
                  !bp__ray_triangle(o, d, v0, v1, v2, 1, 2),
                  "ray/triangle: open interval (tmin, tmax): the hit at t = 1 is outside (0, 1) and (1, 2)");
        BPT_CHECK(bp__ray_triangle(oe, d, v0, v1, v2, 0, HUGE_VAL), "ray/triangle: a ray through the hypotenuse hits");
        BPT_CHECK(!bp__ray_triangle(op, par, v0, v1, v2, -HUGE_VAL, HUGE_VAL), "ray/triangle: a ray in the plane of the triangle does not hit");
        {
            double d2[3] = { 0, 0, 1 }, ob[3] = { 0.25, 0.25, -1 };
            BPT_CHECK(!bp__ray_triangle(ob, d, v0, v1, v2, 0, HUGE_VAL) && bp__ray_triangle(ob, d2, v0, v1, v2, 0, HUGE_VAL),
                      "ray/triangle: a ray pointing away misses, pointing toward hits");
        }
    }
}

/* ---- 2. sphere under the uniform, side and ring models -------------------- */
static double tri_area(const bp_mesh *m, uint32_t t)
{
    const uint32_t *tv = m->triangles + 3 * (size_t)t;
    return 0.5 * bp__area2_3d(bp__pos(m, tv[0]), bp__pos(m, tv[1]), bp__pos(m, tv[2]));
}

static void test_sphere(void)
{
    tmesh T;
    bp_options opt;
    bp_error err;
    double *raw, *vis, sum = 0, sum2 = 0, mean, var, sigma, worst = 0, aw = 0, A = 0, worstn = 0;
    uint32_t t, N = 1024, nt;
    memset(&T, 0, sizeof T);
    make_sphere(&T, 20, 40, 1);
    nt = T.m.num_triangles;
    raw = (double *)malloc(sizeof(double) * nt);
    vis = (double *)malloc(sizeof(double) * nt);
    memset(&opt, 0, sizeof opt);
    opt.views.model = BP_VIEW_UNIFORM;
    opt.views.samples = N;
    opt.views.seed = 2024;
    if (!BPT_CHECK(bp__vis_run(&T.m, &opt, NULL, NULL, 0, raw, &err) == BP_OK, "sphere: raw visibility: %s", err.message)) goto done;
    /* per sample: c = max(0, n.r), r uniform: E c = 1/4, E c^2 = 1/6, var = 5/48 */
    sigma = sqrt(5.0 / 48 / N);
    for (t = 0; t < nt; t++) {
        double dev = fabs(raw[t] - 0.25) / sigma;
        sum += raw[t]; sum2 += raw[t] * raw[t];
        if (dev > worst) worst = dev;
    }
    mean = sum / nt;
    var = sum2 / nt - mean * mean;
    BPT_CHECK(fabs(mean - 0.25) < 5 * sigma / sqrt((double)nt) && fabs(mean - 0.25) < 0.0025,
              "sphere, uniform: raw mean over %u faces %.5f = 1/4 within 5 standard errors (%.5f)", nt, mean,
              5 * sigma / sqrt((double)nt));
    BPT_CHECK(worst < 5.5, "sphere, uniform: every face within 5.5 sigma of 1/4 (worst %.2f sigma, sigma %.4f, %u rays)",
              worst, sigma, N);
    BPT_CHECK(var > 0.7 * sigma * sigma && var < 1.3 * sigma * sigma,
              "sphere, uniform: spread of the face values %.3g = the Monte-Carlo variance 5/(48 N) = %.3g within 30%%",
              var, sigma * sigma);
    /* normalized */
    if (BPT_CHECK(bp_visibility(&T.m, &opt, vis, &err) == BP_OK, "sphere: bp_visibility")) {
        for (t = 0; t < nt; t++) {
            double a = tri_area(&T.m, t), dev = fabs(vis[t] - 1) / (4 * sigma);
            aw += a * vis[t]; A += a;
            if (dev > worstn) worstn = dev;
        }
        BPT_CHECK(fabs(aw / A - 1) < 1e-12, "sphere, uniform: normalized V has area-weighted mean 1 (%.15f)", aw / A);
        BPT_CHECK(worstn < 5.5, "sphere, uniform: every normalized V_t is 1 within 5.5 sigma (worst %.2f)", worstn);
    }
    /* side: exactly max(0, n.d) (a convex mesh occludes nothing) */
    {
        double d[3] = { 0.3, -0.5, 0.8 }, l = sqrt(0.09 + 0.25 + 0.64), worst_side = 0;
        memset(&opt, 0, sizeof opt);
        opt.views.model = BP_VIEW_SIDE;
        memcpy(opt.views.direction, d, sizeof d);
        opt.views.samples = 16;
        if (BPT_CHECK(bp__vis_run(&T.m, &opt, NULL, NULL, 0, raw, &err) == BP_OK, "sphere: side visibility")) {
            for (t = 0; t < nt; t++) {
                double n[3], c;
                bp__triangle_normal(&T.m, t, n);
                c = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / l;
                c = c > 0 ? c : 0;
                if (fabs(raw[t] - c) > worst_side) worst_side = fabs(raw[t] - c);
            }
            BPT_CHECK(worst_side < 1e-12, "sphere, side (0.3,-0.5,0.8): V_t = max(0, n.d) exactly on every face (max error %.3g)",
                      worst_side);
        }
    }
    /* ring about +y at 40 degrees: the top fan (normal near +y) sees every
       direction at cos(angle to the normal) with the ring; a face whose
       normal is +y exactly would give sin(40 deg).  Check the mean over the
       ring of n.r = sin(e) n_y for faces that see the whole ring
       (n_y sin e > |n_h| cos e). */
    {
        double e = 40 * PI / 180, worst_ring = 0;
        uint32_t used = 0;
        memset(&opt, 0, sizeof opt);
        opt.views.model = BP_VIEW_RING;
        opt.views.elevation = 40;
        opt.views.samples = N;
        opt.views.seed = 5;
        if (BPT_CHECK(bp__vis_run(&T.m, &opt, NULL, NULL, 0, raw, &err) == BP_OK, "sphere: ring visibility")) {
            for (t = 0; t < nt; t++) {
                double n[3], nh;
                bp__triangle_normal(&T.m, t, n);
                nh = sqrt(n[0] * n[0] + n[2] * n[2]);
                if (n[1] * sin(e) <= nh * cos(e)) continue;
                used++;
                /* n.r = n_y sin e + nh cos e cos(phi): spread nh cos e / sqrt 2 */
                {
                    double s = nh * cos(e) / sqrt(2.0 * N) + 1e-15, dev = fabs(raw[t] - n[1] * sin(e)) / s;
                    if (dev > worst_ring) worst_ring = dev;
                }
            }
            BPT_CHECK(used > 0 && worst_ring < 5.5,
                      "sphere, ring at 40 deg: %u upper faces have V_t = n_y sin(40 deg) within 5.5 sigma (worst %.2f)", used,
                      worst_ring);
        }
    }
done:
    free(raw); free(vis);
    tm_free(&T);
}

/* ---- 3. occlusion in a cup -------------------------------------------------- */
static void test_cup_occlusion(void)
{
    tmesh T;
    bp_options opt;
    bp_error err;
    double *raw, w = 0.08, bottom = 0, bottom_a = 0, wall = 0, wall_a = 0, inwall = 0, inwall_a = 0, theta;
    uint32_t t, N = 512;
    memset(&T, 0, sizeof T);
    make_cup(&T, 0.1, 48, w);
    raw = (double *)malloc(sizeof(double) * T.m.num_triangles);
    memset(&opt, 0, sizeof opt);
    opt.views.model = BP_VIEW_UNIFORM;
    opt.views.samples = N;
    opt.views.seed = 77;
    if (BPT_CHECK(bp__vis_run(&T.m, &opt, NULL, NULL, 0, raw, &err) == BP_OK, "cup: raw visibility: %s", err.message)) {
        for (t = 0; t < T.m.num_triangles; t++) {
            const uint32_t *tv = T.m.triangles + 3 * (size_t)t;
            double c[3] = { 0, 0, 0 }, n[3], rr, a = tri_area(&T.m, t);
            int k;
            for (k = 0; k < 3; k++) {
                c[0] += bp__pos(&T.m, tv[k])[0] / 3; c[1] += bp__pos(&T.m, tv[k])[1] / 3; c[2] += bp__pos(&T.m, tv[k])[2] / 3;
            }
            bp__triangle_normal(&T.m, t, n);
            rr = sqrt(c[0] * c[0] + c[2] * c[2]);
            if (n[1] > 0.99 && c[1] < 0.5 && rr < 0.15) { bottom += a * raw[t]; bottom_a += a; }       /* inner bottom, centre */
            if (rr > 0.99 && c[1] > 0.5 && c[1] < 1.5) { wall += a * raw[t]; wall_a += a; }           /* outer wall */
            if (rr < 0.93 && rr > 0.9 && c[1] > 0.2 && c[1] < 0.4) { inwall += a * raw[t]; inwall_a += a; } /* inner wall, low */
        }
        bottom /= bottom_a; wall /= wall_a; inwall /= inwall_a;
        /* the centre of the inner bottom sees the sky through a cone of
           half-angle theta: V = sin^2(theta) / 4 (about 0.046) */
        theta = atan((1 - w) / (2 - w));
        BPT_CHECK(bottom_a > 0 && wall_a > 0 && bottom < 0.3 * wall,
                  "cup, uniform: the inner bottom (%.4f) is far less visible than the outer wall (%.4f)", bottom, wall);
        BPT_CHECK(fabs(wall - 0.25) < 0.01, "cup, uniform: the outer wall is unoccluded: %.4f = 1/4", wall);
        BPT_CHECK(fabs(bottom - sin(theta) * sin(theta) / 4) < 0.012,
                  "cup, uniform: the inner bottom centre %.4f ~ sin^2(theta)/4 = %.4f (opening half-angle %.1f deg)", bottom,
                  sin(theta) * sin(theta) / 4, theta * 180 / PI);
        BPT_CHECK(inwall_a > 0 && inwall < bottom * 1.5 && inwall > 0,
                  "cup, uniform: the low inner wall (%.4f) is occluded too", inwall);
    }
    free(raw);
    tm_free(&T);
}

/* ---- 4. bijectivity under every view model, side-view density --------------- */
static int all_charts_valid(const bp_atlas *A, uint32_t *bad_chart)
{
    uint32_t c;
    for (c = 0; c < A->num_charts; c++) {
        bp_check_report r;
        const bp_chart *ch = &A->charts[c];
        bp_status st = bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL);
        /* bijective: the verdict and every count of the report agree */
        if (st != BP_OK || r.flipped || r.degenerate || r.nonfinite || r.boundary_intersections || r.loop_orientation ||
            r.nested || r.nonmanifold_edges || r.misoriented_edges) {
            *bad_chart = c;
            return 0;
        }
    }
    return 1;
}

static void set_model(bp_views *V, int model, const double *front, const double *side)
{
    static const double list[12] = { 1, 0, 0, 3, 0, 1, 0, 1, -1, 0.2, 0.4, 0.5 };
    memset(V, 0, sizeof *V);
    V->model = model;
    if (model == BP_VIEW_FRONT) memcpy(V->direction, front, 3 * sizeof(double));
    if (model == BP_VIEW_SIDE) memcpy(V->direction, side, 3 * sizeof(double));
    V->up[1] = 1;
    V->elevation = 30;
    V->samples = 32;
    V->seed = 11;
    if (model == BP_VIEW_LIST) { V->list = list; V->list_count = 3; }
}

/* every model on m, or (few) only the uniform and side models */
static void models_bijective(const char *name, const bp_mesh *m, const double *front, const double *side, int few)
{
    static const char *mn[6] = { "", "uniform", "front", "ring", "side", "list" };
    bp_atlas iso, side_map;
    bp_options opt;
    bp_error err;
    int model, have_iso, have_side = 0;
    uint32_t bad = 0;
    memset(&opt, 0, sizeof opt);
    have_iso = BPT_CHECK(bp_parameterize(&iso, m, &opt, &err) == BP_OK, "%s: isometric map: %s", name, err.message);
    for (model = BP_VIEW_UNIFORM; model <= BP_VIEW_LIST; model++) {
        bp_atlas A;
        if (few && model != BP_VIEW_UNIFORM && model != BP_VIEW_SIDE) continue;
        set_model(&opt.views, model, front, side);
        if (!BPT_CHECK(bp_parameterize(&A, m, &opt, &err) == BP_OK, "%s, %s: bp_parameterize: %s", name, mn[model], err.message))
            continue;
        BPT_CHECK(all_charts_valid(&A, &bad), "%s, %s: all %u charts bijective (bp_check)%s", name, mn[model], A.num_charts,
                  bad ? " - a chart failed" : "");
        if (model == BP_VIEW_SIDE) { side_map = A; have_side = 1; }
        else bp_atlas_free(&A);
    }
    if (have_iso && have_side) {
        double di = 0, ds = 0;
        set_model(&opt.views, BP_VIEW_SIDE, front, side);
        opt.views.samples = 64;
        opt.views.seed = 0xABCDEF;       /* a stream independent of the optimization's */
        if (BPT_CHECK(bp_texture_to_screen(m, &iso, &opt, &di, &err) == BP_OK &&
                      bp_texture_to_screen(m, &side_map, &opt, &ds, &err) == BP_OK, "%s: texel density measured", name))
            BPT_CHECK(ds > 0 && di / ds > 1.2, "%s: side-view density ratio isometric/side-map = %.3f > 1.2", name, di / ds);
    }
    if (have_iso) bp_atlas_free(&iso);
    if (have_side) bp_atlas_free(&side_map);
}

static void test_bijective(void)
{
    bp_mesh mesh;
    bp_error err;
    tmesh T;
    double cow_front[3] = { 1, 0, 0 }, cow_side[3] = { 0, 0, 1 }, front[3] = { 0, 0, 1 }, side[3] = { 1, 0, 0 };
    if (BPT_CHECK(bp_read_obj("tests/data/cow_param_withSUV.obj", &mesh, NULL, &err) == BP_OK, "read cow: %s", err.message)) {
        models_bijective("cow", &mesh, cow_front, cow_side, quick);
        bp_mesh_free(&mesh, NULL);
    }
    memset(&T, 0, sizeof T);
    make_cup(&T, 0.2, 32, 0.08);
    models_bijective("cup (4 quadrant charts)", &T.m, front, side, 0);
    tm_free(&T);
}

/* ---- 5. eq 4.1 --------------------------------------------------------------- */
/* singular values of a 2x2 matrix, independently: sqrt of the eigenvalues of J^T J */
static void svd2(double a, double b, double c, double d, double *s1, double *s2)
{
    double p = a * a + c * c, q = a * b + c * d, r = b * b + d * d;
    double tr = p + r, disc = sqrt((p - r) * (p - r) + 4 * q * q);
    double det = fabs(a * d - b * c);
    *s1 = sqrt(0.5 * (tr + disc));
    *s2 = det / *s1;
}

/* E_D = sum weight_t E_t with the library's per-triangle energy and
   gradient (bp__triangle_energy), on rest data built as bp_chart_optimize
   builds it with opt.importance (the solver's own assembly, chunks and
   barrier are tested in test_energy.c / test_hash.c) */
typedef struct tsolver {
    bp_energy energy;
    uint32_t nv, nt;
    const uint32_t *tri;
    bp__rest *rest;
} tsolver;

static double objective(const tsolver *S, const double *x, double *g, double *ed)
{
    double sum = 0;
    uint32_t t;
    if (g) memset(g, 0, sizeof(double) * 2 * S->nv);
    for (t = 0; t < S->nt; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        double e = bp__triangle_energy(S->energy, &S->rest[t], x + 2 * (size_t)tr[0], x + 2 * (size_t)tr[1],
                                       x + 2 * (size_t)tr[2], g ? g + 2 * (size_t)tr[0] : NULL,
                                       g ? g + 2 * (size_t)tr[1] : NULL, g ? g + 2 * (size_t)tr[2] : NULL);
        if (e == HUGE_VAL) return *ed = HUGE_VAL;
        sum += S->rest[t].weight * e;
    }
    return *ed = sum;
}

static void test_importance(void)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_chart *ch;
    tsolver S;
    double *imp = NULL, *x, *g, *gd, A = 0, E = 0, fp, fm, ed, h = 1e-6, worst = 0, gmax = 0, worst_e = 0;
    uint32_t t, i;
    if (!BPT_CHECK(bp_read_obj("tests/data/bishop_part_f1000.obj", &mesh, NULL, &err) == BP_OK, "read bishop: %s", err.message))
        return;
    memset(&opt, 0, sizeof opt);
    if (!BPT_CHECK(bp_atlas_build(&atlas, &mesh, &opt, &err) == BP_OK && atlas.num_charts == 1 &&
                   bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) == BP_OK, "bishop: chart and start map")) {
        bp_mesh_free(&mesh, NULL);
        return;
    }
    ch = &atlas.charts[0];
    rng_state = 4242;
    imp = (double *)malloc(sizeof(double) * mesh.num_triangles);
    for (t = 0; t < mesh.num_triangles; t++) imp[t] = exp(2 * srand1());    /* in [e^-2, e^2] */
    /* the solver's rest data, as bp_chart_optimize builds it with opt.importance */
    memset(&S, 0, sizeof S);
    S.energy = BP_ENERGY_SYMMETRIC_DIRICHLET;
    S.nv = ch->num_vertices;
    S.nt = ch->num_triangles;
    S.tri = ch->triangles;
    S.rest = (bp__rest *)malloc(sizeof(bp__rest) * S.nt);
    x = (double *)malloc(sizeof(double) * 2 * S.nv);
    g = (double *)malloc(sizeof(double) * 2 * S.nv);
    gd = (double *)malloc(sizeof(double) * 2 * S.nv);
    for (t = 0; t < S.nt; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        double w, px, py, I = imp[ch->face[t]], k = 1 / sqrt(I);
        bp__rest_shape(bp__pos(&mesh, ch->vertex[tr[0]]), bp__pos(&mesh, ch->vertex[tr[1]]), bp__pos(&mesh, ch->vertex[tr[2]]),
                       &w, &px, &py);
        S.rest[t].m00 = k / w;
        S.rest[t].m01 = -k * px / (w * py);
        S.rest[t].m11 = k / py;
        S.rest[t].weight = 0.5 * w * py * I;
        /* eq 4.1 from the singular values of the unscaled map, computed
           independently: J = D M^-1 */
        {
            const double *u1 = ch->uv + 2 * (size_t)tr[0], *u2 = ch->uv + 2 * (size_t)tr[1], *u3 = ch->uv + 2 * (size_t)tr[2];
            double d00 = u2[0] - u1[0], d10 = u2[1] - u1[1], d01 = u3[0] - u1[0], d11 = u3[1] - u1[1];
            double mi00 = 1 / w, mi01 = -px / (w * py), mi11 = 1 / py, s1, s2, ehat, elib;
            svd2(d00 * mi00, d00 * mi01 + d01 * mi11, d10 * mi00, d10 * mi01 + d11 * mi11, &s1, &s2);
            ehat = I * (s1 * s1 / I + s2 * s2 / I + I / (s1 * s1) + I / (s2 * s2));
            elib = I * bp__triangle_energy(S.energy, &S.rest[t], u1, u2, u3, NULL, NULL, NULL);
            if (fabs(elib - ehat) / ehat > worst_e) worst_e = fabs(elib - ehat) / ehat;
            A += 0.5 * w * py;
            E += 0.5 * w * py * ehat;
        }
    }
    BPT_CHECK(worst_e < 1e-10, "eq 4.1: I * E_t(rest scaled by 1/sqrt I) = I(s1^2/I + s2^2/I + I/s1^2 + I/s2^2) (rel. error %.2g)",
              worst_e);
    /* bp_chart_optimize with opt.importance reports energy_start = sum A_t Ehat_t / A */
    {
        bp_chart copy;
        bp_atlas at2;
        opt.importance = imp;
        opt.max_iterations = 1;
        if (BPT_CHECK(bp_atlas_build(&at2, &mesh, &opt, &err) == BP_OK && bp_chart_init(&at2.charts[0], &mesh, &opt, &err) == BP_OK &&
                      bp_chart_optimize(&at2.charts[0], 0, &mesh, &opt, &err) == BP_OK, "bishop: optimize with importance")) {
            copy = at2.charts[0];
            BPT_CHECK(fabs(copy.energy_start - E / A) < 1e-9 * (E / A),
                      "bp_chart_optimize uses eq 4.1: energy_start %.12g = area-weighted mean of Ehat %.12g", copy.energy_start, E / A);
            BPT_CHECK(copy.energy_end < copy.energy_start, "one iteration decreases the importance energy (%.6g -> %.6g)",
                      copy.energy_start, copy.energy_end);
            bp_atlas_free(&at2);
        }
        opt.importance = NULL;
        opt.max_iterations = 0;
    }
    /* gradient of the importance energy against central differences, at the start
       map and at a perturbed (still valid) map */
    memcpy(x, ch->uv, sizeof(double) * 2 * S.nv);
    {
        int pass;
        for (pass = 0; pass < 2; pass++) {
            if (pass == 1) {
                double f0;
                for (i = 0; i < 2 * S.nv; i++) x[i] += 1e-3 * srand1() * 0.01;
                f0 = objective(&S, x, NULL, &ed);
                if (!BPT_CHECK(f0 < HUGE_VAL, "perturbed map still valid")) break;
            }
            objective(&S, x, g, &ed);
            for (i = 0; i < 2 * S.nv; i++) {
                double xi = x[i];
                x[i] = xi + h; fp = objective(&S, x, NULL, &ed);
                x[i] = xi - h; fm = objective(&S, x, NULL, &ed);
                x[i] = xi;
                gd[i] = (fp - fm) / (2 * h);
                if (fabs(g[i]) > gmax) gmax = fabs(g[i]);
            }
            worst = 0;
            for (i = 0; i < 2 * S.nv; i++) {
                double e = fabs(g[i] - gd[i]) / (gmax + 1e-300);
                if (e > worst) worst = e;
            }
            BPT_CHECK(worst < 1e-6, "importance energy (random I in [e^-2, e^2]): gradient == central differences on %u coordinates "
                      "(%s map; max error %.2g of the largest component %.3g)", 2 * S.nv, pass ? "perturbed" : "start", worst, gmax);
        }
    }
    free(S.rest); free(x); free(g); free(gd);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    /* constant importance I on a flat chart: the optimum is the isometry
       scaled by sqrt(I): UV area = I * 3D area */
    {
        tmesh T;
        int gi, gj, n = 12;
        double I = 4, uva = 0, a3 = 0;
        uint32_t c;
        memset(&T, 0, sizeof T);
        for (gj = 0; gj <= n; gj++)
            for (gi = 0; gi <= n; gi++)
                tm_v(&T, gi + 0.3 * sin(gj * 1.7), 0.9 * gj + 0.2 * cos(gi * 2.3), 0);   /* an irregular flat grid */
        for (gj = 0; gj < n; gj++)
            for (gi = 0; gi < n; gi++) {
                uint32_t v00 = (uint32_t)(gj * (n + 1) + gi);
                tm_t(&T, v00, v00 + 1, v00 + n + 2, 0);
                tm_t(&T, v00, v00 + n + 2, v00 + n + 1, 0);
            }
        tm_finish(&T, 0);
        imp = (double *)realloc(imp, sizeof(double) * T.m.num_triangles);
        for (t = 0; t < T.m.num_triangles; t++) imp[t] = I;
        memset(&opt, 0, sizeof opt);
        opt.importance = imp;
        opt.tolerance = 1e-12;
        if (BPT_CHECK(bp_parameterize(&atlas, &T.m, &opt, &err) == BP_OK, "flat grid with importance 4: %s", err.message)) {
            for (c = 0; c < atlas.num_charts; c++) {
                const bp_chart *C = &atlas.charts[c];
                for (t = 0; t < C->num_triangles; t++) {
                    const double *p = C->uv + 2 * (size_t)C->triangles[3 * t], *q = C->uv + 2 * (size_t)C->triangles[3 * t + 1];
                    const double *r = C->uv + 2 * (size_t)C->triangles[3 * t + 2];
                    uva += 0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
                }
                a3 += C->area3d;
            }
            BPT_CHECK(fabs(uva / a3 - I) < 1e-3 * I, "flat chart, importance %g everywhere: UV area / 3D area = %.6f", I, uva / a3);
            bp_atlas_free(&atlas);
        }
        tm_free(&T);
    }
    free(imp);
}

/* ---- 6. determinism -------------------------------------------------------------- */
static void reverse_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    for (i = count; i-- > 0;) fn(task, i);
}

static void interleaved_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    for (i = 1; i < count; i += 2) fn(task, i);
    for (i = 0; i < count; i += 2) fn(task, i);
}

static void test_determinism(void)
{
    bp_mesh mesh;
    bp_error err;
    bp_options opt;
    bp_atlas atlas;
    double *v0, *v1, *v2, d0 = 0, d1 = 0, d2 = 0;
    int model;
    if (!BPT_CHECK(bp_read_obj("tests/data/spot.obj", &mesh, NULL, &err) == BP_OK, "read spot")) return;
    v0 = (double *)malloc(sizeof(double) * mesh.num_triangles);
    v1 = (double *)malloc(sizeof(double) * mesh.num_triangles);
    v2 = (double *)malloc(sizeof(double) * mesh.num_triangles);
    memset(&opt, 0, sizeof opt);
    opt.max_iterations = 20;
    if (!BPT_CHECK(bp_parameterize(&atlas, &mesh, &opt, &err) == BP_OK, "spot: a map to measure")) goto out;
    for (model = BP_VIEW_UNIFORM; model <= BP_VIEW_SIDE; model++) {
        int same, same_d, ok = 1;
        uint32_t t;
        /* different fillers, so that a call writing nothing cannot pass */
        for (t = 0; t < mesh.num_triangles; t++) { v0[t] = -1.0; v1[t] = -2.0; v2[t] = -3.0; }
        d0 = -1.0; d1 = -2.0; d2 = -3.0;
        memset(&opt.views, 0, sizeof opt.views);
        opt.views.model = model;
        opt.views.direction[1] = 1;
        opt.views.elevation = 20;
        opt.views.samples = 16;
        opt.views.seed = 31337;
        opt.parallel_for = NULL;
        ok &= bp_visibility(&mesh, &opt, v0, &err) == BP_OK;
        ok &= bp_texture_to_screen(&mesh, &atlas, &opt, &d0, &err) == BP_OK;
        opt.parallel_for = reverse_for;
        ok &= bp_visibility(&mesh, &opt, v1, &err) == BP_OK;
        ok &= bp_texture_to_screen(&mesh, &atlas, &opt, &d1, &err) == BP_OK;
        opt.parallel_for = interleaved_for;
        ok &= bp_visibility(&mesh, &opt, v2, &err) == BP_OK;
        ok &= bp_texture_to_screen(&mesh, &atlas, &opt, &d2, &err) == BP_OK;
        BPT_CHECK(ok, "spot, model %d: the six bp_visibility / bp_texture_to_screen calls return BP_OK", model);
        same = !memcmp(v0, v1, sizeof(double) * mesh.num_triangles) && !memcmp(v0, v2, sizeof(double) * mesh.num_triangles);
        same_d = !memcmp(&d0, &d1, sizeof d0) && !memcmp(&d0, &d2, sizeof d0);
        BPT_CHECK(same && same_d, "spot, model %d: bp_visibility and bp_texture_to_screen bit-identical with tasks in "
                  "serial, reverse and interleaved order (%u tasks)", model, (mesh.num_triangles + 63) / 64);
    }
    /* and a different seed does change the estimate (the check can fail) */
    opt.parallel_for = NULL;
    opt.views.model = BP_VIEW_UNIFORM;
    BPT_CHECK(bp_visibility(&mesh, &opt, v0, &err) == BP_OK, "spot, seed 31337: BP_OK");
    opt.views.seed = 31338;
    BPT_CHECK(bp_visibility(&mesh, &opt, v1, &err) == BP_OK, "spot, seed 31338: BP_OK");
    BPT_CHECK(memcmp(v0, v1, sizeof(double) * mesh.num_triangles) != 0, "spot: another seed gives another estimate");
    bp_atlas_free(&atlas);
out:
    free(v0); free(v1); free(v2);
    bp_mesh_free(&mesh, NULL);
}

int main(void)
{
    quick = getenv("BP_TEST_QUICK") != NULL;
    test_bvh();
    test_sphere();
    test_cup_occlusion();
    test_importance();
    test_determinism();
    test_bijective();
    return bpt_finish();
}
