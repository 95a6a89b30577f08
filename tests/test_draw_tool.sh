#!/usr/bin/env bash
# test_draw_tool.sh - the tool's atlas pictures (examples/bp_draw.h).
#
# - --svg-color chart on spot packed into an atlas (its 13 vt charts,
#   --segment off: not split further by >>segment): one
#   even-odd path per chart, 13 different colours, the legend says
#   "colour: chart (13 charts"; the atlas square is drawn.
# - A packed atlas's legend reports the energy at one common scale: its
#   mean symmetric Dirichlet energy equals the one computed here, by a
#   separate formula (||J||^2 (1 + 1/det^2) per triangle, area-weighted,
#   the whole UV layout scaled so its area is the 3D area) from the OBJ the
#   tool wrote - not the energy of the unit square's scale.
# - An unknown --svg-color is a usage error that lists "chart".
# Prints "BPTEST <passed> <failed>" last (tests/run_all.sh).  Run from the
# repository root.
set -u
tool=build/bijparam
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_draw_tool.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_draw_tool.sh: $2"; fi
}
if [ ! -x "$tool" ] || [ ! -f tests/data/spot.obj ]; then
    check 1 "$tool and tests/data/spot.obj exist (make build/bijparam)"
    echo "BPTEST $passed $failed"
    exit 1
fi
d=$(mktemp -d /tmp/bptest_draw_XXXXXX)
trap 'rm -rf "$d"' EXIT

"$tool" --threads 1 tests/data/spot.obj --atlas 1024 --padding 4 --segment off --svg "$d/a.svg" --svg-color chart \
    -o "$d/out.obj" >"$d/stdout" 2>"$d/stderr"
rc=$?
check $rc "spot --atlas 1024 --svg-color chart runs (exit $rc: $(head -c 300 "$d/stderr"))"
n=$(grep -c 'fill-rule="evenodd"' "$d/a.svg")
check $(( n != 13 )) "one even-odd path per chart: $n of 13"
colours=$(grep -o '<path fill="#[0-9a-f]*" fill-rule="evenodd"' "$d/a.svg" | sort -u | wc -l)
check $(( colours != 13 )) "13 different chart colours: $colours"
grep -q 'colour: chart (13 charts' "$d/a.svg"
check $? "legend: colour: chart (13 charts ...)"
grep -q 'fill="#f4f4f4" stroke="#999"' "$d/a.svg"
check $? "the atlas square is drawn"

legend=$(sed -n 's/.*symmetric Dirichlet energy: mean \([0-9.e+-]*\),.*/\1/p' "$d/a.svg")
python3 - "$d/out.obj" "$legend" <<'PY'
import math, sys
v, vt, tris = [], [], []
for line in open(sys.argv[1]):
    w = line.split()
    if not w: continue
    if w[0] == "v": v.append([float(x) for x in w[1:4]])
    elif w[0] == "vt": vt.append([float(x) for x in w[1:3]])
    elif w[0] == "f":
        c = [(int(x.split("/")[0]) - 1, int(x.split("/")[1]) - 1) for x in w[1:]]
        tris += [(c[0], c[k], c[k + 1]) for k in range(1, len(c) - 1)]
rows, a3, auv = [], 0.0, 0.0
for (p0, q0), (p1, q1), (p2, q2) in tris:
    # J maps the 3D triangle's edges to the UV edges: J E = U, E = [e1 e2]
    # in 3D; ||J||^2 = trace(U G^-1 U^T) with G = E^T E, det J = det U / sqrt(det G)
    e1 = [v[p1][i] - v[p0][i] for i in range(3)]; e2 = [v[p2][i] - v[p0][i] for i in range(3)]
    g11 = sum(x * x for x in e1); g22 = sum(x * x for x in e2); g12 = sum(e1[i] * e2[i] for i in range(3))
    dg = g11 * g22 - g12 * g12
    u1 = [vt[q1][i] - vt[q0][i] for i in range(2)]; u2 = [vt[q2][i] - vt[q0][i] for i in range(2)]
    fro = sum((u1[i] * u1[i] * g22 - 2 * u1[i] * u2[i] * g12 + u2[i] * u2[i] * g11) / dg for i in range(2))
    det = (u1[0] * u2[1] - u1[1] * u2[0]) / math.sqrt(dg)
    A = math.sqrt(dg) / 2
    rows.append((A, fro, det)); a3 += A; auv += A * abs(det)
s2 = a3 / auv
mean = sum(A * s2 * fro * (1 + 1 / (s2 * det) ** 2) for A, fro, det in rows) / a3
got = float(sys.argv[2]) if sys.argv[2] else float("nan")
ok = abs(got - mean) <= 1e-4 * mean
print("%s test_draw_tool.sh: legend's mean energy %s = %.6g computed from the output at one common scale"
      % ("ok  " if ok else "FAIL", sys.argv[2] or "(none)", mean))
sys.exit(0 if ok else 1)
PY
r=$?
[ $r -eq 0 ] && passed=$((passed + 1)) || failed=$((failed + 1))

"$tool" tests/data/spot.obj --svg-color nonsense >"$d/stdout" 2>"$d/stderr"
rc=$?
grep -q "energy, area, angle or chart" "$d/stderr"
check $(( $? != 0 || rc != 2 )) "unknown --svg-color: usage error naming chart (exit $rc: $(head -1 "$d/stderr"))"

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
