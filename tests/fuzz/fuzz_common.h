/* fuzz_common.h - shared by the fuzz harnesses (tests/fuzz/fuzz_*.c).

   Each harness is one translation unit that defines BP_IMPLEMENTATION and
   LLVMFuzzerTestOneInput.  It is linked either with libFuzzer (clang
   -fsanitize=fuzzer,address,undefined: `make fuzz`) or with
   standalone_main.c (any C compiler, -fsanitize=address,undefined), which
   feeds corpus files and deterministic mutations of them.

   A property violation calls fuzz_fail(), which prints what was violated
   and aborts, so libFuzzer saves the input as a crash-* file. */
#ifndef BP_FUZZ_COMMON_H
#define BP_FUZZ_COMMON_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#define fuzz_fail(...) do { fprintf(stderr, "fuzz property violated (%s:%d): ", __FILE__, __LINE__); \
                            fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); abort(); } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The input copied into an exact-size heap block (no NUL terminator): a
   read past `size` is caught by AddressSanitizer. */
static inline char *fuzz_copy(const uint8_t *data, size_t size)
{
    char *p = (char *)malloc(size ? size : 1);
    if (!p) abort();
    if (size) memcpy(p, data, size);
    return p;
}

static inline int fuzz_mesh_all_null(const bp_mesh *m)
{
    return !m->positions && !m->triangles && !m->corner_uv && !m->uvs && !m->triangle_line && !m->triangle_face &&
           !m->num_vertices && !m->num_triangles && !m->num_uvs;
}

/* What a parser that returned BP_OK must have produced. */
static inline void fuzz_check_mesh(const bp_mesh *m)
{
    uint32_t i;
    if (!m->num_triangles || !m->triangles || !m->num_vertices || !m->positions)
        fuzz_fail("BP_OK with an empty mesh (%u vertices, %u triangles)", m->num_vertices, m->num_triangles);
    for (i = 0; i < 3 * m->num_vertices; i++)
        if (!isfinite(m->positions[i])) fuzz_fail("BP_OK with a non-finite coordinate at %u", i);
    for (i = 0; i < 3 * m->num_triangles; i++)
        if (m->triangles[i] >= m->num_vertices) fuzz_fail("BP_OK with vertex index %u >= %u", m->triangles[i], m->num_vertices);
    if (m->corner_uv) {
        if (!m->uvs || !m->num_uvs) fuzz_fail("corner_uv without uvs");
        for (i = 0; i < 3 * m->num_triangles; i++)
            if (m->corner_uv[i] >= m->num_uvs) fuzz_fail("uv index %u >= %u", m->corner_uv[i], m->num_uvs);
        for (i = 0; i < 2 * m->num_uvs; i++)
            if (!isfinite(m->uvs[i])) fuzz_fail("non-finite uv at %u", i);
    }
    if (m->triangle_line)
        for (i = 1; i < m->num_triangles; i++)
            if (m->triangle_line[i] < m->triangle_line[i - 1] || m->triangle_line[i] == 0)
                fuzz_fail("triangle_line not increasing at %u", i);
    if (m->triangle_face) {
        if (m->num_faces > m->num_triangles) fuzz_fail("more faces than triangles");
        for (i = 0; i < m->num_triangles; i++)
            if (m->triangle_face[i] >= m->num_faces || (i && m->triangle_face[i] < m->triangle_face[i - 1]))
                fuzz_fail("triangle_face %u out of order", i);
    }
}

/* What a failing call must have reported. */
static inline void fuzz_check_error(bp_status st, const bp_error *err)
{
    if (st <= BP_OK || st >= BP_STATUS_COUNT) fuzz_fail("status %d out of range", (int)st);
    if (err->status != st) fuzz_fail("err.status %d != returned %d", (int)err->status, (int)st);
    if (!err->message[0] || !memchr(err->message, 0, sizeof err->message)) fuzz_fail("empty or unterminated message");
    if (err->element == BP_ELEMENT_LINE && (err->line <= 0 || err->index != err->line))
        fuzz_fail("line error without its line (%lld, %lld): %s", (long long)err->line, (long long)err->index, err->message);
}

static inline int fuzz_report_valid(const bp_check_report *r)
{
    return !r->flipped && !r->degenerate && !r->nonfinite && !r->boundary_intersections && !r->loop_orientation &&
           !r->nested;
}

/* The parser harnesses (fuzz_obj.c, fuzz_off.c): one input through `parse`,
   then the properties their comments list. */
typedef bp_status (*fuzz_parse_fn)(const char *, size_t, bp_mesh *, const bp_allocator *, bp_error *);

static inline int fuzz_parser(const uint8_t *data, size_t size, fuzz_parse_fn parse)
{
    char *text = fuzz_copy(data, size);
    bp_mesh m;
    bp_error err;
    bp_status st;
    memset(&m, 0xAB, sizeof m);
    st = parse(text, size, &m, NULL, &err);
    free(text);
    if (st == BP_OK) {
        bp_atlas at;
        fuzz_check_mesh(&m);
        st = bp_atlas_build(&at, &m, NULL, &err);
        if (st != BP_OK && st != BP_ERR_CHARTS_FAILED) {
            fuzz_check_error(st, &err);
            if (at.charts || at.num_charts) fuzz_fail("failed bp_atlas_build left charts");
        }
        bp_atlas_free(&at);
        bp_mesh_free(&m, NULL);
    } else {
        fuzz_check_error(st, &err);
        if (!fuzz_mesh_all_null(&m)) fuzz_fail("failed parse left the mesh non-zero");
    }
    return 0;
}

#endif
