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
   read past the end.  The writers: bp_write_obj_from on a hand-written
   asset must give back every line of it except vt, byte for byte, with vt
   that make the same charts; I/O errors must name the file and the reason. */
#define _POSIX_C_SOURCE 200809L
#define BP_IMPLEMENTATION
#define BP_USE_PTHREADS
/* The writers' buffers and line tasks made tiny, so that these small files
   go through every path: many tasks and rounds, full buffers flushed, a
   piece longer than the buffer written directly (the defaults are tried
   by the tool's tests and test_threads). */
#define BP__OUT_CAP 64u
#define BP__OUT_LINES_PER_TASK 5u
#define BP__OUT_TASKS 3u
#define BP__OUT_PAR_MIN 1u
/* The chunked OBJ reader on any text (not only files of a megabyte), in
   chunks of a line or two. */
#define BP__READ_PAR_MIN 1u
#define BP__READ_CHUNK 9u
#include "bijparam.h"
#include "bptest.h"

#include <errno.h>
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

/* One malformed input: the status is the expected one, err.line == line,
   the message names the line, and nothing is left allocated. */
static void expect_error(int fmt, const char *what, const char *text, int status, long line)
{
    bp_mesh m;
    bp_error err;
    bp_allocator a = counting();
    bp_status st;
    counter_reset();
    st = parse(fmt, text, strlen(text), &m, &a, &err);
    BPT_CHECK(st == (bp_status)status, "%s %s: status %s (%d), expected %s", fmt_name[fmt], what,
              bp_status_string(st), (int)st, bp_status_string((bp_status)status));
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

/* Faces with and without vt (see the reader's essay): a corner without vt
   gets the synthetic uv index (number of vt) + v, so the face without vt
   is cut from the one with vt along their shared vertices. */
static void check_mixed(const bp_mesh *m, const char *what)
{
    BPT_CHECK(m->corner_uv && m->num_uvs == 2 + 4 &&
              m->corner_uv[0] == 0 && m->corner_uv[1] == 1 && m->corner_uv[2] == 0 &&
              m->corner_uv[3] == 2 + 0 && m->corner_uv[4] == 2 + 2 && m->corner_uv[5] == 2 + 3,
              "%s: the vt face keeps vt 1 2 1, the plain face 'f 1 3 4' gets uv 2+0 2+2 2+3 (of %u)",
              what, (unsigned)m->num_uvs);
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
    expect_ok(OBJ, "faces with and without vt",
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nf 1/1 2/2 3/1\nf 1 3 4\n", 4, 2, check_mixed);
}

/* ---- "%.17g" without printf ---------------------------------------------

   bp__fmt_g17 must print every double exactly as snprintf("%.17g") does,
   byte for byte, and take its own path (bp__g17_digits) for exactly the
   numbers of the documented range: 1e-3 <= |x| < 1e17 and printed
   without an exponent.  The numbers: random bit patterns (every exponent,
   subnormals, inf, nan), uniform in [0, 1) and scaled by 10^-6 .. 10^19
   with either sign, short binary fractions (k 2^-j: their decimals end
   early, so many sit exactly halfway between two 17-digit decimals, the
   ties that must go to the even digit), and the 40 doubles around each
   power of ten from 10^-6 to 10^19.  Exact ties are counted (the 18th
   significant digit of the exact decimal is its last and a 5) so the test
   shows it met them. */
static uint64_t g17_rng = 0x9e3779b97f4a7c15ull;
static uint64_t g17_next(void)
{
    g17_rng ^= g17_rng << 13;
    g17_rng ^= g17_rng >> 7;
    g17_rng ^= g17_rng << 17;
    return g17_rng;
}

typedef struct g17_count { long n, differ, taken, eligible, missed, stray, ties; } g17_count;

/* The exact decimal of x has 18 significant digits, the last a 5. */
static int g17_is_tie(double x)
{
    char b[96];
    int n = 0, j;
    char d[96];
    snprintf(b, sizeof b, "%.70e", x);
    d[n++] = b[b[0] == '-' ? 1 : 0];
    for (j = b[0] == '-' ? 3 : 2; b[j] && b[j] != 'e'; j++) d[n++] = b[j];
    while (n > 0 && d[n - 1] == '0') n--;
    return n == 18 && d[17] == '5';
}

static void g17_one(g17_count *c, double x, int tie_check)
{
    char mine[64], libc[64];
    uint64_t D;
    int X, took, el;
    size_t n = bp__fmt_g17(mine, x);
    double ax = x < 0 ? -x : x;
    snprintf(libc, sizeof libc, "%.17g", x);
    c->n++;
    if (n != strlen(mine) || strcmp(mine, libc) != 0) {
        if (c->differ++ < 5) printf("#   %a: bp__fmt_g17 %s, snprintf %s\n", x, mine, libc);
    }
    took = x != 0 && bp__g17_digits(ax, &D, &X);
    el = ax >= 1e-3 && ax < 1e17 && !strchr(libc, 'e');
    c->taken += took;
    c->eligible += el;
    if (el && !took) c->missed++;
    if (took && !el) c->stray++;
    if (tie_check && g17_is_tie(x)) c->ties++;
}

static void test_fmt_g17(void)
{
    g17_count c;
    long i;
    int k, j;
    memset(&c, 0, sizeof c);
    for (i = 0; i < 200000; i++) {                         /* every bit pattern */
        uint64_t b = g17_next();
        double x;
        memcpy(&x, &b, sizeof x);
        g17_one(&c, x, 0);
    }
    for (i = 0; i < 300000; i++) {                         /* [0, 1), scaled, signed */
        double x = (double)(g17_next() >> 11) / 9007199254740992.0;
        if (i % 3) x *= pow(10.0, (int)(g17_next() % 26) - 6);
        g17_one(&c, g17_next() & 1 ? x : -x, 0);
    }
    for (i = 0; i < 300000; i++)                           /* k 2^-j: ties */
        g17_one(&c, ldexp((double)(g17_next() >> (11 + g17_next() % 12)), -(int)(g17_next() % 12)), 1);
    for (k = -6; k <= 19; k++) {                           /* around the powers of ten */
        double p = pow(10.0, k), y = p;
        for (j = 0; j < 20; j++) { g17_one(&c, y, 0); y = nextafter(y, 0); }
        for (y = p, j = 0; j < 20; j++) { g17_one(&c, y, 0); y = nextafter(y, HUGE_VAL); }
    }
    g17_one(&c, 0.0, 0);
    g17_one(&c, -0.0, 0);
    g17_one(&c, 1e-3, 0);
    g17_one(&c, 99999999999999999.0, 0);       /* rounds to 1e17: the exponent style */
    g17_one(&c, 0.00099999999999999999, 0);
    BPT_CHECK(c.differ == 0, "\"%%.17g\" without printf: %ld of %ld numbers differ from snprintf's bytes", c.differ, c.n);
    BPT_CHECK(c.missed == 0 && c.stray == 0 && c.taken > 300000 && c.ties > 10000,
              "... its own path takes exactly the plain range (%ld numbers; %ld missed, %ld outside), "
              "%ld exact ties among them", c.taken, c.missed, c.stray, c.ties);
}

/* ---- the rewrite's head ----------------------------------------------------

   bp__rewrite_head copies the lines before the first vt or f line in one
   piece, counting the v lines, with memchr for the line ends.  It must do
   exactly what taking those lines one by one with the parser's own steps
   does (bp__skip_space, bp__keyword, bp__next_line: the rule the rest of
   the writer and the reader follow): the same bytes out, the same count of
   v lines and of lines, and the cursor left at the same place -- on random
   texts of v, vt, f, vn, comment, blank and odd lines ("vtx", "fo", "v"
   alone, leading spaces and tabs, a NUL byte), with \n, \r\n and lone \r
   endings mixed, the last line with or without one. */
static uint64_t head_rng = 0x2545f4914f6cdd1dull;
static uint32_t head_next(uint32_t n)
{
    head_rng ^= head_rng << 13;
    head_rng ^= head_rng >> 7;
    head_rng ^= head_rng << 17;
    return (uint32_t)(head_rng >> 32) % n;
}

static void test_rewrite_head(void)
{
    static const char *const kinds[] = { "v 1 2 3", "v", "vt 0.5 0.5", "vt", "f 1 2 3", "f", "vn 0 0 1", "# c",
                                         "", "  ", "vtx 1", "fo 2", "\tv 4 5 6", " f 1 2 3", "o name", "v\t1 2 3",
                                         "vp 1", "g" };
    static const char *const eols[] = { "\n", "\r\n", "\r" };
    char text[2048], want[2048];
    long runs, bad = 0, heads = 0, stopped = 0;
    for (runs = 0; runs < 4000; runs++) {
        size_t n = 0, wn = 0;
        int lines = (int)head_next(24), k;
        int64_t want_nv = 0, want_line = 1;
        const char *want_p;
        bp__parser ps;
        bp__out o;
        bp__rewriter r;
        for (k = 0; k < lines; k++) {
            const char *s = kinds[head_next(k < lines / 2 ? 3 : (uint32_t)(sizeof kinds / sizeof *kinds))];
            n += (size_t)sprintf(text + n, "%s", s);
            if (head_next(40) == 0) text[n++] = '\0';
            if (k + 1 < lines || head_next(2)) n += (size_t)sprintf(text + n, "%s", eols[head_next(3)]);
        }
        /* the reference: line by line */
        memset(&ps, 0, sizeof ps);
        ps.p = text; ps.end = text + n; ps.line = 1;
        while (ps.p < ps.end) {
            const char *line = ps.p;
            bp__skip_space(&ps);
            if (bp__keyword(&ps, "vt") || bp__keyword(&ps, "f")) { ps.p = line; break; }
            if (bp__keyword(&ps, "v")) want_nv++;
            bp__next_line(&ps);
            memcpy(want + wn, line, (size_t)(ps.p - line));
            wn += (size_t)(ps.p - line);
        }
        want_p = ps.p;
        want_line = ps.line;
        /* bp__rewrite_head into a buffer of its own */
        memset(&o, 0, sizeof o);
        o.ok = 1;
        o.buf = (char *)malloc(sizeof want);
        o.cap = sizeof want;
        memset(&r, 0, sizeof r);
        r.ps.p = text; r.ps.end = text + n; r.ps.line = 1;
        r.o = &o;
        bp__rewrite_head(&r);
        if (!o.ok || o.len != wn || memcmp(o.buf, want, wn) != 0 || r.nv != want_nv || r.ps.line != want_line ||
            r.ps.p != want_p) {
            if (bad++ < 3)
                printf("#   run %ld: %zu bytes out (want %zu), nv %lld (%lld), line %lld (%lld), at %ld (%ld)\n", runs,
                       o.len, wn, (long long)r.nv, (long long)want_nv, (long long)r.ps.line, (long long)want_line,
                       (long)(r.ps.p - text), (long)(want_p - text));
        }
        heads += wn > 0;
        stopped += want_p < text + n;
        free(o.buf);
    }
    BPT_CHECK(bad == 0 && heads > 1000 && stopped > 1000,
              "the rewrite's head: the same bytes, v lines, lines and cursor as line by line (%ld of 4000 random texts "
              "differ; %ld with a head, %ld stopped at a vt or f line)", bad, heads, stopped);
}

/* ---- the decimals' fast path -------------------------------------------

   bp__decimal_fast reads m x 10^q with at most 15 significant digits and
   |q| <= 22 by one multiplication or division, and must give strtod's
   double bit for bit; everything else it must hand back (0) to strtod.
   Random tokens of every shape (signs, leading and trailing zeros, a
   point anywhere or none, exponents with and without signs, long
   mantissas, large exponents): each one the fast path takes must equal
   strtod's bits, each one of the documented shape it must take, and the
   reader (bp_parse_obj) must give strtod's bits for all of them, taken or
   not. */
static uint64_t dec_rng = 0x243f6a8885a308d3ull;
static uint32_t dec_next(uint32_t n)
{
    dec_rng = dec_rng * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(dec_rng >> 33) % n;
}

/* A random decimal token in t; *eligible: of the fast path's shape. */
static size_t dec_token(char *t, int *eligible)
{
    size_t n = 0;
    int ni = (int)dec_next(12), nf = dec_next(3) ? (int)dec_next(12) : -1, d, sig = 0, nz = 0, q = 0, ex = 0;
    if (dec_next(4) == 0) ni += (int)dec_next(8);            /* long mantissas too */
    if (ni == 0 && nf <= 0) ni = 1;
    if (dec_next(3) == 0) t[n++] = dec_next(2) ? '-' : '+';
    for (d = 0; d < ni; d++) {
        char c = (char)('0' + (d == 0 && dec_next(3) == 0 ? 0 : dec_next(10)));
        t[n++] = c;
        if (nz || c != '0') { nz = 1; sig++; }
    }
    if (nf >= 0) {
        t[n++] = '.';
        for (d = 0; d < nf; d++) {
            char c = (char)('0' + (dec_next(4) == 0 ? 0 : dec_next(10)));
            t[n++] = c;
            q--;
            if (nz || c != '0') { nz = 1; sig++; }
        }
    }
    if (dec_next(3) == 0) {
        int en = dec_next(2), k, len = 1 + (int)dec_next(2);
        t[n++] = dec_next(2) ? 'e' : 'E';
        if (en || dec_next(3) == 0) t[n++] = en ? '-' : '+';
        for (k = 0; k < len; k++) { int c = (int)dec_next(k ? 10 : 4); t[n++] = (char)('0' + c); ex = 10 * ex + c; }
        q += en ? -ex : ex;
    }
    t[n] = 0;
    *eligible = sig <= 15 && (sig == 0 || (q >= -22 && q <= 22));
    return n;
}

static void test_decimal_fast(void)
{
    static const char *const edge[] = { "0", "-0", "+0", "-0.0", "0e500", "-0e-9999", ".5", "5.", "-.5e-3",
                                        "1e22", "1e-22", "1e23", "9e-23", "123456789012345", "1234567890123456",
                                        "9007199254740993", "0.000000000000000000000001", "1.7976931348623157e308",
                                        "4.9e-324", "1e", "1e+", "1.5.2", "e5", "+", "-", ".", "0x10", "inf",
                                        "nan", "1,5", "1d5", "--1", "1e5x", "170.381", "-2.76586" };
    char tok[80], *text;
    size_t k, n, len = 0, cap = 40 * 3 * 20000 + 64;
    long i, taken = 0, eligible_n = 0, wrong = 0, missed = 0, stray = 0, read_wrong = 0;
    bp_mesh m;
    bp_error err;
    double *want = (double *)malloc(3 * 20000 * sizeof(double));
    text = (char *)malloc(cap);
    for (k = 0; k < sizeof edge / sizeof *edge; k++) {
        double x, y;
        char *stop;
        int took = bp__decimal_fast(edge[k], strlen(edge[k]), &x);
        y = strtod(edge[k], &stop);
        if (took && (*stop || memcmp(&x, &y, sizeof x) != 0)) stray++;
    }
    for (i = 0; i < 3 * 20000; i++) {
        double x, y;
        int el, took;
        n = dec_token(tok, &el);
        took = bp__decimal_fast(tok, n, &x);
        y = strtod(tok, NULL);
        taken += took;
        eligible_n += el;
        if (took && memcmp(&x, &y, sizeof x) != 0) wrong++;
        if (el && !took) missed++;
        if (!el && took) stray++;
        want[i] = y;
        if (i % 3 == 0) len += (size_t)sprintf(text + len, "v");
        len += (size_t)sprintf(text + len, " %s", tok);
        if (i % 3 == 2) len += (size_t)sprintf(text + len, "\n");
    }
    len += (size_t)sprintf(text + len, "f 1 2 3\n");
    if (bp_parse_obj(text, len, &m, NULL, &err) != BP_OK || m.num_vertices != 20000) read_wrong = -1;
    else {
        for (i = 0; i < 3 * 20000; i++)
            if (memcmp(&m.positions[i], &want[i], sizeof(double)) != 0) read_wrong++;
        bp_mesh_free(&m, NULL);
    }
    BPT_CHECK(wrong == 0 && missed == 0 && stray == 0 && taken > 30000 && taken < 3 * 20000 - 3000,
              "the decimals' fast path: %ld of 60000 random tokens taken (%ld of the documented shape), "
              "each strtod's bits (%ld differ), none of that shape refused (%ld), none of another shape or "
              "edge case taken wrongly (%ld)", taken, eligible_n, wrong, missed, stray);
    BPT_CHECK(read_wrong == 0, "bp_parse_obj reads 60000 random decimals (fast path or strtod) as strtod's bits "
              "(%ld differ; -1: the text was refused: %s)", read_wrong, read_wrong < 0 ? err.message : "");
    {   /* a token of 80 characters or more is refused, also when the fast path could read it */
        char big[160];
        bp_status st;
        memset(big, 0, sizeof big);
        memcpy(big, "v ", 2);
        memset(big + 2, '0', 84);
        len = 86 + (size_t)sprintf(big + 86, "1.5 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        st = bp_parse_obj(big, len, &m, NULL, &err);
        BPT_CHECK(st == BP_ERR_PARSE && err.line == 1 && strstr(err.message, "too long") != NULL,
                  "an 87-character coordinate (84 leading zeros) is refused as too long, whatever the fast path takes "
                  "(status %d: %s)", (int)st, err.message);
        if (st == BP_OK) bp_mesh_free(&m, NULL);
    }
    free(text);
    free(want);
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

    expect_error(OBJ, "empty input", "", BP_ERR_EMPTY, 0);
    expect_error(OBJ, "only comments", "# nothing\n\n", BP_ERR_EMPTY, 0);
    expect_error(OBJ, "only vertices", tri3, BP_ERR_EMPTY, 0);
    expect_error(OBJ, "truncated vertex (v 1 2)", "v 0 0 0\nv 1 2\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, 2);
    expect_error(OBJ, "truncated vertex at end of input (v 1)", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 1", BP_ERR_PARSE, 4);
    expect_error(OBJ, "bad number (v 1.0 abc 2)", "v 0 0 0\nv 1.0 abc 2\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, 2);
    expect_error(OBJ, "number with trailing junk (v 1 2x 3)", "v 0 0 0\nv 1 2x 3\nv 0 1 0\nf 1 2 3\n", BP_ERR_PARSE, 2);
    expect_error(OBJ, "overflowing coordinate (v 1e999 0 0)", "v 0 0 0\nv 1 0 0\nv 1e999 0 0\nf 1 2 3\n",
                 BP_ERR_NONFINITE, 3);
    expect_error(OBJ, "nan coordinate", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", BP_ERR_NONFINITE, 2);
    expect_error(OBJ, "inf coordinate", "v 0 0 0\nv 0 inf 0\nv 0 1 0\nf 1 2 3\n", BP_ERR_NONFINITE, 2);
    expect_error(OBJ, "nan texture coordinate", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt nan 0\nf 1/1 2/1 3/1\n",
                 BP_ERR_NONFINITE, 4);
    expect_error(OBJ, "too few corners (f 1 2)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", BP_ERR_POLYGON, 4);
    expect_error(OBJ, "face with no corners (f)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n", BP_ERR_POLYGON, 4);
    expect_error(OBJ, "index 0", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", BP_ERR_INDEX, 4);
    expect_error(OBJ, "index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n", BP_ERR_INDEX, 5);
    expect_error(OBJ, "huge index (f 99999999999999999999 1 2)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 99999999999999999999 1 2\n",
                 BP_ERR_INDEX, 4);
    expect_error(OBJ, "index 2^32+1 (would wrap to 1)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 4294967297 2 3\n",
                 BP_ERR_INDEX, 4);
    expect_error(OBJ, "negative index past the start", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n", BP_ERR_INDEX, 4);
    expect_error(OBJ, "huge negative index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -99999999999999999999 -2 -1\n",
                 BP_ERR_INDEX, 4);
    expect_error(OBJ, "vt index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n", BP_ERR_INDEX, 5);
    expect_error(OBJ, "vt index 0", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\n", BP_ERR_INDEX, 5);
    expect_error(OBJ, "garbage in a face (f 1 x 3)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", BP_ERR_PARSE, 4);
    expect_error(OBJ, "garbage after an index (f 1 2 3x)", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n", BP_ERR_PARSE, 4);
    expect_error(OBJ, "error after CRLF lines", "v 0 0 0\r\nv 1 0 0\r\n\r\nv 0 1 0\r\nf 1 2 9\r\n", BP_ERR_INDEX, 5);
    /* a long valid prefix: the line count must survive buffer growth */
    {
        size_t n = 0;
        int i;
        static char big[200000];
        for (i = 0; i < 5000; i++) n += (size_t)sprintf(big + n, "v %d 0 0\n", i);
        n += (size_t)sprintf(big + n, "f 1 2 3\nf 1 2 5001\n");
        (void)n;
        expect_error(OBJ, "error on line 5002 after 5000 vertices", big, BP_ERR_INDEX, 5002);
    }

    /* the error names what kind of element it is about */
    counter_reset();
    st = parse(OBJ, bad0, strlen(bad0), &m, &a, &err);
    BPT_CHECK(st == BP_ERR_INDEX && err.element == BP_ELEMENT_LINE && err.index == 5,
              "OBJ index 0: err.element is the line, index 5 (%d, %lld)", (int)err.element, (long long)err.index);
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
    BPT_CHECK(m->triangle_line && m->triangle_line[0] == 7 && m->triangle_line[1] == 8,
              "%s: triangle_line gives the face lines 7, 8", what);
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

    expect_error(OFF, "empty input", "", BP_ERR_EMPTY, 0);
    expect_error(OFF, "bad magic (OFX)", "OFX\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, 1);
    expect_error(OFF, "bad count (3 x 0)", "OFF\n3 x 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, 2);
    expect_error(OFF, "negative count", "OFF\n-3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, 2);
    expect_error(OFF, "missing counts", "OFF\n\n", BP_ERR_PARSE, 0);
    expect_error(OFF, "only vertices (0 faces)", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", BP_ERR_EMPTY, 0);
    expect_error(OFF, "bad vertex line", "OFF\n3 1 0\n0 0 0\n1 zz 0\n0 1 0\n3 0 1 2\n", BP_ERR_PARSE, 4);
    expect_error(OFF, "nan vertex", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", BP_ERR_NONFINITE, 4);
    expect_error(OFF, "index out of range", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", BP_ERR_INDEX, 6);
    expect_error(OFF, "negative index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", BP_ERR_INDEX, 6);
    expect_error(OFF, "face with two corners", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", BP_ERR_POLYGON, 6);
    expect_error(OFF, "face shorter than its count", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", BP_ERR_PARSE, 6);
    /* counts larger than the data: the error names the line where the data
       ran out (one past the last line), or the header when the counts
       cannot fit in the file at all */
    {
        static const struct { const char *what, *text; long line; } cases[] = {
            { "4 vertices declared, 3 given", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n", 6 },
            { "2 faces declared, 1 given", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 7 },
            { "huge vertex count", "OFF\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 2 },
            { "huge face count", "OFF\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 2 },
        };
        size_t i;
        for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            bp_mesh m;
            bp_error err;
            bp_allocator a = counting();
            bp_status st;
            counter_reset();
            st = parse(OFF, cases[i].text, strlen(cases[i].text), &m, &a, &err);
            BPT_CHECK(st == BP_ERR_PARSE, "OFF %s: BP_ERR_PARSE (%s: %s)", cases[i].what,
                      bp_status_string(st), err.message);
            BPT_CHECK(err.line == cases[i].line && bpt_has_number(err.message, err.line),
                      "OFF %s: err.line %lld (expected %ld), message \"%s\"",
                      cases[i].what, (long long)err.line, cases[i].line, err.message);
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
    BPT_CHECK(st == BP_ERR_IO && strstr(err.message, path) && strstr(err.message, strerror(ENOENT)) &&
              mesh_all_null(&m) && counter_balanced(),
              "bp_read_obj: a missing file is BP_ERR_IO naming the file and the reason, nothing allocated (%s: %s)",
              bp_status_string(st), err.message);

    sprintf(path, "%s/e.stl", dir);
    write_file(path, obj);
    counter_reset();
    st = bp_read_mesh(path, &m, &a, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && strstr(err.message, path) && mesh_all_null(&m) && counter_balanced(),
              "bp_read_mesh: unknown extension .stl rejected, the message names the file (%s: %s)",
              bp_status_string(st), err.message);
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
    BPT_CHECK(st == BP_ERR_IO && strstr(err.message, dir) && strstr(err.message, strerror(EISDIR)) &&
              mesh_all_null(&m) && counter_balanced(),
              "bp_read_obj on a directory: BP_ERR_IO saying it is a directory, nothing allocated (%s: %s)",
              bp_status_string(st), err.message);
    rmdir(dir);
}

/* ---- bp_write_obj_from: the user's own file back, with new vt ---------- */

/* A small asset with everything an OBJ from a game pipeline carries:
   materials, groups, objects, smoothing, normals, comments, a line element,
   an unknown statement, quads and triangles, relative indices, a face
   without vt next to faces with vt (its own chart), tabs, CRLF endings and
   no line ending at the very end.  Three charts: the left two quads (vt
   1-6), the lower right triangles (vt 7-12, a seam down the middle) and the
   upper right quad written v//vn. */
static const char asset_obj[] =
    "# test asset\r\n"
    "mtllib test.mtl\r\n"
    "o thing\r\n"
    "v 0 0 0\r\nv 1 0 0.1\r\nv 2 0 0\r\n"
    "v 0 1 0.1\r\nv 1 1 0.3\r\nv 2 1 0.1\r\n"
    "v 0 2 0\r\nv 1 2 0.1\r\nv 2 2 0\r\n"
    "vn 0 0 1\r\nvn 0 0.1 1\r\n"
    "# old uvs\r\n"
    "vt 0 0\r\nvt 1 0\r\nvt 0 1\r\nvt 1 1\r\nvt 0 2\r\nvt 1 2\r\n"
    "vp 0.5\r\n"
    "vt 1 0\r\nvt 2 0\r\nvt 1 1\r\nvt 2 1\r\nvt 1 2\r\nvt 2 2\r\n"
    "g left\r\n"
    "usemtl red\r\n"
    "s 1\r\n"
    "f 1/1/1 2/2/1 5/4/2 4/3/2\r\n"
    "f\t-6/-10/-2 -5/-9/-2  -2/-7/-1 -3/-8/-1 # upper left, relative\r\n"
    "\r\n"
    "g right\r\n"
    "usemtl blue\r\n"
    "s off\r\n"
    "f 2/7 3/8 6/10\r\n"
    "f 2/7 6/10 5/9\r\n"
    "l 1 2 3\r\n"
    "frobnicate 42\r\n"
    "f 5//2 6//2 9//1 8//1\r\n"
    "# end";

static int write_bytes(const char *path, const char *text, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    if (fwrite(text, 1, n, f) != n) { fclose(f); return 0; }
    return fclose(f) == 0;
}

static char *read_bytes(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long len;
    *n = 0;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = (char *)malloc((size_t)len + 1);
    if (buf && fread(buf, 1, (size_t)len, f) != (size_t)len) { free(buf); buf = NULL; }
    fclose(f);
    if (buf) { buf[len] = 0; *n = (size_t)len; }
    return buf;
}

/* The lines of a text, each with its own line ending. */
typedef struct text_lines { const char *start[128]; size_t len[128]; int n; } text_lines;

static void split_lines(const char *s, size_t n, text_lines *l)
{
    size_t i = 0;
    l->n = 0;
    while (i < n && l->n < 128) {
        size_t j = i;
        while (j < n && s[j] != '\n') j++;
        if (j < n) j++;
        l->start[l->n] = s + i;
        l->len[l->n++] = j - i;
        i = j;
    }
}

static int line_is(const char *s, size_t n, const char *kw)
{
    size_t k = strlen(kw);
    while (n && (*s == ' ' || *s == '\t')) { s++; n--; }
    return n > k && !memcmp(s, kw, k) && (s[k] == ' ' || s[k] == '\t');
}

/* The corners of an f line: v text, vt text (may be empty), vn text. */
static int face_corners(const char *s, size_t n, char v[][16], char vt[][16], char vn[][16], int max)
{
    char buf[256], *p, *save = NULL;
    int k = 0;
    if (n >= sizeof buf) return -1;
    memcpy(buf, s, n);
    buf[n] = 0;
    if ((p = strchr(buf, '#')) != NULL) *p = 0;
    p = strtok_r(buf, " \t\r\n", &save);              /* "f" */
    while ((p = strtok_r(NULL, " \t\r\n", &save)) != NULL && k < max) {
        char *s1 = strchr(p, '/'), *s2 = s1 ? strchr(s1 + 1, '/') : NULL;
        if (s1) *s1 = 0;
        if (s2) *s2 = 0;
        snprintf(v[k], 16, "%s", p);
        snprintf(vt[k], 16, "%s", s1 ? s1 + 1 : "");
        snprintf(vn[k], 16, "%s", s2 ? s2 + 1 : "");
        k++;
    }
    return k;
}

/* Compare source and result line by line: every line except vt comes
   back byte for byte and in order; the new vt lines form one block where
   the first vt line was; f lines keep their v and vn text, their spacing
   before the first corner, their comment and their line ending, and each
   corner gets a vt exactly when `want_vt(line, corner)` says so. */
static void compare_rewrite(const char *src, size_t src_n, const char *out, size_t out_n,
                            uint32_t new_vt, const char *what)
{
    text_lines a, b;
    int i = 0, j = 0, first_vt = -1, block = -1, block_len = 0, same = 1, faces = 0, bad_face = 0;
    split_lines(src, src_n, &a);
    split_lines(out, out_n, &b);
    while (i < a.n || j < b.n) {
        if (i < a.n && line_is(a.start[i], a.len[i], "vt")) { if (first_vt < 0) first_vt = j; i++; continue; }
        if (j < b.n && line_is(b.start[j], b.len[j], "vt")) {
            if (block < 0) block = j;
            else if (block + block_len != j) same = 0;        /* not one block */
            block_len++;
            j++;
            continue;
        }
        if (i >= a.n || j >= b.n) { same = 0; break; }
        if (line_is(a.start[i], a.len[i], "f")) {
            char v1[16][16], t1[16][16], n1[16][16], v2[16][16], t2[16][16], n2[16][16];
            int k1 = face_corners(a.start[i], a.len[i], v1, t1, n1, 16);
            int k2 = face_corners(b.start[j], b.len[j], v2, t2, n2, 16), k;
            const char *ha = (const char *)memchr(a.start[i], '#', a.len[i]), *hb = (const char *)memchr(b.start[j], '#', b.len[j]);
            faces++;
            if (k1 != k2 || k1 < 3 || !line_is(b.start[j], b.len[j], "f")) bad_face++;
            for (k = 0; k < k1 && k1 == k2; k++) {
                long vt = atol(t2[k]);
                if (strcmp(v1[k], v2[k]) || strcmp(n1[k], n2[k]) || vt < 1 || vt > (long)new_vt) bad_face++;
            }
            /* the line ending and a trailing comment are kept */
            if ((ha == NULL) != (hb == NULL) ||
                (ha && strncmp(ha, hb, a.len[i] - (size_t)(ha - a.start[i])) != 0) ||
                (a.start[i][a.len[i] - 1] == '\n') != (b.start[j][b.len[j] - 1] == '\n') ||
                (a.len[i] > 1 && a.start[i][a.len[i] - 2] == '\r') != (b.len[j] > 1 && b.start[j][b.len[j] - 2] == '\r'))
                bad_face++;
            /* the spacing between "f" and the first corner ("f\t") */
            if (a.start[i][1] != b.start[j][1]) bad_face++;
        } else if (a.len[i] != b.len[j] || memcmp(a.start[i], b.start[j], a.len[i]) != 0) {
            same = 0;
        }
        i++; j++;
    }
    BPT_CHECK(same, "%s: every line but vt and f comes back byte for byte and in order", what);
    BPT_CHECK(faces > 0 && bad_face == 0,
              "%s: %d f lines keep their v and vn text, comment, spacing and line ending, every corner has a new vt (%d bad)",
              what, faces, bad_face);
    BPT_CHECK(block == first_vt && block_len == (int)new_vt,
              "%s: the %u new vt lines are one block where the first vt was (line %d, expected %d; %d lines)",
              what, (unsigned)new_vt, block + 1, first_vt + 1, block_len);
}

/* The result, read back, makes the same charts with the same uv: each
   corner's written vt holds exactly its chart vertex's uv, two corners
   share a vt exactly when they share a chart vertex, and the charts built
   from the result are the atlas's charts. */
static void check_same_charts(const bp_mesh *src, const bp_atlas *atlas, const char *out_path, const char *what)
{
    bp_mesh m;
    bp_error err;
    bp_atlas again;
    bp_options opt;
    uint32_t i, j, bad_uv = 0, bad_share = 0, bad_chart = 0;
    bp_status st = bp_read_obj(out_path, &m, NULL, &err);
    BPT_CHECK(st == BP_OK, "%s: the result reads back (%s)", what, err.message);
    if (st != BP_OK) return;
    BPT_CHECK(m.num_vertices == src->num_vertices && m.num_triangles == src->num_triangles &&
              !memcmp(m.positions, src->positions, 3 * sizeof(double) * m.num_vertices) &&
              !memcmp(m.triangles, src->triangles, 3 * sizeof(uint32_t) * m.num_triangles) &&
              m.num_faces == src->num_faces,
              "%s: same vertices (bit for bit), triangles and faces", what);
    for (i = 0; m.corner_uv && i < 3 * m.num_triangles; i++) {
        const bp_chart *ch = &atlas->charts[atlas->corner_chart[i]];
        uint32_t cv = atlas->corner_vertex[i];
        if (!ch->uv || m.uvs[2 * m.corner_uv[i]] != ch->uv[2 * cv] || m.uvs[2 * m.corner_uv[i] + 1] != ch->uv[2 * cv + 1])
            bad_uv++;
        for (j = 0; j < i; j++)
            if ((m.corner_uv[i] == m.corner_uv[j]) !=
                (atlas->corner_chart[i] == atlas->corner_chart[j] && atlas->corner_vertex[i] == atlas->corner_vertex[j]))
                bad_share++;
    }
    BPT_CHECK(m.corner_uv && bad_uv == 0 && bad_share == 0,
              "%s: each corner's vt is its chart vertex's uv exactly, shared exactly when the chart vertex is (%u, %u bad)",
              what, (unsigned)bad_uv, (unsigned)bad_share);
    memset(&opt, 0, sizeof opt);
    st = bp_atlas_build(&again, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && again.num_charts == atlas->num_charts, "%s: the result has %u charts (%u)", what,
              (unsigned)atlas->num_charts, st == BP_OK ? (unsigned)again.num_charts : 0u);
    if (st == BP_OK) {
        for (i = 0; i < 3 * m.num_triangles; i++)
            for (j = 0; j < i; j++)
                if ((again.corner_chart[i] == again.corner_chart[j]) != (atlas->corner_chart[i] == atlas->corner_chart[j]))
                    bad_chart++;
        BPT_CHECK(bad_chart == 0, "%s: the charts of the result are the atlas's charts (%u pairs differ)", what,
                  (unsigned)bad_chart);
        bp_atlas_free(&again);
    }
    bp_mesh_free(&m, NULL);
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

static void test_write_from(void)
{
    char dir[] = "/tmp/bptest_wf_XXXXXX", src[256], out[256], other[256];
    bp_mesh m, m2;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_status st;
    size_t n_src = sizeof asset_obj - 1, n_out;
    char *text;
    uint32_t c, new_vt = 0;
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    sprintf(src, "%s/asset.obj", dir);
    sprintf(out, "%s/asset_uv.obj", dir);
    sprintf(other, "%s/other.obj", dir);
    write_bytes(src, asset_obj, n_src);
    st = bp_read_obj(src, &m, NULL, &err);
    BPT_CHECK(st == BP_OK && m.num_vertices == 9 && m.num_triangles == 8 && m.num_faces == 5,
              "asset: reads (%s), 9 vertices, 8 triangles, 5 faces", err.message);
    if (st != BP_OK) { rmdir(dir); return; }
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    st = bp_parameterize(&atlas, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && atlas.num_charts == 3, "asset: 3 charts flattened (%s, %u charts)",
              err.message, st == BP_OK ? (unsigned)atlas.num_charts : 0u);
    if (st != BP_OK) { bp_mesh_free(&m, NULL); rmdir(dir); return; }
    for (c = 0; c < atlas.num_charts; c++) new_vt += atlas.charts[c].num_vertices;

    st = bp_write_obj_from(out, src, &m, &atlas, &err);
    BPT_CHECK(st == BP_OK && err.status == BP_OK, "bp_write_obj_from writes (%s)", err.message);
    text = read_bytes(out, &n_out);
    BPT_CHECK(text != NULL, "bp_write_obj_from: the result exists");
    if (text) {
        compare_rewrite(asset_obj, n_src, text, n_out, new_vt, "asset");
        BPT_CHECK(n_out > 5 && !memcmp(text + n_out - 5, "# end", 5), "asset: the last line stays without a line ending");
        free(text);
        check_same_charts(&m, &atlas, out, "asset");
    }

    /* a failed chart: its faces keep v and vn, without vt */
    {
        bp_error why;
        uint32_t t, k, plain = 0, with_vt = 0, chart0_faces = 0;
        memset(&why, 0, sizeof why);
        why.status = BP_ERR_TOPOLOGY;
        strcpy(why.message, "failed on purpose");
        bp_atlas_fail_chart(&atlas, 0, &why);
        for (t = 0; t < m.num_triangles; t++) chart0_faces += atlas.corner_chart[3 * t] == 0;
        st = bp_write_obj_from(out, src, &m, &atlas, &err);
        BPT_CHECK(st == BP_OK, "bp_write_obj_from with a failed chart (%s)", err.message);
        st = bp_read_obj(out, &m2, NULL, &err);
        BPT_CHECK(st == BP_OK, "the result with a failed chart reads back (%s)", err.message);
        if (st == BP_OK) {
            /* corners without vt get synthetic uv indices num_vt + v (see the reader) */
            uint32_t nvt = m2.num_uvs - m2.num_vertices;
            for (t = 0; t < m2.num_triangles; t++)
                for (k = 0; k < 3; k++) {
                    int is_plain = m2.corner_uv[3 * t + k] >= nvt;
                    if (atlas.corner_chart[3 * t + k] == 0) plain += is_plain;
                    else with_vt += !is_plain;
                }
            BPT_CHECK(chart0_faces > 0 && plain == 3 * chart0_faces && with_vt == 3 * (m2.num_triangles - chart0_faces),
                      "failed chart: its %u triangles have no vt, the others all have theirs", (unsigned)chart0_faces);
            bp_mesh_free(&m2, NULL);
        }
        text = read_bytes(out, &n_out);
        BPT_CHECK(text && strstr(text, "f 1//1 2//1 5//2 4//2\r\n") && strstr(text, "\r\nf\t-6//-2 -5//-2  -2//-1 -3//-1 # upper left, relative\r\n"),
                  "failed chart: 'f 1/1/1 ...' becomes 'f 1//1 ...', relative indices, spacing and comment kept");
        free(text);
    }

    /* the wrong source, the same path, a missing source, a bad target */
    {
        const char *wrong = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nf 1 2 3\nf 2 4 3\n";
        write_bytes(other, wrong, strlen(wrong));
    }
    remove(out);
    st = bp_write_obj_from(out, other, &m, &atlas, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && err.line == 5 && bpt_has_number(err.message, 5) && !file_exists(out),
              "a source the mesh was not read from is refused at its first face, line 5, and no file is left (%s)",
              err.message);
    st = bp_write_obj_from(src, src, &m, &atlas, &err);
    text = read_bytes(src, &n_out);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && text && n_out == n_src && !memcmp(text, asset_obj, n_src),
              "writing over the source is refused and leaves it unchanged (%s)", err.message);
    free(text);
    sprintf(other, "%s/missing.obj", dir);
    st = bp_write_obj_from(out, other, &m, &atlas, &err);
    BPT_CHECK(st == BP_ERR_IO && strstr(err.message, strerror(ENOENT)) && strstr(err.message, other) && !file_exists(out),
              "a missing source: BP_ERR_IO naming the file and the reason (%s)", err.message);
    sprintf(other, "%s/no/such/dir/out.obj", dir);
    st = bp_write_obj_from(other, src, &m, &atlas, &err);
    BPT_CHECK(st == BP_ERR_IO && strstr(err.message, strerror(ENOENT)) && strstr(err.message, other),
              "an output in a missing directory: BP_ERR_IO naming the file and the reason (%s)", err.message);
    st = bp_write_obj(other, &m, &atlas, &err);
    BPT_CHECK(st == BP_ERR_IO && strstr(err.message, strerror(ENOENT)),
              "bp_write_obj too gives the reason (%s)", err.message);

    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    remove(src);
    remove(out);
    sprintf(other, "%s/other.obj", dir);
    remove(other);
    BPT_CHECK(rmdir(dir) == 0, "no file left behind in the test directory");
}

/* A polygon whose fan triangles disagree on a corner (here: one of its
   triangles is in a chart marked failed) is written as its fan triangles;
   a plain quad stays one line. */
static void test_write_from_split(void)
{
    char dir[] = "/tmp/bptest_ws_XXXXXX", src[256], out[256];
    const char *text = "v 0 0 0\nv 1 0 0\nv 1 1 0.2\nv 0 1 0\nv 2 0.5 0\nf 1 2 3 4\nf 2 5 3\n";
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err, why;
    bp_status st;
    size_t n;
    char *res;
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    sprintf(src, "%s/s.obj", dir);
    sprintf(out, "%s/s_uv.obj", dir);
    write_bytes(src, text, strlen(text));
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    st = bp_read_obj(src, &m, NULL, &err);
    if (st == BP_OK) st = bp_parameterize(&atlas, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && atlas.num_charts == 1, "split: one chart (%s)", err.message);
    if (st != BP_OK) { remove(src); rmdir(dir); return; }
    st = bp_write_obj_from(out, src, &m, &atlas, &err);
    res = read_bytes(out, &n);
    BPT_CHECK(st == BP_OK && res && strstr(res, "\nf 1/1 2/2 3/3 4/4\n") && strstr(res, "\nf 2/2 5/5 3/3\n"),
              "a quad in one chart stays one line with one vt per corner");
    free(res);
    /* Pretend the quad's second fan triangle belongs to a failed chart:
       corners 0 and 2 then have two different vt. */
    {
        bp_atlas fake = atlas;
        bp_chart charts[2];
        uint32_t cc[9];
        memcpy(cc, atlas.corner_chart, sizeof cc);
        cc[3] = cc[4] = cc[5] = 1;
        charts[0] = atlas.charts[0];
        memset(&charts[1], 0, sizeof charts[1]);
        memset(&why, 0, sizeof why);
        charts[1].error.status = BP_ERR_TOPOLOGY;
        fake.charts = charts;
        fake.num_charts = 2;
        fake.corner_chart = cc;
        st = bp_write_obj_from(out, src, &m, &fake, &err);
        res = read_bytes(out, &n);
        BPT_CHECK(st == BP_OK && res && strstr(res, "\nf 1/1 2/2 3/3\nf 1 3 4\nf 2/2 5/5 3/3\n"),
                  "a quad split between a valid and a failed chart is written as its two triangles");
        free(res);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    remove(src);
    remove(out);
    rmdir(dir);
}

/* bp_write_obj on a closed cube of quads (no vt): the automatic cut runs
   along some quads' diagonals, so the two fan triangles of such a quad
   give its diagonal corners different chart vertices.  The written file,
   read back, must give every corner exactly its chart vertex's uv (one f
   line per quad would give the second triangle the first one's vt). */
static void test_write_fan_cut(void)
{
    char dir[] = "/tmp/bptest_fc_XXXXXX", out[256];
    const char *text = "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                       "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    bp_mesh m, r;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_status st;
    uint32_t i, t, split = 0, bad = 0;
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    sprintf(out, "%s/cube_uv.obj", dir);
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    st = bp_parse_off(text, strlen(text), &m, NULL, &err);
    if (st == BP_OK) st = bp_parameterize(&atlas, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && atlas.num_charts == 1 && atlas.charts[0].cut_edges > 0,
              "fan cut: the cube of quads is cut into one chart (%s)", err.message);
    if (st != BP_OK) { rmdir(dir); return; }
    for (t = 0; t + 1 < m.num_triangles; t++)      /* quads whose diagonal is a seam */
        split += m.triangle_face[t] == m.triangle_face[t + 1] &&
                 atlas.corner_vertex[3 * t] != atlas.corner_vertex[3 * (t + 1)];
    BPT_CHECK(split > 0, "fan cut: the cut runs along %u quad diagonals (the case under test)", (unsigned)split);
    st = bp_write_obj(out, &m, &atlas, &err);
    BPT_CHECK(st == BP_OK, "fan cut: bp_write_obj writes (%s)", err.message);
    st = st == BP_OK ? bp_read_obj(out, &r, NULL, &err) : st;
    BPT_CHECK(st == BP_OK && r.corner_uv && r.num_triangles == m.num_triangles &&
              !memcmp(r.triangles, m.triangles, 3 * sizeof(uint32_t) * m.num_triangles),
              "fan cut: the result reads back with the same triangles (%s)", err.message);
    if (st == BP_OK) {
        for (i = 0; r.corner_uv && i < 3 * r.num_triangles; i++) {
            const double *uv = atlas.charts[atlas.corner_chart[i]].uv + 2 * (size_t)atlas.corner_vertex[i];
            bad += r.uvs[2 * r.corner_uv[i]] != uv[0] || r.uvs[2 * r.corner_uv[i] + 1] != uv[1];
        }
        BPT_CHECK(r.corner_uv && bad == 0, "fan cut: each written corner has its chart vertex's uv exactly (%u bad)",
                  (unsigned)bad);
        bp_mesh_free(&r, NULL);
    }
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    remove(out);
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

/* The asset with 1 to 4 random edits (as test_fuzz's): a character
   replaced, deleted or inserted, or the text cut; returns its length. */
static size_t mutated_asset(char *buf, size_t cap)
{
    size_t len = sizeof asset_obj - 1;
    int edits = 1 + (int)(rng() % 4), e;
    memcpy(buf, asset_obj, len);
    for (e = 0; e < edits; e++) {
        size_t pos = (size_t)(rng() % len);
        switch (rng() % 4) {
        case 0: buf[pos] = "0123456789-/ \n\r#fvt"[rng() % 19]; break;
        case 1: memmove(buf + pos, buf + pos + 1, len - pos - 1); len--; break;
        case 2: if (len + 1 < cap) { memmove(buf + pos + 1, buf + pos, len - pos); buf[pos] = "1-/ \n"[rng() % 5]; len++; } break;
        default: len = pos > 0 ? pos : 1; break;
        }
    }
    return len;
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

/* ---- the OBJ reader on several threads --------------------------------------

   bp_read_mesh_opt reads a large OBJ in chunks on threads (bijparam.h, "OBJ
   on several threads"); here every text goes through it (chunks of about
   9 bytes) with tasks run backwards, odd-even and on pools of 2 and 3
   threads, and must give what the serial parser (bp_parse_obj) gives: the
   same arrays, bit for bit, or the same error -- status, element, line and
   message. */
static int same_mesh(const bp_mesh *a, const bp_mesh *b)
{
    size_t nt = 3 * (size_t)a->num_triangles;
    if (a->num_vertices != b->num_vertices || a->num_triangles != b->num_triangles || a->num_uvs != b->num_uvs ||
        a->num_faces != b->num_faces || !a->corner_uv != !b->corner_uv || !a->uvs != !b->uvs ||
        !a->triangle_line != !b->triangle_line || !a->triangle_face != !b->triangle_face)
        return 0;
    return !memcmp(a->positions, b->positions, 3 * sizeof(double) * a->num_vertices) &&
           !memcmp(a->triangles, b->triangles, sizeof(uint32_t) * nt) &&
           (!a->corner_uv || !memcmp(a->corner_uv, b->corner_uv, sizeof(uint32_t) * nt)) &&
           (!a->uvs || !memcmp(a->uvs, b->uvs, 2 * sizeof(double) * a->num_uvs)) &&
           (!a->triangle_line || !memcmp(a->triangle_line, b->triangle_line, sizeof(uint32_t) * a->num_triangles)) &&
           (!a->triangle_face || !memcmp(a->triangle_face, b->triangle_face, sizeof(uint32_t) * a->num_triangles));
}

/* 1 when the chunked reader agrees with the serial one on this text. */
static int chunked_agrees(const char *text, size_t len, long *errors)
{
    static const bp_parallel_for_fn runner[] = { bpt_backwards_for, bpt_odd_even_for, NULL, NULL };
    bp_mesh ms, mp;
    bp_error es, ep;
    bp_status ss, sp;
    bp_allocator a = counting();
    int r, ok = 1;
    ss = bp_parse_obj(text, len, &ms, &a, &es);
    if (ss != BP_OK) (*errors)++;
    for (r = 0; r < 4; r++) {
        bp_options opt;
        memset(&opt, 0, sizeof opt);
        opt.allocator = a;
        opt.parallel_for = runner[r];
        opt.threads = r == 2 ? 2 : 3;
        memset(&ep, 0, sizeof ep);
        sp = bp__parse_text(text, len, &mp, &a, &ep, BP__FORMAT_OBJ, &opt);
        if (sp != ss || (ss == BP_OK && !same_mesh(&ms, &mp)) ||
            (ss != BP_OK && (ep.line != es.line || ep.element != es.element || ep.index != es.index ||
                             strcmp(ep.message, es.message) || !mesh_all_null(&mp))))
            ok = 0;
        if (sp == BP_OK) bp_mesh_free(&mp, &a);
    }
    if (ss == BP_OK) bp_mesh_free(&ms, &a);
    return ok;
}

static void test_read_chunked(void)
{
    /* relative indices, vt on some faces, CRLF and a lone CR, no final
       line ending, a polygon of 70 corners (more than a task has room for:
       its chunk is read by the caller), errors early and late */
    static const char *const texts[] = {
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf -4 -2 -1\nf 1 2 3 4",
        "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\rv 0 1 0\r\n# c\r\nf 1 2 3 # x\r\n\r\nf 1 3 4\r\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 9\nv 5 5 5\nf 1 2 x\n",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nv 1 2\nf 1 2\n",
        "v 0 0 0\nv 1 0 0\nf -3 1 2\n",
    };
    char big[4096];
    size_t k, n = 0;
    long i, errors = 0, bad = 0, total = 0;
    int c;
    counter_reset();
    for (k = 0; k < sizeof texts / sizeof *texts; k++, total++)
        bad += !chunked_agrees(texts[k], strlen(texts[k]), &errors);
    for (c = 0; c < 70; c++) n += (size_t)sprintf(big + n, "v %d %d 0\n", c, c * c % 7);
    n += (size_t)sprintf(big + n, "f");
    for (c = 0; c < 70; c++) n += (size_t)sprintf(big + n, " %d", c + 1);
    n += (size_t)sprintf(big + n, "\nf 1 2 3\n");
    bad += !chunked_agrees(big, n, &errors);
    total++;
    for (i = 0; i < FUZZ_ROUNDS / 4; i++, total++) {     /* mutations, as test_fuzz */
        char buf[1024];
        size_t len = mutated_asset(buf, sizeof buf);
        bad += !chunked_agrees(buf, len, &errors);
    }
    BPT_CHECK(bad == 0 && errors > 0 && errors < total && counter_balanced(),
              "%ld OBJ texts through the chunked reader (backwards, odd-even, 2 and 3 threads): the serial parser's mesh "
              "bit for bit or its error (status, line, message), nothing leaked (%ld with errors, %ld differ)",
              total, errors, bad);
}

/* The chunked reader and the writers on a runner: failing each of their
   allocations gives BP_ERR_OUT_OF_MEMORY, nothing left (no mesh, no file,
   no block). */
static void test_par_alloc_failures(void)
{
    char dir[] = "/tmp/bptest_pa_XXXXXX", src[256], out[256];
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_allocator a = counting(), saved;
    long n, total, bad = 0, oom = 0;
    int w;
    memset(&opt, 0, sizeof opt);
    opt.parallel_for = bpt_backwards_for;
    opt.allocator = a;
    counter_reset();
    bp__parse_text(asset_obj, sizeof asset_obj - 1, &m, &a, &err, BP__FORMAT_OBJ, &opt);
    total = the_counter.calls;
    bp_mesh_free(&m, &a);
    for (n = 1; n <= total; n++) {
        bp_status st;
        counter_reset();
        the_counter.fail_at = n;
        st = bp__parse_text(asset_obj, sizeof asset_obj - 1, &m, &a, &err, BP__FORMAT_OBJ, &opt);
        if (st == BP_OK) bp_mesh_free(&m, &a);
        else if (st != BP_ERR_OUT_OF_MEMORY || !mesh_all_null(&m)) bad++;
        else oom++;
        if (!counter_balanced()) bad++;
    }
    BPT_CHECK(total > 0 && bad == 0 && oom == total,
              "chunked reader: failing each of its %ld allocations gives BP_ERR_OUT_OF_MEMORY, no mesh, no leak (%ld bad)",
              total, bad);
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    sprintf(src, "%s/m.obj", dir);
    sprintf(out, "%s/m_uv.obj", dir);
    write_bytes(src, asset_obj, sizeof asset_obj - 1);
    opt.allocator.alloc = NULL;
    opt.allocator.free = NULL;
    opt.threads = 1;
    if (bp_parse_obj(asset_obj, sizeof asset_obj - 1, &m, NULL, &err) != BP_OK ||
        bp_parameterize(&atlas, &m, &opt, &err) != BP_OK) {
        BPT_CHECK(0, "asset: %s", err.message);
        rmdir(dir);
        return;
    }
    saved = atlas.allocator;
    atlas.allocator = a;                       /* the writers allocate with the atlas's */
    for (w = 0; w < 2; w++) {
        counter_reset();
        bp_write_obj_opt(out, w ? src : NULL, &m, &atlas, &opt, &err);
        total = the_counter.calls;
        remove(out);
        bad = oom = 0;
        for (n = 1; n <= total; n++) {
            bp_status st;
            counter_reset();
            the_counter.fail_at = n;
            st = bp_write_obj_opt(out, w ? src : NULL, &m, &atlas, &opt, &err);
            if (st != BP_ERR_OUT_OF_MEMORY || file_exists(out)) bad++;
            else oom++;
            if (!counter_balanced()) bad++;
            remove(out);
        }
        BPT_CHECK(total > 2 && bad == 0,
                  "%s on a runner: failing each of its %ld allocations gives BP_ERR_OUT_OF_MEMORY, no file, no leak (%ld bad)",
                  w ? "bp_write_obj_from" : "bp_write_obj", total, bad);
    }
    atlas.allocator = saved;
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    remove(src);
    rmdir(dir);
}

/* A UTF-8 byte order mark (EF BB BF) before the first line: the OBJ and
   OFF readers read the file as if it were not there -- the same mesh, by
   the serial and the chunked reader, errors on the same line numbers --
   and bp_write_obj_from gives it back first, the rest as without it. */
static void test_bom(void)
{
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\nf 1 3 4\n";
    static const char bad[] = "v 0 0 0\nv 1 0 0\nf 1 2 5\n";
    static const char off[] = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    char buf[256], dir[] = "/tmp/bptest_bom_XXXXXX", src[96], src_bom[96], out[96], out_bom[96];
    bp_mesh m0, m1;
    bp_error e0, e1;
    bp_status s0, s1;
    long errors = 0;
    size_t n0 = 0, n1 = 0;
    char *o0 = NULL, *o1 = NULL;
    memcpy(buf, "\xEF\xBB\xBF", 3);
    memcpy(buf + 3, obj, sizeof obj - 1);
    s0 = parse(OBJ, obj, sizeof obj - 1, &m0, NULL, &e0);
    s1 = parse(OBJ, buf, 3 + sizeof obj - 1, &m1, NULL, &e1);
    BPT_CHECK(s0 == BP_OK && s1 == BP_OK && same_mesh(&m0, &m1) && m1.num_vertices == 4,
              "OBJ after a byte order mark: the same mesh (%u vertices, %u triangles; %s)", m1.num_vertices,
              m1.num_triangles, e1.message);
    if (s0 == BP_OK) bp_mesh_free(&m0, NULL);
    if (s1 == BP_OK) bp_mesh_free(&m1, NULL);
    BPT_CHECK(chunked_agrees(buf, 3 + sizeof obj - 1, &errors) && errors == 0,
              "... the chunked reader on 2 and 3 threads agrees with the serial one");
    memcpy(buf + 3, bad, sizeof bad - 1);
    s0 = parse(OBJ, bad, sizeof bad - 1, &m0, NULL, &e0);
    s1 = parse(OBJ, buf, 3 + sizeof bad - 1, &m1, NULL, &e1);
    BPT_CHECK(s0 == BP_ERR_INDEX && s1 == s0 && e1.line == 3 && e0.line == 3 && !strcmp(e0.message, e1.message),
              "... an error names the same line after the mark (line %ld: %s)", (long)e1.line, e1.message);
    memcpy(buf + 3, off, sizeof off - 1);
    s0 = parse(OFF, off, sizeof off - 1, &m0, NULL, &e0);
    s1 = parse(OFF, buf, 3 + sizeof off - 1, &m1, NULL, &e1);
    BPT_CHECK(s0 == BP_OK && s1 == BP_OK && same_mesh(&m0, &m1) && m1.num_triangles == 2,
              "OFF after a byte order mark: the same mesh (%s)", e1.message);
    if (s0 == BP_OK) bp_mesh_free(&m0, NULL);
    if (s1 == BP_OK) bp_mesh_free(&m1, NULL);
    /* the writer: the mark first, then what it writes without it */
    if (!BPT_CHECK(mkdtemp(dir) != NULL, "a temporary directory")) return;
    snprintf(src, sizeof src, "%s/a.obj", dir);
    snprintf(src_bom, sizeof src_bom, "%s/b.obj", dir);
    snprintf(out, sizeof out, "%s/a_out.obj", dir);
    snprintf(out_bom, sizeof out_bom, "%s/b_out.obj", dir);
    memcpy(buf + 3, obj, sizeof obj - 1);
    if (write_bytes(src, obj, sizeof obj - 1) && write_bytes(src_bom, buf, 3 + sizeof obj - 1) &&
        bp_read_mesh(src_bom, &m1, NULL, &e1) == BP_OK) {
        bp_atlas at;
        if (bp_parameterize(&at, &m1, NULL, &e1) == BP_OK) {
            s0 = bp_write_obj_from(out, src, &m1, &at, &e0);
            s1 = bp_write_obj_from(out_bom, src_bom, &m1, &at, &e1);
            o0 = read_bytes(out, &n0);
            o1 = read_bytes(out_bom, &n1);
            bp_atlas_free(&at);
        }
        bp_mesh_free(&m1, NULL);
    }
    BPT_CHECK(o0 && o1 && s0 == BP_OK && s1 == BP_OK && n1 == n0 + 3 && !memcmp(o1, "\xEF\xBB\xBF", 3) &&
                  !memcmp(o1 + 3, o0, n0),
              "bp_write_obj_from on a source with the mark: the mark, then the bytes it writes without it (%zu and %zu "
              "bytes)", n1, n0);
    free(o0);
    free(o1);
    remove(src); remove(src_bom); remove(out); remove(out_bom);
    rmdir(dir);
}

/* Mutations of the asset as the source of bp_write_obj_from, with the mesh
   and atlas of the original: the writer must never crash or leak, must
   leave no file when it fails, and must succeed whenever the mutated text
   still reads to the same triangles and faces (then it is the file the mesh
   could have been read from). */
static void test_write_from_fuzz(void)
{
    char dir[] = "/tmp/bptest_wz_XXXXXX", src[256], out[256], buf[2048];
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_allocator a = counting(), saved;
    long i, ok = 0, refused = 0, bad = 0, par_bad = 0;
    size_t n1 = 0, n2 = 0;
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    sprintf(src, "%s/m.obj", dir);
    sprintf(out, "%s/m_uv.obj", dir);
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    if (bp_parse_obj(asset_obj, sizeof asset_obj - 1, &m, NULL, &err) != BP_OK ||
        bp_parameterize(&atlas, &m, &opt, &err) != BP_OK) {
        BPT_CHECK(0, "asset for the writer fuzz: %s", err.message);
        rmdir(dir);
        return;
    }
    counter_reset();
    saved = atlas.allocator;
    atlas.allocator = a;              /* the writer's tables through the counter */
    for (i = 0; i < FUZZ_ROUNDS / 4; i++) {
        size_t len = mutated_asset(buf, sizeof buf);
        int same;
        bp_mesh mm;
        bp_status st, pst;
        write_bytes(src, buf, len);
        pst = bp_parse_obj(buf, len, &mm, NULL, &err);
        same = pst == BP_OK && mm.num_triangles == m.num_triangles && mm.num_faces == m.num_faces &&
               !memcmp(mm.triangles, m.triangles, 3 * sizeof(uint32_t) * m.num_triangles) &&
               !memcmp(mm.triangle_face, m.triangle_face, sizeof(uint32_t) * m.num_triangles);
        if (pst == BP_OK) bp_mesh_free(&mm, NULL);
        st = bp_write_obj_from(out, src, &m, &atlas, &err);
        if (st == BP_OK) ok++;
        else refused++;
        if ((st != BP_OK && (file_exists(out) || !err.message[0])) || (same && st != BP_OK)) bad++;
        {   /* the chunked rewrite (tasks backwards or odd-even): the same bytes or the same error */
            bp_options po;
            bp_error perr;
            bp_status pst2;
            char *t1 = st == BP_OK ? read_bytes(out, &n1) : NULL, *t2;
            memset(&po, 0, sizeof po);
            po.allocator = a;
            po.parallel_for = i % 2 ? bpt_backwards_for : bpt_odd_even_for;
            remove(out);
            pst2 = bp_write_obj_opt(out, src, &m, &atlas, &po, &perr);
            t2 = pst2 == BP_OK ? read_bytes(out, &n2) : NULL;
            if (pst2 != st || (st == BP_OK && (!t1 || !t2 || n1 != n2 || memcmp(t1, t2, n1))) ||
                (st != BP_OK && (perr.line != err.line || strcmp(perr.message, err.message) || file_exists(out))))
                par_bad++;
            free(t1);
            free(t2);
        }
        remove(out);
    }
    BPT_CHECK(bad == 0 && counter_balanced() && ok > 0 && refused > 0,
              "%d mutated sources through bp_write_obj_from: no crash, no leak, no file left on failure, success whenever the text reads to the same faces (%ld written, %ld refused, %ld bad)",
              FUZZ_ROUNDS / 4, ok, refused, bad);
    BPT_CHECK(par_bad == 0 && counter_balanced(),
              "the same %d sources through the chunked rewrite (chunks of ~9 bytes, tasks backwards and odd-even): "
              "the serial writer's bytes or its error (line, message), no leak (%ld differ)", FUZZ_ROUNDS / 4, par_bad);
    atlas.allocator = saved;
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
    remove(src);
    rmdir(dir);
}

/* ---- the writers on several threads ---------------------------------------

   The v and vt lines are formatted in tasks (bijparam.h, "the output goes
   through a buffer"): whoever runs the tasks and in whatever order, the
   file must be the same bytes, and its v / vt lines exactly those of one
   loop of fprintf "%.17g" over the positions and the charts' uv, written
   here independently. */

/* The reference lines, "v ..." or "vt ...", one per element, joined. */
static char *reference_lines(const char *kw, const double *x, uint32_t n, int dim, const char *eol, size_t *len)
{
    char *out = (char *)malloc((size_t)n * 96 + 1), *p = out;
    uint32_t i;
    if (!out) return NULL;
    for (i = 0; i < n; i++) {
        p += sprintf(p, "%s %.17g %.17g", kw, x[dim * (size_t)i], x[dim * (size_t)i + 1]);
        if (dim == 3) p += sprintf(p, " %.17g", x[3 * (size_t)i + 2]);
        p += sprintf(p, "%s", eol);
    }
    *len = (size_t)(p - out);
    return out;
}

/* All vt lines of a chart list, in chart order. */
static char *reference_vt(const bp_atlas *atlas, const char *eol, size_t *len)
{
    size_t total = 0, n, k = 0;
    uint32_t c;
    char *all, *part;
    for (c = 0; c < atlas->num_charts; c++) total += atlas->charts[c].uv ? atlas->charts[c].num_vertices : 0;
    all = (char *)malloc(total * 96 + 1);
    for (c = 0; all && c < atlas->num_charts; c++) {
        if (!atlas->charts[c].uv) continue;
        part = reference_lines("vt", atlas->charts[c].uv, atlas->charts[c].num_vertices, 2, eol, &n);
        if (!part) { free(all); return NULL; }
        memcpy(all + k, part, n);
        k += n;
        free(part);
    }
    *len = k;
    return all;
}

static int contains(const char *hay, size_t n, const char *needle, size_t m)
{
    size_t i;
    for (i = 0; i + m <= n; i++)
        if (!memcmp(hay + i, needle, m)) return 1;
    return m == 0;
}

static void test_write_threads_one(const char *path, const char *dir)
{
    static const char *const how[] = { "1 thread", "2 threads", "3 threads", "backwards", "odd-even" };
    char out[256], what[300];
    bp_mesh m;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_status st;
    int w, r, same[2] = { 1, 1 }, wrote[2] = { 1, 1 };
    char *first[2] = { NULL, NULL };
    size_t first_n[2] = { 0, 0 };
    memset(&opt, 0, sizeof opt);
    opt.threads = 1;
    opt.init_only = 1;
    if (bp_read_mesh(path, &m, NULL, &err) != BP_OK || bp_parameterize(&atlas, &m, &opt, &err) != BP_OK) {
        BPT_CHECK(0, "%s: read and mapped (%s)", path, err.message);
        return;
    }
    sprintf(out, "%s/threads.obj", dir);
    for (r = 0; r < 5; r++) {
        memset(&opt, 0, sizeof opt);
        opt.threads = r < 3 ? r + 1 : 1;
        if (r == 3) opt.parallel_for = bpt_backwards_for;
        if (r == 4) opt.parallel_for = bpt_odd_even_for;
        for (w = 0; w < 2; w++) {             /* bp_write_obj, bp_write_obj_from */
            size_t n;
            char *text;
            st = bp_write_obj_opt(out, w ? path : NULL, &m, &atlas, &opt, &err);
            text = st == BP_OK ? read_bytes(out, &n) : NULL;
            if (!text) { wrote[w] = 0; continue; }
            if (!r) { first[w] = text; first_n[w] = n; continue; }
            if (n != first_n[w] || memcmp(text, first[w], n)) {
                same[w] = 0;
                fprintf(stderr, "  %s: %s differs from 1 thread\n", w ? "bp_write_obj_from" : "bp_write_obj", how[r]);
            }
            free(text);
        }
    }
    for (w = 0; w < 2; w++) {
        sprintf(what, "%s, %s", path, w ? "bp_write_obj_from" : "bp_write_obj");
        BPT_CHECK(wrote[w] && same[w], "%s: the same bytes with 1, 2, 3 threads and the tasks run backwards and odd-even", what);
    }
    if (first[0] && first[1]) {
        size_t nv, nvt;
        char *v = reference_lines("v", m.positions, m.num_vertices, 3, "\n", &nv);
        char *vt = reference_vt(&atlas, "\n", &nvt);
        BPT_CHECK(v && vt && contains(first[0], first_n[0], v, nv) && contains(first[0], first_n[0], vt, nvt),
                  "%s, bp_write_obj: its v block and its vt block are fprintf's %%.17g of the positions and the uv, in order", path);
        BPT_CHECK(vt && contains(first[1], first_n[1], vt, nvt),
                  "%s, bp_write_obj_from: its vt block is fprintf's %%.17g of the charts' uv, in order", path);
        free(v);
        free(vt);
    }
    free(first[0]);
    free(first[1]);
    remove(out);
    bp_atlas_free(&atlas);
    bp_mesh_free(&m, NULL);
}

static void test_write_threads(void)
{
    char dir[] = "/tmp/bptest_wt_XXXXXX";
    if (!mkdtemp(dir)) { BPT_CHECK(0, "mkdtemp"); return; }
    test_write_threads_one("tests/data/spot.obj", dir);
    test_write_threads_one("tests/data/camel_b.obj", dir);
    {   /* a line longer than a task's slice (a comment of 1500 bytes) and a
           face of 200 corners (more than a task has room for) after the
           first face: the caller rewrites those chunks itself */
        char path[256];
        FILE *f;
        int i;
        sprintf(path, "%s/long.obj", dir);
        f = fopen(path, "wb");
        if (f) {
            for (i = 0; i < 200; i++) fprintf(f, "v %.17g %.17g %.17g\n", cos(i * 0.0314159), sin(i * 0.0314159), 0.01 * (i % 3));
            fprintf(f, "v 3 0 0\nv 4 0 0\nv 3 1 0\nf 201 202 203\n# ");
            for (i = 0; i < 1500; i++) fputc('x', f);
            fprintf(f, "\nf");
            for (i = 0; i < 200; i++) fprintf(f, " %d", i + 1);
            fprintf(f, "\ng end\n");
            fclose(f);
            test_write_threads_one(path, dir);
            remove(path);
        }
    }
    rmdir(dir);
}

int main(void)
{
    test_write_threads();
    test_read_chunked();
    test_par_alloc_failures();
    test_obj_ok();
    test_decimal_fast();
    test_fmt_g17();
    test_rewrite_head();
    test_bom();
    test_obj_errors();
    test_off();
    test_alloc_failures();
    test_files();
    test_write_from();
    test_write_from_split();
    test_write_fan_cut();
    test_fuzz();
    test_write_from_fuzz();
    return bpt_finish();
}
