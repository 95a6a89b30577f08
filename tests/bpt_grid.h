/* bpt_grid.h - flat test charts shared by tests/test_pack.c and
   bench/pack_bench.c (no test framework, so the bench can include it).

   bpt_add_grid appends to positions/triangles the caller has room for: a
   (w+1) x (h+1) vertex grid of cells of side s, rotated by a and moved to
   (ox, oy) in the z = 0 plane, two counter-clockwise triangles per cell;
   kind 1 drops the cells with i >= w/2 and j >= h/2 (an L shape), kind 2
   the middle cell (a hole). */
#ifndef BPT_GRID_H
#define BPT_GRID_H
#include <math.h>
#include <stdint.h>

typedef struct bpt_gen { double *pos; uint32_t *tri; uint32_t nv, nt; } bpt_gen;

static inline void bpt_add_grid(bpt_gen *g, int w, int h, int kind, double s, double a, double ox, double oy)
{
    uint32_t base = g->nv;
    int i, j;
    double c = cos(a), sn = sin(a);
    for (j = 0; j <= h; j++)
        for (i = 0; i <= w; i++) {
            double x = i * s, y = j * s;
            g->pos[3 * g->nv] = ox + c * x - sn * y;
            g->pos[3 * g->nv + 1] = oy + sn * x + c * y;
            g->pos[3 * g->nv + 2] = 0;
            g->nv++;
        }
    for (j = 0; j < h; j++)
        for (i = 0; i < w; i++) {
            uint32_t v00 = base + (uint32_t)(j * (w + 1) + i), v10 = v00 + 1, v01 = v00 + (uint32_t)(w + 1), v11 = v01 + 1;
            if (kind == 1 && i >= w / 2 && j >= h / 2) continue;                /* L shape */
            if (kind == 2 && i == w / 2 && j == h / 2) continue;                /* a hole */
            g->tri[3 * g->nt] = v00; g->tri[3 * g->nt + 1] = v10; g->tri[3 * g->nt + 2] = v11; g->nt++;
            g->tri[3 * g->nt] = v00; g->tri[3 * g->nt + 1] = v11; g->tri[3 * g->nt + 2] = v01; g->nt++;
        }
}
#endif
