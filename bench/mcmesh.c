/* bench/mcmesh.c - marching-cubes meshes of the kind reconstruction and
   3D-generation pipelines hand to a parameterizer (make bench-generated).

       cc -std=c99 -O2 bench/mcmesh.c -o build/bench/mcmesh -lm
       build/bench/mcmesh [--grid N] KIND FACES SEED OUT.obj

   writes OUT.obj (v and f lines only) and prints one JSON line of its
   statistics on stdout.  KIND is

     blob    one closed surface of genus 0: a four-legged creature (an
             ellipsoid body, a head on a neck, four legs, a tail and two
             ears, all blended by a smooth minimum) under three octaves of
             noise;
     noisy   the same creature with 20 handles (tori half sunk into the
             body: tunnels, genus about 20) and 13 small blobs floating
             near it, as a reconstruction leaves them.

   FACES is the face count aimed at: the grid is chosen from a first pass
   on a 160^3 grid (faces grow as the square of the grid), so the result
   lands within a few percent of it; --grid N takes the grid as given.
   SEED (an integer) draws the noise and the places of the handles and
   blobs.  The output is a function of (KIND, grid, SEED) alone: the only
   randomness is splitmix64, the arithmetic is plain double (no library
   function but sqrt in the field), and every coordinate is rounded to a
   float (as a .glb stores it) and written exactly ("%.9g").

   The field.  f < 0 inside.  The shapes are signed distances (exact for
   spheres, capsules and tori; for the ellipsoid m (|D p| - 1), D =
   diag(1/a, 1/b, 1/c), m = min(a, b, c), whose gradient is at most 1),
   blended one after the other by the polynomial smooth minimum

       smin(a, b) = min(a, b) - h^2 k / 4,   h = max(k - |a - b|, 0) / k,

   whose partial derivatives are h' and 1 - h' (h' in [0, 1]), so the
   blend of 1-Lipschitz shapes is 1-Lipschitz.  The noise is band-limited:
   octave o is a uniform cubic B-spline on a lattice of spacing s_o with
   coefficients uniform in [-1, 1], times an amplitude A_o; a cubic
   B-spline's spectrum falls as sinc^4 beyond the lattice frequency 1/s_o.
   Its value is at most A_o and its gradient at most 1.5 sqrt(3) A_o / s_o
   (the derivatives of the four cubic B-spline weights sum in absolute value
   to at most 1.5).  So f is L-Lipschitz with L = 1 + sum 1.5 sqrt(3) A_o / s_o.

   Where to evaluate.  The grid has N cells a side over [-1, 1]^3 (spacing
   h = 2 / N).  Blocks of 4^3 cells are sorted by an octree: a box whose
   centre value exceeds L times its half diagonal in magnitude has one
   sign throughout and is skipped; what is left are the blocks the surface
   may cross, and only their samples are evaluated (a few percent of
   N^3).  The noise there is evaluated layer by layer, one axis at a time
   (the B-spline is a tensor product): per layer the lattice plane
   contracted in z, per row that plane contracted in y, per sample four
   products in x.

   Marching cubes.  Each cube whose corners differ in sign gets the
   polygons that its six faces dictate: on a face, walked counter-clockwise
   as seen from outside the cube, every sign change is a crossing, and a
   segment runs from a crossing that enters the inside to one that leaves
   it.  A face with four crossings (inside corners diagonal) is decided by
   the bilinear interpolant's saddle (the asymptotic decider of Nielson and
   Hamann, 1991): the inside corners connect through the face centre when
   the product of their values exceeds that of the outside corners.  The
   decision depends on the face's four values only, so the two cubes
   sharing a face draw the same segments, in opposite directions; within a
   cube every crossing starts one segment and ends another, so the
   segments close into cycles, each a polygon fanned into triangles.  The
   surface is therefore closed and consistently oriented (outward normals,
   counter-clockwise), and the program checks it: every directed edge
   appears once and its reverse once.  A crossing's vertex is linear
   interpolation on its grid edge, t = f0 / (f0 - f1), computed once per
   edge and shared by the four cubes around it.  Where the surface passes
   near a sample, three crossings come close together: the slivers and
   near-zero-area triangles of real marching-cubes meshes.

   The JSON line: faces, vertices, grid, components (connected pieces),
   genus (the sum over the pieces of (2 - chi) / 2), main_genus (the
   largest piece's), floating (pieces other than the largest),
   slivers (share of triangles with an angle under 1 degree), tiny (share
   with area under 1e-4 of the mean), zero_area (triangles whose float
   corners are collinear), seconds. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define BLOCK 4          /* cells per octree leaf block, a side */
#define MAXOCT 4
#define MAXPRIM 64
#define NONE 0xffffffffu

static void die(const char *what)
{
    fprintf(stderr, "mcmesh: %s\n", what);
    exit(1);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) die("out of memory");
    return p;
}

static void *xcalloc(size_t n, size_t s)
{
    void *p = calloc(n ? n : 1, s ? s : 1);
    if (!p) die("out of memory");
    return p;
}

/* ---- random numbers: splitmix64 -------------------------------------- */

static uint64_t rng_state;

static uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* uniform in [lo, hi) */
static double rng_uniform(double lo, double hi)
{
    return lo + (hi - lo) * (double)(rng_next() >> 11) * (1.0 / 9007199254740992.0);
}

/* ---- the shapes -------------------------------------------------------- */

enum { ELLIPSOID, SPHERE, CAPSULE, TORUS };

typedef struct prim {
    int type;
    double c[3], r[3];   /* ELLIPSOID: centre, radii; SPHERE: centre, r[0] */
    double a[3], b[3];   /* CAPSULE: segment a-b, radius r[0]             */
    double t[3];         /* TORUS: centre c, unit axis t, major r[0], minor r[1] */
    double k;            /* smooth-minimum width with what came before     */
    double bc[3], br;    /* bounding sphere: the distance is >= |p - bc| - br */
} prim;

typedef struct octave {
    double amp, s;       /* amplitude, lattice spacing */
    int M;               /* coefficients per axis */
    double *coef;        /* M^3, index (z M + y) M + x */
    int *idx;            /* per grid coordinate: first lattice index */
    double *w;           /* per grid coordinate: four weights */
} octave;

typedef struct field {
    prim p[MAXPRIM];
    int np;
    octave o[MAXOCT];
    int no;
    double lipschitz;
} field;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double prim_dist(const prim *q, const double *p)
{
    double d[3], x, y, z, h, len;
    switch (q->type) {
    case ELLIPSOID: {
        double m = q->r[0];
        if (q->r[1] < m) m = q->r[1];
        if (q->r[2] < m) m = q->r[2];
        x = (p[0] - q->c[0]) / q->r[0];
        y = (p[1] - q->c[1]) / q->r[1];
        z = (p[2] - q->c[2]) / q->r[2];
        return m * (sqrt(x * x + y * y + z * z) - 1);
    }
    case SPHERE:
        d[0] = p[0] - q->c[0]; d[1] = p[1] - q->c[1]; d[2] = p[2] - q->c[2];
        return sqrt(dot3(d, d)) - q->r[0];
    case CAPSULE: {
        double ba[3], pa[3];
        ba[0] = q->b[0] - q->a[0]; ba[1] = q->b[1] - q->a[1]; ba[2] = q->b[2] - q->a[2];
        pa[0] = p[0] - q->a[0]; pa[1] = p[1] - q->a[1]; pa[2] = p[2] - q->a[2];
        h = dot3(pa, ba) / dot3(ba, ba);
        if (h < 0) h = 0;
        if (h > 1) h = 1;
        d[0] = pa[0] - h * ba[0]; d[1] = pa[1] - h * ba[1]; d[2] = pa[2] - h * ba[2];
        return sqrt(dot3(d, d)) - q->r[0];
    }
    default: {   /* TORUS */
        d[0] = p[0] - q->c[0]; d[1] = p[1] - q->c[1]; d[2] = p[2] - q->c[2];
        h = dot3(d, q->t);
        x = d[0] - h * q->t[0]; y = d[1] - h * q->t[1]; z = d[2] - h * q->t[2];
        len = sqrt(x * x + y * y + z * z) - q->r[0];
        return sqrt(len * len + h * h) - q->r[1];
    }
    }
}

/* The blend of every shape (see the essay).  A shape whose bound is k or
   more above the blend so far would leave it unchanged (h = 0): skipped. */
static double shapes_at(const field *F, const double *p)
{
    double cur = 1e30;
    int i;
    for (i = 0; i < F->np; i++) {
        const prim *q = &F->p[i];
        double d[3], lim = cur + q->k + q->br, di, h;
        d[0] = p[0] - q->bc[0]; d[1] = p[1] - q->bc[1]; d[2] = p[2] - q->bc[2];
        if (lim >= 0 && dot3(d, d) >= lim * lim) continue;
        di = prim_dist(q, p);
        h = q->k - fabs(cur - di);
        if (h < 0) h = 0;
        h /= q->k;
        cur = (cur < di ? cur : di) - h * h * q->k * 0.25;
    }
    return cur;
}

/* The four cubic B-spline weights at fraction t. */
static void bspline_weights(double t, double *w)
{
    double u = 1 - t, t2 = t * t, t3 = t2 * t;
    w[0] = u * u * u / 6;
    w[1] = (3 * t3 - 6 * t2 + 4) / 6;
    w[2] = (-3 * t3 + 3 * t2 + 3 * t + 1) / 6;
    w[3] = t3 / 6;
}

/* Lattice coordinate of world coordinate x in [-1, 1]: first index and
   weights (the lattice has one spare coefficient before -1, two after 1). */
static int lattice_at(const octave *o, double x, double *w)
{
    double u = (x + 1) / o->s + 1;
    int m = (int)floor(u);
    if (m > o->M - 3) m = o->M - 3;
    bspline_weights(u - m, w);
    return m - 1;
}

static double noise_at(const octave *o, const double *p)
{
    double wx[4], wy[4], wz[4], sum = 0;
    int ix = lattice_at(o, p[0], wx), iy = lattice_at(o, p[1], wy), iz = lattice_at(o, p[2], wz), a, b, c;
    for (c = 0; c < 4; c++)
        for (b = 0; b < 4; b++) {
            const double *row = o->coef + ((size_t)(iz + c) * o->M + (iy + b)) * o->M + ix;
            double r = 0;
            for (a = 0; a < 4; a++) r += wx[a] * row[a];
            sum += wz[c] * wy[b] * r;
        }
    return o->amp * sum;
}

static double field_at(const field *F, const double *p)
{
    double f = shapes_at(F, p);
    int o;
    for (o = 0; o < F->no; o++) f += noise_at(&F->o[o], p);
    return f;
}

/* ---- the two kinds ----------------------------------------------------- */

static prim *add_prim(field *F, int type, double k)
{
    prim *q;
    if (F->np == MAXPRIM) die("too many shapes");
    q = &F->p[F->np++];
    memset(q, 0, sizeof *q);
    q->type = type;
    q->k = k;
    return q;
}

static void set3(double *v, double x, double y, double z) { v[0] = x; v[1] = y; v[2] = z; }

static void bound_prim(prim *q)
{
    int i;
    switch (q->type) {
    case ELLIPSOID:
        memcpy(q->bc, q->c, sizeof q->bc);
        q->br = q->r[0] > q->r[1] ? q->r[0] : q->r[1];
        if (q->r[2] > q->br) q->br = q->r[2];
        break;
    case SPHERE: memcpy(q->bc, q->c, sizeof q->bc); q->br = q->r[0]; break;
    case CAPSULE: {
        double d[3];
        for (i = 0; i < 3; i++) { q->bc[i] = 0.5 * (q->a[i] + q->b[i]); d[i] = q->b[i] - q->a[i]; }
        q->br = 0.5 * sqrt(dot3(d, d)) + q->r[0];
        break;
    }
    default: memcpy(q->bc, q->c, sizeof q->bc); q->br = q->r[0] + q->r[1]; break;
    }
}

static void capsule(field *F, double ax, double ay, double az, double bx, double by, double bz, double r, double k)
{
    prim *q = add_prim(F, CAPSULE, k);
    set3(q->a, ax, ay, az);
    set3(q->b, bx, by, bz);
    q->r[0] = r;
}

/* The creature: body, neck and head, four legs, tail, two ears. */
static void creature(field *F)
{
    prim *q = add_prim(F, ELLIPSOID, 0.08);
    int sx, sz;
    set3(q->c, -0.05, 0.05, 0);
    set3(q->r, 0.55, 0.3, 0.3);
    capsule(F, 0.3, 0.12, 0, 0.52, 0.32, 0, 0.13, 0.08);
    q = add_prim(F, SPHERE, 0.06);
    set3(q->c, 0.6, 0.38, 0);
    q->r[0] = 0.19;
    for (sx = -1; sx <= 1; sx += 2)
        for (sz = -1; sz <= 1; sz += 2)
            capsule(F, 0.3 * sx - 0.05, -0.1, 0.16 * sz, 0.33 * sx - 0.05, -0.78, 0.2 * sz, 0.085, 0.08);
    capsule(F, -0.55, 0.1, 0, -0.88, 0.4, 0.05, 0.05, 0.06);
    capsule(F, 0.6, 0.5, 0.08, 0.58, 0.74, 0.14, 0.045, 0.04);
    capsule(F, 0.6, 0.5, -0.08, 0.58, 0.74, -0.14, 0.045, 0.04);
}

static void unit(double *v)
{
    double n = sqrt(dot3(v, v));
    v[0] /= n; v[1] /= n; v[2] /= n;
}

/* A random point of the body's ellipsoid (F->p[0]) between x0 and x1 with
   y above ymin, and the outward normal there. */
static void body_point(const field *F, double x0, double x1, double ymin, double *p, double *n)
{
    const prim *b = &F->p[0];
    for (;;) {
        double d[3], s;
        int i;
        do { set3(d, rng_uniform(-1, 1), rng_uniform(-1, 1), rng_uniform(-1, 1)); } while (dot3(d, d) > 1 || dot3(d, d) < 1e-4);
        unit(d);
        for (i = 0; i < 3; i++) p[i] = b->c[i] + b->r[i] * d[i];
        if (p[0] < x0 || p[0] > x1 || p[1] < ymin) continue;
        for (i = 0; i < 3; i++) n[i] = d[i] / b->r[i];
        s = sqrt(dot3(n, n));
        for (i = 0; i < 3; i++) n[i] /= s;
        return;
    }
}

/* 20 handles: tori whose ring stands on the body, half in and half out
   (each a tunnel), at least two ring diameters apart; then 13 small
   spheres floating 0.12-0.25 off the surface, clear of every handle. */
static void handles_and_debris(field *F)
{
    double hc[20][3], n[3], p[3], t[3], r[3];
    int nh = 0, nd = 0, i, tries = 0;
    while (nh < 20) {
        double R = rng_uniform(0.07, 0.11), rr = rng_uniform(0.018, 0.028);
        int ok = 1;
        body_point(F, -0.55, 0.3, -0.2, p, n);
        for (i = 0; i < nh && ok; i++) {
            double d[3];
            set3(d, p[0] - hc[i][0], p[1] - hc[i][1], p[2] - hc[i][2]);
            if (dot3(d, d) < 0.2 * 0.2) ok = 0;
        }
        if (++tries > 100000) die("cannot place the handles");
        if (!ok) continue;
        set3(r, rng_uniform(-1, 1), rng_uniform(-1, 1), rng_uniform(-1, 1));
        t[0] = n[1] * r[2] - n[2] * r[1]; t[1] = n[2] * r[0] - n[0] * r[2]; t[2] = n[0] * r[1] - n[1] * r[0];
        unit(t);
        {
            prim *q = add_prim(F, TORUS, 0.02);
            memcpy(q->c, p, sizeof q->c);
            memcpy(q->t, t, sizeof q->t);
            q->r[0] = R;
            q->r[1] = rr;
            bound_prim(q);
        }
        memcpy(hc[nh++], p, sizeof p);
    }
    while (nd < 13) {
        double rad = rng_uniform(0.025, 0.045), gap = rng_uniform(0.12, 0.25), c[3];
        body_point(F, -0.6, 0.6, -0.2, p, n);
        for (i = 0; i < 3; i++) c[i] = p[i] + (gap + rad) * n[i];
        if (++tries > 200000) die("cannot place the floating pieces");
        if (shapes_at(F, c) < rad + 0.1 || fabs(c[0]) > 0.9 || fabs(c[1]) > 0.9 || fabs(c[2]) > 0.9) continue;
        {
            prim *q = add_prim(F, SPHERE, 0.02);
            memcpy(q->c, c, sizeof q->c);
            q->r[0] = rad;
            bound_prim(q);
        }
        nd++;
    }
}

static void add_octave(field *F, double amp, double s)
{
    octave *o = &F->o[F->no++];
    size_t i, n;
    o->amp = amp;
    o->s = s;
    o->M = (int)floor(2 / s) + 5;
    n = (size_t)o->M * o->M * o->M;
    o->coef = (double *)xmalloc(n * sizeof(double));
    for (i = 0; i < n; i++) o->coef[i] = rng_uniform(-1, 1);
    F->lipschitz += 1.5 * sqrt(3.0) * amp / s;
}

static void make_field(field *F, const char *kind, uint64_t seed)
{
    int i;
    memset(F, 0, sizeof *F);
    rng_state = seed * 0x2545f4914f6cdd1dull + 1;
    F->lipschitz = 1;
    creature(F);
    for (i = 0; i < F->np; i++) bound_prim(&F->p[i]);
    if (!strcmp(kind, "noisy")) handles_and_debris(F);
    else if (strcmp(kind, "blob")) die("KIND is blob or noisy");
    add_octave(F, 0.05, 0.25);
    add_octave(F, 0.015, 0.08);
    add_octave(F, 0.004, 0.025);
}

/* Per-grid-coordinate lattice indices and weights of each octave. */
static void octave_tables(field *F, int N)
{
    int o, i;
    for (o = 0; o < F->no; o++) {
        octave *q = &F->o[o];
        free(q->idx); free(q->w);
        q->idx = (int *)xmalloc(sizeof(int) * (N + 1));
        q->w = (double *)xmalloc(sizeof(double) * 4 * (N + 1));
        for (i = 0; i <= N; i++) q->idx[i] = lattice_at(q, -1 + 2.0 * i / N, q->w + 4 * i);
    }
}

/* ---- the octree of blocks ---------------------------------------------- */

typedef struct grid {
    int N, nb;               /* cells a side, blocks a side */
    double h;
    unsigned char *state;    /* per block: 0 outside, 1 inside, 2 crossed */
} grid;

static double coord(const grid *G, int i) { return -1 + G->h * i; }

static void cull(const field *F, grid *G, int x0, int x1, int y0, int y1, int z0, int z1)
{
    int sx0 = x0 * BLOCK, sx1 = x1 * BLOCK > G->N ? G->N : x1 * BLOCK;
    int sy0 = y0 * BLOCK, sy1 = y1 * BLOCK > G->N ? G->N : y1 * BLOCK;
    int sz0 = z0 * BLOCK, sz1 = z1 * BLOCK > G->N ? G->N : z1 * BLOCK;
    double c[3], hx = 0.5 * G->h * (sx1 - sx0), hy = 0.5 * G->h * (sy1 - sy0), hz = 0.5 * G->h * (sz1 - sz0), f;
    set3(c, coord(G, sx0) + hx, coord(G, sy0) + hy, coord(G, sz0) + hz);
    f = field_at(F, c);
    if (fabs(f) > 1.01 * F->lipschitz * sqrt(hx * hx + hy * hy + hz * hz) + 1e-12) {
        int x, y, z;
        for (z = z0; z < z1; z++)
            for (y = y0; y < y1; y++)
                for (x = x0; x < x1; x++) G->state[((size_t)z * G->nb + y) * G->nb + x] = f < 0;
        return;
    }
    if (x1 - x0 == 1 && y1 - y0 == 1 && z1 - z0 == 1) {
        G->state[((size_t)z0 * G->nb + y0) * G->nb + x0] = 2;
        return;
    }
    {
        int xm = x1 - x0 > 1 ? (x0 + x1) / 2 : x1, ym = y1 - y0 > 1 ? (y0 + y1) / 2 : y1;
        int zm = z1 - z0 > 1 ? (z0 + z1) / 2 : z1, a, b, d;
        int xs[3], ys[3], zs[3];
        xs[0] = x0; xs[1] = xm; xs[2] = x1;
        ys[0] = y0; ys[1] = ym; ys[2] = y1;
        zs[0] = z0; zs[1] = zm; zs[2] = z1;
        for (d = 0; d < 2; d++)
            for (b = 0; b < 2; b++)
                for (a = 0; a < 2; a++)
                    if (xs[a] < xs[a + 1] && ys[b] < ys[b + 1] && zs[d] < zs[d + 1])
                        cull(F, G, xs[a], xs[a + 1], ys[b], ys[b + 1], zs[d], zs[d + 1]);
    }
}

/* ---- layers of samples --------------------------------------------------- */

typedef struct layer {
    int z;                   /* sample layer held */
    double *val;             /* (N+1)^2 */
    uint32_t *stamp;         /* z + 1 where val is set */
    double *cz[MAXOCT];      /* per octave: the lattice contracted in z, M^2 */
    double *dy[MAXOCT];      /* per octave and row: contracted in y too, (N+1) M */
    uint32_t *rowstamp;      /* z + 1 where dy of the row is set */
    uint32_t *ex, *exs, *ey, *eys;   /* vertex of the x / y edge at a sample, and its stamp */
} layer;

static void layer_alloc(layer *L, const field *F, int N)
{
    size_t n = (size_t)(N + 1) * (N + 1);
    int o;
    L->z = -1;
    L->val = (double *)xmalloc(n * sizeof(double));
    L->stamp = (uint32_t *)xcalloc(n, sizeof(uint32_t));
    L->ex = (uint32_t *)xmalloc(n * sizeof(uint32_t));
    L->exs = (uint32_t *)xcalloc(n, sizeof(uint32_t));
    L->ey = (uint32_t *)xmalloc(n * sizeof(uint32_t));
    L->eys = (uint32_t *)xcalloc(n, sizeof(uint32_t));
    L->rowstamp = (uint32_t *)xcalloc(N + 1, sizeof(uint32_t));
    for (o = 0; o < F->no; o++) {
        L->cz[o] = (double *)xmalloc(sizeof(double) * F->o[o].M * F->o[o].M);
        L->dy[o] = (double *)xmalloc(sizeof(double) * (N + 1) * F->o[o].M);
    }
}

static void layer_free(layer *L, const field *F)
{
    int o;
    free(L->val); free(L->stamp); free(L->ex); free(L->exs); free(L->ey); free(L->eys); free(L->rowstamp);
    for (o = 0; o < F->no; o++) { free(L->cz[o]); free(L->dy[o]); }
}

/* Make L hold layer z: the lattice planes contracted in z. */
static void layer_start(layer *L, const field *F, int z)
{
    int o, i;
    L->z = z;
    for (o = 0; o < F->no; o++) {
        const octave *q = &F->o[o];
        const double *w = q->w + 4 * z;
        size_t plane = (size_t)q->M * q->M, c;
        for (i = 0; i < q->M * q->M; i++) {
            double s = 0;
            for (c = 0; c < 4; c++) s += w[c] * q->coef[(size_t)(q->idx[z] + c) * plane + i];
            L->cz[o][i] = s;
        }
    }
}

/* The value at sample (x, y) of L's layer (the shapes exactly, the noise
   by the contracted lattice). */
static double sample(layer *L, const field *F, const grid *G, int x, int y)
{
    size_t k = (size_t)y * (G->N + 1) + x;
    uint32_t st = (uint32_t)L->z + 1;
    double p[3], f;
    int o, a, b;
    if (L->stamp[k] == st) return L->val[k];
    if (L->rowstamp[y] != st) {
        for (o = 0; o < F->no; o++) {
            const octave *q = &F->o[o];
            const double *w = q->w + 4 * y;
            double *dy = L->dy[o] + (size_t)y * q->M;
            for (a = 0; a < q->M; a++) {
                double s = 0;
                for (b = 0; b < 4; b++) s += w[b] * L->cz[o][(size_t)(q->idx[y] + b) * q->M + a];
                dy[a] = s;
            }
        }
        L->rowstamp[y] = st;
    }
    set3(p, coord(G, x), coord(G, y), coord(G, L->z));
    f = shapes_at(F, p);
    for (o = 0; o < F->no; o++) {
        const octave *q = &F->o[o];
        const double *w = q->w + 4 * x, *dy = L->dy[o] + (size_t)y * q->M + q->idx[x];
        f += q->amp * (w[0] * dy[0] + w[1] * dy[1] + w[2] * dy[2] + w[3] * dy[3]);
    }
    L->val[k] = f;
    L->stamp[k] = st;
    return f;
}

/* ---- the mesh ------------------------------------------------------------ */

typedef struct mesh {
    float *v;  size_t nv, cv;
    uint32_t *f; size_t nf, cf;
} mesh;

static uint32_t add_vertex(mesh *M, double x, double y, double z)
{
    if (M->nv == M->cv) {
        M->cv = M->cv ? 2 * M->cv : 1 << 16;
        M->v = (float *)realloc(M->v, sizeof(float) * 3 * M->cv);
        if (!M->v) die("out of memory");
    }
    M->v[3 * M->nv] = (float)x; M->v[3 * M->nv + 1] = (float)y; M->v[3 * M->nv + 2] = (float)z;
    if (M->nv >= NONE - 1) die("too many vertices");
    return (uint32_t)M->nv++;
}

static void add_face(mesh *M, uint32_t a, uint32_t b, uint32_t c)
{
    if (M->nf == M->cf) {
        M->cf = M->cf ? 2 * M->cf : 1 << 16;
        M->f = (uint32_t *)realloc(M->f, sizeof(uint32_t) * 3 * M->cf);
        if (!M->f) die("out of memory");
    }
    M->f[3 * M->nf] = a; M->f[3 * M->nf + 1] = b; M->f[3 * M->nf + 2] = c;
    M->nf++;
}

/* ---- marching cubes -------------------------------------------------------

   Corner c of a cube is (c & 1, c >> 1 & 1, c >> 2 & 1).  Edge e = 4 axis +
   the other two bits (lower axis first) joins the two corners that differ
   in bit `axis`.  Face 2 axis + side: its corners counter-clockwise as
   seen from outside, and the edge from each to the next. */

static int face_corner[6][4], face_edge[6][4];

static int edge_of(int c0, int c1)
{
    int d = c0 ^ c1, axis = d == 1 ? 0 : d == 2 ? 1 : 2, lo = c0 & c1, o1 = (axis + 1) % 3, o2 = (axis + 2) % 3, t;
    if (o1 > o2) { t = o1; o1 = o2; o2 = t; }
    return 4 * axis + ((lo >> o1) & 1) + 2 * ((lo >> o2) & 1);
}

static void face_tables(void)
{
    int axis, side, i;
    for (axis = 0; axis < 3; axis++)
        for (side = 0; side < 2; side++) {
            /* u x v = +axis; seen from outside on side 0 (normal -axis), swap them */
            int u = (axis + 1) % 3, v = (axis + 2) % 3, f = 2 * axis + side;
            static const int uv[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
            if (side == 0) { int t = u; u = v; v = t; }
            for (i = 0; i < 4; i++) face_corner[f][i] = (side << axis) | (uv[i][0] << u) | (uv[i][1] << v);
            for (i = 0; i < 4; i++) face_edge[f][i] = edge_of(face_corner[f][i], face_corner[f][(i + 1) % 4]);
        }
}

typedef struct mc {
    const field *F;
    const grid *G;
    layer *L[2];             /* layers z and z + 1 */
    uint32_t *ez, *ezs;      /* vertex of the z edge at a sample, and its stamp */
    mesh *M;
} mc;

/* The vertex on edge e of cube (x, y, z), made on first use. */
static uint32_t edge_vertex(mc *S, int x, int y, int z, int e, const double *val)
{
    int axis = e >> 2, b1 = e & 1, b2 = (e >> 1) & 1, o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
    int off[3], c0, c1;
    size_t k;
    uint32_t *id, *st, want;
    off[axis] = 0; off[o1] = b1; off[o2] = b2;
    c0 = off[0] | off[1] << 1 | off[2] << 2;
    c1 = c0 | 1 << axis;
    k = (size_t)(y + off[1]) * (S->G->N + 1) + x + off[0];
    if (axis == 2) { id = S->ez; st = S->ezs; want = (uint32_t)z + 1; }
    else {
        layer *L = S->L[off[2]];
        id = axis == 0 ? L->ex : L->ey;
        st = axis == 0 ? L->exs : L->eys;
        want = (uint32_t)L->z + 1;
    }
    if (st[k] != want) {
        double p[3], t = val[c0] / (val[c0] - val[c1]);
        set3(p, coord(S->G, x + off[0]), coord(S->G, y + off[1]), coord(S->G, z + off[2]));
        p[axis] += t * S->G->h;
        id[k] = add_vertex(S->M, p[0], p[1], p[2]);
        st[k] = want;
    }
    return id[k];
}

/* The two faces of cube edge e (see face_tables' numbering). */
static int edge_faces(int e)
{
    int axis = e >> 2, o1 = axis == 0 ? 1 : 0, o2 = axis == 2 ? 1 : 2;
    return 1 << (2 * o1 + (e & 1)) | 1 << (2 * o2 + ((e >> 1) & 1));
}

/* Fan the polygon (vertices poly, on cube edges pe) into triangles from an
   apex none of whose diagonals joins two crossings of one cube face: the
   neighbouring cube may hold the same two crossings, and its own diagonal
   between them would make an edge of four triangles.  A diagonal that
   lies on no face is inside this cube alone.  When no apex qualifies the
   polygon is fanned around its centroid, a vertex of its own. */
static void fan(mc *S, const uint32_t *poly, const int *pe, int np)
{
    int s, i;
    for (s = 0; s < np; s++) {
        int ok = 1;
        for (i = 2; i + 1 < np && ok; i++)
            if (edge_faces(pe[s]) & edge_faces(pe[(s + i) % np])) ok = 0;
        if (ok) {
            for (i = 1; i + 1 < np; i++) add_face(S->M, poly[s], poly[(s + i) % np], poly[(s + i + 1) % np]);
            return;
        }
    }
    {
        double c[3] = { 0, 0, 0 };
        uint32_t m;
        for (i = 0; i < np; i++) {
            const float *v = S->M->v + 3 * (size_t)poly[i];
            c[0] += v[0]; c[1] += v[1]; c[2] += v[2];
        }
        m = add_vertex(S->M, c[0] / np, c[1] / np, c[2] / np);
        for (i = 0; i < np; i++) add_face(S->M, m, poly[i], poly[(i + 1) % np]);
    }
}

static void cube(mc *S, int x, int y, int z, const double *val)
{
    int next[12], i, f, e, in = 0;
    unsigned char seen[12];
    for (i = 0; i < 8; i++) in |= (val[i] < 0) << i;
    if (in == 0 || in == 255) return;
    for (i = 0; i < 12; i++) next[i] = -1;
    for (f = 0; f < 6; f++) {
        const int *q = face_corner[f], *fe = face_edge[f];
        int b[4], n = 0;
        for (i = 0; i < 4; i++) { b[i] = (in >> q[i]) & 1; }
        for (i = 0; i < 4; i++) n += b[i] != b[(i + 1) % 4];
        if (n == 2) {
            int enter = -1, leave = -1;
            for (i = 0; i < 4; i++) {
                if (!b[i] && b[(i + 1) % 4]) enter = fe[i];
                if (b[i] && !b[(i + 1) % 4]) leave = fe[i];
            }
            next[enter] = leave;
        } else if (n == 4) {
            int a = b[0] ? 0 : 1;   /* an inside corner */
            int joined = val[q[a]] * val[q[a + 2]] > val[q[a + 1]] * val[q[(a + 3) % 4]];
            for (i = 0; i < 4; i++) {
                if (!joined && b[i]) next[fe[(i + 3) % 4]] = fe[i];   /* around an inside corner */
                if (joined && !b[i]) next[fe[i]] = fe[(i + 3) % 4];   /* around an outside corner */
            }
        }
    }
    memset(seen, 0, sizeof seen);
    for (e = 0; e < 12; e++) {
        uint32_t poly[12];
        int pe[12], np = 0, c = e;
        if (next[e] < 0 || seen[e]) continue;
        do {
            seen[c] = 1;
            pe[np] = c;
            poly[np++] = edge_vertex(S, x, y, z, c, val);
            c = next[c];
        } while (c != e && np < 12);
        if (c != e) die("internal error: open polygon");
        fan(S, poly, pe, np);
    }
}

/* The whole grid: octree, then cube layers in order. */
static void march(const field *F, int N, mesh *M)
{
    grid G;
    layer A, B;
    mc S;
    size_t n = (size_t)(N + 1) * (N + 1);
    unsigned char *plane;
    int z, x, y, bx, by;
    G.N = N;
    G.nb = (N + BLOCK - 1) / BLOCK;
    G.h = 2.0 / N;
    G.state = (unsigned char *)xmalloc((size_t)G.nb * G.nb * G.nb);
    cull(F, &G, 0, G.nb, 0, G.nb, 0, G.nb);
    layer_alloc(&A, F, N);
    layer_alloc(&B, F, N);
    S.F = F; S.G = &G; S.M = M;
    S.ez = (uint32_t *)xmalloc(n * sizeof(uint32_t));
    S.ezs = (uint32_t *)xcalloc(n, sizeof(uint32_t));
    S.L[0] = &A; S.L[1] = &B;
    layer_start(&A, F, 0);
    layer_start(&B, F, 1);
    for (z = 0; z < N; z++) {
        if (z > 0) {
            layer *t = S.L[0];
            S.L[0] = S.L[1];
            S.L[1] = t;
            layer_start(S.L[1], F, z + 1);
        }
        plane = G.state + (size_t)(z / BLOCK) * G.nb * G.nb;
        for (by = 0; by < G.nb; by++)
            for (bx = 0; bx < G.nb; bx++) {
                if (plane[by * G.nb + bx] != 2) continue;
                for (y = by * BLOCK; y < (by + 1) * BLOCK && y < N; y++)
                    for (x = bx * BLOCK; x < (bx + 1) * BLOCK && x < N; x++) {
                        double val[8];
                        int c;
                        for (c = 0; c < 8; c++)
                            val[c] = sample(S.L[c >> 2], F, &G, x + (c & 1), y + ((c >> 1) & 1));
                        if ((x == 0 || y == 0 || z == 0 || x == N - 1 || y == N - 1 || z == N - 1))
                            for (c = 0; c < 8; c++) if (val[c] < 0) die("the surface reaches the grid's boundary");
                        cube(&S, x, y, z, val);
                    }
            }
    }
    layer_free(&A, F);
    layer_free(&B, F);
    free(S.ez); free(S.ezs); free(G.state);
}

/* ---- statistics and checks ------------------------------------------------ */

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static uint32_t find(uint32_t *p, uint32_t a)
{
    while (p[a] != a) { p[a] = p[p[a]]; a = p[a]; }
    return a;
}

typedef struct stats {
    size_t components, floating;
    long genus, main_genus;
    double slivers, tiny, zero_area;
} stats;

/* Closed and oriented: every directed edge once, its reverse once. */
static void check_closed(const mesh *M)
{
    size_t n = 3 * M->nf, i;
    uint64_t *e = (uint64_t *)xmalloc(n * sizeof(uint64_t));
    for (i = 0; i < M->nf; i++) {
        int k;
        for (k = 0; k < 3; k++) {
            uint64_t a = M->f[3 * i + k], b = M->f[3 * i + (k + 1) % 3];
            if (a == b) die("internal error: a face repeats a vertex");
            e[3 * i + k] = a << 32 | b;
        }
    }
    qsort(e, n, sizeof *e, cmp_u64);
    for (i = 0; i < n; i++) {
        uint64_t r = (e[i] & 0xffffffffu) << 32 | e[i] >> 32;
        if (i + 1 < n && e[i + 1] == e[i]) die("internal error: a directed edge appears twice");
        if (!bsearch(&r, e, n, sizeof *e, cmp_u64)) die("internal error: an edge without its twin (the surface is open)");
    }
    free(e);
}

static stats measure(const mesh *M)
{
    stats S;
    uint32_t *par = (uint32_t *)xmalloc(M->nv * sizeof(uint32_t)), i, big = 0;
    size_t *nv = (size_t *)xcalloc(M->nv, sizeof(size_t)), *nf = (size_t *)xcalloc(M->nv, sizeof(size_t)), f;
    double mean = 0, *area = (double *)xmalloc(M->nf * sizeof(double));
    memset(&S, 0, sizeof S);
    for (i = 0; i < M->nv; i++) par[i] = i;
    for (f = 0; f < M->nf; f++) {
        uint32_t a = find(par, M->f[3 * f]), b = find(par, M->f[3 * f + 1]), c = find(par, M->f[3 * f + 2]);
        if (a != b) par[a > b ? a : b] = a < b ? a : b;
        a = find(par, a); c = find(par, c);
        if (a != c) par[a > c ? a : c] = a < c ? a : c;
    }
    for (i = 0; i < M->nv; i++) nv[find(par, i)]++;
    for (f = 0; f < M->nf; f++) nf[find(par, M->f[3 * f])]++;
    for (i = 0; i < M->nv; i++)
        if (par[i] == i) {
            long chi = (long)nv[i] - (long)nf[i] / 2;   /* V - E + F with E = 3F/2 */
            S.components++;
            S.genus += (2 - chi) / 2;
            if (nf[i] > nf[big] || par[big] != big) big = i;
        }
    S.main_genus = (2 - ((long)nv[big] - (long)nf[big] / 2)) / 2;
    S.floating = S.components - 1;
    for (f = 0; f < M->nf; f++) {
        const float *p[3];
        double e[3][3], cr[3], minang = 180;
        int k;
        for (k = 0; k < 3; k++) p[k] = M->v + 3 * (size_t)M->f[3 * f + k];
        for (k = 0; k < 3; k++) set3(e[k], (double)p[(k + 1) % 3][0] - p[k][0], (double)p[(k + 1) % 3][1] - p[k][1],
                                    (double)p[(k + 1) % 3][2] - p[k][2]);
        cr[0] = e[0][1] * e[2][2] - e[0][2] * e[2][1];
        cr[1] = e[0][2] * e[2][0] - e[0][0] * e[2][2];
        cr[2] = e[0][0] * e[2][1] - e[0][1] * e[2][0];
        area[f] = 0.5 * sqrt(dot3(cr, cr));
        mean += area[f];
        if (area[f] == 0) { S.zero_area++; S.slivers++; continue; }
        for (k = 0; k < 3; k++) {   /* angle at corner k between e[k] and -e[k-1] */
            const double *a = e[k], *b = e[(k + 2) % 3];
            double c[3], d = -dot3(a, b), ang;
            c[0] = a[1] * b[2] - a[2] * b[1]; c[1] = a[2] * b[0] - a[0] * b[2]; c[2] = a[0] * b[1] - a[1] * b[0];
            ang = atan2(sqrt(dot3(c, c)), d) * (180 / 3.14159265358979323846);
            if (ang < minang) minang = ang;
        }
        if (minang < 1) S.slivers++;
    }
    mean /= M->nf ? (double)M->nf : 1;
    for (f = 0; f < M->nf; f++) if (area[f] < 1e-4 * mean) S.tiny++;
    S.slivers /= M->nf; S.tiny /= M->nf; S.zero_area /= M->nf;
    free(par); free(nv); free(nf); free(area);
    return S;
}

/* ---- output ---------------------------------------------------------------- */

static void write_obj(const mesh *M, const char *path, const char *kind, int N, uint64_t seed)
{
    char tmp[4096];
    FILE *fp;
    size_t i;
    static char buf[1 << 20];
    if (snprintf(tmp, sizeof tmp, "%s.tmp", path) >= (int)sizeof tmp) die("path too long");
    fp = fopen(tmp, "w");
    if (!fp) die("cannot write the output");
    setvbuf(fp, buf, _IOFBF, sizeof buf);
    fprintf(fp, "# bench/mcmesh.c %s grid %d seed %llu: %lu vertices, %lu faces\n", kind, N,
            (unsigned long long)seed, (unsigned long)M->nv, (unsigned long)M->nf);
    for (i = 0; i < M->nv; i++)
        fprintf(fp, "v %.9g %.9g %.9g\n", M->v[3 * i], M->v[3 * i + 1], M->v[3 * i + 2]);
    for (i = 0; i < M->nf; i++)
        fprintf(fp, "f %lu %lu %lu\n", (unsigned long)M->f[3 * i] + 1, (unsigned long)M->f[3 * i + 1] + 1,
                (unsigned long)M->f[3 * i + 2] + 1);
    if (ferror(fp) | fclose(fp)) { remove(tmp); die("cannot write the output"); }
    if (rename(tmp, path)) { remove(tmp); die("cannot rename the output"); }
}

int main(int argc, char **argv)
{
    field F;
    mesh M;
    stats S;
    int N = 0, ai = 1;
    long target;
    unsigned long long seed;
    clock_t t0 = clock();
    if (argc > 2 && !strcmp(argv[1], "--grid")) { N = atoi(argv[2]); ai = 3; }
    if (argc - ai != 4) {
        fprintf(stderr, "usage: mcmesh [--grid N] blob|noisy FACES SEED OUT.obj\n");
        return 2;
    }
    target = atol(argv[ai + 1]);
    seed = strtoull(argv[ai + 2], NULL, 10);
    make_field(&F, argv[ai], seed);
    face_tables();
    memset(&M, 0, sizeof M);
    if (N <= 0) {      /* faces grow as N^2: one pass on 160^3 gives the grid */
        int N0 = 160;
        if (target <= 0) die("FACES must be positive");
        octave_tables(&F, N0);
        march(&F, N0, &M);
        N = (int)floor(N0 * sqrt((double)target / (double)M.nf) + 0.5);
        if (N < 16) N = 16;
        M.nv = M.nf = 0;
    }
    octave_tables(&F, N);
    march(&F, N, &M);
    check_closed(&M);
    S = measure(&M);
    write_obj(&M, argv[ai + 3], argv[ai], N, seed);
    printf("{\"kind\":\"%s\",\"seed\":%llu,\"grid\":%d,\"faces\":%lu,\"vertices\":%lu,\"components\":%lu,"
           "\"floating\":%lu,\"genus\":%ld,\"main_genus\":%ld,\"slivers\":%.5f,\"tiny\":%.5f,\"zero_area\":%.6f,"
           "\"lipschitz\":%.3f,\"seconds\":%.2f}\n",
           argv[ai], seed, N, (unsigned long)M.nf, (unsigned long)M.nv, (unsigned long)S.components,
           (unsigned long)S.floating, S.genus, S.main_genus, S.slivers, S.tiny, S.zero_area, F.lipschitz,
           (double)(clock() - t0) / CLOCKS_PER_SEC);
    free(M.v); free(M.f);
    return 0;
}
