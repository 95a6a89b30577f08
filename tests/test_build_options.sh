#!/usr/bin/env bash
# test_build_options.sh - the library built without some of its parts.
#
# tests/build_options.c is compiled (gcc -std=c99 -O1, warnings as errors)
# once per combination of the opt-out macros below and run on
# tests/data/camel_b.obj: in each build camel_b is flattened with the
# defaults, every chart passes bp_check, and tests/uvcheck.py (an
# independent exact checker) accepts the written map; every option that
# needs a left-out part fails with BP_ERR_UNSUPPORTED naming the macro.
# Also: a left-out part's public functions are not declared (a call does
# not compile), and BP_NO_IO never includes <stdio.h>.
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
PY=${PYTHON:-python3}
WARN="-Wall -Wextra -pedantic -Werror"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_options.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_build_options.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_build_options.sh: $*"; failed=$((failed + 1)); }

n=0
for macros in "BP_NO_VISIBILITY" "BP_NO_IO" "BP_NO_IO BP_NO_VISIBILITY"; do
    n=$((n + 1))
    defs=$(for m in $macros; do printf ' -D%s' "$m"; done)
    exe="$TMP/options$n"
    if $CC -std=c99 -O1 $WARN $defs -I"$ROOT" -I"$ROOT/tests" "$ROOT/tests/build_options.c" -o "$exe" -lm \
            2>"$TMP/cc$n.log"; then
        ok "$macros: compiles warning-free"
    else
        fail "$macros: does not compile"; cat "$TMP/cc$n.log"; continue
    fi
    if "$exe" "$ROOT/tests/data/camel_b.obj" "$TMP/out$n.obj" >"$TMP/run$n.log" 2>&1; then
        ok "$macros: $(tail -1 "$TMP/run$n.log") (camel_b flattened, checked, refusals)"
    else
        fail "$macros: the program failed"; cat "$TMP/run$n.log"
    fi
    if $PY "$ROOT/tests/uvcheck.py" "$TMP/out$n.obj" >"$TMP/uv$n.log" 2>&1; then
        ok "$macros: tests/uvcheck.py finds camel_b's map bijective"
    else
        fail "$macros: tests/uvcheck.py rejects camel_b's map"; cat "$TMP/uv$n.log"
    fi
done

# a left-out part's functions are not declared
nodecl() {   # macro, call
    printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void) { %s; return 0; }\n' "$2" >"$TMP/call.c"
    if $CC -std=c99 $WARN -D"$1" -I"$ROOT" -c "$TMP/call.c" -o "$TMP/call.o" 2>/dev/null; then
        fail "$1: '$2' still compiles"
    elif $CC -std=c99 $WARN -I"$ROOT" -c "$TMP/call.c" -o "$TMP/call.o" 2>/dev/null; then
        ok "$1: '$2' does not compile (it does without $1)"
    else
        fail "$1: '$2' does not compile even without $1 (the check is broken)"
    fi
}
nodecl BP_NO_IO "bp_mesh m; (void)bp_parse_obj(\"v 0 0 0\", 7, &m, 0, 0)"
nodecl BP_NO_IO "(void)bp_mesh_format(\"a.obj\")"
nodecl BP_NO_VISIBILITY "bp_mesh m = {0}; double v; (void)bp_visibility(&m, 0, &v, 0)"

printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\n' >"$TMP/impl.c"
if $CC -std=c99 -DBP_NO_IO -I"$ROOT" -E "$TMP/impl.c" 2>/dev/null | grep -q 'stdio\.h'; then
    fail "BP_NO_IO includes <stdio.h>"
elif $CC -std=c99 -I"$ROOT" -E "$TMP/impl.c" 2>/dev/null | grep -q 'stdio\.h'; then
    ok "BP_NO_IO never includes <stdio.h> (the full build does)"
else
    fail "the full build does not include <stdio.h> either (the check is broken)"
fi

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
