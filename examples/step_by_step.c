/* step_by_step.c - watching the solver one iteration at a time.

   The API offers two honest ways, and this example runs both on chart 0 of
   a mesh (default tests/data/bishop_part_f1000.obj):

   1. The progress callback.  bp_chart_optimize calls it once per accepted
      iteration with the mean energy and the step length t of the line
      search; during the call the chart's uv holds the current map, which is
      exactly valid (here we also run bp_check on it to prove that).  This
      *is* the solver's own sequence of iterates; the callback can stop it
      by returning nonzero (the chart keeps the last valid map).

   2. Calling bp_chart_optimize with max_iterations = 1 again and again.
      Each call continues from the chart's current map, but it is a fresh
      solve: the L-BFGS memory is empty, the line search starts anew and
      the preconditioner is factored again.  So the iterates differ from
      (1): with an empty memory every step is a preconditioned gradient
      step.  In the first few iterations the two are close; over many the
      memory pays (on tests/data/camel_b.obj, 100 iterations of one solve
      reach a mean energy of 7.87, 100 one-iteration calls only 12.8).

       build/examples/step_by_step [mesh.obj|mesh.off] [iterations] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

typedef struct watch { const bp_chart *chart; int bad; } watch;

static int on_step(void *user, uint32_t chart, int iteration, double energy, double step)
{
    watch *w = (watch *)user;
    bp_check_report rep;
    const bp_chart *c = w->chart;
    int valid = bp_check(c->triangles, c->num_triangles, c->uv, c->num_vertices, NULL, &rep, NULL) == BP_OK;
    if (!valid) w->bad++;
    printf("  chart %u  iteration %3d  energy %.6f  step %.3g  %s\n", (unsigned)chart, iteration,
           energy, step, valid ? "valid" : "INVALID");
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "tests/data/bishop_part_f1000.obj";
    int n = argc > 2 ? atoi(argv[2]) : 15, k;
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    watch w = { NULL, 0 };
    bp_chart *c;
    double *start;

    memset(&opt, 0, sizeof opt);
    if (bp_read_mesh(path, &mesh, NULL, &err) != BP_OK) { fprintf(stderr, "%s: %s\n", path, err.message); return 1; }
    if (bp_atlas_build(&atlas, &mesh, &opt, &err) != BP_OK ||
        bp_chart_init(&atlas.charts[0], &mesh, &opt, &err) != BP_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        bp_mesh_free(&mesh, NULL);
        return 1;
    }
    c = &atlas.charts[0];
    start = (double *)malloc(2 * (size_t)c->num_vertices * sizeof(double));
    if (!start) return 1;
    memcpy(start, c->uv, 2 * (size_t)c->num_vertices * sizeof(double));  /* the Tutte map */

    printf("1. one solve of %d iterations, watched by the progress callback:\n", n);
    w.chart = c;
    opt.progress = on_step;
    opt.progress_user = &w;
    opt.max_iterations = n;
    if (bp_chart_optimize(c, 0, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
    printf("  -> energy %.6f after %d iterations\n\n", c->energy_end, c->iterations);

    printf("2. %d calls with max_iterations = 1 from the same start map:\n", n);
    memcpy(c->uv, start, 2 * (size_t)c->num_vertices * sizeof(double));
    opt.progress = NULL;
    opt.max_iterations = 1;
    for (k = 1; k <= n; k++) {
        if (bp_chart_optimize(c, 0, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s\n", err.message); return 1; }
        printf("  call %3d  energy %.6f  (%s)\n", k, c->energy_end, bp_stop_string(c->stop));
        if (c->stop != BP_STOP_MAX_ITERATIONS) break;   /* converged or no progress */
    }
    printf("  -> energy %.6f (each call starts with an empty L-BFGS memory)\n", c->energy_end);
    printf("%s\n", w.bad ? "some iterate was INVALID" : "every iterate of (1) passed bp_check");

    free(start);
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    return w.bad != 0;
}
