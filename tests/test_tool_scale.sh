#!/usr/bin/env bash
# test_tool_scale.sh - the tool at any finite scale.
#
# camel_b without its vt (3,576 faces, one disk) is written at its own size
# and scaled by 1e100, 1e200, 1e300, 1e-100, 1e-200 and 1e-300.  Each copy
# must be flattened (exit 0), its output must pass the tool's exact check
# (`--check`: every chart bijective, none overlapping), and its map divided
# by the factor must be the map at scale 1: the same texture vertices, none
# farther than 1e-7 of the map's diameter from its place at scale 1 (the
# copies differ from the original by the rounding of the scaled
# coordinates, and the map by the rounding that carries through the solve;
# the energies agree to 1e-9).  With --atlas --segment off the map is in
# [0,1]^2 at every scale and must agree the same way without dividing.
# With --atlas alone the segmentation's choices (seeds at the most
# deviating normal, fronts meeting between near-equal costs) may fall
# differently on coordinates rounded differently, so there only the exact
# check is asked for.  A scale the arithmetic cannot take (a rescale that
# is not exact) would be a failed chart, exit 1: that too fails here.
#
# Needs build/bijparam.  Prints ok/FAIL lines and "BPTEST <passed> <failed>".
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TOOL=${BIJPARAM:-$ROOT/build/bijparam}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_scale.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_tool_scale.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_tool_scale.sh: $*"; failed=$((failed + 1)); }
if [ ! -x "$TOOL" ]; then fail "$TOOL is missing (make build/bijparam)"; echo "BPTEST $passed $failed"; exit 1; fi

# the scaled copies: python3 multiplies each coordinate by 10.0**e (one rounding)
python3 - "$ROOT/tests/data/camel_b.obj" "$TMP" <<'PY' || fail "writing the scaled copies"
import sys
src, out = sys.argv[1], sys.argv[2]
lines = open(src).read().splitlines()
for e in (0, 100, 200, 300, -100, -200, -300):
    with open("%s/camel_%d.obj" % (out, e), "w") as fh:
        for l in lines:
            if l.startswith("v "):
                fh.write("v %r %r %r\n" % tuple(float(t) * 10.0 ** e for t in l.split()[1:4]))
            elif l.startswith("f "):
                fh.write("f " + " ".join(t.split("/")[0] for t in l.split()[1:]) + "\n")
PY

compare() {   # compare REF OUT E DIVIDE JSON_REF JSON_OUT: the maps agree after dividing by 10^E
    python3 - "$@" <<'PY'
import json, sys
ref, out, e, divide = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1"
def vts(p):
    return [tuple(float(x) for x in l.split()[1:3]) for l in open(p) if l.startswith("vt ")]
a, b = vts(ref), vts(out)
if not a or len(a) != len(b):
    print("vt counts differ: %d and %d" % (len(a), len(b))); sys.exit(1)
f = 10.0 ** e if divide else 1.0
xs, ys = [p[0] for p in a], [p[1] for p in a]
diam = max(max(xs) - min(xs), max(ys) - min(ys))
d = max(max(abs(q[0] / f - p[0]), abs(q[1] / f - p[1])) for p, q in zip(a, b)) / diam
ea = json.load(open(sys.argv[5]))["per_chart"][0]["energy_end"]
eb = json.load(open(sys.argv[6]))["per_chart"][0]["energy_end"]
print("largest difference %.2g of the diameter, energies %.15g and %.15g" % (d, ea, eb))
sys.exit(0 if d < 1e-7 and abs(ea - eb) <= 1e-9 * ea else 1)
PY
}

for mode in plain atlas segmented; do
    args="--threads 2"
    [ $mode = atlas ] && args="$args --atlas 1024 --padding 4 --segment off"
    [ $mode = segmented ] && args="$args --atlas 1024 --padding 4"
    "$TOOL" "$TMP/camel_0.obj" $args -q --json -o "$TMP/out_0_$mode.obj" > "$TMP/out_0_$mode.json" \
        || fail "$mode: camel_b at scale 1 is flattened"
    for e in 100 200 300 -100 -200 -300; do
        "$TOOL" "$TMP/camel_$e.obj" $args -q --json -o "$TMP/out_${e}_$mode.obj" > "$TMP/out_${e}_$mode.json" \
            2> "$TMP/err"; rc=$?
        if [ $rc -ne 0 ]; then fail "$mode: camel_b x 1e$e: exit $rc: $(head -c 300 "$TMP/err")"; continue; fi
        "$TOOL" --check "$TMP/out_${e}_$mode.obj" > "$TMP/check" 2>&1 \
            && ok "$mode: camel_b x 1e$e: flattened, and its output is bijective by the exact check" \
            || fail "$mode: camel_b x 1e$e: the exact check of the output: $(tail -1 "$TMP/check")"
        [ $mode = segmented ] && continue
        divide=1
        [ $mode = atlas ] && divide=0
        msg=$(compare "$TMP/out_0_$mode.obj" "$TMP/out_${e}_$mode.obj" "$e" $divide \
                      "$TMP/out_0_$mode.json" "$TMP/out_${e}_$mode.json")
        [ $? -eq 0 ] && ok "$mode: camel_b x 1e$e: the map at scale 1 ($msg)" \
                     || fail "$mode: camel_b x 1e$e: not the map at scale 1 ($msg)"
    done
done
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
