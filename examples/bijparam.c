/* bijparam.c - the command-line front end of bijparam.h.

   It reads a triangle mesh (OBJ, OFF or PLY), splits it into charts, gives
   each chart a bijective start map, minimizes its distortion
   while keeping the map bijective at every step, packs the charts side by
   side and, when asked, writes the mesh back as OBJ with the new `vt`
   coordinates: an OBJ input is streamed through bp_write_obj_from, so every
   other line of the user's file (normals, materials, groups, comments)
   comes back unchanged; an OFF input is written by bp_write_obj; a glTF
   input (.gltf, .glb: examples/bp_gltf.h) may also be written back as
   glTF with a new TEXCOORD_0 and everything else of the file kept.  It shows
   every public step of the library in the order a program calls them
   (bp_read_mesh, bp_atlas_build, bp_atlas_solve for several charts -- the
   charts themselves on the threads -- or bp_chart_solve chart by chart --
   bp_chart_init and bp_chart_optimize in one call, separate with
   --frames --, bp_atlas_pack, bp_write_obj_from / bp_write_obj), how the options map onto
   bp_options, how a progress callback traces the solve, and how bp_check
   proves the result.  With --demo it flattens a built-in "wavy cone" (fig
   3.3 of the dissertation) whose isometric flattening overlaps itself, so
   only the boundary barrier keeps it bijective.

   Pictures (examples/bp_draw.h): --svg draws the UV layout coloured by
   distortion, --png the mesh with a checkerboard through the map, and
   --frames the layout every few iterations while the solver runs (read
   from the chart's uv inside the progress callback, where it is the
   current valid map).

   Writing is safe: the result goes into a temporary file created next to
   OUT (before the work starts, so a bad -o fails at once), which is renamed
   over OUT only when complete; on an error, a cancel or SIGINT / SIGTERM /
   SIGHUP the temporary is removed.  SIGINT cancels through the library's
   run-progress callback (every chart stops at its next iteration, nothing
   is written, exit status 130); a second SIGINT ends the program at once.
   On a terminal (stderr a tty, no --quiet) a one-line progress bar shows
   the stage (read, charts, start, visibility, optimize, pack, write) and
   its share done.  An output that is the input file
   (same device and inode, whatever the spelling) is refused unless
   --force.  After a run that wrote OUT, one line on stderr says so; a
   successful run without -o says "no output written (use -o FILE)".  Both
   are left out with --quiet; with --json the report's "output" field says
   it instead.

   Messages name vertices, faces and lines as the file numbers them (OBJ
   from 1), while bp_error.index stays 0-based.

   Defects the library repairs (faces wound the other way, duplicate
   faces, edges of more than two faces, zero-area faces) get one line each
   on stderr ("bijparam: repaired: FILE: ..."; none with --quiet) and a
   "repairs" object in --json; --strict makes each of them an error.  The
   faces re-oriented are written with their corners in the repaired order
   (corner 0, then the others reversed; "written_reordered" in --json).

   Exit status: 0 success, 1 input rejected or a step failed (one line on
   stderr: "bijparam: error: FILE:LINE: what" or "bijparam: error: FILE: what"),
   2 usage error (one line, then "see bijparam --help"), 130 cancelled by
   SIGINT. */
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700        /* realpath */
#include <errno.h>
#include <limits.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <time.h>
#include <sys/stat.h>
#ifndef _WIN32
#include <unistd.h>
#include <sys/resource.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>              /* mallopt: keep_freed_memory */
#endif

#define BP_IMPLEMENTATION
#include "bijparam.h"
#define BPD_IMPLEMENTATION
#include "bp_draw.h"
#define BPG_IMPLEMENTATION
#include "bp_gltf.h"

/* Windows (mingw-w64): the few POSIX calls of this program have Windows
   equivalents, defined here; <windows.h> comes after the libraries, whose
   names it must not touch.  Files keep Windows' default permissions (no
   mode to copy), and there is no SIGHUP. */
#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#define NOMINMAX
#define PSAPI_VERSION 2                 /* GetProcessMemoryInfo in kernel32 */
#include <windows.h>
#include <psapi.h>
#include <io.h>
#include <direct.h>
/* An absolute path with '/' separators (Windows accepts them), which the
   path arithmetic below expects; it need not exist, as realpath's must. */
static char *win_realpath(const char *p)
{
    char *r = _fullpath(NULL, p, 0), *q;
    if (r) for (q = r; *q; q++) if (*q == '\\') *q = '/';
    return r;
}
#define realpath(p, buf) win_realpath(p)
#define mkdir(dir, mode) _mkdir(dir)
#define isatty _isatty
#define unlink _unlink
#define close _close
#endif

/* Rename `from` over `to`, replacing it (POSIX rename does; Windows' needs
   MoveFileEx to). */
static int replace_file(const char *from, const char *to)
{
#ifdef _WIN32
    return MoveFileExA(from, to, MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH) ? 0 : (errno = EACCES, -1);
#else
    return rename(from, to);
#endif
}

/* The last path separator of s ('/', and '\\' on Windows), or NULL. */
static const char *last_separator(const char *s)
{
    const char *r = strrchr(s, '/');
#ifdef _WIN32
    const char *b = strrchr(s, '\\');
    if (b && (!r || b > r)) r = b;
#endif
    return r;
}

static const char usage_text[] =
    "usage: bijparam [options] INPUT.(obj|off|ply|gltf|glb) [-o OUT.(obj|gltf|glb)]\n"
    "       bijparam [options] --demo [-o OUT.obj]\n"
    "  -o FILE            write the mesh with the new uv map (OBJ); an OBJ input\n"
    "                     keeps every other line of its file (vn, usemtl, g, ...);\n"
    "                     a glTF input may be written as .glb or .gltf: the new\n"
    "                     TEXCOORD_0, everything else of the file kept\n"
    "  --texcoord N       glTF: read and write TEXCOORD_N (default 0)\n"
    "  --force            allow -o (or --svg, --png, --trace) to replace the input\n"
    "  -q, --quiet        no progress bar, no line saying where the result went\n"
    "  --json             print a one-line JSON report on stdout\n"
    "  --demo             use the built-in wavy cone instead of a file\n"
    "  --check            only check the file's own vt charts exactly (each chart\n"
    "                     bijective, no two overlapping): exit 0 yes, 1 no\n"
    "  --init auto|conformal|mvc|tutte|input   start map; auto (default):\n"
    "                     conformal (least squares, free boundary) when\n"
    "                     exactly bijective, below 100,000 triangles or at\n"
    "                     any size with at most 2.5 sqrt(V) boundary vertices,\n"
    "                     else mean-value (Floater), Tutte if that one fails its\n"
    "                     exact check; conformal: at any size; mvc: mean-value;\n"
    "                     tutte: uniform weights; input: the file's own\n"
    "                     vt per chart when bijective (else auto, reported), and\n"
    "                     those charts keep their place unless --normalize\n"
    "  --pin FILE         pinned vertices, lines 'vertex u v [vt]' (numbered from 1\n"
    "                     as in the input; vt: only that side of a seam; '#'\n"
    "                     comments): they end exactly at (u, v) and their charts\n"
    "                     are not moved by packing\n"
    "  --start auto|plain|progressive   auto (default): a planar chart starts\n"
    "                     from its own projection (when exactly bijective),\n"
    "                     any other from the --init map; plain: the --init\n"
    "                     map always; progressive: auto, then a non-planar start\n"
    "                     relaxed toward the rest shapes in rounds\n"
    "  --init-only        stop after the start map\n";
static const char usage_solver[] =
    "  --energy sd|conformal|mips|iso|maxiso   distortion (default sd)\n"
    "  --no-barrier       locally injective only (no boundary barrier)\n"
    "  --epsilon X        barrier width (default: mean boundary edge / 4, at\n"
    "                     most the median boundary triangle height)\n"
    "  --direction default|precond|lbfgs|gd|newton   search direction; default:\n"
    "                     projected Newton for charts of 1,000 triangles or\n"
    "                     more whose start's mean symmetric Dirichlet energy\n"
    "                     is 8 or more (twice the isometry's), at any size;\n"
    "                     else (and for the other energies) precond;\n"
    "                     precond: L-BFGS preconditioned by the Laplacian, lbfgs:\n"
    "                     plain L-BFGS, gd: gradient descent, newton: always Newton\n"
    "  --history M        L-BFGS memory (default 5)\n"
    "  --max-iters N      iterations per chart (default 10000)\n"
    "  --tol X            relative energy decrease to stop (default 1e-7)\n"
    "  --max-seconds X    time limit per chart (0: none)\n"
    "  --normalize        scale the packed atlas into [0,1]^2\n"
    "  --atlas RES        pack the charts by their outlines into a RES x RES\n"
    "                     texture atlas in [0,1]^2, one texel density, rotated\n"
    "                     to pack better (default: bounding boxes on shelves)\n"
    "  --padding PX       texels between charts with --atlas (default 4)\n"
    "  --no-rotate        with --atlas: keep each chart's orientation\n"
    "  --repack           keep the input's own charts and texture coordinates\n"
    "                     (checked exactly), only pack them\n"
    "  --cut auto|none    charts that are closed or have handles: cut them into\n"
    "                     disks along mesh edges (default auto) or reject them\n"
    "  --segment auto|on|off  grow several charts of bounded normal deviation\n"
    "                     in each chart (default auto: with --atlas or\n"
    "                     --max-charts; vt seams are kept)\n"
    "  --max-distortion X split charts whose mean distortion stays above X\n"
    "                     after the optimization, and optimize the pieces again\n"
    "  --max-charts N     at most N charts when segmenting (0: no limit)\n"
    "  --strict           a mesh defect or a chart that cannot be flattened fails\n"
    "                     the whole run (default: defects -- flipped, duplicate,\n"
    "                     non-manifold, zero-area triangles -- are repaired and\n"
    "                     reported; a failed chart is reported, the others written)\n"
    "  --trace FILE       one line per iteration: chart iter seconds energy step\n"
    "                     cpu (seconds since start, wall and process CPU)\n"
    "  --threads N        threads (default 0: all cores; 1: serial)\n";
static const char usage_views[] =
    "  --visibility uniform|front|ring|side   optimize texel density for a view\n"
    "                     model (chapter 4): visible parts get more texture area\n"
    "  --view-dir X,Y,Z   front axis / side direction (default +z / +x)\n"
    "  --up X,Y,Z         turntable axis of the ring model (default +y)\n"
    "  --ring-elevation D ring elevation in degrees (default 30)\n"
    "  --vis-samples N    rays per triangle (default 64)\n"
    "  --vis-floor X      least importance relative to the mean (default 0.05)\n"
    "  --importance FILE  one weight > 0 per face (painted importance)\n"
    "  --density-report uniform|front|ring|side   texel density of the result\n"
    "                     against a plain isometric map under that view model\n";
/* (four strings: C99 promises string literals of 4095 characters only) */
static const char usage_pictures[] =
    "pictures:\n"
    "  --svg FILE         the UV layout as SVG: triangles coloured by distortion,\n"
    "                     boundary loops, chart indices, colour scale, energies\n"
    "  --svg-color energy|area|angle|chart   what the colour shows (default\n"
    "                     energy): the energy, UV/3D area ratio, s_max/s_min,\n"
    "                     or one colour per chart (seams and packing)\n"
    "  --png FILE         the mesh with a checkerboard through the map (PNG)\n"
    "  --png-view X,Y,Z   direction toward the camera (default 1,0.6,1.2;\n"
    "                     --demo: 0.5,-0.9,1.4 with up 0,0,1)\n"
    "  --png-up X,Y,Z     screen up and turntable axis (default 0,1,0)\n"
    "  --png-size N       pixels of one view (default 512)\n"
    "  --png-views N      a turntable strip of N views side by side (default 1)\n"
    "  --checker N        checker squares across the atlas (default 16)\n"
    "  --frames DIR       the layout of each chart as SVG every K iterations,\n"
    "                     DIR/chartC_iterNNNNN.svg, and DIR/strip.svg: snapshots\n"
    "                     of the largest chart side by side\n"
    "  --frames-every K   iterations between frames (default 10)\n"
    "  -h, --help         show this help\n"
    "  --version          print the version\n"
    "messages number vertices, faces and lines as the file does (OBJ from 1)\n";

static const char *const energy_names[] = { "sd", "conformal", "mips", "iso", "maxiso" };
static const char *const view_names[] = { "none", "uniform", "front", "ring", "side" };

static int parse_view(const char *v)
{
    int k;
    for (k = 1; k < 5; k++) if (!strcmp(v, view_names[k])) return k;
    return 0;
}

/* "x,y,z" into three finite doubles. */
static int parse_vec3(const char *s, double *out)
{
    char *end;
    int k;
    for (k = 0; k < 3; k++) {
        errno = 0;
        out[k] = strtod(s, &end);
        if (end == s || errno || !(out[k] - out[k] == 0)) return 0;
        if (k < 2) { if (*end != ',') return 0; s = end + 1; }
    }
    return *end == 0 && (out[0] != 0 || out[1] != 0 || out[2] != 0);
}

/* One weight per face, whitespace separated; faces are the file's polygons,
   spread to their fan triangles.  Returns NULL with a message on error. */
static double *read_importance(const char *path, const bp_mesh *m, char *msg, size_t msz)
{
    FILE *f = fopen(path, "r");
    double *w, *face;
    uint32_t n = m->num_faces ? m->num_faces : m->num_triangles, i;
    if (!f) { snprintf(msg, msz, "cannot open importance file: %s", strerror(errno)); return NULL; }
    face = (double *)malloc(sizeof(double) * (n ? n : 1));
    w = (double *)malloc(sizeof(double) * m->num_triangles);
    if (!face || !w) { free(face); free(w); fclose(f); snprintf(msg, msz, "out of memory"); return NULL; }
    for (i = 0; i < n; i++) {
        if (fscanf(f, "%lf", &face[i]) != 1 || !(face[i] > 0) || !(face[i] - face[i] == 0)) {
            snprintf(msg, msz, "importance of face %u is missing, not a number or not > 0 (need %u weights)",
                     (unsigned)i + 1, (unsigned)n);
            free(face); free(w); fclose(f);
            return NULL;
        }
    }
    fclose(f);
    for (i = 0; i < m->num_triangles; i++)
        w[i] = face[m->triangle_face ? m->triangle_face[i] : i];
    free(face);
    return w;
}

/* --pin FILE: lines "vertex u v [vt]" (vertex and vt from 1, as the input
   numbers them; with vt only the chart vertex using that vt is pinned, one
   side of a seam), blank lines and '#' comments allowed.  On an error msg names the line
   (*line) and NULL is returned. */
static bp_pin *read_pins(const char *path, const bp_mesh *m, uint32_t *count, long *line, char *msg, size_t msz)
{
    FILE *f = fopen(path, "r");
    bp_pin *p = NULL;
    size_t n = 0, cap = 0;
    char buf[512];
    *line = 0;
    *count = 0;
    if (!f) { snprintf(msg, msz, "cannot open pin file: %s", strerror(errno)); return NULL; }
    while (fgets(buf, sizeof buf, f)) {
        char *s = buf, *end;
        long long v, vt;
        double u, w;
        (*line)++;
        while (*s == ' ' || *s == '\t') s++;
        if (*s == '#' || *s == '\n' || *s == '\r' || *s == 0) continue;
        errno = 0;
        v = strtoll(s, &end, 10);
        if (end == s || v < 1 || v > (long long)m->num_vertices) {
            snprintf(msg, msz, "expected 'vertex u v' with a vertex in 1..%u", (unsigned)m->num_vertices);
            goto fail;
        }
        s = end;
        u = strtod(s, &end);
        if (end == s || !isfinite(u)) { snprintf(msg, msz, "vertex %lld: u is missing or not a finite number", v); goto fail; }
        s = end;
        w = strtod(s, &end);
        if (end == s || !isfinite(w)) { snprintf(msg, msz, "vertex %lld: v is missing or not a finite number", v); goto fail; }
        for (s = end; *s == ' ' || *s == '\t'; s++) {}
        vt = 0;
        if (*s >= '0' && *s <= '9') {            /* optional: the vt of one side of a seam */
            vt = strtoll(s, &end, 10);
            if (vt < 1 || vt > (long long)m->num_uvs) {
                snprintf(msg, msz, "vertex %lld: vt must be in 1..%u", v, (unsigned)m->num_uvs);
                goto fail;
            }
            s = end;
        }
        for (; *s == ' ' || *s == '\t' || *s == '\r' || *s == '\n'; s++) {}
        if (*s && *s != '#') { snprintf(msg, msz, "vertex %lld: unexpected text after 'vertex u v [vt]'", v); goto fail; }
        if (n == cap) {
            bp_pin *q = (bp_pin *)realloc(p, sizeof *p * (cap = cap ? 2 * cap : 64));
            if (!q) { snprintf(msg, msz, "out of memory"); goto fail; }
            p = q;
        }
        p[n].vertex = (uint32_t)(v - 1);
        p[n].uv = (uint32_t)vt;
        p[n].u = u;
        p[n].v = w;
        n++;
    }
    fclose(f);
    *line = 0;
    *count = (uint32_t)n;
    if (!p) p = (bp_pin *)malloc(sizeof *p);   /* an empty file: no pins, not an error */
    if (!p) snprintf(msg, msz, "out of memory");
    return p;
fail:
    fclose(f);
    free(p);
    return NULL;
}

/* Freed memory kept for reuse (glibc only).  The solver allocates and
   frees its large arrays as it goes: the start map's factor, Newton's
   pattern and factor each time the barrier's pairs grow it, the scratch
   of each factorization, the exact checks' grids.  On bimba (89K faces)
   it allocates 349 MB in blocks of 128 KiB or more over a run whose live
   memory peaks at 135 MB.  glibc gives such blocks back to the system (a
   block above its mmap threshold is unmapped when freed, and the heap's
   free top is trimmed), so later blocks start on fresh pages, each one a
   page fault at its first touch: about 2.5 us per 4 KiB page on the test
   machine, 46,000 faults in bimba's run, and on two threads the two
   threads' faults contend in the kernel.  So the tool asks glibc to keep
   what is freed for the next allocation: no mmap for large blocks
   (M_MMAP_MAX 0; glibc still maps when the heap cannot grow) and no
   trimming of the heap (M_TRIM_THRESHOLD at its largest).  On bimba this
   saves a quarter of the page faults and 2-12% of the two-thread run
   (docs/performance.md, "Threads"); the price is a higher peak where a
   freed block stays in the heap and later ones do not all fit (the
   4,740-chart case: 366 instead of 270 bytes per face on one thread, a
   third of the million-face budget).  A fixed 16 MiB mmap threshold saved
   less than half of the faults.
   The library itself must not touch the process's malloc settings (and
   uses only the C library); a program calling it can do the same as here,
   or pass opt.allocator one that keeps its blocks.  With another C
   library nothing changes. */
static void keep_freed_memory(void)
{
#if defined(__GLIBC__)
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, INT_MAX);
#endif
}

/* Peak resident memory of this process.  Linux: VmHWM of /proc/self/status,
   the high-water mark of this program's own address space.  getrusage's
   ru_maxrss survives execve, so a tool started by a large parent (the
   benchmark's Python) would report the parent's size at fork time. */
static double peak_rss_bytes(void)
{
#ifdef _WIN32
    PROCESS_MEMORY_COUNTERS pmc;
    if (!GetProcessMemoryInfo(GetCurrentProcess(), &pmc, sizeof pmc)) return 0;
    return (double)pmc.PeakWorkingSetSize;
#else
    struct rusage ru;
    FILE *f = fopen("/proc/self/status", "r");
    if (f) {
        char line[256];
        double kb = -1;
        while (fgets(line, sizeof line, f))
            if (!strncmp(line, "VmHWM:", 6)) { kb = atof(line + 6); break; }
        fclose(f);
        if (kb >= 0) return kb * 1024.0;
    }
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return (double)ru.ru_maxrss * 1024.0;      /* Linux reports KiB */
#endif
}

/* ---- small helpers ------------------------------------------------------ */

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds of the whole process (all threads), for the trace: on a
   shared machine wall time says little, CPU time with --threads 1 says how
   much work the solve took. */
static double cpu_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return -1;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "bijparam: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\nsee bijparam --help\n");
    return 2;
}

/* ---- safe output -------------------------------------------------------- */

/* Do two paths name the same existing file (device and inode, so that
   "a.obj", "./a.obj" and a symlink to it all match)? */
static int same_file(const char *a, const char *b)
{
#ifdef _WIN32   /* no inode in stat: the volume and file index of an open handle */
    BY_HANDLE_FILE_INFORMATION ia, ib;
    HANDLE ha, hb;
    int same = 0;
    if (!a || !b) return 0;
    ha = CreateFileA(a, 0, FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, NULL, OPEN_EXISTING,
                     FILE_FLAG_BACKUP_SEMANTICS, NULL);
    hb = CreateFileA(b, 0, FILE_SHARE_READ | FILE_SHARE_WRITE | FILE_SHARE_DELETE, NULL, OPEN_EXISTING,
                     FILE_FLAG_BACKUP_SEMANTICS, NULL);
    if (ha != INVALID_HANDLE_VALUE && hb != INVALID_HANDLE_VALUE && GetFileInformationByHandle(ha, &ia) &&
        GetFileInformationByHandle(hb, &ib))
        same = ia.dwVolumeSerialNumber == ib.dwVolumeSerialNumber && ia.nFileIndexHigh == ib.nFileIndexHigh &&
               ia.nFileIndexLow == ib.nFileIndexLow;
    if (ha != INVALID_HANDLE_VALUE) CloseHandle(ha);
    if (hb != INVALID_HANDLE_VALUE) CloseHandle(hb);
    return same;
#else
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
#endif
}

/* The temporary file the result is written to, known to the signal handler
   so that an interrupted run leaves nothing behind.  (The library keeps no
   globals; this program may.) */
static char temp_path[4096];
static volatile sig_atomic_t temp_live = 0;
/* A .gltf output's .bin file has a temporary of its own. */
static char temp_bin[4096];
static volatile sig_atomic_t temp_bin_live = 0;

static void on_signal(int sig)
{
    if (temp_live) unlink(temp_path);          /* async-signal-safe */
    if (temp_bin_live) unlink(temp_bin);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* SIGINT (Ctrl-C) cancels through the library: the run-progress callback
   answers nonzero at the next report, every chart stops at its next
   iteration, the temporary is removed, and the tool exits with status 130.
   A second SIGINT does not wait: on_signal removes the temporary and the
   signal ends the program. */
static volatile sig_atomic_t interrupted = 0;

static void on_interrupt(int sig)
{
    if (interrupted) { on_signal(sig); return; }
    interrupted = 1;
#ifdef _WIN32
    signal(SIGINT, on_interrupt);        /* Windows resets a handler when it runs */
#endif
}

/* Create DIR/.NAME.bijparam-XXXXXX next to `target` (a symlink is followed,
   so the link keeps pointing at the replaced file), with the mode the
   target has or, for a new file, 0666 minus the umask.  `final` gets the
   path to rename onto, `tp` (4096 bytes) the temporary's and *live is set
   while it exists.  Returns 0 and sets *why to errno on failure. */
static int temp_create(char *tp, volatile sig_atomic_t *live, const char *target, char *final, size_t final_size, int *why)
{
    char *real = realpath(target, NULL);
    const char *t = real ? real : target, *slash = last_separator(t);
    size_t dir = slash ? (size_t)(slash - t) + 1 : 0;
#ifndef _WIN32
    struct stat st;
    mode_t mode, mask;
#endif
    int fd;
    if (strlen(t) + 24 >= 4096 || strlen(t) >= final_size) {
        free(real);
        *why = ENAMETOOLONG;
        return 0;
    }
    snprintf(final, final_size, "%s", t);
    snprintf(tp, 4096, "%.*s.%s.bijparam-XXXXXX", (int)dir, t, t + dir);
    free(real);
#ifndef _WIN32
    mask = umask(0);
    umask(mask);
    mode = stat(final, &st) == 0 ? (mode_t)(st.st_mode & 07777) : (mode_t)(0666 & ~mask);
#endif
#ifndef _WIN32
    {   /* no signal between the file's creation and *live: it would be left behind */
        sigset_t block, old;
        sigemptyset(&block);
        sigaddset(&block, SIGINT);
        sigaddset(&block, SIGTERM);
        sigaddset(&block, SIGHUP);
        sigprocmask(SIG_BLOCK, &block, &old);
        fd = mkstemp(tp);
        if (fd >= 0) *live = 1;
        else *why = errno;
        sigprocmask(SIG_SETMASK, &old, NULL);
    }
#else
    fd = mkstemp(tp);
    if (fd >= 0) *live = 1;
    else *why = errno;
#endif
    if (fd < 0) return 0;
#ifndef _WIN32
    if (fchmod(fd, mode) != 0) { *why = errno; close(fd); unlink(tp); *live = 0; return 0; }
#endif
    close(fd);
    return 1;
}

static void temp_discard(void)
{
    if (temp_live) unlink(temp_path);
    if (temp_bin_live) unlink(temp_bin);
    temp_live = temp_bin_live = 0;
}

static int ends_with_obj(const char *s)
{
    size_t n = strlen(s);
    return n >= 4 && s[n - 4] == '.' && (s[n - 3] | 32) == 'o' && (s[n - 2] | 32) == 'b' && (s[n - 1] | 32) == 'j';
}

/* The glTF file read, when the input is one (examples/bp_gltf.h): its mesh
   welds the file's vertices, so a library message's vertex and triangle
   numbers are the mesh's; the messages add the file's own names. */
static const bpg_file *gltf_names = NULL;

/* " [mesh 0 primitive 1 triangle 5 (vertices 3 4 9)]" for an element of a
   glTF input (a triangle, a vertex, the two vertices of an edge), else "". */
static void gltf_element(bp_element kind, int64_t index, int64_t index2, char *buf, size_t n)
{
    char a[200] = "", b[200] = "";
    buf[0] = 0;
    if (!gltf_names || index < 0 || index > 0xffffffffLL) return;
    if (kind == BP_ELEMENT_TRIANGLE) bpg_name_triangle(gltf_names, (uint32_t)index, a, sizeof a);
    else if (kind == BP_ELEMENT_VERTEX || kind == BP_ELEMENT_EDGE) bpg_name_vertex(gltf_names, (uint32_t)index, a, sizeof a);
    if (kind == BP_ELEMENT_EDGE && index2 >= 0 && index2 <= 0xffffffffLL) bpg_name_vertex(gltf_names, (uint32_t)index2, b, sizeof b);
    if (a[0]) snprintf(buf, n, " [%s%s%s]", a, b[0] ? " - " : "", b);
}

/* "file:line: message" when the library knows the line, else "file: message".
   The library's messages already start with "line N: ", which the
   file:line prefix makes redundant. */
static void report_error(const char *file, const bp_error *err)
{
    char names[420];
    gltf_element(err->element, err->index, err->index2, names, sizeof names);
    if (err->line > 0) {
        char prefix[40];
        const char *msg = err->message;
        size_t n = (size_t)snprintf(prefix, sizeof prefix, "line %lld: ", (long long)err->line);
        if (strncmp(msg, prefix, n) == 0) msg += n;
        fprintf(stderr, "bijparam: error: %s:%lld: %s%s\n", file, (long long)err->line, msg, names);
    } else
        fprintf(stderr, "bijparam: error: %s: %s%s\n", file, err->message, names);
}

/* ---- glTF input and output (examples/bp_gltf.h) ---------------------------

   A .gltf or .glb input is read by bpg_read: its triangle primitives
   become one mesh (vertices welded by position, seams where TEXCOORD_n
   differs), so every option works on it as on an OBJ.  -o FILE.glb or
   FILE.gltf writes it back with the new TEXCOORD_n and everything else of
   the file kept (bpg_encode).  A .gltf output whose input kept its bytes
   in files (a .bin next to a .gltf, or a .glb's BIN chunk) gets its new
   bytes in OUT's name with .bin, written through a temporary of its own
   and renamed before OUT; otherwise they go into a data: URI.  Written in
   another folder than the input's, the output's relative uris (buffers,
   images) are rewritten to reach the same files. */

/* The mesh of INPUT: glTF through bp_gltf.h (gltf_names set), else the
   library's readers. */
static bp_status read_input(const char *input, bp_mesh *mesh, bpg_file *gltf, int texcoord, const bp_options *opt,
                            bp_error *err)
{
    if (bpg_is_gltf_path(input)) {
        bpg_options go;
        bp_status st;
        memset(&go, 0, sizeof go);
        go.texcoord = texcoord;
        st = bpg_read(gltf, input, &go, err);
        if (st == BP_OK) { *mesh = gltf->mesh; gltf_names = gltf; }
        return st;
    }
    return bp_read_mesh_opt(input, mesh, opt, err);
}

static void free_input(bp_mesh *mesh, bpg_file *gltf)
{
    if (gltf_names) bpg_free(gltf);
    else bp_mesh_free(mesh, NULL);
    gltf_names = NULL;
    memset(mesh, 0, sizeof *mesh);
}

/* The folder part of path ("" for none, "dir/" with its slash). */
static void dir_of(const char *path, char *buf, size_t n)
{
    const char *slash = last_separator(path);
    size_t k = slash ? (size_t)(slash - path) + 1 : 0;
    if (k >= n) k = 0;
    memcpy(buf, path, k);
    buf[k] = 0;
}

/* The relative path from the output's folder to the input's ("../in/"), ""
   when they are one folder; 0 when a folder cannot be resolved. */
static int relative_dir(const char *input, const char *output, char *buf, size_t n)
{
    char a[4096], b[4096], *ra, *rb;
    size_t i, common = 0, k = 0;
    int ok = 1;
    dir_of(input, a, sizeof a);
    dir_of(output, b, sizeof b);
    ra = realpath(a[0] ? a : ".", NULL);
    rb = realpath(b[0] ? b : ".", NULL);
    buf[0] = 0;
    if (!ra || !rb) { free(ra); free(rb); return 0; }
    if (strcmp(ra, rb) != 0) {
        size_t la = strlen(ra), lb = strlen(rb);
        /* the longest common prefix that ends at a folder boundary */
        for (i = 0; i <= la && i <= lb; i++) {
            int end_a = i == la || ra[i] == '/', end_b = i == lb || rb[i] == '/';
            if (end_a && end_b) common = i;
            if (i == la || i == lb || ra[i] != rb[i]) break;
        }
        for (i = common; i < lb; i++)                    /* up from the output's folder */
            if (rb[i] == '/' && (i + 1 < lb || i == common)) {
                if (k + 4 >= n) { ok = 0; break; }
                memcpy(buf + k, "../", 3); k += 3; buf[k] = 0;
            }
        if (ok && common < la) {                         /* then down to the input's */
            const char *rest = ra + common + (ra[common] == '/');
            if (k + strlen(rest) + 2 >= n) ok = 0;
            else { k += (size_t)snprintf(buf + k, n - k, "%s/", rest); }
        }
    }
    free(ra);
    free(rb);
    return ok;
}

/* n bytes into the file at path: 0, or the errno of the failure. */
static int write_all(const char *path, const unsigned char *d, size_t n)
{
    FILE *fp = fopen(path, "wb");
    int bad;
    if (!fp) return errno ? errno : EIO;
    bad = fwrite(d, 1, n, fp) != n;
    if (bad) bad = errno ? errno : EIO;
    if (fclose(fp) != 0 && !bad) bad = errno ? errno : EIO;
    return bad;
}

/* -o FILE.glb / FILE.gltf: encode, the .bin and the file into their
   temporaries, then the .bin renamed, then the file.  *where names what
   failed. */
static bp_status write_gltf(const bpg_file *g, const bp_atlas *atlas, const char *input, const char *output,
                            const char *final, const bp_options *opt, bpg_output *info, const char **where, bp_error *err)
{
    bpg_write_options wo;
    bpg_output out;
    char bin_uri[1024] = "", bin_target[4096], bin_final[4096], prefix[4096];
    size_t n = strlen(output);
    bp_status st;
    int why = 0;
    uint32_t i;
    const char *base = last_separator(output), *x;
    memset(&wo, 0, sizeof wo);
    memset(err, 0, sizeof *err);
    wo.glb = n >= 4 && (output[n - 1] | 32) == 'b';
    wo.check = opt;
    base = base ? base + 1 : output;
    if (!wo.glb && (g->glb || g->num_buffer_files)) {     /* the new bytes go into OUT's name .bin */
        size_t stem = strlen(base) - 5;
        snprintf(bin_uri, sizeof bin_uri, "%.*s.bin", (int)stem, base);
        dir_of(output, bin_target, sizeof bin_target);
        snprintf(bin_target + strlen(bin_target), sizeof bin_target - strlen(bin_target), "%s", bin_uri);
        for (i = 0; (x = bpg_external_file(g, i)) != NULL; i++)
            if (same_file(x, bin_target) || same_file(input, bin_target)) {
                *where = output;
                snprintf(err->message, sizeof err->message,
                         "its new data would go into %s, which the input reads; choose another output name", bin_target);
                return BP_ERR_INVALID_ARGUMENT;
            }
        wo.bin_uri = bin_uri;
    }
    if (relative_dir(input, output, prefix, sizeof prefix) && prefix[0]) wo.uri_prefix = prefix;
    *where = output;
    if ((st = bpg_encode(g, atlas, &wo, &out, err)) != BP_OK) { *where = input; return st; }
    *info = out;
    info->data = info->bin = NULL;
    if (out.bin && !temp_create(temp_bin, &temp_bin_live, bin_target, bin_final, sizeof bin_final, &why)) {
        *where = bin_target;
        snprintf(err->message, sizeof err->message, "cannot create a file next to it: %s", strerror(why));
        bpg_output_free(&out);
        return BP_ERR_IO;
    }
    if (out.bin && (why = write_all(temp_bin, out.bin, out.bin_size)) != 0) *where = bin_target;
    else if ((why = write_all(temp_path, out.data, out.size)) != 0) *where = output;
    bpg_output_free(&out);
    if (why) {
        snprintf(err->message, sizeof err->message, "cannot write: %s", strerror(why));
        return BP_ERR_IO;
    }
    if (temp_bin_live && replace_file(temp_bin, bin_final) != 0) {
        *where = bin_target;
        snprintf(err->message, sizeof err->message, "cannot rename the finished result onto it: %s", strerror(errno));
        return BP_ERR_IO;
    }
    temp_bin_live = 0;
    if (replace_file(temp_path, final) != 0) {
        snprintf(err->message, sizeof err->message, "cannot rename the finished result onto it: %s", strerror(errno));
        return BP_ERR_IO;
    }
    temp_live = 0;
    return BP_OK;
}

/* Strict number parsing: the whole argument must be a finite number. */
static int parse_double(const char *s, double lo, double *out)
{
    char *end;
    double x;
    errno = 0;
    x = strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE || !isfinite(x) || x < lo)
        return 0;
    *out = x;
    return 1;
}

static int parse_int(const char *s, long lo, int *out)
{
    char *end;
    long x;
    errno = 0;
    x = strtol(s, &end, 10);
    if (end == s || *end != '\0' || errno == ERANGE || x < lo || x > 2147483647L)
        return 0;
    *out = (int)x;
    return 1;
}

/* JSON numbers: shortest exact round trip, and null for NaN / infinity. */
static void json_number(double x)
{
    if (isfinite(x)) printf("%.17g", x);
    else printf("null");
}

static void json_string(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') printf("\\%c", c);
        else if (c < 0x20) printf("\\u%04x", c);
        else putchar(c);
    }
    putchar('"');
}

/* ---- the demo mesh ------------------------------------------------------ */

/* A wavy cone (fig 3.3): apex at the origin, rim point at angle theta
   r(theta) = (cos theta, sin theta, H + A sin(K theta)).  Every ring of
   vertices is the rim scaled by t = i / RINGS, so the surface is ruled by
   lines through the apex and is developable: it can be flattened without
   any distortion.  The total angle at the apex is the length of r/|r| on the
   unit sphere; with H = 0.3, A = 0.3, K = 5 it is about 1.32 * 2 pi, so the
   distortion-free flattening wraps around the apex and overlaps itself by a
   third of a turn -- only the boundary barrier keeps the optimum bijective.
   The mesh is cut along the generator theta = 0 by giving the seam its own
   copy of each vertex (column SEGS duplicates column 0), which makes it a
   disk: SEGS + 2 SEGS (RINGS - 1) triangles (3008 here). */
enum { DEMO_SEGS = 64, DEMO_RINGS = 24 };

static int demo_mesh(bp_mesh *m)
{
    const double H = 0.3, A = 0.3, K = 5.0, two_pi = 6.283185307179586;
    const uint32_t cols = DEMO_SEGS + 1, nv = 1 + DEMO_RINGS * cols;
    const uint32_t nt = DEMO_SEGS + 2 * DEMO_SEGS * (DEMO_RINGS - 1);
    uint32_t i, j, t = 0;
    memset(m, 0, sizeof *m);
    m->positions = (double *)malloc(3 * (size_t)nv * sizeof(double));
    m->triangles = (uint32_t *)malloc(3 * (size_t)nt * sizeof(uint32_t));
    if (!m->positions || !m->triangles) {
        free(m->positions); free(m->triangles);
        m->positions = NULL; m->triangles = NULL;
        return 0;
    }
    m->num_vertices = nv;
    m->num_triangles = nt;
    m->num_faces = nt;
    m->positions[0] = m->positions[1] = m->positions[2] = 0.0; /* apex */
    for (i = 1; i <= DEMO_RINGS; i++)
        for (j = 0; j < cols; j++) {
            double s = (double)i / DEMO_RINGS, th = two_pi * (double)j / DEMO_SEGS;
            double *p = m->positions + 3 * (1 + (i - 1) * cols + j);
            if (j == DEMO_SEGS) th = 0.0; /* the seam copy sits on column 0 */
            p[0] = s * cos(th);
            p[1] = s * sin(th);
            p[2] = s * (H + A * sin(K * th));
        }
#define DEMO_V(i, j) (1 + ((i) - 1) * cols + (j))
    for (j = 0; j < DEMO_SEGS; j++) { /* apex fan */
        uint32_t *tri = m->triangles + 3 * t++;
        tri[0] = 0; tri[1] = DEMO_V(1, j); tri[2] = DEMO_V(1, j + 1);
    }
    for (i = 1; i < DEMO_RINGS; i++)
        for (j = 0; j < DEMO_SEGS; j++) {
            uint32_t a = DEMO_V(i, j), b = DEMO_V(i + 1, j);
            uint32_t c = DEMO_V(i + 1, j + 1), d = DEMO_V(i, j + 1);
            uint32_t *tri = m->triangles + 3 * t;
            tri[0] = a; tri[1] = b; tri[2] = c;
            tri[3] = a; tri[4] = c; tri[5] = d;
            t += 2;
        }
#undef DEMO_V
    return 1;
}

/* ---- per-chart facts for the report ------------------------------------- */

/* V - E + F of a chart, counting each undirected edge once (1 for a disk),
   from its triangles alone (not from its loops: the report checks the
   library's topology, it does not repeat it).  The corner edges are
   bucketed by their smaller vertex (a counting sort) and each bucket's
   larger ends counted once, marked with the bucket's vertex: linear in
   the corners, where a qsort of the edge keys would be serial and cost 2%
   of face's two-thread run. */
static long chart_euler(const bp_chart *c)
{
    size_t n = 3 * (size_t)c->num_triangles, k, i, edges = 0;
    uint32_t nv = c->num_vertices, v;
    uint32_t *start = (uint32_t *)calloc((size_t)nv + 2, sizeof *start);
    uint32_t *hi = (uint32_t *)malloc((n ? n : 1) * sizeof *hi);
    uint32_t *mark = (uint32_t *)malloc(((size_t)nv + 1) * sizeof *mark);
    if (!start || !hi || !mark) { free(start); free(hi); free(mark); return 0; }
    for (k = 0; k < n; k++) {
        uint32_t a = c->triangles[k], b = c->triangles[k - k % 3 + (k + 1) % 3];
        start[(a < b ? a : b) + 2]++;
    }
    for (v = 2; v <= nv + 1; v++) start[v] += start[v - 1];   /* start[v + 1]: where bucket v begins */
    for (k = 0; k < n; k++) {
        uint32_t a = c->triangles[k], b = c->triangles[k - k % 3 + (k + 1) % 3];
        hi[start[(a < b ? a : b) + 1]++] = a < b ? b : a;
    }
    for (v = 0; v < nv; v++) mark[v] = 0xffffffffu;
    for (v = 0; v < nv; v++)                                  /* filled: bucket v is [start[v], start[v+1]) */
        for (i = start[v]; i < start[v + 1]; i++)
            if (mark[hi[i]] != v) { mark[hi[i]] = v; edges++; }
    free(start); free(hi); free(mark);
    return (long)c->num_vertices - (long)edges + (long)c->num_triangles;
}

/* A chart-level failure (not out of memory, not a cancel) marks the chart
   as failed and lets the others go on, unless --strict. */
static int chart_failed(bp_atlas *atlas, uint32_t c, bp_status *st, bp_error *err, int strict)
{
    if (*st == BP_OK || *st == BP_ERR_OUT_OF_MEMORY || *st == BP_ERR_CANCELLED || *st == BP_ERR_IO || strict)
        return 0;
    bp_atlas_fail_chart(atlas, c, err);
    *st = BP_OK;
    return 1;
}

/* ---- progress and trace ------------------------------------------------- */

/* --frames: an SVG of the chart every `every` iterations, and snapshots of
   the largest chart (iterations 0, K, 2K, 4K, ... and the last) for the
   strip.  The callback reads the chart's uv, which the header documents as
   the current, exactly valid map during the call. */
enum { MAX_SNAPS = 40 };

typedef struct frames_state {
    const char *dir;
    int every;
    const bp_mesh *mesh;
    bp_atlas *atlas;
    bpd_svg_options svg;
    uint32_t strip_chart;            /* the chart with the most triangles */
    int nsnap, next_snap;            /* next_snap: next iteration to keep  */
    double *snap[MAX_SNAPS];
    int snap_iter[MAX_SNAPS];
    double snap_energy[MAX_SNAPS];
    int error;                       /* errno of a failed write, else 0   */
    char error_path[1100];
} frames_state;

typedef struct run_state {
    FILE    *trace;
    int      tty;              /* draw the progress bar (stderr is a terminal, no --quiet) */
    double   start;
    uint32_t num_charts;
    frames_state *frames;
    /* the progress bar: the run's fraction of each stage */
    uint32_t chart;            /* the chart being solved                   */
    double   tris_before, tris_chart, tris_total;   /* charts before it, it, all */
    int      drawn;            /* last percentage drawn (-1: none), and its stage */
    bp_stage drawn_stage;
    int      bar_visible;
    double   start_done_cpu;   /* the process's CPU seconds at start_done */
    double   start_done;       /* when the chart's start map was done (the
                                  split of bp_chart_solve's time)          */
    int      together;         /* the charts solved at once (bp_atlas_solve) */
} run_state;

/* The one-line progress bar (stderr, only on a terminal): the stage, a bar
   of its fraction, and for the solve the chart.  Redrawn only when the
   percentage or the stage changes.  Start and optimize of one chart are
   shown as the share of the mesh's triangles in the charts done so far. */
static void draw_bar(run_state *rs, bp_stage s, double f)
{
    char bar[31];
    int pct, i;
    if (s == BP_STAGE_START && rs->together) s = BP_STAGE_OPTIMIZE;   /* one bar for both: they interleave */
    if (s == BP_STAGE_START || s == BP_STAGE_OPTIMIZE)
        f = rs->tris_total > 0 ? (rs->tris_before + f * rs->tris_chart) / rs->tris_total : f;
    if (f < 0) f = 0;
    if (f > 1) f = 1;
    pct = (int)(100 * f);
    if (pct == rs->drawn && s == rs->drawn_stage) return;
    rs->drawn = pct;
    rs->drawn_stage = s;
    for (i = 0; i < 30; i++) bar[i] = i < (int)(30 * f) ? '#' : '.';
    bar[30] = 0;
    if ((s == BP_STAGE_START || s == BP_STAGE_OPTIMIZE) && rs->together)
        fprintf(stderr, "\rbijparam: %-10s [%s] %3d%%  %u charts   ", "solve", bar, pct, (unsigned)rs->num_charts);
    else if (s == BP_STAGE_START || s == BP_STAGE_OPTIMIZE)
        fprintf(stderr, "\rbijparam: %-10s [%s] %3d%%  chart %u/%u   ", bp_stage_name(s), bar, pct,
                (unsigned)rs->chart + 1, (unsigned)rs->num_charts);
    else
        fprintf(stderr, "\rbijparam: %-10s [%s] %3d%%                 ", bp_stage_name(s), bar, pct);
    rs->bar_visible = 1;
}

/* Clear the bar's line (before any other message on stderr). */
static void clear_bar(run_state *rs)
{
    if (rs->bar_visible) fprintf(stderr, "\r%70s\r", "");
    rs->bar_visible = 0;
}

/* bp_options.run_progress: the bar, and the cancel on SIGINT. */
static int on_run_progress(void *user, bp_stage s, double f, uint32_t chart)
{
    run_state *rs = (run_state *)user;
    (void)chart;
    if (s == BP_STAGE_START && f >= 1) { rs->start_done = now_seconds(); rs->start_done_cpu = cpu_seconds(); }
    if (rs->tty) draw_bar(rs, s, f);
    return interrupted != 0;
}

/* One frame: DIR/chartC_iterNNNNN.svg of the chart's current map. */
static int write_frame(frames_state *fs, uint32_t c, int iteration, double energy)
{
    char path[1100], label[80];
    const char *labels[1];
    const double *uvs[1];
    const bp_chart *ch = &fs->atlas->charts[c];
    snprintf(path, sizeof path, "%s/chart%u_iter%05d.svg", fs->dir, (unsigned)c, iteration);
    snprintf(label, sizeof label, "chart %u, iteration %d, mean energy %.5g", (unsigned)c, iteration, energy);
    labels[0] = label;
    uvs[0] = ch->uv;
    if (!bpd_write_strip_svg(path, fs->mesh, ch, uvs, labels, 1, &fs->svg)) {
        fs->error = errno ? errno : EIO;
        snprintf(fs->error_path, sizeof fs->error_path, "%s", path);
        return 0;
    }
    return 1;
}

/* Keep a copy of the strip chart's map (iteration 0, K, 2K, 4K, ...; `last`
   always, replacing a previous copy of the same iteration). */
static void keep_snapshot(frames_state *fs, uint32_t c, int iteration, double energy, int last)
{
    const bp_chart *ch = &fs->atlas->charts[c];
    size_t n = 2 * (size_t)ch->num_vertices;
    int k;
    if (c != fs->strip_chart || !ch->uv) return;
    if (!last && iteration != fs->next_snap) return;
    if (fs->nsnap > 0 && fs->snap_iter[fs->nsnap - 1] == iteration) return;
    if (fs->nsnap == MAX_SNAPS) { free(fs->snap[MAX_SNAPS - 1]); fs->nsnap--; }
    k = fs->nsnap;
    if (!(fs->snap[k] = (double *)malloc(n * sizeof(double)))) return;  /* the strip just has fewer */
    memcpy(fs->snap[k], ch->uv, n * sizeof(double));
    fs->snap_iter[k] = iteration;
    fs->snap_energy[k] = energy;
    fs->nsnap++;
    if (iteration >= fs->next_snap)
        fs->next_snap = iteration == 0 ? fs->every : 2 * iteration;
}

/* DIR/strip.svg: at most 6 snapshots, evenly spread over the kept ones. */
static int write_strip(frames_state *fs)
{
    char path[1100], text[6][80], title[160];
    const double *uvs[6];
    const char *labels[6];
    int n = fs->nsnap < 6 ? fs->nsnap : 6, k;
    bpd_svg_options o = fs->svg;
    if (n == 0) return 1;
    for (k = 0; k < n; k++) {
        int j = n == 1 ? 0 : (int)((double)k * (fs->nsnap - 1) / (n - 1) + 0.5);
        uvs[k] = fs->snap[j];
        snprintf(text[k], sizeof text[k], "iteration %d: %.4g", fs->snap_iter[j], fs->snap_energy[j]);
        labels[k] = text[k];
    }
    snprintf(title, sizeof title, "chart %u during the optimization (mean %s energy under each)",
             (unsigned)fs->strip_chart, bp_energy_name(o.energy));
    o.title = title;
    o.size = 1200;
    o.quantile = 0.98;               /* the start map's worst triangles would
                                        wash out the colours of the rest */
    snprintf(path, sizeof path, "%s/strip.svg", fs->dir);
    if (!bpd_write_strip_svg(path, fs->mesh, &fs->atlas->charts[fs->strip_chart], uvs, labels, n, &o)) {
        fs->error = errno ? errno : EIO;
        snprintf(fs->error_path, sizeof fs->error_path, "%s", path);
        return 0;
    }
    return 1;
}

static int on_progress(void *user, uint32_t chart, int iteration,
                       double mean_energy, double step)
{
    run_state *rs = (run_state *)user;
    double t = now_seconds() - rs->start;
    if (rs->trace)
        fprintf(rs->trace, "%u %d %.6f %.17g %.17g %.6f\n", (unsigned)chart,
                iteration, t, mean_energy, step, cpu_seconds());
    if (rs->frames) {
        frames_state *fs = rs->frames;
        keep_snapshot(fs, chart, iteration, mean_energy, 0);
        if (iteration % fs->every == 0 && !write_frame(fs, chart, iteration, mean_energy))
            return 1;                  /* cancel: the write error is reported */
    }
    return 0;
}

/* ---- extreme scales ------------------------------------------------------

   The map does not depend on the mesh's scale, but the arithmetic does:
   rest shapes and energies multiply squared lengths, which overflow above
   about 1e77 and underflow below 1e-77.  bp_parameterize solves such a
   mesh on a copy rescaled by a power of two; the step-by-step calls below
   work in the mesh's own units, so the tool does the same: a mesh whose
   size (the largest side of the box of the vertices its triangles use) is
   beyond 2^+-100 is solved with its positions -- and the pins, the input
   uvs and --epsilon, which are lengths in the same units -- times 2^k, k
   bringing the size near 1.  A power of two is exact, so the copy is the
   same shape.  The map comes back times 2^-k, exact too unless a
   coordinate leaves the normal range (then that chart fails, saying so);
   with --atlas or --normalize it is in [0,1]^2 and stays there.  Meshes
   of ordinary size are solved as given, bit for bit. */
typedef struct rescale {
    int k;                      /* 0: the mesh is solved as given          */
    double *pos, *uvs;          /* the user's arrays, while the mesh holds copies */
} rescale;

static int size_exponent(const bp_mesh *m)
{
    double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL }, size = 0;
    uint32_t t;
    int k, e;
    for (t = 0; t < 3 * m->num_triangles; t++) {
        const double *p = m->positions + 3 * (size_t)m->triangles[t];
        if (m->triangles[t] >= m->num_vertices) return 0;     /* the library names it */
        for (k = 0; k < 3; k++) {
            if (!isfinite(p[k])) return 0;
            if (p[k] < lo[k]) lo[k] = p[k];
            if (p[k] > hi[k]) hi[k] = p[k];
        }
    }
    for (k = 0; k < 3; k++)            /* halves first: hi - lo may overflow */
        if (hi[k] >= lo[k] && 0.5 * hi[k] - 0.5 * lo[k] > size) size = 0.5 * hi[k] - 0.5 * lo[k];
    if (!(size > 0)) return 0;
    (void)frexp(size, &e);             /* 2^(e-1) <= size < 2^e: the whole side is below 2^(e+1) */
    return e + 1 > 100 || e + 1 < -100 ? -(e + 1) : 0;
}

/* Positions and uvs times 2^k into copies held by the mesh (the user's
   arrays kept in r), epsilon in place (the pins, read later, follow r->k).
   0 if out of memory. */
static int rescale_mesh(bp_mesh *m, bp_options *opt, rescale *r)
{
    size_t i;
    double *pos, *uvs = NULL;
    memset(r, 0, sizeof *r);
    r->k = size_exponent(m);
    if (!r->k) return 1;
    pos = (double *)malloc(3 * (size_t)m->num_vertices * sizeof(double) + 1);
    if (m->uvs && m->num_uvs) uvs = (double *)malloc(2 * (size_t)m->num_uvs * sizeof(double));
    if (!pos || (m->uvs && m->num_uvs && !uvs)) { free(pos); free(uvs); r->k = 0; return 0; }
    for (i = 0; i < 3 * (size_t)m->num_vertices; i++) pos[i] = ldexp(m->positions[i], r->k);
    for (i = 0; uvs && i < 2 * (size_t)m->num_uvs; i++) uvs[i] = ldexp(m->uvs[i], r->k);
    r->pos = m->positions;
    m->positions = pos;
    if (uvs) { r->uvs = m->uvs; m->uvs = uvs; }
    if (opt->epsilon > 0) opt->epsilon = ldexp(opt->epsilon, r->k);
    return 1;
}

/* The user's positions and uvs back in the mesh; the map (unless it is in
   [0,1]^2), the charts' areas and repaired rest shapes times 2^-k. */
static void unscale(bp_mesh *m, bp_atlas *at, rescale *r, int normalized)
{
    uint32_t c, i;
    if (!r->k) return;
    free(m->positions);
    m->positions = r->pos;
    if (r->uvs) { free(m->uvs); m->uvs = r->uvs; }
    for (c = 0; c < at->num_charts; c++) {
        bp_chart *ch = &at->charts[c];
        int exact = 1;
        ch->area3d = ldexp(ch->area3d, -2 * r->k);
        for (i = 0; ch->rest_side && i < ch->num_triangles; i++) ch->rest_side[i] = ldexp(ch->rest_side[i], -r->k);
        if (!ch->uv || normalized) continue;
        for (i = 0; i < 2 * ch->num_vertices && exact; i++) exact = ldexp(ldexp(ch->uv[i], -r->k), r->k) == ch->uv[i];
        if (exact) for (i = 0; i < 2 * ch->num_vertices; i++) ch->uv[i] = ldexp(ch->uv[i], -r->k);
        else {
            bp_error why;
            memset(&why, 0, sizeof why);
            why.status = BP_ERR_NUMERICAL;
            why.element = BP_ELEMENT_CHART;
            why.index = c;
            why.index2 = -1;
            snprintf(why.message, sizeof why.message, "chart %u: solved on the mesh rescaled by 2^%d, its map "
                     "underflows or overflows at the mesh's size: use --atlas or --normalize", (unsigned)c, r->k);
            bp_atlas_fail_chart(at, c, &why);
        }
    }
    r->k = 0;
}

/* ---- the JSON report ---------------------------------------------------- */

/* Seconds per stage: "cut" is bp_atlas_build (gluing, repairs, the
   automatic seams), "segment" bp_atlas_segment; the report's "charts" is
   their sum. */
typedef struct timings { double read, cut, segment, init, optimize, pack, write; } timings;

/* The wall and the CPU seconds (all threads) of the stages. */
typedef struct stage_clock { timings wall, cpu; double t0, c0; } stage_clock;

static void stage_start(stage_clock *k)
{
    k->t0 = now_seconds();
    k->c0 = cpu_seconds();
}

/* The time since stage_start, added to the field at byte offset `at` of
   both tables (offsetof(timings, read) ...). */
static void stage_add(stage_clock *k, size_t at)
{
    *(double *)((char *)&k->wall + at) += now_seconds() - k->t0;
    *(double *)((char *)&k->cpu + at) += cpu_seconds() - k->c0;
}

typedef struct extra_report {
    const char *format;                /* "obj", "off", "ply", "gltf", "glb"; NULL: the demo mesh */
    const bpg_output *gltf;            /* a glTF written: its vertices, NULL else */
    int threads;
    int resolution, padding;           /* --atlas, --padding (0, 0 without --atlas) */
    int density_model;                 /* 0: no density report */
    double density_map, density_iso;
} extra_report;

/* "repairs": the defects the library mended (not --strict): per kind the
   count, the first elements numbered as the file does (triangles from 1;
   an edge as its two vertices from 1; a duplicate as [copy, kept]) and the
   library's sentence naming them.  "flipped" also has "written_reordered":
   how many of those triangles the output file lists with their corners in
   the repaired order (all of them when a file was written, else 0): the
   faces where OUT's winding differs from the input's. */
static void print_json_repairs(const bp_repair_report *r, int written)
{
    int k;
    uint32_t i;
    printf("\"repairs\":{\"total\":%u", (unsigned)r->total);
    for (k = 0; k < BP_REPAIR_KINDS; k++) {
        const bp_repair *p = &r->kind[k];
        uint32_t n = p->count < BP_REPAIR_FIRST ? p->count : BP_REPAIR_FIRST;
        printf(",\"%s\":{\"count\":%u,\"first\":[", bp_repair_name((bp_repair_kind)k), (unsigned)p->count);
        for (i = 0; i < n; i++) {
            if (p->first2[i] >= 0)
                printf("%s[%lld,%lld]", i ? "," : "", (long long)p->first[i] + 1, (long long)p->first2[i] + 1);
            else
                printf("%s%lld", i ? "," : "", (long long)p->first[i] + 1);
        }
        printf("]");
        if (k == BP_REPAIR_FLIPPED) printf(",\"written_reordered\":%u", written ? (unsigned)p->count : 0u);
        printf(",\"message\":");
        json_string(p->message);
        printf("}");
    }
    printf("}");
}

static void print_timings(const timings *t)
{
    printf("{\"read\":");
    json_number(t->read);
    printf(",\"charts\":");
    json_number(t->cut + t->segment);
    printf(",\"cut\":");
    json_number(t->cut);
    printf(",\"segment\":");
    json_number(t->segment);
    printf(",\"init\":");
    json_number(t->init);
    printf(",\"optimize\":");
    json_number(t->optimize);
    printf(",\"pack\":");
    json_number(t->pack);
    printf(",\"write\":");
    json_number(t->write);
    printf("}");
}

/* The seams: mesh edges with a chart boundary on both sides (a boundary
   edge of a chart is a seam when another chart boundary edge runs between
   the same two mesh vertices; alone, it is the mesh's own boundary).
   Their 3D length, and that over the square root of the mesh's area (a
   measure free of the mesh's scale: the seams of a sphere of area A cut
   into k round charts are about sqrt(k pi A)).  0 when out of memory. */
typedef struct seam_edge { uint32_t lo, hi; } seam_edge;

static int seam_edge_cmp(const void *pa, const void *pb)
{
    const seam_edge *a = (const seam_edge *)pa, *b = (const seam_edge *)pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    return (a->hi > b->hi) - (a->hi < b->hi);
}

static int seam_stats(const bp_mesh *m, const bp_atlas *at, double *edges, double *length, double *relative)
{
    size_t n = 0, i, j;
    uint32_t c, l, k, t;
    double area = 0;
    seam_edge *e;
    *edges = *length = *relative = 0;
    for (c = 0; c < at->num_charts; c++)
        if (at->charts[c].num_loops) n += at->charts[c].loop_start[at->charts[c].num_loops];
    e = (seam_edge *)malloc((n ? n : 1) * sizeof *e);
    if (!e) return 0;
    for (c = 0, n = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        for (l = 0; l < ch->num_loops; l++) {
            uint32_t a0 = ch->loop_start[l], a1 = ch->loop_start[l + 1];
            for (k = a0; k < a1; k++) {
                uint32_t u = ch->vertex[ch->loop_vertices[k]], v = ch->vertex[ch->loop_vertices[k + 1 < a1 ? k + 1 : a0]];
                e[n].lo = u < v ? u : v;
                e[n].hi = u < v ? v : u;
                n++;
            }
        }
    }
    qsort(e, n, sizeof *e, seam_edge_cmp);
    for (i = 0; i < n; i = j) {
        for (j = i + 1; j < n && e[j].lo == e[i].lo && e[j].hi == e[i].hi; j++) {}
        if (j - i >= 2) {
            const double *p = m->positions + 3 * (size_t)e[i].lo, *q = m->positions + 3 * (size_t)e[i].hi;
            double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
            *edges += (double)((j - i) / 2);
            *length += (double)((j - i) / 2) * sqrt(dx * dx + dy * dy + dz * dz);
        }
    }
    free(e);
    for (t = 0; t < m->num_triangles; t++) {
        const uint32_t *tr = m->triangles + 3 * (size_t)t;
        const double *a = m->positions + 3 * (size_t)tr[0], *b = m->positions + 3 * (size_t)tr[1],
                     *d = m->positions + 3 * (size_t)tr[2];
        double u[3], v[3], x, y, z;
        for (k = 0; k < 3; k++) { u[k] = b[k] - a[k]; v[k] = d[k] - a[k]; }
        x = u[1] * v[2] - u[2] * v[1]; y = u[2] * v[0] - u[0] * v[2]; z = u[0] * v[1] - u[1] * v[0];
        area += 0.5 * sqrt(x * x + y * y + z * z);
    }
    if (area > 0) *relative = *length / sqrt(area);
    return 1;
}

static void print_json(const char *input, const char *output, bp_status status, const char *message,
                       const bp_mesh *mesh, const bp_atlas *atlas, const bp_options *opt,
                       const stage_clock *sc, const extra_report *ex)
{
    uint32_t c, l;
    printf("{\"input\":");
    json_string(input);
    printf(",\"format\":");              /* the format read, or null (demo) */
    if (ex->format) json_string(ex->format);
    else printf("null");
    printf(",\"output\":");              /* the file written, or null */
    if (output) json_string(output);
    else printf("null");
    printf(",\"status\":");
    json_string(bp_status_string(status));
    if (message) { printf(",\"error\":"); json_string(message); }
    printf(",\"charts\":%u,\"failed_charts\":%u,\"split_vertices\":%u,",
           (unsigned)atlas->num_charts, (unsigned)atlas->num_failed, (unsigned)atlas->num_split);
    print_json_repairs(&atlas->repairs, output != NULL);
    printf(",\"per_chart\":[");
    for (c = 0; c < atlas->num_charts; c++) {
        const bp_chart *ch = atlas->charts + c;
        bp_check_report rep;
        double e_start = ch->energy_start, e_end = ch->energy_end, e_max = ch->energy_max;
        memset(&rep, 0, sizeof rep);
        if (ch->uv)                      /* on the run's threads: the same report */
            bp_check_opt(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices,
                         opt, &rep, NULL);
        /* not optimized (--init-only): report the distortion of the start map */
        if (ch->uv && ch->stop == BP_STOP_NONE &&
            bp_chart_distortion(ch, mesh, opt->energy, &e_start, &e_max, NULL, NULL) == BP_OK)
            e_end = e_start;
        printf("%s{\"index\":%u,\"vertices\":%u,\"faces\":%u,\"loops\":[",
               c ? "," : "", (unsigned)c, (unsigned)ch->num_vertices,
               (unsigned)ch->num_triangles);
        for (l = 0; l < ch->num_loops; l++)
            printf("%s%u", l ? "," : "",
                   (unsigned)(ch->loop_start[l + 1] - ch->loop_start[l]));
        printf("],\"euler\":%ld,\"split_vertices\":%u,\"cut_edges\":%u,\"energy_start\":",
               chart_euler(ch), (unsigned)ch->split_vertices, (unsigned)ch->cut_edges);
        json_number(e_start);
        printf(",\"energy_end\":");
        json_number(e_end);
        printf(",\"energy_max\":");
        json_number(e_max);
        printf(",\"iterations\":%d,\"stop\":", ch->iterations);
        json_string(bp_stop_string(ch->stop));
        printf(",\"error\":");
        if (ch->error.status != BP_OK) json_string(ch->error.message);
        else printf("null");
        printf(",\"init_used\":%d,\"start_map\":", ch->init_used);
        if (!ch->uv) printf("null");           /* no map (the chart failed before or in its start) */
        else
            json_string(ch->start_map == BP_INIT_CONFORMAL ? "conformal" : ch->start_map == BP_INIT_MEAN_VALUE ? "mvc" :
                        ch->start_map == BP_INIT_TUTTE ? "tutte" : ch->start_map == BP_INIT_INPUT ? "input" : "planar");
        printf(",\"direction\":");                /* the direction the solve ran (the default's choice) */
        if (ch->direction == BP_DIRECTION_DEFAULT) printf("null");    /* not optimized (--init-only, a failure) */
        else
            json_string(ch->direction == BP_DIRECTION_NEWTON ? "newton" : ch->direction == BP_DIRECTION_PRECONDITIONED
                        ? "precond" : ch->direction == BP_DIRECTION_GRADIENT ? "gd" : "lbfgs");
        printf(",\"pins\":%u,\"in_place\":%d,\"seconds\":", (unsigned)ch->num_pins, ch->in_place);
        json_number(ch->seconds);
        if (ch->uv)
            printf(",\"flipped\":%u,\"degenerate\":%u,\"boundary_intersections\":%u}",
                   (unsigned)rep.flipped, (unsigned)rep.degenerate,
                   (unsigned)rep.boundary_intersections);
        else
            printf(",\"flipped\":null,\"degenerate\":null,\"boundary_intersections\":null}");
    }
    printf("],\"timings\":");
    print_timings(&sc->wall);
    printf(",\"cpu_timings\":");
    print_timings(&sc->cpu);
    printf(",\"atlas_resolution\":%d,\"padding\":%d,\"utilization\":", ex->resolution, ex->padding);
    json_number(atlas->utilization);
    printf(",\"threads\":%d,\"peak_rss_bytes\":", ex->threads);
    json_number(peak_rss_bytes());
    printf(",\"bytes_per_face\":");
    json_number(mesh->num_triangles ? peak_rss_bytes() / mesh->num_triangles : 0);
    {   /* after the peak memory: this adds its own */
        double edges, length, relative;
        if (seam_stats(mesh, atlas, &edges, &length, &relative)) {
            printf(",\"seams\":{\"edges\":%.0f,\"length\":", edges);
            json_number(length);
            printf(",\"relative\":");
            json_number(relative);
            printf("}");
        }
    }
    if (ex->gltf)
        printf(",\"gltf\":{\"primitives\":%u,\"vertices_in\":%u,\"vertices_out\":%u,\"rounding_fixed\":%u,"
               "\"accessors_removed\":%u,\"views_removed\":%u,\"bytes_removed\":%llu}",
               gltf_names ? (unsigned)gltf_names->num_primitives : 0u, (unsigned)ex->gltf->vertices_in,
               (unsigned)ex->gltf->vertices_out, (unsigned)ex->gltf->rounding_fixed, (unsigned)ex->gltf->accessors_removed,
               (unsigned)ex->gltf->views_removed, (unsigned long long)ex->gltf->bytes_removed);
    if (ex->density_model) {
        printf(",\"density\":{\"model\":");
        json_string(view_names[ex->density_model]);
        printf(",\"map_det\":");
        json_number(ex->density_map);
        printf(",\"isometric_det\":");
        json_number(ex->density_iso);
        printf(",\"ratio\":");
        json_number(ex->density_map > 0 ? ex->density_iso / ex->density_map : 0);
        printf("}");
    }
    printf("}\n");
}

/* ---- main --------------------------------------------------------------- */

/* ---- --check: the exact check of the file's own vt charts ----------------

   Nothing is optimized or written: the charts are the file's (edges cut
   where the vt indices differ, bp_atlas_build), each chart's coordinates
   are the file's vt (chart.vertex_uv), and bp_check decides each chart,
   then all charts together (two charts overlapping).  Elements are named
   as the file numbers them: faces and lines, vertices and vt from 1. */

typedef struct check_names {
    const bp_mesh *m;
    const bp_atlas *at;
    const uint32_t *first;    /* first global vertex of each chart (all-charts check) */
} check_names;

/* "vertex 12 (vt 40)" for chart c's vertex i */
static void name_vertex(const check_names *N, uint32_t c, uint32_t i, char *out, size_t cap)
{
    const bp_chart *ch = &N->at->charts[c];
    if (gltf_names) { bpg_name_vertex(gltf_names, ch->vertex[i], out, cap); return; }
    snprintf(out, cap, "vertex %lu (vt %lu)", (unsigned long)ch->vertex[i] + 1, (unsigned long)ch->vertex_uv[i] + 1);
}

/* "face 17 (line 2045), vertices 5 6 7 (vt 8 9 10)" for chart c's triangle t */
static void name_face(const check_names *N, uint32_t c, uint32_t t, char *out, size_t cap)
{
    const bp_chart *ch = &N->at->charts[c];
    const uint32_t *tr = ch->triangles + 3 * (size_t)t;
    uint32_t f = ch->face[t], face = N->m->triangle_face ? N->m->triangle_face[f] : f;
    char line[32] = "";
    if (gltf_names) { bpg_name_triangle(gltf_names, f, out, cap); return; }
    if (N->m->triangle_line) snprintf(line, sizeof line, " (line %lu)", (unsigned long)N->m->triangle_line[f]);
    snprintf(out, cap, "face %lu%s, vertices %lu %lu %lu (vt %lu %lu %lu)", (unsigned long)face + 1, line,
             (unsigned long)ch->vertex[tr[0]] + 1, (unsigned long)ch->vertex[tr[1]] + 1,
             (unsigned long)ch->vertex[tr[2]] + 1, (unsigned long)ch->vertex_uv[tr[0]] + 1,
             (unsigned long)ch->vertex_uv[tr[1]] + 1, (unsigned long)ch->vertex_uv[tr[2]] + 1);
}

/* global vertex -> (chart, local) of the all-charts check */
static uint32_t chart_of(const check_names *N, int64_t g, uint32_t *local)
{
    uint32_t c = 0;
    while (c + 1 < N->at->num_charts && N->first[c + 1] <= (uint64_t)g) c++;
    *local = (uint32_t)(g - N->first[c]);
    return c;
}

/* One line naming what bp_check found first.  tri_chart / tri_local: the
   chart and triangle of err->index for a triangle; vertices are mapped
   through N->first when given (the all-charts check), else belong to c. */
static void explain(const check_names *N, uint32_t c, const double *uv, const uint32_t *tris,
                    const bp_check_report *r, const bp_error *e, uint32_t tri_chart, uint32_t tri_local)
{
    char a[160], b[160];
    uint32_t ca = c, cb = c, la, lb;
    if (e->element == BP_ELEMENT_TRIANGLE) {
        const uint32_t *tr = tris + 3 * (size_t)e->index;
        const char *what = r->nonfinite ? "has a NaN or infinite vt coordinate"
                         : bp_orient2d(uv + 2 * (size_t)tr[0], uv + 2 * (size_t)tr[1], uv + 2 * (size_t)tr[2]) < 0
                               ? "is flipped (negative area in UV)" : "has zero area in UV";
        name_face(N, tri_chart, tri_local, a, sizeof a);
        printf("    first bad triangle: %s %s\n", a, what);
        return;
    }
    la = (uint32_t)e->index;
    lb = (uint32_t)(e->index2 >= 0 ? e->index2 : 0);
    if (N->first) { ca = chart_of(N, e->index, &la); if (e->index2 >= 0) cb = chart_of(N, e->index2, &lb); }
    name_vertex(N, ca, la, a, sizeof a);
    if (e->index2 >= 0) name_vertex(N, cb, lb, b, sizeof b);
    if (e->status == BP_ERR_NONMANIFOLD || e->status == BP_ERR_ORIENTATION)
        printf("    the edge %s - %s is used by more than two faces or twice in one direction\n", a, b);
    else if (r->boundary_intersections) {
        uint32_t cc = c, lc = (uint32_t)r->first_bad_edge[1];
        char d[160];
        if (N->first) cc = chart_of(N, r->first_bad_edge[1], &lc);
        name_vertex(N, cc, lc, d, sizeof d);
        printf("    boundary edges meet: the edge %s - %s and the edge from %s%s%s\n", a, b, d,
               N->first && ca != cc ? " (another chart)" : "",
               !strcmp(a, d) ? " (one file vertex and vt used twice on the boundary: the chart is pinched there)" : "");
    } else if (r->nested)
        printf("    the piece with %s lies on the piece with %s\n", a, b);
    else
        printf("    at %s: the boundary is pinched, or the piece is mirrored or wraps around twice\n", a);
}

static int run_check(const char *input, int texcoord)
{
    bp_mesh mesh;
    bpg_file gltf;
    bp_atlas at;
    bp_options opt;
    bp_error err;
    bp_status st;
    check_names N;
    uint32_t c, i, bad = 0, nt = 0, nv = 0, *tri = NULL, *first = NULL;
    double *all = NULL;
    int overlap = 0;
    bp_options_init(&opt);             /* threads 0: the checks on all cores */
    memset(&at, 0, sizeof at);
    st = read_input(input, &mesh, &gltf, texcoord, &opt, &err);
    if (st != BP_OK) { report_error(input, &err); return 1; }
    if (!mesh.corner_uv || !mesh.uvs || (gltf_names && !gltf.has_uv)) {
        fprintf(stderr, "bijparam: error: %s: --check needs texture coordinates (%s)\n", input,
                gltf_names ? "TEXCOORD_n in every triangle primitive" : "vt in every face");
        free_input(&mesh, &gltf);
        return 1;
    }
    st = bp_atlas_build(&at, &mesh, &opt, &err);
    if (st != BP_OK && st != BP_ERR_CHARTS_FAILED) { report_error(input, &err); free_input(&mesh, &gltf); return 1; }
    N.m = &mesh; N.at = &at; N.first = NULL;
    printf("%s: %u charts from its vt, %u faces\n", input, (unsigned)at.num_charts, (unsigned)mesh.num_faces);
    first = (uint32_t *)calloc((size_t)at.num_charts + 1, sizeof *first);
    for (c = 0; c < at.num_charts; c++) { nt += at.charts[c].num_triangles; nv += at.charts[c].num_vertices; }
    tri = (uint32_t *)malloc(3 * (size_t)nt * sizeof *tri + 1);
    all = (double *)malloc(2 * (size_t)nv * sizeof *all + 1);
    if (!first || !tri || !all) { fprintf(stderr, "bijparam: error: out of memory\n"); bad = 1; goto done; }
    nt = nv = 0;
    for (c = 0; c < at.num_charts; c++) {
        const bp_chart *ch = &at.charts[c];
        bp_check_report r;
        bp_error e;
        double *uv = all + 2 * (size_t)nv;
        first[c] = nv;
        for (i = 0; i < ch->num_vertices; i++) {
            uv[2 * i] = mesh.uvs[2 * (size_t)ch->vertex_uv[i]];
            uv[2 * i + 1] = mesh.uvs[2 * (size_t)ch->vertex_uv[i] + 1];
        }
        for (i = 0; i < 3 * ch->num_triangles; i++) tri[3 * (size_t)nt + i] = ch->triangles[i] + nv;
        nt += ch->num_triangles;
        nv += ch->num_vertices;
        if (ch->error.status != BP_OK) {          /* closed or higher-genus chart */
            printf("chart %u: %u faces: NOT bijective: %s\n", (unsigned)c, (unsigned)ch->num_triangles, ch->error.message);
            bad++;
            continue;
        }
        st = bp_check_opt(ch->triangles, ch->num_triangles, uv, ch->num_vertices, &opt, &r, &e);
        if (st == BP_OK) {
            printf("chart %u: %u faces: bijective\n", (unsigned)c, (unsigned)ch->num_triangles);
            continue;
        }
        bad++;
        printf("chart %u: %u faces: NOT bijective (%s): %u flipped, %u degenerate, %u with NaN/Inf, "
               "%u boundary intersections, %u loop problems, %u nested pieces\n", (unsigned)c,
               (unsigned)ch->num_triangles, bp_status_string(st), r.flipped, r.degenerate, r.nonfinite,
               r.boundary_intersections, r.loop_orientation, r.nested);
        explain(&N, c, uv, ch->triangles, &r, &e, c, (uint32_t)(e.index >= 0 ? e.index : 0));
    }
    first[at.num_charts] = nv;
    if (!bad && at.num_charts > 1) {
        bp_check_report r;
        bp_error e;
        st = bp_check_opt(tri, nt, all, nv, &opt, &r, &e);
        if (st != BP_OK) {
            uint32_t tc = 0, tl = 0;
            overlap = 1;
            N.first = first;
            if (e.element == BP_ELEMENT_TRIANGLE) {
                uint32_t t = (uint32_t)e.index;
                while (tc + 1 < at.num_charts && t >= at.charts[tc].num_triangles) { t -= at.charts[tc].num_triangles; tc++; }
                tl = t;
            }
            printf("all charts together: charts overlap (%s): %u boundary intersections, %u nested pieces\n",
                   bp_status_string(st), r.boundary_intersections, r.nested);
            explain(&N, 0, all, tri, &r, &e, tc, tl);
        } else {
            printf("all charts together: no two charts overlap\n");
        }
    }
    if (bad || overlap)
        printf("result: NOT bijective (%u of %u charts fail%s)\n", (unsigned)bad, (unsigned)at.num_charts,
               overlap ? ", charts overlap" : "");
    else
        printf("result: bijective (%u charts, none overlapping)\n", (unsigned)at.num_charts);
done:
    free(first); free(tri); free(all);
    bp_atlas_free(&at);
    free_input(&mesh, &gltf);
    return bad || overlap ? 1 : 0;
}

int main(int argc, char **argv)
{
    bp_options opt;
    bp_pool *pool = NULL;              /* one pool for every stage (step 0) */
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_status st = BP_OK;
    stage_clock sc;
    rescale scale;
    run_state rs;
    const char *input = NULL, *output = NULL, *trace_path = NULL, *importance_path = NULL, *pin_path = NULL, *where;
    extra_report ex;
    double *importance = NULL;
    bp_pin *pins = NULL;
    int elevation_set = 0;
    const char *svg_path = NULL, *png_path = NULL;
    bpd_svg_options svg_opt;
    bpd_render_options png_opt;
    frames_state fs;
    char final_path[4096];
    bpg_file gltf;                     /* a glTF input (examples/bp_gltf.h) */
    bpg_output gltf_out;               /* what writing it reports            */
    int texcoord = 0;
    int json = 0, demo = 0, have_mesh = 0, i, status = 0, segmented = 0, together = 0, force = 0, quiet = 0, wrote = 0, check = 0, repack = 0, padding_set = 0;
    uint32_t c;

    keep_freed_memory();
    bp_options_init(&opt);
    memset(&mesh, 0, sizeof mesh);
    memset(&atlas, 0, sizeof atlas);
    memset(&err, 0, sizeof err);
    memset(&sc, 0, sizeof sc);
    memset(&scale, 0, sizeof scale);
    memset(&rs, 0, sizeof rs);
    memset(&ex, 0, sizeof ex);
    memset(&svg_opt, 0, sizeof svg_opt);
    memset(&png_opt, 0, sizeof png_opt);
    memset(&fs, 0, sizeof fs);
    memset(&gltf, 0, sizeof gltf);
    memset(&gltf_out, 0, sizeof gltf_out);
    fs.every = 10;

    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        /* options that take a value */
        if (!strcmp(a, "-o") || !strcmp(a, "--init") || !strcmp(a, "--energy") ||
            !strcmp(a, "--epsilon") || !strcmp(a, "--direction") ||
            !strcmp(a, "--history") || !strcmp(a, "--max-iters") ||
            !strcmp(a, "--tol") || !strcmp(a, "--max-seconds") ||
            !strcmp(a, "--trace") || !strcmp(a, "--threads") || !strcmp(a, "--cut") || !strcmp(a, "--visibility") ||
            !strcmp(a, "--view-dir") || !strcmp(a, "--up") || !strcmp(a, "--ring-elevation") ||
            !strcmp(a, "--vis-samples") || !strcmp(a, "--vis-floor") || !strcmp(a, "--importance") ||
            !strcmp(a, "--density-report") || !strcmp(a, "--svg") || !strcmp(a, "--svg-color") ||
            !strcmp(a, "--png") || !strcmp(a, "--png-view") || !strcmp(a, "--png-up") ||
            !strcmp(a, "--png-size") || !strcmp(a, "--png-views") || !strcmp(a, "--checker") ||
            !strcmp(a, "--frames") || !strcmp(a, "--frames-every") || !strcmp(a, "--atlas") ||
            !strcmp(a, "--padding") || !strcmp(a, "--pin") || !strcmp(a, "--segment") ||
            !strcmp(a, "--max-distortion") || !strcmp(a, "--max-charts") || !strcmp(a, "--start") ||
            !strcmp(a, "--texcoord")) {
            const char *v;
            if (i + 1 >= argc) return usage_error("option %s needs a value", a);
            v = argv[++i];
            if (!strcmp(a, "-o")) output = v;
            else if (!strcmp(a, "--trace")) trace_path = v;
            else if (!strcmp(a, "--importance")) importance_path = v;
            else if (!strcmp(a, "--pin")) pin_path = v;
            else if (!strcmp(a, "--svg")) svg_path = v;
            else if (!strcmp(a, "--png")) png_path = v;
            else if (!strcmp(a, "--frames")) fs.dir = v;
            else if (!strcmp(a, "--texcoord")) {
                if (!parse_int(v, 0, &texcoord) || texcoord > 99)
                    return usage_error("--texcoord needs a set from 0 to 99, not '%s'", v);
            }
            else if (!strcmp(a, "--svg-color")) {
                if (!strcmp(v, "energy")) svg_opt.color = BPD_COLOR_ENERGY;
                else if (!strcmp(v, "area")) svg_opt.color = BPD_COLOR_AREA;
                else if (!strcmp(v, "angle")) svg_opt.color = BPD_COLOR_ANGLE;
                else if (!strcmp(v, "chart")) svg_opt.color = BPD_COLOR_CHART;
                else return usage_error("unknown --svg-color '%s' (energy, area, angle or chart)", v);
            } else if (!strcmp(a, "--png-view")) {
                if (!parse_vec3(v, png_opt.view))
                    return usage_error("--png-view needs a nonzero X,Y,Z, not '%s'", v);
            } else if (!strcmp(a, "--png-up")) {
                if (!parse_vec3(v, png_opt.up))
                    return usage_error("--png-up needs a nonzero X,Y,Z, not '%s'", v);
            } else if (!strcmp(a, "--png-size")) {
                if (!parse_int(v, 16, &png_opt.size) || png_opt.size > 8192)
                    return usage_error("--png-size needs an integer in [16, 8192], not '%s'", v);
            } else if (!strcmp(a, "--png-views")) {
                if (!parse_int(v, 1, &png_opt.views) || png_opt.views > 64)
                    return usage_error("--png-views needs an integer in [1, 64], not '%s'", v);
            } else if (!strcmp(a, "--checker")) {
                if (!parse_double(v, 0.0, &png_opt.checker) || png_opt.checker <= 0)
                    return usage_error("--checker needs a positive number, not '%s'", v);
            } else if (!strcmp(a, "--frames-every")) {
                if (!parse_int(v, 1, &fs.every))
                    return usage_error("--frames-every needs an integer >= 1, not '%s'", v);
            }
            else if (!strcmp(a, "--atlas")) {
                if (!parse_int(v, 1, &opt.atlas_resolution) || opt.atlas_resolution > 32768)
                    return usage_error("--atlas needs a resolution in [1, 32768] texels, not '%s'", v);
            } else if (!strcmp(a, "--padding")) {
                if (!parse_int(v, 0, &opt.padding))
                    return usage_error("--padding needs an integer >= 0, not '%s'", v);
                padding_set = 1;
            } else if (!strcmp(a, "--segment")) {
                if (!strcmp(v, "auto")) opt.segment = 0;
                else if (!strcmp(v, "on")) opt.segment = 1;
                else if (!strcmp(v, "off")) opt.segment = -1;
                else return usage_error("unknown --segment '%s' (auto, on or off)", v);
            } else if (!strcmp(a, "--max-distortion")) {
                if (!parse_double(v, 0.0, &opt.max_distortion))
                    return usage_error("--max-distortion needs a number >= 0, not '%s'", v);
            } else if (!strcmp(a, "--max-charts")) {
                int n;
                if (!parse_int(v, 0, &n)) return usage_error("--max-charts needs an integer >= 0, not '%s'", v);
                opt.max_charts = (uint32_t)n;
            } else if (!strcmp(a, "--start")) {
                if (!strcmp(v, "auto")) opt.start = BP_START_AUTO;
                else if (!strcmp(v, "plain")) opt.start = BP_START_PLAIN;
                else if (!strcmp(v, "progressive")) opt.start = BP_START_PROGRESSIVE;
                else return usage_error("unknown --start '%s' (auto, plain or progressive)", v);
            } else if (!strcmp(a, "--cut")) {
                if (!strcmp(v, "auto")) opt.cut = BP_CUT_AUTO;
                else if (!strcmp(v, "none")) opt.cut = BP_CUT_NONE;
                else return usage_error("unknown --cut '%s' (auto or none)", v);
            } else if (!strcmp(a, "--threads")) {
                if (!parse_int(v, 0, &opt.threads))
                    return usage_error("--threads needs an integer >= 0, not '%s'", v);
            } else if (!strcmp(a, "--visibility")) {
                if (!(opt.views.model = parse_view(v)))
                    return usage_error("unknown view model '%s' (uniform, front, ring, side)", v);
            } else if (!strcmp(a, "--density-report")) {
                if (!(ex.density_model = parse_view(v)))
                    return usage_error("unknown view model '%s' (uniform, front, ring, side)", v);
            } else if (!strcmp(a, "--view-dir")) {
                if (!parse_vec3(v, opt.views.direction))
                    return usage_error("--view-dir needs a nonzero X,Y,Z, not '%s'", v);
            } else if (!strcmp(a, "--up")) {
                if (!parse_vec3(v, opt.views.up))
                    return usage_error("--up needs a nonzero X,Y,Z, not '%s'", v);
            } else if (!strcmp(a, "--ring-elevation")) {
                if (!parse_double(v, -90.0, &opt.views.elevation) || opt.views.elevation > 90)
                    return usage_error("--ring-elevation needs degrees in [-90, 90], not '%s'", v);
                elevation_set = 1;
            } else if (!strcmp(a, "--vis-samples")) {
                int n;
                if (!parse_int(v, 1, &n)) return usage_error("--vis-samples needs an integer >= 1, not '%s'", v);
                opt.views.samples = (uint32_t)n;
            } else if (!strcmp(a, "--vis-floor")) {
                if (!parse_double(v, 0.0, &opt.views.floor) || opt.views.floor <= 0)
                    return usage_error("--vis-floor needs a positive number, not '%s'", v);
            }
            else if (!strcmp(a, "--init")) {
                if (!strcmp(v, "auto")) opt.init = BP_INIT_AUTO;
                else if (!strcmp(v, "tutte")) opt.init = BP_INIT_TUTTE;
                else if (!strcmp(v, "mvc")) opt.init = BP_INIT_MEAN_VALUE;
                else if (!strcmp(v, "input")) opt.init = BP_INIT_INPUT;
                else if (!strcmp(v, "conformal")) opt.init = BP_INIT_CONFORMAL;
                else return usage_error("unknown start map '%s' (auto, conformal, mvc, tutte or input)", v);
            } else if (!strcmp(a, "--energy")) {
                int e, found = 0;
                for (e = 0; e < (int)BP_ENERGY_COUNT; e++)
                    if (!strcmp(v, energy_names[e])) { opt.energy = (bp_energy)e; found = 1; }
                if (!found)
                    return usage_error("unknown energy '%s' (sd, conformal, mips, iso, maxiso)", v);
            } else if (!strcmp(a, "--direction")) {
                if (!strcmp(v, "default")) opt.direction = BP_DIRECTION_DEFAULT;
                else if (!strcmp(v, "precond")) opt.direction = BP_DIRECTION_PRECONDITIONED;
                else if (!strcmp(v, "lbfgs")) opt.direction = BP_DIRECTION_LBFGS;
                else if (!strcmp(v, "gd")) opt.direction = BP_DIRECTION_GRADIENT;
                else if (!strcmp(v, "newton")) opt.direction = BP_DIRECTION_NEWTON;
                else return usage_error("unknown direction '%s' (default, precond, lbfgs, gd or newton)", v);
            } else if (!strcmp(a, "--epsilon")) {
                if (!parse_double(v, 0.0, &opt.epsilon) || opt.epsilon <= 0.0)
                    return usage_error("--epsilon needs a positive number, not '%s'", v);
            } else if (!strcmp(a, "--tol")) {
                if (!parse_double(v, 0.0, &opt.tolerance) || opt.tolerance <= 0.0)
                    return usage_error("--tol needs a positive number, not '%s'", v);
            } else if (!strcmp(a, "--max-seconds")) {
                if (!parse_double(v, 0.0, &opt.max_seconds))
                    return usage_error("--max-seconds needs a number >= 0, not '%s'", v);
            } else if (!strcmp(a, "--history")) {
                if (!parse_int(v, 1, &opt.history))
                    return usage_error("--history needs an integer >= 1, not '%s'", v);
            } else if (!parse_int(v, 1, &opt.max_iterations)) {
                return usage_error("--max-iters needs an integer >= 1, not '%s'", v);
            }
        }
        else if (!strcmp(a, "-h") || !strcmp(a, "--help")) { fputs(usage_text, stdout); fputs(usage_solver, stdout); fputs(usage_views, stdout); fputs(usage_pictures, stdout); return 0; }
        else if (!strcmp(a, "--version")) { printf("bijparam %s\n", BP_VERSION_STRING); return 0; }
        else if (!strcmp(a, "--force")) force = 1;
        else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) quiet = 1;
        else if (!strcmp(a, "--json")) json = 1;
        else if (!strcmp(a, "--demo")) demo = 1;
        else if (!strcmp(a, "--check")) check = 1;
        else if (!strcmp(a, "--init-only")) opt.init_only = 1;
        else if (!strcmp(a, "--no-barrier")) opt.no_barrier = 1;
        else if (!strcmp(a, "--normalize")) opt.normalize = 1;
        else if (!strcmp(a, "--strict")) opt.strict = 1;
        else if (!strcmp(a, "--no-rotate")) opt.no_rotation = 1;
        else if (!strcmp(a, "--repack")) repack = 1;
        else if (a[0] == '-' && a[1] != '\0') return usage_error("unknown option '%s'", a);
        else if (input) return usage_error("more than one input file ('%s')", a);
        else input = a;
    }
    if (demo && input) return usage_error("--demo takes no input file ('%s')", input);
    if (!demo && !input) return usage_error("%s", "no input file");
    if (check && demo) return usage_error("%s", "--check takes an input file, not --demo");
    if (check) return run_check(input, texcoord);
    if (output && bpg_is_gltf_path(output) && (demo || !bpg_is_gltf_path(input)))
        return usage_error("-o '%s' needs a .gltf or .glb input (write OBJ from other inputs)", output);
    if (pin_path && !demo && bpg_is_gltf_path(input))
        return usage_error("%s", "--pin takes an OBJ, OFF or PLY input (it numbers vertices as the file does)");
    if (!force) {           /* an output that would replace an input file */
        const char *outs[4], *flags[4] = { "-o", "--svg", "--png", "--trace" };
        int k;
        outs[0] = output; outs[1] = svg_path; outs[2] = png_path; outs[3] = trace_path;
        for (k = 0; k < 4; k++)
            if (!demo && (same_file(outs[k], input) || same_file(outs[k], importance_path) ||
                          same_file(outs[k], pin_path))) {
                fprintf(stderr, "bijparam: %s '%s' is an input file; add --force to replace it\n"
                        "see bijparam --help\n", flags[k], outs[k]);
                return 2;
            }
    }
    if (demo) input = "<demo>";
    if (!elevation_set) opt.views.elevation = 30;
    if (padding_set && !opt.atlas_resolution) return usage_error("%s", "--padding needs --atlas RES");
    if (opt.no_rotation && !opt.atlas_resolution) return usage_error("%s", "--no-rotate needs --atlas RES");
    if (!padding_set) opt.padding = 4;
    if (repack && demo) return usage_error("%s", "--repack needs an input file with texture coordinates");

    if (trace_path) {
        rs.trace = fopen(trace_path, "w");
        if (!rs.trace) {
            fprintf(stderr, "bijparam: error: %s: cannot open trace file: %s\n",
                    trace_path, strerror(errno));
            return 1;
        }
    }
    rs.tty = isatty(2) && !quiet;
    rs.drawn = -1;
    opt.run_progress = on_run_progress;
    opt.run_progress_user = &rs;
    {   /* SIGINT: cancel (sigaction: a blocked read is resumed, the handler stays) */
#ifdef _WIN32
        signal(SIGINT, on_interrupt);
#else
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_interrupt;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESTART;
        sigaction(SIGINT, &sa, NULL);
#endif
    }
    rs.start = now_seconds();
    opt.progress = on_progress;
    opt.progress_user = &rs;
    where = input;
    svg_opt.energy = opt.energy;
    if (demo && png_opt.view[0] == 0 && png_opt.view[1] == 0 && png_opt.view[2] == 0) {
        /* the demo cone opens toward +z and its triangles face into the bowl */
        png_opt.view[0] = 0.5; png_opt.view[1] = -0.9; png_opt.view[2] = 1.4;
        if (png_opt.up[0] == 0 && png_opt.up[1] == 0 && png_opt.up[2] == 0) png_opt.up[2] = 1;
    }
    if (opt.no_barrier) svg_opt.fill_opacity = 0.6;   /* overlaps show darker */
    if (fs.dir) {
        if (mkdir(fs.dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "bijparam: error: %s: cannot create the frames directory: %s\n",
                    fs.dir, strerror(errno));
            if (rs.trace) fclose(rs.trace);
            return 1;
        }
        fs.svg = svg_opt;
        fs.svg.size = 500;
        rs.frames = &fs;
    }

    /* 0. one pool of threads for every stage (bp_pool_create): each call
          would otherwise start and stop threads of its own, and the pool
          started now is running by the time the reader needs it.  Without
          one (out of memory) every call starts its own, as opt.threads. */
    if (opt.threads != 1 && bp_pool_create(&pool, opt.threads, NULL, NULL) == BP_OK) {
        opt.parallel_for = bp_pool_for;
        opt.parallel_user = pool;
    }

    /* 0b. the temporary the result goes into, created now so that an
           output that cannot be written fails before the work, removed on
           any error or signal */
    if (output) {
        int why = 0;
        signal(SIGTERM, on_signal);
#ifdef SIGHUP
        signal(SIGHUP, on_signal);
#endif
        if (!temp_create(temp_path, &temp_live, output, final_path, sizeof final_path, &why)) {
            fprintf(stderr, "bijparam: error: %s: cannot create a file next to it: %s\n",
                    output, strerror(why));
            if (rs.trace) fclose(rs.trace);
            bp_pool_destroy(pool);
            return 1;
        }
    }

    /* 1. read */
    stage_start(&sc);
    if (demo) {
        if (!demo_mesh(&mesh)) {
            st = BP_ERR_OUT_OF_MEMORY;
            snprintf(err.message, sizeof err.message, "out of memory building the demo mesh");
        }
    } else {
        struct stat sb;
        if (stat(input, &sb) == 0 && S_ISDIR(sb.st_mode)) {
            st = BP_ERR_IO;    /* before the extension test of bp_read_mesh */
            memset(&err, 0, sizeof err);
            snprintf(err.message, sizeof err.message, "is a directory, not an .obj or .off file");
        } else
            st = read_input(input, &mesh, &gltf, texcoord, &opt, &err);
        ex.format = gltf_names ? (gltf.glb ? "glb" : "gltf") : bp_mesh_format(input);
    }
    have_mesh = st == BP_OK;
    if (st == BP_OK && !rescale_mesh(&mesh, &opt, &scale)) {
        st = BP_ERR_OUT_OF_MEMORY;
        memset(&err, 0, sizeof err);
        snprintf(err.message, sizeof err.message, "out of memory rescaling the mesh");
    }
    stage_add(&sc, offsetof(timings, read));

    /* 2. charts (a chart that cannot be flattened is reported and skipped;
          the others are still solved and written, unless --strict) */
    if (st == BP_OK) {
        stage_start(&sc);
        st = bp_atlas_build(&atlas, &mesh, &opt, &err);
        if (st == BP_ERR_CHARTS_FAILED) st = BP_OK;
        stage_add(&sc, offsetof(timings, cut));
        rs.num_charts = atlas.num_charts;
        rs.tris_total = mesh.num_triangles;
        fs.mesh = &mesh;
        fs.atlas = &atlas;
        for (c = 0; st == BP_OK && c < atlas.num_charts; c++)
            if (atlas.charts[c].num_triangles > atlas.charts[fs.strip_chart].num_triangles)
                fs.strip_chart = c;
    }
    /* 2b. chapter 4: per-face importance from visibility and/or a file */
    if (st == BP_OK && importance_path) {
        char msg[200];
        importance = read_importance(importance_path, &mesh, msg, sizeof msg);
        if (!importance) {
            st = BP_ERR_INVALID_ARGUMENT;
            where = importance_path;
            memset(&err, 0, sizeof err);
            snprintf(err.message, sizeof err.message, "%s", msg);
        }
    }
    if (st == BP_OK && opt.views.model != BP_VIEW_NONE && !opt.init_only) {
        double *vis = (double *)malloc(sizeof(double) * mesh.num_triangles);
        if (!vis) { st = BP_ERR_OUT_OF_MEMORY; snprintf(err.message, sizeof err.message, "out of memory"); }
        else if ((st = bp_visibility(&mesh, &opt, vis, &err)) == BP_OK) {
            if (importance) { for (c = 0; c < mesh.num_triangles; c++) vis[c] *= importance[c]; free(importance); }
            importance = vis;
        } else free(vis);
    }
    opt.importance = importance;
    /* 2c. pinned vertices */
    if (st == BP_OK && pin_path) {
        char msg[200];
        long line;
        pins = read_pins(pin_path, &mesh, &opt.num_pins, &line, msg, sizeof msg);
        opt.pins = pins;
        for (c = 0; pins && c < opt.num_pins; c++) { pins[c].u = ldexp(pins[c].u, scale.k); pins[c].v = ldexp(pins[c].v, scale.k); }
        if (!pins) {
            st = BP_ERR_PARSE;
            where = pin_path;
            memset(&err, 0, sizeof err);
            err.line = line;
            snprintf(err.message, sizeof err.message, "%s", msg);
        }
    }
    /* 3a. --repack: the file's own maps, checked exactly (a chart whose map
       is not bijective is reported and not packed, unless --strict) */
    if (st == BP_OK && repack) {
        stage_start(&sc);
        st = bp_atlas_use_input_uvs(&atlas, &mesh, &err);
        if (st == BP_ERR_CHARTS_FAILED || (st == BP_ERR_NOT_BIJECTIVE && atlas.num_failed)) {
            if (opt.strict) {
                for (c = 0; c < atlas.num_charts; c++)
                    if (atlas.charts[c].error.status != BP_OK) { err = atlas.charts[c].error; break; }
                st = err.status;
            } else st = BP_OK;
        }
        stage_add(&sc, offsetof(timings, init));
    }
    /* 3'. segmentation (bp_atlas_segment does nothing unless it is on):
          several charts, solved in parallel, then the charts still above
          --max-distortion split again (bp_atlas_refine) */
    segmented = st == BP_OK && !repack && !fs.dir && !opt.init_only &&
                (opt.segment > 0 || (opt.segment == 0 && (opt.atlas_resolution || opt.max_distortion > 0 || opt.max_charts)));
    if (segmented) {
        stage_start(&sc);
        st = bp_atlas_segment(&atlas, &mesh, &opt, &err);
        stage_add(&sc, offsetof(timings, segment));
        stage_start(&sc);
        if (st == BP_OK) st = bp_atlas_solve(&atlas, &mesh, &opt, &err);
        if (st == BP_ERR_CHARTS_FAILED && !opt.strict) st = BP_OK;
        if (st == BP_OK) st = bp_atlas_refine(&atlas, &mesh, &opt, &err);
        stage_add(&sc, offsetof(timings, optimize));
        rs.num_charts = atlas.num_charts;
    }
    /* 3. start map and optimization.  Several charts (without --frames):
          all at once by bp_atlas_solve, which solves the charts themselves
          on the threads when none holds half the triangles (each one the
          same bits as alone); the start and optimize stages of different
          charts then interleave, so their whole time is "optimize".  One
          chart, or --frames: chart by chart, each chart's time split into
          its start map and its optimization. */
    together = st == BP_OK && !repack && !segmented && !fs.dir && atlas.num_charts > 1;
    if (together) {
        stage_start(&sc);
        rs.tris_before = 0;                  /* the bar: the run's fraction of triangles */
        rs.tris_chart = rs.tris_total;
        rs.together = 1;
        st = bp_atlas_solve(&atlas, &mesh, &opt, &err);
        /* a chart that failed (also every chart: then the status is the
           first chart's own) is reported below, as chart by chart */
        if (!opt.strict && atlas.num_failed && st != BP_OK && st != BP_ERR_OUT_OF_MEMORY && st != BP_ERR_CANCELLED)
            st = BP_OK;
        stage_add(&sc, offsetof(timings, optimize));
    }
    /* chart by chart */
    for (c = 0; st == BP_OK && !repack && !segmented && !together && c < atlas.num_charts; c++) {
        if (atlas.charts[c].error.status != BP_OK) continue;   /* failed in step 2 */
        rs.chart = c;                        /* the progress bar's place */
        rs.tris_chart = atlas.charts[c].num_triangles;
        for (rs.tris_before = 0, i = 0; i < (int)c; i++) rs.tris_before += atlas.charts[i].num_triangles;
        stage_start(&sc);
        if (!fs.dir) {   /* start and optimization at once: the start's factor serves Newton */
            double t1, c1;
            rs.start_done = 0;
            st = bp_chart_solve(&atlas.charts[c], c, &mesh, &opt, &err);
            t1 = rs.start_done > 0 ? rs.start_done : now_seconds();
            c1 = rs.start_done > 0 ? rs.start_done_cpu : cpu_seconds();
            sc.wall.init += t1 - sc.t0;
            sc.cpu.init += c1 - sc.c0;
            sc.wall.optimize += now_seconds() - t1;
            sc.cpu.optimize += cpu_seconds() - c1;
            chart_failed(&atlas, c, &st, &err, opt.strict);
            continue;
        }
        st = bp_chart_init(&atlas.charts[c], &mesh, &opt, &err);
        stage_add(&sc, offsetof(timings, init));
        if (chart_failed(&atlas, c, &st, &err, opt.strict)) continue;
        if (st == BP_OK && fs.dir) {     /* frame 0: the start map */
            double e0 = 0;
            bp_chart_distortion(&atlas.charts[c], &mesh, opt.energy, &e0, NULL, NULL, NULL);
            keep_snapshot(&fs, c, 0, e0, 0);
            if (!write_frame(&fs, c, 0, e0)) st = BP_ERR_IO;
        }
        if (st != BP_OK || opt.init_only) continue;
        stage_start(&sc);
        st = bp_chart_optimize(&atlas.charts[c], c, &mesh, &opt, &err);
        stage_add(&sc, offsetof(timings, optimize));
        if (chart_failed(&atlas, c, &st, &err, opt.strict)) continue;
        if (st == BP_OK && fs.dir) {     /* the last frame, whatever K */
            const bp_chart *ch = &atlas.charts[c];
            keep_snapshot(&fs, c, ch->iterations, ch->energy_end, 1);
            if (ch->iterations % fs.every != 0 && !write_frame(&fs, c, ch->iterations, ch->energy_end))
                st = BP_ERR_IO;
        }
    }
    if (st == BP_OK && fs.dir && !write_strip(&fs)) st = BP_ERR_IO;
    if (fs.error) {                      /* a frame could not be written */
        st = BP_ERR_IO;
        where = fs.error_path;
        memset(&err, 0, sizeof err);
        snprintf(err.message, sizeof err.message, "cannot write frame: %s", strerror(fs.error));
    }
    /* 4. pack */
    if (st == BP_OK) {
        stage_start(&sc);
        st = bp_atlas_pack(&atlas, &opt, &err);
        stage_add(&sc, offsetof(timings, pack));
    }
    /* 4a. an extreme scale: the user's mesh back, the map at its size */
    unscale(&mesh, &atlas, &scale, opt.atlas_resolution > 0 || opt.normalize);
    /* 4b. texel density (sec 4.3) of this map against a plain isometric
       map of the same mesh, both under the chosen view model */
    if (st == BP_OK && ex.density_model) {
        bp_options iso_opt = opt, meas = opt;
        bp_atlas iso;
        iso_opt.importance = NULL;
        iso_opt.views.model = BP_VIEW_NONE;
        iso_opt.progress = NULL;
        meas.views.model = ex.density_model;
        st = bp_parameterize(&iso, &mesh, &iso_opt, &err);
        if (st == BP_OK) {
            st = bp_texture_to_screen(&mesh, &atlas, &meas, &ex.density_map, &err);
            if (st == BP_OK) st = bp_texture_to_screen(&mesh, &iso, &meas, &ex.density_iso, &err);
            bp_atlas_free(&iso);
        }
    }
    /* 5. write: into the temporary, renamed over OUT only when complete.
          An OBJ input is streamed (every other line of the user's file
          kept); an OFF input or the demo mesh is written from the mesh. */
    if (st == BP_OK && output) {
        stage_start(&sc);
        where = output;
        memset(&err, 0, sizeof err);
        if (bpg_is_gltf_path(output)) {
            st = write_gltf(&gltf, &atlas, input, output, final_path, &opt, &gltf_out, &where, &err);
            if (st == BP_OK) ex.gltf = &gltf_out;
        } else
            st = bp_write_obj_opt(temp_path, !demo && ends_with_obj(input) ? input : NULL, &mesh, &atlas, &opt, &err);
        if (st == BP_OK && temp_live && replace_file(temp_path, final_path) != 0) {
            st = BP_ERR_IO;
            err.line = 0;
            snprintf(err.message, sizeof err.message,
                     "cannot rename the finished result onto it: %s", strerror(errno));
        }
        if (st == BP_OK) { temp_live = 0; wrote = 1; }
        stage_add(&sc, offsetof(timings, write));
    }
    temp_discard();                       /* on any failure before or here */
    clear_bar(&rs);

    /* 6. pictures of the packed atlas (examples/bp_draw.h) */
    /* a layout packed into [0,1]^2: draw the square, and measure the energy
       at one common scale (UV area = 3D area), not at the square's */
    svg_opt.packed = opt.atlas_resolution > 0 || opt.normalize;
    if (st == BP_OK && svg_path && !bpd_write_atlas_svg(svg_path, &mesh, &atlas, &svg_opt)) {
        st = BP_ERR_IO;
        where = svg_path;
        memset(&err, 0, sizeof err);
        snprintf(err.message, sizeof err.message, "cannot write the SVG: %s", strerror(errno));
    }
    if (st == BP_OK && png_path && !bpd_write_checker_png(png_path, &mesh, &atlas, &png_opt)) {
        st = BP_ERR_IO;
        where = png_path;
        memset(&err, 0, sizeof err);
        snprintf(err.message, sizeof err.message, "cannot write the PNG: %s", strerror(errno));
    }

    if (st != BP_OK && interrupted) {
        fprintf(stderr, "bijparam: cancelled (SIGINT): nothing written\n");
        status = 130;
    } else if (st != BP_OK) {
        report_error(where, &err);
        status = 1;
    }
    /* charts that failed: one line each, exit status 1, the rest written */
    for (c = 0; c < atlas.num_charts; c++)
        if (atlas.charts[c].error.status != BP_OK) {
            report_error(input, &atlas.charts[c].error);
            if (status == 0) status = 1;
        }
    /* repairs (not --strict): one line each on stderr */
    if (!json && !quiet) {
        int k;
        for (k = 0; k < BP_REPAIR_KINDS; k++)
            if (atlas.repairs.kind[k].count) {
                const bp_repair *r = &atlas.repairs.kind[k];
                char names[420];
                gltf_element(r->element, r->first[0], r->first2[0], names, sizeof names);
                fprintf(stderr, "bijparam: repaired: %s: %s%s\n", input ? input : "demo", r->message, names);
            }
    }
    if (json)
    {
        for (c = 0; c < atlas.num_charts; c++)
            if (atlas.charts[c].threads > ex.threads) ex.threads = atlas.charts[c].threads;
        bp_status js = (st == BP_OK && atlas.num_failed) ? BP_ERR_CHARTS_FAILED : st;
        ex.resolution = opt.atlas_resolution;
        ex.padding = opt.atlas_resolution ? opt.padding : 0;
        print_json(input, wrote ? output : NULL, js, st == BP_OK ? NULL : err.message, &mesh, &atlas,
                   &opt, &sc, &ex);
    } else if (!quiet && wrote) {
        fprintf(stderr, "bijparam: wrote %s (%u chart%s%s)\n", output, (unsigned)atlas.num_charts,
                atlas.num_charts == 1 ? "" : "s", atlas.num_failed ? "; failed charts without vt" : "");
    } else if (!quiet && status == 0 && !output) {
        fprintf(stderr, "bijparam: no output written (use -o FILE)\n");
    }

    if (rs.trace) fclose(rs.trace);
    bp_pool_destroy(pool);
    for (i = 0; i < fs.nsnap; i++) free(fs.snap[i]);
    free(importance);
    free(pins);
    bp_atlas_free(&atlas);
    if (have_mesh) {
        if (demo) { free(mesh.positions); free(mesh.triangles); }
        else free_input(&mesh, &gltf);
    }
    return status;
}
