/* bp_draw.h - pictures of bijparam.h results: SVG of the UV layout, PNG of a
   checkerboard-textured render - MIT license, same as bijparam.h

   A small companion of bijparam.h for the examples and the tool.  It draws
   what the dissertation's figures show:

     - bpd_write_atlas_svg: the UV layout (figs 3.3, 3.8): each triangle
       filled with a colour for its distortion (the energy, the area ratio or
       the angle ratio s_max/s_min) or each chart with a colour of its own,
       the boundary loops drawn on top, a
       legend with the colour scale and the mean and maximum energy, every
       chart labelled with its index;
     - bpd_write_strip_svg: several snapshots of one chart side by side (the
       optimization in motion, fig 3.8);
     - bpd_write_checker_png: the 3D mesh textured with a checkerboard through
       its UV map (figs 3.2, 3.7), drawn by a software rasterizer (z-buffer,
       Lambert shading, orthographic camera), one view or a turntable strip;
     - bpd_write_png: an RGB image as PNG, with a small deflate encoder of
       its own (LZ77 with fixed Huffman codes), so no zlib is needed.

   Use: include bijparam.h first (declarations), then this file; in exactly
   one C file define BPD_IMPLEMENTATION before including it:

       #define BP_IMPLEMENTATION
       #include "bijparam.h"
       #define BPD_IMPLEMENTATION
       #include "bp_draw.h"

   Every writer returns 1 on success and 0 on failure (errno tells why: a
   file error, or ENOMEM).  It keeps no global state.  C99, stdlib only. */
#ifndef BP_DRAW_H
#define BP_DRAW_H

#include "bijparam.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What colours the triangles of the UV layout. */
typedef enum bpd_color {
    BPD_COLOR_ENERGY = 0,  /* E_t of the chosen energy, log scale from its minimum */
    BPD_COLOR_AREA,        /* area ratio (UV area / 3D area, divided by the
                              chart's overall ratio): blue shrunk, red grown */
    BPD_COLOR_ANGLE,       /* angle distortion s_max/s_min (1 = conformal)   */
    BPD_COLOR_CHART        /* one colour per chart (bpd_chart_color), to see
                              the seams and the packing of an atlas        */
} bpd_color;

/* Options of the SVG writers; zero means the default. */
typedef struct bpd_svg_options {
    int       size;         /* width of the drawing in pixels; 0: 800        */
    bpd_color color;        /* what the fill shows                           */
    bp_energy energy;       /* the energy for BPD_COLOR_ENERGY and the legend */
    double    range_max;    /* top of the colour scale; 0: the largest value
                               (fix it to compare frames of a sequence)     */
    double    quantile;     /* in (0,1): the top of the colour scale is this
                               quantile of the values (e.g. 0.98: a few
                               extreme triangles do not wash out the rest);
                               0: the largest value                        */
    double    fill_opacity; /* 0: opaque; below 1 overlaps show darker       */
    const char *title;      /* optional caption at the top                   */
    int       packed;       /* nonzero: the layout is a packed atlas in
                               [0,1]^2 (atlas SVG only): the whole square is
                               drawn, framed, and the energies (fill and
                               legend) are measured with the layout scaled by
                               one factor so that its UV area equals its 3D
                               area (not at the scale of the unit square);
                               one factor for all charts, as they share one
                               texel density                                */
} bpd_svg_options;

/* Options of the checkerboard render; zero means the default. */
typedef struct bpd_render_options {
    int    size;            /* pixels of one (square) view; 0: 512          */
    double view[3];         /* direction from the mesh toward the camera;
                               0: (1, 0.6, 1.2), a 3/4 view                  */
    double up[3];           /* the screen's up and the turntable axis; 0: +y */
    double checker;         /* checker squares across the atlas; 0: 16       */
    int    views;           /* turntable views side by side; 0: 1            */
} bpd_render_options;

/* The whole atlas (every chart that has a map). */
int bpd_write_atlas_svg(const char *path, const bp_mesh *mesh, const bp_atlas *atlas,
                        const bpd_svg_options *opt);
/* One chart drawn `count` times side by side, with uvs[k] as its map in cell
   k (2*num_vertices each) and labels[k] as the cell's caption (may be NULL). */
int bpd_write_strip_svg(const char *path, const bp_mesh *mesh, const bp_chart *chart,
                        const double *const *uvs, const char *const *labels, int count,
                        const bpd_svg_options *opt);
/* The mesh with a checkerboard texture through the atlas's map. */
int bpd_write_checker_png(const char *path, const bp_mesh *mesh, const bp_atlas *atlas,
                          const bpd_render_options *opt);
/* 8-bit RGB pixels, rows top to bottom, as a PNG file. */
int bpd_write_png(const char *path, int width, int height, const unsigned char *rgb);
/* The colour of t in [0, 1]: viridis (sequential) or, if diverging,
   blue - white - red. */
void bpd_colormap(double t, int diverging, unsigned char rgb[3]);
/* The colour of chart c: hues that step by the golden ratio of a turn, so
   that charts of neighbouring indices (often neighbours on the surface and
   in the atlas) differ clearly however many charts there are; saturation
   and value in three alternating levels.  Deterministic. */
void bpd_chart_color(uint32_t c, unsigned char rgb[3]);

#ifdef __cplusplus
}
#endif
#endif /* BP_DRAW_H */

/* ==========================================================================
   IMPLEMENTATION
   ========================================================================== */
#if defined(BPD_IMPLEMENTATION) && !defined(BPD__IMPLEMENTATION_DONE)
#define BPD__IMPLEMENTATION_DONE

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- colours ------------------------------------------------------------ */

void bpd_chart_color(uint32_t c, unsigned char rgb[3])
{
    /* hue h = frac(0.08 + c (sqrt(5) - 1) / 2), then HSV -> RGB */
    double h = fmod(0.08 + (double)c * 0.6180339887498949, 1.0) * 6;
    double s = c % 3 == 1 ? 0.45 : 0.6, v = c % 3 == 2 ? 0.8 : 0.95;
    int i = (int)h, k;
    double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    double r[3];
    switch (i % 6) {
    case 0: r[0] = v; r[1] = t; r[2] = p; break;
    case 1: r[0] = q; r[1] = v; r[2] = p; break;
    case 2: r[0] = p; r[1] = v; r[2] = t; break;
    case 3: r[0] = p; r[1] = q; r[2] = v; break;
    case 4: r[0] = t; r[1] = p; r[2] = v; break;
    default: r[0] = v; r[1] = p; r[2] = q; break;
    }
    for (k = 0; k < 3; k++) rgb[k] = (unsigned char)(255 * r[k] + 0.5);
}

void bpd_colormap(double t, int diverging, unsigned char rgb[3])
{
    /* viridis and ColorBrewer RdBu (reversed), sampled at equal steps */
    static const unsigned char seq[9][3] = {
        {68, 1, 84}, {71, 45, 123}, {59, 82, 139}, {44, 114, 142}, {33, 145, 140},
        {40, 174, 128}, {94, 201, 98}, {173, 220, 48}, {253, 231, 37} };
    static const unsigned char div[9][3] = {
        {33, 102, 172}, {67, 147, 195}, {146, 197, 222}, {209, 229, 240}, {247, 247, 247},
        {253, 219, 199}, {244, 165, 130}, {214, 96, 77}, {178, 24, 43} };
    const unsigned char (*tab)[3] = diverging ? div : seq;
    double x;
    int i, k;
    if (!(t > 0)) t = 0;               /* NaN too */
    if (t > 1) t = 1;
    x = t * 8;
    i = (int)x;
    if (i > 7) i = 7;
    x -= i;
    for (k = 0; k < 3; k++)
        rgb[k] = (unsigned char)(tab[i][k] + x * (tab[i + 1][k] - tab[i][k]) + 0.5);
}

/* ---- per-triangle distortion -------------------------------------------- */

static const double *bpd__pos(const bp_mesh *m, uint32_t v) { return m->positions + 3 * (size_t)v; }

static double bpd__area3(const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], x, y, z;
    int k;
    for (k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; }
    x = e1[1] * e2[2] - e1[2] * e2[1];
    y = e1[2] * e2[0] - e1[0] * e2[2];
    z = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

static double bpd__area2(const double *a, const double *b, const double *c)
{
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

/* The least value an energy can take (at an isometry). */
static double bpd__energy_min(bp_energy e)
{
    switch (e) {
    case BP_ENERGY_SYMMETRIC_DIRICHLET: return 4;
    case BP_ENERGY_MIPS: return 2;
    case BP_ENERGY_ISOMETRIC: return sqrt(2.0);
    default: return 1;
    }
}

/* What the fill shows, per triangle of `chart` under the map `uv`:
   energy and angle ratio from bp_chart_distortion (the angle ratio is the
   conformal energy s_max/s_min); the area ratio as log2 of the triangle's
   UV/3D area ratio over the chart's, so 0 means "as the chart on average".
   Also the chart's mean and max of opt->energy.  The energies are measured
   with uv scaled by `scale` (1: as it is). */
static int bpd__values(const bp_mesh *m, const bp_chart *chart, const double *uv, double scale,
                       const bpd_svg_options *o, double *val, double *mean, double *max)
{
    bp_chart c = *chart;               /* a shallow copy that looks at uv */
    double *scaled = NULL;
    int ok;
    c.uv = (double *)uv;
    if (scale != 1) {
        size_t i;
        if (!(scaled = (double *)malloc((2 * (size_t)c.num_vertices + 1) * sizeof(double)))) return 0;
        for (i = 0; i < 2 * (size_t)c.num_vertices; i++) scaled[i] = scale * uv[i];
        c.uv = scaled;
    }
    ok = bp_chart_distortion(&c, m, o->energy, mean, max,
                             o->color == BPD_COLOR_ENERGY ? val : NULL, NULL) == BP_OK;
    if (ok && o->color == BPD_COLOR_ANGLE)
        ok = bp_chart_distortion(&c, m, BP_ENERGY_CONFORMAL, NULL, NULL, val, NULL) == BP_OK;
    free(scaled);
    c.uv = (double *)uv;
    if (!ok) return 0;
    if (o->color == BPD_COLOR_CHART) {
        memset(val, 0, c.num_triangles * sizeof(double));   /* one colour */
    } else if (o->color == BPD_COLOR_AREA) {
        double a3 = 0, a2 = 0, s;
        uint32_t t;
        for (t = 0; t < c.num_triangles; t++) {
            const uint32_t *tr = c.triangles + 3 * (size_t)t;
            double A3 = bpd__area3(bpd__pos(m, c.vertex[tr[0]]), bpd__pos(m, c.vertex[tr[1]]),
                                   bpd__pos(m, c.vertex[tr[2]]));
            double A2 = bpd__area2(uv + 2 * tr[0], uv + 2 * tr[1], uv + 2 * tr[2]);
            a3 += A3; a2 += A2;
            val[t] = A2 / A3;
        }
        s = a3 / a2;
        for (t = 0; t < c.num_triangles; t++) val[t] = log(val[t] * s) / log(2.0);
    }
    return 1;
}

/* A colour scale: value -> t in [0, 1].  Energy and angle ratio go on a log
   scale from their minimum lo to hi; the area's log2 ratio on [-hi, hi]. */
typedef struct bpd__scale { int diverging, clipped; double lo, hi; } bpd__scale;

static double bpd__scale_t(const bpd__scale *s, double v)
{
    double t;
    if (v != v) return 1;                        /* NaN: worst */
    if (s->diverging) t = 0.5 + 0.5 * v / s->hi;
    else if (!(v > s->lo)) t = 0;
    else t = log(v / s->lo) / log(s->hi / s->lo);
    return t < 0 ? 0 : t > 1 ? 1 : t;
}

/* ---- SVG ----------------------------------------------------------------

   Triangles are grouped by their colour, quantized to 64 steps, into one
   <path> per colour, which keeps files of many thousands of triangles small.
   Each path is also stroked with its own colour, half a pixel wide, to
   hide the hairline gaps a browser's anti-aliasing leaves between
   neighbouring triangles.  Translucent fills (fill_opacity < 1) are drawn
   one <path> per triangle instead, without strokes, so that overlapping
   triangles (a map made without the barrier) show darker. */

enum { BPD__LEVELS = 64 };

typedef struct bpd__cell {          /* uv -> pixel: x = ox + s (u - u0), y = oy - s (v - v0) */
    double s, u0, v0, ox, oy;
    double w;                       /* width of the cell in pixels */
} bpd__cell;

static void bpd__bbox(const double *uv, uint32_t n, double lo[2], double hi[2])
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        int k;
        for (k = 0; k < 2; k++) {
            if (uv[2 * i + k] < lo[k]) lo[k] = uv[2 * i + k];
            if (uv[2 * i + k] > hi[k]) hi[k] = uv[2 * i + k];
        }
    }
}

/* Fit the box [lo, hi] into the pixel rectangle (x, y, w, h), centred. */
static bpd__cell bpd__fit(const double lo[2], const double hi[2], double x, double y, double w, double h)
{
    bpd__cell c;
    double du = hi[0] - lo[0], dv = hi[1] - lo[1], s;
    if (!(du > 0)) du = 1;
    if (!(dv > 0)) dv = 1;
    s = w / du < h / dv ? w / du : h / dv;
    c.s = s;
    c.w = w;
    c.u0 = lo[0]; c.v0 = lo[1];
    c.ox = x + 0.5 * (w - s * du);
    c.oy = y + h - 0.5 * (h - s * dv);
    return c;
}

#define BPD__X(c, p) ((c)->ox + (c)->s * ((p)[0] - (c)->u0))
#define BPD__Y(c, p) ((c)->oy - (c)->s * ((p)[1] - (c)->v0))

static void bpd__svg_text(FILE *f, double x, double y, double size, const char *anchor, const char *text)
{
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"%.1f\" text-anchor=\"%s\">", x, y, size, anchor);
    for (; *text; text++) {
        if (*text == '<') fputs("&lt;", f);
        else if (*text == '>') fputs("&gt;", f);
        else if (*text == '&') fputs("&amp;", f);
        else fputc(*text, f);
    }
    fputs("</text>\n", f);
}

/* The triangles of one chart (values val) and its boundary loops.  With
   the colour `solid` (not NULL) and an opaque fill, the chart is instead
   one path through its boundary loops filled even-odd: for a bijective map
   that region is exactly the union of its UV triangles (the loops bound
   the image), and the file stays small however many triangles the chart
   has.  A map with fold-overs (--no-barrier) would show its boundary's
   region, not its triangles; translucent fills keep the triangles. */
static void bpd__svg_chart(FILE *f, const bp_chart *ch, const double *uv, const double *val,
                           const unsigned char *solid, const bpd__scale *sc, const bpd__cell *cell,
                           double opacity)
{
    int level;
    uint32_t t, l;
    /* coordinates to 0.1 pixel; whole pixels in small cells (the strips),
       which keeps a strip of several thousand-triangle frames small */
    const int digits = cell->w < 300 ? 0 : 1;
    if (solid && opacity >= 1 && ch->num_loops > 0) {
        fprintf(f, "<path fill=\"#%02x%02x%02x\" fill-rule=\"evenodd\" d=\"", solid[0], solid[1], solid[2]);
        for (l = 0; l < ch->num_loops; l++) {
            uint32_t k;
            for (k = ch->loop_start[l]; k < ch->loop_start[l + 1]; k++) {
                const double *p = uv + 2 * (size_t)ch->loop_vertices[k];
                fprintf(f, "%s%.*f %.*f", k > ch->loop_start[l] ? "L" : "M", digits, BPD__X(cell, p),
                        digits, BPD__Y(cell, p));
            }
            fputc('Z', f);
        }
        fputs("\"/>\n", f);
    }
    for (level = 0; level < BPD__LEVELS && !(solid && opacity >= 1 && ch->num_loops > 0); level++) {
        unsigned char rgb[3];
        int any = 0;
        for (t = 0; t < ch->num_triangles; t++) {
            const uint32_t *tr = ch->triangles + 3 * (size_t)t;
            int q = (int)(bpd__scale_t(sc, val[t]) * (BPD__LEVELS - 1) + 0.5), k;
            if (q < 0) q = 0;
            if (q > BPD__LEVELS - 1) q = BPD__LEVELS - 1;
            if (solid) q = 0;
            if (q != level) continue;
            if (!any) {
                if (solid) memcpy(rgb, solid, 3);
                else bpd_colormap((double)level / (BPD__LEVELS - 1), sc->diverging, rgb);
                if (opacity < 1)
                    fprintf(f, "<path fill=\"#%02x%02x%02x\" fill-opacity=\"%.2f\" d=\"",
                            rgb[0], rgb[1], rgb[2], opacity);
                else
                    fprintf(f, "<path fill=\"#%02x%02x%02x\" stroke=\"#%02x%02x%02x\" "
                            "stroke-width=\"0.5\" stroke-linejoin=\"round\" d=\"",
                            rgb[0], rgb[1], rgb[2], rgb[0], rgb[1], rgb[2]);
                any = 1;
            }
            for (k = 0; k < 3; k++) {
                const double *p = uv + 2 * (size_t)tr[k];
                fprintf(f, "%s%.*f %.*f", k ? "L" : "M", digits, BPD__X(cell, p), digits, BPD__Y(cell, p));
            }
            fputc('Z', f);
            /* translucent: one element per triangle, so that where two
               triangles overlap both are composited (within one path the
               union is filled once and the overlap would not show) */
            if (opacity < 1) { fputs("\"/>\n", f); any = 0; }
        }
        if (any) fputs("\"/>\n", f);
    }
    for (l = 0; l < ch->num_loops; l++) {
        uint32_t k;
        fprintf(f, "<polygon fill=\"none\" stroke=\"%s\" stroke-width=\"%s\" stroke-linejoin=\"round\" points=\"",
                l == 0 ? "#000" : "#444", l == 0 ? "1.2" : "0.9");
        for (k = ch->loop_start[l]; k < ch->loop_start[l + 1]; k++) {
            const double *p = uv + 2 * (size_t)ch->loop_vertices[k];
            fprintf(f, "%s%.*f,%.*f", k > ch->loop_start[l] ? " " : "", digits, BPD__X(cell, p), digits, BPD__Y(cell, p));
        }
        fputs("\"/>\n", f);
    }
}

/* A label at the chart's "middle": the centroid of the triangle nearest to
   the area centroid of its UV triangles (inside the chart even if concave). */
static void bpd__svg_label(FILE *f, const bp_chart *ch, const double *uv, const bpd__cell *cell,
                           const char *text)
{
    double cx = 0, cy = 0, A = 0, best = HUGE_VAL, lx = 0, ly = 0;
    uint32_t t;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        const double *a = uv + 2 * tr[0], *b = uv + 2 * tr[1], *c = uv + 2 * tr[2];
        double w = fabs(bpd__area2(a, b, c));
        cx += w * (a[0] + b[0] + c[0]) / 3; cy += w * (a[1] + b[1] + c[1]) / 3; A += w;
    }
    if (!(A > 0)) return;
    cx /= A; cy /= A;
    for (t = 0; t < ch->num_triangles; t++) {
        const uint32_t *tr = ch->triangles + 3 * (size_t)t;
        const double *a = uv + 2 * tr[0], *b = uv + 2 * tr[1], *c = uv + 2 * tr[2];
        double mx = (a[0] + b[0] + c[0]) / 3, my = (a[1] + b[1] + c[1]) / 3;
        double d = (mx - cx) * (mx - cx) + (my - cy) * (my - cy);
        if (d < best) { best = d; lx = mx; ly = my; }
    }
    {
        double p[2];
        p[0] = lx; p[1] = ly;
        fprintf(f, "<g class=\"label\">");
        bpd__svg_text(f, BPD__X(cell, p), BPD__Y(cell, p) + 5, 15, "middle", text);
        fprintf(f, "</g>\n");
    }
}

/* The colour bar with three ticks and the energy summary; for colour by
   chart, a row of the first charts' colours instead of the bar. */
static void bpd__svg_legend(FILE *f, double x, double y, double w, const bpd__scale *sc,
                            const bpd_svg_options *o, uint32_t charts, double mean, double max)
{
    char buf[200];
    int k;
    if (o->color == BPD_COLOR_CHART) {
        uint32_t c, shown = charts < 24 ? charts : 24;
        snprintf(buf, sizeof buf, "colour: chart (%u chart%s, each its own colour)",
                 (unsigned)charts, charts == 1 ? "" : "s");
        bpd__svg_text(f, x, y, 13, "start", buf);
        for (c = 0; c < shown; c++) {
            unsigned char rgb[3];
            bpd_chart_color(c, rgb);
            fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"14\" fill=\"#%02x%02x%02x\" "
                    "stroke=\"#000\" stroke-width=\"0.5\"/>\n", x + w * c / 24, y + 6, w / 24,
                    rgb[0], rgb[1], rgb[2]);
        }
        snprintf(buf, sizeof buf, "charts 0%s%u", shown < charts ? " ... " : " - ", (unsigned)(shown - 1));
        if (shown > 0) bpd__svg_text(f, x, y + 37, 12, "start", buf);
        snprintf(buf, sizeof buf, "%s energy: mean %.5g, max %.5g (minimum possible %.4g)",
                 bp_energy_name(o->energy), mean, max, bpd__energy_min(o->energy));
        bpd__svg_text(f, x, y + 54, 13, "start", buf);
        return;
    }
    const char *what = o->color == BPD_COLOR_AREA ? "area ratio (UV / 3D, relative to the chart)"
                     : o->color == BPD_COLOR_ANGLE ? "angle distortion s_max / s_min"
                     : bp_energy_name(o->energy);
    fprintf(f, "<defs><linearGradient id=\"bpd_scale\" x1=\"0\" x2=\"1\" y1=\"0\" y2=\"0\">\n");
    for (k = 0; k <= 16; k++) {
        unsigned char rgb[3];
        bpd_colormap(k / 16.0, sc->diverging, rgb);
        fprintf(f, "<stop offset=\"%.4f\" stop-color=\"#%02x%02x%02x\"/>\n", k / 16.0, rgb[0], rgb[1], rgb[2]);
    }
    fprintf(f, "</linearGradient></defs>\n");
    snprintf(buf, sizeof buf, "colour: %s%s", what,
             o->color == BPD_COLOR_AREA ? "" : ", log scale");
    bpd__svg_text(f, x, y, 13, "start", buf);
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"14\" fill=\"url(#bpd_scale)\" stroke=\"#000\" stroke-width=\"0.5\"/>\n",
            x, y + 6, w);
    for (k = 0; k < 3; k++) {
        double v;
        if (sc->diverging) v = pow(2.0, sc->hi * (k - 1));          /* ratio */
        else v = sc->lo * pow(sc->hi / sc->lo, k / 2.0);
        snprintf(buf, sizeof buf, "%.4g%s", v, k == 2 && sc->clipped ? " or more" : "");
        fprintf(f, "<line x1=\"%.1f\" x2=\"%.1f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#000\" stroke-width=\"0.8\"/>\n",
                x + w * k / 2, x + w * k / 2, y + 20, y + 25);
        bpd__svg_text(f, x + w * k / 2, y + 37, 12, k == 0 ? "start" : k == 2 ? "end" : "middle", buf);
    }
    snprintf(buf, sizeof buf, "%s energy: mean %.5g, max %.5g (minimum possible %.4g)",
             bp_energy_name(o->energy), mean, max, bpd__energy_min(o->energy));
    bpd__svg_text(f, x, y + 54, 13, "start", buf);
}

static FILE *bpd__svg_begin(const char *path, double w, double h)
{
    FILE *f = fopen(path, "w");
    if (!f) return NULL;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" "
            "font-family=\"Helvetica, Arial, sans-serif\">\n"
            "<style>.label text { fill: #fff; stroke: #000; stroke-width: 3px; paint-order: stroke; font-weight: bold; }</style>\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"#fff\"/>\n", w, h, w, h);
    return f;
}

static int bpd__svg_end(FILE *f)
{
    int bad;
    fputs("</svg>\n", f);
    bad = ferror(f);
    if (fclose(f) != 0 || bad) { if (!errno) errno = EIO; return 0; }
    return 1;
}

/* The scale of a set of values (all drawn charts share it). */
static void bpd__scale_grow(bpd__scale *sc, const double *val, uint32_t n)
{
    uint32_t t;
    for (t = 0; t < n; t++) {
        double v = sc->diverging ? fabs(val[t]) : val[t];
        if (v > sc->hi && v < HUGE_VAL) sc->hi = v;
    }
}

static int bpd__cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Lower the top of the scale to the q-quantile of the n values (the area
   scale looks at |log2 ratio|); without memory the scale stays as it is. */
static void bpd__scale_quantile(bpd__scale *sc, const double *val, size_t n, double q)
{
    double *tmp;
    size_t i, m = 0;
    if (!(q > 0 && q < 1) || n == 0) return;
    if (!(tmp = (double *)malloc(n * sizeof(double)))) return;
    for (i = 0; i < n; i++) {
        double v = sc->diverging ? fabs(val[i]) : val[i];
        if (v == v) tmp[m++] = v;
    }
    if (m > 0) {
        double top;
        qsort(tmp, m, sizeof(double), bpd__cmp_double);
        top = tmp[(size_t)(q * (double)(m - 1))];
        if (top < sc->hi) { sc->hi = top; sc->clipped = 1; }
    }
    free(tmp);
}

static void bpd__scale_init(bpd__scale *sc, const bpd_svg_options *o)
{
    sc->diverging = o->color == BPD_COLOR_AREA;
    sc->lo = o->color == BPD_COLOR_ENERGY ? bpd__energy_min(o->energy) : 1;
    sc->hi = sc->diverging ? 0.25 : sc->lo * 1.05;   /* never a zero-width scale */
    sc->clipped = 0;
}

static void bpd__scale_finish(bpd__scale *sc, const bpd_svg_options *o)
{
    if (o->range_max > 0) {
        sc->hi = sc->diverging ? log(o->range_max) / log(2.0) : o->range_max;
        sc->clipped = 1;
    }
    if (!sc->diverging && !(sc->hi > sc->lo)) sc->hi = sc->lo * 1.05;
    if (sc->diverging && !(sc->hi > 0)) sc->hi = 0.25;
}

int bpd_write_atlas_svg(const char *path, const bp_mesh *mesh, const bp_atlas *atlas,
                        const bpd_svg_options *opt)
{
    bpd_svg_options o;
    bpd__scale sc;
    bpd__cell cell;
    double **val, lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL };
    double sum = 0, area = 0, emax = 0, W, H, top, du, dv, uv_scale = 1;
    uint32_t c;
    FILE *f;
    int ok = 1;
    char buf[32];
    memset(&o, 0, sizeof o);
    if (opt) o = *opt;
    if (o.size <= 0) o.size = 800;
    if (o.fill_opacity <= 0 || o.fill_opacity > 1) o.fill_opacity = 1;
    val = (double **)calloc(atlas->num_charts + 1, sizeof *val);
    if (!val) { errno = ENOMEM; return 0; }
    bpd__scale_init(&sc, &o);
    if (o.packed) {              /* one factor: UV area = 3D area */
        double a3 = 0, a2 = 0;
        for (c = 0; c < atlas->num_charts; c++) {
            const bp_chart *ch = &atlas->charts[c];
            uint32_t t;
            if (!ch->uv) continue;
            for (t = 0; t < ch->num_triangles; t++) {
                const uint32_t *tr = ch->triangles + 3 * (size_t)t;
                a3 += bpd__area3(bpd__pos(mesh, ch->vertex[tr[0]]), bpd__pos(mesh, ch->vertex[tr[1]]),
                                 bpd__pos(mesh, ch->vertex[tr[2]]));
                a2 += fabs(bpd__area2(ch->uv + 2 * tr[0], ch->uv + 2 * tr[1], ch->uv + 2 * tr[2]));
            }
        }
        if (a3 > 0 && a2 > 0) uv_scale = sqrt(a3 / a2);
    }
    for (c = 0; c < atlas->num_charts && ok; c++) {
        const bp_chart *ch = &atlas->charts[c];
        double mean, mx;
        if (!ch->uv) continue;
        val[c] = (double *)malloc((ch->num_triangles + 1) * sizeof(double));
        if (!val[c] || !bpd__values(mesh, ch, ch->uv, uv_scale, &o, val[c], &mean, &mx)) { ok = 0; break; }
        sum += mean * ch->area3d; area += ch->area3d;
        if (mx > emax) emax = mx;
        bpd__scale_grow(&sc, val[c], ch->num_triangles);
        bpd__bbox(ch->uv, ch->num_vertices, lo, hi);
    }
    if (ok && o.quantile > 0 && o.quantile < 1) {
        size_t n = 0, m = 0;
        double *all;
        for (c = 0; c < atlas->num_charts; c++) if (val[c]) n += atlas->charts[c].num_triangles;
        if ((all = (double *)malloc((n + 1) * sizeof(double))) != NULL) {
            for (c = 0; c < atlas->num_charts; c++)
                if (val[c]) { memcpy(all + m, val[c], atlas->charts[c].num_triangles * sizeof(double)); m += atlas->charts[c].num_triangles; }
            bpd__scale_quantile(&sc, all, m, o.quantile);
            free(all);
        }
    }
    bpd__scale_finish(&sc, &o);
    if (!ok) errno = ENOMEM;
    if (ok && !(hi[0] >= lo[0])) { lo[0] = lo[1] = 0; hi[0] = hi[1] = 1; }
    if (o.packed) {                    /* the whole atlas square */
        int k;
        for (k = 0; k < 2; k++) {
            if (lo[k] > 0) lo[k] = 0;
            if (hi[k] < 1) hi[k] = 1;
        }
    }
    /* page: title, the atlas at its aspect ratio, the legend under it */
    W = o.size;
    du = hi[0] - lo[0]; dv = hi[1] - lo[1];
    top = o.title ? 30 : 10;
    H = top + (W - 20) * (du > 0 && dv > 0 ? (dv / du < 1.5 ? dv / du : 1.5) : 1) + 10 + 70;
    cell = bpd__fit(lo, hi, 10, top, W - 20, H - top - 80);
    if (ok && !(f = bpd__svg_begin(path, W, H))) ok = 0;
    if (ok) {
        if (o.title) bpd__svg_text(f, W / 2, 20, 15, "middle", o.title);
        if (o.packed) {
            double p0[2] = { 0, 1 }, p1[2] = { 1, 0 };
            fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#f4f4f4\" "
                    "stroke=\"#999\" stroke-width=\"1\"/>\n", BPD__X(&cell, p0), BPD__Y(&cell, p0),
                    BPD__X(&cell, p1) - BPD__X(&cell, p0), BPD__Y(&cell, p1) - BPD__Y(&cell, p0));
        }
        for (c = 0; c < atlas->num_charts; c++)
            if (val[c]) {
                unsigned char rgb[3];
                bpd_chart_color(c, rgb);
                bpd__svg_chart(f, &atlas->charts[c], atlas->charts[c].uv, val[c],
                               o.color == BPD_COLOR_CHART ? rgb : NULL, &sc, &cell, o.fill_opacity);
            }
        for (c = 0; c < atlas->num_charts; c++)
            if (val[c]) {
                snprintf(buf, sizeof buf, "%u", (unsigned)c);
                bpd__svg_label(f, &atlas->charts[c], atlas->charts[c].uv, &cell, buf);
            }
        bpd__svg_legend(f, 10, H - 72, W < 420 ? W - 20 : 400, &sc, &o, atlas->num_charts,
                        area > 0 ? sum / area : 0, emax);
        ok = bpd__svg_end(f);
    }
    for (c = 0; c < atlas->num_charts; c++) free(val[c]);
    free(val);
    return ok;
}

int bpd_write_strip_svg(const char *path, const bp_mesh *mesh, const bp_chart *chart,
                        const double *const *uvs, const char *const *labels, int count,
                        const bpd_svg_options *opt)
{
    bpd_svg_options o;
    bpd__scale sc;
    double *val, cw, W, H, mean_last = 0, max_last = 0;
    int k, ok = 1;
    FILE *f = NULL;
    memset(&o, 0, sizeof o);
    if (opt) o = *opt;
    if (o.size <= 0) o.size = 800;
    if (o.fill_opacity <= 0 || o.fill_opacity > 1) o.fill_opacity = 1;
    if (count < 1) { errno = EINVAL; return 0; }
    val = (double *)malloc(((size_t)chart->num_triangles * (size_t)count + 1) * sizeof(double));
    if (!val) { errno = ENOMEM; return 0; }
    bpd__scale_init(&sc, &o);
    for (k = 0; k < count && ok; k++) {
        ok = bpd__values(mesh, chart, uvs[k], 1, &o, val + (size_t)k * chart->num_triangles, &mean_last, &max_last);
        bpd__scale_grow(&sc, val + (size_t)k * chart->num_triangles, chart->num_triangles);
    }
    if (ok) bpd__scale_quantile(&sc, val, (size_t)chart->num_triangles * (size_t)count, o.quantile);
    bpd__scale_finish(&sc, &o);
    if (!ok) errno = ENOMEM;
    W = o.size;
    cw = (W - 10) / count;
    H = (o.title ? 30 : 10) + cw + 24 + 80;
    if (ok && !(f = bpd__svg_begin(path, W, H))) ok = 0;
    if (ok) {
        double top = o.title ? 30 : 10;
        if (o.title) bpd__svg_text(f, W / 2, 20, 15, "middle", o.title);
        for (k = 0; k < count; k++) {
            double lo[2] = { HUGE_VAL, HUGE_VAL }, hi[2] = { -HUGE_VAL, -HUGE_VAL };
            bpd__cell cell;
            bpd__bbox(uvs[k], chart->num_vertices, lo, hi);
            cell = bpd__fit(lo, hi, 5 + k * cw + 4, top, cw - 8, cw - 8);
            unsigned char rgb[3];
            bpd_chart_color(0, rgb);
            bpd__svg_chart(f, chart, uvs[k], val + (size_t)k * chart->num_triangles,
                           o.color == BPD_COLOR_CHART ? rgb : NULL, &sc, &cell, o.fill_opacity);
            if (labels && labels[k]) bpd__svg_text(f, 5 + (k + 0.5) * cw, top + cw + 12, 13, "middle", labels[k]);
        }
        bpd__svg_legend(f, 10, H - 72, W < 420 ? W - 20 : 400, &sc, &o, 1, mean_last, max_last);
        ok = bpd__svg_end(f);
    }
    free(val);
    return ok;
}

/* ---- PNG ----------------------------------------------------------------

   A PNG is a signature and chunks (length, type, data, CRC-32 of type and
   data): IHDR (size, 8-bit RGB), IDAT (the zlib stream of the filtered
   rows) and IEND.  Each row is first filtered (RFC 2083: None, Sub, Up,
   Average, Paeth; the one with the least sum of |bytes| wins, the usual
   heuristic), which turns flat regions and smooth shading into runs of
   small numbers.  The zlib stream (RFC 1950) is a two-byte header, one
   deflate block (RFC 1951) with the fixed Huffman codes, and the Adler-32
   of the data.  The deflate block is a greedy LZ77 parse: a hash of the
   next three bytes finds earlier positions in a 32 KiB window (up to 64
   candidates, newest first) and the longest match of at least 3 bytes is
   sent as (length, distance), anything else as a literal. */

typedef struct bpd__bits {
    unsigned char *buf;
    size_t len, cap;
    uint32_t acc;
    int n, fail;
} bpd__bits;

static void bpd__byte(bpd__bits *b, unsigned char c)
{
    if (b->len == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 65536;
        unsigned char *p = (unsigned char *)realloc(b->buf, cap);
        if (!p) { b->fail = 1; return; }
        b->buf = p; b->cap = cap;
    }
    b->buf[b->len++] = c;
}

/* n bits of v, least significant first (deflate's bit order). */
static void bpd__put(bpd__bits *b, uint32_t v, int n)
{
    b->acc |= v << b->n;
    b->n += n;
    while (b->n >= 8) { bpd__byte(b, (unsigned char)(b->acc & 255)); b->acc >>= 8; b->n -= 8; }
}

/* A Huffman code is sent most significant bit first: reverse it. */
static void bpd__put_code(bpd__bits *b, uint32_t code, int n)
{
    uint32_t r = 0;
    int i;
    for (i = 0; i < n; i++) { r = (r << 1) | (code & 1); code >>= 1; }
    bpd__put(b, r, n);
}

/* Fixed literal/length code (RFC 1951 sec 3.2.6). */
static void bpd__put_sym(bpd__bits *b, int s)
{
    if (s < 144) bpd__put_code(b, 0x30 + (uint32_t)s, 8);
    else if (s < 256) bpd__put_code(b, 0x190 + (uint32_t)(s - 144), 9);
    else if (s < 280) bpd__put_code(b, (uint32_t)(s - 256), 7);
    else bpd__put_code(b, 0xc0 + (uint32_t)(s - 280), 8);
}

static const unsigned short bpd__len_base[29] = { 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31,
    35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258 };
static const unsigned char bpd__len_extra[29] = { 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2,
    3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0 };
static const unsigned short bpd__dist_base[30] = { 1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129,
    193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577 };
static const unsigned char bpd__dist_extra[30] = { 0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6,
    7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13 };

static void bpd__put_match(bpd__bits *b, int len, int dist)
{
    int i = 28, j = 29;
    while (bpd__len_base[i] > len) i--;
    bpd__put_sym(b, 257 + i);
    bpd__put(b, (uint32_t)(len - bpd__len_base[i]), bpd__len_extra[i]);
    while (bpd__dist_base[j] > dist) j--;
    bpd__put_code(b, (uint32_t)j, 5);
    bpd__put(b, (uint32_t)(dist - bpd__dist_base[j]), bpd__dist_extra[j]);
}

enum { BPD__WIN = 32768, BPD__HASH = 1 << 15, BPD__CHAIN = 64 };

/* zlib stream of data[0, n) appended to b. */
static int bpd__zlib(bpd__bits *b, const unsigned char *d, size_t n)
{
    int32_t *head = (int32_t *)malloc(BPD__HASH * sizeof(int32_t));
    int32_t *prev = (int32_t *)malloc(BPD__WIN * sizeof(int32_t));
    uint32_t s1 = 1, s2 = 0;
    size_t i = 0, k;
    if (!head || !prev) { free(head); free(prev); return 0; }
    for (k = 0; k < BPD__HASH; k++) head[k] = -1;
    bpd__byte(b, 0x78); bpd__byte(b, 0x01);       /* deflate, 32K window, (0x7801 % 31 == 0) */
    bpd__put(b, 1, 1);                            /* last block */
    bpd__put(b, 1, 2);                            /* fixed Huffman codes */
#define BPD__H(p) ((((uint32_t)d[p] << 10) ^ ((uint32_t)d[(p) + 1] << 5) ^ d[(p) + 2]) & (BPD__HASH - 1))
    while (i < n) {
        int best = 0, bestd = 0;
        if (i + 3 <= n) {
            int32_t cand = head[BPD__H(i)];
            int chain = BPD__CHAIN;
            size_t maxlen = n - i < 258 ? n - i : 258;
            while (cand >= 0 && i - (size_t)cand <= BPD__WIN && chain-- > 0) {
                size_t l = 0;
                while (l < maxlen && d[(size_t)cand + l] == d[i + l]) l++;
                if ((int)l > best) { best = (int)l; bestd = (int)(i - (size_t)cand); if (l == maxlen) break; }
                cand = prev[cand & (BPD__WIN - 1)];
            }
        }
        if (best >= 3) {
            bpd__put_match(b, best, bestd);
        } else {
            bpd__put_sym(b, d[i]);
            best = 1;
        }
        for (k = 0; k < (size_t)best; k++, i++) {   /* index every position passed */
            if (i + 3 <= n) {
                uint32_t h = BPD__H(i);
                prev[i & (BPD__WIN - 1)] = head[h];
                head[h] = (int32_t)i;
            }
        }
    }
#undef BPD__H
    bpd__put_sym(b, 256);                         /* end of block */
    bpd__put(b, 0, 7);                            /* flush to a byte */
    b->n = 0; b->acc = 0;
    for (k = 0; k < n; k++) { s1 = (s1 + d[k]) % 65521; s2 = (s2 + s1) % 65521; }
    bpd__byte(b, (unsigned char)(s2 >> 8)); bpd__byte(b, (unsigned char)s2);
    bpd__byte(b, (unsigned char)(s1 >> 8)); bpd__byte(b, (unsigned char)s1);
    free(head); free(prev);
    return !b->fail;
}

static uint32_t bpd__crc(uint32_t crc, const unsigned char *p, size_t n)
{
    size_t i;
    int k;
    crc = ~crc;
    for (i = 0; i < n; i++) {
        crc ^= p[i];
        for (k = 0; k < 8; k++) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1)));
    }
    return ~crc;
}

static void bpd__be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24); p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8); p[3] = (unsigned char)v;
}

static int bpd__chunk(FILE *f, const char *type, const unsigned char *data, size_t n)
{
    unsigned char h[8], c[4];
    uint32_t crc;
    bpd__be32(h, (uint32_t)n);
    memcpy(h + 4, type, 4);
    crc = bpd__crc(0, h + 4, 4);
    crc = bpd__crc(crc, data, n);
    bpd__be32(c, crc);
    return fwrite(h, 1, 8, f) == 8 && (n == 0 || fwrite(data, 1, n, f) == n) && fwrite(c, 1, 4, f) == 4;
}

static int bpd__paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return (pa <= pb && pa <= pc) ? a : pb <= pc ? b : c;
}

int bpd_write_png(const char *path, int w, int h, const unsigned char *rgb)
{
    static const unsigned char sig[8] = { 137, 80, 78, 71, 13, 10, 26, 10 };
    size_t stride = 3 * (size_t)w, y, x;
    unsigned char *raw, *cand, ihdr[13];
    bpd__bits z;
    FILE *f;
    int ok;
    if (w <= 0 || h <= 0) { errno = EINVAL; return 0; }
    raw = (unsigned char *)malloc((stride + 1) * (size_t)h);
    cand = (unsigned char *)malloc(5 * stride);
    if (!raw || !cand) { free(raw); free(cand); errno = ENOMEM; return 0; }
    for (y = 0; y < (size_t)h; y++) {
        const unsigned char *row = rgb + y * stride, *up = y ? row - stride : NULL;
        long best = -1;
        int ft, bestf = 0;
        for (ft = 0; ft < 5; ft++) {
            unsigned char *o = cand + ft * stride;
            long sum = 0;
            for (x = 0; x < stride; x++) {
                int a = x >= 3 ? row[x - 3] : 0, b = up ? up[x] : 0, c = (x >= 3 && up) ? up[x - 3] : 0;
                int pred = ft == 0 ? 0 : ft == 1 ? a : ft == 2 ? b : ft == 3 ? (a + b) / 2 : bpd__paeth(a, b, c);
                o[x] = (unsigned char)(row[x] - pred);
                sum += o[x] < 128 ? o[x] : 256 - o[x];
            }
            if (best < 0 || sum < best) { best = sum; bestf = ft; }
        }
        raw[y * (stride + 1)] = (unsigned char)bestf;
        memcpy(raw + y * (stride + 1) + 1, cand + bestf * stride, stride);
    }
    free(cand);
    memset(&z, 0, sizeof z);
    ok = bpd__zlib(&z, raw, (stride + 1) * (size_t)h);
    free(raw);
    if (!ok) { free(z.buf); errno = ENOMEM; return 0; }
    bpd__be32(ihdr, (uint32_t)w);
    bpd__be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8; ihdr[9] = 2; ihdr[10] = ihdr[11] = ihdr[12] = 0;   /* 8-bit RGB */
    f = fopen(path, "wb");
    if (!f) { free(z.buf); return 0; }
    ok = fwrite(sig, 1, 8, f) == 8 && bpd__chunk(f, "IHDR", ihdr, 13) &&
         bpd__chunk(f, "IDAT", z.buf, z.len) && bpd__chunk(f, "IEND", NULL, 0);
    free(z.buf);
    if (fclose(f) != 0) ok = 0;
    if (!ok && !errno) errno = EIO;
    return ok;
}

/* ---- the checkerboard render --------------------------------------------

   An orthographic camera looks along -view: with d = view/|view|, the
   screen axes are right = up x d and top = d x right, and a point p goes to
   (p.right, p.top) on screen and to depth p.d (larger is nearer).  The
   mesh's bounding sphere fills 90% of the image in every view, so the views
   of a turntable share one scale.

   Every triangle is filled by its edge functions at pixel centres, at twice
   the resolution (2x2 samples per pixel, averaged at the end).  An
   orthographic projection is affine, so depth and uv interpolate linearly
   in screen space (no perspective correction).  The texture is a
   checkerboard of period `atlas size / checker` in uv; the shading is
   Lambert's cosine law with the smooth vertex normal (area-weighted face
   normals) and a light above and to the left of the camera.  A triangle
   seen from behind (its CCW side facing away) is drawn blue-grey: on a
   closed, consistently oriented mesh none should show, so any blue-grey
   means a face is inside out. */

static void bpd__normalize(double *v)
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) { v[0] /= l; v[1] /= l; v[2] /= l; }
}

static void bpd__cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double bpd__dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

typedef struct bpd__scene {
    const bp_mesh *m;
    const bp_atlas *atlas;
    double *normal;          /* 3 per mesh vertex */
    double center[3], radius, period;
} bpd__scene;

/* One view into the size x size tile at (x0, 0) of an image `stride` pixels wide. */
static int bpd__render_view(const bpd__scene *S, const double *view, const double *up0, int size,
                            unsigned char *img, int stride, int x0)
{
    const int ss = 2, n = size * ss;
    float *zb = (float *)malloc((size_t)n * n * sizeof(float));
    float *col = (float *)malloc((size_t)n * n * 3 * sizeof(float));
    double d[3], up[3], right[3], top[3], light[3], scale;
    uint32_t t;
    int i, j, k;
    if (!zb || !col) { free(zb); free(col); errno = ENOMEM; return 0; }
    memcpy(d, view, sizeof d); bpd__normalize(d);
    memcpy(up, up0, sizeof up);
    bpd__cross(up, d, right);
    if (bpd__dot(right, right) < 1e-12) {        /* looking along up: any other up */
        double alt[3] = { 0, 0, 1 };
        if (fabs(d[2]) > 0.9) { alt[1] = 1; alt[2] = 0; }
        bpd__cross(alt, d, right);
    }
    bpd__normalize(right);
    bpd__cross(d, right, top);
    for (k = 0; k < 3; k++) light[k] = d[k] + 0.6 * top[k] - 0.4 * right[k];
    bpd__normalize(light);
    scale = 0.45 * n / S->radius;
    for (i = 0; i < n * n; i++) { zb[i] = -HUGE_VAL; col[3 * i] = 1; col[3 * i + 1] = 1; col[3 * i + 2] = 1; }
    for (t = 0; t < S->m->num_triangles; t++) {
        double sx[3], sy[3], sz[3], uv[3][2], nn[3][3], fn[3], area;
        int bx0, bx1, by0, by1, front;
        uint32_t ci = S->atlas->corner_chart[3 * t];
        const bp_chart *ch = &S->atlas->charts[ci];
        if (!ch->uv) continue;
        for (k = 0; k < 3; k++) {
            uint32_t v = S->m->triangles[3 * t + k];
            const double *p = bpd__pos(S->m, v);
            double q[3];
            q[0] = p[0] - S->center[0]; q[1] = p[1] - S->center[1]; q[2] = p[2] - S->center[2];
            sx[k] = 0.5 * n + scale * bpd__dot(q, right);
            sy[k] = 0.5 * n - scale * bpd__dot(q, top);
            sz[k] = bpd__dot(q, d);
            uv[k][0] = ch->uv[2 * (size_t)S->atlas->corner_vertex[3 * t + k]];
            uv[k][1] = ch->uv[2 * (size_t)S->atlas->corner_vertex[3 * t + k] + 1];
            memcpy(nn[k], S->normal + 3 * (size_t)v, sizeof nn[k]);
        }
        {
            const double *a = bpd__pos(S->m, S->m->triangles[3 * t]);
            const double *b = bpd__pos(S->m, S->m->triangles[3 * t + 1]);
            const double *c = bpd__pos(S->m, S->m->triangles[3 * t + 2]);
            double e1[3], e2[3];
            for (k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; }
            bpd__cross(e1, e2, fn);
            front = bpd__dot(fn, d) > 0;
        }
        /* signed area in screen space (y points down) */
        area = (sx[1] - sx[0]) * (sy[2] - sy[0]) - (sx[2] - sx[0]) * (sy[1] - sy[0]);
        if (area == 0) continue;
        bx0 = (int)floor(fmin(sx[0], fmin(sx[1], sx[2]))); bx1 = (int)ceil(fmax(sx[0], fmax(sx[1], sx[2])));
        by0 = (int)floor(fmin(sy[0], fmin(sy[1], sy[2]))); by1 = (int)ceil(fmax(sy[0], fmax(sy[1], sy[2])));
        if (bx0 < 0) bx0 = 0;
        if (by0 < 0) by0 = 0;
        if (bx1 > n - 1) bx1 = n - 1;
        if (by1 > n - 1) by1 = n - 1;
        for (j = by0; j <= by1; j++)
            for (i = bx0; i <= bx1; i++) {
                double px = i + 0.5, py = j + 0.5, w[3], z, u, v, nrm[3], lam, base[3];
                int cu, cv;
                w[0] = ((sx[1] - px) * (sy[2] - py) - (sx[2] - px) * (sy[1] - py)) / area;
                w[1] = ((sx[2] - px) * (sy[0] - py) - (sx[0] - px) * (sy[2] - py)) / area;
                w[2] = 1 - w[0] - w[1];
                if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
                z = w[0] * sz[0] + w[1] * sz[1] + w[2] * sz[2];
                if (z <= zb[j * n + i]) continue;
                zb[j * n + i] = (float)z;
                u = w[0] * uv[0][0] + w[1] * uv[1][0] + w[2] * uv[2][0];
                v = w[0] * uv[0][1] + w[1] * uv[1][1] + w[2] * uv[2][1];
                for (k = 0; k < 3; k++) nrm[k] = w[0] * nn[0][k] + w[1] * nn[1][k] + w[2] * nn[2][k];
                bpd__normalize(nrm);
                if (!front) for (k = 0; k < 3; k++) nrm[k] = -nrm[k];
                lam = bpd__dot(nrm, light);
                if (lam < 0) lam = 0;
                cu = (int)floor(u / S->period); cv = (int)floor(v / S->period);
                if (!front) { base[0] = 0.45; base[1] = 0.55; base[2] = 0.75; }
                else if ((cu + cv) & 1) { base[0] = 0.92; base[1] = 0.42; base[2] = 0.12; }
                else { base[0] = 0.97; base[1] = 0.95; base[2] = 0.90; }
                for (k = 0; k < 3; k++) col[3 * (j * n + i) + k] = (float)(base[k] * (0.25 + 0.75 * lam));
            }
    }
    for (j = 0; j < size; j++)
        for (i = 0; i < size; i++)
            for (k = 0; k < 3; k++) {
                double s = 0;
                int a, b;
                for (a = 0; a < ss; a++)
                    for (b = 0; b < ss; b++) s += col[3 * ((j * ss + a) * n + i * ss + b) + k];
                s = s / (ss * ss);
                img[3 * ((size_t)j * stride + x0 + i) + k] = (unsigned char)(s >= 1 ? 255 : s * 255 + 0.5);
            }
    free(zb); free(col);
    return 1;
}

int bpd_write_checker_png(const char *path, const bp_mesh *mesh, const bp_atlas *atlas,
                          const bpd_render_options *opt)
{
    bpd_render_options o;
    bpd__scene S;
    double lo[3] = { HUGE_VAL, HUGE_VAL, HUGE_VAL }, hi[3] = { -HUGE_VAL, -HUGE_VAL, -HUGE_VAL };
    double ulo[2] = { HUGE_VAL, HUGE_VAL }, uhi[2] = { -HUGE_VAL, -HUGE_VAL }, ext;
    unsigned char *img;
    uint32_t i, c, t;
    int k, v, ok = 1;
    memset(&o, 0, sizeof o);
    if (opt) o = *opt;
    if (o.size <= 0) o.size = 512;
    if (o.views <= 0) o.views = 1;
    if (o.checker <= 0) o.checker = 16;
    if (o.view[0] == 0 && o.view[1] == 0 && o.view[2] == 0) { o.view[0] = 1; o.view[1] = 0.6; o.view[2] = 1.2; }
    if (o.up[0] == 0 && o.up[1] == 0 && o.up[2] == 0) o.up[1] = 1;
    bpd__normalize(o.up);
    if (!mesh || !atlas || atlas->num_corners != 3 * mesh->num_triangles) { errno = EINVAL; return 0; }
    memset(&S, 0, sizeof S);
    S.m = mesh;
    S.atlas = atlas;
    for (i = 0; i < mesh->num_vertices; i++)
        for (k = 0; k < 3; k++) {
            if (mesh->positions[3 * i + k] < lo[k]) lo[k] = mesh->positions[3 * i + k];
            if (mesh->positions[3 * i + k] > hi[k]) hi[k] = mesh->positions[3 * i + k];
        }
    for (k = 0; k < 3; k++) S.center[k] = 0.5 * (lo[k] + hi[k]);
    for (i = 0; i < mesh->num_vertices; i++) {
        double q[3];
        for (k = 0; k < 3; k++) q[k] = mesh->positions[3 * i + k] - S.center[k];
        if (sqrt(bpd__dot(q, q)) > S.radius) S.radius = sqrt(bpd__dot(q, q));
    }
    if (!(S.radius > 0)) S.radius = 1;
    for (c = 0; c < atlas->num_charts; c++)
        if (atlas->charts[c].uv) bpd__bbox(atlas->charts[c].uv, atlas->charts[c].num_vertices, ulo, uhi);
    ext = fmax(uhi[0] - ulo[0], uhi[1] - ulo[1]);
    S.period = ext > 0 ? ext / o.checker : 1;
    S.normal = (double *)calloc(3 * (size_t)mesh->num_vertices + 1, sizeof(double));
    img = (unsigned char *)malloc(3 * (size_t)o.size * o.size * o.views);
    if (!S.normal || !img) { free(S.normal); free(img); errno = ENOMEM; return 0; }
    for (t = 0; t < mesh->num_triangles; t++) {      /* area-weighted vertex normals */
        const uint32_t *tr = mesh->triangles + 3 * (size_t)t;
        double e1[3], e2[3], fn[3];
        for (k = 0; k < 3; k++) {
            e1[k] = mesh->positions[3 * tr[1] + k] - mesh->positions[3 * tr[0] + k];
            e2[k] = mesh->positions[3 * tr[2] + k] - mesh->positions[3 * tr[0] + k];
        }
        bpd__cross(e1, e2, fn);
        for (k = 0; k < 3; k++) {
            S.normal[3 * tr[0] + k] += fn[k]; S.normal[3 * tr[1] + k] += fn[k]; S.normal[3 * tr[2] + k] += fn[k];
        }
    }
    for (i = 0; i < mesh->num_vertices; i++) bpd__normalize(S.normal + 3 * (size_t)i);
    for (v = 0; v < o.views && ok; v++) {
        /* turn the view about the up axis by 360 v / views degrees (Rodrigues) */
        double a = 6.283185307179586 * v / o.views, ca = cos(a), sa = sin(a), kv[3], dir[3];
        double kd = bpd__dot(o.up, o.view);
        bpd__cross(o.up, o.view, kv);
        for (k = 0; k < 3; k++) dir[k] = o.view[k] * ca + kv[k] * sa + o.up[k] * kd * (1 - ca);
        ok = bpd__render_view(&S, dir, o.up, o.size, img, o.size * o.views, o.size * v);
    }
    if (ok) ok = bpd_write_png(path, o.size * o.views, o.size, img);
    free(S.normal);
    free(img);
    return ok;
}

#endif /* BPD_IMPLEMENTATION */
