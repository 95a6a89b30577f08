/* test_ply.c - PLY input (ASCII, binary little and big endian): files
   written here read to the same mesh as the equivalent OBJ, whatever the
   property order, the extra properties, lists and elements; malformed
   files are refused with the exact status and the element named. */
#define _POSIX_C_SOURCE 200809L      /* mkdtemp */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define GRID 4                       /* GRID x GRID quads, (GRID+1)^2 vertices */
#define NV ((GRID + 1) * (GRID + 1))
#define NQ (GRID * GRID)

static double P[NV][3];              /* multiples of 1/8: exact as float too */
static int Q[NQ][4];

static void make_grid(void)
{
    int i, j;
    for (i = 0; i <= GRID; i++)
        for (j = 0; j <= GRID; j++) {
            double *p = P[i * (GRID + 1) + j];
            p[0] = j; p[1] = i; p[2] = (double)(int)(bpt_rng_unit() * 16) / 8;
        }
    for (i = 0; i < GRID; i++)
        for (j = 0; j < GRID; j++) {
            int *q = Q[i * GRID + j], v = i * (GRID + 1) + j;
            q[0] = v; q[1] = v + 1; q[2] = v + GRID + 2; q[3] = v + GRID + 1;
        }
}

static size_t obj_text(char *buf, size_t cap)
{
    size_t n = 0;
    int v, f;
    for (v = 0; v < NV; v++) n += (size_t)snprintf(buf + n, cap - n, "v %.17g %.17g %.17g\n", P[v][0], P[v][1], P[v][2]);
    for (f = 0; f < NQ; f++)
        n += (size_t)snprintf(buf + n, cap - n, "f %d %d %d %d\n", Q[f][0] + 1, Q[f][1] + 1, Q[f][2] + 1, Q[f][3] + 1);
    return n;
}

/* ASCII: vertex properties in the order y, nx, x, (list) extra, z, red;
   an "edge" element between vertex and face; a face "flags" before the
   indices and a texcoord list after them. */
static size_t ply_ascii(char *buf, size_t cap)
{
    size_t n = 0;
    int v, f;
    n += (size_t)snprintf(buf + n, cap - n,
        "ply\r\nformat ascii 1.0\ncomment made by test_ply\nelement vertex %d\nproperty double y\n"
        "property float nx\nproperty float x\nproperty list uchar int extra\nproperty float z\n"
        "property uchar red\nelement edge 2\nproperty int vertex1\nproperty int vertex2\n"
        "element face %d\nproperty uchar flags\nproperty list uchar uint vertex_indices\n"
        "property list uchar float texcoord\nend_header\n", NV, NQ);
    for (v = 0; v < NV; v++)
        n += (size_t)snprintf(buf + n, cap - n, "%.17g 0.5 %.17g %d %s %.17g 255\n", P[v][1], P[v][0], v % 3,
                              v % 3 == 0 ? "" : v % 3 == 1 ? "7" : "7 8", P[v][2]);
    n += (size_t)snprintf(buf + n, cap - n, "0 1\n1 2\n");
    for (f = 0; f < NQ; f++)
        n += (size_t)snprintf(buf + n, cap - n, "3 4 %d %d %d %d 2 0.5 0.25\n", Q[f][0], Q[f][1], Q[f][2], Q[f][3]);
    return n;
}

static void put(unsigned char **o, uint64_t u, int size, int be)
{
    int i;
    for (i = 0; i < size; i++) (*o)[i] = (unsigned char)(u >> (8 * (be ? size - 1 - i : i)));
    *o += size;
}

static void put_f64(unsigned char **o, double x, int be) { uint64_t u; memcpy(&u, &x, 8); put(o, u, 8, be); }
static void put_f32(unsigned char **o, float x, int be) { uint32_t u; memcpy(&u, &x, 4); put(o, u, 4, be); }

/* Binary: LE with double x y z, int indices; BE with float z x y, a
   per-vertex list, ushort indices with a uint8 count.  Quads. */
static size_t ply_binary(unsigned char *buf, int be)
{
    unsigned char *o = buf;
    int v, f, k;
    o += sprintf((char *)o, be ?
        "ply\nformat binary_big_endian 1.0\nelement vertex %d\nproperty float z\nproperty list uint8 int16 junk\n"
        "property float32 x\nproperty float y\nelement face %d\nproperty list uint8 uint16 vertex_indices\n"
        "property int flags\nend_header\n" :
        "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
        "property double z\nproperty uchar alpha\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n",
        NV, NQ);
    for (v = 0; v < NV; v++) {
        if (be) {
            put_f32(&o, (float)P[v][2], 1);
            put(&o, 2, 1, 1); put(&o, 0xfffe, 2, 1); put(&o, 5, 2, 1);
            put_f32(&o, (float)P[v][0], 1); put_f32(&o, (float)P[v][1], 1);
        } else {
            for (k = 0; k < 3; k++) put_f64(&o, P[v][k], 0);
            put(&o, 200, 1, 0);
        }
    }
    for (f = 0; f < NQ; f++) {
        put(&o, 4, 1, be);
        for (k = 0; k < 4; k++) put(&o, (uint64_t)Q[f][k], be ? 2 : 4, be);
        if (be) put(&o, 0xdeadbeef, 4, 1);
    }
    return (size_t)(o - buf);
}

static int same_mesh(const bp_mesh *a, const bp_mesh *b)
{
    return a->num_vertices == b->num_vertices && a->num_triangles == b->num_triangles &&
           a->num_faces == b->num_faces &&
           !memcmp(a->positions, b->positions, 3 * sizeof(double) * a->num_vertices) &&
           !memcmp(a->triangles, b->triangles, 3 * sizeof(uint32_t) * a->num_triangles) &&
           !memcmp(a->triangle_face, b->triangle_face, sizeof(uint32_t) * a->num_triangles);
}

static char text[1 << 16];
static unsigned char bin[1 << 16];

static void test_same_as_obj(void)
{
    bp_mesh obj, m;
    bp_error err;
    size_t n;
    int be;
    FILE *f;
    char dir[] = "/tmp/bptest_ply_XXXXXX", path[64];
    n = obj_text(text, sizeof text);
    BPT_CHECK(bp_parse_obj(text, n, &obj, NULL, &err) == BP_OK && obj.num_triangles == 2 * NQ, "the OBJ: %s", err.message);
    n = ply_ascii(text, sizeof text);
    BPT_CHECK(bp_parse_ply(text, n, &m, NULL, &err) == BP_OK, "ASCII PLY reads: %s", err.message);
    BPT_CHECK(same_mesh(&obj, &m), "ASCII PLY (reordered and extra properties, an extra element, lists) = the OBJ");
    BPT_CHECK(m.triangle_line && m.triangle_line[0] == 18 + NV + 2 + 1, "ASCII PLY: a triangle's line is its face's line (%u)",
              m.triangle_line ? m.triangle_line[0] : 0);
    bp_mesh_free(&m, NULL);
    for (be = 0; be < 2; be++) {
        n = ply_binary(bin, be);
        BPT_CHECK(bp_parse_ply((const char *)bin, n, &m, NULL, &err) == BP_OK, "binary %s PLY reads: %s",
                  be ? "big endian" : "little endian", err.message);
        BPT_CHECK(same_mesh(&obj, &m), "binary %s PLY = the OBJ", be ? "big endian" : "little endian");
        bp_mesh_free(&m, NULL);
    }
    /* by extension, through the file reader */
    BPT_CHECK(mkdtemp(dir) != NULL, "a temporary directory %s", dir);
    snprintf(path, sizeof path, "%s/test.PLY", dir);
    f = fopen(path, "wb");
    BPT_CHECK(f && fwrite(bin, 1, n, f) == n && fclose(f) == 0, "wrote %s", path);
    BPT_CHECK(bp_read_mesh(path, &m, NULL, &err) == BP_OK && same_mesh(&obj, &m),
              "bp_read_mesh picks PLY by extension: %s", err.message);
    BPT_CHECK(!strcmp(bp_mesh_format("a.Ply"), "ply") && !strcmp(bp_mesh_format("a.obj"), "obj") &&
              !strcmp(bp_mesh_format("a.OFF"), "off") && !bp_mesh_format("a.stl"), "bp_mesh_format by extension");
    bp_mesh_free(&m, NULL);
    remove(path);
    rmdir(dir);
    bp_mesh_free(&obj, NULL);
}

/* The grid as triangle strips (the Stanford scans' `tristrips`): row i of
   quads as one strip running top, bottom, top, bottom; rows 0-1 joined by
   -1, rows 1 onward by repeating a row's last vertex and the next one's
   first (joining triangles that repeat a vertex, which are skipped).  Each
   triangle must be one of the OBJ's up to rotation, each once, and all
   counter-clockwise in xy as the quads are. */
static void test_strips(void)
{
    bp_mesh obj, m;
    bp_error err;
    char *t = text;
    size_t n = 0, cap = sizeof text;
    uint32_t i, j, k, found = 0, ccw = 0, *used;
    int row, c, G1 = GRID + 1, len = 0;
    int seq[4 * NV];
    obj_text(text, sizeof text);
    if (!BPT_CHECK(bp_parse_obj(text, strlen(text), &obj, NULL, &err) == BP_OK, "the OBJ: %s", err.message)) return;
    for (row = 0; row < GRID; row++) {
        if (row == 1) seq[len++] = -1;
        if (row >= 2) { seq[len] = seq[len - 1]; len++; seq[len++] = (row + 1) * G1; }
        for (c = 0; c <= GRID; c++) { seq[len++] = (row + 1) * G1 + c; seq[len++] = row * G1 + c; }
    }
    n += (size_t)snprintf(t + n, cap - n, "ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\n"
                          "property double y\nproperty double z\nelement tristrips 1\n"
                          "property list int int vertex_indices\nend_header\n", NV);
    for (i = 0; i < NV; i++) n += (size_t)snprintf(t + n, cap - n, "%.17g %.17g %.17g\n", P[i][0], P[i][1], P[i][2]);
    n += (size_t)snprintf(t + n, cap - n, "%d", len);
    for (c = 0; c < len; c++) n += (size_t)snprintf(t + n, cap - n, " %d", seq[c]);
    n += (size_t)snprintf(t + n, cap - n, "\n");
    if (BPT_CHECK(bp_parse_ply(text, n, &m, NULL, &err) == BP_OK, "tristrips read: %s", err.message)) {
        used = (uint32_t *)calloc(obj.num_triangles, sizeof(uint32_t));
        for (i = 0; i < m.num_triangles; i++) {
            const uint32_t *a = m.triangles + 3 * i;
            double ux = P[a[1]][0] - P[a[0]][0], uy = P[a[1]][1] - P[a[0]][1];
            double vx = P[a[2]][0] - P[a[0]][0], vy = P[a[2]][1] - P[a[0]][1];
            ccw += ux * vy - uy * vx > 0;
            for (j = 0; j < obj.num_triangles; j++)
                for (k = 0; k < 3; k++) {
                    const uint32_t *b = obj.triangles + 3 * j;
                    if (!used[j] && a[0] == b[k] && a[1] == b[(k + 1) % 3] && a[2] == b[(k + 2) % 3]) { used[j] = 1; found++; }
                }
        }
        free(used);
        BPT_CHECK(m.num_vertices == NV && m.num_triangles == 2 * NQ && found == 2 * NQ && ccw == 2 * NQ,
                  "4 strips (joined by -1 and by repeated vertices): %u triangles, %u of the OBJ's %u found, "
                  "%u counter-clockwise", m.num_triangles, found, obj.num_triangles, ccw);
        bp_mesh_free(&m, NULL);
    }
    bp_mesh_free(&obj, NULL);
}

static void test_uvs(void)
{
    const char *t = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_index\nend_header\n"
                    "0 0 0 0.25 0.5\n1 0 0 0.75 0.5\n0 1 0 0.25 1\n3 0 1 2\n";
    bp_mesh m;
    bp_error err;
    BPT_CHECK(bp_parse_ply(t, strlen(t), &m, NULL, &err) == BP_OK, "per-vertex s t: %s", err.message);
    BPT_CHECK(m.num_uvs == 3 && m.uvs && m.uvs[2] == 0.75 && m.uvs[5] == 1 && m.corner_uv && m.corner_uv[1] == 1,
              "per-vertex s t become the uvs, corner uv = vertex");
    bp_mesh_free(&m, NULL);
}

/* A malformed file: the status, and the numbers its message must name. */
static void expect(const char *what, const char *data, size_t n, bp_status want, long long num1, long long num2,
                   int64_t line)
{
    bp_mesh m;
    bp_error err;
    bp_status st = bp_parse_ply(data, n, &m, NULL, &err);
    BPT_CHECK(st == want && m.positions == NULL && m.num_triangles == 0, "%s: %s (want %s): %s", what,
              bp_status_string(st), bp_status_string(want), err.message);
    BPT_CHECK((num1 < 0 || bpt_has_number(err.message, num1)) && (num2 < 0 || bpt_has_number(err.message, num2)) &&
              (line < 0 || err.line == line), "%s: the message names %lld and %lld (line %lld): %s", what, num1, num2,
              (long long)line, err.message);
}

/* the element the message names, as the header does */
static void expect_what(const char *what, const char *data, const char *name)
{
    bp_mesh m;
    bp_error err;
    bp_parse_ply(data, strlen(data), &m, NULL, &err);
    BPT_CHECK(strstr(err.message, name) != NULL, "%s: the message names '%s': %s", what, name, err.message);
    bp_mesh_free(&m, NULL);
}

static void test_malformed(void)
{
    static const char *hdr = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
    char t[1024];
    size_t n, h;
    unsigned char *b;
    uint32_t off;
    snprintf(t, sizeof t, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 7\n", hdr);
    expect("ASCII index out of range", t, strlen(t), BP_ERR_INDEX, 2, 7, 14);
    snprintf(t, sizeof t, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 2\n", hdr);
    expect("ASCII face of 2 corners", t, strlen(t), BP_ERR_POLYGON, 2, -1, 14);
    snprintf(t, sizeof t, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", hdr);
    expect("ASCII file ends in face 2", t, strlen(t), BP_ERR_PARSE, 2, -1, -1);
    snprintf(t, sizeof t, "%s0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n3 0 1 2\n", hdr);
    expect("ASCII bad number in vertex 2", t, strlen(t), BP_ERR_PARSE, 2, 11, 11);
    snprintf(t, sizeof t, "%s0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n3 0 1 2\n", hdr);
    expect("ASCII infinite coordinate in vertex 2", t, strlen(t), BP_ERR_NONFINITE, 2, -1, 11);
    snprintf(t, sizeof t, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n3 0 1 2\n", hdr);
    expect("ASCII fractional index", t, strlen(t), BP_ERR_PARSE, 1, -1, 13);
    strcpy(t, "ply\nformat ascii 1.0\nelement vertex 3\n");
    expect("no end_header", t, strlen(t), BP_ERR_PARSE, -1, -1, -1);
    strcpy(t, "plx\nformat ascii 1.0\nend_header\n");
    expect("no magic", t, strlen(t), BP_ERR_PARSE, 1, -1, 1);
    strcpy(t, "ply\nformat binary_middle_endian 1.0\nend_header\n");
    expect("unknown format", t, strlen(t), BP_ERR_PARSE, 2, -1, 2);
    strcpy(t, "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n");
    expect("unknown type", t, strlen(t), BP_ERR_PARSE, 4, -1, 4);
    strcpy(t, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement face 1\n"
              "property list float int vertex_indices\nend_header\n");
    expect("float list count", t, strlen(t), BP_ERR_PARSE, 6, -1, 6);
    strcpy(t, "ply\nformat ascii 1.0\nelement vertex 0\nelement face 0\nend_header\n");
    expect("no faces", t, strlen(t), BP_ERR_EMPTY, -1, -1, -1);
    strcpy(t, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
              "6 0 1 2 -1 2 9\n");
    expect("ASCII strip index out of range", t, strlen(t), BP_ERR_INDEX, 9, 6, 13);
    expect_what("ASCII strip index out of range", t, "tristrips 1");
    /* binary: counts beyond the file, an index out of range at a byte offset, a truncated value */
    n = ply_binary(bin, 0);
    h = (size_t)(strstr((const char *)bin, "end_header\n") - (const char *)bin) + 11;
    memcpy(t, bin, h);
    memcpy(strstr(t, "vertex 25"), "vertex 99", 9);
    expect("binary vertex count beyond the file", t, h + 100, BP_ERR_PARSE, 99, -1, -1);
    b = bin + h + NV * 25 + 2 * 17;           /* face 3; 25 bytes a vertex, 17 a face */
    off = 77;
    memcpy(b + 1 + 4 * 2, &off, 4);
    expect("binary index out of range", (const char *)bin, n, BP_ERR_INDEX, 3, (long long)(b + 1 + 4 * 2 - bin), -1);
    n = ply_binary(bin, 0);
    expect("binary truncated in face 16", (const char *)bin, n - 2, BP_ERR_PARSE, 16, (long long)(n - 4), -1);
    expect("binary truncated in vertex 25", (const char *)bin, h + 24 * 25 + 3, BP_ERR_PARSE, 25,
           (long long)(h + 24 * 25), -1);
}

int main(void)
{
    make_grid();
    test_same_as_obj();
    test_uvs();
    test_strips();
    test_malformed();
    return bpt_finish();
}
