#!/usr/bin/env bash
# make bench-scale: time and memory of one chart subdivided to 8K, 133K,
# 298K and 1M faces, 1 and 2 threads (bench/scale.py documents the columns
# and the BENCH_SCALE_* variables).  The million-face run takes minutes.
#
#   bash bench/scale.sh                              (or: make bench-scale)
#   BENCH_SCALE_N="1 2" bash bench/scale.sh          8K and 33K faces only
set -u
cd "$(dirname "$0")/.."
[ -x build/bijparam ] || { echo "bench-scale: build/bijparam missing: run 'make' first" >&2; exit 1; }
command -v python3 >/dev/null || { echo "bench-scale: python3 is needed" >&2; exit 1; }
mkdir -p build/bench/scale
if [ -z "${BENCH_TOOL:-}" ]; then     # a snapshot: a rebuild mid-bench cannot mix versions
    cp build/bijparam build/bench/bijparam-scale
    export BENCH_TOOL=build/bench/bijparam-scale
fi
exec python3 bench/scale.py
