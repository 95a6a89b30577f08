/* minimal.c - the smallest complete use of bijparam.h.

   Reads an OBJ or OFF mesh, flattens every chart bijectively with the
   default options, proves each chart's map with the exact bp_check,
   prints one line per chart and writes the result as OBJ.

       gcc -std=c99 -Wall -Wextra -pedantic -Werror -I. minimal.c -lm
       ./a.out tests/data/bishop_part_f1000.obj out.obj

   It also compiles as C++ (g++ -x c++).  Exit status: 0 success,
   1 failure (one line on stderr). */
#include <stdio.h>
#include <string.h>

#define BP_IMPLEMENTATION
#include "bijparam.h"

/* Called once per accepted iteration of each chart; nonzero cancels. */
static int progress(void *user, uint32_t chart, int iteration, double mean_energy, double step)
{
    (void)user; (void)step;
    if (iteration % 100 == 0)
        fprintf(stderr, "chart %u: iteration %d, mean energy %.6f\n",
                (unsigned)chart, iteration, mean_energy);
    return 0;
}

int main(int argc, char **argv)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    bp_status st;
    uint32_t c;
    int bad = 0;

    if (argc != 3) {
        fprintf(stderr, "usage: %s IN.obj|IN.off OUT.obj\n", argv[0]);
        return 1;
    }
    if (bp_read_mesh(argv[1], &mesh, NULL, &err) != BP_OK) {
        fprintf(stderr, "%s: %s\n", argv[1], err.message);
        return 1;
    }
    memset(&opt, 0, sizeof opt);       /* every field 0: the defaults */
    opt.progress = progress;

    st = bp_parameterize(&atlas, &mesh, &opt, &err);
    if (st != BP_OK) {                 /* the atlas is already freed
                                          (except after BP_ERR_CANCELLED) */
        fprintf(stderr, "%s: %s (%s)\n", argv[1], err.message, bp_status_string(st));
        bp_mesh_free(&mesh, NULL);
        return 1;
    }

    for (c = 0; c < atlas.num_charts; c++) {
        const bp_chart *ch = &atlas.charts[c];
        bp_check_report rep;
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices,
                     NULL, &rep) != BP_OK) {
            bad = 1;
            continue;
        }
        if (rep.flipped || rep.degenerate || rep.nonfinite || rep.boundary_intersections)
            bad = 1;
        printf("chart %u: %u triangles, %u loops, %s energy %.4f -> %.4f (max %.4f), "
               "%d iterations, stop: %s, flipped %u, boundary intersections %u\n",
               (unsigned)c, (unsigned)ch->num_triangles, (unsigned)ch->num_loops,
               bp_energy_name(opt.energy), ch->energy_start, ch->energy_end,
               ch->energy_max, ch->iterations, bp_stop_string(ch->stop),
               (unsigned)rep.flipped, (unsigned)rep.boundary_intersections);
    }

    if (bp_write_obj(argv[2], &mesh, &atlas, &err) != BP_OK) {
        fprintf(stderr, "%s: %s\n", argv[2], err.message);
        bad = 1;
    }
    bp_atlas_free(&atlas);             /* the atlas remembers its allocator */
    bp_mesh_free(&mesh, NULL);         /* same allocator as bp_read_mesh  */
    return bad;
}
