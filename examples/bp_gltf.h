/* bp_gltf.h - glTF 2.0 (.gltf, .glb) in and out of bijparam.h - MIT license,
   same as bijparam.h

   A companion of bijparam.h, as bp_draw.h is: the tool reads and writes
   glTF through it, and any program can.  It reads every triangle primitive
   of every mesh of a .gltf (JSON with external .bin files or data: URIs)
   or .glb (binary chunks) into one bp_mesh, and writes the file back with
   a new TEXCOORD_n from a bp_atlas, keeping everything else.

   Reading
     - Triangle primitives: mode 4 (TRIANGLES, the default), and 5
       (TRIANGLE_STRIP) and 6 (TRIANGLE_FAN), which are turned into
       triangles (a strip's degenerate joining triangles are dropped) and
       written back as mode 4.  Points and lines stay as they are.
     - POSITION and indices of any component type (unsigned byte, short,
       int; normalized or plain integer positions of KHR_mesh_quantization),
       or no indices; byteStride, byteOffset, sparse accessors, accessors
       shared between primitives, buffers in the GLB's BIN chunk, in data:
       URIs (base64) or in files next to the .gltf (percent-encoded
       relative paths).
     - Vertices: a glTF vertex is an element of its accessors, and
       exporters split a vertex wherever any attribute differs (a hard
       normal edge, a texture seam), so the mesh would fall apart into as
       many pieces as the normals have creases.  The vertices of one
       primitive (and of the primitives sharing its attribute accessors)
       at the same position are welded into one bp_mesh vertex, and
       when the primitive has TEXCOORD_n, the corners at the same position
       with the same texture coordinates share one uv index: seams cut
       exactly where the file's texture coordinates differ, and a crease
       of the normals alone cuts nothing.  Primitives with different
       vertex accessors are never welded together.  Node transforms do not
       matter: texture coordinates belong to the primitive, and one mesh
       used by several nodes has one set of them.
     - v runs downward in glTF: the mesh's uvs are (u, 1 - v), the
       convention of OBJ and of the library, and the writer turns them back.
     - The mesh's triangles are the primitives' triangles, meshes and
       primitives in file order; bpg_name_triangle / bpg_name_vertex name
       a bp_mesh element as the file numbers it (mesh, primitive, triangle,
       accessor and vertex, from 0 as glTF counts).
   Writing
     - Every vertex of a written primitive is split where the new seams
       cut it, and every vertex attribute (NORMAL, TANGENT, COLOR_n,
       JOINTS_n, WEIGHTS_n, the other TEXCOORD_n, application-specific
       ones) and every morph target's attributes are duplicated with it.
       Vertex k of the input stays vertex k (its bytes unchanged); the
       copies follow, so a vertex that no seam cuts keeps its index.
     - The new attribute and index accessors, their bufferViews and their
       data are appended; primitives that shared their accessors (one
       mesh drawn twice, as instancing files do) share the new ones, the
       index accessor too when their triangles are the same.  The
       accessors the written primitives used before, which nothing else
       references, go with their bufferViews and, in a .glb, their bytes
       ("what the rewrite leaves unused" below); every other accessor and
       bufferView keeps its JSON and its bytes, renumbered where one before
       it went.  Nodes, materials, textures, images, skins, animations,
       cameras, extras, extensions and the non-triangle primitives stay as
       they were.  The JSON is the input's text with the few values that
       must change replaced in place: key order, spacing, number and
       string text come back byte for byte.
     - Where the new bytes go: a .glb appends them to its BIN chunk
       (buffer 0); a .gltf to a new buffer, in a data: URI or in a .bin
       file of its own (bpg_write_options.bin_uri).  A .glb input written
       as .gltf moves its BIN chunk there too.
     - A primitive whose repaired orientation differs from the file's
       (bp_atlas.repairs, BP_REPAIR_FLIPPED) is written with those
       triangles' corners in the repaired order (corner 0, then the other
       two swapped), as the OBJ writers do, so every triangle agrees with
       its uvs.  Triangles of a chart that failed keep the input's
       TEXCOORD_n values (0, 0 without them).
     - The map is written as 32-bit floats.  Rounding a double map to
       float can flip a sliver; the writer checks the rounded map exactly
       (bp_check over all charts) and moves a corner of a flipped triangle
       by a few floats where that repairs it (bpg_output.rounding_fixed);
       if any triangle stays invalid, writing fails naming it.
   Failures
     Every error is a bp_status with one message naming the element as
     the file numbers it: "accessor 5 (POSITION of mesh 0 primitive 1)",
     "bufferView 2", "buffer 1 ('model.bin')", "mesh 3 primitive 0", or
     a JSON byte offset (and line, for .gltf): out-of-range offsets,
     lengths, strides, counts and indices, bad base64, bad JSON, a
     truncated GLB, chunk lengths that lie, sizes that overflow.
     BP_ERR_PARSE for a malformed file, BP_ERR_INDEX for an index out of
     range, BP_ERR_IO for a file that cannot be read or written,
     BP_ERR_TOO_LARGE beyond the library's limits, BP_ERR_EMPTY when no
     primitive has triangles, BP_ERR_INVALID_ARGUMENT for what this reader
     does not decode (KHR_draco_mesh_compression, EXT_meshopt_compression).

   Use: include bijparam.h first, then this file; in exactly one C or C++
   file define BPG_IMPLEMENTATION before including it (the library's
   implementation may be in another file):

       bpg_file g;  bp_atlas atlas;  bp_error err;  bp_options opt;
       bp_options_init(&opt);  opt.atlas_resolution = 1024;
       if (bpg_read(&g, "in.glb", NULL, &err) == BP_OK &&
           bp_parameterize(&atlas, &g.mesh, &opt, &err) == BP_OK)
           bpg_write(&g, &atlas, "out.glb", NULL, NULL, &err);

   C99 that also compiles as C++, the C library only, no global state,
   every allocation through the bp_allocator given (NULL: malloc / free),
   nothing printed, no exit. */
#ifndef BP_GLTF_H
#define BP_GLTF_H

#include "bijparam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reading options; zero means the default. */
typedef struct bpg_options {
    bp_allocator allocator;   /* zero: malloc / free                        */
    int          texcoord;    /* n of the TEXCOORD_n read for seams and
                                 written (0: TEXCOORD_0).  Writing n > 0
                                 needs TEXCOORD_0 .. TEXCOORD_(n-1) on every
                                 triangle primitive (glTF numbers the sets
                                 without gaps)                              */
} bpg_options;

/* A glTF file read: the mesh for the library, and what the writer needs. */
typedef struct bpg_file {
    bp_mesh  mesh;            /* every triangle of every triangle primitive
                                 (read only; freed by bpg_free)             */
    uint32_t num_meshes;      /* meshes in the file                         */
    uint32_t num_primitives;  /* triangle primitives read                   */
    uint32_t num_skipped;     /* primitives left as they are (points, lines) */
    uint32_t num_groups;      /* sets of primitives sharing their vertex
                                 accessors (each one vertex set)            */
    int      glb;             /* 1: read from a .glb, 0: from JSON          */
    uint32_t num_buffer_files;/* buffers whose uri names a file             */
    int      has_uv;          /* 1: every triangle primitive has TEXCOORD_n  */
    struct bpg__file *p;      /* the rest, the implementation's own         */
} bpg_file;

/* Writing options; zero means the default. */
typedef struct bpg_write_options {
    int         glb;          /* 1: write a .glb, 0: a .gltf (bpg_write:
                                 -1 there means "by the path's extension")  */
    const char *bin_uri;      /* .gltf: the new bytes (and a .glb input's BIN
                                 chunk) go into bpg_output.bin, referenced
                                 by this uri (bpg_write: written to
                                 bin_path); NULL: a data: URI in the JSON    */
    const char *uri_prefix;   /* prepended to every relative uri of the
                                 input (buffers and images) when the output
                                 is written in another folder, e.g.
                                 "../models/"; percent-encoded here.  NULL:
                                 the uris are kept as they are             */
    const bp_options *check;  /* the exact check of the rounded map runs on
                                 check->threads (NULL: the caller's thread)  */
} bpg_write_options;

/* The encoded result (bpg_encode). */
typedef struct bpg_output {
    unsigned char *data;      /* the .glb, or the .gltf's JSON              */
    size_t         size;
    unsigned char *bin;       /* with bin_uri: the .bin file's bytes        */
    size_t         bin_size;
    uint32_t       vertices_in, vertices_out; /* vertices of the written
                                 primitives before and after the split      */
    uint32_t       rounding_fixed; /* corners moved by a few floats to keep
                                 the rounded map bijective                 */
    uint32_t       accessors_removed, views_removed; /* the input's, left
                                 unreferenced by the rewrite (the essay)   */
    size_t         bytes_removed; /* of a .glb's BIN chunk, with them      */
    bp_allocator   allocator;
} bpg_output;

/* Read a .gltf or .glb (told apart by the GLB magic, not the name);
   external files are read from the folder of `path`.  On failure `file`
   is zeroed (bpg_free is harmless). */
BPDEF bp_status bpg_read(bpg_file *file, const char *path, const bpg_options *opt, bp_error *err);
/* The same from bytes in memory; `dir` is the folder of external files
   ("" for the current one), NULL to refuse them.  `data` is copied. */
BPDEF bp_status bpg_parse(bpg_file *file, const void *data, size_t size, const char *dir,
                          const bpg_options *opt, bp_error *err);
BPDEF void      bpg_free(bpg_file *file);

/* The file with the atlas's map as TEXCOORD_n (see the essay above): the
   atlas must have been built on file->mesh.  On failure `out` is zeroed.
   One call at a time per file (it reports through the file's state);
   different files may be encoded on different threads. */
BPDEF bp_status bpg_encode(const bpg_file *file, const bp_atlas *atlas, const bpg_write_options *wo,
                           bpg_output *out, bp_error *err);
BPDEF void      bpg_output_free(bpg_output *out);
/* bpg_encode, then `path` (and `bin_path` with wo->bin_uri) written; on an
   error nothing written stays behind.  wo NULL: the format by the
   extension of path, new bytes in a data: URI for a .gltf. */
BPDEF bp_status bpg_write(const bpg_file *file, const bp_atlas *atlas, const char *path, const char *bin_path,
                          const bpg_write_options *wo, bp_error *err);

/* "mesh 1 ('Body') primitive 0 triangle 17 (vertices 4 5 9)" for mesh
   triangle t, "accessor 3 vertex 12 (mesh 1 primitive 0)" for mesh vertex v
   (one of the glTF vertices welded into it); "" when out of range. */
BPDEF void bpg_name_triangle(const bpg_file *file, uint32_t t, char *buf, size_t size);
BPDEF void bpg_name_vertex(const bpg_file *file, uint32_t v, char *buf, size_t size);
/* The external files the input reads (buffers and images, resolved
   against its folder) one by one: i from 0 until NULL. */
BPDEF const char *bpg_external_file(const bpg_file *file, uint32_t i);
/* 1 when the path ends in .gltf or .glb (any case). */
BPDEF int bpg_is_gltf_path(const char *path);

#ifdef __cplusplus
}
#endif
#endif /* BP_GLTF_H */

/* ==========================================================================
   IMPLEMENTATION
   ========================================================================== */
#if defined(BPG_IMPLEMENTATION) && !defined(BPG__IMPLEMENTATION_DONE)
#define BPG__IMPLEMENTATION_DONE

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BPG__NONE 0xffffffffu
/* JSON nesting deeper than this is refused (the parser recurses once per
   level; glTF's own objects nest six deep, extras may go further). */
#define BPG__MAX_DEPTH 512
/* Integers in the JSON (offsets, lengths, counts, indices) up to 2^53, so
   that any sum of two or products with a stride stays within uint64. */
#define BPG__MAX_INT 9007199254740992.0

/* ---- memory and errors ---------------------------------------------------

   Every allocation goes through the file's allocator (malloc / free when
   the caller gives none); sizes are multiplied only through bpg__alloc_n,
   which refuses a product that overflows size_t. */

typedef struct bpg__node {
    size_t   start, end;      /* the value's bytes [start, end) in the text   */
    size_t   key, key_end;    /* a member's key with its quotes; key == end
                                 of nothing (SIZE_MAX) for array elements     */
    uint32_t first, next;     /* first child, next sibling (BPG__NONE)        */
    uint32_t count;           /* children                                     */
    unsigned char type;       /* BPG__OBJECT ... BPG__NULL                    */
    unsigned char integer;    /* a number written without fraction/exponent  */
} bpg__node;

enum { BPG__OBJECT = 1, BPG__ARRAY, BPG__STRING, BPG__NUMBER, BPG__TRUE, BPG__FALSE, BPG__NULL };

typedef struct bpg__buffer {
    uint64_t             length;    /* byteLength                             */
    uint32_t             node;      /* its JSON object                        */
    uint32_t             uri;       /* its uri string, or BPG__NONE           */
    int                  kind;      /* 0 the GLB's BIN chunk, -1 a uri (or none) */
    int                  loaded;
    const unsigned char *data;      /* at least `length` bytes once loaded    */
    unsigned char       *owned;     /* what we allocated for it               */
    char                *path;      /* an external file: its path             */
} bpg__buffer;

/* An accessor as read: where element i is, and the sparse substitutions. */
typedef struct bpg__acc {
    uint32_t             index;
    uint32_t             count;
    int                  ctype, csize, ncomp, normalized;
    size_t               esize;     /* bytes of one element (matrix columns padded) */
    const unsigned char *base;      /* element 0, or NULL: zeros               */
    size_t               stride;
    uint32_t             scount;    /* sparse substitutions                   */
    const unsigned char *sidx, *sval;
    int                  sidx_size;
} bpg__acc;

typedef struct bpg__prim {
    uint32_t mesh, index;           /* meshes[mesh].primitives[index]          */
    uint32_t node, attributes, targets; /* JSON: the primitive, its attributes
                                       object, its targets array (or NONE)     */
    uint32_t group;
    uint32_t first, num;            /* its triangles in the bp_mesh            */
    int      mode;
    uint32_t indices;               /* accessor, or BPG__NONE                  */
    uint32_t position, texcoord;    /* accessors (texcoord: BPG__NONE)         */
} bpg__prim;

typedef struct bpg__group {
    uint32_t prim;                  /* its first primitive (the attributes)   */
    uint32_t count;                 /* glTF vertices                           */
    uint32_t vbase, vnum;           /* its bp_mesh vertices                    */
    uint32_t first, num;            /* its bp_mesh triangles (primitives in a
                                       group are not contiguous in the mesh:
                                       see prim_of / the group's list)         */
} bpg__group;

struct bpg__file {
    bp_allocator  a;
    bp_error     *err, scratch;
    char         *doc;              /* the JSON text (own copy)                */
    size_t        doc_len, doc_offset; /* its first byte in the file (GLB: 20) */
    int           glb;
    bpg__node    *node;
    uint32_t      num_nodes, cap_nodes;
    unsigned char *bin;             /* the GLB's BIN chunk, or NULL            */
    size_t        bin_size;
    int           has_bin;
    unsigned char *tail;            /* GLB chunks after the BIN one, verbatim  */
    size_t        tail_size;
    char         *dir;              /* folder of external files; NULL: refused */
    uint32_t      buffers, views, accessors, meshes, images; /* arrays or NONE */
    uint32_t      num_buffer_files;
    uint32_t      num_buffers, num_views, num_accessors, num_images;
    bpg__buffer  *buf;
    bpg__prim    *prim;
    uint32_t      num_prims;
    bpg__group   *group;
    uint32_t      num_groups;
    uint32_t     *tri_prim, *tri_num;   /* per mesh triangle: primitive, its
                                           triangle number there              */
    uint32_t     *corner_src;       /* per mesh corner: glTF vertex in its group */
    uint32_t     *vertex_src;       /* per mesh vertex: one glTF vertex welded in */
    uint32_t     *vertex_group;     /* per mesh vertex: its group             */
    char        **external;
    uint32_t      num_external, cap_external;
    unsigned char *raw;             /* the file's bytes (doc, bin, tail point in) */
    int           texcoord;
    int           depth;
};

static void *bpg__alloc(struct bpg__file *f, size_t n)
{
    if (n == 0) n = 1;
    return f->a.alloc ? f->a.alloc(f->a.user, n) : malloc(n);
}

static void bpg__free_p(const bp_allocator *a, void *p)
{
    if (!p) return;
    if (a->alloc) a->free(a->user, p); else free(p);
}

static void bpg__freef(struct bpg__file *f, void *p) { bpg__free_p(&f->a, p); }

static void *bpg__alloc_n(struct bpg__file *f, size_t n, size_t size)
{
    if (size && n > (size_t)-1 / size) return NULL;
    return bpg__alloc(f, n * size);
}

static void *bpg__calloc_n(struct bpg__file *f, size_t n, size_t size)
{
    void *p = bpg__alloc_n(f, n, size);
    if (p) memset(p, 0, n * size > 0 ? n * size : 1);
    return p;
}

/* A message into f->err (the first error wins: later ones are ignored). */
static bp_status bpg__fail(struct bpg__file *f, bp_status st, const char *fmt, ...)
{
    va_list ap;
    bp_error *e = f->err;
    if (e->status != BP_OK) return e->status;
    e->status = st;
    e->element = BP_ELEMENT_NONE;
    e->index = -1;
    e->index2 = -1;
    e->line = 0;
    va_start(ap, fmt);
    vsnprintf(e->message, sizeof e->message, fmt, ap);
    va_end(ap);
    return st;
}

static bp_status bpg__oom(struct bpg__file *f, const char *what)
{
    return bpg__fail(f, BP_ERR_OUT_OF_MEMORY, "out of memory %s", what);
}

/* Little-endian reads and writes (glTF's byte order, whatever the host's). */
static uint32_t bpg__le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void bpg__put32(unsigned char *p, uint32_t x)
{
    p[0] = (unsigned char)x; p[1] = (unsigned char)(x >> 8);
    p[2] = (unsigned char)(x >> 16); p[3] = (unsigned char)(x >> 24);
}

/* ---- JSON ------------------------------------------------------------------

   The writer must give back every byte it does not change, so the parser
   keeps no values, only where each one is: a node per value with its byte
   span, a member's key span, and links to its first child and its next
   sibling.  Values are read from the text when asked (bpg__get_int,
   bpg__str_eq, bpg__str_decode); the writer copies spans.  The grammar is
   RFC 8259's, strictly: a byte that breaks it is an error naming its byte
   offset (and line and column in a .gltf). */

typedef struct bpg__parser {
    struct bpg__file *f;
    const char *s;
    size_t n, i;
} bpg__parser;

static bp_status bpg__json_error(bpg__parser *p, size_t at, const char *what)
{
    struct bpg__file *f = p->f;
    size_t k, line = 1, col = 1;
    bp_status st;
    if (at > p->n) at = p->n;
    for (k = 0; k < at; k++) {
        if (p->s[k] == '\n') { line++; col = 1; } else col++;
    }
    if (f->glb)
        st = bpg__fail(f, BP_ERR_PARSE, "JSON chunk, byte %llu of the file: %s",
                       (unsigned long long)(f->doc_offset + at), what);
    else {
        st = bpg__fail(f, BP_ERR_PARSE, "line %llu: JSON, column %llu (byte %llu): %s", (unsigned long long)line,
                       (unsigned long long)col, (unsigned long long)at, what);
        if (f->err->status == st) { f->err->line = (int64_t)line; f->err->element = BP_ELEMENT_LINE; f->err->index = (int64_t)line; }
    }
    return st;
}

static void bpg__skip_ws(bpg__parser *p)
{
    while (p->i < p->n && (p->s[p->i] == ' ' || p->s[p->i] == '\t' || p->s[p->i] == '\n' || p->s[p->i] == '\r')) p->i++;
}

static uint32_t bpg__new_node(bpg__parser *p, unsigned char type)
{
    struct bpg__file *f = p->f;
    bpg__node *n;
    if (f->num_nodes == f->cap_nodes) {
        uint32_t cap;
        bpg__node *q;
        if (f->cap_nodes >= 0x40000000u) { bpg__fail(f, BP_ERR_TOO_LARGE, "the JSON has more than 2^30 values"); return BPG__NONE; }
        cap = f->cap_nodes ? 2 * f->cap_nodes : 64;
        q = (bpg__node *)bpg__alloc_n(f, cap, sizeof *q);
        if (!q) { bpg__oom(f, "parsing the JSON"); return BPG__NONE; }
        if (f->num_nodes) memcpy(q, f->node, f->num_nodes * sizeof *q);
        bpg__freef(f, f->node);
        f->node = q;
        f->cap_nodes = cap;
    }
    n = &f->node[f->num_nodes];
    memset(n, 0, sizeof *n);
    n->type = type;
    n->start = p->i;
    n->key = n->key_end = (size_t)-1;
    n->first = n->next = BPG__NONE;
    return f->num_nodes++;
}

static int bpg__hex(int c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* A string from its opening quote; p->i ends past the closing one. */
static bp_status bpg__parse_string(bpg__parser *p)
{
    size_t open = p->i;
    p->i++;
    for (;;) {
        unsigned char c;
        if (p->i >= p->n) return bpg__json_error(p, open, "a string is not closed");
        c = (unsigned char)p->s[p->i];
        if (c == '"') { p->i++; return BP_OK; }
        if (c < 0x20) return bpg__json_error(p, p->i, "a control character inside a string");
        if (c == '\\') {
            int e;
            if (p->i + 1 >= p->n) return bpg__json_error(p, open, "a string is not closed");
            e = p->s[p->i + 1];
            if (e == 'u') {
                int k;
                for (k = 0; k < 4; k++)
                    if (p->i + 2 + k >= p->n || bpg__hex(p->s[p->i + 2 + k]) < 0)
                        return bpg__json_error(p, p->i, "\\u needs four hexadecimal digits");
                p->i += 6;
                continue;
            }
            if (!strchr("\"\\/bfnrt", e) || e == 0) return bpg__json_error(p, p->i, "an unknown escape in a string");
            p->i += 2;
            continue;
        }
        p->i++;
    }
}

static bp_status bpg__parse_number(bpg__parser *p, uint32_t id)
{
    size_t i = p->i, s = i;
    int integer = 1;
    if (i < p->n && p->s[i] == '-') i++;
    if (i >= p->n || p->s[i] < '0' || p->s[i] > '9') return bpg__json_error(p, s, "not a JSON value");
    if (p->s[i] == '0') i++;
    else while (i < p->n && p->s[i] >= '0' && p->s[i] <= '9') i++;
    if (i < p->n && p->s[i] == '.') {
        i++;
        integer = 0;
        if (i >= p->n || p->s[i] < '0' || p->s[i] > '9') return bpg__json_error(p, i, "a digit must follow the decimal point");
        while (i < p->n && p->s[i] >= '0' && p->s[i] <= '9') i++;
    }
    if (i < p->n && (p->s[i] == 'e' || p->s[i] == 'E')) {
        i++;
        integer = 0;
        if (i < p->n && (p->s[i] == '+' || p->s[i] == '-')) i++;
        if (i >= p->n || p->s[i] < '0' || p->s[i] > '9') return bpg__json_error(p, i, "an exponent needs digits");
        while (i < p->n && p->s[i] >= '0' && p->s[i] <= '9') i++;
    }
    p->i = i;
    p->f->node[id].integer = (unsigned char)integer;
    return BP_OK;
}

static bp_status bpg__parse_value(bpg__parser *p, uint32_t *out);

/* An object or array from its opening bracket. */
static bp_status bpg__parse_container(bpg__parser *p, uint32_t id, int object)
{
    struct bpg__file *f = p->f;
    char close = object ? '}' : ']';
    uint32_t last = BPG__NONE;
    bp_status st;
    if (++f->depth > BPG__MAX_DEPTH) return bpg__json_error(p, p->i, "the JSON nests deeper than 512 levels");
    p->i++;
    bpg__skip_ws(p);
    if (p->i < p->n && p->s[p->i] == close) { p->i++; f->depth--; return BP_OK; }
    for (;;) {
        size_t key = 0, key_end = 0;
        uint32_t child;
        bpg__skip_ws(p);
        if (object) {
            if (p->i >= p->n || p->s[p->i] != '"')
                return bpg__json_error(p, p->i, p->i >= p->n ? "the text ends inside an object" : "an object member must start with a string key");
            key = p->i;
            if ((st = bpg__parse_string(p)) != BP_OK) return st;
            key_end = p->i;
            bpg__skip_ws(p);
            if (p->i >= p->n || p->s[p->i] != ':') return bpg__json_error(p, p->i, "':' must follow an object key");
            p->i++;
            bpg__skip_ws(p);
        }
        if ((st = bpg__parse_value(p, &child)) != BP_OK) return st;
        if (object) { f->node[child].key = key; f->node[child].key_end = key_end; }
        if (last == BPG__NONE) f->node[id].first = child; else f->node[last].next = child;
        last = child;
        if (++f->node[id].count == 0xffffffffu) return bpg__json_error(p, p->i, "too many elements");
        bpg__skip_ws(p);
        if (p->i < p->n && p->s[p->i] == ',') { p->i++; continue; }
        if (p->i < p->n && p->s[p->i] == close) { p->i++; break; }
        return bpg__json_error(p, p->i, p->i >= p->n ? (object ? "the text ends inside an object" : "the text ends inside an array")
                                                    : (object ? "expected ',' or '}' after an object member"
                                                              : "expected ',' or ']' after an array element"));
    }
    f->depth--;
    return BP_OK;
}

static bp_status bpg__parse_value(bpg__parser *p, uint32_t *out)
{
    uint32_t id;
    bp_status st = BP_OK;
    char c;
    if (p->i >= p->n) return bpg__json_error(p, p->i, "the text ends where a value should be");
    c = p->s[p->i];
    id = bpg__new_node(p, c == '{' ? BPG__OBJECT : c == '[' ? BPG__ARRAY : c == '"' ? BPG__STRING :
                          c == 't' ? BPG__TRUE : c == 'f' ? BPG__FALSE : c == 'n' ? BPG__NULL : BPG__NUMBER);
    if (id == BPG__NONE) return p->f->err->status;
    if (c == '{' || c == '[') st = bpg__parse_container(p, id, c == '{');
    else if (c == '"') st = bpg__parse_string(p);
    else if (c == 't' || c == 'f' || c == 'n') {
        const char *w = c == 't' ? "true" : c == 'f' ? "false" : "null";
        size_t k = strlen(w);
        if (p->n - p->i < k || memcmp(p->s + p->i, w, k) != 0) return bpg__json_error(p, p->i, "not a JSON value");
        p->i += k;
    } else st = bpg__parse_number(p, id);
    if (st != BP_OK) return st;
    p->f->node[id].end = p->i;
    *out = id;
    return BP_OK;
}

/* The whole text: one value (glTF: an object), whitespace around it. */
static bp_status bpg__parse_json(struct bpg__file *f, uint32_t *root)
{
    bpg__parser p;
    bp_status st;
    p.f = f; p.s = f->doc; p.n = f->doc_len; p.i = 0;
    if (p.n >= 3 && (unsigned char)p.s[0] == 0xEF && (unsigned char)p.s[1] == 0xBB && (unsigned char)p.s[2] == 0xBF)
        p.i = 3;                          /* a UTF-8 byte order mark: kept, not read */
    bpg__skip_ws(&p);
    if ((st = bpg__parse_value(&p, root)) != BP_OK) return st;
    bpg__skip_ws(&p);
    if (p.i < p.n) return bpg__json_error(&p, p.i, "text after the JSON value");
    if (f->node[*root].type != BPG__OBJECT) return bpg__json_error(&p, f->node[*root].start, "the JSON is not an object");
    return BP_OK;
}

/* ---- reading JSON values -------------------------------------------------- */

/* A string node's content decoded (escapes resolved, \u as UTF-8) into buf
   (NUL-terminated, cut at size - 1 bytes); returns the decoded length. */
static size_t bpg__str_decode(const struct bpg__file *f, size_t open, char *buf, size_t size)
{
    const char *s = f->doc;
    size_t i = open + 1, n = 0;
    for (;;) {
        unsigned long cp;
        char c = s[i];
        if (c == '"') break;
        if (c != '\\') { if (n + 1 < size) buf[n] = c; n++; i++; continue; }
        c = s[i + 1];
        if (c != 'u') {
            char d = c == 'b' ? '\b' : c == 'f' ? '\f' : c == 'n' ? '\n' : c == 'r' ? '\r' : c == 't' ? '\t' : c;
            if (n + 1 < size) buf[n] = d;
            n++; i += 2;
            continue;
        }
        cp = (unsigned long)(bpg__hex(s[i + 2]) << 12 | bpg__hex(s[i + 3]) << 8 | bpg__hex(s[i + 4]) << 4 | bpg__hex(s[i + 5]));
        i += 6;
        if (cp >= 0xD800 && cp < 0xDC00 && s[i] == '\\' && s[i + 1] == 'u') {
            unsigned long lo = (unsigned long)(bpg__hex(s[i + 2]) << 12 | bpg__hex(s[i + 3]) << 8 |
                                               bpg__hex(s[i + 4]) << 4 | bpg__hex(s[i + 5]));
            if (lo >= 0xDC00 && lo < 0xE000) { cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00); i += 6; }
        }
        {
            unsigned char u[4];
            int k, m;
            if (cp < 0x80) { u[0] = (unsigned char)cp; m = 1; }
            else if (cp < 0x800) { u[0] = (unsigned char)(0xC0 | cp >> 6); u[1] = (unsigned char)(0x80 | (cp & 63)); m = 2; }
            else if (cp < 0x10000) { u[0] = (unsigned char)(0xE0 | cp >> 12); u[1] = (unsigned char)(0x80 | (cp >> 6 & 63));
                                     u[2] = (unsigned char)(0x80 | (cp & 63)); m = 3; }
            else { u[0] = (unsigned char)(0xF0 | cp >> 18); u[1] = (unsigned char)(0x80 | (cp >> 12 & 63));
                   u[2] = (unsigned char)(0x80 | (cp >> 6 & 63)); u[3] = (unsigned char)(0x80 | (cp & 63)); m = 4; }
            for (k = 0; k < m; k++) { if (n + 1 < size) buf[n] = (char)u[k]; n++; }
        }
    }
    if (size) buf[n < size ? n : size - 1] = 0;
    return n;
}

/* Is the string at `open` (its opening quote) exactly `lit`? */
static int bpg__str_eq(const struct bpg__file *f, size_t open, const char *lit)
{
    size_t n = strlen(lit), i;
    const char *s = f->doc + open + 1;
    char tmp[64];
    for (i = 0; i < n && s[i] == lit[i] && s[i] != '\\' && s[i] != '"'; i++) {}
    if (i == n) return s[n] == '"';
    if (s[i] != '\\' || n >= sizeof tmp - 1) return 0;
    return bpg__str_decode(f, open, tmp, sizeof tmp) == n && memcmp(tmp, lit, n) == 0;
}

/* Member `key` of object `obj`: its node, BPG__NONE when absent.  A key
   given twice is an error (JSON leaves its meaning open). */
static uint32_t bpg__get(struct bpg__file *f, uint32_t obj, const char *key, const char *what)
{
    uint32_t c, found = BPG__NONE;
    if (obj == BPG__NONE || f->node[obj].type != BPG__OBJECT) return BPG__NONE;
    for (c = f->node[obj].first; c != BPG__NONE; c = f->node[c].next)
        if (bpg__str_eq(f, f->node[c].key, key)) {
            if (found != BPG__NONE) {
                bpg__fail(f, BP_ERR_PARSE, "%s has the key \"%s\" twice (JSON byte %llu)", what, key,
                          (unsigned long long)(f->doc_offset + f->node[c].key));
                return BPG__NONE;
            }
            found = c;
        }
    return found;
}

/* Element k of array `arr`. */
static uint32_t bpg__at(const struct bpg__file *f, uint32_t arr, uint32_t k)
{
    uint32_t c;
    if (arr == BPG__NONE || f->node[arr].type != BPG__ARRAY || k >= f->node[arr].count) return BPG__NONE;
    for (c = f->node[arr].first; k; k--) c = f->node[c].next;
    return c;
}

/* A JSON number that is a whole number in [0, 2^53] ("12", and also "12.0"
   or "1.2e1").  Returns 0 and fails with a message otherwise. */
static int bpg__int_value(struct bpg__file *f, uint32_t id, uint64_t *out, const char *what, const char *key)
{
    const bpg__node *n = &f->node[id];
    const char *s = f->doc + n->start, *e = f->doc + n->end;
    char digits[40];
    int nd = 0, neg = 0, frac = 0, after_point = 0;
    long exp = 0;
    uint64_t v = 0;
    if (n->type != BPG__NUMBER) goto bad;
    if (*s == '-') { neg = 1; s++; }
    for (; s < e && ((*s >= '0' && *s <= '9') || *s == '.'); s++) {
        if (*s == '.') { after_point = 1; continue; }
        if (nd == 0 && *s == '0') { if (after_point) frac++; continue; }     /* leading zeros */
        if (nd >= 39) goto bad;
        digits[nd++] = *s;
        if (after_point) frac++;
    }
    if (s < e) {                                           /* exponent */
        int eneg = 0;
        s++;
        if (*s == '+' || *s == '-') eneg = *s++ == '-';
        for (; s < e; s++) { if (exp > 100000) goto bad; exp = 10 * exp + (*s - '0'); }
        if (eneg) exp = -exp;
    }
    exp -= frac;
    while (exp < 0 && nd > 0 && digits[nd - 1] == '0') { nd--; exp++; }
    if (nd == 0) { *out = 0; return 1; }                    /* zero, "-0" too */
    if (exp < 0 || neg || nd + exp > 16) goto bad;
    {
        int k;
        for (k = 0; k < nd; k++) v = 10 * v + (uint64_t)(digits[k] - '0');
        for (k = 0; k < exp; k++) v *= 10;
    }
    if ((double)v > BPG__MAX_INT) goto bad;
    *out = v;
    return 1;
bad:
    bpg__fail(f, BP_ERR_PARSE, "%s: \"%s\" must be a whole number from 0 to 2^53 (JSON byte %llu)", what, key,
              (unsigned long long)(f->doc_offset + n->start));
    return 0;
}

/* Optional integer member: *out = def when absent.  Returns 0 on error. */
static int bpg__get_int(struct bpg__file *f, uint32_t obj, const char *key, uint64_t def, uint64_t *out, const char *what)
{
    uint32_t id = bpg__get(f, obj, key, what);
    if (f->err->status != BP_OK) return 0;
    if (id == BPG__NONE) { *out = def; return 1; }
    return bpg__int_value(f, id, out, what, key);
}

/* Required integer member. */
static int bpg__need_int(struct bpg__file *f, uint32_t obj, const char *key, uint64_t *out, const char *what)
{
    uint32_t id = bpg__get(f, obj, key, what);
    if (f->err->status != BP_OK) return 0;
    if (id == BPG__NONE) { bpg__fail(f, BP_ERR_PARSE, "%s has no \"%s\"", what, key); return 0; }
    return bpg__int_value(f, id, out, what, key);
}

/* An index member that must be < limit (an array's length). */
static int bpg__get_index(struct bpg__file *f, uint32_t obj, const char *key, uint32_t limit, const char *array,
                          uint32_t *out, const char *what)
{
    uint64_t v;
    if (!bpg__need_int(f, obj, key, &v, what)) return 0;
    if (v >= limit) {
        bpg__fail(f, BP_ERR_INDEX, "%s: \"%s\" is %llu, but the file has %u %s", what, key, (unsigned long long)v,
                  (unsigned)limit, array);
        return 0;
    }
    *out = (uint32_t)v;
    return 1;
}

/* ---- buffers ---------------------------------------------------------------

   A buffer's bytes come from the GLB's BIN chunk (the first buffer of a
   .glb, without uri), from a data: URI (base64, or percent-encoded bytes)
   or from a file named by a relative uri next to the .gltf (percent-
   encoded: "my%20model.bin").  A buffer is loaded the first time an
   accessor the reader needs points into it, so a buffer nobody reads (an
   image's, a compression extension's fallback) may be missing. */

/* base64 (RFC 4648, standard alphabet, '=' padding optional) of s[0, n)
   into out (room for 3 n / 4 bytes); returns the bytes, or -1 with the
   offending character's position in *bad. */
static long long bpg__base64(const char *s, size_t n, unsigned char *out, size_t *bad)
{
    size_t i, m = n, o = 0;
    uint32_t acc = 0;
    int bits = 0;
    while (m > 0 && s[m - 1] == '=' && n - m < 2) m--;
    if (m % 4 == 1) { *bad = m; return -1; }
    for (i = 0; i < m; i++) {
        char c = s[i];
        int v = c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52 :
                c == '+' ? 62 : c == '/' ? 63 : -1;
        if (v < 0) { *bad = i; return -1; }
        acc = acc << 6 | (uint32_t)v;
        bits += 6;
        if (bits >= 8) { bits -= 8; out[o++] = (unsigned char)(acc >> bits); acc &= (1u << bits) - 1; }
    }
    if (m < n && (n - m) != (4 - m % 4) % 4) { *bad = m; return -1; }   /* wrong amount of padding */
    return (long long)o;
}

/* Percent-decoding of s[0, n) into out (NUL-terminated); -1 on a bad or
   NUL escape, with its position in *bad. */
static long long bpg__percent(const char *s, size_t n, char *out, size_t *bad)
{
    size_t i, o = 0;
    for (i = 0; i < n; i++) {
        if (s[i] == '%') {
            int h;
            if (n - i < 3 || bpg__hex(s[i + 1]) < 0 || bpg__hex(s[i + 2]) < 0 ||
                (h = bpg__hex(s[i + 1]) << 4 | bpg__hex(s[i + 2])) == 0) { *bad = i; return -1; }
            out[o++] = (char)h;
            i += 2;
        } else out[o++] = s[i];
    }
    out[o] = 0;
    return (long long)o;
}

/* The decoded uri of buffer or image `uri_node` (a JSON string) into a new
   NUL-terminated string. */
static char *bpg__uri(struct bpg__file *f, uint32_t uri_node)
{
    const bpg__node *n = &f->node[uri_node];
    size_t cap = n->end - n->start;
    char *s = (char *)bpg__alloc(f, cap + 1);
    if (!s) { bpg__oom(f, "reading a uri"); return NULL; }
    bpg__str_decode(f, n->start, s, cap + 1);
    return s;
}

/* A uri with a scheme ("data:", "http:", "C:") or an absolute path. */
static int bpg__uri_absolute(const char *u)
{
    const char *p = u;
    if (*u == '/' || *u == '\\') return 1;
    if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z'))) return 0;
    while ((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '+' || *p == '-' || *p == '.') p++;
    return *p == ':';
}

/* The local path of a relative uri: the folder, then the percent-decoded uri. */
static char *bpg__uri_path(struct bpg__file *f, const char *uri, const char *what)
{
    size_t d = f->dir ? strlen(f->dir) : 0, n = strlen(uri), bad = 0;
    char *path = (char *)bpg__alloc(f, d + n + 2);
    if (!path) { bpg__oom(f, "reading a uri"); return NULL; }
    memcpy(path, f->dir ? f->dir : "", d);
    if (d && f->dir[d - 1] != '/' && f->dir[d - 1] != '\\') path[d++] = '/';
    if (bpg__percent(uri, n, path + d, &bad) < 0) {
        bpg__fail(f, BP_ERR_PARSE, "%s: its uri '%s' has a bad percent escape at character %llu", what, uri,
                  (unsigned long long)bad + 1);
        bpg__freef(f, path);
        return NULL;
    }
    return path;
}

static bp_status bpg__read_file_part(struct bpg__file *f, bpg__buffer *b, const char *what)
{
    FILE *fp = fopen(b->path, "rb");
    size_t got;
    int c;
    if ((uint64_t)(size_t)b->length != b->length)
        return bpg__fail(f, BP_ERR_TOO_LARGE, "%s ('%s'): byteLength %llu does not fit in memory here", what, b->path,
                         (unsigned long long)b->length);
    if (!fp) return bpg__fail(f, BP_ERR_IO, "%s: cannot open '%s': %s", what, b->path, strerror(errno));
    if (!(b->owned = (unsigned char *)bpg__alloc(f, (size_t)b->length))) { fclose(fp); return bpg__oom(f, "reading a buffer"); }
    got = fread(b->owned, 1, (size_t)b->length, fp);
    c = ferror(fp);
    fclose(fp);
    if (c) return bpg__fail(f, BP_ERR_IO, "%s: cannot read '%s'", what, b->path);
    if (got < b->length)
        return bpg__fail(f, BP_ERR_PARSE, "%s: '%s' has %llu bytes, but byteLength is %llu", what, b->path,
                         (unsigned long long)got, (unsigned long long)b->length);
    b->data = b->owned;
    return BP_OK;
}

static bp_status bpg__load_data_uri(struct bpg__file *f, bpg__buffer *b, const char *uri, const char *what)
{
    const char *comma = strchr(uri, ',');
    size_t n, bad = 0;
    long long got;
    if (!comma) return bpg__fail(f, BP_ERR_PARSE, "%s: its data: URI has no ','", what);
    n = strlen(comma + 1);
    if (!(b->owned = (unsigned char *)bpg__alloc(f, n + 1))) return bpg__oom(f, "decoding a data: URI");
    if (comma - uri >= 7 && memcmp(comma - 7, ";base64", 7) == 0) {
        got = bpg__base64(comma + 1, n, b->owned, &bad);
        if (got < 0)
            return bpg__fail(f, BP_ERR_PARSE, "%s: bad base64 in its data: URI at character %llu of the data",
                             what, (unsigned long long)bad + 1);
    } else {
        got = bpg__percent(comma + 1, n, (char *)b->owned, &bad);
        if (got < 0)
            return bpg__fail(f, BP_ERR_PARSE, "%s: bad percent escape in its data: URI at character %llu of the data",
                             what, (unsigned long long)bad + 1);
    }
    if ((uint64_t)got < b->length)
        return bpg__fail(f, BP_ERR_PARSE, "%s: its data: URI holds %llu bytes, but byteLength is %llu", what,
                         (unsigned long long)got, (unsigned long long)b->length);
    b->data = b->owned;
    return BP_OK;
}

/* Buffer i's bytes, loaded once. */
static const unsigned char *bpg__buffer_data(struct bpg__file *f, uint32_t i)
{
    bpg__buffer *b = &f->buf[i];
    char what[64], *uri;
    if (b->loaded) return b->data;
    snprintf(what, sizeof what, "buffer %u", (unsigned)i);
    if (b->kind == 0) {
        b->loaded = 1;
        b->data = f->bin;
        return b->data;
    }
    if (b->uri == BPG__NONE) {
        bpg__fail(f, BP_ERR_PARSE, "%s has no uri (only the first buffer of a .glb, stored in its BIN chunk, may lack one)", what);
        return NULL;
    }
    if (!(uri = bpg__uri(f, b->uri))) return NULL;
    if (strncmp(uri, "data:", 5) == 0) bpg__load_data_uri(f, b, uri, what);
    else if (bpg__uri_absolute(uri))
        bpg__fail(f, BP_ERR_PARSE, "%s: its uri '%s' is not a relative path or a data: URI (only local files are read)", what, uri);
    else if (!f->dir)
        bpg__fail(f, BP_ERR_IO, "%s refers to the external file '%s', which is not read here (no folder given)", what, uri);
    else if ((b->path = bpg__uri_path(f, uri, what)) != NULL)
        bpg__read_file_part(f, b, what);
    bpg__freef(f, uri);
    if (f->err->status != BP_OK) return NULL;
    b->loaded = 1;
    return b->data;
}

/* ---- accessors -------------------------------------------------------------

   An accessor's element i is at base + i * stride (stride: the
   bufferView's byteStride, or the element's size), then the sparse
   substitutions (strictly increasing indices) replace some elements; an
   accessor without bufferView starts from zeros.  Every offset, length and
   stride is checked against what holds it before anything is read:
       accessor.byteOffset + stride * (count - 1) + element <= bufferView.byteLength
       bufferView.byteOffset + bufferView.byteLength <= buffer.byteLength
       buffer.byteLength <= the bytes the buffer really has
   each term at most 2^53 (bpg__int_value), so no sum overflows. */

static uint32_t bpg__uint(const unsigned char *p, int size)
{
    return size == 1 ? p[0] : size == 2 ? (uint32_t)(p[0] | p[1] << 8) : bpg__le32(p);
}

static int bpg__csize(int ctype)
{
    switch (ctype) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

/* bufferView `v` checked; *data its first byte, *len its byteLength,
   *stride its byteStride (0: none). */
static int bpg__view(struct bpg__file *f, uint32_t v, const unsigned char **data, uint64_t *len, uint32_t *stride,
                     const char *who)
{
    char what[160];
    uint32_t node = bpg__at(f, f->views, v), b;
    uint64_t off, st;
    const unsigned char *bd;
    snprintf(what, sizeof what, "bufferView %u (of %s)", (unsigned)v, who);
    if (node == BPG__NONE || f->node[node].type != BPG__OBJECT) {
        bpg__fail(f, BP_ERR_PARSE, "%s is not an object", what);
        return 0;
    }
    if (bpg__get(f, bpg__get(f, node, "extensions", what), "EXT_meshopt_compression", what) != BPG__NONE) {
        bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "%s is compressed with EXT_meshopt_compression, which this reader does not decode", what);
        return 0;
    }
    if (!bpg__get_index(f, node, "buffer", f->num_buffers, "buffers", &b, what) ||
        !bpg__get_int(f, node, "byteOffset", 0, &off, what) || !bpg__need_int(f, node, "byteLength", len, what) ||
        !bpg__get_int(f, node, "byteStride", 0, &st, what))
        return 0;
    if (bpg__get(f, node, "byteStride", what) != BPG__NONE && (st < 4 || st > 252 || st % 4)) {
        bpg__fail(f, BP_ERR_PARSE, "%s: byteStride %llu is not a multiple of 4 from 4 to 252", what, (unsigned long long)st);
        return 0;
    }
    if (off + *len > f->buf[b].length) {
        bpg__fail(f, BP_ERR_INDEX, "%s: byteOffset %llu + byteLength %llu runs past the %llu bytes of buffer %u", what,
                  (unsigned long long)off, (unsigned long long)*len, (unsigned long long)f->buf[b].length, (unsigned)b);
        return 0;
    }
    if (!(bd = bpg__buffer_data(f, b))) return 0;
    *data = bd + off;
    *stride = (uint32_t)st;
    return 1;
}

static int bpg__type_components(struct bpg__file *f, uint32_t type_node, int *mat)
{
    static const char *const names[7] = { "SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4" };
    static const int comps[7] = { 1, 2, 3, 4, 4, 9, 16 };
    int k;
    *mat = 0;
    if (type_node == BPG__NONE || f->node[type_node].type != BPG__STRING) return 0;
    for (k = 0; k < 7; k++)
        if (bpg__str_eq(f, f->node[type_node].start, names[k])) { *mat = k >= 4 ? k - 2 : 0; return comps[k]; }
    return 0;
}

/* Accessor `index` checked into *a; `what` names it ("accessor 5
   (POSITION of mesh 0 primitive 1)"). */
static int bpg__accessor(struct bpg__file *f, uint32_t index, bpg__acc *a, const char *what)
{
    uint32_t node, bv, sp, mat;
    uint64_t ct, count, off;
    int m;
    memset(a, 0, sizeof *a);
    a->index = index;
    if (index >= f->num_accessors) {
        bpg__fail(f, BP_ERR_INDEX, "%s: the file has %u accessors", what, (unsigned)f->num_accessors);
        return 0;
    }
    node = bpg__at(f, f->accessors, index);
    if (f->node[node].type != BPG__OBJECT) { bpg__fail(f, BP_ERR_PARSE, "%s is not an object", what); return 0; }
    if (!bpg__need_int(f, node, "componentType", &ct, what) || !bpg__need_int(f, node, "count", &count, what) ||
        !bpg__get_int(f, node, "byteOffset", 0, &off, what))
        return 0;
    a->ctype = (int)ct;
    if (!(a->csize = bpg__csize(a->ctype))) {
        bpg__fail(f, BP_ERR_PARSE, "%s: componentType %llu is not one of glTF's (5120-5123, 5125, 5126)", what, (unsigned long long)ct);
        return 0;
    }
    if (!(a->ncomp = bpg__type_components(f, bpg__get(f, node, "type", what), &m))) {
        if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "%s: \"type\" is missing or not SCALAR, VEC2-4 or MAT2-4", what);
        return 0;
    }
    mat = (uint32_t)m;
    /* matrix columns start on 4-byte boundaries */
    if (mat && a->csize < 4) a->esize = (size_t)mat * (((size_t)mat * (size_t)a->csize + 3) / 4 * 4);
    else a->esize = (size_t)a->ncomp * (size_t)a->csize;
    if (count == 0 || count >= BPG__NONE) {
        bpg__fail(f, count ? BP_ERR_TOO_LARGE : BP_ERR_PARSE, "%s: count %llu is not from 1 to 2^32 - 2", what, (unsigned long long)count);
        return 0;
    }
    a->count = (uint32_t)count;
    {
        uint32_t nn = bpg__get(f, node, "normalized", what);
        a->normalized = nn != BPG__NONE && f->node[nn].type == BPG__TRUE;
    }
    bv = bpg__get(f, node, "bufferView", what);
    if (bv != BPG__NONE) {
        const unsigned char *vd;
        uint64_t vlen;
        uint32_t vs, vi;
        if (!bpg__get_index(f, node, "bufferView", f->num_views, "bufferViews", &vi, what)) return 0;
        if (!bpg__view(f, vi, &vd, &vlen, &vs, what)) return 0;
        a->stride = vs ? vs : a->esize;
        if (vs && vs < a->esize) {
            bpg__fail(f, BP_ERR_PARSE, "%s: byteStride %u of bufferView %u is smaller than its %u-byte elements", what,
                      (unsigned)vs, (unsigned)vi, (unsigned)a->esize);
            return 0;
        }
        if (off + (uint64_t)a->stride * (count - 1) + a->esize > vlen) {
            bpg__fail(f, BP_ERR_INDEX, "%s: byteOffset %llu + %llu elements of %u bytes (stride %u) run past the %llu bytes of bufferView %u",
                      what, (unsigned long long)off, (unsigned long long)count, (unsigned)a->esize, (unsigned)a->stride,
                      (unsigned long long)vlen, (unsigned)vi);
            return 0;
        }
        a->base = vd + off;
    } else if (f->err->status != BP_OK) return 0;
    sp = bpg__get(f, node, "sparse", what);
    if (sp != BPG__NONE) {
        uint32_t in = bpg__get(f, sp, "indices", what), vn = bpg__get(f, sp, "values", what), vi;
        uint64_t sc, ioff, voff, ict, vlen;
        const unsigned char *vd;
        uint32_t vs;
        char sw[200];
        snprintf(sw, sizeof sw, "%s, sparse", what);
        if (!bpg__need_int(f, sp, "count", &sc, sw)) return 0;
        if (sc == 0 || sc > count) {
            bpg__fail(f, BP_ERR_INDEX, "%s: count %llu is not from 1 to the accessor's count %llu", sw, (unsigned long long)sc,
                      (unsigned long long)count);
            return 0;
        }
        if (in == BPG__NONE || vn == BPG__NONE) { bpg__fail(f, BP_ERR_PARSE, "%s: \"indices\" or \"values\" is missing", sw); return 0; }
        snprintf(sw, sizeof sw, "%s, sparse indices", what);
        if (!bpg__get_index(f, in, "bufferView", f->num_views, "bufferViews", &vi, sw) ||
            !bpg__get_int(f, in, "byteOffset", 0, &ioff, sw) || !bpg__need_int(f, in, "componentType", &ict, sw))
            return 0;
        if (ict != 5121 && ict != 5123 && ict != 5125) {
            bpg__fail(f, BP_ERR_PARSE, "%s: componentType %llu is not 5121, 5123 or 5125", sw, (unsigned long long)ict);
            return 0;
        }
        a->sidx_size = bpg__csize((int)ict);
        if (!bpg__view(f, vi, &vd, &vlen, &vs, sw)) return 0;
        if (ioff + sc * (uint64_t)a->sidx_size > vlen) {
            bpg__fail(f, BP_ERR_INDEX, "%s: byteOffset %llu + %llu indices of %d bytes run past the %llu bytes of bufferView %u",
                      sw, (unsigned long long)ioff, (unsigned long long)sc, a->sidx_size, (unsigned long long)vlen, (unsigned)vi);
            return 0;
        }
        a->sidx = vd + ioff;
        snprintf(sw, sizeof sw, "%s, sparse values", what);
        if (!bpg__get_index(f, vn, "bufferView", f->num_views, "bufferViews", &vi, sw) ||
            !bpg__get_int(f, vn, "byteOffset", 0, &voff, sw) || !bpg__view(f, vi, &vd, &vlen, &vs, sw))
            return 0;
        if (voff + sc * (uint64_t)a->esize > vlen) {
            bpg__fail(f, BP_ERR_INDEX, "%s: byteOffset %llu + %llu values of %u bytes run past the %llu bytes of bufferView %u",
                      sw, (unsigned long long)voff, (unsigned long long)sc, (unsigned)a->esize, (unsigned long long)vlen, (unsigned)vi);
            return 0;
        }
        a->sval = vd + voff;
        a->scount = (uint32_t)sc;
        {   /* the indices, strictly increasing and below count, checked now */
            uint32_t i, prev = 0;
            for (i = 0; i < a->scount; i++) {
                uint32_t k = bpg__uint(a->sidx + (size_t)i * (size_t)a->sidx_size, a->sidx_size);
                if (k >= a->count || (i && k <= prev)) {
                    bpg__fail(f, BP_ERR_INDEX, "%s: sparse index %u is %u, %s", what, (unsigned)i, (unsigned)k,
                              k >= a->count ? "beyond the accessor's count" : "not above the one before it (they must increase)");
                    return 0;
                }
                prev = k;
            }
        }
    }
    return f->err->status == BP_OK;
}

/* The accessor's elements, packed (count * esize bytes, sparse applied). */
static unsigned char *bpg__fetch(struct bpg__file *f, const bpg__acc *a)
{
    unsigned char *out = (unsigned char *)bpg__alloc_n(f, a->count, a->esize);
    uint32_t i;
    if (!out) { bpg__oom(f, "reading an accessor"); return NULL; }
    if (!a->base) memset(out, 0, (size_t)a->count * a->esize);
    else if (a->stride == a->esize) memcpy(out, a->base, (size_t)a->count * a->esize);
    else for (i = 0; i < a->count; i++) memcpy(out + (size_t)i * a->esize, a->base + (size_t)i * a->stride, a->esize);
    for (i = 0; i < a->scount; i++) {                 /* indices checked by bpg__accessor */
        uint32_t k = bpg__uint(a->sidx + (size_t)i * (size_t)a->sidx_size, a->sidx_size);
        memcpy(out + (size_t)k * a->esize, a->sval + (size_t)i * a->esize, a->esize);
    }
    return out;
}

/* Component c of a packed element as a number: floats as they are,
   normalized integers scaled to [-1, 1] or [0, 1] as glTF says, plain
   integers as integers. */
static double bpg__comp(const unsigned char *e, int ctype, int normalized, int c)
{
    switch (ctype) {
    case 5120: { int v = (signed char)e[c]; return normalized ? (v < -127 ? -1.0 : v / 127.0) : v; }
    case 5121: return normalized ? e[c] / 255.0 : e[c];
    case 5122: { int v = (int16_t)(uint16_t)(e[2 * c] | e[2 * c + 1] << 8); return normalized ? (v < -32767 ? -1.0 : v / 32767.0) : v; }
    case 5123: { unsigned v = (unsigned)(e[2 * c] | e[2 * c + 1] << 8); return normalized ? v / 65535.0 : v; }
    case 5125: { uint32_t v = bpg__le32(e + 4 * c); return normalized ? v / 4294967295.0 : (double)v; }
    default: { uint32_t u = bpg__le32(e + 4 * c); float x; memcpy(&x, &u, 4); return x; }
    }
}

/* ---- primitives, vertex sets and welding -----------------------------------

   A group is the set of triangle primitives that share one vertex set:
   the same accessor for every attribute and the same morph targets
   (exporters split a mesh by material this way).  Its vertices are
   written once, split where the seams of any of its primitives cut them,
   and each primitive gets its own new indices.  Primitives that share
   only some accessors (POSITION, but not NORMAL) are separate groups:
   each gets its own copy of the shared data.

   Welding (see the essay at the top): the referenced vertices of a group
   at the same position, compared as numbers (-0 = +0; a NaN equals
   nothing), become one mesh vertex; with TEXCOORD_n, the corners at one
   mesh vertex with the same (u, v) share a uv index. */

/* splitmix64's finalizer: the hash of a key made of doubles. */
static uint64_t bpg__mix(uint64_t x)
{
    x ^= x >> 30; x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27; x *= 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

static uint64_t bpg__hash_doubles(const double *v, int n, uint64_t h)
{
    int k;
    for (k = 0; k < n; k++) {
        double x = v[k] == 0 ? 0.0 : v[k];     /* -0 and +0 weld */
        uint64_t u;
        memcpy(&u, &x, 8);
        h = bpg__mix(h ^ u) + 0x9e3779b97f4a7c15ull;
    }
    return h;
}

/* An open-addressing set of ids (0: empty slot, else id + 1) whose keys
   are `dim` doubles at keys + dim * id (plus an integer tag per id). */
typedef struct bpg__set {
    uint32_t *slot;
    size_t    mask;
    const double *keys;
    const uint32_t *tags;
    int dim;
} bpg__set;

static int bpg__set_init(struct bpg__file *f, bpg__set *s, size_t n, const double *keys, const uint32_t *tags, int dim)
{
    size_t cap = 16;
    while (cap < 2 * n + 2) cap *= 2;
    s->slot = (uint32_t *)bpg__calloc_n(f, cap, sizeof(uint32_t));
    s->mask = cap - 1;
    s->keys = keys; s->tags = tags; s->dim = dim;
    return s->slot != NULL;
}

/* The id of the key equal to key[0, dim) with tag `tag`, or `fresh` after
   inserting it (the caller has stored the key at fresh's place). */
static uint32_t bpg__set_find(bpg__set *s, const double *key, uint32_t tag, uint32_t fresh)
{
    size_t i = (size_t)bpg__hash_doubles(key, s->dim, tag) & s->mask;
    for (;; i = (i + 1) & s->mask) {
        uint32_t id = s->slot[i];
        int k;
        if (!id) { s->slot[i] = fresh + 1; return fresh; }
        id--;
        if (s->tags && s->tags[id] != tag) continue;
        for (k = 0; k < s->dim && s->keys[(size_t)s->dim * id + k] == key[k]; k++) {}
        if (k == s->dim) return id;
    }
}

static void bpg__prim_name(const struct bpg__file *f, const bpg__prim *p, char *buf, size_t size)
{
    (void)f;
    snprintf(buf, size, "mesh %u primitive %u", (unsigned)p->mesh, (unsigned)p->index);
}

/* Are the objects a and b the same map of names to integers (attributes,
   a morph target)? */
static int bpg__same_map(struct bpg__file *f, uint32_t a, uint32_t b)
{
    uint32_t x, y;
    if (a == b) return 1;
    if (a == BPG__NONE || b == BPG__NONE || f->node[a].count != f->node[b].count) return 0;
    for (x = f->node[a].first; x != BPG__NONE; x = f->node[x].next) {
        char kx[256];
        size_t nx = bpg__str_decode(f, f->node[x].key, kx, sizeof kx);
        int found = 0;
        if (nx >= sizeof kx) return 0;
        for (y = f->node[b].first; y != BPG__NONE && !found; y = f->node[y].next) {
            char ky[256];
            size_t ny = bpg__str_decode(f, f->node[y].key, ky, sizeof ky);
            if (ny == nx && memcmp(kx, ky, nx) == 0) {
                const bpg__node *vx = &f->node[x], *vy = &f->node[y];
                if (vx->end - vx->start != vy->end - vy->start || memcmp(f->doc + vx->start, f->doc + vy->start, vx->end - vx->start))
                    return 0;
                found = 1;
            }
        }
        if (!found) return 0;
    }
    return 1;
}

static int bpg__same_targets(struct bpg__file *f, uint32_t a, uint32_t b)
{
    uint32_t x, y;
    if (a == BPG__NONE || b == BPG__NONE) return a == b || f->node[a == BPG__NONE ? b : a].count == 0;
    if (f->node[a].count != f->node[b].count) return 0;
    for (x = f->node[a].first, y = f->node[b].first; x != BPG__NONE; x = f->node[x].next, y = f->node[y].next)
        if (!bpg__same_map(f, x, y)) return 0;
    return 1;
}

/* Every attribute and morph target accessor of the group checked: in
   range, readable, of the POSITION accessor's count. */
static int bpg__check_group_accessors(struct bpg__file *f, const bpg__prim *p, uint32_t count)
{
    char pn[64], what[200], key[64];
    uint32_t c, t, k = 0;
    bpg__acc a;
    bpg__prim_name(f, p, pn, sizeof pn);
    for (t = 0; ; t++) {
        uint32_t obj = t == 0 ? p->attributes : bpg__at(f, p->targets, t - 1);
        if (t > 0 && obj == BPG__NONE) break;
        if (f->node[obj].type != BPG__OBJECT) {
            bpg__fail(f, BP_ERR_PARSE, "%s: morph target %u is not an object", pn, (unsigned)(t - 1));
            return 0;
        }
        for (c = f->node[obj].first; c != BPG__NONE; c = f->node[c].next, k++) {
            uint64_t idx;
            bpg__str_decode(f, f->node[c].key, key, sizeof key);
            if (t == 0) snprintf(what, sizeof what, "%s attribute %s", pn, key);
            else snprintf(what, sizeof what, "%s morph target %u attribute %s", pn, (unsigned)(t - 1), key);
            if (!bpg__int_value(f, c, &idx, what, key)) return 0;
            if (idx >= f->num_accessors) {
                bpg__fail(f, BP_ERR_INDEX, "%s: accessor %llu, but the file has %u accessors", what, (unsigned long long)idx,
                          (unsigned)f->num_accessors);
                return 0;
            }
            snprintf(what, sizeof what, "accessor %u (%s%s of %s)", (unsigned)idx, t ? "morph target " : "", key, pn);
            if (!bpg__accessor(f, (uint32_t)idx, &a, what)) return 0;
            if (a.count != count) {
                bpg__fail(f, BP_ERR_PARSE, "%s: count %u differs from the %u of POSITION (accessor %u)", what,
                          (unsigned)a.count, (unsigned)count, (unsigned)p->position);
                return 0;
            }
        }
    }
    return 1;
}

/* A growable array of uint32 (the triangles as read). */
typedef struct bpg__u32s { uint32_t *v; size_t n, cap; } bpg__u32s;

static int bpg__push(struct bpg__file *f, bpg__u32s *a, uint32_t x)
{
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 1024;
        uint32_t *q = (uint32_t *)bpg__alloc_n(f, cap, sizeof *q);
        if (!q) return 0;
        if (a->n) memcpy(q, a->v, a->n * sizeof *q);
        bpg__freef(f, a->v);
        a->v = q;
        a->cap = cap;
    }
    a->v[a->n++] = x;
    return 1;
}

/* The triangles of primitive p (glTF vertex indices) onto tri / num:
   triangles as they are, a strip's p_i = {v_i, v_(i+1+i%2), v_(i+2-i%2)},
   a fan's {v_(i+1), v_(i+2), v_0} (glTF 2.0, "Primitive Topologies"); a
   strip's or fan's triangle that repeats a vertex joins nothing and is
   dropped. */
static int bpg__prim_triangles(struct bpg__file *f, bpg__prim *p, uint32_t count, bpg__u32s *corner, bpg__u32s *num)
{
    uint32_t *idx = NULL, n, i;
    char pn[64], what[160];
    bpg__prim_name(f, p, pn, sizeof pn);
    if (p->indices != BPG__NONE) {
        bpg__acc a;
        unsigned char *raw;
        snprintf(what, sizeof what, "accessor %u (indices of %s)", (unsigned)p->indices, pn);
        if (!bpg__accessor(f, p->indices, &a, what)) return 0;
        if (a.ncomp != 1 || (a.ctype != 5121 && a.ctype != 5123 && a.ctype != 5125)) {
            bpg__fail(f, BP_ERR_PARSE, "%s: indices must be SCALAR of componentType 5121, 5123 or 5125", what);
            return 0;
        }
        if (!(raw = bpg__fetch(f, &a))) return 0;
        n = a.count;
        if (!(idx = (uint32_t *)bpg__alloc_n(f, n, sizeof *idx))) { bpg__freef(f, raw); bpg__oom(f, "reading indices"); return 0; }
        for (i = 0; i < n; i++) {
            idx[i] = bpg__uint(raw + (size_t)i * (size_t)a.csize, a.csize);
            if (idx[i] >= count) {
                bpg__fail(f, BP_ERR_INDEX, "%s: index %u (element %u) is beyond the %u vertices of POSITION (accessor %u)", what,
                          (unsigned)idx[i], (unsigned)i, (unsigned)count, (unsigned)p->position);
                bpg__freef(f, raw); bpg__freef(f, idx);
                return 0;
            }
        }
        bpg__freef(f, raw);
    } else n = count;
    p->first = (uint32_t)(corner->n / 3);
    for (i = 0; i + 2 < n; i += p->mode == 4 ? 3 : 1) {
        uint32_t v[3];
        int k;
#define BPG__IDX(j) (idx ? idx[j] : (uint32_t)(j))
        if (p->mode == 4) { v[0] = BPG__IDX(i); v[1] = BPG__IDX(i + 1); v[2] = BPG__IDX(i + 2); }
        else if (p->mode == 5) { v[0] = BPG__IDX(i); v[1] = BPG__IDX(i + 1 + i % 2); v[2] = BPG__IDX(i + 2 - i % 2); }
        else { v[0] = BPG__IDX(i + 1); v[1] = BPG__IDX(i + 2); v[2] = BPG__IDX(0); }
#undef BPG__IDX
        if (p->mode != 4 && (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])) continue;
        if (corner->n / 3 >= 0x55555554u) {
            bpg__freef(f, idx);
            bpg__fail(f, BP_ERR_TOO_LARGE, "%s: the file has more than 1,431,655,764 triangles, the library's limit", pn);
            return 0;
        }
        for (k = 0; k < 3; k++) if (!bpg__push(f, corner, v[k])) break;
        if (k < 3 || !bpg__push(f, num, p->mode == 4 ? i / 3 : i)) { bpg__freef(f, idx); bpg__oom(f, "reading triangles"); return 0; }
    }
    bpg__freef(f, idx);
    p->num = (uint32_t)(corner->n / 3) - p->first;
    return 1;
}

/* One primitive of mesh m: recorded when it has triangles to read. */
static int bpg__read_primitive(struct bpg__file *f, bpg_file *file, uint32_t m, uint32_t k, uint32_t node, bpg__prim *p)
{
    char pn[64], key[32];
    uint64_t mode;
    uint32_t attr, c;
    memset(p, 0, sizeof *p);
    p->mesh = m; p->index = k; p->node = node;
    p->indices = p->texcoord = p->targets = BPG__NONE;
    bpg__prim_name(f, p, pn, sizeof pn);
    if (f->node[node].type != BPG__OBJECT) { bpg__fail(f, BP_ERR_PARSE, "%s is not an object", pn); return 0; }
    if (!bpg__get_int(f, node, "mode", 4, &mode, pn)) return 0;
    if (mode > 6) { bpg__fail(f, BP_ERR_PARSE, "%s: mode %llu is not 0-6", pn, (unsigned long long)mode); return 0; }
    p->mode = (int)mode;
    if (mode < 4) { file->num_skipped++; return 1; }
    if (bpg__get(f, bpg__get(f, node, "extensions", pn), "KHR_draco_mesh_compression", pn) != BPG__NONE) {
        bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "%s is compressed with KHR_draco_mesh_compression, which this reader does not decode", pn);
        return 0;
    }
    attr = bpg__get(f, node, "attributes", pn);
    if (attr == BPG__NONE || f->node[attr].type != BPG__OBJECT) {
        if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "%s has no \"attributes\" object", pn);
        return 0;
    }
    p->attributes = attr;
    if (bpg__get(f, attr, "POSITION", pn) == BPG__NONE) {
        if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "%s has no POSITION attribute", pn);
        return 0;
    }
    if (!bpg__get_index(f, attr, "POSITION", f->num_accessors, "accessors", &p->position, pn)) return 0;
    if (bpg__get(f, node, "indices", pn) != BPG__NONE &&
        !bpg__get_index(f, node, "indices", f->num_accessors, "accessors", &p->indices, pn))
        return 0;
    for (c = 0; c < (uint32_t)f->texcoord; c++) {
        snprintf(key, sizeof key, "TEXCOORD_%u", (unsigned)c);
        if (bpg__get(f, attr, key, pn) == BPG__NONE) {
            if (f->err->status == BP_OK)
                bpg__fail(f, BP_ERR_PARSE, "%s has no %s, so TEXCOORD_%d cannot be written (glTF numbers the sets without gaps)",
                          pn, key, f->texcoord);
            return 0;
        }
    }
    snprintf(key, sizeof key, "TEXCOORD_%d", f->texcoord);
    if (bpg__get(f, attr, key, pn) != BPG__NONE &&
        !bpg__get_index(f, attr, key, f->num_accessors, "accessors", &p->texcoord, pn))
        return 0;
    p->targets = bpg__get(f, node, "targets", pn);
    if (p->targets != BPG__NONE && f->node[p->targets].type != BPG__ARRAY) {
        bpg__fail(f, BP_ERR_PARSE, "%s: \"targets\" is not an array", pn);
        return 0;
    }
    return f->err->status == BP_OK;
}

/* Positions (and uvs) of group g as doubles, one xyz (uv) per glTF vertex. */
static double *bpg__group_values(struct bpg__file *f, const bpg__prim *p, uint32_t acc, int dim)
{
    char pn[64], what[160];
    bpg__acc a;
    unsigned char *raw;
    double *out;
    uint32_t i;
    int k;
    bpg__prim_name(f, p, pn, sizeof pn);
    snprintf(what, sizeof what, "accessor %u (%s of %s)", (unsigned)acc, dim == 3 ? "POSITION" : "TEXCOORD", pn);
    if (!bpg__accessor(f, acc, &a, what)) return NULL;
    if (a.ncomp != dim || a.esize != (size_t)dim * (size_t)a.csize) {
        bpg__fail(f, BP_ERR_PARSE, "%s must be of type %s", what, dim == 3 ? "VEC3" : "VEC2");
        return NULL;
    }
    if (!(raw = bpg__fetch(f, &a))) return NULL;
    out = (double *)bpg__alloc_n(f, (size_t)a.count * (size_t)dim, sizeof(double));
    if (!out) { bpg__freef(f, raw); bpg__oom(f, "reading vertices"); return NULL; }
    for (i = 0; i < a.count; i++)
        for (k = 0; k < dim; k++)
            out[(size_t)dim * i + k] = bpg__comp(raw + (size_t)i * a.esize, a.ctype, a.normalized, k);
    if (dim == 2)                                     /* glTF's v runs downward */
        for (i = 0; i < a.count; i++) out[2 * (size_t)i + 1] = 1.0 - out[2 * (size_t)i + 1];
    bpg__freef(f, raw);
    return out;
}

/* A top-level array ("buffers", "meshes", ...): BPG__NONE when absent. */
static int bpg__top_array(struct bpg__file *f, uint32_t root, const char *name, uint32_t *node, uint32_t *count)
{
    *node = bpg__get(f, root, name, "the glTF object");
    *count = 0;
    if (f->err->status != BP_OK) return 0;
    if (*node == BPG__NONE) return 1;
    if (f->node[*node].type != BPG__ARRAY) {
        bpg__fail(f, BP_ERR_PARSE, "\"%s\" is not an array (JSON byte %llu)", name, (unsigned long long)(f->doc_offset + f->node[*node].start));
        return 0;
    }
    *count = f->node[*node].count;
    return 1;
}

static int bpg__read_asset(struct bpg__file *f, uint32_t root)
{
    uint32_t asset = bpg__get(f, root, "asset", "the glTF object"), ver, minv;
    char v[32];
    if (asset == BPG__NONE || f->node[asset].type != BPG__OBJECT) {
        if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "the JSON has no \"asset\" object: not a glTF file");
        return 0;
    }
    ver = bpg__get(f, asset, "version", "asset");
    if (ver == BPG__NONE || f->node[ver].type != BPG__STRING) {
        if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "asset has no \"version\" string");
        return 0;
    }
    bpg__str_decode(f, f->node[ver].start, v, sizeof v);
    if (strncmp(v, "2.", 2) != 0) {
        bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "asset.version is \"%s\": this reader reads glTF 2.0", v);
        return 0;
    }
    minv = bpg__get(f, asset, "minVersion", "asset");
    if (minv != BPG__NONE && f->node[minv].type == BPG__STRING) {
        bpg__str_decode(f, f->node[minv].start, v, sizeof v);
        if (strcmp(v, "2.0") != 0) {
            bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "asset.minVersion is \"%s\": this reader reads glTF 2.0", v);
            return 0;
        }
    }
    return f->err->status == BP_OK;
}

static int bpg__read_buffers(struct bpg__file *f)
{
    uint32_t i, c;
    if (!(f->buf = (bpg__buffer *)bpg__calloc_n(f, f->num_buffers, sizeof *f->buf))) { bpg__oom(f, "reading buffers"); return 0; }
    for (i = 0, c = f->num_buffers ? f->node[f->buffers].first : BPG__NONE; i < f->num_buffers; i++, c = f->node[c].next) {
        bpg__buffer *b = &f->buf[i];
        char what[32];
        snprintf(what, sizeof what, "buffer %u", (unsigned)i);
        b->node = c;
        b->kind = -1;
        if (f->node[c].type != BPG__OBJECT) { bpg__fail(f, BP_ERR_PARSE, "%s is not an object", what); return 0; }
        if (!bpg__need_int(f, c, "byteLength", &b->length, what)) return 0;
        b->uri = bpg__get(f, c, "uri", what);
        if (b->uri != BPG__NONE && f->node[b->uri].type != BPG__STRING) {
            bpg__fail(f, BP_ERR_PARSE, "%s: \"uri\" is not a string", what);
            return 0;
        }
        if (f->err->status != BP_OK) return 0;
        if (b->uri != BPG__NONE && !bpg__str_eq(f, f->node[b->uri].start, "") ) {
            char *u = bpg__uri(f, b->uri);
            if (!u) return 0;
            if (strncmp(u, "data:", 5) != 0) f->num_buffer_files++;
            bpg__freef(f, u);
        }
        if (i == 0 && f->glb && b->uri == BPG__NONE) {
            if (!f->has_bin) { bpg__fail(f, BP_ERR_PARSE, "buffer 0 has no uri, and the GLB has no BIN chunk"); return 0; }
            if (b->length > f->bin_size) {
                bpg__fail(f, BP_ERR_INDEX, "buffer 0: byteLength %llu is more than the %llu bytes of the GLB's BIN chunk",
                          (unsigned long long)b->length, (unsigned long long)f->bin_size);
                return 0;
            }
            b->kind = 0;
        }
    }
    return 1;
}

static int bpg__push_external(struct bpg__file *f, char *path)
{
    if (f->num_external == f->cap_external) {
        uint32_t cap = f->cap_external ? 2 * f->cap_external : 8;
        char **q = (char **)bpg__alloc_n(f, cap, sizeof *q);
        if (!q) return 0;
        if (f->num_external) memcpy(q, f->external, f->num_external * sizeof *q);
        bpg__freef(f, f->external);
        f->external = q;
        f->cap_external = cap;
    }
    f->external[f->num_external++] = path;
    return 1;
}

/* The external files of buffers and images (for bpg_external_file): each
   relative uri that decodes, joined to the folder. */
static void bpg__list_external(struct bpg__file *f, uint32_t images)
{
    uint32_t pass;
    if (!f->dir) return;
    for (pass = 0; pass < 2; pass++) {
        uint32_t arr = pass ? images : f->buffers, c;
        for (c = arr == BPG__NONE ? BPG__NONE : f->node[arr].first; c != BPG__NONE; c = f->node[c].next) {
            uint32_t u = bpg__get(f, c, "uri", pass ? "an image" : "a buffer");
            char *uri, *path = NULL;
            size_t bad, d = strlen(f->dir);
            if (f->err->status != BP_OK) return;
            if (u == BPG__NONE || f->node[u].type != BPG__STRING || !(uri = bpg__uri(f, u))) continue;
            if (strncmp(uri, "data:", 5) != 0 && !bpg__uri_absolute(uri) &&
                (path = (char *)bpg__alloc(f, d + strlen(uri) + 2)) != NULL) {
                memcpy(path, f->dir, d);
                if (d && f->dir[d - 1] != '/' && f->dir[d - 1] != '\\') path[d++] = '/';
                if (bpg__percent(uri, strlen(uri), path + d, &bad) < 0) { bpg__freef(f, path); path = NULL; }
            }
            bpg__freef(f, uri);
            if (path && !bpg__push_external(f, path)) bpg__freef(f, path);
        }
    }
}

/* Groups: each triangle primitive joins the first group whose primitive has
   the same attributes and targets, else starts one (its accessors checked). */
static int bpg__make_groups(struct bpg__file *f, uint32_t *gcount)
{
    uint32_t i, g;
    bpg__acc a;
    char pn[64], what[160];
    for (i = 0; i < f->num_prims; i++) {
        bpg__prim *p = &f->prim[i];
        for (g = 0; g < f->num_groups; g++) {
            const bpg__prim *q = &f->prim[f->group[g].prim];
            if (q->position == p->position && bpg__same_map(f, q->attributes, p->attributes) &&
                bpg__same_targets(f, q->targets, p->targets))
                break;
        }
        if (g == f->num_groups) {
            bpg__prim_name(f, p, pn, sizeof pn);
            snprintf(what, sizeof what, "accessor %u (POSITION of %s)", (unsigned)p->position, pn);
            if (!bpg__accessor(f, p->position, &a, what)) return 0;
            if (!bpg__check_group_accessors(f, p, a.count)) return 0;
            f->group[g].prim = i;
            f->group[g].count = a.count;
            gcount[g] = a.count;
            f->num_groups++;
        }
        p->group = g;
    }
    return 1;
}

/* The mesh: welded vertices, uv indices, triangles (see the essay). */
static int bpg__weld(struct bpg__file *f, bpg_file *file, const bpg__u32s *corner)
{
    bp_mesh *m = &file->mesh;
    size_t total = 0, *goff, c, nc = corner->n;
    uint32_t g, i, nw = 0, nu = 0, *wmap = NULL, *umap = NULL, *uvtag = NULL, *wuv = NULL, nref = 0;
    int any_uv = 0, ok = 0;
    const uint32_t REF = BPG__NONE - 1;
    if (!(goff = (size_t *)bpg__alloc_n(f, (size_t)f->num_groups + 1, sizeof *goff))) { bpg__oom(f, "welding"); return 0; }
    for (g = 0; g < f->num_groups; g++) { goff[g] = total; total += f->group[g].count; }
    goff[g] = total;
    for (i = 0; i < f->num_prims; i++) if (f->prim[i].texcoord != BPG__NONE && f->prim[i].num) any_uv = 1;
    wmap = (uint32_t *)bpg__alloc_n(f, total, sizeof *wmap);
    if (any_uv) umap = (uint32_t *)bpg__alloc_n(f, total, sizeof *umap);
    if (!wmap || (any_uv && !umap)) { bpg__oom(f, "welding"); goto done; }
    for (c = 0; c < total; c++) wmap[c] = BPG__NONE;
    for (i = 0; i < f->num_prims; i++) {
        const bpg__prim *p = &f->prim[i];
        for (c = 3 * (size_t)p->first; c < 3 * ((size_t)p->first + p->num); c++) {
            uint32_t *w = &wmap[goff[p->group] + corner->v[c]];
            if (*w == BPG__NONE) { *w = REF; if (++nref >= 0xfffffffeu) { bpg__fail(f, BP_ERR_TOO_LARGE, "more than 2^32 - 2 vertices"); goto done; } }
        }
    }
    m->positions = (double *)bpg__alloc_n(f, 3 * (size_t)nref, sizeof(double));
    f->vertex_src = (uint32_t *)bpg__alloc_n(f, nref, sizeof(uint32_t));
    f->vertex_group = (uint32_t *)bpg__alloc_n(f, nref, sizeof(uint32_t));
    if (any_uv) {
        m->uvs = (double *)bpg__alloc_n(f, 2 * (size_t)nref, sizeof(double));
        uvtag = (uint32_t *)bpg__alloc_n(f, nref, sizeof(uint32_t));
        wuv = (uint32_t *)bpg__alloc_n(f, nref, sizeof(uint32_t));
    }
    if (!m->positions || !f->vertex_src || !f->vertex_group || (any_uv && (!m->uvs || !uvtag || !wuv))) { bpg__oom(f, "welding"); goto done; }
    for (g = 0; g < f->num_groups; g++) {
        const bpg__prim *p = &f->prim[f->group[g].prim];
        uint32_t n = f->group[g].count, v, nw0 = nw;
        uint32_t *gw = wmap + goff[g];
        double *pos, *uv = NULL;
        bpg__set s;
        size_t here = 0;
        for (v = 0; v < n; v++) here += gw[v] == REF;
        f->group[g].vbase = nw;
        if (!here) continue;
        if (!(pos = bpg__group_values(f, p, p->position, 3))) goto done;
        if (!bpg__set_init(f, &s, here, m->positions, NULL, 3)) { bpg__freef(f, pos); bpg__oom(f, "welding"); goto done; }
        for (v = 0; v < n; v++) {
            const double *q = pos + 3 * (size_t)v;
            if (gw[v] != REF) continue;
            if (!(q[0] - q[0] == 0 && q[1] - q[1] == 0 && q[2] - q[2] == 0)) {
                bpg__fail(f, BP_ERR_NONFINITE, "accessor %u (POSITION of mesh %u primitive %u): vertex %u is NaN or infinite",
                          (unsigned)p->position, (unsigned)p->mesh, (unsigned)p->index, (unsigned)v);
                bpg__freef(f, s.slot); bpg__freef(f, pos);
                goto done;
            }
            memcpy(m->positions + 3 * (size_t)nw, pos + 3 * (size_t)v, 3 * sizeof(double));
            gw[v] = bpg__set_find(&s, pos + 3 * (size_t)v, 0, nw);
            if (gw[v] == nw) { f->vertex_src[nw] = v; f->vertex_group[nw] = g; nw++; }
        }
        bpg__freef(f, s.slot);
        bpg__freef(f, pos);
        f->group[g].vnum = nw - nw0;
        if (!any_uv) continue;
        if (p->texcoord != BPG__NONE) {
            if (!(uv = bpg__group_values(f, p, p->texcoord, 2))) goto done;
            if (!bpg__set_init(f, &s, here, m->uvs, uvtag, 2)) { bpg__freef(f, uv); bpg__oom(f, "welding"); goto done; }
            for (v = 0; v < n; v++) {
                const double *q = uv + 2 * (size_t)v;
                if (gw[v] >= REF) continue;
                if (!(q[0] - q[0] == 0 && q[1] - q[1] == 0)) {
                    bpg__fail(f, BP_ERR_NONFINITE, "accessor %u (TEXCOORD_%d of mesh %u primitive %u): vertex %u is NaN or infinite",
                              (unsigned)p->texcoord, f->texcoord, (unsigned)p->mesh, (unsigned)p->index, (unsigned)v);
                    bpg__freef(f, s.slot); bpg__freef(f, uv);
                    goto done;
                }
                memcpy(m->uvs + 2 * (size_t)nu, uv + 2 * (size_t)v, 2 * sizeof(double));
                uvtag[nu] = gw[v];
                umap[goff[g] + v] = bpg__set_find(&s, uv + 2 * (size_t)v, gw[v], nu);
                if (umap[goff[g] + v] == nu) nu++;
            }
            bpg__freef(f, s.slot);
            bpg__freef(f, uv);
        } else {                     /* no uvs here: one uv index per mesh vertex, no seams */
            for (v = nw0; v < nw; v++) wuv[v] = BPG__NONE;
            for (v = 0; v < n; v++) {
                if (gw[v] >= REF) continue;
                if (wuv[gw[v]] == BPG__NONE) { m->uvs[2 * (size_t)nu] = m->uvs[2 * (size_t)nu + 1] = 0; wuv[gw[v]] = nu++; }
                umap[goff[g] + v] = wuv[gw[v]];
            }
        }
    }
    m->num_vertices = nw;
    m->num_uvs = nu;
    m->num_triangles = m->num_faces = (uint32_t)(nc / 3);
    if (!(m->triangles = (uint32_t *)bpg__alloc_n(f, nc, sizeof(uint32_t))) ||
        (any_uv && !(m->corner_uv = (uint32_t *)bpg__alloc_n(f, nc, sizeof(uint32_t))))) { bpg__oom(f, "welding"); goto done; }
    for (i = 0; i < f->num_prims; i++) {
        const bpg__prim *p = &f->prim[i];
        for (c = 3 * (size_t)p->first; c < 3 * ((size_t)p->first + p->num); c++) {
            m->triangles[c] = wmap[goff[p->group] + corner->v[c]];
            if (any_uv) m->corner_uv[c] = umap[goff[p->group] + corner->v[c]];
        }
    }
    if (!any_uv) { bpg__freef(f, m->uvs); m->uvs = NULL; }
    ok = 1;
done:
    bpg__freef(f, goff); bpg__freef(f, wmap); bpg__freef(f, umap); bpg__freef(f, uvtag); bpg__freef(f, wuv);
    return ok;
}

static bp_status bpg__read_doc(struct bpg__file *f, bpg_file *file)
{
    uint32_t root, m, k, c, pc, i, *gcount = NULL;
    bpg__u32s corner, num;
    memset(&corner, 0, sizeof corner);
    memset(&num, 0, sizeof num);
    if (bpg__parse_json(f, &root) != BP_OK || !bpg__read_asset(f, root)) return f->err->status;
    if (!bpg__top_array(f, root, "buffers", &f->buffers, &f->num_buffers) ||
        !bpg__top_array(f, root, "bufferViews", &f->views, &f->num_views) ||
        !bpg__top_array(f, root, "accessors", &f->accessors, &f->num_accessors) ||
        !bpg__top_array(f, root, "meshes", &f->meshes, &file->num_meshes) ||
        !bpg__top_array(f, root, "images", &f->images, &f->num_images) || !bpg__read_buffers(f))
        return f->err->status;
    bpg__list_external(f, f->images);
    if (f->err->status != BP_OK) return f->err->status;
    /* the primitives */
    for (m = 0, pc = 0, c = f->meshes == BPG__NONE ? BPG__NONE : f->node[f->meshes].first; c != BPG__NONE; m++, c = f->node[c].next) {
        uint32_t prims = bpg__get(f, c, "primitives", "a mesh");
        if (f->node[c].type != BPG__OBJECT || prims == BPG__NONE || f->node[prims].type != BPG__ARRAY) {
            if (f->err->status == BP_OK) bpg__fail(f, BP_ERR_PARSE, "mesh %u has no \"primitives\" array", (unsigned)m);
            return f->err->status;
        }
        pc += f->node[prims].count;
    }
    if (!(f->prim = (bpg__prim *)bpg__calloc_n(f, pc, sizeof *f->prim)) ||
        !(f->group = (bpg__group *)bpg__calloc_n(f, pc, sizeof *f->group)) ||
        !(gcount = (uint32_t *)bpg__calloc_n(f, pc, sizeof *gcount)))
        return bpg__oom(f, "reading primitives");
    for (m = 0, c = f->meshes == BPG__NONE ? BPG__NONE : f->node[f->meshes].first; c != BPG__NONE; m++, c = f->node[c].next) {
        uint32_t prims = bpg__get(f, c, "primitives", "a mesh"), q;
        for (k = 0, q = f->node[prims].first; q != BPG__NONE; k++, q = f->node[q].next) {
            if (!bpg__read_primitive(f, file, m, k, q, &f->prim[f->num_prims])) goto fail;
            if (f->prim[f->num_prims].mode >= 4) f->num_prims++;
        }
    }
    if (!bpg__make_groups(f, gcount)) goto fail;
    for (i = 0; i < f->num_prims; i++)
        if (!bpg__prim_triangles(f, &f->prim[i], gcount[f->prim[i].group], &corner, &num)) goto fail;
    if (corner.n == 0) {
        bpg__fail(f, BP_ERR_EMPTY, "no triangles: of the file's %u primitives (%u meshes), none is a triangle primitive (mode 4, 5 or 6) with a triangle",
                  (unsigned)(f->num_prims + file->num_skipped), (unsigned)file->num_meshes);
        goto fail;
    }
    if (!bpg__weld(f, file, &corner)) goto fail;
    if (!(f->tri_prim = (uint32_t *)bpg__alloc_n(f, num.n, sizeof(uint32_t)))) { bpg__oom(f, "reading triangles"); goto fail; }
    for (i = 0; i < f->num_prims; i++)
        for (k = 0; k < f->prim[i].num; k++) f->tri_prim[f->prim[i].first + k] = i;
    f->corner_src = corner.v;
    f->tri_num = num.v;
    file->num_primitives = f->num_prims;
    file->num_groups = f->num_groups;
    file->has_uv = 1;
    for (i = 0; i < f->num_prims; i++) if (f->prim[i].texcoord == BPG__NONE && f->prim[i].num) file->has_uv = 0;
    bpg__freef(f, gcount);
    return BP_OK;
fail:
    bpg__freef(f, corner.v);
    bpg__freef(f, num.v);
    bpg__freef(f, gcount);
    return f->err->status;
}

/* ---- the containers: .glb chunks, .gltf text -------------------------------

   A .glb: a 12-byte header ("glTF", version 2, total length), then chunks
   of (length, type, data): the JSON chunk first, then at most one BIN
   chunk; chunks of other types are kept, in order, after the BIN chunk.
   Every length is checked against what is really there. */

static bp_status bpg__read_glb(struct bpg__file *f, unsigned char *d, size_t n)
{
    size_t at = 12;
    uint32_t k = 0, len;
    if (n < 12) return bpg__fail(f, BP_ERR_PARSE, "truncated GLB: %llu bytes, less than its 12-byte header", (unsigned long long)n);
    if (bpg__le32(d + 4) != 2)
        return bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "the GLB header says version %u: this reader reads glTF 2.0", (unsigned)bpg__le32(d + 4));
    len = bpg__le32(d + 8);
    if (len != n)
        return bpg__fail(f, BP_ERR_PARSE, "%s GLB: its header says %u bytes, the file has %llu", len > n ? "truncated" : "bad",
                         (unsigned)len, (unsigned long long)n);
    f->glb = 1;
    while (at < n) {
        uint32_t cl, ct;
        if (n - at < 8)
            return bpg__fail(f, BP_ERR_PARSE, "truncated GLB: chunk %u at byte %llu has no room for its 8-byte header", (unsigned)k,
                             (unsigned long long)at);
        cl = bpg__le32(d + at);
        ct = bpg__le32(d + at + 4);
        if (cl > n - at - 8)
            return bpg__fail(f, BP_ERR_PARSE, "GLB chunk %u at byte %llu says it has %u bytes, but only %llu follow", (unsigned)k,
                             (unsigned long long)at, (unsigned)cl, (unsigned long long)(n - at - 8));
        if (k == 0) {
            if (ct != 0x4E4F534Au)
                return bpg__fail(f, BP_ERR_PARSE, "the GLB's first chunk (byte 12) is not JSON (type 0x%08x)", (unsigned)ct);
            f->doc = (char *)d + at + 8;
            f->doc_len = cl;
            f->doc_offset = at + 8;
        } else if (ct == 0x004E4942u) {
            if (f->has_bin || k != 1)
                return bpg__fail(f, BP_ERR_PARSE, "GLB chunk %u at byte %llu is a BIN chunk, but only the second chunk may be one",
                                 (unsigned)k, (unsigned long long)at);
            f->bin = d + at + 8;
            f->bin_size = cl;
            f->has_bin = 1;
        } else if (!f->tail) {
            f->tail = d + at;
            f->tail_size = n - at;
        }
        at += 8 + (size_t)cl;
        k++;
    }
    if (k == 0) return bpg__fail(f, BP_ERR_PARSE, "the GLB has no JSON chunk");
    return BP_OK;
}

BPDEF void bpg_free(bpg_file *file)
{
    struct bpg__file *f;
    uint32_t i;
    if (!file) return;
    f = file->p;
    if (f) {
        bp_allocator a = f->a;
        for (i = 0; i < f->num_buffers && f->buf; i++) { bpg__freef(f, f->buf[i].owned); bpg__freef(f, f->buf[i].path); }
        for (i = 0; i < f->num_external; i++) bpg__freef(f, f->external[i]);
        bpg__freef(f, f->external);
        bpg__freef(f, f->buf);
        bpg__freef(f, f->node);
        bpg__freef(f, f->raw);
        bpg__freef(f, f->dir);
        bpg__freef(f, f->prim);
        bpg__freef(f, f->group);
        bpg__freef(f, f->tri_prim);
        bpg__freef(f, f->tri_num);
        bpg__freef(f, f->corner_src);
        bpg__freef(f, f->vertex_src);
        bpg__freef(f, f->vertex_group);
        bpg__freef(f, file->mesh.positions);
        bpg__freef(f, file->mesh.triangles);
        bpg__freef(f, file->mesh.corner_uv);
        bpg__freef(f, file->mesh.uvs);
        bpg__free_p(&a, f);
    }
    memset(file, 0, sizeof *file);
}

/* Takes `data` (allocated with the allocator of opt) whatever happens. */
static bp_status bpg__parse_owned(bpg_file *file, unsigned char *data, size_t size, const char *dir,
                                  const bpg_options *opt, bp_error *err)
{
    struct bpg__file *f;
    bp_allocator a;
    bp_error *e = err;
    memset(file, 0, sizeof *file);
    memset(&a, 0, sizeof a);
    if (opt) a = opt->allocator;
    f = (struct bpg__file *)(a.alloc ? a.alloc(a.user, sizeof *f) : malloc(sizeof *f));
    if (!f) {
        bpg__free_p(&a, data);
        if (e) { memset(e, 0, sizeof *e); e->status = BP_ERR_OUT_OF_MEMORY; e->index = e->index2 = -1;
                 snprintf(e->message, sizeof e->message, "out of memory reading a glTF file"); }
        return BP_ERR_OUT_OF_MEMORY;
    }
    memset(f, 0, sizeof *f);
    f->a = a;
    f->raw = data;
    f->err = err ? err : &f->scratch;
    memset(f->err, 0, sizeof *f->err);
    f->err->index = f->err->index2 = -1;
    f->buffers = f->views = f->accessors = f->meshes = f->images = BPG__NONE;
    f->texcoord = opt ? opt->texcoord : 0;
    file->p = f;
    if (f->texcoord < 0 || f->texcoord > 99) {
        bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "texcoord %d is not a set from 0 to 99", f->texcoord);
    } else if (dir && !(f->dir = (char *)bpg__alloc(f, strlen(dir) + 1))) bpg__oom(f, "reading");
    else {
        if (dir) strcpy(f->dir, dir);
        if (size >= 4 && memcmp(data, "glTF", 4) == 0) bpg__read_glb(f, data, size);
        else { f->doc = (char *)data; f->doc_len = size; }
        if (f->err->status == BP_OK) bpg__read_doc(f, file);
    }
    if (f->err->status != BP_OK) {
        bp_status st = f->err->status;
        bpg_free(file);
        return st;
    }
    file->glb = f->glb;
    file->num_buffer_files = f->num_buffer_files;
    return BP_OK;
}

BPDEF bp_status bpg_parse(bpg_file *file, const void *data, size_t size, const char *dir,
                          const bpg_options *opt, bp_error *err)
{
    bp_allocator a;
    unsigned char *copy;
    memset(&a, 0, sizeof a);
    if (opt) a = opt->allocator;
    copy = (unsigned char *)(a.alloc ? a.alloc(a.user, size ? size : 1) : malloc(size ? size : 1));
    if (!copy) {
        memset(file, 0, sizeof *file);
        if (err) { memset(err, 0, sizeof *err); err->status = BP_ERR_OUT_OF_MEMORY; err->index = err->index2 = -1;
                   snprintf(err->message, sizeof err->message, "out of memory copying a glTF file"); }
        return BP_ERR_OUT_OF_MEMORY;
    }
    if (size) memcpy(copy, data, size);
    return bpg__parse_owned(file, copy, size, dir, opt, err);
}

BPDEF bp_status bpg_read(bpg_file *file, const char *path, const bpg_options *opt, bp_error *err)
{
    bp_allocator a;
    FILE *fp;
    unsigned char *data = NULL;
    size_t n = 0, cap = 0;
    char *dir;
    const char *slash = NULL, *s;
    bp_status st;
    bp_error scratch, *e = err ? err : &scratch;
    memset(&a, 0, sizeof a);
    if (opt) a = opt->allocator;
    memset(file, 0, sizeof *file);
    memset(e, 0, sizeof *e);
    e->index = e->index2 = -1;
    if (!(fp = fopen(path, "rb"))) {
        e->status = BP_ERR_IO;
        snprintf(e->message, sizeof e->message, "cannot open: %s", strerror(errno));
        return BP_ERR_IO;
    }
    for (;;) {                                /* read it all, growing the block */
        size_t got;
        if (n == cap) {
            size_t nc = cap ? 2 * cap : 1 << 16;
            unsigned char *q = nc > cap ? (unsigned char *)(a.alloc ? a.alloc(a.user, nc) : malloc(nc)) : NULL;
            if (!q) {
                fclose(fp); bpg__free_p(&a, data);
                e->status = BP_ERR_OUT_OF_MEMORY;
                snprintf(e->message, sizeof e->message, "out of memory reading the file");
                return BP_ERR_OUT_OF_MEMORY;
            }
            if (n) memcpy(q, data, n);
            bpg__free_p(&a, data);
            data = q;
            cap = nc;
        }
        got = fread(data + n, 1, cap - n, fp);
        n += got;
        if (got == 0) break;
    }
    if (ferror(fp)) {
        fclose(fp); bpg__free_p(&a, data);
        e->status = BP_ERR_IO;
        snprintf(e->message, sizeof e->message, "cannot read the file");
        return BP_ERR_IO;
    }
    fclose(fp);
    for (s = path; *s; s++) if (*s == '/' || *s == '\\') slash = s;
    dir = (char *)(a.alloc ? a.alloc(a.user, (size_t)(slash ? slash - path + 2 : 1)) : malloc((size_t)(slash ? slash - path + 2 : 1)));
    if (!dir) {
        bpg__free_p(&a, data);
        e->status = BP_ERR_OUT_OF_MEMORY;
        snprintf(e->message, sizeof e->message, "out of memory reading the file");
        return BP_ERR_OUT_OF_MEMORY;
    }
    if (slash) { memcpy(dir, path, (size_t)(slash - path + 1)); dir[slash - path + 1] = 0; } else dir[0] = 0;
    st = bpg__parse_owned(file, data, n, dir, opt, err);
    bpg__free_p(&a, dir);
    return st;
}

/* ---- naming ------------------------------------------------------------- */

BPDEF void bpg_name_triangle(const bpg_file *file, uint32_t t, char *buf, size_t size)
{
    const struct bpg__file *f = file ? file->p : NULL;
    const bpg__prim *p;
    const uint32_t *cs;
    if (!size) return;
    buf[0] = 0;
    if (!f || t >= file->mesh.num_triangles) return;
    p = &f->prim[f->tri_prim[t]];
    cs = f->corner_src + 3 * (size_t)t;
    snprintf(buf, size, "mesh %u primitive %u triangle %u (vertices %u %u %u)", (unsigned)p->mesh, (unsigned)p->index,
             (unsigned)f->tri_num[t], (unsigned)cs[0], (unsigned)cs[1], (unsigned)cs[2]);
}

BPDEF void bpg_name_vertex(const bpg_file *file, uint32_t v, char *buf, size_t size)
{
    const struct bpg__file *f = file ? file->p : NULL;
    const bpg__prim *p;
    if (!size) return;
    buf[0] = 0;
    if (!f || v >= file->mesh.num_vertices) return;
    p = &f->prim[f->group[f->vertex_group[v]].prim];
    snprintf(buf, size, "vertex %u of accessor %u (POSITION of mesh %u primitive %u)", (unsigned)f->vertex_src[v],
             (unsigned)p->position, (unsigned)p->mesh, (unsigned)p->index);
}

BPDEF const char *bpg_external_file(const bpg_file *file, uint32_t i)
{
    return file && file->p && i < file->p->num_external ? file->p->external[i] : NULL;
}

BPDEF int bpg_is_gltf_path(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    const char *e;
    if (n >= 5 && path[n - 5] == '.') { e = path + n - 4; return (e[0] | 32) == 'g' && (e[1] | 32) == 'l' && (e[2] | 32) == 't' && (e[3] | 32) == 'f'; }
    if (n >= 4 && path[n - 4] == '.') { e = path + n - 3; return (e[0] | 32) == 'g' && (e[1] | 32) == 'l' && (e[2] | 32) == 'b'; }
    return 0;
}

/* ---- writing: byte strings and JSON edits ----------------------------------

   The output JSON is the input's text with edits applied: each edit
   replaces the bytes [at, end) (an insertion when end == at) with its
   text.  Edits never overlap; those at one place keep the order they were
   made in. */

typedef struct bpg__out {
    struct bpg__file *f;
    unsigned char *d;
    size_t n, cap;
    int failed;
} bpg__out;

static void bpg__o_put(bpg__out *o, const void *p, size_t n)
{
    if (o->failed) return;
    if (n > o->cap - o->n) {
        size_t cap = o->cap ? o->cap : 256;
        unsigned char *q;
        while (cap - o->n < n) {
            if (cap > (size_t)-1 / 2) { o->failed = 1; return; }
            cap *= 2;
        }
        if (!(q = (unsigned char *)bpg__alloc(o->f, cap))) { o->failed = 1; return; }
        if (o->n) memcpy(q, o->d, o->n);
        bpg__freef(o->f, o->d);
        o->d = q;
        o->cap = cap;
    }
    if (n) memcpy(o->d + o->n, p, n);
    o->n += n;
}

static void bpg__o_str(bpg__out *o, const char *s) { bpg__o_put(o, s, strlen(s)); }

static void bpg__o_uint(bpg__out *o, uint64_t x)
{
    char b[24];
    int i = 24;
    do { b[--i] = (char)('0' + x % 10); x /= 10; } while (x);
    bpg__o_put(o, b + i, (size_t)(24 - i));
}

static void bpg__o_zeros(bpg__out *o, size_t n, unsigned char byte)
{
    unsigned char z[64];
    memset(z, byte, sizeof z);
    while (n) { size_t k = n < sizeof z ? n : sizeof z; bpg__o_put(o, z, k); n -= k; }
}

static void bpg__o_align(bpg__out *o, size_t a, unsigned char byte)
{
    if (o->n % a) bpg__o_zeros(o, a - o->n % a, byte);
}

/* base64 of d[0, n) onto o. */
static void bpg__o_base64(bpg__out *o, const unsigned char *d, size_t n)
{
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t i;
    char q[4];
    for (i = 0; i + 2 < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (uint32_t)d[i + 1] << 8 | d[i + 2];
        q[0] = al[v >> 18]; q[1] = al[v >> 12 & 63]; q[2] = al[v >> 6 & 63]; q[3] = al[v & 63];
        bpg__o_put(o, q, 4);
    }
    if (n - i == 1) { uint32_t v = (uint32_t)d[i] << 16; q[0] = al[v >> 18]; q[1] = al[v >> 12 & 63]; q[2] = q[3] = '='; bpg__o_put(o, q, 4); }
    if (n - i == 2) { uint32_t v = (uint32_t)d[i] << 16 | (uint32_t)d[i + 1] << 8;
                      q[0] = al[v >> 18]; q[1] = al[v >> 12 & 63]; q[2] = al[v >> 6 & 63]; q[3] = '='; bpg__o_put(o, q, 4); }
}

typedef struct bpg__edit { size_t at, end, text, len; uint32_t seq; } bpg__edit;

typedef struct bpg__enc {
    const bpg_file *file;
    struct bpg__file *f;
    const bp_atlas *atlas;
    const bpg_write_options *wo;
    bpg__out text;              /* the texts of the edits                    */
    bpg__out data;              /* the new bytes (bufferViews, 4-aligned)    */
    bpg__out acc, views;        /* new accessors and bufferViews (JSON)      */
    bpg__edit *edit;
    uint32_t num_edits, cap_edits;
    uint32_t num_new_acc, num_new_views;
    uint32_t new_buffer;        /* the buffer the new bytes go to             */
    uint64_t data_base;         /* their offset in it                         */
    uint32_t *chart_base;       /* first global chart vertex of each chart    */
    float    *uv;               /* per global chart vertex: u, v (glTF's)     */
    unsigned char *flip;        /* per mesh triangle: written (0, 2, 1)       */
    char     texkey[16];
    uint32_t vertices_in, vertices_out, fixed;
    uint32_t acc_base, view_base; /* the first new accessor and bufferView    */
    uint32_t *acc_new, *view_new; /* per input accessor, bufferView: its index
                                     in the output, BPG__NONE: removed        */
    uint64_t *cut;              /* buffer 0's removed 4-byte units [a, b)    */
    uint32_t num_cuts;
    const unsigned char *bin;   /* buffer 0 (the BIN chunk) as written       */
    unsigned char *bin_owned;
    size_t   bin_len;
    uint32_t accessors_removed, views_removed;
} bpg__enc;

/* An edit: text (already in e->text from `from`) replaces [at, end). */
static int bpg__edit_add(bpg__enc *e, size_t at, size_t end, size_t from)
{
    bpg__edit *x;
    if (e->text.failed) return 0;
    if (e->num_edits == e->cap_edits) {
        uint32_t cap = e->cap_edits ? 2 * e->cap_edits : 64;
        bpg__edit *q = (bpg__edit *)bpg__alloc_n(e->f, cap, sizeof *q);
        if (!q) return 0;
        if (e->num_edits) memcpy(q, e->edit, e->num_edits * sizeof *q);
        bpg__freef(e->f, e->edit);
        e->edit = q;
        e->cap_edits = cap;
    }
    x = &e->edit[e->num_edits];
    x->at = at; x->end = end; x->text = from; x->len = e->text.n - from; x->seq = e->num_edits;
    e->num_edits++;
    return 1;
}

/* Replace a JSON value by an unsigned integer. */
static int bpg__edit_uint(bpg__enc *e, uint32_t node, uint64_t x)
{
    size_t from = e->text.n;
    bpg__o_uint(&e->text, x);
    return bpg__edit_add(e, e->f->node[node].start, e->f->node[node].end, from);
}

static int bpg__edit_cmp(const void *a, const void *b)
{
    const bpg__edit *x = (const bpg__edit *)a, *y = (const bpg__edit *)b;
    if (x->at != y->at) return x->at < y->at ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

/* A new bufferView over the new bytes [off, off + len). */
static uint32_t bpg__new_view(bpg__enc *e, size_t off, size_t len, size_t stride, int target)
{
    bpg__out *o = &e->views;
    if (e->num_new_views) bpg__o_str(o, ",");
    bpg__o_str(o, "{\"buffer\":");
    bpg__o_uint(o, e->new_buffer);
    bpg__o_str(o, ",\"byteOffset\":");
    bpg__o_uint(o, e->data_base + off);
    bpg__o_str(o, ",\"byteLength\":");
    bpg__o_uint(o, len);
    if (stride) { bpg__o_str(o, ",\"byteStride\":"); bpg__o_uint(o, stride); }
    bpg__o_str(o, ",\"target\":");
    bpg__o_uint(o, (uint64_t)target);
    bpg__o_str(o, "}");
    return e->view_base + e->num_new_views++;
}

/* A new accessor: `old` (an accessor node) with its bufferView and count
   replaced and its byteOffset and sparse dropped, every other member (type,
   componentType, normalized, min, max, name, extras, extensions) copied as
   written; old BPG__NONE: a plain one of the given type. */
static uint32_t bpg__new_accessor(bpg__enc *e, uint32_t old, uint32_t view, uint32_t count, int ctype, const char *type)
{
    struct bpg__file *f = e->f;
    bpg__out *o = &e->acc;
    uint32_t c;
    int n = 0;
    if (e->num_new_acc) bpg__o_str(o, ",");
    bpg__o_str(o, "{");
    if (old == BPG__NONE || bpg__get(f, old, "bufferView", "an accessor") == BPG__NONE) {
        bpg__o_str(o, "\"bufferView\":");
        bpg__o_uint(o, view);
        n++;
    }
    if (old == BPG__NONE) {
        bpg__o_str(o, ",\"componentType\":");
        bpg__o_uint(o, (uint64_t)ctype);
        bpg__o_str(o, ",\"count\":");
        bpg__o_uint(o, count);
        bpg__o_str(o, ",\"type\":\"");
        bpg__o_str(o, type);
        bpg__o_str(o, "\"");
    } else
        for (c = f->node[old].first; c != BPG__NONE; c = f->node[c].next) {
            const bpg__node *m = &f->node[c];
            if (bpg__str_eq(f, m->key, "byteOffset") || bpg__str_eq(f, m->key, "sparse")) continue;
            if (n++) bpg__o_str(o, ",");
            bpg__o_put(o, f->doc + m->key, m->key_end - m->key);
            bpg__o_str(o, ":");
            if (bpg__str_eq(f, m->key, "bufferView")) bpg__o_uint(o, view);
            else if (bpg__str_eq(f, m->key, "count")) bpg__o_uint(o, count);
            else bpg__o_put(o, f->doc + m->start, m->end - m->start);
        }
    bpg__o_str(o, "}");
    return e->acc_base + e->num_new_acc++;
}

/* ---- writing: the map -------------------------------------------------------

   The written uv of a corner is its chart vertex's: chart vertex i of
   chart c is global vertex chart_base[c] + i, and its (u, v) in the file
   is ((float)u, (float)(1 - v)).  Rounding to float moves each coordinate
   by at most half a float step, which can flip a sliver whose height is
   about that step; the rounded map is checked exactly as a whole
   (bp_check over every mapped chart, with v negated: (u, -v_file) is the
   library's map translated, so orientations and overlaps are the same),
   and a corner of a flipped triangle is moved to a nearby float point
   (up to 3 steps in u and v) where every triangle around it is positive. */

static float bpg__nan(void)
{
    uint32_t bits = 0x7fc00000u;
    float x;
    memcpy(&x, &bits, 4);
    return x;
}

static float bpg__step(float x, int k)
{
    for (; k > 0; k--) x = nextafterf(x, 3.0e38f);
    for (; k < 0; k++) x = nextafterf(x, -3.0e38f);
    return x;
}

/* The global chart triangle list of the mapped charts and the rounded map
   as doubles (u, -v); tstart[c]: chart c's first global triangle. */
typedef struct bpg__rmap {
    uint32_t *tri, *tstart, *vt_start, *vt;   /* triangles; vertex -> triangles (CSR) */
    double   *xy;
    uint32_t  nt, nv;
} bpg__rmap;

static int bpg__vertex_ok(const bpg__rmap *r, uint32_t v)
{
    uint32_t k;
    for (k = r->vt_start[v]; k < r->vt_start[v + 1]; k++) {
        const uint32_t *t = r->tri + 3 * (size_t)r->vt[k];
        if (bp_orient2d(r->xy + 2 * (size_t)t[0], r->xy + 2 * (size_t)t[1], r->xy + 2 * (size_t)t[2]) <= 0) return 0;
    }
    return 1;
}

/* Vertex -> triangles (CSR) of the rounded map, made once. */
static int bpg__build_vt(struct bpg__file *f, bpg__rmap *r)
{
    uint32_t t, v, k;
    if (r->vt) return 1;
    r->vt_start = (uint32_t *)bpg__calloc_n(f, (size_t)r->nv + 1, sizeof(uint32_t));
    r->vt = (uint32_t *)bpg__alloc_n(f, 3 * (size_t)r->nt, sizeof(uint32_t));
    if (!r->vt_start || !r->vt) return 0;
    for (k = 0; k < 3 * r->nt; k++) r->vt_start[r->tri[k] + 1]++;
    for (v = 0; v < r->nv; v++) r->vt_start[v + 1] += r->vt_start[v];
    for (t = 0; t < r->nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t w = r->tri[3 * (size_t)t + k];
            r->vt[r->vt_start[w]++] = t;
        }
    for (v = r->nv; v > 0; v--) r->vt_start[v] = r->vt_start[v - 1];
    r->vt_start[0] = 0;
    return 1;
}

/* The corner of triangle t at vertex x (0-2), or 3. */
static int bpg__corner(const bpg__rmap *r, uint32_t t, uint32_t x)
{
    int k;
    for (k = 0; k < 3 && r->tri[3 * (size_t)t + k] != x; k++) {}
    return k;
}

/* Boundary edges at x: out = 1 those leaving x (x -> y), 0 those entering
   (y -> x); the other ends into ends[0, 8), their number returned.  An edge
   is on the boundary when no triangle has it the other way. */
static int bpg__boundary_at(const bpg__rmap *r, uint32_t x, int out, uint32_t *ends)
{
    uint32_t i, j;
    int n = 0;
    for (i = r->vt_start[x]; i < r->vt_start[x + 1] && n < 8; i++) {
        const uint32_t *t = r->tri + 3 * (size_t)r->vt[i];
        int k = bpg__corner(r, r->vt[i], x), twin = 0;
        uint32_t y = t[out ? (k + 1) % 3 : (k + 2) % 3];
        for (j = r->vt_start[x]; j < r->vt_start[x + 1] && !twin; j++) {
            const uint32_t *s = r->tri + 3 * (size_t)r->vt[j];
            int m = bpg__corner(r, r->vt[j], x);
            twin = s[out ? (m + 2) % 3 : (m + 1) % 3] == y;
        }
        if (!twin) ends[n++] = y;
    }
    return n;
}

static int bpg__meet(const bpg__rmap *r, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    return bp_segments_intersect(r->xy + 2 * (size_t)a, r->xy + 2 * (size_t)b, r->xy + 2 * (size_t)c, r->xy + 2 * (size_t)d);
}

/* Is vertex w, where it is now, clear of edge (c, d): every triangle
   around it positive, and no boundary edge at it meeting (c, d) (edges
   sharing an end with it aside)? */
static int bpg__clear_of(const bpg__rmap *r, uint32_t w, uint32_t c, uint32_t d)
{
    uint32_t ends[8];
    int out, n, k;
    if (!bpg__vertex_ok(r, w)) return 0;
    for (out = 0; out < 2; out++) {
        n = bpg__boundary_at(r, w, out, ends);
        for (k = 0; k < n; k++)
            if (ends[k] != c && ends[k] != d && w != c && w != d && bpg__meet(r, w, ends[k], c, d)) return 0;
    }
    return 1;
}

/* Try the float points near vertex w (|du|, |dv| <= 3 steps, nearest
   first) until ok(w) holds; keeps the first that does.  ok: the kind of
   clearance wanted, with (c, d) the edge to clear (unused for flips). */
static int bpg__nudge(bpg__enc *e, bpg__rmap *r, uint32_t w, uint32_t c, uint32_t d, int crossing)
{
    float u0 = e->uv[2 * (size_t)w], v0 = e->uv[2 * (size_t)w + 1];
    int radius, du, s;
    for (radius = 1; radius <= 6; radius++)
        for (du = -radius; du <= radius; du++) {
            int dv = radius - (du < 0 ? -du : du);
            if (du > 3 || du < -3 || dv > 3) continue;
            for (s = 0; s < (dv ? 2 : 1); s++) {
                float u1 = bpg__step(u0, du), v1 = bpg__step(v0, s ? -dv : dv);
                r->xy[2 * (size_t)w] = u1;
                r->xy[2 * (size_t)w + 1] = -(double)v1;
                if (crossing ? bpg__clear_of(r, w, c, d) : bpg__vertex_ok(r, w)) {
                    e->uv[2 * (size_t)w] = u1;
                    e->uv[2 * (size_t)w + 1] = v1;
                    return 1;
                }
            }
        }
    r->xy[2 * (size_t)w] = u0;
    r->xy[2 * (size_t)w + 1] = -(double)v0;
    return 0;
}

/* Move a corner of each non-positive triangle; the number moved. */
static uint32_t bpg__fix_flips(bpg__enc *e, bpg__rmap *r)
{
    uint32_t t, moved = 0;
    for (t = 0; t < r->nt; t++) {
        const uint32_t *tr = r->tri + 3 * (size_t)t;
        int c;
        if (bp_orient2d(r->xy + 2 * (size_t)tr[0], r->xy + 2 * (size_t)tr[1], r->xy + 2 * (size_t)tr[2]) > 0) continue;
        for (c = 0; c < 3; c++) if (bpg__nudge(e, r, tr[c], 0, 0, 0)) { moved++; break; }
    }
    return moved;
}

/* Two boundary edges that meet, leaving the vertices a and c (bp_check's
   report): move one of their four ends until they are apart. */
static int bpg__fix_crossing(bpg__enc *e, bpg__rmap *r, uint32_t a, uint32_t c)
{
    uint32_t ea[8], ec[8];
    int na = bpg__boundary_at(r, a, 1, ea), nc = bpg__boundary_at(r, c, 1, ec), i, j;
    for (i = 0; i < na; i++)
        for (j = 0; j < nc; j++) {
            uint32_t b = ea[i], d = ec[j];
            if (a == c || a == d || b == c || b == d || !bpg__meet(r, a, b, c, d)) continue;
            if (bpg__nudge(e, r, a, c, d, 1) || bpg__nudge(e, r, b, c, d, 1) ||
                bpg__nudge(e, r, c, a, b, 1) || bpg__nudge(e, r, d, a, b, 1))
                return 1;
        }
    return 0;
}

/* Name chart triangle `gt` of the rounded map check as the file does. */
static void bpg__name_chart_triangle(bpg__enc *e, const bpg__rmap *r, uint32_t gt, char *buf, size_t size)
{
    const bp_atlas *at = e->atlas;
    uint32_t lo = 0, hi = at->num_charts;
    while (hi - lo > 1) { uint32_t mid = lo + (hi - lo) / 2; if (r->tstart[mid] <= gt) lo = mid; else hi = mid; }
    {
        char nm[200];
        const bp_chart *ch = &at->charts[lo];
        uint32_t lt = gt - r->tstart[lo];
        bpg_name_triangle(e->file, lt < ch->num_triangles ? ch->face[lt] : BPG__NONE, nm, sizeof nm);
        snprintf(buf, size, "chart %u, %s", (unsigned)lo, nm);
    }
}

/* Name global chart vertex `gv` as the file does. */
static void bpg__name_chart_vertex(bpg__enc *e, uint32_t gv, char *buf, size_t size)
{
    const bp_atlas *at = e->atlas;
    uint32_t lo = 0, hi = at->num_charts;
    char nm[200];
    while (hi - lo > 1) { uint32_t mid = lo + (hi - lo) / 2; if (e->chart_base[mid] <= gv) lo = mid; else hi = mid; }
    bpg_name_vertex(e->file, at->charts[lo].vertex[gv - e->chart_base[lo]], nm, sizeof nm);
    snprintf(buf, size, "chart %u, %s", (unsigned)lo, nm);
}

static bp_status bpg__round_check(bpg__enc *e, uint32_t nv)
{
    struct bpg__file *f = e->f;
    const bp_atlas *at = e->atlas;
    bpg__rmap r;
    bp_check_report rep;
    bp_error ce;
    bp_status st;
    uint32_t c, i, nt = 0;
    int round;
    const bp_options *opt = e->wo ? e->wo->check : NULL;
    memset(&r, 0, sizeof r);
    for (c = 0; c < at->num_charts; c++) if (at->charts[c].uv) nt += at->charts[c].num_triangles;
    r.nt = nt; r.nv = nv;
    r.tri = (uint32_t *)bpg__alloc_n(f, 3 * (size_t)nt, sizeof(uint32_t));
    r.tstart = (uint32_t *)bpg__alloc_n(f, (size_t)at->num_charts + 1, sizeof(uint32_t));
    r.xy = (double *)bpg__alloc_n(f, 2 * (size_t)nv, sizeof(double));
    if (!r.tri || !r.tstart || !r.xy) { st = bpg__oom(f, "checking the rounded map"); goto done; }
    for (i = 0; i < nv; i++) {
        float u = e->uv[2 * (size_t)i], v = e->uv[2 * (size_t)i + 1];
        r.xy[2 * (size_t)i] = u != u ? 0.0 : u;
        r.xy[2 * (size_t)i + 1] = v != v ? 0.0 : -(double)v;
    }
    for (c = 0, nt = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        r.tstart[c] = nt;
        if (!ch->uv) continue;
        for (i = 0; i < 3 * ch->num_triangles; i++) r.tri[3 * (size_t)nt + i] = e->chart_base[c] + ch->triangles[i];
        nt += ch->num_triangles;
    }
    r.tstart[at->num_charts] = nt;
    st = bp_check_opt(r.tri, r.nt, r.xy, r.nv, opt, &rep, &ce);
    /* repairs: the flipped triangles in one pass, then the crossings one
       by one (each time the whole map checked again) */
    for (round = 0; st == BP_ERR_NOT_BIJECTIVE && round < 256; round++) {
        uint32_t moved = 0;
        if (!bpg__build_vt(f, &r)) { st = bpg__oom(f, "checking the rounded map"); goto done; }
        if (rep.flipped || rep.degenerate) moved = bpg__fix_flips(e, &r);
        else if (rep.boundary_intersections && rep.first_bad_edge[0] >= 0 && rep.first_bad_edge[1] >= 0)
            moved = (uint32_t)bpg__fix_crossing(e, &r, (uint32_t)rep.first_bad_edge[0], (uint32_t)rep.first_bad_edge[1]);
        if (!moved) break;
        e->fixed += moved;
        st = bp_check_opt(r.tri, r.nt, r.xy, r.nv, opt, &rep, &ce);
    }
    if (st == BP_ERR_NOT_BIJECTIVE || st == BP_ERR_NONFINITE) {
        char nm[300] = "";
        if (rep.first_bad_triangle >= 0) bpg__name_chart_triangle(e, &r, (uint32_t)rep.first_bad_triangle, nm, sizeof nm);
        else if (rep.first_bad_edge[0] >= 0 && rep.first_bad_edge[0] < (int64_t)nv)
            bpg__name_chart_vertex(e, (uint32_t)rep.first_bad_edge[0], nm, sizeof nm);
        st = bpg__fail(f, BP_ERR_NOT_BIJECTIVE, "the map rounded to 32-bit floats (glTF's %s) is not bijective%s%s: %u flipped, %u degenerate, "
                       "%u boundary intersections (the double map is; write OBJ to keep it)", e->texkey, nm[0] ? " at " : "", nm,
                       (unsigned)rep.flipped, (unsigned)rep.degenerate, (unsigned)rep.boundary_intersections);
    } else if (st != BP_OK) st = bpg__fail(f, st, "checking the rounded map: %s", ce.message);
done:
    bpg__freef(f, r.tri); bpg__freef(f, r.tstart); bpg__freef(f, r.xy); bpg__freef(f, r.vt_start); bpg__freef(f, r.vt);
    return st;
}

/* chart_base, the rounded uvs, the repaired orientations, then the check. */
static bp_status bpg__prepare_map(bpg__enc *e)
{
    struct bpg__file *f = e->f;
    const bp_atlas *at = e->atlas;
    const bp_mesh *m = &e->file->mesh;
    uint64_t nv = 0;
    uint32_t c, i, t;
    size_t k;
    if (!at || at->num_corners != 3 * m->num_triangles || !at->corner_chart || !at->corner_vertex || !at->charts)
        return bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "the atlas was not built on this file's mesh (%u corners, the mesh has %u)",
                         at ? (unsigned)at->num_corners : 0u, (unsigned)(3 * m->num_triangles));
    if (!(e->chart_base = (uint32_t *)bpg__alloc_n(f, (size_t)at->num_charts + 1, sizeof(uint32_t))))
        return bpg__oom(f, "writing");
    for (c = 0; c < at->num_charts; c++) {
        e->chart_base[c] = (uint32_t)nv;
        nv += at->charts[c].num_vertices;
        if (nv >= BPG__NONE) return bpg__fail(f, BP_ERR_TOO_LARGE, "the atlas has more than 2^32 - 2 chart vertices");
    }
    e->chart_base[at->num_charts] = (uint32_t)nv;
    for (k = 0; k < 3 * (size_t)m->num_triangles; k++)
        if (at->corner_chart[k] >= at->num_charts || at->corner_vertex[k] >= at->charts[at->corner_chart[k]].num_vertices)
            return bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "the atlas was not built on this file's mesh (corner %llu)", (unsigned long long)k);
    if (!(e->uv = (float *)bpg__alloc_n(f, 2 * (size_t)nv + 2, sizeof(float))) ||
        !(e->flip = (unsigned char *)bpg__calloc_n(f, m->num_triangles, 1)))
        return bpg__oom(f, "writing");
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        for (i = 0; i < ch->num_vertices; i++) {
            float *q = e->uv + 2 * ((size_t)e->chart_base[c] + i);
            if (ch->uv) { q[0] = (float)ch->uv[2 * (size_t)i]; q[1] = (float)(1.0 - ch->uv[2 * (size_t)i + 1]); }
            else q[0] = q[1] = bpg__nan();
        }
        /* the repaired orientation (as the OBJ writers read it) */
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t, fc = ch->face[t];
            const uint32_t *cv = at->corner_vertex + 3 * (size_t)fc;
            if (fc < m->num_triangles && tr[0] == cv[0] && tr[1] == cv[2] && tr[2] == cv[1] && tr[1] != tr[2]) e->flip[fc] = 1;
        }
    }
    return bpg__round_check(e, (uint32_t)nv);
}

/* ---- writing: one vertex set ------------------------------------------------

   Output vertices of a group: vertex v of the input stays v for the first
   chart vertex its corners meet; each further chart vertex at v (a seam
   through v) gets a copy after the group's count.  (v, chart vertex)
   pairs beyond the first are found in a small open-addressing table. */

typedef struct bpg__split {
    uint64_t *key;
    uint32_t *val;
    size_t    mask, n;
} bpg__split;

static int bpg__split_grow(struct bpg__file *f, bpg__split *s)
{
    size_t cap = s->mask ? 2 * (s->mask + 1) : 1024, i;
    uint64_t *k = (uint64_t *)bpg__alloc_n(f, cap, sizeof *k);
    uint32_t *v = (uint32_t *)bpg__alloc_n(f, cap, sizeof *v);
    if (!k || !v) { bpg__freef(f, k); bpg__freef(f, v); return 0; }
    for (i = 0; i < cap; i++) k[i] = ~(uint64_t)0;
    for (i = 0; s->mask && i <= s->mask; i++)
        if (s->key[i] != ~(uint64_t)0) {
            size_t j = (size_t)bpg__mix(s->key[i]) & (cap - 1);
            while (k[j] != ~(uint64_t)0) j = (j + 1) & (cap - 1);
            k[j] = s->key[i]; v[j] = s->val[i];
        }
    bpg__freef(f, s->key); bpg__freef(f, s->val);
    s->key = k; s->val = v; s->mask = cap - 1;
    return 1;
}

/* The copy number of (v, chart vertex g), `fresh` if new; BPG__NONE on OOM. */
static uint32_t bpg__split_find(struct bpg__file *f, bpg__split *s, uint32_t v, uint32_t g, uint32_t fresh)
{
    uint64_t key = (uint64_t)v << 32 | g;
    size_t j;
    if (2 * (s->n + 1) > s->mask && !bpg__split_grow(f, s)) return BPG__NONE;
    for (j = (size_t)bpg__mix(key) & s->mask; s->key[j] != ~(uint64_t)0; j = (j + 1) & s->mask)
        if (s->key[j] == key) return s->val[j];
    s->key[j] = key; s->val[j] = fresh; s->n++;
    return fresh;
}

/* New indices of the attributes of a group, by name (and target). */
typedef struct bpg__renamed { char name[64]; uint32_t target, acc; } bpg__renamed;

/* Duplicate accessor `idx` over the output vertices (src: the input vertex
   of each) into a new accessor; returns it, BPG__NONE on error. */
static uint32_t bpg__dup_accessor(bpg__enc *e, uint32_t idx, const uint32_t *src, uint32_t n, uint32_t out_n, const char *what)
{
    struct bpg__file *f = e->f;
    bpg__acc a;
    unsigned char *packed, pad[4] = { 0, 0, 0, 0 };
    size_t eo, off;
    uint32_t j;
    if (!bpg__accessor(f, idx, &a, what) || !(packed = bpg__fetch(f, &a))) return BPG__NONE;
    eo = (a.esize + 3) / 4 * 4;                  /* vertex attributes start on 4-byte boundaries */
    bpg__o_align(&e->data, 4, 0);
    off = e->data.n;
    for (j = 0; j < out_n; j++) {
        bpg__o_put(&e->data, packed + (size_t)(j < n ? j : src[j - n]) * a.esize, a.esize);
        if (eo > a.esize) bpg__o_put(&e->data, pad, eo - a.esize);
    }
    bpg__freef(f, packed);
    return bpg__new_accessor(e, bpg__at(f, f->accessors, idx), bpg__new_view(e, off, (size_t)out_n * eo, eo > a.esize ? eo : 0, 34962),
                             out_n, 0, NULL);
}

/* The input's TEXCOORD_n values (as the file has them, v downward) of a
   group, for corners of failed charts and unused vertices; NULL: none. */
static float *bpg__input_uv(bpg__enc *e, const bpg__prim *p)
{
    struct bpg__file *f = e->f;
    bpg__acc a;
    unsigned char *raw;
    float *out;
    uint32_t i;
    if (p->texcoord == BPG__NONE) return NULL;
    if (!bpg__accessor(f, p->texcoord, &a, "TEXCOORD") || !(raw = bpg__fetch(f, &a))) return NULL;
    if ((out = (float *)bpg__alloc_n(f, 2 * (size_t)a.count, sizeof(float))) != NULL)
        for (i = 0; i < 2 * a.count; i++) out[i] = (float)bpg__comp(raw + (size_t)(i / 2) * a.esize, a.ctype, a.normalized, (int)(i % 2));
    bpg__freef(f, raw);
    return out;
}

static void bpg__o_f32(bpg__out *o, float x)
{
    uint32_t u;
    unsigned char b[4];
    memcpy(&u, &x, 4);
    bpg__put32(b, u);
    bpg__o_put(o, b, 4);
}

/* Edit the attributes (or one morph target) object `obj`: each member gets
   the new accessor of its name. */
static int bpg__edit_map(bpg__enc *e, uint32_t obj, const bpg__renamed *rn, uint32_t nrn, uint32_t target, uint32_t tex_acc)
{
    struct bpg__file *f = e->f;
    uint32_t c, k;
    for (c = f->node[obj].first; c != BPG__NONE; c = f->node[c].next) {
        char name[64];
        size_t len = bpg__str_decode(f, f->node[c].key, name, sizeof name);
        uint32_t acc = BPG__NONE;
        if (target == 0 && tex_acc != BPG__NONE && bpg__str_eq(f, f->node[c].key, e->texkey)) acc = tex_acc;
        for (k = 0; k < nrn && acc == BPG__NONE; k++)
            if (rn[k].target == target && len < sizeof name && strcmp(rn[k].name, name) == 0) acc = rn[k].acc;
        if (acc == BPG__NONE) return bpg__fail(f, BP_ERR_PARSE, "internal: attribute \"%s\" not written", name) == BP_OK;
        if (!bpg__edit_uint(e, c, acc)) return 0;
    }
    return 1;
}

/* Group g with its triangle primitives prims[0, np). */
static int bpg__write_group(bpg__enc *e, uint32_t g, const uint32_t *prims, uint32_t np)
{
    struct bpg__file *f = e->f;
    const bp_atlas *at = e->atlas;
    const bpg__prim *p0 = &f->prim[prims[0]];
    uint32_t n = f->group[g].count, extras = 0, out_n, i, j, c, t, nrn = 0, tex_acc, ntg;
    uint32_t *first = NULL, *cout = NULL, *src = NULL, *ekey = NULL, *iacc = NULL;
    size_t ncorner = 0, cap_extra = 0, k, *ioff = NULL;
    bpg__split split;
    bpg__renamed *rn = NULL;
    float *inuv = NULL;
    char pn[64], what[200];
    int ok = 0;
    memset(&split, 0, sizeof split);
    for (i = 0; i < np; i++) ncorner += 3 * (size_t)f->prim[prims[i]].num;
    first = (uint32_t *)bpg__alloc_n(f, n, sizeof *first);
    cout = (uint32_t *)bpg__alloc_n(f, ncorner, sizeof *cout);
    iacc = (uint32_t *)bpg__alloc_n(f, np, sizeof *iacc);
    ioff = (size_t *)bpg__alloc_n(f, 2 * (size_t)np, sizeof *ioff);   /* start, length of each index list */
    if (!first || !cout || !iacc || !ioff) { bpg__oom(f, "writing"); goto done; }
    for (j = 0; j < n; j++) first[j] = BPG__NONE;
    /* 1. the output vertex of every corner */
    for (i = 0, k = 0; i < np; i++) {
        const bpg__prim *p = &f->prim[prims[i]];
        for (c = 3 * p->first; c < 3 * (p->first + p->num); c++, k++) {
            uint32_t v = f->corner_src[c], gv = e->chart_base[at->corner_chart[c]] + at->corner_vertex[c], x;
            if (first[v] == BPG__NONE) first[v] = gv;
            if (first[v] == gv) { cout[k] = v; continue; }
            x = bpg__split_find(f, &split, v, gv, extras);
            if (x == BPG__NONE) { bpg__oom(f, "writing"); goto done; }
            if (x == extras) {
                if (extras == cap_extra) {
                    size_t cap = cap_extra ? 2 * cap_extra : 256;
                    uint32_t *s2 = (uint32_t *)bpg__alloc_n(f, cap, sizeof *s2), *k2 = (uint32_t *)bpg__alloc_n(f, cap, sizeof *k2);
                    if (!s2 || !k2) { bpg__freef(f, s2); bpg__freef(f, k2); bpg__oom(f, "writing"); goto done; }
                    if (extras) { memcpy(s2, src, extras * sizeof *s2); memcpy(k2, ekey, extras * sizeof *k2); }
                    bpg__freef(f, src); bpg__freef(f, ekey);
                    src = s2; ekey = k2; cap_extra = cap;
                }
                src[extras] = v; ekey[extras] = gv;
                if (++extras >= BPG__NONE - n) { bpg__fail(f, BP_ERR_TOO_LARGE, "more than 2^32 - 2 vertices in one vertex set"); goto done; }
            }
            cout[k] = n + x;
        }
    }
    out_n = n + extras;
    e->vertices_in += n;
    e->vertices_out += out_n;
    /* 2. every attribute and morph target attribute, duplicated */
    ntg = p0->targets == BPG__NONE ? 0 : f->node[p0->targets].count;
    {
        uint32_t cnt = f->node[p0->attributes].count;
        for (t = 0; t < ntg; t++) cnt += f->node[bpg__at(f, p0->targets, t)].count;
        if (!(rn = (bpg__renamed *)bpg__calloc_n(f, cnt, sizeof *rn))) { bpg__oom(f, "writing"); goto done; }
    }
    bpg__prim_name(f, p0, pn, sizeof pn);
    for (t = 0; t <= ntg; t++) {
        uint32_t obj = t == 0 ? p0->attributes : bpg__at(f, p0->targets, t - 1), m;
        for (m = f->node[obj].first; m != BPG__NONE; m = f->node[m].next) {
            uint64_t idx;
            bpg__renamed *r = &rn[nrn];
            if (t == 0 && bpg__str_eq(f, f->node[m].key, e->texkey)) continue;
            if (bpg__str_decode(f, f->node[m].key, r->name, sizeof r->name) >= sizeof r->name) {
                bpg__fail(f, BP_ERR_TOO_LARGE, "%s: an attribute name is longer than 63 bytes", pn);
                goto done;
            }
            if (!bpg__int_value(f, m, &idx, pn, r->name)) goto done;
            snprintf(what, sizeof what, "accessor %u (%s%s of %s)", (unsigned)idx, t ? "morph target " : "", r->name, pn);
            r->target = t;
            if ((r->acc = bpg__dup_accessor(e, (uint32_t)idx, src, n, out_n, what)) == BPG__NONE) goto done;
            nrn++;
        }
    }
    /* 3. the new TEXCOORD_n */
    inuv = bpg__input_uv(e, p0);
    if (p0->texcoord != BPG__NONE && !inuv) goto done;
    bpg__o_align(&e->data, 4, 0);
    {
        size_t off = e->data.n;
        for (j = 0; j < out_n; j++) {
            uint32_t gv = j < n ? first[j] : ekey[j - n], v = j < n ? j : src[j - n];
            float u = 0, w = 0;
            if (gv != BPG__NONE && e->uv[2 * (size_t)gv] == e->uv[2 * (size_t)gv]) { u = e->uv[2 * (size_t)gv]; w = e->uv[2 * (size_t)gv + 1]; }
            else if (inuv) { u = inuv[2 * (size_t)v]; w = inuv[2 * (size_t)v + 1]; }
            bpg__o_f32(&e->data, u);
            bpg__o_f32(&e->data, w);
        }
        tex_acc = bpg__new_accessor(e, BPG__NONE, bpg__new_view(e, off, 8 * (size_t)out_n, 0, 34962), out_n, 5126, "VEC2");
    }
    /* 4. each primitive: its indices, then its JSON */
    for (i = 0, k = 0; i < np; i++) {
        const bpg__prim *p = &f->prim[prims[i]];
        uint32_t maxi = 0, ctype, acc, ind;
        size_t off, q;
        bpg__acc old;
        for (q = 0; q < 3 * (size_t)p->num; q++) if (cout[k + q] > maxi) maxi = cout[k + q];
        ctype = 5123;
        if (p->indices != BPG__NONE) {
            bpg__prim_name(f, p, pn, sizeof pn);
            snprintf(what, sizeof what, "accessor %u (indices of %s)", (unsigned)p->indices, pn);
            if (!bpg__accessor(f, p->indices, &old, what)) goto done;
            ctype = (uint32_t)old.ctype;
        }
        if (ctype == 5121 && maxi >= 255) ctype = 5123;
        if (ctype == 5123 && maxi >= 65535) ctype = 5125;
        bpg__o_align(&e->data, 4, 0);
        off = e->data.n;
        for (t = 0; t < p->num; t++) {
            const uint32_t *o3 = cout + k + 3 * (size_t)t;
            uint32_t order[3];
            int z;
            order[0] = o3[0];
            order[1] = e->flip[p->first + t] ? o3[2] : o3[1];
            order[2] = e->flip[p->first + t] ? o3[1] : o3[2];
            for (z = 0; z < 3; z++) {
                unsigned char b[4];
                bpg__put32(b, order[z]);
                bpg__o_put(&e->data, b, (size_t)bpg__csize((int)ctype));
            }
        }
        /* primitives drawing the same triangles (meshes sharing their
           accessors) share one index accessor again, as in the input */
        for (q = 0; q < i; q++)
            if (ioff[2 * q + 1] == e->data.n - off && f->prim[prims[q]].num == p->num &&
                !e->data.failed && !memcmp(e->data.d + ioff[2 * q], e->data.d + off, e->data.n - off))
                break;
        if (q < i) {
            e->data.n = off;
            acc = iacc[q];
        } else
            acc = bpg__new_accessor(e, BPG__NONE, bpg__new_view(e, off, 3 * (size_t)p->num * (size_t)bpg__csize((int)ctype), 0, 34963),
                                    3 * p->num, (int)ctype, "SCALAR");
        iacc[i] = acc;
        ioff[2 * (size_t)i] = off;
        ioff[2 * (size_t)i + 1] = q < i ? 0 : e->data.n - off;
        k += 3 * (size_t)p->num;
        /* the JSON of the primitive */
        if (!bpg__edit_map(e, p->attributes, rn, nrn, 0, tex_acc)) goto done;
        if (bpg__get(f, p->attributes, e->texkey, "attributes") == BPG__NONE) {
            size_t from = e->text.n;
            bpg__o_str(&e->text, ",\"");
            bpg__o_str(&e->text, e->texkey);
            bpg__o_str(&e->text, "\":");
            bpg__o_uint(&e->text, tex_acc);
            if (!bpg__edit_add(e, f->node[p->attributes].end - 1, f->node[p->attributes].end - 1, from)) goto done;
        }
        for (t = 0; t < ntg; t++)
            if (!bpg__edit_map(e, bpg__at(f, p->targets, t), rn, nrn, t + 1, BPG__NONE)) goto done;
        ind = bpg__get(f, p->node, "indices", "a primitive");
        if (ind != BPG__NONE) { if (!bpg__edit_uint(e, ind, acc)) goto done; }
        else {
            size_t from = e->text.n;
            bpg__o_str(&e->text, "\"indices\":");
            bpg__o_uint(&e->text, acc);
            bpg__o_str(&e->text, ",");
            if (!bpg__edit_add(e, f->node[p->node].start + 1, f->node[p->node].start + 1, from)) goto done;
        }
        if (p->mode != 4 && !bpg__edit_uint(e, bpg__get(f, p->node, "mode", "a primitive"), 4)) goto done;
    }
    ok = f->err->status == BP_OK;
done:
    bpg__freef(f, first); bpg__freef(f, cout); bpg__freef(f, src); bpg__freef(f, ekey);
    bpg__freef(f, iacc); bpg__freef(f, ioff);
    bpg__freef(f, split.key); bpg__freef(f, split.val); bpg__freef(f, rn); bpg__freef(f, inuv);
    if (!ok && f->err->status == BP_OK) bpg__oom(f, "writing");
    return ok;
}

/* ---- writing: what the rewrite leaves unused ----------------------------------

   A written primitive gets new accessors for every attribute and for its
   indices, so the accessors it used before -- and their bufferViews and
   bytes -- may be referenced by nothing any more: kept, they would double
   a .glb whose every primitive is written.  They are removed when nothing
   else of the file names them, and everything the file still references
   comes back with the same JSON text and the same bytes, renumbered:

     - an accessor goes when only written primitives referenced it (their
       attributes, morph targets and indices); one the input itself left
       unreferenced stays, as does one that another primitive (points,
       lines), a skin, an animation sampler or EXT_mesh_gpu_instancing
       names;
     - a bufferView goes when only accessors that go referenced it;
     - in a .glb's BIN chunk (buffer 0), the bytes of the bufferViews that
       go are cut out where no kept bufferView overlaps them, whole 4-byte
       units only, so every offset keeps its alignment; bytes of a buffer
       in a file or a data: URI stay where they are (only the JSON entries
       go);
     - every reference to a kept accessor or bufferView is renumbered
       (bufferView, sparse indices and values, image bufferView, and the
       references above) and a kept bufferView's byteOffset moves with the
       bytes cut before it.

   Extensions may hold indices this writer cannot know about.  Those that
   never name an accessor or bufferView (materials, texture transforms
   and formats, lights, quantization, variants, XMP) are read past; any
   other extension object holding a whole number, or a reference that is
   not a whole number in range, leaves the file's accessors and
   bufferViews all in place, as the file had them. */

static int bpg__ext_known(const struct bpg__file *f, size_t key)
{
    static const char *const safe[] = { "KHR_texture_transform", "KHR_lights_punctual", "KHR_mesh_quantization",
                                        "KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif", "KHR_xmp_json_ld",
                                        "KHR_materials_variants", "MSFT_texture_dds", "EXT_lights_image_based" };
    char name[64];
    size_t i, n = bpg__str_decode(f, key, name, sizeof name);
    if (n >= sizeof name) return 0;
    if (strncmp(name, "KHR_materials_", 14) == 0) return 1;
    for (i = 0; i < sizeof safe / sizeof *safe; i++) if (strcmp(name, safe[i]) == 0) return 1;
    return 0;
}

/* 1 when the subtree of node id holds a number written as a whole number. */
static int bpg__has_integer(const struct bpg__file *f, uint32_t id)
{
    uint32_t c;
    if (f->node[id].type == BPG__NUMBER) return f->node[id].integer;
    for (c = f->node[id].first; c != BPG__NONE; c = f->node[c].next) if (bpg__has_integer(f, c)) return 1;
    return 0;
}

/* A JSON value that is an index: digits only, below `limit`. */
static int bpg__index_of(const struct bpg__file *f, uint32_t id, uint32_t limit, uint32_t *out)
{
    const bpg__node *n = &f->node[id];
    uint64_t v = 0;
    size_t i;
    if (n->type != BPG__NUMBER || n->end - n->start > 10) return 0;
    for (i = n->start; i < n->end; i++) {
        if (f->doc[i] < '0' || f->doc[i] > '9') return 0;
        v = 10 * v + (uint64_t)(f->doc[i] - '0');
    }
    if (v >= limit) return 0;
    *out = (uint32_t)v;
    return 1;
}

/* A reference the compaction renumbers: the JSON number `node`, naming
   accessor (kind 0) or bufferView (kind 1) `old`. */
typedef struct bpg__ref { uint32_t node, old; int kind; } bpg__ref;

typedef struct bpg__plan {
    unsigned char *acc_use;     /* per input accessor: 0 none, 1 written
                                   primitives only, 2 anything else          */
    unsigned char *view_use;    /* per input bufferView: the same by accessor */
    bpg__ref *ref;
    uint32_t num_refs, cap_refs;
    int refused;                /* an index this writer cannot renumber      */
} bpg__plan;

static int bpg__plan_ref(struct bpg__file *f, bpg__plan *p, uint32_t node, int kind, unsigned char use)
{
    uint32_t idx, limit = kind ? f->num_views : f->num_accessors;
    unsigned char *u = kind ? p->view_use : p->acc_use;
    if (node == BPG__NONE) return 1;
    if (!bpg__index_of(f, node, limit, &idx)) { p->refused = 1; return 1; }
    if (u[idx] < use) u[idx] = use;
    if (use == 1) return 1;                      /* a written primitive's: edited there */
    if (p->num_refs == p->cap_refs) {
        uint32_t cap = p->cap_refs ? 2 * p->cap_refs : 64;
        bpg__ref *q = (bpg__ref *)bpg__alloc_n(f, cap, sizeof *q);
        if (!q) return 0;
        if (p->num_refs) memcpy(q, p->ref, p->num_refs * sizeof *q);
        bpg__freef(f, p->ref);
        p->ref = q;
        p->cap_refs = cap;
    }
    p->ref[p->num_refs].node = node; p->ref[p->num_refs].old = idx; p->ref[p->num_refs].kind = kind;
    p->num_refs++;
    return 1;
}

/* Every member value of object obj as a reference (attributes, targets). */
static int bpg__plan_members(struct bpg__file *f, bpg__plan *p, uint32_t obj, unsigned char use)
{
    uint32_t c;
    if (obj == BPG__NONE || f->node[obj].type != BPG__OBJECT) return 1;
    for (c = f->node[obj].first; c != BPG__NONE; c = f->node[c].next) if (!bpg__plan_ref(f, p, c, 0, use)) return 0;
    return 1;
}

/* Member `key` of every element of array `arr` of objects, or of each
   element's `sub` array (animations' samplers). */
static int bpg__plan_each(struct bpg__file *f, bpg__plan *p, uint32_t arr, const char *sub, const char *key, int kind)
{
    uint32_t c, s;
    if (arr == BPG__NONE || f->node[arr].type != BPG__ARRAY) return 1;
    for (c = f->node[arr].first; c != BPG__NONE; c = f->node[c].next) {
        if (!sub) { if (!bpg__plan_ref(f, p, bpg__get(f, c, key, "an object"), kind, 2)) return 0; continue; }
        s = bpg__get(f, c, sub, "an object");
        if (s == BPG__NONE || f->node[s].type != BPG__ARRAY) continue;
        for (s = f->node[s].first; s != BPG__NONE; s = f->node[s].next) {
            if (!bpg__plan_ref(f, p, bpg__get(f, s, "input", "a sampler"), 0, 2) ||
                !bpg__plan_ref(f, p, bpg__get(f, s, "output", "a sampler"), 0, 2))
                return 0;
        }
    }
    return 1;
}

/* A JSON number of digits only (a byte offset or length), up to 2^53. */
static int bpg__u64_of(const struct bpg__file *f, uint32_t id, uint64_t *out)
{
    const bpg__node *n;
    uint64_t v = 0;
    size_t i;
    if (id == BPG__NONE) { *out = 0; return 1; }
    n = &f->node[id];
    if (n->type != BPG__NUMBER || n->end - n->start > 16) return 0;
    for (i = n->start; i < n->end; i++) {
        if (f->doc[i] < '0' || f->doc[i] > '9') return 0;
        v = 10 * v + (uint64_t)(f->doc[i] - '0');
    }
    *out = v;
    return 1;
}

static int bpg__range_cmp(const void *a, const void *b)
{
    const uint64_t *x = (const uint64_t *)a, *y = (const uint64_t *)b;
    return x[0] < y[0] ? -1 : x[0] > y[0];
}

/* Sort the n ranges r[2k], r[2k+1] and merge those that touch; returns
   how many remain. */
static uint32_t bpg__merge_ranges(uint64_t *r, uint32_t n)
{
    uint32_t i, m = 0;
    qsort(r, n, 2 * sizeof *r, bpg__range_cmp);
    for (i = 0; i < n; i++) {
        if (m && r[2 * i] <= r[2 * m - 1]) { if (r[2 * i + 1] > r[2 * m - 1]) r[2 * m - 1] = r[2 * i + 1]; continue; }
        r[2 * m] = r[2 * i]; r[2 * m + 1] = r[2 * i + 1]; m++;
    }
    return m;
}

/* Remove the elements k of array arr whose renum[k] is BPG__NONE: one
   before the first kept element with the text up to the next element's
   start, any other with the text from the previous element's end (its
   comma), so that the removed texts never overlap. */
static int bpg__remove_elements(bpg__enc *e, uint32_t arr, const uint32_t *renum)
{
    struct bpg__file *f = e->f;
    uint32_t c, prev = BPG__NONE, k;
    int seen_kept = 0;
    if (arr == BPG__NONE) return 1;
    for (k = 0, c = f->node[arr].first; c != BPG__NONE; k++, prev = c, c = f->node[c].next) {
        uint32_t next = f->node[c].next;
        size_t at, end;
        if (renum[k] != BPG__NONE) { seen_kept = 1; continue; }
        if (seen_kept) { at = f->node[prev].end; end = f->node[c].end; }
        else { at = f->node[c].start; end = next != BPG__NONE ? f->node[next].start : f->node[c].end; }
        if (!bpg__edit_add(e, at, end, e->text.n)) return 0;
    }
    return 1;
}

/* The numbering of kept elements: renum[k] its new index, or BPG__NONE. */
static uint32_t bpg__renumber(const unsigned char *use, uint32_t n, uint32_t *renum)
{
    uint32_t k, kept = 0;
    for (k = 0; k < n; k++) renum[k] = use[k] == 1 ? BPG__NONE : kept++;
    return kept;
}

/* Plan and edit the compaction (the essay above); glb_buf0: buffer 0 is
   the BIN chunk, whose bytes may be cut.  Sets e->acc_base, e->view_base
   and e->bin, e->bin_len (the BIN chunk as written). */
static int bpg__compact(bpg__enc *e, int glb_buf0)
{
    struct bpg__file *f = e->f;
    bpg__plan p;
    unsigned char *written = NULL;
    uint64_t *drop = NULL, *keep = NULL, *voff = NULL;
    uint32_t i, c, m, q, nd = 0, nk = 0;
    int ok = 0;
    memset(&p, 0, sizeof p);
    e->acc_base = f->num_accessors;
    e->view_base = f->num_views;
    e->bin = f->bin;
    e->bin_len = glb_buf0 ? (size_t)f->buf[0].length : 0;
    p.acc_use = (unsigned char *)bpg__calloc_n(f, (size_t)f->num_accessors + 1, 1);
    p.view_use = (unsigned char *)bpg__calloc_n(f, (size_t)f->num_views + 1, 1);
    written = (unsigned char *)bpg__calloc_n(f, f->num_nodes, 1);
    e->acc_new = (uint32_t *)bpg__alloc_n(f, (size_t)f->num_accessors + 1, sizeof(uint32_t));
    e->view_new = (uint32_t *)bpg__alloc_n(f, (size_t)f->num_views + 1, sizeof(uint32_t));
    voff = (uint64_t *)bpg__alloc_n(f, 3 * (size_t)f->num_views + 1, sizeof(uint64_t));
    drop = (uint64_t *)bpg__alloc_n(f, 2 * (size_t)f->num_views + 1, sizeof(uint64_t));
    keep = (uint64_t *)bpg__alloc_n(f, 2 * (size_t)f->num_views + 1, sizeof(uint64_t));
    if (!p.acc_use || !p.view_use || !written || !e->acc_new || !e->view_new || !voff || !drop || !keep) goto done;
    for (i = 0; i < f->num_prims; i++) if (f->prim[i].num) written[f->prim[i].node] = 1;
    /* 1. who references each accessor */
    for (c = f->meshes == BPG__NONE ? BPG__NONE : f->node[f->meshes].first; c != BPG__NONE; c = f->node[c].next)
        for (q = f->node[bpg__get(f, c, "primitives", "a mesh")].first; q != BPG__NONE; q = f->node[q].next) {
            unsigned char use = written[q] ? 1 : 2;
            uint32_t tg = bpg__get(f, q, "targets", "a primitive");
            if (!bpg__plan_members(f, &p, bpg__get(f, q, "attributes", "a primitive"), use) ||
                !bpg__plan_ref(f, &p, bpg__get(f, q, "indices", "a primitive"), 0, use))
                goto done;
            if (tg != BPG__NONE && f->node[tg].type == BPG__ARRAY)
                for (m = f->node[tg].first; m != BPG__NONE; m = f->node[m].next)
                    if (!bpg__plan_members(f, &p, m, use)) goto done;
        }
    if (!bpg__plan_each(f, &p, bpg__get(f, 0, "skins", "the glTF object"), NULL, "inverseBindMatrices", 0) ||
        !bpg__plan_each(f, &p, bpg__get(f, 0, "animations", "the glTF object"), "samplers", NULL, 0) ||
        !bpg__plan_each(f, &p, f->images, NULL, "bufferView", 1))
        goto done;
    for (c = 0; c < f->num_nodes; c++) {
        const bpg__node *n = &f->node[c];
        if (n->type != BPG__OBJECT || n->key == (size_t)-1 || !bpg__str_eq(f, n->key, "extensions")) continue;
        for (m = n->first; m != BPG__NONE; m = f->node[m].next) {
            if (bpg__str_eq(f, f->node[m].key, "EXT_mesh_gpu_instancing")) {
                if (!bpg__plan_members(f, &p, bpg__get(f, m, "attributes", "EXT_mesh_gpu_instancing"), 2)) goto done;
            } else if (!bpg__ext_known(f, f->node[m].key) && bpg__has_integer(f, m)) p.refused = 1;
        }
    }
    if (f->err->status != BP_OK) goto fail_quietly;
    /* 2. which bufferViews the kept accessors (and images) reference */
    for (i = 0, c = f->accessors == BPG__NONE ? BPG__NONE : f->node[f->accessors].first; c != BPG__NONE; i++, c = f->node[c].next) {
        unsigned char use = p.acc_use[i] == 1 ? 1 : 2;
        uint32_t sp = bpg__get(f, c, "sparse", "an accessor");
        if (!bpg__plan_ref(f, &p, bpg__get(f, c, "bufferView", "an accessor"), 1, use) ||
            !bpg__plan_ref(f, &p, bpg__get(f, bpg__get(f, sp, "indices", "sparse"), "bufferView", "sparse indices"), 1, use) ||
            !bpg__plan_ref(f, &p, bpg__get(f, bpg__get(f, sp, "values", "sparse"), "bufferView", "sparse values"), 1, use))
            goto done;
    }
    if (f->err->status != BP_OK) goto fail_quietly;
    /* 3. the bytes of buffer 0 that go */
    for (i = 0, c = f->views == BPG__NONE ? BPG__NONE : f->node[f->views].first; c != BPG__NONE && !p.refused; i++, c = f->node[c].next) {
        uint64_t buf = 0, off = 0, len = 0;
        if (!bpg__u64_of(f, bpg__get(f, c, "buffer", "a bufferView"), &buf) ||
            !bpg__u64_of(f, bpg__get(f, c, "byteOffset", "a bufferView"), &off) ||
            !bpg__u64_of(f, bpg__get(f, c, "byteLength", "a bufferView"), &len) || bpg__get(f, c, "buffer", "") == BPG__NONE)
            { p.refused = 1; break; }
        voff[3 * i] = buf; voff[3 * i + 1] = off; voff[3 * i + 2] = len;
        if (!glb_buf0 || buf != 0) continue;
        if (off + len > e->bin_len) { p.refused = 1; break; }
        if (p.view_use[i] == 1) { drop[2 * nd] = (off + 3) / 4; drop[2 * nd + 1] = (off + len) / 4; nd += drop[2 * nd] < drop[2 * nd + 1]; }
        else { keep[2 * nk] = off / 4; keep[2 * nk + 1] = (off + len + 3) / 4; nk++; }
    }
    if (f->err->status != BP_OK) goto fail_quietly;
    if (p.refused) { ok = 1; goto done; }         /* nothing removed, nothing renumbered */
    nd = bpg__merge_ranges(drop, nd);
    nk = bpg__merge_ranges(keep, nk);
    {
        /* cuts = drop minus keep, in 4-byte units, into drop (m of them) */
        uint32_t a, b = 0;
        uint64_t removed = 0;
        uint64_t *cut = (uint64_t *)bpg__alloc_n(f, 2 * ((size_t)nd + nk) + 2, sizeof(uint64_t));
        if (!cut) goto done;
        for (a = 0, m = 0; a < nd; a++) {
            uint64_t lo = drop[2 * a], hi = drop[2 * a + 1];
            while (b < nk && keep[2 * b + 1] <= lo) b++;
            for (q = b; lo < hi; q++) {
                uint64_t end = q < nk && keep[2 * q] < hi ? keep[2 * q] : hi;
                if (end > lo) { cut[2 * m] = lo; cut[2 * m + 1] = end; m++; removed += 4 * (end - lo); }
                if (q >= nk || keep[2 * q] >= hi) break;
                lo = keep[2 * q + 1];
            }
        }
        e->cut = cut;
        e->num_cuts = m;
        if (removed) {
            unsigned char *nb = (unsigned char *)bpg__alloc(f, e->bin_len - (size_t)removed + 1);
            size_t at = 0, to = 0;
            if (!nb) goto done;
            for (a = 0; a < m; a++) {
                memcpy(nb + to, f->bin + at, (size_t)(4 * cut[2 * a]) - at);
                to += (size_t)(4 * cut[2 * a]) - at;
                at = (size_t)(4 * cut[2 * a + 1]);
            }
            memcpy(nb + to, f->bin + at, e->bin_len - at);
            e->bin_owned = nb;
            e->bin = nb;
            e->bin_len -= (size_t)removed;
        }
    }
    /* 4. the edits: references renumbered, offsets moved, elements removed */
    e->acc_base = bpg__renumber(p.acc_use, f->num_accessors, e->acc_new);
    e->view_base = bpg__renumber(p.view_use, f->num_views, e->view_new);
    for (i = 0; i < p.num_refs; i++) {
        const bpg__ref *r = &p.ref[i];
        uint32_t to = r->kind ? e->view_new[r->old] : e->acc_new[r->old];
        if (to != r->old && !bpg__edit_uint(e, r->node, to)) goto done;
    }
    for (i = 0, c = f->views == BPG__NONE ? BPG__NONE : f->node[f->views].first; c != BPG__NONE; i++, c = f->node[c].next) {
        uint64_t shift = 0;
        if (!glb_buf0 || voff[3 * i] != 0 || e->view_new[i] == BPG__NONE) continue;
        for (m = 0; m < e->num_cuts && 4 * e->cut[2 * m + 1] <= voff[3 * i + 1]; m++) shift += 4 * (e->cut[2 * m + 1] - e->cut[2 * m]);
        if (shift && !bpg__edit_uint(e, bpg__get(f, c, "byteOffset", "a bufferView"), voff[3 * i + 1] - shift)) goto done;
    }
    if (!bpg__remove_elements(e, f->accessors, e->acc_new) || !bpg__remove_elements(e, f->views, e->view_new)) goto done;
    e->accessors_removed = f->num_accessors - e->acc_base;
    e->views_removed = f->num_views - e->view_base;
    ok = 1;
done:
    if (!ok && f->err->status == BP_OK) bpg__oom(f, "writing");
fail_quietly:
    bpg__freef(f, p.acc_use); bpg__freef(f, p.view_use); bpg__freef(f, p.ref);
    bpg__freef(f, written); bpg__freef(f, drop); bpg__freef(f, keep); bpg__freef(f, voff);
    return ok && f->err->status == BP_OK;
}

/* ---- writing: the file -------------------------------------------------------

   Where the new bytes go (the essay at the top): appended to a .glb's
   buffer 0 (its BIN chunk), 4-aligned after its byteLength; for a .glb
   without buffers, a new buffer 0 that becomes its BIN chunk; otherwise
   a new last buffer, in a data: URI or an external file.  A .glb input
   written as .gltf gives its buffer 0 a uri, and the BIN chunk's bytes
   travel with the new ones. */

/* A uri (or a prefix of one) percent-encoded: everything but unreserved
   characters and '/' (a '\' from a Windows path becomes '/'). */
static void bpg__o_uri(bpg__out *o, const char *s)
{
    static const char hex[] = "0123456789ABCDEF";
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '.' || c == '_' ||
            c == '~' || c == '/')
            bpg__o_put(o, &c, 1);
        else if (c == '\\') bpg__o_str(o, "/");
        else { char q[3]; q[0] = '%'; q[1] = hex[c >> 4]; q[2] = hex[c & 15]; bpg__o_put(o, q, 3); }
    }
}

/* "uri" of the new buffer: the .bin's name, or a data: URI of bytes. */
static void bpg__o_uri_value(bpg__enc *e, const unsigned char *head, size_t head_len, size_t pad)
{
    bpg__out *o = &e->text;
    bpg__o_str(o, "\"");
    if (e->wo->bin_uri) bpg__o_uri(o, e->wo->bin_uri);
    else {
        /* head (a .glb's BIN chunk), pad zeros, then the new bytes: one stream */
        bpg__out all;
        memset(&all, 0, sizeof all);
        all.f = e->f;
        bpg__o_put(&all, head, head_len);
        bpg__o_zeros(&all, pad, 0);
        bpg__o_put(&all, e->data.d, e->data.n);
        bpg__o_str(o, "data:application/octet-stream;base64,");
        if (all.failed) o->failed = 1;
        else bpg__o_base64(o, all.d, all.n);
        bpg__freef(e->f, all.d);
    }
    bpg__o_str(o, "\"");
}

/* Append the texts in `items` (comma-separated elements) to the top-level
   array `name` (node arr, BPG__NONE: create it) that keeps `kept` of its
   elements. */
static int bpg__append_array(bpg__enc *e, uint32_t root, uint32_t arr, const char *name, const bpg__out *items, uint32_t kept)
{
    struct bpg__file *f = e->f;
    size_t from = e->text.n, at;
    if (!items->n) return 1;
    if (arr == BPG__NONE) {
        bpg__o_str(&e->text, ",\"");
        bpg__o_str(&e->text, name);
        bpg__o_str(&e->text, "\":[");
        bpg__o_put(&e->text, items->d, items->n);
        bpg__o_str(&e->text, "]");
        at = f->node[root].end - 1;
    } else {
        if (kept) bpg__o_str(&e->text, ",");
        bpg__o_put(&e->text, items->d, items->n);
        at = f->node[arr].end - 1;
    }
    return bpg__edit_add(e, at, at, from);
}

/* Relative uris of buffers and images get wo->uri_prefix. */
static int bpg__prefix_uris(bpg__enc *e)
{
    struct bpg__file *f = e->f;
    uint32_t pass, c;
    for (pass = 0; pass < 2; pass++) {
        uint32_t arr = pass ? f->images : f->buffers;
        for (c = arr == BPG__NONE ? BPG__NONE : f->node[arr].first; c != BPG__NONE; c = f->node[c].next) {
            uint32_t u = bpg__get(f, c, "uri", "a buffer or image");
            char *uri;
            int rel;
            size_t from = e->text.n;
            if (u == BPG__NONE || f->node[u].type != BPG__STRING) continue;
            if (!(uri = bpg__uri(f, u))) return 0;
            rel = strncmp(uri, "data:", 5) != 0 && !bpg__uri_absolute(uri);
            bpg__freef(f, uri);
            if (!rel) continue;
            bpg__o_str(&e->text, "\"");
            bpg__o_uri(&e->text, e->wo->uri_prefix);
            bpg__o_put(&e->text, f->doc + f->node[u].start + 1, f->node[u].end - f->node[u].start - 2);
            bpg__o_str(&e->text, "\"");
            if (!bpg__edit_add(e, f->node[u].start, f->node[u].end, from)) return 0;
        }
    }
    return 1;
}

/* The JSON with the edits applied, onto o. */
static void bpg__apply_edits(bpg__enc *e, bpg__out *o)
{
    struct bpg__file *f = e->f;
    size_t at = 0;
    uint32_t i;
    qsort(e->edit, e->num_edits, sizeof *e->edit, bpg__edit_cmp);
    for (i = 0; i < e->num_edits; i++) {
        const bpg__edit *x = &e->edit[i];
        bpg__o_put(o, f->doc + at, x->at - at);
        bpg__o_put(o, e->text.d + x->text, x->len);
        at = x->end;
    }
    bpg__o_put(o, f->doc + at, f->doc_len - at);
}

static void bpg__enc_free(bpg__enc *e)
{
    struct bpg__file *f = e->f;
    bpg__freef(f, e->text.d); bpg__freef(f, e->data.d); bpg__freef(f, e->acc.d); bpg__freef(f, e->views.d);
    bpg__freef(f, e->edit); bpg__freef(f, e->chart_base); bpg__freef(f, e->uv); bpg__freef(f, e->flip);
    bpg__freef(f, e->acc_new); bpg__freef(f, e->view_new); bpg__freef(f, e->cut); bpg__freef(f, e->bin_owned);
}

BPDEF void bpg_output_free(bpg_output *out)
{
    if (!out) return;
    bpg__free_p(&out->allocator, out->data);
    bpg__free_p(&out->allocator, out->bin);
    memset(out, 0, sizeof *out);
}

/* The primitives of each group, in file order (a counting sort). */
static int bpg__write_groups(bpg__enc *e)
{
    struct bpg__file *f = e->f;
    uint32_t *start = (uint32_t *)bpg__calloc_n(f, (size_t)f->num_groups + 1, sizeof(uint32_t));
    uint32_t *list = (uint32_t *)bpg__alloc_n(f, f->num_prims, sizeof(uint32_t)), i, g;
    int ok = 1;
    if (!start || !list) { bpg__freef(f, start); bpg__freef(f, list); bpg__oom(f, "writing"); return 0; }
    for (i = 0; i < f->num_prims; i++) if (f->prim[i].num) start[f->prim[i].group + 1]++;
    for (g = 0; g < f->num_groups; g++) start[g + 1] += start[g];
    for (i = 0; i < f->num_prims; i++) if (f->prim[i].num) list[start[f->prim[i].group]++] = i;
    for (g = f->num_groups; g > 0; g--) start[g] = start[g - 1];
    start[0] = 0;
    for (g = 0; g < f->num_groups && ok; g++)
        if (start[g + 1] > start[g]) ok = bpg__write_group(e, g, list + start[g], start[g + 1] - start[g]);
    bpg__freef(f, start);
    bpg__freef(f, list);
    return ok;
}

BPDEF bp_status bpg_encode(const bpg_file *file, const bp_atlas *atlas, const bpg_write_options *wo,
                           bpg_output *out, bp_error *err)
{
    struct bpg__file *f = file ? file->p : NULL;
    bpg__enc e;
    bpg_write_options def;
    bpg__out json;
    int glb_out, glb_buf0;
    uint32_t root = 0;
    size_t bin_len = 0, bin_pad = 0;
    bp_status st = BP_OK;
    memset(out, 0, sizeof *out);
    if (!f) {
        if (err) { memset(err, 0, sizeof *err); err->status = BP_ERR_INVALID_ARGUMENT; err->index = err->index2 = -1;
                   snprintf(err->message, sizeof err->message, "no glTF file was read"); }
        return BP_ERR_INVALID_ARGUMENT;
    }
    out->allocator = f->a;
    f->err = err ? err : &f->scratch;
    memset(f->err, 0, sizeof *f->err);
    f->err->index = f->err->index2 = -1;
    memset(&e, 0, sizeof e);
    memset(&json, 0, sizeof json);
    if (!wo) { memset(&def, 0, sizeof def); def.glb = f->glb; wo = &def; }
    e.file = file; e.f = f; e.atlas = atlas; e.wo = wo;
    e.text.f = e.data.f = e.acc.f = e.views.f = json.f = f;
    snprintf(e.texkey, sizeof e.texkey, "TEXCOORD_%d", f->texcoord);
    glb_out = wo->glb != 0;
    glb_buf0 = f->glb && f->num_buffers > 0 && f->buf[0].kind == 0;
    if (!bpg__compact(&e, glb_buf0)) goto fail;
    if (glb_buf0) { e.new_buffer = 0; bin_len = e.bin_len; e.data_base = (bin_len + 3) / 4 * 4; bin_pad = (size_t)e.data_base - bin_len; }
    else if (glb_out && f->num_buffers == 0) e.new_buffer = 0;
    else e.new_buffer = f->num_buffers;
    if (glb_out && !glb_buf0 && f->num_buffers > 0 && f->buf[0].uri == BPG__NONE) {
        bpg__fail(f, BP_ERR_INVALID_ARGUMENT, "buffer 0 has no uri: in a .glb it would be the BIN chunk, and the input has "
                  "no bytes for it (write .gltf)");
        goto fail;
    }
    /* root: the JSON's outermost object (node 0: the parser made it first) */
    if ((st = bpg__prepare_map(&e)) != BP_OK || !bpg__write_groups(&e)) goto fail;
    if (!bpg__append_array(&e, root, f->accessors, "accessors", &e.acc, e.acc_base) ||
        !bpg__append_array(&e, root, f->views, "bufferViews", &e.views, e.view_base))
        goto fail;
    /* the buffer of the new bytes */
    if (glb_buf0) {
        size_t from = e.text.n;
        uint32_t bl = bpg__get(f, f->buf[0].node, "byteLength", "buffer 0");
        if (!bpg__edit_uint(&e, bl, e.data_base + e.data.n)) goto fail;
        if (!glb_out) {
            from = e.text.n;
            bpg__o_str(&e.text, "\"uri\":");
            bpg__o_uri_value(&e, e.bin, bin_len, bin_pad);
            bpg__o_str(&e.text, ",");
            if (!bpg__edit_add(&e, f->node[f->buf[0].node].start + 1, f->node[f->buf[0].node].start + 1, from)) goto fail;
        }
    } else {
        bpg__out item;
        size_t from = e.text.n;
        memset(&item, 0, sizeof item);
        item.f = f;
        bpg__o_str(&e.text, "{\"byteLength\":");
        bpg__o_uint(&e.text, e.data.n);
        if (!(glb_out && e.new_buffer == 0)) {
            bpg_write_options w2 = *wo;
            if (glb_out) w2.bin_uri = NULL;             /* a .glb's extra buffer: a data: URI */
            bpg__o_str(&e.text, ",\"uri\":");
            e.wo = &w2;
            bpg__o_uri_value(&e, NULL, 0, 0);
            e.wo = wo;
        }
        bpg__o_str(&e.text, "}");
        /* move the item's text out of e.text into its own array element */
        bpg__o_put(&item, e.text.d + from, e.text.n - from);
        e.text.n = from;
        if (item.failed || !bpg__append_array(&e, root, f->buffers, "buffers", &item, f->num_buffers)) { bpg__freef(f, item.d); goto fail; }
        bpg__freef(f, item.d);
    }
    if (wo->uri_prefix && wo->uri_prefix[0] && !bpg__prefix_uris(&e)) goto fail;
    if (e.text.failed || e.data.failed || e.acc.failed || e.views.failed) { bpg__oom(f, "writing"); goto fail; }
    /* assemble */
    if (glb_out) {
        bpg__out jt, o;
        size_t binsz = 0;
        int bin_chunk = glb_buf0 || e.new_buffer == 0 || f->has_bin;
        memset(&jt, 0, sizeof jt); memset(&o, 0, sizeof o);
        jt.f = o.f = f;
        bpg__apply_edits(&e, &jt);
        bpg__o_align(&jt, 4, ' ');
        if (glb_buf0 || e.new_buffer == 0) binsz = (size_t)e.data_base + e.data.n;
        else if (f->has_bin) binsz = f->bin_size;
        binsz = (binsz + 3) / 4 * 4;
        if (jt.failed) { bpg__freef(f, jt.d); bpg__oom(f, "writing"); goto fail; }
        if ((uint64_t)12 + 8 + jt.n + (bin_chunk ? 8 + (uint64_t)binsz : 0) + (f->glb ? f->tail_size : 0) > 0xffffffffu) {
            bpg__freef(f, jt.d);
            bpg__fail(f, BP_ERR_TOO_LARGE, "the .glb would have more than 4 GiB, the format's limit (write .gltf)");
            goto fail;
        }
        {
            unsigned char h[12];
            uint32_t total = (uint32_t)(12 + 8 + jt.n + (bin_chunk ? 8 + binsz : 0) + (f->glb ? f->tail_size : 0));
            memcpy(h, "glTF", 4); bpg__put32(h + 4, 2); bpg__put32(h + 8, total);
            bpg__o_put(&o, h, 12);
            bpg__put32(h, (uint32_t)jt.n); bpg__put32(h + 4, 0x4E4F534Au);
            bpg__o_put(&o, h, 8);
            bpg__o_put(&o, jt.d, jt.n);
            if (bin_chunk) {
                size_t start;
                bpg__put32(h, (uint32_t)binsz); bpg__put32(h + 4, 0x004E4942u);
                bpg__o_put(&o, h, 8);
                start = o.n;
                if (glb_buf0) { bpg__o_put(&o, e.bin, bin_len); bpg__o_zeros(&o, bin_pad, 0); bpg__o_put(&o, e.data.d, e.data.n); }
                else if (e.new_buffer == 0) bpg__o_put(&o, e.data.d, e.data.n);
                else bpg__o_put(&o, f->bin, f->bin_size);
                bpg__o_zeros(&o, binsz - (o.n - start), 0);
            }
            if (f->glb) bpg__o_put(&o, f->tail, f->tail_size);
        }
        bpg__freef(f, jt.d);
        if (o.failed) { bpg__freef(f, o.d); bpg__oom(f, "writing"); goto fail; }
        out->data = o.d; out->size = o.n;
    } else {
        bpg__apply_edits(&e, &json);
        if (json.failed) { bpg__oom(f, "writing"); goto fail; }
        out->data = json.d; out->size = json.n;
        json.d = NULL;
        if (wo->bin_uri) {
            bpg__out b;
            memset(&b, 0, sizeof b);
            b.f = f;
            if (glb_buf0) { bpg__o_put(&b, e.bin, bin_len); bpg__o_zeros(&b, bin_pad, 0); }
            bpg__o_put(&b, e.data.d, e.data.n);
            if (b.failed) { bpg__freef(f, b.d); bpg__oom(f, "writing"); goto fail; }
            out->bin = b.d; out->bin_size = b.n;
        }
    }
    out->vertices_in = e.vertices_in;
    out->vertices_out = e.vertices_out;
    out->rounding_fixed = e.fixed;
    out->accessors_removed = e.accessors_removed;
    out->views_removed = e.views_removed;
    out->bytes_removed = glb_buf0 ? (size_t)f->buf[0].length - e.bin_len : 0;
    bpg__enc_free(&e);
    f->err = &f->scratch;
    return BP_OK;
fail:
    st = f->err->status != BP_OK ? f->err->status : bpg__oom(f, "writing");
    bpg__freef(f, json.d);
    bpg__enc_free(&e);
    bpg_output_free(out);
    f->err = &f->scratch;
    return st;
}

/* Write n bytes to path; on failure the file is removed. */
static int bpg__write_bytes(const char *path, const unsigned char *d, size_t n, char *why, size_t wsz)
{
    FILE *fp = fopen(path, "wb");
    int ok;
    if (!fp) { snprintf(why, wsz, "cannot create '%s': %s", path, strerror(errno)); return 0; }
    ok = fwrite(d, 1, n, fp) == n;
    if (!ok) snprintf(why, wsz, "cannot write '%s': %s", path, strerror(errno));
    if (fclose(fp) != 0 && ok) { ok = 0; snprintf(why, wsz, "cannot write '%s': %s", path, strerror(errno)); }
    if (!ok) remove(path);
    return ok;
}

BPDEF bp_status bpg_write(const bpg_file *file, const bp_atlas *atlas, const char *path, const char *bin_path,
                          const bpg_write_options *wo, bp_error *err)
{
    bpg_write_options w;
    bpg_output out;
    bp_status st;
    char why[sizeof err->message];
    size_t n = strlen(path);
    if (wo) w = *wo; else memset(&w, 0, sizeof w);
    if (!wo || w.glb < 0) w.glb = n >= 4 && (path[n - 1] | 32) == 'b' && (path[n - 2] | 32) == 'l' && (path[n - 3] | 32) == 'g' && path[n - 4] == '.';
    if (w.bin_uri && !bin_path) w.bin_uri = NULL;
    st = bpg_encode(file, atlas, &w, &out, err);
    if (st != BP_OK) return st;
    if (out.bin && !bpg__write_bytes(bin_path, out.bin, out.bin_size, why, sizeof why)) st = BP_ERR_IO;
    else if (!bpg__write_bytes(path, out.data, out.size, why, sizeof why)) {
        st = BP_ERR_IO;
        if (out.bin) remove(bin_path);
    }
    if (st != BP_OK && err) {
        memset(err, 0, sizeof *err);
        err->status = st; err->index = err->index2 = -1;
        snprintf(err->message, sizeof err->message, "%s", why);
    }
    bpg_output_free(&out);
    return st;
}

#endif /* BPG_IMPLEMENTATION */
