#!/usr/bin/env bash
# test_pins_tool.sh - the tool's --pin FILE and --init input.
#
#   - bishop: 5 vertices pinned (lines 'vertex u v', targets the unpinned
#     result's vt shifted by (0.25, -0.5)): exit 0, and in the written OBJ
#     every face corner of a pinned vertex has a vt EXACTLY at its target
#     (awk compares the parsed doubles), --json reports "pins":5 and
#     "in_place":1; the independent checker (tests/uvcheck.py) agrees the file is
#     bijective, with bishop's vertices and faces;
#   - pin files with errors name the file and line: a malformed line 3, a
#     vertex outside the mesh (exit 1, nothing written); infeasible pins (two
#     at one point) name both vertices, exit 1, and the chart is written
#     without vt like any failed chart;
#   - --init input on the cow: "init_used":1 and the result bijective; an
#     unknown --init value is a usage error (exit 2);
#   - "start_map" in --json: bishop starts conformal by default and
#     mean-value with --init mvc; the cow's conformal map folds, so even
#     --init conformal gives "mvc".
#
# Needs build/bijparam.  Prints ok/FAIL lines and "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TOOL=${BIJPARAM:-$ROOT/build/bijparam}
UVCHECK=$ROOT/tests/uvcheck.py
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_pinstool.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_pins_tool.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_pins_tool.sh: $*"; failed=$((failed + 1)); }
finish() { echo "BPTEST $passed $failed"; [ "$failed" -eq 0 ]; exit $?; }

if [ ! -x "$TOOL" ]; then fail "$TOOL is missing (make build/bijparam)"; finish; fi
BISHOP=$ROOT/tests/data/bishop_part_f1000.obj
COW=$ROOT/tests/data/cow_param_withSUV.obj
for f in "$BISHOP" "$COW"; do [ -f "$f" ] || { fail "$f is missing"; finish; }; done

# the unpinned result, and pins from it: the vt of vertices 1, 50, 100, 200, 300 shifted
"$TOOL" -q "$BISHOP" -o "$TMP/free.obj" || fail "unpinned bishop"
awk '/^vt / { n++; u[n] = $2; v[n] = $3 }
     /^f / { for (i = 2; i <= NF; i++) { split($i, a, "/"); vt[a[1]] = a[2] } }
     END { printf "# pins from the free result\n\n";
           split("1 50 100 200 300", P, " ");
           for (k = 1; k <= 5; k++) printf "%d %.17g %.17g\n", P[k], u[vt[P[k]]] + 0.25, v[vt[P[k]]] - 0.5 }' \
    "$TMP/free.obj" >"$TMP/pins.txt"
"$TOOL" "$BISHOP" --pin "$TMP/pins.txt" --json -o "$TMP/pinned.obj" >"$TMP/pinned.json" 2>"$TMP/pinned.err"; rc=$?
if [ $rc -eq 0 ]; then ok "bishop with 5 pins: exit 0"; else fail "bishop with 5 pins: exit $rc"; sed 's/^/     | /' "$TMP/pinned.err"; fi
grep -q '"pins":5' "$TMP/pinned.json" && grep -q '"in_place":1' "$TMP/pinned.json" &&
    ok "--json reports \"pins\":5 and \"in_place\":1" || fail "--json lacks pins/in_place: $(head -c 300 "$TMP/pinned.json")"
res=$(awk 'FNR == NR { if ($1 !~ /^#/ && NF >= 3) { tu[$1] = $2 + 0; tv[$1] = $3 + 0 } next }
     /^vt / { n++; u[n] = $2 + 0; v[n] = $3 + 0 }
     /^f / { for (i = 2; i <= NF; i++) { split($i, a, "/"); if (a[1] in tu) { seen++; if (u[a[2]] == tu[a[1]] && v[a[2]] == tv[a[1]]) same++ } } }
     END { printf "%d %d", same, seen }' "$TMP/pins.txt" "$TMP/pinned.obj")
set -- $res
if [ "${2:-0}" -gt 0 ] && [ "$1" = "$2" ]; then ok "every corner of a pinned vertex has its vt exactly at the target ($1 of $2)"
else fail "pinned corners at their targets: $1 of ${2:-0}"; fi
python3 "$UVCHECK" "$TMP/pinned.obj" "$BISHOP" >"$TMP/uvc.out" 2>&1 && ok "uvcheck: the pinned result is bijective" ||
    { fail "uvcheck rejects the pinned result"; sed 's/^/     | /' "$TMP/uvc.out" | head; }

# errors in the pin file name the file and the line
printf '# bad\n1 0 0\n7 oops 1\n' >"$TMP/bad.txt"
"$TOOL" "$BISHOP" --pin "$TMP/bad.txt" -o "$TMP/bad.obj" 2>"$TMP/bad.err"; rc=$?
if [ $rc -eq 1 ] && grep -q "bad.txt:3:" "$TMP/bad.err" && [ ! -e "$TMP/bad.obj" ]; then ok "malformed line 3 named: $(cat "$TMP/bad.err")"
else fail "malformed pin line: exit $rc: $(cat "$TMP/bad.err")"; fi
printf '1 0 0\n\n999999 1 1\n' >"$TMP/range.txt"
"$TOOL" "$BISHOP" --pin "$TMP/range.txt" -o "$TMP/range.obj" 2>"$TMP/range.err"; rc=$?
if [ $rc -eq 1 ] && grep -q "range.txt:3:" "$TMP/range.err"; then ok "vertex outside the mesh, line 3 named: $(cat "$TMP/range.err")"
else fail "vertex outside the mesh: exit $rc: $(cat "$TMP/range.err")"; fi
printf '10 0.5 0.5\n20 0.5 0.5\n' >"$TMP/same.txt"
"$TOOL" "$BISHOP" --pin "$TMP/same.txt" -o "$TMP/same.obj" 2>"$TMP/same.err"; rc=$?
if [ $rc -eq 1 ] && grep -Eq "vertices 10 and 20|vertices 20 and 10" "$TMP/same.err" &&
   { [ ! -e "$TMP/same.obj" ] || ! grep -q '^vt ' "$TMP/same.obj"; }; then
    ok "two pins at one point: exit 1, both vertices named, the chart without vt (as any failed chart)"
else fail "two pins at one point: exit $rc: $(cat "$TMP/same.err")"; fi

# --init input
"$TOOL" "$COW" --init input --max-iters 200 --json -o "$TMP/cow.obj" >"$TMP/cow.json" 2>"$TMP/cow.err"; rc=$?
if [ $rc -eq 0 ] && grep -q '"init_used":1' "$TMP/cow.json"; then ok "--init input on the cow: its own vt used (\"init_used\":1)"
else fail "--init input on the cow: exit $rc $(cat "$TMP/cow.err")"; fi
python3 "$UVCHECK" "$TMP/cow.obj" "$COW" >"$TMP/uvc.out" 2>&1 && ok "uvcheck: the cow from its own vt is bijective" ||
    { fail "uvcheck rejects the cow from its own vt"; sed 's/^/     | /' "$TMP/uvc.out" | head; }
# --init conformal / mvc and "start_map" (bishop's conformal map is bijective, the cow's folds)
"$TOOL" "$BISHOP" --json -q -o "$TMP/b_auto.obj" >"$TMP/b_auto.json" 2>&1; rc1=$?
"$TOOL" "$BISHOP" --init mvc --json -q -o "$TMP/b_mvc.obj" >"$TMP/b_mvc.json" 2>&1; rc2=$?
"$TOOL" "$COW" --init conformal --max-iters 20 --json -q -o "$TMP/c_conf.obj" >"$TMP/c_conf.json" 2>&1; rc3=$?
if [ $rc1 -eq 0 ] && [ $rc2 -eq 0 ] && [ $rc3 -eq 0 ] && grep -q '"start_map":"conformal"' "$TMP/b_auto.json" &&
   grep -q '"start_map":"mvc"' "$TMP/b_mvc.json" && grep -q '"start_map":"mvc"' "$TMP/c_conf.json"; then
    ok "\"start_map\": bishop conformal by default, mvc when asked; the cow's conformal map folds: mvc"
else fail "start_map: exits $rc1 $rc2 $rc3: $(grep -o '"start_map":[^,]*' "$TMP/b_auto.json" "$TMP/b_mvc.json" "$TMP/c_conf.json" | tr '\n' ' ')"; fi
"$TOOL" "$COW" --init bogus -o "$TMP/x.obj" 2>"$TMP/usage.err"; rc=$?
[ $rc -eq 2 ] && grep -q "input" "$TMP/usage.err" && ok "--init bogus: usage error naming the choices" ||
    fail "--init bogus: exit $rc $(cat "$TMP/usage.err")"
finish
