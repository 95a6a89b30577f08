/* bijparam.h - v0.1.0 - bijective free-boundary mesh parameterization - MIT license
   (see the end of this file)

   bijparam flattens triangle-mesh charts into the plane (UV space) with a map
   that is guaranteed bijective -- no triangle flips and no boundary overlaps
   itself -- while the chart boundary is free to move, so the distortion is far
   lower than with a pinned boundary.  It follows Jason Smith's dissertation
   "Bijective Parameterization with Free Boundaries" (Smith & Schaefer,
   SIGGRAPH 2015); section numbers below ("sec 3.4.2", "eq 3.3") refer to it.

   QUICK START
   -----------
   In exactly one C or C++ file:

       #define BP_IMPLEMENTATION
       #include "bijparam.h"

   and then:

       bp_mesh mesh;  bp_atlas atlas;  bp_error err;
       bp_options opt = {0};                       -- zero means "defaults"
       if (bp_read_obj("cow.obj", &mesh, NULL, &err) != BP_OK) { puts(err.message); return 1; }
       if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK) { puts(err.message); return 1; }
       bp_write_obj("cow_uv.obj", &mesh, &atlas, &err);
       bp_atlas_free(&atlas);  bp_mesh_free(&mesh, NULL);

   CONTENTS  (search for the banner text, e.g. ">>predicates")
   --------
      >>api            public declarations
      >>config         macros, allocator plumbing, error helpers
      >>predicates     exact orientation and segment tests           (robustness)
      >>io             OBJ / OFF reading, OBJ writing                 (BP_NO_STDIO)
      >>charts         seams, connected components, pinches, loops    (sec 3.1, 3.6)
      >>rest           isometric flattening of each triangle          (sec 3.1)
      >>sparse         ordering + sparse LDL^T / LU direct solver
      >>tutte          Tutte / Floater start with filled holes        (sec 3.4.1, 3.6)
      >>check          exact validity check (the ground truth)
      >>energy         distortion energies and gradients              (sec 3.2)
      >>barrier        boundary barrier with a spatial hash           (sec 3.3)
      >>stepbound      singularity-aware maximum step                 (sec 3.4.2)
      >>lbfgs          search directions and the line search          (sec 3.4, 3.5)
      >>driver         charts -> start -> optimize -> pack

   BUILD OPTIONS  (define before including the implementation)
   -------------
      BP_IMPLEMENTATION     emit the implementation in this translation unit
      BP_STATIC             make every function static (private copy per file)
      BP_NO_STDIO           leave out file reading/writing (no <stdio.h>)
      BP_MALLOC(sz,u)       default allocator (both or neither):
      BP_FREE(p,u)          defaults are malloc/free; u is the user pointer
      BP_ASSERT(x)          internal invariant check, default: nothing

   CONVENTIONS
   -----------
   - Triangles are counter-clockwise seen from outside the surface; a UV
     triangle is valid when its signed area is > 0 (decided exactly).
   - Every index is 0-based uint32_t; file line numbers are 1-based.
   - Every function that can fail returns a bp_status and, if given a
     bp_error, fills it with a message that names the offending element.
   - The library keeps no global state, never prints, never exits.  Every
     allocation goes through the allocator in bp_options (or the one passed
     to the I/O functions); NULL means BP_MALLOC/BP_FREE.
   - Structures whose fields say "0 = default" may be zero-initialized.
*/
#ifndef BIJPARAM_H
#define BIJPARAM_H

/* >>api ====================================================================*/

#include <stddef.h>
#include <stdint.h>

#ifdef BP_STATIC
#define BPDEF static
#else
#define BPDEF extern
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Every status the library returns, with its message (one X-macro list gives
   both the enum and bp_status_string). */
#define BP_STATUS_LIST(X)                                                       \
    X(BP_OK,                 "ok")                                              \
    X(BP_ERR_INVALID_ARGUMENT, "invalid argument")                              \
    X(BP_ERR_OUT_OF_MEMORY,  "out of memory")                                   \
    X(BP_ERR_IO,             "file could not be opened, read or written")       \
    X(BP_ERR_PARSE,          "malformed input file")                            \
    X(BP_ERR_EMPTY,          "mesh has no triangles")                           \
    X(BP_ERR_INDEX,          "index out of range")                              \
    X(BP_ERR_NONFINITE,      "coordinate is NaN or infinite")                   \
    X(BP_ERR_POLYGON,        "face is not a triangle")                          \
    X(BP_ERR_DEGENERATE,     "triangle has (near) zero area")                   \
    X(BP_ERR_DUPLICATE_FACE, "two triangles use the same three vertices")       \
    X(BP_ERR_NONMANIFOLD,    "edge is shared by more than two triangles")       \
    X(BP_ERR_ORIENTATION,    "neighbouring triangles have opposite orientation") \
    X(BP_ERR_TOPOLOGY,       "chart is not a disk or a disk with holes")        \
    X(BP_ERR_NUMERICAL,      "floating point produced an invalid map")          \
    X(BP_ERR_NOT_BIJECTIVE,  "map is not bijective")                            \
    X(BP_ERR_CANCELLED,      "cancelled by the progress callback")

typedef enum bp_status {
#define BP__ENUM(name, text) name,
    BP_STATUS_LIST(BP__ENUM)
#undef BP__ENUM
    BP_STATUS_COUNT
} bp_status;

/* What kind of element an error names. */
typedef enum bp_element {
    BP_ELEMENT_NONE = 0,
    BP_ELEMENT_VERTEX,    /* mesh vertex index                          */
    BP_ELEMENT_TRIANGLE,  /* mesh triangle index                        */
    BP_ELEMENT_EDGE,      /* mesh vertex pair (index, index2)           */
    BP_ELEMENT_CHART,     /* chart index                                */
    BP_ELEMENT_LINE       /* 1-based line of the input file             */
} bp_element;

typedef struct bp_error {
    bp_status  status;
    bp_element element;     /* what `index` refers to                     */
    int64_t    index;       /* -1 when there is none                      */
    int64_t    index2;      /* second vertex of an edge, else -1          */
    int64_t    line;        /* 1-based file line when known, else 0       */
    char       message[256];/* full sentence naming the element           */
} bp_error;

/* The allocator: both functions or neither.  `user` is passed to each call. */
typedef struct bp_allocator {
    void *(*alloc)(void *user, size_t size);
    void  (*free)(void *user, void *ptr);
    void  *user;
} bp_allocator;

/* A triangle mesh as flat arrays.  The reader fills one (and owns its arrays,
   free with bp_mesh_free); you may also point the fields at your own arrays.

   Seams: if corner_uv is set, two triangles that share a mesh edge belong to
   the same chart only when they also use the same uv index at both ends of
   that edge (OBJ `vt` indices).  Without corner_uv the charts are the
   edge-connected components. */
typedef struct bp_mesh {
    double   *positions;     /* 3*num_vertices xyz                          */
    uint32_t  num_vertices;
    uint32_t *triangles;     /* 3*num_triangles vertex indices, CCW         */
    uint32_t  num_triangles;
    uint32_t *corner_uv;     /* optional 3*num_triangles uv indices, or NULL*/
    double   *uvs;           /* optional 2*num_uvs input texture coords     */
    uint32_t  num_uvs;
    uint32_t *triangle_line; /* optional: file line of each triangle (1-based) */
    uint32_t *triangle_face; /* optional: source polygon of each triangle (fan) */
    uint32_t  num_faces;     /* number of source polygons (== triangles if none split) */
} bp_mesh;

typedef enum bp_energy {
    BP_ENERGY_SYMMETRIC_DIRICHLET = 0, /* s1^2+s2^2+s1^-2+s2^-2, eq 3.1-3.3 (min 4) */
    BP_ENERGY_CONFORMAL,               /* s_max/s_min                  (min 1)   */
    BP_ENERGY_MIPS,                    /* s_max/s_min + s_min/s_max    (min 2)   */
    BP_ENERGY_ISOMETRIC,               /* sqrt(s_max^2 + s_min^-2)     (min sqrt2)*/
    BP_ENERGY_MAX_ISOMETRIC,           /* max(s_max, 1/s_min)          (min 1)   */
    BP_ENERGY_COUNT
} bp_energy;

typedef enum bp_init {
    BP_INIT_TUTTE = 0,   /* uniform weights (Tutte 1963)                      */
    BP_INIT_MEAN_VALUE   /* Floater's mean-value weights (Floater 2003)      */
} bp_init;

typedef enum bp_direction {
    BP_DIRECTION_LBFGS = 0,
    BP_DIRECTION_GRADIENT
} bp_direction;

typedef enum bp_stop {
    BP_STOP_NONE = 0,        /* not optimized (init only)                     */
    BP_STOP_CONVERGED,       /* relative decrease below tolerance             */
    BP_STOP_MAX_ITERATIONS,
    BP_STOP_MAX_SECONDS,
    BP_STOP_CANCELLED,
    BP_STOP_NO_PROGRESS      /* line search could not decrease the energy     */
} bp_stop;

/* Progress: called once per iteration of each chart.  Return nonzero to
   cancel; the chart then keeps its last valid (bijective) map. */
typedef int (*bp_progress_fn)(void *user, uint32_t chart, int iteration,
                              double mean_energy, double step);

typedef struct bp_options {
    bp_allocator  allocator;      /* zero: BP_MALLOC / BP_FREE                 */
    bp_init       init;           /* start map, default Tutte                  */
    int           init_only;      /* nonzero: stop after the start map         */
    bp_energy     energy;         /* default symmetric Dirichlet               */
    int           no_barrier;     /* nonzero: injective only (no E_B)          */
    double        epsilon;        /* barrier width; 0: mean 3D boundary edge/4 */
    bp_direction  direction;      /* default L-BFGS                            */
    int           history;        /* L-BFGS memory m; 0: 5                     */
    int           max_iterations; /* 0: 10000                                  */
    double        tolerance;      /* relative decrease; 0: 1e-7                */
    double        max_seconds;    /* per solve; 0: no limit                    */
    bp_progress_fn progress;      /* optional                                  */
    void         *progress_user;
    int           normalize;      /* nonzero: scale the packed atlas into [0,1]^2 */
} bp_options;

/* One chart: a connected piece of the mesh cut along seams.  Chart vertices
   are pairs (mesh vertex, uv index); a pinch vertex is split into one chart
   vertex per fan.  Boundary loops follow the triangles' orientation (interior
   on the left): loop 0 is the outer loop (the longest in 3D), counter-
   clockwise in a valid map; the others are holes, clockwise. */
typedef struct bp_chart {
    uint32_t  num_vertices;
    uint32_t  num_triangles;
    uint32_t *vertex;         /* mesh vertex of each chart vertex            */
    uint32_t *vertex_uv;      /* input uv index of each chart vertex or UINT32_MAX */
    uint32_t *triangles;      /* 3*num_triangles chart vertex indices        */
    uint32_t *face;           /* mesh triangle of each chart triangle        */
    uint32_t  num_loops;
    uint32_t *loop_start;     /* num_loops+1 offsets into loop_vertices      */
    uint32_t *loop_vertices;  /* chart vertices along each loop              */
    uint32_t  split_vertices; /* chart vertices added by pinch repair        */
    double    area3d;         /* total 3D area                               */
    double   *uv;             /* 2*num_vertices: the map (atlas placement)   */
    /* report of the solve */
    double    energy_start, energy_end, energy_max; /* area-weighted mean E_t, max */
    int       iterations;
    bp_stop   stop;
    double    seconds;
} bp_chart;

typedef struct bp_atlas {
    uint32_t     num_charts;
    bp_chart    *charts;
    uint32_t     num_corners;     /* 3 * mesh triangles                      */
    uint32_t    *corner_chart;    /* chart of each mesh corner               */
    uint32_t    *corner_vertex;   /* chart vertex of each mesh corner        */
    uint32_t     num_split;       /* pinch vertices repaired in all charts   */
    bp_allocator allocator;
} bp_atlas;

/* Result of the exact validity check. */
typedef struct bp_check_report {
    uint32_t flipped;              /* signed area < 0 (exact)                 */
    uint32_t degenerate;           /* signed area == 0 (exact)                */
    uint32_t nonfinite;            /* a uv coordinate is NaN/Inf              */
    uint32_t boundary_intersections; /* pairs of boundary edges that meet     */
    int64_t  first_bad_triangle;   /* chart-local triangle, or -1             */
    int64_t  first_bad_edge[2];    /* boundary edge pair (indices into the edge
                                      list, as chart vertex of its start), or -1 */
} bp_check_report;

BPDEF const char *bp_status_string(bp_status s);
BPDEF const char *bp_energy_name(bp_energy e);
BPDEF const char *bp_stop_string(bp_stop s);

/* Split a mesh into validated charts with boundary loops (no map yet). */
BPDEF bp_status bp_atlas_build(bp_atlas *atlas, const bp_mesh *mesh,
                               const bp_options *opt, bp_error *err);
/* The start map of one chart (Tutte or Floater, holes filled, sec 3.6). */
BPDEF bp_status bp_chart_init(bp_chart *chart, const bp_mesh *mesh,
                              const bp_options *opt, bp_error *err);
/* Minimize distortion keeping the map bijective at every iteration (chap 3). */
BPDEF bp_status bp_chart_optimize(bp_chart *chart, uint32_t chart_index,
                                  const bp_mesh *mesh, const bp_options *opt,
                                  bp_error *err);
/* Place the charts side by side without overlap (and into [0,1]^2 if asked). */
BPDEF bp_status bp_atlas_pack(bp_atlas *atlas, const bp_options *opt, bp_error *err);
/* Everything: build, init, optimize, pack.  On failure the atlas is freed. */
BPDEF bp_status bp_parameterize(bp_atlas *atlas, const bp_mesh *mesh,
                                const bp_options *opt, bp_error *err);
BPDEF void      bp_atlas_free(bp_atlas *atlas);

/* Exact validity of a planar triangulation: every triangle positively
   oriented and no two boundary edges meeting except consecutive ones at their
   shared vertex.  Boundary edges are found from the triangles themselves. */
BPDEF bp_status bp_check(const uint32_t *triangles, uint32_t num_triangles,
                         const double *uv, uint32_t num_vertices,
                         const bp_allocator *alloc, bp_check_report *report);

/* Per-triangle distortion of a chart's map under an energy (area-weighted
   mean and max).  per_triangle may be NULL. */
BPDEF bp_status bp_chart_distortion(const bp_chart *chart, const bp_mesh *mesh,
                                    bp_energy energy, double *mean, double *max,
                                    double *per_triangle);

/* Exact sign of the orientation of (a, b, c): +1 counter-clockwise, -1
   clockwise, 0 collinear.  Correct for all finite doubles whose products
   neither overflow nor underflow. */
BPDEF int bp_orient2d(const double a[2], const double b[2], const double c[2]);
/* Exact: do closed segments [a,b] and [c,d] share a point? */
BPDEF int bp_segments_intersect(const double a[2], const double b[2],
                                const double c[2], const double d[2]);

#ifndef BP_NO_STDIO
/* Readers: v, vt, f (v, v/vt, v/vt/vn, v//vn, negative indices), comments,
   CRLF; polygons are fan-triangulated (triangle_face keeps the source face).
   On failure nothing is allocated and err names the file line. */
BPDEF bp_status bp_read_obj(const char *path, bp_mesh *mesh,
                            const bp_allocator *alloc, bp_error *err);
BPDEF bp_status bp_read_off(const char *path, bp_mesh *mesh,
                            const bp_allocator *alloc, bp_error *err);
/* Reads .obj or .off by extension (case-insensitive). */
BPDEF bp_status bp_read_mesh(const char *path, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
/* Writes v in input order, one vt per chart vertex, f v/vt in face order. */
BPDEF bp_status bp_write_obj(const char *path, const bp_mesh *mesh,
                             const bp_atlas *atlas, bp_error *err);
#endif
/* The same parsers on text in memory (used by the fuzzers). */
BPDEF bp_status bp_parse_obj(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
BPDEF bp_status bp_parse_off(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
BPDEF void      bp_mesh_free(bp_mesh *mesh, const bp_allocator *alloc);

#ifdef __cplusplus
}
#endif
#endif /* BIJPARAM_H */
