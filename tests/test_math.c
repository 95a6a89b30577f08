/* test_math.c - >>math: the library's own log, pow, sin, cos, tan, atan2.

   (a) Accuracy: each function against the C library's long double one
       (logl, powl, sinl, cosl, tanl, atan2l: 64 or 113 bits where long
       double is wider than double) on random arguments over the ranges
       the library uses and wider ones; the largest error in ulps of the
       double result must stay below 0.75 (measured: 0.62).  Where long
       double is double (MSVC), the reference is the double function and
       the bound 1.5 ulps.
   (b) Identities, which need no reference: sin^2 + cos^2 = 1 and
       tan = sin / cos within a few ulps, atan2(sin t, cos t) = t, pow(x, 2)
       = x x, pow(x, 0.5) = sqrt x and pow(x, -1) = 1 / x within an ulp,
       pow(2, k) = 2^k and log(2^k) = k log 2 exactly; sin and cos odd and
       even bit for bit; the special values (0, infinities, NaN, signed
       zeros of atan2) as C99's Annex F gives them.
   (d) The exact operations the others stand on: bp__two_prod's error term
       equals the C library's fma(a, b, -a b) (exact by definition; glibc's
       is), and bp__sqrt x is the double nearest the true root: x - r^2,
       computed exactly, is smaller than for either neighbour of r.
   (c) "math hash": a 64-bit hash of the bits of 40,000 results of each
       function, printed for make check, which compares it between the
       native build, the aarch64 one (under qemu) and the Windows one
       (under wine) (tests/test_cross.sh), which run it with --hash: (a)
       needs an accurate reference, and the Windows runtime's sinl is the
       x87 fsin, whose 66-bit pi misses by thousands of ulps near large
       multiples of pi.  The arguments are made here from integers, so they
       are the same everywhere. */
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include "bptest.h"

#include <float.h>
#include <math.h>
#include <string.h>

#if LDBL_MANT_DIG > DBL_MANT_DIG
#define WIDE 1
typedef long double wide;
#define W_LOG logl
#define W_POW powl
#define W_SIN sinl
#define W_COS cosl
#define W_TAN tanl
#define W_ATAN2 atan2l
#else
#define WIDE 0
typedef double wide;
#define W_LOG log
#define W_POW pow
#define W_SIN sin
#define W_COS cos
#define W_TAN tan
#define W_ATAN2 atan2
#endif

/* |got - ref| in ulps of the double nearest ref (subnormal spacing below
   the normal range). */
static double ulps(double got, wide ref)
{
    double r = (double)ref;
    int e;
    if (got == r) return 0;
    if (!(got - got == 0) || !(r - r == 0)) return got == r ? 0 : 1e300;
    frexp(r, &e);
    if (e - 53 < -1074) e = -1074 + 53;
    return (double)((got > ref ? (wide)got - ref : ref - (wide)got) / (wide)ldexp(1.0, e - 53));
}

/* e^x from the integer-built generator, without libm: for log-uniform
   arguments. */
static double log_uniform(double lo_exp2, double hi_exp2)
{
    double t = bpt_rng_range(lo_exp2, hi_exp2), k = floor(t);
    return ldexp(1 + (t - k), (int)k);          /* 2^k (1 + frac): spans the binade evenly */
}

enum { N = 200000 };

typedef struct worst { double u, a, b; } worst;
static void note(worst *w, double u, double a, double b)
{
    if (u > w->u) { w->u = u; w->a = a; w->b = b; }
}

static void accuracy(void)
{
    const double bound = WIDE ? 0.75 : 1.5;
    worst w;
    int i;
#define REPORT(what)                                                                                         \
    BPT_CHECK(w.u < bound, "%s: largest error %.3f ulp (< %.2f) over %d arguments, at (%.17g, %.17g)", what, \
              w.u, bound, N, w.a, w.b)
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = log_uniform(-1070, 1020); note(&w, ulps(bp__log(x), W_LOG((wide)x)), x, 0); }
    REPORT("log, x in [2^-1070, 2^1021)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(0.5, 2); note(&w, ulps(bp__log(x), W_LOG((wide)x)), x, 0); }
    REPORT("log, x in [0.5, 2)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) {
        double x = log_uniform(-33, 33), y = bpt_rng_unit();
        note(&w, ulps(bp__pow(x, y), W_POW((wide)x, (wide)y)), x, y);
    }
    REPORT("pow, x in [2^-33, 2^34), y in [0, 1) (the start's references)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) {
        double x = bpt_rng_range(0.1, 10), y = bpt_rng_range(-60, 60);
        note(&w, ulps(bp__pow(x, y), W_POW((wide)x, (wide)y)), x, y);
    }
    REPORT("pow, x in [0.1, 10), y in [-60, 60)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) {
        double x = log_uniform(-1000, 1000), y = bpt_rng_range(-0.7, 0.7);
        note(&w, ulps(bp__pow(x, y), W_POW((wide)x, (wide)y)), x, y);
    }
    REPORT("pow, x in [2^-1000, 2^1001), y in [-0.7, 0.7) (results down to the subnormals)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(-7, 7); note(&w, ulps(bp__sin(x), W_SIN((wide)x)), x, 0); }
    REPORT("sin, x in [-7, 7)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(-1.6e6, 1.6e6); note(&w, ulps(bp__sin(x), W_SIN((wide)x)), x, 0); }
    REPORT("sin, x in [-1.6e6, 1.6e6)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(-7, 7); note(&w, ulps(bp__cos(x), W_COS((wide)x)), x, 0); }
    REPORT("cos, x in [-7, 7)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(-1.6e6, 1.6e6); note(&w, ulps(bp__cos(x), W_COS((wide)x)), x, 0); }
    REPORT("cos, x in [-1.6e6, 1.6e6)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(0, 1.5707963267948966); note(&w, ulps(bp__tan(x), W_TAN((wide)x)), x, 0); }
    REPORT("tan, x in [0, pi/2) (half angles of triangles)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) { double x = bpt_rng_range(-1e5, 1e5); note(&w, ulps(bp__tan(x), W_TAN((wide)x)), x, 0); }
    REPORT("tan, x in [-1e5, 1e5)");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) {
        double y = bpt_rng_range(-1, 1), x = bpt_rng_range(-1, 1);
        note(&w, ulps(bp__atan2(y, x), W_ATAN2((wide)y, (wide)x)), y, x);
    }
    REPORT("atan2, (y, x) in [-1, 1)^2");
    memset(&w, 0, sizeof w);
    for (i = 0; i < N; i++) {
        double y = log_uniform(-1000, 1000) * (bpt_rng_u64() & 1 ? -1 : 1);
        double x = log_uniform(-1000, 1000) * (bpt_rng_u64() & 1 ? -1 : 1);
        note(&w, ulps(bp__atan2(y, x), W_ATAN2((wide)y, (wide)x)), y, x);
    }
    REPORT("atan2, |y|, |x| in [2^-1000, 2^1001)");
#undef REPORT
}

static void identities(void)
{
    double worst_pyth = 0, worst_tan = 0, worst_atan = 0, worst_sq = 0, worst_sqrt = 0, worst_inv = 0;
    int i, k, odd = 1, exact2 = 1, exactlog = 1;
    for (i = 0; i < N; i++) {
        double t = bpt_rng_range(-3.14, 3.14), s = bp__sin(t), c = bp__cos(t), x = log_uniform(-500, 500), e;
        e = fabs(s * s + c * c - 1) / DBL_EPSILON;
        if (e > worst_pyth) worst_pyth = e;
        if (fabs(c) > 1e-3) {
            e = fabs(bp__tan(t) - s / c) / (fabs(s / c) * DBL_EPSILON);
            if (e > worst_tan) worst_tan = e;
        }
        e = fabs(bp__atan2(s, c) - t) / (fabs(t) * DBL_EPSILON);
        if (e > worst_atan && fabs(t) > 1e-3) worst_atan = e;
        e = fabs(bp__pow(x, 2) - x * x) / (x * x * DBL_EPSILON);
        if (e > worst_sq) worst_sq = e;
        e = fabs(bp__pow(x, 0.5) - sqrt(x)) / (sqrt(x) * DBL_EPSILON);
        if (e > worst_sqrt) worst_sqrt = e;
        e = fabs(bp__pow(x, -1) - 1 / x) / (DBL_EPSILON / x);
        if (e > worst_inv) worst_inv = e;
        if (bp__sin(-t) != -s || bp__cos(-t) != c) odd = 0;
    }
    BPT_CHECK(worst_pyth <= 2, "sin^2 + cos^2 = 1 within %.2f eps", worst_pyth);
    BPT_CHECK(worst_tan <= 3, "tan = sin / cos within %.2f eps", worst_tan);
    BPT_CHECK(worst_atan <= 3, "atan2(sin t, cos t) = t within %.2f eps of t", worst_atan);
    BPT_CHECK(worst_sq <= 1, "pow(x, 2) = x x within %.2f eps", worst_sq);
    BPT_CHECK(worst_sqrt <= 1, "pow(x, 0.5) = sqrt x within %.2f eps", worst_sqrt);
    BPT_CHECK(worst_inv <= 1, "pow(x, -1) = 1 / x within %.2f eps", worst_inv);
    BPT_CHECK(odd, "sin(-t) = -sin t and cos(-t) = cos t bit for bit");
    for (k = -1074; k <= 1023; k++) {
        if (bp__pow(2, k) != ldexp(1, k)) exact2 = 0;
        if (k > -1022 && bp__log(ldexp(1, k)) != (double)(k * (wide)0.693147180559945309417232121458176568L)) exactlog = 0;
    }
    BPT_CHECK(exact2, "pow(2, k) = 2^k exactly for k = -1074 .. 1023");
    BPT_CHECK(!WIDE || exactlog, "log(2^k) = k log 2 correctly rounded for k = -1021 .. 1023");
    BPT_CHECK(bp__log(1) == 0 && bp__log(0) == -HUGE_VAL && bp__log(HUGE_VAL) == HUGE_VAL && bp__log(-1) != bp__log(-1) &&
                  bp__log(NAN) != bp__log(NAN),
              "log: 1 -> 0, 0 -> -inf, inf -> inf, -1 and NaN -> NaN");
    BPT_CHECK(bp__sin(0) == 0 && bp__cos(0) == 1 && bp__tan(0) == 0 && 1 / bp__sin(-0.0) < 0 && bp__sin(HUGE_VAL) != bp__sin(HUGE_VAL) &&
                  bp__cos(NAN) != bp__cos(NAN) && bp__tan(-HUGE_VAL) != bp__tan(-HUGE_VAL),
              "sin, cos, tan: 0 -> 0, 1, 0, sin(-0) = -0, infinities and NaN -> NaN");
    BPT_CHECK(bp__atan2(0.0, 1) == 0 && 1 / bp__atan2(-0.0, 1) < 0 && bp__atan2(0.0, -1) == 3.141592653589793 &&
                  bp__atan2(-0.0, -1) == -3.141592653589793 && bp__atan2(0.0, -0.0) == 3.141592653589793 &&
                  bp__atan2(1, 0) == 1.5707963267948966 && bp__atan2(-1, 0) == -1.5707963267948966 &&
                  bp__atan2(1, 1) == 0.7853981633974483 && bp__atan2(HUGE_VAL, -HUGE_VAL) == 2.356194490192345 &&
                  bp__atan2(1, HUGE_VAL) == 0 && bp__atan2(NAN, 1) != bp__atan2(NAN, 1),
              "atan2: signed zeros, +-pi, +-pi/2, pi/4, 3pi/4 at infinities, NaN as C99 Annex F");
    BPT_CHECK(bp__pow(0.0, 2) == 0 && bp__pow(0.0, -1) == HUGE_VAL && bp__pow(-2, 3) == -8 && bp__pow(-2, 2) == 4 &&
                  bp__pow(-2, 0.5) != bp__pow(-2, 0.5) && bp__pow(NAN, 0) == 1 && bp__pow(1, NAN) == 1 &&
                  bp__pow(2, 1e10) == HUGE_VAL && bp__pow(2, -1e10) == 0 && bp__pow(HUGE_VAL, -1) == 0,
              "pow: zeros, negative bases with integer exponents, NaN, overflow and underflow");
}

/* |x - r^2|, exactly up to the final rounding of the difference. */
static double residual(double x, double r)
{
    double e, p = bp__two_prod(r, r, &e);
    return fabs((x - p) - e);
}

/* (d): two_prod against fma, sqrt against its neighbours. */
static void exact_ops(void)
{
    int i, prod_bad = 0, sqrt_bad = 0;
    for (i = 0; i < N; i++) {
        double a = log_uniform(-60, 60), b = log_uniform(-60, 60), e, p, x, r;
        if (i & 1) a = -a;
        p = bp__two_prod(a, b, &e);
        if (p != a * b || e != fma(a, b, -p)) prod_bad++;
        x = log_uniform(-200, 200);
        r = bp__sqrt(x);
        if (residual(x, r) > residual(x, nextafter(r, 0)) || residual(x, r) > residual(x, nextafter(r, HUGE_VAL)))
            sqrt_bad++;
    }
    BPT_CHECK(prod_bad == 0, "two_prod: a b = p + e exactly (fma's error term) on %d products: %d differ", N, prod_bad);
    BPT_CHECK(sqrt_bad == 0, "sqrt: the nearest double on %d arguments: %d are not", N, sqrt_bad);
    BPT_CHECK(bp__sqrt(0.0) == 0 && bp__sqrt(4.0) == 2 && bp__sqrt(HUGE_VAL) == HUGE_VAL && bp__sqrt(-1.0) != bp__sqrt(-1.0),
              "sqrt: 0, 4, infinity and a negative argument (NaN)");
}

/* 40,000 results of each function on arguments made from integers. */
static void hash(void)
{
    uint64_t h = 1469598103934665603ull;
    int i, f;
    for (i = 0; i < 40000; i++) {
        double a = (i - 20000) / 1024.0, b = (double)((i * 7919) % 40000 - 20000) / 997.0, r[9];
        r[0] = bp__log(ldexp(1 + (i % 1000) / 1000.0, i % 2000 - 1000));
        r[1] = bp__pow(fabs(a) + 0.5, b / 40);
        r[2] = bp__sin(a * 3);
        r[3] = bp__cos(a * 3);
        r[4] = bp__tan(a);
        r[5] = bp__atan2(a, b);
        r[6] = bp__exp2d(a / 30, 0);
        bp__two_prod(a / 3, b / 7, &r[7]);
        r[8] = bp__sqrt(ldexp(1 + (i % 997) / 331.0, i % 200 - 100));
        for (f = 0; f < 9; f++) {
            uint64_t bits;
            memcpy(&bits, &r[f], 8);
            h = (h ^ bits) * 1099511628211ull;
        }
    }
    printf("note math hash %016llx\n", (unsigned long long)h);
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--hash")) {   /* the cross builds: the hash alone */
        hash();
        return 0;
    }
    bpt_rng_state = 0x2545F4914F6CDD1Dull;
    accuracy();
    identities();
    exact_ops();
    hash();
    return bpt_finish();
}
