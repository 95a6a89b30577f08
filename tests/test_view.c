/* test_view.c - bp_mesh_view: positions as float or double at any byte
   stride.  A mesh taken from an interleaved float buffer, from a double
   buffer with a stride, and from packed doubles (used in place, no copy)
   has the same positions as the mesh it came from and gives bit for bit
   the same map; bad strides and types are refused. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include <string.h>

typedef struct vtx_f { float nrm[3]; float pos[3]; float uv[2]; unsigned char rgba[4]; } vtx_f;   /* 48 bytes */
typedef struct vtx_d { double pos[3]; float w; } vtx_d;                                           /* 32 bytes */

static bp_mesh base;

static void make_base(void)
{
    enum { N = 10 };
    static double pos[3 * (N + 1) * (N + 1)];
    static uint32_t tri[6 * N * N];
    int i, j, t = 0;
    for (i = 0; i <= N; i++)
        for (j = 0; j <= N; j++) {         /* multiples of 1/64: exact as float */
            double *p = pos + 3 * (i * (N + 1) + j);
            p[0] = j; p[1] = i; p[2] = (double)(int)(bpt_rng_unit() * 64) / 64;
        }
    for (i = 0; i < N; i++)
        for (j = 0; j < N; j++) {
            uint32_t v = (uint32_t)(i * (N + 1) + j);
            tri[t++] = v; tri[t++] = v + 1; tri[t++] = v + N + 2;
            tri[t++] = v; tri[t++] = v + N + 2; tri[t++] = v + N + 1;
        }
    memset(&base, 0, sizeof base);
    base.positions = pos;
    base.num_vertices = (N + 1) * (N + 1);
    base.triangles = tri;
    base.num_triangles = 2 * N * N;
}

/* The map of m, and whether it equals the base mesh's map bit for bit. */
static int same_map(const bp_mesh *m, const bp_atlas *ref)
{
    bp_atlas at;
    bp_error err;
    bp_options opt;
    int same;
    bp_options_init(&opt);
    if (bp_parameterize(&at, m, &opt, &err) != BP_OK) return 0;
    same = at.num_charts == ref->num_charts && at.charts[0].num_vertices == ref->charts[0].num_vertices &&
           !memcmp(at.charts[0].uv, ref->charts[0].uv, 2 * sizeof(double) * ref->charts[0].num_vertices);
    bp_atlas_free(&at);
    return same;
}

int main(void)
{
    static vtx_f vf[121];
    static vtx_d vd[121];
    bp_mesh_view view;
    bp_mesh m;
    bp_atlas ref;
    bp_error err;
    bp_options opt;
    uint32_t i;
    make_base();
    bp_options_init(&opt);
    BPT_CHECK(bp_parameterize(&ref, &base, &opt, &err) == BP_OK, "the reference map: %s", err.message);
    for (i = 0; i < base.num_vertices; i++) {
        int k;
        for (k = 0; k < 3; k++) {
            vf[i].pos[k] = (float)base.positions[3 * i + k];
            vf[i].nrm[k] = 9;
            vd[i].pos[k] = base.positions[3 * i + k];
        }
        vd[i].w = -1;
    }
    /* interleaved float */
    memset(&view, 0, sizeof view);
    view.positions = vf[0].pos;
    view.position_type = BP_SCALAR_F32;
    view.position_stride = sizeof(vtx_f);
    view.num_vertices = base.num_vertices;
    view.triangles = base.triangles;
    view.num_triangles = base.num_triangles;
    BPT_CHECK(bp_mesh_from_view(&m, &view, NULL, &err) == BP_OK && m.positions != base.positions &&
              !memcmp(m.positions, base.positions, 3 * sizeof(double) * base.num_vertices) &&
              m.triangles == base.triangles, "interleaved float (stride %u): converted to the same doubles, "
              "triangles borrowed", (unsigned)sizeof(vtx_f));
    BPT_CHECK(same_map(&m, &ref), "interleaved float: the same map bit for bit");
    bp_mesh_view_free(&m, &view, NULL);
    BPT_CHECK(m.positions == NULL && m.triangles == NULL, "bp_mesh_view_free zeroes the mesh");
    /* double with a stride */
    view.positions = vd[0].pos;
    view.position_type = BP_SCALAR_F64;
    view.position_stride = sizeof(vtx_d);
    BPT_CHECK(bp_mesh_from_view(&m, &view, NULL, &err) == BP_OK &&
              !memcmp(m.positions, base.positions, 3 * sizeof(double) * base.num_vertices) && same_map(&m, &ref),
              "double at stride %u: the same positions and map", (unsigned)sizeof(vtx_d));
    bp_mesh_view_free(&m, &view, NULL);
    /* packed double: used in place */
    view.positions = base.positions;
    view.position_stride = 0;
    BPT_CHECK(bp_mesh_from_view(&m, &view, NULL, &err) == BP_OK && m.positions == base.positions && same_map(&m, &ref),
              "packed double: no copy (the caller's array), the same map");
    bp_mesh_view_free(&m, &view, NULL);
    BPT_CHECK(base.positions[0] == 0 && base.positions[3] == 1, "bp_mesh_view_free leaves the caller's array alone");
    /* refused */
    view.position_stride = 16;
    BPT_CHECK(bp_mesh_from_view(&m, &view, NULL, &err) == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, 16) &&
              bpt_has_number(err.message, 24) && m.positions == NULL, "a stride shorter than x y z: refused (%s)",
              err.message);
    view.position_stride = 0;
    view.position_type = (bp_scalar)7;
    BPT_CHECK(bp_mesh_from_view(&m, &view, NULL, &err) == BP_ERR_INVALID_ARGUMENT, "an unknown type: refused (%s)",
              err.message);
    bp_atlas_free(&ref);
    return bpt_finish();
}
