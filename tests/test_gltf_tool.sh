#!/usr/bin/env bash
# test_gltf_tool.sh - glTF through the tool (build/bijparam, examples/bp_gltf.h).
#
# - examples/bp_gltf.h compiles warning-free on its own as C99 (gcc, clang)
#   and C++11 (g++).
# - The models of tests/gltf_make.py (two meshes with normals, materials and
#   extras in a .glb; strips, fans and quantized positions in data: URIs; a
#   .gltf with an external .bin and image; two meshes drawing one sphere
#   from the same accessors) and the real ones of
#   tests/data/gltf (Khronos samples: a textured box as .glb and as .gltf
#   with its .bin and image, morph targets with an animation, two
#   primitives with morph targets, a skin) go through the tool as .glb and
#   as .gltf, and tests/gltf_check.py, which reads glTF without the
#   project's code, proves that everything but what the new map must change
#   came back: every JSON value, the input's bytes, every corner's
#   attributes and morph target attributes byte for byte, while the
#   accessors, bufferViews and .glb bytes only the rewritten primitives
#   used are gone (every one left is referenced, the file valid glTF, no
#   bigger than the input scaled by the split plus the new uvs and
#   indices; an unknown extension holding whole numbers keeps them); the new
#   TEXCOORD_0, read by it and written as OBJ, passes the exact checkers
#   (bijparam --check, tests/uvcheck.py), and so does the output read by
#   the tool itself.
# - Numbers and strings come back as written (1.50e0, -0.0e+0, \u00e9); the
#   input is never changed; no temporary stays behind.
# - A .gltf written in another folder reaches the same .bin and image
#   files (its uris rewritten); a .gltf with a .bin gets OUT.bin, and an
#   output whose .bin would be a file the input reads is refused.
# - --repack and --init input keep the file's own map: the written
#   TEXCOORD_0 is that map moved and scaled (--repack), or the start the
#   report names (--init input).
# - --texcoord 1 writes a second set beside the file's TEXCOORD_0, which
#   comes back byte for byte.
# - Bad files give one error line naming the element and write nothing;
#   -o .glb from an OBJ is a usage error; --check names glTF triangles.
# Prints "BPTEST <passed> <failed>" last (tests/run_all.sh).  Run from the
# repository root.
set -u
tool=build/bijparam
passed=0
failed=0
check() {   # check OK MESSAGE
    if [ "$1" -eq 0 ]; then passed=$((passed + 1)); echo "ok   test_gltf_tool.sh: $2"
    else failed=$((failed + 1)); echo "FAIL test_gltf_tool.sh: $2"; fi
}
if [ ! -x "$tool" ] || ! command -v python3 >/dev/null; then
    check 1 "$tool exists (make build/bijparam) and python3 is installed (the independent reader)"
    echo "BPTEST $passed $failed"
    exit 1
fi
d=$(mktemp -d /tmp/bptest_gltf_XXXXXX)
trap 'rm -rf "$d"' EXIT
py=python3
run() { "$tool" --threads 1 "$@" >"$d/stdout" 2>"$d/stderr"; echo $? >"$d/rc"; }
rc() { cat "$d/rc"; }
no_temp() { [ -z "$(find "$d" -name '.*.bijparam-*' 2>/dev/null)" ]; }
# compare IN OUT: the independent reader's proof, then the exact check of
# the map it reads (as OBJ) and of OUT as the tool reads it
compare() {
    local in=$1 out=$2 what=$3
    $py tests/gltf_check.py compare "$in" "$out" >"$d/cmp.log" 2>&1
    local r=$?
    [ "$r" -ne 0 ] && grep -v '^ok' "$d/cmp.log" | head -20
    check "$r" "$what: everything kept ($(grep -c '^ok' "$d/cmp.log") properties, $(sed -n 's/.*triangle primitives written, \([0-9]*\) corners compared.*/\1/p' "$d/cmp.log") corners compared)"
    $py tests/gltf_check.py obj "$out" "$d/map.obj" >/dev/null 2>&1 && "$tool" --check "$d/map.obj" >"$d/chk.log" 2>&1
    r=$?
    [ "$r" -ne 0 ] && tail -5 "$d/chk.log"
    check "$r" "$what: the new TEXCOORD_0, read independently, is bijective ($(tail -1 "$d/chk.log"))"
    $py tests/uvcheck.py "$d/map.obj" >"$d/uvc.log" 2>&1
    r=$?
    [ "$r" -ne 0 ] && tail -5 "$d/uvc.log"
    check "$r" "$what: and by tests/uvcheck.py, which shares no code with the tool"
    "$tool" --check "$out" >"$d/chk2.log" 2>&1
    r=$?
    [ "$r" -ne 0 ] && tail -5 "$d/chk2.log"
    check "$r" "$what: and as the tool reads it ($(tail -1 "$d/chk2.log"))"
}

# --- bp_gltf.h on its own: C99, C++11 -------------------------------------
ok=0
for c in "gcc -std=c99 -x c" "g++ -std=c++11 -x c++"; do
    $c -Wall -Wextra -pedantic -Werror -I. -c -DBPG_IMPLEMENTATION examples/bp_gltf.h -o "$d/g.o" 2>"$d/cc.log" || { ok=1; cat "$d/cc.log"; }
done
if command -v clang >/dev/null; then
    clang -std=c99 -x c -Wall -Wextra -pedantic -Werror -I. -c -DBPG_IMPLEMENTATION examples/bp_gltf.h -o "$d/g.o" 2>"$d/cc.log" || { ok=1; cat "$d/cc.log"; }
fi
check $ok "examples/bp_gltf.h compiles warning-free as C99 (gcc$(command -v clang >/dev/null && echo ', clang')) and C++11 (g++)"

# --- the generated models ---------------------------------------------------
$py tests/gltf_make.py "$d/gen" >/dev/null
check $? "tests/gltf_make.py makes the models"
$py tests/gltf_make.py "$d/gen2" >/dev/null && cmp -s "$d/gen/two_meshes.glb" "$d/gen2/two_meshes.glb" && cmp -s "$d/gen/strips.gltf" "$d/gen2/strips.gltf"
check $? "tests/gltf_make.py makes the same bytes twice"
cp -r "$d/gen" "$d/orig"

run "$d/gen/two_meshes.glb" --atlas 512 -o "$d/gen/two_out.glb" --json
check $(( $(rc) != 0 )) "two_meshes.glb -> .glb: the tool runs (exit $(rc)) $(head -c 300 "$d/stderr")"
compare "$d/gen/two_meshes.glb" "$d/gen/two_out.glb" "two_meshes.glb -> .glb"
$py - "$d/stdout" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
g = j['gltf']
ok = j['format'] == 'glb' and g['primitives'] == 3 and g['vertices_out'] > g['vertices_in'] and j['charts'] >= 2
print('ok' if ok else 'bad', j['format'], g)
sys.exit(0 if ok else 1)
EOF
check $? "two_meshes.glb: --json says format glb, 3 triangle primitives, vertices split at the seams"
# the size: the input's vertex data scaled by the split, 8 bytes of uv per
# vertex, 4 per corner index, and the JSON of the new accessors -- the old
# vertex data of the written primitives is gone
$py - "$d/stdout" "$d/gen/two_meshes.glb" "$d/gen/two_out.glb" >"$d/size.log" <<'EOF'
import json, os, sys
sys.path.insert(0, 'tests')
import gltf_check as g
j = json.load(open(sys.argv[1]))['gltf']
doc, bufs, _ = g.load(sys.argv[3])
tris = sum(len(g.triangles(doc, bufs, p)) for m in doc['meshes'] for p in m['primitives'] if p.get('mode', 4) == 4)
size_in, size_out = os.path.getsize(sys.argv[2]), os.path.getsize(sys.argv[3])
bound = size_in * j['vertices_out'] / j['vertices_in'] + 8 * j['vertices_out'] + 12 * tris + 4096 + 512 * j['primitives']
din, bin_, _ = g.load(sys.argv[2])
amap, vmap, binc, refused = g.plan(din, bin_, lambda p: g.written(p, din, bin_))
removed = (amap.count(None), vmap.count(None), len(bin_[0]) - len(binc))
print('in %d bytes, out %d, bound %d; removed %s, --json says %s' % (size_in, size_out, bound, removed,
      (j['accessors_removed'], j['views_removed'], j['bytes_removed'])))
sys.exit(0 if size_out <= bound and removed == (j['accessors_removed'], j['views_removed'], j['bytes_removed'])
         and removed[0] > 0 else 1)
EOF
check $? "two_meshes.glb -> .glb: no bigger than the input scaled by the split plus the new uvs and indices, --json's removed counts as worked out independently ($(cat "$d/size.log"))"
# an extension this writer does not know, holding whole numbers (they may
# be accessor or bufferView indices): nothing is removed or renumbered
$py - "$d/gen/two_meshes.glb" "$d/gen/refs.glb" <<'EOF'
import json, struct, sys
data = open(sys.argv[1], 'rb').read()
n = struct.unpack_from('<I', data, 12)[0]
doc = json.loads(data[20:20 + n])
doc['nodes'][0].setdefault('extensions', {})['EXT_example_refs'] = {'accessor': 3, 'bufferView': 2}
text = json.dumps(doc).encode()
text += b' ' * (-len(text) % 4)
rest = data[20 + n:]
open(sys.argv[2], 'wb').write(b'glTF' + struct.pack('<II', 2, 12 + 8 + len(text) + len(rest)) +
                              struct.pack('<II', len(text), 0x4E4F534A) + text + rest)
EOF
run "$d/gen/refs.glb" --atlas 512 -o "$d/gen/refs_out.glb"
[ "$(rc)" = 0 ] && $py tests/gltf_check.py compare "$d/gen/refs.glb" "$d/gen/refs_out.glb" >"$d/cmp.log" 2>&1 &&
    grep -q 'kept: an extension holds indices' "$d/cmp.log" && grep -q "the input's 17 kept accessors come first" "$d/cmp.log"
check $? "an unknown extension holding whole numbers: every accessor and bufferView kept in place ($(grep -c '^ok' "$d/cmp.log") properties)"
# the text of numbers and strings the writer did not change
for s in '1.50e0' '-0.0e+0' '"\u00e9t\u00e9 \/ \"q\""'; do
    n_in=$(grep -aoF -- "$s" "$d/gen/two_meshes.glb" | wc -l); n_out=$(grep -aoF -- "$s" "$d/gen/two_out.glb" | wc -l)
    check $(( n_in == 0 || n_in != n_out )) "two_meshes.glb: the text $s comes back as written ($n_in in, $n_out out)"
done
cmp -s "$d/gen/two_meshes.glb" "$d/orig/two_meshes.glb"
check $? "two_meshes.glb: the input is unchanged"

run "$d/gen/two_meshes.glb" --atlas 512 -o "$d/gen/two_out.gltf"
[ "$(rc)" = 0 ] && [ -s "$d/gen/two_out.bin" ]
check $? "two_meshes.glb -> .gltf: runs, the BIN chunk and the new bytes in two_out.bin"
compare "$d/gen/two_meshes.glb" "$d/gen/two_out.gltf" "two_meshes.glb -> .gltf + .bin"

run "$d/gen/strips.gltf" --atlas 256 -o "$d/gen/strips_out.gltf" --json
check $(( $(rc) != 0 )) "strips.gltf (data: URIs) -> .gltf: runs"
compare "$d/gen/strips.gltf" "$d/gen/strips_out.gltf" "strips.gltf -> .gltf"
r=$($py -c "import json; j=json.load(open('$d/stdout')); print(j['repairs']['flipped']['count'], j['repairs']['flipped']['written_reordered'])")
grep -q '1 triangles re-oriented' "$d/cmp.log" && [ "$r" = "1 1" ]
check $? "strips.gltf: the triangle wound the other way is written turned (corners 0, 2, 1), as --json says ($r)"
check $([ ! -e "$d/gen/strips_out.bin" ] && grep -q '"uri":"data:application/octet-stream;base64,' "$d/gen/strips_out.gltf"; echo $?) \
    "strips.gltf: data: URIs in, a data: URI out (no .bin)"
run "$d/gen/strips.gltf" --atlas 256 -o "$d/gen/strips_out.glb"
compare "$d/gen/strips.gltf" "$d/gen/strips_out.glb" "strips.gltf -> .glb"

# two meshes drawing one sphere from the same accessors: both copies keep
# the data, and their written primitives share one index accessor again
for a in "" "--atlas 256"; do
    run "$d/gen/instanced.glb" $a -o "$d/gen/inst_out.glb"
    check $(( $(rc) != 0 )) "instanced.glb${a:+ $a}: runs (exit $(rc)) $(head -c 300 "$d/stderr")"
    # (not compare: the two instances share their uvs, so the map of both
    # together covers each point twice; one instance's faces are checked)
    $py tests/gltf_check.py compare "$d/gen/instanced.glb" "$d/gen/inst_out.glb" >"$d/cmp.log" 2>&1
    check $? "instanced.glb${a:+ $a} -> .glb: everything kept ($(grep -c '^ok' "$d/cmp.log") properties)"
    $py tests/gltf_check.py obj "$d/gen/inst_out.glb" "$d/map.obj" >/dev/null 2>&1 &&
        awk '!/^f / || !seen[$0]++' "$d/map.obj" >"$d/map1.obj" && [ "$(grep -c '^f ' "$d/map1.obj")" = 108 ] &&
        $py tests/uvcheck.py "$d/map1.obj" >"$d/uvc.log" 2>&1
    check $? "instanced.glb${a:+ $a}: one instance's 108 faces are bijective by tests/uvcheck.py"
    $py - "$d/gen/inst_out.glb" >"$d/inst.log" <<'EOF'
import sys
sys.path.insert(0, 'tests')
import gltf_check as g
doc, bufs, _ = g.load(sys.argv[1])
p0, p1 = (m['primitives'][0] for m in doc['meshes'])
views = {doc['accessors'][p['indices']]['bufferView'] for p in (p0, p1)}
print('indices', p0['indices'], p1['indices'], 'TEXCOORD_0', p0['attributes']['TEXCOORD_0'], p1['attributes']['TEXCOORD_0'],
      'index views', len(views))
sys.exit(0 if p0['indices'] == p1['indices'] and p0['attributes'] == p1['attributes'] and len(views) == 1 else 1)
EOF
    check $? "instanced.glb${a:+ $a}: the two primitives share their indices and attributes again ($(cat "$d/inst.log"))"
done

run "$d/gen/external.gltf" -o "$d/gen/ext_out.gltf"
[ "$(rc)" = 0 ] && [ -s "$d/gen/ext_out.bin" ]
check $? "external.gltf -> .gltf: runs, its new bytes in ext_out.bin"
compare "$d/gen/external.gltf" "$d/gen/ext_out.gltf" "external.gltf -> .gltf + .bin"
cmp -s "$d/gen/external data.bin" "$d/orig/external data.bin" && cmp -s "$d/gen/external.gltf" "$d/orig/external.gltf"
check $? "external.gltf: the input and its .bin are unchanged"
mkdir -p "$d/other/deeper"
run "$d/gen/external.gltf" -o "$d/other/deeper/moved.gltf"
check $(( $(rc) != 0 )) "external.gltf -> another folder: runs"
grep -q '"uri": *"../../gen/external%20data.bin"' "$d/other/deeper/moved.gltf" && grep -q '"uri": *"../../gen/checker.png"' "$d/other/deeper/moved.gltf"
check $? "written in another folder, its uris reach the same .bin and image ($(grep -o '"uri": *"[^"]*"' "$d/other/deeper/moved.gltf" | head -2 | tr '\n' ' '))"
compare "$d/gen/external.gltf" "$d/other/deeper/moved.gltf" "external.gltf -> another folder"
run "$d/gen/external.gltf" -o "$d/gen/external data.gltf"
check $(( $(rc) != 1 )) "an output whose .bin is the input's own .bin is refused (exit $(rc)): $(head -1 "$d/stderr")"
cmp -s "$d/gen/external data.bin" "$d/orig/external data.bin"
check $? "and the input's .bin is unchanged"

# --- the file's own map: --repack, --init input ----------------------------
run "$d/gen/external.gltf" --repack --atlas 256 -o "$d/gen/repack.gltf"
check $(( $(rc) != 0 )) "external.gltf --repack --atlas 256: runs"
fit=$($py - "$d/gen/external.gltf" "$d/gen/repack.gltf" <<'EOF'
import sys
sys.path.insert(0, 'tests')
import gltf_check as g
din, bin_, _ = g.load(sys.argv[1]); dout, bout, _ = g.load(sys.argv[2])
a = g.values(din, bin_, din['meshes'][0]['primitives'][0]['attributes']['TEXCOORD_0'])
b = g.values(dout, bout, dout['meshes'][0]['primitives'][0]['attributes']['TEXCOORD_0'])
# the packed map is the file's moved, turned by a multiple of 90 degrees
# and scaled: fit it from two vertices, then every vertex must agree
i, j = 0, len(a) - 1
da = (a[j][0] - a[i][0], a[j][1] - a[i][1]); db = (b[j][0] - b[i][0], b[j][1] - b[i][1])
n2 = da[0] ** 2 + da[1] ** 2
c, s = (da[0] * db[0] + da[1] * db[1]) / n2, (da[0] * db[1] - da[1] * db[0]) / n2
err = max(abs(b[i][0] + c * (p[0] - a[i][0]) - s * (p[1] - a[i][1]) - q[0]) + abs(b[i][1] + s * (p[0] - a[i][0]) + c * (p[1] - a[i][1]) - q[1])
          for p, q in zip(a, b))
print('largest misfit', err, 'scale', (c * c + s * s) ** 0.5)
sys.exit(0 if err < 1e-5 and len(a) <= len(b) else 1)
EOF
)
check $? "--repack: the written TEXCOORD_0 is the file's map moved and scaled ($fit)"
run "$d/gen/external.gltf" --init input --json -o "$d/gen/init.glb"
check $(( $(rc) != 0 )) "external.gltf --init input: runs"
$py -c "import json,sys; j=json.load(open('$d/stdout')); sys.exit(0 if all(c['init_used'] == 1 and c['start_map'] == 'input' for c in j['per_chart']) else 1)"
check $? "--init input: every chart started from the file's TEXCOORD_0"
compare "$d/gen/external.gltf" "$d/gen/init.glb" "external.gltf --init input -> .glb"

# --- a second set: --texcoord 1 keeps TEXCOORD_0 and writes TEXCOORD_1 ------
run "$d/gen/external.gltf" --texcoord 1 --atlas 256 -o "$d/gen/lightmap.glb"
check $(( $(rc) != 0 )) "external.gltf --texcoord 1: runs"
$py tests/gltf_check.py compare "$d/gen/external.gltf" "$d/gen/lightmap.glb" --texcoord 1 >"$d/cmp.log" 2>&1
r=$?
[ "$r" -ne 0 ] && grep -v '^ok' "$d/cmp.log" | head
check "$r" "--texcoord 1: every corner keeps its TEXCOORD_0 (and all else) byte for byte, TEXCOORD_1 added"
$py tests/gltf_check.py obj "$d/gen/lightmap.glb" "$d/lm.obj" --texcoord 1 >/dev/null && $py tests/uvcheck.py "$d/lm.obj" >/dev/null 2>&1
check $? "--texcoord 1: TEXCOORD_1 is bijective (tests/uvcheck.py)"

# --- the real models (tests/data/gltf) --------------------------------------
cp -r tests/data/gltf "$d/data_before"
for f in tests/data/gltf/BoxTextured.glb tests/data/gltf/BoxTextured/BoxTextured.gltf \
         tests/data/gltf/AnimatedMorphCube/AnimatedMorphCube.gltf tests/data/gltf/MorphPrimitivesTest/MorphPrimitivesTest.gltf \
         tests/data/gltf/SimpleSkin.gltf; do
    b=$(basename "$f"); b=${b%.*}
    for ext in glb gltf; do
        run "$f" --atlas 256 -o "$d/real_$b.$ext"
        check $(( $(rc) != 0 )) "$b -> .$ext: runs $(head -c 200 "$d/stderr")"
        compare "$f" "$d/real_$b.$ext" "$b -> .$ext"
    done
done
diff -r tests/data/gltf "$d/data_before" >/dev/null
check $? "tests/data/gltf is unchanged"
run --check tests/data/gltf/BoxTextured.glb
check $(( $(rc) != 1 )) "--check BoxTextured.glb: its own map has mirrored faces (exit $(rc))"
grep -q 'first bad triangle: mesh 0 primitive 0 triangle [0-9]* (vertices [0-9]* [0-9]* [0-9]*) is flipped' "$d/stdout"
check $? "--check names the flipped triangle as the file does: $(grep -m1 'first bad' "$d/stdout")"

# --- bad files and misuse ------------------------------------------------------
head -c 1000 "$d/gen/two_meshes.glb" > "$d/trunc.glb"
run "$d/trunc.glb" -o "$d/trunc_out.glb"
check $(( $(rc) != 1 || $(wc -l < "$d/stderr") != 1 )) "a truncated .glb: exit 1, one line: $(cat "$d/stderr")"
grep -q 'truncated GLB' "$d/stderr" && [ ! -e "$d/trunc_out.glb" ] && no_temp
check $? "  it says so, writes nothing and leaves no temporary"
$py - "$d/gen/strips.gltf" "$d/bad_index.gltf" <<'EOF'
import base64, json, sys
doc = json.load(open(sys.argv[1]))
raw = bytearray(base64.b64decode(doc['buffers'][0]['uri'].split(',', 1)[1]))
v = doc['bufferViews'][doc['accessors'][doc['meshes'][0]['primitives'][0]['indices']]['bufferView']]
raw[v.get('byteOffset', 0) + 3] = 200                      # index 200 of 36 vertices
doc['buffers'][0]['uri'] = 'data:application/octet-stream;base64,' + base64.b64encode(bytes(raw)).decode()
json.dump(doc, open(sys.argv[2], 'w'))
EOF
run "$d/bad_index.gltf" -o "$d/bad_out.gltf"
grep -q 'bad_index.gltf: accessor [0-9]* (indices of mesh 0 primitive 0): index 200 (element 3)' "$d/stderr" && [ "$(rc)" = 1 ] && [ ! -e "$d/bad_out.gltf" ]
check $? "an index out of range names the accessor, primitive, index and element: $(cat "$d/stderr")"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$d/t.obj"
run "$d/t.obj" -o "$d/t.glb"
check $(( $(rc) != 2 )) "-o .glb from an OBJ input is a usage error (exit $(rc)): $(head -1 "$d/stderr")"
run "$d/gen/strips.gltf" --pin "$d/t.obj" -o "$d/p.gltf"
check $(( $(rc) != 2 )) "--pin with a glTF input is a usage error (exit $(rc))"
run "$d/gen/strips.gltf" -o "$d/strips.obj"
check $(( $(rc) != 0 )) "a glTF input written as OBJ: runs"
"$tool" --check "$d/strips.obj" > "$d/chk.log" 2>&1
check $? "  and that OBJ is bijective ($(tail -1 "$d/chk.log"))"
no_temp
check $? "no temporary file stays behind"
echo "BPTEST $passed $failed"
[ "$failed" -eq 0 ]
