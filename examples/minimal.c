/* minimal.c - the smallest complete program: a bumpy 20x20 height field is
   built in memory, flattened bijectively with the default options (symmetric
   Dirichlet energy, free boundary), and its mean distortion is printed
   before and after the optimization (4 would be an isometry). */
#include <math.h>
#include <stdio.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

enum { N = 20 };                                   /* vertices per side */

int main(void)
{
    double pos[3 * N * N];
    uint32_t tri[6 * (N - 1) * (N - 1)], i, j, t = 0;
    bp_mesh mesh = { 0 };
    bp_options opt = { 0 };                        /* 0 = defaults */
    bp_atlas atlas;
    bp_error err;
    for (i = 0; i < N; i++)
        for (j = 0; j < N; j++) {                  /* z = bumps over [0,1]^2 */
            double x = (double)j / (N - 1), y = (double)i / (N - 1);
            pos[3 * (i * N + j)] = x; pos[3 * (i * N + j) + 1] = y;
            pos[3 * (i * N + j) + 2] = 0.15 * sin(6 * x) * cos(5 * y);
        }
    for (i = 0; i + 1 < N; i++)
        for (j = 0; j + 1 < N; j++) {              /* two CCW triangles per square */
            uint32_t a = i * N + j, b = a + 1, c = a + N + 1, d = a + N;
            tri[t++] = a; tri[t++] = b; tri[t++] = c;
            tri[t++] = a; tri[t++] = c; tri[t++] = d;
        }
    mesh.positions = pos; mesh.num_vertices = N * N;
    mesh.triangles = tri; mesh.num_triangles = t / 3;
    if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK) { puts(err.message); return 1; }
    printf("%u chart(s); energy %.4f -> %.4f after %d iterations (%s)\n",
           (unsigned)atlas.num_charts, atlas.charts[0].energy_start, atlas.charts[0].energy_end,
           atlas.charts[0].iterations, bp_stop_string(atlas.charts[0].stop));
    bp_atlas_free(&atlas);
    return 0;
}
