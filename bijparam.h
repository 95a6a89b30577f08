/* bijparam.h - v0.2.0 - bijective free-boundary mesh parameterization - MIT license
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
       bp_options opt;  memset(&opt, 0, sizeof opt);   -- zero means "defaults"
       if (bp_read_obj("cow.obj", &mesh, NULL, &err) != BP_OK) { puts(err.message); return 1; }
       st = bp_parameterize(&atlas, &mesh, &opt, &err);   -- bp_status st
       if (st != BP_OK) puts(err.message);    -- BP_ERR_CHARTS_FAILED: the others are valid
       if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) bp_write_obj("cow_uv.obj", &mesh, &atlas, &err);
       bp_atlas_free(&atlas);  bp_mesh_free(&mesh, NULL);   -- a zeroed atlas frees harmlessly

   CONTENTS  (search for the banner text, e.g. ">>predicates")
   --------
      >>api            public declarations
      >>config         macros, allocator plumbing, error helpers
      >>progress       whole-run progress and cancel, growing bp_options
      >>threads        deterministic parallel loops, optional pool    (sec 3.5)
      >>predicates     exact orientation and segment tests           (robustness)
      >>io             OBJ / OFF / PLY reading, OBJ writing           (BP_NO_STDIO)
      >>charts         seams, components, repairs, pinches, loops     (sec 3.1, 3.6)
      >>cut            automatic seams: closed / genus > 0 charts to disks
      >>sparse         ordering + sparse LDL^T / LU, supernodal Cholesky
      >>check          exact bijectivity check (the ground truth)
      >>tutte          Tutte / Floater start with filled holes        (sec 3.4.1, 3.6)
      >>rest           isometric flattening of each triangle          (sec 3.1)
      >>energy         distortion energies and gradients              (sec 3.2)
      >>hessian        their projected (PSD) Hessians, closed form
      >>barrier        boundary barrier with a spatial hash           (sec 3.3)
      >>stepbound      singularity-aware maximum step                 (sec 3.4.2)
      >>lbfgs          search directions and the line search          (sec 3.4, 3.5)
      >>newton         projected Newton direction
      >>optimize       one chart's iteration in phases                (sec 3.4, 3.5)
      >>pack           texel density, rotation, outline packing, padding
      >>pins           pinned vertices: the homotopy to the targets
      >>start          planar start, thin-chart barrier, progressive references
      >>segment        several charts: grown by normal deviation, split by distortion
      >>driver         charts -> start -> optimize -> pack
      >>bvh            bounding volume hierarchy, watertight rays      (chap 4)
      >>visibility     view models, V_t, texel density               (sec 4.2, 4.3)

   BUILD OPTIONS  (define before including the implementation)
   -------------
      BP_IMPLEMENTATION     emit the implementation in this translation unit
      BP_STATIC             make every function static (private copy per file)
      BP_NO_STDIO           leave out file reading/writing (no <stdio.h>)
      BP_MALLOC(sz,u)       default allocator (both or neither):
      BP_FREE(p,u)          defaults are malloc/free; u is the user pointer
      BP_ASSERT(x)          internal invariant check, default: nothing
      BP_USE_PTHREADS       a small thread pool inside the header (link with
                            -pthread); without it no link flags are needed
      BP_TRUST_FLT_EVAL_METHOD  accept FLT_EVAL_METHOD != 0 when you know each
                            double operation is rounded to double (>>predicates)
      BP_NO_SIMD            leave out the AVX kernels of the sparse factorization
                            (x86-64, GCC/Clang, chosen at run time; they give
                            the same bits as the plain C loops, >>sparse)

   CONVENTIONS
   -----------
   - Triangles are counter-clockwise seen from outside the surface; a UV
     triangle is valid when its signed area is > 0 (decided exactly).
   - Every index is 0-based uint32_t; file line numbers are 1-based.
   - Every function that can fail returns a bp_status and, if given a
     bp_error, fills it with a message that names the offending element.
     Messages number vertices and triangles as an OBJ file does, from 1
     ("triangle 29 (line 31), vertices 2 8 7"; a polygon split into a fan
     is named as its face), while bp_error.index / index2 stay 0-based.
   - The library keeps no global state, never prints, never exits.  Every
     allocation goes through the allocator in bp_options (or the one passed
     to the I/O functions); NULL means BP_MALLOC/BP_FREE.
   - Use the same allocator (bp_options.allocator) for every call on one
     atlas.  When charts are solved in parallel, the allocator and the
     progress callbacks are called from several threads at once.  The
     per-iteration progress returning nonzero cancels that one chart, not
     the others; run_progress returning nonzero cancels the whole run
     (every chart stops at its next iteration, see >>progress).
   - Size limits (indices are uint32_t): a mesh has fewer than 0x55555555
     triangles (1 431 655 765, so that 3 * num_triangles fits in uint32_t;
     bp_atlas_build says BP_ERR_INVALID_ARGUMENT) and fewer than 2^32 - 1
     vertices, texture coordinates and faces (the readers say
     BP_ERR_INDEX); a chart's sparse factor (the start map's system, the
     preconditioner) holds at most 2^32 - 16 entries, BP_ERR_TOO_LARGE
     beyond, with the chart, its size and the limit named (bimba's 89K
     triangles need 2.5 million entries, 1700 times fewer).  Memory runs
     out long before any of these on most machines.
   - Threads (BP_USE_PTHREADS, options.threads = 0: all cores): a waiting
     thread polls for at most 20 microseconds, then sleeps; charts below
     8192 triangles and small loops run serially; when the threads get
     less than half a core each (other processes keep the cores busy), the
     loops run on the caller alone for a while.  So the default is not
     slower than threads = 1 on a machine busy with other work.
   - Structures whose fields say "0 = default" may be zero-initialized
     (memset, `= {0}` in C, `= {}` in C++).  After a failed call that fills
     a bp_mesh or bp_atlas, the structure is zeroed and safe to free.
   - The one failure rule of bp_atlas_build and bp_parameterize: two
     statuses keep the atlas, BP_ERR_CHARTS_FAILED (some charts failed, not
     in strict mode) and, for bp_parameterize, BP_ERR_CANCELLED.  Then every
     chart is either valid -- mapped, packed without overlap and verified
     exactly -- or a reported failure (chart.error says why, chart.uv is
     NULL), and the caller must bp_atlas_free the atlas.  Every other error
     leaves the atlas zeroed (freeing it is harmless).  When every chart
     fails, the call returns the first chart's own status, not
     BP_ERR_CHARTS_FAILED.
   - Mesh defects.  Fatal, failing the whole call: no triangles, an index
     out of range, a used vertex that is NaN or infinite.  Repaired by
     default and reported in atlas.repairs (count, first elements, a
     sentence naming them as the file does); each is an error naming the
     element with opt.strict: two triangles on the same vertices (the copy
     is dropped), an edge of more than two triangles (made a seam),
     neighbours of opposite orientation (triangles re-oriented; a
     non-orientable component cut), a triangle that repeats a vertex or
     has (near) zero area -- twice the area at most 1e-12 of the squared
     bounding-box diagonal (a regularized rest shape, >>rest).  Local,
     failing only its chart (unless strict): a chart that is closed or of
     genus > 0 when opt.cut is BP_CUT_NONE (by default such a chart is cut
     into a disk along mesh edges, see >>cut).
     The tests are scale-free: a mesh valid at one scale is valid at every
     representable scale, and bp_parameterize solves meshes of extreme size
     (beyond 2^+-100) on an exactly rescaled copy.
*/
#ifndef BIJPARAM_H
#define BIJPARAM_H

/* The version of this header (semantic versioning: a MINOR step adds, a
   MAJOR step may break; CHANGELOG.md lists what changed). */
#define BP_VERSION_MAJOR 0
#define BP_VERSION_MINOR 2
#define BP_VERSION_PATCH 0
#define BP_VERSION_STRING "0.2.0"

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
    X(BP_ERR_CANCELLED,      "cancelled by the progress callback")              \
    X(BP_ERR_CHARTS_FAILED,  "some charts failed; the others are valid")      \
    X(BP_ERR_TOO_LARGE,      "input exceeds a size limit of the library")

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
    BP_INIT_AUTO = 0,    /* the default: conformal (>>conformal) when
                            exactly bijective and below 100,000 triangles,
                            else mean-value, and Tutte if that map fails
                            its exact check (>>tutte)                        */
    BP_INIT_MEAN_VALUE,  /* Floater's mean-value weights (Floater 2003)      */
    BP_INIT_INPUT,       /* the mesh's own uvs (corner_uv/uvs) when exactly
                            bijective, else AUTO; see bp_chart.init_used     */
    BP_INIT_TUTTE,       /* uniform weights (Tutte 1963); the default until
                            0.2 (then = 0), now 3: set it by name            */
    BP_INIT_CONFORMAL    /* least squares conformal (Levy et al. 2002), free
                            boundary, when exactly bijective, at any size
                            (AUTO's stops at 100,000 triangles for memory),
                            else the mean-value map (>>conformal)           */
} bp_init;

typedef enum bp_start {
    BP_START_AUTO = 0,   /* a planar chart: its own projection when exactly
                            bijective; any other: the map of opt.init (>>start) */
    BP_START_PLAIN,      /* the map of opt.init, unchanged (as before 0.3)  */
    BP_START_PROGRESSIVE /* AUTO, then a Tutte start relaxed by rounds of
                            progressive references (>>start)              */
} bp_start;

/* A pinned vertex (see >>pins): chart vertices of mesh vertex `vertex`
   (0-based) end exactly at (u, v).  uv = 0: every chart vertex of it -- on
   a seam that is one in each chart the vertex belongs to, all at the same
   target; uv = k > 0: only the chart vertex whose input uv index
   (mesh->corner_uv, the OBJ vt) is k - 1, i.e. one side of a seam. */
typedef struct bp_pin {
    uint32_t vertex;
    uint32_t uv;          /* 0: all chart vertices of `vertex`; else vt index + 1 */
    double   u, v;
} bp_pin;

typedef enum bp_direction {
    BP_DIRECTION_DEFAULT = 0,        /* chosen per chart before solving (>>optimize,
                                        bp__opt_choose_newton): NEWTON for charts of
                                        20,000-99,999 triangles (start energy
                                        finite), else PRECONDITIONED               */
    BP_DIRECTION_LBFGS,              /* the dissertation's L-BFGS, scalar initial
                                        Hessian (sec 3.5, Algorithm 1)             */
    BP_DIRECTION_GRADIENT,           /* gradient descent (for comparison)          */
    BP_DIRECTION_NEWTON,             /* projected Newton: per-triangle Hessians
                                        projected to PSD, sparse LDL^T (>>newton)  */
    BP_DIRECTION_PRECONDITIONED      /* L-BFGS with the rest-shape Laplacian as
                                        initial Hessian (far fewer iterations);
                                        every chart's default, as the value 0,
                                        until docs/performance.md sec 6.6          */
} bp_direction;

typedef enum bp_stop {
    BP_STOP_NONE = 0,        /* not optimized (init only)                     */
    BP_STOP_CONVERGED,       /* relative decrease below tolerance             */
    BP_STOP_MAX_ITERATIONS,
    BP_STOP_MAX_SECONDS,
    BP_STOP_CANCELLED,
    BP_STOP_NO_PROGRESS      /* line search could not decrease the energy     */
} bp_stop;

/* Progress: called once per iteration of each chart, after the step was
   accepted; during the call the chart's `uv` holds the current map, which
   is exactly valid: every triangle positively oriented (exact predicates)
   and, unless no_barrier is set, the chart bijective (no two boundary
   edges meet and exactly one boundary loop is counter-clockwise: all of
   bp_check for one chart, see >>check).  With no_barrier only the
   orientation is guaranteed.  Return nonzero to cancel; the chart then
   keeps this last valid map. */
typedef int (*bp_progress_fn)(void *user, uint32_t chart, int iteration,
                              double mean_energy, double step);

/* Whole-run progress and cancel (0.2).  One callback for every stage of a
   run, called at its start (fraction 0), as it goes, and at its end
   (fraction 1); `fraction` is the share of that stage done, `chart` the
   chart concerned or BP_NO_CHART.  Returning nonzero cancels the whole
   run: every chart stops at its next iteration, charts not yet started
   are reported failed with BP_ERR_CANCELLED, the calls return
   BP_ERR_CANCELLED, and every map returned is valid (see bp_parameterize).
   It may be called from several threads at once when charts are solved in
   parallel; the stages start and optimize of different charts interleave
   then.  The per-iteration `progress` keeps its meaning: its nonzero
   return stops that one chart only. */
typedef enum bp_stage {
    BP_STAGE_READ = 0,    /* bp_read_mesh_opt: bytes loaded, then parsed      */
    BP_STAGE_CHARTS,      /* bp_atlas_build                                   */
    BP_STAGE_START,       /* bp_chart_init (Tutte / Floater)                  */
    BP_STAGE_VISIBILITY,  /* bp_visibility (chapter 4), when views are set    */
    BP_STAGE_OPTIMIZE,    /* bp_chart_optimize, once per iteration            */
    BP_STAGE_PACK,        /* bp_atlas_pack and the final exact check          */
    BP_STAGE_WRITE,       /* bp_write_obj_opt: faces written                  */
    BP_STAGE_COUNT
} bp_stage;
#define BP_NO_CHART 0xffffffffu
typedef int (*bp_run_progress_fn)(void *user, bp_stage stage, double fraction, uint32_t chart);

/* Parallel loops.  The library splits its heavy loops into `count` tasks
   whose results it combines in a fixed order, so the output is bit-identical
   for any number of threads.  A parallel_for must call fn(task, i) once for
   every i in [0, count), in any order and on any threads, and return when
   all calls have returned.  Charts below 8192 triangles, and loops too
   small to gain, run on the calling thread without it. */
typedef void (*bp_task_fn)(void *task, uint32_t index);
typedef void (*bp_parallel_for_fn)(void *user, bp_task_fn fn, void *task, uint32_t count);

/* View models of fig 4.3: where the camera may be, as directions toward it. */
typedef enum bp_view_model {
    BP_VIEW_NONE = 0,
    BP_VIEW_UNIFORM,      /* the whole sphere (ambient occlusion)              */
    BP_VIEW_FRONT,        /* the hemisphere around views.direction             */
    BP_VIEW_RING,         /* a turntable circle at views.elevation about views.up */
    BP_VIEW_SIDE,         /* the single direction views.direction              */
    BP_VIEW_LIST          /* weighted directions in views.list                 */
} bp_view_model;

typedef struct bp_views {
    int      model;           /* bp_view_model; 0 = none                    */
    double   direction[3];    /* FRONT axis, SIDE direction (0: +z, +x)      */
    double   up[3];           /* RING axis (0: +y)                          */
    double   elevation;       /* RING elevation in degrees                  */
    const double *list;       /* LIST: x y z weight per direction           */
    uint32_t list_count;
    uint32_t samples;         /* rays per triangle; 0: 64                   */
    uint64_t seed;            /* random stream seed                         */
    double   floor;           /* least importance, relative to the mean;
                                 0: 0.05 (hidden triangles keep some area)  */
} bp_views;

/* What to do with a chart that is not a disk (with holes): a closed
   surface, or one with handles (genus > 0). */
typedef enum bp_cut {
    BP_CUT_AUTO = 0,     /* cut it into a disk along mesh edges (>>cut)        */
    BP_CUT_NONE          /* reject it (BP_ERR_TOPOLOGY in chart.error)          */
} bp_cut;

typedef struct bp_options {
    bp_allocator  allocator;      /* zero: BP_MALLOC / BP_FREE                 */
    bp_init       init;           /* start map, default AUTO (conformal, else
                                     mean-value)                           */
    int           init_only;      /* nonzero: stop after the start map         */
    bp_energy     energy;         /* default symmetric Dirichlet               */
    int           no_barrier;     /* nonzero: locally injective only: no E_B and
                                     no boundary check, so the map may overlap
                                     itself (fig 3.2, 3.3)                     */
    double        epsilon;        /* barrier width; 0: mean 3D boundary edge/4 */
    bp_direction  direction;      /* default: per chart (BP_DIRECTION_DEFAULT) */
    int           history;        /* L-BFGS memory m; 0: 5                     */
    int           max_iterations; /* 0: 10000                                  */
    double        tolerance;      /* relative decrease; 0: 1e-7                */
    double        max_seconds;    /* per chart; 0: no limit (wall time with
                                     BP_USE_PTHREADS, else processor time)      */
    bp_progress_fn progress;      /* optional                                  */
    void         *progress_user;
    int           normalize;      /* nonzero: scale the packed atlas into [0,1]^2 */
    int           threads;        /* with BP_USE_PTHREADS: 0 = all cores, 1 = serial */
    bp_parallel_for_fn parallel_for; /* your own job system (overrides threads)  */
    void         *parallel_user;
    const double *importance;     /* optional weight per mesh triangle (> 0); the
                                     map gives triangle t about importance[t] times
                                     its 3D area (eq 4.1); NULL = 1 everywhere     */
    bp_views      views;          /* visibility-aware maps (chapter 4)         */
    int           strict;         /* nonzero: any defect (those repaired by
                                     default included) or chart failure fails
                                     the whole call.  Zero (default): flipped,
                                     duplicate, non-manifold and degenerate
                                     triangles are repaired (atlas.repairs); a
                                     chart that cannot be flattened (a local
                                     defect, see CONVENTIONS) is reported in
                                     chart.error, the others are still solved,
                                     and the call returns BP_ERR_CHARTS_FAILED
                                     with the atlas kept: free it             */
    /* ---- added in 0.2.0 (see bp_options_init: growing the struct) ---- */
    size_t        struct_size;    /* sizeof(bp_options) of the caller's header,
                                     set by bp_options_init; 0: the 0.2.0 size */
    bp_run_progress_fn run_progress; /* whole-run progress and cancel, optional */
    void         *run_progress_user;
    /* Packing (>>pack). */
    int           atlas_resolution; /* texels per side of a square atlas: the
                                     charts are packed by their rasterized
                                     outlines at one texel density into
                                     [0,1]^2 (normalize is implied).  0: no
                                     fixed resolution, the shelf packing of
                                     bounding boxes (3D units, or [0,1]^2 with
                                     normalize), unchanged since 0.1          */
    int           padding;        /* with atlas_resolution: at least this many
                                     texels between any two charts, and
                                     ceil(padding/2) between every chart and
                                     the edge of [0,1]^2, measured on the
                                     final UVs.  0: none (charts still never
                                     share a texel).  Negative is invalid     */
    int           no_rotation;    /* nonzero: keep each chart's orientation
                                     (no minimum-area-box rotation and no 90
                                     degree turns).  0: rotate when it packs
                                     better                                   */
    const bp_pin *pins;           /* pinned vertices (see >>pins); NULL or
                                     num_pins 0: none.  Pinned charts are not
                                     moved by packing; pins together with
                                     normalize or atlas_resolution are
                                     refused (BP_ERR_INVALID_ARGUMENT)         */
    uint32_t      num_pins;
    bp_cut        cut;            /* charts that are closed or of genus > 0:
                                     BP_CUT_AUTO (default) cuts them into disks
                                     (>>cut), BP_CUT_NONE rejects them         */
    /* Segmentation into several charts (>>segment). */
    int           segment;        /* 0: automatic -- on when atlas_resolution,
                                     max_distortion or max_charts is set; 1:
                                     always; -1: never (the charts are the
                                     input's, cut only where >>cut must)       */
    double        max_distortion; /* > 0: a chart whose mean distortion (under
                                     `energy`, area-weighted) stays above this
                                     after the optimization is split and its
                                     pieces optimized again.  0: no bound      */
    uint32_t      max_charts;     /* > 0: at most this many charts (those of the
                                     input count; a mesh with more is left as
                                     it is).  0: no limit                     */
    bp_start      start;          /* BP_START_AUTO (default): a planar chart
                                     starts from its own projection, others
                                     from the init map; BP_START_PLAIN: the
                                     init map always; BP_START_PROGRESSIVE:
                                     AUTO, then progressive references
                                     (>>start)                                 */
} bp_options;

/* Growing bp_options.  New fields are only ever appended, so a caller's
   positional initializer keeps its meaning, and zero is the default of
   every field.  `struct_size` tells the library how large the caller's
   struct is: fields beyond it are read as zero, never from the caller's
   memory, so a program built against this header keeps working with a
   later implementation that has more fields.  Fill it with
   bp_options_init (defaults, i.e. zeros, and struct_size = sizeof), or
   leave it 0, which means the 0.2.0 layout.  A struct_size larger than
   the library's is accepted only when every byte the library does not
   know is zero (else BP_ERR_INVALID_ARGUMENT: a field this version cannot
   honour).  Callers built against 0.1.0, which had no struct_size, must
   be recompiled (a single header is compiled with its caller anyway). */
BPDEF void bp_options_init(bp_options *opt);
/* Short name of a stage ("read", "charts", "start", "visibility",
   "optimize", "pack", "write"); "unknown" out of range. */
BPDEF const char *bp_stage_name(bp_stage s);

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
    uint32_t  cut_edges;      /* mesh edges cut by automatic seams (>>cut)   */
    double   *rest_side;      /* NULL, or per chart triangle: 0 = flattened as
                                 its 3D shape; s > 0 = a degenerate triangle
                                 (repaired) flattened as the equilateral
                                 triangle of side s (>>rest)                 */
    double    area3d;         /* total 3D area (a repaired degenerate
                                 triangle counts with its rest shape)        */
    double   *uv;             /* 2*num_vertices: the map (atlas placement)   */
    /* report of the solve */
    double    energy_start, energy_end, energy_max; /* area-weighted mean E_t, max */
    int       iterations;
    bp_stop   stop;
    double    seconds;
    int       threads;        /* threads used (0: a user parallel_for)         */
    bp_error  error;          /* BP_OK, or why this chart has no map (then uv
                                 is NULL); see bp_options.strict            */
    int       init_used;      /* BP_INIT_INPUT: 1 the input uvs were the start,
                                 -1 they were missing or not bijective and
                                 the AUTO map was used instead; 0: not asked */
    uint32_t  num_pins;       /* chart vertices pinned (opt.pins)            */
    int       in_place;       /* nonzero: packing left the chart where its
                                 start map put it (pins, or input uvs)      */
    uint32_t *start_order;    /* the library's own, NULL or set by
                                 bp_chart_init: the start map's nested-
                                 dissection order of the chart's vertices,
                                 which bp_chart_optimize takes for its first
                                 factorization (>>tutte, phase 5b); freed
                                 with the chart or by bp_chart_optimize    */
    int       start_map;      /* set by bp_chart_init, which start it made:
                                 BP_INIT_CONFORMAL, _MEAN_VALUE, _TUTTE or
                                 _INPUT, or BP_INIT_AUTO for a planar chart's
                                 own projection (>>start)                   */
} bp_chart;

/* Repairs (bp_atlas.repairs).  Outside opt.strict, bp_atlas_build mends
   the defects real assets carry instead of rejecting the mesh (>>charts,
   "repair"), and reports each kind: how many, the first few elements
   (0-based, as bp_error.index) and a sentence naming them as the file does
   (from 1, with file lines).  With opt.strict each is an error instead. */
typedef enum bp_repair_kind {
    BP_REPAIR_FLIPPED = 0,      /* triangle re-oriented to agree with its
                                   component (first2: -1)                    */
    BP_REPAIR_NONORIENTABLE,    /* edge first-first2 cut into a seam: its
                                   component is non-orientable (Moebius)    */
    BP_REPAIR_DUPLICATE,        /* triangle dropped, a copy of triangle first2 */
    BP_REPAIR_NONMANIFOLD_EDGE, /* edge first-first2 of more than two
                                   triangles made a seam for all of them     */
    BP_REPAIR_DEGENERATE,       /* zero-area or repeated-vertex triangle given
                                   a regularized rest shape (>>rest)         */
    BP_REPAIR_KINDS
} bp_repair_kind;

#define BP_REPAIR_FIRST 4
typedef struct bp_repair {
    uint32_t   count;
    bp_element element;                 /* BP_ELEMENT_TRIANGLE or _EDGE       */
    int64_t    first[BP_REPAIR_FIRST];  /* first elements, -1 beyond count    */
    int64_t    first2[BP_REPAIR_FIRST]; /* edge: second vertex; duplicate: the
                                           triangle kept; else -1             */
    char       message[256];            /* "" when count is 0                 */
} bp_repair;

typedef struct bp_repair_report {
    uint32_t  total;                    /* sum of the counts                  */
    bp_repair kind[BP_REPAIR_KINDS];    /* indexed by bp_repair_kind          */
} bp_repair_report;

typedef struct bp_atlas {
    uint32_t     num_charts;
    bp_chart    *charts;
    uint32_t     num_corners;     /* 3 * mesh triangles                      */
    uint32_t    *corner_chart;    /* chart of each mesh corner               */
    uint32_t    *corner_vertex;   /* chart vertex of each mesh corner        */
    uint32_t     num_split;       /* pinch vertices repaired in all charts   */
    uint32_t     num_failed;      /* charts without a map (chart.error says why) */
    bp_repair_report repairs;     /* defects mended (not strict), see above  */
    bp_allocator allocator;
    double       utilization;     /* after bp_atlas_pack: total UV area of the
                                     charts over the atlas area (the square
                                     [0,1]^2 with atlas_resolution, else the
                                     square on the longer side of the packing) */
} bp_atlas;

/* Result of the exact validity check (see bp_check).  The counts describe
   the whole map; the first_* fields name the first bad element in the
   caller's own 0-based indices. */
typedef struct bp_check_report {
    uint32_t flipped;              /* signed area < 0 (exact)                 */
    uint32_t degenerate;           /* signed area == 0 (exact)                */
    uint32_t nonfinite;            /* triangles with a NaN/Inf coordinate     */
    uint32_t boundary_intersections; /* pairs of boundary edges that meet     */
    uint32_t loop_orientation;     /* connected pieces without exactly one
                                      counter-clockwise boundary loop, plus
                                      pinched boundary vertices               */
    uint32_t nested;               /* pieces lying on another piece           */
    int64_t  first_bad_triangle;   /* triangle index, or -1                   */
    int64_t  first_bad_edge[2];    /* start vertices of the first pair of
                                      boundary edges that meet, or -1         */
    /* the precondition: an oriented manifold triangulation */
    uint32_t nonmanifold_edges;    /* edges used by more than two triangles   */
    uint32_t misoriented_edges;    /* edges used twice in one direction: a
                                      triangle listed twice, or neighbours of
                                      opposite orientation                    */
    int64_t  first_nonmanifold_edge[2]; /* vertices of the first edge counted
                                      in either of the two, or -1             */
} bp_check_report;

BPDEF const char *bp_status_string(bp_status s);
BPDEF const char *bp_energy_name(bp_energy e);
BPDEF const char *bp_stop_string(bp_stop s);
/* Short name of a repair kind ("flipped", "nonorientable", "duplicate",
   "nonmanifold_edge", "degenerate"), as the tool's --json uses it. */
BPDEF const char *bp_repair_name(bp_repair_kind k);

/* Split a mesh into validated charts with boundary loops (no map yet).
   BP_ERR_CHARTS_FAILED keeps the atlas with the failed charts reported in
   chart.error; any other error zeroes it (CONVENTIONS: the failure rule).
   A mesh of 8192 triangles or more is checked and glued on opt->threads
   (or opt->parallel_for); the atlas, the repairs and the first error are
   those of one thread. */
BPDEF bp_status bp_atlas_build(bp_atlas *atlas, const bp_mesh *mesh,
                               const bp_options *opt, bp_error *err);
/* The start map of one chart (Tutte or Floater, holes filled, sec 3.6; or
   the input uvs with BP_INIT_INPUT), carried onto opt->pins if the chart
   has any (see >>pins).  Charts of 8192 triangles or more factor
   their system on opt->threads. */
BPDEF bp_status bp_chart_init(bp_chart *chart, const bp_mesh *mesh,
                              const bp_options *opt, bp_error *err);
/* Minimize distortion keeping the map bijective at every iteration (chap 3).
   The start map in chart->uv (bp_chart_init's or your own) is checked with
   bp_check first: an invalid one fails with BP_ERR_NOT_BIJECTIVE (or
   BP_ERR_NONFINITE) naming the triangle or the boundary edges; without the
   barrier only its triangles' orientation is required.  Pinned vertices
   (opt->pins) are held fixed and must be at their targets in the start. */
BPDEF bp_status bp_chart_optimize(bp_chart *chart, uint32_t chart_index,
                                  const bp_mesh *mesh, const bp_options *opt,
                                  bp_error *err);
/* bp_chart_init, then (unless opt->init_only, or it failed)
   bp_chart_optimize: the same map, bit for bit, and the same statuses,
   but what the two share is kept between them instead of being made
   twice: the conformal start's factorization serves Newton's first one
   (on face, 0.05 s of 0.6).  bp_atlas_solve and bp_parameterize do this
   for every chart. */
BPDEF bp_status bp_chart_solve(bp_chart *chart, uint32_t chart_index,
                               const bp_mesh *mesh, const bp_options *opt,
                               bp_error *err);
/* Place the charts side by side without overlap (and into [0,1]^2 if asked).
   With opt->atlas_resolution the charts are scaled to one texel density,
   rotated and packed by their rasterized outlines with opt->padding texels
   between them (>>pack); every moved chart is re-checked exactly (on
   opt->threads when the charts have 8192 triangles or more).
   Charts with pins, and charts started from their input uvs (without
   normalize or atlas_resolution), stay where they are: see chart.in_place
   and >>pins; pins with normalize or atlas_resolution are refused. */
BPDEF bp_status bp_atlas_pack(bp_atlas *atlas, const bp_options *opt, bp_error *err);
/* Take each chart's map from the mesh's own texture coordinates (mesh->uvs
   through chart.vertex_uv) instead of computing one, for repacking a mesh
   that is already parameterized.  Each chart's input map is checked exactly;
   a chart without texture coordinates or whose map is not bijective is
   marked failed (chart.error names it) and is not packed.  Returns BP_OK,
   or BP_ERR_CHARTS_FAILED when some charts failed. */
BPDEF bp_status bp_atlas_use_input_uvs(bp_atlas *atlas, const bp_mesh *mesh, bp_error *err);
/* Segmentation (>>segment), used by bp_parameterize when bp__seg_enabled:
   bp_atlas_segment, after bp_atlas_build, splits every chart into charts
   of bounded normal deviation (at most opt->max_charts in all);
   bp_atlas_solve is the start map and optimization of every chart, the
   charts in parallel (BP_ERR_CHARTS_FAILED: some failed, reported in
   chart.error); bp_atlas_refine, after the solve, splits every chart whose
   mean distortion is above opt->max_distortion and optimizes the pieces
   again from their part of the map.  Each keeps every map valid and the
   result bit-identical for any number of threads; with segmentation off
   (opt->segment -1, or no atlas_resolution / max_distortion / max_charts,
   or input uvs or pins) bp_atlas_segment and bp_atlas_refine do nothing. */
BPDEF bp_status bp_atlas_segment(bp_atlas *atlas, const bp_mesh *mesh, const bp_options *opt, bp_error *err);
BPDEF bp_status bp_atlas_solve(bp_atlas *atlas, const bp_mesh *mesh, const bp_options *opt, bp_error *err);
BPDEF bp_status bp_atlas_refine(bp_atlas *atlas, const bp_mesh *mesh, const bp_options *opt, bp_error *err);
/* Everything: build, init, optimize, pack, and an exact check of the packed
   atlas.  BP_OK: every chart mapped.  BP_ERR_CHARTS_FAILED (not strict) and
   BP_ERR_CANCELLED: the atlas is kept, every chart valid or reported failed,
   and must be freed; any other error zeroes it (CONVENTIONS).  A cancel by
   run_progress while the visibility is computed or the charts are built
   leaves no charts (zeroed). */
BPDEF bp_status bp_parameterize(bp_atlas *atlas, const bp_mesh *mesh,
                                const bp_options *opt, bp_error *err);
BPDEF void      bp_atlas_free(bp_atlas *atlas);
/* Mark chart `chart` as failed for the reason in `why` (copied into
   chart.error); its map is freed and bp_atlas_pack / bp_write_obj skip it.
   For callers that run the steps themselves and want bp_parameterize's
   tolerant behaviour. */
BPDEF void      bp_atlas_fail_chart(bp_atlas *atlas, uint32_t chart, const bp_error *why);

/* Exact bijectivity of a planar triangulation (one chart or several):
   every triangle positively oriented, no two boundary edges meeting except
   consecutive ones at their shared vertex, each connected piece bounded by
   exactly one counter-clockwise loop, and no piece on another.  The
   triangles must form an oriented manifold (each edge used once, or twice in
   opposite directions), as charts do; bp_check verifies that too.  Boundary
   edges are found from the triangles themselves.  Every finite coordinate is
   handled exactly (a map outside the predicates' range is scaled by a power
   of two), except maps whose nonzero magnitudes span more than 2^994.
   bp_check runs on the caller's thread; the library's own checks (of a
   start map, an optimizer's start, a packed chart) run the same tasks on
   opt->threads, with the same result (>>check).

   Returns BP_OK only for a valid map.  A verdict of "not valid" fills the
   report and names the first bad element in err (0-based indices into your
   arrays; err may be NULL):
     BP_ERR_NONMANIFOLD / BP_ERR_ORIENTATION  the precondition fails (edge named;
                              only the triangle counts are filled then),
     BP_ERR_NONFINITE         a NaN or infinite coordinate (triangle named),
     BP_ERR_NOT_BIJECTIVE     a flipped or degenerate triangle, two boundary
                              edges that meet, a wrongly oriented or nested
                              piece (triangle, edges or vertices named).
   Failures to check: BP_ERR_INVALID_ARGUMENT (NULL arrays, or the range
   above), BP_ERR_INDEX (a vertex index >= num_vertices), BP_ERR_OUT_OF_MEMORY. */
BPDEF bp_status bp_check(const uint32_t *triangles, uint32_t num_triangles,
                         const double *uv, uint32_t num_vertices,
                         const bp_allocator *alloc, bp_check_report *report, bp_error *err);

/* Per-triangle distortion of a chart's map under an energy: the
   area-weighted mean and the max of E_t, each optional, and E_t of every
   chart triangle into per_triangle (NULL: not wanted).  err may be NULL. */
BPDEF bp_status bp_chart_distortion(const bp_chart *chart, const bp_mesh *mesh,
                                    bp_energy energy, double *mean, double *max,
                                    double *per_triangle, bp_error *err);

/* Chapter 4.  Visibility V_t of each mesh triangle under opt->views (eq
   4.2), normalized to an area-weighted mean of 1 and floored at
   opt->views.floor; `out` has num_triangles entries. */
BPDEF bp_status bp_visibility(const bp_mesh *mesh, const bp_options *opt, double *out, bp_error *err);
/* Texel density of sec 4.3: the mean, over the visible texels (texture
   area whose surface point is seen) and the view directions of opt->views,
   of det of the Jacobian from texture to screen space -- the screen area of
   a texel -- with the atlas scaled to the mesh's 3D area.  Lower means
   denser texels; the fig 4.8 ratio of a map against a reference map is
   reference / map. */
BPDEF bp_status bp_texture_to_screen(const bp_mesh *mesh, const bp_atlas *atlas,
                                     const bp_options *opt, double *mean_det, bp_error *err);

/* Exact sign of the orientation of (a, b, c): +1 counter-clockwise, -1
   clockwise, 0 collinear.  Exact whenever every nonzero coordinate has a
   magnitude in [2^-485, 2^510) (about 1.0e-146 to 3.3e153): then no product
   overflows and no rounding error underflows (see >>predicates).  bp_check
   scales maps outside that range by a power of two first. */
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
/* PLY (ASCII, binary little and big endian): the `vertex` element's x y z
   (float or double, any order, other properties and lists skipped), the
   `face` element's vertex_indices / vertex_index list (any integer type),
   polygons fan-triangulated; per-vertex s t / u v / texture_u texture_v /
   texture_s texture_t become the uvs, one per vertex (so no seams; a
   per-face texcoord list is read past).  Errors name
   the element as the header numbers it (vertex 7, face 12, from 1) with
   the line (ASCII) or byte offset (binary). */
BPDEF bp_status bp_read_ply(const char *path, bp_mesh *mesh,
                            const bp_allocator *alloc, bp_error *err);
/* Reads .obj, .off or .ply by extension (case-insensitive). */
BPDEF bp_status bp_read_mesh(const char *path, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
/* The same with options: the allocator of opt, and opt->run_progress called
   with BP_STAGE_READ (bytes loaded, then bytes parsed); a cancel returns
   BP_ERR_CANCELLED with *mesh zeroed.  An OBJ of 1 MiB or more is parsed on
   opt->threads (or opt->parallel_for): the same mesh and the same errors
   as on one thread (>>io, "OBJ on several threads"). */
BPDEF bp_status bp_read_mesh_opt(const char *path, bp_mesh *mesh,
                                 const bp_options *opt, bp_error *err);
/* Writers.  Both write `path` directly and, on any error, remove what
   they wrote (no half-written file); the messages give the reason
   (strerror).  bp_write_obj writes the mesh alone: v in input order, one vt
   per chart vertex, f v/vt in face order (polygons as read, except one
   whose fan triangles give a corner two vt -- a seam along a diagonal --
   which is written as its triangles).
   bp_write_obj_from keeps everything else of the OBJ file `source` the
   mesh was read from: every line comes back byte for byte and in order
   (vn, usemtl, mtllib, g, o, s, l, comments, unknown statements, CRLF),
   except that the old vt lines are replaced by the new ones (placed where
   the first vt or f line was) and each f corner gets its new vt index,
   keeping its v and vn indices as written.  Faces of failed charts keep v
   (and vn) without vt.  In both, a face the repair re-oriented
   (atlas->repairs, BP_REPAIR_FLIPPED) has its corners in the repaired
   order: corner 0, then the others reversed -- the v/vt/vn triples moved,
   never altered -- so every face agrees with its uvs.  `source` must be the file the mesh was read from
   (checked face by face: BP_ERR_INVALID_ARGUMENT otherwise) and another
   path than `path` (the same string is refused; the library cannot tell
   two names of one file apart -- the tool compares device and inode). */
BPDEF bp_status bp_write_obj(const char *path, const bp_mesh *mesh,
                             const bp_atlas *atlas, bp_error *err);
BPDEF bp_status bp_write_obj_from(const char *path, const char *source, const bp_mesh *mesh,
                                  const bp_atlas *atlas, bp_error *err);
/* Either writer with options: source NULL is bp_write_obj, else
   bp_write_obj_from; opt->run_progress is called with BP_STAGE_WRITE (faces
   written) and a cancel removes what was written and returns
   BP_ERR_CANCELLED.  Large outputs are formatted on opt->threads (or
   opt->parallel_for): the same bytes and errors as on one thread. */
BPDEF bp_status bp_write_obj_opt(const char *path, const char *source, const bp_mesh *mesh,
                                 const bp_atlas *atlas, const bp_options *opt, bp_error *err);
#endif
/* "obj", "off" or "ply" for a path's extension (case-insensitive), else NULL. */
BPDEF const char *bp_mesh_format(const char *path);
/* The same parsers on text in memory (used by the fuzzers). */
BPDEF bp_status bp_parse_obj(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
BPDEF bp_status bp_parse_off(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
BPDEF bp_status bp_parse_ply(const char *data, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err);
BPDEF void      bp_mesh_free(bp_mesh *mesh, const bp_allocator *alloc);

/* Positions from the caller's vertex buffer (0.2): float or double x y z
   at any byte stride (an interleaved vertex struct), triangles as uint32.
   The library computes in double (exact predicates, rest shapes, the
   barrier), so bp_mesh_from_view gives a bp_mesh whose triangles point at
   view->triangles (no copy) and whose positions point at the caller's
   array when it already is packed double (stride 0 or 24: no copy), else
   at packed doubles converted once (24 bytes per vertex; 14 ms per
   million vertices measured, float at stride 32 -- little next to the
   solve, which reads each position many times).  The mesh borrows the
   caller's arrays: free it with bp_mesh_view_free, not bp_mesh_free. */
typedef enum bp_scalar { BP_SCALAR_F64 = 0, BP_SCALAR_F32 } bp_scalar;
typedef struct bp_mesh_view {
    const void     *positions;       /* x of vertex 0; y, z follow            */
    bp_scalar       position_type;   /* double (default) or float             */
    size_t          position_stride; /* bytes between vertices; 0: packed xyz */
    uint32_t        num_vertices;
    const uint32_t *triangles;       /* 3*num_triangles vertex indices, CCW   */
    uint32_t        num_triangles;
} bp_mesh_view;
BPDEF bp_status bp_mesh_from_view(bp_mesh *mesh, const bp_mesh_view *view,
                                  const bp_allocator *alloc, bp_error *err);
BPDEF void      bp_mesh_view_free(bp_mesh *mesh, const bp_mesh_view *view, const bp_allocator *alloc);

#ifdef __cplusplus
}
#endif
#endif /* BIJPARAM_H */

/* ==========================================================================
   IMPLEMENTATION
   ========================================================================== */
#if defined(BP_IMPLEMENTATION) && !defined(BP__IMPLEMENTATION_DONE)
#define BP__IMPLEMENTATION_DONE

/* >>config =================================================================

   Everything the implementation needs from the C library is here: memory
   (through the allocator), <math.h>, <string.h>, <stdlib.h> for qsort and
   strtod, <time.h> for the optional time limit, and <stdio.h> only for the
   file functions.  Overriding half of the BP_MALLOC/BP_FREE pair is an
   error: memory from one allocator must go back to the same one. */

#include <string.h>
#include <stdarg.h>
#include <stdlib.h>
#include <math.h>
#include <float.h>
#include <time.h>
#ifndef BP_NO_STDIO
#include <stdio.h>
#include <errno.h>      /* the reason of a failed file operation (strerror) */
#endif
/* The dense kernels of the supernodal factorization on AVX registers
   (>>sparse), x86-64 with GCC or Clang only, the processor asked at run
   time; the same bits as the plain loops.  BP_NO_SIMD leaves them out. */
#if !defined(BP_NO_SIMD) && (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define BP__AVX 1
#include <immintrin.h>
#ifndef BP__HAVE_AVX
#define BP__HAVE_AVX() __builtin_cpu_supports("avx")
#endif
#else
#define BP__AVX 0
#undef BP__HAVE_AVX
#define BP__HAVE_AVX() 0
#endif

#if defined(BP_MALLOC) != defined(BP_FREE)
#error "bijparam.h: define both BP_MALLOC and BP_FREE, or neither"
#endif
#ifndef BP_MALLOC
#define BP_MALLOC(sz, u) ((void)(u), malloc(sz))
#define BP_FREE(p, u)    ((void)(u), free(p))
#endif
#ifndef BP_ASSERT
#define BP_ASSERT(x) ((void)0)
#endif

#if defined(BP_STATIC) && (defined(__GNUC__) || defined(__clang__))
/* A static copy of the API: functions this translation unit does not call
   are expected, not a mistake. */
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

#define BP__NONE 0xffffffffu

/* All allocation goes through these two.  A zero allocator (both function
   pointers NULL) means BP_MALLOC/BP_FREE, which still receive `user`. */
static void *bp__alloc(const bp_allocator *a, size_t n)
{
    if (n == 0) n = 1;
    if (a->alloc) return a->alloc(a->user, n);
    return BP_MALLOC(n, a->user);
}

static void bp__free(const bp_allocator *a, void *p)
{
    if (!p) return;
    if (a->free) a->free(a->user, p);
    else BP_FREE(p, a->user);
}

/* count*size with an overflow check before every array allocation. */
static void *bp__alloc_array(const bp_allocator *a, size_t count, size_t size)
{
    if (size != 0 && count > (size_t)-1 / size) return NULL;
    return bp__alloc(a, count * size);
}

static void *bp__calloc_array(const bp_allocator *a, size_t count, size_t size)
{
    void *p = bp__alloc_array(a, count, size);
    if (p) memset(p, 0, (count && size) ? count * size : 1);
    return p;
}

static bp_allocator bp__allocator_of(const bp_options *opt)
{
    bp_allocator a;
    memset(&a, 0, sizeof a);
    if (opt && (opt->allocator.alloc || opt->allocator.free || opt->allocator.user))
        a = opt->allocator;
    return a;
}

/* A growable array that remembers its allocator (used by the parsers). */
typedef struct bp__vec {
    void  *data;
    size_t count, cap, elem;
} bp__vec;

static int bp__vec_reserve(const bp_allocator *a, bp__vec *v, size_t need)
{
    size_t cap;
    void *p;
    if (need <= v->cap) return 1;
    cap = v->cap ? v->cap : 64;
    while (cap < need) {
        if (cap > (size_t)-1 / 2) return 0;
        cap *= 2;
    }
    p = bp__alloc_array(a, cap, v->elem);
    if (!p) return 0;
    if (v->count) memcpy(p, v->data, v->count * v->elem);
    bp__free(a, v->data);
    v->data = p;
    v->cap = cap;
    return 1;
}

/* One item at the end.  The parsers push every coordinate and index this
   way, so the common sizes are copied with a constant size (a move, not a
   call to memcpy: 3-4 ms of face's 20 ms read). */
static int bp__vec_push(const bp_allocator *a, bp__vec *v, const void *item)
{
    char *to;
    if (v->count >= v->cap && !bp__vec_reserve(a, v, v->count + 1)) return 0;
    to = (char *)v->data + v->count++ * v->elem;
    if (v->elem == 4) memcpy(to, item, 4);
    else if (v->elem == 8) memcpy(to, item, 8);
    else memcpy(to, item, v->elem);
    return 1;
}

/* --- error messages ------------------------------------------------------

   Messages are formatted by a small formatter of our own so that the
   library needs no <stdio.h> when BP_NO_STDIO is set.  It knows %s (string),
   %d (int), %u (unsigned), %D (int64_t) and %g (double, 6 significant
   digits, enough for a message). */

static void bp__fmt_char(char *out, size_t *n, size_t cap, char c)
{
    if (*n + 1 < cap) out[(*n)++] = c;
}

static void bp__fmt_uint(char *out, size_t *n, size_t cap, uint64_t v)
{
    char tmp[24];
    int k = 0;
    do { tmp[k++] = (char)('0' + (int)(v % 10)); v /= 10; } while (v);
    while (k) bp__fmt_char(out, n, cap, tmp[--k]);
}

static void bp__fmt_int(char *out, size_t *n, size_t cap, int64_t v)
{
    if (v < 0) { bp__fmt_char(out, n, cap, '-'); bp__fmt_uint(out, n, cap, (uint64_t)0 - (uint64_t)v); }
    else bp__fmt_uint(out, n, cap, (uint64_t)v);
}

static void bp__fmt_double(char *out, size_t *n, size_t cap, double v)
{
    int e = 0, i;
    uint64_t m;
    if (v != v) { const char *s = "nan"; while (*s) bp__fmt_char(out, n, cap, *s++); return; }
    if (v < 0) { bp__fmt_char(out, n, cap, '-'); v = -v; }
    if (v > DBL_MAX) { const char *s = "inf"; while (*s) bp__fmt_char(out, n, cap, *s++); return; }
    if (v == 0) { bp__fmt_char(out, n, cap, '0'); return; }
    while (v >= 10) { v /= 10; e++; }
    while (v < 1) { v *= 10; e--; }
    m = (uint64_t)(v * 100000.0 + 0.5);            /* 6 digits: d.ddddd */
    if (m >= 1000000) { m /= 10; e++; }
    bp__fmt_char(out, n, cap, (char)('0' + (int)(m / 100000)));
    bp__fmt_char(out, n, cap, '.');
    for (i = 4; i >= 0; i--) {
        uint64_t p = 1;
        int j;
        for (j = 0; j < i; j++) p *= 10;
        bp__fmt_char(out, n, cap, (char)('0' + (int)((m / p) % 10)));
    }
    if (e) { bp__fmt_char(out, n, cap, 'e'); bp__fmt_int(out, n, cap, e); }
}

static void bp__vformat(char *out, size_t cap, const char *fmt, va_list ap)
{
    size_t n = 0;
    for (; *fmt; fmt++) {
        if (*fmt != '%') { bp__fmt_char(out, &n, cap, *fmt); continue; }
        switch (*++fmt) {
        case 's': {
            const char *s = va_arg(ap, const char *);
            if (!s) s = "(null)";
            while (*s) bp__fmt_char(out, &n, cap, *s++);
            break;
        }
        case 'd': bp__fmt_int(out, &n, cap, va_arg(ap, int)); break;
        case 'u': bp__fmt_uint(out, &n, cap, va_arg(ap, unsigned)); break;
        case 'D': bp__fmt_int(out, &n, cap, va_arg(ap, int64_t)); break;
        case 'g': bp__fmt_double(out, &n, cap, va_arg(ap, double)); break;
        case '%': bp__fmt_char(out, &n, cap, '%'); break;
        default:  fmt--; bp__fmt_char(out, &n, cap, '%'); break;
        }
        if (!*fmt) break;
    }
    out[n] = 0;
}

/* Format into a buffer (the same conversions as bp__fail). */
static void bp__format(char *out, size_t cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    bp__vformat(out, cap, fmt, ap);
    va_end(ap);
}

/* Record a failure: status, the element it concerns, and a message.  Returns
   the status so that callers can write `return bp__fail(...)`. */

static bp_status bp__fail(bp_error *err, bp_status status, bp_element element,
                          int64_t index, int64_t index2, int64_t line,
                          const char *fmt, ...)
{
    va_list ap;
    if (!err) return status;
    err->status = status;
    err->element = element;
    err->index = index;
    err->index2 = index2;
    err->line = line;
    va_start(ap, fmt);
    bp__vformat(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return status;
}

static bp_status bp__ok(bp_error *err)
{
    if (err) {
        memset(err, 0, sizeof *err);
        err->index = err->index2 = -1;
        strcpy(err->message, "ok");
    }
    return BP_OK;
}

static bp_status bp__oom(bp_error *err, const char *what)
{
    return bp__fail(err, BP_ERR_OUT_OF_MEMORY, BP_ELEMENT_NONE, -1, -1, 0,
                    "out of memory while %s", what);
}

BPDEF const char *bp_status_string(bp_status s)
{
    static const char *const names[] = {
#define BP__STR(name, text) text,
        BP_STATUS_LIST(BP__STR)
#undef BP__STR
    };
    if ((int)s < 0 || (int)s >= (int)BP_STATUS_COUNT) return "unknown status";
    return names[s];
}

BPDEF const char *bp_energy_name(bp_energy e)
{
    static const char *const names[] = { "symmetric Dirichlet", "conformal", "MIPS",
                                         "isometric", "maximal isometric" };
    if ((int)e < 0 || (int)e >= (int)BP_ENERGY_COUNT) return "unknown energy";
    return names[e];
}

BPDEF const char *bp_stop_string(bp_stop s)
{
    static const char *const names[] = { "none", "converged", "max_iterations",
                                         "max_seconds", "cancelled", "no_progress" };
    if ((int)s < 0 || (int)s > (int)BP_STOP_NO_PROGRESS) return "unknown";
    return names[s];
}


/* >>progress ===============================================================

   Whole-run progress and cancel.  Every stage reports through bp__report
   (stage, fraction of the stage, chart), which calls opt->run_progress and
   returns nonzero when the caller wants to stop.  A stage that is told to
   stop leaves what it has made valid and returns BP_ERR_CANCELLED:

     read       nothing allocated, *mesh zeroed;
     visibility nothing computed; inside bp_parameterize it comes before
                the charts (it guides the seams), so the charts stage sees
                the cancel and the atlas is zeroed;
     charts     the atlas zeroed (bp_atlas_build's failure rule);
     start      a chart not started gets no map and is reported failed
                (chart.error BP_ERR_CANCELLED); a chart whose start map is
                done keeps it (it passed the exact check, >>tutte);
     optimize   the chart keeps its last accepted iterate, exactly valid
                (>>lbfgs);
     pack       packing is not interrupted -- the charts form a valid atlas
                only once placed -- and the cancel takes effect after it;
     write      the partial file is removed.

   bp_parameterize runs the stages with one flag for the run: the options
   it hands down carry bp__run_forward in place of the caller's callback,
   which calls the caller until it first answers nonzero, then raises the
   flag and answers nonzero to every later report without calling the
   caller again.  Every chart, on whatever thread, reads the flag at its
   next iteration (and before its start map), so one cancel stops them
   all.  The flag and the count of finished triangles are touched with
   atomic operations (GCC / Clang builtins; elsewhere a volatile int, which
   is enough on the platforms such compilers target for a one-way flag but
   is not a C99 guarantee), so the threads that race on them do not make a
   data race.

   The per-iteration `progress` of 0.1 is unchanged: a chart's optimization
   sees bp__iter_forward in its place, which calls the caller's progress
   first (its nonzero answer stops that one chart, as before) and then
   reports BP_STAGE_OPTIMIZE. */

#if defined(__GNUC__) || defined(__clang__)
#define BP__FLAG_LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define BP__FLAG_RAISE(p) __atomic_store_n((p), 1, __ATOMIC_RELEASE)
#define BP__COUNT_ADD(p, v) ((void)__atomic_fetch_add((p), (v), __ATOMIC_RELAXED))
#define BP__COUNT_LOAD(p) __atomic_load_n((p), __ATOMIC_RELAXED)
#else
#define BP__FLAG_LOAD(p) (*(volatile int *)(p))
#define BP__FLAG_RAISE(p) ((void)(*(volatile int *)(p) = 1))
#define BP__COUNT_ADD(p, v) ((void)(*(volatile uint64_t *)(p) += (v)))
#define BP__COUNT_LOAD(p) (*(volatile uint64_t *)(p))
#endif

BPDEF const char *bp_stage_name(bp_stage s)
{
    static const char *const names[] = { "read", "charts", "start", "visibility", "optimize", "pack", "write" };
    if ((int)s < 0 || (int)s >= (int)BP_STAGE_COUNT) return "unknown";
    return names[s];
}

static int bp__report(const bp_options *opt, bp_stage stage, double fraction, uint32_t chart)
{
    return opt && opt->run_progress && opt->run_progress(opt->run_progress_user, stage, fraction, chart) != 0;
}

/* One run of bp_parameterize: the caller's callback, the flag, and the
   triangles of the charts solved so far (the fraction of start and
   optimize, which interleave when charts run in parallel). */
typedef struct bp__run {
    bp_run_progress_fn fn;
    void    *user;
    int      cancelled;
    uint64_t done, total;
} bp__run;

static int bp__run_forward(void *user, bp_stage stage, double fraction, uint32_t chart)
{
    bp__run *R = (bp__run *)user;
    if (BP__FLAG_LOAD(&R->cancelled)) return 1;
    if ((stage == BP_STAGE_START || stage == BP_STAGE_OPTIMIZE) && R->total)
        fraction = (double)BP__COUNT_LOAD(&R->done) / (double)R->total;
    if (R->fn(R->user, stage, fraction, chart)) { BP__FLAG_RAISE(&R->cancelled); return 1; }
    return 0;
}

/* The run behind opt, if opt came from bp_parameterize with a callback. */
static bp__run *bp__run_of(const bp_options *opt)
{
    return opt && opt->run_progress == bp__run_forward ? (bp__run *)opt->run_progress_user : NULL;
}

/* The per-iteration link: the caller's progress, then the run's report.
   The chart's own fraction is its iteration over max_iterations (an upper
   bound on the work left; inside bp_parameterize the run's fraction of
   triangles replaces it). */
typedef struct bp__iter_link {
    bp_progress_fn fn;
    void *user;
    const bp_options *opt;
    int max_iterations;
} bp__iter_link;

static int bp__iter_forward(void *user, uint32_t chart, int iteration, double mean_energy, double step)
{
    const bp__iter_link *L = (const bp__iter_link *)user;
    if (L->fn && L->fn(L->user, chart, iteration, mean_energy, step)) return 1;
    return bp__report(L->opt, BP_STAGE_OPTIMIZE, (double)iteration / L->max_iterations, chart);
}

/* opt with bp__iter_forward as its per-iteration progress (in *copy), or
   opt itself when there is no run callback. */
static const bp_options *bp__with_iter_link(const bp_options *opt, bp_options *copy, bp__iter_link *L)
{
    if (!opt || !opt->run_progress) return opt;
    *copy = *opt;
    L->fn = opt->progress;
    L->user = opt->progress_user;
    L->opt = opt;
    L->max_iterations = opt->max_iterations > 0 ? opt->max_iterations : 10000;
    copy->progress = bp__iter_forward;
    copy->progress_user = L;
    return copy;
}

/* Growing bp_options (see bp_options_init in >>api).  The caller's struct
   is copied up to its struct_size and the rest zeroed, so the library
   never reads a field the caller's header did not have.  0 is the 0.2.0
   size: today sizeof(bp_options); when a later version appends fields,
   BP__OPTIONS_SIZE_0_2 keeps the 0.2.0 value as a number. */
#define BP__OPTIONS_SIZE_0_2 sizeof(bp_options)
#define BP__OPTIONS_SIZE_MIN (offsetof(bp_options, struct_size) + sizeof(size_t))

BPDEF void bp_options_init(bp_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->struct_size = sizeof *opt;
}

/* The caller's options as this version's struct in *out (NULL stays NULL).
   *st: BP_ERR_INVALID_ARGUMENT for a size below 0.2.0's, or a field beyond
   this version's struct that is set. */
static const bp_options *bp__opts(const bp_options *in, bp_options *out, bp_error *err, bp_status *st)
{
    size_t n, i;
    *st = BP_OK;
    if (!in) return NULL;
    n = in->struct_size ? in->struct_size : BP__OPTIONS_SIZE_0_2;
    if (n < BP__OPTIONS_SIZE_MIN) {
        *st = bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                       "bp_options.struct_size is %D, less than any version's (%D): use bp_options_init",
                       (int64_t)n, (int64_t)BP__OPTIONS_SIZE_MIN);
        return NULL;
    }
    for (i = sizeof *out; i < n; i++)
        if (((const unsigned char *)in)[i] != 0) {
            *st = bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                           "bp_options: byte %D is set, in a field this version (" BP_VERSION_STRING
                           ", %D bytes) does not know", (int64_t)i, (int64_t)sizeof *out);
            return NULL;
        }
    memset(out, 0, sizeof *out);
    memcpy(out, in, n < sizeof *out ? n : sizeof *out);
    out->struct_size = sizeof *out;
    return out;
}

/* >>threads ================================================================

   Sec 3.5 parallelizes the energy, the barrier and the step bound.  Here
   every heavy loop is cut into tasks whose boundaries depend only on the
   number of items, never on the number of threads, and each task writes its
   own slot (a partial sum, a minimum, a list of gradient records); the
   slots are combined in task order.  The result is therefore bit-identical
   for 1, 2, ... threads, and the serial path is simply the same tasks run
   one after the other.

   Who runs the tasks: a parallel_for supplied in the options (your job
   system), or, with BP_USE_PTHREADS, a small pool (one per bp_parameterize
   call, or per bp_chart_init / bp_chart_optimize of a large chart called
   alone), or a plain loop; small charts and small loops always run as a
   plain loop (below).  If a thread cannot be created the pool runs with
   the threads it has (possibly none besides the caller); chart->threads
   says how many the chart's loops could use. */

typedef struct bp__par {
    bp_parallel_for_fn run;
    void *user;
    int   threads;
} bp__par;

static void bp__serial_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    uint32_t i;
    (void)user;
    for (i = 0; i < count; i++) fn(task, i);
}

/* Small work runs serially.  A parallel loop costs a join (2 us on an idle
   pool, a wake-up of tens of microseconds when a thread slept, a
   scheduler time slice when the other core is taken by another process),
   so it pays only when its tasks are much longer than that.  Two
   thresholds, measured on the 2-core test machine (docs/performance.md):

   - a chart below BP__PAR_MIN_TRIANGLES triangles is solved with serial
     loops (its whole iteration takes less than a millisecond, of which
     dozens of joins would take a good part), and bp_chart_optimize /
     bp_chart_init called alone start no pool for it;
   - a loop over fewer than BP__PAR_MIN_ITEMS cheap items (boundary
     vertices and edges) runs serially inside a large chart.

   Loops over triangles and vertices need no threshold of their own: their
   chunks hold up to 2048 items, so a small loop is one task, run by the
   caller.  The tasks are the same whoever runs them, so the thresholds
   change no result (tests/test_threads.c sets both to 1 to send every loop
   of its small meshes through the pool). */
#ifndef BP__PAR_MIN_TRIANGLES
#define BP__PAR_MIN_TRIANGLES 8192u
#endif
#ifndef BP__PAR_MIN_ITEMS
#define BP__PAR_MIN_ITEMS     1024u
#endif

/* Work is split in chunks of items (see above): at most BP__*_CHUNK
   items each, all of nearly the same size (chunk c of nc holds items
   n c / nc up to n (c + 1) / nc), and, when there is more than one, a
   multiple of four of them.  Both depend on n alone.  Fixed-size chunks
   left a short one at the end: camelhead's 22704 triangles made 11 full
   chunks and one of 176, so of two threads, one had 12288 triangles to
   evaluate and the other 10416, and the first finished 9% after the
   second, in every energy evaluation.  Equal chunks in a multiple of four
   give 2 and 4 threads equal blocks. */
#define BP__TRI_CHUNK  2048u
#define BP__VERT_CHUNK 2048u
#define BP__EDGE_CHUNK 128u

static uint32_t bp__nchunks(uint32_t n, uint32_t size)
{
    uint32_t nc = n / size + (n % size != 0);
    if (nc > 1) nc = (nc + 3u) & ~3u;
    return nc < n ? nc : n;
}

/* The first item of chunk c of nc over n items (c = nc: n). */
static uint32_t bp__chunk_at(uint32_t n, uint32_t nc, uint32_t c)
{
    return (uint32_t)((uint64_t)n * c / nc);
}

static void bp__par_run(const bp__par *par, bp_task_fn fn, void *task, uint32_t count, uint32_t items)
{
    if (items < BP__PAR_MIN_ITEMS) bp__serial_for(NULL, fn, task, count);
    else par->run(par->user, fn, task, count);
}

/* Two independent loops as one: tasks [0, a.count) are a's, the rest b's.
   A loop that is one long task (the dissection's root split) leaves the
   other threads idle; run beside a loop of many short tasks that does
   not depend on it (the conformal start's matrix), the threads share
   both: the caller takes task 0 first (the pool hands the caller the
   first block) and the others take b's tasks.  Each loop's tasks do what
   they would alone: the same bits. */
typedef struct bp__loop {
    bp_task_fn fn;
    void *task;
    uint32_t count;
} bp__loop;

typedef struct bp__two_loops { bp__loop a, b; } bp__two_loops;

static void bp__two_loops_run(void *task, uint32_t i)
{
    const bp__two_loops *L = (const bp__two_loops *)task;
    if (i < L->a.count) L->a.fn(L->a.task, i);
    else L->b.fn(L->b.task, i - L->a.count);
}

/* a's loop, and b's (when not NULL) in the same parallel loop. */
static void bp__par_run_with(const bp__par *par, bp_task_fn fn, void *task, uint32_t count, uint32_t items,
                             const bp__loop *b)
{
    bp__two_loops L;
    if (!b || !b->count) { bp__par_run(par, fn, task, count, items); return; }
    L.a.fn = fn; L.a.task = task; L.a.count = count;
    L.b = *b;
    bp__par_run(par, bp__two_loops_run, &L, count + b->count, items);
}

#ifdef BP_USE_PTHREADS
#include <pthread.h>
#include <unistd.h>

#define BP__LINE 8                      /* uint64_t per cache line (64 bytes) */

typedef struct bp__pool bp__pool;
typedef struct bp__worker { bp__pool *P; int id; } bp__worker;

struct bp__pool {
    pthread_t      *th;
    bp__worker     *who;            /* each worker's pool and number (1..)   */
    int             nth;            /* worker threads created                */
    pthread_mutex_t mu;
    pthread_cond_t  wake, done;
    uint32_t        gen;            /* job number (written under mu)         */
    int             quit;
    bp_task_fn      fn;             /* the job: fn(task, i), i < count       */
    void           *task;           /*   (written and read under mu)         */
    uint32_t        count;
    uint32_t        finished;       /* tasks of the job finished             */
    uint64_t       *claim;          /* per block, a cache line apart:
                                       gen << 32 | its next unclaimed task   */
    uint32_t        skip;           /* loops to run on the caller alone      */
    uint32_t        backoff;        /* the next skip (bp__pool_for)          */
    uint32_t        wjobs;          /* parallel loops in the current window  */
    uint32_t        spin;           /* ns a waiting thread polls (bp__pool_poll) */
    int             looked;         /* the first window's early look is done */
    double          wwall, wcpu;    /* the window's start: wall, process CPU */
};

/* Waiting.  Waking a sleeping thread costs tens of microseconds, longer
   than many of the solver's tasks (a vector chunk takes a few), and an
   iteration has dozens of parallel loops, so a thread that waits (a worker
   for the next job, the caller for the last task of one) first polls for a
   short while.  Short is the point: an earlier version polled up to 200000
   iterations (about a millisecond), and on a machine whose cores were all
   busy with other processes a polling thread took the core from the very
   thread it waited for: the default was 5 to 200 times slower than
   --threads 1 (issue 13).  Now a thread polls at most BP__SPIN_NS
   nanoseconds, with the processor's pause hint between reads, then sleeps
   on a condition variable.  The bound is on the clock, not on a count of
   iterations, whose length varies tenfold between processors.  Without
   GCC/Clang atomics a thread sleeps at once and tasks are claimed under
   the mutex.

   How long is short depends on the machine.  Counted on the 2-core test
   machine (a virtual machine, where a wake takes 55 us on average), face's
   two-thread run posts 599 loops; with a 20 us poll the worker was asleep
   at 310 of them and the caller slept 100 times waiting for the worker's
   last task: some 17 ms of a 0.37 s run with one thread working or none.
   A 100 us poll (BP__SPIN_LONG_NS) cut that to 99 and 26 sleeps and the
   run by 10 ms (the median of 25 paired runs).  But a long poll is exactly
   what hurt on the crowded machine of issue 13, so the pool polls long
   only while it gets the cores it asked for: it starts short, looks
   early in its first measuring window (after BP__SPIN_WINDOW_JOBS loops
   and BP__SPIN_WINDOW_S seconds; bp__pool_window, below), then at the end
   of each window, and polls long when the threads used at least
   BP__SPIN_LONG_CORES of a core each (polling included: a thread the
   system does not run does not poll), short otherwise.  With the other
   cores taken the process gets about one core between its threads, below
   that bound.  (Starting long instead cost bimba 7% more CPU time on the
   crowded machine of bench/threads.py: every pool's first window polled
   long; and an early look in every window let a few lucky milliseconds
   set the long poll again for most of each window.)  The early look only
   sets the poll; the backoff waits for the whole window, as before. */
#ifndef BP__SPIN_LONG_NS
#define BP__SPIN_LONG_NS 100000
#endif
#ifndef BP__SPIN_LONG_CORES
#define BP__SPIN_LONG_CORES 0.75
#endif
#define BP__SPIN_WINDOW_JOBS 32u
#define BP__SPIN_WINDOW_S    0.002
#if defined(__GNUC__) || defined(__clang__)
#define BP__SPIN_NS 20000
#define BP__LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define BP__STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)
#define BP__ATOMICS 1
#if defined(__x86_64__) || defined(__i386__)
#define BP__PAUSE() __builtin_ia32_pause()
#elif defined(__aarch64__)
#define BP__PAUSE() __asm__ __volatile__("yield" ::: "memory")
#else
#define BP__PAUSE() ((void)0)
#endif
#else
#define BP__SPIN_NS 0
#define BP__LOAD(p) (*(p))
#define BP__STORE(p, v) (*(p) = (v))
#define BP__ATOMICS 0
#endif

static double bp__seconds(void);

/* Poll until *w differs from `old` (is_ne) or equals it (!is_ne), or
   P's spin time is over; returns whether the condition was met. */
static int bp__pool_poll(bp__pool *P, const uint32_t *w, uint32_t old, int is_ne)
{
#if BP__ATOMICS
    double until = 0;
    int k;
    for (k = 0;; k++) {
        if ((BP__LOAD(w) != old) == is_ne || BP__LOAD(&P->quit)) return 1;
        if ((k & 31) == 0) {                    /* the clock every 32 polls */
            double now = bp__seconds();
            if (k == 0) until = now + 1e-9 * BP__LOAD(&P->spin);
            else if (now >= until) return 0;
        }
        BP__PAUSE();
    }
#else
    (void)P; (void)w; (void)old; (void)is_ne;
    return 0;
#endif
}

/* Who waits for whom.  A job's tasks are claimed one at a time (below),
   and the caller waits until every task is *finished*, counted in
   P->finished, not until every worker has looked at the job.  A worker
   that the system has not scheduled yet (the other core is busy with
   another process) therefore costs nothing: the caller claims and runs its
   tasks itself, and when the worker wakes it finds nothing left.  An
   earlier version counted workers instead, so every loop waited for every worker to be
   scheduled: with a competing process, a scheduler time slice (a few
   milliseconds) per loop, dozens of loops per iteration.  The caller now
   waits only for a task that a worker has claimed and is still running.

   A worker that wakes late must not take a task of a later job for the
   job it read.  So each block's claim word carries the job number in its
   high half, a task is claimed by a compare-and-swap of the whole word,
   and a worker whose job number no longer matches stops; it read its job
   (fn, task, count) under the mutex, all of one job.

   Which thread runs which task changes no result, but it decides where the
   data is.  The solver's loops touch the same data in the same task
   numbers loop after loop (chunk c of every vector, subtree k of both
   solves), and a task's data is fastest where it ran last: in that core's
   caches, not the other's.  So the tasks are cut into one block per
   thread, in order, and thread t takes the tasks of block t first; only
   then does it help with the blocks of the others (from their next
   unclaimed task).  On the 2-core test machine this took camelhead's
   2-thread speed-up from 1.47 to 1.67 (the preconditioner solve alone
   from 1.37 to 1.71), against one shared counter. */
static int bp__pool_claim(bp__pool *P, int u, uint32_t gen, uint32_t end, uint32_t *i)
{
    uint64_t *c = &P->claim[BP__LINE * u];
#if BP__ATOMICS
    uint64_t w = __atomic_load_n(c, __ATOMIC_ACQUIRE);
    for (;;) {
        if ((uint32_t)(w >> 32) != gen || (uint32_t)w >= end) return 0;
        if (__atomic_compare_exchange_n(c, &w, w + 1, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) break;
    }
    *i = (uint32_t)w;
    return 1;
#else
    uint64_t w;
    pthread_mutex_lock(&P->mu);
    w = *c;
    if ((uint32_t)(w >> 32) == gen && (uint32_t)w < end) *c = w + 1;
    pthread_mutex_unlock(&P->mu);
    if ((uint32_t)(w >> 32) != gen || (uint32_t)w >= end) return 0;
    *i = (uint32_t)w;
    return 1;
#endif
}

/* Adds `ran` finished tasks; returns the job's new total. */
static uint32_t bp__pool_finish(bp__pool *P, uint32_t ran)
{
#if BP__ATOMICS
    return __atomic_add_fetch(&P->finished, ran, __ATOMIC_ACQ_REL);
#else
    uint32_t f;
    pthread_mutex_lock(&P->mu);
    f = P->finished += ran;
    pthread_mutex_unlock(&P->mu);
    return f;
#endif
}

/* Runs tasks of job `gen` until none is left to claim: its own block
   first, then the others'.  Returns how many it ran. */
static uint32_t bp__pool_drain(bp__pool *P, int me, uint32_t gen, bp_task_fn fn, void *task, uint32_t count)
{
    int nt = P->nth + 1, k;
    uint32_t i, ran = 0;
    for (k = 0; k < nt; k++) {
        int u = (me + k) % nt;
        uint32_t end = (uint32_t)((uint64_t)count * (uint32_t)(u + 1) / (uint32_t)nt);
        while (bp__pool_claim(P, u, gen, end, &i)) { fn(task, i); ran++; }
    }
    return ran;
}

static void *bp__pool_worker(void *arg)
{
    bp__pool *P = ((bp__worker *)arg)->P;
    int me = ((bp__worker *)arg)->id;
    uint32_t seen = 0, gen, count, ran;
    bp_task_fn fn;
    void *task;
    for (;;) {
        bp__pool_poll(P, &P->gen, seen, 1);
        pthread_mutex_lock(&P->mu);
        while (!P->quit && P->gen == seen) pthread_cond_wait(&P->wake, &P->mu);
        if (P->quit) { pthread_mutex_unlock(&P->mu); break; }
        seen = gen = P->gen;
        fn = P->fn; task = P->task; count = P->count;
        pthread_mutex_unlock(&P->mu);
        ran = bp__pool_drain(P, me, gen, fn, task, count);
        if (ran && bp__pool_finish(P, ran) == count) {   /* the last task: wake the caller */
            pthread_mutex_lock(&P->mu);
            pthread_cond_signal(&P->done);
            pthread_mutex_unlock(&P->mu);
        }
    }
    return NULL;
}

/* When the other cores are taken.  Threads help only if the system gives
   them cores.  Linux groups the threads of a session (a terminal, a job
   started by make) and shares the processors fairly between the groups
   ("autogroup"): while another session keeps both cores busy, the two
   threads of this process get one core between them, no more than one
   thread would, and then the second thread only adds its costs (the joins,
   a task stalled while the system runs another process in the middle of
   it, the second cache: camelhead takes 12% more CPU time on 2 threads).
   Measured with the load average at 6-8 from other sessions: camelhead
   8.3 s with 1 thread, 8.6-12.0 s with 2.

   So the pool measures what it gets: over a window of at least
   BP__WINDOW_JOBS parallel loops and BP__WINDOW_S seconds, the process's
   CPU time divided by the wall time, the number of cores it actually
   used.  Below BP__MIN_CORES_PER_THREAD per thread (two threads that got
   less than one core between them: then one thread would have had that
   core to itself, without the second one's costs), the next `backoff`
   loops run on the caller alone, as with threads = 1 (2048 loops, about
   50 iterations of a large chart, doubling up to 32768 while the machine
   stays crowded); then a parallel window measures again.  Camelhead's
   windows on a nearly idle machine used 1.3-2.0 cores; with the load
   average at 10 from other sessions, 0.28.  Who runs the tasks changes no
   result. */
#define BP__WINDOW_JOBS 256u
#define BP__WINDOW_S    0.05
#define BP__MIN_CORES_PER_THREAD 0.5
#define BP__BACKOFF_MIN 2048u
#define BP__BACKOFF_MAX 32768u

static double bp__cpu_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return -1;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The poll for the next loops: long when the threads used at least
   BP__SPIN_LONG_CORES of a core each over `wall` seconds (`cpu` of them). */
static void bp__pool_spin(bp__pool *P, double wall, double cpu)
{
    BP__STORE(&P->spin, cpu >= BP__SPIN_LONG_CORES * (P->nth + 1) * wall ? (uint32_t)BP__SPIN_LONG_NS
                                                                          : (uint32_t)BP__SPIN_NS);
}

/* After each parallel loop: close the window when it is long enough and
   decide whether the next loops run on the caller alone, and how long a
   waiting thread polls (the essay on waiting, above; the first window also
   looks early, for the poll only). */
static void bp__pool_window(bp__pool *P)
{
    double wall, cpu;
    if (P->wjobs++ == 0) { P->wwall = bp__seconds(); P->wcpu = bp__cpu_seconds(); return; }
    if (!P->looked && P->wjobs == BP__SPIN_WINDOW_JOBS && P->wcpu >= 0 &&   /* the early look: the poll only */
        (wall = bp__seconds() - P->wwall) >= BP__SPIN_WINDOW_S && (cpu = bp__cpu_seconds() - P->wcpu) >= 0) {
        P->looked = 1;
        bp__pool_spin(P, wall, cpu);
    }
    if (P->wjobs < BP__WINDOW_JOBS || (wall = bp__seconds() - P->wwall) < BP__WINDOW_S) return;
    cpu = bp__cpu_seconds() - P->wcpu;
    P->wjobs = 0;
    P->looked = 1;                                           /* whole windows decide from now on */
    if (P->wcpu < 0 || cpu < 0) return;                      /* no CPU clock: keep the threads */
    bp__pool_spin(P, wall, cpu);
    if (cpu < BP__MIN_CORES_PER_THREAD * (P->nth + 1) * wall) {
        P->backoff = P->backoff < BP__BACKOFF_MIN ? BP__BACKOFF_MIN
                   : P->backoff < BP__BACKOFF_MAX ? 2 * P->backoff : BP__BACKOFF_MAX;
        P->skip = P->backoff;
    } else {
        P->backoff = 0;
    }
}

static void bp__pool_for(void *user, bp_task_fn fn, void *task, uint32_t count)
{
    bp__pool *P = (bp__pool *)user;
    uint32_t gen;
    int t;
    if (count <= 1 || P->nth == 0 || P->skip > 0) {
        if (P->skip > 0) P->skip--;
        bp__serial_for(NULL, fn, task, count);
        return;
    }
    pthread_mutex_lock(&P->mu);
    gen = P->gen + 1;
    P->fn = fn;
    P->task = task;
    P->count = count;
    BP__STORE(&P->finished, 0u);
    for (t = 0; t <= P->nth; t++)              /* block t: [count t / nt, count (t+1) / nt) */
        BP__STORE(&P->claim[BP__LINE * t],
                  (uint64_t)gen << 32 | (uint32_t)((uint64_t)count * (uint32_t)t / (uint32_t)(P->nth + 1)));
    BP__STORE(&P->gen, gen);
    pthread_cond_broadcast(&P->wake);
    pthread_mutex_unlock(&P->mu);
    if (bp__pool_finish(P, bp__pool_drain(P, 0, gen, fn, task, count)) != count &&   /* the caller works too */
        !bp__pool_poll(P, &P->finished, count, 0)) {
        pthread_mutex_lock(&P->mu);
        while (BP__LOAD(&P->finished) != count) pthread_cond_wait(&P->done, &P->mu);
        pthread_mutex_unlock(&P->mu);
    }
    bp__pool_window(P);
}

/* A pool of `threads` (0: all cores) including the caller. */
static bp__pool *bp__pool_start(const bp_allocator *a, int threads)
{
    bp__pool *P;
    int i, mu = 0, wake = 0, done = 0;
    if (threads <= 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n > 0 ? (int)(n < 256 ? n : 256) : 1;
    }
    if (threads <= 1) return NULL;
    P = (bp__pool *)bp__calloc_array(a, 1, sizeof *P);
    if (!P) return NULL;
    P->spin = BP__SPIN_NS;                     /* short until a window says otherwise */
    P->th = (pthread_t *)bp__alloc_array(a, (size_t)threads - 1, sizeof(pthread_t));
    P->who = (bp__worker *)bp__alloc_array(a, (size_t)threads - 1, sizeof(bp__worker));
    P->claim = (uint64_t *)bp__calloc_array(a, (size_t)threads * BP__LINE, sizeof(uint64_t));
    if (P->th && P->who && P->claim) mu = pthread_mutex_init(&P->mu, NULL) == 0;
    if (mu) wake = pthread_cond_init(&P->wake, NULL) == 0;
    if (wake) done = pthread_cond_init(&P->done, NULL) == 0;
    if (!done) {
        if (wake) pthread_cond_destroy(&P->wake);
        if (mu) pthread_mutex_destroy(&P->mu);
        bp__free(a, P->th); bp__free(a, P->who); bp__free(a, P->claim); bp__free(a, P);
        return NULL;
    }
    for (i = 0; i < threads - 1; i++) {
        P->who[i].P = P;
        P->who[i].id = i + 1;                   /* the caller is thread 0 */
        if (pthread_create(&P->th[i], NULL, bp__pool_worker, &P->who[i]) != 0) break;  /* run with what we have */
        P->nth++;
    }
    return P;
}

static void bp__pool_stop(const bp_allocator *a, bp__pool *P)
{
    int i;
    if (!P) return;
    pthread_mutex_lock(&P->mu);
    BP__STORE(&P->quit, 1);
    pthread_cond_broadcast(&P->wake);
    pthread_mutex_unlock(&P->mu);
    for (i = 0; i < P->nth; i++) pthread_join(P->th[i], NULL);
    pthread_cond_destroy(&P->done);
    pthread_cond_destroy(&P->wake);
    pthread_mutex_destroy(&P->mu);
    bp__free(a, P->th);
    bp__free(a, P->who);
    bp__free(a, P->claim);
    bp__free(a, P);
}
#endif /* BP_USE_PTHREADS */

static bp__par bp__par_serial(void)
{
    bp__par par;
    par.run = bp__serial_for;
    par.user = NULL;
    par.threads = 1;
    return par;
}

/* Choose how loops run for a solve; *pool receives a pool to stop later. */
static bp__par bp__par_begin(const bp_allocator *a, const bp_options *opt, void **pool)
{
    bp__par par = bp__par_serial();
    *pool = NULL;
    (void)a;
    if (opt && opt->parallel_for) {
        par.run = opt->parallel_for;
        par.user = opt->parallel_user;
        par.threads = 0;
        return par;
    }
#ifdef BP_USE_PTHREADS
    if (!opt || opt->threads != 1) {
        bp__pool *P = bp__pool_start(a, opt ? opt->threads : 0);
        if (P) {
            *pool = P;
            par.run = bp__pool_for;
            par.user = P;
            par.threads = P->nth + 1;
        }
    }
#endif
    return par;
}

/* Seconds for time limits and reports: wall time from the monotonic clock
   when the pool is compiled in (POSIX is there anyway), otherwise clock(),
   which for a single compute-bound thread is the same. */
static double bp__seconds(void)
{
#ifdef BP_USE_PTHREADS
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0) return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return (double)clock() / CLOCKS_PER_SEC;
}

static void bp__par_end(const bp_allocator *a, void *pool)
{
#ifdef BP_USE_PTHREADS
    bp__pool_stop(a, (bp__pool *)pool);
#else
    (void)a; (void)pool;
#endif
}

/* >>predicates =============================================================

   Every validity decision in bijparam -- is this triangle flipped, do these
   two boundary edges touch -- is made exactly.  A UV triangle (a, b, c) is
   valid when

       orient(a, b, c) = (ax - cx)(by - cy) - (ay - cy)(bx - cx)  >  0.

   Evaluated in floating point this can get the sign wrong when the three
   points are nearly collinear, which is exactly the situation a barrier
   method drives the boundary toward.  We follow Shewchuk's adaptive scheme
   ("Adaptive precision floating-point arithmetic and fast robust geometric
   predicates", 1997) in a simplified two-stage form:

   1. Filter.  The rounded determinant `det` differs from the true one by at
      most  (3 + 16 eps) eps (|detleft| + |detright|)  with eps = 2^-53.  If
      |det| exceeds that bound its sign is right.
   2. Exact.  Otherwise expand the determinant into six products,
          ax by - ax cy - cx by - ay bx + ay cx + cy bx,
      turn each product into an exact sum of two doubles (x = fl(p*q) and the
      rounding error fma(p, q, -x), exact by definition of fma), and add the
      twelve terms into a nonoverlapping expansion with Grow-Expansion.  The
      sign of a nonoverlapping expansion is the sign of its largest (last
      nonzero) component.

   The range on which this is exact.  Both stages are exact (the filter's
   bound holds, every fma error term is representable) as long as no
   product overflows and no rounding error underflows.  A sufficient
   condition on the input: every nonzero coordinate has a magnitude in
   [2^-485, 2^510).  Above: |coordinate differences| < 2^511, so every
   product is below 2^1022 and the twelve-term sum below 2^1024.  Below:
   a double of magnitude >= 2^-485 is a multiple of u = 2^-537, so every
   coordinate, every (rounded) difference and every product is a multiple
   of u^2 = 2^-1074, the smallest subnormal: results in the subnormal range
   are then exact, and rounding errors of the products are representable.
   bp_check scales maps outside the range by a power of two (exact), the
   line search treats a trial map outside it as invalid.

   The arithmetic must be IEEE double as written: each operation rounded
   once to double (no x87 extended intermediates, FLT_EVAL_METHOD == 0), no
   reassociation or "x - x == 0" shortcuts (-ffast-math breaks TwoSum and
   the NaN tests), and a correctly rounded fma (C99 requires one; without
   the instruction the C library emulates it).  A compiler that says
   otherwise is refused below.  FLT_EVAL_METHOD == -1 ("indeterminable") is
   refused too, since nothing then promises double rounding; define
   BP_TRUST_FLT_EVAL_METHOD if you know that your target rounds each double
   operation to double anyway. */

#if defined(__FAST_MATH__)
#error "bijparam.h: compiled with -ffast-math (__FAST_MATH__): the exact predicates need strict IEEE double arithmetic (no reassociation, NaN and Inf respected); compile bijparam without -ffast-math"
#endif
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0 && !defined(BP_TRUST_FLT_EVAL_METHOD)
#error "bijparam.h: FLT_EVAL_METHOD != 0: double expressions are evaluated in a wider or unknown precision, which breaks the exact predicates (they need each operation rounded once to double, e.g. SSE2 -mfpmath=sse rather than x87)"
#endif

/* x + y = a + b exactly (Knuth's TwoSum; no branch, any magnitudes). */
static double bp__two_sum(double a, double b, double *y)
{
    double x = a + b, bv = x - a, av = x - bv;
    *y = (a - av) + (b - bv);
    return x;
}

/* Add `b` to the nonoverlapping expansion e[0..n) (increasing magnitude),
   dropping zero components; returns the new length. */
static int bp__grow_expansion(double *e, int n, double b)
{
    double q = b, h;
    int i, m = 0;
    for (i = 0; i < n; i++) {
        q = bp__two_sum(q, e[i], &h);
        if (h != 0) e[m++] = h;
    }
    if (q != 0 || m == 0) e[m++] = q;
    return m;
}

static int bp__orient2d_exact(const double *a, const double *b, const double *c)
{
    const double p[6] = { a[0], -a[0], -c[0], -a[1], a[1], c[1] };
    const double q[6] = { b[1], c[1], b[1], b[0], c[0], b[0] };
    double e[16];
    int n = 0, i;
    for (i = 0; i < 6; i++) {
        double x = p[i] * q[i];
        double err = fma(p[i], q[i], -x);
        n = bp__grow_expansion(e, n, err);
        n = bp__grow_expansion(e, n, x);
    }
    return (e[n - 1] > 0) - (e[n - 1] < 0);
}

BPDEF int bp_orient2d(const double a[2], const double b[2], const double c[2])
{
    const double errbound = (3.0 + 16.0 * DBL_EPSILON / 2) * (DBL_EPSILON / 2);
    double detleft = (a[0] - c[0]) * (b[1] - c[1]);
    double detright = (a[1] - c[1]) * (b[0] - c[0]);
    double det = detleft - detright;
    double detsum = fabs(detleft) + fabs(detright);
    if (fabs(det) > errbound * detsum) return (det > 0) - (det < 0);
    return bp__orient2d_exact(a, b, c);
}

/* Is p inside the closed axis box of segment [a, b]?  (exact comparisons) */
static int bp__in_box(const double *a, const double *b, const double *p)
{
    return (p[0] >= (a[0] < b[0] ? a[0] : b[0])) && (p[0] <= (a[0] > b[0] ? a[0] : b[0])) &&
           (p[1] >= (a[1] < b[1] ? a[1] : b[1])) && (p[1] <= (a[1] > b[1] ? a[1] : b[1]));
}

/* Closed segments [a,b] and [c,d] share a point iff c, d are not strictly on
   one side of line ab and a, b are not strictly on one side of line cd; when
   all four orientations vanish the segments are collinear and they meet iff
   one endpoint lies in the other's box.  (A degenerate segment a == b is a
   point and is handled by the same rules.) */
BPDEF int bp_segments_intersect(const double a[2], const double b[2],
                                const double c[2], const double d[2])
{
    int o1 = bp_orient2d(a, b, c), o2 = bp_orient2d(a, b, d);
    int o3, o4;
    if (o1 * o2 > 0) return 0;
    o3 = bp_orient2d(c, d, a);
    o4 = bp_orient2d(c, d, b);
    if (o3 * o4 > 0) return 0;
    if (o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0)
        return bp__in_box(a, b, c) || bp__in_box(a, b, d) ||
               bp__in_box(c, d, a) || bp__in_box(c, d, b);
    return 1;
}

/* >>io =====================================================================

   OBJ, OFF and PLY parsing works on data in memory (bp_parse_obj,
   bp_parse_off, bp_parse_ply), so the same code serves files and fuzzers.
   The OBJ and OFF parsers are strict where a silent guess would corrupt
   the mesh (bad numbers, index 0, indices out of range, non-finite
   coordinates, faces with fewer than three corners) and lenient where the
   format is (unknown statements, comments, CRLF, tabs, `vn`, `o`, `g`,
   `s`, `usemtl`).  Every error names its 1-based line (PLY: below).  On
   failure nothing stays allocated and *mesh is zeroed.

   Seams come from `vt`: a corner written `v/vt` carries uv index vt-1.  In
   a file where only some faces carry `vt`, a corner without one gets the
   synthetic uv index (number of vt) + v, so those faces are glued to each
   other along shared vertices and cut from the faces that have `vt`. */

typedef struct bp__parser {
    const char *p, *end;       /* cursor in the text                        */
    int64_t     line;          /* 1-based line of the cursor                */
    const bp_allocator *a;
    bp_error   *err;
    const bp_options *opt;     /* run_progress while reading, or NULL       */
    const char *begin;         /* start of the text (the fraction parsed)   */
    int         cancelled;     /* the callback said stop: p was set to end  */
} bp__parser;

/* Progress while parsing (>>progress): every 16384 lines the share of the
   bytes parsed, the second half of BP_STAGE_READ (loading is the first).
   A cancel moves the cursor to the end, so every parser loop ends; the
   caller then discards what was parsed. */
static void bp__parse_tick(bp__parser *ps)
{
    double f = 0.5 + 0.5 * (double)(ps->p - ps->begin) / (double)(ps->end - ps->begin);
    if (bp__report(ps->opt, BP_STAGE_READ, f, BP_NO_CHART)) {
        ps->cancelled = 1;
        ps->p = ps->end;
    }
}

static int bp__is_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
static int bp__is_eol(char c) { return c == '\n' || c == '\r'; }

static void bp__skip_space(bp__parser *ps)
{
    while (ps->p < ps->end && bp__is_space(*ps->p)) ps->p++;
}

/* Move to the start of the next line (handles \n, \r\n and \r). */
static void bp__next_line(bp__parser *ps)
{
    while (ps->p < ps->end && !bp__is_eol(*ps->p)) ps->p++;
    if (ps->p < ps->end && *ps->p == '\r') ps->p++;
    if (ps->p < ps->end && *ps->p == '\n') ps->p++;
    ps->line++;
    if (ps->opt && (ps->line & 16383) == 0) bp__parse_tick(ps);
}

static int bp__at_eol(bp__parser *ps)
{
    bp__skip_space(ps);
    return ps->p >= ps->end || bp__is_eol(*ps->p) || *ps->p == '#';
}

/* Length of the token at the cursor (up to whitespace, end of line, or a
   character in `stops`). */
static size_t bp__token_len(const bp__parser *ps, const char *stops)
{
    const char *q = ps->p;
    while (q < ps->end && !bp__is_space(*q) && !bp__is_eol(*q) && *q != '#' &&
           !(stops && strchr(stops, *q)))
        q++;
    return (size_t)(q - ps->p);
}

/* The plain decimals of mesh files without strtod (Clinger, "How to read
   floating point numbers accurately", PLDI 1990, the fast path).  A token
   [+-] digits [. digits] [(e|E) [+-] digits] is m x 10^q with m its
   digits as an integer; when m has at most 15 significant digits (so m <
   10^15 < 2^53 is a double exactly) and |q| <= 22 (10^|q| is a double
   exactly: 5^22 < 2^53), the value is m * 10^q or m / 10^-q, one
   operation on two exact doubles, which IEEE 754 rounds correctly -- so
   it is the double nearest to the decimal, strtod's result bit for bit
   (glibc and every conforming C library round correctly), provided each
   operation is rounded once to double: FLT_EVAL_METHOD 0, which the
   header requires (>>predicates).  Returns 0 for anything else (longer
   mantissas, larger exponents, hex, inf, nan, a stray character), which
   strtod then reads or rejects as before.  Face's 77,715 coordinates all
   take this path: about 2.5 ms of strtod on one thread. */
static int bp__decimal_fast(const char *s, size_t n, double *out)
{
    static const double p10[23] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
                                    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };
    const char *e = s + n;
    uint64_t m = 0;
    int neg = 0, digits = 0, sig = 0, q = 0, eneg = 0, ex = 0, edigits = 0;
    double x;
    if (s < e && (*s == '+' || *s == '-')) neg = *s++ == '-';
    for (; s < e && *s >= '0' && *s <= '9'; s++, digits++)
        if (m || *s != '0') { m = 10 * m + (uint64_t)(*s - '0'); sig++; }
    if (s < e && *s == '.')
        for (s++; s < e && *s >= '0' && *s <= '9'; s++, digits++, q--)
            if (m || *s != '0') { m = 10 * m + (uint64_t)(*s - '0'); sig++; }
    if (!digits || sig > 15) return 0;
    if (s < e && (*s == 'e' || *s == 'E')) {
        s++;
        if (s < e && (*s == '+' || *s == '-')) eneg = *s++ == '-';
        for (; s < e && *s >= '0' && *s <= '9' && edigits < 4; s++, edigits++) ex = 10 * ex + (*s - '0');
        if (!edigits) return 0;
        q += eneg ? -ex : ex;
    }
    if (s != e) return 0;
    if (m == 0) { *out = neg ? -0.0 : 0.0; return 1; }
    if (q < -22 || q > 22) return 0;
    x = q < 0 ? (double)m / p10[-q] : (double)m * p10[q];
    *out = neg ? -x : x;
    return 1;
}

/* A finite double: by bp__decimal_fast, else by strtod on a copy of the
   token (so strtod never reads past `end`). */
static bp_status bp__parse_double(bp__parser *ps, double *out, const char *what)
{
    char buf[80];
    char *stop;
    size_t n;
    bp__skip_space(ps);
    n = bp__token_len(ps, NULL);
    if (n == 0)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s is missing", ps->line, what);
    if (bp__decimal_fast(ps->p, n, out)) { ps->p += n; return BP_OK; }
    if (n >= sizeof buf)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s is not a number (token too long)", ps->line, what);
    memcpy(buf, ps->p, n);
    buf[n] = 0;
    *out = strtod(buf, &stop);
    if (stop != buf + n)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s '%s' is not a number", ps->line, what, buf);
    if (!(*out - *out == 0))
        return bp__fail(ps->err, BP_ERR_NONFINITE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s '%s' is not finite", ps->line, what, buf);
    ps->p += n;
    return BP_OK;
}

/* A signed decimal integer of at most 18 digits (no overflow possible). */
static bp_status bp__parse_int(bp__parser *ps, int64_t *out, const char *what)
{
    int neg = 0, digits = 0;
    int64_t v = 0;
    if (ps->p < ps->end && (*ps->p == '-' || *ps->p == '+')) neg = *ps->p++ == '-';
    while (ps->p < ps->end && *ps->p >= '0' && *ps->p <= '9') {
        if (++digits > 18)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                            "line %D: %s has too many digits", ps->line, what);
        v = v * 10 + (*ps->p++ - '0');
    }
    if (!digits)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s is not an integer", ps->line, what);
    *out = neg ? -v : v;
    return BP_OK;
}

/* Whether the cursor is at the word kw (non-empty), then past it.  The
   first letter is tested before anything else: the readers and the writer
   ask this of every line up to three times ("v", "vt", "f"). */
static int bp__keyword(bp__parser *ps, const char *kw)
{
    size_t n;
    if (ps->p >= ps->end || *ps->p != kw[0]) return 0;
    n = strlen(kw);
    if ((size_t)(ps->end - ps->p) < n || memcmp(ps->p, kw, n) != 0) return 0;
    if (ps->p + n < ps->end && !bp__is_space(ps->p[n]) && !bp__is_eol(ps->p[n])) return 0;
    ps->p += n;
    return 1;
}

BPDEF void bp_mesh_free(bp_mesh *mesh, const bp_allocator *alloc)
{
    bp_allocator a;
    if (!mesh) return;
    memset(&a, 0, sizeof a);
    if (alloc) a = *alloc;
    bp__free(&a, mesh->positions);
    bp__free(&a, mesh->triangles);
    bp__free(&a, mesh->corner_uv);
    bp__free(&a, mesh->uvs);
    bp__free(&a, mesh->triangle_line);
    bp__free(&a, mesh->triangle_face);
    memset(mesh, 0, sizeof *mesh);
}

/* Views (see bp_mesh_view in >>api): a packed double array is used in
   place; anything else is converted once, vertex by vertex, reading each
   coordinate with memcpy (a stride need not be a multiple of the scalar's
   alignment). */
BPDEF bp_status bp_mesh_from_view(bp_mesh *mesh, const bp_mesh_view *view, const bp_allocator *alloc, bp_error *err)
{
    bp_allocator a;
    size_t size, stride, i;
    double *pos;
    if (mesh) memset(mesh, 0, sizeof *mesh);
    if (!mesh || !view || !view->positions || !view->triangles || (int)view->position_type < 0 ||
        (int)view->position_type > (int)BP_SCALAR_F32)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_mesh_from_view needs a mesh, positions, triangles and a known position_type");
    size = view->position_type == BP_SCALAR_F32 ? sizeof(float) : sizeof(double);
    stride = view->position_stride ? view->position_stride : 3 * size;
    if (stride < 3 * size)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "position_stride %D is less than the %D bytes of x y z", (int64_t)stride, (int64_t)(3 * size));
    mesh->num_vertices = view->num_vertices;
    mesh->triangles = (uint32_t *)(uintptr_t)view->triangles;     /* borrowed, never written */
    mesh->num_triangles = view->num_triangles;
    mesh->num_faces = view->num_triangles;
    if (size == sizeof(double) && stride == 3 * sizeof(double)) {
        mesh->positions = (double *)(uintptr_t)view->positions;   /* borrowed, never written */
        return bp__ok(err);
    }
    memset(&a, 0, sizeof a);
    if (alloc) a = *alloc;
    pos = (double *)bp__alloc_array(&a, 3 * (size_t)view->num_vertices, sizeof(double));
    if (!pos) { memset(mesh, 0, sizeof *mesh); return bp__oom(err, "converting the positions"); }
    for (i = 0; i < view->num_vertices; i++) {
        const unsigned char *p = (const unsigned char *)view->positions + i * stride;
        int k;
        for (k = 0; k < 3; k++) {
            if (size == sizeof(float)) { float f; memcpy(&f, p + k * sizeof f, sizeof f); pos[3 * i + k] = f; }
            else memcpy(&pos[3 * i + k], p + k * sizeof(double), sizeof(double));
        }
    }
    mesh->positions = pos;
    return bp__ok(err);
}

BPDEF void bp_mesh_view_free(bp_mesh *mesh, const bp_mesh_view *view, const bp_allocator *alloc)
{
    bp_allocator a;
    if (!mesh) return;
    memset(&a, 0, sizeof a);
    if (alloc) a = *alloc;
    if (!view || (const void *)mesh->positions != view->positions) bp__free(&a, mesh->positions);
    memset(mesh, 0, sizeof *mesh);
}

/* The arrays a parser fills, turned into a bp_mesh at the end. */
typedef struct bp__mesh_builder {
    bp__vec pos, uv, tri, cuv, line, face;
    uint32_t faces;
    int any_vt, any_plain;
    int64_t nv0, nvt0;        /* v and vt before the text parsed (a chunk) */
} bp__mesh_builder;

static void bp__builder_init(bp__mesh_builder *b)
{
    memset(b, 0, sizeof *b);
    b->pos.elem = b->uv.elem = sizeof(double);
    b->tri.elem = b->cuv.elem = b->line.elem = b->face.elem = sizeof(uint32_t);
}

static void bp__builder_free(const bp_allocator *a, bp__mesh_builder *b)
{
    bp__free(a, b->pos.data); bp__free(a, b->uv.data); bp__free(a, b->tri.data);
    bp__free(a, b->cuv.data); bp__free(a, b->line.data); bp__free(a, b->face.data);
    bp__builder_init(b);
}

/* Fan-triangulate one polygon of n corners (v[i], t[i]) as (0, i, i+1):
   room for its n - 2 triangles first, then plain stores. */
static bp_status bp__builder_face(bp__parser *ps, bp__mesh_builder *b,
                                  const uint32_t *v, const uint32_t *t, size_t n)
{
    size_t i, nt = n > 2 ? n - 2 : 0;
    uint32_t line32 = ps->line > 0xffffffffLL ? 0xffffffffu : (uint32_t)ps->line;
    if (b->faces == BP__NONE)
        return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: too many faces", ps->line);
    if (!bp__vec_reserve(ps->a, &b->tri, b->tri.count + 3 * nt) ||
        (t && !bp__vec_reserve(ps->a, &b->cuv, b->cuv.count + 3 * nt)) ||
        !bp__vec_reserve(ps->a, &b->line, b->line.count + nt) || !bp__vec_reserve(ps->a, &b->face, b->face.count + nt))
        return bp__oom(ps->err, "reading faces");
    for (i = 1; i + 1 < n; i++) {
        uint32_t *tri = (uint32_t *)b->tri.data + b->tri.count;
        if (b->tri.count / 3 >= 0xfffffffeu)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                            "line %D: too many triangles", ps->line);
        tri[0] = v[0]; tri[1] = v[i]; tri[2] = v[i + 1];
        b->tri.count += 3;
        if (t) {
            uint32_t *cuv = (uint32_t *)b->cuv.data + b->cuv.count;
            cuv[0] = t[0]; cuv[1] = t[i]; cuv[2] = t[i + 1];
            b->cuv.count += 3;
        }
        ((uint32_t *)b->line.data)[b->line.count++] = line32;
        ((uint32_t *)b->face.data)[b->face.count++] = b->faces;
    }
    b->faces++;
    return BP_OK;
}

/* Move the builder's arrays into *mesh. */
static bp_status bp__builder_finish(bp__parser *ps, bp__mesh_builder *b, bp_mesh *mesh)
{
    if (b->tri.count == 0)
        return bp__fail(ps->err, BP_ERR_EMPTY, BP_ELEMENT_NONE, -1, -1, 0,
                        "the file has no faces (%u vertices, 0 triangles)",
                        (unsigned)(b->pos.count / 3));
    mesh->positions = (double *)b->pos.data;
    mesh->num_vertices = (uint32_t)(b->pos.count / 3);
    mesh->triangles = (uint32_t *)b->tri.data;
    mesh->num_triangles = (uint32_t)(b->tri.count / 3);
    mesh->corner_uv = b->cuv.count ? (uint32_t *)b->cuv.data : NULL;
    if (!b->cuv.count) bp__free(ps->a, b->cuv.data);
    mesh->uvs = b->uv.count ? (double *)b->uv.data : NULL;
    if (!b->uv.count) bp__free(ps->a, b->uv.data);
    mesh->num_uvs = (uint32_t)(b->uv.count / 2);
    mesh->triangle_line = (uint32_t *)b->line.data;
    mesh->triangle_face = (uint32_t *)b->face.data;
    mesh->num_faces = b->faces;
    bp__builder_init(b);
    return BP_OK;
}

/* One OBJ index: 1-based, 0 invalid, negative counts back from the last of
   the `count` elements read so far.  Returns the 0-based index in *out. */
static bp_status bp__obj_index(bp__parser *ps, int64_t count, const char *what, int64_t *out)
{
    bp_status st;
    int64_t i;
    if ((st = bp__parse_int(ps, &i, what)) != BP_OK) return st;
    if (i == 0)
        return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: %s 0 is invalid (OBJ indices start at 1)", ps->line, what);
    if (i < 0) {
        if (-i > count)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                            "line %D: relative %s %D points before the first element", ps->line, what, i);
        i = count + i + 1;
    }
    *out = i - 1;
    return BP_OK;
}

/* Where the parts of one corner stand in the text (the OBJ writer that
   streams the user's file copies the v and vn parts as they were written). */
typedef struct bp__corner_text {
    const char *v, *v_end;     /* the vertex index as written               */
    const char *vn, *vn_end;   /* the normal index, or vn == NULL           */
} bp__corner_text;

/* One OBJ face corner: v, v/vt, v/vt/vn or v//vn.  Negative indices count
   back from the last element read so far (nv vertices, nvt vt).  Returns
   0-based indices (vt = -1 when absent); the range check against the final
   counts happens after the whole file is read, since OBJ allows forward
   use.  The normal index is checked to be an integer and otherwise kept
   only as text (in *span, which may be NULL). */
static bp_status bp__obj_corner(bp__parser *ps, int64_t nv, int64_t nvt,
                                int64_t *v, int64_t *vt, bp__corner_text *span)
{
    bp__corner_text s;
    bp_status st;
    int64_t i;
    *vt = -1;
    s.v = ps->p;
    s.vn = s.vn_end = NULL;
    if ((st = bp__obj_index(ps, nv, "vertex index", v)) != BP_OK) return st;
    s.v_end = ps->p;
    if (ps->p < ps->end && *ps->p == '/') {
        ps->p++;
        if (ps->p < ps->end && *ps->p != '/' && (st = bp__obj_index(ps, nvt, "texture index", vt)) != BP_OK)
            return st;
        if (ps->p < ps->end && *ps->p == '/') {
            ps->p++;
            s.vn = ps->p;
            if ((st = bp__parse_int(ps, &i, "normal index")) != BP_OK) return st;
            s.vn_end = ps->p;
        }
    }
    if (!(ps->p >= ps->end || bp__is_space(*ps->p) || bp__is_eol(*ps->p) || *ps->p == '#'))
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: unexpected character '%s' in a face corner", ps->line,
                        *ps->p == '/' ? "/" : "?");
    if (span) *span = s;
    return BP_OK;
}

/* The phases of bp__parse_obj: one function per statement it reads (v, vt,
   f), then the checks that need the whole file. */
static bp_status bp__obj_vertex(bp__parser *ps, bp__mesh_builder *b)
{
    static const char *const what[3] = { "x coordinate", "y coordinate", "z coordinate" };
    double x[3];
    bp_status st;
    int k;
    for (k = 0; k < 3; k++)
        if ((st = bp__parse_double(ps, &x[k], what[k])) != BP_OK) return st;
    if (b->pos.count / 3 >= 0xfffffffeu)
        return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: too many vertices", ps->line);
    for (k = 0; k < 3; k++)
        if (!bp__vec_push(ps->a, &b->pos, &x[k])) return bp__oom(ps->err, "reading vertices");
    return BP_OK;
}

static bp_status bp__obj_texcoord(bp__parser *ps, bp__mesh_builder *b)
{
    double x[2];
    bp_status st;
    int k;
    if ((st = bp__parse_double(ps, &x[0], "u coordinate")) != BP_OK) return st;
    if (bp__at_eol(ps)) x[1] = 0;                  /* 1D texture: v = 0 */
    else if ((st = bp__parse_double(ps, &x[1], "v coordinate")) != BP_OK) return st;
    for (k = 0; k < 2; k++)
        if (!bp__vec_push(ps->a, &b->uv, &x[k])) return bp__oom(ps->err, "reading vt");
    return BP_OK;
}

/* The corners of one `f` line into fv / ft (0-based uint32 vertex and uv
   indices, ft = BP__NONE without vt), then its fan into the builder. */
static bp_status bp__obj_face(bp__parser *ps, bp__mesh_builder *b, bp__vec *fv, bp__vec *ft)
{
    int64_t nv = b->nv0 + (int64_t)(b->pos.count / 3), nvt = b->nvt0 + (int64_t)(b->uv.count / 2);
    int has_vt = -1;
    bp_status st;
    fv->count = ft->count = 0;
    while (!bp__at_eol(ps)) {
        int64_t v = 0, vt = -1;
        uint32_t v32, t32;
        if ((st = bp__obj_corner(ps, nv, nvt, &v, &vt, NULL)) != BP_OK) return st;
        if (has_vt >= 0 && has_vt != (vt >= 0))
            return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                            "line %D: some corners of this face have a texture index and some do not", ps->line);
        has_vt = vt >= 0;
        if (v >= 0xfffffffeLL || vt >= 0xfffffffeLL)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                            "line %D: index %D is out of range", ps->line, (v > vt ? v : vt) + 1);
        v32 = (uint32_t)v;
        t32 = vt >= 0 ? (uint32_t)vt : BP__NONE;
        if (!bp__vec_push(ps->a, fv, &v32) || !bp__vec_push(ps->a, ft, &t32))
            return bp__oom(ps->err, "reading faces");
    }
    if (fv->count < 3)
        return bp__fail(ps->err, BP_ERR_POLYGON, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: a face needs at least 3 corners, this one has %u", ps->line, (unsigned)fv->count);
    if (has_vt) b->any_vt = 1; else b->any_plain = 1;
    return bp__builder_face(ps, b, (uint32_t *)fv->data, (uint32_t *)ft->data, fv->count);
}

/* After the whole file: every index in range of the final counts, and the
   uv indices of corners written without vt (see the essay above). */
static bp_status bp__obj_finish_indices(bp__parser *ps, bp__mesh_builder *b)
{
    uint32_t nv = (uint32_t)(b->pos.count / 3), nvt = (uint32_t)(b->uv.count / 2);
    uint32_t *tri = (uint32_t *)b->tri.data, *cuv = (uint32_t *)b->cuv.data;
    uint32_t *line = (uint32_t *)b->line.data;
    double zero = 0;
    size_t i;
    for (i = 0; i < b->tri.count; i++) {
        if (tri[i] >= nv)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, line[i / 3], -1, line[i / 3],
                            "line %u: vertex index %u is out of range (the file has %u vertices)",
                            line[i / 3], tri[i] + 1, nv);
        if (cuv[i] != BP__NONE && cuv[i] >= nvt)
            return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, line[i / 3], -1, line[i / 3],
                            "line %u: texture index %u is out of range (the file has %u vt)",
                            line[i / 3], cuv[i] + 1, nvt);
    }
    if (!b->any_vt) {
        b->cuv.count = 0;    /* no seams at all */
        return BP_OK;
    }
    if (!b->any_plain) return BP_OK;
    if ((uint64_t)nvt + nv >= 0xfffffffeu)
        return bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_NONE, -1, -1, 0, "too many texture coordinates");
    for (i = 0; i < 2 * (size_t)nv; i++)
        if (!bp__vec_push(ps->a, &b->uv, &zero)) return bp__oom(ps->err, "reading vt");
    cuv = (uint32_t *)b->cuv.data;
    for (i = 0; i < b->tri.count; i++)
        if (cuv[i] == BP__NONE) cuv[i] = nvt + tri[i];
    return BP_OK;
}

/* The statements from the cursor to the end of the text. */
static bp_status bp__obj_lines(bp__parser *ps, bp__mesh_builder *b, bp__vec *fv, bp__vec *ft)
{
    bp_status st = BP_OK;
    while (ps->p < ps->end && st == BP_OK) {
        bp__skip_space(ps);
        if (bp__keyword(ps, "v")) st = bp__obj_vertex(ps, b);
        else if (bp__keyword(ps, "vt")) st = bp__obj_texcoord(ps, b);
        else if (bp__keyword(ps, "f")) st = bp__obj_face(ps, b, fv, ft);
        /* Anything else (vn, o, g, s, usemtl, mtllib, l, comments) is skipped. */
        if (st == BP_OK) bp__next_line(ps);
    }
    return st;
}

static bp_status bp__parse_obj(bp__parser *ps, bp_mesh *mesh)
{
    bp__mesh_builder b;
    bp__vec fv, ft;               /* corners of the current face (uint32)   */
    bp_status st;
    bp__builder_init(&b);
    memset(&fv, 0, sizeof fv); memset(&ft, 0, sizeof ft);
    fv.elem = ft.elem = sizeof(uint32_t);
    st = bp__obj_lines(ps, &b, &fv, &ft);
    bp__free(ps->a, fv.data);
    bp__free(ps->a, ft.data);
    if (st == BP_OK) st = bp__obj_finish_indices(ps, &b);
    if (st == BP_OK) st = bp__builder_finish(ps, &b, mesh);
    if (st != BP_OK) bp__builder_free(ps->a, &b);
    return st;
}

/* ---- OBJ on several threads ----------------------------------------------

   Reading a large OBJ is mostly strtod and the index parsing, line by line,
   and the lines are independent but for three running counts: a relative
   index (-1) means the last v or vt read so far, and each face goes to the
   next triangles.  So bp_read_mesh_opt, for an OBJ file of BP__READ_PAR_MIN
   bytes or more and more than one thread, reads it in two parallel passes
   over chunks of about BP__READ_CHUNK bytes cut at line starts:

     1. count, per chunk, its lines, v lines, vt lines, faces and fan
        triangles (a face's corners are its tokens: an index with its
        slashes runs up to a space, a line end or '#', as bp__obj_corner
        reads it); prefix sums give each chunk where it starts: line number,
        the v and vt before it (for relative indices), the first face and
        triangle; the arrays are allocated once, at their final sizes;
     2. parse each chunk with the serial code (bp__obj_lines), starting from
        those counts, into its own stretch of the arrays.

   Then, in file order, the first chunk that failed gives the error -- the
   error of the serial parser, since every chunk before it read exactly
   what it counted, so its line, counts and message are the serial ones --
   and the checks that need the whole file (bp__obj_finish_indices) run as
   before.  The mesh is the serial parser's, array for array.  A task never
   allocates (its allocator fails: the counts are exact, so nothing grows),
   and a chunk with a face of more than BP__READ_CORNERS corners is left to
   the caller, who parses it afterwards with room for its longest face.
   Totals near the 32-bit limits go to the serial parser, which names the
   line where they are exceeded. */
#ifndef BP__READ_PAR_MIN
#define BP__READ_PAR_MIN (1u << 20)
#endif
#ifndef BP__READ_CHUNK
#define BP__READ_CHUNK (1u << 16)
#endif
#define BP__READ_CORNERS 64u

typedef struct bp__obj_chunk {
    const char *begin, *end;
    int64_t lines, nv, nvt, faces, tris, max_corners;  /* pass 1            */
    int64_t line0, nv0, nvt0, face0, tri0;             /* before the chunk  */
    bp_status st;                                      /* pass 2            */
    int retry, any_vt, any_plain;
    bp_error err;
} bp__obj_chunk;

typedef struct bp__obj_par {
    bp__obj_chunk *ch;
    double *pos, *uv;
    uint32_t *tri, *cuv, *line, *face;
    uint32_t *corners;        /* 2 * BP__READ_CORNERS per chunk (fv, ft)    */
} bp__obj_par;

static void *bp__no_alloc(void *user, size_t n) { (void)user; (void)n; return NULL; }
static void bp__no_free(void *user, void *p) { (void)user; (void)p; }

/* Pass 1 on chunk k. */
static void bp__obj_count_run(void *task, uint32_t k)
{
    bp__obj_chunk *c = ((bp__obj_par *)task)->ch + k;
    bp__parser ps;
    memset(&ps, 0, sizeof ps);
    ps.p = c->begin;
    ps.end = c->end;
    c->lines = c->nv = c->nvt = c->faces = c->tris = c->max_corners = 0;
    while (ps.p < ps.end) {
        bp__skip_space(&ps);
        if (bp__keyword(&ps, "v")) c->nv++;
        else if (bp__keyword(&ps, "vt")) c->nvt++;
        else if (bp__keyword(&ps, "f")) {
            int64_t n = 0;
            while (!bp__at_eol(&ps)) {
                n++;
                while (ps.p < ps.end && !bp__is_space(*ps.p) && !bp__is_eol(*ps.p) && *ps.p != '#') ps.p++;
            }
            c->faces++;
            if (n > 2) c->tris += n - 2;
            if (n > c->max_corners) c->max_corners = n;
        }
        bp__next_line(&ps);
        c->lines++;
    }
}

/* Pass 2 on chunk k with corner room fv / ft: the serial statements into
   the chunk's stretch of the arrays. */
static bp_status bp__obj_chunk_parse(bp__obj_par *P, uint32_t k, bp__vec *fv, bp__vec *ft)
{
    bp__obj_chunk *c = P->ch + k;
    bp_allocator none;
    bp__parser ps;
    bp__mesh_builder b;
    none.alloc = bp__no_alloc;
    none.free = bp__no_free;
    none.user = NULL;
    memset(&ps, 0, sizeof ps);
    ps.p = ps.begin = c->begin;
    ps.end = c->end;
    ps.line = 1 + c->line0;
    ps.a = &none;
    ps.err = &c->err;
    bp__builder_init(&b);
    b.pos.data = P->pos + 3 * (size_t)c->nv0;   b.pos.cap = 3 * (size_t)c->nv;
    b.uv.data = P->uv + 2 * (size_t)c->nvt0;    b.uv.cap = 2 * (size_t)c->nvt;
    b.tri.data = P->tri + 3 * (size_t)c->tri0;  b.tri.cap = 3 * (size_t)c->tris;
    b.cuv.data = P->cuv + 3 * (size_t)c->tri0;  b.cuv.cap = 3 * (size_t)c->tris;
    b.line.data = P->line + c->tri0;            b.line.cap = (size_t)c->tris;
    b.face.data = P->face + c->tri0;            b.face.cap = (size_t)c->tris;
    b.faces = (uint32_t)c->face0;
    b.nv0 = c->nv0;
    b.nvt0 = c->nvt0;
    c->st = bp__obj_lines(&ps, &b, fv, ft);
    c->any_vt = b.any_vt;
    c->any_plain = b.any_plain;
    return c->st;
}

static void bp__obj_parse_run(void *task, uint32_t k)
{
    bp__obj_par *P = (bp__obj_par *)task;
    bp__vec fv, ft;
    if (P->ch[k].max_corners > (int64_t)BP__READ_CORNERS) { P->ch[k].retry = 1; return; }
    memset(&fv, 0, sizeof fv);
    memset(&ft, 0, sizeof ft);
    fv.elem = ft.elem = sizeof(uint32_t);
    fv.cap = ft.cap = BP__READ_CORNERS;
    fv.data = P->corners + 2 * (size_t)BP__READ_CORNERS * k;
    ft.data = P->corners + 2 * (size_t)BP__READ_CORNERS * k + BP__READ_CORNERS;
    bp__obj_chunk_parse(P, k, &fv, &ft);
}

/* Chunks of about BP__READ_CHUNK bytes, each starting at a line start (as
   bp__next_line moves: after "\n", "\r\n" or a lone "\r"); *n of them. */
static bp__obj_chunk *bp__obj_chunks(const bp__parser *ps, uint32_t *n)
{
    size_t len = (size_t)(ps->end - ps->p), want = len / BP__READ_CHUNK + 1, k = 0;
    bp__obj_chunk *ch = (bp__obj_chunk *)bp__calloc_array(ps->a, want, sizeof *ch);
    const char *at = ps->p;
    if (!ch) return NULL;
    while (at < ps->end && k < want) {
        bp__parser q = *ps;
        q.p = (size_t)(ps->end - at) > BP__READ_CHUNK && k + 1 < want ? at + BP__READ_CHUNK : ps->end;
        if (q.p < ps->end) {
            while (q.p < q.end && !bp__is_eol(*q.p)) q.p++;
            if (q.p < q.end && *q.p == '\r') q.p++;
            if (q.p < q.end && *q.p == '\n') q.p++;
        }
        ch[k].begin = at;
        ch[k].end = q.p;
        at = q.p;
        k++;
    }
    *n = (uint32_t)k;
    return ch;
}

static void bp__obj_par_free(const bp_allocator *a, bp__obj_par *P)
{
    bp__free(a, P->ch); bp__free(a, P->corners);
    bp__free(a, P->pos); bp__free(a, P->uv); bp__free(a, P->tri);
    bp__free(a, P->cuv); bp__free(a, P->line); bp__free(a, P->face);
    memset(P, 0, sizeof *P);
}

/* Pass 1, the prefix sums and the arrays.  1: ready; 0: not worth it or
   near the limits (the serial parser reads the file instead); -1: out of
   memory. */
static int bp__obj_par_prepare(bp__parser *ps, const bp__par *par, bp__obj_par *P, uint32_t *n)
{
    const bp_allocator *a = ps->a;
    int64_t line = 0, nv = 0, nvt = 0, faces = 0, tris = 0;
    uint32_t k;
    memset(P, 0, sizeof *P);
    if (!(P->ch = bp__obj_chunks(ps, n))) return -1;
    if (*n < 2) { bp__obj_par_free(a, P); return 0; }
    par->run(par->user, bp__obj_count_run, P, *n);
    for (k = 0; k < *n; k++) {
        bp__obj_chunk *c = P->ch + k;
        c->line0 = line; c->nv0 = nv; c->nvt0 = nvt; c->face0 = faces; c->tri0 = tris;
        line += c->lines; nv += c->nv; nvt += c->nvt; faces += c->faces; tris += c->tris;
    }
    if (nv >= 0xfffffffeLL || nvt >= 0xfffffffeLL || faces >= 0xfffffffeLL || tris >= 0xfffffffeLL) {
        bp__obj_par_free(a, P);
        return 0;
    }
    P->corners = (uint32_t *)bp__alloc_array(a, 2 * (size_t)BP__READ_CORNERS * *n, sizeof(uint32_t));
    P->pos = (double *)bp__alloc_array(a, 3 * (size_t)nv, sizeof(double));
    P->uv = (double *)bp__alloc_array(a, 2 * (size_t)nvt, sizeof(double));
    P->tri = (uint32_t *)bp__alloc_array(a, 3 * (size_t)tris, sizeof(uint32_t));
    P->cuv = (uint32_t *)bp__alloc_array(a, 3 * (size_t)tris, sizeof(uint32_t));
    P->line = (uint32_t *)bp__alloc_array(a, (size_t)tris, sizeof(uint32_t));
    P->face = (uint32_t *)bp__alloc_array(a, (size_t)tris, sizeof(uint32_t));
    if (!P->corners || !P->pos || !P->uv || !P->tri || !P->cuv || !P->line || !P->face) {
        bp__obj_par_free(a, P);
        return -1;
    }
    return 1;
}

/* The chunks' results in file order: a chunk left to the caller is parsed
   now; the first failure is the file's error. */
static bp_status bp__obj_par_collect(bp__parser *ps, bp__obj_par *P, uint32_t n, bp__mesh_builder *b)
{
    uint32_t k;
    bp_status st = BP_OK;
    for (k = 0; k < n && st == BP_OK; k++) {
        bp__obj_chunk *c = P->ch + k;
        if (c->retry) {
            bp__vec fv, ft;
            memset(&fv, 0, sizeof fv);
            memset(&ft, 0, sizeof ft);
            fv.elem = ft.elem = sizeof(uint32_t);
            fv.cap = ft.cap = (size_t)c->max_corners;
            fv.data = bp__alloc_array(ps->a, fv.cap, sizeof(uint32_t));
            ft.data = bp__alloc_array(ps->a, ft.cap, sizeof(uint32_t));
            if (fv.data && ft.data) bp__obj_chunk_parse(P, k, &fv, &ft);
            else c->st = bp__oom(&c->err, "reading faces");
            bp__free(ps->a, fv.data);
            bp__free(ps->a, ft.data);
        }
        if (c->st != BP_OK) {
            st = c->st;
            if (ps->err) *ps->err = c->err;
        }
        b->any_vt |= c->any_vt;
        b->any_plain |= c->any_plain;
    }
    return st;
}

/* bp__parse_obj on `par`: 1 in *done when it read the file (st is the
   result), 0 when the serial parser should. */
static bp_status bp__parse_obj_par(bp__parser *ps, bp_mesh *mesh, const bp__par *par, int *done)
{
    bp__obj_par P;
    bp__mesh_builder b;
    const bp__obj_chunk *last;
    uint32_t n = 0;
    bp_status st;
    int ready = bp__obj_par_prepare(ps, par, &P, &n);
    *done = ready != 0;
    if (ready < 0) return bp__oom(ps->err, "reading the OBJ file");
    if (!ready) return BP_OK;
    if (ps->opt && bp__report(ps->opt, BP_STAGE_READ, 0.75, BP_NO_CHART)) {
        ps->cancelled = 1;
        bp__obj_par_free(ps->a, &P);
        return BP_ERR_CANCELLED;
    }
    par->run(par->user, bp__obj_parse_run, &P, n);
    bp__builder_init(&b);
    st = bp__obj_par_collect(ps, &P, n, &b);
    last = P.ch + n - 1;
    b.pos.data = P.pos;   b.pos.count = b.pos.cap = 3 * (size_t)(last->nv0 + last->nv);
    b.uv.data = P.uv;     b.uv.count = b.uv.cap = 2 * (size_t)(last->nvt0 + last->nvt);
    b.tri.data = P.tri;   b.tri.count = b.tri.cap = 3 * (size_t)(last->tri0 + last->tris);
    b.cuv.data = P.cuv;   b.cuv.count = b.cuv.cap = b.tri.count;
    b.line.data = P.line; b.line.count = b.line.cap = b.tri.count / 3;
    b.face.data = P.face; b.face.count = b.face.cap = b.tri.count / 3;
    b.faces = (uint32_t)(last->face0 + last->faces);
    P.pos = P.uv = NULL;
    P.tri = P.cuv = P.line = P.face = NULL;       /* b owns them now */
    ps->line = 1 + last->line0 + last->lines;
    bp__obj_par_free(ps->a, &P);
    if (st == BP_OK) st = bp__obj_finish_indices(ps, &b);
    if (st == BP_OK) st = bp__builder_finish(ps, &b, mesh);
    if (st != BP_OK) bp__builder_free(ps->a, &b);
    return st;
}

/* OFF: "OFF" (optionally followed by the counts on the same line), then
   "V F E", V lines of x y z (extra values such as colours ignored), F lines
   "n i0 .. i(n-1)" with 0-based indices.  '#' starts a comment. */
static bp_status bp__off_next_content_line(bp__parser *ps)
{
    while (ps->p < ps->end && bp__at_eol(ps)) bp__next_line(ps);
    return ps->p < ps->end ? BP_OK : BP_ERR_PARSE;
}

static bp_status bp__parse_off(bp__parser *ps, bp_mesh *mesh)
{
    bp__mesh_builder b;
    bp__vec fv;
    bp_status st = BP_OK;
    int64_t nv = 0, nf = 0, ne = 0, i, j;
    bp__builder_init(&b);
    memset(&fv, 0, sizeof fv);
    fv.elem = sizeof(uint32_t);
    if (bp__off_next_content_line(ps) != BP_OK)
        return bp__fail(ps->err, BP_ERR_EMPTY, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "the file is empty");
    bp__skip_space(ps);
    if (!bp__keyword(ps, "OFF"))
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: an OFF file must start with 'OFF'", ps->line);
    if (bp__at_eol(ps) && bp__off_next_content_line(ps) != BP_OK)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: the vertex and face counts are missing", ps->line);
    bp__skip_space(ps);
    if ((st = bp__parse_int(ps, &nv, "vertex count")) != BP_OK) return st;
    bp__skip_space(ps);
    if ((st = bp__parse_int(ps, &nf, "face count")) != BP_OK) return st;
    bp__skip_space(ps);
    if (!bp__at_eol(ps) && (st = bp__parse_int(ps, &ne, "edge count")) != BP_OK) return st;
    /* Every vertex needs at least 6 bytes ("0 0 0\n") and every face 8, so a
       header that claims more than the file can hold is rejected before any
       allocation is sized by it. */
    if (nv < 0 || nf < 0 || nv > (int64_t)(ps->end - ps->p) / 6 + 1 || nf > (int64_t)(ps->end - ps->p) / 8 + 1)
        return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                        "line %D: the header claims %D vertices and %D faces, more than the file holds",
                        ps->line, nv, nf);
    bp__next_line(ps);
    if (!bp__vec_reserve(ps->a, &b.pos, (size_t)nv * 3)) return bp__oom(ps->err, "reading vertices");
    for (i = 0; i < nv && st == BP_OK; i++) {
        double x[3];
        int k;
        if (bp__off_next_content_line(ps) != BP_OK) {
            st = bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                          "line %D: the file ends after %D of %D vertices", ps->line, i, nv);
            break;
        }
        for (k = 0; k < 3 && st == BP_OK; k++)
            st = bp__parse_double(ps, &x[k], k == 0 ? "x coordinate" : k == 1 ? "y coordinate" : "z coordinate");
        for (k = 0; k < 3 && st == BP_OK; k++)
            if (!bp__vec_push(ps->a, &b.pos, &x[k])) st = bp__oom(ps->err, "reading vertices");
        bp__next_line(ps);
    }
    for (i = 0; i < nf && st == BP_OK; i++) {
        int64_t n;
        if (bp__off_next_content_line(ps) != BP_OK) {
            st = bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                          "line %D: the file ends after %D of %D faces", ps->line, i, nf);
            break;
        }
        bp__skip_space(ps);
        if ((st = bp__parse_int(ps, &n, "corner count")) != BP_OK) break;
        if (n < 3) {
            st = bp__fail(ps->err, BP_ERR_POLYGON, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                          "line %D: a face needs at least 3 corners, this one has %D", ps->line, n);
            break;
        }
        fv.count = 0;
        for (j = 0; j < n && st == BP_OK; j++) {
            int64_t v;
            uint32_t v32;
            bp__skip_space(ps);
            if ((st = bp__parse_int(ps, &v, "vertex index")) != BP_OK) break;
            if (v < 0 || v >= nv) {
                st = bp__fail(ps->err, BP_ERR_INDEX, BP_ELEMENT_LINE, ps->line, -1, ps->line,
                              "line %D: vertex index %D is out of range (the file has %D vertices)", ps->line, v, nv);
                break;
            }
            v32 = (uint32_t)v;
            if (!bp__vec_push(ps->a, &fv, &v32)) st = bp__oom(ps->err, "reading faces");
        }
        if (st == BP_OK) st = bp__builder_face(ps, &b, (uint32_t *)fv.data, NULL, fv.count);
        bp__next_line(ps);
    }
    bp__free(ps->a, fv.data);
    if (st == BP_OK) st = bp__builder_finish(ps, &b, mesh);
    if (st != BP_OK) bp__builder_free(ps->a, &b);
    return st;
}

enum { BP__FORMAT_OBJ, BP__FORMAT_OFF, BP__FORMAT_PLY };
static bp_status bp__parse_ply(bp__parser *ps, bp_mesh *mesh);

/* Parse text of a format; opt (may be NULL) gives run_progress. */
static bp_status bp__parse_text(const char *text, size_t length, bp_mesh *mesh,
                                const bp_allocator *alloc, bp_error *err, int format, const bp_options *opt)
{
    bp__parser ps;
    bp_allocator a;
    bp_status st;
    memset(&a, 0, sizeof a);
    if (alloc) a = *alloc;
    if (!mesh || (!text && length))
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "mesh and text must not be NULL");
    memset(mesh, 0, sizeof *mesh);
    ps.p = text;
    ps.end = text + length;
    ps.line = 1;
    ps.a = &a;
    ps.err = err;
    ps.opt = opt && opt->run_progress && length ? opt : NULL;
    ps.begin = text;
    ps.cancelled = 0;
    if (format == BP__FORMAT_OBJ && opt && length >= BP__READ_PAR_MIN) {   /* a large OBJ: on threads */
        void *pool = NULL;
        bp__par par = bp__par_begin(&a, opt, &pool);
        int done = 0;
        st = par.run != bp__serial_for ? bp__parse_obj_par(&ps, mesh, &par, &done) : BP_OK;
        bp__par_end(&a, pool);
        if (!done) st = bp__parse_obj(&ps, mesh);
    } else
        st = format == BP__FORMAT_OFF ? bp__parse_off(&ps, mesh)
           : format == BP__FORMAT_PLY ? bp__parse_ply(&ps, mesh) : bp__parse_obj(&ps, mesh);
    if (ps.cancelled) {                       /* whatever the parse made of it */
        bp_mesh_free(mesh, &a);
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled while reading");
    }
    if (st == BP_OK) bp__ok(err);
    return st;
}

BPDEF bp_status bp_parse_obj(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err)
{
    return bp__parse_text(text, length, mesh, alloc, err, BP__FORMAT_OBJ, NULL);
}

BPDEF bp_status bp_parse_off(const char *text, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err)
{
    return bp__parse_text(text, length, mesh, alloc, err, BP__FORMAT_OFF, NULL);
}

BPDEF bp_status bp_parse_ply(const char *data, size_t length, bp_mesh *mesh,
                             const bp_allocator *alloc, bp_error *err)
{
    return bp__parse_text(data, length, mesh, alloc, err, BP__FORMAT_PLY, NULL);
}

/* ---- PLY ----------------------------------------------------------------

   A PLY file is a text header that declares elements (name, count) and
   their properties (a scalar type, or a list: count type and item type),
   then the data: ASCII numbers, or binary values of the declared sizes in
   little- or big-endian order.  We keep the `vertex` element's x y z (and
   s t / u v / texture_u texture_v / texture_s texture_t when present: the
   input uvs, one per vertex) and the `face` element's vertex_indices (or
   vertex_index) list; every other property and element is read past.
   Polygons are fan-triangulated as in OBJ.

   Fuzz safety: the header is bounded (32 elements, 128 properties); a
   count the rest of the file cannot hold (each instance needs at least one
   byte per scalar in binary, two characters in ASCII) is refused before any
   allocation is sized by it; every binary read is bounds-checked, so no
   loop runs longer than the file is.  Messages name the element as the
   header numbers it, from 1 ("face 12"), with the line (ASCII) or the byte
   offset (binary) where the bad value is. */

enum { BP__PLY_I8, BP__PLY_U8, BP__PLY_I16, BP__PLY_U16, BP__PLY_I32, BP__PLY_U32, BP__PLY_F32, BP__PLY_F64 };
enum { BP__PLY_SKIP, BP__PLY_X, BP__PLY_Y, BP__PLY_Z, BP__PLY_U, BP__PLY_V, BP__PLY_INDICES };
enum { BP__PLY_ASCII, BP__PLY_LE, BP__PLY_BE };

typedef struct bp__ply_prop { int type, list; int role; } bp__ply_prop;   /* list: count type or -1 */
typedef struct bp__ply_elem { int kind; int64_t count; int first, nprops; } bp__ply_elem;  /* kind 1 vertex, 2 face */

typedef struct bp__ply {
    bp__parser  *ps;
    int          format;
    bp__ply_elem elem[32];
    int          nelem;
    bp__ply_prop prop[128];
    int          nprop;
    const char  *what;         /* "vertex", "face" or the element's role   */
    int64_t      index;        /* 0-based instance being read              */
    const char  *at;           /* where the value being read starts         */
} bp__ply;

static const int bp__ply_size[] = { 1, 1, 2, 2, 4, 4, 4, 8 };

/* "line 12: face 3: ..." (ASCII) or "face 3 (byte offset 1234): ..." */
static bp_status bp__ply_fail(bp__ply *P, bp_status st, const char *fmt, ...)
{
    char detail[200];
    va_list ap;
    bp__parser *ps = P->ps;
    va_start(ap, fmt);
    bp__vformat(detail, sizeof detail, fmt, ap);
    va_end(ap);
    if (P->format == BP__PLY_ASCII)
        return bp__fail(ps->err, st, BP_ELEMENT_LINE, ps->line, -1, ps->line, "line %D: %s %D: %s",
                        ps->line, P->what, P->index + 1, detail);
    return bp__fail(ps->err, st, BP_ELEMENT_NONE, -1, -1, 0, "%s %D (byte offset %D): %s",
                    P->what, P->index + 1, (int64_t)((P->at ? P->at : ps->p) - ps->begin), detail);
}

/* The header's type names (the PLY 1.0 names and their sized aliases). */
static int bp__ply_type(const char *w, size_t n)
{
    static const char *const names[] = { "char", "uchar", "short", "ushort", "int", "uint", "float", "double",
                                         "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64" };
    int i;
    for (i = 0; i < 16; i++)
        if (strlen(names[i]) == n && !memcmp(names[i], w, n)) return i % 8;
    return -1;
}

static int bp__ply_word_is(const char *w, size_t n, const char *s)
{
    return strlen(s) == n && !memcmp(w, s, n);
}

/* The next word of a header line into (*w, *n); 0 at the end of the line. */
static int bp__ply_word(bp__parser *ps, const char **w, size_t *n)
{
    bp__skip_space(ps);
    *w = ps->p;
    *n = bp__token_len(ps, NULL);
    ps->p += *n;
    return *n > 0;
}

static int bp__ply_role(int kind, const char *w, size_t n, int list)
{
    if (kind == 1 && list < 0) {
        if (bp__ply_word_is(w, n, "x")) return BP__PLY_X;
        if (bp__ply_word_is(w, n, "y")) return BP__PLY_Y;
        if (bp__ply_word_is(w, n, "z")) return BP__PLY_Z;
        if (bp__ply_word_is(w, n, "s") || bp__ply_word_is(w, n, "u") || bp__ply_word_is(w, n, "texture_u") ||
            bp__ply_word_is(w, n, "texture_s")) return BP__PLY_U;
        if (bp__ply_word_is(w, n, "t") || bp__ply_word_is(w, n, "v") || bp__ply_word_is(w, n, "texture_v") ||
            bp__ply_word_is(w, n, "texture_t")) return BP__PLY_V;
    }
    if (kind == 2 && list >= 0 && (bp__ply_word_is(w, n, "vertex_indices") || bp__ply_word_is(w, n, "vertex_index")))
        return BP__PLY_INDICES;
    return BP__PLY_SKIP;
}

static bp_status bp__ply_header_fail(bp__parser *ps, const char *what)
{
    return bp__fail(ps->err, BP_ERR_PARSE, BP_ELEMENT_LINE, ps->line, -1, ps->line, "line %D: %s", ps->line, what);
}

/* One `element` or `property` line (the keyword already read). */
static bp_status bp__ply_declare(bp__ply *P, int is_elem)
{
    bp__parser *ps = P->ps;
    const char *w;
    size_t n;
    if (is_elem) {
        bp__ply_elem *e = &P->elem[P->nelem];
        int64_t c;
        bp_status st;
        if (P->nelem == 32) return bp__ply_header_fail(ps, "more than 32 elements");
        if (!bp__ply_word(ps, &w, &n)) return bp__ply_header_fail(ps, "the element has no name");
        e->kind = bp__ply_word_is(w, n, "vertex") ? 1 : bp__ply_word_is(w, n, "face") ? 2 : 0;
        bp__skip_space(ps);
        if ((st = bp__parse_int(ps, &c, "element count")) != BP_OK) return st;
        if (c < 0 || c > 0xffffffffLL) return bp__ply_header_fail(ps, "the element count is negative or above 2^32-1");
        e->count = c;
        e->first = P->nprop;
        e->nprops = 0;
        P->nelem++;
        return BP_OK;
    }
    if (!P->nelem) return bp__ply_header_fail(ps, "a property before any element");
    if (P->nprop == 128) return bp__ply_header_fail(ps, "more than 128 properties");
    {
        bp__ply_prop *p = &P->prop[P->nprop];
        bp__ply_elem *e = &P->elem[P->nelem - 1];
        if (!bp__ply_word(ps, &w, &n)) return bp__ply_header_fail(ps, "the property has no type");
        p->list = -1;
        if (bp__ply_word_is(w, n, "list")) {
            if (!bp__ply_word(ps, &w, &n) || (p->list = bp__ply_type(w, n)) < 0 || p->list >= BP__PLY_F32)
                return bp__ply_header_fail(ps, "a list needs an integer count type");
            if (!bp__ply_word(ps, &w, &n)) return bp__ply_header_fail(ps, "the list has no item type");
        }
        if ((p->type = bp__ply_type(w, n)) < 0) return bp__ply_header_fail(ps, "unknown property type");
        if (!bp__ply_word(ps, &w, &n)) return bp__ply_header_fail(ps, "the property has no name");
        p->role = bp__ply_role(e->kind, w, n, p->list);
        if (p->role == BP__PLY_INDICES && p->type >= BP__PLY_F32)
            return bp__ply_header_fail(ps, "vertex indices must have an integer type");
        P->nprop++;
        e->nprops++;
    }
    return BP_OK;
}

/* Header: "ply", "format ...", then element / property / comment / obj_info
   lines up to "end_header".  The cursor is left at the first data byte. */
static bp_status bp__ply_header(bp__ply *P)
{
    bp__parser *ps = P->ps;
    const char *w;
    size_t n;
    int have_format = 0;
    bp_status st;
    if (!bp__keyword(ps, "ply")) return bp__ply_header_fail(ps, "a PLY file must start with 'ply'");
    for (;;) {
        bp__next_line(ps);
        if (ps->p >= ps->end) return bp__ply_header_fail(ps, "the file ends before 'end_header'");
        bp__ply_word(ps, &w, &n);
        if (bp__ply_word_is(w, n, "end_header")) break;
        if (bp__ply_word_is(w, n, "format")) {
            bp__ply_word(ps, &w, &n);
            if (bp__ply_word_is(w, n, "ascii")) P->format = BP__PLY_ASCII;
            else if (bp__ply_word_is(w, n, "binary_little_endian")) P->format = BP__PLY_LE;
            else if (bp__ply_word_is(w, n, "binary_big_endian")) P->format = BP__PLY_BE;
            else return bp__ply_header_fail(ps, "unknown format (ascii, binary_little_endian, binary_big_endian)");
            have_format = 1;
        } else if (bp__ply_word_is(w, n, "element") || bp__ply_word_is(w, n, "property")) {
            if ((st = bp__ply_declare(P, w[0] == 'e')) != BP_OK) return st;
        } else if (n && !bp__ply_word_is(w, n, "comment") && !bp__ply_word_is(w, n, "obj_info"))
            return bp__ply_header_fail(ps, "unknown header line");
    }
    if (!have_format) return bp__ply_header_fail(ps, "the header has no 'format' line");
    bp__next_line(ps);
    return BP_OK;
}

/* One value of a type, as a double (exact for every PLY integer). */
static bp_status bp__ply_value(bp__ply *P, int type, double *out)
{
    bp__parser *ps = P->ps;
    if (P->format == BP__PLY_ASCII) {
        char buf[80], *stop;
        size_t n;
        while (ps->p < ps->end && (bp__is_space(*ps->p) || bp__is_eol(*ps->p))) {
            if (*ps->p == '\n' || (*ps->p == '\r' && (ps->p + 1 >= ps->end || ps->p[1] != '\n'))) ps->line++;
            ps->p++;
        }
        n = bp__token_len(ps, NULL);
        if (n == 0) return bp__ply_fail(P, BP_ERR_PARSE, "the file ends before this value");
        if (n >= sizeof buf) return bp__ply_fail(P, BP_ERR_PARSE, "a value is too long");
        memcpy(buf, ps->p, n);
        buf[n] = 0;
        *out = strtod(buf, &stop);
        if (stop != buf + n) return bp__ply_fail(P, BP_ERR_PARSE, "'%s' is not a number", buf);
        ps->p += n;
        if (type < BP__PLY_F32) {      /* an integer: whole and in its type's range */
            static const double lo[] = { -128, 0, -32768, 0, -2147483648.0, 0 };
            static const double hi[] = { 127, 255, 32767, 65535, 2147483647.0, 4294967295.0 };
            if (!(*out == floor(*out) && *out >= lo[type] && *out <= hi[type]))
                return bp__ply_fail(P, BP_ERR_PARSE, "'%s' is not a value of the property's integer type", buf);
        }
        return BP_OK;
    } else {
        const unsigned char *b = (const unsigned char *)ps->p;
        int size = bp__ply_size[type], i;
        uint64_t u = 0;
        P->at = ps->p;
        if (ps->end - ps->p < size) return bp__ply_fail(P, BP_ERR_PARSE, "the file ends inside this value");
        for (i = 0; i < size; i++) u = (u << 8) | b[P->format == BP__PLY_BE ? i : size - 1 - i];
        ps->p += size;
        switch (type) {
        case BP__PLY_I8:  *out = (double)(int8_t)(uint8_t)u; break;
        case BP__PLY_I16: *out = (double)(int16_t)(uint16_t)u; break;
        case BP__PLY_I32: *out = (double)(int32_t)(uint32_t)u; break;
        case BP__PLY_F32: { uint32_t w = (uint32_t)u; float f; memcpy(&f, &w, 4); *out = f; } break;
        case BP__PLY_F64: memcpy(out, &u, 8); break;
        default: *out = (double)u; break;
        }
        return BP_OK;
    }
}

/* Read past a scalar of a property the library does not use (ASCII: any
   token, even one that is not a number). */
static bp_status bp__ply_skip(bp__ply *P, int type)
{
    double x;
    bp__parser *ps = P->ps;
    if (P->format != BP__PLY_ASCII) {
        P->at = ps->p;
        if (ps->end - ps->p < bp__ply_size[type]) return bp__ply_fail(P, BP_ERR_PARSE, "the file ends inside this value");
        ps->p += bp__ply_size[type];
        return BP_OK;
    }
    if (bp__ply_value(P, BP__PLY_F64, &x) == BP_OK) return BP_OK;
    return ps->p < ps->end && bp__token_len(ps, NULL) > 0 ? (ps->p += bp__token_len(ps, NULL), BP_OK)
                                                         : bp__ply_fail(P, BP_ERR_PARSE, "the file ends before this value");
}

/* The count of a list: a non-negative integer. */
static bp_status bp__ply_list_count(bp__ply *P, int type, int64_t *n)
{
    double c;
    bp_status st = bp__ply_value(P, type, &c);
    if (st != BP_OK) return st;
    if (c < 0 || c > 4294967295.0) return bp__ply_fail(P, BP_ERR_PARSE, "a list has %g items", c);
    *n = (int64_t)c;
    return BP_OK;
}

/* Read past one property the library does not use: a scalar, or a list
   (its count, then that many items). */
static bp_status bp__ply_skip_prop(bp__ply *P, const bp__ply_prop *p)
{
    int64_t n = 1, j;
    bp_status st = BP_OK;
    if (p->list >= 0) st = bp__ply_list_count(P, p->list, &n);
    for (j = 0; j < n && st == BP_OK; j++) st = bp__ply_skip(P, p->type);
    return st;
}

/* The least bytes one instance of e takes: 1 per binary byte / 2 ASCII
   characters per scalar or list count (list items may be none). */
static int64_t bp__ply_min_bytes(const bp__ply *P, const bp__ply_elem *e)
{
    int64_t b = 0;
    int i;
    for (i = 0; i < e->nprops; i++) {
        const bp__ply_prop *p = &P->prop[e->first + i];
        b += P->format == BP__PLY_ASCII ? 2 : bp__ply_size[p->list >= 0 ? p->list : p->type];
    }
    return b;
}

/* One vertex: x y z (and u v) into the builder. */
static bp_status bp__ply_vertex(bp__ply *P, const bp__ply_elem *e, bp__mesh_builder *b, int has_uv)
{
    double x[5] = { 0, 0, 0, 0, 0 };
    int i, k;
    bp_status st;
    for (i = 0; i < e->nprops; i++) {
        const bp__ply_prop *p = &P->prop[e->first + i];
        if (p->list >= 0 || p->role == BP__PLY_SKIP) {
            if ((st = bp__ply_skip_prop(P, p)) != BP_OK) return st;
        } else {
            if ((st = bp__ply_value(P, p->type, &x[p->role - BP__PLY_X])) != BP_OK) return st;
            if (!(x[p->role - BP__PLY_X] - x[p->role - BP__PLY_X] == 0))
                return bp__ply_fail(P, BP_ERR_NONFINITE, "a coordinate is not finite");
        }
    }
    for (k = 0; k < 3; k++)
        if (!bp__vec_push(P->ps->a, &b->pos, &x[k])) return bp__oom(P->ps->err, "reading vertices");
    for (k = 3; has_uv && k < 5; k++)
        if (!bp__vec_push(P->ps->a, &b->uv, &x[k])) return bp__oom(P->ps->err, "reading vertices");
    return BP_OK;
}

/* One face: its vertex_indices list, fan-triangulated. */
static bp_status bp__ply_face(bp__ply *P, const bp__ply_elem *e, bp__mesh_builder *b, bp__vec *fv, int64_t nv)
{
    int i, got = 0;
    bp_status st;
    for (i = 0; i < e->nprops; i++) {
        const bp__ply_prop *p = &P->prop[e->first + i];
        int64_t n, j;
        if (p->list < 0 || p->role != BP__PLY_INDICES || got) {
            if ((st = bp__ply_skip_prop(P, p)) != BP_OK) return st;
            continue;
        }
        if ((st = bp__ply_list_count(P, p->list, &n)) != BP_OK) return st;
        got = 1;
        if (n < 3) return bp__ply_fail(P, BP_ERR_POLYGON, "a face needs at least 3 corners, this one has %D", n);
        fv->count = 0;
        for (j = 0; j < n; j++) {
            double v;
            uint32_t v32;
            if ((st = bp__ply_value(P, p->type, &v)) != BP_OK) return st;
            if (v < 0 || v >= (double)nv)
                return bp__ply_fail(P, BP_ERR_INDEX, "vertex index %D is out of range (the header declares %D vertices)",
                                    (int64_t)v, nv);
            v32 = (uint32_t)v;
            if (!bp__vec_push(P->ps->a, fv, &v32)) return bp__oom(P->ps->err, "reading faces");
        }
    }
    if (!got) return bp__ply_fail(P, BP_ERR_PARSE, "the face has no vertex_indices list");
    return bp__builder_face(P->ps, b, (const uint32_t *)fv->data, NULL, fv->count);
}

/* The body, element by element in header order. */
static bp_status bp__ply_body(bp__ply *P, bp__mesh_builder *b, bp__vec *fv)
{
    bp__parser *ps = P->ps;
    int64_t nv = 0, i;
    int k, j, has_uv = 0, u = 0, v = 0;
    bp_status st = BP_OK;
    for (k = 0; k < P->nelem; k++)
        if (P->elem[k].kind == 1) {
            nv += P->elem[k].count;
            for (j = 0; j < P->elem[k].nprops; j++) {
                u |= P->prop[P->elem[k].first + j].role == BP__PLY_U;
                v |= P->prop[P->elem[k].first + j].role == BP__PLY_V;
            }
        }
    has_uv = u && v;
    for (k = 0; k < P->nelem && st == BP_OK; k++) {
        const bp__ply_elem *e = &P->elem[k];
        int64_t min = bp__ply_min_bytes(P, e);
        static const char *const kinds[] = { "element", "vertex", "face" };
        P->what = kinds[e->kind];
        P->index = 0;
        P->at = ps->p;
        if (e->count > 0 && min > 0 && e->count > (int64_t)(ps->end - ps->p) / min + 1)
            return bp__ply_fail(P, BP_ERR_PARSE, "the header declares %D of this element, more than the rest of the file "
                                "(%D bytes) can hold", e->count, (int64_t)(ps->end - ps->p));
        if (e->kind == 1) {            /* every vertex needs x, y and z (faces index them) */
            int have = 0;
            for (j = 0; j < e->nprops; j++) {
                int r = P->prop[e->first + j].role;
                if (P->prop[e->first + j].list < 0 && r >= BP__PLY_X && r <= BP__PLY_Z) have |= 1 << (r - BP__PLY_X);
            }
            if (have != 7 && e->count > 0)
                return bp__ply_fail(P, BP_ERR_PARSE, "the vertex element does not declare the properties x, y and z");
        }
        if (!e->nprops) continue;                      /* nothing to read */
        if (e->kind == 1 && (!bp__vec_reserve(ps->a, &b->pos, 3 * (size_t)e->count + b->pos.count) ||
                             (has_uv && !bp__vec_reserve(ps->a, &b->uv, 2 * (size_t)e->count + b->uv.count))))
            return bp__oom(ps->err, "reading vertices");
        for (i = 0; i < e->count && st == BP_OK; i++) {
            P->index = i;
            if (e->kind == 1) st = bp__ply_vertex(P, e, b, has_uv);
            else if (e->kind == 2) st = bp__ply_face(P, e, b, fv, nv);
            else {
                int p;
                for (p = 0; p < e->nprops && st == BP_OK; p++) st = bp__ply_skip_prop(P, &P->prop[e->first + p]);
            }
            if (ps->opt && (i & 16383) == 16383) bp__parse_tick(ps);
            if (ps->cancelled) return BP_ERR_CANCELLED;
        }
    }
    return st;
}

static bp_status bp__parse_ply(bp__parser *ps, bp_mesh *mesh)
{
    bp__ply P;
    bp__mesh_builder b;
    bp__vec fv;
    bp_status st;
    memset(&P, 0, sizeof P);
    P.ps = ps;
    P.what = "element";
    bp__builder_init(&b);
    memset(&fv, 0, sizeof fv);
    fv.elem = sizeof(uint32_t);
    if ((st = bp__ply_header(&P)) != BP_OK) return st;
    st = bp__ply_body(&P, &b, &fv);
    bp__free(ps->a, fv.data);
    if (st == BP_OK && b.uv.count) {        /* per-vertex uvs: corner uv = vertex */
        size_t i;
        if (!bp__vec_reserve(ps->a, &b.cuv, b.tri.count)) st = bp__oom(ps->err, "reading faces");
        for (i = 0; st == BP_OK && i < b.tri.count; i++) bp__vec_push(ps->a, &b.cuv, (uint32_t *)b.tri.data + i);
    }
    if (st == BP_OK) st = bp__builder_finish(ps, &b, mesh);
    if (st != BP_OK) { bp__builder_free(ps->a, &b); return st; }
    if (P.format != BP__PLY_ASCII) {       /* no lines to name in a binary file */
        bp__free(ps->a, mesh->triangle_line);
        mesh->triangle_line = NULL;
    }
    return BP_OK;
}

#ifndef BP_NO_STDIO
/* Why a file operation failed, for the message: strerror(errno) when the C
   library set errno (POSIX always does), else nothing. */
static const char *bp__io_reason(int e)
{
    return e ? strerror(e) : "unknown reason";
}

/* The whole file into one allocation (*text, *length; free with bp__free).
   A directory opens on POSIX but cannot be read: its EISDIR says so. */
static bp_status bp__load_file(const char *path, const bp_allocator *a, char **text,
                               size_t *length, bp_error *err, const bp_options *opt)
{
    FILE *f;
    char *buf = NULL;
    size_t len = 0, cap = 0;
    int e;
    double size = 0;                  /* for the progress: bytes in the file */
    *text = NULL;
    *length = 0;
    errno = 0;
    f = fopen(path, "rb");
    if (!f)
        return bp__fail(err, BP_ERR_IO, BP_ELEMENT_NONE, -1, -1, 0, "cannot open '%s': %s",
                        path, bp__io_reason(errno));
    if (opt && opt->run_progress && fseek(f, 0, SEEK_END) == 0) {
        long n = ftell(f);
        size = n > 0 ? (double)n : 0;
        if (fseek(f, 0, SEEK_SET) != 0) size = -1;
    }
    for (;;) {                                  /* read in growing chunks */
        size_t got;
        if (size < 0 || (opt && opt->run_progress &&
                         bp__report(opt, BP_STAGE_READ, size > 0 && len < size ? 0.5 * len / size : 0, BP_NO_CHART))) {
            bp__free(a, buf);
            fclose(f);
            if (size < 0) return bp__fail(err, BP_ERR_IO, BP_ELEMENT_NONE, -1, -1, 0, "cannot read '%s': cannot seek", path);
            return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled while reading '%s'", path);
        }
        if (len == cap) {
            size_t ncap = cap ? cap * 2 : size > 0 && size < 1e15 ? (size_t)size + 1 : 1 << 16;
            char *nb = ncap > cap ? (char *)bp__alloc(a, ncap) : NULL;
            if (!nb) { bp__free(a, buf); fclose(f); return bp__oom(err, "reading the file"); }
            if (len) memcpy(nb, buf, len);
            bp__free(a, buf);
            buf = nb;
            cap = ncap;
        }
        errno = 0;
        got = fread(buf + len, 1, cap - len < (1u << 22) ? cap - len : (1u << 22), f);   /* 4 MiB: progress */
        len += got;
        if (got == 0) break;
    }
    e = errno;
    if (ferror(f)) {
        bp__free(a, buf);
        fclose(f);
        return bp__fail(err, BP_ERR_IO, BP_ELEMENT_NONE, -1, -1, 0, "cannot read '%s': %s",
                        path, bp__io_reason(e));
    }
    fclose(f);
    *text = buf;
    *length = len;
    return BP_OK;
}

static bp_status bp__read_file(const char *path, bp_mesh *mesh, const bp_allocator *alloc,
                               bp_error *err, int format, const bp_options *opt)
{
    bp_allocator a;
    char *buf;
    size_t len;
    bp_status st;
    memset(&a, 0, sizeof a);
    if (alloc) a = *alloc;
    if (mesh) memset(mesh, 0, sizeof *mesh);
    if (!path || !mesh)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "path and mesh must not be NULL");
    if ((st = bp__load_file(path, &a, &buf, &len, err, opt)) != BP_OK) return st;
    st = bp__parse_text(buf, len, mesh, &a, err, format, opt);
    if (st == BP_OK && bp__report(opt, BP_STAGE_READ, 1, BP_NO_CHART)) {
        bp_mesh_free(mesh, &a);
        st = bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled after reading '%s'", path);
    }
    bp__free(&a, buf);
    return st;
}

BPDEF bp_status bp_read_obj(const char *path, bp_mesh *mesh, const bp_allocator *alloc, bp_error *err)
{
    return bp__read_file(path, mesh, alloc, err, BP__FORMAT_OBJ, NULL);
}

BPDEF bp_status bp_read_off(const char *path, bp_mesh *mesh, const bp_allocator *alloc, bp_error *err)
{
    return bp__read_file(path, mesh, alloc, err, BP__FORMAT_OFF, NULL);
}

BPDEF bp_status bp_read_ply(const char *path, bp_mesh *mesh, const bp_allocator *alloc, bp_error *err)
{
    return bp__read_file(path, mesh, alloc, err, BP__FORMAT_PLY, NULL);
}

static int bp__ends_with_ci(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix), i;
    if (n < m) return 0;
    for (i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != suffix[i]) return 0;
    }
    return 1;
}

BPDEF const char *bp_mesh_format(const char *path)
{
    if (path && bp__ends_with_ci(path, ".obj")) return "obj";
    if (path && bp__ends_with_ci(path, ".off")) return "off";
    if (path && bp__ends_with_ci(path, ".ply")) return "ply";
    return NULL;
}

BPDEF bp_status bp_read_mesh_opt(const char *path, bp_mesh *mesh, const bp_options *opt, bp_error *err)
{
    const char *f = bp_mesh_format(path);
    bp_options o;
    bp_allocator a;
    bp_status st;
    if ((opt = bp__opts(opt, &o, err, &st)), st != BP_OK) { if (mesh) memset(mesh, 0, sizeof *mesh); return st; }
    a = bp__allocator_of(opt);
    if (f) return bp__read_file(path, mesh, &a, err, f[1] == 'f' ? BP__FORMAT_OFF : f[0] == 'p' ? BP__FORMAT_PLY : BP__FORMAT_OBJ, opt);
    if (mesh) memset(mesh, 0, sizeof *mesh);
    return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                    "'%s': unknown file type (expected .obj, .off or .ply)", path ? path : "(null)");
}

BPDEF bp_status bp_read_mesh(const char *path, bp_mesh *mesh, const bp_allocator *alloc, bp_error *err)
{
    bp_options o;
    memset(&o, 0, sizeof o);
    if (alloc) o.allocator = *alloc;
    o.threads = 1;            /* no options, no threads: as bp_read_obj */
    return bp_read_mesh_opt(path, mesh, &o, err);
}

/* ---- writing ------------------------------------------------------------

   Two writers.  bp_write_obj writes a new OBJ from the mesh alone: v in
   input order, one vt per chart vertex, f v/vt in face order (a polygon
   whose fan triangles disagree on a corner, below, as its triangles).  Whatever
   else the file had (normals, materials, groups, comments) is not in a
   bp_mesh, so it is gone.  bp_write_obj_from keeps it: it streams the
   file the mesh was read from and copies every line byte for byte, in
   order, except the texture coordinates it replaces:

     - every old `vt` line goes; the new ones (one per chart vertex, charts
       in order) go where the first `vt` or `f` line was, whichever comes
       first, so every face refers backwards to them;
     - each `f` line keeps its text (the `f`, the spacing, a trailing
       comment, the line ending) and each corner keeps its vertex and
       normal index exactly as written -- a relative index such as -1 still
       means the same element, since no v or vn line moves relative to the
       faces -- and gets the absolute index of its new vt;
     - a face of a chart that failed keeps v (and vn) without vt;
     - a face the repair re-oriented (>>charts, "repair") is written with
       its corners in the repaired order: corner 0, then the others
       reversed, each corner's text (v/vt/vn) moved as a whole while the
       spacing stays in place.  The charts' maps are bijective for the
       repaired orientation; a face left in its file order would run
       against its own uvs (mirrored), and no order that keeps every face
       as written can be valid (two neighbours running the same way along
       their edge cannot both map counter-clockwise without overlap).  So
       the file comes out consistently oriented; compared with the damaged
       input, exactly these faces are reversed.  Which faces: those whose
       chart triangle runs (0, 2, 1) of their corners (bp__face_flips).

   A polygon is one `f` line whose fan triangles (0, i, i+1) are the mesh
   triangles t .. t+n-3; its corner k is corner 0 of every fan triangle
   (k = 0) or a corner of one or two of them.  The charts glue the fan
   triangles along their diagonals, so all of them give the corner the
   same chart vertex.  If they do not (a diagonal that is also a seam: a
   non-manifold edge, a repair cut, an automatic seam of >>cut; or fan
   triangles in a failed and a valid chart), one polygon cannot carry
   both, and both writers write that polygon as its fan triangles, one `f`
   line each (the only change to the line structure); so too a polygon
   whose fan triangles the repair re-oriented differently (across a cut
   diagonal), each fan triangle in its own repaired order.  bp_write_obj_from
   checks as it goes that the file's faces are the mesh's triangles: a
   mesh from another file is refused, not mislabelled.

   Neither writer leaves a half-written file behind: on any error the file
   at `path` is closed and removed.  They write `path` directly; replacing
   a file atomically (write a temporary next to it, then rename) needs
   POSIX, and the tool does it (examples/bijparam.c). */

/* The output goes through a buffer of our own (BP__OUT_CAP bytes) and
   reaches the FILE in large fwrite calls: a face line is a dozen small
   pieces (the corners' text, "/", the new index), and one fwrite per piece
   cost more than the rest of the writer together (docs/performance.md
   6.18).  The bytes and their order are exactly those the pieces make.

   The vt lines (and bp_write_obj's v lines) are most of the formatting
   work: each holds two (three) doubles printed "%.17g", which the C
   library does digit by digit in multiple precision.  They are formatted
   in parallel: the lines are cut into tasks of BP__OUT_LINES_PER_TASK
   consecutive lines, each task formats its lines with the same snprintf
   call into its own slice of a scratch area, and the caller appends the
   slices in task order, a round of BP__OUT_TASKS tasks at a time (so the
   scratch stays at about a megabyte whatever the mesh).  The file's bytes
   are therefore those of one loop of fprintf calls, for any number of
   threads and any order in which the tasks run.  The writers start a pool
   (bp__par_begin: opt->threads, or opt->parallel_for) only when there are
   BP__OUT_PAR_MIN lines or more; the allocator is only called by the
   caller's thread. */
#ifndef BP__OUT_CAP
#define BP__OUT_CAP (1u << 16)
#endif
#ifndef BP__OUT_LINES_PER_TASK
#define BP__OUT_LINES_PER_TASK 1024u
#endif
#ifndef BP__OUT_TASKS
#define BP__OUT_TASKS 16u
#endif
#ifndef BP__OUT_PAR_MIN
#define BP__OUT_PAR_MIN 8192u
#endif
/* The longest formatted line: "%.17g" prints at most 24 characters (sign,
   17 digits, point, "e-308"), so "v x y z\n" is at most 77 bytes and
   "vt u v\r\n" 54. */
#define BP__OUT_LINE_MAX 96u

typedef struct bp__out {
    FILE *f;
    int   ok, e;            /* e: errno of the first failed write         */
    const bp_options *opt;  /* run_progress (BP_STAGE_WRITE), or NULL     */
    int   cancelled;        /* the callback said stop: ok is 0 too        */
    const bp_allocator *a;
    char *buf;              /* bytes not yet handed to fwrite             */
    size_t len, cap;        /* cap: BP__OUT_CAP, or a task's slice        */
    int   full;             /* f NULL (a task's slice): it is full, ok 0  */
    int   oom;              /* scratch memory failed: ok 0 too            */
    bp__par par;            /* who formats the v / vt lines               */
    void *pool;             /* bp__par_begin's pool, stopped at close     */
} bp__out;

/* Progress while writing: every 4096 faces, the share of the mesh's
   triangles written.  A cancel stops the writer as a failed write does,
   and bp__out_close removes the file. */
static void bp__out_tick(bp__out *o, uint32_t t, uint32_t total)
{
    if (!o->opt || (t & 4095) != 0 || !o->ok) return;
    if (bp__report(o->opt, BP_STAGE_WRITE, total ? (double)t / total : 1, BP_NO_CHART)) {
        o->cancelled = 1;
        o->ok = 0;
    }
}

static void bp__out_flush(bp__out *o)
{
    if (o->ok && o->len && fwrite(o->buf, 1, o->len, o->f) != o->len) { o->ok = 0; o->e = errno; }
    o->len = 0;
}

static void bp__out_bytes(bp__out *o, const char *p, size_t n)
{
    if (!o->ok || !n) return;
    if (o->len + n > o->cap) {
        if (!o->f) { o->ok = 0; o->full = 1; return; }
        bp__out_flush(o);
        if (n > o->cap) {
            if (o->ok && fwrite(p, 1, n, o->f) != n) { o->ok = 0; o->e = errno; }
            return;
        }
    }
    memcpy(o->buf + o->len, p, n);
    o->len += n;
}

static void bp__out_str(bp__out *o, const char *s) { bp__out_bytes(o, s, strlen(s)); }

static void bp__out_uint(bp__out *o, uint64_t v)
{
    char buf[24];
    size_t n = 0;
    bp__fmt_uint(buf, &n, sizeof buf, v);
    bp__out_bytes(o, buf, n);
}

/* Line i of a block into dst (at most BP__OUT_LINE_MAX bytes); its length. */
typedef size_t (*bp__line_fn)(const void *ctx, uint32_t i, char *dst);

typedef struct bp__lines_task {
    bp__line_fn fn;
    const void *ctx;
    char       *scratch;    /* task k's slice: k * per * BP__OUT_LINE_MAX  */
    size_t     *len;        /* bytes task k formatted                     */
    uint32_t    first, end, per;
} bp__lines_task;

static void bp__lines_run(void *task, uint32_t k)
{
    const bp__lines_task *T = (const bp__lines_task *)task;
    uint32_t i = T->first + k * T->per, end = T->end - i > T->per ? i + T->per : T->end;
    char *d = T->scratch + (size_t)k * T->per * BP__OUT_LINE_MAX;
    size_t n = 0;
    for (; i < end; i++) n += T->fn(T->ctx, i, d + n);
    T->len[k] = n;
}

/* Lines 0 .. count-1 of a block, in order (see the essay above). */
static void bp__out_lines(bp__out *o, uint32_t count, bp__line_fn fn, const void *ctx)
{
    const uint32_t per = BP__OUT_LINES_PER_TASK, round = per * BP__OUT_TASKS;
    uint32_t first, k, ntask, nround = count < round ? count : round;
    size_t len[BP__OUT_TASKS];
    bp__lines_task T;
    char *scratch;
    if (!count || !o->ok) return;
    if (!(scratch = (char *)bp__alloc_array(o->a, nround, BP__OUT_LINE_MAX))) { o->ok = 0; o->oom = 1; return; }
    T.fn = fn; T.ctx = ctx; T.scratch = scratch; T.len = len; T.per = per;
    for (first = 0; first < count && o->ok; first = T.end) {
        T.first = first;
        T.end = count - first > round ? first + round : count;
        ntask = (T.end - first + per - 1) / per;
        if (ntask > 1) o->par.run(o->par.user, bp__lines_run, &T, ntask);
        else bp__lines_run(&T, 0);
        for (k = 0; k < ntask; k++) bp__out_bytes(o, scratch + (size_t)k * per * BP__OUT_LINE_MAX, len[k]);
    }
    bp__free(o->a, scratch);
}

static bp_status bp__out_open(bp__out *o, const char *path, const bp_allocator *a, bp_error *err)
{
    memset(o, 0, sizeof *o);
    o->a = a;
    o->par = bp__par_serial();
    o->cap = BP__OUT_CAP;
    if (!(o->buf = (char *)bp__alloc(a, BP__OUT_CAP))) return bp__oom(err, "writing the OBJ file");
    errno = 0;
    o->f = fopen(path, "wb");
    o->ok = o->f != NULL;
    if (!o->f) {
        bp__free(a, o->buf);
        return bp__fail(err, BP_ERR_IO, BP_ELEMENT_NONE, -1, -1, 0, "cannot open '%s' for writing: %s",
                        path, bp__io_reason(errno));
    }
    return BP_OK;
}

/* Threads for the lines when there are enough of them and options
   (bp_write_obj and bp_write_obj_from, without, stay on one thread). */
static void bp__out_threads(bp__out *o, const bp_options *opt, uint64_t lines)
{
    if (opt && lines >= BP__OUT_PAR_MIN) o->par = bp__par_begin(o->a, opt, &o->pool);
}

/* Close; if anything failed (a write here, or `st` from the caller), remove
   the partial file. */
static bp_status bp__out_close(bp__out *o, const char *path, bp_status st, bp_error *err)
{
    bp__par_end(o->a, o->pool);
    o->pool = NULL;
    bp__out_flush(o);
    bp__free(o->a, o->buf);
    errno = 0;
    if (fclose(o->f) != 0 && o->ok) { o->ok = 0; o->e = errno; }
    if (st == BP_OK && o->ok && bp__report(o->opt, BP_STAGE_WRITE, 1, BP_NO_CHART)) o->cancelled = 1;
    if (st == BP_OK && o->oom) st = bp__oom(err, "writing the OBJ file");
    if (st == BP_OK && o->cancelled)
        st = bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0,
                      "cancelled while writing '%s' (the partial file is removed)", path);
    if (st == BP_OK && !o->ok)
        st = bp__fail(err, BP_ERR_IO, BP_ELEMENT_NONE, -1, -1, 0, "cannot write '%s': %s",
                      path, bp__io_reason(o->e));
    if (st != BP_OK) remove(path);
    return st == BP_OK ? bp__ok(err) : st;
}

/* 0-based index of the first new vt of each chart (charts without a map
   have none). */
static uint32_t *bp__vt_base(const bp_atlas *atlas, const bp_allocator *a)
{
    uint32_t *base = (uint32_t *)bp__alloc_array(a, (size_t)atlas->num_charts + 1, sizeof *base);
    uint32_t c;
    if (!base) return NULL;
    base[0] = 0;
    for (c = 0; c < atlas->num_charts; c++)
        base[c + 1] = base[c] + (atlas->charts[c].uv ? atlas->charts[c].num_vertices : 0);
    return base;
}

/* The new vt lines: line i is vertex i - base[c] of the chart c with
   base[c] <= i < base[c + 1] (found by bisection). */
typedef struct bp__vt_lines { const bp_atlas *atlas; const uint32_t *base; const char *eol; } bp__vt_lines;

static size_t bp__vt_line(const void *ctx, uint32_t i, char *dst)
{
    const bp__vt_lines *L = (const bp__vt_lines *)ctx;
    uint32_t lo = 0, hi = L->atlas->num_charts;       /* base[lo] <= i < base[hi] */
    const double *uv;
    int n;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (L->base[mid] <= i) lo = mid; else hi = mid;
    }
    uv = L->atlas->charts[lo].uv + 2 * (size_t)(i - L->base[lo]);
    n = snprintf(dst, BP__OUT_LINE_MAX, "vt %.17g %.17g%s", uv[0], uv[1], L->eol);
    return n <= 0 ? 0 : n < (int)BP__OUT_LINE_MAX ? (size_t)n : BP__OUT_LINE_MAX - 1;
}

static void bp__out_vt_block(bp__out *o, const bp_atlas *atlas, const uint32_t *base, const char *eol)
{
    bp__vt_lines L;
    L.atlas = atlas; L.base = base; L.eol = eol;
    bp__out_lines(o, base[atlas->num_charts], bp__vt_line, &L);
}

/* The new vt (0-based) of corner k of mesh triangle t, BP__NONE in a chart
   without a map. */
static uint32_t bp__corner_vt(const bp_atlas *atlas, const uint32_t *base, uint32_t t, int k)
{
    uint32_t c = atlas->corner_chart[3 * (size_t)t + k];
    return atlas->charts[c].uv ? base[c] + atlas->corner_vertex[3 * (size_t)t + k] : BP__NONE;
}

/* The triangles the repair re-oriented (>>charts, "repair"): flip[t] = 1
   when the chart triangle of mesh triangle t runs its corners (0, 2, 1),
   read from the charts themselves (a chart's three corners are distinct
   chart vertices).  *out = NULL when the repair flipped nothing.  A dropped
   copy (in no chart) keeps its file order. */
static bp_status bp__face_flips(const bp_atlas *atlas, const bp_mesh *mesh, const bp_allocator *a,
                                unsigned char **out)
{
    uint32_t c, t;
    *out = NULL;
    if (!atlas->repairs.kind[BP_REPAIR_FLIPPED].count) return BP_OK;
    if (!(*out = (unsigned char *)bp__calloc_array(a, mesh->num_triangles ? mesh->num_triangles : 1, 1)))
        return BP_ERR_OUT_OF_MEMORY;
    for (c = 0; c < atlas->num_charts; c++) {
        const bp_chart *ch = &atlas->charts[c];
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t, f = ch->face[t];
            const uint32_t *cv = atlas->corner_vertex + 3 * (size_t)f;
            if (f < mesh->num_triangles && tr[0] == cv[0] && tr[1] == cv[2] && tr[2] == cv[1] && tr[1] != tr[2])
                (*out)[f] = 1;
        }
    }
    return BP_OK;
}

/* Does every fan triangle of [t, end) have the same orientation flag? */
static int bp__fan_flip(const unsigned char *flip, uint32_t t, uint32_t end, int *same)
{
    uint32_t j;
    *same = 1;
    if (!flip) return 0;
    for (j = t + 1; j < end; j++)
        if (flip[j] != flip[t]) *same = 0;
    return flip[t];
}

/* Do the fan triangles [t, end) of one polygon give each of its corners
   one vt?  Triangle j shares corner 0 with triangle t and its corner 1 is
   triangle j-1's corner 2 (the essay above). */
static int bp__fan_agrees(const bp_atlas *atlas, const uint32_t *base, uint32_t t, uint32_t end)
{
    uint32_t j;
    for (j = t + 1; j < end; j++)
        if (bp__corner_vt(atlas, base, j, 0) != bp__corner_vt(atlas, base, t, 0) ||
            bp__corner_vt(atlas, base, j, 1) != bp__corner_vt(atlas, base, j - 1, 2))
            return 0;
    return 1;
}

/* One f line for the fan triangles [t, end): corners 0, 1, 2 of the first,
   then corner 2 of each further one; reversed after corner 0 (0, n-1, ...,
   1) when `rev`, the triangles' repaired orientation; a chart that failed
   has no map: geometry only. */
static void bp__out_fan(bp__out *o, const bp_mesh *mesh, const bp_atlas *atlas, const uint32_t *base,
                        uint32_t t, uint32_t end, int rev)
{
    uint32_t j, n = 3 + (end - t - 1);
    int mapped = atlas->charts[atlas->corner_chart[3 * (size_t)t]].uv != NULL;
    bp__out_str(o, "f");
    for (j = 0; j < n; j++) {
        uint32_t k = rev && j ? n - j : j, tt = k < 3 ? t : t + k - 2, kk = k < 3 ? k : 2;
        bp__out_str(o, " ");
        bp__out_uint(o, (uint64_t)mesh->triangles[3 * (size_t)tt + kk] + 1);
        if (mapped) {
            bp__out_str(o, "/");
            bp__out_uint(o, (uint64_t)bp__corner_vt(atlas, base, tt, (int)kk) + 1);
        }
    }
    bp__out_str(o, "\n");
}

/* Line i of the v block: vertex i's position. */
static size_t bp__v_line(const void *ctx, uint32_t i, char *dst)
{
    const double *p = ((const bp_mesh *)ctx)->positions + 3 * (size_t)i;
    int n = snprintf(dst, BP__OUT_LINE_MAX, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    return n <= 0 ? 0 : n < (int)BP__OUT_LINE_MAX ? (size_t)n : BP__OUT_LINE_MAX - 1;
}

static bp_status bp__write_obj(const char *path, const bp_mesh *mesh,
                               const bp_atlas *atlas, const bp_options *opt, bp_error *err)
{
    bp__out o;
    char head[128];
    int n;
    uint32_t t, *base;
    unsigned char *flip = NULL;
    bp_allocator a;
    bp_status st;
    if (!path || !mesh || !atlas || atlas->num_corners != 3 * mesh->num_triangles)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_write_obj needs a path, the mesh and the atlas built from it");
    a = atlas->allocator;
    if (!(base = bp__vt_base(atlas, &a))) return bp__oom(err, "writing the OBJ file");
    if (bp__face_flips(atlas, mesh, &a, &flip) != BP_OK) { bp__free(&a, base); return bp__oom(err, "writing the OBJ file"); }
    if ((st = bp__out_open(&o, path, &a, err)) != BP_OK) { bp__free(&a, flip); bp__free(&a, base); return st; }
    o.opt = opt;
    bp__out_threads(&o, opt, (uint64_t)mesh->num_vertices + base[atlas->num_charts]);
    n = snprintf(head, sizeof head, "# written by bijparam " BP_VERSION_STRING ": %u vertices, %u charts\n",
                 mesh->num_vertices, atlas->num_charts);
    bp__out_bytes(&o, head, n > 0 && n < (int)sizeof head ? (size_t)n : 0);
    bp__out_lines(&o, mesh->num_vertices, bp__v_line, mesh);
    bp__out_vt_block(&o, atlas, base, "\n");
    for (t = 0; t < mesh->num_triangles && o.ok; ) {
        uint32_t end = t + 1, j;
        int same, rev;
        if (mesh->triangle_face)
            while (end < mesh->num_triangles && mesh->triangle_face[end] == mesh->triangle_face[t]) end++;
        rev = bp__fan_flip(flip, t, end, &same);
        if (same && bp__fan_agrees(atlas, base, t, end)) bp__out_fan(&o, mesh, atlas, base, t, end, rev);
        else for (j = t; j < end; j++) bp__out_fan(&o, mesh, atlas, base, j, j + 1, flip && flip[j]);   /* one line each */
        for (; t < end; t++) bp__out_tick(&o, t + 1, mesh->num_triangles);
    }
    bp__free(&a, flip);
    bp__free(&a, base);
    return bp__out_close(&o, path, BP_OK, err);
}

BPDEF bp_status bp_write_obj(const char *path, const bp_mesh *mesh,
                             const bp_atlas *atlas, bp_error *err)
{
    return bp__write_obj(path, mesh, atlas, NULL, err);
}

/* bp_write_obj_from: the state of one pass over the source text. */
typedef struct bp__src_corner {
    bp__corner_text text;
    const char *pre;          /* the spacing before the corner             */
    uint32_t    v, vt;        /* 0-based vertex; new vt (BP__NONE: none)   */
    int         vt_set;
} bp__src_corner;

typedef struct bp__rewriter {
    bp__parser      ps;       /* cursor in the source text                 */
    bp__out        *o;
    const bp_mesh  *mesh;
    const bp_atlas *atlas;
    const uint32_t *base;     /* bp__vt_base                               */
    const unsigned char *flip; /* bp__face_flips, or NULL                  */
    const char     *eol;      /* line ending of the vt lines: the file's own */
    int64_t         nv, nvt;  /* v and vt lines passed so far              */
    uint32_t        t;        /* mesh triangle of the next face            */
    int             vt_done;  /* the new vt are written                    */
    bp__vec         corners;  /* bp__src_corner of the current face        */
} bp__rewriter;

/* The line ending the file uses first: "\r\n", "\r" or "\n" (default). */
static const char *bp__eol_of(const char *p, const char *end)
{
    for (; p < end; p++) {
        if (*p == '\n') return "\n";
        if (*p == '\r') return p + 1 < end && p[1] == '\n' ? "\r\n" : "\r";
    }
    return "\n";
}

/* One corner as written, with its new vt. */
static void bp__out_corner(bp__out *o, const bp__src_corner *c, uint32_t vt)
{
    bp__out_bytes(o, c->text.v, (size_t)(c->text.v_end - c->text.v));
    if (vt != BP__NONE) {
        bp__out_str(o, "/");
        bp__out_uint(o, (uint64_t)vt + 1);
    }
    if (c->text.vn) {
        bp__out_str(o, vt != BP__NONE ? "/" : "//");
        bp__out_bytes(o, c->text.vn, (size_t)(c->text.vn_end - c->text.vn));
    }
}

/* The corners of the `f` line at the cursor, with the spacing before
   each; *tail gets where the spacing after the last one starts. */
static bp_status bp__rewrite_read_corners(bp__rewriter *r, const char **tail)
{
    bp__parser *ps = &r->ps;
    bp_status st;
    r->corners.count = 0;
    for (;;) {
        bp__src_corner c;
        int64_t v, vt;
        memset(&c, 0, sizeof c);
        c.pre = ps->p;
        if (bp__at_eol(ps)) { *tail = c.pre; return BP_OK; }
        if ((st = bp__obj_corner(ps, r->nv, r->nvt, &v, &vt, &c.text)) != BP_OK) return st;
        c.v = v < 0xffffffffLL ? (uint32_t)v : BP__NONE;
        if (!bp__vec_push(ps->a, &r->corners, &c)) return bp__oom(ps->err, "writing the OBJ file");
    }
}

/* Check that the n corners are mesh triangles t .. t+n-3 (fan order, one
   source face) and give each corner its new vt; *agree = 0 when the fan
   triangles give one corner two different vt (see the essay). */
static bp_status bp__rewrite_match(bp__rewriter *r, int *agree)
{
    const bp_mesh *m = r->mesh;
    bp__src_corner *c = (bp__src_corner *)r->corners.data;
    size_t n = r->corners.count, j;
    uint32_t t = r->t;
    *agree = 1;
    if (n < 3)
        return bp__fail(r->ps.err, BP_ERR_POLYGON, BP_ELEMENT_LINE, r->ps.line, -1, r->ps.line,
                        "line %D: a face needs at least 3 corners, this one has %u", r->ps.line, (unsigned)n);
    if ((uint64_t)t + n - 2 > m->num_triangles)
        return bp__fail(r->ps.err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_LINE, r->ps.line, -1, r->ps.line,
                        "line %D: the file has more faces than the mesh has triangles (%u); "
                        "was the mesh read from this file?", r->ps.line, m->num_triangles);
    for (j = 0; j + 2 < n; j++) {
        uint32_t tt = t + (uint32_t)j, pc[3];
        int k;
        pc[0] = 0; pc[1] = (uint32_t)j + 1; pc[2] = (uint32_t)j + 2;
        for (k = 0; k < 3; k++) {
            uint32_t vt = bp__corner_vt(r->atlas, r->base, tt, k);
            bp__src_corner *cc = &c[pc[k]];
            if (m->triangles[3 * (size_t)tt + k] != cc->v ||
                (m->triangle_face && m->triangle_face[tt] != m->triangle_face[t]))
                return bp__fail(r->ps.err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_LINE, r->ps.line, -1, r->ps.line,
                                "line %D: the face does not match triangle %u of the mesh (vertices %u %u %u); "
                                "was the mesh read from this file?", r->ps.line, tt + 1,
                                m->triangles[3 * (size_t)tt] + 1, m->triangles[3 * (size_t)tt + 1] + 1,
                                m->triangles[3 * (size_t)tt + 2] + 1);
            if (!cc->vt_set) { cc->vt = vt; cc->vt_set = 1; }
            else if (cc->vt != vt) *agree = 0;
        }
    }
    if (m->triangle_face && t + n - 2 < m->num_triangles && m->triangle_face[t + n - 2] == m->triangle_face[t])
        return bp__fail(r->ps.err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_LINE, r->ps.line, -1, r->ps.line,
                        "line %D: the face has fewer corners than its polygon in the mesh; "
                        "was the mesh read from this file?", r->ps.line);
    return BP_OK;
}

/* One `f` line: `line` is its start, the cursor is after the keyword. */
static bp_status bp__rewrite_face(bp__rewriter *r, const char *line)
{
    bp__parser *ps = &r->ps;
    bp__src_corner *c;
    const char *tail = NULL, *term;
    size_t n, j, k;
    int agree, same, rev;
    bp_status st;
    if ((st = bp__rewrite_read_corners(r, &tail)) != BP_OK) return st;
    if ((st = bp__rewrite_match(r, &agree)) != BP_OK) return st;
    c = (bp__src_corner *)r->corners.data;
    n = r->corners.count;
    rev = bp__fan_flip(r->flip, r->t, r->t + (uint32_t)(n - 2), &same);
    bp__next_line(ps);                            /* [tail, ps->p): the rest */
    for (term = tail; term < ps->p && !bp__is_eol(*term); term++) {}
    if (agree && same) {                          /* re-oriented: the corners
                                                     move, the spacing stays */
        bp__out_bytes(r->o, line, (size_t)(c[0].pre - line));
        for (k = 0; k < n; k++) {
            size_t pk = rev && k ? n - k : k;
            bp__out_bytes(r->o, c[k].pre, (size_t)(c[k].text.v - c[k].pre));
            bp__out_corner(r->o, &c[pk], c[pk].vt);
        }
    } else {
        for (j = 0; j + 2 < n; j++) {             /* one line per fan triangle */
            int fl = r->flip && r->flip[r->t + (uint32_t)j];
            if (j && term < ps->p) bp__out_bytes(r->o, term, (size_t)(ps->p - term));
            else if (j) bp__out_str(r->o, r->eol);    /* the last line had none */
            bp__out_str(r->o, "f");
            for (k = 0; k < 3; k++) {
                size_t kk = fl && k ? 3 - k : k, pc = kk == 0 ? 0 : j + kk;
                bp__out_str(r->o, " ");
                bp__out_corner(r->o, &c[pc], bp__corner_vt(r->atlas, r->base, r->t + (uint32_t)j, (int)kk));
            }
        }
    }
    bp__out_bytes(r->o, tail, (size_t)(ps->p - tail));
    if ((r->t >> 12) != ((r->t + (uint32_t)(n - 2)) >> 12))     /* crossed a multiple of 4096 */
        bp__out_tick(r->o, ((r->t + (uint32_t)(n - 2)) >> 12) << 12, r->mesh->num_triangles);
    r->t += (uint32_t)(n - 2);
    return BP_OK;
}

/* One line: copied, dropped or rewritten. */
static bp_status bp__rewrite_line(bp__rewriter *r)
{
    bp__parser *ps = &r->ps;
    const char *line = ps->p;
    int is_vt, is_f;
    bp__skip_space(ps);
    is_vt = bp__keyword(ps, "vt");
    is_f = !is_vt && bp__keyword(ps, "f");
    if ((is_vt || is_f) && !r->vt_done) {
        bp__out_vt_block(r->o, r->atlas, r->base, r->eol);
        r->vt_done = 1;
    }
    if (is_f) return bp__rewrite_face(r, line);
    if (is_vt) r->nvt++;
    else if (bp__keyword(ps, "v")) r->nv++;
    bp__next_line(ps);
    if (!is_vt) bp__out_bytes(r->o, line, (size_t)(ps->p - line));
    return BP_OK;
}

/* ---- the rewrite on several threads --------------------------------------

   After the new vt block (written by the serial pass at the first vt or f
   line) each line's output depends only on the line itself and on three
   running counts: the v and vt lines before it (a relative index keeps
   its text, but bp__obj_corner checks it against them) and the mesh
   triangles before it (which triangles a face must match).  So the rest
   of the text is cut into chunks at line starts as the reader cuts it
   (bp__obj_chunks), counted in parallel (bp__obj_count_run: lines, v, vt,
   fan triangles), and rewritten in parallel, a round of BP__OUT_TASKS
   chunks at a time, each into its own slice of 3 BP__READ_CHUNK + 1 KiB
   bytes; the caller appends the slices in file order.  A task stops
   before a line that does not fit its slice, or that has more corners
   than BP__READ_CORNERS, and the caller rewrites the rest of that chunk
   itself.  A task that meets an error keeps it, and the first in file
   order is the serial writer's error, since every chunk before it was
   rewritten from exact counts.  Tasks never allocate and never call the
   progress callback; the caller reports as it appends. */
typedef struct bp__rw_chunk {
    const char *resume;        /* where the caller takes over, or NULL      */
    int64_t     line, nv, nvt; /* the counts there                          */
    uint32_t    t;
    size_t      len;           /* bytes in the slice                        */
    bp_status   st;
    bp_error    err;
} bp__rw_chunk;

typedef struct bp__rw_par {
    const bp__rewriter *r;     /* the serial writer (tables, counts before) */
    bp__obj_par    cnt;        /* the chunks and their counts               */
    bp__rw_chunk  *rc;         /* one per chunk of the round                */
    char          *scratch;    /* slice j of the round at j * slice         */
    size_t         slice;
    bp__src_corner *corners;   /* BP__READ_CORNERS per slice                */
    uint32_t       first;      /* the round's first chunk                   */
    int64_t        line0, nv0, nvt0;   /* the counts where the chunks begin */
    uint32_t       t0;
} bp__rw_par;

/* Chunk first + j into slice j. */
static void bp__rw_run(void *task, uint32_t j)
{
    bp__rw_par *W = (bp__rw_par *)task;
    const bp__obj_chunk *c = W->cnt.ch + W->first + j;
    bp__rw_chunk *rc = W->rc + j;
    bp__rewriter r = *W->r;
    bp__out o;
    bp_allocator none;
    none.alloc = bp__no_alloc;
    none.free = bp__no_free;
    none.user = NULL;
    memset(&o, 0, sizeof o);
    o.ok = 1;
    o.buf = W->scratch + (size_t)j * W->slice;
    o.cap = W->slice;
    o.par = bp__par_serial();
    r.o = &o;
    r.ps.p = r.ps.begin = c->begin;
    r.ps.end = c->end;
    r.ps.line = W->line0 + c->line0;
    r.ps.a = &none;
    r.ps.err = &rc->err;
    r.nv = W->nv0 + c->nv0;
    r.nvt = W->nvt0 + c->nvt0;
    r.t = W->t0 + (uint32_t)c->tri0;
    r.corners.data = W->corners + (size_t)j * BP__READ_CORNERS;
    r.corners.count = 0;
    r.corners.cap = BP__READ_CORNERS;
    rc->resume = NULL;
    rc->st = BP_OK;
    while (r.ps.p < r.ps.end) {
        const char *p = r.ps.p;
        int64_t line = r.ps.line, nv = r.nv, nvt = r.nvt;
        uint32_t t = r.t;
        size_t len = o.len;
        bp_status st = bp__rewrite_line(&r);
        if (st == BP_OK && o.ok) continue;
        if (o.full || st == BP_ERR_OUT_OF_MEMORY) {        /* the caller goes on */
            rc->resume = p; rc->line = line; rc->nv = nv; rc->nvt = nvt; rc->t = t;
            o.len = len;
        } else
            rc->st = st;
        break;
    }
    rc->len = o.len;
}

/* The rest of the text from the cursor (the vt block written) on the
   writer's threads (fewer than two chunks: the serial pass goes on). */
static bp_status bp__rewrite_par(bp__rewriter *r)
{
    bp__parser *ps = &r->ps;
    const bp_allocator *a = ps->a;
    const char *text_end = ps->end;
    const bp__par *par = &r->o->par;
    bp__rw_par W;
    uint32_t n = 0, k, j, m, nround;
    int64_t line = 0, nv = 0, nvt = 0, tris = 0;
    bp_status st = BP_OK;
    memset(&W, 0, sizeof W);
    if (!(W.cnt.ch = bp__obj_chunks(ps, &n))) return bp__oom(ps->err, "writing the OBJ file");
    if (n < 2) { bp__free(a, W.cnt.ch); return BP_OK; }
    nround = n < BP__OUT_TASKS ? n : BP__OUT_TASKS;
    W.r = r;
    W.line0 = ps->line; W.nv0 = r->nv; W.nvt0 = r->nvt; W.t0 = r->t;
    W.slice = 3 * (size_t)BP__READ_CHUNK + 1024;
    W.rc = (bp__rw_chunk *)bp__alloc_array(a, nround, sizeof *W.rc);
    W.scratch = (char *)bp__alloc_array(a, nround, W.slice);
    W.corners = (bp__src_corner *)bp__alloc_array(a, (size_t)nround * BP__READ_CORNERS, sizeof *W.corners);
    if (W.rc && W.scratch && W.corners) {
        par->run(par->user, bp__obj_count_run, &W.cnt, n);
        for (k = 0; k < n; k++) {                 /* counts before each chunk */
            bp__obj_chunk *c = W.cnt.ch + k;
            c->line0 = line; c->nv0 = nv; c->nvt0 = nvt; c->tri0 = tris;
            line += c->lines; nv += c->nv; nvt += c->nvt; tris += c->tris;
        }
        if ((uint64_t)r->t + (uint64_t)tris > r->mesh->num_triangles) n = 0;   /* the serial pass says where */
    } else {
        n = 0;
        st = bp__oom(ps->err, "writing the OBJ file");
    }
    for (W.first = 0; W.first < n && st == BP_OK && r->o->ok; W.first += m) {
        m = n - W.first < nround ? n - W.first : nround;
        par->run(par->user, bp__rw_run, &W, m);
        for (j = 0; j < m && st == BP_OK && r->o->ok; j++) {
            const bp__obj_chunk *c = W.cnt.ch + W.first + j;
            const bp__rw_chunk *rc = W.rc + j;
            uint32_t t0 = r->t;
            bp__out_bytes(r->o, W.scratch + (size_t)j * W.slice, rc->len);
            if (rc->st != BP_OK) {
                if (ps->err) *ps->err = rc->err;
                st = rc->st;
                break;
            }
            if (rc->resume) {
                ps->p = rc->resume; ps->line = rc->line; r->nv = rc->nv; r->nvt = rc->nvt; r->t = rc->t;
                ps->end = c->end;
                while (ps->p < ps->end && st == BP_OK && r->o->ok) st = bp__rewrite_line(r);
                ps->end = text_end;
            } else {
                ps->line += c->lines;
                r->nv += c->nv;
                r->nvt += c->nvt;
                r->t += (uint32_t)c->tris;
            }
            ps->p = c->end;
            if ((t0 >> 12) != (r->t >> 12)) bp__out_tick(r->o, (r->t >> 12) << 12, r->mesh->num_triangles);
        }
    }
    bp__free(a, W.cnt.ch);
    bp__free(a, W.rc);
    bp__free(a, W.scratch);
    bp__free(a, W.corners);
    return st;
}

/* The pass: copy, drop or rewrite each line; after the new vt block, on
   the writer's threads when it has them (above). */
static bp_status bp__rewrite_obj(bp__rewriter *r)
{
    bp__parser *ps = &r->ps;
    bp_status st = BP_OK;
    while (ps->p < ps->end && st == BP_OK && r->o->ok && !r->vt_done) st = bp__rewrite_line(r);
    if (st == BP_OK && r->o->ok && ps->p < ps->end && r->o->par.run != bp__serial_for)
        st = bp__rewrite_par(r);
    while (ps->p < ps->end && st == BP_OK && r->o->ok) st = bp__rewrite_line(r);
    if (st == BP_OK && r->o->ok && r->t != r->mesh->num_triangles)
        st = bp__fail(ps->err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                      "the file's faces make %u triangles, the mesh has %u; was the mesh read from this file?",
                      r->t, r->mesh->num_triangles);
    return st;
}

static bp_status bp__write_obj_from(const char *path, const char *source, const bp_mesh *mesh,
                                    const bp_atlas *atlas, const bp_options *opt, bp_error *err)
{
    bp__rewriter r;
    bp__out o;
    bp_allocator a;
    char *text = NULL;
    size_t len = 0;
    uint32_t *base;
    unsigned char *flip = NULL;
    bp_status st;
    if (!path || !source || !mesh || !atlas || atlas->num_corners != 3 * mesh->num_triangles)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_write_obj_from needs two paths, the mesh and the atlas built from it");
    if (!strcmp(path, source))
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "'%s' is the source file: write to another path", path);
    a = atlas->allocator;
    if ((st = bp__load_file(source, &a, &text, &len, err, NULL)) != BP_OK) return st;
    if (!(base = bp__vt_base(atlas, &a))) { bp__free(&a, text); return bp__oom(err, "writing the OBJ file"); }
    if (bp__face_flips(atlas, mesh, &a, &flip) != BP_OK) {
        bp__free(&a, base); bp__free(&a, text);
        return bp__oom(err, "writing the OBJ file");
    }
    if ((st = bp__out_open(&o, path, &a, err)) == BP_OK) {
        o.opt = opt;
        bp__out_threads(&o, opt, base[atlas->num_charts] + len / 64);   /* a line: ~64 bytes */
        memset(&r, 0, sizeof r);
        r.ps.p = text;
        r.ps.end = text + len;
        r.ps.line = 1;
        r.ps.a = &a;
        r.ps.err = err;
        r.o = &o;
        r.mesh = mesh;
        r.atlas = atlas;
        r.base = base;
        r.flip = flip;
        r.eol = bp__eol_of(text, text + len);
        r.corners.elem = sizeof(bp__src_corner);
        st = bp__rewrite_obj(&r);
        bp__free(&a, r.corners.data);
        st = bp__out_close(&o, path, st, err);
    }
    bp__free(&a, flip);
    bp__free(&a, base);
    bp__free(&a, text);
    return st;
}

BPDEF bp_status bp_write_obj_from(const char *path, const char *source, const bp_mesh *mesh,
                                  const bp_atlas *atlas, bp_error *err)
{
    return bp__write_obj_from(path, source, mesh, atlas, NULL, err);
}

BPDEF bp_status bp_write_obj_opt(const char *path, const char *source, const bp_mesh *mesh,
                                 const bp_atlas *atlas, const bp_options *opt, bp_error *err)
{
    bp_options o;
    bp_status st;
    if ((opt = bp__opts(opt, &o, err, &st)), st != BP_OK) return st;
    if (opt && opt->run_progress && bp__report(opt, BP_STAGE_WRITE, 0, BP_NO_CHART))
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled before writing");
    return source ? bp__write_obj_from(path, source, mesh, atlas, opt, err)
                  : bp__write_obj(path, mesh, atlas, opt, err);
}
#endif /* BP_NO_STDIO */

/* >>charts =================================================================

   A chart is a piece of surface that will be flattened in one piece.  Two
   triangles are glued into the same chart when they share a mesh edge and,
   if the mesh has per-corner uv indices, use the same uv index at both ends
   of it; otherwise the edge is a seam (sec 3.1: "the input is a triangulated
   surface with an initially prescribed seam").

   The same gluing decides the chart *vertices*.  Every triangle corner
   starts as its own vertex; gluing two triangles along edge (a, b) merges
   their corners at a and at b.  A corner meets exactly two edges of its
   triangle, so the merged corners around a mesh vertex form a fan, and:
     - an interior vertex becomes one chart vertex (a closed fan),
     - a boundary vertex one chart vertex per open fan.
   The second rule is the pinch repair: a vertex where the chart boundary
   touches itself (two fans, as in spot.obj after cutting) is split, and
   every chart is a manifold surface with boundary.

   Then the topology is checked.  With V, E, F the chart's vertices, edges
   and triangles and b its boundary loops, the Euler characteristic is
       chi = V - E + F = 2 - 2g - b,
   and only g = 0, b >= 1 (a disk, or a disk with b-1 holes, sec 3.6) can be
   flattened without further cuts; other charts are cut into disks by >>cut
   (or, with opt.cut = BP_CUT_NONE, reported failed).  Boundary loops are walked along the
   boundary edges in the triangles' orientation, so the interior lies to the
   left: the outer loop (the longest in 3D, sec 3.6) runs counter-clockwise
   in a valid map, holes clockwise. */

static uint32_t bp__uf_find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];     /* path halving */
        x = parent[x];
    }
    return x;
}

static void bp__uf_union(uint32_t *parent, uint32_t x, uint32_t y)
{
    x = bp__uf_find(parent, x);
    y = bp__uf_find(parent, y);
    if (x == y) return;
    if (x < y) parent[y] = x; else parent[x] = y;  /* smallest index is the root */
}

typedef struct bp__edge_rec {
    uint32_t lo, hi;   /* mesh vertices, lo < hi                           */
    uint32_t ce;       /* corner edge 3*t+i: from corner i to corner i+1    */
} bp__edge_rec;

static int bp__edge_cmp(const void *pa, const void *pb)
{
    const bp__edge_rec *a = (const bp__edge_rec *)pa, *b = (const bp__edge_rec *)pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->ce < b->ce ? -1 : a->ce > b->ce;
}

typedef struct bp__tri_key { uint32_t v[3], t; } bp__tri_key;

static int bp__tri_key_cmp(const void *pa, const void *pb)
{
    const bp__tri_key *a = (const bp__tri_key *)pa, *b = (const bp__tri_key *)pb;
    int i;
    for (i = 0; i < 3; i++)
        if (a->v[i] != b->v[i]) return a->v[i] < b->v[i] ? -1 : 1;
    return a->t < b->t ? -1 : a->t > b->t;
}

typedef struct bp__vkey { uint32_t chart, v, uv; } bp__vkey;

static int bp__vkey_cmp(const void *pa, const void *pb)
{
    const bp__vkey *a = (const bp__vkey *)pa, *b = (const bp__vkey *)pb;
    if (a->chart != b->chart) return a->chart < b->chart ? -1 : 1;
    if (a->v != b->v) return a->v < b->v ? -1 : 1;
    return a->uv < b->uv ? -1 : a->uv > b->uv;
}

static const double *bp__pos(const bp_mesh *m, uint32_t v) { return m->positions + 3 * (size_t)v; }

static double bp__dist3(const double *a, const double *b)
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* Twice the area of a 3D triangle, |(b-a) x (c-a)|. */
static double bp__area2_3d(const double *a, const double *b, const double *c)
{
    double u[3], v[3], n[3];
    int k;
    for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = c[k] - a[k]; }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* The file line of triangle t, or 0 when the mesh does not record it. */
static int64_t bp__tri_line(const bp_mesh *m, uint32_t t)
{
    return m->triangle_line ? (int64_t)m->triangle_line[t] : 0;
}

/* Messages name mesh elements the way the user's file numbers them: from 1
   (bp_error.index stays 0-based, see CONVENTIONS).  Triangle t is "triangle
   t+1"; when the reader split polygons into fans it is named by its source
   face, "face f+1"; the file line follows when the mesh records it:
   "triangle 29 (line 31)".  buf holds at least 48 characters. */
static const char *bp__tri_name(const bp_mesh *m, uint32_t t, char *buf)
{
    int face = m->triangle_face && m->num_faces != m->num_triangles;
    uint32_t n = (face ? m->triangle_face[t] : t) + 1;
    if (m->triangle_line) bp__format(buf, 48, "%s %u (line %u)", face ? "face" : "triangle", n, m->triangle_line[t]);
    else bp__format(buf, 48, "%s %u", face ? "face" : "triangle", n);
    return buf;
}

static void bp__chart_free(const bp_allocator *a, bp_chart *c)
{
    bp__free(a, c->vertex); bp__free(a, c->vertex_uv); bp__free(a, c->triangles);
    bp__free(a, c->face); bp__free(a, c->loop_start); bp__free(a, c->loop_vertices);
    bp__free(a, c->uv); bp__free(a, c->rest_side); bp__free(a, c->start_order);
    memset(c, 0, sizeof *c);
}

BPDEF void bp_atlas_free(bp_atlas *atlas)
{
    uint32_t c;
    bp_allocator a;
    if (!atlas) return;
    a = atlas->allocator;
    if (atlas->charts)
        for (c = 0; c < atlas->num_charts; c++) bp__chart_free(&a, &atlas->charts[c]);
    bp__free(&a, atlas->charts);
    bp__free(&a, atlas->corner_chart);
    bp__free(&a, atlas->corner_vertex);
    memset(atlas, 0, sizeof *atlas);
}

/* --- mesh validation -----------------------------------------------------

   Two kinds of defect, told apart by what they break.
     Global: no triangles, too many, a vertex or uv index out of range, a
       used vertex with a NaN or infinite coordinate.  Nothing can be built
       on such a mesh (the adjacency itself would read out of bounds, the
       size scale is undefined), so they fail the whole call.
     Mendable: the defects that decide what the charts *are* -- two
       triangles on the same three vertices, an edge shared by three or
       more triangles, neighbours of opposite orientation (found while
       gluing, below) -- and the local ones, a triangle that repeats a
       vertex or whose 3D area is zero or near zero (its rest shape, eq
       3.1, has no inverse).  By default they are repaired ("repair",
       below) and reported in atlas.repairs; with opt.strict the first one
       fails the whole call, naming the element.

   "Near zero" is relative and therefore scale-free: twice the area below
   1e-12 diag^2, diag the bounding-box diagonal of the used vertices.  To
   keep it so at every representable scale (products of coordinates near
   1e300 overflow, near 1e-300 underflow) the test runs on coordinates
   rescaled by powers of two, which are exact: p is divided by 2^e1, the
   power of two just above max |p| (so |p| / 2^e1 < 1 and differences
   cannot overflow), and differences then by 2^e2, the power just above the
   rescaled extent.  A mesh scaled by a power of two is judged bit for bit
   as the unscaled one; any other factor only rounds the input. */

typedef struct bp__mesh_scale {
    int e1, e2;
    double diag2;
    double s1, s2;   /* 2^-e1 and 2^-e2 when both are doubles, else 0 (below) */
} bp__mesh_scale;

/* The checks of one triangle t: its vertex and uv indices, then its
   vertices' coordinates, whose box lo / hi it widens.  The first failure
   is the error (the order of the serial loop below). */
static bp_status bp__validate_tri(const bp_mesh *m, uint32_t t, double *lo, double *hi, bp_error *err)
{
    const uint32_t *tri = m->triangles + 3 * (size_t)t;
    uint32_t k;
    char nm[48];
    for (k = 0; k < 3; k++) {
        if (tri[k] >= m->num_vertices)
            return bp__fail(err, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, t, -1, bp__tri_line(m, t),
                            "%s: vertex %u is out of range (the mesh has %u vertices, numbered from 1)",
                            bp__tri_name(m, t, nm), tri[k] + 1, m->num_vertices);
        if (m->corner_uv && m->corner_uv[3 * (size_t)t + k] >= m->num_uvs)
            return bp__fail(err, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, t, -1, bp__tri_line(m, t),
                            "%s: uv %u is out of range (the mesh has %u uvs, numbered from 1)",
                            bp__tri_name(m, t, nm), m->corner_uv[3 * (size_t)t + k] + 1, m->num_uvs);
    }
    for (k = 0; k < 3; k++) {
        const double *p = bp__pos(m, tri[k]);
        int j;
        for (j = 0; j < 3; j++) {
            if (!(p[j] - p[j] == 0))
                return bp__fail(err, BP_ERR_NONFINITE, BP_ELEMENT_VERTEX, tri[k], -1, bp__tri_line(m, t),
                                "vertex %u (used by %s) has a coordinate that is NaN or infinite",
                                tri[k] + 1, bp__tri_name(m, t, nm));
            if (p[j] < lo[j]) lo[j] = p[j];
            if (p[j] > hi[j]) hi[j] = p[j];
        }
    }
    return BP_OK;
}

/* The checks of the whole mesh before its triangles. */
static bp_status bp__validate_sizes(const bp_mesh *m, bp_error *err)
{
    if (!m || !m->positions || !m->triangles)
        return bp__fail(err, m && m->num_triangles == 0 ? BP_ERR_EMPTY : BP_ERR_INVALID_ARGUMENT,
                        BP_ELEMENT_NONE, -1, -1, 0, "the mesh has no vertex or triangle array");
    if (m->num_triangles == 0 || m->num_vertices == 0)
        return bp__fail(err, BP_ERR_EMPTY, BP_ELEMENT_NONE, -1, -1, 0, "the mesh has no triangles");
    if (m->num_triangles > 0x55555554u)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "too many triangles (%u): at most 1431655764", m->num_triangles);
    return BP_OK;
}

/* The exponents and the squared diagonal from the box of the used vertices. */
static void bp__scale_of_box(const double *lo, const double *hi, bp__mesh_scale *sc)
{
    double big = 0, ext = 0;
    int k;
    for (k = 0; k < 3; k++) {
        if (fabs(lo[k]) > big) big = fabs(lo[k]);
        if (fabs(hi[k]) > big) big = fabs(hi[k]);
    }
    (void)frexp(big, &sc->e1);                    /* big < 2^e1 (e1 = 0 for 0) */
    for (k = 0; k < 3; k++) {
        double d = ldexp(hi[k], -sc->e1) - ldexp(lo[k], -sc->e1);  /* <= 2: no overflow */
        if (d > ext) ext = d;
    }
    (void)frexp(ext, &sc->e2);
    sc->diag2 = 0;
    for (k = 0; k < 3; k++) {
        double d = ldexp(ldexp(hi[k], -sc->e1) - ldexp(lo[k], -sc->e1), -sc->e2);
        sc->diag2 += d * d;
    }
    sc->s1 = sc->e1 >= -1023 && sc->e1 <= 1074 ? ldexp(1.0, -sc->e1) : 0;
    sc->s2 = sc->e2 >= -1023 && sc->e2 <= 1074 ? ldexp(1.0, -sc->e2) : 0;
}

/* Global checks (above), and the exponents of the used vertices. */
static bp_status bp__validate_global(const bp_mesh *m, bp__mesh_scale *sc, bp_error *err)
{
    uint32_t t;
    double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
    bp_status st = bp__validate_sizes(m, err);
    if (st != BP_OK) return st;
    for (t = 0; t < m->num_triangles; t++)
        if ((st = bp__validate_tri(m, t, lo, hi, err)) != BP_OK) return st;
    bp__scale_of_box(lo, hi, sc);
    return BP_OK;
}

/* b - a in the rescaled units of bp__mesh_scale: ldexp(ldexp(b, -e1) -
   ldexp(a, -e1), -e2).  A product by a power of two 2^s that is itself a
   double (s in [-1074, 1023]) is x 2^s rounded once, exactly what ldexp
   gives, so the products give the same bits at a fraction of the cost
   (ldexp was a fifth of bp_atlas_build's time, docs/performance.md 6.18);
   ldexp stays for scales beyond that range. */
static void bp__scaled_diff(const double *a, const double *b, const bp__mesh_scale *sc, double *d)
{
    int k;
    if (sc->s1 != 0 && sc->s2 != 0)
        for (k = 0; k < 3; k++) d[k] = (b[k] * sc->s1 - a[k] * sc->s1) * sc->s2;
    else
        for (k = 0; k < 3; k++) d[k] = ldexp(ldexp(b[k], -sc->e1) - ldexp(a[k], -sc->e1), -sc->e2);
}

/* Twice the area of triangle t in the rescaled units. */
static double bp__area2_scaled(const bp_mesh *m, uint32_t t, const bp__mesh_scale *sc)
{
    const uint32_t *tri = m->triangles + 3 * (size_t)t;
    double u[3], v[3], n[3];
    bp__scaled_diff(bp__pos(m, tri[0]), bp__pos(m, tri[1]), sc, u);
    bp__scaled_diff(bp__pos(m, tri[0]), bp__pos(m, tri[2]), sc, v);
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

/* The local defect of triangle t: 0 (none), 1 a repeated vertex, 2 (near)
   zero area. */
static int bp__tri_defect(const bp_mesh *m, uint32_t t, const bp__mesh_scale *sc)
{
    const uint32_t *tri = m->triangles + 3 * (size_t)t;
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) return 1;
    return bp__area2_scaled(m, t, sc) > 1e-12 * sc->diag2 ? 0 : 2;
}

static bp_status bp__tri_defect_error(const bp_mesh *m, uint32_t t, const bp__mesh_scale *sc, bp_error *err)
{
    const uint32_t *tri = m->triangles + 3 * (size_t)t;
    char nm[48];
    if (bp__tri_defect(m, t, sc) == 1)
        return bp__fail(err, BP_ERR_DEGENERATE, BP_ELEMENT_TRIANGLE, t, -1, bp__tri_line(m, t),
                        "%s, vertices %u %u %u, uses vertex %u twice", bp__tri_name(m, t, nm), tri[0] + 1,
                        tri[1] + 1, tri[2] + 1, (tri[0] == tri[1] || tri[0] == tri[2] ? tri[0] : tri[1]) + 1);
    return bp__fail(err, BP_ERR_DEGENERATE, BP_ELEMENT_TRIANGLE, t, -1, bp__tri_line(m, t),
                    "%s, vertices %u %u %u, has zero or near-zero area: twice its area is %g of the "
                    "squared mesh size (at most 1e-12 is degenerate)", bp__tri_name(m, t, nm), tri[0] + 1,
                    tri[1] + 1, tri[2] + 1, bp__area2_scaled(m, t, sc) / sc->diag2);
}

/* The local defects: with bad == NULL the first one is an error (strict);
   otherwise bad[t] is set to the defect of each triangle. */
static bp_status bp__find_defects(const bp_mesh *m, const bp__mesh_scale *sc, unsigned char *bad, bp_error *err)
{
    uint32_t t;
    for (t = 0; t < m->num_triangles; t++) {
        int d = bp__tri_defect(m, t, sc);
        if (d && !bad) return bp__tri_defect_error(m, t, sc, err);
        if (bad) bad[t] = (unsigned char)d;
    }
    return BP_OK;
}

/* The whole validation with every defect an error (bp_visibility). */
static bp_status bp__validate_mesh(const bp_mesh *m, bp_error *err)
{
    bp__mesh_scale sc;
    bp_status st = bp__validate_global(m, &sc, err);
    return st != BP_OK ? st : bp__find_defects(m, &sc, NULL, err);
}

#define BP__BUILD_TASKS 64u       /* at most, per pass (below)              */

/* Working arrays of bp_atlas_build, freed together. */
typedef struct bp__build {
    bp__edge_rec *edges;
    bp__tri_key  *keys;
    uint32_t *tri_uf, *corner_uf, *glued, *chart_of_root;
    uint32_t *vert_of_root;       /* = mate, once the gluing is done         */
    uint32_t *next, *loop_id;
    bp__vkey *vkeys;
    unsigned char *bad;           /* triangle kept out of the gluing: strict
                                     mode never has one; repair: a repeated
                                     vertex (it becomes a chart of its own) */
    /* repair (not strict), see "repair" below */
    int repair;
    unsigned char *degen;         /* local defect of each triangle (0: none) */
    unsigned char *drop;          /* duplicate copy, left out of the charts  */
    unsigned char *flip;          /* re-oriented: corners 1 and 2 swapped    */
    uint32_t *twin;               /* the triangle a dropped copy repeats     */
    uint32_t *mate;               /* mesh corner edge across a manifold edge,
                                     BP__NONE, or BP__CUT                     */
    uint32_t *queue;
    uint32_t *fixed_tri, *fixed_uv;
    bp_mesh fm;                   /* the mesh as glued: flipped triangles
                                     with their corners 1 and 2 swapped      */
    bp_repair_report *rep;
    bp__mesh_scale scale;
    /* the tasks (below, "the build on several threads") */
    const bp_mesh *m;             /* the user's mesh                         */
    bp_atlas *atlas;              /* the atlas being built (bp__fill_task)   */
    bp__par par;
    uint32_t *estart;             /* nv + 2: the edge records whose smaller
                                     vertex is v are edges[estart[v],
                                     estart[v + 1])                          */
    double *area;                 /* nt: half of each triangle's 3D area     */
    uint32_t nchunk;              /* chunks of the current pass              */
    uint32_t first[BP__BUILD_TASKS];     /* per chunk: its first failing item */
    double box[6 * BP__BUILD_TASKS];     /* per chunk: its box, lo then hi    */
} bp__build;

#define BP__CUT (BP__NONE - 1u)

static void bp__repair_note(bp_repair_report *r, bp_repair_kind k, int64_t a, int64_t b2);

static void bp__build_free(const bp_allocator *a, bp__build *b)
{
    bp__free(a, b->edges); bp__free(a, b->keys); bp__free(a, b->tri_uf);
    bp__free(a, b->corner_uf); bp__free(a, b->glued); bp__free(a, b->chart_of_root);
    bp__free(a, b->next); bp__free(a, b->loop_id);
    bp__free(a, b->vkeys); bp__free(a, b->bad);
    bp__free(a, b->degen); bp__free(a, b->drop); bp__free(a, b->flip); bp__free(a, b->twin);
    bp__free(a, b->mate); bp__free(a, b->queue); bp__free(a, b->fixed_tri); bp__free(a, b->fixed_uv);
    bp__free(a, b->estart); bp__free(a, b->area);
}

/* Boundary loops of one chart from its triangles: next[v] is the end of the
   boundary edge leaving v (BP__NONE for interior vertices). */
static bp_status bp__chart_loops(const bp_allocator *a, bp_chart *ch, const bp_mesh *m,
                                 uint32_t *next, uint32_t *loop_id, const uint32_t *glued_ce,
                                 uint32_t chart_index, bp_error *err)
{
    uint32_t t, k, v, nb = 0, nloops = 0, pos = 0;
    double best = -1;
    uint32_t best_loop = 0;
    for (v = 0; v < ch->num_vertices; v++) { next[v] = BP__NONE; loop_id[v] = BP__NONE; }
    for (t = 0; t < ch->num_triangles; t++)
        for (k = 0; k < 3; k++)
            if (glued_ce[3 * (size_t)ch->face[t] + k] == BP__NONE) {
                uint32_t va = ch->triangles[3 * t + k], vb = ch->triangles[3 * t + (k + 1) % 3];
                BP_ASSERT(next[va] == BP__NONE);
                next[va] = vb;
                nb++;
            }
    ch->loop_vertices = (uint32_t *)bp__alloc_array(a, nb, sizeof(uint32_t));
    if (!ch->loop_vertices) return bp__oom(err, "building boundary loops");
    /* count the loops first so loop_start can be sized exactly */
    for (v = 0; v < ch->num_vertices; v++) {
        uint32_t w = v;
        if (next[v] == BP__NONE || loop_id[v] != BP__NONE) continue;
        do { loop_id[w] = nloops; w = next[w]; } while (w != v && w != BP__NONE && loop_id[w] == BP__NONE);
        if (w != v)
            return bp__fail(err, BP_ERR_TOPOLOGY, BP_ELEMENT_CHART, chart_index, -1, 0,
                            "chart %u: the boundary at vertex %u does not close into a loop",
                            chart_index, ch->vertex[v] + 1);
        nloops++;
    }
    ch->num_loops = nloops;
    ch->loop_start = (uint32_t *)bp__alloc_array(a, (size_t)nloops + 1, sizeof(uint32_t));
    if (!ch->loop_start) return bp__oom(err, "building boundary loops");
    /* walk again, writing the loops in discovery order and finding the
       longest one in 3D */
    for (v = 0; v < ch->num_vertices; v++) loop_id[v] = BP__NONE;
    nloops = 0;
    for (v = 0; v < ch->num_vertices; v++) {
        uint32_t w = v;
        double len = 0;
        if (next[v] == BP__NONE || loop_id[v] != BP__NONE) continue;
        ch->loop_start[nloops] = pos;
        do {
            loop_id[w] = nloops;
            ch->loop_vertices[pos++] = w;
            len += bp__dist3(bp__pos(m, ch->vertex[w]), bp__pos(m, ch->vertex[next[w]]));
            w = next[w];
        } while (w != v);
        if (len > best) { best = len; best_loop = nloops; }
        nloops++;
    }
    ch->loop_start[nloops] = pos;
    /* rotate the longest loop to the front (a cyclic shift of the loop list) */
    if (best_loop != 0) {
        uint32_t s0 = ch->loop_start[best_loop], s1 = ch->loop_start[best_loop + 1];
        uint32_t n0 = s1 - s0, i, j;
        uint32_t *tmp = (uint32_t *)bp__alloc_array(a, pos, sizeof(uint32_t));
        uint32_t *st2 = (uint32_t *)bp__alloc_array(a, (size_t)nloops + 1, sizeof(uint32_t));
        if (!tmp || !st2) { bp__free(a, tmp); bp__free(a, st2); return bp__oom(err, "building boundary loops"); }
        memcpy(tmp, ch->loop_vertices + s0, n0 * sizeof(uint32_t));
        j = n0;
        st2[0] = 0;
        for (i = 0, k = 1; i < nloops; i++) {
            uint32_t a0 = ch->loop_start[i], a1 = ch->loop_start[i + 1];
            if (i == best_loop) continue;
            st2[k++] = j;
            memcpy(tmp + j, ch->loop_vertices + a0, (a1 - a0) * sizeof(uint32_t));
            j += a1 - a0;
        }
        st2[nloops] = pos;
        memcpy(ch->loop_vertices, tmp, pos * sizeof(uint32_t));
        memcpy(ch->loop_start, st2, ((size_t)nloops + 1) * sizeof(uint32_t));
        bp__free(a, tmp);
        bp__free(a, st2);
    }
    return BP_OK;
}

/* BP_OK when every chart is fine; BP_ERR_CHARTS_FAILED with a message that
   counts the failures and quotes the first when some failed; when all
   failed, the first chart's own error (the caller then frees the atlas:
   nothing in it is usable). */
static bp_status bp__charts_status(const bp_atlas *atlas, bp_error *err)
{
    uint32_t c;
    if (!atlas->num_failed) return bp__ok(err);
    if (atlas->num_failed == atlas->num_charts) {
        if (err) *err = atlas->charts[0].error;
        return atlas->charts[0].error.status;
    }
    for (c = 0; c < atlas->num_charts; c++)
        if (atlas->charts[c].error.status != BP_OK) {
            const bp_error *e = &atlas->charts[c].error;
            return bp__fail(err, BP_ERR_CHARTS_FAILED, BP_ELEMENT_CHART, c, -1, e->line,
                            "%u of %u charts failed (the others are valid); the first: %s",
                            atlas->num_failed, atlas->num_charts, e->message);
        }
    return bp__ok(err);
}

/* --- the build on several threads -----------------------------------------

   bp_atlas_build starts a pool from the options (opt->threads, or
   opt->parallel_for) for a mesh of BP__PAR_MIN_TRIANGLES triangles or
   more, as bp_chart_init does for a chart.  What runs on it is the work
   that is independent per triangle or per mesh vertex; what depends on an
   order stays serial, and the tasks prepare it:
     validate   chunks of triangles: each chunk's box and its first failing
                triangle; the boxes are merged in chunk order with the
                serial loop's comparisons (so even the sign of a zero is
                the serial one), and the first failing chunk's triangle is
                checked again on the caller for the message;
     defects    the same chunks: degen[] and bad[] (repair), or each
                chunk's first defect (strict), and the arrays the later
                phases start from (mate, glued, the union-finds);
     sorts      for the duplicates and the edges, a counting sort by the
                smallest vertex on the caller (a pass to count, one to
                place: each bucket in triangle order), then each bucket
                sorted by the rest of its key, and its groups of equal keys
                read, in chunks of mesh vertices: duplicate copies marked,
                the mates of the manifold edges set, and what gluing does
                with each edge decided;
     glue       the unions, serial in the order of the edges (a union-find
                with the smallest index as root gives the same classes in
                any order, but the loop is short once the decisions are
                made);
     charts     the numbering, serial passes over the arrays in order, then
                the charts' arrays filled and the triangles' areas taken in
                chunks of triangles (the areas added in order after them).
   The chunks' bounds depend on the counts alone and each task writes its
   own items or its own slot, so the atlas, the repairs and the first error
   are those of one thread, whatever runs the tasks. */

/* The chunks of a pass over n items: BP__TRI_CHUNK each, or more so that
   there are at most BP__BUILD_TASKS (their slots live in bp__build, so no
   pass allocates, and a failed allocation is always out of memory). */
static void bp__build_chunks(bp__build *b, uint32_t n)
{
    uint32_t size = n / BP__BUILD_TASKS + 1;
    b->nchunk = bp__nchunks(n, size > BP__TRI_CHUNK ? size : BP__TRI_CHUNK);
}

/* Items [i0, i1) of chunk c of the current pass over n items. */
static uint32_t bp__build_range(const bp__build *b, uint32_t n, uint32_t c, uint32_t *i1)
{
    *i1 = bp__chunk_at(n, b->nchunk, c + 1);
    return bp__chunk_at(n, b->nchunk, c);
}

/* The first chunk's failing item in chunk order, or BP__NONE. */
static uint32_t bp__build_first(const bp__build *b)
{
    uint32_t c;
    for (c = 0; c < b->nchunk; c++)
        if (b->first[c] != BP__NONE) return b->first[c];
    return BP__NONE;
}

static void bp__validate_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    double *lo = b->box + 6 * (size_t)c, *hi = lo + 3;
    uint32_t t, t1, k;
    for (k = 0; k < 3; k++) { lo[k] = DBL_MAX; hi[k] = -DBL_MAX; }
    b->first[c] = BP__NONE;
    for (t = bp__build_range(b, b->m->num_triangles, c, &t1); t < t1; t++)
        if (bp__validate_tri(b->m, t, lo, hi, NULL) != BP_OK) { b->first[c] = t; return; }
}

/* bp__validate_global in chunks (above). */
static bp_status bp__validate_par(bp__build *b, bp_error *err)
{
    double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
    uint32_t c, k, t;
    bp__build_chunks(b, b->m->num_triangles);
    bp__par_run(&b->par, bp__validate_task, b, b->nchunk, b->m->num_triangles);
    if ((t = bp__build_first(b)) != BP__NONE) return bp__validate_tri(b->m, t, lo, hi, err);
    for (c = 0; c < b->nchunk; c++)
        for (k = 0; k < 3; k++) {
            const double *bx = b->box + 6 * (size_t)c;
            if (bx[k] < lo[k]) lo[k] = bx[k];
            if (bx[3 + k] > hi[k]) hi[k] = bx[3 + k];
        }
    bp__scale_of_box(lo, hi, &b->scale);
    return BP_OK;
}

/* Before the arrays exist (strict): each chunk's first local defect.
   After: in repair, every triangle's defect (bad: a repeated vertex, kept
   out of the gluing), and in both the start of the later phases' arrays. */
static void bp__defect_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    uint32_t t, t1, nt = b->m->num_triangles;
    b->first[c] = BP__NONE;
    for (t = bp__build_range(b, nt, c, &t1); t < t1; t++) {
        int d = 0;
        if (!b->degen || b->repair) d = bp__tri_defect(b->m, t, &b->scale);
        if (!b->degen) {
            if (d) { b->first[c] = t; return; }
            continue;
        }
        if (b->repair) {
            b->degen[t] = (unsigned char)d;
            b->bad[t] = d == 1;
        }
        b->tri_uf[t] = t;
        b->corner_uf[3 * (size_t)t] = 3 * t;
        b->corner_uf[3 * (size_t)t + 1] = 3 * t + 1;
        b->corner_uf[3 * (size_t)t + 2] = 3 * t + 2;
        b->glued[3 * (size_t)t] = b->glued[3 * (size_t)t + 1] = b->glued[3 * (size_t)t + 2] = BP__NONE;
        b->mate[3 * (size_t)t] = b->mate[3 * (size_t)t + 1] = b->mate[3 * (size_t)t + 2] = BP__NONE;
    }
}

/* Strict (degen not yet allocated): the first defect is the error. */
static bp_status bp__defects_par(bp__build *b, bp_error *err)
{
    uint32_t t, nt = b->m->num_triangles;
    bp__build_chunks(b, nt);
    bp__par_run(&b->par, bp__defect_task, b, b->nchunk, nt);
    if (!b->degen && (t = bp__build_first(b)) != BP__NONE) return bp__tri_defect_error(b->m, t, &b->scale, err);
    return BP_OK;
}

/* bp_atlas_build runs in named phases, each over the whole mesh:
     validate   the global checks, then the local defects (strict: errors;
                repair: marked, below)
     duplicates two triangles on the same three vertices (repair: dropped)
     edges      the corner edges sorted by vertex pair (repair: the mates
                across manifold edges)
     orient     (repair) re-orient each component, cut non-orientable ones
                (nothing to do when no two mates run the same way)
     glue       mesh edges, manifoldness, orientation; triangles and
                corners merged into charts and chart vertices (repair:
                non-manifold and cut edges are seams)
     charts     charts numbered by their smallest triangle, their arrays
     regularize (repair) the rest shape of each degenerate triangle
     pinches    chart vertices that share a (mesh vertex, uv) key
     topology   boundary loops and Euler characteristic of each chart
     cut        (unless opt.cut is BP_CUT_NONE) a closed or genus > 0
                chart cut into a disk along mesh edges (>>cut)
   Any phase can fail the whole call (strict: at the first defect); the
   topology phase fails single charts unless opt.strict is set.  Which
   parts of the phases run in tasks: "the build on several threads" above. */

static bp_status bp__build_alloc(const bp_allocator *a, bp__build *b, const bp_mesh *m, bp_error *err)
{
    uint32_t nt = m->num_triangles;
    size_t nc = 3 * (size_t)nt;
    b->edges = (bp__edge_rec *)bp__alloc_array(a, nc, sizeof *b->edges);
    b->keys = (bp__tri_key *)bp__alloc_array(a, nt, sizeof *b->keys);
    b->tri_uf = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    b->corner_uf = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->glued = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->chart_of_root = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    b->next = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->loop_id = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->bad = (unsigned char *)bp__calloc_array(a, nt, 1);
    b->degen = (unsigned char *)bp__calloc_array(a, nt, 1);
    b->drop = (unsigned char *)bp__calloc_array(a, nt, 1);
    b->flip = (unsigned char *)bp__calloc_array(a, nt, 1);
    b->twin = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    b->mate = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->queue = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    b->estart = (uint32_t *)bp__alloc_array(a, (size_t)m->num_vertices + 2, sizeof(uint32_t));
    b->area = (double *)bp__alloc_array(a, nt, sizeof(double));
    b->fm = *m;
    if (!b->edges || !b->keys || !b->tri_uf || !b->corner_uf || !b->glued || !b->chart_of_root ||
        !b->next || !b->loop_id || !b->bad || !b->degen || !b->drop || !b->flip ||
        !b->twin || !b->mate || !b->queue || !b->estart || !b->area)
        return bp__oom(err, "building charts");
    return BP_OK;
}

/* A counting sort's buckets: with start[0 .. nkeys + 1] zeroed and
   start[key + 2] counting the records of each key, the sums make placing a
   record at start[key + 1]++ leave bucket v in [start[v], start[v + 1]). */
static void bp__bucket_offsets(uint32_t *start, uint32_t nkeys)
{
    uint32_t v;
    for (v = 2; v <= nkeys + 1; v++) start[v] += start[v - 1];
}

/* The three vertices of triangle t in increasing order. */
static void bp__tri_sorted(const bp_mesh *m, uint32_t t, uint32_t *v)
{
    uint32_t x;
    memcpy(v, m->triangles + 3 * (size_t)t, 3 * sizeof(uint32_t));
    if (v[0] > v[1]) { x = v[0]; v[0] = v[1]; v[1] = x; }
    if (v[1] > v[2]) { x = v[1]; v[1] = v[2]; v[2] = x; }
    if (v[0] > v[1]) { x = v[0]; v[0] = v[1]; v[1] = x; }
}

/* One bucket of triangle keys (the same smallest vertex, in triangle
   order) into bp__tri_key_cmp's order: by the other two vertices, stable,
   so ties stay in triangle order (qsort on the whole key for a vertex of
   more than 32 triangles: the same order, a total one). */
static void bp__tri_keys_sort(bp__tri_key *k, uint32_t n)
{
    uint32_t i, j;
    if (n > 32) { qsort(k, n, sizeof *k, bp__tri_key_cmp); return; }
    for (i = 1; i < n; i++) {
        bp__tri_key x = k[i];
        for (j = i; j > 0 && (k[j - 1].v[1] > x.v[1] || (k[j - 1].v[1] == x.v[1] && k[j - 1].v[2] > x.v[2])); j--)
            k[j] = k[j - 1];
        k[j] = x;
    }
}

/* Chunk c of the mesh vertices: each one's bucket of triangle keys sorted,
   and its equal keys read (repair: the later copies dropped; strict: the
   chunk's first copy, by its position in keys[]). */
static void bp__dup_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    uint32_t v, v1, i;
    b->first[c] = BP__NONE;
    for (v = bp__build_range(b, b->m->num_vertices, c, &v1); v < v1; v++) {
        uint32_t lo = b->estart[v], hi = b->estart[v + 1];
        bp__tri_keys_sort(b->keys + lo, hi - lo);
        for (i = lo + 1; i < hi; i++)
            if (b->keys[i].v[1] == b->keys[i - 1].v[1] && b->keys[i].v[2] == b->keys[i - 1].v[2]) {
                uint32_t t0 = b->keys[i - 1].t, t1 = b->keys[i].t;
                if (!b->repair) { b->first[c] = i; return; }
                b->drop[t1] = 1;                /* keep the first of the group, drop the copy */
                b->twin[t1] = b->drop[t0] ? b->twin[t0] : t0;
            }
    }
}

/* Duplicate triangles: equal sorted vertex triples, found in the order of
   the keys (the smallest vertex, the other two, the triangle). */
static bp_status bp__find_duplicates(bp__build *b, const bp_mesh *m, bp_error *err)
{
    uint32_t t, i, nt = m->num_triangles, nv = m->num_vertices, v[3];
    char n0[48], n1[48];
    memset(b->estart, 0, ((size_t)nv + 2) * sizeof(uint32_t));
    for (t = 0; t < nt; t++) {
        bp__tri_sorted(m, t, v);
        b->estart[v[0] + 2]++;
    }
    bp__bucket_offsets(b->estart, nv);
    for (t = 0; t < nt; t++) {
        bp__tri_key *k;
        bp__tri_sorted(m, t, v);
        k = &b->keys[b->estart[v[0] + 1]++];
        memcpy(k->v, v, sizeof v);
        k->t = t;
    }
    bp__build_chunks(b, nv);
    bp__par_run(&b->par, bp__dup_task, b, b->nchunk, nv);
    if ((i = bp__build_first(b)) != BP__NONE) {
        uint32_t t0 = b->keys[i - 1].t, t1 = b->keys[i].t;
        const uint32_t *w = m->triangles + 3 * (size_t)t1;
        return bp__fail(err, BP_ERR_DUPLICATE_FACE, BP_ELEMENT_TRIANGLE, t1, t0, bp__tri_line(m, t1),
                        "%s and %s use the same vertices %u %u %u", bp__tri_name(m, t0, n0),
                        bp__tri_name(m, t1, n1), w[0] + 1, w[1] + 1, w[2] + 1);
    }
    for (t = 0; t < nt; t++)
        if (b->drop[t]) bp__repair_note(b->rep, BP_REPAIR_DUPLICATE, t, b->twin[t]);
    return BP_OK;
}

/* The mesh corner edge of corner edge ce of the glued mesh b->fm (a flipped
   triangle's corner edge k runs backwards along its mesh corner edge 2-k). */
static uint32_t bp__mesh_ce(const bp__build *b, uint32_t ce)
{
    return b->flip[ce / 3] ? ce - ce % 3 + (2 - ce % 3) : ce;
}

/* The corner edges of one mesh edge are b->edges[e, g) (sorted by vertex
   pair): g for a group starting at e, within its bucket [e, end). */
static size_t bp__edge_group_end(const bp__build *b, size_t e, size_t end)
{
    size_t g;
    for (g = e + 1; g < end && b->edges[g].hi == b->edges[e].hi; g++) {}
    return g;
}

/* The live corner edges of group [e, g): those of triangles neither
   repeating a vertex (bad) nor dropped as copies.  Returns their count; the
   first three go to live[]. */
static uint32_t bp__live_edges(const bp__build *b, size_t e, size_t g, uint32_t live[3])
{
    uint32_t n = 0;
    size_t i;
    for (i = e; i < g; i++)
        if (!b->bad[b->edges[i].ce / 3] && !b->drop[b->edges[i].ce / 3] && n++ < 3) live[n - 1] = b->edges[i].ce;
    return n;
}

/* What gluing does with one mesh edge, the corner edges edges[e, g) of the
   same vertex pair (of the glued mesh m = b->fm).  Repeated-vertex
   triangles (bad) and dropped copies take no part.  Strict: an edge of
   more than two triangles or two neighbours running the same way fail the
   call (BP__GLUE_FAIL); repair: such an edge, or one cut to make a
   component orientable, is a seam (BP__GLUE_NOTE: a non-manifold edge to
   report).  Two triangles that agree on the edge and its uvs are glued:
   the first corner edge is returned and glued[] pairs the two (a task's
   own entries: a corner edge is in one group).  BP__NONE: nothing. */
#define BP__GLUE_NOTE (BP__NONE - 2u)
#define BP__GLUE_FAIL (BP__NONE - 3u)

static uint32_t bp__glue_decide(bp__build *b, const bp_mesh *m, size_t e, size_t g)
{
    uint32_t good[3], ng = bp__live_edges(b, e, g, good);
    uint32_t c0, c1, a0, b0, a1, b1;
    if (ng > 2) return b->repair ? BP__GLUE_NOTE : BP__GLUE_FAIL;
    if (ng < 2 || (b->repair && b->mate[bp__mesh_ce(b, good[0])] == BP__CUT)) return BP__NONE;
    c0 = good[0];
    c1 = good[1];
    a0 = c0; b0 = c0 - c0 % 3 + (c0 % 3 + 1) % 3;   /* corners of the edge in its two triangles */
    a1 = c1; b1 = c1 - c1 % 3 + (c1 % 3 + 1) % 3;
    if (m->triangles[a0] == m->triangles[a1]) return BP__GLUE_FAIL;
    /* opposite directions: a0 pairs with b1 (same mesh vertex), b0 with a1 */
    if (m->corner_uv && (m->corner_uv[a0] != m->corner_uv[b1] || m->corner_uv[b0] != m->corner_uv[a1]))
        return BP__NONE;
    b->glued[c0] = c1;
    b->glued[c1] = c0;
    return c0;
}

/* The error of an edge that bp__glue_decide failed. */
static bp_status bp__glue_error(const bp__build *b, const bp_mesh *m, size_t e, size_t g, bp_error *err)
{
    uint32_t good[3], ng = bp__live_edges(b, e, g, good), lo = b->edges[e].lo, hi = b->edges[e].hi;
    uint32_t t0 = good[0] / 3, t1 = good[1] / 3;
    char n0[48], n1[48], n2[48];
    if (ng > 2)
        return bp__fail(err, BP_ERR_NONMANIFOLD, BP_ELEMENT_EDGE, lo, hi, bp__tri_line(m, good[2] / 3),
                        "edge %u-%u is shared by %u triangles (%s, %s, %s%s): a surface edge may have at most two",
                        lo + 1, hi + 1, ng, bp__tri_name(m, good[0] / 3, n0), bp__tri_name(m, good[1] / 3, n1),
                        bp__tri_name(m, good[2] / 3, n2), ng > 3 ? ", ..." : "");
    return bp__fail(err, BP_ERR_ORIENTATION, BP_ELEMENT_EDGE, lo, hi, bp__tri_line(m, t1),
                    "%s and %s both run along edge %u-%u in the same direction: their orientations disagree",
                    bp__tri_name(m, t0, n0), bp__tri_name(m, t1, n1), lo + 1, hi + 1);
}

/* One bucket of edge records (the same smaller vertex, in corner edge
   order) into bp__edge_cmp's order: by the larger vertex, stable (qsort on
   the whole key for a vertex of more than 32 corner edges). */
static void bp__edge_recs_sort(bp__edge_rec *r, uint32_t n)
{
    uint32_t i, j;
    if (n > 32) { qsort(r, n, sizeof *r, bp__edge_cmp); return; }
    for (i = 1; i < n; i++) {
        bp__edge_rec x = r[i];
        for (j = i; j > 0 && r[j - 1].hi > x.hi; j--) r[j] = r[j - 1];
        r[j] = x;
    }
}

/* Chunk c of the mesh vertices: each one's bucket of edge records sorted
   and, in repair, the mates across its manifold edges (the groups of
   exactly two live triangles; mate[] starts as BP__NONE); first[c] says
   whether two mates run the same way along their edge (the orientation
   repair has work only then). */
static void bp__edge_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    const uint32_t *tri = b->m->triangles;
    uint32_t v, v1;
    b->first[c] = BP__NONE;
    for (v = bp__build_range(b, b->m->num_vertices, c, &v1); v < v1; v++) {
        size_t e, g, end = b->estart[v + 1];
        bp__edge_recs_sort(b->edges + b->estart[v], (uint32_t)(end - b->estart[v]));
        if (!b->repair) continue;
        for (e = b->estart[v]; e < end; e = g) {
            uint32_t live[3];
            g = bp__edge_group_end(b, e, end);
            if (bp__live_edges(b, e, g, live) != 2) continue;
            b->mate[live[0]] = live[1];
            b->mate[live[1]] = live[0];
            if (tri[live[0]] == tri[live[1]]) b->first[c] = v;
        }
    }
}

/* Edges: the corner edges sorted by their unordered vertex pair (and
   then by corner edge); each group is one mesh edge. */
static void bp__sort_edges(bp__build *b, const bp_mesh *m)
{
    uint32_t t, k, nt = m->num_triangles, nv = m->num_vertices;
    memset(b->estart, 0, ((size_t)nv + 2) * sizeof(uint32_t));
    for (t = 0; t < 3 * nt; t++) {
        uint32_t va = m->triangles[t], vb = m->triangles[t - t % 3 + (t % 3 + 1) % 3];
        b->estart[(va < vb ? va : vb) + 2]++;
    }
    bp__bucket_offsets(b->estart, nv);
    for (t = 0; t < nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t va = m->triangles[3 * (size_t)t + k], vb = m->triangles[3 * (size_t)t + (k + 1) % 3];
            bp__edge_rec *r = &b->edges[b->estart[(va < vb ? va : vb) + 1]++];
            r->lo = va < vb ? va : vb;
            r->hi = va < vb ? vb : va;
            r->ce = 3 * t + k;
        }
    bp__build_chunks(b, nv);
    bp__par_run(&b->par, bp__edge_task, b, b->nchunk, nv);
}

/* --- repair ----------------------------------------------------------------

   Outside strict mode the defects that today's assets carry are mended, not
   rejected, each counted in atlas.repairs (first elements named as the file
   numbers them); opt.strict turns every one of them back into an error.
     Duplicates: of triangles on the same three vertices (any order or
       orientation) the first is kept and the copies dropped: they are in no
       chart, and their corners take the chart vertices of the kept twin's
       corners at the same mesh vertices (so a writer still gives every
       corner a uv).
     Orientation: the manifold edges (exactly two live triangles) join the
       triangles into components; a breadth-first walk from each
       component's smallest triangle gives every triangle the orientation
       that agrees with the one it was reached from.  An edge whose two
       triangles then still run the same way closes a cycle that reverses
       orientation -- the component is non-orientable (a Moebius band) --
       and is cut: it becomes a seam, so what is glued is orientable.  The
       component then keeps the orientation of the majority of its
       triangles (on a tie, that of its smallest triangle), and each
       triangle of the minority is flipped: the glued mesh b->fm has its
       corners 1 and 2 swapped, and so its chart triangle runs the other
       way.  atlas.corner_chart / corner_vertex stay per *mesh* corner.
     Non-manifold edges (more than two live triangles): not glued, a seam
       for every triangle on them; a vertex where the resulting fans meet
       only at a point is split by the pinch repair.
     Degenerate triangles (a repeated vertex, or zero or near-zero area):
       flattened with a regularized rest shape (>>rest).  A zero-area
       triangle is glued to its neighbours as any other; one that repeats
       a vertex cannot be (two of its corners would be one chart vertex)
       and becomes a chart of its own. */

static void bp__repair_note(bp_repair_report *r, bp_repair_kind k, int64_t a, int64_t b2)
{
    bp_repair *p = &r->kind[k];
    if (p->count < BP_REPAIR_FIRST) { p->first[p->count] = a; p->first2[p->count] = b2; }
    p->count++;
    r->total++;
}

BPDEF const char *bp_repair_name(bp_repair_kind k)
{
    static const char *const names[] = { "flipped", "nonorientable", "duplicate", "nonmanifold_edge", "degenerate" };
    if ((int)k < 0 || (int)k >= (int)BP_REPAIR_KINDS) return "unknown";
    return names[k];
}

static void bp__repair_init(bp_repair_report *r)
{
    int k, i;
    memset(r, 0, sizeof *r);
    for (k = 0; k < BP_REPAIR_KINDS; k++) {
        r->kind[k].element = k == BP_REPAIR_NONORIENTABLE || k == BP_REPAIR_NONMANIFOLD_EDGE ? BP_ELEMENT_EDGE
                                                                                          : BP_ELEMENT_TRIANGLE;
        for (i = 0; i < BP_REPAIR_FIRST; i++) r->kind[k].first[i] = r->kind[k].first2[i] = -1;
    }
}

/* The sentence of each repair kind, naming its first elements. */
static void bp__repair_messages(bp_repair_report *r, const bp_mesh *m)
{
    static const char *const what[] = {
        "re-oriented to agree with the rest of their component (the OBJ writers give them their corners in that order)",
        "cut into seams: a non-orientable component (a Moebius band) cannot be glued there",
        "dropped as copies of another triangle on the same vertices",
        "shared by more than two triangles made seams for all of them",
        "with zero area or a repeated vertex flattened with a regularized rest shape" };
    int k;
    for (k = 0; k < BP_REPAIR_KINDS; k++) {
        bp_repair *p = &r->kind[k];
        size_t len;
        uint32_t i, n = p->count < BP_REPAIR_FIRST ? p->count : BP_REPAIR_FIRST;
        char nm[48], n2[48];
        if (!p->count) continue;
        bp__format(p->message, sizeof p->message, "%u %s%s %s:", p->count,
                   p->element == BP_ELEMENT_EDGE ? "edge" : "triangle", p->count == 1 ? "" : "s", what[k]);
        for (i = 0; i < n; i++) {
            len = strlen(p->message);
            if (p->element == BP_ELEMENT_EDGE)
                bp__format(p->message + len, sizeof p->message - len, "%s edge %u-%u", i ? "," : "",
                           (uint32_t)p->first[i] + 1, (uint32_t)p->first2[i] + 1);
            else if (k == BP_REPAIR_DUPLICATE)
                bp__format(p->message + len, sizeof p->message - len, "%s %s repeats %s", i ? "," : "",
                           bp__tri_name(m, (uint32_t)p->first[i], nm), bp__tri_name(m, (uint32_t)p->first2[i], n2));
            else
                bp__format(p->message + len, sizeof p->message - len, "%s %s", i ? "," : "",
                           bp__tri_name(m, (uint32_t)p->first[i], nm));
        }
        if (p->count > n) {
            len = strlen(p->message);
            bp__format(p->message + len, sizeof p->message - len, ", ...");
        }
    }
}

/* The breadth-first walk over one component from triangle t0: flip[] as
   reached (0 for t0), conflicting edges cut; then the majority rule.
   Returns the size of the component. */
static uint32_t bp__orient_component(bp__build *b, const bp_mesh *m, uint32_t t0, unsigned char *seen)
{
    uint32_t head = 0, tail = 0, ones = 0, i, k;
    b->queue[tail++] = t0;
    seen[t0] = 1;
    b->flip[t0] = 0;
    while (head < tail) {
        uint32_t u = b->queue[head++];
        for (k = 0; k < 3; k++) {
            uint32_t c = 3 * u + k, c2 = b->mate[c], w;
            unsigned char need;
            if (c2 == BP__NONE || c2 == BP__CUT) continue;
            w = c2 / 3;
            /* same direction along the edge: opposite orientations */
            need = (unsigned char)(b->flip[u] ^ (m->triangles[c] == m->triangles[c2]));
            if (!seen[w]) { seen[w] = 1; b->flip[w] = need; b->queue[tail++] = w; }
            else if (b->flip[w] != need) {
                uint32_t va = m->triangles[c], vb = m->triangles[c - k + (k + 1) % 3];
                b->mate[c] = b->mate[c2] = BP__CUT;
                bp__repair_note(b->rep, BP_REPAIR_NONORIENTABLE, va < vb ? va : vb, va < vb ? vb : va);
            }
        }
    }
    for (i = 0; i < tail; i++) ones += b->flip[b->queue[i]];
    if (2 * (uint64_t)ones > tail)
        for (i = 0; i < tail; i++) b->flip[b->queue[i]] ^= 1;
    return tail;
}

/* Orientation repair (above): flip[] for every triangle, then the glued
   mesh b->fm and the corner edges renumbered to it.  When no two mates run
   the same way (the edge tasks' flags: a consistently wound mesh), every
   walk keeps flip[] = 0 and cuts nothing, so there is nothing to walk.
   Returns 0 when out of memory. */
static int bp__orient(const bp_allocator *a, bp__build *b, const bp_mesh *m)
{
    uint32_t t, nt = m->num_triangles, nflip = 0;
    size_t i, nc = 3 * (size_t)nt;
    unsigned char *seen;
    if (bp__build_first(b) == BP__NONE) return 1;
    seen = (unsigned char *)bp__calloc_array(a, nt, 1);
    if (!seen) return 0;
    for (t = 0; t < nt; t++)
        if (!seen[t] && !b->bad[t] && !b->drop[t]) bp__orient_component(b, m, t, seen);
    bp__free(a, seen);
    for (t = 0; t < nt; t++)
        if (b->flip[t]) { bp__repair_note(b->rep, BP_REPAIR_FLIPPED, t, -1); nflip++; }
    if (!nflip) return 1;
    b->fixed_tri = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    b->fixed_uv = m->corner_uv ? (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t)) : NULL;
    if (!b->fixed_tri || (m->corner_uv && !b->fixed_uv)) return 0;
    for (i = 0; i < nc; i++) {
        size_t j = b->flip[i / 3] && i % 3 ? i - i % 3 + 3 - i % 3 : i;     /* corners 1 <-> 2 */
        b->fixed_tri[i] = m->triangles[j];
        if (b->fixed_uv) b->fixed_uv[i] = m->corner_uv[j];
    }
    b->fm.triangles = b->fixed_tri;
    if (b->fixed_uv) b->fm.corner_uv = b->fixed_uv;
    for (i = 0; i < nc; i++) {
        uint32_t ce = b->edges[i].ce;
        if (b->flip[ce / 3]) b->edges[i].ce = ce - ce % 3 + (2 - ce % 3);
    }
    return 1;
}

/* Chunk c of the mesh vertices: what gluing does with each edge of their
   buckets, at the edge's first record of b->next (the others BP__NONE);
   b->next is free until the topology phase. */
static void bp__glue_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    uint32_t v, v1;
    for (v = bp__build_range(b, b->m->num_vertices, c, &v1); v < v1; v++) {
        size_t e, g, i, end = b->estart[v + 1];
        for (e = b->estart[v]; e < end; e = g) {
            g = bp__edge_group_end(b, e, end);
            b->next[e] = bp__glue_decide(b, &b->fm, e, g);
            for (i = e + 1; i < g; i++) b->next[i] = BP__NONE;
        }
    }
}

/* Glue every mesh edge (of the glued mesh b->fm): the decisions in tasks,
   then, in the order of the edges, the repairs noted, the first failure
   reported and the unions made. */
static bp_status bp__glue(bp__build *b, bp_error *err)
{
    size_t e, nc = 3 * (size_t)b->m->num_triangles;
    const bp_mesh *m = &b->fm;
    bp__build_chunks(b, m->num_vertices);
    bp__par_run(&b->par, bp__glue_task, b, b->nchunk, m->num_vertices);
    for (e = 0; e < nc; e++) {
        uint32_t c0 = b->next[e], c1, a0, b0, a1, b1;
        if (c0 == BP__NONE) continue;
        if (c0 == BP__GLUE_NOTE) {
            bp__repair_note(b->rep, BP_REPAIR_NONMANIFOLD_EDGE, b->edges[e].lo, b->edges[e].hi);
            continue;
        }
        if (c0 == BP__GLUE_FAIL) return bp__glue_error(b, m, e, bp__edge_group_end(b, e, b->estart[b->edges[e].lo + 1]), err);
        c1 = b->glued[c0];
        a0 = c0; b0 = c0 - c0 % 3 + (c0 % 3 + 1) % 3;
        a1 = c1; b1 = c1 - c1 % 3 + (c1 % 3 + 1) % 3;
        bp__uf_union(b->tri_uf, c0 / 3, c1 / 3);
        bp__uf_union(b->corner_uf, a0, b1);
        bp__uf_union(b->corner_uf, b0, a1);
    }
    return BP_OK;
}

/* A dropped copy's corners take its twin's chart vertices at the same
   mesh vertices (again after >>cut renumbered the twin's chart). */
static void bp__corners_of_copies(bp__build *b, bp_atlas *atlas, const bp_mesh *m)
{
    uint32_t t, k, j, nt = m->num_triangles;
    for (t = 0; t < nt; t++) {
        uint32_t tw = b->twin[t];
        if (!b->drop[t]) continue;
        for (k = 0; k < 3; k++) {
            for (j = 0; j < 2 && m->triangles[3 * (size_t)tw + j] != m->triangles[3 * (size_t)t + k]; j++) {}
            atlas->corner_chart[3 * (size_t)t + k] = atlas->corner_chart[3 * (size_t)tw + j];
            atlas->corner_vertex[3 * (size_t)t + k] = atlas->corner_vertex[3 * (size_t)tw + j];
        }
    }
}

/* Corners of the glued mesh m = b->fm -> corners of the user's mesh: the
   copies as above; a flipped triangle's corners 1 and 2 swap back. */
static void bp__corners_to_mesh(bp__build *b, bp_atlas *atlas, const bp_mesh *m)
{
    uint32_t t, nt = m->num_triangles;
    bp__corners_of_copies(b, atlas, m);
    for (t = 0; t < nt; t++)
        if (b->flip[t]) {
            uint32_t x = atlas->corner_vertex[3 * (size_t)t + 1];
            atlas->corner_vertex[3 * (size_t)t + 1] = atlas->corner_vertex[3 * (size_t)t + 2];
            atlas->corner_vertex[3 * (size_t)t + 2] = x;
        }
}

/* Degenerate triangles (repair): the side s of the equilateral rest shape
   of >>rest, the mean of the triangle's three 3D edge lengths, or when
   they are all zero the mean edge length of the chart's other triangles
   (1 when there is none); the chart's area3d counts sqrt(3)/4 s^2. */
static bp_status bp__regularize(const bp_allocator *a, bp__build *b, bp_chart *ch, const bp_mesh *m, bp_error *err)
{
    uint32_t t, k, n = 0;
    double sum = 0, mean;
    for (t = 0; t < ch->num_triangles && !b->degen[ch->face[t]]; t++) {}
    if (t == ch->num_triangles) return BP_OK;
    ch->rest_side = (double *)bp__calloc_array(a, ch->num_triangles, sizeof(double));
    if (!ch->rest_side) return bp__oom(err, "building charts");
    for (t = 0; t < ch->num_triangles; t++)
        if (!b->degen[ch->face[t]])
            for (k = 0; k < 3; k++, n++)
                sum += bp__dist3(bp__pos(m, ch->vertex[ch->triangles[3 * t + k]]),
                                 bp__pos(m, ch->vertex[ch->triangles[3 * t + (k + 1) % 3]]));
    mean = n && sum > 0 ? sum / n : 1;
    for (t = 0; t < ch->num_triangles; t++) {
        double s = 0;
        if (!b->degen[ch->face[t]]) continue;
        for (k = 0; k < 3; k++)
            s += bp__dist3(bp__pos(m, ch->vertex[ch->triangles[3 * t + k]]),
                           bp__pos(m, ch->vertex[ch->triangles[3 * t + (k + 1) % 3]])) / 3;
        ch->rest_side[t] = s > 0 ? s : mean;
        ch->area3d += 0.4330127018922193 * ch->rest_side[t] * ch->rest_side[t];
    }
    return BP_OK;
}

/* The union-finds' parents point to smaller indices (the root of a class
   is its smallest element, and path halving only moves a parent down), so
   one sweep upwards points every element at its root, without a find. */
static void bp__uf_flatten(uint32_t *parent, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) parent[i] = parent[parent[i]];
}

/* Chunk c of the triangles: half the 3D area of each (of the glued mesh:
   a chart adds them in its triangles' order). */
static void bp__area_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    const uint32_t *tri = b->fm.triangles;
    const double *pos = b->fm.positions;
    uint32_t t, t1;
    for (t = bp__build_range(b, b->fm.num_triangles, c, &t1); t < t1; t++)
        b->area[t] = 0.5 * bp__area2_3d(pos + 3 * (size_t)tri[3 * (size_t)t], pos + 3 * (size_t)tri[3 * (size_t)t + 1],
                                        pos + 3 * (size_t)tri[3 * (size_t)t + 2]);
}

/* Chunk c of the triangles: a chart's arrays, where the serial pass put
   them (the triangle's place in its chart in b->queue, free after the
   orientation repair; each class root's chart vertex in vert_of_root).
   A chart vertex's mesh vertex and uv are written from its class root
   alone: every corner of the class has them, and one writer is enough. */
static void bp__fill_task(void *task, uint32_t c)
{
    bp__build *b = (bp__build *)task;
    bp_atlas *atlas = b->atlas;
    const bp_mesh *m = &b->fm;
    uint32_t t, t1, k;
    for (t = bp__build_range(b, m->num_triangles, c, &t1); t < t1; t++) {
        bp_chart *ch;
        uint32_t ct = b->queue[t];
        if (b->drop[t]) continue;
        ch = &atlas->charts[atlas->corner_chart[3 * (size_t)t]];
        ch->face[ct] = t;
        for (k = 0; k < 3; k++) {
            size_t i = 3 * (size_t)t + k;
            uint32_t r = b->corner_uf[i], cv = b->vert_of_root[r];
            atlas->corner_vertex[i] = cv;
            ch->triangles[3 * (size_t)ct + k] = cv;
            if (r != i) continue;
            ch->vertex[cv] = m->triangles[i];
            ch->vertex_uv[cv] = m->corner_uv ? m->corner_uv[i] : BP__NONE;
        }
    }
}

/* Number the charts by their smallest triangle and the chart vertices by
   first appearance in the chart's triangles (deterministic), and fill each
   chart's arrays.  A corner class's root is its smallest corner, so its
   first appearance: the serial passes number the charts, give each
   triangle its place in its chart and each root its chart vertex, reading
   the arrays in order; the tasks fill the charts; the areas are added in
   each chart's triangle order. */
static bp_status bp__make_charts(const bp_allocator *a, bp__build *b, bp_atlas *atlas, const bp_mesh *m,
                                 bp_error *err)
{
    uint32_t t, k, c, nt = m->num_triangles, nchart = 0;
    size_t nc = 3 * (size_t)nt;
    bp__build_chunks(b, nt);
    bp__par_run(&b->par, bp__area_task, b, b->nchunk, nt);
    bp__uf_flatten(b->tri_uf, nt);
    bp__uf_flatten(b->corner_uf, nc);
    b->vert_of_root = b->mate;            /* mate[] is done with after the gluing */
    for (t = 0; t < nt; t++) b->chart_of_root[t] = BP__NONE;
    for (t = 0; t < nt; t++) {
        uint32_t r = b->tri_uf[t];
        if (b->drop[t]) continue;
        if (b->chart_of_root[r] == BP__NONE) b->chart_of_root[r] = nchart++;
    }
    atlas->num_charts = nchart;
    atlas->num_corners = (uint32_t)nc;
    atlas->charts = (bp_chart *)bp__calloc_array(a, nchart, sizeof(bp_chart));
    atlas->corner_chart = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    atlas->corner_vertex = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    if (!atlas->charts || !atlas->corner_chart || !atlas->corner_vertex) return bp__oom(err, "building charts");
    for (t = 0; t < nt; t++) {
        bp_chart *ch;
        if (b->drop[t]) continue;
        c = b->chart_of_root[b->tri_uf[t]];
        ch = &atlas->charts[c];
        b->queue[t] = ch->num_triangles++;
        for (k = 0; k < 3; k++) {
            size_t i = 3 * (size_t)t + k;
            if (b->corner_uf[i] == i) b->vert_of_root[i] = ch->num_vertices++;
            atlas->corner_chart[i] = c;
        }
    }
    for (c = 0; c < nchart; c++) {
        bp_chart *ch = &atlas->charts[c];
        ch->vertex = (uint32_t *)bp__alloc_array(a, ch->num_vertices, sizeof(uint32_t));
        ch->vertex_uv = (uint32_t *)bp__alloc_array(a, ch->num_vertices, sizeof(uint32_t));
        ch->triangles = (uint32_t *)bp__alloc_array(a, 3 * (size_t)ch->num_triangles, sizeof(uint32_t));
        ch->face = (uint32_t *)bp__alloc_array(a, ch->num_triangles, sizeof(uint32_t));
        if (!ch->vertex || !ch->vertex_uv || !ch->triangles || !ch->face) return bp__oom(err, "building charts");
    }
    b->atlas = atlas;
    bp__par_run(&b->par, bp__fill_task, b, b->nchunk, nt);
    for (t = 0; t < nt; t++)
        if (!b->drop[t] && !b->degen[t]) atlas->charts[atlas->corner_chart[3 * (size_t)t]].area3d += b->area[t];
    bp__corners_to_mesh(b, atlas, m);
    return BP_OK;
}

/* The pinches among one mesh vertex's chart vertices k[0, n), in chart
   order: within each chart, the vertices whose uv an earlier one has
   (qsort for a chart of more than 32 of them at one mesh vertex). */
static void bp__pinches_at(bp_atlas *atlas, bp__vkey *k, uint32_t n)
{
    uint32_t i, j, e;
    for (i = 0; i < n; i = e) {
        uint32_t c = k[i].chart, dup = 0;
        for (e = i + 1; e < n && k[e].chart == c; e++) {}
        if (e - i > 32) {
            qsort(k + i, e - i, sizeof *k, bp__vkey_cmp);
            for (j = i + 1; j < e; j++) dup += k[j].uv == k[j - 1].uv;
        } else
            for (j = i + 1; j < e; j++) {
                uint32_t l;
                for (l = i; l < j && k[l].uv != k[j].uv; l++) {}
                dup += l < j;
            }
        atlas->charts[c].split_vertices += dup;
        atlas->num_split += dup;
    }
}

/* Pinch repairs: the chart vertices beyond one per distinct (chart, mesh
   vertex, uv) key, counted per mesh vertex after a counting sort by it
   (b->estart is free after the gluing). */
static bp_status bp__count_pinches(const bp_allocator *a, bp__build *b, bp_atlas *atlas, bp_error *err)
{
    size_t nv_total = 0;
    uint32_t c, i, v, nv = b->m->num_vertices;
    for (c = 0; c < atlas->num_charts; c++) nv_total += atlas->charts[c].num_vertices;
    b->vkeys = (bp__vkey *)bp__alloc_array(a, nv_total, sizeof *b->vkeys);
    if (!b->vkeys) return bp__oom(err, "building charts");
    memset(b->estart, 0, ((size_t)nv + 2) * sizeof(uint32_t));
    for (c = 0; c < atlas->num_charts; c++)
        for (i = 0; i < atlas->charts[c].num_vertices; i++) b->estart[atlas->charts[c].vertex[i] + 2]++;
    bp__bucket_offsets(b->estart, nv);
    for (c = 0; c < atlas->num_charts; c++)
        for (i = 0; i < atlas->charts[c].num_vertices; i++) {
            bp__vkey *k = &b->vkeys[b->estart[atlas->charts[c].vertex[i] + 1]++];
            k->chart = c;
            k->v = atlas->charts[c].vertex[i];
            k->uv = atlas->charts[c].vertex_uv[i];
        }
    for (v = 0; v < nv; v++) bp__pinches_at(atlas, b->vkeys + b->estart[v], b->estart[v + 1] - b->estart[v]);
    return BP_OK;
}

/* Chart c's verdict in ch->error: its boundary loops and Euler
   characteristic chi = V - E + F = 2 - 2g - b, which must be that of a
   disk with holes (g = 0, b >= 1); other charts go to >>cut unless
   opt.cut is BP_CUT_NONE.
   Returns a status only for what ends the whole call (out of memory, a
   boundary that does not close); the verdict is in ch->error. */
static bp_status bp__chart_topology(const bp_allocator *a, bp__build *b, bp_atlas *atlas, uint32_t c,
                                    const bp_mesh *m, bp_error *err)
{
    bp_chart *ch = &atlas->charts[c];
    int64_t chi, ne, g2;
    uint32_t t0 = ch->face[0], nl;
    bp_status st;
    char nm[48];
    if ((st = bp__chart_loops(a, ch, m, b->next, b->loop_id, b->glued, c, err)) != BP_OK) return st;
    nl = ch->num_loops;
    ne = ((int64_t)3 * ch->num_triangles + ch->loop_start[nl]) / 2;
    chi = (int64_t)ch->num_vertices - ne + ch->num_triangles;
    g2 = 2 - (int64_t)nl - chi;     /* = 2g */
    if (nl > 0 && g2 == 0) {
        bp__ok(&ch->error);
        return BP_OK;
    }
    if (nl == 0 && chi == 2)
        bp__fail(&ch->error, BP_ERR_TOPOLOGY, BP_ELEMENT_CHART, c, -1, bp__tri_line(m, t0),
                 "chart %u (from %s, %u triangles) is a closed surface with no boundary: it cannot be "
                 "flattened without seams; cut it into disks first (vt seams, or opt.cut = BP_CUT_AUTO, the "
                 "default, which cuts it automatically)",
                 c, bp__tri_name(m, t0, nm), ch->num_triangles);
    else
        bp__fail(&ch->error, BP_ERR_TOPOLOGY, BP_ELEMENT_CHART, c, -1, bp__tri_line(m, t0),
                 "chart %u (from %s) has genus %D and %u boundary loops (Euler characteristic %D): only "
                 "disks and disks with holes can be flattened; it needs seams that cut it into disks (vt seams, or "
                 "opt.cut = BP_CUT_AUTO, the default)",
                 c, bp__tri_name(m, t0, nm), g2 / 2, nl, chi);
    return BP_OK;
}

static bp_status bp__chart_cut(const bp_allocator *a, bp_atlas *atlas, uint32_t c, const bp_mesh *m,
                               const double *importance, uint32_t *glued, uint32_t *next, uint32_t *loop_id,
                               bp_error *err);

BPDEF bp_status bp_atlas_build(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status ost_;
    const bp_options *opt_ = bp__opts(opt, &o_, err, &ost_);     /* >>progress */
    bp_allocator a = bp__allocator_of(opt_);
    bp__build b;
    bp_status st;
    uint32_t c;
    void *pool = NULL;
    int strict = opt_ && opt_->strict;
    if (ost_ != BP_OK) return ost_;
    opt = opt_;
    if (!atlas)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "atlas must not be NULL");
    memset(atlas, 0, sizeof *atlas);
    if (bp__report(opt, BP_STAGE_CHARTS, 0, BP_NO_CHART))
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled before building the charts");
    atlas->allocator = a;
    memset(&b, 0, sizeof b);
    bp__repair_init(&atlas->repairs);
    if ((st = bp__validate_sizes(m, err)) != BP_OK) return st;
    b.m = m;
    b.par = m->num_triangles >= BP__PAR_MIN_TRIANGLES ? bp__par_begin(&a, opt, &pool) : bp__par_serial();
    st = bp__validate_par(&b, err);
    if (st == BP_OK && strict) st = bp__defects_par(&b, err);
    b.repair = !strict;
    b.rep = &atlas->repairs;
    if (st == BP_OK) st = bp__build_alloc(&a, &b, m, err);
    if (st == BP_OK) st = bp__defects_par(&b, err);
    if (st == BP_OK) st = bp__find_duplicates(&b, m, err);
    if (st == BP_OK) bp__sort_edges(&b, m);
    if (st == BP_OK && b.repair && !bp__orient(&a, &b, m)) st = bp__oom(err, "building charts");
    if (st == BP_OK) st = bp__glue(&b, err);
    if (st == BP_OK) st = bp__make_charts(&a, &b, atlas, &b.fm, err);
    for (c = 0; st == BP_OK && c < atlas->num_charts; c++) st = bp__regularize(&a, &b, &atlas->charts[c], m, err);
    if (st == BP_OK) st = bp__count_pinches(&a, &b, atlas, err);
    for (c = 0; st == BP_OK && c < atlas->num_charts; c++) {
        st = bp__chart_topology(&a, &b, atlas, c, m, err);
        if (st == BP_OK && atlas->charts[c].error.status == BP_ERR_TOPOLOGY && !(opt && opt->cut == BP_CUT_NONE))
            st = bp__chart_cut(&a, atlas, c, m, opt ? opt->importance : NULL, b.glued, b.next, b.loop_id, err);   /* >>cut */
        if (st != BP_OK || atlas->charts[c].error.status == BP_OK) continue;
        atlas->num_failed++;
        if (strict) {
            if (err) *err = atlas->charts[c].error;
            st = atlas->charts[c].error.status;
        }
    }
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) {
        uint32_t t;
        bp__corners_of_copies(&b, atlas, m);      /* the twins' charts may be cut */
        for (t = 0; t < m->num_triangles; t++)
            if (b.degen[t] && !b.drop[t]) bp__repair_note(&atlas->repairs, BP_REPAIR_DEGENERATE, t, -1);
        bp__repair_messages(&atlas->repairs, m);
    }
    bp__build_free(&a, &b);
    bp__par_end(&a, pool);
    if (st == BP_OK) st = bp__charts_status(atlas, err);
    if ((st == BP_OK || st == BP_ERR_CHARTS_FAILED) && bp__report(opt, BP_STAGE_CHARTS, 1, BP_NO_CHART))
        st = bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled after building the charts");
    if (st != BP_OK && st != BP_ERR_CHARTS_FAILED) bp_atlas_free(atlas);
    return st;
}

/* >>cut ====================================================================

   Automatic seams.  The topology phase of >>charts accepts only charts with
   chi = V - E + F = 2 - 2g - b equal to that of a disk with holes (g = 0,
   b >= 1).  A closed chart (b = 0) or one with handles (g > 0) cannot be
   laid flat as it is; with opt.cut == BP_CUT_AUTO (the default) this section
   cuts it into a topological disk, along mesh edges, and hands it back to
   the topology check.  Charts that are already disks with holes, and every
   vt seam of the input, are left as they are: seams are added only where a
   chart needs them.

   The cut graph.  Let C be a spanning tree of the chart's dual graph (the
   triangles, adjacent across interior edges).  Cutting along every interior
   edge NOT in C leaves the triangles glued along a tree, which is a disk:
   each triangle is attached to the ones before it along one edge.  That cut
   is far too long; it is pruned by gluing back, one at a time, every cut
   edge with an end of degree 1 in the cut graph (boundary edges count in the
   degree and are never removed).  Zipping up such a dangling edge glues the
   disk's boundary along two consecutive edges, which keeps a disk, so the
   pruned cut still opens the chart into one disk (chi = 1, one loop); the
   chart's holes end up connected to the cut.

   Which tree C: the greedy homotopy basis of Erickson & Whittlesey (2005)
   on 3D edge lengths.  Dijkstra grows a shortest-path tree T from a base
   point -- for a chart with boundary, from all its boundary vertices at
   once, so that the boundary acts as one contracted base point; for a
   closed chart, from the middle of an approximate diameter (below), so the
   loops through it are short from every side (on fertility: 350 edges cut
   instead of 380 from vertex 0, and half the iterations).  Every interior
   edge (u, v) not in T closes a loop of length d(u) + d(v) + |uv| through
   the base.  C is the maximum spanning tree of the dual under that loop
   length (Kruskal; edges of T come last), so the edges left out of C --
   whose T-paths form the cut after pruning -- close the shortest loops: the 2g handle loops (Eppstein's
   tree-cotree, 2003, with the short choice of trees), plus for a chart with
   several holes, short paths joining the holes.

   A closed chart of genus 0 has no handle loop: the pruning would remove
   the whole tree.  It is cut along one shortest path between far-apart
   points instead, the two ends of an approximate diameter found by two
   Dijkstra sweeps (the farthest vertex p from vertex 0, then the farthest q
   from p), so that the boundary Tutte's start map lays on a circle is long
   and the free-boundary optimization has room to open it.  The path has at
   least two edges (a one-edge cut would give a boundary of two vertices).

   Extremity branches.  A disk whose boundary is far from some part of the
   surface (a leg, a horn, the far side of a sphere cut along one path)
   must shrink that part a lot in the plane, and the symmetric Dirichlet
   energy pays for it.  So, after either cut, while the vertex farthest
   from the cut graph and the boundary is farther than tau = 0.3 sqrt(A)
   (A the chart's 3D area; on a sphere slit from pole to pole, the equator
   point opposite the slit lies about 0.44 sqrt(A) away), the shortest path
   from it to them is cut too (at most 16 such branches).  Measured with 2
   threads: the cow without its vt goes from mean energy 6.87 (one path, 56
   edges) to 4.43 (158 edges), fertility from 4.24 to 4.09 (with the base
   point above), torus_with_holes from 4.07 to 4.04; a tetrahedron and an
   icosahedron unfold into isometric nets (energy 4).  The branches do not
   shorten the solve: the free boundary needs as many or more iterations.

   The split.  Cut edges are unglued: the chart's corners are merged again
   across the remaining interior edges (as >>charts glues them), one chart
   vertex per corner class -- a vertex on the cut gets one copy per fan
   between cut edges -- numbered by first appearance in the triangles.  The
   atlas's corner_vertex is updated so the writers give each side of the
   new seam its own vt; the boundary loops are walked again with the same
   code as before.  chart.cut_edges reports the number of mesh edges cut.

   Importance.  With opt.importance -- painted, or the visibility V_t of
   chapter 4, which bp_parameterize computes before building the charts
   when views are on -- every path is found under costs |uv| times the mean
   relative importance of the edge's two triangles (relative to the chart's
   mean), so seams run where the map matters least, the dissertation's
   importance put to a second use.  Which points are far (the diameter's
   ends, the branch tips, the threshold) is still decided in plain 3D
   lengths: weighted distances would make the important parts look far and
   draw branches into them.  On the cow without vt under a front view
   model, the mean visibility along the seams drops from 1.30 to 0.25.

   Smoothing (below, after the branches): each junction of the cut graph
   is moved to the point that makes its three pieces shortest, and the
   branches run again where a move left a part far from the cut.

   Segmentation into several charts (grown by normal deviation, or split
   when one disk flattens with high distortion) is >>segment's: it works
   on the disks made here. */

/* Scratch of one cut, freed together. */
typedef struct bp__cut {
    uint32_t *twin;      /* 3*nt: corner edge across the edge, or BP__NONE    */
    uint32_t *adj_start, *adj;  /* per vertex, the corner edges at it (CSR)  */
    double   *len;       /* 6*nt: each corner edge's path cost (3D length,
                            importance-weighted), then its 3D length        */
    double   *glen;      /* = len + 3*nt: the 3D lengths                    */
    int       weighted;  /* the costs differ from the lengths               */
    double   *dist;      /* nv: Dijkstra distance                           */
    uint32_t *parent;    /* nv: corner edge to the parent in the tree       */
    unsigned char *cut;  /* 3*nt: corner edge is cut                        */
    unsigned char *in_tree; /* 3*nt: corner edge in the tree T              */
    uint32_t *deg;       /* nv: degree in the cut graph (with boundary)     */
    uint32_t *work;      /* max(3*nt, nv) + 1: union-find, queues, order     */
    uint32_t *work2;     /* max(3*nt, nv) + 1                               */
    double   *heap_d;    /* heap of (distance, vertex): 6*nt + 1            */
    uint32_t *heap_v;
} bp__cut;

static void bp__cut_free(const bp_allocator *a, bp__cut *K)
{
    bp__free(a, K->twin); bp__free(a, K->adj_start); bp__free(a, K->adj); bp__free(a, K->len);
    bp__free(a, K->dist); bp__free(a, K->parent); bp__free(a, K->cut); bp__free(a, K->in_tree);
    bp__free(a, K->deg); bp__free(a, K->work); bp__free(a, K->work2);
    bp__free(a, K->heap_d); bp__free(a, K->heap_v);
}

/* The end vertices of chart corner edge ce = 3t + k: from corner k to k+1. */
static uint32_t bp__ce_from(const bp_chart *ch, uint32_t ce) { return ch->triangles[ce]; }
static uint32_t bp__ce_to(const bp_chart *ch, uint32_t ce) { return ch->triangles[ce - ce % 3 + (ce % 3 + 1) % 3]; }

typedef struct bp__face_pos { uint32_t face, t; } bp__face_pos;

static int bp__face_pos_cmp(const void *pa, const void *pb)
{
    const bp__face_pos *x = (const bp__face_pos *)pa, *y = (const bp__face_pos *)pb;
    return x->face < y->face ? -1 : x->face > y->face;
}

/* The importance of chart triangle t relative to `mean`; 1 where the
   user's value is not positive and finite (bp_chart_optimize reports it). */
static double bp__cut_importance(const bp_chart *ch, const double *importance, uint32_t t, double mean)
{
    double w = importance[ch->face[t]];
    return w > 0 && w < HUGE_VAL ? w / mean : 1;
}

/* Importance-weighted lengths: an edge's length times the mean relative
   importance of its two triangles (its one triangle on the boundary), the
   importance taken relative to its mean over the chart's triangles, so that
   seams go where the map matters least -- where visibility (chapter 4) or
   painted importance is low -- and the branch threshold keeps its scale.
   With uniform importance nothing changes. */
static void bp__cut_weigh(bp__cut *K, const bp_chart *ch, const double *importance)
{
    uint32_t t, k, nt = ch->num_triangles;
    double num = 0, den = 0, mean;
    for (t = 0; t < nt; t++) {
        double w = importance[ch->face[t]];
        if (w > 0 && w < HUGE_VAL) { num += w; den += 1; }
    }
    mean = den > 0 && num > 0 && num < HUGE_VAL ? num / den : 1;
    K->weighted = 1;
    for (t = 0; t < nt; t++) {
        double w0 = bp__cut_importance(ch, importance, t, mean);
        for (k = 0; k < 3; k++) {
            uint32_t ce = 3 * t + k, tw = K->twin[ce];
            double w1 = tw == BP__NONE ? w0 : bp__cut_importance(ch, importance, tw / 3, mean);
            K->len[ce] = K->glen[ce] * 0.5 * (w0 + w1);
        }
    }
}

/* Twins of the chart's corner edges from the mesh-level gluing (glued[mesh
   corner edge]), lengths, and the vertex -> corner edges adjacency (each
   corner edge listed at both of its ends). */
static int bp__cut_adjacency(const bp_allocator *a, bp__cut *K, const bp_chart *ch, const bp_mesh *m,
                             const uint32_t *glued, const double *importance)
{
    uint32_t nt = ch->num_triangles, nv = ch->num_vertices, t, k, ce, v;
    bp__face_pos *fp = (bp__face_pos *)bp__alloc_array(a, nt, sizeof *fp);
    if (!fp) return 0;
    for (t = 0; t < nt; t++) { fp[t].face = ch->face[t]; fp[t].t = t; }
    qsort(fp, nt, sizeof *fp, bp__face_pos_cmp);
    for (t = 0; t < nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t g = glued[3 * (size_t)ch->face[t] + k], lo = 0, hi = nt;
            ce = 3 * t + k;
            K->twin[ce] = BP__NONE;
            K->glen[ce] = K->len[ce] =
                bp__dist3(bp__pos(m, ch->vertex[bp__ce_from(ch, ce)]), bp__pos(m, ch->vertex[bp__ce_to(ch, ce)]));
            if (g == BP__NONE) continue;
            while (lo < hi) {                      /* the chart triangle of mesh triangle g/3 */
                uint32_t mid = lo + (hi - lo) / 2;
                if (fp[mid].face < g / 3) lo = mid + 1; else hi = mid;
            }
            if (lo < nt && fp[lo].face == g / 3) K->twin[ce] = 3 * fp[lo].t + g % 3;
        }
    bp__free(a, fp);
    if (importance) bp__cut_weigh(K, ch, importance);
    for (v = 0; v <= nv; v++) K->adj_start[v] = 0;
    for (ce = 0; ce < 3 * nt; ce++) { K->adj_start[bp__ce_from(ch, ce) + 1]++; K->adj_start[bp__ce_to(ch, ce) + 1]++; }
    for (v = 0; v < nv; v++) K->adj_start[v + 1] += K->adj_start[v];
    for (v = 0; v < nv; v++) K->work[v] = K->adj_start[v];
    for (ce = 0; ce < 3 * nt; ce++) { K->adj[K->work[bp__ce_from(ch, ce)]++] = ce; K->adj[K->work[bp__ce_to(ch, ce)]++] = ce; }
    return 1;
}

/* A binary min-heap of (distance, vertex), ties by vertex: deterministic. */
static int bp__heap_less(const bp__cut *K, uint32_t i, uint32_t j)
{
    return K->heap_d[i] < K->heap_d[j] || (K->heap_d[i] == K->heap_d[j] && K->heap_v[i] < K->heap_v[j]);
}

static void bp__heap_swap(bp__cut *K, uint32_t i, uint32_t j)
{
    double d = K->heap_d[i];
    uint32_t v = K->heap_v[i];
    K->heap_d[i] = K->heap_d[j]; K->heap_v[i] = K->heap_v[j];
    K->heap_d[j] = d; K->heap_v[j] = v;
}

static void bp__heap_push(bp__cut *K, uint32_t *n, double d, uint32_t v)
{
    uint32_t i = (*n)++;
    K->heap_d[i] = d; K->heap_v[i] = v;
    while (i > 0 && bp__heap_less(K, i, (i - 1) / 2)) { bp__heap_swap(K, i, (i - 1) / 2); i = (i - 1) / 2; }
}

static void bp__heap_pop(bp__cut *K, uint32_t *n)
{
    uint32_t i = 0;
    bp__heap_swap(K, 0, --*n);
    for (;;) {
        uint32_t l = 2 * i + 1, r = l + 1, s = i;
        if (l < *n && bp__heap_less(K, l, s)) s = l;
        if (r < *n && bp__heap_less(K, r, s)) s = r;
        if (s == i) break;
        bp__heap_swap(K, i, s);
        i = s;
    }
}

/* Dijkstra on the edge lengths len (K->glen or K->len) from the sources
   (src[v] set, or the single vertex `root` when src is NULL): K->dist, and
   K->parent the corner edge to each vertex's parent.  Each edge is relaxed at most twice,
   so the heap holds at most 6 nt + 1 entries.  Returns the farthest vertex
   reached (the smallest index among equals; a vertex the sources do not
   reach is never returned, its dist stays HUGE_VAL and its parent
   BP__NONE), or root when nothing was reached. */
static uint32_t bp__cut_dijkstra(bp__cut *K, const bp_chart *ch, const double *len, const unsigned char *src,
                                 uint32_t root)
{
    uint32_t nv = ch->num_vertices, v, n = 0, far = BP__NONE, i;
    for (v = 0; v < nv; v++) { K->dist[v] = HUGE_VAL; K->parent[v] = BP__NONE; }
    for (v = 0; v < nv; v++)
        if (src ? src[v] : v == root) { K->dist[v] = 0; bp__heap_push(K, &n, 0.0, v); }
    while (n > 0) {
        double d = K->heap_d[0];
        v = K->heap_v[0];
        bp__heap_pop(K, &n);
        if (d > K->dist[v]) continue;                       /* a stale entry */
        if (far == BP__NONE || d > K->dist[far] || (d == K->dist[far] && v < far)) far = v;
        for (i = K->adj_start[v]; i < K->adj_start[v + 1]; i++) {
            uint32_t ce = K->adj[i], w = bp__ce_from(ch, ce) == v ? bp__ce_to(ch, ce) : bp__ce_from(ch, ce);
            double dw = d + len[ce];
            if (dw < K->dist[w]) { K->dist[w] = dw; K->parent[w] = ce; bp__heap_push(K, &n, dw, w); }
        }
    }
    return far == BP__NONE ? root : far;
}

/* Mark corner edge ce and its twin as cut; 1 if it was not cut before. */
static int bp__cut_mark(bp__cut *K, uint32_t ce)
{
    if (K->cut[ce]) return 0;
    K->cut[ce] = 1;
    if (K->twin[ce] != BP__NONE) K->cut[K->twin[ce]] = 1;
    return 1;
}

/* The ends of an approximate diameter (the essay above): p the farthest
   vertex from vertex 0, returned, and *q the farthest from p, both in 3D
   length; K->dist and K->parent are left as the sweep from p made them. */
static uint32_t bp__cut_diameter(bp__cut *K, const bp_chart *ch, uint32_t *q)
{
    uint32_t p = bp__cut_dijkstra(K, ch, K->glen, NULL, 0);
    *q = bp__cut_dijkstra(K, ch, K->glen, NULL, p);
    return p;
}

/* Closed genus 0: the shortest path between the ends of an approximate
   diameter, at least two edges long. */
static uint32_t bp__cut_sphere(bp__cut *K, const bp_chart *ch)
{
    uint32_t q, p = bp__cut_diameter(K, ch, &q), v = q, n = 0;
    if (ch->num_vertices < 3 || p == q) return 0;
    if (K->weighted) bp__cut_dijkstra(K, ch, K->len, NULL, p);   /* the path by cost */
    if (K->parent[q] == BP__NONE) return 0;                       /* not reached (defensive) */
    if (bp__ce_from(ch, K->parent[q]) == p || bp__ce_to(ch, K->parent[q]) == p) {
        /* adjacent: go around the third corner of the edge's triangle */
        uint32_t ce = K->parent[q], e1 = ce - ce % 3 + (ce % 3 + 1) % 3, e2 = ce - ce % 3 + (ce % 3 + 2) % 3;
        return (uint32_t)(bp__cut_mark(K, e1) + bp__cut_mark(K, e2));
    }
    while (v != p && K->parent[v] != BP__NONE) {
        uint32_t ce = K->parent[v];
        n += (uint32_t)bp__cut_mark(K, ce);
        v = bp__ce_from(ch, ce) == v ? bp__ce_to(ch, ce) : bp__ce_from(ch, ce);
    }
    return n;
}

/* The base point of a closed chart: the middle (in 3D length) of the
   shortest path between the ends of an approximate diameter, so that the
   loops through it are short from every side. */
static uint32_t bp__cut_center(bp__cut *K, const bp_chart *ch)
{
    uint32_t q, p = bp__cut_diameter(K, ch, &q), v = q;
    double half = 0.5 * K->dist[q];
    while (v != p && K->dist[v] > half && K->parent[v] != BP__NONE) {
        uint32_t e = K->parent[v];
        v = bp__ce_from(ch, e) == v ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
    }
    return v;
}

/* Kruskal order: longer loops first, edges of T last, then by index. */
typedef struct bp__loop_edge { double w; uint32_t ce; } bp__loop_edge;

static int bp__loop_edge_cmp(const void *pa, const void *pb)
{
    const bp__loop_edge *x = (const bp__loop_edge *)pa, *y = (const bp__loop_edge *)pb;
    if (x->w != y->w) return x->w > y->w ? -1 : 1;
    return x->ce < y->ce ? -1 : x->ce > y->ce;
}

/* Genus > 0: the tree-cotree cut graph (the essay above), before pruning:
   every interior edge not in the dual tree C is cut.  0 if out of memory. */
static int bp__cut_cotree(const bp_allocator *a, bp__cut *K, const bp_chart *ch)
{
    uint32_t nt = ch->num_triangles, nv = ch->num_vertices, ce, v, ne = 0, i;
    unsigned char *src = (unsigned char *)bp__calloc_array(a, nv, 1);
    bp__loop_edge *le = (bp__loop_edge *)bp__alloc_array(a, 3 * (size_t)nt / 2 + 1, sizeof *le);
    uint32_t *uf = K->work;
    if (!src || !le) { bp__free(a, src); bp__free(a, le); return 0; }
    for (ce = 0; ce < 3 * nt; ce++)
        if (K->twin[ce] == BP__NONE) src[bp__ce_from(ch, ce)] = src[bp__ce_to(ch, ce)] = 1;
    bp__cut_dijkstra(K, ch, K->len, ch->num_loops ? src : NULL, ch->num_loops ? 0 : bp__cut_center(K, ch));
    bp__free(a, src);
    for (v = 0; v < nv; v++)
        if (K->parent[v] != BP__NONE) {
            K->in_tree[K->parent[v]] = 1;
            if (K->twin[K->parent[v]] != BP__NONE) K->in_tree[K->twin[K->parent[v]]] = 1;
        }
    for (ce = 0; ce < 3 * nt; ce++)
        if (K->twin[ce] != BP__NONE && ce < K->twin[ce]) {
            le[ne].w = K->in_tree[ce] ? -1.0 :    /* loop length d(u) + d(v) + |uv| >= 0 */
                       K->dist[bp__ce_from(ch, ce)] + K->dist[bp__ce_to(ch, ce)] + K->len[ce];
            le[ne++].ce = ce;
        }
    qsort(le, ne, sizeof *le, bp__loop_edge_cmp);
    for (i = 0; i < nt; i++) uf[i] = i;
    for (i = 0; i < ne; i++) {
        uint32_t t0 = bp__uf_find(uf, le[i].ce / 3), t1 = bp__uf_find(uf, K->twin[le[i].ce] / 3);
        if (t0 != t1) bp__uf_union(uf, t0, t1);  /* in C: stays glued */
        else bp__cut_mark(K, le[i].ce);
    }
    bp__free(a, le);
    return 1;
}

/* Prune the cut graph: glue back cut edges with an end of degree 1 (the
   degree counts boundary edges, so boundary vertices never qualify).
   Returns the number of cut mesh edges left. */
static uint32_t bp__cut_prune(bp__cut *K, const bp_chart *ch)
{
    uint32_t nt = ch->num_triangles, nv = ch->num_vertices, ce, v, nq = 0, left = 0, i;
    uint32_t *queue = K->work2;
    for (v = 0; v < nv; v++) K->deg[v] = 0;
    for (ce = 0; ce < 3 * nt; ce++)
        if (K->twin[ce] == BP__NONE || (K->cut[ce] && ce < K->twin[ce])) {
            K->deg[bp__ce_from(ch, ce)]++;
            K->deg[bp__ce_to(ch, ce)]++;
            left += K->twin[ce] != BP__NONE;
        }
    for (v = 0; v < nv; v++)
        if (K->deg[v] == 1) queue[nq++] = v;
    while (nq > 0) {
        v = queue[--nq];
        if (K->deg[v] != 1) continue;
        for (i = K->adj_start[v]; i < K->adj_start[v + 1]; i++) {
            uint32_t e = K->adj[i], w;
            if (!K->cut[e] || K->twin[e] == BP__NONE) continue;
            w = bp__ce_from(ch, e) == v ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
            K->cut[e] = K->cut[K->twin[e]] = 0;
            K->deg[v]--;
            left--;
            if (--K->deg[w] == 1) queue[nq++] = w;
            break;
        }
    }
    return left;
}

/* Extremity branches (the essay above): tau = BP__CUT_BRANCH sqrt(area). */
#define BP__CUT_BRANCH 0.3

/* While some vertex lies farther than tau from the cut graph and the
   boundary (Dijkstra from all of them), cut the shortest path from the
   farthest one to them.  A slit from the boundary into a disk keeps a disk
   (V and E both grow by the path's length).  At most 16 branches.  Returns
   the edges added; *oom set if the scratch could not be allocated. */
static uint32_t bp__cut_branches(const bp_allocator *a, bp__cut *K, const bp_chart *ch, double tau, int *oom)
{
    uint32_t nt = ch->num_triangles, ce, n = 0, b;
    unsigned char *src = (unsigned char *)bp__calloc_array(a, ch->num_vertices, 1);
    if (!src) { *oom = 1; return 0; }
    for (ce = 0; ce < 3 * nt; ce++)
        if (K->cut[ce] || K->twin[ce] == BP__NONE) src[bp__ce_from(ch, ce)] = src[bp__ce_to(ch, ce)] = 1;
    for (b = 0; b < 16; b++) {
        uint32_t v = bp__cut_dijkstra(K, ch, K->glen, src, 0);    /* the farthest in 3D */
        if (!(K->dist[v] > tau) || K->parent[v] == BP__NONE) break;
        if (K->weighted) bp__cut_dijkstra(K, ch, K->len, src, 0); /* its path by cost */
        while (!src[v] && K->parent[v] != BP__NONE) {
            uint32_t e = K->parent[v];
            n += (uint32_t)bp__cut_mark(K, e);
            src[v] = 1;
            v = bp__ce_from(ch, e) == v ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
        }
    }
    bp__free(a, src);
    return n;
}

/* ---- smoothing: the junctions of the cut moved ---------------------------

   The cut graph's paths were found one at a time -- the handle loops as two
   shortest paths from one base point closed by an edge, each extremity
   branch as the shortest path from its tip to the cut found so far -- so
   where three paths meet, the meeting point (a junction: a vertex of cut
   degree 3 inside the chart) is wherever the earlier path happened to run.
   A piece of the cut between two branch points (vertices of cut degree
   other than 2, or on the chart's boundary) cannot be shortened with its
   ends kept: measured on fertility, torus_with_holes and the cow without
   vt, every one of the 39 pieces (all 569 cut edges) is already the
   cheapest path between its ends through the disk the cut opens (the
   homotopy class it must keep).  What can be shortened is the Steiner
   point: the three pieces from a junction J to their far ends A_0, A_1,
   A_2 are glued back, and the vertex X of what is left (off its boundary)
   that minimizes d(X, A_0) + d(X, A_1) + d(X, A_2) becomes the junction,
   joined to each A_k by a shortest path (Dijkstra from each A_k, starting
   into the fan of A_k that its piece came from, stopping at the old three
   pieces' cost, so the search stays in a band around them).  The move is
   kept only when it is strictly cheaper and the cut still opens a disk --
   the opened chart connected with chi = 1, checked exactly on the corner
   classes -- else everything is put back; the split below checks chi and
   the loops once more.  Passes over the junctions (in vertex order) repeat
   while a junction moves, at most BP__CUT_SMOOTH_PASSES times.

   A moved junction can leave a part of the surface farther than tau from
   the cut, the distance the extremity branches guarantee; so the branches
   run again after the moves (at most 16 more), and the junctions they
   create are moved in turn (which may leave a little of that distance
   behind again: the second round is not repeated).  On the cow without vt
   the second round takes the cut from 146 edges (moves alone) to 171 and
   the mean energy from 4.53 to 4.33.  Measured (--atlas 1024 --padding 4, 1 thread, this commit against
   the cut without moves): fertility 350 -> 326 edges cut, cut length
   -6.2%, utilization 0.360 -> 0.375, mean symmetric Dirichlet 4.086 ->
   4.099; torus_with_holes 61 -> 61 edges, length -1.7%, 0.358 -> 0.357,
   4.041 -> 4.038; the cow without vt 158 -> 171 edges (the branches
   again), length +2.5%, 0.466 -> 0.504, 4.426 -> 4.329.  Costs are the
   cut's own (3D length, importance-weighted with importance).  Serial and
   deterministic (ties by vertex index). */
#define BP__CUT_SMOOTH_PASSES 3

typedef struct bp__smooth {
    uint32_t *vdeg;           /* nv: cut degree of each chart vertex          */
    unsigned char *vbnd;      /* nv: on the chart's own boundary              */
    unsigned char *dirty;     /* nv: a junction worth trying (again) in this
                                 pass: all at first, then the ends of moves  */
    double   *d[3];           /* nv: cost from each far end (HUGE_VAL: not reached) */
    uint32_t *via[3];         /* nv: corner edge reached by                   */
    uint32_t *touched[3], nt_[3]; /* vertices whose d[k] was set            */
    uint32_t *seg, *tri, *path; /* a piece's corner edges; the three pieces';
                                 the new ones                                */
} bp__smooth;

static uint32_t bp__ce_next(uint32_t ce) { return ce - ce % 3 + (ce % 3 + 1) % 3; }
static uint32_t bp__ce_prev(uint32_t ce) { return ce - ce % 3 + (ce % 3 + 2) % 3; }

static void bp__smooth_free(const bp_allocator *a, bp__smooth *S)
{
    int k;
    for (k = 0; k < 3; k++) { bp__free(a, S->d[k]); bp__free(a, S->via[k]); bp__free(a, S->touched[k]); }
    bp__free(a, S->vdeg); bp__free(a, S->vbnd); bp__free(a, S->dirty); bp__free(a, S->seg); bp__free(a, S->tri); bp__free(a, S->path);
}

/* Cut (on = 1) or glue (0) the mesh edge of corner edge e, keeping vdeg. */
static void bp__smooth_cut(bp__cut *K, bp__smooth *S, const bp_chart *ch, uint32_t e, unsigned char on)
{
    int delta = on ? 1 : -1;
    if (K->cut[e] == on) return;
    K->cut[e] = K->cut[K->twin[e]] = on;
    S->vdeg[bp__ce_from(ch, e)] += (uint32_t)delta;
    S->vdeg[bp__ce_to(ch, e)] += (uint32_t)delta;
}

/* Does the cut open the chart into a disk: the corner classes across the
   uncut interior edges (as bp__cut_split merges them) give chi = 1, and
   the triangles stay connected across them? */
static int bp__cut_opens_disk(const bp__cut *K, const bp_chart *ch)
{
    uint32_t nt = ch->num_triangles, nc = 3 * nt, ce, t, ncls = 0, nb = 0, roots = 0;
    uint32_t *uf = K->work;
    for (ce = 0; ce < nc; ce++) uf[ce] = ce;
    for (ce = 0; ce < nc; ce++) {
        uint32_t tw = K->twin[ce];
        if (tw == BP__NONE || K->cut[ce]) { nb++; continue; }
        if (tw < ce) continue;
        bp__uf_union(uf, ce, bp__ce_next(tw));
        bp__uf_union(uf, bp__ce_next(ce), tw);
    }
    for (ce = 0; ce < nc; ce++) ncls += bp__uf_find(uf, ce) == ce;
    for (t = 0; t < nt; t++) uf[t] = t;
    for (ce = 0; ce < nc; ce++)
        if (K->twin[ce] != BP__NONE && !K->cut[ce]) bp__uf_union(uf, ce / 3, K->twin[ce] / 3);
    for (t = 0; t < nt; t++) roots += uf[t] == t;
    return roots == 1 && (int64_t)ncls - ((int64_t)nc + nb) / 2 + nt == 1;
}

static int bp__smooth_branch(const bp__smooth *S, uint32_t v) { return S->vbnd[v] || S->vdeg[v] != 2; }

/* The piece from cut corner edge ce (leaving a branch point) to the next
   branch point, through vertices of cut degree 2: its corner edges in
   S->seg, each leaving the previous one's end.  Returns their number, 0 if
   the walk does not end (defensive). */
static uint32_t bp__smooth_piece(const bp__cut *K, const bp__smooth *S, const bp_chart *ch, uint32_t ce)
{
    uint32_t n = 0, e = ce, nc = 3 * ch->num_triangles, v, i;
    for (;;) {
        if (n >= nc) return 0;
        S->seg[n++] = e;
        v = bp__ce_to(ch, e);
        if (bp__smooth_branch(S, v)) return n;
        for (i = K->adj_start[v]; i < K->adj_start[v + 1]; i++) {
            uint32_t f = K->adj[i];
            if (K->cut[f] && K->twin[f] != BP__NONE && f != e && f != K->twin[e] && bp__ce_from(ch, f) == v) break;
        }
        if (i == K->adj_start[v + 1]) return 0;
        e = K->adj[i];
    }
}

/* Relax from vertex v (cost d) to the other end of corner edge e, when that
   end is off the cut and the boundary. */
static void bp__smooth_relax(bp__cut *K, bp__smooth *S, const bp_chart *ch, int k, uint32_t v, uint32_t e,
                             double d, uint32_t *n)
{
    uint32_t w = bp__ce_from(ch, e) == v ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
    double dw = d + K->len[e];
    if (S->vdeg[w] || S->vbnd[w] || !(dw < S->d[k][w])) return;
    if (S->d[k][w] == HUGE_VAL) S->touched[k][S->nt_[k]++] = w;
    S->d[k][w] = dw;
    S->via[k][w] = e;
    bp__heap_push(K, n, dw, w);
}

/* Dijkstra from far end A (chart vertex), leaving it only into the fan of
   corner c0 (the corner at A of the triangle its piece ended in), bounded
   by `bound`; through vertices off the cut and the boundary. */
static void bp__smooth_grow(bp__cut *K, bp__smooth *S, const bp_chart *ch, int k, uint32_t A, uint32_t c0,
                            double bound)
{
    uint32_t n = 0, c, e, dir, i;
    for (dir = 0; dir < 2; dir++)                /* around A both ways, up to a cut or boundary edge */
        for (c = c0;;) {
            bp__smooth_relax(K, S, ch, k, A, c, 0.0, &n);
            bp__smooth_relax(K, S, ch, k, A, bp__ce_prev(c), 0.0, &n);
            e = dir ? bp__ce_prev(c) : c;
            if (K->twin[e] == BP__NONE || K->cut[e]) break;
            c = dir ? K->twin[e] : bp__ce_next(K->twin[e]);
            if (c == c0) break;
        }
    while (n > 0) {
        double d = K->heap_d[0];
        uint32_t v = K->heap_v[0];
        bp__heap_pop(K, &n);
        if (d > S->d[k][v]) continue;
        if (!(d < bound)) break;
        for (i = K->adj_start[v]; i < K->adj_start[v + 1]; i++) bp__smooth_relax(K, S, ch, k, v, K->adj[i], d, &n);
    }
}

/* Move junction J (the essay above); 1 if it moved. */
static int bp__smooth_junction(bp__cut *K, bp__smooth *S, const bp_chart *ch, uint32_t J)
{
    uint32_t i, k, n = 0, start[3], ns = 0, far[3], c0[3], X = BP__NONE, nnew = 0;
    double old = 0, best = HUGE_VAL, cost = 0;
    int moved = 0;
    for (i = K->adj_start[J]; i < K->adj_start[J + 1]; i++) {
        uint32_t ce = K->adj[i];
        if (K->cut[ce] && K->twin[ce] != BP__NONE && bp__ce_from(ch, ce) == J) {
            if (ns == 3) return 0;
            start[ns++] = ce;
        }
    }
    if (ns != 3) return 0;
    for (k = 0; k < 3; k++) {                    /* the three pieces */
        uint32_t m = bp__smooth_piece(K, S, ch, start[k]);
        if (m == 0 || n + m > 3 * ch->num_triangles) return 0;
        far[k] = bp__ce_to(ch, S->seg[m - 1]);
        c0[k] = bp__ce_next(S->seg[m - 1]);     /* the corner at far[k] beside the piece */
        if (far[k] == J) return 0;               /* a loop back to J */
        memcpy(S->tri + n, S->seg, m * sizeof(uint32_t));
        n += m;
    }
    for (i = 0; i < n; i++) { old += K->len[S->tri[i]]; bp__smooth_cut(K, S, ch, S->tri[i], 0); }
    /* searches 0 and 1 to `old`; then m01 = min (d0 + d1) bounds the third:
       a better X has d2(X) < old - (d0 + d1)(X) <= old - m01.  The last
       piece found (k = 2) is searched last. */
    bp__smooth_grow(K, S, ch, 0, far[0], c0[0], old);
    bp__smooth_grow(K, S, ch, 1, far[1], c0[1], old);
    for (i = 0; i < S->nt_[0]; i++) {
        uint32_t x = S->touched[0][i];
        if (S->d[0][x] + S->d[1][x] < best) best = S->d[0][x] + S->d[1][x];
    }
    if (best < old) bp__smooth_grow(K, S, ch, 2, far[2], c0[2], old - best);
    best = HUGE_VAL;
    for (i = 0; i < S->nt_[2]; i++) {            /* X: reached from all three */
        uint32_t x = S->touched[2][i];
        double c = S->d[0][x] + S->d[1][x] + S->d[2][x];
        if (c < best || (c == best && x < X)) { best = c; X = x; }
    }
    if (X != BP__NONE && best < old * (1 - 1e-9)) {
        for (k = 0; k < 3; k++) {
            uint32_t x = X;
            while (x != far[k]) {
                uint32_t e = S->via[k][x];
                if (!K->cut[e]) { bp__smooth_cut(K, S, ch, e, 1); S->path[nnew++] = e; cost += K->len[e]; }
                x = bp__ce_from(ch, e) == x ? bp__ce_to(ch, e) : bp__ce_from(ch, e);
            }
        }
        moved = cost < old * (1 - 1e-9) && bp__cut_opens_disk(K, ch);
        if (!moved)
            for (i = 0; i < nnew; i++) bp__smooth_cut(K, S, ch, S->path[i], 0);
        else                                     /* try the new junction and the far ends again */
            for (k = 0; k < 3; k++) S->dirty[far[k]] = S->dirty[X] = 1;
    }
    if (!moved)                                  /* put the three pieces back */
        for (i = 0; i < n; i++) bp__smooth_cut(K, S, ch, S->tri[i], 1);
    for (k = 0; k < 3; k++) {                    /* reset what the searches touched */
        for (i = 0; i < S->nt_[k]; i++) S->d[k][S->touched[k][i]] = HUGE_VAL;
        S->nt_[k] = 0;
    }
    return moved;
}

/* The smoothing passes (the essay above).  Returns the number of junctions
   moved; *oom when the scratch could not be allocated. */
static uint32_t bp__cut_smooth(const bp_allocator *a, bp__cut *K, const bp_chart *ch, int *oom)
{
    bp__smooth S;
    uint32_t nt = ch->num_triangles, nc = 3 * nt, nv = ch->num_vertices, changed = 0, pass, v, ce;
    int k, ok = 1;
    memset(&S, 0, sizeof S);
    for (k = 0; k < 3; k++) {
        S.d[k] = (double *)bp__alloc_array(a, nv, sizeof(double));
        S.via[k] = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
        S.touched[k] = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
        ok = ok && S.d[k] && S.via[k] && S.touched[k];
    }
    S.vdeg = (uint32_t *)bp__calloc_array(a, nv, sizeof(uint32_t));
    S.vbnd = (unsigned char *)bp__calloc_array(a, nv, 1);
    S.dirty = (unsigned char *)bp__alloc_array(a, nv, 1);
    S.seg = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    S.tri = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    S.path = (uint32_t *)bp__alloc_array(a, nc, sizeof(uint32_t));
    if (!ok || !S.vdeg || !S.vbnd || !S.dirty || !S.seg || !S.tri || !S.path) {
        bp__smooth_free(a, &S);
        *oom = 1;
        return 0;
    }
    for (k = 0; k < 3; k++)
        for (v = 0; v < nv; v++) S.d[k][v] = HUGE_VAL;
    for (ce = 0; ce < nc; ce++) {
        if (K->twin[ce] == BP__NONE) S.vbnd[bp__ce_from(ch, ce)] = S.vbnd[bp__ce_to(ch, ce)] = 1;
        else if (K->cut[ce] && ce < K->twin[ce]) { S.vdeg[bp__ce_from(ch, ce)]++; S.vdeg[bp__ce_to(ch, ce)]++; }
    }
    memset(S.dirty, 1, nv);
    if (bp__cut_opens_disk(K, ch))               /* only a cut that opens a disk */
        for (pass = 0; pass < BP__CUT_SMOOTH_PASSES; pass++) {
            uint32_t before = changed;
            for (v = 0; v < nv; v++) {
                if (!S.dirty[v]) continue;
                S.dirty[v] = 0;
                if (S.vdeg[v] == 3 && !S.vbnd[v]) changed += (uint32_t)bp__smooth_junction(K, &S, ch, v);
            }
            if (changed == before) break;
        }
    bp__smooth_free(a, &S);
    return changed;
}

/* Split the chart along the cut edges: new chart vertices (one per corner
   class across the uncut interior edges), triangles, vertex, vertex_uv,
   the atlas's corner_vertex, and the mesh-level gluing of the cut edges
   (so the loop walk sees them as boundary).  0 if out of memory. */
static int bp__cut_split(const bp_allocator *a, bp__cut *K, bp_chart *ch, uint32_t *corner_vertex,
                         uint32_t *glued)
{
    uint32_t nt = ch->num_triangles, nc = 3 * nt, ce, nnv = 0;
    uint32_t *uf = K->work, *id = K->work2, *vtx, *vuv;
    for (ce = 0; ce < nc; ce++) { uf[ce] = ce; id[ce] = BP__NONE; }
    for (ce = 0; ce < nc; ce++) {
        uint32_t tw = K->twin[ce];
        if (tw == BP__NONE || K->cut[ce] || tw < ce) continue;
        bp__uf_union(uf, ce, tw - tw % 3 + (tw % 3 + 1) % 3);    /* corner at the edge's start */
        bp__uf_union(uf, ce - ce % 3 + (ce % 3 + 1) % 3, tw);    /* corner at its end          */
    }
    for (ce = 0; ce < nc; ce++) {
        uint32_t r = bp__uf_find(uf, ce);
        if (id[r] == BP__NONE) id[r] = nnv++;
    }
    vtx = (uint32_t *)bp__alloc_array(a, nnv, sizeof(uint32_t));
    vuv = (uint32_t *)bp__alloc_array(a, nnv, sizeof(uint32_t));
    if (!vtx || !vuv) { bp__free(a, vtx); bp__free(a, vuv); return 0; }
    for (ce = 0; ce < nc; ce++) {
        uint32_t old = ch->triangles[ce], nw = id[bp__uf_find(uf, ce)], k = ce % 3;
        size_t f3 = 3 * (size_t)ch->face[ce / 3];
        /* chart corner k is corner k of the glued mesh (glued[] counts so),
           but corner_vertex is per corner of the user's mesh: a triangle
           the repair re-oriented runs its corners (0, 2, 1) in the chart,
           seen (before corner 0 is rewritten) as chart corner 1 not being
           the chart vertex of mesh corner 1 */
        int flipped = ch->triangles[ce - k + 1] != corner_vertex[f3 + 1] && ch->triangles[ce - k] == corner_vertex[f3];
        vtx[nw] = ch->vertex[old];
        vuv[nw] = ch->vertex_uv[old];
        if (K->cut[ce]) glued[f3 + k] = BP__NONE;
        if (k == 2) {                            /* the whole triangle at once */
            uint32_t n0 = id[bp__uf_find(uf, ce - 2)], n1 = id[bp__uf_find(uf, ce - 1)];
            corner_vertex[f3] = n0;
            corner_vertex[f3 + 1] = flipped ? nw : n1;
            corner_vertex[f3 + 2] = flipped ? n1 : nw;
        }
    }
    for (ce = 0; ce < nc; ce++) ch->triangles[ce] = id[bp__uf_find(uf, ce)];
    bp__free(a, ch->vertex);
    bp__free(a, ch->vertex_uv);
    ch->vertex = vtx;
    ch->vertex_uv = vuv;
    ch->num_vertices = nnv;
    return 1;
}

/* Cut chart c (a closed chart or one of genus > 0, already through the
   topology check, which put BP_ERR_TOPOLOGY in its error) into a disk, walk
   its loops again and check that chi = 1 - (holes kept): the chart's error
   is then cleared.  next / loop_id / glued are >>charts' arrays (next and
   loop_id hold at least 3 nt entries).  Returns a status only for what ends
   the whole call (out of memory). */
static bp_status bp__chart_cut(const bp_allocator *a, bp_atlas *atlas, uint32_t c, const bp_mesh *m,
                               const double *importance, uint32_t *glued, uint32_t *next, uint32_t *loop_id,
                               bp_error *err)
{
    bp_chart *ch = &atlas->charts[c];
    bp__cut K;
    uint32_t nt = ch->num_triangles, nv = ch->num_vertices, big = (3 * nt > nv ? 3 * nt : nv) + 1, ncut = 0;
    int64_t ne, chi;
    int ok, oom = 0;
    bp_status st;
    char nm[48];
    memset(&K, 0, sizeof K);
    K.twin = (uint32_t *)bp__alloc_array(a, 3 * (size_t)nt, sizeof(uint32_t));
    K.adj_start = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    K.adj = (uint32_t *)bp__alloc_array(a, 6 * (size_t)nt, sizeof(uint32_t));
    K.len = (double *)bp__alloc_array(a, 6 * (size_t)nt, sizeof(double));
    K.glen = K.len ? K.len + 3 * (size_t)nt : NULL;
    K.dist = (double *)bp__alloc_array(a, nv, sizeof(double));
    K.parent = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    K.cut = (unsigned char *)bp__calloc_array(a, 3 * (size_t)nt, 1);
    K.in_tree = (unsigned char *)bp__calloc_array(a, 3 * (size_t)nt, 1);
    K.deg = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    K.work = (uint32_t *)bp__alloc_array(a, big, sizeof(uint32_t));
    K.work2 = (uint32_t *)bp__alloc_array(a, big, sizeof(uint32_t));
    K.heap_d = (double *)bp__alloc_array(a, 6 * (size_t)nt + 1, sizeof(double));
    K.heap_v = (uint32_t *)bp__alloc_array(a, 6 * (size_t)nt + 1, sizeof(uint32_t));
    ok = K.twin && K.adj_start && K.adj && K.len && K.dist && K.parent && K.cut && K.in_tree && K.deg &&
         K.work && K.work2 && K.heap_d && K.heap_v && bp__cut_adjacency(a, &K, ch, m, glued, importance);
    if (ok) {                                  /* the cut graph (the essay above) */
        chi = (int64_t)nv - ((int64_t)3 * nt + ch->loop_start[ch->num_loops]) / 2 + nt;
        if (ch->num_loops == 0 && chi == 2) ncut = bp__cut_sphere(&K, ch);
        else if ((ok = bp__cut_cotree(a, &K, ch)) != 0) ncut = bp__cut_prune(&K, ch);
    }
    if (ok) {
        double tau = BP__CUT_BRANCH * sqrt(ch->area3d);
        uint32_t ce;
        bp__cut_branches(a, &K, ch, tau, &oom);
        /* the junctions moved; where that left a part far from the cut, the
           branches again, and their junctions moved (the smoothing essay) */
        if (!oom && bp__cut_smooth(a, &K, ch, &oom) > 0 && !oom && bp__cut_branches(a, &K, ch, tau, &oom) > 0 && !oom)
            bp__cut_smooth(a, &K, ch, &oom);
        for (ncut = 0, ce = 0; ce < 3 * nt; ce++) ncut += K.cut[ce] && K.twin[ce] != BP__NONE && ce < K.twin[ce];
        ok = !oom && bp__cut_split(a, &K, ch, atlas->corner_vertex, glued);
    }
    bp__cut_free(a, &K);
    if (!ok) return bp__oom(err, "cutting a chart into a disk");
    bp__free(a, ch->loop_start); bp__free(a, ch->loop_vertices);
    ch->loop_start = ch->loop_vertices = NULL;
    ch->num_loops = 0;
    if ((st = bp__chart_loops(a, ch, m, next, loop_id, glued, c, err)) != BP_OK) return st;
    ch->cut_edges = ncut;
    ne = ((int64_t)3 * nt + ch->loop_start[ch->num_loops]) / 2;
    chi = (int64_t)ch->num_vertices - ne + nt;
    if (ch->num_loops > 0 && chi == 2 - (int64_t)ch->num_loops) bp__ok(&ch->error);
    else
        bp__fail(&ch->error, BP_ERR_TOPOLOGY, BP_ELEMENT_CHART, c, -1, bp__tri_line(m, ch->face[0]),
                 "chart %u (from %s): cutting %u edges left Euler characteristic %D with %u boundary loops, "
                 "not a disk", c, bp__tri_name(m, ch->face[0], nm), ncut, chi, ch->num_loops);
    return BP_OK;
}

/* >>sparse =================================================================

   The start map solves a sparse linear system (the Tutte / Floater
   Laplacian), and later solvers reuse the same machinery.  It is a direct
   solver in three steps, each a classic:

   1. Ordering.  Elimination creates fill; on mesh graphs nested dissection
      keeps it near O(n log n).  We split the graph by a level set of a
      breadth-first search from a pseudo-peripheral vertex (a level is a
      separator: no edge jumps over a BFS level), order both halves first
      and the separator last, and recurse.  Disconnected pieces are ordered
      one after the other.  For the supernodal factorization the cut is
      the best of three distance keys, then shortened by
      Fiduccia-Mattheyses moves (bp__nd_refine), which halves the
      factorization's flops on real charts.
   2. Symbolic.  The elimination tree (Liu's algorithm with path compression)
      and, for each row k, the "row subtree" reach of A(0:k-1, k) in it give
      the exact pattern of L, so its storage is allocated once, by rows.
   3. Numeric, up-looking.  Row k of L and column k of U are the solutions of
      two sparse triangular systems with that pattern:
          L(0:k,0:k) U(0:k,k) = A(0:k,k),    U(0:k,0:k)^T L(k,0:k)^T = A(k,0:k)^T,
          U(k,k) = A(k,k) - L(k,0:k) U(0:k,k).
      For a symmetric matrix U = D L^T and the second solve is skipped: this
      is the LDL^T (square-root free Cholesky) factorization.  Every
      system solved here is stable without pivoting: the start map's
      uniform Laplacian (SPD) and mean-value one (diagonally dominant
      M-matrix), the preconditioner's cotangent Laplacian (>>lbfgs) and
      Newton's H + delta I (>>newton), both SPD by their shift.
      Solved by gathers along rows already computed, row k is exactly what
      is stored, so L exists once, by rows, sorted (no column copy: 8 bytes
      per entry in the preconditioner's single precision, against 16 for L
      by columns and by rows).  Rows in disjoint subtrees of the dissection
      never meet, so they are computed in parallel phases.
   The start map's solves are followed by one step of iterative refinement;
   the preconditioner's and Newton's (which only shape a search direction,
   checked like any other) are not.
   Newton's systems, symmetric positive definite and in 2x2 blocks (x, y of
   a vertex; bp__sparse.blocks2), take a supernodal Cholesky instead
   (bp__super_*, its essay before bp__super_graph), through the same
   bp__factorize, bp__fact_numeric and bp__factor_solve; so do the scalar
   SPD systems with blocks of 1 (bp__sparse.super1: the preconditioner's
   Laplacian, converted afterwards to the single-precision rows its
   solves read, and the uniform Tutte system), and the mean-value system
   is solved by BiCGSTAB preconditioned with the supernodal Cholesky of
   its symmetrized Laplacian (>>tutte, phase 6a).  The up-looking rows
   remain as the fallback: the mean-value LU when the iteration does not
   converge, and any scalar system whose Cholesky meets a pivot that is
   not positive (the rows' LDL^T needs only nonzero pivots). */

typedef struct bp__sparse {       /* n x n, compressed columns            */
    uint32_t n;
    uint32_t *colp;               /* n+1                                  */
    uint32_t *row;                /* sorted rows, diagonal included       */
    double   *val;
    int       symmetric;          /* values symmetric (pattern always is) */
    int       blocks2;            /* symmetric, in whole 2x2 blocks (x, y of
                                     a vertex): bp__factorize goes supernodal */
    int       super1;             /* symmetric and positive definite, scalar:
                                     supernodal too, with blocks of 1 (the
                                     scalar rows when a pivot fails); 2:
                                     refactored at every iteration (Newton's
                                     isotropic K1), keep a scatter map    */
} bp__sparse;

/* The top of the nested-dissection tree: node k covers the permuted range
   [lo, hi) = [A | B | S] with A = [lo, a), B = [a, b), S = [b, hi) and
   children 2k+1 (A) and 2k+2 (B); a node that was not split is a leaf.  Its
   subtrees are independent in the factorization and the triangular solves,
   which is what lets them run on several threads. */
#define BP__ND_DEPTH 4
#define BP__ND_NODES 31                 /* 2^(depth+1) - 1 */
typedef struct bp__ndnode {
    uint32_t lo, a, b, hi;
    int used, split;
    uint32_t ncut, poff;          /* separator: column ranges of the solve
                                     plan, and where its rows' cuts start */
} bp__ndnode;

/* The supernodal factor of a matrix in 2x2 blocks (the essay before
   bp__super_graph below).  Supernode s is the run of vertices
   [first[s], first[s+1]) of the new order; its rows are the vertices
   ri[rp[s] .. rp[s+1]) (its own first, then those below, increasing), and
   its part of L is one dense block at x + xp[s] of 2|rows| x 2|cols|
   doubles by rows (row 2i + a, column 2j + b: coordinate a of row vertex
   i, coordinate b of column vertex j).  Supernode s receives updates from
   the supernodes uk[up[s] .. up[s+1]) (increasing), each from its row
   position uo[] on. */
typedef struct bp__super {
    uint32_t  nv, ns;             /* vertices (the matrix is bs nv x bs nv), supernodes */
    uint32_t  bs;                 /* the block size: 2 (Newton's x, y), or 1
                                     (a scalar matrix: vertex = unknown);
                                     row i of a block is vertex i >> (bs-1),
                                     coordinate i & (bs-1): no division  */
    uint32_t *vperm, *viperm;     /* vertex order: new -> old, old -> new   */
    uint32_t *first;              /* ns+1                                   */
    uint32_t *snode;              /* nv: the supernode of each new vertex    */
    uint32_t *rp, *ri;            /* ns+1; rp[ns]                           */
    size_t   *xp;                 /* ns+1                                   */
    double   *x;                  /* xp[ns]: the blocks of L                */
    uint32_t *up, *uk, *uo;       /* ns+1; up[ns]; up[ns]                   */
    uint32_t  ntask, maxcols;     /* work arrays: tasks of a phase, bs max |cols| */
    uint32_t  maxrows;            /* ... and max |rows|                     */
    uint32_t *amap;               /* bs 2: per entry p of A, its row of its
                                     supernode's block (BP__NONE above the
                                     supernode), or NULL                   */
    int       amap_ok;            /* amap filled (by the first numeric)    */
} bp__super;

static void bp__super_free(const bp_allocator *a, bp__super *S)
{
    if (!S) return;
    bp__free(a, S->vperm); bp__free(a, S->viperm); bp__free(a, S->first); bp__free(a, S->snode);
    bp__free(a, S->rp); bp__free(a, S->ri); bp__free(a, S->xp); bp__free(a, S->x);
    bp__free(a, S->up); bp__free(a, S->uk); bp__free(a, S->uo); bp__free(a, S->amap);
    bp__free(a, S);
}

/* L is stored once, by rows, each row sorted by column: the row k computed
   by the up-looking step is exactly what is stored, and both triangular
   solves read rows (forward by gathers, backward by scatters). */
typedef struct bp__factor {
    uint32_t  n;
    int       symmetric;
    uint32_t *perm, *iperm;       /* new -> old, old -> new               */
    uint32_t *Rp, *Ri;            /* strictly lower L by rows             */
    double   *Rx, *Ux, *D;        /* L(i,j) at row i, column j; Ux there:
                                     U(j,i) (U^T by rows); D: diagonal of U */
    float    *Rxf;                /* the preconditioner's L in single
                                     precision (it reuses Rx's storage)   */
    uint32_t *cutp;               /* the solve plan (bp__solve_plan)      */
    bp__ndnode tree[BP__ND_NODES];
    bp__super *sn;                /* the supernodal factor (A->blocks2;
                                     then only n, symmetric, D, tree and sn
                                     are used)                            */
} bp__factor;

static void bp__factor_free(const bp_allocator *a, bp__factor *f)
{
    bp__free(a, f->perm); bp__free(a, f->iperm); bp__free(a, f->Rp); bp__free(a, f->Ri);
    bp__free(a, f->Rx); bp__free(a, f->Ux); bp__free(a, f->D); bp__free(a, f->Rxf);
    bp__free(a, f->cutp);
    bp__super_free(a, f->sn);
    memset(f, 0, sizeof *f);
}

/* BFS inside the subset marked owner[v] == id, from `start`.  Writes the
   visited vertices to queue[] in level order and their levels; returns the
   count. */
static uint32_t bp__bfs(const bp__sparse *A, const uint32_t *owner, uint32_t id, uint32_t start,
                        uint32_t *queue, uint32_t *level, uint32_t *seen, uint32_t stamp)
{
    const uint32_t *row = A->row;
    uint32_t head = 0, tail = 0, p;
    queue[tail++] = start;
    seen[start] = stamp;
    level[start] = 0;
    while (head < tail) {
        uint32_t v = queue[head++], p1 = A->colp[v + 1], lv = level[v] + 1;   /* (the stores below may alias) */
        for (p = A->colp[v]; p < p1; p++) {
            uint32_t w = row[p];
            if (seen[w] == stamp || owner[w] != id) continue;   /* seen first: half the neighbours, one load */
            seen[w] = stamp;
            level[w] = lv;
            queue[tail++] = w;
        }
    }
    return tail;
}

/* A better separator for the supernodal factorization (mode 1 of
   bp__nd_order).  A level set of one BFS is an arc around the start
   vertex, longer than a straight cut across the piece; measured on the
   face chart the top separator had 349 vertices against sqrt(25,905) =
   161.  So several keys are tried, each a function on the piece whose
   level sets cut it: the BFS distance d_u from the pseudo-peripheral
   vertex u (the classic one), d_u - d_v with v the far end of that BFS
   (its level sets run across the piece, near the bisector of u and v),
   and d_w - d_w' with w the vertex farthest from both u and v and w' the
   far end of a BFS from w (a cut in the other direction).  For a key and
   a threshold k, S = the vertices with key < k that have a neighbour with
   key >= k is a vertex separator between A = the rest below k and
   B = key >= k (every edge from below k to k or more starts in S).  Each
   vertex v lies in S exactly for k in (key(v), max key of its
   neighbours], so one pass with a difference array gives |S| for every
   k; the split taken is the smallest S over all keys and all k that leave
   30-70% of the piece below k. */
typedef struct bp__nd_work {
    uint32_t *dv, *dw, *dw2, *key, *q2;   /* n each                     */
    int32_t  *hist, *diff;                /* 2n + 2 each                */
} bp__nd_work;

/* The best threshold of one key over the piece queue[0 .. cnt) (owner id,
   keys in [0, R)); returns |S| (BP__NONE if no k is balanced), *kb. */
static uint32_t bp__nd_cut(const bp__sparse *A, const uint32_t *owner, uint32_t id, const uint32_t *queue, uint32_t cnt,
                           const uint32_t *key, uint32_t R, bp__nd_work *W, uint32_t *kb)
{
    uint32_t j, p, k, below = 0, best = BP__NONE;
    int32_t sep = 0;
    memset(W->hist, 0, ((size_t)R + 1) * sizeof(int32_t));
    memset(W->diff, 0, ((size_t)R + 1) * sizeof(int32_t));
    for (j = 0; j < cnt; j++) {
        uint32_t v = queue[j], kv = key[v], mx = kv;
        W->hist[kv]++;
        for (p = A->colp[v]; p < A->colp[v + 1]; p++)
            if (owner[A->row[p]] == id && key[A->row[p]] > mx) mx = key[A->row[p]];
        if (mx > kv) { W->diff[kv + 1]++; W->diff[mx + 1]--; }
    }
    *kb = BP__NONE;
    for (k = 1; k < R; k++) {
        below += (uint32_t)W->hist[k - 1];
        sep += W->diff[k];
        if (10 * (uint64_t)below >= 3 * (uint64_t)cnt && 10 * (uint64_t)below <= 7 * (uint64_t)cnt && (uint32_t)sep < best) {
            best = (uint32_t)sep;
            *kb = k;
        }
    }
    return best;
}

/* key = a - b + max b over the piece (a difference of two distances). */
static uint32_t bp__nd_key_diff(const uint32_t *queue, uint32_t cnt, const uint32_t *da, const uint32_t *db, uint32_t *key)
{
    uint32_t j, mb = 0, R = 0;
    for (j = 0; j < cnt; j++) if (db[queue[j]] > mb) mb = db[queue[j]];
    for (j = 0; j < cnt; j++) {
        key[queue[j]] = da[queue[j]] + mb - db[queue[j]];
        if (key[queue[j]] + 1 > R) R = key[queue[j]] + 1;
    }
    return R;
}

/* Refining the separator (Fiduccia & Mattheyses 1982, in the form for
   vertex separators of Karypis & Kumar's node refinement, 1998).  A
   threshold of a key is a cut across the piece, but a level set of graph
   distances is a staircase on an irregular mesh, longer than the shortest
   cut near it: measured on face, the top separator had 281 vertices where
   METIS finds 149, and the factorization's flops were 2.5x METIS's.  So
   the split [A | B | S] is improved by moves: a vertex s of S moves into
   side X, and its neighbours on the other side Y join S (so no edge joins
   A and B, ever).  The gain is 1 - |N(s) in Y|; each step takes the best
   move of an unlocked separator vertex (ties: into the smaller side)
   that leaves Y at least 30% of the piece, negative gains included, and
   locks s; a pass stops BP__ND_FM_STALL moves after its best state (the
   fewest separator vertices, then the best balance) or when its undo log
   is full, and rolls back to that best state; passes repeat while they
   improve, at most BP__ND_FM_PASSES.  On face, bimba_i, camelhead and
   lucy this halved the supernodal factorization's flops (1.26e8 ->
   6.5e7 on face's vertex graph; docs/performance.md sec 6.19).  Every
   choice is a fixed function of the piece (candidates in a fixed order,
   ties broken by it), so the order is the same on any schedule.
   Scratch: side and lock in W's dv and dw (own vertices only, no longer
   needed by the split), the candidates in q2, the undo log (vertex, old
   side) in hist, the rebuilt order in diff. */
#ifndef BP__ND_FM_PASSES
#define BP__ND_FM_PASSES 8
#endif
#ifndef BP__ND_FM_STALL
#define BP__ND_FM_STALL 100
#endif

/* Vertex v of the piece takes side x (0 A, 1 B, 2 S): the counts na, nb
   of A and B neighbours kept for the separator's vertices follow (a
   vertex entering S gets its own counted afresh). */
static void bp__nd_side(const bp__sparse *A, const uint32_t *owner, uint32_t id, uint32_t *side, uint32_t *na,
                        uint32_t *nb, uint32_t v, uint32_t x)
{
    uint32_t p, old = side[v];
    side[v] = x;
    if (x == 2) { na[v] = nb[v] = 0; }
    for (p = A->colp[v]; p < A->colp[v + 1]; p++) {
        uint32_t w = A->row[p];
        if (w == v || owner[w] != id) continue;
        if (x == 2) { na[v] += side[w] == 0; nb[v] += side[w] == 1; }
        if (side[w] != 2) continue;
        if (old == 0) na[w]--;
        else if (old == 1) nb[w]--;
        if (x == 0) na[w]++;
        else if (x == 1) nb[w]++;
    }
}

static void bp__nd_refine(const bp__sparse *A, const uint32_t *owner, uint32_t id, uint32_t *out, uint32_t cnt,
                          bp__nd_work *W, uint32_t *pa, uint32_t *pb)
{
    uint32_t *side = W->dv, *lock = W->dw, *na = W->dw2, *nb = W->key, *sl = W->q2;
    uint32_t *undo = (uint32_t *)W->hist, *tmp = (uint32_t *)W->diff;
    uint32_t cap = 2 * cnt + 2, lo = (uint32_t)(3 * (uint64_t)cnt / 10), sz[3], j, p, pass, w;
    sz[0] = *pa; sz[1] = *pb; sz[2] = cnt - *pa - *pb;
    for (j = 0; j < cnt; j++) side[out[j]] = j < sz[0] ? 0 : j < sz[0] + sz[1] ? 1 : 2;
    for (pass = 0; pass < BP__ND_FM_PASSES; pass++) {
        uint32_t nu = 0, best_nu = 0, best_s = sz[2], ns = 0, since = 0;
        uint32_t best_imb = sz[0] > sz[1] ? sz[0] - sz[1] : sz[1] - sz[0];
        for (j = 0; j < cnt; j++) {
            uint32_t v = out[j];
            lock[v] = 0;
            if (side[v] != 2) continue;
            sl[ns++] = v;
            na[v] = nb[v] = 0;
            for (p = A->colp[v]; p < A->colp[v + 1]; p++)
                if (A->row[p] != v && owner[A->row[p]] == id) { na[v] += side[A->row[p]] == 0; nb[v] += side[A->row[p]] == 1; }
        }
        for (;;) {
            uint32_t k, bk = BP__NONE, x, bx = 0, v, imb;
            int bg = 0;
            for (k = 0; k < ns; k++)                        /* moving sl[k] into x pulls its 1 - x neighbours */
                for (x = 0; x < 2; x++) {
                    uint32_t pulled = x ? na[sl[k]] : nb[sl[k]];
                    int g = 1 - (int)pulled;
                    if (sz[1 - x] < lo + pulled) continue;
                    if (bk == BP__NONE || g > bg || (g == bg && sz[x] < sz[bx])) { bk = k; bx = x; bg = g; }
                }
            if (bk == BP__NONE) break;
            v = sl[bk];
            if (nu + 2 * (A->colp[v + 1] - A->colp[v]) + 2 > cap) break;
            sl[bk] = sl[--ns];
            undo[nu++] = v; undo[nu++] = 2;
            bp__nd_side(A, owner, id, side, na, nb, v, bx);
            lock[v] = 1; sz[2]--; sz[bx]++;
            for (p = A->colp[v]; p < A->colp[v + 1]; p++) {
                w = A->row[p];
                if (w == v || owner[w] != id || side[w] != 1 - bx) continue;
                undo[nu++] = w; undo[nu++] = side[w];
                bp__nd_side(A, owner, id, side, na, nb, w, 2);
                sz[1 - bx]--; sz[2]++;
                if (!lock[w]) sl[ns++] = w;
            }
            imb = sz[0] > sz[1] ? sz[0] - sz[1] : sz[1] - sz[0];
            if (sz[2] < best_s || (sz[2] == best_s && imb < best_imb)) { best_s = sz[2]; best_imb = imb; best_nu = nu; since = 0; }
            else if (++since > BP__ND_FM_STALL) break;
        }
        while (nu > best_nu) {                              /* back to the best state (counts: next pass) */
            uint32_t old = undo[--nu], v = undo[--nu];
            sz[side[v]]--; side[v] = old; sz[old]++;
        }
        if (best_nu == 0) break;
    }
    for (w = 0, p = 0; p < 3; p++)                          /* [A | B | S], each in out's order */
        for (j = 0; j < cnt; j++) if (side[out[j]] == p) tmp[w++] = out[j];
    memcpy(out, tmp, cnt * sizeof(uint32_t));
    *pa = sz[0];
    *pb = sz[1];
}

/* Split the connected piece queue[0 .. cnt) (owner id; level = d_u from
   the pseudo-peripheral u, queue in BFS order) by the best of the three
   keys: writes out = [A | B | S] and *ca, *cb.  Returns 0 when no key has
   a balanced threshold (the caller then takes its level split). */
static int bp__nd_split(const bp__sparse *A, const uint32_t *owner, uint32_t id, const uint32_t *queue, uint32_t cnt,
                        const uint32_t *level, bp__nd_work *W, uint32_t *seen, uint32_t *stamp, uint32_t *out,
                        uint32_t *ca, uint32_t *cb, int refine)
{
    uint32_t j, p, w = queue[0], best, kb, k, R, which = 0, kbest, wmin = 0, c;
    best = bp__nd_cut(A, owner, id, queue, cnt, level, level[queue[cnt - 1]] + 1, W, &kbest);
    bp__bfs(A, owner, id, queue[cnt - 1], W->q2, W->dv, seen, ++*stamp);
    R = bp__nd_key_diff(queue, cnt, level, W->dv, W->key);
    if ((k = bp__nd_cut(A, owner, id, queue, cnt, W->key, R, W, &kb)) < best) { best = k; kbest = kb; which = 1; }
    for (j = 0; j < cnt; j++) {
        uint32_t v = queue[j], mn = level[v] < W->dv[v] ? level[v] : W->dv[v];
        if (mn > wmin) { wmin = mn; w = v; }
    }
    c = bp__bfs(A, owner, id, w, W->q2, W->dw, seen, ++*stamp);
    bp__bfs(A, owner, id, W->q2[c - 1], W->q2, W->dw2, seen, ++*stamp);
    R = bp__nd_key_diff(queue, cnt, W->dw, W->dw2, W->key);
    if ((k = bp__nd_cut(A, owner, id, queue, cnt, W->key, R, W, &kb)) < best) { best = k; kbest = kb; which = 2; }
    if (best == BP__NONE) return 0;
    if (which == 1) bp__nd_key_diff(queue, cnt, level, W->dv, W->key);
    {
        const uint32_t *key = which == 0 ? level : W->key;
        uint32_t na = 0, nb = 0, ns = 0;
        for (j = 0; j < cnt; j++) {                       /* A, and S parked in q2 */
            uint32_t v = queue[j], mx = key[v];
            if (key[v] >= kbest) continue;
            for (p = A->colp[v]; p < A->colp[v + 1]; p++)
                if (owner[A->row[p]] == id && key[A->row[p]] > mx) mx = key[A->row[p]];
            if (mx >= kbest) W->q2[ns++] = v;
            else out[na++] = v;
        }
        for (j = 0; j < cnt; j++)
            if (key[queue[j]] >= kbest) out[na + nb++] = queue[j];
        memcpy(out + na + nb, W->q2, ns * sizeof(uint32_t));
        if (refine) bp__nd_refine(A, owner, id, out, cnt, W, &na, &nb);
        *ca = na;
        *cb = nb;
    }
    return 1;
}

/* The dissection's state.  Shared by all its pieces: the order being
   built (each piece owns the range [lo, hi) of it), and the arrays indexed
   by vertex (owner, seen, level, and W's dv, dw, dw2, key).  Private to
   one piece's task (bp__nd_task): its stack, its BFS queue, W's q2, hist
   and diff, and its stamp counter. */
typedef struct bp__nd {
    const bp__sparse *A;
    uint32_t   *order, *owner, *level, *seen;
    bp__ndnode *tree;
    int         mode;
} bp__nd;

typedef struct bp__nd_task {
    uint32_t   *queue, *stack, sp, stamp;
    bp__nd_work W;
} bp__nd_task;

/* One node of the dissection: the piece [lo, hi) of the order (its
   vertices marked owner == lo), node `node` of the recorded tree (or
   BP__NONE below it).  Records the node, splits the piece into
   [A | B | S] (or a reached component and the rest) and pushes A and B on
   T's stack; a piece of 32 vertices or fewer, or too shallow to cut, is a
   leaf and pushes nothing.

   Mode 0: the level split for every node; mode 1: bp__nd_split's best of
   three keys first, refined (bp__nd_refine: the supernodal
   factorization's ordering); mode 2: the keys without the refinement
   (for tests and measurements). */
static void bp__nd_step(const bp__nd *D, bp__nd_task *T, uint32_t lo, uint32_t hi, uint32_t node)
{
    const bp__sparse *A = D->A;
    uint32_t *order = D->order, *owner = D->owner, *level = D->level, *seen = D->seen, *queue = T->queue;
    bp__ndnode *tree = D->tree;
    uint32_t size = hi - lo, cnt, nlev, m, ca, cs, cb, j;
    uint32_t c1 = node < BP__ND_NODES && 2 * node + 1 < BP__ND_NODES ? 2 * node + 1 : BP__NONE;
    uint32_t c2 = c1 != BP__NONE ? c1 + 1 : BP__NONE;
    if (node < BP__ND_NODES) {
        tree[node].used = 1;
        tree[node].lo = lo; tree[node].hi = hi; tree[node].a = tree[node].b = hi;
    }
    if (size <= 32) return;
    /* pseudo-peripheral start: the last vertex of a BFS from any vertex */
    cnt = bp__bfs(A, owner, lo, order[lo], queue, level, seen, ++T->stamp);
    cnt = bp__bfs(A, owner, lo, queue[cnt - 1], queue, level, seen, ++T->stamp);
    if (cnt < size) {
        /* disconnected: reached component first, then the rest */
        uint32_t w = cnt;
        for (j = lo; j < hi; j++)
            if (seen[order[j]] != T->stamp) queue[w++] = order[j];
        memcpy(order + lo, queue, size * sizeof(uint32_t));
        for (j = lo + cnt; j < hi; j++) owner[order[j]] = lo + cnt;
        if (node < BP__ND_NODES) { tree[node].split = 1; tree[node].a = lo + cnt; tree[node].b = hi; }
        T->stack[T->sp++] = lo; T->stack[T->sp++] = lo + cnt; T->stack[T->sp++] = c1;
        T->stack[T->sp++] = lo + cnt; T->stack[T->sp++] = hi; T->stack[T->sp++] = c2;
        return;
    }
    nlev = level[queue[cnt - 1]] + 1;
    if (nlev < 3) return;
    if (D->mode && bp__nd_split(A, owner, lo, queue, cnt, level, &T->W, seen, &T->stamp, order + lo, &ca, &cb, D->mode == 1))
        goto split;
    /* separator: the smallest level among those that leave between 30%
       and 70% of the vertices on the near side (the middle level if
       none qualifies) */
    {
        uint32_t best = BP__NONE, best_size = BP__NONE, lev = 0, lsize = 0, before = 0, mid = 1;
        for (j = 0; j <= cnt; j++) {
            if (j == cnt || level[queue[j]] != lev) {
                /* level `lev` has lsize vertices, `before` lie below it */
                if (lev >= 1 && lev <= nlev - 2) {
                    if (before <= size / 2) mid = lev;
                    if (10 * (uint64_t)before >= 3 * (uint64_t)size && 10 * (uint64_t)(before + lsize) <= 7 * (uint64_t)size &&
                        lsize < best_size) { best = lev; best_size = lsize; }
                }
                if (j == cnt) break;
                before += lsize;
                lev = level[queue[j]];
                lsize = 0;
            }
            lsize++;
        }
        m = best != BP__NONE ? best : mid;
    }
    for (ca = 0; level[queue[ca]] < m; ca++) {}
    for (cs = 0; ca + cs < cnt && level[queue[ca + cs]] == m; cs++) {}
    cb = cnt - ca - cs;
    /* queue is in level order: [A | S | B] -> order [A | B | S].  A
       vertex of level m with no neighbour at level m + 1 separates
       nothing: it joins A, and the separator (and the fill) shrinks */
    memcpy(order + lo, queue, ca * sizeof(uint32_t));
    {
        uint32_t s0 = ca, keep = 0, s, q2;
        for (s = s0; s < s0 + cs; s++) {
            uint32_t v = queue[s];
            int needed = 0;
            for (q2 = A->colp[v]; q2 < A->colp[v + 1] && !needed; q2++)
                needed = owner[A->row[q2]] == lo && level[A->row[q2]] == m + 1;
            if (needed) queue[s0 + keep++] = v;
            else order[lo + ca++] = v;
        }
        memcpy(order + lo + ca, queue + s0 + cs, cb * sizeof(uint32_t));
        memcpy(order + lo + ca + cb, queue + s0, keep * sizeof(uint32_t));
        cs = keep;
    }
split:
    for (j = lo + ca; j < lo + ca + cb; j++) owner[order[j]] = lo + ca;
    for (j = lo + ca + cb; j < hi; j++) owner[order[j]] = BP__NONE;
    if (node < BP__ND_NODES) { tree[node].split = 1; tree[node].a = lo + ca; tree[node].b = lo + ca + cb; }
    T->stack[T->sp++] = lo; T->stack[T->sp++] = lo + ca; T->stack[T->sp++] = c1;
    T->stack[T->sp++] = lo + ca; T->stack[T->sp++] = lo + ca + cb; T->stack[T->sp++] = c2;
}

/* Every node below those on T's stack, depth first. */
static void bp__nd_subtree(const bp__nd *D, bp__nd_task *T)
{
    while (T->sp) {
        uint32_t node = T->stack[--T->sp], hi = T->stack[--T->sp], lo = T->stack[--T->sp];
        bp__nd_step(D, T, lo, hi, node);
    }
}

/* The ordering on several threads.

   The pieces of a split are independent.  The task of a piece [lo, hi)
   reads and writes order[lo, hi) and, of the arrays indexed by vertex
   (owner, seen, level, W's dv, dw, dw2, key), only the entries of its own
   vertices, those with owner == lo: bp__bfs, bp__nd_cut, bp__nd_split and
   the level split test owner[w] == id before they touch anything else of
   a neighbour w; bp__nd_key_diff and the disconnected case read only the
   piece's own list; the owner writes after a split are to its own
   vertices.  Of a neighbour w outside the piece it reads owner[w], which
   is BP__NONE, and (bp__bfs, which tests it first: for the neighbours
   inside, half of them already reached, one load instead of two) seen[w],
   neither written after the task began or ever again, because every
   such w lies in the separator S of an ancestor (so a stale seen[w] is
   only ever followed by the owner test).  By
   induction from the root (the whole graph, no outside), since no edge
   joins the two halves of any split (the pattern is symmetric,
   bp__sparse):
     - level split: the BFS levels of two neighbours differ by at most 1;
       A holds the levels below m and the vertices of level m with no
       neighbour at m + 1, B the levels above m;
     - key split: a vertex below the threshold with a neighbour at or
       above it is in S, not in A;
     - disconnected: the reached part is a whole connected component of
       the piece, the rest has no edge to it.
   (With an unsymmetric pattern a neighbour could lie in a sibling piece;
   its owner would be the sibling's id or a sub-piece's, all inside the
   sibling's range, never lo: the same result, but a race.)  A piece's id
   is the start of its range, so the ids of the pieces alive at one time
   differ.  Each task writes its own nodes of tree[].  tests/test_sparse.c
   (h) checks the premise: no edge across a recorded split.

   The same bits.  A piece's result is a function of its own vertices'
   state and of owner == BP__NONE around it, so it depends neither on which
   piece runs first nor on the thread.  Stamps are compared for equality
   only, and only at the piece's own vertices; a task starts its counter at
   `base`, above every stamp written before it (the maximum over the
   previous level's tasks), and counts up, so each BFS's stamp is new at
   every vertex it may visit: exactly what the serial loop's single
   counter guarantees.  Sibling tasks use the same stamp values on
   disjoint vertices, which no comparison ever sees.

   The schedule.  The root is split alone (a tenth of the work on the
   26K-vertex face chart: 3.8 of 36 ms), as one task of a loop in which
   the caller's other work independent of the order may run on the other
   threads (bp__nd_order_with: the conformal start's columns); then each
   level of the recorded tree
   down to depth BP__ND_PAR_DEPTH is one parallel loop with a task per
   piece (one split each), and the pieces at that depth (up to
   2^BP__ND_PAR_DEPTH) are ordered whole, one task each, largest first
   (the pool hands tasks out in index order).  A task's private scratch
   is carved from the serial loop's arrays, allocated with room for it:
   at a level sorted by lo, piece r of m vertices takes queue and q2 from
   lo (m each), hist and diff from 2 lo + 2 r (2 m + 2 each: its keys stay
   below 2 m) and the stack from 3 lo + 3 r (3 m + 3: the depth-first walk
   of the piece holds one pending sibling per node on its path, and every
   split shrinks the piece).  No piece's scratch meets another's, and the
   loops allocate nothing (a failure can only happen before them, and the
   allocator is not called from the pool's threads). */
#ifndef BP__ND_PAR_DEPTH
#define BP__ND_PAR_DEPTH BP__ND_DEPTH /* up to 16 subtree tasks */
#endif
#define BP__ND_PIECES (1u << BP__ND_PAR_DEPTH)

typedef struct bp__nd_par {
    const bp__nd *D;
    uint32_t   *queue, *stack, *q2;   /* the serial loop's arrays      */
    int32_t    *hist, *diff;
    uint32_t    npiece, whole, base;  /* whole: order the subtrees     */
    uint32_t    piece[3 * BP__ND_PIECES];   /* lo, hi, node; by lo    */
    uint32_t    kids[6 * BP__ND_PIECES];    /* each piece's halves     */
    uint32_t    ksp[BP__ND_PIECES], stamp[BP__ND_PIECES];
    uint32_t    turn[BP__ND_PIECES];  /* task index -> piece, largest first */
    bp__nd_work W;                    /* the shared dv, dw, dw2, key  */
} bp__nd_par;

static void bp__nd_piece_task(void *task, uint32_t i)
{
    bp__nd_par *P = (bp__nd_par *)task;
    uint32_t r = P->turn[i], lo = P->piece[3 * r], hi = P->piece[3 * r + 1], node = P->piece[3 * r + 2];
    bp__nd_task T;
    T.W = P->W;
    T.queue = P->queue + lo;
    T.stamp = P->base;
    if (P->D->mode) {
        T.W.q2 = P->q2 + lo;
        T.W.hist = P->hist + 2 * (size_t)lo + 2 * r;
        T.W.diff = P->diff + 2 * (size_t)lo + 2 * r;
    }
    if (P->whole) {
        T.stack = P->stack + 3 * (size_t)lo + 3 * r;
        T.stack[0] = lo; T.stack[1] = hi; T.stack[2] = node;
        T.sp = 3;
        bp__nd_subtree(P->D, &T);
    } else {
        T.stack = P->kids + 6 * r;
        T.sp = 0;
        bp__nd_step(P->D, &T, lo, hi, node);
        P->ksp[r] = T.sp;
    }
    P->stamp[r] = T.stamp;
}

/* One parallel loop over P's pieces: a split each, or (whole) their
   subtrees, with the loop `with` beside them when not NULL
   (bp__par_run_with); then the next level's pieces, in lo order, and the
   new base. */
static void bp__nd_par_level(bp__nd_par *P, const bp__par *par, uint32_t n, const bp__loop *with)
{
    uint32_t r, i, k = 0, sz;
    for (r = 0; r < P->npiece; r++) {               /* largest first */
        sz = P->piece[3 * r + 1] - P->piece[3 * r];
        for (i = r; i > 0 && P->piece[3 * P->turn[i - 1] + 1] - P->piece[3 * P->turn[i - 1]] < sz; i--)
            P->turn[i] = P->turn[i - 1];
        P->turn[i] = r;
    }
    bp__par_run_with(par, bp__nd_piece_task, P, P->npiece, n, with);
    for (r = 0; r < P->npiece; r++) if (P->stamp[r] > P->base) P->base = P->stamp[r];
    if (P->whole) return;
    for (r = 0; r < P->npiece; r++)                 /* kids: A then B */
        for (i = 0; i < P->ksp[r]; i += 3) {
            P->piece[3 * k] = P->kids[6 * r + i];
            P->piece[3 * k + 1] = P->kids[6 * r + i + 1];
            P->piece[3 * k + 2] = P->kids[6 * r + i + 2];
            k++;
        }
    P->npiece = k;
}

/* The nested-dissection order of A's graph (order: new -> old) and the
   top of its tree; on par's threads when par is given (any thread count,
   any task order: the same order and tree).  with (or NULL): a loop
   independent of the order, run beside the root's split (in the same
   parallel loop: the root is one task), or before the order on one
   thread.  Returns 0 out of memory (with then may not have run). */
static int bp__nd_order_with(const bp_allocator *a, const bp__sparse *A, uint32_t *order, bp__ndnode *tree, int mode,
                             const bp__par *par, const bp__loop *with)
{
    uint32_t n = A->n, i;
    uint32_t *owner = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    uint32_t *level = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    uint32_t *queue = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    uint32_t *seen = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    uint32_t *stack = (uint32_t *)bp__alloc_array(a, 3 * (size_t)n + 3 * BP__ND_PIECES, sizeof(uint32_t));
    bp__nd_work W;
    bp__nd D;
    bp__nd_task T;
    int ok = 0;
    memset(&W, 0, sizeof W);
    if (mode) {
        W.dv = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
        W.dw = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
        W.dw2 = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
        W.key = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
        W.q2 = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
        W.hist = (int32_t *)bp__alloc_array(a, 2 * (size_t)n + 2 * BP__ND_PIECES, sizeof(int32_t));
        W.diff = (int32_t *)bp__alloc_array(a, 2 * (size_t)n + 2 * BP__ND_PIECES, sizeof(int32_t));
    }
    if (!owner || !level || !queue || !seen || !stack ||
        (mode && (!W.dv || !W.dw || !W.dw2 || !W.key || !W.q2 || !W.hist || !W.diff))) goto done;
    for (i = 0; i < n; i++) { order[i] = i; owner[i] = 0; seen[i] = 0; }
    memset(tree, 0, BP__ND_NODES * sizeof *tree);
    D.A = A; D.order = order; D.owner = owner; D.level = level; D.seen = seen; D.tree = tree; D.mode = mode;
    if (!par || par->threads == 1) {
        if (with) bp__serial_for(NULL, with->fn, with->task, with->count);
        T.queue = queue; T.stack = stack; T.stamp = 0; T.W = W;
        T.stack[0] = 0; T.stack[1] = n; T.stack[2] = 0;
        T.sp = 3;
        bp__nd_subtree(&D, &T);
    } else {
        bp__nd_par P;
        int d;
        memset(&P, 0, sizeof P);
        P.D = &D; P.queue = queue; P.stack = stack; P.q2 = W.q2; P.hist = W.hist; P.diff = W.diff; P.W = W;
        P.npiece = 1;
        P.piece[0] = 0; P.piece[1] = n; P.piece[2] = 0;
        for (d = 0; d < BP__ND_PAR_DEPTH && P.npiece; d++, with = NULL) bp__nd_par_level(&P, par, n, with);
        P.whole = 1;
        if (P.npiece) bp__nd_par_level(&P, par, n, with);
    }
    ok = 1;
done:
    bp__free(a, owner); bp__free(a, level); bp__free(a, queue); bp__free(a, seen); bp__free(a, stack);
    bp__free(a, W.dv); bp__free(a, W.dw); bp__free(a, W.dw2); bp__free(a, W.key); bp__free(a, W.q2);
    bp__free(a, W.hist); bp__free(a, W.diff);
    return ok;
}

static int bp__nd_order(const bp_allocator *a, const bp__sparse *A, uint32_t *order, bp__ndnode *tree, int mode,
                        const bp__par *par)
{
    return bp__nd_order_with(a, A, order, tree, mode, par, NULL);
}

/* A dissection restricted to some of its vertices: keep[v] is v's number
   among the kept ones, BP__NONE for a vertex dropped.  Dropping vertices
   keeps every split a split (a path between the two halves in the smaller
   graph is one in the larger, so it meets the separator), so the order of
   the kept vertices (out: new -> kept number) with the tree's ranges
   counted in kept vertices (rtree) is a nested dissection of any subgraph
   on them.  pre: n + 1 words of scratch. */
static void bp__nd_restrict(const uint32_t *order, const bp__ndnode *tree, uint32_t n, const uint32_t *keep,
                            uint32_t *out, bp__ndnode *rtree, uint32_t *pre)
{
    uint32_t k, m = 0;
    for (k = 0; k < n; k++) {
        pre[k] = m;
        if (keep[order[k]] != BP__NONE) out[m++] = keep[order[k]];
    }
    pre[n] = m;
    memset(rtree, 0, BP__ND_NODES * sizeof *rtree);
    for (k = 0; k < BP__ND_NODES; k++) {
        if (!tree[k].used) continue;
        rtree[k].used = 1;
        rtree[k].split = tree[k].split;
        rtree[k].lo = pre[tree[k].lo]; rtree[k].a = pre[tree[k].a];
        rtree[k].b = pre[tree[k].b]; rtree[k].hi = pre[tree[k].hi];
    }
}

/* The nodes of the recorded top of the nested-dissection tree, in the order
   the triangular solves and the factorization may take them: phase 0 holds
   the subtrees that are handled whole (leaves of the recorded tree and the
   nodes at its deepest level), phase p > 0 the split nodes at depth
   BP__ND_DEPTH - p, whose separators [b, hi) wait for both children.  The
   nodes of one phase cover disjoint ranges. */
static int bp__nd_depth(uint32_t k)
{
    int d = 0;
    while (k > 0) { k = (k - 1) / 2; d++; }
    return d;
}

static uint32_t bp__nd_phase(const bp__factor *F, int phase, uint32_t *nodes)
{
    uint32_t k, n = 0, i;
    for (k = 0; k < BP__ND_NODES; k++) {
        const bp__ndnode *N = &F->tree[k];
        int d = bp__nd_depth(k);
        if (!N->used) continue;
        if (phase == 0 ? (!N->split || d == BP__ND_DEPTH) : (N->split && d == BP__ND_DEPTH - phase && d < BP__ND_DEPTH))
            nodes[n++] = k;
    }
    /* the largest range first: the pool hands tasks out in index order, and
       a large subtree taken last would leave the other threads idle (the
       order changes no result) */
    for (k = 1; k < n; k++) {
        uint32_t v = nodes[k], sz = F->tree[v].hi - F->tree[v].lo;
        for (i = k; i > 0 && F->tree[nodes[i - 1]].hi - F->tree[nodes[i - 1]].lo < sz; i--) nodes[i] = nodes[i - 1];
        nodes[i] = v;
    }
    return n;
}

/* The first position in idx[p0, p1) (sorted) holding a value >= cut. */
static uint32_t bp__lower_bound(const uint32_t *idx, uint32_t p0, uint32_t p1, uint32_t cut)
{
    while (p0 < p1) {
        uint32_t m = p0 + (p1 - p0) / 2;
        if (idx[m] < cut) p0 = m + 1; else p1 = m;
    }
    return p0;
}

/* The numeric rows of one phase.  Row k reaches only columns of its own
   node, so the tasks of one phase share dense work arrays without touching
   the same entries.  Phase 0 computes the subtrees whole (mode WHOLE, the
   arrays x, y).  A separator [b, hi) takes two passes, as in the solves:
   its rows depend on each other only through the separator's own block,
   while most of their entries (and work) lie in the columns below b.
     OUTSIDE: the rows in BP__FACT_PARTS chunks, in parallel, compute their
       entries below b (each chunk with its own arrays xs, ys, since the
       rows of one separator reach the same columns) and park them: U(j,k)
       in Rx (symmetric) or Ux, L(k,j) in Rx (unsymmetric);
     INSIDE: one task per separator takes its rows in order, reloads the
       parked values, computes the entries inside the block and finishes
       the row (L, D) exactly as WHOLE does.
   Every value, and the order of every sum, is the one-pass algorithm's. */
#define BP__FACT_PARTS 4u
enum { BP__FACT_WHOLE, BP__FACT_OUTSIDE, BP__FACT_INSIDE };

typedef struct bp__fact_task {
    const bp__sparse *A;
    bp__factor *F;
    const uint32_t *tpos;
    double *x, *y, *xs, *ys;        /* xs, ys: BP__FACT_PARTS arrays of n   */
    uint32_t nodes[BP__ND_NODES];
    int mode;
} bp__fact_task;

/* Row k's entries q in [q0, q1), in increasing column j: U(j,k) by a
   gather along row j into x[j] and, unsymmetric, L(k,j) along row j of
   U^T into y[j].  Every entry a row j needs lies in row j's own pattern,
   below j, hence earlier in this order (a topological order). */
static void bp__fact_entries(const bp__factor *F, int sym, uint32_t q0, uint32_t q1, double *x, double *y)
{
    uint32_t q, r;
    for (q = q0; q < q1; q++) {
        uint32_t j = F->Ri[q];
        double u = x[j];
        for (r = F->Rp[j]; r < F->Rp[j + 1]; r++) u -= F->Rx[r] * x[F->Ri[r]];
        x[j] = u;
        if (!sym) {
            double w = y[j];
            for (r = F->Rp[j]; r < F->Rp[j + 1]; r++) w -= F->Ux[r] * y[F->Ri[r]];
            y[j] = w / F->D[j];
        }
    }
}

/* x[i], y[i] = A(i,k), A(k,i) for the (permuted) rows lo <= i < hi. */
static void bp__fact_scatter(const bp__fact_task *T, uint32_t k, uint32_t lo, uint32_t hi, double *x, double *y)
{
    const bp__sparse *A = T->A;
    uint32_t old = T->F->perm[k], p;
    for (p = A->colp[old]; p < A->colp[old + 1]; p++) {
        uint32_t i = T->F->iperm[A->row[p]];
        if (i < lo || i >= hi) continue;
        x[i] = A->val[p];
        if (!A->symmetric) y[i] = A->val[T->tpos[p]];
    }
}

static void bp__fact_rows(void *task, uint32_t t)
{
    bp__fact_task *T = (bp__fact_task *)task;
    bp__factor *F = T->F;
    int sym = T->A->symmetric;
    uint32_t part = T->mode == BP__FACT_OUTSIDE ? t % BP__FACT_PARTS : 0;
    const bp__ndnode *N = &F->tree[T->nodes[T->mode == BP__FACT_OUTSIDE ? t / BP__FACT_PARTS : t]];
    uint32_t k, q, k0 = T->mode == BP__FACT_WHOLE ? N->lo : N->b, k1 = N->hi;
    double *x = T->x, *y = T->y;
    if (T->mode == BP__FACT_OUTSIDE) {
        k0 = N->b + (uint32_t)((uint64_t)(N->hi - N->b) * part / BP__FACT_PARTS);
        k1 = N->b + (uint32_t)((uint64_t)(N->hi - N->b) * (part + 1) / BP__FACT_PARTS);
        x = T->xs + (size_t)part * F->n;
        y = sym ? y : T->ys + (size_t)part * F->n;
    }
    for (k = k0; k < k1; k++) {
        uint32_t qb = F->Rp[k], qe = F->Rp[k + 1];
        double dk;
        if (T->mode == BP__FACT_OUTSIDE) {           /* the entries below b, parked */
            qe = bp__lower_bound(F->Ri, qb, qe, N->b);
            bp__fact_scatter(T, k, 0, N->b, x, y);
            bp__fact_entries(F, sym, qb, qe, x, y);
            for (q = qb; q < qe; q++) {
                uint32_t j = F->Ri[q];
                if (sym) F->Rx[q] = x[j];
                else { F->Ux[q] = x[j]; F->Rx[q] = y[j]; }
                x[j] = 0;
                if (!sym) y[j] = 0;
            }
            continue;
        }
        if (T->mode == BP__FACT_INSIDE) {            /* reload them, then the block */
            uint32_t qm = bp__lower_bound(F->Ri, qb, qe, N->b);
            bp__fact_scatter(T, k, N->b, k + 1, x, y);
            for (q = qb; q < qm; q++) {
                x[F->Ri[q]] = sym ? F->Rx[q] : F->Ux[q];
                if (!sym) y[F->Ri[q]] = F->Rx[q];
            }
            dk = x[k];
            x[k] = 0;
            y[k] = 0;
            bp__fact_entries(F, sym, qm, qe, x, y);
        } else {
            bp__fact_scatter(T, k, 0, k + 1, x, y);
            dk = x[k];
            x[k] = 0;
            y[k] = 0;
            bp__fact_entries(F, sym, qb, qe, x, y);
        }
        for (q = qb; q < qe; q++) {                  /* L(k,j), U(j,k), D(k) */
            uint32_t j = F->Ri[q];
            double u = x[j], l = sym ? u / F->D[j] : y[j];
            F->Rx[q] = l;
            if (!sym) F->Ux[q] = u;
            dk -= l * u;
        }
        for (q = qb; q < qe; q++) x[F->Ri[q]] = y[F->Ri[q]] = 0;
        F->D[k] = dk;            /* checked by the caller, in row order */
    }
}

/* The pattern of row k of L, its "row subtree": the nodes on the etree
   paths from each j < k with A(j,k) != 0 up to k (exclusive), written to
   out in no particular order; returns their count.  mark[] must not hold k
   before the call (stamps of earlier rows are fine). */
static uint32_t bp__row_subtree(const bp__sparse *A, const bp__factor *F, const uint32_t *parent, uint32_t *mark,
                                uint32_t k, uint32_t *out)
{
    uint32_t old = F->perm[k], p, j, m = 0;
    mark[k] = k;
    for (p = A->colp[old]; p < A->colp[old + 1]; p++)
        for (j = F->iperm[A->row[p]]; j < k && mark[j] != k; j = parent[j]) {
            mark[j] = k;
            out[m++] = j;
        }
    return m;
}

/* The factor's size limit.  L's row pointers Rp and column indices Ri are
   uint32_t, so L holds at most BP__FACTOR_MAX_NNZ entries below the
   diagonal (a little under 2^32; the factor then takes about 64 GB).  The
   symbolic phase counts the entries before anything is allocated and
   stops with BP_ERR_TOO_LARGE, not with an allocation that fails or an
   index that wraps around. */
#ifndef BP__FACTOR_MAX_NNZ
#define BP__FACTOR_MAX_NNZ 0xfffffff0u
#endif

/* tpos[p]: the position in A of the transpose of entry p (A's rows are
   sorted, so the transposes of column k come out in order). */
static int bp__fact_transpose(const bp_allocator *a, const bp__sparse *A, uint32_t **tpos_out)
{
    uint32_t n = A->n, k, p, *tpos, *cursor;
    *tpos_out = tpos = (uint32_t *)bp__alloc_array(a, A->colp[n], sizeof(uint32_t));
    cursor = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    if (!tpos || !cursor) { bp__free(a, cursor); return 0; }
    for (k = 0; k < n; k++) cursor[k] = A->colp[k];
    for (k = 0; k < n; k++)
        for (p = A->colp[k]; p < A->colp[k + 1]; p++) tpos[p] = cursor[A->row[p]]++;
    bp__free(a, cursor);
    return 1;
}

/* Liu's step for row k: each neighbour j < k climbs its ancestor links,
   compressing them to k, until a root, whose parent becomes k. */
static void bp__etree_row(const bp__sparse *A, const bp__factor *F, uint32_t *parent, uint32_t *anc, uint32_t k)
{
    uint32_t old = F->perm[k], p;
    parent[k] = BP__NONE;
    anc[k] = BP__NONE;
    for (p = A->colp[old]; p < A->colp[old + 1]; p++) {
        uint32_t j = F->iperm[A->row[p]];
        while (j != BP__NONE && j < k) {
            uint32_t next = anc[j];
            anc[j] = k;
            if (next == BP__NONE) { parent[j] = k; break; }
            j = next;
        }
    }
}

/* The elimination tree of the permuted matrix: parent[k], the first row
   below k whose pattern contains column k (Liu's algorithm; mark holds
   the path-compressed "ancestor" links). */
static void bp__fact_etree(const bp__sparse *A, const bp__factor *F, uint32_t *parent, uint32_t *mark)
{
    uint32_t k;
    for (k = 0; k < A->n; k++) bp__etree_row(A, F, parent, mark, k);
}

/* The pattern of L (F->Rp, F->Ri).  The pattern of row k is its row
   subtree (bp__row_subtree).  Counted first (row and column counts, and
   the size limit), then listed by columns (each column comes out sorted,
   as k increases), then transposed into rows (each row sorted).  Returns
   BP_OK, BP_ERR_OUT_OF_MEMORY or BP_ERR_TOO_LARGE (*stop_row: the row at
   which the count passed the limit). */
static bp_status bp__fact_symbolic(const bp_allocator *a, const bp__sparse *A, bp__factor *F,
                                   const uint32_t *parent, uint32_t *stop_row)
{
    uint32_t n = A->n, k, i, p;
    uint32_t *mark, *cnt, *Cp, *reach, *Ci = NULL;
    size_t nnzL = 0;
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    mark = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    cnt = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    Cp = (uint32_t *)bp__alloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    reach = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    if (!mark || !cnt || !Cp || !reach) goto done;
    for (k = 0; k <= n; k++) Cp[k] = 0;
    for (k = 0; k < n; k++) mark[k] = BP__NONE;
    for (k = 0; k < n; k++) {
        uint32_t m = bp__row_subtree(A, F, parent, mark, k, reach);
        F->Rp[k] = (uint32_t)nnzL;
        nnzL += m;
        if (nnzL > BP__FACTOR_MAX_NNZ) { *stop_row = k; st = BP_ERR_TOO_LARGE; goto done; }
        for (i = 0; i < m; i++) Cp[reach[i] + 1]++;
    }
    F->Rp[n] = (uint32_t)nnzL;
    for (k = 0; k < n; k++) Cp[k + 1] += Cp[k];
    Ci = (uint32_t *)bp__alloc_array(a, nnzL, sizeof(uint32_t));
    F->Ri = (uint32_t *)bp__alloc_array(a, nnzL, sizeof(uint32_t));
    if (!Ci || !F->Ri) goto done;
    for (k = 0; k < n; k++) { cnt[k] = Cp[k]; mark[k] = BP__NONE; }
    for (k = 0; k < n; k++) {
        uint32_t m = bp__row_subtree(A, F, parent, mark, k, reach);
        for (i = 0; i < m; i++) Ci[cnt[reach[i]]++] = k;
    }
    for (k = 0; k < n; k++) cnt[k] = F->Rp[k];
    for (i = 0; i < n; i++)
        for (p = Cp[i]; p < Cp[i + 1]; p++) F->Ri[cnt[Ci[p]]++] = i;
    st = BP_OK;
done:
    bp__free(a, mark); bp__free(a, cnt); bp__free(a, Cp); bp__free(a, reach); bp__free(a, Ci);
    return st;
}

/* ---- The supernodal Cholesky factorization of a 2x2-block matrix ---------

   Projected Newton (>>newton) solves (H + delta I) v = -g every iteration
   with H the 2nv x 2nv matrix of a chart's vertices' x and y.  Factored by
   the scalar up-looking rows above, each entry of L is one sparse gather
   through an index, and the factorization was 85% of a Newton iteration
   (face, 51,712 faces: 1.4 s of 1.45 s).  Three things make it cheaper;
   Davis, "Direct Methods for Sparse Linear Systems" (SIAM 2006), ch. 4
   and 9, is the reference for all of them.

   The vertex graph.  H is made of 2x2 blocks: a triangle couples all six
   coordinates of its vertices, a barrier pair all four of its two
   vertices.  Eliminating the two columns of a vertex fills exactly where
   eliminating the vertex in the graph of the blocks does, so L is the
   vertex graph's factor with every entry a full 2x2 block (the diagonal
   blocks lower triangular).  The ordering, the elimination tree, the row
   and column counts and the supernodes are all computed on the vertex
   graph G (bp__super_graph): a quarter of the symbolic work, and x and y
   of a vertex always side by side (a level-set separator of the scalar
   graph can take one without the other and be twice as thick).

   Supernodes (Ng & Peyton, "Block sparse Cholesky algorithms on advanced
   uniprocessor computers", SIAM J. Sci. Comput. 14, 1993).  Consecutive
   columns whose patterns below the diagonal are the same, j + 1 = parent
   of j and |L(:, j)| = |L(:, j+1)| + 1, form a dense trapezoid: it is
   stored as one dense block, indexed once per row vertex (one index per
   2 x 2 nc values), and computed by dense loops with no indirection.  On
   mesh graphs the fundamental supernodes are short (1.6 vertices on
   face, most of the work in the long ones of the separators); merging a
   child into its parent at the price of explicit zeros (relaxed
   amalgamation, bp__super_relax) was measured and is off by default.

   The numeric factorization is left-looking by supernodes.  For supernode
   J with columns C and rows R (C first), its block B (|R| x |C| in 2x2
   blocks) starts as A(R, C); then for every earlier supernode K with rows
   in C, in increasing K,
       B(R_K, C_K) -= L_K(R_K, :) L_K(C_K, :)^T,
   C_K = K's rows that lie in C, R_K = K's rows from the first of them on
   (both runs of K's sorted rows, so the product is dense; a map from
   vertex to row of B places it); then the dense Cholesky of B's diagonal
   block, B(C, C) = L_CC L_CC^T, and the rows below by the triangular
   solve L_RC = B(R \ C, C) L_CC^-T.  Ng and Peyton find the K of each J
   by linked lists that follow the computation; here the lists are built
   once by the analysis (bp__super_updates), sorted by K, so every entry
   sums its terms in one fixed order: the same bits whatever the schedule,
   and a task writes only its own supernodes' blocks while it reads only
   finished ones.  The tasks are those of the scalar code: the dissection
   tree's subtrees in parallel, then its separators bottom-up (supernodes
   never cross a tree node's boundary).  The dense loops run on blocks by
   rows, dots of contiguous rows, four rows by two columns at a time with
   each sum split into even and odd terms (a fixed order that compilers
   vectorize without licence to reassociate; two rows to a register where
   the processor has AVX, the same bits).

   The ordering.  Nested dissection as above, on G, but each separator is
   the best of three candidate cuts (bp__nd_split): on face the flop count
   falls from 1.85e9 to 1.0e9 and L from 5.1M to 4.6M entries.

   This is Cholesky, L L^T, not L D L^T: H + delta I is positive definite
   (>>newton) and a pivot d_i that is not positive stops the factorization
   with BP_ERR_NUMERICAL; the pivots d_i = L(i,i)^2 stay in F->D, where
   the Newton code checks them.  docs/performance.md sec 6.1 has the
   measurements.

   Blocks of 1 (bp__super.bs; docs/performance.md sec 6.8).  A scalar SPD
   matrix (A->super1: the L-BFGS preconditioner's Laplacian, the uniform
   Tutte system, the symmetrized mean-value Laplacian of >>tutte phase 6a)
   is the same computation with 1x1 blocks: the vertex graph is the
   matrix's own, a supernode's block is |rows| x |cols| doubles, and the
   kernels take two columns of B at a time as before, now two column
   vertices (bp__super_update), rows four at a time with an odd count's
   remainder one by one (bp__super_trsm_rows), every dot product's lanes as
   before plus an odd last term in the even lane: bs 2 computes exactly
   the bits it did.  On the 1M-face chart's Laplacian the numeric phase
   takes 13x fewer seconds than the scalar up-looking rows, which gather
   one scattered entry per multiply-add while the dense loops stream
   (5.7x with the analysis, now the larger part), and mode 1's better
   separators cut the flops by 36%.  The preconditioner's solves
   stay with the rows (bp__super_to_rows: L in single precision by rows,
   solved in parallel phases, both coordinates at once). */

/* The vertex graph G of A: G(w, v) != 0 when A's 2x2 block (w, v) is in
   its pattern.  Returns 1; 0 when A is not made of whole 2x2 blocks (the
   scalar factorization then serves); -1 out of memory. */
static int bp__super_graph(const bp_allocator *a, const bp__sparse *A, bp__sparse *G)
{
    uint32_t nv = A->n / 2, v, p, q, w = 0;
    memset(G, 0, sizeof *G);
    if (A->n % 2 || !A->symmetric) return 0;
    for (v = 0; v < nv; v++) {
        uint32_t p0 = A->colp[2 * v], p1 = A->colp[2 * v + 1], p2 = A->colp[2 * v + 2];
        if (p1 - p0 != p2 - p1 || (p1 - p0) % 2) return 0;
        for (p = p0, q = p1; p < p1; p += 2, q += 2)
            if (A->row[p] % 2 || A->row[p + 1] != A->row[p] + 1 || A->row[q] != A->row[p] || A->row[q + 1] != A->row[p + 1])
                return 0;
    }
    G->n = nv;
    G->symmetric = 1;
    G->colp = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    G->row = (uint32_t *)bp__alloc_array(a, A->colp[A->n] / 4 + 1, sizeof(uint32_t));
    if (!G->colp || !G->row) { bp__free(a, G->colp); bp__free(a, G->row); return -1; }
    for (v = 0; v < nv; v++) {
        G->colp[v] = w;
        for (p = A->colp[2 * v]; p < A->colp[2 * v + 1]; p += 2) G->row[w++] = A->row[p] / 2;
    }
    G->colp[nv] = w;
    return 1;
}

/* Relaxed amalgamation (Ashcraft & Grimes 1989; the thresholds are
   CHOLMOD's, in vertices = 2 columns): a supernode of nc vertices whose
   lower trapezoid would hold a fraction z of explicit zeros is accepted
   when nc <= 2, or nc <= 8 and z < 0.8, or nc <= 24 and z < 0.1, or
   z < 0.05.  On by default since session 10 (BP__SUPER_RELAX 0 turns it
   off): on face it makes the supernodes 6.5 vertices long instead of 1.55
   (3,993 instead of 16,676) for 12% more stored values, and the kernels
   of sec 6.16 (panels, the update by 4 x 2 blocks) then pay less per
   supernode: a whole one-thread run 7% faster (docs/performance.md sec
   6.23).  When it was first measured (sec 6.1), with the older kernels,
   it gained nothing. */
#ifndef BP__SUPER_ORDER
#define BP__SUPER_ORDER 1           /* bp__nd_order's mode for the supernodal factor */
#endif
#ifndef BP__SCALAR_ORDER
#define BP__SCALAR_ORDER 0          /* ... and for the scalar one */
#endif
#ifndef BP__SUPER_SCALAR
#define BP__SUPER_SCALAR 1          /* the scalar SPD systems (A->super1) go supernodal */
#endif
#ifndef BP__SUPER_RELAX
#define BP__SUPER_RELAX 1           /* relaxed supernodes (sec 6.23) */
#endif
static int bp__super_relax(uint32_t nc, double nz, double size)
{
    double z = 1 - nz / size;
    return BP__SUPER_RELAX && (nc <= 2 || (nc <= 8 && z < 0.8) || (nc <= 24 && z < 0.1) || z < 0.05);
}

/* The supernodes: fundamental ones (column k-1 joins k's run when k is
   its parent in the elimination tree and its row count is one more:
   then its pattern is {k} and k's), never across a boundary of the
   dissection tree (so that every tree node's range is whole supernodes),
   then relaxed: a run is merged with the next one when that one is its
   parent and bp__super_relax agrees.  Writes first[0 .. ns], returns ns;
   msz[s] = |rows| of each. */
static uint32_t bp__super_partition(const uint32_t *parent, const uint32_t *cnt, const uint8_t *bound, uint32_t nv,
                                    uint32_t *first, uint32_t *msz)
{
    uint32_t k = 0, e, ns = 0, f = 0, nc = 0, m = 0, nct, mt;
    double nz = 0, nzt;
    while (k < nv) {
        /* the fundamental run [k, e): nct columns, mt rows */
        e = k;
        nzt = 0;
        do { nzt += cnt[e] + 1; e++; }
        while (e < nv && !bound[e] && parent[e - 1] == e && cnt[e - 1] == cnt[e] + 1);
        nct = e - k;
        mt = nct + cnt[e - 1];
        if (k > 0 && !bound[k] && parent[k - 1] == k &&
            bp__super_relax(nc + nct, nz + nzt, (double)(nc + nct) * (nc + mt) - (double)(nc + nct) * (nc + nct - 1) / 2)) {
            m = nc + mt;                  /* the group's columns, then the run's rows */
            nc += nct;
            nz += nzt;
        } else {
            if (k > 0) { first[ns] = f; msz[ns++] = m; }
            f = k; nc = nct; m = mt; nz = nzt;
        }
        k = e;
    }
    if (nv > 0) { first[ns] = f; msz[ns++] = m; }
    first[ns] = nv;
    return ns;
}

static int bp__u32_cmp(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* Sort a few vertex numbers: by insertion for the short lists meshes give
   (a vertex's neighbours, a dozen; a supernode's rows, 16 on average on
   face), by qsort beyond 32 (a hole centre's neighbours, a separator's
   rows). */
static void bp__u32_sort(uint32_t *v, uint32_t n)
{
    uint32_t k, m;
    if (n > 32) { qsort(v, n, sizeof(uint32_t), bp__u32_cmp); return; }
    for (k = 1; k < n; k++) {
        uint32_t x = v[k];
        for (m = k; m > 0 && v[m - 1] > x; m--) v[m] = v[m - 1];
        v[m] = x;
    }
}

/* Who updates whom: supernode K's rows below its columns fall in runs,
   one per supernode J they belong to; each run is an update K -> J,
   listed under J in increasing K (the fixed order of every sum). */
static int bp__super_updates(const bp_allocator *a, bp__super *S)
{
    uint32_t K, q, J, ns = S->ns, tot = 0;
    S->up = (uint32_t *)bp__calloc_array(a, (size_t)ns + 1, sizeof(uint32_t));
    if (!S->up) return 0;
    for (K = 0; K < ns; K++)
        for (q = S->rp[K] + S->first[K + 1] - S->first[K], J = BP__NONE; q < S->rp[K + 1]; q++)
            if (S->snode[S->ri[q]] != J) { J = S->snode[S->ri[q]]; S->up[J + 1]++; tot++; }
    for (J = 0; J < ns; J++) S->up[J + 1] += S->up[J];
    S->uk = (uint32_t *)bp__alloc_array(a, tot ? tot : 1, sizeof(uint32_t));
    S->uo = (uint32_t *)bp__alloc_array(a, tot ? tot : 1, sizeof(uint32_t));
    if (!S->uk || !S->uo) return 0;
    for (K = 0; K < ns; K++)
        for (q = S->rp[K] + S->first[K + 1] - S->first[K], J = BP__NONE; q < S->rp[K + 1]; q++)
            if (S->snode[S->ri[q]] != J) {
                J = S->snode[S->ri[q]];
                S->uk[S->up[J]] = K;
                S->uo[S->up[J]++] = q - S->rp[K];
            }
    for (J = ns; J > 0; J--) S->up[J] = S->up[J - 1];
    S->up[0] = 0;
    return 1;
}

/* The analysis on several threads (issue 15).  Three of its loops cost
   about 20 ms per call on bimba, serial, three calls per chart: the
   elimination tree, the column counts by row subtrees and the supernodes'
   rows.  Each is a loop in increasing k (or s) that reads only what
   earlier iterations wrote, but the dissection that ordered the matrix
   bounds how far back: a vertex of the tree node [lo, hi) = [A | B | S]
   has its neighbours in [lo, hi) and in the separators of its ancestors,
   which come after hi, never in a sibling's range.  So
     - row k's etree step (Liu's path-compressed ancestors) and its row
       subtree (which walks parent[] from k's neighbours j < k up to k)
       touch only parent[], the ancestor links, the stamps and the counts
       of vertices in [lo, k), lo the start of the smallest recorded node
       holding k;
     - supernode s's rows are merged from its own columns and its
       children's rows, and its children lie in the same node (a child's
       last vertex has its etree parent in s).
   The loops therefore run in the phases of the numeric factorization
   (bp__nd_phase): the whole subtrees of phase 0 in parallel, then the
   separators [b, hi) bottom-up, each node's rows or supernodes in their
   own increasing order.  Every value written is the one the serial loop
   writes (the etree and the counts are functions of the pattern; each
   row's steps are the serial steps restricted to the node's range).
   The stamps of the supernodes' rows are the one exception: a separator
   vertex u above a node is a row of supernodes in several nodes at once,
   so each task stamps in its own array (mark + t n), unless the runner
   is serial (threads 1): the stamps are supernode numbers, so one array
   serves tasks that run one after another.  When the tree's
   phases do not cover [0, n) exactly (no tree: a small matrix), the
   loops run whole, serially. */
typedef struct bp__sym_task {
    const bp__sparse *G;
    const bp__factor *F;          /* tree, and the vertex order (perm, iperm) */
    bp__super *S;
    uint32_t *parent, *anc, *mark, *cnt, *head, *next;
    uint32_t nodes[BP__ND_NODES], n;
    size_t slot;                  /* task t stamps rows at mark + t slot */
    uint8_t *fresh;               /* slot t not yet set to BP__NONE (1)  */
    int phase, whole;             /* whole: the one task is [0, n)   */
    int bad[BP__ND_NODES];        /* a supernode's row count disagreed  */
} bp__sym_task;

/* Row k's subtree counted into the column counts: cnt[j]++ for every j on
   the paths from k's neighbours j < k up to k (bp__row_subtree without
   the list). */
static void bp__row_count(const bp__sparse *A, const bp__factor *F, const uint32_t *parent, uint32_t *mark, uint32_t k,
                          uint32_t *cnt)
{
    uint32_t old = F->perm[k], p, j;
    mark[k] = k;
    for (p = A->colp[old]; p < A->colp[old + 1]; p++)
        for (j = F->iperm[A->row[p]]; j < k && mark[j] != k; j = parent[j]) {
            mark[j] = k;
            cnt[j]++;
        }
}

/* The range of task t of a phase: a whole subtree in phase 0, the
   separator [b, hi) after. */
static void bp__sym_range(const bp__sym_task *T, uint32_t t, uint32_t *k0, uint32_t *k1)
{
    const bp__ndnode *N = &T->F->tree[T->nodes[t]];
    if (T->whole) { *k0 = 0; *k1 = T->n; return; }
    *k0 = T->phase == 0 ? N->lo : N->b;
    *k1 = N->hi;
}

/* Task t: the etree and the column counts of its rows, row by row (row
   k's subtree needs parent[] only below k, set by rows up to k). */
static void bp__sym_counts_task(void *task, uint32_t t)
{
    bp__sym_task *T = (bp__sym_task *)task;
    uint32_t k, k0, k1;
    bp__sym_range(T, t, &k0, &k1);
    for (k = k0; k < k1; k++) {
        bp__etree_row(T->G, T->F, T->parent, T->anc, k);
        T->mark[k] = BP__NONE;
        bp__row_count(T->G, T->F, T->parent, T->mark, k, T->cnt);
    }
}

/* The rows of supernode s: its own vertices, the entries of G in its
   columns below it, and the rows below it of its children (Liu's
   multifrontal pattern; the children, listed from head[s] through next[],
   end before it), stamped s in mark.  Returns 0 if the count disagrees
   with the partition's (a bug, caught by the caller). */
static int bp__super_rows_one(const bp__sparse *G, bp__super *S, uint32_t *mark, const uint32_t *head,
                              const uint32_t *next, uint32_t s)
{
    uint32_t f = S->first[s], l = S->first[s + 1], w = S->rp[s], v, p, c, q;
    for (v = f; v < l; v++) { S->ri[w++] = v; mark[v] = s; }
    for (v = f; v < l; v++)
        for (p = G->colp[S->vperm[v]]; p < G->colp[S->vperm[v] + 1]; p++) {
            uint32_t u = S->viperm[G->row[p]];
            if (u >= l && mark[u] != s) { mark[u] = s; if (w < S->rp[s + 1]) S->ri[w] = u; w++; }
        }
    for (c = head[s]; c != BP__NONE; c = next[c])
        for (q = S->rp[c]; q < S->rp[c + 1]; q++) {
            uint32_t u = S->ri[q];
            if (u >= l && mark[u] != s) { mark[u] = s; if (w < S->rp[s + 1]) S->ri[w] = u; w++; }
        }
    if (w != S->rp[s + 1]) return 0;
    bp__u32_sort(S->ri + S->rp[s] + (l - f), w - S->rp[s] - (l - f));
    return 1;
}

/* Task t: the rows of the supernodes of its range, stamped in its own
   array (slot t), which the first task to use it sets to BP__NONE (slot
   t serves task t of every phase, one task at a time: ntask x n words,
   set in parallel and first touched by a thread that stamps them). */
static void bp__sym_rows_task(void *task, uint32_t t)
{
    bp__sym_task *T = (bp__sym_task *)task;
    bp__super *S = T->S;
    uint32_t k0, k1, s, j;
    if (T->fresh && T->fresh[t]) {
        uint32_t *m = T->mark + (size_t)t * T->slot;
        for (j = 0; j < T->n; j++) m[j] = BP__NONE;
        T->fresh[t] = 0;
    }
    bp__sym_range(T, t, &k0, &k1);
    if (k0 >= k1) return;
    for (s = S->snode[k0]; s <= S->snode[k1 - 1]; s++)
        if (!bp__super_rows_one(T->G, S, T->mark + (size_t)t * T->slot, T->head, T->next, s)) T->bad[t] = 1;
}

/* Run fn over the phases bottom-up (or once, whole). */
static void bp__sym_phases(bp__sym_task *T, const bp__par *par, bp_task_fn fn)
{
    int p;
    if (T->whole) { fn(T, 0); return; }
    for (p = 0; p <= BP__ND_DEPTH; p++) {
        uint32_t c = bp__nd_phase(T->F, p, T->nodes);
        T->phase = p;
        if (c) bp__par_run(par, fn, T, c, T->n);
    }
}

/* Whether the phases cover [0, n) exactly (each vertex in one range). */
static int bp__sym_covers(const bp__factor *F, uint32_t n)
{
    uint32_t nodes[BP__ND_NODES], c, i, sum = 0;
    int p;
    for (p = 0; p <= BP__ND_DEPTH; p++)
        for (c = bp__nd_phase(F, p, nodes), i = 0; i < c; i++) {
            const bp__ndnode *N = &F->tree[nodes[i]];
            sum += N->hi - (p == 0 ? N->lo : N->b);
        }
    return n > 0 && F->tree[0].used && F->tree[0].lo == 0 && F->tree[0].hi == n && sum == n;
}

/* The analysis on the vertex graph: ordering (nested dissection, its tree
   in F->tree in vertex ranges; on par's threads), elimination tree, column counts (by row
   subtrees), supernodes, their rows, the update lists and the blocks'
   offsets.  With order given (and its tree), that order instead of a
   new one: it must be a valid dissection of G (bp__nd_keeps). */
static bp_status bp__super_analyse(const bp_allocator *a, const bp__sparse *G, bp__factor *F, const bp__par *par,
                                   const uint32_t *order, const bp__ndnode *tree)
{
    bp__super *S = F->sn;
    uint32_t nv = G->n, k, s, *parent, *mark, *cnt, *reach, *msz, *marks = NULL;
    size_t j;
    bp__sym_task T;
    bp__par serial;
    double nnzl = 0;
    uint8_t *bound;
    bp__factor Fv;
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    memset(&T, 0, sizeof T);                       /* (T.fresh freed at done) */
    S->nv = nv;
    S->vperm = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    S->viperm = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    S->snode = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    S->first = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    parent = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    mark = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    cnt = (uint32_t *)bp__calloc_array(a, nv, sizeof(uint32_t));
    reach = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    msz = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    bound = (uint8_t *)bp__calloc_array(a, (size_t)nv + 1, 1);
    if (!S->vperm || !S->viperm || !S->snode || !S->first || !parent || !mark || !cnt || !reach || !msz || !bound) goto done;
    if (order) {                                   /* a given order (bp__factorize_order) */
        memcpy(S->vperm, order, nv * sizeof(uint32_t));
        memcpy(F->tree, tree, sizeof F->tree);
    } else if (!bp__nd_order(a, G, S->vperm, F->tree, BP__SUPER_ORDER, par))
        goto done;
    for (k = 0; k < nv; k++) S->viperm[S->vperm[k]] = k;
    memset(&Fv, 0, sizeof Fv);
    Fv.perm = S->vperm;
    Fv.iperm = S->viperm;
    memcpy(Fv.tree, F->tree, sizeof Fv.tree);
    serial = bp__par_serial();
    if (!par) par = &serial;
    memset(&T, 0, sizeof T);
    T.G = G; T.F = &Fv; T.S = S; T.n = nv;
    T.parent = parent; T.anc = reach; T.mark = mark; T.cnt = cnt;
    T.whole = !bp__sym_covers(&Fv, nv);
    S->ntask = 1;
    for (k = 0; k <= BP__ND_DEPTH; k++) {
        uint32_t c = bp__nd_phase(F, (int)k, T.nodes);
        if (c > S->ntask) S->ntask = c;
    }
    bp__sym_phases(&T, par, bp__sym_counts_task);         /* etree, column counts */
    for (k = 0; k < BP__ND_NODES; k++)
        if (F->tree[k].used) { bound[F->tree[k].lo] = bound[F->tree[k].a] = bound[F->tree[k].b] = bound[F->tree[k].hi] = 1; }
    S->ns = bp__super_partition(parent, cnt, bound, nv, S->first, msz);
    S->rp = (uint32_t *)bp__alloc_array(a, (size_t)S->ns + 1, sizeof(uint32_t));
    S->xp = (size_t *)bp__alloc_array(a, (size_t)S->ns + 1, sizeof(size_t));
    if (!S->rp || !S->xp) goto done;
    S->rp[0] = 0;
    S->xp[0] = 0;
    S->maxcols = S->maxrows = 0;
    for (s = 0; s < S->ns; s++) {
        uint32_t nc = S->first[s + 1] - S->first[s];
        double cb = (double)S->bs * nc;
        nnzl += cb * S->bs * msz[s] - cb * (cb + 1) / 2;        /* L's entries below the diagonal */
        if ((uint64_t)S->rp[s] + msz[s] > BP__FACTOR_MAX_NNZ || nnzl > BP__FACTOR_MAX_NNZ) { st = BP_ERR_TOO_LARGE; goto done; }
        S->rp[s + 1] = S->rp[s] + msz[s];
        S->xp[s + 1] = S->xp[s] + (size_t)S->bs * S->bs * msz[s] * nc;
        if (S->bs * nc > S->maxcols) S->maxcols = S->bs * nc;
        if (msz[s] > S->maxrows) S->maxrows = msz[s];
        for (k = S->first[s]; k < S->first[s + 1]; k++) S->snode[k] = s;
    }
    S->ri = (uint32_t *)bp__alloc_array(a, S->rp[S->ns] ? S->rp[S->ns] : 1, sizeof(uint32_t));
    if (!S->ri) goto done;
    /* the children lists (in cnt and reach), then the rows by phases, each
       task stamping in its own array */
    T.head = cnt; T.next = reach;
    for (s = 0; s < S->ns; s++) T.head[s] = BP__NONE;
    for (s = 0; s < S->ns; s++) {
        uint32_t last = parent[S->first[s + 1] - 1];
        if (last != BP__NONE) { uint32_t t = S->snode[last]; T.next[s] = T.head[t]; T.head[t] = s; }
    }
    T.slot = T.whole || par->threads == 1 ? 0 : nv;
    marks = T.slot ? (uint32_t *)bp__alloc_array(a, (size_t)S->ntask * nv, sizeof(uint32_t)) : mark;
    T.fresh = T.slot ? (uint8_t *)bp__alloc_array(a, S->ntask, 1) : NULL;
    if (!marks || (T.slot && !T.fresh)) goto done;
    if (T.slot) memset(T.fresh, 1, S->ntask);     /* each slot set by its first task */
    else for (j = 0; j < nv; j++) marks[j] = BP__NONE;
    T.mark = marks;
    bp__sym_phases(&T, par, bp__sym_rows_task);
    for (k = 0; k < BP__ND_NODES; k++)
        if (T.bad[k]) { st = BP_ERR_NUMERICAL; goto done; }
    if (!bp__super_updates(a, S)) goto done;
    st = BP_OK;
done:
    if (marks != mark) bp__free(a, marks);
    bp__free(a, T.fresh);
    bp__free(a, parent); bp__free(a, mark); bp__free(a, cnt); bp__free(a, reach); bp__free(a, msz); bp__free(a, bound);
    return st;
}

/* The dense kernels on 256-bit registers.  The sums of the two kernels
   below (bp__super_dots, bp__super_trsm_rows) run in two lanes, even and
   odd k, as their comments say.  On an x86-64 processor with AVX (asked
   at run time by the compiler's __builtin_cpu_supports; GCC or Clang;
   BP_NO_SIMD leaves this out, >>config) one register holds the two lanes
   of two rows, [a0[k] a0[k+1] a1[k] a1[k+1]], and multiplies them by
   [b[k] b[k+1] b[k] b[k+1]]: each lane gets the very terms, in the very
   order, of the plain loops -- separate multiplications and additions,
   never a fused multiply-add -- so the factor has the same bits with AVX
   or without (tests/test_sparse.c (k) compares the two) for half the
   instructions.  The odd last term goes to the even lane after the
   registers, as in the plain loops.  On face's Newton matrix (5.4e8
   multiply-adds) one numeric factorization takes 0.050 s instead of
   0.074 (the least of 9 runs; docs/performance.md 6.28).  A build that
   lets the compiler fuse the plain loops' multiply-adds (FMA enabled by
   -mfma or -march, with GCC's -ffp-contract=fast or Clang's default)
   gets other bits in those loops; the default target has no FMA. */
#if BP__AVX
/* Rows a0, a1 at k, k+1 in one register. */
#define BP__AVX_ROWS(a0, a1, k) \
    _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd((a0) + (k))), _mm_loadu_pd((a1) + (k)), 1)

/* bp__super_dots for four rows: s[2r + c] = a_r . b_c. */
__attribute__((target("avx")))
static void bp__super_dots_avx(const double *a, size_t stride, const double *b0, const double *b1, uint32_t n,
                               double *s)
{
    const double *a0 = a, *a1 = a + stride, *a2 = a1 + stride, *a3 = a2 + stride;
    __m256d c0 = _mm256_setzero_pd(), c1 = c0, c2 = c0, c3 = c0;
    double t[4][4];
    uint32_t k;
    int r;
    for (k = 0; k + 1 < n; k += 2) {
        __m256d y = _mm256_broadcast_pd((const __m128d *)(b0 + k)), z = _mm256_broadcast_pd((const __m128d *)(b1 + k));
        __m256d x01 = BP__AVX_ROWS(a0, a1, k), x23 = BP__AVX_ROWS(a2, a3, k);
        c0 = _mm256_add_pd(c0, _mm256_mul_pd(x01, y)); c1 = _mm256_add_pd(c1, _mm256_mul_pd(x01, z));
        c2 = _mm256_add_pd(c2, _mm256_mul_pd(x23, y)); c3 = _mm256_add_pd(c3, _mm256_mul_pd(x23, z));
    }
    _mm256_storeu_pd(t[0], c0); _mm256_storeu_pd(t[1], c1); _mm256_storeu_pd(t[2], c2); _mm256_storeu_pd(t[3], c3);
    /* t[2 h + c] = (even, odd of row 2h, even, odd of row 2h + 1) with b_c */
    if (k < n) {
        t[0][0] += a0[k] * b0[k]; t[1][0] += a0[k] * b1[k]; t[0][2] += a1[k] * b0[k]; t[1][2] += a1[k] * b1[k];
        t[2][0] += a2[k] * b0[k]; t[3][0] += a2[k] * b1[k]; t[2][2] += a3[k] * b0[k]; t[3][2] += a3[k] * b1[k];
    }
    for (r = 0; r < 4; r++) {
        const double *e0 = t[2 * (r / 2)] + 2 * (r % 2), *e1 = t[2 * (r / 2) + 1] + 2 * (r % 2);
        s[2 * r] = e0[0] + e0[1];
        s[2 * r + 1] = e1[0] + e1[1];
    }
}

/* bp__super_trsm_rows for the four rows r0 .. r3 (= r0 + 3 c2), columns
   [j0, j1). */
__attribute__((target("avx")))
static void bp__super_trsm4_avx(double *B, uint32_t c2, double *r0, uint32_t j0, uint32_t j1, const double *inv)
{
    double *r1 = r0 + c2, *r2 = r1 + c2, *r3 = r2 + c2, t[2][4];
    uint32_t j, k;
    for (j = j0; j < j1; j++) {
        const double *rj = B + (size_t)j * c2;
        __m256d c01 = _mm256_setzero_pd(), c23 = c01;
        for (k = 0; k + 1 < j; k += 2) {
            __m256d y = _mm256_broadcast_pd((const __m128d *)(rj + k));
            c01 = _mm256_add_pd(c01, _mm256_mul_pd(BP__AVX_ROWS(r0, r1, k), y));
            c23 = _mm256_add_pd(c23, _mm256_mul_pd(BP__AVX_ROWS(r2, r3, k), y));
        }
        _mm256_storeu_pd(t[0], c01); _mm256_storeu_pd(t[1], c23);
        if (k < j) { t[0][0] += r0[k] * rj[k]; t[0][2] += r1[k] * rj[k]; t[1][0] += r2[k] * rj[k]; t[1][2] += r3[k] * rj[k]; }
        r0[j] = (r0[j] - (t[0][0] + t[0][1])) * inv[j];
        r1[j] = (r1[j] - (t[0][2] + t[0][3])) * inv[j];
        r2[j] = (r2[j] - (t[1][0] + t[1][1])) * inv[j];
        r3[j] = (r3[j] - (t[1][2] + t[1][3])) * inv[j];
    }
}
#endif

/* The update kernel: s[2r + c] = a_r . b_c for the nr <= 4 rows
   a_r = a + r stride and the two rows b_0, b_1, n terms each.  Every sum
   runs in two lanes, even and odd k (an odd n's last term goes to the
   even lane), added at the end: a fixed order, so the same bits on any
   schedule, and one that compilers turn into packed SIMD instructions
   without licence to reassociate. */
static void bp__super_dots(const double *a, size_t stride, int nr, const double *b0, const double *b1, uint32_t n,
                           double *s, int avx)
{
    uint32_t k;
    int r;
#if BP__AVX
    if (avx && nr == 4) { bp__super_dots_avx(a, stride, b0, b1, n, s); return; }
#else
    (void)avx;
#endif
    if (nr == 4) {
        const double *a0 = a, *a1 = a + stride, *a2 = a1 + stride, *a3 = a2 + stride;
        double e00 = 0, o00 = 0, e01 = 0, o01 = 0, e10 = 0, o10 = 0, e11 = 0, o11 = 0;
        double e20 = 0, o20 = 0, e21 = 0, o21 = 0, e30 = 0, o30 = 0, e31 = 0, o31 = 0;
        for (k = 0; k + 1 < n; k += 2) {
            double y0 = b0[k], z0 = b0[k + 1], y1 = b1[k], z1 = b1[k + 1];
            e00 += a0[k] * y0; o00 += a0[k + 1] * z0; e01 += a0[k] * y1; o01 += a0[k + 1] * z1;
            e10 += a1[k] * y0; o10 += a1[k + 1] * z0; e11 += a1[k] * y1; o11 += a1[k + 1] * z1;
            e20 += a2[k] * y0; o20 += a2[k + 1] * z0; e21 += a2[k] * y1; o21 += a2[k + 1] * z1;
            e30 += a3[k] * y0; o30 += a3[k + 1] * z0; e31 += a3[k] * y1; o31 += a3[k + 1] * z1;
        }
        if (k < n) {
            e00 += a0[k] * b0[k]; e01 += a0[k] * b1[k]; e10 += a1[k] * b0[k]; e11 += a1[k] * b1[k];
            e20 += a2[k] * b0[k]; e21 += a2[k] * b1[k]; e30 += a3[k] * b0[k]; e31 += a3[k] * b1[k];
        }
        s[0] = e00 + o00; s[1] = e01 + o01; s[2] = e10 + o10; s[3] = e11 + o11;
        s[4] = e20 + o20; s[5] = e21 + o21; s[6] = e30 + o30; s[7] = e31 + o31;
        return;
    }
    for (r = 0; r < nr; r++) {
        const double *a0 = a + (size_t)r * stride;
        double e0 = 0, o0 = 0, e1 = 0, o1 = 0;
        for (k = 0; k + 1 < n; k += 2) {
            e0 += a0[k] * b0[k]; o0 += a0[k + 1] * b0[k + 1];
            e1 += a0[k] * b1[k]; o1 += a0[k + 1] * b1[k + 1];
        }
        if (k < n) { e0 += a0[k] * b0[k]; e1 += a0[k] * b1[k]; }
        s[2 * r] = e0 + o0;
        s[2 * r + 1] = e1 + o1;
    }
}

/* The update of supernode J (block B, bs nc columns) by supernode K from
   K's row position o, in J's column vertices [v0, v1): for K's rows
   i >= c and its rows c that are such columns,
       L_J(i, c) -= sum_k L_K(i, k) L_K(c, k),
   two columns of B at a time (bs 2: x and y of a column vertex; bs 1: two
   column vertices, the second only when it is a column in range too; an
   entry this puts above the diagonal of J's diagonal block is never
   read), four rows of B at a time.  Where K's rows lie in J's: map[] (a
   vertex's row in J), or with map NULL by a merge of the two sorted
   lists; pos: mK words. */
static void bp__super_update(const bp__super *S, uint32_t K, uint32_t o, uint32_t J, double *B, const uint32_t *map,
                             uint32_t *pos, uint32_t v0, uint32_t v1)
{
    const uint32_t *rk = S->ri + S->rp[K], *rj = S->ri + S->rp[J];
    const double *LK = S->x + S->xp[K];
    uint32_t bs = S->bs, mK = S->rp[K + 1] - S->rp[K], cK = bs * (S->first[K + 1] - S->first[K]);
    uint32_t f = S->first[J], c2 = bs * (S->first[J + 1] - f), c, i, r, q = 0;
    int avx = cK >= 8 && BP__HAVE_AVX();
    for (c = o; c < mK && rk[c] < v0; c++) {}
    if (c == mK || rk[c] >= v1) return;
    for (i = c; i < mK; i++) {
        if (map) pos[i] = map[rk[i]];
        else { while (rj[q] < rk[i]) q++; pos[i] = q; }
    }
    for (; c < mK && rk[c] < v1; c += 2 / bs) {
        uint32_t R0 = bs * c, R1 = bs == 2 ? R0 + 1 : c + 1 < mK && rk[c + 1] < v1 ? c + 1 : c;
        uint32_t j0 = bs * (rk[c] - f), j1 = bs == 2 ? j0 + 1 : rk[R1] - f;
        const double *b0 = LK + (size_t)R0 * cK, *b1 = LK + (size_t)R1 * cK;
        for (i = R0; i < bs * mK; i += 4) {
            int nr = bs * mK - i < 4 ? (int)(bs * mK - i) : 4;
            double s[8];
            bp__super_dots(LK + (size_t)i * cK, cK, nr, b0, b1, cK, s, avx);
            for (r = 0; r < (uint32_t)nr; r++) {
                double *t = B + ((size_t)bs * pos[(i + r) >> (bs - 1)] + ((i + r) & (bs - 1))) * c2;
                t[j0] -= s[2 * r];
                if (R1 != R0) t[j1] -= s[2 * r + 1];
            }
        }
    }
}

/* The dense Cholesky of supernode s's block B (2|rows| x c2, by rows)
   after its updates, entry by entry,
       L(i, j) = (B(i, j) - sum_{k<j} L(i, k) L(j, k)) / L(j, j),   j < i,
       d_i = B(i, i) - sum_{k<i} L(i, k)^2,   L(i, i) = sqrt(d_i),
   the diagonal block's rows first, then the rows below it (a triangular
   solve with L's diagonal block, j < c2).  Each sum runs in a fixed order:
   in the diagonal block one accumulator over increasing k; below it two
   lanes, even and odd k (an odd count's last term to the even lane),
   added at the end, as in bp__super_dots.  Every entry needs only its own
   row left of it and the rows j above it up to column j, so the order in
   which entries are computed is free as long as that holds, and the bits
   never depend on it.  The work goes by panels of BP__DENSE_PANEL
   columns [q0, q1):
     the triangle: the panel's own rows i in [q0, q1), columns [q0, i),
       and their pivots (their columns left of q0 are done);
     the rows below the triangle, i >= q1, in columns [q0, q1): each row
       independent of the others, so big supernodes (the top separators,
       where a phase has fewer tasks than threads) cut them into ranges
       for several threads (the WIDE pass below).
   Rows go four at a time where they can (four independent sums, so the
   loads of row j serve four rows and the additions do not wait on each
   other; one row at a time gives the same bits).  D[] gets the pivots
   d_i; one that is not positive leaves a NaN or infinity behind, which
   the caller's check of D reports. */
#define BP__DENSE_PANEL 32u               /* columns; a multiple of 4 */

/* Rows [i0, i1) of the diagonal block, columns [j0, j1) (j1 <= i0): each
   sum one chain of subtractions, so eight rows at a time where they can
   (eight chains in flight: 3% of face's factorization), then four, then
   one; every row's chain is the same whatever the grouping. */
static void bp__super_diag_rows(double *B, uint32_t c2, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1,
                                const double *inv)
{
    uint32_t i = i0, j, k;
    for (; i + 8 <= i1; i += 8) {
        double *r0 = B + (size_t)i * c2, *r1 = r0 + c2, *r2 = r1 + c2, *r3 = r2 + c2;
        double *r4 = r3 + c2, *r5 = r4 + c2, *r6 = r5 + c2, *r7 = r6 + c2;
        for (j = j0; j < j1; j++) {
            const double *rj = B + (size_t)j * c2;
            double t0 = r0[j], t1 = r1[j], t2 = r2[j], t3 = r3[j], t4 = r4[j], t5 = r5[j], t6 = r6[j], t7 = r7[j];
            for (k = 0; k < j; k++) {
                double y = rj[k];
                t0 -= r0[k] * y; t1 -= r1[k] * y; t2 -= r2[k] * y; t3 -= r3[k] * y;
                t4 -= r4[k] * y; t5 -= r5[k] * y; t6 -= r6[k] * y; t7 -= r7[k] * y;
            }
            r0[j] = t0 * inv[j]; r1[j] = t1 * inv[j]; r2[j] = t2 * inv[j]; r3[j] = t3 * inv[j];
            r4[j] = t4 * inv[j]; r5[j] = t5 * inv[j]; r6[j] = t6 * inv[j]; r7[j] = t7 * inv[j];
        }
    }
    for (; i + 4 <= i1; i += 4) {
        double *r0 = B + (size_t)i * c2, *r1 = r0 + c2, *r2 = r1 + c2, *r3 = r2 + c2;
        for (j = j0; j < j1; j++) {
            const double *rj = B + (size_t)j * c2;
            double t0 = r0[j], t1 = r1[j], t2 = r2[j], t3 = r3[j];
            for (k = 0; k < j; k++) {
                double y = rj[k];
                t0 -= r0[k] * y; t1 -= r1[k] * y; t2 -= r2[k] * y; t3 -= r3[k] * y;
            }
            r0[j] = t0 * inv[j]; r1[j] = t1 * inv[j]; r2[j] = t2 * inv[j]; r3[j] = t3 * inv[j];
        }
    }
    for (; i < i1; i++) {
        double *r = B + (size_t)i * c2;
        for (j = j0; j < j1; j++) {
            const double *rj = B + (size_t)j * c2;
            double t = r[j];
            for (k = 0; k < j; k++) t -= r[k] * rj[k];
            r[j] = t * inv[j];
        }
    }
}

/* Rows [i0, i1) below the diagonal block (i0 >= c2), columns [j0, j1):
   the two-lane sums. */
static void bp__super_trsm_rows(double *B, uint32_t c2, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1,
                                const double *inv)
{
    uint32_t i = i0, j, k;
#if BP__AVX
    if (j1 >= 8 && BP__HAVE_AVX())
        for (; i + 4 <= i1; i += 4) bp__super_trsm4_avx(B, c2, B + (size_t)i * c2, j0, j1, inv);
#endif
    for (; i + 4 <= i1; i += 4) {
        double *r0 = B + (size_t)i * c2, *r1 = r0 + c2, *r2 = r1 + c2, *r3 = r2 + c2;
        for (j = j0; j < j1; j++) {
            const double *rj = B + (size_t)j * c2;
            double e0 = 0, o0 = 0, e1 = 0, o1 = 0, e2 = 0, o2 = 0, e3 = 0, o3 = 0;
            for (k = 0; k + 1 < j; k += 2) {
                double y = rj[k], z = rj[k + 1];
                e0 += r0[k] * y; o0 += r0[k + 1] * z; e1 += r1[k] * y; o1 += r1[k + 1] * z;
                e2 += r2[k] * y; o2 += r2[k + 1] * z; e3 += r3[k] * y; o3 += r3[k + 1] * z;
            }
            if (k < j) { e0 += r0[k] * rj[k]; e1 += r1[k] * rj[k]; e2 += r2[k] * rj[k]; e3 += r3[k] * rj[k]; }
            r0[j] = (r0[j] - (e0 + o0)) * inv[j];
            r1[j] = (r1[j] - (e1 + o1)) * inv[j];
            r2[j] = (r2[j] - (e2 + o2)) * inv[j];
            r3[j] = (r3[j] - (e3 + o3)) * inv[j];
        }
    }
    for (; i < i1; i++) {
        double *r0 = B + (size_t)i * c2;
        for (j = j0; j < j1; j++) {
            const double *rj = B + (size_t)j * c2;
            double e0 = 0, o0 = 0;
            for (k = 0; k + 1 < j; k += 2) { e0 += r0[k] * rj[k]; o0 += r0[k + 1] * rj[k + 1]; }
            if (k < j) e0 += r0[k] * rj[k];
            r0[j] = (r0[j] - (e0 + o0)) * inv[j];
        }
    }
}

/* Rows [i0, i1) (all at or below q1) in the panel's columns [q0, q1). */
static void bp__super_panel_rows(double *B, uint32_t c2, uint32_t i0, uint32_t i1, uint32_t q0, uint32_t q1,
                                 const double *inv)
{
    if (i0 < c2) bp__super_diag_rows(B, c2, i0, i1 < c2 ? i1 : c2, q0, q1, inv);
    if (i1 > c2) bp__super_trsm_rows(B, c2, i0 > c2 ? i0 : c2, i1, q0, q1, inv);
}

/* The panel's triangle: rows i in [q0, q1), columns [q0, i), pivots. */
static void bp__super_panel_tri(double *B, uint32_t c2, uint32_t q0, uint32_t q1, double *D, double *inv)
{
    uint32_t i, k;
    for (i = q0; i < q1; i++) {
        double *r = B + (size_t)i * c2, d;
        bp__super_diag_rows(B, c2, i, i + 1, q0, i, inv);
        d = r[i];
        for (k = 0; k < i; k++) d -= r[k] * r[k];
        D[i] = d;
        r[i] = sqrt(d);
        inv[i] = 1 / r[i];
    }
}

/* The panels in turn; with a runner (par not NULL) and a block of at
   least BP__DENSE_WIDE multiply-adds, each panel's rows below its
   triangle go to 2 x threads tasks of whole groups of four rows (the
   WIDE pass), else on the calling thread.
   Look-ahead: the next panel's triangle needs only its own rows, all
   finished up to the current panel once this pass is done.  So task 0
   of a pass takes exactly those rows (the next panel's, [q1, q2)) and
   then that triangle, while the other tasks share the rows below q2;
   the caller no longer computes each triangle alone between two passes
   (measured on face with 2 threads: 4.6 ms of such triangles in a run).
   Every entry and pivot is the same sum as before, in the same order:
   each row's values depend only on its own chains, not on which task
   or group of rows holds it; the same bits.  The first panel's triangle,
   and any after a pass too short to cut, stay on the caller. */
#define BP__SUPER_PIECES 64u              /* pieces per parallel loop, at most */
#define BP__DENSE_WIDE 2000000.0          /* multiply-adds of a block worth cutting */
typedef struct bp__dense_task {
    double *B, *D, *inv;
    uint32_t c2, q0, q1, q2;              /* q2: the next panel's end, 0 without look-ahead */
    uint32_t cut[BP__SUPER_PIECES + 2];
} bp__dense_task;

static void bp__dense_run(void *task, uint32_t t)
{
    bp__dense_task *T = (bp__dense_task *)task;
    bp__super_panel_rows(T->B, T->c2, T->cut[t], T->cut[t + 1], T->q0, T->q1, T->inv);
    if (t == 0 && T->q2) bp__super_panel_tri(T->B, T->c2, T->q1, T->q2, T->D, T->inv);
}

static void bp__super_dense(bp__factor *F, uint32_t s, double *B, double *inv, const bp__par *par)
{
    const bp__super *S = F->sn;
    uint32_t f = S->first[s], c2 = S->bs * (S->first[s + 1] - f), m2 = S->bs * (S->rp[s + 1] - S->rp[s]), parts = 1, r;
    uint32_t ahead = 0, n;               /* ahead: this panel's triangle is done */
    bp__dense_task T;
    if (par && (double)m2 * c2 * c2 / 2 >= BP__DENSE_WIDE) parts = 2 * (uint32_t)par->threads;
    if (parts > BP__SUPER_PIECES) parts = BP__SUPER_PIECES;
    T.B = B; T.D = F->D + (size_t)S->bs * f; T.inv = inv; T.c2 = c2;
    for (T.q0 = 0; T.q0 < c2; T.q0 = T.q1) {
        uint32_t rows, lo;
        T.q1 = T.q0 + BP__DENSE_PANEL < c2 ? T.q0 + BP__DENSE_PANEL : c2;
        if (!ahead) bp__super_panel_tri(B, c2, T.q0, T.q1, T.D, inv);
        rows = m2 - T.q1;
        ahead = 0;
        if (parts == 1 || rows < 8 * parts) { bp__super_panel_rows(B, c2, T.q1, m2, T.q0, T.q1, inv); continue; }
        T.q2 = T.q1 + BP__DENSE_PANEL < c2 ? T.q1 + BP__DENSE_PANEL : c2;
        if (T.q1 < c2 && m2 - T.q2 >= 8 * parts) {  /* task 0: the next panel's rows, then its triangle */
            T.cut[0] = T.q1;
            lo = T.q2;
            n = 1;
            ahead = 1;
        } else {
            T.q2 = 0;
            lo = T.q1;
            n = 0;
        }
        rows = m2 - lo;
        for (r = 0; r < parts; r++) T.cut[n + r] = lo + 4 * (uint32_t)(((uint64_t)rows / 4 * r) / parts);
        T.cut[n + parts] = m2;
        par->run(par->user, bp__dense_run, &T, n + parts);
    }
}

/* Supernode s's column vertices [v0, v1) set to A's values: zero, then
   A(R, v) placed: entry p of A, in row vertex u = viperm[row / bs], goes
   to the row r of s's sorted rows with rows[r] = u (none when u < first[s]:
   the upper triangle), and into B's row bs r + row % bs.  Finding r is a
   look-up in map[] (a vertex's row in s, filled by the caller: the whole
   nodes of the dissection's phases) or else a binary search of s's rows
   (the separators' pieces); Newton refactors the same pattern at every
   factorized iteration, so for bs 2 the first numeric factorization also
   writes B's row (or BP__NONE) to the scatter map amap[p] (one word per
   entry of A; every p belongs to one column, so to one task: no races),
   and the later ones read it: no search, no division.  The same place
   either way, so the same bits. */
static void bp__super_start(const bp__sparse *A, const bp__super *S, uint32_t s, uint32_t v0, uint32_t v1,
                            const uint32_t *map)
{
    uint32_t bs = S->bs, f = S->first[s], c2 = bs * (S->first[s + 1] - f), m = S->rp[s + 1] - S->rp[s], i, v, p, b, col;
    const uint32_t *rows = S->ri + S->rp[s];
    uint32_t *amap = S->amap;
    double *B = S->x + S->xp[s];
    for (i = 0; i < bs * m; i++) memset(B + (size_t)i * c2 + bs * (v0 - f), 0, (size_t)bs * (v1 - v0) * sizeof(double));
    for (v = v0; v < v1; v++)
        for (b = 0; b < bs; b++) {
            col = bs * S->vperm[v] + b;
            if (amap && S->amap_ok) {
                double *Bc = B + bs * (v - f) + b;
                for (p = A->colp[col]; p < A->colp[col + 1]; p++)
                    if (amap[p] != BP__NONE) Bc[(size_t)amap[p] * c2] = A->val[p];
                continue;
            }
            for (p = A->colp[col]; p < A->colp[col + 1]; p++) {
                uint32_t u = S->viperm[A->row[p] >> (bs - 1)], r;
                if (amap) amap[p] = BP__NONE;
                if (u < f) continue;
                r = map ? map[u] : bp__lower_bound(rows, 0, m, u);
                if (amap) amap[p] = bs * r + (A->row[p] & (bs - 1));
                B[((size_t)bs * r + (A->row[p] & (bs - 1))) * c2 + bs * (v - f) + b] = A->val[p];
            }
        }
}

/* Supernode s from its update q0 on (the earlier ones done), then the
   dense factorization; with q0 = up[s] after bp__super_start, the whole
   supernode.  map: nv words holding each of s's rows' place in s (the
   caller fills it), pos: maxrows words of workspace. */
static void bp__super_finish(bp__factor *F, uint32_t s, uint32_t q0, const uint32_t *map, uint32_t *pos, double *inv)
{
    const bp__super *S = F->sn;
    uint32_t f = S->first[s], l = S->first[s + 1], q;
    double *B = S->x + S->xp[s];
    for (q = q0; q < S->up[s + 1]; q++) bp__super_update(S, S->uk[q], S->uo[q], s, B, map, pos, f, l);
    bp__super_dense(F, s, B, inv, NULL);
}

/* The numeric factorization in the phases of the dissection tree (as
   bp__fact_numeric's): phase 0 the subtrees whole, one task per tree
   node, its supernodes in order.  A separator [b, hi) of phase p > 0
   takes two passes, as in the scalar code: most of its work is the
   updates from supernodes below b, finished in earlier phases, and those
   are independent of each other's results.
     OUTSIDE: pieces (a supernode of the separator and a range of its
       column vertices, cut by equal shares of the trapezoid's rows) in
       parallel: bp__super_start, then the updates from below b;
     INSIDE: one task per separator, its supernodes in order: the updates
       from within the separator, then the dense factorization.
   A supernode reads only blocks of its descendants, all finished in
   earlier phases or earlier in its own task, and every entry sums its
   terms in increasing K either way, so every value is the same on any
   schedule and any cut into pieces. */
typedef struct bp__super_piece { uint32_t s, v0, v1, k0; } bp__super_piece;
typedef struct bp__super_task {
    const bp__sparse *A;
    bp__factor *F;
    uint32_t nodes[BP__ND_NODES];
    int mode;                     /* 0 whole nodes, 1 OUTSIDE, 2 INSIDE,
                                     3 WIDE's updates (bp__super_wide)    */
    bp__super_piece piece[BP__SUPER_PIECES];
    uint32_t *map;                /* ntask x nv                            */
    uint32_t *pos;                /* max(ntask, BP__SUPER_PIECES) x maxrows */
    double *inv;                  /* ntask x maxcols                       */
} bp__super_task;

static void bp__super_run(void *task, uint32_t t)
{
    bp__super_task *T = (bp__super_task *)task;
    const bp__super *S = T->F->sn;
    uint32_t *pos = T->pos + (size_t)t * S->maxrows, s, q;
    if (T->mode == 1) {
        const bp__super_piece *P = &T->piece[t];
        bp__super_start(T->A, S, P->s, P->v0, P->v1, NULL);
        for (q = S->up[P->s]; q < S->up[P->s + 1] && S->uk[q] < P->k0; q++)
            bp__super_update(S, S->uk[q], S->uo[q], P->s, S->x + S->xp[P->s], NULL, pos, P->v0, P->v1);
    } else if (T->mode == 3) {                             /* WIDE: the updates from k0 on */
        const bp__super_piece *P = &T->piece[t];
        for (q = S->up[P->s]; q < S->up[P->s + 1]; q++)
            if (S->uk[q] >= P->k0)
                bp__super_update(S, S->uk[q], S->uo[q], P->s, S->x + S->xp[P->s], NULL, pos, P->v0, P->v1);
    } else {
        const bp__ndnode *N = &T->F->tree[T->nodes[t]];
        uint32_t v0 = T->mode == 2 ? N->b : N->lo, *map = T->map + (size_t)t * S->nv;
        if (v0 >= N->hi) return;
        for (s = S->snode[v0]; s <= S->snode[N->hi - 1]; s++) {
            uint32_t i, m = S->rp[s + 1] - S->rp[s];
            const uint32_t *rows = S->ri + S->rp[s];
            for (i = 0; i < m; i++) map[rows[i]] = i;     /* s's rows' places, for start and finish */
            q = S->up[s];
            if (T->mode == 2)                              /* past the OUTSIDE updates */
                while (q < S->up[s + 1] && S->uk[q] < S->snode[v0]) q++;
            else
                bp__super_start(T->A, S, s, S->first[s], S->first[s + 1], map);
            bp__super_finish(T->F, s, q, map, pos, T->inv + (size_t)t * S->maxcols);
        }
    }
}

/* The OUTSIDE pass of one phase's separators, in loops of at most
   BP__SUPER_PIECES pieces: a supernode of nc vertices is cut into
   min(nc / 8, 8) column ranges (at least one) of about equal work, the
   column vertex j of m rows counting m - j. */
static uint32_t bp__super_cut(bp__super_task *T, const bp__par *par, uint32_t s, uint32_t k0, uint32_t n)
{
    const bp__super *S = T->F->sn;
    uint32_t f = S->first[s], nc = S->first[s + 1] - f, m = S->rp[s + 1] - S->rp[s], parts = nc / 8, r, j = 0;
    double w = 0, tot = (double)nc * m - (double)nc * (nc - 1) / 2;
    if (parts < 1) parts = 1;
    if (parts > 8) parts = 8;
    for (r = 0; r < parts; r++) {
        bp__super_piece *P = &T->piece[n];
        P->s = s;
        P->k0 = k0;
        P->v0 = f + j;
        while (j < nc && (r + 1 == parts || w < tot * (r + 1) / parts)) { w += m - j; j++; }
        P->v1 = f + j;
        if (P->v1 > P->v0 && ++n == BP__SUPER_PIECES) { par->run(par->user, bp__super_run, T, n); n = 0; }
    }
    return n;
}

static void bp__super_outside(bp__super_task *T, const bp__par *par, uint32_t cnt)
{
    const bp__super *S = T->F->sn;
    uint32_t k, s, n = 0;
    T->mode = 1;
    for (k = 0; k < cnt; k++) {
        const bp__ndnode *N = &T->F->tree[T->nodes[k]];
        if (N->b >= N->hi) continue;
        for (s = S->snode[N->b]; s <= S->snode[N->hi - 1]; s++) n = bp__super_cut(T, par, s, S->snode[N->b], n);
    }
    if (n) par->run(par->user, bp__super_run, T, n);
}

/* WIDE: a phase with fewer separators than threads (the top of the
   tree: one separator on two threads), or with one separator much
   bigger than the others (bp__super_unbalanced below), would leave
   threads idle in the INSIDE pass, and the top separators' dense blocks
   are the biggest of the factor.  So each separator in turn gets every thread: for each of
   its supernodes, the updates from within the separator in OUTSIDE-like
   pieces (mode 3: column ranges; each entry still takes its terms in
   increasing K), then the dense factorization with the runner (its
   panels' rows cut into ranges when the block is big; task 0's
   workspace on the calling thread).  The same entries get the same
   sums as in the one-task INSIDE pass: the same bits. */
static void bp__super_wide(bp__super_task *T, const bp__par *par, uint32_t cnt)
{
    bp__factor *F = T->F;
    const bp__super *S = F->sn;
    uint32_t k, s, q, n;
    for (k = 0; k < cnt; k++) {
        const bp__ndnode *N = &F->tree[T->nodes[k]];
        if (N->b >= N->hi) continue;
        for (s = S->snode[N->b]; s <= S->snode[N->hi - 1]; s++) {
            double *B = S->x + S->xp[s];
            for (q = S->up[s]; q < S->up[s + 1] && S->uk[q] < S->snode[N->b]; q++) {}
            if (q < S->up[s + 1]) {
                T->mode = 3;
                if ((n = bp__super_cut(T, par, s, S->snode[N->b], 0)) != 0) par->run(par->user, bp__super_run, T, n);
            }
            bp__super_dense(F, s, B, T->inv, par);
        }
    }
}

/* Whether a phase's INSIDE pass should go WIDE (above) although it has
   as many separators as threads or more: one task per separator takes as
   long as the biggest, so when one separator holds most of the phase's
   dense work (bimba's third phase: separators of 189 and 94 vertices, the
   first with 85% of the work) the other threads wait.  A separator of C
   columns whose first supernode has R rows costs about C^2 R / 2
   multiply-adds; WIDE (every thread on each separator in turn, with the
   cost of cutting) wins when the biggest share times the threads exceeds
   BP__WIDE_SHARE.  Which pass runs never changes a bit (above). */
#define BP__WIDE_SHARE 1.2

static int bp__super_unbalanced(const bp__factor *F, const uint32_t *nodes, uint32_t cnt, int threads)
{
    const bp__super *S = F->sn;
    double tot = 0, big = 0;
    uint32_t k;
    if (threads < 2) return 0;
    if (cnt < (uint32_t)threads) return 1;
    for (k = 0; k < cnt; k++) {
        const bp__ndnode *N = &F->tree[nodes[k]];
        double c, r, w;
        if (N->b >= N->hi) continue;
        c = (double)S->bs * (N->hi - N->b);
        r = (double)S->bs * (S->rp[S->snode[N->b] + 1] - S->rp[S->snode[N->b]]);
        w = c * c * r / 2;
        tot += w;
        if (w > big) big = w;
    }
    return tot > 0 && big * threads > BP__WIDE_SHARE * tot;
}

static int bp__super_numeric(const bp_allocator *a, const bp__sparse *A, bp__factor *F, const bp__par *par)
{
    bp__super *S = F->sn;
    bp__super_task T;
    int phase;
    uint32_t np = S->ntask > BP__SUPER_PIECES ? S->ntask : BP__SUPER_PIECES;
    memset(&T, 0, sizeof T);
    if (!S->x) S->x = (double *)bp__alloc_array(a, S->xp[S->ns] ? S->xp[S->ns] : 1, sizeof(double));
    T.map = (uint32_t *)bp__alloc_array(a, (size_t)S->ntask * S->nv, sizeof(uint32_t));
    T.pos = (uint32_t *)bp__alloc_array(a, (size_t)np * S->maxrows + 1, sizeof(uint32_t));
    T.inv = (double *)bp__alloc_array(a, (size_t)S->ntask * S->maxcols + 1, sizeof(double));
    if (!S->x || !T.map || !T.pos || !T.inv) { bp__free(a, T.map); bp__free(a, T.pos); bp__free(a, T.inv); return 0; }
    T.A = A;
    T.F = F;
    for (phase = 0; phase <= BP__ND_DEPTH; phase++) {
        uint32_t c = bp__nd_phase(F, phase, T.nodes);
        if (!c) continue;
        if (phase > 0) bp__super_outside(&T, par, c);
        if (phase > 0 && bp__super_unbalanced(F, T.nodes, c, par->threads)) { bp__super_wide(&T, par, c); continue; }
        T.mode = phase > 0 ? 2 : 0;
        par->run(par->user, bp__super_run, &T, c);
    }
    bp__free(a, T.map); bp__free(a, T.pos); bp__free(a, T.inv);
    return 1;
}

/* x = A^-1 b: forward L z = P b, backward L^T y = z, x = P^T y, supernode
   by supernode (z: n doubles of workspace), in the dissection tree's
   phases like the factorization (bp__super_numeric).
   The forward solve, serially, is a scatter: supernode K solves with its
   diagonal block,
       z_i = (z_i - sum_{j<i} L(i, j) z_j) / L(i, i),
   then subtracts its terms from the rows below it,
       z_v -= sum_j L(v, j) z_j     (j over K's columns, increasing),
   K increasing, so each z_v subtracts its terms in increasing K.  In
   parallel a task owns the range of a tree node and scatters only into
   rows inside it: phase 0's subtrees whole (all their rows' terms come
   from inside), and a separator [b, hi) of a later phase in two passes:
     OUTSIDE: the terms of the supernodes below b (finished in earlier
       phases, whose scatters stopped at their own ranges) gathered by the
       separator's supernodes s from the factorization's update lists
       uk[up[s] .. up[s+1]) (increasing K), as parallel pieces (a
       supernode of the separator and a range of its column vertices);
     INSIDE: one task per separator, its supernodes in order: the diagonal
       block, then the scatter into the separator's own rows.
   Every z_v still subtracts its terms in increasing K (those from below
   b first, then the separator's own) and every term is the same dot
   product, so the bits are the serial scatter's on any schedule.  The
   scatter inside the subtrees streams L in memory order; a gather for
   everything was measured 10% slower on face's whole run (small
   supernodes: many short pieces of many blocks).  One thread
   (par->threads 1) takes the plain scatter without the phases: the same
   bits, L streamed once in memory order.
   Buffered (the default where it fits): those OUTSIDE gathers of phase
   0's terms were most of the parallel solve's extra cost (face: a 27%
   longer sum of tasks than one thread's scatter, two threads only 1.24x
   faster), reading each subtree's blocks a second time, a few rows at a
   time.  So phase 0's tasks scatter their terms for the separators' rows
   into a buffer of their own (bs doubles per separator vertex, in x,
   which is free until the end), summed per row in increasing K; after
   the phase each separator row subtracts the subtrees' sums in tree-node
   order; the OUTSIDE gathers then take only the terms of the separators
   below.  Other sums than the plain scatter's, so one thread takes the
   same phases whenever the buffers fit (nleaf nsep <= nv: on every
   chart measured), and every thread count gets the same bits.  Face's
   solve: one thread 8.4 -> 8.8 ms, two 6.8 -> 5.0 ms.
   The backward solve, L^T y = z, reads only ancestors (the rows of s
   below its diagonal block):
       y_j -= sum_i L(i, j) y_i  (i over s's rows below, increasing),
   then the diagonal block backwards; so it runs top-down: the separators
   from the top phase down, each one task, its supernodes in decreasing
   order, then phase 0's subtrees whole.  A separator's rows are few (its
   own and its ancestors'), so its backward work is small; most of the
   work is in the subtrees, parallel in phase 0. */
typedef struct bp__ssolve_task {
    const bp__factor *F;
    double *z;
    uint32_t nodes[BP__ND_NODES];
    int mode;                     /* 0 forward whole, 1 OUTSIDE pieces, 2 INSIDE,
                                     3 backward separators, 4 backward whole */
    bp__super_piece piece[BP__SUPER_PIECES];
    double *buf;                  /* phase 0's terms for the separators' rows,
                                     bs nsep per subtree (NULL: gathered)  */
    uint32_t nsep, nr;            /* separator vertices; ranges            */
    uint32_t rb[BP__ND_NODES], rhi[BP__ND_NODES], roff[BP__ND_NODES]; /* by b */
    uint32_t slot[BP__ND_NODES];  /* phase 0's task t -> its buffer        */
    const double *b;              /* in the tasks (b != x): phase 0's and the  */
    double *x;                    /*   separators' own ranges permuted in and out */
    uint32_t nrhs;                /* right-hand sides: 1, or 2 (bs 1 only:
                                     two interleaved, x y per vertex)       */
} bp__ssolve_task;

/* Whether phase 0's ranges and the later phases' separators, disjoint by
   the tree's making, cover all the vertices (their sizes add up to nv). */
static int bp__ssolve_covers(const bp__factor *F)
{
    uint32_t nodes[BP__ND_NODES], c, k, sum = 0;
    int phase;
    for (phase = 0; phase <= BP__ND_DEPTH; phase++)
        for (c = bp__nd_phase(F, phase, nodes), k = 0; k < c; k++)
            sum += F->tree[nodes[k]].hi - (phase ? F->tree[nodes[k]].b : F->tree[nodes[k]].lo);
    return sum == F->sn->nv;
}

/* z = P b and x = P^T z over the new vertices [v0, v1), w values per
   vertex (bs, or 2 for two right-hand sides of a scalar factor). */
static void bp__ssolve_perm_in(const bp__super *S, uint32_t w, const double *b, double *z, uint32_t v0, uint32_t v1)
{
    uint32_t v, a;
    for (v = v0; v < v1; v++)
        for (a = 0; a < w; a++) z[w * (size_t)v + a] = b[w * (size_t)S->vperm[v] + a];
}

static void bp__ssolve_perm_out(const bp__super *S, uint32_t w, const double *z, double *x, uint32_t v0, uint32_t v1)
{
    uint32_t v, a;
    for (v = v0; v < v1; v++)
        for (a = 0; a < w; a++) x[w * (size_t)S->vperm[v] + a] = z[w * (size_t)v + a];
}

/* The separators' rows (the phases after 0), for the buffered forward
   solve below: the index of row vertex v among them, or BP__NONE. */
static uint32_t bp__ssolve_sep(const bp__ssolve_task *T, uint32_t v)
{
    uint32_t lo = 0, hi = T->nr;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (T->rhi[mid] <= v) lo = mid + 1; else hi = mid;
    }
    return lo < T->nr && T->rb[lo] <= v ? T->roff[lo] + v - T->rb[lo] : BP__NONE;
}

/* z of s's column vertices [v0, v1) minus the terms of the updates
   uk[q0 .. q1) of s (bs 2: both coordinates of a row vertex). */
static void bp__super_gather(const bp__super *S, uint32_t q0, uint32_t q1, uint32_t v0, uint32_t v1, double *z)
{
    uint32_t bs = S->bs, q, c, a, j;
    for (q = q0; q < q1; q++) {
        uint32_t K = S->uk[q], mK = S->rp[K + 1] - S->rp[K], cK = bs * (S->first[K + 1] - S->first[K]);
        const uint32_t *rk = S->ri + S->rp[K];
        const double *B = S->x + S->xp[K], *zK = z + bs * (size_t)S->first[K];
        c = rk[S->uo[q]] < v0 ? bp__lower_bound(rk, S->uo[q], mK, v0) : S->uo[q];
        for (; c < mK && rk[c] < v1; c++)
            for (a = 0; a < bs; a++) {
                const double *r = B + ((size_t)bs * c + a) * cK;
                double t = 0;
                for (j = 0; j < cK; j++) t += r[j] * zK[j];
                z[bs * (size_t)rk[c] + a] -= t;
            }
    }
}

/* bp__super_gather for two right-hand sides of a scalar factor (bs 1,
   z: x y per vertex; bp__super_fdiag2 below). */
static void bp__super_gather2(const bp__super *S, uint32_t q0, uint32_t q1, uint32_t v0, uint32_t v1, double *z)
{
    uint32_t q, c, j;
    for (q = q0; q < q1; q++) {
        uint32_t K = S->uk[q], mK = S->rp[K + 1] - S->rp[K], cK = S->first[K + 1] - S->first[K];
        const uint32_t *rk = S->ri + S->rp[K];
        const double *B = S->x + S->xp[K], *zK = z + 2 * (size_t)S->first[K];
        c = rk[S->uo[q]] < v0 ? bp__lower_bound(rk, S->uo[q], mK, v0) : S->uo[q];
        for (; c < mK && rk[c] < v1; c++) {
            const double *r = B + (size_t)c * cK;
            double t0 = 0, t1 = 0;
            for (j = 0; j < cK; j++) { t0 += r[j] * zK[2 * j]; t1 += r[j] * zK[2 * j + 1]; }
            z[2 * (size_t)rk[c]] -= t0;
            z[2 * (size_t)rk[c] + 1] -= t1;
        }
    }
}

/* Supernode s, forward, its diagonal block: z_s = L_ss^-1 z_s. */
static void bp__super_fdiag(const bp__super *S, uint32_t s, double *z)
{
    uint32_t c2 = S->bs * (S->first[s + 1] - S->first[s]), i, j;
    const double *B = S->x + S->xp[s];
    double *zs = z + S->bs * (size_t)S->first[s];
    for (i = 0; i < c2; i++) {
        const double *r = B + (size_t)i * c2;
        double t = zs[i];
        for (j = 0; j < i; j++) t -= r[j] * zs[j];
        zs[i] = t / r[i];
    }
}

/* Supernode s, forward: its diagonal block, then its terms scattered to
   the rows below it that are less than vhi (the end of its task's range;
   the rows from vhi on gather them later). */
static void bp__super_fscatter(const bp__super *S, uint32_t s, uint32_t vhi, double *z)
{
    uint32_t bs = S->bs, c2 = bs * (S->first[s + 1] - S->first[s]), m2 = bs * (S->rp[s + 1] - S->rp[s]), i, j;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *zs = z + bs * (size_t)S->first[s];
    bp__super_fdiag(S, s, z);
    for (i = c2; i + 4 <= m2 && rows[(i + 3) >> (bs - 1)] < vhi; i += 4) {   /* four chains in flight */
        const double *r0 = B + (size_t)i * c2, *r1 = r0 + c2, *r2 = r1 + c2, *r3 = r2 + c2;
        double t0 = 0, t1 = 0, t2 = 0, t3 = 0;
        for (j = 0; j < c2; j++) { double y = zs[j]; t0 += r0[j] * y; t1 += r1[j] * y; t2 += r2[j] * y; t3 += r3[j] * y; }
        z[bs * (size_t)rows[i >> (bs - 1)] + (i & (bs - 1))] -= t0;
        z[bs * (size_t)rows[(i + 1) >> (bs - 1)] + ((i + 1) & (bs - 1))] -= t1;
        z[bs * (size_t)rows[(i + 2) >> (bs - 1)] + ((i + 2) & (bs - 1))] -= t2;
        z[bs * (size_t)rows[(i + 3) >> (bs - 1)] + ((i + 3) & (bs - 1))] -= t3;
    }
    for (; i < m2 && rows[i >> (bs - 1)] < vhi; i++) {
        const double *r = B + (size_t)i * c2;
        double t = 0;
        for (j = 0; j < c2; j++) t += r[j] * zs[j];
        z[bs * (size_t)rows[i >> (bs - 1)] + (i & (bs - 1))] -= t;
    }
}

/* The buffered solve's OUTSIDE gather: the updates uk[q0 .. q1) of a
   separator's supernode that come from supernodes of the separators
   below (phase 0's terms are in the buffers).  uk is increasing and each
   separator range is a run of supernodes, so the runs from phase 0 are
   jumped over by binary search, not visited. */
static void bp__ssolve_gather_sep(const bp__ssolve_task *T, uint32_t q0, uint32_t q1, uint32_t v0, uint32_t v1)
{
    const bp__super *S = T->F->sn;
    uint32_t q = q0, r = 0;
    while (q < q1 && r < T->nr) {
        uint32_t K = S->uk[q], kb = S->snode[T->rb[r]], ke = S->snode[T->rhi[r] - 1];
        if (K > ke) { r++; continue; }
        if (K >= kb) {                                  /* a run inside range r */
            uint32_t e = q;
            while (e < q1 && S->uk[e] <= ke) e++;
            if (T->nrhs == 2) bp__super_gather2(S, q, e, v0, v1, T->z); else bp__super_gather(S, q, e, v0, v1, T->z);
            q = e;
            r++;
            continue;
        }
        {                                               /* phase 0's run: jump to kb */
            uint32_t lo = q, hi = q1;
            while (lo < hi) {
                uint32_t mid = lo + (hi - lo) / 2;
                if (S->uk[mid] < kb) lo = mid + 1; else hi = mid;
            }
            q = lo;
        }
    }
}

/* Supernode s of a phase-0 subtree ending at vhi, forward, buffered: as
   bp__super_fscatter, but its terms for the rows from vhi on (all in the
   separators above, by the dissection) are added up in buf, at the row's
   separator index (bp__ssolve_sep), to be subtracted after the phase. */
static void bp__super_fscatter_buf(const bp__ssolve_task *T, uint32_t s, uint32_t vhi, double *buf)
{
    const bp__super *S = T->F->sn;
    uint32_t bs = S->bs, c2 = bs * (S->first[s + 1] - S->first[s]), m2 = bs * (S->rp[s + 1] - S->rp[s]), i, j;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *z = T->z, *zs = z + bs * (size_t)S->first[s];
    bp__super_fdiag(S, s, z);
    for (i = c2; i < m2; i++) {
        const double *r = B + (size_t)i * c2;
        uint32_t u = rows[i >> (bs - 1)];
        double t = 0;
        for (j = 0; j < c2; j++) t += r[j] * zs[j];
        if (u < vhi) z[bs * (size_t)u + (i & (bs - 1))] -= t;
        else buf[bs * (size_t)bp__ssolve_sep(T, u) + (i & (bs - 1))] += t;
    }
}

/* Supernode s, backward: its rows below, then its diagonal block.  Each
   zs[j] subtracts the rows' terms in increasing row order; four columns
   at a time keep their sums in registers over the rows (not in memory,
   where each row's subtraction waited on the last one's store): the same
   terms in the same order, so the same bits. */
static void bp__super_back(const bp__super *S, uint32_t s, double *z)
{
    uint32_t bs = S->bs, c2 = bs * (S->first[s + 1] - S->first[s]), m2 = bs * (S->rp[s + 1] - S->rp[s]), i, j;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *zs = z + bs * (size_t)S->first[s];
    for (j = 0; j + 4 <= c2; j += 4) {
        double a0 = zs[j], a1 = zs[j + 1], a2 = zs[j + 2], a3 = zs[j + 3];
        for (i = c2; i < m2; i++) {
            const double *r = B + (size_t)i * c2 + j;
            double t = z[bs * (size_t)rows[i >> (bs - 1)] + (i & (bs - 1))];
            a0 -= r[0] * t; a1 -= r[1] * t; a2 -= r[2] * t; a3 -= r[3] * t;
        }
        zs[j] = a0; zs[j + 1] = a1; zs[j + 2] = a2; zs[j + 3] = a3;
    }
    for (; j < c2; j++) {
        double a0 = zs[j];
        for (i = c2; i < m2; i++) a0 -= B[(size_t)i * c2 + j] * z[bs * (size_t)rows[i >> (bs - 1)] + (i & (bs - 1))];
        zs[j] = a0;
    }
    for (i = c2; i-- > 0;) {
        const double *r = B + (size_t)i * c2;
        zs[i] /= r[i];
        for (j = 0; j < i; j++) zs[j] -= r[j] * zs[i];
    }
}

/* Two right-hand sides of a scalar factor (bs 1, bp__super_solve_n's
   nr 2): z holds x y per vertex, and each kernel below is the one above
   with its row of L read once for both sides, each side's sum the very
   terms of the one-side kernel in their order (the same bits as two
   solves).  Newton's isotropic K1 solves for x and y at once this way,
   and so does the conformal start's Schur complement (>>conformal);
   bp__super_gather2, above, is the gather's. */
static void bp__super_fdiag2(const bp__super *S, uint32_t s, double *z)
{
    uint32_t c = S->first[s + 1] - S->first[s], i, j;
    const double *B = S->x + S->xp[s];
    double *zs = z + 2 * (size_t)S->first[s];
    for (i = 0; i < c; i++) {
        const double *r = B + (size_t)i * c;
        double t0 = zs[2 * i], t1 = zs[2 * i + 1];
        for (j = 0; j < i; j++) { t0 -= r[j] * zs[2 * j]; t1 -= r[j] * zs[2 * j + 1]; }
        zs[2 * i] = t0 / r[i];
        zs[2 * i + 1] = t1 / r[i];
    }
}

/* Row i of supernode s's block against its columns' two sides. */
static void bp__super_dot2(const double *r, const double *zs, uint32_t c, double *t0, double *t1)
{
    uint32_t j;
    double a = 0, b = 0;
    for (j = 0; j < c; j++) { a += r[j] * zs[2 * j]; b += r[j] * zs[2 * j + 1]; }
    *t0 = a;
    *t1 = b;
}

static void bp__super_fscatter2(const bp__super *S, uint32_t s, uint32_t vhi, double *z)
{
    uint32_t c = S->first[s + 1] - S->first[s], m = S->rp[s + 1] - S->rp[s], i;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *zs = z + 2 * (size_t)S->first[s], t0, t1;
    bp__super_fdiag2(S, s, z);
    for (i = c; i + 2 <= m && rows[i + 1] < vhi; i += 2) {        /* two rows: four chains in flight */
        const double *r0 = B + (size_t)i * c, *r1 = r0 + c;
        double a0 = 0, b0 = 0, a1 = 0, b1 = 0;
        uint32_t j;
        for (j = 0; j < c; j++) {
            double x = zs[2 * j], y = zs[2 * j + 1];
            a0 += r0[j] * x; b0 += r0[j] * y; a1 += r1[j] * x; b1 += r1[j] * y;
        }
        z[2 * (size_t)rows[i]] -= a0; z[2 * (size_t)rows[i] + 1] -= b0;
        z[2 * (size_t)rows[i + 1]] -= a1; z[2 * (size_t)rows[i + 1] + 1] -= b1;
    }
    for (; i < m && rows[i] < vhi; i++) {
        bp__super_dot2(B + (size_t)i * c, zs, c, &t0, &t1);
        z[2 * (size_t)rows[i]] -= t0;
        z[2 * (size_t)rows[i] + 1] -= t1;
    }
}

static void bp__super_fscatter_buf2(const bp__ssolve_task *T, uint32_t s, uint32_t vhi, double *buf)
{
    const bp__super *S = T->F->sn;
    uint32_t c = S->first[s + 1] - S->first[s], m = S->rp[s + 1] - S->rp[s], i;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *z = T->z, *zs = z + 2 * (size_t)S->first[s], t0, t1;
    bp__super_fdiag2(S, s, z);
    for (i = c; i < m; i++) {
        uint32_t u = rows[i];
        bp__super_dot2(B + (size_t)i * c, zs, c, &t0, &t1);
        if (u < vhi) { z[2 * (size_t)u] -= t0; z[2 * (size_t)u + 1] -= t1; }
        else {
            size_t k = 2 * (size_t)bp__ssolve_sep(T, u);
            buf[k] += t0;
            buf[k + 1] += t1;
        }
    }
}

static void bp__super_back2(const bp__super *S, uint32_t s, double *z)
{
    uint32_t c = S->first[s + 1] - S->first[s], m = S->rp[s + 1] - S->rp[s], i, j;
    const uint32_t *rows = S->ri + S->rp[s];
    const double *B = S->x + S->xp[s];
    double *zs = z + 2 * (size_t)S->first[s];
    for (j = 0; j + 4 <= c; j += 4) {             /* as bp__super_back: sums in registers */
        double a0 = zs[2 * j], b0 = zs[2 * j + 1], a1 = zs[2 * j + 2], b1 = zs[2 * j + 3];
        double a2 = zs[2 * j + 4], b2 = zs[2 * j + 5], a3 = zs[2 * j + 6], b3 = zs[2 * j + 7];
        for (i = c; i < m; i++) {
            const double *r = B + (size_t)i * c + j, *zt = z + 2 * (size_t)rows[i];
            double t0 = zt[0], t1 = zt[1];
            a0 -= r[0] * t0; b0 -= r[0] * t1; a1 -= r[1] * t0; b1 -= r[1] * t1;
            a2 -= r[2] * t0; b2 -= r[2] * t1; a3 -= r[3] * t0; b3 -= r[3] * t1;
        }
        zs[2 * j] = a0; zs[2 * j + 1] = b0; zs[2 * j + 2] = a1; zs[2 * j + 3] = b1;
        zs[2 * j + 4] = a2; zs[2 * j + 5] = b2; zs[2 * j + 6] = a3; zs[2 * j + 7] = b3;
    }
    for (; j < c; j++) {
        double a0 = zs[2 * j], b0 = zs[2 * j + 1];
        for (i = c; i < m; i++) {
            const double *zt = z + 2 * (size_t)rows[i];
            double rr = B[(size_t)i * c + j];
            a0 -= rr * zt[0]; b0 -= rr * zt[1];
        }
        zs[2 * j] = a0; zs[2 * j + 1] = b0;
    }
    for (i = c; i-- > 0;) {
        const double *r = B + (size_t)i * c;
        zs[2 * i] /= r[i];
        zs[2 * i + 1] /= r[i];
        for (j = 0; j < i; j++) { zs[2 * j] -= r[j] * zs[2 * i]; zs[2 * j + 1] -= r[j] * zs[2 * i + 1]; }
    }
}

static void bp__ssolve_run(void *task, uint32_t t)
{
    bp__ssolve_task *T = (bp__ssolve_task *)task;
    const bp__super *S = T->F->sn;
    const bp__ndnode *N;
    uint32_t s, s0, s1, q;
    if (T->mode == 1) {
        const bp__super_piece *P = &T->piece[t];
        for (q = S->up[P->s]; q < S->up[P->s + 1] && S->uk[q] < P->k0; q++) {}
        if (T->buf) bp__ssolve_gather_sep(T, S->up[P->s], q, P->v0, P->v1);
        else if (T->nrhs == 2) bp__super_gather2(S, S->up[P->s], q, P->v0, P->v1, T->z);
        else bp__super_gather(S, S->up[P->s], q, P->v0, P->v1, T->z);
        return;
    }
    N = &T->F->tree[T->nodes[t]];
    if ((T->mode == 2 || T->mode == 3 ? N->b : N->lo) >= N->hi) return;
    s0 = S->snode[T->mode == 2 || T->mode == 3 ? N->b : N->lo];
    s1 = S->snode[N->hi - 1] + 1;
    if (T->mode >= 3) {
        for (s = s1; s-- > s0;) {
            if (T->nrhs == 2) bp__super_back2(S, s, T->z); else bp__super_back(S, s, T->z);
        }
        if (T->b)                                                 /* final here */
            bp__ssolve_perm_out(S, S->bs * T->nrhs, T->z, T->x, T->mode == 3 ? N->b : N->lo, N->hi);
        return;
    }
    if (T->mode == 0 && T->b) bp__ssolve_perm_in(S, S->bs * T->nrhs, T->b, T->z, N->lo, N->hi);
    if (T->mode == 0 && T->buf) {
        double *buf = T->buf + (size_t)T->slot[t] * S->bs * T->nrhs * T->nsep;
        for (s = s0; s < s1; s++) {
            if (T->nrhs == 2) bp__super_fscatter_buf2(T, s, N->hi, buf); else bp__super_fscatter_buf(T, s, N->hi, buf);
        }
        return;
    }
    for (s = s0; s < s1; s++) {
        if (T->nrhs == 2) bp__super_fscatter2(S, s, N->hi, T->z); else bp__super_fscatter(S, s, N->hi, T->z);
    }
}

/* The OUTSIDE pieces of one phase's separators: each supernode of nc
   vertices cut into min(nc / 8, 8) (at least one) equal column ranges. */
static void bp__ssolve_outside(bp__ssolve_task *T, const bp__par *par, uint32_t cnt)
{
    const bp__super *S = T->F->sn;
    uint32_t k, s, r, n = 0;
    T->mode = 1;
    for (k = 0; k < cnt; k++) {
        const bp__ndnode *N = &T->F->tree[T->nodes[k]];
        if (N->b >= N->hi) continue;
        for (s = S->snode[N->b]; s <= S->snode[N->hi - 1]; s++) {
            uint32_t f = S->first[s], nc = S->first[s + 1] - f, parts = nc / 8;
            if (parts < 1) parts = 1;
            if (parts > 8) parts = 8;
            for (r = 0; r < parts; r++) {
                bp__super_piece *P = &T->piece[n];
                P->s = s;
                P->k0 = S->snode[N->b];
                P->v0 = f + (uint32_t)((uint64_t)nc * r / parts);
                P->v1 = f + (uint32_t)((uint64_t)nc * (r + 1) / parts);
                if (P->v1 > P->v0 && ++n == BP__SUPER_PIECES) { par->run(par->user, bp__ssolve_run, T, n); n = 0; }
            }
        }
    }
    if (n) par->run(par->user, bp__ssolve_run, T, n);
}

/* Whether the forward solve can buffer phase 0's terms for the
   separators (bp__super_fscatter_buf) in x, free until the end: the
   separators' ranges [b, hi) of the split nodes above phase 0, sorted,
   and room for bs nrhs nsep doubles per subtree of phase 0 (x holds
   bs nrhs nv).  Sets T's ranges
   and buf (x, zeroed) or leaves buf NULL.  Depends on the factor only, so
   one thread and several take the same sums. */
static void bp__ssolve_buffers(bp__ssolve_task *T, const bp__factor *F, double *x)
{
    const bp__super *S = F->sn;
    uint32_t k, i, nleaf = bp__nd_phase(F, 0, T->nodes);
    T->buf = NULL;
    T->nsep = T->nr = 0;
    if (!F->tree[0].used || F->tree[0].lo != 0 || F->tree[0].hi != S->nv || nleaf < 2) return;
    for (k = 0; k < BP__ND_NODES; k++) {
        const bp__ndnode *N = &F->tree[k];
        if (!N->used || !N->split || bp__nd_depth(k) >= BP__ND_DEPTH || N->b >= N->hi) continue;
        for (i = T->nr++; i > 0 && T->rb[i - 1] > N->b; i--) { T->rb[i] = T->rb[i - 1]; T->rhi[i] = T->rhi[i - 1]; }
        T->rb[i] = N->b;
        T->rhi[i] = N->hi;
    }
    for (i = 0; i < T->nr; i++) { T->roff[i] = T->nsep; T->nsep += T->rhi[i] - T->rb[i]; }
    if ((uint64_t)nleaf * T->nsep > S->nv) return;
    for (i = 0; i < nleaf; i++)                  /* buffers in node order, whatever the task order */
        for (T->slot[i] = 0, k = 0; k < nleaf; k++) T->slot[i] += T->nodes[k] < T->nodes[i];
    T->buf = x;
    memset(x, 0, (size_t)nleaf * S->bs * T->nrhs * T->nsep * sizeof(double));
}

/* After phase 0 of the buffered forward solve: each separator row
   subtracts the subtrees' sums, in node order. */
static void bp__ssolve_reduce(const bp__ssolve_task *T, uint32_t nleaf)
{
    const bp__super *S = T->F->sn;
    uint32_t r, v, a, k, w = S->bs * T->nrhs;
    size_t m = (size_t)w * T->nsep;
    for (r = 0; r < T->nr; r++)
        for (v = T->rb[r]; v < T->rhi[r]; v++)
            for (a = 0; a < w; a++) {
                size_t i = w * (size_t)(T->roff[r] + v - T->rb[r]) + a;
                double *zv = T->z + w * (size_t)v + a;
                for (k = 0; k < nleaf; k++) *zv -= T->buf[k * m + i];
            }
}

/* nrhs right-hand sides (2: only with bs 1, interleaved x y per vertex;
   b, x and z then hold 2 nv). */
static void bp__super_solve_n(const bp__factor *F, const double *b, double *x, double *z, const bp__par *par,
                              uint32_t nrhs)
{
    const bp__super *S = F->sn;
    bp__ssolve_task T;
    uint32_t v, c, k, w = S->bs * nrhs;
    int phase;
    memset(&T, 0, sizeof T);
    T.F = F;
    T.z = z;
    T.nrhs = nrhs;
    if (par->threads != 1 && b != x && bp__ssolve_covers(F)) {   /* the tasks permute their own ranges */
        T.b = b;
        T.x = x;
        for (phase = 1; phase <= BP__ND_DEPTH; phase++)   /* the separators' ranges here */
            for (c = bp__nd_phase(F, phase, T.nodes), k = 0; k < c; k++)
                bp__ssolve_perm_in(S, w, b, z, F->tree[T.nodes[k]].b, F->tree[T.nodes[k]].hi);
    } else
        bp__ssolve_perm_in(S, w, b, z, 0, S->nv);
    bp__ssolve_buffers(&T, F, x);
    if (par->threads == 1 && !T.buf) {           /* one thread: the plain scatter, no phases */
        for (v = 0; v < S->ns; v++) {
            if (nrhs == 2) bp__super_fscatter2(S, v, S->nv, z); else bp__super_fscatter(S, v, S->nv, z);
        }
        phase = BP__ND_DEPTH + 1;
    } else
        phase = 0;
    for (; phase <= BP__ND_DEPTH; phase++) {
        if (!(c = bp__nd_phase(F, phase, T.nodes))) continue;
        if (phase > 0) bp__ssolve_outside(&T, par, c);
        T.mode = phase > 0 ? 2 : 0;
        par->run(par->user, bp__ssolve_run, &T, c);
        if (phase == 0 && T.buf) bp__ssolve_reduce(&T, c);
    }
    if (par->threads == 1) {                     /* backward: the plain loop, or by phases */
        for (v = S->ns; v-- > 0;) {
            if (nrhs == 2) bp__super_back2(S, v, z); else bp__super_back(S, v, z);
        }
    }
    for (phase = par->threads == 1 ? -1 : BP__ND_DEPTH; phase >= 0; phase--) {
        if (!(c = bp__nd_phase(F, phase, T.nodes))) continue;
        T.mode = phase > 0 ? 3 : 4;
        par->run(par->user, bp__ssolve_run, &T, c);
    }
    if (!T.b) bp__ssolve_perm_out(S, w, z, x, 0, S->nv);
}

static void bp__super_solve(const bp__factor *F, const double *b, double *x, double *z, const bp__par *par)
{
    bp__super_solve_n(F, b, x, z, par, 1);
}

/* bp__factorize for a symmetric matrix in whole 2x2 blocks (bs 2,
   A->blocks2) or a scalar one (bs 1, A->super1: the vertex graph is A's
   own): the analysis and the numeric factorization above.  Returns as
   bp__factorize, and BP_ERR_NUMERICAL also for a pivot that is not
   positive (this is Cholesky: A must be positive definite); *fallback = 1
   when A is not in whole blocks after all (nothing done).  order, tree:
   a kept vertex order, or NULL (bp__super_analyse).  like (or NULL): a
   factor analysed on A's very vertex graph in that very order, with
   another block size: its analysis is copied (bp__super_clone) instead. */
static int bp__super_clone(const bp_allocator *a, const bp__factor *like, const bp__ndnode *tree, bp__factor *F);
static bp_status bp__super_factorize_like(const bp_allocator *a, const bp__sparse *A, bp__factor *F, uint32_t *bad_row,
                                          const bp__par *par, uint32_t bs, int *fallback, const uint32_t *order,
                                          const bp__ndnode *tree, const bp__factor *like)
{
    bp__sparse G;
    bp__par serial = bp__par_serial();
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    uint32_t k;
    int g = 1;
    if (like) G = *A;                          /* not read */
    else if (bs == 2) g = bp__super_graph(a, A, &G);
    else if (A->symmetric) G = *A;
    else g = 0;
    *fallback = g == 0;
    if (g <= 0) return BP_ERR_OUT_OF_MEMORY;
    memset(F, 0, sizeof *F);
    F->n = A->n;
    F->symmetric = 1;
    F->sn = (bp__super *)bp__calloc_array(a, 1, sizeof(bp__super));
    F->D = (double *)bp__alloc_array(a, A->n ? A->n : 1, sizeof(double));
    if (F->sn && F->D) F->sn->bs = bs;
    if (F->sn && F->D && like) st = bp__super_clone(a, like, tree, F) ? BP_OK : BP_ERR_OUT_OF_MEMORY;
    else if (F->sn && F->D) st = bp__super_analyse(a, &G, F, par, order, tree);
    if (st == BP_OK) {
        st = BP_ERR_OUT_OF_MEMORY;
        /* the scatter map for the refactorizations (bp__super_start; its
           rows 2 r + 1 < BP__NONE, else the binary searches stay): Newton's
           H, and the scalar K1 of its isotropic phase (super1 == 2) */
        int want = (bs == 2 || A->super1 == 2) && F->sn->maxrows < 0x7fffffffu;
        if (want) F->sn->amap = (uint32_t *)bp__alloc_array(a, (size_t)A->colp[A->n] + 1, sizeof(uint32_t));
        if ((!want || F->sn->amap) && bp__super_numeric(a, A, F, par ? par : &serial)) {
            st = BP_OK;
            F->sn->amap_ok = F->sn->amap != NULL;
            for (k = 0; k < A->n && st == BP_OK; k++)
                if (!(F->D[k] > 0) || !(F->D[k] < HUGE_VAL)) {
                    *bad_row = bs * F->sn->vperm[k / bs] + k % bs;
                    st = BP_ERR_NUMERICAL;
                }
        }
    }
    if (bs == 2 && !like) { bp__free(a, G.colp); bp__free(a, G.row); }
    if (st != BP_OK) bp__factor_free(a, F);
    return st;
}

static bp_status bp__super_factorize(const bp_allocator *a, const bp__sparse *A, bp__factor *F, uint32_t *bad_row,
                                     const bp__par *par, uint32_t bs, int *fallback, const uint32_t *order,
                                     const bp__ndnode *tree)
{
    return bp__super_factorize_like(a, A, F, bad_row, par, bs, fallback, order, tree, NULL);
}

/* The analysis of `like` for F->sn->bs (F->n = bs nv, F->sn and F->D
   allocated): bp__super_analyse's result depends on the vertex graph, the
   order and the tree alone, but for the block sizes in xp and maxcols, so
   the same graph in the same order needs no second analysis (Newton's
   isotropic K1 after the conformal start: face, 8 ms of one thread).
   The tree is the caller's, as bp__super_analyse copies it.  Returns 0
   out of memory. */
static int bp__super_clone(const bp_allocator *a, const bp__factor *like, const bp__ndnode *tree, bp__factor *F)
{
    const bp__super *L = like->sn;
    bp__super *S = F->sn;
    uint32_t nv = L->nv, ns = L->ns, bs = S->bs, s, nup = L->up[ns];
    S->nv = nv;
    S->ns = ns;
    S->ntask = L->ntask;
    S->maxrows = L->maxrows;
    memcpy(F->tree, tree, sizeof F->tree);
    S->vperm = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    S->viperm = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    S->snode = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    S->first = (uint32_t *)bp__alloc_array(a, (size_t)ns + 1, sizeof(uint32_t));
    S->rp = (uint32_t *)bp__alloc_array(a, (size_t)ns + 1, sizeof(uint32_t));
    S->xp = (size_t *)bp__alloc_array(a, (size_t)ns + 1, sizeof(size_t));
    S->ri = (uint32_t *)bp__alloc_array(a, L->rp[ns] ? L->rp[ns] : 1, sizeof(uint32_t));
    S->up = (uint32_t *)bp__alloc_array(a, (size_t)ns + 1, sizeof(uint32_t));
    S->uk = (uint32_t *)bp__alloc_array(a, nup ? nup : 1, sizeof(uint32_t));
    S->uo = (uint32_t *)bp__alloc_array(a, nup ? nup : 1, sizeof(uint32_t));
    if (!S->vperm || !S->viperm || !S->snode || !S->first || !S->rp || !S->xp || !S->ri || !S->up || !S->uk || !S->uo)
        return 0;
    memcpy(S->vperm, L->vperm, nv * sizeof(uint32_t));
    memcpy(S->viperm, L->viperm, nv * sizeof(uint32_t));
    memcpy(S->snode, L->snode, nv * sizeof(uint32_t));
    memcpy(S->first, L->first, ((size_t)ns + 1) * sizeof(uint32_t));
    memcpy(S->rp, L->rp, ((size_t)ns + 1) * sizeof(uint32_t));
    memcpy(S->ri, L->ri, L->rp[ns] * sizeof(uint32_t));
    memcpy(S->up, L->up, ((size_t)ns + 1) * sizeof(uint32_t));
    memcpy(S->uk, L->uk, nup * sizeof(uint32_t));
    memcpy(S->uo, L->uo, nup * sizeof(uint32_t));
    S->xp[0] = 0;
    S->maxcols = 0;
    for (s = 0; s < ns; s++) {                 /* as bp__super_analyse sizes them */
        uint32_t nc = S->first[s + 1] - S->first[s];
        S->xp[s + 1] = S->xp[s] + (size_t)bs * bs * (S->rp[s + 1] - S->rp[s]) * nc;
        if (bs * nc > S->maxcols) S->maxcols = bs * nc;
    }
    return 1;
}

/* The values of L, U and D, one row k at a time, in parallel phases along
   the dissection tree (see bp__fact_rows).  Arrays already allocated are
   reused: a new matrix on the same pattern is refactored in place
   (>>newton).  Returns 0 out of memory. */
static int bp__fact_numeric(const bp_allocator *a, const bp__sparse *A, bp__factor *F, const uint32_t *tpos,
                            const bp__par *par)
{
    uint32_t n = A->n, nnzL;
    bp__fact_task T;
    int phase, ok = 0;
    if (F->sn) return bp__super_numeric(a, A, F, par);
    nnzL = F->Rp[n];
    memset(&T, 0, sizeof T);
    if (!F->Rx) F->Rx = (double *)bp__alloc_array(a, nnzL, sizeof(double));
    if (!A->symmetric && !F->Ux) F->Ux = (double *)bp__alloc_array(a, nnzL, sizeof(double));
    T.x = (double *)bp__calloc_array(a, n, sizeof(double));
    T.y = (double *)bp__calloc_array(a, n, sizeof(double));
    T.xs = (double *)bp__calloc_array(a, BP__FACT_PARTS * (size_t)n, sizeof(double));
    if (!A->symmetric) T.ys = (double *)bp__calloc_array(a, BP__FACT_PARTS * (size_t)n, sizeof(double));
    if (F->Rx && (A->symmetric || (F->Ux && T.ys)) && T.x && T.y && T.xs) {
        T.A = A;
        T.F = F;
        T.tpos = tpos;
        for (phase = 0; phase <= BP__ND_DEPTH; phase++) {
            uint32_t cntn = bp__nd_phase(F, phase, T.nodes);
            if (phase == 0) {
                T.mode = BP__FACT_WHOLE;
                par->run(par->user, bp__fact_rows, &T, cntn);
                continue;
            }
            T.mode = BP__FACT_OUTSIDE;
            par->run(par->user, bp__fact_rows, &T, cntn * BP__FACT_PARTS);
            T.mode = BP__FACT_INSIDE;
            par->run(par->user, bp__fact_rows, &T, cntn);
        }
        ok = 1;
    }
    bp__free(a, T.x); bp__free(a, T.y); bp__free(a, T.xs); bp__free(a, T.ys);
    return ok;
}

/* Factor A (symmetric pattern) in four phases: the ordering (nested
   dissection), the elimination tree, the pattern of L, the values.
   Returns BP_OK; BP_ERR_OUT_OF_MEMORY; BP_ERR_TOO_LARGE when L would have
   more than BP__FACTOR_MAX_NNZ entries (*bad_row: the row where the count
   passed it); BP_ERR_NUMERICAL with *bad_row set (the original row) when a
   pivot is zero or not finite.  The ordering's subtrees and the numeric
   rows run in parallel when par is given; the order and every row are
   computed by the same operations either way. */
static bp_status bp__factorize_order(const bp_allocator *a, const bp__sparse *A, bp__factor *F, uint32_t *bad_row,
                                     const bp__par *par, const uint32_t *order, const bp__ndnode *tree)
{
    uint32_t n = A->n, k;
    uint32_t *parent = NULL, *mark = NULL, *tpos = NULL;
    bp__par serial = bp__par_serial();
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    if (A->blocks2 || A->super1) {
        int fallback;
        st = bp__super_factorize(a, A, F, bad_row, par, A->blocks2 ? 2 : 1, &fallback, order, tree);
        if (!fallback && (st != BP_ERR_NUMERICAL || A->blocks2)) return st;
        st = BP_ERR_OUT_OF_MEMORY;
    }
    memset(F, 0, sizeof *F);
    F->n = n;
    F->symmetric = A->symmetric;
    F->perm = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    F->iperm = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    F->Rp = (uint32_t *)bp__alloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    F->D = (double *)bp__alloc_array(a, n, sizeof(double));
    parent = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    mark = (uint32_t *)bp__alloc_array(a, n, sizeof(uint32_t));
    if (!F->perm || !F->iperm || !F->Rp || !F->D || !parent || !mark) goto done;
    if (!A->symmetric && !bp__fact_transpose(a, A, &tpos)) goto done;
    if (!bp__nd_order(a, A, F->perm, F->tree, BP__SCALAR_ORDER, par)) goto done;
    for (k = 0; k < n; k++) F->iperm[F->perm[k]] = k;
    bp__fact_etree(A, F, parent, mark);
    bp__free(a, mark);
    mark = NULL;
    if ((st = bp__fact_symbolic(a, A, F, parent, bad_row)) != BP_OK) goto done;
    st = BP_ERR_OUT_OF_MEMORY;
    if (!bp__fact_numeric(a, A, F, tpos, par ? par : &serial)) goto done;
    for (k = 0; k < n; k++)
        if (!(F->D[k] != 0) || !(F->D[k] - F->D[k] == 0)) {
            *bad_row = F->perm[k];
            st = BP_ERR_NUMERICAL;
            goto done;
        }
    st = BP_OK;
done:
    bp__free(a, parent); bp__free(a, mark); bp__free(a, tpos);
    if (st != BP_OK) bp__factor_free(a, F);
    return st;
}

/* The same with the ordering computed here (order NULL).  A given order
   (order: new -> old, with its dissection tree) serves the supernodal
   factors only; the scalar rows, and their fallback, order for themselves. */
static bp_status bp__factorize(const bp_allocator *a, const bp__sparse *A, bp__factor *F, uint32_t *bad_row,
                               const bp__par *par)
{
    return bp__factorize_order(a, A, F, bad_row, par, NULL, NULL);
}

/* The message for BP_ERR_TOO_LARGE from bp__factorize: the chart, the
   system's size and the limit (chart BP__NONE: not known here). */
static bp_status bp__factor_too_large(bp_error *err, uint32_t chart, uint32_t nt, const char *what, uint32_t n)
{
    if (chart == BP__NONE)
        return bp__fail(err, BP_ERR_TOO_LARGE, BP_ELEMENT_NONE, -1, -1, 0,
                        "a chart of %u triangles: its %s (%u unknowns) needs a sparse factor of more than %u "
                        "entries, the limit of 32-bit indices; cut the chart into smaller ones",
                        nt, what, n, BP__FACTOR_MAX_NNZ);
    return bp__fail(err, BP_ERR_TOO_LARGE, BP_ELEMENT_CHART, chart, -1, 0,
                    "chart %u (%u triangles): its %s (%u unknowns) needs a sparse factor of more than %u "
                    "entries, the limit of 32-bit indices; cut the chart into smaller ones",
                    chart, nt, what, n, BP__FACTOR_MAX_NNZ);
}

/* x = A^-1 b through the factors; z is workspace of size n.  Forward
   L z = b by rows (gathers); backward U x = z by rows of U^T (scatters:
   x_i is final once every later row has been subtracted).  A supernodal
   factor is solved in the dissection's phases on par's threads (NULL:
   serial; the same bits either way); the rows, serially. */
static void bp__factor_solve_par(const bp__factor *F, const double *b, double *x, double *z, const bp__par *par)
{
    uint32_t n = F->n, i, q;
    if (F->sn) {
        bp__par serial = bp__par_serial();
        bp__super_solve(F, b, x, z, par ? par : &serial);
        return;
    }
    for (i = 0; i < n; i++) z[i] = b[F->perm[i]];
    for (i = 0; i < n; i++) {                        /* L z = b (unit)   */
        double s = z[i];
        for (q = F->Rp[i]; q < F->Rp[i + 1]; q++) s -= F->Rx[q] * z[F->Ri[q]];
        z[i] = s;
    }
    if (F->symmetric) {                              /* D L^T x = z      */
        for (i = 0; i < n; i++) z[i] /= F->D[i];
        for (i = n; i-- > 0;)
            for (q = F->Rp[i]; q < F->Rp[i + 1]; q++) z[F->Ri[q]] -= F->Rx[q] * z[i];
    } else {                                         /* U x = z          */
        for (i = n; i-- > 0;) {
            z[i] /= F->D[i];
            for (q = F->Rp[i]; q < F->Rp[i + 1]; q++) z[F->Ri[q]] -= F->Ux[q] * z[i];
        }
    }
    for (i = 0; i < n; i++) x[F->perm[i]] = z[i];
}

/* The same, serial. */
static void bp__factor_solve(const bp__factor *F, const double *b, double *x, double *z)
{
    bp__factor_solve_par(F, b, x, z, NULL);
}

/* Solve with one step of iterative refinement: x += A^-1 (b - A x).
   work: 3n doubles. */
static void bp__solve_refined(const bp__sparse *A, const bp__factor *F, const double *b,
                              double *x, double *work)
{
    double *r = work, *d = work + A->n, *z = work + 2 * (size_t)A->n;
    uint32_t j, p;
    bp__factor_solve(F, b, x, z);
    for (j = 0; j < A->n; j++) r[j] = b[j];
    for (j = 0; j < A->n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) r[A->row[p]] -= A->val[p] * x[j];
    bp__factor_solve(F, r, d, z);
    for (j = 0; j < A->n; j++) x[j] += d[j];
}

/* For the preconditioner: L in single precision.  A preconditioner only
   shapes the search direction, so float coefficients (with double
   arithmetic) serve as well, and they halve the memory the solves stream
   through.  The factorization itself needs double (the regularized
   Laplacian's last pivot is 1e-8 of its diagonal), so the conversion
   happens afterwards, in place: float p goes to bytes [4p, 4p + 4) of the
   double array, which only overlap doubles already read.  The bytes are
   moved with memcpy, which is exact about aliasing.
   A supernodal factor of a scalar matrix (bs 1, A->super1) is turned into
   the same rows instead (bp__super_to_rows, on par's threads; par NULL:
   serially).  Returns 0 out of memory. */
static int bp__super_to_rows(const bp_allocator *a, bp__factor *F, const bp__par *par);
static int bp__factor_single(const bp_allocator *a, bp__factor *F, const bp__par *par)
{
    size_t p, nnz;
    unsigned char *buf = (unsigned char *)F->Rx;
    if (F->sn) return bp__super_to_rows(a, F, par);
    nnz = F->Rp[F->n];
    for (p = 0; p < nnz; p++) {
        double d;
        float f;
        memcpy(&d, buf + sizeof d * p, sizeof d);
        f = (float)d;
        memcpy(buf + sizeof f * p, &f, sizeof f);
    }
    F->Rxf = (float *)(void *)buf;
    F->Rx = NULL;
    return 1;
}

/* The preconditioner's solves (bp__precondition) read a unit lower L by
   rows in single precision, and D.  From the supernodal Cholesky factor
   C C^T of a scalar matrix (bs 1) that is
       L(i, j) = C(i, j) / C(j, j),    D(j) = C(j, j)^2 (F->D already),
   written supernode by supernode, column by column: j increases, so every
   row comes out sorted.  The ordering and the dissection tree stay (vertex
   = unknown), and the supernodal blocks are freed.

   On several threads (issue 15: 20 ms serial per factor on a 132K-face
   chart, twice per run).  The supernodes are cut into BP__ROWS_RANGES
   consecutive ranges holding about the same number of block entries (the
   cut depends on the factor alone).  Serially, an entry of row i goes to
   the slot cur[i]++, cur[i] starting at Rp[i]; so the first entry of row
   i in range r goes to Rp[i] plus the number of row i's entries in the
   ranges before r.  Each range counts its entries per row (in parallel),
   a pass per row turns the counts into those starting slots, and each
   range then writes its supernodes with its own cursors (in parallel):
   every entry lands in the serial slot with the serial value.  The counts
   cost BP__ROWS_RANGES words per vertex while the conversion runs. */
#define BP__ROWS_RANGES 8u
static uint32_t bp__nchunks(uint32_t n, uint32_t size);
static uint32_t bp__chunk_at(uint32_t n, uint32_t nc, uint32_t c);

typedef struct bp__rows_task {
    bp__factor *F;
    const bp__super *S;
    uint32_t cut[BP__ROWS_RANGES + 1];  /* range r: supernodes [cut[r], cut[r+1]) */
    uint32_t *cnt;                      /* [r * n + i]: count, then cursor  */
    uint32_t nchunk;                    /* row chunks of the pass per row   */
    int write;
} bp__rows_task;

static void bp__rows_range(void *task, uint32_t r)
{
    bp__rows_task *J = (bp__rows_task *)task;
    const bp__super *S = J->S;
    bp__factor *F = J->F;
    uint32_t s, jj, ii, *cur = J->cnt + (size_t)r * S->nv;
    for (s = J->cut[r]; s < J->cut[r + 1]; s++) {
        uint32_t f = S->first[s], nc = S->first[s + 1] - f, m = S->rp[s + 1] - S->rp[s];
        const uint32_t *rows = S->ri + S->rp[s];
        const double *B = S->x + S->xp[s];
        if (!J->write) {
            for (ii = 1; ii < m; ii++) cur[rows[ii]] += ii < nc ? ii : nc;
            continue;
        }
        for (jj = 0; jj < nc; jj++)
            for (ii = jj + 1; ii < m; ii++) {
                uint32_t q = cur[rows[ii]]++;
                F->Ri[q] = f + jj;
                F->Rxf[q] = (float)(B[(size_t)ii * nc + jj] / B[(size_t)jj * nc + jj]);
            }
    }
}

/* Row chunk c: the ranges' counts of each row into its starting slots. */
static void bp__rows_slots(void *task, uint32_t c)
{
    bp__rows_task *J = (bp__rows_task *)task;
    uint32_t n = J->S->nv, i, r, i1 = bp__chunk_at(n, J->nchunk, c + 1);
    for (i = bp__chunk_at(n, J->nchunk, c); i < i1; i++) {
        uint32_t at = J->F->Rp[i];
        for (r = 0; r < BP__ROWS_RANGES; r++) {
            uint32_t k = J->cnt[(size_t)r * n + i];
            J->cnt[(size_t)r * n + i] = at;
            at += k;
        }
    }
}

static int bp__super_to_rows(const bp_allocator *a, bp__factor *F, const bp__par *par)
{
    bp__super *S = F->sn;
    bp__par serial = bp__par_serial();
    bp__rows_task J;
    uint32_t n = S->nv, s, r, jj;
    size_t nnz = 0;
    if (S->bs != 1) return 0;
    if (!par) par = &serial;
    memset(&J, 0, sizeof J);
    J.F = F;
    J.S = S;
    F->perm = (uint32_t *)bp__alloc_array(a, n ? n : 1, sizeof(uint32_t));
    F->iperm = (uint32_t *)bp__alloc_array(a, n ? n : 1, sizeof(uint32_t));
    F->Rp = (uint32_t *)bp__calloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    J.cnt = (uint32_t *)bp__calloc_array(a, (size_t)BP__ROWS_RANGES * n + 1, sizeof(uint32_t));
    if (!F->perm || !F->iperm || !F->Rp || !J.cnt) { bp__free(a, J.cnt); return 0; }
    for (r = 0, s = 0; r <= BP__ROWS_RANGES; r++) {       /* equal shares of the blocks */
        while (s < S->ns && S->xp[s] < S->xp[S->ns] / BP__ROWS_RANGES * r) s++;
        J.cut[r] = r == BP__ROWS_RANGES ? S->ns : s;
    }
    bp__par_run(par, bp__rows_range, &J, BP__ROWS_RANGES, n);
    for (jj = 0; jj < n; jj++) {
        for (r = 0; r < BP__ROWS_RANGES; r++) nnz += J.cnt[(size_t)r * n + jj];
        F->Rp[jj + 1] = (uint32_t)(nnz <= BP__FACTOR_MAX_NNZ ? nnz : 0);
    }
    F->Ri = (uint32_t *)bp__alloc_array(a, nnz ? nnz : 1, sizeof(uint32_t));
    F->Rxf = (float *)bp__alloc_array(a, nnz ? nnz : 1, sizeof(float));
    if (nnz > BP__FACTOR_MAX_NNZ || !F->Ri || !F->Rxf) { bp__free(a, J.cnt); return 0; }
    J.nchunk = bp__nchunks(n, 2048u);
    bp__par_run(par, bp__rows_slots, &J, J.nchunk, n);
    J.write = 1;
    bp__par_run(par, bp__rows_range, &J, BP__ROWS_RANGES, n);
    memcpy(F->perm, S->vperm, n * sizeof(uint32_t));
    memcpy(F->iperm, S->viperm, n * sizeof(uint32_t));
    bp__free(a, J.cnt);
    bp__super_free(a, S);
    F->sn = NULL;
    return 1;
}

/* The preconditioner solve r = K^-1 q for both coordinates at once (q, r
   interleaved xy), in phases along the dissection tree.  z (x then y, n
   doubles each, permuted order) and acc (the same: running sums) are
   shared by the tasks, with the coordinates apart so that the two tasks of
   a per-coordinate pass never write the same cache line; each
   task owns a range of rows, and moves its rows between the old and the
   permuted order itself (q[perm[i]] into z[i] before row i's first pass,
   r[perm[i]] out when row i is final), so no serial loop surrounds the
   solve.  (r may be q: every read of q ends before the backward solve.)

   Forward, L z = q, by rows: z_i -= sum_j L(i,j) z_j, a gather, bottom-up
   (leaves first, the top separator last).  A separator's rows depend on
   each other only through the small block of L inside the separator; most
   of each row's entries lie in the subtrees below, which are solved.  So a
   separator takes two passes: a parallel one over its rows that sums the
   entries outside the separator, and a sequential one that carries each
   running sum on through the separator block.

   Backward, D L^T x = z, by rows again but as a scatter, top-down: once
   x_i = z_i / D_i - acc_i is final, row i adds L(i,j) x_i to acc_j of
   every j in it.  Again a separator takes two passes: a sequential one
   through its own block, which finishes its x, and a parallel one that
   scatters its rows into the columns below, cut into column ranges.

   Where each pass starts and stops inside a separator's row is looked up
   in the solve plan (bp__solve_plan below), not searched for: a binary
   search per row and pass cost a third of the whole solve on camelhead.

   Every sum is taken in an order fixed by the factor alone (a row's
   entries in column order forward; the rows in decreasing order backward),
   so the bits do not depend on the schedule or on the plan's column
   ranges.  The sequential passes are the only serial work of the top
   separator, and the two coordinates are independent in them, so they run
   as two tasks, one per coordinate. */

/* The solve plan.  A separator [b, hi) of node N has its backward scatter
   cut into N->ncut column ranges [c_r, c_r+1) with c_0 = lo and
   c_ncut = b, chosen so that each range holds about the same number of
   entries (the ranges are the tasks of that pass, and equal tasks balance
   on any number of threads).  For each row i of the separator the plan
   stores the ncut + 1 positions where its entries reach c_0 .. c_ncut, at
   cutp[poff + (i - b)(ncut + 1) + r]; the last one is also where the
   forward pass 1 stops and the sequential passes start.  It depends on
   the pattern only, and costs (ncut + 1) words per separator row. */
#define BP__PLAN_ENTRIES 8192u            /* about this many per range ... */
#define BP__PLAN_RANGES  8u               /* ... and at most this many      */

static const uint32_t *bp__row_cuts(const bp__factor *F, const bp__ndnode *N, uint32_t i)
{
    return F->cutp + N->poff + (size_t)(i - N->b) * (N->ncut + 1);
}

static int bp__solve_plan(const bp_allocator *a, bp__factor *F)
{
    uint32_t k, i, r, c, *cnt;
    size_t off = 0;
    for (k = 0; k < BP__ND_NODES; k++) {
        bp__ndnode *N = &F->tree[k];
        size_t e = 0;
        N->ncut = N->poff = 0;
        if (!N->used || !N->split || bp__nd_depth(k) >= BP__ND_DEPTH) continue;
        for (i = N->b; i < N->hi; i++) e += bp__lower_bound(F->Ri, F->Rp[i], F->Rp[i + 1], N->b) - F->Rp[i];
        N->ncut = (uint32_t)(e / BP__PLAN_ENTRIES < BP__PLAN_RANGES ? e / BP__PLAN_ENTRIES : BP__PLAN_RANGES);
        if (N->ncut == 0) N->ncut = 1;
        N->poff = (uint32_t)off;
        off += (size_t)(N->hi - N->b) * (N->ncut + 1);
    }
    F->cutp = (uint32_t *)bp__alloc_array(a, off ? off : 1, sizeof(uint32_t));
    cnt = (uint32_t *)bp__alloc_array(a, F->n ? F->n : 1, sizeof(uint32_t));
    if (!F->cutp || !cnt) { bp__free(a, cnt); return 0; }
    for (k = 0; k < BP__ND_NODES; k++) {
        bp__ndnode *N = &F->tree[k];
        uint32_t cut[BP__PLAN_RANGES + 1];
        size_t e = 0, run = 0;
        if (!N->ncut) continue;
        /* entries per column below b, then cuts at equal shares */
        memset(cnt + N->lo, 0, (N->b - N->lo) * sizeof(uint32_t));
        for (i = N->b; i < N->hi; i++) {
            uint32_t p, p1 = bp__lower_bound(F->Ri, F->Rp[i], F->Rp[i + 1], N->b);
            for (p = F->Rp[i]; p < p1; p++) cnt[F->Ri[p]]++;
            e += p1 - F->Rp[i];
        }
        cut[0] = N->lo;
        for (r = 1, c = N->lo; r < N->ncut; r++) {
            while (c < N->b && run < e * r / N->ncut) run += cnt[c++];
            cut[r] = c;
        }
        cut[N->ncut] = N->b;
        for (i = N->b; i < N->hi; i++) {
            uint32_t *pos = F->cutp + N->poff + (size_t)(i - N->b) * (N->ncut + 1), q = F->Rp[i];
            for (r = 0; r <= N->ncut; r++) pos[r] = q = bp__lower_bound(F->Ri, q, F->Rp[i + 1], cut[r]);
        }
    }
    bp__free(a, cnt);
    return 1;
}

#define BP__SOLVE_TASKS 160
typedef struct bp__solve_task {
    const bp__factor *F;
    const double *q;                    /* right-hand side, old order       */
    double *r;                          /* result, old order                */
    double *z, *acc;                    /* 2n each: x block, then y block   */
    uint32_t lo[BP__SOLVE_TASKS];       /* rows [lo, hi) of each task       */
    uint32_t hi[BP__SOLVE_TASKS];
    uint8_t node[BP__SOLVE_TASKS];      /* its separator's tree node        */
    uint8_t part[BP__SOLVE_TASKS];      /* BELOW: its column range          */
    int mode;                           /* see bp__solve_range              */
    int per_coord;                      /* task k: range k/2, coordinate k%2 */
} bp__solve_task;

enum {
    BP__FWD_WHOLE,      /* forward, rows [lo, hi) complete                   */
    BP__FWD_OUTSIDE,    /* forward pass 1: the entries in columns < b        */
    BP__FWD_FINISH,     /* forward pass 2: the rest, after pass 1            */
    BP__BWD_WHOLE,      /* backward, rows [lo, hi) complete                  */
    BP__BWD_BLOCK,      /* backward pass 1: x of [lo, hi), scattered >= b     */
    BP__BWD_BELOW       /* backward pass 2: rows [b, hi) into column range part */
};

static void bp__solve_range(void *task, uint32_t k)
{
    bp__solve_task *T = (bp__solve_task *)task;
    const bp__factor *F = T->F;
    const float *Lx = F->Rxf;
    const uint32_t *Ri = F->Ri;
    size_t n = F->n;
    uint32_t t = T->per_coord ? k >> 1 : k, lo = T->lo[t], hi = T->hi[t], i, p;
    uint32_t c = T->per_coord ? (k & 1) : 0;          /* the (first) coordinate */
    const bp__ndnode *N = &F->tree[T->node[t]];       /* (WHOLE modes: unused) */
    int both = !T->per_coord, mode = T->mode;
    double *zx = T->z + c * n, *zy = T->z + n, *ax = T->acc + c * n, *ay = T->acc + n;
    if (mode <= BP__FWD_FINISH) {
        if (mode != BP__FWD_FINISH)                       /* the rows' first pass: fetch q */
            for (i = lo; i < hi; i++) {
                zx[i] = T->q[2 * (size_t)F->perm[i] + c];
                if (both) zy[i] = T->q[2 * (size_t)F->perm[i] + 1];
            }
        for (i = lo; i < hi; i++) {
            double sx = 0, sy = 0;
            uint32_t p0 = F->Rp[i], p1 = F->Rp[i + 1];
            if (mode == BP__FWD_FINISH) {                 /* continue pass 1's sums */
                sx = ax[i];
                if (both) sy = ay[i];
                p0 = bp__row_cuts(F, N, i)[N->ncut];
            } else if (mode == BP__FWD_OUTSIDE) {
                p1 = bp__row_cuts(F, N, i)[N->ncut];
            }
            if (both)
                for (p = p0; p < p1; p++) {
                    sx += (double)Lx[p] * zx[Ri[p]];
                    sy += (double)Lx[p] * zy[Ri[p]];
                }
            else
                for (p = p0; p < p1; p++) sx += (double)Lx[p] * zx[Ri[p]];
            if (mode == BP__FWD_OUTSIDE) {
                ax[i] = sx;
                if (both) ay[i] = sy;
            } else {                                      /* final; acc starts the backward sums */
                zx[i] -= sx;
                ax[i] = 0;
                if (both) { zy[i] -= sy; ay[i] = 0; }
            }
        }
    } else if (mode != BP__BWD_BELOW) {
        for (i = hi; i-- > lo;) {
            double xx = zx[i] / F->D[i] - ax[i], xy = 0;
            uint32_t p0 = F->Rp[i], p1 = F->Rp[i + 1];
            zx[i] = xx;
            T->r[2 * (size_t)F->perm[i] + c] = xx;
            if (both) {
                xy = zy[i] / F->D[i] - ay[i];
                zy[i] = xy;
                T->r[2 * (size_t)F->perm[i] + 1] = xy;
            }
            if (mode == BP__BWD_BLOCK) p0 = bp__row_cuts(F, N, i)[N->ncut];
            if (both)
                for (p = p0; p < p1; p++) {
                    ax[Ri[p]] += (double)Lx[p] * xx;
                    ay[Ri[p]] += (double)Lx[p] * xy;
                }
            else
                for (p = p0; p < p1; p++) ax[Ri[p]] += (double)Lx[p] * xx;
        }
    } else {
        /* the separator's rows, already final, into column range part */
        uint32_t part = T->part[t];
        for (i = N->hi; i-- > N->b;) {
            double xx = zx[i], xy = zy[i];
            const uint32_t *cut = bp__row_cuts(F, N, i);
            for (p = cut[part]; p < cut[part + 1]; p++) {
                ax[Ri[p]] += (double)Lx[p] * xx;
                ay[Ri[p]] += (double)Lx[p] * xy;
            }
        }
    }
}

/* One parallel loop of the solve over n tasks described in T. */
static void bp__solve_run(bp__solve_task *T, const bp__par *par, int mode, int per_coord, uint32_t n)
{
    T->mode = mode;
    T->per_coord = per_coord;
    par->run(par->user, bp__solve_range, T, per_coord ? 2 * n : n);
}

static void bp__precondition(const bp__factor *F, const bp__par *par, const double *q, double *r, double *z)
{
    bp__solve_task T;
    uint32_t nodes[BP__ND_NODES], cnt, k, n, lo, step;
    int phase;
    T.F = F;
    T.q = q;
    T.r = r;
    T.z = z;
    T.acc = z + 2 * (size_t)F->n;               /* z has 4n doubles */
    memset(T.node, 0, sizeof T.node);
    /* forward, bottom-up */
    for (phase = 0; phase <= BP__ND_DEPTH; phase++) {
        if ((cnt = bp__nd_phase(F, phase, nodes)) == 0) continue;
        if (phase == 0) {
            for (k = 0; k < cnt; k++) { T.lo[k] = F->tree[nodes[k]].lo; T.hi[k] = F->tree[nodes[k]].hi; }
            bp__solve_run(&T, par, BP__FWD_WHOLE, 0, cnt);
            continue;
        }
        /* pass 1: the separators' rows in chunks of 16 rows or more, at
           most about 120 chunks in all */
        for (n = 0, k = 0; k < cnt; k++) n += F->tree[nodes[k]].hi - F->tree[nodes[k]].b;
        step = n / 120 + 1 > 16 ? n / 120 + 1 : 16;
        n = 0;
        for (k = 0; k < cnt; k++)
            for (lo = F->tree[nodes[k]].b; lo < F->tree[nodes[k]].hi && n < BP__SOLVE_TASKS; lo += step, n++) {
                T.lo[n] = lo;
                T.hi[n] = lo + step < F->tree[nodes[k]].hi ? lo + step : F->tree[nodes[k]].hi;
                T.node[n] = (uint8_t)nodes[k];
            }
        if (n < BP__SOLVE_TASKS) bp__solve_run(&T, par, BP__FWD_OUTSIDE, 0, n);
        for (k = 0; k < cnt; k++) { T.lo[k] = F->tree[nodes[k]].b; T.hi[k] = F->tree[nodes[k]].hi; T.node[k] = (uint8_t)nodes[k]; }
        /* pass 2, or the only pass when the chunks were too many */
        bp__solve_run(&T, par, n < BP__SOLVE_TASKS ? BP__FWD_FINISH : BP__FWD_WHOLE, 1, cnt);
    }
    /* backward, top-down */
    for (phase = BP__ND_DEPTH; phase >= 0; phase--) {
        if ((cnt = bp__nd_phase(F, phase, nodes)) == 0) continue;
        if (phase == 0) {
            for (k = 0; k < cnt; k++) { T.lo[k] = F->tree[nodes[k]].lo; T.hi[k] = F->tree[nodes[k]].hi; }
            bp__solve_run(&T, par, BP__BWD_WHOLE, 0, cnt);
            continue;
        }
        for (k = 0; k < cnt; k++) { T.lo[k] = F->tree[nodes[k]].b; T.hi[k] = F->tree[nodes[k]].hi; T.node[k] = (uint8_t)nodes[k]; }
        bp__solve_run(&T, par, BP__BWD_BLOCK, 1, cnt);
        /* pass 2: the plan's column ranges of every separator of the phase */
        for (n = 0, k = 0; k < cnt; k++)
            for (lo = 0; lo < F->tree[nodes[k]].ncut; lo++, n++) { T.node[n] = (uint8_t)nodes[k]; T.part[n] = (uint8_t)lo; }
        bp__solve_run(&T, par, BP__BWD_BELOW, 0, n);
    }
}

/* >>check ==================================================================

   The exact validity check is the ground truth of every test.  Its
   precondition: the triangles form an oriented manifold -- each undirected
   edge is used once (a boundary edge) or twice in opposite directions (an
   interior edge).  bp_check verifies that first, from the same sorted list
   of directed edges that gives it the boundary: an edge used twice in one
   direction (a triangle listed twice, or two neighbours of opposite
   orientation) or by more than two triangles is reported, never passed.

   A planar map of such a triangulation is bijective when
     (a) every triangle has positive signed area (exact orient2d),
     (b) no two boundary edges share a point, except two edges that share a
         vertex index, which may meet at that vertex only,
     (c) each connected piece has exactly one counter-clockwise boundary
         loop (all its other loops run clockwise), and
     (d) no piece lies inside another one.
   Why: with positive triangles, the number of triangles covering a generic
   point p is the sum, over the boundary loops, of their winding numbers
   around p (the boundary of the 2-chain of triangles is the 1-cycle of
   boundary edges, and the degree of a chain at p is the winding number of
   its boundary).  By (b) the loops are simple, pairwise disjoint polygons,
   so each winds 0 or +1 around p (counter-clockwise) or 0 or -1
   (clockwise).  With (c), a piece covers p at most once (one +1, the rest
   <= 0) and at least zero times, and by (d) two pieces do not cover the
   same p.  A point covered at most once everywhere also rules out branch
   points (around one, nearby points are covered twice), so the map is a
   local homeomorphism and injective.

   What (c) catches, by Hopf's Umlaufsatz: a simple closed polygon has
   turning number +1 or -1, and for a map with positive triangles of a disk
   with h holes (Euler characteristic chi = 1 - h) the Gauss-Bonnet sum of
   the exterior angles gives
       sum over loops of turning numbers = chi + B,
   where B >= 0 is the total branching: an interior vertex whose angles sum
   to 2 pi (1 + b) adds b, a boundary vertex whose angles exceed 2 pi adds
   the extra turns (the Poincare-Hopf count of an immersion with branch
   points).  With k counter-clockwise and h + 1 - k clockwise loops,
   2k - h - 1 = 1 - h + B, i.e. k = 1 + B/2: exactly one counter-clockwise
   loop if and only if the map has no branch point.  A simple polygon's
   orientation is decided exactly by orient2d at its lexicographically
   smallest vertex (convex there, and not collinear once (a) and (b) hold),
   so (c) costs O(boundary length).  This is also why the line search
   (>>lbfgs) needs only (a), (b) and (c) for one chart.

   Exactness needs every nonzero coordinate in [2^-485, 2^510) in magnitude
   (the range of >>predicates).  A map outside it is scaled by a power of
   two, which changes no orientation and loses no bit while the scaled
   coordinates stay normal; a map whose coordinates span more than 2^994
   (say 1e-300 next to 1e+300) cannot be decided and is refused.

   Boundary edges are found from the triangles (directed edges without a
   reverse twin) so the check does not trust the chart's loop lists.  The
   pairs of edges that could meet are found with a uniform grid whose cells
   are about one edge long; a pair is decided once, in the cell that holds
   the lower-left corner of the overlap of the two edges' boxes. */

typedef struct bp__dedge { uint32_t a, b; } bp__dedge;

/* The exact range of bp_orient2d (>>predicates): 0, or a magnitude in
   [2^-485, 2^510).  The two literals are those powers of two exactly. */
#define BP__EXACT_MIN 1.0010415475915505e-146
#define BP__EXACT_MAX 3.3519519824856493e+153
static int bp__exact_range(double v)
{
    double m = fabs(v);
    return m == 0 || (m >= BP__EXACT_MIN && m < BP__EXACT_MAX);
}

/* Do boundary edges e and f (distinct) violate (b)? */
static int bp__edges_conflict(const double *uv, const bp__dedge *e, const bp__dedge *f)
{
    const double *a = uv + 2 * (size_t)e->a, *b = uv + 2 * (size_t)e->b;
    const double *c = uv + 2 * (size_t)f->a, *d = uv + 2 * (size_t)f->b;
    uint32_t s = BP__NONE;
    const double *p, *q, *sv;
    if (e->a == f->a || e->a == f->b) s = e->a;
    else if (e->b == f->a || e->b == f->b) s = e->b;
    if (s == BP__NONE) return bp_segments_intersect(a, b, c, d);
    if ((e->a == f->a || e->a == f->b) && (e->b == f->a || e->b == f->b)) return 1; /* same edge twice */
    /* sharing vertex s: they may only meet at s, so the two far ends p, q
       must not lie on a common ray from s */
    sv = uv + 2 * (size_t)s;
    p = (e->a == s) ? b : a;
    q = (f->a == s) ? d : c;
    if (bp_orient2d(sv, p, q) != 0) return 0;
    return bp__in_box(sv, p, q) || bp__in_box(sv, q, p);
}

/* Reusable storage of the exact boundary check (grown, never shrunk). */
typedef struct bp__grid_ws {
    uint32_t *cellp, *cells;
    size_t    ncellp, ncells;
} bp__grid_ws;

/* Grow a uint32 array of the workspace to n entries (contents lost). */
static int bp__ws_grow(const bp_allocator *a, uint32_t **p, size_t *cap, size_t n)
{
    if (n <= *cap) return 1;
    bp__free(a, *p);
    *p = (uint32_t *)bp__alloc_array(a, n + n / 2, sizeof(uint32_t));
    *cap = *p ? n + n / 2 : 0;
    return *p != NULL;
}

/* Condition (b) for the boundary edges de[0..nb): counts conflicting pairs
   into rep->boundary_intersections and keeps the first pair in first[0..1]
   (when given).  Uses a grid as described above.  The cell size h is the
   mean edge length, grown so that there are at most ~50 nb cells even when
   the edges are short and far apart (the extent of coordinates in the
   exact range cannot overflow). */
static bp_status bp__boundary_conflicts(const bp_allocator *a, const double *uv, const bp__dedge *de,
                                        uint32_t nb, bp_check_report *rep, bp__grid_ws *ws, bp__dedge *first)
{
    bp__grid_ws tmp = { NULL, NULL, 0, 0 }, *w = ws ? ws : &tmp;
    uint32_t *cellp = NULL, *cells = NULL, i, k;
    bp_status st = BP_OK;
    double lo[2] = { DBL_MAX, DBL_MAX }, hi[2] = { -DBL_MAX, -DBL_MAX }, h, len = 0, ex, ey;
    size_t ncell, gx, gy;
    if (nb < 2) return BP_OK;
    for (i = 0; i < nb; i++) {
        const double *p = uv + 2 * (size_t)de[i].a, *q = uv + 2 * (size_t)de[i].b;
        for (k = 0; k < 2; k++) {
            if (p[k] < lo[k]) lo[k] = p[k];
            if (p[k] > hi[k]) hi[k] = p[k];
        }
        len += sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]));
    }
    ex = hi[0] - lo[0];
    ey = hi[1] - lo[1];
    if (!(ex < HUGE_VAL && ey < HUGE_VAL && len < HUGE_VAL)) return BP_ERR_INVALID_ARGUMENT;
    /* cells about one mean edge long, at most ~16 per edge, and never more
       than 16 nb along one axis */
    h = len / nb;
    if (ex * ey > 16.0 * nb * h * h) h = sqrt(ex * ey / (16.0 * nb));
    if (ex > 16.0 * nb * h) h = ex / (16.0 * nb);
    if (ey > 16.0 * nb * h) h = ey / (16.0 * nb);
    if (!(h > 0)) h = 1;
    gx = (size_t)(ex / h) + 1;
    gy = (size_t)(ey / h) + 1;
    ncell = gx * gy;
    {
        /* counting sort of (edge, cell) incidences; a long edge is entered
           in every cell of its box */
        size_t total = 0, c;
        if (ncell + 1 > 0xfffffff0u || !bp__ws_grow(a, &w->cellp, &w->ncellp, ncell + 1)) {
            st = BP_ERR_OUT_OF_MEMORY;
            goto done;
        }
        cellp = w->cellp;
        memset(cellp, 0, (ncell + 1) * sizeof(uint32_t));
#define BP__CELLX(x) ((size_t)(((x) - lo[0]) / h) < gx ? (size_t)(((x) - lo[0]) / h) : gx - 1)
#define BP__CELLY(y) ((size_t)(((y) - lo[1]) / h) < gy ? (size_t)(((y) - lo[1]) / h) : gy - 1)
        for (i = 0; i < nb; i++) {
            const double *p = uv + 2 * (size_t)de[i].a, *q = uv + 2 * (size_t)de[i].b;
            size_t x0 = BP__CELLX(p[0] < q[0] ? p[0] : q[0]), x1 = BP__CELLX(p[0] < q[0] ? q[0] : p[0]);
            size_t y0 = BP__CELLY(p[1] < q[1] ? p[1] : q[1]), y1 = BP__CELLY(p[1] < q[1] ? q[1] : p[1]);
            size_t xx, yy;
            for (yy = y0; yy <= y1; yy++)
                for (xx = x0; xx <= x1; xx++) { cellp[yy * gx + xx + 1]++; total++; }
        }
        if (total > 0xfffffff0u) { st = BP_ERR_OUT_OF_MEMORY; goto done; }
        for (c = 0; c < ncell; c++) cellp[c + 1] += cellp[c];
        if (!bp__ws_grow(a, &w->cells, &w->ncells, total)) { st = BP_ERR_OUT_OF_MEMORY; goto done; }
        cells = w->cells;
        for (i = 0; i < nb; i++) {
            const double *p = uv + 2 * (size_t)de[i].a, *q = uv + 2 * (size_t)de[i].b;
            size_t x0 = BP__CELLX(p[0] < q[0] ? p[0] : q[0]), x1 = BP__CELLX(p[0] < q[0] ? q[0] : p[0]);
            size_t y0 = BP__CELLY(p[1] < q[1] ? p[1] : q[1]), y1 = BP__CELLY(p[1] < q[1] ? q[1] : p[1]);
            size_t xx, yy;
            for (yy = y0; yy <= y1; yy++)
                for (xx = x0; xx <= x1; xx++) cells[cellp[yy * gx + xx]++] = i;
        }
        for (c = ncell; c > 0; c--) cellp[c] = cellp[c - 1];
        cellp[0] = 0;
        for (c = 0; c < ncell; c++) {
            uint32_t u, w;
            for (u = cellp[c]; u < cellp[c + 1]; u++)
                for (w = u + 1; w < cellp[c + 1]; w++) {
                    const bp__dedge *e1 = &de[cells[u]], *e2 = &de[cells[w]];
                    const double *p1 = uv + 2 * (size_t)e1->a, *q1 = uv + 2 * (size_t)e1->b;
                    const double *p2 = uv + 2 * (size_t)e2->a, *q2 = uv + 2 * (size_t)e2->b;
                    double mx = p1[0] < q1[0] ? p1[0] : q1[0], my = p1[1] < q1[1] ? p1[1] : q1[1];
                    double m2x = p2[0] < q2[0] ? p2[0] : q2[0], m2y = p2[1] < q2[1] ? p2[1] : q2[1];
                    double Mx = p1[0] > q1[0] ? p1[0] : q1[0], My = p1[1] > q1[1] ? p1[1] : q1[1];
                    double M2x = p2[0] > q2[0] ? p2[0] : q2[0], M2y = p2[1] > q2[1] ? p2[1] : q2[1];
                    if (mx > M2x || m2x > Mx || my > M2y || m2y > My) continue;   /* boxes apart */
                    if (mx < m2x) mx = m2x;
                    if (my < m2y) my = m2y;
                    if (BP__CELLY(my) * gx + BP__CELLX(mx) != c) continue;        /* decided elsewhere */
                    if (bp__edges_conflict(uv, e1, e2)) {
                        if (rep->boundary_intersections == 0) {
                            rep->first_bad_edge[0] = e1->a;
                            rep->first_bad_edge[1] = e2->a;
                            if (first) { first[0] = *e1; first[1] = *e2; }
                        }
                        rep->boundary_intersections++;
                    }
                }
        }
#undef BP__CELLX
#undef BP__CELLY
    }
done:
    if (!ws) { bp__free(a, tmp.cellp); bp__free(a, tmp.cells); }
    return st;
}

/* Condition (b) for at most BP__CONFLICT_SCAN edges: every pair of edges
   whose closed boxes overlap is decided by bp__edges_conflict, exactly the
   pairs the grid above decides (each once), so the count is the same; what
   goes is the grid itself -- its extent, cell size, counting sort and
   cleared cells cost about 700 instructions per edge and call, more than
   the nb^2/2 box tests of a small chart.  The line search calls this for
   every trial map of such a chart (>>barrier).  Returns the number of
   conflicting pairs, or 1 when a coordinate is not finite (not decided). */
#define BP__CONFLICT_SCAN 64u

static uint32_t bp__conflicts_scan(const double *uv, const bp__dedge *de, uint32_t nb)
{
    double box[4 * BP__CONFLICT_SCAN];
    uint32_t i, j, n = 0;
    for (i = 0; i < nb; i++) {
        const double *p = uv + 2 * (size_t)de[i].a, *q = uv + 2 * (size_t)de[i].b;
        if (!(p[0] - p[0] == 0 && p[1] - p[1] == 0 && q[0] - q[0] == 0 && q[1] - q[1] == 0)) return 1;
        box[4 * i] = p[0] < q[0] ? p[0] : q[0];
        box[4 * i + 1] = p[1] < q[1] ? p[1] : q[1];
        box[4 * i + 2] = p[0] < q[0] ? q[0] : p[0];
        box[4 * i + 3] = p[1] < q[1] ? q[1] : p[1];
    }
    for (i = 0; i < nb; i++) {
        const double *b = box + 4 * i;
        for (j = i + 1; j < nb; j++) {
            const double *c = box + 4 * j;
            if (b[0] > c[2] || c[0] > b[2] || b[1] > c[3] || c[1] > b[3]) continue;   /* boxes apart */
            n += (uint32_t)bp__edges_conflict(uv, &de[i], &de[j]);
        }
    }
    return n;
}

/* Winding number of the closed loop e[0..n) (directed edges) around p,
   exact (Sunday's crossing rule with orient2d); p must not lie on it. */
static int bp__winding(const double *uv, const bp__dedge *e, uint32_t n, const double *p)
{
    int w = 0;
    uint32_t i;
    for (i = 0; i < n; i++) {
        const double *a = uv + 2 * (size_t)e[i].a, *b = uv + 2 * (size_t)e[i].b;
        if (a[1] <= p[1]) {
            if (b[1] > p[1] && bp_orient2d(a, b, p) > 0) w++;
        } else if (b[1] <= p[1] && bp_orient2d(a, b, p) < 0) {
            w--;
        }
    }
    return w;
}

/* Orientation of the closed loop e[0..n) (consecutive directed edges,
   e[j].b == e[j+1].a): the exact turn at its lexicographically smallest
   vertex, +1 counter-clockwise, -1 clockwise.  For a simple polygon this
   is its orientation: the smallest vertex is a convex corner, and its two
   neighbours are not on one ray from it (they would make two boundary
   edges overlap, which (b) excludes).  The box of the loop goes to box[4]
   (min x, min y, max x, max y) when given. */
static int bp__loop_sign(const double *uv, const bp__dedge *e, uint32_t n, double *box)
{
    uint32_t j, best = 0;
    for (j = 1; j < n; j++) {
        const double *p = uv + 2 * (size_t)e[j].a, *q = uv + 2 * (size_t)e[best].a;
        if (p[0] < q[0] || (p[0] == q[0] && p[1] < q[1])) best = j;
    }
    if (box) {
        box[0] = box[1] = DBL_MAX;
        box[2] = box[3] = -DBL_MAX;
        for (j = 0; j < n; j++) {
            const double *p = uv + 2 * (size_t)e[j].a;
            if (p[0] < box[0]) box[0] = p[0];
            if (p[1] < box[1]) box[1] = p[1];
            if (p[0] > box[2]) box[2] = p[0];
            if (p[1] > box[3]) box[3] = p[1];
        }
    }
    return bp_orient2d(uv + 2 * (size_t)e[best == 0 ? n - 1 : best - 1].a, uv + 2 * (size_t)e[best].a,
                       uv + 2 * (size_t)e[best].b);
}

/* The number of counter-clockwise loops among the nl loops stored in e
   (loop L is e[start[L] .. start[L+1])). */
static uint32_t bp__ccw_loops(const double *uv, const bp__dedge *e, const uint32_t *start, uint32_t nl)
{
    uint32_t L, k = 0;
    for (L = 0; L < nl; L++)
        if (start[L + 1] > start[L] && bp__loop_sign(uv, e + start[L], start[L + 1] - start[L], NULL) > 0) k++;
    return k;
}

/* What bp_check found first, for its message. */
enum {
    BP__BAD_NONE = 0, BP__BAD_NONMANIFOLD, BP__BAD_MISORIENTED, BP__BAD_PINCH, BP__BAD_OPEN,
    BP__BAD_CCW, BP__BAD_NESTED
};
typedef struct bp__check_first {
    int      kind;          /* BP__BAD_*: the first failure of (c), (d) or the precondition */
    uint32_t v0, v1, count; /* its vertices (an edge, or a piece's vertex), a count */
    bp__dedge pair[2];      /* first pair of boundary edges that meet (b) */
} bp__check_first;

/* The loops of condition (c) and (d), traced from the boundary edges
   de[0..nb) into le (consecutive edges), loop L being le[lstart[L] ..
   lstart[L+1]).  Each boundary vertex must start exactly one boundary edge
   (else the boundary is pinched there) and every chain must close. */
typedef struct bp__loops {
    bp__dedge *le;
    uint32_t  *lstart, nl;
    uint32_t  *piece;        /* union-find over vertices: connected pieces */
    int       *sign;         /* per loop */
    double    *box;          /* 4 per loop */
} bp__loops;

static int bp__loops_trace(const bp__dedge *de, uint32_t nb, uint32_t *out, uint32_t *loop_of, bp__loops *Lp,
                           bp_check_report *rep, bp__check_first *first)
{
    uint32_t i, pos = 0;
    for (i = 0; i < nb; i++) loop_of[i] = BP__NONE;
    for (i = 0; i < nb; i++) {
        if (out[de[i].a] != BP__NONE) {                   /* pinched vertex */
            if (!rep->loop_orientation) { first->kind = BP__BAD_PINCH; first->v0 = de[i].a; }
            rep->loop_orientation++;
        }
        out[de[i].a] = i;
    }
    if (rep->loop_orientation) return 0;
    Lp->nl = 0;
    for (i = 0; i < nb; i++) {
        uint32_t e = i;
        if (loop_of[i] != BP__NONE) continue;
        Lp->lstart[Lp->nl] = pos;
        while (loop_of[e] == BP__NONE) {
            loop_of[e] = Lp->nl;
            Lp->le[pos++] = de[e];
            e = out[de[e].b];
            if (e == BP__NONE) {                          /* open chain */
                rep->loop_orientation++;
                first->kind = BP__BAD_OPEN;
                first->v0 = Lp->le[pos - 1].b;
                return 0;
            }
        }
        Lp->nl++;
    }
    Lp->lstart[Lp->nl] = pos;
    return 1;
}

/* (c): exactly one counter-clockwise loop per connected piece.  ccw is
   scratch of nv counters. */
static void bp__loops_per_piece(const double *uv, bp__loops *Lp, uint32_t nv, uint32_t *ccw,
                                bp_check_report *rep, bp__check_first *first)
{
    uint32_t i;
    for (i = 0; i < nv; i++) ccw[i] = 0;
    for (i = 0; i < Lp->nl; i++) {
        Lp->sign[i] = bp__loop_sign(uv, Lp->le + Lp->lstart[i], Lp->lstart[i + 1] - Lp->lstart[i], Lp->box + 4 * (size_t)i);
        if (Lp->sign[i] > 0) ccw[bp__uf_find(Lp->piece, Lp->le[Lp->lstart[i]].a)]++;
    }
    for (i = 0; i < Lp->nl; i++) {
        uint32_t root = bp__uf_find(Lp->piece, Lp->le[Lp->lstart[i]].a);
        if (ccw[root] == BP__NONE) continue;            /* piece already counted */
        if (ccw[root] != 1) {
            if (!rep->loop_orientation) {
                first->kind = BP__BAD_CCW;
                first->v0 = Lp->le[Lp->lstart[i]].a;
                first->count = ccw[root];
            }
            rep->loop_orientation++;
        }
        ccw[root] = BP__NONE;
    }
}

/* (d): a vertex of each piece's outer (counter-clockwise) loop must not be
   covered by another piece, i.e. the sum of that piece's loop windings
   around it must be 0.  (Boundaries do not meet, so a piece overlapping
   another has a whole outer loop inside it.) */
static void bp__loops_nested(const double *uv, const bp__loops *Lp, bp_check_report *rep, bp__check_first *first)
{
    uint32_t i, j, l;
    for (i = 0; i < Lp->nl; i++) {
        uint32_t rb;
        const double *p;
        if (Lp->sign[i] <= 0) continue;
        rb = bp__uf_find(Lp->piece, Lp->le[Lp->lstart[i]].a);
        p = uv + 2 * (size_t)Lp->le[Lp->lstart[i]].a;
        for (j = 0; j < Lp->nl; j++) {
            const double *bx = Lp->box + 4 * (size_t)j;
            uint32_t ra;
            int w = 0;
            if (Lp->sign[j] <= 0 || j == i) continue;
            ra = bp__uf_find(Lp->piece, Lp->le[Lp->lstart[j]].a);
            if (ra == rb || p[0] < bx[0] || p[0] > bx[2] || p[1] < bx[1] || p[1] > bx[3]) continue;
            for (l = 0; l < Lp->nl; l++)
                if (bp__uf_find(Lp->piece, Lp->le[Lp->lstart[l]].a) == ra)
                    w += bp__winding(uv, Lp->le + Lp->lstart[l], Lp->lstart[l + 1] - Lp->lstart[l], p);
            if (w > 0) {
                if (!rep->nested) {
                    first->kind = BP__BAD_NESTED;
                    first->v0 = Lp->le[Lp->lstart[i]].a;
                    first->v1 = Lp->le[Lp->lstart[j]].a;
                }
                rep->nested++;
            }
        }
    }
}

/* Conditions (c) and (d), once (a) and (b) hold.  Two nested pieces, or a
   hole loop running counter-clockwise around a doubly covered region, pass
   (a) and (b) and fail these.  piece: the union-find of the connected
   pieces over the nv vertices (bp__check_pieces), read and compressed. */
static bp_status bp__loop_topology(const bp_allocator *a, const double *uv, uint32_t nv, uint32_t *piece,
                                   const bp__dedge *de, uint32_t nb, bp_check_report *rep, bp__check_first *first)
{
    uint32_t *out, *loop_of, i;
    bp__loops Lp;
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    memset(&Lp, 0, sizeof Lp);
    out = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    loop_of = (uint32_t *)bp__alloc_array(a, nb, sizeof(uint32_t));
    Lp.piece = piece;
    Lp.le = (bp__dedge *)bp__alloc_array(a, nb, sizeof(bp__dedge));
    Lp.lstart = (uint32_t *)bp__alloc_array(a, (size_t)nb + 1, sizeof(uint32_t));
    Lp.sign = (int *)bp__alloc_array(a, nb, sizeof(int));
    Lp.box = (double *)bp__alloc_array(a, 4 * (size_t)nb, sizeof(double));
    if (!out || !loop_of || !Lp.le || !Lp.lstart || !Lp.sign || !Lp.box) goto done;
    st = BP_OK;
    for (i = 0; i < nv; i++) out[i] = BP__NONE;
    if (!bp__loops_trace(de, nb, out, loop_of, &Lp, rep, first)) goto done;
    bp__loops_per_piece(uv, &Lp, nv, out, rep, first);     /* out[] reused as counters */
    if (!rep->loop_orientation) bp__loops_nested(uv, &Lp, rep, first);
done:
    bp__free(a, out); bp__free(a, loop_of); bp__free(a, Lp.le); bp__free(a, Lp.lstart);
    bp__free(a, Lp.sign); bp__free(a, Lp.box);
    return st;
}

/* --- bp_check in tasks -----------------------------------------------------

   bp_check runs about four times on a chart in the tool (the start map's
   verification, the optimizer's first check, the packer's check before and
   after it moves the chart), 2 ms each on a 50K-triangle chart and 6 ms on
   an 89K one: serial time on a two-thread run.  Its work over the
   triangles is therefore cut into tasks like every heavy loop (>>threads),
   on the caller's runner when the library has one (bp__check_par), and the
   result -- counts, first bad element, message -- is the serial one for
   any number of threads and any task order:

   1. Triangle chunks (2048 triangles, BP__TRI_CHUNK's size; the chunks
      depend on the count alone).  Each checks its triangles' indices,
      then in one pass their finiteness, the largest and smallest
      magnitude and the exact orientation (a), and counts its directed
      edges per key range (2. below).  A chunk keeps
      its counts and its first bad triangle of each kind; the caller adds
      the counts and takes the element of the first chunk that has one,
      which is the serial loop's first.  The magnitudes combine by max and
      min, exact in any order.  A map outside the exact range is scaled,
      and (a) runs again on the scaled copy by the same chunks; a map in
      it has every chunk's magnitudes in it, so (a) stands as decided.
   2. The directed edges in the order (smaller end v, larger end w,
      start), so that the uses of an undirected edge are adjacent, in
      two levels.  The chunks scatter their edges into key
      ranges (2^s consecutive values of v, at most BP__CHECK_RANGES ranges,
      s from the vertex count alone); each range puts its edges into
      buckets by v (a counting sort), each bucket (about six edges) as
      64-bit keys 2 w + (start == w != v), whose order is that order
      inside a bucket, sorted by insertion (plain integer compares: five
      times faster than comparing records on a mesh whose vertices are not
      numbered along its surface), and classifies the groups of equal w
      (bp__check_group).  That order is total up to identical edges, so
      the list, its boundary edges and its first bad group are those of
      one global sort however the ranges are cut or run; the ranges'
      boundary edges are appended in range order, their counts added and
      the first range's bad group kept.  A map of fewer than 2^10
      vertices, or checked on one thread, is one range, read straight
      from the triangles (the scatter would cost a tenth of the check).
   3. The connected pieces (for (c) and (d)): a union-find over the
      vertices, one task beside the ranges, when (c) may be reached.  Two
      unions per triangle: the third edge joins vertices already joined.
   (b), (c) and (d) read the boundary edges only and stay serial. */

#ifndef BP__CHECK_CHUNK
#define BP__CHECK_CHUNK      2048u     /* triangles per chunk (BP__TRI_CHUNK) */
#endif
#define BP__CHECK_RANGES     16u       /* at most this many key ranges        */
#ifndef BP__CHECK_RANGE_SHIFT
#define BP__CHECK_RANGE_SHIFT 10u      /* and at least 2^this vertices each   */
#endif                                 /* (tests/test_check.c sets both small) */

/* What one triangle chunk found (1.). */
typedef struct bp__check_part {
    uint32_t bad_index;            /* first triangle with a vertex >= nv, or BP__NONE */
    uint32_t nonfinite, first_nonfinite;
    uint32_t flipped, degenerate;
    uint32_t first_bad, first_flipped; /* (a): first flipped or degenerate triangle
                                      (BP__NONE: none), 1 if it is flipped */
    double   maxabs, minabs;       /* finite magnitudes (minabs: nonzero)   */
} bp__check_part;

/* What one key range found (2.): its boundary edges and bad groups. */
typedef struct bp__check_range {
    uint32_t nb, nonmanifold, misoriented;
    int      kind;                 /* its first bad group: BP__BAD_*, or 0  */
    uint32_t v0, v1, count;
} bp__check_range;

typedef struct bp__check_task {
    const uint32_t  *tris;
    const double    *uv;           /* what (a) reads: the map or its scaled copy */
    uint32_t         nt, nv, nchunk, nrange, shift;
    bp__check_part  *part;         /* nchunk                                 */
    uint32_t        *rcnt;         /* nchunk x nrange: chunk c's edges in range r,
                                      then the slot of its first one         */
    uint32_t        *roff;         /* nrange + 1: where range r's edges start */
    bp__dedge       *rec;          /* 3 nt: the edges by range, then each
                                      range's boundary edges at its start    */
    uint64_t        *key;          /* 3 nt: the ranges' buckets              */
    uint32_t        *start;        /* nv: the end of each bucket             */
    uint32_t        *piece;        /* nv: the pieces' union-find, or NULL    */
    bp__check_range *range;        /* nrange                                 */
} bp__check_task;

/* Are all finite magnitudes in [minabs, maxabs] in the exact range? */
static int bp__check_exact(double maxabs, double minabs)
{
    return maxabs < BP__EXACT_MAX && (minabs >= BP__EXACT_MIN || minabs == HUGE_VAL);
}

/* Triangles [t0, t1) in one pass: finiteness (rep->nonfinite's count), the
   largest and smallest nonzero finite magnitude, and (a), the exact
   orientation of each triangle with finite corners -- decided only if the
   magnitudes turn out to be in the exact range; else the caller scales the
   map and runs (a) again (bp__check_orientation).  The magnitudes are
   kept in locals: through P they would be stored and loaded again for
   every coordinate, as uv might alias them. */
static void bp__check_triangles(const uint32_t *tris, const double *uv, uint32_t t0, uint32_t t1, bp__check_part *P)
{
    const double errbound = (3.0 + 16.0 * DBL_EPSILON / 2) * (DBL_EPSILON / 2);
    double maxabs = 0, minabs = HUGE_VAL;
    uint32_t t, k;
    for (t = t0; t < t1; t++) {
        const uint32_t *tr = tris + 3 * (size_t)t;
        const double *p[3];
        int o, fin = 1;
        for (k = 0; k < 3; k++) p[k] = uv + 2 * (size_t)tr[k];
        for (k = 0; k < 6; k++) {
            double c = p[k / 2][k % 2], m = fabs(c);
            if (!(c - c == 0)) { fin = 0; continue; }
            maxabs = m > maxabs ? m : maxabs;
            minabs = m > 0 && m < minabs ? m : minabs;
        }
        if (!fin) {
            if (!P->nonfinite) P->first_nonfinite = t;
            P->nonfinite++;
            continue;
        }
        {   /* bp_orient2d, its filter written out (a call per triangle costs) */
            double dl = (p[0][0] - p[2][0]) * (p[1][1] - p[2][1]), dr = (p[0][1] - p[2][1]) * (p[1][0] - p[2][0]);
            double det = dl - dr;
            o = fabs(det) > errbound * (fabs(dl) + fabs(dr)) ? (det > 0) - (det < 0) : bp__orient2d_exact(p[0], p[1], p[2]);
        }
        if (o <= 0) {
            if (o < 0) P->flipped++; else P->degenerate++;
            if (P->first_bad == BP__NONE) { P->first_bad = t; P->first_flipped = o < 0; }
        }
    }
    P->maxabs = maxabs;
    P->minabs = minabs;
}

/* (a) alone on triangles [t0, t1) with finite corners. */
static void bp__check_orientation(const uint32_t *tris, const double *uv, uint32_t t0, uint32_t t1,
                                  bp__check_part *P)
{
    uint32_t t, k;
    P->flipped = P->degenerate = 0;
    P->first_bad = BP__NONE;
    for (t = t0; t < t1; t++) {
        const uint32_t *tr = tris + 3 * (size_t)t;
        int o, fin = 1;
        for (k = 0; k < 3; k++) {
            const double *p = uv + 2 * (size_t)tr[k];
            if (!(p[0] - p[0] == 0) || !(p[1] - p[1] == 0)) fin = 0;
        }
        if (!fin) continue;
        o = bp_orient2d(uv + 2 * (size_t)tr[0], uv + 2 * (size_t)tr[1], uv + 2 * (size_t)tr[2]);
        if (o <= 0) {
            if (o < 0) P->flipped++; else P->degenerate++;
            if (P->first_bad == BP__NONE) { P->first_bad = t; P->first_flipped = o < 0; }
        }
    }
}

/* Task of 1.: chunk c's indices, finiteness, (a) and edges per range. */
static void bp__check_chunk_task(void *task, uint32_t c)
{
    bp__check_task *T = (bp__check_task *)task;
    bp__check_part *P = &T->part[c];
    uint32_t t0 = bp__chunk_at(T->nt, T->nchunk, c), t1 = bp__chunk_at(T->nt, T->nchunk, c + 1), t, k;
    uint32_t *cnt = T->rcnt + (size_t)c * T->nrange;
    memset(P, 0, sizeof *P);
    P->bad_index = P->first_nonfinite = P->first_bad = BP__NONE;
    for (t = t0; t < t1; t++) {
        const uint32_t *tr = T->tris + 3 * (size_t)t;
        if (tr[0] >= T->nv || tr[1] >= T->nv || tr[2] >= T->nv) { P->bad_index = t; return; }
    }
    bp__check_triangles(T->tris, T->uv, t0, t1, P);
    for (k = 0; k < T->nrange; k++) cnt[k] = 0;
    if (T->nrange > 1)
        for (t = 3 * t0; t < 3 * t1; t++) {
            uint32_t a = T->tris[t], b = T->tris[t % 3 == 2 ? t - 2 : t + 1];
            cnt[(a < b ? a : b) >> T->shift]++;
        }
}

/* (a) again on the scaled copy (a map outside the exact range). */
static void bp__check_orient_task(void *task, uint32_t c)
{
    bp__check_task *T = (bp__check_task *)task;
    bp__check_orientation(T->tris, T->uv, bp__chunk_at(T->nt, T->nchunk, c), bp__chunk_at(T->nt, T->nchunk, c + 1),
                          &T->part[c]);
}

/* Task of 2., first level: chunk c's edges into their ranges' slots. */
static void bp__check_scatter_task(void *task, uint32_t c)
{
    bp__check_task *T = (bp__check_task *)task;
    uint32_t t0 = bp__chunk_at(T->nt, T->nchunk, c), t1 = bp__chunk_at(T->nt, T->nchunk, c + 1), t;
    uint32_t *slot = T->rcnt + (size_t)c * T->nrange;
    for (t = 3 * t0; t < 3 * t1; t++) {
        bp__dedge e;
        e.a = T->tris[t];
        e.b = T->tris[t % 3 == 2 ? t - 2 : t + 1];
        T->rec[slot[(e.a < e.b ? e.a : e.b) >> T->shift]++] = e;
    }
}

static int bp__key_cmp(const void *pa, const void *pb)
{
    uint64_t x = *(const uint64_t *)pa, y = *(const uint64_t *)pb;
    return (x > y) - (x < y);
}

/* Bucket v's keys k[0..n) (2 w + (start == w != v)) sorted, then its
   groups of equal w classified into range R: a boundary edge to out[R->nb],
   a bad group counted (and kept if it is the range's first). */
static void bp__check_group(uint32_t v, uint64_t *k, size_t n, bp__check_range *R, bp__dedge *out)
{
    size_t i, j, g;
    if (n > 32) qsort(k, n, sizeof *k, bp__key_cmp);
    else
        for (i = 1; i < n; i++) {
            uint64_t x = k[i];
            for (j = i; j > 0 && k[j - 1] > x; j--) k[j] = k[j - 1];
            k[j] = x;
        }
    for (i = 0; i < n; i = g) {
        uint32_t w = (uint32_t)(k[i] >> 1), a = k[i] & 1 ? w : v, b = k[i] & 1 ? v : w;
        for (g = i + 1; g < n && k[g] >> 1 == w; g++) {}
        if (g - i == 1) {
            out[R->nb].a = a;
            out[R->nb++].b = b;
        } else if (g - i > 2 || (k[i] == k[i + 1] && v != w)) {
            int nonman = g - i > 2;
            if (!R->kind) {
                R->kind = nonman ? BP__BAD_NONMANIFOLD : BP__BAD_MISORIENTED;
                R->v0 = a;
                R->v1 = b;
                R->count = (uint32_t)(g - i);
            }
            if (nonman) R->nonmanifold++; else R->misoriented++;
        }
    }
}

/* The edge a->b into its bucket (counted first, then placed). */
#define BP__CHECK_EDGE(a, b, place)                                                         \
    do {                                                                                    \
        uint32_t v_ = (a) < (b) ? (a) : (b), w_ = (a) < (b) ? (b) : (a);                    \
        if (place) T->key[T->start[v_]++] = (uint64_t)w_ << 1 | ((a) > (b));                \
        else T->start[v_]++;                                                                \
    } while (0)

/* Range r's edges into buckets by v: counted (place 0) or placed (1).
   With one range they are read from the triangles themselves. */
static void bp__check_bucket(bp__check_task *T, uint32_t r, int place)
{
    size_t i;
    if (T->nrange == 1)
        for (i = 0; i < 3 * (size_t)T->nt; i++) {
            uint32_t a = T->tris[i], b = T->tris[i % 3 == 2 ? i - 2 : i + 1];
            BP__CHECK_EDGE(a, b, place);
        }
    else
        for (i = T->roff[r]; i < T->roff[r + 1]; i++) {
            uint32_t a = T->rec[i].a, b = T->rec[i].b;
            BP__CHECK_EDGE(a, b, place);
        }
}
#undef BP__CHECK_EDGE

/* Task of 2., second level: range r's buckets, sorted and classified; its
   boundary edges go to rec from roff[r] on (its own edges are read by
   then). */
static void bp__check_range_task(bp__check_task *T, uint32_t r)
{
    bp__check_range *R = &T->range[r];
    uint32_t v0 = r ? r << T->shift : 0, v1 = r + 1 < T->nrange ? (r + 1) << T->shift : T->nv, v, pos, lo;
    memset(R, 0, sizeof *R);
    for (v = v0; v < v1; v++) T->start[v] = 0;
    bp__check_bucket(T, r, 0);
    for (pos = T->roff[r], v = v0; v < v1; v++) {
        uint32_t c = T->start[v];
        T->start[v] = pos;
        pos += c;
    }
    bp__check_bucket(T, r, 1);
    for (lo = T->roff[r], v = v0; v < v1; v++) {
        bp__check_group(v, T->key + lo, T->start[v] - lo, R, T->rec + T->roff[r]);
        lo = T->start[v];
    }
}

/* 3.: the union-find of the connected pieces. */
static void bp__check_pieces(const uint32_t *tris, uint32_t nt, uint32_t nv, uint32_t *piece)
{
    uint32_t i;
    for (i = 0; i < nv; i++) piece[i] = i;
    for (i = 0; i < nt; i++) {
        bp__uf_union(piece, tris[3 * (size_t)i], tris[3 * (size_t)i + 1]);
        bp__uf_union(piece, tris[3 * (size_t)i + 1], tris[3 * (size_t)i + 2]);
    }
}

/* Task i of 2. and 3.: the pieces (i = 0, when wanted), range i - 1. */
static void bp__check_edges_task(void *task, uint32_t i)
{
    bp__check_task *T = (bp__check_task *)task;
    if (i > 0) bp__check_range_task(T, i - 1);
    else if (T->piece) bp__check_pieces(T->tris, T->nt, T->nv, T->piece);
}

/* A copy of uv scaled by 2^s when the finite magnitudes [minabs, maxabs]
   leave the exact range (else *scaled = NULL: use uv as it is).  The
   scaling is exact: every scaled coordinate stays a normal double. */
static bp_status bp__check_scale(const bp_allocator *a, const double *uv, uint32_t nv, double maxabs, double minabs,
                                 double **scaled, bp_error *err)
{
    int emax, emin, s = 0;
    size_t i;
    *scaled = NULL;
    if (bp__check_exact(maxabs, minabs)) return BP_OK;
    emax = ilogb(maxabs);                    /* 2^emax <= maxabs < 2^(emax+1) */
    emin = ilogb(minabs);
    if (emax - emin > 994)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_check: the coordinates range from %g to %g in magnitude, a ratio above 2^994; "
                        "no power-of-two scaling brings both into the range [2^-485, 2^510) where the exact "
                        "predicates are exact", minabs, maxabs);
    if (emax > 509) s = 509 - emax;
    else s = -485 - emin;
    *scaled = (double *)bp__alloc_array(a, 2 * (size_t)nv, sizeof(double));
    if (!*scaled) return bp__oom(err, "scaling the map for the exact check");
    for (i = 0; i < 2 * (size_t)nv; i++) (*scaled)[i] = ldexp(uv[i], s);
    return BP_OK;
}

/* The task's arrays for nt triangles over nv vertices: the chunks, and the
   ranges (2^shift vertices each, at most BP__CHECK_RANGES of them; one
   when the tasks run serially: the sorted edges are the same, and one
   range saves its scatter). */
static int bp__check_alloc(const bp_allocator *a, bp__check_task *T, const bp__par *par)
{
    T->nchunk = T->nt ? bp__nchunks(T->nt, BP__CHECK_CHUNK) : 0;
    for (T->shift = BP__CHECK_RANGE_SHIFT; T->shift < 31 && ((T->nv - 1) >> T->shift) >= BP__CHECK_RANGES;) T->shift++;
    T->nrange = T->nv ? ((T->nv - 1) >> T->shift) + 1 : 1;
    if (par->run == bp__serial_for || T->nt < BP__PAR_MIN_ITEMS) T->nrange = 1;
    T->part = (bp__check_part *)bp__alloc_array(a, T->nchunk + 1, sizeof *T->part);
    T->rcnt = (uint32_t *)bp__alloc_array(a, (size_t)T->nchunk * T->nrange + 1, sizeof(uint32_t));
    T->roff = (uint32_t *)bp__alloc_array(a, (size_t)T->nrange + 1, sizeof(uint32_t));
    T->range = (bp__check_range *)bp__alloc_array(a, T->nrange, sizeof *T->range);
    return T->part && T->rcnt && T->roff && T->range;
}

static void bp__check_free(const bp_allocator *a, bp__check_task *T)
{
    bp__free(a, T->part); bp__free(a, T->rcnt); bp__free(a, T->roff); bp__free(a, T->range);
    bp__free(a, T->rec); bp__free(a, T->key); bp__free(a, T->start); bp__free(a, T->piece);
}

/* 1. combined in chunk order into rep and first (the serial loops' first
   elements); BP_ERR_INDEX for a vertex index out of range.  *maxabs and
   *minabs: the magnitudes of the whole map. */
static bp_status bp__check_chunks(const bp__check_task *T, bp_check_report *rep, double *maxabs,
                                  double *minabs, bp_error *err)
{
    uint32_t c, k;
    *maxabs = 0;
    *minabs = HUGE_VAL;
    for (c = 0; c < T->nchunk; c++) {
        const bp__check_part *P = &T->part[c];
        if (P->bad_index != BP__NONE) {
            const uint32_t *tr = T->tris + 3 * (size_t)P->bad_index;
            for (k = 0; k < 2 && tr[k] < T->nv; k++) {}
            return bp__fail(err, BP_ERR_INDEX, BP_ELEMENT_TRIANGLE, P->bad_index, -1, 0,
                            "bp_check: triangle index %u uses vertex %u, but there are %u vertices", P->bad_index,
                            tr[k], T->nv);
        }
        if (P->nonfinite && !rep->nonfinite) rep->first_bad_triangle = P->first_nonfinite;
        rep->nonfinite += P->nonfinite;
        if (P->maxabs > *maxabs) *maxabs = P->maxabs;
        if (P->minabs < *minabs) *minabs = P->minabs;
    }
    return BP_OK;
}

/* (a)'s counts and first bad triangle, in chunk order. */
static void bp__check_oriented(const bp__check_task *T, bp_check_report *rep, bp__check_first *first)
{
    uint32_t c;
    for (c = 0; c < T->nchunk; c++) {
        const bp__check_part *P = &T->part[c];
        rep->flipped += P->flipped;
        rep->degenerate += P->degenerate;
        if (!rep->nonfinite && rep->first_bad_triangle < 0 && P->first_bad != BP__NONE) {
            rep->first_bad_triangle = P->first_bad;
            first->count = P->first_flipped;
        }
    }
}

/* 2.: the ranges' slots (range-major, chunk order), the ranges and the
   pieces on the runner, then their boundary edges appended in range order
   into T->rec[0..*nb) and their bad groups added (the first range's first
   kept).  Returns 0 when out of memory. */
static int bp__check_edges(const bp_allocator *a, bp__check_task *T, const bp__par *par, int pieces,
                           bp_check_report *rep, bp__check_first *first, uint32_t *nb)
{
    uint32_t c, r, pos = 0;
    size_t m = 3 * (size_t)T->nt;
    T->rec = (bp__dedge *)bp__alloc_array(a, m + 1, sizeof *T->rec);
    T->key = (uint64_t *)bp__alloc_array(a, m + 1, sizeof *T->key);
    T->start = (uint32_t *)bp__alloc_array(a, (size_t)T->nv + 1, sizeof(uint32_t));
    if (pieces) T->piece = (uint32_t *)bp__alloc_array(a, (size_t)T->nv + 1, sizeof(uint32_t));
    if (!T->rec || !T->key || !T->start || (pieces && !T->piece)) return 0;
    for (r = 0; r < T->nrange; r++) {
        T->roff[r] = pos;
        for (c = 0; T->nrange > 1 && c < T->nchunk; c++) {
            uint32_t *x = T->rcnt + (size_t)c * T->nrange + r, n = *x;
            *x = pos;
            pos += n;
        }
    }
    T->roff[T->nrange] = (uint32_t)m;
    if (T->nrange > 1) bp__par_run(par, bp__check_scatter_task, T, T->nchunk, T->nt);
    bp__par_run(par, bp__check_edges_task, T, T->nrange + 1, T->nt);
    for (*nb = 0, r = 0; r < T->nrange; r++) {
        const bp__check_range *R = &T->range[r];
        memmove(T->rec + *nb, T->rec + T->roff[r], R->nb * sizeof *T->rec);
        *nb += R->nb;
        if (R->kind && !rep->nonmanifold_edges && !rep->misoriented_edges) {
            first->kind = R->kind;
            first->v0 = R->v0;
            first->v1 = R->v1;
            first->count = R->count;
            rep->first_nonmanifold_edge[0] = R->v0;
            rep->first_nonmanifold_edge[1] = R->v1;
        }
        rep->nonmanifold_edges += R->nonmanifold;
        rep->misoriented_edges += R->misoriented;
    }
    return 1;
}

/* Up to three triangles that use the edge {u, v}, into tl (returns how many). */
static uint32_t bp__edge_triangles(const uint32_t *tris, uint32_t nt, uint32_t u, uint32_t v, uint32_t *tl)
{
    uint32_t t, k, n = 0;
    for (t = 0; t < nt && n < 3; t++)
        for (k = 0; k < 3; k++) {
            uint32_t p = tris[3 * (size_t)t + k], q = tris[3 * (size_t)t + (k + 1) % 3];
            if ((p == u && q == v) || (p == v && q == u)) { tl[n++] = t; break; }
        }
    return n;
}

/* The verdict: BP_OK for a valid map, else the status of the first
   failure in the order precondition, non-finite, (a), (b), (c), (d), with
   err naming its elements in the caller's own (0-based) indices. */
static bp_status bp__check_verdict(const uint32_t *tris, uint32_t nt, const bp_check_report *rep,
                                   const bp__check_first *first, bp_error *err)
{
    if (rep->nonmanifold_edges || rep->misoriented_edges) {
        uint32_t tl[3] = { 0, 0, 0 }, n = bp__edge_triangles(tris, nt, first->v0, first->v1, tl);
        if (first->kind == BP__BAD_NONMANIFOLD)
            return bp__fail(err, BP_ERR_NONMANIFOLD, BP_ELEMENT_EDGE, first->v0, first->v1, 0,
                            "bp_check: edge %u-%u is used by %u triangles (triangle indices %u, %u, %u%s): the "
                            "triangles do not form a manifold, which the check needs",
                            first->v0, first->v1, first->count, tl[0], tl[1], tl[2], first->count > 3 ? ", ..." : "");
        return bp__fail(err, BP_ERR_ORIENTATION, BP_ELEMENT_EDGE, first->v0, first->v1, 0,
                        "bp_check: edge %u-%u is used twice in the direction %u->%u (triangle indices %u and %u): "
                        "a triangle listed twice, or two neighbours of opposite orientation",
                        first->v0, first->v1, first->v0, first->v1, tl[0], n > 1 ? tl[1] : tl[0]);
    }
    if (rep->nonfinite || rep->flipped || rep->degenerate) {
        uint32_t t = (uint32_t)rep->first_bad_triangle;
        const uint32_t *tr = tris + 3 * (size_t)t;
        if (rep->nonfinite)
            return bp__fail(err, BP_ERR_NONFINITE, BP_ELEMENT_TRIANGLE, t, -1, 0,
                            "bp_check: triangle index %u (vertices %u %u %u) has a NaN or infinite coordinate "
                            "(%u such triangles)", t, tr[0], tr[1], tr[2], rep->nonfinite);
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_TRIANGLE, t, -1, 0,
                        "bp_check: triangle index %u (vertices %u %u %u) is %s (%u flipped and %u degenerate "
                        "triangles in all)", t, tr[0], tr[1], tr[2],
                        first->count ? "flipped (negative signed area)" : "degenerate (zero signed area)",
                        rep->flipped, rep->degenerate);
    }
    if (rep->boundary_intersections)
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_EDGE, first->pair[0].a, first->pair[0].b, 0,
                        "bp_check: boundary edges %u-%u and %u-%u meet (%u such pairs)", first->pair[0].a,
                        first->pair[0].b, first->pair[1].a, first->pair[1].b, rep->boundary_intersections);
    switch (first->kind) {
    case BP__BAD_PINCH:
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_VERTEX, first->v0, -1, 0,
                        "bp_check: vertex %u starts two boundary edges (the boundary is pinched there)", first->v0);
    case BP__BAD_OPEN:
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_VERTEX, first->v0, -1, 0,
                        "bp_check: the boundary stops at vertex %u", first->v0);
    case BP__BAD_CCW:
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_VERTEX, first->v0, -1, 0,
                        "bp_check: the connected piece with boundary vertex %u has %u counter-clockwise boundary "
                        "loops, not exactly one (%s)", first->v0, first->count,
                        first->count ? "it wraps around a point more than once" : "it is mirrored");
    case BP__BAD_NESTED:
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_VERTEX, first->v0, first->v1, 0,
                        "bp_check: the piece with boundary vertex %u lies on top of the piece with boundary vertex %u",
                        first->v0, first->v1);
    default:
        return bp__ok(err);
    }
}

/* bp_check on a runner, in order: indices, finiteness and the magnitude
   range, (a) per triangle (1.); a copy scaled into the exact range if
   needed, and (a) again on it; the precondition and the boundary edges
   (2.) with the pieces (3.); (b); (c) and (d); the verdict.  The same
   report, error and status as bp_check for any runner. */
static bp_status bp__check_par(const uint32_t *tris, uint32_t nt, const double *uv, uint32_t nv,
                               const bp_allocator *alloc, const bp__par *par, bp_check_report *rep, bp_error *err)
{
    bp_allocator a;
    bp__check_task T;
    bp__check_first first;
    double *scaled = NULL, maxabs, minabs;
    uint32_t nb = 0;
    bp_status st = BP_OK;
    memset(&a, 0, sizeof a);
    memset(&T, 0, sizeof T);
    memset(&first, 0, sizeof first);
    if (alloc) a = *alloc;
    if (!rep || (!tris && nt) || (!uv && nv))
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_check needs a report, and triangle and uv arrays when their counts are not zero");
    memset(rep, 0, sizeof *rep);
    rep->first_bad_triangle = rep->first_bad_edge[0] = rep->first_bad_edge[1] = -1;
    rep->first_nonmanifold_edge[0] = rep->first_nonmanifold_edge[1] = -1;
    T.tris = tris;
    T.uv = uv;
    T.nt = nt;
    T.nv = nv;
    if (!bp__check_alloc(&a, &T, par)) { bp__check_free(&a, &T); return bp__oom(err, "checking a map"); }
    bp__par_run(par, bp__check_chunk_task, &T, T.nchunk, nt);
    if ((st = bp__check_chunks(&T, rep, &maxabs, &minabs, err)) != BP_OK ||
        (st = bp__check_scale(&a, uv, nv, maxabs, minabs, &scaled, err)) != BP_OK) {
        bp__check_free(&a, &T);
        return st;
    }
    if (scaled) {
        T.uv = scaled;
        bp__par_run(par, bp__check_orient_task, &T, T.nchunk, nt);
    }
    bp__check_oriented(&T, rep, &first);
    if (!bp__check_edges(&a, &T, par, !rep->nonfinite && !rep->flipped && !rep->degenerate, rep, &first, &nb))
        st = BP_ERR_OUT_OF_MEMORY;
    else if (!rep->nonfinite && !rep->nonmanifold_edges && !rep->misoriented_edges) {
        /* boundary geometry is meaningful: (b), then (c) and (d) */
        st = bp__boundary_conflicts(&a, T.uv, T.rec, nb, rep, NULL, first.pair);
        if (st == BP_OK && !rep->flipped && !rep->degenerate && !rep->boundary_intersections)
            st = bp__loop_topology(&a, T.uv, nv, T.piece, T.rec, nb, rep, &first);
    }
    bp__check_free(&a, &T);
    bp__free(&a, scaled);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "checking a map");
    if (st != BP_OK)
        return bp__fail(err, st, BP_ELEMENT_NONE, -1, -1, 0, "bp_check: the boundary's extent overflows");
    return bp__check_verdict(tris, nt, rep, &first, err);
}

/* The public check: the same tasks, one after the other. */
BPDEF bp_status bp_check(const uint32_t *tris, uint32_t nt, const double *uv, uint32_t nv,
                         const bp_allocator *alloc, bp_check_report *rep, bp_error *err)
{
    bp__par serial = bp__par_serial();
    return bp__check_par(tris, nt, uv, nv, alloc, &serial, rep, err);
}

static int bp__report_valid(const bp_check_report *r)
{
    return !r->flipped && !r->degenerate && !r->nonfinite && !r->boundary_intersections &&
           !r->loop_orientation && !r->nested && !r->nonmanifold_edges && !r->misoriented_edges;
}

/* Is st a verdict of bp_check (a report was filled), not a failure to check? */
static int bp__check_verdict_status(bp_status st)
{
    return st == BP_OK || st == BP_ERR_NOT_BIJECTIVE || st == BP_ERR_NONFINITE || st == BP_ERR_NONMANIFOLD ||
           st == BP_ERR_ORIENTATION;
}

/* >>tutte ==================================================================

   The interior point method of sec 3.4.1 must start from a bijective map.
   Tutte's theorem (1963) and Floater's extension (2003) give one: fix the
   outer loop on a convex polygon and place every other vertex at a convex
   combination of its neighbours,
       sum_j w_ij (u_i - u_j) = 0,   w_ij > 0,
   and the result is an embedding of a triangulated disk.  Uniform weights
   (w_ij = 1) give Tutte's map; Floater's mean-value weights
       w_ij = (tan(alpha_ij / 2) + tan(beta_ij / 2)) / |p_i - p_j|,
   with alpha, beta the 3D angles at i on either side of edge ij, follow the
   surface more closely.  The outer loop goes on a circle, spaced by 3D arc
   length, with the radius that gives the circle the chart's 3D area.

   Holes (sec 3.6, fig 3.14): a chart with holes is not a disk, so each hole
   is closed with a fan of temporary triangles to a virtual centre vertex
   (placed, for the mean-value weights, at the hole loop's 3D centroid).  The
   filled chart is a disk; after the solve the temporary triangles and
   centres are dropped.  What remains is bijective: removing faces from an
   embedding keeps it an embedding, and each hole becomes a simple loop.

   The solve is exact in theory but rounded in practice: on large charts a
   few triangles can come out with an area near the rounding level.  The map
   is therefore checked exactly before it is returned, and a chart whose
   start map is not valid fails with BP_ERR_NUMERICAL naming the triangle.

   Tutte's map crushes long protrusions and thin charts (the boundary on a
   circle, every interior vertex at a mean of its neighbours): >>start
   gives a planar chart its own projection instead (the default), and can
   relax a Tutte start by progressive references (bp_options.start).

   The default start (BP_INIT_AUTO) is now the conformal map of
   >>conformal when it passes the exact check (below BP__CONFORMAL_MAX
   triangles); the barycentric map is its fallback, and which weights
   that fallback takes was measured before (docs/performance.md sec 6.7):
   The uniform map ignores the geometry, so its distortion grows with the
   resolution: on the face with six holes subdivided to 133K and 298K faces
   the optimizer needs 447 and 623 iterations from Tutte, 42 and 52 from
   the mean-value map, which reproduces the shape (start energy 4.19 at
   every size): 4-5.6x less CPU.  On the 15 corpus meshes (one thread)
   it needs fewer iterations on 12, half the CPU on camelhead, and 120.0
   against 121.3 s of CPU in all, with equal final energies (within 2e-4
   relative).  Its price: the weights are not symmetric (w_ij != w_ji), so
   the system is solved by LU instead of LDL^T: about twice the
   factorization time and up to 17% more peak memory.  On charts with long
   crushed protrusions (bimba, lucy, hilbert) both starts are about as bad
   and the mean-value one costs 3-11% more; no size rule separates them
   (bimba, 89K faces, loses; camelhead, 23K, wins), so AUTO is the
   mean-value map for every chart.  Floater's theorem makes it an
   embedding like Tutte's, but the LU solve is rounded like any other: if
   its map fails the exact check, AUTO recomputes the chart with uniform
   weights (whose symmetric system is the better conditioned) before
   reporting BP_ERR_NUMERICAL.  BP_INIT_TUTTE asks for the uniform map. */

/* Angle at corner p between directions to q and r, in (0, pi). */
static double bp__angle3(const double *p, const double *q, const double *r)
{
    double u[3], v[3], c[3], dot = 0, cr;
    int k;
    for (k = 0; k < 3; k++) { u[k] = q[k] - p[k]; v[k] = r[k] - p[k]; dot += u[k] * v[k]; }
    c[0] = u[1] * v[2] - u[2] * v[1];
    c[1] = u[2] * v[0] - u[0] * v[2];
    c[2] = u[0] * v[1] - u[1] * v[0];
    cr = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    return atan2(cr, dot);
}

/* Position of j in the sorted neighbour list of i (binary search). */
static uint32_t bp__adj_find(const uint32_t *adjp, const uint32_t *adj, uint32_t i, uint32_t j)
{
    uint32_t lo = adjp[i], hi = adjp[i + 1];
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (adj[mid] < j) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* The working state of one start map, in the order bp__chart_init's phases
   fill it. */
typedef struct bp__tutte {
    uint32_t nv, N, nt;           /* chart vertices, + hole centres, filled triangles */
    uint32_t *tri;                /* 3*nt: the chart's triangles, then the hole fans */
    double   *pos;                /* 3*N: 3D positions, centres at hole centroids */
    uint32_t *adjp, *adj, ne;     /* sorted neighbour lists (both directions) */
    double   *w;                  /* w[e] = w_{i, adj[e]}                    */
    uint32_t *idx, nfree;         /* free-vertex number, BP__NONE when fixed */
    bp__sparse A;
    double   *rhs, *sol, *work;
    int       krylov_iters;       /* phase 6a: iterations, -1 not converged */
    double    krylov_rel;         /* ... and its relative residual          */
    uint32_t *incp, *inc;         /* corners 3t+k of each vertex, increasing */
    bp__par   par;                /* who runs the phases' tasks (run NULL: serial) */
    uint32_t *nd;                 /* phase 5b: the filled chart's order, N words */
    bp__ndnode ndtree[BP__ND_NODES];
} bp__tutte;

static void bp__tutte_free(const bp_allocator *a, bp__tutte *T)
{
    bp__free(a, T->tri); bp__free(a, T->pos); bp__free(a, T->adjp); bp__free(a, T->adj);
    bp__free(a, T->w); bp__free(a, T->idx); bp__free(a, T->rhs); bp__free(a, T->sol); bp__free(a, T->work);
    bp__free(a, T->A.colp); bp__free(a, T->A.row); bp__free(a, T->A.val);
    bp__free(a, T->incp); bp__free(a, T->inc); bp__free(a, T->nd);
}

/* Phase 1, the filled chart: real triangles, then one fan per hole to a
   centre at the hole loop's 3D centroid (reverse twins of the hole's
   boundary edges, so the filled chart is a disk). */
static int bp__tutte_fill(const bp_allocator *a, bp__tutte *T, const bp_chart *ch, const bp_mesh *m)
{
    uint32_t t, i, j, k, nfan = ch->loop_start[ch->num_loops] - ch->loop_start[1];
    T->nv = ch->num_vertices;
    T->N = T->nv + ch->num_loops - 1;
    T->nt = ch->num_triangles + nfan;
    T->tri = (uint32_t *)bp__alloc_array(a, 3 * (size_t)T->nt, sizeof(uint32_t));
    T->pos = (double *)bp__alloc_array(a, 3 * (size_t)T->N, sizeof(double));
    if (!T->tri || !T->pos) return 0;
    memcpy(T->tri, ch->triangles, 3 * (size_t)ch->num_triangles * sizeof(uint32_t));
    for (i = 0; i < T->nv; i++) memcpy(T->pos + 3 * (size_t)i, bp__pos(m, ch->vertex[i]), 3 * sizeof(double));
    for (t = ch->num_triangles, i = 1; i < ch->num_loops; i++) {
        uint32_t s0 = ch->loop_start[i], s1 = ch->loop_start[i + 1], c = T->nv + i - 1;
        double cen[3] = { 0, 0, 0 };
        for (j = s0; j < s1; j++) {
            uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < s1 ? j + 1 : s0];
            for (k = 0; k < 3; k++) cen[k] += T->pos[3 * (size_t)va + k] / (s1 - s0);
            T->tri[3 * (size_t)t] = vb; T->tri[3 * (size_t)t + 1] = va; T->tri[3 * (size_t)t + 2] = c;
            t++;
        }
        memcpy(T->pos + 3 * (size_t)c, cen, sizeof cen);
    }
    return 1;
}

/* The phases on several threads (issue 15).  Phases 2, 3 and 5 were
   scatters over the triangles (and a qsort per vertex): serial set-up of
   tens of milliseconds on a 132K-face chart, while the iterations after
   them run on every thread.  They are gathers per vertex instead, run by
   vertex chunks (>>threads: chunk boundaries depend on the count alone),
   and each gives the scatter's bits:
   - the corners of each vertex, inc[incp[v] .. incp[v+1]), are the corner
     numbers 3t+k with tri[3t+k] = v in increasing order (a counting sort
     in triangle order), so a vertex that visits its corners in that order
     adds into each of its own entries in the scatter's order (triangle t,
     then corner k), and only it writes them;
   - a vertex's neighbour list is a set (sorted, without repeats), the same
     whichever sort builds it;
   - a column of the system is written by its own vertex alone, in the
     order of the serial loop, once the columns' offsets are known.
   The phases take their runner from T->par (run NULL: a plain loop). */
#define BP__TUTTE_CHUNK 2048u             /* vertices per task */

typedef struct bp__tutte_task {
    bp__tutte *T;
    const bp_chart *ch;
    uint32_t nc, *cnt;                    /* chunks over N; per vertex counts */
    int mvc;
} bp__tutte_task;

static void bp__tutte_run(bp__tutte_task *J, bp_task_fn fn)
{
    bp__tutte *T = J->T;
    J->nc = bp__nchunks(T->N, BP__TUTTE_CHUNK);
    if (T->par.run) bp__par_run(&T->par, fn, J, J->nc, T->N);
    else bp__serial_for(NULL, fn, J, J->nc);
}

/* Phase 2, vertex chunk c: the neighbours of each vertex v (the two other
   corners of each of its corners), sorted and without repeats, written at
   the start of v's slot adj[2 incp[v] .. 2 incp[v+1]); their count in
   cnt[v]. */
static void bp__tutte_adj_task(void *task, uint32_t c)
{
    bp__tutte_task *J = (bp__tutte_task *)task;
    bp__tutte *T = J->T;
    uint32_t v, v1 = bp__chunk_at(T->N, J->nc, c + 1), q;
    for (v = bp__chunk_at(T->N, J->nc, c); v < v1; v++) {
        uint32_t *row = T->adj + 2 * (size_t)T->incp[v], n = 0, k, last = BP__NONE;
        for (q = T->incp[v]; q < T->incp[v + 1]; q++) {
            uint32_t t = T->inc[q] / 3, kk = T->inc[q] % 3;
            row[n++] = T->tri[3 * (size_t)t + (kk + 1) % 3];
            row[n++] = T->tri[3 * (size_t)t + (kk + 2) % 3];
        }
        bp__u32_sort(row, n);
        for (k = 0, q = 0; k < n; k++)
            if (row[k] != last) row[q++] = last = row[k];
        J->cnt[v] = q;
    }
}

/* Phase 2, adjacency: both directions of every triangle edge, sorted and
   deduplicated per vertex.  The corners of each vertex first (kept for
   phase 3), then each vertex's list from them in parallel, then the lists
   moved together in vertex order. */
static int bp__tutte_adjacency(const bp_allocator *a, bp__tutte *T)
{
    uint32_t t, i, N = T->N;
    size_t nc3 = 3 * (size_t)T->nt;
    bp__tutte_task J;
    uint32_t *cnt = (uint32_t *)bp__alloc_array(a, (size_t)N + 1, sizeof(uint32_t));
    T->incp = (uint32_t *)bp__calloc_array(a, (size_t)N + 2, sizeof(uint32_t));
    T->inc = (uint32_t *)bp__alloc_array(a, nc3 ? nc3 : 1, sizeof(uint32_t));
    T->adjp = (uint32_t *)bp__alloc_array(a, (size_t)N + 1, sizeof(uint32_t));
    T->adj = (uint32_t *)bp__alloc_array(a, 2 * nc3 + 1, sizeof(uint32_t));
    if (!cnt || !T->incp || !T->inc || !T->adjp || !T->adj) { bp__free(a, cnt); return 0; }
    for (t = 0; t < nc3; t++) T->incp[T->tri[t] + 2]++;
    for (i = 0; i < N; i++) T->incp[i + 2] += T->incp[i + 1];
    for (t = 0; t < nc3; t++) T->inc[T->incp[T->tri[t] + 1]++] = t;   /* vertex v: [incp[v], incp[v+1]) */
    memset(&J, 0, sizeof J);
    J.T = T;
    J.cnt = cnt;
    bp__tutte_run(&J, bp__tutte_adj_task);
    for (T->ne = 0, i = 0; i < N; i++) {
        memmove(T->adj + T->ne, T->adj + 2 * (size_t)T->incp[i], cnt[i] * sizeof(uint32_t));
        T->adjp[i] = T->ne;
        T->ne += cnt[i];
    }
    T->adjp[N] = T->ne;
    bp__free(a, cnt);
    return 1;
}

/* Phase 3, vertex chunk c: the weights of each vertex's row, its corners
   in increasing order (see above). */
static void bp__tutte_weights_task(void *task, uint32_t c)
{
    bp__tutte_task *J = (bp__tutte_task *)task;
    bp__tutte *T = J->T;
    uint32_t vi, v1 = bp__chunk_at(T->N, J->nc, c + 1), q, e;
    for (vi = bp__chunk_at(T->N, J->nc, c); vi < v1; vi++) {
        for (q = T->incp[vi]; q < T->incp[vi + 1]; q++) {
            uint32_t t = T->inc[q] / 3, k = T->inc[q] % 3;
            uint32_t vj = T->tri[3 * (size_t)t + (k + 1) % 3], vk = T->tri[3 * (size_t)t + (k + 2) % 3];
            uint32_t ej = bp__adj_find(T->adjp, T->adj, vi, vj), ek = bp__adj_find(T->adjp, T->adj, vi, vk);
            if (!J->mvc) {
                T->w[ej] = T->w[ek] = 1;
            } else {
                const double *pi = T->pos + 3 * (size_t)vi, *pj = T->pos + 3 * (size_t)vj, *pk = T->pos + 3 * (size_t)vk;
                double th = tan(0.5 * bp__angle3(pi, pj, pk));
                T->w[ej] += th / bp__dist3(pi, pj);
                T->w[ek] += th / bp__dist3(pi, pk);
            }
        }
        for (e = T->adjp[vi]; e < T->adjp[vi + 1]; e++)
            if (!(T->w[e] > 0) || !(T->w[e] - T->w[e] == 0)) T->w[e] = 1;   /* keep every weight positive */
    }
}

/* Phase 3, the weights: 1 (Tutte), or Floater's mean-value weights
   (tan(alpha/2) + tan(beta/2)) / |p_i - p_j| summed over the two triangles
   of edge ij (in triangle order); anything not positive and finite
   becomes 1.  bp__tutte_weights_loop only allocates them and sets up the
   loop *L that computes them (to run beside phase 5b's root split, which
   does not need them: bp__tutte_map); bp__tutte_weights runs it. */
static int bp__tutte_weights_loop(const bp_allocator *a, bp__tutte *T, int mvc, bp__tutte_task *J, bp__loop *L)
{
    T->w = (double *)bp__calloc_array(a, T->ne ? T->ne : 1, sizeof(double));
    if (!T->w) return 0;
    memset(J, 0, sizeof *J);
    J->T = T;
    J->mvc = mvc;
    J->nc = bp__nchunks(T->N, BP__TUTTE_CHUNK);
    L->fn = bp__tutte_weights_task;
    L->task = J;
    L->count = J->nc;
    return 1;
}

static int bp__tutte_weights(const bp_allocator *a, bp__tutte *T, int mvc)
{
    bp__tutte_task J;
    bp__loop L;
    if (!bp__tutte_weights_loop(a, T, mvc, &J, &L)) return 0;
    bp__tutte_run(&J, bp__tutte_weights_task);
    return 1;
}

/* Phase 4, the outer loop on the circle of the chart's 3D area, R =
   sqrt(area / pi), spaced by 3D arc length; every other vertex is free and
   numbered in vertex order. */
static int bp__tutte_circle(const bp_allocator *a, bp__tutte *T, bp_chart *ch)
{
    uint32_t i, j, l0 = ch->loop_start[0], l1 = ch->loop_start[1];
    double R = sqrt(ch->area3d / 3.14159265358979323846), total = 0, acc = 0, floor_len;
    T->idx = (uint32_t *)bp__calloc_array(a, T->N, sizeof(uint32_t));
    if (!T->idx) return 0;
    for (j = l0; j < l1; j++) {
        uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < l1 ? j + 1 : 0];
        total += bp__dist3(T->pos + 3 * (size_t)va, T->pos + 3 * (size_t)vb);
        T->idx[va] = BP__NONE;                   /* fixed */
    }
    /* a boundary edge of (near) zero 3D length (a repaired degenerate
       triangle, >>rest) still gets an arc of 1e-6 of the mean, so no two
       vertices share a point of the circle; other loops are spaced as is */
    floor_len = total > 0 ? 1e-6 * total / (l1 - l0) : 1;
    for (j = l0, total = 0; j < l1; j++) {
        uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < l1 ? j + 1 : 0];
        double d = bp__dist3(T->pos + 3 * (size_t)va, T->pos + 3 * (size_t)vb);
        total += d > floor_len ? d : floor_len;
    }
    for (j = l0; j < l1; j++) {
        uint32_t va = ch->loop_vertices[j], vb = ch->loop_vertices[j + 1 < l1 ? j + 1 : 0];
        double ang = 2 * 3.14159265358979323846 * acc / total, d;
        ch->uv[2 * (size_t)va] = R * cos(ang);
        ch->uv[2 * (size_t)va + 1] = R * sin(ang);
        d = bp__dist3(T->pos + 3 * (size_t)va, T->pos + 3 * (size_t)vb);
        acc += d > floor_len ? d : floor_len;
    }
    for (T->nfree = 0, i = 0; i < T->N; i++) if (T->idx[i] != BP__NONE) T->idx[i] = T->nfree++;
    return 1;
}

/* Phase 5, vertex chunk c: the number of entries of each free vertex's
   column (its free neighbours and the diagonal) into cnt, or, once the
   offsets are in A->colp (J->cnt NULL), the columns themselves. */
static void bp__tutte_system_task(void *task, uint32_t c)
{
    bp__tutte_task *J = (bp__tutte_task *)task;
    bp__tutte *T = J->T;
    bp__sparse *A = &T->A;
    uint32_t j, j1 = bp__chunk_at(T->N, J->nc, c + 1), e, p, nfree = T->nfree;
    for (j = bp__chunk_at(T->N, J->nc, c); j < j1; j++) {
        uint32_t cj = T->idx[j], nnz;
        double diag = 0;
        int diag_done = 0;
        if (cj == BP__NONE) continue;
        if (J->cnt) {
            for (nnz = 1, e = T->adjp[j]; e < T->adjp[j + 1]; e++) nnz += T->idx[T->adj[e]] != BP__NONE;
            J->cnt[cj] = nnz;
            continue;
        }
        nnz = A->colp[cj];
        for (e = T->adjp[j]; e < T->adjp[j + 1]; e++) {
            uint32_t vi = T->adj[e];
            diag += T->w[e];
            if (T->idx[vi] == BP__NONE) {         /* fixed neighbour -> rhs */
                T->rhs[cj] += T->w[e] * J->ch->uv[2 * (size_t)vi];
                T->rhs[nfree + cj] += T->w[e] * J->ch->uv[2 * (size_t)vi + 1];
            }
        }
        /* rows in increasing free index: adj is sorted by vertex and the
           free numbering is increasing in vertex, so it stays sorted */
        for (e = T->adjp[j]; e < T->adjp[j + 1]; e++) {
            uint32_t vi = T->adj[e];
            if (T->idx[vi] == BP__NONE) continue;
            if (!diag_done && vi > j) { A->row[nnz] = cj; A->val[nnz++] = 0; diag_done = 1; }
            A->row[nnz] = T->idx[vi];
            A->val[nnz++] = -T->w[bp__adj_find(T->adjp, T->adj, vi, j)];
        }
        if (!diag_done) { A->row[nnz] = cj; A->val[nnz++] = 0; }
        for (p = A->colp[cj]; p < nnz; p++) if (A->row[p] == cj) A->val[p] = diag;
    }
}

/* Phase 5, the system sum_j w_ij (u_i - u_j) = 0 over the free vertices,
   column by column, fixed neighbours moved to the right-hand side (both
   coordinates: rhs[0, nfree) and rhs[nfree, 2 nfree)): the columns'
   lengths, their offsets, then the columns (in parallel, see above). */
static int bp__tutte_system(const bp_allocator *a, bp__tutte *T, const bp_chart *ch, int mvc)
{
    uint32_t j, nnz = 0, nfree = T->nfree;
    bp__sparse *A = &T->A;
    bp__tutte_task J;
    A->n = nfree;
    A->symmetric = !mvc;
    A->super1 = !mvc && BP__SUPER_SCALAR;
    A->colp = (uint32_t *)bp__alloc_array(a, (size_t)nfree + 1, sizeof(uint32_t));
    A->row = (uint32_t *)bp__alloc_array(a, (size_t)T->ne + nfree, sizeof(uint32_t));
    A->val = (double *)bp__alloc_array(a, (size_t)T->ne + nfree, sizeof(double));
    T->rhs = (double *)bp__calloc_array(a, 2 * (size_t)nfree, sizeof(double));
    T->sol = (double *)bp__alloc_array(a, 2 * (size_t)nfree, sizeof(double));
    T->work = (double *)bp__alloc_array(a, 3 * (size_t)nfree, sizeof(double));
    if (!A->colp || !A->row || !A->val || !T->rhs || !T->sol || !T->work) return 0;
    memset(&J, 0, sizeof J);
    J.T = T;
    J.ch = ch;
    J.cnt = A->colp;
    bp__tutte_run(&J, bp__tutte_system_task);
    for (j = 0; j < nfree; j++) { uint32_t k = A->colp[j]; A->colp[j] = nnz; nnz += k; }
    A->colp[nfree] = nnz;
    J.cnt = NULL;
    bp__tutte_run(&J, bp__tutte_system_task);
    return 1;
}

/* Phase 6a, the mean-value system without its LU.  The mean-value matrix
   A is not symmetric, and its LU by the scalar up-looking rows (>>sparse)
   was half of a million-face chart's whole run (docs/performance.md sec
   6.5: 40 s of 79).  First each row is divided by its diagonal, so the
   system reads u_i - sum_j lambda_ij u_j = rhs_i with Floater's
   normalized weights lambda_ij = w_ij / sum_k w_ik (the same solution;
   measured, this made the iteration below 2.5x shorter on 132K faces than
   the raw weights: 16 against 40 iterations).  The symmetric part of that
   A, made a Laplacian again,
       M(i, j) = -(a_ij + a_ji) / 2  (i != j, both free),
       M(i, i) = -sum_j (a_ij + a_ji) / 2 over free j + the row's fixed part,
   is symmetric positive definite (weakly diagonally dominant, strictly
   next to the boundary, irreducible) on the same pattern, and close to A
   where the mesh is regular.  So the supernodal Cholesky of M (A->super1),
   in the preconditioner's single-precision rows (bp__factor_single: both
   coordinates per solve, in parallel), preconditions BiCGSTAB (van der
   Vorst 1992) on A from the right,
       A K^-1 y = b,  x = K^-1 y,  K = M,
   one iteration per coordinate in lockstep (the two share each solve with
   K), until |b - A x| <= BP__KRYLOV_TOL |b| for both.  The residual is the
   true one, recomputed from x in double; K only steers, so its rounding to
   single precision costs iterations, not accuracy.  If that does not happen
   within BP__KRYLOV_ITERS iterations, or K cannot be factored, the LU
   below solves as before; either way the exact check of phase 7 follows.
   Every sum runs in a fixed order (the dot products serially, the
   products by A as gathers by rows, see bp__krylov_task) and
   bp__precondition's bits do not depend on the schedule, so x is the same
   on any thread count. */
#ifndef BP__TUTTE_KRYLOV
#define BP__TUTTE_KRYLOV 1
#endif
#define BP__KRYLOV_TOL 1e-13
#define BP__KRYLOV_ITERS 200

/* The set-up of phase 6a in column chunks on the runner's threads (it was
   serial: 25-45 ms of a two-thread run on the 132K-face chart, while the
   other thread waited; docs/performance.md sec 6.33).  Each pass writes
   only its own columns and each sum runs in the serial order, so the bits
   do not depend on the schedule:
     pass 0: dg_j, A's positive diagonal (1 if none), and the transposes
             tpos[p] (A's pattern is symmetric and its rows sorted, so the
             transpose of entry (i, j) is row j's place in column i);
     pass 1: As = D^-1 A (each row over its diagonal) and b = D^-1 rhs;
     pass 2: M of As (above): row sums of As as gathers of its transposes,
             in column order, the order the serial scatter added them. */
typedef struct bp__ksym_task {
    const bp__sparse *A;          /* A, then As                             */
    bp__sparse *M;
    const double *rhs;            /* 2 nfree: x block, then y block         */
    double *b, *dg, *sval;        /* b interleaved, the scaled values       */
    uint32_t *tpos;
    uint32_t nc;
    int pass;
} bp__ksym_task;

static void bp__ksym_run(void *task, uint32_t c)
{
    bp__ksym_task *T = (bp__ksym_task *)task;
    const bp__sparse *A = T->A;
    uint32_t n = A->n, j, p, j1 = bp__chunk_at(n, T->nc, c + 1);
    for (j = bp__chunk_at(n, T->nc, c); j < j1; j++) {
        uint32_t p0 = A->colp[j], p1 = A->colp[j + 1], d = BP__NONE;
        double fix = 0, off = 0;
        if (T->pass == 0) {
            if (T->dg) {                                          /* (bp__tutte_scaled) */
                T->dg[j] = 1;
                for (p = p0; p < p1; p++)
                    if (A->row[p] == j && A->val[p] > 0) T->dg[j] = A->val[p];
            }
            if (T->tpos)                                          /* (bp__tutte_symmetric) */
                for (p = p0; p < p1; p++)
                    T->tpos[p] = bp__lower_bound(A->row, A->colp[A->row[p]], A->colp[A->row[p] + 1], j);
        } else if (T->pass == 1) {
            for (p = p0; p < p1; p++) T->sval[p] = A->val[p] / T->dg[A->row[p]];
            T->b[2 * (size_t)j] = T->rhs[j] / T->dg[j];
            T->b[2 * (size_t)j + 1] = T->rhs[n + j] / T->dg[j];
        } else {
            for (p = p0; p < p1; p++) fix += A->val[T->tpos[p]];     /* row j's sum */
            for (p = p0; p < p1; p++) {
                if (A->row[p] == j) { d = p; continue; }
                T->M->val[p] = 0.5 * (A->val[p] + A->val[T->tpos[p]]);
                off -= T->M->val[p];
            }
            if (d != BP__NONE) T->M->val[d] = fix + off;
        }
    }
}

static void bp__ksym_pass(bp__ksym_task *T, const bp__par *par, int pass)
{
    bp__par serial = bp__par_serial();
    T->pass = pass;
    bp__par_run(par ? par : &serial, bp__ksym_run, T, T->nc, T->A->n);
}

/* As's values (D^-1 A) into sval and b = D^-1 rhs (interleaved), dg the
   diagonal D. */
static void bp__tutte_scaled(const bp__sparse *A, const double *rhs, const bp__par *par, double *sval, double *b,
                             double *dg)
{
    bp__ksym_task T;
    memset(&T, 0, sizeof T);
    T.A = A;
    T.rhs = rhs;
    T.b = b;
    T.dg = dg;
    T.sval = sval;
    T.nc = bp__nchunks(A->n, BP__VERT_CHUNK);
    bp__ksym_pass(&T, par, 0);
    bp__ksym_pass(&T, par, 1);
}

/* M of A (see above), on A's pattern; par NULL: serially. */
static int bp__tutte_symmetric(const bp_allocator *a, const bp__sparse *A, bp__sparse *M, const bp__par *par)
{
    bp__ksym_task T;
    uint32_t n = A->n;
    memset(M, 0, sizeof *M);
    memset(&T, 0, sizeof T);
    M->n = n;
    M->symmetric = 1;
    M->super1 = 1;
    M->colp = (uint32_t *)bp__alloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    M->row = (uint32_t *)bp__alloc_array(a, A->colp[n] ? A->colp[n] : 1, sizeof(uint32_t));
    M->val = (double *)bp__alloc_array(a, A->colp[n] ? A->colp[n] : 1, sizeof(double));
    T.tpos = (uint32_t *)bp__alloc_array(a, A->colp[n] ? A->colp[n] : 1, sizeof(uint32_t));
    if (!M->colp || !M->row || !M->val || !T.tpos) { bp__free(a, T.tpos); return 0; }
    memcpy(M->colp, A->colp, ((size_t)n + 1) * sizeof(uint32_t));
    memcpy(M->row, A->row, A->colp[n] * sizeof(uint32_t));
    T.A = A;
    T.M = M;
    T.nc = bp__nchunks(n, BP__VERT_CHUNK);
    bp__ksym_pass(&T, par, 0);
    bp__ksym_pass(&T, par, 2);
    bp__free(a, T.tpos);
    return 1;
}

/* d[c] = u . v per coordinate c of two interleaved vectors. */
static void bp__dot2(const double *u, const double *v, size_t n, double *d)
{
    size_t i;
    d[0] = d[1] = 0;
    for (i = 0; i < n; i++) { d[0] += u[2 * i] * v[2 * i]; d[1] += u[2 * i + 1] * v[2 * i + 1]; }
}

/* d = u . v and e = u . w in one pass (each sum in bp__dot2's order). */
static void bp__dot2x2(const double *u, const double *v, const double *w, size_t n, double *d, double *e)
{
    size_t i;
    d[0] = d[1] = e[0] = e[1] = 0;
    for (i = 0; i < n; i++) {
        d[0] += u[2 * i] * v[2 * i]; d[1] += u[2 * i + 1] * v[2 * i + 1];
        e[0] += u[2 * i] * w[2 * i]; e[1] += u[2 * i + 1] * w[2 * i + 1];
    }
}

/* BiCGSTAB on several threads (issue 15).  Between its two preconditioner
   solves (parallel, >>sparse) an iteration multiplies by A twice, takes
   five dot products and updates four vectors, all serial before: on a
   132K-face chart a tenth of the start map's solve.  Now:
   - y = A x is a gather by rows over a row-compressed copy of A, built
     once per solve with each row's entries in increasing column.  The
     scatter over the columns it replaced (y = 0, then for j = 0, 1, ...
     y_i += A(i, j) x_j over column j) adds into each y_i its terms in
     increasing j, starting from 0; the gather adds the same terms in the
     same order from 0, so every y_i has the same bits, and row chunks are
     independent;
   - the vector updates are element by element: any split gives the bits;
   - the dot products are sums over all rows in row order, and a split
     into partial sums would change their rounding: they stay serial, in
     bp__dot2's order, but two that read the same vector share a pass
     (t.r with t.t, and r.r with the next iteration's rh.r), and b.b, which
     does not change, is taken once.
   Row chunks depend on n alone (>>threads). */
typedef struct bp__krylov_task {
    const uint32_t *rp, *ci;            /* A by rows: columns increasing */
    const double *rv;
    const double *src, *b;              /* SPMV: y = A src; RESID: y = b - A src */
    double *y, *x, *r, *p, *v, *ph, *t;
    double beta[2], al[2], om[2];
    int live[2], mode;
    uint32_t n, nc;
} bp__krylov_task;

enum { BP__KRY_SPMV, BP__KRY_RESID, BP__KRY_P, BP__KRY_AL, BP__KRY_OM };
#define BP__KRYLOV_CHUNK 2048u            /* rows per task */

static void bp__krylov_task_run(void *task, uint32_t c)
{
    bp__krylov_task *K = (bp__krylov_task *)task;
    uint32_t i, q, i0 = bp__chunk_at(K->n, K->nc, c), i1 = bp__chunk_at(K->n, K->nc, c + 1);
    int m;
    if (K->mode <= BP__KRY_RESID) {
        for (i = i0; i < i1; i++) {
            double sx = 0, sy = 0;
            for (q = K->rp[i]; q < K->rp[i + 1]; q++) {
                sx += K->rv[q] * K->src[2 * (size_t)K->ci[q]];
                sy += K->rv[q] * K->src[2 * (size_t)K->ci[q] + 1];
            }
            if (K->mode == BP__KRY_RESID) { sx = K->b[2 * (size_t)i] - sx; sy = K->b[2 * (size_t)i + 1] - sy; }
            K->y[2 * (size_t)i] = sx;
            K->y[2 * (size_t)i + 1] = sy;
        }
        return;
    }
    for (i = 2 * i0; i < 2 * i1; i++) {
        m = (int)(i & 1);
        if (K->mode == BP__KRY_P) K->p[i] = K->live[m] ? K->r[i] + K->beta[m] * (K->p[i] - K->om[m] * K->v[i]) : 0;
        else if (K->mode == BP__KRY_AL) { K->x[i] += K->al[m] * K->ph[i]; K->r[i] -= K->al[m] * K->v[i]; }
        else { K->x[i] += K->om[m] * K->ph[i]; K->r[i] -= K->om[m] * K->t[i]; }
    }
}

static void bp__krylov_run(bp__krylov_task *K, const bp__par *par, int mode)
{
    K->mode = mode;
    bp__par_run(par, bp__krylov_task_run, K, K->nc, K->n);
}

/* y = A src (resid 0) or y = b - A src (resid 1), by the gather. */
static void bp__krylov_spmv(bp__krylov_task *K, const bp__par *par, const double *src, double *y, int resid)
{
    K->src = src;
    K->y = y;
    bp__krylov_run(K, par, resid ? BP__KRY_RESID : BP__KRY_SPMV);
}

/* A's rows (rp, ci, rv), columns increasing: a counting sort of the
   columns' entries in column order.  0 out of memory. */
static int bp__sparse_rows(const bp_allocator *a, const bp__sparse *A, uint32_t **rp, uint32_t **ci, double **rv)
{
    uint32_t n = A->n, j, p, nnz = A->colp[n], *cur;
    *rp = (uint32_t *)bp__calloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    *ci = (uint32_t *)bp__alloc_array(a, nnz ? nnz : 1, sizeof(uint32_t));
    *rv = (double *)bp__alloc_array(a, nnz ? nnz : 1, sizeof(double));
    cur = (uint32_t *)bp__alloc_array(a, n ? n : 1, sizeof(uint32_t));
    if (!*rp || !*ci || !*rv || !cur) { bp__free(a, cur); return 0; }
    for (p = 0; p < nnz; p++) (*rp)[A->row[p] + 1]++;
    for (j = 0; j < n; j++) (*rp)[j + 1] += (*rp)[j];
    memcpy(cur, *rp, n * sizeof(uint32_t));
    for (j = 0; j < n; j++)
        for (p = A->colp[j]; p < A->colp[j + 1]; p++) {
            uint32_t q = cur[A->row[p]]++;
            (*ci)[q] = j;
            (*rv)[q] = A->val[p];
        }
    bp__free(a, cur);
    return 1;
}

/* |b - A x| <= BP__KRYLOV_TOL |b| for both coordinates (r: 2n of work;
   bb = b.b per coordinate). */
static int bp__krylov_done(bp__krylov_task *K, const bp__par *par, const double *b, const double *bb,
                           const double *x, double *r, double *rel)
{
    double rr[2];
    K->b = b;
    bp__krylov_spmv(K, par, x, r, 1);
    bp__dot2(r, r, K->n, rr);
    *rel = sqrt(rr[0] > rr[1] ? rr[0] / (bb[0] > 0 ? bb[0] : 1) : rr[1] / (bb[1] > 0 ? bb[1] : 1));
    return rr[0] <= BP__KRYLOV_TOL * BP__KRYLOV_TOL * bb[0] && rr[1] <= BP__KRYLOV_TOL * BP__KRYLOV_TOL * bb[1];
}

/* Right-preconditioned BiCGSTAB for both coordinates (b, x: 2n
   interleaved; x starts at 0).  Returns the iterations taken, -1 when it
   did not converge (breakdown or BP__KRYLOV_ITERS), -2 out of memory. */
static int bp__tutte_bicgstab(const bp_allocator *a, const bp__sparse *A, const bp__factor *K, const bp__par *par,
                              const double *b, double *x, double *rel)
{
    size_t n = A->n, i, m = 2 * n;
    double *buf = (double *)bp__alloc_array(a, 12 * n + 1, sizeof(double));
    double *r, *rh, *p, *v, *ph, *t, *z, rho[2] = {1, 1}, bb[2], rn[2];
    int it, c, ok = -1;
    bp__krylov_task J;
    memset(&J, 0, sizeof J);
    J.al[0] = J.al[1] = J.om[0] = J.om[1] = 1;
    J.live[0] = J.live[1] = 1;
    J.n = (uint32_t)n;
    J.nc = bp__nchunks(J.n, BP__KRYLOV_CHUNK);
    z = (double *)bp__alloc_array(a, 4 * n + 1, sizeof(double));
    if (!buf || !z || !bp__sparse_rows(a, A, (uint32_t **)&J.rp, (uint32_t **)&J.ci, (double **)&J.rv)) {
        bp__free(a, buf); bp__free(a, z);
        bp__free(a, (void *)J.rp); bp__free(a, (void *)J.ci); bp__free(a, (void *)J.rv);
        return -2;
    }
    r = buf; rh = r + m; p = rh + m; v = p + m; ph = v + m; t = ph + m;
    J.x = x; J.r = r; J.p = p; J.v = v; J.ph = ph; J.t = t;
    for (i = 0; i < m; i++) { x[i] = 0; r[i] = rh[i] = b[i]; p[i] = v[i] = 0; }
    bp__dot2(b, b, n, bb);
    rn[0] = bb[0]; rn[1] = bb[1];                                         /* rh.r: r = rh = b */
    *rel = 1;
    for (it = 1; it <= BP__KRYLOV_ITERS; it++) {
        double d[2], e[2];
        for (c = 0; c < 2; c++) {
            J.beta[c] = J.live[c] ? (rn[c] / rho[c]) * (J.al[c] / J.om[c]) : 0;
            if (J.live[c] && !(J.beta[c] - J.beta[c] == 0)) goto done;    /* breakdown */
            rho[c] = rn[c];
        }
        bp__krylov_run(&J, par, BP__KRY_P);                                 /* p = r + beta (p - om v) */
        bp__precondition(K, par, p, ph, z);                               /* ph = K^-1 p */
        bp__krylov_spmv(&J, par, ph, v, 0);
        bp__dot2(rh, v, n, d);
        for (c = 0; c < 2; c++) {
            J.al[c] = J.live[c] ? rho[c] / d[c] : 0;
            if (!(J.al[c] - J.al[c] == 0)) goto done;
        }
        bp__krylov_run(&J, par, BP__KRY_AL);                                /* x += al ph, r = s = r - al v */
        bp__precondition(K, par, r, ph, z);                               /* ph = K^-1 s */
        bp__krylov_spmv(&J, par, ph, t, 0);
        bp__dot2x2(t, r, t, n, d, e);
        for (c = 0; c < 2; c++) {
            J.om[c] = J.live[c] && e[c] > 0 ? d[c] / e[c] : 0;
            if (J.live[c] && !(J.om[c] != 0 && J.om[c] - J.om[c] == 0)) J.live[c] = 0;   /* s = 0 or breakdown */
        }
        bp__krylov_run(&J, par, BP__KRY_OM);                                /* x += om ph, r -= om t */
        bp__dot2x2(r, r, rh, n, d, rn);                                   /* r.r; the next rh.r (rh.r = r.rh) */
        for (c = 0; c < 2; c++)
            if (J.live[c] && d[c] <= 0.01 * BP__KRYLOV_TOL * BP__KRYLOV_TOL * bb[c]) J.live[c] = 0;
        if ((!J.live[0] && !J.live[1]) || it % 10 == 0) {                 /* the true residual */
            if (bp__krylov_done(&J, par, b, bb, x, t, rel)) { ok = it; break; }
            if (!J.live[0] && !J.live[1]) break;
        }
    }
done:
    bp__free(a, buf);
    bp__free(a, z);
    bp__free(a, (void *)J.rp); bp__free(a, (void *)J.ci); bp__free(a, (void *)J.rv);
    return ok;
}

/* Phase 5b, one ordering for two factorizations.  The start map's system
   and Newton's (>>newton) are both factored after a nested dissection of
   the chart's vertex graph, and that ordering is a third of either's
   analysis (face: about 60 ms of the one-thread run each, docs/
   performance.md sec 6.23).  So the dissection is computed once, here, on
   the filled chart's graph (all N vertices: hole centres and the fixed
   outer loop too), and restricted (bp__nd_restrict) twice: to the free
   vertices, for this system, whose graph is the filled graph's induced
   subgraph on them; and to the chart's own vertices, for Newton's first
   factorization, whose pattern is the chart's edges (a subgraph of the
   filled graph's on them) plus the barrier's pairs, which bp__nd_keeps
   checks there before the order is used (else Newton orders anew).  The
   order is computed on the runner's threads with the same result on any
   number (>>sparse); with (or NULL) is a loop run beside the dissection's
   root split (bp__nd_order_with): the conformal start's matrix, or
   without it phase 3's weights. */
static int bp__tutte_order(const bp_allocator *a, bp__tutte *T, const bp__par *runner, const bp__loop *with)
{
    bp__sparse G;
    uint32_t v, e, w = 0;
    int ok;
    memset(&G, 0, sizeof G);
    G.n = T->N;
    G.symmetric = 1;
    G.colp = (uint32_t *)bp__alloc_array(a, (size_t)T->N + 1, sizeof(uint32_t));
    G.row = (uint32_t *)bp__alloc_array(a, (size_t)T->ne + T->N + 1, sizeof(uint32_t));
    T->nd = (uint32_t *)bp__alloc_array(a, T->N ? T->N : 1, sizeof(uint32_t));
    if (G.colp && G.row && T->nd) {
        for (v = 0; v < T->N; v++) {               /* the sorted neighbours with v itself, as in H's graph */
            G.colp[v] = w;
            for (e = T->adjp[v]; e < T->adjp[v + 1] && T->adj[e] < v; e++) G.row[w++] = T->adj[e];
            G.row[w++] = v;
            for (; e < T->adjp[v + 1]; e++) G.row[w++] = T->adj[e];
        }
        G.colp[T->N] = w;
    }
    ok = G.colp && G.row && T->nd && bp__nd_order_with(a, &G, T->nd, T->ndtree, BP__SUPER_ORDER, runner, with);
    bp__free(a, G.colp);
    bp__free(a, G.row);
    return ok;
}

/* A's factor (the free vertices' system, or its symmetric part) in the
   order of phase 5b restricted to the free vertices (without phase 5b,
   T->nd NULL, in its own order). */
static bp_status bp__tutte_factorize(const bp_allocator *a, const bp__tutte *T, const bp__sparse *A, bp__factor *F,
                                     uint32_t *bad, const bp__par *runner)
{
    uint32_t *order = (uint32_t *)bp__alloc_array(a, T->nfree ? T->nfree : 1, sizeof(uint32_t));
    uint32_t *pre = (uint32_t *)bp__alloc_array(a, (size_t)T->N + 1, sizeof(uint32_t));
    bp__ndnode tree[BP__ND_NODES];
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    if (!T->nd) st = bp__factorize(a, A, F, bad, runner);
    else if (order && pre) {
        bp__nd_restrict(T->nd, T->ndtree, T->N, T->idx, order, tree, pre);
        st = bp__factorize_order(a, A, F, bad, runner, order, tree);
    }
    bp__free(a, order);
    bp__free(a, pre);
    return st;
}

/* The order restricted to the chart's vertices (hole centres dropped):
   order (nv words) and its tree.  Returns 0 out of memory. */
static int bp__tutte_chart_order(const bp_allocator *a, const bp__tutte *T, uint32_t *order, bp__ndnode *tree)
{
    uint32_t *keep = (uint32_t *)bp__alloc_array(a, (size_t)T->N + 1, sizeof(uint32_t));
    uint32_t *pre = (uint32_t *)bp__alloc_array(a, (size_t)T->N + 1, sizeof(uint32_t));
    uint32_t v;
    int ok = keep && pre;
    if (ok) {
        for (v = 0; v < T->N; v++) keep[v] = v < T->nv ? v : BP__NONE;
        bp__nd_restrict(T->nd, T->ndtree, T->N, keep, order, tree, pre);
    }
    bp__free(a, keep);
    bp__free(a, pre);
    return ok;
}

/* That order (allocated with room for the tree: nv + 6 BP__ND_NODES
   words), handed to the chart for Newton and the preconditioner: nv words
   of the order, then six per tree node (lo, a, b, hi, used, split), read
   back by bp__opt_start_order. */
static void bp__tutte_keep_order(const bp__tutte *T, uint32_t *order, const bp__ndnode *tree, bp_chart *ch)
{
    uint32_t k;
    for (k = 0; k < BP__ND_NODES; k++) {
        uint32_t *w = order + T->nv + 6 * k;
        w[0] = tree[k].lo; w[1] = tree[k].a; w[2] = tree[k].b; w[3] = tree[k].hi;
        w[4] = (uint32_t)tree[k].used; w[5] = (uint32_t)tree[k].split;
    }
    ch->start_order = order;
}

/* Phase 6a as a whole: M, its factor, the iteration; the solution in
   T->sol (x then y).  Returns 1 when it converged, 0 when it did not (the
   LU serves), -1 out of memory (reported as such: a failed allocation is
   never hidden by the fallback). */
static int bp__tutte_krylov(const bp_allocator *a, bp__tutte *T, const bp__par *runner)
{
    bp__sparse M, As = T->A;
    bp__factor K;
    bp__par serial = bp__par_serial();
    uint32_t bad, i, nfree = T->nfree;
    double *b = NULL, *x = NULL, *dg = NULL, rel = 1;
    int ok = 0, it = -1;
    bp_status st;
    memset(&K, 0, sizeof K);
    memset(&M, 0, sizeof M);
    T->krylov_iters = -1;
    if (!BP__TUTTE_KRYLOV || T->A.symmetric) return 0;
    b = (double *)bp__alloc_array(a, 2 * (size_t)nfree, sizeof(double));
    x = (double *)bp__alloc_array(a, 2 * (size_t)nfree, sizeof(double));
    dg = (double *)bp__alloc_array(a, nfree ? nfree : 1, sizeof(double));
    As.val = (double *)bp__alloc_array(a, T->A.colp[nfree] ? T->A.colp[nfree] : 1, sizeof(double));
    if (b && x && dg && As.val) bp__tutte_scaled(&T->A, T->rhs, runner, As.val, b, dg);   /* rows over diagonals */
    if (!b || !x || !dg || !As.val || !bp__tutte_symmetric(a, &As, &M, runner)) ok = -1;
    else if ((st = bp__tutte_factorize(a, T, &M, &K, &bad, runner)) != BP_OK) ok = st == BP_ERR_OUT_OF_MEMORY ? -1 : 0;
    else if (!K.sn) ok = 0;                           /* (the scalar rows took over: not SPD) */
    else if (!bp__factor_single(a, &K, runner) || !bp__solve_plan(a, &K)) ok = -1;
    else {
        it = bp__tutte_bicgstab(a, &As, &K, runner ? runner : &serial, b, x, &rel);
        if (it == -2) ok = -1;
        if (it > 0) {
            for (i = 0; i < nfree; i++) { T->sol[i] = x[2 * (size_t)i]; T->sol[nfree + i] = x[2 * (size_t)i + 1]; }
            ok = 1;
        }
    }
    T->krylov_iters = it;
    T->krylov_rel = rel;
    bp__factor_free(a, &K);
    bp__free(a, M.colp); bp__free(a, M.row); bp__free(a, M.val);
    bp__free(a, As.val);
    bp__free(a, dg);
    bp__free(a, b);
    bp__free(a, x);
    return ok;
}

/* Phase 6, factor and solve (with iterative refinement); the free
   vertices' uv from the solution.  BP_ERR_NUMERICAL names the vertex of a
   zero pivot. */
static bp_status bp__tutte_solve(const bp_allocator *a, bp__tutte *T, bp_chart *ch, const bp__par *runner,
                                 bp_error *err)
{
    bp__factor F;
    uint32_t bad = 0, i, nfree = T->nfree;
    bp_status st;
    int k;
    memset(&F, 0, sizeof F);
    if (!T->A.symmetric && (k = bp__tutte_krylov(a, T, runner)) != 0) st = k > 0 ? BP_OK : BP_ERR_OUT_OF_MEMORY;
    else {
        st = bp__tutte_factorize(a, T, &T->A, &F, &bad, runner);
        if (st == BP_OK) {
            bp__solve_refined(&T->A, &F, T->rhs, T->sol, T->work);
            bp__solve_refined(&T->A, &F, T->rhs + nfree, T->sol + nfree, T->work);
        }
    }
    if (st == BP_ERR_NUMERICAL) {
        uint32_t bv = 0;
        for (i = 0; i < T->nv; i++) if (T->idx[i] == bad) bv = ch->vertex[i];
        bp__factor_free(a, &F);
        return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_VERTEX, bv, -1, 0,
                        "the start-map system is singular at vertex %u", bv + 1);
    }
    if (st == BP_ERR_TOO_LARGE) {
        bp__factor_free(a, &F);
        return bp__factor_too_large(err, BP__NONE, ch->num_triangles, "start-map system", nfree);
    }
    if (st != BP_OK) { bp__factor_free(a, &F); return bp__oom(err, "computing the start map"); }
    bp__factor_free(a, &F);
    for (i = 0; i < T->nv; i++)
        if (T->idx[i] != BP__NONE) {
            ch->uv[2 * (size_t)i] = T->sol[T->idx[i]];
            ch->uv[2 * (size_t)i + 1] = T->sol[nfree + T->idx[i]];
        }
    return BP_OK;
}

/* Phase 7, the exact check of the rounded start map.  A verdict of
   bp_check other than BP_OK is reported as BP_ERR_NUMERICAL: the start map
   is valid in exact arithmetic (Tutte's theorem), so only rounding can
   break it.  On the start map's runner (NULL: serial). */
static bp_status bp__tutte_verify(const bp_allocator *a, bp_chart *ch, const bp_mesh *m, const bp__par *runner,
                                  bp_error *err)
{
    bp_check_report rep;
    bp_error why;
    char n0[48], n1[48];
    bp__par serial = bp__par_serial();
    bp_status st = bp__check_par(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, a,
                                 runner ? runner : &serial, &rep, &why);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "computing the start map");
    if (!bp__check_verdict_status(st))
        return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_TRIANGLE, ch->face[0], -1, 0,
                        "the start map of the chart with %s could not be checked: %s",
                        bp__tri_name(m, ch->face[0], n0), why.message);
    if (bp__report_valid(&rep)) return BP_OK;
    if (rep.first_bad_triangle >= 0) {
        uint32_t bt = ch->face[rep.first_bad_triangle];
        return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_TRIANGLE, bt, -1, bp__tri_line(m, bt),
                        "the start map of the chart with %s is not valid in floating point: %s is %s",
                        bp__tri_name(m, ch->face[0], n0), bp__tri_name(m, bt, n1),
                        rep.nonfinite ? "not finite" : rep.flipped ? "flipped" : "degenerate");
    }
    if (rep.first_bad_edge[0] >= 0) {
        uint32_t bv = ch->vertex[rep.first_bad_edge[0]];
        return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_VERTEX, bv, -1, 0,
                        "the start map of the chart with %s has touching boundary edges at vertex %u",
                        bp__tri_name(m, ch->face[0], n0), bv + 1);
    }
    return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_TRIANGLE, ch->face[0], -1, 0,   /* loops or the precondition */
                    "the start map of the chart with %s is not valid: %s", bp__tri_name(m, ch->face[0], n0),
                    why.message);
}

/* Start maps with the user's controls (beyond the dissertation).

   Input uvs (BP_INIT_INPUT): the chart's own vt coordinates -- mesh->uvs
   through chart.vertex_uv -- are the start when every chart vertex has
   one and bp_check passes them; then chart.init_used = 1.  Otherwise
   (no vt, or a map that flips, overlaps or pinches) the chart falls back
   to the default map (BP_INIT_AUTO, >>tutte) and init_used = -1.  Nothing else is trusted: the optimizer
   checks its start map again anyway.

   Pins (opt.pins): each names a mesh vertex and a target; every chart
   vertex of that mesh vertex is pinned (a seam vertex has one per chart).
   The targets are first checked against three necessary conditions, each
   exactly (>>predicates): no two pins of one chart at the same point, every
   triangle whose three vertices are pinned counter-clockwise (bp_orient2d
   > 0), and no two pinned boundary edges (both ends pinned, consecutive on
   a loop) meeting other than at a shared end (bp_segments_intersect).  They
   are not sufficient -- pins can still ask for a map that does not exist,
   e.g. a pinned vertex outside the loop its pinned neighbours enclose --
   and the start map below then fails, saying so.

   The start with pins: the free start (Tutte optimized without pins, see
   bp__pins_relax_free; or the input uvs), moved by the similarity
   z -> a z + b that fits the pins best in least squares (complex numbers:
       a = sum (t_i - t_c) conj(z_i - z_c) / sum |z_i - z_c|^2,
       b = t_c - a z_c,
   the c's the centroids; one pin: a = 1, a translation; an input start is
   not moved), and then carried to the targets by the homotopy of >>pins.
   Every map on the way is exactly bijective. */

typedef struct bp__pinkey { uint32_t vertex, uv, pin; } bp__pinkey;

static int bp__pinkey_cmp(const void *pa, const void *pb)
{
    const bp__pinkey *a = (const bp__pinkey *)pa, *b = (const bp__pinkey *)pb;
    if (a->vertex != b->vertex) return a->vertex < b->vertex ? -1 : 1;
    if (a->uv != b->uv) return a->uv < b->uv ? -1 : 1;
    return a->pin < b->pin ? -1 : a->pin > b->pin;
}

/* The pins of one chart: pidx[i] = the index in o->pins of chart vertex
   i's pin, or BP__NONE (*pidx NULL when the chart has none); *count the
   pinned chart vertices.  The list is validated here: a vertex outside the
   mesh, a target not finite, or a vertex pinned twice fail with
   BP_ERR_INVALID_ARGUMENT naming the pin and the vertex (from 1). */
static bp_status bp__pin_map(const bp_allocator *a, const bp_chart *ch, const bp_mesh *m, const bp_options *o,
                             uint32_t **pidx, uint32_t *count, bp_error *err)
{
    bp__pinkey *key;
    uint32_t k, i, np = o ? o->num_pins : 0;
    *pidx = NULL;
    *count = 0;
    if (!np) return BP_OK;
    if (!o->pins) return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "num_pins is %u but pins is NULL", np);
    key = (bp__pinkey *)bp__alloc_array(a, np, sizeof *key);
    if (!key) return bp__oom(err, "reading the pins");
    for (k = 0; k < np; k++) {
        const bp_pin *p = &o->pins[k];
        if (p->vertex >= m->num_vertices || !(p->u - p->u == 0) || !(p->v - p->v == 0) ||
            (p->uv && (!m->corner_uv || p->uv > m->num_uvs))) {
            bp__free(a, key);
            if (p->vertex >= m->num_vertices)
                return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, p->vertex, -1, 0,
                                "pin %u names vertex %u, but the mesh has %u vertices", k + 1, p->vertex + 1,
                                m->num_vertices);
            if (p->uv && (!m->corner_uv || p->uv > m->num_uvs))
                return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, p->vertex, -1, 0,
                                "pin %u (vertex %u) names vt %u, but the mesh has %u", k + 1, p->vertex + 1, p->uv,
                                m->corner_uv ? m->num_uvs : 0);
            return bp__fail(err, BP_ERR_NONFINITE, BP_ELEMENT_VERTEX, p->vertex, -1, 0,
                            "pin %u (vertex %u) has a target that is NaN or infinite", k + 1, p->vertex + 1);
        }
        key[k].vertex = p->vertex;
        key[k].uv = p->uv;
        key[k].pin = k;
    }
    qsort(key, np, sizeof *key, bp__pinkey_cmp);
    for (k = 1; k < np; k++)
        if (key[k].vertex == key[k - 1].vertex && (key[k - 1].uv == 0 || key[k].uv == key[k - 1].uv)) {
            uint32_t v = key[k].vertex, p0 = key[k - 1].pin, p1 = key[k].pin;
            bp__free(a, key);
            return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, v, -1, 0,
                            "vertex %u is pinned twice (pins %u and %u)", v + 1, p0 + 1, p1 + 1);
        }
    for (i = 0; i < ch->num_vertices; i++) {
        uint32_t lo = 0, hi = np, v = ch->vertex[i];
        while (lo < hi) { uint32_t mid = lo + (hi - lo) / 2; if (key[mid].vertex < v) lo = mid + 1; else hi = mid; }
        while (lo < np && key[lo].vertex == v && key[lo].uv != 0 &&
               (!ch->vertex_uv || key[lo].uv - 1 != ch->vertex_uv[i]))
            lo++;                                /* a pin of another side of a seam */
        if (lo == np || key[lo].vertex != v) continue;
        if (!*pidx) {
            *pidx = (uint32_t *)bp__alloc_array(a, ch->num_vertices, sizeof(uint32_t));
            if (!*pidx) { bp__free(a, key); return bp__oom(err, "reading the pins"); }
            for (k = 0; k < ch->num_vertices; k++) (*pidx)[k] = BP__NONE;
        }
        (*pidx)[i] = key[lo].pin;
        (*count)++;
    }
    bp__free(a, key);
    return BP_OK;
}

typedef struct bp__pinpt { double u, v; uint32_t cv; } bp__pinpt;

static int bp__pinpt_cmp(const void *pa, const void *pb)
{
    const bp__pinpt *a = (const bp__pinpt *)pa, *b = (const bp__pinpt *)pb;
    if (a->u != b->u) return a->u < b->u ? -1 : 1;
    if (a->v != b->v) return a->v < b->v ? -1 : 1;
    return a->cv < b->cv ? -1 : a->cv > b->cv;
}

/* The target of pinned chart vertex i. */
static void bp__pin_target(const bp_pin *pins, const uint32_t *pidx, uint32_t i, double t[2])
{
    t[0] = pins[pidx[i]].u;
    t[1] = pins[pidx[i]].v;
}

/* Necessary condition 1: no two pinned chart vertices at one point. */
static bp_status bp__pins_distinct(const bp_allocator *a, const bp_chart *ch, const bp_pin *pins, const uint32_t *pidx,
                                   uint32_t npin, bp_error *err)
{
    bp__pinpt *pt = (bp__pinpt *)bp__alloc_array(a, npin, sizeof *pt);
    uint32_t i, n = 0;
    if (!pt) return bp__oom(err, "checking the pins");
    for (i = 0; i < ch->num_vertices; i++)
        if (pidx[i] != BP__NONE) { pt[n].u = pins[pidx[i]].u; pt[n].v = pins[pidx[i]].v; pt[n++].cv = i; }
    qsort(pt, n, sizeof *pt, bp__pinpt_cmp);
    for (i = 1; i < n; i++)
        if (pt[i].u == pt[i - 1].u && pt[i].v == pt[i - 1].v) {
            uint32_t v0 = ch->vertex[pt[i - 1].cv], v1 = ch->vertex[pt[i].cv];
            bp__free(a, pt);
            return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_EDGE, v0, v1, 0,
                            "vertices %u and %u of one chart are pinned to the same point%s", v0 + 1, v1 + 1,
                            v0 == v1 ? " (a pinch vertex, split into one chart vertex per fan)" : "");
        }
    bp__free(a, pt);
    return BP_OK;
}

/* Necessary condition 2: a triangle with three pinned vertices is
   positively oriented at the targets (it cannot move). */
static bp_status bp__pins_triangles(const bp_chart *ch, const bp_mesh *m, const bp_pin *pins, const uint32_t *pidx,
                                    bp_error *err)
{
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        char name[48];
        double p0[2], p1[2], p2[2];
        int o;
        if (pidx[tr[0]] == BP__NONE || pidx[tr[1]] == BP__NONE || pidx[tr[2]] == BP__NONE) continue;
        bp__pin_target(pins, pidx, tr[0], p0);
        bp__pin_target(pins, pidx, tr[1], p1);
        bp__pin_target(pins, pidx, tr[2], p2);
        o = bp_orient2d(p0, p1, p2);
        if (o > 0) continue;
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_TRIANGLE, ch->face[t], -1, bp__tri_line(m, ch->face[t]),
                        "%s, vertices %u %u %u, has all three vertices pinned and the targets are %s: "
                        "it would be %s", bp__tri_name(m, ch->face[t], name), ch->vertex[tr[0]] + 1,
                        ch->vertex[tr[1]] + 1, ch->vertex[tr[2]] + 1, o < 0 ? "clockwise" : "collinear",
                        o < 0 ? "flipped" : "degenerate");
    }
    return BP_OK;
}

/* Necessary condition 3: pinned boundary edges do not meet, except two
   consecutive ones at their shared end (which must not fold back onto
   each other: the far end of one must not lie on the other).  All pairs:
   quadratic in the pinned boundary edges, which are few in practice. */
static bp_status bp__pins_boundary(const bp_allocator *a, const bp_chart *ch, const bp_pin *pins, const uint32_t *pidx,
                                   bp_error *err)
{
    uint32_t L, k, i, j, ne = 0, *e = (uint32_t *)bp__alloc_array(a, 2 * (size_t)ch->loop_start[ch->num_loops] + 2,
                                                                   sizeof(uint32_t));
    if (!e) return bp__oom(err, "checking the pins");
    for (L = 0; L < ch->num_loops; L++)
        for (k = ch->loop_start[L]; k < ch->loop_start[L + 1]; k++) {
            uint32_t va = ch->loop_vertices[k], vb = ch->loop_vertices[k + 1 < ch->loop_start[L + 1] ? k + 1 : ch->loop_start[L]];
            if (pidx[va] != BP__NONE && pidx[vb] != BP__NONE) { e[2 * ne] = va; e[2 * ne + 1] = vb; ne++; }
        }
    for (i = 0; i < ne; i++)
        for (j = i + 1; j < ne; j++) {
            uint32_t a0 = e[2 * i], a1 = e[2 * i + 1], b0 = e[2 * j], b1 = e[2 * j + 1];
            double A0[2], A1[2], B0[2], B1[2];
            int bad;
            bp__pin_target(pins, pidx, a0, A0); bp__pin_target(pins, pidx, a1, A1);
            bp__pin_target(pins, pidx, b0, B0); bp__pin_target(pins, pidx, b1, B1);
            if (a1 == b0) bad = bp_segments_intersect(A0, A1, B1, B1) || bp_segments_intersect(B0, B1, A0, A0);
            else if (b1 == a0) bad = bp_segments_intersect(B0, B1, A1, A1) || bp_segments_intersect(A0, A1, B0, B0);
            else bad = bp_segments_intersect(A0, A1, B0, B1);
            if (bad) {
                uint32_t v0 = ch->vertex[a0], v1 = ch->vertex[a1], v2 = ch->vertex[b0], v3 = ch->vertex[b1];
                bp__free(a, e);
                return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_EDGE, v0, v2, 0,
                                "the pinned boundary edges %u-%u and %u-%u %s at their targets", v0 + 1, v1 + 1,
                                v2 + 1, v3 + 1, (a1 == b0 || b1 == a0) ? "fold onto each other" : "cross");
            }
        }
    bp__free(a, e);
    return BP_OK;
}

/* The input uvs as the start map: 1 used, 0 missing or not bijective (the
   caller falls back to the AUTO map), -1 out of memory. */
static int bp__init_input(const bp_allocator *a, bp_chart *ch, const bp_mesh *m)
{
    uint32_t i;
    bp_check_report rep;
    bp_status st;
    if (!m->uvs || !m->corner_uv || !ch->vertex_uv) return 0;
    for (i = 0; i < ch->num_vertices; i++) {
        uint32_t q = ch->vertex_uv[i];
        if (q == BP__NONE || q >= m->num_uvs) return 0;
        ch->uv[2 * (size_t)i] = m->uvs[2 * (size_t)q];
        ch->uv[2 * (size_t)i + 1] = m->uvs[2 * (size_t)q + 1];
    }
    st = bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, a, &rep, NULL);
    if (st == BP_ERR_OUT_OF_MEMORY) return -1;
    return st == BP_OK;
}

/* The similarity that best fits the pins (see above), applied to the map.
   A rotation and positive scale keep every orientation, so the result is
   bijective up to rounding; it is checked again by the caller. */
static void bp__pins_similarity(bp_chart *ch, const bp_pin *pins, const uint32_t *pidx)
{
    double zc[2] = { 0, 0 }, tc[2] = { 0, 0 }, nr = 0, ni = 0, den = 0, ar = 1, ai = 0;
    uint32_t i, n = 0;
    for (i = 0; i < ch->num_vertices; i++)
        if (pidx[i] != BP__NONE) {
            zc[0] += ch->uv[2 * (size_t)i]; zc[1] += ch->uv[2 * (size_t)i + 1];
            tc[0] += pins[pidx[i]].u; tc[1] += pins[pidx[i]].v;
            n++;
        }
    zc[0] /= n; zc[1] /= n; tc[0] /= n; tc[1] /= n;
    for (i = 0; n > 1 && i < ch->num_vertices; i++)
        if (pidx[i] != BP__NONE) {
            double zr = ch->uv[2 * (size_t)i] - zc[0], zi = ch->uv[2 * (size_t)i + 1] - zc[1];
            double tr = pins[pidx[i]].u - tc[0], ti = pins[pidx[i]].v - tc[1];
            nr += tr * zr + ti * zi;            /* (t) conj(z) */
            ni += ti * zr - tr * zi;
            den += zr * zr + zi * zi;
        }
    if (n > 1 && den > 0 && (nr != 0 || ni != 0) && (nr / den) - (nr / den) == 0 && (ni / den) - (ni / den) == 0) {
        ar = nr / den;
        ai = ni / den;
    }
    for (i = 0; i < ch->num_vertices; i++) {
        double zr = ch->uv[2 * (size_t)i] - zc[0], zi = ch->uv[2 * (size_t)i + 1] - zc[1];
        ch->uv[2 * (size_t)i] = ar * zr - ai * zi + tc[0];
        ch->uv[2 * (size_t)i + 1] = ai * zr + ar * zi + tc[1];
    }
}

/* >>pins, defined after the optimizer it uses. */
static bp_status bp__pins_at_targets(bp_chart *ch, uint32_t chart_index, const bp_mesh *m, const bp_options *opt,
                                     bp_error *err);
static bp_status bp__pins_reach(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                const uint32_t *pidx, bp_error *err);
static bp_status bp__pins_relax_free(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                     bp_error *err);

/* The conformal start's factor handed to Newton's first factorization.
   bp_parameterize makes a chart's start map and optimizes it at once
   (bp__chart_task), so the factor of the conformal system, whose pattern
   (2x2 blocks on the chart's edges) and order (the start map's
   dissection, kept for Newton: bp__tutte_keep_order) are those of
   Newton's first matrix when the barrier adds no pair, need not be freed
   and analysed again: bp__conformal_end moves it here, with its matrix's
   pattern, and bp__newton_factorize refactors it in place when H's
   pattern is that very one (compared entry by entry), else frees it.
   The analysis of one pattern in one order is the same, so are the bits.
   Never held between the public bp_chart_init and bp_chart_optimize (a
   caller may start every chart before optimizing any).  Only the
   conformal map solved in 2x2 blocks has such a factor: one solved by
   the boundary's Schur complement (>>conformal) hands nothing, and
   Newton's first factorization then analyses its pattern itself. */
typedef struct bp__handoff {
    bp__factor F;                 /* F.sn NULL: nothing handed over         */
    uint32_t   n, *colp, *row;    /* the factored matrix's pattern          */
    int        used;              /* set when Newton took F (for tests)     */
} bp__handoff;

static void bp__handoff_free(const bp_allocator *a, bp__handoff *h)
{
    if (!h) return;
    bp__factor_free(a, &h->F);
    bp__free(a, h->colp);
    bp__free(a, h->row);
    memset(h, 0, sizeof *h);
}

/* >>conformal, defined after >>rest, whose rest shapes it uses. */
typedef struct bp__conformal_task {
    const bp__tutte *T;
    const bp_chart *ch;
    const bp_mesh *m;
    bp__sparse *K;
    bp__sparse *L;                /* scalar: the Laplacian's columns instead */
    double *rhs;
    uint32_t *glen;               /* first pass: each column vertex's count */
    const uint32_t *bxp;          /* scalar: a boundary column's place in bxy
                                     (BP__NONE elsewhere)                   */
    double *bxy;                  /* ... and there its xy entries K(2u, 2v+1) */
    uint32_t p[2], nc;
    int scalar;                   /* fill L, bxy and rhs, not K            */
    double d;
} bp__conformal_task;

/* The conformal start in two halves around the dissection (>>conformal):
   bp__conformal_begin sets up the system, whose columns are then filled
   by the loop C->J (bp__conformal_task_run, C->J.nc tasks) beside the
   dissection's root split, and bp__conformal_end factors and solves it in
   that order. */
typedef struct bp__conformal {
    bp__conformal_task J;
    bp__sparse K;                 /* the 2x2 system (n = 2 nv always set;
                                     its arrays only when that solve is
                                     taken: bp__conformal_full)             */
    bp__sparse L;                 /* the Schur complement's way: the scalar
                                     Laplacian, K's xx entries             */
    uint32_t *bxp;                /* its boundary columns' xy entries      */
    double *bxy;
    double *buf;                  /* rhs, then the solve's workspace       */
    int how;                      /* the solve bp__conformal_end took: 1 the
                                     boundary's Schur complement, 2 the
                                     factor in 2x2 blocks (set to 2 before
                                     it: that one, for tests)              */
} bp__conformal;
static int bp__conformal_begin(const bp_allocator *a, const bp__tutte *T, bp_chart *ch, const bp_mesh *m,
                               const bp__par *runner, int any_size, bp__conformal *C);
static void bp__conformal_task_run(void *task, uint32_t c);
static int bp__conformal_end(const bp_allocator *a, bp__conformal *C, bp_chart *ch, const bp_mesh *m,
                             const bp__par *runner, const uint32_t *order, const bp__ndnode *tree, bp__handoff *h);
static void bp__conformal_free(const bp_allocator *a, bp__conformal *C);
#ifndef BP__INIT_AUTO_CONFORMAL
#define BP__INIT_AUTO_CONFORMAL 1       /* 0: BP_INIT_AUTO starts barycentric, as before >>conformal */
#endif

/* >>start, defined after the optimizer it uses. */
static int bp__start_thin_eps(const bp_allocator *a, const bp_chart *ch, const double *wxy, double *eps);
static int bp__start_planar(const bp_allocator *a, bp_chart *ch, const bp_mesh *m, const bp__par *par);
static bp_status bp__start_progressive(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                       bp_error *err);
struct bp__opt;
static int bp__start_scale(struct bp__opt *P, double *f, double *ed);
#ifndef BP__START_SCALE
#define BP__START_SCALE 1                /* 0: never enlarge a crushed start (>>start, 4) */
#endif
#ifndef BP__START_SCALE_E0
#define BP__START_SCALE_E0 1e9           /* mean start energy that counts as crushed */
#endif

/* The pins' part of a start map: the three necessary conditions, the fit
   (Tutte starts only) and the homotopy. */
static bp_status bp__pins_start(const bp_allocator *a, bp_chart *ch, const bp_mesh *m, const bp_options *opt,
                                const bp__par *runner, const uint32_t *pidx, bp_error *err)
{
    bp_status st = bp__pins_distinct(a, ch, opt->pins, pidx, ch->num_pins, err);
    if (st == BP_OK) st = bp__pins_triangles(ch, m, opt->pins, pidx, err);
    if (st == BP_OK) st = bp__pins_boundary(a, ch, opt->pins, pidx, err);
    if (st != BP_OK) return st;
    if (ch->init_used != 1) {
        if ((st = bp__pins_relax_free(ch, m, opt, runner, err)) != BP_OK) return st;
        bp__pins_similarity(ch, opt->pins, pidx);
        if ((st = bp__tutte_verify(a, ch, m, runner, err)) != BP_OK) return st;
    }
    return bp__pins_reach(ch, m, opt, runner, pidx, err);
}

/* The seven phases above: the Tutte (mvc = 0) or mean-value (mvc = 1) map
   of the filled chart into ch->uv, exactly checked, or first, with
   conformal (1: below BP__CONFORMAL_MAX triangles, 2: at any size), the
   conformal map of >>conformal when it passes that check (its factor to
   *h when h is not NULL: bp__handoff);
   the ordering of phase 5b kept for Newton (ch->start_order), and which
   map it was in ch->start_map. */
static bp_status bp__tutte_map(const bp_allocator *a, bp_chart *ch, const bp_mesh *m, const bp__par *runner, int mvc,
                               int conformal, bp__handoff *h, bp_error *err)
{
    bp__tutte T;
    bp__ndnode tree[BP__ND_NODES];
    uint32_t *order = (uint32_t *)bp__alloc_array(a, (size_t)ch->num_vertices + 6 * BP__ND_NODES, sizeof(uint32_t));
    bp_status st = BP_OK;
    bp__conformal C;
    bp__loop cols;
    bp__tutte_task WJ;
    int done = 0, cf = 0, wpre = 0; /* cf 1: the conformal system is set up;
                                      wpre 1: the weights beside the order */
    memset(&T, 0, sizeof T);
    memset(&C, 0, sizeof C);
    if (runner) T.par = *runner;
    bp__free(a, ch->start_order);
    ch->start_order = NULL;
    if (!order || !bp__tutte_fill(a, &T, ch, m) || !bp__tutte_adjacency(a, &T))
        st = bp__oom(err, "computing the start map");
    if (st == BP_OK && conformal && (cf = bp__conformal_begin(a, &T, ch, m, runner, conformal == 2, &C)) < 0)
        st = bp__oom(err, "computing the start map");
    cols.fn = bp__conformal_task_run;               /* its columns, beside the root split */
    cols.task = &C.J;
    cols.count = cf == 1 ? C.J.nc : 0;
    if (st == BP_OK && cf != 1 && !(wpre = bp__tutte_weights_loop(a, &T, mvc, &WJ, &cols)))
        st = bp__oom(err, "computing the start map");   /* no conformal try: the weights beside it */
    if (st == BP_OK &&
        (!bp__tutte_order(a, &T, runner, &cols) || !bp__tutte_chart_order(a, &T, order, tree)))
        st = bp__oom(err, "computing the start map");
    if (st == BP_OK && cf == 1 && (done = bp__conformal_end(a, &C, ch, m, runner, order, tree, h)) < 0)
        st = bp__oom(err, "computing the start map");
    bp__conformal_free(a, &C);
    if (st == BP_OK && !done) {
        if ((!wpre && !bp__tutte_weights(a, &T, mvc)) || !bp__tutte_circle(a, &T, ch) ||
            (T.nfree > 0 && !bp__tutte_system(a, &T, ch, mvc)))
            st = bp__oom(err, "computing the start map");
        if (st == BP_OK && T.nfree > 0) st = bp__tutte_solve(a, &T, ch, runner, err);
        if (st == BP_OK) st = bp__tutte_verify(a, ch, m, runner, err);
    }
    if (st == BP_OK) {
        bp__tutte_keep_order(&T, order, tree, ch);
        order = NULL;
        ch->start_map = done ? BP_INIT_CONFORMAL : mvc ? BP_INIT_MEAN_VALUE : BP_INIT_TUTTE;
    }
    bp__free(a, order);
    bp__tutte_free(a, &T);
    return st;
}

/* The start map: the input uvs (BP_INIT_INPUT), or a planar chart's own
   projection (>>start, 1), or the seven phases above, optionally relaxed
   by progressive references (>>start, 3); then the pins. */
static bp_status bp__chart_init(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                bp__handoff *h, bp_error *err)
{
    bp_allocator a = bp__allocator_of(opt);
    bp_status st = BP_OK;
    uint32_t *pidx = NULL;
    int tutte = opt && opt->init == BP_INIT_TUTTE, better = !opt || opt->start != BP_START_PLAIN, planar = 0;
    int conformal = opt && opt->init == BP_INIT_CONFORMAL ? 2 :         /* by name: at any size */
                    BP__INIT_AUTO_CONFORMAL && (!opt || (opt->init != BP_INIT_MEAN_VALUE && opt->init != BP_INIT_TUTTE));
                                                                /* (any other value acts as AUTO) */
    if (ch && ch->error.status != BP_OK) {
        if (err) *err = ch->error;
        return ch->error.status;                 /* a chart that cannot be flattened */
    }
    if (!ch || !m || !ch->num_loops)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_chart_init needs a chart from bp_atlas_build and its mesh");
    if (!ch->uv) ch->uv = (double *)bp__alloc_array(&a, 2 * (size_t)ch->num_vertices, sizeof(double));
    if (!ch->uv) return bp__oom(err, "computing the start map");
    ch->init_used = 0;
    ch->start_map = BP_INIT_INPUT;
    if ((st = bp__pin_map(&a, ch, m, opt, &pidx, &ch->num_pins, err)) != BP_OK) return st;
    if (opt && opt->init == BP_INIT_INPUT) {
        int used = bp__init_input(&a, ch, m);
        if (used < 0) st = bp__oom(err, "checking the input map");
        ch->init_used = used > 0 ? 1 : -1;
    }
    if (st == BP_OK && ch->init_used != 1 && better) {                   /* >>start, 1 */
        planar = bp__start_planar(&a, ch, m, runner);
        if (planar < 0) st = bp__oom(err, "checking the planar start map");
        if (planar == 1) ch->start_map = BP_INIT_AUTO;
    }
    if (st == BP_OK && ch->init_used != 1 && planar != 1) {
        st = bp__tutte_map(&a, ch, m, runner, !tutte, tutte ? 0 : conformal, h, err);
        if (st == BP_ERR_NUMERICAL && !tutte && (!opt || opt->init != BP_INIT_MEAN_VALUE))
            st = bp__tutte_map(&a, ch, m, runner, 0, 0, NULL, err);  /* AUTO: rounding spoiled the mean-value map */
        if (st == BP_OK && opt && opt->start == BP_START_PROGRESSIVE && !pidx)
            st = bp__start_progressive(ch, m, opt, runner, err);                /* >>start, 3 */
    }
    if (st == BP_OK && pidx) st = bp__pins_start(&a, ch, m, opt, runner, pidx, err);
    bp__free(&a, pidx);
    if (st != BP_OK) return st;
    ch->stop = BP_STOP_NONE;
    ch->iterations = 0;
    return bp__ok(err);
}

/* The public entry point: the factorization's rows run on the threads of
   opt (a pool for this call) when the chart is large enough to gain
   (BP__PAR_MIN_TRIANGLES, see >>threads). */
static bp_status bp__chart_start(bp_chart *ch, const bp_mesh *m, const bp_options *opt, bp__handoff *h,
                                 bp_error *err)
{
    bp_allocator a = bp__allocator_of(opt);
    void *pool = NULL;
    bp__par par;
    bp_status st;
    if (bp__report(opt, BP_STAGE_START, 0, BP_NO_CHART))
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled before the start map");
    par = bp__par_serial();
    if (ch && ch->num_triangles >= BP__PAR_MIN_TRIANGLES) par = bp__par_begin(&a, opt, &pool);
    st = bp__chart_init(ch, m, opt, &par, h, err);
    bp__par_end(&a, pool);
    if (st == BP_OK) bp__report(opt, BP_STAGE_START, 1, BP_NO_CHART);  /* a cancel here: the next stage sees it */
    return st;
}

BPDEF bp_status bp_chart_init(bp_chart *ch, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status st;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;     /* >>progress */
    return bp__chart_start(ch, m, opt, NULL, err);
}

/* >>rest ===================================================================

   Sec 3.1: each 3D triangle (P1, P2, P3) is flattened isometrically into its
   own plane as F1 = (0, 0), F2 = (w, 0), F3 = (x, y) with
       w = |P2 - P1|,  x = (P2 - P1).(P3 - P1) / w,  y = |(P2 - P1) x (P3 - P1)| / w.
   The map of a triangle to its UV image (U1, U2, U3) has the constant
   Jacobian
       J = [U2 - U1, U3 - U1] [F2 - F1, F3 - F1]^-1 = D M^-1,
       M^-1 = 1/(w y) [ y  -x ]
                      [ 0   w ],
   whose singular values s_max >= s_min measure the stretch (eq 3.1).  Only
   M^-1 and the triangle's area w y / 2 depend on the 3D mesh, so they are
   computed once per solve (the "precomputation" of sec 3.5). */

typedef struct bp__rest {
    double m00, m01, m11;   /* M^-1 = [m00 m01; 0 m11]                    */
    double weight;          /* area / mean area: E_D = sum weight * E_t   */
} bp__rest;

static void bp__rest_shape(const double *p1, const double *p2, const double *p3, double *w,
                           double *x, double *y)
{
    double e1[3], e2[3];
    int k;
    for (k = 0; k < 3; k++) { e1[k] = p2[k] - p1[k]; e2[k] = p3[k] - p1[k]; }
    *w = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    *x = (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / *w;
    *y = bp__area2_3d(p1, p2, p3) / *w;            /* |e1 x e2| / w */
}

/* Degenerate triangles.  A triangle that repeats a vertex or has zero or
   near-zero area (the test of >>charts: twice its area at most 1e-12 of
   the squared mesh size) has no usable rest shape: M is singular or nearly
   so, and E_t would be infinite or dominate the whole chart.  Outside
   strict mode such a triangle is kept (repair, >>charts) and flattened, by
   rule, as the equilateral triangle of the same edge-length scale:
       F1 = (0, 0),  F2 = (s, 0),  F3 = (s/2, s sqrt(3)/2),
   s the mean of its three 3D edge lengths (when all three are zero, the
   mean edge length of the chart's other triangles; chart.rest_side holds
   s).  Its energy is then finite and smallest when the UV triangle is
   equilateral of side s, so the optimizer keeps it open with a positive
   area like any other triangle (the map stays exactly valid, checked as
   always), and its weight (area) is that of the equilateral triangle,
   sqrt(3)/4 s^2, comparable to its neighbours'.  Every other triangle
   keeps its exact 3D shape: a clean mesh is solved bit for bit as before. */
static void bp__chart_rest(const bp_chart *ch, const bp_mesh *m, uint32_t t, double *w, double *x, double *y)
{
    const uint32_t *tr = ch->triangles + 3 * (size_t)t;
    double s = ch->rest_side ? ch->rest_side[t] : 0;
    if (s > 0) {
        *w = s;
        *x = 0.5 * s;
        *y = 0.86602540378443865 * s;              /* sqrt(3)/2 s */
        return;
    }
    bp__rest_shape(bp__pos(m, ch->vertex[tr[0]]), bp__pos(m, ch->vertex[tr[1]]), bp__pos(m, ch->vertex[tr[2]]),
                   w, x, y);
}

/* M^-1 of the flattened triangle (w, x, y) above, scaled by q (1, or the
   I^-1/2 of an importance, eq 4.1): the one place the formula is written.
       q M^-1 = [ q/w   -q x/(w y) ]
                [ 0      q/y       ]
   Leaves r->weight to the caller. */
static void bp__rest_inverse(double w, double x, double y, double q, bp__rest *r)
{
    r->m00 = q / w;
    r->m01 = -q * x / (w * y);
    r->m11 = q / y;
}

/* >>conformal ==============================================================

   A conformal start (beyond the dissertation; issue 15, "a better start").
   The barycentric maps above put the outer loop on a circle, whatever the
   chart's shape: a face or a bust comes out with its rim stretched round
   and its middle crushed (face: mean energy 87, bimba: 674, against
   optima of 7.0 and 7.6), and Newton's first iterations go to undoing
   that.  A map with a free boundary starts nearer.  The least squares
   conformal map (Levy, Petitjean, Ray & Maillot 2002, "LSCM") is one
   linear solve: a triangle's Jacobian J = [a b; c d] (>>rest, J = D M^-1)
   is a similarity exactly when a = d and b = -c, so
       E_C = sum_t A_t ((a - d)^2 + (b + c)^2)
   measures how far the map is from conformal (A_t the 3D area).  Each
   residual is linear in the triangle's six uv coordinates, r = g . U, so
   E_C is a quadratic form with the 6 x 6 blocks A_t (g1 g1^T + g2 g2^T),
   positive semidefinite, on the mesh's pattern in 2x2 blocks: the same
   pattern as Newton's matrix, factored by the same supernodal Cholesky
   after the same dissection (phase 5b's, restricted to the chart's
   vertices) -- or, on a chart with few boundary vertices, reduced to
   the boundary first (the boundary's Schur complement, below: a scalar
   factor, a small dense system).  E_C is zero on every similarity, so two vertices are held:
   the two boundary vertices furthest apart in 3D (the second of two
   sweeps: the vertex furthest from the first loop's first vertex, then
   the one furthest from it), at (0, 0) and (d, 0), d their 3D distance.
   Their rows and columns are the identity's and their couplings go to
   the right-hand side, which leaves the matrix positive definite on a
   connected chart.
       K U = b (one solve, not refined: the map only has to be a good
       start, and the exact check below has the last word),
       then U <- s U,   s^4 = sum A_t |J|^2 / det(J)^2 / sum A_t |J|^2,
   the scale that minimizes the symmetric Dirichlet energy of the map
   (E(s) = s^2 a + b / s^2 over the chart: a conformal map shrinks
   protrusions, and the area-preserving scale leaves them crushed: face
   112 against 30 at the optimal scale); the other energies are either
   blind to the scale (conformal, MIPS) or weigh stretch against
   compression alike (isometric), so the same s serves them.

   Nothing guarantees that the result is bijective: LSCM can fold a
   triangle or run the boundary over itself on a chart that curls (of
   ../shared/meshes, camel_b, shark, horse_cut and lucy fold).  So the
   scaled map goes through the exact check (bp__check_par), and only a map
   that passes it is kept; otherwise the barycentric map of >>tutte is
   computed as before, from the same graph and the same dissection, and
   the attempt has cost one factorization.  Measured (docs/performance.md
   sec 6.27, one thread, to SCAF's energy): face 0.85 -> 0.73 s, bimba
   3.00 -> 2.10 s, face_holes 0.049 -> 0.035 s, hilbert's conformal map an
   isometry (no iteration left), the 4,740-chart atlas 2.6 -> 1.5 s; the
   charts whose map folds 2-6% slower.  Charts of BP__CONFORMAL_MAX
   triangles and more skip it under BP_INIT_AUTO: the 2x2 factor needs
   four times the memory of the barycentric map's scalar one, and the
   million-face chart must stay under 1 KiB per face (docs/performance.md
   sec 6.27 measures both choices: the 132K chart would be 30% faster at
   1.27 KiB per face instead of 0.76); BP_INIT_CONFORMAL asked by name
   tries it at any size.  The map depends only on the chart (the sums of each
   entry run over the corners in triangle order, gathered per vertex like
   the phases above), so it is the same bits on any number of threads. */

#ifndef BP__CONFORMAL_MAX
#define BP__CONFORMAL_MAX 100000u       /* triangles: larger charts start barycentric */
#endif

/* The residuals r1 = a - d and r2 = b + c of chart triangle t as rows
   g1, g2 over (U1x, U1y, U2x, U2y, U3x, U3y), from J = D M^-1 (>>rest):
       a = m00 (U2x - U1x),            c = m00 (U2y - U1y),
       b = m01 (U2x - U1x) + m11 (U3x - U1x),
       d = m01 (U2y - U1y) + m11 (U3y - U1y).
   Returns the triangle's area (0 when its rest shape is not usable: the
   triangle then adds nothing). */
static double bp__conformal_rows(const bp_chart *ch, const bp_mesh *m, uint32_t t, double *g1, double *g2)
{
    double w, x, y, area;
    bp__rest r;
    bp__chart_rest(ch, m, t, &w, &x, &y);
    area = 0.5 * w * y;
    if (!(area > 0) || !(area < HUGE_VAL)) return 0;
    bp__rest_inverse(w, x, y, 1, &r);
    g1[0] = -r.m00;          g1[1] = r.m01 + r.m11; g1[2] = r.m00; g1[3] = -r.m01; g1[4] = 0;     g1[5] = -r.m11;
    g2[0] = -r.m01 - r.m11;  g2[1] = -r.m00;        g2[2] = r.m01; g2[3] = r.m00;  g2[4] = r.m11; g2[5] = 0;
    return area;
}

/* The two held vertices (see above) and their distance; 0 when the
   boundary has no two distinct points. */
static int bp__conformal_pins(const bp_chart *ch, const bp_mesh *m, uint32_t *p0, uint32_t *p1, double *d)
{
    uint32_t j, j0 = ch->loop_start[0], j1 = ch->loop_start[ch->num_loops], from = ch->loop_vertices[j0], far = from;
    int sweep;
    for (sweep = 0; sweep < 2; sweep++) {
        double best = 0;
        from = far;
        for (j = j0; j < j1; j++) {
            double e = bp__dist3(bp__pos(m, ch->vertex[from]), bp__pos(m, ch->vertex[ch->loop_vertices[j]]));
            if (e > best) { best = e; far = ch->loop_vertices[j]; }
        }
        *d = best;
    }
    *p0 = from;
    *p1 = far;
    return *d > 0 && *d < HUGE_VAL && from != far;
}

/* The place of vertex u in column vertex v's block pattern (v and its
   chart neighbours, increasing): v's sorted neighbours below u
   (bp__adj_find; the hole centres, numbered last, are never below a chart
   vertex), plus v itself when it is below u. */
static uint32_t bp__conformal_pos(const bp__tutte *T, uint32_t v, uint32_t u)
{
    return bp__adj_find(T->adjp, T->adj, v, u) - T->adjp[v] + (v < u);
}

/* The rows of column vertex v's pattern, increasing: v and its chart
   neighbours, each as bs rows bs u .. bs u + bs - 1 (bs 1: L's column v;
   2: K's column 2v, and 2v + 1 the same). */
static void bp__conformal_col_rows(const bp__tutte *T, uint32_t v, uint32_t bs, uint32_t *out)
{
    uint32_t e, w = 0, b;
    int dv = 0;
    for (e = T->adjp[v]; e <= T->adjp[v + 1]; e++) {
        uint32_t u = e < T->adjp[v + 1] ? T->adj[e] : BP__NONE;
        if (!dv && u > v) { for (b = 0; b < bs; b++) out[w++] = bs * v + b; dv = 1; }
        if (u < T->nv) for (b = 0; b < bs; b++) out[w++] = bs * u + b;
    }
}

/* Corner q of the incidence lists: its triangle *t, its corner *k, and
   t's residual rows and area (bp__conformal_rows); 0 for a corner that
   adds nothing (a hole's fan, a rest shape not usable). */
static int bp__conformal_corner(const bp__conformal_task *J, uint32_t q, uint32_t *t, uint32_t *k, double *g1,
                                double *g2, double *area)
{
    *t = J->T->inc[q] / 3;
    *k = J->T->inc[q] % 3;
    if (*t >= J->ch->num_triangles) return 0;                       /* a hole's fan */
    return (*area = bp__conformal_rows(J->ch, J->m, *t, g1, g2)) > 0;
}

/* A held vertex's right-hand side: (d, 0) at the far one, (0, 0) at the
   origin (its column is the identity's). */
static void bp__conformal_held_rhs(const bp__conformal_task *J, uint32_t v)
{
    J->rhs[2 * v] = v == J->p[1] ? J->d : 0;
    J->rhs[2 * v + 1] = 0;
}

/* Column v of the scalar Laplacian L (J->scalar: the Schur complement's
   way, which reads nothing else of K): rows v and its chart neighbours,
   increasing, and each value K's xx entry (2u, 2v), the very terms in the
   very order of bp__conformal_task_run's below (so the same bits); for a
   boundary column also K's xy entries (2u, 2v+1), the only ones of K's
   other three blocks the Schur complement needs (bp__cschur_system); the
   right-hand side as there.  A quarter of K's entries (face: 2.2 of 8.7
   MB, 1,600 fewer pages touched) and of its products. */
static void bp__conformal_scalar_col(bp__conformal_task *J, uint32_t v)
{
    const bp__tutte *T = J->T;
    bp__sparse *L = J->L;
    uint32_t c0 = L->colp[v], len = L->colp[v + 1] - c0, q, t, k, r;
    double *xy = J->bxp[v] != BP__NONE ? J->bxy + J->bxp[v] : NULL, g1[6], g2[6], area;
    bp__conformal_col_rows(T, v, 1, L->row + c0);
    memset(L->val + c0, 0, len * sizeof(double));
    if (xy) memset(xy, 0, len * sizeof(double));
    if (v == J->p[0] || v == J->p[1]) {                              /* held: the identity's column */
        L->val[c0 + bp__conformal_pos(T, v, v)] = 1;
        bp__conformal_held_rhs(J, v);
        return;
    }
    for (q = T->incp[v]; q < T->incp[v + 1]; q++) {
        if (!bp__conformal_corner(J, q, &t, &k, g1, g2, &area)) continue;
        for (r = 0; r < 3; r++) {
            uint32_t u = T->tri[3 * (size_t)t + r], p = bp__conformal_pos(T, v, u);
            double hxx = area * (g1[2 * r] * g1[2 * k] + g2[2 * r] * g2[2 * k]);
            double hxy = area * (g1[2 * r] * g1[2 * k + 1] + g2[2 * r] * g2[2 * k + 1]);
            if (u == J->p[1]) { J->rhs[2 * v] -= hxx * J->d; J->rhs[2 * v + 1] -= hxy * J->d; }
            else if (u != J->p[0]) {
                L->val[c0 + p] += hxx;
                if (xy) xy[p] += hxy;
            }
        }
    }
}

/* Vertex chunk c: with J->glen, the number of vertices in each column's
   block pattern (the vertex and its chart neighbours); with J->scalar,
   the columns of L (above); else the
   columns 2v, 2v+1 themselves (rows 2u, 2u+1 for each u in increasing
   order, as Newton's matrix) and their values: each corner of v in
   increasing corner number (so triangle order: the same sums on any
   schedule) adds its triangle's blocks (r, k), k v's corner; a held
   vertex's column is the identity's, and a held neighbour's block goes to
   the right-hand side. */
static void bp__conformal_task_run(void *task, uint32_t c)
{
    bp__conformal_task *J = (bp__conformal_task *)task;
    const bp__tutte *T = J->T;
    bp__sparse *K = J->K;
    uint32_t v, v1 = bp__chunk_at(T->nv, J->nc, c + 1), e, q, t, k, r;
    double g1[6], g2[6], area;
    for (v = bp__chunk_at(T->nv, J->nc, c); v < v1; v++) {
        uint32_t c0, len, n = 1;
        for (e = T->adjp[v]; e < T->adjp[v + 1]; e++) n += T->adj[e] < T->nv;
        if (J->glen) { J->glen[v] = n; continue; }
        if (J->scalar) { bp__conformal_scalar_col(J, v); continue; }
        c0 = K->colp[2 * v];
        len = 2 * n;
        bp__conformal_col_rows(T, v, 2, K->row + c0);                 /* rows of column 2v, */
        memcpy(K->row + c0 + len, K->row + c0, len * sizeof(uint32_t)); /* and of 2v + 1 */
        memset(K->val + c0, 0, 2 * (size_t)len * sizeof(double));
        if (v == J->p[0] || v == J->p[1]) {                          /* held: the identity's columns */
            uint32_t p = bp__conformal_pos(T, v, v);
            K->val[c0 + 2 * p] = K->val[c0 + len + 2 * p + 1] = 1;
            bp__conformal_held_rhs(J, v);
            continue;
        }
        for (q = T->incp[v]; q < T->incp[v + 1]; q++) {
            if (!bp__conformal_corner(J, q, &t, &k, g1, g2, &area)) continue;
            for (r = 0; r < 3; r++) {
                uint32_t u = T->tri[3 * (size_t)t + r], p = bp__conformal_pos(T, v, u);
                int i, j;
                for (j = 0; j < 2; j++)
                    for (i = 0; i < 2; i++) {
                        double h = area * (g1[2 * r + i] * g1[2 * k + j] + g2[2 * r + i] * g2[2 * k + j]);
                        if (u == J->p[1] && i == 0) J->rhs[2 * v + j] -= h * J->d;
                        else if (u != J->p[0] && u != J->p[1]) K->val[c0 + j * len + 2 * p + i] += h;
                    }
            }
        }
    }
}

/* The runner of the task above over the chart's vertices. */
static void bp__conformal_run(bp__conformal_task *J, const bp__par *par)
{
    J->nc = bp__nchunks(J->T->nv, BP__TUTTE_CHUNK);
    bp__par_run(par, bp__conformal_task_run, J, J->nc, J->T->nv);
}

/* The scale s of the essay for the map in ch->uv: s^4 = sum_t sb_t /
   sum_t sa_t with sa_t = A_t |J_t|^2, sb_t = A_t |J_t|^2 / det(J_t)^2 over
   the triangles of positive finite rest area; 0 when a triangle of the map
   is flipped, degenerate or not finite (the map is then not used), -1 out
   of memory.  The terms in chunks of triangles on the threads (each its
   own), the sums in triangle order after them: the serial loop's bits. */
typedef struct bp__scale_task {
    const bp_chart *ch;
    const bp_mesh *m;
    double *term;                 /* 2 per triangle: sa_t, sb_t (0, 0 when skipped) */
    uint32_t nc;
    int *bad;                     /* per chunk: a triangle not positive      */
} bp__scale_task;

static void bp__scale_run(void *task, uint32_t c)
{
    const bp__scale_task *J = (const bp__scale_task *)task;
    const bp_chart *ch = J->ch;
    uint32_t t, t1 = bp__chunk_at(ch->num_triangles, J->nc, c + 1);
    J->bad[c] = 0;
    for (t = bp__chunk_at(ch->num_triangles, J->nc, c); t < t1; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        const double *u1 = ch->uv + 2 * (size_t)tr[0], *u2 = ch->uv + 2 * (size_t)tr[1], *u3 = ch->uv + 2 * (size_t)tr[2];
        double w, x, y, area, a, b, cc, d, det, *o = J->term + 2 * (size_t)t;
        bp__rest r;
        o[0] = o[1] = 0;
        bp__chart_rest(ch, J->m, t, &w, &x, &y);
        area = 0.5 * w * y;
        if (!(area > 0) || !(area < HUGE_VAL)) continue;
        bp__rest_inverse(w, x, y, 1, &r);
        a = (u2[0] - u1[0]) * r.m00;
        b = (u2[0] - u1[0]) * r.m01 + (u3[0] - u1[0]) * r.m11;
        cc = (u2[1] - u1[1]) * r.m00;
        d = (u2[1] - u1[1]) * r.m01 + (u3[1] - u1[1]) * r.m11;
        det = a * d - b * cc;
        if (!(det > 0)) { J->bad[c] = 1; return; }
        o[0] = area * (a * a + b * b + cc * cc + d * d);
        o[1] = area * (a * a + b * b + cc * cc + d * d) / (det * det);
    }
}

static double bp__conformal_scale(const bp_allocator *al, const bp_chart *ch, const bp_mesh *m, const bp__par *par)
{
    bp__scale_task J;
    double sa = 0, sb = 0, s;
    uint32_t t, c;
    J.ch = ch;
    J.m = m;
    J.nc = bp__nchunks(ch->num_triangles, BP__TRI_CHUNK);
    J.term = (double *)bp__alloc_array(al, 2 * (size_t)ch->num_triangles + 1, sizeof(double));
    J.bad = (int *)bp__alloc_array(al, (size_t)J.nc + 1, sizeof(int));
    if (!J.term || !J.bad) { bp__free(al, J.term); bp__free(al, J.bad); return -1; }
    bp__par_run(par, bp__scale_run, &J, J.nc, ch->num_triangles);
    for (c = 0; c < J.nc && !J.bad[c]; c++) {}
    for (t = 0; c == J.nc && t < ch->num_triangles; t++) {   /* adding 0 for a skipped one changes nothing */
        sa += J.term[2 * (size_t)t];
        sb += J.term[2 * (size_t)t + 1];
    }
    bp__free(al, J.term);
    bp__free(al, J.bad);
    if (c < J.nc) return 0;
    s = sqrt(sqrt(sb / sa));
    return s > 0 && s < HUGE_VAL ? s : 0;
}

/* The boundary's Schur complement (beyond Levy et al.; issue 15, a
   cheaper start).  Expand a triangle's residuals:
       (a - d)^2 + (b + c)^2 = |J|^2 - 2 det J,
   so E_C = sum_t A_t |J_t|^2 - 2 sum_t A_t det J_t: the Dirichlet energy
   of x and of y, each the same scalar Laplacian L (the xx and the yy
   blocks of K are sums of the same two products per triangle; L is
   taken from the xx ones), minus twice the map's signed area (A_t det
   J_t is triangle t's area in the plane), and the area is a sum over the
   boundary's edges alone (Green: half the sum of x_i y_j - x_j y_i along
   the loops).  So K
   couples x with y only between boundary vertices; inside, its xy entries
   are the rounding of terms that cancel across every interior edge.
   Order the interior vertices I first (the chart's dissection without
   the boundary) and the free boundary vertices B last, as the root's
   separator; factor the scalar L = R R^T; the trailing block R_BB of R
   gives L's Schur complement on the boundary, S = R_BB R_BB^T (the
   interior eliminated), and with C = K's xy entries between boundary
   vertices, K's whole system reduces to the dense one on B,
       [S C; C^T S] (x_B, y_B) = (S u_B, S w_B),   u = L^-1 b_x, w = L^-1 b_y,
   (since (L^-1)_BB = S^-1), after which x = L^-1 (b_x - C y_B) and
   y = L^-1 (b_y - C^T x_B), the corrections on the boundary rows only.
   One scalar factorization of nv columns, a dense one of 2 |B|, and two
   scalar solves with two right-hand sides each (bp__super_solve_n)
   replace the factorization in 2x2 blocks, which costs
   eight times the scalar one's multiply-adds: face's start map, with 96
   boundary vertices, measured in docs/performance.md sec 6.32.  The dense
   parts grow as |B|^3, so charts with more than BP__CONFORMAL_SCHUR_K
   sqrt(nv) boundary vertices keep the 2x2 factorization (of
   ../shared/meshes: face, bimba and camelhead go this way; hilbert,
   face_holes and the many-loop charts the other).  The map solves the same
   least squares problem (the interior xy terms taken as the zeros they
   are), so it goes through the same scale and the same exact check.
   Since this way reads only L, C and the right-hand side, the columns'
   pass writes just those when it will be taken (bp__conformal_scalar_col,
   the same values), and K itself is built only for the 2x2 solve
   (bp__conformal_full). */
#ifndef BP__CONFORMAL_SCHUR
#define BP__CONFORMAL_SCHUR 1           /* 0: always the factorization in 2x2 blocks */
#endif
#ifndef BP__CONFORMAL_SCHUR_K
#define BP__CONFORMAL_SCHUR_K 2.5       /* boundary vertices at most this times sqrt(nv) */
#endif

typedef struct bp__cschur {
    uint32_t nv, ni, nb;          /* vertices, interior (and held), free boundary */
    uint32_t *bidx;               /* nv: v's place among B, BP__NONE inside  */
    uint32_t *ord, *bv;           /* the order (B last), B's vertices        */
    bp__ndnode tree[BP__ND_NODES];
    bp__sparse L;                 /* K's xx entries: the scalar Laplacian    */
    bp__factor F, FB;             /* L's factor; the dense system's          */
    bp__sparse KB;                /* [S C; C^T S] in 2x2 blocks, dense       */
    double *R, *Cx;               /* nb x nb: R_BB then S, by rows; C        */
    double *work;                 /* 6 nv + 6 nb: (u, w), the solves' work,
                                     the corrected right side (each x y per
                                     vertex); the dense system's right
                                     side, solution and work              */
} bp__cschur;

static void bp__cschur_free(const bp_allocator *a, bp__cschur *Z)
{
    bp__free(a, Z->bidx); bp__free(a, Z->ord); bp__free(a, Z->bv);
    bp__free(a, Z->L.colp); bp__free(a, Z->L.row); bp__free(a, Z->L.val);
    bp__factor_free(a, &Z->F); bp__factor_free(a, &Z->FB);
    bp__free(a, Z->KB.colp); bp__free(a, Z->KB.row); bp__free(a, Z->KB.val);
    bp__free(a, Z->R); bp__free(a, Z->Cx); bp__free(a, Z->work);
    memset(Z, 0, sizeof *Z);
}

/* B (the loops' vertices but the two held ones) in Z->bidx and its size;
   the order: the dissection's with B moved to the end (in the order's
   sequence), its tree with the root's range stretched over B. */
static void bp__cschur_order(bp__cschur *Z, const bp_chart *ch, const uint32_t *held, const uint32_t *order,
                             const bp__ndnode *tree)
{
    uint32_t j, k, v, m = 0;
    for (v = 0; v < Z->nv; v++) Z->bidx[v] = BP__NONE;
    for (j = ch->loop_start[0]; j < ch->loop_start[ch->num_loops]; j++) {
        v = ch->loop_vertices[j];
        if (v != held[0] && v != held[1]) Z->bidx[v] = 0;
    }
    for (k = 0; k < Z->nv; k++) {                 /* the interior, pre[k] in bv */
        Z->bv[k] = m;
        if (Z->bidx[order[k]] == BP__NONE) Z->ord[m++] = order[k];
    }
    Z->ni = m;
    memset(Z->tree, 0, sizeof Z->tree);
    for (k = 0; k < BP__ND_NODES; k++) {
        if (!tree[k].used) continue;
        Z->tree[k] = tree[k];
        Z->tree[k].lo = tree[k].lo < Z->nv ? Z->bv[tree[k].lo] : m;
        Z->tree[k].a = tree[k].a < Z->nv ? Z->bv[tree[k].a] : m;
        Z->tree[k].b = tree[k].b < Z->nv ? Z->bv[tree[k].b] : m;
        Z->tree[k].hi = tree[k].hi < Z->nv ? Z->bv[tree[k].hi] : m;
    }
    if (Z->tree[0].used) Z->tree[0].hi = Z->nv;   /* B in the root's separator */
    for (k = 0; k < Z->nv; k++)                   /* then B */
        if (Z->bidx[order[k]] != BP__NONE) {
            Z->bidx[order[k]] = m - Z->ni;
            Z->bv[m - Z->ni] = order[k];
            Z->ord[m++] = order[k];
        }
}

/* L from K: column v is column 2v's even rows (2u: u's x), halved. */
static int bp__cschur_laplacian(const bp_allocator *a, bp__cschur *Z, const bp__sparse *K)
{
    uint32_t v, i, nnz = K->colp[K->n] / 4;
    Z->L.n = Z->nv;
    Z->L.symmetric = 1;
    Z->L.super1 = 1;
    Z->L.colp = (uint32_t *)bp__alloc_array(a, (size_t)Z->nv + 1, sizeof(uint32_t));
    Z->L.row = (uint32_t *)bp__alloc_array(a, (size_t)nnz + 1, sizeof(uint32_t));
    Z->L.val = (double *)bp__alloc_array(a, (size_t)nnz + 1, sizeof(double));
    if (!Z->L.colp || !Z->L.row || !Z->L.val) return 0;
    for (v = 0; v <= Z->nv; v++) Z->L.colp[v] = K->colp[2 * v] / 4;
    for (v = 0; v < Z->nv; v++) {
        uint32_t c0 = K->colp[2 * v], p = Z->L.colp[v], len = Z->L.colp[v + 1] - p;
        for (i = 0; i < len; i++) {
            Z->L.row[p + i] = K->row[c0 + 2 * i] / 2;
            Z->L.val[p + i] = K->val[c0 + 2 * i];
        }
    }
    return 1;
}

/* Rows [i0, i1) of S = R R^T (task->R: R_BB by rows, into task->S by
   rows, the lower triangle and its mirror): each sum in four lanes added
   in a fixed order, so the same bits in any chunks. */
typedef struct bp__rrt_task { const double *R; double *S; uint32_t nb, nc; } bp__rrt_task;

static void bp__rrt_run(void *task, uint32_t t)
{
    const bp__rrt_task *T = (const bp__rrt_task *)task;
    uint32_t nb = T->nb, i, j, k, i1 = bp__chunk_at(nb, T->nc, t + 1);
    for (i = bp__chunk_at(nb, T->nc, t); i < i1; i++)
        for (j = 0; j <= i; j++) {
            const double *ri = T->R + (size_t)i * nb, *rj = T->R + (size_t)j * nb;
            double q[4] = { 0, 0, 0, 0 };
            for (k = 0; k + 4 <= j + 1; k += 4) {
                q[0] += ri[k] * rj[k]; q[1] += ri[k + 1] * rj[k + 1];
                q[2] += ri[k + 2] * rj[k + 2]; q[3] += ri[k + 3] * rj[k + 3];
            }
            for (; k <= j; k++) q[0] += ri[k] * rj[k];
            T->S[(size_t)i * nb + j] = (q[0] + q[1]) + (q[2] + q[3]);
        }
}

/* R_BB, the trailing nb x nb block of L's factor (B's rows and columns,
   which no interior supernode holds: rows come after columns), into Z->R
   by rows, then S = R_BB R_BB^T in its place (bp__rrt_run, on the
   threads in 16 chunks of rows: the later rows have more terms, and the
   pool deals the chunks out as threads come free). */
static int bp__cschur_complement(const bp_allocator *a, bp__cschur *Z, const bp__par *par)
{
    const bp__super *S = Z->F.sn;
    uint32_t nb = Z->nb, ni = Z->ni, s, i, j, c;
    bp__rrt_task T;
    double *R = (double *)bp__calloc_array(a, (size_t)nb * nb, sizeof(double));
    if (!R) return 0;
    for (s = S->snode[ni]; s < S->ns; s++) {
        uint32_t cs = S->first[s + 1] - S->first[s], mr = S->rp[s + 1] - S->rp[s];
        const uint32_t *rows = S->ri + S->rp[s];
        const double *B = S->x + S->xp[s];
        for (c = S->first[s] < ni ? ni - S->first[s] : 0; c < cs; c++)
            for (i = c; i < mr; i++) R[(size_t)(rows[i] - ni) * nb + (S->first[s] + c - ni)] = B[(size_t)i * cs + c];
    }
    Z->R = (double *)bp__alloc_array(a, (size_t)nb * nb, sizeof(double));
    if (!Z->R) { bp__free(a, R); return 0; }
    T.R = R;
    T.S = Z->R;
    T.nb = nb;
    T.nc = nb < 16 ? 1 : 16;
    bp__par_run(par, bp__rrt_run, &T, T.nc, nb * nb / 2);   /* (items: the entries, not the rows) */
    for (i = 0; i < nb; i++)                            /* the mirror */
        for (j = 0; j < i; j++) Z->R[(size_t)j * nb + i] = Z->R[(size_t)i * nb + j];
    bp__free(a, R);
    return 1;
}

/* Task t: chunk t of the columns of the dense system [S C; C^T S] in 2x2
   blocks (every entry in the pattern).  KB's 2|B| columns are 4.5 MB
   of values and 2.2 MB of rows on bimba, first touched by the thread that
   fills them (one serial pass was 7 ms of a two-thread run). */
typedef struct bp__kb_task { bp__cschur *Z; uint32_t nc; } bp__kb_task;

static void bp__kb_run(void *task, uint32_t t)
{
    const bp__kb_task *T = (const bp__kb_task *)task;
    bp__cschur *Z = T->Z;
    uint32_t nb = Z->nb, n = 2 * nb, i, j, r, j1 = bp__chunk_at(n, T->nc, t + 1);
    for (j = bp__chunk_at(n, T->nc, t); j < j1; j++) {
        double *col = Z->KB.val + (size_t)j * n;
        uint32_t *row = Z->KB.row + (size_t)j * n;
        Z->KB.colp[j] = j * n;
        for (r = 0; r < n; r++) row[r] = r;
        for (i = 0; i < nb; i++) {
            col[2 * i + (j & 1)] = Z->R[(size_t)i * nb + j / 2];                       /* S */
            col[2 * i + 1 - (j & 1)] = j & 1 ? Z->Cx[(size_t)i * nb + j / 2]          /* (x_i, y_j): C */
                                             : Z->Cx[(size_t)(j / 2) * nb + i];       /* (y_i, x_j): C^T */
        }
    }
}

/* C (x of B's vertex i against y of j: K's row 2 bv[i], column
   2 bv[j] + 1) from the y columns of B (xy: those entries kept beside L
   by the columns' pass, bp__conformal_scalar_col; NULL: K's own), and
   the dense system [S C; C^T S] (bp__kb_run, on the threads in 16 column
   chunks). */
static int bp__cschur_system(const bp_allocator *a, bp__cschur *Z, const bp__sparse *K, const uint32_t *bxp,
                             const double *bxy, const bp__par *par)
{
    uint32_t nb = Z->nb, n = 2 * nb, j, p;
    bp__kb_task T;
    Z->Cx = (double *)bp__calloc_array(a, (size_t)nb * nb, sizeof(double));
    Z->KB.colp = (uint32_t *)bp__alloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    Z->KB.row = (uint32_t *)bp__alloc_array(a, (size_t)n * n, sizeof(uint32_t));
    Z->KB.val = (double *)bp__alloc_array(a, (size_t)n * n, sizeof(double));
    if (!Z->Cx || !Z->KB.colp || !Z->KB.row || !Z->KB.val) return 0;
    for (j = 0; j < nb; j++) {
        uint32_t v = Z->bv[j], c0, c1;
        if (bxy) {                                     /* L's pattern, the kept xy entries */
            for (c0 = Z->L.colp[v], p = c0; p < Z->L.colp[v + 1]; p++)
                if (Z->bidx[Z->L.row[p]] != BP__NONE) Z->Cx[(size_t)Z->bidx[Z->L.row[p]] * nb + j] = bxy[bxp[v] + p - c0];
            continue;
        }
        c0 = K->colp[2 * v + 1];
        c1 = K->colp[2 * v + 2];
        for (p = c0; p < c1; p += 2) {
            uint32_t u = K->row[p] / 2;
            if (Z->bidx[u] != BP__NONE) Z->Cx[(size_t)Z->bidx[u] * nb + j] = K->val[p];
        }
    }
    Z->KB.n = n;
    Z->KB.symmetric = 1;
    Z->KB.blocks2 = 1;
    T.Z = Z;
    T.nc = n < 16 ? 1 : 16;
    bp__par_run(par, bp__kb_run, &T, T.nc, n * n);
    Z->KB.colp[n] = n * n;
    return 1;
}

/* The solves above, x and y at once (bp__super_solve_n, two right-hand
   sides): rhs (2 per vertex, x y) to ch->uv. */
static void bp__cschur_solve(bp__cschur *Z, const double *rhs, bp_chart *ch, const bp__par *par)
{
    uint32_t nv = Z->nv, nb = Z->nb, i, j;
    double *uw = Z->work, *z = uw + 2 * (size_t)nv, *b = z + 2 * (size_t)nv;
    double *kb = b + 2 * (size_t)nv, *xb = kb + 2 * (size_t)nb, *zb = xb + 2 * (size_t)nb;
    bp__super_solve_n(&Z->F, rhs, uw, z, par, 2);       /* (u, w) = L^-1 (b_x, b_y) */
    for (i = 0; i < nb; i++) {                          /* (S u_B, S w_B), interleaved */
        const double *si = Z->R + (size_t)i * nb;
        double sx = 0, sy = 0;
        for (j = 0; j < nb; j++) { sx += si[j] * uw[2 * (size_t)Z->bv[j]]; sy += si[j] * uw[2 * (size_t)Z->bv[j] + 1]; }
        kb[2 * i] = sx;
        kb[2 * i + 1] = sy;
    }
    bp__factor_solve_par(&Z->FB, kb, xb, zb, par);      /* (x_B, y_B) interleaved */
    memcpy(b, rhs, 2 * (size_t)nv * sizeof(double));
    for (i = 0; i < nb; i++) {                          /* b_x - C y_B, b_y - C^T x_B */
        double cx = 0, cy = 0;
        for (j = 0; j < nb; j++) {
            cx += Z->Cx[(size_t)i * nb + j] * xb[2 * j + 1];
            cy += Z->Cx[(size_t)j * nb + i] * xb[2 * j];
        }
        b[2 * (size_t)Z->bv[i]] -= cx;
        b[2 * (size_t)Z->bv[i] + 1] -= cy;
    }
    bp__super_solve_n(&Z->F, b, ch->uv, z, par, 2);
}

/* The conformal map (unscaled) into ch->uv by the Schur complement.
   Returns 1, 0 when not taken (too many boundary vertices, a pivot not
   positive: the 2x2 factorization then serves), -1 out of memory. */
static int bp__conformal_schur(const bp_allocator *a, const bp__conformal *C, bp_chart *ch, const bp__par *par,
                               const uint32_t *order, const bp__ndnode *tree)
{
    bp__cschur Z;
    uint32_t nv = C->K.n / 2, bad, k;
    int fallback = 0, ok = -1;
    bp_status st;
    bp__ndnode one[BP__ND_NODES];
    if (!BP__CONFORMAL_SCHUR || !order || !tree) return 0;
    memset(&Z, 0, sizeof Z);
    Z.nv = nv;
    Z.bidx = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    Z.ord = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    Z.bv = (uint32_t *)bp__alloc_array(a, 2 * (size_t)nv + 1, sizeof(uint32_t));   /* B's, then an identity */
    if (!Z.bidx || !Z.ord || !Z.bv) goto done;
    bp__cschur_order(&Z, ch, C->J.p, order, tree);
    Z.nb = nv - Z.ni;
    ok = 0;
    if (Z.nb == 0 || (double)Z.nb > BP__CONFORMAL_SCHUR_K * sqrt((double)nv)) goto done;
    ok = -1;
    Z.work = (double *)bp__alloc_array(a, 6 * (size_t)nv + 6 * (size_t)Z.nb, sizeof(double));
    if (C->J.scalar) Z.L = C->L;                        /* built by the columns' pass: borrowed */
    if (!Z.work || (!C->J.scalar && !bp__cschur_laplacian(a, &Z, &C->K))) goto done;
    st = bp__super_factorize(a, &Z.L, &Z.F, &bad, par, 1, &fallback, Z.ord, Z.tree);
    if (st != BP_OK || fallback) { ok = st == BP_ERR_OUT_OF_MEMORY ? -1 : 0; goto done; }
    if (!bp__cschur_complement(a, &Z, par) ||
        !bp__cschur_system(a, &Z, &C->K, C->J.scalar ? C->bxp : NULL, C->J.scalar ? C->bxy : NULL, par))
        goto done;
    for (k = 0; k < Z.nb; k++) Z.bv[Z.nb + k] = k;      /* the dense system's order */
    memset(one, 0, sizeof one);                         /* one separator: the dense */
    one[0].used = one[0].split = 1;                      /* factor's panels on the threads */
    one[0].hi = Z.nb;
    st = bp__super_factorize(a, &Z.KB, &Z.FB, &bad, par, 2, &fallback, Z.bv + Z.nb, one);
    if (st != BP_OK || fallback) { ok = st == BP_ERR_OUT_OF_MEMORY ? -1 : 0; goto done; }
    bp__cschur_solve(&Z, C->buf, ch, par);
    ok = 1;
done:
    if (C->J.scalar) memset(&Z.L, 0, sizeof Z.L);      /* C's own, freed with C */
    bp__cschur_free(a, &Z);
    return ok;
}

/* K's arrays in 2x2 blocks from L's column lengths (4 entries per
   block, columns 2v and 2v+1 each 2 |column v|).  Returns 0 out of
   memory. */
static int bp__conformal_alloc_k(const bp_allocator *a, bp__conformal *C)
{
    bp__sparse *K = &C->K;
    uint32_t nv = C->L.n, v;
    size_t w = 0;
    K->colp = (uint32_t *)bp__alloc_array(a, 2 * (size_t)nv + 1, sizeof(uint32_t));
    if (!K->colp) return 0;
    for (v = 0; v < nv; v++) {
        uint32_t g = C->L.colp[v + 1] - C->L.colp[v];
        K->colp[2 * v] = (uint32_t)w;
        K->colp[2 * v + 1] = (uint32_t)(w + 2 * (size_t)g);
        w += 4 * (size_t)g;
    }
    K->colp[2 * nv] = (uint32_t)w;
    K->row = (uint32_t *)bp__alloc_array(a, w + 1, sizeof(uint32_t));
    K->val = (double *)bp__alloc_array(a, w + 1, sizeof(double));
    return K->row && K->val;
}

/* Whether bp__conformal_schur will be tried: the free boundary B (the
   loops' vertices but the held two) is not empty and has at most
   BP__CONFORMAL_SCHUR_K sqrt(nv) vertices, the test it makes itself.
   Marks B in bxp (0 there, BP__NONE elsewhere). */
static int bp__conformal_schur_planned(const bp_chart *ch, const uint32_t *held, uint32_t nv, uint32_t *bxp)
{
    uint32_t j, v, nb = 0;
    for (v = 0; v < nv; v++) bxp[v] = BP__NONE;
    for (j = ch->loop_start[0]; j < ch->loop_start[ch->num_loops]; j++) {
        v = ch->loop_vertices[j];
        if (v != held[0] && v != held[1] && bxp[v] == BP__NONE) { bxp[v] = 0; nb++; }
    }
    return BP__CONFORMAL_SCHUR && nb > 0 && (double)nb <= BP__CONFORMAL_SCHUR_K * sqrt((double)nv);
}

/* The 2x2 system after all (asked for, or the Schur complement refused
   it): K's arrays and its columns, the right-hand side again with them
   (the same sums).  Returns 0 out of memory. */
static int bp__conformal_full(const bp_allocator *a, bp__conformal *C, const bp__par *par)
{
    uint32_t i;
    if (C->K.row) return 1;
    if (!bp__conformal_alloc_k(a, C)) return 0;
    for (i = 0; i < C->K.n; i++) C->buf[i] = 0;
    C->J.scalar = 0;
    bp__conformal_run(&C->J, par);
    return 1;
}

/* The conformal map of the chart into ch->uv, scaled, in the order
   (order, tree) of the chart's vertices, in two halves around the
   dissection (bp__tutte_map).  bp__conformal_begin: 0 when the map is not
   tried (too large -- any_size: also at BP__CONFORMAL_MAX triangles and
   more, BP_INIT_CONFORMAL asked by name --, no two boundary points, a
   pattern too big), -1 out of memory, 1 when the system is set up: its
   pattern's column lengths counted (the first pass of C->J), K's arrays
   allocated, and C->J ready for the second pass (the columns and the
   right-hand side), which the caller runs. */
static int bp__conformal_begin(const bp_allocator *a, const bp__tutte *T, bp_chart *ch, const bp_mesh *m,
                               const bp__par *runner, int any_size, bp__conformal *C)
{
    bp__conformal_task *J = &C->J;
    bp__par serial = bp__par_serial();
    const bp__par *par = runner ? runner : &serial;
    uint32_t nv = T->nv, n = 2 * nv, v;
    size_t i;
    memset(C, 0, sizeof *C);
    if ((!any_size && ch->num_triangles >= BP__CONFORMAL_MAX) || !bp__conformal_pins(ch, m, &J->p[0], &J->p[1], &J->d))
        return 0;
    J->T = T;
    J->ch = ch;
    J->m = m;
    J->K = &C->K;
    J->L = &C->L;
    J->glen = (uint32_t *)bp__alloc_array(a, nv, sizeof(uint32_t));
    C->L.colp = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    C->bxp = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    C->buf = (double *)bp__alloc_array(a, 2 * (size_t)n, sizeof(double));
    if (!J->glen || !C->L.colp || !C->bxp || !C->buf) return -1;
    bp__conformal_run(J, par);                               /* the columns' lengths */
    C->L.colp[0] = 0;
    for (v = 0; v < nv; v++) {
        if ((size_t)C->L.colp[v] + J->glen[v] > 0x3ffffffcu) return 0;   /* K's 4x must fit */
        C->L.colp[v + 1] = C->L.colp[v] + J->glen[v];
    }
    C->K.n = n;
    C->K.symmetric = 1;
    C->K.blocks2 = 1;
    C->L.n = nv;
    C->L.symmetric = 1;
    C->L.super1 = 1;
    for (i = 0; i < n; i++) C->buf[i] = 0;
    bp__free(a, J->glen);
    J->glen = NULL;                                          /* the next pass: the columns */
    J->rhs = C->buf;
    if (bp__conformal_schur_planned(ch, J->p, nv, C->bxp)) {
        size_t nxy = 0;
        for (v = 0; v < nv; v++)
            if (C->bxp[v] != BP__NONE) { C->bxp[v] = (uint32_t)nxy; nxy += C->L.colp[v + 1] - C->L.colp[v]; }
        C->L.row = (uint32_t *)bp__alloc_array(a, (size_t)C->L.colp[nv] + 1, sizeof(uint32_t));
        C->L.val = (double *)bp__alloc_array(a, (size_t)C->L.colp[nv] + 1, sizeof(double));
        C->bxy = (double *)bp__alloc_array(a, nxy + 1, sizeof(double));
        if (!C->L.row || !C->L.val || !C->bxy) return -1;
        J->bxp = C->bxp;
        J->bxy = C->bxy;
        J->scalar = 1;
        return 1;
    }
    return bp__conformal_alloc_k(a, C) ? 1 : -1;
}

/* bp__conformal_end, after the columns' pass: the solve, by the
   boundary's Schur complement (above) or else by the factor in 2x2 blocks
   in the order (order, tree) (C->how says which), then the scale and the
   exact check.  Returns 1 when the map passed the check (ch->uv holds it;
   the 2x2 factor to *h when h is not NULL: bp__handoff), 0 when it is not
   used (a pivot or a triangle gone wrong, the check failed: ch->uv is
   then overwritten by the caller), -1 out of memory. */
static int bp__conformal_end(const bp_allocator *a, bp__conformal *C, bp_chart *ch, const bp_mesh *m,
                             const bp__par *runner, const uint32_t *order, const bp__ndnode *tree, bp__handoff *h)
{
    bp__sparse *K = &C->K;
    bp__factor F;
    bp_check_report rep;
    bp__par serial = bp__par_serial();
    const bp__par *par = runner ? runner : &serial;
    uint32_t n = K->n, bad;
    size_t i;
    double *rhs = C->buf, *z = rhs + n, s;
    int ok = -1;
    bp_status st;
    memset(&F, 0, sizeof F);
    if (C->how != 2 && (ok = bp__conformal_schur(a, C, ch, par, order, tree)) < 0) goto done;
    C->how = ok == 1 ? 1 : 2;
    if (C->how == 2) {                                       /* the 2x2 factorization */
        ok = -1;
        if (!bp__conformal_full(a, C, par)) goto done;
        st = bp__factorize_order(a, K, &F, &bad, par, order, tree);
        if (st != BP_OK) { ok = st == BP_ERR_OUT_OF_MEMORY ? -1 : 0; goto done; }
        bp__factor_solve_par(&F, rhs, ch->uv, z, par);
    }
    ok = -1;
    if (!((s = bp__conformal_scale(a, ch, m, par)) > 0)) { ok = s < 0 ? -1 : 0; goto done; }
    for (i = 0; i < n; i++) ch->uv[i] *= s;
    st = bp__check_par(ch->triangles, ch->num_triangles, ch->uv, n / 2, a, par, &rep, NULL);
    ok = st == BP_ERR_OUT_OF_MEMORY ? -1 : bp__check_verdict_status(st) && bp__report_valid(&rep);
    if (ok == 1 && h && F.sn) {                              /* to Newton (bp__handoff) */
        bp__handoff_free(a, h);
        h->F = F; h->n = n; h->colp = K->colp; h->row = K->row;
        memset(&F, 0, sizeof F);
        K->colp = K->row = NULL;
    }
done:
    bp__factor_free(a, &F);
    return ok;
}

static void bp__conformal_free(const bp_allocator *a, bp__conformal *C)
{
    bp__free(a, C->J.glen);
    bp__free(a, C->K.colp); bp__free(a, C->K.row); bp__free(a, C->K.val);
    bp__free(a, C->L.colp); bp__free(a, C->L.row); bp__free(a, C->L.val);
    bp__free(a, C->bxp); bp__free(a, C->bxy);
    bp__free(a, C->buf);
    memset(C, 0, sizeof *C);
}

/* >>energy =================================================================

   Sec 3.2.  Every energy here is a function f(s_max, s_min) of the singular
   values of J, infinite when the triangle degenerates (s_min -> 0), so a
   descent method that never crosses a singularity never flips a triangle.
   The dissertation's own energy (eq 3.1-3.3) is the symmetric Dirichlet
       E_t = s_max^2 + s_min^2 + s_max^-2 + s_min^-2     (minimum 4 at a rotation),
   and the others of fig 3.2 are the conformal s_max/s_min, MIPS
   s_max/s_min + s_min/s_max, isometric sqrt(s_max^2 + s_min^-2) and maximal
   isometric max(s_max, 1/s_min).

   The singular values of a 2x2 J = [a b; c d] have a closed form.  With
       E = (a+d)/2, F = (a-d)/2, G = (c+b)/2, H = (c-b)/2,
       Q = sqrt(E^2 + H^2),   R = sqrt(F^2 + G^2),
   s_max = Q + R and s_min = Q - R = det J / s_max (the second form is the
   accurate one when det J is small).  So any f(s_max, s_min) has gradient
       df/dJ = (f_a + f_b) dQ/dJ + (f_a - f_b) dR/dJ,
       dQ/dJ = [E -H; H E] / (2Q),   dR/dJ = [F G; G -F] / (2R),
   (f_a, f_b the partials in s_max, s_min), and by the chain rule through
   J = D M^-1 the gradient in the UV positions is df/dD = df/dJ M^-T, whose
   columns are the gradients for U2 and U3 (U1 gets minus their sum).  For
   the symmetric Dirichlet energy this equals eq 3.3's closed form (area
   term plus cotangent weights).  At R = 0 (a conformal J) dR/dJ is taken as
   0; f_a - f_b vanishes there for the symmetric energies (symmetric
   Dirichlet, MIPS), whose gradient is therefore continuous.  Conformal,
   isometric and maximal isometric have a kink at s_max = s_min (and the
   last also at s_max s_min = 1): there the code returns one of the two
   one-sided slopes, a valid subgradient for the line search. */

/* f(s_max, s_min) and its partials; returns +inf for s_min <= 0. */
static double bp__energy_sv(bp_energy kind, double sa, double sb, double *fa, double *fb)
{
    double r;
    if (!(sb > 0)) { *fa = *fb = 0; return HUGE_VAL; }
    switch (kind) {
    case BP_ENERGY_CONFORMAL:
        *fa = 1 / sb; *fb = -sa / (sb * sb);
        return sa / sb;
    case BP_ENERGY_MIPS:
        *fa = 1 / sb - sb / (sa * sa); *fb = 1 / sa - sa / (sb * sb);
        return sa / sb + sb / sa;
    case BP_ENERGY_ISOMETRIC:
        r = sqrt(sa * sa + 1 / (sb * sb));
        *fa = sa / r; *fb = -1 / (sb * sb * sb * r);
        return r;
    case BP_ENERGY_MAX_ISOMETRIC:
        if (sa >= 1 / sb) { *fa = 1; *fb = 0; return sa; }
        *fa = 0; *fb = -1 / (sb * sb);
        return 1 / sb;
    default:   /* symmetric Dirichlet */
        *fa = 2 * sa - 2 / (sa * sa * sa);
        *fb = 2 * sb - 2 / (sb * sb * sb);
        return sa * sa + sb * sb + 1 / (sa * sa) + 1 / (sb * sb);
    }
}

/* E_t of one triangle at UV corners u1, u2, u3; if g is given, adds
   weight * dE_t/dU to g1, g2, g3. */
static double bp__triangle_energy(bp_energy kind, const bp__rest *r, const double *u1,
                                  const double *u2, const double *u3, double *g1, double *g2, double *g3)
{
    double d00 = u2[0] - u1[0], d10 = u2[1] - u1[1], d01 = u3[0] - u1[0], d11 = u3[1] - u1[1];
    /* J = D M^-1 with M^-1 upper triangular */
    double a = d00 * r->m00, b = d00 * r->m01 + d01 * r->m11;
    double c = d10 * r->m00, d = d10 * r->m01 + d11 * r->m11;
    double E = 0.5 * (a + d), F = 0.5 * (a - d), G = 0.5 * (c + b), H = 0.5 * (c - b);
    double Q = sqrt(E * E + H * H), R = sqrt(F * F + G * G);
    double det = a * d - b * c, sa = Q + R, sb, fa, fb, e;
    if (!(det > 0)) return HUGE_VAL;
    sb = det / sa;
    e = bp__energy_sv(kind, sa, sb, &fa, &fb);
    if (g1) {
        double kq = (fa + fb) / (2 * Q), kr = R > 0 ? (fa - fb) / (2 * R) : 0;
        /* dE/dJ */
        double ja = kq * E + kr * F, jb = -kq * H + kr * G;
        double jc = kq * H + kr * G, jd = kq * E - kr * F;
        /* dE/dD = dE/dJ M^-T: columns are dE/dU2, dE/dU3 */
        double w = r->weight;
        double gx2 = w * (ja * r->m00 + jb * r->m01), gy2 = w * (jc * r->m00 + jd * r->m01);
        double gx3 = w * (jb * r->m11), gy3 = w * (jd * r->m11);
        g2[0] += gx2; g2[1] += gy2;
        g3[0] += gx3; g3[1] += gy3;
        g1[0] -= gx2 + gx3; g1[1] -= gy2 + gy3;
    }
    return e;
}

/* >>hessian ================================================================

   For Newton's method (>>newton) each E_t also needs its second derivative,
   and a positive semidefinite one, since a Newton step is a descent
   direction only when the matrix it inverts is positive definite.  These
   energies are isotropic -- f(J) depends on J only through its singular
   values -- and for such energies the Hessian in the 4 entries of J has a
   closed-form eigensystem (Smith, de Goes & Kim 2019, "Analytic eigensystems
   for isotropic distortion energies", sec 4-5 in 2D).  Write the SVD as
   J = U diag(s_max, s_min) V^T (det J > 0 here, so no reflection).  Then,
   with f_a, f_b the partials and f_aa, f_ab, f_bb the second partials in
   (s_max, s_min):
     twist   U [0 -1; 1 0] V^T / sqrt2,   lambda = (f_a + f_b) / (s_max + s_min)
     flip    U [0  1; 1 0] V^T / sqrt2,   lambda = (f_a - f_b) / (s_max - s_min)
     scaling U diag(1,0) V^T, U diag(0,1) V^T: the 2x2 block [f_aa f_ab; f_ab f_bb].
   No SVD is needed: with the E, F, G, H, Q, R of >>energy,
       U diag(1,0) V^T + U diag(0,1) V^T = [E -H; H E] / Q      (the rotation part)
       U diag(1,0) V^T - U diag(0,1) V^T = [F G; G -F] / R      (the reflection part)
       twist = [-H -E; E -H] / (sqrt2 Q),   flip = [-G F; F G] / (sqrt2 R),
   four orthonormal 2x2 matrices (at R = 0 any reflection direction serves;
   [1 0; 0 -1] is taken).  The projection onto the positive semidefinite
   cone clamps each of the four eigenvalues (the scaling block after its
   own 2x2 eigen-decomposition) at 0: closed form, no iteration.

   The flip eigenvalue divides by s_max - s_min.  For the symmetric
   energies the quotient has a closed form without the division:
       symmetric Dirichlet: 2 + 2 (s_max^2 + s_max s_min + s_min^2) / (s_max s_min)^3,
       MIPS: 1 / (s_max s_min) + (s_max^2 + s_max s_min + s_min^2) / (s_max s_min)^2.
   Conformal, isometric and maximal isometric have a kink at s_max = s_min
   (see >>energy): their curvature there is infinite, and the code divides
   by max(s_max - s_min, 1e-4 s_max), a finite stand-in for the kink.  The
   maximal isometric energy max(s_max, 1/s_min) is non-smooth also where
   s_max s_min = 1; the Hessian used is that of the active piece (s_max
   alone: zero scaling curvature; 1/s_min alone), exact everywhere off the
   switching set and a generalized Hessian on it.

   The Hessian in the 6 UV coordinates follows from J = D M^-1 being linear
   in them: the x coordinates of the corners move row 0 of J, the y
   coordinates row 1, corner k by the vector g_k (g_2 = (m00, m01),
   g_3 = (0, m11), g_1 = -g_2 - g_3: the rows of M^-1 read as in >>energy),
       d^2 E_t / dU_k,alpha dU_l,beta = weight sum_pq g_k[p] H4(2 alpha + p, 2 beta + q) g_l[q],
   a congruence, so a positive semidefinite H4 gives a positive
   semidefinite 6x6 block.  It is computed by 2x2 blocks (docs/
   performance.md sec 6.9): with B_ab the block H4(2a + p, 2b + q) and
   G = [g_2 g_3], the corners 2 and 3 take M_ab = G^T B_ab G, and corner 1
   follows from g_1 = -g_2 - g_3 by linearity (its rows and columns are
   minus the sums of the others'); M_ba = M_ab^T since H4 is symmetric, so
   three 2x2 congruences make all 36 entries (~60 multiplications instead
   of 288). */

/* Second partials (f_aa, f_ab, f_bb) and the twist and flip eigenvalues of
   one energy at (sa, sb) = (s_max, s_min), given its partials fa, fb. */
static void bp__energy_sv2(bp_energy kind, double sa, double sb, double fa, double fb, double h[3],
                           double *twist, double *flip)
{
    double p = sa * sb, den = sa - sb > 1e-4 * sa ? sa - sb : 1e-4 * sa, r;
    *twist = (fa + fb) / (sa + sb);
    *flip = (fa - fb) / den;
    switch (kind) {
    case BP_ENERGY_CONFORMAL:                     /* sa / sb */
        h[0] = 0; h[1] = -1 / (sb * sb); h[2] = 2 * sa / (sb * sb * sb);
        break;
    case BP_ENERGY_MIPS:                          /* sa / sb + sb / sa */
        h[0] = 2 * sb / (sa * sa * sa); h[1] = -1 / (sb * sb) - 1 / (sa * sa); h[2] = 2 * sa / (sb * sb * sb);
        *flip = 1 / p + (sa * sa + p + sb * sb) / (p * p);
        break;
    case BP_ENERGY_ISOMETRIC:                     /* r = sqrt(sa^2 + sb^-2) */
        r = sqrt(sa * sa + 1 / (sb * sb));
        h[0] = 1 / (sb * sb * r * r * r);
        h[1] = sa / (sb * sb * sb * r * r * r);
        h[2] = 3 / (sb * sb * sb * sb * r) - 1 / (sb * sb * sb * sb * sb * sb * r * r * r);
        break;
    case BP_ENERGY_MAX_ISOMETRIC:                 /* the active piece */
        h[0] = h[1] = 0;
        h[2] = sa >= 1 / sb ? 0 : 2 / (sb * sb * sb);
        break;
    default:                                      /* symmetric Dirichlet */
        h[0] = 2 + 6 / (sa * sa * sa * sa); h[1] = 0; h[2] = 2 + 6 / (sb * sb * sb * sb);
        *flip = 2 + 2 * (sa * sa + p + sb * sb) / (p * p * p);
        break;
    }
}

/* What both Hessians below need of J (the essay above): its rotation and
   reflection parts E, F, G, H and their norms Q, R, the twist and flip
   eigenvalues, the scaling block hs = [f_aa f_ab; f_ab f_bb] with its
   eigenvalues l1 >= l2 (t their half difference) and, when t > 0, the
   better conditioned of the two unnormalized eigenvectors of l1,
   (h1, l1 - h0) or (l1 - h2, h1), as (x, y).  Returns 0 when J is not
   positively oriented. */
typedef struct bp__jeig {
    double E, F, G, H, Q, R, tw, fl, hs[3], t, l1, l2, x, y;
} bp__jeig;

static int bp__hessian_eig(bp_energy kind, const double J[4], bp__jeig *e)
{
    double a = J[0], b = J[1], c = J[2], d = J[3], det = a * d - b * c, sa, sb, fa, fb;
    e->E = 0.5 * (a + d); e->F = 0.5 * (a - d); e->G = 0.5 * (c + b); e->H = 0.5 * (c - b);
    e->Q = sqrt(e->E * e->E + e->H * e->H);
    e->R = sqrt(e->F * e->F + e->G * e->G);
    if (!(det > 0)) return 0;
    sa = e->Q + e->R;
    sb = det / sa;
    bp__energy_sv(kind, sa, sb, &fa, &fb);
    bp__energy_sv2(kind, sa, sb, fa, fb, e->hs, &e->tw, &e->fl);
    e->t = sqrt(0.25 * (e->hs[0] - e->hs[2]) * (e->hs[0] - e->hs[2]) + e->hs[1] * e->hs[1]);
    e->l1 = 0.5 * (e->hs[0] + e->hs[2]) + e->t;
    e->l2 = 0.5 * (e->hs[0] + e->hs[2]) - e->t;
    if (e->t > 0) {
        double x1 = e->hs[1], y1 = e->l1 - e->hs[0], x2 = e->l1 - e->hs[2], y2 = e->hs[1];
        if (x1 * x1 + y1 * y1 >= x2 * x2 + y2 * y2) { e->x = x1; e->y = y1; } else { e->x = x2; e->y = y2; }
    } else { e->x = 1; e->y = 0; }
    return 1;
}

/* The 4x4 Hessian of f(J) in J's entries (a, b, c, d) = (J00, J01, J10,
   J11), row major into h4; with `project`, its positive semidefinite
   projection.  Returns 0 when J is not positively oriented. */
static int bp__hessian_j(bp_energy kind, const double J[4], int project, double h4[16])
{
    double rot[4], ref[4], m[4][4], lam[4], s2 = sqrt(0.5), c1, c2, hv, out[16];
    bp__jeig e;
    int i, j, k;
    if (!bp__hessian_eig(kind, J, &e)) return 0;
    rot[0] = e.E / e.Q; rot[1] = -e.H / e.Q; rot[2] = e.H / e.Q; rot[3] = e.E / e.Q;
    if (e.R > 0) { ref[0] = e.F / e.R; ref[1] = e.G / e.R; ref[2] = e.G / e.R; ref[3] = -e.F / e.R; }
    else { ref[0] = 1; ref[1] = 0; ref[2] = 0; ref[3] = -1; }
    /* twist and flip: [-H -E; E -H] / Q and [-G F; F G] / R, over sqrt2 */
    m[0][0] = -rot[2] * s2; m[0][1] = -rot[0] * s2; m[0][2] = rot[0] * s2; m[0][3] = -rot[2] * s2;
    m[1][0] = -ref[1] * s2; m[1][1] = ref[0] * s2; m[1][2] = ref[0] * s2; m[1][3] = ref[1] * s2;
    lam[0] = e.tw; lam[1] = e.fl;
    /* the scaling block in the basis D1 = (rot + ref) / 2, D2 = (rot - ref) / 2:
       eigenvalues l1 >= l2, the unit eigenvector (c1, c2) of l1 */
    c1 = e.x; c2 = e.y;
    if (e.t > 0) {
        hv = sqrt(c1 * c1 + c2 * c2);
        c1 /= hv; c2 /= hv;
    }
    for (k = 0; k < 4; k++) {
        double d1 = 0.5 * (rot[k] + ref[k]), d2 = 0.5 * (rot[k] - ref[k]);
        m[2][k] = c1 * d1 + c2 * d2;         /* eigenvector of l1 */
        m[3][k] = -c2 * d1 + c1 * d2;        /* eigenvector of l2 */
    }
    lam[2] = e.l1; lam[3] = e.l2;
    for (k = 0; k < 4; k++) if (project && !(lam[k] > 0)) lam[k] = 0;
    for (i = 0; i < 4; i++)                  /* symmetric: the upper triangle, mirrored */
        for (j = i; j < 4; j++) {
            double s = 0;
            for (k = 0; k < 4; k++) s += lam[k] * m[k][i] * m[k][j];
            out[4 * i + j] = out[4 * j + i] = s;
        }
    /* Built in a local array and copied out whole: GCC 12 (at -O1 and -O2,
       with this function out of line) rewrote the mirrored store into the
       caller's array as a memory reference based at address 0, which its
       mod/ref analysis then took for a null dereference ending the block:
       the function was summarized as storing nothing, and a caller's reads
       of a zero-initialized h4 were folded to the zeros (fixed in later
       GCC's induction-variable pass; tests/test_newton.c (l) reads one) */
    memcpy(h4, out, sizeof out);
    return 1;
}

/* Block (al, be) of the 4x4 Hessian h4 in J, B_ab (rows 2 al, 2 al + 1,
   columns 2 be, 2 be + 1), carried to the corners: M = G^T B_ab G, with
   G the rows of J's gradient (g_2 = (m00, m01), g_3 = (0, m11), and
   corner 1's g_1 = -g_2 - g_3). */
static void bp__hessian_corners(const bp__rest *r, const double *h4, int al, int be, double M[3][3])
{
    const double *b0 = h4 + 4 * (2 * al) + 2 * be, *b1 = b0 + 4;   /* rows p = 0, 1 of B_ab */
    double c[2][2];
    c[0][0] = b0[0] * r->m00 + b0[1] * r->m01; c[0][1] = b0[1] * r->m11;      /* c = B_ab G */
    c[1][0] = b1[0] * r->m00 + b1[1] * r->m01; c[1][1] = b1[1] * r->m11;
    M[1][1] = r->m00 * c[0][0] + r->m01 * c[1][0]; M[1][2] = r->m00 * c[0][1] + r->m01 * c[1][1];
    M[2][1] = r->m11 * c[1][0];                    M[2][2] = r->m11 * c[1][1];
    M[0][1] = -M[1][1] - M[2][1]; M[0][2] = -M[1][2] - M[2][2];
    M[1][0] = -M[1][1] - M[1][2]; M[2][0] = -M[2][1] - M[2][2];
    M[0][0] = -M[0][1] - M[0][2];
}

/* J of the triangle's map; 0 when it is not positive. */
static int bp__triangle_j(const bp__rest *r, const double *u1, const double *u2, const double *u3, double J[4])
{
    double d00 = u2[0] - u1[0], d10 = u2[1] - u1[1], d01 = u3[0] - u1[0], d11 = u3[1] - u1[1];
    J[0] = d00 * r->m00; J[1] = d00 * r->m01 + d01 * r->m11;
    J[2] = d10 * r->m00; J[3] = d10 * r->m01 + d11 * r->m11;
    return 1;
}

/* The 6x6 Hessian of weight * E_t in (u1x, u1y, u2x, u2y, u3x, u3y), row
   major into h6 (projected to positive semidefinite with `project`).
   Returns 0 (h6 untouched) for a triangle that is not positive. */
static int bp__triangle_hessian(bp_energy kind, const bp__rest *r, const double *u1, const double *u2,
                                const double *u3, int project, double h6[36])
{
    double J[4], h4[16], w = r->weight, M[3][3];
    int k, l, al, be;
    bp__triangle_j(r, u1, u2, u3, J);
    if (!bp__hessian_j(kind, J, project, h4)) return 0;
    for (al = 0; al < 2; al++)
        for (be = al; be < 2; be++) {
            bp__hessian_corners(r, h4, al, be, M);
            for (k = 0; k < 3; k++)
                for (l = 0; l < 3; l++) {
                    h6[6 * (2 * k + al) + 2 * l + be] = w * M[k][l];
                    h6[6 * (2 * l + be) + 2 * k + al] = w * M[k][l];     /* (M_ba = M_ab^T) */
                }
        }
    return 1;
}

/* Its isotropic part (Newton's isotropic phase, bp__newton_tri_task):
   k[i] = (xx + yy) / 2 of corner block (r, q), r <= q, at i =
   bp__ht_block[r][q] / 4.  Newton's H keeps its six 2x2 corner blocks
   (r, q), r <= q, per triangle in that order, each row major, the block
   (r, q) at bp__ht_block[r][q] (bp__newton_tri_task); the isotropic phase
   keeps one number per block, at a quarter of that.

   The average of the xx and yy blocks needs neither the 4x4 nor two
   congruences.  The x coordinates move J's row 0 and the y coordinates
   its row 1 (>>hessian), so (xx + yy) / 2 = G^T C G with
   C = (B_00 + B_11) / 2, B_aa the diagonal 2x2 blocks of the projected
   H4 = sum_k lambda_k vec(Q_k) vec(Q_k)^T.  Summing over J's two rows,
       C = 1/2 sum_k lambda_k Q_k^T Q_k.
   Twist and flip are U [0 -+1; 1 0] V^T / sqrt2, so Q^T Q = I / 2 for
   both; a scaling eigenvector c1 U diag(1,0) V^T + c2 U diag(0,1) V^T
   gives V diag(c1^2, c2^2) V^T, and summed with its eigenvalues the two
   give V diag(al, be) V^T, with (al, be) the diagonal of the projected
   scaling block (the block itself when both its eigenvalues are >= 0, as
   for symmetric Dirichlet always).  With V diag(1, -1) V^T = rot^T ref
   (rot = U V^T = [E -H; H E] / Q, ref = U diag(1,-1) V^T =
   [F G; G -F] / R, as in bp__hessian_j),
       C = (tw + fl + al + be) / 4 I + (al - be) / 4 P,
       P = rot^T ref = [EF + HG, EG - HF; EG - HF, -(EF + HG)] / (Q R),
   tw and fl clamped at 0; at R = 0 the reflection [1 0; 0 -1] of
   bp__hessian_j, P = [E -H; -H -E] / Q.  Face: less than half the time
   of the 4x4 and its two congruences (docs/performance.md sec 6.34).
   C is written as a block of an H4 (rows at stride 4: C[0] C[1] / C[4]
   C[5]) for bp__hessian_corners.  tests/test_newton.c (l) checks it
   against the 4x4's blocks for every energy. */
static int bp__hessian_iso_j(bp_energy kind, const double J[4], double C[8])
{
    double al, be, tw, fl, iso, dev, p0, p1;
    bp__jeig e;
    if (!bp__hessian_eig(kind, J, &e)) return 0;
    if (e.l2 >= 0) { al = e.hs[0]; be = e.hs[2]; }    /* already positive semidefinite */
    else if (!(e.l1 > 0)) al = be = 0;
    else {                                            /* l1 e e^T, e = (x, y) / |(x, y)| */
        double n = e.x * e.x + e.y * e.y;
        al = e.l1 * e.x * e.x / n;
        be = e.l1 * e.y * e.y / n;
    }
    tw = e.tw > 0 ? e.tw : 0;
    fl = e.fl > 0 ? e.fl : 0;
    iso = 0.25 * (tw + fl + al + be);
    dev = 0.25 * (al - be);
    if (e.R > 0) { p0 = (e.E * e.F + e.H * e.G) / (e.Q * e.R); p1 = (e.E * e.G - e.H * e.F) / (e.Q * e.R); }
    else { p0 = e.E / e.Q; p1 = -e.H / e.Q; }
    C[0] = iso + dev * p0;
    C[1] = C[4] = dev * p1;
    C[5] = iso - dev * p0;
    return 1;
}

static const unsigned char bp__ht_block[3][3] = { { 0, 4, 8 }, { 4, 12, 16 }, { 8, 16, 20 } };
static int bp__triangle_hessian_iso(bp_energy kind, const bp__rest *r, const double *u1, const double *u2,
                                    const double *u3, double k6[6])
{
    double J[4], C[8], w = r->weight, M[3][3];
    int k, l;
    bp__triangle_j(r, u1, u2, u3, J);
    if (!bp__hessian_iso_j(kind, J, C)) return 0;
    bp__hessian_corners(r, C, 0, 0, M);
    for (k = 0; k < 3; k++)
        for (l = k; l < 3; l++) k6[bp__ht_block[k][l] / 4] = w * M[l][k];
    return 1;
}

/* >>barrier ================================================================

   Sec 3.3.  Positive triangles make the map locally injective, not
   bijective: the boundary can still run over itself (fig 3.3).  For each
   boundary edge (U1, U2) and each boundary vertex Ui not on it,
       E_B += max(0, eps / dist(U1, U2, Ui) - 1)^2,
   which is zero (with zero gradient) beyond distance eps and infinite at
   contact.  dist is the distance from Ui to the closest point
   C = U1 + s (U2 - U1), s clamped to [0, 1]; with n the unit vector from C
   to Ui, d dist/dUi = n, d dist/dU1 = -(1 - s) n, d dist/dU2 = -s n (the
   derivative through s vanishes: s minimizes the distance, or is clamped).
   eps defaults to a quarter of the chart's mean 3D boundary edge length.

   Only vertex/edge pairs within eps matter, so a spatial hash finds them
   (fig 3.6 left): boundary vertices are binned in a uniform grid, and each
   edge visits the cells of its box grown by eps.

   Loops of one chart are never tested against each other (sec 3.6): while
   every triangle stays positive, a vertex of one loop cannot reach an edge
   of another.  The image of the chart near that edge lies on its inner
   side, and a vertex arriving from the inner side is already covered by a
   triangle next to the edge: an overlap of two triangles, which a map that
   is injective up to that moment cannot acquire without some triangle
   degenerating first.  One hash per loop therefore suffices, and the exact
   check after each step confirms it. */

/* The spatial hash.  Items (boundary vertices, as boxes: a point for the
   barrier, a swept segment for the step bound) are entered in every cell of
   a uniform grid that their box covers; cells live in a hash table keyed by
   (cell x, cell y, loop), so each loop has its own hash (sec 3.6) with its
   own cell size, all in one table.  A query visits the cells of a box and
   reports each item whose box overlaps it exactly once: an item covering
   several of those cells is reported only in the cell holding the lower-left
   corner of the overlap of the two boxes.  Queries only read the table, so
   the edges of a loop can query it from several threads at once.

   Small loops are not entered at all.  Entering a vertex and answering an
   edge's query cost the table several hundred instructions each (cell
   sizes, hashed cells, buckets shared with other loops, the test of which
   cell reports a pair), where scanning a loop's n boxes costs about 8 n;
   so a loop of at most BP__SCAN_MAX vertices -- the holes of a scanned
   facade, most loops of a photogrammetry atlas's thousands of small charts
   -- answers its queries by that scan, and neither its cells nor its cell
   size are computed (measured on bench/photogrammetry.py's charts: 64 and
   128 both gain, 256 loses to the table).  The scan reports the
   same items (each overlapping box once, in loop order), so the barrier sum
   changes only in the order of its terms and the step bound, a minimum,
   not at all.  A chart whose loops are all small builds no table. */
#define BP__SCAN_MAX 128u

typedef struct bp__hash {
    uint32_t  mask;              /* table size - 1 (power of two)             */
    uint32_t *start;             /* mask+2 bucket offsets                     */
    uint32_t *items;             /* entries                                   */
    size_t    cap;               /* capacity of items                         */
    const double *box;           /* 4 per item: xmin ymin xmax ymax           */
    const uint32_t *group;       /* loop of each item                         */
    const uint32_t *group_start; /* items of loop g: [group_start[g], ..[g+1]) */
    const double *h;             /* cell size per loop                        */
    int64_t  *cell0;             /* 2 per item: its lower-left cell           */
    uint32_t  scan_max;          /* loops of at most this many items: scanned */
    uint32_t  entered;           /* items of the loops that are not scanned   */
} bp__hash;

/* Is loop g answered by a scan instead of the table? */
static int bp__hash_scanned(const bp__hash *H, uint32_t g)
{
    return H->group_start[g + 1] - H->group_start[g] <= H->scan_max;
}

/* Scan the loops of at most scan_max items (0: none, the table holds every
   loop); counts the items left for the table. */
static void bp__hash_set_scan(bp__hash *H, uint32_t nloops, uint32_t scan_max)
{
    uint32_t g;
    H->scan_max = scan_max;
    H->entered = 0;
    for (g = 0; g < nloops; g++)
        if (!bp__hash_scanned(H, g)) H->entered += H->group_start[g + 1] - H->group_start[g];
}

static uint32_t bp__hash_cell(const bp__hash *H, int64_t ix, int64_t iy, uint32_t g)
{
    uint64_t k = (uint64_t)ix * 0x9E3779B97F4A7C15ull ^ (uint64_t)iy * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)g * 0x165667B19E3779F9ull;
    return (uint32_t)(k >> 32) & H->mask;
}

static int64_t bp__cell_of(double x, double h)
{
    double c = floor(x / h);
    if (c > 4e18) c = 4e18;
    if (c < -4e18) c = -4e18;
    return (int64_t)c;
}

/* Build over items [0, n) (n = group_start[#loops]); returns 0 if the
   entries would exceed the capacity (the caller then grows the cells). */
static int bp__hash_build(bp__hash *H, uint32_t n)
{
    uint32_t i, b;
    size_t total = 0;
    for (b = 0; b <= H->mask + 1; b++) H->start[b] = 0;
    for (i = 0; i < n; i++) {
        const double *bx = H->box + 4 * (size_t)i;
        uint32_t g = H->group[i];
        double h;
        int64_t x0, x1, ix, y0, y1, iy;
        if (bp__hash_scanned(H, g)) continue;
        h = H->h[g];
        x0 = bp__cell_of(bx[0], h); x1 = bp__cell_of(bx[2], h);
        y0 = bp__cell_of(bx[1], h); y1 = bp__cell_of(bx[3], h);
        if ((double)(x1 - x0 + 1) * (double)(y1 - y0 + 1) > (double)(H->cap - total)) return 0;
        H->cell0[2 * (size_t)i] = x0;
        H->cell0[2 * (size_t)i + 1] = y0;
        for (iy = y0; iy <= y1; iy++)
            for (ix = x0; ix <= x1; ix++) { H->start[bp__hash_cell(H, ix, iy, g) + 1]++; total++; }
    }
    for (b = 0; b <= H->mask; b++) H->start[b + 1] += H->start[b];
    for (i = 0; i < n; i++) {
        const double *bx = H->box + 4 * (size_t)i;
        uint32_t g = H->group[i];
        double h;
        int64_t x0, x1, ix, y0, y1, iy;
        if (bp__hash_scanned(H, g)) continue;
        h = H->h[g];
        x0 = bp__cell_of(bx[0], h); x1 = bp__cell_of(bx[2], h);
        y0 = bp__cell_of(bx[1], h); y1 = bp__cell_of(bx[3], h);
        for (iy = y0; iy <= y1; iy++)
            for (ix = x0; ix <= x1; ix++) H->items[H->start[bp__hash_cell(H, ix, iy, g)]++] = i;
    }
    for (b = H->mask + 1; b > 0; b--) H->start[b] = H->start[b - 1];
    H->start[0] = 0;
    return 1;
}

/* Calls visit(user, item) once for every item of loop g whose box overlaps
   the query box: a scan of the loop's items when the loop is not in the
   table or the box covers more cells than the table has. */
typedef void (*bp__visit_fn)(void *user, uint32_t item);

static void bp__hash_query(const bp__hash *H, uint32_t g, double x0, double y0, double x1, double y1,
                           bp__visit_fn visit, void *user)
{
    double h;
    int64_t cx0 = 0, cx1 = -1, ix, cy0 = 0, cy1 = -1, iy;
    uint32_t q;
    int scan = bp__hash_scanned(H, g);
    if (!scan) {
        h = H->h[g];
        cx0 = bp__cell_of(x0, h); cx1 = bp__cell_of(x1, h);
        cy0 = bp__cell_of(y0, h); cy1 = bp__cell_of(y1, h);
        scan = (double)(cx1 - cx0 + 1) * (double)(cy1 - cy0 + 1) > 2.0 * (H->mask + 1);
    }
    if (scan) {
        /* a small loop, or a box larger than the table: test every item of the loop */
        for (q = H->group_start[g]; q < H->group_start[g + 1]; q++) {
            const double *bx = H->box + 4 * (size_t)q;
            if (bx[0] <= x1 && bx[2] >= x0 && bx[1] <= y1 && bx[3] >= y0) visit(user, q);
        }
        return;
    }
    for (iy = cy0; iy <= cy1; iy++)
        for (ix = cx0; ix <= cx1; ix++) {
            uint32_t bkt = bp__hash_cell(H, ix, iy, g), e;
            for (e = H->start[bkt]; e < H->start[bkt + 1]; e++) {
                uint32_t it = H->items[e];
                const double *bx = H->box + 4 * (size_t)it;
                /* an item whose cells collide in one bucket is entered there
                   more than once, always in a row (items are entered in order) */
                if (e > H->start[bkt] && H->items[e - 1] == it) continue;
                if (H->group[it] != g) continue;                              /* collision */
                if (bx[0] > x1 || bx[2] < x0 || bx[1] > y1 || bx[3] < y0) continue;  /* apart */
                /* the cell of the overlap's lower-left corner: the cell index
                   is monotonic, so it is the larger of the two first cells */
                if ((H->cell0[2 * (size_t)it] > cx0 ? H->cell0[2 * (size_t)it] : cx0) != ix ||
                    (H->cell0[2 * (size_t)it + 1] > cy0 ? H->cell0[2 * (size_t)it + 1] : cy0) != iy)
                    continue;                                                    /* reported elsewhere */
                visit(user, it);
            }
        }
}

/* The swept hash of the step bound is built by BP__HASH_TASKS tasks (see
   bp__step_hash). */
#define BP__HASH_TASKS 4u

/* A gradient contribution of the barrier, applied after the parallel part
   in chunk order. */
typedef struct bp__grec { uint32_t v; double gx, gy; } bp__grec;

/* The solver's state for one chart.  bp__solver_init allocates every array
   the iterations need, so the loop itself allocates nothing (except the
   barrier's record lists and the check's grid when they first grow). */
typedef struct bp__solver {
    const bp_allocator *a;
    bp__par    par;                /* how chunks run (serial by default)      */
    bp_energy  energy;
    uint32_t   nv, nt;
    const uint32_t *tri;
    bp__rest  *rest;
    uint32_t   nloops;
    const uint32_t *loop_start, *loop_vertices;
    uint32_t   nb;                 /* boundary vertices (= edges)            */
    int        barrier;
    double     eps;
    double     mean_edge;          /* mean 3D boundary edge length           */
    bp__hash   hash;
    double    *box;                /* 4 per boundary vertex                  */
    uint32_t  *bl_loop;            /* loop of each boundary position          */
    double    *hs;                 /* hash cell size per loop                 */
    double    *gc;                 /* 6 per triangle: corner gradients        */
    uint32_t  *vc_start, *vc_list; /* corners around each vertex (CSR)        */
    double    *part;               /* one slot per triangle chunk             */
    double    *part_b;             /* one slot per boundary edge chunk        */
    double    *part_o;             /* a flipped triangle in this chunk?       */
    uint32_t   nchunk_t, nchunk_v, nchunk_b;
    bp__vec   *rec;                /* barrier records per edge chunk          */
    int        oom;                /* a task could not grow its records       */
    int        bclip;              /* the last step bound was the boundary's  */
    bp__dedge *edges;              /* the loops' edges, for the exact check   */
    uint32_t  *hcnt;               /* per-task bucket counts of the swept hash */
    uint32_t   conflicts;          /* boundary conflicts found by that check  */
    bp__grid_ws ws;
} bp__solver;

static void bp__solver_free(bp__solver *S)
{
    uint32_t c;
    const bp_allocator *a = S->a;
    if (!a) return;
    if (S->rec)
        for (c = 0; c < S->nchunk_b; c++) bp__free(a, S->rec[c].data);
    bp__free(a, S->rec);
    bp__free(a, S->rest); bp__free(a, S->hash.start); bp__free(a, S->hash.items); bp__free(a, S->hash.cell0);
    bp__free(a, S->box); bp__free(a, S->bl_loop); bp__free(a, S->hs); bp__free(a, S->gc);
    bp__free(a, S->vc_start); bp__free(a, S->vc_list); bp__free(a, S->part); bp__free(a, S->edges);
    bp__free(a, S->hcnt);
    bp__free(a, S->ws.cellp); bp__free(a, S->ws.cells);
    memset(S, 0, sizeof *S);
}

/* Allocate the solver for a triangulation with boundary loops; rest shapes,
   eps and mean_edge are filled by the caller.  Loops run serially until the
   caller sets S->par. */
static bp_status bp__solver_init(bp__solver *S, const bp_allocator *a, uint32_t nv, uint32_t nt,
                                 const uint32_t *tri, uint32_t nloops, const uint32_t *loop_start,
                                 const uint32_t *loop_vertices)
{
    uint32_t nb = loop_start[nloops], L, k, t, c, nchunk;
    memset(S, 0, sizeof *S);
    S->a = a;
    S->par.run = bp__serial_for;
    S->par.threads = 1;
    S->nv = nv;
    S->nt = nt;
    S->tri = tri;
    S->nloops = nloops;
    S->loop_start = loop_start;
    S->loop_vertices = loop_vertices;
    S->nb = nb;
    S->barrier = 1;
    S->nchunk_t = bp__nchunks(nt, BP__TRI_CHUNK);
    S->nchunk_v = bp__nchunks(nv, BP__VERT_CHUNK);
    S->nchunk_b = bp__nchunks(nb, BP__EDGE_CHUNK);
    nchunk = 2 * S->nchunk_t + S->nchunk_b;
    S->hash.mask = 1;
    while (S->hash.mask + 1 < 2 * nb) S->hash.mask = 2 * S->hash.mask + 1;
    S->hash.cap = 32 * (size_t)nb + 64;
    S->rest = (bp__rest *)bp__calloc_array(a, nt, sizeof(bp__rest));
    S->hash.start = (uint32_t *)bp__alloc_array(a, (size_t)S->hash.mask + 2, sizeof(uint32_t));
    S->hash.items = (uint32_t *)bp__alloc_array(a, S->hash.cap, sizeof(uint32_t));
    S->hash.cell0 = (int64_t *)bp__alloc_array(a, 2 * (size_t)nb, sizeof(int64_t));
    S->box = (double *)bp__alloc_array(a, 4 * (size_t)nb, sizeof(double));
    S->bl_loop = (uint32_t *)bp__alloc_array(a, nb, sizeof(uint32_t));
    S->hs = (double *)bp__alloc_array(a, nloops, sizeof(double));
    S->gc = (double *)bp__alloc_array(a, 6 * (size_t)nt, sizeof(double));
    S->vc_start = (uint32_t *)bp__calloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    S->vc_list = (uint32_t *)bp__alloc_array(a, 3 * (size_t)nt, sizeof(uint32_t));
    S->part = (double *)bp__alloc_array(a, nchunk ? nchunk : 1, sizeof(double));
    S->rec = (bp__vec *)bp__calloc_array(a, S->nchunk_b ? S->nchunk_b : 1, sizeof(bp__vec));
    S->edges = (bp__dedge *)bp__alloc_array(a, nb ? nb : 1, sizeof(bp__dedge));
    S->hcnt = (uint32_t *)bp__alloc_array(a, BP__HASH_TASKS * ((size_t)S->hash.mask + 1), sizeof(uint32_t));
    if (!S->rest || !S->hash.start || !S->hash.items || !S->hash.cell0 || !S->box || !S->bl_loop || !S->hs || !S->gc ||
        !S->vc_start || !S->vc_list || !S->part || !S->rec || !S->edges || !S->hcnt) {
        bp__solver_free(S);
        return BP_ERR_OUT_OF_MEMORY;
    }
    S->part_b = S->part + S->nchunk_t;
    S->part_o = S->part_b + S->nchunk_b;
    for (c = 0; c < S->nchunk_b; c++) S->rec[c].elem = sizeof(bp__grec);
    for (L = 0; L < nloops; L++)
        for (k = loop_start[L]; k < loop_start[L + 1]; k++) {
            S->bl_loop[k] = L;
            S->edges[k].a = loop_vertices[k];
            S->edges[k].b = loop_vertices[k + 1 < loop_start[L + 1] ? k + 1 : loop_start[L]];
        }
    S->hash.box = S->box;
    S->hash.group = S->bl_loop;
    S->hash.group_start = loop_start;
    S->hash.h = S->hs;
    bp__hash_set_scan(&S->hash, nloops, BP__SCAN_MAX);
    /* corners around each vertex, in increasing corner order */
    for (t = 0; t < 3 * nt; t++) S->vc_start[tri[t] + 1]++;
    for (k = 0; k < nv; k++) S->vc_start[k + 1] += S->vc_start[k];
    for (t = 0; t < 3 * nt; t++) S->vc_list[S->vc_start[tri[t]]++] = t;
    for (k = nv; k > 0; k--) S->vc_start[k] = S->vc_start[k - 1];
    S->vc_start[0] = 0;
    return BP_OK;
}

/* --- E_D over triangle chunks ---------------------------------------------- */

typedef struct bp__eval_task {
    bp__solver   *S;
    const double *x;
    double       *g;
    const double *dir;          /* step bound: direction                      */
    double        tmax;         /* step bound: the bound so far; hash: sweep  */
} bp__eval_task;

/* Several kinds of tasks as one parallel loop: the groups are laid end to
   end and task i runs in the group that holds it.  Work that would
   otherwise run alone between two loops (building a hash, the exact
   boundary check) becomes one task among the chunks of another loop, and
   two loops that do not depend on each other share one join.  Each task
   still writes only its own slots, so the result does not depend on the
   schedule.  A long task goes first, so that it starts at once. */
typedef struct bp__group { bp_task_fn fn; void *task; uint32_t count; } bp__group;
typedef struct bp__groups { bp__group g[4]; uint32_t n, total; } bp__groups;

static void bp__groups_task(void *task, uint32_t i)
{
    const bp__groups *G = (const bp__groups *)task;
    uint32_t k;
    for (k = 0; k < G->n; k++) {
        if (i < G->g[k].count) { G->g[k].fn(G->g[k].task, i); return; }
        i -= G->g[k].count;
    }
}

static void bp__groups_add(bp__groups *G, bp_task_fn fn, void *task, uint32_t count)
{
    G->g[G->n].fn = fn;
    G->g[G->n].task = task;
    G->g[G->n++].count = count;
    G->total += count;
}

static void bp__groups_run(const bp__par *par, const bp__groups *G)
{
    if (G->total) par->run(par->user, bp__groups_task, (void *)G, G->total);
}

static void bp__energy_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t t, t1 = bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    double sum = 0;
    for (t = bp__chunk_at(S->nt, S->nchunk_t, c); t < t1; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        double *gc = T->g ? S->gc + 6 * (size_t)t : NULL, e;
        if (gc) { gc[0] = gc[1] = gc[2] = gc[3] = gc[4] = gc[5] = 0; }
        e = bp__triangle_energy(S->energy, &S->rest[t], T->x + 2 * (size_t)tr[0], T->x + 2 * (size_t)tr[1],
                                T->x + 2 * (size_t)tr[2], gc, gc ? gc + 2 : NULL, gc ? gc + 4 : NULL);
        if (e == HUGE_VAL) { sum = HUGE_VAL; if (!gc) break; }
        else sum += S->rest[t].weight * e;
    }
    S->part[c] = sum;
}

/* Exact orientation of the triangles of a chunk: part_o[c] = 1 if one is
   not positive.  Each chunk also checks the same share of the vertices'
   coordinates against the predicates' exact range (see >>check; never met
   in practice, but outside it a sign would not be proven): one pass over
   the coordinates in all, instead of six tests per triangle. */
static void bp__orient_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t t, t1 = bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    size_t i, i1 = 2 * (size_t)bp__chunk_at(S->nv, S->nchunk_t, c + 1);
    int out = 0;
    double bad = 0;
    for (i = 2 * (size_t)bp__chunk_at(S->nv, S->nchunk_t, c); i < i1; i++) out |= !bp__exact_range(T->x[i]);
    if (out) bad = 1;
    for (t = bp__chunk_at(S->nt, S->nchunk_t, c); t < t1 && !bad; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        if (bp_orient2d(T->x + 2 * (size_t)tr[0], T->x + 2 * (size_t)tr[1], T->x + 2 * (size_t)tr[2]) <= 0) bad = 1;
    }
    S->part_o[c] = bad;
}

/* g(v) = sum of its corners' gradients, in corner order. */
static void bp__gather_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1), p;
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        double gx = 0, gy = 0;
        for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++) {
            gx += S->gc[2 * (size_t)S->vc_list[p]];
            gy += S->gc[2 * (size_t)S->vc_list[p] + 1];
        }
        T->g[2 * (size_t)v] = gx;
        T->g[2 * (size_t)v + 1] = gy;
    }
}

/* --- E_B over edge chunks ------------------------------------------------ */

/* The state of one edge's query (on the task's stack). */
typedef struct bp__edge_query {
    const bp__solver *S;
    const double *x, *dir;
    uint32_t s0, n, i;          /* loop start, length, edge position in loop */
    double   acc, tmax;
    bp__vec *rec;
    int      grad, oom;
} bp__edge_query;

static void bp__barrier_visit(void *user, uint32_t k)
{
    bp__edge_query *Q = (bp__edge_query *)user;
    const bp__solver *S = Q->S;
    uint32_t kk = k - Q->s0, i1 = (Q->i + 1) % Q->n;
    uint32_t va, vb, vp;
    const double *A, *B, *P;
    double ex, ey, len2, sp, cx, cy, dx, dy, d, r;
    if (kk == Q->i || kk == i1) return;
    va = S->loop_vertices[Q->s0 + Q->i]; vb = S->loop_vertices[Q->s0 + i1]; vp = S->loop_vertices[k];
    A = Q->x + 2 * (size_t)va; B = Q->x + 2 * (size_t)vb; P = Q->x + 2 * (size_t)vp;
    ex = B[0] - A[0]; ey = B[1] - A[1];
    len2 = ex * ex + ey * ey;
    sp = len2 > 0 ? ((P[0] - A[0]) * ex + (P[1] - A[1]) * ey) / len2 : 0;
    if (sp < 0) sp = 0;
    if (sp > 1) sp = 1;
    cx = A[0] + sp * ex; cy = A[1] + sp * ey;
    dx = P[0] - cx; dy = P[1] - cy;
    d = sqrt(dx * dx + dy * dy);
    if (d >= S->eps) return;
    if (!(d > 0)) { Q->acc = HUGE_VAL; return; }
    r = S->eps / d - 1;
    Q->acc += r * r;
    if (Q->grad) {
        /* dE/dd = -2 r eps / d^2, times d dist/dU (see the essay) */
        double k2 = -2 * r * S->eps / (d * d), nx = dx / d, ny = dy / d;
        bp__grec g3[3];
        int j;
        g3[0].v = vp; g3[0].gx = k2 * nx;            g3[0].gy = k2 * ny;
        g3[1].v = va; g3[1].gx = -k2 * (1 - sp) * nx; g3[1].gy = -k2 * (1 - sp) * ny;
        g3[2].v = vb; g3[2].gx = -k2 * sp * nx;       g3[2].gy = -k2 * sp * ny;
        for (j = 0; j < 3; j++)
            if (!bp__vec_push(S->a, Q->rec, &g3[j])) Q->oom = 1;
    }
}

/* Cell size for the hash of one loop: about one current edge long, but at
   least eps, so that a query box covers a handful of cells. */
static double bp__loop_cell(const bp__solver *S, const double *x, uint32_t L)
{
    uint32_t s0 = S->loop_start[L], n = S->loop_start[L + 1] - s0, k;
    double len = 0;
    for (k = 0; k < n; k++) {
        const double *p = x + 2 * (size_t)S->loop_vertices[s0 + k];
        const double *q = x + 2 * (size_t)S->loop_vertices[s0 + (k + 1) % n];
        len += sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]));
    }
    len /= n;
    return len > S->eps ? len : S->eps;
}

/* Enter the boundary vertices into the hash: as points (v NULL, the
   barrier) or as the boxes they sweep along U + t v for t in [0, tsweep]
   (the step bound). */
static void bp__hash_boxes(bp__solver *S, const double *x, const double *v, double tsweep, uint32_t k0, uint32_t k1)
{
    uint32_t k;
    for (k = k0; k < k1; k++) {
        const double *p = x + 2 * (size_t)S->loop_vertices[k];
        double qx = p[0], qy = p[1];
        if (v) {
            const double *d = v + 2 * (size_t)S->loop_vertices[k];
            qx = p[0] + tsweep * d[0];
            qy = p[1] + tsweep * d[1];
        }
        S->box[4 * k] = p[0] < qx ? p[0] : qx;  S->box[4 * k + 2] = p[0] < qx ? qx : p[0];
        S->box[4 * k + 1] = p[1] < qy ? p[1] : qy;  S->box[4 * k + 3] = p[1] < qy ? qy : p[1];
    }
}

/* The cell size of each loop in the table (0 for a scanned loop). */
static void bp__hash_cells(bp__solver *S, const double *x)
{
    uint32_t L;
    for (L = 0; L < S->nloops; L++) S->hs[L] = bp__hash_scanned(&S->hash, L) ? 0 : bp__loop_cell(S, x, L);
}

static void bp__hash_fill(bp__solver *S, const double *x, const double *v, double tsweep)
{
    uint32_t L;
    bp__hash_boxes(S, x, v, tsweep, 0, S->nb);
    if (!S->hash.entered) return;                 /* every loop is scanned */
    bp__hash_cells(S, x);
    while (!bp__hash_build(&S->hash, S->nb))
        for (L = 0; L < S->nloops; L++) S->hs[L] *= 2;
}

/* The swept hash in parallel: its counting sort split in BP__HASH_TASKS
   item ranges.  Each task counts its items' cells into its own bucket
   counters (and computes their boxes); the counters are turned into write
   offsets bucket by bucket, task by task; each task then writes its items.
   A bucket thus lists task 0's items, then task 1's, ..., each in item
   order: exactly the serial bp__hash_build's layout, so the queries see
   the same table on any schedule. */
typedef struct bp__hash_job {
    bp__solver   *S;
    const double *x, *v;
    double        tsweep;
    size_t        total[BP__HASH_TASKS];
    int           over[BP__HASH_TASKS];
} bp__hash_job;

/* Task t's items [*i0, *i1) and its bucket counters. */
static uint32_t *bp__hash_part(const bp__hash_job *J, uint32_t t, uint32_t *i0, uint32_t *i1)
{
    const bp__solver *S = J->S;
    *i0 = (uint32_t)((uint64_t)S->nb * t / BP__HASH_TASKS);
    *i1 = (uint32_t)((uint64_t)S->nb * (t + 1) / BP__HASH_TASKS);
    return S->hcnt + (size_t)t * (S->hash.mask + 1);
}

static void bp__hash_count_task(void *task, uint32_t t)
{
    bp__hash_job *J = (bp__hash_job *)task;
    bp__solver *S = J->S;
    bp__hash *H = &S->hash;
    uint32_t i, i0, i1, *cnt = bp__hash_part(J, t, &i0, &i1);
    size_t total = 0;
    bp__hash_boxes(S, J->x, J->v, J->tsweep, i0, i1);
    memset(cnt, 0, ((size_t)H->mask + 1) * sizeof(uint32_t));
    J->over[t] = 0;
    for (i = i0; i < i1; i++) {
        const double *bx = H->box + 4 * (size_t)i;
        uint32_t g = H->group[i];
        double h;
        int64_t x0, x1, ix, y0, y1, iy;
        if (bp__hash_scanned(H, g)) continue;
        h = H->h[g];
        x0 = bp__cell_of(bx[0], h); x1 = bp__cell_of(bx[2], h);
        y0 = bp__cell_of(bx[1], h); y1 = bp__cell_of(bx[3], h);
        if ((double)(x1 - x0 + 1) * (double)(y1 - y0 + 1) > (double)(H->cap - total)) { J->over[t] = 1; return; }
        H->cell0[2 * (size_t)i] = x0;
        H->cell0[2 * (size_t)i + 1] = y0;
        for (iy = y0; iy <= y1; iy++)
            for (ix = x0; ix <= x1; ix++) { cnt[bp__hash_cell(H, ix, iy, g)]++; total++; }
    }
    J->total[t] = total;
}

static void bp__hash_place_task(void *task, uint32_t t)
{
    bp__hash_job *J = (bp__hash_job *)task;
    bp__hash *H = &J->S->hash;
    uint32_t i, i0, i1, *cnt = bp__hash_part(J, t, &i0, &i1);
    for (i = i0; i < i1; i++) {
        const double *bx = H->box + 4 * (size_t)i;
        uint32_t g = H->group[i];
        double h;
        int64_t x0, x1, ix, y0, y1, iy;
        if (bp__hash_scanned(H, g)) continue;
        h = H->h[g];
        x0 = H->cell0[2 * (size_t)i]; x1 = bp__cell_of(bx[2], h);
        y0 = H->cell0[2 * (size_t)i + 1]; y1 = bp__cell_of(bx[3], h);
        for (iy = y0; iy <= y1; iy++)
            for (ix = x0; ix <= x1; ix++) H->items[cnt[bp__hash_cell(H, ix, iy, g)]++] = i;
    }
}

/* Enter the boundary vertices swept along U + t v, t in [0, tsweep]: the
   count tasks, the offsets (serial, a pass over the buckets), the place
   tasks; the cells double while the entries would not fit. */
static void bp__step_hash(bp__solver *S, const double *x, const double *v, double tsweep)
{
    bp__hash *H = &S->hash;
    bp__hash_job J;
    uint32_t L, b, t;
    memset(&J, 0, sizeof J);
    J.S = S;
    J.x = x;
    J.v = v;
    J.tsweep = tsweep;
    if (!H->entered) {                            /* every loop is scanned: boxes only */
        bp__hash_boxes(S, x, v, tsweep, 0, S->nb);
        return;
    }
    bp__hash_cells(S, x);
    for (;;) {
        size_t total = 0, run = 0;
        int over = 0;
        bp__par_run(&S->par, bp__hash_count_task, &J, BP__HASH_TASKS, S->nb);
        for (t = 0; t < BP__HASH_TASKS; t++) { over |= J.over[t]; total += J.total[t]; }
        if (!over && total <= H->cap) {
            for (b = 0; b <= H->mask; b++) {
                H->start[b] = (uint32_t)run;
                for (t = 0; t < BP__HASH_TASKS; t++) {
                    uint32_t *c = S->hcnt + (size_t)t * (H->mask + 1) + b, k = *c;
                    *c = (uint32_t)run;
                    run += k;
                }
            }
            H->start[H->mask + 1] = (uint32_t)run;
            break;
        }
        for (L = 0; L < S->nloops; L++) S->hs[L] *= 2;
    }
    bp__par_run(&S->par, bp__hash_place_task, &J, BP__HASH_TASKS, S->nb);
}

static void bp__hash_fill_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    (void)c;
    bp__hash_fill(T->S, T->x, T->dir, T->tmax);
}

static void bp__barrier_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t e, e1 = bp__chunk_at(S->nb, S->nchunk_b, c + 1);
    bp__edge_query Q;
    double sum = 0;
    memset(&Q, 0, sizeof Q);
    Q.S = S;
    Q.x = T->x;
    Q.rec = &S->rec[c];
    Q.grad = T->g != NULL;
    S->rec[c].count = 0;
    for (e = bp__chunk_at(S->nb, S->nchunk_b, c); e < e1; e++) {
        uint32_t L = S->bl_loop[e];
        const double *p, *q;
        Q.s0 = S->loop_start[L];
        Q.n = S->loop_start[L + 1] - Q.s0;
        Q.i = e - Q.s0;
        p = Q.x + 2 * (size_t)S->loop_vertices[e];
        q = Q.x + 2 * (size_t)S->loop_vertices[Q.s0 + (Q.i + 1) % Q.n];
        Q.acc = 0;
        bp__hash_query(&S->hash, L, (p[0] < q[0] ? p[0] : q[0]) - S->eps, (p[1] < q[1] ? p[1] : q[1]) - S->eps,
                       (p[0] > q[0] ? p[0] : q[0]) + S->eps, (p[1] > q[1] ? p[1] : q[1]) + S->eps,
                       bp__barrier_visit, &Q);
        sum += Q.acc;
    }
    S->part_b[c] = sum;
    if (Q.oom) S->oom = 1;
}

/* The sum of the edge chunks' E_B, and their gradient records added to g
   (when given), both in chunk order. */
static double bp__barrier_finish(bp__solver *S, double *g)
{
    double total = 0;
    uint32_t c;
    for (c = 0; c < S->nchunk_b; c++) total += S->part_b[c];
    if (g)
        for (c = 0; c < S->nchunk_b; c++) {
            const bp__grec *r = (const bp__grec *)S->rec[c].data;
            size_t j;
            for (j = 0; j < S->rec[c].count; j++) {
                g[2 * (size_t)r[j].v] += r[j].gx;
                g[2 * (size_t)r[j].v + 1] += r[j].gy;
            }
        }
    return total;
}

/* The exact boundary check of a trial map, as one task of the evaluation:
   bp_check's conditions (b) and (c) on the chart's own loops.  (b) no two
   boundary edges meet (S->conflicts counts the pairs); (c) exactly one
   loop is counter-clockwise, else S->conflicts is set too.  Together with
   (a), the exact orientation of bp__orient_task, this proves the map
   bijective: a chart is one connected disk with holes, so (d) does not
   arise, and by the argument in >>check (a) + (b) + (c) leave each point
   covered at most once.  (c) is O(number of loops + boundary length) and
   is only evaluated when (b) holds (the loops are then simple). */
static void bp__conflict_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    bp_check_report rep;
    bp_status st;
    (void)c;
    memset(&rep, 0, sizeof rep);
    if (S->nb <= BP__CONFLICT_SCAN) {
        S->conflicts = bp__conflicts_scan(T->x, S->edges, S->nb);   /* a small chart: no grid */
    } else {
        st = bp__boundary_conflicts(S->a, T->x, S->edges, S->nb, &rep, &S->ws, NULL);
        if (st == BP_ERR_OUT_OF_MEMORY) S->oom = 1;
        S->conflicts = (uint32_t)rep.boundary_intersections;
        if (st != BP_OK) S->conflicts = 1;                 /* (an extent beyond DBL_MAX: not decided) */
    }
    if (!S->conflicts && !S->oom && bp__ccw_loops(T->x, S->edges, S->loop_start, S->nloops) != 1) S->conflicts = 1;
}

/* f = E_D + E_B at x (E_D = sum weight_t E_t); gradient into g if given.
   *ed receives E_D alone.  +inf outside the valid region.  The sums are
   taken per chunk and added in chunk order: the same bits for any number
   of threads.

   A trial point of the line search (`valid` given) needs more: whether it
   is, exactly, a bijective map of the chart: every triangle positive by
   orient2d and, with the barrier, no two boundary edges in conflict and
   exactly one counter-clockwise loop (bp__conflict_task; that is all of
   bp_check for one connected chart).  Without the barrier only the
   triangles' orientation is checked (fig 3.2, 3.3): the boundary may
   overlap.  And it needs nothing more when it fails the sufficient
   decrease test: E_B >= 0, so E_D > fmax already rejects it, and the
   evaluation stops there (returning E_D, which is above fmax).
   Two parallel loops in all:
     1. E_D over triangle chunks, and the barrier's hash (one task);
     2. the per-vertex gradient gather, E_B over edge chunks and, for a
        trial point, the orientation chunks and the exact boundary check
        (one task). */
static double bp__evaluate(bp__solver *S, const double *x, double *g, double *ed, double fmax, int *valid)
{
    bp__eval_task T;
    bp__groups G;
    double sum = 0;
    uint32_t c;
    memset(&T, 0, sizeof T);
    T.S = S;
    T.x = x;
    T.g = g;
    memset(&G, 0, sizeof G);
    if (S->barrier) bp__groups_add(&G, bp__hash_fill_task, &T, 1);
    bp__groups_add(&G, bp__energy_task, &T, S->nchunk_t);
    bp__groups_run(&S->par, &G);
    for (c = 0; c < S->nchunk_t; c++) sum += S->part[c];
    if (valid) *valid = 0;
    *ed = sum;
    if (!(sum < HUGE_VAL && sum <= fmax)) return sum;     /* also NaN: no exact check of NaN */
    memset(&G, 0, sizeof G);
    if (S->barrier && valid) bp__groups_add(&G, bp__conflict_task, &T, 1);
    if (valid) bp__groups_add(&G, bp__orient_task, &T, S->nchunk_t);
    if (S->barrier) bp__groups_add(&G, bp__barrier_task, &T, S->nchunk_b);
    if (g) bp__groups_add(&G, bp__gather_task, &T, S->nchunk_v);
    S->conflicts = 0;
    bp__groups_run(&S->par, &G);
    if (S->barrier) sum += bp__barrier_finish(S, g);
    if (valid) {
        *valid = !S->conflicts;
        for (c = 0; c < S->nchunk_t; c++) if (S->part_o[c] != 0) *valid = 0;
    }
    return sum;
}

static double bp__objective(bp__solver *S, const double *x, double *g, double *ed)
{
    return bp__evaluate(S, x, g, ed, HUGE_VAL, NULL);
}

/* The barrier's full curvature for one pair (for Newton, >>newton).  With
   f(d) = (eps / d - 1)^2 and d = d(P, A, B) the distance from P to the
   segment AB, the pair's Hessian in the six coordinates (P, A, B) is
       K = f''(d) grad d grad d^T + f'(d) Hess d,
   f' = -2 (eps / d - 1) eps / d^2 < 0.  The Gauss-Newton part alone (the
   first term) sees only the relative motion along the normal n.  Where
   the closest point is an end of the segment, d = |P - A| and Hess d =
   (I - n n^T) / d is positive semidefinite, so the second term is negative
   semidefinite and dropping it is the right projection.  Where the closest
   point is inside the segment it is not: with q = P - A, e = B - A,
   c = q x e and L = |e|, d = sigma c / L (sigma = sign c) is bilinear in q
   and e up to the 1/L, and Hess d couples the vertex's slide along the
   edge with the edge's rotation.  A step that slides P along AB by a
   distance a while AB turns by an angle w brings them closer by about
   a w, a second-order change the Gauss-Newton model calls free; near
   contact, |f'| a w can outweigh f'' times the normal motion squared by
   orders of magnitude (docs/performance.md sec 6.10: on hilbert, a vertex
   at eps/170 from an edge slides 200 d per unit step while the edge turns,
   and Newton's steps are cut to t = 0.005 for 100 iterations).  So K is
   formed whole and projected onto the positive semidefinite cone: its 6x6
   eigen-decomposition (cyclic Jacobi), negative eigenvalues set to 0.
   In q, e (4 coordinates; c's Hessian has d2c/dqx dey = 1,
   d2c/dqy dex = -1, and grad (1/L) = -e / L^3, Hess (1/L) = -I / L^3 +
   3 e e^T / L^5 on e):
       Hess d = sigma (Hess c / L + grad c grad(1/L)^T + grad(1/L) grad c^T
                       + c Hess(1/L)),
   and (P, A, B) -> (q, e) is linear: q = P - A, e = B - A.  K (row-major
   6x6, P's x y, then A's, then B's) is written for d in (0, eps); returns
   0 (K untouched) outside.  With project = 0 it is the whole Hessian
   (for the tests), at an end too. */
static void bp__sym_psd6(double *K)
{
    double V[36], a[36];
    int i, j, k, sweep;
    memcpy(a, K, sizeof a);
    for (i = 0; i < 36; i++) V[i] = (i % 7 == 0) ? 1 : 0;
    for (sweep = 0; sweep < 30; sweep++) {
        double off = 0, tot = 0;
        for (i = 0; i < 6; i++)
            for (j = 0; j < 6; j++) { tot += a[6 * i + j] * a[6 * i + j]; if (i != j) off += a[6 * i + j] * a[6 * i + j]; }
        if (!(off > 1e-30 * tot)) break;
        for (i = 0; i < 5; i++)
            for (j = i + 1; j < 6; j++) {
                double apq = a[6 * i + j], th, t, c, sn;
                if (apq == 0) continue;
                th = (a[6 * j + j] - a[6 * i + i]) / (2 * apq);
                t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
                c = 1 / sqrt(t * t + 1); sn = t * c;
                for (k = 0; k < 6; k++) {                       /* columns i, j */
                    double x = a[6 * k + i], y = a[6 * k + j];
                    a[6 * k + i] = c * x - sn * y; a[6 * k + j] = sn * x + c * y;
                }
                for (k = 0; k < 6; k++) {                       /* rows i, j */
                    double x = a[6 * i + k], y = a[6 * j + k];
                    a[6 * i + k] = c * x - sn * y; a[6 * j + k] = sn * x + c * y;
                }
                for (k = 0; k < 6; k++) {
                    double x = V[6 * k + i], y = V[6 * k + j];
                    V[6 * k + i] = c * x - sn * y; V[6 * k + j] = sn * x + c * y;
                }
            }
    }
    for (i = 0; i < 6; i++)
        for (j = 0; j < 6; j++) {
            double sum = 0;
            for (k = 0; k < 6; k++) if (a[7 * k] > 0) sum += V[6 * i + k] * a[7 * k] * V[6 * j + k];
            K[6 * i + j] = sum;
        }
}

static int bp__barrier_pair_hessian(const double *P, const double *A, const double *B, double eps, int project,
                                    double *K)
{
    double ex = B[0] - A[0], ey = B[1] - A[1], qx = P[0] - A[0], qy = P[1] - A[1];
    double L2 = ex * ex + ey * ey, sp = L2 > 0 ? (qx * ex + qy * ey) / L2 : 0, dx, dy, d, f1, f2, g[6];
    int i, j;
    if (sp < 0) sp = 0;
    if (sp > 1) sp = 1;
    dx = qx - sp * ex; dy = qy - sp * ey;
    d = sqrt(dx * dx + dy * dy);
    if (!(d < eps) || !(d > 0)) return 0;
    f1 = -2 * (eps / d - 1) * eps / (d * d);
    f2 = 2 * eps * eps / (d * d * d * d) + 4 * (eps / d - 1) * eps / (d * d * d);
    g[0] = dx / d; g[1] = dy / d;
    g[2] = -(1 - sp) * g[0]; g[3] = -(1 - sp) * g[1];
    g[4] = -sp * g[0]; g[5] = -sp * g[1];
    for (i = 0; i < 6; i++) for (j = 0; j < 6; j++) K[6 * i + j] = f2 * g[i] * g[j];
    if (sp > 0 && sp < 1) {                      /* inside the segment: the whole Hessian */
        double L = sqrt(L2), c = qx * ey - qy * ex, sg = c >= 0 ? 1 : -1, iL3 = 1 / (L * L2);
        double gc[4], gi[4], H4[16], J[4][6];
        memset(H4, 0, sizeof H4);
        gc[0] = ey; gc[1] = -ex; gc[2] = -qy; gc[3] = qx;
        gi[0] = 0; gi[1] = 0; gi[2] = -ex * iL3; gi[3] = -ey * iL3;
        H4[0 * 4 + 3] = H4[3 * 4 + 0] = 1 / L;
        H4[1 * 4 + 2] = H4[2 * 4 + 1] = -1 / L;
        for (i = 0; i < 4; i++) for (j = 0; j < 4; j++) H4[4 * i + j] += gc[i] * gi[j] + gi[i] * gc[j];
        H4[2 * 4 + 2] += c * (-iL3 + 3 * ex * ex * iL3 / L2);
        H4[2 * 4 + 3] += c * (3 * ex * ey * iL3 / L2);
        H4[3 * 4 + 2] += c * (3 * ex * ey * iL3 / L2);
        H4[3 * 4 + 3] += c * (-iL3 + 3 * ey * ey * iL3 / L2);
        memset(J, 0, sizeof J);                  /* q = P - A, e = B - A */
        J[0][0] = 1; J[0][2] = -1; J[1][1] = 1; J[1][3] = -1;
        J[2][4] = 1; J[2][2] = -1; J[3][5] = 1; J[3][3] = -1;
        for (i = 0; i < 6; i++)
            for (j = 0; j < 6; j++) {
                double sum = 0;
                int k, l;
                for (k = 0; k < 4; k++) for (l = 0; l < 4; l++) sum += J[k][i] * H4[4 * k + l] * J[l][j];
                K[6 * i + j] += f1 * sg * sum;
            }
        if (project) bp__sym_psd6(K);
    } else if (!project) {                       /* at an end E: f'(d) (I - n n^T) / d on P - E (its projection: 0) */
        int e = sp > 0 ? 2 : 1, a_, b_;
        double t[2];
        t[0] = -g[1]; t[1] = g[0];
        for (a_ = 0; a_ < 2; a_++)
            for (b_ = 0; b_ < 2; b_++) {
                double w = f1 / d * t[a_] * t[b_];
                K[6 * a_ + b_] += w; K[6 * (2 * e + a_) + 2 * e + b_] += w;
                K[6 * a_ + 2 * e + b_] -= w; K[6 * (2 * e + a_) + b_] -= w;
            }
    }
    return 1;
}

/* >>stepbound ==============================================================

   Sec 3.4.2.  Along a search line U + t V every singularity of the energy is
   a moment where three points become collinear: the corners of a triangle
   (eq 3.4), or a boundary vertex and a boundary edge of its loop (eq 3.5).
   For points A, B, C moving with velocities VA, VB, VC,
       det[B - A + t (VB - VA), C - A + t (VC - VA)] = alpha t^2 + beta t + gamma
   with gamma = det[B - A, C - A], beta = det[B - A, VC - VA] + det[VB - VA, C - A],
   alpha = det[VB - VA, VC - VA].  Its smallest positive root bounds the step.
   Roots are computed without cancellation (Numerical Recipes' q form):
       q = -(beta + sign(beta) sqrt(beta^2 - 4 alpha gamma)) / 2,
       t1 = q / alpha,  t2 = gamma / q,
   which needs no special case when alpha ~ 0: t1 goes to infinity and t2 to
   the linear root -gamma / beta.  (Not -beta / gamma: dividing the other
   way round is an easy slip that the linear case would expose.)
   For a vertex and an edge a root counts only if at that moment the vertex
   lies within the edge (0 <= s <= 1 along it); outside, the three are
   collinear but nothing touches.  The boundary pairs are found with the
   swept hash of fig 3.6 (right): every vertex enters the cells of the box
   swept by U + t V for t in [0, tmax], every edge queries the box of its
   swept endpoints, and the box shrinks as tmax falls. */

/* Smallest root in (0, tmax) of alpha t^2 + beta t + gamma, else tmax.
   If P/VP etc. are given (edge case), the root must put P on segment AB. */
static double bp__min_root(double alpha, double beta, double gamma, double tmax,
                           const double *A, const double *VA, const double *B, const double *VB,
                           const double *P, const double *VP)
{
    double disc, q, r[2];
    int k;
    /* Filter: for gamma > 0 the polynomial stays above gamma - |beta| t -
       |alpha| t^2, so if that is positive at tmax there is no root before
       tmax (this skips the square root for most triangles once tmax is
       small); if alpha, beta >= 0 there is no positive root at all. */
    if (gamma > 0 && ((alpha >= 0 && beta >= 0) || gamma - fabs(beta) * tmax - fabs(alpha) * tmax * tmax > 0))
        return tmax;
    disc = beta * beta - 4 * alpha * gamma;
    if (disc < 0) return tmax;
    q = -0.5 * (beta + (beta >= 0 ? sqrt(disc) : -sqrt(disc)));
    r[0] = alpha != 0 ? q / alpha : HUGE_VAL;
    r[1] = q != 0 ? gamma / q : HUGE_VAL;
    if (r[0] > r[1]) { double tmp = r[0]; r[0] = r[1]; r[1] = tmp; }
    for (k = 0; k < 2; k++) {
        double t = r[k];
        if (!(t > 0) || !(t < tmax)) continue;
        if (P) {
            double ax = A[0] + t * VA[0], ay = A[1] + t * VA[1];
            double ex = B[0] + t * VB[0] - ax, ey = B[1] + t * VB[1] - ay;
            double px = P[0] + t * VP[0] - ax, py = P[1] + t * VP[1] - ay;
            double dot = px * ex + py * ey, len2 = ex * ex + ey * ey;
            if (dot < 0 || dot > len2) continue;
        }
        return t;
    }
    return tmax;
}

static double bp__collinear_time(const double *A, const double *VA, const double *B, const double *VB,
                                 const double *C, const double *VC, double tmax, int edge_case)
{
    double e1x = B[0] - A[0], e1y = B[1] - A[1], e2x = C[0] - A[0], e2y = C[1] - A[1];
    double f1x = VB[0] - VA[0], f1y = VB[1] - VA[1], f2x = VC[0] - VA[0], f2y = VC[1] - VA[1];
    double gamma = e1x * e2y - e1y * e2x;
    double beta = e1x * f2y - e1y * f2x + f1x * e2y - f1y * e2x;
    double alpha = f1x * f2y - f1y * f2x;
    if (edge_case) return bp__min_root(alpha, beta, gamma, tmax, A, VA, B, VB, C, VC);
    return bp__min_root(alpha, beta, gamma, tmax, NULL, NULL, NULL, NULL, NULL, NULL);
}

static void bp__step_visit(void *user, uint32_t k)
{
    bp__edge_query *Q = (bp__edge_query *)user;
    const bp__solver *S = Q->S;
    uint32_t kk = k - Q->s0, i1 = (Q->i + 1) % Q->n, va, vb, vp;
    if (kk == Q->i || kk == i1) return;
    va = S->loop_vertices[Q->s0 + Q->i]; vb = S->loop_vertices[Q->s0 + i1]; vp = S->loop_vertices[k];
    Q->tmax = bp__collinear_time(Q->x + 2 * (size_t)va, Q->dir + 2 * (size_t)va, Q->x + 2 * (size_t)vb,
                                 Q->dir + 2 * (size_t)vb, Q->x + 2 * (size_t)vp, Q->dir + 2 * (size_t)vp,
                                 Q->tmax, 1);
}

static void bp__step_tri_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t t, t1 = bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    double tmax = HUGE_VAL;
    for (t = bp__chunk_at(S->nt, S->nchunk_t, c); t < t1; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        tmax = bp__collinear_time(T->x + 2 * (size_t)tr[0], T->dir + 2 * (size_t)tr[0], T->x + 2 * (size_t)tr[1],
                                  T->dir + 2 * (size_t)tr[1], T->x + 2 * (size_t)tr[2], T->dir + 2 * (size_t)tr[2],
                                  tmax, 0);
    }
    S->part[c] = tmax;
}

/* Each edge chunk starts from the triangles' bound and lowers its own copy;
   the bound is an exact minimum, so the order of the chunks cannot change
   it. */
static void bp__step_edge_task(void *task, uint32_t c)
{
    bp__eval_task *T = (bp__eval_task *)task;
    bp__solver *S = T->S;
    uint32_t e, e1 = bp__chunk_at(S->nb, S->nchunk_b, c + 1);
    bp__edge_query Q;
    memset(&Q, 0, sizeof Q);
    Q.S = S;
    Q.x = T->x;
    Q.dir = T->dir;
    Q.tmax = T->tmax;
    for (e = bp__chunk_at(S->nb, S->nchunk_b, c); e < e1; e++) {
        uint32_t L = S->bl_loop[e], va, vb;
        const double *p, *q, *dp, *dq;
        double xs[4], ys[4], bx0, by0, bx1, by1;
        int j;
        Q.s0 = S->loop_start[L];
        Q.n = S->loop_start[L + 1] - Q.s0;
        Q.i = e - Q.s0;
        va = S->loop_vertices[e];
        vb = S->loop_vertices[Q.s0 + (Q.i + 1) % Q.n];
        p = Q.x + 2 * (size_t)va; q = Q.x + 2 * (size_t)vb;
        dp = Q.dir + 2 * (size_t)va; dq = Q.dir + 2 * (size_t)vb;
        xs[0] = p[0]; xs[1] = q[0]; xs[2] = p[0] + Q.tmax * dp[0]; xs[3] = q[0] + Q.tmax * dq[0];
        ys[0] = p[1]; ys[1] = q[1]; ys[2] = p[1] + Q.tmax * dp[1]; ys[3] = q[1] + Q.tmax * dq[1];
        bx0 = bx1 = xs[0]; by0 = by1 = ys[0];
        for (j = 1; j < 4; j++) {
            if (xs[j] < bx0) bx0 = xs[j];
            if (xs[j] > bx1) bx1 = xs[j];
            if (ys[j] < by0) by0 = ys[j];
            if (ys[j] > by1) by1 = ys[j];
        }
        bp__hash_query(&S->hash, L, bx0, by0, bx1, by1, bp__step_visit, &Q);
    }
    S->part_b[c] = Q.tmax;
}

/* The largest t <= tcap such that the energy has no singularity on
   [0, t).  The caller only needs the bound up to the step it would try
   first, tcap; below tcap the result is exact.  The triangles' bound comes
   first: the boundary vertices then sweep only up to it (in practice it is
   usually well below tcap, and the swept boxes, hence the hash, stay
   small). */
static double bp__step_bound(bp__solver *S, const double *x, const double *v, double tcap)
{
    bp__eval_task T;
    double tmax = HUGE_VAL;
    uint32_t c;
    memset(&T, 0, sizeof T);
    T.S = S;
    T.x = x;
    T.dir = v;
    S->bclip = 0;
    S->par.run(S->par.user, bp__step_tri_task, &T, S->nchunk_t);
    for (c = 0; c < S->nchunk_t; c++) if (S->part[c] < tmax) tmax = S->part[c];
    if (tmax > tcap) tmax = tcap;
    if (!S->barrier) return tmax;
    /* "In the extremely unlikely case that tmax = inf, it is set to a large
       positive value" (sec 3.4.2): here, the time to move 100 chart sizes. */
    if (tmax == HUGE_VAL) {
        double vmax = 0;
        uint32_t i;
        for (i = 0; i < 2 * S->nv; i++) if (fabs(v[i]) > vmax) vmax = fabs(v[i]);
        tmax = vmax > 0 ? 100 * S->mean_edge * S->nb / vmax : 1;
    }
    /* every boundary vertex enters the cells its swept segment's box covers */
    bp__step_hash(S, x, v, tmax);
    T.tmax = tmax;
    bp__par_run(&S->par, bp__step_edge_task, &T, S->nchunk_b, S->nb);
    for (c = 0; c < S->nchunk_b; c++) if (S->part_b[c] < tmax) tmax = S->part_b[c];
    S->bclip = tmax < T.tmax;             /* (>>newton: the model's wider barrier) */
    return tmax;
}

/* >>lbfgs ==================================================================

   Sec 3.4 and 3.5.  Each iteration: (1) energy and gradient, (2) a search
   direction, (3) the step bound tmax, (4) a backtracking line search from
   min(1, 0.9 tmax) that accepts the first t with sufficient decrease
   (Armijo: f(x + t v) <= f(x) + 1e-4 t g.v) and an exactly valid map, (5)
   the convergence test.  The direction is L-BFGS (Algorithm 1, memory m,
   initial scaling s.y / y.y; by default with the preconditioner below),
   plain gradient descent for comparison, or projected Newton (>>newton).
   Floating point cannot defeat the guarantee: the step bound is computed in
   floating point, so every accepted step is re-checked with the exact
   predicates -- every triangle positive, no two boundary edges meeting,
   exactly one counter-clockwise loop, which for one chart is all of
   bp_check (see >>check for why the loop count completes it) -- and halved
   until the check passes.  The start map itself is checked with bp_check
   before the first iteration, whoever computed it.  The iteration itself,
   in named phases, follows the directions (>>optimize). */

/* Preconditioning (beyond the dissertation).  Algorithm 1 starts each
   L-BFGS direction from a scalar multiple of the identity, H0 = (s.y / y.y) I,
   which ignores the mesh: a gradient step moves one vertex without its
   neighbours, and thousands of iterations pass before the map relaxes.  A
   better H0 is the inverse of the cotangent Laplacian K of the rest shape,
   the Hessian of the Dirichlet energy sum A_t |J_t|^2 (up to a factor 2).
   It is not the Hessian of the symmetric Dirichlet energy (near an isometry
   that is about 4 K on stretches and 0 on rotations, see docs/math.md), but
   it has the mesh's structure: K^-1 moves whole neighbourhoods together,
   and the scale sigma below absorbs the constant.  The same idea drives
   the blended quasi-Newton method of Zhu et al. (2018).  K is factored
   once per chart with the sparse LDL^T above (regularized by 1e-8 of its
   mean diagonal, since a free map can translate), and H0 = K^-1 / sigma
   with the scale sigma = s.y / s.K s fitted to the latest curvature pair. */

static void bp__sparse_free(const bp_allocator *a, bp__sparse *A)
{
    bp__free(a, A->colp); bp__free(a, A->row); bp__free(a, A->val);
    memset(A, 0, sizeof *A);
}

/* K of the chart's rest shape: for each triangle and each corner i with
   opposite edge (j, k), 1/2 cot(theta_i) couples j and k (the linear FEM
   stiffness matrix, positive semi-definite for any triangle shapes):

       K_jk -= w_i,   K_jj += w_i,   K_kk += w_i,   w_i = 1/2 cot(theta_i),

   and every diagonal gains the regularizer below.  K is assembled
   straight into its compressed columns, on the solver's threads, in three
   passes (a triplet list sorted by column was 78 ms of serial work on a
   132K-face chart's two-thread run, docs/performance.md sec 6.33):
     1. per triangle chunk, the three weights w of each triangle;
     2. per vertex chunk, v's rows (bp__vertex_col): v and the other
        corners of the triangles around it (the solver's corner lists),
        sorted, duplicates dropped;
     3. per vertex chunk, v's values: each entry the sum of its
        contributions in triangle order (corner order within a triangle),
        started from -0 so that the first contribution is taken as it is.
   Each entry's sum runs in the order the serial triplet assembly it
   replaced summed it (triangle by triangle; tests/bpt_triplets.h keeps
   that assembly, and test_tutte (c) compares the two bit for bit), and
   the regularizer's mean diagonal is one serial sum over the weights in
   that order, so K has the same bits on any number of threads. */
/* The rows of vertex v's column in a matrix on the chart's edges: v, the
   other two corners of every triangle around v (the solver's corner
   lists), and the nx extra vertices xl (NULL: none), sorted, repeats
   dropped, into col (room for 2 x v's corners + 1 + nx); returns their
   count.  With pins (pidx not NULL) a pinned v has only itself and a
   pinned neighbour is left out.  Newton's H (>>newton) and the
   preconditioner's K below both take their patterns from it. */
static uint32_t bp__vertex_col(const bp__solver *S, uint32_t v, const uint32_t *pidx, const uint32_t *xl, uint32_t nx,
                               uint32_t *col)
{
    uint32_t m = 0, p, k, q;
    col[m++] = v;
    if (!pidx || pidx[v] == BP__NONE) {
        for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++)
            for (k = 1; k <= 2; k++) {
                uint32_t u = S->tri[3 * (size_t)(S->vc_list[p] / 3) + (S->vc_list[p] % 3 + k) % 3];
                if (!pidx || pidx[u] == BP__NONE) col[m++] = u;
            }
        for (q = 0; q < nx; q++) col[m++] = xl[q];
    }
    bp__u32_sort(col, m);
    for (k = 1, q = 1; q < m; q++)
        if (col[q] != col[k - 1]) col[k++] = col[q];
    return k;
}

/* The position of row r in a sorted column of m rows that holds it: the
   count of rows below r, without branches for a short column (a binary
   search's branches were mispredicted at every step, half of pass (2)). */
static uint32_t bp__pattern_pos(const uint32_t *col, uint32_t m, uint32_t r)
{
    uint32_t q, pos = 0;
    if (m > 64) return bp__lower_bound(col, 0, m, r);
    for (q = 0; q < m; q++) pos += col[q] < r;
    return pos;
}

typedef struct bp__lap_task {
    const bp__solver *S;
    const double *wxy;            /* rest triangles (w, x, y)               */
    const uint32_t *pidx;         /* pins (NULL: none)                      */
    double *w;                    /* 3 per triangle: 1/2 cot of each corner */
    uint32_t *gr, *glen;          /* v's rows at gr + 2 vc_start[v] + v     */
    bp__sparse *K;
    double diag;                  /* sum of K's diagonal, before the regularizer */
} bp__lap_task;

static void bp__lap_weights(void *task, uint32_t c)
{
    bp__lap_task *T = (bp__lap_task *)task;
    uint32_t f, f1 = bp__chunk_at(T->S->nt, T->S->nchunk_t, c + 1);
    for (f = bp__chunk_at(T->S->nt, T->S->nchunk_t, c); f < f1; f++) {
        const double *r = T->wxy + 3 * (size_t)f;      /* F1=(0,0) F2=(w,0) F3=(x,y) */
        double P[3][2], area2 = r[0] * r[2];
        int i;
        P[0][0] = 0; P[0][1] = 0; P[1][0] = r[0]; P[1][1] = 0; P[2][0] = r[1]; P[2][1] = r[2];
        for (i = 0; i < 3; i++) {
            int j = (i + 1) % 3, k = (i + 2) % 3;
            double ux = P[j][0] - P[i][0], uy = P[j][1] - P[i][1], vx = P[k][0] - P[i][0], vy = P[k][1] - P[i][1];
            T->w[3 * (size_t)f + i] = 0.5 * (ux * vx + uy * vy) / area2;      /* 1/2 cot(theta_i) */
        }
    }
}

static int bp__lap_pinned(const bp__lap_task *T, uint32_t v) { return T->pidx && T->pidx[v] != BP__NONE; }

/* Pass 2: the rows of column v.  A pinned vertex keeps only its diagonal,
   and a free one no coupling to a pinned one. */
static void bp__lap_cols(void *task, uint32_t c)
{
    bp__lap_task *T = (bp__lap_task *)task;
    const bp__solver *S = T->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1);
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++)
        T->glen[v] = bp__vertex_col(S, v, T->pidx, NULL, 0, T->gr + 2 * (size_t)S->vc_start[v] + v);
}

/* Pass 3: the values of column v, each added where its row sits, then
   the regularizer: 1e-8 of the mean diagonal (a free map can translate),
   and on a pinned vertex the mean diagonal alone.  K is then block
   diagonal, K_ff (free rows and columns of the Laplacian) and a diagonal
   on the pinned ones, so K^-1 maps a vector that is zero on the pinned
   coordinates to one that is zero there too (see >>pins). */
static void bp__lap_values(void *task, uint32_t c)
{
    bp__lap_task *T = (bp__lap_task *)task;
    const bp__solver *S = T->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1), p, q, k;
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        const uint32_t *col = T->gr + 2 * (size_t)S->vc_start[v] + v;
        uint32_t m = T->glen[v], c0 = T->K->colp[v], dpos = 0;
        double *val = T->K->val + c0;
        memcpy(T->K->row + c0, col, m * sizeof(uint32_t));
        for (q = 0; q < m; q++) { val[q] = -0.0; if (col[q] == v) dpos = q; }
        if (!bp__lap_pinned(T, v))
            for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++) {
                uint32_t t = S->vc_list[p] / 3, cv = S->vc_list[p] % 3;
                const double *w = T->w + 3 * (size_t)t;
                for (k = 0; k < 3; k++) {                 /* corner k's weight, in corner order */
                    uint32_t u;
                    if (k == cv) continue;
                    val[dpos] += w[k];                    /* v is an end of corner k's edge */
                    u = S->tri[3 * (size_t)t + 3 - k - cv];   /* the edge's other end */
                    if (!bp__lap_pinned(T, u)) val[bp__pattern_pos(col, m, u)] -= w[k];
                }
            }
        val[dpos] += (bp__lap_pinned(T, v) ? 1 : 1e-8) * T->diag / S->nv;   /* (as the triplets had it) */
    }
}

static bp_status bp__laplacian(const bp_allocator *a, const bp__solver *S, const double *rest_wxy,
                               const uint32_t *pidx, bp__sparse *K, bp__factor *F, const uint32_t *order,
                               const bp__ndnode *tree)
{
    bp__lap_task T;
    size_t f, w = 0, nslot = 6 * (size_t)S->nt + S->nv;
    uint32_t v, bad;
    double diag = 0;
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    memset(&T, 0, sizeof T);
    T.S = S;
    T.wxy = rest_wxy;
    T.pidx = pidx;
    T.K = K;
    T.w = (double *)bp__alloc_array(a, 3 * (size_t)S->nt + 1, sizeof(double));
    T.gr = (uint32_t *)bp__alloc_array(a, nslot + 1, sizeof(uint32_t));
    T.glen = (uint32_t *)bp__alloc_array(a, (size_t)S->nv + 1, sizeof(uint32_t));
    K->n = S->nv;
    K->colp = (uint32_t *)bp__alloc_array(a, (size_t)S->nv + 1, sizeof(uint32_t));
    if (!T.w || !T.gr || !T.glen || !K->colp || nslot > 0xfffffff0u) goto done;
    S->par.run(S->par.user, bp__lap_weights, &T, S->nchunk_t);
    for (f = 0; f < 3 * (size_t)S->nt; f++) diag += 2 * T.w[f];        /* the order of the serial sum */
    T.diag = diag;
    S->par.run(S->par.user, bp__lap_cols, &T, S->nchunk_v);
    for (v = 0; v < S->nv; v++) { K->colp[v] = (uint32_t)w; w += T.glen[v]; }
    K->colp[S->nv] = (uint32_t)w;
    K->row = (uint32_t *)bp__alloc_array(a, w + 1, sizeof(uint32_t));
    K->val = (double *)bp__alloc_array(a, w + 1, sizeof(double));
    if (!K->row || !K->val) goto done;
    S->par.run(S->par.user, bp__lap_values, &T, S->nchunk_v);
    st = BP_OK;
done:
    bp__free(a, T.w); bp__free(a, T.gr); bp__free(a, T.glen);
    if (st != BP_OK) return st;
    K->symmetric = 1;
    K->super1 = BP__SUPER_SCALAR;
    st = bp__factorize_order(a, K, F, &bad, &S->par, order, tree);     /* order: the start map's, or NULL */
    if (st == BP_OK && (!bp__factor_single(a, F, &S->par) || !bp__solve_plan(a, F))) st = BP_ERR_OUT_OF_MEMORY;
    return st;
}

/* s.K s (s interleaved xy), by column chunks whose partial sums are added
   in order (see >>threads). */
typedef struct bp__quad_task { const bp__sparse *K; const double *s; double *part; uint32_t nc; } bp__quad_task;
#define BP__QUAD_CHUNK 2048u

static void bp__quad_task_run(void *task, uint32_t c)
{
    bp__quad_task *T = (bp__quad_task *)task;
    const bp__sparse *K = T->K;
    const double *s = T->s;
    uint32_t j, p, j1 = bp__chunk_at(K->n, T->nc, c + 1);
    double sum = 0;
    for (j = bp__chunk_at(K->n, T->nc, c); j < j1; j++)
        for (p = K->colp[j]; p < K->colp[j + 1]; p++)
            sum += K->val[p] * (s[2 * (size_t)K->row[p]] * s[2 * (size_t)j] +
                                s[2 * (size_t)K->row[p] + 1] * s[2 * (size_t)j + 1]);
    T->part[c] = sum;
}

static double bp__quad_form(const bp__sparse *K, const double *s, const bp__par *par, double *part)
{
    bp__quad_task T;
    uint32_t c, nc = bp__nchunks(K->n, BP__QUAD_CHUNK);
    double sum = 0;
    T.nc = nc;
    T.K = K;
    T.s = s;
    T.part = part;
    par->run(par->user, bp__quad_task_run, &T, nc);
    for (c = 0; c < nc; c++) sum += part[c];
    return sum;
}

/* The rest shapes of the triangles of chunk c: M^-1 and the weight
   before its normalization, the flattened (w, x, y) in wxy, and in bad[c]
   the chunk's first triangle whose importance is not positive and finite
   (BP__NONE: none).  Each task writes its own triangles, so the chunks may
   run on any threads (bp__solver_chart_par). */
typedef struct bp__rest_task {
    bp__solver      *S;
    const bp_chart  *ch;
    const bp_mesh   *m;
    const double    *importance;
    double          *wxy;
    uint32_t        *bad;
} bp__rest_task;

static void bp__rest_task_run(void *task, uint32_t c)
{
    bp__rest_task *T = (bp__rest_task *)task;
    bp__solver *S = T->S;
    uint32_t t, t1 = bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    T->bad[c] = BP__NONE;
    for (t = bp__chunk_at(S->nt, S->nchunk_t, c); t < t1; t++) {
        double w, px, py, imp = T->importance ? T->importance[T->ch->face[t]] : 1;
        bp__chart_rest(T->ch, T->m, t, &w, &px, &py);
        /* importance I (eq 4.1): singular values scaled by I^-1/2 (the rest
           shape grows by sqrt(I)) and the energy weighted by I */
        if (!(imp > 0) || !(imp < HUGE_VAL)) { T->bad[c] = t; return; }
        bp__rest_inverse(w, px, py, 1 / sqrt(imp), &S->rest[t]);
        S->rest[t].weight = 0.5 * w * py * imp;
        T->wxy[3 * (size_t)t] = w; T->wxy[3 * (size_t)t + 1] = px; T->wxy[3 * (size_t)t + 2] = py;
    }
}

/* The solver of one chart, set up as bp_chart_optimize uses it (and as the
   tests check it): rest shapes of sec 3.1 with the importance of eq 4.1,
   weights E_D = sum (A_t / mean area) E_t (so E_D / nt is the area-weighted
   mean the report shows), the energy, and the barrier width eps -- a
   quarter of the mean 3D boundary edge (sec 3.3) unless o->epsilon is set.
   rest_wxy (3 per triangle, may be NULL) receives the flattened triangles
   (w, x, y) for the preconditioner.  On failure the solver is freed.  The
   rest shapes are made on par's threads, in chunks of triangles; the areas
   are added in triangle order after them, so the weights have the same
   bits on any threads.  bp__solver_chart: the same on the caller alone. */
static bp_status bp__solver_chart_par(bp__solver *S, const bp_allocator *a, const bp_chart *ch, const bp_mesh *m,
                                      const bp_options *o, double *rest_wxy, const bp__par *par, bp_error *err)
{
    uint32_t t, L, k, c;
    double total_area = 0, len = 0;
    int ok;
    bp__rest_task T;
    if (bp__solver_init(S, a, ch->num_vertices, ch->num_triangles, ch->triangles, ch->num_loops,
                        ch->loop_start, ch->loop_vertices) != BP_OK)
        return bp__oom(err, "optimizing a chart");
    S->energy = o->energy;
    S->barrier = !o->no_barrier;
    T.S = S; T.ch = ch; T.m = m; T.importance = o->importance;
    T.wxy = rest_wxy ? rest_wxy : (double *)bp__alloc_array(a, 3 * (size_t)S->nt + 1, sizeof(double));
    T.bad = (uint32_t *)bp__alloc_array(a, (size_t)S->nchunk_t + 1, sizeof(uint32_t));
    if (!T.wxy || !T.bad) {
        if (!rest_wxy) bp__free(a, T.wxy);
        bp__free(a, T.bad);
        bp__solver_free(S);
        return bp__oom(err, "optimizing a chart");
    }
    par->run(par->user, bp__rest_task_run, &T, S->nchunk_t);
    for (c = 0; c < S->nchunk_t && T.bad[c] == BP__NONE; c++) {}
    for (t = 0; c == S->nchunk_t && t < S->nt; t++) total_area += 0.5 * T.wxy[3 * (size_t)t] * T.wxy[3 * (size_t)t + 2];
    if (c < S->nchunk_t) {                         /* the first bad triangle, as a serial loop finds it */
        uint32_t f = ch->face[T.bad[c]];
        if (!rest_wxy) bp__free(a, T.wxy);
        bp__free(a, T.bad);
        bp__solver_free(S);
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_TRIANGLE, f, -1, 0,
                        "importance of mesh triangle %u is %g: it must be positive and finite", f, o->importance[f]);
    }
    bp__free(a, T.bad);
    for (t = 0; t < S->nt; t++) S->rest[t].weight *= S->nt / total_area;
    for (L = 0; L < S->nloops; L++)
        for (k = S->loop_start[L]; k < S->loop_start[L + 1]; k++) {
            uint32_t va = S->loop_vertices[k], vb = S->loop_vertices[k + 1 < S->loop_start[L + 1] ? k + 1 : S->loop_start[L]];
            len += bp__dist3(bp__pos(m, ch->vertex[va]), bp__pos(m, ch->vertex[vb]));
        }
    S->mean_edge = len / S->nb;
    S->eps = o->epsilon > 0 ? o->epsilon : S->mean_edge / 4;
    ok = o->epsilon > 0 || bp__start_thin_eps(a, ch, T.wxy, &S->eps);      /* thin charts, >>start */
    if (!rest_wxy) bp__free(a, T.wxy);
    if (!ok) {
        bp__solver_free(S);
        return bp__oom(err, "optimizing a chart");
    }
    return BP_OK;
}

static bp_status bp__solver_chart(bp__solver *S, const bp_allocator *a, const bp_chart *ch, const bp_mesh *m,
                                  const bp_options *o, double *rest_wxy, bp_error *err)
{
    bp__par serial = bp__par_serial();
    return bp__solver_chart_par(S, a, ch, m, o, rest_wxy, &serial, err);
}

/* The L-BFGS vector work in chunks (see >>threads).  One pass over n
   doubles computes, on each chunk,
       out = c0 base + c_1 w_1 + ... + c_nw w_nw     (out NULL: nothing;
                                                     base NULL: 0)
   term by term in that order, and then the dot products A_k . B_k
   (k < nd) of the vectors as they are after that; the partial dots of the
   chunks are added in chunk order.  out may be base (the update is
   elementwise).  A pass costs one join and one sweep of its vectors, so
   the solver asks for as much as it can in each.
   The chunks hold whole xy pairs: for a vector of 2 nv coordinates, chunk
   c is the x and y of the vertices of the gradient gather's chunk c, so
   each core meets again the vertices it gathered. */
#define BP__VEC_CHUNK 4096u

static uint32_t bp__vec_nchunks(uint32_t n)
{
    return bp__nchunks(n / 2 + n % 2, BP__VEC_CHUNK / 2);
}

/* The first coordinate of chunk k of nc (k = nc: n). */
static uint32_t bp__vec_chunk_at(uint32_t n, uint32_t nc, uint32_t k)
{
    return k < nc ? 2 * bp__chunk_at(n / 2, nc, k) : n;
}

typedef struct bp__vec_task {
    double             *out;
    const double       *base;
    double              c0;
    const double *const *w;
    const double       *c;
    const double *const *A, *const *B;
    uint32_t            nw, nd, n, nc;
    double             *part;            /* nd per chunk                     */
} bp__vec_task;

static void bp__vec_task_run(void *task, uint32_t k)
{
    bp__vec_task *T = (bp__vec_task *)task;
    uint32_t i, j, i0 = bp__vec_chunk_at(T->n, T->nc, k), i1 = bp__vec_chunk_at(T->n, T->nc, k + 1);
    if (T->out) {
        if (T->base) for (i = i0; i < i1; i++) T->out[i] = T->c0 * T->base[i];
        else for (i = i0; i < i1; i++) T->out[i] = 0;
        for (j = 0; j < T->nw; j++) {
            const double *w = T->w[j], c = T->c[j];
            for (i = i0; i < i1; i++) T->out[i] += c * w[i];
        }
    }
    for (j = 0; j < T->nd; j++) {
        const double *a = T->A[j], *b = T->B[j];
        double d0 = 0, d1 = 0, d2 = 0, d3 = 0;
        for (i = i0; i + 4 <= i1; i += 4) {      /* four sums: not one long chain of dependent adds */
            d0 += a[i] * b[i];
            d1 += a[i + 1] * b[i + 1];
            d2 += a[i + 2] * b[i + 2];
            d3 += a[i + 3] * b[i + 3];
        }
        for (; i < i1; i++) d0 += a[i] * b[i];
        T->part[(size_t)k * T->nd + j] = (d0 + d1) + (d2 + d3);
    }
}

/* Runs one pass; dot[k] receives A_k . B_k.  part: nd per chunk. */
static void bp__vec_pass(const bp__par *par, double *part, uint32_t n, double *out, double c0, const double *base,
                         uint32_t nw, const double *const *w, const double *c,
                         uint32_t nd, const double *const *A, const double *const *B, double *dot)
{
    bp__vec_task T;
    uint32_t k, j, nc = bp__vec_nchunks(n);
    T.nc = nc;
    T.out = out; T.base = base; T.c0 = c0;
    T.w = w; T.c = c; T.nw = nw;
    T.A = A; T.B = B; T.nd = nd;
    T.part = part;
    T.n = n;
    par->run(par->user, bp__vec_task_run, &T, nc);
    for (j = 0; j < nd; j++) {
        double s = 0;
        for (k = 0; k < nc; k++) s += part[(size_t)k * nd + j];
        dot[j] = s;
    }
}

/* The common case: out = base + c w (base NULL: c w), with up to one dot. */
static void bp__vec_axpy(const bp__par *par, double *part, uint32_t n, double *out, const double *base, double c,
                         const double *w, const double *a, const double *b, double *dot)
{
    bp__vec_pass(par, part, n, out, 1, base, 1, &w, &c, a ? 1u : 0u, &a, &b, dot);
}

/* The L-BFGS memory (Algorithm 1; Nocedal & Wright, Algorithm 7.4): the
   last m pairs s = x_new - x, y = g_new - g in a ring of slots, and the
   search direction v = -H g by the two-loop recursion
       q = g;  for j newest..oldest: alpha_j = rho_j s_j.q,  q -= alpha_j y_j
       r = H0 q;  for j oldest..newest: beta_j = rho_j y_j.r,  r += (alpha_j - beta_j) s_j
   with rho_j = 1 / s_j.y_j.  Written out, every dot product the loops take
   is a dot with g, with p = K^-1 q, or between two stored vectors:
       s_j.q = s_j.g - sum_{l newer than j} alpha_l s_j.y_l
       y_j.r = scale y_j.p + sum_{l older than j} (alpha_l - beta_l) s_l.y_j
   (H0 = scale K^-1).  The products s_i.y_j are kept in the Gram matrix SY,
   to which each new pair adds its row and column, so the recursion takes
   four passes over the vectors, (a) s_j.g, (b) q, (c) y_j.p, (d) v = -r
   with g.v, instead of 2m + 2, with scalar work in between (the
   "vector-free" form of Chen, Wang and Zhou, NIPS 2014).  The result is
   the recursion's, up to rounding; tests/test_optimize.c compares the two. */
typedef struct bp__lbfgs {
    int hist, nh, head;               /* slots, pairs stored, next slot   */
    uint32_t n;                       /* vector length                    */
    double *s, *y;                    /* hist vectors each                */
    double *rho, *sy, *yy, *SY;       /* per slot; SY(i, j) = s_i . y_j   */
    double *alpha, *coef, *sg, *yr;   /* per age (0: the newest pair)     */
    double *vc, *vd;                  /* a pass's coefficients and dots   */
    const double **vA, **vB;          /* a pass's vectors                 */
    double *part;                     /* partial dots: 2 hist + 2 per chunk */
} bp__lbfgs;

static void bp__lbfgs_free(const bp_allocator *a, bp__lbfgs *L)
{
    bp__free(a, L->s); bp__free(a, L->y); bp__free(a, L->rho); bp__free(a, (void *)L->vA); bp__free(a, L->part);
    memset(L, 0, sizeof *L);
}

static int bp__lbfgs_init(const bp_allocator *a, bp__lbfgs *L, int hist, uint32_t n)
{
    size_t h1 = (size_t)hist + 1;
    memset(L, 0, sizeof *L);
    L->hist = hist;
    L->n = n;
    L->s = (double *)bp__alloc_array(a, (size_t)n * (hist ? hist : 1), sizeof(double));
    L->y = (double *)bp__alloc_array(a, (size_t)n * (hist ? hist : 1), sizeof(double));
    L->rho = (double *)bp__alloc_array(a, 10 * h1 + h1 * h1, sizeof(double));
    L->vA = (const double **)bp__alloc_array(a, 4 * h1, sizeof(const double *));
    L->part = (double *)bp__alloc_array(a, 2 * h1 * ((size_t)bp__vec_nchunks(n) + 1), sizeof(double));
    if (!L->s || !L->y || !L->rho || !L->vA || !L->part) { bp__lbfgs_free(a, L); return 0; }
    L->sy = L->rho + h1; L->yy = L->sy + h1; L->alpha = L->yy + h1; L->coef = L->alpha + h1;
    L->sg = L->coef + h1; L->yr = L->sg + h1; L->vc = L->yr + h1; L->vd = L->vc + h1; L->SY = L->vd + 2 * h1;
    L->vB = L->vA + 2 * h1;
    return 1;
}

#define BP__S(L, k) ((L)->s + (size_t)(k) * (L)->n)
#define BP__Y(L, k) ((L)->y + (size_t)(k) * (L)->n)
#define BP__SLOT(L, j) (((L)->head - 1 - (j) + (L)->hist) % (L)->hist)   /* the pair of age j */

/* v = -H g (needs nh > 0); returns g.v.  K, KF: H0 = K^-1 / sigma with
   sigma = s.y / s.K s of the newest pair (pwork: 2n doubles, qpart: the
   quad form's partial sums); K NULL: H0 = (s.y / y.y) I. */
static double bp__lbfgs_direction(bp__lbfgs *L, const bp__par *par, const double *g, double *v,
                                  const bp__sparse *K, const bp__factor *KF, double *pwork, double *qpart)
{
    int j, l, nh = L->nh, nw = BP__SLOT(L, 0);
    uint32_t n = L->n;
    double scale, gv;
    for (j = 0; j < nh; j++) { L->vA[j] = BP__S(L, BP__SLOT(L, j)); L->vB[j] = g; }
    bp__vec_pass(par, L->part, n, NULL, 0, NULL, 0, NULL, NULL, (uint32_t)nh, L->vA, L->vB, L->sg);      /* (a) */
    for (j = 0; j < nh; j++) {
        double sq = L->sg[j];
        for (l = 0; l < j; l++) sq -= L->alpha[l] * L->SY[(size_t)BP__SLOT(L, j) * L->hist + BP__SLOT(L, l)];
        L->alpha[j] = L->rho[BP__SLOT(L, j)] * sq;
    }
    for (j = 0; j < nh; j++) { L->vA[j] = BP__Y(L, BP__SLOT(L, j)); L->vc[j] = -L->alpha[j]; }
    bp__vec_pass(par, L->part, n, v, 1, g, (uint32_t)nh, L->vA, L->vc, 0, NULL, NULL, NULL);              /* (b) */
    if (K) {
        scale = bp__quad_form(K, BP__S(L, nw), par, qpart) / L->sy[nw];
        bp__precondition(KF, par, v, v, pwork);
    } else {
        scale = L->sy[nw] / L->yy[nw];
    }
    for (j = 0; j < nh; j++) { L->vA[j] = BP__Y(L, BP__SLOT(L, j)); L->vB[j] = v; }
    bp__vec_pass(par, L->part, n, NULL, 0, NULL, 0, NULL, NULL, (uint32_t)nh, L->vA, L->vB, L->yr);      /* (c) */
    for (j = nh - 1; j >= 0; j--) {
        double yrj = scale * L->yr[j];
        for (l = nh - 1; l > j; l--) yrj += L->coef[l] * L->SY[(size_t)BP__SLOT(L, l) * L->hist + BP__SLOT(L, j)];
        L->coef[j] = L->alpha[j] - L->rho[BP__SLOT(L, j)] * yrj;
    }
    for (j = 0; j < nh; j++) { L->vA[j] = BP__S(L, BP__SLOT(L, j)); L->vc[j] = -L->coef[j]; }
    L->vB[0] = g; L->vB[1] = v;
    bp__vec_pass(par, L->part, n, v, -scale, v, (uint32_t)nh, L->vA, L->vc, 1, L->vB, L->vB + 1, &gv);  /* (d) */
    return gv;
}

/* Store s = x_new - x and y = g_new - g in the slot of the oldest pair: s
   with s.s in one pass, then y with y.y, s.y and the new row and column of
   SY in another.  The pair is dropped when the curvature s.y is not
   positive; the oldest pair is then gone too (its slot was written). */
static void bp__lbfgs_push(bp__lbfgs *L, const bp__par *par, const double *x, const double *xn, const double *g,
                           const double *gn)
{
    double ss, *sp, *yp;
    int j, nd = 2;
    if (!L->hist) return;
    sp = BP__S(L, L->head);
    yp = BP__Y(L, L->head);
    bp__vec_axpy(par, L->part, L->n, sp, xn, -1, x, sp, sp, &ss);
    L->vA[0] = yp; L->vB[0] = yp;
    L->vA[1] = sp; L->vB[1] = yp;
    for (j = 0; j < L->nh; j++)
        if (BP__SLOT(L, j) != L->head) {
            L->vA[nd] = BP__S(L, BP__SLOT(L, j)); L->vB[nd++] = yp;    /* s_j . y */
            L->vA[nd] = sp; L->vB[nd++] = BP__Y(L, BP__SLOT(L, j));    /* s . y_j */
        }
    L->vc[0] = -1;
    bp__vec_pass(par, L->part, L->n, yp, 1, gn, 1, &g, L->vc, (uint32_t)nd, L->vA, L->vB, L->vd);
    if (L->vd[1] > 1e-12 * sqrt(ss * L->vd[0])) {
        int h = L->head;
        L->rho[h] = 1 / L->vd[1];
        L->sy[h] = L->vd[1];
        L->yy[h] = L->vd[0];
        L->SY[(size_t)h * L->hist + h] = L->vd[1];
        for (nd = 2, j = 0; j < L->nh; j++)
            if (BP__SLOT(L, j) != h) {
                L->SY[(size_t)BP__SLOT(L, j) * L->hist + h] = L->vd[nd++];
                L->SY[(size_t)h * L->hist + BP__SLOT(L, j)] = L->vd[nd++];
            }
        L->head = (h + 1) % L->hist;
        if (L->nh < L->hist) L->nh++;
    } else if (L->nh == L->hist) {
        L->nh--;
    }
}
#undef BP__S
#undef BP__Y
#undef BP__SLOT

/* >>newton =================================================================

   Projected Newton (beyond the dissertation; BP_DIRECTION_NEWTON).  L-BFGS
   learns the curvature from the last few steps and needs 1,000-3,000
   iterations on large charts; Newton's method takes it from the energy
   itself and needs tens.  Each iteration solves
       (H + delta I) v = -g,
   H the sum of every triangle's projected Hessian (>>hessian) plus a
   positive semidefinite part of the barrier's, and hands v to the same
   step bound, line search and exact checks as every other direction (the
   first trial step is 1, clipped at 0.9 of the bound), so every iterate
   stays bijective (and after an accepted full step, longer ones are
   tried: below).  H is positive semidefinite by construction; the shift
   delta = 1e-8 mean diag(H) makes it definite (translations, and the
   rotation of a chart at a rotation-invariant minimum, are exact null
   directions).  If the factorization still meets a pivot that is not
   positive and finite, or v is not a descent direction, the iteration
   falls back to a gradient step (the caller's code).

   The barrier.  E_B = sum f(d) over boundary vertex / edge pairs closer
   than eps, f(d) = (eps / d - 1)^2 (>>barrier), has the Gauss-Newton part
   f''(d) grad d grad d^T, f'' = 2 eps^2 / d^4 + 4 (eps / d - 1) eps / d^3
   >= 0, with grad d = c_i n on the vertex (c = 1) and the edge's ends
   (c = -(1 - s), -s; n the unit direction from the closest point); the
   other part, f'(d) times the Hessian of the distance, couples a vertex's
   slide along its edge with the edge's turn, so in mode 3 each pair gives
   its whole 6x6 Hessian projected to PSD instead (bp__barrier_pair_hessian,
   >>barrier; BP__BARRIER_FULL 0: the Gauss-Newton part alone).  Its pairs join a vertex to an edge anywhere on the boundary,
   outside the mesh's pattern, and they come and go as the map moves.
   Four treatments were measured (BP__NEWTON_BARRIER; docs/performance.md
   sec 5):
     0  none: the barrier is left to the line search;
     1  the three diagonal 2x2 blocks f'' c_i^2 n n^T of each pair (each
        positive semidefinite, pattern fixed), which also penalize moving
        the vertex and its edge together: camel_b stalls at 4.4;
     2  those blocks in the factored matrix and the full terms through
        conjugate gradients preconditioned by it (30 solves an iteration);
     3  (default) the full terms in the pattern: the vertex couplings of
        every pair closer than 3 eps join the pattern, which is then
        analysed again (bp__newton_grow); the pattern only grows, at most
        once every 8 factorizations, and until a pair's couplings are in it
        the pair gives its diagonal blocks.  Every term is positive
        semidefinite either way.

   A wider barrier in the model (docs/performance.md sec 6.9).  The
   barrier is 0 beyond eps, so the model cannot see two parts of the
   boundary that are further apart than eps: a full Newton step runs a
   boundary vertex through an edge, the step bound clips it to 0.9 of the
   collision, and the next iterations creep (horse_cut, whose cut's two
   sides lie side by side: 22 of its first 29 steps clipped by the
   boundary; hilbert: 220 of 243).  So after a step clipped by the
   boundary's step bound (bp__step_bound sets S->bclip) the matrix takes
   the Gauss-Newton terms of the barrier of width em = BP__NEWTON_WIDE
   eps = 3 eps, f''(d; em) w w^T for every pair closer than em (their
   couplings are in the pattern already: those within 3 eps grow it; a
   width above 3 eps would give the pairs beyond only their diagonal
   blocks), in place of width eps's.  The
   energy, the gradient, the step bound and the checks are untouched:
   only the matrix changes, by a positive semidefinite term (f''(d; e) =
   2 e (3 e - 2 d) / d^4 grows with e for d < e), so the direction is
   still one of descent; it is a proxy, not Newton's, and so only used
   while the boundary clips (always: hilbert needs 770 iterations instead
   of 185 to SCAF's energy, the extra stiffness near the minimum slowing
   the end; and from the first direction on, beetle's first steps go
   worse).  Measured (one thread, CPU to SCAF's E x 1.001): horse_cut
   29 -> 23 iterations, hilbert 185 -> 162; bimba, face and camelhead
   the same iterations.

   The system is the 2nv x 2nv matrix with the mesh Laplacian's pattern in
   2x2 blocks (x and y of a vertex interleaved, as in the map), plus the
   barrier's couplings.  Its pattern is built once per chart (and again
   when the barrier grows it), with the position of each triangle's 36
   entries in it; the first factorization of a pattern runs bp__factorize
   (ordering and symbolic analysis: the elimination tree and the exact
   pattern of L) and every later one only its numeric phase,
   bp__fact_numeric, on the same pattern of L (bp__newton_refactor), whose
   rows run in the same phases along the dissection tree, so the result is
   the same bits on any number of threads.  The triangles' Hessians are
   computed in parallel chunks, each into its own slots, and added into the
   matrix in triangle order.

   Pins (>>pins) are fixed variables here too: a held vertex's rows and
   columns are those of the identity (bp__newton_pins), its right-hand side
   is 0, and the direction is exactly 0 there; the homotopy's pull adds its
   own curvature 2 w to the pinned diagonal.

   Two things make an iteration go further for its factorization (docs/
   performance.md sec 6.2): a full step accepted at once is followed by
   longer trial steps t = 2, 4, ... (bp__opt_extend, >>optimize), since the
   quadratic model of a crushed triangle's 1/s^2 stops far short of the
   line's minimum; and near the minimum the factor of an earlier H
   preconditions conjugate gradients on the current one instead of a new
   factorization (bp__newton_reuse_solve, below).  With the
   supernodal factorization (sec 6.1) an iteration costs 7-24 L-BFGS ones,
   and on issue 15's ten meshes (sec 6.6) Newton reaches SCAF's energy
   3.4-6.7x sooner than the preconditioned L-BFGS on the charts of 22K-89K
   triangles, but 1.3x later on the 10K-triangle shark (on lucy, 1.9x
   sooner from the mean-value start, sec 6.10); so the default
   (BP_DIRECTION_DEFAULT, bp__opt_choose_newton in >>optimize) takes Newton
   for 20,000-99,999 triangles.
   bench/scaf_ratio.py (make bench-scaf) repeats the comparison. */

#ifndef BP__NEWTON_BARRIER
#define BP__NEWTON_BARRIER 3
#endif
#ifndef BP__BARRIER_FULL
#define BP__BARRIER_FULL 1            /* 0: the Gauss-Newton part only (measurements) */
#endif
#ifndef BP__NEWTON_WIDE
#define BP__NEWTON_WIDE 3.0       /* the model's barrier width after a boundary clip, in eps (1: off) */
#endif
#ifndef BP__NEWTON_CG_MAX
#define BP__NEWTON_CG_MAX 30
#endif
#ifndef BP__NEWTON_CG_TOL
#define BP__NEWTON_CG_TOL 1e-8
#endif

/* One barrier pair's Gauss-Newton term f'' w w^T: w = c_i n on vertices
   v[0] (c = 1), v[1] (c = -(1 - s)), v[2] (c = -s). */
typedef struct bp__bpair { uint32_t v[3]; double s, nx, ny, f2, K[36]; } bp__bpair;   /* K: >>barrier */
typedef struct bp__bnear { uint32_t v[3]; } bp__bnear;   /* a pair within 3 eps (its couplings) */

#define BP__HT 24u                    /* doubles per triangle in bp__newton.ht */
typedef struct bp__newton {
    bp__sparse H;                 /* 2nv x 2nv, full symmetric pattern      */
    bp__factor F;
    const bp__par *par;           /* the solves' threads (NULL: serial), set
                                     by bp__newton_direction               */
    int        factored;          /* ordering and pattern of L are known    */
    int        fvalid;            /* F holds the factor of an earlier H     */
    uint32_t  *tpos;              /* 9 per triangle: its 2x2 blocks in H.val */
    uint32_t  *dpos;              /* 4 per vertex: its 2x2 diagonal block   */
    double    *ht;                /* BP__HT per triangle: its Hessian's
                                     blocks (bp__newton_tri_task)          */
    double    *bd;                /* 3 per vertex: barrier block xx, xy, yy */
    double    *dg;                /* per vertex: its diagonal's part of the
                                     trace, written by the gather tasks   */
    double     delta;             /* the shift of the diagonal (assembly)   */
    double    *rhs, *z;
    double    *r, *p, *q;         /* conjugate gradients (the barrier pairs) */
    bp__vec    pairs;             /* bp__bpair: the barrier's pairs at x     */
    bp__vec    extra;             /* vertex couplings added to the pattern   */
    bp__vec    near;              /* bp__bnear: pairs within 3 eps at x      */
    int        since_grow;        /* directions since the pattern grew       */
    int        reused, cut;       /* consecutive reuses of F; the last line
                                     search had to shrink its first step     */
    int        wide;              /* the last step was clipped by the boundary
                                     step bound: the model's barrier is wider */
    long       nfact, nreuse, ncg, ntry; /* factorizations, directions from a
                                     reused factor, CG steps, reuse attempts
                                     (counts for tests and measurements)     */
    long       nkept;             /* analyses with a kept order (the same)   */
    long       ncloned;           /* ... of them copied from K1's (below)    */
    long       nhanded;           /* first factorizations handed over by the
                                     conformal start (bp__handoff)          */
    bp__handoff *given;           /* that start's factor, or NULL            */
    int        iso;               /* the isotropic phase is on (below)       */
    int        k1ok;              /* K1's pattern is H's, F1 analysed        */
    long       niso;              /* directions by the isotropic matrix      */
    bp__sparse K1;                /* its scalar matrix, nv x nv, and factor  */
    bp__factor F1;
    double    *b1;                /* 4 nv: the two coordinates' rhs, solution */
    double    *w;                 /* CG: F^-1 r                              */
    double    *part;              /* CG: the chunks' partial dots (bp__vec_pass) */
    uint32_t  *kperm, *kiperm;    /* the vertex order of the factor before the
                                     pattern grew, and its inverse (or NULL) */
    bp__ndnode ktree[BP__ND_NODES]; /* ... and its dissection tree          */
    int        oom;
    bp__solver *S;                /* for the chunk tasks                    */
    const double *x;
    const uint32_t *hold;         /* pins, chart vertex -> pin or BP__NONE:  */
    const uint32_t *pull;         /*   held fixed, or pulled with weight    */
    double     pull_w;            /*   pull_w (the homotopy, >>pins)        */
} bp__newton;

static void bp__newton_free(const bp_allocator *a, bp__newton *N)
{
    bp__sparse_free(a, &N->H);
    bp__factor_free(a, &N->F);
    bp__sparse_free(a, &N->K1);
    bp__factor_free(a, &N->F1);
    bp__free(a, N->b1);
    bp__free(a, N->tpos); bp__free(a, N->dpos); bp__free(a, N->ht); bp__free(a, N->bd); bp__free(a, N->dg);
    bp__free(a, N->rhs); bp__free(a, N->z);
    bp__free(a, N->r); bp__free(a, N->p); bp__free(a, N->q); bp__free(a, N->w); bp__free(a, N->part);
    bp__free(a, N->kperm); bp__free(a, N->kiperm);
    bp__free(a, N->pairs.data);
    bp__free(a, N->extra.data); bp__free(a, N->near.data);
    memset(N, 0, sizeof *N);
}

/* Position of entry (i, j) in the compressed columns (it must exist). */
static uint32_t bp__sparse_find(const bp__sparse *A, uint32_t i, uint32_t j)
{
    uint32_t lo = A->colp[j], hi = A->colp[j + 1];
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (A->row[mid] <= i) lo = mid; else hi = mid;
    }
    return lo;
}

/* Position of entry (i, j), or BP__NONE when the pattern lacks it. */
static uint32_t bp__sparse_has(const bp__sparse *A, uint32_t i, uint32_t j)
{
    uint32_t p = A->colp[j] < A->colp[j + 1] ? bp__sparse_find(A, i, j) : BP__NONE;
    return p != BP__NONE && A->row[p] == i ? p : BP__NONE;
}

/* The pattern of H (all values 0): the 2x2 blocks of the vertex graph G
   of the triangles' edges, every vertex's diagonal block and the vertex
   couplings in `extra` (barrier pairs met so far); and where each
   triangle's 3x3 blocks and each vertex's diagonal entries lie in it.
   Columns 2v and 2v+1 of H both hold the rows 2w, 2w+1 of every w in G's
   column v, so block (w, v) of H starts at
       colp[2v] + 2 (position of w in G's column v)
   and its entry (2w + a, 2v + b) lies a + b (colp[2v+1] - colp[2v]) after
   that: tpos keeps one position per block (9 per triangle).

   G is built column by column, without a global sort (issue 15: the
   triplets and their sort were 30 ms of serial time per call on bimba,
   three calls per chart).  Column v of G is v itself, the two other
   corners of every triangle around v (the solver's corner lists vc_start,
   vc_list) and the other ends of v's extra pairs: at most
   2 (corners of v) + 1 + (extra pairs of v) rows, so column v gets the
   slots from
       gp(v) = 2 vc_start[v] + v + xp[v]
   on (xp: the extra pairs per vertex, counted before).  Each column is
   listed there, sorted (bp__u32_sort) and its repeats dropped: the same
   sorted distinct rows the triplets gave.  Two parallel passes over the
   vertex chunks, with a prefix sum of the column lengths between them:
     (1) list, sort and count each column (bp__pattern_cols);
     (2) write H's two columns of each vertex, its diagonal positions dpos
         and the positions tpos of the blocks in its column -- the corners
         of v give every block (r, c) of a triangle with c = v's corner
         exactly once, so the chunks write disjoint entries of tpos
         (bp__pattern_place).
   The old pattern and its factor are freed first, so that a rebuild (the
   barrier growing the pattern) never holds two of them. */
typedef struct bp__pattern_task {
    bp__newton *N;
    const bp__solver *S;
    const uint32_t *xp, *xl;     /* extra pairs' other ends by vertex (CSR),
                                    NULL when there are none             */
    uint32_t *gr, *glen;         /* G's columns: v's rows at gr + gp(v)   */
} bp__pattern_task;

static size_t bp__pattern_at(const bp__pattern_task *T, uint32_t v)
{
    return 2 * (size_t)T->S->vc_start[v] + v + (T->xp ? T->xp[v] : 0);
}

/* Pass (1) for the vertices of chunk c. */
static void bp__pattern_cols(void *task, uint32_t c)
{
    bp__pattern_task *T = (bp__pattern_task *)task;
    const bp__solver *S = T->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1);
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++)
        T->glen[v] = bp__vertex_col(S, v, NULL, T->xp ? T->xl + T->xp[v] : NULL, T->xp ? T->xp[v + 1] - T->xp[v] : 0,
                                    T->gr + bp__pattern_at(T, v));
}

/* Pass (2) for the vertices of chunk c (H.colp is known).  H's values
   are left as allocated: every assembly zeroes v's columns before it
   gathers them (bp__newton_gather_task), and the isotropic phase never
   reads them, so their pages are first touched at Newton's first
   assembly, after it (face: 5 ms of page faults and zeroing off the
   start of the optimization). */
static void bp__pattern_place(void *task, uint32_t c)
{
    bp__pattern_task *T = (bp__pattern_task *)task;
    const bp__solver *S = T->S;
    bp__newton *N = T->N;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1), p, k, w;
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        const uint32_t *col = T->gr + bp__pattern_at(T, v);
        uint32_t m = T->glen[v], c0 = N->H.colp[2 * v], len = 2 * m;
        for (k = 0, w = c0; k < 2; k++)
            for (p = 0; p < m; p++) { N->H.row[w++] = 2 * col[p]; N->H.row[w++] = 2 * col[p] + 1; }
        w = c0 + 2 * bp__pattern_pos(col, m, v);
        for (k = 0; k < 4; k++) N->dpos[4 * (size_t)v + k] = w + k % 2 + (k / 2) * len;
        for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++) {
            uint32_t t = S->vc_list[p] / 3, cc = S->vc_list[p] % 3;
            for (k = 0; k < 3; k++)         /* block (k, cc) of triangle t */
                N->tpos[9 * (size_t)t + 3 * k + cc] = c0 + 2 * bp__pattern_pos(col, m, S->tri[3 * (size_t)t + k]);
        }
    }
}

/* A kept order.  When the barrier's pairs grow H's pattern (a few
   couplings between boundary vertices), the nested dissection of the old
   pattern is usually still one of the new: an ordering is a third of a
   symbolic analysis and more (bimba: 0.12 of 0.17 s on one thread), so
   the old factor's vertex order and tree are kept (taken from the factor
   before it is freed) and reused when bp__nd_keeps says that no new pair
   joins the two halves of a split, the property that makes the subtrees
   independent (and lets them run on several threads).  Otherwise a new
   order, as before.  Either way the same order on any number of threads.
   Before the first factorization the order to keep is the start map's
   (bp__opt_start_order), also when the pattern grows first. */
static void bp__newton_keep_order(bp__newton *N, const bp_allocator *a)
{
    if (!N->F.sn && N->kperm) return;            /* no factor yet: the start map's order stays */
    bp__free(a, N->kperm);
    bp__free(a, N->kiperm);
    N->kperm = N->kiperm = NULL;
    if (!N->F.sn || !N->F.sn->vperm || !N->F.sn->viperm || !N->F.tree[0].used) return;
    N->kperm = N->F.sn->vperm;                 /* taken: bp__factor_free skips NULL */
    N->kiperm = N->F.sn->viperm;
    N->F.sn->vperm = N->F.sn->viperm = NULL;
    memcpy(N->ktree, N->F.tree, sizeof N->ktree);
}

/* Whether the dissection tree (in the positions iperm gives) still
   separates the graph after adding the count vertex pairs: each pair,
   followed down from the root, must end with one vertex in a node's
   separator [b, hi) or both in an unsplit node, never one in each half. */
static int bp__nd_keeps(const bp__ndnode *tree, const uint32_t *iperm, const uint32_t *pairs, size_t count)
{
    size_t e;
    for (e = 0; e < count; e++) {
        uint32_t pu = iperm[pairs[2 * e]], pw = iperm[pairs[2 * e + 1]], k = 0;
        if (pu < tree[0].lo || pu >= tree[0].hi || pw < tree[0].lo || pw >= tree[0].hi) return 0;
        while (k < BP__ND_NODES && tree[k].used && tree[k].split && pu < tree[k].b && pw < tree[k].b) {
            if ((pu < tree[k].a) != (pw < tree[k].a)) return 0;
            k = 2 * k + (pu < tree[k].a ? 1 : 2);
        }
    }
    return 1;
}

/* The extra pairs by vertex: xp[v] .. xp[v+1] index v's other ends in xl
   (each pair (u, w) lists w under u and u under w).  Returns 0 out of
   memory. */
static int bp__pattern_extra(const bp_allocator *a, const bp__newton *N, uint32_t nv, uint32_t **xp_out, uint32_t **xl_out)
{
    const uint32_t *ex = (const uint32_t *)N->extra.data;
    size_t e, ne = N->extra.count;
    uint32_t v, *xp, *xl;
    *xp_out = xp = (uint32_t *)bp__calloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    *xl_out = xl = (uint32_t *)bp__alloc_array(a, 2 * ne, sizeof(uint32_t));
    if (!xp || !xl) return 0;
    for (e = 0; e < 2 * ne; e++) xp[ex[e] + 1]++;
    for (v = 0; v < nv; v++) xp[v + 1] += xp[v];
    for (e = 0; e < 2 * ne; e++) xl[xp[ex[e]]++] = ex[e ^ 1];
    for (v = nv; v > 0; v--) xp[v] = xp[v - 1];
    xp[0] = 0;
    return 1;
}

static bp_status bp__newton_pattern(bp__newton *N, const bp_allocator *a, bp__solver *S)
{
    uint32_t nv = S->nv, n = 2 * nv, v, *xp = NULL, *xl = NULL;
    size_t nslot = 6 * (size_t)S->nt + nv + 2 * N->extra.count, w = 0;
    bp__pattern_task T;
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    bp__sparse_free(a, &N->H);
    bp__newton_keep_order(N, a);
    bp__factor_free(a, &N->F);
    bp__sparse_free(a, &N->K1);                   /* the isotropic matrix follows H's pattern */
    bp__factor_free(a, &N->F1);
    N->k1ok = 0;
    N->factored = 0;
    N->fvalid = 0;
    memset(&T, 0, sizeof T);
    T.N = N;
    T.S = S;
    T.gr = (uint32_t *)bp__alloc_array(a, nslot ? nslot : 1, sizeof(uint32_t));
    T.glen = (uint32_t *)bp__alloc_array(a, nv ? nv : 1, sizeof(uint32_t));
    if (!T.gr || !T.glen || nslot > 0xfffffff0u) goto done;
    if (N->extra.count && !bp__pattern_extra(a, N, nv, &xp, &xl)) goto done;
    T.xp = xp;
    T.xl = xl;
    S->par.run(S->par.user, bp__pattern_cols, &T, S->nchunk_v);
    N->H.n = n;
    N->H.symmetric = 1;
    N->H.blocks2 = 1;
    N->H.colp = (uint32_t *)bp__alloc_array(a, (size_t)n + 1, sizeof(uint32_t));
    if (!N->H.colp) goto done;
    for (v = 0; v < nv; v++) {          /* 4 entries per block, G's block (w, v) */
        N->H.colp[2 * v] = (uint32_t)w;
        N->H.colp[2 * v + 1] = (uint32_t)(w + 2 * (size_t)T.glen[v]);
        w += 4 * (size_t)T.glen[v];
    }
    if (w > 0xfffffff0u) goto done;
    N->H.colp[n] = (uint32_t)w;
    N->H.row = (uint32_t *)bp__alloc_array(a, w + 1, sizeof(uint32_t));
    N->H.val = (double *)bp__alloc_array(a, w + 1, sizeof(double));
    if (!N->H.row || !N->H.val) goto done;
    N->H.val[w] = 0;
    S->par.run(S->par.user, bp__pattern_place, &T, S->nchunk_v);
    st = BP_OK;
done:
    bp__free(a, T.gr); bp__free(a, T.glen); bp__free(a, xp); bp__free(a, xl);
    return st;
}

static bp_status bp__newton_init(bp__newton *N, const bp_allocator *a, bp__solver *S)
{
    uint32_t n = 2 * S->nv;
    memset(N, 0, sizeof *N);
    N->extra.elem = 2 * sizeof(uint32_t);
    N->pairs.elem = sizeof(bp__bpair);
    N->near.elem = sizeof(bp__bnear);
    N->tpos = (uint32_t *)bp__alloc_array(a, 9 * (size_t)S->nt, sizeof(uint32_t));
    N->dpos = (uint32_t *)bp__alloc_array(a, 4 * (size_t)S->nv, sizeof(uint32_t));
    N->ht = (double *)bp__alloc_array(a, BP__HT * (size_t)S->nt, sizeof(double));   /* written whole by
                                                 bp__newton_tri_task before any read: not zeroed, so its pages are
                                                 first touched on the threads */
    N->bd = (double *)bp__alloc_array(a, 3 * (size_t)S->nv, sizeof(double));
    N->dg = (double *)bp__alloc_array(a, (size_t)S->nv + 1, sizeof(double));
    N->rhs = (double *)bp__alloc_array(a, n, sizeof(double));
    N->z = (double *)bp__alloc_array(a, n, sizeof(double));
    N->r = (double *)bp__alloc_array(a, n, sizeof(double));
    N->p = (double *)bp__alloc_array(a, n, sizeof(double));
    N->q = (double *)bp__alloc_array(a, n, sizeof(double));
    N->w = (double *)bp__alloc_array(a, n, sizeof(double));
    N->part = (double *)bp__alloc_array(a, (size_t)bp__vec_nchunks(n) + 1, sizeof(double));
    N->b1 = (double *)bp__alloc_array(a, 2 * (size_t)n + 1, sizeof(double));
    if (!N->tpos || !N->dpos || !N->ht || !N->bd || !N->dg || !N->rhs || !N->z || !N->r || !N->p || !N->q || !N->w || !N->part || !N->b1 ||
        bp__newton_pattern(N, a, S) != BP_OK) {
        bp__newton_free(a, N);
        return BP_ERR_OUT_OF_MEMORY;
    }
    return BP_OK;
}

/* Mode 3: every coupling of a barrier pair (vertex-vertex, both ends of the
   edge) must be in H's pattern; the missing ones are added to `extra` and
   the pattern is rebuilt (a new ordering and symbolic analysis).  The
   pattern only grows, and the pairs settle after the first iterations, so
   this happens a few times per chart.  Returns 0 out of memory. */
static int bp__newton_grow(bp__newton *N, bp__solver *S)
{
    const bp__bnear *pr = (const bp__bnear *)N->near.data;
    size_t k, before = N->extra.count;
    int i, j;
    for (k = 0; k < N->near.count; k++)
        for (i = 0; i < 3; i++)
            for (j = i + 1; j < 3; j++) {
                uint32_t u = pr[k].v[i], w = pr[k].v[j], uw[2];
                if (u == w || bp__sparse_has(&N->H, 2 * u, 2 * w) != BP__NONE) continue;
                uw[0] = u; uw[1] = w;
                if (!bp__vec_push(S->a, &N->extra, uw)) return 0;
            }
    if (N->extra.count == before) return 1;
    if (N->since_grow < 8 && (N->factored || N->k1ok)) { N->extra.count = before; return 1; }   /* not yet: blocks for now */
    N->since_grow = 0;
    return bp__newton_pattern(N, S->a, S) == BP_OK;
}

/* Triangle chunk c: the projected Hessians into ht.  A triangle's 6x6
   Hessian is exactly symmetric (bp__triangle_hessian writes each value to
   both places), so ht keeps its six 2x2 blocks (r, c) with r <= c, in the
   order (0,0) (0,1) (0,2) (1,1) (1,2) (2,2), each row major: BP__HT = 24
   doubles instead of 36, two thirds of the memory the gather below
   streams through at every factorized iteration.  Block (r, c) with
   r > c is block (c, r) transposed: the same values, so the same bits.
   bp__ht_block[r][c] (defined before bp__triangle_hessian_iso) is where
   block (r, c) starts. */

static void bp__newton_tri_task(void *task, uint32_t c)
{
    bp__newton *N = (bp__newton *)task;
    bp__solver *S = N->S;
    uint32_t t, t1 = bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    int r, q;
    for (t = bp__chunk_at(S->nt, S->nchunk_t, c); t < t1; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        double h6[36], *h = N->ht + BP__HT * (size_t)t;
        if (N->iso) {                      /* (xx + yy) / 2 per block (bp__newton_iso_gather_task) */
            double *k = N->ht + 6 * (size_t)t;
            if (!bp__triangle_hessian_iso(S->energy, &S->rest[t], N->x + 2 * (size_t)tr[0],
                                          N->x + 2 * (size_t)tr[1], N->x + 2 * (size_t)tr[2], k))
                memset(k, 0, 6 * sizeof(double));
            continue;
        }
        if (!bp__triangle_hessian(S->energy, &S->rest[t], N->x + 2 * (size_t)tr[0], N->x + 2 * (size_t)tr[1],
                                  N->x + 2 * (size_t)tr[2], 1, h6))
            memset(h6, 0, sizeof h6);
        for (r = 0; r < 3; r++)
            for (q = r; q < 3; q++) {
                double *b = h + bp__ht_block[r][q];
                const double *s6 = h6 + 12 * r + 2 * q;
                b[0] = s6[0]; b[1] = s6[1]; b[2] = s6[6]; b[3] = s6[7];
            }
    }
}

/* H's columns 2v, 2v+1 for the vertices v of chunk c, from the
   triangles' 6x6 Hessians: zeroed, then for each corner of v (vc_list:
   increasing corner number, so increasing triangle t) the three blocks
   (r, c) of t with c = v's corner, at their places tpos.  An entry of
   H(u, v) gets one term per triangle holding both u and v, in increasing
   t: the order of a scatter over the triangles in turn, so the same
   bits; but a gather writes only its own columns, so the chunks run in
   parallel (the scatter was serial: 2 ms of face's 10 per iteration on
   two threads). */
static void bp__newton_gather_task(void *task, uint32_t c)
{
    bp__newton *N = (bp__newton *)task;
    const bp__solver *S = N->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1), p, r;
    double *val = N->H.val;
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        uint32_t c0 = N->H.colp[2 * v], len = N->H.colp[2 * v + 1] - c0;
        memset(val + c0, 0, (size_t)(N->H.colp[2 * v + 2] - c0) * sizeof(double));
        for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++) {
            uint32_t t = S->vc_list[p] / 3, cc = S->vc_list[p] % 3;
            for (r = 0; r < 3; r++) {        /* block (r, cc) of the triangle: H(2r + i, 2cc + j) */
                const double *b = N->ht + BP__HT * (size_t)t + bp__ht_block[r][cc];
                uint32_t P = N->tpos[9 * (size_t)t + 3 * r + cc];
                if (r <= cc) { val[P] += b[0]; val[P + 1] += b[2]; val[P + len] += b[1]; val[P + len + 1] += b[3]; }
                else { val[P] += b[0]; val[P + 1] += b[1]; val[P + len] += b[2]; val[P + len + 1] += b[3]; }
            }
        }
        N->dg[v] = val[N->dpos[4 * (size_t)v]] + val[N->dpos[4 * (size_t)v + 3]];   /* its part of the trace */
    }
}

/* The shift delta I of H's diagonal, in chunks of vertices (each
   vertex's diagonal block lies in its own two columns). */
static void bp__newton_shift_task(void *task, uint32_t c)
{
    bp__newton *N = (bp__newton *)task;
    const bp__solver *S = N->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1);
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        N->H.val[N->dpos[4 * (size_t)v]] += N->delta;
        N->H.val[N->dpos[4 * (size_t)v + 3]] += N->delta;
    }
}

/* The barrier's diagonal blocks for the pairs of one edge query. */
typedef struct bp__bhess_query {
    const bp__solver *S;
    const double *x;
    double *bd;
    bp__vec *pairs, *near;      /* pairs within eps; within 3 eps (mode 3) */
    int oom;
    double em;                  /* the model's barrier width (>= eps)     */
    uint32_t s0, n, i;
} bp__bhess_query;

static void bp__barrier_hess_visit(void *user, uint32_t k)
{
    bp__bhess_query *Q = (bp__bhess_query *)user;
    const bp__solver *S = Q->S;
    uint32_t kk = k - Q->s0, i1 = (Q->i + 1) % Q->n, vv[3];
    const double *A, *B, *P;
    double ex, ey, len2, sp, dx, dy, d, r, f2, nx, ny, cc[3];
    int j;
    if (kk == Q->i || kk == i1) return;
    vv[0] = S->loop_vertices[k]; vv[1] = S->loop_vertices[Q->s0 + Q->i]; vv[2] = S->loop_vertices[Q->s0 + i1];
    P = Q->x + 2 * (size_t)vv[0]; A = Q->x + 2 * (size_t)vv[1]; B = Q->x + 2 * (size_t)vv[2];
    ex = B[0] - A[0]; ey = B[1] - A[1];
    len2 = ex * ex + ey * ey;
    sp = len2 > 0 ? ((P[0] - A[0]) * ex + (P[1] - A[1]) * ey) / len2 : 0;
    if (sp < 0) sp = 0;
    if (sp > 1) sp = 1;
    dx = P[0] - (A[0] + sp * ex); dy = P[1] - (A[1] + sp * ey);
    d = sqrt(dx * dx + dy * dy);
    if (Q->near && d < 3 * S->eps) {
        bp__bnear nb;
        nb.v[0] = vv[0]; nb.v[1] = vv[1]; nb.v[2] = vv[2];
        if (!bp__vec_push(S->a, Q->near, &nb)) Q->oom = 1;
    }
    if (!(d < Q->em) || !(d > 0)) return;
    r = Q->em / d - 1;
    f2 = 2 * Q->em * Q->em / (d * d * d * d) + 4 * r * Q->em / (d * d * d);   /* f''(d) of width em */
    nx = dx / d; ny = dy / d;
    cc[0] = 1; cc[1] = -(1 - sp); cc[2] = -sp;
    {
        bp__bpair bp;
        bp.v[0] = vv[0]; bp.v[1] = vv[1]; bp.v[2] = vv[2];
        bp.s = sp; bp.nx = nx; bp.ny = ny; bp.f2 = f2;
        if (!BP__BARRIER_FULL || !bp__barrier_pair_hessian(P, A, B, Q->em, 1, bp.K)) {
            int a_, b_;
            for (a_ = 0; a_ < 6; a_++)
                for (b_ = 0; b_ < 6; b_++)
                    bp.K[6 * a_ + b_] = f2 * cc[a_ / 2] * cc[b_ / 2] * (a_ % 2 ? ny : nx) * (b_ % 2 ? ny : nx);
        }
        if (!bp__vec_push(S->a, Q->pairs, &bp)) Q->oom = 1;
    }
    for (j = 0; j < 3; j++) {
        double w = f2 * cc[j] * cc[j];
        Q->bd[3 * (size_t)vv[j]] += w * nx * nx;
        Q->bd[3 * (size_t)vv[j] + 1] += w * nx * ny;
        Q->bd[3 * (size_t)vv[j] + 2] += w * ny * ny;
    }
}

/* bd = the barrier's diagonal blocks at x: every boundary edge queries the
   hash (filled here with x), serially, in edge order. */
static void bp__newton_barrier(bp__newton *N, bp__solver *S, const double *x)
{
    uint32_t e;
    bp__bhess_query Q;
    double rad = (BP__NEWTON_BARRIER == 3 ? 3 : 1) * S->eps;
    memset(N->bd, 0, 3 * (size_t)S->nv * sizeof(double));
    N->pairs.count = 0;
    if (!S->barrier || !BP__NEWTON_BARRIER) return;
    bp__hash_fill(S, x, NULL, 0);
    Q.S = S;
    Q.x = x;
    Q.bd = N->bd;
    Q.pairs = &N->pairs;
    Q.near = BP__NEWTON_BARRIER == 3 ? &N->near : NULL;
    N->near.count = 0;
    Q.oom = 0;
    Q.em = N->wide ? BP__NEWTON_WIDE * S->eps : S->eps;
    if (Q.em > rad) rad = Q.em;
    for (e = 0; e < S->nb; e++) {
        uint32_t L = S->bl_loop[e];
        const double *p, *q;
        Q.s0 = S->loop_start[L];
        Q.n = S->loop_start[L + 1] - Q.s0;
        Q.i = e - Q.s0;
        p = x + 2 * (size_t)S->loop_vertices[e];
        q = x + 2 * (size_t)S->loop_vertices[Q.s0 + (Q.i + 1) % Q.n];
        bp__hash_query(&S->hash, L, (p[0] < q[0] ? p[0] : q[0]) - rad, (p[1] < q[1] ? p[1] : q[1]) - rad,
                       (p[0] > q[0] ? p[0] : q[0]) + rad, (p[1] > q[1] ? p[1] : q[1]) + rad,
                       bp__barrier_hess_visit, &Q);
    }
    if (Q.oom) N->oom = 1;
}

/* Pins (>>pins).  The homotopy's pull w sum_p |x_p - t_p|^2 adds 2 w to
   the diagonal of each pinned coordinate.  A held vertex is a fixed
   variable: its two rows and columns become those of the identity, so with
   its right-hand side -g = 0 (bp__opt_hold zeroes g there) the solve gives
   v = 0 there exactly (every product with the zeroed entries is 0), and
   the other rows are the Newton system of the free coordinates alone. */
static void bp__newton_pins(bp__newton *N, const bp__solver *S)
{
    uint32_t v, j, p;
    if (N->pull)
        for (v = 0; v < S->nv; v++)
            if (N->pull[v] != BP__NONE) {
                N->H.val[N->dpos[4 * (size_t)v]] += 2 * N->pull_w;
                N->H.val[N->dpos[4 * (size_t)v + 3]] += 2 * N->pull_w;
            }
    if (N->hold)
        for (j = 0; j < N->H.n; j++)
            for (p = N->H.colp[j]; p < N->H.colp[j + 1]; p++)
                if (N->hold[j / 2] != BP__NONE || N->hold[N->H.row[p] / 2] != BP__NONE)
                    N->H.val[p] = N->H.row[p] == j ? 1 : 0;
}

/* The isotropic phase (beyond the dissertation; docs/performance.md sec
   6.29).  From a conformal start, the first Newton steps are clipped by
   the step bound: the quadratic model of s^2 + s^-2 at a triangle
   stretched to s = 3 puts its minimum at s = 0.14, past the rotation the
   energy wants (face: 6,664 triangles would flip on the first full step,
   which stops at t = 0.585), and the early iterations are spent moving
   area, an isotropic change, more than shaping angles.  There a cheaper
   matrix does as well.  For H in 2x2 blocks (x and y of each vertex)
   write S for the reflection (x, y) -> (x, -y) and R for the rotation
   (x, y) -> (-y, x) of every vertex at once: (H + S H S) / 2 keeps H's xx
   and yy entries and drops the xy ones, and its average with its own
   rotation R (.) R^T averages xx with yy:
       H_iso = K1 (x) I_2,    K1(u, v) = (H(2u, 2v) + H(2u+1, 2v+1)) / 2,
   an average of congruences of H, so positive definite with H (the
   barrier's terms, the pins' rows and delta I included), and
   v = -(K1 (x) I_2)^-1 g is a descent direction: two solves with the
   Cholesky factor of the scalar nv x nv matrix K1, whose factorization
   costs an eighth of H's (face: 6.8e7 multiply-adds against 5.4e8), on
   the vertex order of the start map's (or Newton's kept) dissection.
   The step bound, the line search and the exact checks are the same, so
   every iterate is as valid as Newton's.  Measured (one thread, CPU to
   SCAF's energy x 1.001, medians of 3; sec 6.29): face 0.57 -> 0.40 s
   (6 isotropic iterations of 0.028 s against 5 Newton ones of 0.07),
   bimba 1.53 -> 0.99 s, camelhead 0.31 -> 0.20, horse_cut 1.45 -> 0.94,
   lucy 4.43 -> 2.32.  Its convergence is linear (it drops the
   anisotropic curvature that matters near the minimum), so the phase
   ends for good after the first iteration that lowers the energy by
   less than BP__NEWTON_ISO_TAU of it, or when K1 cannot be factored;
   Newton's own iterations follow, starting with the handed-over or kept
   analysis as before.  Symmetric Dirichlet only (the energy it was
   measured on), and not under the pins' homotopy. */
#ifndef BP__NEWTON_ISO
#define BP__NEWTON_ISO 1              /* 0: Newton from the first iteration */
#endif
#ifndef BP__NEWTON_ISO_TAU
#define BP__NEWTON_ISO_TAU 1e-3
#endif

/* K1's pattern from H's: H is in whole 2x2 blocks with sorted rows, so
   its column 2v lists 2u, 2u + 1 for each vertex u coupled to v.
   Returns 0 out of memory. */
static int bp__newton_iso_pattern(bp__newton *N, const bp_allocator *a)
{
    const bp__sparse *H = &N->H;
    bp__sparse *K = &N->K1;
    uint32_t nv = H->n / 2, v, p, w = 0, nnz = H->colp[H->n] / 4;
    bp__sparse_free(a, K);
    K->colp = (uint32_t *)bp__alloc_array(a, (size_t)nv + 1, sizeof(uint32_t));
    K->row = (uint32_t *)bp__alloc_array(a, (size_t)nnz + 1, sizeof(uint32_t));
    K->val = (double *)bp__alloc_array(a, (size_t)nnz + 1, sizeof(double));
    if (!K->colp || !K->row || !K->val) { bp__sparse_free(a, K); return 0; }
    K->n = nv;
    K->symmetric = 1;
    K->super1 = 2;
    for (v = 0; v < nv; v++) {
        K->colp[v] = w;
        for (p = H->colp[2 * v]; p < H->colp[2 * v + 1]; p += 2) K->row[w++] = H->row[p] >> 1;
    }
    K->colp[nv] = w;
    return 1;
}

/* A barrier pair's blocks (v_i, v_j) in H: pos[i][j] the place of the
   entry (2 v_i, 2 v_j); returns 1 when all nine couplings are in H's
   pattern, 0 when some are not (then only the diagonal blocks count). */
static int bp__newton_pair_places(const bp__newton *N, const bp__bpair *pr, uint32_t pos[3][3])
{
    int i, j, full = 1;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            pos[i][j] = i == j ? N->dpos[4 * (size_t)pr->v[i]] : bp__sparse_has(&N->H, 2 * pr->v[i], 2 * pr->v[j]);
            if (pos[i][j] == BP__NONE) full = 0;
        }
    return full;
}

/* K1's columns for the vertices of chunk c, from the triangles' blocks:
   in the isotropic phase bp__newton_tri_task keeps 6 doubles per
   triangle, (xx + yy) / 2 of each block (r, c) with r <= c (a quarter of
   the memory the gather streams), and block (r, c) adds its value to K1
   at the place of its H entry (2u, 2v): place 2k of H's column 2v is
   place k of K1's column v.  In increasing corner order, as
   bp__newton_gather_task: the same bits on any number of threads. */
static void bp__newton_iso_gather_task(void *task, uint32_t c)
{
    bp__newton *N = (bp__newton *)task;
    const bp__solver *S = N->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1), p, r;
    double *val = N->K1.val;
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        uint32_t k0 = N->K1.colp[v], h0 = N->H.colp[2 * v];
        memset(val + k0, 0, (size_t)(N->K1.colp[v + 1] - k0) * sizeof(double));
        for (p = S->vc_start[v]; p < S->vc_start[v + 1]; p++) {
            uint32_t t = S->vc_list[p] / 3, cc = S->vc_list[p] % 3;
            for (r = 0; r < 3; r++)
                val[k0 + (N->tpos[9 * (size_t)t + 3 * r + cc] - h0) / 2] += N->ht[6 * (size_t)t + bp__ht_block[r][cc] / 4];
        }
        N->dg[v] = 2 * val[k0 + (N->dpos[4 * (size_t)v] - h0) / 2];             /* its part of the trace */
    }
}

/* K1's diagonal: the shift delta, then the homotopy's pull, per vertex,
   in chunks of vertices. */
static void bp__newton_iso_shift_task(void *task, uint32_t c)
{
    bp__newton *N = (bp__newton *)task;
    const bp__solver *S = N->S;
    uint32_t v, v1 = bp__chunk_at(S->nv, S->nchunk_v, c + 1);
    for (v = bp__chunk_at(S->nv, S->nchunk_v, c); v < v1; v++) {
        double *d = N->K1.val + N->K1.colp[v] + (N->dpos[4 * (size_t)v] - N->H.colp[2 * v]) / 2;
        *d += N->delta;
        if (N->pull && N->pull[v] != BP__NONE) *d += 2 * N->pull_w;
    }
}

/* K1's place of H's entry (2u, 2v) at H position P. */
static uint32_t bp__newton_iso_at(const bp__newton *N, uint32_t v, uint32_t P)
{
    return N->K1.colp[v] + (P - N->H.colp[2 * v]) / 2;
}

/* K1 = the isotropic part of what bp__newton_assemble makes H: the
   triangles' blocks, the barrier's (its pairs' full terms, or their
   diagonal blocks), delta I (the same delta: H's trace is twice K1's) and
   the pins' rows. */
static void bp__newton_iso_assemble(bp__newton *N, bp__solver *S)
{
    uint32_t v, j, p;
    double trace = 0, delta, *val = N->K1.val;
    S->par.run(S->par.user, bp__newton_iso_gather_task, N, S->nchunk_v);
    if (BP__NEWTON_BARRIER == 3) {
        const bp__bpair *pr = (const bp__bpair *)N->pairs.data;
        size_t q;
        for (q = 0; q < N->pairs.count; q++) {
            uint32_t pos[3][3];
            int i, k, full = bp__newton_pair_places(N, pr + q, pos);
            for (i = 0; i < 3; i++)
                for (k = 0; k < 3; k++)
                    if (full || i == k)
                        val[bp__newton_iso_at(N, pr[q].v[k], pos[i][k])] +=
                            0.5 * (pr[q].K[6 * (2 * i) + 2 * k] + pr[q].K[6 * (2 * i + 1) + 2 * k + 1]);
        }
        for (q = 0; q < N->pairs.count; q++)           /* the diagonals the pairs changed */
            for (v = 0; v < 3; v++)
                N->dg[pr[q].v[v]] = 2 * val[bp__newton_iso_at(N, pr[q].v[v], N->dpos[4 * (size_t)pr[q].v[v]])];
    } else
        for (v = 0; v < S->nv; v++) {
            double *d = val + bp__newton_iso_at(N, v, N->dpos[4 * (size_t)v]);
            *d += 0.5 * (N->bd[3 * (size_t)v] + N->bd[3 * (size_t)v + 2]);
            N->dg[v] = 2 * *d;
        }
    for (v = 0; v < S->nv; v++) trace += N->dg[v];    /* in vertex order: the same sum on any threads */
    delta = 1e-8 * trace / (2 * (double)S->nv);
    N->delta = delta;
    S->par.run(S->par.user, bp__newton_iso_shift_task, N, S->nchunk_v);
    if (N->hold)
        for (j = 0; j < N->K1.n; j++)
            for (p = N->K1.colp[j]; p < N->K1.colp[j + 1]; p++)
                if (N->hold[j] != BP__NONE || N->hold[N->K1.row[p]] != BP__NONE) val[p] = N->K1.row[p] == j ? 1 : 0;
}

/* H = sum of the triangles' blocks (in triangle order) + the barrier's
   blocks + delta I, with the pins' rows (bp__newton_pins). */
static void bp__newton_assemble(bp__newton *N, bp__solver *S, const double *x)
{
    uint32_t v, n = N->H.n;
    double trace = 0, delta;
    N->S = S;
    N->x = x;
    S->par.run(S->par.user, bp__newton_tri_task, N, S->nchunk_t);
    bp__newton_barrier(N, S, x);
    if (BP__NEWTON_BARRIER == 3 && !bp__newton_grow(N, S)) { N->oom = 1; return; }
    if (N->iso) {                                   /* the isotropic phase: K1 alone */
        if (!N->K1.colp && !bp__newton_iso_pattern(N, S->a)) { N->oom = 1; return; }
        bp__newton_iso_assemble(N, S);
        return;
    }
    n = N->H.n;
    S->par.run(S->par.user, bp__newton_gather_task, N, S->nchunk_v);
    if (BP__NEWTON_BARRIER == 3) {                  /* the pairs' full terms */
        const bp__bpair *pr = (const bp__bpair *)N->pairs.data;
        size_t q;
        for (q = 0; q < N->pairs.count; q++) {
            uint32_t pos[3][3];                /* block (v_i, v_j): its (2 v_i, 2 v_j) entry */
            int i, j, al, be, full = bp__newton_pair_places(N, pr + q, pos);   /* else only the blocks */
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) {
                    uint32_t col = 2 * pr[q].v[j], len = N->H.colp[col + 1] - N->H.colp[col];
                    if (!full && i != j) continue;
                    for (al = 0; al < 2; al++)    /* entry (2 v_i + al, 2 v_j + be): al + be len further */
                        for (be = 0; be < 2; be++)
                            N->H.val[pos[i][j] + al + be * len] +=
                                pr[q].K[6 * (2 * i + al) + 2 * j + be];   /* >>barrier: f'' c c n n^T, or whole */
                }
        }
        for (q = 0; q < N->pairs.count; q++)           /* the diagonals the pairs changed */
            for (v = 0; v < 3; v++) {
                const uint32_t *dp = N->dpos + 4 * (size_t)pr[q].v[v];
                N->dg[pr[q].v[v]] = N->H.val[dp[0]] + N->H.val[dp[3]];
            }
    } else
        for (v = 0; v < S->nv; v++) {
            const uint32_t *dp = N->dpos + 4 * (size_t)v;
            const double *b = N->bd + 3 * (size_t)v;
            N->H.val[dp[0]] += b[0]; N->H.val[dp[1]] += b[1]; N->H.val[dp[2]] += b[1]; N->H.val[dp[3]] += b[2];
            N->dg[v] = N->H.val[dp[0]] + N->H.val[dp[3]];
        }
    for (v = 0; v < S->nv; v++) trace += N->dg[v];    /* in vertex order: the same sum on any threads */
    delta = 1e-8 * trace / n;
    N->delta = delta;
    S->par.run(S->par.user, bp__newton_shift_task, N, S->nchunk_v);
    bp__newton_pins(N, S);
}

/* 1 when every pivot of the factor is positive and finite (H + delta I
   was positive definite in floating point), else 0. */
static int bp__newton_pivots_ok(const bp__factor *F)
{
    uint32_t k;
    for (k = 0; k < F->n; k++)
        if (!(F->D[k] > 0) || !(F->D[k] < HUGE_VAL)) return 0;
    return 1;
}

/* The numeric factorization alone, on the pattern bp__factorize found:
   bp__fact_numeric's row phases along the dissection tree, on H's new
   values, into the factor's existing arrays.  Returns 1, 0 when a pivot is
   not positive and finite, -1 out of memory (its work arrays). */
static int bp__newton_refactor(bp__newton *N, const bp_allocator *a, const bp__par *par)
{
    if (!bp__fact_numeric(a, &N->H, &N->F, NULL, par)) return -1;
    return bp__newton_pivots_ok(&N->F);
}

/* y = A x with A = M - blocks(B) + B: M the factored matrix, blocks(B)
   the barrier's diagonal blocks in it, B the barrier's full Gauss-Newton
   terms.  Serial, in a fixed order. */
static void bp__newton_apply(const bp__newton *N, uint32_t nv, const double *x, double *y)
{
    const bp__sparse *H = &N->H;
    const bp__bpair *pr = (const bp__bpair *)N->pairs.data;
    uint32_t j, p, v;
    size_t k;
    for (j = 0; j < H->n; j++) y[j] = 0;
    for (j = 0; j < H->n; j++)
        for (p = H->colp[j]; p < H->colp[j + 1]; p++) y[H->row[p]] += H->val[p] * x[j];
    for (v = 0; v < nv; v++) {
        const double *b = N->bd + 3 * (size_t)v;
        y[2 * v] -= b[0] * x[2 * v] + b[1] * x[2 * v + 1];
        y[2 * v + 1] -= b[1] * x[2 * v] + b[2] * x[2 * v + 1];
    }
    for (k = 0; k < N->pairs.count; k++) {
        const bp__bpair *q = pr + k;
        double c[3], t = 0;
        int i;
        c[0] = 1; c[1] = -(1 - q->s); c[2] = -q->s;
        for (i = 0; i < 3; i++) t += c[i] * (q->nx * x[2 * q->v[i]] + q->ny * x[2 * q->v[i] + 1]);
        t *= q->f2;
        for (i = 0; i < 3; i++) { y[2 * q->v[i]] += c[i] * t * q->nx; y[2 * q->v[i] + 1] += c[i] * t * q->ny; }
    }
}

/* The barrier's pairs couple vertices that H's pattern does not: solve
   A v = b (A above) by conjugate gradients preconditioned with the
   factored M, starting from v = M^-1 b, until r.M^-1 r falls below 1e-8
   of b.M^-1 b (at most 30 steps, each one solve with the factor). */
static void bp__newton_pcg(bp__newton *N, uint32_t nv, const double *b, double *v)
{
    uint32_t n = N->H.n, i;
    double rz = 0, rz0 = 0, pq, alpha, rzn;
    int k;
    double *r = N->r, *p = N->p, *q = N->q;
    bp__newton_apply(N, nv, v, q);
    for (i = 0; i < n; i++) { r[i] = b[i] - q[i]; rz0 += b[i] * v[i]; }
    bp__factor_solve_par(&N->F, r, p, N->z, N->par);
    for (i = 0; i < n; i++) rz += r[i] * p[i];
    for (k = 0; k < BP__NEWTON_CG_MAX && rz > BP__NEWTON_CG_TOL * rz0; k++) {
        bp__newton_apply(N, nv, p, q);
        pq = 0;
        for (i = 0; i < n; i++) pq += p[i] * q[i];
        if (!(pq > 0)) break;
        alpha = rz / pq;
        for (i = 0; i < n; i++) { v[i] += alpha * p[i]; r[i] -= alpha * q[i]; }
        bp__factor_solve_par(&N->F, r, q, N->z, N->par);              /* q = M^-1 r */
        rzn = 0;
        for (i = 0; i < n; i++) rzn += r[i] * q[i];
        for (i = 0; i < n; i++) p[i] = q[i] + (rzn / rz) * p[i];
        rz = rzn;
    }
}

/* Factor reuse.  The factorization is most of an iteration's cost, and
   near the minimum (or along a long valley) H changes little from one
   iterate to the next.  So the factor F of an earlier H serves as the
   preconditioner of conjugate gradients on the current system
       (H + delta I) v = -g,
   started from v = 0: the first step is F^-1 (-g) scaled to minimize the
   quadratic model m(v) = g.v + v.(H + delta I) v / 2 along it, and every
   later one minimizes m over a larger Krylov space, so m(v) < m(0) = 0 and
   hence g.v < -v.(H + delta I) v / 2 < 0: every CG iterate is a descent
   direction (a truncated Newton step).  CG stops when its steps stop
   lowering m (the test below).  Not by the residual in F's norm, r.F^-1 r
   <= eta^2 g.F^-1 g, the usual forcing term: measured on camel_b
   (tests/test_newton.c (h)), where the step grew some crushed triangles
   F is far stiffer than H along them, that norm all but ignores them, and
   CG "converged" at half of the model's decrease.  No cheap test inside
   CG sees that (Nash & Sofer's, below, was fooled the same way), so the
   factor is reused only where H changes slowly: when the last step was the
   full step t = 1 (not shrunk, not clipped by the bound, not extended) and
   its decrease f - f(x + v) was within [rho, 1/rho] of the decrease the
   model predicted, -m(v) = -g.v / 2 (for CG from 0 and for the exact step
   alike, v.H v = -g.v), rho = 1/2 -- the ratio test of trust-region
   methods -- and at most a tenth of f (far from the minimum the model's
   ratio can look right while whole regions of the map still change
   scale: camel_b at f = 3e5).  CG then stops when the last step's share
   of the model's decrease so far, times the step number k, is at most
   1/10 (Nash & Sofer's truncation test, 1990); at the maps the gate lets
   through, test (h) finds it within 10% of the exact step's decrease.  If
   CG needs more than BP__NEWTON_REUSE_CG steps, or F was already reused
   BP__NEWTON_REUSE times running, H is factored afresh.  Serial, in a
   fixed order: the same bits on any number of threads. */
#ifndef BP__NEWTON_REUSE
#define BP__NEWTON_REUSE 4            /* reuses of one factor in a row (0: never) */
#endif
#ifndef BP__NEWTON_REUSE_CG
#define BP__NEWTON_REUSE_CG 20
#endif
#ifndef BP__NEWTON_REUSE_Q
#define BP__NEWTON_REUSE_Q 0.1
#endif
#ifndef BP__NEWTON_REUSE_RHO
#define BP__NEWTON_REUSE_RHO 0.5      /* decrease / predicted within [rho, 1/rho] */
#endif
#ifndef BP__NEWTON_REUSE_DF
#define BP__NEWTON_REUSE_DF 0.1       /* ... and at most this share of f */
#endif

/* y = H x, H's values as assembled (its pattern holds both triangles, so
   row j of H is column j: y_j gathers column j, p increasing), in the
   chunks of bp__vec_pass on the solver's threads: each y_j is one task's
   sum in a fixed order, the same bits on any number of threads. */
typedef struct bp__hmul_task { const bp__sparse *H; const double *x; double *y; uint32_t nc; } bp__hmul_task;

static void bp__hmul_run(void *task, uint32_t k)
{
    const bp__hmul_task *T = (const bp__hmul_task *)task;
    const bp__sparse *H = T->H;
    uint32_t j, p, j1 = bp__vec_chunk_at(H->n, T->nc, k + 1);
    for (j = bp__vec_chunk_at(H->n, T->nc, k); j < j1; j++) {
        double s = 0;
        for (p = H->colp[j]; p < H->colp[j + 1]; p++) s += H->val[p] * T->x[H->row[p]];
        T->y[j] = s;
    }
}

static void bp__newton_mul(const bp__sparse *H, const double *x, double *y, const bp__par *par)
{
    bp__hmul_task T;
    bp__par serial = bp__par_serial();
    T.H = H; T.x = x; T.y = y; T.nc = bp__vec_nchunks(H->n);
    if (!par) par = &serial;
    par->run(par->user, bp__hmul_run, &T, T.nc);
}

/* CG on H v = b from v = 0, preconditioned by the (older) factor F.
   Step k lowers the model by alpha_k r_k.F^-1 r_k / 2, so m(v_k) is known
   as CG goes; it stops when the last step's share of the whole decrease,
   times k, is at most BP__NEWTON_REUSE_Q (Nash & Sofer's truncation test
   for truncated Newton, 1990): returns 1 then, 0 when that takes more
   than BP__NEWTON_REUSE_CG steps.  The vector work goes through
   bp__vec_pass (chunks, dots added in chunk order) and the products
   through bp__newton_mul, both on the solver's threads: the same bits on
   any number of them (the solves already were). */
static int bp__newton_reuse_solve(bp__newton *N, const double *b, double *v)
{
    uint32_t n = N->H.n;
    double rz = 0, pq, alpha, rzn, beta, m = 0, dm;
    const double one = 1;
    int k;
    double *r = N->r, *p = N->p, *q = N->q, *w = N->w;
    const double *wv = w;
    bp__par serial = bp__par_serial();
    const bp__par *par = N->par ? N->par : &serial;
    N->ntry++;
    memset(v, 0, n * sizeof(double));
    memcpy(r, b, n * sizeof(double));
    bp__factor_solve_par(&N->F, r, w, N->z, N->par);
    bp__vec_pass(par, N->part, n, p, 1, w, 0, NULL, NULL, 1, (const double *const *)&r, (const double *const *)&w, &rz);
    if (!(rz > 0 && rz < HUGE_VAL)) return 0;
    for (k = 1; k <= BP__NEWTON_REUSE_CG; k++) {
        N->ncg++;
        bp__newton_mul(&N->H, p, q, par);
        bp__vec_pass(par, N->part, n, NULL, 0, NULL, 0, NULL, NULL, 1, (const double *const *)&p,
                     (const double *const *)&q, &pq);
        if (!(pq > 0 && pq < HUGE_VAL)) return 0;
        alpha = rz / pq;
        bp__vec_axpy(par, N->part, n, v, v, alpha, p, NULL, NULL, NULL);          /* v += alpha p */
        bp__vec_axpy(par, N->part, n, r, r, -alpha, q, NULL, NULL, NULL);         /* r -= alpha q */
        dm = 0.5 * alpha * rz;                 /* m(v_k) = m(v_k-1) - dm */
        m -= dm;
        if (k > 1 && k * dm <= BP__NEWTON_REUSE_Q * -m) return 1;
        bp__factor_solve_par(&N->F, r, w, N->z, N->par);
        bp__vec_pass(par, N->part, n, NULL, 0, NULL, 0, NULL, NULL, 1, (const double *const *)&r,
                     (const double *const *)&w, &rzn);
        if (!(rzn > 0)) return 1;              /* exact */
        beta = rzn / rz;
        bp__vec_pass(par, N->part, n, p, beta, p, 1, &wv, &one, 0, NULL, NULL, NULL);   /* p = w + beta p */
        rz = rzn;
    }
    return 0;
}

/* Whether two recorded trees are the same nodes. */
static int bp__nd_same_tree(const bp__ndnode *x, const bp__ndnode *y)
{
    uint32_t k;
    for (k = 0; k < BP__ND_NODES; k++)
        if (x[k].used != y[k].used || x[k].split != y[k].split || x[k].lo != y[k].lo || x[k].a != y[k].a ||
            x[k].b != y[k].b || x[k].hi != y[k].hi)
            return 0;
    return 1;
}

/* The isotropic phase's K1 analysis, kept by bp__newton_iso_end, as H's
   own: K1's pattern is H's vertex graph (built from it, and freed with it
   whenever the pattern grows: bp__newton_pattern), and its order is the
   one H's first factorization would take -- the kept order when it
   dissects that graph (bp__newton_iso_order checks as
   bp__newton_factorize did), else a dissection of that very graph, the
   one H's bp__factorize would compute again -- so bp__super_clone copies
   it for blocks of 2 instead of a second analysis (face: 8 ms of one
   thread, which the conformal start's 2x2 factor saved Newton before the
   start was solved by the boundary's Schur complement, >>conformal).
   NULL when there is none (no isotropic phase, or a pattern since). */
static const bp__factor *bp__newton_h_like(const bp__newton *N, uint32_t nv)
{
    const bp__factor *F1 = &N->F1;
    if (N->iso || !F1->sn || !F1->sn->vperm || !F1->sn->ri || F1->sn->bs != 1 || F1->sn->nv != nv || !F1->tree[0].used)
        return NULL;
    return F1;
}

/* The first factorization of H's pattern: with the order kept from
   before the pattern grew when it still dissects the new pattern (above),
   else a new one.  The kept order is then dropped: the new factor holds
   it. */
static bp_status bp__newton_factorize(bp__newton *N, bp__solver *S, uint32_t *bad)
{
    bp_status st = BP_ERR_OUT_OF_MEMORY;
    const bp__factor *like;
    int fallback = 0;
    bp__handoff *h = N->given;
    N->given = NULL;
    if (h && h->F.sn && h->n == N->H.n && !memcmp(h->colp, N->H.colp, ((size_t)h->n + 1) * sizeof(uint32_t)) &&
        !memcmp(h->row, N->H.row, (size_t)N->H.colp[h->n] * sizeof(uint32_t))) {
        N->F = h->F;                              /* the conformal start's analysis */
        memset(&h->F, 0, sizeof h->F);
        N->nhanded++;
        st = bp__fact_numeric(S->a, &N->H, &N->F, NULL, &S->par) ? BP_OK : BP_ERR_OUT_OF_MEMORY;
        bp__handoff_free(S->a, h);
        h->used = 1;
        bp__free(S->a, N->kperm);
        bp__free(S->a, N->kiperm);
        N->kperm = N->kiperm = NULL;
        return st;
    }
    bp__handoff_free(S->a, h);
    if ((like = bp__newton_h_like(N, S->nv)) != NULL) {
        st = bp__super_factorize_like(S->a, &N->H, &N->F, bad, &S->par, 2, &fallback, like->sn->vperm, like->tree,
                                      like);
        if (!fallback) N->ncloned++;
    } else if (N->kperm && bp__nd_keeps(N->ktree, N->kiperm, (const uint32_t *)N->extra.data, N->extra.count)) {
        st = bp__super_factorize(S->a, &N->H, &N->F, bad, &S->par, 2, &fallback, N->kperm, N->ktree);
        if (!fallback) N->nkept++;
    } else
        fallback = 1;
    if (!N->iso) bp__factor_free(S->a, &N->F1);   /* (the phase's analysis, copied or not) */
    if (fallback) st = bp__factorize(S->a, &N->H, &N->F, bad, &S->par);
    bp__free(S->a, N->kperm);
    bp__free(S->a, N->kiperm);
    N->kperm = N->kiperm = NULL;
    return st;
}

/* The vertex order for K1's first analysis: the kept one while it still
   dissects H's graph, else the start map's handed-over factor's when its
   matrix had H's pattern (compared entry by entry, as
   bp__newton_factorize does), else none (a dissection of its own, then
   kept for Newton's first factorization). */
static const uint32_t *bp__newton_iso_order(const bp__newton *N, const bp__ndnode **tree)
{
    const bp__handoff *h = N->given;
    if (N->kperm && bp__nd_keeps(N->ktree, N->kiperm, (const uint32_t *)N->extra.data, N->extra.count)) {
        *tree = N->ktree;
        return N->kperm;
    }
    if (h && h->F.sn && h->F.sn->vperm && h->F.tree[0].used && h->n == N->H.n &&
        !memcmp(h->colp, N->H.colp, ((size_t)h->n + 1) * sizeof(uint32_t)) &&
        !memcmp(h->row, N->H.row, (size_t)N->H.colp[h->n] * sizeof(uint32_t))) {
        *tree = h->F.tree;
        return h->F.sn->vperm;
    }
    *tree = NULL;
    return NULL;
}

/* The start map's handed-over factor when its analysis is K1's own: its
   matrix's vertex graph is K1's pattern, entry by entry, and it was
   analysed in this order and tree (bp__super_clone copies it), else NULL. */
static const bp__factor *bp__newton_iso_like(const bp__newton *N, const uint32_t *order, const bp__ndnode *tree)
{
    const bp__handoff *h = N->given;
    const bp__sparse *K = &N->K1;
    uint32_t v, i;
    if (!order || !tree || !h || !h->F.sn || h->F.sn->bs != 2 || h->n != 2 * K->n || h->F.sn->nv != K->n ||
        memcmp(order, h->F.sn->vperm, K->n * sizeof(uint32_t)) != 0)
        return NULL;
    if (!bp__nd_same_tree(tree, h->F.tree)) return NULL;
    for (v = 0; v < K->n; v++) {                      /* column 2v's even rows, halved: v's column of K1 */
        uint32_t p0 = h->colp[2 * v], len = K->colp[v + 1] - K->colp[v];
        if (h->colp[2 * v + 1] - p0 != 2 * len) return NULL;
        for (i = 0; i < len; i++)
            if (h->row[p0 + 2 * i] != 2 * K->row[K->colp[v] + i]) return NULL;
    }
    return &h->F;
}

/* K1's factor (its values assembled, bp__newton_iso_assemble): on a new
   pattern the analysis (above), else the numeric phase alone.  Returns 1,
   0 when a pivot is not positive and finite (the phase ends), -1 out of
   memory. */
static int bp__newton_iso_factor(bp__newton *N, bp__solver *S)
{
    const bp__ndnode *tree;
    const uint32_t *order;
    uint32_t bad, nv = S->nv;
    int fallback;
    bp_status st;
    if (N->k1ok) {
        if (!bp__fact_numeric(S->a, &N->K1, &N->F1, NULL, &S->par)) return -1;
        return bp__newton_pivots_ok(&N->F1);
    }
    order = bp__newton_iso_order(N, &tree);
    st = bp__super_factorize_like(S->a, &N->K1, &N->F1, &bad, &S->par, 1, &fallback, order, tree,
                                  bp__newton_iso_like(N, order, tree));
    if (st == BP_ERR_OUT_OF_MEMORY) return -1;
    if (st != BP_OK || fallback || !N->F1.sn) return 0;
    N->k1ok = 1;
    if (!order && !N->kperm && N->F1.tree[0].used) {        /* Newton's first analysis: the same order */
        N->kperm = (uint32_t *)bp__alloc_array(S->a, nv ? nv : 1, sizeof(uint32_t));
        N->kiperm = (uint32_t *)bp__alloc_array(S->a, nv ? nv : 1, sizeof(uint32_t));
        if (!N->kperm || !N->kiperm) return -1;
        memcpy(N->kperm, N->F1.sn->vperm, nv * sizeof(uint32_t));
        memcpy(N->kiperm, N->F1.sn->viperm, nv * sizeof(uint32_t));
        memcpy(N->ktree, N->F1.tree, sizeof N->ktree);
    }
    return 1;
}

/* The phase's end, for good: K1 and its factor freed before Newton's
   own factor takes the memory. */
static void bp__newton_iso_end(bp__newton *N, const bp_allocator *a)
{
    N->iso = 0;
    N->k1ok = 0;
    N->cut = 1;
    bp__sparse_free(a, &N->K1);
    if (N->F1.sn) {                               /* the analysis stays for H's (bp__newton_factorize) */
        bp__free(a, N->F1.sn->x); N->F1.sn->x = NULL;
        bp__free(a, N->F1.sn->amap); N->F1.sn->amap = NULL;
        N->F1.sn->amap_ok = 0;
    }
}

/* v = -(K1 (x) I_2)^-1 g (rhs = -g, interleaved): x and y through F1
   in one solve with two right-hand sides (bp__super_solve_n: F1 is
   supernodal, bp__newton_iso_factor sees to it; the same bits as two
   solves, for one pass over L each way instead of two).  Returns 1, 0
   when K1 could not be factored, -1 out of memory. */
static int bp__newton_iso_direction(bp__newton *N, bp__solver *S, double *v)
{
    bp__par serial = bp__par_serial();
    int r = bp__newton_iso_factor(N, S);
    if (r <= 0) return r;
    bp__super_solve_n(&N->F1, N->rhs, v, N->z, N->par ? N->par : &serial, 2);   /* x and y at once */
    return 1;
}

/* v = -(H + delta I)^-1 g at x, *gv = g.v: by the factor of an earlier H
   and CG when that converges (above), else by factoring H.  Returns 1; 0
   when H could not be factored or v is not a descent direction (the
   caller then takes -g); -1 out of memory. */
static int bp__newton_direction(bp__newton *N, bp__solver *S, const double *x, const double *g, double *v, double *gv)
{
    uint32_t n, i, bad;
    double s = 0;
    N->par = &S->par;
    bp__newton_assemble(N, S, x);
    if (N->oom) return -1;
    n = N->H.n;
    N->since_grow++;
    for (i = 0; i < n; i++) N->rhs[i] = -g[i];
    if (N->iso) {                                 /* the isotropic phase (above) */
        int r = bp__newton_iso_direction(N, S, v);
        if (r < 0) return -1;
        if (r > 0) {
            for (i = 0; i < n; i++) s += g[i] * v[i];
            if (s < 0 && s > -HUGE_VAL) { *gv = s; N->niso++; return 1; }
            s = 0;
        }
        bp__newton_iso_end(N, S->a);              /* K1 failed: Newton from here on, */
        bp__newton_assemble(N, S, x);             /* on H itself */
        if (N->oom) return -1;
    }
    if (N->factored && N->fvalid && BP__NEWTON_BARRIER != 2 && !N->cut && N->reused < BP__NEWTON_REUSE &&
        bp__newton_reuse_solve(N, N->rhs, v)) {
        N->reused++;
        N->nreuse++;
    } else {
        if (!N->factored) {
            bp_status st = bp__newton_factorize(N, S, &bad);
            if (st == BP_ERR_OUT_OF_MEMORY) return -1;
            if (st != BP_OK) return 0;
            N->factored = 1;
            N->fvalid = 0;
            if (!bp__newton_pivots_ok(&N->F)) return 0;
        } else {
            int ok = bp__newton_refactor(N, S->a, &S->par);
            N->fvalid = 0;
            if (ok <= 0) return ok;
        }
        N->fvalid = 1;
        N->nfact++;
        N->reused = 0;
        bp__factor_solve_par(&N->F, N->rhs, v, N->z, N->par);
        if (BP__NEWTON_BARRIER == 2 && N->pairs.count) bp__newton_pcg(N, S->nv, N->rhs, v);
    }
    for (i = 0; i < n; i++) s += g[i] * v[i];
    *gv = s;
    return s < 0 && s > -HUGE_VAL;
}

/* >>optimize ===============================================================

   bp__chart_optimize: the iteration of >>lbfgs (sec 3.4, 3.5) with any of
   the directions above, in named phases -- 1 the exact check of the start
   map, 2 the set-up (options, solver, preconditioner or Newton's pattern,
   the pins held), then per iteration 3 the direction and 4 the step bound
   (>>stepbound) with the line search, and 5 the chart's report.  The
   homotopy of >>pins runs the same iteration with a pull toward the
   targets (bp__chart_optimize_pen).  The state of one solve: */
typedef struct bp__opt {
    bp_allocator a;
    bp_options   o;              /* opt with the defaults filled in          */
    bp__solver   S;
    bp__lbfgs    L;
    bp__sparse   K;              /* the preconditioner (if any) and its factor */
    bp__factor   KF;
    bp__par      par;
    int          precond, hist, gd_scale_set;
    int          newton, nd;     /* BP_DIRECTION_NEWTON; this iteration's
                                    direction is Newton's (1), out of memory (-1) */
    bp__newton   N;
    uint32_t     nv2;
    double      *x, *g, *xn, *gn, *v, *pwork, *vpart;
    double      *xe, *ge;        /* Newton's longer trial steps (bp__opt_extend) */
    double       tlast;          /* the last accepted step                   */
    int          crushed;        /* the start was enlarged (>>start, 4)      */
    uint32_t    *pidx, *held, nheld; /* pins: chart vertex -> pin, the pinned
                                    chart vertices (held fixed, >>pins)      */
    const struct bp__penalty *pen; /* the homotopy's pull toward the pins   */
    bp__handoff *handoff;        /* the conformal start's factor, or NULL  */
} bp__opt;

static void bp__opt_free(bp__opt *P)
{
    bp__solver_free(&P->S);
    bp__free(&P->a, P->x); bp__free(&P->a, P->g); bp__free(&P->a, P->xn); bp__free(&P->a, P->gn);
    bp__free(&P->a, P->v); bp__free(&P->a, P->pwork); bp__free(&P->a, P->vpart);
    bp__free(&P->a, P->xe); bp__free(&P->a, P->ge);
    bp__free(&P->a, P->pidx); bp__free(&P->a, P->held);
    bp__lbfgs_free(&P->a, &P->L);
    bp__newton_free(&P->a, &P->N);
    bp__sparse_free(&P->a, &P->K);
    bp__factor_free(&P->a, &P->KF);
}

/* Phase 1: the start map in chart->uv must be exactly valid, whoever put
   it there (bp_chart_init, or the caller's own map): with the barrier the
   whole of bp_check, without it every triangle positively oriented (such a
   map may overlap itself).  The elements are named as the mesh numbers
   them.  On the optimizer's runner. */
static bp_status bp__opt_check_start(const bp_allocator *a, const bp_chart *ch, uint32_t chart_index,
                                     const bp_mesh *m, int barrier, const bp__par *par, bp_error *err)
{
    bp_check_report rep;
    bp_error why;
    bp_status st = bp__check_par(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, a, par, &rep, &why);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "checking the start map");
    if (!bp__check_verdict_status(st))
        return bp__fail(err, st, BP_ELEMENT_CHART, chart_index, -1, 0, "chart %u: the start map could not be checked: %s",
                        chart_index, why.message);
    if (st == BP_OK || (!barrier && !rep.flipped && !rep.degenerate && !rep.nonfinite && !rep.nonmanifold_edges &&
                        !rep.misoriented_edges))
        return BP_OK;
    if (rep.first_bad_triangle >= 0 && (rep.nonfinite || rep.flipped || rep.degenerate)) {
        uint32_t t = (uint32_t)rep.first_bad_triangle, f = ch->face[t];
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        const char *what = rep.nonfinite ? "not finite" : "degenerate (zero area)";
        if (!rep.nonfinite && bp_orient2d(ch->uv + 2 * (size_t)tr[0], ch->uv + 2 * (size_t)tr[1], ch->uv + 2 * (size_t)tr[2]) < 0)
            what = "flipped";
        char where[48];
        where[0] = 0;
        if (bp__tri_line(m, f) > 0) bp__format(where, sizeof where, " (line %D)", bp__tri_line(m, f));
        return bp__fail(err, rep.nonfinite ? BP_ERR_NONFINITE : BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_TRIANGLE, f, -1,
                        bp__tri_line(m, f),
                        "chart %u: the start map is not valid: triangle %u%s, vertices %u %u %u, is %s "
                        "(%u flipped, %u degenerate, %u with NaN/Inf)", chart_index, f + 1, where,
                        ch->vertex[tr[0]] + 1, ch->vertex[tr[1]] + 1, ch->vertex[tr[2]] + 1, what,
                        rep.flipped, rep.degenerate, rep.nonfinite);
    }
    if (rep.boundary_intersections) {
        uint32_t v0 = ch->vertex[rep.first_bad_edge[0]], v1 = ch->vertex[rep.first_bad_edge[1]];
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_EDGE, v0, v1, 0,
                        "chart %u: the start map overlaps itself: the boundary edges from vertex %u and from "
                        "vertex %u meet (%u such pairs)", chart_index, v0 + 1, v1 + 1, rep.boundary_intersections);
    }
    return bp__fail(err, st, BP_ELEMENT_CHART, chart_index, -1, 0,
                    "chart %u: the start map is not bijective (%s; the indices are the chart's)", chart_index,
                    why.message);
}

/* Fixed variables (pins, see >>pins): the pinned chart vertices are held
   where the start map has them.  Their gradient components are zeroed after
   every evaluation and their direction components after every direction,
   so x + t v never moves them (x + t * 0 == x exactly) and every L-BFGS
   pair s, y is zero there too; the preconditioner is the Laplacian of the
   free vertices (bp__laplacian).  The iteration is then the same method on
   the free coordinates alone. */
static bp_status bp__opt_pins(bp__opt *P, const bp_chart *ch, const bp_mesh *m, bp_error *err)
{
    uint32_t i, n = 0;
    bp_status st = bp__pin_map(&P->a, ch, m, &P->o, &P->pidx, &P->nheld, err);
    if (st != BP_OK || !P->pidx) return st;
    P->held = (uint32_t *)bp__alloc_array(&P->a, P->nheld, sizeof(uint32_t));
    if (!P->held) return bp__oom(err, "optimizing a chart");
    for (i = 0; i < ch->num_vertices; i++) if (P->pidx[i] != BP__NONE) P->held[n++] = i;
    return BP_OK;
}

/* The homotopy of >>pins minimizes E + w sum_p |x_p - t_p|^2 with the
   pins free: the penalty's value, and its gradient 2 w (x_p - t_p) added
   to g. */
typedef struct bp__penalty { const bp_pin *pins; const uint32_t *pidx; double w; } bp__penalty;

static double bp__opt_penalty(const bp__opt *P, const double *x, double *g)
{
    uint32_t i;
    double sum = 0;
    for (i = 0; i < P->S.nv; i++) {
        const bp_pin *p;
        double du, dv;
        if (P->pen->pidx[i] == BP__NONE) continue;
        p = &P->pen->pins[P->pen->pidx[i]];
        du = x[2 * (size_t)i] - p->u;
        dv = x[2 * (size_t)i + 1] - p->v;
        sum += P->pen->w * (du * du + dv * dv);
        g[2 * (size_t)i] += 2 * P->pen->w * du;
        g[2 * (size_t)i + 1] += 2 * P->pen->w * dv;
    }
    return sum;
}

/* Zero the held (pinned) coordinates of a gradient or direction. */
static void bp__opt_hold(const bp__opt *P, double *g)
{
    uint32_t k;
    for (k = 0; k < P->nheld; k++) g[2 * (size_t)P->held[k]] = g[2 * (size_t)P->held[k] + 1] = 0;
}

/* The default direction (BP_DIRECTION_DEFAULT) is chosen per chart before
   the first iteration, from what is known then: the number of triangles
   and the start map's mean energy E0 = sum_t w_t E_t / n_t (the report's
   energy_start).  On issue 15's ten meshes (docs/performance.md sec 6.6:
   CPU seconds to SCAF's final energy x 1.001, one thread, medians of 3)
   projected Newton, with the supernodal factorization, reaches it 3.4-6.7x
   sooner than the preconditioned L-BFGS on camelhead, face and bimba
   (22,704-89,215 triangles), 2.5x on hilbert, and ties on horse_cut; it
   also wins on the small camel_b and cow, but loses 1.3x on the 10,192
   triangles of mech-holes-shark, so below 20,000 triangles the
   preconditioned L-BFGS stays (an iteration of it costs 0.7-1.6 ms there,
   one of Newton 7-17 times as much).  Sec 6.6 also kept L-BFGS for a
   start above E0 = 1e9, for lucy (48,275 triangles), whose Tutte start
   (E0 = 3.9e12) clipped every Newton step; from the mean-value start that
   is now the default (E0 = 1.2e15, sec 6.7) Newton reaches SCAF's energy
   in 77 iterations, 1.9x sooner than L-BFGS (sec 6.10), so that threshold
   is gone (BP__AUTO_NEWTON_E0 is infinite; a start whose energy is not
   finite keeps L-BFGS).  Above 100,000 triangles
   nothing was compared, and Newton's factor needs ~1.7 KB per face against
   L-BFGS's ~0.75 (issue 15's million-face chart must stay under 1 KiB),
   so L-BFGS stays there.  The sum is taken by chunks of triangles added
   in chunk order (bp__energy_task, as bp__evaluate takes it), so the
   choice is the same on any number of threads. */
#ifndef BP__AUTO_NEWTON_MIN
#define BP__AUTO_NEWTON_MIN 20000u
#endif
#ifndef BP__AUTO_NEWTON_MAX
#define BP__AUTO_NEWTON_MAX 100000u
#endif
#ifndef BP__AUTO_NEWTON_E0
#define BP__AUTO_NEWTON_E0 HUGE_VAL   /* sec 6.6 had 1e9 (measurements) */
#endif
static int bp__opt_choose_newton(bp__solver *S, const double *x)
{
    bp__eval_task T;
    double sum = 0;
    uint32_t c;
    if (S->nt < BP__AUTO_NEWTON_MIN || S->nt >= BP__AUTO_NEWTON_MAX) return 0;
    memset(&T, 0, sizeof T);
    T.S = S;
    T.x = x;
    S->par.run(S->par.user, bp__energy_task, &T, S->nchunk_t);   /* E_D by chunks, as bp__evaluate */
    for (c = 0; c < S->nchunk_t; c++) sum += S->part[c];
    return sum / S->nt < BP__AUTO_NEWTON_E0;       /* also false for a NaN or infinite start */
}

/* Whether the edges of chunk c of the triangles respect the order (in
   ok[c]). */
typedef struct bp__keeps_task {
    const bp__solver  *S;
    const bp__ndnode  *tree;
    const uint32_t    *iperm;
    uint32_t          *ok;
} bp__keeps_task;

static void bp__keeps_task_run(void *task, uint32_t c)
{
    bp__keeps_task *T = (bp__keeps_task *)task;
    const bp__solver *S = T->S;
    size_t j, j1 = 3 * (size_t)bp__chunk_at(S->nt, S->nchunk_t, c + 1);
    T->ok[c] = 1;
    for (j = 3 * (size_t)bp__chunk_at(S->nt, S->nchunk_t, c); j < j1; j++) {
        uint32_t uw[2];
        uw[0] = S->tri[j];
        uw[1] = S->tri[j % 3 == 2 ? j - 2 : j + 1];
        if (!bp__nd_keeps(T->tree, T->iperm, uw, 1)) { T->ok[c] = 0; return; }
    }
}

/* The start map's order (>>tutte, phase 5b), taken from the chart, which
   keeps it no longer (a new start map makes a new one), into P->N's kept
   order: the chart's own edges must respect it (they do, unless the
   caller changed chart.start_order: then it is dropped, as it is when
   its tree is not nested: a node outside its half of its parent).
   Newton's first factorization uses it as it does a kept order, when the
   barrier's pairs respect it too (bp__nd_keeps); the L-BFGS
   preconditioner, the chart's Laplacian (its graph the chart's edges,
   fewer where pins are), always, after which it is freed (bp__opt_setup).
   Returns 0 out of memory. */
static int bp__opt_start_order(bp__opt *P, bp_chart *ch)
{
    uint32_t nv = P->S.nv, k, j, *o = ch->start_order, *iv;
    ch->start_order = NULL;
    if (!o || !(P->newton || P->precond) || P->N.kperm || nv != ch->num_vertices) { bp__free(&P->a, o); return 1; }
    if (!(iv = (uint32_t *)bp__alloc_array(&P->a, nv ? nv : 1, sizeof(uint32_t)))) { bp__free(&P->a, o); return 0; }
    for (k = 0; k < nv; k++) iv[k] = BP__NONE;
    for (k = 0; k < nv && o[k] < nv && iv[o[k]] == BP__NONE; k++) iv[o[k]] = k;
    for (j = 0; j < BP__ND_NODES; j++) {
        const uint32_t *w = o + nv + 6 * j;
        bp__ndnode *N = &P->N.ktree[j];
        memset(N, 0, sizeof *N);
        N->lo = w[0]; N->a = w[1]; N->b = w[2]; N->hi = w[3]; N->used = w[4] != 0; N->split = w[5] != 0;
        if (N->used && !(N->lo <= N->a && N->a <= N->b && N->b <= N->hi && N->hi <= nv)) k = 0;
        if (N->used && j > 0) {                   /* inside its half of a split parent */
            const bp__ndnode *U = &P->N.ktree[(j - 1) / 2];
            uint32_t lo = j % 2 ? U->lo : U->a, hi = j % 2 ? U->a : U->b;
            if (!U->used || !U->split || N->lo < lo || N->hi > hi) k = 0;
        }
    }
    if (k != nv || !P->N.ktree[0].used || P->N.ktree[0].lo != 0 || P->N.ktree[0].hi != nv) k = 0;
    if (k == nv) {                                            /* every edge of the chart, by chunks */
        bp__keeps_task T;
        T.S = &P->S; T.tree = P->N.ktree; T.iperm = iv;
        T.ok = (uint32_t *)bp__alloc_array(&P->a, (size_t)P->S.nchunk_t + 1, sizeof(uint32_t));
        if (!T.ok) { bp__free(&P->a, o); bp__free(&P->a, iv); return 0; }
        P->par.run(P->par.user, bp__keeps_task_run, &T, P->S.nchunk_t);
        for (j = 0; j < P->S.nchunk_t; j++) if (!T.ok[j]) k = 0;
        bp__free(&P->a, T.ok);
    }
    if (k != nv) { bp__free(&P->a, o); bp__free(&P->a, iv); return 1; }
    P->N.kperm = o;                               /* nv words and more: freed as one */
    P->N.kiperm = iv;
    return 1;
}

/* Phase 2: options, the pins held, solver, the direction (the default's
   choice, above), Newton's pattern and first order or the preconditioner,
   vectors; x = the start map. */
static bp_status bp__opt_setup(bp__opt *P, bp_chart *ch, uint32_t chart_index, const bp_mesh *m, bp_error *err)
{
    double *rest_wxy;
    bp_status st;
    uint32_t nv2;
    if (P->o.max_iterations <= 0) P->o.max_iterations = 10000;
    if (!(P->o.tolerance > 0)) P->o.tolerance = 1e-7;
    if ((st = bp__opt_pins(P, ch, m, err)) != BP_OK) return st;                 /* pins */
    rest_wxy = (double *)bp__alloc_array(&P->a, 3 * (size_t)ch->num_triangles, sizeof(double));
    if (!rest_wxy) return bp__oom(err, "optimizing a chart");
    if ((st = bp__solver_chart_par(&P->S, &P->a, ch, m, &P->o, rest_wxy, &P->par, err)) != BP_OK) {
        bp__free(&P->a, rest_wxy);
        return st;
    }
    P->S.par = P->par;
    if (P->o.direction == BP_DIRECTION_DEFAULT) {
        P->newton = bp__opt_choose_newton(&P->S, ch->uv);
        P->precond = !P->newton;
    }
    P->hist = P->o.history > 0 ? P->o.history : 5;
    if (P->o.direction == BP_DIRECTION_GRADIENT || P->newton) P->hist = 0;   /* Newton falls back to -g */
    if (P->newton) {                          /* >>newton; pins held or pulled */
        if (bp__newton_init(&P->N, &P->a, &P->S) != BP_OK) {
            bp__free(&P->a, rest_wxy);
            return bp__oom(err, "setting up Newton's method");
        }
        P->N.hold = P->pidx;
        if (P->pen) { P->N.pull = P->pen->pidx; P->N.pull_w = P->pen->w; }
        P->N.given = P->handoff;              /* for the first factorization */
        P->N.iso = BP__NEWTON_ISO && P->S.energy == BP_ENERGY_SYMMETRIC_DIRICHLET && !P->pen;   /* (>>newton) */
    } else
        bp__handoff_free(&P->a, P->handoff);  /* not Newton: freed before the preconditioner */
    if (!bp__opt_start_order(P, ch)) {
        bp__free(&P->a, rest_wxy);
        return bp__oom(err, "setting up the solver");
    }
    /* the preconditioner first: its factorization is the memory peak, and
       the flattened rest triangles are not needed after it */
    if (P->precond && (st = bp__laplacian(&P->a, &P->S, rest_wxy, P->pidx, &P->K, &P->KF, P->N.kperm, P->N.ktree)) != BP_OK) {
        bp__free(&P->a, rest_wxy);
        if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "factoring the preconditioner");
        if (st == BP_ERR_TOO_LARGE)
            return bp__factor_too_large(err, chart_index, ch->num_triangles, "Laplacian preconditioner", P->S.nv);
        return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, chart_index, -1, 0,
                        "chart %u: the Laplacian preconditioner could not be factored", chart_index);
    }
    bp__free(&P->a, rest_wxy);
    if (!P->newton) {                          /* the start order served the preconditioner */
        bp__free(&P->a, P->N.kperm);
        bp__free(&P->a, P->N.kiperm);
        P->N.kperm = P->N.kiperm = NULL;
    }
    nv2 = P->nv2 = 2 * P->S.nv;
    P->x = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
    P->g = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
    P->xn = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
    P->gn = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
    P->v = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
    P->pwork = (double *)bp__alloc_array(&P->a, 4 * (size_t)P->S.nv, sizeof(double));
    P->vpart = (double *)bp__alloc_array(&P->a, 2 * ((size_t)bp__vec_nchunks(nv2) + 1) +
                                         (size_t)bp__nchunks(P->S.nv, BP__QUAD_CHUNK) + 1, sizeof(double));
    if (P->newton) {
        P->xe = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
        P->ge = (double *)bp__alloc_array(&P->a, nv2, sizeof(double));
        if (!P->xe || !P->ge) return bp__oom(err, "optimizing a chart");
    }
    if (!P->pwork || !P->vpart || !P->x || !P->g || !P->xn || !P->gn || !P->v ||
        !bp__lbfgs_init(&P->a, &P->L, P->hist, nv2))
        return bp__oom(err, "optimizing a chart");
    memcpy(P->x, ch->uv, nv2 * sizeof(double));
    return BP_OK;
}

/* Phase 3 (step 2 of each iteration): the search direction v = -H g
   (L-BFGS, above), or with no pairs yet -K^-1 g (preconditioned) or -g,
   or Newton's -(H + delta I)^-1 g (>>newton; P->nd = 1, or -1 out of
   memory; when its matrix cannot be factored, -g); returns g.v (0:
   converged).  Also sets the first step of gradient descent: move the
   fastest vertex by about a tenth of a boundary edge. */
static double bp__opt_direction(bp__opt *P)
{
    double gv = 0, *g = P->g, *v = P->v;
    uint32_t i, nv2 = P->nv2;
    P->nd = P->newton ? bp__newton_direction(&P->N, &P->S, P->x, g, v, &gv) : 0;
    if (P->nd < 0) return 0;
    if (P->nd) {
        /* v = -(H + delta I)^-1 g, computed above */
    } else if (P->L.nh > 0) {
        gv = bp__lbfgs_direction(&P->L, &P->par, g, v, P->precond ? &P->K : NULL, &P->KF, P->pwork, P->vpart);
    } else if (P->precond) {
        const double *gp = g, *vp = v;
        bp__vec_axpy(&P->par, P->vpart, nv2, v, NULL, -1, g, NULL, NULL, NULL);
        bp__precondition(&P->KF, &P->par, v, v, P->pwork);
        bp__vec_pass(&P->par, P->vpart, nv2, NULL, 0, NULL, 0, NULL, NULL, 1, &gp, &vp, &gv);
    } else {
        bp__vec_axpy(&P->par, P->vpart, nv2, v, NULL, -1, g, g, v, &gv);
    }
    bp__opt_hold(P, v);                       /* pins: g is zero there, so g.v is unchanged */
    if (!(gv < 0)) {                          /* not a descent direction: restart */
        P->L.nh = 0;
        gv = 0;
        for (i = 0; i < nv2; i++) { v[i] = -g[i]; gv -= g[i] * g[i]; }
    }
    if (gv != 0 && !P->nd && P->L.nh == 0 && (!P->gd_scale_set || P->hist == 0)) {
        double vmax = 0;
        for (i = 0; i < nv2; i++) if (fabs(v[i]) > vmax) vmax = fabs(v[i]);
        if (!P->gd_scale_set) P->tlast = 0.05 * P->S.mean_edge / vmax;
        P->gd_scale_set = 1;
    }
    return gv;
}

/* Longer Newton steps (beyond the dissertation).  A full Newton step that
   is accepted at once says little about how far the line goes down: the
   quadratic model of a term 1/s^2 (a triangle crushed by the start map,
   s its scale) puts the minimum at s + s/3, so a full step only shrinks
   such a term by (3/4)^2 = 9/16, while the true minimum along the line
   lies many steps out.  So, after an accepted full step, try t = 2, 4,
   8, ... (each one evaluation of the energy and the exact check, cheap
   next to a factorization), within 0.9 of the step bound computed again
   for the longer line, and keep the lowest energy among them; stop at the
   first trial that does not lower it (or fails the check).  Every kept
   point passed the same exact check as any other, so it is bijective.
   The trial points go to P->xe / P->ge and are swapped in when better.
   Only worth trying when the full step went down about as far as the
   quadratic model said, -g.v / 2 (v = -M^-1 g for Newton's H or K1, so
   the model's curvature along v is -g.v): with a share r of that
   decrease, the parabola through f, g.v and f(1) has its minimum at
   t = 1 / (2 - r), short of 1 when r < 1.  Measured on fifteen corpus
   meshes (docs/performance.md sec 6.32): of the 43 trials after a share
   below 1, 41 failed (each an evaluation and an exact check for nothing:
   face's isotropic iterations 3 to 6, 20 ms of one thread), and the two
   that gained were at 0.966 and 0.991, on horse_cut's crushed start; so
   the doubling is tried from a share of BP__NEWTON_EXTEND_RATIO on. */
#ifndef BP__NEWTON_EXTEND
#define BP__NEWTON_EXTEND 1           /* 0: stop at the full step (measurements) */
#endif
#ifndef BP__NEWTON_EXTEND_MAX
#define BP__NEWTON_EXTEND_MAX 40      /* doublings: t up to 2^40 */
#endif
#ifndef BP__NEWTON_EXTEND_RATIO
#define BP__NEWTON_EXTEND_RATIO 0.9   /* only past this share of the model's decrease */
#endif
static int bp__opt_extend(bp__opt *P, double f, double gv, double *t, double *fn, double *edn)
{
    double cap = 1024, tmax = bp__step_bound(&P->S, P->x, P->v, cap), tt = *t;
    int k;
    for (k = 0; k < BP__NEWTON_EXTEND_MAX; k++) {
        double fe, ede, *tp;
        int valid;
        tt *= 2;
        while (tt > 0.9 * tmax && tmax == cap && cap < 1e30) {   /* the bound was the cap: look further */
            cap *= 1024;
            tmax = bp__step_bound(&P->S, P->x, P->v, cap);
        }
        if (tt > 0.9 * tmax) tt = 0.9 * tmax;
        if (!(tt > *t)) return 1;
        bp__vec_axpy(&P->par, P->vpart, P->nv2, P->xe, P->x, tt, P->v, NULL, NULL, NULL);
        fe = bp__evaluate(&P->S, P->xe, P->ge, &ede, *fn, &valid);
        if (P->S.oom) return -1;
        bp__opt_hold(P, P->ge);               /* pins */
        if (P->pen) fe += bp__opt_penalty(P, P->xe, P->ge);
        if (!(fe < *fn && fe <= f + 1e-4 * tt * gv) || !valid) return 1;
        *t = tt; *fn = fe; *edn = ede;
        P->N.cut = 1;                         /* not the model's step: refactor next */
        tp = P->xn; P->xn = P->xe; P->xe = tp; tp = P->gn; P->gn = P->ge; P->ge = tp;
    }
    return 1;
}

/* A chart whose start was crushed and enlarged (>>start, 4) spends its
   first ~60 Newton iterations with steps clipped by the step bound at one
   to a few crushed triangles that the direction would flip; there the
   first trial goes to 0.99 tmax instead of 0.9 (the exact check and
   Armijo still decide; halving follows as always).  Not for other charts:
   on hilbert, whose clipping pair is a barrier jam, 0.99 took 101
   iterations to SCAF's energy against 64 (docs/performance.md 6.11). */
#ifndef BP__CRUSHED_SHARE
#define BP__CRUSHED_SHARE 0.99
#endif

/* Phase 4 (steps 3 and 4): the singularity-aware bound tmax, then the
   backtracking line search from min(first step, 0.9 tmax): the first t with
   sufficient decrease whose map xn passes the exact check (bp__evaluate:
   orientation, boundary conflicts, one counter-clockwise loop) is
   accepted.  Returns 1 with *t, *fn, *edn set, 0 if no step was found,
   -1 when out of memory. */
static int bp__opt_line_search(bp__opt *P, double f, double gv, double *t, double *fn, double *edn)
{
    double tt = (P->L.nh > 0 || P->nd) ? 1.0 : 2 * P->tlast;   /* the first step to try ... */
    double tmax = bp__step_bound(&P->S, P->x, P->v, tt / 0.9);
    int tries;
    if (tmax < tt / 0.9 && tt > 0.9 * tmax)                      /* ... at most 0.9 tmax */
        tt = (P->nd && P->crushed ? BP__CRUSHED_SHARE : 0.9) * tmax;
    for (tries = 0; tries < 60 && tt > 0; tries++, tt *= 0.5) {
        int valid;
        bp__vec_axpy(&P->par, P->vpart, P->nv2, P->xn, P->x, tt, P->v, NULL, NULL, NULL);
        *fn = bp__evaluate(&P->S, P->xn, P->gn, edn, f + 1e-4 * tt * gv, &valid);  /* f, gradient, exact check */
        if (P->S.oom) return -1;
        bp__opt_hold(P, P->gn);               /* pins */
        if (P->pen) *fn += bp__opt_penalty(P, P->xn, P->gn);
        if (!(*fn <= f + 1e-4 * tt * gv)) continue;
        if (!valid) continue;                 /* floating point was wrong: shrink */
        *t = tt;
        /* Newton: the factor may serve the next iteration only when this
           step behaved as the quadratic model said (>>newton) */
        P->N.cut = !(tries == 0 && tt == 1 && f - *fn >= -0.5 * BP__NEWTON_REUSE_RHO * gv &&
                     f - *fn <= -0.5 * gv / BP__NEWTON_REUSE_RHO && f - *fn <= BP__NEWTON_REUSE_DF * fabs(f));
        P->N.wide = tries == 0 && tt < 1 && P->S.bclip;   /* clipped by the boundary (>>newton) */
        if (P->nd && tries == 0 && tt == 1 && BP__NEWTON_EXTEND && f - *fn >= -0.5 * BP__NEWTON_EXTEND_RATIO * gv)
            return bp__opt_extend(P, f, gv, t, fn, edn);
        return 1;
    }
    return 0;
}

/* Phase 5: the chart's report from the final map x (already in ch->uv). */
static bp_status bp__opt_finish(bp__opt *P, bp_chart *ch, uint32_t chart_index, double ed, double c0, bp_error *err)
{
    double emax = 0;
    uint32_t t;
    ch->energy_end = ed / P->S.nt;
    for (t = 0; t < P->S.nt; t++) {
        const uint32_t *tr = P->S.tri + 3 * (size_t)t;
        double e = bp__triangle_energy(P->S.energy, &P->S.rest[t], P->x + 2 * (size_t)tr[0],
                                       P->x + 2 * (size_t)tr[1], P->x + 2 * (size_t)tr[2], NULL, NULL, NULL);
        if (e > emax) emax = e;
    }
    ch->energy_max = emax;
    ch->seconds = bp__seconds() - c0;
    if (ch->stop == BP_STOP_CANCELLED)
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_CHART, chart_index, -1, 0,
                        "chart %u: cancelled by the progress callback after %d iterations (the map is the last valid one)",
                        chart_index, ch->iterations);
    return bp__ok(err);
}

/* The optimization of one chart (sec 3.4, 3.5): phases 1 and 2, then the
   iterations, each (1) energy and gradient (from the line search of the
   previous one), (2) direction, (3)+(4) step bound and line search, (5)
   convergence test, and phase 5.  The map in ch->uv is replaced only by
   accepted iterates, each exactly valid; the progress callback sees each. */
static bp_status bp__chart_optimize_pen(bp_chart *ch, uint32_t chart_index, const bp_mesh *m,
                                        const bp_options *opt, const bp__par *runner,
                                        const struct bp__penalty *pen, bp__handoff *h, bp_error *err)
{
    bp__opt P;
    void *pool = NULL;
    int it, small = 0;
    double f, ed;
    bp_status st;
    double c0 = bp__seconds();
    memset(&P, 0, sizeof P);
    P.a = bp__allocator_of(opt);
    P.pen = pen;                              /* pins (homotopy) */
    P.handoff = h;
    P.tlast = 1;
    P.precond = opt && opt->direction == BP_DIRECTION_PRECONDITIONED;   /* the default: bp__opt_setup */
    P.newton = opt && opt->direction == BP_DIRECTION_NEWTON;
    if (opt) P.o = *opt;
    if (!ch || !m || !ch->uv || !ch->num_loops)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_CHART, chart_index, -1, 0,
                        "bp_chart_optimize needs a chart with a start map (bp_chart_init)");
    if ((int)P.o.energy < 0 || (int)P.o.energy >= (int)BP_ENERGY_COUNT)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "unknown energy %d", (int)P.o.energy);
    if (runner) P.par = *runner;                /* bp_parameterize's pool, or serial */
    else if (ch->num_triangles >= BP__PAR_MIN_TRIANGLES) P.par = bp__par_begin(&P.a, opt, &pool);
    else P.par = bp__par_serial();              /* small: no pool (see >>threads) */
    if ((st = bp__opt_check_start(&P.a, ch, chart_index, m, !P.o.no_barrier, &P.par, err)) != BP_OK) {
        bp__par_end(&P.a, pool);
        return st;
    }
    ch->threads = P.par.threads;
    if ((st = bp__opt_setup(&P, ch, chart_index, m, err)) != BP_OK) goto done;
    f = bp__objective(&P.S, P.x, P.g, &ed);
    if (P.S.oom) { st = bp__oom(err, "evaluating the barrier"); goto done; }
    bp__opt_hold(&P, P.g);                    /* pins */
    if (P.pen) f += bp__opt_penalty(&P, P.x, P.g);
    if (!(f < HUGE_VAL)) {
        st = bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, chart_index, -1, 0,
                      "chart %u: the start map is exactly valid but its energy is not finite in floating point "
                      "(a triangle too thin, or coordinates too large)", chart_index);
        goto done;
    }
    ch->energy_start = ed / P.S.nt;
    if (BP__START_SCALE && bp__start_scale(&P, &f, &ed) < 0) { st = bp__oom(err, "evaluating the barrier"); goto done; }
    ch->stop = BP_STOP_MAX_ITERATIONS;
    for (it = 0; it < P.o.max_iterations; it++) {
        double gv = bp__opt_direction(&P), tt = 0, fn = HUGE_VAL, edn = HUGE_VAL;
        int found;
        if (P.nd < 0) { st = bp__oom(err, "factoring Newton's system"); goto done; }
        if (gv == 0) { ch->stop = BP_STOP_CONVERGED; break; }
        /* Newton: the decrement -g.v / 2 predicts the decrease left */
        if (P.nd && !P.N.iso && -gv <= 2 * P.o.tolerance * fabs(f)) { ch->stop = BP_STOP_CONVERGED; break; }
        found = bp__opt_line_search(&P, f, gv, &tt, &fn, &edn);
        if (found < 0) { st = bp__oom(err, "evaluating a step"); goto done; }
        if (!found) { ch->stop = BP_STOP_NO_PROGRESS; break; }
        P.tlast = tt;
        bp__lbfgs_push(&P.L, &P.par, P.x, P.xn, P.g, P.gn);     /* the new pair s, y */
        { double *tp = P.x; P.x = P.xn; P.xn = tp; tp = P.g; P.g = P.gn; P.gn = tp; }   /* accept: swap, no copy */
        /* the current (exactly valid) map, visible to the progress callback */
        bp__vec_pass(&P.par, P.vpart, P.nv2, ch->uv, 1, P.x, 0, NULL, NULL, 0, NULL, NULL, NULL);
        /* (5) convergence: relative decrease below tol three times running */
        if ((f - fn) <= P.o.tolerance * fabs(fn)) small++; else small = 0;
        if (P.N.iso && !(f - fn >= BP__NEWTON_ISO_TAU * fabs(f))) bp__newton_iso_end(&P.N, &P.a);   /* Newton next */
        f = fn;
        ed = edn;
        ch->iterations = it + 1;
        if (P.o.progress && P.o.progress(P.o.progress_user, chart_index, it + 1, ed / P.S.nt, tt)) {
            ch->stop = BP_STOP_CANCELLED;
            break;
        }
        if (small >= 3) { ch->stop = BP_STOP_CONVERGED; break; }
        if (P.o.max_seconds > 0 && bp__seconds() - c0 > P.o.max_seconds) {
            ch->stop = BP_STOP_MAX_SECONDS;
            break;
        }
    }
    /* every accepted x passed the exact check, so x is the last valid map */
    memcpy(ch->uv, P.x, P.nv2 * sizeof(double));
    st = bp__opt_finish(&P, ch, chart_index, ed, c0, err);
done:
    bp__opt_free(&P);
    bp__par_end(&P.a, pool);
    return st;
}

static bp_status bp__chart_optimize(bp_chart *ch, uint32_t chart_index, const bp_mesh *m,
                                    const bp_options *opt, const bp__par *runner, bp_error *err)
{
    return bp__chart_optimize_pen(ch, chart_index, m, opt, runner, NULL, NULL, err);
}

/* The public optimization (opt already read by bp__opts), with the start's
   factor h or NULL. */
static bp_status bp__chart_optimize_api(bp_chart *ch, uint32_t chart_index, const bp_mesh *m, const bp_options *opt,
                                        bp__handoff *h, bp_error *err)
{
    bp_options linked;                                            /* >>progress */
    bp__iter_link L;
    if (ch && m && ch->uv && opt && opt->num_pins) {                            /* pins */
        bp_status st = bp__pins_at_targets(ch, chart_index, m, opt, err);
        if (st != BP_OK) return st;
    }
    return bp__chart_optimize_pen(ch, chart_index, m, bp__with_iter_link(opt, &linked, &L), NULL, NULL, h, err);
}

BPDEF bp_status bp_chart_optimize(bp_chart *ch, uint32_t chart_index, const bp_mesh *m,
                                  const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status st;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;
    return bp__chart_optimize_api(ch, chart_index, m, opt, NULL, err);
}

/* Both at once (bp__handoff between them).  The same calls as
   bp_chart_init's and bp_chart_optimize's, in the same order. */
BPDEF bp_status bp_chart_solve(bp_chart *ch, uint32_t chart_index, const bp_mesh *m, const bp_options *opt,
                               bp_error *err)
{
    bp_options o_;
    bp_status st;
    bp_allocator a;
    bp__handoff h;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;       /* >>progress */
    a = bp__allocator_of(opt);
    memset(&h, 0, sizeof h);
    st = bp__chart_start(ch, m, opt, &h, err);
    if (st == BP_OK && !(opt && opt->init_only)) st = bp__chart_optimize_api(ch, chart_index, m, opt, &h, err);
    bp__handoff_free(&a, &h);
    return st;
}

/* Area-weighted mean and max of E_t for a chart's current map. */
BPDEF bp_status bp_chart_distortion(const bp_chart *ch, const bp_mesh *m, bp_energy energy,
                                    double *mean, double *max, double *per_triangle, bp_error *err)
{
    uint32_t t;
    double sum = 0, area = 0, emax = 0;
    if (!ch || !m || !ch->uv)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_chart_distortion needs a chart with a map (uv) and its mesh");
    if ((int)energy < 0 || (int)energy >= (int)BP_ENERGY_COUNT)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "unknown energy %d", (int)energy);
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        bp__rest r;
        double w, px, py, e;
        bp__chart_rest(ch, m, t, &w, &px, &py);
        bp__rest_inverse(w, px, py, 1, &r);
        r.weight = 1;
        e = bp__triangle_energy(energy, &r, ch->uv + 2 * (size_t)tr[0], ch->uv + 2 * (size_t)tr[1],
                                ch->uv + 2 * (size_t)tr[2], NULL, NULL, NULL);
        if (per_triangle) per_triangle[t] = e;
        sum += 0.5 * w * py * e;
        area += 0.5 * w * py;
        if (e > emax) emax = e;
    }
    if (mean) *mean = sum / area;
    if (max) *max = emax;
    return bp__ok(err);
}

/* >>pack ===================================================================

   Without opt->atlas_resolution (0, the default) the charts' bounding
   boxes go on shelves (bp__pack_shelf, >>driver).  With atlas_resolution =
   RES the charts go into the square [0,1]^2 as a texture of RES x RES
   texels, with opt->padding = P texels between any two of them and
   ceil(P/2) between each of them and the edge of the square.  Four
   steps:

   1. One texel density.  A texture spends its texels evenly only when every
      chart has the same ratio of UV area to 3D area, so chart c is scaled
      by k_c = sqrt(A3d_c / Auv_c) before anything else; a common factor d
      (texels per unit of length) then sizes the whole atlas.  With
      importance (opt->importance, or visibility, chapter 4) the optimized
      map already gives each triangle about I_t times its 3D area (eq 4.1:
      the rest shape grows by sqrt(I_t)), across charts as well as inside
      them, so the charts keep their relative scale (k_c = 1) and the
      importance-weighted density carries over to the atlas.

   2. Orientation.  A convex polygon's minimum-area enclosing rectangle has
      a side collinear with one of the polygon's edges (Freeman and
      Shapira, CACM 1975; the classical fact behind Toussaint's rotating
      calipers, 1983, as the McGill "rotating calipers" pages and D.
      Eberly's note "Minimum-Area Rectangle Containing a Set of Points",
      Geometric Tools 2015, explain; the calipers visit the candidates in
      linear time, the exhaustive search in quadratic).  The convex hull of the chart's vertices is computed with
      exact orientation tests and every hull edge is tried (the exhaustive
      search: quadratic in the hull size, which is small next to the chart);
      the chart is rotated so that the best edge lies on the x axis.  The
      packer then also tries the three quarter turns of that orientation,
      which are exact in floating point, and keeps whichever lands lowest.
      A long chart (box aspect above 1.5) that is large (at least 1/64 of
      the total area) also tries the four turns of its smallest bounding
      square (sampled every half degree), which is what lets a lone long
      chart use the square atlas.  A mirror image is never tried: it would
      flip every triangle.

   3. Placement on rasterized outlines.  Each chart is rasterized
      conservatively: every texel [i,i+1]x[j,j+1] that a closed triangle,
      grown by a margin of 1e-6 texel, touches.  The atlas keeps one bit per
      texel in rows of 64-bit words; a placed chart marks its raster dilated
      by P texels (a square of side 2P+1 around each texel, so the Chebyshev
      distance).  A new chart may go where its undilated raster meets no
      marked bit.  Charts are placed largest first at the lowest, then
      leftmost, origin where they fit, so small charts fill the notches and
      holes that larger ones leave: the bottom-left rule of the nesting
      literature (Dowsland, Vaid and Dowsland, "An algorithm for polygon
      placement using a bottom-left strategy", EJOR 141, 2002, which lets
      pieces nest inside the partial layout as here, and cites Jakobs's
      genetic algorithms for the packing of polygons as its origin), here on
      rasters instead of no-fit polygons.  xatlas packs rasterized, dilated
      charts in 64-bit-word bit images too, with a random or a brute-force
      search over positions; we read it to learn, and wrote the search below
      with pruning of our own.  What keeps the search fast: each atlas row
      remembers its longest free run of texels; a chart's row that is longer
      rules a position out with one comparison, a monotone pointer per run
      length skips the rows that have become too full for good, and the
      candidate positions come from the free runs of the atlas row under the
      chart's longest row and are intersected, 64 at a time, with those
      allowed by its first and last rows (and, for a tall chart, by its
      quarter rows) before the full bit test, which skips each row's empty
      words.  For small charts (both sides at most 32 texels) a table
      remembers, per size, the lowest row at which a chart of that size
      found room or gave up; a chart at least as large starts there.  That
      is a heuristic (a larger box does not always hold a larger shape): it
      costs 0.7% of utilization on 5,000 small charts and makes their
      packing 3.3 times faster.  The density d is the largest that fits:
      start at the d that would fill the square exactly (utilization 1),
      shrink by the square root of the share of the area that found room
      until the charts fit, then bisect (geometric mean) to 0.2%.

   4. The final coordinates are uv = (L + (x, y)) / RES, L being the
      rotated, scaled chart shifted into its raster.  Rotation and scaling
      round, so each moved chart is checked exactly again, like every move
      in bp_atlas_pack; a chart whose rotated copy is not exactly as valid as
      it was falls back to its own orientation (scaled only) and the packing
      runs again.

   The border.  The atlas starts with a frame of B = ceil(P/2) texels along
   each of its four edges marked as taken, so every chart keeps at least
   P/2 texels from the edge of the square.  Why half the padding and not
   all of it, nor none: the padding is there for the texture filters and
   for a baker's dilation (edge padding), which grow each chart into the
   gutter around it.  Between two charts the gutter of P texels is shared,
   P/2 for each side.  At the edge of the square only one chart grows
   into it; with clamp-to-edge sampling nothing lies beyond, and with
   wrap-around (repeat) sampling -- the case where a chart touching the
   edge bleeds -- the chart across the edge keeps its own P/2, so the
   tiled atlas keeps P texels between any two charts, across the edge as
   inside.  A full P at the edge would leave 2P there, texels no filter
   needs.  xatlas's packer (as read, source/xatlas/xatlas.cpp: "translate
   to remove padding from top and left atlas edges", and the atlas size
   reduced by twice the padding) keeps only about half a texel at the
   edge, so its charts bleed under wrap-around; bakers that tile (lightmaps
   and repeating textures) want the gutter.  Padding 0 keeps no border.

   Why the padding holds on the final coordinates: a point of a chart lies
   in one of its marked texels (the rasterization is conservative, and the
   margin of 1e-6 texel is far above the rounding of the final formula, at
   most RES * 2^-52 texel).  Marked texels of two different charts are at
   least P+1 apart in x or in y (the dilation), so their points are at least
   P texels = P/RES apart in that coordinate.  No marked texel lies in the
   frame, so a point is at least B texels from each edge: uv in
   [B/RES, 1 - B/RES].  Padding 0 still keeps the charts on disjoint
   texels.  tests/test_pack.c measures the distance between the boundary
   segments of different charts, and of every uv to the edge, by brute
   force.

   The packer is serial and uses no floating-point state that depends on the
   thread count, so the atlas is bit-identical for any number of threads. */

#define BP__PACK_MARGIN 1e-6      /* texels the rasterized triangles grow by */
#define BP__PACK_SHIFT  4e-6      /* texels between a raster's edge and its chart */
#define BP__PACK_MAX_RES 32768
#define BP__PACK_PREFILTER_RUNS 16
#define BP__PACK_MEMO 32

/* A bit image: h rows of `words` 64-bit words; bit x of row y is texel (x,y). */
typedef struct bp__bits { int w, h, words; uint64_t *b; } bp__bits;

/* A chart's raster in one orientation, with the facts the search prunes by. */
typedef struct bp__shape {
    bp__bits r;
    int *rowrun;                /* longest run of marked texels in each row */
    int *span;                  /* first and last nonzero word of each row  */
    int rstar;                  /* the row with the longest run              */
} bp__shape;

/* The atlas being filled. */
typedef struct bp__occ {
    int res, aw;                /* texels per side, words per row (2 spare)  */
    int border;                 /* texels along each edge kept free: ceil(P/2) */
    uint64_t *b;                /* res rows; bits at x >= res are set        */
    int *maxfree;               /* longest run of free texels in each row    */
    int *ylow;                  /* ylow[v]: every row below has maxfree < v  */
    uint64_t *t0, *t1, *v;      /* scratch rows                              */
    int floor_[BP__PACK_MEMO][BP__PACK_MEMO]; /* small charts: floor_[w][h] is
                                   a row below which no chart of at least
                                   w+1 x h+1 texels found room (a heuristic
                                   lower bound where the search starts)      */
} bp__occ;

typedef struct bp__pchart {
    uint32_t chart;
    double *orig;               /* the chart's map before packing            */
    double k;                   /* scale to the common density (per unit d)  */
    double cs, sn;              /* rotation onto the minimum-area box        */
    double cs2, sn2;            /* rotation onto the smallest bounding square */
    double target;              /* area at d = 1 (the order: largest first)  */
    int turns;                  /* orientations tried: 4 quarter turns of the
                                   minimum-area box, 8 with those of the
                                   smallest square too, 1 (fallback)         */
    int x, y, turn;             /* placement in the current attempt          */
    int fx, fy, fturn;          /* placement at the best density that fit    */
    bp_check_report before;     /* the map's own validity                    */
} bp__pchart;

/* Signed area of the UV triangle (p0, p1, p2), in floating point (the sign
   is decided exactly only by bp_orient2d). */
static double bp__uv_tri_area(const double *p0, const double *p1, const double *p2)
{
    return 0.5 * ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]));
}

/* Total signed UV area of a chart's map (shoelace over its triangles). */
static double bp__chart_uv_area(const bp_chart *ch)
{
    double area = 0;
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        area += bp__uv_tri_area(ch->uv + 2 * (size_t)tr[0], ch->uv + 2 * (size_t)tr[1], ch->uv + 2 * (size_t)tr[2]);
    }
    return area;
}

/* All calls to the exact check from the packer go through here, on the
   packer's runner (bp_atlas_pack's).  BP_OK when bp_check gave a verdict
   (valid or not: the report says which, and the packer compares reports),
   else bp_check's failure. */
static bp_status bp__pack_check(const bp_allocator *a, const bp__par *par, const bp_chart *ch, const double *uv,
                                bp_check_report *rep)
{
    bp_status st = bp__check_par(ch->triangles, ch->num_triangles, uv, ch->num_vertices, a, par, rep, NULL);
    return bp__check_verdict_status(st) ? BP_OK : st;
}

/* Not worse than `before` on any count (a chart optimized without the
   barrier may overlap itself, and stays so). */
static int bp__report_no_worse(const bp_check_report *r, const bp_check_report *before)
{
    return r->flipped <= before->flipped && r->degenerate <= before->degenerate &&
           r->nonfinite <= before->nonfinite && r->boundary_intersections <= before->boundary_intersections &&
           r->loop_orientation <= before->loop_orientation && r->nested <= before->nested;
}

/* ---- bit rows ---- */

static void bp__bits_set_range(uint64_t *row, int x0, int x1)   /* texels x0..x1 */
{
    int q;
    for (q = x0 >> 6; q <= x1 >> 6; q++) {
        int lo = q == (x0 >> 6) ? (x0 & 63) : 0, hi = q == (x1 >> 6) ? (x1 & 63) : 63;
        uint64_t m = hi == 63 ? ~(uint64_t)0 : (((uint64_t)1 << (hi + 1)) - 1);
        row[q] |= m & (~(uint64_t)0 << lo);
    }
}

/* out = a >> k over n words: bit i of out is bit i+k of a (0 past the end). */
static void bp__bits_shr(const uint64_t *a, int n, int k, uint64_t *out)
{
    int q = k >> 6, s = k & 63, i;
    for (i = 0; i < n; i++) {
        uint64_t lo = i + q < n ? a[i + q] : 0, hi = i + q + 1 < n ? a[i + q + 1] : 0;
        out[i] = s ? (lo >> s) | (hi << (64 - s)) : lo;
    }
}

/* out = a << k over n words: bit i of out is bit i-k of a. */
static void bp__bits_shl(const uint64_t *a, int n, int k, uint64_t *out)
{
    int q = k >> 6, s = k & 63, i;
    for (i = n - 1; i >= 0; i--) {
        uint64_t hi = i - q >= 0 ? a[i - q] : 0, lo = i - q - 1 >= 0 ? a[i - q - 1] : 0;
        out[i] = s ? (hi << s) | (lo >> (64 - s)) : hi;
    }
}

/* dst |= src placed at bit offset off (may be negative), clipped to dst. */
static void bp__bits_or_at(uint64_t *dst, int dwords, const uint64_t *src, int swords, int off)
{
    int i;
    for (i = 0; i < swords; i++) {
        uint64_t v = src[i];
        int pos = off + 64 * i, q, s;
        if (!v || pos <= -64) continue;
        if (pos < 0) { dst[0] |= v >> (-pos); continue; }
        q = pos >> 6; s = pos & 63;
        if (q < dwords) dst[q] |= v << s;
        if (s && q + 1 < dwords) dst[q + 1] |= v >> (64 - s);
    }
}

/* Index of the lowest set bit of v != 0. */
static int bp__ctz64(uint64_t v)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctzll(v);
#else
    int n = 0;
    while (!(v & 1)) { v >>= 1; n++; }
    return n;
#endif
}

/* Longest run of set (want = 1) or clear (want = 0) bits among texels
   [0, w): run by run, each found with one count of trailing zeros. */
static int bp__bits_longest(const uint64_t *row, int w, int want)
{
    int best = 0, run = 0, x = 0;
    while (x < w) {
        int avail = 64 - (x & 63), k;
        uint64_t v = row[x >> 6] >> (x & 63), mask, rest;
        if (avail > w - x) avail = w - x;
        mask = avail == 64 ? ~(uint64_t)0 : ((uint64_t)1 << avail) - 1;
        if (!want) v = ~v;                       /* wanted bits as ones */
        v &= mask;
        if (v == mask) { run += avail; x += avail; continue; }
        k = bp__ctz64(~v);                       /* wanted bits before the first other one */
        run += k;
        if (run > best) best = run;
        run = 0;
        rest = v >> k;                           /* skip the run of other bits */
        if (!rest) { x += avail; continue; }
        x += k + bp__ctz64(rest);
    }
    return run > best ? run : best;
}

/* The runs of set bits of a row (at most cap of them). */
static int bp__bits_runs(const uint64_t *row, int w, int *start, int *len, int cap)
{
    int n = 0, x = 0;
    while (x < w && n < cap) {
        while (x < w && !(row[x >> 6] >> (x & 63) & 1)) x++;
        if (x >= w) break;
        start[n] = x;
        while (x < w && (row[x >> 6] >> (x & 63) & 1)) x++;
        len[n] = x - start[n];
        n++;
    }
    return n;
}

/* ---- rasterization ---- */

/* Every texel [i,i+1]x[j,j+1] that the closed triangle grown by m touches.
   Row j: the x-extent of the triangle within the slab [j-m, j+1+m] is
   reached at a vertex inside the slab or where an edge crosses one of the
   slab's lines; texels floor(xmin-m) to floor(xmax+m) cover it. */
static void bp__raster_triangle(bp__bits *B, const double *p0, const double *p1, const double *p2, double m)
{
    const double *p[3];
    double ylo, yhi;
    int j0, j1, j, k, l;
    p[0] = p0; p[1] = p1; p[2] = p2;
    ylo = yhi = p0[1];
    for (k = 1; k < 3; k++) { if (p[k][1] < ylo) ylo = p[k][1]; if (p[k][1] > yhi) yhi = p[k][1]; }
    j0 = (int)floor(ylo - m); j1 = (int)floor(yhi + m);
    if (j0 < 0) j0 = 0;
    if (j1 > B->h - 1) j1 = B->h - 1;
    for (j = j0; j <= j1; j++) {
        double lines[2], xmin = HUGE_VAL, xmax = -HUGE_VAL;
        int x0, x1;
        lines[0] = j - m; lines[1] = j + 1 + m;
        for (k = 0; k < 3; k++) {
            const double *a = p[k], *b = p[(k + 1) % 3];
            if (a[1] >= lines[0] && a[1] <= lines[1]) {
                if (a[0] < xmin) xmin = a[0];
                if (a[0] > xmax) xmax = a[0];
            }
            for (l = 0; l < 2; l++) {
                double Y = lines[l], t, x, lo = a[0] < b[0] ? a[0] : b[0], hi = a[0] < b[0] ? b[0] : a[0];
                if ((Y > a[1]) == (Y > b[1])) continue;    /* the edge does not cross Y */
                t = (Y - a[1]) / (b[1] - a[1]);
                x = a[0] + t * (b[0] - a[0]);
                if (x < lo) x = lo;
                if (x > hi) x = hi;
                if (x < xmin) xmin = x;
                if (x > xmax) xmax = x;
            }
        }
        if (!(xmin <= xmax)) continue;
        x0 = (int)floor(xmin - m); x1 = (int)floor(xmax + m);
        if (x0 < 0) x0 = 0;
        if (x1 > B->w - 1) x1 = B->w - 1;
        if (x0 <= x1) bp__bits_set_range(B->b + (size_t)j * B->words, x0, x1);
    }
}

static void bp__shape_free(const bp_allocator *a, bp__shape *S)
{
    bp__free(a, S->r.b);
    bp__free(a, S->rowrun);
    bp__free(a, S->span);
    S->r.b = NULL; S->rowrun = NULL; S->span = NULL;
}

/* The raster of a chart whose local coordinates L are >= BP__PACK_SHIFT.
   BP_ERR_NUMERICAL (not an error: the caller skips this orientation) when
   it is wider or taller than the atlas, before anything is allocated. */
static bp_status bp__shape_make(const bp_allocator *a, const bp_chart *ch, const double *L, int res, bp__shape *S)
{
    double mx[2] = { 0, 0 };
    uint32_t i, t;
    int r;
    memset(S, 0, sizeof *S);
    for (i = 0; i < ch->num_vertices; i++) {
        if (L[2 * i] > mx[0]) mx[0] = L[2 * i];
        if (L[2 * i + 1] > mx[1]) mx[1] = L[2 * i + 1];
    }
    if (!(mx[0] + BP__PACK_MARGIN < res && mx[1] + BP__PACK_MARGIN < res)) return BP_ERR_NUMERICAL;
    S->r.w = (int)floor(mx[0] + BP__PACK_MARGIN) + 1;
    S->r.h = (int)floor(mx[1] + BP__PACK_MARGIN) + 1;
    S->r.words = (S->r.w + 63) >> 6;
    S->r.b = (uint64_t *)bp__calloc_array(a, (size_t)S->r.h * S->r.words, sizeof(uint64_t));
    S->rowrun = (int *)bp__alloc_array(a, (size_t)S->r.h, sizeof(int));
    S->span = (int *)bp__alloc_array(a, 2 * (size_t)S->r.h, sizeof(int));
    if (!S->r.b || !S->rowrun || !S->span) { bp__shape_free(a, S); return BP_ERR_OUT_OF_MEMORY; }
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        bp__raster_triangle(&S->r, L + 2 * (size_t)tr[0], L + 2 * (size_t)tr[1], L + 2 * (size_t)tr[2],
                            BP__PACK_MARGIN);
    }
    S->rstar = 0;
    for (r = 0; r < S->r.h; r++) {
        const uint64_t *row = S->r.b + (size_t)r * S->r.words;
        int lo = 0, hi = S->r.words - 1;
        S->rowrun[r] = bp__bits_longest(row, S->r.w, 1);
        if (S->rowrun[r] > S->rowrun[S->rstar]) S->rstar = r;
        while (lo < hi && !row[lo]) lo++;
        while (hi > lo && !row[hi]) hi--;
        S->span[2 * r] = lo; S->span[2 * r + 1] = hi;
    }
    return BP_OK;
}

/* The raster dilated by p texels (Chebyshev): (w+2p) x (h+2p), texel (x,y)
   of the raster is texel (x+p, y+p) of the result. */
static bp_status bp__dilate(const bp_allocator *a, const bp__bits *R, int p, bp__bits *D)
{
    uint64_t *row, *tmp;
    int r, i, j, have;
    D->w = R->w + 2 * p; D->h = R->h + 2 * p; D->words = (D->w + 63) >> 6;
    D->b = (uint64_t *)bp__calloc_array(a, (size_t)D->h * D->words, sizeof(uint64_t));
    row = (uint64_t *)bp__alloc_array(a, 2 * (size_t)D->words, sizeof(uint64_t));
    if (!D->b || !row) { bp__free(a, D->b); bp__free(a, row); D->b = NULL; return BP_ERR_OUT_OF_MEMORY; }
    tmp = row + D->words;
    for (r = 0; r < R->h; r++) {
        /* horizontal: bit x spreads to x..x+2p (OR of 2p+1 shifts, doubling) */
        for (i = 0; i < D->words; i++) row[i] = i < R->words ? R->b[(size_t)r * R->words + i] : 0;
        for (have = 1; have < 2 * p + 1;) {
            int step = have < 2 * p + 1 - have ? have : 2 * p + 1 - have;
            bp__bits_shl(row, D->words, step, tmp);
            for (i = 0; i < D->words; i++) row[i] |= tmp[i];
            have += step;
        }
        /* vertical: row r spreads to rows r..r+2p */
        for (j = r; j <= r + 2 * p; j++)
            for (i = 0; i < D->words; i++) D->b[(size_t)j * D->words + i] |= row[i];
    }
    bp__free(a, row);
    return BP_OK;
}

/* ---- the atlas ---- */

static void bp__occ_free(const bp_allocator *a, bp__occ *O)
{
    bp__free(a, O->b); bp__free(a, O->maxfree); bp__free(a, O->ylow); bp__free(a, O->t0);
    memset(O, 0, sizeof *O);
}

static bp_status bp__occ_init(const bp_allocator *a, bp__occ *O, int res)
{
    memset(O, 0, sizeof *O);
    O->res = res;
    O->aw = (res >> 6) + 2;
    O->b = (uint64_t *)bp__alloc_array(a, (size_t)res * O->aw, sizeof(uint64_t));
    O->maxfree = (int *)bp__alloc_array(a, (size_t)res, sizeof(int));
    O->ylow = (int *)bp__alloc_array(a, (size_t)res + 1, sizeof(int));
    O->t0 = (uint64_t *)bp__alloc_array(a, 3 * (size_t)O->aw, sizeof(uint64_t));
    if (!O->b || !O->maxfree || !O->ylow || !O->t0) { bp__occ_free(a, O); return BP_ERR_OUT_OF_MEMORY; }
    O->t1 = O->t0 + O->aw;
    O->v = O->t1 + O->aw;
    return BP_OK;
}

/* Empty atlas: texels [B, res - B) free, where B = O->border; the frame
   of B texels along each edge (the border padding, step 3 of the essay)
   and the spare bits beyond res taken. */
static void bp__occ_clear(bp__occ *O)
{
    int y, i, B = O->border;
    for (y = 0; y < O->res; y++) {
        uint64_t *row = O->b + (size_t)y * O->aw;
        for (i = 0; i < O->aw; i++) row[i] = 0;
        if (y < B || y >= O->res - B) bp__bits_set_range(row, 0, O->aw * 64 - 1);
        else {
            if (B > 0) bp__bits_set_range(row, 0, B - 1);
            bp__bits_set_range(row, O->res - B, O->aw * 64 - 1);
        }
        O->maxfree[y] = bp__bits_longest(row, O->res, 0);
    }
    for (i = 0; i <= O->res; i++) O->ylow[i] = 0;
    memset(O->floor_, 0, sizeof O->floor_);
}

/* Remember that a chart of w x h texels found nothing below row y; every
   chart at least as wide and as tall starts its search there.  (A larger
   box need not hold a larger shape, so this may skip a place that a
   differently shaped chart could use: it trades a little utilization for
   speed on many small charts.  Large charts are not memoized.) */
static void bp__occ_memo(bp__occ *O, int w, int h, int y)
{
    int i, j;
    if (w > BP__PACK_MEMO || h > BP__PACK_MEMO || O->floor_[w - 1][h - 1] >= y) return;
    for (i = w - 1; i < BP__PACK_MEMO; i++)
        for (j = h - 1; j < BP__PACK_MEMO; j++)
            if (O->floor_[i][j] < y) O->floor_[i][j] = y;
}

/* The lowest row whose longest free run may still be >= v (maxfree only
   shrinks, so the pointer only moves up). */
static int bp__occ_ylow(bp__occ *O, int v)
{
    if (v <= 0) return 0;
    if (v > O->res) return O->res;
    while (O->ylow[v] < O->res && O->maxfree[O->ylow[v]] < v) O->ylow[v]++;
    return O->ylow[v];
}

/* Does raster R fit with its origin at texel (x, y)? */
static int bp__occ_fits(const bp__occ *O, const bp__shape *S, int x, int y)
{
    const bp__bits *R = &S->r;
    int r, i;
    for (r = 0; r < R->h; r++) {
        const uint64_t *orow = O->b + (size_t)(y + r) * O->aw, *rrow = R->b + (size_t)r * R->words;
        for (i = S->span[2 * r]; i <= S->span[2 * r + 1]; i++) {
            uint64_t v = rrow[i];
            int pos = x + 64 * i, q = pos >> 6, s = pos & 63;
            if (!v) continue;
            if (orow[q] & (v << s)) return 0;
            if (s && (orow[q + 1] & (v >> (64 - s)))) return 0;
        }
    }
    return 1;
}

/* V &= the origins x at which the runs of chart row `crow` avoid atlas row
   `orow`: a run [s, s+len) needs texels x+s .. x+s+len-1 free, i.e. x+s
   must start a free run of length len (computed for 64 x at a time by
   doubling: F_{a+b} = F_a & (F_b >> a)). */
static void bp__occ_filter_row(bp__occ *O, const uint64_t *orow, const uint64_t *crow, int w)
{
    int st[BP__PACK_PREFILTER_RUNS], ln[BP__PACK_PREFILTER_RUNS], n, k, i, have;
    n = bp__bits_runs(crow, w, st, ln, BP__PACK_PREFILTER_RUNS);
    for (k = 0; k < n; k++) {
        for (i = 0; i < O->aw; i++) O->t0[i] = ~orow[i];
        for (have = 1; have < ln[k];) {
            int step = have < ln[k] - have ? have : ln[k] - have;
            bp__bits_shr(O->t0, O->aw, step, O->t1);
            for (i = 0; i < O->aw; i++) O->t0[i] &= O->t1[i];
            have += step;
        }
        bp__bits_shr(O->t0, O->aw, st[k], O->t1);
        for (i = 0; i < O->aw; i++) O->v[i] &= O->t1[i];
    }
}

/* O->v = the origins x in [0, res - w] at which the longest run [s, s+len)
   of the chart's row r* lies in a free run [f0, f1) of atlas row y + r*:
   f0 - s <= x <= f1 - len - s.  Returns 0 when there is none. */
static int bp__occ_candidates(bp__occ *O, const bp__shape *S, int y)
{
    const uint64_t *orow = O->b + (size_t)(y + S->rstar) * O->aw, *crow = S->r.b + (size_t)S->rstar * S->r.words;
    int st, ln, x = 0, any = 0, i;
    for (i = 0; i < O->aw; i++) O->v[i] = 0;
    {   /* the longest run of the row, not the first */
        int xs = 0, n, k, sts[BP__PACK_PREFILTER_RUNS], lns[BP__PACK_PREFILTER_RUNS];
        n = bp__bits_runs(crow, S->r.w, sts, lns, BP__PACK_PREFILTER_RUNS);
        for (k = 0; k < n; k++) if (lns[k] > lns[xs]) xs = k;
        st = sts[xs]; ln = lns[xs];
    }
    while (x < O->res) {                /* free runs of the atlas row */
        int f0, f1, lo, hi;
        while (x < O->res && (orow[x >> 6] >> (x & 63) & 1)) {
            uint64_t rest = ~(orow[x >> 6] >> (x & 63));
            x += rest ? bp__ctz64(rest) : 64 - (x & 63);
        }
        if (x >= O->res) break;
        f0 = x;
        while (x < O->res && !(orow[x >> 6] >> (x & 63) & 1)) {
            uint64_t rest = orow[x >> 6] >> (x & 63);
            x += rest ? bp__ctz64(rest) : 64 - (x & 63);
        }
        f1 = x < O->res ? x : O->res;
        lo = f0 - st; hi = f1 - ln - st;
        if (lo < 0) lo = 0;
        if (hi > O->res - S->r.w) hi = O->res - S->r.w;
        if (lo <= hi) { bp__bits_set_range(O->v, lo, hi); any = 1; }
    }
    return any;
}

/* The lowest, then leftmost, origin where shape S fits, no later than
   (ylim, xlim) in that order.  Returns 0 when there is none. */
static int bp__occ_find(bp__occ *O, const bp__shape *S, int ylim, int xlim, int *ox, int *oy)
{
    const bp__bits *R = &S->r;
    int y, y0, r, i, k, rows[7], nrows = 0;
    if (R->w > O->res || R->h > O->res) return 0;
    y0 = bp__occ_ylow(O, S->rowrun[0]);
    r = bp__occ_ylow(O, S->rowrun[S->rstar]) - S->rstar;
    if (r > y0) y0 = r;
    if (R->w <= BP__PACK_MEMO && R->h <= BP__PACK_MEMO && O->floor_[R->w - 1][R->h - 1] > y0)
        y0 = O->floor_[R->w - 1][R->h - 1];
    /* the filter rows: r* first, then the ends, and for a tall chart the
       quarters and an eighth (bit-parallel filtering beats testing many
       candidates one by one; at 4096 px it makes spot's packing 6x faster) */
    for (k = 0; k < (R->h >= 16 ? 7 : 3); k++) {
        int cand = k == 0 ? S->rstar : k == 1 ? 0 : k == 2 ? R->h - 1 : k == 3 ? R->h / 2 :
                   k == 4 ? R->h / 4 : k == 5 ? 3 * R->h / 4 : R->h / 8, dup = 0;
        for (i = 0; i < nrows; i++) dup |= rows[i] == cand;
        if (!dup) rows[nrows++] = cand;
    }
    for (y = y0; y <= O->res - R->h && y <= ylim; y++) {
        if (O->maxfree[y + S->rstar] < S->rowrun[S->rstar]) continue;
        for (r = 0; r < R->h; r++)
            if (O->maxfree[y + r] < S->rowrun[r]) break;
        if (r < R->h) continue;
        /* candidate origins: where the longest run of row r* meets a free
           run of the atlas, then filtered by the chart's first and last rows
           and its quarters */
        if (!bp__occ_candidates(O, S, y)) continue;
        for (i = 1; i < nrows; i++) {
            int any = 0, q;
            bp__occ_filter_row(O, O->b + (size_t)(y + rows[i]) * O->aw, R->b + (size_t)rows[i] * R->words, R->w);
            for (q = 0; q < O->aw; q++) any |= O->v[q] != 0;
            if (!any) break;
        }
        for (i = 0; i < O->aw; i++) {
            uint64_t v = O->v[i];
            while (v) {
                int b = bp__ctz64(v), x;
                v &= v - 1;
                x = 64 * i + b;
                if (y == ylim && x >= xlim) { bp__occ_memo(O, R->w, R->h, y); return 0; }
                if (bp__occ_fits(O, S, x, y)) { *ox = x; *oy = y; bp__occ_memo(O, R->w, R->h, y); return 1; }
            }
        }
    }
    bp__occ_memo(O, R->w, R->h, y > ylim ? ylim : y);
    return 0;
}

/* Mark the dilated raster D with the chart's origin at (x, y): D's texel
   (0,0) goes to (x-p, y-p). */
static void bp__occ_mark(bp__occ *O, const bp__bits *D, int p, int x, int y)
{
    int j;
    for (j = 0; j < D->h; j++) {
        int row = y - p + j;
        if (row < 0 || row >= O->res) continue;
        bp__bits_or_at(O->b + (size_t)row * O->aw, O->aw, D->b + (size_t)j * D->words, D->words, x - p);
        O->maxfree[row] = bp__bits_longest(O->b + (size_t)row * O->aw, O->res, 0);
    }
}

/* ---- charts ---- */

typedef struct bp__pt { double p[2]; } bp__pt;

static int bp__pt_cmp(const void *pa, const void *pb)
{
    const bp__pt *a = (const bp__pt *)pa, *b = (const bp__pt *)pb;
    if (a->p[0] != b->p[0]) return a->p[0] < b->p[0] ? -1 : 1;
    return (a->p[1] > b->p[1]) - (a->p[1] < b->p[1]);
}

/* Rotation (cs, sn) that puts the minimum-area bounding box of the chart's
   map on the axes: x' = cs x + sn y, y' = cs y - sn x.  Andrew's monotone
   chain with exact orientation gives the convex hull; each hull edge is a
   candidate side of the box (Freeman and Shapira).  The identity wins ties. */
static bp_status bp__min_box_rotation(const bp_allocator *a, const double *uv, uint32_t nv, double *cs, double *sn,
                                      double *cs2, double *sn2, double *aspect)
{
    bp__pt *p = (bp__pt *)bp__alloc_array(a, nv, sizeof *p), *h;
    uint32_t i, n = 0, lower;
    double best = HUGE_VAL;
    int pass;
    *cs = 1; *sn = 0; *cs2 = 1; *sn2 = 0; *aspect = 1;
    if (!p) return BP_ERR_OUT_OF_MEMORY;
    h = (bp__pt *)bp__alloc_array(a, 2 * (size_t)nv + 1, sizeof *h);
    if (!h) { bp__free(a, p); return BP_ERR_OUT_OF_MEMORY; }
    for (i = 0; i < nv; i++) { p[i].p[0] = uv[2 * i]; p[i].p[1] = uv[2 * i + 1]; }
    qsort(p, nv, sizeof *p, bp__pt_cmp);
    for (i = 0; i < nv; i++) {                       /* lower hull */
        while (n >= 2 && bp_orient2d(h[n - 2].p, h[n - 1].p, p[i].p) <= 0) n--;
        h[n++] = p[i];
    }
    lower = n + 1;
    for (i = nv - 1; i-- > 0;) {                     /* upper hull */
        while (n >= lower && bp_orient2d(h[n - 2].p, h[n - 1].p, p[i].p) <= 0) n--;
        h[n++] = p[i];
    }
    if (n > 0) n--;                                  /* the first point again */
    for (pass = 0; pass < 2 && n >= 3; pass++) {
        uint32_t e, m = pass ? n : 1;
        for (e = 0; e < m; e++) {
            double dx = pass ? h[(e + 1) % n].p[0] - h[e].p[0] : 1, dy = pass ? h[(e + 1) % n].p[1] - h[e].p[1] : 0;
            double len = sqrt(dx * dx + dy * dy), c, s, lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL }, area;
            if (!(len > 0)) continue;
            c = dx / len; s = dy / len;
            for (i = 0; i < n; i++) {
                double x = c * h[i].p[0] + s * h[i].p[1], y = c * h[i].p[1] - s * h[i].p[0];
                if (x < lo[0]) lo[0] = x;
                if (x > hi[0]) hi[0] = x;
                if (y < lo[1]) lo[1] = y;
                if (y > hi[1]) hi[1] = y;
            }
            area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
            if (area < best * (1 - 1e-9)) {
                best = area; *cs = c; *sn = s;
                *aspect = (hi[0] - lo[0]) > (hi[1] - lo[1]) ? (hi[0] - lo[0]) / (hi[1] - lo[1]) : (hi[1] - lo[1]) / (hi[0] - lo[0]);
            }
        }
    }
    /* The smallest bounding square (the longer side of the box, minimized)
       need not have a side on a hull edge: sample every half degree of a
       quarter turn.  It matters for a long chart that must fit the square
       atlas on its own. */
    *cs2 = *cs; *sn2 = *sn;
    for (pass = 0, best = HUGE_VAL; n >= 3 && pass < 180; pass++) {
        double ang = pass * (3.14159265358979323846 / 360), c = cos(ang), s = sin(ang), side;
        double lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL };
        for (i = 0; i < n; i++) {
            double x = c * h[i].p[0] + s * h[i].p[1], y = c * h[i].p[1] - s * h[i].p[0];
            if (x < lo[0]) lo[0] = x;
            if (x > hi[0]) hi[0] = x;
            if (y < lo[1]) lo[1] = y;
            if (y > hi[1]) hi[1] = y;
        }
        side = hi[0] - lo[0] > hi[1] - lo[1] ? hi[0] - lo[0] : hi[1] - lo[1];
        if (side < best * (1 - 1e-9)) { best = side; *cs2 = c; *sn2 = s; }
    }
    bp__free(a, p);
    bp__free(a, h);
    return BP_OK;
}

/* Local coordinates of chart pc at density d after `turn` quarter turns,
   shifted so that the smallest is BP__PACK_SHIFT. */
static void bp__pack_local(const bp_chart *ch, const bp__pchart *pc, int turn, double d, double *L)
{
    double s = pc->k * d, mn[2] = { HUGE_VAL, HUGE_VAL }, cs = turn < 4 ? pc->cs : pc->cs2, sn = turn < 4 ? pc->sn : pc->sn2;
    uint32_t i;
    for (i = 0; i < ch->num_vertices; i++) {
        double x = pc->orig[2 * i], y = pc->orig[2 * i + 1];
        double rx = (cs * x + sn * y) * s, ry = (cs * y - sn * x) * s, u, v;
        switch (turn & 3) {
        case 1:  u = -ry; v = rx; break;
        case 2:  u = -rx; v = -ry; break;
        case 3:  u = ry; v = -rx; break;
        default: u = rx; v = ry; break;
        }
        L[2 * i] = u; L[2 * i + 1] = v;
        if (u < mn[0]) mn[0] = u;
        if (v < mn[1]) mn[1] = v;
    }
    for (i = 0; i < ch->num_vertices; i++) {
        L[2 * i] = L[2 * i] - mn[0] + BP__PACK_SHIFT;
        L[2 * i + 1] = L[2 * i + 1] - mn[1] + BP__PACK_SHIFT;
    }
}

static int bp__pchart_cmp(const void *pa, const void *pb)
{
    const bp__pchart *a = (const bp__pchart *)pa, *b = (const bp__pchart *)pb;
    if (a->target != b->target) return a->target > b->target ? -1 : 1;
    return (a->chart > b->chart) - (a->chart < b->chart);
}

typedef struct bp__packer {
    bp_allocator a;
    bp_atlas *atlas;
    bp__pchart *pc;
    uint32_t n;                 /* charts with a map */
    int res, pad;
    bp__occ occ;
    double *L;                  /* scratch: local coordinates of one chart */
    const bp__par *par;         /* runs the exact checks                   */
} bp__packer;

/* One attempt at density d: 1 if every chart found a place (pc[].x, y,
   turn hold them), 0 if not (*placed: the share of the total area placed
   before the first chart that found none), -1 out of memory. */
static int bp__pack_attempt(bp__packer *P, double d, double *placed)
{
    uint32_t i;
    *placed = 0;
    bp__occ_clear(&P->occ);
    for (i = 0; i < P->n; i++) {
        bp__pchart *pc = &P->pc[i];
        const bp_chart *ch = &P->atlas->charts[pc->chart];
        bp__shape best, S;
        bp__bits D;
        int turn, bx = 0, by = P->res, bturn = -1, x, y;
        memset(&best, 0, sizeof best);
        for (turn = 0; turn < pc->turns; turn++) {
            bp_status st;
            bp__pack_local(ch, pc, turn, d, P->L);
            st = bp__shape_make(&P->a, ch, P->L, P->res, &S);
            if (st == BP_ERR_OUT_OF_MEMORY) { bp__shape_free(&P->a, &best); return -1; }
            if (st != BP_OK) continue;
            if (bp__occ_find(&P->occ, &S, by, bturn < 0 ? P->res : bx, &x, &y)) {
                bp__shape_free(&P->a, &best);
                best = S; bx = x; by = y; bturn = turn;
            } else {
                bp__shape_free(&P->a, &S);
            }
        }
        if (bturn < 0) return 0;
        *placed += pc->target;
        if (bp__dilate(&P->a, &best.r, P->pad, &D) != BP_OK) { bp__shape_free(&P->a, &best); return -1; }
        bp__occ_mark(&P->occ, &D, P->pad, bx, by);
        bp__free(&P->a, D.b);
        bp__shape_free(&P->a, &best);
        pc->x = bx; pc->y = by; pc->turn = bturn;
    }
    return 1;
}

/* Keep the placements of an attempt that fit. */
static void bp__pack_keep(bp__packer *P)
{
    uint32_t i;
    for (i = 0; i < P->n; i++) { P->pc[i].fx = P->pc[i].x; P->pc[i].fy = P->pc[i].y; P->pc[i].fturn = P->pc[i].turn; }
}

/* The largest density that fits.  Start at the density that would fill the
   square exactly (utilization 1); while it does not fit, shrink by the
   square root of the share of the area that was placed (the charts scale
   as d^2), at least 3% and at most 50% a step; then bisect (geometric
   mean) between the last failure and the first fit to 0.2%.  *d = 0 when
   nothing fits. */
static bp_status bp__pack_search(bp__packer *P, double *d_out)
{
    double total = 0, hi = 0, lo, d, placed;
    uint32_t i;
    int it, r;
    *d_out = 0;
    for (i = 0; i < P->n; i++) total += P->pc[i].target;
    d = (P->res - 2 * P->occ.border) / sqrt(total);     /* the free square */
    for (it = 0; it < 200; it++) {
        double f;
        r = bp__pack_attempt(P, d, &placed);
        if (r < 0) return BP_ERR_OUT_OF_MEMORY;
        if (r) break;
        hi = d;
        f = sqrt(placed / total);
        d *= f < 0.5 ? 0.5 : f > 0.97 ? 0.97 : f;
    }
    if (it == 200) return BP_OK;
    bp__pack_keep(P);
    lo = d;
    for (it = 0; hi > 0 && hi > lo * 1.002 && it < 16; it++) {
        double mid = sqrt(lo * hi);
        r = bp__pack_attempt(P, mid, &placed);
        if (r < 0) return BP_ERR_OUT_OF_MEMORY;
        if (r) { lo = mid; bp__pack_keep(P); } else hi = mid;
    }
    *d_out = lo;
    return BP_OK;
}

/* Write the final coordinates uv = (L + (x, y)) / RES and check each chart
   exactly.  Returns the index into P->pc of a chart that broke, or n. */
static bp_status bp__pack_apply(bp__packer *P, double d, uint32_t *broken)
{
    uint32_t i, v;
    *broken = P->n;
    for (i = 0; i < P->n; i++) {
        bp__pchart *pc = &P->pc[i];
        bp_chart *ch = &P->atlas->charts[pc->chart];
        bp_check_report rep;
        bp_status st;
        bp__pack_local(ch, pc, pc->fturn, d, P->L);
        for (v = 0; v < ch->num_vertices; v++) {
            ch->uv[2 * v] = (P->L[2 * v] + pc->fx) / P->res;
            ch->uv[2 * v + 1] = (P->L[2 * v + 1] + pc->fy) / P->res;
        }
        st = bp__pack_check(&P->a, P->par, ch, ch->uv, &rep);
        if (st != BP_OK) return st;
        if (!bp__report_no_worse(&rep, &pc->before)) { *broken = i; return BP_OK; }
    }
    return BP_OK;
}

/* Density factor, orientation and the map's own validity of each chart. */
static bp_status bp__pack_prepare(bp__packer *P, const bp_options *opt, bp_error *err)
{
    uint32_t c, t, n = 0, maxv = 1;
    double aspect = 1, total;
    for (c = 0; c < P->atlas->num_charts; c++) {
        bp_chart *ch = &P->atlas->charts[c];
        bp__pchart *pc;
        double auv = 0, *copy;
        bp_status st;
        if (!ch->uv) continue;
        pc = &P->pc[n++];
        memset(pc, 0, sizeof *pc);
        pc->chart = c;
        copy = (double *)bp__alloc_array(&P->a, 2 * (size_t)ch->num_vertices, sizeof(double));
        if (!copy) return bp__oom(err, "packing charts");
        memcpy(copy, ch->uv, 2 * (size_t)ch->num_vertices * sizeof(double));
        pc->orig = copy;
        if (ch->num_vertices > maxv) maxv = ch->num_vertices;
        st = bp__pack_check(&P->a, P->par, ch, pc->orig, &pc->before);
        if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "packing charts");
        if (st != BP_OK || pc->before.nonfinite)
            return bp__fail(err, st != BP_OK ? st : BP_ERR_NONFINITE, BP_ELEMENT_CHART, c, -1, 0,
                            "chart %u: its map cannot be packed (invalid or non-finite coordinates)", c);
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t;
            const double *uv = pc->orig;
            auv += fabs(bp__uv_tri_area(uv + 2 * (size_t)tr[0], uv + 2 * (size_t)tr[1], uv + 2 * (size_t)tr[2]));
        }
        if (!(auv > 0) || !(auv < HUGE_VAL))
            return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, c, -1, 0,
                            "chart %u: its map has no area to pack", c);
        /* one texel density: UV area / 3D area equal across charts (step 1) */
        if (opt->importance || !(ch->area3d > 0)) { pc->k = 1; pc->target = auv; }
        else { pc->k = sqrt(ch->area3d / auv); pc->target = ch->area3d; }
        pc->turns = opt->no_rotation ? 1 : 4;
        pc->cs = pc->cs2 = 1; pc->sn = pc->sn2 = 0;
        if (!opt->no_rotation &&
            bp__min_box_rotation(&P->a, pc->orig, ch->num_vertices, &pc->cs, &pc->sn, &pc->cs2, &pc->sn2, &aspect) != BP_OK)
            return bp__oom(err, "packing charts");
        if (!opt->no_rotation && aspect > 1.5) pc->turns = 8;
    }
    P->n = n;
    /* The square orientations cost a second search per chart; they only
       matter for long charts large enough to set the atlas's scale. */
    for (c = 0, total = 0; c < n; c++) total += P->pc[c].target;
    for (c = 0; c < n; c++)
        if (P->pc[c].turns == 8 && P->pc[c].target < total / 64) P->pc[c].turns = 4;
    P->L = (double *)bp__alloc_array(&P->a, 2 * (size_t)maxv, sizeof(double));
    if (!P->L) return bp__oom(err, "packing charts");
    qsort(P->pc, n, sizeof *P->pc, bp__pchart_cmp);
    return BP_OK;
}

/* Step 4's loop: search, apply, and on a chart whose rotated copy broke,
   retry with that chart in its own orientation. */
static bp_status bp__pack_outlines(bp_atlas *atlas, const bp_options *opt, const bp__par *par, bp_error *err)
{
    bp__packer P;
    bp_status st;
    uint32_t i, broken;
    double d = 0, area = 0;
    memset(&P, 0, sizeof P);
    P.a = atlas->allocator;
    P.atlas = atlas;
    P.par = par;
    P.res = opt->atlas_resolution;
    P.pad = opt->padding;
    P.pc = (bp__pchart *)bp__calloc_array(&P.a, atlas->num_charts ? atlas->num_charts : 1, sizeof *P.pc);
    if (!P.pc) return bp__oom(err, "packing charts");
    st = bp__pack_prepare(&P, opt, err);
    if (st == BP_OK && bp__occ_init(&P.a, &P.occ, P.res) != BP_OK) st = bp__oom(err, "packing charts");
    P.occ.border = (P.pad + 1) / 2;                  /* ceil(P/2), the border padding */
    for (;;) {
        if (st != BP_OK || P.n == 0) break;
        st = bp__pack_search(&P, &d);
        if (st != BP_OK) { st = bp__oom(err, "packing charts"); break; }
        if (d == 0) {
            st = bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                          "the %u charts do not fit in a %d x %d atlas with %d texels of padding",
                          P.n, P.res, P.res, P.pad);
            break;
        }
        st = bp__pack_apply(&P, d, &broken);
        if (st != BP_OK) { st = st == BP_ERR_OUT_OF_MEMORY ? bp__oom(err, "packing charts") : st; break; }
        if (broken == P.n) break;
        if (P.pc[broken].turns == 1 && P.pc[broken].cs == 1 && P.pc[broken].sn == 0 && P.pc[broken].fturn == 0) {
            st = bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, P.pc[broken].chart, -1, 0,
                          "chart %u: placing it in the atlas would break its validity in floating point",
                          P.pc[broken].chart);
            break;
        }
        P.pc[broken].turns = 1; P.pc[broken].cs = 1; P.pc[broken].sn = 0;   /* unrotated */
    }
    if (st != BP_OK) {           /* leave the charts as they were */
        for (i = 0; i < P.n; i++)
            if (P.pc[i].orig) {
                bp_chart *ch = &atlas->charts[P.pc[i].chart];
                memcpy(ch->uv, P.pc[i].orig, 2 * (size_t)ch->num_vertices * sizeof(double));
            }
    } else {
        for (i = 0; i < P.n; i++) area += bp__chart_uv_area(&atlas->charts[P.pc[i].chart]);
        atlas->utilization = area;       /* the atlas is the unit square */
        bp__ok(err);
    }
    for (i = 0; i < atlas->num_charts; i++) bp__free(&P.a, P.pc[i].orig);
    bp__free(&P.a, P.pc);
    bp__free(&P.a, P.L);
    bp__occ_free(&P.a, &P.occ);
    return st;
}

/* >>pins ===================================================================

   Pinned vertices (beyond the dissertation; Blender's, Maya's and SLIM's
   pins).  What is guaranteed, precisely:
     - every pinned chart vertex ends at its target bit for bit (the
       final chart->uv holds the very doubles of bp_pin.u, v), and packing
       does not move a chart that has pins (bp_atlas_pack leaves it where
       it is and places the other charts beside it; pins together with
       normalize or atlas_resolution are refused, since scaling would move
       them);
     - the map is exactly bijective at every iterate, as without pins, and
       the optimization minimizes the same energy over the free vertices;
     - pins that fail the necessary conditions of >>tutte are rejected
       with the elements named, and pins that the homotopy below cannot
       reach fail that chart with a message: never a wrong map.
   Not guaranteed: that pins which admit a bijective map are always
   reached.  The homotopy is a heuristic that succeeds when the targets are
   a moderate deformation of the start (the common case: a few pins placed
   by an artist near where the unpinned map has them); a target that needs
   the map to turn inside out fails.

   The homotopy (from the fitted start of >>tutte), in rounds k = 0, 1, ...:
     1. snap: put every pin at its target; if that map passes the exact
        check, done (the snapped coordinates are the targets themselves);
     2. move: d = target - x on the pins, 0 elsewhere; the step bound of
        >>stepbound along d (the same singularity-aware bound as the
        optimizer's: no triangle flips, no boundary crossing), a step
        t = min(1, 0.9 tmax) halved until the moved map passes the exact
        check;
     3. pull: BP__PIN_RELAX iterations of the optimizer on
            E + w_k sum_p |x_p - t_p|^2,   w_k = 10^k nt / (n_pins L^2)
        (L the mean 3D boundary edge; at k = 0 a pin one edge away costs
        about the whole energy), all vertices free -- the same interior
        point method, so every iterate is exactly bijective, and the
        whole chart deforms toward the pins instead of the pins pushing
        through their neighbours;
   until the pins are at their targets, or the largest remaining distance
   has not dropped by 1% in BP__PIN_STALL rounds, or BP__PIN_ROUNDS rounds
   have passed (then the chart fails).  Every map on the way passed the
   exact check. */

#define BP__PIN_ROUNDS 40
#define BP__PIN_STALL 6
#define BP__PIN_RELAX 100

/* Before the fit, a Tutte start is first optimized without its pins
   (at most BP__PIN_FREE iterations): the fitted similarity then starts
   from a shape like the unpinned result, which pins taken from an earlier
   unwrap match closely, instead of from a disk. */
#define BP__PIN_FREE 300

static bp_status bp__pins_relax_free(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                     bp_error *err)
{
    bp_options o = *opt;
    o.progress = NULL;
    o.max_seconds = 0;
    o.pins = NULL;
    o.num_pins = 0;
    if (o.max_iterations <= 0 || o.max_iterations > BP__PIN_FREE) o.max_iterations = BP__PIN_FREE;
    return bp__chart_optimize(ch, 0, m, &o, runner, err);
}

/* Step 2: move the pins along d by the largest checked step; 1 if moved. */
static int bp__pins_move(bp__solver *S, double *x, double *xn, const double *d, uint32_t nv2)
{
    double tmax = bp__step_bound(S, x, d, 1 / 0.9), tt = tmax < 1 / 0.9 ? 0.9 * tmax : 1, ed;
    uint32_t i;
    int tries, valid;
    for (tries = 0; tries < 50 && tt > 0; tries++, tt *= 0.5) {
        for (i = 0; i < nv2; i++) xn[i] = d[i] != 0 ? x[i] + tt * d[i] : x[i];
        bp__evaluate(S, xn, NULL, &ed, HUGE_VAL, &valid);
        if (S->oom) return -1;
        if (valid) { memcpy(x, xn, nv2 * sizeof(double)); return 1; }
    }
    return 0;
}

/* Step 1's snapped map into xn and d = target - x; returns the largest
   remaining coordinate distance, *worst its chart vertex. */
static double bp__pins_snap(const bp_chart *ch, const bp_pin *pins, const uint32_t *pidx, double *xn, double *d,
                            uint32_t *worst)
{
    uint32_t i;
    double dist = 0;
    for (i = 0; i < ch->num_vertices; i++) {
        double du = 0, dv = 0;
        xn[2 * (size_t)i] = ch->uv[2 * (size_t)i];
        xn[2 * (size_t)i + 1] = ch->uv[2 * (size_t)i + 1];
        if (pidx[i] != BP__NONE) {
            du = pins[pidx[i]].u - xn[2 * (size_t)i];
            dv = pins[pidx[i]].v - xn[2 * (size_t)i + 1];
            xn[2 * (size_t)i] = pins[pidx[i]].u;
            xn[2 * (size_t)i + 1] = pins[pidx[i]].v;
            if (fabs(du) > dist || fabs(dv) > dist) { dist = fabs(du) > fabs(dv) ? fabs(du) : fabs(dv); *worst = i; }
        }
        d[2 * (size_t)i] = du;
        d[2 * (size_t)i + 1] = dv;
    }
    return dist;
}

static bp_status bp__pins_reach(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                const uint32_t *pidx, bp_error *err)
{
    bp_allocator a = bp__allocator_of(opt);
    bp__solver S;
    bp__penalty pen;
    bp_options o = *opt;
    uint32_t nv2 = 2 * ch->num_vertices, worst = 0;
    double *xn, *d, best = HUGE_VAL, dist = 0;
    int round, stall = 0, valid;
    bp_status st;
    o.progress = NULL;
    o.max_seconds = 0;
    o.max_iterations = BP__PIN_RELAX;
    o.pins = NULL;                                  /* the pull: no vertex held */
    o.num_pins = 0;
    memset(&S, 0, sizeof S);
    if ((st = bp__solver_chart(&S, &a, ch, m, &o, NULL, err)) != BP_OK) return st;
    S.par = *runner;
    pen.pins = opt->pins;
    pen.pidx = pidx;
    pen.w = S.nt / (ch->num_pins * S.mean_edge * S.mean_edge);
    xn = (double *)bp__alloc_array(&a, nv2, sizeof(double));
    d = (double *)bp__alloc_array(&a, nv2, sizeof(double));
    for (round = 0; xn && d; round++, pen.w *= 10) {
        double ed;
        if ((dist = bp__pins_snap(ch, opt->pins, pidx, xn, d, &worst)) == 0) break;
        bp__evaluate(&S, xn, NULL, &ed, HUGE_VAL, &valid);                     /* 1. snap */
        if (S.oom) break;
        if (valid) { memcpy(ch->uv, xn, nv2 * sizeof(double)); dist = 0; break; }
        if (dist < 0.99 * best) { best = dist; stall = 0; } else stall++;
        if (round >= BP__PIN_ROUNDS || stall >= BP__PIN_STALL) break;
        if (bp__pins_move(&S, ch->uv, xn, d, nv2) < 0) break;                  /* 2. move */
        st = bp__chart_optimize_pen(ch, 0, m, &o, runner, &pen, NULL, err);    /* 3. pull */
        if (st != BP_OK) break;
    }
    bp__solver_free(&S);
    bp__free(&a, xn);
    bp__free(&a, d);
    if (st != BP_OK) return st;
    if (!xn || !d || S.oom) return bp__oom(err, "moving the pins");
    if (dist > 0) {
        char name[48];
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, ch->vertex[worst], -1, 0,
                        "the pins of the chart with %s cannot be reached from its start map: vertex %u is still "
                        "%g from its target after %d rounds (no bijective map through the targets was found)",
                        bp__tri_name(m, ch->face[0], name), ch->vertex[worst] + 1, dist, round);
    }
    return BP_OK;
}

/* bp_chart_optimize holds the pinned vertices where the start map has
   them; the caller's start must have them at their targets. */
static bp_status bp__pins_at_targets(bp_chart *ch, uint32_t chart_index, const bp_mesh *m, const bp_options *opt,
                                     bp_error *err)
{
    bp_allocator a = bp__allocator_of(opt);
    uint32_t *pidx, i;
    bp_status st = bp__pin_map(&a, ch, m, opt, &pidx, &ch->num_pins, err);
    for (i = 0; st == BP_OK && pidx && i < ch->num_vertices; i++) {
        const bp_pin *p = pidx[i] != BP__NONE ? &opt->pins[pidx[i]] : NULL;
        if (p && (ch->uv[2 * (size_t)i] != p->u || ch->uv[2 * (size_t)i + 1] != p->v))
            st = bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, p->vertex, -1, 0,
                          "chart %u: vertex %u is pinned to (%g, %g) but the start map has it at (%g, %g)",
                          chart_index, p->vertex + 1, p->u, p->v, ch->uv[2 * (size_t)i], ch->uv[2 * (size_t)i + 1]);
    }
    bp__free(&a, pidx);
    return st;
}

/* >>start ==================================================================

   A better start (issue 15).  The Tutte map of >>tutte is bijective but
   far from the optimum where a chart is long or thin: the boundary goes on
   a circle, and a protrusion or a strip is squeezed exponentially toward
   its tip -- triangles a million times too small (a 1 x 1e-7 strip of 398
   triangles starts at mean energy 9e8, lucy at 4e12) -- and every step
   bound of the optimizer is throttled by them.  What is here, each handing
   the optimizer a map that passed the exact check (bp_check), and each
   measured (docs/performance.md, sec 6.3):

   1. Planar charts start from themselves (bp_options.start = AUTO, the
      default).  A chart whose triangles all face one side of a plane
      within about 37 degrees is projected onto the plane of its
      area-weighted normal n; when every triangle keeps at least
      BP__START_PLANAR of its 3D area there and bp_check passes the
      projection exactly, the projection is the start: its singular values
      are s_max <= 1 and s_min >= BP__START_PLANAR, and for a flat chart it
      is the optimum itself (energy 4, nothing left to do).  A nearly flat
      chart whose projection overlaps itself (a helix band) fails the check
      and starts from Tutte as before.  No chart of ../shared/meshes is
      planar: their start maps are the same bits as before.

   2. Thin charts: the barrier width (bp__start_thin_eps below, used by
      the solver of >>optimize).  Without it no start helps a strip: the
      barrier itself pushes the strip wider than its rest shape.

   3. Progressive references (Liu, Ye et al. 2018, "Progressive
      parameterizations"; bp_options.start = PROGRESSIVE, not the default:
      it cuts lucy's iterations but not its time, sec 6.3).  After Tutte,
      in rounds, each triangle gets a reference shape between its current
      image and its rest shape,
          C = J^T J = V diag(s1^2, s2^2) V^T   (J the current Jacobian),
          reference metric C^a,   a = max(0, 1 - log K / log d),
          d = max(s1, 1/s2),
      so that the current map is within a factor K in both singular values
      of the reference, and a triangle already within K of its rest shape
      gets the rest shape itself (a = 0).  The iteration of >>optimize then
      runs up to BP__START_ITERS steps on the energy measured against the
      references (the same interior point method: every iterate is exactly
      bijective), preconditioned by the Laplacian of the reference
      triangles (cotangent weights of shapes close to the current ones; the
      rest shapes' Laplacian, tried, leaves the crushed triangles crushed).
      The crushed triangles see a moderate distortion and grow by about K
      per round.  The rounds stop when every triangle is within K of its
      rest shape or after BP__START_ROUNDS; the ordinary optimization takes
      over from there. */

#define BP__START_PLANAR 0.8      /* least projected / 3D area of a planar start */
#define BP__START_K 4.0           /* the current map within K of the references */
#define BP__START_ITERS 30        /* optimizer iterations per round            */
#define BP__START_ROUNDS 40

/* The reference of one triangle (3 above) into out = (w', x', y'):
   the rest triangle F1 = (0, 0), F2 = (w, 0), F3 = (x, y) (read back from
   M^-1 = [1/w  -x/(w y); 0  1/y], importance included) mapped by a linear
   A with A^T A = C^a:
       w' = w sqrt(Ca_00),  x' = (Ca_00 x + Ca_01 y) / sqrt(Ca_00),
       y' = det(A) w y / w',  det(A) = (s1 s2)^a.
   Returns log d, the triangle's distortion (0 when not finite: the rest). */
static double bp__start_triangle(const bp__rest *r, const double *u1, const double *u2, const double *u3,
                                 double logk, double *out)
{
    double w = 1 / r->m00, y = 1 / r->m11, x = -r->m01 * w * y;
    double d00 = u2[0] - u1[0], d10 = u2[1] - u1[1], d01 = u3[0] - u1[0], d11 = u3[1] - u1[1];
    double j00 = d00 * r->m00, j01 = d00 * r->m01 + d01 * r->m11, j10 = d10 * r->m00, j11 = d10 * r->m01 + d11 * r->m11;
    double c00 = j00 * j00 + j10 * j10, c01 = j00 * j01 + j10 * j11, c11 = j01 * j01 + j11 * j11;
    double det = j00 * j11 - j01 * j10, h = 0.5 * (c00 + c11), q = 0.5 * (c00 - c11);
    double l1 = h + sqrt(q * q + c01 * c01), l2, s1, s2, logd, a, v[2], n1, n2, p1, p2, ca00, ca01;
    out[0] = w; out[1] = x; out[2] = y;
    l2 = det * det / l1;
    s1 = sqrt(l1);
    s2 = fabs(det) / s1;
    logd = log(s1) > -log(s2) ? log(s1) : -log(s2);
    if (!(logd - logd == 0) || !(det > 0)) return 0;
    if (logd <= logk) return logd;
    a = 1 - logk / logd;
    /* the eigenvector of l1: the better conditioned of two candidates */
    n1 = c01 * c01 + (l1 - c00) * (l1 - c00);
    n2 = (l1 - c11) * (l1 - c11) + c01 * c01;
    if (n1 >= n2 && n1 > 0) { v[0] = c01; v[1] = l1 - c00; n1 = sqrt(n1); }
    else if (n2 > 0) { v[0] = l1 - c11; v[1] = c01; n1 = sqrt(n2); }
    else { v[0] = 1; v[1] = 0; n1 = 1; }
    v[0] /= n1; v[1] /= n1;
    p1 = pow(l1, a);
    p2 = pow(l2, a);
    ca00 = p1 * v[0] * v[0] + p2 * v[1] * v[1];          /* C^a = p1 v v^T + p2 v' v'^T */
    ca01 = (p1 - p2) * v[0] * v[1];
    {
        double wn = w * sqrt(ca00), xn = (ca00 * x + ca01 * y) / sqrt(ca00), yn = sqrt(p1 * p2) * w * y / wn;
        if (wn > 0 && yn > 0 && wn - wn == 0 && xn - xn == 0 && yn - yn == 0) { out[0] = wn; out[1] = xn; out[2] = yn; }
    }
    return logd;
}

/* The references of every triangle (3 above) from the rest shapes rest0
   and the map x: into S's rest shapes (weights kept) and wxy (3 per
   triangle, for the preconditioner); returns the largest log d. */
static double bp__start_references(bp__solver *S, const bp__rest *rest0, const double *x, double logk, double *wxy)
{
    double worst = 0;
    uint32_t t;
    for (t = 0; t < S->nt; t++) {
        const uint32_t *tr = S->tri + 3 * (size_t)t;
        double *r = wxy + 3 * (size_t)t;
        double lg = bp__start_triangle(&rest0[t], x + 2 * (size_t)tr[0], x + 2 * (size_t)tr[1], x + 2 * (size_t)tr[2],
                                       logk, r);
        if (lg > worst) worst = lg;
        bp__rest_inverse(r[0], r[1], r[2], 1, &S->rest[t]);
        S->rest[t].weight = rest0[t].weight;
    }
    return worst;
}

/* 3 above: the rounds of progressive references in one solver of
   >>optimize (set up once), each round: the references, their Laplacian
   factored as the preconditioner, the L-BFGS memory cleared, and at most
   BP__START_ITERS iterations of >>optimize (direction, step bound and
   line search with the exact check) on the energy against the references.
   Only the last accepted, exactly valid map is kept. */
static bp_status bp__start_progressive(bp_chart *ch, const bp_mesh *m, const bp_options *opt, const bp__par *runner,
                                       bp_error *err)
{
    bp__opt P;
    bp__rest *rest0 = NULL;
    double *wxy = NULL, logk = log(BP__START_K);
    int round;
    bp_status st;
    memset(&P, 0, sizeof P);
    P.a = bp__allocator_of(opt);
    P.o = *opt;
    P.o.progress = NULL;
    P.o.max_seconds = 0;
    P.o.pins = NULL;
    P.o.num_pins = 0;
    P.tlast = 1;
    P.precond = opt->direction == BP_DIRECTION_PRECONDITIONED;
    P.newton = opt->direction == BP_DIRECTION_NEWTON;
    P.par = *runner;
    if ((st = bp__opt_setup(&P, ch, 0, m, err)) != BP_OK) goto done;
    rest0 = (bp__rest *)bp__alloc_array(&P.a, P.S.nt, sizeof(bp__rest));
    wxy = (double *)bp__alloc_array(&P.a, 3 * (size_t)P.S.nt, sizeof(double));
    if (!rest0 || !wxy) { st = bp__oom(err, "computing the start map"); goto done; }
    memcpy(rest0, P.S.rest, P.S.nt * sizeof(bp__rest));
    for (round = 0; round < BP__START_ROUNDS; round++) {
        double f, ed;
        int it, small = 0;
        double worst = bp__start_references(&P.S, rest0, P.x, logk, wxy);
        if (worst <= logk) break;
        if (P.precond) {                       /* the references' Laplacian */
            bp__sparse_free(&P.a, &P.K);
            bp__factor_free(&P.a, &P.KF);
            memset(&P.K, 0, sizeof P.K);
            memset(&P.KF, 0, sizeof P.KF);
            if ((st = bp__laplacian(&P.a, &P.S, wxy, NULL, &P.K, &P.KF, NULL, NULL)) != BP_OK) {
                if (st == BP_ERR_OUT_OF_MEMORY) st = bp__oom(err, "factoring the preconditioner");
                else {
                    char name[48];
                    st = bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_TRIANGLE, ch->face[0], -1, 0,
                                  "the progressive start of the chart with %s: the Laplacian of its references "
                                  "could not be factored", bp__tri_name(m, ch->face[0], name));
                }
                goto done;
            }
        }
        f = bp__objective(&P.S, P.x, P.g, &ed);
        if (P.S.oom) { st = bp__oom(err, "evaluating the barrier"); goto done; }
        P.L.nh = 0;
        for (it = 0; it < BP__START_ITERS; it++) {
            double gv = bp__opt_direction(&P), tt = 0, fn = HUGE_VAL, edn = HUGE_VAL;
            int found;
            if (P.nd < 0) { st = bp__oom(err, "factoring Newton's system"); goto done; }
            if (gv == 0) break;
            found = bp__opt_line_search(&P, f, gv, &tt, &fn, &edn);
            if (found < 0) { st = bp__oom(err, "evaluating a step"); goto done; }
            if (!found) break;
            P.tlast = tt;
            bp__lbfgs_push(&P.L, &P.par, P.x, P.xn, P.g, P.gn);
            { double *tp = P.x; P.x = P.xn; P.xn = tp; tp = P.g; P.g = P.gn; P.gn = tp; }
            if ((f - fn) <= P.o.tolerance * fabs(fn)) small++; else small = 0;
            f = fn;
            if (small >= 3) break;
        }
    }
    memcpy(ch->uv, P.x, P.nv2 * sizeof(double));      /* every accepted x passed the exact check */
done:
    bp__free(&P.a, rest0);
    bp__free(&P.a, wxy);
    bp__opt_free(&P);
    return st;
}

/* 4. A crushed start, enlarged (beyond the dissertation; issue 15, lucy).
   A start whose mean energy is astronomical (lucy's mean-value map:
   1.2e15) has whole protrusions crushed to slivers: the symmetric
   Dirichlet terms 1/s^2 of their singular values s dominate it, while the
   rest of the chart sits near scale 1.  Enlarging the whole map by c
   divides the crushed terms by c^2 and multiplies the others by c^2, so
   the energy-optimal c is about (E0 / 2)^(1/4), lucy's ~5000.  That
   optimum is the wrong target (measured: 287 iterations to SCAF's energy
   against 77 unscaled, the body then shrinks back by steps clipped at
   t ~ 0.01); the geometric middle between it and 1, c ~ E0^(1/8), took
   65 of them (c = 10 ... 100 all between 65 and 69; 300: 83; 1000: 122;
   docs/performance.md 6.11).  The scale is a power of two,
   c = 2^round(log2(E0) / 8): multiplying by it is exact in floating point,
   so every orientation and every boundary predicate keeps its exact sign
   and the map stays bijective; it is checked again anyway (bp__evaluate),
   and kept only if it passes and lowers the energy.  Only Newton charts
   (>>optimize's rule) with the symmetric Dirichlet energy (the one
   measured; conformal and MIPS do not see the scale at all) whose start
   exceeds BP__START_SCALE_E0 and that hold no pins are enlarged (the
   others' maps are left bit for bit as before); the energy has one
   minimum scale, so the result is the same kind of minimum.
   Returns k (0: not scaled), -1 when out of memory. */
static int bp__start_scale(bp__opt *P, double *f, double *ed)
{
    double e0 = *ed / P->S.nt, c, fs, eds;
    uint32_t i;
    int k, valid;
    if (!P->newton || P->nheld || P->pen || P->S.energy != BP_ENERGY_SYMMETRIC_DIRICHLET ||
        !(e0 > BP__START_SCALE_E0) || !(e0 < HUGE_VAL)) return 0;
    k = (int)floor(log(e0) / log(2.0) / 8 + 0.5);
    if (k <= 0) return 0;
    c = ldexp(1.0, k);
    for (i = 0; i < P->nv2; i++) P->xn[i] = c * P->x[i];
    fs = bp__evaluate(&P->S, P->xn, P->gn, &eds, *f, &valid);
    if (P->S.oom) return -1;
    if (!(fs < *f) || !valid) return 0;
    { double *tp = P->x; P->x = P->xn; P->xn = tp; tp = P->g; P->g = P->gn; P->gn = tp; }
    *f = fs;
    *ed = eds;
    P->crushed = 1;
    return k;
}

/* (q - p) x (r - p) */
static void bp__start_cross(const double *p, const double *q, const double *r, double *c)
{
    double u[3], v[3];
    int k;
    for (k = 0; k < 3; k++) { u[k] = q[k] - p[k]; v[k] = r[k] - p[k]; }
    c[0] = u[1] * v[2] - u[2] * v[1];
    c[1] = u[2] * v[0] - u[0] * v[2];
    c[2] = u[0] * v[1] - u[1] * v[0];
}

/* An orthonormal e1, e2 with e1 x e2 = n (unit): e1 the coordinate axis
   least aligned with n, made orthogonal to it; e2 = n x e1. */
static void bp__start_frame(const double *n, double *e1, double *e2)
{
    int k, ax = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0 : fabs(n[1]) <= fabs(n[2]) ? 1 : 2;
    double len;
    for (k = 0; k < 3; k++) e1[k] = (k == ax) - n[ax] * n[k];
    len = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (k = 0; k < 3; k++) e1[k] /= len;
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

static int bp__start_dbl_cmp(const void *pa, const void *pb)
{
    double x = *(const double *)pa, y = *(const double *)pb;
    return x < y ? -1 : x > y;
}

/* Thin charts: the barrier width.  The barrier of >>barrier acts on every
   boundary vertex within eps of a boundary edge, eps a quarter of the mean
   boundary edge.  Across a strip thinner than that, every boundary vertex
   is within eps of the opposite side in the rest shape itself, so the
   barrier pushes the strip wider than its rest shape and the optimum of
   E_D + E_B is not the isometry: a 1 x 1e-4 strip of 398 triangles
   "converges" at mean energy 16.8, a 1 x 1e-7 one at 17,600, from any
   start.  So eps is also at most the chart's thickness at its boundary,
       eps <= median over boundary edges e of  h_e = 2 A_t / |e|,
   the altitude onto e of its triangle t, in the rest shape (>>rest).  On
   an ordinary mesh h_e is about 0.8 of an edge and the bound never acts
   (eps stays |e| / 4: the 15 meshes of ../shared/meshes keep their eps bit
   for bit); on a strip of width h, eps = h and the isometric map has no
   barrier energy at all (every boundary vertex is at least h from every
   boundary edge not its own).  The barrier's guarantee does not depend on
   eps: any eps > 0 is infinite at contact, and the exact check accepts
   every iterate anyway.  wxy: the rest shapes (>>rest) the solver's
   set-up has just made, 3 per triangle; only a boundary edge's length is
   taken.  Returns 0 when out of memory. */
static int bp__start_thin_eps(const bp_allocator *a, const bp_chart *ch, const double *wxy, double *eps)
{
    uint32_t nb = ch->loop_start[ch->num_loops], L, k, t, n = 0;
    uint32_t *next = (uint32_t *)bp__alloc_array(a, ch->num_vertices, sizeof(uint32_t));
    double *h = (double *)bp__alloc_array(a, (size_t)nb + 1, sizeof(double));
    if (!next || !h) { bp__free(a, next); bp__free(a, h); return 0; }
    for (k = 0; k < ch->num_vertices; k++) next[k] = BP__NONE;
    for (L = 0; L < ch->num_loops; L++)
        for (k = ch->loop_start[L]; k < ch->loop_start[L + 1]; k++)
            next[ch->loop_vertices[k]] = ch->loop_vertices[k + 1 < ch->loop_start[L + 1] ? k + 1 : ch->loop_start[L]];
    for (t = 0; t < ch->num_triangles && n < nb; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        double w = wxy[3 * (size_t)t], x = wxy[3 * (size_t)t + 1], y = wxy[3 * (size_t)t + 2], len;
        int c;
        for (c = 0; c < 3; c++) {                 /* F1 = (0,0), F2 = (w,0), F3 = (x,y) */
            uint32_t vi = tr[c], vj = tr[(c + 1) % 3];
            if (next[vi] != vj && next[vj] != vi) continue;
            len = c == 0 ? w : c == 1 ? sqrt((x - w) * (x - w) + y * y) : sqrt(x * x + y * y);
            h[n++] = w * y / len;                 /* 2 A / |e| */
        }
    }
    bp__free(a, next);
    if (n > 0) {
        double med;
        qsort(h, n, sizeof(double), bp__start_dbl_cmp);
        med = h[n / 2];
        if (med > 0 && med < *eps) *eps = med;
    }
    bp__free(a, h);
    return 1;
}

/* 1 above: the projection of a planar chart onto its plane (the
   area-weighted normal n, e1 e2 n right-handed so that a triangle facing
   n is counter-clockwise), used when every triangle keeps
   BP__START_PLANAR of its area and the map passes bp_check: 1 used, 0
   not, -1 out of memory.  The triangles' cross products are taken in
   chunks on par's threads (each its own), and added in triangle order
   after them: the serial loop's n, bit for bit. */
typedef struct bp__cross_task { const bp_chart *ch; const bp_mesh *m; double *cr; uint32_t nc; } bp__cross_task;

static void bp__cross_run(void *task, uint32_t c)
{
    const bp__cross_task *J = (const bp__cross_task *)task;
    const bp_chart *ch = J->ch;
    uint32_t t, t1 = bp__chunk_at(ch->num_triangles, J->nc, c + 1);
    for (t = bp__chunk_at(ch->num_triangles, J->nc, c); t < t1; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        bp__start_cross(bp__pos(J->m, ch->vertex[tr[0]]), bp__pos(J->m, ch->vertex[tr[1]]),
                        bp__pos(J->m, ch->vertex[tr[2]]), J->cr + 3 * (size_t)t);
    }
}

static int bp__start_planar(const bp_allocator *a, bp_chart *ch, const bp_mesh *m, const bp__par *par)
{
    double n[3] = { 0, 0, 0 }, c[3] = { 0, 0, 0 }, e1[3], e2[3], len;
    uint32_t t, i, k;
    bp_check_report rep;
    bp_status st;
    bp__cross_task J;
    bp__par serial = bp__par_serial();
    for (t = 0; ch->rest_side && t < ch->num_triangles; t++) if (ch->rest_side[t] > 0) return 0;
    J.ch = ch;
    J.m = m;
    J.nc = bp__nchunks(ch->num_triangles, BP__TRI_CHUNK);
    if (!(J.cr = (double *)bp__alloc_array(a, 3 * (size_t)ch->num_triangles + 1, sizeof(double)))) return -1;
    bp__par_run(par ? par : &serial, bp__cross_run, &J, J.nc, ch->num_triangles);
    for (t = 0; t < ch->num_triangles; t++)
        for (k = 0; k < 3; k++) n[k] += J.cr[3 * (size_t)t + k];
    len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0) || !(len < HUGE_VAL)) { bp__free(a, J.cr); return 0; }
    for (k = 0; k < 3; k++) n[k] /= len;
    bp__start_frame(n, e1, e2);
    for (t = 0; t < ch->num_triangles; t++) {
        const double *cr = J.cr + 3 * (size_t)t;
        double ar = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        if (!(cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2] >= BP__START_PLANAR * ar)) break;
    }
    bp__free(a, J.cr);
    if (t < ch->num_triangles) return 0;
    for (i = 0; i < ch->num_vertices; i++)
        for (k = 0; k < 3; k++) c[k] += bp__pos(m, ch->vertex[i])[k] / ch->num_vertices;
    for (i = 0; i < ch->num_vertices; i++) {
        const double *p = bp__pos(m, ch->vertex[i]);
        double d[3];
        for (k = 0; k < 3; k++) d[k] = p[k] - c[k];
        ch->uv[2 * (size_t)i] = d[0] * e1[0] + d[1] * e1[1] + d[2] * e1[2];
        ch->uv[2 * (size_t)i + 1] = d[0] * e2[0] + d[1] * e2[1] + d[2] * e2[2];
    }
    st = bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, a, &rep, NULL);
    if (st == BP_ERR_OUT_OF_MEMORY) return -1;
    return st == BP_OK;
}
/* >>segment ================================================================

   Segmentation into several charts (issue 14).  The cut of >>cut opens a
   closed or high-genus chart into ONE disk; that disk can be long and
   branched (fertility, a torus with holes), so it fills its square of the
   atlas badly, and on a 90K-triangle scan the single large chart is what
   makes the solve slow.  Splitting charts into several fixes both, and is
   always safe for bijectivity: any part of a bijective map is bijective,
   so a chart cut along mesh edges has valid sub-charts.  Two mechanisms:

   (b) Growing charts by normal deviation, before the solve (Cohen-Steiner,
       Alliez & Desbrun's variational shape approximation, 2004, with the
       L^{2,1} metric on normals; xatlas, UVAtlas and D-charts grow charts
       by the same kind of planarity cost).  K proxies, each a normal N_k
       and a seed triangle, share the chart's triangles by a priority flood
       from the seeds across interior edges; triangle t joins proxy k at
       the cost

           c(t, k) = ( |n_t - N_k|^2 + lambda (d_k(t) / r)^2 ) / w_t,

       n_t its unit normal, d_k(t) the length of the flood's path from the
       seed (between centroids), r = sqrt(A / (pi K)) the radius of a chart
       of the mean area, lambda = BP__SEG_COMPACT the weight that keeps
       charts round (round charts pack well), w_t the relative importance
       (1 without; below).  Lloyd iterations then move each proxy to the
       area-weighted mean normal of its region and its seed to the region's
       triangle of least cost from the region's centroid.  Proxies are
       inserted where the fit is bad: every region whose mean deviation
       1 - n_t.N_k (area-weighted) is above BP__SEG_DEV = 0.25 -- the mean
       over a spherical cap of 60 degrees, (1 - cos 60)/2 -- and that has
       at least BP__SEG_LEAST triangles gets a new seed at its most
       deviating triangle, one Lloyd step per round, until no region
       needs one or the chart count allowed is reached; three more Lloyd
       steps finish.  A mean, not the largest deviation: a scan's noisy
       triangles would otherwise each become a chart.  Each region is
       connected (the flood grows it from its seed), and a region of a
       disk with holes is a disk with holes (genus 0), so every piece
       passes the topology check; a piece enclosing another has a hole,
       which the free boundary handles.  Charts that are already disks are
       split too: this is what raises a single chart's utilization (the
       cow's one vt chart).  The vt seams stay: pieces are parts of charts.

   (a) Splitting charts whose distortion stays high after the bijective
       optimization (seed sec 3.6 suggests it): a chart whose mean
       distortion (bp_chart_distortion under opt.energy, area-weighted)
       is above opt.max_distortion is split in two by the same flood with
       K = 2, seeded at the two ends of an approximate diameter (two
       floods: the farthest triangle from triangle 0, then the farthest
       from it), which gives balanced halves -- a seed at the most
       deviating normal cut off slivers, down to single triangles, on the
       cow.  Each piece keeps its part of the map -- valid as it is,
       checked exactly -- and is optimized again from it with its new free
       boundary; the optimizer accepts only decreases of its objective, so
       the piece ends near or below the energy it started with.  Rounds
       repeat until every chart meets the bound, the chart count reaches
       opt.max_charts, or a chart cannot be split (one triangle: its
       energy is what the barrier allows, e.g. 4.44 for a thin one).

   Importance.  With opt.importance (painted, or the visibility of chapter
   4), the flood's path lengths are divided by the edge's mean relative
   importance and the costs by w_t, and seeds prefer important triangles:
   regions spread fast through what matters and their fronts meet -- the
   seams -- where importance is low, as the cut's importance-weighted
   paths do (>>cut).

   Mechanics.  A split renumbers nothing of the other charts: the piece
   with the chart's first triangle keeps its index, the others are
   appended.  Each piece gets its chart vertices as in >>cut's split (the
   chart's corners merged again across the interior edges inside the
   piece, so a vertex on a new seam gets one copy per piece and per fan),
   its loops walked by bp__chart_loops, its Euler characteristic checked,
   and the atlas's corner_chart / corner_vertex follow, so the writers give
   each side of a new seam its own vt.  Everything is serial except the
   solves of the pieces, which are independent charts: the result is
   bit-identical for any number of threads. */

#ifndef BP__SEG_DEV             /* largest mean deviation 1 - n.N of a grown chart (a 60 degree cap) */
#define BP__SEG_DEV 0.25
#endif
#define BP__SEG_LEAST 16        /* a region of fewer triangles gets no new seed */
#ifndef BP__SEG_COMPACT         /* lambda: weight of roundness against planarity */
#define BP__SEG_COMPACT 0.5
#endif
#define BP__SEG_LLOYD 3         /* floods per insertion round */

typedef struct bp__seg_item { double cost, d; uint32_t t, k; } bp__seg_item;

/* Scratch of one chart's segmentation. */
typedef struct bp__seg {
    uint32_t nt, K, cap;
    uint32_t *twin;       /* 3nt: chart corner edge across an interior edge, or BP__NONE */
    double   *geo;        /* 7nt: unit normal, centroid, area                  */
    double   *w;          /* nt: relative importance (1 without)               */
    uint32_t *label;      /* nt: proxy of each triangle                        */
    double   *dist;       /* nt: the flood's path length from the seed         */
    uint32_t *seed;       /* cap                                               */
    double   *prox;       /* 3 cap: proxy normals                              */
    double   *ctr;        /* 4 cap: region centroid sums and area              */
    double   *nsum;       /* 3 cap: area-weighted normal sums                  */
    double   *worst;      /* cap: mean deviation 1 - n.N in the region (area-weighted) */
    uint32_t *worst_t;    /* cap: its triangle of largest deviation            */
    uint32_t *count;      /* cap: its triangles                                */
    bp__seg_item *heap;   /* 3nt + cap                                         */
    double    area, r2;
} bp__seg;

typedef struct bp__seg_edge { uint32_t lo, hi, ce; } bp__seg_edge;

static int bp__seg_edge_cmp(const void *pa, const void *pb)
{
    const bp__seg_edge *x = (const bp__seg_edge *)pa, *y = (const bp__seg_edge *)pb;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
    return x->ce < y->ce ? -1 : x->ce > y->ce;
}

/* Twins inside a chart: the two corner edges of an interior edge run
   between the same two chart vertices in opposite directions.  An edge
   met once, or more than twice, or twice in one direction, is boundary.
   0 if out of memory. */
static int bp__seg_twins(const bp_allocator *a, const bp_chart *ch, uint32_t *twin)
{
    uint32_t nc = 3 * ch->num_triangles, ce, i, j;
    bp__seg_edge *e = (bp__seg_edge *)bp__alloc_array(a, nc ? nc : 1, sizeof *e);
    if (!e) return 0;
    for (ce = 0; ce < nc; ce++) {
        uint32_t u = bp__ce_from(ch, ce), v = bp__ce_to(ch, ce);
        e[ce].lo = u < v ? u : v;
        e[ce].hi = u < v ? v : u;
        e[ce].ce = ce;
        twin[ce] = BP__NONE;
    }
    qsort(e, nc, sizeof *e, bp__seg_edge_cmp);
    for (i = 0; i < nc; i = j) {
        for (j = i + 1; j < nc && e[j].lo == e[i].lo && e[j].hi == e[i].hi; j++) {}
        if (j - i == 2 && bp__ce_from(ch, e[i].ce) != bp__ce_from(ch, e[i + 1].ce)) {
            twin[e[i].ce] = e[i + 1].ce;
            twin[e[i + 1].ce] = e[i].ce;
        }
    }
    bp__free(a, e);
    return 1;
}

static void bp__seg_free(const bp_allocator *a, bp__seg *S)
{
    bp__free(a, S->twin); bp__free(a, S->geo); bp__free(a, S->w); bp__free(a, S->label); bp__free(a, S->dist);
    bp__free(a, S->seed); bp__free(a, S->prox); bp__free(a, S->ctr); bp__free(a, S->nsum); bp__free(a, S->worst);
    bp__free(a, S->worst_t); bp__free(a, S->count); bp__free(a, S->heap);
    memset(S, 0, sizeof *S);
}

/* Normals, centroids and areas of the chart's triangles (oriented as the
   chart is; a repaired degenerate triangle has no normal and its rest
   area), the relative importance, and the scratch for up to cap proxies.
   0 if out of memory. */
static int bp__seg_setup(const bp_allocator *a, bp__seg *S, const bp_chart *ch, const bp_mesh *m,
                         const double *importance, uint32_t cap)
{
    uint32_t nt = ch->num_triangles, t, k;
    double isum = 0;
    memset(S, 0, sizeof *S);
    S->nt = nt;
    S->cap = cap;
    S->twin = (uint32_t *)bp__alloc_array(a, 3 * (size_t)nt, sizeof(uint32_t));
    S->geo = (double *)bp__alloc_array(a, 7 * (size_t)nt, sizeof(double));
    S->w = (double *)bp__alloc_array(a, nt, sizeof(double));
    S->label = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    S->dist = (double *)bp__alloc_array(a, nt, sizeof(double));
    S->seed = (uint32_t *)bp__alloc_array(a, cap, sizeof(uint32_t));
    S->prox = (double *)bp__alloc_array(a, 3 * (size_t)cap, sizeof(double));
    S->ctr = (double *)bp__alloc_array(a, 4 * (size_t)cap, sizeof(double));
    S->nsum = (double *)bp__alloc_array(a, 3 * (size_t)cap, sizeof(double));
    S->worst = (double *)bp__alloc_array(a, cap, sizeof(double));
    S->worst_t = (uint32_t *)bp__alloc_array(a, cap, sizeof(uint32_t));
    S->count = (uint32_t *)bp__alloc_array(a, cap, sizeof(uint32_t));
    S->heap = (bp__seg_item *)bp__alloc_array(a, 3 * (size_t)nt + cap, sizeof(bp__seg_item));
    if (!S->twin || !S->geo || !S->w || !S->label || !S->dist || !S->seed || !S->prox || !S->ctr || !S->nsum || !S->worst ||
        !S->worst_t || !S->count || !S->heap || !bp__seg_twins(a, ch, S->twin))
        return 0;
    for (t = 0; t < nt; t++) {
        const double *p[3];
        double *g = S->geo + 7 * (size_t)t, e1[3], e2[3], n[3], len;
        for (k = 0; k < 3; k++) p[k] = bp__pos(m, ch->vertex[ch->triangles[3 * t + k]]);
        for (k = 0; k < 3; k++) { e1[k] = p[1][k] - p[0][k]; e2[k] = p[2][k] - p[0][k]; }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (k = 0; k < 3; k++) {
            g[k] = len > 0 && !(ch->rest_side && ch->rest_side[t] > 0) ? n[k] / len : 0;
            g[3 + k] = (p[0][k] + p[1][k] + p[2][k]) / 3;
        }
        g[6] = ch->rest_side && ch->rest_side[t] > 0 ? 0.4330127018922193 * ch->rest_side[t] * ch->rest_side[t]
                                                      : 0.5 * len;
        S->area += g[6];
        S->w[t] = importance ? importance[ch->face[t]] : 1;
        if (!(S->w[t] > 0 && S->w[t] < HUGE_VAL)) S->w[t] = 1;
        isum += S->w[t];
    }
    for (t = 0; t < nt; t++) S->w[t] /= isum / nt;          /* mean 1 */
    if (!(S->area > 0)) S->area = 1;
    return 1;
}

/* Deviation |n_t - N_k|^2 = 2 (1 - n_t . N_k) for unit vectors. */
static double bp__seg_dev(const bp__seg *S, uint32_t t, uint32_t k)
{
    const double *n = S->geo + 7 * (size_t)t, *p = S->prox + 3 * (size_t)k;
    double dx = n[0] - p[0], dy = n[1] - p[1], dz = n[2] - p[2];
    return dx * dx + dy * dy + dz * dz;
}

static double bp__seg_cost(const bp__seg *S, uint32_t t, uint32_t k, double d)
{
    return (bp__seg_dev(S, t, k) + BP__SEG_COMPACT * d * d / S->r2) / S->w[t];
}

/* The heap of the flood, ordered by (cost, triangle, proxy): deterministic. */
static int bp__seg_less(const bp__seg_item *x, const bp__seg_item *y)
{
    if (x->cost != y->cost) return x->cost < y->cost;
    if (x->t != y->t) return x->t < y->t;
    return x->k < y->k;
}

static void bp__seg_push(bp__seg *S, uint32_t *n, bp__seg_item it)
{
    uint32_t i = (*n)++;
    while (i > 0 && bp__seg_less(&it, &S->heap[(i - 1) / 2])) { S->heap[i] = S->heap[(i - 1) / 2]; i = (i - 1) / 2; }
    S->heap[i] = it;
}

static bp__seg_item bp__seg_pop(bp__seg *S, uint32_t *n)
{
    bp__seg_item top = S->heap[0], last = S->heap[--*n];
    uint32_t i = 0;
    for (;;) {
        uint32_t l = 2 * i + 1, r = l + 1, s = l;
        if (l >= *n) break;
        if (r < *n && bp__seg_less(&S->heap[r], &S->heap[l])) s = r;
        if (!bp__seg_less(&S->heap[s], &last)) break;
        S->heap[i] = S->heap[s];
        i = s;
    }
    if (*n) S->heap[i] = last;
    return top;
}

/* The flood: every seed claims its triangle first (cost -1), then the
   cheapest (triangle, proxy) pair is taken, repeatedly; each triangle is
   taken once, by a neighbour's proxy, so every region is connected.  At
   most 3 nt + K entries are ever pushed. */
static void bp__seg_flood(bp__seg *S)
{
    uint32_t n = 0, t, k, j;
    S->r2 = S->area / (3.141592653589793 * S->K);
    for (t = 0; t < S->nt; t++) S->label[t] = BP__NONE;
    for (k = 0; k < S->K; k++) {
        bp__seg_item it;
        it.cost = -1; it.d = 0; it.t = S->seed[k]; it.k = k;
        bp__seg_push(S, &n, it);
    }
    while (n > 0) {
        bp__seg_item it = bp__seg_pop(S, &n);
        const double *c0 = S->geo + 7 * (size_t)it.t + 3;
        if (S->label[it.t] != BP__NONE) continue;
        S->label[it.t] = it.k;
        S->dist[it.t] = it.d;
        for (j = 0; j < 3; j++) {
            uint32_t tw = S->twin[3 * it.t + j], u;
            const double *c1;
            bp__seg_item nx;
            if (tw == BP__NONE || S->label[u = tw / 3] != BP__NONE) continue;
            c1 = S->geo + 7 * (size_t)u + 3;
            nx.d = it.d + bp__dist3(c0, c1) * 2 / (S->w[it.t] + S->w[u]);
            nx.cost = bp__seg_cost(S, u, it.k, nx.d);
            nx.t = u;
            nx.k = it.k;
            bp__seg_push(S, &n, nx);
        }
    }
}

/* Lloyd's update: each proxy's normal becomes its region's area-weighted
   mean normal, its seed the region's triangle of least cost from the
   region's centroid; and each region's worst deviation is found. */
static void bp__seg_fit(bp__seg *S, int reseed)
{
    uint32_t t, k, i;
    double *best = S->worst;                     /* reused below */
    for (i = 0; i < 4 * S->K; i++) S->ctr[i] = 0;
    {
        double *nsum = S->nsum;
        for (i = 0; i < 3 * S->K; i++) nsum[i] = 0;
        for (t = 0; t < S->nt; t++) {
            const double *g = S->geo + 7 * (size_t)t;
            k = S->label[t];
            if (k == BP__NONE) continue;
            for (i = 0; i < 3; i++) { nsum[3 * k + i] += g[6] * g[i]; S->ctr[4 * k + i] += g[6] * g[3 + i]; }
            S->ctr[4 * k + 3] += g[6];
        }
        for (k = 0; k < S->K; k++) {
            double len = sqrt(nsum[3 * k] * nsum[3 * k] + nsum[3 * k + 1] * nsum[3 * k + 1] +
                              nsum[3 * k + 2] * nsum[3 * k + 2]);
            if (len > 0) for (i = 0; i < 3; i++) S->prox[3 * k + i] = nsum[3 * k + i] / len;
            if (S->ctr[4 * k + 3] > 0) for (i = 0; i < 3; i++) S->ctr[4 * k + i] /= S->ctr[4 * k + 3];
        }
    }
    if (reseed) {
        for (k = 0; k < S->K; k++) best[k] = HUGE_VAL;
        for (t = 0; t < S->nt; t++) {
            const double *c = S->geo + 7 * (size_t)t + 3;
            double d, s;
            k = S->label[t];
            if (k == BP__NONE) continue;
            d = bp__dist3(c, S->ctr + 4 * (size_t)k);
            s = (bp__seg_dev(S, t, k) + BP__SEG_COMPACT * d * d / S->r2) / S->w[t];
            if (s < best[k]) { best[k] = s; S->seed[k] = t; }
        }
    }
    for (k = 0; k < S->K; k++) { S->worst[k] = 0; S->worst_t[k] = BP__NONE; S->count[k] = 0; }
    for (t = 0; t < S->nt; t++) {
        double dv, mx = -1;
        k = S->label[t];
        if (k == BP__NONE) continue;
        S->count[k]++;
        if (!(S->geo[7 * (size_t)t + 6] > 0)) continue;
        dv = 0.5 * bp__seg_dev(S, t, k);                  /* 1 - n . N */
        S->worst[k] += S->geo[7 * (size_t)t + 6] * dv;    /* area-weighted, divided below */
        if (S->worst_t[k] != BP__NONE) mx = 0.5 * bp__seg_dev(S, S->worst_t[k], k);
        if (dv > mx) S->worst_t[k] = t;
    }
    for (k = 0; k < S->K; k++) S->worst[k] = S->ctr[4 * k + 3] > 0 ? S->worst[k] / S->ctr[4 * k + 3] : 0;
}

/* Seed k at triangle t, its proxy normal t's. */
static void bp__seg_seed(bp__seg *S, uint32_t k, uint32_t t)
{
    S->seed[k] = t;
    S->prox[3 * k] = S->geo[7 * (size_t)t];
    S->prox[3 * k + 1] = S->geo[7 * (size_t)t + 1];
    S->prox[3 * k + 2] = S->geo[7 * (size_t)t + 2];
}

/* The triangle the flood from one seed reached by the longest path (the
   smallest index among equals). */
static uint32_t bp__seg_farthest(bp__seg *S, uint32_t from)
{
    uint32_t t, far = from;
    S->K = 1;
    bp__seg_seed(S, 0, from);
    bp__seg_flood(S);
    for (t = 0; t < S->nt; t++)
        if (S->label[t] != BP__NONE && S->dist[t] > S->dist[far]) far = t;
    return far;
}

/* Mechanism (a)'s split in two: seeds at the ends of an approximate
   diameter of the chart (two floods: the farthest p from triangle 0, then
   the farthest q from p), then Lloyd's iterations.  Balanced halves: a
   seed at the most deviating normal would often cut off a sliver. */
static void bp__seg_label_two(bp__seg *S)
{
    uint32_t p = bp__seg_farthest(S, 0), q = bp__seg_farthest(S, p), it;
    if (p == q) { S->K = 1; return; }
    S->K = 2;
    bp__seg_seed(S, 0, p);
    bp__seg_seed(S, 1, q);
    for (it = 0; it < BP__SEG_LLOYD; it++) {
        bp__seg_flood(S);
        bp__seg_fit(S, it + 1 < BP__SEG_LLOYD);
    }
}

/* Label the chart's triangles into at most kmax regions: a region whose
   mean deviation 1 - n.N (area-weighted) is above `dev` and that has at
   least `least` triangles gets a new seed at its most deviating triangle
   (mechanism (b)). */
static void bp__seg_label(bp__seg *S, uint32_t kmax, double dev, uint32_t least)
{
    uint32_t k, it, round;
    if (kmax > S->cap) kmax = S->cap;
    S->K = 1;
    S->seed[0] = 0;
    S->prox[0] = S->geo[0]; S->prox[1] = S->geo[1]; S->prox[2] = S->geo[2];
    for (round = 0; round < 64; round++) {
        uint32_t K0 = S->K;
        bp__seg_flood(S);                 /* one Lloyd step per round ... */
        bp__seg_fit(S, 1);
        for (k = 0; k < K0 && S->K < kmax; k++)
            if (S->worst_t[k] != BP__NONE && S->worst[k] > dev && S->count[k] >= least &&
                S->worst_t[k] != S->seed[k]) {
                uint32_t t = S->worst_t[k];
                S->seed[S->K] = t;
                S->prox[3 * S->K] = S->geo[7 * (size_t)t];
                S->prox[3 * S->K + 1] = S->geo[7 * (size_t)t + 1];
                S->prox[3 * S->K + 2] = S->geo[7 * (size_t)t + 2];
                S->K++;
            }
        if (S->K == K0) break;
    }
    for (it = 0; it < BP__SEG_LLOYD; it++) {   /* ... and a few more at the end */
        bp__seg_flood(S);
        bp__seg_fit(S, it + 1 < BP__SEG_LLOYD);
    }
}

/* Mesh-size scratch shared by the splits of one call. */
typedef struct bp__seg_mesh {
    uint32_t *glued;     /* 3 F: 0 inside a piece, BP__NONE on its boundary (for bp__chart_loops) */
    uint32_t *facepos;   /* F: chart triangle of each mesh triangle of the chart split, else BP__NONE */
} bp__seg_mesh;

/* Scratch of one split, over the chart's triangles and corners. */
typedef struct bp__split {
    uint32_t P;          /* pieces                                           */
    uint32_t *pid;       /* nt: piece of each triangle                       */
    uint32_t *lt;        /* nt: its index in the piece                       */
    uint32_t *cuf;       /* 3nt: corner union-find                          */
    uint32_t *vid;       /* 3nt: piece vertex of each corner class root      */
    uint32_t *next, *loop_id; /* 3nt + 1: for bp__chart_loops                */
    uint32_t *cnt;       /* 2P: triangles and vertices of each piece         */
    bp_chart *pc;        /* P pieces                                         */
} bp__split;

static uint32_t bp__seg_nextc(uint32_t x) { return x - x % 3 + (x % 3 + 1) % 3; }

static void bp__split_free(const bp_allocator *a, bp__split *X)
{
    uint32_t p;
    if (X->pc) for (p = 0; p < X->P; p++) bp__chart_free(a, &X->pc[p]);
    bp__free(a, X->pc); bp__free(a, X->pid); bp__free(a, X->lt); bp__free(a, X->cuf);
    bp__free(a, X->vid); bp__free(a, X->next); bp__free(a, X->loop_id); bp__free(a, X->cnt);
    memset(X, 0, sizeof *X);
}

/* Pieces: the connected components of the triangles under `label` across
   the chart's interior edges, numbered by their first triangle; then the
   chart vertices of each piece, one per corner class across the interior
   edges inside the piece, numbered by first appearance. */
static void bp__split_pieces(bp__split *X, const bp_chart *ch, const uint32_t *twin, const uint32_t *label)
{
    uint32_t nt = ch->num_triangles, nc = 3 * nt, t, ce, *tuf = X->cuf, *rootp = X->lt;
    for (t = 0; t < nt; t++) { tuf[t] = t; rootp[t] = BP__NONE; }
    for (ce = 0; ce < nc; ce++)
        if (twin[ce] != BP__NONE && label[ce / 3] == label[twin[ce] / 3]) bp__uf_union(tuf, ce / 3, twin[ce] / 3);
    X->P = 0;
    for (t = 0; t < nt; t++) {
        uint32_t r = bp__uf_find(tuf, t);
        if (rootp[r] == BP__NONE) rootp[r] = X->P++;
        X->pid[t] = rootp[r];
    }
    for (ce = 0; ce < nc; ce++) { X->cuf[ce] = ce; X->vid[ce] = BP__NONE; }
    for (ce = 0; ce < nc; ce++) {
        uint32_t tw = twin[ce];
        if (tw == BP__NONE || tw < ce || X->pid[ce / 3] != X->pid[tw / 3]) continue;
        bp__uf_union(X->cuf, ce, bp__seg_nextc(tw));      /* corner at the edge's start */
        bp__uf_union(X->cuf, bp__seg_nextc(ce), tw);      /* corner at its end          */
    }
}

/* Number the pieces' triangles and vertices and fill their arrays (the
   map too, restricted, when the chart has one).  0 if out of memory. */
static int bp__split_fill(const bp_allocator *a, bp__split *X, const bp_chart *ch, const bp_mesh *m)
{
    uint32_t nt = ch->num_triangles, t, k, p, *nT = X->cnt, *nV = X->cnt + X->P;
    for (p = 0; p < 2 * X->P; p++) X->cnt[p] = 0;
    for (t = 0; t < nt; t++) {
        nT[X->pid[t]]++;
        for (k = 0; k < 3; k++) {
            uint32_t r = bp__uf_find(X->cuf, 3 * t + k);
            if (X->vid[r] == BP__NONE) X->vid[r] = nV[X->pid[t]]++;
        }
    }
    for (p = 0; p < X->P; p++) {
        bp_chart *pc = &X->pc[p];
        pc->vertex = (uint32_t *)bp__alloc_array(a, nV[p], sizeof(uint32_t));
        pc->vertex_uv = (uint32_t *)bp__alloc_array(a, nV[p], sizeof(uint32_t));
        pc->triangles = (uint32_t *)bp__alloc_array(a, 3 * (size_t)nT[p], sizeof(uint32_t));
        pc->face = (uint32_t *)bp__alloc_array(a, nT[p], sizeof(uint32_t));
        if (ch->uv) pc->uv = (double *)bp__alloc_array(a, 2 * (size_t)nV[p], sizeof(double));
        if (ch->rest_side) pc->rest_side = (double *)bp__calloc_array(a, nT[p], sizeof(double));
        if (!pc->vertex || !pc->vertex_uv || !pc->triangles || !pc->face || (ch->uv && !pc->uv) ||
            (ch->rest_side && !pc->rest_side))
            return 0;
        pc->num_vertices = nV[p];
    }
    for (t = 0; t < nt; t++) {
        bp_chart *pc = &X->pc[X->pid[t]];
        uint32_t l = pc->num_triangles++;
        X->lt[t] = l;
        pc->face[l] = ch->face[t];
        for (k = 0; k < 3; k++) {
            uint32_t old = ch->triangles[3 * t + k], nw = X->vid[bp__uf_find(X->cuf, 3 * t + k)];
            pc->triangles[3 * l + k] = nw;
            pc->vertex[nw] = ch->vertex[old];
            pc->vertex_uv[nw] = ch->vertex_uv[old];
            if (ch->uv) { pc->uv[2 * nw] = ch->uv[2 * old]; pc->uv[2 * nw + 1] = ch->uv[2 * old + 1]; }
        }
        if (ch->rest_side && ch->rest_side[t] > 0) {
            pc->rest_side[l] = ch->rest_side[t];
            pc->area3d += 0.4330127018922193 * ch->rest_side[t] * ch->rest_side[t];
        } else
            pc->area3d += 0.5 * bp__area2_3d(bp__pos(m, pc->vertex[pc->triangles[3 * l]]),
                                             bp__pos(m, pc->vertex[pc->triangles[3 * l + 1]]),
                                             bp__pos(m, pc->vertex[pc->triangles[3 * l + 2]]));
    }
    return 1;
}

/* Loops of every piece, and the test that it is a disk with holes (and,
   with a map, that the restricted map is valid, exactly).  BP_OK: all
   fine; BP_ERR_TOPOLOGY / BP_ERR_NOT_BIJECTIVE: leave the chart whole
   (should not happen: a part of a disk with holes, of a bijective map);
   BP_ERR_OUT_OF_MEMORY. */
static bp_status bp__split_verify(const bp_allocator *a, bp__split *X, const bp_chart *ch, const bp_mesh *m,
                                  const uint32_t *twin, bp__seg_mesh *G, uint32_t c)
{
    uint32_t nt = ch->num_triangles, t, k, p, ce;
    bp_error why;
    for (ce = 0; ce < 3 * nt; ce++) X->next[ce] = 0;
    for (t = 0; t < nt; t++)
        for (k = 0; k < 3; k++) {
            uint32_t tw = twin[3 * t + k];
            int in = tw != BP__NONE && X->pid[tw / 3] == X->pid[t];
            G->glued[3 * (size_t)ch->face[t] + k] = in ? 0 : BP__NONE;
            if (!in && ++X->next[bp__uf_find(X->cuf, 3 * t + k)] > 1) return BP_ERR_TOPOLOGY;  /* a pinch */
        }
    for (p = 0; p < X->P; p++) {
        bp_chart *pc = &X->pc[p];
        int64_t ne, chi;
        bp_status st = bp__chart_loops(a, pc, m, X->next, X->loop_id, G->glued, c, &why);
        if (st != BP_OK) return st;
        ne = ((int64_t)3 * pc->num_triangles + pc->loop_start[pc->num_loops]) / 2;
        chi = (int64_t)pc->num_vertices - ne + pc->num_triangles;
        if (pc->num_loops == 0 || chi != 2 - (int64_t)pc->num_loops) return BP_ERR_TOPOLOGY;
        if (pc->uv) {
            bp_check_report rep;
            st = bp_check(pc->triangles, pc->num_triangles, pc->uv, pc->num_vertices, a, &rep, NULL);
            if (st == BP_ERR_OUT_OF_MEMORY) return st;
            if (st != BP_OK) return BP_ERR_NOT_BIJECTIVE;
        }
    }
    return BP_OK;
}

/* The atlas takes the pieces: corner_chart / corner_vertex of every mesh
   corner of chart c (a dropped duplicate's corners, whose triangle is not
   in the chart, follow the first corner of their chart vertex), piece 0 at
   index c, the others appended.  0 if out of memory. */
static int bp__split_commit(bp_atlas *atlas, uint32_t c, bp__split *X, const uint32_t *twin, bp__seg_mesh *G)
{
    bp_allocator a = atlas->allocator;
    bp_chart *ch = &atlas->charts[c], *nch;
    uint32_t nt = ch->num_triangles, n0 = atlas->num_charts, t, k, p, ce, seams = 0, i;
    uint32_t *first = X->loop_id;                   /* free again: first corner of each chart vertex */
    nch = (bp_chart *)bp__alloc_array(&a, (size_t)n0 + X->P - 1, sizeof(bp_chart));
    if (!nch) return 0;
    for (i = 0; i < ch->num_vertices; i++) first[i] = BP__NONE;
    for (ce = 3 * nt; ce-- > 0;) first[ch->triangles[ce]] = ce;
    for (t = 0; t < nt; t++) G->facepos[ch->face[t]] = t;
    for (i = 0; i < atlas->num_corners; i++) {
        uint32_t ov, f, hit = BP__NONE;
        if (atlas->corner_chart[i] != c) continue;
        ov = atlas->corner_vertex[i];
        f = i / 3;
        if ((t = G->facepos[f]) != BP__NONE)
            for (k = 0; k < 3; k++) if (ch->triangles[3 * t + k] == ov) hit = 3 * t + k;
        if (hit == BP__NONE) hit = first[ov];
        p = X->pid[hit / 3];
        atlas->corner_chart[i] = p ? n0 + p - 1 : c;
        atlas->corner_vertex[i] = X->vid[bp__uf_find(X->cuf, hit)];
    }
    for (t = 0; t < nt; t++) G->facepos[ch->face[t]] = BP__NONE;
    for (ce = 0; ce < 3 * nt; ce++)
        seams += twin[ce] != BP__NONE && ce < twin[ce] && X->pid[ce / 3] != X->pid[twin[ce] / 3];
    for (p = 0; p < X->P; p++) {
        bp_chart *pc = &X->pc[p];
        pc->energy_start = ch->energy_start;
        pc->energy_end = ch->energy_end;
        pc->energy_max = ch->energy_max;
        pc->iterations = ch->iterations;
        pc->stop = ch->stop;
        pc->threads = ch->threads;
        pc->init_used = ch->init_used;
        bp__ok(&pc->error);
    }
    X->pc[0].cut_edges = ch->cut_edges + seams;
    X->pc[0].split_vertices = ch->split_vertices;
    memcpy(nch, atlas->charts, (size_t)n0 * sizeof(bp_chart));
    bp__chart_free(&a, &nch[c]);
    nch[c] = X->pc[0];
    for (p = 1; p < X->P; p++) nch[n0 + p - 1] = X->pc[p];
    bp__free(&a, X->pc);
    X->pc = NULL;
    bp__free(&a, atlas->charts);
    atlas->charts = nch;
    atlas->num_charts = n0 + X->P - 1;
    return 1;
}

/* Replace chart c by the connected pieces of its triangles under `label`
   (the essay above).  *pieces: how many charts it became (1: left whole).
   Fails only for out of memory. */
static bp_status bp__seg_split(bp_atlas *atlas, uint32_t c, const bp_mesh *m, const uint32_t *twin,
                               const uint32_t *label, bp__seg_mesh *G, uint32_t *pieces, bp_error *err)
{
    bp_allocator a = atlas->allocator;
    const bp_chart *ch = &atlas->charts[c];
    uint32_t nt = ch->num_triangles, nc = 3 * nt;
    bp__split X;
    bp_status st = BP_OK;
    *pieces = 1;
    memset(&X, 0, sizeof X);
    X.pid = (uint32_t *)bp__alloc_array(&a, nt, sizeof(uint32_t));
    X.lt = (uint32_t *)bp__alloc_array(&a, nt, sizeof(uint32_t));
    X.cuf = (uint32_t *)bp__alloc_array(&a, nc, sizeof(uint32_t));
    X.vid = (uint32_t *)bp__alloc_array(&a, nc, sizeof(uint32_t));
    X.next = (uint32_t *)bp__alloc_array(&a, (size_t)nc + 1, sizeof(uint32_t));
    X.loop_id = (uint32_t *)bp__alloc_array(&a, (size_t)nc + 1 > ch->num_vertices ? (size_t)nc + 1 : ch->num_vertices,
                                            sizeof(uint32_t));
    if (!X.pid || !X.lt || !X.cuf || !X.vid || !X.next || !X.loop_id) { bp__split_free(&a, &X); return bp__oom(err, "splitting a chart"); }
    bp__split_pieces(&X, ch, twin, label);
    if (X.P < 2) { bp__split_free(&a, &X); return BP_OK; }
    X.cnt = (uint32_t *)bp__alloc_array(&a, 2 * (size_t)X.P, sizeof(uint32_t));
    X.pc = (bp_chart *)bp__calloc_array(&a, X.P, sizeof(bp_chart));
    if (!X.cnt || !X.pc || !bp__split_fill(&a, &X, ch, m)) st = BP_ERR_OUT_OF_MEMORY;
    if (st == BP_OK) st = bp__split_verify(&a, &X, ch, m, twin, G, c);
    if (st == BP_OK) {
        uint32_t P = X.P;
        if (!bp__split_commit(atlas, c, &X, twin, G)) st = BP_ERR_OUT_OF_MEMORY;
        else *pieces = P;
    }
    bp__split_free(&a, &X);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "splitting a chart");
    return BP_OK;
}

/* Is segmentation on (bp_options.segment, the essay above)?  Never for
   charts started from the input uvs or pinned: those keep their charts. */
static int bp__seg_enabled(const bp_options *opt)
{
    if (!opt || opt->segment < 0 || opt->init == BP_INIT_INPUT || (opt->pins && opt->num_pins)) return 0;
    return opt->segment > 0 || opt->atlas_resolution > 0 || opt->max_distortion > 0 || opt->max_charts > 0;
}

static bp_status bp__seg_options(const bp_options *opt, bp_error *err)
{
    if (opt && (opt->max_distortion < 0 || opt->max_distortion != opt->max_distortion ||
                opt->segment < -1 || opt->segment > 1))
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "segmentation options out of range: max_distortion %g must be >= 0 (0: no bound) "
                        "and segment %d must be -1, 0 or 1", opt->max_distortion, opt->segment);
    return BP_OK;
}

static bp_status bp__seg_mesh_alloc(const bp_allocator *a, bp__seg_mesh *G, const bp_mesh *m, bp_error *err)
{
    uint32_t t;
    G->glued = (uint32_t *)bp__alloc_array(a, 3 * (size_t)m->num_triangles, sizeof(uint32_t));
    G->facepos = (uint32_t *)bp__alloc_array(a, m->num_triangles, sizeof(uint32_t));
    if (!G->glued || !G->facepos) {
        bp__free(a, G->glued); bp__free(a, G->facepos);
        return bp__oom(err, "segmenting charts");
    }
    for (t = 0; t < m->num_triangles; t++) G->facepos[t] = BP__NONE;
    return BP_OK;
}

/* Label chart c into at most kmax regions (mechanism (b), or the split in
   two of (a)) and split it; *pieces as bp__seg_split. */
static bp_status bp__seg_chart(bp_atlas *atlas, uint32_t c, const bp_mesh *m, const double *importance,
                               uint32_t kmax, double dev, uint32_t least, bp__seg_mesh *G, uint32_t *pieces,
                               bp_error *err)
{
    bp_allocator a = atlas->allocator;
    bp__seg S;
    bp_status st;
    uint32_t cap = kmax < atlas->charts[c].num_triangles ? kmax : atlas->charts[c].num_triangles;
    *pieces = 1;
    if (cap < 2) return BP_OK;
    if (!bp__seg_setup(&a, &S, &atlas->charts[c], m, importance, cap)) {
        bp__seg_free(&a, &S);
        return bp__oom(err, "segmenting charts");
    }
    if (dev < 0) bp__seg_label_two(&S);
    else bp__seg_label(&S, kmax, dev, least);
    st = S.K > 1 ? bp__seg_split(atlas, c, m, S.twin, S.label, G, pieces, err) : BP_OK;
    bp__seg_free(&a, &S);
    return st;
}

/* Mechanism (b): every chart that has no map yet and was built fine is
   grown into charts of bounded normal deviation, before the solve.  With
   opt.max_charts the extra charts are shared among the charts in
   proportion to their 3D area. */
BPDEF bp_status bp_atlas_segment(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status st;
    bp__seg_mesh G;
    uint32_t c, n0;
    double total = 0;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;
    if (!atlas || !atlas->charts || !m)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "bp_atlas_segment needs an atlas and its mesh");
    if ((st = bp__seg_options(opt, err)) != BP_OK) return st;
    n0 = atlas->num_charts;
    if (!bp__seg_enabled(opt) || !(opt->segment > 0 || opt->atlas_resolution > 0 || opt->max_charts > 0) ||
        (opt->max_charts && opt->max_charts <= n0))
        return bp__ok(err);       /* max_distortion alone: only (a), after the solve */
    if ((st = bp__seg_mesh_alloc(&atlas->allocator, &G, m, err)) != BP_OK) return st;
    for (c = 0; c < n0; c++) if (atlas->charts[c].error.status == BP_OK) total += atlas->charts[c].area3d;
    for (c = 0; c < n0 && st == BP_OK; c++) {
        const bp_chart *ch = &atlas->charts[c];
        uint32_t kmax = ch->num_triangles, pieces;
        if (ch->error.status != BP_OK || ch->uv) continue;
        if (opt->max_charts)      /* half the budget when (a) may need the rest */
            kmax = 1 + (uint32_t)((double)(opt->max_charts - n0) * (total > 0 ? ch->area3d / total : 0) *
                                  (opt->max_distortion > 0 ? 0.5 : 1));
        st = bp__seg_chart(atlas, c, m, opt->importance, kmax, BP__SEG_DEV, BP__SEG_LEAST, &G, &pieces, err);
    }
    bp__free(&atlas->allocator, G.glued);
    bp__free(&atlas->allocator, G.facepos);
    return st == BP_OK ? bp__ok(err) : st;
}

static bp_status bp__solve_charts(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err);

/* Start map and optimization of every chart, the charts in parallel when
   there are several (bp_parameterize's solve, >>driver). */
BPDEF bp_status bp_atlas_solve(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status st;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;
    if (!atlas || !atlas->charts || !m)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "bp_atlas_solve needs an atlas and its mesh");
    st = bp__solve_charts(atlas, m, opt, err);
    return st == BP_OK ? bp__charts_status(atlas, err) : st;
}

/* The pieces of one round of mechanism (a), optimized from their
   restricted maps: independent charts, solved in parallel. */
typedef struct bp__seg_job {
    bp_atlas *atlas;
    const bp_mesh *m;
    const bp_options *opt;
    const uint32_t *list;
    const bp__par *inner;
    bp_status *st;
    bp_error *errs;
} bp__seg_job;

static void bp__seg_task(void *task, uint32_t i)
{
    bp__seg_job *J = (bp__seg_job *)task;
    uint32_t c = J->list[i];
    J->st[i] = bp__chart_optimize(&J->atlas->charts[c], c, J->m, J->opt, J->inner, &J->errs[i]);
}

/* 1 when chart c has a map whose mean distortion is above the bound. */
static int bp__seg_too_high(const bp_atlas *atlas, uint32_t c, const bp_mesh *m, const bp_options *opt)
{
    const bp_chart *ch = &atlas->charts[c];
    double mean = 0;
    if (!ch->uv || ch->error.status != BP_OK || ch->num_triangles < 2) return 0;
    if (bp_chart_distortion(ch, m, opt->energy, &mean, NULL, NULL, NULL) != BP_OK) return 0;
    return !(mean <= opt->max_distortion);
}

static bp_status bp__seg_reoptimize(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, const uint32_t *list,
                                    uint32_t n, bp_error *err)
{
    bp_allocator a = atlas->allocator;
    bp__seg_job J;
    bp__par par, serial = bp__par_serial();
    void *pool = NULL;
    uint32_t i;
    bp_status st = BP_OK;
    J.atlas = atlas; J.m = m; J.opt = opt; J.list = list;
    J.st = (bp_status *)bp__alloc_array(&a, n, sizeof(bp_status));
    J.errs = (bp_error *)bp__calloc_array(&a, n, sizeof(bp_error));
    if (!J.st || !J.errs) { bp__free(&a, J.st); bp__free(&a, J.errs); return bp__oom(err, "optimizing split charts"); }
    par = bp__par_begin(&a, opt, &pool);
    if (n > 1 && par.threads != 1) { J.inner = &serial; par.run(par.user, bp__seg_task, &J, n); }
    else { J.inner = &par; bp__serial_for(NULL, bp__seg_task, &J, n); }
    bp__par_end(&a, pool);
    for (i = 0; i < n && st == BP_OK; i++)     /* a piece that cannot improve keeps its valid start */
        if (J.st[i] == BP_ERR_OUT_OF_MEMORY || J.st[i] == BP_ERR_CANCELLED) { st = J.st[i]; if (err) *err = J.errs[i]; }
    bp__free(&a, J.st);
    bp__free(&a, J.errs);
    return st;
}

/* Mechanism (a): rounds of splitting every chart above opt.max_distortion
   in two and optimizing the pieces again, until every chart meets the
   bound, the count reaches opt.max_charts, or no chart can be split.
   A cancel stops the rounds; every map stays valid. */
BPDEF bp_status bp_atlas_refine(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_options o_;
    bp_status st;
    bp__seg_mesh G;
    bp_allocator a;
    bp__vec list;                 /* uint32_t: the split charts and their pieces, in order */
    uint32_t round, nstuck = 0;
    unsigned char *stuck = NULL;
    memset(&list, 0, sizeof list);
    list.elem = sizeof(uint32_t);
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;
    if (!atlas || !atlas->charts || !m)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "bp_atlas_refine needs an atlas and its mesh");
    if ((st = bp__seg_options(opt, err)) != BP_OK) return st;
    if (!bp__seg_enabled(opt) || !(opt->max_distortion > 0) || opt->no_barrier || opt->init_only) return bp__ok(err);
    a = atlas->allocator;
    if ((st = bp__seg_mesh_alloc(&a, &G, m, err)) != BP_OK) return st;
    for (round = 0; round < 32 && st == BP_OK; round++) {
        uint32_t n0 = atlas->num_charts, c, budget = opt->max_charts ? opt->max_charts : BP__NONE;
        list.count = 0;
        {
            unsigned char *s2 = (unsigned char *)bp__calloc_array(&a, n0, 1);
            if (s2 && stuck) memcpy(s2, stuck, nstuck);     /* charts only ever get added */
            bp__free(&a, stuck);
            stuck = s2;
            nstuck = n0;
        }
        if (!stuck) { st = bp__oom(err, "splitting charts"); break; }
        for (c = 0; c < n0 && st == BP_OK && atlas->num_charts < budget; c++) {
            uint32_t pieces, p, before = atlas->num_charts;
            if (stuck[c] || !bp__seg_too_high(atlas, c, m, opt)) continue;
            st = bp__seg_chart(atlas, c, m, opt->importance, 2, -1, 2, &G, &pieces, err);
            if (pieces < 2) { stuck[c] = 1; continue; }
            /* c itself, then each of its new pieces (a split may give more than two) */
            for (p = before - 1; p < atlas->num_charts; p++) {
                uint32_t id = p == before - 1 ? c : p;
                if (!bp__vec_push(&a, &list, &id)) { st = bp__oom(err, "splitting charts"); break; }
            }
        }
        if (st != BP_OK || list.count == 0) break;
        st = bp__seg_reoptimize(atlas, m, opt, (const uint32_t *)list.data, (uint32_t)list.count, err);
        if (st == BP_ERR_CANCELLED) { st = BP_OK; break; }
    }
    bp__free(&a, list.data);
    bp__free(&a, stuck);
    bp__free(&a, G.glued);
    bp__free(&a, G.facepos);
    return st == BP_OK ? bp__ok(err) : st;
}


/* >>driver =================================================================

   bp_parameterize runs the whole pipeline: charts (bp_atlas_build), the
   start map of each chart (bp_chart_init), the optimization (bp_chart_optimize)
   and the packing (bp_atlas_pack), then one exact check of the whole atlas.
   Without opt->atlas_resolution the packing places the charts' bounding
   boxes on shelves (tallest first) with a gap, so no two charts can
   overlap (bp__pack_shelf below); with it, the charts' rasterized outlines
   go into a square texture (>>pack).  Charts with pins, and charts started
   from their input uvs, stay where they are (bp__pack_in_place).  A
   translation or scale rounds coordinates, which could in principle flip a
   triangle that is within rounding of degenerate; every moved chart is
   re-checked exactly and the move is retried with a slightly different
   offset if it ever fails. */

typedef struct bp__packbox { double w, h, ox, oy; uint32_t chart; } bp__packbox;

static int bp__packbox_cmp(const void *pa, const void *pb)
{
    const bp__packbox *a = (const bp__packbox *)pa, *b = (const bp__packbox *)pb;
    if (a->h != b->h) return a->h > b->h ? -1 : 1;
    return a->chart < b->chart ? -1 : a->chart > b->chart;
}

/* uv = s * (uv - lo) + off, checked exactly: the moved chart must be as
   valid as it was (bp__pack_check, bp__report_no_worse: a chart optimized
   without the barrier may overlap itself, and stays so); on failure
   restore and retry. */
static bp_status bp__move_chart(const bp_allocator *a, const bp__par *par, bp_chart *ch, const double *lo,
                                double s, double ox, double oy)
{
    double *save = (double *)bp__alloc_array(a, 2 * (size_t)ch->num_vertices, sizeof(double));
    uint32_t i;
    int attempt;
    bp_check_report before;
    bp_status st;
    if (!save) return BP_ERR_OUT_OF_MEMORY;
    memcpy(save, ch->uv, 2 * (size_t)ch->num_vertices * sizeof(double));
    if ((st = bp__pack_check(a, par, ch, ch->uv, &before)) != BP_OK) { bp__free(a, save); return st; }
    for (attempt = 0; attempt < 8; attempt++) {
        bp_check_report rep;
        double jig = attempt ? 1 + attempt * 1e-7 : 1;
        for (i = 0; i < ch->num_vertices; i++) {
            ch->uv[2 * i] = s * (save[2 * i] - lo[0]) + ox * jig;
            ch->uv[2 * i + 1] = s * (save[2 * i + 1] - lo[1]) + oy * jig;
        }
        if ((st = bp__pack_check(a, par, ch, ch->uv, &rep)) != BP_OK) { bp__free(a, save); return st; }
        if (bp__report_no_worse(&rep, &before)) {
            bp__free(a, save);
            return BP_OK;
        }
    }
    memcpy(ch->uv, save, 2 * (size_t)ch->num_vertices * sizeof(double));
    bp__free(a, save);
    return BP_ERR_NUMERICAL;
}

/* No fixed resolution: bounding boxes on shelves (the 0.1 packing). */
static bp_status bp__pack_shelf(bp_atlas *atlas, const bp_options *opt, const bp__par *par, bp_error *err)
{
    bp_allocator a;
    bp__packbox *bx;
    double *lo, area = 0, shelf_w, x = 0, y = 0, rowh = 0, gap = 0, W = 0, H = 0, s = 1;
    uint32_t c, i;
    bp_options o_;
    bp_status ost_;
    if ((opt = bp__opts(opt, &o_, err, &ost_)), ost_ != BP_OK) return ost_;   /* >>progress: */
    bp__report(opt, BP_STAGE_PACK, 0, BP_NO_CHART);      /* not interrupted: see there */
    if (!atlas || !atlas->charts)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "bp_atlas_pack needs an atlas");
    a = atlas->allocator;
    bx = (bp__packbox *)bp__alloc_array(&a, atlas->num_charts, sizeof *bx);
    lo = (double *)bp__alloc_array(&a, 2 * (size_t)atlas->num_charts, sizeof(double));
    if (!bx || !lo) { bp__free(&a, bx); bp__free(&a, lo); return bp__oom(err, "packing charts"); }
    for (c = 0; c < atlas->num_charts; c++) {
        bp_chart *ch = &atlas->charts[c];
        double mn[2] = { DBL_MAX, DBL_MAX }, mx[2] = { -DBL_MAX, -DBL_MAX };
        if (!ch->uv) { mn[0] = mn[1] = mx[0] = mx[1] = 0; }   /* no map: takes no room */
        for (i = 0; ch->uv && i < ch->num_vertices; i++) {
            int k;
            for (k = 0; k < 2; k++) {
                if (ch->uv[2 * i + k] < mn[k]) mn[k] = ch->uv[2 * i + k];
                if (ch->uv[2 * i + k] > mx[k]) mx[k] = ch->uv[2 * i + k];
            }
        }
        lo[2 * c] = mn[0]; lo[2 * c + 1] = mn[1];
        bx[c].w = mx[0] - mn[0]; bx[c].h = mx[1] - mn[1]; bx[c].chart = c;
        area += bx[c].w * bx[c].h;
        if (bx[c].w > gap) gap = bx[c].w;
        if (bx[c].h > gap) gap = bx[c].h;
    }
    gap *= 0.02;
    qsort(bx, atlas->num_charts, sizeof *bx, bp__packbox_cmp);
    shelf_w = sqrt(area) * 1.3;
    for (i = 0; i < atlas->num_charts; i++) if (bx[i].w > shelf_w) shelf_w = bx[i].w;
    /* shelf placement: offsets of each chart's lower-left corner */
    for (i = 0; i < atlas->num_charts; i++) {
        if (x > 0 && x + bx[i].w > shelf_w) { x = 0; y += rowh + gap; rowh = 0; }
        bx[i].ox = x;
        bx[i].oy = y;
        x += bx[i].w + gap;
        if (bx[i].h > rowh) rowh = bx[i].h;
        if (bx[i].ox + bx[i].w > W) W = bx[i].ox + bx[i].w;
        if (bx[i].oy + bx[i].h > H) H = bx[i].oy + bx[i].h;
    }
    if (opt && opt->normalize && W > 0 && H > 0) s = 1 / (W > H ? W : H);
    area = 0;
    for (i = 0; i < atlas->num_charts; i++) {
        c = bx[i].chart;
        if (!atlas->charts[c].uv) continue;
        bp_status ms = bp__move_chart(&a, par, &atlas->charts[c], lo + 2 * (size_t)c, s, s * bx[i].ox, s * bx[i].oy);
        if (ms != BP_OK) {
            bp__free(&a, bx); bp__free(&a, lo);
            if (ms == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "packing charts");
            return bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, c, -1, 0,
                            "chart %u: placing it in the atlas would break its validity in floating point", c);
        }
        area += bp__chart_uv_area(&atlas->charts[c]);
    }
    /* the square on the longer side, the one normalize scales to [0,1]^2 */
    W *= s; H *= s;
    atlas->utilization = W > 0 && H > 0 ? area / ((W > H ? W : H) * (W > H ? W : H)) : 0;
    bp__free(&a, bx);
    bp__free(&a, lo);
    bp__report(opt, BP_STAGE_PACK, 1, BP_NO_CHART);
    return bp__ok(err);
}

/* Every chart that has a map, by shelves or by outlines (atlas_resolution). */
static bp_status bp__pack_all(bp_atlas *atlas, const bp_options *opt, const bp__par *par, bp_error *err)
{
    atlas->utilization = 0;
    if (!opt || opt->atlas_resolution == 0) return bp__pack_shelf(atlas, opt, par, err);
    if (opt->atlas_resolution < 0 || opt->atlas_resolution > BP__PACK_MAX_RES)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "atlas resolution %d is out of range: it must be between 1 and %d texels",
                        opt->atlas_resolution, BP__PACK_MAX_RES);
    if (opt->padding < 0 || opt->padding >= opt->atlas_resolution)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "padding %d is out of range: it must be at least 0 and less than the resolution %d",
                        opt->padding, opt->atlas_resolution);
    return bp__pack_outlines(atlas, opt, par, err);
}

/* The last word before success: the whole atlas -- every mapped chart, in
   its packed place -- passes the exact check as one triangulation, which
   also proves that no two charts overlap.  This should never fail (every
   step was checked); if it does, the caller gets BP_ERR_NOT_BIJECTIVE, not
   a wrong map. */
static bp_status bp__atlas_verify(const bp_atlas *atlas, const bp__par *par, bp_error *err)
{
    bp_allocator a = atlas->allocator;
    uint32_t c, nt = 0, nv = 0, t, i, *tri, ov = 0, ot = 0;
    double *uv;
    bp_check_report rep;
    bp_error why;
    bp_status st;
    for (c = 0; c < atlas->num_charts; c++)
        if (atlas->charts[c].uv) { nt += atlas->charts[c].num_triangles; nv += atlas->charts[c].num_vertices; }
    if (!nt) return BP_OK;
    tri = (uint32_t *)bp__alloc_array(&a, 3 * (size_t)nt, sizeof(uint32_t));
    uv = (double *)bp__alloc_array(&a, 2 * (size_t)nv, sizeof(double));
    if (!tri || !uv) { bp__free(&a, tri); bp__free(&a, uv); return bp__oom(err, "verifying the atlas"); }
    for (c = 0; c < atlas->num_charts; c++) {
        const bp_chart *ch = &atlas->charts[c];
        if (!ch->uv) continue;
        for (t = 0; t < 3 * ch->num_triangles; t++) tri[3 * (size_t)ot + t] = ch->triangles[t] + ov;
        for (i = 0; i < 2 * ch->num_vertices; i++) uv[2 * (size_t)ov + i] = ch->uv[i];
        ot += ch->num_triangles;
        ov += ch->num_vertices;
    }
    st = bp__check_par(tri, nt, uv, nv, &a, par, &rep, &why);
    bp__free(&a, tri);
    bp__free(&a, uv);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(err, "verifying the atlas");
    if (!bp__check_verdict_status(st)) return bp__fail(err, st, BP_ELEMENT_NONE, -1, -1, 0, "verifying the atlas failed: %s", why.message);
    if (st != BP_OK)
        return bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_NONE, -1, -1, 0,
                        "the final atlas is not bijective (%u flipped, %u degenerate, %u boundary "
                        "intersections, %u loop-orientation and %u nesting problems; indices of the "
                        "concatenated charts: %s): this is a bug",
                        rep.flipped, rep.degenerate, rep.boundary_intersections, rep.loop_orientation, rep.nested,
                        why.message);
    return BP_OK;
}

/* Charts kept in place (>>pins): a chart with pins never moves; a chart
   whose start was its input uvs (BP_INIT_INPUT, chart.init_used = 1) keeps
   its placement unless normalize asks for packing -- and only when those
   charts do not overlap each other, which the exact check of the kept
   charts together decides (the input charts are then packed like the
   others).  The other charts are packed as usual and then translated, as
   one block, to the right of the kept charts' bounding box, so the kept
   and the packed never meet; bp_parameterize's final check proves it.
   Without the barrier nothing is verified (maps may overlap themselves). */
static bp_status bp__pack_kept_ok(bp_atlas *atlas, const int *keep, int barrier, const bp__par *par, bp_error *why)
{
    double **save;
    uint32_t c;
    bp_status st;
    if (!barrier) return BP_OK;
    save = (double **)bp__alloc_array(&atlas->allocator, atlas->num_charts, sizeof(double *));
    if (!save) return BP_ERR_OUT_OF_MEMORY;
    for (c = 0; c < atlas->num_charts; c++) { save[c] = atlas->charts[c].uv; if (!keep[c]) atlas->charts[c].uv = NULL; }
    st = bp__atlas_verify(atlas, par, why);
    for (c = 0; c < atlas->num_charts; c++) atlas->charts[c].uv = save[c];
    bp__free(&atlas->allocator, save);
    return st;
}

static bp_status bp__pack_in_place(bp_atlas *atlas, const bp_options *opt, const bp__par *par, bp_error *err)
{
    bp_allocator a = atlas->allocator;
    int *keep = (int *)bp__calloc_array(&a, atlas->num_charts ? atlas->num_charts : 1, sizeof(int));
    double **save = (double **)bp__alloc_array(&a, atlas->num_charts ? atlas->num_charts : 1, sizeof(double *));
    double kb[4] = { DBL_MAX, DBL_MAX, -DBL_MAX, -DBL_MAX }, pb[2] = { DBL_MAX, DBL_MAX }, gap;
    uint32_t c, i, nkeep = 0, npin = 0;
    int normalize = opt && (opt->normalize || opt->atlas_resolution), barrier = !(opt && opt->no_barrier);
    bp_error why;
    bp_status st = BP_OK;
    if (!keep || !save) { bp__free(&a, keep); bp__free(&a, save); return bp__oom(err, "packing charts"); }
    for (c = 0; c < atlas->num_charts; c++) {
        const bp_chart *ch = &atlas->charts[c];
        keep[c] = ch->uv && (ch->num_pins > 0 || (ch->init_used == 1 && !normalize));
        npin += ch->uv && ch->num_pins > 0;
    }
    if (npin && normalize)
        st = bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                      "normalize and atlas_resolution would move the pinned charts off their pins: "
                      "use pins without them");
    if (st == BP_OK && (st = bp__pack_kept_ok(atlas, keep, barrier, par, &why)) == BP_ERR_NOT_BIJECTIVE) {
        for (c = 0; c < atlas->num_charts; c++) keep[c] = keep[c] && atlas->charts[c].num_pins > 0;
        if ((st = bp__pack_kept_ok(atlas, keep, barrier, par, &why)) == BP_ERR_NOT_BIJECTIVE)
            st = bp__fail(err, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_NONE, -1, -1, 0,
                          "the pinned charts overlap each other at their targets (%s)", why.message);
    }
    if (st == BP_ERR_OUT_OF_MEMORY) st = bp__oom(err, "packing charts");
    else if (st != BP_OK && st != BP_ERR_INVALID_ARGUMENT && st != BP_ERR_NOT_BIJECTIVE) st = bp__fail(err, st, BP_ELEMENT_NONE, -1, -1, 0, "%s", why.message);
    for (c = 0; c < atlas->num_charts; c++) {
        bp_chart *ch = &atlas->charts[c];
        save[c] = ch->uv;
        ch->in_place = keep[c];
        nkeep += keep[c] != 0;
        for (i = 0; keep[c] && i < ch->num_vertices; i++) {
            double u = ch->uv[2 * (size_t)i], v = ch->uv[2 * (size_t)i + 1];
            if (u < kb[0]) kb[0] = u;
            if (v < kb[1]) kb[1] = v;
            if (u > kb[2]) kb[2] = u;
            if (v > kb[3]) kb[3] = v;
        }
        if (keep[c]) ch->uv = NULL;            /* hidden from the packer: takes no room */
    }
    if (st == BP_OK) st = bp__pack_all(atlas, opt, par, err);
    for (c = 0; c < atlas->num_charts; c++) if (keep[c]) atlas->charts[c].uv = save[c];
    if (st == BP_OK && nkeep) {
        gap = 0.02 * (kb[2] - kb[0] > kb[3] - kb[1] ? kb[2] - kb[0] : kb[3] - kb[1]);
        for (c = 0; c < atlas->num_charts; c++)
            for (i = 0; !keep[c] && atlas->charts[c].uv && i < atlas->charts[c].num_vertices; i++) {
                if (atlas->charts[c].uv[2 * (size_t)i] < pb[0]) pb[0] = atlas->charts[c].uv[2 * (size_t)i];
                if (atlas->charts[c].uv[2 * (size_t)i + 1] < pb[1]) pb[1] = atlas->charts[c].uv[2 * (size_t)i + 1];
            }
        for (c = 0; st == BP_OK && c < atlas->num_charts; c++) {
            double zero[2] = { 0, 0 };
            if (keep[c] || !atlas->charts[c].uv) continue;
            if (bp__move_chart(&a, par, &atlas->charts[c], zero, 1, kb[2] + gap - pb[0], kb[1] - pb[1]) != BP_OK)
                st = bp__fail(err, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, c, -1, 0,
                              "chart %u: placing it beside the charts kept in place would break its validity", c);
        }
    }
    bp__free(&a, keep);
    bp__free(&a, save);
    return st;
}

/* The packer's runner, for its exact checks (four per chart in the tool:
   two here): a pool from opt when the charts with a map have
   BP__PAR_MIN_TRIANGLES triangles or more together (*pool: to stop
   later), else serial, as for a chart's own loops (>>threads). */
static bp__par bp__pack_par(const bp_atlas *atlas, const bp_options *opt, void **pool)
{
    uint32_t c, nt = 0;
    *pool = NULL;
    for (c = 0; c < atlas->num_charts; c++)
        if (atlas->charts[c].uv) nt += atlas->charts[c].num_triangles;
    if (nt < BP__PAR_MIN_TRIANGLES) return bp__par_serial();
    return bp__par_begin(&atlas->allocator, opt, pool);
}

/* Place the charts side by side without overlap, leaving pinned charts
   (and, without normalize, charts started from their input uvs) where
   they are: see bp__pack_in_place. */
BPDEF bp_status bp_atlas_pack(bp_atlas *atlas, const bp_options *opt, bp_error *err)
{
    void *pool;
    bp__par par;
    bp_status st;
    if (!atlas || !atlas->charts)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "bp_atlas_pack needs an atlas");
    par = bp__pack_par(atlas, opt, &pool);
    st = bp__pack_in_place(atlas, opt, &par, err);
    bp__par_end(&atlas->allocator, pool);
    return st;
}

BPDEF void bp_atlas_fail_chart(bp_atlas *atlas, uint32_t chart, const bp_error *why)
{
    bp_chart *ch;
    if (!atlas || chart >= atlas->num_charts) return;
    ch = &atlas->charts[chart];
    if (ch->error.status == BP_OK) atlas->num_failed++;
    if (why && why->status != BP_OK) ch->error = *why;
    else bp__fail(&ch->error, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_CHART, chart, -1, 0, "chart %u: failed", chart);
    bp__free(&atlas->allocator, ch->uv);
    ch->uv = NULL;
}

/* --repack: a chart's map is the file's own (vt) texture coordinates, taken
   only when they are exactly bijective (the same check as every result). */
static bp_status bp__input_map(bp_atlas *atlas, uint32_t c, const bp_mesh *m, bp_error *why)
{
    bp_allocator a = atlas->allocator;
    bp_chart *ch = &atlas->charts[c];
    bp__par serial = bp__par_serial();
    bp_check_report rep;
    bp_status st;
    uint32_t i;
    for (i = 0; i < ch->num_vertices; i++)
        if (!ch->vertex_uv || ch->vertex_uv[i] >= m->num_uvs)
            return bp__fail(why, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_VERTEX, ch->vertex[i], -1, 0,
                            "chart %u: vertex %u has no texture coordinate to repack", c, ch->vertex[i] + 1);
    bp__free(&a, ch->uv);
    ch->uv = (double *)bp__alloc_array(&a, 2 * (size_t)ch->num_vertices, sizeof(double));
    if (!ch->uv) return bp__oom(why, "repacking charts");
    for (i = 0; i < ch->num_vertices; i++) {
        ch->uv[2 * i] = m->uvs[2 * (size_t)ch->vertex_uv[i]];
        ch->uv[2 * i + 1] = m->uvs[2 * (size_t)ch->vertex_uv[i] + 1];
    }
    st = bp__pack_check(&a, &serial, ch, ch->uv, &rep);
    if (st == BP_ERR_OUT_OF_MEMORY) return bp__oom(why, "repacking charts");
    if (st == BP_OK && bp__report_valid(&rep)) return BP_OK;
    if (rep.first_bad_triangle >= 0) {
        uint32_t f = ch->face[rep.first_bad_triangle];
        if (m->triangle_line)
            return bp__fail(why, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_TRIANGLE, f, -1, m->triangle_line[f],
                            "chart %u: its input texture coordinates are not bijective (%u flipped, %u degenerate, "
                            "%u non-finite triangles; the first is triangle %u (line %u))", c, rep.flipped,
                            rep.degenerate, rep.nonfinite, f + 1, m->triangle_line[f]);
        return bp__fail(why, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_TRIANGLE, f, -1, 0,
                        "chart %u: its input texture coordinates are not bijective (%u flipped, %u degenerate, "
                        "%u non-finite triangles; the first is triangle %u)", c, rep.flipped, rep.degenerate,
                        rep.nonfinite, f + 1);
    }
    if (rep.first_bad_edge[0] >= 0)
        return bp__fail(why, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_VERTEX, ch->vertex[rep.first_bad_edge[0]], -1, 0,
                        "chart %u: its input texture coordinates overlap themselves (%u pairs of boundary edges "
                        "meet; the first at vertex %u)", c, rep.boundary_intersections,
                        ch->vertex[rep.first_bad_edge[0]] + 1);
    return bp__fail(why, BP_ERR_NOT_BIJECTIVE, BP_ELEMENT_CHART, c, -1, 0,
                    "chart %u: its input texture coordinates are not bijective (%u loop-orientation and %u "
                    "nesting problems)", c, rep.loop_orientation, rep.nested);
}

BPDEF bp_status bp_atlas_use_input_uvs(bp_atlas *atlas, const bp_mesh *m, bp_error *err)
{
    uint32_t c;
    if (!atlas || !atlas->charts || !m)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_atlas_use_input_uvs needs an atlas and its mesh");
    if (!m->corner_uv || !m->uvs)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "the mesh has no texture coordinates to repack");
    for (c = 0; c < atlas->num_charts; c++) {
        bp_error why;
        bp_status st;
        if (atlas->charts[c].error.status != BP_OK) continue;
        st = bp__input_map(atlas, c, m, &why);
        if (st == BP_ERR_OUT_OF_MEMORY) { if (err) *err = why; return st; }
        if (st != BP_OK) bp_atlas_fail_chart(atlas, c, &why);
    }
    return atlas->num_failed ? bp__charts_status(atlas, err) : bp__ok(err);
}

/* One chart, start map and optimization: the unit of work when charts are
   solved in parallel. */
typedef struct bp__chart_job {
    bp_atlas *atlas;
    const bp_mesh *m;
    const bp_options *opt;
    const bp__par *inner;         /* how a large chart's own loops run      */
    bp_status *status;
    bp_error *errs;
    bp__run *run;                 /* bp_parameterize's run, or NULL (>>progress) */
} bp__chart_job;

static void bp__chart_task(void *task, uint32_t c)
{
    bp__chart_job *J = (bp__chart_job *)task;
    bp__par serial = bp__par_serial();
    const bp__par *inner = J->atlas->charts[c].num_triangles >= BP__PAR_MIN_TRIANGLES ? J->inner : &serial;
    bp_allocator a = bp__allocator_of(J->opt);
    bp__handoff h;                                    /* start -> Newton, at once */
    bp_status st;
    memset(&h, 0, sizeof h);
    if (J->atlas->charts[c].error.status != BP_OK) {   /* failed in bp_atlas_build */
        J->status[c] = BP_OK;
        return;
    }
    if (bp__report(J->opt, BP_STAGE_START, 0, c))     /* cancelled: no map (>>progress) */
        st = bp__fail(&J->errs[c], BP_ERR_CANCELLED, BP_ELEMENT_CHART, c, -1, 0,
                      "chart %u: cancelled before its start map", c);
    else
        st = bp__chart_init(&J->atlas->charts[c], J->m, J->opt, inner, &h, &J->errs[c]);
    if (st == BP_OK && bp__report(J->opt, BP_STAGE_START, 1, c)) {   /* keeps its start map */
        J->atlas->charts[c].stop = BP_STOP_CANCELLED;
        st = bp__fail(&J->errs[c], BP_ERR_CANCELLED, BP_ELEMENT_CHART, c, -1, 0,
                      "chart %u: cancelled after its start map (the map is the valid start map)", c);
    }
    if (st == BP_OK && !(J->opt && J->opt->init_only))
        st = bp__chart_optimize_pen(&J->atlas->charts[c], c, J->m, J->opt, inner, NULL, &h, &J->errs[c]);
    bp__handoff_free(&a, &h);
    if (J->run) BP__COUNT_ADD(&J->run->done, (uint64_t)J->atlas->charts[c].num_triangles);
    J->status[c] = st;
}

/* Every chart's state after the solve is one of two: a valid map, or a
   reported failure (chart.error set, uv NULL).  So every chart is visited,
   also after a cancelled one: a chart that failed loses its map
   (bp_atlas_fail_chart), a cancelled chart keeps its last valid map.  Out
   of memory, and in strict mode any failure, end the call (returned with
   err).  Otherwise the result is BP_OK or BP_ERR_CANCELLED (err: the first
   cancelled chart). */
static bp_status bp__collect(bp_atlas *atlas, const bp__chart_job *J, int strict, bp_error *err)
{
    bp_status st = BP_OK;
    uint32_t c;
    for (c = 0; c < atlas->num_charts; c++) {
        bp_status cs = J->status[c];
        if (cs == BP_OK) continue;
        if (cs == BP_ERR_OUT_OF_MEMORY || (strict && cs != BP_ERR_CANCELLED)) {
            if (err) *err = J->errs[c];
            return cs;
        }
        /* a chart cancelled before its start map has none: reported failed */
        if (cs != BP_ERR_CANCELLED || !atlas->charts[c].uv) bp_atlas_fail_chart(atlas, c, &J->errs[c]);
        if (cs == BP_ERR_CANCELLED && st == BP_OK) {
            st = cs;
            if (err) *err = J->errs[c];
        }
    }
    return st;
}

/* Start map and optimization of every chart.  Charts are independent, so
   with several threads and no dominant chart (none holds more than half of
   the triangles) the charts themselves are the parallel tasks, each solved
   with serial loops; otherwise the charts go one after the other and the
   loops of the large ones (see >>threads) run in parallel.  Either way each
   chart's result is bit-identical to a serial solve.  One pool serves the
   whole call, and none is started when neither way would use it (one small
   chart).  Returns as bp__collect. */
static bp_status bp__solve_charts(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_allocator a = atlas->allocator;
    bp__par par, serial;
    bp__chart_job J;
    void *pool = NULL;
    uint32_t c, largest = 0;
    int by_chart;
    bp_status st;
    bp_options linked;
    bp__iter_link L;
    J.run = bp__run_of(opt);                                 /* >>progress */
    opt = bp__with_iter_link(opt, &linked, &L);
    J.status = (bp_status *)bp__alloc_array(&a, atlas->num_charts, sizeof(bp_status));
    J.errs = (bp_error *)bp__calloc_array(&a, atlas->num_charts, sizeof(bp_error));
    if (!J.status || !J.errs) {
        bp__free(&a, J.status); bp__free(&a, J.errs);
        return bp__oom(err, "starting the solve");
    }
    J.atlas = atlas;
    J.m = m;
    J.opt = opt;
    serial = bp__par_serial();
    for (c = 0; c < atlas->num_charts; c++)
        if (atlas->charts[c].num_triangles > largest) largest = atlas->charts[c].num_triangles;
    by_chart = atlas->num_charts > 1 && 2 * (uint64_t)largest <= m->num_triangles;
    par = by_chart || largest >= BP__PAR_MIN_TRIANGLES ? bp__par_begin(&a, opt, &pool) : serial;
    if (par.threads != 1 && by_chart) {
        J.inner = &serial;
        par.run(par.user, bp__chart_task, &J, atlas->num_charts);
        for (c = 0; c < atlas->num_charts; c++) atlas->charts[c].threads = par.threads;
    } else {
        J.inner = &par;
        bp__serial_for(NULL, bp__chart_task, &J, atlas->num_charts);
    }
    bp__par_end(&a, pool);
    st = bp__collect(atlas, &J, opt && opt->strict, err);
    bp__free(&a, J.status);
    bp__free(&a, J.errs);
    return st;
}

/* Extreme scales.  The map is scale-invariant, but the arithmetic is not:
   rest shapes and energies multiply squared lengths, which overflow above
   ~1e77 and underflow below ~1e-77.  When the mesh's size (bp__mesh_scale:
   about 2^(e1+e2)) is beyond 2^+-100, bp_parameterize solves a copy
   rescaled by the power of two 2^k that brings its size near 1 -- exact,
   so the copy is the same shape -- and scales the map back by 2^-k
   (unless normalize or atlas_resolution put it into [0,1]^2).  That
   is exact too unless a coordinate leaves the normal range (underflow
   near 1e-308, overflow near 1e308); then the chart fails with
   BP_ERR_NUMERICAL instead of carrying a map that is not the solved one.
   Meshes of ordinary size are solved as given, bit for bit. */
static bp_status bp__rescaled_mesh(const bp_allocator *a, const bp_mesh *m, bp_mesh *ms, int *k, bp_error *err)
{
    bp__mesh_scale sc;
    size_t i;
    bp_status st = bp__validate_global(m, &sc, err);
    *k = 0;
    if (st != BP_OK) return st;
    *ms = *m;
    if (sc.e1 + sc.e2 >= -100 && sc.e1 + sc.e2 <= 100) return BP_OK;
    *k = -(sc.e1 + sc.e2);
    ms->positions = (double *)bp__alloc_array(a, 3 * (size_t)m->num_vertices, sizeof(double));
    if (!ms->positions) return bp__oom(err, "rescaling the mesh");
    for (i = 0; i < 3 * (size_t)m->num_vertices; i++) ms->positions[i] = ldexp(m->positions[i], *k);
    return BP_OK;
}

/* The user's uv-space inputs follow the rescaled copy: pin targets and
   input uvs are scaled by 2^k too (exact in the normal range), so they come
   back bit for bit with the map. */
static bp_status bp__rescale_controls(const bp_allocator *a, bp_options *o, bp_mesh *ms, int k, bp_pin **pins,
                                      double **uvs, bp_error *err)
{
    size_t i;
    if (o->num_pins && o->pins) {
        *pins = (bp_pin *)bp__alloc_array(a, o->num_pins, sizeof(bp_pin));
        if (!*pins) return bp__oom(err, "rescaling the pins");
        for (i = 0; i < o->num_pins; i++) {
            (*pins)[i] = o->pins[i];
            (*pins)[i].u = ldexp(o->pins[i].u, k);
            (*pins)[i].v = ldexp(o->pins[i].v, k);
        }
        o->pins = *pins;
    }
    if (o->init == BP_INIT_INPUT && ms->uvs && ms->num_uvs) {
        *uvs = (double *)bp__alloc_array(a, 2 * (size_t)ms->num_uvs, sizeof(double));
        if (!*uvs) return bp__oom(err, "rescaling the input uvs");
        for (i = 0; i < 2 * (size_t)ms->num_uvs; i++) (*uvs)[i] = ldexp(ms->uvs[i], k);
        ms->uvs = *uvs;
    }
    return BP_OK;
}

/* The map of the rescaled copy, back in the mesh's units (see above). */
static void bp__unscale_atlas(bp_atlas *atlas, int k, int normalized)
{
    uint32_t c, i;
    for (c = 0; c < atlas->num_charts; c++) {
        bp_chart *ch = &atlas->charts[c];
        int exact = 1;
        ch->area3d = ldexp(ch->area3d, -2 * k);
        if (ch->rest_side)                       /* repaired degenerate triangles */
            for (i = 0; i < ch->num_triangles; i++) ch->rest_side[i] = ldexp(ch->rest_side[i], -k);
        if (!ch->uv || normalized) continue;     /* [0,1]^2 is its own scale */
        for (i = 0; i < 2 * ch->num_vertices && exact; i++)
            exact = ldexp(ldexp(ch->uv[i], -k), k) == ch->uv[i];
        if (exact) {
            for (i = 0; i < 2 * ch->num_vertices; i++) ch->uv[i] = ldexp(ch->uv[i], -k);
        } else {
            bp_error why;
            bp__fail(&why, BP_ERR_NUMERICAL, BP_ELEMENT_CHART, c, -1, 0,
                     "chart %u: its map was solved on the mesh rescaled by 2^%d, but a coordinate underflows "
                     "or overflows when scaled back to the mesh's size: use normalize, or rescale the mesh",
                     c, k);
            bp_atlas_fail_chart(atlas, c, &why);
        }
    }
}

/* The whole pipeline.  Its failure rule (CONVENTIONS): BP_ERR_CHARTS_FAILED
   and BP_ERR_CANCELLED keep the atlas -- every chart a valid map or a
   reported failure, packed and verified -- and any other error frees it. */
BPDEF bp_status bp_parameterize(bp_atlas *atlas, const bp_mesh *m, const bp_options *opt, bp_error *err)
{
    bp_status st;
    bp_allocator a;
    bp_options local;
    bp_mesh ms;
    bp_error cancel;
    bp__run run;
    double *imp = NULL, *uvs_k = NULL;
    bp_pin *pins_k = NULL;
    int k = 0;
    uint32_t t;
    if ((opt = bp__opts(opt, &local, err, &st)), st != BP_OK) return st;   /* >>progress */
    a = bp__allocator_of(opt);
    if (!atlas) return bp_atlas_build(atlas, m, opt, err);
    memset(atlas, 0, sizeof *atlas);
    if ((st = bp__rescaled_mesh(&a, m, &ms, &k, err)) != BP_OK) return st;
    if (!opt) memset(&local, 0, sizeof local);
    memset(&run, 0, sizeof run);
    if (local.run_progress) {        /* one flag for the whole run (>>progress) */
        run.fn = local.run_progress;
        run.user = local.run_progress_user;
        run.total = m->num_triangles;
        local.run_progress = bp__run_forward;
        local.run_progress_user = &run;
    }
    if (k) local.epsilon = ldexp(local.epsilon, k);     /* a barrier width is a length */
    if (k) st = bp__rescale_controls(&a, &local, &ms, k, &pins_k, &uvs_k, err);   /* pins, input uvs */
    if (st == BP_OK && local.views.model != BP_VIEW_NONE && !local.init_only) {
        /* chapter 4: visibility (times the user's importance) drives eq 4.1,
           and automatic seams (>>cut) prefer the parts seen least */
        imp = (double *)bp__alloc_array(&a, m->num_triangles, sizeof(double));
        st = imp ? bp_visibility(&ms, &local, imp, err) : bp__oom(err, "computing visibility");
        if (st == BP_ERR_CANCELLED) {            /* bp_atlas_build sees the run's flag: no charts */
            st = BP_OK;
            bp__free(&a, imp);
            imp = NULL;
        }
        if (st == BP_OK && imp && local.importance)
            for (t = 0; t < m->num_triangles; t++) imp[t] *= local.importance[t];
        if (imp) local.importance = imp;
    }
    if (st == BP_OK) st = bp_atlas_build(atlas, &ms, &local, err);
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) {           /* >>segment: (b) */
        bp_status ss = bp_atlas_segment(atlas, &ms, &local, err);
        if (ss != BP_OK) st = ss;
    }
    if (st == BP_OK || st == BP_ERR_CHARTS_FAILED) {
        st = bp__solve_charts(atlas, &ms, &local, &cancel);
        if (st == BP_OK) st = bp_atlas_refine(atlas, &ms, &local, &cancel);   /* >>segment: (a) */
        if (st != BP_OK && st != BP_ERR_CANCELLED && err) *err = cancel;
    }
    if (st == BP_OK || (st == BP_ERR_CANCELLED && atlas->charts)) {   /* a cancel in bp_atlas_build: no charts */
        void *pool = NULL;
        bp__par par = atlas->charts ? bp__pack_par(atlas, &local, &pool) : bp__par_serial();
        bp_status ps = atlas->charts ? bp__pack_in_place(atlas, &local, &par, err) : bp_atlas_pack(atlas, &local, err);
        if (ps == BP_OK && !local.no_barrier) ps = bp__atlas_verify(atlas, &par, err);
        bp__par_end(&atlas->allocator, pool);
        if (ps == BP_OK && k) bp__unscale_atlas(atlas, k, local.normalize || local.atlas_resolution);
        if (ps != BP_OK) st = ps;
        else if (st == BP_ERR_CANCELLED) { if (err) *err = cancel; }
        else if (run.fn && BP__FLAG_LOAD(&run.cancelled))   /* asked during the packing */
            st = bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0,
                          "cancelled; every chart was solved, packed and verified first");
        else st = bp__charts_status(atlas, err);
    }
    bp__free(&a, imp);
    bp__free(&a, pins_k);
    bp__free(&a, uvs_k);
    if (k) bp__free(&a, ms.positions);
    if (st != BP_OK && st != BP_ERR_CHARTS_FAILED && st != BP_ERR_CANCELLED) bp_atlas_free(atlas);
    return st;
}

/* >>bvh ====================================================================

   Chapter 4 needs occlusion queries: is the segment from a surface point
   toward a camera at infinity blocked by the mesh?  A bounding volume
   hierarchy answers them in logarithmic time.

   Build: top-down with the surface area heuristic over 16 bins of triangle
   centroids along the widest axis.  A split costs
       C = 1 + (A_left N_left + A_right N_right) / A_node
   (A: box surface area, N: triangles), a leaf costs N; the cheaper wins,
   and leaves hold at most 16 triangles.  Nodes live in one flat array; an
   inner node's children are stored next to each other.

   Ray/triangle: the watertight test of Woop, Benthin and Wald (2013).  The
   ray is made the +z axis of a sheared frame, every vertex is transformed
   the same way, and the three 2D edge functions decide containment.  An
   edge shared by two triangles produces the same products in both (with
   opposite sign), so a ray through an edge or a vertex cannot slip between
   neighbours; the box test widens each slab's exit by its rounding bound so
   that the traversal cannot lose them either.  Traversal is iterative with
   a fixed stack. */

typedef struct bp__bvh_node {
    double   lo[3], hi[3];
    uint32_t first;           /* leaf: first entry in tri[]; inner: left child */
    uint32_t count;           /* leaf: triangles; inner: 0                   */
} bp__bvh_node;

typedef struct bp__bvh {
    bp__bvh_node *nodes;
    uint32_t      num_nodes;
    uint32_t     *tri;        /* triangle order of the leaves                */
    const double *pos;
    const uint32_t *tris;
} bp__bvh;

static void bp__bvh_free(const bp_allocator *a, bp__bvh *B)
{
    bp__free(a, B->nodes);
    bp__free(a, B->tri);
    memset(B, 0, sizeof *B);
}

static double bp__box_area(const double *lo, const double *hi)
{
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    if (dx < 0) return 0;
    return 2 * (dx * dy + dy * dz + dz * dx);
}

static void bp__box_grow(double *lo, double *hi, const double *p)
{
    int k;
    for (k = 0; k < 3; k++) {
        if (p[k] < lo[k]) lo[k] = p[k];
        if (p[k] > hi[k]) hi[k] = p[k];
    }
}

static bp_status bp__bvh_build(const bp_allocator *a, bp__bvh *B, const bp_mesh *m)
{
    uint32_t nt = m->num_triangles, i, sp = 0;
    double *cen = (double *)bp__alloc_array(a, 3 * (size_t)nt, sizeof(double));
    uint32_t *stack = (uint32_t *)bp__alloc_array(a, 3 * 128, sizeof(uint32_t));
    memset(B, 0, sizeof *B);
    B->pos = m->positions;
    B->tris = m->triangles;
    B->nodes = (bp__bvh_node *)bp__alloc_array(a, 2 * (size_t)nt, sizeof(bp__bvh_node));
    B->tri = (uint32_t *)bp__alloc_array(a, nt, sizeof(uint32_t));
    if (!cen || !stack || !B->nodes || !B->tri) {
        bp__free(a, cen); bp__free(a, stack); bp__bvh_free(a, B);
        return BP_ERR_OUT_OF_MEMORY;
    }
    for (i = 0; i < nt; i++) {
        int k;
        B->tri[i] = i;
        for (k = 0; k < 3; k++)
            cen[3 * (size_t)i + k] = (bp__pos(m, m->triangles[3 * (size_t)i])[k] + bp__pos(m, m->triangles[3 * (size_t)i + 1])[k] +
                                      bp__pos(m, m->triangles[3 * (size_t)i + 2])[k]) / 3;
    }
    B->num_nodes = 1;
    stack[sp++] = 0; stack[sp++] = 0; stack[sp++] = nt;
    while (sp) {
        uint32_t end = stack[--sp], begin = stack[--sp], node = stack[--sp], n = end - begin, j;
        bp__bvh_node *N = &B->nodes[node];
        double clo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, chi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
        double best = HUGE_VAL, ext;
        int axis = 0, k, best_split = -1;
        uint32_t mid;
        for (k = 0; k < 3; k++) { N->lo[k] = DBL_MAX; N->hi[k] = -DBL_MAX; }
        for (i = begin; i < end; i++) {
            const uint32_t *t = m->triangles + 3 * (size_t)B->tri[i];
            for (k = 0; k < 3; k++) bp__box_grow(N->lo, N->hi, bp__pos(m, t[k]));
            bp__box_grow(clo, chi, cen + 3 * (size_t)B->tri[i]);
        }
        N->first = begin;
        N->count = n;
        if (n <= 2 || sp + 6 > 3 * 128) continue;
        for (k = 1; k < 3; k++) if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
        ext = chi[axis] - clo[axis];
        if (ext > 0) {
            /* binned SAH */
            uint32_t cnt[16] = { 0 };
            double blo[16][3], bhi[16][3], llo[3], lhi[3], larea[16];
            uint32_t lcnt[16];
            for (j = 0; j < 16; j++)
                for (k = 0; k < 3; k++) { blo[j][k] = DBL_MAX; bhi[j][k] = -DBL_MAX; }
            for (i = begin; i < end; i++) {
                const uint32_t *t = m->triangles + 3 * (size_t)B->tri[i];
                int b = (int)(16 * (cen[3 * (size_t)B->tri[i] + axis] - clo[axis]) / ext);
                if (b > 15) b = 15;
                cnt[b]++;
                for (k = 0; k < 3; k++) bp__box_grow(blo[b], bhi[b], bp__pos(m, t[k]));
            }
            for (k = 0; k < 3; k++) { llo[k] = DBL_MAX; lhi[k] = -DBL_MAX; }
            for (j = 0; j < 15; j++) {               /* sweep from the left */
                bp__box_grow(llo, lhi, blo[j]); if (cnt[j]) bp__box_grow(llo, lhi, bhi[j]);
                lcnt[j] = (j ? lcnt[j - 1] : 0) + cnt[j];
                larea[j] = lcnt[j] ? bp__box_area(llo, lhi) : 0;
            }
            for (k = 0; k < 3; k++) { llo[k] = DBL_MAX; lhi[k] = -DBL_MAX; }
            {
                uint32_t rc = 0;
                double area = bp__box_area(N->lo, N->hi);
                for (j = 15; j > 0; j--) {           /* sweep from the right */
                    double cost;
                    if (cnt[j]) { bp__box_grow(llo, lhi, blo[j]); bp__box_grow(llo, lhi, bhi[j]); }
                    rc += cnt[j];
                    if (!lcnt[j - 1] || !rc) continue;
                    cost = 1 + (larea[j - 1] * lcnt[j - 1] + bp__box_area(llo, lhi) * rc) / (area > 0 ? area : 1);
                    if (cost < best) { best = cost; best_split = (int)j; }
                }
            }
        }
        if (best_split < 0 || (best >= n && n <= 16)) {
            if (n <= 16) continue;             /* leaf */
            best_split = -1;                   /* fall back to a median split */
        }
        /* partition the range */
        if (best_split >= 0) {
            uint32_t lo_i = begin, hi_i = end;
            while (lo_i < hi_i) {
                int b = (int)(16 * (cen[3 * (size_t)B->tri[lo_i] + axis] - clo[axis]) / ext);
                if (b > 15) b = 15;
                if (b < best_split) lo_i++;
                else { uint32_t tmp = B->tri[lo_i]; B->tri[lo_i] = B->tri[--hi_i]; B->tri[hi_i] = tmp; }
            }
            mid = lo_i;
        } else {
            mid = begin + n / 2;
        }
        if (mid == begin || mid == end) mid = begin + n / 2;
        N->first = B->num_nodes;
        N->count = 0;
        B->num_nodes += 2;
        stack[sp++] = N->first; stack[sp++] = begin; stack[sp++] = mid;
        stack[sp++] = N->first + 1; stack[sp++] = mid; stack[sp++] = end;
    }
    bp__free(a, cen);
    bp__free(a, stack);
    return BP_OK;
}

/* Watertight ray/triangle: a hit with t in (tmin, tmax)? */
static int bp__ray_triangle(const double *o, const double *d, const double *v0, const double *v1,
                            const double *v2, double tmin, double tmax)
{
    int kz = 0, kx, ky, k;
    double Sx, Sy, Sz, A[3], Bv[3], C[3], Ax, Ay, Bx, By, Cx, Cy, U, V, W, det, T;
    for (k = 1; k < 3; k++) if (fabs(d[k]) > fabs(d[kz])) kz = k;
    kx = (kz + 1) % 3;
    ky = (kx + 1) % 3;
    if (d[kz] < 0) { int t = kx; kx = ky; ky = t; }   /* keep the winding */
    Sx = d[kx] / d[kz]; Sy = d[ky] / d[kz]; Sz = 1 / d[kz];
    for (k = 0; k < 3; k++) { A[k] = v0[k] - o[k]; Bv[k] = v1[k] - o[k]; C[k] = v2[k] - o[k]; }
    Ax = A[kx] - Sx * A[kz]; Ay = A[ky] - Sy * A[kz];
    Bx = Bv[kx] - Sx * Bv[kz]; By = Bv[ky] - Sy * Bv[kz];
    Cx = C[kx] - Sx * C[kz]; Cy = C[ky] - Sy * C[kz];
    U = Cx * By - Cy * Bx;
    V = Ax * Cy - Ay * Cx;
    W = Bx * Ay - By * Ax;
    if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return 0;
    det = U + V + W;
    if (det == 0) return 0;
    T = U * (Sz * A[kz]) + V * (Sz * Bv[kz]) + W * (Sz * C[kz]);
    if (det > 0) return T > tmin * det && T < tmax * det;
    return T < tmin * det && T > tmax * det;
}

/* Slab test of a box against the ray segment (tmin, tmax). */
static int bp__ray_box(const double *o, const double *d, const double *inv, const double *lo,
                       const double *hi, double tmin, double tmax)
{
    int k;
    for (k = 0; k < 3; k++) {
        double t0, t1;
        if (d[k] == 0) {                       /* parallel to the slab */
            if (o[k] < lo[k] || o[k] > hi[k]) return 0;
            continue;
        }
        t0 = (lo[k] - o[k]) * inv[k];
        t1 = (hi[k] - o[k]) * inv[k];
        if (t0 > t1) { double t = t0; t0 = t1; t1 = t; }
        /* Rounding can make a ray through a box corner exit one slab an
           ulp before it enters the next, and lose the node: widen the exit
           by the bound on the rounding of the two operations above (Ize,
           "Robust BVH ray traversal", 2013: 2 gamma_3). */
        t1 += fabs(t1) * 2 * (3 * (DBL_EPSILON / 2) / (1 - 3 * (DBL_EPSILON / 2)));
        if (t0 > tmin) tmin = t0;
        if (t1 < tmax) tmax = t1;
        if (tmin > tmax) return 0;
    }
    return 1;
}

/* Any hit on the ray o + t d, t in (tmin, tmax), other than triangle `skip`. */
static int bp__bvh_occluded(const bp__bvh *B, const double *o, const double *d, double tmin, double tmax,
                            uint32_t skip)
{
    uint32_t stack[128], sp = 0, i;
    double inv[3];
    int k;
    for (k = 0; k < 3; k++) inv[k] = d[k] != 0 ? 1 / d[k] : 0;
    stack[sp++] = 0;
    while (sp) {
        const bp__bvh_node *N = &B->nodes[stack[--sp]];
        if (!bp__ray_box(o, d, inv, N->lo, N->hi, tmin, tmax)) continue;
        if (N->count) {
            for (i = N->first; i < N->first + N->count; i++) {
                uint32_t t = B->tri[i];
                const uint32_t *tv = B->tris + 3 * (size_t)t;
                if (t == skip) continue;
                if (bp__ray_triangle(o, d, B->pos + 3 * (size_t)tv[0], B->pos + 3 * (size_t)tv[1],
                                     B->pos + 3 * (size_t)tv[2], tmin, tmax))
                    return 1;
            }
        } else if (sp + 2 <= 128) {
            stack[sp++] = N->first;
            stack[sp++] = N->first + 1;
        }
    }
    return 0;
}

/* >>visibility =============================================================

   Sec 4.2.1.  The importance of a surface point p seen from direction r (a
   camera at infinity, so the projection is orthographic) is its projected
   area,
       v(p, r) = n_p . r   if the ray from p toward r is unblocked and n_p . r > 0,
       v(p, r) = 0         otherwise,
   and a triangle's visibility is its mean over the triangle and over the
   view model m(r) (eq 4.2, with m a probability distribution):
       V_t = E_{p in t, r ~ m} [ v(p, r) ].
   It is estimated by Monte Carlo: points stratified over the triangle (a
   jittered grid mapped by the square-root parameterization, which is
   uniform in area), one direction drawn from the model per point.  Every
   triangle has its own random stream derived from (seed, triangle), so the
   estimate does not depend on how triangles are split among threads.

   The view models of fig 4.3: the uniform sphere, the front hemisphere
   around an axis, a "top ring" of directions at a fixed elevation around an
   up axis (a turntable), a single side direction, or the user's weighted
   list.  V_t is normalized to an area-weighted mean of 1 (then a uniform
   visibility gives the isometric map) and floored (views.floor, default
   0.05): a triangle nobody sees would otherwise ask for zero area, which
   the energy cannot reach.  Eq 4.1 uses V_t through opt->importance.

   Texel density (sec 4.3, fig 4.8).  For a triangle t seen from r, a texel
   covers det J = A3_t (n.r) / Auv_t of screen (orthographic, A3 the 3D
   area, Auv its texture area once the atlas is scaled to the same total
   area as the surface).  The dissertation averages det J "from texture
   space to screen space" because its inverse is infinite for triangles
   seen edge-on.  For each view direction r_j (K directions drawn from the
   model and shared by all triangles) we average it over the visible
   texels -- each sample of triangle t weighted by Auv_t --
       M(r_j) = sum_t A3_t (n.r_j) [visible] / sum_t Auv_t [visible],
   the screen area of the average visible texel, and report the mean of
   M over the views.  Averaging per view first means that a map which
   starves some views of texels (a side-view map seen from behind) pays
   for it.  (Averaged over surface area instead, eq 4.1's ideal map would
   tie with the isometric one exactly: Auv proportional to V cancels.) */

typedef struct bp__rng { uint64_t s; } bp__rng;

static uint64_t bp__splitmix(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double bp__rand(bp__rng *r)
{
    return (double)(bp__splitmix(&r->s) >> 11) * (1.0 / 9007199254740992.0);
}

static void bp__normalize3(double *v)
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}

/* An orthonormal frame (e1, e2) perpendicular to the unit vector n. */
static void bp__frame(const double *n, double *e1, double *e2)
{
    double t[3] = { 1, 0, 0 };
    if (fabs(n[0]) > 0.9) { t[0] = 0; t[1] = 1; }
    e1[0] = t[1] * n[2] - t[2] * n[1]; e1[1] = t[2] * n[0] - t[0] * n[2]; e1[2] = t[0] * n[1] - t[1] * n[0];
    bp__normalize3(e1);
    e2[0] = n[1] * e1[2] - n[2] * e1[1]; e2[1] = n[2] * e1[0] - n[0] * e1[2]; e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

static void bp__view_direction(const bp_views *V, bp__rng *rng, double *r)
{
    double u = bp__rand(rng), w = bp__rand(rng), z, rad, phi, axis[3], e1[3], e2[3];
    int k;
    switch (V->model) {
    case BP_VIEW_FRONT:                  /* uniform on the hemisphere around direction */
    case BP_VIEW_UNIFORM:                /* uniform on the sphere */
        z = V->model == BP_VIEW_FRONT ? u : 2 * u - 1;
        rad = sqrt(1 - z * z > 0 ? 1 - z * z : 0);
        phi = 2 * 3.14159265358979323846 * w;
        if (V->model == BP_VIEW_UNIFORM) { r[0] = rad * cos(phi); r[1] = rad * sin(phi); r[2] = z; return; }
        memcpy(axis, V->direction, sizeof axis);
        if (axis[0] == 0 && axis[1] == 0 && axis[2] == 0) axis[2] = 1;
        bp__normalize3(axis);
        bp__frame(axis, e1, e2);
        for (k = 0; k < 3; k++) r[k] = z * axis[k] + rad * (cos(phi) * e1[k] + sin(phi) * e2[k]);
        return;
    case BP_VIEW_RING:                   /* turntable: fixed elevation around up */
        memcpy(axis, V->up, sizeof axis);
        if (axis[0] == 0 && axis[1] == 0 && axis[2] == 0) axis[1] = 1;
        bp__normalize3(axis);
        bp__frame(axis, e1, e2);
        z = sin(V->elevation * 3.14159265358979323846 / 180);
        rad = cos(V->elevation * 3.14159265358979323846 / 180);
        phi = 2 * 3.14159265358979323846 * u;
        for (k = 0; k < 3; k++) r[k] = z * axis[k] + rad * (cos(phi) * e1[k] + sin(phi) * e2[k]);
        return;
    case BP_VIEW_LIST: {                 /* weighted list: inverse CDF */
        double total = 0, acc = 0;
        uint32_t i, pick = 0;
        for (i = 0; i < V->list_count; i++) total += V->list[4 * (size_t)i + 3];
        u *= total;
        for (i = 0; i < V->list_count; i++) {
            acc += V->list[4 * (size_t)i + 3];
            pick = i;
            if (u < acc) break;
        }
        memcpy(r, V->list + 4 * (size_t)pick, 3 * sizeof(double));
        bp__normalize3(r);
        return;
    }
    default:                             /* SIDE: a single direction */
        memcpy(r, V->direction, 3 * sizeof(double));
        if (r[0] == 0 && r[1] == 0 && r[2] == 0) r[0] = 1;
        bp__normalize3(r);
        return;
    }
}

/* Shared state of the per-triangle sampling tasks. */
typedef struct bp__vis_task {
    const bp_mesh *m;
    const bp_views *views;
    const bp__bvh *bvh;
    const double *uv_area;     /* texel density: UV area per mesh triangle (scaled) */
    const double *dirs;        /* texel density: the shared view directions  */
    uint32_t ndirs;
    double  tmin;              /* ray offset, relative to the mesh size      */
    uint32_t samples;
    double *out;               /* per triangle V_t, or per (chunk, direction)
                                  the texel-weighted sums (num, den)          */
} bp__vis_task;

/* Sample point s of triangle t (stratified) and a view direction. */
static void bp__vis_sample(const bp__vis_task *T, uint32_t t, uint32_t s, bp__rng *rng, double *p, double *r)
{
    const uint32_t *tv = T->m->triangles + 3 * (size_t)t;
    uint32_t g = 1;
    double a, b, su;
    int k;
    while ((g + 1) * (g + 1) <= T->samples) g++;
    a = ((s % g) + bp__rand(rng)) / g;
    b = (((s / g) % g) + bp__rand(rng)) / g;
    su = sqrt(a);
    for (k = 0; k < 3; k++)
        p[k] = (1 - su) * bp__pos(T->m, tv[0])[k] + su * (1 - b) * bp__pos(T->m, tv[1])[k] +
               su * b * bp__pos(T->m, tv[2])[k];
    if (T->dirs) memcpy(r, T->dirs + 3 * (size_t)(s % T->ndirs), 3 * sizeof(double));
    else bp__view_direction(T->views, rng, r);
}

static void bp__triangle_normal(const bp_mesh *m, uint32_t t, double *n)
{
    const uint32_t *tv = m->triangles + 3 * (size_t)t;
    const double *a = bp__pos(m, tv[0]), *b = bp__pos(m, tv[1]), *c = bp__pos(m, tv[2]);
    double u[3], v[3];
    int k;
    for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = c[k] - a[k]; }
    n[0] = u[1] * v[2] - u[2] * v[1]; n[1] = u[2] * v[0] - u[0] * v[2]; n[2] = u[0] * v[1] - u[1] * v[0];
    bp__normalize3(n);
}

#define BP__VIS_CHUNK 64

/* Task: V_t (or the texel-density sums) for one chunk of triangles. */
static void bp__vis_task_run(void *task, uint32_t chunk)
{
    bp__vis_task *T = (bp__vis_task *)task;
    uint32_t t, s, t0 = chunk * BP__VIS_CHUNK, t1 = t0 + BP__VIS_CHUNK;
    if (t1 > T->m->num_triangles) t1 = T->m->num_triangles;
    for (t = t0; t < t1; t++) {
        bp__rng rng;
        double n[3], sum = 0;
        uint64_t seed = T->views->seed ^ ((uint64_t)t * 0xD1B54A32D192ED03ull);
        rng.s = bp__splitmix(&seed);
        bp__triangle_normal(T->m, t, n);
        for (s = 0; s < T->samples; s++) {
            double p[3], r[3], c;
            bp__vis_sample(T, t, s, &rng, p, r);
            c = n[0] * r[0] + n[1] * r[1] + n[2] * r[2];
            if (c <= 0 || (T->uv_area && !(T->uv_area[t] > 0))) continue;   /* no map here */
            if (bp__bvh_occluded(T->bvh, p, r, T->tmin, HUGE_VAL, t)) continue;
            if (T->uv_area) {
                /* a visible texel of this triangle covers c A3 / Auv of
                   screen; weighted by Auv (texel average): c A3 and Auv */
                double a3 = 0.5 * bp__area2_3d(bp__pos(T->m, T->m->triangles[3 * (size_t)t]),
                                               bp__pos(T->m, T->m->triangles[3 * (size_t)t + 1]),
                                               bp__pos(T->m, T->m->triangles[3 * (size_t)t + 2]));
                double *slot = T->out + 2 * ((size_t)chunk * T->ndirs + s % T->ndirs);
                slot[0] += c * a3;
                slot[1] += T->uv_area[t];
            } else {
                sum += c;
            }
        }
        if (!T->uv_area) T->out[t] = sum / T->samples;
    }
}

static bp_status bp__vis_run(const bp_mesh *m, const bp_options *opt, const double *uv_area, const double *dirs,
                             uint32_t ndirs, double *out, bp_error *err)
{
    bp_allocator a = bp__allocator_of(opt);
    bp__bvh B;
    bp__vis_task T;
    bp__par par;
    void *pool = NULL;
    double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
    uint32_t v;
    bp_status st;
    if (!opt || opt->views.model <= BP_VIEW_NONE || opt->views.model > BP_VIEW_LIST)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "visibility needs a view model in opt->views.model");
    if (opt->views.model == BP_VIEW_LIST) {
        double total = 0;
        uint32_t i;
        for (i = 0; i < opt->views.list_count; i++) {
            const double *d = opt->views.list + 4 * (size_t)i;
            if (!(d[3] >= 0) || !(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0))
                return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, i, -1, 0,
                                "view %u of the list needs a nonzero direction and a weight >= 0", i);
            total += d[3];
        }
        if (!(total > 0))
            return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                            "the view list is empty or all its weights are zero");
    }
    if ((st = bp__validate_mesh(m, err)) != BP_OK) return st;
    if (bp__bvh_build(&a, &B, m) != BP_OK) return bp__oom(err, "building the ray-casting hierarchy");
    for (v = 0; v < m->num_vertices; v++) bp__box_grow(lo, hi, bp__pos(m, v));
    T.m = m;
    T.views = &opt->views;
    T.bvh = &B;
    T.uv_area = uv_area;
    T.dirs = dirs;
    T.ndirs = ndirs;
    T.tmin = 1e-7 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                         (hi[2] - lo[2]) * (hi[2] - lo[2]));
    T.samples = opt->views.samples ? opt->views.samples : 64;
    T.out = out;
    par = bp__par_begin(&a, opt, &pool);
    par.run(par.user, bp__vis_task_run, &T, (m->num_triangles + BP__VIS_CHUNK - 1) / BP__VIS_CHUNK);
    bp__par_end(&a, pool);
    bp__bvh_free(&a, &B);
    return BP_OK;
}

BPDEF bp_status bp_visibility(const bp_mesh *m, const bp_options *opt, double *out, bp_error *err)
{
    bp_status st;
    uint32_t t;
    double sum = 0, area = 0, fl;
    bp_options o_;
    if ((opt = bp__opts(opt, &o_, err, &st)), st != BP_OK) return st;     /* >>progress */
    if (!out) return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "out must not be NULL");
    if (bp__report(opt, BP_STAGE_VISIBILITY, 0, BP_NO_CHART))
        return bp__fail(err, BP_ERR_CANCELLED, BP_ELEMENT_NONE, -1, -1, 0, "cancelled before the visibility");
    if ((st = bp__vis_run(m, opt, NULL, NULL, 0, out, err)) != BP_OK) return st;
    bp__report(opt, BP_STAGE_VISIBILITY, 1, BP_NO_CHART);   /* a cancel here: the next stage sees it */
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *tv = m->triangles + 3 * (size_t)t;
        double a2 = bp__area2_3d(bp__pos(m, tv[0]), bp__pos(m, tv[1]), bp__pos(m, tv[2]));
        sum += a2 * out[t];
        area += a2;
    }
    fl = opt->views.floor > 0 ? opt->views.floor : 0.05;
    for (t = 0; t < m->num_triangles; t++) {
        out[t] = sum > 0 ? out[t] * area / sum : 1;
        if (out[t] < fl) out[t] = fl;
    }
    return bp__ok(err);
}

BPDEF bp_status bp_texture_to_screen(const bp_mesh *m, const bp_atlas *atlas, const bp_options *opt,
                                     double *mean_det, bp_error *err)
{
    bp_options o_;
    bp_status ost_;
    const bp_options *opt_ = bp__opts(opt, &o_, err, &ost_);     /* >>progress */
    bp_allocator a = bp__allocator_of(opt_);
    double *uv_area, *sums, *dirs, a3 = 0, auv = 0, total = 0;
    uint32_t c, t, j, K, nchunk, used = 0;
    bp_status st;
    bp__rng rng;
    uint64_t seed;
    if (ost_ != BP_OK) return ost_;
    opt = opt_;
    if (!m || !atlas || !mean_det || !opt || atlas->num_corners != 3 * m->num_triangles)
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0,
                        "bp_texture_to_screen needs the mesh, the atlas built from it and options with a view model");
    K = opt->views.samples ? opt->views.samples : 64;
    nchunk = (m->num_triangles + BP__VIS_CHUNK - 1) / BP__VIS_CHUNK;
    uv_area = (double *)bp__alloc_array(&a, m->num_triangles, sizeof(double));
    sums = (double *)bp__calloc_array(&a, 2 * (size_t)nchunk * K, sizeof(double));
    dirs = (double *)bp__alloc_array(&a, 3 * (size_t)K, sizeof(double));
    if (!uv_area || !sums || !dirs) {
        bp__free(&a, uv_area); bp__free(&a, sums); bp__free(&a, dirs);
        return bp__oom(err, "measuring texel density");
    }
    for (t = 0; t < m->num_triangles; t++) uv_area[t] = 0;
    for (c = 0; c < atlas->num_charts; c++) {
        const bp_chart *ch = &atlas->charts[c];
        for (t = 0; ch->uv && t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t;
            const double *uv = ch->uv;
            uv_area[ch->face[t]] = fabs(bp__uv_tri_area(uv + 2 * (size_t)tr[0], uv + 2 * (size_t)tr[1], uv + 2 * (size_t)tr[2]));
        }
    }
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *tv = m->triangles + 3 * (size_t)t;
        a3 += 0.5 * bp__area2_3d(bp__pos(m, tv[0]), bp__pos(m, tv[1]), bp__pos(m, tv[2]));
        auv += uv_area[t];
    }
    /* same total texture area as surface area (sec 4.2: fair comparison) */
    if (!(auv > 0)) {
        bp__free(&a, uv_area); bp__free(&a, sums); bp__free(&a, dirs);
        return bp__fail(err, BP_ERR_INVALID_ARGUMENT, BP_ELEMENT_NONE, -1, -1, 0, "the atlas has no mapped triangles");
    }
    for (t = 0; t < m->num_triangles; t++) uv_area[t] *= a3 / auv;
    /* K directions drawn once from the view model and shared by every
       triangle, so that each view's texels can be pooled */
    seed = opt->views.seed ^ 0x5DEECE66Dull;
    rng.s = bp__splitmix(&seed);
    for (j = 0; j < K; j++) bp__view_direction(&opt->views, &rng, dirs + 3 * (size_t)j);
    st = bp__vis_run(m, opt, uv_area, dirs, K, sums, err);
    if (st == BP_OK) {
        /* per view: mean screen area of a visible texel; then the mean
           over the views (a view that sees few texels weighs as much as
           one that sees many) */
        for (j = 0; j < K; j++) {
            double num = 0, den = 0;
            for (c = 0; c < nchunk; c++) {
                num += sums[2 * ((size_t)c * K + j)];
                den += sums[2 * ((size_t)c * K + j) + 1];
            }
            if (den > 0) { total += num / den; used++; }
        }
        *mean_det = used ? total / used : 0;
        bp__ok(err);
    }
    bp__free(&a, uv_area);
    bp__free(&a, sums);
    bp__free(&a, dirs);
    return st;
}

#endif /* BP_IMPLEMENTATION */

/*
   ------------------------------------------------------------------------------
   MIT License

   Copyright (c) 2026 the bijparam authors

   Permission is hereby granted, free of charge, to any person obtaining a copy
   of this software and associated documentation files (the "Software"), to deal
   in the Software without restriction, including without limitation the rights
   to use, copy, modify, merge, publish, distribute, sublicense, and/or sell
   copies of the Software, and to permit persons to whom the Software is
   furnished to do so, subject to the following conditions:

   The above copyright notice and this permission notice shall be included in
   all copies or substantial portions of the Software.

   THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
   IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
   FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
   AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
   LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
   OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
   SOFTWARE.
   ------------------------------------------------------------------------------
*/
