#!/usr/bin/env bash
# test_uvcheck.sh - the independent checker tests/uvcheck.py says no to each
# kind of broken map built here by hand, and yes to the valid ones beside
# them (the maps are small, their verdicts known from their construction):
#   - a square of two triangles: bijective; one triangle flipped; one of
#     zero area; a NaN coordinate;
#   - two charts apart (bijective), touching at one vertex, one vertex of
#     one exactly on an edge of the other, one inside the other (no edges
#     meet: only the containment test sees it), overlapping;
#   - a ring of triangles around a square hole, a third chart inside the
#     hole: bijective; the same chart straddling the hole's edge: not;
#   - a strip wound 1.2 times round a circle: every triangle positive, its
#     boundary crosses itself; a fan turning twice round an inner vertex;
#   - with a reference mesh: the same faces pass, a face with its corners
#     reversed fails unless --allow-reorient, a moved vertex fails;
#   - a corner without vt: unreadable (exit 2).
# Prints "BPTEST <passed> <failed>".  Needs python3.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
UV=$ROOT/tests/uvcheck.py
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_uvcheck.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0
ok()   { echo "ok   test_uvcheck.sh: $*"; passed=$((passed + 1)); }
fail() { echo "FAIL test_uvcheck.sh: $*"; failed=$((failed + 1)); }

# expect NAME EXIT [KIND]: run the checker on $TMP/NAME.obj (and $REF when
# set), want exit status EXIT and, when KIND is given, a count of KIND
expect() {
    local name=$1 want=$2 kind=${3:-} rc
    python3 "$UV" --json $OPTS "$TMP/$name.obj" ${REF:+"$REF"} >"$TMP/$name.json" 2>"$TMP/$name.err"; rc=$?
    if [ "$rc" -ne "$want" ]; then
        fail "$name: exit $rc, want $want: $(head -c 400 "$TMP/$name.json") $(head -c 200 "$TMP/$name.err")"; return
    fi
    if [ -n "$kind" ] && ! grep -q "\"$kind\": [1-9]" "$TMP/$name.json"; then
        fail "$name: exit $rc but no $kind: $(head -c 400 "$TMP/$name.json")"; return
    fi
    ok "$name: exit $rc${kind:+, $kind $(grep -o "\"$kind\": [0-9]*" "$TMP/$name.json" | head -n 1 | cut -d' ' -f2)}"
}
OPTS=
REF=

# square (0,0)-(1,1), two triangles; v = vt
sq='v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1'
printf '%s\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n' "$sq" >"$TMP/square.obj"
expect square 0
printf '%s\nf 1/1 2/2 3/3\nf 1/1 4/4 3/3\n' "$sq" >"$TMP/flipped.obj"
expect flipped 1 flipped_triangles
printf '%s\nvt 2 2\nf 1/1 2/2 3/3\nf 1/1 3/3 4/5\n' "$sq" >"$TMP/zero.obj"     # (0,0) (1,1) (2,2)
expect zero 1 degenerate_triangles
printf '%s\nvt nan 0.5\nf 1/1 2/2 3/3\nf 1/1 3/3 4/5\n' "$sq" >"$TMP/nan.obj"
expect nan 1 nonfinite_triangles

# two one-triangle charts: B = (x, y) + {(0,0), (1,0), (0,1)}
two() {   # two NAME X Y [SCALE]
    printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\n' >"$TMP/$1.obj"
    awk -v x="$2" -v y="$3" -v s="${4:-1}" 'BEGIN { printf "vt 0 0\nvt 1 0\nvt 0 1\nvt %.17g %.17g\nvt %.17g %.17g\nvt %.17g %.17g\n",
        x, y, x + s, y, x, y + s }' >>"$TMP/$1.obj"
    printf 'f 1/1 2/2 3/3\nf 4/4 5/5 6/6\n' >>"$TMP/$1.obj"
}
two apart 2 0
expect apart 0
two vertex_touch 1 0                    # B's first corner on A's corner (1,0)
expect vertex_touch 1 chart_overlaps
two edge_touch 0.5 0.5                  # B's first corner on A's edge x + y = 1
expect edge_touch 1 chart_overlaps
two nested 0.125 0.125 0.25             # B inside A, no edges meet
expect nested 1 chart_overlaps
two overlap 0.5 0.25
expect overlap 1 chart_overlaps

# a ring: outer square (0..3), inner square hole (1..2), 8 triangles
ring='v 0 0 0
v 3 0 0
v 3 3 0
v 0 3 0
v 1 1 0
v 2 1 0
v 2 2 0
v 1 2 0
vt 0 0
vt 3 0
vt 3 3
vt 0 3
vt 1 1
vt 2 1
vt 2 2
vt 1 2
f 1/1 2/2 6/6
f 1/1 6/6 5/5
f 2/2 3/3 7/7
f 2/2 7/7 6/6
f 3/3 4/4 8/8
f 3/3 8/8 7/7
f 4/4 1/1 5/5
f 4/4 5/5 8/8'
printf '%s\n' "$ring" >"$TMP/ring.obj"
expect ring 0
printf '%s\nv 9 9 9\nv 9 8 9\nv 8 9 9\nvt 1.25 1.25\nvt 1.75 1.25\nvt 1.25 1.75\nf 9/9 10/10 11/11\n' "$ring" >"$TMP/in_hole.obj"
expect in_hole 0
printf '%s\nv 9 9 9\nv 9 8 9\nv 8 9 9\nvt 1.25 1.25\nvt 2.5 1.25\nvt 1.25 1.75\nf 9/9 10/10 11/11\n' "$ring" >"$TMP/straddle.obj"
expect straddle 1 chart_overlaps

# a strip of 24 quads wound 1.2 times round a circle (radii 1 and 2)
python3 - "$TMP/spiral.obj" <<'EOF'
import math, sys
n = 24
with open(sys.argv[1], "w") as f:
    for k in range(n + 1):
        t = 2 * math.pi * 1.2 * k / n
        for r in (1, 2):
            f.write("v %d %d 0\nvt %.17g %.17g\n" % (k, r, r * math.cos(t), r * math.sin(t)))
    for k in range(n):
        a, b, c, d = 2 * k + 1, 2 * k + 2, 2 * k + 4, 2 * k + 3   # inner k, outer k, outer k+1, inner k+1
        f.write("f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n" % (a, a, b, b, c, c, a, a, c, c, d, d))
EOF
expect spiral 1 boundary_intersections
if grep -q flipped "$TMP/spiral.json"; then fail "spiral: flipped triangles reported, the strip has none"; else ok "spiral: no flipped triangle"; fi
# a fan of 6 triangles of 120 degrees round vertex 1: it turns twice
python3 - "$TMP/twice.obj" <<'EOF'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("v 0 0 0\nvt 0 0\n")
    for k in range(6):
        t, r = 2 * math.pi * k / 3, 1 + 0.1 * k
        f.write("v %d 1 0\nvt %.17g %.17g\n" % (k + 1, r * math.cos(t), r * math.sin(t)))
    for k in range(6):
        a, b = k + 2, (k + 1) % 6 + 2
        f.write("f 1/1 %d/%d %d/%d\n" % (a, a, b, b))
EOF
expect twice 1 winding_vertices

# against a reference: the square's own faces; reversed corners; a moved vertex
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 2 3 1\nf 1 3 4\n' >"$TMP/ref.obj"
REF=$TMP/ref.obj
expect square 0
sed 's/^f 2 3 1$/f 3 2 1/' "$TMP/ref.obj" >"$TMP/ref_rev.obj"
REF=$TMP/ref_rev.obj
expect square 1 reversed_faces
OPTS=--allow-reorient
expect square 0
OPTS=
sed 's/^v 1 1 0$/v 1 1 1e-300/' "$TMP/ref.obj" >"$TMP/ref_moved.obj"
REF=$TMP/ref_moved.obj
expect square 1 reference_vertices
REF=

printf '%s\nf 1/1 2/2 3\n' "$sq" >"$TMP/no_vt.obj"
expect no_vt 2
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
