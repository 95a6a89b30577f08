/* fuzz_gltf.c - libFuzzer harness for examples/bp_gltf.h: the reader, then
   the writer's round trip.

   The input is a .glb or a .gltf (external files refused: no folder is
   given).  Properties:
     - never crash, leak (LeakSanitizer), hang or read outside the input
       (it is copied into a block of its exact size);
     - a failure returns a status in range with a message, and leaves the
       file zeroed;
     - a file read has a mesh the library accepts as input (indices in
       range, finite positions, uv indices in range and finite uvs);
     - its charts get a Tutte start map (bp_atlas_solve, init only: small
       and quick) and bpg_encode writes the file as .glb and as .gltf;
       a write that fails says why; a file written reads back, in the
       format written, with the same triangles at the same positions and a
       finite TEXCOORD_0 at every corner. */
#ifndef BP_FUZZ_EXTERNAL_IMPL  /* else bijparam.h is compiled once, separately */
#define BP_IMPLEMENTATION
#endif
#include "bijparam.h"
#define BPG_IMPLEMENTATION
#include "examples/bp_gltf.h"
#include "fuzz_common.h"

static void check_back(const bpg_file *g, const bpg_output *out, int glb)
{
    bpg_file back;
    bp_error err;
    bp_status st = bpg_parse(&back, out->data, out->size, NULL, NULL, &err);
    uint32_t t, k;
    if (st != BP_OK) fuzz_fail("the %s written does not read back: %s", glb ? ".glb" : ".gltf", err.message);
    if (back.glb != glb) fuzz_fail("wrote glb %d, read back %d", glb, back.glb);
    if (back.mesh.num_triangles != g->mesh.num_triangles)
        fuzz_fail("%u triangles written, %u read back", g->mesh.num_triangles, back.mesh.num_triangles);
    if (!back.has_uv || !back.mesh.corner_uv) fuzz_fail("written without TEXCOORD_0 on every primitive");
    for (t = 0; t < g->mesh.num_triangles; t++)
        for (k = 0; k < 3; k++) {
            const double *a = g->mesh.positions + 3 * (size_t)g->mesh.triangles[3 * t + k];
            uint32_t j, found = 0;
            /* the corner may have moved to another place of its triangle (a re-oriented one) */
            for (j = 0; j < 3; j++) {
                const double *b = back.mesh.positions + 3 * (size_t)back.mesh.triangles[3 * t + j];
                found |= a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
            }
            if (!found) fuzz_fail("triangle %u corner %u: its position is not in the triangle read back", t, k);
        }
    fuzz_check_mesh(&back.mesh);
    bpg_free(&back);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *copy = fuzz_copy(data, size);
    bpg_file g;
    bp_error err;
    bp_status st;
    memset(&g, 0xAB, sizeof g);
    st = bpg_parse(&g, copy, size, NULL, NULL, &err);
    free(copy);
    if (st != BP_OK) {
        fuzz_check_error(st, &err);
        if (g.p || g.mesh.positions || g.mesh.triangles || g.mesh.num_triangles) fuzz_fail("failed read left the file non-zero");
        return 0;
    }
    fuzz_check_mesh(&g.mesh);
    if (g.mesh.num_triangles <= 2000) {
        bp_atlas at;
        bp_options opt;
        bp_options_init(&opt);
        opt.threads = 1;
        opt.init = BP_INIT_TUTTE;
        opt.init_only = 1;
        opt.segment = -1;
        st = bp_atlas_build(&at, &g.mesh, &opt, &err);
        if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) {
            int glb;
            bp_atlas_solve(&at, &g.mesh, &opt, &err);
            for (glb = 0; glb < 2; glb++) {
                bpg_write_options wo;
                bpg_output out;
                memset(&wo, 0, sizeof wo);
                wo.glb = glb;
                st = bpg_encode(&g, &at, &wo, &out, &err);
                if (st != BP_OK) {
                    fuzz_check_error(st, &err);
                    if (out.data || out.bin) fuzz_fail("failed write left output");
                    continue;
                }
                check_back(&g, &out, glb);
                bpg_output_free(&out);
            }
            bp_atlas_free(&at);
        } else
            fuzz_check_error(st, &err);
    }
    bpg_free(&g);
    return 0;
}
