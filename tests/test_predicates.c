/* test_predicates.c - exactness of bp_orient2d and bp_segments_intersect.

   Everything the library proves about a map (no flipped triangle, no
   boundary crossing) rests on these two predicates, so they are checked
   against a reference that shares no code with the library: an exact
   evaluator that expands the orientation determinant into six products of
   doubles and adds them in a wide fixed-point integer (every finite double
   product fits, so the sign it reports is the true one).

     (a) the classic near-collinear grid of Kettner et al., where the naive
         double formula is provably wrong somewhere;
     (b) random integer points scaled by powers of two, against the wide
         reference and (when the coordinates are small) against plain int64;
     (c) the permutation identities of the determinant on near-degenerate
         random inputs;
     (d) segment intersection on hand-made cases (crossing, endpoint touch,
         T-junction, collinear overlap and gap, parallel, one-ulp misses) and
         on random grid segments, against a reference built from exact signs
         and exact coordinate comparisons. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <math.h>
#include <string.h>

/* ---- the independent exact reference ------------------------------------ */

/* A double is m * 2^e with an integer |m| < 2^53 (frexp gives the split).  A
   product of two doubles is then m1 m2 * 2^(e1+e2) with e1+e2 >= -2 * 1127,
   and |m1 m2| < 2^106, so all of them fit in a fixed-point number with the
   binary point WIDE_BASE bits above its lowest bit and WIDE_LIMBS 32-bit
   limbs (2^-2272 .. 2^2208, far more than a double product can reach). */
enum { WIDE_LIMBS = 140 };
#define WIDE_BASE 2272

typedef struct wide { uint32_t limb[WIDE_LIMBS]; } wide;

static void split_double(double x, uint64_t *m, int *e, int *neg)
{
    int ex;
    double f = frexp(fabs(x), &ex); /* |x| = f 2^ex, f in [0.5, 1) */
    *neg = x < 0;
    *m = (uint64_t)ldexp(f, 53);   /* exact: f has at most 53 bits */
    *e = ex - 53;
}

/* acc += v * 2^bit, bit >= 0 */
static void wide_add(wide *acc, uint64_t v, int bit)
{
    int k = bit / 32, s = bit % 32;
    uint64_t lo = (v & 0xffffffffu) << s;       /* < 2^63 */
    uint64_t hi = (v >> 32) << s;               /* < 2^63 */
    uint64_t carry = 0;
    int i;
    /* add lo at limb k and hi at limb k+1, then ripple the carry */
    carry = (uint64_t)acc->limb[k] + (lo & 0xffffffffu);
    acc->limb[k] = (uint32_t)carry;
    carry = (carry >> 32) + (lo >> 32) + (hi & 0xffffffffu) + acc->limb[k + 1];
    acc->limb[k + 1] = (uint32_t)carry;
    carry = (carry >> 32) + (hi >> 32);
    for (i = k + 2; carry && i < WIDE_LIMBS; i++) {
        carry += acc->limb[i];
        acc->limb[i] = (uint32_t)carry;
        carry >>= 32;
    }
}

/* pos or neg += sign * x * y, exactly */
static void wide_add_product(wide *pos, wide *neg, int sign, double x, double y)
{
    uint64_t mx, my, xh, xl, yh, yl;
    int ex, ey, nx, ny, base;
    wide *acc;
    if (x == 0.0 || y == 0.0) return;
    split_double(x, &mx, &ex, &nx);
    split_double(y, &my, &ey, &ny);
    if (nx) sign = -sign;
    if (ny) sign = -sign;
    acc = sign > 0 ? pos : neg;
    base = ex + ey + WIDE_BASE;
    xh = mx >> 32; xl = mx & 0xffffffffu;
    yh = my >> 32; yl = my & 0xffffffffu;
    wide_add(acc, xl * yl, base);
    wide_add(acc, xh * yl, base + 32);
    wide_add(acc, xl * yh, base + 32);
    wide_add(acc, xh * yh, base + 64);
}

static int wide_compare(const wide *a, const wide *b)
{
    int i;
    for (i = WIDE_LIMBS - 1; i >= 0; i--)
        if (a->limb[i] != b->limb[i]) return a->limb[i] > b->limb[i] ? 1 : -1;
    return 0;
}

/* (bx-ax)(cy-ay) - (by-ay)(cx-ax) expanded into products of the inputs:
   bx cy - bx ay - ax cy - by cx + by ax + ay cx. */
static int ref_orient(const double a[2], const double b[2], const double c[2])
{
    wide pos, neg;
    memset(&pos, 0, sizeof pos);
    memset(&neg, 0, sizeof neg);
    wide_add_product(&pos, &neg, +1, b[0], c[1]);
    wide_add_product(&pos, &neg, -1, b[0], a[1]);
    wide_add_product(&pos, &neg, -1, a[0], c[1]);
    wide_add_product(&pos, &neg, -1, b[1], c[0]);
    wide_add_product(&pos, &neg, +1, b[1], a[0]);
    wide_add_product(&pos, &neg, +1, a[1], c[0]);
    return wide_compare(&pos, &neg);
}

/* Plain int64 orientation for integer coordinates below 2^26 in magnitude:
   differences < 2^27, products < 2^54, their difference < 2^55. */
static int int_orient(const int64_t a[2], const int64_t b[2], const int64_t c[2])
{
    int64_t d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    return (d > 0) - (d < 0);
}

static int naive_orient(const double a[2], const double b[2], const double c[2])
{
    double d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    return (d > 0) - (d < 0);
}

/* p lies on the closed segment [a, b], given that a, b, p are collinear:
   exact coordinate comparisons only. */
static int ref_on_segment(const double a[2], const double b[2], const double p[2])
{
    return fmin(a[0], b[0]) <= p[0] && p[0] <= fmax(a[0], b[0]) &&
           fmin(a[1], b[1]) <= p[1] && p[1] <= fmax(a[1], b[1]);
}

/* Closed segments share a point: a proper crossing (strictly opposite signs
   on both sides), or an endpoint lying on the other segment (CLRS 33.1). */
static int ref_segments(const double a[2], const double b[2],
                        const double c[2], const double d[2])
{
    int o1 = ref_orient(a, b, c), o2 = ref_orient(a, b, d);
    int o3 = ref_orient(c, d, a), o4 = ref_orient(c, d, b);
    if (o1 * o2 < 0 && o3 * o4 < 0) return 1;
    if (o1 == 0 && ref_on_segment(a, b, c)) return 1;
    if (o2 == 0 && ref_on_segment(a, b, d)) return 1;
    if (o3 == 0 && ref_on_segment(c, d, a)) return 1;
    if (o4 == 0 && ref_on_segment(c, d, b)) return 1;
    return 0;
}

/* The library's answer under all 8 symmetries of the question (swap the
   segments, reverse either): returns the common answer, or -1 if they
   disagree. */
static int lib_segments_all(const double a[2], const double b[2],
                            const double c[2], const double d[2])
{
    int r = !!bp_segments_intersect(a, b, c, d);
    if (!!bp_segments_intersect(b, a, c, d) != r) return -1;
    if (!!bp_segments_intersect(a, b, d, c) != r) return -1;
    if (!!bp_segments_intersect(b, a, d, c) != r) return -1;
    if (!!bp_segments_intersect(c, d, a, b) != r) return -1;
    if (!!bp_segments_intersect(d, c, a, b) != r) return -1;
    if (!!bp_segments_intersect(c, d, b, a) != r) return -1;
    if (!!bp_segments_intersect(d, c, b, a) != r) return -1;
    return r;
}

/* ---- seeded xorshift (no rand()) ---------------------------------------- */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t rng(void)
{
    uint64_t x = rng_state;
    x ^= x << 13; x ^= x >> 7; x ^= x << 17;
    return rng_state = x;
}
static int64_t rng_range(int64_t lo, int64_t hi) /* inclusive */
{
    return lo + (int64_t)(rng() % (uint64_t)(hi - lo + 1));
}

/* ---- (a) the near-collinear grid ---------------------------------------- */

static void test_near_collinear_grid(void)
{
    /* a = (0.5 + i u, 0.5 + j u) with u = 2^-53, the spacing of doubles in
       [0.5, 1), so every a is exact.  Writing ax = 0.5 + dx, ay = 0.5 + dy:
         (bx-ax)(cy-ay) - (by-ay)(cx-ax)
           = (11.5-dx)(23.5-dy) - (11.5-dy)(23.5-dx)
           = -11.5 dy - 23.5 dx + 11.5 dx + 23.5 dy   (the dx dy cancel)
           = 12 (dy - dx) = 12 (ay - ax),
       so the exact sign is sign(j - i): +1 above the diagonal, 0 on it. */
    const double u = ldexp(1.0, -53), b[2] = { 12, 12 }, c[2] = { 24, 24 };
    int i, j, wrong_lib = 0, wrong_naive = 0, wrong_ref = 0, first_i = -1, first_j = -1;
    for (i = 0; i < 256; i++)
        for (j = 0; j < 256; j++) {
            double a[2];
            int exact = (j > i) - (j < i);
            a[0] = 0.5 + i * u;
            a[1] = 0.5 + j * u;
            if (bp_orient2d(a, b, c) != exact) {
                if (!wrong_lib) { first_i = i; first_j = j; }
                wrong_lib++;
            }
            if (naive_orient(a, b, c) != exact) wrong_naive++;
            if (ref_orient(a, b, c) != exact) wrong_ref++;
        }
    BPT_CHECK(wrong_ref == 0, "reference evaluator agrees with sign(ay-ax) on the 256x256 grid (%d wrong)", wrong_ref);
    BPT_CHECK(wrong_lib == 0, "bp_orient2d exact on all 65536 near-collinear points (%d wrong, first i=%d j=%d)",
              wrong_lib, first_i, first_j);
    BPT_CHECK(wrong_naive > 0, "the naive double formula is wrong on %d of 65536 (so the grid really tests exactness)",
              wrong_naive);
    {
        /* the values, not just the signs, are -1, 0, +1 */
        double a0[2] = { 0.5, 0.5 }, a1[2], a2[2];
        a1[0] = 0.5; a1[1] = 0.5 + u;
        a2[0] = 0.5 + u; a2[1] = 0.5;
        BPT_CHECK(bp_orient2d(a0, b, c) == 0 && bp_orient2d(a1, b, c) == 1 &&
                  bp_orient2d(a2, b, c) == -1, "bp_orient2d returns exactly 0, +1, -1");
    }
}

/* ---- (b) random points against exact integers ---------------------------- */

static void test_random_integer_points(void)
{
    int n, bad_int = 0, bad_ref = 0, bad_ref_int = 0, zeros = 0, naive_wrong = 0;
    for (n = 0; n < 200000; n++) {
        int64_t p[3][2];
        double a[2], b[2], c[2];
        int k, e = (int)rng_range(-60, 60), bits = (int)rng_range(2, 26);
        int64_t lim = ((int64_t)1 << bits) - 1;
        if (n % 2 == 0) {
            /* near-collinear: p0 + m d, p0 + m' d, and a nudge of -1..1 */
            int64_t dl = lim / 4 > 0 ? lim / 4 : 1, dx, dy, m1, m2;
            p[0][0] = rng_range(-lim / 2, lim / 2);
            p[0][1] = rng_range(-lim / 2, lim / 2);
            dx = rng_range(-dl, dl);
            dy = rng_range(-dl, dl);
            m1 = rng_range(-2, 2);
            m2 = rng_range(-2, 2);
            p[1][0] = p[0][0] + m1 * dx; p[1][1] = p[0][1] + m1 * dy;
            p[2][0] = p[0][0] + m2 * dx + rng_range(-1, 1);
            p[2][1] = p[0][1] + m2 * dy + rng_range(-1, 1);
        } else {
            for (k = 0; k < 3; k++) {
                p[k][0] = rng_range(-lim, lim);
                p[k][1] = rng_range(-lim, lim);
            }
        }
        a[0] = ldexp((double)p[0][0], e); a[1] = ldexp((double)p[0][1], e);
        b[0] = ldexp((double)p[1][0], e); b[1] = ldexp((double)p[1][1], e);
        c[0] = ldexp((double)p[2][0], e); c[1] = ldexp((double)p[2][1], e);
        {
            int exact = int_orient(p[0], p[1], p[2]); /* scaling by 2^e keeps the sign */
            int got = bp_orient2d(a, b, c), ref = ref_orient(a, b, c);
            if (got != exact) bad_int++;
            if (got != ref) bad_ref++;
            if (ref != exact) bad_ref_int++;
            if (naive_orient(a, b, c) != exact) naive_wrong++;
            if (exact == 0) zeros++;
        }
    }
    BPT_CHECK(bad_ref_int == 0, "wide reference == int64 determinant on 200000 scaled integer triples (%d differ)", bad_ref_int);
    BPT_CHECK(bad_int == 0, "bp_orient2d == int64 determinant on 200000 scaled integer triples (%d wrong; %d collinear, naive wrong %d)",
              bad_int, zeros, naive_wrong);
    BPT_CHECK(bad_ref == 0, "bp_orient2d == wide reference on the same triples (%d wrong)", bad_ref);

    /* arbitrary doubles (random mantissas and exponents within +-200, so no
       product can overflow or underflow), made near-collinear by rounding */
    {
        int bad = 0, collinear = 0;
        for (n = 0; n < 100000; n++) {
            double a[2], b[2], c[2], t;
            int k;
            a[0] = ldexp((double)(int64_t)(rng() >> 11) - 4503599627370496.0, (int)rng_range(-200, 100));
            a[1] = ldexp((double)(int64_t)(rng() >> 11) - 4503599627370496.0, (int)rng_range(-200, 100));
            b[0] = ldexp((double)(int64_t)(rng() >> 11) - 4503599627370496.0, (int)rng_range(-200, 100));
            b[1] = ldexp((double)(int64_t)(rng() >> 11) - 4503599627370496.0, (int)rng_range(-200, 100));
            t = ldexp((double)(rng() >> 11), -53) * 3.0 - 1.0;
            c[0] = a[0] + t * (b[0] - a[0]);
            c[1] = a[1] + t * (b[1] - a[1]);
            for (k = 0; k < 2; k++) { /* nudge by a few ulps, sometimes */
                int steps = (int)rng_range(-2, 2);
                while (steps > 0) { c[k] = nextafter(c[k], INFINITY); steps--; }
                while (steps < 0) { c[k] = nextafter(c[k], -INFINITY); steps++; }
            }
            {
                int ref = ref_orient(a, b, c);
                if (bp_orient2d(a, b, c) != ref) bad++;
                if (ref == 0) collinear++;
            }
        }
        BPT_CHECK(bad == 0, "bp_orient2d == wide reference on 100000 near-collinear arbitrary doubles (%d wrong, %d exactly collinear)",
                  bad, collinear);
    }
}

/* ---- (c) permutation identities ----------------------------------------- */

static void test_permutations(void)
{
    int n, bad = 0, nonzero = 0;
    for (n = 0; n < 100000; n++) {
        double a[2], b[2], c[2], t;
        int o[6];
        a[0] = ldexp((double)(rng() >> 11), -52) - 1.0;
        a[1] = ldexp((double)(rng() >> 11), -52) - 1.0;
        b[0] = ldexp((double)(rng() >> 11), -52) * 64.0;
        b[1] = ldexp((double)(rng() >> 11), -52) * 64.0;
        t = ldexp((double)(rng() >> 11), -53) * 4.0 - 2.0;
        c[0] = a[0] + t * (b[0] - a[0]);
        c[1] = a[1] + t * (b[1] - a[1]);
        if (n % 3 == 0) c[n % 2] = nextafter(c[n % 2], (n % 4) ? 10.0 : -10.0);
        o[0] = bp_orient2d(a, b, c);
        o[1] = bp_orient2d(b, c, a);
        o[2] = bp_orient2d(c, a, b);
        o[3] = -bp_orient2d(b, a, c);
        o[4] = -bp_orient2d(a, c, b);
        o[5] = -bp_orient2d(c, b, a);
        if (o[0] != o[1] || o[0] != o[2] || o[0] != o[3] || o[0] != o[4] || o[0] != o[5])
            bad++;
        if (o[0]) nonzero++;
    }
    BPT_CHECK(bad == 0, "orient(a,b,c) == orient(b,c,a) == orient(c,a,b) == -orient(b,a,c) == ... on 100000 near-degenerate triples (%d broken, %d nonzero)",
              bad, nonzero);
    {
        double a[2] = { 1.5, -2.25 }, b[2] = { 1.5, -2.25 }, c[2] = { 7, 3 };
        BPT_CHECK(bp_orient2d(a, b, c) == 0 && bp_orient2d(a, a, a) == 0,
                  "repeated points are collinear (orient == 0)");
    }
}

/* ---- (d) segment intersection ------------------------------------------- */

static void seg_case(const char *what, double ax, double ay, double bx, double by,
                     double cx, double cy, double dx, double dy, int expected)
{
    double a[2], b[2], c[2], d[2];
    int lib, ref;
    a[0] = ax; a[1] = ay; b[0] = bx; b[1] = by;
    c[0] = cx; c[1] = cy; d[0] = dx; d[1] = dy;
    lib = lib_segments_all(a, b, c, d);
    ref = ref_segments(a, b, c, d);
    BPT_CHECK(ref == expected, "reference: %s -> %d (expected %d)", what, ref, expected);
    BPT_CHECK(lib == expected, "bp_segments_intersect: %s -> %d under all 8 symmetries (expected %d; -1 = symmetries disagree)",
              what, lib, expected);
}

static void test_segments(void)
{
    const double up = nextafter(0.5, 1.0), down = nextafter(0.5, 0.0);
    const double one_up = nextafter(1.0, 2.0);

    seg_case("X crossing", 0, 0, 2, 2, 0, 2, 2, 0, 1);
    seg_case("shared endpoint (V)", 0, 0, 1, 1, 1, 1, 2, 0, 1);
    seg_case("T-junction: endpoint inside the other", 0, 0, 2, 0, 1, 0, 1, 5, 1);
    seg_case("T-junction on a diagonal", 0, 0, 1, 1, 0.5, 0.5, 0.5, -1, 1);
    seg_case("collinear overlapping", 0, 0, 2, 0, 1, 0, 3, 0, 1);
    seg_case("collinear, one inside the other", 0, 0, 4, 4, 1, 1, 2, 2, 1);
    seg_case("collinear touching at one endpoint", 0, 0, 1, 0, 1, 0, 2, 0, 1);
    seg_case("collinear disjoint", 0, 0, 1, 0, 2, 0, 3, 0, 0);
    seg_case("collinear disjoint on a diagonal", 0, 0, 1, 1, 2, 2, 3, 3, 0);
    seg_case("parallel", 0, 0, 2, 0, 0, 1, 2, 1, 0);
    seg_case("parallel diagonal", 0, 0, 2, 2, 1, 0, 3, 2, 0);
    seg_case("lines cross outside both segments", 0, 0, 1, 1, 3, 0, 2, 1, 0);
    seg_case("T stops one ulp short of the diagonal", 0, 0, 1, 1, 0.5, down, 0.5, -1, 0);
    seg_case("T reaches one ulp past the diagonal", 0, 0, 1, 1, 0.5, up, 0.5, -1, 1);
    seg_case("collinear gap of one ulp", 0, 0, 1, 0, one_up, 0, 2, 0, 0);
    seg_case("collinear overlap of one ulp", 0, 0, one_up, 0, 1, 0, 2, 0, 1);
    seg_case("point-segment on the segment", 0, 0, 2, 2, 1, 1, 1, 1, 1);
    seg_case("point-segment one ulp off", 0, 0, 2, 2, 1, one_up, 1, one_up, 0);
    seg_case("two equal points", 3, 4, 3, 4, 3, 4, 3, 4, 1);
    seg_case("two different points", 3, 4, 3, 4, 3, nextafter(4.0, 5.0), 3, nextafter(4.0, 5.0), 0);

    /* An endpoint near a line with an irrational-looking slope: the point
       0.1 * (3, 1) is not representable, so the reference decides which
       side each rounding lies on; the library must agree. */
    {
        double a[2] = { 0, 0 }, b[2] = { 3, 1 }, c[2], d[2] = { 0.1, -5 };
        int k, disagree = 0, hits = 0;
        for (k = -3; k <= 3; k++) {
            int s;
            c[0] = 0.1;
            c[1] = 0.1 / 3.0;
            for (s = 0; s < (k < 0 ? -k : k); s++) c[1] = nextafter(c[1], k < 0 ? -1.0 : 1.0);
            d[0] = c[0];
            if (lib_segments_all(a, b, c, d) != ref_segments(a, b, c, d)) disagree++;
            hits += ref_segments(a, b, c, d);
        }
        BPT_CHECK(disagree == 0 && hits > 0 && hits < 7,
                  "near-touch with a non-representable contact point: library == reference for 7 ulp offsets (%d disagree, %d hit)",
                  disagree, hits);
    }

    /* random segments on a small grid (lots of collinear, touching and
       overlapping cases), scaled and shifted by exact amounts, and with the
       occasional one-ulp nudge */
    {
        int n, bad = 0, yes = 0, asym = 0;
        for (n = 0; n < 200000; n++) {
            double p[4][2], scale = ldexp(1.0, (int)rng_range(-30, 30));
            double shift = (double)rng_range(-8, 8) * 0.5;
            int k, lib, ref;
            for (k = 0; k < 4; k++) {
                p[k][0] = (double)rng_range(0, 4) * scale + shift;
                p[k][1] = (double)rng_range(0, 4) * scale;
            }
            if (n % 4 == 0) {
                /* a one-ulp nudge, but never of a zero: the next double
                   after 0 is subnormal, and products of subnormals
                   underflow, outside what bp_orient2d promises */
                k = (int)rng_range(0, 3);
                if (p[k][n % 8 == 0] != 0.0)
                    p[k][n % 8 == 0] = nextafter(p[k][n % 8 == 0], (n % 16) ? 100.0 : -100.0);
            }
            lib = lib_segments_all(p[0], p[1], p[2], p[3]);
            ref = ref_segments(p[0], p[1], p[2], p[3]);
            if (lib < 0) asym++;
            else if (lib != ref) bad++;
            yes += ref;
        }
        BPT_CHECK(bad == 0 && asym == 0,
                  "bp_segments_intersect == reference on 200000 random grid segment pairs (%d wrong, %d asymmetric, %d intersect)",
                  bad, asym, yes);
    }
}

int main(void)
{
    test_near_collinear_grid();
    test_random_integer_points();
    test_permutations();
    test_segments();
    return bpt_finish();
}
