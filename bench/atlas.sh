#!/usr/bin/env bash
# Atlas benchmark (make bench-atlas): every mesh of tests/data through
# --atlas 1024 --padding 4, one at a time, each output checked by
# tests/uvcheck.py; a Markdown table on stdout,
# one JSON line per mesh on stderr and in build/bench/atlas.jsonl.
# bench/atlas.py documents every column and the environment variables.
#   bash bench/atlas.sh                          ~5 min on 2 cores
#   ATLAS_MESHES="spot.obj fertility.off" bash bench/atlas.sh
set -u
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "bench-atlas: build/bijparam missing: run 'make' first" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench-atlas: python3 is needed" >&2; exit 1; }
mkdir -p build/bench
# a closed 90K-triangle genus-0 scan (bimba closed over its base)
[ -f build/bench/bimba_closed.obj ] ||
    python3 bench/close_base.py tests/data/bimba_i.obj build/bench/bimba_closed.obj
if [ -z "${BENCH_TOOL:-}" ]; then     # a snapshot: a rebuild mid-bench cannot mix versions
    cp build/bijparam build/bench/bijparam-atlas
    export BENCH_TOOL=build/bench/bijparam-atlas
fi
exec python3 bench/atlas.py
