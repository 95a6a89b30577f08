#!/usr/bin/env bash
# Packing benchmark (make bench-pack): utilization of the outline packer
# (--atlas 1024 --padding 4) against the shelf packer on spot and the cow,
# each result checked by tests/uvcheck.py, and the time to pack
# 5,000 small charts (bench/pack_bench.c).  Prints a table and JSON lines.
set -u
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "bench-pack: build/bijparam missing: run 'make' first" >&2; exit 1; }
mkdir -p build/bench
${CC:-gcc} -I. -std=c99 -O2 -Wall -Wextra -pedantic -Werror bench/pack_bench.c -o build/bench/pack_bench -lm || exit 1
check=tests/uvcheck.py
printf "%-22s %8s %8s %12s %10s %8s\n" mesh charts shelf "atlas 1024/4" "pack (s)" uvcheck
for m in tests/data/spot.obj tests/data/cow_param_withSUV.obj; do
    [ -f "$m" ] || { echo "bench-pack: $m missing" >&2; continue; }
    name=$(basename "$m" .obj)
    shelf=$(build/bijparam "$m" --json | python3 -c 'import sys,json; print("%.3f" % json.load(sys.stdin)["utilization"])')
    build/bijparam "$m" --atlas 1024 --padding 4 --json -o build/bench/$name.atlas.obj > build/bench/$name.atlas.json
    read -r charts util secs < <(python3 -c 'import sys,json; j=json.load(open(sys.argv[1])); print(j["charts"], "%.3f" % j["utilization"], "%.3f" % j["timings"]["pack"])' build/bench/$name.atlas.json)
    python3 "$check" build/bench/$name.atlas.obj "$m" > /dev/null && ok=valid || ok=INVALID
    printf "%-22s %8s %8s %12s %10s %8s\n" "$name" "$charts" "$shelf" "$util" "$secs" "$ok"
done
for n in 1000 5000; do build/bench/pack_bench $n 1024 4; done
