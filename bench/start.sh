#!/usr/bin/env bash
# The start maps (make bench-start, part of make bench; docs/performance.md,
# "Start maps"): thin strips (1 x 1e-7 and 1 x 1e-4, 398 triangles,
# flat and rotated into 3D; their optimum is the isometry, mean energy 4)
# and lucy, each with the default start (--start auto) and the plain Tutte
# start (--start plain), one thread: CPU seconds (user+sys of the process),
# iterations of the final optimization, final mean energy, and the exact
# check by tests/uvcheck.py.  Prints a table and JSON lines.
#
#   bash bench/start.sh                 (~3 min: lucy twice)
#   START_MESHES="" bash bench/start.sh only the strips (~10 s)
set -u
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "bench-start: build/bijparam missing: run 'make' first" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench-start: python3 is needed" >&2; exit 1; }
out=build/bench/start
mkdir -p $out
python3 - "$out" <<'PY'
import math, sys
out = sys.argv[1]
def strip(h, rot, path, n=200):
    a = (0.48, 0.6, 0.64)
    b0 = (-0.8, 0.6, 0.0)
    d = sum(x * y for x, y in zip(a, b0))
    b = [x - d * y for x, y in zip(b0, a)]
    l = math.sqrt(sum(x * x for x in b)); b = [x / l for x in b]
    with open(path, "w") as f:
        for r in range(2):
            for i in range(n):
                x, y = i / (n - 1), r * h
                p = (x, y, 0.0) if not rot else tuple(x * a[k] + y * b[k] for k in range(3))
                f.write("v %.17g %.17g %.17g\n" % p)
        for i in range(n - 1):
            f.write("f %d %d %d\nf %d %d %d\n" % (i + 1, i + 2, n + i + 2, i + 1, n + i + 2, n + i + 1))
for h, tag in ((1e-7, "1e-7"), (1e-4, "1e-4")):
    strip(h, 0, "%s/strip_%s.obj" % (out, tag))
    strip(h, 1, "%s/strip_%s_3d.obj" % (out, tag))
PY
meshes="$out/strip_1e-7.obj $out/strip_1e-7_3d.obj $out/strip_1e-4.obj $out/strip_1e-4_3d.obj"
for m in ${START_MESHES-tests/data/lucy_o_f48275.obj}; do
    if [ -f "$m" ]; then meshes="$meshes $m"; else echo "bench-start: $m missing, skipped" >&2; fi
done
check=tests/uvcheck.py
printf "%-22s %-6s %9s %7s %14s %14s %8s\n" mesh start "cpu (s)" iters "E start" "E final" uvcheck
for m in $meshes; do
    name=$(basename "$m"); name=${name%.*}
    for s in auto plain; do
        o=$out/$name.$s
        /usr/bin/time -f "%U %S" -o $o.time build/bijparam --threads 1 --json -q --start $s "$m" -o $o.obj > $o.json 2> $o.err
        python3 "$check" $o.obj "$m" > /dev/null 2>&1 && ok=valid || ok=INVALID
        python3 - "$name" "$s" "$o" "$ok" <<'PY'
import json, sys
name, s, o, ok = sys.argv[1:5]
j = json.load(open(o + ".json"))
u, sy = (float(x) for x in open(o + ".time").read().split()[-2:])
c = j["per_chart"]
it = sum(x["iterations"] for x in c)
area = 1
e0 = c[0]["energy_start"] if len(c) == 1 else float("nan")
e1 = c[0]["energy_end"] if len(c) == 1 else float("nan")
print("%-22s %-6s %9.2f %7d %14.6g %14.9g %8s" % (name, s, u + sy, it, e0, e1, ok))
print("JSON " + json.dumps({"bench": "start", "mesh": name, "start": s, "cpu_seconds": u + sy, "iterations": it,
                            "energy_start": e0, "energy_end": e1, "uvcheck": ok,
                            "init_seconds": j["timings"]["init"], "optimize_seconds": j["timings"]["optimize"]}))
PY
    done
done | tee $out/start.txt | grep -v '^JSON'
grep '^JSON' $out/start.txt | sed 's/^JSON //' > $out/start.jsonl
