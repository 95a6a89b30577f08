#!/usr/bin/env bash
# test_build_options.sh - the library built without some of its parts
# (make test; every combination of the macros is built by
# tests/test_build_matrix.sh in make check).
#
#   - tests/build_options.c built with all four opt-out macros (BP_NO_NEWTON
#     BP_NO_ATLAS BP_NO_VISIBILITY BP_NO_IO; gcc -std=c99 -Og, warnings as
#     errors) and run on tests/data/camel_b.obj: camel_b flattened with the
#     defaults, every chart through bp_check and the written map through
#     tests/uvcheck.py (an independent exact checker); every option that
#     needs a left-out part fails with BP_ERR_UNSUPPORTED naming the macro;
#     the conformal start by name on tests/data/bishop_part_f1000.obj;
#   - the README's example built as the core library (BP_NO_NEWTON
#     BP_NO_ATLAS BP_NO_VISIBILITY, -O2) flattens camel_b, and
#     tests/uvcheck.py finds the written file bijective; built with
#     BP_SMALL=0 at -Og it writes the same bytes;
#   - a left-out part's public functions are not declared (a call does not
#     compile), and BP_NO_IO never includes <stdio.h>.
# Prints one "ok"/"FAIL" line per check and a final "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CC=${CC:-gcc}
PY=${PYTHON:-python3}
WARN="-Wall -Wextra -pedantic -Werror"
ALL="BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY BP_NO_IO"
CORE="BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_options.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_build_options.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_build_options.sh: $*"; failed=$((failed + 1)); }
defs() { for m in "$@"; do printf ' -D%s' "$m"; done; }

# tests/build_options.c with every part left out
if $CC -std=c99 -Og $WARN $(defs $ALL) -I"$ROOT" -I"$ROOT/tests" "$ROOT/tests/build_options.c" -o "$TMP/options" -lm \
        2>"$TMP/cc.log"; then
    ok "$ALL: compiles warning-free"
    if "$TMP/options" "$ROOT/tests/data/camel_b.obj" "$TMP/out.obj" "$ROOT/tests/data/bishop_part_f1000.obj" \
            >"$TMP/run.log" 2>&1; then
        ok "$ALL: $(tail -1 "$TMP/run.log") (camel_b flattened, checked, refusals, the conformal start)"
    else
        fail "$ALL: the program failed"; cat "$TMP/run.log"
    fi
    if $PY "$ROOT/tests/uvcheck.py" "$TMP/out.obj" >"$TMP/uv.log" 2>&1; then
        ok "$ALL: tests/uvcheck.py finds camel_b's map bijective"
    else
        fail "$ALL: tests/uvcheck.py rejects camel_b's map"; cat "$TMP/uv.log"
    fi
else
    fail "$ALL: does not compile"; cat "$TMP/cc.log"
fi

# the README example as the core library
awk '/^```c$/ { if (!done) { on = 1; next } } /^```$/ { if (on) { on = 0; done = 1 } } on' "$ROOT/README.md" >"$TMP/example.c"
if $CC -std=c99 -O2 $WARN $(defs $CORE) -I"$ROOT" "$TMP/example.c" -o "$TMP/example" -lm 2>"$TMP/ex.log"; then
    ok "the README example compiles warning-free with $CORE at -O2"
    if "$TMP/example" "$ROOT/tests/data/camel_b.obj" "$TMP/example.obj" >"$TMP/exrun.log" 2>&1 &&
       $PY "$ROOT/tests/uvcheck.py" "$TMP/example.obj" >"$TMP/exuv.log" 2>&1; then
        ok "the README example built with $CORE flattens camel_b bijectively ($(tail -1 "$TMP/exuv.log"))"
    else
        fail "the README example built with $CORE on camel_b"; cat "$TMP/exrun.log" "$TMP/exuv.log" 2>/dev/null
    fi
else
    fail "the README example does not compile with $CORE"; cat "$TMP/ex.log"
fi
# The core compiles for size by default (BP_SMALL, GCC: -Os with the inner
# loops at -O2); without it, at -Og, the same file must come out.
if $CC -std=c99 -Og $WARN $(defs $CORE BP_SMALL=0) -I"$ROOT" "$TMP/example.c" -o "$TMP/example0" -lm 2>"$TMP/ex0.log" &&
   "$TMP/example0" "$ROOT/tests/data/camel_b.obj" "$TMP/example0.obj" >"$TMP/exrun0.log" 2>&1; then
    if cmp -s "$TMP/example.obj" "$TMP/example0.obj"; then
        ok "$CORE: BP_SMALL=0 at -Og writes camel_b's bytes of the default -O2 build"
    else
        fail "$CORE: BP_SMALL=0 at -Og writes other bytes than the default -O2 build"
    fi
else
    fail "$CORE BP_SMALL=0: does not build or run"; cat "$TMP/ex0.log" "$TMP/exrun0.log" 2>/dev/null
fi

# a left-out part's functions are not declared: calls.c holds every call,
# one a line, and compiles without the macros; with a macro, the compiler
# reports an error on the line of each of that macro's calls (one compile
# per macro: gcc goes on after an error, and each call is a statement of
# its own, so one call's error cannot stand in for another's)
calls=("BP_NO_IO|bp_mesh m; (void)bp_parse_obj(\"v 0 0 0\", 7, &m, 0, 0)"
       "BP_NO_IO|(void)bp_mesh_format(\"a.obj\")"
       "BP_NO_VISIBILITY|bp_mesh m = {0}; double v; (void)bp_visibility(&m, 0, &v, 0)"
       "BP_NO_ATLAS|bp_atlas at = {0}; bp_mesh m = {0}; (void)bp_atlas_segment(&at, &m, 0, 0)"
       "BP_NO_ATLAS|bp_atlas at = {0}; bp_mesh m = {0}; (void)bp_atlas_refine(&at, &m, 0, 0)")
{
    printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\nint main(void)\n{\n'
    for c in "${calls[@]}"; do printf '    { %s; }\n' "${c#*|}"; done
    printf '    return 0;\n}\n'
} >"$TMP/calls.c"
if $CC -std=c99 $WARN -I"$ROOT" -fsyntax-only "$TMP/calls.c" 2>"$TMP/calls.log"; then
    for macro in BP_NO_IO BP_NO_VISIBILITY BP_NO_ATLAS; do
        $CC -std=c99 $WARN -D"$macro" -I"$ROOT" -fsyntax-only "$TMP/calls.c" >"$TMP/$macro.log" 2>&1
        line=$(grep -n -m1 '^    { ' "$TMP/calls.c" | cut -d: -f1)   # the first call's
        for c in "${calls[@]}"; do
            if [ "${c%%|*}" = "$macro" ]; then
                if grep -q "calls\.c:$line:[0-9]*: error" "$TMP/$macro.log"; then
                    ok "$macro: '${c#*|}' does not compile (it does without $macro)"
                else
                    fail "$macro: '${c#*|}' still compiles"; cat "$TMP/$macro.log"
                fi
            fi
            line=$((line + 1))
        done
    done
else
    fail "the calls do not compile even without the macros (the check is broken)"; cat "$TMP/calls.log"
fi

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
