#!/usr/bin/env bash
# test_build_matrix.sh - every combination of the opt-out macros (make check).
#
# For each of the 16 subsets of BP_NO_NEWTON, BP_NO_ATLAS, BP_NO_VISIBILITY
# and BP_NO_IO:
#   - tests/build_options.c compiles warning-free (-Wall -Wextra -pedantic
#     -Werror) as C99 with gcc -O2 and runs on tests/data/camel_b.obj:
#     camel_b flattened with the defaults and checked by bp_check, every
#     option needing a left-out part refused with BP_ERR_UNSUPPORTED naming
#     its macro (see that file), and the written map bijective by
#     tests/uvcheck.py;
#   - the implementation compiles warning-free as C++11 with g++ -O2.
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
CXX=${CXX:-g++}
PY=${PYTHON:-python3}
WARN="-Wall -Wextra -pedantic -Werror"
MACROS="BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY BP_NO_IO"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_matrix.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_build_matrix.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_build_matrix.sh: $*"; failed=$((failed + 1)); }

printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\n' >"$TMP/impl.cpp"
for mask in $(seq 0 15); do
    set -- $MACROS
    used="" defs=""
    for bit in 1 2 4 8; do
        [ $((mask & bit)) -ne 0 ] && { used="$used $1"; defs="$defs -D$1"; }
        shift
    done
    name=${used# }
    name=${name:-"(all parts)"}
    if $CC -std=c99 -O2 $WARN $defs -I"$ROOT" -I"$ROOT/tests" "$ROOT/tests/build_options.c" -o "$TMP/options" -lm \
            2>"$TMP/cc.log"; then
        if "$TMP/options" "$ROOT/tests/data/camel_b.obj" "$TMP/out.obj" "$ROOT/tests/data/bishop_part_f1000.obj" \
                >"$TMP/run.log" 2>&1 && $PY "$ROOT/tests/uvcheck.py" "$TMP/out.obj" >"$TMP/uv.log" 2>&1; then
            ok "$name: C99 builds warning-free, $(tail -1 "$TMP/run.log"), camel_b bijective by tests/uvcheck.py"
        else
            fail "$name: the C99 build's run"; cat "$TMP/run.log" "$TMP/uv.log" 2>/dev/null
        fi
    else
        fail "$name: does not compile as C99"; head -n 30 "$TMP/cc.log"
    fi
    if $CXX -std=c++11 -O2 $WARN $defs -I"$ROOT" -c "$TMP/impl.cpp" -o "$TMP/impl.o" 2>"$TMP/cxx.log"; then
        ok "$name: C++11 builds warning-free"
    else
        fail "$name: does not compile as C++11"; head -n 30 "$TMP/cxx.log"
    fi
done
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
