/* obj_roundtrip.c - OBJ files with seams in and out.

   An OBJ face corner names a position (v) and a texture coordinate (vt).
   Two triangles that share an edge belong to the same chart only if they
   also share the vt indices at both ends of it, so the `vt` seams of the
   file cut the mesh into charts (bp_mesh.corner_uv).  This example reads a
   mesh with seams (default tests/data/spot.obj, 13 charts), prints what
   bp_atlas_build found (charts, their triangles and boundary loops, pinch
   vertices that had to be split), parameterizes it, writes it back with
   bp_write_obj (same v and faces in the same order, new vt: one per chart
   vertex), reads the written file again and checks that it has the same
   charts, the same faces and a valid map in every chart.

       build/examples/obj_roundtrip [in.obj] [out.obj] */
#include <stdio.h>
#include <string.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

static void describe(const char *what, const bp_mesh *m, const bp_atlas *a)
{
    uint32_t c;
    printf("%s: %u vertices, %u vt, %u faces -> %u chart(s), %u pinch vertex split(s)\n", what,
           (unsigned)m->num_vertices, (unsigned)m->num_uvs, (unsigned)m->num_faces,
           (unsigned)a->num_charts, (unsigned)a->num_split);
    for (c = 0; c < a->num_charts && c < 6; c++)
        printf("   chart %u: %u triangles, %u boundary loop(s)\n", (unsigned)c,
               (unsigned)a->charts[c].num_triangles, (unsigned)a->charts[c].num_loops);
    if (a->num_charts > 6) printf("   ...\n");
}

int main(int argc, char **argv)
{
    const char *in = argc > 1 ? argv[1] : "tests/data/spot.obj";
    const char *out = argc > 2 ? argv[2] : "build/examples/roundtrip.obj";
    bp_mesh mesh, back;
    bp_atlas atlas, again;
    bp_error err;
    bp_options opt;
    uint32_t c;
    int ok = 1;

    memset(&opt, 0, sizeof opt);
    if (bp_read_obj(in, &mesh, NULL, &err) != BP_OK) { fprintf(stderr, "%s: %s\n", in, err.message); return 1; }
    if (bp_atlas_build(&atlas, &mesh, &opt, &err) != BP_OK) { fprintf(stderr, "%s: %s\n", in, err.message); return 1; }
    describe(in, &mesh, &atlas);
    bp_atlas_free(&atlas);

    if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK ||
        bp_write_obj(out, &mesh, &atlas, &err) != BP_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    if (bp_read_obj(out, &back, NULL, &err) != BP_OK || bp_atlas_build(&again, &back, &opt, &err) != BP_OK) {
        fprintf(stderr, "%s: %s\n", out, err.message);
        return 1;
    }
    describe(out, &back, &again);
    /* same charts and faces; the written vt are the map: check each chart */
    ok = again.num_charts == atlas.num_charts && back.num_faces == mesh.num_faces &&
         back.num_vertices == mesh.num_vertices;
    for (c = 0; c < again.num_charts && ok; c++) {
        const bp_chart *ch = &again.charts[c];
        bp_check_report rep;
        double uv[2 * 4096], *p = uv;
        uint32_t i;
        if (ch->num_vertices > 4096) continue;   /* enough for the examples' meshes */
        for (i = 0; i < ch->num_vertices; i++, p += 2) {
            p[0] = back.uvs[2 * ch->vertex_uv[i]];
            p[1] = back.uvs[2 * ch->vertex_uv[i] + 1];
        }
        if (bp_check(ch->triangles, ch->num_triangles, uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK) ok = 0;
    }
    printf("%s: %s\n", out, ok ? "same charts and faces, every chart's written map is valid"
                               : "MISMATCH");
    bp_atlas_free(&atlas); bp_atlas_free(&again);
    bp_mesh_free(&mesh, NULL); bp_mesh_free(&back, NULL);
    return !ok;
}
