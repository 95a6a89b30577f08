#!/usr/bin/env bash
# bench/build.sh (make bench-build) - the implementation's compile time and
# code size per build configuration.
#
# For each configuration (the full header, each BP_NO_ macro alone, the
# core library -- BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY -- with and
# without BP_NO_IO, the core without its default BP_SMALL and the whole
# with BP_SMALL=1) and each compiler (gcc and clang, -std=c99
# -O2 -c of a file holding only `#define BP_IMPLEMENTATION` and
# `#include "bijparam.h"`): user CPU seconds (median of ROUNDS runs, 3 by
# default; the rounds alternate between configurations so that a change in
# the machine's load spreads over all of them), wall seconds (median), and
# the bytes of text of the object file (`size`).  Prints a table and writes
# build/bench/build.json.  CPU time is the figure to compare: on a busy
# machine wall time grows, CPU time much less.
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT="$ROOT/build/bench"
ROUNDS=${ROUNDS:-3}
COMPILERS=${COMPILERS:-"gcc clang"}
mkdir -p "$OUT"
TMP=$(mktemp -d "${TMPDIR:-/tmp}/bp_build.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
printf '#define BP_IMPLEMENTATION\n#include "bijparam.h"\n' >"$TMP/impl.c"

# name|macros (the configurations a BP_NO_ macro of this header defines)
CONFIGS="full|
no_newton|BP_NO_NEWTON
no_atlas|BP_NO_ATLAS
no_visibility|BP_NO_VISIBILITY
no_io|BP_NO_IO
core|BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY
core_no_io|BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY BP_NO_IO
core_not_small|BP_NO_NEWTON BP_NO_ATLAS BP_NO_VISIBILITY BP_SMALL=0
full_small|BP_SMALL=1"

: >"$TMP/raw"
for r in $(seq "$ROUNDS"); do
    while IFS='|' read -r name macros; do
        defs=$(for m in $macros; do printf ' -D%s' "$m"; done)
        for cc in $COMPILERS; do
            command -v "$cc" >/dev/null || continue
            /usr/bin/time -f '%U %e' -o "$TMP/t" $cc -std=c99 -O2 $defs -I"$ROOT" -c "$TMP/impl.c" -o "$TMP/o.o"
            text=$(size "$TMP/o.o" | awk 'NR == 2 { print $1 }')
            echo "$name $cc $(cat "$TMP/t") $text" >>"$TMP/raw"
        done
    done <<<"$CONFIGS"
done

python3 - "$TMP/raw" "$OUT/build.json" "$ROUNDS" <<'PY'
import json, statistics, sys
raw, out, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
rows = {}
for line in open(raw):
    name, cc, user, wall, text = line.split()
    r = rows.setdefault((name, cc), {"config": name, "compiler": cc, "user": [], "wall": [], "text": int(text)})
    r["user"].append(float(user)); r["wall"].append(float(wall))
res = []
full = {cc: statistics.median(r["user"]) for (n, cc), r in rows.items() if n == "full"}
print("%-18s %-6s %9s %9s %10s %8s" % ("config", "cc", "user s", "wall s", "text B", "vs full"))
for (name, cc), r in rows.items():
    u, w = statistics.median(r["user"]), statistics.median(r["wall"])
    ratio = u / full[cc] if full.get(cc) else None
    print("%-18s %-6s %9.2f %9.2f %10d %8s" % (name, cc, u, w, r["text"], "%.2fx" % ratio if ratio else "-"))
    res.append({"config": name, "compiler": cc, "user_s_median": u, "wall_s_median": w, "text_bytes": r["text"],
                "user_s": r["user"], "wall_s": r["wall"], "user_vs_full": ratio})
json.dump({"rounds": rounds, "flags": "-std=c99 -O2 -c", "results": res}, open(out, "w"), indent=1)
print("wrote", out)
PY
