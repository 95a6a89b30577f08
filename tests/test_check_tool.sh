#!/usr/bin/env bash
# test_check_tool.sh - `bijparam --check IN.obj`: the exact check of a file's
# own vt charts, nothing changed.
#
#   - a valid parameterization (cow_param_withSUV.obj) passes: exit 0;
#   - a copy of it with ONE vt moved far away fails: exit 1, and the first
#     bad element printed names that vt (as the file numbers it, from 1);
#   - spot.obj (whose vt has a mirrored chart) fails with exit 1, and the
#     tool's own parameterization of spot passes;
#   - two charts side by side pass, one on top of the other fails;
#   - usage errors exit 2; the input file is not modified;
#   - the independent checker tests/uvcheck.py agrees on all three files
#     (exit status, and spot's number of flipped triangles).
#
# Needs build/bijparam (make build/bijparam).  Prints ok/FAIL lines and
# "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TOOL=${BIJPARAM:-$ROOT/build/bijparam}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_checktool.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_check_tool.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_check_tool.sh: $*"; failed=$((failed + 1)); }

if [ ! -x "$TOOL" ]; then fail "$TOOL is missing (make build/bijparam)"; echo "BPTEST $passed $failed"; exit 1; fi
COW=$ROOT/tests/data/cow_param_withSUV.obj
SPOT=$ROOT/tests/data/spot.obj
for f in "$COW" "$SPOT"; do [ -f "$f" ] || fail "$f is missing"; done

sum_before=$(cksum <"$COW")
"$TOOL" --check "$COW" >"$TMP/cow.out" 2>&1; rc=$?
if [ $rc -eq 0 ] && grep -q '^result: bijective' "$TMP/cow.out"; then ok "cow_param_withSUV.obj: bijective, exit 0"
else fail "cow_param_withSUV.obj: exit $rc"; sed 's/^/     | /' "$TMP/cow.out" | head; fi
[ "$(cksum <"$COW")" = "$sum_before" ] && ok "--check leaves the input unchanged" || fail "--check changed the input"

# the broken copy: the 100th vt moved to (50, 50)
awk 'BEGIN { n = 0 } /^vt / { n++; if (n == 100) { print "vt 50 50"; next } } { print }' "$COW" >"$TMP/broken.obj"
"$TOOL" --check "$TMP/broken.obj" >"$TMP/broken.out" 2>&1; rc=$?
if [ $rc -eq 1 ] && grep -q '^result: NOT bijective' "$TMP/broken.out"; then ok "one vt moved: NOT bijective, exit 1"
else fail "one vt moved: exit $rc"; sed 's/^/     | /' "$TMP/broken.out" | head; fi
if grep -E '^    ' "$TMP/broken.out" | head -n 1 | grep -Eq 'vt ([0-9]+ )*100[ )]'; then
    ok "the first bad element printed names vt 100: $(grep -E '^    ' "$TMP/broken.out" | head -n 1)"
else
    fail "the first bad element does not name vt 100"; sed 's/^/     | /' "$TMP/broken.out" | head
fi
if grep -E '^    ' "$TMP/broken.out" | head -n 1 | grep -Eq 'line [0-9]+|vertex [0-9]+'; then
    ok "... with file line or vertex numbers"
else fail "... without file numbers"; fi

"$TOOL" --check "$SPOT" >"$TMP/spot.out" 2>&1; rc=$?
flips=$(sed -n 's/.* \([0-9][0-9]*\) flipped,.*/\1/p' "$TMP/spot.out" | awk '{ s += $1 } END { print s + 0 }')
if [ $rc -eq 1 ] && [ "$flips" -gt 0 ]; then ok "spot.obj: NOT bijective (exit 1), $flips flipped triangles over its charts"
else fail "spot.obj: exit $rc, $flips flipped"; sed 's/^/     | /' "$TMP/spot.out" | head; fi

# two one-triangle charts (separate vt): apart, then one on top of the other
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 2 0\nvt 3 0\nvt 2 1\nf 1/1 2/2 3/3\nf 4/4 5/5 6/6\n' >"$TMP/two.obj"
"$TOOL" --check "$TMP/two.obj" >"$TMP/two.out" 2>&1; rc=$?
if [ $rc -eq 0 ] && grep -q 'no two charts overlap' "$TMP/two.out"; then ok "two charts side by side: exit 0"
else fail "two charts side by side: exit $rc"; sed 's/^/     | /' "$TMP/two.out"; fi
sed 's/^vt 2 0$/vt 0.2 0.2/; s/^vt 3 0$/vt 0.4 0.2/; s/^vt 2 1$/vt 0.2 0.4/' "$TMP/two.obj" >"$TMP/over.obj"
"$TOOL" --check "$TMP/over.obj" >"$TMP/over.out" 2>&1; rc=$?
if [ $rc -eq 1 ] && grep -q 'charts overlap' "$TMP/over.out" && grep -Eq 'vertex [456] \(vt [456]\)' "$TMP/over.out"; then
    ok "a chart on top of another: exit 1, naming a vertex of the inner one: $(grep -E '^    ' "$TMP/over.out" | head -n 1)"
else fail "a chart on top of another: exit $rc"; sed 's/^/     | /' "$TMP/over.out"; fi

# the tool's own output for spot (its charts re-parameterized) passes --check
if "$TOOL" --threads 1 "$SPOT" -o "$TMP/spot_new.obj" >/dev/null 2>&1; then
    "$TOOL" --check "$TMP/spot_new.obj" >"$TMP/new.out" 2>&1; rc=$?
    if [ $rc -eq 0 ] && grep -q 'no two charts overlap' "$TMP/new.out"; then ok "spot parameterized by bijparam: --check passes (every chart, no overlap)"
    else fail "spot parameterized by bijparam: --check exit $rc"; sed 's/^/     | /' "$TMP/new.out" | grep -v ': bijective' | head; fi
else
    fail "bijparam could not parameterize spot.obj"
fi

"$TOOL" --check >/dev/null 2>&1; rc=$?
[ $rc -eq 2 ] && ok "--check without a file: usage error (exit 2)" || fail "--check without a file: exit $rc"
"$TOOL" --check --demo >/dev/null 2>&1; rc=$?
[ $rc -eq 2 ] && ok "--check --demo: usage error (exit 2)" || fail "--check --demo: exit $rc"

UV=$ROOT/tests/uvcheck.py
for f in "$COW" "$TMP/broken.obj" "$SPOT"; do
    python3 "$UV" --json "$f" >"$TMP/uv.out" 2>&1; urc=$?
    "$TOOL" --check "$f" >/dev/null 2>&1; brc=$?
    if [ "$urc" -eq "$brc" ]; then ok "$(basename "$f"): uvcheck.py and --check agree (exit $brc)"
    else fail "$(basename "$f"): uvcheck.py exit $urc, --check exit $brc"; head -c 600 "$TMP/uv.out" | sed 's/^/     | /'; fi
    if [ "$(basename "$f")" = spot.obj ]; then
        uflips=$(python3 -c 'import json, sys; print(json.load(sys.stdin)["counts"].get("flipped_triangles", 0))' <"$TMP/uv.out")
        [ "$uflips" = "$flips" ] && ok "spot.obj: the same number of flipped triangles as uvcheck.py ($flips)" \
            || fail "spot.obj: $flips flipped, uvcheck.py says $uflips"
    fi
done
echo "BPTEST $passed $failed"
