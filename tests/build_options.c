/* build_options.c - the library built without some of its parts
   (BP_NO_VISIBILITY, BP_NO_IO, ...: tests/test_build_options.sh compiles
   this file once per combination).  What it proves in each build:
     (a) the rest still works: camel_b, read by this file's own OBJ reader
         (the library's may be left out), is flattened by bp_parameterize
         with the defaults, every chart passes bp_check, and the map is
         written (argv[2]) for tests/uvcheck.py, an independent exact
         checker, to check again;
     (b) every option that needs a left-out part fails with
         BP_ERR_UNSUPPORTED and a message naming the macro, and leaves the
         atlas zeroed -- never does something else. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* v and f lines only (f fanned, the index before any '/'); vt is left out,
   so seams are the library's own. */
static int read_obj(const char *path, bp_mesh *m)
{
    FILE *f = fopen(path, "rb");
    char line[4096];
    size_t nv = 0, nt = 0, cv = 1024, ct = 1024;
    double *pos = (double *)malloc(3 * cv * sizeof(double));
    uint32_t *tri = (uint32_t *)malloc(3 * ct * sizeof(uint32_t));
    if (!f || !pos || !tri) { if (f) fclose(f); free(pos); free(tri); return 0; }
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (nv == cv) { cv *= 2; pos = (double *)realloc(pos, 3 * cv * sizeof(double)); }
            if (sscanf(line + 2, "%lf %lf %lf", pos + 3 * nv, pos + 3 * nv + 1, pos + 3 * nv + 2) != 3) break;
            nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            long idx[64];
            int n = 0, k;
            char *p = line + 2, *e;
            while (n < 64) {
                long v = strtol(p, &e, 10);
                if (e == p) break;
                idx[n++] = v < 0 ? (long)nv + v : v - 1;
                p = e;
                while (*p && *p != ' ' && *p != '\t' && *p != '\n' && *p != '\r') p++;
            }
            for (k = 1; k + 1 < n; k++) {
                if (nt == ct) { ct *= 2; tri = (uint32_t *)realloc(tri, 3 * ct * sizeof(uint32_t)); }
                tri[3 * nt] = (uint32_t)idx[0];
                tri[3 * nt + 1] = (uint32_t)idx[k];
                tri[3 * nt + 2] = (uint32_t)idx[k + 1];
                nt++;
            }
        }
    }
    fclose(f);
    memset(m, 0, sizeof *m);
    m->positions = pos;
    m->num_vertices = (uint32_t)nv;
    m->triangles = tri;
    m->num_triangles = (uint32_t)nt;
    return nv > 0 && nt > 0;
}

/* The atlas as OBJ: the mesh's v, one vt per chart vertex, each chart
   triangle as f v/vt (the check's input). */
static int write_obj(const char *path, const bp_mesh *m, const bp_atlas *at)
{
    FILE *f = fopen(path, "w");
    uint32_t c, i, t, base = 0;
    if (!f) return 0;
    for (i = 0; i < m->num_vertices; i++)
        fprintf(f, "v %.17g %.17g %.17g\n", m->positions[3 * i], m->positions[3 * i + 1], m->positions[3 * i + 2]);
    for (c = 0; c < at->num_charts; c++)
        for (i = 0; i < at->charts[c].num_vertices; i++)
            fprintf(f, "vt %.17g %.17g\n", at->charts[c].uv[2 * i], at->charts[c].uv[2 * i + 1]);
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * t;
            fprintf(f, "f %u/%u %u/%u %u/%u\n", ch->vertex[tr[0]] + 1, base + tr[0] + 1, ch->vertex[tr[1]] + 1,
                    base + tr[1] + 1, ch->vertex[tr[2]] + 1, base + tr[2] + 1);
        }
        base += ch->num_vertices;
    }
    return fclose(f) == 0;
}

#if defined(BP_NO_VISIBILITY) || defined(BP_NO_NEWTON) || defined(BP_NO_ATLAS)
/* (b): opt fails with BP_ERR_UNSUPPORTED naming macro, the atlas zeroed. */
static void refused(const bp_mesh *m, const bp_options *opt, const char *macro, const char *what)
{
    bp_atlas at;
    bp_error err;
    bp_status st;
    memset(&at, 0xAB, sizeof at);
    st = bp_parameterize(&at, m, opt, &err);
    BPT_CHECK(st == BP_ERR_UNSUPPORTED && strstr(err.message, macro) != NULL && at.num_charts == 0 && !at.charts,
              "%s: %s is refused (%s: \"%s\")", macro, what, bp_status_string(st), err.message);
    bp_atlas_free(&at);
}
#endif

int main(int argc, char **argv)
{
    bp_mesh m;
    bp_atlas at;
    bp_options opt;
    bp_error err;
    bp_status st;
    uint32_t c, bad = 0;
    if (argc < 3) { fprintf(stderr, "usage: %s MESH.obj OUT.obj\n", argv[0]); return 2; }
    memset(&m, 0, sizeof m);
    if (!BPT_CHECK(read_obj(argv[1], &m), "%s read (%u vertices, %u triangles)", argv[1], m.num_vertices,
                   m.num_triangles))
        return bpt_finish();
    memset(&opt, 0, sizeof opt);
    memset(&at, 0, sizeof at);
    st = bp_parameterize(&at, &m, &opt, &err);                                   /* (a) */
    BPT_CHECK(st == BP_OK, "camel_b flattened with the defaults (%s)", st == BP_OK ? "ok" : err.message);
    for (c = 0; st == BP_OK && c < at.num_charts; c++) {
        const bp_chart *ch = &at.charts[c];
        bp_check_report rep;
        if (bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK) bad++;
    }
    BPT_CHECK(st == BP_OK && at.num_charts > 0 && bad == 0, "every one of its %u charts passes bp_check (%u fail)",
              at.num_charts, bad);
    BPT_CHECK(st == BP_OK && write_obj(argv[2], &m, &at), "the map written to %s", argv[2]);
    bp_atlas_free(&at);
#ifdef BP_NO_VISIBILITY
    opt.views.model = BP_VIEW_FRONT;
    refused(&m, &opt, "BP_NO_VISIBILITY", "a view model (opt.views)");
    opt.views.model = BP_VIEW_NONE;
#endif
    free((void *)m.positions);
    free((void *)m.triangles);
    return bpt_finish();
}
