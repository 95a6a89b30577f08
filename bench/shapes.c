/* bench/shapes.c - the synthetic shapes of fig 4.4 (chapter 4) as OBJ files.

       cc -std=c99 -O2 bench/shapes.c -o build/bench/shapes -lm
       build/bench/shapes OUTDIR        writes OUTDIR/{cup,holes,ripple,sphere}.obj

   Every file is a closed or open triangle mesh whose `vt` indices cut it into
   charts (a chart vertex is the pair (v, vt)); every chart is a topological
   disk, so `build/bijparam FILE` accepts it.  The vt coordinates written are
   only placeholders (the library uses the indices to find the seams and
   computes its own map).  Shapes, all about 2 units across:

   cup     a thin-walled cup made by revolving a closed profile about +y:
           outer bottom (radius 1 at y = 0), outer wall up to y = 2, a flat
           rim 0.08 wide, the inner wall down to y = 0.08 and the inner
           bottom.  The surface is closed (a sphere) with the cavity open to
           +y.  Cut into four identical quadrant charts along the meridians
           at 0, 90, 180 and 270 degrees: each chart runs from the centre of
           the outer bottom over the wall and the rim down into the cup to
           the centre of the inner bottom (as in fig 4.5).
   holes   a cube frame: the cube [-1,1]^3 with a square tunnel of half width
           0.5 through each pair of opposite faces (genus 5), made of
           axis-aligned quads on a 16^3 lattice.  Cut into eight identical
           corner charts by the planes x = 0, y = 0, z = 0 (the dissertation's
           "eight identical corners"); each corner is then a sphere with
           three holes, made a disk by "a seam on the inside": the three
           inner edges of the corner's arms that meet at its inner vertex
           (+-0.5, +-0.5, +-0.5) are cut.
   ripple  an open cylinder of radius 1 + 0.12 sin(2 pi 5 y / 3), y in
           [0, 3], axis +y: horizontal ripples, so the visible side of each
           ripple changes quickly with the view.  One vertical seam at
           angle 0 makes it a single disk chart.
   sphere  a UV sphere of radius 1 (axis +y), cut at the equator y = 0 into
           two hemisphere charts.

   All triangles are oriented with outward normals (checked: positive
   signed volume for the closed shapes). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

typedef struct shape {
    double *v; int nv, cv;
    int *t; int nt, ct;           /* 3 per triangle */
    int *chart;                   /* per triangle   */
    int *seam; int ns, cs;        /* extra seam edges (pairs) inside charts */
} shape;

static void *xrealloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q) { fprintf(stderr, "shapes: out of memory\n"); exit(1); }
    return q;
}

static int add_v(shape *s, double x, double y, double z)
{
    if (s->nv == s->cv) { s->cv = s->cv ? 2 * s->cv : 1024; s->v = (double *)xrealloc(s->v, sizeof(double) * 3 * s->cv); }
    s->v[3 * s->nv] = x; s->v[3 * s->nv + 1] = y; s->v[3 * s->nv + 2] = z;
    return s->nv++;
}

static void add_t(shape *s, int a, int b, int c, int chart)
{
    if (s->nt == s->ct) {
        s->ct = s->ct ? 2 * s->ct : 1024;
        s->t = (int *)xrealloc(s->t, sizeof(int) * 3 * s->ct);
        s->chart = (int *)xrealloc(s->chart, sizeof(int) * s->ct);
    }
    s->t[3 * s->nt] = a; s->t[3 * s->nt + 1] = b; s->t[3 * s->nt + 2] = c;
    s->chart[s->nt++] = chart;
}

static void add_seam(shape *s, int a, int b)
{
    if (s->ns == s->cs) { s->cs = s->cs ? 2 * s->cs : 256; s->seam = (int *)xrealloc(s->seam, sizeof(int) * 2 * s->cs); }
    s->seam[2 * s->ns] = a < b ? a : b; s->seam[2 * s->ns + 1] = a < b ? b : a;
    s->ns++;
}

static void shape_free(shape *s)
{
    free(s->v); free(s->t); free(s->chart); free(s->seam);
    memset(s, 0, sizeof *s);
}

/* signed volume (closed meshes: > 0 when normals point outward) */
static double volume(const shape *s)
{
    double vol = 0;
    int i;
    for (i = 0; i < s->nt; i++) {
        const double *a = s->v + 3 * s->t[3 * i], *b = s->v + 3 * s->t[3 * i + 1], *c = s->v + 3 * s->t[3 * i + 2];
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    }
    return vol;
}

static void flip_all(shape *s)
{
    int i;
    for (i = 0; i < s->nt; i++) { int k = s->t[3 * i + 1]; s->t[3 * i + 1] = s->t[3 * i + 2]; s->t[3 * i + 2] = k; }
}

/* ---- writing with vt seams ------------------------------------------------
   Corners (t, v) are merged across every edge whose two triangles are in
   the same chart and which is not a seam edge; each merged class is one vt. */
typedef struct edge_rec { int a, b, t; } edge_rec;

static int edge_cmp(const void *p, const void *q)
{
    const edge_rec *x = (const edge_rec *)p, *y = (const edge_rec *)q;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    return x->t < y->t ? -1 : x->t > y->t;
}

static int seam_cmp(const void *p, const void *q)
{
    const int *x = (const int *)p, *y = (const int *)q;
    if (x[0] != y[0]) return x[0] < y[0] ? -1 : 1;
    return x[1] < y[1] ? -1 : x[1] > y[1];
}

static int uf_find(int *p, int i)
{
    while (p[i] != i) { p[i] = p[p[i]]; i = p[i]; }
    return i;
}

static int corner_of(const shape *s, int t, int v)
{
    int k;
    for (k = 0; k < 3; k++) if (s->t[3 * t + k] == v) return 3 * t + k;
    return -1;
}

static int write_obj(const shape *s, const char *path, const char *comment)
{
    int i, n = 3 * s->nt, nvt = 0, *parent = (int *)xrealloc(NULL, sizeof(int) * n), *vt = (int *)xrealloc(NULL, sizeof(int) * n);
    edge_rec *E = (edge_rec *)xrealloc(NULL, sizeof(edge_rec) * n);
    int *seam = (int *)xrealloc(NULL, sizeof(int) * 2 * (s->ns ? s->ns : 1));
    FILE *f;
    memcpy(seam, s->seam, sizeof(int) * 2 * s->ns);
    qsort(seam, s->ns, 2 * sizeof(int), seam_cmp);
    for (i = 0; i < n; i++) {
        int a = s->t[i], b = s->t[i - i % 3 + (i % 3 + 1) % 3];
        parent[i] = i;
        E[i].a = a < b ? a : b; E[i].b = a < b ? b : a; E[i].t = i / 3;
    }
    qsort(E, n, sizeof *E, edge_cmp);
    for (i = 0; i + 1 < n; i++) {
        int key[2];
        if (E[i].a != E[i + 1].a || E[i].b != E[i + 1].b) continue;
        if (i + 2 < n && E[i + 2].a == E[i].a && E[i + 2].b == E[i].b) {
            fprintf(stderr, "shapes: %s: non-manifold edge %d-%d\n", path, E[i].a, E[i].b);
            exit(1);
        }
        if (s->chart[E[i].t] != s->chart[E[i + 1].t]) continue;
        key[0] = E[i].a; key[1] = E[i].b;
        if (s->ns && bsearch(key, seam, s->ns, 2 * sizeof(int), seam_cmp)) continue;
        {
            int ca = corner_of(s, E[i].t, E[i].a), cb = corner_of(s, E[i + 1].t, E[i].a);
            int da = corner_of(s, E[i].t, E[i].b), db = corner_of(s, E[i + 1].t, E[i].b);
            parent[uf_find(parent, ca)] = uf_find(parent, cb);
            parent[uf_find(parent, da)] = uf_find(parent, db);
        }
    }
    for (i = 0; i < n; i++) vt[i] = -1;
    f = fopen(path, "w");
    if (!f) { fprintf(stderr, "shapes: cannot write %s\n", path); exit(1); }
    fprintf(f, "# %s\n# generated by bench/shapes.c (bijparam): %d vertices, %d triangles\n", comment, s->nv, s->nt);
    for (i = 0; i < s->nv; i++) fprintf(f, "v %.17g %.17g %.17g\n", s->v[3 * i], s->v[3 * i + 1], s->v[3 * i + 2]);
    for (i = 0; i < n; i++) {
        int r = uf_find(parent, i);
        if (vt[r] < 0) {
            const double *p = s->v + 3 * s->t[i];
            vt[r] = nvt++;
            fprintf(f, "vt %.9g %.9g\n", p[0] + 3 * s->chart[i / 3], p[1] + p[2]);   /* placeholder */
        }
        vt[i] = vt[r];
    }
    for (i = 0; i < s->nt; i++)
        fprintf(f, "f %d/%d %d/%d %d/%d\n", s->t[3 * i] + 1, vt[3 * i] + 1, s->t[3 * i + 1] + 1, vt[3 * i + 1] + 1,
                s->t[3 * i + 2] + 1, vt[3 * i + 2] + 1);
    fclose(f);
    fprintf(stderr, "%s: %d vertices, %d vt, %d triangles\n", path, s->nv, nvt, s->nt);
    free(parent); free(vt); free(E); free(seam);
    return 0;
}

/* ---- surfaces of revolution (about +y) -----------------------------------
   Profile points (r_j, y_j), j = 0..K; r_0 = r_K = 0 are poles.  N columns;
   the chart of a quad or fan triangle in column i is chart_of(i). */
static void revolve(shape *s, const double *r, const double *y, int K, int N, int charts, int flip)
{
    int j, i, p0, pK, *ring = (int *)xrealloc(NULL, sizeof(int) * (K + 1) * N);
    p0 = add_v(s, 0, y[0], 0);
    for (j = 1; j < K; j++)
        for (i = 0; i < N; i++) {
            double phi = 2 * PI * i / N;
            ring[j * N + i] = add_v(s, r[j] * cos(phi), y[j], r[j] * sin(phi));
        }
    pK = add_v(s, 0, y[K], 0);
    for (i = 0; i < N; i++) {
        int i1 = (i + 1) % N, c = i * charts / N;
        add_t(s, p0, ring[1 * N + i1], ring[1 * N + i], c);
        add_t(s, pK, ring[(K - 1) * N + i], ring[(K - 1) * N + i1], c);
        for (j = 1; j + 1 < K; j++) {
            int a = ring[j * N + i], b = ring[j * N + i1], cc = ring[(j + 1) * N + i1], d = ring[(j + 1) * N + i];
            add_t(s, a, b, cc, c);
            add_t(s, a, cc, d, c);
        }
    }
    if (flip) flip_all(s);
    free(ring);
}

/* append samples of the segment (r0,y0)-(r1,y1) with about spacing h (end
   point included, start point excluded) */
static int segment(double *r, double *y, int k, double r0, double y0, double r1, double y1, double h)
{
    int n = (int)ceil(hypot(r1 - r0, y1 - y0) / h - 1e-9), i;
    if (n < 1) n = 1;
    for (i = 1; i <= n; i++) { r[k] = r0 + (r1 - r0) * i / n; y[k] = y0 + (y1 - y0) * i / n; k++; }
    return k;
}

static void make_cup(shape *s)
{
    double r[512], y[512], w = 0.08, h = 0.1;
    int K = 0;
    r[0] = 0; y[0] = 0;
    K = segment(r, y, K + 1, 0, 0, 1, 0, h) - 1;            /* outer bottom */
    K = segment(r, y, K + 1, 1, 0, 1, 2, h) - 1;            /* outer wall   */
    K = segment(r, y, K + 1, 1, 2, 1 - w, 2, h) - 1;        /* rim          */
    K = segment(r, y, K + 1, 1 - w, 2, 1 - w, w, h) - 1;    /* inner wall   */
    K = segment(r, y, K + 1, 1 - w, w, 0, w, h) - 1;        /* inner bottom */
    revolve(s, r, y, K, 64, 4, 0);
    if (volume(s) < 0) flip_all(s);
}

static void make_sphere(shape *s)
{
    double r[64], y[64];
    int j, K = 32, i, N = 64;
    for (j = 0; j <= K; j++) { double th = PI * j / K; r[j] = sin(th); y[j] = -cos(th); }
    r[0] = r[K] = 0;
    revolve(s, r, y, K, N, 1, 0);
    if (volume(s) < 0) flip_all(s);
    /* charts: the lower (y < 0) and upper hemisphere */
    for (i = 0; i < s->nt; i++) {
        const int *t = s->t + 3 * i;
        s->chart[i] = s->v[3 * t[0] + 1] + s->v[3 * t[1] + 1] + s->v[3 * t[2] + 1] > 0;
    }
}

static void make_ripple(shape *s)
{
    int N = 96, M = 60, i, j, *id = (int *)xrealloc(NULL, sizeof(int) * N * (M + 1));
    double H = 3;
    for (j = 0; j <= M; j++)
        for (i = 0; i < N; i++) {
            double yy = H * j / M, rr = 1 + 0.12 * sin(2 * PI * 5 * yy / H), phi = 2 * PI * i / N;
            id[j * N + i] = add_v(s, rr * cos(phi), yy, rr * sin(phi));
        }
    for (j = 0; j < M; j++)
        for (i = 0; i < N; i++) {
            int i1 = (i + 1) % N;
            int a = id[j * N + i], b = id[j * N + i1], c = id[(j + 1) * N + i1], d = id[(j + 1) * N + i];
            /* outward normal: (b - a) x (d - a) points out for phi increasing
               toward -z... checked numerically below */
            add_t(s, a, c, b, 0);
            add_t(s, a, d, c, 0);
        }
    /* the vertical seam at phi = 0: edges between rows at column 0 */
    for (j = 0; j < M; j++) add_seam(s, id[j * N], id[(j + 1) * N]);
    /* orientation: the normal of the first triangle must point away from the axis */
    {
        const double *a = s->v + 3 * s->t[0], *b = s->v + 3 * s->t[1], *c = s->v + 3 * s->t[2];
        double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
        double cx = (a[0] + b[0] + c[0]) / 3, cz = (a[2] + b[2] + c[2]) / 3;
        if (n[0] * cx + n[2] * cz < 0) flip_all(s);
    }
    free(id);
}

/* cube frame on a lattice of L+1 points per axis, coordinate -1 + 2 i / L */
#define HL 16
static int frame_solid(int i, int j, int k)
{
    int mid;
    if (i < 0 || j < 0 || k < 0 || i >= HL || j >= HL || k >= HL) return 0;
    mid = (i >= HL / 4 && i < 3 * HL / 4) + (j >= HL / 4 && j < 3 * HL / 4) + (k >= HL / 4 && k < 3 * HL / 4);
    return mid <= 1;
}

static void make_holes(shape *s)
{
    int *id = (int *)xrealloc(NULL, sizeof(int) * (HL + 1) * (HL + 1) * (HL + 1));
    int i, j, k, ax, sg;
    for (i = 0; i < (HL + 1) * (HL + 1) * (HL + 1); i++) id[i] = -1;
#define LID(a, b, c) id[((a) * (HL + 1) + (b)) * (HL + 1) + (c)]
    for (i = 0; i < HL; i++)
        for (j = 0; j < HL; j++)
            for (k = 0; k < HL; k++) {
                int c[3] = { i, j, k };
                if (!frame_solid(i, j, k)) continue;
                for (ax = 0; ax < 3; ax++)
                    for (sg = -1; sg <= 1; sg += 2) {
                        int nb[3] = { i, j, k }, q[4][3], vid[4], m, u = (ax + 1) % 3, w = (ax + 2) % 3, chart;
                        double cen[3];
                        nb[ax] += sg;
                        if (frame_solid(nb[0], nb[1], nb[2])) continue;
                        /* face at lattice plane c[ax] + (sg > 0); corners in (u, w) */
                        for (m = 0; m < 4; m++) {
                            q[m][ax] = c[ax] + (sg > 0);
                            q[m][u] = c[u] + (m == 1 || m == 2);
                            q[m][w] = c[w] + (m >= 2);
                        }
                        /* (u, w, ax) is right-handed: corners 0,1,2,3 are CCW
                           seen from +ax; reverse them for a face toward -ax */
                        for (m = 0; m < 4; m++) {
                            int *p = q[sg > 0 ? m : 3 - m];
                            if (LID(p[0], p[1], p[2]) < 0)
                                LID(p[0], p[1], p[2]) = add_v(s, -1 + 2.0 * p[0] / HL, -1 + 2.0 * p[1] / HL, -1 + 2.0 * p[2] / HL);
                            vid[m] = LID(p[0], p[1], p[2]);
                        }
                        for (m = 0; m < 3; m++) {
                            double a = 0;
                            int n;
                            for (n = 0; n < 4; n++) a += q[n][m];
                            cen[m] = -1 + 2.0 * (a / 4) / HL;
                        }
                        chart = (cen[0] > 0) + 2 * (cen[1] > 0) + 4 * (cen[2] > 0);
                        /* diagonal: mirror-symmetric choice, so the eight corners are identical */
                        if ((cen[u] > 0) == (cen[w] > 0)) {
                            add_t(s, vid[0], vid[1], vid[2], chart);
                            add_t(s, vid[0], vid[2], vid[3], chart);
                        } else {
                            add_t(s, vid[0], vid[1], vid[3], chart);
                            add_t(s, vid[1], vid[2], vid[3], chart);
                        }
                    }
            }
    /* seams on the inside: the edges x in [0, 1/2] at |y| = |z| = 1/2 of
       every arm, and likewise for y and z */
    for (ax = 0; ax < 3; ax++) {
        int sy, sz;
        for (sy = 0; sy < 2; sy++)
            for (sz = 0; sz < 2; sz++)
                for (i = HL / 4; i < 3 * HL / 4; i++) {
                    int p[3], q[3], u = (ax + 1) % 3, w = (ax + 2) % 3;
                    p[ax] = i; q[ax] = i + 1;
                    p[u] = q[u] = sy ? 3 * HL / 4 : HL / 4;
                    p[w] = q[w] = sz ? 3 * HL / 4 : HL / 4;
                    if (LID(p[0], p[1], p[2]) >= 0 && LID(q[0], q[1], q[2]) >= 0)
                        add_seam(s, LID(p[0], p[1], p[2]), LID(q[0], q[1], q[2]));
                }
    }
#undef LID
    free(id);
}

int main(int argc, char **argv)
{
    char path[4096];
    shape s;
    const char *dir = argc > 1 ? argv[1] : ".";
    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) {
        fprintf(stderr, "usage: shapes [OUTDIR]   (writes cup.obj holes.obj ripple.obj sphere.obj)\n");
        return 2;
    }
    memset(&s, 0, sizeof s);
    make_cup(&s);
    fprintf(stderr, "cup volume %g\n", volume(&s));
    snprintf(path, sizeof path, "%s/cup.obj", dir);
    write_obj(&s, path, "cup: thin-walled cup about +y, opening at +y, four quadrant charts");
    shape_free(&s);
    make_holes(&s);
    fprintf(stderr, "holes volume %g\n", volume(&s));
    snprintf(path, sizeof path, "%s/holes.obj", dir);
    write_obj(&s, path, "holes: cube frame [-1,1]^3 with square tunnels of half width 0.5, eight corner charts with inner seams");
    shape_free(&s);
    make_ripple(&s);
    snprintf(path, sizeof path, "%s/ripple.obj", dir);
    write_obj(&s, path, "ripple: open rippled cylinder about +y, one vertical seam at angle 0");
    shape_free(&s);
    make_sphere(&s);
    fprintf(stderr, "sphere volume %g\n", volume(&s));
    snprintf(path, sizeof path, "%s/sphere.obj", dir);
    write_obj(&s, path, "sphere: unit UV sphere about +y, two hemisphere charts");
    shape_free(&s);
    return 0;
}
