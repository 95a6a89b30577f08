/* custom_energy.c - weighting the distortion per triangle ("painting").

   bijparam has no callback for a user-defined energy: the energy is one of
   the five of bp_energy (symmetric Dirichlet by default).  What it does let
   you change per triangle is the *importance* I_t of eq 4.1: opt.importance
   holds one weight > 0 per mesh triangle, and the optimizer then measures
   triangle t against a rest shape sqrt(I_t) times larger and weights its
   energy by I_t, so in the result the triangle gets about I_t times its 3D
   area in UV space.  Painting large weights on a region buys it more
   texels (sharper texture) at the cost of the rest; this is exactly how the
   chapter 4 visibility maps are made (with I_t = visibility).

   Here we paint the top quarter of the mesh (by height along +y) with
   weight W and compare the share of UV area it gets with and without the
   paint.  With a third argument the two layouts are also written as SVG,
   coloured by area ratio (examples/bp_draw.h): PREFIX_plain.svg and
   PREFIX_painted.svg.

       build/examples/custom_energy [mesh] [W] [PREFIX] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"
#define BPD_IMPLEMENTATION
#include "bp_draw.h"

static double area2(const double *a, const double *b, const double *c)
{
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

static double area3(const double *a, const double *b, const double *c)
{
    double u[3], v[3], x, y, z;
    int k;
    for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = c[k] - a[k]; }
    x = u[1] * v[2] - u[2] * v[1]; y = u[2] * v[0] - u[0] * v[2]; z = u[0] * v[1] - u[1] * v[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

/* Share of the atlas's UV area (and of the 3D area) taken by painted triangles. */
static void shares(const bp_mesh *m, const bp_atlas *a, const unsigned char *painted,
                   double *uv_share, double *area_share)
{
    double uv_p = 0, uv_all = 0, a_p = 0, a_all = 0;
    uint32_t c, t;
    for (c = 0; c < a->num_charts; c++) {
        const bp_chart *ch = &a->charts[c];
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t;
            const uint32_t *mt = m->triangles + 3 * (size_t)ch->face[t];
            double A2 = area2(ch->uv + 2 * tr[0], ch->uv + 2 * tr[1], ch->uv + 2 * tr[2]);
            double A3 = area3(m->positions + 3 * mt[0], m->positions + 3 * mt[1], m->positions + 3 * mt[2]);
            uv_all += A2; a_all += A3;
            if (painted[ch->face[t]]) { uv_p += A2; a_p += A3; }
        }
    }
    *uv_share = uv_p / uv_all;
    *area_share = a_p / a_all;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "tests/data/camel_b.obj";
    double W = argc > 2 ? atof(argv[2]) : 8, lo = 1e300, hi = -1e300, uvs, as;
    const char *prefix = argc > 3 ? argv[3] : NULL;
    bp_mesh mesh;
    bp_atlas plain, painted;
    bp_error err;
    bp_options opt;
    double *importance;
    unsigned char *mask;
    uint32_t i, t;
    char name[1024];

    if (!(W > 0)) { fprintf(stderr, "W must be > 0\n"); return 2; }
    if (bp_read_mesh(path, &mesh, NULL, &err) != BP_OK) { fprintf(stderr, "%s: %s\n", path, err.message); return 1; }
    importance = (double *)malloc(mesh.num_triangles * sizeof(double));
    mask = (unsigned char *)malloc(mesh.num_triangles);
    if (!importance || !mask) return 1;
    for (i = 0; i < mesh.num_vertices; i++) {
        double y = mesh.positions[3 * i + 1];
        if (y < lo) lo = y;
        if (y > hi) hi = y;
    }
    for (t = 0; t < mesh.num_triangles; t++) {   /* the paint: centroid in the top quarter */
        double y = 0;
        for (i = 0; i < 3; i++) y += mesh.positions[3 * mesh.triangles[3 * t + i] + 1] / 3;
        mask[t] = y > lo + 0.75 * (hi - lo);
        importance[t] = mask[t] ? W : 1;
    }

    memset(&opt, 0, sizeof opt);
    if (bp_parameterize(&plain, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    opt.importance = importance;                 /* the only difference */
    if (bp_parameterize(&painted, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }

    shares(&mesh, &plain, mask, &uvs, &as);
    printf("painted region: %.1f%% of the 3D area, weight %g\n", 100 * as, W);
    printf("  without importance: %.1f%% of the UV area\n", 100 * uvs);
    shares(&mesh, &painted, mask, &uvs, &as);
    printf("  with importance:    %.1f%% of the UV area (%.2f times its share before weighting)\n",
           100 * uvs, uvs / as);

    if (prefix) {
        bpd_svg_options so;
        memset(&so, 0, sizeof so);
        so.color = BPD_COLOR_AREA;
        snprintf(name, sizeof name, "%s_plain.svg", prefix);
        so.title = "no importance";
        if (!bpd_write_atlas_svg(name, &mesh, &plain, &so)) perror(name);
        snprintf(name, sizeof name, "%s_painted.svg", prefix);
        so.title = "top quarter painted with importance W";
        if (!bpd_write_atlas_svg(name, &mesh, &painted, &so)) perror(name);
    }
    bp_atlas_free(&plain);
    bp_atlas_free(&painted);
    bp_mesh_free(&mesh, NULL);
    free(importance);
    free(mask);
    return 0;
}
