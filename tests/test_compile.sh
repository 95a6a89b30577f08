#!/usr/bin/env bash
# test_compile.sh - bijparam.h builds everywhere it promises to, and its
# build options do what the header says.
#
#   - warning-free (-Wall -Wextra -pedantic -Werror) as C99 with gcc, and
#     with clang when it is installed (a missing clang is reported, not
#     counted), at -O0 and -O2;
#   - as C++11 and C++17 with g++ (and clang++ when installed);
#   - with -DBP_NO_STDIO: compiles, and <stdio.h> is never included;
#   - with -DBP_NO_SIMD: <immintrin.h> is never included (on x86-64 gcc it
#     is without), and camel_b by Newton writes the same bytes both ways;
#   - with -DBP_STATIC in two translation units linked into one program;
#   - with BP_MALLOC/BP_FREE overridden (both): the overrides receive every
#     allocation and the allocator's user pointer; defining only one of the
#     pair is an #error;
#   - a counting allocator through a whole run on tests/data/bishop_part_f1000.obj
#     (read, build, init, optimize, pack, check, write, free): every call
#     gets the user pointer, allocations == frees, bytes balance; once
#     serial and once with -DBP_USE_PTHREADS and 4 threads on spot.obj
#     (which must also compile warning-free as C and C++).
#
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
# Run from anywhere; CC/CXX/CLANG/CLANGXX pick the compilers, EXTRA_CFLAGS
# adds flags to the gcc/g++ compiles.
set -u

ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
CXX=${CXX:-g++}
CLANG=${CLANG:-clang}
CLANGXX=${CLANGXX:-clang++}
# EXTRA_CFLAGS is appended to the warning flags of every gcc/g++ compile
# (for example -Wno-error=... to look past one known warning while
# debugging); the clang checks always use the plain flags.
CLANG_WARN="-Wall -Wextra -pedantic -Werror"
WARN="$CLANG_WARN${EXTRA_CFLAGS:+ $EXTRA_CFLAGS}"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_compile.XXXXXX")
trap 'rm -rf "$TMP"' EXIT

passed=0
failed=0
ok()   { echo "ok   test_compile.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_compile.sh: $*"; failed=$((failed + 1)); }

# check "what" command...: ok when the command succeeds; on failure the
# compiler output is shown, indented.
check() {
    local what=$1; shift
    if "$@" >"$TMP/log" 2>&1; then ok "$what"
    else fail "$what"; sed 's/^/     | /' "$TMP/log" | head -n 30; fi
}
# check_fails "what" command...: ok when the command fails.
check_fails() {
    local what=$1; shift
    if "$@" >"$TMP/log" 2>&1; then fail "$what (it compiled)"
    else ok "$what"; fi
}

# ---- one translation unit that uses the whole API ------------------------
cat >"$TMP/all.c" <<'EOF'
#define BP_IMPLEMENTATION
#include "bijparam.h"

int main(void)
{
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const double a[2] = { 0, 0 }, b[2] = { 1, 0 }, c[2] = { 0, 1 };
    bp_mesh mesh;
    bp_atlas atlas;
    bp_options opt;
    bp_error err;
    bp_status st;
    memset(&opt, 0, sizeof opt);
    opt.max_iterations = 5;
    st = bp_parse_obj(text, sizeof text - 1, &mesh, NULL, &err);
    if (st != BP_OK) return 1;
    st = bp_parameterize(&atlas, &mesh, &opt, &err);
    if (st == BP_OK) bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    (void)bp_status_string(st);
    (void)bp_energy_name(BP_ENERGY_MIPS);
    (void)bp_stop_string(BP_STOP_CONVERGED);
    return bp_orient2d(a, b, c) == 1 && !bp_segments_intersect(a, b, c, c) ? 0 : 1;
}
EOF
cp "$TMP/all.c" "$TMP/all.cpp"
# a translation unit with the declarations only (no implementation), using
# the zero initializers the documentation recommends: `= {0}` in C is
# warning-free; in C++ `= {}` is the warning-free spelling (`{0}` trips
# -Wmissing-field-initializers there)
cat >"$TMP/decl.c" <<'EOF'
#include "bijparam.h"
int use_declarations(void);
int use_declarations(void) { bp_options opt = {0}; bp_atlas atlas = {0};
                             return (int)opt.init + (int)atlas.num_charts + (int)BP_STATUS_COUNT; }
EOF
sed 's/= {0}/= {}/g' "$TMP/decl.c" >"$TMP/decl.cpp"

for opt in -O0 -O2; do
    check "gcc -std=c99 $opt $WARN: declarations only" $CC -std=c99 $opt $WARN -I"$ROOT" -c "$TMP/decl.c" -o "$TMP/decl.o"
    check "gcc -std=c99 $opt $WARN: implementation, linked" $CC -std=c99 $opt $WARN -I"$ROOT" "$TMP/all.c" -o "$TMP/all_gcc" -lm
done
if [ -x "$TMP/all_gcc" ]; then check "the gcc build runs" "$TMP/all_gcc"; fi

if command -v "$CLANG" >/dev/null 2>&1; then
    for opt in -O0 -O2; do
        check "clang -std=c99 $opt $CLANG_WARN: implementation, linked" $CLANG -std=c99 $opt $CLANG_WARN -I"$ROOT" "$TMP/all.c" -o "$TMP/all_clang" -lm
    done
else
    echo "     (clang not installed: clang checks skipped, not counted)"
fi

for std in c++11 c++17; do
    check "g++ -std=$std $WARN: declarations only" $CXX -std=$std -O2 $WARN -I"$ROOT" -c "$TMP/decl.cpp" -o "$TMP/decl_cpp.o"
    check "g++ -std=$std $WARN: implementation, linked" $CXX -std=$std -O2 $WARN -I"$ROOT" "$TMP/all.cpp" -o "$TMP/all_gxx" -lm
    if command -v "$CLANGXX" >/dev/null 2>&1; then
        check "clang++ -std=$std $CLANG_WARN: implementation, linked" $CLANGXX -std=$std -O2 $CLANG_WARN -I"$ROOT" "$TMP/all.cpp" -o "$TMP/all_clangxx" -lm
    fi
done

# ---- BP_NO_STDIO -----------------------------------------------------------
cat >"$TMP/nostdio.c" <<'EOF'
#define BP_NO_STDIO
#define BP_IMPLEMENTATION
#include "bijparam.h"
int main(void)
{
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    bp_mesh mesh;
    bp_error err;
    if (bp_parse_obj(text, sizeof text - 1, &mesh, NULL, &err) != BP_OK) return 1;
    bp_mesh_free(&mesh, NULL);
    return 0;
}
EOF
check "gcc -std=c99 -DBP_NO_STDIO $WARN: compiles and runs" \
    sh -c "$CC -std=c99 -O2 $WARN -I'$ROOT' '$TMP/nostdio.c' -o '$TMP/nostdio' -lm && '$TMP/nostdio'"
if $CC -std=c99 -O2 -I"$ROOT" -H -fsyntax-only "$TMP/nostdio.c" 2>"$TMP/headers"; then
    if grep -q 'stdio\.h' "$TMP/headers"; then fail "-DBP_NO_STDIO never includes <stdio.h> (it does: $(grep -m1 'stdio\.h' "$TMP/headers"))"
    else ok "-DBP_NO_STDIO never includes <stdio.h>"; fi
else
    fail "-DBP_NO_STDIO header listing (gcc -H) failed"
fi
cat >"$TMP/nostdio_read.c" <<'EOF'
#define BP_NO_STDIO
#define BP_IMPLEMENTATION
#include "bijparam.h"
int main(void) { bp_mesh m; bp_error e; return (int)bp_read_obj("x.obj", &m, NULL, &e); }
EOF
check_fails "-DBP_NO_STDIO leaves out bp_read_obj (calling it does not compile)" \
    $CC -std=c99 $WARN -I"$ROOT" -c "$TMP/nostdio_read.c" -o "$TMP/nostdio_read.o"

# ---- BP_NO_SIMD ------------------------------------------------------------
# Without it (x86-64, GCC) the AVX kernels are compiled in, <immintrin.h>
# included; with it they are not.  Either way the whole run gives the
# same bytes: camel_b by projected Newton (its factorizations take the
# AVX kernels where the processor has them), the written OBJ compared.
cat >"$TMP/simd.c" <<'EOF'
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include <string.h>
int main(int argc, char **argv)
{
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_options opt;
    (void)argc;
    memset(&opt, 0, sizeof opt);
    opt.direction = BP_DIRECTION_NEWTON;
    opt.threads = 1;
    if (bp_read_obj(argv[1], &mesh, NULL, &err) != BP_OK) return 1;
    if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK) return 1;
    if (bp_write_obj(argv[2], &mesh, &atlas, &err) != BP_OK) return 1;
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, NULL);
    return 0;
}
EOF
if [ "$(uname -m)" = x86_64 ]; then
    if $CC -std=c99 -O2 -I"$ROOT" -H -fsyntax-only "$TMP/simd.c" 2>"$TMP/headers" && grep -q 'immintrin\.h' "$TMP/headers"; then
        ok "gcc on x86-64 compiles the AVX kernels in (<immintrin.h> included)"
    else fail "gcc on x86-64 compiles the AVX kernels in (<immintrin.h> not included)"; fi
fi
if $CC -std=c99 -O2 -DBP_NO_SIMD -I"$ROOT" -H -fsyntax-only "$TMP/simd.c" 2>"$TMP/headers"; then
    if grep -q 'immintrin\.h' "$TMP/headers"; then fail "-DBP_NO_SIMD never includes <immintrin.h> (it does)"
    else ok "-DBP_NO_SIMD never includes <immintrin.h>"; fi
else
    fail "-DBP_NO_SIMD header listing (gcc -H) failed"
fi
check "gcc -std=c99 $WARN, with and without -DBP_NO_SIMD: camel_b by Newton, the same bytes written" \
    sh -c "$CC -std=c99 -O2 $WARN -I'$ROOT' '$TMP/simd.c' -o '$TMP/simd' -lm &&
           $CC -std=c99 -O2 $WARN -DBP_NO_SIMD -I'$ROOT' '$TMP/simd.c' -o '$TMP/nosimd' -lm &&
           '$TMP/simd' '$ROOT/tests/data/camel_b.obj' '$TMP/simd.obj' &&
           '$TMP/nosimd' '$ROOT/tests/data/camel_b.obj' '$TMP/nosimd.obj' &&
           cmp '$TMP/simd.obj' '$TMP/nosimd.obj'"

# ---- BP_STATIC in two translation units --------------------------------------
cat >"$TMP/static_a.c" <<'EOF'
#define BP_STATIC
#define BP_IMPLEMENTATION
#include "bijparam.h"
int orient_from_b(void);
int main(void)
{
    const double a[2] = { 0, 0 }, b[2] = { 1, 0 }, c[2] = { 0, 1 };
    return bp_orient2d(a, b, c) == 1 && orient_from_b() == 1 ? 0 : 1;
}
EOF
cat >"$TMP/static_b.c" <<'EOF'
#define BP_STATIC
#define BP_IMPLEMENTATION
#include "bijparam.h"
#include <string.h>
int orient_from_b(void);
int orient_from_b(void)
{
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    bp_mesh mesh;
    bp_error err;
    if (bp_parse_obj(text, sizeof text - 1, &mesh, NULL, &err) != BP_OK) return 0;
    bp_mesh_free(&mesh, NULL);
    return strcmp(bp_status_string(BP_OK), "ok") == 0;
}
EOF
check "-DBP_STATIC: two translation units with their own copy compile, link and run" \
    sh -c "$CC -std=c99 -O2 $WARN -I'$ROOT' '$TMP/static_a.c' '$TMP/static_b.c' -o '$TMP/static' -lm && '$TMP/static'"
cat >"$TMP/extern_a.c" <<'EOF'
#define BP_IMPLEMENTATION
#include "bijparam.h"
int main(void) { return 0; }
EOF
cp "$TMP/extern_a.c" "$TMP/extern_b.c"
check_fails "without BP_STATIC, two implementations in one program clash at link time (so BP_STATIC matters)" \
    $CC -std=c99 -O0 -I"$ROOT" "$TMP/extern_a.c" "$TMP/extern_b.c" -o "$TMP/extern" -lm

# ---- BP_MALLOC / BP_FREE -----------------------------------------------------
cat >"$TMP/override.c" <<'EOF'
#include <stdlib.h>
#include <string.h>
static long n_malloc, n_free, n_wrong_user;
static int user_token;
static void *my_malloc(size_t size, void *u)
{
    if (u != (void *)&user_token) n_wrong_user++;
    n_malloc++;
    return malloc(size);
}
static void my_free(void *p, void *u)
{
    if (u != (void *)&user_token) n_wrong_user++;
    if (p) n_free++;
    free(p);
}
#define BP_MALLOC(sz, u) my_malloc((sz), (u))
#define BP_FREE(p, u)    my_free((p), (u))
#define BP_IMPLEMENTATION
#include "bijparam.h"
int main(void)
{
    static const char text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
    bp_mesh mesh;
    bp_error err;
    bp_allocator only_user;               /* no functions: BP_MALLOC/BP_FREE get `user` */
    bp_atlas atlas;
    bp_options opt;
    memset(&only_user, 0, sizeof only_user);
    only_user.user = &user_token;
    if (bp_parse_obj(text, sizeof text - 1, &mesh, &only_user, &err) != BP_OK) return 10;
    memset(&opt, 0, sizeof opt);
    opt.allocator = only_user;
    opt.max_iterations = 20;
    if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK) return 11;
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, &only_user);
    if (n_malloc == 0) return 12;           /* the overrides were not used */
    if (n_malloc != n_free) return 13;      /* leak or double free */
    if (n_wrong_user) return 14;            /* the user pointer got lost */
    return 0;
}
EOF
if $CC -std=c99 -O2 $WARN -I"$ROOT" "$TMP/override.c" -o "$TMP/override" -lm >"$TMP/log" 2>&1; then
    ok "BP_MALLOC(sz,u) and BP_FREE(p,u) both overridden: compiles"
    "$TMP/override"; rc=$?
    case $rc in
        0)  ok "the overrides get every allocation and free, each with the user pointer" ;;
        10|11) fail "override program: parse/parameterize failed (exit $rc)" ;;
        12) fail "BP_MALLOC override never called" ;;
        13) fail "BP_MALLOC/BP_FREE calls do not balance" ;;
        14) fail "BP_MALLOC/BP_FREE received a wrong user pointer" ;;
        *)  fail "override program crashed or failed (exit $rc)" ;;
    esac
else
    fail "BP_MALLOC(sz,u) and BP_FREE(p,u) both overridden: compiles"; sed 's/^/     | /' "$TMP/log" | head -n 30
fi
for only in "-DBP_MALLOC(s,u)=malloc(s)" "-DBP_FREE(p,u)=free(p)"; do
    printf '#include <stdlib.h>\n#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { return 0; }\n' >"$TMP/half.c"
    if $CC -std=c99 -I"$ROOT" "$only" -c "$TMP/half.c" -o "$TMP/half.o" >"$TMP/log" 2>&1; then
        fail "defining only $only is an #error (it compiled)"
    elif grep -q '#error\|error: #error\|BP_MALLOC' "$TMP/log"; then
        ok "defining only $only is an #error"
    else
        fail "defining only $only fails, but not with the #error"; sed 's/^/     | /' "$TMP/log" | head -n 10
    fi
done

# ---- the exact predicates refuse arithmetic they cannot trust ------------------
# -ffast-math (reassociation breaks TwoSum, NaN tests vanish) and a nonzero
# FLT_EVAL_METHOD (wider intermediates: i386 x87 gives 2) are #errors that
# say why; the same program compiles without them (so the failure is the
# #error, not something else).
printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { return 0; }\n' >"$TMP/fm.c"
check "plain -std=c99: the fast-math probe compiles" $CC -std=c99 -I"$ROOT" -c "$TMP/fm.c" -o "$TMP/fm.o"
if $CC -std=c99 -ffast-math -I"$ROOT" -c "$TMP/fm.c" -o "$TMP/fm.o" >"$TMP/log" 2>&1; then
    fail "-ffast-math is an #error (it compiled)"
elif grep -q 'fast-math.*exact predicates need strict IEEE' "$TMP/log"; then
    ok "-ffast-math is an #error saying why (the exact predicates need strict IEEE double arithmetic)"
else
    fail "-ffast-math fails, but not with the #error"; sed 's/^/     | /' "$TMP/log" | head -n 10
fi
if $CXX -std=c++11 -ffast-math -I"$ROOT" -x c++ -c "$TMP/fm.c" -o "$TMP/fm.o" >"$TMP/log" 2>&1; then
    fail "g++ -ffast-math is an #error (it compiled)"
elif grep -q 'fast-math' "$TMP/log"; then
    ok "g++ -ffast-math is an #error too"
else
    fail "g++ -ffast-math fails, but not with the #error"; sed 's/^/     | /' "$TMP/log" | head -n 10
fi
# FLT_EVAL_METHOD 2 where the compiler can produce it (-m32 -mfpmath=387 needs
# 32-bit headers); else the same #if is exercised through a forced value.
printf '#include <float.h>\n#undef FLT_EVAL_METHOD\n#define FLT_EVAL_METHOD 2\n#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { return 0; }\n' >"$TMP/fem.c"
if $CC -std=c99 -I"$ROOT" -c "$TMP/fem.c" -o "$TMP/fem.o" >"$TMP/log" 2>&1; then
    fail "FLT_EVAL_METHOD 2 is an #error (it compiled)"
elif grep -q 'FLT_EVAL_METHOD != 0' "$TMP/log"; then
    ok "FLT_EVAL_METHOD 2 is an #error saying why"
else
    fail "FLT_EVAL_METHOD 2 fails, but not with the #error"; sed 's/^/     | /' "$TMP/log" | head -n 10
fi
printf '#include <float.h>\n#undef FLT_EVAL_METHOD\n#define FLT_EVAL_METHOD 2\n#define BP_TRUST_FLT_EVAL_METHOD\n#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { return 0; }\n' >"$TMP/fem2.c"
check "BP_TRUST_FLT_EVAL_METHOD accepts FLT_EVAL_METHOD 2 knowingly" $CC -std=c99 -I"$ROOT" -c "$TMP/fem2.c" -o "$TMP/fem2.o"
if echo 'int main(void){return 0;}' | $CC -m32 -x c - -o "$TMP/m32" >/dev/null 2>&1; then
    if $CC -std=c99 -m32 -mfpmath=387 -I"$ROOT" -c "$TMP/fm.c" -o "$TMP/fm32.o" >"$TMP/log" 2>&1; then
        fail "-m32 -mfpmath=387 (x87, FLT_EVAL_METHOD 2) is an #error (it compiled)"
    elif grep -q 'FLT_EVAL_METHOD' "$TMP/log"; then ok "-m32 -mfpmath=387 is an #error (FLT_EVAL_METHOD)"
    else fail "-m32 -mfpmath=387 fails, but not with the #error"; sed 's/^/     | /' "$TMP/log" | head -n 10; fi
else
    echo "note test_compile.sh: no 32-bit toolchain: the x87 case is covered only by the forced FLT_EVAL_METHOD above"
fi

# ---- a counting allocator through a whole run ---------------------------------
cat >"$TMP/counting.c" <<'EOF'
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

/* With BP_USE_PTHREADS the library may allocate from worker threads, so the
   counter is then behind a mutex. */
#ifdef BP_USE_PTHREADS
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
#define LOCK() pthread_mutex_lock(&lock)
#define UNLOCK() pthread_mutex_unlock(&lock)
#else
#define LOCK() ((void)0)
#define UNLOCK() ((void)0)
#endif

typedef struct counter { long allocs, frees, wrong_user, bad_free; long long live; } counter;
static counter the_counter;

static void *count_alloc(void *user, size_t size)
{
    size_t *p;
    LOCK();
    if (user != (void *)&the_counter) { the_counter.wrong_user++; UNLOCK(); return NULL; }
    p = (size_t *)malloc(size + 16);
    if (p) {
        p[0] = size; p[1] = 0xa110c;
        the_counter.allocs++;
        the_counter.live += (long long)size;
    }
    UNLOCK();
    return p ? (char *)p + 16 : NULL;
}
static void count_free(void *user, void *ptr)
{
    size_t *p;
    if (!ptr) return;
    LOCK();
    if (user != (void *)&the_counter) { the_counter.wrong_user++; UNLOCK(); return; }
    p = (size_t *)((char *)ptr - 16);
    if (p[1] != 0xa110c) { the_counter.bad_free++; UNLOCK(); return; }
    p[1] = 0;
    the_counter.frees++;
    the_counter.live -= (long long)p[0];
    UNLOCK();
    free(p);
}

int main(int argc, char **argv)
{
    bp_allocator a;
    bp_options opt;
    bp_mesh mesh;
    bp_atlas atlas;
    bp_error err;
    bp_status st;
    uint32_t c;
    if (argc < 3) return 2;
    a.alloc = count_alloc; a.free = count_free; a.user = &the_counter;
    memset(&opt, 0, sizeof opt);
    opt.allocator = a;
    opt.max_iterations = 50;
#ifdef BP_USE_PTHREADS
    opt.threads = 4;
#endif

    st = bp_read_obj(argv[1], &mesh, &a, &err);
    if (st != BP_OK) { printf("read: %s\n", err.message); return 1; }
    st = bp_atlas_build(&atlas, &mesh, &opt, &err);
    if (st != BP_OK) { printf("build: %s\n", err.message); return 1; }
    for (c = 0; c < atlas.num_charts && st == BP_OK; c++) {
        bp_check_report rep;
        double mean, max;
        st = bp_chart_init(&atlas.charts[c], &mesh, &opt, &err);
        if (st == BP_OK) st = bp_chart_optimize(&atlas.charts[c], c, &mesh, &opt, &err);
        if (st == BP_OK) st = bp_check(atlas.charts[c].triangles, atlas.charts[c].num_triangles,
                                       atlas.charts[c].uv, atlas.charts[c].num_vertices, &a, &rep, &err);
        if (st == BP_OK) st = bp_chart_distortion(&atlas.charts[c], &mesh, BP_ENERGY_SYMMETRIC_DIRICHLET,
                                                  &mean, &max, NULL, &err);
    }
    if (st != BP_OK) { printf("init/optimize/check: %s\n", err.message); return 1; }
    st = bp_atlas_pack(&atlas, &opt, &err);
    if (st == BP_OK) st = bp_write_obj(argv[2], &mesh, &atlas, &err);
    if (st != BP_OK) { printf("pack/write: %s\n", err.message); return 1; }
    bp_atlas_free(&atlas);
    /* and once more through the one-call driver */
    st = bp_parameterize(&atlas, &mesh, &opt, &err);
    if (st != BP_OK) { printf("parameterize: %s\n", err.message); return 1; }
    bp_atlas_free(&atlas);
    bp_mesh_free(&mesh, &a);

    printf("allocs %ld frees %ld live %lld wrong_user %ld bad_free %ld\n", the_counter.allocs,
           the_counter.frees, the_counter.live, the_counter.wrong_user, the_counter.bad_free);
    if (the_counter.wrong_user) return 3;
    if (the_counter.bad_free) return 4;
    if (the_counter.allocs != the_counter.frees || the_counter.live != 0) return 5;
    return 0;
}
EOF
# run_counting "label" mesh extra-flags...: build counting.c with the flags,
# run it on tests/data/<mesh>
run_counting() {
    local label=$1 mesh=$2 DATA="$ROOT/tests/data/$2"; shift 2
    if $CC -std=c99 -O2 $WARN "$@" -I"$ROOT" "$TMP/counting.c" -o "$TMP/counting" -lm >"$TMP/log" 2>&1; then
        rm -f "$TMP/out.obj"
        "$TMP/counting" "$DATA" "$TMP/out.obj" >"$TMP/run" 2>&1; rc=$?
        summary=$(tail -n 1 "$TMP/run")
        case $rc in
            0) ok "counting allocator$label, $mesh: every call has the user pointer, allocations == frees, bytes balance ($summary)" ;;
            1) fail "counting allocator$label: a step failed: $summary" ;;
            3) fail "counting allocator$label: a call got a wrong user pointer ($summary)" ;;
            4) fail "counting allocator$label: free of a pointer it did not allocate ($summary)" ;;
            5) fail "counting allocator$label: leak ($summary)" ;;
            *) fail "counting allocator$label run crashed (exit $rc): $summary" ;;
        esac
        if [ -s "$TMP/out.obj" ] && grep -q '^vt ' "$TMP/out.obj" && grep -q '^f [0-9]*/[0-9]*' "$TMP/out.obj"; then
            ok "bp_write_obj$label wrote vt lines and f v/vt faces"
        else
            fail "bp_write_obj$label output has no vt lines or no f v/vt faces"
        fi
    else
        fail "counting allocator program$label compiles"; sed 's/^/     | /' "$TMP/log" | head -n 30
    fi
}
run_counting "" bishop_part_f1000.obj
# ---- BP_USE_PTHREADS: the built-in pool compiles warning-free (C and C++)
# and the counting run balances with 4 threads on spot (13 charts, solved in
# parallel)
printf '#define BP_USE_PTHREADS\n#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { return 0; }\n' >"$TMP/pthreads.c"
cp "$TMP/pthreads.c" "$TMP/pthreads.cpp"
check "gcc -std=c99 -DBP_USE_PTHREADS -pthread $WARN: compiles and links" \
    $CC -std=c99 -O2 $WARN -pthread -I"$ROOT" "$TMP/pthreads.c" -o "$TMP/pthreads" -lm
check "g++ -std=c++11 -DBP_USE_PTHREADS -pthread $WARN: compiles and links" \
    $CXX -std=c++11 -O2 $WARN -pthread -I"$ROOT" "$TMP/pthreads.cpp" -o "$TMP/pthreads_cpp" -lm
run_counting " (BP_USE_PTHREADS, 4 threads)" spot.obj -DBP_USE_PTHREADS -pthread

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
