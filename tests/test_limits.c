/* test_limits.c - a chart beyond the sparse factor's size limit fails with
   BP_ERR_TOO_LARGE, naming the chart, its size and the limit, and not with
   BP_ERR_OUT_OF_MEMORY.

   The real limit (2^32 - 16 entries of L) needs a chart of hundreds of
   millions of triangles, so this test lowers it before including the
   header: BP__FACTOR_MAX_NNZ is 20000 here.  camel_b (3576 triangles) has
   about 35 000 entries in its preconditioner's L and
   fails; the one-triangle charts and the small grid below stay under the
   limit and succeed, so the limit is a threshold on the size and not a
   failure of every factorization.  The sizes in the message are checked
   against the mesh (bpt_has_number). */
#define BP__FACTOR_MAX_NNZ 20000u
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <stdio.h>
#include <string.h>

/* bp_chart_init then bp_chart_optimize on chart 0 of a one-chart mesh. */
static bp_status init_and_optimize(const bp_mesh *m, bp_error *e, uint32_t *nt)
{
    bp_options o;
    bp_atlas at;
    bp_status st;
    memset(&o, 0, sizeof o);
    o.max_iterations = 5;
    o.threads = 1;
    st = bp_atlas_build(&at, m, &o, e);
    if (st != BP_OK) return st;
    *nt = at.charts[0].num_triangles;
    st = bp_chart_init(&at.charts[0], m, &o, e);
    if (st == BP_OK) st = bp_chart_optimize(&at.charts[0], 0, m, &o, e);
    bp_atlas_free(&at);
    return st;
}

static void check_camel(void)
{
    bp_mesh m;
    bp_error e;
    bp_options o;
    bp_atlas at;
    bp_status st;
    uint32_t nt = 0;
    if (bp_read_mesh("tests/data/camel_b.obj", &m, NULL, &e) != BP_OK) {
        BPT_CHECK(0, "read tests/data/camel_b.obj: %s", e.message);
        return;
    }
    memset(&e, 0, sizeof e);
    st = init_and_optimize(&m, &e, &nt);
    BPT_CHECK(st == BP_ERR_TOO_LARGE && e.status == BP_ERR_TOO_LARGE,
              "camel_b, factor limit 20000: BP_ERR_TOO_LARGE, not \"%s\" (%s)", bp_status_string(st), e.message);
    BPT_CHECK(bpt_has_number(e.message, 20000) && bpt_has_number(e.message, (long long)nt) && nt == m.num_triangles,
              "the message names the limit 20000 and the chart's %u triangles: \"%s\"", nt, e.message);
    BPT_CHECK(strcmp(bp_status_string(BP_ERR_TOO_LARGE), bp_status_string(BP_ERR_OUT_OF_MEMORY)) != 0 &&
              (int)BP_ERR_TOO_LARGE == (int)BP_ERR_CHARTS_FAILED + 1,
              "BP_ERR_TOO_LARGE has its own string (\"%s\") and comes after BP_ERR_CHARTS_FAILED",
              bp_status_string(BP_ERR_TOO_LARGE));
    /* through bp_parameterize: its only chart fails, so the call returns
       the chart's own status (and frees the atlas) */
    memset(&o, 0, sizeof o);
    o.max_iterations = 5;
    memset(&e, 0, sizeof e);
    st = bp_parameterize(&at, &m, &o, &e);
    BPT_CHECK(st == BP_ERR_TOO_LARGE && bpt_has_number(e.message, 20000) && bpt_has_number(e.message, 3576),
              "bp_parameterize on camel_b: %s, \"%s\"", bp_status_string(st), e.message);
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* A 10 x 10 grid of squares (200 triangles, a bump in z): far below the
   limit, it is solved. */
static void check_small(void)
{
    enum { N = 10 };
    static double pos[3 * (N + 1) * (N + 1)];
    static uint32_t tri[6 * N * N];
    bp_mesh m;
    bp_error e;
    uint32_t i, j, k = 0, nt = 0;
    bp_status st;
    memset(&m, 0, sizeof m);
    for (j = 0; j <= N; j++)
        for (i = 0; i <= N; i++) {
            double *p = pos + 3 * (j * (N + 1) + i);
            p[0] = i; p[1] = j; p[2] = 0.05 * (double)(i * (N - i) + j * (N - j));
        }
    for (j = 0; j < N; j++)
        for (i = 0; i < N; i++) {
            uint32_t a = j * (N + 1) + i, b = a + 1, c = a + N + 2, d = a + N + 1;
            tri[k++] = a; tri[k++] = b; tri[k++] = c;
            tri[k++] = a; tri[k++] = c; tri[k++] = d;
        }
    m.positions = pos; m.num_vertices = (N + 1) * (N + 1);
    m.triangles = tri; m.num_triangles = 2 * N * N;
    m.num_faces = m.num_triangles;
    st = init_and_optimize(&m, &e, &nt);
    BPT_CHECK(st == BP_OK, "a 200-triangle grid under the same limit is solved (%s)", st == BP_OK ? "ok" : e.message);
}

int main(void)
{
    check_camel();
    check_small();
    return bpt_finish();
}
