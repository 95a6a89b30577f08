/* bench/fig48.c - one mesh's fig 4.8 matrix (texel density vs isometric).

       fig48 MESH NAME [--front X,Y,Z] [--side X,Y,Z] [--up X,Y,Z]
             [--elevation D] [--samples N] [--measure-samples N] [--floor F]
             [--threads N]

   Builds the plain ("isometric", symmetric Dirichlet without importance)
   map once and one visibility-aware map per view model (columns: uniform,
   front, ring, side), checks every chart of every map with bp_check, and
   measures each map under each view model (rows) with
   bp_texture_to_screen.  Entry (row, column) is
       isometric_det(row) / map_det(column's map, row)
   (> 1: the map shows more texels per screen area than the isometric map
   under the row's views), exactly the tool's `density.ratio` of
       build/bijparam MESH --visibility COL --density-report ROW
   except that the measurement uses its own random stream (seed 0x5EED,
   --measure-samples rays per triangle) independent of the rays the map
   was optimized with.  Prints a markdown block: the matrix, the diagonal
   verdicts and visibility statistics per model.  Also one JSON line
   (prefix "JSON ") for scripts. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

static const char *names[5] = { "", "uniform", "front", "ring", "side" };

static int parse3(const char *s, double *v)
{
    return sscanf(s, "%lf,%lf,%lf", &v[0], &v[1], &v[2]) == 3;
}

static void set_views(bp_views *V, int model, const double *front, const double *side, const double *up,
                      double elev, uint32_t samples, double floor_, uint64_t seed)
{
    memset(V, 0, sizeof *V);
    V->model = model;
    if (model == BP_VIEW_FRONT) memcpy(V->direction, front, 3 * sizeof(double));
    if (model == BP_VIEW_SIDE) memcpy(V->direction, side, 3 * sizeof(double));
    memcpy(V->up, up, 3 * sizeof(double));
    V->elevation = elev;
    V->samples = samples;
    V->floor = floor_;
    V->seed = seed;
}

static int check_atlas(const bp_atlas *A)
{
    uint32_t c, bad = 0;
    for (c = 0; c < A->num_charts; c++) {
        bp_check_report r;
        const bp_chart *ch = &A->charts[c];
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK) bad++;
    }
    return bad == 0;
}

int main(int argc, char **argv)
{
    const char *path = NULL, *name = NULL;
    double front[3] = { 0, 0, 1 }, side[3] = { 1, 0, 0 }, up[3] = { 0, 1, 0 }, elev = 30, floor_ = 0.05;
    uint32_t samples = 64, msamples = 256;
    int threads = 0, i, row, col, ok_all = 1;
    bp_mesh mesh;
    bp_error err;
    bp_options opt, meas;
    bp_atlas iso, maps[5];
    double iso_det[5], det[5][5], ratio[5][5];
    int bij[5];
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--front") && v) { if (!parse3(v, front)) return 2; i++; }
        else if (!strcmp(a, "--side") && v) { if (!parse3(v, side)) return 2; i++; }
        else if (!strcmp(a, "--up") && v) { if (!parse3(v, up)) return 2; i++; }
        else if (!strcmp(a, "--elevation") && v) { elev = atof(v); i++; }
        else if (!strcmp(a, "--samples") && v) { samples = (uint32_t)atoi(v); i++; }
        else if (!strcmp(a, "--measure-samples") && v) { msamples = (uint32_t)atoi(v); i++; }
        else if (!strcmp(a, "--floor") && v) { floor_ = atof(v); i++; }
        else if (!strcmp(a, "--threads") && v) { threads = atoi(v); i++; }
        else if (!path) path = a;
        else if (!name) name = a;
        else { fprintf(stderr, "fig48: unexpected argument %s\n", a); return 2; }
    }
    if (!path) { fprintf(stderr, "usage: fig48 MESH [NAME] [options]\n"); return 2; }
    if (!name) name = path;
    if (bp_read_mesh(path, &mesh, NULL, &err) != BP_OK) { fprintf(stderr, "fig48: %s: %s\n", path, err.message); return 1; }
    memset(&opt, 0, sizeof opt);
    opt.threads = threads;
    if (bp_parameterize(&iso, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "fig48: %s: isometric: %s\n", name, err.message); return 1; }
    bij[0] = check_atlas(&iso);
    for (col = 1; col <= 4; col++) {
        bp_options o = opt;
        set_views(&o.views, col, front, side, up, elev, samples, floor_, 0);
        if (bp_parameterize(&maps[col], &mesh, &o, &err) != BP_OK) {
            fprintf(stderr, "fig48: %s: %s map: %s\n", name, names[col], err.message);
            return 1;
        }
        bij[col] = check_atlas(&maps[col]);
        fprintf(stderr, "fig48: %s: %s map done\n", name, names[col]);
    }
    meas = opt;
    for (row = 1; row <= 4; row++) {
        set_views(&meas.views, row, front, side, up, elev, msamples, floor_, 0x5EED);
        if (bp_texture_to_screen(&mesh, &iso, &meas, &iso_det[row], &err) != BP_OK) return 1;
        for (col = 1; col <= 4; col++) {
            if (bp_texture_to_screen(&mesh, &maps[col], &meas, &det[row][col], &err) != BP_OK) return 1;
            ratio[row][col] = iso_det[row] / det[row][col];
        }
    }
    printf("### %s\n\n", name);
    printf("`%s`: %u vertices, %u triangles, %u charts; front %g,%g,%g; side %g,%g,%g; ring up %g,%g,%g at %g deg; "
           "%u rays per triangle to optimize, %u to measure; floor %g\n\n",
           path, mesh.num_vertices, mesh.num_triangles, iso.num_charts, front[0], front[1], front[2], side[0], side[1],
           side[2], up[0], up[1], up[2], elev, samples, msamples, floor_);
    printf("| measured \\ optimized for | uniform | front | ring | side |\n|---|---|---|---|---|\n");
    for (row = 1; row <= 4; row++) {
        printf("| **%s** |", names[row]);
        for (col = 1; col <= 4; col++) {
            int best = 1, c2;
            for (c2 = 1; c2 <= 4; c2++) if (c2 != col && ratio[row][c2] >= ratio[row][col]) best = 0;
            printf(row == col ? " **%.3f**%s |" : " %.3f%s |", ratio[row][col], best ? " (max)" : "");
        }
        printf("\n");
    }
    printf("\nDiagonal: ");
    for (row = 1; row <= 4; row++) {
        int best = 1, c2;
        for (c2 = 1; c2 <= 4; c2++) if (c2 != row && ratio[row][c2] >= ratio[row][row]) best = 0;
        printf("%s %s%s; ", names[row], best ? "highest in its row" : "NOT highest in its row",
               ratio[row][row] > 1 ? ", > 1" : ", NOT > 1");
        if (!best || !(ratio[row][row] > 1)) ok_all = 0;
    }
    printf("all maps bijective (bp_check on every chart): %s.\n\n", bij[0] && bij[1] && bij[2] && bij[3] && bij[4] ? "yes" : "NO");
    /* visibility statistics per model (the importance the maps were optimized with) */
    printf("| model | raw mean V (area-weighted) | share of area at the floor | normalized V min / max | "
           "mean E_t of the map (area-weighted) | ideal ratio, UV area = max(V, floor) | best possible ratio, UV area ~ sqrt(V) |\n"
           "|---|---|---|---|---|---|---|\n");
    for (col = 1; col <= 4; col++) {
        bp_options o = opt;
        double *raw = (double *)malloc(sizeof(double) * mesh.num_triangles), *nv = (double *)malloc(sizeof(double) * mesh.num_triangles);
        double A = 0, rsum = 0, fl_area = 0, mn = HUGE_VAL, mx = 0, e = 0, ea = 0, gsum = 0, vg = 0, sq = 0;
        uint32_t t, c;
        set_views(&o.views, col, front, side, up, elev, samples, floor_, 0);
        bp__vis_run(&mesh, &o, NULL, NULL, 0, raw, &err);
        bp_visibility(&mesh, &o, nv, &err);
        for (t = 0; t < mesh.num_triangles; t++) {
            const uint32_t *tv = mesh.triangles + 3 * (size_t)t;
            double a = 0.5 * bp__area2_3d(bp__pos(&mesh, tv[0]), bp__pos(&mesh, tv[1]), bp__pos(&mesh, tv[2]));
            A += a; rsum += a * raw[t];
            if (nv[t] <= floor_) fl_area += a;
            /* the measure of a map with UV area s_t per unit 3D area is
               proportional to sum a V / s (sum a s = A): s = normalized,
               floored V (eq 4.1 without distortion) and s ~ sqrt(V), its
               minimizer (Cauchy-Schwarz) */
            gsum += a * nv[t]; vg += a * raw[t] / nv[t]; sq += a * sqrt(raw[t]);
            if (nv[t] < mn) mn = nv[t];
            if (nv[t] > mx) mx = nv[t];
        }
        for (c = 0; c < maps[col].num_charts; c++) {
            double m_, x_;
            bp_chart_distortion(&maps[col].charts[c], &mesh, BP_ENERGY_SYMMETRIC_DIRICHLET, &m_, &x_, NULL, NULL);
            e += m_ * maps[col].charts[c].area3d; ea += maps[col].charts[c].area3d;
        }
        printf("| %s | %.4f | %.1f%% | %.3f / %.3f | %.3f | %.3f | %.3f |\n", names[col], rsum / A, 100 * fl_area / A, mn, mx,
               e / ea, rsum / (vg * gsum / A), rsum * A / (sq * sq));
        free(raw); free(nv);
    }
    printf("\nJSON {\"name\":\"%s\",\"ratio\":[", name);
    for (row = 1; row <= 4; row++) {
        printf("%s[", row > 1 ? "," : "");
        for (col = 1; col <= 4; col++) printf("%s%.6f", col > 1 ? "," : "", ratio[row][col]);
        printf("]");
    }
    printf("],\"iso_det\":[%.6g,%.6g,%.6g,%.6g],\"bijective\":%s,\"diagonal_ok\":%s}\n\n", iso_det[1], iso_det[2],
           iso_det[3], iso_det[4], bij[0] && bij[1] && bij[2] && bij[3] && bij[4] ? "true" : "false",
           ok_all ? "true" : "false");
    bp_atlas_free(&iso);
    for (col = 1; col <= 4; col++) bp_atlas_free(&maps[col]);
    bp_mesh_free(&mesh, NULL);
    return 0;
}
