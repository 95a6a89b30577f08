/* test_segment.c - segmentation into several charts (>>segment).

   Inputs: the cow read without its vt (closed, genus 0), torus_with_holes
   (genus 1, 2 loops), fertility (closed, genus 4), two copies of the torus
   in one mesh (two components), and spot with its 13 vt charts.  Each is
   run through bp_parameterize with a chart budget (max_charts), a
   distortion bound (max_distortion) and an atlas (atlas_resolution), on 1
   and on 2 threads.  Every property is checked by code written here, not
   by the library's bookkeeping:
     - partition, by brute force: every mesh triangle is the face of
       exactly one chart triangle in all the charts, on the mesh triangle's
       own vertices, and the atlas's corner_chart / corner_vertex name that
       chart and those chart vertices;
     - each chart is connected (a flood over its own triangles, across
       edges whose two chart vertices both triangles share) and is a disk
       or a disk with holes (chi = V - E + F with E counted as distinct
       vertex pairs equals 2 - b, b the boundary loops walked on the
       half-edges without a reverse twin, b >= 1, b = chart.num_loops);
     - the atlas is valid: bp_check (exact) of every chart alone and of all
       charts together (no two overlap), and every uv in [0,1]^2;
     - at most max_charts charts, more than one on the closed inputs;
     - every chart of two or more triangles has mean distortion (symmetric
       Dirichlet, area-weighted, recomputed here from the map and the 3D
       triangles) at most the bound (one triangle cannot be split further:
       reported, not asserted);
     - the same charts and the same bits of every map on 1 and 2 threads;
     - vt seams are kept: every chart of spot lies inside one of its 13 vt
       charts;
     - without --atlas and without the new options nothing is segmented
       (the charts are bp_atlas_build's), and max_distortion alone splits
       only after the solve;
     - importance steers the new seams: with 25 on one half of the cow and
       1 on the other, the mean importance along the seams the
       segmentation adds is lower than without importance;
     - out of memory at each allocation of bp_atlas_segment and of
       bp_atlas_refine (a cube of 108 triangles on a sphere): the status says so, no
       leak, and every chart is still a valid disk with a valid map;
     - a chart of 65,712 triangles (a cube of 74 x 74 squares a face, on a
       sphere) is labelled on patches first (>>segment, the coarse level):
       the same properties as above, 1 and 2 threads alike;
     - the chart's twins (bp__seg_twins, a counting sort) against a sort of
       all its edges done here, on the cow and that sphere;
     - splitting before the solve: camelhead's segmentation leaves charts
       of 3,738 and 1,622 triangles whose start maps are far from an
       isometry (mean E_SD 163 and 41.5); with an atlas each is split
       before it is optimized, so the atlas has more charts than the
       segmentation made, each inside one of them, none of 1,000 triangles
       or more reporting a start above 16, the atlas valid and the same on
       1 and 2 threads; and on mech-holes-shark (one such chart), failing
       each of the 80 allocations from the split's first on: out of
       memory (or ok, every chart then a valid map), and no leak once the
       atlas is freed. */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#define BP_USE_PTHREADS
#include "bijparam.h"
#include "bptest.h"

/* BP_TEST_QUICK (make test): every fourth allocation of the split's sweep,
   and the twins checked on the cow alone; make check runs the full form. */
static int quick = 0;

#include <math.h>

static int read_mesh(const char *path, bp_mesh *m)
{
    bp_error err;
    bp_status st = bp_read_mesh(path, m, NULL, &err);
    return BPT_CHECK(st == BP_OK, "read %s: %s", path, st ? err.message : "ok");
}

/* ---- one chart, from its own triangles ------------------------------------ */

typedef struct dedge { uint32_t a, b, t; } dedge;

static int dedge_cmp(const void *pa, const void *pb)
{
    const dedge *x = (const dedge *)pa, *y = (const dedge *)pb;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

static long find_dedge(const dedge *e, size_t n, uint32_t a, uint32_t b)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (e[mid].a < a || (e[mid].a == a && e[mid].b < b)) lo = mid + 1; else hi = mid;
    }
    return lo < n && e[lo].a == a && e[lo].b == b ? (long)lo : -1;
}

/* Connected (flood across shared edges), chi = 2 - b with b >= 1 loops. */
static int chart_shape(const bp_chart *ch, char *why, size_t cap)
{
    size_t n = 3 * (size_t)ch->num_triangles, i, nb = 0, pairs = 0;
    dedge *e = (dedge *)malloc(n * sizeof *e);
    uint32_t *next = (uint32_t *)malloc(ch->num_vertices * sizeof(uint32_t));
    unsigned char *seen = (unsigned char *)calloc(ch->num_triangles, 1), *used = (unsigned char *)calloc(ch->num_vertices, 1);
    uint32_t *queue = (uint32_t *)malloc(ch->num_triangles * sizeof(uint32_t)), nq = 0, reached = 0, v, loops = 0, nv = 0;
    long long chi;
    int ok = 1;
    for (i = 0; i < n; i++) {
        e[i].a = ch->triangles[i];
        e[i].b = ch->triangles[i - i % 3 + (i % 3 + 1) % 3];
        e[i].t = (uint32_t)(i / 3);
        used[e[i].a] = 1;
    }
    qsort(e, n, sizeof *e, dedge_cmp);
    for (i = 0; i + 1 < n; i++)
        if (e[i].a == e[i + 1].a && e[i].b == e[i + 1].b) { snprintf(why, cap, "directed edge used twice"); ok = 0; }
    for (v = 0; v < ch->num_vertices; v++) { next[v] = UINT32_MAX; nv += used[v]; }
    for (i = 0; i < n && ok; i++) {
        if (find_dedge(e, n, e[i].b, e[i].a) < 0) {
            if (next[e[i].a] != UINT32_MAX) { snprintf(why, cap, "pinched boundary vertex"); ok = 0; }
            next[e[i].a] = e[i].b;
            nb++;
        } else if (e[i].a < e[i].b)
            pairs++;
    }
    /* flood */
    seen[0] = 1; queue[nq++] = 0;
    while (ok && nq) {
        uint32_t t = queue[--nq], k;
        reached++;
        for (k = 0; k < 3; k++) {
            uint32_t a = ch->triangles[3 * t + k], b = ch->triangles[3 * t + (k + 1) % 3];
            long j = find_dedge(e, n, b, a);
            if (j >= 0 && !seen[e[j].t]) { seen[e[j].t] = 1; queue[nq++] = e[j].t; }
        }
    }
    if (ok && reached != ch->num_triangles) { snprintf(why, cap, "not connected: %u of %u triangles reached", reached, ch->num_triangles); ok = 0; }
    /* loops */
    for (v = 0; ok && v < ch->num_vertices; v++) {
        uint32_t w = v, steps = 0;
        if (next[v] == UINT32_MAX || used[v] == 2) continue;
        do { used[w] = 2; w = next[w]; steps++; } while (w != UINT32_MAX && w != v && used[w] != 2 && steps <= nb);
        if (w != v) { snprintf(why, cap, "boundary does not close"); ok = 0; }
        loops++;
    }
    chi = (long long)nv - (long long)(pairs + nb) + ch->num_triangles;
    if (ok && (loops < 1 || chi != 2 - (long long)loops || loops != ch->num_loops)) {
        snprintf(why, cap, "chi %lld with %u loops (chart says %u): not a disk with holes", chi, loops, ch->num_loops);
        ok = 0;
    }
    free(e); free(next); free(seen); free(used); free(queue);
    return ok;
}

/* Mean symmetric Dirichlet energy of a chart, area-weighted, from the 3D
   triangles and the map: sigma1^2 + sigma2^2 + their inverses.  The
   energy is not scale-invariant and the atlas scales every chart to one
   texel density, so on a packed atlas the bound is checked at the best
   scale of each chart, which is at most its energy at the scale the
   optimizer left it (where the library compares it with the bound). */
static double chart_esd(const bp_chart *ch, const bp_mesh *m, int best_scale)
{
    double sa = 0, sb = 0, area = 0;
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * t;
        const double *p0 = m->positions + 3 * ch->vertex[tr[0]], *p1 = m->positions + 3 * ch->vertex[tr[1]],
                     *p2 = m->positions + 3 * ch->vertex[tr[2]];
        const double *u0 = ch->uv + 2 * tr[0], *u1 = ch->uv + 2 * tr[1], *u2 = ch->uv + 2 * tr[2];
        double e1[3], e2[3], l1, x2, y2, a3, du1[2], du2[2], J[4], fro, det;
        int k;
        for (k = 0; k < 3; k++) { e1[k] = p1[k] - p0[k]; e2[k] = p2[k] - p0[k]; }
        l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
        x2 = (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / l1;
        y2 = sqrt(fmax(0, e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2] - x2 * x2));
        a3 = 0.5 * l1 * y2;
        if (!(a3 > 0)) continue;
        du1[0] = u1[0] - u0[0]; du1[1] = u1[1] - u0[1];
        du2[0] = u2[0] - u0[0]; du2[1] = u2[1] - u0[1];
        /* J maps the rest triangle (0,0), (l1,0), (x2,y2) onto the uv one */
        J[0] = du1[0] / l1; J[2] = du1[1] / l1;
        J[1] = (du2[0] - J[0] * x2) / y2; J[3] = (du2[1] - J[2] * x2) / y2;
        fro = J[0] * J[0] + J[1] * J[1] + J[2] * J[2] + J[3] * J[3];
        det = J[0] * J[3] - J[1] * J[2];
        sa += a3 * fro;                     /* s1^2 + s2^2 */
        sb += a3 * fro / (det * det);       /* s1^-2 + s2^-2 = (s1^2 + s2^2) / (s1 s2)^2 */
        area += a3;
    }
    /* at the map's own scale, or at the best uniform scale s of the map:
       min over s of s^2 A + s^-2 B = 2 sqrt(A B) */
    return best_scale ? 2 * sqrt(sa * sb) / area : (sa + sb) / area;
}

/* ---- the whole atlas ------------------------------------------------------ */

/* Partition, per-chart shape, validity of each chart and of all together,
   uvs in [0,1]^2 (with an atlas). */
static void check_atlas(const char *what, const bp_mesh *m, const bp_atlas *at, int unit)
{
    uint32_t *owner = (uint32_t *)malloc(m->num_triangles * sizeof(uint32_t)), *cnt = (uint32_t *)calloc(m->num_triangles, 4);
    uint32_t c, t, k, f, nt = 0, nv = 0, bad_shape = 0, bad_check = 0, bad_corner = 0, bad_vertex = 0, out = 0, multi = 0;
    uint32_t *tri, ot = 0, ov = 0;
    double *uv;
    char why[160] = "", first[200] = "";
    bp_check_report rep;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        nt += ch->num_triangles;
        nv += ch->num_vertices;
        for (t = 0; t < ch->num_triangles; t++) {
            f = ch->face[t];
            cnt[f]++;
            owner[f] = c;
            for (k = 0; k < 3; k++) {
                uint32_t cv = ch->triangles[3 * t + k], j, hit = 0;
                for (j = 0; j < 3; j++) hit |= m->triangles[3 * f + j] == ch->vertex[cv];
                bad_vertex += !hit;
                /* the atlas names this chart and one of this triangle's chart vertices */
                hit = 0;
                for (j = 0; j < 3; j++) hit |= at->corner_vertex[3 * f + k] == ch->triangles[3 * t + j];
                bad_corner += at->corner_chart[3 * f + k] != c || !hit;
            }
        }
        if (!chart_shape(ch, why, sizeof why)) { if (!bad_shape++) snprintf(first, sizeof first, "chart %u: %s", c, why); }
        if (!ch->uv || bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK) bad_check++;
        for (k = 0; ch->uv && k < 2 * ch->num_vertices; k++) out += unit && !(ch->uv[k] >= 0 && ch->uv[k] <= 1);
    }
    for (f = 0; f < m->num_triangles; f++) multi += cnt[f] != 1;
    BPT_CHECK(multi == 0 && nt == m->num_triangles, "%s: every one of the %u triangles in exactly one chart (%u not)",
              what, m->num_triangles, multi);
    BPT_CHECK(bad_vertex == 0 && bad_corner == 0, "%s: charts on the mesh's vertices (%u wrong), corner_chart/vertex agree (%u wrong)",
              what, bad_vertex, bad_corner);
    BPT_CHECK(bad_shape == 0, "%s: all %u charts connected disks (with holes) %s", what, at->num_charts, first);
    BPT_CHECK(bad_check == 0, "%s: every chart alone passes bp_check (%u do not)", what, bad_check);
    if (unit) BPT_CHECK(out == 0, "%s: every uv in [0,1]^2 (%u coordinates outside)", what, out);
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof(uint32_t));
    uv = (double *)malloc(2 * (size_t)nv * sizeof(double));
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        for (t = 0; t < 3 * ch->num_triangles; t++) tri[3 * ot + t] = ch->triangles[t] + ov;
        if (ch->uv) memcpy(uv + 2 * ov, ch->uv, 2 * ch->num_vertices * sizeof(double));
        ot += ch->num_triangles;
        ov += ch->num_vertices;
    }
    BPT_CHECK(bp_check(tri, nt, uv, nv, NULL, &rep, NULL) == BP_OK,
              "%s: the %u charts together pass bp_check (no overlap; %u boundary intersections, %u nested)",
              what, at->num_charts, rep.boundary_intersections, rep.nested);
    free(tri); free(uv); free(owner); free(cnt);
}

static bp_options seg_options(int threads, uint32_t max_charts, double bound, int res)
{
    bp_options o;
    bp_options_init(&o);
    o.threads = threads;
    o.max_charts = max_charts;
    o.max_distortion = bound;
    o.atlas_resolution = res;
    o.padding = res ? 4 : 0;
    return o;
}

/* The same charts and the same bits of every map. */
static int same_atlas(const bp_atlas *x, const bp_atlas *y)
{
    uint32_t c;
    if (x->num_charts != y->num_charts) return 0;
    for (c = 0; c < x->num_charts; c++) {
        const bp_chart *a = &x->charts[c], *b = &y->charts[c];
        if (a->num_triangles != b->num_triangles || a->num_vertices != b->num_vertices) return 0;
        if (memcmp(a->face, b->face, a->num_triangles * sizeof(uint32_t)) ||
            memcmp(a->triangles, b->triangles, 3 * a->num_triangles * sizeof(uint32_t)))
            return 0;
        if ((a->uv == NULL) != (b->uv == NULL) || (a->uv && memcmp(a->uv, b->uv, 2 * a->num_vertices * sizeof(double))))
            return 0;
    }
    return 1;
}

/* bp_parameterize with a budget and a bound, on 1 and 2 threads. */
static void run(const char *what, const bp_mesh *m, uint32_t max_charts, double bound, int closed)
{
    bp_atlas at1, at2;
    bp_error err;
    bp_options o1 = seg_options(1, max_charts, bound, 1024), o2 = seg_options(2, max_charts, bound, 1024);
    uint32_t c, above = 0, single = 0;
    double worst = 0;
    char name[160];
    if (!BPT_CHECK(bp_parameterize(&at1, m, &o1, &err) == BP_OK, "%s: parameterized (%s)", what, err.message)) return;
    snprintf(name, sizeof name, "%s, max %u charts, bound %g", what, max_charts, bound);
    check_atlas(name, m, &at1, 1);
    BPT_CHECK(at1.num_charts <= max_charts && (!closed || at1.num_charts > 1),
              "%s: %u charts, at most %u%s", name, at1.num_charts, max_charts, closed ? " and more than one" : "");
    for (c = 0; c < at1.num_charts; c++) {
        double e = chart_esd(&at1.charts[c], m, 1);
        if (at1.charts[c].num_triangles == 1) { single++; continue; }
        above += !(e <= bound * (1 + 1e-12));
        if (e > worst) worst = e;
    }
    if (at1.num_charts < max_charts)
        BPT_CHECK(above == 0, "%s: every chart of 2+ triangles at mean E_SD <= %g (worst %.4f, %u above; %u single triangles)",
                  name, bound, worst, above, single);
    else
        printf("note %s: the chart budget is used up (worst chart %.4f)\n", name, worst);
    printf("note %s: %u charts, utilization %.3f\n", name, at1.num_charts, at1.utilization);
    if (BPT_CHECK(bp_parameterize(&at2, m, &o2, &err) == BP_OK, "%s: parameterized on 2 threads (%s)", what, err.message)) {
        BPT_CHECK(same_atlas(&at1, &at2), "%s: the same charts and bits on 1 and 2 threads", name);
        bp_atlas_free(&at2);
    }
    bp_atlas_free(&at1);
}

/* Every chart of the segmented atlas inside one chart of the unsegmented
   one (the vt seams are kept). */
static void keeps_seams(const char *what, const bp_mesh *m)
{
    bp_atlas base, seg;
    bp_error err;
    bp_options o = seg_options(2, 0, 0, 1024);
    uint32_t c, t, crossing = 0;
    if (!BPT_CHECK(bp_atlas_build(&base, m, NULL, &err) == BP_OK, "%s: built (%s)", what, err.message)) return;
    if (BPT_CHECK(bp_parameterize(&seg, m, &o, &err) == BP_OK, "%s: atlas (%s)", what, err.message)) {
        for (c = 0; c < seg.num_charts; c++)
            for (t = 1; t < seg.charts[c].num_triangles; t++)
                crossing += base.corner_chart[3 * seg.charts[c].face[t]] != base.corner_chart[3 * seg.charts[c].face[0]];
        BPT_CHECK(seg.num_charts > base.num_charts && crossing == 0,
                  "%s: %u charts from %u, each inside one vt chart (%u triangles outside theirs)", what,
                  seg.num_charts, base.num_charts, crossing);
        check_atlas(what, m, &seg, 1);
        bp_atlas_free(&seg);
    }
    bp_atlas_free(&base);
}

/* No atlas, no new options: the charts are bp_atlas_build's.  The bound
   alone: split only after the solve, every chart (2+ triangles) under it. */
static void defaults(const char *what, const bp_mesh *m, double bound)
{
    bp_atlas base, at;
    bp_error err;
    bp_options o;
    uint32_t c, above = 0;
    if (!BPT_CHECK(bp_atlas_build(&base, m, NULL, &err) == BP_OK, "%s: built (%s)", what, err.message)) return;
    bp_options_init(&o);
    if (BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_OK, "%s: default options (%s)", what, err.message)) {
        BPT_CHECK(at.num_charts == base.num_charts, "%s: default options keep bp_atlas_build's %u charts (%u)", what,
                  base.num_charts, at.num_charts);
        bp_atlas_free(&at);
    }
    o.max_distortion = bound;
    if (BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_OK, "%s: max_distortion %g (%s)", what, bound, err.message)) {
        char name[160];
        snprintf(name, sizeof name, "%s, max_distortion %g alone", what, bound);
        check_atlas(name, m, &at, 0);
        for (c = 0; c < at.num_charts; c++)
            above += at.charts[c].num_triangles > 1 && !(chart_esd(&at.charts[c], m, 0) <= bound * (1 + 1e-12));
        BPT_CHECK(at.num_charts > base.num_charts && above == 0, "%s: %u charts, none of 2+ triangles above the bound (%u)",
                  name, at.num_charts, above);
        bp_atlas_free(&at);
    }
    o.max_distortion = -1;
    BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_ERR_INVALID_ARGUMENT, "%s: max_distortion -1 refused (%s)", what,
              err.message);
    bp_atlas_free(&base);
}

/* Length-weighted mean of (w_f + w_g) / 2 over the mesh edges between two
   triangles f, g that are in one chart of `base` but in two of `seg`: the
   seams the segmentation added. */
static double mean_along_new_seams(const bp_mesh *m, const bp_atlas *base, const bp_atlas *seg, const double *w,
                                   uint32_t *count)
{
    size_t n = 3 * (size_t)m->num_triangles, i;
    dedge *e = (dedge *)malloc(n * sizeof *e);
    double sum = 0, len = 0;
    *count = 0;
    for (i = 0; i < n; i++) {
        uint32_t a = m->triangles[i], b = m->triangles[i - i % 3 + (i % 3 + 1) % 3];
        e[i].a = a < b ? a : b;
        e[i].b = a < b ? b : a;
        e[i].t = (uint32_t)(i / 3);
    }
    qsort(e, n, sizeof *e, dedge_cmp);
    for (i = 0; i + 1 < n; i++) {
        uint32_t f = e[i].t, g = e[i + 1].t;
        const double *p = m->positions + 3 * e[i].a, *q = m->positions + 3 * e[i].b;
        double l;
        if (e[i].a != e[i + 1].a || e[i].b != e[i + 1].b) continue;
        if (base->corner_chart[3 * f] != base->corner_chart[3 * g]) continue;
        if (seg->corner_chart[3 * f] == seg->corner_chart[3 * g]) continue;
        l = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        sum += l * 0.5 * (w[f] + w[g]);
        len += l;
        ++*count;
    }
    free(e);
    return len > 0 ? sum / len : 0;
}

/* Importance steers the new seams: 25 on one half of the mesh, 1 on the
   other; the charts grown with it put less of their seams on the
   important half than those grown without it. */
static void importance_steers(const char *what, const bp_mesh *m)
{
    bp_atlas base, plain, steered;
    bp_error err;
    bp_options o = seg_options(1, 0, 0, 1024);
    double *w = bpt_half_importance(m), a, b;
    uint32_t na, nb;
    if (BPT_CHECK(bp_atlas_build(&base, m, &o, &err) == BP_OK && bp_atlas_build(&plain, m, &o, &err) == BP_OK &&
                  bp_atlas_segment(&plain, m, &o, &err) == BP_OK, "%s: segmented (%s)", what, err.message)) {
        o.importance = w;
        if (BPT_CHECK(bp_atlas_build(&steered, m, &o, &err) == BP_OK && bp_atlas_segment(&steered, m, &o, &err) == BP_OK,
                      "%s: segmented with importance (%s)", what, err.message)) {
            a = mean_along_new_seams(m, &base, &plain, w, &na);
            b = mean_along_new_seams(m, &base, &steered, w, &nb);
            BPT_CHECK(na > 0 && nb > 0 && b < a, "%s: painted importance (25 on one half): mean importance along the "
                      "new seams %.2f < %.2f without it (%u and %u seam edges, %u and %u charts)", what, b, a, nb, na,
                      steered.num_charts, plain.num_charts);
            bp_atlas_free(&steered);
        }
        bp_atlas_free(&plain);
        bp_atlas_free(&base);
    }
    free(w);
}

/* A closed cube of side 1, each face an n x n grid of squares split in two. */
static bp_mesh cube(uint32_t n)
{
    bp_mesh m = bpt_mesh_new(6 * (n + 1) * (n + 1), 12 * n * n);
    uint32_t f, i, j, v = 0, t = 0, g, *first = (uint32_t *)malloc((size_t)(n + 1) * (n + 1) * (n + 1) * sizeof(uint32_t));
    uint32_t *cell = (uint32_t *)malloc((size_t)m.num_vertices * sizeof(uint32_t));
    for (g = 0; g < (n + 1) * (n + 1) * (n + 1); g++) first[g] = UINT32_MAX;
    for (f = 0; f < 6; f++) {
        uint32_t ax = f / 2, s = f % 2, u = (ax + 1) % 3, w = (ax + 2) % 3, base = v;
        for (j = 0; j <= n; j++)
            for (i = 0; i <= n; i++, v++) {
                uint32_t q[3];
                m.positions[3 * v + ax] = s;
                m.positions[3 * v + u] = (double)i / n;
                m.positions[3 * v + w] = (double)j / n;
                q[ax] = s * n; q[u] = i; q[w] = j;       /* the grid point, as integers */
                cell[v] = (q[0] * (n + 1) + q[1]) * (n + 1) + q[2];
                if (first[cell[v]] == UINT32_MAX) first[cell[v]] = v;
            }
        for (j = 0; j < n; j++)
            for (i = 0; i < n; i++) {
                uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
                /* outward: counter-clockwise seen from outside (s = 1: u, w order; s = 0: reversed) */
                if (s) { m.triangles[3*t] = a; m.triangles[3*t+1] = b; m.triangles[3*t+2] = d; t++;
                         m.triangles[3*t] = a; m.triangles[3*t+1] = d; m.triangles[3*t+2] = c; t++; }
                else   { m.triangles[3*t] = a; m.triangles[3*t+1] = d; m.triangles[3*t+2] = b; t++;
                         m.triangles[3*t] = a; m.triangles[3*t+1] = c; m.triangles[3*t+2] = d; t++; }
            }
    }
    for (t = 0; t < 3 * m.num_triangles; t++)   /* weld the faces' shared edges: one closed surface */
        m.triangles[t] = first[cell[m.triangles[t]]];
    free(first);
    free(cell);
    return m;
}

/* Failing each allocation of bp_atlas_segment, then of bp_atlas_refine:
   BP_ERR_OUT_OF_MEMORY (or BP_OK when the failure fell where no call is
   made), every chart still a valid disk with its map valid, and nothing
   leaked once the atlas is freed. */
static void out_of_memory(const bp_mesh *m)
{
    int phase;
    for (phase = 0; phase < 2; phase++) {
        long k, total = 0, wrong = 0, leaks = 0, broken = 0;
        bpt_oom counter;
        bp_options o = seg_options(1, 0, phase ? 4.05 : 0, phase ? 0 : 64);
        bpt_oom_use(&o, &counter);
        for (k = 0;; k++) {
            bp_atlas at;
            bp_error err;
            bp_status st;
            uint32_t c;
            char why[160];
            counter.fail_at = 0;
            st = bp_atlas_build(&at, m, &o, &err);
            if (st == BP_OK && phase) st = bp_atlas_solve(&at, m, &o, &err);
            if (st != BP_OK) { BPT_CHECK(0, "out-of-memory sweep set-up: %s", err.message); break; }
            counter.calls = 0;
            counter.fail_at = k;
            st = phase ? bp_atlas_refine(&at, m, &o, &err) : bp_atlas_segment(&at, m, &o, &err);
            counter.fail_at = 0;
            if (k == 0) total = counter.calls;
            else if (st != BP_ERR_OUT_OF_MEMORY && st != BP_OK) wrong++;
            for (c = 0; c < at.num_charts; c++) {
                const bp_chart *ch = &at.charts[c];
                bp_check_report rep;
                if (!chart_shape(ch, why, sizeof why) ||
                    (ch->uv && bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK))
                    broken++;
            }
            bp_atlas_free(&at);
            if (counter.live != 0) leaks++;
            if (k > 0 && k >= total) break;
        }
        BPT_CHECK(total > 0 && wrong == 0 && leaks == 0 && broken == 0,
                  "failing each of the %ld allocations of %s: out of memory or ok (%ld other), no leak (%ld), "
                  "every chart still a valid disk (%ld broken)", total,
                  phase ? "bp_atlas_refine (bound 4.05)" : "bp_atlas_segment", wrong, leaks, broken);
    }
}

/* Splitting before the solve (the header comment). */
static void splits_before_solve(const char *what, const bp_mesh *m)
{
    bp_atlas seg, at, at2;
    bp_error err;
    bp_options o = seg_options(1, 0, 0, 1024), o2 = seg_options(2, 0, 0, 1024);
    uint32_t c, t, crossing = 0, high = 0;
    if (!BPT_CHECK(bp_atlas_build(&seg, m, &o, &err) == BP_OK && bp_atlas_segment(&seg, m, &o, &err) == BP_OK,
                   "%s: segmented (%s)", what, err.message))
        return;
    if (BPT_CHECK(bp_parameterize(&at, m, &o, &err) == BP_OK, "%s: atlas (%s)", what, err.message)) {
        for (c = 0; c < at.num_charts; c++) {
            for (t = 1; t < at.charts[c].num_triangles; t++)
                crossing += seg.corner_chart[3 * at.charts[c].face[t]] != seg.corner_chart[3 * at.charts[c].face[0]];
            high += at.charts[c].num_triangles >= 1000 && !(at.charts[c].energy_start <= 16);
        }
        BPT_CHECK(at.num_charts > seg.num_charts && crossing == 0 && high == 0,
                  "%s: split before the solve: %u charts from the segmentation's %u, each inside one (%u triangles "
                  "outside), %u of 1,000+ triangles starting above 16", what, at.num_charts, seg.num_charts, crossing,
                  high);
        check_atlas(what, m, &at, 1);
        if (BPT_CHECK(bp_parameterize(&at2, m, &o2, &err) == BP_OK, "%s: atlas on 2 threads (%s)", what, err.message)) {
            BPT_CHECK(same_atlas(&at, &at2), "%s: the same charts and bits on 1 and 2 threads", what);
            bp_atlas_free(&at2);
        }
        bp_atlas_free(&at);
    }
    bp_atlas_free(&seg);
}

/* The counting allocator, also noting the call that first asks for
   `mark` bytes. */
typedef struct mark_oom { bpt_oom c; size_t mark; long at; } mark_oom;

static void *mark_alloc(void *user, size_t size)
{
    mark_oom *o = (mark_oom *)user;
    if (size == o->mark && !o->at) o->at = o->c.calls + 1;
    return bpt_oom_alloc(&o->c, size);
}

static void mark_free(void *user, void *p) { bpt_oom_free(&((mark_oom *)user)->c, p); }

/* Out of memory in the split before the solve (the header comment): the
   split starts with the mesh-size scratch of 3 F uint32 (bp__seg_mesh). */
static void split_out_of_memory(const char *what, const bp_mesh *m)
{
    mark_oom o;
    bp_options opt = seg_options(1, 0, 0, 1024);
    long k, wrong = 0, leaks = 0, broken = 0, first = 0, step = quick ? 4 : 1;
    memset(&o, 0, sizeof o);
    o.mark = 3 * (size_t)m->num_triangles * sizeof(uint32_t);
    opt.allocator.alloc = mark_alloc;
    opt.allocator.free = mark_free;
    opt.allocator.user = &o;
    for (k = 0; k <= 80; k += k ? step : 1) {
        bp_atlas at;
        bp_error err;
        bp_status st;
        uint32_t c;
        char why[160];
        o.c.fail_at = 0;
        st = bp_atlas_build(&at, m, &opt, &err);
        if (st == BP_OK) st = bp_atlas_segment(&at, m, &opt, &err);
        if (st != BP_OK) { BPT_CHECK(0, "%s: split sweep set-up: %s", what, err.message); return; }
        o.c.calls = 0;
        o.at = 0;
        o.c.fail_at = k ? first + k - 1 : 0;
        st = bp_atlas_solve(&at, m, &opt, &err);
        o.c.fail_at = 0;
        if (k == 0) {
            first = o.at;
            if (!BPT_CHECK(st == BP_OK && first > 0, "%s: the solve splits a chart (its scratch is allocation %ld)", what, first)) {
                bp_atlas_free(&at);
                return;
            }
        } else if (st != BP_ERR_OUT_OF_MEMORY && st != BP_OK)
            wrong++;
        for (c = 0; c < at.num_charts; c++) {
            const bp_chart *ch = &at.charts[c];
            bp_check_report rep;
            if (st == BP_OK && (!ch->uv || !chart_shape(ch, why, sizeof why) ||
                bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK))
                broken++;
        }
        bp_atlas_free(&at);
        if (o.c.live != 0) leaks++;
    }
    BPT_CHECK(wrong == 0 && leaks == 0 && broken == 0, "%s: failing each %sof 80 allocations from the split's first: "
              "out of memory or ok (%ld other), no leak once the atlas is freed (%ld), ok only with every chart a valid "
              "map (%ld not)", what, quick ? "fourth " : "", wrong, leaks, broken);
}

/* A cube of n x n squares a face, on the unit sphere: not developable. */
static bp_mesh sphere(uint32_t n)
{
    bp_mesh m = cube(n);
    uint32_t v;
    for (v = 0; v < m.num_vertices; v++) {
        double *p = m.positions + 3 * v, r;
        p[0] -= 0.5; p[1] -= 0.5; p[2] -= 0.5;
        r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        p[0] /= r; p[1] /= r; p[2] /= r;
    }
    return m;
}

static int pair_cmp(const void *pa, const void *pb)
{
    const uint32_t *a = (const uint32_t *)pa, *b = (const uint32_t *)pb;
    int k;
    for (k = 0; k < 3; k++) if (a[k] != b[k]) return a[k] < b[k] ? -1 : 1;
    return 0;
}

/* bp__seg_twins of every chart of m's atlas (as bp_atlas_build makes it)
   against twins found here: the corner edges sorted by (smaller end,
   larger end, corner edge), a pair of opposite directions twinned. */
static void twins_by_sort(const char *what, const bp_mesh *m)
{
    bp_atlas at;
    bp_error err;
    bp_options o = seg_options(1, 0, 0, 1024);
    uint32_t c, bad = 0, pairs = 0;
    if (!BPT_CHECK(bp_atlas_build(&at, m, &o, &err) == BP_OK, "%s: built (%s)", what, err.message)) return;
    for (c = 0; c < at.num_charts; c++) {
        const bp_chart *ch = &at.charts[c];
        uint32_t nc = 3 * ch->num_triangles, ce, i, j;
        uint32_t *tw = (uint32_t *)malloc(nc * sizeof(uint32_t)), *ref = (uint32_t *)malloc(nc * sizeof(uint32_t));
        uint32_t *e = (uint32_t *)malloc(3 * (size_t)nc * sizeof(uint32_t));
        for (ce = 0; ce < nc; ce++) {
            uint32_t u = ch->triangles[ce], v = ch->triangles[ce - ce % 3 + (ce % 3 + 1) % 3];
            e[3 * ce] = u < v ? u : v; e[3 * ce + 1] = u < v ? v : u; e[3 * ce + 2] = ce;
            ref[ce] = BP__NONE;
        }
        qsort(e, nc, 3 * sizeof(uint32_t), pair_cmp);
        for (i = 0; i < nc; i = j) {
            for (j = i + 1; j < nc && e[3 * j] == e[3 * i] && e[3 * j + 1] == e[3 * i + 1]; j++) {}
            if (j - i == 2 && ch->triangles[e[3 * i + 2]] != ch->triangles[e[3 * i + 5]]) {
                ref[e[3 * i + 2]] = e[3 * i + 5];
                ref[e[3 * i + 5]] = e[3 * i + 2];
                pairs++;
            }
        }
        if (!bp__seg_twins(&at.allocator, ch, tw)) bad++;
        else for (ce = 0; ce < nc; ce++) bad += tw[ce] != ref[ce];
        free(tw); free(ref); free(e);
    }
    BPT_CHECK(bad == 0 && pairs > 0, "%s: bp__seg_twins = the twins of a sort of the chart's edges (%u pairs, %u differ)",
              what, pairs, bad);
    bp_atlas_free(&at);
}

int main(void)
{
    bp_mesh m = sphere(3);
    out_of_memory(&m);
    bpt_mesh_free(&m);
    quick = getenv("BP_TEST_QUICK") != NULL;
    m = sphere(74);
    if (!quick) twins_by_sort("sphere of 65,712 triangles", &m);   /* the cow's below in make test */
    run("sphere of 65,712 triangles (the coarse level)", &m, 400, 4.1, 1);
    bpt_mesh_free(&m);
    if (read_mesh("tests/data/cow_param_withSUV.obj", &m)) {
        uint32_t *keep = m.corner_uv;
        m.corner_uv = NULL;                            /* read without its vt: closed, genus 0 */
        run("cow without vt (closed, genus 0)", &m, 60, 4.1, 1);
        run("cow without vt (closed, genus 0)", &m, 6, 4.1, 1);
        defaults("cow without vt", &m, 4.2);
        twins_by_sort("cow without vt", &m);
        m.corner_uv = keep;
        importance_steers("cow with its vt (one chart)", &m);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/torus_with_holes.obj", &m)) {
        bp_mesh two = bpt_concat(&m, &m, 40);
        run("torus_with_holes (genus 1, 2 loops)", &m, 40, 4.05, 1);
        run("two torus_with_holes (two components)", &two, 30, 4.05, 1);
        bpt_mesh_free(&two);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/fertility.off", &m)) {
        run("fertility (closed, genus 4)", &m, 80, 4.1, 1);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/camelhead.off", &m)) {
        splits_before_solve("camelhead", &m);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/mech-holes-shark.off", &m)) {
        split_out_of_memory("mech-holes-shark", &m);
        bp_mesh_free(&m, NULL);
    }
    if (read_mesh("tests/data/spot.obj", &m)) {
        keeps_seams("spot (13 vt charts)", &m);
        bp_mesh_free(&m, NULL);
    }
    return bpt_finish();
}
