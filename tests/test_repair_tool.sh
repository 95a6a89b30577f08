#!/usr/bin/env bash
# test_repair_tool.sh - how the tool reports repairs (build/bijparam).
#
# - A file with one defect of each kind (a flipped face, a duplicate face, a
#   fin on an edge, a zero-area face): by default it is written, exit 0, and
#   --json has "repairs" with each kind's count, its first elements numbered
#   as the file does ([copy, kept] for a duplicate, [a, b] for an edge) and
#   the library's message; without --json one stderr line per kind, none
#   with --quiet; every f line of the output has a vt on each corner.
# - --strict: exit 1, nothing written, the error names the element.
# - camel_b with every second face flipped: 1788 re-oriented (a tie: the
#   first face's orientation wins), first faces 2 4 6 8.  The output is
#   written with those faces' corners in the repaired order, so the
#   independent checker passes it against the consistently wound camel_b
#   (exit 0: bijective, every face's corners those of camel_b's face, up
#   to rotation), and against the damaged input it finds exactly the 1788
#   re-oriented faces reversed; every f line's corners are a permutation
#   of the input line's v/vt/vn triples.
# - the cow without its vt (closed: the automatic cut) and every third face
#   flipped: the same against the cow without vt, and every vt of the
#   output belongs to one v (the cut renumbers re-oriented triangles).
# - spot with every 7th face flipped: the output is the clean output byte
#   for byte (the re-oriented faces come back in the clean file's order,
#   with the vt of every corner right).
# The independent checker is tests/uvcheck.py.
# The validity of repaired maps is proven exactly in test_repair.c.
# Prints "BPTEST <passed> <failed>" last.  Run from the repository root.
set -u
tool=build/bijparam
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_repair_tool.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_repair_tool.sh: $2"; fi
}
if [ ! -x "$tool" ] || ! command -v python3 >/dev/null; then
    check 1 "$tool exists (make build/bijparam) and python3 is installed (reads the JSON)"
    echo "BPTEST $passed $failed"
    exit 1
fi
d=$(mktemp -d /tmp/bptest_repair_XXXXXX)
trap 'rm -rf "$d"' EXIT
run() { "$tool" --threads 1 "$@" >"$d/stdout" 2>"$d/stderr"; echo $? >"$d/rc"; }
rc() { cat "$d/rc"; }
# json EXPR: evaluate a Python expression on the JSON report (as j); prints it
json() { python3 -c "import json,sys; j=json.load(open('$d/stdout')); print($1)" 2>/dev/null; }

cat >"$d/strip.obj" <<'EOF'
# a strip with one defect of each kind
v 0 0 0
v 1 0 0
v 2 0 0
v 0 1 0
v 1 1 0
v 2 1 0
v 1 0.5 1
v 3 0 0
f 1 2 5
f 1 5 4
f 2 6 3
f 2 6 5
f 5 1 2
f 2 5 7
f 2 8 3
EOF
# lines: f 1 2 5 is line 10; the flipped face 3 line 12, the copy (face 5)
# line 14, the fin face 6 on edge 2-5, the zero-area face 7 line 16

run "$d/strip.obj" --json -o "$d/out.obj"
check "$([ "$(rc)" = 0 ] && [ "$(json "j['status']")" = ok ] && [ -s "$d/out.obj" ]; echo $?)" \
    "defect strip: repaired and written, exit 0 (rc $(rc), $(head -c 300 "$d/stderr"))"
check "$([ "$(json "j['repairs']['total']")" = 4 ] &&
         [ "$(json "j['repairs']['flipped']['count'], j['repairs']['flipped']['first']")" = "1 [3]" ] &&
         [ "$(json "j['repairs']['duplicate']['count'], j['repairs']['duplicate']['first']")" = "1 [[5, 1]]" ] &&
         [ "$(json "j['repairs']['nonmanifold_edge']['count'], j['repairs']['nonmanifold_edge']['first']")" = "1 [[2, 5]]" ] &&
         [ "$(json "j['repairs']['degenerate']['count'], j['repairs']['degenerate']['first']")" = "1 [7]" ] &&
         [ "$(json "j['repairs']['nonorientable']['count'], j['repairs']['nonorientable']['first'], j['repairs']['nonorientable']['message']")" = "0 [] " ]
         echo $?)" \
    "--json repairs: total 4; flipped [3], duplicate [[5, 1]], nonmanifold_edge [[2, 5]], degenerate [7], nonorientable none ($(json "j['repairs']"))"
check "$(json "j['repairs']['degenerate']['message']" | grep -q 'triangle 7 (line 16)' &&
         json "j['repairs']['duplicate']['message']" | grep -q 'triangle 5 (line 14) repeats triangle 1 (line 10)'; echo $?)" \
    "--json messages name faces with their lines"
check "$(python3 - "$d/out.obj" <<'EOF'
import sys
f = [l.split()[1:] for l in open(sys.argv[1]) if l.startswith('f ')]
sys.exit(0 if len(f) == 7 and all(len(c.split('/')) >= 2 and c.split('/')[1] for x in f for c in x) else 1)
EOF
echo $?)" "every f line of the output (7) has a vt on each corner"

run "$d/strip.obj" -o "$d/out2.obj"
check "$([ "$(rc)" = 0 ] && [ "$(grep -c '^bijparam: repaired: ' "$d/stderr")" = 4 ] &&
         grep -q 'repaired: .*strip.obj: 1 edge shared by more than two triangles made seams for all of them: edge 2-5' "$d/stderr"; echo $?)" \
    "without --json: one 'repaired:' line per kind on stderr ($(head -c 400 "$d/stderr"))"
run "$d/strip.obj" -q -o "$d/out3.obj"
check "$([ "$(rc)" = 0 ] && [ ! -s "$d/stderr" ]; echo $?)" "--quiet: no repair lines"

run "$d/strip.obj" --strict -o "$d/strict.obj"
check "$([ "$(rc)" = 1 ] && [ ! -e "$d/strict.obj" ] && grep -q 'error: .*strip.obj:16: triangle 7 (line 16), vertices 2 8 3, has zero' "$d/stderr"; echo $?)" \
    "--strict: exit 1, nothing written, the zero-area face named with its line ($(head -c 300 "$d/stderr"))"
# without the zero-area face, strict stops at the duplicate
grep -v '^f 2 8 3' "$d/strip.obj" >"$d/strip2.obj"
run "$d/strip2.obj" --strict --json
check "$([ "$(rc)" = 1 ] && [ "$(json "j['status']")" = "two triangles use the same three vertices" ] &&
         json "j['error']" | grep -q 'triangle 1 (line 10) and triangle 5 (line 14)'; echo $?)" \
    "--strict --json: the duplicate is the error, naming both faces ($(json "j.get('error')"))"

uvcheck=tests/uvcheck.py
# camel_b, every second face flipped
if [ -f tests/data/camel_b.obj ]; then
    awk '/^f /{n++; if (n % 2 == 0) { print $1, $2, $4, $3; next } } {print}' tests/data/camel_b.obj >"$d/camel_flip.obj"
    run "$d/camel_flip.obj" --json --max-iters 50
    check "$([ "$(rc)" = 0 ] && [ "$(json "j['repairs']['flipped']['count'], j['repairs']['flipped']['first']")" = "1788 [2, 4, 6, 8]" ]; echo $?)" \
        "camel_b, every second face flipped: 1788 re-oriented, first 2 4 6 8 ($(json "j['repairs']['flipped']"))"
    run "$d/camel_flip.obj" --json --max-iters 50 -o "$d/camel_flip_out.obj"
    check "$(python3 - "$d/camel_flip.obj" "$d/camel_flip_out.obj" <<'EOF'
import sys
fi = [l.split()[1:] for l in open(sys.argv[1]) if l.startswith('f ')]
fo = [l.split()[1:] for l in open(sys.argv[2]) if l.startswith('f ')]
strip = lambda c: (c.split('/')[0], c.split('/')[2] if c.count('/') == 2 else '')
ok = len(fi) == len(fo) and all(sorted(map(strip, a)) == sorted(map(strip, b)) for a, b in zip(fi, fo))
rev = sum(1 for a, b in zip(fi, fo) if list(map(strip, a)) != list(map(strip, b)))
sys.exit(0 if ok and rev == 1788 else 1)
EOF
echo $?)" "camel_b flipped: every output f line is a permutation of the input's v/vn, 1788 lines reordered"
    check "$([ "$(json "j['repairs']['flipped']['written_reordered']")" = 1788 ]; echo $?)" \
        "camel_b flipped, written: --json says 1788 written reordered ($(json "j['repairs']['flipped']"))"
    python3 "$uvcheck" --json "$d/camel_flip_out.obj" tests/data/camel_b.obj >"$d/uvc.json"
    check "$?" "camel_b flipped: uvcheck against the consistently wound camel_b passes ($(head -c 300 "$d/uvc.json"))"
    python3 "$uvcheck" --json "$d/camel_flip_out.obj" "$d/camel_flip.obj" >"$d/uvc.json"
    check "$(python3 -c "import json; c=json.load(open('$d/uvc.json'))['counts']; print(0 if c == {'reversed_faces': 1788} else 1)")" \
        "camel_b flipped: against the damaged input, uvcheck sees exactly the 1788 re-oriented faces reversed and nothing else ($(head -c 200 "$d/uvc.json"))"
    python3 "$uvcheck" --allow-reorient "$d/camel_flip_out.obj" "$d/camel_flip.obj" >/dev/null
    check "$?" "camel_b flipped: uvcheck --allow-reorient against the damaged input passes"
    run "$d/camel_flip.obj" --json --strict --max-iters 50
    check "$([ "$(rc)" = 1 ] && json "j['error']" | grep -q 'orientations disagree'; echo $?)" \
        "camel_b flipped, --strict: rejected ($(json "j.get('error')"))"
else
    check 1 "tests/data/camel_b.obj exists"
fi

# spot (vt seams, 13 charts), every 7th face from the 3rd flipped: the
# repair flips them back, so the output with those f lines swapped back must
# be byte for byte the clean output (same vt for every corner)
if [ -f tests/data/spot.obj ]; then
    flip7() { awk '/^f /{n++; if (n % 7 == 3) { print $1, $2, $4, $3; next } } {print}' "$1"; }
    flip7 tests/data/spot.obj >"$d/spot_flip.obj"
    run "$d/spot_flip.obj" --json -o "$d/spot_flip_out.obj"
    check "$([ "$(rc)" = 0 ] && [ "$(json "j['repairs']['flipped']['count'], j['repairs']['total'], j['charts']")" = "837 837 13" ]; echo $?)" \
        "spot with 837 faces flipped: 837 re-oriented, 13 charts ($(json "j['repairs']['flipped']['count'], j['charts']"))"
    run tests/data/spot.obj -q -o "$d/spot_clean.obj"
    check "$(cmp -s "$d/spot_flip_out.obj" "$d/spot_clean.obj"; echo $?)" \
        "spot flipped and repaired: the output is the clean output byte for byte (re-oriented faces in the clean order)"
else
    check 1 "tests/data/spot.obj exists"
fi

# the cow without vt (closed: cut automatically), every third face flipped
# exit 0 when every vt of the OBJ's f lines belongs to one v
vt_owned() {
    python3 - "$1" <<'EOF'
import sys
owner = {}
for l in open(sys.argv[1]):
    if l.startswith('f '):
        for c in l.split()[1:]:
            v, t = c.split('/')[:2]
            if owner.setdefault(t, v) != v: sys.exit(1)
EOF
}

if [ -f tests/data/cow_param_withSUV.obj ]; then
    sed -e '/^vt /d' -e '/^vn /d' -e 's|/[0-9/]*||g' tests/data/cow_param_withSUV.obj >"$d/cow_novt.obj"
    awk '/^f /{n++; if (n % 3 == 0) { print $1, $2, $4, $3; next } } {print}' "$d/cow_novt.obj" >"$d/cow_flip.obj"
    run "$d/cow_flip.obj" --json --max-iters 30 -o "$d/cow_flip_out.obj"
    check "$([ "$(rc)" = 0 ] && [ "$(json "j['repairs']['flipped']['count'], j['per_chart'][0]['cut_edges'] > 0")" = "1934 True" ]; echo $?)" \
        "cow without vt, every third face flipped: 1934 re-oriented and cut ($(json "j['repairs']['flipped']['count']"))"
    check "$(vt_owned "$d/cow_flip_out.obj"; echo $?)" "cow flipped and cut: every vt of the output belongs to one v"
    # three faces repeated at the end: the dropped copies take their twins'
    # vt after the cut renumbered the twins' chart
    (cat "$d/cow_novt.obj"; grep '^f ' "$d/cow_novt.obj" | sed -n '100p;2000p;4000p') >"$d/cow_dup.obj"
    run "$d/cow_dup.obj" --json --max-iters 5 -o "$d/cow_dup_out.obj"
    check "$([ "$(json "j['repairs']['duplicate']['count']")" = 3 ] && vt_owned "$d/cow_dup_out.obj"; echo $?)" "cow without vt, 3 faces repeated: 3 dropped, every vt of the output (copies too) belongs to one v"
    python3 "$uvcheck" --json "$d/cow_flip_out.obj" "$d/cow_novt.obj" >"$d/uvc.json"
    check "$?" "cow flipped and cut: uvcheck against the cow without vt passes ($(head -c 300 "$d/uvc.json"))"
else
    check 1 "tests/data/cow_param_withSUV.obj exists"
fi

echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
