#!/usr/bin/env bash
# Benchmark: run build/bijparam on every mesh in tests/data, and on the larger
# meshes in ../shared/meshes when that folder is present, 3 times each; print
# a table and one JSON line per mesh with V, F, charts, the median wall time
# of the 3 runs, the tool's status, and (when ../shared/tools/uvcheck.py is
# there) the independent checker's verdict on the output.
#
#   bash bench/run.sh                 (or: make bench)
#   BENCH_RUNS=5 BENCH_TIMEOUT=300 bash bench/run.sh
#
# Progress (one JSON line per mesh as it finishes) goes to stderr; the table
# and the JSON lines go to stdout at the end.  Needs python3 and a built tool.
set -u
cd "$(dirname "$0")/.."

tool=build/bijparam
runs=${BENCH_RUNS:-3}
limit=${BENCH_TIMEOUT:-600}
shared=../shared
uvcheck=$shared/tools/uvcheck.py
[ -x "$tool" ] || { echo "bench: $tool missing: run 'make' first" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench: python3 is needed" >&2; exit 1; }

meshes=(tests/data/*.obj tests/data/*.off)
for m in hilbert.obj beetle.off horse_cut.obj lucy_o_f48275.obj face.obj bimba_i.obj; do
    [ -f "$shared/meshes/$m" ] && meshes+=("$shared/meshes/$m")
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
results=$work/results.jsonl
: >"$results"

for mesh in "${meshes[@]}"; do
    out=$work/out.obj
    times=()
    rc=0
    for ((r = 1; r <= runs; r++)); do
        rm -f "$out"
        t0=$(date +%s.%N)
        timeout "$limit" "$tool" --json "$mesh" -o "$out" >"$work/report.json" 2>"$work/stderr"
        rc=$?
        t1=$(date +%s.%N)
        times+=("$(python3 -c "print($t1 - $t0)")")
        [ "$rc" -eq 0 ] || break   # a rejected or failed mesh is not timed again
    done
    verdict=""
    if [ "$rc" -eq 0 ] && [ -f "$uvcheck" ] && [ -f "$out" ]; then
        timeout "$limit" python3 "$uvcheck" --compact "$out" "$mesh" >"$work/uvcheck.json" 2>/dev/null
        verdict=$work/uvcheck.json
    fi
    python3 - "$mesh" "$rc" "$work/report.json" "$work/stderr" "$verdict" "${times[@]}" <<'PY' | tee -a "$results" >&2
import json, statistics, sys
mesh, rc, report, stderr, verdict = sys.argv[1:6]
times = [float(t) for t in sys.argv[6:]]
def count(path):
    """V and F as stored in the file (OFF header, or OBJ v/f lines)."""
    with open(path, "rb") as f:
        data = f.read().decode("ascii", "replace")
    if path.lower().endswith(".off"):
        words = [w for line in data.splitlines() for w in line.split("#")[0].split()]
        return int(words[1]), int(words[2])
    v = sum(1 for l in data.splitlines() if l.startswith("v "))
    f = sum(1 for l in data.splitlines() if l.startswith("f "))
    return v, f
V, F = count(mesh)
row = {"mesh": mesh.split("/")[-1], "V": V, "F": F, "charts": None,
       "median_seconds": round(statistics.median(times), 4) if times else None,
       "runs": len(times), "exit": int(rc), "status": None, "uvcheck": None}
try:
    with open(report) as f:
        rep = json.loads(f.read().strip().splitlines()[-1])
    row["charts"] = rep.get("charts")
    row["status"] = rep.get("status")
    if rep.get("error"):
        row["error"] = rep["error"]
except Exception:
    with open(stderr) as f:
        row["error"] = f.read().strip()[:200] or "no JSON report"
if verdict:
    try:
        with open(verdict) as f:
            d = json.load(f)
        row["uvcheck"] = "bijective" if d["verdict"]["pass"] else "NOT bijective"
    except Exception:
        row["uvcheck"] = "checker gave no answer"
print(json.dumps(row))
PY
done

python3 - "$results" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
fmt = "%-24s %7s %7s %6s %10s  %-10s %s"
print(fmt % ("mesh", "V", "F", "charts", "median s", "uvcheck", "status"))
for r in rows:
    print(fmt % (r["mesh"], r["V"], r["F"], "-" if r["charts"] is None else r["charts"],
                 "-" if r["median_seconds"] is None else "%.3f" % r["median_seconds"],
                 r["uvcheck"] or "-", r.get("error") or r["status"] or "exit %d" % r["exit"]))
print()
for r in rows:
    print(json.dumps(r))
PY
