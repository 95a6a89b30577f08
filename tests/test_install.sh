#!/usr/bin/env bash
# test_install.sh - bijparam can be taken into another project the four ways
# README.md promises, each tried from a clean temporary directory:
#
#   (a) `make install PREFIX=...`: the header, the tool and bijparam.pc land
#       where they should (and under DESTDIR when given, with the .pc still
#       naming PREFIX); a consumer C program outside the repository builds
#       with `pkg-config --cflags --libs bijparam` against the installed
#       header and runs; the installed tool runs; `make uninstall` removes
#       exactly what was installed;
#   (d) the top-level CMake build: configures with -Werror, registers one
#       ctest test per tests/test_*.c (and *.cpp when OpenMesh is found),
#       builds the tool, an example and a subset of the tests, and ctest
#       runs that subset (test_io and test_openmesh: ~1 s
#       together; BP_TEST_INSTALL_FULL=1 builds everything and runs all of
#       ctest: ~5 minutes on the shared 2-core machine); then `cmake --install`;
#   (b) a CMake consumer with find_package(bijparam <version> CONFIG
#       REQUIRED) against that prefix builds and runs (and a request for a
#       version that does not exist is refused); the pkg-config file CMake
#       installed serves the consumer too;
#   (c) CMake consumers that take the source tree with add_subdirectory and
#       with FetchContent (URL of a local tarball: offline) build and run,
#       and building them builds nothing of bijparam's own (tool, tests).
#
# The consumer flattens a wavy 9x9 height field and proves the map
# bijective with the header's exact predicates; it prints the version it was
# compiled against, which must be bijparam.h's BP_VERSION_STRING and what
# pkg-config / find_package report.  cmake and pkg-config are required: when
# one is missing that is a FAIL naming the package to install (Debian:
# cmake, pkgconf), and the parts needing it do not run.
#
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
# Run from anywhere.  Builds and installs go to $TMPDIR; in the repository
# only ctest's runner (cmake/bptest_run.cmake) makes build/tests/ if it is
# missing (ignored by git: test_threads writes its scratch files there).
set -u

ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_install.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
# a clean build: nothing inherited from a calling make (jobserver, overrides)
unset MAKEFLAGS MFLAGS MAKELEVEL CMAKE_PREFIX_PATH PKG_CONFIG_PATH
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2}

passed=0
failed=0
ok()   { echo "ok   test_install.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_install.sh: $*"; failed=$((failed + 1)); }
# check "what" command...: ok when the command succeeds, else FAIL with the
# end of its output, indented.
check() {
    local what=$1; shift
    if "$@" >"$TMP/log" 2>&1; then ok "$what"; return 0; fi
    fail "$what"; tail -n 30 "$TMP/log" | sed 's/^/     | /'; return 1
}
# run_consumer "what" program: runs it; ok when it exits 0 and reports the
# header's version and a bijective map.
run_consumer() {
    local what=$1 prog=$2 out
    out=$("$prog" 2>&1); rc=$?
    if [ "$rc" -eq 0 ] && printf '%s\n' "$out" | grep -q "^version $VERSION: .*, bijective$"; then
        ok "$what runs: $out"
    else
        fail "$what runs (exit $rc): $out"
    fi
}

VERSION=$(sed -n 's/^#define BP_VERSION_STRING "\([0-9][0-9.]*\)".*/\1/p' "$ROOT/bijparam.h")
if [ -n "$VERSION" ]; then ok "bijparam.h defines BP_VERSION_STRING \"$VERSION\""
else fail "bijparam.h has no #define BP_VERSION_STRING \"X.Y.Z\""; VERSION=none; fi

have_cmake=1 have_pkgconfig=1
if command -v cmake >/dev/null 2>&1; then ok "cmake is installed ($(cmake --version | head -n 1))"
else fail "cmake is not installed (Debian: apt-get install cmake): the CMake parts are not run"; have_cmake=0; fi
if command -v pkg-config >/dev/null 2>&1; then ok "pkg-config is installed ($(pkg-config --version))"
else fail "pkg-config is not installed (Debian: apt-get install pkgconf): the pkg-config consumer is not run"; have_pkgconfig=0; fi

# ---- the consumer program -----------------------------------------------------
cat >"$TMP/consumer.c" <<'EOF'
/* consumer.c - a program outside the repository that takes bijparam the
   way a user does (the installed header, or the CMake target): flattens a
   wavy 9x9 height field and proves the result bijective with the header's
   exact predicates: every triangle counter-clockwise (bp_orient2d > 0) and
   no two boundary edges without a common vertex meet (bp_segments_intersect)
   -- for a disc that is the whole of bijectivity.  Prints the version it was
   compiled against; exit 0 only when all holds. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define BP_IMPLEMENTATION
#include "bijparam.h"

enum { N = 9 };

int main(void)
{
    double pos[3 * N * N];
    uint32_t tri[6 * (N - 1) * (N - 1)], i, j, k, t = 0, nb = 0, *edge;
    bp_mesh mesh;
    bp_options opt;
    bp_atlas atlas;
    bp_error err;
    const bp_chart *c;
    int bad = 0;
    memset(&mesh, 0, sizeof mesh);
    memset(&opt, 0, sizeof opt);                   /* 0 = defaults */
    for (i = 0; i < N; i++)
        for (j = 0; j < N; j++) {
            double x = (double)j / (N - 1), y = (double)i / (N - 1);
            pos[3 * (i * N + j)] = x;
            pos[3 * (i * N + j) + 1] = y;
            pos[3 * (i * N + j) + 2] = 0.3 * sin(6 * x) * cos(5 * y);
        }
    for (i = 0; i + 1 < N; i++)
        for (j = 0; j + 1 < N; j++) {
            uint32_t a = i * N + j, b = a + 1, d = a + N + 1, e = a + N;
            tri[t++] = a; tri[t++] = b; tri[t++] = d;
            tri[t++] = a; tri[t++] = d; tri[t++] = e;
        }
    mesh.positions = pos; mesh.num_vertices = N * N;
    mesh.triangles = tri; mesh.num_triangles = t / 3;
    if (bp_parameterize(&atlas, &mesh, &opt, &err) != BP_OK) { printf("bp_parameterize: %s\n", err.message); return 1; }
    if (atlas.num_charts != 1 || atlas.num_failed != 0 || !atlas.charts[0].uv) {
        printf("expected one chart with a map, got %u charts, %u failed\n", (unsigned)atlas.num_charts,
               (unsigned)atlas.num_failed);
        return 1;
    }
    c = &atlas.charts[0];
    for (k = 0; k < c->num_triangles; k++) {
        const uint32_t *v = c->triangles + 3 * k;
        if (bp_orient2d(c->uv + 2 * v[0], c->uv + 2 * v[1], c->uv + 2 * v[2]) <= 0) {
            printf("triangle %u is flipped or degenerate in UV\n", (unsigned)k + 1);
            bad = 1;
        }
    }
    /* boundary edges: the edges of exactly one triangle (brute force) */
    edge = (uint32_t *)malloc(sizeof(uint32_t) * 6 * c->num_triangles);
    if (!edge) return 1;
    for (k = 0; k < 3 * c->num_triangles; k++) {
        uint32_t a = c->triangles[k], b = c->triangles[k % 3 == 2 ? k - 2 : k + 1], m, n = 0;
        for (m = 0; m < 3 * c->num_triangles; m++) {
            uint32_t p = c->triangles[m], q = c->triangles[m % 3 == 2 ? m - 2 : m + 1];
            if ((p == a && q == b) || (p == b && q == a)) n++;
        }
        if (n == 1) { edge[2 * nb] = a; edge[2 * nb + 1] = b; nb++; }
    }
    if (nb != 4 * (N - 1)) { printf("%u boundary edges, expected %d\n", (unsigned)nb, 4 * (N - 1)); bad = 1; }
    for (i = 0; i < nb; i++)
        for (j = i + 1; j < nb; j++) {
            const uint32_t *e = edge + 2 * i, *f = edge + 2 * j;
            if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1]) continue;
            if (bp_segments_intersect(c->uv + 2 * e[0], c->uv + 2 * e[1], c->uv + 2 * f[0], c->uv + 2 * f[1])) {
                printf("boundary edges %u-%u and %u-%u meet\n", (unsigned)e[0] + 1, (unsigned)e[1] + 1,
                       (unsigned)f[0] + 1, (unsigned)f[1] + 1);
                bad = 1;
            }
        }
    if (!(c->energy_end <= c->energy_start) || !(c->energy_end >= 4.0)) {
        printf("energy %g -> %g: expected a decrease to at least 4 (isometry)\n", c->energy_start, c->energy_end);
        bad = 1;
    }
    printf("version %s: %u triangles, %u boundary edges, energy %.4f -> %.4f, %s\n", BP_VERSION_STRING,
           (unsigned)c->num_triangles, (unsigned)nb, c->energy_start, c->energy_end,
           bad ? "NOT bijective" : "bijective");
    free(edge);
    bp_atlas_free(&atlas);
    return bad;
}
EOF

# ---- (a) make install / pkg-config / make uninstall ------------------------------
MP=$TMP/make_prefix
if check "make install PREFIX=\$TMP/make_prefix (builds the tool into \$TMP, not the repository)" \
        make -C "$ROOT" --no-print-directory BUILD="$TMP/make_build" PREFIX="$MP" install; then
    files=$(cd "$MP" && find . ! -type d | sort | tr '\n' ' ')
    want="./bin/bijparam ./include/bijparam.h ./share/pkgconfig/bijparam.pc "
    if [ "$files" = "$want" ]; then ok "make install installs exactly: $files"
    else fail "make install installs '$files', expected '$want'"; fi
    if cmp -s "$ROOT/bijparam.h" "$MP/include/bijparam.h"; then ok "the installed header is bijparam.h"
    else fail "the installed header differs from bijparam.h"; fi
    if "$MP/bin/bijparam" --demo -o "$TMP/demo.obj" >"$TMP/log" 2>&1 && grep -q '^vt ' "$TMP/demo.obj"; then
        ok "the installed tool runs (--demo writes an OBJ with vt lines)"
    else fail "the installed tool fails on --demo"; tail -n 10 "$TMP/log" | sed 's/^/     | /'; fi
    pc=$MP/share/pkgconfig/bijparam.pc
    if grep -qx "prefix=$MP" "$pc" && grep -qx "Version: $VERSION" "$pc"; then
        ok "bijparam.pc names the prefix and version $VERSION"
    else fail "bijparam.pc does not say prefix=$MP and Version: $VERSION"; sed 's/^/     | /' "$pc"; fi

    if [ "$have_pkgconfig" = 1 ]; then
        export PKG_CONFIG_PATH=$MP/share/pkgconfig
        mv=$(pkg-config --modversion bijparam 2>&1)
        [ "$mv" = "$VERSION" ] && ok "pkg-config --modversion bijparam: $mv" \
                                || fail "pkg-config --modversion bijparam says '$mv', expected $VERSION"
        flags="$(pkg-config --cflags bijparam) $(pkg-config --libs bijparam)"
        case " $flags " in
            *" -I$MP/include "*" -lm "*) ok "pkg-config --cflags --libs bijparam: $flags" ;;
            *) fail "pkg-config --cflags --libs bijparam gives '$flags', expected -I$MP/include and -lm" ;;
        esac
        if check "a consumer outside the repository compiles with pkg-config (-std=c99 -Wall -Wextra -pedantic -Werror)" \
                sh -c "cd '$TMP' && $CC -std=c99 -Wall -Wextra -pedantic -Werror \$(pkg-config --cflags bijparam) consumer.c -o consumer_pc \$(pkg-config --libs bijparam)"; then
            run_consumer "the pkg-config consumer (make install)" "$TMP/consumer_pc"
        fi
        unset PKG_CONFIG_PATH
    fi

    # DESTDIR stages the same tree; the .pc still names the real prefix
    if check "make install PREFIX=/usr/local DESTDIR=\$TMP/stage" \
            make -C "$ROOT" --no-print-directory BUILD="$TMP/make_build" PREFIX=/usr/local DESTDIR="$TMP/stage" install; then
        files=$(cd "$TMP/stage" && find . ! -type d | sort | tr '\n' ' ')
        want="./usr/local/bin/bijparam ./usr/local/include/bijparam.h ./usr/local/share/pkgconfig/bijparam.pc "
        if [ "$files" = "$want" ] && grep -qx "prefix=/usr/local" "$TMP/stage/usr/local/share/pkgconfig/bijparam.pc"; then
            ok "DESTDIR: the files land under DESTDIR, bijparam.pc says prefix=/usr/local"
        else fail "DESTDIR: installed '$files' (expected '$want'), or bijparam.pc's prefix is not /usr/local"; fi
    fi

    if check "make uninstall PREFIX=\$TMP/make_prefix" make -C "$ROOT" --no-print-directory BUILD="$TMP/make_build" PREFIX="$MP" uninstall; then
        left=$(cd "$MP" && find . ! -type d | tr '\n' ' ')
        [ -z "$left" ] && ok "make uninstall removes every installed file" || fail "make uninstall leaves: $left"
    fi
fi

[ "$have_cmake" = 1 ] || { echo "BPTEST $passed $failed"; exit 1; }

# ---- (d) the top-level CMake build: configure, build, ctest, install ----------
TB=$TMP/top_build
CP=$TMP/cmake_prefix
if check "cmake configures the repository as the top-level project (-DBIJPARAM_WERROR=ON)" \
        cmake -S "$ROOT" -B "$TB" -DBIJPARAM_WERROR=ON; then
    cp "$TMP/log" "$TMP/configure.log"
    n_c=$(ls "$ROOT"/tests/test_*.c | wc -l)
    n_cpp=$(ls "$ROOT"/tests/test_*.cpp 2>/dev/null | wc -l)
    subset="test_io"
    if grep -q 'bijparam: OpenMesh found' "$TMP/configure.log"; then
        n_want=$((n_c + n_cpp)); subset="$subset|test_openmesh"; why="$n_c C + $n_cpp C++ (OpenMesh found)"
    else
        n_want=$n_c; why="$n_c C; OpenMesh not found, so the C++ tests are not built (cmake said so)"
        grep -q 'OpenMesh not found' "$TMP/configure.log" || fail "cmake did not say why the C++ tests are missing"
    fi
    n_reg=$(cd "$TB" && ctest -N | sed -n 's/^Total Tests: //p')
    [ "$n_reg" = "$n_want" ] && ok "ctest registers one test per tests/test_*: $n_reg ($why)" \
                             || fail "ctest registers $n_reg tests, expected $n_want ($why)"
    if [ -n "${BP_TEST_INSTALL_FULL:-}" ]; then
        targets=""; subset=".*"; n_run=$n_want
    else
        targets="--target bijparam_tool example_minimal $(echo "$subset" | tr '|' ' ')"
        n_run=$(echo "$subset" | tr '|' '\n' | wc -l)
    fi
    t0=$(date +%s)
    if check "cmake --build $targets" cmake --build "$TB" $targets; then
        t1=$(date +%s)
        if (cd "$TB" && ctest -R "^($subset)\$" --output-on-failure) >"$TMP/ctest.log" 2>&1 &&
                grep -q "100% tests passed, 0 tests failed out of $n_run\$" "$TMP/ctest.log"; then
            ok "ctest -R '^($subset)\$' passes all $n_run (build $((t1 - t0)) s, ctest $(( $(date +%s) - t1 )) s)"
        else
            fail "ctest -R '^($subset)\$'"; tail -n 30 "$TMP/ctest.log" | sed 's/^/     | /'
        fi
        if "$TB/bijparam" --demo -o "$TMP/demo2.obj" >"$TMP/log" 2>&1 && grep -q '^vt ' "$TMP/demo2.obj"; then
            ok "the CMake-built tool runs (--demo)"
        else fail "the CMake-built tool fails on --demo"; tail -n 10 "$TMP/log" | sed 's/^/     | /'; fi
        check "the CMake-built example runs (examples/minimal)" "$TB/examples/minimal"
        if check "cmake --install --prefix \$TMP/cmake_prefix" cmake --install "$TB" --prefix "$CP"; then
            files=$(cd "$CP" && find . ! -type d | sort | tr '\n' ' ')
            want="./bin/bijparam ./include/bijparam.h ./share/cmake/bijparam/bijparamConfig.cmake ./share/cmake/bijparam/bijparamConfigVersion.cmake ./share/cmake/bijparam/bijparamTargets.cmake ./share/pkgconfig/bijparam.pc "
            [ "$files" = "$want" ] && ok "cmake --install installs exactly: $files" \
                                   || fail "cmake --install installs '$files', expected '$want'"
            grep -qx "prefix=$CP" "$CP/share/pkgconfig/bijparam.pc" && ok "CMake's bijparam.pc says prefix=\$TMP/cmake_prefix (the --prefix given at install time)" \
                || fail "CMake's bijparam.pc does not say prefix=$CP"
        fi
    fi
fi

# ---- (b) find_package against the CMake install; pkg-config against it too ----
# cmake_consumer dir "cmake lines": a consumer project in $TMP/dir
cmake_consumer() {
    mkdir -p "$TMP/$1"
    cp "$TMP/consumer.c" "$TMP/$1/"
    printf '%s\n' "$2" "add_executable(consumer consumer.c)" \
        "target_link_libraries(consumer PRIVATE bijparam::bijparam)" >"$TMP/$1/CMakeLists.txt"
}
if [ -f "$CP/share/cmake/bijparam/bijparamConfig.cmake" ]; then
    cmake_consumer find 'cmake_minimum_required(VERSION 3.13)
project(consumer C)
find_package(bijparam ${WANT} CONFIG REQUIRED)
message(STATUS "found bijparam ${bijparam_VERSION} in ${bijparam_DIR}")'
    if check "find_package(bijparam $VERSION CONFIG REQUIRED) with CMAKE_PREFIX_PATH=\$TMP/cmake_prefix configures" \
            cmake -S "$TMP/find" -B "$TMP/find/build" -DWANT="$VERSION" -DCMAKE_PREFIX_PATH="$CP" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON; then
        grep -q "found bijparam $VERSION in $CP/share/cmake/bijparam\$" "$TMP/log" \
            && ok "find_package found version $VERSION in the prefix" \
            || fail "find_package did not report version $VERSION in $CP/share/cmake/bijparam"
        if check "the find_package consumer builds" cmake --build "$TMP/find/build"; then
            grep -q -- "$CP/include" "$TMP/find/build/compile_commands.json" \
                && ok "the find_package consumer compiles against the installed header ($CP/include)" \
                || fail "the find_package consumer's compile line does not name $CP/include"
            run_consumer "the find_package consumer" "$TMP/find/build/consumer"
        fi
    fi
    if cmake -S "$TMP/find" -B "$TMP/find/build99" -DWANT=99.0 -DCMAKE_PREFIX_PATH="$CP" >"$TMP/log" 2>&1; then
        fail "find_package(bijparam 99.0) is accepted by version $VERSION"
    elif grep -q "99.0" "$TMP/log"; then ok "find_package(bijparam 99.0 ...) is refused (the version file works)"
    else fail "find_package(bijparam 99.0) fails, but not on the version"; tail -n 10 "$TMP/log" | sed 's/^/     | /'; fi
    if [ "$have_pkgconfig" = 1 ]; then
        if check "the pkg-config consumer compiles against CMake's bijparam.pc" \
                sh -c "cd '$TMP' && export PKG_CONFIG_PATH='$CP/share/pkgconfig' && $CC -std=c99 -Wall -Wextra -pedantic -Werror \$(pkg-config --cflags bijparam) consumer.c -o consumer_pc2 \$(pkg-config --libs bijparam)"; then
            run_consumer "the pkg-config consumer (CMake install)" "$TMP/consumer_pc2"
        fi
    fi
else
    fail "no CMake install to try find_package on (see above)"
fi

# ---- (c) add_subdirectory and FetchContent ---------------------------------------
# ours_built dir: the programs bijparam builds as top-level project, if any
# were built below dir
ours_built() { find "$1" -type f \( -name bijparam -o -name 'test_*' -o -name minimal \) ! -name '*.*' | tr '\n' ' '; }
cmake_consumer sub 'cmake_minimum_required(VERSION 3.13)
project(consumer C)
add_subdirectory(${BIJPARAM_SOURCE} bijparam)'
if check "an add_subdirectory consumer configures and builds" \
        sh -c "cmake -S '$TMP/sub' -B '$TMP/sub/build' -DBIJPARAM_SOURCE='$ROOT' && cmake --build '$TMP/sub/build'"; then
    run_consumer "the add_subdirectory consumer" "$TMP/sub/build/consumer"
    built=$(ours_built "$TMP/sub/build/bijparam")
    n_reg=$(cd "$TMP/sub/build" && ctest -N | sed -n 's/^Total Tests: //p')
    [ -z "$built" ] && [ "$n_reg" = 0 ] && ok "as a subproject bijparam builds no tool, example or test, and registers no ctest test" \
        || fail "as a subproject bijparam built '$built' and registered $n_reg tests"
fi
(cd "$ROOT" && tar --exclude=./build --exclude=./.git -czf "$TMP/bijparam-src.tar.gz" .)
cmake_consumer fetch 'cmake_minimum_required(VERSION 3.14)
project(consumer C)
if(POLICY CMP0135)
  cmake_policy(SET CMP0135 NEW)
endif()
include(FetchContent)
FetchContent_Declare(bijparam URL ${BIJPARAM_URL})
FetchContent_MakeAvailable(bijparam)'
if check "a FetchContent consumer (URL file://\$TMP/bijparam-src.tar.gz, offline) configures and builds" \
        sh -c "cmake -S '$TMP/fetch' -B '$TMP/fetch/build' -DBIJPARAM_URL='file://$TMP/bijparam-src.tar.gz' && cmake --build '$TMP/fetch/build'"; then
    run_consumer "the FetchContent consumer" "$TMP/fetch/build/consumer"
    built=$(ours_built "$TMP/fetch/build/_deps")
    [ -z "$built" ] && ok "through FetchContent bijparam builds no tool, example or test" \
        || fail "through FetchContent bijparam built '$built'"
fi

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
