#!/usr/bin/env bash
# test_tool_io.sh - what the tool does with the user's files (build/bijparam).
#
# - An OBJ input comes back whole: every line but vt byte for byte and in
#   order (mtllib, usemtl, g, o, s, vn, l, comments, CRLF), each f corner
#   keeps its v and vn and gets a vt (bp_write_obj_from); an OFF input gets
#   the plain writer.
# - An output that is the input (another spelling, a symlink) is refused
#   without --force and the input stays unchanged; --force replaces it.
# - No half-written or temporary file stays behind: after a failed write,
#   after a read error, and after SIGTERM in the middle of a run (the run is
#   held inside by an importance file that is a FIFO nobody writes to yet).
# - Where the result went: one stderr line with -o, "no output written" without
#   it, nothing with --quiet, the "output" field with --json.
# - The --json report's "euler" (counted from the triangles alone) is 2 minus
#   the chart's loops for every chart of spot, face_holes, the cow and
#   fertility (each a disk with holes after the tool's cut).
# - A usage error is two lines (the error, "see bijparam --help"); --version
#   prints the header's BP_VERSION_STRING; I/O errors give the reason; the
#   messages count faces from 1.
# Prints "BPTEST <passed> <failed>" last (tests/run_all.sh).  Run from the
# repository root.
set -u
tool=build/bijparam
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_tool_io.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_tool_io.sh: $2"; fi
}
if [ ! -x "$tool" ]; then
    check 1 "$tool exists (make build/bijparam)"
    echo "BPTEST $passed $failed"
    exit 1
fi
d=$(mktemp -d /tmp/bptest_tool_XXXXXX)
trap 'rm -rf "$d"' EXIT
run() { "$tool" --threads 1 "$@" >"$d/stdout" 2>"$d/stderr"; echo $? >"$d/rc"; }
rc() { cat "$d/rc"; }
no_temp() { [ -z "$(find "$d" -name '.*.bijparam-*' 2>/dev/null)" ]; }

# --- an asset with everything (CRLF), three charts -----------------------
printf '%s\r\n' '# test asset' 'mtllib test.mtl' 'o thing' \
    'v 0 0 0' 'v 1 0 0.1' 'v 2 0 0' 'v 0 1 0.1' 'v 1 1 0.3' 'v 2 1 0.1' 'v 0 2 0' 'v 1 2 0.1' 'v 2 2 0' \
    'vn 0 0 1' 'vn 0 0.1 1' '# old uvs' \
    'vt 0 0' 'vt 1 0' 'vt 0 1' 'vt 1 1' 'vt 0 2' 'vt 1 2' 'vp 0.5' \
    'vt 1 0' 'vt 2 0' 'vt 1 1' 'vt 2 1' 'vt 1 2' 'vt 2 2' \
    'g left' 'usemtl red' 's 1' 'f 1/1/1 2/2/1 5/4/2 4/3/2' \
    'f	-6/-10/-2 -5/-9/-2  -2/-7/-1 -3/-8/-1 # upper left, relative' '' \
    'g right' 'usemtl blue' 's off' 'f 2/7 3/8 6/10' 'f 2/7 6/10 5/9' 'l 1 2 3' 'frobnicate 42' \
    'f 5//2 6//2 9//1 8//1' '# end' > "$d/asset.obj"
truncate -s -2 "$d/asset.obj"             # the last line without a line ending
cp "$d/asset.obj" "$d/asset.orig"

run "$d/asset.obj" -o "$d/out.obj"
check $(( $(rc) != 0 )) "asset: the tool runs (exit $(rc))"
grep -avE '^[[:space:]]*(vt|f)[[:space:]]' "$d/asset.obj" > "$d/a.rest"
grep -avE '^[[:space:]]*(vt|f)[[:space:]]' "$d/out.obj" > "$d/b.rest"
cmp -s "$d/a.rest" "$d/b.rest"
check $? "asset: every line but vt and f comes back byte for byte and in order ($(wc -l < "$d/a.rest") lines)"
nf_in=$(grep -acE '^[[:space:]]*f[[:space:]]' "$d/asset.obj")
nf_out=$(grep -acE '^[[:space:]]*f[[:space:]]' "$d/out.obj")
nf_vt=$(grep -acE '^f[[:space:]]+(-?[0-9]+/[0-9]+(/-?[0-9]+)?[[:space:]]+){2,}-?[0-9]+/[0-9]+(/-?[0-9]+)?[[:space:]]*(#.*)?'$'\r''$' "$d/out.obj")
check $(( nf_in != 5 || nf_out != 5 || nf_vt != 5 )) "asset: 5 f lines, each corner with a vt, CRLF kept ($nf_in in, $nf_out out, $nf_vt with vt)"
# v and vn of each corner unchanged: strip the vt from the output's corners
sed -E 's#(-?[0-9]+)/[0-9]+/(-?[0-9]+)#\1/X/\2#g; s#(-?[0-9]+)/[0-9]+([[:space:]]|$)#\1/X\2#g' "$d/out.obj" | grep -aE '^[[:space:]]*f' > "$d/b.f"
sed -E 's#(-?[0-9]+)/-?[0-9]+/(-?[0-9]+)#\1/X/\2#g; s#(-?[0-9]+)/-?[0-9]+([[:space:]]|$)#\1/X\2#g; s#(-?[0-9]+)//(-?[0-9]+)#\1/X/\2#g' "$d/asset.obj" | grep -aE '^[[:space:]]*f' > "$d/a.f"
cmp -s "$d/a.f" "$d/b.f"
check $? "asset: each f line keeps its v and vn indices (relative ones too), spacing and comment"
lines=$(wc -l < "$d/out.obj"); crlf=$(grep -ac $'\r$' "$d/out.obj")
check $(( lines != crlf )) "asset: CRLF stays CRLF ($crlf of $lines lines)"
check $(( $(tail -c 5 "$d/out.obj" | tr -d '\n' | wc -c) != 5 )) "asset: the last line stays without a line ending"
grep -q '^bijparam: wrote .*out.obj (3 charts)$' "$d/stderr"
check $? "asset: one stderr line says where the result went: $(head -1 "$d/stderr")"
cmp -s "$d/asset.obj" "$d/asset.orig"
check $? "asset: the input is unchanged"

# --- OFF input: the plain writer -------------------------------------------
printf 'OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0.2\n0 1 0\n4 0 1 2 3\n' > "$d/q.off"
run "$d/q.off" -o "$d/q.obj"
head -1 "$d/q.obj" 2>/dev/null | grep -q '^# written by bijparam'
check $(( $? != 0 || $(rc) != 0 )) "OFF input: written by bp_write_obj (exit $(rc))"
check $(( $(grep -c '^f [0-9]*/[0-9]* [0-9]*/[0-9]* [0-9]*/[0-9]* [0-9]*/[0-9]*$' "$d/q.obj") != 1 )) "OFF input: the quad is one f line with vt"

# --- writing over the input -------------------------------------------------
ln -s asset.obj "$d/link.obj"
for out in "$d/./asset.obj" "$d/link.obj"; do
    run "$d/asset.obj" -o "$out"
    cmp -s "$d/asset.obj" "$d/asset.orig"; same=$?
    check $(( $(rc) != 2 || same != 0 || $(wc -l < "$d/stderr") != 2 )) \
        "-o $(basename "$out") (the input): refused with exit 2 and two lines, input unchanged: $(head -1 "$d/stderr")"
done
run "$d/asset.obj" --svg "$d/asset.obj"
check $(( $(rc) != 2 )) "--svg onto the input: refused too (exit $(rc))"
run "$d/asset.obj" -o "$d/link.obj" --force
cmp -s "$d/asset.obj" "$d/asset.orig"; changed=$?
[ -L "$d/link.obj" ]; islink=$?
grep -q '^usemtl red' "$d/asset.obj"; kept=$?
check $(( $(rc) != 0 || changed == 0 || islink != 0 || kept != 0 )) \
    "--force: the input is replaced through the symlink (still a link), its other lines kept (exit $(rc))"
cp "$d/asset.orig" "$d/asset.obj"

# --- no half-written or temporary file --------------------------------------
mkdir "$d/dir.obj"
run "$d/asset.obj" -o "$d/dir.obj"
grep -q 'Is a directory' "$d/stderr"; why=$?
no_temp; clean=$?
check $(( $(rc) != 1 || why != 0 || clean != 0 )) "-o onto a directory: exit 1, the reason given, no temporary left: $(cat "$d/stderr")"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n' > "$d/bad.obj"
run "$d/bad.obj" -o "$d/bad_out.obj"
no_temp; clean=$?
check $(( $(rc) != 1 || clean != 0 )) "a bad input with -o: exit 1, no output and no temporary left ($( [ -e "$d/bad_out.obj" ] && echo 'output exists' || echo 'no output'))"
check $([ -e "$d/bad_out.obj" ] && echo 1 || echo 0) "a bad input with -o: no output file"
mkfifo "$d/imp.fifo"
"$tool" --threads 1 "$d/asset.obj" --importance "$d/imp.fifo" -o "$d/sig.obj" >/dev/null 2>&1 &
pid=$!
seen=1
for _ in $(seq 1 100); do
    if [ -n "$(find "$d" -name '.sig.obj.bijparam-*')" ]; then seen=0; break; fi
    sleep 0.05
done
check $seen "SIGTERM: the temporary exists while the tool runs"
kill -TERM "$pid" 2>/dev/null
wait "$pid" 2>/dev/null; st=$?
no_temp; clean=$?
check $(( st != 143 || clean != 0 )) "SIGTERM in the middle of a run: killed (status $st), the temporary removed"
check $([ -e "$d/sig.obj" ] && echo 1 || echo 0) "SIGTERM: no output file"

# --- saying where the result went --------------------------------------------
run "$d/asset.obj"
check $(( $(rc) != 0 )) "without -o: exit 0"
[ "$(cat "$d/stderr")" = "bijparam: no output written (use -o FILE)" ]
check $? "without -o: stderr says 'no output written (use -o FILE)' and nothing else"
run "$d/asset.obj" -q
check $(( $(rc) != 0 || $(wc -c < "$d/stderr") != 0 )) "--quiet: nothing on stderr"
run "$d/asset.obj" --json
grep -q '"output":null' "$d/stdout"; js=$?
check $(( $(rc) != 0 || js != 0 || $(wc -c < "$d/stderr") != 0 )) "--json without -o: \"output\":null in the report, stderr empty"
run "$d/asset.obj" --json -o "$d/j.obj"
grep -q '"output":"'"$d"'/j.obj"' "$d/stdout"
check $? "--json with -o: the report names the output"

# --- the report's Euler characteristic ---------------------------------------
# chart_euler counts the edges from the triangles alone (a counting sort);
# every chart the tool solves is a disk with holes, so V - E + F = 2 - (its
# loops), which the report lists separately: spot's 13 charts, face_holes
# (several holes), the cow's seamed chart, fertility (genus 4, closed: cut).
for m in tests/data/spot.obj tests/data/face_holes.off tests/data/cow_param_withSUV.obj tests/data/fertility.off; do
    run "$m" --json --init-only
    python3 -c '
import json, sys
r = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
bad = [c["index"] for c in r["per_chart"] if c["euler"] != 2 - len(c["loops"])]
print(len(r["per_chart"]), bad)
sys.exit(1 if bad or not r["per_chart"] else 0)' "$d/stdout" > "$d/euler"
    check $? "$(basename "$m"): every chart's euler is 2 - its loops (charts, wrong: $(cat "$d/euler"))"
done

# --- usage, version, messages -------------------------------------------------
run --bogus
check $(( $(rc) != 2 || $(wc -l < "$d/stderr") != 2 )) "usage error: exit 2, two lines: $(tr '\n' '|' < "$d/stderr")"
[ "$(sed -n 2p "$d/stderr")" = "see bijparam --help" ]
check $? "usage error: the second line is 'see bijparam --help'"
run
check $(( $(rc) != 2 || $(wc -l < "$d/stderr") != 2 )) "no input: exit 2, two lines"
version=$(sed -n 's/^#define BP_VERSION_STRING "\(.*\)"$/\1/p' bijparam.h)
run --version
[ -n "$version" ] && [ "$(cat "$d/stdout")" = "bijparam $version" ]
check $? "--version prints 'bijparam $version' ($(cat "$d/stdout"))"
run "$d/dir.obj"
grep -qi 'is a directory' "$d/stderr"
check $(( $? != 0 || $(rc) != 1 )) "a directory as input: says so: $(cat "$d/stderr")"
run "$d"
grep -qi 'is a directory' "$d/stderr"
check $(( $? != 0 || $(rc) != 1 )) "a directory without .obj as input: says so: $(cat "$d/stderr")"
run "$d/missing.obj"
grep -q 'No such file or directory' "$d/stderr"
check $(( $? != 0 || $(rc) != 1 )) "a missing input: the reason: $(cat "$d/stderr")"
printf '1.5\n' > "$d/imp.txt"
run "$d/asset.obj" --importance "$d/imp.txt"
grep -q 'importance of face 2 ' "$d/stderr"
check $? "importance: the first missing weight is face 2 of 5, counted from 1: $(cat "$d/stderr")"

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
