/* test_cancel.c - whole-run progress and cancel (bp_options.run_progress):
   a cancel at every stage (read, charts, start, visibility, optimize, pack,
   write) returns BP_ERR_CANCELLED and leaves valid maps or none -- every
   chart either mapped, packed and exactly valid, or reported failed -- and
   never a half-written file; one cancel stops every chart, also charts
   solved in parallel; a slow callback on two threads is never entered by
   two at once nor called after its stop, inside bp_parameterize and from
   bp_atlas_solve called on its own; the per-iteration progress still
   cancels one chart; and bp_options.struct_size keeps an older caller's
   meaning. */
#define _POSIX_C_SOURCE 200809L      /* mkdtemp */
#define BP_USE_PTHREADS
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

/* bp__atlas_verify's runner: the serial loop. */
static const bp__par serial_par = { bp__serial_for, NULL, 1 };
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ---- meshes written by the test ---- */

/* K separate bumpy n x n grids (K charts) as OBJ text. */
static char *grids_obj(int K, int n, size_t *len)
{
    size_t cap = (size_t)K * (n + 1) * (n + 1) * 80 + (size_t)K * n * n * 40 + 64, m = 0;
    char *t = (char *)malloc(cap);
    int k, i, j;
    for (k = 0; k < K; k++)
        for (i = 0; i <= n; i++)
            for (j = 0; j <= n; j++)
                m += (size_t)snprintf(t + m, cap - m, "v %.17g %.17g %.17g\n", j + 2.0 * n * k, (double)i,
                                      0.3 * sin(0.7 * i + k) * cos(0.5 * j));
    for (k = 0; k < K; k++)
        for (i = 0; i < n; i++)
            for (j = 0; j < n; j++) {
                int v = k * (n + 1) * (n + 1) + i * (n + 1) + j + 1;
                m += (size_t)snprintf(t + m, cap - m, "f %d %d %d %d\n", v, v + 1, v + n + 2, v + n + 1);
            }
    *len = m;
    return t;
}

static int write_text(const char *path, const char *t, size_t n)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(t, 1, n, f) == n;
    if (f && fclose(f) != 0) ok = 0;
    return ok;
}

static int file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

/* ---- the recording callback (called from several threads) ---- */

typedef struct recorder {
    pthread_mutex_t mu;
    bp_stage stage;          /* cancel at the nth call of this stage        */
    int nth, seen;           /* ... counting only reports at a fraction  */
    double from;             /* of at least `from` (optimize reports of  */
                             /* parallel charts may be skipped, >>progress) */
    int cancelled;           /* we answered nonzero                         */
    int calls_after;         /* calls that reached us after that            */
    int bad_fraction;        /* a fraction outside [0, 1]                   */
    int calls[BP_STAGE_COUNT];
    int iter_after[64];      /* per-iteration calls per chart after the cancel */
} recorder;

static void rec_init(recorder *r, bp_stage stage, int nth)
{
    memset(r, 0, sizeof *r);
    pthread_mutex_init(&r->mu, NULL);
    r->stage = stage;
    r->nth = nth;
}

static int on_run(void *user, bp_stage s, double f, uint32_t chart)
{
    recorder *r = (recorder *)user;
    int stop = 0;
    (void)chart;
    pthread_mutex_lock(&r->mu);
    if (!(f >= 0 && f <= 1)) r->bad_fraction++;
    if ((int)s >= 0 && s < BP_STAGE_COUNT) r->calls[s]++;
    if (r->cancelled) r->calls_after++;
    else if (s == r->stage && f >= r->from && ++r->seen >= r->nth) stop = r->cancelled = 1;
    pthread_mutex_unlock(&r->mu);
    return stop;
}

static int on_iter(void *user, uint32_t chart, int it, double e, double step)
{
    recorder *r = (recorder *)user;
    (void)it; (void)e; (void)step;
    pthread_mutex_lock(&r->mu);
    if (r->cancelled && chart < 64) r->iter_after[chart]++;
    pthread_mutex_unlock(&r->mu);
    return 0;
}

/* Each chart mapped and exactly valid, or failed with a reason (that
   reason, when want_chart_error is not BP_OK).  Returns the number of
   mapped charts, -1 if not. */
static int charts_valid_or_failed(const bp_atlas *at, bp_status want_chart_error)
{
    uint32_t c;
    int mapped = 0;
    for (c = 0; c < at->num_charts; c++) {
        const bp_chart *ch = &at->charts[c];
        bp_check_report r;
        if (!ch->uv) {
            if (ch->error.status == BP_OK || (want_chart_error != BP_OK && ch->error.status != want_chart_error))
                return -1;
            continue;
        }
        if (ch->error.status != BP_OK ||
            bp_check(ch->triangles, ch->num_triangles, ch->uv, ch->num_vertices, NULL, &r, NULL) != BP_OK)
            return -1;
        mapped++;
    }
    return mapped;
}

/* Valid maps or none (above), and all mapped charts together pass the
   exact check (packed, no two overlapping). */
static int valid_or_none(const bp_atlas *at, bp_status want_chart_error)
{
    bp_error e;
    int mapped = charts_valid_or_failed(at, want_chart_error);
    if (mapped > 0 && bp__atlas_verify(at, &serial_par, &e) != BP_OK) return -1;
    return mapped;
}

static bp_mesh grids;                 /* 6 charts of 12 x 12 quads */

static void setup(void)
{
    size_t n;
    char *t = grids_obj(6, 12, &n);
    bp_error err;
    BPT_CHECK(bp_parse_obj(t, n, &grids, NULL, &err) == BP_OK, "6 grids: %s", err.message);
    free(t);
}

static bp_status run(recorder *r, bp_atlas *at, int views, bp_error *err)
{
    bp_options opt;
    bp_options_init(&opt);
    opt.threads = 2;
    opt.run_progress = on_run;
    opt.run_progress_user = r;
    opt.progress = on_iter;
    opt.progress_user = r;
    if (views) { opt.views.model = BP_VIEW_FRONT; opt.views.samples = 8; }
    return bp_parameterize(at, &grids, &opt, err);
}

/* A cancel at the nth report of `stage` at a fraction of at least `from`
   inside bp_parameterize. */
static void cancel_in_run(bp_stage stage, int nth, double from, int views)
{
    recorder r;
    bp_atlas at;
    bp_error err;
    bp_status st;
    int mapped;
    uint32_t c;
    char at_[80];
    rec_init(&r, stage, nth);
    r.from = from;
    snprintf(at_, sizeof at_, "%s #%d at a fraction >= %g", bp_stage_name(stage), nth, from);
    st = run(&r, &at, views, &err);
    mapped = valid_or_none(&at, BP_ERR_CANCELLED);
    BPT_CHECK(st == BP_ERR_CANCELLED && r.cancelled, "cancel at %s: BP_ERR_CANCELLED (%s: %s)", at_, bp_status_string(st),
              err.message);
    BPT_CHECK(mapped >= 0, "cancel at %s: every chart valid or reported (%d of %u mapped)", at_, mapped,
              at.num_charts);
    BPT_CHECK(r.calls_after == 0 && !r.bad_fraction,
              "cancel at %s: the callback is not called again after it said stop (%d), fractions in [0,1]",
              at_, r.calls_after);
    if (stage == BP_STAGE_CHARTS || stage == BP_STAGE_VISIBILITY)   /* visibility comes first (it guides the seams) */
        BPT_CHECK(at.num_charts == 0 && at.charts == NULL, "cancel at %s: no atlas (%u charts)", bp_stage_name(stage),
                  at.num_charts);
    if (stage == BP_STAGE_START && nth == 1)
        BPT_CHECK(at.num_charts == 6 && mapped == 0 && at.num_failed == 6,
                  "cancel at %s before any start map: 6 charts, none mapped, each failed with BP_ERR_CANCELLED (%d)",
                  bp_stage_name(stage), mapped);
    if (stage == BP_STAGE_PACK)
        BPT_CHECK(mapped == 6 && at.num_failed == 0, "cancel at pack: the packing ends, all 6 charts mapped (%d)", mapped);
    if (stage == BP_STAGE_OPTIMIZE) {
        int most = 0;
        for (c = 0; c < at.num_charts; c++) if (r.iter_after[c] > most) most = r.iter_after[c];
        BPT_CHECK(most <= 1 && mapped >= 1,
                  "cancel at optimize: every chart stops at its next iteration (at most %d iteration after the cancel), "
                  "%d charts keep a map", most, mapped);
    }
    bp_atlas_free(&at);
}

/* The pack stage is reported by both packers, the shelves and the
   outlines of atlas_resolution: once at 0 and once at 1, after the last
   start and optimize report; and a cancel there still ends with every
   chart packed. */
typedef struct pack_order { int pack0, pack1, solve_after_pack, other; } pack_order;

static int on_pack(void *user, bp_stage s, double f, uint32_t chart)
{
    pack_order *o = (pack_order *)user;
    (void)chart;
    if (s == BP_STAGE_PACK && f == 0 && !o->pack1) o->pack0++;
    else if (s == BP_STAGE_PACK && f == 1 && o->pack0) o->pack1++;
    else if (s == BP_STAGE_PACK) o->other++;
    else if ((s == BP_STAGE_START || s == BP_STAGE_OPTIMIZE) && o->pack0) o->solve_after_pack++;
    return 0;
}

static void pack_reports(int resolution)
{
    pack_order o;
    recorder r;
    bp_options opt;
    bp_atlas at;
    bp_error err;
    bp_status st;
    memset(&o, 0, sizeof o);
    bp_options_init(&opt);
    opt.threads = 2;
    opt.atlas_resolution = resolution;
    opt.normalize = 1;
    opt.run_progress = on_pack;
    opt.run_progress_user = &o;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_OK && o.pack0 == 1 && o.pack1 == 1 && o.other == 0 && o.solve_after_pack == 0,
              "atlas_resolution %d: the pack stage reported once at 0 and once at 1, after the solve "
              "(%s; %d, %d, %d other, %d solve reports after it)", resolution, bp_status_string(st), o.pack0, o.pack1,
              o.other, o.solve_after_pack);
    bp_atlas_free(&at);
    rec_init(&r, BP_STAGE_PACK, 1);
    opt.run_progress = on_run;
    opt.run_progress_user = &r;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_ERR_CANCELLED && r.cancelled && r.calls_after == 0 && valid_or_none(&at, BP_OK) == 6,
              "atlas_resolution %d: a cancel at pack: every chart packed and valid, BP_ERR_CANCELLED (%s)",
              resolution, bp_status_string(st));
    bp_atlas_free(&at);
}

/* The 0.1 per-iteration cancel stops one chart; the others are solved. */
static int cancel_chart2(void *user, uint32_t chart, int it, double e, double step)
{
    (void)user; (void)it; (void)e; (void)step;
    return chart == 2;
}

static void per_chart_cancel(void)
{
    bp_options opt;
    bp_atlas at;
    bp_error err;
    bp_status st;
    uint32_t c, others = 0;
    bp_options_init(&opt);
    opt.threads = 2;
    opt.progress = cancel_chart2;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_ERR_CANCELLED && at.num_charts == 6 && at.charts[2].stop == BP_STOP_CANCELLED &&
              at.charts[2].iterations == 1 && at.charts[2].uv,
              "per-iteration progress cancels chart 2 after one iteration, keeping its map (%s)", bp_status_string(st));
    for (c = 0; c < at.num_charts; c++)
        if (c != 2 && at.charts[c].uv && at.charts[c].stop != BP_STOP_CANCELLED && at.charts[c].iterations > 1) others++;
    BPT_CHECK(others == 5 && valid_or_none(&at, BP_OK) == 6,
              "... and does not stop the other 5 charts (%u solved on), all 6 valid", others);
    bp_atlas_free(&at);
}

/* The whole-run callback is never entered by two threads at once, and
   never again once it answered stop -- also when it is slow and charts are
   solved in parallel.  The callback below stays inside for a while (a
   busy wait on the clock) to open the window in which a second thread
   would enter it; `inside` counts the threads in it. */
typedef struct slow_recorder {
    recorder r;
    int inside, overlaps;
} slow_recorder;

static void busy_wait_us(long us)
{
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    do clock_gettime(CLOCK_MONOTONIC, &b);
    while ((b.tv_sec - a.tv_sec) * 1000000L + (b.tv_nsec - a.tv_nsec) / 1000 < us);
}

static int on_run_slow(void *user, bp_stage s, double f, uint32_t chart)
{
    slow_recorder *S = (slow_recorder *)user;
    int stop;
    pthread_mutex_lock(&S->r.mu);
    if (++S->inside > 1) S->overlaps++;
    pthread_mutex_unlock(&S->r.mu);
    busy_wait_us(300);
    stop = on_run(&S->r, s, f, chart);
    pthread_mutex_lock(&S->r.mu);
    S->inside--;
    pthread_mutex_unlock(&S->r.mu);
    return stop;
}

/* direct: bp_atlas_build, then bp_atlas_solve called by the caller (its
   charts on 2 threads too), instead of bp_parameterize. */
static void slow_callback(bp_stage stage, int nth, double from, int direct)
{
    slow_recorder S;
    bp_options opt;
    bp_atlas at;
    bp_error err;
    bp_status st;
    int mapped;
    memset(&S, 0, sizeof S);
    rec_init(&S.r, stage, nth);
    S.r.from = from;
    bp_options_init(&opt);
    opt.threads = 2;
    opt.run_progress = on_run_slow;
    opt.run_progress_user = &S;
    if (direct) {
        st = bp_atlas_build(&at, &grids, &opt, &err);
        if (st == BP_OK) st = bp_atlas_solve(&at, &grids, &opt, &err);
        mapped = charts_valid_or_failed(&at, BP_ERR_CANCELLED);   /* solved, not packed: they may lie on each other */
    } else {
        st = bp_parameterize(&at, &grids, &opt, &err);
        mapped = valid_or_none(&at, BP_ERR_CANCELLED);
    }
    BPT_CHECK(st == BP_ERR_CANCELLED && S.r.cancelled && mapped >= 0,
              "a slow callback cancels %s at %s #%d at a fraction >= %g: BP_ERR_CANCELLED, every chart valid or "
              "reported (%s)", direct ? "bp_atlas_solve" : "bp_parameterize", bp_stage_name(stage), nth, from,
              bp_status_string(st));
    BPT_CHECK(S.overlaps == 0 && S.r.calls_after == 0,
              "a slow callback on 2 threads (%s): never entered by two threads at once (%d overlaps), never called "
              "after it said stop (%d calls; %d optimize reports reached it)", direct ? "bp_atlas_solve" : "bp_parameterize",
              S.overlaps, S.r.calls_after, S.r.calls[BP_STAGE_OPTIMIZE]);
    bp_atlas_free(&at);
}

/* Reading: a cancel at the start (loading) or while parsing (every 16384
   lines) leaves no mesh; writing: a cancel before or while writing leaves
   no file. */
static void read_write(void)
{
    char dir[] = "/tmp/bptest_cancel_XXXXXX", obj[64], out[64];
    size_t n;
    char *t = grids_obj(1, 120, &n);           /* 14641 v + 14400 f lines, 28800 triangles */
    bp_options opt;
    bp_mesh m;
    bp_atlas at;
    bp_error err;
    bp_status st;
    recorder r;
    int nth, src;
    BPT_CHECK(mkdtemp(dir) != NULL, "a temporary directory %s", dir);
    snprintf(obj, sizeof obj, "%s/big.obj", dir);
    snprintf(out, sizeof out, "%s/out.obj", dir);
    BPT_CHECK(write_text(obj, t, n), "wrote %s", obj);
    free(t);
    for (nth = 1; nth <= 3; nth++) {
        rec_init(&r, BP_STAGE_READ, nth);
        bp_options_init(&opt);
        opt.run_progress = on_run;
        opt.run_progress_user = &r;
        st = bp_read_mesh_opt(obj, &m, &opt, &err);
        BPT_CHECK(st == BP_ERR_CANCELLED && !m.positions && !m.triangles && !m.triangle_line && m.num_vertices == 0,
                  "cancel at read #%d (%d calls): BP_ERR_CANCELLED, no mesh (%s)", nth, r.calls[BP_STAGE_READ], err.message);
    }
    rec_init(&r, BP_STAGE_COUNT, 1);
    opt.run_progress_user = &r;
    st = bp_read_mesh_opt(obj, &m, &opt, &err);
    BPT_CHECK(st == BP_OK && m.num_triangles == 28800 && r.calls[BP_STAGE_READ] >= 4 && !r.bad_fraction,
              "read without cancel: %d progress calls (load, parse ticks, end), fractions in [0,1]",
              r.calls[BP_STAGE_READ]);
    bp_options_init(&opt);
    opt.init_only = 1;
    st = bp_parameterize(&at, &m, &opt, &err);
    BPT_CHECK(st == BP_OK, "a start map of the big grid: %s", err.message);
    for (src = 0; src < 2; src++)
        for (nth = 1; nth <= 3; nth++) {
            remove(out);
            rec_init(&r, BP_STAGE_WRITE, nth);
            opt.run_progress = on_run;
            opt.run_progress_user = &r;
            st = bp_write_obj_opt(out, src ? obj : NULL, &m, &at, &opt, &err);
            BPT_CHECK(st == BP_ERR_CANCELLED && !file_exists(out),
                      "cancel at write #%d (%s): BP_ERR_CANCELLED and no file left (%s)", nth,
                      src ? "bp_write_obj_from" : "bp_write_obj", err.message);
        }
    rec_init(&r, BP_STAGE_COUNT, 1);
    st = bp_write_obj_opt(out, obj, &m, &at, &opt, &err);
    BPT_CHECK(st == BP_OK && file_exists(out) && r.calls[BP_STAGE_WRITE] >= 8,
              "write without cancel: the file, %d progress calls", r.calls[BP_STAGE_WRITE]);
    remove(out);
    remove(obj);
    rmdir(dir);
    bp_atlas_free(&at);
    bp_mesh_free(&m, NULL);
}

/* struct_size: the library reads no field beyond the caller's size. */
static int always_cancel(void *user, bp_stage s, double f, uint32_t chart)
{
    (void)user; (void)s; (void)f; (void)chart;
    return 1;
}

static void struct_size(void)
{
    bp_options opt;
    bp_atlas at;
    bp_error err;
    bp_status st;
    unsigned char big[sizeof(bp_options) + 16];
    bp_options_init(&opt);
    BPT_CHECK(opt.struct_size == sizeof opt && opt.run_progress == NULL && opt.threads == 0,
              "bp_options_init: zeros (the defaults) and struct_size = sizeof");
    /* a caller whose struct ends before run_progress: the field is not read */
    opt.run_progress = always_cancel;
    opt.struct_size = offsetof(bp_options, run_progress);
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_OK, "an older struct_size (%u bytes): run_progress beyond it is ignored (%s)",
              (unsigned)opt.struct_size, bp_status_string(st));
    bp_atlas_free(&at);
    opt.struct_size = sizeof opt;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_ERR_CANCELLED, "the full struct_size: run_progress is read (%s)", bp_status_string(st));
    bp_atlas_free(&at);
    opt.struct_size = 0;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_ERR_CANCELLED, "struct_size 0 (the 0.2.0 layout): run_progress is read (%s)", bp_status_string(st));
    bp_atlas_free(&at);
    opt.struct_size = 8;
    st = bp_parameterize(&at, &grids, &opt, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, 8), "struct_size 8 refused: %s", err.message);
    /* a newer caller: unknown bytes must be zero */
    memset(big, 0, sizeof big);
    bp_options_init(&opt);
    opt.struct_size = sizeof big;
    memcpy(big, &opt, sizeof opt);
    st = bp_parameterize(&at, &grids, (const bp_options *)(const void *)big, &err);
    BPT_CHECK(st == BP_OK, "a larger struct_size whose unknown bytes are zero is accepted (%s)", err.message);
    bp_atlas_free(&at);
    big[sizeof(bp_options) + 3] = 1;
    st = bp_parameterize(&at, &grids, (const bp_options *)(const void *)big, &err);
    BPT_CHECK(st == BP_ERR_INVALID_ARGUMENT && bpt_has_number(err.message, (long long)sizeof(bp_options) + 3),
              "a set byte beyond this version's struct is refused, named: %s", err.message);
}

int main(void)
{
    setup();
    cancel_in_run(BP_STAGE_CHARTS, 1, 0, 0);
    cancel_in_run(BP_STAGE_CHARTS, 2, 0, 0);
    cancel_in_run(BP_STAGE_START, 1, 0, 0);
    cancel_in_run(BP_STAGE_START, 4, 0, 0);
    cancel_in_run(BP_STAGE_VISIBILITY, 1, 0, 1);
    cancel_in_run(BP_STAGE_OPTIMIZE, 1, 0, 0);
    cancel_in_run(BP_STAGE_OPTIMIZE, 1, 0.5, 0);    /* half the triangles done: the last chart reports alone */
    cancel_in_run(BP_STAGE_PACK, 1, 0, 0);
    cancel_in_run(BP_STAGE_PACK, 2, 0, 0);
    pack_reports(0);
    pack_reports(256);
    per_chart_cancel();
    slow_callback(BP_STAGE_START, 3, 0, 0);
    slow_callback(BP_STAGE_OPTIMIZE, 1, 0.5, 0);
    slow_callback(BP_STAGE_START, 3, 0, 1);
    slow_callback(BP_STAGE_OPTIMIZE, 1, 0.5, 1);
    read_write();
    struct_size();
    bp_mesh_free(&grids, NULL);
    return bpt_finish();
}
