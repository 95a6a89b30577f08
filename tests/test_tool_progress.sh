#!/usr/bin/env bash
# test_tool_progress.sh - the tool's progress bar, its cancel on SIGINT and
# the format it reports (build/bijparam).
#
# - SIGINT cancels through the library's run-progress callback: the tool,
#   held before the solve by an importance file that is a FIFO, gets SIGINT,
#   keeps running until the FIFO is fed, then stops at the next progress
#   report: exit 130, "cancelled", no output and no temporary left.  A
#   second SIGINT ends it at once, temporary removed.
# - The progress bar: none when stderr is not a terminal, a bar naming the
#   stages on a pseudo-terminal (script(1)), none with --quiet.
# - --json names the format read: "obj", "off", "ply" (an ASCII PLY written
#   here), and a PLY error names the file line.
# - Several charts are solved together (bp_atlas_solve) on the threads: the
#   report's thread count, the same bytes as one thread, one "solve" bar.
# - --json's wall and CPU seconds per stage, and the seams (edges, 3D
#   length, length over the square root of the area) of a square cut on
#   its diagonal.
# Prints "BPTEST <passed> <failed>" last (tests/run_all.sh).  Run from the
# repository root.
set -u
tool=build/bijparam
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_tool_progress.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_tool_progress.sh: $2"; fi
}
if [ ! -x "$tool" ]; then
    check 1 "$tool exists (make build/bijparam)"
    echo "BPTEST $passed $failed"
    exit 1
fi
d=$(mktemp -d /tmp/bptest_progress_XXXXXX)
trap 'rm -rf "$d"' EXIT
no_temp() { [ -z "$(find "$d" -name '.*.bijparam-*' 2>/dev/null)" ]; }
wait_temp() {   # wait_temp NAME: until the tool's temporary for NAME exists
    for _ in $(seq 1 100); do
        [ -n "$(find "$d" -name ".$1.bijparam-*")" ] && return 0
        sleep 0.05
    done
    return 1
}

# a 3 x 3 grid of quads, as OBJ, OFF and ASCII PLY
{
    for i in 0 1 2 3; do for j in 0 1 2 3; do echo "v $j $i 0.$((i * j))"; done; done
    for i in 0 1 2; do for j in 0 1 2; do
        v=$((i * 4 + j + 1)); echo "f $v $((v + 1)) $((v + 5)) $((v + 4))"
    done; done
} > "$d/grid.obj"
{
    echo OFF; echo "16 9 0"
    grep '^v ' "$d/grid.obj" | cut -c3-
    grep '^f ' "$d/grid.obj" | awk '{ print 4, $2 - 1, $3 - 1, $4 - 1, $5 - 1 }'
} > "$d/grid.off"
{
    printf 'ply\nformat ascii 1.0\nelement vertex 16\nproperty float x\nproperty float y\nproperty float z\n'
    printf 'element face 9\nproperty list uchar int vertex_indices\nend_header\n'
    grep '^v ' "$d/grid.obj" | cut -c3-
    grep '^f ' "$d/grid.obj" | awk '{ print 4, $2 - 1, $3 - 1, $4 - 1, $5 - 1 }'
} > "$d/grid.ply"

# --- --json names the format ---------------------------------------------------
for f in obj off ply; do
    "$tool" --threads 1 "$d/grid.$f" --json > "$d/out.json" 2> "$d/err"; rc=$?
    grep -q "\"format\":\"$f\"" "$d/out.json"; has=$?
    check $(( rc != 0 || has != 0 )) "--json on grid.$f: \"format\":\"$f\" ($(cut -c1-80 "$d/out.json"))"
done
sed 's/^4 0 1 5 4$/4 0 1 5 44/' "$d/grid.ply" > "$d/bad.ply"
"$tool" --threads 1 "$d/bad.ply" > /dev/null 2> "$d/err"; rc=$?
grep -q "bad.ply:26: face 1: vertex index 44 (item 4 of the list) is out of range" "$d/err"
check $(( rc != 1 || $? != 0 )) "a PLY index out of range: exit 1, file:line and face named: $(cat "$d/err")"

# --- no bar when stderr is not a terminal ----------------------------------------
"$tool" --threads 1 "$d/grid.obj" -o "$d/plain.obj" 2> "$d/err"; rc=$?
check $(( rc != 0 || $(tr -cd '\r' < "$d/err" | wc -c) != 0 )) "stderr not a terminal: no progress bar ($(cat "$d/err"))"

# --- the bar on a terminal, silenced by --quiet ------------------------------------
if command -v script > /dev/null; then
    script -qc "$tool --threads 1 $d/grid.obj -o $d/tty.obj" /dev/null > "$d/tty" 2>&1; rc=$?
    ok=0
    for s in read charts start optimize pack write; do grep -q "bijparam: $s *\[" "$d/tty" || ok=1; done
    check $(( rc != 0 || ok != 0 )) "on a terminal: a one-line bar through read, charts, start, optimize, pack, write"
    check $(( $(grep -c 'wrote' "$d/tty") != 1 )) "on a terminal: the bar is cleared before the 'wrote' line"
    script -qc "$tool --threads 1 $d/grid.obj -o $d/tty.obj --quiet" /dev/null > "$d/tty" 2>&1; rc=$?
    check $(( rc != 0 || $(wc -c < "$d/tty") != 0 )) "--quiet on a terminal: nothing at all ($(wc -c < "$d/tty") bytes)"
else
    check 1 "script(1) is needed to give the tool a terminal (util-linux)"
fi

# --- several charts: solved together (bp_atlas_solve), on the threads ----------------
# spot's 13 vt charts (--repack off: solved), none holding half the triangles:
# with 2 threads the charts themselves are the tasks ("threads": 2 in the
# report, where chart by chart each small chart ran alone), the same bytes
# as one thread, the solve's time all under "optimize" ("init" 0), and on a
# terminal one "solve" bar naming the charts.
"$tool" tests/data/spot.obj -o "$d/spot1.obj" --threads 1 -q
"$tool" tests/data/spot.obj -o "$d/spot2.obj" --threads 2 -q --json > "$d/spot2.json"; rc=$?
python3 - "$d/spot2.json" <<'PY'; ok=$?
import json, sys
d = json.load(open(sys.argv[1]))
t = d["timings"]
sys.exit(0 if d["threads"] == 2 and d["charts"] == 13 and t["init"] == 0 and t["optimize"] > 0 else 1)
PY
cmp -s "$d/spot1.obj" "$d/spot2.obj"; same=$?
check $(( rc != 0 || ok != 0 || same != 0 )) "spot's 13 charts on 2 threads: solved together (\"threads\": 2, init 0), the same bytes as 1 thread"
if command -v script > /dev/null; then
    script -qc "$tool --threads 2 tests/data/spot.obj -o $d/spot3.obj" /dev/null > "$d/tty2" 2>&1; rc=$?
    grep -q 'bijparam: solve *\[.*13 charts' "$d/tty2"; bar=$?
    check $(( rc != 0 || bar != 0 )) "spot on a terminal: one 'solve' bar for the 13 charts solved together"
fi

# --- the report's stage times and seams ------------------------------------------------
# A 2 x 2 square cut along its diagonal by its vt: two charts, one seam edge
# of length 2 sqrt(2) (its four outer edges are the mesh's boundary, not
# seams), relative to sqrt(area 4): sqrt(2).  Every stage has a wall and a
# CPU time, and "charts" is "cut" plus "segment".
printf 'v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/4 3/5 4/6\n' > "$d/diag.obj"
"$tool" "$d/diag.obj" --json -q > "$d/diag.json"; rc=$?
python3 - "$d/diag.json" <<'PY'; ok=$?
import json, math, sys
d = json.load(open(sys.argv[1]))
s = d["seams"]
keys = ("read", "charts", "cut", "segment", "init", "optimize", "pack", "write")
ok = d["charts"] == 2 and s["edges"] == 1 and abs(s["length"] - 2 * math.sqrt(2)) < 1e-12 \
    and abs(s["relative"] - math.sqrt(2)) < 1e-12
for t in (d["timings"], d["cpu_timings"]):
    ok = ok and all(t[k] >= 0 for k in keys) and t["charts"] == t["cut"] + t["segment"]
sys.exit(0 if ok else 1)
PY
check $(( rc != 0 || ok != 0 )) "--json: a square cut on its diagonal has one seam edge, 2 sqrt(2) long, sqrt(2) relative; wall and CPU per stage"
"$tool" tests/data/spot.obj --atlas 256 --json -q > "$d/spot_seg.json"; rc=$?
python3 - "$d/spot_seg.json" <<'PY'; ok=$?
import json, sys
d = json.load(open(sys.argv[1]))
t = d["timings"]
sys.exit(0 if d["charts"] > 13 and t["segment"] > 0 and t["charts"] == t["cut"] + t["segment"]
         and d["seams"]["edges"] > 0 else 1)
PY
check $(( rc != 0 || ok != 0 )) "--json: spot segmented with --atlas: its own segment time, charts = cut + segment, seams"

# --- SIGINT: cancel through the callback ---------------------------------------------
# The tool must be blocked in a read when the signal comes, not still in
# the stages before it (whose progress reports would cancel at once): this
# shell holds the FIFO open for reading and writing, so the tool's open
# returns and its read waits for the weights; SIGINT is sent only once the
# FIFO is among the tool's open files.
holds_fifo() {   # holds_fifo PID: PID has imp.fifo open (Linux /proc)
    for _ in $(seq 1 200); do
        for f in /proc/"$1"/fd/*; do
            [ "$(readlink "$f" 2> /dev/null)" = "$d/imp.fifo" ] && return 0
        done
        sleep 0.05
    done
    return 1
}
mkfifo "$d/imp.fifo"
exec 3<> "$d/imp.fifo"
"$tool" --threads 1 "$d/grid.obj" --importance "$d/imp.fifo" -o "$d/int.obj" > /dev/null 2> "$d/err" 3<&- &
pid=$!
wait_temp int.obj; seen=$?
check $seen "SIGINT: the temporary exists while the tool runs"
holds_fifo "$pid"; blocked=$?
check $blocked "SIGINT: the tool is waiting in its read of the importance FIFO"
kill -INT "$pid"
sleep 0.3
kill -0 "$pid" 2> /dev/null; alive=$?
check $alive "SIGINT: the tool is not killed, it cancels at its next progress report"
# the weights, then the end of the FIFO; the read resumes (SA_RESTART)
for _ in $(seq 1 9); do echo 1; done >&3
exec 3>&-
wait "$pid"; st=$?
no_temp; clean=$?
grep -q 'cancelled' "$d/err"; said=$?
check $(( st != 130 || clean != 0 || said != 0 )) "SIGINT: exit 130 (got $st), 'cancelled' said, the temporary removed: $(cat "$d/err")"
check $([ -e "$d/int.obj" ] && echo 1 || echo 0) "SIGINT: no output file"
"$tool" --threads 1 "$d/grid.obj" --importance "$d/imp.fifo" -o "$d/int2.obj" > /dev/null 2> "$d/err" &
pid=$!
wait_temp int2.obj
kill -INT "$pid"; sleep 0.2; kill -INT "$pid"; sleep 0.3
kill -0 "$pid" 2> /dev/null && { kill -KILL "$pid"; check 1 "a second SIGINT: the tool still ran (killed)"; }
wait "$pid"; st=$?
no_temp; clean=$?
check $(( st != 130 || clean != 0 )) "a second SIGINT ends the tool at once (status $st), the temporary removed"
check $([ -e "$d/int2.obj" ] && echo 1 || echo 0) "a second SIGINT: no output file"

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
