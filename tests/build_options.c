/* build_options.c - the library built without some of its parts
   (BP_NO_NEWTON, BP_NO_ATLAS, BP_NO_VISIBILITY, BP_NO_IO: make test builds
   it with all four, make check with each of their 16 combinations, see
   tests/test_build_options.sh and tests/test_build_matrix.sh).  What it
   proves in each build:
     (a) the rest still works: camel_b, read by this file's own OBJ reader
         (the library's may be left out), is flattened by bp_parameterize
         with the defaults, every chart passes bp_check, and the map is
         written (argv[2]) for tests/uvcheck.py, an independent exact
         checker, to check again;
     (b) every option that needs a left-out part fails with
         BP_ERR_UNSUPPORTED and a message naming the macro, and leaves the
         atlas zeroed -- never does something else;
     (c) without Newton (BP_NO_NEWTON): the default direction is the
         preconditioned L-BFGS on every chart (chart.direction), and the
         conformal start asked by name is still made, by the scalar
         factorization, on a chart where it is bijective (argv[3], the
         bishop, whose conformal map is: start_map says so) and the map is
         valid; a chart whose conformal map folds (camel_b) falls to the
         mean-value map, as in the full build. */
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

/* Every chart of at passes bp_check; the count of those that fail. */
static uint32_t failing(const bp_atlas *at)
{
    uint32_t c, bad = 0;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        bp_check_report rep;
        if (!ch->uv || bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, NULL) != BP_OK)
            bad++;
    }
    return bad;
}

#if defined(BP_NO_VISIBILITY) || defined(BP_NO_NEWTON) || defined(BP_NO_ATLAS)
/* (b): opt fails with BP_ERR_UNSUPPORTED, its message naming the option
   (what) and the macro, the atlas zeroed. */
static void refused(const bp_mesh *m, const bp_options *opt, const char *macro, const char *what)
{
    bp_atlas at;
    bp_error err;
    bp_status st;
    memset(&at, 0xAB, sizeof at);
    st = bp_parameterize(&at, m, opt, &err);
    BPT_CHECK(st == BP_ERR_UNSUPPORTED && strstr(err.message, macro) != NULL && strstr(err.message, what) != NULL &&
              at.num_charts == 0 && !at.charts,
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
    uint32_t bad = 0;
    int ok;
    if (argc < 4) { fprintf(stderr, "usage: %s camel_b.obj OUT.obj bishop_part_f1000.obj\n", argv[0]); return 2; }
    memset(&m, 0, sizeof m);
    ok = read_obj(argv[1], &m);
    if (!BPT_CHECK(ok, "%s read (%u vertices, %u triangles)", argv[1], m.num_vertices, m.num_triangles))
        return bpt_finish();
    memset(&opt, 0, sizeof opt);
    memset(&at, 0, sizeof at);
    st = bp_parameterize(&at, &m, &opt, &err);                                   /* (a) */
    BPT_CHECK(st == BP_OK, "camel_b flattened with the defaults (%s)", st == BP_OK ? "ok" : err.message);
    if (st == BP_OK) bad = failing(&at);
    BPT_CHECK(st == BP_OK && at.num_charts > 0 && bad == 0, "every one of its %u charts passes bp_check (%u fail)",
              at.num_charts, bad);
    BPT_CHECK(st == BP_OK && write_obj(argv[2], &m, &at), "the map written to %s", argv[2]);
#ifdef BP_NO_NEWTON
    uint32_t c;
    for (c = 0, bad = 0; st == BP_OK && c < at.num_charts; c++)                   /* (c) */
        bad += at.charts[c].direction != BP_DIRECTION_PRECONDITIONED;
    BPT_CHECK(st == BP_OK && bad == 0, "BP_NO_NEWTON: the default direction is the preconditioned L-BFGS on every "
              "chart (%u charts, %u other)", at.num_charts, bad);
#endif
#if defined(BP_NO_NEWTON) || defined(BP_NO_ATLAS)
    if (st == BP_OK) {                            /* (b) through the calls that take one step */
        bp_options o2 = opt;
        double u0 = at.charts[0].uv[0];
#ifdef BP_NO_NEWTON
        o2.direction = BP_DIRECTION_NEWTON;
        st = bp_atlas_solve(&at, &m, &o2, &err);
        BPT_CHECK(st == BP_ERR_UNSUPPORTED && strstr(err.message, "BP_NO_NEWTON") && at.charts[0].uv[0] == u0,
                  "BP_NO_NEWTON: bp_atlas_solve with BP_DIRECTION_NEWTON is refused, the map untouched (%s)",
                  err.message);
        o2.direction = BP_DIRECTION_DEFAULT;
#endif
#ifdef BP_NO_ATLAS
        o2.atlas_resolution = 512;
        st = bp_atlas_pack(&at, &o2, &err);
        BPT_CHECK(st == BP_ERR_UNSUPPORTED && strstr(err.message, "BP_NO_ATLAS") &&
                  strstr(err.message, "opt.atlas_resolution") && at.charts[0].uv[0] == u0,
                  "BP_NO_ATLAS: bp_atlas_pack at a resolution is refused, the map untouched (%s)", err.message);
#endif
        st = BP_OK;
    }
#endif
    bp_atlas_free(&at);
#ifdef BP_NO_VISIBILITY
    opt.views.model = BP_VIEW_FRONT;
    refused(&m, &opt, "BP_NO_VISIBILITY", "opt.views");
    opt.views.model = BP_VIEW_NONE;
#endif
#ifdef BP_NO_NEWTON
    opt.direction = BP_DIRECTION_NEWTON;
    refused(&m, &opt, "BP_NO_NEWTON", "opt.direction BP_DIRECTION_NEWTON");
    opt.direction = BP_DIRECTION_DEFAULT;
    {                                           /* (c): the conformal start by name */
        bp_mesh b;
        memset(&b, 0, sizeof b);
        opt.init = BP_INIT_CONFORMAL;
        st = bp_parameterize(&at, &m, &opt, &err);
        BPT_CHECK(st == BP_OK && at.num_charts > 0 && failing(&at) == 0 &&
                  at.charts[0].start_map == BP_INIT_MEAN_VALUE,
                  "BP_NO_NEWTON: BP_INIT_CONFORMAL on camel_b, whose conformal map folds: the mean-value start, "
                  "the map valid (%s, start %d)", st == BP_OK ? "ok" : err.message, st == BP_OK ? at.charts[0].start_map : -1);
        bp_atlas_free(&at);
        ok = read_obj(argv[3], &b);
        if (BPT_CHECK(ok, "%s read (%u triangles)", argv[3], b.num_triangles)) {
            st = bp_parameterize(&at, &b, &opt, &err);
            BPT_CHECK(st == BP_OK && at.num_charts == 1 && failing(&at) == 0 &&
                      at.charts[0].start_map == BP_INIT_CONFORMAL,
                      "BP_NO_NEWTON: BP_INIT_CONFORMAL on the bishop: the conformal start (by the scalar "
                      "factorization), the map valid (%s, start %d)", st == BP_OK ? "ok" : err.message,
                      st == BP_OK ? at.charts[0].start_map : -1);
            bp_atlas_free(&at);
        }
        free((void *)b.positions);
        free((void *)b.triangles);
        opt.init = BP_INIT_AUTO;
    }
#endif
#ifdef BP_NO_ATLAS
    opt.atlas_resolution = 1024;
    refused(&m, &opt, "BP_NO_ATLAS", "opt.atlas_resolution");
    opt.atlas_resolution = 0;
    opt.segment = 1;
    refused(&m, &opt, "BP_NO_ATLAS", "opt.segment = 1");
    opt.segment = 0;
    opt.max_distortion = 5;
    refused(&m, &opt, "BP_NO_ATLAS", "opt.max_distortion");
    opt.max_distortion = 0;
    opt.max_charts = 4;
    refused(&m, &opt, "BP_NO_ATLAS", "opt.max_charts");
    opt.max_charts = 0;
    opt.segment = -1;                           /* "never": needs nothing left out */
    st = bp_parameterize(&at, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && failing(&at) == 0, "BP_NO_ATLAS: opt.segment = -1 is accepted (%s)",
              st == BP_OK ? "ok" : err.message);
    bp_atlas_free(&at);
    opt.segment = 0;
#endif
    free((void *)m.positions);
    free((void *)m.triangles);
    return bpt_finish();
}
