/* test_io.c - the OBJ and OFF readers on well-formed and malformed text.

   For every malformed input the reader must return the expected status,
   name the 1-based line in err.line and in the message, and leave the mesh
   with NULL arrays: nothing allocated.  For every well-formed input the mesh
   must hold exactly what the text says.  A counting allocator (its user
   pointer is checked on every call) proves that each success path frees
   everything in bp_mesh_free and each failure path frees everything it took,
   also when an allocation fails halfway.  Finally 2000 random byte strings
   and 2000 random mutations of a valid OBJ go through both parsers: they
   must never crash, never leak, and every mesh they accept must be
   consistent.  Each buffer handed to a parser is allocated with exactly
   `length` bytes and no terminating NUL, so a sanitizer build catches any
   read past the end. */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- the counting allocator --------------------------------------------- */

typedef struct counter {
    long      allocs, frees, wrong_user, bad_free;
    long long live_bytes;
    long      fail_at;   /* make the fail_at-th allocation (1-based) fail; 0: never */
    long      calls;
} counter;

static counter the_counter;

static void *count_alloc(void *user, size_t size)
{
    counter *c = &the_counter;
    size_t *p;
    if (user != (void *)&the_counter) c->wrong_user++;
    c->calls++;
    if (c->fail_at && c->calls == c->fail_at) return NULL;
    p = (size_t *)malloc(size + 16);
    if (!p) return NULL;
    p[0] = size;
    p[1] = 0x5eed5eedu;
    c->allocs++;
    c->live_bytes += (long long)size;
    return (char *)p + 16;
}

static void count_free(void *user, void *ptr)
{
    counter *c = &the_counter;
    size_t *p;
    if (user != (void *)&the_counter) c->wrong_user++;
    if (!ptr) return;
    p = (size_t *)((char *)ptr - 16);
    if (p[1] != 0x5eed5eedu) { c->bad_free++; return; }
    p[1] = 0;
    c->frees++;
    c->live_bytes -= (long long)p[0];
    free(p);
}

static bp_allocator counting(void)
{
    bp_allocator a;
    a.alloc = count_alloc;
    a.free = count_free;
    a.user = &the_counter;
    return a;
}

static void counter_reset(void) { memset(&the_counter, 0, sizeof the_counter); }

static int counter_balanced(void)
{
    return the_counter.allocs == the_counter.frees && the_counter.live_bytes == 0 &&
           the_counter.wrong_user == 0 && the_counter.bad_free == 0;
}

/* ---- helpers ------------------------------------------------------------ */

enum { OBJ, OFF };
static const char *const fmt_name[] = { "OBJ", "OFF" };

/* Parse `text` from a heap copy of exactly strlen(text) bytes (no NUL). */
static bp_status parse(int fmt, const char *text, size_t len, bp_mesh *m,
                       const bp_allocator *a, bp_error *err)
{
    char *buf = (char *)malloc(len ? len : 1);
    bp_status st;
    memcpy(buf, text, len);
    memset(m, 0xAB, sizeof *m);   /* the parser must overwrite every field */
    memset(err, 0, sizeof *err);
    st = fmt == OBJ ? bp_parse_obj(buf, len, m, a, err) : bp_parse_off(buf, len, m, a, err);
    free(buf);
    return st;
}

static int mesh_all_null(const bp_mesh *m)
{
    return !m->positions && !m->triangles && !m->corner_uv && !m->uvs &&
           !m->triangle_line && !m->triangle_face;
}

/* A parsed mesh is consistent: every index in range, every number finite. */
static int mesh_consistent(const bp_mesh *m)
{
    uint32_t i;
    if (m->num_triangles && !m->triangles) return 0;
    if (m->num_vertices && !m->positions) return 0;
    for (i = 0; i < 3 * m->num_vertices; i++)
        if (!isfinite(m->positions[i])) return 0;
    for (i = 0; i < 3 * m->num_triangles; i++)
        if (m->triangles[i] >= m->num_vertices) return 0;
    if (m->corner_uv)
        for (i = 0; i < 3 * m->num_triangles; i++)
            if (m->corner_uv[i] >= m->num_uvs && m->corner_uv[i] != UINT32_MAX) return 0;
    if (m->num_uvs && !m->uvs) return 0;
    for (i = 0; m->uvs && i < 2 * m->num_uvs; i++)
        if (!isfinite(m->uvs[i])) return 0;
    if (m->triangle_face) {
        for (i = 0; i < m->num_triangles; i++)
            if (m->triangle_face[i] >= m->num_faces) return 0;
        for (i = 1; i < m->num_triangles; i++)
            if (m->triangle_face[i] < m->triangle_face[i - 1]) return 0;
    }
    return m->num_faces <= m->num_triangles;
}

/* One malformed input: the status is one of the allowed ones (a second
   allowed status, or -1), err.line == line, the message names the line,
   and nothing is left allocated. */
static void expect_error(int fmt, const char *what, const char *text,
                         int status, int status2, long line)
{
    bp_mesh m;
    bp_error err;
    bp_allocator a = counting();
    bp_status st;
    counter_reset();
    st = parse(fmt, text, strlen(text), &m, &a, &err);
    BPT_CHECK(st == (bp_status)status || (status2 >= 0 && st == (bp_status)status2),
              "%s %s: status %s (%d), expected %s%s%s", fmt_name[fmt], what,
              bp_status_string(st), (int)st, bp_status_string((bp_status)status),
              status2 >= 0 ? " or " : "", status2 >= 0 ? bp_status_string((bp_status)status2) : "");
    BPT_CHECK(err.status == st, "%s %s: err.status matches the return value", fmt_name[fmt], what);
    if (line > 0) {
        BPT_CHECK(err.line == line && bpt_has_number(err.message, line),
                  "%s %s: err.line %lld (expected %ld), message \"%s\"", fmt_name[fmt],
                  what, (long long)err.line, line, err.message);
    } else {
        BPT_CHECK(err.message[0] != '\0', "%s %s: message \"%s\" (line %lld)", fmt_name[fmt],
                  what, err.message, (long long)err.line);
    }
    BPT_CHECK(mesh_all_null(&m) && counter_balanced(),
              "%s %s: mesh arrays NULL and nothing left allocated (%ld allocs, %ld frees, %lld bytes live)",
              fmt_name[fmt], what, the_counter.allocs, the_counter.frees, the_counter.live_bytes);
}

/* A well-formed input: parses, is consistent, and frees everything.  The
   mesh is handed to `check` before being freed. */
static void expect_ok(int fmt, const char *what, const char *text,
                      uint32_t nv, uint32_t nt, void (*check)(const bp_mesh *, const char *))
{
    bp_mesh m;
    bp_error err;
    bp_allocator a = counting();
    bp_status st;
    counter_reset();
    st = parse(fmt, text, strlen(text), &m, &a, &err);
    BPT_CHECK(st == BP_OK, "%s %s: parses (%s: %s)", fmt_name[fmt], what,
              bp_status_string(st), st == BP_OK ? "" : err.message);
    if (st != BP_OK) {
        BPT_CHECK(mesh_all_null(&m) && counter_balanced(), "%s %s: failure left nothing allocated",
                  fmt_name[fmt], what);
        return;
    }
    BPT_CHECK(m.num_vertices == nv && m.num_triangles == nt && mesh_consistent(&m),
              "%s %s: %u vertices, %u triangles, consistent (got %u, %u)", fmt_name[fmt], what,
              (unsigned)nv, (unsigned)nt, (unsigned)m.num_vertices, (unsigned)m.num_triangles);
    if (check) check(&m, what);
    bp_mesh_free(&m, &a);
    BPT_CHECK(counter_balanced(), "%s %s: bp_mesh_free frees all %ld allocations (%ld freed, %lld bytes live)",
              fmt_name[fmt], what, the_counter.allocs, the_counter.frees, the_counter.live_bytes);
}

static int tri_is(const bp_mesh *m, uint32_t t, uint32_t a, uint32_t b, uint32_t c)
{
    return m->triangles[3 * t] == a && m->triangles[3 * t + 1] == b && m->triangles[3 * t + 2] == c;
}

/* ---- well-formed OBJ ---------------------------------------------------- */

static void check_basic(const bp_mesh *m, const char *what)
{
    BPT_CHECK(tri_is(m, 0, 0, 1, 2) && m->positions[0] == 1.5 && m->positions[4] == -2.0 &&
              m->positions[8] == 300.0, "%s: indices and coordinates exact", what);
    BPT_CHECK(m->corner_uv == NULL && m->uvs == NULL && m->num_uvs == 0,
              "%s: no vt means no corner_uv", what);
}

static void check_negative(const bp_mesh *m, const char *what)
{
    BPT_CHECK(tri_is(m, 0, 1, 2, 3), "%s: f -3 -2 -1 after 4 vertices is 1 2 3 (0-based)", what);
}

static void check_vt(const bp_mesh *m, const char *what)
{
    BPT_CHECK(m->corner_uv != NULL && m->uvs != NULL && m->num_uvs == 4,
              "%s: corner_uv and %u uvs present", what, (unsigned)m->num_uvs);
    if (!m->corner_uv || !m->uvs) return;
    BPT_CHECK(m->corner_uv[0] == 0 && m->corner_uv[1] == 1 && m->corner_uv[2] == 2 &&
              m->corner_uv[3] == 0 && m->corner_uv[4] == 2 && m->corner_uv[5] == 3,
              "%s: corner_uv follows the vt indices", what);
    BPT_CHECK(m->uvs[2] == 1.0 && m->uvs[3] == 0.0 && m->uvs[7] == 1.0, "%s: uv values", what);
    BPT_CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3), "%s: triangles", what);
}

static void check_vn_only(const bp_mesh *m, const char *what)
{
    BPT_CHECK(m->corner_uv == NULL && tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3),
              "%s: v//vn keeps the vertex indices and gives no corner_uv", what);
}

static void check_quad(const bp_mesh *m, const char *what)
{
    BPT_CHECK(m->num_faces == 1, "%s: one source face (num_faces %u)", what, (unsigned)m->num_faces);
    BPT_CHECK(m->triangle_face && m->triangle_face[0] == 0 && m->triangle_face[1] == 0,
              "%s: triangle_face maps both triangles to face 0", what);
    BPT_CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3), "%s: fan 0 1 2, 0 2 3", what);
}

static void check_quad_lines(const bp_mesh *m, const char *what)
{
    check_quad(m, what);
    BPT_CHECK(m->triangle_line && m->triangle_line[0] == 6 && m->triangle_line[1] == 6,
              "%s: triangle_line gives the face's file line (6) for both", what);
}

static void check_lines(const bp_mesh *m, const char *what)
{
    BPT_CHECK(m->triangle_line && m->triangle_line[0] == 7 && m->triangle_line[1] == 9,
              "%s: triangle_line counts comments, blank lines and CRLF (7, 9)", what);
}

static void check_mixed(const bp_mesh *m, const char *what)
{
    /* Either no uv at all, or the corners of the face without vt are marked
       missing (UINT32_MAX), or they got uv indices of their own (in range,
       one per vertex, none shared with the vt face: a seam between them). */
    int ok = 1, k, j;
    if (m->corner_uv) {
        for (k = 0; k < 3; k++) ok &= m->corner_uv[k] < m->num_uvs;
        for (k = 3; k < 6; k++) {
            uint32_t u = m->corner_uv[k];
            if (u == UINT32_MAX) continue;
            ok &= u < m->num_uvs;
            for (j = 0; j < 3; j++) ok &= u != m->corner_uv[j];
        }
    }
    BPT_CHECK(ok, "%s: faces with and without vt give a consistent corner_uv (%s)", what,
              m->corner_uv ? "present" : "NULL");
}

static void test_obj_ok(void)
{
    expect_ok(OBJ, "basic", "v 1.5 0 0\nv 0 -2 0\nv 0 0 3e2\nf 1 2 3\n", 3, 1, check_basic);
    expect_ok(OBJ, "no final newline", "v 1.5 0 0\nv 0 -2 0\nv 0 0 3e2\nf 1 2 3", 3, 1, check_basic);
    expect_ok(OBJ, "negative indices", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf -3 -2 -1\n", 4, 1, check_negative);
    expect_ok(OBJ, "v/vt",
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
              "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n", 4, 2, check_vt);
    expect_ok(OBJ, "v/vt/vn",
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
              "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n", 4, 2, check_vt);
    expect_ok(OBJ, "negative vt",
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
              "f -4/-4 -3/-3 -2/-2\nf 1/-4 3/-2 4/-1\n", 4, 2, check_vt);
    expect_ok(OBJ, "v//vn",
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n"
              "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n", 4, 2, check_vn_only);
    expect_ok(OBJ, "quad",
              "# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", 4, 2, check_quad_lines);
    expect_ok(OBJ, "comments, blank lines, CRLF, tabs",
              "# header\r\n\r\nv\t0 0 0\r\nv 1\t0\t0\r\n   v 0 1 0\r\nv 1 1 0 \r\nf 1 2 3\r\n# between\r\n"
              "f\t2 4 3\t\r\n\r\n", 4, 2, check_lines);
    expect_ok(OBJ, "ignored statements (o g s usemtl mtllib vp)",
              "mtllib a.mtl\no thing\ng group\nusemtl m\ns 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvp 0.5\nf 1 2 3\ns off\n",
              3, 1, NULL);
    expect_ok(OBJ, "pentagon fan", "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n", 5, 3, NULL);
    {
        bp_mesh m;
        bp_error err;
        bp_allocator a = counting();
        const char *text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nf 1/1 2/2 3/1\nf 1 3 4\n";
        bp_status st;
        counter_reset();
        st = parse(OBJ, text, strlen(text), &m, &a, &err);
        if (st == BP_OK) {
            BPT_CHECK(mesh_consistent(&m), "OBJ mixed vt: accepted with a consistent mesh");
            check_mixed(&m, "OBJ mixed vt");
            bp_mesh_free(&m, &a);
        } else {
            BPT_CHECK(err.message[0] && mesh_all_null(&m) && err.line == 8,
                      "OBJ mixed vt: rejected (%s) at line %lld: \"%s\"", bp_status_string(st),
                      (long long)err.line, err.message);
        }
        BPT_CHECK(counter_balanced(), "OBJ mixed vt: nothing left allocated");
        printf("     note: faces with and without vt -> %s%s%s\n", bp_status_string(st),
               st == BP_OK ? "" : ": ", st == BP_OK ? "" : err.message);
    }
}

/* ---- malformed OBJ ------------------------------------------------------ */

static void test_obj_errors(void)
{
    const char *tri3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    const char *bad0 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 0\n";
    bp_mesh m;
    bp_error err;
    bp_allocator a = counting();
    bp_status st;

    expect_error(OBJ, "empty input", "", BP_ERR_EMPTY, BP_ERR_PARSE, 0);
    expect_error(OBJ, "only comments", "# nothing\n\n", BP_ERR_EMPTY, -1, 0);
    expect_error(OBJ, "only vertices", tri3, BP_ERR_EMPTY, -1, 0);
    expect_error(OBJ, "truncated vertex (v 1 2)", "v 0 0 0\nv 1 2\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, -1, 2);
    expect_error(OBJ, "truncated vertex at end of input (v 1)", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 1", BP_ERR_PARSE, -1, 4);
    expect_error(OBJ, "bad number (v 1.0 abc 2)", "v 0 0 0\nv 1.0 abc 2\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, -1, 2);
    expect_error(OBJ, "number with trailing junk (v 1 2x 3)", "v 0 0 0\nv 1 2x 3\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, -1, 2);
    expect_error(OBJ, "overflowing coordinate (v 1e999 0 0)", "v 0 0 0\nv 1 0 0\nv 1e999 0 0\nf 1 2 3\n",
                 BP_ERR_NONFINITE, BP_ERR_PARSE, 3);
    expect_error(OBJ, "nan coordinate", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", BP_ERR_NONFINITE, BP_ERR_PARSE, 2);
    expect_error(OBJ, "inf coordinate", "v 0 0 0\nv 0 inf 0\nv 0 1 0\nf 1 2 3\n", BP_ERR_NONFINITE, BP_ERR_PARSE, 2);
    expect_error(OBJ, "nan texture coordinate", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan 0\nf 1/1 2/1 3/1\n",
                 BP_ERR_NONFINITE, BP_ERR_PARSE, 4);
    expect_error(OBJ, "too few corners (f 1 2)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", BP_ERR_PARSE, BP_ERR_POLYGON, 4);
    expect_error(OBJ, "face with no corners (f)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n", BP_ERR_PARSE, BP_ERR_POLYGON, 4);
    expect_error(OBJ, "index 0", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", BP_ERR_INDEX, BP_ERR_PARSE, 4);
    expect_error(OBJ, "index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n", BP_ERR_INDEX, -1, 5);
    expect_error(OBJ, "huge index (f 99999999999999999999 1 2)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 99999999999999999999 1 2\n",
                 BP_ERR_INDEX, BP_ERR_PARSE, 4);
    expect_error(OBJ, "index 2^32+1 (would wrap to 1)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 4294967297 2 3\n",
                 BP_ERR_INDEX, BP_ERR_PARSE, 4);
    expect_error(OBJ, "negative index past the start", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n", BP_ERR_INDEX, -1, 4);
    expect_error(OBJ, "huge negative index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -99999999999999999999 -2 -1\n",
                 BP_ERR_INDEX, BP_ERR_PARSE, 4);
    expect_error(OBJ, "vt index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", BP_ERR_INDEX, -1, 5);
    expect_error(OBJ, "vt index 0", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\n", BP_ERR_INDEX, BP_ERR_PARSE, 5);
    expect_error(OBJ, "garbage in a face (f 1 x 3)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", BP_ERR_PARSE, -1, 4);
    expect_error(OBJ, "garbage after an index (f 1 2 3x)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n", BP_ERR_PARSE, -1, 4);
    expect_error(OBJ, "error after CRLF lines", "v 0 0 0\r\nv 1 0 0\r\n\r\nv 0 1 0\r\nf 1 2 9\r\n", BP_ERR_INDEX, -1, 5);
    /* a long valid prefix: the line count must survive buffer growth */
    {
        size_t n = 0;
        int i;
        static char big[200000];
        for (i = 0; i < 5000; i++) n += (size_t)sprintf(big + n, "v %d 0 0\n", i);
        n += (size_t)sprintf(big + n, "f 1 2 3\nf 1 2 5001\n");
        (void)n;
        expect_error(OBJ, "error on line 5002 after 5000 vertices", big, BP_ERR_INDEX, -1, 5002);
    }

    /* the error names what kind of element it is about */
    counter_reset();
    st = parse(OBJ, bad0, strlen(bad0), &m, &a, &err);
    BPT_CHECK(st != BP_OK && (err.element == BP_ELEMENT_LINE || err.element == BP_ELEMENT_VERTEX),
              "OBJ index 0: err.element names a line or vertex (%d)", (int)err.element);
}

/* ---- OFF ---------------------------------------------------------------- */

static void check_off_quad(const bp_mesh *m, const char *what)
{
    check_quad(m, what);
    BPT_CHECK(m->corner_uv == NULL && m->positions[3] == 1.0 && m->positions[7] == 1.0,
              "%s: coordinates, no uv", what);
}

static void check_off_tri(const bp_mesh *m, const char *what)
{
    BPT_CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3), "%s: 0-based indices kept", what);
    BPT_CHECK(m->triangle_line == NULL || (m->triangle_line[0] == 7 && m->triangle_line[1] == 8),
              "%s: triangle_line (if kept) gives the face lines 7, 8", what);
}

static void test_off(void)
{
    const char *sq = "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    expect_ok(OFF, "quad (polygon face)", sq, 4, 2, check_off_quad);
    expect_ok(OFF, "two triangles with comments and CRLF",
              "OFF\r\n# comment\r\n4 2 0\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n3 0 1 2\r\n3 0 2 3\r\n", 4, 2, NULL);
    expect_ok(OFF, "two triangles",
              "OFF\n4 2 5\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\n3 0 1 2\n3 0 2 3\n", 4, 2, NULL);
    expect_ok(OFF, "counts on the OFF line", "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", 4, 2, NULL);
    expect_ok(OFF, "mixed polygon sizes", "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 2 0\n3 0 1 2\n4 1 4 2 3\n",
              5, 3, NULL);
    expect_ok(OFF, "0-based indices and triangle lines",
              "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n", 4, 2, check_off_tri);

    expect_error(OFF, "empty input", "", BP_ERR_PARSE, BP_ERR_EMPTY, 0);
    expect_error(OFF, "bad magic (OFX)", "OFX\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, -1, 1);
    expect_error(OFF, "bad count (3 x 0)", "OFF\n3 x 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, -1, 2);
    expect_error(OFF, "negative count", "OFF\n-3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, BP_ERR_INDEX, 2);
    expect_error(OFF, "missing counts", "OFF\n\n", BP_ERR_PARSE, -1, 0);
    expect_error(OFF, "only vertices (0 faces)", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", BP_ERR_EMPTY, -1, 0);
    expect_error(OFF, "bad vertex line", "OFF\n3 1 0\n0 0 0\n1 zz 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, -1, 4);
    expect_error(OFF, "nan vertex", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", BP_ERR_NONFINITE, BP_ERR_PARSE, 4);
    expect_error(OFF, "index out of range", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", BP_ERR_INDEX, -1, 6);
    expect_error(OFF, "negative index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", BP_ERR_INDEX, BP_ERR_PARSE, 6);
    expect_error(OFF, "face with two corners", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", BP_ERR_PARSE, BP_ERR_POLYGON, 6);
    expect_error(OFF, "face shorter than its count", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", BP_ERR_PARSE, -1, 6);
    /* counts larger than the data: the error names the line where data ran
       out (the last line, or one past it); checked separately below */
    {
        static const struct { const char *what, *text; long last; } cases[] = {
            { "4 vertices declared, 3 given", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n", 5 },
            { "2 faces declared, 1 given", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 6 },
            { "huge vertex count", "OFF\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 6 },
            { "huge face count", "OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 6 },
        };
        size_t i;
        for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            bp_mesh m;
            bp_error err;
            bp_allocator a = counting();
            bp_status st;
            counter_reset();
            st = parse(OFF, cases[i].text, strlen(cases[i].text), &m, &a, &err);
            BPT_CHECK(st == BP_ERR_PARSE || st == BP_ERR_INDEX,
                      "OFF %s: rejected (%s: %s)", cases[i].what, bp_status_string(st), err.message);
            BPT_CHECK(err.line >= 2 && err.line <= cases[i].last + 1 && bpt_has_number(err.message, err.line),
                      "OFF %s: err.line %lld names where the data ran out, message \"%s\"",
                      cases[i].what, (long long)err.line, err.message);
            BPT_CHECK(mesh_all_null(&m) && counter_balanced(), "OFF %s: nothing left allocated (%ld/%ld)",
                      cases[i].what, the_counter.allocs, the_counter.frees);
        }
    }
}

/* ---- allocation failure at every step ----------------------------------- */

static void test_alloc_failures(void)
{
    static const struct { int fmt; const char *text; } inputs[] = {
        { OBJ, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
               "f 1/1 2/2 3/3 4/4\nf 1/1 3/3 2/2\n" },
        { OFF, "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 1\n" },
    };
    size_t k;
    for (k = 0; k < 2; k++) {
        long n, total, bad = 0, oom_seen = 0;
        bp_mesh m;
        bp_error err;
        bp_allocator a = counting();
        counter_reset();
        parse(inputs[k].fmt, inputs[k].text, strlen(inputs[k].text), &m, &a, &err);
        total = the_counter.calls;
        bp_mesh_free(&m, &a);
        for (n = 1; n <= total; n++) {
            bp_status st;
            counter_reset();
            the_counter.fail_at = n;
            st = parse(inputs[k].fmt, inputs[k].text, strlen(inputs[k].text), &m, &a, &err);
            if (st == BP_OK) bp_mesh_free(&m, &a);
            else if (st != BP_ERR_OUT_OF_MEMORY || !mesh_all_null(&m)) bad++;
            else oom_seen++;
            if (!counter_balanced()) bad++;
        }
        BPT_CHECK(total > 0 && bad == 0 && oom_seen > 0,
                  "%s: failing each of the %ld allocations gives BP_ERR_OUT_OF_MEMORY, NULL arrays, no leak (%ld bad)",
                  fmt_name[inputs[k].fmt], total, bad);
    }
}

/* ---- files --------------------------------------------------------------- */

static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

static void test_files(void)
{
    char dir[] = "/tmp/bptest_io_XXXXXX", path[256];
    const char *obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    bp_mesh m;
    bp_error err;
    bp_allocator a = counting();
    bp_status st;
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }

    sprintf(path, "%s/a.obj", dir);
    write_file(path, obj);
    counter_reset();
    st = bp_read_obj(path, &m, &a, &err);
    BPT_CHECK(st == BP_OK && m.num_triangles == 2, "bp_read_obj reads a file (%s)", bp_status_string(st));
    if (st == BP_OK) bp_mesh_free(&m, &a);
    BPT_CHECK(counter_balanced(), "bp_read_obj + bp_mesh_free: balanced");
    remove(path);

    sprintf(path, "%s/b.OBJ", dir);
    write_file(path, obj);
    counter_reset();
    st = bp_read_mesh(path, &m, &a, &err);
    BPT_CHECK(st == BP_OK && m.num_triangles == 2, "bp_read_mesh: extension .OBJ is case-insensitive (%s)",
              bp_status_string(st));
    if (st == BP_OK) bp_mesh_free(&m, &a);
    BPT_CHECK(counter_balanced(), "bp_read_mesh (.OBJ): balanced");
    remove(path);

    sprintf(path, "%s/c.off", dir);
    write_file(path, "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
    counter_reset();
    st = bp_read_mesh(path, &m, &a, &err);
    BPT_CHECK(st == BP_OK && m.num_triangles == 2 && m.num_faces == 1, "bp_read_mesh reads .off (%s)",
              bp_status_string(st));
    if (st == BP_OK) bp_mesh_free(&m, &a);
    BPT_CHECK(counter_balanced(), "bp_read_mesh (.off): balanced");
    remove(path);

    sprintf(path, "%s/d.obj", dir);
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 3\nf 1 2 7\n");
    counter_reset();
    st = bp_read_obj(path, &m, &a, &err);
    BPT_CHECK(st == BP_ERR_INDEX && err.line == 6 && bpt_has_number(err.message, 6) && mesh_all_null(&m) &&
              counter_balanced(), "bp_read_obj: a bad file names line 6 (%s, line %lld: %s)",
              bp_status_string(st), (long long)err.line, err.message);
    remove(path);

    sprintf(path, "%s/missing.obj", dir);
    counter_reset();
    st = bp_read_obj(path, &m, &a, &err);
    BPT_CHECK(st == BP_ERR_IO && err.message[0] && mesh_all_null(&m) && counter_balanced(),
              "bp_read_obj: a missing file is BP_ERR_IO, nothing allocated (%s: %s)", bp_status_string(st),
              err.message);

    sprintf(path, "%s/e.ply", dir);
    write_file(path, obj);
    counter_reset();
    st = bp_read_mesh(path, &m, &a, &err);
    BPT_CHECK(st != BP_OK && err.message[0] && mesh_all_null(&m) && counter_balanced(),
              "bp_read_mesh: unknown extension .ply rejected (%s: %s)", bp_status_string(st), err.message);
    remove(path);

    sprintf(path, "%s/f.obj", dir);
    write_file(path, "");
    counter_reset();
    st = bp_read_obj(path, &m, &a, &err);
    BPT_CHECK(st == BP_ERR_EMPTY && mesh_all_null(&m) && counter_balanced(),
              "bp_read_obj: an empty file is BP_ERR_EMPTY (%s)", bp_status_string(st));
    remove(path);

    counter_reset();
    st = bp_read_obj(dir, &m, &a, &err);
    BPT_CHECK(st != BP_OK && mesh_all_null(&m) && counter_balanced(),
              "bp_read_obj on a directory fails cleanly (%s: %s)", bp_status_string(st), err.message);
    rmdir(dir);
}

/* ---- fuzzing ------------------------------------------------------------- */

/* -DFUZZ_ROUNDS=200000 (with -fsanitize=address,undefined) for a long run. */
#ifndef FUZZ_ROUNDS
#define FUZZ_ROUNDS 2000
#endif

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static uint64_t rng(void)
{
    uint64_t x = rng_state;
    x ^= x << 13; x ^= x >> 7; x ^= x << 17;
    return rng_state = x;
}

static const char fuzz_seed[] =
    "# seed\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 1/1 3/3 4/4\nf -4 -2 -1\nf 1 2 3 4\n"
    "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n4 0 1 2 3\n";

/* Feed one buffer to both parsers; count crashes-that-did-not-happen. */
static void fuzz_one(const char *buf, size_t len, long *accepted, long *bad)
{
    int fmt;
    for (fmt = 0; fmt < 2; fmt++) {
        bp_mesh m;
        bp_error err;
        bp_allocator a = counting();
        char *copy = (char *)malloc(len ? len : 1);
        bp_status st;
        memcpy(copy, buf, len);
        memset(&m, 0xAB, sizeof m);
        st = fmt == OBJ ? bp_parse_obj(copy, len, &m, &a, &err) : bp_parse_off(copy, len, &m, &a, &err);
        free(copy);
        if (st == BP_OK) {
            (*accepted)++;
            if (!mesh_consistent(&m) || m.num_triangles == 0) (*bad)++;
            bp_mesh_free(&m, &a);
        } else if (!mesh_all_null(&m) || !err.message[0] || (int)st <= 0 || st >= BP_STATUS_COUNT) {
            (*bad)++;
        }
    }
}

static void test_fuzz(void)
{
    static const char alphabet[] = "vtfnOF0123456789 -/.#e\n\r\t+x";
    char buf[1024];
    long i, accepted = 0, bad = 0;
    counter_reset();
    for (i = 0; i < FUZZ_ROUNDS; i++) {
        size_t len = (size_t)(rng() % 300), k;
        int biased = (int)(i % 2);
        for (k = 0; k < len; k++) {
            uint64_t r = rng();
            buf[k] = biased ? alphabet[r % (sizeof alphabet - 1)] : (char)(r & 0xff);
        }
        fuzz_one(buf, len, &accepted, &bad);
    }
    BPT_CHECK(bad == 0 && counter_balanced(),
              "%d random byte strings through both parsers: no crash, no leak, consistent (%ld accepted, %ld bad, %ld allocs)",
              FUZZ_ROUNDS, accepted, bad, the_counter.allocs);

    counter_reset();
    accepted = bad = 0;
    for (i = 0; i < FUZZ_ROUNDS; i++) {
        size_t len = sizeof fuzz_seed - 1;
        int edits = 1 + (int)(rng() % 8), e;
        memcpy(buf, fuzz_seed, len);
        if (i % 2) { /* OFF half of the seed for the OFF-minded mutations */
            const char *off = strstr(fuzz_seed, "OFF");
            len = strlen(off);
            memcpy(buf, off, len);
        }
        for (e = 0; e < edits; e++) {
            size_t pos = len ? (size_t)(rng() % len) : 0;
            switch (rng() % 6) {
            case 0: if (len) buf[pos] = (char)(rng() & 0xff); break;            /* replace */
            case 1: if (len) buf[pos] = "0123456789-/ \n"[rng() % 14]; break;     /* plausible */
            case 2: if (len) { memmove(buf + pos, buf + pos + 1, len - pos - 1); len--; } break; /* delete */
            case 3: if (len + 1 < sizeof buf) {                                   /* insert */
                        memmove(buf + pos + 1, buf + pos, len - pos);
                        buf[pos] = "9-/ \n.e"[rng() % 7]; len++; } break;
            case 4: len = pos; break;                                             /* truncate */
            default: if (len + 24 < sizeof buf) {                                 /* huge number */
                        const char *big = "99999999999999999999";
                        memmove(buf + pos + 20, buf + pos, len - pos);
                        memcpy(buf + pos, big, 20); len += 20; } break;
            }
        }
        fuzz_one(buf, len, &accepted, &bad);
    }
    BPT_CHECK(bad == 0 && counter_balanced(),
              "%d mutations of a valid OBJ/OFF through both parsers: no crash, no leak, consistent (%ld accepted, %ld bad, %ld allocs)",
              FUZZ_ROUNDS, accepted, bad, the_counter.allocs);
}

int main(void)
{
    test_obj_ok();
    test_obj_errors();
    test_off();
    test_alloc_failures();
    test_files();
    test_fuzz();
    return bpt_finish();
}
