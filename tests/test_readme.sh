#!/usr/bin/env bash
# test_readme.sh - the README's example program is what it says it is.
#
# The packages of the README's `apt-get install` line are those .ci/run
# installs.
# Extracts the first ```c block of README.md (the "Use" section), compiles it
# warning-free (-Wall -Wextra -pedantic -Werror) as C99 with gcc and as C++11
# with g++ (and with clang / clang++ when installed; a missing clang is
# reported, not counted), with AddressSanitizer (leaks included) for the C
# build, and runs it:
#   - on a good mesh (the disk alone): prints nothing, writes the file, 0;
#   - on a closed tetrahedron next to the disk: with the default options it
#     is cut into a disk (automatic seams), so every face gets vt, 0;
#   - on a mesh with a NaN vertex (a defect that fails the whole call):
#     prints the error, writes nothing, 1;
#   - with a missing input: prints the error, writes nothing, 1.
# With the default options every local defect is repaired or cut, so no
# chart fails on its own any more.  The BP_ERR_CHARTS_FAILED path of the
# example (the atlas kept, the good charts written, the atlas freed) is
# reached by the same program with one line added after its memset,
# `opt.cut = BP_CUT_NONE;`, built with gcc + AddressSanitizer and g++: on
# the disk next to the tetrahedron it prints the message, writes the 18
# disk faces with vt and the 4 closed ones without, exits 1, leaks nothing.
# With BP_TEST_QUICK set (make test) one gcc + AddressSanitizer build at -O0
# serves both programs (the added line sets BP_CUT_NONE when the environment
# has BP_README_CUT_NONE); make check builds all six at -O1.
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
CXX=${CXX:-g++}
WARN="-Wall -Wextra -pedantic -Werror"
OPT=-O1
[ -n "${BP_TEST_QUICK:-}" ] && OPT=-O0
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_readme.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_readme.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_readme.sh: $*"; failed=$((failed + 1)); }

# The README's set-up command installs what CI (.ci/run) installs.
pk() {   # the packages of the first apt-get install command of $1 (continued lines joined)
    awk '/apt-get install/ { on = 1 } on { line = line " " $0; if ($0 !~ /\\$/) exit } END { print line }' "$1" |
        sed 's/.*--no-install-recommends//; s/&&.*//; s/\\//g' | tr ' ' '\n' | grep -v '^$' | sort | tr '\n' ' '
}
if [ -n "$(pk "$ROOT/README.md")" ] && [ "$(pk "$ROOT/README.md")" = "$(pk "$ROOT/.ci/run")" ]; then
    ok "README.md installs the packages CI installs: $(pk "$ROOT/README.md")"
else
    fail "README.md's apt-get install ($(pk "$ROOT/README.md")) is not .ci/run's ($(pk "$ROOT/.ci/run"))"
fi

awk '/^```c$/ { if (!done) { on = 1; next } } /^```$/ { if (on) { on = 0; done = 1 } } on' "$ROOT/README.md" >"$TMP/example.c"
if grep -q 'bp_parameterize' "$TMP/example.c" && grep -q 'int main' "$TMP/example.c"; then
    ok "README.md: extracted the example ($(wc -l <"$TMP/example.c") lines, calls bp_parameterize)"
else
    fail "README.md: no \`\`\`c block with main and bp_parameterize found"
fi
cp "$TMP/example.c" "$TMP/example.cpp"

# a 3x3 grid (a disk, faces 1-18) and a chart of two triangles, the second of
# zero area (vertex 21 on the line through 17 and 18; faces 19-20)
{
    for j in 0 1 2 3; do for i in 0 1 2 3; do echo "v $i $j 0.$((i * j))"; done; done
    echo "v 10 0 0"; echo "v 11 0 0"; echo "v 10 1 0"; echo "v 10 0 1"; echo "v 12 0 0"
    for j in 0 1 2; do for i in 0 1 2; do
        a=$((j * 4 + i + 1)); b=$((a + 1)); c=$((a + 5)); d=$((a + 4))
        echo "f $a $b $c"; echo "f $a $c $d"
    done; done
} >"$TMP/disk.obj"
cp "$TMP/disk.obj" "$TMP/mixed.obj"
printf 'f 17 19 18\nf 17 18 20\nf 17 20 19\nf 18 19 20\n' >>"$TMP/mixed.obj"
{ cat "$TMP/disk.obj"; echo "v nan 0 0"; echo "f 1 2 22"; } >"$TMP/nan.obj"
# the example with automatic seams off: the tetrahedron's chart then fails
sed 's/^\( *\)memset(&opt, 0, sizeof opt);.*$/&\n\1opt.cut = BP_CUT_NONE;/' "$TMP/example.c" >"$TMP/nocut.c"
cp "$TMP/nocut.c" "$TMP/nocut.cpp"
grep -q 'opt.cut = BP_CUT_NONE;' "$TMP/nocut.c" && ok "README.md: the example with automatic seams off (one line added after its memset)" ||
    fail "README.md: the example has no 'memset(&opt, 0, sizeof opt);' line to add 'opt.cut = BP_CUT_NONE;' after"

# run_example BIN label: the default program's runs above
run_example() {
    local bin=$1 label=$2 out rc
    rm -f "$TMP/out.obj"
    out=$("$bin" "$TMP/disk.obj" "$TMP/out.obj" 2>&1); rc=$?
    if [ $rc -eq 0 ] && [ -z "$out" ] && [ "$(grep -c '^f [0-9]*/[0-9]*' "$TMP/out.obj" 2>/dev/null)" = 18 ]; then
        ok "$label: a good mesh: silent, every face written with vt, exits 0"
    else
        fail "$label on the disk: exit $rc, output: $(echo "$out" | head -n 3)"
    fi
    rm -f "$TMP/out.obj"
    out=$("$bin" "$TMP/mixed.obj" "$TMP/out.obj" 2>&1); rc=$?
    if [ $rc -eq 0 ] && [ -z "$out" ] && [ "$(grep -c '^f [0-9]*/[0-9]*' "$TMP/out.obj" 2>/dev/null)" = 22 ]; then
        ok "$label: disk + closed tetrahedron: the tetrahedron is cut, every face written with vt, exits 0"
    else
        fail "$label on disk + tetrahedron: exit $rc, output: $(echo "$out" | head -n 3)"
    fi
    rm -f "$TMP/out.obj"
    out=$("$bin" "$TMP/nan.obj" "$TMP/out.obj" 2>&1); rc=$?
    if [ $rc -eq 1 ] && echo "$out" | grep -qi 'nan\|finite' && [ ! -e "$TMP/out.obj" ] &&
       ! echo "$out" | grep -q 'Sanitizer'; then
        ok "$label: a whole-mesh defect (NaN vertex): prints why, writes nothing, exits 1, no leak"
    else
        fail "$label on the NaN mesh: exit $rc, file $( [ -e "$TMP/out.obj" ] && echo written || echo absent), output: $(echo "$out" | head -n 3)"
    fi
    out=$("$bin" "$TMP/missing.obj" "$TMP/out.obj" 2>&1); rc=$?
    if [ $rc -eq 1 ] && [ -n "$out" ] && [ ! -e "$TMP/out.obj" ]; then
        ok "$label: a missing input: prints the error, writes nothing, exits 1"
    else
        fail "$label on a missing file: exit $rc, output: $(echo "$out" | head -n 3)"
    fi
}

# run_failed_chart BIN label: the nocut program on disk + tetrahedron
run_failed_chart() {
    local bin=$1 label=$2 out rc
    rm -f "$TMP/out.obj"
    out=$("$bin" "$TMP/mixed.obj" "$TMP/out.obj" 2>&1); rc=$?
    if [ $rc -eq 1 ] && echo "$out" | grep -q 'charts failed' && [ -s "$TMP/out.obj" ] &&
       [ "$(grep -c '^f [0-9]*/[0-9]*' "$TMP/out.obj")" -eq 18 ] &&
       [ "$(grep -c '^f [0-9]* [0-9]* [0-9]*$' "$TMP/out.obj")" -eq 4 ] && [ "$(grep -c '^vt ' "$TMP/out.obj")" -ge 16 ] &&
       ! echo "$out" | grep -q 'LeakSanitizer\|AddressSanitizer'; then
        ok "$label (cut none): one chart fails: says so, writes the 18 disk faces with vt and the 4 closed ones without, exits 1, no leak"
    else
        fail "$label (cut none) on disk + tetrahedron: exit $rc, output: $(echo "$out" | head -n 3)"
    fi
}

# compile "label" compiler std src: -Werror build, then run_example
compile_and_run() {
    local label=$1 cc=$2 std=$3 src=$4; shift 4
    if $cc -std=$std $OPT $WARN "$@" -I"$ROOT" "$src" -o "$TMP/example" -lm >"$TMP/log" 2>&1; then
        ok "$label -std=$std $WARN $*: the README example compiles"
        run_example "$TMP/example" "$label"
    else
        fail "$label -std=$std $WARN $*: the README example compiles"; sed 's/^/     | /' "$TMP/log" | head -n 20
    fi
}
if [ -n "${BP_TEST_QUICK:-}" ]; then
    # one build for both programs: the added line reads the environment
    { echo '#include <stdlib.h>'
      sed 's/^\( *\)opt.cut = BP_CUT_NONE;$/\1if (getenv("BP_README_CUT_NONE")) opt.cut = BP_CUT_NONE;/' "$TMP/nocut.c"; } >"$TMP/both.c"
    compile_and_run gcc "$CC" c99 "$TMP/both.c" -fsanitize=address -fno-omit-frame-pointer
    BP_README_CUT_NONE=1 run_failed_chart "$TMP/example" gcc
    echo "note: BP_TEST_QUICK: the example and the one with automatic seams off built as one program (the line added reads BP_README_CUT_NONE); the g++, clang and clang++ builds are left to make check (not counted)"
    echo "BPTEST $passed $failed"
    [ "$failed" -eq 0 ]
    exit
fi
compile_and_run gcc "$CC" c99 "$TMP/example.c" -fsanitize=address -fno-omit-frame-pointer
nocut_builds=("gcc $CC c99 nocut.c -fsanitize=address -fno-omit-frame-pointer" "g++ $CXX c++11 nocut.cpp")
for v in "${nocut_builds[@]}"; do
    set -- $v
    label=$1 cc=$2 std=$3 src=$4; shift 4
    if $cc -std=$std $OPT $WARN "$@" -I"$ROOT" "$TMP/$src" -o "$TMP/nocut" -lm >"$TMP/log" 2>&1; then
        run_failed_chart "$TMP/nocut" "$label"
    else
        fail "$label: the example with opt.cut = BP_CUT_NONE compiles"; sed 's/^/     | /' "$TMP/log" | head -n 20
    fi
done
compile_and_run g++ "$CXX" c++11 "$TMP/example.cpp"
if command -v clang >/dev/null 2>&1; then
    compile_and_run clang clang c99 "$TMP/example.c"
    compile_and_run clang++ clang++ c++11 "$TMP/example.cpp"
else
    echo "note: clang not installed, the README example was not built with it (not counted)"
fi
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
