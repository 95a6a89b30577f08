#!/usr/bin/env bash
# test_cross.sh - the same bytes on x86-64 Linux, Windows and aarch64
# (make check).
#
#   - The tool (examples/bijparam.c) is cross-built for Windows with
#     mingw-w64 (x86_64-w64-mingw32-gcc, its POSIX threads, static) and run
#     under wine, and for aarch64 with aarch64-linux-gnu-gcc (static,
#     -std=gnu99, where GCC fuses a * b + c into fma unless the header
#     stops it) and run under qemu-aarch64.  On camel_b, spot, spot
#     --atlas 1024, face_holes --atlas 512 --padding 2 and a grid of quads
#     (polygons fanned into triangles) each writes the native build's
#     output byte for byte.
#   - tests/test_math.c --hash prints the same hash of the elementary
#     functions' bits on all three.
#   - The README's example built with mingw-w64 (at -O2 and at -O0, where
#     GCC calls the C library's sqrt instead of the instruction) and run
#     under wine writes camel_b's native bytes (those of the same example
#     built natively).
# A missing cross compiler, wine or qemu is a failure, not a skip (make
# deps installs them).  wine runs in a temporary WINEPREFIX; its first start
# takes a while.  Prints "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_cross.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_cross.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_cross.sh: $*"; failed=$((failed + 1)); }
finish() { echo "BPTEST $passed $failed"; [ "$failed" -eq 0 ]; exit; }

CC=${CC:-gcc}
MINGW=${MINGW:-x86_64-w64-mingw32-gcc}
ARM=${ARM:-aarch64-linux-gnu-gcc}
QEMU=${QEMU:-qemu-aarch64}
WINE=${WINE:-$(command -v wine64 || echo /usr/lib/wine/wine64)}
WARN="-Wall -Wextra -pedantic -Werror"
export WINEPREFIX=$TMP/wine WINEDEBUG=-all
for t in "$CC" "$MINGW" "$ARM" "$QEMU" "$WINE"; do
    command -v "$t" >/dev/null 2>&1 || { fail "$t is not installed (make deps)"; finish; }
done

# build NAME COMPILER FLAGS... SOURCE: one binary, -Werror
build() {
    local name=$1 cc=$2; shift 2
    if "$cc" "$@" -I"$ROOT" -I"$ROOT/tests" -o "$TMP/$name" >"$TMP/$name.log" 2>&1; then
        ok "$name: $cc $(echo "$*" | sed "s|$ROOT/||g; s|$TMP/||g")"
    else
        fail "$name: $cc $* does not build"; sed 's/^/     | /' "$TMP/$name.log" | head -20; return 1
    fi
}
T=$ROOT/examples/bijparam.c
build tool "$CC" -std=c99 -O2 $WARN -DBP_USE_PTHREADS -pthread "$T" -lm || finish
build tool.exe "$MINGW" -std=c99 -O2 $WARN -DBP_USE_PTHREADS "$T" -static -lpthread || finish
build tool.arm "$ARM" -std=gnu99 -O2 $WARN -DBP_USE_PTHREADS -pthread "$T" -static -lm || finish
build math "$CC" -std=c99 -O2 $WARN "$ROOT/tests/test_math.c" -lm
build math.exe "$MINGW" -std=c99 -O2 $WARN "$ROOT/tests/test_math.c" -static
build math.arm "$ARM" -std=gnu99 -O2 $WARN "$ROOT/tests/test_math.c" -static -lm
awk '/^```c$/ { if (!done) { on = 1; next } } /^```$/ { if (on) { on = 0; done = 1 } } on' "$ROOT/README.md" >"$TMP/example.c"
build example "$CC" -std=c99 -O2 $WARN "$TMP/example.c" -lm
build example.exe "$MINGW" -std=c99 -O2 $WARN "$TMP/example.c" -static
build example-O0.exe "$MINGW" -std=c99 -O0 $WARN "$TMP/example.c" -static

# run_on PLATFORM CMD...: the command under its platform
run_on() {
    case $1 in
        native) shift; "$@" ;;
        windows) shift; "$WINE" "$@" ;;
        aarch64) shift; "$QEMU" "$@" ;;
    esac
}

# the math hash
if [ -x "$TMP/math" ] && [ -x "$TMP/math.exe" ] && [ -x "$TMP/math.arm" ]; then
    n=$("$TMP/math" --hash | grep 'math hash')
    w=$(run_on windows "$TMP/math.exe" --hash 2>"$TMP/wine.err" | tr -d '\r' | grep 'math hash')
    a=$(run_on aarch64 "$TMP/math.arm" --hash | grep 'math hash')
    if [ -n "$n" ] && [ "$n" = "$w" ] && [ "$n" = "$a" ]; then ok "the elementary functions' hash is the same on all three: ${n#note }"
    else fail "the elementary functions' hash: native '$n', windows '$w', aarch64 '$a'"; head -5 "$TMP/wine.err"; fi
fi

D=$ROOT/tests/data
# a wavy 40 x 40 grid of quads: the polygons' triangles share a face
awk 'BEGIN { n = 40
    for (j = 0; j <= n; j++) for (i = 0; i <= n; i++)
        printf "v %.6f %.6f %.6f\n", i / n, j / n, 0.2 * sin(3 * i / n) * cos(2 * j / n)
    for (j = 0; j < n; j++) for (i = 0; i < n; i++) {
        a = j * (n + 1) + i + 1; printf "f %d %d %d %d\n", a, a + 1, a + n + 2, a + n + 1 } }' >"$TMP/quads.obj"
i=0
for args in "camel_b.obj" "spot.obj" "spot.obj --atlas 1024" "face_holes.off --atlas 512 --padding 2" "$TMP/quads.obj"; do
    set -- $args
    m=$1; shift
    case $m in /*) ;; *) m=$D/$m ;; esac
    i=$((i + 1))
    "$TMP/tool" -q "$m" "$@" -o "$TMP/n$i.obj" || { fail "$args: the native tool failed"; continue; }
    for p in windows aarch64; do
        case $p in windows) bin=$TMP/tool.exe ;; aarch64) bin=$TMP/tool.arm ;; esac
        rm -f "$TMP/o$i.obj"
        run_on $p "$bin" -q "$m" "$@" -o "$TMP/o$i.obj" >"$TMP/run.log" 2>&1
        if cmp -s "$TMP/n$i.obj" "$TMP/o$i.obj"; then
            ok "${args#$TMP/}: $p writes the native bytes ($(wc -c <"$TMP/n$i.obj") bytes)"
        else
            fail "${args#$TMP/}: $p's output differs from the native one ($(cmp "$TMP/n$i.obj" "$TMP/o$i.obj" 2>&1 | head -1))"
            head -5 "$TMP/run.log"
        fi
    done
done

if [ -x "$TMP/example" ]; then
    "$TMP/example" "$D/camel_b.obj" "$TMP/ex_n.obj"
    for x in example.exe example-O0.exe; do
        [ -x "$TMP/$x" ] || continue
        rm -f "$TMP/ex_w.obj"
        run_on windows "$TMP/$x" "$D/camel_b.obj" "$TMP/ex_w.obj" >/dev/null 2>&1
        if [ -s "$TMP/ex_n.obj" ] && cmp -s "$TMP/ex_n.obj" "$TMP/ex_w.obj"; then
            ok "the README example built with mingw-w64 ($x), under wine: camel_b's native bytes"
        else
            fail "the README example ($x) under wine: camel_b differs from the native output"
        fi
    done
fi
finish
