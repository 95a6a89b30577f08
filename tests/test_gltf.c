/* test_gltf.c - examples/bp_gltf.h: glTF in and out, in memory.

   - Bad files: a valid .glb made here is broken one way at a time (its
     JSON, its chunks, its bytes), and each break gives one error with the
     status and the words that name the element (accessor, bufferView,
     buffer, mesh/primitive, byte offset), and a zeroed file: out-of-range
     offsets, lengths, strides, counts and indices, sparse indices, bad
     base64 and percent escapes, bad JSON, a truncated GLB, chunk lengths
     that lie, integers past 2^53 and counts past 2^32, compression
     extensions it does not decode.
   - Round trip: the model through bp_parameterize and bpg_encode (.glb and
     .gltf), read back: every triangle has the corners, positions and
     normals it had, and the written map, read back as the file's seams
     and uvs, passes bp_check chart by chart and as a whole.
   - Rounding: a map valid in doubles whose float rounding flips a sliver
     and closes a slit of 2e-8 (the plain rounding fails bp_check: the
     test can fail); the writer moves corners by a few floats and the map
     read back is exactly bijective.
   - The allocator: every allocation of reading and writing refused in
     turn gives BP_ERR_OUT_OF_MEMORY and leaks nothing; a run that
     succeeds frees all it took.
   - TEXCOORD_1 written beside a kept TEXCOORD_0; the same bytes from the
     same input twice. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#define BPG_IMPLEMENTATION
#include "examples/bp_gltf.h"

/* ---- the model: a 4 x 4 grid, NORMAL, unsigned short indices -------------- */

enum { GN = 4, NV = GN * GN, NI = (GN - 1) * (GN - 1) * 6 };

static unsigned char bin[NV * 12 * 2 + NI * 2 + 64];
static size_t bin_len;

static const char *base_json =
    "{\"asset\":{\"version\":\"2.0\"},\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},"
    "\"indices\":2}]}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":16,\"type\":\"VEC3\"},"
    "{\"bufferView\":1,\"componentType\":5126,\"count\":16,\"type\":\"VEC3\"},"
    "{\"bufferView\":2,\"componentType\":5123,\"count\":54,\"type\":\"SCALAR\"}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":192},{\"buffer\":0,\"byteOffset\":192,\"byteLength\":192},"
    "{\"buffer\":0,\"byteOffset\":384,\"byteLength\":108}],\"buffers\":[{\"byteLength\":492}]}";

static void put_f32(unsigned char *p, float x) { uint32_t u; memcpy(&u, &x, 4); p[0] = (unsigned char)u; p[1] = (unsigned char)(u >> 8); p[2] = (unsigned char)(u >> 16); p[3] = (unsigned char)(u >> 24); }
static void put_u16(unsigned char *p, unsigned x) { p[0] = (unsigned char)x; p[1] = (unsigned char)(x >> 8); }
static void put_u32(unsigned char *p, uint32_t x) { p[0] = (unsigned char)x; p[1] = (unsigned char)(x >> 8); p[2] = (unsigned char)(x >> 16); p[3] = (unsigned char)(x >> 24); }

static void make_bin(void)
{
    int i, j, at = 0, z;
    for (j = 0; j < GN; j++)
        for (i = 0; i < GN; i++) {
            unsigned char *p = bin + 12 * (size_t)(j * GN + i), *n = bin + 192 + 12 * (size_t)(j * GN + i);
            put_f32(p, (float)i); put_f32(p + 4, (float)j); put_f32(p + 8, (float)(0.1 * ((i * j) % 3)));
            put_f32(n, 0.0f); put_f32(n + 4, 0.0f); put_f32(n + 8, (float)(1 + i + 16 * j));   /* a normal per vertex: tells them apart */
        }
    for (j = 0; j < GN - 1; j++)
        for (i = 0; i < GN - 1; i++) {
            unsigned a = (unsigned)(j * GN + i), q[6];
            q[0] = a; q[1] = a + 1; q[2] = a + GN + 1; q[3] = a; q[4] = a + GN + 1; q[5] = a + GN;
            for (z = 0; z < 6; z++) put_u16(bin + 384 + 2 * (size_t)(at++), q[z]);
        }
    bin_len = 492;
}

/* A .glb of json and bin[0, blen) into out (malloc'd), its size returned. */
static size_t make_glb(const char *json, const unsigned char *b, size_t blen, unsigned char **out)
{
    size_t jl = strlen(json), jp = (jl + 3) / 4 * 4, bp = (blen + 3) / 4 * 4, total = 12 + 8 + jp + (b ? 8 + bp : 0);
    unsigned char *g = (unsigned char *)calloc(total, 1);
    memcpy(g, "glTF", 4); put_u32(g + 4, 2); put_u32(g + 8, (uint32_t)total);
    put_u32(g + 12, (uint32_t)jp); put_u32(g + 16, 0x4E4F534Au);
    memcpy(g + 20, json, jl);
    memset(g + 20 + jl, ' ', jp - jl);
    if (b) {
        put_u32(g + 20 + jp, (uint32_t)bp); put_u32(g + 24 + jp, 0x004E4942u);
        memcpy(g + 28 + jp, b, blen);
    }
    *out = g;
    return total;
}

/* json with the first `from` replaced by `to` (in one of four static
   buffers, so that calls may nest). */
static const char *subst(const char *json, const char *from, const char *to)
{
    static char buf[4][8192];
    static int k = 0;
    const char *p = strstr(json, from);
    char *b = buf[k = (k + 1) % 4];
    if (!p) { printf("subst: '%s' not found\n", from); exit(2); }
    snprintf(b, sizeof buf[0], "%.*s%s%s", (int)(p - json), json, to, p + strlen(from));
    return b;
}

static int zeroed(const bpg_file *g)
{
    return !g->p && !g->mesh.positions && !g->mesh.triangles && !g->mesh.num_triangles;
}

/* One bad input: its status and the words its message must hold. */
static void expect(const char *what, const unsigned char *data, size_t n, const char *dir, bp_status want,
                   const char *w1, const char *w2)
{
    bpg_file g;
    bp_error err;
    bp_status st;
    memset(&g, 0x5a, sizeof g);
    st = bpg_parse(&g, data, n, dir, NULL, &err);
    BPT_CHECK(st == want && err.status == st && strstr(err.message, w1) && (!w2 || strstr(err.message, w2)) && zeroed(&g),
              "%s: %s (status %s, want %s): %s", what, w2 ? w2 : w1, bp_status_string(st), bp_status_string(want), err.message);
    if (st == BP_OK) bpg_free(&g);
}

static void expect_json(const char *what, const char *json, bp_status want, const char *w1, const char *w2)
{
    unsigned char *g;
    size_t n = make_glb(json, bin, bin_len, &g);
    expect(what, g, n, NULL, want, w1, w2);
    free(g);
}

static void bad_files(void)
{
    unsigned char *g, *h;
    size_t n;
    char gltf[12000];
    const char *j = base_json;
    /* accessors, bufferViews, buffers: offsets, lengths, counts, strides */
    expect_json("accessor byteOffset past its view", subst(j, "{\"bufferView\":0,", "{\"bufferView\":0,\"byteOffset\":4,"),
                BP_ERR_INDEX, "accessor 0 (POSITION of mesh 0 primitive 0)", "bufferView 0");
    expect_json("accessor count past its view", subst(j, "\"count\":16,\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5126,\"count\":16",
                                                      "\"count\":16,\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5126,\"count\":17"),
                BP_ERR_INDEX, "accessor 1", "192 bytes of bufferView 1");
    expect_json("bufferView past its buffer", subst(j, "\"byteOffset\":384,\"byteLength\":108", "\"byteOffset\":384,\"byteLength\":109"),
                BP_ERR_INDEX, "bufferView 2", "buffer 0");
    expect_json("buffer longer than the BIN chunk", subst(j, "\"byteLength\":492}", "\"byteLength\":9999}"),
                BP_ERR_INDEX, "buffer 0", "BIN chunk");
    expect_json("byteStride below the element", subst(j, "\"byteOffset\":0,\"byteLength\":192}", "\"byteOffset\":0,\"byteLength\":192,\"byteStride\":8}"),
                BP_ERR_PARSE, "byteStride 8", "accessor 0");
    expect_json("byteStride not a multiple of 4", subst(j, "\"byteOffset\":0,\"byteLength\":192}", "\"byteOffset\":0,\"byteLength\":192,\"byteStride\":13}"),
                BP_ERR_PARSE, "byteStride 13", "bufferView 0");
    expect_json("stride times count past the view", subst(j, "\"byteOffset\":0,\"byteLength\":192}", "\"byteOffset\":0,\"byteLength\":192,\"byteStride\":16}"),
                BP_ERR_INDEX, "accessor 0", "stride 16");
    expect_json("unknown componentType", subst(j, "5126", "5124"), BP_ERR_PARSE, "accessor 0", "componentType 5124");
    expect_json("unknown type", subst(j, "\"VEC3\"", "\"VEC5\""), BP_ERR_PARSE, "accessor 0", "type");
    expect_json("POSITION not VEC3", subst(j, "\"VEC3\"", "\"VEC4\""), BP_ERR_INDEX, "accessor 0", NULL);
    expect_json("count past 2^32", subst(j, "\"count\":16", "\"count\":4294967296"), BP_ERR_TOO_LARGE, "accessor 0", "count 4294967296");
    expect_json("offset near 2^53 (no overflow)", subst(j, "{\"bufferView\":0,", "{\"bufferView\":0,\"byteOffset\":9007199254740990,"),
                BP_ERR_INDEX, "accessor 0", "9007199254740990");
    expect_json("integer past 2^53", subst(j, "\"count\":16", "\"count\":18446744073709551617"), BP_ERR_PARSE, "accessor 0", "whole number");
    expect_json("count 1e300", subst(j, "\"count\":16", "\"count\":1e300"), BP_ERR_PARSE, "accessor 0", "whole number");
    expect_json("count 16.5", subst(j, "\"count\":16", "\"count\":16.5"), BP_ERR_PARSE, "\"count\"", "whole number");
    expect_json("negative offset", subst(j, "\"byteOffset\":192", "\"byteOffset\":-192"), BP_ERR_PARSE, "bufferView 1", "byteOffset");
    expect_json("attribute counts differ", subst(j, "\"bufferView\":1,\"componentType\":5126,\"count\":16", "\"bufferView\":1,\"componentType\":5126,\"count\":15"),
                BP_ERR_PARSE, "accessor 1 (NORMAL of mesh 0 primitive 0)", "count 15 differs");
    expect_json("accessor index past the array", subst(j, "\"POSITION\":0", "\"POSITION\":9"), BP_ERR_INDEX, "mesh 0 primitive 0", "3 accessors");
    expect_json("bufferView index past the array", subst(j, "{\"bufferView\":1,", "{\"bufferView\":7,"), BP_ERR_INDEX, "accessor 1", "bufferViews");
    expect_json("buffer index past the array", subst(j, "{\"buffer\":0,\"byteOffset\":192", "{\"buffer\":3,\"byteOffset\":192"), BP_ERR_INDEX, "bufferView 1", "buffers");
    expect_json("indices of floats", subst(j, "5123,\"count\":54", "5126,\"count\":27"), BP_ERR_PARSE, "accessor 2 (indices of mesh 0 primitive 0)", "SCALAR");
    expect_json("a mode past 6", subst(j, "\"indices\":2", "\"indices\":2,\"mode\":7"), BP_ERR_PARSE, "mesh 0 primitive 0", "mode 7");
    expect_json("no triangle primitive", subst(j, "\"indices\":2", "\"indices\":2,\"mode\":1"), BP_ERR_EMPTY, "no triangles", NULL);
    expect_json("no POSITION", subst(j, "\"POSITION\":0,", ""), BP_ERR_PARSE, "mesh 0 primitive 0", "POSITION");
    expect_json("a key twice", subst(j, "\"count\":16,", "\"count\":16,\"count\":16,"), BP_ERR_PARSE, "accessor 0", "twice");
    expect_json("KHR_draco_mesh_compression", subst(j, "\"indices\":2", "\"indices\":2,\"extensions\":{\"KHR_draco_mesh_compression\":{}}"),
                BP_ERR_INVALID_ARGUMENT, "mesh 0 primitive 0", "KHR_draco_mesh_compression");
    expect_json("EXT_meshopt_compression", subst(j, "{\"buffer\":0,\"byteOffset\":0,", "{\"extensions\":{\"EXT_meshopt_compression\":{}},\"buffer\":0,\"byteOffset\":0,"),
                BP_ERR_INVALID_ARGUMENT, "bufferView 0", "EXT_meshopt_compression");
    expect_json("glTF 1.0", subst(j, "\"2.0\"", "\"1.0\""), BP_ERR_INVALID_ARGUMENT, "asset.version", "2.0");
    expect_json("no asset", subst(j, "\"asset\":{\"version\":\"2.0\"},", ""), BP_ERR_PARSE, "asset", NULL);
    /* sparse accessors */
    {
        char sj[4000];
        /* indices 3 and 1: not increasing; then 3 and 16: out of range (they sit in the index buffer's bytes) */
        snprintf(sj, sizeof sj, "%s", subst(j, "{\"bufferView\":1,\"componentType\":5126,\"count\":16,\"type\":\"VEC3\"}",
            "{\"bufferView\":1,\"componentType\":5126,\"count\":16,\"type\":\"VEC3\",\"sparse\":{\"count\":2,"
            "\"indices\":{\"bufferView\":2,\"byteOffset\":SPOFF,\"componentType\":5123},\"values\":{\"bufferView\":0}}}"));
        {
            char a[4000];
            snprintf(a, sizeof a, "%s", subst(sj, "SPOFF", "100"));       /* indices 16 (value at 484) ...: see below */
            expect_json("sparse values fit, indices checked", a, BP_ERR_INDEX, "accessor 1", "sparse index");
            snprintf(a, sizeof a, "%s", subst(sj, "SPOFF", "108"));
            expect_json("sparse indices past their view", a, BP_ERR_INDEX, "sparse indices", "bufferView 2");
            snprintf(a, sizeof a, "%s", subst(subst(sj, "SPOFF", "0"), "\"count\":2,", "\"count\":17,"));
            expect_json("sparse count past the accessor's", a, BP_ERR_INDEX, "sparse", "count 17");
        }
    }
    /* JSON syntax */
    expect_json("JSON: a missing comma", subst(j, "\"count\":16,\"type\"", "\"count\":16 \"type\""), BP_ERR_PARSE, "JSON chunk, byte", "','");
    expect_json("JSON: a string not closed", "{\"asset\":{\"version\":\"2.0}}", BP_ERR_PARSE, "byte", "not closed");
    expect_json("JSON: text after the value", subst(j, "492}]}", "492}]}x"), BP_ERR_PARSE, "byte", "after the JSON value");
    expect_json("JSON: a bad escape", subst(j, "\"2.0\"", "\"2\\q0\""), BP_ERR_PARSE, "byte", "escape");
    expect_json("JSON: a control character", subst(j, "\"2.0\"", "\"2\t0\""), BP_ERR_PARSE, "byte", "control character");
    expect_json("JSON: a bad number", subst(j, "\"count\":16", "\"count\":016"), BP_ERR_PARSE, "byte", NULL);
    expect_json("JSON: not an object", "[1,2]", BP_ERR_PARSE, "byte", "not an object");
    {
        char deep[2000];
        int k;
        for (k = 0; k < 600; k++) deep[k] = '[';
        deep[600] = 0;
        expect_json("JSON: nested 600 deep", deep, BP_ERR_PARSE, "byte", "512 levels");
    }
    /* the GLB container */
    n = make_glb(j, bin, bin_len, &g);
    expect("truncated GLB", g, n - 10, NULL, BP_ERR_PARSE, "truncated GLB", NULL);
    expect("GLB under 12 bytes", g, 7, NULL, BP_ERR_PARSE, "truncated GLB", NULL);
    h = (unsigned char *)malloc(n);
    memcpy(h, g, n); put_u32(h + 12, (uint32_t)(n));                           /* JSON chunk length lies */
    expect("JSON chunk length lies", h, n, NULL, BP_ERR_PARSE, "chunk 0 at byte 12", NULL);
    memcpy(h, g, n); put_u32(h + n - bin_len - 8, (uint32_t)(bin_len + 4));   /* BIN chunk length lies */
    expect("BIN chunk length lies", h, n, NULL, BP_ERR_PARSE, "chunk 1", NULL);
    memcpy(h, g, n); put_u32(h + 8, (uint32_t)(n + 4));
    expect("header length lies", h, n, NULL, BP_ERR_PARSE, "truncated GLB", NULL);
    memcpy(h, g, n); put_u32(h + 4, 1);
    expect("GLB version 1", h, n, NULL, BP_ERR_INVALID_ARGUMENT, "version 1", NULL);
    memcpy(h, g, n); put_u32(h + 16, 0x12345678u);
    expect("first chunk not JSON", h, n, NULL, BP_ERR_PARSE, "not JSON", NULL);
    memcpy(h, g, n); put_u16(h + n - bin_len + 384 + 10, 99);                  /* an index out of range */
    expect("index out of range", h, n, NULL, BP_ERR_INDEX, "accessor 2 (indices of mesh 0 primitive 0)", "index 99");
    free(h);
    free(g);
    n = make_glb(j, NULL, 0, &g);
    expect("no BIN chunk for buffer 0", g, n, NULL, BP_ERR_PARSE, "buffer 0", "BIN chunk");
    free(g);
    /* .gltf buffers: data: URIs, files */
    snprintf(gltf, sizeof gltf, "%s", subst(j, "{\"byteLength\":492}", "{\"byteLength\":492,\"uri\":\"data:application/octet-stream;base64,AAAA*AAA\"}"));
    expect("bad base64", (const unsigned char *)gltf, strlen(gltf), NULL, BP_ERR_PARSE, "buffer 0", "bad base64 in its data: URI at character 5");
    snprintf(gltf, sizeof gltf, "%s", subst(j, "{\"byteLength\":492}", "{\"byteLength\":492,\"uri\":\"data:application/octet-stream;base64,AAAA\"}"));
    expect("data: URI too short", (const unsigned char *)gltf, strlen(gltf), NULL, BP_ERR_PARSE, "buffer 0", "holds 3 bytes");
    snprintf(gltf, sizeof gltf, "%s", subst(j, "{\"byteLength\":492}", "{\"byteLength\":492,\"uri\":\"model.bin\"}"));
    expect("external file, no folder", (const unsigned char *)gltf, strlen(gltf), NULL, BP_ERR_IO, "buffer 0", "model.bin");
    expect("external file missing", (const unsigned char *)gltf, strlen(gltf), "/nonexistent-folder-for-a-test/", BP_ERR_IO, "buffer 0", "cannot open");
    snprintf(gltf, sizeof gltf, "%s", subst(j, "{\"byteLength\":492}", "{\"byteLength\":492,\"uri\":\"http://example.com/a.bin\"}"));
    expect("a uri with a scheme", (const unsigned char *)gltf, strlen(gltf), "", BP_ERR_PARSE, "buffer 0", "not a relative path");
    snprintf(gltf, sizeof gltf, "%s", subst(j, "{\"byteLength\":492}", "{\"byteLength\":492,\"uri\":\"a%zz.bin\"}"));
    expect("a bad percent escape", (const unsigned char *)gltf, strlen(gltf), "", BP_ERR_PARSE, "buffer 0", "percent escape");
    snprintf(gltf, sizeof gltf, "%s", j);
    expect("a .gltf buffer without uri", (const unsigned char *)gltf, strlen(gltf), "", BP_ERR_PARSE, "buffer 0 has no uri", NULL);
    {
        const char *t = "{\n\"asset\": {\n  \"version\": 2.0.1}}";
        expect(".gltf: JSON error with its line", (const unsigned char *)t, strlen(t), NULL, BP_ERR_PARSE, "line 3: JSON, column", NULL);
    }
}

/* ---- the round trip ----------------------------------------------------------- */

static bpg_file read_glb(const char *json, bp_error *err)
{
    unsigned char *g;
    size_t n = make_glb(json, bin, bin_len, &g);
    bpg_file f;
    bpg_parse(&f, g, n, NULL, NULL, err);
    free(g);
    return f;
}

/* The map written, read back: the file's charts (its uv seams) each
   bijective, and all of them together, by bp_check. */
static int map_bijective(const bpg_file *back, uint32_t *charts)
{
    bp_atlas at;
    bp_error err;
    bp_status st;
    uint32_t c, nt = 0, nv = 0, i, *tri;
    double *uv;
    int ok = 1;
    bp_check_report rep;
    if (bp_atlas_build(&at, &back->mesh, NULL, &err) != BP_OK) { printf("build: %s\n", err.message); return 0; }
    st = bp_atlas_use_input_uvs(&at, &back->mesh, &err);
    if (st != BP_OK) { printf("input uvs: %s\n", err.message); bp_atlas_free(&at); return 0; }
    for (c = 0; c < at.num_charts; c++) { nt += at.charts[c].num_triangles; nv += at.charts[c].num_vertices; }
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri);
    uv = (double *)malloc(2 * (size_t)nv * sizeof *uv);
    for (c = 0, nt = 0, nv = 0; c < at.num_charts; c++) {
        const bp_chart *ch = &at.charts[c];
        for (i = 0; i < 3 * ch->num_triangles; i++) tri[3 * (size_t)nt + i] = ch->triangles[i] + nv;
        memcpy(uv + 2 * (size_t)nv, ch->uv, 2 * (size_t)ch->num_vertices * sizeof *uv);
        nt += ch->num_triangles;
        nv += ch->num_vertices;
    }
    if (bp_check(tri, nt, uv, nv, NULL, &rep, &err) != BP_OK) { printf("all charts: %s\n", err.message); ok = 0; }
    *charts = at.num_charts;
    free(tri); free(uv);
    bp_atlas_free(&at);
    return ok;
}

static void round_trip(void)
{
    bp_error err;
    bpg_file f = read_glb(base_json, &err), back;
    bp_atlas at;
    bp_options opt;
    bpg_write_options wo;
    bpg_output out, out2;
    int fmt;
    bp_status st;
    BPT_CHECK(f.p && f.mesh.num_triangles == 18 && f.mesh.num_vertices == 16 && f.num_primitives == 1 && !f.mesh.corner_uv,
              "the model reads: 18 triangles, 16 vertices, no uvs (%s)", f.p ? "" : err.message);
    bp_options_init(&opt);
    opt.atlas_resolution = 64;
    opt.padding = 2;
    opt.threads = 1;
    st = bp_parameterize(&at, &f.mesh, &opt, &err);
    BPT_CHECK(st == BP_OK, "parameterized: %u charts", at.num_charts);
    for (fmt = 1; fmt >= 0; fmt--) {
        uint32_t t, k, charts = 0;
        int same = 1, ok;
        memset(&wo, 0, sizeof wo);
        wo.glb = fmt;
        st = bpg_encode(&f, &at, &wo, &out, &err);
        BPT_CHECK(st == BP_OK, "%s encoded: %llu bytes, %u vertices -> %u", fmt ? ".glb" : ".gltf",
                  (unsigned long long)out.size, out.vertices_in, out.vertices_out);
        st = bpg_parse(&back, out.data, out.size, NULL, NULL, &err);
        BPT_CHECK(st == BP_OK && back.has_uv && back.mesh.corner_uv,
                  "%s read back with TEXCOORD_0 (%s)", fmt ? ".glb" : ".gltf", back.p ? "" : err.message);
        if (!back.p) { bpg_output_free(&out); continue; }
        for (t = 0; t < f.mesh.num_triangles && same; t++)
            for (k = 0; k < 3; k++) {
                const double *a = f.mesh.positions + 3 * (size_t)f.mesh.triangles[3 * t + k];
                const double *b = back.mesh.positions + 3 * (size_t)back.mesh.triangles[3 * t + k];
                same &= a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
            }
        BPT_CHECK(same && back.mesh.num_triangles == f.mesh.num_triangles, "%s: every corner at its position", fmt ? ".glb" : ".gltf");
        ok = map_bijective(&back, &charts);
        BPT_CHECK(ok && charts == at.num_charts,
                  "%s: the map read back is bijective (bp_check), %u charts from its seams (the atlas has %u)",
                  fmt ? ".glb" : ".gltf", charts, at.num_charts);
        BPT_CHECK(bpg_encode(&f, &at, &wo, &out2, &err) == BP_OK && out2.size == out.size && !memcmp(out.data, out2.data, out.size),
                  "%s: the same input gives the same bytes", fmt ? ".glb" : ".gltf");
        bpg_output_free(&out2);
        bpg_output_free(&out);
        bpg_free(&back);
    }
    bp_atlas_free(&at);
    bpg_free(&f);
}

/* TEXCOORD_1 beside the file's TEXCOORD_0 (a lightmap set): TEXCOORD_0's
   values come back per corner, TEXCOORD_1 is the new map. */
static void second_set(void)
{
    char json[4000];
    unsigned char b2[sizeof bin + 128];
    bp_error err;
    bpg_file f, back;
    bpg_options go;
    bp_atlas at;
    bp_options opt;
    bpg_output out;
    memset(&out, 0, sizeof out);
    unsigned char *g;
    size_t n;
    uint32_t t, k, charts = 0;
    int same = 1, ok;
    bp_status st;
    memcpy(b2, bin, bin_len);
    for (k = 0; k < 16; k++) { put_f32(b2 + bin_len + 8 * k, (float)(k % 4) * 0.25f); put_f32(b2 + bin_len + 8 * k + 4, (float)(k / 4) * 0.25f); }
    snprintf(json, sizeof json, "%s", subst(subst(subst(base_json, "\"NORMAL\":1}", "\"NORMAL\":1,\"TEXCOORD_0\":3}"),
                                                  "\"type\":\"SCALAR\"}]", "\"type\":\"SCALAR\"},{\"bufferView\":3,\"componentType\":5126,\"count\":16,\"type\":\"VEC2\"}]"),
                                            "\"byteLength\":108}]", "\"byteLength\":108},{\"buffer\":0,\"byteOffset\":492,\"byteLength\":128}]"));
    snprintf(json, sizeof json, "%s", subst(json, "\"byteLength\":492}", "\"byteLength\":620}"));
    n = make_glb(json, b2, bin_len + 128, &g);
    memset(&go, 0, sizeof go);
    go.texcoord = 1;
    BPT_CHECK(bpg_parse(&f, g, n, NULL, &go, &err) == BP_OK && !f.mesh.corner_uv, "TEXCOORD_1 asked, TEXCOORD_0 present: reads (%s)", f.p ? "" : err.message);
    if (!f.p) { free(g); return; }
    bp_options_init(&opt);
    opt.atlas_resolution = 64;
    opt.threads = 1;
    bp_parameterize(&at, &f.mesh, &opt, &err);
    st = bpg_encode(&f, &at, NULL, &out, &err);
    BPT_CHECK(st == BP_OK, "TEXCOORD_1 written (%s)", err.message);
    st = bpg_parse(&back, out.data, out.size, NULL, &go, &err);
    ok = st == BP_OK && back.mesh.corner_uv && map_bijective(&back, &charts);
    BPT_CHECK(ok && charts == at.num_charts, "read back: TEXCOORD_1 is a bijective map (%u charts)", charts);
    bpg_free(&back);
    BPT_CHECK(bpg_parse(&back, out.data, out.size, NULL, NULL, &err) == BP_OK && back.mesh.corner_uv, "read back for its TEXCOORD_0");
    for (t = 0; back.p && t < f.mesh.num_triangles; t++)
        for (k = 0; k < 3; k++) {
            const double *a = back.mesh.uvs + 2 * (size_t)back.mesh.corner_uv[3 * t + k];
            uint32_t v = f.p->corner_src[3 * t + k];
            same &= a[0] == (double)(float)((v % 4) * 0.25) && a[1] == 1.0 - (double)(float)((v / 4) * 0.25);
        }
    BPT_CHECK(same, "TEXCOORD_0 keeps the file's values at every corner");
    bpg_free(&back);
    bpg_output_free(&out);
    bp_atlas_free(&at);
    bpg_free(&f);
    free(g);
    memset(&go, 0, sizeof go);
    go.texcoord = 2;
    n = make_glb(base_json, bin, bin_len, &g);
    BPT_CHECK(bpg_parse(&f, g, n, NULL, &go, &err) == BP_ERR_PARSE && strstr(err.message, "TEXCOORD_0"), "TEXCOORD_2 needs TEXCOORD_0 and _1: %s", err.message);
    free(g);
}

/* ---- rounding: a sliver and a slit that float rounding breaks ----------- */

static void rounding(void)
{
    /* a U: a lower arm y in [0, 0.1], an upper arm y in [0.1 + 2e-8, 0.2],
       joined by a bar at x in [1, 1.1]; glTF's v = 1 - y puts both sides of
       the slit near 0.9, where floats are 6e-8 apart */
    static const double xy[10][2] = { { 0, 0 }, { 1, 0 }, { 1, 0.1 }, { 0, 0.1 }, { 1, 0.1 + 2e-8 }, { 0, 0.1 + 2e-8 },
                                       { 0, 0.2 }, { 1, 0.2 }, { 1.1, 0 }, { 1.1, 0.2 } };
    static const unsigned tri[8][3] = { { 0, 1, 2 }, { 0, 2, 3 }, { 5, 4, 7 }, { 5, 7, 6 }, { 1, 8, 2 }, { 2, 8, 9 }, { 2, 9, 4 }, { 4, 9, 7 } };
    char json[2000];
    unsigned char b[10 * 12 + 24 * 2], *g;
    size_t n;
    bpg_file f, back;
    bp_atlas at;
    bp_error err;
    bpg_output out;
    memset(&out, 0, sizeof out);
    uint32_t i, k, charts = 0;
    double fl[20];
    bp_status naive, st;
    int ok;
    bp_check_report rep;
    for (i = 0; i < 10; i++) { put_f32(b + 12 * i, (float)xy[i][0]); put_f32(b + 12 * i + 4, (float)xy[i][1]); put_f32(b + 12 * i + 8, 0); }
    for (i = 0; i < 8; i++) for (k = 0; k < 3; k++) put_u16(b + 120 + 2 * (3 * i + k), tri[i][k]);
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":10,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5123,\"count\":24,\"type\":\"SCALAR\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":120},{\"buffer\":0,\"byteOffset\":120,\"byteLength\":48}],"
             "\"buffers\":[{\"byteLength\":168}]}");
    n = make_glb(json, b, sizeof b, &g);
    BPT_CHECK(bpg_parse(&f, g, n, NULL, NULL, &err) == BP_OK, "the U reads (%s)", err.message);
    free(g);
    if (!f.p) return;
    BPT_CHECK(bp_atlas_build(&at, &f.mesh, NULL, &err) == BP_OK && at.num_charts == 1, "one chart");
    {   /* its map: the double coordinates above (the float positions are near them, not equal) */
        bp_chart *ch = &at.charts[0];
        ch->uv = (double *)malloc(2 * (size_t)ch->num_vertices * sizeof(double));
        for (i = 0; i < ch->num_vertices; i++) {
            uint32_t v = f.p->vertex_src[ch->vertex[i]];
            ch->uv[2 * i] = xy[v][0];
            ch->uv[2 * i + 1] = xy[v][1];
        }
        BPT_CHECK(bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &rep, &err) == BP_OK,
                  "the double map is bijective");
        for (i = 0; i < ch->num_vertices; i++) { fl[2 * i] = (float)ch->uv[2 * i]; fl[2 * i + 1] = -(double)(float)(1.0 - ch->uv[2 * i + 1]); }
        naive = bp_check(ch->triangles, ch->num_triangles, fl, ch->num_vertices, NULL, &rep, &err);
        BPT_CHECK(naive == BP_ERR_NOT_BIJECTIVE, "rounded to floats as they are, it is not (%s)", err.message);
    }
    st = bpg_encode(&f, &at, NULL, &out, &err);
    BPT_CHECK(st == BP_OK && out.rounding_fixed >= 1, "the writer repairs it: %u corners moved (%s)", out.rounding_fixed,
              st == BP_OK ? "" : err.message);
    ok = out.data && bpg_parse(&back, out.data, out.size, NULL, NULL, &err) == BP_OK && map_bijective(&back, &charts);
    BPT_CHECK(ok && charts == 1, "the map read back is bijective, %u chart", charts);
    if (out.data) bpg_free(&back);
    bpg_output_free(&out);
    bp_atlas_free(&at);
    bpg_free(&f);
}

/* ---- the allocator -------------------------------------------------------------- */

typedef struct counting { long allocs, frees, fail_at; } counting;

static void *c_alloc(void *user, size_t n)
{
    counting *c = (counting *)user;
    if (c->fail_at >= 0 && c->allocs == c->fail_at) { c->fail_at = -2; return NULL; }
    c->allocs++;
    return malloc(n);
}

static void c_free(void *user, void *p)
{
    ((counting *)user)->frees++;
    free(p);
}

static void allocator(void)
{
    bp_error err;
    bpg_file f0 = read_glb(base_json, &err), f;
    bp_atlas at;
    bp_options opt;
    unsigned char *g;
    size_t n = make_glb(base_json, bin, bin_len, &g);
    counting c;
    bpg_options go;
    long k, total = -1, read_fail = 0, write_fail = 0, leaks = 0, other = 0;
    bp_options_init(&opt);
    opt.atlas_resolution = 64;
    opt.threads = 1;
    bp_parameterize(&at, &f0.mesh, &opt, &err);
    memset(&go, 0, sizeof go);
    go.allocator.alloc = c_alloc;
    go.allocator.free = c_free;
    go.allocator.user = &c;
    for (k = 0; k < 10000; k++) {
        bp_status st;
        bpg_output out;
        c.allocs = c.frees = 0;
        c.fail_at = k;
        st = bpg_parse(&f, g, n, NULL, &go, &err);
        if (st == BP_OK) {
            st = bpg_encode(&f, &at, NULL, &out, &err);
            if (st == BP_OK) bpg_output_free(&out);
            else if (st == BP_ERR_OUT_OF_MEMORY) write_fail++;
            else other++;
            bpg_free(&f);
        } else if (st == BP_ERR_OUT_OF_MEMORY) read_fail++;
        else other++;
        if (c.allocs != c.frees) leaks++;
        if (c.fail_at != -2) { total = c.allocs; break; }      /* nothing was refused: every point tried */
    }
    BPT_CHECK(total > 0 && other == 0 && leaks == 0 && read_fail > 0 && write_fail > 0,
              "each of the %ld allocations refused in turn: %ld reads and %ld writes fail with out of memory, no other error, no leak",
              total, read_fail, write_fail);
    c.fail_at = -1; c.allocs = c.frees = 0;
    BPT_CHECK(bpg_parse(&f, g, n, NULL, &go, &err) == BP_OK, "the counting allocator reads");
    {
        bpg_output out;
        BPT_CHECK(bpg_encode(&f, &at, NULL, &out, &err) == BP_OK && out.data, "and writes");
        bpg_output_free(&out);
    }
    bpg_free(&f);
    BPT_CHECK(c.allocs > 0 && c.allocs == c.frees, "every block it gave (%ld) comes back", c.allocs);
    free(g);
    bp_atlas_free(&at);
    bpg_free(&f0);
}

int main(void)
{
    make_bin();
    bad_files();
    round_trip();
    second_set();
    rounding();
    allocator();
    return bpt_finish();
}
